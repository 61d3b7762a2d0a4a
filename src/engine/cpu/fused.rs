//! The pair stage and the gather fused, for a step on one thread: each candidate
//! pair is evaluated and added to its two particles at once, in pair order, instead
//! of being written to the results array that the gather then reads back.
//!
//! # Same bits as the two stages
//! The gather adds a particle's pairs in ascending pair order, starting from its
//! weight; a sweep over the pairs in order reaches every particle's pairs in that
//! same order, so each particle gets the same additions in the same order (the
//! pairs with nothing to do are skipped: in the gather they add zeros), and the
//! totals are summed in pair order as the gather sums them. A run on one thread is
//! therefore bit for bit a run on many (`tests/thread_count.rs`).
//!
//! # Why
//! On one thread the results array is pure traffic: every pair's 88-byte result is
//! written, then read back at a scattered place for each of its particles. The sweep
//! keeps the first particle's sums in registers while its pairs follow one another
//! (pairs are sorted by the first particle) and touches the second's in place.

use super::contact_state::ContactState;
use super::pair_results::BLOCK;
use super::pairs::{BlockPlans, ContactTotals, PairLaws, StartLoads, evaluate_block};
use super::prefetch::PairPrefetch;
use super::type_table::TypeTable;
use crate::Real;
use crate::engine::neighbours::NeighbourList;
use crate::geometry::overlap::OverlapCache;
use crate::world::World;

/// Sets every particle's force, torque and touching flag as [`super::pairs::gather`]
/// after [`super::pairs::pair_contacts`] would, evaluating the pairs on this thread.
/// Returns the pairs' count and energies.
pub(super) fn pair_contacts_gathered(
    world: &mut World,
    list: &NeighbourList,
    state: &mut ContactState,
    (radii, types): (&[Real], &TypeTable),
    laws: PairLaws,
    touching: &mut Vec<bool>,
) -> ContactTotals {
    let n = world.particles.len();
    touching.resize(n, false);
    // The sums are written outside the world while the pairs read it.
    let mut force = std::mem::take(&mut world.particles.force);
    let mut torque = std::mem::take(&mut world.particles.torque);
    let p = &world.particles;
    let start = StartLoads {
        owned: p.owned(),
        body_type: &p.body_type,
        frozen: &p.frozen,
        types: &world.body_types,
        gravity: world.gravity,
    };
    for k in 0..n {
        (force[k], torque[k], touching[k]) = start.of(k);
    }
    let with_plans = state.overlap_plans.len() == list.pairs().len();
    let mut spare = OverlapCache::default();
    let pairs = list.pairs();
    let (plans, keeps_contact) = state.overlap_plans.split();
    let prefetch = PairPrefetch::new(
        (plans, keeps_contact),
        &state.pair_history,
        pairs,
        &p.body_type,
        types,
    );
    let mut totals = ContactTotals::of_candidates(p, pairs);
    for first in (0..pairs.len()).step_by(BLOCK) {
        let block = first..pairs.len().min(first + BLOCK);
        let plans = with_plans.then(|| BlockPlans {
            plans: &mut plans[block.clone()],
            prefetch,
            first,
        });
        let block_pairs = &pairs[block.clone()];
        let history = &mut state.pair_history[block];
        let held = &mut state.held[first / BLOCK];
        evaluate_block(
            world,
            radii,
            &laws,
            (block_pairs, history, held),
            plans,
            &mut spare,
            |k, c| {
                let pair = block_pairs[k];
                for (particle, first) in [(pair[0] as usize, true), (pair[1] as usize, false)] {
                    // A ghost's sums stay zero (the gather leaves them so).
                    if particle < start.owned {
                        c.add_to(
                            (
                                &mut force[particle],
                                &mut torque[particle],
                                &mut touching[particle],
                            ),
                            first,
                        );
                    }
                }
                totals.count(p, pair, &c);
            },
        );
    }
    world.particles.force = force;
    world.particles.torque = torque;
    totals
}

/// Whether the pair stage runs fused with the gather: on one thread.
pub(super) fn fused() -> bool {
    rayon::current_num_threads() == 1
}
