//! The scene file as written: serde structures of the TOML document.
//!
//! Every table rejects unknown fields, so that a misspelt key is an error with its
//! line rather than a silently ignored setting. Lengths are in metres, times in
//! seconds, angles in radians unless a field says otherwise.

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::Real;
use crate::contact::RollingModel;
use crate::engine::RoundLaw;
use crate::engine::choice::BackendKind;
use crate::geometry::ShapeSpec;
use crate::world::{DriveInput, MotionKey};

/// The whole scene file.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// Time stepping, gravity, end.
    pub simulation: SimulationSpec,
    /// Contact-law settings.
    #[serde(default)]
    pub contact: ContactSpec,
    /// What is written, and how often.
    #[serde(default)]
    pub output: OutputSpec,
    /// Materials by name.
    pub materials: BTreeMap<String, MaterialSpec>,
    /// Particle shapes by name.
    #[serde(default)]
    pub shapes: BTreeMap<String, ShapeSpec>,
    /// Walls, in output order.
    #[serde(default, rename = "wall")]
    pub walls: Vec<WallSpec>,
    /// Particles present at the start.
    #[serde(default)]
    pub particles: Vec<ParticleGroupSpec>,
    /// Particle sources.
    #[serde(default, rename = "inlet")]
    pub inlets: Vec<InletSpec>,
    /// Rotating-drum analysis.
    pub drum: Option<DrumSpec>,
    /// Packed-bed analysis.
    pub bed: Option<BedSpec>,
    /// A coupled fluid: its grid and drag.
    pub fluid: Option<FluidSpec>,
}

/// `[fluid]`: the cells of a coupled CFD code, the fluid and its drag law (see
/// [`crate::fluid`]). A coupled code sets each cell's velocity and pressure gradient
/// and reads back the solid volume fraction, the mean particle velocity and the
/// momentum source; without one the fluid stays as the scene gives it.
///
/// The cells (`grid`):
/// - `"cartesian"` (default): `origin`, `cell` (edges) and `cells` (counts along
///   x, y, z);
/// - `"cylindrical"`: a tube from `base` along `axis` (default z) of `height`, with
///   `cells = [annuli, slabs, sectors]` and either `radius` (annuli of equal width)
///   or `radii` (each annulus's outer radius, ascending);
/// - `"cells"`: `file`, a CSV of the coupled code's cells (header `x,y,z,volume`,
///   one cell per line, in the order of its arrays), taken as the Voronoi cells of
///   their centres.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct FluidSpec {
    /// The kind of cells.
    #[serde(default)]
    pub grid: GridKind,
    /// Cartesian: corner of the grid (its lowest x, y, z).
    pub origin: Option<[Real; 3]>,
    /// Cartesian: cell edges along x, y, z, m.
    pub cell: Option<[Real; 3]>,
    /// Cartesian: cells along x, y, z; cylindrical: annuli, slabs, sectors.
    pub cells: Option<[usize; 3]>,
    /// Cylindrical: centre of the tube's base.
    pub base: Option<[Real; 3]>,
    /// Cylindrical: the tube's axis (default z).
    pub axis: Option<[Real; 3]>,
    /// Cylindrical: the tube's radius (annuli of equal width).
    pub radius: Option<Real>,
    /// Cylindrical: each annulus's outer radius, ascending (instead of `radius`).
    pub radii: Option<Vec<Real>>,
    /// Cylindrical: the tube's length along its axis.
    pub height: Option<Real>,
    /// Given cells: the CSV file of centres and volumes (relative to the scene).
    pub file: Option<String>,
    /// Fluid density, kg/m³.
    pub density: Real,
    /// Dynamic viscosity, Pa s.
    pub viscosity: Real,
    /// The drag law.
    pub drag: crate::fluid::DragLaw,
    /// Shape correction of the drag of non-spherical particles (default none).
    #[serde(default)]
    pub shape_correction: crate::fluid::ShapeCorrection,
    /// The fluid's (interstitial) velocity in every cell at the start, m/s.
    #[serde(default)]
    pub velocity: [Real; 3],
    /// The pressure gradient in every cell at the start, Pa/m (default: hydrostatic,
    /// density × gravity).
    pub pressure_gradient: Option<[Real; 3]>,
    /// When the particles' volume per cell (the solid fraction and the weights of
    /// the exchange) is computed again: every so many steps (default 50: the
    /// coupling interval of usual CFD–DEM runs, in which a particle moves a small
    /// part of a cell), or `"communication"`: at the start of each communication
    /// step of a coupled run (FMU, C API, zenoh), when the coupled code has just
    /// exchanged its fields.
    #[serde(default)]
    pub update_interval: UpdateInterval,
}

/// The kinds of fluid cells (`[fluid] grid`).
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum GridKind {
    /// Axis-aligned cells of one size.
    #[default]
    Cartesian,
    /// Annuli × slabs × sectors in a tube.
    Cylindrical,
    /// Cells a coupled code gives by centres and volumes.
    Cells,
}

/// When the fluid's particle shares are computed again (`[fluid] update_interval`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UpdateInterval {
    /// Every so many DEM steps (at least 1).
    Steps(u64),
    /// At the start of each communication step of a coupled run.
    Communication,
}

impl Default for UpdateInterval {
    fn default() -> Self {
        UpdateInterval::Steps(50)
    }
}

impl Serialize for UpdateInterval {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            UpdateInterval::Steps(n) => s.serialize_u64(*n),
            UpdateInterval::Communication => s.serialize_str("communication"),
        }
    }
}

impl<'de> Deserialize<'de> for UpdateInterval {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = UpdateInterval;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number of steps or \"communication\"")
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Self::Value, E> {
                u64::try_from(v)
                    .map(UpdateInterval::Steps)
                    .map_err(|_| E::custom(format!("{v} steps: must be at least 1")))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Self::Value, E> {
                Ok(UpdateInterval::Steps(v))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Self::Value, E> {
                if v == "communication" {
                    Ok(UpdateInterval::Communication)
                } else {
                    Err(E::custom(format!(
                        "\"{v}\": expected a number of steps or \"communication\""
                    )))
                }
            }
        }
        d.deserialize_any(Visitor)
    }
}

/// `[bed]`: the tube a bed is packed in, and how the packing is analysed (see
/// [`crate::analysis::packing`]).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BedSpec {
    /// Centre of the tube's base.
    pub base: [Real; 3],
    /// Tube axis, up the bed (default z).
    #[serde(default = "up")]
    pub axis: [Real; 3],
    /// Inner radius of the tube.
    pub radius: Real,
    /// Radial bin width (default d/20, d the volume-equivalent diameter).
    pub bin: Option<Real>,
    /// Axial slice thickness (default d/10).
    pub slice: Option<Real>,
    /// Layer left out of the averages at the base and below the top (default 2 d).
    pub exclude: Option<Real>,
    /// Surfaces closer than this touch, for coordination (default d/1000).
    pub gap: Option<Real>,
    /// Each particle's size in `bed.stl`, relative to its own (default 1; below 1
    /// separates touching particles for CFD meshing).
    #[serde(default = "one")]
    pub shrink: Real,
    /// The gap `bed_caps.stl` leaves between capped particles and between them and
    /// the tube (default d/100; see [`crate::analysis::packing::mesher`]).
    pub cap_gap: Option<Real>,
    /// Write `bed_bridges.stl`: the particles joined by bridges of this diameter,
    /// relative to the smaller particle's volume-equivalent diameter (see
    /// [`crate::analysis::packing::bridges`]); absent: no bridged bed.
    pub bridge: Option<Real>,
    /// Freeze the buried part of the bed while it is fed (see [`FreezeSpec`]).
    pub freeze: Option<FreezeSpec>,
}

/// `[bed] freeze`: while the bed is measured (every 5 ms of simulated time), every
/// particle that touches something, moves slower than `max_speed` and lies wholly
/// (its bounding sphere) more than `depth` below the bed height is frozen for the
/// rest of the run: it keeps its pose and is no longer integrated, and its contacts
/// with other frozen particles and with walls are skipped. A long bed then costs
/// what its top layer costs. Frozen particles no longer load the walls, so wall
/// forces leave out the frozen part of the bed.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct FreezeSpec {
    /// Depth below the bed height, m: a few particle diameters, deeper than the
    /// stress from the layers above reaches in a narrow tube (Janssen).
    pub depth: Real,
    /// Largest speed of a particle to freeze, m/s.
    pub max_speed: Real,
}

fn up() -> [Real; 3] {
    [0.0, 0.0, 1.0]
}

/// `[drum]`: the walls that form a rotating drum, and how its bed is analysed
/// (see [`crate::analysis::drum`]).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DrumSpec {
    /// The walls that turn together; the first one's reference point is on the axis.
    pub walls: Vec<String>,
    /// Axis direction at the start.
    pub axis: [Real; 3],
    /// Thickness of the central slice analysed (default: the whole drum).
    pub slice: Option<Real>,
    /// Velocity-field cell edge (default: the largest circumscribed diameter).
    pub cell: Option<Real>,
    /// Time between samples of the surface and the field, s.
    #[serde(default = "default_sample_interval")]
    pub sample_interval: Real,
    /// Start of the averages, s (default: when the first revolution is complete).
    pub average_after: Option<Real>,
}

fn default_sample_interval() -> Real {
    0.01
}

/// `[simulation]`.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SimulationSpec {
    /// Time step: a number of seconds, or `"auto"` for the suggested one.
    #[serde(default)]
    pub dt: TimeStepSpec,
    /// Simulated time at which the run ends.
    pub end_time: Real,
    /// Gravitational acceleration.
    #[serde(default = "default_gravity")]
    pub gravity: [Real; 3],
    /// Seed of the random generator (inlets, random orientations).
    #[serde(default)]
    pub seed: u64,
    /// Worker threads (0: all cores).
    #[serde(default)]
    pub threads: usize,
    /// End the run early once the bed has settled.
    #[serde(default)]
    pub settle: Option<SettleSpec>,
    /// What computes the steps.
    #[serde(default)]
    pub backend: BackendKind,
}

fn default_gravity() -> [Real; 3] {
    [0.0, 0.0, -9.81]
}

/// The time step: fixed or suggested.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(untagged)]
pub enum TimeStepSpec {
    /// Seconds.
    Fixed(Real),
    /// `"auto"`: the suggested step.
    #[default]
    #[serde(with = "auto")]
    Auto,
}

mod auto {
    use serde::{Deserialize, Deserializer, Serializer, de::Error};

    pub fn serialize<S: Serializer>(s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str("auto")
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<(), D::Error> {
        let s = String::deserialize(d)?;
        if s == "auto" {
            Ok(())
        } else {
            Err(D::Error::custom(
                "dt must be a number of seconds or \"auto\"",
            ))
        }
    }
}

/// When a run counts as settled: every particle slower than `max_speed` and the mean
/// kinetic energy per particle below `kinetic_energy_per_particle`, for `hold` seconds,
/// and no inlet still inserting.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SettleSpec {
    /// Largest particle speed, m/s.
    pub max_speed: Real,
    /// Mean kinetic energy per particle, J.
    #[serde(default = "infinite")]
    pub kinetic_energy_per_particle: Real,
    /// How long both must hold, s.
    #[serde(default)]
    pub hold: Real,
    /// Do not stop before this time, s.
    #[serde(default)]
    pub after: Real,
}

fn infinite() -> Real {
    Real::INFINITY
}

/// `[contact]`.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Regularisation length of the volume law, relative to the smaller equivalent
    /// radius (see `contact::normal_force`).
    #[serde(default = "default_regularisation")]
    pub regularisation: Real,
    /// Skin of the candidate lists, in metres (default 0.2 times the smallest
    /// bounding radius): the lists are rebuilt once a particle has moved half of it.
    /// Results do not depend on it; only the cost does.
    pub skin: Option<Real>,
    /// The law of contacts that involve a sphere: `"volume"` (default) or
    /// `"hertz_mindlin"` (polyhedron pairs follow the volume law either way).
    #[serde(default)]
    pub law: ContactLawSpec,
    /// Rolling resistance of Hertz–Mindlin contacts: `"none"` (default),
    /// `"constant_torque"` or `"elastic_plastic"` (materials' `rolling_friction`,
    /// `rolling_damping`).
    #[serde(default)]
    pub rolling: RollingModel,
}

/// `[contact] law`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ContactLawSpec {
    /// The volume law for every contact.
    #[default]
    Volume,
    /// Hertz–Mindlin for contacts that involve a sphere.
    HertzMindlin,
}

impl Default for ContactSpec {
    fn default() -> Self {
        ContactSpec {
            regularisation: default_regularisation(),
            skin: None,
            law: ContactLawSpec::Volume,
            rolling: RollingModel::None,
        }
    }
}

impl ContactSpec {
    /// The engine's law of contacts that involve a sphere.
    pub fn round_law(&self) -> RoundLaw {
        match self.law {
            ContactLawSpec::Volume => RoundLaw::Volume,
            ContactLawSpec::HertzMindlin => RoundLaw::HertzMindlin {
                rolling: self.rolling,
            },
        }
    }
}

fn default_regularisation() -> Real {
    crate::engine::REGULARISATION_LENGTH
}

/// `[output]`.
#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Output directory, relative to the scene file (the command line may override).
    pub dir: Option<PathBuf>,
    /// Interval between ParaView frames, s (none: first and last frame only).
    pub frame_interval: Option<Real>,
    /// Interval between rows of `walls.csv` and `energy.csv`, s (none: every frame).
    pub csv_interval: Option<Real>,
    /// Interval of simulated time between checkpoints of `talus run`, s (none: only
    /// `--checkpoint-every` and an interrupted run write one).
    pub checkpoint_interval: Option<Real>,
    /// How frames draw spheres (default: icospheres).
    #[serde(default)]
    pub spheres: SphereFrames,
}

/// How ParaView frames draw spheres (`[output] spheres`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SphereFrames {
    /// 80-facet icospheres: a sphere as a surface, as polyhedra are drawn.
    #[default]
    Icospheres,
    /// One point a sphere with its radius (ParaView: Point Gaussian or Glyph scaled
    /// by `radius`): a thousandth of the bytes, for beds of millions.
    Points,
}

/// A material (SI units).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Density, kg/m³.
    pub density: Real,
    /// Young's modulus, Pa.
    pub young: Real,
    /// Poisson's ratio.
    pub poisson: Real,
    /// Coefficient of restitution.
    pub restitution: Real,
    /// Coulomb friction coefficient.
    #[serde(default)]
    pub friction: Real,
    /// Rolling friction coefficient of the rolling-resistance models (`[contact]
    /// rolling`), default 0.
    #[serde(default)]
    pub rolling_friction: Real,
    /// Damping ratio of the elastic–plastic rolling spring, default 0.
    #[serde(default)]
    pub rolling_damping: Real,
}

/// `[[wall]]`.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct WallSpec {
    /// Name (unique), used in outputs and co-simulation variables.
    pub name: String,
    /// Material name.
    pub material: String,
    /// The surface.
    pub geometry: WallGeometrySpec,
    /// Reference point: frame origin, about which torque is reported (default: the
    /// rotation point of a rotating wall, else the world origin).
    pub reference: Option<[Real; 3]>,
    /// How the wall moves.
    #[serde(default)]
    pub motion: MotionSpec,
}

/// The surface of a wall.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum WallGeometrySpec {
    /// A triangle mesh file (STL or OBJ); facets face the particles.
    Mesh {
        /// Path relative to the scene file.
        file: PathBuf,
        /// Factor applied to the coordinates.
        #[serde(default = "one")]
        scale: Real,
        /// Turn every facet over (for a mesh whose normals point away from the
        /// particles).
        #[serde(default)]
        flip: bool,
    },
    /// A square patch.
    Plane {
        /// Centre.
        centre: [Real; 3],
        /// Normal, towards the particles.
        normal: [Real; 3],
        /// Edge length.
        size: Real,
    },
    /// The inside of an axis-aligned box.
    Box {
        /// Lower corner.
        min: [Real; 3],
        /// Upper corner.
        max: [Real; 3],
        /// Leave out the face at `max.z`.
        #[serde(default)]
        open_top: bool,
    },
    /// A flat disc or annulus.
    Disc {
        /// Centre.
        centre: [Real; 3],
        /// Normal, towards the particles.
        normal: [Real; 3],
        /// Outer radius.
        radius: Real,
        /// Radius of a central hole.
        #[serde(default)]
        inner_radius: Real,
        /// Polygon sides.
        #[serde(default = "default_sides")]
        sides: usize,
    },
    /// The inside of a cylinder (a tube, or a drum with both caps).
    Cylinder {
        /// Centre of the bottom end.
        base: [Real; 3],
        /// Axis direction (from the bottom end to the top end).
        axis: [Real; 3],
        /// Length along the axis.
        length: Real,
        /// Radius.
        radius: Real,
        /// Polygon sides.
        #[serde(default = "default_sides")]
        sides: usize,
        /// Rings of facets along the axis.
        #[serde(default = "one_usize")]
        segments: usize,
        /// Close the bottom end.
        #[serde(default)]
        bottom: bool,
        /// Close the top end.
        #[serde(default)]
        top: bool,
    },
    /// The inside of a cone frustum (a hopper).
    Cone {
        /// Centre of the bottom end.
        base: [Real; 3],
        /// Axis direction.
        axis: [Real; 3],
        /// Length along the axis.
        length: Real,
        /// Radius at the bottom end.
        radius_bottom: Real,
        /// Radius at the top end.
        radius_top: Real,
        /// Polygon sides.
        #[serde(default = "default_sides")]
        sides: usize,
        /// Rings of facets along the axis.
        #[serde(default = "one_usize")]
        segments: usize,
    },
}

impl WallGeometrySpec {
    /// The points and directions of the geometry, by field name.
    pub fn points(&self) -> Vec<(&'static str, &[Real; 3])> {
        match self {
            WallGeometrySpec::Mesh { .. } => Vec::new(),
            WallGeometrySpec::Plane { centre, normal, .. }
            | WallGeometrySpec::Disc { centre, normal, .. } => {
                vec![("centre", centre), ("normal", normal)]
            }
            WallGeometrySpec::Box { min, max, .. } => vec![("min", min), ("max", max)],
            WallGeometrySpec::Cylinder { base, axis, .. }
            | WallGeometrySpec::Cone { base, axis, .. } => vec![("base", base), ("axis", axis)],
        }
    }
}

fn one() -> Real {
    1.0
}

fn one_usize() -> usize {
    1
}

fn default_sides() -> usize {
    48
}

/// How a wall moves.
#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum MotionSpec {
    /// At rest.
    #[default]
    Fixed,
    /// Constant linear velocity.
    Linear {
        /// Velocity, m/s.
        velocity: [Real; 3],
    },
    /// Rotation about an axis through a point at a constant rate.
    Rotation {
        /// Axis direction (right-hand rule).
        axis: [Real; 3],
        /// Point on the axis (becomes the wall's reference point).
        #[serde(default)]
        point: [Real; 3],
        /// Revolutions per minute (or give `rate`).
        rpm: Option<Real>,
        /// Rad/s (or give `rpm`).
        rate: Option<Real>,
    },
    /// Harmonic translation `amplitude · sin(2π f t)`.
    Oscillation {
        /// Displacement amplitude vector, m.
        amplitude: [Real; 3],
        /// Frequency, Hz.
        frequency: Real,
    },
    /// Velocities interpolated linearly in time between keys.
    Table {
        /// The keys, in increasing time.
        keys: Vec<MotionKey>,
    },
    /// Driven from outside (co-simulation inputs), at rest until set.
    External {
        /// What the master gives: `velocity` (default) or `pose`.
        #[serde(default)]
        input: DriveInput,
    },
    /// Moves rigidly with another wall listed before this one, about the same
    /// reference point (the end caps of a drum); reported separately.
    Attached {
        /// Name of the wall it moves with.
        to: String,
    },
}

/// `[[particles]]`: particles present at the start.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ParticleGroupSpec {
    /// A simple cubic lattice filling a box.
    Lattice {
        /// Shape name.
        shape: String,
        /// Material name.
        material: String,
        /// Lower corner of the region the particles' bounding spheres stay in.
        min: [Real; 3],
        /// Upper corner.
        max: [Real; 3],
        /// Lattice spacing (default: 1.05 circumscribed diameters).
        spacing: Option<Real>,
        /// At most this many particles.
        count: Option<usize>,
        /// Random orientations (default) or the shape as given.
        #[serde(default = "yes")]
        random_orientation: bool,
        /// Initial velocity.
        #[serde(default)]
        velocity: [Real; 3],
        /// Keep only sites inside this cylinder (a drum's fill).
        inside: Option<CylinderRegionSpec>,
    },
    /// Particles listed one by one.
    List {
        /// Shape name.
        shape: String,
        /// Material name.
        material: String,
        /// The bodies.
        bodies: Vec<BodySpec>,
    },
    /// Poses from a CSV file with the header
    /// `x,y,z,qw,qx,qy,qz` (and optionally `vx,vy,vz,wx,wy,wz`).
    File {
        /// Shape name.
        shape: String,
        /// Material name.
        material: String,
        /// Path relative to the scene file.
        file: PathBuf,
    },
}

/// A cylindrical region for lattice sites: a particle is kept if its bounding sphere
/// lies inside the cylinder and its centre lies in the lowest `fill` of the
/// cross-section (measured along gravity).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CylinderRegionSpec {
    /// A point on the axis.
    pub centre: [Real; 3],
    /// Axis direction.
    pub axis: [Real; 3],
    /// Radius.
    pub radius: Real,
    /// Fraction of the cross-section's area, from its lowest point upwards, that the
    /// sites fill (default 1). The lattice is looser than a settled bed, so the bed
    /// settles lower.
    #[serde(default = "one")]
    pub fill: Real,
}

fn yes() -> bool {
    true
}

/// One listed particle.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Centroid.
    pub position: [Real; 3],
    /// Rotation vector (axis times angle, rad) applied to the shape as given.
    #[serde(default)]
    pub rotation: [Real; 3],
    /// Velocity.
    #[serde(default)]
    pub velocity: [Real; 3],
    /// Angular velocity.
    #[serde(default)]
    pub angular_velocity: [Real; 3],
}

/// `[[inlet]]`: inserts particles into a box at a rate.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct InletSpec {
    /// Shape name.
    pub shape: String,
    /// Material name.
    pub material: String,
    /// Lower corner of the insertion box (bounding spheres stay inside).
    pub min: [Real; 3],
    /// Upper corner.
    pub max: [Real; 3],
    /// Particles per second.
    pub rate: Real,
    /// Total number to insert.
    pub count: usize,
    /// Initial velocity.
    #[serde(default)]
    pub velocity: [Real; 3],
    /// Start time.
    #[serde(default)]
    pub start: Real,
    /// Stop feeding once the bed of the scene's `[bed]` section is this high: its bed
    /// height from the tube's base, counting the particles that touch another or a
    /// wall and move slower than half of √(g d) (not those in flight or sliding
    /// down the tube wall), measured every 5 ms of simulated time. `count`
    /// stays the upper limit. Particles in flight when feeding stops still land.
    pub bed_height: Option<Real>,
    /// Move the insertion box up the `[bed]` axis with the bed: it is shifted by
    /// the bed height measured every 5 ms (by nothing before there is a bed), so
    /// particles fall from the same height above the bed surface throughout a long
    /// fill, as from a loading sock lifted with the bed.
    #[serde(default)]
    pub above_bed: bool,
}
