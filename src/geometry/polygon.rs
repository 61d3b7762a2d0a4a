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
fn cut(inside: &Point3<Real>, di: Real, outside: &Point3<Real>, do_: Real) -> Point3<Real> {
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
