//! Drag laws: the force a fluid moving past a particle puts on it.
//!
//! Every law gives the drag *without* the pressure-gradient (buoyancy) force, which
//! is added apart as `−V ∇p`: the "model A" split of the CFD–DEM equations (Zhou,
//! Kuang, Chu and Yu, J. Fluid Mech. 661 (2010)), the one CFDEMcoupling and the
//! preCICE–LIGGGHTS adapter use; the fluid then carries `−ε ∇p` and the reaction of
//! the drag alone. Velocities are interstitial: `slip = u_fluid − u_particle`; `ε`
//! is the fluid's volume fraction (voidage) at the particle; `d` the diameter of
//! the sphere of equal volume. Reynolds numbers of the dense laws are formed with the
//! superficial slip `ε |slip|`.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::Real;

/// Density and dynamic viscosity of the fluid.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FluidProperties {
    /// Density, kg/m³.
    pub density: Real,
    /// Dynamic viscosity, Pa s.
    pub viscosity: Real,
}

/// A drag law.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DragLaw {
    /// Stokes: `3π μ d slip` (creeping flow, a single particle).
    Stokes,
    /// Schiller and Naumann (1933): a single particle, `C_d = 24/Re (1 + 0.15
    /// Re^0.687)` up to Re = 1000 and 0.44 above.
    SchillerNaumann,
    /// Di Felice (1994): the single-particle `C_d = (0.63 + 4.8/√Re)²` with the
    /// voidage function `ε^(2−χ)`, `χ = 3.7 − 0.65 exp(−(1.5 − log₁₀ Re)²/2)`.
    DiFelice,
    /// Gidaspow (1994): Ergun below ε = 0.8, Wen and Yu (Schiller–Naumann with
    /// `ε^−2.65`) above.
    Gidaspow,
    /// Beetstra, van der Hoef and Kuipers (2007), fitted to lattice-Boltzmann
    /// simulations of random sphere arrays.
    Beetstra,
}

impl DragLaw {
    /// The law's name as scene files write it.
    pub fn name(self) -> &'static str {
        match self {
            DragLaw::Stokes => "stokes",
            DragLaw::SchillerNaumann => "schiller_naumann",
            DragLaw::DiFelice => "di_felice",
            DragLaw::Gidaspow => "gidaspow",
            DragLaw::Beetstra => "beetstra",
        }
    }
}

/// The Schiller–Naumann drag coefficient of a sphere.
pub fn schiller_naumann_cd(re: Real) -> Real {
    if re > 1000.0 {
        0.44
    } else {
        24.0 / re * (1.0 + 0.15 * re.powf(0.687))
    }
}

/// Drag on a sphere of diameter `d` at voidage `epsilon` and slip velocity `slip`,
/// by `law`, times `shape` (the shape correction's factor at the law's Reynolds
/// number: 1 for a sphere; see [`super::shape`]).
pub fn drag_force(
    law: DragLaw,
    fluid: &FluidProperties,
    d: Real,
    epsilon: Real,
    slip: Vector3<Real>,
    shape: impl Fn(Real) -> Real,
) -> Vector3<Real> {
    let speed = slip.norm();
    if speed == 0.0 {
        return Vector3::zeros();
    }
    let (rho, mu) = (fluid.density, fluid.viscosity);
    let area = std::f64::consts::PI * d * d / 4.0;
    let volume = area * d * (2.0 / 3.0);
    // Coefficient c of the force c · slip.
    let c = match law {
        DragLaw::Stokes => 3.0 * std::f64::consts::PI * mu * d * shape(rho * speed * d / mu),
        DragLaw::SchillerNaumann => {
            let re = rho * speed * d / mu;
            0.5 * rho * area * speed * schiller_naumann_cd(re) * shape(re)
        }
        DragLaw::DiFelice => {
            let re = rho * epsilon * speed * d / mu;
            let cd = (0.63 + 4.8 / re.sqrt()).powi(2);
            let chi = 3.7 - 0.65 * (-(1.5 - re.log10()).powi(2) / 2.0).exp();
            0.5 * rho * area * speed * cd * epsilon.powf(2.0 - chi) * shape(re)
        }
        DragLaw::Gidaspow => {
            let re = rho * epsilon * speed * d / mu;
            // β / (1 − ε): per unit particle volume, finite as ε → 1.
            let beta_per_solid = if epsilon <= 0.8 {
                150.0 * (1.0 - epsilon) * mu / (epsilon * d * d) + 1.75 * rho * speed / d
            } else {
                0.75 * schiller_naumann_cd(re) * epsilon * rho * speed / d * epsilon.powf(-2.65)
            };
            volume * beta_per_solid * shape(re)
        }
        DragLaw::Beetstra => {
            let re = rho * epsilon * speed * d / mu;
            let phi = 1.0 - epsilon;
            let e2 = epsilon * epsilon;
            let f = 10.0 * phi / e2
                + e2 * (1.0 + 1.5 * phi.sqrt())
                + 0.413 * re / (24.0 * e2)
                    * (1.0 / epsilon + 3.0 * epsilon * phi + 8.4 * re.powf(-0.343))
                    / (1.0 + (10.0 as Real).powf(3.0 * phi) * re.powf(-(1.0 + 4.0 * phi) / 2.0));
            3.0 * std::f64::consts::PI * mu * d * epsilon * f * shape(re)
        }
    };
    slip * c
}

#[cfg(test)]
mod tests {
    use super::*;

    const AIR: FluidProperties = FluidProperties {
        density: 1.2,
        viscosity: 1.8e-5,
    };

    fn drag(law: DragLaw, eps: Real, u: Real) -> Real {
        drag_force(law, &AIR, 1e-3, eps, Vector3::new(0.0, 0.0, u), |_| 1.0).z
    }

    #[test]
    fn single_particle_limits() {
        let stokes = 3.0 * std::f64::consts::PI * AIR.viscosity * 1e-3;
        // Creeping flow: every law tends to Stokes's drag at ε = 1 (to its own
        // correction at small Re: Schiller–Naumann 0.15 Re^0.687).
        let u = 1e-6;
        for law in [
            DragLaw::Stokes,
            DragLaw::SchillerNaumann,
            DragLaw::Gidaspow,
            DragLaw::Beetstra,
        ] {
            let f = drag(law, 1.0, u);
            assert!(
                (f / (stokes * u) - 1.0).abs() < 2e-3,
                "{law:?}: {}",
                f / (stokes * u)
            );
        }
        // Gidaspow above ε = 0.8 is Schiller–Naumann at ε = 1.
        let u = 2.0;
        assert!(
            (drag(DragLaw::Gidaspow, 1.0, u) / drag(DragLaw::SchillerNaumann, 1.0, u) - 1.0).abs()
                < 1e-14
        );
        // Di Felice at ε = 1 is the Dallavalle sphere: C_d = (0.63 + 4.8/√Re)².
        let re = AIR.density * u * 1e-3 / AIR.viscosity;
        let cd = (0.63 + 4.8 / re.sqrt()).powi(2);
        let expected = 0.5 * AIR.density * std::f64::consts::PI * 1e-6 / 4.0 * cd * u * u;
        assert!((drag(DragLaw::DiFelice, 1.0, u) / expected - 1.0).abs() < 1e-14);
        // Opposite slip, opposite force.
        assert_eq!(
            drag(DragLaw::Beetstra, 0.5, -u),
            -drag(DragLaw::Beetstra, 0.5, u)
        );
    }

    #[test]
    fn gidaspow_in_a_dense_bed_is_ergun() {
        // n particles per unit volume carry ε ∆p/L of Ergun's pressure gradient
        // (the rest through −V∇p): n F = ε ∆p/L.
        let (eps, superficial, d) = (0.42, 0.05, 1e-3);
        let f = drag_force(
            DragLaw::Gidaspow,
            &AIR,
            d,
            eps,
            Vector3::new(superficial / eps, 0.0, 0.0),
            |_| 1.0,
        )
        .x;
        let n = (1.0 - eps) / (std::f64::consts::PI * d.powi(3) / 6.0);
        let ergun = 150.0 * AIR.viscosity * (1.0 - eps).powi(2) * superficial
            / (eps.powi(3) * d * d)
            + 1.75 * AIR.density * (1.0 - eps) * superficial * superficial / (eps.powi(3) * d);
        assert!((n * f / (eps * ergun) - 1.0).abs() < 1e-13);
    }

    #[test]
    fn beetstra_in_creeping_flow_is_its_dense_limit() {
        // Re → 0: F = 10(1−ε)/ε² + ε²(1 + 1.5√(1−ε)), the low-Re fit of van der Hoef
        // et al. (2005), on Stokes's drag of the superficial slip.
        let (eps, u) = (0.5, 1e-9);
        let f = 10.0 * 0.5 / 0.25 + 0.25 * (1.0 + 1.5 * (0.5 as Real).sqrt());
        let stokes = 3.0 * std::f64::consts::PI * AIR.viscosity * 1e-3;
        assert!((drag(DragLaw::Beetstra, eps, u) / (stokes * eps * u * f) - 1.0).abs() < 1e-4);
    }
}
