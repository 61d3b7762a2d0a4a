//! Validation 4: a frictionless, perfectly elastic gas of 100 dodecahedra in a closed
//! box keeps its total energy (kinetic plus the elastic energy stored in the contacts)
//! within 0.5 % over 100 mean collision times.
//!
//! The mean collision time is measured, not assumed: the number of particle–particle
//! contacts that begin, per particle, over the run.

use std::collections::BTreeSet;
use std::path::Path;

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use talus::scene::{Scene, Simulation};

const SCENE: &str = r#"
[simulation]
dt = "auto"
end_time = 1.0
gravity = [0.0, 0.0, 0.0]

[contact]
regularisation = 0.5

[materials.elastic]
density = 1500.0
young = 1e6
poisson = 0.25
restitution = 1.0
friction = 0.0

[shapes.dodecahedron]
kind = "platonic"
solid = "dodecahedron"
circumradius = 0.005

[[wall]]
name = "box"
material = "elastic"
geometry = { kind = "box", min = [0.0, 0.0, 0.0], max = [0.06, 0.06, 0.06] }

[[particles]]
kind = "lattice"
shape = "dodecahedron"
material = "elastic"
min = [0.0, 0.0, 0.0]
max = [0.06, 0.06, 0.06]
count = 100
"#;

#[test]
fn elastic_gas_of_dodecahedra_conserves_energy() {
    let scene = Scene::parse(SCENE, Path::new("gas.toml")).unwrap();
    let mut sim = Simulation::new(&scene);
    let mut rng = Pcg64::seed_from_u64(3);
    assert_eq!(sim.world().particles.len(), 100);
    sim.edit_world(|w| {
        let p = &mut w.particles;
        for i in 0..p.len() {
            let mut v = || rng.random_range(-1.0..1.0);
            p.velocity[i] = Vector3::new(v(), v(), v()) * 2.0;
            p.angular_momentum[i] = Vector3::new(v(), v(), v()) * 1e-7;
        }
    });
    let energy = |s: &Simulation| s.world().kinetic_energy() + s.stats().elastic_energy;
    let e0 = energy(&sim);
    // Count contacts that begin: pairs in contact now but not at the previous check.
    let mut collisions = 0usize;
    let mut previous: BTreeSet<(usize, usize)> = BTreeSet::new();
    let mut worst: f64 = 0.0;
    let mut steps = 0;
    while collisions < 100 * 100 / 2 {
        sim.step();
        steps += 1;
        let now = touching(&sim);
        collisions += now.difference(&previous).count();
        previous = now;
        worst = worst.max((energy(&sim) / e0 - 1.0).abs());
        assert!(steps < 2_000_000, "too few collisions: {collisions}");
    }
    println!(
        "{steps} steps (dt = {:.3e} s, t = {:.3} s), {collisions} collisions, \
         largest energy error {:.3e}",
        scene.dt,
        sim.time(),
        worst
    );
    assert!(worst < 5e-3, "energy drifted by {worst}");
}

/// Pairs of particles whose bounding spheres overlap and whose shapes intersect.
fn touching(sim: &Simulation) -> BTreeSet<(usize, usize)> {
    use talus::geometry::gjk::{GjkResult, gjk};
    let w = sim.world();
    let p = &w.particles;
    let shape = w.body_types[0].shape.as_polyhedron().unwrap();
    let r = shape.circumradius();
    let mut out = BTreeSet::new();
    for i in 0..p.len() {
        for j in i + 1..p.len() {
            if (p.position[i] - p.position[j]).norm() < 2.0 * r {
                let pi = nalgebra::Isometry3::from_parts(p.position[i].into(), p.orientation[i]);
                let pj = nalgebra::Isometry3::from_parts(p.position[j].into(), p.orientation[j]);
                if matches!(
                    gjk(shape, shape, &(pi.inverse() * pj), None),
                    GjkResult::Intersecting
                ) {
                    out.insert((i, j));
                }
            }
        }
    }
    out
}
