//! The backend seam: ghost copies give the owned particles the forces of the whole
//! world, removed particles leave the others' contact history as it was, and every
//! change the host makes reaches the backend through its sync calls.

use std::ops::{ControlFlow, Range};
use std::path::Path;
use std::sync::{Arc, Mutex};

use talus::Real;
use talus::engine::{Backend, ContactHistory, CpuBackend, StageTimes, StepParams, StepStats};
use talus::scene::{Scene, Simulation, StateReader, StateWriter};
use talus::world::{Particles, World};

/// Four layers of dodecahedra, randomly turned and close enough to overlap, on the
/// floor of a box.
const BOX: &str = include_str!("scenes/lattice_box.toml");

fn world_of(text: &str) -> World {
    Scene::parse(text, Path::new("box.toml"))
        .expect("valid scene")
        .world
}

/// `world` with its particles `0..owned` kept as owned and the rest as ghosts.
fn split(world: &World, owned: usize) -> World {
    let p = &world.particles;
    let mut q = Particles::default();
    for i in 0..p.len() {
        if i < owned {
            q.push(p.body_type[i], p.position[i], p.orientation[i], p.id[i]);
        } else {
            q.push_ghost(p.body_type[i], p.position[i], p.orientation[i], p.id[i]);
        }
        let k = q.len() - 1;
        q.velocity[k] = p.velocity[i];
        q.angular_momentum[k] = p.angular_momentum[i];
    }
    World {
        particles: q,
        ..world.clone()
    }
}

#[test]
fn ghosts_give_the_owned_half_the_forces_of_the_whole_box() {
    let dt = 1e-5;
    let mut whole = world_of(BOX);
    let n = whole.particles.len();
    assert_eq!(n, 100, "4 layers of 25");
    // The lattice fills layer by layer from the floor: the first half of the
    // particles is the lower half of the box, and the ghosts of the upper half come
    // after every owned particle, as they do in the whole box.
    let owned = n / 2;
    let mut half = split(&whole, owned);
    assert_eq!(half.particles.owned(), owned);
    assert_eq!(half.particles.ghosts(), n - owned);
    assert!(half.particles.is_ghost(owned) && !half.particles.is_ghost(owned - 1));
    assert_eq!(
        half.particles.index_of(whole.particles.id[owned]),
        Some(owned)
    );

    let mut a = CpuBackend::new(StepParams::default());
    let mut b = CpuBackend::new(StepParams::default());
    a.initialise(&mut whole, dt);
    b.initialise(&mut half, dt);
    let touching_ghost = (0..owned).filter(|&i| {
        b.neighbours()
            .incident(i)
            .iter()
            .any(|&e| b.neighbours().pairs()[e.pair()][1] as usize >= owned)
    });
    assert!(
        touching_ghost.count() >= 10,
        "the lower half has candidates in the upper half"
    );
    assert!(a.stats().pair_contacts > 50, "{:?}", a.stats());
    assert!(
        a.stats().contacts > a.stats().pair_contacts,
        "wall contacts too"
    );
    // The ghosts matter: without them the lower half has fewer contacts and other
    // forces.
    let mut lower = World {
        particles: half.particles.owned_only(),
        ..half.clone()
    };
    let mut c = CpuBackend::new(StepParams::default());
    c.initialise(&mut lower, dt);
    assert!(
        c.stats().pair_contacts + 5 <= b.stats().pair_contacts,
        "{} pair contacts without ghosts, {} with",
        c.stats().pair_contacts,
        b.stats().pair_contacts
    );
    let changed = (0..owned)
        .filter(|&i| lower.particles.force[i] != whole.particles.force[i])
        .count();
    assert!(changed >= 5, "{changed} forces change without the ghosts");
    for i in 0..owned {
        assert_eq!(
            half.particles.force[i], whole.particles.force[i],
            "force of {i}"
        );
        assert_eq!(
            half.particles.torque[i], whole.particles.torque[i],
            "torque of {i}"
        );
    }
    for i in owned..n {
        assert_eq!(
            half.particles.force[i],
            nalgebra::Vector3::zeros(),
            "ghost {i}"
        );
    }
    // Only the owned half touches the floor: the wall forces are the whole box's.
    assert_eq!(half.walls[0].force, whole.walls[0].force);
    assert_eq!(half.walls[0].facet_force, whole.walls[0].facet_force);

    // A step moves the owned particles as in the whole box, and never a ghost.
    let ghost_position = half.particles.position[owned];
    a.step(&mut whole, dt);
    b.step(&mut half, dt);
    for i in 0..owned {
        assert_eq!(
            half.particles.position[i], whole.particles.position[i],
            "{i}"
        );
        assert_eq!(
            half.particles.orientation[i],
            whole.particles.orientation[i]
        );
    }
    assert_eq!(half.particles.position[owned], ghost_position);
    assert_ne!(whole.particles.position[owned], ghost_position);
    assert_eq!(b.stats().integrated, owned);

    // Ghosts are in no figure of the world.
    let owned_only = half.particles.owned_only();
    assert_eq!((owned_only.len(), owned_only.ghosts()), (owned, 0));
    let moving = World {
        particles: owned_only,
        ..half.clone()
    };
    assert_eq!(half.kinetic_energy(), moving.kinetic_energy());
    assert_eq!(half.max_speed(), moving.max_speed());
    half.particles.clear_ghosts();
    assert_eq!(half.particles.len(), owned);
    assert_eq!(half.particles.index_of(whole.particles.id[owned]), None);
}

#[test]
fn removing_a_particle_keeps_the_others_history() {
    let scene = Scene::parse(BOX, Path::new("box.toml")).unwrap();
    let mut sim = Simulation::new(&scene);
    let _ = sim.advance_to(2e-3, |_, _| ControlFlow::<()>::Continue(()));
    let gone = sim.world().particles.id[30];
    // The same world and history without the particle, restored into a fresh run.
    let mut state = sim.snapshot();
    let i = state.particles.index_of(gone).unwrap();
    state.particles.remove_where(|k| k == i);
    state
        .history
        .pairs
        .retain(|((a, b), _)| *a != gone && *b != gone);
    state.history.walls.retain(|((id, _, _), _)| *id != gone);
    assert!(!state.history.pairs.is_empty());
    let mut restored = Simulation::new(&scene);
    restored.restore(&state).unwrap();

    assert_eq!(sim.remove_particles(|w, k| w.particles.id[k] == gone), 1);
    assert_eq!(sim.world().particles.index_of(gone), None);
    for s in [&mut sim, &mut restored] {
        let _ = s.advance_to(4e-3, |_, _| ControlFlow::<()>::Continue(()));
    }
    let (a, b) = (&sim.world().particles, &restored.world().particles);
    assert_eq!(a.id, b.id);
    assert_eq!(a.position, b.position);
    assert_eq!(a.velocity, b.velocity);
    assert_eq!(a.angular_momentum, b.angular_momentum);
    assert_eq!(
        sim.backend().contact_history(),
        restored.backend().contact_history()
    );
}

#[test]
fn the_first_non_finite_particle_is_named() {
    let scene = Scene::parse(BOX, Path::new("box.toml")).unwrap();
    let mut sim = Simulation::new(&scene);
    let _ = sim.advance_to(1e-3, |_, _| ControlFlow::<()>::Continue(()));
    assert_eq!(sim.first_non_finite(), None);
    // The step looked itself, so the host need not.
    assert_eq!(sim.backend().stepped_finite(), Some(true));
    let (a, b) = (sim.world().particles.id[40], sim.world().particles.id[70]);
    sim.edit_world(|w| {
        w.particles.velocity[70].y = f64::NAN;
        w.particles.position[40].z = f64::INFINITY;
    });
    // An edit since the step: the step's look no longer holds, the host looks.
    assert_eq!(sim.backend().stepped_finite(), None);
    assert_eq!(sim.first_non_finite(), Some(a));
    // Stepping a blown-up state answers (non-finite values), never panics or hangs:
    // the broad phase bins a non-finite particle into a corner cell.
    let t = sim.time();
    let _ = sim.advance_to(t + 1e-4, |_, _| ControlFlow::<()>::Continue(()));
    assert_eq!(sim.backend().stepped_finite(), Some(false));
    assert_eq!(sim.first_non_finite(), Some(a));
    sim.edit_world(|w| w.particles.position[40].z = 0.01);
    assert_eq!(sim.first_non_finite(), Some(b));
}

/// The sync calls a backend received, in order.
type Calls = Arc<Mutex<Vec<String>>>;

/// A CPU backend that records the host's sync calls, and checks at every step that
/// the host world holds what the calls told it: the particle ids it was told of.
#[derive(Debug)]
struct Recording {
    inner: CpuBackend,
    ids: Vec<u64>,
    calls: Calls,
}

impl Recording {
    fn log(&self, call: String) {
        self.calls.lock().unwrap().push(call);
    }
}

impl Backend for Recording {
    fn name(&self) -> &'static str {
        "recording"
    }
    fn params(&self) -> &StepParams {
        self.inner.params()
    }
    fn set_params(&mut self, params: StepParams) {
        self.inner.set_params(params)
    }
    fn initialise(&mut self, world: &mut World, dt: Real) {
        assert_eq!(
            world.particles.id, self.ids,
            "a change the backend was not told of"
        );
        self.inner.initialise(world, dt)
    }
    fn step(&mut self, world: &mut World, dt: Real) {
        assert_eq!(
            world.particles.id, self.ids,
            "a change the backend was not told of"
        );
        self.inner.step(world, dt)
    }
    fn stats(&self) -> &StepStats {
        self.inner.stats()
    }
    fn stage_times(&self) -> &StageTimes {
        self.inner.stage_times()
    }
    fn touching(&self) -> &[bool] {
        self.inner.touching()
    }
    fn particles_added(&mut self, world: &World, added: Range<usize>) {
        assert_eq!(added.start, self.ids.len());
        self.ids
            .extend_from_slice(&world.particles.id[added.clone()]);
        self.log(format!("added {added:?}"));
        self.inner.particles_added(world, added)
    }
    fn particles_frozen(&mut self, world: &World, frozen: &[usize]) {
        assert!(frozen.iter().all(|&i| world.particles.frozen[i]));
        self.log(format!("frozen {}", frozen.len()));
        self.inner.particles_frozen(world, frozen)
    }
    fn particles_removed(&mut self, world: &World) {
        self.ids.clone_from(&world.particles.id);
        self.log("removed".into());
        self.inner.particles_removed(world)
    }
    fn velocities_set(&mut self, world: &World) {
        self.log("velocities".into());
        self.inner.velocities_set(world)
    }
    fn walls_moved(&mut self, world: &World) {
        self.log("walls".into());
        self.inner.walls_moved(world)
    }
    fn fluid_changed(&mut self, world: &World) {
        self.log("fluid".into());
        self.inner.fluid_changed(world)
    }
    fn world_changed(&mut self, world: &World) {
        self.ids.clone_from(&world.particles.id);
        self.log("world".into());
        self.inner.world_changed(world)
    }
    fn contact_history(&self) -> ContactHistory {
        self.inner.contact_history()
    }
    fn restore(&mut self, world: &World, history: ContactHistory, stats: StepStats) {
        self.ids.clone_from(&world.particles.id);
        self.log("restore".into());
        self.inner.restore(world, history, stats)
    }
    fn sync_to_host(&mut self, world: &mut World) {
        self.inner.sync_to_host(world)
    }
}

#[test]
fn every_change_of_the_host_reaches_the_backend() {
    // The box fed by an inlet: particles are added between steps.
    let text = BOX.replace(
        "[[particles]]",
        "[[inlet]]\nshape = \"dodecahedron\"\nmaterial = \"pla\"\nmin = [0.0, 0.0, 0.05]\n\
         max = [0.046, 0.046, 0.09]\nrate = 5000.0\ncount = 10\n\n[[particles]]",
    );
    let scene = Scene::parse(&text, Path::new("box.toml")).unwrap();
    let calls = Calls::default();
    let backend = Recording {
        inner: CpuBackend::new(scene.step_params()),
        ids: Vec::new(),
        calls: calls.clone(),
    };
    let mut recorded = Simulation::with_backend(&scene, Box::new(backend));
    let mut plain = Simulation::new(&scene);
    let state = plain.snapshot();
    for sim in [&mut recorded, &mut plain] {
        let _ = sim.advance_to(3e-3, |_, _| ControlFlow::<()>::Continue(()));
        sim.move_walls(|walls| walls[0].velocity.x = 0.01);
        sim.damp_velocities(0.5);
        let _ = sim.advance_to(4e-3, |_, _| ControlFlow::<()>::Continue(()));
        sim.remove_particles(|_, k| k == 3);
        sim.restore(&state).unwrap();
        let _ = sim.advance_to(1e-3, |_, _| ControlFlow::<()>::Continue(()));
    }
    // The recording backend computes what the CPU backend does.
    assert_eq!(
        recorded.world().particles.position,
        plain.world().particles.position
    );
    let calls = calls.lock().unwrap().clone();
    let added = calls.iter().filter(|c| c.starts_with("added")).count();
    // The inlet inserts 10 particles by 2 ms, once after the restore too (1 ms).
    assert!(added >= 6, "{calls:?}");
    for call in ["walls", "velocities", "removed", "restore"] {
        assert!(calls.iter().any(|c| c == call), "no {call} call: {calls:?}");
    }
}

/// A run restored from a saved state (through its bytes) builds its candidate lists
/// at the same steps as the run it was saved from, starting from the saved build's
/// positions: the same candidate pairs at every step, the first included. (A list
/// built from the restored positions holds other candidates and is rebuilt at other
/// steps.)
#[test]
fn a_restored_run_builds_its_lists_at_the_same_steps() {
    let scene = Scene::parse(BOX, Path::new("box.toml")).unwrap();
    let mut saved = Simulation::new(&scene);
    let _ = saved.advance_to(1e-3, |_, _| ControlFlow::<()>::Continue(()));
    let mut bytes = StateWriter::default();
    saved.write_state(11, &mut bytes);
    let mut restored = Simulation::new(&scene);
    let bytes = bytes.into_bytes();
    restored
        .read_state(11, &mut StateReader::new(&bytes))
        .unwrap();
    // (list builds so far, candidate pairs) after every step.
    let steps = |sim: &mut Simulation| {
        let mut seen = Vec::new();
        let _ = sim.advance_to(2.1e-2, |s, _| {
            let stats = s.stats();
            seen.push((stats.list_builds, stats.candidate_pairs));
            ControlFlow::<()>::Continue(())
        });
        seen
    };
    let (a, b) = (steps(&mut saved), steps(&mut restored));
    assert_eq!(a.len(), 2000);
    // The steps (after the first) that build the lists.
    let builds = |seen: &[(u64, usize)]| -> Vec<usize> {
        (1..seen.len())
            .filter(|&k| seen[k].0 > seen[k - 1].0)
            .collect()
    };
    let built = builds(&a);
    assert!((5..200).contains(&built.len()), "builds at steps {built:?}");
    assert_eq!(built, builds(&b), "the steps that build the lists");
    let candidates = |seen: &[(u64, usize)]| seen.iter().map(|s| s.1).collect::<Vec<_>>();
    assert_eq!(candidates(&a), candidates(&b));
    assert_eq!(
        saved.world().particles.position,
        restored.world().particles.position
    );
}

/// A state of format 7 (before the lists' anchors and the particles' cell codes
/// were saved: version 8's bytes without the list, whose flag ends them, and
/// without the codes) still restores, and steps on to the same
/// bits (the contacts' order does not depend on when the lists were built).
#[test]
fn a_state_of_version_7_still_restores() {
    let scene = Scene::parse(BOX, Path::new("box.toml")).unwrap();
    let mut saved = Simulation::new(&scene);
    let _ = saved.advance_to(1e-3, |_, _| ControlFlow::<()>::Continue(()));
    let mut state = saved.snapshot();
    assert!(state.list.is_some());
    state.list = None;
    let mut w = StateWriter::default();
    state.write(3, &mut w);
    let mut bytes = w.into_bytes();
    assert_eq!(&bytes[..8], b"TALUSST8");
    assert_eq!(bytes.split_off(bytes.len() - 8), [0; 8], "no list: flag 0");
    // Nor each particle's cell code, the last of its 23 words (placed: a
    // simulation starts in the space order). Version 7 reads as version 8 with
    // every code `NO_CELL`: the reference.
    let count_at = 8 + 8 * 15;
    let word = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap());
    let n = word(count_at) as usize;
    assert_eq!(n, saved.world().particles.len());
    let first = count_at + 8;
    let (mut v7, mut uncoded) = (bytes[..first].to_vec(), bytes[..first].to_vec());
    for k in 0..n {
        let record = first + 8 * 23 * k;
        assert_ne!(word(record + 8 * 22), Particles::NO_CELL, "particle {k}");
        v7.extend_from_slice(&bytes[record..record + 8 * 22]);
        uncoded.extend_from_slice(&bytes[record..record + 8 * 22]);
        uncoded.extend_from_slice(&Particles::NO_CELL.to_le_bytes());
    }
    v7.extend_from_slice(&bytes[first + 8 * 23 * n..]);
    uncoded.extend_from_slice(&bytes[first + 8 * 23 * n..]);
    uncoded.extend_from_slice(&[0; 8]);
    v7[7] = b'7';
    let read = |bytes: &[u8]| {
        let mut sim = Simulation::new(&scene);
        sim.read_state(3, &mut StateReader::new(bytes)).unwrap();
        sim
    };
    let (mut restored, mut reference) = (read(&v7), read(&uncoded));
    assert_eq!(restored.snapshot().list, None);
    for sim in [&mut reference, &mut restored] {
        let _ = sim.advance_to(3e-3, |_, _| ControlFlow::<()>::Continue(()));
    }
    assert_eq!(
        reference.world().particles.position,
        restored.world().particles.position
    );
    assert_eq!(
        reference.world().particles.velocity,
        restored.world().particles.velocity
    );
}

/// A sphere removed while its friction spring against a wall is stretched lets the
/// spring go at the next step, as a contact that parts does: that step books the
/// spring's energy as dissipated, to the bit, and the wall history no longer holds
/// the patch.
#[test]
fn a_removed_particle_lets_its_wall_spring_go() {
    let text = r#"
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
[shapes.ball]
kind = "sphere"
radius = 0.005
[[wall]]
name = "floor"
material = "glass"
geometry = { kind = "plane", centre = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], size = 0.2 }
[[particles]]
kind = "list"
shape = "ball"
material = "glass"
bodies = [
    { position = [0.0, 0.0, 0.00499], velocity = [0.01, 0.0, 0.0] },
    { position = [0.05, 0.0, 0.05] },
]
"#;
    let scene = Scene::parse(text, Path::new("slide.toml")).unwrap();
    let mut sim = Simulation::new(&scene);
    let _ = sim.advance_to(2e-4, |_, _| ControlFlow::<()>::Continue(()));
    let sliding = sim.world().particles.id[0];
    let walls = sim.backend().contact_history().walls;
    assert_eq!(walls.len(), 1, "the sliding sphere's patch: {walls:?}");
    assert_eq!(walls[0].0.0, sliding);
    let spring = walls[0].1.spring_energy();
    assert!(spring > 0.0);

    assert_eq!(sim.remove_particles(|w, k| w.particles.id[k] == sliding), 1);
    sim.step();
    // The other sphere falls free: the only energy let go is the spring's.
    assert_eq!(sim.stats().contacts, 0);
    assert_eq!(sim.stats().dissipated, spring);
    assert!(sim.backend().contact_history().walls.is_empty());
}
