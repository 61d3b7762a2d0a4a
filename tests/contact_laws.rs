//! The contact laws on real contact geometry: the elastic volume force derives from a
//! potential (no work around a closed path), and the calibrated damping realises the
//! requested restitution for flat (p = 1/3) and edge (p = 5/3) impacts.

mod common;

use common::pose;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use talus::contact::{
    DampingTable, NormalContact, Regularisation, TangentialHistory, normal_force, tangential_force,
};
use talus::geometry::ConvexPolyhedron;
use talus::geometry::generators;
use talus::geometry::overlap::overlap;

/// Elastic force on B and stored energy at a relative pose (no damping).
fn elastic(
    a: &ConvexPolyhedron,
    b: &ConvexPolyhedron,
    rel: &Isometry3<f64>,
    kappa: f64,
    regularisation: f64,
) -> (Vector3<f64>, f64) {
    match overlap(a, b, rel) {
        None => (Vector3::zeros(), 0.0),
        Some(o) => {
            let f = normal_force(
                &NormalContact {
                    volume: o.volume,
                    area: o.area,
                    depth: o.depth,
                    normal: o.normal,
                    relative_velocity: Vector3::zeros(),
                    effective_mass: 1.0,
                    stiffness: kappa,
                    regularisation: Regularisation::new(regularisation),
                    dt: 0.0,
                },
                &DampingTable::new(1.0),
            );
            (f.force, f.energy)
        }
    }
}

#[test]
fn elastic_force_does_no_work_around_a_closed_path() {
    let a = generators::dodecahedron(0.01).unwrap();
    let b = generators::prism(20, 0.01, 0.012).unwrap();
    let kappa = 2.0 * 1e7 / 0.008;
    let rot = UnitQuaternion::from_scaled_axis(Vector3::new(0.4, -0.3, 1.1));
    // A loop in contact: a circle in a plane tilted against the line of centres.
    let centre = Vector3::new(0.0125, 0.002, -0.001);
    let (e1, e2) = (
        Vector3::new(0.0, 1.0, 0.3).normalize() * 0.002,
        Vector3::new(0.4, 0.0, 1.0).normalize() * 0.0015,
    );
    let at = |s: f64| {
        Isometry3::from_parts(
            Translation3::from(centre + e1 * s.cos() + e2 * s.sin()),
            rot,
        )
    };
    // The pure law, and a regularised one whose V₀ lies inside the loop's range of
    // overlap volumes (so the path crosses from one branch of the potential to the
    // other).
    let volumes: Vec<f64> = (0..16)
        .map(|k| overlap(&a, &b, &at(k as f64 * 0.4)).unwrap().volume)
        .collect();
    let mid = 0.5
        * (volumes.iter().copied().fold(f64::INFINITY, f64::min)
            + volumes.iter().copied().fold(0.0, f64::max));
    for v0 in [0.0, mid] {
        let steps = 4000;
        let mut work = 0.0;
        let mut max_energy: f64 = 0.0;
        let (mut f_prev, u0) = elastic(&a, &b, &at(0.0), kappa, v0);
        for k in 1..=steps {
            let s0 = 2.0 * std::f64::consts::PI * (k - 1) as f64 / steps as f64;
            let s1 = 2.0 * std::f64::consts::PI * k as f64 / steps as f64;
            let dx = at(s1).translation.vector - at(s0).translation.vector;
            let (f, u) = elastic(&a, &b, &at(s1), kappa, v0);
            assert!(u > 0.0, "the loop stays in contact");
            work += 0.5 * (f + f_prev).dot(&dx);
            f_prev = f;
            max_energy = max_energy.max(u);
        }
        assert!(u0 > 0.0);
        assert!(
            work.abs() < 1e-4 * max_energy,
            "work {work:e} vs energy {max_energy:e}"
        );
        // Along an open path the work is the drop in stored energy.
        let (mut work, mut f_prev) = (0.0, elastic(&a, &b, &at(0.0), kappa, v0).0);
        for k in 1..=steps / 4 {
            let s0 = 2.0 * std::f64::consts::PI * (k - 1) as f64 / steps as f64;
            let s1 = 2.0 * std::f64::consts::PI * k as f64 / steps as f64;
            let dx = at(s1).translation.vector - at(s0).translation.vector;
            let f = elastic(&a, &b, &at(s1), kappa, v0).0;
            work += 0.5 * (f + f_prev).dot(&dx);
            f_prev = f;
        }
        let u1 = elastic(&a, &b, &at(std::f64::consts::FRAC_PI_2), kappa, v0).1;
        assert!(
            (work + (u1 - u0)).abs() < 1e-4 * max_energy,
            "work {work:e}, ΔU {:e}",
            u1 - u0
        );
    }
}

/// Drops body B (translation only, along −z) onto fixed body A at speed `v0` and
/// returns the rebound speed over the impact speed, integrating with step `dt`.
fn realised_restitution(
    a: &ConvexPolyhedron,
    b: &ConvexPolyhedron,
    start: Isometry3<f64>,
    e: f64,
    dt: f64,
    regularisation: f64,
) -> f64 {
    let density = 2500.0;
    let mass = density * b.volume();
    let kappa = 2.0 * 1e8 / b.equivalent_radius();
    let table = DampingTable::new(e);
    let v0 = 0.5;
    let (mut z, mut v) = (0.0, -v0);
    let force = |z: f64, v: f64| -> f64 {
        let mut rel = start;
        rel.translation.vector.z += z;
        match overlap(a, b, &rel) {
            None => 0.0,
            Some(o) => {
                normal_force(
                    &NormalContact {
                        volume: o.volume,
                        area: o.area,
                        depth: o.depth,
                        normal: o.normal,
                        relative_velocity: Vector3::new(0.0, 0.0, v),
                        effective_mass: mass,
                        stiffness: kappa,
                        regularisation: Regularisation::new(regularisation),
                        dt,
                    },
                    &table,
                )
                .force
                .z
            }
        }
    };
    // Velocity Verlet with the velocity-dependent part taken at the half step.
    let mut touched = false;
    for _ in 0..20_000_000 {
        let f = force(z, v);
        let v_half = v + 0.5 * dt * f / mass;
        z += dt * v_half;
        let f_new = force(z, v_half);
        v = v_half + 0.5 * dt * f_new / mass;
        touched |= f_new != 0.0;
        if touched && f_new == 0.0 && v > 0.0 {
            return v / v0;
        }
    }
    panic!("no rebound");
}

/// The contact lasts about 3 µs here (E = 100 MPa, 1 cm cube, 0.5 m/s).
#[test]
fn restitution_of_flat_and_edge_impacts() {
    let cube = generators::cuboid(0.01, 0.01, 0.01).unwrap();
    let slab = generators::cuboid(0.1, 0.1, 0.01).unwrap();
    // Flat: face on face (force ∝ δ^1/3), just touching at the start.
    let flat = pose([0.001, -0.002, 0.01], [0.0; 3]);
    // Edge: the cube turned 45° about x lands on one edge (force ∝ δ^5/3).
    let edge = pose(
        [0.0, 0.0, 0.005 + 0.005 * std::f64::consts::SQRT_2],
        [std::f64::consts::FRAC_PI_4, 0.0, 0.0],
    );
    for e in [0.1, 0.5, 0.9] {
        // An edge contact is resolved at ~150 steps per contact (the remaining error
        // is the damping table's interpolation in p, under 0.5 %).
        let got = realised_restitution(&slab, &cube, edge, e, 2e-8, 0.0);
        assert!((got - e).abs() < 5e-3 * e, "edge, e = {e}: realised {got}");
        // A flat contact's damping is singular at onset (tangent stiffness ∝ δ^-2/3):
        // the realised value converges to the requested one as the onset is
        // resolved (measured: e = 0.1 gives 0.113, 0.105, 0.102 at 2e-8, 5e-9, 1e-9 s).
        let coarse = realised_restitution(&slab, &cube, flat, e, 5e-9, 0.0);
        let fine = realised_restitution(&slab, &cube, flat, e, 1e-9, 0.0);
        assert!(
            (fine - e).abs() < 0.02 * e,
            "flat, e = {e}: realised {fine}"
        );
        assert!(
            (fine - e).abs() < (coarse - e).abs(),
            "flat, e = {e}: {coarse} then {fine}"
        );
    }
}

#[test]
fn coulomb_friction_sticks_slides_and_carries_its_history() {
    let n = Vector3::z();
    let (k, c, dt) = (1e4, 0.0, 1e-4);
    // Sticking: the spring grows with the tangential displacement.
    let spring = |v: Vector3<f64>| TangentialHistory {
        spring: v,
        stiffness: k,
        ..Default::default()
    };
    let t = tangential_force(
        &TangentialHistory::default(),
        &n,
        &Vector3::new(0.1, 0.0, -0.3),
        dt,
        k,
        c,
        1.0,
    );
    assert!(!t.sliding);
    assert!((t.history.spring - Vector3::new(1e-5, 0.0, 0.0)).norm() < 1e-18);
    assert!((t.force - Vector3::new(-0.1, 0.0, 0.0)).norm() < 1e-12);
    // Sliding: the force is capped at the limit and the spring shrinks to the length
    // whose force is the cap.
    let t = tangential_force(
        &spring(Vector3::new(1e-3, 0.0, 0.0)),
        &n,
        &Vector3::new(1.0, 0.0, 0.0),
        dt,
        k,
        c,
        2.0,
    );
    assert!(t.sliding);
    assert!((t.force.norm() - 2.0).abs() < 1e-12 && t.force.x < 0.0);
    assert!((k * t.history.spring.norm() - 2.0).abs() < 1e-12);
    // A dashpot stronger than the cap slides the contact but must not lengthen the
    // spring: sliding stores no energy.
    let short = Vector3::new(1e-6, 0.0, 0.0);
    let t = tangential_force(
        &spring(short),
        &n,
        &Vector3::new(1.0, 0.0, 0.0),
        dt,
        k,
        50.0,
        2.0,
    );
    assert!(t.sliding && (t.force.norm() - 2.0).abs() < 1e-12);
    assert!((t.history.spring - (short + Vector3::new(1e-4, 0.0, 0.0))).norm() < 1e-18);
    // A history from a turned contact frame is rotated into the new tangent plane
    // with its length kept.
    let tilted = Vector3::new(0.0, 1.0, 1.0).normalize();
    let t = tangential_force(
        &spring(Vector3::new(0.0, 3e-5, 0.0)),
        &tilted,
        &Vector3::zeros(),
        dt,
        k,
        c,
        10.0,
    );
    assert!((t.history.spring.norm() - 3e-5).abs() < 1e-18);
    assert!(t.history.spring.dot(&tilted).abs() < 1e-18);
}
