//! What the CPU backend keeps of its contacts from step to step: the tangential
//! history of every candidate pair and wall patch, and the overlap decisions that
//! only change the cost.

use super::blocks::BLOCK;
use super::overlap_plans::OverlapPlans;
use super::wall_history::WallHistory;
use crate::Real;
use crate::contact::TangentialHistory;
use crate::engine::backend::ContactHistory;
use crate::engine::fast_hash::FastMap;
use crate::engine::neighbours::NeighbourList;
use crate::world::World;

/// Persistent contact state, aligned with a [`NeighbourList`].
///
/// # Invariant
/// `pair_history[k]` and `overlap_plans[k]` belong to `list.pairs()[k]` of the list
/// last built, unless `pending` holds a history set from outside, which is matched to
/// the pairs (by particle ids) at the next build and until then is the history.
/// Where `overlap_plans` is empty, bit `k % BLOCK` of `held[k / BLOCK]` is set where
/// `pair_history[k]` is not empty (with plans every pair is evaluated, the mask is
/// not read, and it is made anew at the next build).
/// `overlap_plans` is empty when the world had no polyhedra at that build.
#[derive(Clone, Debug, Default)]
pub(super) struct ContactState {
    /// Tangential history of each candidate pair.
    pub pair_history: Vec<TangentialHistory>,
    /// Per block of [`BLOCK`] pairs, which hold a history: the pair stage of spheres
    /// finds the pairs with something to do without reading the histories of those
    /// apart.
    pub held: Vec<u64>,
    /// What each candidate pair's exact overlap decided at some pose: it changes the
    /// cost, never the answer (see [`crate::geometry::overlap::OverlapCache`]), so it
    /// is neither saved nor carried over a list build.
    pub overlap_plans: OverlapPlans,
    /// History set from outside, to be matched to the pairs at the next list build.
    pending: Option<FastMap<(u64, u64), TangentialHistory>>,
    /// History of the particle–wall patches of the last step.
    pub wall_history: WallHistory,
}

impl ContactState {
    /// The tangential history of the particle pairs, keyed by the two ids.
    fn pair_history_by_ids(&self, list: &NeighbourList) -> FastMap<(u64, u64), TangentialHistory> {
        if let Some(pending) = &self.pending {
            return pending.clone();
        }
        list.pairs()
            .iter()
            .zip(&self.pair_history)
            .filter(|(_, h)| !h.is_empty())
            .map(|(&pair, h)| (list.pair_ids(pair), *h))
            .collect()
    }

    /// The whole history, sorted by key.
    pub fn history(&self, list: &NeighbourList) -> ContactHistory {
        let mut pairs: Vec<_> = self.pair_history_by_ids(list).into_iter().collect();
        pairs.sort_by_key(|e| e.0);
        let walls = self.wall_history.to_sorted();
        ContactHistory { pairs, walls }
    }

    /// Replaces the history; `list` must be rebuilt before it is used again.
    pub fn set_history(&mut self, history: ContactHistory, list: &mut NeighbourList) {
        self.pending = Some(history.pairs.into_iter().collect());
        list.invalidate();
        self.wall_history.set(history.walls);
    }

    /// Rebuilds `list` for `world` (`radii`: bounding radii), carrying each pair's
    /// history over by the two particle ids and grouping the wall patches' history by
    /// the particles (a list is stale whenever the ids change, so the wall stage
    /// finds it grouped between builds).
    pub fn rebuild(&mut self, list: &mut NeighbourList, world: &World, radii: &[Real]) {
        let carried = match self.pending.take() {
            Some(pending) => pending,
            None => self.pair_history_by_ids(list),
        };
        list.build(world, radii);
        self.wall_history.align(&world.particles.id);
        // Only polyhedron pairs use a plan: a world of spheres keeps none (a plan is a
        // few hundred bytes, written for every pair at every build).
        let polyhedra = (world.body_types.iter()).any(|t| t.shape.as_polyhedron().is_some());
        (self.overlap_plans).reset(if polyhedra { list.pairs().len() } else { 0 });
        self.pair_history.clear();
        self.pair_history.extend(list.pairs().iter().map(|&pair| {
            carried
                .get(&list.pair_ids(pair))
                .copied()
                .unwrap_or_default()
        }));
        self.held.clear();
        (self.held).extend(self.pair_history.chunks(BLOCK).map(held_mask));
    }
}

/// The mask of the pairs of a block (at most [`BLOCK`]) whose `history` is not empty.
pub(super) fn held_mask(history: &[TangentialHistory]) -> u64 {
    (history.iter().enumerate()).fold(0, |mask, (k, h)| mask | u64::from(!h.is_empty()) << k)
}
