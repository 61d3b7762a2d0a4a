//! A structured grid of axis-aligned cells of one size (a finite-volume or lattice
//! Boltzmann code's grid), and a particle's exact volume in each of its cells.

use nalgebra::{Point3, Vector3};

use super::grid::{GridError, MAX_CELLS};
use crate::Real;
use crate::geometry::cell_volumes::{
    CellBounds, placed_faces, polyhedron_cell_volumes, sphere_cell_volumes,
};
use crate::geometry::{Pose, Shape};

/// A structured grid of `counts` cells of size `cell` from `origin`.
///
/// # Invariant
/// Cell sizes are positive and finite, counts at least 1; cell `[i, j, k]` has the
/// flat index `i + nx (j + ny k)` (x fastest), the order of every per-cell array.
#[derive(Clone, Debug, PartialEq)]
pub struct CartesianGrid {
    origin: Point3<Real>,
    cell: Vector3<Real>,
    counts: [usize; 3],
    bounds: [Vec<Real>; 3],
}

impl CartesianGrid {
    /// A grid, or why the numbers make none.
    pub fn new(
        origin: Point3<Real>,
        cell: Vector3<Real>,
        counts: [usize; 3],
    ) -> Result<Self, GridError> {
        if !origin.coords.iter().all(|x| x.is_finite()) {
            return Err(GridError::NotFinite("origin"));
        }
        if !cell.iter().all(|&h| h > 0.0 && h.is_finite()) {
            return Err(GridError::CellSize(cell.into()));
        }
        if counts.contains(&0) || counts.iter().product::<usize>() > MAX_CELLS {
            return Err(GridError::Counts(counts));
        }
        let bounds = std::array::from_fn(|a| {
            (0..=counts[a])
                .map(|k| origin[a] + cell[a] * k as Real)
                .collect()
        });
        Ok(CartesianGrid {
            origin,
            cell,
            counts,
            bounds,
        })
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.counts.iter().product()
    }

    /// Whether the grid has no cells (never: see the invariant).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The lower corner of cell `[0, 0, 0]`.
    pub fn origin(&self) -> Point3<Real> {
        self.origin
    }

    /// Cells along each axis.
    pub fn counts(&self) -> [usize; 3] {
        self.counts
    }

    /// Volume of one cell.
    pub fn cell_volume(&self) -> Real {
        self.cell.product()
    }

    /// Size of a cell along each axis.
    pub fn cell_size(&self) -> Vector3<Real> {
        self.cell
    }

    /// The cell boundaries along each axis.
    pub fn bounds(&self) -> CellBounds<'_> {
        [&self.bounds[0], &self.bounds[1], &self.bounds[2]]
    }

    /// Flat index of cell `c`.
    pub fn index(&self, c: [usize; 3]) -> usize {
        c[0] + self.counts[0] * (c[1] + self.counts[1] * c[2])
    }

    /// Centre of the cell of flat index `n`.
    pub fn centre(&self, n: usize) -> Point3<Real> {
        let c = [
            n % self.counts[0],
            (n / self.counts[0]) % self.counts[1],
            n / (self.counts[0] * self.counts[1]),
        ];
        Point3::from(Vector3::from_fn(|a, _| {
            self.origin[a] + self.cell[a] * (c[a] as Real + 0.5)
        }))
    }

    /// Flat index of the cell holding `p`, if any.
    pub fn cell_of(&self, p: &Point3<Real>) -> Option<usize> {
        let mut c = [0; 3];
        for (a, c) in c.iter_mut().enumerate() {
            let x = ((p[a] - self.origin[a]) / self.cell[a]).floor();
            if !(x >= 0.0 && x < self.counts[a] as Real) {
                return None;
            }
            *c = x as usize;
        }
        Some(self.index(c))
    }

    /// The cells `shape` at `pose` reaches, ascending, with its volume in each.
    pub fn shares(&self, shape: &Shape, pose: &Pose) -> Vec<(u32, Real)> {
        let centre = pose.translation.vector.into();
        let reach = shape.circumradius();
        // Wholly inside one cell: no clipping.
        if let Some(c) = self.cell_of(&centre) {
            let b = self.bounds();
            let inside = (0..3).all(|a| {
                let k = b[a].partition_point(|&x| x <= centre[a]) - 1;
                centre[a] - reach >= b[a][k] && centre[a] + reach <= b[a][k + 1]
            });
            if inside {
                return vec![(c as u32, shape.volume())];
            }
        }
        let mut out = Vec::new();
        let mut push = |c: [usize; 3], v: Real| {
            if v > 0.0 {
                out.push((self.index(c) as u32, v));
            }
        };
        match shape {
            Shape::Sphere(s) => sphere_cell_volumes(centre, s.radius, self.bounds(), &mut push),
            Shape::Polyhedron(p) => {
                polyhedron_cell_volumes(placed_faces(p, pose), self.bounds(), &mut push)
            }
        }
        out.sort_by_key(|x| x.0);
        out
    }
}
