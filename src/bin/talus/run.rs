//! `talus check` and `talus run`: validate a scene, print its plan, and run it with
//! progress, ParaView output, CSV series and a summary; checkpoints on the way, and
//! resumption from them.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressStyle};
use talus::checkpoint::{Checkpoint, RunProgress};
use talus::output::{EnergySummary, OutputClock, RunOutput, StageSummary, Summary, WallSummary};
use talus::recording::{Outputs, world_at_the_end};
use talus::scene::energy_balance::EnergyBalance;
use talus::scene::energy_ledger::EnergyReport;
use talus::scene::spec::{SphereFrames, UpdateInterval};
use talus::scene::{Scene, Simulation};

use crate::launch::Launch;
use crate::run_outputs::{Checkpoints, STOP_VOTE_STEPS};
use crate::{checkpoint, expected};

/// Loads a scene, printing its warnings.
pub fn load(path: &Path) -> Result<Scene> {
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
    print!("{}", expected::describe(&scene, &expected::measure(&scene)));
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
    /// Resume the run in this output directory from its newest checkpoint.
    pub resume: Option<PathBuf>,
    /// Also write a checkpoint after this much wall-clock time.
    pub checkpoint_every: Option<Duration>,
}

/// `talus run` of the scene at `path` (optional with `resume`: the checkpoint names
/// its scene).
pub fn run(path: Option<&Path>, options: RunOptions) -> Result<()> {
    let (scene, dir, start) = match &options.resume {
        Some(dir) => {
            let (scene, checkpoint) = checkpoint::resume(dir, path)?;
            (scene, dir.clone(), Some(checkpoint))
        }
        None => {
            let scene = load(path.context("a scene file is needed (or --resume)")?)?;
            let dir = options.out.clone().unwrap_or_else(|| scene.output_dir());
            (scene, dir, None)
        }
    };
    if let Some(f) = &scene.spec.fluid
        && f.update_interval == UpdateInterval::Communication
    {
        bail!(
            "{}: [fluid] update_interval = \"communication\" needs a coupled run (FMU, C API, \
             zenoh), which has communication steps; talus run has none: give a number of steps",
            scene.file.display()
        );
    }
    let mut launch = Launch::detect()?;
    let (pool, threads) = worker_pool_of(options.threads, &scene, launch.local_ranks())?;
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
    let checkpoints = Checkpoints::new(&scene, &dir, options.checkpoint_every, threads);
    let quiet = options.quiet || !launch.is_root();
    pool.install(|| {
        let sim = match &start {
            None => launch.simulation(&scene, None)?,
            Some(c) => launch
                .simulation(&scene, Some(&c.sim))
                .context("the checkpoint does not fit its scene")?,
        };
        run_loop(&scene, &dir, sim, start, checkpoints, &stop, quiet)
    })
    .map_err(|e| launch.fail(e))
}

/// Steps between two checks of the energy balance (see
/// `talus::scene::energy_balance`): a blow-up is stopped within them.
const BALANCE_STEPS: u64 = 200;

/// Steps `sim` (the whole scene, or this rank's share of it) to the end; `quiet`:
/// no progress and no messages (every rank but 0).
fn run_loop(
    scene: &Scene,
    dir: &Path,
    mut sim: Simulation,
    start: Option<Checkpoint>,
    mut checkpoints: Checkpoints,
    stop: &AtomicBool,
    quiet: bool,
) -> Result<()> {
    let root = sim.rank().is_none_or(|(rank, _)| rank == 0);
    let frame_interval = scene.spec.output.frame_interval;
    let csv_interval = scene.spec.output.csv_interval;
    let drum = scene.drum.is_some();
    let sphere_points = scene.spec.output.spheres == SphereFrames::Points;
    let (mut out, before) = match start {
        None => {
            let mut out = if root {
                let files = RunOutput::create(
                    dir,
                    sim.world(),
                    frame_interval,
                    csv_interval,
                    scene.drum.as_ref(),
                )
                .with_context(|| format!("cannot write to {}", dir.display()))?;
                Outputs::writing(files.with_sphere_points(sphere_points), drum)
            } else {
                Outputs::following(
                    OutputClock::new(frame_interval, csv_interval, sim.time()),
                    drum,
                )
            };
            out.record(&sim, 0.0, true)?;
            (out, RunProgress::default())
        }
        Some(c) => {
            let out = if root {
                let files = RunOutput::resume(dir, frame_interval, csv_interval, c.output)
                    .with_context(|| format!("cannot take up the outputs in {}", dir.display()))?;
                Outputs::writing(files.with_sphere_points(sphere_points), drum)
            } else {
                Outputs::following(c.output.clock(frame_interval, csv_interval), drum)
            };
            if !quiet {
                eprintln!(
                    "resuming at t = {:.6e} s after {} steps from {}",
                    sim.time(),
                    sim.steps,
                    dir.join(checkpoint::FILE).display()
                );
            }
            (out, c.progress)
        }
    };
    let impacts = if root {
        expected::measure(scene)
    } else {
        Vec::new()
    };
    if !quiet {
        eprint!("{}", expected::describe(scene, &impacts));
    }
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
    let mut contact_sum = before.contact_sum;
    let mut particle_steps = before.particle_steps;
    let progress = |contact_sum, particle_steps| RunProgress {
        contact_sum,
        particle_steps,
        wall_clock_s: before.wall_clock_s + started.elapsed().as_secs_f64(),
        threads: 0,
    };
    let mut last_draw = Instant::now();
    // What ends a run, in this order: Ctrl-C, the end time, the settling criterion.
    let interrupted = |sim: &Simulation| match sim.rank() {
        None => stop.load(Ordering::SeqCst),
        Some(_) => sim.steps % STOP_VOTE_STEPS == 0 && sim.any_rank(stop.load(Ordering::SeqCst)),
    };
    let stopped = |sim: &Simulation| {
        if interrupted(sim) {
            Some("interrupted")
        } else if !sim.is_finished() && sim.is_settled() {
            Some("settled")
        } else {
            None
        }
    };
    // Why the run diverged: the first particle that went non-finite, or the energy
    // balance of the last BALANCE_STEPS steps broken grossly.
    let mut blown_up: Option<String> = None;
    let mut balance = EnergyBalance::start(&sim);
    // The particles come back from a device backend only for the steps that read
    // them: a row, a frame or a checkpoint due, the drum's monitor, the energy
    // balance (the CPU backend steps the host's world itself).
    sim.set_particles_each_step(false);
    let ended_by = match stopped(&sim) {
        Some(reason) => reason,
        None => {
            let end = sim.end_time;
            let advanced = sim.advance_to(end, |sim, taken| {
                let balance_due = sim.steps % BALANCE_STEPS == 0;
                let checkpoint_due = checkpoints.due(sim, taken);
                if balance_due || checkpoint_due || out.reads_particles(sim.time(), taken) {
                    sim.sync_particles();
                }
                let sim = &*sim;
                // Before anything of this step is written: the outputs stay finite.
                if sim.particles_current()
                    && let Some(id) = sim.first_non_finite()
                {
                    blown_up = Some(format!(
                        "particle {id} went non-finite (position, velocity or force) in step {} \
                         at t = {:.6e} s; the outputs hold the run up to the step before{}",
                        sim.steps,
                        sim.time(),
                        scene.suggested.as_ref().map_or(String::new(), |s| format!(
                            "; the time step {:.3e} s is {:.3} times the suggested {:.3e} s",
                            sim.dt(),
                            sim.dt() / s.dt,
                            s.dt
                        ))
                    ));
                    return ControlFlow::Break(Ok("diverged"));
                }
                if balance_due {
                    if let Some(problem) = balance.broken(sim) {
                        blown_up = Some(format!(
                            "in the {BALANCE_STEPS} steps up to step {} (t = {:.6e} s), {problem}; \
                             the outputs hold the run up to the step before",
                            sim.steps,
                            sim.time()
                        ));
                        return ControlFlow::Break(Ok("diverged"));
                    }
                    balance = EnergyBalance::start(sim);
                }
                let stats = sim.stats();
                particle_steps += stats.integrated as u64;
                contact_sum += stats.contacts as u64;
                if let Err(e) = out.record(sim, taken, false) {
                    return ControlFlow::Break(Err(e.into()));
                }
                if checkpoint_due
                    && let Err(e) =
                        checkpoints.write(sim, &mut out, progress(contact_sum, particle_steps))
                {
                    return ControlFlow::Break(Err(e));
                }
                // The energy error reads the particles: drawn with them current.
                if last_draw.elapsed() > Duration::from_millis(200) && sim.particles_current() {
                    last_draw = Instant::now();
                    bar.set_position(sim.steps);
                    bar.set_message(format!(
                        "{:.4e} s | {} particles | {} contacts | energy error {:+.1e}",
                        sim.time(),
                        sim.particle_count(),
                        stats.contacts,
                        EnergyReport::of(sim).relative_error
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
    sim.sync_particles();
    bar.finish_and_clear();
    if ended_by == "interrupted" {
        // Before the last frame and row, which an uninterrupted run would not write.
        checkpoints.write(&sim, &mut out, progress(contact_sum, particle_steps))?;
        if root {
            eprintln!(
                "interrupted at t = {:.6e} s; continue with: {}talus run --resume {}",
                sim.time(),
                sim.rank()
                    .map_or(String::new(), |(_, n)| format!("mpirun -np {n} ")),
                dir.display()
            );
        }
    }
    if blown_up.is_none() {
        out.record(&sim, 0.0, true)?;
    }
    // The bed's files and the drum's summary read the whole world: every rank
    // takes part in gathering it; rank 0 writes.
    let whole = world_at_the_end(&sim, scene);
    let Some(mut out) = out.into_files() else {
        return match blown_up {
            Some(message) => bail!("{}: the run diverged: {message}", scene.file.display()),
            None => Ok(()),
        };
    };
    let drum = out.finish(whole.as_deref().unwrap_or(sim.world()))?;
    let elapsed = before.wall_clock_s + started.elapsed().as_secs_f64();
    let mut summary = summary(
        scene,
        &sim,
        ended_by,
        Totals {
            elapsed,
            particle_steps,
            contact_sum,
        },
        out.frames(),
        checkpoints.threads,
        drum,
    );
    summary.expected = expected::summarise(scene, &impacts);
    out.write_summary(&summary)?;
    if let Some(message) = blown_up {
        anyhow::bail!("{}: the run diverged: {message}", scene.file.display());
    }
    if let (Some(bed), Some(world)) = (&scene.bed, &whole) {
        crate::analyze::write_bed_files(scene, bed, world, dir)?;
    }
    println!(
        "{}: {} at t = {:.6e} s after {} steps in {:.2} s ({:.3e} particle-steps/s, {:.3e} contacts/s); {} particles; energy error {:+.2e} of {:.3e} J dissipated; output in {}",
        scene.file.display(),
        match ended_by {
            "settled" => "settled",
            "interrupted" => "interrupted",
            _ => "finished",
        },
        summary.time,
        sim.steps,
        elapsed,
        summary.particle_steps_per_s,
        summary.contacts_per_s,
        summary.particles,
        summary.energy.relative_error,
        summary.energy.dissipated,
        dir.display()
    );
    let stages: Vec<(&str, f64)> = summary
        .stages
        .iter()
        .map(|s| (s.stage.as_str(), s.share))
        .collect();
    println!(
        "  last step: {} contacts, {} between particles among {} candidate pairs and {} with walls; stages: {}",
        summary.contacts,
        summary.pair_contacts,
        summary.candidate_pairs,
        summary.contacts.saturating_sub(summary.pair_contacts),
        if stages.iter().any(|s| s.1 > 0.0) {
            crate::bench::stage_line(&stages)
        } else {
            "not timed apart by this backend".into()
        }
    );
    Ok(())
}

/// What a run counted over all its stretches.
struct Totals {
    elapsed: f64,
    particle_steps: u64,
    contact_sum: u64,
}

/// The figures of `summary.json`.
fn summary(
    scene: &Scene,
    sim: &Simulation,
    ended_by: &str,
    totals: Totals,
    frames: usize,
    threads: usize,
    drum: Option<talus::analysis::DrumSummary>,
) -> Summary {
    let report = sim.report();
    let elapsed = totals.elapsed.max(1e-9);
    Summary {
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
        wall_clock_s: totals.elapsed,
        particles: report.particles,
        frozen: sim.figures().frozen,
        contacts: report.contacts,
        pair_contacts: sim.stats().pair_contacts,
        candidate_pairs: sim.stats().candidate_pairs,
        particle_steps_per_s: totals.particle_steps as f64 / elapsed,
        contacts_per_s: totals.contact_sum as f64 / elapsed,
        kinetic_energy: report.kinetic_energy,
        max_speed: report.max_speed,
        frames,
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
        energy: energy_summary(&EnergyReport::of(sim)),
        expected: Vec::new(),
        drum,
    }
}

/// The energy figures of `summary.json`.
fn energy_summary(r: &EnergyReport) -> EnergySummary {
    EnergySummary {
        kinetic: r.held.kinetic,
        potential: r.held.potential,
        elastic: r.held.elastic,
        start: r.ledger.start,
        wall_work: r.ledger.wall_work,
        fluid_work: r.ledger.fluid_work,
        dissipated: r.ledger.dissipated,
        host: r.ledger.host,
        error: r.error,
        relative_error: r.relative_error,
    }
}

/// The worker threads of a command: `threads` if given (not 0), else the scene's
/// `[simulation] threads`, else all cores.
pub fn worker_pool(threads: usize, scene: &Scene) -> Result<(rayon::ThreadPool, usize)> {
    worker_pool_of(threads, scene, 1)
}

/// [`worker_pool`] of one of `processes` processes on this machine, which share
/// its cores when neither the command nor the scene set the threads.
fn worker_pool_of(
    threads: usize,
    scene: &Scene,
    processes: usize,
) -> Result<(rayon::ThreadPool, usize)> {
    let threads = match (threads, scene.spec.simulation.threads) {
        (0, 0) => {
            let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
            (cores / processes.max(1)).max(1)
        }
        (0, t) | (t, _) => t,
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .context("cannot start the worker threads")?;
    Ok((pool, threads))
}
