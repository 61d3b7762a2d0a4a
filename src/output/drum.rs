//! The drum's files in a run's output directory:
//!
//! - `drum.csv`: per row of `walls.csv`, the revolutions turned, the angular speed,
//!   the mean drive torque and power, the mean axial torque of the particles on each
//!   drum wall (`<wall>_torque`: the shell and each end cap apart), the mean of minus
//!   the bed's gravitational moment (what the drive torque balances in steady
//!   motion) and the angle of repose of the latest sample;
//! - `drum_revolutions.csv`: the same means per revolution, with the mean angle of
//!   repose;
//! - `drum_field.csv` and `drum_field.png`: the time-averaged velocity field of the
//!   central slice (cross-section coordinates `h` across, `v` up, about the axis);
//!   the image colours the mean speed from 0 (dark blue) to the largest cell mean
//!   (yellow), grey where no particle came, with the drum's rim in black and the mean
//!   free surface in red;
//! - `drum.json`: averages over the analysis window (see
//!   [`crate::analysis::DrumSummary`]).

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

use super::png::{Image, viridis};
use crate::Real;
use crate::analysis::{Drum, DrumMonitor, DrumRow, DrumSummary};
use crate::world::World;

/// Writes a drum's files as the run goes.
pub struct DrumOutput {
    monitor: DrumMonitor,
    csv: BufWriter<File>,
}

impl DrumOutput {
    /// Starts `drum.csv` in `dir`.
    pub fn create(dir: &Path, drum: &Drum, world: &World) -> io::Result<Self> {
        let mut csv = BufWriter::new(File::create(dir.join("drum.csv"))?);
        let mut header =
            String::from("time,revolutions,angular_speed,drive_torque,power,gravity_moment");
        for &w in &drum.walls {
            header.push_str(&format!(",{}_torque", world.walls[w].name));
        }
        header.push_str(",angle_of_repose");
        writeln!(csv, "{header}")?;
        Ok(DrumOutput {
            monitor: DrumMonitor::new(drum.clone(), world),
            csv,
        })
    }

    /// Takes up a drum's files where a checkpoint left them: `drum.csv` cut to its
    /// first `csv_len` bytes, the monitor as it was.
    pub fn resume(dir: &Path, monitor: DrumMonitor, csv_len: u64) -> io::Result<Self> {
        Ok(DrumOutput {
            monitor,
            csv: BufWriter::new(super::resume::open_at(&dir.join("drum.csv"), csv_len)?),
        })
    }

    /// Flushes `drum.csv` and tells how many bytes it holds.
    pub fn written(&mut self) -> io::Result<u64> {
        self.csv.flush()?;
        Ok(self.csv.get_ref().metadata()?.len())
    }

    /// The monitor (for its figures while running).
    pub fn monitor(&self) -> &DrumMonitor {
        &self.monitor
    }

    /// Accounts for a step of length `dt`.
    pub fn record(&mut self, world: &World, dt: Real) {
        self.monitor.record(world, dt);
    }

    /// Writes a row of `drum.csv` (means since the previous row) and returns it.
    pub fn write_row(&mut self, world: &World) -> io::Result<DrumRow> {
        let r = self.monitor.take_row(world);
        let mut row = format!(
            "{:.9e},{:.6},{:.9e},{:.9e},{:.9e},{:.9e}",
            world.time, r.revolutions, r.angular_speed, r.drive_torque, r.power, r.gravity_moment
        );
        for t in &r.wall_torques {
            row.push_str(&format!(",{t:.9e}"));
        }
        match r.angle_of_repose {
            Some(a) => row.push_str(&format!(",{a:.4}")),
            None => row.push(','),
        }
        writeln!(self.csv, "{row}")?;
        self.csv.flush()?;
        Ok(r)
    }

    /// Writes the per-revolution table, the field and the summary; returns the
    /// summary.
    pub fn finish(&mut self, dir: &Path, world: &World) -> io::Result<DrumSummary> {
        let mut revs = BufWriter::new(File::create(dir.join("drum_revolutions.csv"))?);
        writeln!(
            revs,
            "revolution,start,end,drive_torque,power,gravity_moment,angle_of_repose,surface_samples"
        )?;
        for r in self.monitor.revolutions() {
            writeln!(
                revs,
                "{},{:.6e},{:.6e},{:.9e},{:.9e},{:.9e},{},{}",
                r.number,
                r.start,
                r.end,
                r.drive_torque,
                r.power,
                r.gravity_moment,
                r.angle_of_repose
                    .map_or(String::new(), |a| format!("{a:.4}")),
                r.surface_samples
            )?;
        }
        revs.flush()?;
        self.write_field(dir)?;
        let summary = self.monitor.summary(world);
        let text = serde_json::to_string_pretty(&summary).map_err(io::Error::other)?;
        std::fs::write(dir.join("drum.json"), text + "\n")?;
        Ok(summary)
    }

    fn write_field(&self, dir: &Path) -> io::Result<()> {
        let field = self.monitor.field();
        let drum = self.monitor.drum();
        let cell_volume = field.cell * field.cell * drum.slice;
        let mut csv = BufWriter::new(File::create(dir.join("drum_field.csv"))?);
        writeln!(csv, "h,v,count,solid_fraction,u_h,u_v,speed")?;
        let mut top: Real = 0.0;
        for c in field.cells() {
            if c.count == 0 {
                continue;
            }
            let speed = c.velocity[0].hypot(c.velocity[1]);
            top = top.max(speed);
            writeln!(
                csv,
                "{:.6e},{:.6e},{},{:.6e},{:.6e},{:.6e},{:.6e}",
                c.centre[0],
                c.centre[1],
                c.count,
                c.volume / cell_volume,
                c.velocity[0],
                c.velocity[1],
                speed
            )?;
        }
        csv.flush()?;
        // The image: `scale` pixels per cell, v up.
        let scale = (480 / field.n.max(1)).max(1);
        let size = scale * field.n;
        let mut image = Image::new(size, size);
        let px_per_m = scale as Real / field.cell;
        for j in 0..field.n {
            for i in 0..field.n {
                let c = field.cell(i, j);
                let inside = c.centre[0].hypot(c.centre[1]) <= field.radius;
                let colour = if c.count > 0 {
                    viridis(c.velocity[0].hypot(c.velocity[1]) / top.max(Real::MIN_POSITIVE))
                } else if inside {
                    [210, 210, 210]
                } else {
                    continue;
                };
                for dy in 0..scale {
                    for dx in 0..scale {
                        let x = (i * scale + dx) as i64;
                        let y = ((field.n - 1 - j) * scale + dy) as i64;
                        image.put(x, y, colour);
                    }
                }
            }
        }
        let to_pixel = |h: Real, v: Real| {
            (
                ((h + field.radius) * px_per_m).round() as i64,
                (size as Real - (v + field.radius) * px_per_m).round() as i64,
            )
        };
        let steps = 8 * size;
        for k in 0..steps {
            let a = std::f64::consts::TAU * k as Real / steps as Real;
            let (x, y) = to_pixel(field.radius * a.cos(), field.radius * a.sin());
            image.put(x, y, [0, 0, 0]);
        }
        if let Some(s) = self.monitor.mean_surface() {
            for k in 0..steps {
                let h = -field.radius + 2.0 * field.radius * k as Real / steps as Real;
                let v = s.intercept + s.slope * h;
                if h.hypot(v) < field.radius {
                    let (x, y) = to_pixel(h, v);
                    image.put(x, y, [220, 30, 30]);
                }
            }
        }
        let mut png = BufWriter::new(File::create(dir.join("drum_field.png"))?);
        image.write_png(&mut png)?;
        png.flush()
    }
}
