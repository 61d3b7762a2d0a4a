//! A running simulation's output files, written by rank 0 (or the one process)
//! with every rank taking part: each rank keeps the clock of rows and frames, since
//! gathering the whole world for them is collective. `talus run` and the
//! component record through it. A layer beside cosim: it uses scene and output.

use std::borrow::Cow;
use std::io;

use crate::Real;
use crate::analysis::DrumSummary;
use crate::output::{OutputClock, RunOutput};
use crate::scene::{Scene, Simulation};
use crate::world::World;

/// The outputs of a run: the files on rank 0 (whose clock is the run's), the
/// clock alone on the other ranks.
pub struct Outputs {
    side: Side,
    /// The scene has a drum, whose samples need the whole world.
    drum: bool,
}

enum Side {
    Files(Box<RunOutput>),
    Clock(OutputClock),
}

impl Outputs {
    /// Rank 0's outputs (or the one process's): `files`, `drum` when the scene has
    /// a drum.
    pub fn writing(files: RunOutput, drum: bool) -> Self {
        Outputs {
            side: Side::Files(Box::new(files)),
            drum,
        }
    }

    /// Another rank's: the clock of rank 0's files.
    pub fn following(clock: OutputClock, drum: bool) -> Self {
        Outputs {
            side: Side::Clock(clock),
            drum,
        }
    }

    /// The files, on rank 0.
    pub fn files(&mut self) -> Option<&mut RunOutput> {
        match &mut self.side {
            Side::Files(out) => Some(out),
            Side::Clock(_) => None,
        }
    }

    /// The files, on rank 0, for the run's last words.
    pub fn into_files(self) -> Option<RunOutput> {
        match self.side {
            Side::Files(out) => Some(*out),
            Side::Clock(_) => None,
        }
    }

    fn clock(&self) -> &OutputClock {
        match &self.side {
            Side::Files(out) => out.clock(),
            Side::Clock(clock) => clock,
        }
    }

    /// Whether [`record`](Self::record) after a step of length `dt` that ended at
    /// `t` reads the particles: a row or a frame is due, or the scene has a drum
    /// (whose monitor takes the bed's mass moments every step).
    pub fn reads_particles(&self, t: Real, dt: Real) -> bool {
        self.drum || self.clock().due(t, dt, false).any()
    }

    /// [`RunOutput::record`] after a step of length `dt`, the whole world gathered
    /// when a row, a frame or a drum's sample is due (collective on ranks).
    pub fn record(&mut self, sim: &Simulation, dt: Real, force: bool) -> io::Result<()> {
        let t = sim.time();
        let due = self.clock().due(t, dt, force);
        if let Side::Clock(clock) = &mut self.side {
            clock.advance(due, t, dt);
        }
        // Rank 0's drum keeps its own clock of samples; it tells the others.
        let sample = self.drum
            && sim.rank().is_some()
            && sim.any_rank(matches!(&self.side, Side::Files(o) if o.drum_samples_at(t, dt)));
        // Otherwise only the walls are read, whose forces are the whole run's on
        // every rank, and the bed's mass moments, the whole run's too.
        let world = if due.any() || sample {
            sim.whole_world()
        } else {
            Some(Cow::Borrowed(sim.world()))
        };
        if let (Side::Files(out), Some(world)) = (&mut self.side, world) {
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

    /// Writes the files of the run's end that read the whole world (the bed's, the
    /// drum's summary; collective on ranks) and returns the drum's summary, on
    /// rank 0.
    pub fn finish(&mut self, sim: &Simulation, scene: &Scene) -> io::Result<Option<DrumSummary>> {
        let whole = world_at_the_end(sim, scene);
        match &mut self.side {
            Side::Files(out) => out.finish(whole.as_deref().unwrap_or(sim.world())),
            Side::Clock(_) => Ok(None),
        }
    }
}

/// The whole world the files of a run's end read (the bed's, the drum's summary):
/// gathered on rank 0 when the scene has a bed or a drum (collective on ranks; the
/// world itself in one process), `None` otherwise and on the other ranks.
pub fn world_at_the_end<'a>(sim: &'a Simulation, scene: &Scene) -> Option<Cow<'a, World>> {
    if scene.bed.is_some() || scene.drum.is_some() {
        sim.whole_world()
    } else {
        None
    }
}
