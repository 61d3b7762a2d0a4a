//! What a run leaves behind: a ParaView series, CSV time series and a summary.
//!
//! Layout of an output directory:
//!
//! - `particles.pvd`, `walls.pvd` and `frames/*.vtp`: the ParaView series (open the
//!   `.pvd` files);
//! - `walls.csv`: per wall, the force and torque (about the wall's reference point)
//!   the particles exert on it, and the power the wall delivers to the particles, each
//!   the mean over the interval since the previous row (impulse over time, so nothing
//!   between rows is lost); with a drum, its drive torque and power at the end;
//! - `series.csv`: particles, contacts, kinetic energy and largest speed;
//! - `summary.json`: the run's figures;
//! - with a `[drum]` section, the drum's files (see [`drum`]);
//! - with a `[fluid]` section, `fluid.pvd` and `frames/fluid_*.vti` (`.vtp` for cells
//!   other than a structured grid): the fluid grid's
//!   cells with the solid fraction, fluid and mean particle velocities, pressure
//!   gradient and the drag the particles in each cell receive;
//! - `checkpoint.talus` and `checkpoint.prev.talus` (when checkpoints are asked for or
//!   the run is interrupted): the last two checkpoints, see [`crate::checkpoint`]; a
//!   resumed run takes up the files above where a checkpoint left them
//!   ([`OutputCursor`]).

mod clock;
pub mod drum;
pub mod packing;
pub mod plot;
mod resume;
pub mod vtk;

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use nalgebra::Vector3;
use serde::Serialize;

use crate::Real;
use crate::analysis::{Drum, DrumSummary};
use crate::engine::{Stage, StageTimes};
use crate::world::{MassMoments, World};
pub use clock::{Due, OutputClock};
use drum::DrumOutput;
pub use resume::OutputCursor;
use vtk::Collection;

/// Time spent in one stage of the steps of a run.
#[derive(Clone, Debug, Default, Serialize)]
pub struct StageSummary {
    /// The stage (see [`crate::engine::Stage`]).
    pub stage: String,
    /// Wall-clock seconds, summed over the run.
    pub seconds: Real,
    /// Share of the time of all stages.
    pub share: Real,
}

impl StageSummary {
    /// The stages of `times`, in step order.
    pub fn of(times: &StageTimes) -> Vec<StageSummary> {
        Stage::ALL
            .iter()
            .zip(times.shares())
            .map(|(&stage, (name, share))| StageSummary {
                stage: name.into(),
                seconds: times.seconds(stage),
                share,
            })
            .collect()
    }
}

/// Figures of a finished (or interrupted) run, written as `summary.json`.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Summary {
    /// The scene file.
    pub scene: String,
    /// How the run ended: "end_time", "settled" or "interrupted".
    pub ended_by: String,
    /// Simulated time reached, s.
    pub time: Real,
    /// Time step, s.
    pub dt: Real,
    /// Suggested time step, s.
    pub suggested_dt: Option<Real>,
    /// Steps taken.
    pub steps: u64,
    /// Wall-clock time, s.
    pub wall_clock_s: Real,
    /// Particles at the end.
    pub particles: usize,
    /// Of them frozen (`[bed] freeze`).
    pub frozen: usize,
    /// Contacts at the end.
    pub contacts: usize,
    /// Of them between particles (the rest are with walls).
    pub pair_contacts: usize,
    /// Candidate pairs of the neighbour list at the end (pairs whose bounding spheres,
    /// widened by the skin, overlap): what the narrow phase examined in the last step.
    /// It depends on where the list was last built, so a resumed run, which builds
    /// its list afresh, may count a few more or fewer than a run never stopped.
    pub candidate_pairs: usize,
    /// Particle-steps per second of wall-clock time (particles integrated: frozen
    /// ones do not count).
    pub particle_steps_per_s: Real,
    /// Contact evaluations per second of wall-clock time.
    pub contacts_per_s: Real,
    /// Kinetic energy at the end, J.
    pub kinetic_energy: Real,
    /// Largest particle speed at the end, m/s.
    pub max_speed: Real,
    /// ParaView frames written.
    pub frames: usize,
    /// Per wall: name, force and torque at the end.
    pub walls: Vec<WallSummary>,
    /// Threads used.
    pub threads: usize,
    /// Wall-clock time of each stage of the steps, in step order.
    pub stages: Vec<StageSummary>,
    /// The run's energy account at the end.
    pub energy: EnergySummary,
    /// The errors to expect of the scene's settings: one reference impact of each
    /// particle kind on each wall material (`talus::accuracy`).
    pub expected: Vec<ImpactSummary>,
    /// The drum's averages, with a `[drum]` section.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub drum: Option<DrumSummary>,
}

/// A run's energy account at its end (`talus::scene::energy_ledger`), J: what the
/// particles hold against what flowed in and out since the start; the error is what
/// the integration created (positive) or lost.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct EnergySummary {
    /// Kinetic energy held, translation and rotation.
    pub kinetic: Real,
    /// Gravitational potential energy held, `−m g · x`.
    pub potential: Real,
    /// Elastic energy held in the contacts.
    pub elastic: Real,
    /// What the particles held at the start.
    pub start: Real,
    /// Work of the walls on the particles.
    pub wall_work: Real,
    /// Work of a coupled fluid's forces on the particles.
    pub fluid_work: Real,
    /// Energy dissipated by the contacts.
    pub dissipated: Real,
    /// Energy the host's changes between steps brought or took (particles
    /// inserted, frozen, removed).
    pub host: Real,
    /// Held − start − work + dissipated − host.
    pub error: Real,
    /// The error over the largest of the energy dissipated, the work, and the
    /// kinetic plus elastic energy brought in or held.
    pub relative_error: Real,
}

/// One reference impact of a scene's particle kind (`talus::accuracy::Impact`).
#[derive(Clone, Debug, Default, Serialize)]
pub struct ImpactSummary {
    /// The particle kind's shape name.
    pub kind: String,
    /// The plane's material.
    pub wall_material: String,
    /// What met the plane first: "face", "edge", "vertex" or "sphere".
    pub feature: String,
    /// Impact speed, m/s.
    pub speed: Real,
    /// Restitution requested by the pair's materials.
    pub requested: Real,
    /// Restitution realised.
    pub realised: Real,
    /// `realised / requested − 1`.
    pub restitution_error: Real,
    /// The impact's energy account error over the energy brought in.
    pub energy_error: Real,
}

/// A wall's state at the end of a run.
#[derive(Clone, Debug, Default, Serialize)]
pub struct WallSummary {
    /// Name.
    pub name: String,
    /// Force the particles exert on it, N.
    pub force: [Real; 3],
    /// Torque about its reference point, N m.
    pub torque: [Real; 3],
}

/// Writes a run's outputs as it goes.
pub struct RunOutput {
    dir: PathBuf,
    particles: Collection,
    walls: Collection,
    /// Frames of a coupled fluid's grid (none without one).
    fluid: Collection,
    walls_csv: BufWriter<File>,
    series_csv: BufWriter<File>,
    clock: OutputClock,
    /// Per wall: impulse, angular impulse, work delivered, since the last row.
    impulses: Vec<[Vector3<Real>; 2]>,
    work: Vec<Real>,
    last_frame: Option<Real>,
    drum: Option<DrumOutput>,
    /// Whether frames write spheres as points with a radius (see
    /// [`vtk::write_particles`]).
    sphere_points: bool,
}

impl RunOutput {
    /// Creates the directory (and `frames/` in it) and the CSV headers.
    pub fn create(
        dir: &Path,
        world: &World,
        frame_interval: Option<Real>,
        csv_interval: Option<Real>,
        drum: Option<&Drum>,
    ) -> io::Result<Self> {
        std::fs::create_dir_all(dir.join("frames"))?;
        let mut walls_csv = BufWriter::new(File::create(dir.join("walls.csv"))?);
        let mut header = String::from("time");
        for w in &world.walls {
            for c in ["fx", "fy", "fz", "tx", "ty", "tz", "power"] {
                header.push_str(&format!(",{}_{c}", w.name));
            }
        }
        if drum.is_some() {
            header.push_str(",drive_torque,drive_power");
        }
        writeln!(walls_csv, "{header}")?;
        let mut series_csv = BufWriter::new(File::create(dir.join("series.csv"))?);
        writeln!(
            series_csv,
            "time,particles,contacts,kinetic_energy,max_speed,frozen"
        )?;
        Ok(RunOutput {
            dir: dir.to_path_buf(),
            particles: Collection::new(dir.join("particles.pvd")),
            walls: Collection::new(dir.join("walls.pvd")),
            fluid: Collection::new(dir.join("fluid.pvd")),
            walls_csv,
            series_csv,
            clock: OutputClock::new(frame_interval, csv_interval, world.time),
            impulses: vec![[Vector3::zeros(); 2]; world.walls.len()],
            work: vec![0.0; world.walls.len()],
            last_frame: None,
            drum: match drum {
                Some(d) => Some(DrumOutput::create(dir, d, world)?),
                None => None,
            },
            sphere_points: false,
        })
    }

    /// Frames that write spheres as points with a radius (`[output] spheres =
    /// "points"`) rather than icospheres.
    pub fn with_sphere_points(mut self, sphere_points: bool) -> Self {
        self.sphere_points = sphere_points;
        self
    }

    /// The output directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Frames written so far.
    pub fn frames(&self) -> usize {
        self.particles.len()
    }

    /// Called after every step of length `dt`: accumulates wall impulses and writes
    /// the rows and frames that are due (all of them when `force` is set). A drum
    /// asks `bed` for the bed's mass moments (the whole run's, on ranks, where
    /// `world` is the whole world only at rows, frames and the drum's samples).
    pub fn record(
        &mut self,
        world: &World,
        bed: impl FnOnce() -> MassMoments,
        dt: Real,
        contacts: usize,
        force: bool,
    ) -> io::Result<()> {
        if let Some(d) = &mut self.drum {
            d.record(world, &bed(), dt);
        }
        for (k, w) in world.walls.iter().enumerate() {
            self.impulses[k][0] += w.force * dt;
            self.impulses[k][1] += w.torque * dt;
            self.work[k] += w.power() * dt;
        }
        let t = world.time;
        // A forced record at a time already written (the end of a run that landed on
        // a row or frame) writes nothing twice.
        let due = self.clock.due(t, dt, force);
        let written = self.write_due(due, world, contacts);
        // The clock moves on whether or not the files took the rows: on ranks the
        // others' clocks did (they gather the whole world for rank 0 by them).
        self.clock.advance(due, t, dt);
        written
    }

    fn write_due(&mut self, due: Due, world: &World, contacts: usize) -> io::Result<()> {
        if due.rows {
            self.write_rows(world, contacts)?;
        }
        if due.frame {
            self.write_frame(world)?;
        }
        Ok(())
    }

    /// Whether the drum samples the bed after the step of length `dt` that ended
    /// at `t` (it needs the whole world then).
    pub fn drum_samples_at(&self, t: Real, dt: Real) -> bool {
        self.drum
            .as_ref()
            .is_some_and(|d| d.monitor().samples_at(t, dt))
    }

    /// When rows and frames are due.
    pub fn clock(&self) -> &OutputClock {
        &self.clock
    }

    fn write_rows(&mut self, world: &World, contacts: usize) -> io::Result<()> {
        let t = world.time;
        let max_speed = world.max_speed();
        let span = t - self.clock.last_row();
        let mut row = format!("{t:.9e}");
        for (k, w) in world.walls.iter().enumerate() {
            // The first row (no interval yet) holds the instantaneous values.
            let (f, m, p) = if span > 0.0 {
                (
                    self.impulses[k][0] / span,
                    self.impulses[k][1] / span,
                    self.work[k] / span,
                )
            } else {
                (w.force, w.torque, w.power())
            };
            for x in f.iter().chain(m.iter()).chain(std::iter::once(&p)) {
                row.push_str(&format!(",{x:.9e}"));
            }
            self.impulses[k] = [Vector3::zeros(); 2];
            self.work[k] = 0.0;
        }
        if let Some(d) = &mut self.drum {
            let r = d.write_row(world)?;
            row.push_str(&format!(",{:.9e},{:.9e}", r.drive_torque, r.power));
        }
        writeln!(self.walls_csv, "{row}")?;
        writeln!(
            self.series_csv,
            "{t:.9e},{},{contacts},{:.9e},{max_speed:.9e},{}",
            world.particles.owned(),
            world.kinetic_energy(),
            world.particles.frozen_count()
        )?;
        self.walls_csv.flush()?;
        self.series_csv.flush()
    }

    fn write_frame(&mut self, world: &World) -> io::Result<()> {
        let k = self.particles.len();
        self.last_frame = Some(world.time);
        let p = format!("frames/particles_{k:06}.vtp");
        let w = format!("frames/walls_{k:06}.vtp");
        vtk::write_particles(world, &self.dir.join(&p), self.sphere_points)?;
        self.particles.add(world.time, p)?;
        if !world.walls.is_empty() {
            vtk::write_walls(world, &self.dir.join(&w))?;
            self.walls.add(world.time, w)?;
        }
        if world.fluid.is_some() {
            let f = format!("frames/fluid_{k:06}.{}", vtk::fluid_extension(world));
            vtk::write_fluid(world, &self.dir.join(&f))?;
            self.fluid.add(world.time, f)?;
        }
        Ok(())
    }

    /// Writes the analyses' files that cover the whole run (the drum's); call once,
    /// after the last `record`.
    pub fn finish(&mut self, world: &World) -> io::Result<Option<DrumSummary>> {
        match &mut self.drum {
            Some(d) => d.finish(&self.dir, world).map(Some),
            None => Ok(None),
        }
    }

    /// Writes `summary.json`.
    pub fn write_summary(&self, summary: &Summary) -> io::Result<()> {
        let text = serde_json::to_string_pretty(summary).map_err(io::Error::other)?;
        std::fs::write(self.dir.join("summary.json"), text + "\n")
    }
}
