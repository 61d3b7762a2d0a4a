//! Inlets on ranks: the particles one process would insert, each on the rank whose
//! box holds its centroid.
//!
//! An inlet places particles clear of the bounding spheres near its box and of the
//! walls, drawing from its own random stream. Every rank holds the same inlets and
//! walls and receives from every rank the owned particles near a due inlet's box:
//! it sees the obstacles one process sees (in another order, which the clearance
//! test does not depend on), draws the same numbers and places the same particles
//! with the same ids. It keeps those in its box; their ids make its lists stale,
//! so the next step renews every rank's lists and the others get them as ghosts.

use nalgebra::Point3;

use super::RankStepper;
use super::stepper::ShareStepper;
use crate::Real;
use crate::engine::exchange::Exchange;
use crate::world::{Inlet, Obstacle, World};

impl<E: Exchange, B: ShareStepper> RankStepper<E, B> {
    /// Lets the `inlets` insert what is due at the world's time. Every rank calls
    /// it after the same step with the same inlets and `next_id`, which advance
    /// alike on all. A new particle owned here gets its weight as the force of its
    /// first half kick, as in one process. Returns the particles placed on all
    /// ranks. Inlets that follow the bed (`stop_height`, `above_bed`) are moved
    /// by the caller from the whole run's bed height, as `Simulation` does.
    pub fn insert(&self, world: &mut World, inlets: &mut [Inlet], next_id: &mut u64) -> usize {
        let (t, me, size) = (world.time, self.exchange.rank(), self.exchange.size());
        let mut placed_here_and_there = 0;
        for inlet in inlets.iter_mut().filter(|inlet| inlet.is_due(t)) {
            let near: Vec<(Point3<Real>, Real)> = inlet
                .obstacles(world, 0..world.particles.owned())
                .into_iter()
                .map(|o| (o.centre, o.radius))
                .collect();
            let obstacles = self
                .exchange
                .all_to_all(vec![near; size])
                .into_iter()
                .flatten()
                .map(|(centre, radius)| Obstacle { centre, radius })
                .collect();
            let placed = inlet.place_due(world, obstacles, t, next_id);
            placed_here_and_there += placed.len();
            let mine = placed
                .iter()
                .filter(|q| self.decomposition.owner(&q.position) == me);
            let first = world.particles.owned();
            for particle in mine {
                particle.push_into(&mut world.particles);
            }
            world.weigh(first..world.particles.owned());
        }
        placed_here_and_there
    }
}
