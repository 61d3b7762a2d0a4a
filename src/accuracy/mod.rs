//! What a scene's settings buy: reference problems built from the user's own shapes,
//! materials and settings, run against exact answers.
//!
//! [`impacts`]: each particle kind dropped on each wall material, face, edge and
//! vertex first, at the scene's time step and a speed its contacts meet. `talus
//! check` and `talus run` state the errors they find (restitution realised against
//! requested, the energy account of one impact); the run's own energy account
//! (`scene::energy_ledger`) then says what the whole run lost to its steps.
//!
//! [`Errors::measure`] runs every reference problem: the impacts, an eccentric and
//! oblique corner impact against the rigid-body answer ([`oblique`]), an elastic
//! collision's energy ([`elastic_pair`]), a resting layer's weight on coarse and
//! fine walls ([`resting_layer`]) and curved particles given as meshes against the
//! curved bodies ([`mesh_resolution`]).

pub mod cost;
pub mod elastic_pair;
pub mod errors;
pub mod impacts;
pub mod mesh_resolution;
pub mod oblique;
pub mod report;
pub mod resting_layer;
pub mod settings;
mod setup;
pub mod sweep;

pub use errors::{Errors, Quantity};
pub use impacts::{Feature, Impact, impact_speed, impacts};
pub use settings::Settings;
pub use sweep::{Sweep, SweepOptions, sweep};

/// Particle kinds a check drops (the first ones of the scene): a scene of
/// thousands of distinct shapes is checked on a sample.
pub const KINDS_CHECKED: usize = 4;
