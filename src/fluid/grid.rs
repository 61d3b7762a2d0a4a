//! The fluid's cells as talus sees them: a structured grid, a cylindrical grid
//! about a tube's axis, or cells a coupled code gives by their centres and volumes.
//! Each kind splits a particle's volume among its cells exactly (see its module).

use nalgebra::Point3;

use super::{CartesianGrid, CylindricalGrid, GivenCells};
use crate::Real;
use crate::geometry::{Pose, Shape};

/// The most cells a grid may have.
pub const MAX_CELLS: usize = 50_000_000;

/// Why numbers make no grid.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum GridError {
    /// A corner or base that is not finite.
    #[error("must be finite")]
    NotFinite(&'static str),
    /// A cell edge that is not positive.
    #[error("cell sizes must be positive, got {0:?}")]
    CellSize([Real; 3]),
    /// No cells along an axis, or too many in all.
    #[error("cell counts must be at least 1 and at most {MAX_CELLS} in all, got {0:?}")]
    Counts([usize; 3]),
    /// An axis that is zero or not finite.
    #[error("must be a finite, non-zero vector")]
    Axis,
    /// Radii that are not positive, finite and ascending.
    #[error("radii must be positive, finite and ascending, got {0:?}")]
    Radii(Vec<Real>),
    /// A height that is not positive.
    #[error("must be positive and finite, got {0}")]
    Height(Real),
    /// A cell whose centre is not finite or whose volume is not positive.
    #[error("cell {cell}: {what}")]
    Cell {
        /// The cell's index (from 0).
        cell: usize,
        /// What is wrong.
        what: String,
    },
}

impl GridError {
    /// The `[fluid]` key the error is about.
    pub fn key(&self) -> &'static str {
        match self {
            GridError::NotFinite(key) => key,
            GridError::CellSize(_) => "cell",
            GridError::Counts(_) => "cells",
            GridError::Axis => "axis",
            GridError::Radii(_) => "radii",
            GridError::Height(_) => "height",
            GridError::Cell { .. } => "file",
        }
    }
}

/// The fluid's cells.
///
/// # Invariant
/// Every per-cell array of the coupling has one entry per cell, in the grid's flat
/// order (see each kind); cells do not overlap, so a particle's shares add up to
/// at most its volume (to its volume when the cells cover it).
#[derive(Clone, Debug, PartialEq)]
pub enum FluidGrid {
    /// Axis-aligned cells of one size.
    Cartesian(CartesianGrid),
    /// Annuli × slabs × sectors about a tube's axis.
    Cylindrical(CylindricalGrid),
    /// The Voronoi cells of centres a coupled code gives, with its volumes.
    Given(GivenCells),
}

impl FluidGrid {
    /// Number of cells.
    pub fn len(&self) -> usize {
        match self {
            FluidGrid::Cartesian(g) => g.len(),
            FluidGrid::Cylindrical(g) => g.len(),
            FluidGrid::Given(g) => g.len(),
        }
    }

    /// Whether the grid has no cells (never: each kind has at least one).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The name of the kind, as `[fluid] grid` spells it.
    pub fn kind(&self) -> &'static str {
        match self {
            FluidGrid::Cartesian(_) => "cartesian",
            FluidGrid::Cylindrical(_) => "cylindrical",
            FluidGrid::Given(_) => "cells",
        }
    }

    /// The grid in words (for a run's plan).
    pub fn describe(&self) -> String {
        match self {
            FluidGrid::Cartesian(g) => {
                let ([nx, ny, nz], h) = (g.counts(), g.cell_size());
                format!(
                    "{nx} × {ny} × {nz} cells of {:.4e} × {:.4e} × {:.4e} m",
                    h.x, h.y, h.z
                )
            }
            FluidGrid::Cylindrical(g) => {
                let [nr, nz, nt] = g.counts();
                format!(
                    "cylindrical, {nr} annuli × {nz} slabs × {nt} sectors, radius {:.4e} m, height {:.4e} m",
                    g.radii()[nr - 1],
                    g.heights()[nz]
                )
            }
            FluidGrid::Given(g) => format!("{} cells given by their centres", g.len()),
        }
    }

    /// The structured grid, if the cells are one.
    pub fn as_cartesian(&self) -> Option<&CartesianGrid> {
        match self {
            FluidGrid::Cartesian(g) => Some(g),
            _ => None,
        }
    }

    /// Volume of cell `c`.
    pub fn cell_volume(&self, c: usize) -> Real {
        match self {
            FluidGrid::Cartesian(g) => g.cell_volume(),
            FluidGrid::Cylindrical(g) => g.cell_volume(c),
            FluidGrid::Given(g) => g.cell_volume(c),
        }
    }

    /// A point in the middle of cell `c` (the cell's centre for the structured and
    /// given kinds; mid-radius, mid-angle, mid-height for the cylindrical one).
    pub fn centre(&self, c: usize) -> Point3<Real> {
        match self {
            FluidGrid::Cartesian(g) => g.centre(c),
            FluidGrid::Cylindrical(g) => g.centre(c),
            FluidGrid::Given(g) => g.centre(c),
        }
    }

    /// Flat index of the cell holding `p`, if any.
    pub fn cell_of(&self, p: &Point3<Real>) -> Option<usize> {
        match self {
            FluidGrid::Cartesian(g) => g.cell_of(p),
            FluidGrid::Cylindrical(g) => g.cell_of(p),
            FluidGrid::Given(g) => Some(g.cell_of(p)),
        }
    }

    /// The cells `shape` at `pose` reaches, ascending, with its volume in each
    /// (positive).
    pub fn shares(&self, shape: &Shape, pose: &Pose) -> Vec<(u32, Real)> {
        match self {
            FluidGrid::Cartesian(g) => g.shares(shape, pose),
            FluidGrid::Cylindrical(g) => g.shares(shape, pose),
            FluidGrid::Given(g) => g.shares(shape, pose),
        }
    }
}
