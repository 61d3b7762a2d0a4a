//! Coordination numbers: how many neighbours each particle's surface touches.

use nalgebra::{Isometry3, Point3};

use crate::Real;
use crate::geometry::Shape;
use crate::geometry::gjk::{PointShape, gjk};
use crate::world::World;

/// Contacts per particle: surfaces within `gap` (a cell grid on the centres finds
/// the candidates).
pub(super) fn coordination(world: &World, gap: Real) -> (Real, Vec<usize>) {
    let p = &world.particles;
    let n = p.len();
    let reach = |i: usize| {
        world.body_types[p.body_type[i] as usize]
            .shape
            .circumradius()
    };
    let cell = 2.0 * (0..n).map(reach).fold(0.0, Real::max) + gap;
    let key = |x: &Point3<Real>| {
        [
            (x.x / cell).floor() as i64,
            (x.y / cell).floor() as i64,
            (x.z / cell).floor() as i64,
        ]
    };
    let mut grid: std::collections::HashMap<[i64; 3], Vec<usize>> = Default::default();
    for i in 0..n {
        grid.entry(key(&p.position[i])).or_default().push(i);
    }
    let mut count = vec![0usize; n];
    for i in 0..n {
        let k = key(&p.position[i]);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(list) = grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) else {
                        continue;
                    };
                    for &j in list.iter().filter(|&&j| j > i) {
                        if (p.position[j] - p.position[i]).norm() > reach(i) + reach(j) + gap {
                            continue;
                        }
                        if surface_distance(world, i, j) <= gap {
                            count[i] += 1;
                            count[j] += 1;
                        }
                    }
                }
            }
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
