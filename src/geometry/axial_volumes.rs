//! A particle's volume clipped to slabs, discs and angular sectors about the z axis
//! of the frame it is placed in: the cells of a tube (a packing's radial bins, the
//! cylindrical grid of a reactor code).
//!
//! The clipped volume is the integral over z of the area of the particle's section
//! inside the region. A convex polyhedron's sections are convex polygons whose
//! vertices move linearly with z between the heights of its vertices, so there the
//! polygon's area is a quadratic in z and Gauss–Legendre quadrature between vertex
//! heights integrates it exactly. The part of a section inside a disc (and a sector)
//! is exact for each z ([`super::section`]) but not polynomial in z, so those
//! integrals are adaptive ([`adaptive_gauss`]: 5-point Gauss–Legendre, halved until
//! two halves agree with the whole to `1e-9` of the particle's volume per unit of its
//! height). All regions of one particle are integrated at the same heights, so the
//! pieces of a partition (sectors, annuli, slabs) add up to the particle's volume to
//! round-off whatever the quadrature's error in each piece. A sphere's sections are
//! discs (lens areas, [`disc_disc_area`], and their parts in a sector).

use std::f64::consts::PI;

use nalgebra::{Isometry3, Point3, UnitQuaternion, Vector3};

use super::quadrature::adaptive_gauss;
use super::section::{
    clip_to_wedge, convex_section, disc_disc_area, lens_wedge_area, polygon_area, polygon_disc_area,
};
use super::{Shape, Sphere};
use crate::Real;

/// The frame of a tube: world point → (x, y across `axis`, z along it from
/// `base`). Its x axis is the world's x turned by the shortest rotation that takes
/// `axis` to z (the world's x itself for an axis along z).
pub fn axis_frame(base: &Point3<Real>, axis: &Vector3<Real>) -> Isometry3<Real> {
    let turn = UnitQuaternion::rotation_between(axis, &Vector3::z()).unwrap_or_else(
        // Axis along −z: half a turn about x.
        || UnitQuaternion::from_axis_angle(&Vector3::x_axis(), PI),
    );
    Isometry3::from_parts((turn * -base.coords).into(), turn)
}

/// A particle placed in a frame whose z axis is the axis of the regions.
#[derive(Clone, Debug)]
pub enum AxialBody<'a> {
    /// A convex polyhedron: its vertices placed, its edges and volume.
    Polyhedron {
        /// The centroid, placed.
        centroid: Point3<Real>,
        /// The vertices, placed.
        vertices: Vec<Point3<Real>>,
        /// The template's edges (vertex indices).
        edges: &'a [[u32; 2]],
        /// The face planes, placed: outward unit normal and offset.
        faces: Vec<(Vector3<Real>, Real)>,
        /// The volume.
        volume: Real,
    },
    /// A sphere.
    Sphere {
        /// The centre, placed.
        centre: Point3<Real>,
        /// The radius.
        radius: Real,
    },
}

/// `count` equal angular sectors about the z axis, sector `k` from the angle
/// `2π k / count` (from +x towards +y) to the next. One sector is the whole turn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sectors(pub usize);

impl Sectors {
    /// The unit directions bounding sector `k` (counter-clockwise from the first).
    fn bounds(self, k: usize) -> ([Real; 2], [Real; 2]) {
        let at = |k: usize| {
            let a = 2.0 * PI * k as Real / self.0 as Real;
            [a.cos(), a.sin()]
        };
        (at(k), at(k + 1))
    }

    /// The sector holding the point `(x, y)` (angles measured from +x, the last
    /// sector taking what round-off puts at the full turn).
    pub fn containing(self, x: Real, y: Real) -> usize {
        let width = 2.0 * PI / self.0 as Real;
        ((y.atan2(x).rem_euclid(2.0 * PI) / width) as usize).min(self.0 - 1)
    }

    /// Directions of the rays bounding the sectors `which` (none for one sector).
    fn rays(self, which: &[usize]) -> Vec<[Real; 2]> {
        if self.0 < 2 {
            return Vec::new();
        }
        which
            .iter()
            .flat_map(|&k| {
                let (u0, u1) = self.bounds(k);
                [u0, u1]
            })
            .collect()
    }

    /// The sectors a body whose section lies within `reach` of the point `(x, y)`
    /// can meet (all when that disc holds the axis).
    fn met(self, x: Real, y: Real, reach: Real) -> Vec<usize> {
        let n = self.0;
        let delta = x.hypot(y);
        if n < 2 || delta <= reach * (1.0 + 1e-9) {
            return (0..n).collect();
        }
        let width = 2.0 * PI / n as Real;
        let half = (reach / delta).asin() + 1e-9;
        let phi = y.atan2(x);
        let first = ((phi - half) / width).floor() as i64;
        let last = ((phi + half) / width).floor() as i64;
        let mut out: Vec<usize> = (first..=last)
            .map(|k| k.rem_euclid(n as i64) as usize)
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }
}

impl<'a> AxialBody<'a> {
    /// `shape` placed at `pose` (body to frame).
    pub fn new(shape: &'a Shape, pose: &Isometry3<Real>) -> Self {
        match shape {
            Shape::Polyhedron(poly) => AxialBody::Polyhedron {
                centroid: pose * Point3::origin(),
                vertices: poly.vertices().iter().map(|v| pose * v).collect(),
                edges: poly.edges(),
                faces: poly
                    .planes()
                    .iter()
                    .map(|p| {
                        let n = pose.rotation * p.normal;
                        (n, p.offset + n.dot(&pose.translation.vector))
                    })
                    .collect(),
                volume: poly.volume(),
            },
            Shape::Sphere(Sphere { radius }) => AxialBody::Sphere {
                centre: pose * Point3::origin(),
                radius: *radius,
            },
        }
    }

    /// Lowest and highest z of the body.
    pub fn z_range(&self) -> (Real, Real) {
        match self {
            AxialBody::Polyhedron { vertices, .. } => vertices
                .iter()
                .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), v| {
                    (lo.min(v.z), hi.max(v.z))
                }),
            AxialBody::Sphere { centre, radius } => (centre.z - radius, centre.z + radius),
        }
    }

    /// The centroid.
    pub fn centroid(&self) -> Point3<Real> {
        match self {
            AxialBody::Polyhedron { centroid, .. } => *centroid,
            AxialBody::Sphere { centre, .. } => *centre,
        }
    }

    /// The largest distance of a point of the body from the axis.
    pub fn reach(&self) -> Real {
        match self {
            AxialBody::Polyhedron { vertices, .. } => {
                vertices.iter().map(|v| v.x.hypot(v.y)).fold(0.0, Real::max)
            }
            AxialBody::Sphere { centre, radius } => centre.x.hypot(centre.y) + radius,
        }
    }

    /// The body's volume.
    pub fn volume(&self) -> Real {
        match self {
            AxialBody::Polyhedron { volume, .. } => *volume,
            AxialBody::Sphere { radius, .. } => 4.0 / 3.0 * PI * radius.powi(3),
        }
    }

    /// Volumes between heights `lo` and `hi` inside each disc of `radii` about the
    /// axis, within each of `sectors`: sector `k`, disc `j` at `k × radii.len() + j`;
    /// and the estimated quadrature error of the largest.
    pub fn clipped_volumes(
        &self,
        lo: Real,
        hi: Real,
        radii: &[Real],
        sectors: Sectors,
    ) -> (Vec<Real>, Real) {
        let all: Vec<usize> = (0..sectors.0).collect();
        self.volumes_in(lo, hi, radii, sectors, &all)
    }

    /// [`Self::clipped_volumes`] in the sectors `which` only (`out` row `n` is
    /// sector `which[n]`).
    fn volumes_in(
        &self,
        lo: Real,
        hi: Real,
        radii: &[Real],
        sectors: Sectors,
        which: &[usize],
    ) -> (Vec<Real>, Real) {
        let mut out = vec![0.0; radii.len() * which.len()];
        let (zmin, zmax) = self.z_range();
        let (lo, hi) = (lo.max(zmin), hi.min(zmax));
        if !(hi > lo) {
            return (out, 0.0);
        }
        let tolerance = 1e-9 * self.volume() / (zmax - zmin);
        let breaks = self.breakpoints(lo, hi, radii, sectors, which);
        let error = adaptive_gauss(&breaks, tolerance, &mut out, &|z, w, out| {
            self.add_section_areas(z, radii, (sectors, which), w, out)
        });
        (out, error)
    }

    /// Heights between which the sections' areas inside the regions are smooth
    /// (sorted, from `lo` to `hi`).
    fn breakpoints(
        &self,
        lo: Real,
        hi: Real,
        radii: &[Real],
        sectors: Sectors,
        which: &[usize],
    ) -> Vec<Real> {
        let mut z = vec![lo, hi];
        let inside = |z: &Real| *z > lo && *z < hi;
        let rays = sectors.rays(which);
        match self {
            AxialBody::Polyhedron {
                vertices,
                edges,
                faces,
                ..
            } => {
                z.extend(vertices.iter().map(|v| v.z).filter(inside));
                let edges = edges
                    .iter()
                    .map(|e| (&vertices[e[0] as usize], &vertices[e[1] as usize]));
                // Where an edge crosses a sector's plane the clipped section gains
                // or loses a corner.
                for u in &rays {
                    let side = |p: &Point3<Real>| u[0] * p.y - u[1] * p.x;
                    for (a, b) in edges.clone() {
                        let (sa, sb) = (side(a), side(b));
                        if (sa < 0.0 && sb > 0.0) || (sa > 0.0 && sb < 0.0) {
                            z.push(a.z + (b.z - a.z) * sa / (sa - sb));
                        }
                    }
                }
                for &r in radii {
                    section_kinks(r, edges.clone(), faces, &rays, &mut z);
                }
                z.retain(inside);
                z.extend([lo, hi]);
            }
            // Where the section's circle starts or stops meeting a radial circle
            // (section radius |δ − r| or δ + r, δ the centre's distance from the
            // axis), a sector's ray (its distance from the ray's line) or the axis
            // itself, the area has a kink: split there.
            AxialBody::Sphere { centre, radius } => {
                let delta = centre.x.hypot(centre.y);
                let mut kinks: Vec<Real> = radii
                    .iter()
                    .flat_map(|&r| [(delta - r).abs(), delta + r])
                    .collect();
                if !rays.is_empty() {
                    kinks.push(delta);
                    kinks.extend(
                        rays.iter()
                            .map(|u| (u[0] * centre.y - u[1] * centre.x).abs()),
                    );
                    // Where a radial circle meets a ray on the section's circle.
                    for &r in radii {
                        kinks.extend(
                            rays.iter()
                                .map(|u| (r * u[0] - centre.x).hypot(r * u[1] - centre.y)),
                        );
                    }
                }
                for s in kinks.into_iter().filter(|s| s < radius) {
                    let h = (radius * radius - s * s).sqrt();
                    z.extend([centre.z - h, centre.z + h].into_iter().filter(inside));
                }
            }
        }
        z.sort_by(Real::total_cmp);
        z.dedup();
        z
    }

    /// Adds `weight` × (area of the section at `z` inside each disc of `radii`, in
    /// each sector) to `out`.
    fn add_section_areas(
        &self,
        z: Real,
        radii: &[Real],
        (sectors, which): (Sectors, &[usize]),
        weight: Real,
        out: &mut [Real],
    ) {
        let rows = which.iter().zip(out.chunks_mut(radii.len()));
        match self {
            AxialBody::Polyhedron {
                vertices, edges, ..
            } => {
                let whole = convex_section(vertices, edges, z);
                if whole.is_empty() {
                    return;
                }
                for (&k, row) in rows {
                    let clipped;
                    let poly = if sectors.0 < 2 {
                        &whole
                    } else {
                        let (u0, u1) = sectors.bounds(k);
                        clipped = clip_to_wedge(&whole, u0, u1);
                        &clipped
                    };
                    if poly.len() < 3 {
                        continue;
                    }
                    let full = polygon_area(poly);
                    let reach = poly.iter().map(|p| p[0].hypot(p[1])).fold(0.0, Real::max);
                    for (o, &r) in row.iter_mut().zip(radii) {
                        *o += weight
                            * if r >= reach {
                                full
                            } else {
                                polygon_disc_area(poly, r)
                            };
                    }
                }
            }
            AxialBody::Sphere { centre, radius } => {
                let s2 = radius * radius - (z - centre.z).powi(2);
                if s2 <= 0.0 {
                    return;
                }
                let (c, s) = ([centre.x, centre.y], s2.sqrt());
                for (&k, row) in rows {
                    for (o, &r) in row.iter_mut().zip(radii) {
                        *o += weight
                            * if sectors.0 < 2 {
                                disc_disc_area(c, s, r)
                            } else {
                                let (u0, u1) = sectors.bounds(k);
                                lens_wedge_area(c, s, r, u0, u1)
                            };
                    }
                }
            }
        }
    }
}

/// Pushes the heights where the area of a polyhedron's section inside the circle of
/// radius `r` has a square-root kink: where a corner of the section crosses the
/// circle (an edge meets the cylinder of radius `r`, or a face meets it on one of
/// the sectors' `rays`) and where a side of the section touches it (a face's trace
/// at the distance `r` from the axis). Split there, the pieces are smooth and the
/// rule integrates them without halving towards each kink.
fn section_kinks<'p>(
    r: Real,
    edges: impl Iterator<Item = (&'p Point3<Real>, &'p Point3<Real>)>,
    faces: &[(Vector3<Real>, Real)],
    rays: &[[Real; 2]],
    z: &mut Vec<Real>,
) {
    for (a, b) in edges {
        let d = b - a;
        let qa = d.x * d.x + d.y * d.y;
        let qb = 2.0 * (a.x * d.x + a.y * d.y);
        let qc = a.x * a.x + a.y * a.y - r * r;
        let disc = qb * qb - 4.0 * qa * qc;
        if qa > 0.0 && disc > 0.0 {
            for t in [-qb - disc.sqrt(), -qb + disc.sqrt()].map(|x| x / (2.0 * qa)) {
                if t > 0.0 && t < 1.0 {
                    z.push(a.z + t * d.z);
                }
            }
        }
    }
    for (n, offset) in faces {
        if n.z.abs() < 1e-12 {
            continue;
        }
        let across = n.x.hypot(n.y);
        z.extend([(offset - r * across) / n.z, (offset + r * across) / n.z]);
        z.extend(
            rays.iter()
                .map(|u| (offset - r * (n.x * u[0] + n.y * u[1])) / n.z),
        );
    }
}

/// A cylindrical grid about the z axis of the frame: annuli out to each of `radii`
/// (ascending; the first cell is the disc out to `radii[0]`), slabs between
/// consecutive `heights` (ascending) and `sectors`. Cell `[i, j, k]` is annulus `i`,
/// slab `j`, sector `k`; what lies beyond the last radius or outside the heights
/// belongs to no cell.
#[derive(Clone, Copy, Debug)]
pub struct CylinderCells<'a> {
    /// Outer radius of each annulus.
    pub radii: &'a [Real],
    /// Slab boundaries.
    pub heights: &'a [Real],
    /// Angular sectors.
    pub sectors: Sectors,
}

/// Calls `share(cell, volume)` for every cell of `cells` that `body` reaches, with
/// its volume there; returns the estimated quadrature error. Only the annuli and
/// sectors within the body's circumsphere are integrated; over all cells that cover
/// it the shares add up to its volume to round-off.
pub fn cylinder_cell_volumes(
    body: &AxialBody,
    cells: CylinderCells,
    mut share: impl FnMut([usize; 3], Real),
) -> Real {
    let c = body.centroid();
    let reach = match body {
        AxialBody::Polyhedron { vertices, .. } => {
            vertices.iter().map(|v| (v - c).norm()).fold(0.0, Real::max)
        }
        AxialBody::Sphere { radius, .. } => *radius,
    };
    let delta = c.x.hypot(c.y);
    // Discs out to at most δ − reach hold none of it; the first disc out to at least
    // δ + reach holds all of it, and so does every larger one.
    let first = cells.radii.partition_point(|&r| r <= delta - reach);
    let last = cells
        .radii
        .partition_point(|&r| r < delta + reach)
        .min(cells.radii.len().saturating_sub(1));
    if first >= cells.radii.len() {
        return 0.0;
    }
    let radii = &cells.radii[first..=last];
    let which = cells.sectors.met(c.x, c.y, reach);
    let (zmin, zmax) = body.z_range();
    let h = cells.heights;
    let mut error = 0.0;
    for j in h.partition_point(|&z| z <= zmin).saturating_sub(1)..h.len().saturating_sub(1) {
        if h[j] >= zmax {
            break;
        }
        let (discs, e) = body.volumes_in(h[j], h[j + 1], radii, cells.sectors, &which);
        error += e;
        for (&k, row) in which.iter().zip(discs.chunks(radii.len())) {
            let mut inner = 0.0;
            for (i, &disc) in row.iter().enumerate() {
                let v = disc - inner;
                inner = disc;
                if v > 0.0 {
                    share([first + i, j, k], v);
                }
            }
        }
    }
    error
}
