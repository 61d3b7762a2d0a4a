//! A running scene: world, engine and inlets advanced step by step, with the
//! settling criterion.

use nalgebra::Vector3;

use super::Scene;
use super::spec::{FreezeSpec, SettleSpec};
use crate::Real;
use crate::analysis::packing::{Bed, bed_height_of};
use crate::engine::step::Engine;
use crate::world::{Inlet, World};

/// A scene being simulated.
#[derive(Clone, Debug)]
pub struct Simulation {
    /// The state.
    pub world: World,
    /// The CPU engine (time step, contact history).
    pub engine: Engine,
    /// Particle sources.
    pub inlets: Vec<Inlet>,
    /// Steps taken.
    pub steps: u64,
    /// End time of the run.
    pub end_time: Real,
    pub(super) next_id: u64,
    settle: Option<SettleSpec>,
    pub(super) quiet_since: Option<Real>,
    /// The bed whose height stops inlets fed "until a bed height", moves inlets fed
    /// above it, and below which particles freeze.
    bed: Option<Bed>,
    freeze: Option<FreezeSpec>,
    /// The bed height last measured while feeding or freezing.
    pub(super) bed_height: Option<Real>,
}

/// Simulated time between two measurements of the bed height (while inlets feed
/// until a height or above the bed, or the bed freezes): a few pellets' worth of
/// feeding at usual rates, and the exact volume integration it costs stays far below
/// the steps in between.
pub const BED_HEIGHT_INTERVAL: Real = 5e-3;

/// Figures of the state after a step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepReport {
    /// Simulated time.
    pub time: Real,
    /// Particles in the world.
    pub particles: usize,
    /// Contacts in the last force evaluation.
    pub contacts: usize,
    /// Largest particle speed.
    pub max_speed: Real,
    /// Total kinetic energy.
    pub kinetic_energy: Real,
}

impl Simulation {
    /// Starts a scene at time 0 (inlets insert what is due at 0).
    pub fn new(scene: &Scene) -> Self {
        let mut engine = Engine::new(scene.dt);
        engine.regularisation_length = scene.spec.contact.regularisation;
        engine.neighbours.skin = scene.spec.contact.skin;
        let mut sim = Simulation {
            world: scene.world.clone(),
            engine,
            inlets: scene.inlets.clone(),
            steps: 0,
            end_time: scene.spec.simulation.end_time,
            next_id: scene.next_id,
            settle: scene.spec.simulation.settle.clone(),
            quiet_since: None,
            bed: scene.bed,
            freeze: scene.spec.bed.as_ref().and_then(|b| b.freeze.clone()),
            bed_height: None,
        };
        sim.insert();
        sim.engine.initialise(&mut sim.world);
        sim
    }

    /// Simulated time.
    pub fn time(&self) -> Real {
        self.world.time
    }

    /// Whether the end time is reached.
    pub fn is_finished(&self) -> bool {
        self.world.time >= self.end_time - 1e-9 * self.engine.dt
    }

    /// Advances one time step, then lets inlets insert what is due.
    pub fn step(&mut self) {
        let before = self.world.time;
        self.engine.step(&mut self.world);
        self.steps += 1;
        self.follow_bed(before);
        self.insert();
        self.update_settling();
    }

    fn insert(&mut self) {
        let first = self.world.particles.len();
        let t = self.world.time;
        for inlet in &mut self.inlets {
            inlet.insert_due(&mut self.world, t, &mut self.next_id);
        }
        // New particles feel gravity in their first half kick.
        let p = &mut self.world.particles;
        for i in first..p.len() {
            p.force[i] = self.world.gravity * self.world.body_types[p.body_type[i] as usize].mass;
            p.torque[i] = Vector3::zeros();
        }
    }

    /// Measures the bed height once per [`BED_HEIGHT_INTERVAL`] of simulated time (at
    /// its multiples, so a restored run measures when the original did) while
    /// something depends on it: stops the inlets whose bed height is reached, moves
    /// those fed above the bed, and freezes the buried particles.
    fn follow_bed(&mut self, before: Real) {
        let Some(bed) = &self.bed else { return };
        let feeding = |i: &Inlet| (i.stop_height.is_some() || i.above_bed) && !i.is_done();
        if !(self.freeze.is_some() || self.inlets.iter().any(feeding))
            || (before / BED_HEIGHT_INTERVAL).floor()
                == (self.world.time / BED_HEIGHT_INTERVAL).floor()
        {
            return;
        }
        // The bed: what touches something and moves slower than half of √(g d)
        // (not particles in flight, nor those sliding down the tube wall). Nothing
        // yet: no bed.
        let w = &self.world;
        let p = &w.particles;
        let g = w.gravity.norm();
        let member: Vec<bool> = (0..p.len())
            .map(|i| {
                let d = 2.0
                    * w.body_types[p.body_type[i] as usize]
                        .shape
                        .equivalent_radius();
                self.engine.touching().get(i) == Some(&true)
                    && p.velocity[i].norm() < 0.5 * (g * d).sqrt()
            })
            .collect();
        let Ok(height) = bed_height_of(w, bed, &member, self.bed_height) else {
            return;
        };
        self.bed_height = Some(height);
        for inlet in self.inlets.iter_mut().filter(|i| feeding(i)) {
            if inlet.stop_height.is_some_and(|h| height >= h) {
                inlet.stop();
            }
            if inlet.above_bed {
                inlet.offset = bed.tube.axis * height;
            }
        }
        // The pairs of frozen particles drop out of the force loop, not out of the
        // candidate lists: no rebuild is needed.
        if let Some(freeze) = &self.freeze {
            freeze_buried(&mut self.world, bed, freeze, height, &member);
        }
    }

    /// Figures of the current state.
    pub fn report(&self) -> StepReport {
        StepReport {
            time: self.world.time,
            particles: self.world.particles.len(),
            contacts: self.engine.contacts,
            max_speed: self.max_speed(),
            kinetic_energy: self.world.kinetic_energy(),
        }
    }

    /// Largest particle speed (translation).
    pub fn max_speed(&self) -> Real {
        self.world.max_speed()
    }

    /// Whether every inlet has inserted all its particles.
    pub fn inlets_done(&self) -> bool {
        self.inlets.iter().all(Inlet::is_done)
    }

    /// Whether the scene's settling criterion has held long enough.
    pub fn is_settled(&self) -> bool {
        match (&self.settle, self.quiet_since) {
            (Some(s), Some(since)) => self.world.time - since >= s.hold,
            _ => false,
        }
    }

    fn update_settling(&mut self) {
        let Some(s) = &self.settle else { return };
        let n = self.world.particles.len().max(1) as Real;
        let quiet = self.world.time >= s.after
            && self.inlets_done()
            && self.max_speed() < s.max_speed
            && self.world.kinetic_energy() / n < s.kinetic_energy_per_particle;
        self.quiet_since = match (quiet, self.quiet_since) {
            (true, None) => Some(self.world.time),
            (true, since) => since,
            (false, _) => None,
        };
    }
}

/// Freezes the particles in `member` (the bed) that are slower than the freeze speed
/// and whose bounding sphere lies wholly more than the freeze depth below `height`.
fn freeze_buried(world: &mut World, bed: &Bed, freeze: &FreezeSpec, height: Real, member: &[bool]) {
    let p = &world.particles;
    let buried: Vec<usize> = (0..p.len())
        .filter(|&i| {
            member[i]
                && !p.frozen[i]
                && bed.tube.top_of(world, i) < height - freeze.depth
                && p.velocity[i].norm() < freeze.max_speed
        })
        .collect();
    for i in buried {
        world.particles.freeze(i);
    }
}
