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
    /// The pairs of the list before a build, and their history, while a build
    /// carries it over (kept to allocate nothing once grown).
    previous_pairs: Vec<[u32; 2]>,
    previous_history: Vec<TangentialHistory>,
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
        let ids = &world.particles.id;
        // The same particles in the same order: both lists ascend by index.
        let by_index = self.pending.is_none() && list.ascends_by_index_of(ids);
        let carried = if by_index {
            self.previous_pairs.clear();
            self.previous_pairs.extend_from_slice(list.pairs());
            std::mem::swap(&mut self.previous_history, &mut self.pair_history);
            None
        } else {
            Some(match self.pending.take() {
                Some(pending) => pending,
                None => self.pair_history_by_ids(list),
            })
        };
        list.build(world, radii);
        self.wall_history.align(ids);
        // Only polyhedron pairs use a plan: a world of spheres keeps none (a plan is a
        // few hundred bytes, written for every pair at every build).
        let polyhedra = (world.body_types.iter()).any(|t| t.shape.as_polyhedron().is_some());
        (self.overlap_plans).reset(if polyhedra { list.pairs().len() } else { 0 });
        self.pair_history.clear();
        let before = (&self.previous_pairs[..], &self.previous_history[..]);
        match carried {
            None if list.ascends_by_index_of(ids) => {
                carry_by_index(before, list.pairs(), &mut self.pair_history)
            }
            None => {
                // The same particles, but their keys changed in place: by the ids.
                let (pairs, history) = before;
                let carried = (pairs.iter().zip(history))
                    .filter(|(_, h)| !h.is_empty())
                    .map(|(&[i, j], h)| ((ids[i as usize], ids[j as usize]), *h))
                    .collect();
                carry_by_ids(&carried, list, &mut self.pair_history)
            }
            Some(carried) => carry_by_ids(&carried, list, &mut self.pair_history),
        }
        self.held.clear();
        (self.held).extend(self.pair_history.chunks(BLOCK).map(held_mask));
    }
}

/// Appends to `history` the history `carried` holds for each pair of `list`, keyed
/// by the two particles' ids, an empty one for the others.
fn carry_by_ids(
    carried: &FastMap<(u64, u64), TangentialHistory>,
    list: &NeighbourList,
    history: &mut Vec<TangentialHistory>,
) {
    history.extend((list.pairs().iter()).map(|&pair| {
        carried
            .get(&list.pair_ids(pair))
            .copied()
            .unwrap_or_default()
    }));
}

/// Appends to `history` the history of each of `pairs` that the list before
/// (`pairs_before`, with their histories `before`) holds, an empty one for the
/// others: both lists ascend by the particles' indices (each pair read smaller
/// index first) and name the same particles, so they are walked side by side.
///
/// Why: carried over by the pairs' ids through a hash map, the history of the
/// 21 600 pairs of a pour of 5000 spheres took 780 µs of each list build (the map
/// made, then read for every pair), a quarter of the build (one thread, AMD EPYC
/// VM, 2026-12-07).
fn carry_by_index(
    (pairs_before, before): (&[[u32; 2]], &[TangentialHistory]),
    pairs: &[[u32; 2]],
    history: &mut Vec<TangentialHistory>,
) {
    let by_index = |[i, j]: [u32; 2]| (i.min(j), i.max(j));
    let mut k = 0;
    history.extend(pairs.iter().map(|&pair| {
        let pair = by_index(pair);
        while k < pairs_before.len() && by_index(pairs_before[k]) < pair {
            k += 1;
        }
        match pairs_before.get(k) {
            Some(&p) if by_index(p) == pair => before[k],
            _ => TangentialHistory::default(),
        }
    }));
}

/// The mask of the pairs of a block (at most [`BLOCK`]) whose `history` is not empty.
pub(super) fn held_mask(history: &[TangentialHistory]) -> u64 {
    (history.iter().enumerate()).fold(0, |mask, (k, h)| mask | u64::from(!h.is_empty()) << k)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spring(x: Real) -> TangentialHistory {
        TangentialHistory {
            spring: nalgebra::Vector3::new(x, 0.0, 0.0),
            stiffness: 1.0,
            ..Default::default()
        }
    }

    /// Walking the lists side by side finds the history of every pair kept from the
    /// list before, whichever of its particles the pair names first (the one of
    /// smaller id), and an empty one for the pairs new to the list; the pairs that
    /// left take theirs with them.
    #[test]
    fn a_pair_keeps_its_history_by_index_whatever_its_orientation() {
        let before = [[0, 3], [2, 1], [1, 4], [2, 3], [4, 3]];
        let histories = [
            spring(1.0),
            spring(2.0),
            spring(3.0),
            spring(4.0),
            spring(5.0),
        ];
        // [0, 3] and [2, 3] left, [0, 1] and [3, 5] came, [1, 2] turned round.
        let pairs = [[0, 1], [1, 2], [1, 4], [4, 3], [3, 5]];
        let mut history = Vec::new();
        carry_by_index((&before, &histories), &pairs, &mut history);
        let expected = [
            TangentialHistory::default(),
            spring(2.0),
            spring(3.0),
            spring(5.0),
            TangentialHistory::default(),
        ];
        assert_eq!(history, expected);
    }
}
