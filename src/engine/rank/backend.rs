//! A rank behind the backend seam: a [`crate::scene::Simulation`] whose world is one
//! rank's share steps it through [`RankStepper`], and reaches the other ranks
//! through [`Backend::share`].
//!
//! The sync calls go to the rank's CPU backend. A change that invalidates its lists
//! (particles removed, the world changed) makes the next step's vote renew every
//! rank's lists, which chooses the ghosts again; velocities set on owned particles
//! reach their ghosts with the next step's refresh.

use std::fmt;
use std::ops::Range;

use super::RankStepper;
use super::share::Share;
use super::stepper::ShareStepper;
use crate::Real;
use crate::engine::backend::{Backend, ContactHistory};
use crate::engine::exchange::Exchange;
use crate::engine::params::StepParams;
use crate::engine::stats::{StageTimes, StepStats};
use crate::world::{RunFigures, World};

impl<E: Exchange + Send + fmt::Debug, B: ShareStepper> Backend for RankStepper<E, B> {
    fn name(&self) -> &'static str {
        self.backend.name()
    }

    fn params(&self) -> &StepParams {
        self.backend.params()
    }

    /// Without a skin the ranks keep following the smallest particle.
    fn set_params(&mut self, mut params: StepParams) {
        self.automatic_skin = params.skin.is_none();
        if params.skin.is_none() {
            params.skin = self.backend.params().skin;
        }
        self.backend.set_params(params);
    }

    fn initialise(&mut self, world: &mut World, dt: Real) {
        self.backend.initialise(world, dt);
    }

    fn step(&mut self, world: &mut World, dt: Real) {
        RankStepper::step(self, world, dt);
    }

    /// This rank's share (see [`StepStats`]).
    fn stats(&self) -> &StepStats {
        self.backend.stats()
    }

    fn stage_times(&self) -> &StageTimes {
        self.backend.stage_times()
    }

    fn touching(&self) -> &[bool] {
        self.backend.touching()
    }

    fn particles_added(&mut self, world: &World, added: Range<usize>) {
        self.backend.particles_added(world, added);
    }

    fn particles_frozen(&mut self, world: &World, frozen: &[usize]) {
        self.backend.particles_frozen(world, frozen);
    }

    fn particles_removed(&mut self, world: &World) {
        self.backend.particles_removed(world);
    }

    fn velocities_set(&mut self, world: &World) {
        self.backend.velocities_set(world);
    }

    fn walls_moved(&mut self, world: &World) {
        self.backend.walls_moved(world);
    }

    fn fluid_changed(&mut self, world: &World) {
        self.backend.fluid_changed(world);
    }

    fn world_changed(&mut self, world: &World) {
        self.backend.world_changed(world);
    }

    /// The history of the pairs and patches this rank holds.
    fn contact_history(&self) -> ContactHistory {
        self.backend.contact_history()
    }

    fn restore(&mut self, world: &World, history: ContactHistory, stats: StepStats) {
        self.backend.restore(world, history, stats);
    }

    fn sync_to_host(&mut self, world: &mut World) {
        self.backend.sync_to_host(world);
    }

    fn particles_on_host(&self) -> bool {
        self.backend.particles_on_host()
    }

    /// This rank's share.
    fn particle_figures(&mut self) -> Option<RunFigures> {
        self.backend.particle_figures()
    }

    fn share(&self) -> Option<&dyn Share> {
        Some(self)
    }
}
