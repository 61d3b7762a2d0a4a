//! The exact split of a particle's volume among grid cells (what the solid volume
//! fraction of a CFD grid is made of), on structured, cylindrical and given (Voronoi)
//! cells: each cell's share against Monte Carlo sampling, the shares against closed
//! forms where they exist, and their sum against the particle's volume to 1e-12.

use std::f64::consts::PI;

use nalgebra::{Isometry3, Point3, Vector3};
use rand::{Rng, SeedableRng};
use talus::Real;
use talus::geometry::axial_volumes::{AxialBody, CylinderCells, Sectors, cylinder_cell_volumes};
use talus::geometry::cell_volumes::{
    disc_area_below_corner, placed_faces, polyhedron_cell_volumes, sphere_cell_volumes,
    volume_below_corner,
};
use talus::geometry::generators::{cuboid, dodecahedron};
use talus::geometry::voronoi_volumes::{polyhedron_voronoi_volumes, sphere_voronoi_volumes};
use talus::geometry::{Shape, Sphere};

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
    cell: impl Fn(&Point3<Real>) -> Option<[usize; 3]>,
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
            if let Some(c) = cell(&p) {
                *hits.entry(c).or_insert(0usize) += 1;
            }
        }
    }
    for (c, v) in got {
        let f = *hits.get(c).unwrap_or(&0) as Real / samples as Real;
        // The spread of the count if the share is right.
        let p = v / box_volume;
        let sigma = (p * (1.0 - p) / samples as Real)
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
        |p| cell_of(p, &b),
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
    against_monte_carlo(
        &got,
        |p| cell_of(p, &b),
        (lo, centre + Vector3::repeat(r)),
        inside,
    );
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

/// Whether `shape` holds the point `p` of its body frame.
fn contains(shape: &Shape, p: &Point3<Real>) -> bool {
    match shape {
        Shape::Polyhedron(poly) => poly
            .planes()
            .iter()
            .all(|q| q.normal.dot(&p.coords) <= q.offset),
        Shape::Sphere(s) => p.coords.norm() <= s.radius,
    }
}

/// The cell of `p` on a cylindrical grid about the z axis: annuli out to `radii`,
/// slabs between `heights`, `n` sectors from +x (None outside).
fn cylinder_cell(
    p: &Point3<Real>,
    radii: &[Real],
    heights: &[Real],
    n: usize,
) -> Option<[usize; 3]> {
    let i = radii.partition_point(|&r| r <= p.x.hypot(p.y));
    let j = heights.partition_point(|&z| z <= p.z);
    if i == radii.len() || j == 0 || j == heights.len() {
        return None;
    }
    let width = 2.0 * PI / n as Real;
    let k = ((p.y.atan2(p.x).rem_euclid(2.0 * PI) / width) as usize).min(n - 1);
    Some([i, j - 1, k])
}

fn cylinder_shares(body: &AxialBody, cells: CylinderCells) -> Vec<([usize; 3], Real)> {
    shares(|f| {
        cylinder_cell_volumes(body, cells, f);
    })
}

#[test]
fn a_turned_dodecahedron_across_the_axis_in_a_cylindrical_grid_matches_sampling() {
    let d = Shape::Polyhedron(dodecahedron(1.0).unwrap().into());
    let pose = Isometry3::new(Vector3::new(0.2, -0.1, 0.4), Vector3::new(0.3, 1.1, -0.7));
    let body = AxialBody::new(&d, &pose);
    let inside = |p: &Point3<Real>| contains(&d, &(pose.inverse() * p));
    // The grid ends inside the particle, radially and along the axis.
    let (radii, heights) = ([0.35, 0.7, 1.1], grid(-0.6, 0.4, 5));
    for n in [1, 6] {
        let cells = CylinderCells {
            radii: &radii,
            heights: &heights,
            sectors: Sectors(n),
        };
        let got = cylinder_shares(&body, cells);
        assert!(got.len() > 10 * n, "{} cells", got.len());
        against_monte_carlo(
            &got,
            |p| cylinder_cell(p, &radii, &heights, n),
            (Point3::new(-2.0, -2.0, -1.6), Point3::new(2.0, 2.0, 2.4)),
            inside,
        );
        // A grid that covers it: the shares add up to its volume.
        let (radii, heights) = ([0.3, 0.8, 1.3, 1.9, 2.5], grid(-1.8, 0.5, 9));
        let cells = CylinderCells {
            radii: &radii,
            heights: &heights,
            sectors: Sectors(n),
        };
        let sum: Real = cylinder_shares(&body, cells).iter().map(|x| x.1).sum();
        assert!((sum / d.volume() - 1.0).abs() < 1e-12, "{n} sectors: {sum}");
    }
}

#[test]
fn a_sphere_in_a_cylindrical_grid_matches_closed_forms_and_sampling() {
    let r: Real = 0.45;
    let ball = 4.0 / 3.0 * PI * r.powi(3);
    let s = Shape::Sphere(Sphere { radius: r });
    // On the axis: the part inside the cylinder of radius ρ is
    // 4π/3 (r³ − (r² − ρ²)^{3/2}), shared equally by the sectors.
    let on_axis = AxialBody::new(&s, &Isometry3::translation(0.0, 0.0, 0.1));
    let radii = [0.1, 0.2, 0.3, 0.45];
    let heights = [-1.0, 1.0];
    let got = cylinder_shares(
        &on_axis,
        CylinderCells {
            radii: &radii,
            heights: &heights,
            sectors: Sectors(5),
        },
    );
    let inside = |rho: Real| 4.0 / 3.0 * PI * (r.powi(3) - (r * r - rho * rho).max(0.0).powf(1.5));
    for ([i, _, k], v) in &got {
        let inner = if *i == 0 { 0.0 } else { inside(radii[i - 1]) };
        let expected = (inside(radii[*i]) - inner) / 5.0;
        assert!(
            (v - expected).abs() < 1e-9 * ball,
            "[{i}, {k}]: {v} against {expected}"
        );
    }
    assert_eq!(got.len(), 20);
    // Off the axis, in eight sectors: sampling, and the sum.
    let centre = Point3::new(0.5, 0.3, 0.1);
    let off = AxialBody::new(&s, &Isometry3::translation(centre.x, centre.y, centre.z));
    let (radii, heights) = ([0.3, 0.5, 0.7, 0.9, 1.2], grid(-0.4, 0.25, 4));
    let cells = CylinderCells {
        radii: &radii,
        heights: &heights,
        sectors: Sectors(8),
    };
    let got = cylinder_shares(&off, cells);
    assert!(got.len() > 30, "{} cells", got.len());
    against_monte_carlo(
        &got,
        |p| cylinder_cell(p, &radii, &heights, 8),
        (centre - Vector3::repeat(r), centre + Vector3::repeat(r)),
        |p| (p - centre).norm() <= r,
    );
    let heights = grid(-0.5, 0.25, 5);
    let cells = CylinderCells {
        heights: &heights,
        ..cells
    };
    let sum: Real = cylinder_shares(&off, cells).iter().map(|x| x.1).sum();
    assert!((sum / ball - 1.0).abs() < 1e-12, "{sum} against {ball}");
}

/// Every centre that can be nearest to a point within `reach` of `p`.
fn candidates(centres: &[Point3<Real>], p: &Point3<Real>, reach: Real) -> Vec<usize> {
    let d0 = centres
        .iter()
        .map(|c| (c - p).norm())
        .fold(Real::INFINITY, Real::min);
    (0..centres.len())
        .filter(|&k| (centres[k] - p).norm() <= d0 + 2.0 * reach)
        .collect()
}

/// Shares in the Voronoi cells of `centres`, by the index of the centre.
fn voronoi_shares(
    shape: &Shape,
    pose: &Isometry3<Real>,
    centres: &[Point3<Real>],
) -> Vec<([usize; 3], Real)> {
    let p = Point3::from(pose.translation.vector);
    let near = candidates(centres, &p, shape.circumradius());
    let local: Vec<Point3<Real>> = near.iter().map(|&k| centres[k]).collect();
    shares(|f| match shape {
        Shape::Polyhedron(poly) => {
            polyhedron_voronoi_volumes(&placed_faces(poly, pose), &local, |k, v| {
                f([near[k], 0, 0], v)
            })
        }
        Shape::Sphere(s) => {
            sphere_voronoi_volumes(p, s.radius, &local, |k, v| f([near[k], 0, 0], v));
        }
    })
}

#[test]
fn shares_in_the_voronoi_cells_of_scattered_centres_match_sampling() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(11);
    let centres: Vec<Point3<Real>> = (0..40)
        .map(|_| Point3::from(Vector3::from_fn(|_, _| rng.random_range(-1.5..1.5))))
        .collect();
    let nearest = |p: &Point3<Real>| {
        let k = (0..centres.len())
            .min_by(|&a, &b| (centres[a] - p).norm().total_cmp(&(centres[b] - p).norm()))
            .unwrap();
        Some([k, 0, 0])
    };
    let d = Shape::Polyhedron(dodecahedron(0.8).unwrap().into());
    let pose = Isometry3::new(Vector3::new(0.2, -0.1, 0.3), Vector3::new(0.3, 1.1, -0.7));
    let ball = Shape::Sphere(Sphere { radius: 0.7 });
    for shape in [&d, &ball] {
        let got = voronoi_shares(shape, &pose, &centres);
        assert!(got.len() > 5, "{} cells", got.len());
        let sum: Real = got.iter().map(|x| x.1).sum();
        assert!((sum / shape.volume() - 1.0).abs() < 1e-12, "{sum}");
        let reach = Vector3::repeat(shape.circumradius());
        let at = Point3::from(pose.translation.vector);
        against_monte_carlo(&got, nearest, (at - reach, at + reach), |p| {
            contains(shape, &(pose.inverse() * p))
        });
    }
}

#[test]
fn a_grid_given_by_its_centres_gets_the_grid_s_shares() {
    // The Voronoi cells of a structured grid's centres are its cells (inside it).
    let b = [grid(-1.0, 0.3, 7), grid(-1.0, 0.25, 8), grid(-0.9, 0.35, 6)];
    let mut centres = Vec::new();
    for k in 0..6 {
        for j in 0..8 {
            for i in 0..7 {
                centres.push(Point3::new(
                    0.5 * (b[0][i] + b[0][i + 1]),
                    0.5 * (b[1][j] + b[1][j + 1]),
                    0.5 * (b[2][k] + b[2][k + 1]),
                ));
            }
        }
    }
    let flat = |c: [usize; 3]| c[0] + 7 * (c[1] + 8 * c[2]);
    // Both sets of shares by flat index; a cell one of them leaves out holds 0.
    let compare =
        |on_grid: Vec<([usize; 3], Real)>, given: Vec<([usize; 3], Real)>, tolerance: Real| {
            let mut by_cell = std::collections::BTreeMap::new();
            for (c, v) in on_grid {
                by_cell.entry(flat(c)).or_insert([0.0; 2])[0] = v;
            }
            for (g, w) in given {
                by_cell.entry(g[0]).or_insert([0.0; 2])[1] = w;
            }
            assert!(by_cell.len() > 8, "{} cells", by_cell.len());
            for (c, [v, w]) in by_cell {
                assert!((v - w).abs() < tolerance, "cell {c}: {v} against {w}");
            }
        };
    let cube = cuboid(0.5, 0.4, 0.3).unwrap();
    let pose = Isometry3::new(
        Vector3::new(0.13, -0.07, 0.11),
        Vector3::new(0.4, -0.9, 0.5),
    );
    compare(
        shares(|f| polyhedron_cell_volumes(placed_faces(&cube, &pose), [&b[0], &b[1], &b[2]], f)),
        voronoi_shares(&Shape::Polyhedron(cube.clone().into()), &pose, &centres),
        1e-12 * cube.volume(),
    );
    let (centre, r) = (Point3::new(0.1, -0.05, 0.12), 0.3);
    compare(
        shares(|f| sphere_cell_volumes(centre, r, [&b[0], &b[1], &b[2]], f)),
        voronoi_shares(
            &Shape::Sphere(Sphere { radius: r }),
            &Isometry3::translation(centre.x, centre.y, centre.z),
            &centres,
        ),
        1e-9 * 4.0 / 3.0 * PI * r.powi(3),
    );
}
