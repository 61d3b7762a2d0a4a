//! Contact laws: from contact geometry and relative motion to forces.
//!
//! This layer knows nothing of how contacts were found. A contact is described by the
//! geometry the kernels of [`crate::geometry`] return (overlap volume `V`, projected
//! area `A_n`, unit normal, depth along the normal, contact point) and by the relative
//! velocity at the contact point.
//!
//! # Normal force: Feng's energy-conserving volume law
//!
//! The elastic part derives from the potential `U(V) = ¾ κ V^{4/3}` of the overlap
//! volume, `κ = E₁/R₁ + E₂/R₂` (Young's moduli over volume-equivalent radii). Since the
//! contact-area vector `A_n n` is exactly `∂V/∂x` (see [`crate::geometry::overlap`]),
//! the force `F = U'(V) A_n n = κ A_n V^{1/3} n` is eq. 12–13 of Xu et al.,
//! "Large-Scale Multiple-GPU-based DEM Simulation of Polyhedral Particle Systems", and
//! conserves energy exactly: the work of the elastic force around any closed path is
//! zero.
//!
//! # Normal damping calibrated to the restitution coefficient
//!
//! Xu et al.'s damping (eq. 15) is the linear spring–dashpot's; printed with
//! `2 ln(e)` it is negative, and taken literally it would feed energy in. The volume
//! law is not linear in the depth δ: with `V ∝ δ^a` near contact (a = 1 for a flat face
//! on a face, 2 for an edge, 3 for a vertex), the force grows as `δ^p`, `p = 4a/3 − 1`
//! (p = 1/3, 5/3, 3). A dashpot of constant coefficient would give a restitution that
//! depends on the impact speed. talus uses the tangent stiffness instead:
//!
//! `F_d = −2 ζ √(m_eff k_t) v_n`, `k_t = dF/dδ = p F/δ`,
//!
//! for which the scaled equation of motion `x'' = −x^p − 2ζ√p x^{(p−1)/2} x'` has no
//! speed left in it: the restitution depends on `ζ` and `p` only. `ζ(e, p)` is found
//! once per restitution coefficient by integrating that equation (with the total force
//! kept non-negative, as in the engine: contacts push, never pull) and stored as a
//! table over `p`; for a linear spring it reduces to `ζ = −ln e / √(ln² e + π²)`.
//! `p` is read off each contact's geometry as `p = 4a/3 − 1`, `a = A_n δ / V`.
//!
//! `m_eff` is the effective mass *at the contact point along the normal*:
//! `1/m_eff = Σ_i (1/m_i + (r_i × n) · I_i⁻¹ (r_i × n))`, which for an eccentric impact
//! on a wall is smaller than the particle's mass; callers compute it.
//!
//! # Tangential force
//!
//! Cundall–Strack: a spring on the accumulated tangential displacement (the history,
//! kept per contact pair and rotated into the current tangent plane every step), a
//! dashpot on the tangential velocity, and the Coulomb cap `|F_t| ≤ μ |F_n|`; when
//! sliding, the history is reset to the length that the cap allows.
//!
//! # Hertz–Mindlin for spheres
//!
//! Sphere scenes may choose the law of LIGGGHTS and EDEM instead (see
//! `hertz_mindlin.rs`), with rolling resistance (`rolling.rs`); polyhedron pairs keep
//! the volume law.
//!
//! # Rocking damping and twisting friction
//!
//! The normal dashpot and the friction force act at one point and cannot resist a
//! body rocking or twisting on a face about that point; [`rocking_damping`] and
//! [`twisting_friction`] spread them over the contact area (see `area.rs`).

mod area;
mod damping;
mod hertz_mindlin;
mod material;
mod normal;
mod rolling;
mod tangential;

pub use area::{rocking_damping, twisting_friction};
pub use damping::DampingTable;
pub use hertz_mindlin::{
    HertzContact, HertzMindlinForce, HertzMindlinPair, effective_radius, hertz_mindlin_force,
};
pub use material::{Material, MaterialError, PairStiffness, pair_restitution};
pub use normal::{NormalContact, NormalForce, Regularisation, normal_force};
pub use rolling::{RollingContact, RollingModel, RollingParameters, rolling_torque};
pub use tangential::{TangentialForce, TangentialHistory, tangential_force};
