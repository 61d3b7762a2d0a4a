//! Where a run's checkpoints go: rank 0 (or the one process) writes them; on
//! ranks every rank takes part in gathering the whole state for a checkpoint (the
//! outputs: `talus::recording`).

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use talus::Real;
use talus::checkpoint::{Checkpoint, RunProgress};
use talus::recording::Outputs;
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
        let (Some(state), Some(out)) = (state, out.files()) else {
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
