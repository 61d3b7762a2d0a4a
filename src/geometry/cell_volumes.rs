//! A particle's volume split among the cells of an axis-aligned grid: what a CFD code
//! needs as the solid volume fraction of its cells, computed exactly.
//!
//! The grid is given by its cell boundaries along each axis (sorted, cell `k` between
//! boundaries `k` and `k + 1`); whatever lies outside the outermost boundaries belongs
//! to no cell.
//!
//! - A convex polyhedron is cut by the boundary planes one axis after the other
//!   (each cut splits the face loops and closes both halves with the section polygon),
//!   and each piece's volume summed over its faces. The pieces partition the particle,
//!   so their volumes add up to its volume to round-off.
//! - A sphere's share of a cell is written through the volume `G(x, y, z)` of the
//!   sphere below a corner (`X < x, Y < y, Z < z`) by inclusion–exclusion over the
//!   cell's eight corners. `G` is a one-dimensional integral of the closed-form area of
//!   a disc below a corner, taken by tanh–sinh quadrature between the heights where
//!   that area has a kink (square-root singularities at the ends of each piece). Neighbouring cells share their corners'
//!   values, so the shares telescope: over cells that cover the sphere they add up to
//!   `G` at the far corner, which is the sphere's exact volume, to round-off, whatever
//!   the quadrature's own error (below 1e-12 of the sphere's volume per value).

use std::f64::consts::PI;

use nalgebra::{Point3, Vector3};

use super::quadrature::tanh_sinh;
use super::{ConvexPolyhedron, Pose, vector_area};
use crate::Real;

/// Boundaries of the cells along the three axes, each sorted ascending.
pub type CellBounds<'a> = [&'a [Real]; 3];

/// A convex body as its face loops (each a planar convex polygon, either orientation).
pub(crate) type Faces = Vec<Vec<Point3<Real>>>;

/// The face loops of `shape` placed at `pose` (what [`polyhedron_cell_volumes`]
/// takes).
pub fn placed_faces(shape: &ConvexPolyhedron, pose: &Pose) -> Vec<Vec<Point3<Real>>> {
    (0..shape.face_count())
        .map(|f| {
            shape
                .face(f)
                .iter()
                .map(|&v| pose * shape.vertices()[v as usize])
                .collect()
        })
        .collect()
}

/// Calls `share(cell, volume)` for every cell the convex polyhedron with face loops
/// `faces` (world coordinates) reaches, with the volume of the polyhedron inside it.
/// Cells whose share is zero may be left out.
pub fn polyhedron_cell_volumes(
    faces: Vec<Vec<Point3<Real>>>,
    bounds: CellBounds,
    mut share: impl FnMut([usize; 3], Real),
) {
    for (i, slab) in slices(faces, 0, bounds[0]) {
        for (j, column) in slices(slab, 1, bounds[1]) {
            for (k, piece) in slices(column, 2, bounds[2]) {
                share([i, j, k], volume(&piece));
            }
        }
    }
}

/// The pieces of `body` between consecutive `bounds` along `axis`, with the index of
/// their interval.
fn slices(body: Faces, axis: usize, bounds: &[Real]) -> Vec<(usize, Faces)> {
    let mut out = Vec::new();
    let Some(&first) = bounds.first() else {
        return out;
    };
    let (_, mut rest) = split(body, &Cut::axis(axis, first));
    for (k, &cut) in bounds.iter().enumerate().skip(1) {
        if rest.is_empty() {
            break;
        }
        let (below, above) = split(rest, &Cut::axis(axis, cut));
        if !below.is_empty() {
            out.push((k - 1, below));
        }
        rest = above;
    }
    out
}

/// A plane that cuts a body: `normal · x = offset`, below where `normal · x` is
/// smaller. A plane of constant `x[axis]` keeps its axis so that the cut is taken
/// on that coordinate alone (and the section's points lie exactly on it).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Cut {
    normal: Vector3<Real>,
    offset: Real,
    axis: Option<usize>,
}

impl Cut {
    /// The plane `x[axis] = at`.
    pub(crate) fn axis(axis: usize, at: Real) -> Self {
        Cut {
            normal: Vector3::ith(axis, 1.0),
            offset: at,
            axis: Some(axis),
        }
    }

    /// The plane `normal · x = offset`.
    pub(crate) fn plane(normal: Vector3<Real>, offset: Real) -> Self {
        Cut {
            normal,
            offset,
            axis: None,
        }
    }

    /// The plane's normal (not necessarily unit).
    pub(crate) fn normal(&self) -> Vector3<Real> {
        self.normal
    }

    /// The plane's offset along its normal.
    pub(crate) fn offset(&self) -> Real {
        self.offset
    }

    fn height(&self, p: &Point3<Real>) -> Real {
        match self.axis {
            Some(a) => p[a],
            None => self.normal.dot(&p.coords),
        }
    }

    /// Two unit vectors spanning the plane.
    fn basis(&self) -> (Vector3<Real>, Vector3<Real>) {
        match self.axis {
            Some(a) => (
                Vector3::ith((a + 1) % 3, 1.0),
                Vector3::ith((a + 2) % 3, 1.0),
            ),
            None => {
                let n = self.normal.normalize();
                let seed = if n.x.abs() < 0.6 {
                    Vector3::x()
                } else {
                    Vector3::y()
                };
                let u = n.cross(&seed).normalize();
                (u, n.cross(&u))
            }
        }
    }
}

/// The parts of a convex body below and above the plane of `cut`, each closed by
/// the section polygon. A part that is empty has no faces.
pub(crate) fn split(body: Faces, cut: &Cut) -> (Faces, Faces) {
    let (lo, hi) =
        body.iter()
            .flatten()
            .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), p| {
                let h = cut.height(p);
                (lo.min(h), hi.max(h))
            });
    if hi <= cut.offset {
        return (body, Vec::new());
    }
    if lo >= cut.offset {
        return (Vec::new(), body);
    }
    let (mut below, mut above, mut section) = (Vec::new(), Vec::new(), Vec::new());
    for face in &body {
        let mut down = Vec::with_capacity(face.len() + 1);
        let mut up = Vec::with_capacity(face.len() + 1);
        for (n, &p) in face.iter().enumerate() {
            let q = face[(n + 1) % face.len()];
            let (s, t) = (cut.height(&p) - cut.offset, cut.height(&q) - cut.offset);
            if s <= 0.0 {
                down.push(p);
            }
            if s >= 0.0 {
                up.push(p);
            }
            if s == 0.0 {
                section.push(p);
            }
            if (s < 0.0 && t > 0.0) || (s > 0.0 && t < 0.0) {
                let mut x = p + (q - p) * (s / (s - t));
                if let Some(a) = cut.axis {
                    x[a] = cut.offset;
                }
                down.push(x);
                up.push(x);
                section.push(x);
            }
        }
        for (part, loop_) in [(&mut below, down), (&mut above, up)] {
            if loop_.len() >= 3 {
                part.push(loop_);
            }
        }
    }
    if let Some(cap) = convex_loop(section, cut.basis()) {
        below.push(cap.clone());
        above.push(cap);
    }
    (below, above)
}

/// The points of a convex section in the plane spanned by `basis`, ordered around
/// their mean (duplicates stay: they add nothing to an area).
fn convex_loop(
    mut points: Vec<Point3<Real>>,
    (a, b): (Vector3<Real>, Vector3<Real>),
) -> Option<Vec<Point3<Real>>> {
    if points.len() < 3 {
        return None;
    }
    let n = points.len() as Real;
    let centre = points.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / n;
    let angle = |p: &Point3<Real>| {
        let d = p.coords - centre;
        d.dot(&b).atan2(d.dot(&a))
    };
    points.sort_by(|p, q| angle(p).total_cmp(&angle(q)));
    Some(points)
}

/// Volume of a closed convex body from its face loops: the pyramids from the mean of
/// its vertices (inside or on it) to each face, whatever the loops' orientation.
pub(crate) fn volume(faces: &Faces) -> Real {
    let count = faces.iter().map(Vec::len).sum::<usize>();
    if count == 0 {
        return 0.0;
    }
    let centre = faces
        .iter()
        .flatten()
        .fold(Vector3::zeros(), |s, p| s + p.coords)
        / count as Real;
    faces
        .iter()
        .map(|face| vector_area(face).dot(&(face[0].coords - centre)).abs() / 3.0)
        .sum()
}

/// Calls `share(cell, volume)` for every cell the sphere reaches, with the volume of
/// the sphere inside it.
pub fn sphere_cell_volumes(
    centre: Point3<Real>,
    radius: Real,
    bounds: CellBounds,
    mut share: impl FnMut([usize; 3], Real),
) {
    // The cells reached along each axis and their boundaries relative to the centre.
    let ranges: [(usize, Vec<Real>); 3] = std::array::from_fn(|a| {
        let b = bounds[a];
        let first = b
            .partition_point(|&x| x <= centre[a] - radius)
            .saturating_sub(1);
        let last = b
            .partition_point(|&x| x < centre[a] + radius)
            .min(b.len() - 1);
        let rel = b[first..=last.max(first)]
            .iter()
            .map(|&x| x - centre[a])
            .collect();
        (first, rel)
    });
    let [(i0, xs), (j0, ys), (k0, zs)] = &ranges;
    if xs.len() < 2 || ys.len() < 2 || zs.len() < 2 {
        return;
    }
    let below = |i: usize, j: usize, k: usize| volume_below_corner(radius, xs[i], ys[j], zs[k]);
    let mut g = vec![0.0; xs.len() * ys.len() * zs.len()];
    let at = |i: usize, j: usize, k: usize| (i * ys.len() + j) * zs.len() + k;
    for i in 0..xs.len() {
        for j in 0..ys.len() {
            for k in 0..zs.len() {
                g[at(i, j, k)] = below(i, j, k);
            }
        }
    }
    for i in 0..xs.len() - 1 {
        for j in 0..ys.len() - 1 {
            for k in 0..zs.len() - 1 {
                let v = g[at(i + 1, j + 1, k + 1)]
                    - g[at(i, j + 1, k + 1)]
                    - g[at(i + 1, j, k + 1)]
                    - g[at(i + 1, j + 1, k)]
                    + g[at(i, j, k + 1)]
                    + g[at(i, j + 1, k)]
                    + g[at(i + 1, j, k)]
                    - g[at(i, j, k)];
                if v > 0.0 {
                    share([i0 + i, j0 + j, k0 + k], v);
                }
            }
        }
    }
}

/// Volume of the ball of `radius` about the origin with `X < x, Y < y, Z < z`.
pub fn volume_below_corner(radius: Real, x: Real, y: Real, z: Real) -> Real {
    let r = radius;
    if x <= -r || y <= -r || z <= -r {
        return 0.0;
    }
    let (x, y, z) = (x.min(r), y.min(r), z.min(r));
    if x == r && y == r {
        // A spherical cap (the whole ball when z = r): closed form.
        let h = z + r;
        return PI * h * h * (3.0 * r - h) / 3.0;
    }
    // The disc area below the corner (x, y) has kinks where the section's radius
    // passes |x|, |y| or the corner's distance from the axis.
    let mut t = vec![-r, z];
    for s in [x.abs(), y.abs(), x.hypot(y)] {
        if s < r {
            let h = (r * r - s * s).sqrt();
            t.extend([-h, h].into_iter().filter(|&h| h > -r && h < z));
        }
    }
    t.sort_by(Real::total_cmp);
    let area = |t: Real| disc_area_below_corner((r * r - t * t).max(0.0).sqrt(), x, y);
    let tolerance = 1e-15 * r * r * r;
    t.windows(2)
        .filter(|w| w[1] > w[0])
        .map(|w| tanh_sinh(&area, w[0], w[1], tolerance))
        .sum()
}

/// Area of the disc of radius `rho` about the origin with `X < x, Y < y`.
pub fn disc_area_below_corner(rho: Real, x: Real, y: Real) -> Real {
    if rho <= 0.0 || x <= -rho || y <= -rho {
        return 0.0;
    }
    let end = x.min(rho);
    // ∫ sqrt(ρ² − X²) dX.
    let p = |x: Real| {
        let x = x.clamp(-rho, rho);
        0.5 * (x * (rho * rho - x * x).max(0.0).sqrt() + rho * rho * (x / rho).asin())
    };
    let chord = |lo: Real, hi: Real| p(hi) - p(lo);
    if y >= rho {
        return 2.0 * chord(-rho, end);
    }
    // Where |X| < w the line Y = y cuts the disc's chord at X.
    let w = (rho * rho - y * y).sqrt();
    let (lo, hi) = (-w, end.min(w));
    let inner = if hi > lo {
        (chord(lo, hi), hi - lo)
    } else {
        (0.0, 0.0)
    };
    if y >= 0.0 {
        // The full chord, less what lies above y within |X| < w.
        2.0 * chord(-rho, end) - (inner.0 - y * inner.1)
    } else {
        inner.0 + y * inner.1
    }
}
