//! `talus check` and `talus run`: validate a scene, print its plan, and run it with
//! progress, ParaView output, CSV series and a summary.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use talus::output::{RunOutput, StageSummary, Summary, WallSummary};
use talus::scene::{Scene, Simulation};

/// Loads a scene, printing its warnings.
fn load(path: &Path) -> Result<Scene> {
    let scene = Scene::load(path)?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    Ok(scene)
}

/// `talus check`: validates the scene and prints the plan.
pub fn check(path: &Path) -> Result<()> {
    let scene = load(path)?;
    println!("{}: valid scene", path.display());
    print!("{}", scene.plan);
    Ok(())
}

/// Options of `talus run`.
pub struct RunOptions {
    /// Output directory (default: the scene's).
    pub out: Option<PathBuf>,
    /// Worker threads (0: the scene's setting, else all cores).
    pub threads: usize,
    /// No progress bar.
    pub quiet: bool,
}

/// `talus run`.
pub fn run(path: &Path, options: RunOptions) -> Result<()> {
    let scene = load(path)?;
    let threads = match (options.threads, scene.spec.simulation.threads) {
        (0, 0) => std::thread::available_parallelism().map_or(1, |n| n.get()),
        (0, t) | (t, _) => t,
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .context("cannot start the worker threads")?;
    let dir = options.out.clone().unwrap_or_else(|| scene.output_dir());
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        // A second Ctrl-C while the outputs are being written kills the process.
        ctrlc::set_handler(move || {
            if stop.swap(true, Ordering::SeqCst) {
                std::process::exit(130);
            }
        })
        .context("cannot install the Ctrl-C handler")?;
    }
    pool.install(|| run_loop(&scene, &dir, threads, &stop, options.quiet))
}

fn run_loop(
    scene: &Scene,
    dir: &Path,
    threads: usize,
    stop: &AtomicBool,
    quiet: bool,
) -> Result<()> {
    let mut sim = Simulation::new(scene);
    let mut out = RunOutput::create(
        dir,
        sim.world(),
        scene.spec.output.frame_interval,
        scene.spec.output.csv_interval,
        scene.drum.as_ref(),
    )
    .with_context(|| format!("cannot write to {}", dir.display()))?;
    out.record(sim.world(), 0.0, sim.stats().contacts, true)?;
    let total_steps = (sim.end_time / scene.dt).ceil() as u64;
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(total_steps)
    };
    bar.set_style(
        ProgressStyle::with_template("{bar:30} {percent:>3}% t = {msg} | {per_sec} | ETA {eta}")
            .expect("valid template"),
    );
    let started = Instant::now();
    let mut contact_sum = 0u64;
    let mut particle_steps = 0u64;
    let mut last_draw = Instant::now();
    // What ends a run, in this order: Ctrl-C, the end time, the settling criterion.
    let stopped = |sim: &Simulation| {
        if stop.load(Ordering::SeqCst) {
            Some("interrupted")
        } else if !sim.is_finished() && sim.is_settled() {
            Some("settled")
        } else {
            None
        }
    };
    let ended_by = match stopped(&sim) {
        Some(reason) => reason,
        None => {
            let end = sim.end_time;
            let advanced = sim.advance_to(end, |sim, taken| {
                let stats = sim.stats();
                particle_steps += stats.integrated as u64;
                contact_sum += stats.contacts as u64;
                if let Err(e) = out.record(sim.world(), taken, stats.contacts, false) {
                    return ControlFlow::Break(Err(e));
                }
                if last_draw.elapsed() > Duration::from_millis(200) {
                    last_draw = Instant::now();
                    bar.set_position(sim.steps);
                    bar.set_message(format!(
                        "{:.4e} s | {} particles | {} contacts",
                        sim.time(),
                        sim.world().particles.owned(),
                        stats.contacts
                    ));
                }
                match stopped(sim) {
                    Some(reason) => ControlFlow::Break(Ok(reason)),
                    None => ControlFlow::Continue(()),
                }
            });
            match advanced {
                ControlFlow::Continue(()) => "end_time",
                ControlFlow::Break(reason) => reason?,
            }
        }
    };
    bar.finish_and_clear();
    out.record(sim.world(), 0.0, sim.stats().contacts, true)?;
    let drum = out.finish(sim.world())?;
    let elapsed = started.elapsed().as_secs_f64();
    let report = sim.report();
    let summary = Summary {
        // Absolute, so that `talus analyze` finds it from anywhere.
        scene: std::fs::canonicalize(&scene.file)
            .unwrap_or_else(|_| scene.file.clone())
            .display()
            .to_string(),
        ended_by: ended_by.into(),
        time: report.time,
        dt: scene.dt,
        suggested_dt: scene.suggested.as_ref().map(|s| s.dt),
        steps: sim.steps,
        wall_clock_s: elapsed,
        particles: report.particles,
        frozen: sim.world().particles.frozen_count(),
        contacts: report.contacts,
        particle_steps_per_s: particle_steps as f64 / elapsed.max(1e-9),
        contacts_per_s: contact_sum as f64 / elapsed.max(1e-9),
        kinetic_energy: report.kinetic_energy,
        max_speed: report.max_speed,
        frames: out.frames(),
        walls: sim
            .world()
            .walls
            .iter()
            .map(|w| WallSummary {
                name: w.name.clone(),
                force: w.force.into(),
                torque: w.torque.into(),
            })
            .collect(),
        threads,
        stages: StageSummary::of(sim.stage_times()),
        drum,
    };
    out.write_summary(&summary)?;
    if let Some(bed) = &scene.bed {
        crate::analyze::write_bed_files(scene, bed, sim.world(), dir)?;
    }
    println!(
        "{}: {} at t = {:.6e} s after {} steps in {:.2} s ({:.3e} particle-steps/s, {:.3e} contacts/s); {} particles; output in {}",
        scene.file.display(),
        match ended_by {
            "settled" => "settled",
            "interrupted" => "interrupted",
            _ => "finished",
        },
        report.time,
        sim.steps,
        elapsed,
        summary.particle_steps_per_s,
        summary.contacts_per_s,
        report.particles,
        dir.display()
    );
    Ok(())
}
