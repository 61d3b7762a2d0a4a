//! The tangential (friction) force with contact history.

use nalgebra::Vector3;

use crate::Real;

/// What a contact keeps of its friction spring from step to step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TangentialHistory {
    /// Accumulated tangential displacement (in the tangent plane of its step).
    pub spring: Vector3<Real>,
    /// The spring constant it was stretched at (N/m).
    pub stiffness: Real,
    /// Accumulated relative twist about the normal, rad (see
    /// [`super::twisting_friction`]).
    pub twist: Real,
    /// The elastic–plastic rolling spring's torque on body 2 (see
    /// [`super::rolling_torque`]; zero under the other models).
    pub rolling: Vector3<Real>,
}

impl TangentialHistory {
    /// Whether there is nothing to keep.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.spring == Vector3::zeros() && self.twist == 0.0 && self.rolling == Vector3::zeros()
    }

    /// Elastic energy held in the friction spring, `½ k s²` (J). The twisting and
    /// rolling springs are not counted: their small energy is booked as dissipated
    /// while they hold it (see `engine::cpu::forces::dissipated`).
    #[inline]
    pub fn spring_energy(&self) -> Real {
        0.5 * self.stiffness * self.spring.norm_squared()
    }
}

/// The tangential force on body 2 and the updated history.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TangentialForce {
    /// Tangential force on body 2.
    pub force: Vector3<Real>,
    /// The spring to keep for the next step.
    pub history: TangentialHistory,
    /// Whether the contact slides (the Coulomb cap is active).
    pub sliding: bool,
}

/// Cundall–Strack friction.
///
/// - `history`: the accumulated tangential displacement from the previous step; it is
///   first rotated into the current tangent plane (keeping its length), so that a
///   contact frame that turns with the bodies carries its spring along;
/// - `relative_velocity`: velocity of body 2 relative to body 1 at the contact point;
/// - `stiffness`: the tangential stiffness `k_t` (N/m), `damping` the coefficient
///   `c_t` (N s/m), `limit` the Coulomb cap `μ |F_n|`.
///
/// When the trial force exceeds the cap the force is the cap along the trial
/// direction, and the spring is shortened (never lengthened) to the length whose force
/// is the cap, so that sliding never stores energy in the spring.
///
/// The spring constant follows the contact area, which changes with the normal load.
/// A spring kept as a displacement would then store energy from nothing when the
/// constant grows (`½ k s²` at fixed `s`), and one kept as a force when it shrinks
/// (`F² / 2k` at fixed `F`); both pump energy into a pile whose contact loads
/// fluctuate. So a stiffer spring keeps its force (the displacement is scaled by
/// `k_old / k_new`) and a softer one keeps its displacement: the stored energy never
/// grows by a change of stiffness.
#[inline(always)]
pub fn tangential_force(
    history: &TangentialHistory,
    normal: &Vector3<Real>,
    relative_velocity: &Vector3<Real>,
    dt: Real,
    stiffness: Real,
    damping: Real,
    limit: Real,
) -> TangentialForce {
    // The spring turned into the current tangent plane keeps its length, unless the
    // stiffness grew (then its force): one square root for both scalings.
    let previous = &history.spring;
    let along = normal.dot(previous);
    let mut spring = previous - normal * along;
    let held = previous.norm_squared();
    if held > 0.0 {
        let keep = if history.stiffness > 0.0 && stiffness > history.stiffness {
            history.stiffness / stiffness
        } else {
            1.0
        };
        spring *= keep * length_kept(along * along, held, &spring);
    }
    let vt = relative_velocity - normal * normal.dot(relative_velocity);
    spring += vt * dt;
    let trial = -stiffness * spring - damping * vt;
    // A sticking contact (the common case of a bed) needs no square root.
    let squared = trial.norm_squared();
    if squared <= limit * limit || squared == 0.0 {
        return TangentialForce {
            force: trial,
            history: TangentialHistory {
                spring,
                stiffness,
                ..*history
            },
            sliding: false,
        };
    }
    let magnitude = squared.sqrt();
    let force = trial * (limit / magnitude);
    // While sliding the spring is shortened, never lengthened, to what the cap allows:
    // resetting it to the length that alone gives the capped force would create spring
    // energy whenever the dashpot carries most of the trial force, and that energy
    // comes back as a push along the motion when the sliding reverses. (Folding the
    // dashpot into the spring, `-(F + c v_t)/k`, is worse: the spring then points along
    // the motion.)
    let length = spring.norm();
    let spring = if stiffness > 0.0 && stiffness * length > limit {
        spring * (limit / (stiffness * length))
    } else {
        spring
    };
    let history = TangentialHistory {
        spring,
        stiffness,
        ..*history
    };
    TangentialForce {
        force,
        history,
        sliding: true,
    }
}

/// The factor that brings a spring of squared length `held`, whose component
/// `along` the new normal was cut off (`along_squared` its square), back to its
/// length: `√(held / |projected|²)`, `|projected|² = held − along²`.
///
/// Where the normal turned by less than a thousandth of a radian since the last
/// step (`along² ≤ 10⁻⁶ held`, nearly every contact of a bed), the series
/// `(1 − ε)^(−½) = 1 + ε/2 + 3ε²/8 + …` of `ε = along²/held`, cut after `ε²`
/// (the rest under `ε³/3`, below the round-off); elsewhere the square root.
///
/// Why: the square root of a quotient of the projected length sat on the path
/// from the normal to the force; with the series the one-thread pair stage of the
/// settled bed of 5000 spheres took 663–668 µs a step against 694–744 µs
/// (alternating runs, 2026-12-07).
#[inline(always)]
fn length_kept(along_squared: Real, held: Real, projected: &Vector3<Real>) -> Real {
    if along_squared <= 1e-6 * held {
        let turn = along_squared / held;
        1.0 + turn * (0.5 + 0.375 * turn)
    } else {
        let projected = projected.norm_squared();
        if projected > 0.0 {
            (held / projected).sqrt()
        } else {
            1.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stuck contact whose stiffness swings up and down at rest stores no energy
    /// from the swings: its spring energy never exceeds what it started with.
    #[test]
    fn a_changing_stiffness_never_adds_spring_energy() {
        let n = Vector3::z();
        let mut h = TangentialHistory {
            spring: Vector3::new(1e-5, 0.0, 0.0),
            stiffness: 1e4,
            ..Default::default()
        };
        let energy = |h: &TangentialHistory| 0.5 * h.stiffness * h.spring.norm_squared();
        let start = energy(&h);
        let mut highest: Real = 0.0;
        for step in 0..1000 {
            let k = 1e4 * (1.0 + 0.9 * (step as Real * 0.1).sin());
            let t = tangential_force(&h, &n, &Vector3::zeros(), 1e-4, k, 0.0, 1e3);
            h = t.history;
            highest = highest.max(energy(&h));
        }
        assert!(highest <= start * (1.0 + 1e-12), "{highest} > {start}");
    }

    /// A spring turned into the plane of a turned normal keeps its length, to the
    /// round-off, by the series where the normal turned little and by the square
    /// root beyond: turns from 1e-9 rad to a right angle, about every axis.
    #[test]
    fn a_turned_spring_keeps_its_length() {
        let spring = Vector3::new(3e-6, -1e-6, 0.0);
        let mut worst: Real = 0.0;
        for k in 0..=200 {
            // Angles spread over 1e-9 .. π/2 by powers, across the series' limit
            // (a turn of 1e-3 rad).
            let angle = (1e-9 as Real) * (1.5e9 as Real).powf(k as Real / 200.0);
            let axis = Vector3::new((k as Real).cos(), (k as Real).sin(), 0.3).normalize();
            let normal = nalgebra::Rotation3::new(axis * angle) * Vector3::z();
            let history = TangentialHistory {
                spring,
                stiffness: 1e4,
                ..Default::default()
            };
            let t = tangential_force(&history, &normal, &Vector3::zeros(), 1e-5, 1e4, 0.0, 1e9);
            let kept = t.history.spring;
            assert!(
                kept.dot(&normal).abs() <= 1e-15 * spring.norm(),
                "angle {angle}"
            );
            worst = worst.max((kept.norm() / spring.norm() - 1.0).abs());
        }
        assert!(worst < 4.0 * Real::EPSILON, "length off by {worst:e}");
    }

    /// The series and the square root agree at the series' limit: the factor of a
    /// cut `ε` is `(1 − ε)^(−½)` either way, to the round-off.
    #[test]
    fn the_series_is_the_square_root_where_they_meet() {
        for turn in [1e-14, 1e-10, 1e-8, 1e-7, 9.9e-7, 1e-6] {
            let held: Real = 2.5e-11;
            let along_squared = turn * held;
            // A projected spring of the right squared length for the root's branch.
            let projected = Vector3::new((held - along_squared).sqrt(), 0.0, 0.0);
            let series = length_kept(along_squared, held, &projected);
            let root = (held / projected.norm_squared()).sqrt();
            let exact = 1.0 / (1.0 - turn).sqrt();
            assert!((series / exact - 1.0).abs() < 3.0 * Real::EPSILON, "{turn}");
            assert!((series / root - 1.0).abs() < 4.0 * Real::EPSILON, "{turn}");
        }
    }
}
