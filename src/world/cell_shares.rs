//! Each particle's volume split among the cells of the fluid's grid: what makes the
//! solid volume fraction of a cell and the weights with which a particle reads the
//! fluid's velocity and gives back its drag.

use rayon::prelude::*;

use super::{BodyType, Particles};
use crate::Real;
use crate::fluid::FluidGrid;
use crate::geometry::Pose;

/// Per particle, the cells it reaches and its volume in each.
///
/// # Invariant
/// `starts` has one entry per particle plus one; particle `i`'s cells are
/// `cells[starts[i]..starts[i + 1]]`, ascending, each with a positive volume; `ids`
/// holds the id of the particle each row was computed for (a row whose id no longer
/// matches the particle at that index is stale and not used).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CellShares {
    starts: Vec<u32>,
    cells: Vec<u32>,
    volumes: Vec<Real>,
    ids: Vec<u64>,
}

impl CellShares {
    /// The shares of the owned particles on `grid`.
    pub fn compute(grid: &FluidGrid, particles: &Particles, types: &[BodyType]) -> Self {
        let n = particles.owned();
        let rows: Vec<Vec<(u32, Real)>> = (0..n)
            .into_par_iter()
            .with_min_len(64)
            .map(|i| {
                let pose = Pose::from_parts(
                    particles.position[i].coords.into(),
                    particles.orientation[i],
                );
                grid.shares(&types[particles.body_type[i] as usize].shape, &pose)
            })
            .collect();
        let mut shares = CellShares {
            starts: Vec::with_capacity(n + 1),
            ids: particles.id[..n].to_vec(),
            ..Default::default()
        };
        shares.starts.push(0);
        for row in rows {
            for (c, v) in row {
                shares.cells.push(c);
                shares.volumes.push(v);
            }
            shares.starts.push(shares.cells.len() as u32);
        }
        shares
    }

    /// Rebuilds shares from their parts (a saved state), checking the invariant
    /// against a grid of `cells` cells.
    pub fn from_parts(
        starts: Vec<u32>,
        cells: Vec<u32>,
        volumes: Vec<Real>,
        ids: Vec<u64>,
        grid_cells: usize,
    ) -> Result<Self, String> {
        let ok = starts.len() == ids.len() + 1
            && starts.first() == Some(&0)
            && starts.windows(2).all(|w| w[0] <= w[1])
            && *starts.last().unwrap() as usize == cells.len()
            && cells.len() == volumes.len()
            && cells.iter().all(|&c| (c as usize) < grid_cells)
            && starts.windows(2).all(|w| {
                cells[w[0] as usize..w[1] as usize]
                    .windows(2)
                    .all(|c| c[0] < c[1])
            })
            && volumes.iter().all(|&v| v > 0.0 && v.is_finite());
        if !ok {
            return Err("fluid cell shares are inconsistent".into());
        }
        Ok(CellShares {
            starts,
            cells,
            volumes,
            ids,
        })
    }

    /// The parts (for a saved state): starts, cells, volumes, ids.
    pub fn parts(&self) -> (&[u32], &[u32], &[Real], &[u64]) {
        (&self.starts, &self.cells, &self.volumes, &self.ids)
    }

    /// Particle `i`'s cells and its volume in each, if its row is up to date for the
    /// particle of `id`.
    pub fn of(&self, i: usize, id: u64) -> Option<(&[u32], &[Real])> {
        if self.ids.get(i) != Some(&id) {
            return None;
        }
        let r = self.starts[i] as usize..self.starts[i + 1] as usize;
        Some((&self.cells[r.clone()], &self.volumes[r]))
    }

    /// Rows (particles) held.
    pub fn len(&self) -> usize {
        self.ids.len()
    }

    /// Whether no rows are held.
    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }
}
