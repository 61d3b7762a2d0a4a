//! The variable table of a component, generated from its scene.
//!
//! Every quantity that crosses the interface is one [`Variable`]: a name, a type, its
//! causality and variability in the FMI sense, a unit, a description and a size (1 for
//! a scalar, 3 for a vector, more for a wall's mesh arrays). The FMI 2.0 face
//! flattens vectors into scalars named `wall.force[1]` ...; FMI 3.0 keeps them as
//! arrays. What a variable *means* is its [`Role`]; the component reads and writes
//! values by role, so the table is the single place where names, units and
//! descriptions live.

use crate::scene::Scene;
use crate::world::{DriveInput, WallMotion};

/// Value type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VarType {
    /// 64-bit float (FMI 2 Real, FMI 3 Float64).
    Real,
    /// Integer (FMI 2 Integer, FMI 3 Int32).
    Integer,
    /// Text (a path).
    String,
}

/// Who sets the value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Causality {
    /// Set before initialisation.
    Parameter,
    /// Set by the master between steps.
    Input,
    /// Computed by the component.
    Output,
    /// Simulated time.
    Independent,
}

/// When the value may change.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variability {
    /// Only before initialisation ends.
    Fixed,
    /// At any communication point.
    Continuous,
    /// At communication points only (counts).
    Discrete,
}

/// What a variable stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// Simulated time.
    Time,
    /// The scene file.
    Scene,
    /// The DEM time step.
    TimeStep,
    /// Directory for ParaView and CSV output ("" for none).
    OutputDir,
    /// Worker threads.
    Threads,
    /// The backend that steps the scene ("cpu", "cuda").
    Backend,
    /// Particles in the world.
    Particles,
    /// Contacts at the end of the step.
    Contacts,
    /// Kinetic energy of the particles.
    KineticEnergy,
    /// Largest particle speed.
    MaxSpeed,
    /// Input: linear velocity of wall `w`'s reference point.
    WallVelocity(usize),
    /// Input: angular velocity of wall `w`.
    WallAngularVelocity(usize),
    /// Input: position of wall `w`'s reference point at the end of the step.
    WallPosition(usize),
    /// Input: orientation (w, x, y, z) of wall `w` at the end of the step.
    WallOrientation(usize),
    /// Output: mean force on wall `w` over the last step.
    WallForce(usize),
    /// Output: mean torque on wall `w` about its reference point over the last step.
    WallTorque(usize),
    /// Output: force on wall `w` at the end of the last step.
    WallForceEnd(usize),
    /// Output: torque on wall `w` at the end of the last step.
    WallTorqueEnd(usize),
    /// Output: mean power wall `w` delivered to the particles over the last step.
    WallPower(usize),
    /// Output (arrays only): wall `w`'s vertices in the world.
    WallVertices(usize),
    /// Output (arrays only): force on each facet of wall `w` at the end of the step.
    WallFacetForces(usize),
    /// Output: mean drive torque of the scene's drum over the last step.
    DriveTorque,
    /// Output: mean power the drum delivered over the last step.
    DrivePower,
    /// Output: dynamic angle of repose of the drum's bed at the end of the step.
    AngleOfRepose,
    /// Output: height of the packed bed at the end of the step.
    BedHeight,
    /// Output: bed-averaged porosity at the end of the step.
    BedPorosity,
    /// Output: the bed's specific surface area at the end of the step.
    BedSpecificSurface,
    /// Output: the bed's Kozeny–Carman permeability at the end of the step.
    BedPermeability,
    /// Input per fluid cell: the fluid's (interstitial) velocity.
    FluidVelocity,
    /// Input per fluid cell: the pressure gradient.
    PressureGradient,
    /// Output per fluid cell: the solid volume fraction at the last update.
    SolidFraction,
    /// Output per fluid cell: the mean particle velocity at the last update.
    ParticleVelocity,
    /// Output per fluid cell: the mean force of the particles on the fluid over the
    /// last step.
    MomentumSource,
}

/// The most fluid cells whose variables the FMI 2.0 face offers as scalars (13 per
/// cell); a larger grid's are left out there (FMI 3.0, the C and Rust APIs and zenoh
/// carry them as arrays).
pub const FMI2_MAX_FLUID_CELLS: usize = 1000;

/// One variable.
#[derive(Clone, Debug, PartialEq)]
pub struct Variable {
    /// Name (`drum.force`, `time` ...).
    pub name: String,
    /// Value type.
    pub ty: VarType,
    /// Who sets it.
    pub causality: Causality,
    /// When it changes.
    pub variability: Variability,
    /// Unit symbol (FMI unit name), if any.
    pub unit: Option<&'static str>,
    /// What it is.
    pub description: String,
    /// Number of values (1 for a scalar).
    pub size: usize,
    /// Meaning.
    pub role: Role,
    /// Only offered where arrays exist (FMI 3, the Rust and C APIs): a mesh's size.
    pub array_only: bool,
}

impl Variable {
    fn new(name: String, role: Role, causality: Causality, size: usize) -> Self {
        let variability = match causality {
            Causality::Parameter => Variability::Fixed,
            _ => Variability::Continuous,
        };
        Variable {
            name,
            ty: VarType::Real,
            causality,
            variability,
            unit: None,
            description: String::new(),
            size,
            role,
            array_only: false,
        }
    }

    fn unit(mut self, unit: &'static str) -> Self {
        self.unit = Some(unit);
        self
    }

    fn about(mut self, description: impl Into<String>) -> Self {
        self.description = description.into();
        self
    }

    fn typed(mut self, ty: VarType) -> Self {
        self.ty = ty;
        if ty == VarType::Integer && self.causality == Causality::Output {
            self.variability = Variability::Discrete;
        }
        self
    }
}

/// The variables of a scene, in a fixed order: time, parameters, then per wall its
/// inputs and outputs, then global outputs.
pub fn variable_table(scene: &Scene) -> Vec<Variable> {
    use Causality::*;
    let mut v = vec![
        Variable::new("time".into(), Role::Time, Independent, 1)
            .unit("s")
            .about("Simulated time"),
        Variable::new("scene".into(), Role::Scene, Parameter, 1)
            .typed(VarType::String)
            .about("Scene file (TOML), relative to the resources directory of an FMU"),
        Variable::new("dt".into(), Role::TimeStep, Parameter, 1)
            .unit("s")
            .about("DEM time step; communication steps are split into steps of this length"),
        Variable::new("output_dir".into(), Role::OutputDir, Parameter, 1)
            .typed(VarType::String)
            .about("Directory for the ParaView series and CSV files (empty: no files)"),
        Variable::new("threads".into(), Role::Threads, Parameter, 1)
            .typed(VarType::Integer)
            .about("Worker threads (results do not depend on it)"),
        Variable::new("backend".into(), Role::Backend, Parameter, 1)
            .typed(VarType::String)
            .about("What steps the scene: cpu, or cuda (a GPU; default: the scene's [simulation] backend)"),
    ];
    for (w, wall) in scene.world.walls.iter().enumerate() {
        let n = &wall.name;
        match wall.motion {
            WallMotion::External(DriveInput::Velocity) => {
                v.push(
                    Variable::new(format!("{n}.velocity"), Role::WallVelocity(w), Input, 3)
                        .unit("m/s")
                        .about(format!(
                            "Linear velocity of wall '{n}' (its reference point)"
                        )),
                );
                v.push(
                    Variable::new(
                        format!("{n}.angular_velocity"),
                        Role::WallAngularVelocity(w),
                        Input,
                        3,
                    )
                    .unit("rad/s")
                    .about(format!(
                        "Angular velocity of wall '{n}' about its reference point"
                    )),
                );
            }
            WallMotion::External(DriveInput::Pose) => {
                v.push(
                    Variable::new(format!("{n}.position"), Role::WallPosition(w), Input, 3)
                        .unit("m")
                        .about(format!(
                            "Position of wall '{n}''s reference point at the end of the step"
                        )),
                );
                v.push(
                    Variable::new(
                        format!("{n}.orientation"),
                        Role::WallOrientation(w),
                        Input,
                        4,
                    )
                    .unit("1")
                    .about(format!(
                        "Orientation quaternion (w, x, y, z) of wall '{n}' at the end of the step"
                    )),
                );
            }
            _ => {}
        }
        let outputs = [
            (
                "force",
                Role::WallForce(w),
                "N",
                "Mean force of the particles on wall '{n}' over the last step (impulse / step)",
            ),
            (
                "torque",
                Role::WallTorque(w),
                "N.m",
                "Mean torque of the particles on wall '{n}' about its reference point over the last step",
            ),
            (
                "force_end",
                Role::WallForceEnd(w),
                "N",
                "Force of the particles on wall '{n}' at the end of the last step",
            ),
            (
                "torque_end",
                Role::WallTorqueEnd(w),
                "N.m",
                "Torque of the particles on wall '{n}' about its reference point at the end of the last step",
            ),
        ];
        for (suffix, role, unit, about) in outputs {
            v.push(
                Variable::new(format!("{n}.{suffix}"), role, Output, 3)
                    .unit(unit)
                    .about(about.replace("{n}", n)),
            );
        }
        v.push(
            Variable::new(format!("{n}.power"), Role::WallPower(w), Output, 1)
                .unit("W")
                .about(format!(
                    "Mean power wall '{n}' delivered to the particles over the last step"
                )),
        );
        let mut vertices = Variable::new(
            format!("{n}.vertices"),
            Role::WallVertices(w),
            Output,
            3 * wall.vertices.len(),
        )
        .unit("m")
        .about(format!(
            "Vertices of wall '{n}' in the world, x y z per vertex"
        ));
        vertices.array_only = true;
        v.push(vertices);
        let mut facets = Variable::new(
            format!("{n}.facet_force"),
            Role::WallFacetForces(w),
            Output,
            3 * wall.triangles.len(),
        )
        .unit("N")
        .about(format!(
            "Force on each facet of wall '{n}' at the end of the step, x y z per facet"
        ));
        facets.array_only = true;
        v.push(facets);
    }
    if scene.drum.is_some() {
        v.extend([
            Variable::new("drive_torque".into(), Role::DriveTorque, Output, 1)
                .unit("N.m")
                .about(
                    "Mean torque the drive applies to the drum about its axis over the last \
                     step (positive along the axis; balances the bed's resistance)",
                ),
            Variable::new("drive_power".into(), Role::DrivePower, Output, 1)
                .unit("W")
                .about("Mean power the drum's walls delivered to the bed over the last step"),
            Variable::new("angle_of_repose".into(), Role::AngleOfRepose, Output, 1)
                .unit("rad")
                .about(
                    "Inclination of the bed's free surface in the drum's central slice at the \
                     end of the step (0 when no surface is found)",
                ),
        ]);
    }
    if scene.bed.is_some() {
        v.extend([
            Variable::new("bed_height".into(), Role::BedHeight, Output, 1)
                .unit("m")
                .about(
                    "Height of the packed bed above the tube's base at the end of the step \
                     (where the slice solid fraction falls below half its median)",
                ),
            Variable::new("porosity".into(), Role::BedPorosity, Output, 1)
                .unit("1")
                .about(
                    "Bed-averaged porosity at the end of the step, from the exact clipped \
                     particle volumes, leaving out the layers at the base and the top \
                     (0 while the bed is too low to leave a region)",
                ),
            Variable::new(
                "specific_surface".into(),
                Role::BedSpecificSurface,
                Output,
                1,
            )
            .unit("1/m")
            .about(
                "Particle surface per bed volume over the porosity's region at the end \
                     of the step (0 while the bed is too low to leave a region)",
            ),
            Variable::new("permeability".into(), Role::BedPermeability, Output, 1)
                .unit("m2")
                .about(
                    "Kozeny-Carman permeability of the porosity's region at the end of the \
                     step, from its porosity and Sauter diameter (0 while the bed is too \
                     low to leave a region)",
                ),
        ]);
    }
    if let Some(fluid) = &scene.world.fluid {
        v.extend(fluid_variables(fluid.grid.len()));
    }
    v.extend([
        Variable::new("particles".into(), Role::Particles, Output, 1)
            .typed(VarType::Integer)
            .about("Particles in the world"),
        Variable::new("contacts".into(), Role::Contacts, Output, 1)
            .typed(VarType::Integer)
            .about("Particle-particle and particle-wall contacts at the end of the step"),
        Variable::new("kinetic_energy".into(), Role::KineticEnergy, Output, 1)
            .unit("J")
            .about("Kinetic energy of the particles (translation and rotation)"),
        Variable::new("max_speed".into(), Role::MaxSpeed, Output, 1)
            .unit("m/s")
            .about("Largest particle speed"),
    ]);
    v
}

/// The variables of a fluid grid of `cells` cells, flat in the grid's order (see
/// [`crate::fluid::FluidGrid`]: x fastest on a structured grid, the annulus fastest
/// on a cylindrical one, the file's order for given cells), x y z per cell for
/// vectors.
fn fluid_variables(cells: usize) -> Vec<Variable> {
    use Causality::*;
    let per_cell = [
        (
            "fluid.velocity",
            Role::FluidVelocity,
            Input,
            3,
            "m/s",
            "Fluid (interstitial) velocity per cell, x y z per cell, held over the step",
        ),
        (
            "fluid.pressure_gradient",
            Role::PressureGradient,
            Input,
            3,
            "Pa/m",
            "Pressure gradient per cell, x y z per cell, held over the step (start: \
             hydrostatic or the scene's)",
        ),
        (
            "fluid.solid_fraction",
            Role::SolidFraction,
            Output,
            1,
            "1",
            "Solid volume fraction per cell (exact clipped particle volumes) at the last \
             update of the shares",
        ),
        (
            "fluid.particle_velocity",
            Role::ParticleVelocity,
            Output,
            3,
            "m/s",
            "Volume-weighted mean particle velocity per cell, x y z per cell, at the last \
             update of the shares",
        ),
        (
            "fluid.momentum_source",
            Role::MomentumSource,
            Output,
            3,
            "N",
            "Mean force of the particles on the fluid per cell over the last step (minus \
             the drag they received; divide by the cell volume for a source density), x y \
             z per cell",
        ),
    ];
    per_cell
        .into_iter()
        .map(|(name, role, causality, width, unit, about)| {
            let mut var = Variable::new(name.into(), role, causality, width * cells)
                .unit(unit)
                .about(about);
            var.array_only = cells > FMI2_MAX_FLUID_CELLS;
            var
        })
        .collect()
}

/// A unit used by the table, as SI base-unit exponents (kg, m, s, rad).
pub fn unit_exponents(unit: &str) -> [i32; 4] {
    match unit {
        "s" => [0, 0, 1, 0],
        "m" => [0, 1, 0, 0],
        "m/s" => [0, 1, -1, 0],
        "rad/s" => [0, 0, -1, 1],
        "rad" => [0, 0, 0, 1],
        "N" => [1, 1, -2, 0],
        "N.m" => [1, 2, -2, 0],
        "J" => [1, 2, -2, 0],
        "W" => [1, 2, -3, 0],
        "Pa/m" => [1, -2, -2, 0],
        "1/m" => [0, -1, 0, 0],
        "m2" => [0, 2, 0, 0],
        _ => [0, 0, 0, 0],
    }
}
