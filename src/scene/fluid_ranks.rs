//! A coupled fluid on ranks: every rank holds the whole grid with the fields the
//! coupled code sets (the same on all), and the shares, drag and impulse of the
//! particles it owns.
//!
//! **The fields the particles make** (solid fraction, mean particle velocity) are
//! one process's bits: each rank splits its particles' volumes among the cells and
//! sends what each particle brings to a cell (its id, volume and momentum) to the
//! rank that owns the cell's block of the flat order; that rank sums each cell's
//! contributions in particle id order, which is the order in which one process
//! sums them, and every rank gets every block back. Each particle then reads the
//! fluid and gives back its drag through the same cells and weights as in one
//! process: its row of the shares moves with it to a new owner (see
//! [`crate::engine::rank`]).
//!
//! **What the particles give the fluid** (the drag's impulse per cell) is summed on
//! each rank over the steps and over the ranks, in rank order, when it is read:
//! within round-off of one process's sum, like the walls' forces.

use std::ops::Range;

use nalgebra::Vector3;

use super::Simulation;
use super::ranks::sum_on_first;
use super::state::FluidState;
use crate::Real;
use crate::engine::rank::{Share, all_gather, all_to_all, gather_to_first};
use crate::world::{
    CellContribution, CellShares, FluidField, MomentumExchange, ParticleFluid, ShareRow, World,
};

/// The flat order of a grid's cells cut into one block per rank, the first ranks'
/// blocks no longer than the last ones'.
#[derive(Clone, Copy, Debug)]
struct CellBlocks {
    cells: usize,
    ranks: usize,
}

impl CellBlocks {
    /// Rank `r`'s cells.
    fn of(&self, r: usize) -> Range<usize> {
        r * self.cells / self.ranks..(r + 1) * self.cells / self.ranks
    }

    /// The rank whose block holds cell `c`.
    fn owner(&self, c: usize) -> usize {
        // The last rank whose block starts at or before `c`.
        let mut r = (c * self.ranks / self.cells.max(1)).min(self.ranks - 1);
        while self.of(r).start > c {
            r -= 1;
        }
        while self.of(r).end <= c {
            r += 1;
        }
        r
    }
}

/// What a particle of one rank brings to the whole run's fluid state: its id, its
/// row of the shares and the drag of the last force evaluation.
type SavedFluidParticle = (u64, (Option<ShareRow>, Option<Vector3<Real>>));

/// [`Simulation::update_fluid`] on ranks (collective; see the module).
pub(super) fn update_fluid_on_ranks(share: &dyn Share, world: &mut World) {
    let Some(fluid) = world.fluid.as_mut() else {
        return;
    };
    fluid.shares = CellShares::compute(&fluid.grid, &world.particles, &world.body_types);
    let blocks = CellBlocks {
        cells: fluid.grid.len(),
        ranks: share.ranks(),
    };
    let mut outgoing = vec![Vec::new(); blocks.ranks];
    for c in fluid.contributions(&world.particles) {
        outgoing[blocks.owner(c.cell as usize)].push(c);
    }
    let mut mine: Vec<CellContribution> = all_to_all(share, &outgoing).concat();
    mine.sort_unstable_by_key(|c| (c.cell, c.id));
    let block = blocks.of(share.rank());
    fluid.add_up(block.clone(), &mine);
    let means: Vec<(Real, Vector3<Real>)> = block
        .clone()
        .map(|c| (fluid.solid_fraction[c], fluid.particle_velocity[c]))
        .collect();
    for (r, means) in all_gather(share, &means).into_iter().enumerate() {
        for (c, (phi, u)) in blocks.of(r).zip(means) {
            fluid.solid_fraction[c] = phi;
            fluid.particle_velocity[c] = u;
        }
    }
}

/// The whole run's particle side of a fluid on rank 0, as one process holds it
/// (collective; `None` on the others): every particle's row of the shares and drag
/// in id order, the impulse summed over the ranks. `ids` are this rank's owned
/// particles, which `shares` and `exchange` are of.
pub(super) fn whole_exchange(
    share: &dyn Share,
    ids: &[u64],
    shares: &CellShares,
    exchange: &MomentumExchange,
) -> Option<(CellShares, MomentumExchange)> {
    let mine: Vec<SavedFluidParticle> = ids
        .iter()
        .enumerate()
        .map(|(i, &id)| (id, (shares.row_of(id), exchange.drag.get(i).copied())))
        .collect();
    let gathered = gather_to_first(share, &mine);
    let impulse = sum_on_first(share, &exchange.impulse);
    if share.rank() != 0 {
        return None;
    }
    let mut all: Vec<SavedFluidParticle> = gathered.into_iter().flatten().collect();
    all.sort_unstable_by_key(|(id, _)| *id);
    let shares = CellShares::from_rows(all.iter().filter_map(|(id, (row, _))| {
        let row = row.as_ref()?;
        Some((*id, &row.cells[..], &row.volumes[..]))
    }));
    let exchange = MomentumExchange {
        // Particles inserted since the last force evaluation have no drag: the
        // newest ids, as in one process.
        drag: all.iter().filter_map(|(_, (_, drag))| *drag).collect(),
        impulse,
        elapsed: exchange.elapsed,
    };
    Some((shares, exchange))
}

/// [`whole_exchange`] of `world`'s fluid, in a copy of the field (`None` without
/// one).
pub(super) fn whole_fluid(share: &dyn Share, world: &World) -> Option<FluidField> {
    let fluid = world.fluid.as_ref()?;
    let p = &world.particles;
    let (shares, exchange) =
        whole_exchange(share, &p.id[..p.owned()], &fluid.shares, &fluid.exchange)?;
    Some(FluidField {
        shares,
        exchange,
        ..fluid.clone()
    })
}

impl Simulation {
    /// The mean force per cell the particles put on the fluid since its sums were
    /// last started ([`crate::world::FluidField::momentum_source`]): in one process
    /// the field's; on ranks (collective) the whole run's on rank 0. `None` without
    /// a fluid and on the other ranks.
    pub fn whole_momentum_source(&self) -> Option<Vec<Vector3<Real>>> {
        let fluid = self.world.fluid.as_ref()?;
        let cells = 0..fluid.grid.len();
        let Some(share) = self.backend.share() else {
            return Some(cells.map(|c| fluid.momentum_source(c)).collect());
        };
        let whole = MomentumExchange {
            impulse: sum_on_first(share, &fluid.exchange.impulse),
            elapsed: fluid.exchange.elapsed,
            drag: Vec::new(),
        };
        (share.rank() == 0).then(|| cells.map(|c| whole.source(c)).collect())
    }

    /// Each particle's id and what the fluid does to it ([`ParticleFluid`]) in id
    /// order: in one process the world's; on ranks (collective) the whole run's on
    /// rank 0. `None` without a fluid and on the other ranks.
    pub fn whole_particle_fluid(&self) -> Option<(Vec<u64>, Vec<ParticleFluid>)> {
        let fluid = self.world.fluid.as_ref()?;
        let p = &self.world.particles;
        let mut mine: Vec<(u64, ParticleFluid)> = (0..p.owned())
            .map(|i| (p.id[i], fluid.at_particle(p, i)))
            .collect();
        let Some(share) = self.backend.share() else {
            // Stored in the space order.
            mine.sort_unstable_by_key(|(id, _)| *id);
            return Some(mine.into_iter().unzip());
        };
        let gathered = gather_to_first(share, &mine);
        if share.rank() != 0 {
            return None;
        }
        let mut all: Vec<(u64, ParticleFluid)> = gathered.into_iter().flatten().collect();
        all.sort_unstable_by_key(|(id, _)| *id);
        Some(all.into_iter().unzip())
    }
}

/// A rank's fluid after its share of a restored `state` was kept: the drag of the
/// particles it owns (the state's is in id order, `ids`), their rows of the shares,
/// and on rank 0 the saved impulse (the others start their sums from zero).
pub(super) fn keep_fluid_share(world: &mut World, state: &FluidState, ids: &[u64], rank: usize) {
    let Some(fluid) = world.fluid.as_mut() else {
        return;
    };
    let p = &world.particles;
    let owned = &p.id[..p.owned()];
    fluid.shares = state.shares.keep(owned, &[]);
    fluid.exchange.drag = owned
        .iter()
        .map_while(|id| {
            let k = ids.binary_search(id).ok()?;
            state.exchange.drag.get(k).copied()
        })
        .collect();
    if rank != 0 {
        fluid.exchange.impulse.fill(Vector3::zeros());
    }
}

#[cfg(test)]
mod tests {
    use super::CellBlocks;

    /// Every cell has one owner, the one whose block holds it, for grids smaller and
    /// larger than the number of ranks.
    #[test]
    fn every_cell_is_in_its_owners_block() {
        for cells in [1, 2, 3, 7, 54, 1000] {
            for ranks in 1..=9 {
                let blocks = CellBlocks { cells, ranks };
                let total: usize = (0..ranks).map(|r| blocks.of(r).len()).sum();
                assert_eq!(total, cells);
                for c in 0..cells {
                    assert!(
                        blocks.of(blocks.owner(c)).contains(&c),
                        "{cells} {ranks} {c}"
                    );
                }
            }
        }
    }
}
