//! The seam between a driver (a [`crate::scene::Simulation`]) and what computes the
//! steps: the CPU engine today, a GPU or a rank of a domain decomposition later.
//!
//! # Why a trait
//! A backend is chosen once per run and then stepped many thousand times; a virtual
//! call per step costs nothing next to the step. A trait keeps each backend in its
//! own module behind its own cargo feature (`cuda`), lets a decomposition wrap any
//! backend (MPI ranks stepping a CPU or a GPU backend), and keeps the driver's code
//! free of a `match` per call. An enum would have put every backend's type, and its
//! feature gates, into the engine's one file.
//!
//! # The sync contract
//! The host's [`World`] is the record of the state that outputs, analyses and saved
//! states read. A backend may keep its own copy of it (on a device); then it learns
//! of a change the host makes only through the calls below, and nothing else:
//!
//! | the host ... | then calls |
//! | --- | --- |
//! | appended particles (inlets) | [`Backend::particles_added`] |
//! | froze particles | [`Backend::particles_frozen`] |
//! | removed or reordered particles | [`Backend::particles_removed`] |
//! | set particle velocities (a drag) | [`Backend::velocities_set`] |
//! | set wall poses or velocities (drives, attached walls) | [`Backend::walls_moved`] |
//! | set the fluid's cell inputs or updated its particle shares | [`Backend::fluid_changed`] |
//! | restored a saved state | [`Backend::restore`] |
//! | changed anything else in the world | [`Backend::world_changed`] |
//!
//! In the other direction: after [`Backend::step`] the walls' forces, torques and
//! facet forces in the host world, the fluid's exchange (each particle's drag, the
//! impulse per cell), and [`Backend::stats`], are those of the step; the
//! particle arrays are current after [`Backend::sync_to_host`] (the CPU backend works
//! on the host world itself, so they always are). The host calls `sync_to_host`
//! before it reads particles: at the end of a communication step, for an output row
//! or frame, and before inlets or the bed measurement look at positions.
//!
//! A backend's answers depend on the state alone: the same world and history give the
//! same bits whether the backend was stepped there or restored there.

use std::fmt;
use std::ops::Range;

use super::neighbours::ListAnchors;
use super::params::StepParams;
use super::rank::Share;
use super::stats::{StageTimes, StepStats};
use crate::Real;
use crate::contact::TangentialHistory;
use crate::world::{RunFigures, World};

/// Key of a particle–wall contact patch: particle id, wall, and the patch plane
/// (normal and offset rounded), so that friction history survives sliding from facet
/// to facet of a flat wall.
pub type WallKey = (u64, u32, [i64; 4]);

/// The tangential contact history of a backend, sorted by key: what must be saved
/// with the particles for a run to continue bit for bit, and what travels with a
/// particle that moves to another backend (another rank).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ContactHistory {
    /// Particle pairs, keyed by the two particle ids.
    pub pairs: Vec<((u64, u64), TangentialHistory)>,
    /// Particle–wall patches.
    pub walls: Vec<(WallKey, TangentialHistory)>,
}

/// What computes the steps of a world (see the module docs for the sync contract).
pub trait Backend: Send + fmt::Debug {
    /// Short name, as a scene selects it (`"cpu"`).
    fn name(&self) -> &'static str;

    /// The step parameters.
    fn params(&self) -> &StepParams;

    /// Replaces the step parameters; they take effect at the next step.
    fn set_params(&mut self, params: StepParams);

    /// Evaluates the forces of the world as it is: before the first step, and after
    /// the host set poses or velocities that the next half kick must see. Forces of
    /// particles added since are overwritten. `dt` is the length of the step to
    /// come (the contact laws' damping and tangential springs depend on it).
    fn initialise(&mut self, world: &mut World, dt: Real);

    /// Advances the world by one step of length `dt`.
    fn step(&mut self, world: &mut World, dt: Real);

    /// Figures of the last force evaluation.
    fn stats(&self) -> &StepStats;

    /// Time spent in each stage so far.
    fn stage_times(&self) -> &StageTimes;

    /// Whether each particle touched another particle or a wall at the last force
    /// evaluation (frozen particles count as touching; particles added since are not
    /// listed). A backend whose particles are not on the host
    /// ([`particles_on_host`](Backend::particles_on_host) false) brings these up to
    /// date with the particles, in [`sync_to_host`](Backend::sync_to_host).
    fn touching(&self) -> &[bool];

    /// Whether the last step left every owned particle's position, velocity,
    /// angular momentum, force and torque finite, as the step's own passes over the
    /// particles found: `Some(true)` spares the host a look at every particle after
    /// each step. `None` where the backend does not know, or since the host world
    /// changed otherwise (any call below); `Some(false)` may be a false alarm. Either
    /// way the host looks itself ([`crate::world::Particles::all_finite`]).
    fn stepped_finite(&self) -> Option<bool> {
        None
    }

    /// Particles `added` were appended to the host world (state and forces set).
    fn particles_added(&mut self, world: &World, added: Range<usize>);

    /// Particles `frozen` were frozen in the host world.
    fn particles_frozen(&mut self, world: &World, frozen: &[usize]);

    /// Particles were removed from the host world, or reordered: what the backend
    /// keeps per particle is found again by id.
    fn particles_removed(&mut self, world: &World);

    /// Particle velocities or angular momenta were set in the host world.
    fn velocities_set(&mut self, world: &World);

    /// Wall poses or velocities were set in the host world.
    fn walls_moved(&mut self, world: &World);

    /// The fluid's cell inputs (velocity, pressure gradient) or its particle shares
    /// and solid fractions were set in the host world.
    fn fluid_changed(&mut self, world: &World);

    /// Anything else in the host world changed: the backend takes the whole world
    /// again (its contact history kept).
    fn world_changed(&mut self, world: &World);

    /// The tangential contact history, sorted by key.
    fn contact_history(&self) -> ContactHistory;

    /// The host world was restored to a saved state whose history and last figures
    /// are given.
    fn restore(&mut self, world: &World, history: ContactHistory, stats: StepStats);

    /// What the last build of the candidate lists started from, saved with a state
    /// so that a run restored from it rebuilds its lists at the same steps; `None`
    /// where the backend keeps no such lists.
    fn list_anchors(&self) -> Option<ListAnchors> {
        None
    }

    /// After [`Backend::restore`]: the saved state's [`Backend::list_anchors`], for
    /// the next build of the lists to start from. A backend without such lists
    /// builds its lists from the restored world (the same bits; builds at other
    /// steps).
    fn resume_lists(&mut self, anchors: ListAnchors) {
        let _ = anchors;
    }

    /// Brings the host world's particle arrays up to date.
    fn sync_to_host(&mut self, world: &mut World);

    /// Whether the particles live in the host world between steps, so that
    /// [`sync_to_host`](Backend::sync_to_host) has nothing to copy (the CPU backend
    /// steps the host world itself; a device backend holds them on the device).
    fn particles_on_host(&self) -> bool {
        true
    }

    /// The figures of the owned particles computed where they live, for a backend
    /// whose particles are not on the host: what [`RunFigures::of`] gives of the
    /// host world once the particles are copied to it (the sums in another order,
    /// round-off apart). `None` where the backend does not compute them: the host
    /// copies the particles back to compute them itself.
    fn particle_figures(&mut self) -> Option<RunFigures> {
        None
    }

    /// Where the host's world is one rank's share of a decomposed run: the other
    /// ranks, through which the host reduces its whole-run figures, gathers the
    /// whole world and inserts particles. `None` for a backend of the whole world.
    fn share(&self) -> Option<&dyn Share> {
        None
    }
}
