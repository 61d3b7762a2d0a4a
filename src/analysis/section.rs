//! Plane sections of particles and their areas inside a circle: the pieces from
//! which packing volumes are integrated along a tube's axis.
//!
//! Coordinates are those of a bed frame whose z axis is the tube's axis, so a
//! cross-section is a plane `z = const` and a radial bin is a disc about the origin.

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
        return std::f64::consts::PI * r.min(s).powi(2);
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
    use std::f64::consts::PI;

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
}
