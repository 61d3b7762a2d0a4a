//! What a pseudo-homogeneous reactor model needs of a packed bed besides its
//! porosity: the specific surface area, the characteristic diameters, the share of
//! particles at the wall and the permeability the bed's own figures give.
//!
//! **Definitions.** Over the region of the bed average, a particle counts with the
//! share of its volume inside the region, `wᵢ = V_in,ᵢ / Vᵢ` (exact, from the same
//! clipped volumes as the porosity), and with its surface in that share:
//! `a_v = Σ wᵢ Sᵢ / V_bed` (the surface of a particle cut by the region's boundary
//! is taken in proportion to its volume there, exact on average over a random
//! bed). The Sauter diameter is `d_S = 6 Σ wᵢVᵢ / Σ wᵢSᵢ`, the volume-equivalent
//! diameter that of the mean particle volume `Σ wᵢVᵢ / Σ wᵢ`; their ratio is the
//! sphericity of a bed of one kind. Ergun's and Kozeny–Carman's permeabilities take
//! the bed's porosity and `d_S` (Ergun's `φ d_v`).

use serde::Serialize;

use crate::Real;

/// Reactor-model figures of a packed bed (see the module docs); all 0 but the wall
/// contacts when the region holds no solid.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ReactorFigures {
    /// Specific surface area: particle surface per bed volume over the region, 1/m.
    pub specific_surface: Real,
    /// Sauter diameter `6 V / S` of the particles in the region, m.
    pub sauter_diameter: Real,
    /// Diameter of the sphere of the mean particle volume in the region, m.
    pub volume_equivalent_diameter: Real,
    /// Sauter over volume-equivalent diameter (for one kind of particle: its
    /// sphericity).
    pub sphericity: Real,
    /// Of the particles with their centroid in the region, the share within `gap` of
    /// the tube wall.
    pub wall_contact_fraction: Real,
    /// Kozeny–Carman permeability `ε³ d_S² / (180 (1 − ε)²)`, m².
    pub permeability_kozeny_carman: Real,
    /// Ergun's viscous permeability `ε³ d_S² / (150 (1 − ε)²)`, m²: with the next,
    /// `∆p / L = μ U / K + β ρ U²`.
    pub permeability_ergun: Real,
    /// Ergun's inertial coefficient `β = 1.75 (1 − ε) / (ε³ d_S)`, 1/m.
    pub inertial_coefficient_ergun: Real,
}

/// The particles' share of a region: volume, surface and count, each particle
/// weighted by the share of its volume inside.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct SolidShare {
    /// `Σ wᵢ Vᵢ`, m³.
    pub volume: Real,
    /// `Σ wᵢ Sᵢ`, m².
    pub surface: Real,
    /// `Σ wᵢ`.
    pub count: Real,
}

impl ReactorFigures {
    /// The figures of a region of `bed_volume` holding `solid`, at `porosity`.
    pub(super) fn new(
        bed_volume: Real,
        porosity: Real,
        solid: SolidShare,
        wall_contact_fraction: Real,
    ) -> Self {
        if !(solid.volume > 0.0) {
            // No solid in the region: no surface, no diameter, and no finite
            // permeability to speak of.
            return ReactorFigures {
                specific_surface: 0.0,
                sauter_diameter: 0.0,
                volume_equivalent_diameter: 0.0,
                sphericity: 0.0,
                wall_contact_fraction,
                permeability_kozeny_carman: 0.0,
                permeability_ergun: 0.0,
                inertial_coefficient_ergun: 0.0,
            };
        }
        let e = porosity;
        let d_s = 6.0 * solid.volume / solid.surface;
        let d_v = (6.0 * solid.volume / (solid.count * std::f64::consts::PI)).cbrt();
        let k = e.powi(3) * d_s * d_s / (1.0 - e).powi(2);
        ReactorFigures {
            specific_surface: solid.surface / bed_volume,
            sauter_diameter: d_s,
            volume_equivalent_diameter: d_v,
            sphericity: d_s / d_v,
            wall_contact_fraction,
            permeability_kozeny_carman: k / 180.0,
            permeability_ergun: k / 150.0,
            inertial_coefficient_ergun: 1.75 * (1.0 - e) / (e.powi(3) * d_s),
        }
    }
}
