//! A cylindrical grid about a tube's axis (the grid of 2-D and 3-D reactor codes):
//! annuli out to given radii, equal slabs along the axis and equal angular sectors,
//! and a particle's volume in each cell, integrated along the axis
//! ([`cylinder_cell_volumes`]: exact in each section, adaptive along the axis to
//! 1e-9 of the particle's volume, the shares of a particle adding up to its volume
//! to round-off).

use std::f64::consts::PI;

use nalgebra::{Isometry3, Point3, Vector3};

use super::grid::{GridError, MAX_CELLS};
use crate::Real;
use crate::geometry::axial_volumes::{
    AxialBody, CylinderCells, Sectors, axis_frame, cylinder_cell_volumes,
};
use crate::geometry::{Pose, Shape};

/// Annuli × slabs × sectors in a tube.
///
/// # Invariant
/// `radii` are positive, finite and ascending (annulus `i` from `radii[i − 1]`, or
/// the axis, out to `radii[i]`); `heights` ascend from 0 (the base) in equal steps;
/// at least one sector. Cell `[i, j, k]` (annulus, slab, sector) has the flat index
/// `i + nr (j + nz k)` (radius fastest). Sector `k` spans the angles
/// `2π k / n … 2π (k + 1) / n` from the frame's x axis ([`axis_frame`]).
#[derive(Clone, Debug, PartialEq)]
pub struct CylindricalGrid {
    /// World → tube frame.
    frame: Isometry3<Real>,
    radii: Vec<Real>,
    heights: Vec<Real>,
    sectors: usize,
}

impl CylindricalGrid {
    /// A grid in the tube from `base` along `axis` (any length), of `height`, with
    /// annuli out to `radii`, `axial` slabs and `sectors`; or why the numbers make
    /// none.
    pub fn new(
        base: Point3<Real>,
        axis: Vector3<Real>,
        radii: Vec<Real>,
        height: Real,
        axial: usize,
        sectors: usize,
    ) -> Result<Self, GridError> {
        if !base.coords.iter().all(|x| x.is_finite()) {
            return Err(GridError::NotFinite("base"));
        }
        let length = axis.norm();
        if !(length > 0.0 && length.is_finite()) {
            return Err(GridError::Axis);
        }
        let ascending = radii.first().is_some_and(|&r| r > 0.0)
            && radii.iter().all(|r| r.is_finite())
            && radii.windows(2).all(|w| w[1] > w[0]);
        if !ascending {
            return Err(GridError::Radii(radii));
        }
        if !(height > 0.0 && height.is_finite()) {
            return Err(GridError::Height(height));
        }
        let counts = [radii.len(), axial, sectors];
        if counts.contains(&0) || counts.iter().product::<usize>() > MAX_CELLS {
            return Err(GridError::Counts(counts));
        }
        Ok(CylindricalGrid {
            frame: axis_frame(&base, &(axis / length)),
            heights: (0..=axial)
                .map(|j| height * j as Real / axial as Real)
                .collect(),
            radii,
            sectors,
        })
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.counts().iter().product()
    }

    /// Whether the grid has no cells (never: see the invariant).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Annuli, slabs and sectors.
    pub fn counts(&self) -> [usize; 3] {
        [self.radii.len(), self.heights.len() - 1, self.sectors]
    }

    /// Outer radius of each annulus.
    pub fn radii(&self) -> &[Real] {
        &self.radii
    }

    /// Slab boundaries, from the base along the axis.
    pub fn heights(&self) -> &[Real] {
        &self.heights
    }

    /// Annulus, slab and sector of the cell of flat index `n`.
    pub fn cell(&self, n: usize) -> [usize; 3] {
        let [nr, nz, _] = self.counts();
        [n % nr, (n / nr) % nz, n / (nr * nz)]
    }

    /// Flat index of cell `c`.
    pub fn index(&self, c: [usize; 3]) -> usize {
        let [nr, nz, _] = self.counts();
        c[0] + nr * (c[1] + nz * c[2])
    }

    fn inner(&self, i: usize) -> Real {
        if i == 0 { 0.0 } else { self.radii[i - 1] }
    }

    /// Volume of the cell of flat index `n`.
    pub fn cell_volume(&self, n: usize) -> Real {
        let [i, j, _] = self.cell(n);
        let (r0, r1) = (self.inner(i), self.radii[i]);
        PI * (r1 * r1 - r0 * r0) / self.sectors as Real * (self.heights[j + 1] - self.heights[j])
    }

    /// The point at mid-radius, mid-angle and mid-height of the cell of flat index
    /// `n` (on the axis for the first annulus of one sector).
    pub fn centre(&self, n: usize) -> Point3<Real> {
        let [i, j, k] = self.cell(n);
        let rho = if i == 0 && self.sectors == 1 {
            0.0
        } else {
            0.5 * (self.inner(i) + self.radii[i])
        };
        let angle = 2.0 * PI * (k as Real + 0.5) / self.sectors as Real;
        let z = 0.5 * (self.heights[j] + self.heights[j + 1]);
        self.frame
            .inverse_transform_point(&Point3::new(rho * angle.cos(), rho * angle.sin(), z))
    }

    /// Flat index of the cell holding `p`, if any.
    pub fn cell_of(&self, p: &Point3<Real>) -> Option<usize> {
        let q = self.frame * p;
        let i = self.radii.partition_point(|&r| r <= q.x.hypot(q.y));
        let j = self.heights.partition_point(|&z| z <= q.z);
        if i == self.radii.len() || j == 0 || j == self.heights.len() {
            return None;
        }
        let k = Sectors(self.sectors).containing(q.x, q.y);
        Some(self.index([i, j - 1, k]))
    }

    /// The cells `shape` at `pose` reaches, ascending, with its volume in each.
    pub fn shares(&self, shape: &Shape, pose: &Pose) -> Vec<(u32, Real)> {
        let body = AxialBody::new(shape, &(self.frame * pose));
        let cells = CylinderCells {
            radii: &self.radii,
            heights: &self.heights,
            sectors: Sectors(self.sectors),
        };
        let mut out = Vec::new();
        cylinder_cell_volumes(&body, cells, |c, v| out.push((self.index(c) as u32, v)));
        out.sort_by_key(|x| x.0);
        out
    }
}
