//! Fluid-coupling benchmark: the time to split every particle's volume among the
//! fluid's cells (what `[fluid] update_interval` renews), for each kind of cells.
//!
//! Run with `cargo bench --bench fluid_shares`. The scene is the settled bed of
//! 10 000 dodecahedra that `talus bench` ships (circumradius 5 mm, a box 0.3155 m
//! square), and the same bed as spheres of equal volume at the same places, on
//!
//! - a structured grid of cells of about two particle diameters (20 × 20 × 7),
//! - a cylindrical grid about the box's axis out past its corners (12 annuli × 10
//!   slabs × 8 sectors),
//! - the structured grid's cells given by their centres and volumes (Voronoi).
//!
//! For each: the time of one renewal on 1 and 2 threads (best of 3, runs of the
//! kinds interleaved), per particle, and the error it is obtained at: how far the
//! shares summed over all cells are from the particles' volume.

use std::path::Path;
use std::time::Instant;

use talus::Real;
use talus::scene::{Scene, Simulation};

mod common;
use common::cpu_model;

/// The shipped bed with its shape's keys replaced by `shape` (the `[shapes.body]`
/// keys) under a fluid of `grid`.
fn scene(shape: &str, grid: &str, dir: &Path) -> Scene {
    let bed = std::fs::read_to_string(dir.join("settled_bed.toml")).unwrap();
    let dodecahedron = "kind = \"platonic\"\nsolid = \"dodecahedron\"\ncircumradius = 0.005";
    assert!(bed.contains(dodecahedron));
    let text = format!(
        "{}\n[fluid]\n{grid}\ndensity = 1000.0\nviscosity = 1e-3\ndrag = \"gidaspow\"\n",
        bed.replace(dodecahedron, shape)
    );
    Scene::parse(&text, &dir.join("settled_bed.toml")).unwrap()
}

fn main() {
    // `cargo test --all-targets` runs benchmarks without `--bench`: nothing to do.
    if !std::env::args().any(|a| a == "--bench") {
        println!("fluid_shares: run with `cargo bench --bench fluid_shares`");
        return;
    }
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/data");
    let h = 0.3155 / 18.0;
    let structured =
        format!("origin = [-{h}, -{h}, -{h}]\ncell = [{h}, {h}, {h}]\ncells = [20, 20, 7]");
    // The structured grid's cells as a coupled code would give them.
    let cells_file =
        std::env::temp_dir().join(format!("talus-bench-cells-{}.csv", std::process::id()));
    let mut csv = String::from("x,y,z,volume\n");
    for k in 0..7 {
        for j in 0..20 {
            for i in 0..20 {
                let c = |n: usize| -h + h * (n as Real + 0.5);
                csv += &format!("{:e},{:e},{:e},{:e}\n", c(i), c(j), c(k), h * h * h);
            }
        }
    }
    std::fs::write(&cells_file, csv).unwrap();
    let grids = [
        ("structured 20 x 20 x 7", structured),
        (
            "cylindrical 12 x 10 x 8",
            "grid = \"cylindrical\"\nbase = [0.15775, 0.15775, -0.01]\nradius = 0.225\n\
             height = 0.2\ncells = [12, 10, 8]"
                .into(),
        ),
        (
            "given 2800 centres",
            format!("grid = \"cells\"\nfile = \"{}\"", cells_file.display()),
        ),
    ];
    // A sphere of the dodecahedron's volume: 2.785 R³ for circumradius R.
    let r_sphere = 0.005 * (2.785_163_863_123_011f64 * 3.0 / (4.0 * std::f64::consts::PI)).cbrt();
    let shapes = [
        (
            "dodecahedra",
            "kind = \"platonic\"\nsolid = \"dodecahedron\"\ncircumradius = 0.005".to_string(),
        ),
        ("spheres", format!("kind = \"sphere\"\nradius = {r_sphere}")),
    ];
    println!("machine: {}", cpu_model());
    println!("scene: the settled bed of talus bench (a), 10 000 particles");
    for (shape_name, shape) in &shapes {
        let mut sims: Vec<(&str, Simulation)> = grids
            .iter()
            .map(|(name, grid)| (*name, Simulation::new(&scene(shape, grid, &data))))
            .collect();
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut best = vec![f64::INFINITY; sims.len()];
            for _ in 0..3 {
                for (k, (_, sim)) in sims.iter_mut().enumerate() {
                    let start = Instant::now();
                    pool.install(|| sim.update_fluid());
                    best[k] = best[k].min(start.elapsed().as_secs_f64());
                }
            }
            for ((name, sim), t) in sims.iter().zip(&best) {
                let fluid = sim.fluid().unwrap();
                let world = sim.world();
                let n = world.particles.len();
                let volume = n as Real * world.body_types[0].shape.volume();
                let shares: Real = fluid
                    .solid_fraction
                    .iter()
                    .enumerate()
                    .map(|(c, phi)| phi * fluid.grid.cell_volume(c))
                    .sum();
                println!(
                    "{shape_name:<11} {name:<24} {threads} thread(s): {:8.1} ms, {:6.1} µs/particle; \
                     shares against volume {:.1e}",
                    1e3 * t,
                    1e6 * t / n as f64,
                    (shares / volume - 1.0).abs()
                );
            }
        }
    }
    let _ = std::fs::remove_file(&cells_file);
}
