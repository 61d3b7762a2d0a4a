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
