//! Scene (d) of `talus bench`: many distinct shapes.
//!
//! A dense lattice of random convex polyhedra three times:
//! - 20 shapes, each particle naming one of them;
//! - the same particles, each with its own shape table (a body type per particle)
//!   of the same 20 seeds, which share the 20 templates (tables that say the same
//!   do): the same contacts, only the number of body types differs, so the ratio
//!   of the two is what a body type costs;
//! - every particle its own random shape (as from scanned rocks): other contacts,
//!   and every contact reads two shapes no other contact shares, which the caches
//!   feel.
//!
//! The bench prints the throughputs, the ratios, and the setup time of each (scene
//! check with the suggested step, then the first force evaluation with its neighbour
//! list).

use std::fmt::Write;
use std::path::Path;
use std::time::Instant;

use anyhow::Result;
use talus::scene::{Scene, Simulation};

/// The bounding radius of every shape, m.
const RADIUS: f64 = 0.005;

/// A cubic lattice of `n_side`³ random convex polyhedra (14 points, radius 5 mm, 30 %
/// jitter) at 1.9 radii, without gravity; particle `k` is shape table `k mod shapes`,
/// the random shape of seed `k mod seeds`.
pub fn many_shapes(n_side: usize, shapes: usize, seeds: usize, material: &str) -> String {
    let a = 1.9 * RADIUS;
    let side = a * (n_side as f64 - 1.0) + 2.0 * RADIUS;
    let mut text = format!(
        r#"
[simulation]
dt = "auto"
end_time = 1.0
gravity = [0.0, 0.0, 0.0]
seed = 3

[contact]
regularisation = 0.2
{material}
[[wall]]
name = "box"
material = "pla"
geometry = {{ kind = "box", min = [-0.001, -0.001, -0.001], max = [{s}, {s}, {s}] }}
"#,
        s = side + 0.001
    );
    let count = n_side.pow(3);
    for k in 0..shapes.min(count) {
        let _ = write!(
            text,
            "[shapes.s{k}]\nkind = \"random_convex\"\npoints = 14\nradius = {RADIUS}\n\
             jitter = 0.3\nseed = {}\n",
            k % seeds
        );
    }
    for k in 0..count {
        let (x, y, z) = (k % n_side, (k / n_side) % n_side, k / (n_side * n_side));
        let at = |i: usize| RADIUS + a * i as f64;
        let _ = write!(
            text,
            "[[particles]]\nkind = \"list\"\nshape = \"s{}\"\nmaterial = \"pla\"\nbodies = [{{ position = [{}, {}, {}] }}]\n",
            k % shapes,
            at(x),
            at(y),
            at(z)
        );
    }
    text
}

/// Seconds to check `text` (with the suggested step) and to build its simulation and
/// first forces.
pub struct Setup {
    pub scene: Scene,
    pub check: f64,
    pub first_step: f64,
}

/// Loads `text` from `dir`, timing the check and the first force evaluation.
pub fn setup(text: &str, dir: &Path) -> Result<Setup> {
    let path = dir.join("shapes.toml");
    std::fs::write(&path, text)?;
    let t = Instant::now();
    let scene = Scene::load(&path)?;
    let check = t.elapsed().as_secs_f64();
    let t = Instant::now();
    drop(Simulation::new(&scene));
    let first_step = t.elapsed().as_secs_f64();
    Ok(Setup {
        scene,
        check,
        first_step,
    })
}
