//! The sweep of `talus accuracy`: every setting's errors and cost, the settings no
//! other beats on both (the Pareto front), and the cheapest that meets a target.

use std::time::Duration;

use serde::Serialize;

use super::cost::{self, Cost};
use super::errors::{Errors, Quantity};
use super::settings::Settings;
use crate::Real;
use crate::scene::{FieldError, Scene, StateError};

/// Time steps swept, as fractions of the suggested one.
pub const DT_FRACTIONS: [Real; 4] = [1.0, 0.5, 0.25, 0.125];
/// Regularisation lengths swept, as factors of the scene's (kept below
/// [`MAX_REGULARISATION`]).
pub const REGULARISATION_FACTORS: [Real; 3] = [0.5, 1.0, 2.0];
/// The largest regularisation length swept (the law needs it below 1).
pub const MAX_REGULARISATION: Real = 0.9;
/// Skins swept at the scene's other settings, as factors of its own. The skin
/// changes what a step costs, never its result.
pub const SKIN_FACTORS: [Real; 3] = [0.5, 1.0, 2.0];
/// Cost passes over the points, interleaved; a point's fastest pass counts (the
/// machine's speed drifts; the fastest pass is the least disturbed).
pub const COST_PASSES: usize = 2;
/// A quantity whose largest and smallest error over the sweep differ by less than
/// this factor is one the knobs do not move.
pub const INSENSITIVE: Real = 2.0;

/// Why a sweep could not be made.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// A setting made the scene invalid.
    #[error("the scene at {settings:?}: {}: {}", .error.field, .error.message)]
    Setting {
        settings: Settings,
        error: FieldError,
    },
    /// The warm state did not fit a setting of the scene.
    #[error("restoring the scene's state at {settings:?}: {source}")]
    State {
        settings: Settings,
        source: StateError,
    },
    /// The scene has no particle kinds to size a time step on.
    #[error("the scene has no particles or inlets: there is nothing to measure")]
    NoKinds,
}

/// One setting measured.
#[derive(Clone, Debug, Serialize)]
pub struct Point {
    pub settings: Settings,
    /// The time step, s.
    pub dt: Real,
    /// Faces (coplanar facets merged) of the scene's first icosphere or prism
    /// kind, where the mesh knob is set.
    pub faces: Option<usize>,
    #[serde(serialize_with = "serialize_errors")]
    pub errors: Errors,
    pub cost: Cost,
    /// No other point is both cheaper (to the scene's end) and more accurate.
    pub pareto: bool,
}

/// Errors as a map from quantity names.
fn serialize_errors<S: serde::Serializer>(e: &Errors, s: S) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeMap;
    let mut map = s.serialize_map(None)?;
    for (q, v) in e.iter() {
        map.serialize_entry(q.name(), &v)?;
    }
    map.end()
}

/// How the sweep runs.
#[derive(Clone, Copy, Debug)]
pub struct SweepOptions {
    /// Wall-clock time for the warm-up and the cost runs together.
    pub budget: Duration,
    /// The largest error the recommendation may have in each quantity it can meet.
    pub target: Real,
}

/// A quantity no point of the sweep brings under the target.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Unmet {
    pub quantity: Quantity,
    /// Its smallest error over the sweep, and the point that has it.
    pub best: Real,
    pub best_point: usize,
    /// Its largest error over its smallest: below [`INSENSITIVE`] the knobs do not
    /// move it (the model or the materials set it); above, settings beyond the
    /// sweep's would reach the target.
    pub spread: Real,
}

impl Unmet {
    /// Whether the knobs swept move it.
    pub fn knob_sensitive(&self) -> bool {
        self.spread >= INSENSITIVE
    }
}

/// The sweep's points and what they recommend.
#[derive(Clone, Debug, Serialize)]
pub struct Sweep {
    pub target: Real,
    /// The scene's own settings.
    pub base: Settings,
    pub points: Vec<Point>,
    /// Quantities no point meets the target in; the recommendation leaves them out.
    pub unmet: Vec<Unmet>,
    /// The cheapest point whose every other error meets the target.
    pub recommended: Option<usize>,
}

/// The settings swept from `base`: time step × regularisation × mesh, and the skins
/// at the scene's own other settings.
pub fn grid(scene: &Scene) -> Vec<Settings> {
    let base = Settings::of(scene);
    let (steps, _) = Settings::mesh_steps(scene);
    let meshes: Vec<Option<usize>> = std::iter::once(None).chain((0..steps).map(Some)).collect();
    let mut out = Vec::new();
    for &mesh in &meshes {
        for &f in &REGULARISATION_FACTORS {
            for &dt_fraction in &DT_FRACTIONS {
                out.push(Settings {
                    dt_fraction,
                    regularisation: (base.regularisation * f).min(MAX_REGULARISATION),
                    mesh,
                    ..base
                });
            }
        }
    }
    out.extend(
        SKIN_FACTORS
            .iter()
            .filter(|&&f| f != 1.0)
            .map(|f| Settings {
                skin: base.skin * f,
                ..base
            }),
    );
    // The scene's own setting, where its time step is not one of the fractions.
    if !out.contains(&base) {
        out.push(base);
    }
    out
}

/// Measures every setting of [`grid`] on `scene`; `progress` hears of each point.
pub fn sweep(
    scene: &Scene,
    options: SweepOptions,
    mut progress: impl FnMut(usize, usize, &Point),
) -> Result<Sweep, SweepError> {
    if scene.suggested.is_none() {
        return Err(SweepError::NoKinds);
    }
    let settings = grid(scene);
    let mut points = Vec::with_capacity(settings.len());
    let mut scenes = Vec::with_capacity(settings.len());
    for (k, &s) in settings.iter().enumerate() {
        let set = s
            .apply(scene)
            .map_err(|error| SweepError::Setting { settings: s, error })?;
        points.push(Point {
            settings: s,
            dt: set.dt,
            faces: s.mesh.and_then(|_| meshed_faces(&set)),
            errors: Errors::measure(&set),
            cost: Cost::default(),
            pareto: false,
        });
        progress(k, settings.len(), &points[k]);
        scenes.push(set);
    }
    let warm = cost::warm_state(scene, options.budget.mul_f64(0.3));
    let each = options
        .budget
        .mul_f64(0.7 / (COST_PASSES * settings.len()) as f64);
    for _ in 0..COST_PASSES {
        for (p, set) in points.iter_mut().zip(&scenes) {
            let c = cost::measure(set, &warm, each).map_err(|source| SweepError::State {
                settings: p.settings,
                source,
            })?;
            if p.cost.steps == 0 || c.seconds_per_step < p.cost.seconds_per_step {
                p.cost = c;
            }
        }
    }
    Ok(recommend(Settings::of(scene), points, options.target))
}

/// The faces (coplanar facets merged) of the first kind given as an icosphere or
/// prism.
fn meshed_faces(scene: &Scene) -> Option<usize> {
    scene
        .shape_names
        .iter()
        .enumerate()
        .find_map(|(kind, name)| {
            let meshed = matches!(
                scene.spec.shapes.get(name),
                Some(
                    crate::geometry::ShapeSpec::Icosphere { .. }
                        | crate::geometry::ShapeSpec::Prism { .. }
                )
            );
            let shape = &scene.world.body_types.get(kind)?.shape;
            meshed.then(|| shape.as_polyhedron().map(|p| p.face_count()))?
        })
}

/// Marks the Pareto front and picks the recommendation.
pub fn recommend(base: Settings, points: Vec<Point>, target: Real) -> Sweep {
    let unmet: Vec<Unmet> = Quantity::ALL
        .iter()
        .filter_map(|&quantity| {
            let errors = points
                .iter()
                .enumerate()
                .filter_map(|(i, p)| p.errors.get(quantity).map(|e| (i, e)));
            let (best_point, best) = errors.clone().min_by(|a, b| a.1.total_cmp(&b.1))?;
            let largest = errors.map(|(_, e)| e).fold(0.0, Real::max);
            (!(best <= target)).then_some(Unmet {
                quantity,
                best,
                best_point,
                spread: largest / best,
            })
        })
        .collect();
    let mut sweep = Sweep {
        target,
        base,
        points,
        unmet,
        recommended: None,
    };
    let worst: Vec<Real> = (0..sweep.points.len())
        .map(|i| sweep.counted_error(i))
        .collect();
    let cost: Vec<Real> = sweep.points.iter().map(|p| p.cost.seconds_to_end).collect();
    let beaten = |i: usize, j: usize| {
        cost[j] <= cost[i] && worst[j] <= worst[i] && (cost[j] < cost[i] || worst[j] < worst[i])
    };
    for (i, p) in sweep.points.iter_mut().enumerate() {
        p.pareto = !(0..cost.len()).any(|j| beaten(i, j));
    }
    sweep.recommended = (0..cost.len())
        .filter(|&i| worst[i] <= target)
        .min_by(|&a, &b| cost[a].total_cmp(&cost[b]));
    sweep
}

impl Sweep {
    /// The worst error of point `i` over the quantities the target applies to
    /// (every one that some point meets it in).
    pub fn counted_error(&self, i: usize) -> Real {
        let mut e = self.points[i].errors;
        self.unmet.iter().for_each(|u| e.set(u.quantity, None));
        e.worst()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(cost: Real, restitution: Real, impulse: Real) -> Point {
        let mut errors = Errors::default();
        errors.set(Quantity::Restitution, Some(restitution));
        errors.set(Quantity::Impulse, Some(impulse));
        Point {
            settings: Settings {
                dt_fraction: 1.0,
                regularisation: 0.5,
                skin: 1e-3,
                mesh: None,
            },
            dt: 1e-6,
            faces: None,
            errors,
            cost: Cost {
                seconds_to_end: cost,
                ..Cost::default()
            },
            pareto: false,
        }
    }

    /// A quantity no point brings under the target is left out of the choice (and
    /// said how far the knobs move it); the front holds the points nothing beats on both cost and error; the
    /// recommendation is the cheapest point under the target.
    #[test]
    fn the_front_and_the_recommendation() {
        let base = point(1.0, 0.0, 0.0).settings;
        let sweep = recommend(
            base,
            vec![
                point(10.0, 0.05, 0.9),  // cheapest, misses the target
                point(20.0, 0.015, 0.5), // meets it: recommended
                point(30.0, 0.015, 0.4), // beaten by the one before
                point(40.0, 0.001, 0.3), // most accurate
            ],
            0.02,
        );
        let unmet = sweep.unmet[0];
        assert_eq!(sweep.unmet.len(), 1);
        assert_eq!(
            (unmet.quantity, unmet.best, unmet.best_point),
            (Quantity::Impulse, 0.3, 3)
        );
        assert!((unmet.spread - 3.0).abs() < 1e-12 && unmet.knob_sensitive());
        let front: Vec<bool> = sweep.points.iter().map(|p| p.pareto).collect();
        assert_eq!(front, [true, true, false, true]);
        assert_eq!(sweep.recommended, Some(1));
        assert_eq!(sweep.counted_error(1), 0.015);
    }
}
