//! A running scene: world, engine and inlets advanced step by step, with the
//! settling criterion.

use std::ops::ControlFlow;

use super::Scene;
use super::energy_ledger::{EnergyLedger, HeldEnergy};
use super::ranks::{RunFigures, WholeRun, bed_height_on_ranks};
use super::spec::{FreezeSpec, SettleSpec, UpdateInterval};
use crate::Real;
use crate::analysis::packing::{Bed, bed_height_of};
use crate::engine::choice::BackendKind;
use crate::engine::{Backend, CpuBackend, StageTimes, StepParams, StepStats};
use crate::world::{Inlet, MassMoments, Wall, World};

/// A scene being simulated: the host's world, the backend that steps it, and what
/// the host does between steps (inlets, the bed's measurement and freezing, the
/// settling clock).
///
/// # Invariant
/// The world changes only through the methods here, and each change is reported to
/// the backend through its sync calls (see [`crate::engine::backend`]).
#[derive(Debug)]
pub struct Simulation {
    pub(super) world: World,
    pub(super) backend: Box<dyn Backend>,
    /// The step length asked for (the last step of an interval may be shorter).
    pub(super) dt: Real,
    /// Particle sources.
    pub(super) inlets: Vec<Inlet>,
    /// Steps taken.
    pub steps: u64,
    /// End time of the run.
    pub end_time: Real,
    pub(super) next_id: u64,
    settle: Option<SettleSpec>,
    pub(super) quiet_since: Option<Real>,
    /// The bed whose height stops inlets fed "until a bed height", moves inlets fed
    /// above it, and below which particles freeze.
    bed: Option<Bed>,
    freeze: Option<FreezeSpec>,
    /// The bed height last measured while feeding or freezing.
    pub(super) bed_height: Option<Real>,
    /// When the fluid's particle shares are computed again (`[fluid]`).
    pub(super) fluid_interval: Option<UpdateInterval>,
    /// The energy account since the start.
    pub(super) energy: EnergyLedger,
    /// On ranks: the whole run's figures after the last step (see [`super::ranks`]).
    pub(super) whole: Option<WholeRun>,
    /// Whether the host world's particles are brought up to date after every step
    /// (see [`Simulation::set_particles_each_step`]).
    particles_each_step: bool,
    /// Whether the backend holds particle state the host world has not received.
    pub(super) particles_behind: bool,
    /// On ranks, where the particles are behind: the backend's figures of its
    /// owned particles after the last step (see [`Backend::particle_figures`]).
    pub(super) backend_figures: Option<RunFigures>,
}

/// Simulated time between two measurements of the bed height (while inlets feed
/// until a height or above the bed, or the bed freezes): a few pellets' worth of
/// feeding at usual rates, and the exact volume integration it costs stays far below
/// the steps in between.
pub const BED_HEIGHT_INTERVAL: Real = 5e-3;

/// Steps between two refreshes of the space order (see
/// [`crate::world::SpaceOrder`]): a particle of a pour crosses a cell in a few
/// hundred steps at the suggested step, one of a bed never; a refresh costs about
/// one build of the lists. A simulation also starts in the space order, once the
/// particles due at time 0 are in (a bed read from a file stepped its first
/// thousand steps in the order of its ids before: on two threads the pair sweep's
/// parts kept back four times the pairs).
pub const SPACE_ORDER_INTERVAL: u64 = 1000;

/// Figures of the state after a step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepReport {
    /// Simulated time.
    pub time: Real,
    /// Particles in the world.
    pub particles: usize,
    /// Contacts in the last force evaluation.
    pub contacts: usize,
    /// Largest particle speed.
    pub max_speed: Real,
    /// Total kinetic energy.
    pub kinetic_energy: Real,
}

impl Simulation {
    /// Starts a scene at time 0 (inlets insert what is due at 0) on the backend it
    /// asks for (checked when it was read).
    ///
    /// # Panics
    /// When the scene's GPU cannot be opened after all (its kernels do not compile
    /// for it, it is out of memory).
    pub fn new(scene: &Scene) -> Self {
        Self::on(scene, scene.backend()).unwrap_or_else(|e| panic!("simulation.backend: {e}"))
    }

    /// Starts a scene at time 0 on `backend` in place of the one it asks for (the
    /// Component's parameter `backend`); `Err` says why that backend cannot step it
    /// here (see [`crate::engine::choice::check`]) or could not be opened.
    pub fn on(scene: &Scene, backend: BackendKind) -> Result<Self, String> {
        let backend: Box<dyn Backend> = match backend {
            BackendKind::Cpu => Box::new(CpuBackend::new(scene.step_params())),
            other => crate::engine::choice::open(other, &scene.world, scene.step_params())?,
        };
        Ok(Self::with_backend(scene, backend))
    }

    /// Starts a scene at time 0 on `backend`, and evaluates the first forces.
    pub fn with_backend(scene: &Scene, backend: Box<dyn Backend>) -> Self {
        let mut sim = Self::assemble(scene, scene.world.clone(), backend);
        sim.backend.world_changed(&sim.world);
        sim.insert();
        // The particles due at 0 are in: they start in the space order (the
        // schedule's first refresh comes at step 1000).
        sim.refresh_space_order();
        sim.update_fluid();
        sim.backend.initialise(&mut sim.world, sim.dt);
        sim.energy = EnergyLedger::new(&sim.held_energy());
        sim
    }

    /// A simulation of `scene` at the start with `world` on `backend`; nothing
    /// inserted, nothing evaluated.
    pub(super) fn assemble(scene: &Scene, world: World, backend: Box<dyn Backend>) -> Self {
        Simulation {
            world,
            backend,
            dt: scene.dt,
            inlets: scene.inlets.clone(),
            steps: 0,
            end_time: scene.spec.simulation.end_time,
            next_id: scene.next_id,
            settle: scene.spec.simulation.settle.clone(),
            quiet_since: None,
            bed: scene.bed,
            freeze: scene.spec.bed.as_ref().and_then(|b| b.freeze.clone()),
            bed_height: None,
            fluid_interval: scene.spec.fluid.as_ref().map(|f| f.update_interval),
            energy: EnergyLedger::default(),
            whole: None,
            particles_each_step: true,
            particles_behind: false,
            backend_figures: None,
        }
    }

    /// Whether the host world's particles are brought up to date after every step
    /// (`true`, the default: whoever reads [`world`](Self::world) between steps sees
    /// the step's state), or only when the simulation's own work between steps reads
    /// or changes them (an inlet inserting, the bed measured or frozen, the settling
    /// test, a fluid, a change through the methods here) and when
    /// [`sync_particles`](Self::sync_particles) is called. A backend that steps on a
    /// device copies the particles back only then (a million spheres' state is 150
    /// MB a step); the CPU backend steps the host world itself, so nothing changes
    /// for it. Whoever turns this off reads the particles only after a
    /// `sync_particles`.
    pub fn set_particles_each_step(&mut self, each: bool) {
        self.particles_each_step = each;
        if each {
            self.sync_particles();
        }
    }

    /// Whether the host world's particles are the backend's (always, unless
    /// [`set_particles_each_step`](Self::set_particles_each_step) turned the copy
    /// after every step off).
    pub fn particles_current(&self) -> bool {
        !self.particles_behind
    }

    /// Brings the host world's particles up to date with the backend's.
    pub fn sync_particles(&mut self) {
        if self.particles_behind {
            self.backend.sync_to_host(&mut self.world);
            self.particles_behind = false;
        }
    }

    /// The energy account since the start (see [`super::energy_ledger`]).
    pub fn energy(&self) -> &EnergyLedger {
        &self.energy
    }

    /// The energy the particles hold now (of the whole run, on ranks).
    pub fn held_energy(&self) -> HeldEnergy {
        match &self.whole {
            Some(w) => HeldEnergy {
                kinetic: w.figures.kinetic,
                potential: w.figures.potential,
                elastic: w.stats.elastic_energy,
            },
            None => HeldEnergy::of(&self.world, self.backend.stats()),
        }
    }

    /// Figures of the whole run's particles (on ranks, as of the last step).
    pub fn figures(&self) -> RunFigures {
        match &self.whole {
            Some(w) => w.figures,
            None => RunFigures::of(&self.world),
        }
    }

    /// The host's world (see the sync contract of [`crate::engine::backend`]): on
    /// ranks this rank's share, whose walls carry the whole run's forces and
    /// torques (see [`Self::whole_world`] for the whole).
    pub fn world(&self) -> &World {
        &self.world
    }

    /// The backend.
    pub fn backend(&self) -> &dyn Backend {
        &*self.backend
    }

    /// Figures of the last force evaluation (of the whole run, on ranks).
    pub fn stats(&self) -> &StepStats {
        match &self.whole {
            Some(w) => &w.stats,
            None => self.backend.stats(),
        }
    }

    /// Time spent in each stage of the steps so far.
    pub fn stage_times(&self) -> &StageTimes {
        self.backend.stage_times()
    }

    /// Particle sources.
    pub fn inlets(&self) -> &[Inlet] {
        &self.inlets
    }

    /// Simulated time.
    pub fn time(&self) -> Real {
        self.world.time
    }

    /// The step length asked for.
    pub fn dt(&self) -> Real {
        self.dt
    }

    /// Sets the step length of the steps to come.
    pub fn set_time_step(&mut self, dt: Real) {
        debug_assert!(dt.is_finite() && dt > 0.0, "time step {dt}");
        self.dt = dt;
    }

    /// The step parameters of the backend.
    pub fn params(&self) -> StepParams {
        *self.backend.params()
    }

    /// Replaces the step parameters of the backend.
    pub fn set_params(&mut self, params: StepParams) {
        self.sync_particles();
        self.backend.set_params(params);
    }

    /// Moves the clock to `t` without stepping: the start time of a co-simulation,
    /// or the exact end of a communication step that the sub-steps reached to within
    /// round-off.
    pub fn set_time(&mut self, t: Real) {
        self.world.time = t;
    }

    /// Evaluates the forces of the current state with the step length to come: after
    /// the host set wall poses or velocities that the first half kick must see.
    pub fn initialise(&mut self) {
        self.sync_particles();
        let before = self.backend.stats().elastic_energy;
        self.backend.initialise(&mut self.world, self.dt);
        self.energy
            .book_host(self.backend.stats().elastic_energy - before);
    }

    /// Changes the walls (poses, velocities) through `change`; attached walls then
    /// follow their leaders, and the backend is told.
    pub fn move_walls(&mut self, change: impl FnOnce(&mut [Wall])) {
        change(&mut self.world.walls);
        self.world.follow_leaders();
        self.backend.walls_moved(&self.world);
    }

    /// Multiplies every owned particle's velocity and angular momentum by `keep` (an
    /// artificial drag that brings a bed to rest).
    pub fn damp_velocities(&mut self, keep: Real) {
        self.sync_particles();
        let before = self.world.kinetic_energy();
        let p = &mut self.world.particles;
        let n = p.owned();
        p.velocity[..n].iter_mut().for_each(|v| *v *= keep);
        p.angular_momentum[..n].iter_mut().for_each(|l| *l *= keep);
        self.backend.velocities_set(&self.world);
        self.energy.book_host(self.world.kinetic_energy() - before);
    }

    /// Changes anything in the world through `change` (a test's or a benchmark's set
    /// up: poses, velocities); the backend takes the whole world again and the forces
    /// are evaluated anew.
    pub fn edit_world(&mut self, change: impl FnOnce(&mut World)) {
        self.sync_particles();
        let before = self.held_energy();
        change(&mut self.world);
        self.world.particles.reindex();
        self.backend.world_changed(&self.world);
        self.backend.initialise(&mut self.world, self.dt);
        self.energy.book_edit(&before, &self.held_energy());
    }

    /// Removes the owned particles for which `remove` is true (given the world and the
    /// particle's index); the others keep their order, and the backend finds what it
    /// keeps per particle again by id. Returns how many were removed.
    pub fn remove_particles(&mut self, mut remove: impl FnMut(&World, usize) -> bool) -> usize {
        self.sync_particles();
        let world = &self.world;
        let owned = world.particles.owned();
        let doomed: Vec<bool> = (0..world.particles.len())
            .map(|i| i < owned && remove(world, i))
            .collect();
        let leaving: Real = (0..owned)
            .filter(|&i| doomed[i])
            .map(|i| HeldEnergy::of_particles(world, i..i + 1).total())
            .sum();
        let removed = self.world.particles.remove_where(|i| doomed[i]);
        if removed > 0 {
            if let Some(fluid) = self.world.fluid.as_mut() {
                fluid.particles_removed(&doomed, &self.world.particles);
            }
            self.backend.particles_removed(&self.world);
            self.energy.book_host(-leaving);
        }
        removed
    }

    /// Whether the end time is reached.
    pub fn is_finished(&self) -> bool {
        self.world.time >= self.end_time - 1e-9 * self.dt
    }

    /// Advances one step of the step length asked for, then lets inlets insert what
    /// is due.
    pub fn step(&mut self) {
        self.step_by(self.dt);
    }

    /// Advances to `end` in steps of the step length asked for, the last one shortened
    /// to land on `end`; stops within `1e-9` steps of it. After every step `each`
    /// gets the simulation and the step's length, and may stop the advance
    /// (`Break`), which is then returned. Where the particles are not copied back
    /// every step ([`set_particles_each_step`](Self::set_particles_each_step)),
    /// `each` calls [`sync_particles`](Self::sync_particles) before it reads them.
    ///
    /// The one sub-step loop of talus: `talus run`, the Component (and so the C, FMI
    /// and zenoh faces) and `talus bench` advance through it.
    pub fn advance_to<B>(
        &mut self,
        end: Real,
        mut each: impl FnMut(&mut Simulation, Real) -> ControlFlow<B>,
    ) -> ControlFlow<B> {
        while self.world.time < end - 1e-9 * self.dt {
            let taken = self.dt.min(end - self.world.time);
            self.step_by(taken);
            each(self, taken)?;
        }
        ControlFlow::Continue(())
    }

    /// One step of length `dt`, then the host's work between steps.
    fn step_by(&mut self, dt: Real) {
        if self.steps > 0 && self.steps % SPACE_ORDER_INTERVAL == 0 {
            self.refresh_space_order();
        }
        let before = self.world.time;
        self.backend.step(&mut self.world, dt);
        self.particles_behind = !self.backend.particles_on_host();
        // On ranks the whole run's figures are reduced every step: from the host's
        // particles when they are brought up anyway, else from what the backend
        // computes where the particles live, and from the host's only where it
        // cannot (the CPU backend steps the host world: nothing is copied there).
        self.backend_figures = None;
        let mut sync = self.particles_each_step || self.reads_particles_between_steps(before);
        if !sync && self.backend.share().is_some() {
            if self.particles_behind {
                self.backend_figures = self.backend.particle_figures();
            }
            sync = self.backend_figures.is_none();
        }
        if sync {
            self.sync_particles();
        }
        self.steps = self.steps.saturating_add(1);
        let freezing = self.follow_bed(before);
        let inserted = self.insert();
        let (inserted, freezing) = self.reduce_over_ranks(inserted, freezing);
        // The step books other sums of the ledger than the bed and the inlets.
        let stats = *self.stats();
        self.energy.book_step(&self.world, &stats, dt);
        self.energy.book_host(freezing);
        self.energy.book_inserted(&inserted);
        if let Some(UpdateInterval::Steps(n)) = self.fluid_interval
            && self.steps % n == 0
        {
            self.update_fluid();
        }
        self.update_settling();
    }

    /// Places the owned particles in the space order anew, at the start and at the
    /// steps of its schedule (so on every rank together, and after a restart as
    /// before it). A
    /// rank codes its particles but keeps their places: it sends the states of
    /// those that are ghosts elsewhere by their places until the next renewal of
    /// the lists, which the change causes.
    fn refresh_space_order(&mut self) {
        self.sync_particles();
        let reorders = self.backend.share().is_none();
        if self.world.refresh_space_order(reorders) {
            self.backend.particles_removed(&self.world);
        }
    }

    /// Whether the host's work after the step that began at `before` reads or changes
    /// the particles: inlets still inserting, the bed measured, the settling test, a
    /// fluid (the figures on ranks are decided in [`Self::step_by`]).
    fn reads_particles_between_steps(&self, before: Real) -> bool {
        !self.inlets_done()
            || self.bed_measured_after(before)
            || self.settle.is_some()
            || self.world.fluid.is_some()
    }

    /// Whether the bed is measured after the step that began at `before`: while
    /// something depends on it, at the multiples of [`BED_HEIGHT_INTERVAL`].
    fn bed_measured_after(&self, before: Real) -> bool {
        self.bed.is_some()
            && (self.freeze.is_some() || self.inlets.iter().any(feeds_by_the_bed))
            && (before / BED_HEIGHT_INTERVAL).floor()
                != (self.world.time / BED_HEIGHT_INTERVAL).floor()
    }

    /// Lets the inlets insert what is due; returns the energy the particles
    /// inserted here hold (for the ledger).
    fn insert(&mut self) -> HeldEnergy {
        if let Some(share) = self.backend.share() {
            let first = self.world.particles.owned();
            share.insert(&mut self.world, &mut self.inlets, &mut self.next_id);
            let added = first..self.world.particles.owned();
            if !added.is_empty() {
                self.backend.particles_added(&self.world, added.clone());
            }
            return HeldEnergy::of_particles(&self.world, added);
        }
        let first = self.world.particles.len();
        let t = self.world.time;
        for inlet in &mut self.inlets {
            inlet.insert_due(&mut self.world, t, &mut self.next_id);
        }
        let added = first..self.world.particles.len();
        self.world.weigh(added.clone());
        if added.is_empty() {
            return HeldEnergy::default();
        }
        let held = HeldEnergy::of_particles(&self.world, added.clone());
        self.backend.particles_added(&self.world, added);
        held
    }

    /// Measures the bed height once per [`BED_HEIGHT_INTERVAL`] of simulated time (at
    /// its multiples, so a restored run measures when the original did) while
    /// something depends on it: stops the inlets whose bed height is reached, moves
    /// those fed above the bed, and freezes the buried particles. Returns the
    /// kinetic energy the freezing took (negative), J.
    fn follow_bed(&mut self, before: Real) -> Real {
        if !self.bed_measured_after(before) {
            return 0.0;
        }
        let Some(bed) = &self.bed else { return 0.0 };
        // The bed: what touches something and moves slower than half of √(g d)
        // (not particles in flight, nor those sliding down the tube wall). Nothing
        // yet: no bed.
        let w = &self.world;
        let p = &w.particles;
        let g = w.gravity.norm();
        let touching = self.backend.touching();
        let member: Vec<bool> = (0..p.len())
            .map(|i| {
                let d = 2.0
                    * w.body_types[p.body_type[i] as usize]
                        .shape
                        .equivalent_radius();
                touching.get(i) == Some(&true) && p.velocity[i].norm() < 0.5 * (g * d).sqrt()
            })
            .collect();
        let height = match self.backend.share() {
            None => bed_height_of(w, bed, &member, self.bed_height).ok(),
            Some(share) => bed_height_on_ranks(share, w, bed, &member, self.bed_height),
        };
        let Some(height) = height else {
            return 0.0;
        };
        self.bed_height = Some(height);
        for inlet in self.inlets.iter_mut().filter(|i| feeds_by_the_bed(i)) {
            if inlet.stop_height.is_some_and(|h| height >= h) {
                inlet.stop();
            }
            if inlet.above_bed {
                inlet.offset = bed.tube.axis * height;
            }
        }
        // The pairs of frozen particles drop out of the force loop, not out of the
        // candidate lists: no rebuild is needed.
        if let Some(freeze) = &self.freeze {
            let before = self.world.kinetic_energy();
            let frozen = freeze_buried(&mut self.world, bed, freeze, height, &member);
            if !frozen.is_empty() {
                self.backend.particles_frozen(&self.world, &frozen);
                return self.world.kinetic_energy() - before;
            }
        }
        0.0
    }

    /// Figures of the current state (of the whole run, on ranks).
    pub fn report(&self) -> StepReport {
        StepReport {
            time: self.world.time,
            particles: self.particle_count(),
            contacts: self.stats().contacts,
            max_speed: self.max_speed(),
            kinetic_energy: self.kinetic_energy(),
        }
    }

    /// Largest particle speed (translation).
    pub fn max_speed(&self) -> Real {
        match &self.whole {
            Some(w) => w.figures.max_speed,
            None => self.world.max_speed(),
        }
    }

    /// The particles' mass and its first moment.
    pub fn mass_moments(&self) -> MassMoments {
        match &self.whole {
            Some(w) => w.figures.moments,
            None => self.world.mass_moments(),
        }
    }

    /// Kinetic energy of the particles.
    pub fn kinetic_energy(&self) -> Real {
        match &self.whole {
            Some(w) => w.figures.kinetic,
            None => self.world.kinetic_energy(),
        }
    }

    /// Particles (owned by the ranks, on ranks).
    pub fn particle_count(&self) -> usize {
        match &self.whole {
            Some(w) => w.figures.particles,
            None => self.world.particles.owned(),
        }
    }

    /// Whether every inlet has inserted all its particles.
    pub fn inlets_done(&self) -> bool {
        self.inlets.iter().all(Inlet::is_done)
    }

    /// The id of the first owned particle whose position, velocity, angular momentum
    /// or force is not finite: the state has blown up (a time step far above the
    /// stable one).
    pub fn first_non_finite(&self) -> Option<u64> {
        if let Some(w) = &self.whole {
            return w.figures.non_finite;
        }
        let p = &self.world.particles;
        if self.backend.stepped_finite() == Some(true) || p.all_finite() {
            return None;
        }
        (0..p.owned()).find(|&i| !p.is_finite(i)).map(|i| p.id[i])
    }

    /// Whether the scene's settling criterion has held long enough.
    pub fn is_settled(&self) -> bool {
        match (&self.settle, self.quiet_since) {
            (Some(s), Some(since)) => self.world.time - since >= s.hold,
            _ => false,
        }
    }

    fn update_settling(&mut self) {
        let Some(s) = &self.settle else { return };
        let n = self.particle_count().max(1) as Real;
        let quiet = self.world.time >= s.after
            && self.inlets_done()
            && self.max_speed() < s.max_speed
            && self.kinetic_energy() / n < s.kinetic_energy_per_particle;
        self.quiet_since = match (quiet, self.quiet_since) {
            (true, None) => Some(self.world.time),
            (true, since) => since,
            (false, _) => None,
        };
    }
}

/// Whether `inlet` still feeds until a bed height or above the bed.
fn feeds_by_the_bed(inlet: &Inlet) -> bool {
    (inlet.stop_height.is_some() || inlet.above_bed) && !inlet.is_done()
}

/// Freezes the particles in `member` (the bed) that are slower than the freeze speed
/// and whose bounding sphere lies wholly more than the freeze depth below `height`;
/// returns them.
fn freeze_buried(
    world: &mut World,
    bed: &Bed,
    freeze: &FreezeSpec,
    height: Real,
    member: &[bool],
) -> Vec<usize> {
    let p = &world.particles;
    let buried: Vec<usize> = (0..p.len())
        .filter(|&i| {
            member[i]
                && !p.frozen[i]
                && bed.tube.top_of(world, i) < height - freeze.depth
                && p.velocity[i].norm() < freeze.max_speed
        })
        .collect();
    for &i in &buried {
        world.particles.freeze(i);
    }
    buried
}
