//! The dynamic state of a [`Simulation`]: what a saved state, a rollback and a
//! checkpoint hold (its bytes: [`super::state_bytes`]).
//!
//! What is kept is everything that evolves: the owned particles (with this step's
//! forces, which the next half kick uses, and whether they are frozen), wall poses,
//! velocities and forces, the tangential contact history, inlet counters, box offsets
//! and random generators, time, step count, the settling clock, the bed height last
//! measured, the energy account, and a coupled fluid's inputs, particle shares and
//! exchange. What a scene defines once (materials, shapes, wall meshes and their facet
//! grids) is not: a state is restored into a simulation of the same scene. Restoring
//! and stepping on gives the same bits as never having saved.

use nalgebra::{Isometry3, Vector3};

use super::Simulation;
use super::energy_ledger::EnergyLedger;
use super::state_bytes::{StateError, StateReader, StateWriter};
use crate::Real;
use crate::engine::{ContactHistory, ListAnchors, StepStats};
use crate::world::{CellShares, MomentumExchange, Particles};

/// Everything of a [`Simulation`] that evolves.
#[derive(Clone, Debug)]
pub struct SimState {
    /// Simulated time.
    pub time: Real,
    /// The step length asked for.
    pub dt: Real,
    /// Steps taken.
    pub steps: u64,
    /// Id of the next inserted particle.
    pub next_id: u64,
    /// Since when the settling criterion holds.
    pub quiet_since: Option<Real>,
    /// The bed height last measured.
    pub bed_height: Option<Real>,
    /// Figures of the last force evaluation (contacts and elastic energy are kept).
    pub stats: StepStats,
    /// The energy account since the start.
    pub energy: EnergyLedger,
    /// The owned particles.
    pub particles: Particles,
    /// Each wall's motion and forces.
    pub walls: Vec<WallState>,
    /// Each inlet's progress.
    pub inlets: Vec<InletState>,
    /// The tangential contact history.
    pub history: ContactHistory,
    /// What the last build of the candidate lists started from (`None`: the lists
    /// are built from the restored world).
    pub list: Option<ListAnchors>,
    /// The fluid's inputs, shares and exchange, with a `[fluid]` section.
    pub fluid: Option<FluidState>,
}

/// What evolves of a fluid field: what the coupled code set, the particles' shares
/// of the cells at the last update and the exchange since it was last read.
#[derive(Clone, Debug, PartialEq)]
pub struct FluidState {
    /// Per cell: the fluid velocity.
    pub velocity: Vec<Vector3<Real>>,
    /// Per cell: the pressure gradient.
    pub pressure_gradient: Vec<Vector3<Real>>,
    /// Per cell: the solid fraction at the last update.
    pub solid_fraction: Vec<Real>,
    /// Per cell: the mean particle velocity at the last update.
    pub particle_velocity: Vec<Vector3<Real>>,
    /// The particles' shares of the cells.
    pub shares: CellShares,
    /// The exchange since it was last read.
    pub exchange: MomentumExchange,
}

/// What evolves of a wall.
#[derive(Clone, Debug, PartialEq)]
pub struct WallState {
    /// Pose of the wall frame.
    pub pose: Isometry3<Real>,
    /// Velocity of the reference point.
    pub velocity: Vector3<Real>,
    /// Angular velocity about the reference point.
    pub angular_velocity: Vector3<Real>,
    /// Force of the last step.
    pub force: Vector3<Real>,
    /// Torque about the reference point of the last step.
    pub torque: Vector3<Real>,
    /// Force on each facet of the last step.
    pub facet_force: Vec<Vector3<Real>>,
}

/// What evolves of an inlet.
#[derive(Clone, Debug, PartialEq)]
pub struct InletState {
    /// Particles inserted so far.
    pub inserted: usize,
    /// Particles to insert in all (lowered when the inlet is stopped).
    pub count: usize,
    /// Offset of the insertion box (an inlet riding above the bed).
    pub offset: Vector3<Real>,
    /// The random generator's state.
    pub rng: Vec<u8>,
}

impl Simulation {
    /// The state as it is now.
    pub fn snapshot(&self) -> SimState {
        let world = &self.world;
        SimState {
            time: world.time,
            dt: self.dt,
            steps: self.steps,
            next_id: self.next_id,
            quiet_since: self.quiet_since,
            bed_height: self.bed_height,
            stats: *self.backend.stats(),
            energy: self.energy,
            particles: world.particles.owned_only(),
            walls: world
                .walls
                .iter()
                .map(|w| WallState {
                    pose: w.pose,
                    velocity: w.velocity,
                    angular_velocity: w.angular_velocity,
                    force: w.force,
                    torque: w.torque,
                    facet_force: w.facet_force.clone(),
                })
                .collect(),
            inlets: self
                .inlets
                .iter()
                .map(|i| InletState {
                    inserted: i.inserted,
                    count: i.count,
                    offset: i.offset,
                    rng: i.rng_state(),
                })
                .collect(),
            history: self.backend.contact_history(),
            list: self.backend.list_anchors(),
            fluid: world.fluid.as_ref().map(|f| FluidState {
                velocity: f.velocity.clone(),
                pressure_gradient: f.pressure_gradient.clone(),
                solid_fraction: f.solid_fraction.clone(),
                particle_velocity: f.particle_velocity.clone(),
                shares: f.shares.clone(),
                exchange: f.exchange.clone(),
            }),
        }
    }

    /// Writes the state as bytes headed by the scene's `fingerprint` (see
    /// [`SimState::write`]).
    pub fn write_state(&self, fingerprint: u64, w: &mut StateWriter) {
        self.snapshot().write(fingerprint, w);
    }

    /// Restores a state written by [`Simulation::write_state`] for the scene with this
    /// `fingerprint`, leaving the reader after it. On error nothing changed.
    pub fn read_state(&mut self, fingerprint: u64, r: &mut StateReader) -> Result<(), StateError> {
        let state = SimState::read(fingerprint, r)?;
        self.restore(&state)
    }

    /// Whether `state` fits this simulation's scene: its body types, walls, facets and
    /// inlets.
    pub fn check_state(&self, state: &SimState) -> Result<(), StateError> {
        self.restored_inlets(state).map(|_| ())
    }

    /// Goes back to `state` (one of this scene, see [`Simulation::check_state`]); on
    /// error nothing changed. The backend learns of it through its restore call.
    pub fn restore(&mut self, state: &SimState) -> Result<(), StateError> {
        if self.backend.share().is_some() {
            return Err(StateError::OnRanks);
        }
        let inlets = self.restored_inlets(state)?;
        self.inlets = inlets;
        let world = &mut self.world;
        world.time = state.time;
        world.particles = state.particles.clone();
        self.particles_behind = false;
        for (wall, s) in world.walls.iter_mut().zip(&state.walls) {
            wall.pose = s.pose;
            wall.velocity = s.velocity;
            wall.angular_velocity = s.angular_velocity;
            wall.force = s.force;
            wall.torque = s.torque;
            wall.facet_force.clone_from(&s.facet_force);
        }
        self.dt = state.dt;
        self.steps = state.steps;
        self.next_id = state.next_id;
        self.quiet_since = state.quiet_since;
        self.bed_height = state.bed_height;
        self.energy = state.energy;
        if let (Some(f), Some(s)) = (world.fluid.as_mut(), &state.fluid) {
            f.velocity.clone_from(&s.velocity);
            f.pressure_gradient.clone_from(&s.pressure_gradient);
            f.solid_fraction.clone_from(&s.solid_fraction);
            f.particle_velocity.clone_from(&s.particle_velocity);
            f.shares = s.shares.clone();
            f.exchange = s.exchange.clone();
        }
        self.backend
            .restore(&self.world, state.history.clone(), state.stats);
        if let Some(anchors) = &state.list {
            self.backend.resume_lists(anchors.clone());
        }
        Ok(())
    }

    /// The inlets as `state` has them, after checking that it fits the scene.
    fn restored_inlets(&self, state: &SimState) -> Result<Vec<crate::world::Inlet>, StateError> {
        let corrupt = |m: String| Err(StateError::Corrupt(m));
        if !(state.dt.is_finite() && state.dt > 0.0) {
            return corrupt(format!("time step {} is not a positive number", state.dt));
        }
        if !state.time.is_finite() {
            return corrupt(format!("time {} is not finite", state.time));
        }
        let world = &self.world;
        let types = world.body_types.len() as u64;
        let p = &state.particles;
        if let Some(i) = (0..p.len()).find(|&i| p.body_type[i] as u64 >= types) {
            return corrupt(format!(
                "particle {} has body type {}; the scene has {types}",
                p.id[i], p.body_type[i]
            ));
        }
        if let Some(i) = (0..p.len()).find(|&i| !p.is_finite(i)) {
            return corrupt(format!(
                "particle {} has a non-finite position, velocity or force",
                p.id[i]
            ));
        }
        if state.walls.len() != world.walls.len() {
            return corrupt(format!(
                "{} walls; the scene has {}",
                state.walls.len(),
                world.walls.len()
            ));
        }
        for (wall, s) in world.walls.iter().zip(&state.walls) {
            if s.facet_force.len() != wall.facet_force.len() {
                return corrupt(format!(
                    "wall '{}' has {} facets in the state, {} in the scene",
                    wall.name,
                    s.facet_force.len(),
                    wall.facet_force.len()
                ));
            }
        }
        if state.inlets.len() != self.inlets.len() {
            return corrupt(format!(
                "{} inlets; the scene has {}",
                state.inlets.len(),
                self.inlets.len()
            ));
        }
        check_fluid(world.fluid.as_ref().map(|f| f.grid.len()), state)?;
        let mut inlets = self.inlets.clone();
        for (inlet, s) in inlets.iter_mut().zip(&state.inlets) {
            inlet.inserted = s.inserted;
            inlet.count = s.count;
            inlet.offset = s.offset;
            inlet
                .set_rng_state(&s.rng)
                .map_err(|e| StateError::Corrupt(format!("inlet generator: {e}")))?;
        }
        Ok(inlets)
    }
}

/// Whether the state's fluid fits a scene whose grid has `cells` cells (`None`: no
/// fluid).
fn check_fluid(cells: Option<usize>, state: &SimState) -> Result<(), StateError> {
    let corrupt = |m: String| Err(StateError::Corrupt(m));
    match (cells, &state.fluid) {
        (None, None) => Ok(()),
        (Some(_), None) => corrupt("the scene has a fluid, the state none".into()),
        (None, Some(_)) => corrupt("the state has a fluid, the scene none".into()),
        (Some(n), Some(f)) => {
            let lengths = [
                f.velocity.len(),
                f.pressure_gradient.len(),
                f.solid_fraction.len(),
                f.particle_velocity.len(),
                f.exchange.impulse.len(),
            ];
            if lengths.iter().any(|&l| l != n) {
                return corrupt(format!(
                    "fluid arrays of {lengths:?} cells; the scene's grid has {n}"
                ));
            }
            if f.shares.parts().1.iter().any(|&c| c as usize >= n) {
                return corrupt(format!("fluid shares name cells beyond the grid's {n}"));
            }
            if f.exchange.drag.len() > state.particles.len()
                || f.shares.len() > state.particles.len()
            {
                return corrupt(
                    "fluid drag or shares for more particles than the state holds".into(),
                );
            }
            Ok(())
        }
    }
}
