//! The energy a perfectly elastic, frictionless collision keeps.
//!
//! Two particles of one kind, turned at random, meet off-centre (the impact
//! parameter a third of the circumradius) at the impact speed, with restitution 1
//! and no friction and no gravity. The exact answer keeps the kinetic energy
//! (translation and rotation) of the pair; what a run gains or loses is the time
//! integration's error, which a smaller step shrinks.

use nalgebra::{Point3, Vector3};
use rand::SeedableRng;
use rand_pcg::Pcg64;

use super::setup;
use crate::Real;
use crate::scene::{Scene, Simulation};
use crate::world::random_orientation;

/// Collisions per kind (orientations drawn from a fixed seed).
pub const COLLISIONS: usize = 3;

/// `(E_after − E_before) / E_before` of the worst of [`COLLISIONS`] elastic
/// collisions of each of the scene's first kinds (up to [`super::KINDS_CHECKED`])
/// with itself, at closing speed `speed`.
pub fn elastic_energy_error(scene: &Scene, speed: Real) -> Real {
    let mut rng = Pcg64::seed_from_u64(0x7a15);
    let mut worst: Real = 0.0;
    for kind in 0..scene.world.body_types.len().min(super::KINDS_CHECKED) {
        for _ in 0..COLLISIONS {
            let qa = random_orientation(&mut rng);
            let qb = random_orientation(&mut rng);
            let error = collision(scene, kind, [qa, qb], speed);
            if error.abs() > worst.abs() || !error.is_finite() {
                worst = error;
            }
        }
    }
    worst
}

fn collision(
    scene: &Scene,
    kind: usize,
    q: [nalgebra::UnitQuaternion<Real>; 2],
    speed: Real,
) -> Real {
    let t = &scene.world.body_types[kind];
    let r = t.shape.circumradius();
    let mut world = setup::world(scene, setup::elastic, vec![t.clone()], Vec::new());
    let x = 1.01 * r;
    let p = &mut world.particles;
    p.push(0, Point3::new(-x, 0.0, 0.0), q[0], 0);
    p.push(0, Point3::new(x, r / 3.0, 0.0), q[1], 1);
    p.velocity[0] = Vector3::new(0.5 * speed, 0.0, 0.0);
    p.velocity[1] = Vector3::new(-0.5 * speed, 0.0, 0.0);
    let before = world.kinetic_energy();
    let mut sim = Simulation::new(&scene.reference(world));
    let end = setup::contact_deadline(scene, r, speed);
    let parted = setup::until_parted(&mut sim, end, |_| 0.0);
    if !parted.ended {
        return Real::INFINITY;
    }
    sim.world().kinetic_energy() / before - 1.0
}
