//! `talus bench`: whole-step throughput on two standard scenes, on 1 and 2 threads,
//! with the accuracy the step was run at.
//!
//! (a) A dense bed of dodecahedra: a lattice of randomly oriented regular dodecahedra
//!     at a spacing of 1.75 circumscribed radii, so that most neighbours touch (about
//!     six contacts per particle), in a box, without gravity. It stands in for a
//!     settled bed, whose preparation would take longer than the benchmark.
//! (b) Spheres (radius 5 mm, friction 0.5) falling into a box whose walls are read
//!     from an STL file.
//! (c) A dense bed of the same spheres: a cubic lattice at a spacing of 1.98 radii
//!     (every neighbour pressed 1 % of the radius, six contacts per particle), in a
//!     box, without gravity: what a settled sphere bed costs.
//!
//! The step is the suggested one of each scene; the accuracy it buys is the realised
//! restitution of a flat drop and of a sphere drop at that step, measured here.

use std::path::Path;
use std::time::Instant;

use anyhow::Result;
use talus::scene::{Scene, Simulation};

fn machine() -> String {
    let model = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    format!("{model}, {cores} logical cores")
}

const MATERIAL: &str = r#"
[materials.pla]
density = 1500.0
young = 1e6
poisson = 0.1
restitution = 0.5
friction = 0.5
"#;

/// A cubic lattice of `n_side`³ particles of `shape` (a [shapes] body, bounding
/// radius 5 mm) at `spacing` bounding radii, in a box, without gravity.
fn dense_lattice(n_side: usize, shape: &str, spacing: f64) -> String {
    let r = 0.005;
    let a = spacing * r;
    let side = a * (n_side as f64 - 1.0) + 2.0 * r;
    format!(
        r#"
[simulation]
dt = "auto"
end_time = 1.0
gravity = [0.0, 0.0, 0.0]
seed = 1

[contact]
regularisation = 0.2
{MATERIAL}
[shapes.body]
{shape}

[[wall]]
name = "box"
material = "pla"
geometry = {{ kind = "box", min = [-0.001, -0.001, -0.001], max = [{s}, {s}, {s}] }}

[[particles]]
kind = "lattice"
shape = "body"
material = "pla"
min = [0.0, 0.0, 0.0]
max = [{side}, {side}, {side}]
spacing = {a}
"#,
        s = side + 0.001
    )
}

fn spheres(n_side: usize, height: usize) -> String {
    let r = 0.005;
    let a = 2.2 * r;
    let w = a * n_side as f64;
    let h = a * height as f64;
    format!(
        r#"
[simulation]
dt = "auto"
end_time = 1.0
seed = 2
{MATERIAL}
[shapes.ball]
kind = "sphere"
radius = {r}

[[wall]]
name = "box"
material = "pla"
geometry = {{ kind = "mesh", file = "box.stl" }}

[[particles]]
kind = "lattice"
shape = "ball"
material = "pla"
min = [0.0, 0.0, 0.0]
max = [{w}, {w}, {h}]
spacing = {a}
velocity = [0.0, 0.0, -0.5]
"#
    )
}

/// Realised restitution error of a drop of `shape` (a [shapes] entry) at step `dt`.
fn restitution_error(shape: &str, dt: f64, regularisation: f64) -> f64 {
    let text = format!(
        r#"
[simulation]
dt = {dt}
end_time = 1.0
gravity = [0.0, 0.0, 0.0]
[contact]
regularisation = {regularisation}
{MATERIAL}
[shapes.s]
{shape}
[[wall]]
name = "floor"
material = "pla"
geometry = {{ kind = "plane", centre = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], size = 0.2 }}
[[particles]]
kind = "list"
shape = "s"
material = "pla"
bodies = [{{ position = [0.0, 0.0, 0.0051] , velocity = [0.0, 0.0, -1.0] }}]
"#
    );
    let scene = Scene::parse(&text, Path::new("drop.toml")).expect("valid drop scene");
    let mut sim = Simulation::new(&scene);
    // A polyhedron falls with a vertex straight below its centroid: a central impact,
    // so the rebound speed of the centroid is that of the contact.
    if let Some(p) = sim.world.body_types[0].shape.as_polyhedron() {
        let v = p.vertices()[0].coords;
        let q = nalgebra::UnitQuaternion::rotation_between(&v, &-nalgebra::Vector3::z())
            .unwrap_or_else(nalgebra::UnitQuaternion::identity);
        sim.world.particles.orientation[0] = q;
        sim.world.particles.position[0].z = v.norm() + 1e-4;
        sim.engine.initialise(&mut sim.world);
    }
    let mut touched = false;
    for _ in 0..10_000_000 {
        sim.step();
        touched |= sim.engine.contacts > 0;
        if touched && sim.engine.contacts == 0 {
            break;
        }
    }
    (sim.world.particles.velocity[0].z / 0.5 - 1.0).abs()
}

struct Measured {
    particles: usize,
    pairs: usize,
    contacts: f64,
    particle_steps: f64,
    contact_rate: f64,
}

fn measure(scene: &Scene, threads: usize, warmup: usize, steps: usize) -> Result<Measured> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    Ok(pool.install(|| {
        let mut sim = Simulation::new(scene);
        for _ in 0..warmup {
            sim.step();
        }
        let mut contacts = 0usize;
        let t = Instant::now();
        for _ in 0..steps {
            sim.step();
            contacts += sim.engine.contacts;
        }
        let s = t.elapsed().as_secs_f64();
        Measured {
            particles: sim.world.particles.len(),
            pairs: sim.engine.candidate_pairs(),
            contacts: contacts as f64 / steps as f64,
            particle_steps: (sim.world.particles.len() * steps) as f64 / s,
            contact_rate: contacts as f64 / s,
        }
    }))
}

/// Options of `talus bench`.
pub struct BenchOptions {
    /// Scale factor on the particle counts (1: 10 000 dodecahedra, 5000 spheres).
    pub scale: f64,
    /// Timed steps per run.
    pub steps: usize,
}

/// `talus bench`.
pub fn bench(options: BenchOptions) -> Result<()> {
    let dir = std::env::temp_dir().join(format!("talus-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let n_side = ((10_000.0 * options.scale).cbrt().round() as usize).max(2);
    let sphere_side = ((5000.0 * options.scale / 20.0).sqrt().round() as usize).max(2);
    let sphere_bed_side = ((5000.0 * options.scale).cbrt().round() as usize).max(2);
    let w = 2.2 * 0.005 * sphere_side as f64;
    let walls = talus::geometry::surfaces::box_inside(
        [-0.001, -0.001, -0.001].into(),
        [w + 0.001, w + 0.001, 0.4].into(),
        true,
    )?;
    let tris: Vec<[usize; 3]> = walls
        .triangles
        .iter()
        .map(|t| t.map(|v| v as usize))
        .collect();
    talus::geometry::mesh_io::write_stl(&dir.join("box.stl"), &walls.vertices, &tris)?;
    let dodecahedron = "kind = \"platonic\"\nsolid = \"dodecahedron\"\ncircumradius = 0.005";
    let sphere = "kind = \"sphere\"\nradius = 0.005";
    let cases = [
        (
            "(a) dense bed of dodecahedra",
            dense_lattice(n_side, dodecahedron, 1.75),
            dodecahedron,
            0.2,
        ),
        (
            "(b) spheres falling into an STL box",
            spheres(sphere_side, 20),
            sphere,
            0.01,
        ),
        (
            "(c) dense bed of spheres",
            dense_lattice(sphere_bed_side, sphere, 1.98),
            sphere,
            0.01,
        ),
    ];
    println!("machine: {}", machine());
    println!(
        "{:<38} {:>7} {:>9} {:>10} {:>9} {:>8} {:>16} {:>14} {:>10}",
        "scene",
        "threads",
        "particles",
        "cand.pairs",
        "contacts",
        "dt",
        "particle-steps/s",
        "contacts/s",
        "e error"
    );
    for (name, text, shape, reg) in cases {
        let path = dir.join("scene.toml");
        std::fs::write(&path, &text)?;
        let scene = Scene::load(&path)?;
        let error = restitution_error(shape, scene.dt, reg);
        for threads in [1, 2] {
            let m = measure(&scene, threads, 200, options.steps)?;
            println!(
                "{:<38} {:>7} {:>9} {:>10} {:>9.0} {:>8.1e} {:>16.3e} {:>14.3e} {:>9.2}%",
                name,
                threads,
                m.particles,
                m.pairs,
                m.contacts,
                scene.dt,
                m.particle_steps,
                m.contact_rate,
                100.0 * error
            );
        }
    }
    println!(
        "dt: the suggested step of each scene; e error: |realised/requested − 1| of the \
         restitution of a drop of the same shape at that dt (requested e = 0.5)."
    );
    let _ = std::fs::remove_dir_all(&dir);
    Ok(())
}
