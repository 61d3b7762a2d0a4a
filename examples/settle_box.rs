//! Diagnostic (not a user example): 200 dodecahedra dropped into an open box.
//!
//! `cargo run --release --example settle_box -- YOUNG DT` prints the largest speed,
//! the kinetic energy and how many particles left the box over one second, and the
//! speed in particle-steps/s and contacts/s. With YOUNG = 1e7 and DT = 1e-5 the pile
//! forms and its kinetic energy falls a thousandfold, but resting faces keep rattling
//! (largest speed ~0.05 m/s): the step exceeds the stable one of the regularised flat
//! contact (period ~8 µs here); a suggested time step is still to be built.
use nalgebra::{Point3, UnitQuaternion, Vector3};
use talus::contact::Material;
use talus::engine::{Backend, CpuBackend};
use talus::geometry::{Shape, generators};
use talus::world::{BodyType, Wall, World};

fn quad(
    v: &mut Vec<Point3<f64>>,
    t: &mut Vec<[u32; 3]>,
    a: Point3<f64>,
    b: Point3<f64>,
    c: Point3<f64>,
    d: Point3<f64>,
) {
    let k = v.len() as u32;
    v.extend([a, b, c, d]);
    t.push([k, k + 1, k + 2]);
    t.push([k, k + 2, k + 3]);
}

fn main() {
    let young: f64 = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(1e7);
    let dt: f64 = std::env::args()
        .nth(2)
        .map(|s| s.parse().unwrap())
        .unwrap_or(1e-5);
    let m = Material {
        name: "g".into(),
        density: 2500.0,
        young,
        poisson: 0.25,
        restitution: 0.5,
        friction: 0.5,
        rolling_friction: 0.0,
        rolling_damping: 0.0,
    };
    let r = 0.005;
    let l = 0.06;
    let h = 0.15;
    let (mut v, mut t) = (Vec::new(), Vec::new());
    let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
    // floor (normal +z), walls facing inwards
    quad(
        &mut v,
        &mut t,
        p(0.0, 0.0, 0.0),
        p(l, 0.0, 0.0),
        p(l, l, 0.0),
        p(0.0, l, 0.0),
    );
    quad(
        &mut v,
        &mut t,
        p(0.0, 0.0, 0.0),
        p(0.0, 0.0, h),
        p(l, 0.0, h),
        p(l, 0.0, 0.0),
    );
    quad(
        &mut v,
        &mut t,
        p(0.0, l, 0.0),
        p(l, l, 0.0),
        p(l, l, h),
        p(0.0, l, h),
    );
    quad(
        &mut v,
        &mut t,
        p(0.0, 0.0, 0.0),
        p(0.0, l, 0.0),
        p(0.0, l, h),
        p(0.0, 0.0, h),
    );
    quad(
        &mut v,
        &mut t,
        p(l, 0.0, 0.0),
        p(l, 0.0, h),
        p(l, l, h),
        p(l, l, 0.0),
    );
    let wall = Wall::new("box", 0, v, t, 0.02);
    let mut world = World {
        body_types: vec![BodyType::new(
            Shape::Polyhedron(generators::dodecahedron(r).unwrap().into()),
            &m,
            0,
        )],
        materials: vec![m],
        walls: vec![wall],
        gravity: Vector3::new(0.0, 0.0, -9.81),
        ..World::default()
    };
    let mut id = 0;
    let s = 0.0105;
    for i in 0..5 {
        for j in 0..5 {
            for k in 0..8 {
                let q = UnitQuaternion::from_scaled_axis(Vector3::new(
                    i as f64 + 0.3 * k as f64,
                    j as f64 * 0.7,
                    k as f64 * 1.3,
                ));
                world.particles.push(
                    0,
                    Point3::new(
                        0.008 + s * i as f64,
                        0.008 + s * j as f64,
                        0.006 + s * k as f64,
                    ),
                    q,
                    id,
                );
                id += 1;
            }
        }
    }
    let (mut engine, engine_dt) = (CpuBackend::default(), dt);
    engine.initialise(&mut world, engine_dt);
    let t0 = std::time::Instant::now();
    let steps = (1.0 / dt) as usize;
    let mut contact_steps = 0usize;
    for step in 0..steps {
        engine.step(&mut world, engine_dt);
        contact_steps += engine.stats().contacts;
        if step % (steps / 20) == 0 {
            let vmax = world
                .particles
                .velocity
                .iter()
                .map(|v| v.norm())
                .fold(0.0, f64::max);
            let zmin = world
                .particles
                .position
                .iter()
                .map(|p| p.z)
                .fold(f64::INFINITY, f64::min);
            let out = world
                .particles
                .position
                .iter()
                .filter(|p| p.x < 0.0 || p.x > l || p.y < 0.0 || p.y > l || p.z < 0.0)
                .count();
            println!(
                "t {:.3} vmax {:.3e} zmin {:.4e} contacts {} out {} ke {:.3e}",
                world.time,
                vmax,
                zmin,
                engine.stats().contacts,
                out,
                world.kinetic_energy()
            );
        }
    }
    let wall = t0.elapsed().as_secs_f64();
    println!(
        "{} particles, {} steps in {:.1} s: {:.0} particle-steps/s, {:.0} contacts/s",
        world.particles.len(),
        steps,
        wall,
        (world.particles.len() * steps) as f64 / wall,
        contact_steps as f64 / wall
    );
}
