//! Shape generators: the particle templates a scene names by parameters.
//!
//! All sizes are in metres. Every generator returns a checked [`ConvexPolyhedron`]
//! in its principal body frame.

use std::collections::HashMap;
use std::f64::consts::PI;

use nalgebra::{Point3, Vector3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::{ConvexPolyhedron, GeometryError, TriMesh, convex_hull};
use crate::Real;

/// The golden ratio.
const PHI: Real = 1.618_033_988_749_895;

fn positive(name: &'static str, value: Real) -> Result<(), GeometryError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(GeometryError::InvalidParameter {
            name,
            value,
            reason: "must be a positive finite number",
        })
    }
}

fn scaled_points(points: &[[Real; 3]], circumradius: Real) -> Vec<Point3<Real>> {
    let r0 = Vector3::from(points[0]).norm();
    points
        .iter()
        .map(|p| Point3::from(Vector3::from(*p) * (circumradius / r0)))
        .collect()
}

/// A box with edge lengths `a`, `b`, `c` along x, y, z.
pub fn cuboid(a: Real, b: Real, c: Real) -> Result<ConvexPolyhedron, GeometryError> {
    positive("a", a)?;
    positive("b", b)?;
    positive("c", c)?;
    let mut pts = Vec::with_capacity(8);
    for sx in [-0.5, 0.5] {
        for sy in [-0.5, 0.5] {
            for sz in [-0.5, 0.5] {
                pts.push(Point3::new(sx * a, sy * b, sz * c));
            }
        }
    }
    ConvexPolyhedron::from_hull(&pts)
}

/// The five Platonic solids.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Platonic {
    /// 4 triangular faces.
    Tetrahedron,
    /// 6 square faces.
    Cube,
    /// 8 triangular faces.
    Octahedron,
    /// 12 pentagonal faces: the DEM workhorse.
    Dodecahedron,
    /// 20 triangular faces.
    Icosahedron,
}

impl Platonic {
    /// Vertex coordinates of the solid at some circumradius (centred at the origin).
    fn raw_vertices(self) -> Vec<[Real; 3]> {
        let ip = 1.0 / PHI;
        match self {
            Platonic::Tetrahedron => vec![
                [1.0, 1.0, 1.0],
                [1.0, -1.0, -1.0],
                [-1.0, 1.0, -1.0],
                [-1.0, -1.0, 1.0],
            ],
            Platonic::Cube => {
                let mut v = Vec::new();
                for x in [-1.0, 1.0] {
                    for y in [-1.0, 1.0] {
                        for z in [-1.0, 1.0] {
                            v.push([x, y, z]);
                        }
                    }
                }
                v
            }
            Platonic::Octahedron => vec![
                [1.0, 0.0, 0.0],
                [-1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, -1.0, 0.0],
                [0.0, 0.0, 1.0],
                [0.0, 0.0, -1.0],
            ],
            Platonic::Dodecahedron => {
                let mut v = Platonic::Cube.raw_vertices();
                for a in [-1.0, 1.0] {
                    for b in [-1.0, 1.0] {
                        v.push([0.0, a * ip, b * PHI]);
                        v.push([a * ip, b * PHI, 0.0]);
                        v.push([a * PHI, 0.0, b * ip]);
                    }
                }
                v
            }
            Platonic::Icosahedron => {
                let mut v = Vec::new();
                for a in [-1.0, 1.0] {
                    for b in [-1.0, 1.0] {
                        v.push([0.0, a, b * PHI]);
                        v.push([a, b * PHI, 0.0]);
                        v.push([a * PHI, 0.0, b]);
                    }
                }
                v
            }
        }
    }
}

/// A Platonic solid with the given circumradius.
pub fn platonic(kind: Platonic, circumradius: Real) -> Result<ConvexPolyhedron, GeometryError> {
    positive("circumradius", circumradius)?;
    ConvexPolyhedron::from_hull(&scaled_points(&kind.raw_vertices(), circumradius))
}

/// The regular dodecahedron with the given circumradius.
pub fn dodecahedron(circumradius: Real) -> Result<ConvexPolyhedron, GeometryError> {
    platonic(Platonic::Dodecahedron, circumradius)
}

/// The most sides of a prism particle, and the most points of a random convex one:
/// beyond them a particle costs more than a bed of simpler ones.
pub const MAX_PRISM_SIDES: usize = 10_000;
pub const MAX_HULL_POINTS: usize = 10_000;

/// Triangle mesh of an `n`-gon prism along z: `2n + 2` vertices and `4n` triangles,
/// the caps fanned about their centres (for `n = 20`, the pellet of Xu et al.'s
/// multiple-GPU polyhedral DEM: 42 vertices and 80 triangles). The polygon is inscribed in the circle of
/// diameter `diameter`.
pub fn prism_mesh(sides: usize, diameter: Real, length: Real) -> Result<TriMesh, GeometryError> {
    positive("diameter", diameter)?;
    positive("length", length)?;
    if sides < 3 {
        return Err(GeometryError::InvalidParameter {
            name: "sides",
            value: sides as Real,
            reason: "a prism needs at least 3 sides",
        });
    }
    if sides > MAX_PRISM_SIDES {
        return Err(GeometryError::InvalidParameter {
            name: "sides",
            value: sides as Real,
            reason: "a particle prism has at most 10 000 sides",
        });
    }
    let r = 0.5 * diameter;
    let h = 0.5 * length;
    let mut vertices = Vec::with_capacity(2 * sides + 2);
    for k in 0..sides {
        let t = 2.0 * PI * k as Real / sides as Real;
        vertices.push(Point3::new(r * t.cos(), r * t.sin(), -h));
        vertices.push(Point3::new(r * t.cos(), r * t.sin(), h));
    }
    let bottom = vertices.len();
    vertices.push(Point3::new(0.0, 0.0, -h));
    let top = vertices.len();
    vertices.push(Point3::new(0.0, 0.0, h));
    let mut triangles = Vec::with_capacity(4 * sides);
    for k in 0..sides {
        let (b0, t0) = (2 * k, 2 * k + 1);
        let (b1, t1) = (2 * ((k + 1) % sides), 2 * ((k + 1) % sides) + 1);
        triangles.push([b0, b1, t1]);
        triangles.push([b0, t1, t0]);
        triangles.push([bottom, b1, b0]);
        triangles.push([top, t0, t1]);
    }
    TriMesh::new(vertices, triangles)
}

/// An `n`-gon prism "cylinder" of diameter `diameter` and length `length` along z.
pub fn prism(
    sides: usize,
    diameter: Real,
    length: Real,
) -> Result<ConvexPolyhedron, GeometryError> {
    ConvexPolyhedron::from_convex_mesh(&prism_mesh(sides, diameter, length)?)
}

/// Triangle mesh of an icosphere: the icosahedron subdivided `level` times
/// (`20 · 4^level` triangles: 320 at level 2, 20480 at level 5), vertices on the
/// sphere of radius `radius`.
pub fn icosphere_mesh(level: u32, radius: Real) -> Result<TriMesh, GeometryError> {
    positive("radius", radius)?;
    if level > 7 {
        return Err(GeometryError::InvalidParameter {
            name: "level",
            value: level as Real,
            reason: "at most 7 subdivisions (327 680 triangles)",
        });
    }
    let base = convex_hull(&scaled_points(
        &Platonic::Icosahedron.raw_vertices(),
        radius,
    ))?;
    let mut vertices = base.vertices;
    let mut triangles = base.triangles;
    for _ in 0..level {
        let mut midpoint: HashMap<(usize, usize), usize> = HashMap::new();
        let mut next = Vec::with_capacity(triangles.len() * 4);
        let mut mid = |a: usize, b: usize, vertices: &mut Vec<Point3<Real>>| {
            *midpoint.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let m = (vertices[a].coords + vertices[b].coords).normalize() * radius;
                vertices.push(Point3::from(m));
                vertices.len() - 1
            })
        };
        for [a, b, c] in triangles {
            let ab = mid(a, b, &mut vertices);
            let bc = mid(b, c, &mut vertices);
            let ca = mid(c, a, &mut vertices);
            next.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        triangles = next;
    }
    TriMesh::new(vertices, triangles)
}

/// An icosphere polyhedron (see [`icosphere_mesh`]).
pub fn icosphere(level: u32, radius: Real) -> Result<ConvexPolyhedron, GeometryError> {
    ConvexPolyhedron::from_convex_mesh(&icosphere_mesh(level, radius)?)
}

/// A random convex particle: the hull of `points` random directions on the sphere of
/// radius `radius`, each pushed in or out by a uniform factor in
/// `[1 - jitter, 1 + jitter]`. The same `seed` gives the same particle.
///
/// The triangle-based DEM draft (appendix E) scales the hull's vertices by a random
/// factor in [0.75, 1] *after* taking the hull, which can make the particle slightly
/// non-convex; here the jitter is applied before the hull so that the particle stays
/// convex (`radius = 0.875 R, jitter = 1/7` gives the same radial range).
pub fn random_convex(
    points: usize,
    radius: Real,
    jitter: Real,
    seed: u64,
) -> Result<ConvexPolyhedron, GeometryError> {
    positive("radius", radius)?;
    if !(0.0..1.0).contains(&jitter) {
        return Err(GeometryError::InvalidParameter {
            name: "jitter",
            value: jitter,
            reason: "must lie in [0, 1)",
        });
    }
    if points < 4 {
        return Err(GeometryError::InvalidParameter {
            name: "points",
            value: points as Real,
            reason: "a convex particle needs at least 4 points",
        });
    }
    if points > MAX_HULL_POINTS {
        return Err(GeometryError::InvalidParameter {
            name: "points",
            value: points as Real,
            reason: "a random convex particle has at most 10 000 points",
        });
    }
    let mut rng = Pcg64::seed_from_u64(seed);
    let pts: Vec<Point3<Real>> = (0..points)
        .map(|_| {
            // Uniform direction: z uniform in [-1, 1], azimuth uniform.
            let z: Real = rng.random_range(-1.0..1.0);
            let phi: Real = rng.random_range(0.0..2.0 * PI);
            let s = (1.0 - z * z).sqrt();
            let r = radius * (1.0 + jitter * rng.random_range(-1.0..1.0));
            Point3::new(r * s * phi.cos(), r * s * phi.sin(), r * z)
        })
        .collect();
    ConvexPolyhedron::from_hull(&pts)
}
