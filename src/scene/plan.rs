//! The pipeline a scene needs, in words: which kernels run, what state is kept, and
//! why. Printed by `talus check`.

use std::fmt;

use super::spec::{SceneSpec, UpdateInterval};
use crate::Real;
use crate::engine::time_step::TimeStepEstimate;
use crate::geometry::Shape;
use crate::world::{DriveInput, Inlet, WallMotion, World};

/// What a scene will compute.
#[derive(Clone, Debug, Default)]
pub struct Plan {
    /// Lines of the plan, each "what: why".
    pub lines: Vec<(String, String)>,
    /// Whether any contact carries friction (tangential history kept).
    pub friction: bool,
    /// Whether polyhedron–polyhedron contacts can occur.
    pub polyhedra: bool,
    /// Whether any wall moves.
    pub moving_walls: bool,
}

impl Plan {
    /// The plan of a built scene.
    pub fn new(
        world: &World,
        inlets: &[Inlet],
        dt: Real,
        suggested: &Option<TimeStepEstimate>,
        spec: &SceneSpec,
    ) -> Plan {
        let mut plan = Plan::default();
        let mut line = |what: String, why: String| plan.lines.push((what, why));
        let types = &world.body_types;
        let n_poly = types
            .iter()
            .filter(|t| t.shape.as_polyhedron().is_some())
            .count();
        let n_sphere = types.len() - n_poly;
        let inserted: usize = inlets.iter().map(|i| i.count).sum();
        let until_height = inlets.iter().any(|i| i.stop_height.is_some());
        line(
            format!(
                "particles: {} at start, {}{} from {} inlet(s)",
                world.particles.len(),
                if until_height { "up to " } else { "" },
                inserted,
                inlets.len()
            ),
            format!("{} particle kind(s)", types.len()),
        );
        for (k, t) in types.iter().enumerate() {
            let shape = match &t.shape {
                Shape::Sphere(s) => format!("sphere r = {:.4e} m", s.radius),
                Shape::Polyhedron(p) => format!(
                    "polyhedron, {} vertices, {} faces, circumradius {:.4e} m",
                    p.vertices().len(),
                    p.face_count(),
                    p.circumradius()
                ),
            };
            line(
                format!("  kind {k}: {shape}"),
                format!(
                    "material '{}', mass {:.4e} kg",
                    world.materials[t.material].name, t.mass
                ),
            );
        }
        if n_poly > 0 {
            line(
                "polyhedron–polyhedron: GJK, then exact overlap volume".into(),
                "polyhedral kinds present".into(),
            );
        }
        if n_sphere > 0 {
            line(
                "sphere–sphere: analytic lens".into(),
                "sphere kinds present (no GJK, no clipping)".into(),
            );
        }
        if n_poly > 0 && n_sphere > 0 {
            line(
                "sphere–polyhedron: closest feature and cap".into(),
                "mixed kinds".into(),
            );
        }
        if n_sphere > 0 {
            let contact = &spec.contact;
            let (law, why) = match contact.law {
                super::spec::ContactLawSpec::Volume => (
                    "volume law".to_string(),
                    "[contact] law = \"volume\" (default)".to_string(),
                ),
                super::spec::ContactLawSpec::HertzMindlin => (
                    format!("Hertz–Mindlin, rolling resistance: {:?}", contact.rolling),
                    "[contact] law = \"hertz_mindlin\"; polyhedron pairs: volume law".to_string(),
                ),
            };
            line(format!("sphere contacts: {law}"), why);
        }
        let used: Vec<usize> = types
            .iter()
            .map(|t| t.material)
            .chain(world.walls.iter().map(|w| w.material))
            .collect();
        let friction = used.iter().any(|&m| world.materials[m].friction > 0.0);
        line(
            format!(
                "tangential history: {}",
                if friction { "kept per contact" } else { "none" }
            ),
            if friction {
                "a material has friction".into()
            } else {
                "every friction coefficient is 0".into()
            },
        );
        let r: Vec<Real> = types.iter().map(|t| t.shape.circumradius()).collect();
        let ratio = r.iter().copied().fold(0.0, Real::max)
            / r.iter().copied().fold(Real::INFINITY, Real::min);
        line(
            format!(
                "broad phase: {} cell grid level(s)",
                if ratio.is_finite() {
                    ratio.log2().floor() as usize + 1
                } else {
                    1
                }
            ),
            format!(
                "size ratio {:.3}",
                if ratio.is_finite() { ratio } else { 1.0 }
            ),
        );
        let moving = world.walls.iter().filter(|w| !w.motion.is_fixed()).count();
        for w in &world.walls {
            let motion = match &w.motion {
                WallMotion::Fixed => "fixed".to_string(),
                WallMotion::Constant {
                    velocity,
                    angular_velocity,
                } => format!(
                    "velocity {:?} m/s, angular velocity {:?} rad/s",
                    velocity.as_slice(),
                    angular_velocity.as_slice()
                ),
                WallMotion::Oscillation {
                    amplitude,
                    frequency,
                } => {
                    format!("oscillation {:?} m at {frequency} Hz", amplitude.as_slice())
                }
                WallMotion::Table(k) => format!("time table of {} keys", k.len()),
                WallMotion::External(DriveInput::Velocity) => {
                    "driven from outside (velocity inputs)".into()
                }
                WallMotion::External(DriveInput::Pose) => {
                    "driven from outside (pose inputs)".into()
                }
                WallMotion::Attached(k) => format!("moves with '{}'", world.walls[*k].name),
            };
            line(
                format!("wall '{}': {} facets", w.name, w.triangles.len()),
                format!(
                    "{motion}; material '{}'; reference point {:?}",
                    world.materials[w.material].name,
                    w.reference().coords.as_slice()
                ),
            );
        }
        line(
            format!(
                "wall kinematics: {}",
                if moving > 0 {
                    "advanced every step"
                } else {
                    "none"
                }
            ),
            format!("{moving} of {} wall(s) move", world.walls.len()),
        );
        line(
            format!(
                "time step: {dt:.4e} s, end time {} s",
                readable(spec.simulation.end_time)
            ),
            match suggested {
                Some(s) => format!(
                    "suggested {:.4e} s ({}, contact period {:.3e} s)",
                    s.dt, s.limited_by, s.period
                ),
                None => "no particle kinds".into(),
            },
        );
        if let Some(f) = &world.fluid {
            line(
                format!("fluid: {}, drag {}", f.grid.describe(), f.model.law.name()),
                format!(
                    "density {} kg/m³, viscosity {} Pa s, shape correction {:?}; solid fraction updated {} ([fluid])",
                    f.model.properties.density,
                    f.model.properties.viscosity,
                    f.model.correction,
                    match spec.fluid.as_ref().map(|s| s.update_interval) {
                        Some(UpdateInterval::Steps(n)) => format!("every {n} steps"),
                        _ => "at each communication step".into(),
                    }
                ),
            );
        }
        if let Some(d) = &spec.drum {
            line(
                format!("drum analysis: walls {}", d.walls.join(", ")),
                "drive torque, angle of repose, velocity field ([drum])".into(),
            );
        }
        if let Some(b) = &spec.bed {
            line(
                format!("bed analysis: tube of radius {} m", b.radius),
                "packing.json, profiles, poses.csv, bed.stl at the end ([bed])".into(),
            );
            if let Some(f) = &b.freeze {
                line(
                    format!(
                        "freezing: particles {} m below the bed height, slower than {} m/s",
                        f.depth, f.max_speed
                    ),
                    "not integrated; no contacts among them or with walls ([bed] freeze)".into(),
                );
            }
        }
        if inlets.iter().any(|i| i.above_bed) {
            line(
                "inlet boxes ride above the bed".into(),
                "shifted by the bed height every 5 ms (above_bed)".into(),
            );
        }
        plan.friction = friction;
        plan.polyhedra = n_poly > 0;
        plan.moving_walls = moving > 0;
        plan
    }
}

impl fmt::Display for Plan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (what, why) in &self.lines {
            writeln!(f, "{what:<60} ({why})")?;
        }
        Ok(())
    }
}

/// A number as written in a scene when it is of everyday size, else in scientific
/// notation (an end time of 1e-300 s is not printed as 300 digits).
fn readable(x: Real) -> String {
    if x == 0.0 || (1e-4..1e7).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}
