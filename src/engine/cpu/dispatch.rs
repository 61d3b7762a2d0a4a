//! The narrow phase's dispatch: the one place that turns a pair of shapes, or a shape
//! and a wall facet, into the geometry of their contact in world coordinates.

use nalgebra::{Isometry3, Point3, Vector3};

use crate::Real;
use crate::geometry::Shape;
use crate::geometry::overlap::{OverlapCache, overlap_cached};
use crate::geometry::sphere::{SphereContact, sphere_polyhedron, sphere_sphere, sphere_triangle};
use crate::geometry::wall::polyhedron_triangle;
use crate::world::World;

/// Geometry of one contact in world coordinates, body 1 → body 2.
#[derive(Clone, Copy, Debug)]
pub(super) struct ContactGeometry {
    pub volume: Real,
    pub area: Real,
    pub depth: Real,
    pub normal: Vector3<Real>,
    pub point: Point3<Real>,
    /// Derivative of the volume with respect to rotating body 2 about its centroid,
    /// where the kernel provides it (polyhedra): the elastic torque then derives from
    /// the same potential as the force.
    pub rotation_gradient: Option<Vector3<Real>>,
}

impl From<SphereContact> for ContactGeometry {
    /// A sphere's contact given in world coordinates: a sphere's has no rotation
    /// gradient (its point lies on the line through the centre).
    #[inline]
    fn from(c: SphereContact) -> Self {
        ContactGeometry {
            volume: c.volume,
            area: c.area,
            depth: c.depth,
            normal: c.normal,
            point: c.point,
            rotation_gradient: None,
        }
    }
}

/// The pose of particle `k`.
#[inline]
pub(super) fn pose_of(world: &World, k: usize) -> Isometry3<Real> {
    let p = &world.particles;
    Isometry3::from_parts(p.position[k].coords.into(), p.orientation[k])
}

/// Contact geometry of particles `i` and `j` in world coordinates (normal i → j);
/// `plan` is the pair's kept overlap plan.
#[inline]
pub(super) fn pair_geometry(
    world: &World,
    i: usize,
    j: usize,
    plan: &mut OverlapCache,
) -> Option<ContactGeometry> {
    let p = &world.particles;
    let (si, sj) = (
        &world.body_types[p.body_type[i] as usize].shape,
        &world.body_types[p.body_type[j] as usize].shape,
    );
    match (si, sj) {
        (Shape::Polyhedron(a), Shape::Polyhedron(b)) => {
            let (pi, pj) = (pose_of(world, i), pose_of(world, j));
            let o = overlap_cached(a, b, &(pi.inverse() * pj), plan)?;
            Some(ContactGeometry {
                volume: o.volume,
                area: o.area,
                depth: o.depth,
                normal: pi.rotation * o.normal,
                point: pi * o.centroid,
                rotation_gradient: Some(pi.rotation * o.rotation_gradient_b),
            })
        }
        (Shape::Sphere(a), Shape::Sphere(b)) => {
            let c = sphere_sphere(a.radius, b.radius, &(p.position[j] - p.position[i]))?;
            Some(ContactGeometry {
                volume: c.volume,
                area: c.area,
                depth: c.depth,
                normal: c.normal,
                point: p.position[i] + c.point.coords,
                rotation_gradient: None,
            })
        }
        (Shape::Polyhedron(a), Shape::Sphere(b)) => {
            let pi = pose_of(world, i);
            let c = sphere_polyhedron(a, &pi.inverse_transform_point(&p.position[j]), b.radius)?;
            Some(ContactGeometry {
                volume: c.volume,
                area: c.area,
                depth: c.depth,
                normal: pi.rotation * c.normal,
                point: pi * c.point,
                rotation_gradient: None,
            })
        }
        (Shape::Sphere(_), Shape::Polyhedron(_)) => {
            // Body 2 here is the polyhedron's partner sphere: the cap model's point lies
            // on the line through the sphere's centre, so it carries no torque model.
            let mut g = pair_geometry(world, j, i, plan)?;
            g.normal = -g.normal;
            g.rotation_gradient = None;
            Some(g)
        }
    }
}

/// Contact geometry of a particle of `shape` at `pose` with the wall facet `tri`
/// (world coordinates), normal out of the wall.
#[inline]
pub(super) fn facet_geometry(
    shape: &Shape,
    pose: &Isometry3<Real>,
    tri: &[Point3<Real>; 3],
) -> Option<ContactGeometry> {
    match shape {
        Shape::Polyhedron(poly) => {
            let local = tri.map(|x| pose.inverse_transform_point(&x));
            polyhedron_triangle(poly, &local).map(|o| {
                let area = o.volume_gradient.norm();
                ContactGeometry {
                    volume: o.volume,
                    area,
                    depth: o.depth,
                    // The force on the particle is along −∇V: out of the wall.
                    normal: -(pose.rotation * o.volume_gradient) / area,
                    point: pose * o.centroid,
                    rotation_gradient: Some(pose.rotation * o.rotation_gradient),
                }
            })
        }
        Shape::Sphere(s) => {
            let centre = Point3::from(pose.translation.vector);
            sphere_triangle(tri, &centre, s.radius).map(|(c, _)| c.into())
        }
    }
}
