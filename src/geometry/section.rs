//! Plane sections of particles and their areas inside a circle and an angular
//! sector: the pieces from which volumes are integrated along a tube's axis
//! ([`super::axial_volumes`]).
//!
//! Coordinates are those of a frame whose z axis is the tube's axis, so a
//! cross-section is a plane `z = const`, a radial bin is a disc about the origin and
//! a sector is a wedge from the origin between two rays (at most half a turn wide,
//! so that it is convex).

use std::f64::consts::PI;

use nalgebra::Point3;

use crate::Real;

/// Area of the part of the convex polygon `poly` (counter-clockwise or clockwise,
/// any start) inside the disc of radius `r` about the origin: exact, as a sum over
/// the edges of the signed area of the triangle (origin, edge) inside the disc, each
/// split where the edge crosses the circle into straight (inside) and circular-sector
/// (outside) pieces.
pub fn polygon_disc_area(poly: &[[Real; 2]], r: Real) -> Real {
    if poly.len() < 3 || !(r > 0.0) {
        return 0.0;
    }
    let mut sum = 0.0;
    for k in 0..poly.len() {
        sum += triangle_disc_area(poly[k], poly[(k + 1) % poly.len()], r);
    }
    sum.abs()
}

/// Signed area of the triangle (origin, p, q) inside the disc of radius `r`.
fn triangle_disc_area(p: [Real; 2], q: [Real; 2], r: Real) -> Real {
    let d = [q[0] - p[0], q[1] - p[1]];
    let a = d[0] * d[0] + d[1] * d[1];
    if a == 0.0 {
        return 0.0;
    }
    let b = 2.0 * (p[0] * d[0] + p[1] * d[1]);
    let c = p[0] * p[0] + p[1] * p[1] - r * r;
    let disc = b * b - 4.0 * a * c;
    let mut cuts = [0.0, 1.0, 1.0, 1.0];
    let mut n = 1;
    if disc > 0.0 {
        let s = disc.sqrt();
        for t in [(-b - s) / (2.0 * a), (-b + s) / (2.0 * a)] {
            if t > 0.0 && t < 1.0 {
                cuts[n] = t;
                n += 1;
            }
        }
    }
    cuts[n] = 1.0;
    let at = |t: Real| [p[0] + t * d[0], p[1] + t * d[1]];
    let mut area = 0.0;
    for k in 0..n {
        let (u, v) = (at(cuts[k]), at(cuts[k + 1]));
        let cross = u[0] * v[1] - u[1] * v[0];
        let mid = at(0.5 * (cuts[k] + cuts[k + 1]));
        if mid[0] * mid[0] + mid[1] * mid[1] <= r * r {
            area += 0.5 * cross;
        } else {
            let dot = u[0] * v[0] + u[1] * v[1];
            area += 0.5 * r * r * cross.atan2(dot);
        }
    }
    area
}

/// Area of the disc of radius `s` about `c` inside the disc of radius `r` about the
/// origin (the lens of two circles).
pub fn disc_disc_area(c: [Real; 2], s: Real, r: Real) -> Real {
    if !(s > 0.0 && r > 0.0) {
        return 0.0;
    }
    let d = c[0].hypot(c[1]);
    if d >= r + s {
        return 0.0;
    }
    if d <= (r - s).abs() {
        return PI * r.min(s).powi(2);
    }
    let alpha = ((d * d + r * r - s * s) / (2.0 * d * r))
        .clamp(-1.0, 1.0)
        .acos();
    let beta = ((d * d + s * s - r * r) / (2.0 * d * s))
        .clamp(-1.0, 1.0)
        .acos();
    let kite = ((-d + r + s) * (d + r - s) * (d - r + s) * (d + r + s))
        .max(0.0)
        .sqrt();
    r * r * alpha + s * s * beta - 0.5 * kite
}

/// The part of the convex polygon `poly` inside the wedge from the ray along `u0`
/// counter-clockwise to the ray along `u1` (unit vectors, at most half a turn
/// apart): the polygon clipped by the two half-planes.
pub fn clip_to_wedge(poly: &[[Real; 2]], u0: [Real; 2], u1: [Real; 2]) -> Vec<[Real; 2]> {
    let left_of_u0 = |p: &[Real; 2]| u0[0] * p[1] - u0[1] * p[0];
    let right_of_u1 = |p: &[Real; 2]| p[0] * u1[1] - p[1] * u1[0];
    let once = clip_half_plane(poly, left_of_u0);
    clip_half_plane(&once, right_of_u1)
}

/// The part of the convex polygon `poly` where `side` (linear) is not negative.
pub fn clip_half_plane(poly: &[[Real; 2]], side: impl Fn(&[Real; 2]) -> Real) -> Vec<[Real; 2]> {
    let mut out = Vec::with_capacity(poly.len() + 1);
    for (k, p) in poly.iter().enumerate() {
        let q = &poly[(k + 1) % poly.len()];
        let (sp, sq) = (side(p), side(q));
        if sp >= 0.0 {
            out.push(*p);
        }
        if (sp < 0.0 && sq > 0.0) || (sp > 0.0 && sq < 0.0) {
            let t = sp / (sp - sq);
            out.push([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]);
        }
    }
    if out.len() < 3 { Vec::new() } else { out }
}

/// Area of the part of the disc of radius `s` about `c` that lies inside the disc
/// of radius `r` about the origin and inside the wedge from `u0` counter-clockwise
/// to `u1` (unit vectors, at most half a turn apart).
///
/// By Green's theorem, as `½ ∮ (x dy − y dx)` around the region: its boundary is
/// made of arcs of the two circles (each arc of one circle that lies inside the
/// other disc and the wedge, counter-clockwise) and pieces of the wedge's rays,
/// which add nothing (`x dy = y dx` along a line through the origin). Each circle
/// is cut at its crossings with the other circle and the rays, and each arc kept or
/// left by its midpoint.
pub fn lens_wedge_area(c: [Real; 2], s: Real, r: Real, u0: [Real; 2], u1: [Real; 2]) -> Real {
    if !(s > 0.0 && r > 0.0) || c[0].hypot(c[1]) >= r + s {
        return 0.0;
    }
    let in_wedge =
        |p: [Real; 2]| u0[0] * p[1] - u0[1] * p[0] >= 0.0 && p[0] * u1[1] - p[1] * u1[0] >= 0.0;
    let in_a = |p: [Real; 2]| (p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) <= s * s;
    let in_b = |p: [Real; 2]| p[0] * p[0] + p[1] * p[1] <= r * r;
    let crossings = circle_crossings(c, s, r);
    // Circle A (about c): cut where it meets circle B and the rays.
    let mut cuts: Vec<Real> = crossings
        .iter()
        .map(|p| (p[1] - c[1]).atan2(p[0] - c[0]))
        .collect();
    for u in [u0, u1] {
        let b = u[0] * c[0] + u[1] * c[1];
        let q = b * b - (c[0] * c[0] + c[1] * c[1] - s * s);
        if q > 0.0 {
            for t in [b - q.sqrt(), b + q.sqrt()] {
                if t > 0.0 {
                    cuts.push((t * u[1] - c[1]).atan2(t * u[0] - c[0]));
                }
            }
        }
    }
    let mut area = 0.0;
    for (a, b) in arcs(cuts) {
        let m = 0.5 * (a + b);
        if in_b([c[0] + s * m.cos(), c[1] + s * m.sin()])
            && in_wedge([c[0] + s * m.cos(), c[1] + s * m.sin()])
        {
            area += 0.5
                * (s * s * (b - a) + s * (c[0] * (b.sin() - a.sin()) - c[1] * (b.cos() - a.cos())));
        }
    }
    // Circle B (about the origin): cut where it meets circle A and the rays.
    let mut cuts: Vec<Real> = crossings.iter().map(|p| p[1].atan2(p[0])).collect();
    cuts.extend([u0[1].atan2(u0[0]), u1[1].atan2(u1[0])]);
    for (a, b) in arcs(cuts) {
        let m = 0.5 * (a + b);
        let p = [r * m.cos(), r * m.sin()];
        if in_a(p) && in_wedge(p) {
            area += 0.5 * r * r * (b - a);
        }
    }
    area
}

/// Where the circle of radius `s` about `c` meets the circle of radius `r` about
/// the origin (none when they do not cross).
fn circle_crossings(c: [Real; 2], s: Real, r: Real) -> Vec<[Real; 2]> {
    let d = c[0].hypot(c[1]);
    if !(d > 0.0) || d >= r + s || d <= (r - s).abs() {
        return Vec::new();
    }
    let along = (d * d + r * r - s * s) / (2.0 * d);
    let across = (r * r - along * along).max(0.0).sqrt();
    let (e, n) = ([c[0] / d, c[1] / d], [-c[1] / d, c[0] / d]);
    [-1.0, 1.0]
        .iter()
        .map(|sign| {
            [
                along * e[0] + sign * across * n[0],
                along * e[1] + sign * across * n[1],
            ]
        })
        .collect()
}

/// The arcs of a circle between consecutive `cuts` (angles), going once around: the
/// whole turn when there are none.
fn arcs(mut cuts: Vec<Real>) -> Vec<(Real, Real)> {
    if cuts.is_empty() {
        return vec![(0.0, 2.0 * PI)];
    }
    cuts.sort_by(Real::total_cmp);
    let mut out: Vec<(Real, Real)> = cuts.windows(2).map(|w| (w[0], w[1])).collect();
    out.push((cuts[cuts.len() - 1], cuts[0] + 2.0 * PI));
    out.retain(|(a, b)| b > a);
    out
}

/// Area of a polygon (shoelace), positive.
pub fn polygon_area(poly: &[[Real; 2]]) -> Real {
    let mut sum = 0.0;
    for k in 0..poly.len() {
        let (u, v) = (poly[k], poly[(k + 1) % poly.len()]);
        sum += u[0] * v[1] - u[1] * v[0];
    }
    0.5 * sum.abs()
}

/// The section of a convex polyhedron (vertices placed in the bed frame, and its
/// edges) by the plane at height `z`: a convex polygon, counter-clockwise, empty when
/// the plane misses it or only touches it.
pub fn convex_section(vertices: &[Point3<Real>], edges: &[[u32; 2]], z: Real) -> Vec<[Real; 2]> {
    let mut points = Vec::with_capacity(16);
    for e in edges {
        let (a, b) = (&vertices[e[0] as usize], &vertices[e[1] as usize]);
        let (da, db) = (a.z - z, b.z - z);
        if (da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0) {
            let t = da / (da - db);
            points.push([a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)]);
        }
    }
    for v in vertices {
        if v.z == z {
            points.push([v.x, v.y]);
        }
    }
    convex_hull(points)
}

/// Convex hull of points in the plane (Andrew's monotone chain), counter-clockwise,
/// without collinear points.
pub fn convex_hull(mut points: Vec<[Real; 2]>) -> Vec<[Real; 2]> {
    points.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    points.dedup();
    if points.len() < 3 {
        return Vec::new();
    }
    let cross = |o: [Real; 2], a: [Real; 2], b: [Real; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[Real; 2]> = Vec::with_capacity(2 * points.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &[Real; 2]>> = if pass == 0 {
            Box::new(points.iter())
        } else {
            Box::new(points.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    if hull.len() < 3 { Vec::new() } else { hull }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(half: Real, centre: [Real; 2]) -> Vec<[Real; 2]> {
        vec![
            [centre[0] - half, centre[1] - half],
            [centre[0] + half, centre[1] - half],
            [centre[0] + half, centre[1] + half],
            [centre[0] - half, centre[1] + half],
        ]
    }

    #[test]
    fn a_centred_square_in_a_disc_has_its_closed_form_area() {
        let sq = square(1.0, [0.0, 0.0]);
        // Disc inside the square, square inside the disc.
        assert!((polygon_disc_area(&sq, 0.7) - PI * 0.49).abs() < 1e-14);
        assert!((polygon_disc_area(&sq, 1.5) - 4.0).abs() < 1e-14);
        // In between: the disc less four circular segments beyond the sides.
        let r: Real = 1.2;
        let half_angle = (1.0 / r).acos();
        let segment = r * r * (half_angle - half_angle.sin() * half_angle.cos());
        let expected = PI * r * r - 4.0 * segment;
        assert!((polygon_disc_area(&sq, r) - expected).abs() < 1e-13);
        // Orientation and start do not matter.
        let mut rev = sq.clone();
        rev.reverse();
        rev.rotate_left(1);
        assert!((polygon_disc_area(&rev, r) - expected).abs() < 1e-13);
    }

    #[test]
    fn an_offset_polygon_agrees_with_sampling() {
        let tri = vec![[0.3, -0.2], [1.6, 0.4], [0.5, 1.1]];
        let exact = polygon_disc_area(&tri, 1.0);
        // Midpoint sampling on a fine grid: error of order h × perimeter.
        let n = 2000;
        let h = 4.0 / n as Real;
        let inside_tri = |x: Real, y: Real| {
            (0..3).all(|k| {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0]) >= 0.0
            })
        };
        let mut count = 0usize;
        for i in 0..n {
            for j in 0..n {
                let (x, y) = (-2.0 + (i as Real + 0.5) * h, -2.0 + (j as Real + 0.5) * h);
                if x * x + y * y <= 1.0 && inside_tri(x, y) {
                    count += 1;
                }
            }
        }
        let sampled = count as Real * h * h;
        assert!((exact - sampled).abs() < 5e-3 * exact, "{exact} {sampled}");
    }

    #[test]
    fn lens_areas() {
        assert_eq!(disc_disc_area([3.0, 0.0], 1.0, 1.0), 0.0);
        assert!((disc_disc_area([0.1, 0.0], 0.5, 1.0) - PI * 0.25).abs() < 1e-15);
        // Two unit circles a radius apart: 2π/3 − √3/2.
        let lens = disc_disc_area([0.0, 1.0], 1.0, 1.0);
        assert!((lens - (2.0 * PI / 3.0 - 3f64.sqrt() / 2.0)).abs() < 1e-14);
    }

    #[test]
    fn the_section_of_a_cube_is_a_square() {
        let mut v = Vec::new();
        for k in 0..8 {
            v.push(Point3::new(
                if k & 1 == 0 { -1.0 } else { 1.0 },
                if k & 2 == 0 { -1.0 } else { 1.0 },
                if k & 4 == 0 { -1.0 } else { 1.0 },
            ));
        }
        let mut edges = Vec::new();
        for a in 0..8u32 {
            for bit in [1, 2, 4] {
                if a & bit == 0 {
                    edges.push([a, a | bit]);
                }
            }
        }
        let s = convex_section(&v, &edges, 0.3);
        assert_eq!(s.len(), 4);
        assert!((polygon_area(&s) - 4.0).abs() < 1e-14);
        assert!(convex_section(&v, &edges, 1.5).is_empty());
    }

    #[test]
    fn sectors_partition_a_lens_and_a_polygon_and_agree_with_sampling() {
        let c = [0.35, -0.2];
        let (s, r) = (0.6, 0.8);
        let tri = vec![[0.3, -0.2], [1.6, 0.4], [-0.5, 1.1]];
        for n in [2, 3, 5, 8] {
            let rays: Vec<[Real; 2]> = (0..=n)
                .map(|k| {
                    let a = 2.0 * PI * k as Real / n as Real;
                    [a.cos(), a.sin()]
                })
                .collect();
            let lens: Real = (0..n)
                .map(|k| lens_wedge_area(c, s, r, rays[k], rays[k + 1]))
                .sum();
            assert!(
                (lens - disc_disc_area(c, s, r)).abs() < 1e-14,
                "{n}: {lens}"
            );
            let poly: Real = (0..n)
                .map(|k| polygon_area(&clip_to_wedge(&tri, rays[k], rays[k + 1])))
                .sum();
            assert!((poly - polygon_area(&tri)).abs() < 1e-14, "{n}: {poly}");
        }
        // One sector of three against midpoint sampling (error of order h × perimeter).
        let (u0, u1) = ([1.0, 0.0], [(2.0 * PI / 3.0).cos(), (2.0 * PI / 3.0).sin()]);
        let exact = lens_wedge_area(c, s, r, u0, u1);
        let m = 2000;
        let h = 2.0 / m as Real;
        let mut count = 0usize;
        for i in 0..m {
            for j in 0..m {
                let p = [-1.0 + (i as Real + 0.5) * h, -1.0 + (j as Real + 0.5) * h];
                let angle = p[1].atan2(p[0]);
                let in_sector = (0.0..=2.0 * PI / 3.0).contains(&angle);
                if in_sector
                    && p[0] * p[0] + p[1] * p[1] <= r * r
                    && (p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) <= s * s
                {
                    count += 1;
                }
            }
        }
        let sampled = count as Real * h * h;
        assert!(
            exact > 0.1 && (exact - sampled).abs() < 2e-3 * exact,
            "{exact} {sampled}"
        );
    }
}
