//! The tangential (friction) force with contact history.

use nalgebra::Vector3;

use crate::Real;

/// The tangential force on body 2 and the updated history.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TangentialForce {
    /// Tangential force on body 2.
    pub force: Vector3<Real>,
    /// Accumulated tangential displacement to keep for the next step (in the current
    /// tangent plane).
    pub history: Vector3<Real>,
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
pub fn tangential_force(
    history: &Vector3<Real>,
    normal: &Vector3<Real>,
    relative_velocity: &Vector3<Real>,
    dt: Real,
    stiffness: Real,
    damping: Real,
    limit: Real,
) -> TangentialForce {
    let length = history.norm();
    let mut spring = history - normal * normal.dot(history);
    let projected = spring.norm();
    if projected > 0.0 {
        spring *= length / projected;
    }
    let vt = relative_velocity - normal * normal.dot(relative_velocity);
    spring += vt * dt;
    let trial = -stiffness * spring - damping * vt;
    let magnitude = trial.norm();
    if magnitude <= limit || magnitude == 0.0 {
        return TangentialForce {
            force: trial,
            history: spring,
            sliding: false,
        };
    }
    let force = trial * (limit / magnitude);
    // While sliding the spring is shortened, never lengthened, to what the cap allows:
    // resetting it to the length that alone gives the capped force would create spring
    // energy whenever the dashpot carries most of the trial force, and that energy
    // comes back as a push along the motion when the sliding reverses. (Folding the
    // dashpot into the spring, `-(F + c v_t)/k`, is worse: the spring then points along
    // the motion.)
    let length = spring.norm();
    let history = if stiffness > 0.0 && stiffness * length > limit {
        spring * (limit / (stiffness * length))
    } else {
        spring
    };
    TangentialForce {
        force,
        history,
        sliding: true,
    }
}
