//! The exact split of a particle's volume among grid cells (what the solid volume
//! fraction of a CFD grid is made of): each cell's share against Monte Carlo
//! sampling, the shares against closed forms where they exist, and their sum
//! against the particle's volume to 1e-12.

use std::f64::consts::PI;

use nalgebra::{Isometry3, Point3, Vector3};
use rand::{Rng, SeedableRng};
use talus::Real;
use talus::geometry::cell_volumes::{
    disc_area_below_corner, placed_faces, polyhedron_cell_volumes, sphere_cell_volumes,
    volume_below_corner,
};
use talus::geometry::generators::{cuboid, dodecahedron};

/// Shares by cell, from a kernel's callback.
fn shares(kernel: impl FnOnce(&mut dyn FnMut([usize; 3], Real))) -> Vec<([usize; 3], Real)> {
    let mut out = Vec::new();
    kernel(&mut |c, v| out.push((c, v)));
    out
}

/// The cell of `p` on a grid of boundaries `b` (None outside).
fn cell_of(p: &Point3<Real>, b: &[Vec<Real>; 3]) -> Option<[usize; 3]> {
    let mut c = [0; 3];
    for a in 0..3 {
        let k = b[a].partition_point(|&x| x <= p[a]);
        if k == 0 || k == b[a].len() {
            return None;
        }
        c[a] = k - 1;
    }
    Some(c)
}

/// Each share against the fraction of `samples` uniform points of the box `lo..hi`
/// that fall inside the body (`inside`) and in that cell: within four standard
/// deviations of the binomial estimate.
fn against_monte_carlo(
    got: &[([usize; 3], Real)],
    bounds: &[Vec<Real>; 3],
    (lo, hi): (Point3<Real>, Point3<Real>),
    inside: impl Fn(&Point3<Real>) -> bool,
) {
    let samples = 400_000;
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    let box_volume = (hi - lo).product();
    let mut hits = std::collections::HashMap::new();
    for _ in 0..samples {
        let p = Point3::from(
            lo.coords + (hi - lo).component_mul(&Vector3::from_fn(|_, _| rng.random::<Real>())),
        );
        if inside(&p) {
            if let Some(c) = cell_of(&p, bounds) {
                *hits.entry(c).or_insert(0usize) += 1;
            }
        }
    }
    for (c, v) in got {
        let f = *hits.get(c).unwrap_or(&0) as Real / samples as Real;
        let sigma = (f * (1.0 - f) / samples as Real)
            .sqrt()
            .max(1.0 / samples as Real);
        assert!(
            (v / box_volume - f).abs() < 4.0 * sigma,
            "cell {c:?}: {v} against {}",
            f * box_volume
        );
    }
    for (c, n) in hits {
        assert!(
            got.iter().any(|(g, _)| *g == c) || n < 3,
            "cell {c:?} holds {n} samples but got no share"
        );
    }
}

fn grid(lo: Real, step: Real, n: usize) -> Vec<Real> {
    (0..=n).map(|k| lo + step * k as Real).collect()
}

#[test]
fn a_cube_halved_on_every_axis_gives_eighths() {
    let cube = cuboid(2.0, 2.0, 2.0).unwrap();
    let b = [-1.0, 0.0, 1.0];
    let got = shares(|f| {
        polyhedron_cell_volumes(placed_faces(&cube, &Isometry3::identity()), [&b, &b, &b], f)
    });
    assert_eq!(got.len(), 8);
    for (_, v) in got {
        assert!((v - 1.0).abs() < 1e-14, "{v}");
    }
}

#[test]
fn a_turned_dodecahedron_split_among_cells_matches_sampling_and_sums_to_its_volume() {
    let d = dodecahedron(1.0).unwrap();
    let pose = Isometry3::new(
        Vector3::new(0.13, -0.27, 0.41),
        Vector3::new(0.3, 1.1, -0.7),
    );
    // Cells of 0.45: the particle spans up to five along each axis, and the grid ends
    // inside it on one side (what lies beyond belongs to no cell).
    let b = [
        grid(-1.2, 0.45, 6),
        grid(-1.1, 0.45, 6),
        grid(-0.5, 0.45, 6),
    ];
    let got =
        shares(|f| polyhedron_cell_volumes(placed_faces(&d, &pose), [&b[0], &b[1], &b[2]], f));
    assert!(got.len() > 40, "{} cells", got.len());
    let planes: Vec<_> = d
        .planes()
        .iter()
        .map(|p| {
            (
                pose.rotation * p.normal,
                p.offset + (pose.rotation * p.normal).dot(&pose.translation.vector),
            )
        })
        .collect();
    let inside = |p: &Point3<Real>| planes.iter().all(|(n, o)| n.dot(&p.coords) <= *o);
    against_monte_carlo(
        &got,
        &b,
        (Point3::new(-1.2, -1.1, -0.5), Point3::new(1.5, 1.6, 2.2)),
        inside,
    );

    // A grid that covers it: the shares add up to its volume.
    let b = [
        grid(-1.6, 0.37, 9),
        grid(-1.6, 0.37, 9),
        grid(-1.2, 0.37, 9),
    ];
    let got =
        shares(|f| polyhedron_cell_volumes(placed_faces(&d, &pose), [&b[0], &b[1], &b[2]], f));
    let sum: Real = got.iter().map(|x| x.1).sum();
    assert!(
        (sum / d.volume() - 1.0).abs() < 1e-12,
        "{sum} against {}",
        d.volume()
    );
}

#[test]
fn disc_and_ball_below_a_corner_in_closed_form() {
    let r: Real = 0.7;
    // Quarter, half and whole disc; a half disc less a segment.
    assert!((disc_area_below_corner(r, 0.0, 0.0) - PI * r * r / 4.0).abs() < 1e-15);
    assert!((disc_area_below_corner(r, 0.0, 2.0) - PI * r * r / 2.0).abs() < 1e-15);
    assert!((disc_area_below_corner(r, 1.0, 1.0) - PI * r * r).abs() < 1e-15);
    let (x, theta) = (0.3, (0.3 / r).acos());
    let segment = r * r * (theta - theta.sin() * theta.cos());
    assert!((disc_area_below_corner(r, 2.0, x) - (PI * r * r - segment)).abs() < 1e-15);
    assert!((disc_area_below_corner(r, 2.0, -x) - segment).abs() < 1e-15);
    // An eighth and a quarter of the ball; a cap.
    let ball = 4.0 / 3.0 * PI * r.powi(3);
    assert!((volume_below_corner(r, 0.0, 0.0, 0.0) / ball - 0.125).abs() < 1e-13);
    assert!((volume_below_corner(r, 0.0, 0.0, 5.0) / ball - 0.25).abs() < 1e-13);
    let h = 0.2;
    let cap = PI * h * h * (3.0 * r - h) / 3.0;
    assert!((volume_below_corner(r, 5.0, 5.0, h - r) - cap).abs() < 1e-13 * ball);
}

#[test]
fn a_sphere_split_among_cells_matches_sampling_and_sums_to_its_volume() {
    let (centre, r) = (Point3::new(0.12, -0.07, 0.31), 0.5);
    let b = [
        grid(-0.5, 0.23, 6),
        grid(-0.6, 0.23, 6),
        grid(-0.3, 0.23, 6),
    ];
    let got = shares(|f| sphere_cell_volumes(centre, r, [&b[0], &b[1], &b[2]], f));
    assert!(got.len() > 30, "{} cells", got.len());
    let inside = |p: &Point3<Real>| (p - centre).norm() <= r;
    let lo = centre - Vector3::repeat(r);
    against_monte_carlo(&got, &b, (lo, centre + Vector3::repeat(r)), inside);
    let ball = 4.0 / 3.0 * PI * r.powi(3);
    let sum: Real = got.iter().map(|x| x.1).sum();
    assert!((sum / ball - 1.0).abs() < 1e-12, "{sum} against {ball}");
    // A share that is an octant's: the cell corner at the centre.
    let b = [vec![-1.0, 0.12, 1.0], vec![-0.07, 1.0], vec![0.31, 1.0]];
    let got = shares(|f| sphere_cell_volumes(centre, r, [&b[0], &b[1], &b[2]], f));
    let whole_octant: Real = got.iter().filter(|x| x.0 == [1, 0, 0]).map(|x| x.1).sum();
    assert!(
        (whole_octant / ball - 0.125).abs() < 1e-13,
        "{whole_octant}"
    );
}

#[test]
fn the_ball_below_a_corner_is_the_same_whichever_axis_is_integrated() {
    // The integral runs along z: swapping z with x or y takes other kinks and
    // nodes to the same volume. Corners near the axes and the poles included.
    let r: Real = 0.002;
    let ball = 4.0 / 3.0 * PI * r.powi(3);
    let mut rng = rand::rngs::StdRng::seed_from_u64(3);
    let mut corners: Vec<[Real; 3]> = (0..300)
        .map(|_| std::array::from_fn(|_| rng.random_range(-r..r)))
        .collect();
    corners.extend([
        [0.0, 9.2e-8, 1.35e-4],
        [2.67e-4, 9.2e-8, 1.35e-4],
        [r * 0.999_999, 0.0, 0.0],
    ]);
    for [x, y, z] in corners {
        let g = volume_below_corner(r, x, y, z);
        for other in [
            volume_below_corner(r, z, y, x),
            volume_below_corner(r, x, z, y),
        ] {
            assert!(
                (g - other).abs() < 1e-13 * ball,
                "({x}, {y}, {z}): {g} against {other}"
            );
        }
    }
}
