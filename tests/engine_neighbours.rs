//! The Verlet lists change nothing but the cost: a run that keeps its candidate lists
//! while particles move less than half the skin is bit for bit the run that rebuilds
//! them every step (skin 0), through inlets adding particles, a turning drum wall,
//! polyhedra, spheres and walls in contact together, and refreshes of the space
//! order that store the particles anew; and the lists are really kept.

use std::path::Path;

use talus::engine::StepParams;
use talus::scene::{Scene, Simulation};
use talus::world::Particles;

/// Dodecahedra and spheres poured by an inlet into a slowly turning closed drum
/// whose end caps follow the shell.
const SCENE: &str = r#"
[simulation]
dt = 2e-5
end_time = 1.0
seed = 5

[contact]
regularisation = 0.5

[materials.pla]
density = 1500.0
young = 1e6
poisson = 0.1
restitution = 0.5
friction = 0.5

[shapes.dodecahedron]
kind = "platonic"
solid = "dodecahedron"
circumradius = 0.004

[shapes.bead]
kind = "sphere"
radius = 0.003

[[wall]]
name = "shell"
material = "pla"
geometry = { kind = "cylinder", base = [0.0, -0.015, 0.0], axis = [0.0, 1.0, 0.0], length = 0.03, radius = 0.04, sides = 48 }
motion = { kind = "rotation", axis = [0.0, 1.0, 0.0], point = [0.0, 0.0, 0.0], rpm = 30.0 }

[[wall]]
name = "front"
material = "pla"
geometry = { kind = "disc", centre = [0.0, -0.015, 0.0], normal = [0.0, 1.0, 0.0], radius = 0.04, sides = 48 }
motion = { kind = "attached", to = "shell" }

[[wall]]
name = "back"
material = "pla"
geometry = { kind = "disc", centre = [0.0, 0.015, 0.0], normal = [0.0, -1.0, 0.0], radius = 0.04, sides = 48 }
motion = { kind = "attached", to = "shell" }

[[particles]]
kind = "lattice"
shape = "dodecahedron"
material = "pla"
min = [-0.025, -0.01, -0.034]
max = [0.025, 0.01, -0.005]
spacing = 0.0085

[[inlet]]
shape = "bead"
material = "pla"
min = [-0.02, -0.01, 0.0]
max = [0.02, 0.01, 0.02]
rate = 4000.0
count = 40
"#;

fn run(skin: Option<f64>, steps: usize) -> Simulation {
    let scene = Scene::parse(SCENE, Path::new("drum.toml")).expect("valid scene");
    let mut sim = Simulation::new(&scene);
    sim.set_params(StepParams {
        skin,
        ..sim.params()
    });
    for _ in 0..steps {
        sim.step();
    }
    sim
}

#[test]
fn kept_lists_give_the_same_run_as_lists_rebuilt_every_step() {
    let steps = 5000;
    let kept = run(None, steps);
    let rebuilt = run(Some(0.0), steps);
    let (a, b) = (&kept.world().particles, &rebuilt.world().particles);
    assert!(a.len() > 40, "the inlet added its beads: {}", a.len());
    assert_eq!(a.len(), b.len());
    assert!(
        kept.stats().contacts > 20,
        "{} contacts",
        kept.stats().contacts
    );
    assert_eq!(a.id, b.id);
    // The space order's refreshes (every 1000 steps) coded every particle and
    // stored them by cell, no longer by id.
    let keys: Vec<_> = (0..a.owned()).map(|i| a.space_key(i)).collect();
    assert!(keys.is_sorted(), "stored in the space order");
    assert!(!a.id.is_sorted(), "stored by cell, not by id");
    assert!(a.cell_code.iter().all(|&c| c != Particles::NO_CELL));
    assert_eq!(a.cell_code, b.cell_code);
    assert_eq!(a.position, b.position);
    assert_eq!(a.orientation, b.orientation);
    assert_eq!(a.velocity, b.velocity);
    assert_eq!(a.angular_momentum, b.angular_momentum);
    for (w, v) in kept.world().walls.iter().zip(&rebuilt.world().walls) {
        assert_eq!(w.force, v.force, "{}", w.name);
        assert_eq!(w.torque, v.torque, "{}", w.name);
    }
    assert_eq!(
        kept.backend().contact_history(),
        rebuilt.backend().contact_history()
    );
    // Rebuilding every step is what skin 0 means; the kept lists last many steps.
    assert_eq!(rebuilt.stats().list_builds, steps as u64 + 1);
    let builds = kept.stats().list_builds;
    println!(
        "{} particles, {} contacts, {} / {} candidate pairs, {builds} builds in {steps} steps",
        a.len(),
        kept.stats().contacts,
        kept.stats().candidate_pairs,
        rebuilt.stats().candidate_pairs
    );
    assert!(
        builds * 5 < steps as u64,
        "{builds} builds in {steps} steps"
    );
    assert!(kept.stats().candidate_pairs >= rebuilt.stats().candidate_pairs);
}
