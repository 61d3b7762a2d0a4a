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
    /// Magnitude of the elastic part, `κ A_n V^{1/3}`.
    pub elastic: Real,
    /// Elastic energy stored in the contact, `¾ κ V^{4/3}`.
    pub energy: Real,
    /// Force exponent `p` read off the geometry (1/3 flat, 5/3 edge, 3 vertex).
    pub exponent: Real,
}

/// Feng's volume-based normal force with restitution-calibrated damping (see the
/// module docs of [`crate::contact`]).
pub fn normal_force(c: &NormalContact, damping: &DampingTable) -> NormalForce {
    let v13 = c.volume.max(0.0).cbrt();
    let elastic = c.stiffness * c.area * v13;
    let energy = 0.75 * c.stiffness * c.volume.max(0.0) * v13;
    // V ∝ δ^a near contact, with a = A δ / V (since dV/dδ = A); F ∝ δ^(4a/3 − 1).
    let a = if c.volume > 0.0 {
        (c.area * c.depth / c.volume).clamp(1.0, 3.0)
    } else {
        1.0
    };
    let exponent = 4.0 * a / 3.0 - 1.0;
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
