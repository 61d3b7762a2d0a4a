//! A particle's volume split among the Voronoi cells of a set of points: the cells
//! of a coupled code that gives only its cells' centres (an unstructured CFD mesh).
//!
//! The cell of centre `a` is where `a` is the nearest centre: the intersection of
//! the half-spaces `(b − a) · x ≤ (b − a) · (a + b) / 2` over the other centres `b`.
//! Only centres that can be nearest to some point of the particle need to be given
//! (the candidates: every centre within `d₀ + 2ρ` of the particle's centre, `d₀` the
//! nearest centre's distance and `ρ` the particle's circumradius, holds all of them).
//!
//! - A convex polyhedron is cut by the bisecting planes ([`split`]), exactly, one
//!   candidate's cell after the other.
//! - A sphere's share is integrated over z: at each height its section is a disc
//!   and each cell's section a convex polygon, and the part of the disc inside each
//!   polygon is exact ([`polygon_disc_area`]); the integral is adaptive
//!   ([`adaptive_gauss`], to `1e-9` of the sphere's volume) and takes every cell at
//!   the same heights, so the shares add up to the sphere's volume to round-off.

use std::f64::consts::PI;

use nalgebra::{Point3, Vector3};

use super::cell_volumes::{Cut, Faces, split, volume};
use super::quadrature::adaptive_gauss;
use super::section::{clip_half_plane, polygon_disc_area};
use crate::Real;

/// The half-space of `a`'s side of the plane bisecting `a` and `b`, as the cut
/// whose lower side it is.
fn bisector(a: &Point3<Real>, b: &Point3<Real>) -> Cut {
    let normal = b - a;
    Cut::plane(normal, normal.dot(&(a.coords + b.coords)) * 0.5)
}

/// Calls `share(k, volume)` for each candidate centre `centres[k]` whose Voronoi
/// cell (among `centres`) the convex polyhedron of face loops `faces` reaches, with
/// its volume there.
pub fn polyhedron_voronoi_volumes(
    faces: &Faces,
    centres: &[Point3<Real>],
    mut share: impl FnMut(usize, Real),
) {
    for (k, a) in centres.iter().enumerate() {
        let mut piece = faces.clone();
        for (m, b) in centres.iter().enumerate() {
            if m == k || piece.is_empty() {
                continue;
            }
            piece = split(piece, &bisector(a, b)).0;
        }
        if !piece.is_empty() {
            let v = volume(&piece);
            if v > 0.0 {
                share(k, v);
            }
        }
    }
}

/// Calls `share(k, volume)` for each candidate centre `centres[k]` whose Voronoi
/// cell (among `centres`) the sphere reaches, with its volume there; returns the
/// estimated quadrature error.
pub fn sphere_voronoi_volumes(
    centre: Point3<Real>,
    radius: Real,
    centres: &[Point3<Real>],
    mut share: impl FnMut(usize, Real),
) -> Real {
    let cuts: Vec<Vec<(Vector3<Real>, Real)>> = centres
        .iter()
        .enumerate()
        .map(|(k, a)| {
            centres
                .iter()
                .enumerate()
                .filter(|&(m, _)| m != k)
                .map(|(_, b)| {
                    let cut = bisector(a, b);
                    (cut.normal(), cut.offset())
                })
                .collect()
        })
        .collect();
    let mut out = vec![0.0; centres.len()];
    let volume = 4.0 / 3.0 * PI * radius.powi(3);
    // Where a bisecting plane's trace on the sections starts or stops meeting the
    // section's circle (the top and bottom of the circle the plane cuts from the
    // sphere) the cells' areas have kinks, or jumps for a level plane: split there.
    let (lo, hi) = (centre.z - radius, centre.z + radius);
    let mut breaks = vec![lo, hi];
    for (n, offset) in cuts.iter().flatten() {
        let length = n.norm();
        let (unit, h) = (n / length, (offset - n.dot(&centre.coords)) / length);
        if h.abs() < radius {
            let spread = (radius * radius - h * h).sqrt() * (1.0 - unit.z * unit.z).max(0.0).sqrt();
            let mid = centre.z + h * unit.z;
            breaks.extend(
                [mid - spread, mid + spread]
                    .into_iter()
                    .filter(|z| *z > lo && *z < hi),
            );
        }
    }
    breaks.sort_by(Real::total_cmp);
    breaks.dedup();
    let error = adaptive_gauss(
        &breaks,
        1e-9 * volume / (2.0 * radius),
        &mut out,
        &|z, w, out| {
            let s2 = radius * radius - (z - centre.z).powi(2);
            if s2 <= 0.0 {
                return;
            }
            let s = s2.sqrt();
            // A square about the disc, relative to its centre (twice its size: a
            // side that only touches the circle would read as inside it).
            let h = 2.0 * s;
            let square = vec![[-h, -h], [h, -h], [h, h], [-h, h]];
            for (o, cuts) in out.iter_mut().zip(&cuts) {
                let mut poly = square.clone();
                for (n, offset) in cuts {
                    if poly.is_empty() {
                        break;
                    }
                    // n · (centre + (x, y, z − centre.z)) ≤ offset.
                    let room = offset - n.dot(&centre.coords) - n.z * (z - centre.z);
                    poly = clip_half_plane(&poly, |p| room - n.x * p[0] - n.y * p[1]);
                }
                *o += w * polygon_disc_area(&poly, s);
            }
        },
    );
    for (k, v) in out.into_iter().enumerate() {
        if v > 0.0 {
            share(k, v);
        }
    }
    error
}
