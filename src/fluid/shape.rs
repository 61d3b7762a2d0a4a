//! What a particle's shape does to its drag: the volume-equivalent diameter, the
//! sphericity, the area it shows the flow, and the shape corrections of the drag
//! coefficient.

use nalgebra::{UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use super::drag::{DragLaw, schiller_naumann_cd};
use crate::Real;
use crate::geometry::{Shape, vector_area};

/// A correction of the drag coefficient for non-spherical particles. Under the
/// single-particle law of Schiller and Naumann the correlation's `C_d` of the shape
/// replaces the sphere's; under the other laws the drag is multiplied by the
/// correlation's `C_d` of the shape over its `C_d` of a sphere at the same Reynolds
/// number. A sphere keeps the law's drag.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ShapeCorrection {
    /// The law's sphere drag for every shape.
    #[default]
    None,
    /// Hölzer and Sommerfeld, Powder Technol. 184 (2008): sphericity and the
    /// crosswise sphericity (the area the particle shows the slip, from its
    /// orientation). The lengthwise sphericity is taken as the sphericity.
    HolzerSommerfeld,
    /// Ganser, Powder Technol. 77 (1993), for isometric particles: the sphericity.
    Ganser,
}

/// A body type's shape as the drag sees it.
#[derive(Clone, Debug, PartialEq)]
pub struct DragShape {
    /// Diameter of the sphere of equal volume, m.
    pub diameter: Real,
    /// Volume, m³.
    pub volume: Real,
    /// Surface area of the sphere of equal volume over the particle's (1 for a
    /// sphere).
    pub sphericity: Real,
    /// Area-weighted outward face normals in the body frame (empty for a sphere): the
    /// area shown along `e` is half the sum of `|n · e|`.
    face_areas: Vec<Vector3<Real>>,
}

impl DragShape {
    /// The drag shape of `shape`.
    pub fn of(shape: &Shape) -> Self {
        let volume = shape.volume();
        let diameter = (6.0 * volume / std::f64::consts::PI).cbrt();
        let face_areas: Vec<Vector3<Real>> = match shape {
            Shape::Sphere(_) => Vec::new(),
            Shape::Polyhedron(p) => (0..p.face_count())
                .map(|f| {
                    let face: Vec<_> = p
                        .face(f)
                        .iter()
                        .map(|&k| p.vertices()[k as usize])
                        .collect();
                    vector_area(&face)
                })
                .collect(),
        };
        let sphericity = match shape {
            Shape::Sphere(_) => 1.0,
            Shape::Polyhedron(_) => {
                std::f64::consts::PI * diameter * diameter / shape.surface_area()
            }
        };
        DragShape {
            diameter,
            volume,
            sphericity,
            face_areas,
        }
    }

    /// Area the particle shows a flow along the unit vector `e` (world frame) at
    /// `orientation`: exact for a convex body.
    pub fn projected_area(&self, orientation: &UnitQuaternion<Real>, e: &Vector3<Real>) -> Real {
        if self.face_areas.is_empty() {
            return std::f64::consts::PI * self.diameter * self.diameter / 4.0;
        }
        let e = orientation.inverse_transform_vector(e);
        0.5 * self
            .face_areas
            .iter()
            .map(|a| a.dot(&e).abs())
            .sum::<Real>()
    }

    /// The factor `correction` puts on the drag of `law` at Reynolds number `re`
    /// (formed with the volume-equivalent diameter) for a slip along `e` at
    /// `orientation`.
    pub fn factor(
        &self,
        correction: ShapeCorrection,
        law: DragLaw,
        re: Real,
        orientation: &UnitQuaternion<Real>,
        e: &Vector3<Real>,
    ) -> Real {
        let phi = self.sphericity;
        let (shape, sphere) = match correction {
            ShapeCorrection::None => return 1.0,
            _ if self.face_areas.is_empty() => return 1.0,
            ShapeCorrection::HolzerSommerfeld => {
                let crosswise = std::f64::consts::PI * self.diameter * self.diameter
                    / 4.0
                    / self.projected_area(orientation, e);
                (
                    holzer_sommerfeld_cd(re, phi, crosswise),
                    holzer_sommerfeld_cd(re, 1.0, 1.0),
                )
            }
            ShapeCorrection::Ganser => (ganser_cd(re, phi), ganser_cd(re, 1.0)),
        };
        match law {
            DragLaw::SchillerNaumann => shape / schiller_naumann_cd(re),
            _ => shape / sphere,
        }
    }
}

/// Hölzer–Sommerfeld drag coefficient (lengthwise sphericity taken as `phi`).
pub fn holzer_sommerfeld_cd(re: Real, phi: Real, crosswise: Real) -> Real {
    8.0 / (re * phi.sqrt())
        + 16.0 / (re * phi.sqrt())
        + 3.0 / (re.sqrt() * phi.powf(0.75))
        + 0.42 * (10.0 as Real).powf(0.4 * (-phi.log10()).max(0.0).powf(0.2)) / crosswise
}

/// Ganser's drag coefficient of an isometric particle of sphericity `phi`.
pub fn ganser_cd(re: Real, phi: Real) -> Real {
    let k1 = 1.0 / (1.0 / 3.0 + 2.0 / 3.0 / phi.sqrt());
    let k2 = (10.0 as Real).powf(1.8148 * (-phi.log10()).max(0.0).powf(0.5743));
    let rk = re * k1 * k2;
    24.0 / (re * k1) * (1.0 + 0.1118 * rk.powf(0.6567)) + 0.4305 * k2 / (1.0 + 3305.0 / rk)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Sphere;
    use crate::geometry::generators::cuboid;

    #[test]
    fn a_cube_in_closed_form() {
        let cube = DragShape::of(&Shape::Polyhedron(cuboid(1.0, 1.0, 1.0).unwrap().into()));
        // d_v = (6/π)^(1/3); ψ = π^(1/3) 6^(2/3) / 6 = 0.806.
        assert!((cube.diameter - (6.0 / std::f64::consts::PI).cbrt()).abs() < 1e-14);
        assert!((cube.sphericity - 0.805_995_977_008_234_6).abs() < 1e-12);
        let q = UnitQuaternion::identity();
        // Face on: one face; along the body diagonal: √3.
        assert!((cube.projected_area(&q, &Vector3::z()) - 1.0).abs() < 1e-14);
        let diagonal = Vector3::new(1.0, 1.0, 1.0).normalize();
        assert!((cube.projected_area(&q, &diagonal) - 3.0_f64.sqrt()).abs() < 1e-14);
        // The corrections raise a cube's drag; none for a sphere.
        let sphere = DragShape::of(&Shape::Sphere(Sphere { radius: 1.0 }));
        for c in [ShapeCorrection::HolzerSommerfeld, ShapeCorrection::Ganser] {
            for law in [DragLaw::SchillerNaumann, DragLaw::DiFelice] {
                assert_eq!(sphere.factor(c, law, 10.0, &q, &Vector3::z()), 1.0);
                assert!(cube.factor(c, law, 10.0, &q, &Vector3::z()) > 1.05);
            }
        }
    }
}
