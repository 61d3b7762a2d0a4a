//! The particles' wall contacts on a device, [`SLOTS`] a particle: each contact's
//! key (the wall and its plane's four rounded numbers), its tangential history (a
//! friction spring, the twist beside the volume law, a rolling spring with rolling
//! resistance), and its record for the
//! walls' sums (`WALL_RECORD_DOUBLES` of `kernels/triangle.cuh`), for this
//! evaluation and the one before, whose springs this one's contacts take up by key
//! and whose contacts not taken up let their springs' energy go.

use nalgebra::Vector3;

use super::Kernel;
use super::device::{Arg, Array, Device, DeviceError};
use super::device_list::run;
use crate::Real;
use crate::contact::TangentialHistory;
use crate::engine::backend::WallKey;

/// Contacts a particle may have with the walls at once (`WALL_SLOTS` of triangle.cuh).
pub const SLOTS: usize = 4;
/// Words of a contact's key: the wall and the plane's four rounded numbers.
const KEY: usize = 5;
/// Doubles of a contact's record: force, torque, the facets' total share, elastic
/// energy, energy dissipated.
const RECORD: usize = 9;

/// One set of per-particle contact slots: counts, keys, histories.
#[derive(Debug, Default)]
pub(super) struct Slots {
    pub count: Array<u32>,
    pub keys: Array<i64>,
    pub history: Array<Real>,
}

/// One wall contact as last evaluated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallContactResult {
    /// The wall's index and the plane's key.
    pub wall: u32,
    pub key: [i64; 4],
    /// Force on the particle; the wall gets the opposite.
    pub force: Vector3<Real>,
    /// Torque on the particle about its centroid.
    pub torque: Vector3<Real>,
    pub energy: Real,
    pub dissipated: Real,
    /// The tangential history it keeps.
    pub history: TangentialHistory,
}

/// A tangential history as the kernels keep it: the spring, its stiffness, the
/// twist, the rolling spring (`kernels/polyhedra.cu`); a history of fewer doubles
/// is the row's first ones.
pub(super) fn history_row(h: &TangentialHistory) -> [Real; 8] {
    let (s, r) = (&h.spring, &h.rolling);
    [s.x, s.y, s.z, h.stiffness, h.twist, r.x, r.y, r.z]
}

/// The tangential history of a kernel's row of 4, 5 or 8 doubles (see
/// [`history_row`]).
pub(super) fn history_of(h: &[Real]) -> TangentialHistory {
    let at = |k: usize| h.get(k).copied().unwrap_or(0.0);
    TangentialHistory {
        spring: Vector3::new(h[0], h[1], h[2]),
        stiffness: h[3],
        twist: at(4),
        rolling: Vector3::new(at(5), at(6), at(7)),
    }
}

/// The error of a particle touching walls at more places than it has slots for.
pub(super) fn too_many_wall_contacts() -> DeviceError {
    DeviceError::Capacity(format!(
        "particle touching walls at more than {SLOTS} places at once"
    ))
}

/// The wall contacts of this evaluation and of the one before (see the module).
///
/// # Invariant
/// Both sets hold [`SLOTS`] contacts for each of the same particles, each
/// history `width` doubles: the spring (3), the stiffness it was stretched at,
/// where `width` is 5 or 8 the twist, where 8 the rolling spring (3).
#[derive(Debug, Default)]
pub struct WallSlots {
    width: usize,
    pub(super) old: Slots,
    pub(super) new: Slots,
    pub(super) records: Array<Real>,
    /// Per contact, the facet of a sphere's, or the patch slot of a polyhedron's.
    pub(super) record_index: Array<u32>,
}

impl WallSlots {
    /// Slots for `n` particles, each without contacts, histories of `width`
    /// doubles (see [`history_row`]).
    pub fn new(device: &mut dyn Device, n: usize, width: usize) -> Result<Self, DeviceError> {
        let mut slots = WallSlots {
            width,
            ..Default::default()
        };
        for set in [&mut slots.old, &mut slots.new] {
            set.count.resize(device, n)?;
            set.keys.resize(device, KEY * SLOTS * n)?;
            set.history.resize(device, width * SLOTS * n)?;
        }
        slots.new.count.write(device, &vec![0; n])?;
        slots.records.resize(device, RECORD * SLOTS * n)?;
        slots.record_index.resize(device, SLOTS * n)?;
        Ok(slots)
    }

    /// Makes room for `n` particles, the first of them already here keeping their
    /// contacts and springs, the new ones without any.
    pub fn grow(&mut self, device: &mut dyn Device, n: usize) -> Result<(), DeviceError> {
        // The last evaluation's slots are the next one's history; the others are
        // written whole by every evaluation.
        self.new.count.grow_zeroed(device, n)?;
        self.new.keys.grow_zeroed(device, KEY * SLOTS * n)?;
        self.new
            .history
            .grow_zeroed(device, self.width * SLOTS * n)?;
        self.old.count.resize(device, n)?;
        self.old.keys.resize(device, KEY * SLOTS * n)?;
        self.old.history.resize(device, self.width * SLOTS * n)?;
        self.records.resize(device, RECORD * SLOTS * n)?;
        self.record_index.resize(device, SLOTS * n)
    }

    /// Doubles of a contact's history.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Makes the last evaluation's contacts the history of the next.
    pub fn turn(&mut self) {
        std::mem::swap(&mut self.old, &mut self.new);
    }

    /// Bytes of device memory held.
    pub fn bytes(&self, device: &dyn Device) -> usize {
        [&self.old, &self.new]
            .iter()
            .map(|s| s.count.bytes(device) + s.keys.bytes(device) + s.history.bytes(device))
            .sum::<usize>()
            + self.records.bytes(device)
            + self.record_index.bytes(device)
    }

    /// The launch arguments of the step before's slots (count, keys, histories)
    /// and this step's (count, keys, histories, records, record indices).
    pub(super) fn args(&self) -> [Arg; 8] {
        let (old, new) = (&self.old, &self.new);
        [
            old.count.arg(),
            old.keys.arg(),
            old.history.arg(),
            new.count.arg(),
            new.keys.arg(),
            new.history.arg(),
            self.records.arg(),
            self.record_index.arg(),
        ]
    }

    /// Sets the contacts' histories (sorted by key) as those of the last
    /// evaluation, for particles of `ids` (ascending; a key of another particle is
    /// left out).
    pub fn set_history(
        &mut self,
        device: &mut dyn Device,
        ids: &[u64],
        history: &[(WallKey, TangentialHistory)],
    ) -> Result<(), DeviceError> {
        let (n, width) = (ids.len(), self.width);
        let mut count = vec![0u32; n];
        let mut keys = vec![0i64; KEY * SLOTS * n];
        let mut springs = vec![0.0; width * SLOTS * n];
        for ((id, wall, plane), h) in history {
            let Ok(i) = ids.binary_search(id) else {
                continue;
            };
            let s = count[i] as usize;
            if s == SLOTS {
                return Err(too_many_wall_contacts());
            }
            let slot = SLOTS * i + s;
            keys[KEY * slot] = *wall as i64;
            keys[KEY * slot + 1..KEY * slot + KEY].copy_from_slice(plane);
            springs[width * slot..width * (slot + 1)].copy_from_slice(&history_row(h)[..width]);
            count[i] += 1;
        }
        self.new.count.write(device, &count)?;
        self.new.keys.write(device, &keys)?;
        self.new.history.write(device, &springs)
    }

    /// Wall contacts at the last evaluation.
    pub fn contact_count(&self, device: &dyn Device) -> Result<usize, DeviceError> {
        let count = self.new.count.read(device)?;
        Ok(count.iter().map(|&c| c as usize).sum())
    }

    /// The contacts of the last evaluation, each particle's in its order.
    pub fn contacts(
        &self,
        device: &dyn Device,
    ) -> Result<Vec<Vec<WallContactResult>>, DeviceError> {
        let (count, keys) = (self.new.count.read(device)?, self.new.keys.read(device)?);
        let (history, records) = (self.new.history.read(device)?, self.records.read(device)?);
        let v = |r: &[Real], k: usize| Vector3::new(r[k], r[k + 1], r[k + 2]);
        let width = self.width;
        let contact = |slot: usize| {
            let r = &records[RECORD * slot..RECORD * (slot + 1)];
            let h = &history[width * slot..width * (slot + 1)];
            WallContactResult {
                wall: keys[KEY * slot] as u32,
                key: keys[KEY * slot + 1..KEY * slot + KEY]
                    .try_into()
                    .expect("four words"),
                force: v(r, 0),
                torque: v(r, 3),
                energy: r[7],
                dissipated: r[8],
                history: history_of(h),
            }
        };
        Ok((count.iter().enumerate())
            .map(|(i, &c)| (0..c as usize).map(|s| contact(SLOTS * i + s)).collect())
            .collect())
    }

    /// The contacts' histories by key, for particles of `ids`, sorted (empty
    /// histories left out).
    pub fn history(
        &self,
        device: &dyn Device,
        ids: &[u64],
    ) -> Result<Vec<(WallKey, TangentialHistory)>, DeviceError> {
        let mut out: Vec<_> = (self.contacts(device)?.into_iter().enumerate())
            .flat_map(|(i, contacts)| {
                contacts
                    .into_iter()
                    .map(move |c| ((ids[i], c.wall, c.key), c.history))
            })
            .filter(|(_, h)| !h.is_empty())
            .collect();
        out.sort_by_key(|e| e.0);
        Ok(out)
    }

    /// Launches the energy terms of `n` particles' wall contacts into records
    /// `first..first + n` of `terms` (`device_sums.rs`).
    pub fn energy_terms(
        &self,
        device: &mut dyn Device,
        n: usize,
        terms: &Array<Real>,
        first: usize,
    ) -> Result<(), DeviceError> {
        // SAFETY: the parameters of wall_energy_terms (walls.cu); the slots hold n
        // particles', `terms` room for records up to first + n.
        unsafe {
            run(
                device,
                Kernel::WallEnergyTerms,
                n,
                &[
                    Arg::U32(n as u32),
                    self.new.count.arg(),
                    self.new.keys.arg(),
                    self.records.arg(),
                    self.old.count.arg(),
                    self.old.keys.arg(),
                    self.old.history.arg(),
                    Arg::U32(self.width as u32),
                    Arg::U32(first as u32),
                    terms.arg(),
                ],
            )
        }
    }
}
