//! What a rank steps its share with: a backend whose step the rank splits where
//! the ghosts are refreshed and where the lists are renewed.
//!
//! The CPU backend steps the host world itself, so its halo calls do nothing; a
//! device backend (`engine::cuda`) copies the states of the particles sent as
//! ghosts down before the exchange and the ghosts' states up after it.

use super::cost::particle_costs;
use crate::Real;
use crate::engine::backend::Backend;
use crate::engine::cpu::CpuBackend;
use crate::world::World;

/// A backend that steps a rank's share (see the module).
///
/// A step of a rank is [`drift`](Self::drift), the ghosts refreshed (the sent
/// particles' states [`owned_to_host`](Self::owned_to_host), exchanged, the
/// received ones [`ghosts_from_host`](Self::ghosts_from_host)), the vote on
/// [`is_stale`](Self::is_stale) and, if any rank votes yes, the renewal (the host
/// world brought up to date by [`Backend::sync_to_host`] first, the backend given
/// the new share by [`Backend::restore`] after), then [`forces`](Self::forces) and
/// [`close`](Self::close).
pub trait ShareStepper: Backend {
    /// The opening half kick and the drift of the owned particles, and the walls
    /// moved to the step's end.
    fn drift(&mut self, world: &mut World, dt: Real);

    /// Brings the motion state of the owned entries of `sends` (per rank, the
    /// particles sent there as ghosts) in the host world up to date.
    fn owned_to_host(&mut self, world: &mut World, sends: &[Vec<usize>]);

    /// The ghosts' states (motion and frozen flag) were set in the host world.
    fn ghosts_from_host(&mut self, world: &World);

    /// Whether this rank's lists must be rebuilt before the forces.
    fn is_stale(&mut self, world: &World) -> bool;

    /// The forces of the step.
    fn forces(&mut self, world: &mut World, dt: Real);

    /// The closing half kick of the owned particles.
    fn close(&mut self, world: &mut World, dt: Real);

    /// Each owned particle's share of the step's cost, for the bisection's
    /// weights.
    fn costs(&self, world: &World) -> Vec<Real>;
}

impl ShareStepper for CpuBackend {
    fn drift(&mut self, world: &mut World, dt: Real) {
        CpuBackend::drift(self, world, dt);
    }

    /// The host world is the backend's: nothing to copy.
    fn owned_to_host(&mut self, _world: &mut World, _sends: &[Vec<usize>]) {}

    /// The host world is the backend's: nothing to copy.
    fn ghosts_from_host(&mut self, _world: &World) {}

    fn is_stale(&mut self, world: &World) -> bool {
        self.neighbours().is_stale(world)
    }

    fn forces(&mut self, world: &mut World, dt: Real) {
        CpuBackend::forces(self, world, dt);
    }

    fn close(&mut self, world: &mut World, dt: Real) {
        CpuBackend::close(self, world, dt);
    }

    /// Its own cost and half of each candidate pair's (see [`particle_costs`]).
    fn costs(&self, world: &World) -> Vec<Real> {
        particle_costs(world, self.neighbours())
    }
}
