//! The broad phase finds exactly the pairs whose bounding spheres overlap, for mono-
//! and polydisperse particles (size ratios 10 and 100), in the same order on any
//! number of threads.

use nalgebra::Point3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use talus::engine::broad_phase::BroadPhase;

fn scene(
    n: usize,
    r_min: f64,
    r_max: f64,
    box_size: f64,
    seed: u64,
) -> (Vec<Point3<f64>>, Vec<f64>) {
    let mut rng = Pcg64::seed_from_u64(seed);
    let positions = (0..n)
        .map(|_| {
            Point3::new(
                rng.random_range(0.0..box_size),
                rng.random_range(0.0..box_size),
                rng.random_range(0.0..box_size),
            )
        })
        .collect();
    // Log-uniform radii, so that every size class is populated.
    let radii = (0..n)
        .map(|_| (rng.random_range(r_min.ln()..=r_max.ln())).exp())
        .collect();
    (positions, radii)
}

fn brute_force(positions: &[Point3<f64>], radii: &[f64], skin: f64) -> Vec<[u32; 2]> {
    let mut out = Vec::new();
    for i in 0..positions.len() {
        for j in i + 1..positions.len() {
            let reach = radii[i] + radii[j] + skin;
            if (positions[j] - positions[i]).norm_squared() < reach * reach {
                out.push([i as u32, j as u32]);
            }
        }
    }
    out
}

fn sorted(mut pairs: Vec<[u32; 2]>) -> Vec<[u32; 2]> {
    pairs.sort_unstable();
    pairs
}

#[test]
fn finds_exactly_the_overlapping_bounding_spheres() {
    let cases = [
        ("monodisperse", 3000, 0.01, 0.01, 0.4),
        ("size ratio 10", 3000, 0.002, 0.02, 0.4),
        ("size ratio 100", 2000, 0.0005, 0.05, 0.5),
        ("dense", 2000, 0.01, 0.012, 0.2),
    ];
    let mut bp = BroadPhase::default();
    let mut pairs = Vec::new();
    for (name, n, r0, r1, size) in cases {
        let (p, r) = scene(n, r0, r1, size, 11);
        for skin in [0.0, 0.001] {
            bp.find_pairs(&p, &r, skin, &mut pairs);
            let expected = brute_force(&p, &r, skin);
            assert!(!expected.is_empty(), "{name}: the scene has contacts");
            assert_eq!(sorted(pairs.clone()), expected, "{name}, skin {skin}");
        }
    }
}

#[test]
fn same_pairs_in_the_same_order_on_one_and_two_threads() {
    let (p, r) = scene(4000, 0.002, 0.02, 0.4, 5);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut bp = BroadPhase::default();
            let mut pairs = Vec::new();
            bp.find_pairs(&p, &r, 0.0005, &mut pairs);
            pairs
        })
    };
    let one = run(1);
    assert!(one.len() > 1000);
    assert_eq!(one, run(2));
}

#[test]
fn degenerate_inputs() {
    let mut bp = BroadPhase::default();
    let mut pairs = vec![[7, 7]];
    bp.find_pairs(&[], &[], 0.0, &mut pairs);
    assert!(pairs.is_empty());
    bp.find_pairs(&[Point3::origin()], &[1.0], 0.0, &mut pairs);
    assert!(pairs.is_empty());
    // All particles at one point (zero extent) and a sparse far-flung pair.
    let p = vec![Point3::origin(); 5];
    bp.find_pairs(&p, &[0.1; 5], 0.0, &mut pairs);
    assert_eq!(pairs.len(), 10);
    let p = vec![
        Point3::origin(),
        Point3::new(1e6, 0.0, 0.0),
        Point3::new(1e6, 0.0, 0.05),
    ];
    bp.find_pairs(&p, &[0.1; 3], 0.0, &mut pairs);
    assert_eq!(pairs, vec![[1, 2]]);
}
