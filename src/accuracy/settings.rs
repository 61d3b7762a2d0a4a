//! The knobs an accuracy sweep turns, and a user's scene set to them.

use serde::Serialize;

use crate::Real;
use crate::engine::neighbours::DEFAULT_SKIN;
use crate::geometry::ShapeSpec;
use crate::scene::{FieldError, FieldPath, Scene};

/// Icosphere levels of the mesh steps: 80 · 4^(level − 1) facets, 80 … 20 480.
pub const ICOSPHERE_LEVELS: [u32; 5] = [1, 2, 3, 4, 5];
/// Prism sides of the mesh steps, 8 … 64 (a step past the last keeps 64).
pub const PRISM_SIDES: [usize; 4] = [8, 16, 32, 64];

/// One setting of the knobs that trade speed for accuracy.
///
/// Invariant: `dt_fraction > 0`, `regularisation ∈ (0, 1)`, `skin ≥ 0`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Settings {
    /// The time step over the one suggested at these settings (the suggestion itself
    /// depends on the regularisation).
    pub dt_fraction: Real,
    /// `[contact] regularisation`: the length, relative to the smaller equivalent
    /// radius, below whose cube the volume law is regularised.
    pub regularisation: Real,
    /// `[contact] skin`, m.
    pub skin: Real,
    /// Index into [`ICOSPHERE_LEVELS`] and [`PRISM_SIDES`] for every icosphere and
    /// prism shape of the scene; `None` keeps the scene's meshes.
    pub mesh: Option<usize>,
}

impl Settings {
    /// The settings `scene` runs at (`dt_fraction` from its time step and the
    /// suggested one; 1 without a suggestion).
    pub fn of(scene: &Scene) -> Settings {
        Settings {
            dt_fraction: scene.suggested.as_ref().map_or(1.0, |s| scene.dt / s.dt),
            regularisation: scene.spec.contact.regularisation,
            skin: skin_of(scene),
            mesh: None,
        }
    }

    /// The scene's mesh steps: how many there are (0 when the scene has no icosphere
    /// or prism shape), and the first step at least as fine as its own first mesh.
    pub fn mesh_steps(scene: &Scene) -> (usize, Option<usize>) {
        let mut steps = 0;
        let mut own = None;
        for shape in scene.spec.shapes.values() {
            match shape {
                ShapeSpec::Icosphere { level, .. } => {
                    steps = steps.max(ICOSPHERE_LEVELS.len());
                    own = own.or(ICOSPHERE_LEVELS.iter().position(|l| l >= level));
                }
                ShapeSpec::Prism { sides, .. } => {
                    steps = steps.max(PRISM_SIDES.len());
                    own = own.or(PRISM_SIDES.iter().position(|s| s >= sides));
                }
                _ => {}
            }
        }
        (steps, own.or((steps > 0).then(|| steps - 1)))
    }

    /// `scene` set to these settings: its spec changed and validated again, the time
    /// step a fraction of the suggested one.
    pub fn apply(&self, scene: &Scene) -> Result<Scene, FieldError> {
        let mut spec = scene.spec.clone();
        spec.contact.regularisation = self.regularisation;
        spec.contact.skin = Some(self.skin);
        if let Some(step) = self.mesh {
            for shape in spec.shapes.values_mut() {
                match shape {
                    ShapeSpec::Icosphere { level, .. } => {
                        *level = ICOSPHERE_LEVELS[step.min(ICOSPHERE_LEVELS.len() - 1)];
                    }
                    ShapeSpec::Prism { sides, .. } => {
                        *sides = PRISM_SIDES[step.min(PRISM_SIDES.len() - 1)];
                    }
                    _ => {}
                }
            }
        }
        let mut set = Scene::from_spec(spec, &scene.file)?;
        let suggested = set.suggested.as_ref().map(|s| s.dt);
        if let Some(dt) = suggested {
            if !(self.dt_fraction.is_finite() && self.dt_fraction > 0.0) {
                return Err(FieldError::new(
                    FieldPath::root("simulation").key("dt"),
                    format!("a time step {} times the suggested one", self.dt_fraction),
                ));
            }
            set.dt = self.dt_fraction * dt;
            set.warnings.clear();
        }
        Ok(set)
    }

    /// The TOML lines that put these settings, at time step `dt`, into `scene`'s
    /// file.
    pub fn as_toml(&self, scene: &Scene, dt: Real) -> String {
        let mut out = format!(
            "[simulation]\ndt = {dt:.4e}    # {:.3} times the suggested step\n",
            self.dt_fraction
        );
        out += &format!(
            "[contact]\nregularisation = {}\nskin = {:.3e}\n",
            self.regularisation, self.skin
        );
        if let Some(step) = self.mesh {
            for (name, shape) in &scene.spec.shapes {
                match shape {
                    ShapeSpec::Icosphere { .. } => {
                        let level = ICOSPHERE_LEVELS[step.min(ICOSPHERE_LEVELS.len() - 1)];
                        out += &format!("[shapes.{name}]\nlevel = {level}\n");
                    }
                    ShapeSpec::Prism { .. } => {
                        let sides = PRISM_SIDES[step.min(PRISM_SIDES.len() - 1)];
                        out += &format!("[shapes.{name}]\nsides = {sides}\n");
                    }
                    _ => {}
                }
            }
        }
        out
    }
}

/// The skin a scene's lists are built with: the one it gives, or the default (a
/// fraction of the smallest bounding radius of its kinds).
pub fn skin_of(scene: &Scene) -> Real {
    scene.spec.contact.skin.unwrap_or_else(|| {
        let smallest = scene
            .world
            .body_types
            .iter()
            .map(|t| t.shape.circumradius())
            .fold(Real::INFINITY, Real::min);
        if smallest.is_finite() {
            DEFAULT_SKIN * smallest
        } else {
            0.0
        }
    })
}
