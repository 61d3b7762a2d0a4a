//! The contacts of candidate pairs on a device (`kernels/pairs.cu`,
//! `pair_contacts`): one thread per pair finds the two particles' contact (the
//! overlap of two polyhedra, a lens of two spheres, a sphere's cap on a
//! polyhedron) and its force, torques, energy and history under the scene's laws,
//! as the CPU backend's pair stage does (`engine/cpu/pairs.rs`,
//! `engine/cpu/dispatch.rs`, `engine/cpu/forces.rs`).
//!
//! What the kernel reads: the particles' states (`device_states.rs`), the body
//! types with their shapes and laws' rows ([`DeviceBodyTypes`]), and per pair its
//! history ([`PairContacts`], or a stepper's pairs).

use nalgebra::Vector3;

use super::Kernel;
use super::device::{Arg, Array, Device, DeviceError};
use super::device_body_types::{DeviceBodyTypes, HISTORY};
use super::device_states::{DeviceStates, StateView};
use super::device_wall_slots::{history_of, history_row};
use crate::Real;
use crate::contact::TangentialHistory;

/// Doubles of a pair's result and energy terms (`RESULT_DOUBLES` and
/// `PAIR_ENERGY_DOUBLES` of contact.cuh).
const RESULT: usize = 9;
const PAIR_ENERGY: usize = 2;
/// A pair's byte where it touches (`PAIR_TOUCHES`).
const PAIR_TOUCHES: u8 = 1;

/// One contact's result: what the CPU backend's pair stage gathers.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PairContactResult {
    /// Force on the second particle; the first gets the opposite.
    pub force: Vector3<Real>,
    /// Torque on the first particle and on the second, about their centroids.
    pub torques: [Vector3<Real>; 2],
    /// Elastic energy the contact holds.
    pub energy: Real,
    /// Energy dissipated over the step (apart: the friction spring's energy let go).
    pub dissipated: Real,
    /// Whether the particles touch.
    pub touching: bool,
}

/// The arrays a pass of [`pair_contacts`] writes, per candidate pair: its
/// history (read and replaced), its result (force on the second particle, torque
/// on the first and on the second: 9 doubles), its energy terms (elastic energy and
/// dissipation, 2 doubles, zero where the world does not count the pair) and its
/// byte (touches, counted: `kernels/contact.cuh`), as `kernels/spheres.cu` writes
/// them for spheres.
pub(super) struct PairOutputs<'a> {
    pub history: &'a Array<Real>,
    pub results: &'a Array<Real>,
    pub energies: &'a Array<Real>,
    pub touching: &'a Array<u8>,
}

/// Launches the contacts of the `count` candidate pairs `pairs` (two particle
/// indices each) over a step of `dt` (see the module).
///
/// # Safety
/// `states` holds every particle a pair names, `types` every body type of those
/// particles, and `out` room for `count` pairs.
pub(super) unsafe fn pair_contacts(
    device: &mut dyn Device,
    types: &DeviceBodyTypes,
    states: &StateView,
    count: usize,
    pairs: &Array<u32>,
    out: &PairOutputs,
    dt: Real,
) -> Result<(), DeviceError> {
    if count == 0 {
        return Ok(());
    }
    let mut args = vec![Arg::U32(count as u32), Arg::F64(dt), pairs.arg()];
    args.extend(states.args());
    args.push(states.role.arg());
    args.extend(types.law_args());
    args.push(types.shape.arg());
    args.extend(types.shapes.args());
    args.extend(types.hertz.args());
    args.extend([
        Arg::U32(types.round_volume()),
        Arg::U32(types.history_width() as u32),
        Arg::U32(types.rolling()),
        out.history.arg(),
        out.results.arg(),
        out.energies.arg(),
        out.touching.arg(),
    ]);
    // SAFETY: the parameters of pair_contacts (pairs.cu), each array
    // sized as the caller promises.
    unsafe { device.launch(Kernel::PairContacts, count, &args) }
}

/// Candidate pairs on a device, with each pair's history (of five doubles: a world
/// without rolling resistance) and the results of its last evaluation.
#[derive(Debug, Default)]
pub struct PairContacts {
    /// Two particle indices per pair.
    pairs: Array<u32>,
    history: Array<Real>,
    results: Array<Real>,
    energies: Array<Real>,
    touching: Array<u8>,
    host: Vec<Real>,
}

impl PairContacts {
    /// Sets the candidate pairs and the history each holds.
    ///
    /// # Panics
    /// When `pairs` and `histories` differ in length.
    pub fn set_pairs(
        &mut self,
        device: &mut dyn Device,
        pairs: &[(u32, u32)],
        histories: &[TangentialHistory],
    ) -> Result<(), DeviceError> {
        assert_eq!(pairs.len(), histories.len(), "a history per pair");
        let flat: Vec<u32> = pairs.iter().flat_map(|&(i, j)| [i, j]).collect();
        self.pairs.write(device, &flat)?;
        self.host.clear();
        for h in histories {
            self.host.extend(&history_row(h)[..HISTORY]);
        }
        self.history.write(device, &self.host)?;
        self.results.resize(device, RESULT * pairs.len())?;
        self.energies.resize(device, PAIR_ENERGY * pairs.len())?;
        self.touching.resize(device, pairs.len())
    }

    /// Evaluates every pair's contact over a step of `dt` (see the module).
    ///
    /// The states must hold every particle a pair names, and the body types every
    /// body type of those particles.
    pub fn evaluate(
        &mut self,
        device: &mut dyn Device,
        types: &DeviceBodyTypes,
        states: &DeviceStates,
        dt: Real,
    ) -> Result<(), DeviceError> {
        let out = PairOutputs {
            history: &self.history,
            results: &self.results,
            energies: &self.energies,
            touching: &self.touching,
        };
        let count = self.pairs.len() / 2;
        // SAFETY: the caller's promise on the states and types; a history, result,
        // energy and byte per pair (set_pairs).
        unsafe { pair_contacts(device, types, &states.view(), count, &self.pairs, &out, dt) }
    }

    /// The results of the last evaluation.
    pub fn results(&mut self, device: &dyn Device) -> Result<Vec<PairContactResult>, DeviceError> {
        let (energies, touching) = (self.energies.read(device)?, self.touching.read(device)?);
        self.results.read_into(device, &mut self.host)?;
        let v = |r: &[Real], k: usize| Vector3::new(r[k], r[k + 1], r[k + 2]);
        Ok((self.host.chunks_exact(RESULT).enumerate())
            .map(|(e, r)| PairContactResult {
                force: v(r, 0),
                torques: [v(r, 3), v(r, 6)],
                energy: energies[PAIR_ENERGY * e],
                dissipated: energies[PAIR_ENERGY * e + 1],
                touching: touching[e] & PAIR_TOUCHES != 0,
            })
            .collect())
    }

    /// Each pair's history as the last evaluation left it.
    pub fn histories(
        &mut self,
        device: &dyn Device,
    ) -> Result<Vec<TangentialHistory>, DeviceError> {
        self.history.read_into(device, &mut self.host)?;
        Ok(self.host.chunks_exact(HISTORY).map(history_of).collect())
    }
}
