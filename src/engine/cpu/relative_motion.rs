//! How two bodies move against each other at a contact point: what the contact
//! laws read of the bodies' motion.

use nalgebra::{Point3, Vector3};

use crate::Real;
use crate::world::{Wall, World};

/// How body 2 moves relative to body 1 at a contact, and how hard it is to move.
#[derive(Clone, Copy, Debug)]
pub(super) struct RelativeMotion {
    /// Velocity at the contact point.
    pub velocity: Vector3<Real>,
    /// Angular velocity.
    pub spin: Vector3<Real>,
    /// Inverse effective mass at the contact point along the normal.
    pub inverse_mass: Real,
    /// Effective moment of inertia `1/(1/I₁ + 1/I₂)` (smallest principal moments).
    pub inertia: Real,
}

impl RelativeMotion {
    /// Particle `j` against particle `i` at `point`, along `normal`.
    #[inline]
    pub(super) fn of_pair(
        world: &World,
        [i, j]: [usize; 2],
        point: &Point3<Real>,
        normal: &Vector3<Real>,
        inertia: Real,
    ) -> Self {
        let (wi, wj) = (world.angular_velocity(i), world.angular_velocity(j));
        RelativeMotion {
            velocity: velocity_at(world, j, &wj, point) - velocity_at(world, i, &wi, point),
            spin: wj - wi,
            inverse_mass: inverse_mass_at(world, i, point, normal)
                + inverse_mass_at(world, j, point, normal),
            inertia,
        }
    }

    /// Particle `i`, turning at `spin`, against `wall` at `point`, where its inverse
    /// effective mass is `inverse_mass` (the particle's angular velocity is taken once
    /// for all its wall contacts). The wall's motion is prescribed: its velocity now
    /// is its velocity at the step's end.
    #[inline]
    pub(super) fn of_wall(
        world: &World,
        (i, spin): (usize, &Vector3<Real>),
        wall: &Wall,
        point: &Point3<Real>,
        (inverse_mass, inertia): (Real, Real),
    ) -> Self {
        RelativeMotion {
            velocity: velocity_at(world, i, spin, point) - wall.velocity_at(point),
            spin: spin - wall.angular_velocity,
            inverse_mass,
            inertia,
        }
    }
}

/// Inverse of the effective mass of particle `i` at `point` along `n`: the lever
/// `r × n` taken into the body frame, where the inertia is diagonal.
#[inline]
pub(super) fn inverse_mass_at(
    world: &World,
    i: usize,
    point: &Point3<Real>,
    n: &Vector3<Real>,
) -> Real {
    let p = &world.particles;
    let t = &world.body_types[p.body_type[i] as usize];
    let lever = p.orientation[i].inverse_transform_vector(&(point - p.position[i]).cross(n));
    1.0 / t.mass + lever.component_div(&t.inertia).dot(&lever)
}

/// Velocity of particle `i`'s material at `point`, given its angular velocity.
#[inline]
pub(super) fn velocity_at(
    world: &World,
    i: usize,
    angular_velocity: &Vector3<Real>,
    point: &Point3<Real>,
) -> Vector3<Real> {
    world.particles.velocity[i] + angular_velocity.cross(&(point - world.particles.position[i]))
}
