//! Contact between a convex polyhedron and one triangle of a wall mesh.
//!
//! # What a facet contributes
//!
//! A facet with unit normal `n` (pointing to the side particles live on) owns the
//! half-infinite prism `Q` under it: the points behind its plane whose projection
//! onto the plane falls inside the triangle. The facet's contact is the overlap
//! `P ∩ Q` of the particle with that prism: its volume, its centroid, and the
//! gradient of its volume with respect to the particle's translation. On a flat wall
//! the prisms of the facets tile the half-space behind the wall, so the sums of
//! these quantities over the touched facets are exactly those of the particle
//! against the whole plane, however the plane is triangulated: the force on a
//! particle pressed onto a flat wall does not depend on the mesh. (The side faces of
//! neighbouring prisms cancel in the gradient; only at the boundary of a wall do they
//! push a particle off its edge, as a potential must.)
//!
//! The overlap polygon of the facet with the particle's cross-section in the facet
//! plane — the Sutherland–Hodgman overlap area of Xu et al.'s multiple-GPU
//! polyhedral DEM — comes out as the top face of `P ∩ Q`.
//!
//! The engine groups the facets a particle touches into coplanar patches and applies
//! the contact law to each patch's sums, sharing the force among the facets in
//! proportion to their volumes.

use std::cell::RefCell;

use nalgebra::{Point3, Vector3};

use super::polygon::{ConeSums, FixedPolygon, area_moment, vector_area};
use super::sphere::closest_point_on_triangle;
use super::{ConvexPolyhedron, Plane};
use crate::Real;

/// The overlap of a particle with the prism under one wall facet, in the particle's
/// body frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FacetOverlap {
    /// Volume of the particle inside the facet's prism.
    pub volume: Real,
    /// Centroid of that volume.
    pub centroid: Point3<Real>,
    /// Gradient of `volume` with respect to the particle's translation; the elastic
    /// force on the particle is `−U'(V) · volume_gradient` (it points out of the
    /// wall).
    pub volume_gradient: Vector3<Real>,
    /// Gradient of `volume` with respect to rotating the particle about its centroid;
    /// the elastic torque on the particle is `−U'(V)` times it.
    pub rotation_gradient: Vector3<Real>,
    /// Deepest penetration of the particle behind the facet plane within the prism.
    pub depth: Real,
    /// Area of the overlap of the facet with the particle's cross-section in the facet
    /// plane.
    pub section_area: Real,
    /// Unit facet normal (towards the particle side).
    pub facet_normal: Vector3<Real>,
}

/// Reusable buffers of [`polyhedron_triangle`].
#[derive(Default, Debug)]
struct WallScratch {
    poly: Box<FixedPolygon>,
    points: Vec<Point3<Real>>,
    starts: Vec<usize>,
}

thread_local! {
    static SCRATCH: RefCell<WallScratch> = RefCell::new(WallScratch::default());
}

/// The unit normal of the triangle `t`, counter-clockwise seen from the side it
/// points to: (t₁ − t₀) × (t₂ − t₀), normalised (NaN for a degenerate triangle).
pub fn facet_normal(t: &[Point3<Real>; 3]) -> Vector3<Real> {
    (t[1] - t[0]).cross(&(t[2] - t[0])).normalize()
}

/// Overlap of `poly` with the prism under the triangle `tri` (given in the particle's
/// body frame, counter-clockwise seen from the particle side). `None` if they do not
/// overlap.
pub fn polyhedron_triangle(
    poly: &ConvexPolyhedron,
    tri: &[Point3<Real>; 3],
) -> Option<FacetOverlap> {
    SCRATCH.with(|s| facet_overlap(poly, tri, &mut s.borrow_mut()))
}

fn facet_overlap(
    poly: &ConvexPolyhedron,
    tri: &[Point3<Real>; 3],
    s: &mut WallScratch,
) -> Option<FacetOverlap> {
    let (closest, _) = closest_point_on_triangle(tri, &Point3::origin());
    if closest.coords.norm() >= poly.circumradius() {
        return None;
    }
    let raw_normal = (tri[1] - tri[0]).cross(&(tri[2] - tri[0]));
    let n = raw_normal.normalize();
    if !n.iter().all(|x| x.is_finite()) {
        return None;
    }
    let facet = Plane {
        normal: n,
        offset: n.dot(&tri[0].coords),
    };
    let deepest = poly.vertices()[poly.support_index(&-n, 0)];
    let max_depth = -facet.distance(&deepest);
    if max_depth <= 0.0 {
        return None;
    }
    let mut planes = [facet; 4];
    for k in 0..3 {
        let e = tri[(k + 1) % 3] - tri[k];
        let m = e.cross(&n).normalize();
        planes[k + 1] = Plane {
            normal: m,
            offset: m.dot(&tri[k].coords),
        };
    }

    if within_prism_sides(poly, &planes[1..]) {
        return overlap_with_half_space(poly, &facet, max_depth, &mut s.poly);
    }
    overlap_with_prism(poly, tri, &planes, max_depth, s)
}

/// The overlap of a particle with the prism under `tri`, bounded by `planes` (the
/// facet plane, then the three sides): the particle's faces clipped to the prism and
/// the prism's faces clipped to the particle. `max_depth`: how far the particle's
/// deepest vertex lies behind the facet plane.
fn overlap_with_prism(
    poly: &ConvexPolyhedron,
    tri: &[Point3<Real>; 3],
    planes: &[Plane; 4],
    max_depth: Real,
    s: &mut WallScratch,
) -> Option<FacetOverlap> {
    let (facet, n) = (planes[0], planes[0].normal);
    let WallScratch {
        poly: clipped,
        points,
        starts,
    } = s;
    points.clear();
    starts.clear();
    starts.push(0);

    // Faces of the particle clipped to the prism; a face wholly in front of the
    // facet plane has nothing behind it.
    let mut grad_p = Vector3::zeros();
    let mut rot_p = Vector3::zeros();
    for f in faces_behind(poly, &facet) {
        clipped.set(poly.face(f).iter().map(|&v| poly.vertices()[v as usize]));
        for plane in planes {
            clipped.clip(plane);
            if clipped.is_degenerate() {
                break;
            }
        }
        if !clipped.is_degenerate() {
            grad_p += vector_area(clipped.points());
            rot_p += area_moment(clipped.points());
            points.extend_from_slice(clipped.points());
            starts.push(points.len());
        }
    }
    if points.is_empty() {
        return None;
    }

    // The prism's sides clipped to the particle, deep enough to reach below it; a
    // side whose plane has the whole particle inside does not meet it. The facet
    // itself (the cap) is not needed: the cones are drawn from a point on its plane,
    // and its vector area closes the surface.
    let reach = max_depth * (1.0 + 1e-6) + 1e-9 * poly.circumradius();
    let mut grad_sides = Vector3::zeros();
    for side in 1..4 {
        if poly
            .vertices()
            .iter()
            .all(|v| planes[side].distance(v) <= 0.0)
        {
            continue;
        }
        let (a, b) = (tri[side - 1], tri[side % 3]);
        clipped.set([a, a - n * reach, b - n * reach, b].into_iter());
        for plane in poly.planes() {
            clipped.clip(plane);
            if clipped.is_degenerate() {
                break;
            }
        }
        if !clipped.is_degenerate() {
            grad_sides += vector_area(clipped.points());
            points.extend_from_slice(clipped.points());
            starts.push(points.len());
        }
    }

    let mean = Point3::from(
        points.iter().fold(Vector3::zeros(), |a, p| a + p.coords) / points.len() as Real,
    );
    let mut cone = ConeSums::new(mean - n * facet.distance(&mean));
    for w in starts.windows(2) {
        cone.add_polygon(&points[w[0]..w[1]]);
    }
    let volume = cone.volume();
    if !(volume > 0.0) {
        return None;
    }
    let depth = points
        .iter()
        .map(|p| -facet.distance(p))
        .fold(0.0, Real::max);
    Some(FacetOverlap {
        volume,
        centroid: cone.centroid(),
        // ∂V/∂x_P = S_P.
        volume_gradient: grad_p,
        rotation_gradient: rot_p,
        depth,
        // The cap closes the surface: its vector area is −(S_P + S_sides).
        section_area: (grad_p + grad_sides).norm(),
        facet_normal: n,
    })
}

/// The faces of the particle with a vertex behind the facet plane: the others have
/// nothing in the prism.
fn faces_behind<'a>(
    poly: &'a ConvexPolyhedron,
    facet: &'a Plane,
) -> impl Iterator<Item = usize> + 'a {
    (0..poly.face_count()).filter(move |&f| {
        poly.face(f)
            .iter()
            .any(|&v| facet.distance(&poly.vertices()[v as usize]) < 0.0)
    })
}

/// Whether the particle lies within the facet's side planes (`sides`), so that the
/// prism cuts it only by the facet plane: the common case of a pellet on a facet
/// much larger than itself.
fn within_prism_sides(poly: &ConvexPolyhedron, sides: &[Plane]) -> bool {
    let centre = Point3::origin();
    sides
        .iter()
        .all(|p| p.distance(&centre) + poly.circumradius() <= 0.0)
        || poly
            .vertices()
            .iter()
            .all(|v| sides.iter().all(|p| p.distance(v) <= 0.0))
}

/// The overlap of a particle lying within the prism's sides: its part behind the
/// facet plane, whose deepest vertex lies `depth` behind it. Only the particle's
/// faces reaching behind the plane are clipped, by that plane alone; the cones of
/// the volume sums are drawn from a point on the plane, so the cap (the particle's
/// section, whose vector area closes the surface: `−Σ` of the pieces') adds nothing
/// to them.
fn overlap_with_half_space(
    poly: &ConvexPolyhedron,
    facet: &Plane,
    depth: Real,
    clipped: &mut FixedPolygon,
) -> Option<FacetOverlap> {
    let n = facet.normal;
    let on_plane = Point3::from(-n * facet.distance(&Point3::origin()));
    let mut cone = ConeSums::new(on_plane);
    let (mut area, mut moment) = (Vector3::zeros(), Vector3::zeros());
    for f in faces_behind(poly, facet) {
        clipped.set(poly.face(f).iter().map(|&v| poly.vertices()[v as usize]));
        clipped.clip(facet);
        if !clipped.is_degenerate() {
            area += vector_area(clipped.points());
            moment += area_moment(clipped.points());
            cone.add_polygon(clipped.points());
        }
    }
    let volume = cone.volume();
    if !(volume > 0.0) {
        return None;
    }
    Some(FacetOverlap {
        volume,
        centroid: cone.centroid(),
        volume_gradient: area,
        rotation_gradient: moment,
        depth,
        section_area: area.norm(),
        facet_normal: n,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::generators;
    use nalgebra::{Isometry3, Vector3};

    /// Within the prism's sides, cutting by the facet plane alone gives what clipping
    /// by the whole prism gives.
    #[test]
    fn half_space_and_prism_agree_within_the_sides() {
        let d = generators::dodecahedron(0.01).unwrap();
        let tri = [
            Point3::new(-1.0, -1.0, 0.0),
            Point3::new(1.0, -1.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
        ];
        let mut s = WallScratch::default();
        let mut compared = 0;
        for k in 0..20 {
            let angle = Vector3::new(0.3 * k as Real, 1.1 - 0.07 * k as Real, 0.5);
            let height = 0.0095 - 0.0004 * k as Real;
            let pose = Isometry3::new(Vector3::new(0.01, 0.02, height), angle);
            let local = tri.map(|p| pose.inverse_transform_point(&p));
            let general = {
                let n = (local[1] - local[0])
                    .cross(&(local[2] - local[0]))
                    .normalize();
                let mut planes = [Plane {
                    normal: n,
                    offset: n.dot(&local[0].coords),
                }; 4];
                for e in 0..3 {
                    let m = (local[(e + 1) % 3] - local[e]).cross(&n).normalize();
                    planes[e + 1] = Plane {
                        normal: m,
                        offset: m.dot(&local[e].coords),
                    };
                }
                assert!(within_prism_sides(&d, &planes[1..]));
                let deepest = d.vertices()[d.support_index(&-n, 0)];
                overlap_with_prism(&d, &local, &planes, -planes[0].distance(&deepest), &mut s)
            };
            let fast = facet_overlap(&d, &local, &mut s);
            match (general, fast) {
                (Some(g), Some(f)) => {
                    let scale = g.volume.max(1e-18);
                    assert!((g.volume - f.volume).abs() <= 1e-12 * scale, "{k}");
                    assert!((g.centroid - f.centroid).norm() <= 1e-12 * 0.01, "{k}");
                    let area = g.volume_gradient.norm();
                    assert!((g.volume_gradient - f.volume_gradient).norm() <= 1e-10 * area);
                    assert!(
                        (g.rotation_gradient - f.rotation_gradient).norm() <= 1e-10 * area * 0.01
                    );
                    assert!((g.depth - f.depth).abs() <= 1e-15);
                    assert!((g.section_area - f.section_area).abs() <= 1e-10 * area);
                    compared += 1;
                }
                (None, None) => {}
                (g, f) => panic!("{k}: {g:?} vs {f:?}"),
            }
        }
        // Every pose reaches behind the plane (the circumradius is 0.01).
        assert_eq!(compared, 20);
    }
}
