//! Minimum fluidisation of the poured bed of `examples/fluid_bed` (1000 glass beads
//! of 2 mm in air, Gidaspow drag) against the Wen–Yu correlation, with the gas side
//! played by a 1-D plug-flow model as a coupled CFD code would: the interstitial
//! velocity `U / ε` and the pressure gradient of each slab's momentum balance set,
//! the solid fraction and momentum source read back.

use std::f64::consts::PI;
use std::ops::ControlFlow;
use std::path::Path;

use nalgebra::Vector3;
use talus::Real;
use talus::scene::{Scene, Simulation};

const RHO_P: Real = 2500.0;
const RHO_F: Real = 1.2;
const MU: Real = 1.8e-5;
const D: Real = 2e-3;
const G: Real = 9.81;
const AREA: Real = 0.024 * 0.024;

fn bed() -> Simulation {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/fluid_bed/fluid_bed.toml");
    Simulation::new(&Scene::load(&path).unwrap())
}

fn porosity(sim: &Simulation) -> Vec<Real> {
    sim.fluid()
        .unwrap()
        .solid_fraction
        .iter()
        .map(|s| 1.0 - s)
        .collect()
}

/// The plug-flow gas at superficial velocity `u`: `u / ε` up in every slab, and the
/// pressure gradient of each slab's steady momentum balance (model A) from the drag
/// the particles took in it, `∇p = ρ_f g − Σf_d / (ε V)`.
fn set_gas(sim: &mut Simulation, u: Real, drag: &[Vector3<Real>]) {
    let eps = porosity(sim);
    // Slabs of one size.
    let volume = sim.fluid().unwrap().grid.cell_volume(0);
    let velocity: Vec<_> = eps.iter().map(|e| Vector3::new(0.0, 0.0, u / e)).collect();
    let gradient: Vec<_> = eps
        .iter()
        .zip(drag)
        .map(|(e, d)| Vector3::new(0.0, 0.0, -RHO_F * G) - d / (e * volume))
        .collect();
    sim.set_fluid_velocity(&velocity).unwrap();
    sim.set_pressure_gradient(&gradient).unwrap();
}

/// The frictional pressure drop across the bed at rest at superficial velocity `u`:
/// `Σ D_k / (ε_k A)` over the slabs, `D_k` the drag on slab `k`'s particles.
fn pressure_drop(sim: &mut Simulation, u: Real) -> (Real, Vec<Vector3<Real>>) {
    let slabs = sim.fluid().unwrap().grid.len();
    set_gas(sim, u, &vec![Vector3::zeros(); slabs]);
    sim.initialise();
    let fluid = sim.fluid().unwrap();
    let p = &sim.world().particles;
    let mut drag = vec![Vector3::zeros(); slabs];
    for i in 0..p.owned() {
        fluid.weights(i, p.id[i], &p.position[i], |c, w| {
            drag[c] += fluid.exchange.drag[i] * w
        });
    }
    let eps = porosity(sim);
    let drop = drag.iter().zip(&eps).map(|(d, e)| d.z / (e * AREA)).sum();
    (drop, drag)
}

fn wen_yu() -> Real {
    let ar = RHO_F * (RHO_P - RHO_F) * G * D.powi(3) / (MU * MU);
    let re = (33.7 * 33.7 + 0.0408 * ar).sqrt() - 33.7;
    re * MU / (RHO_F * D)
}

fn mean_height(sim: &Simulation) -> Real {
    let p = &sim.world().particles;
    p.position.iter().map(|x| x.z).sum::<Real>() / p.len() as Real
}

/// Runs `time` seconds at superficial velocity `u`, the gas model updated every
/// millisecond; returns the rise of the bed's mean height.
fn run(u: Real, time: Real) -> Real {
    let mut sim = bed();
    let slabs = sim.fluid().unwrap().grid.len();
    let start = mean_height(&sim);
    let mut drag = vec![Vector3::zeros(); slabs];
    let interval = 1e-3;
    let mut t = 0.0;
    while t < time - 1e-12 {
        set_gas(&mut sim, u, &drag);
        sim.restart_fluid_exchange();
        t += interval;
        let _ = sim.advance_to(t, |_, _| ControlFlow::<()>::Continue(()));
        drag = sim
            .take_momentum_source()
            .unwrap()
            .iter()
            .map(|s| -s)
            .collect();
    }
    mean_height(&sim) - start
}

/// The pressure-drop method: the fixed bed's ∆p(U) crosses the bed's weight per
/// area at U_mf. Gidaspow's drag is Ergun's in the bed, so this is Ergun's U_mf at
/// the poured bed's own porosity profile; Wen–Yu is Ergun at a typical ε_mf (about
/// 0.40 for these beads), so the two agree as far as the bed's porosity is typical.
#[test]
fn the_bed_fluidises_near_the_wen_yu_velocity() {
    let mut sim = bed();
    let n = sim.world().particles.len() as Real;
    let weight = n * PI / 6.0 * D.powi(3) * (RHO_P - RHO_F) * G / AREA;
    let (mut lo, mut hi) = (0.1, 3.0);
    for _ in 0..30 {
        let mid = 0.5 * (lo + hi);
        if pressure_drop(&mut sim, mid).0 < weight {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let u_mf = 0.5 * (lo + hi);
    let eps = porosity(&sim);
    println!(
        "U_mf {u_mf:.4} m/s, Wen–Yu {:.4} m/s ({:+.1} %); slab porosities {:.3?}",
        wen_yu(),
        100.0 * (u_mf / wen_yu() - 1.0),
        &eps[..4]
    );
    assert!(
        (u_mf / wen_yu() - 1.0).abs() < 0.10,
        "{u_mf} against {}",
        wen_yu()
    );
    // Below U_mf the fixed bed's ∆p rises with U, above the weight it cannot hold.
    let (below, _) = pressure_drop(&mut sim, 0.8 * u_mf);
    assert!(below < 0.8 * weight, "{below} against {weight}");

    // The bed itself: it stays put below U_mf and lifts above it.
    let time = 0.03;
    let rise_below = run(0.85 * u_mf, time);
    let rise_above = run(1.2 * u_mf, time);
    println!(
        "mean height rise in {time} s: {rise_below:.2e} m at 0.85 U_mf, {rise_above:.2e} m at 1.2 U_mf"
    );
    assert!(rise_below.abs() < 0.02 * D, "{rise_below}");
    assert!(rise_above > 0.2 * D, "{rise_above}");
}
