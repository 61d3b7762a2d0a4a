//! Where a run's outputs and checkpoints go: rank 0 (or the one process) writes
//! them; on ranks every rank keeps the clocks and takes part in gathering the whole
//! world for a row or a frame, and the whole state for a checkpoint.

use std::borrow::Cow;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use talus::Real;
use talus::checkpoint::{Checkpoint, RunProgress};
use talus::output::{OutputClock, RunOutput};
use talus::scene::{Scene, Simulation};

use crate::checkpoint;

/// Steps between two votes of the ranks on whether the run was interrupted (on
/// ranks every rank must stop at the same step): a Ctrl-C is answered within them.
pub const STOP_VOTE_STEPS: u64 = 64;

/// When and where a run writes its checkpoints.
pub struct Checkpoints {
    dir: PathBuf,
    /// The scene file, absolute.
    scene: PathBuf,
    fingerprint: u64,
    interval: Option<Real>,
    every: Option<Duration>,
    last: Instant,
    /// Worker threads of this process.
    pub threads: usize,
}

impl Checkpoints {
    pub fn new(scene: &Scene, dir: &Path, every: Option<Duration>, threads: usize) -> Self {
        Checkpoints {
            dir: dir.to_path_buf(),
            scene: std::fs::canonicalize(&scene.file).unwrap_or_else(|_| scene.file.clone()),
            fingerprint: scene.fingerprint(),
            interval: scene.spec.output.checkpoint_interval,
            every,
            last: Instant::now(),
            threads,
        }
    }

    /// Whether a checkpoint is due after a step of length `dt`: at each multiple
    /// of the interval, and after `every` of wall-clock time (on ranks, as rank 0's
    /// clock says, asked every [`STOP_VOTE_STEPS`] steps: all ranks write together).
    pub fn due(&self, sim: &Simulation, dt: Real) -> bool {
        let t = sim.time();
        let crossed = self.interval.is_some_and(|i| {
            let eps = 1e-9 * dt;
            ((t + eps) / i).floor() > ((t - dt + eps) / i).floor()
        });
        let late = |every: Duration| self.last.elapsed() >= every;
        crossed
            || match (sim.rank(), self.every) {
                (_, None) => false,
                (None, Some(every)) => late(every),
                (Some((rank, _)), Some(every)) => {
                    sim.steps % STOP_VOTE_STEPS == 0 && sim.any_rank(rank == 0 && late(every))
                }
            }
    }

    /// Writes one of the simulation and the outputs as they are now (collective on
    /// ranks: the state is gathered on rank 0, which writes it).
    pub fn write(
        &mut self,
        sim: &Simulation,
        out: &mut Outputs,
        progress: RunProgress,
    ) -> Result<()> {
        let state = sim.whole_snapshot();
        self.last = Instant::now();
        let (Some(state), Some(out)) = (state, &mut out.out) else {
            return Ok(());
        };
        let checkpoint = Checkpoint {
            scene: self.scene.clone(),
            progress: RunProgress {
                threads: self.threads,
                ..progress
            },
            output: out.cursor()?,
            sim: state,
        };
        checkpoint::write(&self.dir, &checkpoint.to_bytes(self.fingerprint))
            .with_context(|| format!("cannot write a checkpoint in {}", self.dir.display()))
    }
}

/// The outputs of a run: written by rank 0 (or the one process); every rank keeps
/// the clock, since gathering the whole world for a row or a frame is collective.
pub struct Outputs {
    /// The files, on rank 0.
    pub out: Option<RunOutput>,
    pub clock: OutputClock,
    /// The scene has a drum, whose samples need the whole world.
    pub drum: bool,
}

impl Outputs {
    /// [`RunOutput::record`] after a step of length `dt`, the whole world gathered
    /// when a row, a frame or a drum's sample is due.
    pub fn record(&mut self, sim: &Simulation, dt: Real, force: bool) -> Result<()> {
        let t = sim.time();
        let due = self.clock.due(t, dt, force);
        self.clock.advance(due, t, dt);
        // Rank 0's drum keeps its own clock of samples; it tells the others.
        let sample = self.drum
            && sim.rank().is_some()
            && sim.any_rank(self.out.as_ref().is_some_and(|o| o.drum_samples_at(t, dt)));
        // Otherwise only the walls are read, whose forces are the whole run's on
        // every rank, and the bed's mass moments, the whole run's too.
        let world = if due.any() || sample {
            sim.whole_world()
        } else {
            Some(Cow::Borrowed(sim.world()))
        };
        if let (Some(out), Some(world)) = (&mut self.out, world) {
            out.record(
                &world,
                || sim.mass_moments(),
                dt,
                sim.stats().contacts,
                force,
            )?;
        }
        Ok(())
    }
}
