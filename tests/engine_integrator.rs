//! The rigid-body integrator on the Dzhanibekov flip: a free asymmetric body spinning
//! near its intermediate axis tumbles over and over; energy and world-frame angular
//! momentum must hold to 1e-6 over 1e5 steps at 100 steps per rotation period.

use nalgebra::{UnitQuaternion, Vector3};
use talus::engine::integrate::{RotationState, free_rotation, half_kick, kick_drift, rotate};

#[test]
fn dzhanibekov_flip_conserves_energy_and_angular_momentum() {
    let inertia = Vector3::new(1.0, 2.0, 3.0);
    // Spin about the intermediate (y) axis with a small wobble.
    let omega_body = Vector3::new(1e-3, 1.0, 1e-3);
    let orientation = UnitQuaternion::from_scaled_axis(Vector3::new(0.2, -0.1, 0.3));
    let mut state = RotationState {
        orientation,
        angular_momentum: orientation * omega_body.component_mul(&inertia),
    };
    let energy0 = state.kinetic_energy(&inertia);
    let l0 = state.angular_momentum;
    let period = 2.0 * std::f64::consts::PI / omega_body.norm();
    let dt = period / 100.0;
    let mut flips = 0;
    let mut last_sign = 1.0;
    let (mut worst_energy, mut worst_momentum): (f64, f64) = (0.0, 0.0);
    for _ in 0..100_000 {
        rotate(&mut state, &inertia, &Vector3::zeros(), dt);
        half_kick(&mut state.angular_momentum, &Vector3::zeros(), dt);
        worst_energy = worst_energy.max((state.kinetic_energy(&inertia) - energy0).abs() / energy0);
        worst_momentum = worst_momentum.max((state.angular_momentum - l0).norm() / l0.norm());
        // The body's y axis against the (fixed) angular momentum: reverses at a flip.
        let sign = (state.orientation * Vector3::y()).dot(&l0).signum();
        if sign != last_sign {
            flips += 1;
            last_sign = sign;
        }
    }
    eprintln!("flips {flips}, energy drift {worst_energy:e}, momentum drift {worst_momentum:e}");
    assert!(
        flips >= 10,
        "the body should tumble repeatedly, flipped {flips} times"
    );
    assert!(worst_energy < 1e-6, "energy drift {worst_energy:e}");
    assert!(
        worst_momentum < 1e-6,
        "angular momentum drift {worst_momentum:e}"
    );
    assert!((state.orientation.norm() - 1.0).abs() < 1e-12);
}

#[test]
fn constant_torque_adds_angular_momentum_linearly() {
    // A sphere-like body (isotropic inertia) under a constant world torque: L = τ t
    // exactly, and ω = L / I.
    let inertia = Vector3::repeat(0.5);
    let mut state = RotationState {
        orientation: UnitQuaternion::identity(),
        angular_momentum: Vector3::zeros(),
    };
    let torque = Vector3::new(0.0, 0.0, 2.0);
    let dt = 1e-3;
    for _ in 0..1000 {
        rotate(&mut state, &inertia, &torque, dt);
        half_kick(&mut state.angular_momentum, &torque, dt);
    }
    assert!((state.angular_momentum - torque * 1.0).norm() < 1e-12);
    // Angle turned: ∫ω dt = τ t² / (2 I) = 2 rad (the Cayley turn per step is
    // 2 atan(hω/2), so the angle lags by O(h²)).
    let angle = state.orientation.angle();
    assert!((angle - 2.0).abs() < 1e-5, "{angle}");
    assert!((state.angular_velocity(&inertia) - Vector3::new(0.0, 0.0, 4.0)).norm() < 1e-12);
}

#[test]
fn free_rotation_about_a_principal_axis_is_steady() {
    let inertia = Vector3::new(1.0, 2.0, 3.0);
    let mut state = RotationState {
        orientation: UnitQuaternion::identity(),
        angular_momentum: Vector3::new(0.0, 0.0, 3.0),
    };
    for _ in 0..1000 {
        free_rotation(&mut state, &inertia, 0.01);
    }
    assert!((state.angular_momentum - Vector3::new(0.0, 0.0, 3.0)).norm() < 1e-13);
    assert!((state.orientation * Vector3::z() - Vector3::z()).norm() < 1e-12);
}

#[test]
fn translation_kick_drift_is_exact_for_constant_acceleration() {
    let g = Vector3::new(0.0, 0.0, -9.81);
    let (mut x, mut v) = (Vector3::zeros(), Vector3::new(1.0, 0.0, 0.0));
    let dt = 1e-3;
    for _ in 0..1000 {
        kick_drift(&mut x, &mut v, &g, dt);
        v += g * (0.5 * dt);
    }
    assert!((x - Vector3::new(1.0, 0.0, -0.5 * 9.81)).norm() < 1e-12);
    assert!((v - Vector3::new(1.0, 0.0, -9.81)).norm() < 1e-12);
}
