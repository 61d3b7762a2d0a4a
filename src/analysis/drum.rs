//! Rotating-drum figures: drive torque and power, the torque on each of the drum's
//! walls, the dynamic angle of repose per revolution, a time-averaged velocity field
//! of the cross-section, the flowing-layer thickness and the signs of the flow
//! regime.
//!
//! A drum is one or more walls that turn together (a shell and the end caps attached
//! to it, see `motion = { kind = "attached" }`) about an axis through the first
//! wall's reference point. The **drive torque** is the torque the motor must apply
//! about the axis to keep the drum's motion against the bed, `−Σ_w τ_w · â`, where
//! `τ_w` is the torque the particles exert on wall `w` about the axis point; it is
//! positive when it turns the drum in the `+â` sense. The **power** is what the
//! walls deliver to the bed. In steady motion the drive torque balances the
//! gravitational moment of the bed about the axis, `−((x_c − c) × M g) · â`
//! (`x_c` the bed's centre of mass), which is recorded alongside as a check.

use nalgebra::{Point3, Vector3};
use serde::{Deserialize, Serialize};

use super::field::VelocityField;
use super::regime::{FlowSignSums, FlowSigns, Regime};
use super::surface::{SurfaceFit, fit_surface};
use crate::Real;
use crate::world::{MassMoments, World};

/// A drum resolved against the world: which walls turn together, the axis and the
/// part of the cross-section that is analysed. Axis and centre are kept in the first
/// wall's frame so that they follow the drum wherever it is moved.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Drum {
    /// The drum's walls (indices into the world's walls); the first carries the axis.
    pub walls: Vec<usize>,
    /// Unit axis in the first wall's frame.
    pub axis_local: Vector3<Real>,
    /// The middle of the drum on the axis, in the first wall's frame.
    pub centre_local: Point3<Real>,
    /// Inner radius (largest distance of a wall vertex from the axis), m.
    pub radius: Real,
    /// Length along the axis covered by the walls, m.
    pub length: Real,
    /// Thickness of the central slice that the surface fit and the field use, m.
    pub slice: Real,
    /// Velocity-field cell edge, m.
    pub cell: Real,
    /// Circumscribed diameter of the largest particle (surface-fit column width), m.
    pub diameter: Real,
    /// Time between samples of the surface and the field, s.
    pub sample_interval: Real,
    /// Averages start here; `None`: once the first revolution is complete.
    pub average_after: Option<Real>,
}

impl Drum {
    /// Axis (unit) and centre in the world now.
    pub fn frame(&self, world: &World) -> (Vector3<Real>, Point3<Real>) {
        let pose = world.walls[self.walls[0]].pose;
        (pose * self.axis_local, pose * self.centre_local)
    }

    /// Unit vectors across the axis: horizontal `e_h` and upward `e_v` (against
    /// gravity; any perpendicular pair when gravity is along the axis or zero).
    pub fn cross_section(&self, world: &World, axis: &Vector3<Real>) -> [Vector3<Real>; 2] {
        let g = world.gravity - axis * axis.dot(&world.gravity);
        let up = if g.norm() > 0.0 {
            -g.normalize()
        } else {
            axis.cross(&Vector3::x())
                .try_normalize(1e-9)
                .unwrap_or_else(|| axis.cross(&Vector3::y()).normalize())
        };
        [up.cross(axis), up]
    }

    /// The drive torque about the axis (the motor's, positive along the axis), the
    /// axial torque the particles exert on each drum wall, and the power delivered,
    /// at this instant.
    pub fn torques(&self, world: &World) -> (Real, Vec<Real>, Real) {
        let per_wall: Vec<Real> = self
            .walls
            .iter()
            .map(|&w| {
                let wall = &world.walls[w];
                self.axial_torque(world, w, &wall.force, &wall.torque)
            })
            .collect();
        let power = self.walls.iter().map(|&w| world.walls[w].power()).sum();
        (-per_wall.iter().sum::<Real>(), per_wall, power)
    }

    /// The axial component, about the axis point, of a force and a torque (about
    /// its reference point) on wall `w`.
    pub fn axial_torque(
        &self,
        world: &World,
        w: usize,
        force: &Vector3<Real>,
        torque: &Vector3<Real>,
    ) -> Real {
        let (axis, centre) = self.frame(world);
        (torque + (world.walls[w].reference() - centre).cross(force)).dot(&axis)
    }

    /// Minus the gravitational moment of the bed about the axis: what the drive
    /// torque balances in steady motion.
    pub fn gravity_moment(&self, world: &World) -> Real {
        self.gravity_moment_of(world, &world.mass_moments())
    }

    /// [`Drum::gravity_moment`] of a bed of mass moments `bed` (the whole run's,
    /// on ranks): `Σ (x − c) × m g = (Σ m x − M c) × g`.
    pub fn gravity_moment_of(&self, world: &World, bed: &MassMoments) -> Real {
        let (axis, centre) = self.frame(world);
        let moment = (bed.first - centre.coords * bed.mass).cross(&world.gravity);
        -moment.dot(&axis)
    }

    /// Particles of the central slice in cross-section coordinates: centre `(h, v)`,
    /// velocity `(u_h, u_v)`, volume.
    pub fn slice_particles(&self, world: &World) -> Vec<([Real; 2], [Real; 2], Real)> {
        let (axis, centre) = self.frame(world);
        let [eh, ev] = self.cross_section(world, &axis);
        let p = &world.particles;
        (0..p.len())
            .filter_map(|i| {
                let d = p.position[i] - centre;
                (d.dot(&axis).abs() <= 0.5 * self.slice).then(|| {
                    let u = p.velocity[i];
                    let volume = world.body_types[p.body_type[i] as usize].shape.volume();
                    ([d.dot(&eh), d.dot(&ev)], [u.dot(&eh), u.dot(&ev)], volume)
                })
            })
            .collect()
    }

    /// The free surface of the central slice now.
    pub fn surface(&self, world: &World) -> Option<SurfaceFit> {
        let points: Vec<[Real; 2]> = self
            .slice_particles(world)
            .into_iter()
            .map(|(x, _, _)| x)
            .collect();
        fit_surface(&points, self.diameter)
    }

    /// Angular speed of the drum about its axis, rad/s (signed).
    pub fn angular_speed(&self, world: &World) -> Real {
        let (axis, _) = self.frame(world);
        world.walls[self.walls[0]].angular_velocity.dot(&axis)
    }
}

/// Impulses over an interval of time.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
struct Impulses {
    span: Real,
    drive: Real,
    walls: Vec<Real>,
    work: Real,
    moment: Real,
}

impl Impulses {
    fn add(&mut self, dt: Real, drive: Real, walls: &[Real], power: Real, moment: Real) {
        self.span += dt;
        self.drive += drive * dt;
        self.work += power * dt;
        self.moment += moment * dt;
        self.walls.resize(walls.len(), 0.0);
        for (a, b) in self.walls.iter_mut().zip(walls) {
            *a += b * dt;
        }
    }
}

/// One row of `drum.csv`: means over the interval since the previous row.
#[derive(Clone, Debug)]
pub struct DrumRow {
    /// Revolutions turned (absolute angle / 2π).
    pub revolutions: Real,
    /// Angular speed about the axis at the row's time, rad/s.
    pub angular_speed: Real,
    /// Mean drive torque, N m.
    pub drive_torque: Real,
    /// Mean axial torque of the particles on each drum wall, N m.
    pub wall_torques: Vec<Real>,
    /// Mean power delivered to the bed, W.
    pub power: Real,
    /// Mean of minus the bed's gravitational moment about the axis, N m.
    pub gravity_moment: Real,
    /// Angle of repose of the latest sample, degrees.
    pub angle_of_repose: Option<Real>,
}

/// Figures of one revolution.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Revolution {
    /// Revolution number, from 1.
    pub number: usize,
    /// Start time, s.
    pub start: Real,
    /// End time, s.
    pub end: Real,
    /// Mean drive torque, N m.
    pub drive_torque: Real,
    /// Mean power, W.
    pub power: Real,
    /// Mean of minus the gravitational moment of the bed, N m.
    pub gravity_moment: Real,
    /// Mean angle of repose over the samples with a surface, degrees.
    pub angle_of_repose: Option<Real>,
    /// Samples with a surface.
    pub surface_samples: usize,
}

/// Averages over the analysis window, written as `drum.json`.
#[derive(Clone, Debug, Default, Serialize)]
pub struct DrumSummary {
    /// Start of the averaging window, s (None: it never started).
    pub average_from: Option<Real>,
    /// Length of the window, s.
    pub averaged_over: Real,
    /// Mean angular speed (magnitude), rad/s.
    pub angular_speed: Real,
    /// Mean speed in revolutions per minute.
    pub rpm: Real,
    /// Froude number ω² R / g of the mean speed.
    pub froude: Real,
    /// Revolutions turned in all.
    pub revolutions: Real,
    /// Mean drive torque, N m.
    pub drive_torque: Real,
    /// Mean axial torque of the particles on each drum wall (name, N m).
    pub wall_torques: Vec<(String, Real)>,
    /// Mean power, W.
    pub power: Real,
    /// Mean of minus the bed's gravitational moment, N m.
    pub gravity_moment: Real,
    /// Dynamic angle of repose: mean over the samples, degrees.
    pub angle_of_repose: Option<Real>,
    /// Standard deviation of the sampled angles, degrees.
    pub angle_of_repose_std: Option<Real>,
    /// Mean fraction of the slice's particles more than two diameters above the
    /// fitted surface (in flight).
    pub airborne_fraction: Option<Real>,
    /// The signs of the flow regime the samples show (see [`super::regime`]).
    pub flow_signs: Option<FlowSigns>,
    /// The regime named from them.
    pub regime: Option<Regime>,
    /// Flowing-layer thickness at the middle of the surface, m.
    pub flowing_layer: Option<Real>,
    /// Particle volume over the drum's volume.
    pub solids_fraction: Real,
    /// Samples taken in the window.
    pub samples: usize,
    /// Drum radius, m.
    pub radius: Real,
    /// Thickness of the central slice, m.
    pub slice: Real,
}

/// Follows a drum through a run: fed after every step, sampled at intervals. It
/// serialises (serde) so that a resumed run's checkpoint carries what it summed.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DrumMonitor {
    drum: Drum,
    row: Impulses,
    revolution: Impulses,
    revolution_start: Real,
    revolution_angles: (Real, usize),
    revolutions: Vec<Revolution>,
    window: Impulses,
    window_start: Option<Real>,
    window_speed: Real,
    angles: Vec<Real>,
    slopes: (Real, Real, usize),
    airborne: (Real, usize),
    /// What the samples say of the flow regime (absent in checkpoints written
    /// before it was kept: those runs start it at their resume).
    #[serde(default)]
    regime: FlowSignSums,
    turned: Real,
    next_sample: Real,
    last_angle: Option<Real>,
    field: VelocityField,
}

impl DrumMonitor {
    /// Starts following `drum` at the world's current time.
    pub fn new(drum: Drum, world: &World) -> Self {
        let field = VelocityField::new(drum.radius, drum.cell);
        DrumMonitor {
            row: Impulses::default(),
            revolution: Impulses::default(),
            revolution_start: world.time,
            revolution_angles: (0.0, 0),
            revolutions: Vec::new(),
            window: Impulses::default(),
            window_start: None,
            window_speed: 0.0,
            angles: Vec::new(),
            slopes: (0.0, 0.0, 0),
            airborne: (0.0, 0),
            regime: FlowSignSums::default(),
            turned: 0.0,
            next_sample: world.time,
            last_angle: None,
            field,
            drum,
        }
    }

    /// The drum followed.
    pub fn drum(&self) -> &Drum {
        &self.drum
    }

    /// Whether the step of length `dt` that ended at `t` takes a sample of the bed
    /// (of the whole bed: on ranks, the world gathered).
    pub fn samples_at(&self, t: Real, dt: Real) -> bool {
        t >= self.next_sample - 1e-9 * dt
    }

    /// Accounts for a step of length `dt` that ended at the world's time, the bed's
    /// mass moments being `bed` (see [`Drum::gravity_moment_of`]).
    pub fn record(&mut self, world: &World, bed: &MassMoments, dt: Real) {
        let (drive, walls, power) = self.drum.torques(world);
        let moment = self.drum.gravity_moment_of(world, bed);
        let speed = self.drum.angular_speed(world);
        self.row.add(dt, drive, &walls, power, moment);
        self.revolution.add(dt, drive, &walls, power, moment);
        let before = (self.turned / std::f64::consts::TAU).floor();
        self.turned += speed.abs() * dt;
        let in_window = match self.drum.average_after {
            Some(t) => world.time >= t,
            None => before >= 1.0,
        };
        if in_window {
            self.window_start.get_or_insert(world.time - dt);
            self.window.add(dt, drive, &walls, power, moment);
            self.window_speed += speed.abs() * dt;
        }
        if self.samples_at(world.time, dt) {
            self.sample(world, in_window);
            while self.next_sample <= world.time + 1e-9 * dt {
                self.next_sample += self.drum.sample_interval;
            }
        }
        if (self.turned / std::f64::consts::TAU).floor() > before {
            self.close_revolution(world.time);
        }
    }

    fn sample(&mut self, world: &World, in_window: bool) {
        let particles = self.drum.slice_particles(world);
        let points: Vec<[Real; 2]> = particles.iter().map(|p| p.0).collect();
        let fit = fit_surface(&points, self.drum.diameter);
        self.last_angle = fit.map(|f| f.angle_degrees());
        if let Some(f) = fit {
            self.revolution_angles.0 += f.angle_degrees();
            self.revolution_angles.1 += 1;
        }
        if !in_window {
            return;
        }
        self.field.add_sample(&particles);
        self.regime.add(
            &particles,
            self.drum.angular_speed(world),
            self.drum.radius,
            self.drum.diameter,
            fit.as_ref(),
        );
        if let Some(f) = fit {
            self.angles.push(f.angle_degrees());
            self.slopes.0 += f.slope;
            self.slopes.1 += f.intercept;
            self.slopes.2 += 1;
            if !points.is_empty() {
                let flying = points
                    .iter()
                    .filter(|p| f.height_above(p[0], p[1]) > 2.0 * self.drum.diameter)
                    .count();
                self.airborne.0 += flying as Real / points.len() as Real;
                self.airborne.1 += 1;
            }
        }
    }

    fn close_revolution(&mut self, time: Real) {
        let r = std::mem::take(&mut self.revolution);
        let span = r.span.max(Real::MIN_POSITIVE);
        let (sum, n) = std::mem::take(&mut self.revolution_angles);
        self.revolutions.push(Revolution {
            number: self.revolutions.len() + 1,
            start: self.revolution_start,
            end: time,
            drive_torque: r.drive / span,
            power: r.work / span,
            gravity_moment: r.moment / span,
            angle_of_repose: (n > 0).then(|| sum / n as Real),
            surface_samples: n,
        });
        self.revolution_start = time;
    }

    /// Means since the previous row (instantaneous values for a row that closes no
    /// interval), and resets the row's sums.
    pub fn take_row(&mut self, world: &World) -> DrumRow {
        let r = std::mem::take(&mut self.row);
        let speed = self.drum.angular_speed(world);
        let revolutions = self.turned / std::f64::consts::TAU;
        if r.span > 0.0 {
            DrumRow {
                revolutions,
                angular_speed: speed,
                drive_torque: r.drive / r.span,
                wall_torques: r.walls.iter().map(|x| x / r.span).collect(),
                power: r.work / r.span,
                gravity_moment: r.moment / r.span,
                angle_of_repose: self.last_angle,
            }
        } else {
            let (drive, walls, power) = self.drum.torques(world);
            DrumRow {
                revolutions,
                angular_speed: speed,
                drive_torque: drive,
                wall_torques: walls,
                power,
                gravity_moment: self.drum.gravity_moment(world),
                angle_of_repose: self.last_angle,
            }
        }
    }

    /// Revolutions completed so far.
    pub fn revolutions(&self) -> &[Revolution] {
        &self.revolutions
    }

    /// The velocity field averaged over the window so far.
    pub fn field(&self) -> &VelocityField {
        &self.field
    }

    /// The mean free surface of the window's samples.
    pub fn mean_surface(&self) -> Option<SurfaceFit> {
        let (s, i, n) = self.slopes;
        (n > 0).then(|| SurfaceFit {
            slope: s / n as Real,
            intercept: i / n as Real,
            points: n,
        })
    }

    /// Averages over the window so far.
    pub fn summary(&self, world: &World) -> DrumSummary {
        let w = &self.window;
        let span = w.span;
        let mean = |x: Real| if span > 0.0 { x / span } else { 0.0 };
        let n = self.angles.len();
        let angle = (n > 0).then(|| self.angles.iter().sum::<Real>() / n as Real);
        let std = angle.map(|a| {
            (self.angles.iter().map(|x| (x - a).powi(2)).sum::<Real>() / n as Real).sqrt()
        });
        let speed = mean(self.window_speed);
        let g = world.gravity.norm();
        let solids: Real = (0..world.particles.len())
            .map(|i| {
                world.body_types[world.particles.body_type[i] as usize]
                    .shape
                    .volume()
            })
            .sum();
        let drum_volume = std::f64::consts::PI * self.drum.radius.powi(2) * self.drum.length;
        let airborne = (self.airborne.1 > 0).then(|| self.airborne.0 / self.airborne.1 as Real);
        let signs = self.regime.signs();
        DrumSummary {
            average_from: self.window_start,
            averaged_over: span,
            angular_speed: speed,
            rpm: speed * 60.0 / std::f64::consts::TAU,
            froude: if g > 0.0 {
                speed * speed * self.drum.radius / g
            } else {
                0.0
            },
            revolutions: self.turned / std::f64::consts::TAU,
            drive_torque: mean(w.drive),
            wall_torques: self
                .drum
                .walls
                .iter()
                .enumerate()
                .map(|(k, &i)| {
                    (
                        world.walls[i].name.clone(),
                        mean(w.walls.get(k).copied().unwrap_or(0.0)),
                    )
                })
                .collect(),
            power: mean(w.work),
            gravity_moment: mean(w.moment),
            angle_of_repose: angle,
            angle_of_repose_std: std,
            airborne_fraction: airborne,
            flow_signs: signs,
            regime: signs.and_then(|s| Regime::of(&s, airborne)),
            flowing_layer: self
                .mean_surface()
                .and_then(|s| self.field.flowing_layer(&s)),
            solids_fraction: solids / drum_volume,
            samples: self.field.samples,
            radius: self.drum.radius,
            slice: self.drum.slice,
        }
    }
}
