//! The patches of polyhedra against walls on a device (`kernels/wall_patches.cuh`,
//! `polyhedron_wall_patches` of `kernels/polyhedra.cu`): one thread per particle
//! finds, wall by wall, the facets it lies over, their overlaps with it, and sums
//! them by plane into patches, each with its facets' shares, as the CPU backend's
//! wall stage does for a polyhedron (`engine/cpu/walls.rs`, `engine/cpu/patch.rs`).
//! The contact law of a patch is the volume law's (`kernels/volume_law.cuh`).

use nalgebra::{Point3, Vector3};

use super::Kernel;
use super::device::{Arg, Array, Device, DeviceError};
use super::device_volume_contacts::{DeviceBodyTypes, DeviceStates};
use crate::Real;
use crate::world::World;

/// Patches a particle may have against all walls at once (`PATCH_SLOTS` of
/// wall_patches.cuh).
pub const PATCH_SLOTS: usize = 4;
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
    /// Per wall its first facet, then the facet count.
    wall_facets: Array<u32>,
    /// Per facet its triangle (9 doubles) and unit normal (3).
    facets: Array<Real>,
    normals: Array<Real>,
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
    /// normals the CPU's wall stage computes.
    pub fn place_walls(
        &mut self,
        device: &mut dyn Device,
        world: &World,
    ) -> Result<(), DeviceError> {
        let (mut starts, mut facets, mut normals) = (vec![0u32], Vec::new(), Vec::new());
        for wall in &world.walls {
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
        self.normals.write(device, &normals)
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
