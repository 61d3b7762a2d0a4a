//! `talus bench --ranks` (feature `mpi`), started by `mpirun -np N`: scene (a) of
//! `talus bench`, the settled bed of dodecahedra, stepped by N MPI ranks of
//! `--threads` threads each (the first value), the space bisected at the particles
//! and bisected again by cost at a renewal where the imbalance passes 1.1.
//!
//! Rank 0 prints one row: the particles, the ghosts per owned particle, the
//! contacts summed over the ranks (a pair across a boundary is evaluated on both of
//! its ranks and counted on one: one process's count), particle-steps per second of
//! the slowest rank,
//! the bytes every rank sent to the others per step, and the share of the step
//! the ranks spent in the exchange (the transfer and the wait for the slowest rank;
//! mean and largest over ranks). Every particle moves to the bits of one process
//! (`tests/engine_ranks.rs`, `tests/mpi_ranks.rs`), so the accuracy is that of
//! `talus bench` (a) at the same step, printed beside it.

use std::time::Instant;

use anyhow::Result;
use talus::engine::decomposition::Decomposition;
use talus::engine::exchange::Exchange;
use talus::engine::metered_exchange::MeteredExchange;
use talus::engine::mpi_exchange;
use talus::engine::rank::RankStepper;
use talus::engine::{Backend, ContactHistory};
use talus::scene::Scene;

use crate::bench::{BenchOptions, DODECAHEDRON, machine, restitution_error, settled_bed};

/// Steps before the timed ones (the first renewals and a rebalance, if any).
const WARMUP: usize = 20;

/// `talus bench --ranks`.
pub fn ranks(options: &BenchOptions) -> Result<()> {
    // The exchange holds the communicator, which stays on this thread: the rank's
    // threads are those of the global pool.
    let threads = options.threads.first().copied().unwrap_or(1);
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build_global()?;
    let (_universe, exchange) = mpi_exchange::start()?;
    let exchange = MeteredExchange::new(exchange);
    let (rank, size) = (exchange.rank(), exchange.size());
    let dir = std::env::temp_dir().join(format!("talus-bench-ranks-{}-{rank}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let count = (10_000.0 * options.scale).round() as usize;
    let path = dir.join("scene.toml");
    std::fs::write(&path, settled_bed(&dir, count)?)?;
    let scene = Scene::load(&path)?;
    let _ = std::fs::remove_dir_all(&dir);
    let dt = scene.dt;

    let mut world = scene.world.clone();
    let n = world.particles.len();
    let layout = Decomposition::bisect(&world.particles.position, &vec![1.0; n], size);
    let (row, imbalance) = {
        let history = ContactHistory::default();
        let mut ranked = RankStepper::new(
            exchange,
            layout,
            scene.step_params(),
            &mut world,
            &history,
            dt,
        )
        .rebalance_above(1.1);
        for _ in 0..WARMUP {
            ranked.step(&mut world, dt);
        }
        ranked.exchange().reset();
        let mut contacts = 0;
        let start = Instant::now();
        for _ in 0..options.steps {
            ranked.step(&mut world, dt);
            contacts += ranked.backend().stats().contacts;
        }
        let seconds = start.elapsed().as_secs_f64();
        let meter = ranked.exchange().meter();
        let p = &world.particles;
        let mine = vec![
            p.owned() as f64,
            (p.len() - p.owned()) as f64,
            contacts as f64,
            meter.words_sent as f64,
            meter.seconds,
            seconds,
        ];
        let rows = ranked.exchange().all_to_all(vec![mine; size]);
        (rows, ranked.imbalance())
    };
    if rank != 0 {
        return Ok(());
    }
    let sum = |k: usize| row.iter().map(|r| r[k]).sum::<f64>();
    let steps = options.steps.max(1) as f64;
    let slowest = row.iter().map(|r| r[5]).fold(0.0, f64::max);
    let shares: Vec<f64> = row.iter().map(|r| r[4] / r[5]).collect();
    let mean_share = shares.iter().sum::<f64>() / size as f64;
    let most_share = shares.iter().copied().fold(0.0, f64::max);
    let error = restitution_error(DODECAHEDRON, dt, 0.2);
    // mpirun binds each rank to cores: the count is what rank 0 may use.
    println!("machine: {} for rank 0", machine());
    println!(
        "{:<30} {:>5} {:>7} {:>9} {:>12} {:>9} {:>8} {:>16} {:>12} {:>14} {:>9} {:>8}",
        "scene",
        "ranks",
        "threads",
        "particles",
        "ghosts/owned",
        "contacts",
        "dt",
        "particle-steps/s",
        "bytes/step",
        "exchange share",
        "imbalance",
        "e error"
    );
    println!(
        "{:<30} {:>5} {:>7} {:>9} {:>12.3} {:>9.0} {:>8.1e} {:>16.3e} {:>12.0} {:>7.1}/{:<5.1}% {:>9.3} {:>7.2}%",
        "(a) settled bed of dodecahedra",
        size,
        threads,
        sum(0) as usize,
        sum(1) / sum(0),
        sum(2) / steps,
        dt,
        n as f64 * steps / slowest,
        8.0 * sum(3) / steps,
        100.0 * mean_share,
        100.0 * most_share,
        imbalance,
        100.0 * error
    );
    println!(
        "over {} timed steps after {WARMUP}; contacts: mean per step summed over ranks (a \
         pair across a boundary counts on both); particle-steps/s: all particles over the \
         slowest rank's time; bytes/step: sent by all ranks to others; exchange share: time \
         inside the exchange (transfer and waiting) over the step, mean/largest over ranks; \
         imbalance: the largest rank's cost over the mean at the last renewal (1 before \
         any); e error: |realised/requested − 1| of the restitution of a dodecahedron drop \
         at that dt (the ranks move every particle as one process does).",
        options.steps
    );
    Ok(())
}
