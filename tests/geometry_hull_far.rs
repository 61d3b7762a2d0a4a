//! The convex hull of points spread over many orders of magnitude (a mesh with one
//! vertex kilometres, or 4e11 m, away from the rest) ends in a hull or an error,
//! never a panic.

use nalgebra::Point3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use talus::geometry::convex_hull;

#[test]
fn far_points_give_a_hull_or_an_error() {
    let mut rng = Pcg64::seed_from_u64(17);
    let (mut hulls, mut errors) = (0, 0);
    for case in 0..3000 {
        let size = 10f64.powf(rng.random_range(-4.0..7.0));
        let far = -10f64.powf(rng.random_range(3.0..12.0));
        let n = rng.random_range(4..40);
        let mut points: Vec<Point3<f64>> = (0..n)
            .map(|_| {
                // As an STL stores them: in single precision.
                let mut c = || (rng.random_range(-1.0..1.0) * size) as f32 as f64;
                Point3::new(c(), c(), c())
            })
            .collect();
        let k = rng.random_range(0..n);
        points[k].x = far as f32 as f64;
        match std::panic::catch_unwind(|| convex_hull(&points)) {
            Ok(Ok(_)) => hulls += 1,
            Ok(Err(_)) => errors += 1,
            Err(_) => panic!("case {case}: the hull of {points:?} panicked"),
        }
    }
    println!("{hulls} hulls, {errors} errors");
    assert!(
        hulls > 100 && errors > 100,
        "{hulls} hulls, {errors} errors"
    );
}
