//! The zenoh node: a [`Service`] on a zenoh session.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use prost::Message;
use thiserror::Error;
use zenoh::Wait;

use super::Service;

/// Why a node could not start.
#[derive(Debug, Error)]
pub enum TransportError {
    /// A zenoh configuration value or session failure.
    #[error("zenoh: {0}")]
    Zenoh(String),
}

fn zenoh_error(e: impl std::fmt::Display) -> TransportError {
    TransportError::Zenoh(e.to_string())
}

/// Where and how the node talks.
#[derive(Clone, Debug)]
pub struct NodeConfig {
    /// Key prefix, e.g. `talus/drum`.
    pub key: String,
    /// Endpoints to listen on, e.g. `tcp/127.0.0.1:7447`.
    pub listen: Vec<String>,
    /// Endpoints to connect to.
    pub connect: Vec<String>,
    /// Multicast scouting (off unless asked for).
    pub multicast: bool,
}

impl NodeConfig {
    /// The zenoh configuration: peer mode, the endpoints, scouting as asked.
    pub fn zenoh_config(&self) -> Result<zenoh::Config, TransportError> {
        let mut config = zenoh::Config::default();
        let list = |v: &[String]| serde_json::to_string(v).expect("strings serialise");
        config
            .insert_json5("mode", "\"peer\"")
            .map_err(zenoh_error)?;
        config
            .insert_json5(
                "scouting/multicast/enabled",
                if self.multicast { "true" } else { "false" },
            )
            .map_err(zenoh_error)?;
        if !self.listen.is_empty() {
            config
                .insert_json5("listen/endpoints", &list(&self.listen))
                .map_err(zenoh_error)?;
        }
        if !self.connect.is_empty() {
            config
                .insert_json5("connect/endpoints", &list(&self.connect))
                .map_err(zenoh_error)?;
        }
        Ok(config)
    }
}

/// A running node. Dropping it without [`Node::stop`] also stops it.
pub struct Node {
    session: Option<zenoh::Session>,
    token: Option<zenoh::liveliness::LivelinessToken>,
    service: Option<Arc<Mutex<Service>>>,
    stop: Arc<AtomicBool>,
    workers: Vec<JoinHandle<()>>,
}

/// How long a worker waits for a query before it looks at the stop flag.
const POLL: Duration = Duration::from_millis(50);

impl Node {
    /// Opens the session and declares the queryables, the publisher and the token.
    pub fn start(service: Service, config: &NodeConfig) -> Result<Node, TransportError> {
        let session = zenoh::open(config.zenoh_config()?)
            .wait()
            .map_err(zenoh_error)?;
        let service = Arc::new(Mutex::new(service));
        let stop = Arc::new(AtomicBool::new(false));
        let key = config.key.trim_end_matches('/').to_string();
        let publisher = session
            .declare_publisher(format!("{key}/forces"))
            .wait()
            .map_err(zenoh_error)?;
        let token = session
            .liveliness()
            .declare_token(key.clone())
            .wait()
            .map_err(zenoh_error)?;
        let publisher = Arc::new(publisher);

        let mut workers = Vec::new();
        for endpoint in ["step", "walls", "info", "state", "fluid", "call"] {
            let queryable = session
                .declare_queryable(format!("{key}/{endpoint}"))
                .wait()
                .map_err(zenoh_error)?;
            let service = Arc::clone(&service);
            let stop = Arc::clone(&stop);
            let publisher = Arc::clone(&publisher);
            let worker = std::thread::Builder::new()
                .name(format!("talus-zenoh-{endpoint}"))
                .spawn(move || {
                    while !stop.load(Ordering::Relaxed) {
                        let query = match queryable.recv_timeout(POLL) {
                            Ok(Some(query)) => query,
                            Ok(None) => continue,
                            Err(_) => break,
                        };
                        let payload = query
                            .payload()
                            .map(|p| p.to_bytes().into_owned())
                            .unwrap_or_default();
                        let mut service = service.lock().unwrap_or_else(|p| p.into_inner());
                        let reply = match endpoint {
                            "step" => {
                                let reply = service.step(&payload);
                                let bytes = reply.encode_to_vec();
                                if reply.status == super::messages::Status::Ok as i32 {
                                    // Published under the lock: subscribers see steps in order.
                                    let _ = publisher.put(bytes.clone()).wait();
                                }
                                bytes
                            }
                            "walls" => service.walls(&payload).encode_to_vec(),
                            "info" => service.info(&payload).encode_to_vec(),
                            "fluid" => service.fluid(&payload).encode_to_vec(),
                            "call" => service.call(&payload).encode_to_vec(),
                            _ => service.state(&payload).encode_to_vec(),
                        };
                        drop(service);
                        // A client that went away simply gets nothing.
                        let _ = query.reply(query.key_expr().clone(), reply).wait();
                    }
                    drop(queryable);
                })
                .map_err(zenoh_error)?;
            workers.push(worker);
        }
        Ok(Node {
            session: Some(session),
            token: Some(token),
            service: Some(service),
            stop,
            workers,
        })
    }

    /// Stops serving: workers joined, session closed. Returns the service (to
    /// terminate the component and write its outputs).
    pub fn stop(mut self) -> Service {
        self.shutdown();
        let service = self
            .service
            .take()
            .expect("a node has its service until stopped");
        match Arc::try_unwrap(service) {
            Ok(m) => m.into_inner().unwrap_or_else(|p| p.into_inner()),
            Err(_) => unreachable!("the workers holding the service are joined"),
        }
    }

    fn shutdown(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        for w in self.workers.drain(..) {
            let _ = w.join();
        }
        if let Some(token) = self.token.take() {
            let _ = token.undeclare().wait();
        }
        if let Some(session) = self.session.take() {
            let _ = session.close().wait();
        }
    }
}

impl Drop for Node {
    fn drop(&mut self) {
        self.shutdown();
    }
}
