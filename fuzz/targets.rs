//! The bodies of the fuzz targets, shared by the coverage-guided `cargo fuzz` targets
//! (`fuzz/fuzz_targets/`, nightly) and the bounded mutation run of every CI build
//! (`tests/fuzz_smoke.rs`, stable). Each takes arbitrary bytes and must end in an
//! answer (a result, or an error that says what is wrong) without a panic, a hang or
//! an allocation the bytes do not justify; where a call is refused, what a user can
//! observe must be as it was before the call.
//!
//! Only talus's public API is used: the targets see what a user's file, a master's
//! call or a network peer's message can reach.

#![allow(dead_code)]

use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use talus::checkpoint::Checkpoint;
use talus::cosim::{Component, Mode, VarRef};
use talus::geometry::mesh_io::{parse_obj, parse_stl};
use talus::geometry::{ConvexPolyhedron, convex_hull};
use talus::scene::{Scene, SimState, StateReader, StateWriter};

/// A small scene for the targets that need a running one: three spheres in a box
/// driven from outside, a plane driven by pose, a step of 0.1 ms.
pub const TINY_SCENE: &str = r#"
[simulation]
dt = 1e-4
end_time = 1.0
gravity = [0.0, 0.0, -9.81]

[materials.m]
density = 1000.0
young = 1e5
poisson = 0.3
restitution = 0.5
friction = 0.4

[shapes.ball]
kind = "sphere"
radius = 0.01

[shapes.cube]
kind = "cuboid"
size = [0.015, 0.015, 0.015]

[[wall]]
name = "box"
material = "m"
geometry = { kind = "box", min = [0.0, 0.0, 0.0], max = [0.1, 0.1, 0.1], open_top = true }
motion = { kind = "external", input = "velocity" }

[[wall]]
name = "lid"
material = "m"
geometry = { kind = "plane", centre = [0.05, 0.05, 0.09], normal = [0.0, 0.0, -1.0], size = 0.1 }
motion = { kind = "external", input = "pose" }

[[particles]]
kind = "list"
shape = "ball"
material = "m"
bodies = [
  { position = [0.03, 0.05, 0.011] },
  { position = [0.05, 0.05, 0.011], velocity = [0.1, 0.0, 0.0] },
]

[[particles]]
kind = "list"
shape = "cube"
material = "m"
bodies = [{ position = [0.07, 0.05, 0.03] }]
"#;

/// A directory holding `tiny.toml` (and where outputs of a target may go).
pub fn workspace() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("talus-fuzz-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a temporary directory");
        std::fs::write(dir.join("tiny.toml"), TINY_SCENE).expect("the tiny scene");
        dir
    })
}

fn tiny() -> Component {
    Component::instantiate(workspace(), "tiny.toml").expect("the tiny scene loads")
}

fn started() -> Component {
    let mut c = tiny();
    c.enter_initialization_mode(0.0).expect("initialises");
    c.exit_initialization_mode().expect("starts");
    c
}

/// Bytes read as a sequence of choices; past the end, zeros.
struct Choices<'a> {
    data: &'a [u8],
}

impl Choices<'_> {
    fn byte(&mut self) -> u8 {
        match self.data.split_first() {
            Some((b, rest)) => {
                self.data = rest;
                *b
            }
            None => 0,
        }
    }

    fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// A number: one of the values that break code (NaN, infinities, zeros, the
    /// extremes, negative), an everyday one, or eight raw bytes.
    fn number(&mut self, everyday: &[f64]) -> f64 {
        const SPECIAL: [f64; 12] = [
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            0.0,
            -0.0,
            -1.0,
            1e-300,
            -1e-300,
            1e300,
            f64::MIN_POSITIVE,
            f64::MAX,
            f64::EPSILON,
        ];
        match self.byte() % 4 {
            0 => SPECIAL[self.byte() as usize % SPECIAL.len()],
            1 => {
                let mut b = [0u8; 8];
                b.iter_mut().for_each(|x| *x = self.byte());
                f64::from_le_bytes(b)
            }
            _ if !everyday.is_empty() => everyday[self.byte() as usize % everyday.len()],
            _ => 1.0,
        }
    }
}

/// A scene file: a scene or a located error, and for a scene its plan and
/// fingerprint.
pub fn scene_toml(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    match Scene::parse(text, &workspace().join("fuzz.toml")) {
        Ok(scene) => {
            assert!(scene.dt.is_finite() && scene.dt > 0.0, "dt {}", scene.dt);
            let _ = scene.plan.to_string();
            let _ = scene.fingerprint();
        }
        Err(e) => assert!(!e.to_string().is_empty()),
    }
}

/// A mesh read from a file, then made a particle template as `talus inspect` does
/// (the mesh itself, and the hull of its vertices).
fn mesh_to_template(mesh: &talus::geometry::TriMesh) {
    let _ = ConvexPolyhedron::from_convex_mesh(mesh);
    if let Ok(hull) = convex_hull(&mesh.vertices) {
        let _ = ConvexPolyhedron::from_convex_mesh(&hull);
    }
}

/// STL bytes, ASCII or binary.
pub fn stl(data: &[u8]) {
    match parse_stl(data, Path::new("fuzz.stl")) {
        Ok(mesh) => mesh_to_template(&mesh),
        Err(e) => assert!(e.to_string().contains("fuzz.stl"), "{e}"),
    }
}

/// OBJ text.
pub fn obj(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    match parse_obj(&text, Path::new("fuzz.obj")) {
        Ok(mesh) => mesh_to_template(&mesh),
        Err(e) => assert!(e.to_string().contains("fuzz.obj"), "{e}"),
    }
}

/// A particle file of a scene (`kind = "file"`: `x,y,z,qw,qx,qy,qz[,vx…]`).
pub fn particle_csv(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    if let Ok(poses) = talus::scene::poses::parse_poses(&text) {
        for p in poses {
            assert!(p.position.coords.iter().all(|x| x.is_finite()));
            assert!((p.orientation.norm() - 1.0).abs() < 1e-9);
        }
    }
}

/// A run's `poses.csv`, read back by `talus analyze`.
pub fn poses_csv(data: &[u8]) {
    static WORLD: OnceLock<talus::world::World> = OnceLock::new();
    let world = WORLD.get_or_init(|| {
        Scene::parse(TINY_SCENE, &workspace().join("tiny.toml"))
            .expect("the tiny scene")
            .world
    });
    let mut world = world.clone();
    let text = String::from_utf8_lossy(data);
    if talus::output::packing::parse_poses(&text, Path::new("poses.csv"), &mut world).is_ok() {
        let p = &world.particles;
        for i in 0..p.len() {
            assert!((p.body_type[i] as usize) < world.body_types.len());
            assert!(p.position[i].coords.iter().all(|x| x.is_finite()));
        }
    }
}

/// `bytes` with a correct CRC-32 appended: mutated bodies then reach the parser
/// behind the checksum.
fn with_checksum(bytes: &[u8]) -> Vec<u8> {
    let mut v = bytes.to_vec();
    v.extend_from_slice(&talus::checksum::crc32(bytes).to_le_bytes());
    v
}

/// Saved-state bytes (FMI serialised states, the zenoh `state` queryable, the C
/// API) and checkpoints: refused, or restored and stepped on; refused bytes leave
/// the component as it was.
pub fn state_bytes(data: &[u8]) {
    thread_local! {
        static COMPONENT: RefCell<Option<(Component, talus::cosim::ComponentState)>> =
            const { RefCell::new(None) };
    }
    COMPONENT.with(|cell| {
        let mut cell = cell.borrow_mut();
        let (c, clean) = cell.get_or_insert_with(|| {
            let mut c = started();
            c.do_step(0.0, 2e-3).expect("a step");
            let s = c.save_state().expect("a state");
            (c, s)
        });
        let fixed = with_checksum(data);
        for bytes in [data, &fixed[..]] {
            let before = observe(c);
            match c.state_from_bytes(bytes) {
                Ok(state) => {
                    c.restore_state(&state)
                        .expect("a state that was read restores");
                    let sim = c.simulation().expect("running");
                    let (t, dt) = (sim.time(), sim.dt());
                    // A state's own tiny step makes a long (legitimate) step: not here.
                    if 3e-4 / dt <= 100.0 {
                        let _ = c.do_step(t, 3e-4);
                    }
                    c.restore_state(clean).expect("back to the clean state");
                }
                Err(_) => assert_eq!(observe(c), before, "a refused state changed the component"),
            }
        }
        // The simulation's state alone (no checksum in front of the parser).
        let fingerprint = c.fingerprint();
        if let Ok(state) = SimState::read(fingerprint, &mut StateReader::new(data)) {
            let mut w = StateWriter::default();
            state.write(fingerprint, &mut w);
            let again = SimState::read(fingerprint, &mut StateReader::new(&w.into_bytes()));
            assert!(again.is_ok(), "a state read and written reads again");
        }
        // A checkpoint, with and without its checksum fixed.
        for bytes in [data, &fixed[..]] {
            let _ = Checkpoint::scene_of(bytes);
            let _ = Checkpoint::from_bytes(bytes, fingerprint);
        }
    });
}

/// All that a master can observe: the mode, and every readable real and string.
fn observe(c: &Component) -> (Mode, Vec<u64>, Vec<String>) {
    let mut reals = Vec::new();
    let mut strings = Vec::new();
    for (k, v) in c.variables().iter().enumerate() {
        if let Ok(x) = c.get_real_vector(k) {
            reals.extend(x.iter().map(|x| x.to_bits()));
        }
        let refs: Vec<VarRef> = (0..v.size.max(1))
            .map(|element| VarRef { var: k, element })
            .collect();
        if let Ok(s) = c.get_string(&refs) {
            strings.extend(s);
        }
    }
    (c.mode(), reals, strings)
}

/// A sequence of Component calls, in any order, with any values (NaN, infinities,
/// zero and negative steps, unknown variables): every refused call leaves what the
/// master observes as it was.
pub fn component_calls(data: &[u8]) {
    let mut c = tiny();
    let mut ch = Choices { data };
    let mut saved = Vec::new();
    let mut bytes = Vec::new();
    let n = c.variables().len();
    for _ in 0..64 {
        if ch.is_empty() {
            break;
        }
        let now = c.simulation().map_or(0.0, |s| s.time());
        let before = observe(&c);
        // Each call and whether a refusal must leave the component unchanged (a
        // refused step, for instance; `fail` and `reset` are not refusals).
        let refused = match ch.byte() % 16 {
            0 => c.enter_initialization_mode(ch.number(&[0.0, 1.0])).is_err(),
            1 => c.exit_initialization_mode().is_err(),
            2..=4 => {
                let t = ch.number(&[now, now + 1e-12, now - 1e-12, now + 1.0]);
                let h = ch.number(&[1e-4, 3e-4, 1e-3, 2.5e-5, 1e-13]);
                // A valid step of more than 100 DEM steps is legitimate but slow.
                if h.is_finite() && h > 1e-2 {
                    false
                } else {
                    let refused = c.do_step(t, h).is_err();
                    // A step never takes the clock back.
                    if let Some(sim) = c.simulation() {
                        assert!(sim.time() >= now, "time went back from {now}");
                    }
                    refused
                }
            }
            5 => c.terminate().is_err(),
            6 => {
                c.reset();
                false
            }
            7..=8 => {
                let var = ch.byte() as usize % (n + 2);
                let len = ch.byte() as usize % 8;
                let values: Vec<f64> = (0..len)
                    .map(|_| ch.number(&[0.0, 1.0, 0.5, 1e-4, 2e-4, 1e-3, 4.0]))
                    .collect();
                c.set_real_vector(var, &values).is_err()
            }
            9 => {
                let refs: Vec<VarRef> = (0..ch.byte() % 4)
                    .map(|_| VarRef {
                        var: ch.byte() as usize % (n + 2),
                        element: ch.byte() as usize % 5,
                    })
                    .collect();
                let values: Vec<f64> = refs.iter().map(|_| ch.number(&[0.0, 1.0])).collect();
                c.set_real(&refs, &values).is_err()
            }
            10 => {
                let var = ch.byte() as usize % (n + 2);
                let value = ["", "tiny.toml", "missing.toml", "out", "../x", "\u{0}"]
                    [ch.byte() as usize % 6];
                let refs = [VarRef { var, element: 0 }];
                // A new scene or output directory: only the menu above, inside the
                // workspace.
                c.set_string(&refs, &[value]).is_err()
            }
            11 => {
                let refs = [VarRef {
                    var: ch.byte() as usize % (n + 2),
                    element: ch.byte() as usize % 5,
                }];
                let values = [ch.byte() as i64 - 64];
                c.set_integer(&refs, &values).is_err()
            }
            12 => match c.save_state() {
                Ok(s) => {
                    bytes = c.state_to_bytes(&s);
                    saved.push(s);
                    false
                }
                Err(_) => true,
            },
            13 => match saved.get(ch.byte() as usize % (saved.len() + 1)) {
                Some(s) => c.restore_state(s).is_err(),
                None => false,
            },
            14 => {
                let mut b = bytes.clone();
                if !b.is_empty() && ch.byte() % 2 == 0 {
                    let at = ch.byte() as usize % b.len();
                    b[at] ^= ch.byte() | 1;
                }
                match c.state_from_bytes(&b) {
                    Ok(s) => c.restore_state(&s).is_err(),
                    Err(_) => true,
                }
            }
            _ => {
                let _ = c.wall_mesh(ch.byte() as usize % 3);
                let _ = c.get_real_vector(ch.byte() as usize % (n + 2));
                false
            }
        };
        if refused && c.mode() != Mode::Error {
            assert_eq!(observe(&c), before, "a refused call changed the component");
        }
    }
}

/// The zenoh service's protobuf messages, each queryable with any payload (the
/// life-cycle calls of `<key>/call` too): an answer with a status, and a refused
/// request leaves the component as it was.
#[cfg(feature = "zenoh")]
pub fn zenoh_messages(data: &[u8]) {
    use prost::Message;
    use talus::transport::Service;
    use talus::transport::messages as pb;
    thread_local! {
        static SERVICE: RefCell<Option<Service>> = const { RefCell::new(None) };
    }
    SERVICE.with(|cell| {
        let mut cell = cell.borrow_mut();
        let service = cell.get_or_insert_with(|| Service::new(started()));
        let Some((which, payload)) = data.split_first() else {
            return;
        };
        let before = observe(service.component());
        let ok = pb::Status::Ok as i32;
        let refused = match which % 7 {
            0 => {
                // A valid step of more than 100 DEM steps is legitimate but slow.
                if let Ok(request) = pb::StepRequest::decode(payload)
                    && request.step.is_finite()
                    && request.step > 1e-2
                {
                    return;
                }
                service.step(payload).status != ok
            }
            1 => service.walls(payload).status != ok,
            2 => service.info(payload).status != ok,
            3 => service.state(payload).status != ok,
            5 => service.fluid(payload).status != ok,
            6 => {
                use pb::call_request::Call;
                if let Ok(pb::CallRequest {
                    call: Some(Call::DoStep(s)),
                }) = pb::CallRequest::decode(payload)
                    && s.step.is_finite()
                    && s.step > 1e-2
                {
                    return;
                }
                service.call(payload).status != ok
            }
            _ => service.forces().is_err(),
        };
        if refused {
            assert_eq!(
                observe(service.component()),
                before,
                "a refused request changed the component"
            );
        }
    });
}

/// Seeds made by talus itself for the targets whose inputs are binary: a saved
/// state of the tiny scene (with and without its checksum), call sequences that
/// walk the life cycle, and one message for each zenoh queryable.
pub fn seeds(target: &str) -> Vec<Vec<u8>> {
    match target {
        "state_bytes" => {
            let mut c = started();
            c.do_step(0.0, 2e-3).expect("a step");
            let bytes = c.state_to_bytes(&c.save_state().expect("a state"));
            vec![bytes[..bytes.len() - 4].to_vec(), bytes]
        }
        "component_calls" => vec![
            // enter(0), exit, step(now, 1e-4) ×2, save, step, restore, terminate
            vec![
                0, 2, 0, 1, 2, 2, 0, 2, 0, 3, 2, 0, 2, 0, 12, 4, 2, 0, 2, 1, 13, 0, 5,
            ],
            // enter, exit, set a drive, step, bytes of a saved state back, reset
            vec![
                0, 2, 0, 1, 7, 5, 3, 2, 1, 2, 2, 2, 0, 2, 2, 12, 14, 1, 6, 0, 2, 0,
            ],
            // steps with special values
            vec![0, 2, 0, 1, 2, 0, 0, 0, 1, 2, 0, 3, 0, 5, 3, 2, 0, 0, 6],
        ],
        #[cfg(feature = "zenoh")]
        "zenoh_messages" => {
            use prost::Message;
            use talus::transport::messages as pb;
            let v = |x, y, z| Some(pb::Vec3 { x, y, z });
            let step = pb::StepRequest {
                time: 0.0,
                step: 1e-3,
                walls: vec![
                    pb::WallMotion {
                        wall: "box".into(),
                        motion: Some(pb::wall_motion::Motion::Velocity(pb::Velocity {
                            linear: v(0.0, 0.0, 0.01),
                            angular: v(0.0, 0.0, 0.0),
                        })),
                    },
                    pb::WallMotion {
                        wall: "lid".into(),
                        motion: Some(pb::wall_motion::Motion::Pose(pb::Pose {
                            position: v(0.05, 0.05, 0.08),
                            orientation: Some(pb::Quaternion {
                                w: 1.0,
                                x: 0.0,
                                y: 0.0,
                                z: 0.0,
                            }),
                        })),
                    },
                ],
                fluid: None,
            };
            let walls = pb::WallsRequest {
                walls: vec!["box".into(), "lid".into()],
                facet_forces: true,
            };
            let save = pb::StateRequest {
                action: Some(pb::state_request::Action::Save(true)),
            };
            let mut c = started();
            c.do_step(0.0, 1e-3).expect("a step");
            let restore = pb::StateRequest {
                action: Some(pb::state_request::Action::Restore(
                    c.state_to_bytes(&c.save_state().expect("a state")),
                )),
            };
            let tagged = |tag: u8, body: Vec<u8>| [vec![tag], body].concat();
            use pb::call_request::Call;
            let call = |call| pb::CallRequest { call: Some(call) }.encode_to_vec();
            vec![
                tagged(0, step.encode_to_vec()),
                tagged(1, walls.encode_to_vec()),
                tagged(2, pb::InfoRequest {}.encode_to_vec()),
                tagged(3, save.encode_to_vec()),
                tagged(3, restore.encode_to_vec()),
                vec![4],
                tagged(
                    6,
                    call(Call::GetReal(pb::VarRefs {
                        refs: vec![pb::VarRef {
                            variable: 0,
                            element: 0,
                        }],
                    })),
                ),
                tagged(
                    6,
                    call(Call::DoStep(pb::DoStep {
                        time: 1e-3,
                        step: 1e-3,
                    })),
                ),
                tagged(6, call(Call::Terminate(true))),
                tagged(6, call(Call::Reset(true))),
                tagged(
                    6,
                    call(Call::SetReal(pb::SetReals {
                        refs: vec![pb::VarRef {
                            variable: 1,
                            element: 0,
                        }],
                        values: vec![1e-5],
                    })),
                ),
                tagged(6, call(Call::EnterInitialization(0.0))),
            ]
        }
        _ => Vec::new(),
    }
}
