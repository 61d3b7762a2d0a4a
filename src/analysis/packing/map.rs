//! The porosity and specific surface on the cells of a cylindrical grid about the
//! tube's axis: the radial and axial profiles at once, as the cell values a 2-D (or
//! 3-D) reactor model reads. The grid is the scene's cylindrical `[fluid]` grid when
//! it has one, else the analysis's radial bins × axial slices over the whole tube
//! (one sector). Each particle's volume is split among the cells as the fluid
//! coupling splits it ([`CylindricalGrid::shares`]).

use rayon::prelude::*;

use super::{Bed, Packing};
use crate::Real;
use crate::fluid::{CylindricalGrid, FluidGrid};
use crate::geometry::Pose;
use crate::world::World;

/// Porosity and specific surface per cell of a cylindrical grid.
///
/// # Invariant
/// `porosity` and `specific_surface` have one entry per cell of `grid`, in its flat
/// order (annulus fastest, then slab, then sector).
#[derive(Clone, Debug)]
pub struct PorosityMap {
    /// The cells.
    pub grid: CylindricalGrid,
    /// 1 − solid volume / cell volume.
    pub porosity: Vec<Real>,
    /// Particle surface in the cell / cell volume, 1/m.
    pub specific_surface: Vec<Real>,
}

/// The map of the bed in `world` on the cylindrical `[fluid]` grid of `world`, or
/// on the radial bins and axial slices of `packing` (the analysis of that bed).
pub fn porosity_map(world: &World, bed: &Bed, packing: &Packing) -> Result<PorosityMap, String> {
    let grid = match world.fluid.as_ref().map(|f| &f.grid) {
        Some(FluidGrid::Cylindrical(g)) => g.clone(),
        _ => default_grid(bed, packing)?,
    };
    let ratio: Vec<Real> = world
        .body_types
        .iter()
        .map(|t| t.shape.surface_area() / t.shape.volume())
        .collect();
    let p = &world.particles;
    let rows: Vec<Vec<(u32, Real)>> = (0..p.len())
        .into_par_iter()
        .map(|i| {
            let pose = Pose::from_parts(p.position[i].coords.into(), p.orientation[i]);
            grid.shares(&world.body_types[p.body_type[i] as usize].shape, &pose)
        })
        .collect();
    let (mut solid, mut surface) = (vec![0.0; grid.len()], vec![0.0; grid.len()]);
    for (i, row) in rows.iter().enumerate() {
        for &(c, v) in row {
            solid[c as usize] += v;
            surface[c as usize] += v * ratio[p.body_type[i] as usize];
        }
    }
    let volume = |c: usize| grid.cell_volume(c);
    Ok(PorosityMap {
        porosity: (0..grid.len())
            .map(|c| 1.0 - solid[c] / volume(c))
            .collect(),
        specific_surface: (0..grid.len()).map(|c| surface[c] / volume(c)).collect(),
        grid,
    })
}

/// The radial bins × axial slices of `packing` (from the base to the top of the
/// highest particle), one sector.
fn default_grid(bed: &Bed, packing: &Packing) -> Result<CylindricalGrid, String> {
    let height = packing.axial.last().map_or(0.0, |s| s.z_upper);
    CylindricalGrid::new(
        bed.tube.base,
        bed.tube.axis,
        packing.radial.iter().map(|b| b.r_outer).collect(),
        height,
        packing.axial.len(),
        1,
    )
    .map_err(|e| e.to_string())
}
