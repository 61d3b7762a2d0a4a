//! Gauss–Legendre quadrature: the 5-point rule and an adaptive scalar integral.

use crate::Real;

/// Nodes of the 5-point Gauss–Legendre rule on [−1, 1].
pub const GAUSS5_NODES: [Real; 5] = [
    0.0,
    -0.538_469_310_105_683_1,
    0.538_469_310_105_683_1,
    -0.906_179_845_938_664,
    0.906_179_845_938_664,
];

/// Weights of the 5-point Gauss–Legendre rule on [−1, 1] (they sum to 2).
pub const GAUSS5_WEIGHTS: [Real; 5] = [
    0.568_888_888_888_888_9,
    0.478_628_670_499_366_5,
    0.478_628_670_499_366_5,
    0.236_926_885_056_189_1,
    0.236_926_885_056_189_1,
];

/// ∫ f over [lo, hi] by the 5-point rule.
pub fn gauss5(f: &impl Fn(Real) -> Real, lo: Real, hi: Real) -> Real {
    let (mid, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
    GAUSS5_NODES
        .iter()
        .zip(GAUSS5_WEIGHTS)
        .map(|(x, w)| w * f(mid + half * x))
        .sum::<Real>()
        * half
}

/// ∫ f over [lo, hi], halving until the two halves agree with the whole to
/// `tolerance` per unit length (at most 30 halvings deep). `f` should be smooth
/// inside the interval: split it where `f` has kinks.
pub fn adaptive_gauss5(f: &impl Fn(Real) -> Real, lo: Real, hi: Real, tolerance: Real) -> Real {
    refine(f, lo, hi, gauss5(f, lo, hi), tolerance, 0)
}

fn refine(
    f: &impl Fn(Real) -> Real,
    lo: Real,
    hi: Real,
    whole: Real,
    tolerance: Real,
    depth: u32,
) -> Real {
    let mid = 0.5 * (lo + hi);
    let (left, right) = (gauss5(f, lo, mid), gauss5(f, mid, hi));
    if (left + right - whole).abs() <= tolerance * (hi - lo) || depth >= 30 {
        return left + right;
    }
    refine(f, lo, mid, left, tolerance, depth + 1) + refine(f, mid, hi, right, tolerance, depth + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_for_degree_nine_and_adaptive_on_a_square_root() {
        let p = |x: Real| x.powi(9) - 3.0 * x.powi(4) + 1.0;
        let exact = (1.0 - 0.0) / 10.0 - 3.0 / 5.0 + 1.0;
        assert!((gauss5(&p, 0.0, 1.0) - exact).abs() < 1e-15);
        // ∫₀¹ √x dx = 2/3: a singular derivative at 0, reached by halving.
        let s = adaptive_gauss5(&|x: Real| x.sqrt(), 0.0, 1.0, 1e-13);
        assert!((s - 2.0 / 3.0).abs() < 1e-12, "{s}");
    }
}
