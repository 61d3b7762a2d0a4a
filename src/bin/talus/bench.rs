//! `talus bench`: whole-step throughput on three standard scenes, on 1 and 2 threads,
//! with the accuracy the step was run at.
//!
//! (a) A dense settled bed of dodecahedra: 10 000 regular dodecahedra (circumradius
//!     5 mm) poured into a box under gravity, come to rest. Pouring takes about 20
//!     minutes on two cores even quenched, so the bed's poses ship with talus
//!     (`benches/data/settled_dodecahedra.csv`); `talus bench --prepare-bed FILE`
//!     makes them again (see [`prepare_bed`]). A smaller `--scale` keeps the lowest
//!     particles, a shallower settled bed in the same box.
//! (b) The pour of `benches/peers/`: 5000 spheres (radius 5 mm, Hertz–Mindlin,
//!     friction 0.5) from rest on a lattice poured into an open-top box of STL walls,
//!     timed over its whole second, from free fall to the settled bed.
//! (c) A dense bed of the same spheres: a cubic lattice at a spacing of 1.98 radii
//!     (every neighbour pressed 1 % of the radius, six contacts per particle), in a
//!     box, without gravity: what a settled sphere bed costs.
//!
//! The step is the suggested one of each scene; the accuracy it buys is the realised
//! restitution of a flat drop and of a sphere drop at that step, measured here.

use std::ops::ControlFlow;
use std::path::Path;
use std::time::Instant;

use anyhow::{Result, anyhow, bail};
use rand::{Rng, SeedableRng};
use talus::Real;
use talus::engine::choice::{self, BackendKind};
use talus::scene::{Scene, Simulation};

pub fn machine() -> String {
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

/// The settled bed of scene (a): `x,y,z,qw,qx,qy,qz` of 10 000 dodecahedra resting
/// in [`BED_BOX`] (a few pellets along the walls still slide), written by
/// [`prepare_bed`].
const SETTLED_BED: &str = include_str!("../../../benches/data/settled_dodecahedra.csv");

/// The box of the settled bed: 0.3155 m square (30 lattice columns at 2.1
/// circumradii), open at the top.
const BED_BOX: [f64; 3] = [0.3155, 0.3155, 0.2];

/// The dodecahedron of scene (a).
pub const DODECAHEDRON: &str =
    "kind = \"platonic\"\nsolid = \"dodecahedron\"\ncircumradius = 0.005";

/// Scene (a)'s box under gravity with `material` (a `[materials.pla]` table),
/// `particles` (a `[[particles]]` table) and `extra` lines in `[simulation]`.
fn bed_scene(material: &str, particles: &str, extra: &str) -> String {
    bed_scene_in(BED_BOX, material, particles, extra)
}

/// [`bed_scene`] in a box of size `[x, y, z]`.
fn bed_scene_in([x, y, z]: [f64; 3], material: &str, particles: &str, extra: &str) -> String {
    format!(
        r#"
[simulation]
dt = "auto"
end_time = 10.0
gravity = [0.0, 0.0, -9.81]
seed = 1
{extra}
[contact]
regularisation = 0.2
{material}
[shapes.body]
{DODECAHEDRON}

[[wall]]
name = "box"
material = "pla"
geometry = {{ kind = "box", min = [0.0, 0.0, 0.0], max = [{x}, {y}, {z}], open_top = true }}

{particles}
"#
    )
}

/// The `[[particles]]` table of poses in `file`.
fn pose_file(file: &str) -> String {
    format!(
        "[[particles]]\nkind = \"file\"\nshape = \"body\"\nmaterial = \"pla\"\nfile = \"{file}\""
    )
}

/// Scene (a) with the `count` lowest particles of the settled bed, whose poses are
/// written to `dir`; beyond the bed's 10 000, copies of the whole bed side by side
/// on a square of tiles, in a box as large (the tiles' seams are where the bed met
/// the walls: no two copies overlap), the last tile its lowest particles.
pub fn settled_bed(dir: &Path, count: usize) -> Result<String> {
    let mut rows: Vec<(f64, [f64; 7])> = SETTLED_BED
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .skip(1)
        .map(|l| {
            let values: Vec<f64> = l.split(',').filter_map(|v| v.trim().parse().ok()).collect();
            let row: Option<[f64; 7]> = values.try_into().ok();
            row.map(|r| (r[2], r))
                .ok_or_else(|| anyhow!("settled bed: bad row '{l}'"))
        })
        .collect::<Result<_>>()?;
    if rows.is_empty() {
        bail!("the shipped settled bed is empty: run `talus bench --prepare-bed FILE`");
    }
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    let count = count.max(1);
    let side = count.div_ceil(rows.len()).isqrt();
    let side = if side * side * rows.len() < count {
        side + 1
    } else {
        side
    };
    let [x, y, z] = BED_BOX;
    let mut text = String::from("x,y,z,qw,qx,qy,qz\n");
    for tile in 0..side * side {
        let (dx, dy) = ((tile % side) as f64 * x, (tile / side) as f64 * y);
        let left = count - tile * rows.len().min(count);
        for (_, r) in rows.iter().take(left) {
            let r = [r[0] + dx, r[1] + dy, r[2], r[3], r[4], r[5], r[6]];
            let fields: Vec<String> = r.iter().map(|v| format!("{v:e}")).collect();
            text.push_str(&fields.join(","));
            text.push('\n');
        }
        if left <= rows.len() {
            break;
        }
    }
    std::fs::write(dir.join("bed.csv"), text)?;
    let size = [side as f64 * x, side as f64 * y, z];
    Ok(bed_scene_in(size, MATERIAL, &pose_file("bed.csv"), ""))
}

/// One stage of [`prepare_bed`]: a scene run with an artificial viscous drag on
/// every particle's velocity and angular momentum (rate `drag` per second, from time
/// `drag_after` on), until it settles or, without a settling criterion, to `end`.
struct Stage<'a> {
    name: &'a str,
    drag: Real,
    drag_after: Real,
    end: Real,
}

/// Runs `text` (a scene) through `stage`, with progress on stderr; returns the poses
/// as `x,y,z,qw,qx,qy,qz` CSV and the largest particle speed of the last step.
fn run_stage(text: &str, dir: &Path, stage: &Stage) -> Result<(String, Real)> {
    let path = dir.join(format!("{}.toml", stage.name));
    std::fs::write(&path, text)?;
    let scene = Scene::load(&path)?;
    let mut sim = Simulation::new(&scene);
    let start = Instant::now();
    let keep = 1.0 - stage.drag * scene.dt;
    while !sim.is_settled() && sim.time() < stage.end {
        sim.step();
        if sim.time() >= stage.drag_after {
            sim.damp_velocities(keep);
        }
        if sim.steps % 2000 == 0 {
            let report = sim.report();
            eprintln!(
                "{}: t = {:.4} s (dt {:.2e}), {} contacts, largest speed {:.2e} m/s, {:.0} s",
                stage.name,
                report.time,
                scene.dt,
                report.contacts,
                report.max_speed,
                start.elapsed().as_secs_f64()
            );
        }
    }
    let p = &sim.world().particles;
    let mut out = String::from("x,y,z,qw,qx,qy,qz\n");
    for i in 0..p.len() {
        let (x, q) = (p.position[i], p.orientation[i]);
        // Nine digits: 0.1 nm and 1 nrad, far below the overlaps (~µm) that hold the bed.
        out.push_str(&format!(
            "{:.8e},{:.8e},{:.8e},{:.8e},{:.8e},{:.8e},{:.8e}\n",
            x.x, x.y, x.z, q.w, q.i, q.j, q.k
        ));
    }
    let speed = sim.max_speed();
    eprintln!(
        "{}: {} particles at t = {:.4} s, largest speed {speed:.2e} m/s",
        stage.name,
        p.len(),
        sim.world().time
    );
    Ok((out, speed))
}

/// Pours 10 000 dodecahedra into scene (a)'s box and writes their poses to `out`.
///
/// They start on a loose cubic lattice (2.1 circumradii, 30 × 30 columns, 12 layers)
/// with random orientations. Left to themselves such beds take seconds of simulated
/// time to come to rest (a rattling top layer), hours of computing, so the pour is
/// quenched; the bed is then a random packing at rest under gravity, all the bench
/// needs:
/// 1. *pour*: ten times softer (Young's modulus 1e5 Pa, a three times longer step),
///    free fall for 0.15 s, then a drag of 50 /s on every particle, to 0.45 s or
///    until every particle is slower than 5 mm/s and the mean kinetic energy per
///    particle is below 1e-10 J (a root-mean-square speed of 0.6 mm/s) for 10 ms;
/// 2. *relax*: the bench's own material (1e6 Pa, e = 0.5, friction 0.5), the same
///    drag, for 50 ms or until the same criterion holds;
/// 3. *hold*: 10 ms without drag; the largest speed at its end goes into the file's
///    first line (a comment).
pub fn prepare_bed(out: &Path) -> Result<()> {
    let dir = std::env::temp_dir().join(format!("talus-prepare-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let a = 2.1 * 0.005;
    let top = 11.0 * a + 0.01;
    let lattice = format!(
        "[[particles]]\nkind = \"lattice\"\nshape = \"body\"\nmaterial = \"pla\"\n\
         min = [0.0, 0.0, 0.0]\nmax = [{w}, {w}, {top}]\nspacing = {a}\ncount = 10000",
        w = BED_BOX[0]
    );
    let settle = "settle = { max_speed = 5e-3, kinetic_energy_per_particle = 1e-10, hold = 0.01 }";
    let soft = MATERIAL.replace("young = 1e6", "young = 1e5");
    let stages = [
        Stage {
            name: "pour",
            drag: 50.0,
            drag_after: 0.15,
            end: 0.45,
        },
        Stage {
            name: "relax",
            drag: 50.0,
            drag_after: 0.0,
            end: 0.05,
        },
        Stage {
            name: "hold",
            drag: 0.0,
            drag_after: 0.0,
            end: 0.01,
        },
    ];
    let (poured, _) = run_stage(&bed_scene(&soft, &lattice, settle), &dir, &stages[0])?;
    std::fs::write(dir.join("poured.csv"), poured)?;
    let (relaxed, _) = run_stage(
        &bed_scene(MATERIAL, &pose_file("poured.csv"), settle),
        &dir,
        &stages[1],
    )?;
    std::fs::write(dir.join("relaxed.csv"), relaxed)?;
    let (held, speed) = run_stage(
        &bed_scene(MATERIAL, &pose_file("relaxed.csv"), ""),
        &dir,
        &stages[2],
    )?;
    std::fs::write(
        out,
        format!(
            "# talus bench --prepare-bed; largest speed after 10 ms without drag: {speed:.2e} m/s\n{held}"
        ),
    )?;
    let _ = std::fs::remove_dir_all(&dir);
    Ok(())
}

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

/// Scene (b): `count` spheres (r = 5 mm) at rest on a jittered lattice in the block
/// 0.006–0.194 × 0.006–0.194 × 0.15–0.58 m, poured under Hertz–Mindlin into an
/// open-top STL box of 0.2 × 0.2 × 0.6 m for 1 s (50 000 steps of 2e-5 s): the scene of
/// `benches/peers/`, with talus's own start. Writes `pour.csv` and `pour.stl` to `dir`.
fn pour(dir: &Path, count: usize) -> Result<String> {
    let walls = talus::geometry::surfaces::box_inside(
        [0.0, 0.0, 0.0].into(),
        [0.2, 0.2, 0.6].into(),
        true,
    )?;
    let tris: Vec<[usize; 3]> = walls
        .triangles
        .iter()
        .map(|t| t.map(|v| v as usize))
        .collect();
    talus::geometry::mesh_io::write_stl(&dir.join("pour.stl"), &walls.vertices, &tris)?;
    // 17 × 17 spheres a layer, 11.1 mm apart, jittered by up to 0.5 mm sideways.
    let mut rng = rand_pcg::Pcg64::seed_from_u64(21);
    let mut poses = String::from("x,y,z,qw,qx,qy,qz\n");
    let (side, a) = (17, 0.178 / 16.0);
    for k in 0..count {
        let (i, j, layer) = (k % side, (k / side) % side, k / (side * side));
        let jitter = |rng: &mut rand_pcg::Pcg64| rng.random_range(-5e-4..5e-4);
        let (x, y) = (
            0.011 + a * i as f64 + jitter(&mut rng),
            0.011 + a * j as f64 + jitter(&mut rng),
        );
        let z = 0.155 + 0.0112 * layer as f64;
        if z > 0.575 {
            bail!("--scale: at most {} spheres fit the pour's block", k);
        }
        poses += &format!("{x},{y},{z},1,0,0,0\n");
    }
    std::fs::write(dir.join("pour.csv"), poses)?;
    Ok(r#"
[simulation]
dt = 2e-5
end_time = 1.0
gravity = [0.0, 0.0, -9.81]

[contact]
law = "hertz_mindlin"
skin = 0.002

[materials.glass]
density = 2500.0
young = 1e7
poisson = 0.3
restitution = 0.5
friction = 0.5

[shapes.ball]
kind = "sphere"
radius = 0.005

[[wall]]
name = "box"
material = "glass"
geometry = { kind = "mesh", file = "pour.stl" }

[[particles]]
kind = "file"
shape = "ball"
material = "glass"
file = "pour.csv"
"#
    .to_string())
}

/// Realised restitution error of a drop of `shape` (a [shapes] entry) at step `dt`.
pub fn restitution_error(shape: &str, dt: f64, regularisation: f64) -> f64 {
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
    let vertex = sim.world().body_types[0]
        .shape
        .as_polyhedron()
        .map(|p| p.vertices()[0].coords);
    if let Some(v) = vertex {
        let q = nalgebra::UnitQuaternion::rotation_between(&v, &-nalgebra::Vector3::z())
            .unwrap_or_else(nalgebra::UnitQuaternion::identity);
        sim.edit_world(|w| {
            w.particles.orientation[0] = q;
            w.particles.position[0].z = v.norm() + 1e-4;
        });
    }
    let mut touched = false;
    let end = sim.end_time;
    let _ = sim.advance_to(end, |sim, _| {
        let contacts = sim.stats().contacts;
        touched |= contacts > 0;
        if touched && contacts == 0 {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    });
    (sim.world().particles.velocity[0].z / 0.5 - 1.0).abs()
}

struct Measured {
    /// Each stage's share of the timed steps.
    stages: Vec<(&'static str, f64)>,
    particles: usize,
    pairs: usize,
    contacts: f64,
    particle_steps: f64,
    contact_rate: f64,
}

impl Measured {
    /// The figures of `steps` timed steps that took `seconds` and summed
    /// `contact_sum` contacts, ending with `particles` and `pairs`.
    fn new(
        stages: Vec<(&'static str, f64)>,
        particles: usize,
        pairs: usize,
        contact_sum: usize,
        steps: usize,
        seconds: f64,
    ) -> Self {
        let steps = steps.max(1);
        Measured {
            stages,
            particles,
            pairs,
            contacts: contact_sum as f64 / steps as f64,
            particle_steps: (particles * steps) as f64 / seconds,
            contact_rate: contact_sum as f64 / seconds,
        }
    }
}

fn measure(scene: &Scene, threads: usize, warmup: usize, steps: usize) -> Result<Measured> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    Ok(pool.install(|| {
        let mut sim = Simulation::new(scene);
        // The bench reads figures between steps, not particles.
        sim.set_particles_each_step(false);
        let dt = sim.dt();
        let warm = sim.time() + warmup as f64 * dt;
        let _ = sim.advance_to(warm, |_, _| ControlFlow::<()>::Continue(()));
        let (mut contacts, mut taken) = (0usize, 0usize);
        let before = *sim.stage_times();
        let t = Instant::now();
        let end = sim.time() + steps as f64 * dt;
        let _ = sim.advance_to(end, |sim, _| {
            contacts += sim.stats().contacts;
            taken += 1;
            ControlFlow::<()>::Continue(())
        });
        Measured::new(
            sim.stage_times().since(&before).shares(),
            sim.world().particles.len(),
            sim.stats().candidate_pairs,
            contacts,
            taken,
            t.elapsed().as_secs_f64(),
        )
    }))
}

/// The scene's backend stepped alone, without the simulation's work between steps
/// (particles copied to the host, their finiteness, inlets, the bed, the energy
/// account): what the backend itself computes, and by difference what that work
/// costs.
fn measure_backend(scene: &Scene, warmup: usize, steps: usize) -> Result<Measured> {
    let mut world = scene.world.clone();
    let dt = scene.dt;
    let mut backend = choice::open(scene.spec.simulation.backend, &world, scene.step_params())
        .map_err(|e| anyhow!("{e}"))?;
    backend.initialise(&mut world, dt);
    for _ in 0..warmup {
        backend.step(&mut world, dt);
    }
    let before = *backend.stage_times();
    let mut contacts = 0usize;
    let t = Instant::now();
    for _ in 0..steps {
        backend.step(&mut world, dt);
        contacts += backend.stats().contacts;
    }
    Ok(Measured::new(
        backend.stage_times().since(&before).shares(),
        world.particles.len(),
        backend.stats().candidate_pairs,
        contacts,
        steps,
        t.elapsed().as_secs_f64(),
    ))
}

/// One row of the table and the stage shares below it.
fn print_row(name: &str, threads: usize, m: &Measured, dt: f64, error: &str) {
    println!(
        "{:<38} {:>7} {:>9} {:>10} {:>9.0} {:>8.1e} {:>16.3e} {:>14.3e} {:>10}",
        name,
        threads,
        m.particles,
        m.pairs,
        m.contacts,
        dt,
        m.particle_steps,
        m.contact_rate,
        error
    );
    if m.stages.iter().any(|&(_, share)| share > 0.0) {
        println!("{:<38} stages: {}", "", stage_line(&m.stages));
    } else {
        println!(
            "{:<38} stages: not timed apart by this backend (a GPU's launches return \
             before their kernels finish)",
            ""
        );
    }
}

/// Stage shares as `name 12.3 %, ...`, in step order.
pub(crate) fn stage_line(stages: &[(&str, f64)]) -> String {
    stages
        .iter()
        .map(|(name, share)| format!("{name} {:.1} %", 100.0 * share))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Scene (d): the lattice of random shapes with 20 body types, with a body type per
/// particle of the same 20 shapes, and with every particle its own shape (see
/// [`crate::bench_shapes`]), measured in turn on each thread count.
fn many_shapes(dir: &Path, options: &BenchOptions) -> Result<()> {
    let side = ((10_000.0 * options.scale).cbrt().round() as usize).max(2);
    let count = side.pow(3);
    let variants = [
        (20, 20, "(d) 20 random shapes".to_string()),
        (count, 20, format!("(d) {count} types of 20 shapes")),
        (count, count, format!("(d) {count} random shapes")),
    ];
    let mut setups = Vec::new();
    for (types, seeds, name) in variants {
        let text = crate::bench_shapes::many_shapes(side, types, seeds, MATERIAL);
        let setup = crate::bench_shapes::setup(&text, dir)?;
        let seconds = setup.check + setup.first_step;
        // Per thousand types for the variants of a type per particle.
        let per_thousand = if types == count {
            format!(
                ", {:.3} s per thousand body types",
                seconds / (types as f64 / 1000.0)
            )
        } else {
            String::new()
        };
        println!(
            "{name}: setup {seconds:.3} s (check with suggested step {:.3} s, first forces \
             {:.3} s){per_thousand}",
            setup.check, setup.first_step,
        );
        setups.push((name, setup));
    }
    for &threads in &options.threads {
        let mut rates = Vec::new();
        for (name, setup) in &setups {
            let m = measure(&setup.scene, threads, 20, options.steps)?;
            print_row(name, threads, &m, setup.scene.dt, "-");
            rates.push((m.particle_steps, m.contact_rate));
        }
        println!(
            "(d) {threads} thread(s): {count} body types of 20 shapes step at {:.3} times the \
             speed of 20 body types (same contacts); {count} random shapes at {:.3} times per \
             contact",
            rates[1].0 / rates[0].0,
            rates[2].1 / rates[0].1
        );
    }
    Ok(())
}

/// Options of `talus bench`.
pub struct BenchOptions {
    /// Scale factor on the particle counts (1: 10 000 dodecahedra, 5000 spheres).
    pub scale: f64,
    /// Timed steps per run.
    pub steps: usize,
    /// The scenes to measure, by letter (all when empty).
    pub scenes: Vec<char>,
    /// The thread counts to measure on.
    pub threads: Vec<usize>,
    /// The backend that steps the scenes.
    pub backend: BackendKind,
}

/// `text` (a scene) stepped by `backend`, its spheres under Hertz–Mindlin where the
/// backend models no other law (the CUDA backend).
fn on_backend(text: &str, backend: BackendKind) -> String {
    match backend {
        BackendKind::Cpu => text.to_string(),
        BackendKind::Cuda => {
            let text = text.replacen("[simulation]\n", "[simulation]\nbackend = \"cuda\"\n", 1);
            if text.contains("law = ") {
                text
            } else {
                text.replacen("[contact]\n", "[contact]\nlaw = \"hertz_mindlin\"\n", 1)
            }
        }
    }
}

/// `talus bench`.
pub fn bench(options: BenchOptions) -> Result<()> {
    if let Some(bad) = options.scenes.iter().find(|c| !"abcd".contains(**c)) {
        bail!("--scene {bad}: the scenes are a, b, c and d");
    }
    if options.threads.contains(&0) {
        bail!("--threads: a thread count is at least 1");
    }
    let on_device = options.backend == BackendKind::Cuda;
    if let Some(bad) = (options.scenes.iter()).find(|c| on_device && **c == 'd') {
        bail!("--scene {bad}: the cuda backend steps scenes a, b and c");
    }
    let dir = std::env::temp_dir().join(format!("talus-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let bed_count = (10_000.0 * options.scale).round() as usize;
    let pour_count = ((5000.0 * options.scale).round() as usize).max(2);
    let sphere_bed_side = ((5000.0 * options.scale).cbrt().round() as usize).max(2);
    let sphere = "kind = \"sphere\"\nradius = 0.005";
    let wanted = |letter: char| {
        let all = options.scenes.is_empty() && !(on_device && letter == 'd');
        all || options.scenes.contains(&letter)
    };
    // (letter, name, the drop whose restitution error is printed, whether the whole
    // run is timed); each scene is written when measured.
    let cases = [
        (
            'a',
            "(a) settled bed of dodecahedra",
            Some((DODECAHEDRON, 0.2)),
            false,
        ),
        ('b', "(b) pour of spheres to rest", None, true),
        ('c', "(c) dense bed of spheres", Some((sphere, 0.01)), false),
    ];
    let text = |letter: char| -> Result<String> {
        match letter {
            'a' => settled_bed(&dir, bed_count),
            'b' => pour(&dir, pour_count),
            _ => Ok(dense_lattice(sphere_bed_side, sphere, 1.98)),
        }
    };
    println!("machine: {}", machine());
    if on_device {
        println!(
            "backend: cuda on GPU 0 (the spheres of (b) and (c) under Hertz–Mindlin; threads: \
             the host's, which waits for the device)"
        );
    }
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
    for (letter, name, drop, whole) in cases.into_iter().filter(|c| wanted(c.0)) {
        let path = dir.join("scene.toml");
        std::fs::write(&path, on_backend(&text(letter)?, options.backend))?;
        let scene = Scene::load(&path)?;
        // The spheres' drop is under the volume law, which the device does not
        // step for spheres; its dodecahedra are the CPU's to round-off.
        let drop = drop.filter(|_| !(on_device && letter == 'c'));
        let error = drop.map_or("-".to_string(), |(shape, reg)| {
            format!("{:.2}%", 100.0 * restitution_error(shape, scene.dt, reg))
        });
        let (warmup, steps) = if whole {
            (
                0,
                (scene.spec.simulation.end_time / scene.dt).round() as usize,
            )
        } else {
            (200, options.steps)
        };
        for &threads in &options.threads {
            let m = measure(&scene, threads, warmup, steps)?;
            print_row(name, threads, &m, scene.dt, &error);
        }
        if on_device {
            let m = measure_backend(&scene, warmup, steps)?;
            print_row(&format!("{name}, backend alone"), 1, &m, scene.dt, &error);
        }
    }
    if wanted('d') {
        many_shapes(&dir, &options)?;
    }
    println!(
        "dt: the suggested step of each scene ((b): that of the LIGGGHTS comparison); e \
         error: |realised/requested − 1| of the restitution of a drop of the same shape at \
         that dt (requested e = 0.5; (b) follows Hertz–Mindlin, whose restitution is its \
         own); (b) is timed over its whole second (50 000 steps), the others over --steps; \
         contacts and candidate pairs: the mean per timed step and the last step's; stages: \
         the share of each stage of the step in the timed steps (monotonic clock)."
    );
    let _ = std::fs::remove_dir_all(&dir);
    Ok(())
}
