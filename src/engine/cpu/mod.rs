//! The CPU backend (rayon): the reference implementation of [`Backend`].
//!
//! A step is kick and drift, the walls' prescribed motion, the force evaluation
//! (contact laws, neighbour list, pair contacts, the deferred pairs' sums, wall
//! contacts) and the closing kick: [`CpuBackend::step`] and
//! [`CpuBackend::evaluate_forces`] list the stages in order, each a data-parallel
//! loop over particles, parts of the pair list or particle chunks, timed by
//! [`StageTimes`]. Each particle gets its pairs' forces in pair order (its partners
//! in the order of their space keys) and wall contacts are added in particle order,
//! so the results do not depend on the number of threads, and the particles' motion
//! not on their order in the arrays (the walls' totals do, by round-off;
//! `tests/memory_order.rs`).
//!
//! The parts: [`motion`] (integration stages), [`pairs`] (a pair's contact, a
//! block's pairs), [`fused`] (the pair sweep in parts, each pair added to its
//! particles as it is evaluated), [`part_split`] (where the parts begin, weighed by
//! what they took), [`blocks`] (blocks of pairs and their masks),
//! [`walls`] (wall stage), [`dispatch`] (shape pair → contact geometry), [`patch`]
//! (coplanar facets merged into one contact), [`relative_motion`] (how the bodies
//! move at a contact), [`forces`] (geometry → force through the contact laws),
//! [`contact_state`] (what persists between steps).

mod blocks;
mod contact_state;
mod dispatch;
mod fluid;
mod forces;
mod fused;
mod hertz;
mod huge_pages;
mod keep_awake;
pub(crate) mod motion;
mod overlap_plans;
mod pairs;
mod part_split;
mod patch;
mod prefetch;
#[cfg(all(test, feature = "cuda"))]
pub(in crate::engine) mod reference;
mod relative_motion;
mod shared_sums;
mod type_table;
mod wall_history;
mod walls;

use std::ops::Range;

use rayon::prelude::*;

use self::contact_state::ContactState;
use self::type_table::TypeTable;
use self::walls::{WallInputs, WallWork};
use super::backend::{Backend, ContactHistory};
use super::laws::ContactLaws;
use super::neighbours::{ListAnchors, NeighbourList};
use super::params::StepParams;
use super::stats::{Stage, StageTimes, StepStats};
use crate::Real;
use crate::world::World;

/// Buffers a step reuses: nothing in them survives from one step to the next except
/// their capacity (and the touching flags, read by the host).
#[derive(Clone, Debug, Default)]
struct Workspace {
    /// Bounding radius of every particle.
    radii: Vec<Real>,
    /// The parts the pairs are swept in, with what they defer.
    parts: fused::Parts,
    /// Whether each particle touched another or a wall at the last force evaluation.
    touching: Vec<bool>,
    walls: WallWork,
    /// Each body type's quotients of the integration.
    type_steps: motion::TypeSteps,
    /// The pool's threads kept awake while steps follow one another.
    awake: keep_awake::KeepAwake,
}

/// The CPU engine: step parameters, persistent contact state, the neighbour list, the
/// contact-law and body-type tables, scratch buffers and statistics.
#[derive(Clone, Debug, Default)]
pub struct CpuBackend {
    params: StepParams,
    list: NeighbourList,
    contacts: ContactState,
    laws: ContactLaws,
    types: TypeTable,
    work: Workspace,
    stats: StepStats,
    times: StageTimes,
    /// Whether the last step left every owned particle finite
    /// ([`Backend::stepped_finite`]); `None` once anything else changed the world.
    finite: Option<bool>,
}

impl CpuBackend {
    /// A backend with `params`.
    pub fn new(params: StepParams) -> Self {
        let mut backend = CpuBackend::default();
        backend.set_params(params);
        backend
    }

    /// The neighbour lists (for tests and reports).
    pub fn neighbours(&self) -> &NeighbourList {
        &self.list
    }

    /// The first part of a step: the opening half kick and the drift of the owned
    /// particles, and the walls moved to the step's end. A driver that shares
    /// particles with other ranks refreshes their ghost copies here, before
    /// [`Self::forces`] (`step` is `drift`, `forces`, `close`).
    pub fn drift(&mut self, world: &mut World, dt: Real) {
        self.stats.integrated = self.times.time(Stage::Integrate, || {
            motion::kick_drift(world, dt, &mut self.work.type_steps)
        });
        self.times
            .time(Stage::WallMotion, || motion::advance_walls(world, dt));
    }

    /// The forces of the step (the lists rebuilt first if they are stale).
    pub fn forces(&mut self, world: &mut World, dt: Real) {
        self.evaluate_forces(world, dt, true);
    }

    /// The closing half kick of the owned particles.
    pub fn close(&mut self, world: &mut World, dt: Real) {
        self.finite = Some(self.times.time(Stage::Integrate, || {
            motion::closing_kick(world, dt, &mut self.work.type_steps)
        }));
    }

    /// Forces and torques of the current positions and velocities, stage by stage.
    /// A step's evaluation (`stepped`) also counts the fluid's exchange over `dt`;
    /// the one of `initialise` only sets the forces.
    fn evaluate_forces(&mut self, world: &mut World, dt: Real, stepped: bool) {
        if !stepped {
            self.finite = None;
        }
        let Self {
            params,
            list,
            contacts,
            laws,
            types,
            work,
            stats,
            times,
            finite: _,
        } = self;
        times.time(Stage::Laws, || {
            if laws.prepare(world, params.regularisation_length, params.round_law) {
                types.make(world);
            }
        });
        times.time(Stage::NeighbourList, || {
            update_list(list, contacts, world, types, &mut work.radii)
        });
        let pair_laws = pairs::PairLaws {
            laws,
            round: params.round_law,
            dt,
        };
        let totals = times.time(Stage::PairContacts, || {
            fused::pair_contacts_gathered(
                world,
                list,
                contacts,
                (&work.radii, types),
                pair_laws,
                (&mut work.touching, &mut work.parts),
            )
        });
        let totals = times.time(Stage::Gather, || {
            fused::add_deferred(world, list, (&mut work.touching, &work.parts), totals)
        });
        let (pair_contacts, candidate_pairs) = (totals.contacts, totals.candidates);
        let totals = times.time(Stage::WallContacts, || {
            let inputs = WallInputs {
                list,
                laws,
                types,
                round: params.round_law,
                dt,
            };
            walls::wall_contacts(
                world,
                inputs,
                &mut contacts.wall_history,
                &mut work.walls,
                &mut work.touching,
                totals,
            )
        });
        let fluid_work = times.time(Stage::Fluid, || fluid::fluid_forces(world, dt, stepped));
        stats.contacts = totals.contacts;
        stats.pair_contacts = pair_contacts;
        stats.elastic_energy = totals.energy;
        stats.dissipated = totals.dissipated;
        stats.fluid_work = fluid_work;
        stats.candidate_pairs = candidate_pairs;
        stats.list_builds = list.builds();
    }
}

/// Particles per task of the radii's refresh.
const RADII_PER_TASK: usize = 1024;

/// Brings the candidate lists up to date (the radii are refreshed every step: the
/// body types of the particles may have changed), carrying the pairs' tangential
/// history over to a new list.
fn update_list(
    list: &mut NeighbourList,
    contacts: &mut ContactState,
    world: &World,
    types: &TypeTable,
    radii: &mut Vec<Real>,
) {
    let body_type = &world.particles.body_type;
    radii.resize(body_type.len(), 0.0);
    (radii.par_chunks_mut(RADII_PER_TASK))
        .zip(body_type.par_chunks(RADII_PER_TASK))
        .for_each(|(radii, body_type)| {
            for (r, &t) in radii.iter_mut().zip(body_type) {
                *r = types.radius(t);
            }
        });
    if list.is_stale(world) {
        contacts.rebuild(list, world, radii);
    }
}

impl Backend for CpuBackend {
    fn name(&self) -> &'static str {
        "cpu"
    }

    fn params(&self) -> &StepParams {
        &self.params
    }

    fn set_params(&mut self, params: StepParams) {
        if params.skin != self.params.skin {
            self.list.invalidate();
        }
        self.list.skin = params.skin;
        self.params = params;
    }

    fn initialise(&mut self, world: &mut World, dt: Real) {
        self.evaluate_forces(world, dt, false);
    }

    /// One velocity-Verlet step: the stages in order.
    fn step(&mut self, world: &mut World, dt: Real) {
        let _stepping = self.work.awake.step();
        self.drift(world, dt);
        self.forces(world, dt);
        self.close(world, dt);
    }

    fn stats(&self) -> &StepStats {
        &self.stats
    }

    fn stage_times(&self) -> &StageTimes {
        &self.times
    }

    fn touching(&self) -> &[bool] {
        &self.work.touching
    }

    fn stepped_finite(&self) -> Option<bool> {
        self.finite
    }

    /// The list sees new ids and rebuilds itself at the next step.
    fn particles_added(&mut self, _world: &World, _added: Range<usize>) {
        self.finite = None;
    }

    /// Frozen pairs drop out of the force loop, not out of the candidate lists: no
    /// rebuild is needed.
    fn particles_frozen(&mut self, _world: &World, _frozen: &[usize]) {
        self.finite = None;
    }

    fn particles_removed(&mut self, _world: &World) {
        self.list.invalidate();
        self.finite = None;
    }

    fn velocities_set(&mut self, _world: &World) {
        self.finite = None;
    }

    /// The lists are checked against the walls' frames every step.
    fn walls_moved(&mut self, _world: &World) {}

    /// The fluid stage reads the host world's field every step.
    fn fluid_changed(&mut self, _world: &World) {}

    fn world_changed(&mut self, _world: &World) {
        self.list.invalidate();
        self.finite = None;
    }

    fn contact_history(&self) -> ContactHistory {
        self.contacts.history(&self.list)
    }

    fn restore(&mut self, _world: &World, history: ContactHistory, stats: StepStats) {
        self.contacts.set_history(history, &mut self.list);
        self.finite = None;
        self.stats = StepStats {
            list_builds: self.stats.list_builds,
            ..stats
        };
    }

    fn list_anchors(&self) -> Option<ListAnchors> {
        self.list.anchors()
    }

    fn resume_lists(&mut self, anchors: ListAnchors) {
        self.list.resume_from(anchors);
    }

    /// The CPU backend works on the host world itself.
    fn sync_to_host(&mut self, _world: &mut World) {}
}

/// A thread pool of `threads` for the unit tests.
#[cfg(test)]
fn test_pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
}
