//! Quadrature: the 5-point Gauss–Legendre rule, and tanh–sinh for integrands with
//! end-point singularities.

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

/// ∫ f over [lo, hi] by tanh–sinh (double exponential) quadrature: the nodes crowd
/// towards the ends doubly exponentially, so an integrand that is analytic inside
/// the interval but has a square-root or any algebraic singularity at an end (a kink
/// of a clipped area, split off at the interval's ends) converges as fast as a
/// smooth one. The step is halved (reusing every node) until two levels agree to
/// `tolerance` (absolute), at most down to 1/64: at most 400 evaluations.
pub fn tanh_sinh(f: &impl Fn(Real) -> Real, lo: Real, hi: Real, tolerance: Real) -> Real {
    let (mid, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
    if half <= 0.0 {
        return 0.0;
    }
    let pi2 = std::f64::consts::FRAC_PI_2;
    // Node u ↦ x = tanh(π/2 sinh u), weight π/2 cosh u / cosh²(π/2 sinh u); beyond
    // |u| = 3.2 the weights are below 1e-20.
    let term = |u: Real| {
        let s = pi2 * u.sinh();
        let (x, c) = (s.tanh(), s.cosh());
        let w = pi2 * u.cosh() / (c * c);
        let (a, b) = (mid + half * x, mid - half * x);
        // Stay inside the interval where the node rounds onto an end.
        let inside = |t: Real| t.clamp(lo, hi);
        w * (f(inside(a)) + if u == 0.0 { 0.0 } else { f(inside(b)) })
    };
    const REACH: Real = 3.2;
    let mut h = 0.5;
    let mut sum: Real = (0..=(REACH / h) as usize)
        .map(|k| term(k as Real * h))
        .sum();
    let mut estimate = sum * h * half;
    for _ in 0..6 {
        h *= 0.5;
        // The new nodes: odd multiples of the halved step.
        sum += (0..)
            .map(|k| (2 * k + 1) as Real * h)
            .take_while(|&u| u <= REACH)
            .map(term)
            .sum::<Real>();
        let next = sum * h * half;
        let converged = (next - estimate).abs() <= tolerance;
        estimate = next;
        if converged {
            break;
        }
    }
    estimate
}

/// Adds to `out` the integrals over `[lo, hi]` of the `out.len()` functions that
/// `f(x, weight, out)` adds, each times `weight`, at `x`: 5-point Gauss–Legendre
/// between consecutive `breaks` (sorted, within `[lo, hi]`, where the functions may
/// have kinks), each interval halved until its two halves agree with the whole to
/// `tolerance` per unit of length (at most 20 times). Every function is evaluated at
/// the same points, so a sum over them is integrated as one function (what
/// partitions of a body need: pieces that add up to its whole add up to the whole's
/// integral to round-off when the rule is exact for it). Returns the estimated
/// error, the largest over the functions, summed over intervals.
pub fn adaptive_gauss(
    breaks: &[Real],
    tolerance: Real,
    out: &mut [Real],
    f: &impl Fn(Real, Real, &mut [Real]),
) -> Real {
    let n = out.len();
    let rule = |lo: Real, hi: Real| {
        let (mid, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
        let mut sum = vec![0.0; n];
        for (x, w) in GAUSS5_NODES.iter().zip(GAUSS5_WEIGHTS) {
            f(mid + half * x, w * half, &mut sum);
        }
        sum
    };
    let mut error = 0.0;
    for w in breaks.windows(2).filter(|w| w[1] > w[0]) {
        let whole = rule(w[0], w[1]);
        error += halve(&rule, (w[0], w[1]), whole, tolerance, 0, out);
    }
    error
}

/// One step of [`adaptive_gauss`]: adds the integral over `span` (`whole`, its
/// estimate) to `out`, halving while the halves disagree with it.
fn halve(
    rule: &impl Fn(Real, Real) -> Vec<Real>,
    span: (Real, Real),
    whole: Vec<Real>,
    tolerance: Real,
    depth: usize,
    out: &mut [Real],
) -> Real {
    let (lo, hi) = span;
    let mid = 0.5 * (lo + hi);
    let (left, right) = (rule(lo, mid), rule(mid, hi));
    let diff = whole
        .iter()
        .zip(left.iter().zip(&right))
        .map(|(w, (l, r))| (l + r - w).abs())
        .fold(0.0, Real::max);
    if diff <= tolerance * (hi - lo) || depth >= 20 {
        for (o, (l, r)) in out.iter_mut().zip(left.iter().zip(&right)) {
            *o += l + r;
        }
        return diff;
    }
    halve(rule, (lo, mid), left, tolerance, depth + 1, out)
        + halve(rule, (mid, hi), right, tolerance, depth + 1, out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_exact_for_degree_nine_and_tanh_sinh_on_end_singularities() {
        // The 5-point rule on [0, 1] is exact up to degree 9.
        let p = |x: Real| x.powi(9) - 3.0 * x.powi(4) + 1.0;
        let exact = 1.0 / 10.0 - 3.0 / 5.0 + 1.0;
        let rule: Real = GAUSS5_NODES
            .iter()
            .zip(GAUSS5_WEIGHTS)
            .map(|(x, w)| 0.5 * w * p(0.5 + 0.5 * x))
            .sum();
        assert!((rule - exact).abs() < 1e-15);
        // ∫₀¹ √x dx = 2/3 and ∫₀¹ x^1.5 dx = 0.4: singular derivatives at an end.
        let s = tanh_sinh(&|x: Real| x.sqrt(), 0.0, 1.0, 1e-15);
        assert!((s - 2.0 / 3.0).abs() < 1e-14, "{s}");
        let s = tanh_sinh(&|x: Real| (1.0 - x).powf(1.5), 0.0, 1.0, 1e-15);
        assert!((s - 0.4).abs() < 1e-14, "{s}");
    }
}
