//! Rolling resistance of round contacts: a torque against the relative rolling of the
//! two bodies, for the sphere scenes whose particles stand for rough or non-round
//! grains (Ai et al., "Assessment of rolling resistance models in discrete element
//! simulations", Powder Technology 206, 2011).
//!
//! The relative rolling velocity is the tangential part of `ω₂ − ω₁` (its part along
//! the normal is twisting). Both models cap the torque at `μ_r R* F_n`:
//!
//! - constant torque (Ai et al.'s model A, LIGGGHTS `cdt`): `M = −μ_r R* F_n ω̂_r`,
//!   always at the cap while the bodies roll;
//! - elastic–plastic spring–dashpot (model C, LIGGGHTS `epsd2`): a spring of stiffness
//!   `k_r = 2.25 k_n μ_r² R*²` on the accumulated rolling angle, capped (it then slides
//!   at the cap, like a Coulomb spring), plus a dashpot `C_r = 2 η_r √(I_r k_r)` while
//!   below the cap, `I_r = 1/(1/(I₁ + m₁r₁²) + 1/(I₂ + m₂r₂²))` about the contact point.
//!   The spring and dashpot together are capped too: Ai et al. leave the dashpot
//!   uncapped, and then a rolling sphere whose normal load rises by more than
//!   `k_r ω dt` in a step (the spring drops below the cap) gets a dashpot torque of
//!   many times the cap (measured: 11 times for a 5 mm sphere at 0.1 m/s, which cut
//!   its rolling distance by 6 %).
//!   A pile of these spheres can stand at rest, which the constant torque cannot hold
//!   without chatter.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::Material;
use crate::Real;

/// Which rolling resistance a scene's round contacts feel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RollingModel {
    /// None: spheres roll freely.
    #[default]
    None,
    /// Constant torque against the rolling direction (model A, `cdt`).
    ConstantTorque,
    /// Elastic–plastic spring–dashpot (model C, `epsd2`).
    ElasticPlastic,
}

/// Rolling friction and damping of a pair of materials.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RollingParameters {
    /// Rolling friction coefficient `μ_r`.
    pub friction: Real,
    /// Damping ratio `η_r` of the spring–dashpot.
    pub damping: Real,
}

impl RollingParameters {
    /// The means of materials `a` and `b`.
    pub fn mean(a: &Material, b: &Material) -> Self {
        RollingParameters {
            friction: 0.5 * (a.rolling_friction + b.rolling_friction),
            damping: 0.5 * (a.rolling_damping + b.rolling_damping),
        }
    }
}

/// One contact's inputs to the rolling law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RollingContact {
    /// Unit normal, from body 1 to body 2.
    pub normal: Vector3<Real>,
    /// `ω₂ − ω₁`.
    pub relative_spin: Vector3<Real>,
    /// Normal force magnitude.
    pub normal_force: Real,
    /// Normal stiffness `k_n` of the contact.
    pub normal_stiffness: Real,
    /// Effective radius `R*`.
    pub radius: Real,
    /// Rolling inertia `I_r` about the contact point.
    pub inertia: Real,
}

/// The rolling torque on body 2 (body 1 feels the opposite) and the spring torque to
/// keep, from the kept `spring` of the last step.
#[inline]
pub fn rolling_torque(
    model: RollingModel,
    parameters: &RollingParameters,
    c: &RollingContact,
    spring: &Vector3<Real>,
    dt: Real,
) -> (Vector3<Real>, Vector3<Real>) {
    let n = &c.normal;
    let roll = c.relative_spin - n * n.dot(&c.relative_spin);
    let limit = parameters.friction * c.radius * c.normal_force;
    match model {
        RollingModel::None => (Vector3::zeros(), Vector3::zeros()),
        RollingModel::ConstantTorque => {
            let speed = roll.norm();
            if speed > 0.0 {
                (roll * (-limit / speed), Vector3::zeros())
            } else {
                (Vector3::zeros(), Vector3::zeros())
            }
        }
        RollingModel::ElasticPlastic => {
            let kr = 2.25 * c.normal_stiffness * (parameters.friction * c.radius).powi(2);
            // The kept torque, turned into the current tangent plane at its length.
            let mut kept = spring - n * n.dot(spring);
            let projected = kept.norm();
            if projected > 0.0 {
                kept *= spring.norm() / projected;
            }
            let elastic = kept - roll * (kr * dt);
            let magnitude = elastic.norm();
            if magnitude > limit {
                let capped = elastic * (limit / magnitude);
                (capped, capped)
            } else {
                let dashpot = roll * (-2.0 * parameters.damping * (c.inertia * kr).sqrt());
                let total = elastic + dashpot;
                let magnitude = total.norm();
                if magnitude > limit {
                    (total * (limit / magnitude), elastic)
                } else {
                    (total, elastic)
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn contact(spin: Vector3<Real>) -> RollingContact {
        RollingContact {
            normal: Vector3::z(),
            relative_spin: spin,
            normal_force: 2.0,
            normal_stiffness: 1e4,
            radius: 0.01,
            inertia: 1e-6,
        }
    }

    #[test]
    fn constant_torque_opposes_the_roll_at_the_cap() {
        let p = RollingParameters {
            friction: 0.1,
            damping: 0.0,
        };
        // The twisting part (along z) is not rolling.
        let c = contact(Vector3::new(3.0, 0.0, 7.0));
        let (m, kept) = rolling_torque(
            RollingModel::ConstantTorque,
            &p,
            &c,
            &Vector3::zeros(),
            1e-5,
        );
        assert!((m - Vector3::new(-0.1 * 0.01 * 2.0, 0.0, 0.0)).norm() < 1e-15);
        assert_eq!(kept, Vector3::zeros());
    }

    /// The spring grows by `k_r ω dt` per step until it reaches the cap, then stays
    /// there; reversing the roll unloads it elastically.
    #[test]
    fn elastic_plastic_spring_loads_caps_and_unloads() {
        let p = RollingParameters {
            friction: 0.1,
            damping: 0.0,
        };
        let c = contact(Vector3::x());
        let kr = 2.25 * 1e4 * (0.1 * 0.01 as Real).powi(2);
        let dt = 1e-3;
        let (m, kept) = rolling_torque(RollingModel::ElasticPlastic, &p, &c, &Vector3::zeros(), dt);
        assert!((m.x + kr * dt).abs() < 1e-18 && kept == m);
        let mut spring = Vector3::zeros();
        for _ in 0..100_000 {
            spring = rolling_torque(RollingModel::ElasticPlastic, &p, &c, &spring, dt).1;
        }
        let cap = 0.1 * 0.01 * 2.0;
        assert!((spring.x + cap).abs() < 1e-15, "{spring}");
        let back = contact(-Vector3::x());
        let (m, _) = rolling_torque(RollingModel::ElasticPlastic, &p, &back, &spring, dt);
        assert!((m.x - (-cap + kr * dt)).abs() < 1e-15);
    }
}
