//! Saved states of a run on ranks: the whole run's state gathered on rank 0, the
//! state one process saves but for the particles' order (here by id; one process
//! saves them as it stores them, in the space order), with the contact history
//! sorted by key, so that a state saved by N ranks restores on M ranks or in one
//! process, and one saved by one process restores on ranks.

use std::fmt;

use nalgebra::Vector3;

use super::Scene;
use super::Simulation;
use super::energy_ledger::HeldEnergy;
use super::fluid_ranks::{keep_fluid_share, whole_exchange};
use super::ranks::{REBALANCE_ABOVE, seeds_of, spread_facet_forces, sum_facet_forces};
use super::state::SimState;
use super::state_bytes::StateError;
use crate::Real;
use crate::engine::choice::ShareBackend;
use crate::engine::decomposition::Decomposition;
use crate::engine::exchange::Exchange;
use crate::engine::rank::{ParticleRecord, gather_to_first};
use crate::engine::{ContactHistory, CpuBackend};
use crate::world::Particles;

/// A particle as a saved state holds it: its state, and the force and torque of
/// the step that ended (the next half kick's).
type SavedParticle = (ParticleRecord, (Vector3<Real>, Vector3<Real>));

/// One rank's share of the whole run's state, taken without talking to the other
/// ranks (a component takes one before every step, to go back to it if the step
/// diverges); [`Simulation::gather_state`] makes the whole state of it. In one
/// process it is the whole state.
#[derive(Clone, Debug)]
pub struct ShareState {
    /// This rank's particles with their forces, the contact history this rank
    /// counts, its share of the facet forces; the rest as every rank holds it,
    /// with the whole run's figures.
    state: SimState,
}

impl ShareState {
    /// Steps taken when it was taken.
    pub fn steps(&self) -> u64 {
        self.state.steps
    }
}

impl Simulation {
    /// This rank's share of the state (see [`ShareState`]; no collective).
    pub fn share_snapshot(&self) -> ShareState {
        let mut state = self.snapshot();
        if self.backend.share().is_none() {
            return ShareState { state };
        }
        state.stats = *self.stats();
        // A pair's history from the one rank that counts it (the other may hold a
        // stale copy); a patch's from its particle's owner.
        let p = &self.world.particles;
        let counted = |a: u64, b: u64| match (p.index_of(a), p.index_of(b)) {
            (Some(i), Some(j)) => p.counts_pair(i, j),
            _ => false,
        };
        state.history.pairs.retain(|((a, b), _)| counted(*a, *b));
        state
            .history
            .walls
            .retain(|(key, _)| p.index_of(key.0).is_some_and(|i| !p.is_ghost(i)));
        ShareState { state }
    }

    /// The whole run's state of every rank's `share` (taken at the same step): in
    /// one process the share itself; on ranks (collective) gathered on rank 0 (the
    /// state one process saves: particles in id order with their forces, history
    /// sorted by key, a fluid's shares and drag in id order with the impulse
    /// summed), and `None` on the others.
    pub fn gather_state(&self, share: ShareState) -> Option<SimState> {
        let ShareState { mut state } = share;
        let Some(ranks) = self.backend.share() else {
            return Some(state);
        };
        let p = &state.particles;
        let particles: Vec<SavedParticle> = (0..p.owned())
            .map(|i| (ParticleRecord::of(p, i), (p.force[i], p.torque[i])))
            .collect();
        let particles = gather_to_first(ranks, &particles);
        let histories = gather_to_first(ranks, &[std::mem::take(&mut state.history)]);
        let facets = sum_facet_forces(ranks, state.walls.iter().map(|w| &w.facet_force));
        let ids = &p.id[..p.owned()];
        let exchange = state
            .fluid
            .as_ref()
            .map(|f| whole_exchange(ranks, ids, &f.shares, &f.exchange));
        if ranks.rank() != 0 {
            return None;
        }
        if let (Some(f), Some(Some((shares, exchange)))) = (state.fluid.as_mut(), exchange) {
            f.shares = shares;
            f.exchange = exchange;
        }
        state.particles = saved_particles(particles.into_iter().flatten().collect());
        let mut history = ContactHistory::default();
        for h in histories.into_iter().flatten() {
            history.pairs.extend(h.pairs);
            history.walls.extend(h.walls);
        }
        history.pairs.sort_unstable_by_key(|e| e.0);
        history.walls.sort_unstable_by_key(|e| e.0);
        state.history = history;
        spread_facet_forces(&facets, state.walls.iter_mut().map(|w| &mut w.facet_force));
        Some(state)
    }

    /// The whole run's state: in one process [`Simulation::snapshot`]; on ranks
    /// (collective) gathered on rank 0, and `None` on the others.
    pub fn whole_snapshot(&self) -> Option<SimState> {
        self.gather_state(self.share_snapshot())
    }

    /// A run of `scene` on the ranks of `exchange` that continues from `state` (the
    /// whole run's, as [`Simulation::whole_snapshot`] or one process saved it;
    /// every rank passes the same): each rank keeps its share, the particles with
    /// the saved forces, and the next step continues the saved run to the bit
    /// (on `backend`, opened for this rank).
    pub fn on_ranks_from<E: Exchange + Send + fmt::Debug + 'static>(
        scene: &Scene,
        backend: ShareBackend,
        exchange: E,
        state: &SimState,
    ) -> Result<Self, StateError> {
        let params = scene.step_params();
        let mut sim = Simulation::assemble(
            scene,
            scene.world.clone(),
            Box::new(CpuBackend::new(params)),
        );
        sim.restore(state)?;
        let mut world = sim.world.clone();
        let seeds = seeds_of(&world);
        let layout = Decomposition::bisect(&seeds, &vec![1.0; seeds.len()], exchange.size());
        let rank = exchange.rank();
        let stepper = backend.stepper(
            (exchange, layout, params),
            &mut world,
            &state.history,
            Default::default(),
            REBALANCE_ABOVE,
        );
        if let Some(fluid) = &state.fluid {
            keep_fluid_share(&mut world, fluid, &state.particles.id, rank);
        }
        sim.world = world;
        sim.particles_behind = false;
        sim.backend = stepper;
        sim.reduce_over_ranks(HeldEnergy::default(), 0.0);
        // The walls and figures of the step that ended, as saved (the ranks' own
        // start from nothing).
        for (wall, saved) in sim.world.walls.iter_mut().zip(&state.walls) {
            wall.force = saved.force;
            wall.torque = saved.torque;
        }
        if let Some(whole) = &mut sim.whole {
            whole.stats = state.stats;
        }
        Ok(sim)
    }
}

/// Particles as a saved state holds them, in id order.
fn saved_particles(mut saved: Vec<SavedParticle>) -> Particles {
    saved.sort_unstable_by_key(|(r, _)| r.id);
    let mut p = Particles::default();
    for (r, (force, torque)) in &saved {
        r.push_into(&mut p);
        let i = p.owned() - 1;
        p.force[i] = *force;
        p.torque[i] = *torque;
    }
    p
}
