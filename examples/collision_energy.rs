//! Diagnostic (not a user example): energy budget of one dodecahedron collision.
//!
//! `cargo run --release --example collision_energy -- E MU DT PAIR` with restitution
//! `E`, friction `MU`, time step `DT`, and `PAIR` = 1 for two particles in free space
//! (0 for a drop on a floor). Prints kinetic (+ potential) energy over the initial
//! value while in contact. Every combination must end at or below 1 (an earlier
//! reset of the friction spring while sliding created energy: E = 0.5, MU = 0.5 gave
//! +7 %; now 0.68).

use nalgebra::{Point3, UnitQuaternion, Vector3};
use talus::contact::Material;
use talus::engine::{Backend, CpuBackend};
use talus::geometry::{Shape, generators};
use talus::world::{BodyType, Wall, World};
fn main() {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|s| s.parse().unwrap())
        .collect();
    let (e, mu, dt, two) = (args[0], args[1], args[2], args[3] > 0.5);
    let m = Material {
        name: "g".into(),
        density: 2500.0,
        young: 1e7,
        poisson: 0.25,
        restitution: e,
        friction: mu,
        rolling_friction: 0.0,
        rolling_damping: 0.0,
    };
    let vertices = vec![
        Point3::new(-0.1, -0.1, 0.0),
        Point3::new(0.1, -0.1, 0.0),
        Point3::new(0.1, 0.1, 0.0),
        Point3::new(-0.1, 0.1, 0.0),
    ];
    let wall = Wall::new("floor", 0, vertices, vec![[0, 1, 2], [0, 2, 3]], 0.02);
    let mut world = World {
        body_types: vec![BodyType::new(
            Shape::Polyhedron(generators::dodecahedron(0.005).unwrap().into()),
            &m,
            0,
        )],
        materials: vec![m],
        walls: if two { vec![] } else { vec![wall] },
        gravity: if two {
            Vector3::zeros()
        } else {
            Vector3::new(0.0, 0.0, -9.81)
        },
        ..World::default()
    };
    let q = UnitQuaternion::from_scaled_axis(Vector3::new(1.0, 0.7, 1.3));
    world.particles.push(0, Point3::new(0.0, 0.0, 0.0065), q, 1);
    if two {
        world.particles.push(
            0,
            Point3::new(0.0003, 0.0002, 0.0165),
            UnitQuaternion::from_scaled_axis(Vector3::new(-0.3, 0.2, 0.9)),
            2,
        );
        world.particles.velocity[1] = Vector3::new(0.0, 0.0, -0.5);
    }
    let (mut engine, engine_dt) = (CpuBackend::default(), dt);
    engine.initialise(&mut world, engine_dt);
    let mass = world.body_types[0].mass;
    let energy = |w: &World| {
        w.kinetic_energy()
            + w.particles
                .position
                .iter()
                .map(|p| mass * 9.81 * p.z)
                .sum::<f64>()
                * if two { 0.0 } else { 1.0 }
    };
    let e0 = energy(&world);
    let steps = (0.1 / dt) as usize;
    for k in 0..steps {
        engine.step(&mut world, engine_dt);
        if k % (steps / 2000) == 0 && engine.stats().contacts > 0 {
            println!(
                "t {:.4} E/E0 {:.6} contacts {} z {:.4e}",
                world.time,
                energy(&world) / e0,
                engine.stats().contacts,
                world.particles.position[0].z
            );
        }
    }
}
