//! The CUDA backend behind the seam (`engine::cuda::backend`), its kernels run by the
//! host executor, drives a whole `Simulation` as the CPU backend does: a pour of
//! spheres from an inlet into a box (particles added every few steps, so the device
//! stepper is rebuilt with its contact history each time), to the CPU backend's
//! bits, and the walls' sums and the energy account to round-off.
#![cfg(feature = "cuda")]

use std::path::Path;

mod common;
use common::{close, near};

use talus::engine::cuda::backend::CudaBackend;
use talus::engine::cuda::device::HostDevice;
use talus::engine::{Backend, CpuBackend};
use talus::scene::{Scene, Simulation};

/// 120 beads poured onto 72 in an open box.
const POUR: &str = include_str!("scenes/sphere_pour.toml");

/// 2000 steps: the particles and the step's figures equal the CPU backend's at
/// every hundredth step, and the box's force, torque and facet forces and the
/// energy account to round-off.
#[test]
fn a_pour_from_an_inlet_runs_as_on_the_cpu_backend_to_the_bit() {
    let scene = Scene::parse(POUR, Path::new("pour.toml")).unwrap();
    let mut cpu = Simulation::new(&scene);
    let backend = CudaBackend::new(
        Box::new(HostDevice::new(64)),
        &scene.world,
        scene.step_params(),
    )
    .unwrap();
    let mut gpu = Simulation::with_backend(&scene, Box::new(backend));
    assert_eq!(gpu.backend().name(), "cuda");
    let mut most_walls = 0;
    for step in 1..=2000 {
        cpu.step();
        gpu.step();
        if step % 100 != 0 {
            continue;
        }
        let (a, b) = (cpu.world(), gpu.world());
        assert_eq!(a.particles.id, b.particles.id, "step {step}");
        assert_eq!(a.particles.position, b.particles.position, "step {step}");
        assert_eq!(a.particles.velocity, b.particles.velocity, "step {step}");
        assert_eq!(a.particles.angular_momentum, b.particles.angular_momentum);
        assert_eq!(a.particles.force, b.particles.force, "step {step}");
        let (u, v) = (&a.walls[0], &b.walls[0]);
        assert!(near(&u.force, &v.force), "step {step}");
        assert!(near(&u.torque, &v.torque), "step {step}");
        for (f, g) in u.facet_force.iter().zip(&v.facet_force) {
            assert!(near(f, g), "{f} against {g} at step {step}");
        }
        assert_eq!(a.time, b.time);
        let (s, t) = (cpu.stats(), gpu.stats());
        assert_eq!(
            (s.contacts, s.pair_contacts, s.integrated),
            (t.contacts, t.pair_contacts, t.integrated),
            "step {step}"
        );
        // The device sums the contacts' energies in a tree, the CPU serially: the
        // same terms, round-off apart.
        assert!(close(s.elastic_energy, t.elastic_energy), "step {step}");
        assert!(close(s.dissipated, t.dissipated), "step {step}");
        let (e, f) = (cpu.energy(), gpu.energy());
        for (a, b) in [
            (e.start, f.start),
            (e.wall_work, f.wall_work),
            (e.fluid_work, f.fluid_work),
            (e.dissipated, f.dissipated),
            (e.host, f.host),
            (e.motion_in, f.motion_in),
        ] {
            assert!(close(a, b), "{e:?} against {f:?} at step {step}");
        }
        assert_eq!(cpu.backend().touching(), gpu.backend().touching());
        assert_eq!(
            cpu.backend().contact_history(),
            gpu.backend().contact_history()
        );
        most_walls = most_walls.max(s.contacts - s.pair_contacts);
    }
    let world = gpu.world();
    let lattice = scene.world.particles.len();
    assert_eq!(
        world.particles.len(),
        lattice + 120,
        "the lattice and the inlet's"
    );
    assert!(most_walls > 20, "{most_walls} wall contacts at most");
    assert!(gpu.stats().pair_contacts > 50, "{:?}", gpu.stats());
}

/// With the particles copied back only when asked
/// (`Simulation::set_particles_each_step(false)`), the host world keeps its last
/// copy between steps once the inlet is done, and the pour runs as with them copied
/// every step (the inlet's insertions, which rebuild the device stepper from the host
/// world, still see them): the same bits after `sync_particles`.
#[test]
fn particles_copied_back_when_asked_give_the_same_run() {
    let scene = Scene::parse(POUR, Path::new("pour.toml")).unwrap();
    let start = || {
        let device = Box::new(HostDevice::new(64));
        let backend = CudaBackend::new(device, &scene.world, scene.step_params()).unwrap();
        Simulation::with_backend(&scene, Box::new(backend))
    };
    let (mut every, mut asked) = (start(), start());
    asked.set_particles_each_step(false);
    // Until the inlet's 120 particles are in (the pour of the test above holds
    // them all after 2000 steps), and a hundred steps more.
    for _ in 0..2000 {
        every.step();
        asked.step();
        if asked.inlets_done() && asked.steps % 100 == 0 {
            break;
        }
    }
    assert!(asked.inlets_done() && every.inlets_done());
    let kept = asked.world().particles.position.clone();
    every.step();
    asked.step();
    assert_ne!(every.world().particles.position, kept);
    assert_eq!(asked.world().particles.position, kept, "not copied back");
    assert_ne!(every.backend().touching(), asked.backend().touching());
    asked.sync_particles();
    assert_eq!(every.backend().touching(), asked.backend().touching());
    let (a, b) = (every.world(), asked.world());
    assert_eq!(a.particles.id, b.particles.id);
    assert_eq!(a.particles.position, b.particles.position);
    assert_eq!(a.particles.velocity, b.particles.velocity);
    assert_eq!(a.particles.angular_momentum, b.particles.angular_momentum);
    assert_eq!(every.energy().dissipated, asked.energy().dissipated);
    assert_eq!(every.held_energy().kinetic, asked.held_energy().kinetic);
}

/// `[simulation] backend = "cuda"` is checked when the scene is read: what the
/// backend does not model is refused with what it is, and without a GPU driver the
/// scene says so (on a machine with one, the scene is read and the simulation
/// steps on GPU 0).
#[test]
fn a_scene_asking_for_the_cuda_backend_is_checked_when_read() {
    let cuda = POUR.replace("seed = 3", "seed = 3\nbackend = \"cuda\"");
    let line = cuda.lines().position(|l| l.starts_with("backend")).unwrap() + 1;
    match Scene::parse(&cuda, Path::new("pour.toml")) {
        Ok(scene) => {
            assert!(talus::engine::cuda::driver::CudaDevice::is_present());
            let mut sim = Simulation::new(&scene);
            sim.step();
            assert_eq!(sim.backend().name(), "cuda");
        }
        Err(e) => assert_eq!(
            e.to_string(),
            format!(
                "pour.toml:{line}: simulation.backend: no CUDA driver (libcuda) is found: the \
                 cuda backend needs an NVIDIA GPU and its driver"
            )
        ),
    }
    // Spheres under the volume law and with rolling resistance are stepped; a
    // polyhedron beyond the kernels' 64 faces and vertices is refused.
    let volume = cuda.replace("law = \"hertz_mindlin\"", "law = \"volume\"");
    let rolling = cuda.replace(
        "law = \"hertz_mindlin\"",
        "law = \"hertz_mindlin\"\nrolling = \"elastic_plastic\"",
    );
    for text in [volume, rolling] {
        match Scene::parse(&text, Path::new("pour.toml")) {
            Ok(_) => assert!(talus::engine::cuda::driver::CudaDevice::is_present()),
            Err(e) => assert!(e.to_string().contains("no CUDA driver"), "{e}"),
        }
    }
    let round = cuda.replace(
        "kind = \"sphere\"\nradius = 0.004",
        "kind = \"icosphere\"\nlevel = 2\nradius = 0.004",
    );
    let e = Scene::parse(&round, Path::new("pour.toml")).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!(
            "pour.toml:{line}: simulation.backend: the cuda backend does not yet step body type \
             0, a polyhedron of 162 vertices and 320 faces (at most 64 of each)"
        )
    );
    // Polyhedra are stepped (under the volume law), and so are spheres and
    // polyhedra together.
    let rocks = cuda.replace(
        "kind = \"sphere\"\nradius = 0.004",
        "kind = \"platonic\"\nsolid = \"dodecahedron\"\ncircumradius = 0.004",
    );
    match Scene::parse(&rocks, Path::new("pour.toml")) {
        Ok(_) => assert!(talus::engine::cuda::driver::CudaDevice::is_present()),
        Err(e) => assert!(e.to_string().contains("no CUDA driver"), "{e}"),
    }
    let mixed = cuda.replace(
        "[[wall]]",
        "[shapes.rock]\nkind = \"platonic\"\nsolid = \"cube\"\ncircumradius = 0.004\n[[wall]]",
    );
    let mixed = mixed.replace("[[inlet]]\nshape = \"bead\"", "[[inlet]]\nshape = \"rock\"");
    match Scene::parse(&mixed, Path::new("pour.toml")) {
        Ok(_) => assert!(talus::engine::cuda::driver::CudaDevice::is_present()),
        Err(e) => assert!(e.to_string().contains("no CUDA driver"), "{e}"),
    }
    // The CPU backend stays the default.
    let scene = Scene::parse(POUR, Path::new("pour.toml")).unwrap();
    assert_eq!(Simulation::new(&scene).backend().name(), "cpu");
}

/// The Component's parameter `backend` chooses what steps the scene: "cpu" by
/// default (the scene's), a name that is no backend refused, "cuda" refused with
/// the reason where there is no GPU driver (the parameter left as it was) and, on a
/// machine with a GPU, the component steps on it as the CPU's does (particles to the
/// bit, the box's mean force to round-off). Fixed once initialisation starts.
#[test]
fn the_component_parameter_backend_chooses_what_steps_the_scene() {
    use talus::cosim::{Component, CosimError, VarRef};
    let dir = std::env::temp_dir().join(format!("talus-backend-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("pour.toml"), POUR).unwrap();
    let open = || Component::instantiate(&dir, "pour.toml").unwrap();
    let backend = |c: &Component| {
        let var = c.variable("backend").unwrap();
        c.get_string(&[VarRef { var, element: 0 }]).unwrap()[0].clone()
    };
    let set = |c: &mut Component, name: &str| {
        let var = c.variable("backend").unwrap();
        c.set_string(&[VarRef { var, element: 0 }], &[name])
    };
    let mut cpu = open();
    assert_eq!(backend(&cpu), "cpu");
    let e = set(&mut cpu, "gpu").unwrap_err();
    assert!(matches!(e, CosimError::BadValue { .. }));
    assert_eq!(
        e.to_string(),
        "variable 'backend': 'gpu': the backends are cpu and cuda"
    );
    assert_eq!(backend(&cpu), "cpu");

    let mut gpu = open();
    if let Err(e) = set(&mut gpu, "cuda") {
        assert_eq!(
            e.to_string(),
            "variable 'backend': cuda: no CUDA driver (libcuda) is found: the cuda backend \
             needs an NVIDIA GPU and its driver"
        );
        assert_eq!(backend(&gpu), "cpu");
        assert!(
            std::env::var_os("TALUS_REQUIRE_GPU").is_none(),
            "TALUS_REQUIRE_GPU is set: {e}"
        );
        eprintln!("no GPU driver: the component's cuda run is not checked here");
        return;
    }
    assert_eq!(backend(&gpu), "cuda");
    for c in [&mut cpu, &mut gpu] {
        c.enter_initialization_mode(0.0).unwrap();
        c.exit_initialization_mode().unwrap();
    }
    assert_eq!(gpu.simulation().unwrap().backend().name(), "cuda");
    assert!(
        set(&mut gpu, "cpu").is_err(),
        "fixed once initialisation starts"
    );
    let force = cpu.variable("box.force").unwrap();
    for k in 0..20 {
        let t = k as f64 * 2e-3;
        cpu.do_step(t, 2e-3).unwrap();
        gpu.do_step(t, 2e-3).unwrap();
        let (a, b) = (&cpu.world().particles, &gpu.world().particles);
        assert_eq!(a.id, b.id, "step {k}");
        assert_eq!(a.position, b.position, "step {k}");
        assert_eq!(a.velocity, b.velocity, "step {k}");
        let (f, g) = (
            cpu.get_real_vector(force).unwrap(),
            gpu.get_real_vector(force).unwrap(),
        );
        for (x, y) in f.iter().zip(&g) {
            assert!(close(*x, *y), "box.force {f:?} against {g:?}");
        }
    }
    assert!(cpu.world().particles.len() > 100);
}

/// What the host changes between steps is uploaded alone, as the seam's sync points
/// call it: particles frozen, velocities set and particles appended (an inlet's)
/// go to the device without the stepper being made again from the whole world
/// (`CudaBackend::rebuilds`), and the run stays the CPU backend's to the bit; a
/// removal rebuilds it.
#[test]
fn changes_on_the_host_are_uploaded_alone_and_keep_the_bits() {
    let scene = Scene::parse(POUR, Path::new("pour.toml")).unwrap();
    let dt = scene.dt;
    let mut cpu = CpuBackend::new(scene.step_params());
    let device = Box::new(HostDevice::new(64));
    let mut gpu = CudaBackend::new(device, &scene.world, scene.step_params()).unwrap();
    let (mut a, mut b) = (scene.world.clone(), scene.world.clone());
    cpu.world_changed(&a);
    cpu.initialise(&mut a, dt);
    gpu.initialise(&mut b, dt);
    let compare = |cpu: &mut CpuBackend, gpu: &mut CudaBackend, a: &mut _, b: &mut _| {
        for step in 0..200 {
            cpu.step(a, dt);
            gpu.step(b, dt);
            if step % 50 == 49 {
                gpu.sync_to_host(b);
                let (p, q) = (&a.particles, &b.particles);
                assert_eq!(p.position, q.position, "step {step}");
                assert_eq!(p.velocity, q.velocity, "step {step}");
                assert_eq!(p.angular_momentum, q.angular_momentum, "step {step}");
                assert_eq!(cpu.touching(), gpu.touching(), "step {step}");
                assert_eq!(cpu.stats().contacts, gpu.stats().contacts, "step {step}");
                assert!(near(&a.walls[0].force, &b.walls[0].force), "step {step}");
            }
        }
    };
    compare(&mut cpu, &mut gpu, &mut a, &mut b);
    let n = a.particles.len();
    assert!(n > 40 && cpu.stats().contacts > 20, "{n} {:?}", cpu.stats());

    // Every fifth particle frozen where it is.
    let frozen: Vec<usize> = (0..n).step_by(5).collect();
    for w in [&mut a, &mut b] {
        for &i in &frozen {
            w.particles.freeze(i);
        }
    }
    cpu.particles_frozen(&a, &frozen);
    gpu.particles_frozen(&b, &frozen);
    compare(&mut cpu, &mut gpu, &mut a, &mut b);

    // The others thrown upward.
    for w in [&mut a, &mut b] {
        for i in (0..n).filter(|i| i % 5 != 0) {
            w.particles.velocity[i].z += 0.3;
        }
    }
    cpu.velocities_set(&a);
    gpu.velocities_set(&b);
    compare(&mut cpu, &mut gpu, &mut a, &mut b);

    // Particles appended above the bed, as an inlet does (state and weight set),
    // more than the buffers' room to grow, then a few that fit.
    let mut added = 0;
    for count in [n, 3] {
        for w in [&mut a, &mut b] {
            let p = &mut w.particles;
            for k in 0..count {
                let at = nalgebra::Point3::new(
                    0.006 + 0.009 * (k % 5) as f64,
                    0.006 + 0.009 * (k / 5 % 5) as f64,
                    0.08 + 0.009 * (k / 25) as f64,
                );
                let id = 10_000 + (added + k) as u64;
                p.push(0, at, nalgebra::UnitQuaternion::identity(), id);
                let i = p.len() - 1;
                p.velocity[i] = nalgebra::Vector3::new(0.0, 0.0, -0.5);
            }
            let len = w.particles.len();
            w.weigh(len - count..len);
        }
        let range = a.particles.len() - count..a.particles.len();
        cpu.particles_added(&a, range.clone());
        gpu.particles_added(&b, range);
        added += count;
        compare(&mut cpu, &mut gpu, &mut a, &mut b);
    }
    assert_eq!(a.particles.len(), 2 * n + 3);
    assert_eq!(gpu.rebuilds(), 0, "only what changed was uploaded");

    // A removal takes the whole world again.
    for (w, backend) in [(&mut a, &mut cpu as &mut dyn Backend), (&mut b, &mut gpu)] {
        backend.sync_to_host(w);
        w.particles.remove_where(|i| i % 7 == 3);
        backend.particles_removed(w);
    }
    compare(&mut cpu, &mut gpu, &mut a, &mut b);
    assert_eq!(gpu.rebuilds(), 1);
}
