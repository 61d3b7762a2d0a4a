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
    let mut spring = previous - normal * normal.dot(previous);
    let projected = spring.norm_squared();
    if projected > 0.0 {
        let keep = if history.stiffness > 0.0 && stiffness > history.stiffness {
            history.stiffness / stiffness
        } else {
            1.0
        };
        spring *= keep * (previous.norm_squared() / projected).sqrt();
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
}
