//! A world split among ranks (threads talking through a `ThreadExchange`) moves
//! every particle to the same bits as one process: the ranks own the particles in
//! their boxes, copy those within reach to each other as ghosts, renew their lists
//! when one process would, hand particles that cross a box's face over with their
//! contact history, and insert from inlets the particles one process inserts.

use std::ops::ControlFlow;
use std::path::Path;

use nalgebra::{Point3, Vector3};
use rand::{Rng, SeedableRng};
use talus::Real;
use talus::engine::decomposition::Decomposition;
use talus::engine::exchange::ThreadExchange;
use talus::engine::rank::RankStepper;
use talus::engine::{Backend, ContactHistory, CpuBackend, StepParams, StepStats};
use talus::scene::{SPACE_ORDER_INTERVAL, Scene, Simulation};
use talus::world::World;

/// The world of example `name` (with `overrides` appended) run to `until`, its step
/// parameters and step.
fn example_at(name: &str, overrides: &str, until: Real) -> (World, StepParams, Real) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(name);
    let text = std::fs::read_to_string(&path).unwrap() + overrides;
    let scene = Scene::parse(&text, &path).unwrap();
    let mut sim = Simulation::new(&scene);
    let _ = sim.advance_to(until, |_, _| ControlFlow::<()>::Continue(()));
    (sim.world().clone(), sim.params(), sim.dt())
}

/// Random sideways velocities up to `speed`.
fn shake(world: &mut World, speed: Real, seed: u64) {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let p = &mut world.particles;
    for i in 0..p.len() {
        if !p.frozen[i] {
            p.velocity[i].x = rng.random_range(-speed..speed);
            p.velocity[i].y = rng.random_range(-speed..speed);
        }
    }
}

/// Boxes of `ranks` bisected at the centroids with equal cost.
fn boxes(world: &World, ranks: usize) -> Decomposition {
    let p = &world.particles;
    Decomposition::bisect(&p.position, &vec![1.0; p.len()], ranks)
}

/// What a rank ends with.
struct RankEnd {
    world: World,
    migrated: usize,
    renewals: usize,
    rebalances: usize,
    imbalance: Real,
}

/// Steps `start` `steps` times in one process and on the ranks of each layout;
/// checks every particle owned once with the one-process state to the bit, the
/// renewals at the one-process list builds, and each wall's force and torque
/// summed over the ranks within 1e-12; returns what each rank of each layout ended
/// with.
fn same_motion_on_ranks(
    start: &World,
    params: StepParams,
    dt: Real,
    steps: usize,
    layouts: &[Decomposition],
) -> Vec<Vec<RankEnd>> {
    let history = ContactHistory::default();
    same_motion_from_history(start, &history, params, dt, steps, layouts, None)
}

/// [`same_motion_on_ranks`] from a restored state with its contact `history`, the
/// ranks rebalancing above the imbalance `rebalance`.
fn same_motion_from_history(
    start: &World,
    history: &ContactHistory,
    params: StepParams,
    dt: Real,
    steps: usize,
    layouts: &[Decomposition],
    rebalance: Option<Real>,
) -> Vec<Vec<RankEnd>> {
    let mut whole = start.clone();
    let mut one = CpuBackend::new(params);
    one.restore(&whole, history.clone(), StepStats::default());
    one.initialise(&mut whole, dt);
    for _ in 0..steps {
        one.step(&mut whole, dt);
    }
    let mut ends = Vec::new();
    for layout in layouts {
        let ranks = layout.ranks();
        let results: Vec<RankEnd> = std::thread::scope(|s| {
            let handles: Vec<_> = ThreadExchange::group(ranks)
                .into_iter()
                .map(|exchange| {
                    let (layout, mut world) = (layout.clone(), start.clone());
                    s.spawn(move || {
                        let mut rank =
                            RankStepper::new(exchange, layout, params, &mut world, history, dt);
                        if let Some(threshold) = rebalance {
                            rank = rank.rebalance_above(threshold);
                        }
                        for _ in 0..steps {
                            rank.step(&mut world, dt);
                        }
                        RankEnd {
                            world,
                            migrated: rank.migrated(),
                            renewals: rank.renewals(),
                            rebalances: rank.rebalances(),
                            imbalance: rank.imbalance(),
                        }
                    })
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        assert_same_as_one_process(&whole, one.neighbours().builds(), &results);
        ends.push(results);
    }
    ends
}

/// Checks the ranks' `results` against the one-process world `whole`, whose lists
/// were built `builds` times: every particle owned once with the same state to the
/// bit, the renewals at the one-process list builds, and each wall's force and
/// torque summed over the ranks within 1e-12 (each rank sums its own particles'
/// share in its storage order: the round-off of a different order).
fn assert_same_as_one_process(whole: &World, builds: u64, results: &[RankEnd]) {
    let (q, ranks) = (&whole.particles, results.len());
    let mut seen = 0;
    for end in results {
        let (w, renewals) = (&end.world, end.renewals);
        // The first list is built at the start, the others at renewals.
        assert_eq!(renewals as u64 + 1, builds, "{ranks} ranks");
        let p = &w.particles;
        for i in 0..p.owned() {
            let j = q.index_of(p.id[i]).unwrap();
            let id = p.id[i];
            assert_eq!(p.position[i], q.position[j], "{ranks} ranks: particle {id}");
            assert_eq!(p.orientation[i], q.orientation[j], "{ranks} ranks: {id}");
            assert_eq!(p.velocity[i], q.velocity[j], "{ranks} ranks: {id}");
            assert_eq!(
                p.angular_momentum[i], q.angular_momentum[j],
                "{ranks} ranks"
            );
            assert_eq!(p.frozen[i], q.frozen[j]);
            seen += 1;
        }
    }
    assert_eq!(seen, q.len(), "{ranks} ranks: every particle owned once");
    for (k, wall) in whole.walls.iter().enumerate() {
        let force: Vector3<Real> = results.iter().map(|r| r.world.walls[k].force).sum();
        let torque: Vector3<Real> = results.iter().map(|r| r.world.walls[k].torque).sum();
        let close =
            |a: Vector3<Real>, b: Vector3<Real>| (a - b).norm() <= 1e-12 * b.norm().max(1e-300);
        assert!(
            close(force, wall.force),
            "{ranks} ranks: {force} for {}",
            wall.force
        );
        assert!(
            close(torque, wall.torque),
            "{ranks} ranks: {torque} for {}",
            wall.torque
        );
    }
}

fn migrated(ends: &[RankEnd]) -> usize {
    ends.iter().map(|e| e.migrated).sum()
}

#[test]
fn a_shaken_box_of_polyhedra_moves_alike_on_two_three_and_four_ranks() {
    let (mut world, params, dt) = example_at("examples/settling_box/scene.toml", "", 0.1);
    shake(&mut world, 1.0, 11);
    let layouts: Vec<_> = (2..=4).map(|r| boxes(&world, r)).collect();
    let ends = same_motion_on_ranks(&world, params, dt, 1500, &layouts);
    for (layout, end) in layouts.iter().zip(&ends) {
        let moved = migrated(end);
        assert!(
            moved >= 5,
            "{} ranks: {moved} particles changed rank",
            layout.ranks()
        );
    }
}

/// The settling box poured from its inlet from the start (one particle every
/// 0.5 ms falling from the upper half of the box), and from 0.04 s a second inlet
/// of smaller dodecahedra: the ranks place the particles one process places (the
/// same places, orientations and ids, the same draws), each on the rank that owns
/// its place, then move every particle as one process does while they fall through
/// the boxes' planes onto the floor and each other. The smaller particles shrink
/// the automatic skin at the next list build, on the ranks as in one process.
#[test]
fn an_inlet_pours_alike_on_ranks() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/settling_box/scene.toml");
    let grit = r#"
[shapes.grit]
kind = "platonic"
solid = "dodecahedron"
circumradius = 0.003

[[inlet]]
shape = "grit"
material = "pla"
min = [0.0, 0.0, 0.06]
max = [0.06, 0.06, 0.12]
rate = 1000.0
count = 40
velocity = [0.0, 0.0, -0.5]
start = 0.04
"#;
    let text = std::fs::read_to_string(&path).unwrap() + grit;
    let scene = Scene::parse(&text, &path).unwrap();
    let steps = (0.12 / scene.dt) as usize;
    let mut sim = Simulation::new(&scene);
    for _ in 0..steps {
        sim.step();
    }
    let poured = sim.world().particles.len();
    assert!(poured > 190, "{poured} particles poured");
    // Boxes bisected at a lattice filling the box (0.06 × 0.06 × 0.12 m): two ranks
    // split it at half height, the inlet's lower face.
    let lattice: Vec<Point3<Real>> = (0..3 * 3 * 6)
        .map(|k| Point3::new(k % 3, (k / 3) % 3, k / 9).cast::<Real>() * 0.02)
        .map(|x| x + Vector3::repeat(0.01))
        .collect();
    for ranks in [2, 3] {
        let layout = Decomposition::bisect(&lattice, &vec![1.0; lattice.len()], ranks);
        let results: Vec<(RankEnd, usize)> = std::thread::scope(|s| {
            let handles: Vec<_> = ThreadExchange::group(ranks)
                .into_iter()
                .map(|exchange| {
                    let (layout, scene) = (layout.clone(), &scene);
                    s.spawn(move || {
                        // What is due at 0 goes in before the first forces, as in one
                        // process; every rank starts from the same world.
                        let (mut world, mut inlets) = (scene.world.clone(), scene.inlets.clone());
                        let mut next_id = scene.next_id;
                        let mut placed = 0;
                        for inlet in &mut inlets {
                            placed += inlet.insert_due(&mut world, 0.0, &mut next_id);
                        }
                        // Coded as a simulation starts.
                        world.refresh_space_order(false);
                        let (params, history) = (scene.step_params(), ContactHistory::default());
                        let mut rank = RankStepper::new(
                            exchange, layout, params, &mut world, &history, scene.dt,
                        );
                        for k in 0..steps as u64 {
                            // The space order refreshed as a simulation's driver does.
                            if k > 0
                                && k % SPACE_ORDER_INTERVAL == 0
                                && world.refresh_space_order(false)
                            {
                                rank.particles_removed(&world);
                            }
                            rank.step(&mut world, scene.dt);
                            placed += rank.insert(&mut world, &mut inlets, &mut next_id);
                        }
                        let end = RankEnd {
                            world,
                            migrated: rank.migrated(),
                            renewals: rank.renewals(),
                            rebalances: rank.rebalances(),
                            imbalance: rank.imbalance(),
                        };
                        (end, placed)
                    })
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        for (_, placed) in &results {
            assert_eq!(*placed, poured, "{ranks} ranks: every rank placed them all");
        }
        let ends: Vec<RankEnd> = results.into_iter().map(|(end, _)| end).collect();
        assert_same_as_one_process(sim.world(), sim.stats().list_builds, &ends);
        let moved = migrated(&ends);
        assert!(moved >= 20, "{ranks} ranks: {moved} particles changed rank");
    }
}

#[test]
fn a_turning_drum_moves_alike_on_ranks() {
    let (world, params, dt) = example_at("examples/drum/quasi2d.toml", "", 0.05);
    let layouts = [boxes(&world, 2), boxes(&world, 3)];
    let ends = same_motion_on_ranks(&world, params, dt, 1000, &layouts);
    assert!(
        migrated(&ends[1]) > 0,
        "particles cross boxes in a turning drum"
    );
}

/// The settled box with its lower half frozen (a bed) and the rest shaken; and the
/// same on three ranks of which one owns nothing (its box holds only a heavy
/// point far away).
#[test]
fn a_frozen_bed_and_an_empty_rank_move_alike() {
    let (mut world, params, dt) = example_at("examples/settling_box/scene.toml", "", 0.1);
    let mut heights: Vec<Real> = world.particles.position.iter().map(|x| x.z).collect();
    heights.sort_by(Real::total_cmp);
    let median = heights[heights.len() / 2];
    for i in 0..world.particles.len() {
        if world.particles.position[i].z < median {
            world.particles.freeze(i);
        }
    }
    assert!(world.particles.frozen_count() > 10);
    shake(&mut world, 1.0, 12);
    let n = world.particles.len();
    let mut cloud = world.particles.position.clone();
    cloud.push(Point3::new(100.0, 0.0, 0.0));
    let mut cost = vec![1.0; n];
    cost.push(n as Real);
    let empty = Decomposition::bisect(&cloud, &cost, 3);
    let layouts = [boxes(&world, 2), boxes(&world, 4), empty];
    let ends = same_motion_on_ranks(&world, params, dt, 1000, &layouts);
    assert!(
        ends[2].iter().any(|e| e.world.particles.owned() == 0),
        "one rank of three owns nothing"
    );
}

#[test]
fn hertz_spheres_rolling_elastic_plastic_move_alike_on_ranks() {
    let (world, params, dt) = example_at(
        "examples/fluid_bed/pour.toml",
        "\n[contact]\nlaw = \"hertz_mindlin\"\nrolling = \"elastic_plastic\"\n",
        0.14,
    );
    let ends = same_motion_on_ranks(&world, params, dt, 500, &[boxes(&world, 3)]);
    assert_eq!(ends[0].len(), 3);
}

/// The shaken box stepped 300 steps in one process, then continued from its state
/// and contact history: on ranks as in one process (and the history matters: the
/// continuation without it differs).
#[test]
fn a_restored_state_continues_alike_on_ranks() {
    let (mut world, params, dt) = example_at("examples/settling_box/scene.toml", "", 0.1);
    shake(&mut world, 0.3, 13);
    let mut one = CpuBackend::new(params);
    one.initialise(&mut world, dt);
    for _ in 0..300 {
        one.step(&mut world, dt);
    }
    let history = one.contact_history();
    assert!(history.pairs.len() > 20 && !history.walls.is_empty());
    let layouts = [boxes(&world, 2), boxes(&world, 3)];
    let ends = same_motion_from_history(&world, &history, params, dt, 500, &layouts, None);
    let forgetful = same_motion_on_ranks(&world, params, dt, 500, &layouts[..1]);
    let moved = |e: &[RankEnd]| {
        let mut all: Vec<(u64, Point3<Real>)> = e
            .iter()
            .flat_map(|r| {
                let p = &r.world.particles;
                (0..p.owned())
                    .map(|i| (p.id[i], p.position[i]))
                    .collect::<Vec<_>>()
            })
            .collect();
        all.sort_by_key(|a| a.0);
        all
    };
    assert_ne!(moved(&ends[0]), moved(&forgetful[0]), "the history matters");
}

/// The shaken box on three ranks whose boxes start far off (one rank owns every
/// particle) rebalances at its first renewal: the same motion as one process, and
/// the imbalance (largest rank's cost over the mean, 3 at the start) comes down.
#[test]
fn ranks_rebalance_a_lopsided_split() {
    let (mut world, params, dt) = example_at("examples/settling_box/scene.toml", "", 0.1);
    shake(&mut world, 1.0, 14);
    let far: Vec<Point3<Real>> = (0..3)
        .map(|k| Point3::new(10.0 + k as Real, 0.0, 0.0))
        .collect();
    let lopsided = Decomposition::bisect(&far, &[1.0; 3], 3);
    let n = world.particles.len();
    let owners: Vec<usize> = world
        .particles
        .position
        .iter()
        .map(|x| lopsided.owner(x))
        .collect();
    assert!(
        owners.iter().all(|&o| o == owners[0]),
        "one rank owns all {n}"
    );
    let history = ContactHistory::default();
    let ends = same_motion_from_history(&world, &history, params, dt, 1000, &[lopsided], Some(1.2));
    for end in &ends[0] {
        assert_eq!(end.rebalances, 1, "one bisection brings it under 1.2");
        assert!(
            end.imbalance < 1.2,
            "imbalance {} at the last renewal",
            end.imbalance
        );
        let owned = end.world.particles.owned();
        assert!(owned > n / 5, "{owned} owned");
    }
}
