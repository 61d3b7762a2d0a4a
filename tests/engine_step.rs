//! The CPU engine on small scenes: a particle at rest on a wall carries its weight with
//! the static overlap the volume law predicts; an edge impact on a wall rebounds with
//! the requested restitution; results do not depend on the number of threads.

use nalgebra::{Point3, UnitQuaternion, Vector3};
use talus::contact::Material;
use talus::engine::{Backend, CpuBackend};
use talus::geometry::{Shape, generators};
use talus::world::{BodyType, Wall, World};

fn material(e: f64, friction: f64) -> Material {
    Material {
        name: "glass".into(),
        density: 2500.0,
        young: 1e8,
        poisson: 0.25,
        restitution: e,
        friction,
        rolling_friction: 0.0,
        rolling_damping: 0.0,
    }
}

/// A square floor z = 0 of side `side`, split into `n × n` cells of two triangles.
fn floor(side: f64, n: usize, cell: f64) -> Wall {
    let mut vertices = Vec::new();
    for i in 0..=n {
        for j in 0..=n {
            vertices.push(Point3::new(
                -side / 2.0 + side * i as f64 / n as f64,
                -side / 2.0 + side * j as f64 / n as f64,
                0.0,
            ));
        }
    }
    let id = |i: usize, j: usize| (i * (n + 1) + j) as u32;
    let mut triangles = Vec::new();
    for i in 0..n {
        for j in 0..n {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    Wall::new("floor", 0, vertices, triangles, cell)
}

fn world_with(shape: Shape, e: f64, friction: f64, gravity: f64) -> World {
    let m = material(e, friction);
    World {
        body_types: vec![BodyType::new(shape, &m, 0)],
        materials: vec![m],
        walls: vec![floor(0.2, 8, 0.02)],
        gravity: Vector3::new(0.0, 0.0, -gravity),
        ..World::default()
    }
}

/// A sphere's cap overlap gives F ∝ δ^{5/3}: κ A V^{1/3} with A = π(2rδ − δ²) and
/// V = πδ²(3r − δ)/3.
#[test]
fn sphere_at_rest_on_a_floor_carries_its_weight() {
    let r = 0.005;
    let mut world = world_with(
        Shape::Sphere(talus::geometry::Sphere::new(r).unwrap()),
        0.3,
        0.5,
        9.81,
    );
    world.particles.push(
        0,
        Point3::new(0.003, -0.002, r + 1e-4),
        UnitQuaternion::identity(),
        1,
    );
    let (mut engine, engine_dt) = (CpuBackend::default(), 1e-5);
    engine.initialise(&mut world, engine_dt);
    for _ in 0..30_000 {
        engine.step(&mut world, engine_dt);
    }
    let t = &world.body_types[0];
    let v = world.particles.velocity[0].norm();
    assert!(v < 1e-5, "still moving at {v}");
    let weight = t.mass * 9.81;
    // Solve κ A(δ) V(δ)^{1/3} = m g for δ (κ = 2 E*/R, E* = E/2 for equal materials).
    // The static overlap falls in the regularised range of the law.
    let kappa = 1e8 / r;
    let v0 = (talus::engine::REGULARISATION_LENGTH * r).powi(3);
    let force = |d: f64| {
        let a = std::f64::consts::PI * (2.0 * r * d - d * d);
        let v = std::f64::consts::PI * d * d * (3.0 * r - d) / 3.0;
        if v < v0 {
            kappa * a * v / v0.powf(2.0 / 3.0)
        } else {
            kappa * a * v.cbrt()
        }
    };
    let (mut lo, mut hi) = (0.0, r);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if force(mid) < weight {
            lo = mid
        } else {
            hi = mid
        }
    }
    let sunk = r - world.particles.position[0].z;
    assert!((sunk - lo).abs() < 1e-3 * lo, "sunk {sunk:e} vs {lo:e}");
    assert!((world.walls[0].force.z + weight).abs() < 1e-6 * weight);
    assert!(world.walls[0].force.x.abs() < 1e-9 * weight);
}

#[test]
fn edge_impact_on_a_wall_rebounds_with_the_requested_restitution() {
    let a = 0.01;
    for e in [0.2, 0.7] {
        let mut world = world_with(
            Shape::Polyhedron(generators::cuboid(a, a, a).unwrap().into()),
            e,
            0.0,
            0.0,
        );
        let q =
            UnitQuaternion::from_scaled_axis(Vector3::new(std::f64::consts::FRAC_PI_4, 0.0, 0.0));
        world.particles.push(
            0,
            Point3::new(0.0, 0.0, 0.5 * a * std::f64::consts::SQRT_2 + 1e-5),
            q,
            1,
        );
        world.particles.velocity[0] = Vector3::new(0.0, 0.0, -0.5);
        let (mut engine, engine_dt) = (CpuBackend::default(), 5e-8);
        engine.initialise(&mut world, engine_dt);
        let mut touched = false;
        for _ in 0..400_000 {
            engine.step(&mut world, engine_dt);
            touched |= engine.stats().contacts > 0;
            if touched && engine.stats().contacts == 0 {
                break;
            }
        }
        let v = world.particles.velocity[0];
        assert!(touched && engine.stats().contacts == 0);
        assert!(
            (v.z / 0.5 - e).abs() < 0.02 * e,
            "e = {e}: realised {}",
            v.z / 0.5
        );
        // A centred edge impact does not spin the cube.
        assert!(world.angular_velocity(0).norm() < 1e-6);
    }
}

#[test]
fn results_do_not_depend_on_the_number_of_threads() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let shape = Shape::Polyhedron(generators::dodecahedron(0.005).unwrap().into());
            let mut world = world_with(shape, 0.5, 0.5, 9.81);
            world.materials[0].young = 1e7;
            let mut id = 0;
            for i in 0..5 {
                for j in 0..5 {
                    for k in 0..4 {
                        let q = UnitQuaternion::from_scaled_axis(Vector3::new(
                            i as f64,
                            j as f64 * 0.7,
                            k as f64 * 1.3,
                        ));
                        // Spaced so that the bounding spheres do not overlap.
                        let p = Point3::new(
                            -0.02 + 0.0105 * i as f64,
                            -0.02 + 0.0105 * j as f64,
                            0.0055 + 0.0105 * k as f64,
                        );
                        world.particles.push(0, p, q, id);
                        id += 1;
                    }
                }
            }
            let (mut engine, engine_dt) = (CpuBackend::default(), 1e-5);
            engine.initialise(&mut world, engine_dt);
            let mut contact_steps = 0;
            for _ in 0..4000 {
                engine.step(&mut world, engine_dt);
                contact_steps += engine.stats().contacts;
            }
            assert!(
                world
                    .particles
                    .position
                    .iter()
                    .all(|p| p.coords.iter().all(|x| x.is_finite()))
            );
            (
                world.particles.position.clone(),
                world.particles.angular_momentum.clone(),
                contact_steps,
            )
        })
    };
    let one = run(1);
    assert!(
        one.2 > 2000,
        "the particles land and collide ({} contact-steps)",
        one.2
    );
    let two = run(2);
    assert_eq!(one.0, two.0);
    assert_eq!(one.1, two.1);
}

/// With restitution 1 and no friction the contact forces derive from the potential
/// of the overlap volume, torques included (they come from the volume's rotation
/// gradient, not from a force at the volume centroid): energy is conserved through a
/// tumbling polyhedron–polyhedron collision and a drop on a wall.
#[test]
fn elastic_frictionless_collisions_conserve_energy() {
    for on_wall in [false, true] {
        let shape = Shape::Polyhedron(generators::dodecahedron(0.005).unwrap().into());
        let mut world = world_with(shape, 1.0, 0.0, if on_wall { 9.81 } else { 0.0 });
        world.materials[0].young = 1e7;
        if !on_wall {
            world.walls.clear();
        }
        world.particles.push(
            0,
            Point3::new(0.0, 0.0, 0.0065),
            UnitQuaternion::from_scaled_axis(Vector3::new(1.0, 0.7, 1.3)),
            1,
        );
        if !on_wall {
            let q = UnitQuaternion::from_scaled_axis(Vector3::new(-0.3, 0.2, 0.9));
            world
                .particles
                .push(0, Point3::new(0.0003, 0.0002, 0.0165), q, 2);
            world.particles.velocity[1] = Vector3::new(0.0, 0.0, -0.5);
        }
        let mass = world.body_types[0].mass;
        let energy = |w: &World| {
            w.kinetic_energy()
                + w.particles
                    .position
                    .iter()
                    .map(|p| -mass * w.gravity.z * p.z)
                    .sum::<f64>()
        };
        let (mut engine, engine_dt) = (CpuBackend::default(), 1e-6);
        engine.initialise(&mut world, engine_dt);
        let e0 = energy(&world);
        let mut touched = false;
        for _ in 0..60_000 {
            engine.step(&mut world, engine_dt);
            touched |= engine.stats().contacts > 0;
        }
        assert!(touched, "the bodies collide");
        let e1 = energy(&world);
        assert!(
            (e1 / e0 - 1.0).abs() < 1e-4,
            "on wall {on_wall}: E/E0 = {}",
            e1 / e0
        );
    }
}

/// Regression: resetting the friction spring to the cap's length while a strong
/// dashpot made the contact slide stored energy that came back as a push (a damped,
/// frictional pair collision ended with 7 % more kinetic energy than it began with).
#[test]
fn damped_frictional_collision_never_gains_energy() {
    for (e, mu) in [(0.5, 0.5), (0.9, 0.3), (0.2, 1.0)] {
        let shape = Shape::Polyhedron(generators::dodecahedron(0.005).unwrap().into());
        let mut world = world_with(shape, e, mu, 0.0);
        world.materials[0].young = 1e7;
        world.walls.clear();
        world.particles.push(
            0,
            Point3::new(0.0, 0.0, 0.0065),
            UnitQuaternion::from_scaled_axis(Vector3::new(1.0, 0.7, 1.3)),
            1,
        );
        let q = UnitQuaternion::from_scaled_axis(Vector3::new(-0.3, 0.2, 0.9));
        world
            .particles
            .push(0, Point3::new(0.0003, 0.0002, 0.0165), q, 2);
        world.particles.velocity[1] = Vector3::new(0.0, 0.0, -0.5);
        let (mut engine, engine_dt) = (CpuBackend::default(), 1e-6);
        engine.initialise(&mut world, engine_dt);
        let e0 = world.kinetic_energy();
        let mut worst: f64 = 0.0;
        for _ in 0..5_000 {
            engine.step(&mut world, engine_dt);
            worst = worst.max(world.kinetic_energy() / e0);
        }
        assert!(
            worst <= 1.0 + 1e-9,
            "e = {e}, mu = {mu}: kinetic energy reached {worst} of the initial"
        );
        assert!(
            world.kinetic_energy() < 0.99 * e0,
            "e = {e}, mu = {mu}: the collision dissipates"
        );
    }
}

/// Frozen particles (the buried part of a packed bed) keep their pose to the bit and
/// are no longer integrated, yet still carry a free particle that rests on them: a
/// sphere dropped onto a frozen one comes to rest on top with the static overlap of
/// its weight. Two frozen spheres that overlap have no contact, and frozen spheres
/// do not touch the floor (so the floor carries nothing).
#[test]
fn a_frozen_particle_carries_a_free_one_and_never_moves() {
    let r = 0.005;
    let mut world = world_with(
        Shape::Sphere(talus::geometry::Sphere::new(r).unwrap()),
        0.3,
        0.5,
        9.81,
    );
    let p = &mut world.particles;
    let base = Point3::new(0.01, 0.0, r - 1e-4); // overlaps the floor
    p.push(0, base, UnitQuaternion::identity(), 1);
    p.push(
        0,
        base + Vector3::new(1.9 * r, 0.0, 0.0),
        UnitQuaternion::identity(),
        2,
    );
    p.push(
        0,
        base + Vector3::new(0.0, 0.0, 2.0 * r + 2e-4),
        UnitQuaternion::identity(),
        3,
    );
    p.freeze(0);
    p.freeze(1);
    assert_eq!(p.frozen_count(), 2);
    let frozen: Vec<_> = (0..2).map(|i| (p.position[i], p.orientation[i])).collect();
    let (mut engine, engine_dt) = (CpuBackend::default(), 1e-5);
    engine.initialise(&mut world, engine_dt);
    for _ in 0..30_000 {
        engine.step(&mut world, engine_dt);
    }
    let p = &world.particles;
    for (i, pose) in frozen.iter().enumerate() {
        assert_eq!((p.position[i], p.orientation[i]), *pose, "frozen {i} moved");
        assert_eq!(p.velocity[i], Vector3::zeros());
    }
    assert!(p.velocity[2].norm() < 1e-5, "{}", p.velocity[2].norm());
    assert_eq!(engine.stats().contacts, 1, "only the free sphere's contact");
    assert_eq!(world.walls[0].force, Vector3::zeros());
    // At rest: the contact carries the weight, with the overlap δ of the sphere–sphere
    // volume law at that load: small and positive, straight above the frozen one.
    let m = world.body_types[0].mass;
    assert!((p.force[2].z).abs() < 1e-6 * m * 9.81, "{}", p.force[2].z);
    let delta = 2.0 * r - (p.position[2] - p.position[0]).norm();
    assert!(delta > 0.0 && delta < 0.02 * r, "overlap {delta}");
    assert!((p.position[2].xy() - base.xy()).norm() < 1e-9);
}

/// A pair that parts lets its friction spring go: in the step the two spheres come
/// apart, the stored spring energy is booked as dissipated (no walls here, so it is
/// the step's whole dissipation, to the bit), and the pair keeps no history. On one
/// thread (the fused sweep) and on two (the pair stage and the gather).
#[test]
fn a_parting_pair_lets_its_friction_spring_go() {
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let shape = Shape::Sphere(talus::geometry::Sphere::new(0.005).unwrap());
            // Elastic, so that the normal force (and the friction cap with it) lasts
            // until the spheres part: a dashpot would end it, and empty the spring,
            // a few steps before.
            let mut world = world_with(shape, 1.0, 0.5, 0.0);
            world.walls.clear();
            let rest = UnitQuaternion::identity();
            world.particles.push(0, Point3::new(0.0, 0.0, 0.0), rest, 1);
            world
                .particles
                .push(0, Point3::new(0.004, 0.0, 0.0105), rest, 2);
            // An oblique impact: the spheres slide while they touch.
            world.particles.velocity[1] = Vector3::new(-0.3, 0.0, -0.5);
            let (mut engine, dt) = (CpuBackend::default(), 1e-6);
            engine.initialise(&mut world, dt);
            let mut held = None;
            for step in 0..20_000 {
                engine.step(&mut world, dt);
                let history = engine.contact_history().pairs;
                if engine.stats().contacts > 0 {
                    // (The spring is empty at the first touch: it holds the slip of
                    // the steps since.)
                    assert!(history.len() <= 1, "step {step}: one pair");
                    held = Some(history.first().map_or(0.0, |h| h.1.spring_energy()));
                } else if let Some(spring) = held {
                    assert!(spring > 0.0, "the spring is stretched when they part");
                    assert!(history.is_empty(), "a parted pair keeps no history");
                    assert_eq!(engine.stats().dissipated, spring, "{threads} thread(s)");
                    return;
                }
            }
            panic!("{threads} thread(s): the spheres never touched and parted");
        });
    }
}
