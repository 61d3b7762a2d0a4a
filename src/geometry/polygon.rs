//! Convex polygon clipping and the surface integrals that turn a closed set of
//! polygons into volume, centroid and vector area.

use nalgebra::{Point3, Vector3};

use super::Plane;
use crate::Real;

/// Clips the convex polygon `input` (with signed distances `dist` of its vertices from
/// the plane, positive outside) to the inside of the plane, writing to `out`.
///
/// An edge crossing the plane is cut at a point computed from its inside end towards
/// its outside end, so that the two faces sharing an edge produce bit-identical cut
/// points whichever way they traverse it.
#[inline]
pub(crate) fn clip_with_distances(
    input: &[Point3<Real>],
    dist: &[Real],
    out: &mut Vec<Point3<Real>>,
) {
    out.clear();
    let n = input.len();
    for k in 0..n {
        let (p, dp) = (input[k], dist[k]);
        let j = if k + 1 == n { 0 } else { k + 1 };
        let (q, dq) = (input[j], dist[j]);
        if dp <= 0.0 {
            out.push(p);
            if dq > 0.0 {
                out.push(cut(&p, dp, &q, dq));
            }
        } else if dq <= 0.0 {
            out.push(cut(&q, dq, &p, dp));
        }
    }
}

/// The point where the segment from `inside` (distance `di <= 0`) to `outside`
/// (distance `do_ > 0`) meets the plane.
#[inline]
pub(crate) fn cut(
    inside: &Point3<Real>,
    di: Real,
    outside: &Point3<Real>,
    do_: Real,
) -> Point3<Real> {
    let t = di / (di - do_);
    inside + (outside - inside) * t
}

/// Clips `poly` in place by `plane`, using `scratch` as the second buffer.
#[inline]
pub(crate) fn clip_by_plane(
    poly: &mut Vec<Point3<Real>>,
    plane: &Plane,
    dist: &mut Vec<Real>,
    scratch: &mut Vec<Point3<Real>>,
) {
    dist.clear();
    let mut any_out = false;
    let mut any_in = false;
    for p in poly.iter() {
        let d = plane.distance(p);
        any_out |= d > 0.0;
        any_in |= d <= 0.0;
        dist.push(d);
    }
    if !any_out {
        return;
    }
    if !any_in {
        poly.clear();
        return;
    }
    clip_with_distances(poly, dist, scratch);
    std::mem::swap(poly, scratch);
}

/// Vector area (unit normal times area) of a planar polygon.
#[inline]
pub(crate) fn vector_area(poly: &[Point3<Real>]) -> Vector3<Real> {
    let mut s = Vector3::zeros();
    let p0 = poly[0];
    for k in 1..poly.len().saturating_sub(1) {
        s += (poly[k] - p0).cross(&(poly[k + 1] - p0));
    }
    0.5 * s
}

/// First moment of a planar polygon's vector area about the origin: `Σ ȳ × a` over
/// its fan triangles (centroid `ȳ`, vector area `a`). Summed over the faces a solid
/// moves with, it is the derivative of a volume with respect to rotating that solid.
#[inline]
pub(crate) fn area_moment(poly: &[Point3<Real>]) -> Vector3<Real> {
    let mut m = Vector3::zeros();
    let p0 = poly[0];
    for k in 1..poly.len().saturating_sub(1) {
        let a = 0.5 * (poly[k] - p0).cross(&(poly[k + 1] - p0));
        let centre = (p0.coords + poly[k].coords + poly[k + 1].coords) / 3.0;
        m += centre.cross(&a);
    }
    m
}

/// Accumulates the signed volume and first moment of the cone from `origin` over
/// polygons of a closed outward-oriented surface.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ConeSums {
    origin: Point3<Real>,
    volume6: Real,
    moment24: Vector3<Real>,
}

impl ConeSums {
    pub(crate) fn new(origin: Point3<Real>) -> Self {
        ConeSums {
            origin,
            volume6: 0.0,
            moment24: Vector3::zeros(),
        }
    }

    /// Adds the fan of tetrahedra (origin, p0, pk, pk+1).
    #[inline]
    pub(crate) fn add_polygon(&mut self, poly: &[Point3<Real>]) {
        let a = poly[0] - self.origin;
        for k in 1..poly.len().saturating_sub(1) {
            let b = poly[k] - self.origin;
            let c = poly[k + 1] - self.origin;
            let det = a.dot(&b.cross(&c));
            self.volume6 += det;
            self.moment24 += det * (a + b + c);
        }
    }

    /// Enclosed volume.
    pub(crate) fn volume(&self) -> Real {
        self.volume6 / 6.0
    }

    /// Centroid of the enclosed volume (meaningless when the volume is zero).
    pub(crate) fn centroid(&self) -> Point3<Real> {
        self.origin + self.moment24 / (4.0 * self.volume6)
    }
}

/// Volume and first moment of a closed surface given as convex planar pieces with
/// known outward unit normals, accumulated piece by piece (cones from the first
/// piece's first vertex), together with each piece's vector area and area moment.
///
/// One pass over a piece's fan triangles gives all of it: every fan triangle of a
/// convex planar piece has its vector area along the piece's normal `n`, so with
/// `w_k = n · (p_k − p_0) × (p_{k+1} − p_0)` (twice its area) and `h` the height of
/// the piece's plane over the cone apex `o`, the cone over the piece has volume
/// `h Σ w_k / 6` and first moment `h Σ w_k (p_0 + p_k + p_{k+1} − 3o) / 24`, and the
/// piece's area moment is `Σ w_k (p_0 + p_k + p_{k+1}) × n / 6`.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct SurfaceSums {
    apex: Option<Point3<Real>>,
    volume6: Real,
    moment24: Vector3<Real>,
}

impl SurfaceSums {
    /// Adds the convex piece `poly` (counter-clockwise about `normal`, at least three
    /// vertices); returns its vector area and its area moment about the origin.
    #[inline]
    pub(crate) fn add_piece(
        &mut self,
        poly: &[Point3<Real>],
        normal: &Vector3<Real>,
    ) -> (Vector3<Real>, Vector3<Real>) {
        self.add_piece_by(poly.len(), |k| poly[k], normal)
    }

    /// [`SurfaceSums::add_piece`] for the piece of `len` vertices whose `k`-th is
    /// `vertex(k)`.
    #[inline]
    pub(crate) fn add_piece_by(
        &mut self,
        len: usize,
        vertex: impl Fn(usize) -> Point3<Real>,
        normal: &Vector3<Real>,
    ) -> (Vector3<Real>, Vector3<Real>) {
        let p0 = vertex(0);
        let apex = *self.apex.get_or_insert(p0);
        let (mut twice_area, mut spread) = (0.0, Vector3::zeros());
        let mut u = vertex(1) - p0;
        for k in 2..len {
            let v = vertex(k) - p0;
            let w = normal.dot(&u.cross(&v));
            twice_area += w;
            spread += w * (u + v);
            u = v;
        }
        // Σ w_k (p_0 + p_k + p_{k+1}) = spread + 3 p_0 Σ w_k.
        let offset = p0 - apex;
        let h = offset.dot(normal);
        self.volume6 += h * twice_area;
        self.moment24 += h * (spread + 3.0 * twice_area * offset);
        let weighted = spread + 3.0 * twice_area * p0.coords;
        (normal * (0.5 * twice_area), weighted.cross(normal) / 6.0)
    }

    /// Whether no piece was added.
    pub(crate) fn is_empty(&self) -> bool {
        self.apex.is_none()
    }

    /// Enclosed volume.
    pub(crate) fn volume(&self) -> Real {
        self.volume6 / 6.0
    }

    /// Centroid of the enclosed volume (meaningless when the volume is zero or no
    /// piece was added).
    pub(crate) fn centroid(&self) -> Point3<Real> {
        self.apex.unwrap_or_else(Point3::origin) + self.moment24 / (4.0 * self.volume6)
    }
}

/// Most vertices a clipped face of a shape of at most 64 faces can have (a face has
/// fewer than 64 vertices, and each of at most 64 cuts adds at most one).
pub(crate) const MAX_CLIPPED: usize = 128;

/// A convex polygon in a fixed-size double buffer, clipped without allocation.
#[derive(Clone, Debug)]
pub(crate) struct FixedPolygon {
    buffers: [[Point3<Real>; MAX_CLIPPED]; 2],
    /// Which buffer holds the polygon.
    current: usize,
    len: usize,
    dist: [Real; MAX_CLIPPED],
}

impl Default for FixedPolygon {
    fn default() -> Self {
        FixedPolygon {
            buffers: [[Point3::origin(); MAX_CLIPPED]; 2],
            current: 0,
            len: 0,
            dist: [0.0; MAX_CLIPPED],
        }
    }
}

impl FixedPolygon {
    /// Replaces the polygon by `points` (at most [`MAX_CLIPPED`]).
    #[inline]
    pub(crate) fn set(&mut self, points: impl Iterator<Item = Point3<Real>>) {
        self.len = 0;
        let buffer = &mut self.buffers[self.current];
        for p in points.take(MAX_CLIPPED) {
            buffer[self.len] = p;
            self.len += 1;
        }
    }

    /// The vertices.
    #[inline]
    pub(crate) fn points(&self) -> &[Point3<Real>] {
        &self.buffers[self.current][..self.len]
    }

    /// Whether fewer than three vertices remain.
    #[inline]
    pub(crate) fn is_degenerate(&self) -> bool {
        self.len < 3
    }

    /// Clips to the inside of `plane` (same cut-point rule as [`clip_with_distances`]).
    #[inline]
    pub(crate) fn clip(&mut self, plane: &Plane) {
        let n = self.len;
        let [first, second] = &mut self.buffers;
        let (input, output) = if self.current == 0 {
            (first, second)
        } else {
            (second, first)
        };
        let mut any_out = false;
        let mut any_in = false;
        for (p, d) in input[..n].iter().zip(&mut self.dist) {
            *d = plane.distance(p);
            any_out |= *d > 0.0;
            any_in |= *d <= 0.0;
        }
        if !any_out {
            return;
        }
        if !any_in {
            self.len = 0;
            return;
        }
        // A convex polygon crossing a plane gains at most one vertex, so the buffer
        // cannot overflow; the bound only guards against a non-convex input.
        let mut m = 0;
        let mut push = |p: Point3<Real>| {
            if m < MAX_CLIPPED {
                output[m] = p;
                m += 1;
            }
        };
        for k in 0..n {
            let j = if k + 1 == n { 0 } else { k + 1 };
            let (p, dp) = (input[k], self.dist[k]);
            let (q, dq) = (input[j], self.dist[j]);
            if dp <= 0.0 {
                push(p);
                if dq > 0.0 {
                    push(cut(&p, dp, &q, dq));
                }
            } else if dq <= 0.0 {
                push(cut(&q, dq, &p, dp));
            }
        }
        self.current ^= 1;
        self.len = m;
    }
}
