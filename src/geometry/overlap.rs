//! Exact overlap of two convex polyhedra: volume, centroid, contact normal and
//! contact area.
//!
//! # Method: face clipping and the divergence theorem
//!
//! The boundary of the intersection `A ∩ B` consists of the pieces `f ∩ B` of the
//! faces `f` of A and the pieces `g ∩ A` of the faces `g` of B. Each piece is a convex
//! polygon, obtained by clipping one face polygon against the other solid's planes
//! (Sutherland–Hodgman in 3-D). No topology of the intersection is ever built: the
//! closed set of polygons is enough for
//!
//! - the volume and centroid (a fan of tetrahedra from a point near the overlap);
//! - the contact-area vector `S = Σ_{f ∈ A} n_f |f ∩ B|`, which is exactly the gradient
//!   of the overlap volume with respect to the translation of B relative to A. A
//!   normal force along `S` therefore derives from a potential of the overlap volume
//!   (Feng's energy-conserving framework), and `|S|` is the projected contact area.
//!
//! We chose this over the primary seed's dual-space incremental quickhull because it
//! needs no point strictly inside the intersection (the polar dual does, and finding
//! one for a tiny overlap is itself a linear program), has no combinatorial state that
//! round-off can corrupt (a hull's horizon can), allocates nothing per pair (the
//! scratch buffers are reused), and parallelises as a flat loop over faces. The cost is
//! dominated by one matrix of vertex–plane distances per side, and most faces are
//! rejected from that matrix alone.
//!
//! Coplanar faces of equal orientation (identical shapes at the same pose, boxes of a
//! lattice lying flush) would be counted twice; the piece from B is dropped in that
//! case, since A's face already covers it. The volume is not differentiable there;
//! such flush pieces are left out of the contact-area vector, which picks the
//! subgradient with no component along their normal (flush neighbours in a lattice
//! feel no sideways push).
//!
//! For large meshes (hundreds of faces) only faces whose bounding spheres meet the box
//! `R` enclosing both bounding spheres take part, after clipping to `R`. This is exact
//! when the shapes intersect (B ∩ R is bounded by the planes of the faces of B that
//! meet R), which is checked with GJK first.

use std::cell::RefCell;

use nalgebra::{Point3, Vector3};

use super::gjk::{self, GjkResult};
use super::polygon::{ConeSums, clip_by_plane, clip_with_distances, vector_area};
use super::{ConvexPolyhedron, Plane, Pose};
use crate::Real;

/// Above this many faces in total, faces are culled against the region the overlap can
/// occupy before clipping.
const CULL_FACE_THRESHOLD: usize = 96;

/// The overlap of two convex polyhedra, in the frame of the first.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OverlapGeometry {
    /// Volume of the intersection.
    pub volume: Real,
    /// Centroid of the intersection: the contact point.
    pub centroid: Point3<Real>,
    /// Unit contact normal pointing from A towards B: the direction of the gradient of
    /// the overlap volume with respect to A's position (a repulsive force on B acts
    /// along it).
    pub normal: Vector3<Real>,
    /// Projected contact area: the length of the contact-area vector.
    pub area: Real,
    /// Extent of the intersection along the normal (the penetration depth of a flat
    /// contact).
    pub depth: Real,
}

impl OverlapGeometry {
    /// The contact-area vector `normal * area`: ∂V/∂x_A, and −∂V/∂x_B.
    pub fn area_vector(&self) -> Vector3<Real> {
        self.normal * self.area
    }
}

/// Reusable buffers of [`overlap_with`]; keep one per thread.
#[derive(Default, Debug)]
pub struct OverlapScratch {
    b_points: Vec<Point3<Real>>,
    b_planes: Vec<Plane>,
    a_faces: Vec<u32>,
    b_faces: Vec<u32>,
    a_plane_ids: Vec<u32>,
    b_plane_ids: Vec<u32>,
    /// Distances of A's vertices from B's candidate planes, one row per plane.
    dist_a: Vec<Real>,
    /// Distances of B's vertices from A's candidate planes, one row per plane.
    dist_b: Vec<Real>,
    cutting: Vec<u32>,
    poly: Vec<Point3<Real>>,
    poly_tmp: Vec<Point3<Real>>,
    dist: Vec<Real>,
    points: Vec<Point3<Real>>,
    starts: Vec<u32>,
}

thread_local! {
    static SCRATCH: RefCell<OverlapScratch> = RefCell::new(OverlapScratch::default());
}

/// Overlap of `a` and `b`, where `b_in_a` is the pose of B's body frame in A's body
/// frame. `None` when they do not overlap (or only touch).
pub fn overlap(
    a: &ConvexPolyhedron,
    b: &ConvexPolyhedron,
    b_in_a: &Pose,
) -> Option<OverlapGeometry> {
    SCRATCH.with(|s| overlap_with(a, b, b_in_a, &mut s.borrow_mut()))
}

/// [`overlap`] with caller-owned scratch buffers.
pub fn overlap_with(
    a: &ConvexPolyhedron,
    b: &ConvexPolyhedron,
    b_in_a: &Pose,
    s: &mut OverlapScratch,
) -> Option<OverlapGeometry> {
    let t = b_in_a.translation.vector;
    let (ra, rb) = (a.circumradius(), b.circumradius());
    if t.norm() >= ra + rb {
        return None;
    }
    let tol = 1e-12 * ra.max(rb);

    s.b_points.clear();
    s.b_points
        .extend(b.vertices().iter().map(|p| b_in_a.transform_point(p)));
    s.b_planes.clear();
    s.b_planes
        .extend(b.planes().iter().map(|p| p.transformed(b_in_a)));

    // Region the overlap can occupy, for culling on large meshes.
    let cull = a.face_count() + b.face_count() > CULL_FACE_THRESHOLD;
    let mut region = None;
    if cull {
        if !matches!(gjk::gjk(a, b, b_in_a, None), GjkResult::Intersecting) {
            return None;
        }
        let lo = (-Vector3::repeat(ra)).sup(&(t - Vector3::repeat(rb)));
        let hi = Vector3::repeat(ra).inf(&(t + Vector3::repeat(rb)));
        region = Some((lo, hi));
    }
    let touches_region = |c: &Point3<Real>, r: Real| match region {
        None => true,
        Some((lo, hi)) => {
            let q = c.coords.sup(&lo).inf(&hi);
            (c.coords - q).norm_squared() <= r * r
        }
    };
    s.a_faces.clear();
    s.a_faces.extend((0..a.face_count() as u32).filter(|&f| {
        let (c, r) = a.face_spheres()[f as usize];
        touches_region(&c, r)
    }));
    s.b_faces.clear();
    s.b_faces.extend((0..b.face_count() as u32).filter(|&g| {
        let (c, r) = b.face_spheres()[g as usize];
        touches_region(&b_in_a.transform_point(&c), r)
    }));
    if s.a_faces.is_empty() && s.b_faces.is_empty() {
        return None;
    }

    // Vertex–plane distances for small shapes; planes that leave all of the other
    // shape inside are dropped, and one that leaves all of it outside separates.
    let matrix = !cull;
    if matrix {
        if !distance_matrix(
            a.vertices(),
            &s.b_planes,
            &s.b_faces,
            tol,
            &mut s.dist_a,
            &mut s.b_plane_ids,
        ) || !distance_matrix(
            &s.b_points,
            a.planes(),
            &s.a_faces,
            tol,
            &mut s.dist_b,
            &mut s.a_plane_ids,
        ) {
            return None;
        }
    } else {
        s.b_plane_ids.clear();
        s.b_plane_ids.extend(s.b_faces.iter().map(|&g| g));
        s.a_plane_ids.clear();
        s.a_plane_ids.extend(s.a_faces.iter().map(|&f| f));
    }

    let region_planes = region.map(|(lo, hi)| box_planes(&lo, &hi));
    s.points.clear();
    s.starts.clear();
    s.starts.push(0);

    // Faces of A clipped by B.
    let mut s_a = Vector3::zeros();
    let mut s_flush = Vector3::zeros();
    for k in 0..s.a_faces.len() {
        let f = s.a_faces[k] as usize;
        let face = a.face(f);
        let nv = a.vertices().len();
        let Some(flush) = classify(
            face,
            &a.planes()[f].normal,
            &s.b_planes,
            &s.b_plane_ids,
            |v, j| {
                if matrix {
                    s.dist_a[j * nv + v as usize]
                } else {
                    s.b_planes[s.b_plane_ids[j] as usize].distance(&a.vertices()[v as usize])
                }
            },
            tol,
            false,
            &mut s.cutting,
        ) else {
            continue;
        };
        s.poly.clear();
        s.poly
            .extend(face.iter().map(|&v| a.vertices()[v as usize]));
        let first = s.cutting.first().copied();
        clip_face(
            &mut s.poly,
            &mut s.poly_tmp,
            &mut s.dist,
            first.filter(|_| matrix).map(|j| {
                let j = j as usize;
                face.iter().map(move |&v| j * nv + v as usize)
            }),
            &s.dist_a,
            &s.cutting,
            &s.b_planes,
            &s.b_plane_ids,
            region_planes.as_ref(),
        );
        if s.poly.len() >= 3 {
            if flush {
                s_flush += vector_area(&s.poly);
            } else {
                s_a += vector_area(&s.poly);
            }
            s.points.extend_from_slice(&s.poly);
            s.starts.push(s.points.len() as u32);
        }
    }

    // Faces of B clipped by A.
    let mut s_b = Vector3::zeros();
    for k in 0..s.b_faces.len() {
        let g = s.b_faces[k] as usize;
        let face = b.face(g);
        let nv = b.vertices().len();
        if classify(
            face,
            &s.b_planes[g].normal,
            a.planes(),
            &s.a_plane_ids,
            |v, j| {
                if matrix {
                    s.dist_b[j * nv + v as usize]
                } else {
                    a.planes()[s.a_plane_ids[j] as usize].distance(&s.b_points[v as usize])
                }
            },
            tol,
            true,
            &mut s.cutting,
        )
        .is_none()
        {
            continue;
        }
        s.poly.clear();
        s.poly.extend(face.iter().map(|&v| s.b_points[v as usize]));
        let first = s.cutting.first().copied();
        clip_face(
            &mut s.poly,
            &mut s.poly_tmp,
            &mut s.dist,
            first.filter(|_| matrix).map(|j| {
                let j = j as usize;
                face.iter().map(move |&v| j * nv + v as usize)
            }),
            &s.dist_b,
            &s.cutting,
            a.planes(),
            &s.a_plane_ids,
            region_planes.as_ref(),
        );
        if s.poly.len() >= 3 {
            s_b += vector_area(&s.poly);
            s.points.extend_from_slice(&s.poly);
            s.starts.push(s.points.len() as u32);
        }
    }

    // With flush pieces F left out of S_A: S_A + F + S_B = 0 on the closed surface,
    // and the area vector without F from either side is S_A = −(S_B + F).
    summarise(&s.points, &s.starts, s_a - s_b - s_flush, t)
}

/// Fills `dist` with one row per candidate plane (distances of every vertex), keeping
/// in `ids` the planes that cut the vertex set. Returns `false` if some plane has every
/// vertex outside: the shapes are separated.
fn distance_matrix(
    vertices: &[Point3<Real>],
    planes: &[Plane],
    candidates: &[u32],
    tol: Real,
    dist: &mut Vec<Real>,
    ids: &mut Vec<u32>,
) -> bool {
    dist.clear();
    ids.clear();
    for &g in candidates {
        let plane = planes[g as usize];
        let row = dist.len();
        let mut lo = Real::INFINITY;
        let mut hi = Real::NEG_INFINITY;
        for v in vertices {
            let d = plane.distance(v);
            lo = lo.min(d);
            hi = hi.max(d);
            dist.push(d);
        }
        if lo > tol {
            return false;
        }
        if hi < -tol {
            // Everything strictly inside this plane: it clips nothing, and no face of
            // the other shape lies in it.
            dist.truncate(row);
        } else {
            ids.push(g);
        }
    }
    true
}

/// Decides how the face `face` (normal `normal`) meets the other solid's planes
/// `planes[ids[j]]`, with `dist(v, j)` the distance of vertex `v` from plane `j`.
///
/// Returns `None` if the face lies wholly outside one plane, or (when
/// `drop_coplanar`) lies in a plane of equal orientation. Otherwise `cutting` holds the
/// positions `j` of the planes that cut it, in order, and the flag says whether the
/// face lies in a plane of equal orientation (is flush).
#[allow(clippy::too_many_arguments)]
fn classify(
    face: &[u32],
    normal: &Vector3<Real>,
    planes: &[Plane],
    ids: &[u32],
    dist: impl Fn(u32, usize) -> Real,
    tol: Real,
    drop_coplanar: bool,
    cutting: &mut Vec<u32>,
) -> Option<bool> {
    cutting.clear();
    let mut flush = false;
    for j in 0..ids.len() {
        let mut lo = Real::INFINITY;
        let mut hi = Real::NEG_INFINITY;
        for &v in face {
            let d = dist(v, j);
            lo = lo.min(d);
            hi = hi.max(d);
        }
        if hi <= tol {
            if lo >= -tol && planes[ids[j] as usize].normal.dot(normal) > 0.0 {
                if drop_coplanar {
                    return None;
                }
                flush = true;
            }
            continue;
        }
        if lo >= -tol {
            return None;
        }
        cutting.push(j as u32);
    }
    Some(flush)
}

/// Clips `poly` by the region box (if any) and then by the cutting planes. The first
/// cut may reuse precomputed distances (`first_rows` indexes `matrix`).
#[allow(clippy::too_many_arguments)]
fn clip_face(
    poly: &mut Vec<Point3<Real>>,
    tmp: &mut Vec<Point3<Real>>,
    dist: &mut Vec<Real>,
    first_rows: Option<impl Iterator<Item = usize>>,
    matrix: &[Real],
    cutting: &[u32],
    planes: &[Plane],
    ids: &[u32],
    region: Option<&[Plane; 6]>,
) {
    let mut rest = cutting;
    if let Some(rows) = first_rows {
        dist.clear();
        dist.extend(rows.map(|r| matrix[r]));
        clip_with_distances(poly, dist, tmp);
        std::mem::swap(poly, tmp);
        rest = &cutting[1..];
    }
    if let Some(box_planes) = region {
        for plane in box_planes {
            if poly.len() < 3 {
                return;
            }
            clip_by_plane(poly, plane, dist, tmp);
        }
    }
    for &j in rest {
        if poly.len() < 3 {
            return;
        }
        clip_by_plane(poly, &planes[ids[j as usize] as usize], dist, tmp);
    }
}

/// The six outward planes of the box `[lo, hi]`.
fn box_planes(lo: &Vector3<Real>, hi: &Vector3<Real>) -> [Plane; 6] {
    let e = |k: usize, s: Real| {
        let mut n = Vector3::zeros();
        n[k] = s;
        n
    };
    [
        Plane {
            normal: e(0, 1.0),
            offset: hi.x,
        },
        Plane {
            normal: e(0, -1.0),
            offset: -lo.x,
        },
        Plane {
            normal: e(1, 1.0),
            offset: hi.y,
        },
        Plane {
            normal: e(1, -1.0),
            offset: -lo.y,
        },
        Plane {
            normal: e(2, 1.0),
            offset: hi.z,
        },
        Plane {
            normal: e(2, -1.0),
            offset: -lo.z,
        },
    ]
}

/// Volume, centroid and extent of the closed polygon set; `twice_area` is `S_A − S_B`.
fn summarise(
    points: &[Point3<Real>],
    starts: &[u32],
    twice_area: Vector3<Real>,
    fallback_normal: Vector3<Real>,
) -> Option<OverlapGeometry> {
    if points.is_empty() {
        return None;
    }
    let origin = Point3::from(
        points
            .iter()
            .fold(Vector3::zeros(), |acc, p| acc + p.coords)
            / points.len() as Real,
    );
    let mut cone = ConeSums::new(origin);
    for w in starts.windows(2) {
        cone.add_polygon(&points[w[0] as usize..w[1] as usize]);
    }
    let volume = cone.volume();
    if !(volume > 0.0) {
        return None;
    }
    let area = 0.5 * twice_area.norm();
    // A shape inside another (or two coincident ones) has a vanishing area vector:
    // the overlap volume is stationary, and the normal is only a convention.
    let normal = if area > 0.0 {
        twice_area / (2.0 * area)
    } else if fallback_normal.norm_squared() > 0.0 {
        fallback_normal.normalize()
    } else {
        Vector3::x()
    };
    let (lo, hi) = points
        .iter()
        .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), p| {
            let h = normal.dot(&p.coords);
            (lo.min(h), hi.max(h))
        });
    Some(OverlapGeometry {
        volume,
        centroid: cone.centroid(),
        normal,
        area,
        depth: hi - lo,
    })
}
