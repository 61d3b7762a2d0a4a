//! The signs of a rotating drum's flow regime, measured in the run itself: what
//! the central slice's particles do relative to the turning shell, sampled with
//! the drum's other figures (for Mellmann 2001's regimes: slipping, slumping,
//! rolling, cascading, cataracting, centrifuging).
//!
//! Each sample gives four signs, in cross-section coordinates `(h, v)` about the
//! axis, where the shell's velocity at a point `p` is `ω â × p = ω (−v, h)`:
//! - **co-rotation**: how fast the rim layer (centres within 1.5 diameters of the
//!   shell, below the free surface) moves with the shell, `Σ V u·w / Σ V |w|²`
//!   (`w` the shell's velocity at the particle): 1 when the bed turns with the
//!   drum, 0 when it stays put as the shell slides under it;
//! - **rim coverage**: the fraction of 24 sectors of the rim in which the rim layer
//!   has a particle: 1 for a ring around the whole shell;
//! - **activity**: the bed's mean squared speed relative to the turning drum over
//!   `(ω R)²`, `Σ V |u − w|² / (Σ V (ω R)²)`: nearly 0 while the bed turns as a
//!   rigid body, which a slumping bed does between its avalanches;
//! - **surface curvature**: the root mean square distance of the surface particles
//!   (each column's top, as the angle of repose finds them) from the fitted line,
//!   over the surface's chord: the S or kidney shape of a cascading bed against
//!   the straight surface of a rolling one.
//!
//! Over the analysis window these are averaged ([`FlowSigns`]); with the fraction
//! in flight ([`super::DrumSummary::airborne_fraction`]) they name the regime
//! ([`Regime::of`]): a ring on the shell centrifuges; a rim layer that moves at
//! less than half the shell's speed slips; a tenth of the slice in flight
//! cataracts; a bed at rest in the drum in three samples of ten slumps; a curved
//! surface cascades; a straight one rolls. The thresholds were set against the
//! quasi-2D example's sweep over Froude numbers 1e-4 … 1.5 and Mellmann's (2001)
//! bands (`examples/drum/README.md`).

use serde::{Deserialize, Serialize};

use super::surface::{SurfaceFit, surface_points};
use crate::Real;

/// Sectors of the rim counted for its coverage.
const SECTORS: usize = 24;
/// The rim layer: centres within this many diameters of the shell.
const RIM_LAYER: Real = 1.5;
/// A sample is at rest in the drum when its activity is below this share of the
/// window's mean activity.
pub const AT_REST: Real = 0.1;

/// Rim coverage of a centrifuging bed: a ring around the shell.
pub const RING: Real = 0.9;
/// Co-rotation below which the bed slips: its rim layer moves at less than half
/// the shell's speed.
pub const SLIPPING: Real = 0.5;
/// Fraction of the slice in flight (more than two diameters above the fitted
/// surface) of a cataracting bed.
pub const THROWN: Real = 0.1;
/// Share of samples at rest in the drum of a slumping bed.
pub const SLUMPING: Real = 0.3;
/// Surface curvature of a cascading bed (an S or kidney-shaped surface); a
/// straight, rolling surface stays below (the synthetic beds of the tests: 0.016 for
/// a straight surface of packed spheres, 0.060 for an S of two diameters' bulge).
pub const CURVED: Real = 0.04;

/// The forms of transverse motion in a rotating drum, after Mellmann (2001), in
/// the order of growing Froude number (slipping aside: it needs a smooth shell).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Regime {
    /// The bed slides on the shell instead of turning with it.
    Slipping,
    /// The bed turns with the drum and avalanches from time to time.
    Slumping,
    /// A continuous flowing layer under a straight surface.
    Rolling,
    /// A continuous flowing layer under a curved (S-shaped) surface.
    Cascading,
    /// Particles thrown from the rising bed into free flight.
    Cataracting,
    /// A ring on the shell.
    Centrifuging,
}

impl Regime {
    /// The regime the signs of a window show, with `airborne` the fraction of the
    /// slice in flight; `None` with the drum at rest (no co-rotation to measure).
    pub fn of(signs: &FlowSigns, airborne: Option<Real>) -> Option<Regime> {
        let co_rotation = signs.co_rotation?;
        Some(if signs.rim_coverage >= RING {
            Regime::Centrifuging
        } else if co_rotation < SLIPPING {
            Regime::Slipping
        } else if airborne.unwrap_or(0.0) >= THROWN {
            Regime::Cataracting
        } else if signs.at_rest >= SLUMPING {
            Regime::Slumping
        } else if signs.surface_curvature.unwrap_or(0.0) >= CURVED {
            Regime::Cascading
        } else {
            Regime::Rolling
        })
    }

    /// Its name, as `drum.json` writes it.
    pub fn name(self) -> &'static str {
        match self {
            Regime::Slipping => "slipping",
            Regime::Slumping => "slumping",
            Regime::Rolling => "rolling",
            Regime::Cascading => "cascading",
            Regime::Cataracting => "cataracting",
            Regime::Centrifuging => "centrifuging",
        }
    }
}

/// The signs of a window's flow regime (see the module).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FlowSigns {
    /// Mean co-rotation of the rim layer (`None` with the drum at rest).
    pub co_rotation: Option<Real>,
    /// Mean rim coverage.
    pub rim_coverage: Real,
    /// Fraction of samples with the bed at rest in the drum (activity below
    /// [`AT_REST`] times its mean).
    pub at_rest: Real,
    /// Mean surface curvature (`None` without a surface).
    pub surface_curvature: Option<Real>,
}

/// The signs summed over a window's samples (serialised with the drum monitor, so
/// that a resumed run keeps them).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct FlowSignSums {
    co_rotation: (Real, usize),
    coverage: (Real, usize),
    curvature: (Real, usize),
    activity: Vec<Real>,
}

impl FlowSignSums {
    /// Adds a sample of the slice's `particles` (centre, velocity, volume in
    /// cross-section coordinates) in a drum of `radius` turning at `omega` (rad/s
    /// about its axis), of particles of `diameter`, whose surface is `fit`.
    pub fn add(
        &mut self,
        particles: &[([Real; 2], [Real; 2], Real)],
        omega: Real,
        radius: Real,
        diameter: Real,
        fit: Option<&SurfaceFit>,
    ) {
        let rim = |p: &[Real; 2]| p[0].hypot(p[1]) > radius - RIM_LAYER * diameter;
        let shell = |p: &[Real; 2]| [-omega * p[1], omega * p[0]];
        let (mut along, mut shell_squared) = (0.0, 0.0);
        let mut sectors = [false; SECTORS];
        let (mut relative, mut volume) = (0.0, 0.0);
        for (p, u, v) in particles {
            let w = shell(p);
            relative += v * ((u[0] - w[0]).powi(2) + (u[1] - w[1]).powi(2));
            volume += v;
            if rim(p) {
                let turn = p[1].atan2(p[0]).rem_euclid(std::f64::consts::TAU);
                sectors[((turn / std::f64::consts::TAU * SECTORS as Real) as usize)
                    .min(SECTORS - 1)] = true;
                if fit.is_none_or(|f| f.height_above(p[0], p[1]) < 0.0) {
                    along += v * (u[0] * w[0] + u[1] * w[1]);
                    shell_squared += v * (w[0] * w[0] + w[1] * w[1]);
                }
            }
        }
        if shell_squared > 0.0 {
            self.co_rotation.0 += along / shell_squared;
            self.co_rotation.1 += 1;
        }
        self.coverage.0 += sectors.iter().filter(|&&s| s).count() as Real / SECTORS as Real;
        self.coverage.1 += 1;
        let rim_speed = (omega * radius).powi(2);
        if volume > 0.0 && rim_speed > 0.0 {
            self.activity.push(relative / (volume * rim_speed));
        }
        if let Some(f) = fit {
            let points: Vec<[Real; 2]> = particles.iter().map(|p| p.0).collect();
            if let Some(c) = curvature(&surface_points(&points, diameter), f) {
                self.curvature.0 += c;
                self.curvature.1 += 1;
            }
        }
    }

    /// The signs of the samples so far; `None` before any sample.
    pub fn signs(&self) -> Option<FlowSigns> {
        let mean = |(sum, n): (Real, usize)| (n > 0).then(|| sum / n as Real);
        Some(FlowSigns {
            co_rotation: mean(self.co_rotation),
            rim_coverage: mean(self.coverage)?,
            at_rest: at_rest(&self.activity),
            surface_curvature: mean(self.curvature),
        })
    }
}

/// The fraction of `activity` samples below [`AT_REST`] times their mean.
fn at_rest(activity: &[Real]) -> Real {
    if activity.is_empty() {
        return 0.0;
    }
    let mean = activity.iter().sum::<Real>() / activity.len() as Real;
    let resting = activity.iter().filter(|&&a| a < AT_REST * mean).count();
    resting as Real / activity.len() as Real
}

/// The root mean square distance of `surface` points from `fit`'s line over the
/// chord they span along it; `None` for fewer than three points.
fn curvature(surface: &[[Real; 2]], fit: &SurfaceFit) -> Option<Real> {
    if surface.len() < 3 {
        return None;
    }
    let along = |p: &[Real; 2]| (p[0] + fit.slope * p[1]) / (1.0 + fit.slope * fit.slope).sqrt();
    let (lo, hi) = surface
        .iter()
        .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(along(p)), hi.max(along(p)))
        });
    let mean_square = surface
        .iter()
        .map(|p| fit.height_above(p[0], p[1]).powi(2))
        .sum::<Real>()
        / surface.len() as Real;
    (hi > lo).then(|| mean_square.sqrt() / (hi - lo))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::surface::fit_surface;

    const R: Real = 0.1;
    const D: Real = 0.01;

    type Slice = Vec<([Real; 2], [Real; 2], Real)>;

    /// A hexagonal packing of spheres of diameter `D` in the drum below the surface
    /// `v = tan(angle) h + bulge sin(π h / R)` (an S for a bulge), turning with the
    /// drum at `omega` except a layer two diameters deep that flows down the slope
    /// at `flow` m/s.
    fn bed(angle: Real, bulge: Real, omega: Real, flow: Real) -> Slice {
        let slope = angle.to_radians().tan();
        let top = |h: Real| slope * h + bulge * (std::f64::consts::PI * h / R).sin();
        let downhill = [-1.0, -slope];
        let norm = downhill[0].hypot(downhill[1]);
        let mut out = Vec::new();
        for j in -20..20 {
            for i in -20..20 {
                let h = (i as Real + 0.5 * (j & 1) as Real) * D;
                let v = j as Real * D * 0.75f64.sqrt();
                if h.hypot(v) > R - 0.5 * D || v > top(h) {
                    continue;
                }
                let mut u = [-omega * v, omega * h];
                if v > top(h) - 2.0 * D {
                    u[0] += flow * downhill[0] / norm;
                    u[1] += flow * downhill[1] / norm;
                }
                out.push(([h, v], u, 1.0));
            }
        }
        out
    }

    fn signs_of(samples: &[Slice], omega: Real) -> FlowSigns {
        let mut signs = FlowSignSums::default();
        for s in samples {
            let points: Vec<[Real; 2]> = s.iter().map(|p| p.0).collect();
            let fit = fit_surface(&points, D);
            signs.add(s, omega, R, D, fit.as_ref());
        }
        signs.signs().expect("samples")
    }

    #[test]
    fn a_bed_turning_with_the_drum_under_a_straight_flowing_surface() {
        for omega in [2.0, -2.0] {
            let s = signs_of(&[bed(35.0, 0.0, omega, 0.3)], omega);
            // The flowing layer's ends reach the rim layer.
            assert!(s.co_rotation.unwrap() > 0.95, "{s:?}");
            assert!(s.rim_coverage < 0.6 && s.at_rest == 0.0, "{s:?}");
            assert!(s.surface_curvature.unwrap() < 0.02, "{s:?}");
        }
    }

    #[test]
    fn an_s_shaped_surface_is_curved() {
        let s = signs_of(&[bed(40.0, 2.0 * D, 3.0, 0.5)], 3.0);
        assert!(s.surface_curvature.unwrap() > 0.04, "{s:?}");
    }

    #[test]
    fn a_bed_at_rest_in_a_turning_drum_does_not_co_rotate() {
        let s = signs_of(&[bed(20.0, 0.0, 0.0, 0.0)], 2.0);
        assert!(s.co_rotation.unwrap().abs() < 1e-12, "{s:?}");
    }

    #[test]
    fn a_bed_that_turns_rigidly_between_avalanches_is_at_rest_in_between() {
        let mut samples = vec![bed(30.0, 0.0, 0.5, 0.0); 8];
        samples.extend([bed(30.0, 0.0, 0.5, 0.4), bed(30.0, 0.0, 0.5, 0.4)]);
        let s = signs_of(&samples, 0.5);
        assert!((s.at_rest - 0.8).abs() < 1e-12, "{s:?}");
        assert_eq!(signs_of(&samples[8..], 0.5).at_rest, 0.0);
    }

    #[test]
    fn a_ring_on_the_shell_covers_the_rim() {
        let omega = 12.0;
        let ring: Slice = (0..60)
            .map(|k| {
                let a = k as Real * std::f64::consts::TAU / 60.0;
                let p = [(R - 0.5 * D) * a.cos(), (R - 0.5 * D) * a.sin()];
                (p, [-omega * p[1], omega * p[0]], 1.0)
            })
            .collect();
        let mut signs = FlowSignSums::default();
        signs.add(&ring, omega, R, D, None);
        let s = signs.signs().unwrap();
        assert_eq!((s.rim_coverage, s.co_rotation), (1.0, Some(1.0)));
    }

    /// The synthetic beds are named for what they are built to be.
    #[test]
    fn the_synthetic_beds_are_named_for_what_they_are() {
        let name = |s: &FlowSigns, airborne| Regime::of(s, Some(airborne));
        let rolling = signs_of(&[bed(35.0, 0.0, 2.0, 0.3)], 2.0);
        let cascading = signs_of(&[bed(40.0, 2.0 * D, 3.0, 0.5)], 3.0);
        assert_eq!(name(&rolling, 0.0), Some(Regime::Rolling));
        assert_eq!(name(&cascading, 0.0), Some(Regime::Cascading));
        // The same beds with an eighth of the slice in flight.
        assert_eq!(name(&rolling, 0.125), Some(Regime::Cataracting));
        let mut slumping = vec![bed(30.0, 0.0, 0.5, 0.0); 8];
        slumping.extend([bed(30.0, 0.0, 0.5, 0.4), bed(30.0, 0.0, 0.5, 0.4)]);
        assert_eq!(name(&signs_of(&slumping, 0.5), 0.0), Some(Regime::Slumping));
        let still = signs_of(&[bed(20.0, 0.0, 0.0, 0.0)], 2.0);
        assert_eq!(name(&still, 0.0), Some(Regime::Slipping));
        let ring = FlowSigns {
            co_rotation: Some(1.0),
            rim_coverage: 1.0,
            at_rest: 0.0,
            surface_curvature: None,
        };
        assert_eq!(name(&ring, 0.0), Some(Regime::Centrifuging));
        let resting = FlowSigns {
            co_rotation: None,
            ..ring
        };
        assert_eq!(Regime::of(&resting, None), None);
        assert_eq!(
            serde_json::to_string(&Regime::Cataracting).unwrap(),
            "\"cataracting\""
        );
        assert_eq!(Regime::Cataracting.name(), "cataracting");
    }
}
