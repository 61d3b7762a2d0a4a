//! The Hertz–Mindlin law of sphere scenes (`[contact] law = "hertz_mindlin"`) against
//! Hertz's closed forms, the rigid-body answer of an oblique impact that slides
//! throughout (Chung & Ooi, "Benchmark tests for verifying discrete element modelling
//! codes at particle impact level", Granular Matter 13, 2011: test 6, alumina
//! spheres on an alumina plane), and the rolling resistance models against the
//! deceleration their torque gives a rolling sphere.

use std::ops::ControlFlow;
use std::path::Path;

use nalgebra::Vector3;
use talus::scene::{Scene, Simulation};

/// `∫₀¹ (1 − x^{5/2})^{-1/2} dx`: Hertz's contact time is `2 · this · δ_max / v`.
const HERTZ_TIME_INTEGRAL: f64 = 1.471_637_592;

fn scene(dt: &str, gravity: f64, contact: &str, materials: &str, rest: &str) -> Simulation {
    let text = format!(
        r#"
[simulation]
dt = {dt}
end_time = 10.0
gravity = [0.0, 0.0, {g}]
[contact]
law = "hertz_mindlin"
{contact}
{materials}
{rest}
"#,
        g = -gravity
    );
    let scene = Scene::parse(&text, Path::new("hertz.toml")).expect("a valid scene");
    Simulation::new(&scene)
}

fn material(name: &str, density: f64, young: f64, poisson: f64, e: f64, mu: f64) -> String {
    format!(
        "[materials.{name}]\ndensity = {density}\nyoung = {young}\npoisson = {poisson}\n\
         restitution = {e}\nfriction = {mu}\n"
    )
}

/// Steps until the contact that has begun ends; returns the steps in contact and the
/// largest force on particle `watched`.
fn run_impact(sim: &mut Simulation, watched: usize) -> (usize, f64) {
    let (mut touching, mut steps, mut peak) = (false, 0, 0.0f64);
    let end = sim.end_time;
    let _ = sim.advance_to(end, |sim, _| {
        let contacts = sim.stats().contacts;
        if contacts > 0 {
            touching = true;
            steps += 1;
            peak = peak.max(sim.world().particles.force[watched].norm());
            ControlFlow::Continue(())
        } else if touching {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    });
    (steps, peak)
}

/// Hertz's maximum overlap of an elastic impact at `v` (effective mass, radius and
/// modulus `m`, `r`, `e`).
fn hertz_depth(m: f64, r: f64, e: f64, v: f64) -> f64 {
    (15.0 * m * v * v / (16.0 * e * r.sqrt())).powf(0.4)
}

/// Two equal elastic spheres meeting head on at 1 m/s: contact time, peak force and
/// rebound speed are Hertz's. The step is 1/400 of the contact time, so the step's
/// error is far below the tolerances (0.5 % on time and force, 1e-4 on the speed).
#[test]
fn an_elastic_head_on_impact_is_hertz() {
    let (r, rho, young, nu, v) = (0.005, 2500.0, 1e7, 0.3, 1.0);
    let m = rho * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
    let (m_eff, r_eff, e_eff) = (m / 2.0, r / 2.0, young / (2.0 * (1.0 - nu * nu)));
    let depth = hertz_depth(m_eff, r_eff, e_eff, v);
    let time = 2.0 * HERTZ_TIME_INTEGRAL * depth / v;
    let force = 4.0 / 3.0 * e_eff * r_eff.sqrt() * depth.powf(1.5);
    let mut sim = scene(
        &format!("{}", time / 400.0),
        0.0,
        "",
        &material("m", rho, young, nu, 1.0, 0.5),
        &format!(
            r#"[shapes.ball]
kind = "sphere"
radius = {r}
[[particles]]
kind = "list"
shape = "ball"
material = "m"
bodies = [{{ position = [0.0, 0.0, 0.0], velocity = [0.5, 0.0, 0.0] }},
          {{ position = [{x}, 0.0, 0.0], velocity = [-0.5, 0.0, 0.0] }}]
"#,
            x = 2.0 * r + 1e-6
        ),
    );
    let (steps, peak) = run_impact(&mut sim, 1);
    let measured = steps as f64 * sim.dt();
    assert!(
        (measured / time - 1.0).abs() < 5e-3,
        "contact time {measured:e} s, Hertz {time:e} s"
    );
    assert!(
        (peak / force - 1.0).abs() < 5e-3,
        "peak force {peak} N, Hertz {force} N"
    );
    let rebound = sim.world().particles.velocity[1].x - sim.world().particles.velocity[0].x;
    assert!((rebound / v - 1.0).abs() < 1e-4, "rebound {rebound} m/s");
}

/// The realised restitution of the damped law at `e` for an impact at `v`: a sphere
/// on a wall of the same material.
fn wall_restitution(e: f64, v: f64) -> f64 {
    let r = 0.005;
    let mut sim = scene(
        "1e-6",
        0.0,
        "",
        &material("m", 2500.0, 1e7, 0.3, e, 0.5),
        &format!(
            r#"[shapes.ball]
kind = "sphere"
radius = {r}
[[wall]]
name = "floor"
material = "m"
geometry = {{ kind = "plane", centre = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], size = 0.1 }}
[[particles]]
kind = "list"
shape = "ball"
material = "m"
bodies = [{{ position = [0.0, 0.0, {z}], velocity = [0.0, 0.0, {vz}] }}]
"#,
            z = r + 1e-7,
            vz = -v
        ),
    );
    run_impact(&mut sim, 0);
    sim.world().particles.velocity[0].z / v
}

/// Spheres resting on a flat floor made of two triangles feel the plane wherever
/// their centres fall on the triangulation: one contact each, a force along the
/// floor's normal to the bit (the plane's contact, not a closest point found on a
/// triangle to round-off, which tilted it by ~1e-16) and Hertz's static force.
#[test]
fn spheres_on_a_triangulated_floor_feel_the_plane() {
    let (r, depth, young, nu): (f64, f64, f64, f64) = (0.005, 1e-5, 1e7, 0.3);
    // A 7 × 7 grid 13.7 mm apart, off the floor's diagonal by at least 1 mm.
    let bodies: Vec<String> = (0..49)
        .map(|k| {
            let (x, y) = (
                -0.042 + 0.0137 * (k / 7) as f64,
                -0.0405 + 0.0137 * (k % 7) as f64,
            );
            format!("{{ position = [{x}, {y}, {}] }}", r - depth)
        })
        .collect();
    let sim = scene(
        "1e-6",
        0.0,
        "",
        &material("m", 2500.0, young, nu, 0.5, 0.5),
        &format!(
            r#"[shapes.ball]
kind = "sphere"
radius = {r}
[[wall]]
name = "floor"
material = "m"
geometry = {{ kind = "box", min = [-0.05, -0.05, 0.0], max = [0.05, 0.05, 0.1], open_top = true }}
[[particles]]
kind = "list"
shape = "ball"
material = "m"
bodies = [{}]
"#,
            bodies.join(", ")
        ),
    );
    assert_eq!(sim.stats().contacts, 49);
    let e_eff = young / (2.0 * (1.0 - nu * nu));
    let hertz = 4.0 / 3.0 * e_eff * r.sqrt() * depth.powf(1.5);
    for (k, f) in sim.world().particles.force.iter().enumerate() {
        assert!(f.x == 0.0 && f.y == 0.0, "sphere {k}: {f:?}");
        assert!(
            (f.z / hertz - 1.0).abs() < 1e-12,
            "sphere {k}: {} N, Hertz {hertz} N",
            f.z
        );
    }
}

/// The same impact integrated apart from the engine: the law's equation of motion
/// `m δ'' = −4/3 E* √R δ^{3/2} − γ_n δ'`, `γ_n = −2√(5/6) β √(2 E* √(R δ) m)`, with
/// the force kept non-negative, by RK4 at a thousandth of the engine's step.
fn reference_restitution(e: f64, v: f64) -> f64 {
    let (r, young, nu, rho) = (0.005, 1e7, 0.3, 2500.0);
    let m = rho * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
    let e_eff = young / (2.0 * (1.0 - nu * nu));
    let beta = e.ln() / (e.ln().powi(2) + std::f64::consts::PI.powi(2)).sqrt();
    let accel = |d: f64, dv: f64| {
        if d <= 0.0 {
            return 0.0;
        }
        let elastic = 4.0 / 3.0 * e_eff * r.sqrt() * d.powf(1.5);
        let gamma = -2.0 * (5.0f64 / 6.0).sqrt() * beta * (2.0 * e_eff * (r * d).sqrt() * m).sqrt();
        -(elastic + gamma * dv).max(0.0) / m
    };
    let (mut d, mut dv, h) = (0.0, v, 1e-9);
    loop {
        let k1 = (dv, accel(d, dv));
        let k2 = (
            dv + 0.5 * h * k1.1,
            accel(d + 0.5 * h * k1.0, dv + 0.5 * h * k1.1),
        );
        let k3 = (
            dv + 0.5 * h * k2.1,
            accel(d + 0.5 * h * k2.0, dv + 0.5 * h * k2.1),
        );
        let k4 = (dv + h * k3.1, accel(d + h * k3.0, dv + h * k3.1));
        d += h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
        dv += h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
        if d < 0.0 {
            return -dv / v;
        }
    }
}

/// The damping of the law's restitution coefficient gives a rebound that does not
/// depend on the impact speed (the dashpot grows as δ^{1/4}), equal to the law's own
/// equation integrated apart (0.3 %); it is not `e` itself, as in LIGGGHTS and EDEM
/// (printed).
#[test]
fn the_damped_restitution_is_the_laws_and_speed_free() {
    for e in [0.3, 0.5, 0.8] {
        let reference = reference_restitution(e, 1.0);
        for v in [0.2, 1.0, 3.0] {
            let realised = wall_restitution(e, v);
            println!("e = {e}: realised {realised:.4} at {v} m/s, law's reference {reference:.4}");
            assert!(
                (realised / reference - 1.0).abs() < 3e-3,
                "e = {e}, v = {v}: realised {realised}, reference {reference}"
            );
        }
    }
}

/// A sphere hitting the face of a much heavier cube is Hertz's sphere on a flat
/// (`R* = r`), with the effective mass of the pair.
#[test]
fn a_sphere_on_a_cube_face_is_hertz_on_a_flat() {
    let (r, rho, young, nu, v) = (0.005, 2500.0, 1e7, 0.3, 1.0);
    let side = 0.04;
    let m = rho * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
    let cube = rho * side * side * side;
    let m_eff = m * cube / (m + cube);
    let e_eff = young / (2.0 * (1.0 - nu * nu));
    let depth = hertz_depth(m_eff, r, e_eff, v);
    let time = 2.0 * HERTZ_TIME_INTEGRAL * depth / v;
    let mut sim = scene(
        &format!("{}", time / 400.0),
        0.0,
        "",
        &material("m", rho, young, nu, 1.0, 0.5),
        &format!(
            r#"[shapes.ball]
kind = "sphere"
radius = {r}
[shapes.cube]
kind = "cuboid"
size = [{side}, {side}, {side}]
[[particles]]
kind = "list"
shape = "cube"
material = "m"
bodies = [{{ position = [0.0, 0.0, 0.0] }}]
[[particles]]
kind = "list"
shape = "ball"
material = "m"
bodies = [{{ position = [0.0, 0.0, {z}], velocity = [0.0, 0.0, {vz}] }}]
"#,
            z = side / 2.0 + r + 1e-7,
            vz = -v
        ),
    );
    let (steps, _) = run_impact(&mut sim, 1);
    let measured = steps as f64 * sim.dt();
    assert!(
        (measured / time - 1.0).abs() < 5e-3,
        "contact time {measured:e} s, Hertz on a flat {time:e} s"
    );
    // Momentum is exchanged along the normal only, and the pair's energy is kept.
    let p = &sim.world().particles;
    let momentum = p.velocity[0] * cube + p.velocity[1] * m;
    assert!((momentum - Vector3::new(0.0, 0.0, -v * m)).norm() < 1e-9 * v * m);
    let energy = 0.5 * cube * p.velocity[0].norm_squared() + 0.5 * m * p.velocity[1].norm_squared();
    assert!((energy / (0.5 * m * v * v) - 1.0).abs() < 1e-4);
}

/// Chung & Ooi's test 6: an alumina sphere (R = 2.5 mm, E = 380 GPa, ν = 0.23,
/// ρ = 4000 kg/m³, μ = 0.092, elastic) hits an alumina plane at 3.9 m/s. Steeper
/// than about 35° from the normal it slides throughout, and the tangential
/// restitution of the contact point and the spin after the impact are the rigid-body
/// answer `e_t = 1 − 3.5 μ (1 + e_n) v_n / v_t`, `ω = 2.5 μ (1 + e_n) v_n / R`
/// (within 1 %). At small angles the contact sticks and Mindlin's tangential spring
/// gives the contact point's velocity back: e_t is that of the law's equations
/// integrated apart ([`stuck_reference`], 1 %), far from the rigid answer 0.
#[test]
fn an_oblique_impact_slides_as_the_rigid_body_answer() {
    let (r, mu, speed) = (0.0025, 0.092, 3.9);
    let tangential_restitution = |angle: f64| {
        let (vt, vn) = (
            speed * angle.to_radians().sin(),
            speed * angle.to_radians().cos(),
        );
        let mut sim = scene(
            "2e-8",
            0.0,
            "",
            &material("alumina", 4000.0, 3.8e11, 0.23, 1.0, mu),
            &format!(
                r#"[shapes.ball]
kind = "sphere"
radius = {r}
[[wall]]
name = "plane"
material = "alumina"
geometry = {{ kind = "plane", centre = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], size = 0.1 }}
[[particles]]
kind = "list"
shape = "ball"
material = "alumina"
bodies = [{{ position = [0.0, 0.0, {z}], velocity = [{vt}, 0.0, {vz}] }}]
"#,
                z = r + 1e-8,
                vz = -vn
            ),
        );
        run_impact(&mut sim, 0);
        let w = sim.world().angular_velocity(0);
        let v = sim.world().particles.velocity[0];
        let contact_point = v + w.cross(&Vector3::new(0.0, 0.0, -r));
        let en = v.z / vn;
        (contact_point.x / vt, w.y, en, vt, vn)
    };
    for angle in [45.0, 60.0, 75.0] {
        let (et, spin, en, vt, vn) = tangential_restitution(angle);
        let rigid_et = 1.0 - 3.5 * mu * (1.0 + en) * vn / vt;
        let rigid_spin = 2.5 * mu * (1.0 + en) * vn / r;
        println!(
            "{angle}°: e_t {et:.4} (rigid {rigid_et:.4}), ω {spin:.2} (rigid {rigid_spin:.2}), e_n {en:.5}"
        );
        assert!((en - 1.0).abs() < 1e-3, "{angle}°: e_n {en}");
        assert!(
            (et - rigid_et).abs() < 0.01,
            "{angle}°: e_t {et}, rigid {rigid_et}"
        );
        assert!(
            (spin / rigid_spin - 1.0).abs() < 0.01,
            "{angle}°: ω {spin}, rigid {rigid_spin}"
        );
    }
    for angle in [5.0, 15.0] {
        let (et, _, _, vt, vn) = tangential_restitution(angle);
        let reference = stuck_reference(r, vt, vn);
        println!("{angle}°: e_t {et:.4}, the law's equations {reference:.4}");
        assert!(
            (et - reference).abs() < 0.01,
            "{angle}°: e_t {et}, reference {reference}"
        );
    }
}

/// The contact point's tangential restitution of the alumina impact of
/// [`an_oblique_impact_slides_as_the_rigid_body_answer`], from the law's equations
/// integrated apart at a ten-thousandth of the engine's step: Hertz's normal force,
/// and a tangential spring `k_t = 8 G* a` that keeps its force when it stiffens and
/// its stretch when it softens (`contact::tangential_force`), capped at `μ F_n`,
/// moving the contact point with the mass `m / (1 + m R² / I) = m / 3.5`.
fn stuck_reference(r: f64, vt: f64, vn: f64) -> f64 {
    let (young, nu, rho, mu) = (3.8e11, 0.23, 4000.0, 0.092);
    let m = rho * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
    let e_eff = young / (2.0 * (1.0 - nu * nu));
    let g_eff = young / (4.0 * (2.0 - nu) * (1.0 + nu));
    let (mut depth, mut dn, mut s, mut k_old, mut u) = (0.0f64, vn, 0.0f64, 0.0f64, vt);
    let h = 2e-12;
    loop {
        let a = (r * depth.max(0.0)).sqrt();
        let normal = 4.0 / 3.0 * e_eff * a * depth.max(0.0);
        let k = 8.0 * g_eff * a;
        if k_old > 0.0 && k > k_old {
            s *= k_old / k;
        }
        s += u * h;
        let mut force = -k * s;
        if force.abs() > mu * normal {
            force = force.signum() * mu * normal;
            s = -force / k.max(f64::MIN_POSITIVE);
        }
        k_old = k;
        // Symplectic Euler on both motions.
        dn -= normal / m * h;
        depth += dn * h;
        u += 3.5 * force / m * h;
        if depth < 0.0 && dn < 0.0 {
            return u / vt;
        }
    }
}

/// A sphere rolling on a floor at 0.1 m/s against a rolling friction μ_r = 0.05
/// decelerates at `μ_r g / (1 + 2/5)` under both models and stops after
/// `v² / 2a` (2 %); the spring–dashpot then gives back its elastic angle and holds
/// the sphere still.
#[test]
fn rolling_resistance_stops_a_rolling_sphere_where_its_torque_says() {
    let (r, v0, mu_r, g) = (0.005, 0.1, 0.05, 9.81);
    let decel = mu_r * g / 1.4;
    let distance = v0 * v0 / (2.0 * decel);
    for model in ["constant_torque", "elastic_plastic"] {
        let young = 1e7;
        let m = 2500.0 * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
        // Start at the static overlap: the weight on Hertz's spring.
        let e_eff = young / (2.0 * (1.0 - 0.09));
        let depth = (3.0 * m * g / (4.0 * e_eff * r.sqrt())).powf(2.0 / 3.0);
        let mut sim = scene(
            "\"auto\"",
            g,
            &format!("rolling = \"{model}\""),
            &format!(
                "{}rolling_friction = {mu_r}\nrolling_damping = 0.3\n",
                material("m", 2500.0, young, 0.3, 0.5, 0.5)
            ),
            &format!(
                r#"[shapes.ball]
kind = "sphere"
radius = {r}
[[wall]]
name = "floor"
material = "m"
geometry = {{ kind = "plane", centre = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], size = 1.0 }}
[[particles]]
kind = "list"
shape = "ball"
material = "m"
bodies = [{{ position = [0.0, 0.0, {z}], velocity = [{v0}, 0.0, 0.0], angular_velocity = [0.0, {w}, 0.0] }}]
"#,
                z = r - depth,
                w = v0 / r
            ),
        );
        let mut stopped_at = None;
        let end = 1.5 * v0 / decel;
        let _ = sim.advance_to(end, |sim, _| {
            let v = sim.world().particles.velocity[0].x;
            if stopped_at.is_none() && v <= 0.0 {
                stopped_at = Some(sim.world().particles.position[0].x);
            }
            ControlFlow::<()>::Continue(())
        });
        let travelled = stopped_at.expect("the sphere stops");
        println!("{model}: stopped after {travelled:.5} m, expected {distance:.5} m");
        assert!(
            (travelled / distance - 1.0).abs() < 0.02,
            "{model}: {travelled} m, expected {distance} m"
        );
        if model == "elastic_plastic" {
            let p = &sim.world().particles;
            assert!(p.velocity[0].norm() < 1e-4, "{}", p.velocity[0]);
            // It rolls back by at most the spring's elastic angle at the cap,
            // `μ_r R m g / k_r`, times R (k_r = 2.25 k_n μ_r² R², k_n = m g / δ).
            let recoil = m * g / (2.25 * (m * g / depth) * mu_r);
            let back = travelled - p.position[0].x;
            assert!(
                back >= 0.0 && back < 1.2 * recoil,
                "rolled back {back} m, elastic recoil {recoil} m"
            );
        }
    }
}
