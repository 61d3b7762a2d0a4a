//! A run on one thread is bit for bit the run on two or three: the CPU backend sweeps
//! the pairs in one part per thread (`engine/cpu/fused.rs`), each adding its pairs to
//! the particles whose first pair it holds and deferring the rest, which are added
//! after the sweep part by part; every particle gets its pairs in pair order however
//! many parts there are. Three threads give a particle deferred pairs from two
//! parts. Compared: every particle's state, the step's contacts, elastic energy and
//! dissipation, and the walls' forces.

use std::ops::ControlFlow;
use std::path::Path;

use talus::scene::{Scene, Simulation};

/// Runs `name` (with `overrides`) to `end` on `threads` threads; returns the bits of
/// every particle's state, the last step's figures and the walls' forces.
fn run(name: &str, overrides: &str, end: f64, threads: usize) -> (Vec<u64>, Vec<u64>, usize) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(name);
    let text = std::fs::read_to_string(&path).unwrap() + overrides;
    let scene = Scene::parse(&text, &path).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut sim = Simulation::new(&scene);
        let _ = sim.advance_to(end, |_, _| ControlFlow::<()>::Continue(()));
        let p = &sim.world().particles;
        let mut state = Vec::new();
        for i in 0..p.len() {
            state.extend(p.position[i].coords.iter().map(|x| x.to_bits()));
            state.extend(p.orientation[i].coords.iter().map(|x| x.to_bits()));
            state.extend(p.velocity[i].iter().map(|x| x.to_bits()));
            state.extend(p.angular_momentum[i].iter().map(|x| x.to_bits()));
            state.extend(p.force[i].iter().map(|x| x.to_bits()));
            state.extend(p.torque[i].iter().map(|x| x.to_bits()));
        }
        let stats = sim.stats();
        let mut figures = vec![
            stats.contacts as u64,
            stats.pair_contacts as u64,
            stats.elastic_energy.to_bits(),
            stats.dissipated.to_bits(),
        ];
        for wall in &sim.world().walls {
            figures.extend(wall.force.iter().map(|x| x.to_bits()));
        }
        (state, figures, stats.pair_contacts)
    })
}

fn same_on_one_two_and_three_threads(name: &str, overrides: &str, end: f64) {
    let one = run(name, overrides, end, 1);
    assert!(one.2 > 20, "{name}: {} pair contacts", one.2);
    for threads in [2, 3] {
        let many = run(name, overrides, end, threads);
        assert!(
            one.0 == many.0,
            "{name}: the particles' states differ on {threads} threads"
        );
        assert_eq!(
            one.1, many.1,
            "{name}: contacts, energies or wall forces on {threads} threads"
        );
    }
}

#[test]
fn hertz_spheres_step_alike_on_one_two_and_three_threads() {
    same_on_one_two_and_three_threads(
        "examples/fluid_bed/pour.toml",
        "\n[contact]\nlaw = \"hertz_mindlin\"\nrolling = \"elastic_plastic\"\n",
        0.14,
    );
}

#[test]
fn polyhedra_step_alike_on_one_two_and_three_threads() {
    same_on_one_two_and_three_threads("examples/settling_box/scene.toml", "", 0.1);
}
