//! The bed as a CFD mesher takes it: the list of contacts between the particles as
//! they are meshed, and the particles "capped": flattened where they touch a
//! neighbour or the tube, so that every pair is at least a gap apart and a volume
//! mesher (snappyHexMesh, Fluent, STAR-CCM+) never meets a point contact.
//!
//! **Geometry.** Every particle is taken as the convex polyhedron `bed.stl` shows
//! (a sphere as the 320-facet icosphere inscribed in it), so the contacts and caps
//! are those of the surface the mesher receives. A pair's contact is the closest
//! pair of points (GJK) when apart, the overlap's centroid and normal when they
//! overlap, its gap the distance or minus the overlap's depth along the normal.
//!
//! **Caps.** For a contact of `A` and `B` closer than `gap`, at point `p` with normal
//! `n` (from `A` to `B`), `A` keeps the half-space `n · (x − p) ≤ −gap/2` and `B`
//! the half-space `n · (x − p) ≥ gap/2`: the two are then separated by the slab of
//! width `gap` between the planes. Against the tube each particle keeps the
//! half-space `a · (x − base) ≥ gap/2` above the base and the inside of the regular
//! polygon of [`WALL_SIDES`] sides inscribed in the circle `R − gap/2` about the
//! axis (only the sides it reaches cut it).
//! Each half-space cuts the particle's faces in turn ([`Polytope::cut`]: one
//! crossing point per cut edge, the open loop closed by a new face), so a capped
//! particle is closed, convex and gap-separated from every other however thin the
//! slivers the wall's many sides shave off it.

use std::collections::HashMap;
use std::sync::Arc;

use nalgebra::{Isometry3, Point3, Unit, Vector3};

use super::Tube;
use super::near::near_pairs;
use crate::Real;
use crate::geometry::generators::icosphere_mesh;
use crate::geometry::gjk::{GjkResult, gjk};
use crate::geometry::overlap::overlap;
use crate::geometry::polygon::{clip_by_plane, vector_area};
use crate::geometry::surfaces::tangent_frame;
use crate::geometry::{ConvexPolyhedron, GeometryError, Plane, Polytope, Shape};
use crate::world::World;

/// Icosphere level of a sphere in `bed.stl` and the caps (320 facets).
pub const SPHERE_LEVEL: u32 = 2;

/// Sides of the polygon inscribed in the tube wall's cap that caps the particles at
/// the wall: it lies within `1 − cos(π/720)`, about 1e-5, of the radius inside the
/// circle.
pub const WALL_SIDES: usize = 720;

/// A contact between two particles as they are meshed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BedContact {
    /// Index of the first particle.
    pub i: usize,
    /// Index of the second particle (`j > i`).
    pub j: usize,
    /// Contact point: midway between the closest points, or the overlap's centroid.
    pub point: Point3<Real>,
    /// Unit normal from `i` towards `j`.
    pub normal: Vector3<Real>,
    /// Surface distance; negative: the overlap's depth along the normal.
    pub gap: Real,
}

/// Each body type's shape as a polyhedron: itself, or a sphere's icosphere.
pub(super) fn templates(world: &World) -> Result<Vec<Arc<ConvexPolyhedron>>, GeometryError> {
    let mut balls: HashMap<u64, Arc<ConvexPolyhedron>> = HashMap::new();
    world
        .body_types
        .iter()
        .map(|t| match &t.shape {
            Shape::Polyhedron(p) => Ok(Arc::clone(p)),
            Shape::Sphere(s) => match balls.get(&s.radius.to_bits()) {
                Some(p) => Ok(Arc::clone(p)),
                None => {
                    let mesh = icosphere_mesh(SPHERE_LEVEL, s.radius)?;
                    let p = Arc::new(ConvexPolyhedron::from_convex_mesh(&mesh)?);
                    // The icosphere's centroid is the sphere's centre: its frame is
                    // the body's up to a rotation, kept in `body_to_input`.
                    balls.insert(s.radius.to_bits(), Arc::clone(&p));
                    Ok(p)
                }
            },
        })
        .collect()
}

/// The pose of particle `i`'s template (its own body frame) in the world.
pub(super) fn placement(
    world: &World,
    templates: &[Arc<ConvexPolyhedron>],
    i: usize,
) -> Isometry3<Real> {
    let p = &world.particles;
    let body = Isometry3::from_parts(p.position[i].coords.into(), p.orientation[i]);
    match world.body_types[p.body_type[i] as usize].shape {
        Shape::Polyhedron(_) => body,
        // The icosphere mesh was given in the body frame.
        Shape::Sphere(_) => body * templates[p.body_type[i] as usize].body_to_input(),
    }
}

/// The contacts of the particles closer than `within`, in order of `(i, j)`.
pub fn bed_contacts(world: &World, within: Real) -> Result<Vec<BedContact>, GeometryError> {
    Ok(contacts(world, &templates(world)?, within))
}

/// [`bed_contacts`] of the particles as `templates` mesh them.
fn contacts(world: &World, templates: &[Arc<ConvexPolyhedron>], within: Real) -> Vec<BedContact> {
    let p = &world.particles;
    let n = p.owned();
    let template = |i: usize| &templates[p.body_type[i] as usize];
    let reach: Vec<Real> = (0..n).map(|i| template(i).circumradius()).collect();
    near_pairs(&p.position[..n], &reach, within)
        .into_iter()
        .filter_map(|(i, j)| {
            let (a, b) = (
                placement(world, templates, i),
                placement(world, templates, j),
            );
            let (ta, tb) = (template(i), template(j));
            let b_in_a = a.inverse() * b;
            match gjk(&**ta, &**tb, &b_in_a, None) {
                GjkResult::Separated {
                    distance,
                    point_a,
                    point_b,
                } => (distance <= within).then(|| {
                    let (point_a, point_b) = (a * point_a, a * point_b);
                    let normal = (point_b - point_a) / distance;
                    let shared =
                        shared_face_centre([ta, tb], [&a, &b], [&point_a, &point_b], &normal)
                            .map(|c| c + normal * (0.5 * distance));
                    BedContact {
                        i,
                        j,
                        point: shared
                            .unwrap_or(Point3::from((point_a.coords + point_b.coords) * 0.5)),
                        normal,
                        gap: distance,
                    }
                }),
                GjkResult::Intersecting => overlap(ta, tb, &b_in_a).map(|o| BedContact {
                    i,
                    j,
                    point: a * o.centroid,
                    normal: a * o.normal,
                    gap: -o.depth,
                }),
            }
        })
        .collect()
}

/// Where two particles apart face each other with parallel faces (stacked
/// cylinders, cubes face to face), the closest points GJK returns may lie anywhere
/// on the faces' common part, often on its rim: the centroid of that common part,
/// on `A`'s face through `on_a`, is the contact's point instead (`on_b`: the
/// closest point on `B`). `None` unless both
/// particles have a face across the gap (normal `n` from `A` to `B`).
fn shared_face_centre(
    shapes: [&ConvexPolyhedron; 2],
    poses: [&Isometry3<Real>; 2],
    [on_a, on_b]: [&Point3<Real>; 2],
    n: &Vector3<Real>,
) -> Option<Point3<Real>> {
    const PARALLEL: Real = 1e-9;
    let face_along = |k: usize, dir: Vector3<Real>, through: &Point3<Real>| {
        let (poly, pose) = (shapes[k], poses[k]);
        let tolerance = 1e-9 * poly.circumradius();
        (0..poly.face_count()).find_map(|f| {
            let plane = poly.planes()[f].transformed(pose);
            (plane.normal.dot(&dir) > 1.0 - PARALLEL && plane.distance(through).abs() < tolerance)
                .then(|| {
                    poly.face(f)
                        .iter()
                        .map(move |&v| pose * poly.vertices()[v as usize])
                })
        })
    };
    let mut common: Vec<Point3<Real>> = face_along(0, *n, on_a)?.collect();
    // B's face moved across the gap onto A's plane.
    let across = n * n.dot(&(on_b - on_a));
    let b_face: Vec<Point3<Real>> = face_along(1, -n, on_b)?.map(|x| x - across).collect();
    let (mut dist, mut scratch) = (Vec::new(), Vec::new());
    for k in 0..b_face.len() {
        let (u, v) = (b_face[k], b_face[(k + 1) % b_face.len()]);
        // B's face runs counter-clockwise about −n: its inside lies to the left.
        let Some(side) = (v - u).cross(&-n).try_normalize(1e-300) else {
            continue;
        };
        let plane = Plane {
            normal: side,
            offset: side.dot(&u.coords),
        };
        clip_by_plane(&mut common, &plane, &mut dist, &mut scratch);
    }
    let area = vector_area(&common).norm();
    (common.len() >= 3 && area > 0.0).then(|| {
        let p0 = common[0];
        let mut moment = Vector3::zeros();
        for k in 1..common.len() - 1 {
            let a = 0.5 * (common[k] - p0).cross(&(common[k + 1] - p0)).norm();
            moment += (p0.coords + common[k].coords + common[k + 1].coords) * (a / 3.0);
        }
        Point3::from(moment / area)
    })
}

/// A half-space `normal · x ≤ offset` (world frame).
#[derive(Clone, Copy, Debug)]
struct Keep {
    normal: Vector3<Real>,
    offset: Real,
}

/// A capped particle: its vertices in the world and its triangles (counter-clockwise
/// seen from outside).
#[derive(Clone, Debug)]
pub struct CappedParticle {
    /// Vertices in the world.
    pub vertices: Vec<Point3<Real>>,
    /// Triangles.
    pub triangles: Vec<[u32; 3]>,
}

/// Every particle capped against `contacts` (the [`bed_contacts`] closer than
/// `gap`) and against the tube (see the module docs), in particle order.
pub fn capped_particles(
    world: &World,
    tube: &Tube,
    gap: Real,
    contacts: &[BedContact],
) -> Result<Vec<CappedParticle>, GeometryError> {
    let templates = templates(world)?;
    let p = &world.particles;
    let axis = tube.axis.normalize();
    let mut keeps: Vec<Vec<Keep>> = vec![Vec::new(); p.owned()];
    for c in contacts.iter().filter(|c| c.gap <= gap) {
        let at = c.normal.dot(&c.point.coords);
        keeps[c.i].push(Keep {
            normal: c.normal,
            offset: at - 0.5 * gap,
        });
        keeps[c.j].push(Keep {
            normal: -c.normal,
            offset: -(at + 0.5 * gap),
        });
    }
    let floor = Keep {
        normal: -axis,
        offset: -(axis.dot(&tube.base.coords) + 0.5 * gap),
    };
    // The wall's cap: a polygon inscribed in the circle `R − gap/2`.
    let apothem = (tube.radius - 0.5 * gap) * (std::f64::consts::PI / WALL_SIDES as Real).cos();
    let (e1, e2) = tangent_frame(&Unit::new_normalize(axis));
    let wall_normals: Vec<Vector3<Real>> = (0..WALL_SIDES)
        .map(|k| {
            let angle = 2.0 * std::f64::consts::PI * k as Real / WALL_SIDES as Real;
            e1 * angle.cos() + e2 * angle.sin()
        })
        .collect();
    let radial = |x: &Point3<Real>| {
        let r = x - tube.base;
        r - axis * axis.dot(&r)
    };
    let mut capped = Vec::with_capacity(p.owned());
    for (i, keeps) in keeps.iter().enumerate() {
        let template = &templates[p.body_type[i] as usize];
        let mut poly = Polytope::placed(template, &placement(world, &templates, i));
        for keep in keeps.iter().chain([&floor]) {
            poly.cut(&keep.normal, keep.offset)?;
        }
        // Against the curved wall: the sides of the regular polygon of
        // `WALL_SIDES` sides inscribed in the wall's cap that the particle reaches.
        let reach = poly
            .vertices()
            .iter()
            .map(|v| radial(v).norm())
            .fold(0.0, Real::max);
        if reach > apothem {
            for normal in &wall_normals {
                poly.cut(normal, normal.dot(&tube.base.coords) + apothem)?;
            }
        }
        let (vertices, triangles) = poly.triangulate();
        capped.push(CappedParticle {
            vertices,
            triangles,
        });
    }
    Ok(capped)
}
