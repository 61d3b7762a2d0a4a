//! Prescribed wall kinematics.
//!
//! A wall moves rigidly: its frame origin (the wall's reference point, about which its
//! torque is reported) translates with a linear velocity and the wall turns about that
//! origin with an angular velocity. A [`WallMotion`] gives both as functions of time;
//! [`WallMotion::External`] leaves them to whoever drives the simulation (the
//! co-simulation inputs), which sets [`super::Wall::velocity`] and
//! [`super::Wall::angular_velocity`] directly.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use crate::Real;

/// One row of a velocity time table.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
pub struct MotionKey {
    /// Time, s.
    pub time: Real,
    /// Linear velocity of the reference point, m/s.
    #[serde(default)]
    pub velocity: [Real; 3],
    /// Angular velocity about the reference point, rad/s.
    #[serde(default)]
    pub angular_velocity: [Real; 3],
}

/// How a wall moves.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum WallMotion {
    /// At rest (no kinematics computed).
    #[default]
    Fixed,
    /// Constant linear and angular velocity.
    Constant {
        /// Linear velocity.
        velocity: Vector3<Real>,
        /// Angular velocity about the reference point.
        angular_velocity: Vector3<Real>,
    },
    /// Harmonic translation `x(t) = amplitude · sin(2π f t)` along `direction`
    /// (a vibrating or tapped wall).
    Oscillation {
        /// Displacement amplitude vector.
        amplitude: Vector3<Real>,
        /// Frequency, Hz.
        frequency: Real,
    },
    /// Velocities interpolated linearly between keys (held constant outside).
    Table(Vec<MotionKey>),
    /// Set from outside (co-simulation inputs); the velocities stay as last set.
    External(DriveInput),
    /// Moves rigidly with the wall of this index (listed earlier in the world), sharing
    /// its reference point: the end caps of a drum, the two halves of a mould. The
    /// leader's pose and velocities are copied by [`crate::world::World::follow_leaders`].
    Attached(usize),
}

/// What a co-simulation master gives for a wall driven from outside.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DriveInput {
    /// Linear and angular velocity, held over each communication step.
    #[default]
    Velocity,
    /// The pose to reach at the end of each communication step (reference point
    /// position and orientation); the wall moves there at constant velocity.
    Pose,
}

/// Linear and angular velocity of a wall at one instant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WallVelocity {
    /// Linear velocity of the reference point.
    pub linear: Vector3<Real>,
    /// Angular velocity about the reference point.
    pub angular: Vector3<Real>,
}

impl WallMotion {
    /// Whether the wall never moves.
    pub fn is_fixed(&self) -> bool {
        matches!(self, WallMotion::Fixed)
    }

    /// The prescribed velocity at time `t`, or `None` where it is set from outside.
    pub fn velocity(&self, t: Real) -> Option<WallVelocity> {
        match self {
            WallMotion::Fixed => Some(WallVelocity::default()),
            WallMotion::Constant {
                velocity,
                angular_velocity,
            } => Some(WallVelocity {
                linear: *velocity,
                angular: *angular_velocity,
            }),
            WallMotion::Oscillation {
                amplitude,
                frequency,
            } => {
                let w = std::f64::consts::TAU * frequency;
                Some(WallVelocity {
                    linear: amplitude * (w * (w * t).cos()),
                    angular: Vector3::zeros(),
                })
            }
            WallMotion::Table(keys) => Some(interpolate(keys, t)),
            WallMotion::External(_) | WallMotion::Attached(_) => None,
        }
    }

    /// The wall this one is attached to.
    pub fn leader(&self) -> Option<usize> {
        match self {
            WallMotion::Attached(k) => Some(*k),
            _ => None,
        }
    }
}

fn interpolate(keys: &[MotionKey], t: Real) -> WallVelocity {
    let get = |k: &MotionKey| WallVelocity {
        linear: k.velocity.into(),
        angular: k.angular_velocity.into(),
    };
    let Some(first) = keys.first() else {
        return WallVelocity::default();
    };
    if t <= first.time {
        return get(first);
    }
    for pair in keys.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        if t <= b.time {
            let f = if b.time > a.time {
                (t - a.time) / (b.time - a.time)
            } else {
                1.0
            };
            let (va, vb) = (get(a), get(b));
            return WallVelocity {
                linear: va.linear.lerp(&vb.linear, f),
                angular: va.angular.lerp(&vb.angular, f),
            };
        }
    }
    get(keys.last().expect("non-empty"))
}

/// Moves a rigid frame by `dt` with constant velocities: translation of the origin
/// and an exact turn about it.
pub fn advance_pose(pose: &mut Isometry3<Real>, v: &WallVelocity, dt: Real) {
    let turn = UnitQuaternion::from_scaled_axis(v.angular * dt);
    pose.rotation = turn * pose.rotation;
    pose.translation = Translation3::from(pose.translation.vector + v.linear * dt);
}
