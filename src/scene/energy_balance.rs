//! Whether a stretch of a run has diverged although every value stays finite: the
//! energy balance broken grossly, the bed having gained energy that neither the
//! walls nor gravity gave it (the signature of a time step far above the stable one,
//! whose particles then leave the scene at hundreds of m/s). The Component judges
//! each communication step by it, `talus run` every few hundred steps.
//!
//! The balance of a stretch is the change of the run's energy account
//! ([`super::energy_ledger`]): what the steps created beyond the walls' and the
//! fluid's work and the contacts' dissipation. An explicit integrator at a stable
//! step creates a small fraction of a collision's energy (`validation_energy`: 3e-5
//! of the total over 100 collisions per particle). A stretch has diverged when the
//! energy created exceeds the scale of all the energy the scene could hold: the
//! kinetic and elastic energy at the start, the work done on the particles, and the
//! potential energy of lifting the whole bed across the scene's extent. A step that
//! doubles the bed's energy from nothing is caught; what a stable or slightly
//! under-resolved step does is far below it.

use super::Simulation;
use super::energy_ledger::EnergyLedger;
use super::ranks::RunFigures;
use crate::Real;

/// The account at a stretch's start and the scale it is judged against.
#[derive(Clone, Copy, Debug)]
pub struct EnergyBalance {
    /// The account's error at the start, J.
    error: Real,
    /// The account at the start.
    ledger: EnergyLedger,
    /// Kinetic + elastic energy at the start and the bed's potential energy across
    /// the scene's extent, J.
    scale: Real,
}

impl EnergyBalance {
    /// The balance of a stretch that starts now.
    pub fn start(sim: &Simulation) -> Self {
        let held = sim.held_energy();
        let figures = sim.figures();
        let gravity = sim.world().gravity.norm();
        EnergyBalance {
            error: sim.energy().error(held.total()),
            ledger: *sim.energy(),
            scale: held.kinetic
                + held.elastic
                + figures.moments.mass * gravity * extent(sim, &figures),
        }
    }

    /// The energy created since the start, when it is gross.
    pub fn broken(&self, sim: &Simulation) -> Option<String> {
        let held = sim.held_energy();
        let now = sim.energy();
        let created = now.error(held.total()) - self.error;
        let work =
            (now.wall_work - self.ledger.wall_work) + (now.fluid_work - self.ledger.fluid_work);
        let scale = self.scale + work.abs() + (now.motion_in - self.ledger.motion_in);
        (created > scale).then(|| {
            format!(
                "the energy balance is broken: the particles gained {created:.3e} J that neither \
                 the walls and the fluid ({work:.3e} J of work) nor gravity gave them, more than \
                 all the energy the scene holds ({scale:.3e} J; kinetic energy now {:.3e} J); \
                 the time step {:.3e} s is too long for these contacts",
                held.kinetic,
                sim.dt()
            )
        })
    }
}

/// The diagonal of the box around the walls and the particles (whose box
/// `figures` give), m.
fn extent(sim: &Simulation, figures: &RunFigures) -> Real {
    let (mut lo, mut hi) = (figures.lower, figures.upper);
    for wall in &sim.world().walls {
        for v in &wall.vertices {
            let x = wall.pose * v;
            lo = lo.inf(&x);
            hi = hi.sup(&x);
        }
    }
    if lo.x > hi.x {
        return 0.0;
    }
    (hi - lo).norm()
}
