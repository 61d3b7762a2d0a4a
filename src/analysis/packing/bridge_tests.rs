//! The bridged bed against exact volumes and as a mesher takes it: closed,
//! consistently oriented, free of self-intersections.

use std::collections::HashMap;
use std::f64::consts::PI;
use std::sync::Arc;

use nalgebra::{Point3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};

use super::Tube;
use super::bridges::{BRIDGE_SIDES, Bridge, Surface, bridged_bed, bridges};
use super::mesher::bed_contacts;
use super::tests::{pressed_spheres, tube, world_of};
use crate::Real;
use crate::geometry::generators::{cuboid, icosphere_mesh};
use crate::geometry::{ConvexPolyhedron, Shape, Sphere};

/// Each directed edge once and its twin once: closed and consistently oriented.
fn assert_closed(s: &Surface) {
    let mut edges = HashMap::new();
    for t in &s.triangles {
        for e in 0..3 {
            *edges.entry((t[e], t[(e + 1) % 3])).or_insert(0) += 1;
        }
    }
    for (&(u, v), &count) in &edges {
        assert_eq!(count, 1, "edge {u}-{v} twice");
        assert_eq!(edges.get(&(v, u)), Some(&1), "edge {u}-{v} open");
    }
}

/// Volume enclosed (divergence theorem).
fn volume(s: &Surface) -> Real {
    s.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| s.vertices[v].coords);
            a.dot(&b.cross(&c)) / 6.0
        })
        .sum()
}

/// Six times the signed volume of the tetrahedron `a b c d`.
fn orient(a: &Point3<Real>, b: &Point3<Real>, c: &Point3<Real>, d: &Point3<Real>) -> Real {
    (b - a).dot(&(c - a).cross(&(d - a)))
}

/// Whether segment `p`–`q` crosses the inside of triangle `t`: its ends strictly on
/// either side of the plane and its line strictly inside the three edges, by signed
/// volumes against a tolerance of 1e-10 of the cube of the longest edge involved
/// (triangles that touch along a line or at a point do not cross).
fn crosses(p: &Point3<Real>, q: &Point3<Real>, t: [&Point3<Real>; 3]) -> bool {
    let scale = [
        (q - p).norm(),
        (t[1] - t[0]).norm(),
        (t[2] - t[1]).norm(),
        (t[0] - t[2]).norm(),
    ]
    .into_iter()
    .fold(0.0, Real::max);
    let tolerance = 1e-10 * scale.powi(3);
    let strictly =
        |a: Real, b: Real| a.abs() > tolerance && b.abs() > tolerance && (a > 0.0) == (b > 0.0);
    let (sp, sq) = (orient(t[0], t[1], t[2], p), orient(t[0], t[1], t[2], q));
    if !(sp.abs() > tolerance && sq.abs() > tolerance && (sp > 0.0) != (sq > 0.0)) {
        return false;
    }
    let e = [0, 1, 2].map(|k| orient(p, q, t[k], t[(k + 1) % 3]));
    strictly(e[0], e[1]) && strictly(e[1], e[2])
}

/// Two triangles sharing no vertex of which one has an edge crossing the other's
/// inside, if any (the triangles binned on a grid by their bounding boxes).
fn crossing_triangles(s: &Surface) -> Option<(usize, usize)> {
    let boxes: Vec<(Point3<Real>, Point3<Real>)> = s
        .triangles
        .iter()
        .map(|t| {
            let v = t.map(|k| s.vertices[k]);
            (v[0].inf(&v[1]).inf(&v[2]), v[0].sup(&v[1]).sup(&v[2]))
        })
        .collect();
    let cell = boxes
        .iter()
        .map(|(lo, hi)| (hi - lo).max())
        .fold(0.0, Real::max);
    let key = |x: &Point3<Real>| x.coords.map(|c| (c / cell).floor() as i64);
    let mut grid: HashMap<_, Vec<usize>> = HashMap::new();
    for (k, (lo, hi)) in boxes.iter().enumerate() {
        let (a, b) = (key(lo), key(hi));
        for x in a.x..=b.x {
            for y in a.y..=b.y {
                for z in a.z..=b.z {
                    grid.entry((x, y, z)).or_default().push(k);
                }
            }
        }
    }
    for members in grid.values() {
        for (n, &a) in members.iter().enumerate() {
            for &b in &members[n + 1..] {
                let (ta, tb) = (s.triangles[a], s.triangles[b]);
                if ta.iter().any(|v| tb.contains(v)) {
                    continue;
                }
                let (va, vb) = (ta.map(|k| &s.vertices[k]), tb.map(|k| &s.vertices[k]));
                if (0..3).any(|e| {
                    crosses(va[e], va[(e + 1) % 3], vb) || crosses(vb[e], vb[(e + 1) % 3], va)
                }) {
                    return Some((a, b));
                }
            }
        }
    }
    None
}

fn assert_no_self_intersection(s: &Surface) {
    if let Some((a, b)) = crossing_triangles(s) {
        panic!("triangles {a} and {b} intersect");
    }
}

/// Number of edge-connected shells.
fn shells(s: &Surface) -> usize {
    let mut parent: Vec<usize> = (0..s.vertices.len()).collect();
    fn root(parent: &mut [usize], mut v: usize) -> usize {
        while parent[v] != v {
            parent[v] = parent[parent[v]];
            v = parent[v];
        }
        v
    }
    for t in &s.triangles {
        for e in 0..3 {
            let (a, b) = (root(&mut parent, t[e]), root(&mut parent, t[(e + 1) % 3]));
            parent[a] = b;
        }
    }
    let used: std::collections::HashSet<usize> = s.triangles.iter().flatten().copied().collect();
    let roots: std::collections::HashSet<usize> =
        used.into_iter().map(|v| root(&mut parent, v)).collect();
    roots.len()
}

/// Two unit cubes 0.05 apart face to face: one bridge across the gap, sunk just
/// into each cube's face, and the union holds both cubes plus the prism's part in
/// the gap: 2 + (N/2) r² sin(2π/N) · 0.05, to round-off.
#[test]
fn two_cubes_apart_are_joined_by_one_prism_across_the_gap() {
    let cube = Arc::new(cuboid(1.0, 1.0, 1.0).unwrap());
    let at = |x: Real| (Point3::new(x, 0.3, 0.2), UnitQuaternion::identity());
    let world = world_of(Shape::Polyhedron(cube), &[at(0.0), at(1.05)]);
    let tube = Tube {
        base: Point3::new(0.5, 0.3, -5.0),
        axis: Vector3::z(),
        radius: 10.0,
    };
    let contacts = bed_contacts(&world, 0.1).unwrap();
    assert_eq!(contacts.len(), 1);
    let fraction = 0.2;
    let found = bridges(&world, &tube, 0.1, fraction, &contacts).unwrap();
    assert_eq!(found.len(), 1, "no wall or floor within reach");
    let b = found[0];
    // The cube's volume-equivalent diameter.
    let d = 2.0 * (3.0 / (4.0 * PI)).cbrt();
    assert!((b.radius - 0.5 * fraction * d).abs() < 1e-15);
    // Each end is the margin past the face: the circle's rim needs no depth to fit
    // in a face-on cube.
    assert!(
        (b.start - Point3::new(0.5, 0.3, 0.2)).norm() < 1e-12,
        "{}",
        b.start
    );
    assert!(
        (b.end - Point3::new(0.55, 0.3, 0.2)).norm() < 1e-12,
        "{}",
        b.end
    );

    // Sunk deeper (as into a sphere), the same union.
    let deeper = Bridge {
        start: Point3::new(0.3, 0.3, 0.2),
        end: Point3::new(0.8, 0.3, 0.2),
        ..b
    };
    let n = BRIDGE_SIDES as Real;
    let prism = 0.5 * n * b.radius * b.radius * (2.0 * PI / n).sin() * 0.05;
    let union = bridged_bed(&world, &[deeper]).unwrap();
    assert_closed(&union);
    assert_no_self_intersection(&union);
    assert_eq!(shells(&union), 1);
    assert!(
        (volume(&union) - (2.0 + prism)).abs() < 1e-12,
        "{} against {}",
        volume(&union),
        2.0 + prism
    );
    let apart = bridged_bed(&world, &[]).unwrap();
    assert_eq!(shells(&apart), 2);
    assert!((volume(&apart) - 2.0).abs() < 1e-12);
    // The check sees the prism and the cubes as parts laid side by side, not united.
    let (mut laid, (prism_at, prism_triangles)) = (apart, deeper.mesh());
    let base = laid.vertices.len();
    laid.vertices.extend(prism_at);
    laid.triangles
        .extend(prism_triangles.iter().map(|t| t.map(|v| v as usize + base)));
    assert_closed(&laid);
    assert!(crossing_triangles(&laid).is_some());
}

/// Spheres pressed into each other, the floor and the tube wall, and one alone:
/// the bridged bed is one closed, consistently oriented surface per group of
/// touching particles, free of self-intersections, and encloses the volume of the
/// union of its parts (Monte Carlo on the parts as convex solids, within four
/// standard errors).
#[test]
fn bridged_spheres_are_one_closed_surface_with_the_parts_volume() {
    let (tube, gap) = (tube(1.5), 0.01);
    let placements = pressed_spheres();
    let world = world_of(Shape::Sphere(Sphere::new(0.5).unwrap()), &placements);
    let contacts = bed_contacts(&world, gap).unwrap();
    let found = bridges(&world, &tube, gap, 0.2, &contacts).unwrap();
    // A wall bridge for each icosphere that comes within the gap of the wall, a
    // floor bridge for each within the gap of the floor.
    let ball = ConvexPolyhedron::from_convex_mesh(&icosphere_mesh(2, 0.5).unwrap()).unwrap();
    let ball_at = *ball.body_to_input();
    let placed = |x: Point3<Real>| {
        ball.vertices()
            .iter()
            .map(move |v| x + (ball_at * v).coords)
    };
    let near_wall = placements
        .iter()
        .filter(|(x, _)| placed(*x).any(|v| (v - tube.base).xy().norm() >= 1.5 - gap))
        .count();
    let near_floor = placements
        .iter()
        .filter(|(x, _)| placed(*x).any(|v| v.z <= gap))
        .count();
    assert!(
        near_wall >= 1 && near_floor >= 2,
        "{near_wall} {near_floor}"
    );
    // The contacts overlap: 0–1 by 0.04, 3–4 by 0.05 (necks of radius 0.14 and
    // 0.16), 0–2 by 0.02 and 0–4 by 0.01 (necks of 0.099 and 0.070): the last two
    // need a bridge of radius 0.1.
    let pairs: Vec<(usize, usize)> = contacts.iter().map(|c| (c.i, c.j)).collect();
    assert_eq!(pairs, [(0, 1), (0, 2), (0, 4), (3, 4)]);
    assert_eq!(found.len(), 2 + near_wall + near_floor, "{found:?}");
    let union = bridged_bed(&world, &found).unwrap();
    assert_closed(&union);
    assert_no_self_intersection(&union);
    // The lone sphere and the group of the others: one surface each.
    assert_eq!(shells(&union), 2);

    // The parts as convex solids: icospheres and prisms.
    let mut parts: Vec<Vec<(Vector3<Real>, Real)>> = placements
        .iter()
        .map(|(x, _)| {
            ball.planes()
                .iter()
                .map(|pl| {
                    let pl = pl.transformed(&(nalgebra::Translation3::from(x.coords) * ball_at));
                    (pl.normal, pl.offset)
                })
                .collect()
        })
        .collect();
    for b in &found {
        let hull = ConvexPolyhedron::from_hull(&b.vertices()).unwrap();
        let pose = *hull.body_to_input();
        parts.push(
            hull.planes()
                .iter()
                .map(|pl| {
                    let pl = pl.transformed(&pose);
                    (pl.normal, pl.offset)
                })
                .collect(),
        );
    }
    let lo = union
        .vertices
        .iter()
        .fold(union.vertices[0], |a, b| a.inf(b));
    let hi = union
        .vertices
        .iter()
        .fold(union.vertices[0], |a, b| a.sup(b));
    let box_volume = (hi - lo).product();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(26);
    let samples = 200_000;
    let inside = (0..samples)
        .filter(|_| {
            let x = Point3::from(
                lo.coords + (hi - lo).component_mul(&Vector3::from_fn(|_, _| rng.random())),
            );
            parts
                .iter()
                .any(|planes| planes.iter().all(|(n, d)| n.dot(&x.coords) <= *d))
        })
        .count();
    let f = inside as Real / samples as Real;
    let sampled = f * box_volume;
    let sigma = (f * (1.0 - f) / samples as Real).sqrt() * box_volume;
    let enclosed = volume(&union);
    assert!(
        (enclosed - sampled).abs() < 4.0 * sigma,
        "enclosed {enclosed}, sampled {sampled} ± {sigma}"
    );
    // Overlaps take a little, bridges add a little.
    let balls = 6.0 * ball.volume();
    assert!((enclosed / balls - 1.0).abs() < 0.05, "{enclosed} {balls}");
}
