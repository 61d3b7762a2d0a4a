//! How `talus run` was started: as one process, or as one of the N processes of
//! `mpirun -np N talus run` (feature `mpi`), which then split the scene among them
//! (see `talus::scene::ranks`).
//!
//! A process knows it was started by `mpirun` from the environment the launcher
//! sets (Open MPI: `OMPI_COMM_WORLD_SIZE`; MPICH and Intel MPI: `PMI_SIZE`), so a
//! plain `talus run` never starts MPI.

use anyhow::Result;
use talus::scene::{Scene, SimState, Simulation};

/// The number of processes and of those on this machine that the MPI launcher
/// started, if it started this one.
fn launched_by_mpirun() -> Option<(usize, usize)> {
    let read = |names: &[&str]| {
        names
            .iter()
            .find_map(|n| std::env::var(n).ok()?.trim().parse::<usize>().ok())
    };
    let size = read(&["OMPI_COMM_WORLD_SIZE", "PMI_SIZE"])?;
    let local = read(&["OMPI_COMM_WORLD_LOCAL_SIZE", "MPI_LOCALNRANKS"]).unwrap_or(size);
    Some((size, local.max(1)))
}

/// One process of a run.
pub enum Launch {
    /// The whole scene in this process.
    OneProcess,
    /// One rank of an MPI run.
    #[cfg(feature = "mpi")]
    Rank {
        /// MPI is finalised when this is dropped, after the simulation.
        universe: mpi::environment::Universe,
        exchange: Option<talus::engine::mpi_exchange::MpiExchange>,
        rank: usize,
        local_ranks: usize,
    },
}

impl Launch {
    /// Starts MPI when `mpirun` started this process.
    pub fn detect() -> Result<Launch> {
        let Some((size, local)) = launched_by_mpirun() else {
            return Ok(Launch::OneProcess);
        };
        Self::ranks(size, local)
    }

    #[cfg(feature = "mpi")]
    fn ranks(_size: usize, local_ranks: usize) -> Result<Launch> {
        use talus::engine::exchange::Exchange;
        let (universe, exchange) = talus::engine::mpi_exchange::start()?;
        // A rank that panics would leave the others waiting in their next exchange
        // (and itself in MPI's finalisation): it ends the process, and mpirun ends
        // every rank.
        let report = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            report(info);
            std::process::abort();
        }));
        Ok(Launch::Rank {
            rank: exchange.rank(),
            universe,
            exchange: Some(exchange),
            local_ranks,
        })
    }

    #[cfg(not(feature = "mpi"))]
    fn ranks(size: usize, _: usize) -> Result<Launch> {
        if size > 1 {
            anyhow::bail!(
                "started by mpirun as one of {size} processes, but this talus was built \
                 without the `mpi` feature: each process would run the whole scene \
                 (cargo build --release --features mpi)"
            );
        }
        Ok(Launch::OneProcess)
    }

    /// Ends the run with `error`: on ranks it is printed and every rank is ended
    /// (MPI_Abort), since the others would wait for this one; in one process it
    /// is returned.
    pub fn fail(&self, error: anyhow::Error) -> anyhow::Error {
        match self {
            Launch::OneProcess => error,
            #[cfg(feature = "mpi")]
            Launch::Rank { universe, rank, .. } => {
                use mpi::topology::Communicator;
                eprintln!("error on rank {rank}: {error:#}");
                universe.world().abort(1)
            }
        }
    }

    /// Whether this process writes the outputs and shows the progress (rank 0).
    pub fn is_root(&self) -> bool {
        match self {
            Launch::OneProcess => true,
            #[cfg(feature = "mpi")]
            Launch::Rank { rank, .. } => *rank == 0,
        }
    }

    /// The number of ranks, on ranks.
    #[cfg_attr(not(feature = "zenoh"), allow(dead_code))]
    pub fn rank_count(&self) -> Option<usize> {
        match self {
            Launch::OneProcess => None,
            #[cfg(feature = "mpi")]
            Launch::Rank { universe, .. } => {
                use mpi::topology::Communicator;
                Some(universe.world().size() as usize)
            }
        }
    }

    /// Ranks on this machine (1 for one process): they share its cores.
    pub fn local_ranks(&self) -> usize {
        match self {
            Launch::OneProcess => 1,
            #[cfg(feature = "mpi")]
            Launch::Rank { local_ranks, .. } => *local_ranks,
        }
    }

    /// The ranks of an MPI run for a long-lived host (`talus serve`), once; `None`
    /// in one process.
    #[cfg_attr(not(feature = "zenoh"), allow(dead_code))]
    pub fn take_ranks(&mut self) -> Result<Option<Box<dyn talus::engine::exchange::Ranks>>> {
        match self {
            Launch::OneProcess => Ok(None),
            #[cfg(feature = "mpi")]
            Launch::Rank { exchange, .. } => {
                let exchange = exchange
                    .take()
                    .ok_or_else(|| anyhow::anyhow!("the ranks are taken already"))?;
                Ok(Some(Box::new(exchange)))
            }
        }
    }

    /// The simulation of `scene` at its start, or continuing from the whole run's
    /// `state`: the whole of it, or this rank's share (once).
    pub fn simulation(&mut self, scene: &Scene, state: Option<&SimState>) -> Result<Simulation> {
        match self {
            Launch::OneProcess => {
                let mut sim = Simulation::new(scene);
                if let Some(state) = state {
                    sim.restore(state)?;
                }
                Ok(sim)
            }
            #[cfg(feature = "mpi")]
            Launch::Rank { exchange, .. } => {
                let exchange = exchange
                    .take()
                    .ok_or_else(|| anyhow::anyhow!("one simulation per rank"))?;
                let rank = talus::engine::exchange::Exchange::rank(&exchange);
                let share = talus::engine::choice::ShareBackend::open(scene.backend(), rank)
                    .map_err(|e| anyhow::anyhow!("simulation.backend: {e}"))?;
                Ok(match state {
                    Some(state) => Simulation::on_ranks_from(scene, share, exchange, state)?,
                    None => Simulation::on_ranks(scene, share, exchange),
                })
            }
        }
    }
}
