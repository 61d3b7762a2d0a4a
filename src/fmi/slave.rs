//! What an FMU instance drives: the component in this process, or (feature
//! `zenoh`) a component served by a `talus serve` node elsewhere, perhaps on the
//! ranks of an MPI run, through the proxy of [`super::remote`]. The FMI entry
//! points see one interface; errors are the messages they log.

use crate::cosim::{Component, ComponentState, Mode, VarRef, Variable};

/// An FMU state: the component's, in memory, or a remote node's as its bytes.
#[derive(Clone, Debug)]
pub(crate) enum FmuState {
    Local(Box<ComponentState>),
    #[cfg_attr(not(feature = "zenoh"), allow(dead_code))]
    Remote(Vec<u8>),
}

impl FmuState {
    /// The state of a local instance; an error for a remote one's.
    fn local(&self) -> Result<&ComponentState, String> {
        match self {
            FmuState::Local(state) => Ok(state),
            FmuState::Remote(_) => {
                Err("a state of a remote FMU instance given to a local one".into())
            }
        }
    }

    /// The bytes of a remote instance's state; an error for a local one's.
    #[cfg_attr(not(feature = "zenoh"), allow(dead_code))]
    pub(crate) fn remote(&self) -> Result<&[u8], String> {
        match self {
            FmuState::Remote(bytes) => Ok(bytes),
            FmuState::Local(_) => {
                Err("a state of a local FMU instance given to a remote one".into())
            }
        }
    }
}

/// The calls of the co-simulation life cycle an FMU instance makes.
pub(crate) trait Slave: Send {
    fn variables(&self) -> &[Variable];
    fn fingerprint(&self) -> u64;
    fn mode(&self) -> Mode;
    /// What a master should know about the scene at the current parameters.
    fn warnings(&self) -> Vec<String>;
    /// The simulation's time, once it exists.
    fn time(&self) -> Option<f64>;
    /// After a panic: only reset or free.
    fn fail(&mut self);
    fn enter_initialization_mode(&mut self, start_time: f64) -> Result<(), String>;
    fn exit_initialization_mode(&mut self) -> Result<(), String>;
    fn do_step(&mut self, t: f64, h: f64) -> Result<(), String>;
    fn terminate(&mut self) -> Result<(), String>;
    fn reset(&mut self) -> Result<(), String>;
    fn get_real(&self, refs: &[VarRef], out: &mut [f64]) -> Result<(), String>;
    fn set_real(&mut self, refs: &[VarRef], values: &[f64]) -> Result<(), String>;
    fn get_integer(&self, refs: &[VarRef], out: &mut [i64]) -> Result<(), String>;
    fn set_integer(&mut self, refs: &[VarRef], values: &[i64]) -> Result<(), String>;
    fn get_string(&self, refs: &[VarRef]) -> Result<Vec<String>, String>;
    fn set_string(&mut self, refs: &[VarRef], values: &[&str]) -> Result<(), String>;
    fn save_state(&mut self) -> Result<FmuState, String>;
    fn restore_state(&mut self, state: &FmuState) -> Result<(), String>;
    fn state_to_bytes(&self, state: &FmuState) -> Result<Vec<u8>, String>;
    fn state_from_bytes(&self, bytes: &[u8]) -> Result<FmuState, String>;
}

fn text(e: impl ToString) -> String {
    e.to_string()
}

impl Slave for Component {
    fn variables(&self) -> &[Variable] {
        Component::variables(self)
    }

    fn fingerprint(&self) -> u64 {
        Component::fingerprint(self)
    }

    fn mode(&self) -> Mode {
        Component::mode(self)
    }

    fn warnings(&self) -> Vec<String> {
        Component::warnings(self)
    }

    fn time(&self) -> Option<f64> {
        self.simulation().map(|s| s.world().time)
    }

    fn fail(&mut self) {
        Component::fail(self)
    }

    fn enter_initialization_mode(&mut self, start_time: f64) -> Result<(), String> {
        Component::enter_initialization_mode(self, start_time).map_err(text)
    }

    fn exit_initialization_mode(&mut self) -> Result<(), String> {
        Component::exit_initialization_mode(self).map_err(text)
    }

    fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        Component::do_step(self, t, h).map_err(text)
    }

    fn terminate(&mut self) -> Result<(), String> {
        Component::terminate(self).map_err(text)
    }

    fn reset(&mut self) -> Result<(), String> {
        Component::reset(self);
        Ok(())
    }

    fn get_real(&self, refs: &[VarRef], out: &mut [f64]) -> Result<(), String> {
        Component::get_real(self, refs, out).map_err(text)
    }

    fn set_real(&mut self, refs: &[VarRef], values: &[f64]) -> Result<(), String> {
        Component::set_real(self, refs, values).map_err(text)
    }

    fn get_integer(&self, refs: &[VarRef], out: &mut [i64]) -> Result<(), String> {
        Component::get_integer(self, refs, out).map_err(text)
    }

    fn set_integer(&mut self, refs: &[VarRef], values: &[i64]) -> Result<(), String> {
        Component::set_integer(self, refs, values).map_err(text)
    }

    fn get_string(&self, refs: &[VarRef]) -> Result<Vec<String>, String> {
        Component::get_string(self, refs).map_err(text)
    }

    fn set_string(&mut self, refs: &[VarRef], values: &[&str]) -> Result<(), String> {
        Component::set_string(self, refs, values).map_err(text)
    }

    fn save_state(&mut self) -> Result<FmuState, String> {
        Component::save_state(self)
            .map(|s| FmuState::Local(Box::new(s)))
            .map_err(text)
    }

    fn restore_state(&mut self, state: &FmuState) -> Result<(), String> {
        Component::restore_state(self, state.local()?).map_err(text)
    }

    fn state_to_bytes(&self, state: &FmuState) -> Result<Vec<u8>, String> {
        Ok(Component::state_to_bytes(self, state.local()?))
    }

    fn state_from_bytes(&self, bytes: &[u8]) -> Result<FmuState, String> {
        Component::state_from_bytes(self, bytes)
            .map(|s| FmuState::Local(Box::new(s)))
            .map_err(text)
    }
}
