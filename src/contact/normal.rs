//! The normal contact force.

use nalgebra::Vector3;

use super::DampingTable;
use crate::Real;

/// What the normal law needs to know about one contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalContact {
    /// Overlap volume `V`.
    pub volume: Real,
    /// Projected contact area `A_n` (length of the contact-area vector).
    pub area: Real,
    /// Extent of the overlap along the normal (the depth δ).
    pub depth: Real,
    /// Unit normal, pointing from body 1 to body 2.
    pub normal: Vector3<Real>,
    /// Velocity of body 2 relative to body 1 at the contact point.
    pub relative_velocity: Vector3<Real>,
    /// Effective mass at the contact point along the normal.
    pub effective_mass: Real,
    /// Normal stiffness factor κ of the pair (Pa/m).
    pub stiffness: Real,
    /// Regularisation volume `V₀` (0 for the pure law): below it the potential is
    /// quadratic in `V` (see [`normal_force`]).
    pub regularisation: Real,
    /// Time step of the integration, or 0 for none. The damping force is capped at
    /// what stops the normal approach within one step, `m_eff |v_n| / dt`: the
    /// tangent stiffness of a flat (p = 1/3) contact is unbounded as the contact
    /// begins, and an explicit step would otherwise throw the bodies apart.
    pub dt: Real,
}

/// The normal force on body 2 (body 1 feels the opposite).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalForce {
    /// Total normal force on body 2 (elastic plus damping, never attractive).
    pub force: Vector3<Real>,
    /// Magnitude of the elastic part, `κ A_n V^{1/3}` (or its regularised form).
    pub elastic: Real,
    /// Elastic energy stored in the contact (the potential `U(V)`).
    pub energy: Real,
    /// Force exponent `p` read off the geometry (1/3 flat, 5/3 edge, 3 vertex; 1, 3,
    /// 5 in the regularised range).
    pub exponent: Real,
}

/// Feng's volume-based normal force with restitution-calibrated damping (see the
/// module docs of [`crate::contact`]).
///
/// # Regularisation of flat contacts
/// For a face pressed on a face, `V = A δ` and the pure law gives `F ∝ δ^{1/3}`,
/// whose stiffness is unbounded as δ → 0: a resting face contact would need an
/// overlap of ~1e-19 m and time steps far below a nanosecond. Below a small volume `V₀`
/// the potential is therefore continued quadratically and C¹:
///
/// `U = ½ κ V² / V₀^{2/3}` for `V ≤ V₀`, `U = ¾ κ V^{4/3} − ¼ κ V₀^{4/3}` above,
///
/// so the force is `κ A V / V₀^{2/3}` (linear in δ for a flat contact, with the finite
/// stiffness `κ A² / V₀^{2/3}`), still the gradient of a potential of `V`, and equal
/// to the volume law of Xu et al. above `V₀`.
pub fn normal_force(c: &NormalContact, damping: &DampingTable) -> NormalForce {
    let volume = c.volume.max(0.0);
    let v0 = c.regularisation.max(0.0);
    let regular = volume < v0;
    let (elastic, energy) = if regular {
        // V₀^{2/3} (a cube root is several times cheaper than a power).
        let scale = v0.cbrt().powi(2);
        (
            c.stiffness * c.area * volume / scale,
            0.5 * c.stiffness * volume * volume / scale,
        )
    } else {
        let v13 = volume.cbrt();
        (
            c.stiffness * c.area * v13,
            0.75 * c.stiffness * volume * v13 - 0.25 * c.stiffness * v0 * v0.cbrt(),
        )
    };
    // V ∝ δ^a near contact, with a = A δ / V (since dV/dδ = A); the force grows as
    // δ^(4a/3 − 1), or δ^(2a − 1) in the regularised range.
    let a = if volume > 0.0 {
        (c.area * c.depth / volume).clamp(1.0, 3.0)
    } else {
        1.0
    };
    let exponent = if regular {
        2.0 * a - 1.0
    } else {
        4.0 * a / 3.0 - 1.0
    };
    let mut magnitude = elastic;
    if c.depth > 0.0 && damping.restitution() < 1.0 {
        let tangent_stiffness = exponent * elastic / c.depth;
        let coefficient =
            2.0 * damping.zeta(exponent) * (c.effective_mass * tangent_stiffness).sqrt();
        // Approaching (v_n < 0) adds to the repulsion; separating takes from it.
        let vn = c.relative_velocity.dot(&c.normal);
        let mut damping_force = coefficient * vn.abs();
        if c.dt > 0.0 {
            damping_force = damping_force.min(c.effective_mass * vn.abs() / c.dt);
        }
        magnitude -= damping_force * vn.signum();
    }
    NormalForce {
        force: c.normal * magnitude.max(0.0),
        elastic,
        energy,
        exponent,
    }
}
