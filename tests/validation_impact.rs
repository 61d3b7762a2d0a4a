//! Validation 1: oblique impact of a cylindrical pellet on a wall (primary seed,
//! section 3.1, Table 1: D = 8 mm, L = 5.3 mm, ρ = 1245 kg/m³, E = 1.15 GPa, ν = 0.35,
//! e = 0.85, frictionless, no gravity, Δt = 5e-7 s).
//!
//! Reference: the rigid-body impulse solution for a single corner contact. The corner
//! C (offset r from the centroid) touches the wall of normal n. With no friction the
//! impulse is `J n`, and Newton's restitution law at C, `u⁺ = −e u⁻` for the normal
//! velocity `u = n · (v + ω × r)`, gives
//!
//! `J = −(1 + e) u⁻ / (1/m + (r × n) · I⁻¹ (r × n))`,
//! `v⁺ = v⁻ + J n / m`, `ω⁺ = ω⁻ + I⁻¹ (r × J n)`.
//!
//! For the seed's planar case (rotation about y) this is its eqs. 27–28 with
//! `r cos(α + θ)` the lever arm of the corner. Here r and I are those of the actual
//! 20-gon prism (the seed's pellet mesh), not of a smooth cylinder. The solution holds
//! while one corner touches: near θ = 0 (face flat on the wall) and θ = 90° (mantle
//! flat on the wall) a second corner comes into contact during the impact, which is
//! where the seed's DEM also departs from it.

use nalgebra::{Matrix3, Point3, UnitQuaternion, Vector3};
use talus::contact::Material;
use talus::engine::{Backend, CpuBackend};
use talus::geometry::surfaces;
use talus::geometry::{Shape, generators};
use talus::world::{BodyType, Wall, World};

const SPEED: f64 = 1.0;

struct Outcome {
    /// Deepest penetration of a vertex below the wall, m.
    deepest: f64,
    /// Most vertices below the wall at once.
    corners: usize,
    omega_y: f64,
    v_z: f64,
    ref_omega_y: f64,
    ref_v_z: f64,
}

fn impact(theta_deg: f64, dt: f64) -> Outcome {
    let pellet = Material {
        name: "pellet".into(),
        density: 1245.0,
        young: 1.15e9,
        poisson: 0.35,
        restitution: 0.85,
        friction: 0.0,
        rolling_friction: 0.0,
        rolling_damping: 0.0,
    };
    // A rigid wall: the pellet's modulus alone sets the contact (the seed's R → ∞ wall
    // of the same material is the other common choice; the impulse solution does not
    // depend on stiffness).
    let wall_material = Material {
        name: "wall".into(),
        young: 1.15e9,
        restitution: 0.85,
        ..pellet.clone()
    };
    let poly = generators::prism(20, 8e-3, 5.3e-3).unwrap();
    let input_to_body = poly.body_to_input().rotation;
    let shape = Shape::Polyhedron(std::sync::Arc::new(poly));
    let body = BodyType::new(shape.clone(), &pellet, 0);
    let floor = surfaces::plane(Point3::origin(), Vector3::z(), 0.1).unwrap();
    let wall = Wall::new("floor", 1, floor.vertices, floor.triangles, 0.02);
    let mut world = World {
        materials: vec![pellet, wall_material],
        body_types: vec![body],
        walls: vec![wall],
        gravity: Vector3::zeros(),
        ..World::default()
    };
    // The cylinder's face makes angle θ with the wall: its axis is turned by θ about y.
    let q =
        UnitQuaternion::from_axis_angle(&Vector3::y_axis(), theta_deg.to_radians()) * input_to_body;
    let p = shape.as_polyhedron().unwrap();
    let lowest = p
        .vertices()
        .iter()
        .map(|v| q * v.coords)
        .min_by(|a, b| a.z.total_cmp(&b.z))
        .unwrap();
    // Start 0.1 mm above the wall.
    let centre = Point3::new(0.0, 0.0, -lowest.z + 1e-4);
    world.particles.push(0, centre, q, 1);
    world.particles.velocity[0] = Vector3::new(0.0, 0.0, -SPEED);

    // Reference.
    let m = world.body_types[0].mass;
    let r_mat = q.to_rotation_matrix();
    let i_inv = r_mat.matrix()
        * Matrix3::from_diagonal(&world.body_types[0].inertia.map(|x| 1.0 / x))
        * r_mat.matrix().transpose();
    let n = Vector3::z();
    let rn = lowest.cross(&n);
    let j = (1.0 + 0.85) * SPEED / (1.0 / m + rn.dot(&(i_inv * rn)));
    let v_ref = Vector3::new(0.0, 0.0, -SPEED) + n * (j / m);
    let w_ref = i_inv * lowest.cross(&(n * j));

    let (mut engine, engine_dt) = (CpuBackend::default(), dt);
    engine.initialise(&mut world, engine_dt);
    let mut touched = false;
    let mut deepest = 0.0f64;
    let mut below_max = 0;
    for _ in 0..200_000 {
        engine.step(&mut world, engine_dt);
        let qq = world.particles.orientation[0];
        let x = world.particles.position[0];
        let zs: Vec<f64> = p
            .vertices()
            .iter()
            .map(|v| x.z + (qq * v.coords).z)
            .collect();
        deepest = deepest.max(-zs.iter().cloned().fold(f64::INFINITY, f64::min));
        below_max = below_max.max(zs.iter().filter(|z| **z < 0.0).count());
        touched |= engine.stats().contacts > 0;
        if touched && engine.stats().contacts == 0 {
            break;
        }
    }
    assert!(touched, "θ = {theta_deg}: no impact");

    let w = world.angular_velocity(0);
    Outcome {
        deepest,
        corners: below_max,
        omega_y: w.y,
        v_z: world.particles.velocity[0].z,
        ref_omega_y: w_ref.y,
        ref_v_z: v_ref.z,
    }
}

/// Post-impact angular velocity within 3 % of the reference, and normal velocity
/// within 3 % of the impact speed, over orientation angles 5°–70°, at the seed's step;
/// 5 % at 80°.
///
/// At 80° one corner touches (checked below) but the pellet, nearly lying on its
/// mantle, presents a blunt corner: the contact is deep (60 µm) and long, and the
/// pellet turns by about 0.05 rad while it lasts, changing the lever arm the
/// instantaneous-impulse solution assumes fixed. The result does not change with the
/// step (Δt = 1e-7 s gives the same to 4 digits), so this is the reference's limit,
/// not the integration's; the seed's Fig. 10 departs from the reference there too.
#[test]
fn oblique_cylinder_impact_matches_the_impulse_solution() {
    let mut worst: (f64, f64) = (0.0, 0.0);
    for theta in [5.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0] {
        let o = impact(theta, 5e-7);
        if theta > 5.0 {
            assert_eq!(o.corners, 1, "θ = {theta}: more than one corner touched");
        }
        let ew = (o.omega_y - o.ref_omega_y).abs() / o.ref_omega_y.abs();
        let ev = (o.v_z - o.ref_v_z).abs() / SPEED;
        println!(
            "θ = {theta:>4}°: ω_y = {:+.4} (ref {:+.4}, err {:.2} %), v_z = {:+.4} (ref {:+.4}, err {:.2} % of V⁻)",
            o.omega_y,
            o.ref_omega_y,
            100.0 * ew,
            o.v_z,
            o.ref_v_z,
            100.0 * ev
        );
        println!("         deepest {:.1} µm", o.deepest * 1e6);
        if theta > 75.0 {
            assert!(ew < 0.05 && ev < 0.05, "θ = {theta}: errors {ew}, {ev}");
        } else {
            worst = (worst.0.max(ew), worst.1.max(ev));
        }
    }
    assert!(
        worst.0 < 0.03,
        "angular velocity error {:.3} %",
        100.0 * worst.0
    );
    assert!(
        worst.1 < 0.03,
        "normal velocity error {:.3} %",
        100.0 * worst.1
    );
}
