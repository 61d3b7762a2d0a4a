//! Torques of a contact area on the relative rotation of two bodies: viscous damping
//! of rocking (rotation about axes in the contact plane) and twisting friction
//! (rotation about the normal).
//!
//! # Rocking
//!
//! The normal dashpot acts at the centroid of the overlap, so it sees no normal
//! velocity when a body rocks about that centroid: a polyhedron resting on a face
//! would rock on it for ever, its only losses the small changes of contact point
//! between rocks (observed: a dodecahedron on a floor with e = 0.3 kept rocking at
//! 5 cm/s for half a second). A real contact damps rocking through the whole area.
//! Spreading the normal dashpot's coefficient `c` evenly over the contact area `A`
//! gives, for a relative spin `ω⊥` in the contact plane, the torque
//!
//! `τ = −c J/A ω⊥`, with `J = A² / 4π`
//!
//! the second moment of a disc of area `A` about a diameter. With the dashpot's
//! coefficient from the tangent stiffness `k_t` and the damping ratio ζ of the
//! contact, `c J/A = 2ζ √(I k_θ)` for the rocking stiffness `k_θ = k_t J / A` and
//! the effective moment of inertia `I` of the pair: the rocking mode gets the same
//! damping ratio as the normal mode. The torque only removes energy (`τ · ω⊥ ≤ 0`), is
//! zero for e = 1, and, like the normal dashpot, is capped at what stops the relative
//! rocking within one step.

//!
//! # Twisting
//!
//! Friction acting at one point cannot resist a spin about the normal through that
//! point either: a polyhedron that lands with a twist on a face keeps turning on it
//! (observed: 0.88 rad/s, undamped). Coulomb tractions spread over a disc of area `A`
//! under a uniform pressure resist twisting with at most `M = μ F_n · ⅔ √(A/π)`.
//! [`twisting_friction`] puts a torsional spring (the tangential springs `k_t` spread
//! over the area, `k_twist = k_t A / 2π`) with a dashpot at ζ = 1 on the accumulated
//! twist, capped by that Coulomb moment, so a twisted contact sticks under a steady
//! torque as the tangential spring does under a steady force.

use nalgebra::Vector3;

use crate::Real;

/// Rocking-damping torque on body 2 (body 1 gets the opposite).
///
/// `spin` is body 2's angular velocity relative to body 1, `normal` the unit contact
/// normal, `area` the contact area, `tangent_stiffness` the normal law's `dF/dδ`,
/// `inertia` the effective moment of inertia `1/(1/I₁ + 1/I₂)`, `zeta` the damping
/// ratio, `dt` the time step (0 for no cap).
pub fn rocking_damping(
    spin: &Vector3<Real>,
    normal: &Vector3<Real>,
    area: Real,
    tangent_stiffness: Real,
    inertia: Real,
    zeta: Real,
    dt: Real,
) -> Vector3<Real> {
    let rocking = spin - normal * spin.dot(normal);
    if !(area > 0.0 && tangent_stiffness > 0.0 && inertia > 0.0 && zeta > 0.0) {
        return Vector3::zeros();
    }
    let second_moment_ratio = area / (4.0 * std::f64::consts::PI);
    let stiffness = tangent_stiffness * second_moment_ratio;
    let mut coefficient = 2.0 * zeta * (inertia * stiffness).sqrt();
    if dt > 0.0 {
        coefficient = coefficient.min(inertia / dt);
    }
    -rocking * coefficient
}

/// Twisting friction: the torque on body 2 (body 1 gets the opposite) and the twist
/// to keep for the next step.
///
/// `twist` is the accumulated relative twist (rad) from the previous step, `spin`
/// body 2's angular velocity relative to body 1, `normal` the unit contact normal,
/// `area` the contact area, `tangential_stiffness` the tangential spring constant of
/// the contact (N/m), `inertia` the effective moment of inertia, `coulomb` the
/// friction limit `μ F_n` (N), `dt` the time step.
///
/// A torsional spring `k_tw = k_t A / 2π` (tangential springs spread over a disc of
/// area `A`) on the accumulated twist, a dashpot at ζ = 1, and the Coulomb moment
/// `μ F_n ⅔ √(A/π)` as the cap; while the cap is active the twist is shortened to what
/// the cap allows, as for the tangential spring. The spring makes a twisted contact
/// stick under a steady torque instead of creeping.
#[allow(clippy::too_many_arguments)]
pub fn twisting_friction(
    twist: Real,
    spin: &Vector3<Real>,
    normal: &Vector3<Real>,
    area: Real,
    tangential_stiffness: Real,
    inertia: Real,
    coulomb: Real,
    dt: Real,
) -> (Vector3<Real>, Real) {
    if !(area > 0.0 && tangential_stiffness > 0.0 && inertia > 0.0 && coulomb > 0.0) {
        return (Vector3::zeros(), 0.0);
    }
    let rate = normal.dot(spin);
    let stiffness = tangential_stiffness * area / (2.0 * std::f64::consts::PI);
    let mut damping = 2.0 * (inertia * stiffness).sqrt();
    if dt > 0.0 {
        damping = damping.min(inertia / dt);
    }
    let mut angle = twist + rate * dt;
    let trial = -stiffness * angle - damping * rate;
    let cap = coulomb * (2.0 / 3.0) * (area / std::f64::consts::PI).sqrt();
    let moment = if trial.abs() <= cap {
        trial
    } else {
        if stiffness * angle.abs() > cap {
            angle *= cap / (stiffness * angle.abs());
        }
        cap * trial.signum()
    };
    (normal * moment, angle)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn damps_rocking_only_and_never_feeds_it() {
        let n = Vector3::z();
        let spin = Vector3::new(2.0, -1.0, 5.0);
        let t = rocking_damping(&spin, &n, 1e-4, 1e5, 1e-8, 0.3, 0.0);
        // Nothing about the normal (twist), opposite to the rocking part.
        assert_eq!(t.z, 0.0);
        assert!(t.dot(&spin) < 0.0);
        let expected = 2.0 * 0.3 * (1e-8 * 1e5 * 1e-4 / (4.0 * std::f64::consts::PI)).sqrt();
        assert!((t.x / -2.0 - expected).abs() < 1e-12 * expected);
        // Capped by I/dt; zero without damping.
        let capped = rocking_damping(&spin, &n, 1e-4, 1e5, 1e-8, 0.3, 1e3);
        assert!((capped.x + 2.0 * 1e-8 / 1e3).abs() < 1e-20);
        assert_eq!(
            rocking_damping(&spin, &n, 1e-4, 1e5, 1e-8, 0.0, 0.0),
            Vector3::zeros()
        );
    }

    #[test]
    fn twisting_friction_sticks_then_slides_at_the_coulomb_moment() {
        let n = Vector3::z();
        let area: Real = 1e-4;
        let (k, inertia, dt) = (1e3, 1e-9, 1e-5);
        let k_tw = k * area / (2.0 * std::f64::consts::PI);
        // Sticking: a spring on the accumulated twist, plus the dashpot.
        let spin = Vector3::new(3.0, 0.0, 2.0);
        let (t, angle) = twisting_friction(0.01, &spin, &n, area, k, inertia, 1.0, dt);
        assert!((angle - (0.01 + 2.0 * dt)).abs() < 1e-15);
        let c = (2.0 * (inertia * k_tw).sqrt()).min(inertia / dt);
        assert!((t.z + k_tw * angle + c * 2.0).abs() < 1e-15);
        assert_eq!((t.x, t.y), (0.0, 0.0));
        // A twist held at rest keeps its torque (it sticks, no creep).
        let (t2, angle2) =
            twisting_friction(angle, &Vector3::zeros(), &n, area, k, inertia, 1.0, dt);
        assert_eq!(angle2, angle);
        assert!((t2.z + k_tw * angle).abs() < 1e-15);
        // Beyond the Coulomb moment: capped, and the twist shortened to the cap.
        let coulomb = 1e-6;
        let cap = coulomb * (2.0 / 3.0) * (area / std::f64::consts::PI).sqrt();
        let (t, angle) =
            twisting_friction(10.0, &Vector3::zeros(), &n, area, k, inertia, coulomb, dt);
        assert!((t.z + cap).abs() < 1e-18);
        assert!((k_tw * angle - cap).abs() < 1e-15 * cap.max(1.0));
        // No friction, no torque and no twist kept.
        assert_eq!(
            twisting_friction(0.3, &spin, &n, area, k, inertia, 0.0, dt),
            (Vector3::zeros(), 0.0)
        );
    }
}
