//! The bit-mask path for shapes of at most 64 faces and 128 vertices.
//!
//! For every plane of one shape, one bit per vertex of the other says whether the
//! vertex lies outside the plane, and one whether it lies on it (within the
//! coplanarity tolerance). Every decision about a face and a plane of the other shape
//! is then an AND of such a mask with the face's vertex set:
//!
//! - a plane with every vertex of the other shape outside separates the shapes;
//! - a face can only meet the other solid if that solid straddles the face's plane
//!   (or touches it from inside): the face is *live*;
//! - a face with every vertex outside one plane of the other solid misses it;
//! - a plane g with some of the face's vertices outside cuts the face, but within the
//!   face's plane f the other solid is bounded only by the planes of its faces that
//!   reach plane f (have vertices on both sides of it, or on it): clipping by the
//!   others would cut nothing that those do not, so they are skipped.
//!
//! The masks of one plane are computed four vertices at a time (AVX2 where the CPU
//! has it); the face decisions cost a few integer operations per face and plane.
//! They are made once into a [`FacePlan`], with the margin by which the closest
//! vertex–plane test missed its threshold, and carried out by [`overlap_planned`]:
//! a pair whose plan still holds skips straight to the clipping.

use std::ops::{BitAnd, BitOr, Not};

use nalgebra::{Point3, Vector3};

use super::{OverlapGeometry, OverlapScratch, Pieces, summarise, tolerance};
use crate::Real;
use crate::geometry::plane::PointSoa;
use crate::geometry::polygon::FixedPolygon;
use crate::geometry::{ConvexPolyhedron, Plane};

/// What of B, placed in A's frame, the clipping of `faces_a` (the first `of_a`
/// faces) and `faces_b` (the rest) reads: B's vertices (bits) and B's planes (bits).
pub(super) fn b_parts_used(
    b: &ConvexPolyhedron,
    faces: &[PlannedFace],
    of_a: usize,
) -> (u128, u64) {
    let (faces_a, faces_b) = faces.split_at(of_a);
    let planes = faces_a.iter().fold(0, |m, f| m | f.planes);
    faces_b.iter().fold((0, planes), |(v, p), f| {
        (v | b.face_vertex_masks()[f.face as usize], p | 1 << f.face)
    })
}

/// A face of one shape that bounds the intersection, with the planes of the other
/// shape to clip it by.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct PlannedFace {
    planes: u64,
    face: u8,
    /// The face lies in a plane of the other shape of equal orientation (A's faces
    /// only; such faces of B are left out, A's face covers them).
    flush: bool,
}

impl PlannedFace {
    /// The face's index in its shape.
    pub(super) fn face(&self) -> usize {
        self.face as usize
    }

    /// The other shape's planes (bits) that cut it.
    pub(super) fn planes(&self) -> u64 {
        self.planes
    }
}

/// Every discrete decision of the masked path at one relative pose: whether a plane
/// separates the shapes, and which faces of A, then of B, bound the intersection,
/// each with the planes that cut it.
#[derive(Clone, Debug, Default)]
pub(super) struct FacePlan {
    pub(super) separated: bool,
    /// Where `separated`: the separating plane the slack is of, a plane of B with
    /// `true` (A's vertices outside it) or of A.
    pub(super) separating: (bool, u8),
    /// Faces of A (the first `of_a`), then faces of B.
    pub(super) faces: Vec<PlannedFace>,
    pub(super) of_a: usize,
    /// The slack of the decisions (see [`Slack`]): while no vertex of either shape
    /// moves relative to the other's planes by as much as the test it enters missed
    /// its threshold by, every decision comes out the same.
    pub(super) slack: Slack,
}

/// How far the tests of a pose are from going the other way: the smallest miss
/// `margin` (metres), and the smallest miss per unit lever `per_lever` (metres per
/// radian), where a test's lever is the distance of its point from the pivot `c`.
///
/// If B moves relative to A so that its material point at `c` is displaced by `a`
/// and its orientation turns by `θ` (spectral norm of the change of rotation), a
/// point at lever `L` is displaced by at most `a + θ L`, and no test of miss `m ≥
/// margin` with `m / L ≥ per_lever` can change while `a / margin + θ / per_lever < 1`.
/// Tests near the contact have small misses but short levers, so this holds for far
/// larger turns than one bound with the longest lever would.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Slack {
    pub(super) margin: Real,
    pub(super) per_lever: Real,
}

impl Default for Slack {
    fn default() -> Self {
        Slack::NONE
    }
}

impl Slack {
    /// No test yet: nothing limits the motion.
    pub(super) const NONE: Slack = Slack {
        margin: Real::INFINITY,
        per_lever: Real::INFINITY,
    };

    /// Nothing kept: holds for no motion at all.
    pub(super) const SPENT: Slack = Slack {
        margin: 0.0,
        per_lever: 0.0,
    };

    /// Whether some motion keeps every test as it was.
    pub(super) fn is_kept(&self) -> bool {
        self.margin > 0.0 && self.per_lever > 0.0
    }

    /// The slack of both sets of tests.
    pub(super) fn min(self, other: Slack) -> Slack {
        Slack {
            margin: self.margin.min(other.margin),
            per_lever: self.per_lever.min(other.per_lever),
        }
    }

    /// Whether a displacement `a` at the pivot and a turn `turn` leave every test
    /// as it was.
    pub(super) fn holds(&self, a: Real, turn: Real) -> bool {
        self.is_kept() && a * self.per_lever + turn * self.margin < self.margin * self.per_lever
    }
}

/// Per point of `points`, the inverse of its distance from `pivot` (into `inverse`).
pub(super) fn inverse_levers(points: &PointSoa, pivot: &Point3<Real>, inverse: &mut Vec<Real>) {
    inverse.clear();
    inverse.extend((0..points.x.len()).map(|k| {
        let d = Vector3::new(points.x[k], points.y[k], points.z[k]) - pivot.coords;
        1.0 / d.norm().max(Real::MIN_POSITIVE)
    }));
}

/// Plans the overlap of `a` and `b` into `s.plan` (B's vertices and planes already in
/// A's frame in `s`; `t` is B's centroid in A's frame).
pub(super) fn plan_masked(
    a: &ConvexPolyhedron,
    b: &ConvexPolyhedron,
    t: &Vector3<Real>,
    s: &mut OverlapScratch,
) {
    s.b_point_soa.fill(&s.b_points);
    // Most shapes have at most 64 vertices: their sets take half the operations.
    if a.vertices().len() <= 64 && b.vertices().len() <= 64 {
        plan_with_sets::<u64>(a, b, t, s)
    } else {
        plan_with_sets::<u128>(a, b, t, s)
    }
}

/// [`plan_masked`] with vertex sets of type `M`.
fn plan_with_sets<M: VertexSet>(
    a: &ConvexPolyhedron,
    b: &ConvexPolyhedron,
    t: &Vector3<Real>,
    s: &mut OverlapScratch,
) {
    let tol = tolerance(a, b);
    // Planes that hold the other shape's bounding sphere wholly inside can neither
    // cut nor separate; about half of each shape's planes face away from the other.
    // The balls' centres, A's origin and `t`, both lie |t|/2 from the pivot t/2.
    let (reached_a, margin_a) =
        planes_reached(a.planes(), &Point3::from(*t), b.circumradius(), tol);
    let (reached_b, margin_b) =
        planes_reached(&s.b_planes, &Point3::origin(), a.circumradius(), tol);
    let ball_margin = margin_a.min(margin_b);
    let balls = Slack {
        margin: ball_margin,
        per_lever: ball_margin / (0.5 * t.norm()).max(Real::MIN_POSITIVE),
    };
    let pivot = Point3::from(0.5 * t);
    inverse_levers(a.vertex_soa(), &pivot, &mut s.inverse_lever_a);
    inverse_levers(&s.b_point_soa, &pivot, &mut s.inverse_lever_b);
    let (all_a, all_b) = (M::first(a.vertices().len()), M::first(b.vertices().len()));
    let (out_a, on_a) = (&mut s.out_a, &mut s.on_a);
    let masks_a = vertex_masks(
        a.vertex_soa(),
        &s.inverse_lever_a,
        &s.b_planes,
        reached_b,
        tol,
        all_a,
        out_a,
        on_a,
    );
    let (out_b, on_b) = (&mut s.out_b, &mut s.on_b);
    let masks_b = vertex_masks(
        &s.b_point_soa,
        &s.inverse_lever_b,
        a.planes(),
        reached_a,
        tol,
        all_b,
        out_b,
        on_b,
    );
    let plan = &mut s.plan;
    plan.faces.clear();
    plan.of_a = 0;
    let side_a = MaskedSide::<M>::new(a, a.planes(), reached_a, &s.out_a, &s.on_a);
    let side_b = MaskedSide::<M>::new(b, &s.b_planes, reached_b, &s.out_b, &s.on_b);
    plan.separated = side_a.separated() || side_b.separated();
    if plan.separated {
        // Separated is the one decision that matters: it stands while one separating
        // plane keeps the other shape's vertices outside, whatever the other tests do.
        let (of_b, plane_b) = separating_slack(
            a.vertex_soa(),
            &s.inverse_lever_a,
            &s.b_planes,
            &side_a,
            tol,
        );
        let (of_a, plane_a) =
            separating_slack(&s.b_point_soa, &s.inverse_lever_b, a.planes(), &side_b, tol);
        (plan.slack, plan.separating) = if of_a.margin >= of_b.margin {
            (of_a, (false, plane_a))
        } else {
            (of_b, (true, plane_b))
        };
        return;
    }
    plan.slack = balls.min(masks_a).min(masks_b);
    // Faces of A clipped by B; flush pieces are kept apart.
    for f in bits(reached_a) {
        if let Some(cut) = face_cut(&side_a, &side_b, f) {
            plan.faces.push(PlannedFace {
                planes: cut.planes,
                face: f as u8,
                flush: cut.flush,
            });
        }
    }
    plan.of_a = plan.faces.len();
    // Faces of B clipped by A; a face lying in a plane of A of equal orientation is
    // already covered by A's face.
    for g in bits(reached_b) {
        if let Some(cut) = face_cut(&side_b, &side_a, g).filter(|cut| !cut.flush) {
            plan.faces.push(PlannedFace {
                planes: cut.planes,
                face: g as u8,
                flush: false,
            });
        }
    }
}

/// The overlap by a plan: `faces_a` clipped by B's planes and `faces_b` by A's (B's
/// vertices and planes already in A's frame in `s`; `t` is B's centroid in A's
/// frame).
pub(super) fn overlap_planned(
    a: &ConvexPolyhedron,
    b: &ConvexPolyhedron,
    t: &Vector3<Real>,
    faces_a: &[PlannedFace],
    faces_b: &[PlannedFace],
    s: &mut OverlapScratch,
) -> Option<OverlapGeometry> {
    let mut pieces = Pieces::default();
    for planned in faces_a {
        let f = planned.face as usize;
        s.fixed
            .set(a.face(f).iter().map(|&v| a.vertices()[v as usize]));
        clip_by_planes(&mut s.fixed, planned.planes, &s.b_planes);
        if !s.fixed.is_degenerate() {
            let normal = a.planes()[f].normal;
            pieces.add(
                s.fixed.points(),
                &normal,
                false,
                planned.flush,
                &mut s.points,
            );
        }
    }
    for planned in faces_b {
        let g = planned.face as usize;
        s.fixed
            .set(b.face(g).iter().map(|&v| s.b_points[v as usize]));
        clip_by_planes(&mut s.fixed, planned.planes, a.planes());
        if !s.fixed.is_degenerate() {
            let normal = s.b_planes[g].normal;
            pieces.add(s.fixed.points(), &normal, true, false, &mut s.points);
        }
    }
    summarise(&s.points, &pieces, t)
}

/// A set of vertices, one bit each: `u64` for shapes of up to 64 vertices, `u128`
/// for up to 128.
trait VertexSet: Copy + Eq + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self> {
    const EMPTY: Self;
    /// Vertices `0..n`.
    fn first(n: usize) -> Self;
    /// The set of the vertices below the width of `Self` in `bits`.
    fn narrow(bits: u128) -> Self;
    fn widen(self) -> u128;
    /// The set shifted up by four vertices, with vertices 0..4 from `nibble`.
    fn shifted_in(self, nibble: i32) -> Self;
}

macro_rules! vertex_set {
    ($t:ty) => {
        impl VertexSet for $t {
            const EMPTY: Self = 0;
            fn first(n: usize) -> Self {
                if n >= <$t>::BITS as usize {
                    <$t>::MAX
                } else {
                    (1 << n) - 1
                }
            }
            #[inline]
            fn narrow(bits: u128) -> Self {
                bits as $t
            }
            #[inline]
            fn widen(self) -> u128 {
                self as u128
            }
            #[inline]
            fn shifted_in(self, nibble: i32) -> Self {
                (self << 4) | nibble as $t
            }
        }
    };
}
vertex_set!(u64);
vertex_set!(u128);

/// One shape as the other's planes see it.
struct MaskedSide<'a, M> {
    shape: &'a ConvexPolyhedron,
    /// Its face planes, in A's frame.
    planes: &'a [Plane],
    /// Its planes (bits) that the other shape's bounding sphere reaches: the others
    /// have every vertex of the other shape inside.
    reached: u64,
    /// Per plane of the *other* shape: this shape's vertices outside it, and on it
    /// (no bits beyond its vertices).
    out: &'a [u128],
    on: &'a [u128],
    /// All of this shape's vertices.
    all: M,
}

impl<'a, M: VertexSet> MaskedSide<'a, M> {
    fn new(
        shape: &'a ConvexPolyhedron,
        planes: &'a [Plane],
        reached: u64,
        out: &'a [u128],
        on: &'a [u128],
    ) -> Self {
        MaskedSide {
            shape,
            planes,
            reached,
            out,
            on,
            all: M::first(shape.vertices().len()),
        }
    }

    /// Whether one plane of the other shape has every vertex of this one outside.
    fn separated(&self) -> bool {
        self.out.iter().any(|&m| M::narrow(m) == self.all)
    }

    #[inline]
    fn out(&self, plane: usize) -> M {
        M::narrow(self.out[plane])
    }

    #[inline]
    fn on(&self, plane: usize) -> M {
        M::narrow(self.on[plane])
    }
}

/// How a face meets the other solid.
struct FaceCut {
    /// The other shape's planes to clip the face by.
    planes: u64,
    /// Whether the face lies in a plane of the other shape of equal orientation.
    flush: bool,
}

/// How face `f` of `own` meets `other`: `None` when it cannot bound the intersection.
#[inline(always)]
fn face_cut<M: VertexSet>(own: &MaskedSide<M>, other: &MaskedSide<M>, f: usize) -> Option<FaceCut> {
    let empty = M::EMPTY;
    // The other shape's vertices against this face's plane.
    let (out_f, on_f) = (other.out(f), other.on(f));
    let in_f = other.all & !(out_f | on_f);
    let straddles = out_f != empty && in_f != empty;
    let touches_from_inside = on_f != empty && out_f == empty;
    if !(straddles || touches_from_inside) {
        return None;
    }
    let face = M::narrow(own.shape.face_vertex_masks()[f]);
    let normal = own.planes[f].normal;
    let other_faces = other.shape.face_vertex_masks();
    let mut cut = FaceCut {
        planes: 0,
        flush: false,
    };
    for g in bits(other.reached) {
        let outside = face & own.out(g);
        if outside == face {
            return None;
        }
        if outside == empty {
            if face & own.on(g) == face && other.planes[g].normal.dot(&normal) > 0.0 {
                cut.flush = true;
            }
            continue;
        }
        // Face g of the other shape reaches plane f: vertices on both sides, or on it.
        let other_face = M::narrow(other_faces[g]);
        let reaches = (other_face & out_f != empty && other_face & in_f != empty)
            || other_face & on_f != empty;
        cut.planes |= (reaches as u64) << g;
    }
    Some(cut)
}

/// The slack of the separating plane of `planes` (those with every vertex of `side`
/// outside, `points` its vertices) whose tests miss by the most, and its index:
/// while that plane keeps every vertex more than `tol` outside, the shapes stay
/// separated. No plane separates: no slack (zero margin).
fn separating_slack<M: VertexSet>(
    points: &PointSoa,
    inverse_lever: &[Real],
    planes: &[Plane],
    side: &MaskedSide<M>,
    tol: Real,
) -> (Slack, u8) {
    let count = side.shape.vertices().len();
    let (mut best, mut best_plane) = (Slack::SPENT, 0);
    for (k, p) in planes.iter().enumerate() {
        if side.out(k) != side.all {
            continue;
        }
        let slack = (0..count).fold(Slack::NONE, |slack, v| {
            let d = p.normal.x * points.x[v] + p.normal.y * points.y[v] + p.normal.z * points.z[v]
                - p.offset;
            // Every vertex is outside: d > tol.
            let miss = d - tol;
            slack.min(Slack {
                margin: miss,
                per_lever: miss * inverse_lever[v],
            })
        });
        if slack.margin > best.margin {
            (best, best_plane) = (slack, k as u8);
        }
    }
    (best, best_plane)
}

/// The slack of plane `plane` separating the shapes at the pose (`rotation`, `t`) of
/// B in A, a plane of B with `of_b` (A's vertices outside it) or of A: as
/// [`separating_slack`] makes it, from the plane and the other shape's vertices
/// alone. `None` where some vertex is not more than `2 tol` outside it.
pub(super) fn separation_slack(
    a: &ConvexPolyhedron,
    b: &ConvexPolyhedron,
    rotation: &nalgebra::Matrix3<Real>,
    t: &Vector3<Real>,
    (of_b, plane): (bool, u8),
    tol: Real,
) -> Option<Slack> {
    let pivot = Point3::from(0.5 * t);
    let outside = |plane: &Plane, p: Point3<Real>| {
        let miss = plane.distance(&p) - tol;
        // More than twice the tolerance outside: the fresh plan's masks, whose
        // distances round otherwise, find every vertex outside too.
        (miss > tol).then(|| Slack {
            margin: miss,
            per_lever: miss / (p - pivot).norm().max(Real::MIN_POSITIVE),
        })
    };
    let mut slack = Slack::NONE;
    if of_b {
        let plane = super::plane_in_a(&b.planes()[plane as usize], rotation, t);
        for p in a.vertices() {
            slack = slack.min(outside(&plane, *p)?);
        }
    } else {
        let plane = &a.planes()[plane as usize];
        for p in b.vertices() {
            slack = slack.min(outside(plane, super::point_in_a(p, rotation, t))?);
        }
    }
    Some(slack)
}

/// Planes (bits) whose outside the ball (`centre`, `radius`) reaches to within `tol`,
/// and by how much the closest of the others missed it.
///
/// Only the planes left out need a margin: their vertex tests are skipped on the
/// strength of this one. A reached plane whose ball later falls short has every
/// vertex more than `tol` inside, so its masks are empty and every decision comes
/// out as if it had not been reached; its vertex tests are in the plan's slack.
fn planes_reached(planes: &[Plane], centre: &Point3<Real>, radius: Real, tol: Real) -> (u64, Real) {
    planes
        .iter()
        .enumerate()
        .fold((0, Real::INFINITY), |(m, margin), (k, p)| {
            let reach = p.distance(centre) + radius + tol;
            if reach >= 0.0 {
                (m | 1 << k, margin)
            } else {
                (m, margin.min(-reach))
            }
        })
}

/// Indices of the set bits of `mask`, lowest first.
#[inline]
pub(super) fn bits(mut mask: u64) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (mask != 0).then(|| {
            let k = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            k
        })
    })
}

/// Clips a face polygon by the planes (bits) `cut`.
#[inline]
fn clip_by_planes(poly: &mut FixedPolygon, cut: u64, planes: &[Plane]) {
    for k in bits(cut) {
        poly.clip(&planes[k]);
        if poly.is_degenerate() {
            return;
        }
    }
}

/// For each plane `k` in `active`, sets bit `v` of `out[k]` when point `v` lies more
/// than `tol` outside the plane, and of `on[k]` when it lies within `tol` of it; bits
/// outside `real` (the set of the real, unpadded points) are cleared, and so are the
/// masks of the planes not in `active`. Returns the slack of the tests: the smallest
/// miss `||d| − tol|` over the distances `d` tested (padding included), and the
/// smallest miss times the point's `inverse_lever`.
#[allow(clippy::too_many_arguments)]
fn vertex_masks<M: VertexSet>(
    points: &PointSoa,
    inverse_lever: &[Real],
    planes: &[Plane],
    active: u64,
    tol: Real,
    real: M,
    out: &mut Vec<u128>,
    on: &mut Vec<u128>,
) -> Slack {
    out.clear();
    on.clear();
    out.resize(planes.len(), 0);
    on.resize(planes.len(), 0);
    #[cfg(target_arch = "x86_64")]
    let slack = if std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("fma")
    {
        // SAFETY: the CPU supports the features the function is compiled for.
        unsafe { vertex_masks_avx2::<M>(points, inverse_lever, planes, active, tol, out, on) }
    } else {
        vertex_masks_scalar(points, inverse_lever, planes, active, tol, out, on)
    };
    #[cfg(not(target_arch = "x86_64"))]
    let slack = vertex_masks_scalar(points, inverse_lever, planes, active, tol, out, on);
    let real = real.widen();
    for m in out.iter_mut().chain(on.iter_mut()) {
        *m &= real;
    }
    slack
}

fn vertex_masks_scalar(
    points: &PointSoa,
    inverse_lever: &[Real],
    planes: &[Plane],
    active: u64,
    tol: Real,
    out: &mut [u128],
    on: &mut [u128],
) -> Slack {
    let mut slack = Slack::NONE;
    for k in bits(active) {
        let p = &planes[k];
        let (mut o, mut n) = (0u128, 0u128);
        for (v, inverse) in inverse_lever.iter().enumerate() {
            let d = p.normal.x * points.x[v] + p.normal.y * points.y[v] + p.normal.z * points.z[v]
                - p.offset;
            o |= ((d > tol) as u128) << v;
            n |= ((d <= tol && d >= -tol) as u128) << v;
            let miss = (d.abs() - tol).abs();
            slack = slack.min(Slack {
                margin: miss,
                per_lever: miss * inverse,
            });
        }
        out[k] = o;
        on[k] = n;
    }
    slack
}

/// [`vertex_masks_scalar`] four points at a time, the masks read off the sign bits.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn vertex_masks_avx2<M: VertexSet>(
    points: &PointSoa,
    inverse_lever: &[Real],
    planes: &[Plane],
    active: u64,
    tol: Real,
    out: &mut [u128],
    on: &mut [u128],
) -> Slack {
    use std::arch::x86_64::*;
    let chunks = points.x.len() / 4;
    let tol_v = _mm256_set1_pd(tol);
    let neg_tol_v = _mm256_set1_pd(-tol);
    let sign = _mm256_set1_pd(-0.0);
    let mut margin = _mm256_set1_pd(Real::INFINITY);
    let mut per_lever = _mm256_set1_pd(Real::INFINITY);
    for k in bits(active) {
        let p = &planes[k];
        let (nx, ny, nz, off) = (
            _mm256_set1_pd(p.normal.x),
            _mm256_set1_pd(p.normal.y),
            _mm256_set1_pd(p.normal.z),
            _mm256_set1_pd(p.offset),
        );
        // Chunks from the last, each shifted in below the ones before.
        let (mut o, mut n) = (M::EMPTY, M::EMPTY);
        for c in (0..chunks).rev() {
            // SAFETY: each array holds 4 * chunks values.
            let (x, y, z, inverse) = unsafe {
                (
                    _mm256_loadu_pd(points.x.as_ptr().add(4 * c)),
                    _mm256_loadu_pd(points.y.as_ptr().add(4 * c)),
                    _mm256_loadu_pd(points.z.as_ptr().add(4 * c)),
                    _mm256_loadu_pd(inverse_lever.as_ptr().add(4 * c)),
                )
            };
            let d = _mm256_fmadd_pd(nz, z, _mm256_fmadd_pd(ny, y, _mm256_fmsub_pd(nx, x, off)));
            let outside = _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_GT_OQ>(d, tol_v));
            let on_plane = _mm256_movemask_pd(_mm256_and_pd(
                _mm256_cmp_pd::<_CMP_LE_OQ>(d, tol_v),
                _mm256_cmp_pd::<_CMP_GE_OQ>(d, neg_tol_v),
            ));
            o = o.shifted_in(outside);
            n = n.shifted_in(on_plane);
            let miss = _mm256_sub_pd(_mm256_andnot_pd(sign, d), tol_v);
            let miss = _mm256_andnot_pd(sign, miss);
            margin = _mm256_min_pd(margin, miss);
            per_lever = _mm256_min_pd(per_lever, _mm256_mul_pd(miss, inverse));
        }
        out[k] = o.widen();
        on[k] = n.widen();
    }
    let lowest = |v: __m256d| {
        let mut lanes = [0.0; 4];
        // SAFETY: `lanes` holds four values.
        unsafe { _mm256_storeu_pd(lanes.as_mut_ptr(), v) };
        lanes.into_iter().fold(Real::INFINITY, Real::min)
    };
    Slack {
        margin: lowest(margin),
        per_lever: lowest(per_lever),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The AVX2 plane test gives the same bits as the scalar one, also for points on
    /// and near the planes.
    #[test]
    fn vector_and_scalar_vertex_masks_agree() {
        let d = crate::geometry::generators::dodecahedron(1.0).unwrap();
        let tol = 1e-12;
        let mut points: Vec<Point3<Real>> = d.vertices().to_vec();
        for (k, v) in d.vertices().iter().enumerate() {
            let s = 1.0 + (k as Real - 10.0) * 1e-13;
            points.push(Point3::from(v.coords * s));
            points.push(Point3::from(v.coords * (0.5 + 0.1 * k as Real)));
        }
        points.truncate(128);
        let mut soa = PointSoa::default();
        soa.fill(&points);
        let n = d.planes().len();
        let (mut o1, mut n1) = (vec![0; n], vec![0; n]);
        let (mut o2, mut n2) = (vec![], vec![]);
        let every = u64::first(n);
        let mut inverse = Vec::new();
        inverse_levers(&soa, &Point3::new(0.3, -0.2, 0.1), &mut inverse);
        let s1 = vertex_masks_scalar(&soa, &inverse, d.planes(), every, tol, &mut o1, &mut n1);
        let all = u128::first(points.len());
        let s2 = vertex_masks(
            &soa,
            &inverse,
            d.planes(),
            every,
            tol,
            all,
            &mut o2,
            &mut n2,
        );
        // The vector path fuses multiply–adds: the misses agree to round-off.
        assert!((s1.margin - s2.margin).abs() < 1e-15);
        assert!((s1.per_lever / s2.per_lever - 1.0).abs() < 1e-3);
        assert!(s1.margin < 1e-12 && s1.per_lever > 0.0);
        let o1: Vec<u128> = o1.iter().map(|m| m & all).collect();
        let n1: Vec<u128> = n1.iter().map(|m| m & all).collect();
        assert_eq!(o1, o2);
        assert_eq!(n1, n2);
        assert!(n1.iter().any(|&m| m != 0) && o1.iter().any(|&m| m != 0));
    }
}
