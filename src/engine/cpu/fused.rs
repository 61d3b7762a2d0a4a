//! The pair stage and the gather fused: each candidate pair is evaluated and added to
//! its two particles at once, in pair order, instead of being written to a results
//! array that a gather then reads back. On many threads the pairs are swept in
//! parts, one contiguous run of blocks each, side by side.
//!
//! # Same bits as a sweep on one thread
//! A sweep over the pairs in order adds each particle's pairs in ascending pair order,
//! starting from its weight (the pairs with nothing to do are skipped: they would add
//! zeros). The parts keep that order: a particle belongs to the part of its first
//! pair ([`Parts::lowest`]); that part adds to it in place while it sweeps, and every
//! later part that meets the particle defers that pair's result. After the sweep the
//! deferred results are added part by part, in pair order: the particle gets the
//! additions of a single sweep, in its order, whatever the number of parts. The
//! totals are summed block by block ([`ContactTotals`]): the later parts keep their
//! blocks' sums, added after the first part's in block order. So a run on one
//! thread is bit for bit a run on many (`tests/thread_count.rs`).
//!
//! # Why
//! A results array is pure traffic: every pair's 88-byte result was written, then
//! read back at a scattered place for each of its particles, on two threads a line
//! that the other core had written for about half of them (the gather took a fifth
//! of a step of a settled bed of spheres). The sweep keeps a particle's sums in the
//! caches of the core that adds its pairs; the particles are stored in space order
//! (`world::space_order`), so a part's pairs are a region of the bed and only the
//! particles on the boundary between two parts' regions have deferred pairs.

use std::ops::Range;
use std::time::Instant;

use nalgebra::Vector3;
use rayon::prelude::*;

use super::blocks::BLOCK;
use super::contact_state::ContactState;
use super::forces::PairResult;
use super::pairs::{BlockPlans, ContactTotals, PairLaws, StartLoads, evaluate_block};
use super::part_split::PartSplit;
use super::prefetch::PairPrefetch;
use super::shared_sums::SharedSums;
use super::type_table::TypeTable;
use crate::Real;
use crate::contact::TangentialHistory;
use crate::engine::neighbours::NeighbourList;
use crate::geometry::overlap::OverlapCache;
use crate::world::World;

/// Particles per task of the passes over particles on many threads.
const PARTICLES_PER_TASK: usize = 1024;

/// The sweep's buffers, kept between steps.
#[derive(Clone, Debug, Default)]
pub(super) struct Parts {
    /// Each particle's part: the one that holds its first pair (`u32::MAX` for a
    /// particle without pairs).
    ///
    /// Why kept between steps: a particle's part depends on the list and the split
    /// alone, and finding it every step (its first pair through the incident lists)
    /// took the pass that starts the sums from 8 µs on one thread to 27 µs on two
    /// (the settled bed of 5000 spheres). It is found with each new split.
    lowest: Vec<u32>,
    /// Where the parts begin, and when they ended.
    split: PartSplit,
    /// What each part kept back for after the sweep.
    deferred: Vec<Deferred>,
}

/// What a part kept back: the results of its pairs with a particle of an earlier
/// part, in pair order, and the sums of its blocks, in block order.
#[derive(Clone, Debug, Default)]
struct Deferred {
    results: Vec<(u32, PairResult)>,
    blocks: Vec<ContactTotals>,
    /// The overlap plan of the pairs without one (spheres).
    spare: OverlapCache,
    /// When the part ended, s after the sweep began.
    ended: f64,
}

/// Sets every particle's force, torque and touching flag to its weight plus its pairs'
/// contacts, added in pair order (see the module docs), evaluating the pairs in as
/// many parts as there are threads. Returns the pairs' count and energies.
pub(super) fn pair_contacts_gathered(
    world: &mut World,
    list: &NeighbourList,
    state: &mut ContactState,
    (radii, types): (&[Real], &TypeTable),
    laws: PairLaws,
    (touching, parts): (&mut Vec<bool>, &mut Parts),
) -> ContactTotals {
    let pairs = list.pairs();
    let made_for = (list.builds(), rayon::current_num_threads());
    let find_parts = parts.split.stale(made_for);
    if find_parts {
        parts.split.split(pairs.len(), &state.held, made_for);
        let count = parts.split.count();
        parts.deferred.resize_with(count, Deferred::default);
    }
    if parts.split.count() == 1 {
        return sweep_alone(world, list, state, (radii, types), laws, touching);
    }
    let n = world.particles.len();
    touching.resize(n, false);
    // The sums are written outside the world while the pairs read it.
    let mut force = std::mem::take(&mut world.particles.force);
    let mut torque = std::mem::take(&mut world.particles.torque);
    let p = &world.particles;
    let start = StartLoads::of(world);
    start_sums(
        &start,
        (list, find_parts),
        parts,
        (&mut force, &mut torque, touching),
    );
    // Invariant of `SharedSums`: particle `k`'s sums are written by part
    // `lowest[k]` alone (any other part that meets `k` defers).
    let sums = SharedSums::over(&mut force, &mut torque, touching);
    let with_plans = state.overlap_plans.len() == pairs.len();
    let (plans, prefetch) = PairPrefetch::over(
        &mut state.overlap_plans,
        &state.pair_history,
        pairs,
        &p.body_type,
        types,
    );
    let sweep = Sweep {
        world,
        radii,
        laws: &laws,
        pairs,
        lowest: &parts.lowest,
        owned: start.owned,
        prefetch,
        began: Instant::now(),
    };
    let mut totals = ContactTotals::of_candidates(p, pairs);
    let slices = PartSlices {
        pairs: 0..pairs.len(),
        history: &mut state.pair_history[..],
        held: &mut state.held[..],
        plans: with_plans.then_some(plans),
    };
    // Part 0 sums the totals; each later one keeps its terms (see the module docs).
    sweep.parts(
        (parts.split.starts(), 0),
        slices,
        &mut parts.deferred[..],
        sums,
        &mut totals,
    );
    parts.split.time(parts.deferred.iter().map(|d| d.ended));
    world.particles.force = force;
    world.particles.torque = torque;
    totals
}

/// Adds what the parts of [`pair_contacts_gathered`] deferred, part by part, in pair
/// order: the results to their particles of earlier parts, the terms to `totals`.
pub(super) fn add_deferred(
    world: &mut World,
    list: &NeighbourList,
    (touching, parts): (&mut [bool], &Parts),
    mut totals: ContactTotals,
) -> ContactTotals {
    let pairs = list.pairs();
    let p = &mut world.particles;
    let owned = p.owned();
    for (m, d) in parts.deferred[..parts.split.count()]
        .iter()
        .enumerate()
        .skip(1)
    {
        for (k, c) in &d.results {
            let [i, j] = pairs[*k as usize].map(|x| x as usize);
            for (particle, first) in [(i, true), (j, false)] {
                if particle < owned && (parts.lowest[particle] as usize) < m {
                    let sums = (&mut p.force[particle], &mut p.torque[particle]);
                    c.add_to((sums.0, sums.1, &mut touching[particle]), first);
                }
            }
        }
        for block in &d.blocks {
            totals.add_block(block);
        }
    }
    totals
}

/// Sets every particle's sums to its start ([`StartLoads`]) and, if `find_parts`,
/// finds its part.
///
/// By chunks with a loop over indices: a closure per particle that returned its
/// start and part as a tuple was called out of line, its result read back from the
/// stack by loads that straddled its stores, and the pass took 58–90 µs a step of
/// the settled bed of 5000 spheres on two threads (27–35 µs now).
fn start_sums(
    start: &StartLoads,
    (list, find_parts): (&NeighbourList, bool),
    parts: &mut Parts,
    (force, torque, touching): (&mut [Vector3<Real>], &mut [Vector3<Real>], &mut [bool]),
) {
    let mut lowest = std::mem::take(&mut parts.lowest);
    lowest.resize(force.len(), u32::MAX);
    let part_of = &*parts;
    (
        force.par_chunks_mut(PARTICLES_PER_TASK),
        torque.par_chunks_mut(PARTICLES_PER_TASK),
        touching.par_chunks_mut(PARTICLES_PER_TASK),
        lowest.par_chunks_mut(PARTICLES_PER_TASK),
    )
        .into_par_iter()
        .enumerate()
        .for_each(|(c, (force, torque, touching, lowest))| {
            let first = c * PARTICLES_PER_TASK;
            for (o, lowest) in lowest.iter_mut().enumerate() {
                let k = first + o;
                (force[o], torque[o], touching[o]) = start.of_particle(k);
                if find_parts {
                    let incident = list.incident(k).first();
                    *lowest = incident.map_or(u32::MAX, |e| part_of.split.of_pair(e.pair()));
                }
            }
        });
    parts.lowest = lowest;
}

/// A part's pairs with their histories, masks of held histories and overlap plans
/// (where the pairs keep plans).
struct PartSlices<'a> {
    pairs: Range<usize>,
    history: &'a mut [TangentialHistory],
    held: &'a mut [u64],
    plans: Option<&'a mut [OverlapCache]>,
}

impl<'a> PartSlices<'a> {
    /// The slices before pair `at` and from it on (`at` starts a block).
    fn split_at(self, at: usize) -> (Self, Self) {
        let len = at - self.pairs.start;
        debug_assert!(len % BLOCK == 0);
        let (history, history_after) = self.history.split_at_mut(len);
        let (held, held_after) = self.held.split_at_mut(len / BLOCK);
        let (plans, plans_after) = match self.plans {
            Some(plans) => {
                let (before, after) = plans.split_at_mut(len);
                (Some(before), Some(after))
            }
            None => (None, None),
        };
        (
            PartSlices {
                pairs: self.pairs.start..at,
                history,
                held,
                plans,
            },
            PartSlices {
                pairs: at..self.pairs.end,
                history: history_after,
                held: held_after,
                plans: plans_after,
            },
        )
    }
}

/// What every part of the sweep reads.
struct Sweep<'a> {
    world: &'a World,
    radii: &'a [Real],
    laws: &'a PairLaws<'a>,
    pairs: &'a [[u32; 2]],
    lowest: &'a [u32],
    owned: usize,
    prefetch: PairPrefetch<'a>,
    /// When the sweep began.
    began: Instant,
}

impl Sweep<'_> {
    /// Sweeps the parts `first..first + deferred.len()` (their first pairs in
    /// `starts`), whose pairs `slices` holds, side by side: halves them and sweeps
    /// the halves in parallel (allocating nothing).
    fn parts(
        &self,
        (starts, first): (&[usize], usize),
        slices: PartSlices,
        deferred: &mut [Deferred],
        sums: SharedSums<'_>,
        totals: &mut ContactTotals,
    ) {
        if let [only] = deferred {
            return self.part(first, slices, sums, totals, only);
        }
        let half = deferred.len() / 2;
        let (left, right) = slices.split_at(starts[first + half]);
        let (deferred_left, deferred_right) = deferred.split_at_mut(half);
        rayon::join(
            || self.parts((starts, first), left, deferred_left, sums, totals),
            || {
                let mut unused = ContactTotals::default();
                let at = (starts, first + half);
                self.parts(at, right, deferred_right, sums, &mut unused)
            },
        );
    }

    /// Sweeps part `m` of several: adds its pairs to the particles of part `m` in
    /// `sums` and to `totals` (part 0), defers the rest to `deferred`. Not inlined:
    /// called from both arms of the halving, its loop would be copied, and LLVM
    /// then called the pair's evaluation out of line.
    #[inline(never)]
    fn part(
        &self,
        m: usize,
        slices: PartSlices,
        sums: SharedSums<'_>,
        totals: &mut ContactTotals,
        deferred: &mut Deferred,
    ) {
        deferred.results.clear();
        deferred.blocks.clear();
        let Deferred {
            results,
            blocks,
            spare,
            ended,
        } = deferred;
        let part = m as u32;
        let mut sum = *totals;
        let take = |pair: [u32; 2], k: usize, c: &PairResult| {
            let mut defer = false;
            for (particle, first) in [(pair[0] as usize, true), (pair[1] as usize, false)] {
                // A ghost's sums stay zero.
                if particle < self.owned {
                    if self.lowest[particle] == part {
                        // SAFETY: the particle is this part's (`lowest`).
                        c.add_to(unsafe { sums.of(particle) }, first);
                    } else {
                        defer = true;
                    }
                }
            }
            if defer {
                results.push((k as u32, *c));
            }
        };
        if m == 0 {
            self.blocks(slices, spare, take, |block| sum.add_block(block));
        } else {
            self.blocks(slices, spare, take, |block| blocks.push(*block));
        }
        *totals = sum;
        *ended = self.began.elapsed().as_secs_f64();
    }

    /// Evaluates the pairs of `slices` block by block, in pair order, handing each
    /// busy pair's particles, index in the list and result to `take`, and each
    /// block's sums to `block_sums`.
    #[inline(always)]
    fn blocks(
        &self,
        slices: PartSlices,
        spare: &mut OverlapCache,
        mut take: impl FnMut([u32; 2], usize, &PairResult),
        mut block_sums: impl FnMut(&ContactTotals),
    ) {
        let p = &self.world.particles;
        let PartSlices {
            pairs: range,
            history,
            held,
            mut plans,
        } = slices;
        for (b, start) in range.clone().step_by(BLOCK).enumerate() {
            let block = start..range.end.min(start + BLOCK);
            let local = start - range.start..block.end - range.start;
            let plans = plans.as_mut().map(|plans| BlockPlans {
                plans: &mut plans[local.clone()],
                prefetch: self.prefetch,
                first: start,
            });
            let block_pairs = &self.pairs[block];
            let mut sums = ContactTotals::default();
            evaluate_block(
                self.world,
                self.radii,
                self.laws,
                (block_pairs, &mut history[local], &mut held[b]),
                plans,
                spare,
                |k, c| {
                    take(block_pairs[k], start + k, &c);
                    sums.count(p, block_pairs[k], &c);
                },
            );
            block_sums(&sums);
        }
    }
}

/// [`pair_contacts_gathered`] in one part, on this thread: one sweep adds every pair
/// to its particles. Its own loop, not [`Sweep::part`]'s: with the check of each
/// particle's part and the deferral in the loop, one thread's sweep of the settled
/// bed of spheres took 8–13 % longer (alternating runs, 2026-12-06).
fn sweep_alone(
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
    let start = StartLoads::of(world);
    for k in 0..n {
        (force[k], torque[k], touching[k]) = start.of_particle(k);
    }
    let with_plans = state.overlap_plans.len() == list.pairs().len();
    let mut spare = OverlapCache::default();
    let pairs = list.pairs();
    let (plans, prefetch) = PairPrefetch::over(
        &mut state.overlap_plans,
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
        let mut sums = ContactTotals::default();
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
                    // A ghost's sums stay zero.
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
                sums.count(p, pair, &c);
            },
        );
        totals.add_block(&sums);
    }
    world.particles.force = force;
    world.particles.torque = torque;
    totals
}
