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

fn drum() -> Component {
    let mut c = Component::instantiate(
        Path::new(env!("CARGO_MANIFEST_DIR")),
        "examples/drum_fmu/drum.toml",
    )
    .unwrap();
    c.enter_initialization_mode(0.0).unwrap();
    c.exit_initialization_mode().unwrap();
    c
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

// zenoh needs tokio's multi-threaded runtime.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_client_steps_the_served_drum() {
    let port = 17300 + (std::process::id() % 90) as u16;
    let config = NodeConfig {
        key: "talus/rust-test".into(),
        listen: vec![format!("tcp/127.0.0.1:{port}")],
        connect: vec![],
        multicast: false,
    };
    let node = Node::start(Service::new(drum()), &config).unwrap();
    let client_config = NodeConfig {
        key: config.key.clone(),
        listen: vec![],
        connect: vec![format!("tcp/127.0.0.1:{port}")],
        multicast: false,
    };
    let session = zenoh::open(client_config.zenoh_config().unwrap())
        .await
        .unwrap();
    tokio::time::sleep(Duration::from_millis(500)).await;

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
