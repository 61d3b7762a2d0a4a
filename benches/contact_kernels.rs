//! Contact-kernel benchmark: time per pair for GJK and for the exact overlap volume.
//!
//! Run with `cargo bench --bench contact_kernels`. For each shape pair and overlap
//! level, 64 random relative orientations are placed along random directions at the
//! distance that gives the wanted overlap (as a fraction of one particle's volume,
//! found by bisection), and each kernel is timed over all of them, best of several
//! repeats, on one thread. An argument keeps only the shapes whose name contains it
//! (`cargo bench --bench contact_kernels -- dodecahedron`).

use std::hint::black_box;
use std::time::Instant;

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use talus::geometry::ConvexPolyhedron;
use talus::geometry::generators;
use talus::geometry::gjk::gjk;
use talus::geometry::overlap::{OverlapScratch, overlap_with};
use talus::geometry::wall::polyhedron_triangle;

mod common;
use common::cpu_model;

const PAIRS: usize = 64;

fn random_rotation(rng: &mut Pcg64) -> UnitQuaternion<f64> {
    let v = Vector3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    );
    UnitQuaternion::from_scaled_axis(v * 3.0)
}

/// Relative poses with overlap volume `fraction` of `a`'s volume (negative: a gap of
/// `-fraction` times the circumradius, found with GJK).
fn poses(
    a: &ConvexPolyhedron,
    b: &ConvexPolyhedron,
    fraction: f64,
    seed: u64,
) -> Vec<Isometry3<f64>> {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut scratch = OverlapScratch::default();
    let mut out = Vec::new();
    while out.len() < PAIRS {
        let rot = random_rotation(&mut rng);
        let dir = random_rotation(&mut rng) * Vector3::x();
        let at = |s: f64| Isometry3::from_parts(Translation3::from(dir * s), rot);
        let mut target = |s: f64| {
            if fraction >= 0.0 {
                overlap_with(a, b, &at(s), &mut scratch).map_or(0.0, |o| o.volume) / a.volume()
                    - fraction
            } else {
                -gjk(a, b, &at(s), None).distance() / a.circumradius() - fraction
            }
        };
        // target decreases with s: bisect on [0, ra + rb].
        let (mut lo, mut hi) = (
            0.0,
            a.circumradius() + b.circumradius() + 0.5 * a.circumradius(),
        );
        if target(lo) < 0.0 {
            continue;
        }
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if target(mid) > 0.0 {
                lo = mid
            } else {
                hi = mid
            }
        }
        out.push(at(0.5 * (lo + hi)));
    }
    out
}

fn time_per_call(mut f: impl FnMut() -> usize) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..7 {
        let reps = 200;
        let t = Instant::now();
        let mut sink = 0;
        for _ in 0..reps {
            sink += f();
        }
        black_box(sink);
        best = best.min(t.elapsed().as_secs_f64() / (reps * PAIRS) as f64);
    }
    best * 1e9
}

fn main() {
    println!("talus contact kernels — {} — one thread", cpu_model());
    println!("time per pair in ns, mean over {PAIRS} random orientations (best of 7 repeats)");
    println!(
        "{:<34} {:>12} {:>10} {:>12}",
        "pair", "overlap", "GJK ns", "overlap ns"
    );
    let shapes: Vec<(&str, ConvexPolyhedron)> = vec![
        (
            "dodecahedron (12 faces)",
            generators::dodecahedron(0.005).unwrap(),
        ),
        (
            "20-gon cylinder (80 triangles)",
            generators::prism(20, 5.5e-3, 5.5e-3).unwrap(),
        ),
        (
            "icosphere (320 triangles)",
            generators::icosphere(2, 0.005).unwrap(),
        ),
    ];
    // Cargo passes `--bench` to the harness; any other argument filters the shapes.
    let filter = std::env::args().skip(1).find(|a| !a.starts_with("--"));
    let shapes: Vec<(&str, ConvexPolyhedron)> = shapes
        .into_iter()
        .filter(|(name, _)| filter.as_ref().is_none_or(|f| name.contains(f.as_str())))
        .collect();
    let levels: [(&str, f64); 5] = [
        ("near miss (gap 1% R)", -0.01),
        ("shallow 0.2%", 0.002),
        ("2% by volume", 0.02),
        ("medium 10%", 0.10),
        ("deep 40%", 0.40),
    ];
    let mut scratch = OverlapScratch::default();
    for (name, shape) in &shapes {
        for (level, fraction) in levels {
            let ps = poses(shape, shape, fraction, 42);
            let g = time_per_call(|| {
                ps.iter()
                    .filter(|p| gjk(shape, shape, p, None).intersects())
                    .count()
            });
            let o = time_per_call(|| {
                ps.iter()
                    .filter(|p| overlap_with(shape, shape, p, &mut scratch).is_some())
                    .count()
            });
            println!("{:<34} {:>12} {:>10.0} {:>12.0}", name, level, g, o);
        }
    }

    // Particle against one wall facet (a triangle twice the particle's size), pressed
    // 2 % of the circumradius into it, at random orientations and offsets.
    println!();
    println!(
        "{:<34} {:>12} {:>10} {:>12}",
        "particle vs wall facet", "depth", "", "facet ns"
    );
    let mut rng = Pcg64::seed_from_u64(7);
    for (name, shape) in &shapes {
        let r = shape.circumradius();
        let tris: Vec<[nalgebra::Point3<f64>; 3]> = (0..PAIRS)
            .map(|_| {
                let rot = random_rotation(&mut rng);
                let lowest =
                    shape.vertices()[shape.support_index(&(rot.inverse() * -Vector3::z()), 0)];
                let z = (rot * lowest.coords).z + 0.02 * r;
                let (dx, dy) = (rng.random_range(-r..r), rng.random_range(-r..r));
                let world = [
                    nalgebra::Point3::new(-2.0 * r + dx, -2.0 * r + dy, z),
                    nalgebra::Point3::new(2.0 * r + dx, -2.0 * r + dy, z),
                    nalgebra::Point3::new(dx, 2.0 * r + dy, z),
                ];
                world.map(|p| nalgebra::Point3::from(rot.inverse() * p.coords))
            })
            .collect();
        let t = time_per_call(|| {
            tris.iter()
                .filter(|t| polyhedron_triangle(shape, t).is_some())
                .count()
        });
        println!("{:<34} {:>12} {:>10} {:>12.0}", name, "2% of R", "", t);
    }
}
