//! The walls' facet grids on a device (`kernels/facet_grid.cuh`): each wall's
//! [`FacetGrid`], built once in the wall's own frame as the CPU backend uses it,
//! and the frame's pose in the world, so that the wall kernels test a particle
//! against the facets near it and a moving wall uploads seven numbers, not a grid.

use super::device::{Arg, Array, Device, DeviceError};
use crate::Real;
use crate::world::{FacetGrid, Wall};

/// Doubles per wall: the frame's translation (3) and rotation (i, j, k, w), the
/// grid's origin (3) and cell edge (`GRID_FRAME_DOUBLES` of facet_grid.cuh).
const FRAME: usize = 11;

/// The walls' facet grids on a device.
///
/// # Invariant
/// Per wall, `frame` holds the pose last given to [`Self::place`] (zeros until
/// then) and the grid's origin and cell; `head` its cells along each axis and where its cell starts and
/// entries begin in `starts` and `entries`, which hold each wall's
/// [`FacetGrid::cell_starts`] and [`FacetGrid::entries`] one wall's after the other's.
#[derive(Debug, Default)]
pub struct DeviceFacetGrids {
    frame: Array<Real>,
    head: Array<u32>,
    starts: Array<u32>,
    entries: Array<u32>,
}

impl DeviceFacetGrids {
    /// The grids of `walls`, each to be placed ([`Self::place`]) before a kernel
    /// reads it.
    pub fn new(device: &mut dyn Device, walls: &[Wall]) -> Result<Self, DeviceError> {
        let (mut head, mut starts, mut entries) = (Vec::new(), Vec::new(), Vec::new());
        for wall in walls {
            let grid = &wall.grid;
            head.extend(grid.dims().map(|d| d as u32));
            head.extend([starts.len() as u32, entries.len() as u32]);
            starts.extend_from_slice(grid.cell_starts());
            entries.extend_from_slice(grid.entries());
        }
        let mut grids = DeviceFacetGrids::default();
        grids.frame.resize(device, FRAME * walls.len())?;
        grids.head.write(device, &head)?;
        grids.starts.write(device, &starts)?;
        grids.entries.write(device, &entries)?;
        Ok(grids)
    }

    /// Uploads wall `w`'s frame at its pose now (the same wall as at [`Self::new`]).
    pub fn place(
        &mut self,
        device: &mut dyn Device,
        w: usize,
        wall: &Wall,
    ) -> Result<(), DeviceError> {
        self.frame.write_at(device, FRAME * w, &frame_row(wall))
    }

    /// The grids as launch arguments: frames, heads, cell starts, entries.
    pub fn args(&self) -> [Arg; 4] {
        [
            self.frame.arg(),
            self.head.arg(),
            self.starts.arg(),
            self.entries.arg(),
        ]
    }

    /// Bytes of device memory held.
    pub fn bytes(&self, device: &dyn Device) -> usize {
        self.frame.bytes(device)
            + self.head.bytes(device)
            + self.starts.bytes(device)
            + self.entries.bytes(device)
    }
}

/// A wall's row of `frame`.
fn frame_row(wall: &Wall) -> [Real; FRAME] {
    let grid: &FacetGrid = &wall.grid;
    let (t, q, o) = (
        wall.pose.translation.vector,
        wall.pose.rotation.coords,
        grid.origin(),
    );
    [
        t.x,
        t.y,
        t.z,
        q.x,
        q.y,
        q.z,
        q.w,
        o.x,
        o.y,
        o.z,
        grid.cell(),
    ]
}
