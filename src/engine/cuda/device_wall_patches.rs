//! The patches of polyhedra against walls on a device (`kernels/wall_patches.cuh`,
//! `polyhedron_wall_patches` of `kernels/polyhedra.cu`): one thread per particle
//! finds, wall by wall, the facets it lies over, their overlaps with it, and sums
//! them by plane into patches, each with its facets' shares, as the CPU backend's
//! wall stage does for a polyhedron (`engine/cpu/walls.rs`, `engine/cpu/patch.rs`);
//! [`PolyhedronWallContacts`] then evaluates each patch's contact under the volume
//! law (`polyhedron_wall_contacts`, `kernels/volume_law.cuh`) with the friction
//! spring its wall and plane key held the step before.

use nalgebra::{Point3, Vector3};

use super::Kernel;
use super::device::{Arg, Array, Device, DeviceError};
use super::device_body_types::DeviceBodyTypes;
use super::device_states::StateView;
use super::device_wall_placement::PlacedWalls;
use super::device_wall_slots::WallSlots;
use crate::Real;

/// Patches a particle may have against all walls at once (`WALL_SLOTS` of
/// triangle.cuh: the slots of its wall contacts).
pub const PATCH_SLOTS: usize = super::device_wall_slots::SLOTS;
/// Facets one patch may sum (`SHARE_SLOTS`).
pub const SHARE_SLOTS: usize = 16;
/// Doubles of a patch's geometry (`PATCH_DOUBLES`).
const PATCH: usize = 12;

/// One patch of a particle against a wall: the facets of one plane it overlaps,
/// their overlaps summed.
#[derive(Clone, Debug, PartialEq)]
pub struct WallPatch {
    /// The wall's index.
    pub wall: u32,
    /// The plane's key (`engine/cpu/patch.rs`, `FacetPlane::key`).
    pub key: [i64; 4],
    pub volume: Real,
    /// The volumes' centroid.
    pub point: Point3<Real>,
    /// Unit normal out of the wall (the force on the particle acts along it).
    pub normal: Vector3<Real>,
    pub area: Real,
    pub depth: Real,
    /// Derivative of the volume with respect to turning the particle.
    pub rotation_gradient: Vector3<Real>,
    /// The facets (index within the wall) with their volumes, in facet order.
    pub shares: Vec<(u32, Real)>,
}

/// The patches of each particle against the walls, as last found.
#[derive(Debug, Default)]
pub struct DeviceWallPatches {
    count: Array<u32>,
    wall: Array<u32>,
    keys: Array<i64>,
    geometry: Array<Real>,
    shares: Array<u32>,
    share_facet: Array<u32>,
    share_volume: Array<Real>,
    overflow: Array<u32>,
}

impl DeviceWallPatches {
    /// Finds every particle's patches against the walls placed (see the module),
    /// an error where they do not fit (the tests' call; a stepper launches the
    /// search with its own flag, read with its other figures).
    #[cfg(test)]
    pub(super) fn find(
        &mut self,
        device: &mut dyn Device,
        types: &DeviceBodyTypes,
        states: &StateView,
        walls: &PlacedWalls,
    ) -> Result<(), DeviceError> {
        self.overflow.write(device, &[0])?;
        let overflow = self.overflow.arg();
        // SAFETY: `overflow` holds a word.
        unsafe { self.launch_find(device, types, states, walls, overflow)? };
        if self.overflow.get(device, 0)? != 0 {
            return Err(DeviceError::Capacity(format!(
                "polyhedron touching walls in more than {PATCH_SLOTS} planes at once, or over \
                 more than {SHARE_SLOTS} facets of one plane"
            )));
        }
        Ok(())
    }

    /// Launches the search of [`Self::find`], the word `overflow` set where a
    /// particle's patches do not fit.
    ///
    /// # Safety
    /// `overflow` is a device word.
    pub(super) unsafe fn launch_find(
        &mut self,
        device: &mut dyn Device,
        types: &DeviceBodyTypes,
        states: &StateView,
        walls: &PlacedWalls,
        overflow: Arg,
    ) -> Result<(), DeviceError> {
        let n = states.len();
        let slots = PATCH_SLOTS * n;
        self.count.resize(device, n)?;
        self.wall.resize(device, slots)?;
        self.keys.resize(device, 4 * slots)?;
        self.geometry.resize(device, PATCH * slots)?;
        self.shares.resize(device, slots)?;
        self.share_facet.resize(device, SHARE_SLOTS * slots)?;
        self.share_volume.resize(device, SHARE_SLOTS * slots)?;
        if n == 0 {
            return Ok(());
        }
        let mut args = vec![
            Arg::U32(n as u32),
            states.position.arg(),
            states.orientation.arg(),
            states.body_type.arg(),
            states.role.arg(),
            types.shape.arg(),
        ];
        args.extend(types.shapes.args());
        args.extend([walls.count_arg(), walls.wall_facets.arg()]);
        args.extend(walls.facet_args());
        args.extend([
            self.count.arg(),
            self.wall.arg(),
            self.keys.arg(),
            self.geometry.arg(),
            self.shares.arg(),
            self.share_facet.arg(),
            self.share_volume.arg(),
            overflow,
        ]);
        // SAFETY: the arrays sized above for `n` particles, the states' and the
        // body types' invariants, the walls placed, the caller's overflow word.
        unsafe { device.launch(Kernel::PolyhedronWallPatches, n, &args) }
    }

    /// Bytes of device memory held.
    pub fn bytes(&self, device: &dyn Device) -> usize {
        let words = [&self.count, &self.wall, &self.shares, &self.share_facet];
        words.iter().map(|a| a.bytes(device)).sum::<usize>()
            + self.keys.bytes(device)
            + self.geometry.bytes(device)
            + self.share_volume.bytes(device)
            + self.overflow.bytes(device)
    }

    /// Each particle's patches as last found, in wall order.
    pub fn patches(&self, device: &dyn Device) -> Result<Vec<Vec<WallPatch>>, DeviceError> {
        let (count, wall, keys) = (
            self.count.read(device)?,
            self.wall.read(device)?,
            self.keys.read(device)?,
        );
        let (geometry, shares) = (self.geometry.read(device)?, self.shares.read(device)?);
        let (facet, volume) = (
            self.share_facet.read(device)?,
            self.share_volume.read(device)?,
        );
        let v = |g: &[Real], k: usize| Vector3::new(g[k], g[k + 1], g[k + 2]);
        let patch = |slot: usize| {
            let g = &geometry[PATCH * slot..PATCH * (slot + 1)];
            let first = SHARE_SLOTS * slot;
            let range = first..first + shares[slot] as usize;
            WallPatch {
                wall: wall[slot],
                key: keys[4 * slot..4 * slot + 4].try_into().expect("four words"),
                volume: g[0],
                point: Point3::from(v(g, 1)),
                normal: v(g, 4),
                area: g[7],
                depth: g[8],
                rotation_gradient: v(g, 9),
                shares: facet[range.clone()]
                    .iter()
                    .copied()
                    .zip(volume[range].iter().copied())
                    .collect(),
            }
        };
        Ok(count
            .iter()
            .enumerate()
            .map(|(i, &c)| {
                (0..c as usize)
                    .map(|s| patch(PATCH_SLOTS * i + s))
                    .collect()
            })
            .collect())
    }
}

/// What the wall contacts add to: each particle's force and torque (the pairs'
/// gathered) and whether it touches.
pub(super) struct Loads<'a> {
    pub force: &'a Array<Real>,
    pub torque: &'a Array<Real>,
    pub touching: &'a Array<u8>,
}

/// Evaluates the contact of every patch `patches` last found (for the same
/// states and walls) over a step of `dt`, each with the spring its wall and plane
/// key held in the step before's slots, into this step's `slots`, and adds it to
/// the particle's load (`polyhedron_wall_contacts` of polyhedra.cu).
#[allow(clippy::too_many_arguments)]
pub(super) fn polyhedron_wall_contacts(
    device: &mut dyn Device,
    types: &DeviceBodyTypes,
    states: &StateView,
    walls: &PlacedWalls,
    patches: &DeviceWallPatches,
    slots: &WallSlots,
    loads: &Loads,
    dt: Real,
) -> Result<(), DeviceError> {
    let n = states.len();
    if n == 0 {
        return Ok(());
    }
    let mut args = vec![Arg::U32(n as u32), Arg::F64(dt)];
    args.extend(states.args());
    args.extend(types.law_args());
    args.extend([
        walls.material.arg(),
        walls.motion.arg(),
        patches.count.arg(),
        patches.wall.arg(),
        patches.keys.arg(),
        patches.geometry.arg(),
        patches.shares.arg(),
        patches.share_volume.arg(),
        Arg::U32(slots.width() as u32),
    ]);
    args.extend(slots.args());
    args.extend([loads.force.arg(), loads.torque.arg(), loads.touching.arg()]);
    // SAFETY: every array sized for `n` particles and their slots: the patches
    // found for the same states and walls, the slots made for as many particles.
    unsafe { device.launch(Kernel::PolyhedronWallContacts, n, &args) }
}

/// What the walls' sums of a world of polyhedra read: the particles' positions and
/// body types, each body type's shape (`NO_SHAPE`: a sphere), the walls, the
/// patches and the contacts' slots, all of the same particles.
pub(super) struct PolyhedronSums<'a> {
    pub states: &'a StateView<'a>,
    pub shape: &'a Array<u32>,
    pub walls: &'a PlacedWalls,
    pub patches: &'a DeviceWallPatches,
    pub slots: &'a WallSlots,
}

/// Launches the first pass of the walls' sums of a world of polyhedra (spheres
/// among them or not) into `rows` rows (`polyhedron_wall_sum_rows` of
/// polyhedra.cu).
///
/// # Safety
/// `partials` has room for `rows` rows of the walls' width (6 per wall, 3 per
/// facet); the slots and patches hold the same particles' as the states.
pub(super) unsafe fn polyhedron_wall_sum_rows(
    device: &mut dyn Device,
    at: &PolyhedronSums,
    rows: usize,
    partials: &Array<Real>,
) -> Result<(), DeviceError> {
    let (walls, patches, slots) = (at.walls, at.patches, at.slots);
    let args = [
        Arg::U32(at.states.len() as u32),
        at.states.position.arg(),
        at.states.body_type.arg(),
        at.shape.arg(),
        walls.count_arg(),
        walls.wall_facets.arg(),
        walls.motion.arg(),
        slots.new.count.arg(),
        slots.new.keys.arg(),
        slots.records.arg(),
        slots.record_index.arg(),
        patches.shares.arg(),
        patches.share_facet.arg(),
        patches.share_volume.arg(),
        Arg::U32(rows as u32),
        partials.arg(),
    ];
    // SAFETY: the caller's promise.
    unsafe { device.launch(Kernel::PolyhedronWallSumRows, rows, &args) }
}
