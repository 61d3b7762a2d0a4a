//! Figures of a world's owned particles: what a run on ranks reduces over the
//! ranks every step, and what a backend that holds the particles elsewhere (a GPU)
//! can compute where they are.

use nalgebra::Point3;

use super::{MassMoments, World};
use crate::Real;

/// Figures of the whole run's particles (of a world's owned particles, or summed
/// over the ranks).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RunFigures {
    /// Particles.
    pub particles: usize,
    /// Of them, frozen.
    pub frozen: usize,
    /// Their mass and its first moment.
    pub moments: MassMoments,
    /// Kinetic energy, J.
    pub kinetic: Real,
    /// Potential energy in gravity (zero at the origin), J.
    pub potential: Real,
    /// Largest speed, m/s.
    pub max_speed: Real,
    /// Corners of the box around the centroids (inverted when there is none).
    pub lower: Point3<Real>,
    pub upper: Point3<Real>,
    /// The smallest id of a particle whose state is not finite.
    pub non_finite: Option<u64>,
}

impl RunFigures {
    /// The figures of `world`'s owned particles.
    pub fn of(world: &World) -> Self {
        let p = &world.particles;
        let n = p.owned();
        let (kinetic, potential) = world.kinetic_and_potential(0..n);
        let mut lower = Point3::from([Real::INFINITY; 3]);
        let mut upper = Point3::from([Real::NEG_INFINITY; 3]);
        for x in &p.position[..n] {
            lower = lower.inf(x);
            upper = upper.sup(x);
        }
        let non_finite = if p.all_finite() {
            None
        } else {
            (0..n).filter(|&i| !p.is_finite(i)).map(|i| p.id[i]).min()
        };
        RunFigures {
            particles: n,
            frozen: p.frozen_count(),
            moments: world.mass_moments(),
            kinetic,
            potential,
            max_speed: world.max_speed(),
            lower,
            upper,
            non_finite,
        }
    }
}

impl World {
    /// The kinetic energy (translation and rotation) and the potential energy in
    /// gravity (zero at the origin) of the particles `range`, J, summed in order.
    pub fn kinetic_and_potential(&self, range: std::ops::Range<usize>) -> (Real, Real) {
        let p = &self.particles;
        let (mut kinetic, mut potential) = (0.0, 0.0);
        for i in range {
            kinetic += self.particle_kinetic_energy(i);
            let mass = self.body_types[p.body_type[i] as usize].mass;
            potential -= mass * self.gravity.dot(&p.position[i].coords);
        }
        (kinetic, potential)
    }
}
