//! Requests to component calls, component state to replies.

use nalgebra::Vector3;
use prost::Message;

use super::messages::{
    self as pb, InfoReply, StateReply, StepReply, WallForces, WallsReply, state_request,
    wall_motion,
};
use super::ranks::Call;
use crate::Real;
use crate::cosim::{Causality, Component, VarRef, VarType};
use crate::engine::exchange::Ranks;

/// A component behind the message interface.
#[derive(Debug)]
pub struct Service {
    pub(super) component: Component,
    sequence: u64,
    /// On MPI ranks: the ranks rank 0 hands its requests to (see [`super::ranks`]).
    pub(super) ranks: Option<Box<dyn Ranks>>,
}

fn vec3(v: &[Real]) -> pb::Vec3 {
    pb::Vec3 {
        x: v[0],
        y: v[1],
        z: v[2],
    }
}

fn from_vec3(v: &Option<pb::Vec3>) -> [Real; 3] {
    v.as_ref().map_or([0.0; 3], |v| [v.x, v.y, v.z])
}

impl Service {
    /// Serves `component`, which must be in step mode.
    pub fn new(component: Component) -> Self {
        Service {
            component,
            sequence: 0,
            ranks: None,
        }
    }

    /// The component.
    pub fn component(&self) -> &Component {
        &self.component
    }

    /// The component, mutably (to terminate it at shutdown).
    pub fn component_mut(&mut self) -> &mut Component {
        &mut self.component
    }

    fn vector(&self, name: &str) -> Result<Vec<Real>, String> {
        let var = self.component.variable(name).map_err(|e| e.to_string())?;
        self.component
            .get_real_vector(var)
            .map_err(|e| e.to_string())
    }

    pub(super) fn time(&self) -> Real {
        self.component.simulation().map_or(0.0, |s| s.world().time)
    }

    /// `<key>/step`: sets the wall inputs and steps; on any error nothing changes.
    pub fn step(&mut self, payload: &[u8]) -> StepReply {
        self.tell_ranks(Call::Step, payload);
        match self.try_step(payload) {
            Ok(reply) => reply,
            Err(error) => StepReply {
                status: pb::Status::Error as i32,
                error,
                time: self.time(),
                sequence: self.sequence,
                ..Default::default()
            },
        }
    }

    fn try_step(&mut self, payload: &[u8]) -> Result<StepReply, String> {
        let request =
            pb::StepRequest::decode(payload).map_err(|e| format!("malformed StepRequest: {e}"))?;
        let mut refs = Vec::new();
        let mut values = Vec::new();
        for motion in &request.walls {
            let name = &motion.wall;
            if self.component.wall(name).is_none() {
                return Err(format!("no wall called '{name}'"));
            }
            let (names, parts): ([String; 2], Vec<Vec<Real>>) = match &motion.motion {
                Some(wall_motion::Motion::Velocity(v)) => (
                    [
                        format!("{name}.velocity"),
                        format!("{name}.angular_velocity"),
                    ],
                    vec![
                        from_vec3(&v.linear).to_vec(),
                        from_vec3(&v.angular).to_vec(),
                    ],
                ),
                Some(wall_motion::Motion::Pose(p)) => {
                    let q = p
                        .orientation
                        .as_ref()
                        .map_or([1.0, 0.0, 0.0, 0.0], |q| [q.w, q.x, q.y, q.z]);
                    (
                        [format!("{name}.position"), format!("{name}.orientation")],
                        vec![from_vec3(&p.position).to_vec(), q.to_vec()],
                    )
                }
                None => return Err(format!("wall '{name}': no velocity or pose given")),
            };
            for (var_name, part) in names.iter().zip(parts) {
                let var = self.component.variable(var_name).map_err(|_| {
                    format!("wall '{name}' is not driven from outside by this kind of input")
                })?;
                for (element, x) in part.into_iter().enumerate() {
                    refs.push(VarRef { var, element });
                    values.push(x);
                }
            }
        }
        if let Some(fluid) = &request.fluid {
            for (name, given) in [
                ("fluid.velocity", &fluid.velocity),
                ("fluid.pressure_gradient", &fluid.pressure_gradient),
            ] {
                if given.is_empty() {
                    continue;
                }
                let var = self
                    .component
                    .variable(name)
                    .map_err(|_| "the scene has no [fluid] section".to_string())?;
                let size = self.component.variables()[var].size;
                if given.len() != size {
                    return Err(format!(
                        "{name}: {} values, the grid takes {size} (x y z per cell)",
                        given.len()
                    ));
                }
                refs.extend((0..size).map(|element| VarRef { var, element }));
                values.extend_from_slice(given);
            }
        }
        // Inputs are set all or none, and put back if the step is refused.
        let mut previous = vec![0.0; refs.len()];
        self.component
            .get_real(&refs, &mut previous)
            .map_err(|e| e.to_string())?;
        self.component
            .set_real(&refs, &values)
            .map_err(|e| e.to_string())?;
        if let Err(e) = self.component.do_step(request.time, request.step) {
            self.component
                .set_real(&refs, &previous)
                .expect("the previous inputs were valid");
            return Err(e.to_string());
        }
        self.sequence += 1;
        self.forces()
    }

    /// The reply describing the current state (forces of the last step).
    pub fn forces(&self) -> Result<StepReply, String> {
        let mut walls = Vec::new();
        for wall in &self.component.scene().world.walls {
            let n = &wall.name;
            walls.push(WallForces {
                wall: n.clone(),
                force: Some(vec3(&self.vector(&format!("{n}.force"))?)),
                torque: Some(vec3(&self.vector(&format!("{n}.torque"))?)),
                force_end: Some(vec3(&self.vector(&format!("{n}.force_end"))?)),
                torque_end: Some(vec3(&self.vector(&format!("{n}.torque_end"))?)),
                power: self.vector(&format!("{n}.power"))?[0],
            });
        }
        let sim = self
            .component
            .simulation()
            .ok_or("the component is not running")?;
        Ok(StepReply {
            status: pb::Status::Ok as i32,
            error: String::new(),
            time: sim.world().time,
            walls,
            globals: Some(pb::Globals {
                particles: sim.particle_count() as u64,
                contacts: sim.stats().contacts as u64,
                kinetic_energy: sim.kinetic_energy(),
                max_speed: sim.max_speed(),
            }),
            sequence: self.sequence,
        })
    }

    /// `<key>/walls`: meshes as placed now, per-facet forces on request.
    pub fn walls(&self, payload: &[u8]) -> WallsReply {
        let result = (|| {
            let request = pb::WallsRequest::decode(payload)
                .map_err(|e| format!("malformed WallsRequest: {e}"))?;
            let all: Vec<String> = self
                .component
                .scene()
                .world
                .walls
                .iter()
                .map(|w| w.name.clone())
                .collect();
            let names = if request.walls.is_empty() {
                all
            } else {
                request.walls.clone()
            };
            let mut walls = Vec::new();
            for name in names {
                let w = self
                    .component
                    .wall(&name)
                    .ok_or_else(|| format!("no wall called '{name}'"))?;
                let mesh = self.component.wall_mesh(w).expect("the wall exists");
                let pose = self
                    .component
                    .simulation()
                    .map_or(self.component.scene().world.walls[w].pose, |s| {
                        s.world().walls[w].pose
                    });
                let q = pose.rotation;
                walls.push(pb::WallMesh {
                    wall: name.clone(),
                    vertices: mesh.vertices.iter().flat_map(|v| [v.x, v.y, v.z]).collect(),
                    triangles: mesh.triangles.iter().flatten().copied().collect(),
                    pose: Some(pb::Pose {
                        position: Some(vec3(pose.translation.vector.as_slice())),
                        orientation: Some(pb::Quaternion {
                            w: q.w,
                            x: q.i,
                            y: q.j,
                            z: q.k,
                        }),
                    }),
                    facet_forces: if request.facet_forces {
                        self.vector(&format!("{name}.facet_force"))?
                    } else {
                        Vec::new()
                    },
                });
            }
            Ok::<_, String>(walls)
        })();
        match result {
            Ok(walls) => WallsReply {
                status: pb::Status::Ok as i32,
                error: String::new(),
                walls,
            },
            Err(error) => WallsReply {
                status: pb::Status::Error as i32,
                error,
                walls: Vec::new(),
            },
        }
    }

    /// `<key>/info`: walls, variables, units, time step.
    pub fn info(&self, payload: &[u8]) -> InfoReply {
        if let Err(e) = pb::InfoRequest::decode(payload) {
            return InfoReply {
                status: pb::Status::Error as i32,
                error: format!("malformed InfoRequest: {e}"),
                ..Default::default()
            };
        }
        let c = &self.component;
        let variables = c
            .variables()
            .iter()
            .map(|v| pb::VariableInfo {
                name: v.name.clone(),
                r#type: match v.ty {
                    VarType::Real => "real",
                    VarType::Integer => "integer",
                    VarType::String => "string",
                }
                .into(),
                causality: match v.causality {
                    Causality::Parameter => "parameter",
                    Causality::Input => "input",
                    Causality::Output => "output",
                    Causality::Independent => "independent",
                }
                .into(),
                unit: v.unit.unwrap_or("").into(),
                description: v.description.clone(),
                size: v.size as u32,
            })
            .collect();
        let walls = c
            .scene()
            .world
            .walls
            .iter()
            .map(|w| pb::WallInfo {
                name: w.name.clone(),
                drive: match w.motion {
                    crate::world::WallMotion::External(crate::world::DriveInput::Velocity) => {
                        "velocity"
                    }
                    crate::world::WallMotion::External(crate::world::DriveInput::Pose) => "pose",
                    _ => "prescribed",
                }
                .into(),
                reference: Some(vec3(Vector3::from(w.reference().coords).as_slice())),
                vertices: w.vertices.len() as u32,
                triangles: w.triangles.len() as u32,
            })
            .collect();
        InfoReply {
            status: pb::Status::Ok as i32,
            error: String::new(),
            scene: c.scene().file.display().to_string(),
            dt: c.simulation().map_or(c.scene().dt, |s| s.dt()),
            time: self.time(),
            walls,
            variables,
            talus_version: env!("CARGO_PKG_VERSION").into(),
            fingerprint: c.fingerprint(),
        }
    }

    /// `<key>/fluid`: the grid and the per-cell fields of a coupled fluid (and, when
    /// asked, what the fluid does to each particle: on ranks gathered from all).
    pub fn fluid(&self, payload: &[u8]) -> pb::FluidReply {
        self.tell_ranks(Call::Fluid, payload);
        let result = (|| {
            let request = pb::FluidRequest::decode(payload)
                .map_err(|e| format!("malformed FluidRequest: {e}"))?;
            let grid = self.component.fluid_grid().map_err(|e| e.to_string())?;
            let (ids, particles) = if request.particles {
                self.component.particle_fluid().map_err(|e| e.to_string())?
            } else {
                (Vec::new(), Vec::new())
            };
            let flat = |f: fn(&crate::world::ParticleFluid) -> [Real; 3]| {
                particles.iter().flat_map(f).collect::<Vec<_>>()
            };
            Ok::<_, String>(pb::FluidReply {
                particle_ids: ids,
                particle_drag: flat(|p| p.drag.into()),
                particle_slip: flat(|p| p.slip.into()),
                particle_voidage: particles.iter().map(|p| p.voidage).collect(),
                status: pb::Status::Ok as i32,
                error: String::new(),
                time: self.time(),
                grid: Some(fluid_grid(grid)),
                solid_fraction: self.vector("fluid.solid_fraction")?,
                particle_velocity: self.vector("fluid.particle_velocity")?,
                momentum_source: self.vector("fluid.momentum_source")?,
                velocity: self.vector("fluid.velocity")?,
                pressure_gradient: self.vector("fluid.pressure_gradient")?,
            })
        })();
        result.unwrap_or_else(|error| pb::FluidReply {
            status: pb::Status::Error as i32,
            error,
            time: self.time(),
            ..Default::default()
        })
    }

    /// `<key>/state`: save (the bytes come back) or restore.
    pub fn state(&mut self, payload: &[u8]) -> StateReply {
        self.tell_ranks(Call::State, payload);
        let result = (|| {
            let request = pb::StateRequest::decode(payload)
                .map_err(|e| format!("malformed StateRequest: {e}"))?;
            match request.action {
                Some(state_request::Action::Save(_)) => {
                    let state = self.component.save_state().map_err(|e| e.to_string())?;
                    Ok(self.component.state_to_bytes(&state))
                }
                Some(state_request::Action::Restore(bytes)) => {
                    let state = self
                        .component
                        .state_from_bytes(&bytes)
                        .map_err(|e| e.to_string())?;
                    self.component
                        .restore_state(&state)
                        .map_err(|e| e.to_string())?;
                    Ok(Vec::new())
                }
                None => Err("a StateRequest needs save or restore".to_string()),
            }
        })();
        match result {
            Ok(state) => StateReply {
                status: pb::Status::Ok as i32,
                error: String::new(),
                state,
                time: self.time(),
            },
            Err(error) => StateReply {
                status: pb::Status::Error as i32,
                error,
                state: Vec::new(),
                time: self.time(),
            },
        }
    }
}

/// The message of a fluid's cells.
fn fluid_grid(grid: &crate::fluid::FluidGrid) -> pb::FluidGrid {
    let cartesian = grid.as_cartesian();
    pb::FluidGrid {
        origin: cartesian.map(|g| vec3(g.origin().coords.as_slice())),
        cell: cartesian.map(|g| vec3(g.cell_size().as_slice())),
        counts: cartesian.map_or(Vec::new(), |g| {
            g.counts().iter().map(|&n| n as u32).collect()
        }),
        kind: grid.kind().into(),
        centres: (0..grid.len())
            .flat_map(|c| grid.centre(c).coords.as_slice().to_vec())
            .collect(),
        volumes: (0..grid.len()).map(|c| grid.cell_volume(c)).collect(),
    }
}
