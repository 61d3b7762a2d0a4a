//! Oriented planes.

use nalgebra::{Isometry3, Point3, Vector3};

use crate::Real;

/// The plane `normal · x = offset`, with a unit `normal` pointing out of the solid
/// it bounds: points with `normal · x > offset` are outside.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// Outward unit normal.
    pub normal: Vector3<Real>,
    /// Signed distance of the plane from the origin along `normal`.
    pub offset: Real,
}

impl Plane {
    /// Signed distance of `p` from the plane (positive outside).
    #[inline]
    pub fn distance(&self, p: &Point3<Real>) -> Real {
        self.normal.dot(&p.coords) - self.offset
    }

    /// The plane in the frame that `iso` maps into.
    #[inline]
    pub fn transformed(&self, iso: &Isometry3<Real>) -> Plane {
        let normal = iso.rotation * self.normal;
        Plane {
            normal,
            offset: self.offset + normal.dot(&iso.translation.vector),
        }
    }

    /// Least-squares plane of a planar polygon given counter-clockwise (Newell's
    /// normal, mean offset).
    pub fn fit_polygon(points: &[Point3<Real>]) -> Plane {
        let mut n = Vector3::zeros();
        let mut centre = Vector3::zeros();
        for (k, p) in points.iter().enumerate() {
            let q = points[(k + 1) % points.len()];
            n += p.coords.cross(&q.coords);
            centre += p.coords;
        }
        let normal = n.normalize();
        Plane {
            normal,
            offset: normal.dot(&(centre / points.len() as Real)),
        }
    }
}

/// Planes in structure-of-arrays form, padded to a multiple of 4 so that the
/// distance loop vectorises.
#[derive(Clone, Default, Debug)]
pub(crate) struct PlaneSoa {
    pub(crate) nx: Vec<Real>,
    pub(crate) ny: Vec<Real>,
    pub(crate) nz: Vec<Real>,
    pub(crate) offset: Vec<Real>,
}

impl PlaneSoa {
    /// Largest signed distance of `p` from the planes: positive when outside the solid
    /// they bound.
    pub(crate) fn max_distance(&self, p: &Point3<Real>) -> Real {
        let mut lanes = [Real::NEG_INFINITY; 4];
        for c in 0..self.nx.len() / 4 {
            for (l, lane) in lanes.iter_mut().enumerate() {
                let k = 4 * c + l;
                let d = self.nx[k] * p.x + self.ny[k] * p.y + self.nz[k] * p.z - self.offset[k];
                // A plain select (not f64::max) so that the loop vectorises.
                *lane = if d > *lane { d } else { *lane };
            }
        }
        lanes.iter().copied().fold(Real::NEG_INFINITY, Real::max)
    }

    pub(crate) fn fill(&mut self, planes: &[Plane]) {
        let n = planes.len().next_multiple_of(4);
        for v in [&mut self.nx, &mut self.ny, &mut self.nz, &mut self.offset] {
            v.clear();
        }
        for p in planes {
            self.nx.push(p.normal.x);
            self.ny.push(p.normal.y);
            self.nz.push(p.normal.z);
            self.offset.push(p.offset);
        }
        // Padding planes never cut: every point is far inside them.
        for v in [&mut self.nx, &mut self.ny, &mut self.nz] {
            v.resize(n, 0.0);
        }
        self.offset.resize(n, Real::MAX);
    }
}

/// Points in structure-of-arrays form, padded with the origin to a multiple of 4 so
/// that the plane-distance loop runs four points at a time.
#[derive(Clone, Default, Debug)]
pub(crate) struct PointSoa {
    pub(crate) x: Vec<Real>,
    pub(crate) y: Vec<Real>,
    pub(crate) z: Vec<Real>,
}

impl PointSoa {
    pub(crate) fn fill(&mut self, points: &[Point3<Real>]) {
        let n = points.len().next_multiple_of(4);
        for (k, v) in [&mut self.x, &mut self.y, &mut self.z]
            .into_iter()
            .enumerate()
        {
            v.clear();
            v.extend(points.iter().map(|p| p[k]));
            v.resize(n, 0.0);
        }
    }
}
