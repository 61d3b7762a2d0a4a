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
//!   the plot colours the mean speed (viridis, colour bar in m/s, axes in metres),
//!   grey where no particle came, with the drum's rim in black and the mean free
//!   surface in red;
//! - `drum_torque.png`: the drive torque and the bed's gravitational moment of each
//!   row of `drum.csv` against time;
//! - `drum.json`: averages over the analysis window (see
//!   [`crate::analysis::DrumSummary`]).

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

use plotters::style::RGBColor;

use super::plot::{Cell, HeatMap, LineChart, Series};
use crate::Real;
use crate::analysis::{Drum, DrumMonitor, DrumRow, DrumSummary};
use crate::world::{MassMoments, World};

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

    /// Accounts for a step of length `dt`, the bed's mass moments being `bed`.
    pub fn record(&mut self, world: &World, bed: &MassMoments, dt: Real) {
        self.monitor.record(world, bed, dt);
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
        self.plot_torque(dir)?;
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
        self.plot_field(&dir.join("drum_field.png"), top)
    }

    /// `drum_field.png`: the mean speed of each cell, the rim and the mean free
    /// surface, in the cross-section's coordinates.
    fn plot_field(&self, path: &Path, top: Real) -> io::Result<()> {
        let field = self.monitor.field();
        let half = 0.5 * field.cell;
        let mut cells = Vec::new();
        for j in 0..field.n {
            for i in 0..field.n {
                let c = field.cell(i, j);
                let inside = c.centre[0].hypot(c.centre[1]) <= field.radius;
                if c.count == 0 && !inside {
                    continue;
                }
                cells.push(Cell {
                    x: (c.centre[0] - half, c.centre[0] + half),
                    y: (c.centre[1] - half, c.centre[1] + half),
                    value: (c.count > 0).then(|| c.velocity[0].hypot(c.velocity[1])),
                });
            }
        }
        let r = field.radius;
        let rim = (0..=360)
            .map(|k| {
                let a = (k as Real).to_radians();
                (r * a.cos(), r * a.sin())
            })
            .collect();
        let mut overlays = vec![Series {
            name: "drum wall".into(),
            points: rim,
            colour: RGBColor(0, 0, 0),
        }];
        // The line v = intercept + slope h between its two crossings of the rim (a
        // mean of unsteady fits, as in a cataracting drum, may miss the drum).
        let surface: Vec<(Real, Real)> = self.monitor.mean_surface().map_or(Vec::new(), |s| {
            (0..=400)
                .map(|k| {
                    let h = -r + 2.0 * r * k as Real / 400.0;
                    (h, s.intercept + s.slope * h)
                })
                .filter(|(h, v)| h.hypot(*v) < r)
                .collect()
        });
        if surface.len() > 1 {
            let points = surface;
            overlays.push(Series {
                name: "mean free surface".into(),
                points,
                colour: RGBColor(220, 30, 30),
            });
        }
        let margin = 0.03 * r;
        HeatMap {
            title: format!(
                "Drum: time-averaged particle speed, central slice (largest {top:.3} m/s)"
            ),
            x_label: "h, across the cross-section (m)".into(),
            y_label: "v, up (m)".into(),
            value_label: "mean speed (m/s)".into(),
            extent: (-r - margin, r + margin),
            cells,
            overlays,
        }
        .write_png(path)
    }

    /// `drum_torque.png`: the drive torque and the bed's gravitational moment of each
    /// row of `drum.csv` against time (read back from the file, so a resumed run
    /// plots the whole run).
    fn plot_torque(&mut self, dir: &Path) -> io::Result<()> {
        self.csv.flush()?;
        let text = std::fs::read_to_string(dir.join("drum.csv"))?;
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
        let column = |name: &str| {
            header
                .iter()
                .position(|h| *h == name)
                .ok_or_else(|| io::Error::other(format!("drum.csv has no column {name}")))
        };
        let (t, drive, gravity) = (
            column("time")?,
            column("drive_torque")?,
            column("gravity_moment")?,
        );
        let rows: Vec<Vec<Real>> = lines
            .map(|l| {
                l.split(',')
                    .map(|x| x.parse().unwrap_or(Real::NAN))
                    .collect()
            })
            .collect();
        let at = |r: &[Real], k: usize| r.get(k).copied().unwrap_or(Real::NAN);
        let curve = |k: usize| rows.iter().map(|r| (at(r, t), at(r, k))).collect();
        LineChart::new(
            "Drum: torque about the axis (mean over each output interval)",
            "time (s)",
            "torque (N m)",
        )
        .with("drive torque", curve(drive))
        .with("gravitational moment of the bed", curve(gravity))
        .write_png(&dir.join("drum_torque.png"))
    }
}
