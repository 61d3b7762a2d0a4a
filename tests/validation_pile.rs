//! Validation 5, hard case: 1000 dodecahedra poured into a box come to rest inside it.
//! Its own test binary: at about six minutes of two threads it is the longest test,
//! and it should not share the cores with others.

mod common;

use std::path::Path;

use common::settle;
use talus::scene::{Scene, Simulation};

/// 1000 dodecahedra dropped from a loose lattice into a box come to rest: every
/// particle slower than 1 mm/s for 50 ms (at about 1.75 s), none left the box, nothing
/// became NaN, and the bed never gained energy: kinetic plus gravitational plus
/// contact energy ends below its value at the start (a damped, frictional system can
/// only lose it), and the potential energy released is dissipated.
///
/// The bed compacts slowly after the impact (its mean height falls 0.6 mm between
/// 0.4 and 1.5 s, ever more slowly), with single particles slipping into gaps at up
/// to 0.4 m/s until about 1.7 s: a 1.2 s run, as in earlier sessions, stops amid that.
#[test]
fn a_thousand_dodecahedra_poured_into_a_box_come_to_rest_in_it() {
    let text = r#"
[simulation]
dt = "auto"
end_time = 3.0
seed = 11
settle = { max_speed = 1e-3, hold = 0.05 }

[contact]
regularisation = 0.5

[materials.pla]
density = 1500.0
young = 1e5
poisson = 0.1
restitution = 0.1
friction = 0.5

[materials.steel]
density = 7800.0
young = 2e11
poisson = 0.3
restitution = 0.1
friction = 0.5

[shapes.dodecahedron]
kind = "platonic"
solid = "dodecahedron"
circumradius = 0.005

[[wall]]
name = "box"
material = "steel"
geometry = { kind = "box", min = [0.0, 0.0, 0.0], max = [0.15, 0.15, 0.3] }

[[particles]]
kind = "lattice"
shape = "dodecahedron"
material = "pla"
min = [0.0, 0.0, 0.0]
max = [0.15, 0.15, 0.3]
spacing = 0.0106
count = 1000
"#;
    let energy = |sim: &Simulation| {
        let w = sim.world();
        let p = &w.particles;
        let potential: f64 = (0..p.len())
            .map(|i| w.body_types[p.body_type[i] as usize].mass * 9.81 * p.position[i].z)
            .sum();
        (
            w.kinetic_energy() + potential + sim.stats().elastic_energy,
            potential,
        )
    };
    let start = energy(&Simulation::new(
        &Scene::parse(text, Path::new("pile.toml")).unwrap(),
    ));
    let sim = settle(text, [0.0; 3], [0.15, 0.15, 0.3], 3.0, true);
    assert_eq!(sim.world().particles.len(), 1000);
    let end = energy(&sim);
    let released = start.1 - end.1;
    let ke = sim.world().kinetic_energy();
    println!(
        "energy: start {:.4e} J, end {:.4e} J; potential released {released:.3e} J, \
         kinetic left {ke:.3e} J",
        start.0, end.0
    );
    assert!(end.0 < start.0, "the bed gained energy");
    assert!(
        released > 0.0 && ke < 1e-4 * released,
        "kinetic energy {ke} J"
    );
}
