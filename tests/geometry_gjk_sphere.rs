//! GJK distances and the analytic sphere kernels.

mod common;

use common::{contains, pose};
use nalgebra::{Point3, Vector3};
use proptest::prelude::*;
use talus::geometry::generators;
use talus::geometry::gjk::{GjkResult, PointShape, gjk};
use talus::geometry::overlap::overlap;
use talus::geometry::sphere::{
    TriangleFeature, cap_volume, inward_edge_normals, sphere_on_face, sphere_polyhedron,
    sphere_sphere, sphere_triangle,
};
use talus::geometry::wall::facet_normal;

/// Distance from `p` to the axis-aligned box of half-sizes `h` centred at the origin.
fn box_distance(p: &Point3<f64>, h: &Vector3<f64>) -> f64 {
    let q = p.coords.abs() - h;
    q.sup(&Vector3::zeros()).norm()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn point_to_box_distance(p in prop::array::uniform3(-3.0f64..3.0)) {
        let b = generators::cuboid(1.0, 2.0, 0.5).unwrap();
        let h = Vector3::new(0.5, 1.0, 0.25);
        let point = Point3::from(p);
        let r = gjk(&b, &PointShape(Point3::origin()), &pose(p, [0.0; 3]), None);
        let exact = box_distance(&point, &h);
        if exact > 1e-9 {
            match r {
                GjkResult::Separated { distance, point_a, .. } => {
                    prop_assert!((distance - exact).abs() < 1e-9, "{distance} vs {exact}");
                    prop_assert!((box_distance(&point_a, &h)) < 1e-9);
                }
                GjkResult::Intersecting => prop_assert!(false, "{p:?} is {exact} away"),
            }
        } else if exact == 0.0 {
            prop_assert!(r.intersects() || r.distance() < 1e-9);
        }
    }

    /// The closest points lie on the shapes, are `distance` apart, and moving B by
    /// that distance (plus a little) along their difference makes the shapes overlap.
    #[test]
    fn separation_is_the_distance_between_the_shapes(
        t in prop::array::uniform3(-0.05f64..0.05),
        r1 in prop::array::uniform3(-3.0f64..3.0),
        r2 in prop::array::uniform3(-3.0f64..3.0),
        seed in 0u64..100,
    ) {
        let a = generators::dodecahedron(0.01).unwrap();
        let b = generators::random_convex(20, 0.01, 0.3, seed).unwrap();
        let rel = pose([0.0; 3], r1).inverse() * pose(t, r2);
        if let GjkResult::Separated { distance, point_a, point_b } = gjk(&a, &b, &rel, None) {
            prop_assert!(((point_b - point_a).norm() - distance).abs() < 1e-12);
            let tol = 1e-12;
            prop_assert!(a.planes().iter().all(|p| p.distance(&point_a) < tol));
            prop_assert!(contains(&b, &(rel.inverse() * point_b)) || b.planes().iter().all(|p| p.distance(&(rel.inverse() * point_b)) < tol));
            let dir = (point_b - point_a) / distance;
            let mut closer = rel;
            closer.translation.vector -= dir * (distance * (1.0 + 1e-6) + 1e-9);
            prop_assert!(overlap(&a, &b, &closer).is_some() || distance < 1e-9, "moving by {distance} should touch");
            let mut apart = rel;
            apart.translation.vector -= dir * (distance * (1.0 - 1e-6));
            prop_assert!(!gjk(&a, &b, &apart, None).intersects());
        }
    }
}

#[test]
fn cube_gap_and_warm_start() {
    let c = generators::cuboid(1.0, 1.0, 1.0).unwrap();
    for gap in [1.0, 1e-3, 1e-9] {
        let rel = pose([1.0 + gap, 0.2, -0.1], [0.0; 3]);
        let cold = gjk(&c, &c, &rel, None);
        assert!(
            (cold.distance() - gap).abs() < 1e-12 * (1.0 + gap),
            "{gap}: {cold:?}"
        );
        let warm = gjk(&c, &c, &rel, Some(Vector3::x()));
        assert!((warm.distance() - gap).abs() < 1e-12 * (1.0 + gap));
    }
    assert!(gjk(&c, &c, &pose([0.999, 0.2, -0.1], [0.0; 3]), None).intersects());
    assert!(gjk(&c, &c, &pose([0.0, 0.0, 0.0], [0.3, 0.0, 0.0]), None).intersects());
}

#[test]
fn gjk_on_20480_facets_climbs_the_vertex_graph() {
    let s = generators::icosphere(5, 1.0).unwrap();
    let r = gjk(&s, &s, &pose([2.5, 0.3, 0.0], [0.0; 3]), None);
    let d = (2.5f64 * 2.5 + 0.09).sqrt();
    // Inscribed mesh: between the sphere distance and that of the inscribed spheres.
    let r_in = s
        .planes()
        .iter()
        .map(|p| p.offset)
        .fold(f64::INFINITY, f64::min);
    assert!(
        r.distance() >= d - 2.0 && r.distance() <= d - 2.0 * r_in + 1e-12,
        "{r:?}"
    );
}

#[test]
fn sphere_sphere_lens() {
    let r = 0.5;
    for d in [0.999, 0.8, 0.3] {
        let c = sphere_sphere(r, r, &Vector3::new(0.0, d, 0.0)).unwrap();
        let lens = std::f64::consts::PI * (4.0 * r + d) * (2.0 * r - d).powi(2) / 12.0;
        assert!((c.volume - lens).abs() < 1e-14, "{} vs {lens}", c.volume);
        assert!((c.depth - (1.0 - d)).abs() < 1e-15);
        assert_eq!(c.normal, Vector3::y());
        let a2 = r * r - d * d / 4.0;
        assert!((c.area - std::f64::consts::PI * a2).abs() < 1e-14);
    }
    // Unequal radii: volume is the sum of the two caps.
    let c = sphere_sphere(1.0, 0.25, &Vector3::new(1.1, 0.0, 0.0)).unwrap();
    let x = (1.1f64 * 1.1 + 1.0 - 0.0625) / 2.2;
    assert!(
        (c.volume - (cap_volume(1.0, 1.0 - x) + cap_volume(0.25, 0.25 - (1.1 - x)))).abs() < 1e-15
    );
    assert!(sphere_sphere(0.5, 0.5, &Vector3::new(1.0, 0.0, 0.0)).is_none());
    let inside = sphere_sphere(1.0, 0.1, &Vector3::zeros()).unwrap();
    assert!(inside.volume.is_finite() && inside.normal.norm() == 1.0);
}

#[test]
fn sphere_against_polyhedron() {
    let cube = generators::cuboid(1.0, 1.0, 1.0).unwrap();
    // Over a face.
    let c = sphere_polyhedron(&cube, &Point3::new(0.1, 0.2, 0.7), 0.25).unwrap();
    assert!((c.depth - 0.05).abs() < 1e-12 && (c.normal - Vector3::z()).norm() < 1e-12);
    assert!((c.volume - cap_volume(0.25, 0.05)).abs() < 1e-15);
    // Over an edge: the normal bisects it.
    let e = 0.6;
    let c = sphere_polyhedron(&cube, &Point3::new(e, 0.0, e), 0.2).unwrap();
    let gap = ((e - 0.5) * 2f64.sqrt()).abs();
    assert!((c.depth - (0.2 - gap)).abs() < 1e-12);
    assert!((c.normal - Vector3::new(1.0, 0.0, 1.0).normalize()).norm() < 1e-9);
    // Centre inside: pushed out through the nearest face.
    let c = sphere_polyhedron(&cube, &Point3::new(0.0, 0.45, 0.0), 0.1).unwrap();
    assert!((c.depth - 0.15).abs() < 1e-12 && (c.normal - Vector3::y()).norm() < 1e-12);
    assert!(sphere_polyhedron(&cube, &Point3::new(0.0, 0.0, 0.76), 0.25).is_none());
}

#[test]
fn sphere_against_triangle_features() {
    let t = [
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(1.0, 0.0, 0.0),
        Point3::new(0.0, 1.0, 0.0),
    ];
    let (c, f) = sphere_triangle(&t, &Point3::new(0.2, 0.2, 0.1), 0.15).unwrap();
    assert_eq!(f, TriangleFeature::Face);
    assert!((c.depth - 0.05).abs() < 1e-15 && (c.normal - Vector3::z()).norm() < 1e-15);
    let (_, f) = sphere_triangle(&t, &Point3::new(0.5, -0.05, 0.0), 0.1).unwrap();
    assert_eq!(f, TriangleFeature::Edge(0));
    let (_, f) = sphere_triangle(&t, &Point3::new(0.6, 0.6, 0.0), 0.2).unwrap();
    assert_eq!(f, TriangleFeature::Edge(1));
    let (c, f) = sphere_triangle(&t, &Point3::new(-0.05, -0.05, 0.0), 0.1).unwrap();
    assert_eq!(f, TriangleFeature::Vertex(0));
    assert!((c.depth - (0.1 - 0.05 * 2f64.sqrt())).abs() < 1e-15);
    // From below: the wall is two-sided for spheres.
    let (c, _) = sphere_triangle(&t, &Point3::new(0.2, 0.2, -0.1), 0.15).unwrap();
    assert!((c.normal + Vector3::z()).norm() < 1e-15);
    assert!(sphere_triangle(&t, &Point3::new(0.2, 0.2, 0.2), 0.15).is_none());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// The face test agrees with the closest-point search: over a random triangle a
    /// sphere whose centre projects into it gets the plane's contact (the search's
    /// face contact to round-off), and where the search's closest point is an edge
    /// or a vertex the face test leaves it to the search. Between the two lies only
    /// a band of round-off along the edges, where either answer is the other's to
    /// 1e-12 of the size.
    #[test]
    fn face_contacts_are_the_closest_point_search_s(
        corners in prop::array::uniform3(prop::array::uniform3(-1.0f64..1.0)),
        (u, v) in (-0.5f64..1.5, -0.5f64..1.5),
        above in 0.0f64..=1.0,
        r in 0.05f64..1.0,
    ) {
        let t = corners.map(Point3::from);
        let n = facet_normal(&t);
        prop_assume!((t[1] - t[0]).cross(&(t[2] - t[0])).norm() > 1e-3);
        // A centre over the triangle's plane, inside and around it.
        let c = t[0] + (t[1] - t[0]) * u + (t[2] - t[0]) * v + n * (above * r);
        let height = n.dot(&(c - t[0]));
        prop_assume!((0.0..=r).contains(&height));
        let edges = inward_edge_normals(&t, &n);
        let face = sphere_on_face(&t, &n, &edges, &c, r, height);
        match (face, sphere_triangle(&t, &c, r)) {
            (Some(f), Some((s, feature))) => {
                prop_assert!((f.depth - s.depth).abs() < 1e-12, "{f:?} {s:?}");
                prop_assert!((f.normal - s.normal).norm() < 1e-9 || feature != TriangleFeature::Face);
                prop_assert!((f.point - s.point).norm() < 1e-12 || feature != TriangleFeature::Face);
                prop_assert_eq!(f.normal, n);
                prop_assert!((f.depth - (r - height)).abs() == 0.0);
            }
            (Some(f), None) => prop_assert!(f.depth < 1e-12, "{f:?}"),
            (None, Some((s, feature))) => {
                // Outside the face, or exactly touching: the search's edge or vertex.
                prop_assert!(feature != TriangleFeature::Face || s.depth < 1e-12, "{s:?} {feature:?}");
            }
            (None, None) => {}
        }
    }
}

/// Near contact, GJK once added a support point coplanar with the nearest face of
/// the Minkowski difference and took the flat tetrahedron for one holding the
/// origin: shapes 3.3e-6 apart (3e-4 of their size) were reported intersecting
/// (found by the property test above; 44 of 292 581 random separated pairs before
/// the fix, none after).
#[test]
fn shapes_a_hair_apart_are_not_intersecting() {
    let a = generators::dodecahedron(0.01).unwrap();
    let b = generators::random_convex(20, 0.01, 0.3, 77).unwrap();
    let rel = pose(
        [0.0; 3],
        [
            0.04721235027244604,
            -1.5543117163181648,
            -0.4122728373550433,
        ],
    )
    .inverse()
        * pose(
            [
                -0.021248330409872344,
                -0.04034976163974682,
                0.023779884589163847,
            ],
            [-2.110929586743632, -0.9251505842803961, -2.768168255756862],
        );
    let GjkResult::Separated {
        distance,
        point_a,
        point_b,
    } = gjk(&a, &b, &rel, None)
    else {
        panic!("apart at the start");
    };
    let dir = (point_b - point_a) / distance;
    for f in [0.999, 0.9999, 0.99999, 0.999999] {
        let mut closer = rel;
        closer.translation.vector -= dir * (distance * f);
        let r = gjk(&a, &b, &closer, None);
        assert!(
            (r.distance() - distance * (1.0 - f)).abs() < 1e-12,
            "{f}: {r:?}"
        );
    }
}
