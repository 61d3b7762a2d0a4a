//! A simulation on one rank of a decomposed run (`mpirun -np N talus run`): its
//! world is the rank's share (see [`crate::engine::rank`]); what the host reads of
//! the whole run is reduced over the ranks once per step, and the whole world is
//! gathered on rank 0 when an output needs it.
//!
//! **Once per step**, after the inlets: every rank sends every rank the sums of its
//! share (the contacts' counts and energies, the particles' count, mass, kinetic
//! and potential energy, the energy of the particles it inserted, each wall's
//! force and torque), its largest speed, its bounding box and its first
//! non-finite particle; each rank folds them in rank order, so every rank holds the
//! same bits. The walls of every rank's world then carry the whole run's forces
//! and torques, and the energy ledger books the whole run's step: all ranks keep
//! the same ledger, end a run at the same step (settled, diverged) and report the
//! same figures. They are not the bits of one process (the sums are grouped by
//! rank), but agree with it to round-off.

use std::borrow::Cow;
use std::fmt;

use nalgebra::{Point3, Vector3};

use super::Scene;
use super::Simulation;
use super::energy_ledger::{EnergyLedger, HeldEnergy};
use super::fluid_ranks::whole_fluid;
use crate::Real;
use crate::analysis::packing::{Bed, bed_height_of, measured_from};
use crate::engine::choice::ShareBackend;
use crate::engine::decomposition::Decomposition;
use crate::engine::exchange::Exchange;
use crate::engine::rank::{ParticleRecord, Share, all_gather, gather_to_first};
use crate::engine::{ContactHistory, StepStats};
pub use crate::world::RunFigures;
use crate::world::{MassMoments, Particles, World};

/// The ranks bisect the space again at a list renewal where the most loaded rank's
/// cost exceeds the mean by this factor: a fifth more work on one rank costs a
/// fifth of the step, a new bisection moves a share of the particles once.
pub const REBALANCE_ABOVE: Real = 1.2;

/// What a rank's host knows of the whole run after a step.
#[derive(Clone, Copy, Debug)]
pub(super) struct WholeRun {
    /// The step's figures summed over the ranks (the neighbour-list builds are
    /// this rank's, the same on all).
    pub stats: StepStats,
    pub figures: RunFigures,
}

impl Simulation {
    /// Starts a scene at time 0 on the ranks of `exchange` (every rank calls it
    /// with the same scene): every rank inserts what is due at 0 into the whole
    /// world, as one process does, bisects the space at the particles (at the
    /// walls when there are none yet) and keeps its share; then, as one process,
    /// splits the particles among a coupled fluid's cells and evaluates the first
    /// forces. The ranks step their shares on `backend` (opened for this rank).
    pub fn on_ranks<E: Exchange + Send + fmt::Debug + 'static>(
        scene: &Scene,
        backend: ShareBackend,
        exchange: E,
    ) -> Self {
        let mut world = scene.world.clone();
        let mut inlets = scene.inlets.clone();
        let mut next_id = scene.next_id;
        for inlet in &mut inlets {
            inlet.insert_due(&mut world, 0.0, &mut next_id);
        }
        // Coded as one process starts (each rank keeps the places).
        world.refresh_space_order(false);
        let seeds = seeds_of(&world);
        let layout = Decomposition::bisect(&seeds, &vec![1.0; seeds.len()], exchange.size());
        let stepper = backend.stepper(
            (exchange, layout, scene.step_params()),
            &mut world,
            &ContactHistory::default(),
            StepStats::default(),
            REBALANCE_ABOVE,
        );
        let mut sim = Simulation::assemble(scene, world, stepper);
        sim.inlets = inlets;
        sim.next_id = next_id;
        sim.update_fluid();
        sim.backend.initialise(&mut sim.world, sim.dt);
        sim.reduce_over_ranks(HeldEnergy::default(), 0.0);
        sim.energy = EnergyLedger::new(&sim.held_energy());
        sim
    }

    /// This rank and the number of ranks, on ranks.
    pub fn rank(&self) -> Option<(usize, usize)> {
        self.backend.share().map(|s| (s.rank(), s.ranks()))
    }

    /// Whether any rank passes `true` (collective on ranks; `mine` in one process).
    pub fn any_rank(&self, mine: bool) -> bool {
        match self.backend.share() {
            Some(share) => all_gather(share, &[mine]).concat().into_iter().any(|b| b),
            None => mine,
        }
    }

    /// The whole world: this one in one process; on ranks (collective) the owned
    /// particles of every rank in id order, with the walls' facet forces summed and
    /// a coupled fluid as one process holds it, on rank 0, and `None` on the others.
    pub fn whole_world(&self) -> Option<Cow<'_, World>> {
        let Some(share) = self.backend.share() else {
            return Some(Cow::Borrowed(&self.world));
        };
        let p = &self.world.particles;
        let records: Vec<ParticleRecord> =
            (0..p.owned()).map(|i| ParticleRecord::of(p, i)).collect();
        let records = gather_to_first(share, &records);
        let total = sum_facet_forces(share, self.world.walls.iter().map(|w| &w.facet_force));
        let fluid = whole_fluid(share, &self.world);
        if share.rank() != 0 {
            return None;
        }
        let mut whole = world_of(&self.world, records.into_iter().flatten().collect());
        spread_facet_forces(&total, whole.walls.iter_mut().map(|w| &mut w.facet_force));
        whole.fluid = fluid;
        Some(Cow::Owned(whole))
    }

    /// Every wall's facet forces summed over the ranks: in one process the world's;
    /// on ranks (collective) on rank 0, and `None` on the others.
    pub fn whole_facet_forces(&self) -> Option<Vec<Vec<Vector3<Real>>>> {
        let facets = self.world.walls.iter().map(|w| &w.facet_force);
        let Some(share) = self.backend.share() else {
            return Some(facets.cloned().collect());
        };
        let total = sum_facet_forces(share, facets);
        if share.rank() != 0 {
            return None;
        }
        let mut whole: Vec<_> = self
            .world
            .walls
            .iter()
            .map(|w| w.facet_force.clone())
            .collect();
        spread_facet_forces(&total, whole.iter_mut());
        Some(whole)
    }

    /// On ranks (collective): folds every rank's share of the step, of the
    /// particles inserted after it (`inserted`, their energy) and of the kinetic
    /// energy frozen (`freezing`) into the whole run's figures, and gives the walls
    /// the whole run's forces and torques. Returns the energy inserted and frozen
    /// on all ranks. In one process: the same.
    pub(super) fn reduce_over_ranks(
        &mut self,
        inserted: HeldEnergy,
        freezing: Real,
    ) -> (HeldEnergy, Real) {
        let local = *self.backend.stats();
        let whole = {
            let Some(share) = self.backend.share() else {
                return (inserted, freezing);
            };
            let figures = match self.backend_figures {
                Some(figures) if self.particles_behind => figures,
                _ => RunFigures::of(&self.world),
            };
            let mine = Shares::of(&self.world, figures, &local, &inserted, freezing);
            let all = all_gather(share, &mine.0).into_iter().map(Shares);
            all.reduce(Shares::fold).expect("at least one rank")
        };
        let (whole, inserted, freezing) = whole.unpack(&mut self.world, local);
        self.whole = Some(whole);
        (inserted, freezing)
    }
}

/// One rank's figures as a list of numbers: the sums first, then the maxima, the
/// minima, and six sums per wall.
struct Shares(Vec<Real>);

const SUMS: usize = 18;
const MAXIMA: usize = 4;
const MINIMA: usize = 4;

impl Shares {
    /// `f`: the figures of this rank's particles.
    fn of(
        world: &World,
        f: RunFigures,
        stats: &StepStats,
        inserted: &HeldEnergy,
        freezing: Real,
    ) -> Self {
        let mut v = vec![
            stats.contacts as Real,
            stats.pair_contacts as Real,
            stats.candidate_pairs as Real,
            stats.integrated as Real,
            stats.elastic_energy,
            stats.dissipated,
            stats.fluid_work,
            f.particles as Real,
            f.frozen as Real,
            f.moments.mass,
            f.moments.first.x,
            f.moments.first.y,
            f.moments.first.z,
            f.kinetic,
            f.potential,
            inserted.kinetic,
            inserted.potential,
            freezing,
        ];
        v.extend([f.max_speed, f.upper.x, f.upper.y, f.upper.z]);
        v.extend([f.lower.x, f.lower.y, f.lower.z]);
        // Ids below 2^53 are exact as floats.
        v.push(f.non_finite.map_or(Real::INFINITY, |id| id as Real));
        for w in &world.walls {
            v.extend(w.force.iter().chain(w.torque.iter()));
        }
        Shares(v)
    }

    /// `self` (the ranks before) and `next` (the next rank).
    fn fold(mut self, next: Shares) -> Shares {
        for (k, (a, b)) in self.0.iter_mut().zip(&next.0).enumerate() {
            *a = if (SUMS..SUMS + MAXIMA).contains(&k) {
                a.max(*b)
            } else if (SUMS + MAXIMA..SUMS + MAXIMA + MINIMA).contains(&k) {
                a.min(*b)
            } else {
                *a + b
            };
        }
        self
    }

    /// The whole run's figures (`local`: this rank's stats, for what is not summed)
    /// and the energy of the particles inserted and frozen; gives `world`'s walls the whole
    /// run's forces and torques.
    fn unpack(self, world: &mut World, local: StepStats) -> (WholeRun, HeldEnergy, Real) {
        let v = self.0;
        let (sums, rest) = v.split_at(SUMS);
        let (maxima, rest) = rest.split_at(MAXIMA);
        let (minima, walls) = rest.split_at(MINIMA);
        let [
            contacts,
            pair_contacts,
            candidate_pairs,
            integrated,
            elastic_energy,
            dissipated,
            fluid_work,
            particles,
            frozen,
            mass,
            mx,
            my,
            mz,
            kinetic,
            potential,
            inserted_kinetic,
            inserted_potential,
            freezing,
        ] = sums.try_into().expect("the sums of Shares::of");
        let [max_speed, ux, uy, uz] = maxima.try_into().expect("the maxima");
        let [lx, ly, lz, non_finite] = minima.try_into().expect("the minima");
        let count = |x: Real| x as usize;
        let stats = StepStats {
            contacts: count(contacts),
            pair_contacts: count(pair_contacts),
            candidate_pairs: count(candidate_pairs),
            integrated: count(integrated),
            elastic_energy,
            dissipated,
            fluid_work,
            ..local
        };
        let figures = RunFigures {
            particles: count(particles),
            frozen: count(frozen),
            moments: MassMoments {
                mass,
                first: Vector3::new(mx, my, mz),
            },
            kinetic,
            potential,
            max_speed,
            upper: Point3::new(ux, uy, uz),
            lower: Point3::new(lx, ly, lz),
            non_finite: non_finite.is_finite().then_some(non_finite as u64),
        };
        let inserted = HeldEnergy {
            kinetic: inserted_kinetic,
            potential: inserted_potential,
            elastic: 0.0,
        };
        for (w, sums) in world.walls.iter_mut().zip(walls.chunks(6)) {
            w.force = Vector3::new(sums[0], sums[1], sums[2]);
            w.torque = Vector3::new(sums[3], sums[4], sums[5]);
        }
        (WholeRun { stats, figures }, inserted, freezing)
    }
}

/// A world like `like` holding `records`' particles in id order (the order of one
/// process, whose ids ascend with insertion), without a fluid.
fn world_of(like: &World, mut records: Vec<ParticleRecord>) -> World {
    records.sort_unstable_by_key(|r| r.id);
    let mut particles = Particles::default();
    for r in &records {
        r.push_into(&mut particles);
    }
    // Everything but the particles as `like` holds it (not a copy of its share).
    World {
        materials: like.materials.clone(),
        body_types: like.body_types.clone(),
        particles,
        walls: like.walls.clone(),
        gravity: like.gravity,
        time: like.time,
        fluid: None,
    }
}

/// The bed height one process measures, on ranks (collective): rank 0 measures
/// the bed's particles near its top (`member`s of every rank whose top lies above
/// where [`bed_height_of`] integrates from), which it integrates in id order as
/// one process does, and every rank gets its answer. `None` when there is no bed yet.
pub(super) fn bed_height_on_ranks(
    share: &dyn Share,
    world: &World,
    bed: &Bed,
    member: &[bool],
    last: Option<Real>,
) -> Option<Real> {
    let from = measured_from(world, last);
    let p = &world.particles;
    let near_top: Vec<ParticleRecord> = (0..p.owned())
        .filter(|&i| member[i] && bed.tube.top_of(world, i) > from)
        .map(|i| ParticleRecord::of(p, i))
        .collect();
    let gathered = gather_to_first(share, &near_top);
    let height: Vec<Real> = if share.rank() == 0 {
        let top = world_of(world, gathered.into_iter().flatten().collect());
        let all = vec![true; top.particles.len()];
        bed_height_of(&top, bed, &all, last)
            .ok()
            .into_iter()
            .collect()
    } else {
        Vec::new()
    };
    all_gather(share, &height)[0].first().copied()
}

/// Where a bisection starts: the particles' centroids, or the walls' vertices when
/// there are no particles yet.
pub(super) fn seeds_of(world: &World) -> Vec<Point3<Real>> {
    if !world.particles.is_empty() {
        return world.particles.position.clone();
    }
    world
        .walls
        .iter()
        .flat_map(|w| w.vertices.iter().map(|v| w.pose * v))
        .collect()
}

/// Every wall's facet forces (`walls`: each wall's, all walls' facets in a row)
/// summed over the ranks in rank order, on rank 0 (collective; empty on the
/// others).
pub(super) fn sum_facet_forces<'a>(
    share: &dyn Share,
    walls: impl Iterator<Item = &'a Vec<Vector3<Real>>>,
) -> Vec<Vector3<Real>> {
    let facets: Vec<Vector3<Real>> = walls.flatten().copied().collect();
    sum_on_first(share, &facets)
}

/// Every rank's `mine` (as long on every rank) summed element by element in rank
/// order, on rank 0 (collective; empty on the others).
pub(super) fn sum_on_first(share: &dyn Share, mine: &[Vector3<Real>]) -> Vec<Vector3<Real>> {
    let mut ranks = gather_to_first(share, mine).into_iter();
    let first = ranks.next().unwrap_or_default();
    ranks.fold(first, |mut total, other| {
        for (t, o) in total.iter_mut().zip(&other) {
            *t += o;
        }
        total
    })
}

/// Puts `total` (all walls' facets in a row, as [`sum_facet_forces`] gives them)
/// into each wall's `facets`.
pub(super) fn spread_facet_forces<'a>(
    total: &[Vector3<Real>],
    facets: impl Iterator<Item = &'a mut Vec<Vector3<Real>>>,
) {
    let mut at = 0;
    for f in facets {
        let n = f.len();
        f.copy_from_slice(&total[at..at + n]);
        at += n;
    }
}
