//! Whether a stretch of a run has diverged although every value stays finite: the
//! energy balance broken grossly, the bed having gained energy that neither the
//! walls nor gravity gave it (the signature of a time step far above the stable one,
//! whose particles then leave the scene at hundreds of m/s). The Component judges
//! each communication step by it, `talus run` every few hundred steps.
//!
//! The balance of a stretch: the mechanical energy of the particles present at its
//! start (kinetic + gravitational potential + elastic energy of the contacts) may
//! rise by at most the work the walls delivered; contacts only dissipate. An explicit
//! integrator at a stable step breaks this by a small fraction of a collision's
//! energy (`validation_energy`: 3e-5 of the total over 100 collisions per particle).
//! A step is diverged when the energy created exceeds the scale of all the energy
//! the scene could hold: the kinetic and elastic energy at the start, the walls'
//! work, and the potential energy of lifting the whole bed across the scene's
//! extent. A step that doubles the bed's energy from nothing is caught; what a
//! stable or slightly under-resolved step does is far below it.

use super::Simulation;
use crate::Real;

/// The mechanical energy of a step's start and the scale it is judged against.
#[derive(Clone, Copy, Debug)]
pub struct EnergyBalance {
    /// Particles at the start (inserted ones are not counted after the step).
    particles: usize,
    /// Mechanical energy at the start, J.
    start: Real,
    /// Kinetic + elastic energy at the start and the bed's potential energy across
    /// the scene's extent, J.
    scale: Real,
}

/// Kinetic + gravitational potential energy of the first `n` owned particles, J.
fn particle_energy(sim: &Simulation, n: usize) -> (Real, Real) {
    let w = sim.world();
    let p = &w.particles;
    let (mut kinetic, mut potential) = (0.0, 0.0);
    for i in 0..n.min(p.owned()) {
        kinetic += w.particle_kinetic_energy(i);
        let mass = w.body_types[p.body_type[i] as usize].mass;
        potential -= mass * w.gravity.dot(&p.position[i].coords);
    }
    (kinetic, potential)
}

impl EnergyBalance {
    /// The balance of a stretch that starts now.
    pub fn start(sim: &Simulation) -> Self {
        let w = sim.world();
        let n = w.particles.owned();
        let (kinetic, potential) = particle_energy(sim, n);
        let elastic = sim.stats().elastic_energy;
        let mass: Real = (0..n)
            .map(|i| w.body_types[w.particles.body_type[i] as usize].mass)
            .sum();
        EnergyBalance {
            particles: n,
            start: kinetic + potential + elastic,
            scale: kinetic + elastic + mass * w.gravity.norm() * extent(sim),
        }
    }

    /// The energy created since the start beyond `wall_work` (J the walls delivered
    /// meanwhile), when it is gross.
    pub fn broken(&self, sim: &Simulation, wall_work: Real) -> Option<String> {
        let (kinetic, potential) = particle_energy(sim, self.particles);
        let end = kinetic + potential + sim.stats().elastic_energy;
        let created = end - self.start - wall_work;
        let scale = self.scale + wall_work.abs();
        (created > scale).then(|| {
            format!(
                "the energy balance is broken: the particles gained {created:.3e} J that neither \
                 the walls ({wall_work:.3e} J of work) nor gravity gave them, more than all the \
                 energy the scene holds ({scale:.3e} J; kinetic energy now {kinetic:.3e} J); \
                 the time step {:.3e} s is too long for these contacts",
                sim.dt()
            )
        })
    }
}

/// The diagonal of the box around the walls and the particles, m.
fn extent(sim: &Simulation) -> Real {
    let w = sim.world();
    let mut lo = [Real::INFINITY; 3];
    let mut hi = [Real::NEG_INFINITY; 3];
    let mut add = |x: &[Real]| {
        for k in 0..3 {
            lo[k] = lo[k].min(x[k]);
            hi[k] = hi[k].max(x[k]);
        }
    };
    for wall in &w.walls {
        for v in &wall.vertices {
            add((wall.pose * v).coords.as_slice());
        }
    }
    for x in &w.particles.position[..w.particles.owned()] {
        add(x.coords.as_slice());
    }
    if lo[0] > hi[0] {
        return 0.0;
    }
    (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<Real>().sqrt()
}
