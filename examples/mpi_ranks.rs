//! Under `mpirun -np N`: the ranks of an MPI run move every particle as one
//! process does. Each rank steps the shaken box of `tests/scenes/lattice_box.toml`
//! once alone (the reference) and once as its share of the decomposed run, then
//! checks its own particles against the reference to the bit; the ranks then check
//! together that every particle is owned once and that the wall force summed over
//! them is the reference's within 1e-12. Exits non-zero on any difference.
//! Run by `tests/mpi_ranks.rs` (feature `mpi`).

use std::path::Path;

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use talus::Real;
use talus::engine::decomposition::Decomposition;
use talus::engine::exchange::Exchange;
use talus::engine::mpi_exchange::MpiExchange;
use talus::engine::rank::RankStepper;
use talus::engine::{Backend, ContactHistory, CpuBackend};
use talus::scene::Scene;

fn main() {
    let universe = mpi::initialize().expect("MPI initialises once");
    let exchange = MpiExchange::new(universe.world());
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
