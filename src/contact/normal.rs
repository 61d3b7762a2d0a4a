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
    /// Regularisation volume `V₀` (`Regularisation::new(0.0)` for the pure law): below
    /// it the potential is quadratic in `V` (see [`normal_force`]).
    pub regularisation: Regularisation,
    /// Time step of the integration, or 0 for none. The damping force is capped at
    /// what stops the normal approach within one step, `m_eff |v_n| / dt`: the
    /// tangent stiffness of a flat (p = 1/3) contact is unbounded as the contact
    /// begins, and an explicit step would otherwise throw the bodies apart.
    pub dt: Real,
}

/// The regularisation volume `V₀` of the normal law with its cube root, which every
/// contact's force and energy need: found once per body type, not per contact (the
/// cube roots of `V₀` were 3 % of a step of the dense dodecahedron bed).
///
/// Invariant: `volume ≥ 0`, and `cbrt` is its cube root (to round-off).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Regularisation {
    volume: Real,
    cbrt: Real,
}

impl Regularisation {
    /// The regularisation volume `volume` (negative values count as 0: the pure law).
    pub fn new(volume: Real) -> Self {
        let volume = volume.max(0.0);
        Regularisation {
            volume,
            cbrt: volume.cbrt(),
        }
    }

    /// The regularisation volume of a cube of side `length`, `V₀ = length³`, whose
    /// cube root is `length` itself.
    pub fn of_length(length: Real) -> Self {
        let length = length.max(0.0);
        Regularisation {
            volume: length.powi(3),
            cbrt: length,
        }
    }

    /// `V₀`.
    #[inline]
    pub fn volume(&self) -> Real {
        self.volume
    }

    /// `V₀^{1/3}`.
    #[inline]
    pub fn cbrt(&self) -> Real {
        self.cbrt
    }

    /// The smaller of two (that of the smaller body of a pair).
    #[inline]
    pub fn min(self, other: Self) -> Self {
        if other.volume < self.volume {
            other
        } else {
            self
        }
    }
}

/// The normal force on body 2 (body 1 feels the opposite).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalForce {
    /// Total normal force on body 2 (elastic plus damping, never attractive).
    pub force: Vector3<Real>,
    /// Its size along the normal (≥ 0).
    pub magnitude: Real,
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
    let Regularisation { volume: v0, cbrt } = c.regularisation;
    let regular = volume < v0;
    let (elastic, energy) = if regular {
        // V₀^{2/3} (a cube root is several times cheaper than a power).
        let scale = cbrt.powi(2);
        (
            c.stiffness * c.area * volume / scale,
            0.5 * c.stiffness * volume * volume / scale,
        )
    } else {
        let v13 = volume.cbrt();
        (
            c.stiffness * c.area * v13,
            0.75 * c.stiffness * volume * v13 - 0.25 * c.stiffness * v0 * cbrt,
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
    let magnitude = magnitude.max(0.0);
    NormalForce {
        force: c.normal * magnitude,
        magnitude,
        elastic,
        energy,
        exponent,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat contact of area `area` and volume `volume`, at rest.
    fn contact(volume: Real, area: Real, regularisation: Regularisation) -> NormalContact {
        NormalContact {
            volume,
            area,
            depth: volume / area,
            normal: Vector3::z(),
            relative_velocity: Vector3::zeros(),
            effective_mass: 1.0,
            stiffness: 1e9,
            regularisation,
            dt: 0.0,
        }
    }

    #[test]
    fn a_regularisation_by_its_length_is_the_one_by_its_volume() {
        let elastic = DampingTable::new(1.0);
        let length = 1e-3;
        let (by_length, by_volume) = (
            Regularisation::of_length(length),
            Regularisation::new(length.powi(3)),
        );
        assert_eq!(by_length.volume(), by_volume.volume());
        for volume in [1e-11, 5e-10, 1e-9, 3e-9, 1e-7] {
            let (a, b) = (
                normal_force(&contact(volume, 1e-4, by_length), &elastic),
                normal_force(&contact(volume, 1e-4, by_volume), &elastic),
            );
            // The cube roots differ by at most an ulp or two.
            assert!((a.elastic / b.elastic - 1.0).abs() < 1e-15, "{volume}");
            assert!((a.energy / b.energy - 1.0).abs() < 1e-15, "{volume}");
        }
        assert_eq!(Regularisation::new(-1.0), Regularisation::new(0.0));
        assert_eq!(by_length.min(Regularisation::of_length(2e-3)), by_length);
    }

    #[test]
    fn the_regularised_potential_is_c1_at_v0_and_its_force_the_gradient() {
        let elastic = DampingTable::new(1.0);
        let (length, area) = (1e-3, 1e-4);
        let r = Regularisation::of_length(length);
        let v0 = r.volume();
        let at = |v: Real| normal_force(&contact(v, area, r), &elastic);
        // Continuous force and energy across V₀: κ A V₀^{1/3} and ½ κ V₀^{4/3}.
        let (below, above) = (at(v0 * (1.0 - 1e-12)), at(v0));
        assert!((below.elastic / above.elastic - 1.0).abs() < 1e-11);
        assert!((above.elastic / (1e9 * area * length) - 1.0).abs() < 1e-15);
        assert!((below.energy / above.energy - 1.0).abs() < 1e-11);
        assert!((above.energy / (0.5 * 1e9 * v0 * length) - 1.0).abs() < 1e-15);
        // U'(V) A is the force on either side (central differences, O(h²)).
        for v in [0.3 * v0, 3.0 * v0] {
            let h = 1e-6 * v;
            let du = (at(v + h).energy - at(v - h).energy) / (2.0 * h);
            assert!((du * area / at(v).elastic - 1.0).abs() < 1e-8, "{v}");
        }
    }
}
