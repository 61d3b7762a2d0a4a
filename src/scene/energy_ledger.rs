//! The energy account of a run: what the particles hold against what flowed in and
//! out since the start. What the account misses is the integration's error.
//!
//! The particles hold kinetic energy (translation and rotation), gravitational
//! potential energy and the elastic energy of their contacts (the normal laws'
//! potentials and the friction springs). Energy flows in as the walls' work (each
//! step: the walls' power at the step's end, the state the contact forces were
//! evaluated at) and the fluid's work, and out as what the contacts dissipate (each
//! contact's damping and friction at the step's end velocity, less what its friction
//! spring stored: see `engine::cpu::forces::dissipated`). The host's changes between
//! steps (particles inserted, frozen or removed, velocities damped, the world
//! edited, forces evaluated again) are booked as they happen.
//!
//! What is left, `held − start − work + dissipated − host`, is what the explicit
//! steps created or lost: the normal laws' potentials met at discrete overlaps, the
//! damping of a contact evaluated at the half-step velocity. It falls with the time
//! step (first order in a pour, second order for one impact: `tests/energy_ledger.rs`,
//! `tests/accuracy_impacts.rs`), and is the run's own measure of its error.
//!
//! Not booked where they happen, and so in the error: the elastic energy of contacts
//! between two frozen particles (those pairs drop out of the force evaluation after
//! the freeze) and of contacts of removed particles, both small against the energy a
//! bed dissipates on its way to rest; and where a body has several contacts, the
//! kicks of the others on the velocity a contact's dissipation is booked at.

use super::Simulation;
use crate::Real;
use crate::engine::StepStats;
use crate::world::World;

/// The energy the particles hold, by kind (J).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HeldEnergy {
    /// Kinetic energy, translation and rotation, of the owned particles.
    pub kinetic: Real,
    /// Gravitational potential energy, `−m g · x`, of the owned particles.
    pub potential: Real,
    /// Elastic energy of the contacts at the last force evaluation.
    pub elastic: Real,
}

impl HeldEnergy {
    /// What the particles of `world` hold, with the contacts of `stats`.
    pub fn of(world: &World, stats: &StepStats) -> Self {
        HeldEnergy {
            elastic: stats.elastic_energy,
            ..Self::of_particles(world, 0..world.particles.owned())
        }
    }

    /// Kinetic and potential energy of the particles in `range` (no elastic energy).
    pub fn of_particles(world: &World, range: std::ops::Range<usize>) -> Self {
        let (kinetic, potential) = world.kinetic_and_potential(range);
        HeldEnergy {
            kinetic,
            potential,
            elastic: 0.0,
        }
    }

    /// Kinetic + potential + elastic.
    pub fn total(&self) -> Real {
        self.kinetic + self.potential + self.elastic
    }
}

/// The account since a run's start (J, all sums over the run).
///
/// # Invariant
/// `error(held)` is zero for an exact integration: every change of the held energy
/// is one of the booked flows.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EnergyLedger {
    /// What the particles held at the start.
    pub start: Real,
    /// Work the walls did on the particles.
    pub wall_work: Real,
    /// Work the fluid's forces did on the particles.
    pub fluid_work: Real,
    /// Energy the contacts dissipated.
    pub dissipated: Real,
    /// Energy the host's changes between steps brought (inserted particles) or took
    /// (frozen or removed particles, damped velocities, edits).
    pub host: Real,
    /// Kinetic and elastic energy held at the start and brought by inserted
    /// particles: part of the [`scale`](Self::scale) of the error.
    pub motion_in: Real,
}

impl EnergyLedger {
    /// An account that starts with `held`.
    pub fn new(held: &HeldEnergy) -> Self {
        EnergyLedger {
            start: held.total(),
            motion_in: held.kinetic + held.elastic,
            ..Default::default()
        }
    }

    /// Books a step of length `dt` that has just ended: the walls' work at their
    /// present power, the contacts' dissipation and the fluid's work of its force
    /// evaluation (`stats`).
    pub fn book_step(&mut self, world: &World, stats: &StepStats, dt: Real) {
        self.wall_work += dt * world.walls.iter().map(|w| w.power()).sum::<Real>();
        self.fluid_work += stats.fluid_work;
        self.dissipated += stats.dissipated;
    }

    /// The sums in the order of the fields (what a saved state writes).
    pub fn sums(&self) -> [Real; 6] {
        [
            self.start,
            self.wall_work,
            self.fluid_work,
            self.dissipated,
            self.host,
            self.motion_in,
        ]
    }

    /// Whether every sum is finite.
    pub fn is_finite(&self) -> bool {
        self.sums().iter().all(|x| x.is_finite())
    }

    /// Books a change of `change` J the host made between steps.
    pub fn book_host(&mut self, change: Real) {
        self.host += change;
    }

    /// Books particles inserted with `held`.
    pub fn book_inserted(&mut self, held: &HeldEnergy) {
        self.host += held.total();
        self.motion_in += held.kinetic + held.elastic;
    }

    /// Books an edit of the world that changed what the particles hold from
    /// `before` to `after` (motion it gave counts as brought in).
    pub fn book_edit(&mut self, before: &HeldEnergy, after: &HeldEnergy) {
        self.host += after.total() - before.total();
        let motion = |h: &HeldEnergy| h.kinetic + h.elastic;
        self.motion_in += (motion(after) - motion(before)).max(0.0);
    }

    /// What the account misses when the particles hold `held`: energy the
    /// integration created (positive) or lost.
    pub fn error(&self, held: Real) -> Real {
        held - self.start - self.wall_work - self.fluid_work + self.dissipated - self.host
    }

    /// The energy the error is measured against: the largest of the energy
    /// dissipated, the walls' and the fluid's work, and the kinetic plus elastic
    /// energy brought in or held now. (Potential energy has no natural zero; what a
    /// bed releases falling is dissipated or held as kinetic energy.)
    pub fn scale(&self, held: &HeldEnergy) -> Real {
        [
            self.dissipated.abs(),
            self.wall_work.abs(),
            self.fluid_work.abs(),
            held.kinetic + held.elastic,
            self.motion_in,
        ]
        .into_iter()
        .fold(0.0, Real::max)
    }
}

/// A run's energy figures at one moment: what `summary.json` and the progress line
/// report.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnergyReport {
    pub held: HeldEnergy,
    pub ledger: EnergyLedger,
    /// [`EnergyLedger::error`], J.
    pub error: Real,
    /// The error over [`EnergyLedger::scale`] (0 when nothing moved).
    pub relative_error: Real,
}

impl EnergyReport {
    /// The report of `sim` now.
    pub fn of(sim: &Simulation) -> Self {
        let held = sim.held_energy();
        let ledger = *sim.energy();
        let error = ledger.error(held.total());
        let scale = ledger.scale(&held);
        EnergyReport {
            held,
            ledger,
            error,
            relative_error: if scale > 0.0 { error / scale } else { 0.0 },
        }
    }
}
