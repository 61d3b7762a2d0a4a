//! The culling path for large meshes: only faces near both bounding spheres take
//! part, each clipped by the planes of the other shape's faces near it (see the
//! module docs of [`super`]).

use nalgebra::{Point3, Vector3};

use super::{OverlapGeometry, OverlapScratch, Pieces, summarise, tolerance};
use crate::Real;
use crate::geometry::gjk::{self, GjkResult};
use crate::geometry::plane::PlaneSoa;
use crate::geometry::polygon::clip_by_plane;
use crate::geometry::sphere::closest_point_on_triangle;
use crate::geometry::{ConvexPolyhedron, Plane, Pose};

/// The culling path for large meshes.
pub(super) fn overlap_culled(
    a: &ConvexPolyhedron,
    b: &ConvexPolyhedron,
    b_in_a: &Pose,
    s: &mut OverlapScratch,
) -> Option<OverlapGeometry> {
    if !matches!(gjk::gjk(a, b, b_in_a, None), GjkResult::Intersecting) {
        return None;
    }
    let tol = tolerance(a, b);
    let t = b_in_a.translation.vector;
    let (ra, rb) = (a.circumradius(), b.circumradius());
    // The region R: the box around both bounding spheres, cut to the slab across the
    // line of centres that holds their lens (tight for shallow contacts).
    let lo = (-Vector3::repeat(ra)).sup(&(t - Vector3::repeat(rb)));
    let hi = Vector3::repeat(ra).inf(&(t + Vector3::repeat(rb)));
    let distance = t.norm();
    let mut region = box_planes(&lo, &hi).to_vec();
    if distance > 0.0 {
        let u = t / distance;
        region.push(Plane {
            normal: u,
            offset: ra.min(distance + rb),
        });
        region.push(Plane {
            normal: -u,
            offset: -(distance - rb).max(-ra),
        });
    }
    let touches_region = |c: &Point3<Real>, r: Real| region.iter().all(|p| p.distance(c) <= r);
    s.a_faces.clear();
    s.a_faces.extend((0..a.face_count() as u32).filter(|&f| {
        let (c, r) = a.face_spheres()[f as usize];
        touches_region(&c, r)
    }));
    s.b_faces.clear();
    s.b_spheres.clear();
    for g in 0..b.face_count() {
        let (c, r) = b.face_spheres()[g];
        let c = b_in_a.transform_point(&c);
        if touches_region(&c, r) {
            s.b_faces.push(g as u32);
        }
        s.b_spheres.push((c, r));
    }

    s.a_spheres.clear();
    s.a_spheres.extend_from_slice(a.face_spheres());
    s.b_soa.fill(&s.b_planes);
    let OverlapScratch {
        b_soa,
        b_points,
        b_planes,
        a_faces,
        b_faces,
        a_spheres,
        b_spheres,
        local,
        sorted,
        cutting,
        poly,
        poly_tmp,
        dist,
        points,
        ..
    } = s;
    let mut out = LocalClipOutput {
        local,
        sorted,
        cutting,
        poly,
        tmp: poly_tmp,
        dist,
        points,
    };
    let side_a = LocalSide {
        shape: a,
        points: a.vertices(),
        planes: a.planes(),
        spheres: a_spheres,
        ids: a_faces,
        soa: a.plane_soa(),
    };
    let side_b = LocalSide {
        shape: b,
        points: b_points,
        planes: b_planes,
        spheres: b_spheres,
        ids: b_faces,
        soa: b_soa,
    };
    let mut pieces = Pieces::default();
    clip_faces_locally(side_a, side_b, &region, tol, false, &mut out, &mut pieces);
    clip_faces_locally(side_b, side_a, &region, tol, true, &mut out, &mut pieces);
    summarise(out.points, &pieces, &t)
}

/// One shape as seen by the culled path, everything in A's frame.
#[derive(Clone, Copy)]
struct LocalSide<'a> {
    shape: &'a ConvexPolyhedron,
    points: &'a [Point3<Real>],
    planes: &'a [Plane],
    spheres: &'a [(Point3<Real>, Real)],
    /// Faces meeting the region R.
    ids: &'a [u32],
    /// All planes, for point-in-solid tests.
    soa: &'a PlaneSoa,
}

/// The coordinate axis along which `points` spread the most.
fn widest_axis(points: impl Iterator<Item = Point3<Real>>) -> usize {
    let (lo, hi) = points.fold(
        (
            Vector3::repeat(Real::INFINITY),
            Vector3::repeat(Real::NEG_INFINITY),
        ),
        |(lo, hi), p| (lo.inf(&p.coords), hi.sup(&p.coords)),
    );
    (hi - lo).imax()
}

/// Whether some face among `local` of `side` has a point in the ball and the region.
fn local_face_meets_ball(
    side: &LocalSide,
    local: &[u32],
    centre: Point3<Real>,
    radius: Real,
    region: &[Plane],
) -> bool {
    let r2 = radius * radius;
    local.iter().any(|&g| {
        let face = side.shape.face(g as usize);
        let p0 = side.points[face[0] as usize];
        (1..face.len() - 1).any(|k| {
            let tri = [
                p0,
                side.points[face[k] as usize],
                side.points[face[k + 1] as usize],
            ];
            let (q, _) = closest_point_on_triangle(&tri, &centre);
            (q - centre).norm_squared() <= r2 && region.iter().all(|p| p.distance(&q) <= 0.0)
        })
    })
}

/// Buffers the culled path writes to.
struct LocalClipOutput<'a> {
    local: &'a mut Vec<u32>,
    sorted: &'a mut Vec<(Real, u32)>,
    cutting: &'a mut Vec<u32>,
    poly: &'a mut Vec<Point3<Real>>,
    tmp: &'a mut Vec<Point3<Real>>,
    dist: &'a mut Vec<Real>,
    points: &'a mut Vec<Point3<Real>>,
}

/// Clips every candidate face of `own` by the other shape, locally: within the ball
/// `S_f` around face f, the other solid (if it meets `S_f ∩ R`) is bounded by the
/// planes of its faces that meet that ball, so only those cut f (besides R itself). The
/// sphere tests are conservative, so a non-empty piece is kept only if its centroid
/// lies in the other solid. `drop_coplanar` marks B's side; the pieces are added to
/// `pieces`.
fn clip_faces_locally(
    own: LocalSide,
    other: LocalSide,
    region: &[Plane],
    tol: Real,
    drop_coplanar: bool,
    out: &mut LocalClipOutput,
    pieces: &mut Pieces,
) {
    let inside_tol = 1e3 * tol;
    // The other side's faces sorted along the axis of their widest spread, so that
    // each face finds its neighbours in a window instead of a full scan.
    let axis = widest_axis(other.ids.iter().map(|&g| other.spheres[g as usize].0));
    out.sorted.clear();
    out.sorted.extend(
        other
            .ids
            .iter()
            .map(|&g| (other.spheres[g as usize].0[axis], g)),
    );
    out.sorted.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
    let r_max = other
        .ids
        .iter()
        .map(|&g| other.spheres[g as usize].1)
        .fold(0.0, Real::max);
    for &f in own.ids {
        let f = f as usize;
        let (centre, radius) = own.spheres[f];
        let lo = out
            .sorted
            .partition_point(|e| e.0 < centre[axis] - radius - r_max);
        let hi = out
            .sorted
            .partition_point(|e| e.0 <= centre[axis] + radius + r_max);
        out.local.clear();
        out.local
            .extend(out.sorted[lo..hi].iter().map(|e| e.1).filter(|&g| {
                let (c, r) = other.spheres[g as usize];
                (c - centre).norm_squared() <= (r + radius) * (r + radius)
            }));
        let face = own.shape.face(f);
        let face_points = face.iter().map(|&v| own.points[v as usize]);
        let Some(flush) = classify(
            face_points.clone(),
            (centre, radius),
            &own.planes[f].normal,
            other.planes,
            out.local,
            tol,
            drop_coplanar,
            out.cutting,
        ) else {
            continue;
        };
        out.poly.clear();
        out.poly.extend(face_points);
        for p in region {
            if p.distance(&centre) > -radius {
                clip_by_plane(out.poly, p, out.dist, out.tmp);
            }
        }
        for &j in out.cutting.iter() {
            if out.poly.len() < 3 {
                break;
            }
            let plane = other.planes[out.local[j as usize] as usize];
            clip_by_plane(out.poly, &plane, out.dist, out.tmp);
        }
        if out.poly.len() < 3 {
            continue;
        }
        // Exact unless the other solid misses the ball: a point of one of its local
        // faces inside the ball (and R) proves it does not; otherwise test the piece.
        if !local_face_meets_ball(&other, out.local, centre, radius, region) {
            let mean = out
                .poly
                .iter()
                .fold(Vector3::zeros(), |acc, p| acc + p.coords)
                / out.poly.len() as Real;
            if other.soa.max_distance(&Point3::from(mean)) > inside_tol {
                continue;
            }
        }
        let normal = own.planes[f].normal;
        pieces.add(out.poly, &normal, drop_coplanar, flush, out.points);
    }
}

/// Decides how a face (its points and normal) meets the other solid's candidate
/// planes `planes[ids[j]]`.
///
/// Returns `None` if the face lies wholly outside one plane, or (when
/// `drop_coplanar`) lies in a plane of equal orientation. Otherwise `cutting` holds the
/// positions `j` of the planes that cut it, and the flag says whether the face lies in
/// a plane of equal orientation (is flush).
#[allow(clippy::too_many_arguments)]
fn classify(
    points: impl Iterator<Item = Point3<Real>> + Clone,
    (centre, radius): (Point3<Real>, Real),
    normal: &Vector3<Real>,
    planes: &[Plane],
    ids: &[u32],
    tol: Real,
    drop_coplanar: bool,
    cutting: &mut Vec<u32>,
) -> Option<bool> {
    cutting.clear();
    let mut flush = false;
    for (j, &id) in ids.iter().enumerate() {
        let plane = planes[id as usize];
        // The face's bounding sphere decides most planes with one dot product.
        let dc = plane.distance(&centre);
        if dc < -radius - tol {
            continue;
        }
        if dc > radius + tol {
            return None;
        }
        let (lo, hi) = points
            .clone()
            .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), p| {
                let d = plane.distance(&p);
                (lo.min(d), hi.max(d))
            });
        if hi <= tol {
            if lo >= -tol && plane.normal.dot(normal) > 0.0 {
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

/// The six outward planes of the box `[lo, hi]`.
fn box_planes(lo: &Vector3<Real>, hi: &Vector3<Real>) -> [Plane; 6] {
    let plane = |k: usize, sign: Real, offset: Real| {
        let mut normal = Vector3::zeros();
        normal[k] = sign;
        Plane { normal, offset }
    };
    [
        plane(0, 1.0, hi.x),
        plane(0, -1.0, -lo.x),
        plane(1, 1.0, hi.y),
        plane(1, -1.0, -lo.y),
        plane(2, 1.0, hi.z),
        plane(2, -1.0, -lo.z),
    ]
}
