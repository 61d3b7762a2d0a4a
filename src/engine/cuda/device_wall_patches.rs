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
use super::device_volume_contacts::{DeviceBodyTypes, DeviceStates};
use crate::Real;
use crate::contact::TangentialHistory;
use crate::world::World;

/// Patches a particle may have against all walls at once (`WALL_SLOTS` of
/// triangle.cuh: the slots of the spheres' wall contacts).
pub const PATCH_SLOTS: usize = super::device_walls::SLOTS;
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

/// The walls' facets as placed in the world, and the patches last found.
#[derive(Debug, Default)]
pub struct DeviceWallPatches {
    walls: u32,
    /// Per wall its first facet, and after the last wall the facet count.
    wall_facets: Array<u32>,
    /// Per facet its triangle (9 doubles) and unit normal (3).
    facets: Array<Real>,
    normals: Array<Real>,
    /// Per wall its material, and its velocity, angular velocity and reference
    /// point (9 doubles).
    wall_material: Array<u32>,
    wall_motion: Array<Real>,
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
    /// Uploads the facets of `world`'s walls as placed at their poses now, with the
    /// normals the CPU's wall stage computes, and the walls' materials and motions.
    pub fn place_walls(
        &mut self,
        device: &mut dyn Device,
        world: &World,
    ) -> Result<(), DeviceError> {
        let (mut starts, mut facets, mut normals) = (vec![0u32], Vec::new(), Vec::new());
        let (mut material, mut motion) = (Vec::new(), Vec::new());
        for wall in &world.walls {
            material.push(wall.material as u32);
            motion.extend(wall.velocity.iter().chain(&wall.angular_velocity));
            motion.extend(wall.reference().coords.iter());
            for f in 0..wall.triangles.len() {
                let t = wall.facet_world(f);
                let n = (t[1] - t[0]).cross(&(t[2] - t[0])).normalize();
                facets.extend(t.iter().flat_map(|p| p.coords.iter().copied()));
                normals.extend(n.iter());
            }
            starts.push((facets.len() / 9) as u32);
        }
        self.walls = world.walls.len() as u32;
        self.wall_facets.write(device, &starts)?;
        self.facets.write(device, &facets)?;
        self.normals.write(device, &normals)?;
        self.wall_material.write(device, &material)?;
        self.wall_motion.write(device, &motion)
    }

    /// Finds every particle's patches against the walls placed (see the module).
    pub fn find(
        &mut self,
        device: &mut dyn Device,
        types: &DeviceBodyTypes,
        states: &DeviceStates,
    ) -> Result<(), DeviceError> {
        let n = states.body_type.len();
        let slots = PATCH_SLOTS * n;
        self.count.resize(device, n)?;
        self.wall.resize(device, slots)?;
        self.keys.resize(device, 4 * slots)?;
        self.geometry.resize(device, PATCH * slots)?;
        self.shares.resize(device, slots)?;
        self.share_facet.resize(device, SHARE_SLOTS * slots)?;
        self.share_volume.resize(device, SHARE_SLOTS * slots)?;
        self.overflow.write(device, &[0])?;
        if n == 0 {
            return Ok(());
        }
        let mut args = vec![
            Arg::U32(n as u32),
            states.position.arg(),
            states.orientation.arg(),
            states.body_type.arg(),
            types.shape.arg(),
        ];
        args.extend(types.shapes.args());
        args.extend([
            Arg::U32(self.walls),
            self.wall_facets.arg(),
            self.facets.arg(),
            self.normals.arg(),
            self.count.arg(),
            self.wall.arg(),
            self.keys.arg(),
            self.geometry.arg(),
            self.shares.arg(),
            self.share_facet.arg(),
            self.share_volume.arg(),
            self.overflow.arg(),
        ]);
        // SAFETY: the arrays sized above for `n` particles, the states' and the
        // body types' invariants, the walls placed.
        unsafe { device.launch(Kernel::PolyhedronWallPatches, n, &args)? };
        if self.overflow.get(device, 0)? != 0 {
            return Err(DeviceError::Capacity(format!(
                "polyhedron touching walls in more than {PATCH_SLOTS} planes at once, or over \
                 more than {SHARE_SLOTS} facets of one plane"
            )));
        }
        Ok(())
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

/// Doubles of a wall contact's result (`WALL_RESULT_DOUBLES` of polyhedra.cu).
const WALL_RESULT: usize = 8;
/// Doubles of a contact's history (`VOLUME_HISTORY_DOUBLES`).
const HISTORY: usize = 5;

/// One wall contact of a polyhedron: what its patch puts on the particle.
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
    /// The friction spring and twist it keeps.
    pub history: TangentialHistory,
}

/// The volume law's contacts of the polyhedra's wall patches on a device, with
/// each particle's friction springs of the step before (by wall and plane key) and
/// of this step, in [`PATCH_SLOTS`] slots a particle.
#[derive(Debug, Default)]
pub struct PolyhedronWallContacts {
    old_count: Array<u32>,
    old_keys: Array<i64>,
    old_history: Array<Real>,
    count: Array<u32>,
    keys: Array<i64>,
    history: Array<Real>,
    results: Array<Real>,
}

impl PolyhedronWallContacts {
    /// Sets each particle's springs of the step before: `(wall, key, history)`,
    /// at most [`PATCH_SLOTS`] a particle.
    ///
    /// # Panics
    /// When a particle holds more than [`PATCH_SLOTS`] springs.
    pub fn set_history(
        &mut self,
        device: &mut dyn Device,
        held: &[Vec<(u32, [i64; 4], TangentialHistory)>],
    ) -> Result<(), DeviceError> {
        let slots = PATCH_SLOTS * held.len();
        let (mut count, mut keys, mut history) =
            (Vec::new(), vec![0; 5 * slots], vec![0.0; HISTORY * slots]);
        for (i, springs) in held.iter().enumerate() {
            assert!(springs.len() <= PATCH_SLOTS, "a spring a slot");
            count.push(springs.len() as u32);
            for (s, (wall, key, h)) in springs.iter().enumerate() {
                let slot = PATCH_SLOTS * i + s;
                keys[5 * slot] = i64::from(*wall);
                keys[5 * slot + 1..5 * slot + 5].copy_from_slice(key);
                let at = HISTORY * slot;
                history[at..at + 3].copy_from_slice(h.spring.as_slice());
                history[at + 3] = h.stiffness;
                history[at + 4] = h.twist;
            }
        }
        self.old_count.write(device, &count)?;
        self.old_keys.write(device, &keys)?;
        self.old_history.write(device, &history)
    }

    /// Evaluates the contact of every patch `patches` last found, over a step of
    /// `dt` (the springs set by [`Self::set_history`] for the same particles).
    pub fn evaluate(
        &mut self,
        device: &mut dyn Device,
        types: &DeviceBodyTypes,
        states: &DeviceStates,
        patches: &DeviceWallPatches,
        dt: Real,
    ) -> Result<(), DeviceError> {
        let n = states.body_type.len();
        let slots = PATCH_SLOTS * n;
        self.count.resize(device, n)?;
        self.keys.resize(device, 5 * slots)?;
        self.history.resize(device, HISTORY * slots)?;
        self.results.resize(device, WALL_RESULT * slots)?;
        if n == 0 {
            return Ok(());
        }
        let mut args = vec![Arg::U32(n as u32), Arg::F64(dt)];
        args.extend(states.args());
        args.extend(types.law_args());
        args.extend([
            patches.wall_material.arg(),
            patches.wall_motion.arg(),
            patches.count.arg(),
            patches.wall.arg(),
            patches.keys.arg(),
            patches.geometry.arg(),
            self.old_count.arg(),
            self.old_keys.arg(),
            self.old_history.arg(),
            self.count.arg(),
            self.keys.arg(),
            self.history.arg(),
            self.results.arg(),
        ]);
        // SAFETY: every array sized for `n` particles and their slots: the
        // patches found for the same states, the springs set for them.
        unsafe { device.launch(Kernel::PolyhedronWallContacts, n, &args) }
    }

    /// Each particle's wall contacts as last evaluated.
    pub fn results(&self, device: &dyn Device) -> Result<Vec<Vec<WallContactResult>>, DeviceError> {
        let (count, keys) = (self.count.read(device)?, self.keys.read(device)?);
        let (history, results) = (self.history.read(device)?, self.results.read(device)?);
        let v = |r: &[Real], k: usize| Vector3::new(r[k], r[k + 1], r[k + 2]);
        let contact = |slot: usize| {
            let (r, h) = (
                &results[WALL_RESULT * slot..WALL_RESULT * (slot + 1)],
                &history[HISTORY * slot..HISTORY * (slot + 1)],
            );
            WallContactResult {
                wall: keys[5 * slot] as u32,
                key: keys[5 * slot + 1..5 * slot + 5]
                    .try_into()
                    .expect("four words"),
                force: v(r, 0),
                torque: v(r, 3),
                energy: r[6],
                dissipated: r[7],
                history: TangentialHistory {
                    spring: v(h, 0),
                    stiffness: h[3],
                    twist: h[4],
                    ..Default::default()
                },
            }
        };
        Ok(count
            .iter()
            .enumerate()
            .map(|(i, &c)| {
                (0..c as usize)
                    .map(|s| contact(PATCH_SLOTS * i + s))
                    .collect()
            })
            .collect())
    }
}
