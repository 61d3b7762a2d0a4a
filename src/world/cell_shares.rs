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
/// A row belongs to a particle id, not to an index: it stays the particle's when
/// others are removed or the particle changes rank, until the shares are computed
/// again. A particle inserted since has no row.
///
/// # Invariant
/// `starts` has one entry per row plus one; row `r`'s cells are
/// `cells[starts[r]..starts[r + 1]]`, ascending, each with a positive volume; `ids`
/// holds the particle id of each row, no id twice; `by_id` holds `(id, row)` for
/// every row, sorted by id.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CellShares {
    starts: Vec<u32>,
    cells: Vec<u32>,
    volumes: Vec<Real>,
    ids: Vec<u64>,
    by_id: Vec<(u64, u32)>,
}

/// One particle's row of [`CellShares`]: the cells it reaches and its volume in each.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ShareRow {
    /// Cells, ascending.
    pub cells: Vec<u32>,
    /// The particle's volume in each.
    pub volumes: Vec<Real>,
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
            ..Default::default()
        };
        shares.starts.push(0);
        for (row, &id) in rows.into_iter().zip(&particles.id[..n]) {
            for (c, v) in row {
                shares.cells.push(c);
                shares.volumes.push(v);
            }
            shares.starts.push(shares.cells.len() as u32);
            shares.ids.push(id);
        }
        shares.index();
        shares
    }

    /// Shares of the rows `rows` (particle id, cells, volumes; no id twice), in
    /// that order.
    pub fn from_rows<'a>(rows: impl IntoIterator<Item = (u64, &'a [u32], &'a [Real])>) -> Self {
        let mut shares = CellShares {
            starts: vec![0],
            ..Default::default()
        };
        for (id, cells, volumes) in rows {
            shares.cells.extend_from_slice(cells);
            shares.volumes.extend_from_slice(volumes);
            shares.starts.push(shares.cells.len() as u32);
            shares.ids.push(id);
        }
        shares.index();
        shares
    }

    /// The row of particle `id`, if it has one.
    pub fn row_of(&self, id: u64) -> Option<ShareRow> {
        let r = self.position_of(id)?;
        let (cells, volumes) = self.row(r);
        Some(ShareRow {
            cells: cells.to_vec(),
            volumes: volumes.to_vec(),
        })
    }

    /// Keeps the rows of the particles `ids` (in that order) that have one and
    /// appends `arrived` (rows of particles new to these shares).
    pub fn keep(&self, ids: &[u64], arrived: &[(u64, ShareRow)]) -> Self {
        let kept = ids.iter().filter_map(|&id| {
            let (cells, volumes) = self.row(self.position_of(id)?);
            Some((id, cells, volumes))
        });
        let arrived = arrived
            .iter()
            .map(|(id, row)| (*id, &row.cells[..], &row.volumes[..]));
        Self::from_rows(kept.chain(arrived))
    }

    /// Sorts the id index; ids must be unique.
    fn index(&mut self) {
        self.sort_index();
        debug_assert!(self.by_id.windows(2).all(|w| w[0].0 < w[1].0));
    }

    /// `by_id` from `ids`.
    fn sort_index(&mut self) {
        self.by_id = self
            .ids
            .iter()
            .enumerate()
            .map(|(r, &id)| (id, r as u32))
            .collect();
        self.by_id.sort_unstable();
    }

    fn position_of(&self, id: u64) -> Option<usize> {
        let k = self.by_id.binary_search_by_key(&id, |e| e.0).ok()?;
        Some(self.by_id[k].1 as usize)
    }

    fn row(&self, r: usize) -> (&[u32], &[Real]) {
        let span = self.starts[r] as usize..self.starts[r + 1] as usize;
        (&self.cells[span.clone()], &self.volumes[span])
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
        let mut shares = CellShares {
            starts,
            cells,
            volumes,
            ids,
            by_id: Vec::new(),
        };
        shares.sort_index();
        if let Some(w) = shares.by_id.windows(2).find(|w| w[0].0 == w[1].0) {
            return Err(format!("fluid cell shares hold particle {} twice", w[0].0));
        }
        Ok(shares)
    }

    /// The parts (for a saved state): starts, cells, volumes, ids.
    pub fn parts(&self) -> (&[u32], &[u32], &[Real], &[u64]) {
        (&self.starts, &self.cells, &self.volumes, &self.ids)
    }

    /// The cells of particle `id` (at index `i` of its world) and its volume in
    /// each, if it has a row. Row `i` is looked at first: it is the particle's
    /// unless particles came or went since the shares were computed.
    pub fn of(&self, i: usize, id: u64) -> Option<(&[u32], &[Real])> {
        let r = match self.ids.get(i) {
            Some(&at) if at == id => i,
            _ => self.position_of(id)?,
        };
        Some(self.row(r))
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
