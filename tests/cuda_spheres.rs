//! The device stepper of a world of spheres (`engine::cuda::spheres`) through the
//! host executor, against the CPU backend: every kernel of the step (integration,
//! the hashed-grid list with its prefix sums, the Hertz–Mindlin pair contacts with
//! their tangential history carried over list builds, the gather) performs the CPU
//! backend's operations in its order, so a run gives the CPU backend's bits.
#![cfg(feature = "cuda")]

use std::path::Path;

use nalgebra::{Point3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use talus::engine::cuda::device::{Device, HostDevice};
use talus::engine::cuda::driver::CudaDevice;
use talus::engine::cuda::spheres::{DeviceSpheres, SpheresError};
use talus::engine::{Backend, CpuBackend};
use talus::scene::Scene;
use talus::world::World;

const SCENE: &str = r#"
[simulation]
dt = 2e-5
end_time = 1.0
gravity = [0.0, 0.0, -9.81]
[contact]
law = "hertz_mindlin"
[materials.glass]
density = 2500.0
young = 1e7
poisson = 0.3
restitution = 0.5
friction = 0.5
[materials.steel]
density = 7800.0
young = 2e7
poisson = 0.25
restitution = 0.7
friction = 0.3
[shapes.big]
kind = "sphere"
radius = 0.005
[shapes.small]
kind = "sphere"
radius = 0.004
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

/// A cloud of 1000 spheres of two sizes and materials on a jittered lattice of
/// 12 mm, converging on its centre at up to 2 m/s with random spins (every
/// thirteenth frozen): within a few hundred steps most spheres are in contact,
/// sliding and sticking, and the list is rebuilt many times.
fn cloud() -> (World, talus::engine::StepParams) {
    let scene = Scene::parse(SCENE, Path::new("cloud.toml")).unwrap();
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
        p.velocity[k] = u - x * 35.0;
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
    let dt = 2e-5;
    let mut cpu_world = start.clone();
    let mut cpu = CpuBackend::new(params);
    cpu.initialise(&mut cpu_world, dt);
    let mut spheres = DeviceSpheres::new(device, &start, &params).unwrap();
    spheres.initialise(dt).unwrap();
    let mut device_world = start.clone();
    let (mut most_contacts, mut most_springs, mut most_pairs) = (0, 0, 0);
    for step in 1..=1000 {
        cpu.step(&mut cpu_world, dt);
        spheres.step(dt).unwrap();
        assert_eq!(spheres.contacts(), cpu.stats().pair_contacts, "step {step}");
        most_contacts = most_contacts.max(spheres.contacts());
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
        assert_eq!(spheres.candidate_pairs(), cpu.stats().candidate_pairs);
        let history = cpu.contact_history();
        assert_eq!(spheres.contact_history().unwrap(), history, "step {step}");
        most_springs = most_springs.max(history.pairs.len());
        assert_eq!(spheres.touching().unwrap(), cpu.touching(), "step {step}");
    }
    // A test of contacts, friction and list builds, not of free flight: the cloud
    // collapses (about 1500 contacts at once) and bounces apart.
    assert!(most_contacts > 1200, "{most_contacts} contacts at most");
    assert!(most_springs > 1000, "{most_springs} springs at most");
    assert!(
        spheres.list_builds() > 10,
        "{} builds",
        spheres.list_builds()
    );
    assert_eq!(spheres.list_builds(), cpu.stats().list_builds);
    // Device memory: 230 bytes a particle (its state 166, the list's 64 with a grid
    // of at least 2n buckets) and 201 a candidate pair (the pair 8, its incidences
    // 8, ids 16, history 32, result 88, touching 1, and the previous build's ids
    // and history, 48), buffers sized for the most pairs so far with room to grow
    // by half.
    let (n, pairs) = (1000.0, most_pairs as f64);
    let bytes = spheres.device_bytes() as f64;
    eprintln!("{bytes} bytes for {n} spheres and at most {pairs} candidate pairs");
    assert!(
        bytes <= 1.5 * (230.0 * n + 201.0 * pairs) + 8192.0,
        "{bytes} bytes"
    );
    assert!(
        bytes >= 166.0 * n + 201.0 * spheres.candidate_pairs() as f64,
        "{bytes} bytes"
    );
}

#[test]
fn a_converging_cloud_steps_as_the_cpu_backend_to_the_bit() {
    steps_as_the_cpu_backend(host(64));
}

/// The same on a GPU, where there is one (`scripts/gpu-check.sh`): the kernels are
/// compiled without fused multiply–adds and with IEEE division and square roots,
/// and the only atomics are on integers, so the GPU gives the same bits. Without a
/// driver the test says so and passes, unless `TALUS_REQUIRE_GPU` is set.
#[test]
fn on_a_gpu_the_cloud_steps_as_the_cpu_backend_to_the_bit() {
    match CudaDevice::open(0) {
        Ok(gpu) => {
            eprintln!("on {gpu:?}");
            steps_as_the_cpu_backend(Box::new(gpu));
        }
        Err(e) => {
            assert!(
                std::env::var_os("TALUS_REQUIRE_GPU").is_none(),
                "TALUS_REQUIRE_GPU is set: {e}"
            );
            eprintln!("skipped: {e}");
        }
    }
}

/// The host executor runs a launch's blocks in parallel: blocks of 1, 32 and 256
/// threads give the same bits (the atomics of the binning and of the incidence
/// lists change the order of the scattered entries, never the sorted list).
#[test]
fn the_answer_does_not_depend_on_the_block_size() {
    let (start, params) = cloud();
    let dt = 2e-5;
    let worlds: Vec<World> = [1, 32, 256]
        .into_iter()
        .map(|block| {
            let mut spheres = DeviceSpheres::new(host(block), &start, &params).unwrap();
            spheres.initialise(dt).unwrap();
            for _ in 0..300 {
                spheres.step(dt).unwrap();
            }
            let mut world = start.clone();
            spheres.download(&mut world).unwrap();
            world
        })
        .collect();
    assert!(worlds[0].particles.position != start.particles.position);
    for w in &worlds[1..] {
        assert_eq!(w.particles.position, worlds[0].particles.position);
        assert_eq!(w.particles.velocity, worlds[0].particles.velocity);
    }
}

/// What the device stepper does not model yet is refused with what it is.
#[test]
fn walls_polyhedra_and_other_laws_are_refused() {
    let (world, params) = cloud();
    let mut volume = params;
    volume.round_law = talus::engine::RoundLaw::Volume;
    let said = |r: Result<DeviceSpheres, SpheresError>| r.unwrap_err().to_string();
    assert_eq!(
        said(DeviceSpheres::new(host(64), &world, &volume)),
        "the cuda backend does not yet step a law other than Hertz–Mindlin without rolling resistance"
    );
    let mut shuffled = world.clone();
    shuffled.particles.id.swap(0, 1);
    assert!(
        said(DeviceSpheres::new(host(64), &shuffled, &params))
            .ends_with("particles out of the order of their ids")
    );
}
