//! One rank of a decomposed run: it owns the particles whose centroids lie in its
//! box of a [`Decomposition`], holds ghost copies of the others' particles within
//! reach, and steps its share with a [`ShareStepper`] (the [`CpuBackend`], or a
//! device backend) so that every particle moves to the same bits as in one
//! process.
//!
//! **A step.** The opening kick and drift of the owned particles; the ghosts'
//! states refreshed from their owners; if any rank's lists are stale (one answer
//! for all, as one process would decide), the renewal: particles whose centroid
//! left the box move to their new owner with their contact history, and the ghosts
//! are chosen again; then the forces (the lists rebuilt where renewed) and the
//! closing kick. Ghosts are copied bit for bit, each pair is evaluated the same way
//! round on every rank that holds it (the neighbour lists orient pairs by particle
//! id and sort them by the particles' space keys, which ghosts carry from their
//! owners), and each particle gathers its pairs in its partners' key order, so an
//! owned particle's force is the one-process force to the bit.
//!
//! **History.** A pair's tangential history lives on every rank that holds the
//! pair with one of its particles owned there, computed identically on each; at a
//! renewal a leaving particle takes the history of its pairs and its wall patches
//! with it, and what it brings overrides the new rank's copy (a pair of two ghosts
//! is not evaluated, so that copy may be stale). So does its row of a coupled
//! fluid's cell shares.

use std::collections::BTreeMap;
use std::ops::Range;

use nalgebra::Point3;

use super::backend::ContactHistory;
use super::cpu::CpuBackend;
use super::decomposition::Decomposition;
use super::exchange::Exchange;
use super::neighbours::automatic_skin;
use super::params::StepParams;
use super::stats::StepStats;
use crate::Real;
use crate::world::World;

mod backend;
mod cost;
mod insertion;
mod records;
mod share;
mod stepper;

pub use cost::{PARTICLE_COST, POLYHEDRON_PAIR_COST, particle_costs};
pub use records::ParticleRecord;
use records::{Migrant, history_of};
pub use share::{Share, all_gather, all_to_all, gather_to_first};
pub use stepper::ShareStepper;

/// Steps one rank's share of a decomposed world.
///
/// Invariant: the world holds the owned particles (centroid in this rank's box at
/// the last renewal) first, then the ghosts in the order of `sends` of the ranks
/// before and after this one (rank order, then the sender's order).
#[derive(Debug)]
pub struct RankStepper<E: Exchange, B: ShareStepper = CpuBackend> {
    exchange: E,
    decomposition: Decomposition,
    reach: Real,
    backend: B,
    /// For each rank, the owned particles copied there as ghosts.
    sends: Vec<Vec<usize>>,
    /// No skin was set: it follows the smallest particle of the whole run at each
    /// renewal, as one process's lists choose it at each build.
    automatic_skin: bool,
    /// Bisect again at a renewal where the cost imbalance exceeds this.
    rebalance_above: Option<Real>,
    imbalance: Real,
    rebalances: usize,
    migrated: usize,
    renewals: usize,
}

impl<E: Exchange> RankStepper<E> {
    /// Takes this rank's share of `world` (every rank passes the same world and
    /// decomposition): keeps the particles it owns, adds the ghosts within reach
    /// (twice the largest bounding radius of a body type plus the skin), and
    /// evaluates the forces for a first step of `dt` on the CPU backend. `history`
    /// is the whole run's tangential history (of a restored state; empty for a
    /// fresh start): the rank keeps what concerns its own particles. Without a
    /// skin in `params` the ranks choose it from the whole run's particles at
    /// every renewal, as one process chooses it at every list build.
    pub fn new(
        exchange: E,
        decomposition: Decomposition,
        params: StepParams,
        world: &mut World,
        history: &ContactHistory,
        dt: Real,
    ) -> Self {
        let at = (exchange, decomposition, params);
        Self::new_with(at, world, history, dt, CpuBackend::new)
    }

    /// Takes this rank's share of a restored `world` as [`RankStepper::new`] does,
    /// but as one process's restore takes a state: the owned particles keep the
    /// forces `world` holds (those of the step that ended), and `stats` are the last
    /// figures, so the next step continues the saved run to the bit.
    pub fn restored(
        exchange: E,
        decomposition: Decomposition,
        params: StepParams,
        world: &mut World,
        history: &ContactHistory,
        stats: StepStats,
    ) -> Self {
        let at = (exchange, decomposition, params);
        Self::restored_with(at, world, history, stats, CpuBackend::new)
    }
}

impl<E: Exchange, B: ShareStepper> RankStepper<E, B> {
    /// [`RankStepper::new`] on the backend `make` gives for the step parameters
    /// (their skin set).
    pub fn new_with(
        at: (E, Decomposition, StepParams),
        world: &mut World,
        history: &ContactHistory,
        dt: Real,
        make: impl FnOnce(StepParams) -> B,
    ) -> Self {
        let mut rank = Self::restored_with(at, world, history, StepStats::default(), make);
        rank.backend.initialise(world, dt);
        rank
    }

    /// [`RankStepper::restored`] on the backend `make` gives for the step
    /// parameters (their skin set).
    pub fn restored_with(
        (exchange, decomposition, mut params): (E, Decomposition, StepParams),
        world: &mut World,
        history: &ContactHistory,
        stats: StepStats,
        make: impl FnOnce(StepParams) -> B,
    ) -> Self {
        assert_eq!(exchange.size(), decomposition.ranks(), "one box per rank");
        // Every rank holds the whole world here: its own radii are everyone's.
        let automatic = params.skin.is_none();
        let skin = *params.skin.get_or_insert_with(|| {
            automatic_skin(&bounding_radii(world, 0..world.particles.len()))
        });
        let reach = reach_of(world, skin);
        let me = exchange.rank();
        world.particles.clear_ghosts();
        let positions = world.particles.position.clone();
        world
            .particles
            .remove_where(|i| decomposition.owner(&positions[i]) != me);
        let mut rank = RankStepper {
            sends: vec![Vec::new(); exchange.size()],
            automatic_skin: automatic,
            exchange,
            decomposition,
            reach,
            backend: make(params),
            rebalance_above: None,
            imbalance: 1.0,
            rebalances: 0,
            migrated: 0,
            renewals: 0,
        };
        let p = &world.particles;
        let mine = ContactHistory {
            pairs: history
                .pairs
                .iter()
                .filter(|((a, b), _)| p.index_of(*a).is_some() || p.index_of(*b).is_some())
                .copied()
                .collect(),
            walls: history
                .walls
                .iter()
                .filter(|(key, _)| p.index_of(key.0).is_some())
                .copied()
                .collect(),
        };
        rank.choose_ghosts(world);
        rank.backend.restore(world, mine, stats);
        rank
    }

    /// Bisects the space again at a list renewal where the largest rank's cost
    /// exceeds `threshold` times the mean (see [`particle_costs`]).
    pub fn rebalance_above(mut self, threshold: Real) -> Self {
        self.rebalance_above = Some(threshold);
        self
    }

    /// The cost imbalance (largest rank's cost over the mean) at the last renewal
    /// that measured it (1 before any).
    pub fn imbalance(&self) -> Real {
        self.imbalance
    }

    /// New bisections so far.
    pub fn rebalances(&self) -> usize {
        self.rebalances
    }

    /// The boxes in use.
    pub fn decomposition(&self) -> &Decomposition {
        &self.decomposition
    }

    /// How this rank talks to the others.
    pub fn exchange(&self) -> &E {
        &self.exchange
    }

    /// The backend (figures and lists of this rank's share).
    pub fn backend(&self) -> &B {
        &self.backend
    }

    /// How far from its box a particle is copied as a ghost.
    pub fn reach(&self) -> Real {
        self.reach
    }

    /// Particles that arrived here from other ranks so far.
    pub fn migrated(&self) -> usize {
        self.migrated
    }

    /// List renewals so far (the same on every rank).
    pub fn renewals(&self) -> usize {
        self.renewals
    }

    /// One step of length `dt` (every rank calls it together).
    pub fn step(&mut self, world: &mut World, dt: Real) {
        self.backend.drift(world, dt);
        self.refresh_ghosts(world);
        let stale = self.exchange.any(self.backend.is_stale(world));
        if stale {
            self.backend.sync_to_host(world);
            self.renew(world);
        }
        self.backend.forces(world, dt);
        self.backend.close(world, dt);
    }

    /// Copies the owned particles' states to the ranks where they are ghosts.
    fn refresh_ghosts(&mut self, world: &mut World) {
        self.backend.owned_to_host(world, &self.sends);
        let received = self.send_ghost_states(world);
        let p = &mut world.particles;
        for (k, record) in received.iter().flatten().enumerate() {
            record.set_state(p, p.owned() + k);
        }
        self.backend.ghosts_from_host(world);
    }

    /// Sends the states of the owned particles in `sends` to their ranks; returns
    /// what the other ranks sent this one, in rank order.
    fn send_ghost_states(&self, world: &World) -> Vec<Vec<ParticleRecord>> {
        let p = &world.particles;
        let outgoing = self
            .sends
            .iter()
            .map(|list| list.iter().map(|&i| ParticleRecord::of(p, i)).collect())
            .collect();
        self.exchange.all_to_all(outgoing)
    }

    /// Moves the particles that left the box to their owners, with their history,
    /// and chooses the ghosts again.
    fn renew(&mut self, world: &mut World) {
        self.renewals += 1;
        if self.automatic_skin {
            self.follow_smallest_particle(world);
        }
        if let Some(threshold) = self.rebalance_above {
            self.rebalance(world, threshold);
        }
        let me = self.exchange.rank();
        let mut history = self.backend.contact_history();
        let p = &world.particles;
        let owned_here = |id: u64| p.index_of(id).is_some_and(|i| !p.is_ghost(i));
        history
            .pairs
            .retain(|((a, b), _)| owned_here(*a) || owned_here(*b));
        let mut outgoing: Vec<Vec<Migrant>> = vec![Vec::new(); self.exchange.size()];
        let owners: Vec<usize> = (0..p.owned())
            .map(|i| self.decomposition.owner(&p.position[i]))
            .collect();
        let leaving = |i: usize| owners.get(i).is_some_and(|&o| o != me);
        let mut gone = Vec::new();
        let fluid = world.fluid.as_ref();
        for (i, &owner) in owners.iter().enumerate().filter(|&(i, _)| leaving(i)) {
            gone.push(p.id[i]);
            outgoing[owner].push(Migrant {
                particle: ParticleRecord::of(p, i),
                history: history_of(&history, p.id[i]),
                fluid_share: fluid.and_then(|f| f.shares.row_of(p.id[i])),
            });
        }
        history.walls.retain(|(key, _)| !gone.contains(&key.0));
        world.particles.clear_ghosts();
        world.particles.remove_where(leaving);

        let arrived: Vec<Vec<Migrant>> = self.exchange.all_to_all(outgoing);
        let mut pairs: BTreeMap<_, _> = history.pairs.into_iter().collect();
        let mut walls: BTreeMap<_, _> = history.walls.into_iter().collect();
        let stayed = world.particles.id.clone();
        let mut fluid_shares = Vec::new();
        for m in arrived.into_iter().flatten() {
            m.particle.push_into(&mut world.particles);
            pairs.extend(m.history.pairs);
            walls.extend(m.history.walls);
            fluid_shares.extend(m.fluid_share.map(|row| (m.particle.id, row)));
            self.migrated += 1;
        }
        if let Some(fluid) = world.fluid.as_mut() {
            fluid.shares = fluid.shares.keep(&stayed, &fluid_shares);
        }
        self.choose_ghosts(world);
        let stats = *self.backend.stats();
        let history = ContactHistory {
            pairs: pairs.into_iter().collect(),
            walls: walls.into_iter().collect(),
        };
        // The history is matched to the pairs when the lists are built again.
        self.backend.restore(world, history, stats);
    }

    /// Sets the skin one process would choose for the whole run's particles now
    /// (from the smallest bounding radius of every rank's owned particles), and the
    /// reach with it.
    fn follow_smallest_particle(&mut self, world: &World) {
        let size = self.exchange.size();
        let radii = bounding_radii(world, 0..world.particles.owned());
        let mine = radii.into_iter().fold(Real::INFINITY, Real::min);
        let smallest = self
            .exchange
            .all_to_all(vec![vec![mine]; size])
            .concat()
            .into_iter()
            .fold(Real::INFINITY, Real::min);
        let skin = automatic_skin(&[smallest]);
        let mut params = *self.backend.params();
        params.skin = Some(skin);
        self.backend.set_params(params);
        self.reach = reach_of(world, skin);
    }

    /// Measures the imbalance (every rank's total cost to every rank) and, above
    /// `threshold`, bisects every rank's centroids and costs again: each rank gets
    /// all of them and computes the same boxes, whatever order they came in.
    fn rebalance(&mut self, world: &World, threshold: Real) {
        let size = self.exchange.size();
        let cost = self.backend.costs(world);
        let total: Real = cost.iter().sum();
        let totals = self.exchange.all_to_all(vec![vec![total]; size]).concat();
        let mean = totals.iter().sum::<Real>() / size as Real;
        let most = totals.iter().copied().fold(0.0, Real::max);
        self.imbalance = if mean > 0.0 { most / mean } else { 1.0 };
        if self.imbalance <= threshold {
            return;
        }
        let mine: Vec<(Point3<Real>, Real)> =
            world.particles.position.iter().copied().zip(cost).collect();
        let (centroids, costs): (Vec<_>, Vec<_>) = self
            .exchange
            .all_to_all(vec![mine; size])
            .into_iter()
            .flatten()
            .unzip();
        self.decomposition = Decomposition::bisect(&centroids, &costs, size);
        self.rebalances += 1;
    }

    /// Sends copies of the owned particles within reach of other boxes there and
    /// appends the copies received as ghosts.
    fn choose_ghosts(&mut self, world: &mut World) {
        let me = self.exchange.rank();
        let p = &world.particles;
        for list in &mut self.sends {
            list.clear();
        }
        for i in 0..p.owned() {
            for r in self
                .decomposition
                .ghost_ranks(&p.position[i], me, self.reach)
            {
                self.sends[r].push(i);
            }
        }
        let received = self.send_ghost_states(world);
        let p = &mut world.particles;
        for r in received.iter().flatten() {
            p.push_ghost(r.body_type, r.position, r.orientation, r.id);
            let i = p.len() - 1;
            r.set_state(p, i);
        }
    }
}

/// The bounding radii of the particles `among`.
fn bounding_radii(world: &World, among: Range<usize>) -> Vec<Real> {
    let p = &world.particles;
    among
        .map(|i| {
            world.body_types[p.body_type[i] as usize]
                .shape
                .circumradius()
        })
        .collect()
}

/// How far from its box a particle is copied as a ghost: two of the largest
/// bounding radii of any body type and the skin.
fn reach_of(world: &World, skin: Real) -> Real {
    let largest = world
        .body_types
        .iter()
        .map(|t| t.shape.circumradius())
        .fold(0.0, Real::max);
    2.0 * largest + skin
}
