//! Where a run's outputs stand ([`OutputCursor`]), so that a run resumed from a
//! checkpoint writes on exactly where the checkpointed one was: the CSV files are cut
//! back to the bytes written at the checkpoint (rows a killed run wrote after it are
//! written again, the same), the ParaView collections hold the frames written up to
//! it (later frame files are overwritten, the same), and what the rows and the drum
//! sum between rows is carried over.

use std::fs::{File, OpenOptions};
use std::io::{self, BufWriter, Seek, SeekFrom, Write};
use std::path::Path;

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::drum::DrumOutput;
use super::vtk::Collection;
use super::{OutputClock, RunOutput};
use crate::Real;
use crate::analysis::DrumMonitor;

/// Everything of a [`RunOutput`] that a resumed run needs besides the files.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct OutputCursor {
    next_frame: Real,
    next_row: Real,
    last_row: Real,
    impulses: Vec<[Vector3<Real>; 2]>,
    work: Vec<Real>,
    rows: usize,
    last_frame: Option<Real>,
    particle_frames: Vec<(Real, String)>,
    wall_frames: Vec<(Real, String)>,
    /// Frames of a coupled fluid's grid.
    #[serde(default)]
    fluid_frames: Vec<(Real, String)>,
    /// Bytes of `walls.csv` and `series.csv` written.
    walls_csv: u64,
    series_csv: u64,
    drum: Option<DrumCursor>,
}

/// The drum's part of an [`OutputCursor`].
#[derive(Clone, Debug, Serialize, Deserialize)]
struct DrumCursor {
    monitor: DrumMonitor,
    /// Bytes of `drum.csv` written.
    csv: u64,
}

/// Opens `path` for appending after cutting it to `len` bytes; a file shorter than
/// that (changed since the checkpoint) is an error.
pub(super) fn open_at(path: &Path, len: u64) -> io::Result<File> {
    let mut file = OpenOptions::new().write(true).open(path)?;
    let found = file.metadata()?.len();
    if found < len {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!(
                "{} holds {found} bytes, fewer than the {len} written at the checkpoint (changed or replaced since)",
                path.display()
            ),
        ));
    }
    file.set_len(len)?;
    file.seek(SeekFrom::Start(len))?;
    Ok(file)
}

impl OutputCursor {
    /// The clock of rows and frames where the cursor left it, with the scene's
    /// intervals (what [`RunOutput::resume`] takes up).
    pub fn clock(&self, frame_interval: Option<Real>, csv_interval: Option<Real>) -> OutputClock {
        OutputClock {
            next_frame: self.next_frame,
            next_row: self.next_row,
            last_row: self.last_row,
            rows: self.rows,
            ..OutputClock::new(frame_interval, csv_interval, 0.0)
        }
    }
}

impl RunOutput {
    /// Where the outputs stand now (the CSV files are flushed first).
    pub fn cursor(&mut self) -> io::Result<OutputCursor> {
        let walls_csv = flushed_len(&mut self.walls_csv)?;
        let series_csv = flushed_len(&mut self.series_csv)?;
        let drum = match &mut self.drum {
            Some(d) => Some(DrumCursor {
                csv: d.written()?,
                monitor: d.monitor().clone(),
            }),
            None => None,
        };
        Ok(OutputCursor {
            next_frame: self.clock.next_frame,
            next_row: self.clock.next_row,
            last_row: self.clock.last_row,
            impulses: self.impulses.clone(),
            work: self.work.clone(),
            rows: self.clock.rows,
            last_frame: self.last_frame,
            particle_frames: self.particles.frames().to_vec(),
            wall_frames: self.walls.frames().to_vec(),
            fluid_frames: self.fluid.frames().to_vec(),
            walls_csv,
            series_csv,
            drum,
        })
    }

    /// Takes up the outputs in `dir` where `cursor` left them (see the module's
    /// comment), with the scene's intervals.
    pub fn resume(
        dir: &Path,
        frame_interval: Option<Real>,
        csv_interval: Option<Real>,
        cursor: OutputCursor,
    ) -> io::Result<Self> {
        let c = cursor;
        let clock = c.clock(frame_interval, csv_interval);
        if c.impulses.len() != c.work.len() {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                "the checkpoint's output cursor has unequal wall counts",
            ));
        }
        Ok(RunOutput {
            dir: dir.to_path_buf(),
            particles: Collection::restore(dir.join("particles.pvd"), c.particle_frames)?,
            walls: Collection::restore(dir.join("walls.pvd"), c.wall_frames)?,
            fluid: Collection::restore(dir.join("fluid.pvd"), c.fluid_frames)?,
            walls_csv: BufWriter::new(open_at(&dir.join("walls.csv"), c.walls_csv)?),
            series_csv: BufWriter::new(open_at(&dir.join("series.csv"), c.series_csv)?),
            clock,
            impulses: c.impulses,
            work: c.work,
            last_frame: c.last_frame,
            drum: match c.drum {
                Some(d) => Some(DrumOutput::resume(dir, d.monitor, d.csv)?),
                None => None,
            },
            sphere_points: false,
        })
    }
}

fn flushed_len(w: &mut BufWriter<File>) -> io::Result<u64> {
    w.flush()?;
    Ok(w.get_ref().metadata()?.len())
}
