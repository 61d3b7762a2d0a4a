//! Round contacts under the Hertz–Mindlin law: a sphere against a sphere, a
//! polyhedron or a wall facet, when the scene chose that law (`[contact] law`).
//!
//! A sphere pair takes its own path, without the overlap volume and area the volume
//! law needs: the depth, normal and contact point follow from the two centres, the
//! effective mass is `m₁m₂/(m₁ + m₂)` (the contact point lies on the line of centres,
//! so no rotation enters it), and the angular velocity of an isotropic body is its
//! angular momentum over its moment of inertia.

use nalgebra::Vector3;

use super::forces::{ContactForce, RelativeMotion, ahead, dissipated};
use crate::Real;
use crate::contact::{
    HertzContact, RollingContact, RollingModel, TangentialHistory, hertz_mindlin_force,
    rolling_torque,
};
use crate::engine::laws::{MaterialPair, SphereBody};
use crate::geometry::Shape;
use crate::world::{BodyType, World};

/// What a round contact's law needs besides its geometry and motion.
#[derive(Clone, Copy, Debug)]
pub(super) struct HertzInputs<'a> {
    pub materials: &'a MaterialPair,
    pub rolling: RollingModel,
    /// Effective radius `R*`.
    pub radius: Real,
    /// Rolling inertia about the contact point (see [`crate::contact::rolling_torque`]).
    pub rolling_inertia: Real,
    pub dt: Real,
}

/// The rolling inertia `I + m r²` of body type `t` about a contact at distance `r`.
#[inline]
pub(super) fn rolling_inertia(t: &BodyType, r: Real) -> Real {
    t.inertia.min() + t.mass * r * r
}

/// The force and torque on body 2 of a round contact of `depth` along `normal`, at
/// `lever` from body 2's centroid.
#[inline(always)]
pub(super) fn round_contact_force(
    depth: Real,
    normal: &Vector3<Real>,
    lever: &Vector3<Real>,
    motion: &RelativeMotion,
    law: &HertzInputs,
    history: &TangentialHistory,
) -> ContactForce {
    let c = HertzContact {
        depth,
        normal: *normal,
        relative_velocity: motion.velocity,
        radius: law.radius,
        mass: 1.0 / motion.inverse_mass,
    };
    let m = law.materials;
    let f = hertz_mindlin_force(&c, &m.hertz, m.friction, history, law.dt);
    // The rolling torque and spring as two vectors from either path, not the whole
    // history: a 64-byte history merged from two paths was copied through the stack.
    let lever_torque = lever.cross(&f.force);
    let (torque, resisting, spring) = if law.rolling == RollingModel::None {
        (lever_torque, Vector3::zeros(), f.history.rolling)
    } else {
        let contact = RollingContact {
            normal: *normal,
            relative_spin: motion.spin,
            normal_force: f.normal,
            normal_stiffness: f.stiffness,
            radius: law.radius,
            inertia: law.rolling_inertia,
        };
        let (rolling, spring) = rolling_torque(
            law.rolling,
            &m.rolling,
            &contact,
            &f.history.rolling,
            law.dt,
        );
        (lever_torque + rolling, rolling, spring)
    };
    let kept = TangentialHistory {
        rolling: spring,
        ..f.history
    };
    ContactForce {
        force: f.force,
        torque,
        history: kept,
        energy: f.energy + kept.spring_energy(),
        dissipated: dissipated(
            (
                &(f.force - normal * f.elastic),
                ahead(
                    f.normal,
                    f.elastic,
                    &(f.force - normal * f.normal),
                    f.sliding,
                ),
            ),
            &resisting,
            motion,
            (history, &kept),
            law.dt,
        ),
    }
}

/// The contact of spheres `i` and `j` (body types `a` and `b`), if they overlap:
/// the sphere pair's own path (see the module docs).
#[inline(always)]
pub(super) fn sphere_pair(
    world: &World,
    (i, a): (usize, &SphereBody),
    (j, b): (usize, &SphereBody),
    law: HertzInputs,
    history: &TangentialHistory,
) -> Option<ContactForce> {
    let p = &world.particles;
    let d = p.position[j] - p.position[i];
    let distance_squared = d.norm_squared();
    let reach = a.radius + b.radius;
    if !(distance_squared < reach * reach) || distance_squared == 0.0 {
        return None;
    }
    let distance = distance_squared.sqrt();
    let normal = d * distance.recip();
    let depth = reach - distance;
    // The contact point, and the levers from the centres to it.
    let (ri, rj) = (
        normal * (a.radius - 0.5 * depth),
        normal * -(b.radius - 0.5 * depth),
    );
    let (wi, wj) = (
        p.angular_momentum[i] * a.inverse_inertia,
        p.angular_momentum[j] * b.inverse_inertia,
    );
    let motion = RelativeMotion {
        velocity: p.velocity[j] + wj.cross(&rj) - p.velocity[i] - wi.cross(&ri),
        spin: wj - wi,
        inverse_mass: a.inverse_mass + b.inverse_mass,
        inertia: 0.0,
    };
    Some(round_contact_force(
        depth, &normal, &rj, &motion, &law, history,
    ))
}

/// The radius a body of `shape` brings to a round contact: its own for a sphere,
/// infinite (flat) for a polyhedron.
#[inline]
pub(super) fn round_radius(shape: &Shape) -> Real {
    shape.as_sphere().map_or(Real::INFINITY, |s| s.radius)
}
