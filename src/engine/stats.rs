//! What a step hands back besides the state: counts, energies, and the time spent in
//! each stage.

use std::time::{Duration, Instant};

use crate::Real;

/// Figures of the last step's force evaluation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepStats {
    /// Contacts: particle pairs that touch plus particle–wall patches. On a rank of
    /// a decomposed run, the counts and energies of pairs are this rank's share: a
    /// pair of an owned particle and a ghost counts on the rank that owns the one
    /// of smaller id, so the shares of all ranks add up to one process's.
    pub contacts: usize,
    /// Of them, between particles.
    pub pair_contacts: usize,
    /// Candidate particle pairs of the neighbour list.
    pub candidate_pairs: usize,
    /// Particles integrated in the last step (owned and not frozen).
    pub integrated: usize,
    /// Elastic energy held in all contacts: the normal laws' potentials (of the
    /// overlap volumes, or Hertz's) and the friction springs.
    pub elastic_energy: Real,
    /// Energy the contacts dissipated over the step that ended with this
    /// evaluation (damping, friction), J.
    pub dissipated: Real,
    /// Work of the fluid's drag and pressure-gradient forces on the particles over
    /// that step, J.
    pub fluid_work: Real,
    /// Neighbour-list builds since the backend was made.
    pub list_builds: u64,
}

/// The stages of a step, in the order a step runs them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Kick, drift, and the closing kick.
    Integrate,
    /// Prescribed wall motion.
    WallMotion,
    /// Contact-law parameters of the body types.
    Laws,
    /// Neighbour-list check and rebuild.
    NeighbourList,
    /// Particle-pair contacts (narrow phase and contact laws).
    PairContacts,
    /// Adding to the particles the pairs that the parts of the pair sweep deferred
    /// (the pairs of particles between two parts, on many threads).
    Gather,
    /// Particle–wall contacts and their accumulation on walls and facets.
    WallContacts,
    /// Drag and pressure-gradient forces of a coupled fluid, and their exchange.
    Fluid,
}

impl Stage {
    /// Every stage, in step order.
    pub const ALL: [Stage; 8] = [
        Stage::Integrate,
        Stage::WallMotion,
        Stage::Laws,
        Stage::NeighbourList,
        Stage::PairContacts,
        Stage::Gather,
        Stage::WallContacts,
        Stage::Fluid,
    ];

    /// The stage's name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Integrate => "integrate",
            Stage::WallMotion => "wall_motion",
            Stage::Laws => "laws",
            Stage::NeighbourList => "neighbour_list",
            Stage::PairContacts => "pair_contacts",
            Stage::Gather => "gather",
            Stage::WallContacts => "wall_contacts",
            Stage::Fluid => "fluid",
        }
    }
}

/// Wall-clock time spent in each stage (monotonic clock), summed over a backend's
/// life. Two readings subtract ([`StageTimes::since`]) to time a window.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StageTimes {
    seconds: [f64; Stage::ALL.len()],
}

impl StageTimes {
    /// Runs `f`, adding its duration to `stage`.
    #[inline]
    pub fn time<T>(&mut self, stage: Stage, f: impl FnOnce() -> T) -> T {
        let start = Instant::now();
        let out = f();
        self.add(stage, start.elapsed());
        out
    }

    /// Adds `d` to `stage`.
    #[inline]
    pub fn add(&mut self, stage: Stage, d: Duration) {
        self.seconds[stage as usize] += d.as_secs_f64();
    }

    /// Seconds spent in `stage`.
    pub fn seconds(&self, stage: Stage) -> f64 {
        self.seconds[stage as usize]
    }

    /// Seconds spent in all stages.
    pub fn total(&self) -> f64 {
        self.seconds.iter().sum()
    }

    /// The times spent since `earlier` (a reading of the same backend).
    pub fn since(&self, earlier: &StageTimes) -> StageTimes {
        let mut d = *self;
        for (x, e) in d.seconds.iter_mut().zip(&earlier.seconds) {
            *x -= e;
        }
        d
    }

    /// Each stage's share of the total, in step order (zeros before any step).
    pub fn shares(&self) -> Vec<(&'static str, f64)> {
        let total = self.total();
        Stage::ALL
            .iter()
            .map(|&s| {
                let share = if total > 0.0 {
                    self.seconds(s) / total
                } else {
                    0.0
                };
                (s.name(), share)
            })
            .collect()
    }
}
