//! The bed "bridged" for a CFD mesher: a small cylinder joins the two particles of
//! every contact, and every particle that touches the tube's wall or floor to the
//! wall beyond, and the particles and cylinders are united into one closed surface.
//! Where two pellets (or a pellet and the wall) meet at a point or a line, a volume
//! mesher needs ever smaller cells; a bridge replaces the point by a neck of finite
//! width, keeping the pellets' own size (the alternative to shrinking them or
//! flattening them into caps, see [`super::mesher`]).
//!
//! **Geometry.** Particles are the polyhedra `bed.stl` shows (spheres as their
//! 320-facet icospheres), contacts those of [`super::mesher::bed_contacts`] closer
//! than the cap gap (`contacts.csv`); overlapping particles whose overlap is already
//! a neck wider than the bridge need none. A bridge is a regular prism of
//! [`BRIDGE_SIDES`] sides about the contact's normal through its point, of diameter
//! `diameter` times the smaller particle's volume-equivalent diameter. Each end
//! sinks into its particle just far enough that the circle about the end lies inside
//! it (exactly, against every face plane, with a margin of a thousandth of the
//! radius), so the prism's ends never show; where no such depth exists (a bridge
//! wider than a thin particle), the end goes to the middle of the particle's chord
//! along the normal. A particle whose surface comes within the gap of the tube's
//! wall is bridged from its outermost vertex radially out to `R + r_bridge`, one
//! within the gap of the floor from its lowest vertex down to `r_bridge` below the
//! base: those bridges pass through the wall, so the fluid domain the mesher cuts
//! (tube minus solid) meets the pellet in a neck, not a point.
//!
//! **Union.** The solid is the boolean union of all particles and bridges,
//! computed by `manifold-rust` (a port of the Manifold library, whose booleans are
//! guaranteed to return a closed, oriented, non-self-intersecting mesh), as one
//! batch union (bounding-box partitions composed, then united pairwise).

use std::f64::consts::PI;

use manifold_rust::csg_tree::CsgNode;
use manifold_rust::manifold::Manifold;
use manifold_rust::types::{Error as ManifoldStatus, MeshGL64, OpType};
use nalgebra::{Point3, Unit, Vector3};

use super::Tube;
use super::mesher::{BedContact, placement, templates};
use crate::Real;
use crate::geometry::surfaces::tangent_frame;
use crate::geometry::{ConvexPolyhedron, GeometryError};
use crate::world::World;

/// Sides of a bridge's prism.
pub const BRIDGE_SIDES: usize = 16;

/// A convex solid's face planes `(outward normal, offset)`, world frame.
type FacePlanes = Vec<(Vector3<Real>, Real)>;

/// Margin of a bridge end's circle inside its particle, relative to the radius.
const MARGIN: Real = 1e-3;

/// Why a bridged bed could not be built.
#[derive(Debug, thiserror::Error)]
pub enum BridgeError {
    /// A particle's shape could not be meshed.
    #[error(transparent)]
    Geometry(#[from] GeometryError),
    /// The boolean union failed (the message is the library's status).
    #[error("the union of particles and bridges failed: {0}")]
    Union(String),
}

/// A bridge: the regular prism of [`BRIDGE_SIDES`] sides inscribed in the cylinder
/// of `radius` about the segment `start`–`end`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bridge {
    /// Centre of the first end (inside the first particle).
    pub start: Point3<Real>,
    /// Centre of the other end (inside the other particle, or beyond the wall).
    pub end: Point3<Real>,
    /// Radius of the circumscribed cylinder.
    pub radius: Real,
}

impl Bridge {
    /// The prism's vertices: the ring about `start`, then the ring about `end`.
    pub fn vertices(&self) -> Vec<Point3<Real>> {
        let axis = Unit::new_normalize(self.end - self.start);
        let (e1, e2) = tangent_frame(&axis);
        let ring = |centre: Point3<Real>| {
            (0..BRIDGE_SIDES).map(move |k| {
                let angle = 2.0 * PI * k as Real / BRIDGE_SIDES as Real;
                centre + (e1 * angle.cos() + e2 * angle.sin()) * self.radius
            })
        };
        ring(self.start).chain(ring(self.end)).collect()
    }

    /// The prism as a closed triangle mesh (counter-clockwise seen from outside).
    pub fn mesh(&self) -> (Vec<Point3<Real>>, Vec<[u32; 3]>) {
        let n = BRIDGE_SIDES as u32;
        let mut triangles = Vec::with_capacity(4 * BRIDGE_SIDES);
        for k in 0..n {
            let next = (k + 1) % n;
            // The rings turn counter-clockwise about the axis start → end.
            triangles.push([k, next, n + next]);
            triangles.push([k, n + next, n + k]);
        }
        for k in 1..n - 1 {
            triangles.push([0, k + 1, k]);
            triangles.push([n, n + k, n + k + 1]);
        }
        (self.vertices(), triangles)
    }
}

/// How far from `from` along `inward` the circle of `radius` about the axis (and
/// perpendicular to it) lies wholly inside the convex polyhedron `planes` (world
/// frame): the smallest such distance, or half the chord if the circle fits
/// nowhere.
fn sink_depth(
    planes: &[(Vector3<Real>, Real)],
    from: &Point3<Real>,
    inward: &Unit<Vector3<Real>>,
    radius: Real,
) -> Real {
    let (mut lowest, mut highest, mut chord) = (0.0, Real::INFINITY, Real::INFINITY);
    for (normal, offset) in planes {
        let along = normal.dot(inward);
        // The circle's farthest reach along the plane's normal.
        let rim = radius * (normal - inward.as_ref() * along).norm() * (1.0 + MARGIN);
        let room = offset - normal.dot(&from.coords) - rim;
        if along < 0.0 {
            lowest = Real::max(lowest, room / along);
        } else if along > 0.0 {
            highest = Real::min(highest, room / along);
            chord = Real::min(chord, (offset - normal.dot(&from.coords)) / along);
        } else if room < 0.0 {
            highest = Real::NEG_INFINITY;
        }
    }
    if lowest <= highest {
        lowest
    } else {
        0.5 * chord
    }
}

/// The bridges of a bed (see the module docs): one per contact closer than `gap`
/// (in the order of `contacts`) unless the particles overlap in a neck wider than
/// the bridge, then one per particle within `gap` of the tube's
/// wall and one per particle within `gap` of its floor (in particle order).
/// `diameter`: a bridge's diameter over the smaller particle's volume-equivalent
/// diameter.
pub fn bridges(
    world: &World,
    tube: &Tube,
    gap: Real,
    diameter: Real,
    contacts: &[BedContact],
) -> Result<Vec<Bridge>, GeometryError> {
    let templates = templates(world)?;
    let p = &world.particles;
    let placed: Vec<(Vec<Point3<Real>>, FacePlanes)> = (0..p.owned())
        .map(|i| {
            let pose = placement(world, &templates, i);
            let poly: &ConvexPolyhedron = &templates[p.body_type[i] as usize];
            let vertices = poly.vertices().iter().map(|v| pose * v).collect();
            let planes = poly
                .planes()
                .iter()
                .map(|pl| {
                    let pl = pl.transformed(&pose);
                    (pl.normal, pl.offset)
                })
                .collect();
            (vertices, planes)
        })
        .collect();
    let size = |i: usize| {
        2.0 * world.body_types[p.body_type[i] as usize]
            .shape
            .equivalent_radius()
    };
    let mut out = Vec::new();
    for c in contacts.iter().filter(|c| c.gap <= gap) {
        let radius = 0.5 * diameter * size(c.i).min(size(c.j));
        let normal = Unit::new_normalize(c.normal);
        let into_i = sink_depth(&placed[c.i].1, &c.point, &-normal, radius);
        let into_j = sink_depth(&placed[c.j].1, &c.point, &normal, radius);
        if into_i + into_j <= MARGIN * radius {
            // The circle about the contact's point lies in both: the particles'
            // overlap is already a neck wider than the bridge.
            continue;
        }
        out.push(Bridge {
            start: c.point - normal.as_ref() * into_i,
            end: c.point + normal.as_ref() * into_j,
            radius,
        });
    }
    let axis = Unit::new_normalize(tube.axis);
    let radial = |x: &Point3<Real>| {
        let r = x - tube.base;
        r - axis.as_ref() * axis.dot(&r)
    };
    let height = |x: &Point3<Real>| axis.dot(&(x - tube.base));
    let farthest = |vertices: &[Point3<Real>], key: &dyn Fn(&Point3<Real>) -> Real| {
        vertices
            .iter()
            .copied()
            .max_by(|a, b| key(a).total_cmp(&key(b)))
            .expect("a polyhedron has vertices")
    };
    for (i, (vertices, planes)) in placed.iter().enumerate() {
        let radius = 0.5 * diameter * size(i);
        let outer = farthest(vertices, &|x| radial(x).norm());
        let reach = radial(&outer).norm();
        if tube.radius - reach <= gap && reach > 0.0 {
            let out_dir = Unit::new_normalize(radial(&outer));
            let depth = sink_depth(planes, &outer, &-out_dir, radius);
            out.push(Bridge {
                start: outer - out_dir.as_ref() * depth,
                end: outer + out_dir.as_ref() * (tube.radius + radius - reach),
                radius,
            });
        }
        let lowest = farthest(vertices, &|x| -height(x));
        if height(&lowest) <= gap {
            let depth = sink_depth(planes, &lowest, &axis, radius);
            out.push(Bridge {
                start: lowest + axis.as_ref() * depth,
                end: lowest - axis.as_ref() * (height(&lowest) + radius),
                radius,
            });
        }
    }
    Ok(out)
}

/// A closed surface: vertices and triangles (counter-clockwise seen from outside).
#[derive(Clone, Debug, Default)]
pub struct Surface {
    /// Vertices.
    pub vertices: Vec<Point3<Real>>,
    /// Triangles.
    pub triangles: Vec<[usize; 3]>,
}

/// The union of every particle (as `bed.stl` shows it) and `bridges`: one closed
/// surface (see the module docs).
pub fn bridged_bed(world: &World, bridges: &[Bridge]) -> Result<Surface, BridgeError> {
    let templates = templates(world)?;
    let p = &world.particles;
    let solid = |vertices: Vec<Point3<Real>>, triangles: Vec<[u32; 3]>| {
        let mesh = MeshGL64 {
            num_prop: 3,
            vert_properties: vertices.iter().flat_map(|x| [x.x, x.y, x.z]).collect(),
            tri_verts: triangles.iter().flatten().map(|&v| v as u64).collect(),
            ..MeshGL64::default()
        };
        let m = Manifold::from_mesh_gl64(&mesh);
        match m.status() {
            ManifoldStatus::NoError => Ok(CsgNode::leaf(m.into_impl())),
            status => Err(BridgeError::Union(format!("{status:?} in a part's mesh"))),
        }
    };
    let mut parts = Vec::with_capacity(p.owned() + bridges.len());
    for i in 0..p.owned() {
        let pose = placement(world, &templates, i);
        let poly = &templates[p.body_type[i] as usize];
        let vertices = poly.vertices().iter().map(|v| pose * v).collect();
        parts.push(solid(vertices, poly.triangles())?);
    }
    for b in bridges {
        let (vertices, triangles) = b.mesh();
        parts.push(solid(vertices, triangles)?);
    }
    if parts.is_empty() {
        return Ok(Surface::default());
    }
    let union = Manifold::from_impl(CsgNode::op_n(OpType::Add, parts).evaluate());
    if union.status() != ManifoldStatus::NoError {
        return Err(BridgeError::Union(format!("{:?}", union.status())));
    }
    let mesh = union.get_mesh_gl64(-1);
    let stride = mesh.num_prop as usize;
    Ok(Surface {
        vertices: mesh
            .vert_properties
            .chunks_exact(stride)
            .map(|v| Point3::new(v[0], v[1], v[2]))
            .collect(),
        triangles: mesh
            .tri_verts
            .chunks_exact(3)
            .map(|t| [t[0] as usize, t[1] as usize, t[2] as usize])
            .collect(),
    })
}
