//! A proxy FMU's instance (feature `zenoh`): the FMU of `talus fmu --remote KEY`
//! holds the scene (for its variable table and guid) and `remote.toml`; each FMI
//! call goes as one `CallRequest` to the `<key>/call` queryable of a `talus serve`
//! node, which may run on a cluster under `mpirun`. The node's component checks
//! the call as a local one would; its error comes back as the FMI error's message.
//!
//! No call waits longer than the spec's timeout: a node that is gone, unreachable
//! or slower than that is an FMI error with a logged message.

use std::path::Path;
use std::time::{Duration, Instant};

use prost::Message;
use zenoh::Wait;

use super::SCENE_FILE;
use super::remote_spec::{REMOTE_FILE, RemoteSpec};
use super::slave::{FmuState, Slave};
use crate::cosim::{Mode, VarRef, Variable, fingerprint, variable_table};
use crate::scene::Scene;
use crate::scene::state_bytes::starts_as_state;
use crate::transport::NodeConfig;
use crate::transport::messages::{self as pb, call_request::Call as Request};

/// How long each try to reach a node that is not answering yet waits, when the
/// instance is created.
const FIRST_CONTACT_TRY: Duration = Duration::from_millis(500);

/// The node side of one FMU instance.
pub(crate) struct Remote {
    session: Option<zenoh::Session>,
    spec: RemoteSpec,
    variables: Vec<Variable>,
    fingerprint: u64,
    /// The node's mode after the last call.
    mode: Mode,
    /// The node's time after the last call.
    time: f64,
    /// The node's warnings at the last initialisation.
    warnings: Vec<String>,
}

fn mode_of(name: &str) -> Mode {
    match name {
        "instantiated" => Mode::Instantiated,
        "initialisation" => Mode::Initialisation,
        "step" => Mode::Step,
        "terminated" => Mode::Terminated,
        _ => Mode::Error,
    }
}

impl Remote {
    /// Reads the spec and the scene from `resources`, reaches the node (within the
    /// timeout), checks that it serves the same scene and resets it.
    pub(crate) fn connect(resources: &Path) -> Result<Remote, String> {
        let spec_path = resources.join(REMOTE_FILE);
        let text = std::fs::read_to_string(&spec_path)
            .map_err(|e| format!("{}: {e}", spec_path.display()))?;
        let spec = RemoteSpec::from_toml(&text)?;
        let scene = Scene::load(&resources.join(SCENE_FILE)).map_err(|e| e.to_string())?;
        let config = NodeConfig {
            key: spec.key.clone(),
            listen: Vec::new(),
            connect: spec.connect.clone(),
            multicast: spec.connect.is_empty(),
        };
        let session = zenoh::open(config.zenoh_config().map_err(|e| e.to_string())?)
            .wait()
            .map_err(|e| format!("zenoh: {e}"))?;
        let mut remote = Remote {
            session: Some(session),
            variables: variable_table(&scene),
            fingerprint: fingerprint(&scene),
            spec,
            mode: Mode::Error,
            time: 0.0,
            warnings: Vec::new(),
        };
        let info = remote.first_contact()?;
        if info.fingerprint != remote.fingerprint {
            return Err(format!(
                "the node '{}' serves another scene or talus version ({} {}, fingerprint \
                 {:016x}; this FMU's is {:016x})",
                remote.spec.key,
                info.scene,
                info.talus_version,
                info.fingerprint,
                remote.fingerprint
            ));
        }
        remote.call(Request::Reset(true))?;
        Ok(remote)
    }

    /// The node's info, asked again until it answers or the timeout has passed (a
    /// session needs a moment to find its peers).
    fn first_contact(&self) -> Result<pb::InfoReply, String> {
        let deadline = Instant::now() + self.timeout();
        loop {
            let wait = FIRST_CONTACT_TRY.min(deadline.saturating_duration_since(Instant::now()));
            match self.ask("info", Vec::new(), wait) {
                Ok(bytes) => {
                    return pb::InfoReply::decode(&bytes[..])
                        .map_err(|e| format!("the node's info does not decode: {e}"));
                }
                Err(e) if Instant::now() >= deadline => return Err(e),
                Err(_) => std::thread::sleep(Duration::from_millis(50)),
            }
        }
    }

    fn timeout(&self) -> Duration {
        Duration::from_secs_f64(self.spec.timeout)
    }

    /// The payload of the node's one reply to `payload` on `<key>/<endpoint>`.
    fn ask(&self, endpoint: &str, payload: Vec<u8>, wait: Duration) -> Result<Vec<u8>, String> {
        let key = format!("{}/{endpoint}", self.spec.key.trim_end_matches('/'));
        let session = self.session.as_ref().expect("open until dropped");
        let replies = session
            .get(&key)
            .payload(payload)
            .timeout(wait)
            .wait()
            .map_err(|e| format!("zenoh: {e}"))?;
        match replies.recv() {
            Ok(reply) => match reply.result() {
                Ok(sample) => Ok(sample.payload().to_bytes().into_owned()),
                Err(e) => Err(format!("the node '{key}' answered with an error: {e:?}")),
            },
            Err(_) => Err(format!(
                "no answer from the talus node at '{key}' within {:.3} s (is `talus serve \
                 --key {}` running and reachable?)",
                wait.as_secs_f64(),
                self.spec.key
            )),
        }
    }

    /// Makes `request` on the node; the reply of a call it accepted.
    fn send(&self, request: Request) -> Result<pb::CallReply, String> {
        let payload = pb::CallRequest {
            call: Some(request),
        }
        .encode_to_vec();
        let bytes = self.ask("call", payload, self.timeout())?;
        pb::CallReply::decode(&bytes[..])
            .map_err(|e| format!("the node's reply does not decode: {e}"))
    }

    /// [`Remote::send`] of a call that changes the node: its mode and time kept.
    fn call(&mut self, request: Request) -> Result<pb::CallReply, String> {
        let reply = self.send(request)?;
        self.mode = mode_of(&reply.mode);
        self.time = reply.time;
        accepted(reply)
    }
}

fn accepted(reply: pb::CallReply) -> Result<pb::CallReply, String> {
    if reply.status == pb::Status::Ok as i32 {
        Ok(reply)
    } else {
        Err(reply.error)
    }
}

fn refs(refs: &[VarRef]) -> Vec<pb::VarRef> {
    refs.iter()
        .map(|r| pb::VarRef {
            variable: r.var as u32,
            element: r.element as u32,
        })
        .collect()
}

fn vars(r: &[VarRef]) -> pb::VarRefs {
    pb::VarRefs { refs: refs(r) }
}

fn copy<T: Copy>(got: &[T], out: &mut [T]) -> Result<(), String> {
    if got.len() != out.len() {
        return Err(format!(
            "the node sent {} values for {}",
            got.len(),
            out.len()
        ));
    }
    out.copy_from_slice(got);
    Ok(())
}

impl Slave for Remote {
    fn variables(&self) -> &[Variable] {
        &self.variables
    }

    fn fingerprint(&self) -> u64 {
        self.fingerprint
    }

    fn mode(&self) -> Mode {
        self.mode
    }

    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    fn time(&self) -> Option<f64> {
        (self.mode != Mode::Instantiated).then_some(self.time)
    }

    fn fail(&mut self) {
        self.mode = Mode::Error;
    }

    fn enter_initialization_mode(&mut self, start_time: f64) -> Result<(), String> {
        let reply = self.call(Request::EnterInitialization(start_time))?;
        self.warnings = reply.warnings;
        Ok(())
    }

    fn exit_initialization_mode(&mut self) -> Result<(), String> {
        self.call(Request::ExitInitialization(true)).map(drop)
    }

    fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        self.call(Request::DoStep(pb::DoStep { time: t, step: h }))
            .map(drop)
    }

    fn terminate(&mut self) -> Result<(), String> {
        self.call(Request::Terminate(true)).map(drop)
    }

    fn reset(&mut self) -> Result<(), String> {
        self.call(Request::Reset(true)).map(drop)
    }

    fn get_real(&self, r: &[VarRef], out: &mut [f64]) -> Result<(), String> {
        let reply = accepted(self.send(Request::GetReal(vars(r)))?)?;
        copy(&reply.reals, out)
    }

    fn set_real(&mut self, r: &[VarRef], values: &[f64]) -> Result<(), String> {
        let values = values.to_vec();
        self.call(Request::SetReal(pb::SetReals {
            refs: refs(r),
            values,
        }))
        .map(drop)
    }

    fn get_integer(&self, r: &[VarRef], out: &mut [i64]) -> Result<(), String> {
        let reply = accepted(self.send(Request::GetInteger(vars(r)))?)?;
        copy(&reply.integers, out)
    }

    fn set_integer(&mut self, r: &[VarRef], values: &[i64]) -> Result<(), String> {
        let values = values.to_vec();
        self.call(Request::SetInteger(pb::SetIntegers {
            refs: refs(r),
            values,
        }))
        .map(drop)
    }

    fn get_string(&self, r: &[VarRef]) -> Result<Vec<String>, String> {
        let reply = accepted(self.send(Request::GetString(vars(r)))?)?;
        if reply.strings.len() != r.len() {
            return Err(format!(
                "the node sent {} strings for {}",
                reply.strings.len(),
                r.len()
            ));
        }
        Ok(reply.strings)
    }

    fn set_string(&mut self, r: &[VarRef], values: &[&str]) -> Result<(), String> {
        if let Some(k) = r
            .iter()
            .position(|r| self.variables.get(r.var).is_some_and(|v| v.name == "scene"))
        {
            return Err(format!(
                "'scene' ({}) cannot be changed through a remote FMU: it drives the scene the \
                 node serves",
                values.get(k).unwrap_or(&"")
            ));
        }
        let values = values.iter().map(|s| s.to_string()).collect();
        self.call(Request::SetString(pb::SetStrings {
            refs: refs(r),
            values,
        }))
        .map(drop)
    }

    fn save_state(&mut self) -> Result<FmuState, String> {
        let reply = self.call(Request::SaveState(true))?;
        Ok(FmuState::Remote(reply.state))
    }

    fn restore_state(&mut self, state: &FmuState) -> Result<(), String> {
        let bytes = state.remote()?.to_vec();
        self.call(Request::RestoreState(bytes)).map(drop)
    }

    fn state_to_bytes(&self, state: &FmuState) -> Result<Vec<u8>, String> {
        state.remote().map(<[u8]>::to_vec)
    }

    /// The node checks the bytes when they are restored; here only that they are a
    /// talus state at all.
    fn state_from_bytes(&self, bytes: &[u8]) -> Result<FmuState, String> {
        if !starts_as_state(bytes) {
            return Err("not a talus state".into());
        }
        Ok(FmuState::Remote(bytes.to_vec()))
    }
}

impl Drop for Remote {
    fn drop(&mut self) {
        if let Some(session) = self.session.take() {
            let _ = session.close().wait();
        }
    }
}
