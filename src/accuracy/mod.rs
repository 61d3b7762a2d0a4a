//! What a scene's settings buy: reference problems built from the user's own shapes,
//! materials and settings, run against exact answers.
//!
//! [`impacts`]: each particle kind dropped on each wall material, face, edge and
//! vertex first, at the scene's time step and a speed its contacts meet. `talus
//! check` and `talus run` state the errors they find (restitution realised against
//! requested, the energy account of one impact); the run's own energy account
//! (`scene::energy_ledger`) then says what the whole run lost to its steps.

pub mod impacts;

pub use impacts::{Feature, Impact, impact_speed, impacts};
