//! Reading and writing variables: every access checked against the variable's type,
//! causality and the mode, and a batch of writes applied all or none.

use super::component::{Component, Mode, RUNNING, WallDrive, fingerprint};
use super::variables::{Causality, Role, VarType, Variable, variable_table};
use super::{CosimError, VarRef};
use nalgebra::Vector3;

use crate::Real;
use crate::engine::choice::BackendKind;
use crate::scene::{MAX_THREADS, Scene};

const ANY_BUT_ERROR: &str = "instantiated, initialisation, step, terminated";

impl Component {
    fn var(&self, r: VarRef) -> Result<&Variable, CosimError> {
        let v = self
            .variables
            .get(r.var)
            .ok_or_else(|| CosimError::UnknownVariable(format!("index {}", r.var)))?;
        if r.element >= v.size {
            return Err(CosimError::BadAccess {
                name: v.name.clone(),
                problem: format!("element {} of a variable of size {}", r.element, v.size),
            });
        }
        Ok(v)
    }

    fn check_type(v: &Variable, ty: VarType) -> Result<(), CosimError> {
        if v.ty == ty {
            Ok(())
        } else {
            Err(CosimError::BadAccess {
                name: v.name.clone(),
                problem: format!("is of type {:?}, not {ty:?}", v.ty),
            })
        }
    }

    fn check_readable(&self, v: &Variable) -> Result<(), CosimError> {
        let running = [Mode::Initialisation, Mode::Step, Mode::Terminated];
        match v.causality {
            Causality::Output | Causality::Independent => {
                self.expect_mode("getting an output", &running, RUNNING)
            }
            _ => self.expect_mode(
                "getting a value",
                &[
                    Mode::Instantiated,
                    Mode::Initialisation,
                    Mode::Step,
                    Mode::Terminated,
                ],
                ANY_BUT_ERROR,
            ),
        }
    }

    fn check_writable(&self, v: &Variable) -> Result<(), CosimError> {
        match v.causality {
            Causality::Parameter => self.expect_mode(
                "setting a parameter",
                &[Mode::Instantiated, Mode::Initialisation],
                "instantiated, initialisation",
            ),
            Causality::Input => self.expect_mode(
                "setting an input",
                &[Mode::Instantiated, Mode::Initialisation, Mode::Step],
                "instantiated, initialisation, step",
            ),
            _ => Err(CosimError::BadAccess {
                name: v.name.clone(),
                problem: format!("is {:?}, it cannot be set", v.causality).to_lowercase(),
            }),
        }
    }

    /// Reads real values.
    pub fn get_real(&self, refs: &[VarRef], out: &mut [Real]) -> Result<(), CosimError> {
        for (r, o) in refs.iter().zip(out.iter_mut()) {
            let v = self.var(*r)?;
            Self::check_type(v, VarType::Real)?;
            self.check_readable(v)?;
            *o = self.real_value(v.role, r.element);
        }
        Ok(())
    }

    /// All values of one real variable.
    pub fn get_real_vector(&self, var: usize) -> Result<Vec<Real>, CosimError> {
        let size = self.variables.get(var).map_or(1, |v| v.size);
        let refs: Vec<VarRef> = (0..size).map(|element| VarRef { var, element }).collect();
        let mut out = vec![0.0; size];
        self.get_real(&refs, &mut out)?;
        Ok(out)
    }

    fn real_value(&self, role: Role, k: usize) -> Real {
        let drive = |w: usize| &self.drives[w];
        let sim = self.sim.as_ref();
        let fluid = sim.and_then(|s| s.fluid());
        match role {
            Role::Time => sim.map_or(0.0, |s| s.world().time),
            Role::TimeStep => self.params.dt,
            Role::KineticEnergy => sim.map_or(0.0, |s| s.kinetic_energy()),
            Role::MaxSpeed => sim.map_or(0.0, |s| s.max_speed()),
            Role::WallVelocity(w) => match drive(w) {
                WallDrive::Velocity { linear, .. } => linear[k],
                _ => 0.0,
            },
            Role::WallAngularVelocity(w) => match drive(w) {
                WallDrive::Velocity { angular, .. } => angular[k],
                _ => 0.0,
            },
            Role::WallPosition(w) => match drive(w) {
                WallDrive::Pose { position, .. } => position[k],
                _ => 0.0,
            },
            Role::WallOrientation(w) => match drive(w) {
                WallDrive::Pose { orientation, .. } => orientation[k],
                _ => 0.0,
            },
            Role::WallForce(w) => self.means[w].force[k],
            Role::WallTorque(w) => self.means[w].torque[k],
            Role::WallPower(w) => self.means[w].power,
            Role::WallForceEnd(w) => sim.map_or(0.0, |s| s.world().walls[w].force[k]),
            Role::WallTorqueEnd(w) => sim.map_or(0.0, |s| s.world().walls[w].torque[k]),
            Role::WallVertices(w) => {
                let wall = &self.world().walls[w];
                (wall.pose * wall.vertices[k / 3])[k % 3]
            }
            Role::WallFacetForces(w) => match &self.gathered {
                Some(g) => g.facet_forces[w][k / 3][k % 3],
                None => sim.map_or(0.0, |s| s.world().walls[w].facet_force[k / 3][k % 3]),
            },
            Role::DriveTorque => self.drum_means().0,
            Role::DrivePower => self.drum_means().1,
            Role::AngleOfRepose => match (sim, &self.scene.drum, &self.gathered) {
                (Some(_), Some(_), Some(g)) => g.angle_of_repose,
                (Some(s), Some(d), None) => d.surface(s.world()).map_or(0.0, |f| f.angle()),
                _ => 0.0,
            },
            Role::BedHeight
            | Role::BedPorosity
            | Role::BedSpecificSurface
            | Role::BedPermeability => match (sim, &self.scene.bed) {
                (Some(s), Some(bed)) => match &self.gathered {
                    Some(g) => g.bed.ok_or(()),
                    None => crate::analysis::packing::bed_figures(s.world(), bed).map_err(|_| ()),
                }
                .map_or(0.0, |f| match role {
                    Role::BedHeight => f.height,
                    Role::BedPorosity => f.porosity,
                    Role::BedSpecificSurface => f.specific_surface,
                    _ => f.permeability,
                }),
                _ => 0.0,
            },
            Role::FluidVelocity | Role::PressureGradient => {
                self.fluid_input(role).map_or(0.0, |x| x[k / 3][k % 3])
            }
            Role::SolidFraction => fluid.map_or(0.0, |f| f.solid_fraction[k]),
            Role::ParticleVelocity => fluid.map_or(0.0, |f| f.particle_velocity[k / 3][k % 3]),
            Role::MomentumSource => match self.gathered.as_ref().map(|g| &g.momentum_source) {
                Some(Some(source)) => source[k / 3][k % 3],
                _ => fluid.map_or(0.0, |f| f.momentum_source(k / 3)[k % 3]),
            },
            Role::Scene
            | Role::OutputDir
            | Role::Threads
            | Role::Backend
            | Role::Particles
            | Role::Contacts => {
                unreachable!("not a real variable")
            }
        }
    }

    /// The fluid's velocity or pressure gradient per cell: the simulation's once it
    /// exists, the start values before.
    fn fluid_input(&self, role: Role) -> Option<&[Vector3<Real>]> {
        let (velocity, gradient) = match (&self.sim, &self.fluid_start) {
            (Some(sim), _) => {
                let f = sim.fluid()?;
                (&f.velocity, &f.pressure_gradient)
            }
            (None, Some(start)) => (&start.velocity, &start.pressure_gradient),
            (None, None) => return None,
        };
        Some(if role == Role::FluidVelocity {
            velocity
        } else {
            gradient
        })
    }

    /// Applies elements set of the fluid's inputs, `(role, element, value)`, checked.
    fn set_fluid_inputs(&mut self, edits: &[(Role, usize, Real)]) {
        if edits.is_empty() {
            return;
        }
        let (Some(velocity), Some(gradient)) = (
            self.fluid_input(Role::FluidVelocity),
            self.fluid_input(Role::PressureGradient),
        ) else {
            unreachable!("fluid variables exist only with a fluid")
        };
        let (mut velocity, mut gradient) = (velocity.to_vec(), gradient.to_vec());
        for &(role, k, x) in edits {
            let field = if role == Role::FluidVelocity {
                &mut velocity
            } else {
                &mut gradient
            };
            field[k / 3][k % 3] = x;
        }
        match &mut self.sim {
            Some(sim) => sim
                .set_fluid_velocity(&velocity)
                .and_then(|()| sim.set_pressure_gradient(&gradient))
                .expect("checked finite, sized by the variable table"),
            None => {
                let start = self.fluid_start.as_mut().expect("a fluid");
                start.velocity = velocity;
                start.pressure_gradient = gradient;
            }
        }
    }

    /// The drum's mean drive torque about its axis (from the walls' mean forces and
    /// torques, moved to the axis point where it is at the end of the step) and mean
    /// power over the last step.
    fn drum_means(&self) -> (Real, Real) {
        let (Some(sim), Some(drum)) = (self.sim.as_ref(), &self.scene.drum) else {
            return (0.0, 0.0);
        };
        let mut torque = 0.0;
        let mut power = 0.0;
        for &w in &drum.walls {
            let m = &self.means[w];
            torque -= drum.axial_torque(sim.world(), w, &m.force, &m.torque);
            power += m.power;
        }
        (torque, power)
    }

    /// Sets real values, all or none.
    pub fn set_real(&mut self, refs: &[VarRef], values: &[Real]) -> Result<(), CosimError> {
        for (r, x) in refs.iter().zip(values) {
            let v = self.var(*r)?;
            Self::check_type(v, VarType::Real)?;
            self.check_writable(v)?;
            if !x.is_finite() {
                return Err(CosimError::BadValue {
                    name: v.name.clone(),
                    problem: format!("{x} is not finite"),
                });
            }
            if v.role == Role::TimeStep && !(*x > 0.0) {
                return Err(CosimError::BadValue {
                    name: v.name.clone(),
                    problem: format!("the time step must be positive, not {x}"),
                });
            }
        }
        let mut drives = self.drives.clone();
        let mut fluid = Vec::new();
        for (r, x) in refs.iter().zip(values) {
            let role = self.variables[r.var].role;
            let k = r.element;
            match role {
                Role::TimeStep => {
                    self.params.dt = *x;
                    if let Some(sim) = &mut self.sim {
                        sim.set_time_step(*x);
                    }
                }
                Role::WallVelocity(w) => {
                    if let WallDrive::Velocity { linear, .. } = &mut drives[w] {
                        linear[k] = *x;
                    }
                }
                Role::WallAngularVelocity(w) => {
                    if let WallDrive::Velocity { angular, .. } = &mut drives[w] {
                        angular[k] = *x;
                    }
                }
                Role::WallPosition(w) => {
                    if let WallDrive::Pose { position, .. } = &mut drives[w] {
                        position[k] = *x;
                    }
                }
                Role::WallOrientation(w) => {
                    if let WallDrive::Pose { orientation, .. } = &mut drives[w] {
                        orientation[k] = *x;
                    }
                }
                Role::FluidVelocity | Role::PressureGradient => fluid.push((role, k, *x)),
                _ => unreachable!("checked writable above"),
            }
        }
        self.set_fluid_inputs(&fluid);
        // A quaternion is checked when it is used (a master sets its elements one by
        // one): a zero quaternion at a step is an error there.
        self.drives = drives;
        Ok(())
    }

    /// Sets all values of one real variable.
    pub fn set_real_vector(&mut self, var: usize, values: &[Real]) -> Result<(), CosimError> {
        let refs: Vec<VarRef> = (0..values.len())
            .map(|element| VarRef { var, element })
            .collect();
        self.set_real(&refs, values)
    }

    /// Reads integer values.
    pub fn get_integer(&self, refs: &[VarRef], out: &mut [i64]) -> Result<(), CosimError> {
        for (r, o) in refs.iter().zip(out.iter_mut()) {
            let v = self.var(*r)?;
            Self::check_type(v, VarType::Integer)?;
            self.check_readable(v)?;
            let sim = self.sim.as_ref();
            *o = match v.role {
                Role::Threads => self.params.threads as i64,
                Role::Particles => sim.map_or(0, |s| s.particle_count() as i64),
                Role::Contacts => sim.map_or(0, |s| s.stats().contacts as i64),
                _ => unreachable!("not an integer variable"),
            };
        }
        Ok(())
    }

    /// Sets integer values, all or none.
    pub fn set_integer(&mut self, refs: &[VarRef], values: &[i64]) -> Result<(), CosimError> {
        for (r, x) in refs.iter().zip(values) {
            let v = self.var(*r)?;
            Self::check_type(v, VarType::Integer)?;
            self.check_writable(v)?;
            // Threads is the only settable integer.
            if !(1..=MAX_THREADS as i64).contains(x) {
                return Err(CosimError::BadValue {
                    name: v.name.clone(),
                    problem: format!("{x} threads; give 1 to {MAX_THREADS}"),
                });
            }
            if self.mode != Mode::Instantiated && *x as usize != self.params.threads {
                return Err(CosimError::BadValue {
                    name: v.name.clone(),
                    problem: "the thread count is fixed once initialisation starts".into(),
                });
            }
        }
        if let Some(x) = values.iter().take(refs.len()).next_back() {
            self.params.threads = *x as usize;
        }
        Ok(())
    }

    /// Reads string values.
    pub fn get_string(&self, refs: &[VarRef]) -> Result<Vec<String>, CosimError> {
        refs.iter()
            .map(|r| {
                let v = self.var(*r)?;
                Self::check_type(v, VarType::String)?;
                self.check_readable(v)?;
                Ok(match v.role {
                    Role::Scene => self.params.scene.clone(),
                    Role::OutputDir => self.params.output_dir.clone(),
                    Role::Backend => self.params.backend.name().to_string(),
                    _ => unreachable!("not a string variable"),
                })
            })
            .collect()
    }

    /// Sets string values (the scene before initialisation, the output directory
    /// before stepping).
    pub fn set_string(&mut self, refs: &[VarRef], values: &[&str]) -> Result<(), CosimError> {
        let mut scene = None;
        let mut params = self.params.clone();
        for (r, x) in refs.iter().zip(values) {
            let v = self.var(*r)?;
            Self::check_type(v, VarType::String)?;
            self.check_writable(v)?;
            match v.role {
                Role::Scene if *x != params.scene => {
                    if self.mode != Mode::Instantiated {
                        return Err(CosimError::BadValue {
                            name: v.name.clone(),
                            problem: "the scene is fixed once initialisation starts".into(),
                        });
                    }
                    let loaded = Scene::load(&self.base_dir.join(x))?;
                    if variable_table(&loaded) != self.variables {
                        return Err(CosimError::BadValue {
                            name: v.name.clone(),
                            problem: format!(
                                "scene '{x}' has other variables than the one instantiated"
                            ),
                        });
                    }
                    params.scene = x.to_string();
                    params.dt = loaded.dt;
                    params.backend = loaded.backend();
                    scene = Some(loaded);
                }
                Role::Scene => {}
                Role::OutputDir => params.output_dir = x.to_string(),
                Role::Backend => {
                    let bad = |problem: String| CosimError::BadValue {
                        name: v.name.clone(),
                        problem,
                    };
                    let kind: BackendKind = x.parse().map_err(bad)?;
                    if self.mode != Mode::Instantiated && kind != params.backend {
                        return Err(bad("the backend is fixed once initialisation starts".into()));
                    }
                    let on = scene.as_ref().unwrap_or(&self.scene);
                    crate::engine::choice::check(kind, &on.world, &on.step_params())
                        .map_err(|e| bad(format!("{x}: {e}")))?;
                    params.backend = kind;
                }
                _ => unreachable!("not a string variable"),
            }
        }
        if let Some(scene) = scene {
            self.fingerprint = fingerprint(&scene);
            self.scene = scene;
        }
        self.params = params;
        Ok(())
    }
}
