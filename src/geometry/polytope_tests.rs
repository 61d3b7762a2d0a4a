//! Cuts of a [`Polytope`] against volumes known exactly.

use std::collections::HashMap;
use std::f64::consts::PI;

use nalgebra::{Point3, Vector3};

use super::generators::cuboid;
use super::polygon::{clip_by_plane, vector_area};
use super::{GeometryError, Plane, Polytope};
use crate::Real;

/// The axis-aligned box of edges `a` centred on the origin.
fn cube(a: Real) -> Polytope {
    let c = cuboid(a, a, a).unwrap();
    Polytope::placed(&c, c.body_to_input())
}

/// Every directed edge of the faces once, and its twin once: closed and
/// consistently oriented; and the triangles enclose `volume`.
fn assert_closed(p: &Polytope) {
    let mut edges = HashMap::new();
    for face in p.faces() {
        assert!(face.len() >= 3, "a face of {} vertices", face.len());
        for (k, &v) in face.iter().enumerate() {
            *edges.entry((v, face[(k + 1) % face.len()])).or_insert(0) += 1;
        }
    }
    for (&(u, v), &count) in &edges {
        assert_eq!(count, 1, "edge {u}-{v} twice");
        assert_eq!(edges.get(&(v, u)), Some(&1), "edge {u}-{v} open");
    }
    let used: std::collections::HashSet<u32> = p.faces().iter().flatten().copied().collect();
    assert_eq!(used.len(), p.vertices().len(), "unused vertices");
}

fn has_face_on(p: &Polytope, normal: &Vector3<Real>, offset: Real, corners: usize) -> bool {
    p.faces().iter().any(|f| {
        f.len() == corners
            && f.iter()
                .all(|&v| (normal.dot(&p.vertices()[v as usize].coords) - offset).abs() < 1e-15)
    })
}

#[test]
fn a_cut_through_the_middle_leaves_half_and_a_hexagon() {
    let mut p = cube(1.0);
    let n = Vector3::new(1.0, 1.0, 1.0).normalize();
    assert!(p.cut(&n, 0.0).unwrap());
    assert_closed(&p);
    assert!((p.volume() - 0.5).abs() < 1e-15, "{}", p.volume());
    // Four corners kept, six edges crossed; three faces cut, three kept, the new one.
    assert_eq!(p.vertices().len(), 10);
    assert_eq!(p.faces().len(), 7);
    assert!(has_face_on(&p, &n, 0.0, 6));
}

#[test]
fn a_cut_through_vertices_makes_no_new_points() {
    // Through two opposite vertical edges: a triangular prism of half the volume.
    let mut p = cube(1.0);
    let n = Vector3::new(1.0, 1.0, 0.0).normalize();
    assert!(p.cut(&n, 0.0).unwrap());
    assert_closed(&p);
    assert!((p.volume() - 0.5).abs() < 1e-15);
    assert_eq!(p.vertices().len(), 6);
    assert_eq!(p.faces().len(), 5);
    assert!(has_face_on(&p, &n, 0.0, 4));
    // A cut within round-off of those vertices (1e-17) is the same cut.
    let mut q = cube(1.0);
    assert!(q.cut(&n, 1e-17).unwrap());
    assert_eq!(q.vertices(), p.vertices());
}

#[test]
fn a_plane_on_a_face_cuts_nothing_and_one_beyond_the_polytope_is_refused() {
    let mut p = cube(1.0);
    let x = Vector3::x();
    assert!(!p.cut(&x, 0.5).unwrap(), "the face's own plane");
    assert!(!p.cut(&x, 2.0).unwrap(), "a plane beyond it");
    assert_closed(&p);
    assert!((p.volume() - 1.0).abs() < 1e-15);
    for offset in [-0.5, -0.6] {
        let before = p.vertices().to_vec();
        assert!(matches!(
            p.cut(&x, offset),
            Err(GeometryError::CutAway { count: 8 })
        ));
        assert_eq!(p.vertices(), &before[..], "left as it was");
    }
}

/// The tube-wall cap of the capped bed: a box whose vertical edges reach past a
/// circle, shaved by the 720 sides of the polygon inscribed in it, most of them
/// slivers far thinner than the box. The volume is the height times the area of the
/// square clipped to the polygon (clipped in the plane as a polygon alone); every
/// vertex is inside every side.
#[test]
fn hundreds_of_sliver_cuts_keep_it_closed_and_exact() {
    let sides = 720;
    let apothem = 1.2 * (PI / sides as Real).cos();
    let normals: Vec<Vector3<Real>> = (0..sides)
        .map(|k| {
            let t = 2.0 * PI * k as Real / sides as Real;
            Vector3::new(t.cos(), t.sin(), 0.0)
        })
        .collect();
    let mut p = cube(2.0);
    let mut cut = 0;
    for n in &normals {
        cut += usize::from(p.cut(n, apothem).unwrap());
    }
    assert_closed(&p);
    assert!(cut > 100, "only {cut} sides cut");
    let mut square: Vec<Point3<Real>> = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .iter()
        .map(|&(x, y)| Point3::new(x, y, 0.0))
        .collect();
    let (mut dist, mut scratch) = (Vec::new(), Vec::new());
    for n in &normals {
        let plane = Plane {
            normal: *n,
            offset: apothem,
        };
        clip_by_plane(&mut square, &plane, &mut dist, &mut scratch);
    }
    let area = vector_area(&square).z;
    assert!(
        (p.volume() / (2.0 * area) - 1.0).abs() < 1e-13,
        "{} against {}",
        p.volume(),
        2.0 * area
    );
    for x in p.vertices() {
        for n in &normals {
            assert!(n.dot(&x.coords) - apothem < 1e-13);
        }
    }
}
