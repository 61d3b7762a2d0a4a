//! `talus accuracy`: what each setting of a scene costs and what it buys.

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{Context, Result};
use talus::Real;
use talus::accuracy::oblique::oblique_impacts;
use talus::accuracy::report::{self, percent};
use talus::accuracy::sweep::{COST_PASSES, Point};
use talus::accuracy::{Quantity, Sweep, SweepOptions, impact_speed, sweep};
use talus::scene::Scene;

/// What the command was asked.
pub struct AccuracyOptions {
    /// Wall-clock seconds for the scene's warm-up and cost runs.
    pub budget: Duration,
    /// Largest error the recommendation may have.
    pub target: Real,
    /// Where the files go (default `<scene>_accuracy`).
    pub out: Option<PathBuf>,
    /// Worker threads of the cost runs (0: the scene's, else all cores).
    pub threads: usize,
}

/// Sweeps `path`'s settings, writes the report and prints the recommendation.
pub fn accuracy(path: &Path, options: AccuracyOptions) -> Result<()> {
    let scene = Scene::load(path)?;
    let dir = options.out.clone().unwrap_or_else(|| {
        let stem = path.file_stem().unwrap_or_default().to_string_lossy();
        path.with_file_name(format!("{stem}_accuracy"))
    });
    let (pool, threads) = super::run::worker_pool(options.threads, &scene)?;
    println!("machine: {}, {threads} thread(s)", super::bench::machine());
    println!(
        "scene: {} ({} particle kinds, end {} s); costs from a state at up to half its end, \
         {} s of runs in all",
        path.display(),
        scene.world.body_types.len(),
        scene.spec.simulation.end_time,
        options.budget.as_secs_f64()
    );
    let swept = pool.install(|| {
        sweep(
            &scene,
            SweepOptions {
                budget: options.budget,
                target: options.target,
            },
            |k, n, p| {
                let (s, worst) = (&p.settings, p.errors.worst());
                println!(
                    "errors [{:>2}/{n}] dt {:.3e} s ({:.3} of suggested), regularisation {:.3}, \
                     skin {:.2e} m{}: worst {worst:.2e}",
                    k + 1,
                    p.dt,
                    s.dt_fraction,
                    s.regularisation,
                    s.skin,
                    mesh(p),
                )
            },
        )
    })?;
    println!("\ncosts (the faster of {COST_PASSES} interleaved passes):");
    for (k, p) in swept.points.iter().enumerate() {
        println!("[{:>2}] {}", k + 1, line(p, p.errors.worst()));
    }
    report::write(&swept, &dir).with_context(|| format!("writing {}", dir.display()))?;
    print_summary(&scene, &swept);
    println!(
        "written: {}/accuracy.csv, accuracy.json, pareto.png, convergence.png",
        dir.display()
    );
    Ok(())
}

/// One point as a line: settings, `worst` error, cost.
fn line(p: &Point, worst: Real) -> String {
    let s = &p.settings;
    format!(
        "dt {:.3e} s ({:.3} of suggested), regularisation {:.3}, skin {:.2e} m{}: \
         worst error {:.2e}; {:.3e} particle-steps/s, {:.0} contacts, {:.1} s to the end",
        p.dt,
        s.dt_fraction,
        s.regularisation,
        s.skin,
        mesh(p),
        worst,
        p.cost.particle_steps_per_second,
        p.cost.contacts,
        p.cost.seconds_to_end
    )
}

/// The mesh of a point that sets one.
fn mesh(p: &Point) -> String {
    p.faces
        .map(|f| format!(", mesh of {f} faces"))
        .unwrap_or_default()
}

fn print_summary(scene: &Scene, swept: &Sweep) {
    println!();
    for u in &swept.unmet {
        let at = line(&swept.points[u.best_point], u.best);
        if u.knob_sensitive() {
            println!(
                "{}: no setting swept brings it under {}; the knobs move it {:.1}-fold \
                 across the sweep, to {:.2e} at best, at\n  {at}",
                u.quantity.name(),
                percent(swept.target),
                u.spread,
                u.best
            );
        } else {
            println!(
                "{}: no setting swept brings it under {} (best {:.2e}, {:.1}-fold across \
                 the sweep): the model or the materials set it, not these knobs",
                u.quantity.name(),
                percent(swept.target),
                u.best,
                u.spread
            );
        }
    }
    let rigid = |q: Quantity| matches!(q, Quantity::Eccentric | Quantity::Impulse);
    if swept.unmet.iter().any(|u| rigid(u.quantity)) {
        for o in oblique_impacts(scene, impact_speed(scene)) {
            println!(
                "  kind {}: its corner contact lasts {:.2e} s, in which the rigid-body spin \
                 turns it by {:.2} rad (rigid-body theory needs a contact over long before \
                 the particle turns: a stiffer material)",
                o.kind, o.contact_time, o.turn
            );
        }
    }
    match swept.recommended {
        Some(i) => {
            let p = &swept.points[i];
            println!(
                "recommended (the cheapest setting with every error some setting meets \
                 under {}):\n  {}",
                percent(swept.target),
                line(p, swept.counted_error(i))
            );
            for (q, e) in p.errors.iter() {
                println!("    {:<15} {:.2e}", q.name(), e);
            }
            println!("in the scene file:\n{}", p.settings.as_toml(scene, p.dt));
        }
        None => println!(
            "no setting swept keeps every error under {}: see accuracy.csv",
            percent(swept.target)
        ),
    }
}

/// A fraction given as `0.02` or `2%`.
pub fn fraction(text: &str) -> Result<Real, String> {
    let (number, scale) = match text.trim().strip_suffix('%') {
        Some(n) => (n.trim(), 0.01),
        None => (text.trim(), 1.0),
    };
    match number.parse::<Real>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x * scale),
        _ => Err(format!("{text} is not a positive fraction (0.02 or 2%)")),
    }
}
