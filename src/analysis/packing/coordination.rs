//! Coordination numbers: how many neighbours each particle's surface touches.

use nalgebra::{Isometry3, Point3};

use crate::Real;
use crate::geometry::Shape;
use crate::geometry::gjk::{PointShape, gjk};
use crate::world::World;

use super::near::near_pairs;

/// Contacts per particle: surfaces within `gap`.
pub(super) fn coordination(world: &World, gap: Real) -> (Real, Vec<usize>) {
    let p = &world.particles;
    let n = p.len();
    let reach: Vec<Real> = (0..n)
        .map(|i| {
            world.body_types[p.body_type[i] as usize]
                .shape
                .circumradius()
        })
        .collect();
    let mut count = vec![0usize; n];
    for (i, j) in near_pairs(&p.position[..n], &reach, gap) {
        if surface_distance(world, i, j) <= gap {
            count[i] += 1;
            count[j] += 1;
        }
    }
    let mean = count.iter().sum::<usize>() as Real / n.max(1) as Real;
    let mut histogram = vec![0usize; count.iter().max().map_or(0, |m| m + 1)];
    for c in count {
        histogram[c] += 1;
    }
    (mean, histogram)
}

/// Distance between the surfaces of particles `i` and `j` (0 when they overlap).
fn surface_distance(world: &World, i: usize, j: usize) -> Real {
    let p = &world.particles;
    let shape = |k: usize| &world.body_types[p.body_type[k] as usize].shape;
    let pose = |k: usize| Isometry3::from_parts(p.position[k].coords.into(), p.orientation[k]);
    let j_in_i = pose(i).inverse() * pose(j);
    match (shape(i), shape(j)) {
        (Shape::Sphere(a), Shape::Sphere(b)) => {
            ((p.position[j] - p.position[i]).norm() - a.radius - b.radius).max(0.0)
        }
        (Shape::Polyhedron(a), Shape::Polyhedron(b)) => gjk(&**a, &**b, &j_in_i, None).distance(),
        (Shape::Polyhedron(a), Shape::Sphere(s)) => {
            let centre = PointShape(Point3::origin());
            (gjk(&**a, &centre, &j_in_i, None).distance() - s.radius).max(0.0)
        }
        (Shape::Sphere(s), Shape::Polyhedron(b)) => {
            let centre = PointShape(Point3::origin());
            (gjk(&**b, &centre, &j_in_i.inverse(), None).distance() - s.radius).max(0.0)
        }
    }
}
