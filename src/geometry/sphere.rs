//! Analytic sphere kernels: sphere–sphere, sphere–polyhedron, sphere–triangle.
//!
//! Each returns the penetration depth, normal and contact point, plus the overlap
//! volume and contact area so that the volume-based normal law applies to spheres too.
//! Sphere–sphere volume is the exact lens; against a polyhedron or a triangle it is
//! the spherical cap of the penetration depth (exact for a face contact, an
//! overestimate at edges and vertices, where the overlap is small anyway).

use std::f64::consts::PI;

use nalgebra::{Point3, Vector3};

use super::gjk::{GjkResult, PointShape, gjk};
use super::{ConvexPolyhedron, Pose};
use crate::Real;

/// Contact between a sphere and another shape, in the frame the inputs were given in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereContact {
    /// Penetration depth.
    pub depth: Real,
    /// Unit normal from the other shape (or the first sphere) towards the sphere
    /// (the second sphere).
    pub normal: Vector3<Real>,
    /// Contact point: the middle of the overlap along the normal.
    pub point: Point3<Real>,
    /// Overlap volume.
    pub volume: Real,
    /// Area of the contact disc (the projected contact area).
    pub area: Real,
}

/// Volume of a spherical cap of height `h` on a sphere of radius `r`.
#[inline]
pub fn cap_volume(r: Real, h: Real) -> Real {
    let h = h.clamp(0.0, 2.0 * r);
    PI * h * h * (3.0 * r - h) / 3.0
}

/// Area of the base disc of a spherical cap of height `h`.
#[inline]
fn cap_area(r: Real, h: Real) -> Real {
    let h = h.clamp(0.0, r);
    PI * (2.0 * r * h - h * h)
}

/// Contact of sphere 1 (radius `r1`, at the origin) with sphere 2 (radius `r2`, centre
/// `c2`). The normal points from sphere 1 to sphere 2.
pub fn sphere_sphere(r1: Real, r2: Real, c2: &Vector3<Real>) -> Option<SphereContact> {
    let d = c2.norm();
    let depth = r1 + r2 - d;
    if depth <= 0.0 {
        return None;
    }
    let normal = if d > 0.0 { c2 / d } else { Vector3::x() };
    let (volume, area) = if d <= (r1 - r2).abs() {
        // One sphere inside the other.
        let r = r1.min(r2);
        (4.0 / 3.0 * PI * r.powi(3), PI * r * r)
    } else {
        // Lens; the contact circle lies at distance x from centre 1.
        let x = (d * d + r1 * r1 - r2 * r2) / (2.0 * d);
        let volume = cap_volume(r1, r1 - x) + cap_volume(r2, r2 - (d - x));
        (volume, PI * (r1 * r1 - x * x).max(0.0))
    };
    Some(SphereContact {
        depth,
        normal,
        point: Point3::from(normal * (r1 - 0.5 * depth)),
        volume,
        area,
    })
}

/// Contact of a sphere (radius `r`, centre `c` in the polyhedron's body frame) with a
/// convex polyhedron. The normal points from the polyhedron to the sphere.
pub fn sphere_polyhedron(
    poly: &ConvexPolyhedron,
    c: &Point3<Real>,
    r: Real,
) -> Option<SphereContact> {
    if c.coords.norm() >= poly.circumradius() + r {
        return None;
    }
    let (closest, normal, depth) = match gjk(
        poly,
        &PointShape(Point3::origin()),
        &Pose::translation(c.x, c.y, c.z),
        None,
    ) {
        GjkResult::Separated {
            distance, point_a, ..
        } => {
            if distance >= r {
                return None;
            }
            (point_a, (c - point_a) / distance, r - distance)
        }
        GjkResult::Intersecting => {
            // Centre inside: leave through the nearest face.
            let (plane, d) = poly
                .planes()
                .iter()
                .map(|p| (p, p.distance(c)))
                .max_by(|a, b| a.1.total_cmp(&b.1))?;
            (c - plane.normal * d, plane.normal, r - d)
        }
    };
    Some(SphereContact {
        depth,
        normal,
        point: closest - normal * (0.5 * depth),
        volume: cap_volume(r, depth),
        area: cap_area(r, depth),
    })
}

/// Which feature of a triangle is closest to a point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TriangleFeature {
    /// The interior.
    Face,
    /// Edge `k` (from vertex `k` to vertex `k + 1`).
    Edge(u8),
    /// Vertex `k`.
    Vertex(u8),
}

/// Closest point of the triangle `t` to `p`, and the feature it lies on.
pub fn closest_point_on_triangle(
    t: &[Point3<Real>; 3],
    p: &Point3<Real>,
) -> (Point3<Real>, TriangleFeature) {
    let (a, b, c) = (t[0], t[1], t[2]);
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(&ap);
    let d2 = ac.dot(&ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, TriangleFeature::Vertex(0));
    }
    let bp = p - b;
    let d3 = ab.dot(&bp);
    let d4 = ac.dot(&bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, TriangleFeature::Vertex(1));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return (a + ab * (d1 / (d1 - d3)), TriangleFeature::Edge(0));
    }
    let cp = p - c;
    let d5 = ab.dot(&cp);
    let d6 = ac.dot(&cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, TriangleFeature::Vertex(2));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return (a + ac * (d2 / (d2 - d6)), TriangleFeature::Edge(2));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * w, TriangleFeature::Edge(1));
    }
    let denom = 1.0 / (va + vb + vc);
    (
        a + ab * (vb * denom) + ac * (vc * denom),
        TriangleFeature::Face,
    )
}

/// The in-plane normals of triangle `t`'s edges, each pointing into the triangle:
/// `n × (t[k+1] − t[k])` for its unit normal `n` (`wall::facet_normal`, with `t`
/// counter-clockwise about it). A point `p` projects into the triangle (an edge
/// counting as inside) where `eₖ · (p − t[k]) ≥ 0` for all three.
pub fn inward_edge_normals(t: &[Point3<Real>; 3], n: &Vector3<Real>) -> [Vector3<Real>; 3] {
    [0, 1, 2].map(|k| n.cross(&(t[(k + 1) % 3] - t[k])))
}

/// Contact of a sphere (radius `r`, centre `c`) with the face of triangle `t` (unit
/// normal `n`, inward edge normals `edges`: [`inward_edge_normals`]), the centre
/// `height = n · (c − t[0])` above the triangle's plane: where the centre projects
/// into the triangle, the plane's contact (no point of the plane is nearer), found
/// without the closest-point search. `None` where it projects outside (the closest
/// point lies on an edge or a vertex: [`sphere_triangle`]) or the sphere does not
/// reach below `height` (`height ≥ r`).
///
/// The contact is [`sphere_triangle`]'s (normal `n`, depth `r − height`) to
/// round-off; a caller that merges the facets of a flat patch takes it as the
/// patch's contact, which no facet's edge or vertex contact can beat.
#[inline]
pub fn sphere_on_face(
    t: &[Point3<Real>; 3],
    n: &Vector3<Real>,
    edges: &[Vector3<Real>; 3],
    c: &Point3<Real>,
    r: Real,
    height: Real,
) -> Option<SphereContact> {
    // One branch for the three sides: which side a centre lies on is a coin toss
    // near a shared edge.
    let inside = (edges[0].dot(&(c - t[0])) >= 0.0)
        & (edges[1].dot(&(c - t[1])) >= 0.0)
        & (edges[2].dot(&(c - t[2])) >= 0.0);
    if !inside || !(height < r) {
        return None;
    }
    let depth = r - height;
    let projection = c - n * height;
    Some(SphereContact {
        depth,
        normal: *n,
        point: projection - n * (0.5 * depth),
        volume: cap_volume(r, depth),
        area: cap_area(r, depth),
    })
}

/// Contact of a sphere (radius `r`, centre `c`) with the triangle `t` (two-sided), and
/// the triangle feature touched. The normal points from the triangle to the sphere.
///
/// On a flat mesh a sphere over a shared edge touches the edge of two triangles;
/// callers keep one contact per touched point (a face contact wins over the edges and
/// vertices it bounds).
pub fn sphere_triangle(
    t: &[Point3<Real>; 3],
    c: &Point3<Real>,
    r: Real,
) -> Option<(SphereContact, TriangleFeature)> {
    let (q, feature) = closest_point_on_triangle(t, c);
    let offset = c - q;
    let distance = offset.norm();
    if distance >= r {
        return None;
    }
    let normal = if distance > 0.0 {
        offset / distance
    } else {
        super::wall::facet_normal(t)
    };
    let depth = r - distance;
    Some((
        SphereContact {
            depth,
            normal,
            point: q - normal * (0.5 * depth),
            volume: cap_volume(r, depth),
            area: cap_area(r, depth),
        },
        feature,
    ))
}
