//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::Path;

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use talus::geometry::ConvexPolyhedron;
use talus::scene::{Scene, Simulation};

/// A pose from a translation and a rotation vector (axis times angle).
pub fn pose(t: [f64; 3], rot: [f64; 3]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(t[0], t[1], t[2]),
        UnitQuaternion::from_scaled_axis(Vector3::from(rot)),
    )
}

/// Whether `p` (body frame) lies inside the polyhedron.
pub fn contains(poly: &ConvexPolyhedron, p: &Point3<f64>) -> bool {
    poly.planes().iter().all(|pl| pl.distance(p) <= 0.0)
}

/// Monte Carlo estimate of the overlap volume of A and B (B posed in A's frame):
/// (estimate, one standard error). Samples the box around A's bounding sphere.
pub fn monte_carlo_overlap(
    a: &ConvexPolyhedron,
    b: &ConvexPolyhedron,
    b_in_a: &Isometry3<f64>,
    samples: usize,
    seed: u64,
) -> (f64, f64) {
    let mut rng = Pcg64::seed_from_u64(seed);
    let r = a.circumradius();
    let inv = b_in_a.inverse();
    let mut hits = 0usize;
    for _ in 0..samples {
        let p = Point3::new(
            rng.random_range(-r..r),
            rng.random_range(-r..r),
            rng.random_range(-r..r),
        );
        if contains(a, &p) && contains(b, &inv.transform_point(&p)) {
            hits += 1;
        }
    }
    let box_volume = (2.0 * r).powi(3);
    let p = hits as f64 / samples as f64;
    (
        box_volume * p,
        box_volume * (p * (1.0 - p) / samples as f64).sqrt(),
    )
}

/// Volume of the intersection of two axis-aligned boxes given by centre and size.
pub fn box_overlap(c1: [f64; 3], s1: [f64; 3], c2: [f64; 3], s2: [f64; 3]) -> f64 {
    (0..3)
        .map(|k| {
            let lo = (c1[k] - s1[k] / 2.0).max(c2[k] - s2[k] / 2.0);
            let hi = (c1[k] + s1[k] / 2.0).min(c2[k] + s2[k] / 2.0);
            (hi - lo).max(0.0)
        })
        .product()
}

/// Runs a scene until it settles (or `limit` simulated seconds pass) and checks that
/// every particle came to rest inside `[lo, hi]` with finite state.
pub fn settle(
    text: &str,
    lo: [f64; 3],
    hi: [f64; 3],
    limit: f64,
    require_rest: bool,
) -> Simulation {
    let scene = Scene::parse(text, Path::new("pile.toml")).unwrap();
    let mut sim = Simulation::new(&scene);
    while !sim.is_settled() && sim.time() < limit {
        sim.step();
    }
    let p = &sim.world().particles;
    println!(
        "{} particles, dt = {:.3e} s: settled = {} at t = {:.3} s after {} steps, largest speed {:.2e} m/s, {} contacts",
        p.len(),
        scene.dt,
        sim.is_settled(),
        sim.time(),
        sim.steps,
        sim.max_speed(),
        sim.stats().contacts
    );
    for i in 0..p.len() {
        let x = p.position[i];
        assert!(
            x.iter().all(|c| c.is_finite()) && p.velocity[i].iter().all(|c| c.is_finite()),
            "particle {i} is not finite"
        );
        assert!(
            (0..3).all(|k| x[k] > lo[k] && x[k] < hi[k]),
            "particle {i} left the box: {x}"
        );
    }
    if require_rest {
        assert!(
            sim.is_settled(),
            "not at rest: largest speed {}",
            sim.max_speed()
        );
    }
    sim
}

/// 27 dodecahedra in an open box with a lid pressing down at 0.5 m/s: contacts from
/// the start, a frame (and a row) every millisecond; `END` stands for the end time.
pub const LID_BOX: &str = r#"
[simulation]
dt = 2e-6
end_time = END
gravity = [0.0, 0.0, -9.81]

[contact]
regularisation = 0.2

[output]
frame_interval = 0.001

[materials.pla]
density = 1500.0
young = 1e6
poisson = 0.1
restitution = 0.3
friction = 0.5

[shapes.dodecahedron]
kind = "platonic"
solid = "dodecahedron"
circumradius = 0.005

[[wall]]
name = "box"
material = "pla"
geometry = { kind = "box", min = [0.0, 0.0, 0.0], max = [0.04, 0.04, 0.1], open_top = true }

[[wall]]
name = "lid"
material = "pla"
geometry = { kind = "plane", centre = [0.02, 0.02, 0.09], normal = [0.0, 0.0, -1.0], size = 0.04 }
motion = { kind = "linear", velocity = [0.0, 0.0, -0.5] }

[[particles]]
kind = "lattice"
shape = "dodecahedron"
material = "pla"
min = [0.0, 0.0, 0.0]
max = [0.04, 0.04, 0.04]
"#;

/// A PNG file decoded to 8-bit RGB: what a person would see of a plot.
pub struct Picture {
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<u8>,
}

impl Picture {
    /// Reads an 8-bit RGB PNG.
    pub fn read(path: &Path) -> Picture {
        let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let mut reader = png::Decoder::new(std::io::BufReader::new(file))
            .read_info()
            .unwrap();
        let mut rgb = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut rgb).unwrap();
        assert_eq!(info.color_type, png::ColorType::Rgb, "{}", path.display());
        rgb.truncate(info.buffer_size());
        Picture {
            width: info.width,
            height: info.height,
            rgb,
        }
    }

    /// Pixels within `tolerance` (per channel) of `colour` in the rows `rows`.
    pub fn count(&self, colour: [u8; 3], tolerance: u8, rows: std::ops::Range<u32>) -> usize {
        let row = 3 * self.width as usize;
        self.rgb[rows.start as usize * row..rows.end.min(self.height) as usize * row]
            .chunks_exact(3)
            .filter(|p| (0..3).all(|c| p[c].abs_diff(colour[c]) <= tolerance))
            .count()
    }

    /// Dark pixels (text, axes) in the rows `rows`.
    pub fn dark(&self, rows: std::ops::Range<u32>) -> usize {
        self.count([0, 0, 0], 90, rows)
    }
}

/// A fluid velocity differing from cell to cell, x y z per cell, for `cells` cells:
/// the input of the fluid face tests (the C program `tests/c/fluid_test.c` computes
/// the same).
pub fn fluid_swirl(cells: usize, phase: f64) -> Vec<f64> {
    (0..cells)
        .flat_map(|c| {
            let c = c as f64;
            [
                0.3 * (c + phase).sin(),
                -0.2 * (0.5 * c).cos(),
                2.0 + 0.05 * c + phase,
            ]
        })
        .collect()
}

/// This test program run under `mpirun --oversubscribe -np ranks` (more ranks than
/// cores; as root too, with OpenMPI's consent variables; a thread a rank), with
/// `mark` set in the environment of the copies it starts.
pub fn mpirun_self(ranks: usize, mark: &str) -> Result<std::process::Output, String> {
    let program = std::env::current_exe().map_err(|e| e.to_string())?;
    std::process::Command::new("mpirun")
        .args(["--oversubscribe", "-np", &ranks.to_string()])
        .arg(&program)
        .env(mark, "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .env("RAYON_NUM_THREADS", "1")
        .output()
        .map_err(|e| format!("mpirun (openmpi-bin, scripts/system-deps.sh): {e}"))
}

/// Runs this test program on `ranks` ranks ([`mpirun_self`]) and returns the line of
/// its output that starts with `report` (rank 0's), or why there is none.
pub fn rank_report(ranks: usize, mark: &str, report: &str) -> Result<String, String> {
    let out = mpirun_self(ranks, mark)?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    if !out.status.success() {
        return Err(format!(
            "{ranks} ranks: {}\n{stdout}\n{}",
            out.status,
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    stdout
        .lines()
        .find(|l| l.starts_with(report))
        .map(str::to_string)
        .ok_or_else(|| format!("{ranks} ranks: no report in {stdout}"))
}

/// The head of a scene of Hertz–Mindlin spheres: a step of 20 µs, gravity, glass
/// and steel, big (5 mm) and small (4 mm) spheres; the particles and walls follow.
pub const GLASS_AND_STEEL_SPHERES: &str = r#"
[simulation]
dt = 2e-5
end_time = 1.0
gravity = [0.0, 0.0, -9.81]
[contact]
law = "hertz_mindlin"
[materials.glass]
density = 2500.0
young = 1e7
poisson = 0.3
restitution = 0.5
friction = 0.5
[materials.steel]
density = 7800.0
young = 2e7
poisson = 0.25
restitution = 0.7
friction = 0.3
[shapes.big]
kind = "sphere"
radius = 0.005
[shapes.small]
kind = "sphere"
radius = 0.004
"#;

/// Equal to 1e-12 of the larger: two sums of the same terms in other orders (the
/// CUDA backend's tree of sums, the CPU backend's serial sum; some thousand terms,
/// each sum's round-off within a few ulps of its terms').
pub fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * a.abs().max(b.abs())
}

/// Vectors equal to 1e-12 of the longer: the walls' sums, as [`close`].
pub fn near(a: &nalgebra::Vector3<f64>, b: &nalgebra::Vector3<f64>) -> bool {
    (a - b).norm() <= 1e-12 * a.norm().max(b.norm())
}

/// The arrays of a `.vti` or `.vtp` file written with raw appended data, by name, in
/// the file's order (Float32 and Int64 arrays, as f64).
pub fn read_vtk(path: &Path) -> Vec<(String, Vec<f64>)> {
    let bytes = std::fs::read(path).unwrap();
    let marker = b"<AppendedData encoding=\"raw\">\n   _";
    let start = bytes
        .windows(marker.len())
        .position(|w| w == marker)
        .unwrap()
        + marker.len();
    let text = String::from_utf8_lossy(&bytes[..start]).to_string();
    let field = |s: &str, key: &str| {
        let s = &s[s.find(key).unwrap() + key.len()..];
        s[..s.find('"').unwrap()].to_string()
    };
    text.split("<DataArray ")
        .skip(1)
        .map(|a| {
            let (ty, name) = (field(a, "type=\""), field(a, "Name=\""));
            let at = start + field(a, "offset=\"").parse::<usize>().unwrap();
            let len = u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap()) as usize;
            let raw = &bytes[at + 8..at + 8 + len];
            let data = match ty.as_str() {
                "Float32" => raw
                    .chunks(4)
                    .map(|c| f32::from_le_bytes(c.try_into().unwrap()) as f64)
                    .collect(),
                _ => raw
                    .chunks(8)
                    .map(|c| i64::from_le_bytes(c.try_into().unwrap()) as f64)
                    .collect(),
            };
            (name, data)
        })
        .collect()
}
