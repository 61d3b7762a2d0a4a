//! The device stepper of a world of spheres (`engine::cuda::spheres`) through the
//! host executor, against the CPU backend: every kernel of the step (integration,
//! the hashed-grid list with its prefix sums, the Hertz–Mindlin pair contacts with
//! their tangential history carried over list builds, the gather) performs the CPU
//! backend's operations in its order, so a run gives the CPU backend's bits; the
//! walls' and the energies' sums, in a fixed tree, equal its serial sums to
//! round-off.
#![cfg(feature = "cuda")]

use std::path::Path;

mod common;
use common::{GLASS_AND_STEEL_SPHERES, close, near};

use nalgebra::{Point3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use talus::engine::cuda::device::{Device, HostDevice};
use talus::engine::cuda::driver::CudaDevice;
use talus::engine::cuda::stepper::DeviceWorld;
use talus::engine::{Backend, CpuBackend, StepParams};
use talus::scene::Scene;
use talus::world::{RunFigures, World};

/// The cloud's two lattices (after `GLASS_AND_STEEL_SPHERES`).
const LATTICES: &str = r#"
[[particles]]
kind = "lattice"
shape = "big"
material = "glass"
min = [0.0, 0.0, 0.0]
max = [0.01, 0.01, 0.01]
[[particles]]
kind = "lattice"
shape = "small"
material = "steel"
min = [0.1, 0.0, 0.0]
max = [0.11, 0.01, 0.01]
"#;

/// An open steel box about the cloud (scene text).
const OPEN_BOX: &str = r#"
[[wall]]
name = "box"
material = "steel"
geometry = { kind = "box", min = [-0.07, -0.07, -0.07], max = [0.07, 0.07, 0.3], open_top = true }
"#;

/// A cloud of 1000 spheres of two sizes and materials on a jittered lattice of
/// 12 mm, converging on its centre at up to 2 m/s with random spins (every
/// thirteenth frozen): within a few hundred steps most spheres are in contact,
/// sliding and sticking, and the list is rebuilt many times.
fn cloud() -> (World, StepParams) {
    cloud_in("", -35.0)
}

/// The cloud with `walls` (scene text) added, its spheres moving at `spread` times
/// their position (negative: converging) plus a random velocity.
fn cloud_in(walls: &str, spread: f64) -> (World, StepParams) {
    let scene = Scene::parse(
        &format!("{GLASS_AND_STEEL_SPHERES}{LATTICES}{walls}"),
        Path::new("cloud.toml"),
    )
    .unwrap();
    let params = scene.step_params();
    let mut world = scene.world;
    assert_eq!(world.body_types.len(), 2);
    world.particles = Default::default();
    let mut rng = Pcg64::seed_from_u64(7);
    let mut jitter = |s: f64| Vector3::from_fn(|_, _| rng.random_range(-s..s));
    let mut samples = Vec::new();
    for k in 0..1000usize {
        let cell = Vector3::new(k % 10, (k / 10) % 10, k / 100).map(|c| c as f64 * 0.012 - 0.054);
        samples.push((
            cell + jitter(0.0008),
            jitter(0.3),
            jitter(1e-7),
            jitter(3.0),
        ));
    }
    let p = &mut world.particles;
    for (k, (x, u, l, axis)) in samples.into_iter().enumerate() {
        p.push(
            (k % 3 == 0) as u32,
            Point3::from(x),
            UnitQuaternion::from_scaled_axis(axis),
            k as u64,
        );
        p.velocity[k] = u + x * spread;
        p.angular_momentum[k] = l;
        p.frozen[k] = k % 13 == 5;
    }
    (world, params)
}

fn host(block: u32) -> Box<HostDevice> {
    Box::new(HostDevice::new(block))
}

/// 1000 steps of the cloud on `device`: positions, velocities, orientations,
/// angular momenta, forces and torques are the CPU backend's bits at every
/// hundredth step, and so are the tangential history of every pair, the contact
/// count and the candidate pairs.
fn steps_as_the_cpu_backend(device: Box<dyn Device>) {
    let (start, params) = cloud();
    let run = parity(device, &start, &params, 1000, false);
    // A test of contacts, friction and list builds, not of free flight: the cloud
    // collapses (about 1500 contacts at once) and bounces apart.
    assert!(
        run.most_contacts > 1200,
        "{} contacts at most",
        run.most_contacts
    );
    assert!(
        run.most_springs > 1000,
        "{} springs at most",
        run.most_springs
    );
    assert!(run.builds > 10, "{} builds", run.builds);
    // Device memory: 230 bytes a particle (its state 166, the list's 64 with a grid
    // of at least 2n buckets) and 201 a candidate pair (the pair 8, its incidences
    // 8, ids 16, history 32, result 88, touching 1, and the previous build's ids
    // and history, 48), buffers sized for the most pairs so far with room to grow
    // by half.
    let (n, pairs) = (1000.0, run.most_pairs as f64);
    let bytes = run.bytes as f64;
    eprintln!("{bytes} bytes for {n} spheres and at most {pairs} candidate pairs");
    assert!(
        bytes <= 1.5 * (230.0 * n + 201.0 * pairs) + 8192.0,
        "{bytes} bytes"
    );
    assert!(
        bytes >= 166.0 * n + 201.0 * run.last_pairs as f64,
        "{bytes} bytes"
    );
}

/// What a parity run saw.
struct Parity {
    most_contacts: usize,
    most_wall_contacts: usize,
    most_springs: usize,
    most_pairs: usize,
    last_pairs: usize,
    builds: u64,
    bytes: usize,
}

/// `steps` steps of `start` on `device` and in the CPU backend: positions,
/// velocities, orientations, angular momenta, forces and torques and the walls'
/// poses are the CPU backend's bits at every hundredth step, and so are the
/// tangential history of every pair and wall patch, the contact counts and the
/// touching flags; the walls' forces, torques and facet forces and the contacts'
/// elastic energy and dissipation equal the CPU backend's to round-off (a tree of
/// sums on the device, a serial sum on the CPU). The CPU backend also rebuilds its
/// list when a particle has moved a skin in a moving wall's frame (its wall facet
/// lists), the device's only when one moved half a skin: where walls move
/// (`moving_walls`), the lists' builds and candidate counts differ, never the
/// contacts.
fn parity(
    device: Box<dyn Device>,
    start: &World,
    params: &StepParams,
    steps: usize,
    moving_walls: bool,
) -> Parity {
    let dt = 2e-5;
    let mut cpu_world = start.clone();
    let mut cpu = CpuBackend::new(*params);
    cpu.initialise(&mut cpu_world, dt);
    let mut spheres = DeviceWorld::new(device, start, params).unwrap();
    spheres.initialise(dt).unwrap();
    let mut device_world = start.clone();
    let (mut most_contacts, mut most_springs, mut most_pairs) = (0, 0, 0);
    let mut most_wall_contacts = 0;
    for step in 1..=steps {
        cpu.step(&mut cpu_world, dt);
        spheres.step(dt).unwrap();
        assert_eq!(
            spheres.pair_contacts(),
            cpu.stats().pair_contacts,
            "step {step}"
        );
        most_contacts = most_contacts.max(spheres.pair_contacts());
        most_pairs = most_pairs.max(spheres.candidate_pairs());
        if step % 100 != 0 {
            continue;
        }
        spheres.download(&mut device_world).unwrap();
        let (a, b) = (&cpu_world.particles, &device_world.particles);
        assert_eq!(a.position, b.position, "positions at step {step}");
        assert_eq!(a.velocity, b.velocity, "velocities at step {step}");
        assert_eq!(a.orientation, b.orientation, "orientations at step {step}");
        assert_eq!(
            a.angular_momentum, b.angular_momentum,
            "spins at step {step}"
        );
        assert_eq!(a.force, b.force, "forces at step {step}");
        assert_eq!(a.torque, b.torque, "torques at step {step}");
        assert_eq!(cpu_world.time, device_world.time);
        if !moving_walls {
            let counted = spheres.stats().candidate_pairs;
            assert_eq!(counted, cpu.stats().candidate_pairs, "step {step}");
        }
        let history = cpu.contact_history();
        assert_eq!(spheres.contact_history().unwrap(), history, "step {step}");
        most_springs = most_springs.max(history.pairs.len() + history.walls.len());
        // Summed in a tree on the device, serially on the CPU: the same terms,
        // round-off apart.
        let (elastic, dissipated) = spheres.energies();
        assert!(
            close(elastic, cpu.stats().elastic_energy) && close(dissipated, cpu.stats().dissipated),
            "energies at step {step}: {elastic:e}, {dissipated:e} against {:?}",
            cpu.stats()
        );
        let wall_contacts = cpu.stats().contacts - cpu.stats().pair_contacts;
        assert_eq!(
            spheres.wall_contacts().unwrap(),
            wall_contacts,
            "step {step}"
        );
        most_wall_contacts = most_wall_contacts.max(wall_contacts);
        for (a, b) in cpu_world.walls.iter().zip(&device_world.walls) {
            assert_eq!(a.pose, b.pose, "{} at step {step}", a.name);
            assert!(near(&a.force, &b.force), "{} at step {step}", a.name);
            assert!(near(&a.torque, &b.torque), "{} at step {step}", a.name);
            for (f, g) in a.facet_force.iter().zip(&b.facet_force) {
                assert!(near(f, g), "{}: {f} against {g} at step {step}", a.name);
            }
        }
        assert_eq!(spheres.touching().unwrap(), cpu.touching(), "step {step}");
    }
    if !moving_walls {
        assert_eq!(spheres.list_builds(), cpu.stats().list_builds);
    }
    Parity {
        most_contacts,
        most_wall_contacts,
        most_springs,
        most_pairs,
        last_pairs: spheres.candidate_pairs(),
        builds: spheres.list_builds(),
        bytes: spheres.device_bytes(),
    }
}

#[test]
fn a_converging_cloud_steps_as_the_cpu_backend_to_the_bit() {
    steps_as_the_cpu_backend(host(64));
}

/// A parity run on a device.
type Run = fn(Box<dyn Device>);

/// The same runs on a GPU, where there is one (`scripts/gpu-check.sh`): the
/// converging cloud, the cloud thrown into a box, both under the volume law, the
/// thrown cloud with either rolling resistance, the turning drum, and both clouds
/// as a rank's share with ghosts. The kernels
/// are compiled without fused multiply–adds and with IEEE division and square
/// roots, and the only atomics are on integers, so the GPU gives the same bits.
/// Without a driver the test says so and passes, unless `TALUS_REQUIRE_GPU` is set.
#[test]
fn on_a_gpu_the_cloud_the_box_and_the_drum_step_as_the_cpu_backend_to_the_bit() {
    let runs: [(&str, Run); 9] = [
        ("the converging cloud", steps_as_the_cpu_backend),
        (
            "the converging cloud under the volume law",
            converging_under_the_volume_law,
        ),
        (
            "the cloud thrown into a box under the volume law",
            thrown_under_the_volume_law,
        ),
        (
            "the cloud thrown into a box, constant rolling torque",
            thrown_with_constant_rolling_torque,
        ),
        (
            "the cloud thrown into a box, rolling spring",
            thrown_with_a_rolling_spring,
        ),
        ("the cloud thrown into a box", thrown_into_a_box),
        ("the turning drum", beads_in_a_turning_drum),
        ("a rank's share of the converging cloud", converging_share),
        (
            "a rank's share of the cloud thrown into a box",
            thrown_share,
        ),
    ];
    for (name, run) in runs {
        match CudaDevice::open(0) {
            Ok(gpu) => {
                eprintln!("{name} on {gpu:?}");
                run(Box::new(gpu));
            }
            Err(e) => {
                assert!(
                    std::env::var_os("TALUS_REQUIRE_GPU").is_none(),
                    "TALUS_REQUIRE_GPU is set: {e}"
                );
                eprintln!("skipped: {e}");
                return;
            }
        }
    }
}

/// An open box of STL-like facets (floor and four sides, two triangles each) around
/// the cloud, which expands into it under gravity: every sphere of the outer layer
/// meets a wall, a face, an edge or a corner (two or three patches at once), and
/// slides on it.
#[test]
fn a_cloud_thrown_into_a_box_steps_as_the_cpu_backend_to_the_bit() {
    thrown_into_a_box(host(64));
}

fn thrown_into_a_box(device: Box<dyn Device>) {
    let (start, params) = cloud_in(OPEN_BOX, 30.0);
    thrown(device, &start, &params, "thrown", 100, 100);
}

/// 1000 steps of the cloud `start` thrown into the box under `params` (`parity`),
/// with more than `walls` wall contacts and `contacts` contacts at some hundredth
/// step.
fn thrown(
    device: Box<dyn Device>,
    start: &World,
    params: &StepParams,
    name: &str,
    walls: usize,
    contacts: usize,
) {
    let run = parity(device, start, params, 1000, false);
    eprintln!(
        "{name}: {} wall contacts, {} contacts at most",
        run.most_wall_contacts, run.most_contacts
    );
    assert!(
        run.most_wall_contacts > walls && run.most_contacts > contacts,
        "{} wall contacts, {} contacts at most",
        run.most_wall_contacts,
        run.most_contacts
    );
}

/// The clouds under the volume law (the scenes' default): lens and cap volumes,
/// the volume law's normal force, friction, rocking damping and twist of pairs
/// and wall contacts, the CPU backend's bits; converging (1000 steps), and thrown
/// into the box (1000 steps).
#[test]
fn clouds_under_the_volume_law_step_as_the_cpu_backend_to_the_bit() {
    converging_under_the_volume_law(host(64));
    thrown_under_the_volume_law(host(64));
}

/// `(world, params)` under the volume law.
fn under_the_volume_law((world, mut params): (World, StepParams)) -> (World, StepParams) {
    params.round_law = talus::engine::RoundLaw::Volume;
    (world, params)
}

fn converging_under_the_volume_law(device: Box<dyn Device>) {
    let (start, params) = under_the_volume_law(cloud());
    let run = parity(device, &start, &params, 1000, false);
    eprintln!("converging: {} contacts at most", run.most_contacts);
    assert!(
        run.most_contacts > 500,
        "{} contacts at most",
        run.most_contacts
    );
}

fn thrown_under_the_volume_law(device: Box<dyn Device>) {
    let (start, params) = under_the_volume_law(cloud_in(OPEN_BOX, 30.0));
    thrown(device, &start, &params, "thrown, volume law", 40, 60);
}

/// The cloud thrown into the box with rolling resistance under Hertz–Mindlin
/// (materials of rolling friction 0.05 and damping 0.3): the constant torque and
/// the elastic–plastic spring–dashpot, whose spring every pair and wall contact
/// keeps, 1000 steps each, the CPU backend's bits.
#[test]
fn clouds_with_rolling_resistance_step_as_the_cpu_backend_to_the_bit() {
    thrown_with_constant_rolling_torque(host(64));
    thrown_with_a_rolling_spring(host(64));
}

fn thrown_with_constant_rolling_torque(device: Box<dyn Device>) {
    thrown_with_rolling(device, talus::contact::RollingModel::ConstantTorque);
}

fn thrown_with_a_rolling_spring(device: Box<dyn Device>) {
    thrown_with_rolling(device, talus::contact::RollingModel::ElasticPlastic);
}

fn thrown_with_rolling(device: Box<dyn Device>, rolling: talus::contact::RollingModel) {
    let (mut start, mut params) = cloud_in(OPEN_BOX, 30.0);
    for m in &mut start.materials {
        m.rolling_friction = 0.05;
        m.rolling_damping = 0.3;
    }
    params.round_law = talus::engine::RoundLaw::HertzMindlin { rolling };
    thrown(device, &start, &params, &format!("{rolling:?}"), 100, 100);
}

/// A drum turning at 3 rad/s about a horizontal axis, its end plates attached to
/// the shell (walls that move, their facets placed anew every step), with 53 beads
/// falling onto the shell and carried up: 5000 steps.
#[test]
fn beads_in_a_turning_drum_step_as_the_cpu_backend_to_the_bit() {
    beads_in_a_turning_drum(host(32));
}

fn beads_in_a_turning_drum(device: Box<dyn Device>) {
    let run = beads_in_a_drum_of(device, 72, 1, 5000);
    // The bed rests on the shell and rubs on the plates (21 wall contacts, 73 in
    // all, at the most of the hundredth steps).
    assert!(
        run.most_wall_contacts > 15,
        "{} wall contacts at most",
        run.most_wall_contacts
    );
    assert!(
        run.most_contacts > 50,
        "{} contacts at most",
        run.most_contacts
    );
}

/// The drum meshed finely: a shell of 240 sides in 24 rings (11 520 facets, each
/// 1.6 mm by 0.4 mm under beads of 8 mm) and plates of 240 facets each. The walls'
/// facet grids in their turning frames (cells of a bead's diameter, each listing
/// dozens of facets, each facet in up to eight cells) give each bead the facets
/// near it once each, in index order, as the CPU backend's lists: 3000 steps of
/// the beads landing on the shell, the CPU backend's bits.
#[test]
fn beads_in_a_finely_meshed_drum_step_as_the_cpu_backend_to_the_bit() {
    let run = beads_in_a_drum_of(host(32), 240, 24, 3000);
    assert!(
        run.most_wall_contacts > 15,
        "{} wall contacts at most",
        run.most_wall_contacts
    );
}

/// `steps` steps of beads in the drum whose shell has `sides` sides in `rings`
/// rings of facets (`parity`).
fn beads_in_a_drum_of(device: Box<dyn Device>, sides: usize, rings: usize, steps: usize) -> Parity {
    let text = r#"
[simulation]
dt = 2e-5
end_time = 1.0
gravity = [0.0, 0.0, -9.81]
[contact]
law = "hertz_mindlin"
[materials.bead]
density = 2500.0
young = 3e5
poisson = 0.25
restitution = 0.5
friction = 0.5
[materials.shell]
density = 2500.0
young = 1e6
poisson = 0.3
restitution = 0.6
friction = 0.7
[shapes.bead]
kind = "sphere"
radius = 0.004
[[wall]]
name = "shell"
material = "shell"
geometry = { kind = "cylinder", base = [0.0, 0.0, 0.0], axis = [0.0, 1.0, 0.0], length = 0.009, radius = 0.06, sides = SIDES, segments = RINGS }
motion = { kind = "rotation", axis = [0.0, 1.0, 0.0], point = [0.0, 0.0045, 0.0], rate = 3.0 }
[[wall]]
name = "front"
material = "bead"
geometry = { kind = "disc", centre = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0], radius = 0.06, sides = SIDES }
motion = { kind = "attached", to = "shell" }
[[wall]]
name = "back"
material = "bead"
geometry = { kind = "disc", centre = [0.0, 0.009, 0.0], normal = [0.0, -1.0, 0.0], radius = 0.06, sides = SIDES }
motion = { kind = "attached", to = "shell" }
[[particles]]
kind = "lattice"
shape = "bead"
material = "bead"
min = [-0.06, 0.0, -0.06]
max = [0.06, 0.009, 0.06]
inside = { centre = [0.0, 0.0045, 0.0], axis = [0.0, 1.0, 0.0], radius = 0.06, fill = 0.4 }
"#;
    let text = text
        .replace("SIDES", &sides.to_string())
        .replace("RINGS", &rings.to_string());
    let scene = Scene::parse(&text, Path::new("drum.toml")).unwrap();
    parity(device, &scene.world, &scene.step_params(), steps, true)
}

/// The host executor runs a launch's blocks in parallel: blocks of 1, 32 and 256
/// threads give the same bits (the atomics of the binning and of the incidence
/// lists change the order of the scattered entries, never the sorted list).
#[test]
fn the_answer_does_not_depend_on_the_block_size() {
    let (start, params) = cloud();
    let dt = 2e-5;
    let runs: Vec<(World, (f64, f64))> = [1, 32, 256]
        .into_iter()
        .map(|block| {
            let mut spheres = DeviceWorld::new(host(block), &start, &params).unwrap();
            spheres.initialise(dt).unwrap();
            for _ in 0..300 {
                spheres.step(dt).unwrap();
            }
            let mut world = start.clone();
            spheres.download(&mut world).unwrap();
            (world, spheres.energies())
        })
        .collect();
    let (first, energies) = &runs[0];
    assert!(first.particles.position != start.particles.position);
    assert!(energies.0 > 0.0, "{energies:?}");
    for (w, e) in &runs[1..] {
        assert_eq!(w.particles.position, first.particles.position);
        assert_eq!(w.particles.velocity, first.particles.velocity);
        // The sums' tree is fixed by the number of terms, not by the blocks.
        assert_eq!(e, energies);
    }
}

/// `world` as a rank holds its share: the particles with `ghost` true become
/// ghosts (after the others, their states kept), the owned ones in the reverse
/// order of their ids.
fn as_a_share(world: &World, ghost: impl Fn(&Point3<f64>) -> bool) -> World {
    let (mut share, p) = (world.clone(), &world.particles);
    share.particles = Default::default();
    let owned = (0..p.len()).rev().filter(|&i| !ghost(&p.position[i]));
    let ghosts = (0..p.len()).filter(|&i| ghost(&p.position[i]));
    for (i, is_ghost) in owned.map(|i| (i, false)).chain(ghosts.map(|i| (i, true))) {
        let q = &mut share.particles;
        let args = (p.body_type[i], p.position[i], p.orientation[i], p.id[i]);
        if is_ghost {
            q.push_ghost(args.0, args.1, args.2, args.3);
        } else {
            q.push(args.0, args.1, args.2, args.3);
        }
        let k = q.len() - 1;
        q.velocity[k] = p.velocity[i];
        q.angular_momentum[k] = p.angular_momentum[i];
        q.frozen[k] = p.frozen[i];
    }
    share
}

/// A rank's share of the cloud in a box, its owned particles out of the order of
/// their ids and 400 of its 1000 spheres ghosts (every thirteenth frozen, ghosts
/// too), converging (many pairs) and thrown into the box (many wall contacts): the
/// ghosts are felt, not moved, get no force and no wall contacts, and the figures
/// count the pairs the rank counts, as in the CPU backend, to the bit (its
/// energies to round-off).
#[test]
fn a_ranks_share_with_ghosts_steps_as_the_cpu_backend_to_the_bit() {
    converging_share(host(64));
    thrown_share(host(64));
}

/// The converging cloud as a rank's share: many pairs with ghosts.
fn converging_share(device: Box<dyn Device>) {
    let run = share_with_ghosts(device, -35.0);
    assert!(run.most_contacts > 500, "{} contacts", run.most_contacts);
}

/// The cloud thrown into the box as a rank's share: many wall contacts.
fn thrown_share(device: Box<dyn Device>) {
    let run = share_with_ghosts(device, 30.0);
    let walls = run.most_wall_contacts;
    assert!(walls > 50, "{walls} wall contacts");
}

/// The cloud in the box, its spheres moving at `spread` times their position, as
/// a rank holds its share (see [`as_a_share`]), stepped on `device` against the
/// CPU backend.
fn share_with_ghosts(device: Box<dyn Device>, spread: f64) -> Parity {
    let (whole, params) = cloud_in(OPEN_BOX, spread);
    let start = as_a_share(&whole, |x| x.x > 0.015);
    let p = &start.particles;
    assert!(
        p.ghosts() >= 300 && p.owned() >= 500,
        "{} ghosts",
        p.ghosts()
    );
    assert!(!p.id.is_sorted());
    assert!((p.owned()..p.len()).any(|i| p.frozen[i]));
    parity(device, &start, &params, 1000, false)
}

/// A sphere wedged in a box narrower than itself touches its floor and four sides:
/// one contact more than the four slots a sphere has for walls, which the step
/// reports as an error (read back with the step's sums) instead of dropping it.
#[test]
fn a_sphere_at_more_walls_than_its_slots_is_an_error() {
    let walls = r#"
[[wall]]
name = "box"
material = "glass"
geometry = { kind = "box", min = [-0.0039, -0.0039, 0.0], max = [0.0039, 0.0039, 0.02], open_top = true }
"#;
    let scene = Scene::parse(
        &format!("{GLASS_AND_STEEL_SPHERES}{LATTICES}{walls}"),
        Path::new("wedged.toml"),
    )
    .unwrap();
    let params = scene.step_params();
    let mut world = scene.world;
    world.particles = Default::default();
    world.particles.push(
        1,
        Point3::new(0.0, 0.0, 0.0039),
        UnitQuaternion::identity(),
        0,
    );
    let mut spheres = DeviceWorld::new(host(64), &world, &params).unwrap();
    let e = spheres.initialise(2e-5).unwrap_err();
    assert_eq!(
        e.to_string(),
        "the device stepper holds no particle touching walls at more than 4 places at once"
    );
    // Four places are within the slots.
    world.particles.position[0].x = 0.0005;
    let mut spheres = DeviceWorld::new(host(64), &world, &params).unwrap();
    spheres.initialise(2e-5).unwrap();
    assert_eq!(spheres.stats().contacts, 4);
}

/// A history set on a new stepper is its history until a build carries it into
/// the list (a rank renews its share and reads the history before the next
/// evaluation): read back as set, pairs and wall patches.
#[test]
fn a_history_set_is_read_back_before_the_next_build() {
    let (start, params) = cloud_in(OPEN_BOX, 30.0);
    let dt = 2e-5;
    let mut spheres = DeviceWorld::new(host(64), &start, &params).unwrap();
    spheres.initialise(dt).unwrap();
    for _ in 0..300 {
        spheres.step(dt).unwrap();
    }
    let history = spheres.contact_history().unwrap();
    assert!(history.pairs.len() > 20 && !history.walls.is_empty());
    let mut world = start.clone();
    spheres.download(&mut world).unwrap();
    let mut again = DeviceWorld::new(host(64), &world, &params).unwrap();
    again.set_history(&history).unwrap();
    assert_eq!(again.contact_history().unwrap(), history);
}

/// The figures of a rank's owned particles computed on the device (what a rank on
/// a GPU reduces every step without copying its particles back) are those of the
/// host world the particles are copied to: counts, extent and largest speed
/// exact, the sums (mass, its moment, the energies) within 1e-12; a particle whose
/// velocity is not finite is named by its id.
#[test]
fn the_figures_of_the_owned_particles_are_the_hosts() {
    let (whole, params) = cloud_in(OPEN_BOX, 30.0);
    let mut start = as_a_share(&whole, |x| x.x > 0.015);
    let dt = 2e-5;
    let mut spheres = DeviceWorld::new(host(64), &start, &params).unwrap();
    spheres.initialise(dt).unwrap();
    for _ in 0..200 {
        spheres.step(dt).unwrap();
    }
    spheres.download(&mut start).unwrap();
    let before = spheres.device_bytes();
    let (device, host_figures) = (spheres.particle_figures().unwrap(), RunFigures::of(&start));
    // The figures' scratch is counted: two records of 8 doubles a sphere.
    let n = start.particles.len();
    assert!(spheres.device_bytes() >= before + 128 * n);
    assert_eq!(device.particles, start.particles.owned());
    assert_eq!(
        (device.particles, device.frozen, device.max_speed),
        (
            host_figures.particles,
            host_figures.frozen,
            host_figures.max_speed
        )
    );
    assert_eq!(
        (device.lower, device.upper),
        (host_figures.lower, host_figures.upper)
    );
    assert_eq!((device.non_finite, host_figures.non_finite), (None, None));
    assert!(close(device.moments.mass, host_figures.moments.mass));
    assert!(near(&device.moments.first, &host_figures.moments.first));
    assert!(
        close(device.kinetic, host_figures.kinetic),
        "{device:?} {host_figures:?}"
    );
    assert!(close(device.potential, host_figures.potential));
    assert!(host_figures.kinetic > 0.0 && host_figures.max_speed > 1.0);

    let i = start.particles.owned() / 2;
    start.particles.velocity[i].y = f64::NAN;
    let mut broken = DeviceWorld::new(host(64), &start, &params).unwrap();
    let figures = broken.particle_figures().unwrap();
    assert_eq!(figures.non_finite, Some(start.particles.id[i]));
    assert_eq!(figures.non_finite, RunFigures::of(&start).non_finite);
}
