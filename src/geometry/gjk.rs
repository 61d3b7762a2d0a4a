//! The Gilbert–Johnson–Keerthi distance algorithm on convex support maps.
//!
//! Works on the Minkowski difference `A − B` with B posed in A's frame; answers
//! whether the shapes intersect and, when apart, their distance and closest points
//! (in A's frame). The simplex is reduced with Voronoi-region tests on segments,
//! triangles and tetrahedra (Ericson, *Real-Time Collision Detection*, ch. 5 and 9).

use nalgebra::{Point3, Vector3};

use super::{ConvexPolyhedron, Pose};
use crate::Real;

/// A convex shape known through its support function, in its own frame.
pub trait SupportMap {
    /// A point of the shape farthest along `dir`. `hint` carries a feature index
    /// between calls so that large meshes can climb from the previous answer.
    fn support(&self, dir: &Vector3<Real>, hint: &mut usize) -> Point3<Real>;
}

impl SupportMap for ConvexPolyhedron {
    #[inline]
    fn support(&self, dir: &Vector3<Real>, hint: &mut usize) -> Point3<Real> {
        *hint = self.support_index(dir, *hint);
        self.vertices()[*hint]
    }
}

/// A single point (the core of a sphere).
#[derive(Clone, Copy, Debug)]
pub struct PointShape(pub Point3<Real>);

impl SupportMap for PointShape {
    #[inline]
    fn support(&self, _dir: &Vector3<Real>, _hint: &mut usize) -> Point3<Real> {
        self.0
    }
}

/// Outcome of [`gjk`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GjkResult {
    /// The shapes share at least one point (to round-off).
    Intersecting,
    /// The shapes are apart.
    Separated {
        /// Distance between them.
        distance: Real,
        /// Closest point on A (A's frame).
        point_a: Point3<Real>,
        /// Closest point on B (A's frame).
        point_b: Point3<Real>,
    },
}

impl GjkResult {
    /// Whether the shapes intersect.
    pub fn intersects(&self) -> bool {
        matches!(self, GjkResult::Intersecting)
    }

    /// Separation distance (zero when intersecting).
    pub fn distance(&self) -> Real {
        match self {
            GjkResult::Intersecting => 0.0,
            GjkResult::Separated { distance, .. } => *distance,
        }
    }
}

#[derive(Clone, Copy, Debug)]
struct Vertex {
    /// Point of the Minkowski difference `a − b`.
    w: Vector3<Real>,
    a: Point3<Real>,
    b: Point3<Real>,
}

/// Barycentric weights on a sub-simplex: up to four (vertex index, weight) pairs.
#[derive(Clone, Copy, Debug)]
struct SubSimplex {
    entries: [(usize, Real); 4],
    len: usize,
}

impl SubSimplex {
    fn of(entries: &[(usize, Real)]) -> Self {
        let mut out = SubSimplex {
            entries: [(0, 0.0); 4],
            len: entries.len(),
        };
        out.entries[..entries.len()].copy_from_slice(entries);
        out
    }

    fn iter(&self) -> impl Iterator<Item = &(usize, Real)> {
        self.entries[..self.len].iter()
    }
}

/// Runs GJK on A and B (B posed by `b_in_a`), starting from the search direction
/// `guess` if given (a previous step's separating axis makes this converge in one or
/// two iterations).
pub fn gjk<A: SupportMap + ?Sized, B: SupportMap + ?Sized>(
    a: &A,
    b: &B,
    b_in_a: &Pose,
    guess: Option<Vector3<Real>>,
) -> GjkResult {
    const MAX_ITERATIONS: usize = 128;
    const REL_TOLERANCE: Real = 1e-12;
    const ABS_TOLERANCE: Real = 1e-13;
    let inv_rot = b_in_a.rotation.inverse();
    let (mut hint_a, mut hint_b) = (0usize, 0usize);
    let mut support = |d: &Vector3<Real>| {
        // Support of A − B along d: s_A(d) − s_B(−d).
        let pa = a.support(d, &mut hint_a);
        let pb = b_in_a.transform_point(&b.support(&(inv_rot * -d), &mut hint_b));
        Vertex {
            w: pa - pb,
            a: pa,
            b: pb,
        }
    };
    let mut v = guess
        .filter(|g| g.norm_squared() > 0.0 && g.iter().all(|x| x.is_finite()))
        .unwrap_or(-b_in_a.translation.vector);
    if v.norm_squared() == 0.0 {
        v = Vector3::x();
    }
    let first = support(&-v);
    let mut simplex = [first; 4];
    let mut count = 1;
    let mut weights = SubSimplex::of(&[(0, 1.0)]);
    v = first.w;
    let mut max_w2 = first.w.norm_squared();
    for _ in 0..MAX_ITERATIONS {
        let v2 = v.norm_squared();
        if v2 <= 1e-28 * max_w2.max(Real::MIN_POSITIVE) {
            return GjkResult::Intersecting;
        }
        let w = support(&-v);
        max_w2 = max_w2.max(w.w.norm_squared());
        // Convergence: the support point brings v no closer than round-off can tell.
        // v carries an absolute error of a few hundred ε·|w| from the simplex
        // arithmetic, so v·w does too, times |v|; near contact (|v| ≪ |w|) the
        // relative test alone would go on and add a point coplanar with the nearest
        // face: a flat tetrahedron whose inside test is round-off.
        let gap = v2 - v.dot(&w.w);
        if gap <= REL_TOLERANCE * v2 + ABS_TOLERANCE * (v2 * max_w2).sqrt()
            || simplex[..count].iter().any(|s| s.w == w.w)
        {
            return separated(&simplex, &weights, v2);
        }
        simplex[count] = w;
        count += 1;
        let (closest, sub) = closest_on_simplex(&simplex[..count]);
        // Keep only the vertices of the sub-simplex, in order.
        let mut reduced = simplex;
        for (k, &(i, _)) in sub.iter().enumerate() {
            reduced[k] = simplex[i];
        }
        simplex = reduced;
        count = sub.len;
        weights = sub;
        for (k, e) in weights.entries[..count].iter_mut().enumerate() {
            e.0 = k;
        }
        if count == 4 {
            return GjkResult::Intersecting;
        }
        if closest.norm_squared() >= v2 {
            // No progress (round-off): v is as close as we get.
            return separated(&simplex, &weights, v2);
        }
        v = closest;
    }
    separated(&simplex, &weights, v.norm_squared())
}

fn separated(simplex: &[Vertex], weights: &SubSimplex, v2: Real) -> GjkResult {
    let mut pa = Vector3::zeros();
    let mut pb = Vector3::zeros();
    for &(i, l) in weights.iter() {
        pa += simplex[i].a.coords * l;
        pb += simplex[i].b.coords * l;
    }
    GjkResult::Separated {
        distance: v2.sqrt(),
        point_a: Point3::from(pa),
        point_b: Point3::from(pb),
    }
}

/// The point of the simplex closest to the origin, and the sub-simplex (indices and
/// barycentric weights) it lies on. A full tetrahedron returns itself when it holds
/// the origin.
fn closest_on_simplex(s: &[Vertex]) -> (Vector3<Real>, SubSimplex) {
    match s.len() {
        1 => (s[0].w, SubSimplex::of(&[(0, 1.0)])),
        2 => closest_on_segment(s, 0, 1),
        3 => closest_on_triangle(s, 0, 1, 2),
        _ => closest_on_tetrahedron(s),
    }
}

fn closest_on_segment(s: &[Vertex], i: usize, j: usize) -> (Vector3<Real>, SubSimplex) {
    let (a, b) = (s[i].w, s[j].w);
    let ab = b - a;
    let t = -a.dot(&ab);
    if t <= 0.0 {
        return (a, SubSimplex::of(&[(i, 1.0)]));
    }
    let denom = ab.norm_squared();
    if t >= denom {
        return (b, SubSimplex::of(&[(j, 1.0)]));
    }
    let t = t / denom;
    (a + ab * t, SubSimplex::of(&[(i, 1.0 - t), (j, t)]))
}

fn closest_on_triangle(s: &[Vertex], i: usize, j: usize, k: usize) -> (Vector3<Real>, SubSimplex) {
    let (a, b, c) = (s[i].w, s[j].w, s[k].w);
    let ab = b - a;
    let ac = c - a;
    let ap = -a;
    let d1 = ab.dot(&ap);
    let d2 = ac.dot(&ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, SubSimplex::of(&[(i, 1.0)]));
    }
    let bp = -b;
    let d3 = ab.dot(&bp);
    let d4 = ac.dot(&bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, SubSimplex::of(&[(j, 1.0)]));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + ab * v, SubSimplex::of(&[(i, 1.0 - v), (j, v)]));
    }
    let cp = -c;
    let d5 = ab.dot(&cp);
    let d6 = ac.dot(&cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, SubSimplex::of(&[(k, 1.0)]));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + ac * w, SubSimplex::of(&[(i, 1.0 - w), (k, w)]));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * w, SubSimplex::of(&[(j, 1.0 - w), (k, w)]));
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    (
        a + ab * v + ac * w,
        SubSimplex::of(&[(i, 1.0 - v - w), (j, v), (k, w)]),
    )
}

fn closest_on_tetrahedron(s: &[Vertex]) -> (Vector3<Real>, SubSimplex) {
    let faces = [(0, 1, 2, 3), (0, 1, 3, 2), (0, 2, 3, 1), (1, 2, 3, 0)];
    let mut best: Option<(Vector3<Real>, SubSimplex)> = None;
    let mut best_d2 = Real::INFINITY;
    // A flat tetrahedron (a new support point in the plane of the nearest face, as
    // near contact) has no inside that round-off can decide: take its faces.
    let scale = (1..4)
        .map(|k| (s[k].w - s[0].w).norm())
        .fold(0.0, Real::max);
    let volume = (s[1].w - s[0].w).dot(&(s[2].w - s[0].w).cross(&(s[3].w - s[0].w)));
    let flat = volume.abs() <= 1e-9 * scale.powi(3);
    let mut inside = !flat;
    for (i, j, k, l) in faces {
        let (a, b, c, d) = (s[i].w, s[j].w, s[k].w, s[l].w);
        let n = (b - a).cross(&(c - a));
        let sign_origin = -n.dot(&a);
        let sign_other = n.dot(&(d - a));
        // Origin on the far side of this face from the fourth vertex (or on it for a
        // flat tetrahedron): the closest point lies on this face.
        if flat || sign_origin * sign_other < 0.0 || sign_other == 0.0 {
            inside = false;
            let (p, sub) = closest_on_triangle(s, i, j, k);
            let d2 = p.norm_squared();
            if d2 < best_d2 {
                best_d2 = d2;
                best = Some((p, sub));
            }
        }
    }
    if inside {
        return (
            Vector3::zeros(),
            SubSimplex::of(&[(0, 0.25), (1, 0.25), (2, 0.25), (3, 0.25)]),
        );
    }
    best.unwrap_or((s[0].w, SubSimplex::of(&[(0, 1.0)])))
}
