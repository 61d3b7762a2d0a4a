//! The component: life cycle and communication steps.

use std::fmt;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use nalgebra::{Point3, UnitQuaternion, Vector3};

use super::CosimError;
use super::pool::JoinedPool;
use super::ranks::{Gathered, new_simulation};
use super::variables::{Variable, variable_table};
use crate::Real;
use crate::engine::choice::BackendKind;
use crate::engine::exchange::Ranks;
use crate::output::{OutputClock, RunOutput};
use crate::recording::Outputs;
use crate::scene::energy_balance::EnergyBalance;
use crate::scene::spec::SphereFrames;
use crate::scene::{Scene, SimState, Simulation};
use crate::world::{DriveInput, ParticleFluid, WallMotion, World};

/// Mode of the life cycle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Created; parameters and start values may be set.
    Instantiated,
    /// Between enter and exit of initialisation: the simulation exists, outputs can be
    /// read, inputs and parameters set.
    Initialisation,
    /// Stepping.
    Step,
    /// Terminated: outputs can still be read.
    Terminated,
    /// A panic or an unrecoverable failure: only reset or free.
    Error,
}

impl fmt::Display for Mode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Mode::Instantiated => "instantiated",
            Mode::Initialisation => "initialisation",
            Mode::Step => "step",
            Mode::Terminated => "terminated",
            Mode::Error => "error",
        })
    }
}

/// One element of a variable: `(variable index, element index)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VarRef {
    /// Index into [`Component::variables`].
    pub var: usize,
    /// Element within the variable (0 for a scalar).
    pub element: usize,
}

/// What the master set for one wall driven from outside (held over a step).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum WallDrive {
    /// Not driven from outside.
    Prescribed,
    /// Linear and angular velocity.
    Velocity {
        /// Of the reference point.
        linear: Vector3<Real>,
        /// About the reference point.
        angular: Vector3<Real>,
    },
    /// Pose to reach at the end of the step; the quaternion (w, x, y, z) as set,
    /// normalised when used.
    Pose {
        /// Reference point.
        position: Vector3<Real>,
        /// Orientation as given.
        orientation: [Real; 4],
    },
}

/// Mean force, torque and power on one wall over the last communication step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WallMeans {
    /// Mean force, N.
    pub force: Vector3<Real>,
    /// Mean torque about the reference point, N m.
    pub torque: Vector3<Real>,
    /// Mean power delivered to the particles, W.
    pub power: Real,
}

/// A saved state: everything that evolves, in memory.
#[derive(Clone, Debug)]
pub struct ComponentState {
    /// The fingerprint of the scene it was saved from (see [`fingerprint`]).
    pub(super) fingerprint: u64,
    pub(super) sim: SimState,
    pub(super) drives: Vec<WallDrive>,
    pub(super) means: Vec<WallMeans>,
}

/// A wall's mesh as it is placed now.
#[derive(Clone, Debug)]
pub struct WallMesh<'a> {
    /// Vertices in the world.
    pub vertices: Vec<Point3<Real>>,
    /// Triangles (vertex indices), counter-clockwise seen from the particles.
    pub triangles: &'a [[u32; 3]],
}

/// The fluid's inputs per cell as the master set them before the simulation exists
/// (from then on they live in the simulation's fluid field).
#[derive(Clone, Debug, PartialEq)]
pub(super) struct FluidInputs {
    pub(super) velocity: Vec<Vector3<Real>>,
    pub(super) pressure_gradient: Vec<Vector3<Real>>,
}

impl FluidInputs {
    /// The scene's start values, with a `[fluid]` section.
    fn of(scene: &Scene) -> Option<Self> {
        scene.world.fluid.as_ref().map(|f| FluidInputs {
            velocity: f.velocity.clone(),
            pressure_gradient: f.pressure_gradient.clone(),
        })
    }
}

/// Parameters a master may change before the simulation runs.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Parameters {
    pub(super) scene: String,
    pub(super) dt: Real,
    pub(super) output_dir: String,
    pub(super) threads: usize,
    /// What steps the scene (default: the scene's `[simulation] backend`).
    pub(super) backend: BackendKind,
}

/// A scene behind an FMI-style life cycle (see the [module docs](super)).
pub struct Component {
    pub(super) base_dir: PathBuf,
    pub(super) scene: Scene,
    pub(super) fingerprint: u64,
    pub(super) variables: Vec<Variable>,
    pub(super) mode: Mode,
    pub(super) start: Parameters,
    pub(super) params: Parameters,
    pub(super) drives: Vec<WallDrive>,
    pub(super) means: Vec<WallMeans>,
    /// The fluid's inputs until initialisation starts.
    pub(super) fluid_start: Option<FluidInputs>,
    pub(super) sim: Option<Simulation>,
    pub(super) pool: Option<JoinedPool>,
    pub(super) output: Option<Outputs>,
    /// On MPI ranks: the ranks (see [`super::ranks`]).
    pub(super) ranks: Option<Box<dyn Ranks>>,
    /// On ranks, rank 0's readings of the whole run after the last change.
    pub(super) gathered: Option<Gathered>,
}

impl fmt::Debug for Component {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Component")
            .field("scene", &self.scene.file)
            .field("mode", &self.mode)
            .field("time", &self.sim.as_ref().map(|s| s.world().time))
            .finish()
    }
}

/// A 64-bit fingerprint of a scene: its whole specification and variable names. A
/// saved state carries it; an FMU's guid is made from it.
pub fn fingerprint(scene: &Scene) -> u64 {
    let mut text = format!("talus {} {:?}", env!("CARGO_PKG_VERSION"), scene.spec);
    for v in variable_table(scene) {
        text.push_str(&v.name);
    }
    crate::checksum::fnv1a(text.as_bytes(), crate::checksum::FNV_OFFSET)
}

/// The most DEM steps one `do_step` may take (hours of a small scene): a step far
/// longer than the time step is refused instead of hanging the master.
pub const MAX_SUBSTEPS: Real = 1e8;

pub(super) const RUNNING: &str = "initialisation, step, terminated";

impl Component {
    /// Loads the scene at `path` (relative to `base_dir` when relative).
    pub fn instantiate(base_dir: &Path, path: &str) -> Result<Self, CosimError> {
        let scene = Scene::load(&base_dir.join(path))?;
        let start = Parameters {
            scene: path.to_string(),
            dt: scene.dt,
            output_dir: String::new(),
            threads: scene.spec.simulation.threads.max(1),
            backend: scene.backend(),
        };
        let drives = initial_drives(&scene);
        Ok(Component {
            base_dir: base_dir.to_path_buf(),
            fingerprint: fingerprint(&scene),
            variables: variable_table(&scene),
            mode: Mode::Instantiated,
            params: start.clone(),
            start,
            means: vec![WallMeans::default(); drives.len()],
            drives,
            fluid_start: FluidInputs::of(&scene),
            scene,
            sim: None,
            pool: None,
            output: None,
            ranks: None,
            gathered: None,
        })
    }

    /// The variable table.
    pub fn variables(&self) -> &[Variable] {
        &self.variables
    }

    /// Index of the variable called `name`.
    pub fn variable(&self, name: &str) -> Result<usize, CosimError> {
        self.variables
            .iter()
            .position(|v| v.name == name)
            .ok_or_else(|| CosimError::UnknownVariable(format!("'{name}'")))
    }

    /// The scene's fingerprint (see [`fingerprint`]).
    pub fn fingerprint(&self) -> u64 {
        self.fingerprint
    }

    /// The loaded scene.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// What a user should know about the scene at the current parameters (a time
    /// step above the suggested one), as `talus check` says it. The FMI faces log
    /// these when initialisation starts.
    pub fn warnings(&self) -> Vec<String> {
        crate::scene::time_step_warning(self.params.dt, self.scene.suggested.as_ref())
            .into_iter()
            .collect()
    }

    /// The current mode.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// The running simulation (from initialisation on).
    pub fn simulation(&self) -> Option<&Simulation> {
        self.sim.as_ref()
    }

    /// Puts the component in the error state (after a panic in a call).
    pub fn fail(&mut self) {
        self.mode = Mode::Error;
    }

    pub(super) fn expect_mode(
        &self,
        call: &'static str,
        allowed: &[Mode],
        names: &'static str,
    ) -> Result<(), CosimError> {
        if allowed.contains(&self.mode) {
            Ok(())
        } else {
            Err(CosimError::WrongMode {
                call,
                mode: self.mode,
                allowed: names,
            })
        }
    }

    /// Leaves instantiation: builds the simulation from the parameters, starting at
    /// `start_time`.
    pub fn enter_initialization_mode(&mut self, start_time: Real) -> Result<(), CosimError> {
        self.expect_mode(
            "enter_initialization_mode",
            &[Mode::Instantiated],
            "instantiated",
        )?;
        if !start_time.is_finite() {
            return Err(CosimError::BadStep(format!(
                "start time {start_time} is not finite"
            )));
        }
        let pool =
            JoinedPool::new(self.params.threads).map_err(|e| CosimError::Threads(e.to_string()));
        if self.failed_anywhere(pool.is_err()) {
            pool?;
            return Err(CosimError::Ranks(
                "another rank could not start its worker threads".into(),
            ));
        }
        let pool = pool?;
        let exchange = self.ranks.as_ref().map(|r| r.another());
        let (scene, backend) = (&self.scene, self.params.backend);
        let mut sim = pool.install(move || new_simulation(scene, backend, exchange, None))?;
        sim.set_time_step(self.params.dt);
        sim.set_time(start_time);
        if let Some(start) = &self.fluid_start {
            sim.set_fluid_velocity(&start.velocity)
                .and_then(|()| sim.set_pressure_gradient(&start.pressure_gradient))
                .expect("the start values were checked when set");
        }
        self.pool = Some(pool);
        self.sim = Some(sim);
        self.means = vec![WallMeans::default(); self.drives.len()];
        self.mode = Mode::Initialisation;
        Ok(())
    }

    /// Starts stepping: applies the inputs and evaluates the forces at the start time.
    pub fn exit_initialization_mode(&mut self) -> Result<(), CosimError> {
        self.expect_mode(
            "exit_initialization_mode",
            &[Mode::Initialisation],
            "initialisation",
        )?;
        let output = if self.params.output_dir.is_empty() {
            None
        } else {
            let sim = self.sim.as_ref().expect("initialisation has a simulation");
            let out = &self.scene.spec.output;
            let drum = self.scene.drum.is_some();
            let output = if self.rank().is_none_or(|(rank, _)| rank == 0) {
                RunOutput::create(
                    &self.base_dir.join(&self.params.output_dir),
                    sim.world(),
                    out.frame_interval,
                    out.csv_interval,
                    self.scene.drum.as_ref(),
                )
                .map(|files| {
                    let points = out.spheres == SphereFrames::Points;
                    Outputs::writing(files.with_sphere_points(points), drum)
                })
            } else {
                let clock = OutputClock::new(out.frame_interval, out.csv_interval, sim.time());
                Ok(Outputs::following(clock, drum))
            };
            if self.failed_anywhere(output.is_err()) {
                output?;
                return Err(rank_0_output_error("create the output files"));
            }
            output.ok()
        };
        self.check_orientations()?;
        let sim = self
            .sim
            .as_mut()
            .expect("a running component has a simulation");
        let pool = self.pool.as_ref().expect("a running component has a pool");
        let drives = &self.drives;
        sim.move_walls(|walls| {
            for (wall, drive) in walls.iter_mut().zip(drives) {
                match drive {
                    WallDrive::Prescribed => {}
                    WallDrive::Velocity { linear, angular } => {
                        wall.velocity = *linear;
                        wall.angular_velocity = *angular;
                    }
                    WallDrive::Pose {
                        position,
                        orientation,
                    } => {
                        wall.pose.translation.vector = *position;
                        wall.pose.rotation = unit_quaternion(orientation);
                    }
                }
            }
        });
        pool.install(|| sim.initialise());
        self.means = instantaneous_means(sim);
        self.output = output;
        self.mode = Mode::Step;
        self.gather();
        Ok(())
    }

    fn check_orientations(&self) -> Result<(), CosimError> {
        for (w, drive) in self.drives.iter().enumerate() {
            if let WallDrive::Pose { orientation, .. } = drive {
                let norm = orientation.iter().map(|x| x * x).sum::<Real>().sqrt();
                if !(norm > 1e-12) {
                    return Err(CosimError::BadValue {
                        name: format!("{}.orientation", self.scene.world.walls[w].name),
                        problem: "the quaternion is zero".into(),
                    });
                }
            }
        }
        Ok(())
    }

    /// Advances from `t` (the current time) by `h`, inputs held.
    pub fn do_step(&mut self, t: Real, h: Real) -> Result<(), CosimError> {
        self.expect_mode("do_step", &[Mode::Step], "step")?;
        if !(h > 0.0) || !h.is_finite() {
            return Err(CosimError::BadStep(format!(
                "step size {h} must be positive and finite"
            )));
        }
        let now = self.sim.as_ref().expect("step mode").time();
        if !t.is_finite() || (t - now).abs() > 1e-9 * now.abs().max(h) {
            return Err(CosimError::BadStep(format!(
                "the step starts at {t} but the component is at time {now}"
            )));
        }
        // The step length in use: the parameter's, or a restored state's.
        let dt = self.sim.as_ref().expect("step mode").dt();
        // At a time so large that a DEM step is below the clock's resolution, the
        // clock would not advance (and the step would never end).
        if !((now + dt) - now > 0.5 * dt) {
            return Err(CosimError::BadStep(format!(
                "at t = {now:e} s a DEM step of {dt:e} s is below the resolution of the clock"
            )));
        }
        let substeps = (h / dt).ceil();
        if !(substeps <= MAX_SUBSTEPS) {
            return Err(CosimError::BadStep(format!(
                "the step of {h:e} s would take {substeps:e} DEM steps of {dt:e} s; at most \
                 {MAX_SUBSTEPS:e} in one call (a longer step, or a larger dt)"
            )));
        }
        let drives = self.drives.clone();
        self.check_orientations()?;
        let sim = self
            .sim
            .as_mut()
            .expect("a running component has a simulation");
        let pool = self.pool.as_ref().expect("a running component has a pool");
        // Rollback through the saved state, not a copy of the whole simulation
        // (on ranks: each rank's share, made whole only when it is needed).
        let before = sim.share_snapshot();
        // The momentum source is the mean over this step (and the shares are new
        // with update_interval = "communication").
        sim.start_communication_step();
        let balance = EnergyBalance::start(sim);
        // A start within round-off before the component's time must not take the
        // clock back.
        let end = (t + h).max(now);
        let mut impulse = vec![WallMeans::default(); drives.len()];
        let mut targets = Vec::new();
        sim.move_walls(|walls| {
            for (w, (wall, drive)) in walls.iter_mut().zip(&drives).enumerate() {
                match drive {
                    WallDrive::Prescribed => {}
                    WallDrive::Velocity { linear, angular } => {
                        wall.velocity = *linear;
                        wall.angular_velocity = *angular;
                    }
                    WallDrive::Pose {
                        position,
                        orientation,
                    } => {
                        let q = unit_quaternion(orientation);
                        wall.velocity = (position - wall.pose.translation.vector) / h;
                        wall.angular_velocity =
                            (q * wall.pose.rotation.inverse()).scaled_axis() / h;
                        targets.push((w, *position, q));
                    }
                }
            }
        });
        let mut output = self.output.take();
        // Without outputs to write, the particles come back from a device backend
        // once, at the end of the communication step (the divergence check, the
        // outputs of the step).
        sim.set_particles_each_step(output.is_some());
        // On ranks every rank takes every step: an output error (on rank 0 only) is
        // kept for the end of the step instead of ending it there.
        let on_ranks = self.ranks.is_some();
        let mut failed = None;
        let result = pool.install(|| -> std::io::Result<()> {
            let mut last = instantaneous_means(sim);
            let advanced = sim.advance_to(end, |sim, sub| {
                let now = instantaneous_means(sim);
                for ((acc, a), b) in impulse.iter_mut().zip(&last).zip(&now) {
                    acc.force += (a.force + b.force) * (0.5 * sub);
                    acc.torque += (a.torque + b.torque) * (0.5 * sub);
                    acc.power += (a.power + b.power) * (0.5 * sub);
                }
                last = now;
                match output.as_mut().map(|out| out.record(sim, sub, false)) {
                    Some(Err(e)) if !on_ranks => ControlFlow::Break(e),
                    Some(Err(e)) => {
                        failed.get_or_insert(e);
                        ControlFlow::Continue(())
                    }
                    _ => ControlFlow::Continue(()),
                }
            });
            match (advanced, failed) {
                (ControlFlow::Break(e), _) | (_, Some(e)) => Err(e),
                (ControlFlow::Continue(()), None) => Ok(()),
            }
        });
        sim.sync_particles();
        sim.set_time(end);
        sim.move_walls(|walls| {
            for (w, position, q) in targets {
                walls[w].pose.translation.vector = position;
                walls[w].pose.rotation = q;
            }
        });
        self.output = output;
        let diverged = sim
            .first_non_finite()
            .map(|id| format!("particle {id} has a non-finite position, velocity or force"))
            .or_else(|| balance.broken(sim));
        if let Some(problem) = diverged {
            let before = self.whole_state(before);
            self.install_state(&before)
                .expect("a snapshot of this simulation restores");
            self.gather();
            return Err(CosimError::Diverged(problem));
        }
        self.gather();
        // Every rank fails a step that failed to write on rank 0, so that a host
        // that puts the inputs back after a failed step does so on every rank.
        if self.failed_anywhere(result.is_err()) {
            result?;
            return Err(rank_0_output_error("write the outputs of the step"));
        }
        let sim = self
            .sim
            .as_ref()
            .expect("a running component has a simulation");
        // A step too short for a sub-step (below 1e-9 of one) reports the forces of
        // the state it leaves, not a mean of nothing.
        self.means = if sim.steps == before.steps() {
            instantaneous_means(sim)
        } else {
            impulse
                .iter()
                .map(|m| WallMeans {
                    force: m.force / h,
                    torque: m.torque / h,
                    power: m.power / h,
                })
                .collect()
        };
        Ok(())
    }

    /// Ends the run (writes the last output rows and frame).
    pub fn terminate(&mut self) -> Result<(), CosimError> {
        self.expect_mode(
            "terminate",
            &[Mode::Initialisation, Mode::Step],
            "initialisation, step",
        )?;
        if let (Some(out), Some(sim)) = (&mut self.output, &self.sim) {
            // Both collective on ranks: each is made whether or not the other wrote.
            let recorded = out.record(sim, 0.0, true);
            let finished = out.finish(sim, &self.scene).map(drop);
            let written = recorded.and(finished);
            if self.failed_anywhere(written.is_err()) {
                written?;
                return Err(rank_0_output_error("write the last outputs"));
            }
        }
        self.output = None;
        self.mode = Mode::Terminated;
        Ok(())
    }

    /// Makes the parameters set so far the start values that [`Component::reset`]
    /// returns to (instantiated mode only): a node keeps the output directory and
    /// threads it was started with through the resets of a master.
    pub fn keep_parameters_on_reset(&mut self) -> Result<(), CosimError> {
        self.expect_mode(
            "keeping the parameters",
            &[Mode::Instantiated],
            "instantiated",
        )?;
        self.start = self.params.clone();
        Ok(())
    }

    /// Back to the instantiated mode with the start values (any mode).
    pub fn reset(&mut self) {
        self.sim = None;
        self.pool = None;
        self.output = None;
        self.gathered = None;
        if self.params.scene != self.start.scene {
            if let Ok(scene) = Scene::load(&self.base_dir.join(&self.start.scene)) {
                self.fingerprint = fingerprint(&scene);
                self.scene = scene;
            }
        }
        self.params = self.start.clone();
        self.drives = initial_drives(&self.scene);
        self.means = vec![WallMeans::default(); self.drives.len()];
        self.fluid_start = FluidInputs::of(&self.scene);
        self.mode = Mode::Instantiated;
    }

    /// Wall `w`'s vertices in the world and its triangles.
    pub fn wall_mesh(&self, w: usize) -> Option<WallMesh<'_>> {
        let wall = self
            .sim
            .as_ref()
            .map_or(self.scene.world.walls.get(w), |s| s.world().walls.get(w))?;
        Some(WallMesh {
            vertices: wall.vertices.iter().map(|v| wall.pose * v).collect(),
            triangles: &wall.triangles,
        })
    }

    /// The grid of the scene's coupled fluid, whose cells the `fluid.*` arrays
    /// follow; an error that says so without a `[fluid]` section.
    pub fn fluid_grid(&self) -> Result<&crate::fluid::FluidGrid, CosimError> {
        self.scene
            .world
            .fluid
            .as_ref()
            .map(|f| &f.grid)
            .ok_or(CosimError::NoFluid)
    }

    /// Each particle's id and what the fluid does to it (drag of the last force
    /// evaluation, slip, local voidage: [`ParticleFluid`]), in id order (on ranks
    /// collective: the whole run's on rank 0, empty lists on the others); before
    /// initialisation the scene's particles at rest in the start fields (no drag
    /// yet). Particles come and go, so this crosses the faces as whole lists (C
    /// API, zenoh), not as variables.
    pub fn particle_fluid(&self) -> Result<(Vec<u64>, Vec<ParticleFluid>), CosimError> {
        let world = self.world();
        let fluid = world.fluid.as_ref().ok_or(CosimError::NoFluid)?;
        if let Some(sim) = &self.sim {
            return Ok(sim.whole_particle_fluid().unwrap_or_default());
        }
        let p = &world.particles;
        let n = p.owned();
        Ok((
            p.id[..n].to_vec(),
            (0..n).map(|i| fluid.at_particle(p, i)).collect(),
        ))
    }

    /// The simulation's world once it exists, the scene's at time 0 before.
    pub fn world(&self) -> &World {
        self.sim.as_ref().map_or(&self.scene.world, |s| s.world())
    }

    /// Index of the wall called `name`.
    pub fn wall(&self, name: &str) -> Option<usize> {
        self.scene.world.walls.iter().position(|w| w.name == name)
    }

    /// Mean force, torque and power on each wall over the last step.
    pub fn wall_means(&self) -> &[WallMeans] {
        &self.means
    }
}

/// The error of the ranks whose rank 0 could not `what`.
fn rank_0_output_error(what: &str) -> CosimError {
    CosimError::Output(std::io::Error::other(format!("rank 0 could not {what}")))
}

fn initial_drives(scene: &Scene) -> Vec<WallDrive> {
    scene
        .world
        .walls
        .iter()
        .map(|wall| match wall.motion {
            WallMotion::External(DriveInput::Velocity) => WallDrive::Velocity {
                linear: wall.velocity,
                angular: wall.angular_velocity,
            },
            WallMotion::External(DriveInput::Pose) => {
                let q = wall.pose.rotation;
                WallDrive::Pose {
                    position: wall.pose.translation.vector,
                    orientation: [q.w, q.i, q.j, q.k],
                }
            }
            _ => WallDrive::Prescribed,
        })
        .collect()
}

fn unit_quaternion(q: &[Real; 4]) -> UnitQuaternion<Real> {
    crate::geometry::unit_quaternion(q[0], q[1], q[2], q[3])
        .unwrap_or_else(UnitQuaternion::identity)
}

fn instantaneous_means(sim: &Simulation) -> Vec<WallMeans> {
    sim.world()
        .walls
        .iter()
        .map(|w| WallMeans {
            force: w.force,
            torque: w.torque,
            power: w.power(),
        })
        .collect()
}
