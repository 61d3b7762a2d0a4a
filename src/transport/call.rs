//! `<key>/call`: one call of the component's life cycle as a co-simulation master
//! makes it, which is what a proxy FMU forwards (see [`crate::fmi`]'s remote
//! instances). The component checks each call as it checks the same call through
//! FMI: in the wrong mode, with a bad value, it is refused and nothing changes.

use prost::Message;

use super::Service;
use super::messages::{self as pb, CallReply, call_request::Call as Request};
use super::ranks::Call;
use crate::cosim::{CosimError, VarRef};

impl Service {
    /// Answers a [`pb::CallRequest`]. On ranks, rank 0 hands the others every call
    /// but the reads first.
    pub fn call(&mut self, payload: &[u8]) -> CallReply {
        let request = match pb::CallRequest::decode(payload) {
            Ok(pb::CallRequest { call: Some(call) }) => call,
            Ok(_) => return self.refused("a CallRequest needs a call".into()),
            Err(e) => return self.refused(format!("malformed CallRequest: {e}")),
        };
        let reads = matches!(
            request,
            Request::GetReal(_) | Request::GetInteger(_) | Request::GetString(_)
        );
        if !reads {
            self.tell_ranks(Call::Life, payload);
        }
        let mut reply = CallReply::default();
        match self.make_call(request, &mut reply) {
            Ok(()) => reply.status = pb::Status::Ok as i32,
            Err(e) => return self.refused(e),
        }
        reply.mode = self.component.mode().to_string();
        reply.time = self.time();
        reply
    }

    fn refused(&self, error: String) -> CallReply {
        CallReply {
            status: pb::Status::Error as i32,
            error,
            mode: self.component.mode().to_string(),
            time: self.time(),
            ..Default::default()
        }
    }

    fn make_call(&mut self, request: Request, reply: &mut CallReply) -> Result<(), String> {
        self.apply(request, reply).map_err(|e| match e {
            Refused::Component(e) => e.to_string(),
            Refused::Request(e) => e,
        })
    }

    fn apply(&mut self, request: Request, reply: &mut CallReply) -> Result<(), Refused> {
        let c = &mut self.component;
        match request {
            Request::Reset(_) => c.reset(),
            Request::EnterInitialization(start) => {
                c.enter_initialization_mode(start)?;
                reply.warnings = c.warnings();
            }
            Request::ExitInitialization(_) => c.exit_initialization_mode()?,
            Request::DoStep(s) => c.do_step(s.time, s.step)?,
            Request::Terminate(_) => c.terminate()?,
            Request::SetReal(s) => c.set_real(&refs(&s.refs, s.values.len())?, &s.values)?,
            Request::SetInteger(s) => {
                c.set_integer(&refs(&s.refs, s.values.len())?, &s.values)?;
            }
            Request::SetString(s) => {
                let values: Vec<&str> = s.values.iter().map(String::as_str).collect();
                c.set_string(&refs(&s.refs, values.len())?, &values)?;
            }
            Request::GetReal(r) => {
                reply.reals = vec![0.0; r.refs.len()];
                c.get_real(&refs(&r.refs, r.refs.len())?, &mut reply.reals)?;
            }
            Request::GetInteger(r) => {
                reply.integers = vec![0; r.refs.len()];
                c.get_integer(&refs(&r.refs, r.refs.len())?, &mut reply.integers)?;
            }
            Request::GetString(r) => reply.strings = c.get_string(&refs(&r.refs, r.refs.len())?)?,
            Request::SaveState(_) => {
                let state = c.save_state()?;
                reply.state = c.state_to_bytes(&state);
            }
            Request::RestoreState(bytes) => {
                let state = c.state_from_bytes(&bytes)?;
                c.restore_state(&state)?;
            }
        }
        Ok(())
    }
}

/// Why a call was refused: by the component, or as a request.
enum Refused {
    Component(CosimError),
    Request(String),
}

impl From<CosimError> for Refused {
    fn from(e: CosimError) -> Self {
        Refused::Component(e)
    }
}

/// The component's references of `refs`, which must be `values` many.
fn refs(refs: &[pb::VarRef], values: usize) -> Result<Vec<VarRef>, Refused> {
    if refs.len() != values {
        return Err(Refused::Request(format!(
            "{} references and {values} values",
            refs.len()
        )));
    }
    Ok(refs
        .iter()
        .map(|r| VarRef {
            var: r.variable as usize,
            element: r.element as usize,
        })
        .collect())
}
