//! Time integration of rigid bodies.
//!
//! # Translation
//! Velocity Verlet (kick–drift–kick with the force of the previous step).
//!
//! # Rotation: momentum kicks around an exact-invariant free rotation
//! The torque acts as a half kick on the world-frame angular momentum before and after
//! the free rotation of the body over the step. The free rotation integrates Euler's
//! equations in the body frame, `L' = L × I⁻¹L`, with the implicit midpoint rule, and
//! turns the orientation by the Cayley rotation of the midpoint angular velocity:
//!
//! `L₁ = C(h ω_m)ᵀ L₀`, `q₁ = q₀ ⊗ (1, h ω_m / 2)/‖·‖`, `ω_m = I⁻¹ (L₀ + L₁)/2`.
//!
//! The midpoint rule keeps every quadratic invariant of Euler's equations exactly —
//! the kinetic energy `½ L·I⁻¹L` and `|L|²` — and because the body-frame update is
//! itself the Cayley rotation `C`, turning the orientation by the same `C` keeps the
//! world-frame angular momentum `R L` exactly too. (A plain explicit quaternion update
//! drifts in both; a second-order splitting keeps them only to O(h²).) The implicit
//! equation is solved by fixed-point iteration to round-off; it contracts at the rate
//! `h |ω|`, so a few iterations suffice at the time steps DEM uses.

use nalgebra::{Quaternion, UnitQuaternion, Vector3};

use crate::Real;
use crate::geometry::is_isotropic;

/// The rotational state of one rigid body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RotationState {
    /// Orientation: body frame to world frame.
    pub orientation: UnitQuaternion<Real>,
    /// Angular momentum in the world frame.
    pub angular_momentum: Vector3<Real>,
}

impl RotationState {
    /// Angular velocity in the world frame, for principal moments `inertia`.
    pub fn angular_velocity(&self, inertia: &Vector3<Real>) -> Vector3<Real> {
        let body = self
            .orientation
            .inverse_transform_vector(&self.angular_momentum);
        self.orientation * body.component_div(inertia)
    }

    /// Rotational kinetic energy.
    pub fn kinetic_energy(&self, inertia: &Vector3<Real>) -> Real {
        let body = self
            .orientation
            .inverse_transform_vector(&self.angular_momentum);
        0.5 * body.dot(&body.component_div(inertia))
    }
}

/// First half of a rotation step: half kick with the torque at the start of the step,
/// then the free rotation over `dt`. Finish the step with [`half_kick`] once the torque
/// at the new orientation is known.
pub fn rotate(
    state: &mut RotationState,
    inertia: &Vector3<Real>,
    torque_start: &Vector3<Real>,
    dt: Real,
) {
    half_kick(&mut state.angular_momentum, torque_start, dt);
    free_rotation(state, inertia, dt);
}

/// Adds half a step's torque impulse to `angular_momentum`.
#[inline]
pub fn half_kick(angular_momentum: &mut Vector3<Real>, torque: &Vector3<Real>, dt: Real) {
    *angular_momentum += torque * (0.5 * dt);
}

/// Torque-free rotation over `dt` (see the module docs).
pub fn free_rotation(state: &mut RotationState, inertia: &Vector3<Real>, dt: Real) {
    if is_isotropic(inertia) {
        turn_isotropic(state, 0.5 * dt / inertia.x);
        return;
    }
    if is_zero(&state.angular_momentum) {
        // A body without angular momentum does not turn: its orientation stays as
        // it is (normalised by its last turn). A poured particle falls so until its
        // first contact.
        return;
    }
    let l0 = state
        .orientation
        .inverse_transform_vector(&state.angular_momentum);
    let inv_inertia = inertia.map(|i| 1.0 / i);
    let scale = l0.norm().max(Real::MIN_POSITIVE);
    let mut l1 = l0;
    for _ in 0..64 {
        let w = (0.5 * dt) * (0.5 * (l0 + l1)).component_mul(&inv_inertia);
        let next = cayley_transpose(&w, &l0);
        let change = (next - l1).norm();
        l1 = next;
        if change <= 1e-15 * scale {
            break;
        }
    }
    // Final midpoint velocity from the converged L₁, and the matching Cayley turn.
    let w = (0.5 * dt) * (0.5 * (l0 + l1)).component_mul(&inv_inertia);
    let l1 = cayley_transpose(&w, &l0);
    let turn = UnitQuaternion::from_quaternion(Quaternion::new(1.0, w.x, w.y, w.z));
    state.orientation = UnitQuaternion::new_normalize((state.orientation * turn).into_inner());
    state.angular_momentum = state.orientation * l1;
}

/// The torque-free rotation of an isotropic body (principal moment `I`) over a step
/// `h`, given `half_step = h / (2 I)` (what a caller stepping many bodies of one type
/// computes once): [`free_rotation`]'s answer, bit for bit.
///
/// The midpoint rule's answer in closed form: L stays, and the body turns by the
/// Cayley rotation of h ω / 2: q ⊗ (1, h ω_body / 2) normalised, written as
/// q + (0, h ω / 2) ⊗ q with the world-frame ω = L / I (the same quaternion, without
/// taking L into the body frame, and normalised once).
/// A body without angular momentum does not turn (see [`free_rotation`]).
#[inline]
pub fn turn_isotropic(state: &mut RotationState, half_step: Real) {
    state.orientation = turned_isotropic(&state.orientation, &state.angular_momentum, half_step);
}

/// [`turn_isotropic`] as a function of the orientation and angular momentum: the
/// turned orientation.
///
/// Why a function of values: a stepping loop that kept the state in a
/// [`RotationState`] on its stack read the last particle's orientation back from
/// there as it began the next, and in some builds (the feature `cuda`'s) each
/// particle's square root and division then waited on the one before: the
/// integration stage of the settled bed of 5000 spheres took 221–231 µs a step on
/// one thread against 104–106 µs (2026-12-07).
#[inline(always)]
pub fn turned_isotropic(
    orientation: &UnitQuaternion<Real>,
    angular_momentum: &Vector3<Real>,
    half_step: Real,
) -> UnitQuaternion<Real> {
    if is_zero(angular_momentum) {
        return *orientation;
    }
    let w = angular_momentum * half_step;
    let q = orientation.into_inner();
    let turned = q + Quaternion::from_imag(w) * q;
    UnitQuaternion::new_unchecked(turned * reciprocal_root_near_one(turned.norm_squared()))
}

/// `1 / √s`, by its series about 1 where `s` is within 1e-6 of it, else by the root.
///
/// Why: a turned unit quaternion's squared norm is `1 + |w|²` (and the round-off its
/// orientation carried), and `|w|` is half a step's turn, under a milliradian in
/// nearly every step; there `1 − e/2 + 3e²/8` (`e = s − 1`) is `1/√s` to `5|e|³/16`,
/// under 1e-18, so the orientation is normalised as before to round-off. The
/// square root and the division of every particle's turn took 56 % of the kick of the
/// settled bed of 5000 spheres (perf, 2026-12-07).
#[inline(always)]
fn reciprocal_root_near_one(s: Real) -> Real {
    let e = s - 1.0;
    if e.abs() <= 1e-6 {
        1.0 - e * (0.5 - 0.375 * e)
    } else {
        1.0 / s.sqrt()
    }
}

/// Whether every component of `v` is ±0, tested in one branch (three compares of
/// floating-point numbers, each its own branch, slowed the spinning bed's step).
#[inline(always)]
fn is_zero(v: &Vector3<Real>) -> bool {
    (v.x.to_bits() | v.y.to_bits() | v.z.to_bits()) << 1 == 0
}

/// `Cᵀ v` for the Cayley rotation `C = (1 − ŵ)⁻¹ (1 + ŵ)`, i.e. `(1 + ŵ)⁻¹ (1 − ŵ) v`:
/// the rotation by the angle `2 atan |w|` about `w`, inverted.
#[inline]
fn cayley_transpose(w: &Vector3<Real>, v: &Vector3<Real>) -> Vector3<Real> {
    // The quaternion (1, w)/‖·‖ represents C; its conjugate applied to v gives Cᵀ v.
    let q = UnitQuaternion::from_quaternion(Quaternion::new(1.0, w.x, w.y, w.z));
    q.inverse_transform_vector(v)
}

/// Velocity Verlet for translation: the first half kick and the drift.
#[inline]
pub fn kick_drift(
    position: &mut Vector3<Real>,
    velocity: &mut Vector3<Real>,
    acceleration: &Vector3<Real>,
    dt: Real,
) {
    *velocity += acceleration * (0.5 * dt);
    *position += *velocity * dt;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A body without angular momentum keeps its orientation to the bit (it is not
    /// normalised again), whatever its inertia; an isotropic body's turn given its
    /// `h / 2I` is `free_rotation`'s to the bit.
    #[test]
    fn a_body_without_spin_keeps_its_orientation_and_the_isotropic_turn_is_the_same() {
        let q = UnitQuaternion::new_unchecked(Quaternion::new(0.6, 0.48, 0.36, 0.528));
        assert_ne!(q.norm(), 1.0, "a quaternion a renormalisation would move");
        for inertia in [Vector3::repeat(2e-3), Vector3::new(1e-3, 2e-3, 3e-3)] {
            let mut state = RotationState {
                orientation: q,
                angular_momentum: Vector3::zeros(),
            };
            free_rotation(&mut state, &inertia, 1e-4);
            assert_eq!(state.orientation, q);
        }
        let inertia = Vector3::repeat(2e-3);
        let start = RotationState {
            orientation: UnitQuaternion::from_euler_angles(0.3, -0.2, 1.1),
            angular_momentum: Vector3::new(1e-3, -4e-4, 2e-3),
        };
        let (mut a, mut b) = (start, start);
        free_rotation(&mut a, &inertia, 1e-4);
        turn_isotropic(&mut b, 0.5 * 1e-4 / inertia.x);
        assert_eq!(a, b);
        assert_ne!(a.orientation, start.orientation);
    }

    /// Where the series stands in for the root (within 1e-6 of 1) it is the
    /// correctly rounded `1/√s` to an ulp, and the branches meet there.
    #[test]
    fn the_series_is_the_reciprocal_root_near_one() {
        let exact = |s: Real| 1.0 / s.sqrt();
        let ulp = Real::EPSILON;
        for k in -1000..=1000 {
            let s = 1.0 + 1e-6 * (k as Real / 1000.0);
            let (series, root) = (reciprocal_root_near_one(s), exact(s));
            assert!(
                (series - root).abs() <= ulp,
                "s = 1 + {:e}: {series} against {root}",
                s - 1.0
            );
        }
        for s in [1.0 + 2e-6, 1.0 - 2e-6, 0.25, 4.0] {
            assert_eq!(reciprocal_root_near_one(s), exact(s));
        }
        assert!(reciprocal_root_near_one(Real::NAN).is_nan());
    }

    /// Turned a million times by small steps, an orientation stays a unit quaternion
    /// to round-off: the series normalises as the root did, without drift.
    #[test]
    fn an_orientation_turned_a_million_times_stays_unit() {
        let mut q = UnitQuaternion::from_euler_angles(0.3, -0.2, 1.1);
        let l = Vector3::new(3e-3, -1e-3, 2e-3);
        for _ in 0..1_000_000 {
            q = turned_isotropic(&q, &l, 0.05);
        }
        assert!(
            (q.norm() - 1.0).abs() < 4.0 * Real::EPSILON,
            "|q| - 1 = {:e}",
            q.norm() - 1.0
        );
    }

    #[test]
    fn cayley_quaternion_matches_the_matrix_form() {
        let w = Vector3::new(0.3, -0.2, 0.5);
        let v = Vector3::new(1.0, 2.0, -0.7);
        let skew = w.cross_matrix();
        let id = nalgebra::Matrix3::identity();
        let c = (id - skew).try_inverse().unwrap() * (id + skew);
        assert!((c.transpose() * v - cayley_transpose(&w, &v)).norm() < 1e-14);
    }
}
