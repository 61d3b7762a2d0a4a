//! The zenoh node in-process: a client session steps the drum through `<key>/step`
//! and reads `<key>/info`; the replies match the component stepped directly.
#![cfg(feature = "zenoh")]

use std::path::Path;
use std::time::Duration;

use prost::Message;
use talus::cosim::Component;
use talus::transport::messages as pb;
use talus::transport::{Node, NodeConfig, Service};
use zenoh::Wait;

/// The component of `scene` (relative to the crate), initialised at time 0.
fn started(scene: &str) -> Component {
    let mut c = Component::instantiate(Path::new(env!("CARGO_MANIFEST_DIR")), scene).unwrap();
    c.enter_initialization_mode(0.0).unwrap();
    c.exit_initialization_mode().unwrap();
    c
}

fn drum() -> Component {
    started("examples/drum_fmu/drum.toml")
}

fn query<R: Message + Default>(session: &zenoh::Session, key: &str, payload: Vec<u8>) -> R {
    let replies = session
        .get(key)
        .payload(payload)
        .timeout(Duration::from_secs(60))
        .wait()
        .unwrap();
    let reply = replies.recv().expect("one reply");
    let sample = reply.result().expect("an ok reply");
    R::decode(&*sample.payload().to_bytes()).unwrap()
}

/// Serves `component` under `key` on a local port from `port_base` (by process, so
/// parallel test runs do not meet) and opens a client session to it.
async fn serve(component: Component, key: &str, port_base: u16) -> (Node, zenoh::Session) {
    let port = port_base + (std::process::id() % 90) as u16;
    let config = NodeConfig {
        key: key.into(),
        listen: vec![format!("tcp/127.0.0.1:{port}")],
        connect: vec![],
        multicast: false,
    };
    let node = Node::start(Service::new(component), &config).unwrap();
    let client_config = NodeConfig {
        key: key.into(),
        listen: vec![],
        connect: vec![format!("tcp/127.0.0.1:{port}")],
        multicast: false,
    };
    let session = zenoh::open(client_config.zenoh_config().unwrap())
        .await
        .unwrap();
    tokio::time::sleep(Duration::from_millis(500)).await;
    (node, session)
}

// zenoh needs tokio's multi-threaded runtime.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_client_steps_the_served_drum() {
    let (node, session) = serve(drum(), "talus/rust-test", 17300).await;

    let info: pb::InfoReply = query(&session, "talus/rust-test/info", Vec::new());
    assert_eq!(info.status, pb::Status::Ok as i32);
    assert_eq!(info.walls[0].name, "drum");

    let mut direct = drum();
    let spin = direct.variable("drum.angular_velocity").unwrap();
    let torque = direct.variable("drum.torque").unwrap();
    let request = pb::StepRequest {
        time: 0.0,
        step: 0.02,
        walls: vec![pb::WallMotion {
            wall: "drum".into(),
            motion: Some(pb::wall_motion::Motion::Velocity(pb::Velocity {
                linear: None,
                angular: Some(pb::Vec3 {
                    x: 0.0,
                    y: 3.0,
                    z: 0.0,
                }),
            })),
        }],
        fluid: None,
    };
    let reply: pb::StepReply = query(&session, "talus/rust-test/step", request.encode_to_vec());
    direct.set_real_vector(spin, &[0.0, 3.0, 0.0]).unwrap();
    direct.do_step(0.0, 0.02).unwrap();
    let expected = direct.get_real_vector(torque).unwrap();
    assert_eq!(reply.status, pb::Status::Ok as i32, "{}", reply.error);
    assert_eq!(reply.time, 0.02);
    let t = reply.walls[0].torque.unwrap();
    assert_eq!([t.x, t.y, t.z], [expected[0], expected[1], expected[2]]);

    // A malformed request gets an error reply; the node stays up.
    let bad: pb::StepReply = query(&session, "talus/rust-test/step", vec![0xff, 0xff, 0xff]);
    assert_eq!(bad.status, pb::Status::Error as i32);
    assert!(bad.error.contains("malformed"), "{}", bad.error);
    session.close().await.unwrap();
    let service = node.stop();
    assert_eq!(service.component().simulation().unwrap().world().time, 0.02);
}

fn fluid_column() -> Component {
    started("tests/scenes/fluid_column.toml")
}

/// The fluid over zenoh: a step carries the per-cell inputs, `<key>/fluid` answers
/// the fields, the same bits as the component driven directly; a request of the
/// wrong size is refused and changes nothing.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_client_exchanges_the_fluid_fields_with_the_served_column() {
    let (node, session) = serve(fluid_column(), "talus/fluid-test", 17400).await;

    let velocity: Vec<f64> = (0..54)
        .flat_map(|c| [0.01 * c as f64, -0.1, 2.5 - 0.02 * c as f64])
        .collect();
    let step = |velocity: Vec<f64>| pb::StepRequest {
        time: 0.0,
        step: 3e-4,
        walls: vec![],
        fluid: Some(pb::FluidInputs {
            velocity,
            pressure_gradient: vec![],
        }),
    };
    // The wrong size first: refused, the time and inputs unchanged.
    let refused: pb::StepReply = query(
        &session,
        "talus/fluid-test/step",
        step(velocity[..9].to_vec()).encode_to_vec(),
    );
    assert_eq!(refused.status, pb::Status::Error as i32);
    assert!(refused.error.contains("162"), "{}", refused.error);
    let before: pb::FluidReply = query(&session, "talus/fluid-test/fluid", Vec::new());
    assert_eq!(before.status, pb::Status::Ok as i32, "{}", before.error);
    assert_eq!(before.time, 0.0);
    assert!(before.velocity.chunks(3).all(|u| u == [0.0, 0.0, 2.0]));

    let reply: pb::StepReply = query(
        &session,
        "talus/fluid-test/step",
        step(velocity.clone()).encode_to_vec(),
    );
    assert_eq!(reply.status, pb::Status::Ok as i32, "{}", reply.error);
    let fields: pb::FluidReply = query(&session, "talus/fluid-test/fluid", Vec::new());

    let mut direct = fluid_column();
    let var = direct.variable("fluid.velocity").unwrap();
    direct.set_real_vector(var, &velocity).unwrap();
    direct.do_step(0.0, 3e-4).unwrap();
    let read = |name: &str| {
        direct
            .get_real_vector(direct.variable(name).unwrap())
            .unwrap()
    };
    let grid = fields.grid.as_ref().unwrap();
    assert_eq!(grid.counts, [3, 3, 6]);
    assert_eq!(grid.cell.unwrap().z, 0.01);
    // Every kind of cells comes with centres and volumes: cell [1, 2, 3].
    assert_eq!((grid.kind.as_str(), grid.volumes.len()), ("cartesian", 54));
    let k = 1 + 3 * (2 + 3 * 3);
    assert_eq!(&grid.centres[3 * k..3 * k + 3], &[0.015, 0.025, 0.035]);
    assert!((grid.volumes[k] - 1e-6).abs() < 1e-20);
    assert_eq!(fields.velocity, velocity);
    assert_eq!(fields.momentum_source, read("fluid.momentum_source"));
    assert_eq!(fields.solid_fraction, read("fluid.solid_fraction"));
    assert_eq!(fields.particle_velocity, read("fluid.particle_velocity"));
    assert!(fields.momentum_source.iter().any(|&f| f != 0.0));
    session.close().await.unwrap();
    node.stop();
}
