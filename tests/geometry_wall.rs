//! Polyhedron–triangle contact: on a flat wall the summed contact does not depend on
//! how the wall is triangulated (the primary seed's sliding-cuboid test, with
//! lambda = particle edge / mesh size from 0.5 to 8).

mod common;

use common::pose;
use nalgebra::{Isometry3, Point3, Vector3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use talus::geometry::ConvexPolyhedron;
use talus::geometry::generators;
use talus::geometry::overlap::overlap;
use talus::geometry::wall::polyhedron_triangle;

/// A square plate `[-w/2, w/2]²` in the plane z = 0 (normal +z), split into `n × n`
/// cells of two triangles. `irregular` moves interior nodes in the plane and
/// alternates the diagonals.
fn plate(w: f64, n: usize, irregular: bool, seed: u64) -> Vec<[Point3<f64>; 3]> {
    let mut rng = Pcg64::seed_from_u64(seed);
    let h = w / n as f64;
    let mut nodes = vec![vec![Point3::origin(); n + 1]; n + 1];
    for (i, row) in nodes.iter_mut().enumerate() {
        for (j, node) in row.iter_mut().enumerate() {
            let mut x = -w / 2.0 + i as f64 * h;
            let mut y = -w / 2.0 + j as f64 * h;
            if irregular && i > 0 && i < n && j > 0 && j < n {
                x += rng.random_range(-0.3..0.3) * h;
                y += rng.random_range(-0.3..0.3) * h;
            }
            *node = Point3::new(x, y, 0.0);
        }
    }
    let mut tris = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let (a, b, c, d) = (
                nodes[i][j],
                nodes[i + 1][j],
                nodes[i + 1][j + 1],
                nodes[i][j + 1],
            );
            if irregular && (i + j) % 2 == 1 {
                tris.push([a, b, d]);
                tris.push([b, c, d]);
            } else {
                tris.push([a, b, c]);
                tris.push([a, c, d]);
            }
        }
    }
    tris
}

/// Summed contact of a particle at `pose` (world) with wall triangles (world):
/// (volume, volume gradient, deepest penetration, section area).
fn wall_contact(
    p: &ConvexPolyhedron,
    pose: &Isometry3<f64>,
    tris: &[[Point3<f64>; 3]],
) -> (f64, Vector3<f64>, f64, f64) {
    let inv = pose.inverse();
    let mut v = 0.0;
    let mut grad = Vector3::zeros();
    let mut depth: f64 = 0.0;
    let mut section = 0.0;
    for t in tris {
        let local = [inv * t[0], inv * t[1], inv * t[2]];
        if let Some(o) = polyhedron_triangle(p, &local) {
            v += o.volume;
            grad += pose * o.volume_gradient;
            depth = depth.max(o.depth);
            section += o.section_area;
        }
    }
    (v, grad, depth, section)
}

#[test]
fn flat_wall_contact_is_independent_of_the_triangulation() {
    let edge = 0.01;
    let cuboid = generators::cuboid(edge, edge, edge).unwrap();
    let w = 0.08;
    // A tilted cuboid pressed into the wall, at several places.
    let tilt = [0.15, -0.1, 0.4];
    let particle_poses: Vec<Isometry3<f64>> = (0..5)
        .map(|k| {
            let s = k as f64 * 0.00137;
            let lowest = {
                let q = pose([0.0; 3], tilt);
                cuboid
                    .vertices()
                    .iter()
                    .map(|v| (q * v).z)
                    .fold(f64::INFINITY, f64::min)
            };
            pose([s, -0.7 * s, -lowest - 0.0012], tilt)
        })
        .collect();
    // Reference: the particle against a huge slab whose top face is the wall plane.
    let slab = generators::cuboid(10.0, 10.0, 1.0).unwrap();
    let slab_pose = pose([0.0, 0.0, -0.5], [0.0; 3]);
    for p in &particle_poses {
        let reference = overlap(&slab, &cuboid, &(slab_pose.inverse() * p)).unwrap();
        for lambda in [0.5, 1.0, 2.0, 4.0, 8.0] {
            let n = (w / (edge / lambda)).round() as usize;
            for irregular in [false, true] {
                let tris = plate(w, n, irregular, 17);
                let (v, grad, depth, section) = wall_contact(&cuboid, p, &tris);
                let label = format!("lambda {lambda}, irregular {irregular}");
                assert!(
                    (v - reference.volume).abs() < 1e-9 * reference.volume,
                    "{label}: {v} vs {}",
                    reference.volume
                );
                // The force direction (along the gradient, out of the wall) and the
                // projected area match the slab's.
                let dir = -grad.normalize();
                assert!((dir - Vector3::z()).norm() < 1e-9, "{label}: {dir}");
                assert!(
                    (grad.norm() - reference.area).abs() < 1e-9 * reference.area,
                    "{label}"
                );
                assert!(
                    (depth - reference.depth).abs() < 1e-9 * reference.depth,
                    "{label}"
                );
                assert!(
                    (section - reference.area).abs() < 1e-9 * reference.area,
                    "{label}"
                );
            }
        }
    }
}

#[test]
fn sliding_cuboid_feels_no_spikes_at_facet_edges_and_vertices() {
    // A cuboid at fixed penetration slides across a coarse irregular mesh (lambda 4):
    // volume and force direction stay constant over facet edges and vertices.
    let edge = 0.01;
    let cuboid = generators::cuboid(edge, edge, edge).unwrap();
    let tris = plate(0.1, 40, true, 5);
    let mut first = None;
    for k in 0..400 {
        let x = -0.02 + k as f64 * 1e-4;
        let p = pose([x, 0.3 * x, 0.5 * edge - 2e-4], [0.0, 0.0, 0.3]);
        let (v, grad, _, _) = wall_contact(&cuboid, &p, &tris);
        let v0 = *first.get_or_insert(v);
        assert!((v - v0).abs() < 1e-10 * v0, "x = {x}: {v} vs {v0}");
        assert!((-grad.normalize() - Vector3::z()).norm() < 1e-9);
    }
    let v0 = first.unwrap();
    assert!((v0 - edge * edge * 2e-4).abs() < 1e-12 * v0);
}

#[test]
fn single_facet_overlap_polygon_and_edge_push() {
    // A cube pressed into the middle of one big triangle: the overlap polygon is the
    // whole cross-section; hanging over the triangle's edge, it is cut by the edge and
    // the prism's side pushes the particle off the edge.
    let cube = generators::cuboid(1.0, 1.0, 1.0).unwrap();
    let tri = [
        Point3::new(-10.0, -10.0, 0.0),
        Point3::new(10.0, -10.0, 0.0),
        Point3::new(0.0, 10.0, 0.0),
    ];
    let inside = pose([0.0, 0.0, 0.4], [0.0; 3]);
    let local = |p: &Isometry3<f64>| {
        [
            p.inverse() * tri[0],
            p.inverse() * tri[1],
            p.inverse() * tri[2],
        ]
    };
    let o = polyhedron_triangle(&cube, &local(&inside)).unwrap();
    assert!((o.volume - 0.1).abs() < 1e-14);
    assert!((o.section_area - 1.0).abs() < 1e-14);
    assert!((o.depth - 0.1).abs() < 1e-14);
    assert!((o.centroid.coords - Vector3::new(0.0, 0.0, -0.45)).norm() < 1e-14);
    // Half over the edge y = -10.
    let edge = pose([0.0, -10.0, 0.4], [0.0; 3]);
    let o = polyhedron_triangle(&cube, &local(&edge)).unwrap();
    assert!((o.volume - 0.05).abs() < 1e-14);
    assert!((o.section_area - 0.5).abs() < 1e-14);
    // ∂V/∂x: −0.5 along z (pressing deeper adds volume over the half cross-section)
    // and +0.1 along y (moving off the edge, towards −y, loses the 0.1-high face).
    assert!(
        (o.volume_gradient - Vector3::new(0.0, 0.1, -0.5)).norm() < 1e-13,
        "{}",
        o.volume_gradient
    );
    // Apart: nothing.
    assert!(polyhedron_triangle(&cube, &local(&pose([0.0, 0.0, 0.5 + 1e-9], [0.0; 3]))).is_none());
    assert!(polyhedron_triangle(&cube, &local(&pose([0.0, -10.6, 0.4], [0.0; 3]))).is_none());
}
