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
//! Shapes of up to 64 faces (dodecahedra, prism pellets, most STL pellets) take a
//! bit-mask path: for every vertex one bit per plane of the other shape says
//! "outside"; the AND over a face's vertices rejects it, the OR lists the planes that
//! cut it, and the AND over all vertices detects a separating face plane.
//!
//! For larger meshes (icospheres of hundreds to tens of thousands of facets) only faces
//! whose bounding spheres meet the box `R` enclosing both bounding spheres take part,
//! after clipping to `R`. This is exact when the shapes intersect (B ∩ R is bounded by
//! the planes of the faces of B that meet R), which is checked with GJK first.

use std::cell::RefCell;

use nalgebra::{Point3, Vector3};

use super::gjk::{self, GjkResult};
use super::plane::PlaneSoa;
use super::polygon::{ConeSums, FixedPolygon, area_moment, clip_by_plane, vector_area};
use super::sphere::closest_point_on_triangle;
use super::{ConvexPolyhedron, Plane, Pose};
use crate::Real;

/// Shapes with at most this many faces each take the bit-mask path: one bit per
/// plane and vertex says "outside", and whole faces are accepted, rejected or given
/// their cutting planes by a few ANDs and ORs.
const MASK_MAX_FACES: usize = 64;

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
    /// Derivative of the volume with respect to rotating A about its centroid (A's
    /// frame): the elastic torque on A is `−U'(V)` times it. With the normal force
    /// along the area vector this makes the contact exactly conservative; a force
    /// applied at the volume centroid would not be.
    pub rotation_gradient_a: Vector3<Real>,
    /// Derivative of the volume with respect to rotating B about its centroid (A's
    /// frame).
    pub rotation_gradient_b: Vector3<Real>,
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
    soa: PlaneSoa,
    /// All planes of B (culled path).
    b_soa: PlaneSoa,
    /// Per face of A (B): the planes of B (A) it reaches.
    reach_a: Vec<u64>,
    reach_b: Vec<u64>,
    /// Per vertex of A: bit g set when outside B's plane g (and "on" bits).
    out_a: Vec<u64>,
    on_a: Vec<u64>,
    /// Per vertex of B: bit f set when outside A's plane f (and "on" bits).
    out_b: Vec<u64>,
    on_b: Vec<u64>,
    a_faces: Vec<u32>,
    b_faces: Vec<u32>,
    /// Bounding spheres of A's faces, and of B's faces in A's frame.
    a_spheres: Vec<(Point3<Real>, Real)>,
    b_spheres: Vec<(Point3<Real>, Real)>,
    /// Faces of the other shape near one face, and candidates sorted along an axis
    /// (culled path).
    local: Vec<u32>,
    sorted: Vec<(Real, u32)>,
    cutting: Vec<u32>,
    fixed: Box<FixedPolygon>,
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
    if t.norm() >= a.circumradius() + b.circumradius() {
        return None;
    }
    // A rotation matrix transforms points in half the work of a quaternion.
    let rot = b_in_a.rotation.to_rotation_matrix();
    s.b_points.clear();
    s.b_points.extend(
        b.vertices()
            .iter()
            .map(|p| Point3::from(rot * p.coords + t)),
    );
    s.b_planes.clear();
    s.b_planes.extend(b.planes().iter().map(|p| {
        let normal = rot * p.normal;
        Plane {
            normal,
            offset: p.offset + normal.dot(&t),
        }
    }));
    s.points.clear();
    s.starts.clear();
    s.starts.push(0);
    if a.face_count() <= MASK_MAX_FACES && b.face_count() <= MASK_MAX_FACES {
        overlap_masked(a, b, &t, s)
    } else {
        overlap_culled(a, b, b_in_a, s)
    }
}

/// Coplanarity tolerance on plane distances.
fn tolerance(a: &ConvexPolyhedron, b: &ConvexPolyhedron) -> Real {
    1e-12 * a.circumradius().max(b.circumradius())
}

/// Sets, per point, bit `k` of `out` when the point lies more than `tol` outside
/// plane `k`, and of `on` when it lies within `tol` of it.
fn plane_masks(
    points: &[Point3<Real>],
    planes: &PlaneSoa,
    tol: Real,
    out: &mut Vec<u64>,
    on: &mut Vec<u64>,
) {
    out.clear();
    on.clear();
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the CPU supports the features the function is compiled for.
        unsafe { plane_masks_avx2(points, planes, tol, out, on) };
        return;
    }
    plane_masks_scalar(points, planes, tol, out, on);
}

fn plane_masks_scalar(
    points: &[Point3<Real>],
    planes: &PlaneSoa,
    tol: Real,
    out: &mut Vec<u64>,
    on: &mut Vec<u64>,
) {
    for p in points {
        let (mut o, mut n) = (0u64, 0u64);
        for k in 0..planes.nx.len() {
            let d = planes.nx[k] * p.x + planes.ny[k] * p.y + planes.nz[k] * p.z - planes.offset[k];
            o |= ((d > tol) as u64) << k;
            n |= ((d.abs() <= tol) as u64) << k;
        }
        out.push(o);
        on.push(n);
    }
}

/// [`plane_masks_scalar`] four planes at a time, the masks read off the sign bits.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn plane_masks_avx2(
    points: &[Point3<Real>],
    planes: &PlaneSoa,
    tol: Real,
    out: &mut Vec<u64>,
    on: &mut Vec<u64>,
) {
    use std::arch::x86_64::*;
    let chunks = planes.nx.len() / 4;
    let tol_v = _mm256_set1_pd(tol);
    let neg_tol_v = _mm256_set1_pd(-tol);
    for p in points {
        let (px, py, pz) = (
            _mm256_set1_pd(p.x),
            _mm256_set1_pd(p.y),
            _mm256_set1_pd(p.z),
        );
        let (mut o, mut n) = (0u64, 0u64);
        for c in 0..chunks {
            // SAFETY: each array holds 4 * chunks values.
            let (nx, ny, nz, off) = unsafe {
                (
                    _mm256_loadu_pd(planes.nx.as_ptr().add(4 * c)),
                    _mm256_loadu_pd(planes.ny.as_ptr().add(4 * c)),
                    _mm256_loadu_pd(planes.nz.as_ptr().add(4 * c)),
                    _mm256_loadu_pd(planes.offset.as_ptr().add(4 * c)),
                )
            };
            let d = _mm256_fmadd_pd(
                nz,
                pz,
                _mm256_fmadd_pd(ny, py, _mm256_fmsub_pd(nx, px, off)),
            );
            let outside = _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_GT_OQ>(d, tol_v)) as u64;
            let on_plane = _mm256_movemask_pd(_mm256_and_pd(
                _mm256_cmp_pd::<_CMP_LE_OQ>(d, tol_v),
                _mm256_cmp_pd::<_CMP_GE_OQ>(d, neg_tol_v),
            )) as u64;
            o |= outside << (4 * c);
            n |= on_plane << (4 * c);
        }
        out.push(o);
        on.push(n);
    }
}

/// For every face of `shape`, the planes of the other shape (bits) that the face
/// reaches: has vertices on both sides of, or on.
fn faces_reaching_planes(shape: &ConvexPolyhedron, out: &[u64], on: &[u64], reach: &mut Vec<u64>) {
    reach.clear();
    for f in 0..shape.face_count() {
        let (mut any_out, mut any_in, mut any_on) = (0u64, 0u64, 0u64);
        for &v in shape.face(f) {
            let (o, n) = (out[v as usize], on[v as usize]);
            any_out |= o;
            any_in |= !(o | n);
            any_on |= n;
        }
        reach.push((any_out & any_in) | any_on);
    }
}

/// Bit `k` of the result is bit `bit` of `rows[k]`.
#[inline]
fn transposed_bit(rows: &[u64], bit: usize) -> u64 {
    rows.iter()
        .enumerate()
        .fold(0, |m, (k, &r)| m | ((r >> bit) & 1) << k)
}

/// Planes (bits) that the point set crosses (points strictly on both sides) or
/// touches from inside (points on it, none outside): only faces in such planes can
/// bound the intersection.
fn live_planes(out: &[u64], on: &[u64]) -> u64 {
    let (mut any_out, mut any_in, mut any_on) = (0u64, 0u64, 0u64);
    for (&o, &n) in out.iter().zip(on) {
        any_out |= o;
        any_in |= !(o | n);
        any_on |= n;
    }
    (any_out & any_in) | (any_on & !any_out)
}

/// The bit-mask path for shapes of at most 64 faces each.
fn overlap_masked(
    a: &ConvexPolyhedron,
    b: &ConvexPolyhedron,
    t: &Vector3<Real>,
    s: &mut OverlapScratch,
) -> Option<OverlapGeometry> {
    let tol = tolerance(a, b);
    s.soa.fill(&s.b_planes);
    plane_masks(a.vertices(), &s.soa, tol, &mut s.out_a, &mut s.on_a);
    // A plane of B with every vertex of A outside separates them.
    if s.out_a.iter().fold(u64::MAX, |m, &x| m & x) != 0 {
        return None;
    }
    plane_masks(&s.b_points, a.plane_soa(), tol, &mut s.out_b, &mut s.on_b);
    if s.out_b.iter().fold(u64::MAX, |m, &x| m & x) != 0 {
        return None;
    }
    // A face can only meet the other solid if that solid straddles its plane (or lies
    // in it).
    let live_a = live_planes(&s.out_b, &s.on_b);
    let live_b = live_planes(&s.out_a, &s.on_a);
    // Within the plane of a face f of A, B is bounded by the planes of those faces of
    // B that reach plane f (B meets plane f, as f is live): only they can cut f.
    faces_reaching_planes(b, &s.out_b, &s.on_b, &mut s.reach_b);
    faces_reaching_planes(a, &s.out_a, &s.on_a, &mut s.reach_a);

    // Faces of A clipped by B.
    let mut sums = SideSums::default();
    for f in bits(live_a) {
        let face = a.face(f);
        let Some((cut, coplanar)) = face_masks(face, &s.out_a, &s.on_a) else {
            continue;
        };
        let normal = a.planes()[f].normal;
        let flush = bits(coplanar).any(|g| s.b_planes[g].normal.dot(&normal) > 0.0);
        let cut = cut & transposed_bit(&s.reach_b, f);
        s.fixed.set(face.iter().map(|&v| a.vertices()[v as usize]));
        clip_by_mask(&mut s.fixed, cut, &s.b_planes);
        if !s.fixed.is_degenerate() {
            let area = vector_area(s.fixed.points());
            let moment = area_moment(s.fixed.points());
            if flush {
                sums.flush_area += area;
                sums.flush_moment += moment;
            } else {
                sums.area += area;
                sums.moment += moment;
            }
            s.points.extend_from_slice(s.fixed.points());
            s.starts.push(s.points.len() as u32);
        }
    }

    // Faces of B clipped by A; a face lying in a plane of A of equal orientation is
    // already covered by A's face.
    let mut sums_b = SideSums::default();
    for g in bits(live_b) {
        let face = b.face(g);
        let Some((cut, coplanar)) = face_masks(face, &s.out_b, &s.on_b) else {
            continue;
        };
        let normal = s.b_planes[g].normal;
        if bits(coplanar).any(|f| a.planes()[f].normal.dot(&normal) > 0.0) {
            continue;
        }
        let cut = cut & transposed_bit(&s.reach_a, g);
        s.fixed.set(face.iter().map(|&v| s.b_points[v as usize]));
        clip_by_mask(&mut s.fixed, cut, a.planes());
        if !s.fixed.is_degenerate() {
            sums_b.area += vector_area(s.fixed.points());
            sums_b.moment += area_moment(s.fixed.points());
            s.points.extend_from_slice(s.fixed.points());
            s.starts.push(s.points.len() as u32);
        }
    }
    summarise(&s.points, &s.starts, &sums, &sums_b, t)
}

/// Clips a face polygon by the planes in `cut`.
#[inline]
fn clip_by_mask(poly: &mut FixedPolygon, cut: u64, planes: &[Plane]) {
    for k in bits(cut) {
        poly.clip(&planes[k]);
        if poly.is_degenerate() {
            return;
        }
    }
}

/// For a face with vertex masks `out` and `on`: `None` when one plane has every vertex
/// outside; otherwise the planes that cut it and those it lies in.
#[inline]
fn face_masks(face: &[u32], out: &[u64], on: &[u64]) -> Option<(u64, u64)> {
    let (mut all_out, mut any_out, mut all_on) = (u64::MAX, 0u64, u64::MAX);
    for &v in face {
        let (o, n) = (out[v as usize], on[v as usize]);
        all_out &= o;
        any_out |= o;
        all_on &= n;
    }
    (all_out == 0).then_some((any_out, all_on))
}

/// Indices of the set bits of `mask`, lowest first.
#[inline]
fn bits(mut mask: u64) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (mask != 0).then(|| {
            let k = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            k
        })
    })
}

/// The culling path for large meshes.
fn overlap_culled(
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
        starts,
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
        starts,
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
    let sums = clip_faces_locally(side_a, side_b, &region, tol, false, &mut out);
    let sums_b = clip_faces_locally(side_b, side_a, &region, tol, true, &mut out);
    summarise(out.points, out.starts, &sums, &sums_b, &t)
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
    starts: &'a mut Vec<u32>,
}

/// Clips every candidate face of `own` by the other shape, locally: within the ball
/// `S_f` around face f, the other solid (if it meets `S_f ∩ R`) is bounded by the
/// planes of its faces that meet that ball, so only those cut f (besides R itself). The
/// sphere tests are conservative, so a non-empty piece is kept only if its centroid
/// lies in the other solid. Returns the sums over the pieces.
fn clip_faces_locally(
    own: LocalSide,
    other: LocalSide,
    region: &[Plane],
    tol: Real,
    drop_coplanar: bool,
    out: &mut LocalClipOutput,
) -> SideSums {
    let mut sums = SideSums::default();
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
        let piece = vector_area(out.poly);
        let moment = area_moment(out.poly);
        if flush {
            sums.flush_area += piece;
            sums.flush_moment += moment;
        } else {
            sums.area += piece;
            sums.moment += moment;
        }
        out.points.extend_from_slice(out.poly);
        out.starts.push(out.points.len() as u32);
    }
    sums
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

/// Vector areas and their moments (about A's origin) of one shape's clipped pieces.
#[derive(Clone, Copy, Debug, Default)]
struct SideSums {
    area: Vector3<Real>,
    moment: Vector3<Real>,
    /// Pieces lying flush against a face of the other shape (A's side only).
    flush_area: Vector3<Real>,
    flush_moment: Vector3<Real>,
}

/// Volume, centroid, extent and gradients of the closed polygon set. `t` is B's
/// centroid in A's frame.
///
/// Flush pieces F are left out of A's sums and counted with B's (as B's coincident,
/// dropped face): on the closed surface `S_A + F + S_B = 0`, and the area vector is
/// `S_A = −(S_B + F)` from either side.
fn summarise(
    points: &[Point3<Real>],
    starts: &[u32],
    a: &SideSums,
    b: &SideSums,
    t: &Vector3<Real>,
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
    let s_b = b.area + a.flush_area;
    let twice_area = a.area - s_b;
    let area = 0.5 * twice_area.norm();
    // A shape inside another (or two coincident ones) has a vanishing area vector: the
    // overlap volume is stationary, and the normal is only a convention.
    let normal = if area > 0.0 {
        twice_area / (2.0 * area)
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
        rotation_gradient_a: a.moment,
        rotation_gradient_b: b.moment + a.flush_moment - t.cross(&s_b),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The AVX2 plane test gives the same bits as the scalar one, also for points on
    /// and near the planes.
    #[test]
    fn vector_and_scalar_plane_masks_agree() {
        let d = crate::geometry::generators::dodecahedron(1.0).unwrap();
        let mut soa = PlaneSoa::default();
        soa.fill(d.planes());
        let tol = 1e-12;
        let mut points: Vec<Point3<Real>> = d.vertices().to_vec();
        for (k, v) in d.vertices().iter().enumerate() {
            let s = 1.0 + (k as Real - 10.0) * 1e-13;
            points.push(Point3::from(v.coords * s));
            points.push(Point3::from(v.coords * (0.5 + 0.1 * k as Real)));
        }
        let (mut o1, mut n1, mut o2, mut n2) = (vec![], vec![], vec![], vec![]);
        plane_masks_scalar(&points, &soa, tol, &mut o1, &mut n1);
        plane_masks(&points, &soa, tol, &mut o2, &mut n2);
        assert_eq!(o1, o2);
        assert_eq!(n1, n2);
        assert!(n1.iter().any(|&m| m != 0) && o1.iter().any(|&m| m != 0));
    }
}
