//! The walls as the device's wall kernels read them (`kernels/walls.cu`,
//! `kernels/polyhedra.cu`): every wall's facets placed in the world, one wall's
//! after the other's, with their unit normals, the walls' facet grids, and per
//! wall its material and motion.

use nalgebra::Isometry3;

use super::device::{Arg, Array, Device, DeviceError};
use super::device_facet_grids::DeviceFacetGrids;
use crate::Real;
use crate::geometry::wall::facet_normal;
use crate::world::Wall;

/// Walls placed on a device.
///
/// # Invariant
/// `wall_facets` holds each wall's first facet and, last, the facet count; `facets`
/// and `normals` hold the facets of the walls as they stood at the poses in
/// `placed` (corners, 9 doubles, and unit normals, 3, by the CPU backend's
/// operations), and `grids` the walls' facet grids placed at the same poses;
/// `motion` the walls' velocities, angular velocities and reference
/// points as last updated.
#[derive(Debug, Default)]
pub struct PlacedWalls {
    /// The pose each wall's facets were placed at.
    placed: Vec<Option<Isometry3<Real>>>,
    pub(super) wall_facets: Array<u32>,
    pub(super) facets: Array<Real>,
    pub(super) normals: Array<Real>,
    pub(super) grids: DeviceFacetGrids,
    pub(super) material: Array<u32>,
    /// Per wall: velocity, angular velocity, reference point (9 doubles).
    pub(super) motion: Array<Real>,
}

impl PlacedWalls {
    /// `walls` placed on `device` at their poses now.
    pub fn new(device: &mut dyn Device, walls: &[Wall]) -> Result<Self, DeviceError> {
        let mut starts = vec![0u32];
        for wall in walls {
            starts.push(starts[starts.len() - 1] + wall.triangles.len() as u32);
        }
        let facets = starts[walls.len()] as usize;
        let mut placed = PlacedWalls {
            placed: vec![None; walls.len()],
            grids: DeviceFacetGrids::new(device, walls)?,
            ..Default::default()
        };
        placed.wall_facets.write(device, &starts)?;
        let materials: Vec<u32> = walls.iter().map(|w| w.material as u32).collect();
        placed.material.write(device, &materials)?;
        placed.facets.resize(device, 9 * facets)?;
        placed.normals.resize(device, 3 * facets)?;
        placed.update(device, walls)?;
        Ok(placed)
    }

    /// The placed facets as launch arguments: corners, normals and the grids'
    /// four arrays (`facets`, `facet_normals`, `grid_*` of the wall kernels).
    pub(super) fn facet_args(&self) -> impl Iterator<Item = Arg> + '_ {
        [self.facets.arg(), self.normals.arg()]
            .into_iter()
            .chain(self.grids.args())
    }

    /// Bytes of device memory held.
    pub fn bytes(&self, device: &dyn Device) -> usize {
        let doubles = [&self.facets, &self.normals, &self.motion];
        let words = [&self.wall_facets, &self.material];
        doubles.iter().map(|a| a.bytes(device)).sum::<usize>()
            + words.iter().map(|a| a.bytes(device)).sum::<usize>()
            + self.grids.bytes(device)
    }

    /// The number of walls as a launch argument.
    pub(super) fn count_arg(&self) -> Arg {
        Arg::U32(self.placed.len() as u32)
    }

    /// Places again the facets and the grid of every wall whose pose changed (the
    /// same walls as at [`Self::new`], moved) and uploads them, and every wall's
    /// velocities and reference point.
    pub fn update(&mut self, device: &mut dyn Device, walls: &[Wall]) -> Result<(), DeviceError> {
        let mut motion = Vec::with_capacity(9 * walls.len());
        let mut first = 0;
        for (w, (wall, placed)) in walls.iter().zip(&mut self.placed).enumerate() {
            motion.extend(wall.velocity.iter().chain(&wall.angular_velocity));
            motion.extend(wall.reference().coords.iter());
            let facets = wall.triangles.len();
            if *placed != Some(wall.pose) {
                *placed = Some(wall.pose);
                let (mut corners, mut normals) = (Vec::new(), Vec::new());
                for f in 0..facets {
                    let t = wall.facet_world(f);
                    corners.extend(t.iter().flat_map(|p| p.coords.iter().copied()));
                    normals.extend(facet_normal(&t).iter());
                }
                self.facets.write_at(device, 9 * first, &corners)?;
                self.normals.write_at(device, 3 * first, &normals)?;
                self.grids.place(device, w, wall)?;
            }
            first += facets;
        }
        self.motion.write(device, &motion)
    }
}
