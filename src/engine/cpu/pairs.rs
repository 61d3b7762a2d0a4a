//! A candidate pair's contact and a block's pairs evaluated in pair order: what the
//! pair sweep ([`super::fused`]) adds to the particles.

use nalgebra::Vector3;

use super::blocks::{BLOCK, BusyBits};
use super::contact_state::held_mask;
use super::dispatch::pair_geometry;
use super::forces::{ContactForce, PairResult, RelativeMotion, pair_force};
use super::hertz::{HertzInputs, rolling_inertia, round_contact_force, round_radius, sphere_pair};
use super::overlap_plans::record;
use super::prefetch::PairPrefetch;
use crate::Real;
use crate::contact::{RollingModel, TangentialHistory, effective_radius};
use crate::engine::RoundLaw;
use crate::engine::laws::ContactLaws;
use crate::geometry::overlap::OverlapCache;
use crate::world::{BodyType, Particles, World};

/// The laws of the pair stage.
#[derive(Clone, Copy, Debug)]
pub(super) struct PairLaws<'a> {
    pub laws: &'a ContactLaws,
    pub round: RoundLaw,
    pub dt: Real,
}

/// The result of the contact of particles `i` and `j` whose bounding spheres overlap,
/// under the scene's laws, if they touch, with `history` replaced by the one the
/// contact leaves; `plan` is the pair's kept overlap plan.
#[inline(always)]
fn pair_contact(
    world: &World,
    i: usize,
    j: usize,
    plan: &mut OverlapCache,
    history: &mut TangentialHistory,
    laws: &PairLaws,
) -> Option<PairResult> {
    let p = &world.particles;
    // Each law's contact becomes the pair's result on its own path: a contact merged
    // from the paths was kept on the stack, and read back by loads that straddled
    // its stores (a failed store forwarding at every contact).
    let finish = |c: ContactForce, history: &mut TangentialHistory| {
        *history = c.history;
        Some(PairResult::new(&c, &p.position[i], &p.position[j]))
    };
    let RoundLaw::HertzMindlin { rolling } = laws.round else {
        let g = pair_geometry(world, i, j, plan)?;
        return finish(
            pair_force(world, i, j, &g, *history, laws.laws, laws.dt),
            history,
        );
    };
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
            finish(sphere_pair(world, (i, a), (j, b), law, history)?, history)
        }
        (None, None) => {
            let g = pair_geometry(world, i, j, plan)?;
            finish(
                pair_force(world, i, j, &g, *history, laws.laws, laws.dt),
                history,
            )
        }
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
            let c = round_contact_force(
                g.depth,
                &g.normal,
                &(g.point - p.position[j]),
                &motion,
                &law,
                history,
            );
            finish(c, history)
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
#[inline(always)]
pub(super) fn evaluate_pair(
    world: &World,
    laws: &PairLaws,
    ([i, j], near): ([u32; 2], bool),
    history: &mut TangentialHistory,
    plan: &mut OverlapCache,
) -> PairResult {
    let (i, j) = (i as usize, j as usize);
    if near && let Some(c) = pair_contact(world, i, j, plan, history, laws) {
        return c;
    }
    // A pair that stays apart keeps its empty history unwritten.
    if history.is_empty() {
        return PairResult::default();
    }
    let parted = PairResult::parted(history);
    *history = TangentialHistory::default();
    parted
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
    let (mask, sifted_near) = to_evaluate(sift, p, radii, pairs, *held);
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
        // A sifted block's near pairs are known: testing them again took 4 % of
        // the one-thread pair stage of the settled bed of spheres.
        let near = match sifted_near {
            Some(bits) => (bits >> k) & 1 == 1,
            None => near(p, radii, pairs[k]),
        };
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
/// holding a history) and, where they were sifted, the mask of those [`near`]: if
/// `sift`, the busy ones ([`near_pairs`] or holding a history), else all of them
/// (an evaluation of a pair with nothing to do leaves it as it was). Sifting pays
/// where the pairs are spheres; among polyhedra, whose overlap plans the callers
/// pass, most candidates' bounding spheres overlap, the branch is foreseen, and
/// sifting first cost about 4 % of the dense bed of `talus bench` (a) on one thread.
#[inline(always)]
fn to_evaluate(
    sift: bool,
    p: &Particles,
    radii: &[Real],
    pairs: &[[u32; 2]],
    held: u64,
) -> (u64, Option<u64>) {
    if sift {
        let near = near_pairs(p, radii, pairs);
        (near | held, Some(near))
    } else {
        (u64::MAX >> (BLOCK - pairs.len()), None)
    }
}

/// The mask of the pairs of a block (at most [`BLOCK`]) that are [`near`]: with the
/// pairs holding a history (which parting lets go), those with something to do.
/// Found without a branch per pair: whether a pair touches is as good as a coin
/// toss in a dense bed, and a mispredicted branch for every other candidate pair
/// cost the sweep about a fifth of its time. The histories themselves are not read:
/// in a bed of spheres about half of the candidate pairs are apart, and reading
/// their 64-byte histories to learn that they are empty was a line from memory for
/// each.
#[inline(always)]
fn near_pairs(p: &Particles, radii: &[Real], pairs: &[[u32; 2]]) -> u64 {
    debug_assert!(pairs.len() <= BLOCK);
    let mut near_mask = 0u64;
    for (k, &pair) in pairs.iter().enumerate() {
        near_mask |= u64::from(near(p, radii, pair)) << k;
    }
    near_mask
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

impl<'a> StartLoads<'a> {
    /// The start of every particle of `world`.
    pub(super) fn of(world: &'a World) -> Self {
        let p = &world.particles;
        StartLoads {
            owned: p.owned(),
            body_type: &p.body_type,
            frozen: &p.frozen,
            types: &world.body_types,
            gravity: world.gravity,
        }
    }

    /// Force, torque and touching flag of particle `k` before its pairs.
    #[inline(always)]
    pub(super) fn of_particle(&self, k: usize) -> (Vector3<Real>, Vector3<Real>, bool) {
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
/// particle order. The pairs' energies are summed block by block: each block of
/// [`BLOCK`] pairs from zero in pair order, then the blocks' sums in block order,
/// so that the parts of a sweep on many threads each sum their own blocks and the
/// bits do not depend on the number of parts.
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
        // Without ghosts every pair counts: the pass over the pairs, serial, took
        // 2 % of a step of a settled bed of spheres.
        let candidates = if p.ghosts() == 0 {
            pairs.len()
        } else {
            (pairs.iter())
                .filter(|&&[i, j]| p.counts_pair(i as usize, j as usize))
                .count()
        };
        ContactTotals {
            candidates,
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

    /// Adds the contacts of `block` (a block's sums, [`Self::count`]ed from zero).
    #[inline]
    pub(super) fn add_block(&mut self, block: &ContactTotals) {
        self.contacts += block.contacts;
        self.energy += block.energy;
        self.dissipated += block.dissipated;
    }
}
