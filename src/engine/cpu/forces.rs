//! Contact geometry and the motion of the bodies → the force and torque of one
//! contact, through the contact laws of [`crate::contact`].

use nalgebra::{Point3, Vector3};

use super::dispatch::ContactGeometry;
use crate::Real;
use crate::contact::{
    DampingTable, NormalContact, PairStiffness, TangentialHistory, normal_force, rocking_damping,
    tangential_force, twisting_friction,
};
use crate::engine::laws::{ContactLaws, PairLaw};
use crate::world::World;

/// The force and torque one contact puts on its second body; the first body gets the
/// opposite force and the torque that balances angular momentum.
#[derive(Clone, Copy, Debug)]
pub(super) struct ContactForce {
    pub force: Vector3<Real>,
    /// Torque on body 2 about its centroid.
    pub torque: Vector3<Real>,
    pub history: TangentialHistory,
    /// Elastic energy stored in the contact's normal law.
    pub energy: Real,
}

impl ContactForce {
    /// Torque on body 1 about `x1`, given body 2's centroid `x2`: what keeps the
    /// pair's angular momentum.
    #[inline]
    pub(super) fn reaction_torque(&self, x1: &Point3<Real>, x2: &Point3<Real>) -> Vector3<Real> {
        -(self.torque + (x2 - x1).cross(&self.force))
    }
}

/// What the gather reads of a pair: the force and the torque on each body and the
/// elastic energy of its contact, all zero when the pair does not touch.
///
/// The contact's history is written beside its pair instead, so that the results
/// array the pair stage writes and the gather reads stays small. The torque on body 1
/// is taken here, where the pair's positions are at hand, and a pair apart adds
/// zeros, so that the gather adds without a branch: its loads of scattered results
/// then overlap instead of waiting on a mispredicted test each.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct PairResult {
    /// Force on body 2; body 1 gets the opposite.
    pub force: Vector3<Real>,
    /// Torque on body 1 ([`ContactForce::reaction_torque`]) and on body 2, each about
    /// its centroid.
    pub torques: [Vector3<Real>; 2],
    pub energy: Real,
    /// Whether the bodies touch.
    pub touching: bool,
}

impl PairResult {
    /// The result of contact `c` between bodies at `x1` and `x2`.
    #[inline]
    pub(super) fn new(c: &ContactForce, x1: &Point3<Real>, x2: &Point3<Real>) -> Self {
        PairResult {
            force: c.force,
            torques: [c.reaction_torque(x1, x2), c.torque],
            energy: c.energy,
            touching: true,
        }
    }
}

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

/// The contact law's inputs that do not depend on the pair.
#[derive(Clone, Copy, Debug)]
pub(super) struct LawInputs<'a> {
    pub stiffness: PairStiffness,
    pub damping: &'a DampingTable,
    pub friction: Real,
    /// Regularisation volume `V₀` of the normal law.
    pub regularisation: Real,
    pub dt: Real,
}

impl<'a> LawInputs<'a> {
    /// The inputs of a contact under `law`, one of `laws`'.
    #[inline]
    pub(super) fn new(laws: &'a ContactLaws, law: &PairLaw, dt: Real) -> Self {
        LawInputs {
            stiffness: law.stiffness,
            damping: laws.damping(law),
            friction: law.friction,
            regularisation: law.regularisation,
            dt,
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

/// Normal and tangential force on body 2 of a contact whose centroid is `centre`.
#[inline]
pub(super) fn contact_force(
    g: &ContactGeometry,
    motion: &RelativeMotion,
    law: &LawInputs,
    history: TangentialHistory,
    centre: &Point3<Real>,
) -> ContactForce {
    let (damping, dt) = (law.damping, law.dt);
    let relative_velocity = motion.velocity;
    let effective_mass = 1.0 / motion.inverse_mass;
    let normal = normal_force(
        &NormalContact {
            volume: g.volume,
            area: g.area,
            depth: g.depth,
            normal: g.normal,
            relative_velocity,
            effective_mass,
            stiffness: law.stiffness.normal,
            regularisation: law.regularisation,
            dt,
        },
        damping,
    );
    let kt = law.stiffness.tangential * g.area;
    let ct = 2.0 * damping.zeta(1.0) * (effective_mass * kt).sqrt();
    let t = tangential_force(
        &history,
        &g.normal,
        &relative_velocity,
        dt,
        kt,
        ct,
        law.friction * normal.force.norm(),
    );
    let force = normal.force + t.force;
    let rocking = if g.depth > 0.0 {
        rocking_damping(
            &motion.spin,
            &g.normal,
            g.area,
            normal.exponent * normal.elastic / g.depth,
            motion.inertia,
            damping.zeta(1.0),
            dt,
        )
    } else {
        Vector3::zeros()
    };
    let (twisting, twist) = twisting_friction(
        history.twist,
        &motion.spin,
        &g.normal,
        g.area,
        kt,
        motion.inertia,
        law.friction * normal.force.norm(),
        dt,
    );
    let torque = rocking
        + twisting
        + match g.rotation_gradient {
            // Elastic part from the potential (U' = elastic / area); damping and friction,
            // measured at the contact point, act there.
            Some(rotation) if g.area > 0.0 => {
                let elastic = g.normal * normal.elastic;
                -(normal.elastic / g.area) * rotation + (g.point - centre).cross(&(force - elastic))
            }
            _ => (g.point - centre).cross(&force),
        };
    ContactForce {
        force,
        torque,
        history: TangentialHistory { twist, ..t.history },
        energy: normal.energy,
    }
}

/// The force on particle `j` of its contact with particle `i` of geometry `g`.
#[inline]
pub(super) fn pair_force(
    world: &World,
    i: usize,
    j: usize,
    g: &ContactGeometry,
    history: TangentialHistory,
    laws: &ContactLaws,
    dt: Real,
) -> ContactForce {
    let p = &world.particles;
    let law = laws.pair(p.body_type[i], p.body_type[j]);
    let (wi, wj) = (world.angular_velocity(i), world.angular_velocity(j));
    let motion = RelativeMotion {
        velocity: velocity_at(world, j, &wj, &g.point) - velocity_at(world, i, &wi, &g.point),
        spin: wj - wi,
        inverse_mass: inverse_mass_at(world, i, &g.point, &g.normal)
            + inverse_mass_at(world, j, &g.point, &g.normal),
        inertia: law.inertia,
    };
    contact_force(
        g,
        &motion,
        &LawInputs::new(laws, &law, dt),
        history,
        &p.position[j],
    )
}
