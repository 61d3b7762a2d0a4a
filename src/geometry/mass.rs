//! Mass properties of closed triangle meshes by exact polyhedral integration.
//!
//! The solid is split into signed tetrahedra (origin, a, b, c), one per outward
//! triangle. For such a tetrahedron with `det = a · (b × c)` (six times its volume):
//!
//! - volume `det / 6`,
//! - first moment `det / 24 (a + b + c)`,
//! - second moment `∫ x xᵀ dV = det / 120 (a aᵀ + b bᵀ + c cᵀ + s sᵀ)`, `s = a + b + c`.
//!
//! The sums are exact for any closed, consistently oriented mesh, convex or not.

use nalgebra::{Matrix3, Point3, Vector3};

use crate::Real;

/// Volume, centroid and inertia of a homogeneous solid of unit density.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassProperties {
    /// Volume (positive for an outward-oriented mesh).
    pub volume: Real,
    /// Centre of volume.
    pub centroid: Point3<Real>,
    /// Inertia tensor about the centroid, per unit density (kg m² per kg/m³).
    pub inertia: Matrix3<Real>,
}

impl MassProperties {
    /// Integrates a closed, outward-oriented triangle mesh.
    pub fn of_mesh(vertices: &[Point3<Real>], triangles: &[[usize; 3]]) -> Self {
        // Integrate about a point near the solid to limit cancellation.
        let origin = vertices
            .iter()
            .fold(Vector3::zeros(), |acc, v| acc + v.coords)
            / vertices.len().max(1) as Real;
        let mut volume6 = 0.0;
        let mut first24 = Vector3::zeros();
        let mut second120 = Matrix3::zeros();
        for t in triangles {
            let a = vertices[t[0]].coords - origin;
            let b = vertices[t[1]].coords - origin;
            let c = vertices[t[2]].coords - origin;
            let det = a.dot(&b.cross(&c));
            let s = a + b + c;
            volume6 += det;
            first24 += det * s;
            second120 += det
                * (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
        }
        let volume = volume6 / 6.0;
        let first = first24 / 24.0;
        let centroid_rel = first / volume;
        // Covariance about the centroid (parallel-axis shift).
        let cov = second120 / 120.0 - volume * centroid_rel * centroid_rel.transpose();
        let inertia = Matrix3::identity() * cov.trace() - cov;
        MassProperties {
            volume,
            centroid: Point3::from(origin + centroid_rel),
            inertia,
        }
    }
}

/// Whether principal moments `inertia` are equal to round-off (a sphere, a cube, a
/// Platonic solid): then the angular velocity is the angular momentum over any one of
/// them, in every frame.
#[inline]
pub fn is_isotropic(inertia: &nalgebra::Vector3<crate::Real>) -> bool {
    inertia.max() - inertia.min() <= 1e-12 * inertia.max()
}
