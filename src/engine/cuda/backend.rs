//! The CUDA backend behind the seam ([`Backend`]): a [`DeviceWorld`] on a
//! [`Device`], kept in step with the host world by the seam's sync contract.
//!
//! The device holds the particles between steps; after each step the host world
//! gets the walls' poses, forces and facet forces, the clock, the touching flags and
//! the step's figures (a few numbers), and the particles with their touching flags
//! when it asks (`sync_to_host`). What the host changes in its world is uploaded
//! alone where it can be: particles added by an inlet are appended, frozen flags
//! and velocities set are uploaded, walls moved from outside are placed; particles
//! removed or anything else rebuild the stepper from the host world at the next
//! evaluation, the contact history carried over.
//!
//! On an MPI rank it steps the rank's share ([`ShareStepper`]): in a step without a
//! renewal only the halo crosses (the states of the particles sent as ghosts down,
//! the ghosts' states up); a renewal copies the owned particles down, and the
//! stepper is made again from the rank's new share.
//!
//! A device call that fails (a lost GPU, a sphere at more than four walls) panics:
//! the seam's calls are infallible, and a backend that lost its state cannot go on.

use std::fmt;

use super::device::{Device, DeviceError};
use super::stepper::{DeviceWorld, StepperError};
use crate::Real;
use crate::engine::backend::{Backend, ContactHistory};
use crate::engine::params::StepParams;
use crate::engine::rank::ShareStepper;
use crate::engine::stats::{StageTimes, StepStats};
use crate::world::{RunFigures, World};

/// The CUDA backend (see the module).
pub struct CudaBackend {
    params: StepParams,
    /// The device while no stepper holds it.
    idle: Option<Box<dyn Device>>,
    on_device: Option<DeviceWorld>,
    /// The history to set on the next stepper (a restore, or the one replaced).
    history: Option<ContactHistory>,
    stats: StepStats,
    /// Zero: a device's stages are not timed (see `step`).
    times: StageTimes,
    touching: Vec<bool>,
    /// Particles integrated (not frozen) by the stepper.
    integrated: usize,
    /// Steppers made from the whole host world.
    made: u64,
    /// The owned entries a step sends to other ranks, sorted (kept between steps).
    sent: Vec<usize>,
}

impl fmt::Debug for CudaBackend {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("CudaBackend")
            .field("params", &self.params)
            .field("stats", &self.stats)
            .finish_non_exhaustive()
    }
}

/// The particles of `world` that are integrated (owned, not frozen).
fn integrated(world: &World) -> usize {
    world.particles.owned() - world.particles.frozen_count()
}

fn fail(e: impl fmt::Display) -> ! {
    panic!("the cuda backend failed: {e}")
}

impl CudaBackend {
    /// A backend on `device` stepping `world` (checked: see [`DeviceWorld::new`]).
    pub fn new(
        device: Box<dyn Device>,
        world: &World,
        params: StepParams,
    ) -> Result<Self, StepperError> {
        let on_device = DeviceWorld::new(device, world, &params)?;
        Ok(CudaBackend {
            on_device: Some(on_device),
            integrated: integrated(world),
            made: 1,
            ..Self::without_device(params)
        })
    }

    /// A backend on `device` that makes its stepper from the host world at the
    /// first evaluation (a rank's, once it has cut its share; the world checked
    /// by [`DeviceWorld::check`] before).
    pub fn idle(device: Box<dyn Device>, params: StepParams) -> Self {
        CudaBackend {
            idle: Some(device),
            ..Self::without_device(params)
        }
    }

    /// The fields of a backend before it holds a device.
    fn without_device(params: StepParams) -> Self {
        CudaBackend {
            params,
            idle: None,
            on_device: None,
            history: None,
            stats: StepStats::default(),
            times: StageTimes::default(),
            touching: Vec::new(),
            integrated: 0,
            made: 0,
            sent: Vec::new(),
        }
    }

    /// How many times the stepper was made again from the whole host world (a change
    /// the backend does not upload alone: particles removed, parameters or the
    /// world changed, a state restored, a rank's renewal).
    pub fn rebuilds(&self) -> u64 {
        self.made.saturating_sub(1)
    }

    /// The stepper, rebuilt from `world` if the host changed it.
    fn stepper(&mut self, world: &World) -> &mut DeviceWorld {
        if self.on_device.is_none() {
            let device = self.idle.take().expect("a device");
            let mut on_device =
                DeviceWorld::new(device, world, &self.params).unwrap_or_else(|e| fail(e));
            if let Some(history) = self.history.take() {
                on_device.set_history(&history).unwrap_or_else(|e| fail(e));
            }
            self.on_device = Some(on_device);
            self.integrated = integrated(world);
            self.made += 1;
        }
        self.on_device.as_mut().expect("a stepper")
    }

    /// Frozen flags and velocities changed on the host: uploaded.
    fn motion_from_host(&mut self, world: &World) {
        if let Some(on_device) = self.on_device.as_mut() {
            on_device
                .motion_from_host(world)
                .unwrap_or_else(|e| fail(e));
            self.integrated = integrated(world);
        }
    }

    /// Drops the stepper (its history kept): the next evaluation rebuilds it from
    /// the host world.
    fn rebuild(&mut self) {
        if let Some(on_device) = self.on_device.take() {
            if self.history.is_none() {
                self.history = Some(on_device.contact_history().unwrap_or_else(|e| fail(e)));
            }
            self.idle = Some(on_device.into_device());
        }
    }

    /// The host world's share of an evaluation: walls, clock, figures (the
    /// touching flags come with the particles, in `sync_to_host`).
    fn report_to_host(&mut self, world: &mut World) {
        let on_device = self.on_device.as_ref().expect("a stepper");
        on_device.walls_to_host(world);
        self.stats = StepStats {
            integrated: self.integrated,
            ..on_device.stats()
        };
    }

    /// The particles and their touching flags into the host world.
    fn particles_to_host(&mut self, world: &mut World) -> Result<(), DeviceError> {
        if let Some(on_device) = &self.on_device {
            on_device.particles_to_host(world)?;
            self.touching = on_device.touching()?;
        }
        Ok(())
    }
}

impl Backend for CudaBackend {
    fn name(&self) -> &'static str {
        "cuda"
    }

    fn params(&self) -> &StepParams {
        &self.params
    }

    fn set_params(&mut self, params: StepParams) {
        self.params = params;
        self.rebuild();
    }

    fn initialise(&mut self, world: &mut World, dt: Real) {
        let on_device = self.stepper(world);
        on_device.initialise(dt).unwrap_or_else(|e| fail(e));
        self.particles_to_host(world).unwrap_or_else(|e| fail(e));
        self.report_to_host(world);
    }

    /// One step on the device. Its stages are not timed (the stage times stay
    /// zero): the launches of a GPU return before their kernels finish, so a host
    /// clock would give each stage the wait of the next read instead.
    fn step(&mut self, world: &mut World, dt: Real) {
        self.stepper(world).step(dt).unwrap_or_else(|e| fail(e));
        self.report_to_host(world);
    }

    fn stats(&self) -> &StepStats {
        &self.stats
    }

    fn stage_times(&self) -> &StageTimes {
        &self.times
    }

    fn touching(&self) -> &[bool] {
        &self.touching
    }

    /// Appended to the device's particles (an inlet's, after every other).
    fn particles_added(&mut self, world: &World, added: std::ops::Range<usize>) {
        // The device keeps its particles in id order: new ones follow it where
        // their ids ascend past every other (the host may store the others in the
        // space order).
        let id = &world.particles.id;
        let appended = added.end == id.len()
            && id[added.clone()].is_sorted()
            && (id[..added.start].iter().max()).is_none_or(|&m| id.get(added.start) > Some(&m));
        match self.on_device.as_mut() {
            Some(on_device) if appended && on_device.particles() == added.start => {
                on_device.append(world).unwrap_or_else(|e| fail(e));
                self.integrated = integrated(world);
            }
            _ => self.rebuild(),
        }
    }

    fn particles_frozen(&mut self, world: &World, _frozen: &[usize]) {
        self.motion_from_host(world);
    }

    fn particles_removed(&mut self, _world: &World) {
        self.rebuild();
    }

    fn velocities_set(&mut self, world: &World) {
        self.motion_from_host(world);
    }

    fn walls_moved(&mut self, world: &World) {
        if let Some(on_device) = self.on_device.as_mut() {
            on_device.walls_from_host(world).unwrap_or_else(|e| fail(e));
        }
    }

    fn fluid_changed(&mut self, _world: &World) {}

    fn world_changed(&mut self, _world: &World) {
        self.rebuild();
    }

    fn contact_history(&self) -> ContactHistory {
        match &self.on_device {
            Some(on_device) => on_device.contact_history().unwrap_or_else(|e| fail(e)),
            None => self.history.clone().unwrap_or_default(),
        }
    }

    fn restore(&mut self, _world: &World, history: ContactHistory, stats: StepStats) {
        self.rebuild();
        self.history = Some(history);
        self.stats = stats;
    }

    fn sync_to_host(&mut self, world: &mut World) {
        self.particles_to_host(world).unwrap_or_else(|e| fail(e));
    }

    fn particles_on_host(&self) -> bool {
        false
    }

    /// From the device, when it holds a stepper.
    fn particle_figures(&mut self) -> Option<RunFigures> {
        let on_device = self.on_device.as_mut()?;
        Some(on_device.particle_figures().unwrap_or_else(|e| fail(e)))
    }
}

/// A rank's share on the device (see the module): the halo alone crosses in a step
/// without a renewal.
impl ShareStepper for CudaBackend {
    /// The opening kick and drift on the device; the walls' poses and the clock
    /// of the step's end into the host world (a renewal makes the stepper again
    /// from it).
    fn drift(&mut self, world: &mut World, dt: Real) {
        let on_device = self.stepper(world);
        on_device.drift(dt).unwrap_or_else(|e| fail(e));
        on_device.walls_to_host(world);
    }

    /// The sent particles' states, each once, from the device.
    fn owned_to_host(&mut self, world: &mut World, sends: &[Vec<usize>]) {
        let mut sent = std::mem::take(&mut self.sent);
        sent.clear();
        sent.extend(sends.iter().flatten());
        sent.sort_unstable();
        sent.dedup();
        let on_device = self.stepper(world);
        on_device
            .states_to_host(world, &sent)
            .unwrap_or_else(|e| fail(e));
        self.sent = sent;
    }

    fn ghosts_from_host(&mut self, world: &World) {
        let on_device = self.stepper(world);
        on_device
            .ghosts_from_host(world)
            .unwrap_or_else(|e| fail(e));
    }

    /// Stale when the device's list is, or when the stepper is to be made again.
    fn is_stale(&mut self, _world: &World) -> bool {
        match self.on_device.as_mut() {
            Some(on_device) => on_device.is_stale().unwrap_or_else(|e| fail(e)),
            None => true,
        }
    }

    fn forces(&mut self, world: &mut World, dt: Real) {
        self.stepper(world).forces(dt).unwrap_or_else(|e| fail(e));
        self.report_to_host(world);
    }

    fn close(&mut self, world: &mut World, dt: Real) {
        self.stepper(world).close(dt).unwrap_or_else(|e| fail(e));
    }

    /// One a particle: the device's step costs the ranks by their particles (its
    /// lists are not read back).
    fn costs(&self, world: &World) -> Vec<Real> {
        vec![1.0; world.particles.owned()]
    }
}
