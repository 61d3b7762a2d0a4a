//! The particle-pair stages: every candidate pair's contact, in parallel over the flat
//! pair array, then every particle gathering its pairs' forces in pair order.

use nalgebra::Vector3;
use rayon::prelude::*;

use super::contact_state::{ContactState, held_mask};
use super::dispatch::pair_geometry;
use super::forces::{ContactForce, PairResult, RelativeMotion, pair_force};
use super::hertz::{HertzInputs, rolling_inertia, round_contact_force, round_radius, sphere_pair};
use super::overlap_plans::record;
use super::pair_results::{BLOCK, BusyBits, PairResults};
use super::prefetch::PairPrefetch;
use super::type_table::TypeTable;
use crate::Real;
use crate::contact::{RollingModel, TangentialHistory, effective_radius};
use crate::engine::RoundLaw;
use crate::engine::laws::ContactLaws;
use crate::engine::neighbours::NeighbourList;
use crate::geometry::overlap::OverlapCache;
use crate::world::{BodyType, Particles, World};

/// Smallest share of particles one rayon task takes.
const PARTICLES_PER_TASK: usize = 256;

/// The laws of the pair stage.
#[derive(Clone, Copy, Debug)]
pub(super) struct PairLaws<'a> {
    pub laws: &'a ContactLaws,
    pub round: RoundLaw,
    pub dt: Real,
}

/// The contact of particles `i` and `j` whose bounding spheres overlap, under the
/// scene's laws; `plan` is the pair's kept overlap plan.
#[inline]
fn pair_contact(
    world: &World,
    i: usize,
    j: usize,
    plan: &mut OverlapCache,
    history: &TangentialHistory,
    laws: &PairLaws,
) -> Option<ContactForce> {
    let volume = |plan: &mut OverlapCache| {
        pair_geometry(world, i, j, plan)
            .map(|g| pair_force(world, i, j, &g, *history, laws.laws, laws.dt))
    };
    let RoundLaw::HertzMindlin { rolling } = laws.round else {
        return volume(plan);
    };
    let p = &world.particles;
    let (bi, bj) = (p.body_type[i], p.body_type[j]);
    let inputs = |a: usize, b: usize, radius, rolling_inertia| HertzInputs {
        materials: laws.laws.materials(a, b),
        rolling,
        radius,
        rolling_inertia,
        dt: laws.dt,
    };
    match (laws.laws.sphere(bi), laws.laws.sphere(bj)) {
        (Some(a), Some(b)) => {
            let inertia = if rolling == RollingModel::None {
                0.0
            } else {
                1.0 / (1.0 / a.rolling_inertia + 1.0 / b.rolling_inertia)
            };
            let law = inputs(
                a.material,
                b.material,
                effective_radius(a.radius, b.radius),
                inertia,
            );
            sphere_pair(world, (i, a), (j, b), law, history)
        }
        (None, None) => volume(plan),
        _ => {
            // A sphere and a polyhedron: the polyhedron is locally flat.
            let (ti, tj) = (
                &world.body_types[bi as usize],
                &world.body_types[bj as usize],
            );
            let g = pair_geometry(world, i, j, plan)?;
            let motion = RelativeMotion::of_pair(world, [i, j], &g.point, &g.normal, 0.0);
            let lever = |k: usize| (g.point - p.position[k]).norm();
            let inertia =
                1.0 / (1.0 / rolling_inertia(ti, lever(i)) + 1.0 / rolling_inertia(tj, lever(j)));
            let radius = effective_radius(round_radius(&ti.shape), round_radius(&tj.shape));
            let law = inputs(ti.material, tj.material, radius, inertia);
            Some(round_contact_force(
                g.depth,
                &g.normal,
                &(g.point - p.position[j]),
                &motion,
                &law,
                history,
            ))
        }
    }
}

/// Whether candidate pair `[i, j]` may touch: their bounding spheres (`radii`)
/// overlap and one of them moves. Two passive particles (frozen or ghost) push on
/// nothing that moves here.
#[inline(always)]
fn near(p: &Particles, radii: &[Real], [i, j]: [u32; 2]) -> bool {
    let (i, j) = (i as usize, j as usize);
    let reach = radii[i] + radii[j];
    ((p.position[j] - p.position[i]).norm_squared() < reach * reach)
        & !(p.is_passive(i) & p.is_passive(j))
}

/// The result of candidate pair `[i, j]`, evaluated where it is [`near`], its history
/// replaced by the one its contact leaves (empty when they do not touch).
#[inline]
pub(super) fn evaluate_pair(
    world: &World,
    laws: &PairLaws,
    ([i, j], near): ([u32; 2], bool),
    history: &mut TangentialHistory,
    plan: &mut OverlapCache,
) -> PairResult {
    let p = &world.particles;
    let (i, j) = (i as usize, j as usize);
    let c = if near {
        pair_contact(world, i, j, plan, history, laws)
    } else {
        None
    };
    // A pair that stays apart keeps its empty history unwritten.
    match &c {
        Some(c) => {
            *history = c.history;
            PairResult::new(c, &p.position[i], &p.position[j])
        }
        None if !history.is_empty() => {
            let parted = PairResult::parted(history);
            *history = TangentialHistory::default();
            parted
        }
        None => PairResult::default(),
    }
}

/// Evaluates the candidate pairs into `results`, in parallel over blocks of pairs
/// ([`evaluate_block`]); `radii` are the particles' bounding radii, `types` the
/// table of their body types.
pub(super) fn pair_contacts(
    world: &World,
    list: &NeighbourList,
    state: &mut ContactState,
    (radii, types): (&[Real], &TypeTable),
    laws: PairLaws,
    results: &mut PairResults,
) {
    let pairs = list.pairs();
    let block = |b: usize,
                 (results, mask): (&mut [PairResult], &mut u64),
                 (history, held): BlockHistory,
                 plans: Option<(&mut [OverlapCache], PairPrefetch)>,
                 spare: &mut OverlapCache| {
        let first = b * BLOCK;
        let pairs = &pairs[first..first + results.len()];
        let plans = plans.map(|(plans, prefetch)| BlockPlans {
            plans,
            prefetch,
            first,
        });
        *mask = evaluate_block(
            world,
            radii,
            &laws,
            (pairs, history, held),
            plans,
            spare,
            |k, c| {
                results[k] = c;
            },
        );
    };
    let with_plans = state.overlap_plans.len() == pairs.len();
    let (history, held) = (&mut state.pair_history, &mut state.held);
    if with_plans {
        let (plans, keeps_contact) = state.overlap_plans.split();
        let body_type = &world.particles.body_type;
        // The prefetch keeps where the histories lie; nothing is read through it.
        let prefetch = PairPrefetch::new((plans, keeps_contact), history, pairs, body_type, types);
        result_blocks(results, (history, held), pairs.len())
            .zip(plans.par_chunks_mut(BLOCK))
            .for_each_init(
                OverlapCache::default,
                |spare, ((b, (results, history)), plans)| {
                    block(b, results, history, Some((plans, prefetch)), spare)
                },
            );
    } else {
        // A world of spheres keeps no overlap plans (see `ContactState::rebuild`).
        result_blocks(results, (history, held), pairs.len())
            .for_each_init(OverlapCache::default, |spare, (b, (results, history))| {
                block(b, results, history, None, spare)
            });
    }
}

/// A block's pairs' histories, and the mask of those that hold one (see
/// [`ContactState`]'s invariant).
type BlockHistory<'a> = (&'a mut [TangentialHistory], &'a mut u64);

/// A block of the pair stage: its number, its results with their mask, and its
/// pairs' histories.
type ResultBlock<'a> = (
    usize,
    ((&'a mut [PairResult], &'a mut u64), BlockHistory<'a>),
);

/// The blocks of `pairs` pairs' results (each with its mask) and histories (each
/// with the mask of those held), numbered.
fn result_blocks<'a>(
    results: &'a mut PairResults,
    (history, held): (&'a mut [TangentialHistory], &'a mut [u64]),
    pairs: usize,
) -> impl IndexedParallelIterator<Item = ResultBlock<'a>> {
    results
        .blocks_mut(pairs)
        .zip(history.par_chunks_mut(BLOCK).zip(held.par_iter_mut()))
        .enumerate()
}

/// The overlap plans of a block of pairs starting at pair `first` of the list.
pub(super) struct BlockPlans<'a> {
    pub plans: &'a mut [OverlapCache],
    pub prefetch: PairPrefetch<'a>,
    pub first: usize,
}

/// Evaluates the pairs of one block (at most [`BLOCK`], with their history and, for
/// polyhedra, their overlap plans; `spare` serves as the plan otherwise) that
/// [`to_evaluate`] names, in pair order, handing each one's index in the block and
/// result to `take`, and records which plans keep a contact. Returns the mask of
/// the pairs evaluated.
#[inline(always)]
pub(super) fn evaluate_block(
    world: &World,
    radii: &[Real],
    laws: &PairLaws,
    (pairs, history, held): (&[[u32; 2]], &mut [TangentialHistory], &mut u64),
    mut plans: Option<BlockPlans>,
    spare: &mut OverlapCache,
    mut take: impl FnMut(usize, PairResult),
) -> u64 {
    let p = &world.particles;
    let sift = plans.is_none();
    debug_assert!(
        !sift || *held == held_mask(history),
        "the held mask is the histories'"
    );
    let mask = to_evaluate(sift, p, radii, pairs, *held);
    // The pairs whose plan was read (near), and of them those that keep a contact;
    // the pairs that hold a history after (a pair left out kept its empty one).
    let (mut read, mut kept, mut holds) = (0u64, 0u64, 0u64);
    for k in BusyBits(mask) {
        let plan = match &mut plans {
            Some(p) => {
                p.prefetch.ahead(p.first, k);
                &mut p.plans[k]
            }
            None => &mut *spare,
        };
        let near = near(p, radii, pairs[k]);
        take(
            k,
            evaluate_pair(world, laws, (pairs[k], near), &mut history[k], plan),
        );
        read |= u64::from(near) << k;
        kept |= u64::from(near && plan.keeps_contact()) << k;
        if sift {
            holds |= u64::from(!history[k].is_empty()) << k;
        }
    }
    if sift {
        *held = holds;
    }
    if let Some(p) = &plans {
        record(p.prefetch.keeps_contact_word(p.first), read, kept);
    }
    mask
}

/// The mask of the pairs of a block to evaluate (at most [`BLOCK`]; `held`: those
/// holding a history): the busy ones ([`busy_pairs`]) if `sift`, else all of them
/// (an evaluation of a pair with nothing to do leaves it as it was). Sifting pays
/// where the pairs are spheres; among polyhedra, whose overlap plans the callers
/// pass, most candidates' bounding spheres overlap, the branch is foreseen, and
/// sifting first cost about 4 % of the dense bed of `talus bench` (a) on one thread.
#[inline]
fn to_evaluate(sift: bool, p: &Particles, radii: &[Real], pairs: &[[u32; 2]], held: u64) -> u64 {
    if sift {
        busy_pairs(p, radii, pairs, held)
    } else {
        u64::MAX >> (BLOCK - pairs.len())
    }
}

/// The mask of the pairs of a block (at most [`BLOCK`]) that have something to do:
/// they are [`near`], or they hold a history (`held`) that parting lets go. Found
/// without a branch per pair: whether a pair touches is as good as a coin toss in a
/// dense bed, and a mispredicted branch for every other candidate pair cost the sweep
/// about a fifth of its time. The histories themselves are not read: in a bed of
/// spheres about half of the candidate pairs are apart, and reading their 64-byte
/// histories to learn that they are empty was a line from memory for each.
#[inline]
fn busy_pairs(p: &Particles, radii: &[Real], pairs: &[[u32; 2]], held: u64) -> u64 {
    debug_assert!(pairs.len() <= BLOCK);
    let mut near_mask = 0u64;
    for (k, &pair) in pairs.iter().enumerate() {
        near_mask |= u64::from(near(p, radii, pair)) << k;
    }
    near_mask | held
}

/// Sets every owned particle's force to its weight plus its pairs' forces, gathered in
/// pair order (what a serial sweep over the pairs would add), so the sums do not
/// depend on the threads; marks the particles that touch. Ghosts get no force.
/// Returns the contacts' count and energies.
pub(super) fn gather(
    world: &mut World,
    list: &NeighbourList,
    results: &PairResults,
    touching: &mut Vec<bool>,
) -> ContactTotals {
    let p = &mut world.particles;
    let owned = p.owned();
    let start = StartLoads {
        owned,
        body_type: &p.body_type,
        frozen: &p.frozen,
        types: &world.body_types,
        gravity: world.gravity,
    };
    touching.resize(p.len(), false);
    (&mut p.force, &mut p.torque, touching)
        .into_par_iter()
        .enumerate()
        .with_min_len(PARTICLES_PER_TASK)
        .for_each(|(k, (force, torque, touching))| {
            (*force, *torque, *touching) = start.of(k);
            if k >= owned {
                return;
            }
            // Adding a pair apart adds zeros: `x + 0.0` is `x`, and `x + (−1)·f` is
            // `x − f`, so the sums are those of adding the touching pairs alone.
            for &e in list.incident(k) {
                let c = results.get(e.pair());
                c.add_to((force, torque, touching), e.is_first());
            }
        });
    let p = &world.particles;
    let pairs = list.pairs();
    let mut totals = ContactTotals::of_candidates(p, pairs);
    for (k, c) in results.busy() {
        totals.count(p, pairs[k], c);
    }
    totals
}

/// What a particle carries before its pairs are added: its weight if owned (a ghost
/// gets no force), no torque, and touching if frozen (a frozen particle is part of a
/// bed, whether or not its contacts are evaluated).
#[derive(Clone, Copy)]
pub(super) struct StartLoads<'a> {
    pub owned: usize,
    pub body_type: &'a [u32],
    pub frozen: &'a [bool],
    pub types: &'a [BodyType],
    pub gravity: Vector3<Real>,
}

impl StartLoads<'_> {
    /// Force, torque and touching flag of particle `k` before its pairs.
    #[inline]
    pub(super) fn of(&self, k: usize) -> (Vector3<Real>, Vector3<Real>, bool) {
        if k >= self.owned {
            return (Vector3::zeros(), Vector3::zeros(), false);
        }
        let force = self.gravity * self.types[self.body_type[k] as usize].mass;
        (force, Vector3::zeros(), self.frozen[k])
    }
}

impl PairResult {
    /// Adds the result to the particle that is the pair's first (`first`) or second.
    #[inline(always)]
    pub(super) fn add_to(
        &self,
        (force, torque, touching): (&mut Vector3<Real>, &mut Vector3<Real>, &mut bool),
        first: bool,
    ) {
        let sign = if first { -1.0 } else { 1.0 };
        *touching |= self.touching;
        *force += self.force * sign;
        *torque += self.torques[usize::from(!first)];
    }
}

/// A force evaluation's contacts, summed in pair order, then wall contacts in
/// particle order.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct ContactTotals {
    /// Candidate pairs (of the pair stage).
    pub candidates: usize,
    pub contacts: usize,
    /// Elastic energy held in the contacts, J.
    pub energy: Real,
    /// Energy dissipated over the step, J.
    pub dissipated: Real,
}

impl ContactTotals {
    /// No contacts yet, and the candidate pairs among `pairs` that this world counts
    /// (see [`Particles::counts_pair`]).
    pub(super) fn of_candidates(p: &Particles, pairs: &[[u32; 2]]) -> Self {
        ContactTotals {
            candidates: pairs
                .iter()
                .filter(|&&[i, j]| p.counts_pair(i as usize, j as usize))
                .count(),
            ..Default::default()
        }
    }

    /// Adds pair `[i, j]`'s result if this world counts the pair (see
    /// [`Particles::counts_pair`]); called in pair order. A pair with nothing to do
    /// may be left out: it adds zeros (`x + 0.0` is `x`, and the sums start at +0,
    /// so they are never −0).
    #[inline]
    pub(super) fn count(&mut self, p: &Particles, [i, j]: [u32; 2], c: &PairResult) {
        if !p.counts_pair(i as usize, j as usize) {
            return;
        }
        self.contacts += usize::from(c.touching);
        self.energy += c.energy;
        self.dissipated += c.dissipated;
    }
}
