//! Scene files: a TOML description of a simulation, validated into a [`Scene`] that
//! builds the world, the engine and the minimal pipeline the scene needs.
//!
//! A scene names its materials and shapes once and refers to them by name from walls,
//! particle groups and inlets; file paths are relative to the scene file. Every error
//! names the file, the line and the field (`wall[1].motion.rpm`), whether the TOML is
//! malformed, a key unknown, or a value unusable. See `examples/*/` for scenes and
//! [`spec`] for every field.

mod analyses;
mod build;
mod csv_table;
pub mod energy_balance;
pub mod energy_ledger;
mod error;
mod fluid;
mod fluid_coupling;
mod fluid_ranks;
mod locate;
mod plan;
pub mod poses;
mod rank_states;
pub mod ranks;
mod simulation;
pub mod spec;
pub mod state;
pub mod state_bytes;

use std::path::{Path, PathBuf};

pub use build::MAX_THREADS;
pub use error::{FieldError, FieldPath, FieldSegment, SceneError};
pub use fluid_coupling::FluidError;
pub use plan::Plan;
pub use rank_states::ShareState;
pub use simulation::{SPACE_ORDER_INTERVAL, Simulation, StepReport};
pub use spec::SceneSpec;
pub use state::{FluidState, InletState, SimState, WallState};
pub use state_bytes::{StateError, StateReader, StateWriter};

use crate::Real;
use crate::analysis::Drum;
use crate::analysis::packing::Bed;
use crate::engine::StepParams;
use crate::engine::time_step::{TimeStepEstimate, suggested_time_step};
use crate::world::{Inlet, World};

/// A validated scene: the initial world, the inlets and the settings of the run.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The scene file.
    pub file: PathBuf,
    /// The scene as written.
    pub spec: SceneSpec,
    /// The world at time 0.
    pub world: World,
    /// Particle sources.
    pub inlets: Vec<Inlet>,
    /// Id of the next particle to be created.
    pub next_id: u64,
    /// The time step used.
    pub dt: Real,
    /// The suggested time step (None without particle kinds).
    pub suggested: Option<TimeStepEstimate>,
    /// Warnings a user should see (a time step above the suggested one ...).
    pub warnings: Vec<String>,
    /// What will be computed, and why.
    pub plan: Plan,
    /// The rotating drum the scene analyses, if any.
    pub drum: Option<Drum>,
    /// The packed bed the scene analyses, if any.
    pub bed: Option<Bed>,
    /// The shape name of each body type (kind) of the world.
    pub shape_names: Vec<String>,
}

/// The warning a time step `dt` above the suggested one deserves (also for a step set
/// after loading, through the Component's `dt` parameter).
pub fn time_step_warning(dt: Real, suggested: Option<&TimeStepEstimate>) -> Option<String> {
    let s = suggested.filter(|s| dt > s.dt)?;
    Some(format!(
        "dt = {dt:.3e} s is above the suggested {:.3e} s ({:.3} times it; {:.3} steps per period \
         of the stiffest contact, {}); contacts may be under-resolved or unstable",
        s.dt,
        dt / s.dt,
        s.period / dt,
        s.limited_by
    ))
}

impl Scene {
    /// A 64-bit fingerprint of the scene as written and of the talus version: what a
    /// run's checkpoint carries so that it resumes only the scene it was written for.
    pub fn fingerprint(&self) -> u64 {
        let text = format!("talus {} {:?}", env!("CARGO_PKG_VERSION"), self.spec);
        crate::checksum::fnv1a(text.as_bytes(), crate::checksum::FNV_OFFSET)
    }

    /// The step parameters the scene's `[contact]` section asks for.
    pub fn step_params(&self) -> StepParams {
        let contact = &self.spec.contact;
        StepParams {
            regularisation_length: contact.regularisation,
            skin: contact.skin,
            round_law: contact.round_law(),
        }
    }

    /// What computes the steps (`[simulation] backend`).
    pub fn backend(&self) -> crate::engine::choice::BackendKind {
        self.spec.simulation.backend
    }

    /// A scene with this one's settings (time step, contact laws, materials) that
    /// holds `world` alone: no inlets, fluid, settling, analyses or end. The
    /// reference problems of [`crate::accuracy`] are built so from a user's scene.
    pub fn reference(&self, world: World) -> Scene {
        let mut spec = self.spec.clone();
        spec.simulation.settle = None;
        spec.simulation.end_time = Real::INFINITY;
        spec.bed = None;
        spec.drum = None;
        spec.fluid = None;
        let next_id = world.particles.id.iter().max().map_or(0, |id| id + 1);
        Scene {
            file: self.file.clone(),
            spec,
            world,
            inlets: Vec::new(),
            next_id,
            dt: self.dt,
            suggested: self.suggested.clone(),
            warnings: Vec::new(),
            plan: Plan::default(),
            drum: None,
            bed: None,
            shape_names: Vec::new(),
        }
    }

    /// Reads and validates a scene file.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
            file: path.to_path_buf(),
            source,
        })?;
        Scene::parse(&text, path)
    }

    /// Validates scene `text` as if read from `path` (relative paths start at its
    /// directory).
    pub fn parse(text: &str, path: &Path) -> Result<Scene, SceneError> {
        let spec: SceneSpec = toml::from_str(text).map_err(|e| {
            let (line, column) = e
                .span()
                .map_or((0, 0), |s| error::line_column(text, s.start));
            SceneError::Syntax {
                file: path.to_path_buf(),
                line,
                column,
                message: e.message().trim().to_string(),
            }
        })?;
        Scene::from_spec(spec, path).map_err(|e| e.locate(path, text))
    }

    /// Validates a scene given as a structure; `path` anchors relative file names.
    pub fn from_spec(spec: SceneSpec, path: &Path) -> Result<Scene, FieldError> {
        let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
        let sim = &spec.simulation;
        let sim_path = FieldPath::root("simulation");
        if !(sim.end_time.is_finite() && sim.end_time >= 0.0) {
            return Err(FieldError::new(
                sim_path.key("end_time"),
                format!("{} must be a non-negative number of seconds", sim.end_time),
            ));
        }
        let reg = spec.contact.regularisation;
        if !(reg.is_finite() && reg > 0.0 && reg < 1.0) {
            return Err(FieldError::new(
                FieldPath::root("contact").key("regularisation"),
                format!("{reg} must lie in (0, 1)"),
            ));
        }
        if let Some(skin) = spec.contact.skin
            && !(skin.is_finite() && skin >= 0.0)
        {
            return Err(FieldError::new(
                FieldPath::root("contact").key("skin"),
                format!("{skin} must be a non-negative length"),
            ));
        }
        if spec.contact.rolling != crate::contact::RollingModel::None
            && spec.contact.law != spec::ContactLawSpec::HertzMindlin
        {
            return Err(FieldError::new(
                FieldPath::root("contact").key("rolling"),
                "rolling resistance belongs to the Hertz–Mindlin law: set law = \"hertz_mindlin\"",
            ));
        }
        let built = build::Builder::new(&spec, &dir).build()?;
        let suggested = suggested_time_step(&built.world, reg, spec.contact.round_law());
        let mut warnings = Vec::new();
        let dt = match (&sim.dt, &suggested) {
            (spec::TimeStepSpec::Fixed(dt), _) => {
                if !(dt.is_finite() && *dt > 0.0) {
                    return Err(FieldError::new(
                        sim_path.key("dt"),
                        format!("{dt} must be a positive number of seconds or \"auto\""),
                    ));
                }
                warnings.extend(time_step_warning(*dt, suggested.as_ref()));
                *dt
            }
            (spec::TimeStepSpec::Auto, Some(s)) => s.dt,
            (spec::TimeStepSpec::Auto, None) => {
                return Err(FieldError::new(
                    sim_path.key("dt"),
                    "\"auto\" needs particles or inlets to size the step; give a number",
                ));
            }
        };
        for o in [
            ("frame_interval", spec.output.frame_interval),
            ("csv_interval", spec.output.csv_interval),
            ("checkpoint_interval", spec.output.checkpoint_interval),
        ] {
            if let (name, Some(v)) = o
                && !(v.is_finite() && v > 0.0)
            {
                return Err(FieldError::new(
                    FieldPath::root("output").key(name),
                    format!("{v} must be a positive number of seconds"),
                ));
            }
        }
        if let Some(s) = &sim.settle
            && !(s.max_speed > 0.0 && s.kinetic_energy_per_particle > 0.0 && s.hold >= 0.0)
        {
            return Err(FieldError::new(
                sim_path.key("settle"),
                "max_speed and kinetic_energy_per_particle must be positive, hold non-negative",
            ));
        }
        let params = StepParams {
            regularisation_length: spec.contact.regularisation,
            skin: spec.contact.skin,
            round_law: spec.contact.round_law(),
        };
        crate::engine::choice::check(sim.backend, &built.world, &params)
            .map_err(|e| FieldError::new(sim_path.key("backend"), e))?;
        let drum = match &spec.drum {
            Some(d) => Some(analyses::resolve_drum(d, &built.world)?),
            None => None,
        };
        let bed = match &spec.bed {
            Some(b) => Some(analyses::resolve_bed(b)?),
            None => None,
        };
        let plan = Plan::new(&built.world, &built.inlets, dt, &suggested, &spec);
        Ok(Scene {
            file: path.to_path_buf(),
            spec,
            world: built.world,
            inlets: built.inlets,
            next_id: built.next_id,
            dt,
            suggested,
            warnings,
            plan,
            drum,
            bed,
            shape_names: built.shape_names,
        })
    }

    /// The output directory: the scene's `[output] dir`, relative to the scene file,
    /// or `<scene stem>_out` next to it.
    pub fn output_dir(&self) -> PathBuf {
        let dir = self.file.parent().unwrap_or(Path::new(""));
        match &self.spec.output.dir {
            Some(d) => dir.join(d),
            None => {
                let stem = self
                    .file
                    .file_stem()
                    .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
                dir.join(format!("{stem}_out"))
            }
        }
    }
}
