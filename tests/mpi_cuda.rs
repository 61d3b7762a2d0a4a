//! MPI ranks that each step their share on a device (features `mpi` and `cuda`):
//! under `mpirun -np 2` and `-np 3`, each rank's [`RankStepper`] steps a
//! [`CudaBackend`] on the host executor (the kernels compiled as C++, as CI has no
//! GPU), the halo crossing between device and host every step, and every particle
//! moves as one process on the CPU backend moves it, to the bit; and a whole
//! [`Simulation`] on ranks of devices (as `mpirun talus run` makes one) pours
//! spheres from an inlet into a box as one process does, and polyhedra as one
//! process does to round-off (the device's overlaps are the CPU's to round-off).
//!
//! Its own MPI program (no libtest harness, as `mpi_ranks.rs`): started by `cargo
//! test`, it launches itself under `mpirun` with `TALUS_MPI_RANK` set.

use std::path::Path;
use std::process::ExitCode;

mod common;
use common::{GLASS_AND_STEEL_SPHERES, rank_report};

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use talus::Real;
use talus::engine::choice::ShareBackend;
use talus::engine::cuda::backend::CudaBackend;
use talus::engine::cuda::device::HostDevice;
use talus::engine::decomposition::Decomposition;
use talus::engine::exchange::{Exchange, Ranks};
use talus::engine::mpi_exchange;
use talus::engine::rank::RankStepper;
use talus::engine::{Backend, ContactHistory, CpuBackend};
use talus::scene::{Scene, Simulation};
use talus::world::Particles;

/// Set in the environment of the copies that mpirun starts.
const RANK_MARK: &str = "TALUS_MPI_RANK";

const NAME: &str = "mpi_ranks_on_devices_move_every_sphere_as_one_process_does";

/// 492 glass and steel spheres of two sizes on a lattice in an open box, thrown
/// sideways: they fall, collide and slide on the walls, crossing the ranks' planes.
const PARTICLES: &str = r#"
[[particles]]
kind = "lattice"
shape = "big"
material = "glass"
min = [0.006, 0.006, 0.006]
max = [0.094, 0.094, 0.04]
[[particles]]
kind = "lattice"
shape = "small"
material = "steel"
min = [0.006, 0.006, 0.05]
max = [0.094, 0.094, 0.08]
[[wall]]
name = "box"
material = "steel"
geometry = { kind = "box", min = [0.0, 0.0, 0.0], max = [0.1, 0.1, 0.3], open_top = true }
"#;

fn main() -> ExitCode {
    if std::env::var_os(RANK_MARK).is_some() {
        run_rank();
        return ExitCode::SUCCESS;
    }
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.iter().any(|a| a == "--list") {
        println!("{NAME}: test");
        return ExitCode::SUCCESS;
    }
    let filters: Vec<&String> = args.iter().filter(|a| !a.starts_with('-')).collect();
    if !filters.is_empty() && !filters.iter().any(|f| NAME.contains(f.as_str())) {
        return ExitCode::SUCCESS;
    }
    match launch_ranks() {
        Ok(()) => {
            println!("test {NAME} ... ok");
            ExitCode::SUCCESS
        }
        Err(why) => {
            eprintln!("test {NAME} ... FAILED\n{why}");
            ExitCode::FAILURE
        }
    }
}

/// Runs this program under `mpirun -np 2` and `-np 3` and reads rank 0's report.
fn launch_ranks() -> Result<(), String> {
    for ranks in [2, 3] {
        let line = rank_report(ranks, RANK_MARK, &format!("{ranks} ranks on devices:"))?;
        println!("{line}");
    }
    Ok(())
}

/// One rank: steps the scene once alone on the CPU backend (the reference) and once
/// as its share on a device, checks its own particles against the reference to
/// the bit at every 250th step; the ranks then check together that every particle
/// is owned once, that some changed rank, and that the contacts and the wall
/// force summed over them are the reference's (the force within 1e-12). Panics (a
/// non-zero exit) on any difference.
fn run_rank() {
    let (_universe, exchange) = mpi_exchange::start().expect("MPI starts once");
    let poured = pour_on_ranks(exchange.another());
    let rocks = rocks_on_ranks(exchange.another());
    let (rank, size) = (exchange.rank(), exchange.size());
    let scene = Scene::parse(
        &format!("{GLASS_AND_STEEL_SPHERES}{PARTICLES}"),
        Path::new("mpi_cuda.toml"),
    )
    .expect("a valid scene");
    let (dt, steps, params) = (2e-5, 1500, scene.step_params());
    let mut start = scene.world.clone();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
    for v in &mut start.particles.velocity {
        *v = Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            0.0,
        );
    }
    let n = start.particles.len();
    assert!(n >= 450, "{n} spheres");

    let mut whole = start.clone();
    let mut one = CpuBackend::new(params);
    one.initialise(&mut whole, dt);
    let mut reference = Vec::new();
    for step in 1..=steps {
        one.step(&mut whole, dt);
        if step % 250 == 0 {
            reference.push((whole.particles.clone(), *one.stats(), whole.walls[0].force));
        }
    }

    // Planes through the lattice's centroids shifted by a third of its spacing.
    let shifted: Vec<_> = start
        .particles
        .position
        .iter()
        .map(|x| x + Vector3::repeat(0.003))
        .collect();
    let layout = Decomposition::bisect(&shifted, &vec![1.0; n], size);
    let mut world = start.clone();
    let history = ContactHistory::default();
    let device = || CudaBackend::idle(Box::new(HostDevice::new(64)), params);
    let at = (exchange, layout, params);
    let mut ranked = RankStepper::new_with(at, &mut world, &history, dt, |_| device());
    let mut most_contacts = 0;
    for step in 1..=steps {
        ranked.step(&mut world, dt);
        if step % 250 != 0 {
            continue;
        }
        ranked.sync_to_host(&mut world);
        let (q, stats, force) = &reference[step / 250 - 1];
        let p = &world.particles;
        for i in 0..p.owned() {
            let j = q.index_of(p.id[i]).expect("a particle of the scene");
            let same = p.position[i] == q.position[j]
                && p.orientation[i] == q.orientation[j]
                && p.velocity[i] == q.velocity[j]
                && p.angular_momentum[i] == q.angular_momentum[j]
                && p.force[i] == q.force[j]
                && p.torque[i] == q.torque[j];
            assert!(
                same,
                "rank {rank}, step {step}: particle {} differs",
                p.id[i]
            );
        }
        let e = ranked.exchange();
        let mine = ranked.stats();
        let sums = e.all_to_all(vec![
            vec![mine.pair_contacts as u64, mine.contacts as u64];
            size
        ]);
        let (pairs, contacts) = sums.iter().fold((0, 0), |(a, b), s| (a + s[0], b + s[1]));
        assert_eq!(
            pairs, stats.pair_contacts as u64,
            "step {step}: pair contacts"
        );
        assert_eq!(contacts, stats.contacts as u64, "step {step}: contacts");
        most_contacts = most_contacts.max(contacts);
        let forces = e.all_to_all(vec![vec![world.walls[0].force]; size]);
        let sum: Vector3<Real> = forces.iter().flatten().sum();
        assert!(
            (sum - force).norm() <= 1e-12 * force.norm(),
            "rank {rank}, step {step}: wall force {sum} against {force}"
        );
    }

    let e = ranked.exchange();
    let p = &world.particles;
    let owned: u64 = e
        .all_to_all(vec![vec![p.owned() as u64]; size])
        .iter()
        .flatten()
        .sum();
    assert_eq!(owned, n as u64, "every particle owned once");
    let arrived: u64 = e
        .all_to_all(vec![vec![ranked.migrated() as u64]; size])
        .iter()
        .flatten()
        .sum();
    let ghosts: u64 = e
        .all_to_all(vec![vec![p.ghosts() as u64]; size])
        .iter()
        .flatten()
        .sum();
    assert!(arrived >= 5, "{arrived} particles changed rank");
    assert!(
        ghosts > 0 && most_contacts > 80,
        "{ghosts} ghosts, {most_contacts} contacts"
    );
    if rank == 0 {
        println!(
            "{size} ranks on devices: {n} spheres as one process, to the bit, \
             {arrived} changed rank, {} renewals, {ghosts} ghosts, up to {most_contacts} \
             contacts; a pour from an inlet as one process ({poured} spheres); a pour of \
             polyhedra as one process to round-off ({rocks})",
            ranked.renewals()
        );
    }
}

/// A pour from an inlet into a box on spheres already there (the scene of
/// `tests/cuda_backend.rs`).
const POUR: &str = include_str!("scenes/sphere_pour.toml");

/// Sums grouped by rank against one process's: equal to 1e-9 of the larger.
fn close(a: Real, b: Real) -> bool {
    (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1e-300)
}

/// The pour as a whole simulation on ranks of devices (host executors) against one
/// process on the CPU backend, 1500 steps, the particles copied back only to be
/// compared (the inlet is done after 300 steps; from then on the whole run's
/// figures come from the devices): at every 250th the whole world gathered on
/// rank 0 holds one process's particles to the bit, the whole run's contact counts
/// are one process's, the energies, the box's force and the energy account agree
/// within 1e-9 (sums grouped by rank, on the devices in trees). Returns the particles at the
/// end.
fn pour_on_ranks(exchange: Box<dyn Ranks>) -> usize {
    let scene = Scene::parse(POUR, Path::new("pour.toml")).expect("a valid scene");
    let mut one = Simulation::new(&scene);
    let device = ShareBackend::Cuda(Box::new(HostDevice::new(64)));
    let mut ranks = Simulation::on_ranks(&scene, device, exchange);
    assert_eq!(ranks.backend().name(), "cuda");
    // As `talus run` does: the particles stay on the devices between outputs, the
    // whole run's figures reduced from the devices' own.
    ranks.set_particles_each_step(false);
    for step in 1..=1500 {
        one.step();
        ranks.step();
        if step % 250 != 0 {
            continue;
        }
        let (s, t) = (one.stats(), ranks.stats());
        assert_eq!(
            (s.contacts, s.pair_contacts, s.integrated),
            (t.contacts, t.pair_contacts, t.integrated),
            "step {step}"
        );
        assert!(close(s.elastic_energy, t.elastic_energy), "step {step}");
        assert!(close(s.dissipated, t.dissipated), "step {step}");
        let (e, f) = (one.energy().sums(), ranks.energy().sums());
        for (a, b) in e.into_iter().zip(f) {
            assert!(close(a, b), "{e:?} against {f:?} at step {step}");
        }
        let (u, v) = (one.world().walls[0].force, ranks.world().walls[0].force);
        assert!((u - v).norm() <= 1e-9 * u.norm(), "{u} against {v}");
        let (f, g) = (one.figures(), ranks.figures());
        assert_eq!(
            (f.particles, f.max_speed, f.lower, f.upper, f.non_finite),
            (g.particles, g.max_speed, g.lower, g.upper, g.non_finite),
            "step {step}"
        );
        assert!(close(f.kinetic, g.kinetic) && close(f.potential, g.potential));
        ranks.sync_particles();
        let Some(whole) = ranks.whole_world() else {
            continue;
        };
        // One process stores its particles in the space order, the gathered world
        // by id: compared by id.
        let (a, b) = (&one.world().particles, &whole.particles);
        for (i, j) in by_id(a, b) {
            assert_eq!(a.position[i], b.position[j], "step {step}");
            assert_eq!(a.velocity[i], b.velocity[j], "step {step}");
            assert_eq!(a.angular_momentum[i], b.angular_momentum[j], "step {step}");
            assert_eq!(a.orientation[i], b.orientation[j], "step {step}");
        }
    }
    let inserted = one.world().particles.len() - scene.world.particles.len();
    assert_eq!(inserted, 120, "the inlet's particles");
    one.world().particles.len()
}

/// The entries of `a`'s particles, each with the entry of the same particle (by id)
/// in `b`, which must hold the same particles.
fn by_id<'a>(a: &'a Particles, b: &'a Particles) -> impl Iterator<Item = (usize, usize)> + 'a {
    assert_eq!(a.len(), b.len(), "the same particles");
    (0..a.len()).map(|i| (i, b.index_of(a.id[i]).expect("the same particles")))
}

/// A pour of cubes onto dodecahedra in a box (the scene of `tests/cuda_polyhedra.rs`).
const ROCKS: &str = include_str!("scenes/rock_pour.toml");

/// The pour of polyhedra as a whole simulation on ranks of devices (host
/// executors) against one process on the CPU backend, 1000 steps: at every 250th
/// the contact counts are one process's, and the whole world gathered on rank 0
/// holds one process's particles within 1e-8 of the dodecahedra's circumradius
/// (`tests/cuda_polyhedra.rs` measures the drift of one device: 1e-10, as far as
/// the CPU's own under a nudge of an ulp). Returns a report of the largest
/// difference.
fn rocks_on_ranks(exchange: Box<dyn Ranks>) -> String {
    let scene = Scene::parse(ROCKS, Path::new("rock_pour.toml")).expect("a valid scene");
    let mut one = Simulation::new(&scene);
    let device = ShareBackend::Cuda(Box::new(HostDevice::new(64)));
    let mut ranks = Simulation::on_ranks(&scene, device, exchange);
    assert_eq!(ranks.backend().name(), "cuda");
    let (mut worst, mut most) = (0.0 as Real, 0);
    for step in 1..=1000 {
        one.step();
        ranks.step();
        if step % 250 != 0 {
            continue;
        }
        let (s, t) = (one.stats(), ranks.stats());
        assert_eq!(
            (s.contacts, s.pair_contacts),
            (t.contacts, t.pair_contacts),
            "step {step}"
        );
        most = most.max(s.contacts);
        ranks.sync_particles();
        let Some(whole) = ranks.whole_world() else {
            continue;
        };
        let (a, b) = (&one.world().particles, &whole.particles);
        for (i, j) in by_id(a, b) {
            worst = worst.max((a.position[i] - b.position[j]).norm() / 0.005);
        }
        assert!(worst < 1e-8, "step {step}: {worst:e}");
    }
    format!(
        "{} polyhedra, up to {most} contacts, within {worst:.1e} of a size",
        one.world().particles.len()
    )
}
