//! Calibration of the normal damping ratio to a restitution coefficient.

use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

use rayon::prelude::*;

use crate::Real;

/// Smallest and largest force exponent `p` of the volume law (face on face: 1/3;
/// vertex on face: 3, or 5 in the regularised range).
const P_MIN: Real = 1.0 / 3.0;
const P_MAX: Real = 5.0;
/// Number of table nodes in `p`.
const NODES: usize = 21;

/// The damping ratio `ζ(p)` that realises one restitution coefficient `e` for contact
/// forces growing as `δ^p`, tabulated over `p ∈ [1/3, 3]` (linear interpolation).
///
/// Invariant: integrating `x'' = −x^p − 2ζ√p x^{(p−1)/2} x'` (total force clamped at
/// zero) from `x = 0, x' = 1` until `x` returns to 0 leaves `x' = −e` at every node.
#[derive(Clone, Debug, PartialEq)]
pub struct DampingTable {
    restitution: Real,
    zeta: [Real; NODES],
}

impl DampingTable {
    /// The table for restitution `e ∈ (0, 1]`: calibrated once per process and value
    /// (a calibration integrates a few hundred scaled impacts, a fair part of a
    /// second), then copied.
    pub fn new(restitution: Real) -> Self {
        static CALIBRATED: OnceLock<Mutex<HashMap<u64, DampingTable>>> = OnceLock::new();
        let e = restitution.clamp(1e-6, 1.0);
        let cache = CALIBRATED.get_or_init(Default::default);
        if let Some(table) = cache.lock().ok().and_then(|c| c.get(&e.to_bits()).cloned()) {
            return table;
        }
        let table = Self::calibrate(e);
        if let Ok(mut c) = cache.lock() {
            c.insert(e.to_bits(), table.clone());
        }
        table
    }

    /// Calibrates every node (independently, so in parallel with the same result).
    fn calibrate(e: Real) -> Self {
        let mut zeta = [0.0; NODES];
        if e < 1.0 {
            zeta.par_iter_mut()
                .enumerate()
                .for_each(|(k, z)| *z = calibrate(node_p(k), e));
        }
        DampingTable {
            restitution: e,
            zeta,
        }
    }

    /// The restitution coefficient this table realises.
    pub fn restitution(&self) -> Real {
        self.restitution
    }

    /// The damping ratios at the nodes, equally spaced in the force exponent from
    /// 1/3 to 5, that [`Self::zeta`] interpolates (`kernels/volume_law.cuh` reads them).
    pub fn nodes(&self) -> &[Real; NODES] {
        &self.zeta
    }

    /// Damping ratio for a contact whose force grows as `δ^p`.
    pub fn zeta(&self, p: Real) -> Real {
        let s = ((p.clamp(P_MIN, P_MAX) - P_MIN) / (P_MAX - P_MIN)) * (NODES - 1) as Real;
        let k = (s.floor() as usize).min(NODES - 2);
        let w = s - k as Real;
        self.zeta[k] * (1.0 - w) + self.zeta[k + 1] * w
    }
}

fn node_p(k: usize) -> Real {
    P_MIN + (P_MAX - P_MIN) * k as Real / (NODES - 1) as Real
}

/// Restitution realised by damping ratio `zeta` for exponent `p`.
pub(crate) fn restitution_of(p: Real, zeta: Real) -> Real {
    let alpha = 2.0 * zeta * p.sqrt();
    let accel = |x: Real, v: Real| -> Real {
        let x = x.max(1e-300);
        let elastic = x.powf(p);
        let damping = alpha * x.powf(0.5 * (p - 1.0)) * v;
        // Contacts push, never pull.
        -(elastic + damping).max(0.0)
    };
    // The scaled contact lasts a time of order one; the step is refined near the
    // start, where the damping coefficient of a sub-linear law is singular. The first
    // instant is integrated by hand: while x ≈ t and x' ≈ 1 the damping takes
    // ∫ α s^{(p−1)/2} ds from the speed (the elastic part is of higher order).
    let t0: Real = 1e-6;
    let (mut x, mut v, mut t) = (
        t0,
        1.0 - alpha * t0.powf(0.5 * (p + 1.0)) / (0.5 * (p + 1.0)),
        t0,
    );
    loop {
        let h = if t < 1e-3 {
            1e-6
        } else if t < 2e-2 {
            2e-5
        } else {
            2e-4
        };
        // Classical Runge–Kutta on (x, v).
        let (k1x, k1v) = (v, accel(x, v));
        let (k2x, k2v) = (
            v + 0.5 * h * k1v,
            accel(x + 0.5 * h * k1x, v + 0.5 * h * k1v),
        );
        let (k3x, k3v) = (
            v + 0.5 * h * k2v,
            accel(x + 0.5 * h * k2x, v + 0.5 * h * k2v),
        );
        let (k4x, k4v) = (v + h * k3v, accel(x + h * k3x, v + h * k3v));
        let nx = x + h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
        let nv = v + h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        t += h;
        if nx <= 0.0 && t > 1e-3 {
            // Separation: interpolate the crossing velocity.
            let w = x / (x - nx);
            return -(v + w * (nv - v));
        }
        if v > 0.0 && nv <= 0.0 && nx <= 1e-300 {
            return 0.0;
        }
        if t > 1e3 {
            // Fully damped: the body never comes back.
            return 0.0;
        }
        x = nx;
        v = nv;
    }
}

/// Damping ratio realising restitution `e` for exponent `p`. The restitution falls
/// monotonically as the damping rises, so the root is bracketed and found by the
/// Illinois variant of regula falsi (superlinear, about a third of bisection's
/// integrations).
fn calibrate(p: Real, e: Real) -> Real {
    let excess = |zeta: Real| restitution_of(p, zeta) - e;
    let (mut lo, mut hi) = (0.0, 1.0);
    let (mut f_lo, mut f_hi) = (excess(lo), excess(hi));
    while f_hi > 0.0 {
        (lo, f_lo) = (hi, f_hi);
        hi *= 2.0;
        if hi > 1e3 {
            return hi;
        }
        f_hi = excess(hi);
    }
    // Which end was kept last time (-1 low, +1 high): a twice-kept end's value is
    // halved, the Illinois step.
    let mut kept = 0;
    for _ in 0..60 {
        let mid = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
        let f_mid = excess(mid);
        if f_mid > 0.0 {
            (lo, f_lo) = (mid, f_mid);
            if kept == 1 {
                f_hi *= 0.5;
            }
            kept = 1;
        } else {
            (hi, f_hi) = (mid, f_mid);
            if kept == -1 {
                f_lo *= 0.5;
            }
            kept = -1;
        }
        if hi - lo < 1e-6 * hi || f_mid.abs() < 1e-7 * e {
            return mid;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn undamped_contact_restores_the_speed() {
        for p in [1.0 / 3.0, 1.0, 5.0 / 3.0, 3.0] {
            let e = restitution_of(p, 0.0);
            assert!((e - 1.0).abs() < 1e-5, "p = {p}: {e}");
        }
    }

    #[test]
    fn linear_spring_matches_the_classical_damping_ratio() {
        // Without the no-pull clamp the linear law has ζ = −ln e / √(ln² e + π²); the
        // clamp only cuts the end of the contact, so the two agree closely for mild
        // damping.
        let e: Real = 0.9;
        let classical = -e.ln() / (e.ln().powi(2) + std::f64::consts::PI.powi(2)).sqrt();
        let zeta = DampingTable::new(e).zeta(1.0);
        assert!(
            (zeta - classical).abs() < 0.03 * classical,
            "{zeta} vs {classical}"
        );
    }

    #[test]
    fn table_realises_the_restitution_at_and_between_nodes() {
        for e in [0.1, 0.5, 0.9] {
            let table = DampingTable::new(e);
            for p in [1.0 / 3.0, 5.0 / 3.0, 3.0, 0.9, 2.2] {
                let got = restitution_of(p, table.zeta(p));
                assert!(
                    (got - e).abs() < 0.01 * e,
                    "e = {e}, p = {p}: realised {got}"
                );
            }
        }
    }
}
