//! The zenoh transport: a scene served as a zenoh node with protobuf messages
//! (`proto/talus/v1/talus.proto`), stepped by an orchestrator anywhere on the
//! network.
//!
//! [`Service`] translates messages to [`crate::cosim::Component`] calls and back; it
//! has no logic of its own and no network. [`Node`] puts a service on a zenoh
//! session: queryables `<key>/step`, `<key>/walls`, `<key>/info`, `<key>/state`, a
//! publisher `<key>/forces` that puts every step reply, and a liveliness token
//! `<key>` by which orchestrators discover running instances.
//!
//! One request is served at a time: the service sits behind a mutex, and a request
//! that arrives during a step waits for it to finish (queries are not dropped; a
//! client whose query times out meanwhile simply gets no reply). A bad request gets a
//! reply with `STATUS_ERROR` and the reason, and changes nothing.

pub mod messages {
    //! Types generated from `proto/talus/v1/talus.proto`.
    #![allow(missing_docs, clippy::all)]
    include!(concat!(env!("OUT_DIR"), "/talus.v1.rs"));
}
mod call;
mod node;
mod ranks;
mod service;

pub use node::{Node, NodeConfig, TransportError};
pub use service::Service;
