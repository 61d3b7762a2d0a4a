//! The Hertz–Mindlin law of sphere contacts, as LIGGGHTS and EDEM define it, so that
//! parameters calibrated there carry over.
//!
//! With the overlap δ, the effective radius `R*` (`1/R* = 1/R₁ + 1/R₂`, a flat wall or
//! a polyhedron's face counting as infinite), the effective mass `m*`, and the contact
//! radius `a = √(R* δ)`:
//!
//! - normal: `F_n = 4/3 E* a δ − γ_n v_n`, the Hertz force with a dashpot on the normal
//!   approach velocity, `γ_n = −2 √(5/6) β √(S_n m*)`, `S_n = 2 E* a` (the tangent
//!   stiffness) and `β = ln e / √(ln² e + π²)`. Since `S_n ∝ δ^{1/2}`, the realised
//!   restitution depends on `e` alone, not on the impact speed (Tsuji et al. 1992);
//!   it is not `e` itself (`tests/validation_hertz.rs` measures it), as in those
//!   codes. The force never pulls: it is clamped at zero, LIGGGHTS's `limitForce`.
//! - tangential: Mindlin's no-slip stiffness `k_t = 8 G* a`, a dashpot
//!   `γ_t = −2 √(5/6) β √(k_t m*)`, a spring on the accumulated tangential
//!   displacement and the Coulomb cap `μ F_n` ([`tangential_force`]);
//! - `E* = 1 / ((1 − ν₁²)/E₁ + (1 − ν₂²)/E₂)`,
//!   `G* = 1 / (2 (2 − ν₁)(1 + ν₁)/E₁ + 2 (2 − ν₂)(1 + ν₂)/E₂)`.

use nalgebra::Vector3;

use super::{Material, TangentialHistory, tangential_force};
use crate::Real;

/// `2 √(5/6)`, the factor of the damping coefficients.
const DAMPING_FACTOR: Real = 1.825_741_858_350_553_7;

/// Elastic constants and damping of a pair of materials under Hertz–Mindlin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HertzMindlinPair {
    /// Effective Young's modulus `E*`, Pa.
    pub young: Real,
    /// Effective shear modulus `G*`, Pa.
    pub shear: Real,
    /// `β = ln e / √(ln² e + π²)` ≤ 0 (0 for an elastic pair).
    pub beta: Real,
    /// `√(4G*/E*)`, the ratio of the tangential to the normal damping coefficient
    /// (`k_t / S_n = 4G*/E*`), kept so that a contact takes one square root for both.
    pub damping_ratio: Real,
}

impl HertzMindlinPair {
    /// Between materials `a` and `b` with the pair's restitution `e`.
    pub fn new(a: &Material, b: &Material, e: Real) -> Self {
        let compliance = |m: &Material| (1.0 - m.poisson * m.poisson) / m.young;
        let shear_compliance = |m: &Material| 2.0 * (2.0 - m.poisson) * (1.0 + m.poisson) / m.young;
        let log = e.ln();
        let young = 1.0 / (compliance(a) + compliance(b));
        let shear = 1.0 / (shear_compliance(a) + shear_compliance(b));
        HertzMindlinPair {
            young,
            shear,
            beta: log / (log * log + std::f64::consts::PI.powi(2)).sqrt(),
            damping_ratio: (4.0 * shear / young).sqrt(),
        }
    }
}

/// The effective radius `R* = R₁R₂/(R₁ + R₂)` of two bodies' radii of curvature at a
/// contact, an infinite radius standing for a flat body.
#[inline]
pub fn effective_radius(r1: Real, r2: Real) -> Real {
    if r2.is_infinite() {
        r1
    } else if r1.is_infinite() {
        r2
    } else {
        r1 * r2 / (r1 + r2)
    }
}

/// One contact of two spheres, or of a sphere and a flat body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HertzContact {
    /// Overlap δ > 0.
    pub depth: Real,
    /// Unit normal, from body 1 to body 2.
    pub normal: Vector3<Real>,
    /// Velocity of body 2 relative to body 1 at the contact point.
    pub relative_velocity: Vector3<Real>,
    /// Effective radius `R*`.
    pub radius: Real,
    /// Effective mass `m*`.
    pub mass: Real,
}

/// What a Hertz–Mindlin contact puts on body 2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HertzMindlinForce {
    /// Normal plus tangential force on body 2.
    pub force: Vector3<Real>,
    /// Whether the contact slides (the Coulomb cap is active).
    pub sliding: bool,
    /// Magnitude of the normal force (≥ 0).
    pub normal: Real,
    /// Magnitude of its elastic part, `4/3 E* √R* δ^{3/2}` (the rest is damping).
    pub elastic: Real,
    /// Secant normal stiffness `4/3 E* a` (what the rolling spring is scaled by).
    pub stiffness: Real,
    /// Elastic energy of the normal law, `8/15 E* √R* δ^{5/2}`.
    pub energy: Real,
    /// The tangential spring to keep.
    pub history: TangentialHistory,
}

/// The Hertz–Mindlin force on body 2 of contact `c` (see the module docs), with
/// friction coefficient `friction` and the contact's `history`.
#[inline(always)]
pub fn hertz_mindlin_force(
    c: &HertzContact,
    pair: &HertzMindlinPair,
    friction: Real,
    history: &TangentialHistory,
    dt: Real,
) -> HertzMindlinForce {
    let a = (c.radius * c.depth).sqrt();
    let tangent = 2.0 * pair.young * a;
    let stiffness = (2.0 / 3.0) * tangent;
    let elastic = stiffness * c.depth;
    let damping_n = -DAMPING_FACTOR * pair.beta * (tangent * c.mass).sqrt();
    let vn = c.relative_velocity.dot(&c.normal);
    let normal = (elastic - damping_n * vn).max(0.0);
    let kt = 8.0 * pair.shear * a;
    let damping_t = damping_n * pair.damping_ratio;
    let t = tangential_force(
        history,
        &c.normal,
        &c.relative_velocity,
        dt,
        kt,
        damping_t,
        friction * normal,
    );
    HertzMindlinForce {
        force: c.normal * normal + t.force,
        sliding: t.sliding,
        normal,
        elastic,
        stiffness,
        energy: 0.4 * elastic * c.depth,
        history: t.history,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn material(young: Real, poisson: Real) -> Material {
        Material::of_tests("", 2500.0, young, poisson)
    }

    #[test]
    fn effective_moduli_and_damping() {
        let m = material(1e7, 0.3);
        let p = HertzMindlinPair::new(&m, &m, 0.5);
        assert!((p.young - 1e7 / (2.0 * 0.91)).abs() < 1e-6);
        assert!((p.shear - 1e7 / (4.0 * 1.7 * 1.3)).abs() < 1e-6);
        // β of e = 0.5: ln 0.5 / √(ln² 0.5 + π²).
        assert!((p.beta + 0.215_453_761_966).abs() < 1e-11, "{}", p.beta);
        assert_eq!(HertzMindlinPair::new(&m, &m, 1.0).beta, 0.0);
        assert!((DAMPING_FACTOR - 2.0 * (5.0 as Real / 6.0).sqrt()).abs() < 1e-15);
    }

    /// At rest the force is Hertz's `4/3 E* √R δ^{3/2}` and the energy its integral.
    #[test]
    fn static_force_and_energy_are_hertz() {
        let m = material(1e7, 0.3);
        let p = HertzMindlinPair::new(&m, &m, 0.5);
        let force = |d: Real| {
            let c = HertzContact {
                depth: d,
                normal: Vector3::z(),
                relative_velocity: Vector3::zeros(),
                radius: 0.0025,
                mass: 1e-3,
            };
            hertz_mindlin_force(&c, &p, 0.5, &TangentialHistory::default(), 1e-5)
        };
        let f = force(1e-4);
        let hertz = 4.0 / 3.0 * p.young * (0.0025 as Real).sqrt() * (1e-4 as Real).powf(1.5);
        assert!((f.normal / hertz - 1.0).abs() < 1e-12);
        // Energy: ∫ F dδ by Simpson's rule.
        let n = 1000;
        let h = 1e-4 / n as Real;
        let integral: Real = (0..=n)
            .map(|k| {
                let w = if k == 0 || k == n {
                    1.0
                } else if k % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                w * force((k as Real * h).max(1e-30)).normal
            })
            .sum::<Real>()
            * h
            / 3.0;
        assert!(
            (f.energy / integral - 1.0).abs() < 1e-6,
            "{} {integral}",
            f.energy
        );
    }
}
