//! A component on MPI ranks (`mpirun -np N talus serve`): every rank holds a
//! component of the same scene and makes the same calls in the same order (the
//! host broadcasts them, see `crate::transport`); each builds its simulation on
//! the ranks, so a step is one decomposed step of the whole scene.
//!
//! - **Outputs**: the walls' forces and torques are the whole run's on every rank
//!   (see [`crate::scene::ranks`]); the figures of the particles are the whole run's
//!   sums; a coupled fluid's solid fraction and mean particle velocity are the whole
//!   run's on every rank. What needs the whole world (facet forces, the drum's
//!   angle of repose, the bed's figures, a fluid's momentum source) is gathered on
//!   rank 0 after each change of the state: rank 0 answers the host; the other
//!   ranks' answers are never sent. What a fluid does to each particle is gathered
//!   when it is read ([`Component::particle_fluid`], collective on ranks).
//! - **States**: a saved state is the whole run's, gathered on rank 0 and sent back
//!   to every rank, the same bytes one process saves; a restore (of a state saved
//!   on any number of ranks, or in one process) builds the simulation anew on the
//!   ranks from it. A step that diverges goes back through the same path, from the
//!   share each rank kept before it.

use nalgebra::Vector3;

use super::CosimError;
use super::component::Component;
use crate::Real;
use crate::analysis::packing::{BedFigures, bed_figures};
use crate::engine::choice::{BackendKind, ShareBackend};
use crate::engine::exchange::{Exchange, Ranks, broadcast_bytes};
use crate::scene::{Scene, ShareState, SimState, Simulation, StateReader, StateWriter};

/// What rank 0 reads of the whole run that no rank's share holds, gathered after
/// every change of the state.
#[derive(Clone, Debug, Default)]
pub(super) struct Gathered {
    /// Each wall's facet forces summed over the ranks.
    pub(super) facet_forces: Vec<Vec<Vector3<Real>>>,
    /// The drum's angle of repose, rad (0 without a surface).
    pub(super) angle_of_repose: Real,
    /// The bed's figures (a scene with a bed).
    pub(super) bed: Option<BedFigures>,
    /// A coupled fluid's momentum source per cell.
    pub(super) momentum_source: Option<Vec<Vector3<Real>>>,
}

impl Component {
    /// Loads the scene at `path` (relative to `base_dir`) as this rank's component
    /// of a run on `ranks`: every rank calls it, and then makes the same calls in
    /// the same order.
    pub fn instantiate_on_ranks(
        base_dir: &std::path::Path,
        path: &str,
        ranks: Box<dyn Ranks>,
    ) -> Result<Self, CosimError> {
        let mut component = Component::instantiate(base_dir, path)?;
        component.ranks = Some(ranks);
        Ok(component)
    }

    /// This rank and the number of ranks, on ranks.
    pub fn rank(&self) -> Option<(usize, usize)> {
        self.ranks.as_ref().map(|r| (r.rank(), r.size()))
    }

    /// Whether `failed` holds on any rank: collective on ranks (a call that fails
    /// on one rank, rank 0 writing the files, must fail on all, or they would part
    /// ways in the collectives that follow); `failed` in one process.
    pub(super) fn failed_anywhere(&self, failed: bool) -> bool {
        match &self.ranks {
            Some(ranks) => ranks.any(failed),
            None => failed,
        }
    }

    /// The whole run's state made of every rank's `share` (collective on ranks):
    /// gathered on rank 0 and sent back to all.
    pub(super) fn whole_state(&self, share: ShareState) -> SimState {
        let sim = self
            .sim
            .as_ref()
            .expect("a running component has a simulation");
        let whole = sim.gather_state(share);
        let Some(ranks) = &self.ranks else {
            return whole.expect("one process holds the whole state");
        };
        let mut bytes = StateWriter::default();
        if let Some(state) = &whole {
            state.write(self.fingerprint, &mut bytes);
        }
        let bytes = broadcast_bytes(&**ranks, &bytes.into_checked());
        StateReader::checked(&bytes)
            .and_then(|mut r| SimState::read(self.fingerprint, &mut r))
            .expect("rank 0 wrote the state it gathered")
    }

    /// Puts the running simulation at the whole run's `state`: in one process in
    /// place, on ranks (collective) as a new simulation on the ranks.
    pub(super) fn install_state(&mut self, state: &SimState) -> Result<(), CosimError> {
        let pool = self.pool.as_ref().expect("a running component has a pool");
        if self.ranks.is_none() {
            let sim = self
                .sim
                .as_mut()
                .expect("a running component has a simulation");
            return Ok(sim.restore(state)?);
        }
        let exchange = self.ranks.as_ref().map(|r| r.another());
        let (scene, backend) = (&self.scene, self.params.backend);
        let sim = pool.install(move || new_simulation(scene, backend, exchange, Some(state)))?;
        self.sim = Some(sim);
        Ok(())
    }

    /// On ranks (collective): gathers on rank 0 what it reads of the whole run
    /// (see [`Gathered`]); nothing in one process.
    pub(super) fn gather(&mut self) {
        if self.ranks.is_none() {
            return;
        }
        let sim = self
            .sim
            .as_ref()
            .expect("a running component has a simulation");
        let scene = &self.scene;
        let momentum_source = sim.whole_momentum_source();
        self.gathered = (|| {
            if scene.drum.is_none() && scene.bed.is_none() {
                let facet_forces = sim.whole_facet_forces()?;
                return Some(Gathered {
                    facet_forces,
                    momentum_source,
                    ..Gathered::default()
                });
            }
            let world = sim.whole_world()?;
            Some(Gathered {
                momentum_source,
                facet_forces: world.walls.iter().map(|w| w.facet_force.clone()).collect(),
                angle_of_repose: scene
                    .drum
                    .as_ref()
                    .and_then(|d| d.surface(&world))
                    .map_or(0.0, |f| f.angle()),
                bed: scene.bed.as_ref().and_then(|b| bed_figures(&world, b).ok()),
            })
        })();
    }
}

/// A new simulation of `scene`, at its start or continuing from the whole run's
/// `state`: in one process, or on the ranks of `exchange` (collective, each rank
/// keeps its share).
pub(super) fn new_simulation(
    scene: &Scene,
    backend: BackendKind,
    exchange: Option<Box<dyn Ranks>>,
    state: Option<&SimState>,
) -> Result<Simulation, CosimError> {
    let Some(exchange) = exchange else {
        let mut sim = Simulation::on(scene, backend).map_err(CosimError::Backend)?;
        if let Some(state) = state {
            sim.restore(state)?;
        }
        return Ok(sim);
    };
    let share = ShareBackend::open(backend, exchange.rank()).map_err(CosimError::Backend)?;
    Ok(match state {
        None => Simulation::on_ranks(scene, share, exchange),
        Some(state) => Simulation::on_ranks_from(scene, share, exchange, state)?,
    })
}
