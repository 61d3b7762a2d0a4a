//! The MPI exchange (feature `mpi`): the ranks of an MPI run move every particle of a
//! shaken box as one process does, to the bit, with particles changing rank; and
//! `talus bench --ranks` under `mpirun -np 2` reports every particle once, with
//! ghosts and bytes exchanged.
//!
//! This test has no libtest harness (`harness = false` in Cargo.toml): it is its own
//! MPI program. Started by `cargo test`, it launches itself under `mpirun
//! --oversubscribe -np 1…4` (more ranks than cores; as root, with OpenMPI's consent
//! variables) with `TALUS_MPI_RANK` set, and each copy so started runs one rank.
//! Being its own program, it needs no other binary to have been built first.

use std::path::Path;
use std::process::{Command, ExitCode};

mod common;
use common::rank_report;

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use talus::Real;
use talus::engine::decomposition::Decomposition;
use talus::engine::exchange::Exchange;
use talus::engine::mpi_exchange;
use talus::engine::rank::RankStepper;
use talus::engine::{Backend, ContactHistory, CpuBackend};
use talus::scene::Scene;

/// Set in the environment of the copies that mpirun starts.
const RANK_MARK: &str = "TALUS_MPI_RANK";

fn main() -> ExitCode {
    if std::env::var_os(RANK_MARK).is_some() {
        run_rank();
        return ExitCode::SUCCESS;
    }
    // `cargo test -- --list` and filters: this program is one test.
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.iter().any(|a| a == "--list") {
        println!("mpi_ranks_move_every_particle_as_one_process_does: test");
        return ExitCode::SUCCESS;
    }
    let filters: Vec<&String> = args.iter().filter(|a| !a.starts_with('-')).collect();
    let name = "mpi_ranks_move_every_particle_as_one_process_does";
    if !filters.is_empty() && !filters.iter().any(|f| name.contains(f.as_str())) {
        return ExitCode::SUCCESS;
    }
    match launch_ranks().and_then(|()| bench_on_two_ranks()) {
        Ok(()) => {
            println!("test {name} ... ok");
            ExitCode::SUCCESS
        }
        Err(why) => {
            eprintln!("test {name} ... FAILED\n{why}");
            ExitCode::FAILURE
        }
    }
}

/// Runs this program under `mpirun -np 1…4` and reads rank 0's report of each run.
fn launch_ranks() -> Result<(), String> {
    for ranks in 1..=4 {
        let report = format!("{ranks} ranks: 100 particles moved as one process");
        let line = rank_report(ranks, RANK_MARK, &report)?;
        println!("{line}");
        let changed: usize = line
            .split('(')
            .nth(1)
            .and_then(|s| s.split_whitespace().next())
            .and_then(|s| s.parse().ok())
            .ok_or_else(|| format!("unreadable report: {line}"))?;
        // The bisection planes run through the lattice: particles must cross them.
        if ranks > 1 && changed < 5 {
            return Err(format!("too few particles changed rank: {line}"));
        }
    }
    Ok(())
}

/// `talus bench --ranks` under `mpirun -np 2` on 200 particles of the settled bed:
/// rank 0's row counts every particle once, with ghosts and words exchanged.
fn bench_on_two_ranks() -> Result<(), String> {
    let out = Command::new("mpirun")
        .args(["--oversubscribe", "-np", "2", env!("CARGO_BIN_EXE_talus")])
        .args(["bench", "--ranks", "--scale", "0.02", "--steps", "10"])
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .output()
        .map_err(|e| format!("mpirun: {e}"))?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    let row = stdout
        .lines()
        .find(|l| l.starts_with("(a) settled bed"))
        .ok_or_else(|| {
            format!(
                "talus bench --ranks: no row in\n{stdout}\n{}",
                String::from_utf8_lossy(&out.stderr)
            )
        })?;
    println!("{row}");
    let cells: Vec<&str> = row["(a) settled bed of dodecahedra".len()..]
        .split_whitespace()
        .collect();
    let number = |k: usize| cells.get(k).and_then(|c| c.parse::<f64>().ok());
    let (ranks, particles, ghosts, bytes) = (number(0), number(2), number(3), number(7));
    if ranks != Some(2.0) || particles != Some(200.0) {
        return Err(format!("2 ranks holding 200 particles expected: {row}"));
    }
    if !ghosts.is_some_and(|g| g > 0.0) || !bytes.is_some_and(|b| b > 0.0) {
        return Err(format!("ghosts and bytes exchanged expected: {row}"));
    }
    Ok(())
}

/// One rank: steps the shaken box of `tests/scenes/lattice_box.toml` once alone (the
/// reference) and once as its share of the decomposed run, checks its own particles
/// against the reference to the bit; the ranks then check together that every
/// particle is owned once and that the wall force summed over them is the
/// reference's within 1e-12. Panics (a non-zero exit) on any difference.
fn run_rank() {
    let (_universe, exchange) = mpi_exchange::start().expect("MPI starts once");
    let (rank, size) = (exchange.rank(), exchange.size());
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes/lattice_box.toml");
    let text = std::fs::read_to_string(&path).expect("the scene is shipped");
    let scene = Scene::parse(&text, &path).expect("a valid scene");
    let (dt, steps, params) = (1e-5, 2000, scene.step_params());
    let mut start = scene.world.clone();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
    for v in &mut start.particles.velocity {
        v.x = rng.random_range(-1.0..1.0);
        v.y = rng.random_range(-1.0..1.0);
    }
    let n = start.particles.len();

    let mut whole = start.clone();
    let mut one = CpuBackend::new(params);
    one.initialise(&mut whole, dt);
    for _ in 0..steps {
        one.step(&mut whole, dt);
    }

    // Boxes bisected at the lattice's centroids shifted by half its spacing: their
    // planes run through particles, which cross them back and forth.
    let shifted: Vec<_> = start
        .particles
        .position
        .iter()
        .map(|x| x + Vector3::repeat(0.5 * 0.00925))
        .collect();
    let layout = Decomposition::bisect(&shifted, &vec![1.0; n], size);
    let mut world = start.clone();
    let history = ContactHistory::default();
    let mut ranked = RankStepper::new(exchange, layout, params, &mut world, &history, dt);
    for _ in 0..steps {
        ranked.step(&mut world, dt);
    }

    let (p, q) = (&world.particles, &whole.particles);
    for i in 0..p.owned() {
        let j = q.index_of(p.id[i]).expect("a particle of the scene");
        let same = p.position[i] == q.position[j]
            && p.orientation[i] == q.orientation[j]
            && p.velocity[i] == q.velocity[j]
            && p.angular_momentum[i] == q.angular_momentum[j];
        assert!(
            same,
            "rank {rank}: particle {} differs from one process",
            p.id[i]
        );
    }
    let exchange = ranked.exchange();
    let counts = exchange.all_to_all(vec![vec![p.owned() as u64]; size]);
    let owned: u64 = counts.iter().flatten().sum();
    assert_eq!(owned, n as u64, "every particle owned once");
    let arrived = exchange.all_to_all(vec![vec![ranked.migrated() as u64]; size]);
    let forces = exchange.all_to_all(vec![vec![world.walls[0].force]; size]);
    let force: Vector3<Real> = forces.iter().flatten().sum();
    let expected = whole.walls[0].force;
    assert!(
        (force - expected).norm() <= 1e-12 * expected.norm(),
        "rank {rank}: wall force {force} against {expected}"
    );
    if rank == 0 {
        let arrived: u64 = arrived.iter().flatten().sum();
        println!(
            "{size} ranks: {n} particles moved as one process to the bit over {steps} steps \
             ({arrived} changed rank, {} list renewals)",
            ranked.renewals()
        );
    }
}
