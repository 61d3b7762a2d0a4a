//! A particle placed in the bed frame, and its volume clipped to a slab of the tube
//! and to discs about the axis (the integration of [`super`]'s module docs).

use nalgebra::{Isometry3, Point3};

use crate::Real;
use crate::analysis::section::{convex_section, disc_disc_area, polygon_area, polygon_disc_area};
use crate::geometry::Shape;
use crate::geometry::quadrature::{GAUSS5_NODES, GAUSS5_WEIGHTS};
use crate::world::World;

/// A particle placed in the bed frame.
pub(super) enum Body<'a> {
    Polyhedron {
        centroid: Point3<Real>,
        vertices: Vec<Point3<Real>>,
        edges: &'a [[u32; 2]],
        volume: Real,
    },
    Sphere {
        centre: Point3<Real>,
        radius: Real,
    },
}

impl Body<'_> {
    pub(super) fn place<'a>(world: &'a World, i: usize, frame: &Isometry3<Real>) -> Body<'a> {
        let p = &world.particles;
        let pose = frame * Isometry3::from_parts(p.position[i].coords.into(), p.orientation[i]);
        match &world.body_types[p.body_type[i] as usize].shape {
            Shape::Polyhedron(poly) => Body::Polyhedron {
                centroid: pose * Point3::origin(),
                vertices: poly.vertices().iter().map(|v| pose * v).collect(),
                edges: poly.edges(),
                volume: poly.volume(),
            },
            Shape::Sphere(s) => Body::Sphere {
                centre: pose * Point3::origin(),
                radius: s.radius,
            },
        }
    }

    pub(super) fn z_range(&self) -> (Real, Real) {
        match self {
            Body::Polyhedron { vertices, .. } => vertices
                .iter()
                .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), v| {
                    (lo.min(v.z), hi.max(v.z))
                }),
            Body::Sphere { centre, radius } => (centre.z - radius, centre.z + radius),
        }
    }

    /// The centroid.
    pub(super) fn centroid(&self) -> Point3<Real> {
        match self {
            Body::Polyhedron { centroid, .. } => *centroid,
            Body::Sphere { centre, .. } => *centre,
        }
    }

    /// The largest distance of a point of the body from the axis.
    pub(super) fn reach(&self) -> Real {
        match self {
            Body::Polyhedron { vertices, .. } => {
                vertices.iter().map(|v| v.x.hypot(v.y)).fold(0.0, Real::max)
            }
            Body::Sphere { centre, radius } => centre.x.hypot(centre.y) + radius,
        }
    }

    pub(super) fn volume(&self) -> Real {
        match self {
            Body::Polyhedron { volume, .. } => *volume,
            Body::Sphere { radius, .. } => 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3),
        }
    }

    /// Heights between which the sections' areas inside the discs of `radii` are
    /// smooth (sorted).
    fn breakpoints(&self, lo: Real, hi: Real, radii: &[Real]) -> Vec<Real> {
        let mut z = vec![lo, hi];
        match self {
            Body::Polyhedron { vertices, .. } => {
                z.extend(vertices.iter().map(|v| v.z).filter(|&z| z > lo && z < hi));
            }
            // Where the section's circle starts or stops meeting a radial circle
            // (section radius |δ − r| or δ + r, δ the centre's distance from the
            // axis), the lens area has a kink: split there.
            Body::Sphere { centre, radius } => {
                let delta = centre.x.hypot(centre.y);
                for &r in radii {
                    for s in [(delta - r).abs(), delta + r] {
                        if s < *radius {
                            let h = (radius * radius - s * s).sqrt();
                            z.extend(
                                [centre.z - h, centre.z + h]
                                    .into_iter()
                                    .filter(|&z| z > lo && z < hi),
                            );
                        }
                    }
                }
            }
        }
        z.sort_by(Real::total_cmp);
        z.dedup();
        z
    }

    /// Adds `weight` × (area of the section at `z` inside each disc of `radii`).
    fn add_section_areas(&self, z: Real, radii: &[Real], weight: Real, out: &mut [Real]) {
        match self {
            Body::Polyhedron {
                vertices, edges, ..
            } => {
                let poly = convex_section(vertices, edges, z);
                if poly.is_empty() {
                    return;
                }
                let full = polygon_area(&poly);
                let reach = poly.iter().map(|p| p[0].hypot(p[1])).fold(0.0, Real::max);
                for (o, &r) in out.iter_mut().zip(radii) {
                    *o += weight
                        * if r >= reach {
                            full
                        } else {
                            polygon_disc_area(&poly, r)
                        };
                }
            }
            Body::Sphere { centre, radius } => {
                let s2 = radius * radius - (z - centre.z).powi(2);
                if s2 <= 0.0 {
                    return;
                }
                for (o, &r) in out.iter_mut().zip(radii) {
                    *o += weight * disc_disc_area([centre.x, centre.y], s2.sqrt(), r);
                }
            }
        }
    }

    /// Volumes inside each disc of `radii` between heights `lo` and `hi`, and the
    /// estimated quadrature error.
    pub(super) fn clipped_volumes(&self, lo: Real, hi: Real, radii: &[Real]) -> (Vec<Real>, Real) {
        let mut out = vec![0.0; radii.len()];
        let (zmin, zmax) = self.z_range();
        let (lo, hi) = (lo.max(zmin), hi.min(zmax));
        if !(hi > lo) {
            return (out, 0.0);
        }
        let tolerance = 1e-9 * self.volume() / (zmax - zmin);
        let mut error = 0.0;
        let z = self.breakpoints(lo, hi, radii);
        let q = Quadrature {
            radii,
            tolerance,
            depth: 0,
        };
        for w in z.windows(2) {
            let whole = self.gauss(w[0], w[1], radii);
            error += self.adapt((w[0], w[1]), whole, &q, &mut out);
        }
        (out, error)
    }

    fn gauss(&self, lo: Real, hi: Real, radii: &[Real]) -> Vec<Real> {
        let (mid, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
        let mut out = vec![0.0; radii.len()];
        for (x, w) in GAUSS5_NODES.iter().zip(GAUSS5_WEIGHTS) {
            self.add_section_areas(mid + half * x, radii, w * half, &mut out);
        }
        out
    }

    /// Adds the integral over [lo, hi] to `out` (`whole`: its 5-point estimate),
    /// halving until the halves agree with the whole; returns the error estimate.
    fn adapt(
        &self,
        span: (Real, Real),
        whole: Vec<Real>,
        q: &Quadrature,
        out: &mut [Real],
    ) -> Real {
        let (lo, hi) = span;
        let mid = 0.5 * (lo + hi);
        let (left, right) = (self.gauss(lo, mid, q.radii), self.gauss(mid, hi, q.radii));
        let diff = whole
            .iter()
            .zip(left.iter().zip(&right))
            .map(|(w, (l, r))| (l + r - w).abs())
            .fold(0.0, Real::max);
        if diff <= q.tolerance * (hi - lo) || q.depth >= 20 {
            for (o, (l, r)) in out.iter_mut().zip(left.iter().zip(&right)) {
                *o += l + r;
            }
            return diff;
        }
        let deeper = Quadrature {
            depth: q.depth + 1,
            ..*q
        };
        self.adapt((lo, mid), left, &deeper, out) + self.adapt((mid, hi), right, &deeper, out)
    }
}

/// What an adaptive integration is after: the discs, the tolerance per unit of
/// height, and how often the interval was halved already.
#[derive(Clone, Copy)]
struct Quadrature<'a> {
    radii: &'a [Real],
    tolerance: Real,
    depth: usize,
}
