//! The contacts of polyhedra under the volume law on a device
//! (`kernels/polyhedra.cu`, `polyhedron_contacts`; `kernels/volume_law.cuh`): one
//! thread per candidate pair finds the overlap of the two particles' shapes and
//! its force, torques, energy and friction history, as the CPU backend's pair
//! stage does for a pair of polyhedra (`engine/cpu/dispatch.rs` and
//! `engine/cpu/forces.rs`).
//!
//! What the kernel reads: the particles' states ([`DeviceStates`]), the body types
//! with their shapes and contact-law rows, and the pairs of materials
//! ([`DeviceBodyTypes`]), and per pair its history ([`VolumeContacts`]).

use std::collections::HashMap;

use nalgebra::Vector3;

use super::Kernel;
use super::device::{Arg, Array, Device, DeviceError};
use super::device_hertz::HertzTypes;
use super::device_polyhedra::{DeviceShapes, ShapeTableError};
use super::device_states::{DeviceStates, StateView};
use super::device_wall_slots::{history_of, history_row};
use crate::Real;
use crate::contact::{RollingModel, TangentialHistory};
use crate::engine::laws::ContactLaws;
use crate::engine::params::RoundLaw;
use crate::geometry::{ConvexPolyhedron, is_isotropic};
use crate::world::World;

/// A sphere's shape index (`NO_SHAPE` of polyhedra.cu).
pub(super) const NO_SHAPE: u32 = u32::MAX;
/// Doubles of a body type's law row (`TYPE_LAW_DOUBLES` of volume_law.cuh).
const TYPE_LAW: usize = 7;
/// Nodes of a damping table (`DAMPING_NODES`).
const DAMPING_NODES: usize = 21;
/// Doubles of a pair of materials' law row (`MATERIAL_LAW_DOUBLES`).
const MATERIAL_LAW: usize = 4 + DAMPING_NODES;
/// Doubles of a contact's history (`VOLUME_HISTORY_DOUBLES`).
pub(super) const HISTORY: usize = 5;
/// Doubles of a Hertz–Mindlin history without twist (`HISTORY_DOUBLES`).
const SPRING: usize = 4;
/// Doubles of a history with a rolling spring (`ROLLING_HISTORY_DOUBLES`).
const ROLLING_HISTORY: usize = 8;
/// Doubles of a pair's result and energy terms (`RESULT_DOUBLES` and
/// `PAIR_ENERGY_DOUBLES` of contact.cuh).
const RESULT: usize = 9;
const PAIR_ENERGY: usize = 2;
/// A pair's byte where it touches (`PAIR_TOUCHES`).
const PAIR_TOUCHES: u8 = 1;

/// The body types of a world (polyhedra, spheres or both) and its pairs of
/// materials on a device, as the contact kernels read them.
///
/// # Invariant
/// Every polyhedron's shape is in `shapes` at `shape[t]`, a sphere's `shape[t]` is
/// [`NO_SHAPE`]; the law rows are those of the [`ContactLaws`] they were made
/// from, the Hertz–Mindlin table that of the same world.
#[derive(Debug, Default)]
pub struct DeviceBodyTypes {
    pub(super) shapes: DeviceShapes,
    /// Per body type, its shape's index in `shapes` ([`NO_SHAPE`]: a sphere).
    pub(super) shape: Array<u32>,
    /// The spheres' Hertz–Mindlin table.
    pub(super) hertz: HertzTypes,
    /// Whether a body type is a polyhedron.
    pub(super) polyhedra: bool,
    /// Whether spheres follow the volume law (else Hertz–Mindlin).
    pub(super) round_volume: bool,
    /// The spheres' rolling resistance under Hertz–Mindlin (`ROLLING_*` of
    /// contact.cuh).
    pub(super) rolling: u32,
    mass: Array<Real>,
    /// Principal moments, three per type.
    inertia: Array<Real>,
    /// 1 where the three moments are equal (`is_isotropic`).
    isotropic: Array<u8>,
    /// The law rows (`TYPE_LAW_DOUBLES` of volume_law.cuh).
    pub(super) law: Array<Real>,
    material: Array<u32>,
    material_count: u32,
    /// Per pair of materials, row-major (`MATERIAL_LAW_DOUBLES`).
    pub(super) material_law: Array<Real>,
}

impl DeviceBodyTypes {
    /// The launch arguments of what the volume law reads of the body types and
    /// materials: mass, principal moments, isotropy, law rows, material, the
    /// material count and the material pairs' rows.
    pub(super) fn law_args(&self) -> [Arg; 7] {
        [
            self.mass.arg(),
            self.inertia.arg(),
            self.isotropic.arg(),
            self.law.arg(),
            self.material.arg(),
            Arg::U32(self.material_count),
            self.material_law.arg(),
        ]
    }

    /// Whether every contact is a sphere's under Hertz–Mindlin without rolling
    /// resistance (`sphere_contacts` steps the pairs).
    pub(super) fn spheres_under_hertz(&self) -> bool {
        !self.polyhedra && !self.round_volume && self.rolling == 0
    }

    /// Doubles of a contact's tangential history: the spring and its stiffness
    /// (4: spheres under Hertz–Mindlin alone), the twist (5), and with rolling
    /// resistance the rolling spring (8).
    pub(super) fn history_width(&self) -> usize {
        if self.rolling != 0 {
            ROLLING_HISTORY
        } else if self.spheres_under_hertz() {
            SPRING
        } else {
            HISTORY
        }
    }

    /// Bytes of device memory held.
    pub fn bytes(&self, device: &dyn Device) -> usize {
        let doubles = [&self.mass, &self.inertia, &self.law, &self.material_law];
        self.shapes.bytes(device)
            + self.hertz.bytes(device)
            + doubles.iter().map(|a| a.bytes(device)).sum::<usize>()
            + self.shape.bytes(device)
            + self.material.bytes(device)
            + self.isotropic.bytes(device)
    }

    /// Uploads the body types and materials of `world`, the laws' rows made for
    /// the regularisation length `regularisation_length` (relative to each body's
    /// volume-equivalent radius, as [`crate::engine::params`]' field); body types
    /// sharing a shape share its copy on the device.
    pub fn upload(
        device: &mut dyn Device,
        world: &World,
        regularisation_length: Real,
        round: RoundLaw,
    ) -> Result<Self, ShapeTableError> {
        let mut laws = ContactLaws::default();
        laws.prepare(world, regularisation_length, round);
        let mut distinct: Vec<&ConvexPolyhedron> = Vec::new();
        let mut index_of: HashMap<*const ConvexPolyhedron, u32> = HashMap::new();
        let mut shape = Vec::new();
        for body in &world.body_types {
            let Some(polyhedron) = body.shape.as_polyhedron() else {
                shape.push(NO_SHAPE);
                continue;
            };
            let k = *index_of.entry(polyhedron).or_insert_with(|| {
                distinct.push(polyhedron);
                distinct.len() as u32 - 1
            });
            shape.push(k);
        }
        let types = &world.body_types;
        let mut law = Vec::with_capacity(TYPE_LAW * types.len());
        let mut material = Vec::with_capacity(types.len());
        for row in laws.type_rows() {
            law.extend([
                row.stiffness.normal,
                row.stiffness.tangential,
                row.regularisation.volume(),
                row.regularisation.cbrt(),
                row.inverse_inertia,
                row.radius,
                row.inertia,
            ]);
            material.push(row.material as u32);
        }
        let mut material_law = Vec::new();
        for (friction, table, wall_series) in laws.material_rows() {
            // No table where no contact follows the volume law (spheres under
            // Hertz–Mindlin): a row of zeros, never read.
            let none = [0.0; DAMPING_NODES];
            let (restitution, nodes) = table.map_or((0.0, &none), |t| (t.restitution(), t.nodes()));
            material_law.extend([friction, restitution]);
            material_law.extend(nodes);
            material_law.extend([wall_series.normal, wall_series.tangential]);
        }
        debug_assert_eq!(
            material_law.len(),
            MATERIAL_LAW * laws.material_count().pow(2)
        );
        let mut uploaded = DeviceBodyTypes {
            polyhedra: !distinct.is_empty(),
            round_volume: round == RoundLaw::Volume,
            rolling: match round {
                RoundLaw::HertzMindlin { rolling } => match rolling {
                    RollingModel::None => 0,
                    RollingModel::ConstantTorque => 1,
                    RollingModel::ElasticPlastic => 2,
                },
                RoundLaw::Volume => 0,
            },
            shapes: DeviceShapes::upload(device, &distinct)?,
            hertz: HertzTypes::upload(device, world)?,
            material_count: laws.material_count() as u32,
            ..Default::default()
        };
        uploaded.shape.write(device, &shape)?;
        let masses: Vec<Real> = types.iter().map(|b| b.mass).collect();
        uploaded.mass.write(device, &masses)?;
        let inertia: Vec<Real> = types
            .iter()
            .flat_map(|b| b.inertia.iter().copied())
            .collect();
        uploaded.inertia.write(device, &inertia)?;
        let isotropic: Vec<u8> = types
            .iter()
            .map(|b| is_isotropic(&b.inertia) as u8)
            .collect();
        uploaded.isotropic.write(device, &isotropic)?;
        uploaded.law.write(device, &law)?;
        uploaded.material.write(device, &material)?;
        uploaded.material_law.write(device, &material_law)?;
        Ok(uploaded)
    }
}

/// One contact's result: what the CPU backend's pair stage gathers.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VolumeContactResult {
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

/// The arrays a pass of [`polyhedron_contacts`] writes, per candidate pair: its
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

/// Launches the volume law's contacts of the `count` candidate pairs `pairs` (two
/// particle indices each) over a step of `dt` (see the module).
///
/// # Safety
/// `states` holds every particle a pair names, `types` every body type of those
/// particles, and `out` room for `count` pairs.
pub(super) unsafe fn polyhedron_contacts(
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
        Arg::U32(u32::from(types.round_volume)),
        Arg::U32(types.history_width() as u32),
        Arg::U32(types.rolling),
        out.history.arg(),
        out.results.arg(),
        out.energies.arg(),
        out.touching.arg(),
    ]);
    // SAFETY: the parameters of polyhedron_contacts (polyhedra.cu), each array
    // sized as the caller promises.
    unsafe { device.launch(Kernel::PolyhedronContacts, count, &args) }
}

/// Candidate pairs of polyhedra on a device, with each pair's friction history and
/// the results of its last evaluation.
#[derive(Debug, Default)]
pub struct VolumeContacts {
    /// Two particle indices per pair.
    pairs: Array<u32>,
    history: Array<Real>,
    results: Array<Real>,
    energies: Array<Real>,
    touching: Array<u8>,
    host: Vec<Real>,
}

impl VolumeContacts {
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
        unsafe { polyhedron_contacts(device, types, &states.view(), count, &self.pairs, &out, dt) }
    }

    /// The results of the last evaluation.
    pub fn results(
        &mut self,
        device: &dyn Device,
    ) -> Result<Vec<VolumeContactResult>, DeviceError> {
        let (energies, touching) = (self.energies.read(device)?, self.touching.read(device)?);
        self.results.read_into(device, &mut self.host)?;
        let v = |r: &[Real], k: usize| Vector3::new(r[k], r[k + 1], r[k + 2]);
        Ok((self.host.chunks_exact(RESULT).enumerate())
            .map(|(e, r)| VolumeContactResult {
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
