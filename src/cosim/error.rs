//! Errors of the co-simulation component.

use thiserror::Error;

use super::Mode;
use crate::scene::{SceneError, StateError};

/// Why a component call was refused or failed. A refused call leaves the component
/// as it was.
#[derive(Debug, Error)]
pub enum CosimError {
    /// The scene could not be loaded.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The call is not allowed in the current mode.
    #[error("{call} is not allowed in {mode} mode (allowed in: {allowed})")]
    WrongMode {
        /// The call.
        call: &'static str,
        /// The current mode.
        mode: Mode,
        /// Where it is allowed.
        allowed: &'static str,
    },
    /// No such variable.
    #[error("unknown variable {0}")]
    UnknownVariable(String),
    /// A value of the wrong type or size for a variable.
    #[error("variable '{name}': {problem}")]
    BadAccess {
        /// The variable.
        name: String,
        /// What is wrong.
        problem: String,
    },
    /// A value that is not accepted.
    #[error("variable '{name}': {problem}")]
    BadValue {
        /// The variable.
        name: String,
        /// What is wrong.
        problem: String,
    },
    /// A fluid call on a scene without `[fluid]`.
    #[error("the scene has no [fluid] section")]
    NoFluid,
    /// A communication step that cannot be taken.
    #[error("step refused: {0}")]
    BadStep(String),
    /// The simulation blew up; the state is back where the step started.
    #[error("the step diverged ({0}); the state is back at the start of the step")]
    Diverged(String),
    /// A state that cannot be restored.
    #[error("cannot restore the state: {0}")]
    State(#[from] StateError),
    /// Worker threads could not be started.
    #[error("cannot start worker threads: {0}")]
    Threads(String),
    /// The scene cannot run on the ranks, or its state not be shared among them.
    #[error("on MPI ranks: {0}")]
    Ranks(String),
    /// The backend asked for could not be opened (no GPU, out of device memory).
    #[error("backend: {0}")]
    Backend(String),
    /// Output files could not be written.
    #[error("output: {0}")]
    Output(#[from] std::io::Error),
}
