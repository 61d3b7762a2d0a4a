//! What a driver tells a backend about how to step, besides the step length.

use crate::Real;
use crate::contact::RollingModel;

/// The law of contacts that involve a sphere (polyhedron pairs always follow the
/// volume law).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum RoundLaw {
    /// The volume law of every contact (see [`crate::contact::normal_force`]).
    #[default]
    Volume,
    /// Hertz–Mindlin (see `contact/hertz_mindlin.rs`), with a rolling resistance.
    HertzMindlin {
        /// The rolling-resistance model.
        rolling: RollingModel,
    },
}

/// Default regularisation length: below this fraction of the smaller equivalent
/// radius, cubed, the volume law is continued quadratically (see
/// [`crate::contact::normal_force`]); it bounds the stiffness of flat contacts.
pub const REGULARISATION_LENGTH: Real = 1e-2;

/// Step parameters of a backend. The step length itself is passed with each step
/// ([`super::Backend::step`]): a driver shortens the last step of an interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepParams {
    /// Length, relative to the smaller equivalent radius of a contact, below whose
    /// cube the volume law is regularised (see [`crate::contact::normal_force`]).
    pub regularisation_length: Real,
    /// Skin of the neighbour lists; `None`: [`super::neighbours::DEFAULT_SKIN`] times
    /// the smallest bounding radius.
    pub skin: Option<Real>,
    /// The law of contacts that involve a sphere.
    pub round_law: RoundLaw,
}

impl Default for StepParams {
    fn default() -> Self {
        StepParams {
            regularisation_length: REGULARISATION_LENGTH,
            skin: None,
            round_law: RoundLaw::Volume,
        }
    }
}
