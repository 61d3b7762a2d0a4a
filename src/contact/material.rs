//! Materials and the stiffness of a pair of particles.

use serde::{Deserialize, Serialize};

use crate::Real;

/// Why a material is unusable.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum MaterialError {
    /// A parameter is out of its physical range.
    #[error("material '{material}': {field} = {value} is invalid: {reason}")]
    Invalid {
        /// Material name.
        material: String,
        /// The field.
        field: &'static str,
        /// Its value.
        value: Real,
        /// What is required.
        reason: &'static str,
    },
}

/// Bulk and surface properties of a particle or wall material (SI units).
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Name, for messages.
    #[serde(default)]
    pub name: String,
    /// Density, kg/m³.
    pub density: Real,
    /// Young's modulus, Pa.
    pub young: Real,
    /// Poisson's ratio.
    pub poisson: Real,
    /// Coefficient of restitution of a normal impact, in (0, 1].
    pub restitution: Real,
    /// Coulomb friction coefficient.
    pub friction: Real,
    /// Rolling friction coefficient `μ_r` of the rolling-resistance models (the lever
    /// arm of the resisting torque in units of the contact radius; 0: none).
    #[serde(default)]
    pub rolling_friction: Real,
    /// Damping ratio `η_r` of the elastic–plastic rolling spring (Ai et al. 2011's
    /// model C; 0: none).
    #[serde(default)]
    pub rolling_damping: Real,
}

impl Material {
    /// Checks every parameter's range.
    pub fn validate(&self) -> Result<(), MaterialError> {
        let check = |field, value: Real, ok: bool, reason| {
            if ok {
                Ok(())
            } else {
                Err(MaterialError::Invalid {
                    material: self.name.clone(),
                    field,
                    value,
                    reason,
                })
            }
        };
        check(
            "density",
            self.density,
            self.density.is_finite() && self.density > 0.0,
            "must be positive",
        )?;
        check(
            "young",
            self.young,
            self.young.is_finite() && self.young > 0.0,
            "must be positive",
        )?;
        check(
            "poisson",
            self.poisson,
            self.poisson > -1.0 && self.poisson < 0.5,
            "must lie in (-1, 0.5)",
        )?;
        check(
            "restitution",
            self.restitution,
            self.restitution > 0.0 && self.restitution <= 1.0,
            "must lie in (0, 1]",
        )?;
        check(
            "friction",
            self.friction,
            self.friction.is_finite() && self.friction >= 0.0,
            "must be non-negative",
        )?;
        check(
            "rolling_friction",
            self.rolling_friction,
            self.rolling_friction.is_finite() && self.rolling_friction >= 0.0,
            "must be non-negative",
        )?;
        check(
            "rolling_damping",
            self.rolling_damping,
            self.rolling_damping.is_finite() && self.rolling_damping >= 0.0,
            "must be non-negative",
        )
    }

    /// Shear modulus `E / (2 (1 + ν))`.
    pub fn shear_modulus(&self) -> Real {
        self.young / (2.0 * (1.0 + self.poisson))
    }
}

/// Stiffness factors of a contact between two bodies, per unit contact area: the
/// normal `κ = E₁/R₁ + E₂/R₂` and the tangential `G₁/R₁ + G₂/R₂`, with `R` the
/// volume-equivalent radii (Xu et al., "Large-Scale Multiple-GPU-based DEM
/// Simulation of Polyhedral Particle Systems", eqs. 13 and 19). A wall counts as a
/// body of infinite radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairStiffness {
    /// Normal factor κ, Pa/m.
    pub normal: Real,
    /// Tangential factor, Pa/m.
    pub tangential: Real,
}

impl PairStiffness {
    /// Between two particles of radii `r1`, `r2`.
    pub fn particles(m1: &Material, r1: Real, m2: &Material, r2: Real) -> Self {
        PairStiffness {
            normal: m1.young / r1 + m2.young / r2,
            tangential: m1.shear_modulus() / r1 + m2.shear_modulus() / r2,
        }
    }

    /// Between a particle of radius `r` and a wall. A rigid flat wall has no curvature
    /// of its own; its material's modulus enters in series with the particle's, so
    /// that a wall softer than the particle softens the contact.
    pub fn particle_wall(particle: &Material, r: Real, wall: &Material) -> Self {
        let series = |a: Real, b: Real| a * b / (a + b);
        PairStiffness {
            normal: 2.0 * series(particle.young, wall.young) / r,
            tangential: 2.0 * series(particle.shear_modulus(), wall.shear_modulus()) / r,
        }
    }
}

/// Restitution of a contact between two materials: the mean of the two.
pub fn pair_restitution(a: Real, b: Real) -> Real {
    0.5 * (a + b)
}

#[cfg(test)]
impl Material {
    /// A material of the library's unit tests: `name`, `density`, Young's modulus
    /// `young` and Poisson's ratio `poisson`, restitution and friction 0.5, no
    /// rolling resistance.
    pub(crate) fn of_tests(name: &str, density: Real, young: Real, poisson: Real) -> Self {
        Material {
            name: name.into(),
            density,
            young,
            poisson,
            restitution: 0.5,
            friction: 0.5,
            rolling_friction: 0.0,
            rolling_damping: 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn steel() -> Material {
        Material {
            name: "steel".into(),
            density: 7800.0,
            young: 2e11,
            poisson: 0.3,
            restitution: 0.8,
            friction: 0.4,
            rolling_friction: 0.0,
            rolling_damping: 0.0,
        }
    }

    #[test]
    fn validation_names_material_and_field() {
        assert!(steel().validate().is_ok());
        let mut m = steel();
        m.poisson = 0.5;
        let err = m.validate().unwrap_err().to_string();
        assert!(err.contains("steel") && err.contains("poisson"), "{err}");
        m = steel();
        m.restitution = 0.0;
        assert!(
            m.validate()
                .unwrap_err()
                .to_string()
                .contains("restitution")
        );
        m = steel();
        m.density = f64::NAN;
        assert!(m.validate().unwrap_err().to_string().contains("density"));
    }

    #[test]
    fn pair_stiffness() {
        let s = steel();
        let p = PairStiffness::particles(&s, 0.01, &s, 0.02);
        assert!((p.normal - (2e11 / 0.01 + 2e11 / 0.02)).abs() < 1.0);
        assert!((p.tangential - s.shear_modulus() * (1.0 / 0.01 + 1.0 / 0.02)).abs() < 1.0);
        // A wall of the same material acts as one particle term (Xu et al.'s R → ∞);
        // a rigid wall doubles it.
        let w = PairStiffness::particle_wall(&s, 0.01, &s);
        assert!((w.normal - 2e11 / 0.01).abs() < 1.0);
        let mut rigid = s.clone();
        rigid.young = 1e30;
        assert!(
            (PairStiffness::particle_wall(&s, 0.01, &rigid).normal / (2e11 / 0.01) - 2.0).abs()
                < 1e-9
        );
    }
}
