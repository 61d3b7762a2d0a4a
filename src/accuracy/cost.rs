//! What a setting costs: a short run of the user's own scene at it, from a state
//! the scene reaches at its own settings.

use std::ops::ControlFlow;
use std::time::{Duration, Instant};

use serde::Serialize;

use crate::Real;
use crate::scene::{Scene, SimState, Simulation, StateError};

/// Steps every cost run takes at least (a few list rebuilds' worth).
pub const MIN_STEPS: u64 = 20;

/// The cost of one setting on the user's scene.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Cost {
    /// Particles in the measured stretch.
    pub particles: usize,
    /// Contacts per step, mean over the stretch.
    pub contacts: Real,
    /// Steps timed.
    pub steps: u64,
    /// Wall-clock seconds per step.
    pub seconds_per_step: Real,
    /// Particle-steps per wall-clock second.
    pub particle_steps_per_second: Real,
    /// Contacts evaluated per wall-clock second.
    pub contacts_per_second: Real,
    /// Wall-clock seconds to the scene's end at this rate: `end_time / dt` steps.
    pub seconds_to_end: Real,
}

/// The state the cost runs start from: the scene run at its own settings to half
/// its end time, or as far as `budget` of wall-clock time takes it.
pub fn warm_state(scene: &Scene, budget: Duration) -> SimState {
    let mut sim = Simulation::new(scene);
    let start = Instant::now();
    let end = 0.5 * scene.spec.simulation.end_time;
    let _ = sim.advance_to(end, |_, _| {
        if start.elapsed() >= budget {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    });
    sim.snapshot()
}

/// Runs `scene` (a setting of the user's scene) from `state` for `budget` of
/// wall-clock time (at least [`MIN_STEPS`] steps) and measures its rate.
pub fn measure(scene: &Scene, state: &SimState, budget: Duration) -> Result<Cost, StateError> {
    let mut sim = Simulation::new(scene);
    sim.restore(state)?;
    sim.set_time_step(scene.dt);
    // The first step after a restore builds the lists: measured apart.
    sim.step();
    let (mut steps, mut contacts, mut particles) = (0u64, 0usize, 0usize);
    let start = Instant::now();
    while steps < MIN_STEPS || start.elapsed() < budget {
        sim.step();
        steps += 1;
        contacts += sim.stats().contacts;
        particles += sim.world().particles.owned();
    }
    let seconds = start.elapsed().as_secs_f64();
    let per_step = seconds / steps as Real;
    let steps_to_end = scene.spec.simulation.end_time / scene.dt;
    Ok(Cost {
        particles: particles / steps as usize,
        contacts: contacts as Real / steps as Real,
        steps,
        seconds_per_step: per_step,
        particle_steps_per_second: particles as Real / seconds,
        contacts_per_second: contacts as Real / seconds,
        seconds_to_end: per_step * steps_to_end,
    })
}
