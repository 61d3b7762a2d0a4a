//! Exact overlap of two convex polyhedra: volume, centroid, contact normal and
//! contact area.
//!
//! # Method: face clipping and the divergence theorem
//!
//! The boundary of the intersection `A ∩ B` consists of the pieces `f ∩ B` of the
//! faces `f` of A and the pieces `g ∩ A` of the faces `g` of B. Each piece is a convex
//! polygon, obtained by clipping one face polygon against the other solid's planes
//! (Sutherland–Hodgman in 3-D). The closed set of polygons is enough for
//!
//! - the volume and centroid (a fan of tetrahedra from a point near the overlap);
//! - the contact-area vector `S = Σ_{f ∈ A} n_f |f ∩ B|`, which is exactly the gradient
//!   of the overlap volume with respect to the translation of B relative to A. A
//!   normal force along `S` therefore derives from a potential of the overlap volume
//!   (Feng's energy-conserving framework), and `|S|` is the projected contact area.
//!
//! We chose this over the dual-space incremental quickhull of Xu et al.,
//! "Large-Scale Multiple-GPU-based DEM Simulation of Polyhedral Particle Systems",
//! because it needs no point strictly inside the intersection (the polar dual does, and finding
//! one for a tiny overlap is itself a linear program), builds its combinatorial state
//! from sign tests alone rather than maintaining it through round-off (a hull's
//! horizon can be corrupted), allocates nothing per pair (the scratch buffers are
//! reused), and parallelises as a flat loop over faces. The cost is dominated by one
//! matrix of vertex–plane distances per side, and most faces are rejected from that
//! matrix alone.
//!
//! Coplanar faces of equal orientation (identical shapes at the same pose, boxes of a
//! lattice lying flush) would be counted twice; the piece from B is dropped in that
//! case, since A's face already covers it. The volume is not differentiable there;
//! such flush pieces are left out of the contact-area vector, which picks the
//! subgradient with no component along their normal (flush neighbours in a lattice
//! feel no sideways push).
//!
//! Shapes of up to 64 faces (dodecahedra, prism pellets, most STL pellets) take a
//! bit-mask path ([`masked`]): for every plane of one shape, one bit per vertex of the
//! other says "outside" (and one says "on"); a few ANDs of these with each face's
//! vertex set then reject the face, list the planes that cut it, and detect a
//! separating face plane.
//!
//! The bit-mask path separates deciding (which faces bound the intersection, and
//! which planes cut each) from clipping, and the clipping from evaluating: a
//! labelled clipping records what every vertex of `A ∩ B` lies on (a vertex of one
//! shape, or an edge of one shape cut by a plane of the other) and the loop of
//! vertices of each face, its [`topology`]; the geometry is then evaluated from it,
//! each vertex by one edge cut. A pair evaluated step after step keeps these
//! decisions in an [`OverlapCache`] with how far the closest test was from going the
//! other way (the plan's vertex–plane tests; for a topology, only the tests of its
//! own vertices against the other planes); until the pair has moved that far, they
//! cannot change, and only the evaluation is done again ([`overlap_cached`]), with
//! the same answer bit for bit. Beyond that, a topology is tested again before it is
//! read afresh. Touching configurations (a vertex of the intersection within the
//! tolerance of another plane, flush faces) have no topology and keep the plan,
//! whose faces are clipped again each step.
//!
//! For larger meshes (icospheres of hundreds to tens of thousands of facets) only faces
//! whose bounding spheres meet the box `R` enclosing both bounding spheres take part,
//! after clipping to `R`. This is exact when the shapes intersect (B ∩ R is bounded by
//! the planes of the faces of B that meet R), which is checked with GJK first
//! ([`culled`]).

mod culled;
mod masked;
mod topology;

use std::cell::RefCell;

use nalgebra::{Matrix3, Point3, Vector3};

use super::plane::{PlaneSoa, PointSoa};
use super::polygon::{FixedPolygon, SurfaceSums};
use super::{ConvexPolyhedron, Plane, Pose};
use crate::Real;
use topology::Topology;

/// Shapes with at most this many faces (cut-plane sets are `u64` masks) and vertices
/// (vertex sets are `u128` masks) each take the bit-mask path. A convex polyhedron of
/// at most 64 faces has at most 124 vertices, unless its face loops carry vertices
/// in the middle of straight edges.
const MASK_MAX_FACES: usize = 64;
const MASK_MAX_VERTICES: usize = 128;

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
    /// B's vertices in A's frame, in structure-of-arrays form (masked path).
    b_point_soa: PointSoa,
    /// All planes of B (culled path).
    b_soa: PlaneSoa,
    /// Per plane g of B: bit v set when vertex v of A is outside it (and "on" bits).
    out_a: Vec<u128>,
    on_a: Vec<u128>,
    /// Per plane f of A: bit w set when vertex w of B is outside it (and "on" bits).
    out_b: Vec<u128>,
    on_b: Vec<u128>,
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
    /// The decisions of the masked path at the current pose.
    plan: masked::FacePlan,
    poly: Vec<Point3<Real>>,
    poly_tmp: Vec<Point3<Real>>,
    dist: Vec<Real>,
    points: Vec<Point3<Real>>,
    /// Per vertex of A, and of B, the inverse distance from the plan's pivot.
    inverse_lever_a: Vec<Real>,
    inverse_lever_b: Vec<Real>,
    /// The labelled clipping's double buffer, and edges of B near A (topology).
    labelled: [Vec<topology::LabelledVertex>; 2],
    labelled_distances: Vec<Real>,
    near_edges: Vec<topology::NearEdge>,
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
    let rotation = b_in_a.rotation.to_rotation_matrix().into_inner();
    place_b(b, &rotation, &t, s);
    if maskable(a) && maskable(b) {
        masked::plan_masked(a, b, &t, s);
        let topology = topology_of_plan(a, b, &t, s);
        overlap_by_plan(a, b, &t, topology.as_ref().map(|(topology, _)| topology), s)
    } else {
        culled::overlap_culled(a, b, b_in_a, s)
    }
}

/// What the overlap of one pair decided at some pose, kept between steps: the faces
/// that bound the intersection and the planes that cut each, and how far the pair
/// may move from that pose before any of these decisions could change.
///
/// # Invariant
/// While the vertices of each shape have moved relative to the other's planes by
/// less than the slack allows since `rotation`/`translation`, every test the kept
/// decisions rest on comes out as it did there: for a plan, every vertex–plane and
/// ball–plane test of the bit-mask path, so it *is* the plan of the current pose;
/// for a topology, its vertices' tests against the other planes (its validity), so
/// it is the topology of the current pose (an empty one keeps the plan's tests and
/// the distances of the edges that could meet). [`overlap_cached`] then answers bit
/// for bit what [`overlap`] answers, skipping only the tests. Shapes beyond the
/// bit-mask path, and plans of more faces than fit, are not kept.
///
/// The cache of every candidate pair is read each step, most of them apart: what a
/// pair apart reads (the fields up to `decisions`' tag, 176 bytes) comes first and
/// fills the first three cache lines, hence `repr(C)` and the alignment.
#[derive(Clone, Debug)]
#[repr(C, align(64))]
pub struct OverlapCache {
    /// The two shapes the plan is for (addresses): a pair whose particles were
    /// replaced under the same list slot never uses another pair's plan.
    shapes: (usize, usize),
    /// The two shapes' figures the answer needs before the kept decisions, so that a
    /// pair the cache answers reads neither shape while it stays apart.
    figures: PairFigures,
    /// How far the pair may move (see [`masked::Slack`]); [`masked::Slack::SPENT`]:
    /// nothing kept.
    slack: masked::Slack,
    translation: Vector3<Real>,
    /// The point of B (B's frame) that lay midway between the centroids, the pivot of
    /// `slack`.
    pivot_in_b: Vector3<Real>,
    rotation: Matrix3<Real>,
    decisions: Kept,
    /// B's vertices and planes (bits) that clipping by the plan, or evaluating the
    /// topology, reads: only these are placed in A's frame while the plan holds.
    b_vertices: u128,
    b_planes: u64,
}

// A pair apart reads three cache lines.
const _: () = assert!(OverlapCache::HOT_BYTES <= 3 * 64);

/// What an [`OverlapCache`] keeps of a pose's decisions. One of them only: the cache
/// of every candidate pair is read each step, and its size is memory traffic.
#[derive(Clone, Debug)]
#[repr(u8)]
enum Kept {
    /// A face plane separates the shapes: a plane of B with `plane.0` (A's vertices
    /// outside it) or of A, by index.
    Separated { plane: (bool, u8) },
    /// The intersection's topology: while it holds (the slack is that of its
    /// vertices' tests, see [`Topology::validate`]) it is evaluated instead of
    /// clipping.
    Topology(Topology),
    /// The faces of A (the first `of_a`), then of B, to clip, and the planes to clip
    /// each by: for touching configurations, which have no topology.
    Plan {
        faces: [masked::PlannedFace; CACHED_FACES],
        of_a: u8,
        len: u8,
    },
}

/// Most planned faces (of both shapes together) an [`OverlapCache`] keeps: a shallow
/// contact of dodecahedra has about five.
const CACHED_FACES: usize = 12;

impl Default for OverlapCache {
    fn default() -> Self {
        OverlapCache {
            shapes: (0, 0),
            rotation: Matrix3::identity(),
            translation: Vector3::zeros(),
            pivot_in_b: Vector3::zeros(),
            slack: masked::Slack::SPENT,
            figures: PairFigures::default(),
            b_vertices: 0,
            b_planes: 0,
            decisions: Kept::Separated { plane: (false, 0) },
        }
    }
}

/// What the cached overlap of two shapes needs of them besides the kept decisions.
#[derive(Clone, Copy, Debug, Default)]
struct PairFigures {
    /// The sum of the circumradii: centroids this far apart do not overlap.
    reach: Real,
    /// The coplanarity tolerance ([`tolerance`]).
    tolerance: Real,
}

impl PairFigures {
    fn of(a: &ConvexPolyhedron, b: &ConvexPolyhedron) -> Self {
        PairFigures {
            reach: a.circumradius() + b.circumradius(),
            tolerance: tolerance(a, b),
        }
    }
}

impl OverlapCache {
    /// The bytes at the start of a cache that a pair apart reads: up to the tag of
    /// `decisions`.
    pub const HOT_BYTES: usize = std::mem::offset_of!(OverlapCache, decisions) + 1;

    /// Whether the cache keeps a contact's decisions (a topology or a plan, beyond the
    /// hot bytes), which the pair's next evaluation reads unless it moved too far:
    /// a pair kept apart reads only [`Self::HOT_BYTES`].
    #[inline]
    pub fn keeps_contact(&self) -> bool {
        self.slack.is_kept() && !matches!(self.decisions, Kept::Separated { .. })
    }

    /// The figures of the pair, where decisions are kept for these `shapes`.
    fn kept_for(&self, shapes: (usize, usize)) -> Option<PairFigures> {
        (self.slack.is_kept() && self.shapes == shapes).then_some(self.figures)
    }

    /// Whether the kept decisions still hold at the pose (`rotation`, `translation`)
    /// of B in A (decisions kept for the pair's shapes: [`Self::kept_for`]).
    ///
    /// The relative motion since the kept pose moves B's material point at the pivot
    /// `c` (midway between the centroids then) by `a`, and any other by at most `a +
    /// ‖ΔR‖ L`, `L` its distance from `c` at the kept pose; this bounds how far the
    /// vertices of either shape have moved relative to the other's planes, and B's
    /// edges relative to A's. For rotations the spectral norm `‖ΔR‖` is the
    /// Frobenius norm over √2. The tolerance is added to `a` for the round-off of
    /// the distances at the new pose. A plane–normal sign test between flush faces
    /// (the only other decision) cannot flip without a turn of order one radian, far
    /// beyond any slack.
    fn holds(&self, rotation: &Matrix3<Real>, translation: &Vector3<Real>) -> bool {
        let slack = self.slack;
        let tol = self.figures.tolerance;
        let turn = (rotation - self.rotation).norm() * std::f64::consts::FRAC_1_SQRT_2;
        let pivot = 0.5 * self.translation;
        let a = (rotation * self.pivot_in_b + translation - pivot).norm();
        slack.holds(a + tol, turn)
    }

    /// Keeps the plan in `s`, and the topology `topology` read off it, for the pose
    /// (`rotation`, `translation`), if it fits.
    #[allow(clippy::too_many_arguments)]
    fn keep(
        &mut self,
        a: &ConvexPolyhedron,
        b: &ConvexPolyhedron,
        shapes: (usize, usize),
        topology: Option<&(Topology, masked::Slack)>,
        rotation: Matrix3<Real>,
        translation: Vector3<Real>,
        s: &mut OverlapScratch,
    ) {
        self.slack = masked::Slack::SPENT;
        let plan = &s.plan;
        if plan.faces.len() > CACHED_FACES && topology.is_none() {
            return;
        }
        self.shapes = shapes;
        self.figures = PairFigures::of(a, b);
        let mut slack = plan.slack;
        (self.b_vertices, self.b_planes) = (0, 0);
        self.decisions = match topology {
            _ if plan.separated => Kept::Separated {
                plane: plan.separating,
            },
            // A topology needs none of the plan's tests, only its own vertices'.
            Some((topology, valid)) => {
                (self.b_vertices, self.b_planes) = topology.b_parts_used();
                slack = *valid;
                Kept::Topology(topology.clone())
            }
            None => {
                let mut faces = [masked::PlannedFace::default(); CACHED_FACES];
                faces[..plan.faces.len()].copy_from_slice(&plan.faces);
                (self.b_vertices, self.b_planes) = masked::b_parts_used(b, &plan.faces, plan.of_a);
                Kept::Plan {
                    faces,
                    of_a: plan.of_a as u8,
                    len: plan.faces.len() as u8,
                }
            }
        };
        self.moved_to(rotation, translation, slack);
    }

    /// Keeps the decisions for the pose (`rotation`, `translation`) with `slack`.
    fn moved_to(
        &mut self,
        rotation: Matrix3<Real>,
        translation: Vector3<Real>,
        slack: masked::Slack,
    ) {
        self.rotation = rotation;
        self.translation = translation;
        // The pivot, t/2, as a point of B.
        self.pivot_in_b = rotation.transpose() * (-0.5 * translation);
        self.slack = slack;
    }

    /// Where the slack of a kept topology or separation has run out: tests it at the
    /// pose (`rotation`, `t`) of B in A and, if it still holds, keeps it from this
    /// pose and answers by it. Most renewals of a topology find the same one (two
    /// pellets in a bed rock about their contact), and this test reads none of the
    /// plan's; a separating plane is tested against the other shape's vertices
    /// alone, and a fresh overlap then finds the pair apart too.
    fn revalidate(
        &mut self,
        a: &ConvexPolyhedron,
        b: &ConvexPolyhedron,
        rotation: &Matrix3<Real>,
        t: &Vector3<Real>,
        s: &mut OverlapScratch,
    ) -> Option<Option<OverlapGeometry>> {
        let topology = match &self.decisions {
            Kept::Topology(topology) => topology,
            Kept::Separated { plane } => {
                let tol = self.figures.tolerance;
                let slack = masked::separation_slack(a, b, rotation, t, *plane, tol)?;
                self.moved_to(*rotation, *t, slack);
                return Some(None);
            }
            Kept::Plan { .. } => return None,
        };
        let every_plane = u64::MAX >> (64 - b.face_count());
        place_b_parts(b, rotation, t, self.b_vertices, every_plane, s);
        let slack = topology.validate(a, t, self.figures.tolerance, s)?;
        let answer = topology.evaluate(a, t, s);
        self.moved_to(*rotation, *t, slack);
        Some(answer)
    }
}

/// [`overlap`] for a pair whose overlap is evaluated step after step: the plan of
/// `cache` is used while it holds (see [`OverlapCache`]) and renewed when it does
/// not. Bit for bit the answer of [`overlap`].
pub fn overlap_cached(
    a: &ConvexPolyhedron,
    b: &ConvexPolyhedron,
    b_in_a: &Pose,
    cache: &mut OverlapCache,
) -> Option<OverlapGeometry> {
    SCRATCH.with(|s| overlap_cached_with(a, b, b_in_a, cache, &mut s.borrow_mut()))
}

/// [`overlap_cached`] with caller-owned scratch buffers.
pub fn overlap_cached_with(
    a: &ConvexPolyhedron,
    b: &ConvexPolyhedron,
    b_in_a: &Pose,
    cache: &mut OverlapCache,
    s: &mut OverlapScratch,
) -> Option<OverlapGeometry> {
    let shapes = (std::ptr::from_ref(a).addr(), std::ptr::from_ref(b).addr());
    // A cache kept for these shapes knows their figures (and that both take the
    // bit-mask path): a pair it answers apart reads neither shape.
    let kept = cache.kept_for(shapes);
    let figures = match kept {
        Some(figures) => figures,
        None if maskable(a) && maskable(b) => PairFigures::of(a, b),
        None => return overlap_with(a, b, b_in_a, s),
    };
    let t = b_in_a.translation.vector;
    if t.norm() >= figures.reach {
        return None;
    }
    let rotation = b_in_a.rotation.to_rotation_matrix().into_inner();
    if kept.is_some() && cache.holds(&rotation, &t) {
        // A kept separation needs not even B's vertices.
        if let Kept::Separated { .. } = cache.decisions {
            return None;
        }
        place_b_parts(b, &rotation, &t, cache.b_vertices, cache.b_planes, s);
        return match &cache.decisions {
            Kept::Separated { .. } => None,
            Kept::Topology(topology) => topology.evaluate(a, &t, s),
            Kept::Plan { faces, of_a, len } => {
                let (of_a, len) = (*of_a as usize, *len as usize);
                masked::overlap_planned(a, b, &t, &faces[..of_a], &faces[of_a..len], s)
            }
        };
    }
    if kept.is_some()
        && let Some(answer) = cache.revalidate(a, b, &rotation, &t, s)
    {
        return answer;
    }
    place_b(b, &rotation, &t, s);
    masked::plan_masked(a, b, &t, s);
    let topology = topology_of_plan(a, b, &t, s);
    cache.keep(a, b, shapes, topology.as_ref(), rotation, t, s);
    let topology = topology.as_ref().map(|(topology, _)| topology);
    overlap_by_plan(a, b, &t, topology, s)
}

/// The topology of the intersection by the plan in `s`, where it has one, with the
/// slack within which it stays the current one (all of B in A's frame in `s`; `t` is
/// B's centroid in A's frame).
fn topology_of_plan(
    a: &ConvexPolyhedron,
    b: &ConvexPolyhedron,
    t: &Vector3<Real>,
    s: &mut OverlapScratch,
) -> Option<(Topology, masked::Slack)> {
    if s.plan.separated {
        return None;
    }
    let plan = std::mem::take(&mut s.plan);
    let topology = Topology::read(a, b, &plan, s);
    s.plan = plan;
    let topology = topology?;
    let slack = if topology.is_empty() {
        // No vertex to test: the intersection stays empty while no vertex crosses a
        // plane and no edge crosses an edge.
        s.plan.slack.min(topology::edge_slack(a, b, s))
    } else {
        topology.validate(a, t, tolerance(a, b), s)?
    };
    Some((topology, slack))
}

/// The overlap by the plan in `s`: by its topology where it has one (all of B in A's
/// frame in `s`).
fn overlap_by_plan(
    a: &ConvexPolyhedron,
    b: &ConvexPolyhedron,
    t: &Vector3<Real>,
    topology: Option<&Topology>,
    s: &mut OverlapScratch,
) -> Option<OverlapGeometry> {
    if s.plan.separated {
        return None;
    }
    if let Some(topology) = topology {
        return topology.evaluate(a, t, s);
    }
    let plan = std::mem::take(&mut s.plan);
    let (faces_a, faces_b) = plan.faces.split_at(plan.of_a);
    let overlap = masked::overlap_planned(a, b, t, faces_a, faces_b, s);
    s.plan = plan;
    overlap
}

/// Whether a shape takes the bit-mask path.
fn maskable(p: &ConvexPolyhedron) -> bool {
    p.face_count() <= MASK_MAX_FACES && p.vertices().len() <= MASK_MAX_VERTICES
}

/// Puts B's vertices and planes into A's frame in `s` (B's rotation `rot` and
/// centroid `t` in A), and clears the piece vertices.
fn place_b(b: &ConvexPolyhedron, rot: &Matrix3<Real>, t: &Vector3<Real>, s: &mut OverlapScratch) {
    s.b_points.clear();
    s.b_points
        .extend(b.vertices().iter().map(|p| point_in_a(p, rot, t)));
    s.b_planes.clear();
    s.b_planes
        .extend(b.planes().iter().map(|p| plane_in_a(p, rot, t)));
    s.points.clear();
}

/// A point of B in A's frame (B's rotation `rot` and centroid `t` in A): one
/// formula wherever B is placed, so that a part placed alone has the bits of B
/// placed whole.
#[inline]
fn point_in_a(p: &Point3<Real>, rot: &Matrix3<Real>, t: &Vector3<Real>) -> Point3<Real> {
    Point3::from(rot * p.coords + t)
}

/// A plane of B in A's frame (B's rotation `rot` and centroid `t` in A).
#[inline]
fn plane_in_a(p: &Plane, rot: &Matrix3<Real>, t: &Vector3<Real>) -> Plane {
    let normal = rot * p.normal;
    Plane {
        normal,
        offset: p.offset + normal.dot(t),
    }
}

/// [`place_b`] for the vertices (bits) `vertices` and the planes (bits) `planes` of
/// B only; the others keep whatever they held.
fn place_b_parts(
    b: &ConvexPolyhedron,
    rot: &Matrix3<Real>,
    t: &Vector3<Real>,
    mut vertices: u128,
    planes: u64,
    s: &mut OverlapScratch,
) {
    s.b_points.resize(b.vertices().len(), Point3::origin());
    while vertices != 0 {
        let v = vertices.trailing_zeros() as usize;
        vertices &= vertices - 1;
        s.b_points[v] = point_in_a(&b.vertices()[v], rot, t);
    }
    s.b_planes.resize(
        b.face_count(),
        Plane {
            normal: Vector3::zeros(),
            offset: 0.0,
        },
    );
    for k in masked::bits(planes) {
        s.b_planes[k] = plane_in_a(&b.planes()[k], rot, t);
    }
    s.points.clear();
}

/// Coplanarity tolerance on plane distances.
fn tolerance(a: &ConvexPolyhedron, b: &ConvexPolyhedron) -> Real {
    1e-12 * a.circumradius().max(b.circumradius())
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

/// The clipped pieces of both shapes' faces, summed as they are found; their
/// vertices are kept for the extent along the normal.
#[derive(Debug, Default)]
struct Pieces {
    a: SideSums,
    b: SideSums,
    surface: SurfaceSums,
}

impl Pieces {
    /// Adds a piece of a face of A (`flush`: lying against a face of B of equal
    /// orientation) or, with `of_b`, of a face of B.
    #[inline]
    fn add(
        &mut self,
        poly: &[Point3<Real>],
        normal: &Vector3<Real>,
        of_b: bool,
        flush: bool,
        points: &mut Vec<Point3<Real>>,
    ) {
        let sums = self.surface.add_piece(poly, normal);
        self.add_to_side(sums, of_b, flush);
        points.extend_from_slice(poly);
    }

    /// Adds a piece whose vertices are `points[loop_[k]]`, of a face of A or, with
    /// `of_b`, of B.
    #[inline]
    fn add_loop(
        &mut self,
        points: &[Point3<Real>],
        loop_: &[u8],
        normal: &Vector3<Real>,
        of_b: bool,
    ) {
        let sums = self
            .surface
            .add_piece_by(loop_.len(), |k| points[loop_[k] as usize], normal);
        self.add_to_side(sums, of_b, false);
    }

    #[inline]
    fn add_to_side(
        &mut self,
        (area, moment): (Vector3<Real>, Vector3<Real>),
        of_b: bool,
        flush: bool,
    ) {
        let side = if of_b { &mut self.b } else { &mut self.a };
        if flush {
            side.flush_area += area;
            side.flush_moment += moment;
        } else {
            side.area += area;
            side.moment += moment;
        }
    }
}

/// Volume, centroid, extent and gradients of the closed set of pieces, whose
/// vertices are `points`. `t` is B's centroid in A's frame.
///
/// Flush pieces F are left out of A's sums and counted with B's (as B's coincident,
/// dropped face): on the closed surface `S_A + F + S_B = 0`, and the area vector is
/// `S_A = −(S_B + F)` from either side.
fn summarise(
    points: &[Point3<Real>],
    pieces: &Pieces,
    t: &Vector3<Real>,
) -> Option<OverlapGeometry> {
    if pieces.surface.is_empty() {
        return None;
    }
    let volume = pieces.surface.volume();
    if !(volume > 0.0) {
        return None;
    }
    let (a, b) = (&pieces.a, &pieces.b);
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
        centroid: pieces.surface.centroid(),
        normal,
        area,
        depth: hi - lo,
        rotation_gradient_a: a.moment,
        rotation_gradient_b: b.moment + a.flush_moment - t.cross(&s_b),
    })
}

#[cfg(test)]
mod cache_tests;
