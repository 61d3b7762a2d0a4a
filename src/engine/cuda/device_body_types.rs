//! The body types of a world on a device, as the contact kernels read them: the
//! polyhedra's shapes (`device_polyhedra.rs`), each type's volume-law row and the
//! pairs of materials' rows (`kernels/volume_law.cuh`), the spheres' Hertz–Mindlin
//! table (`device_hertz.rs`), and which laws the spheres follow.

use std::collections::HashMap;

use super::device::{Arg, Array, Device};
use super::device_hertz::HertzTypes;
use super::device_polyhedra::{DeviceShapes, ShapeTableError};
use crate::Real;
use crate::contact::RollingModel;
use crate::engine::laws::ContactLaws;
use crate::engine::params::RoundLaw;
use crate::geometry::{ConvexPolyhedron, is_isotropic};
use crate::world::World;

/// A sphere's shape index (`NO_SHAPE` of overlap.cuh).
pub(super) const NO_SHAPE: u32 = u32::MAX;
/// Doubles of a body type's law row (`TYPE_LAW_DOUBLES` of volume_law.cuh).
const TYPE_LAW: usize = 7;
/// Nodes of a damping table (`DAMPING_NODES`).
const DAMPING_NODES: usize = 21;
/// Doubles of a pair of materials' law row (`MATERIAL_LAW_DOUBLES`).
const MATERIAL_LAW: usize = 4 + DAMPING_NODES;
/// Doubles of a contact's history under the volume law (`VOLUME_HISTORY_DOUBLES`).
pub(super) const HISTORY: usize = 5;
/// Doubles of a Hertz–Mindlin history without twist (`HISTORY_DOUBLES`).
const SPRING: usize = 4;
/// Doubles of a history with a rolling spring (`ROLLING_HISTORY_DOUBLES`).
const ROLLING_HISTORY: usize = 8;

/// The body types of a world (polyhedra, spheres or both) and its pairs of
/// materials on a device, as the contact kernels read them.
///
/// # Invariant
/// Every polyhedron's shape is in `shapes` at `shape[t]`, a sphere's `shape[t]` is
/// [`NO_SHAPE`]; the law rows are those of the [`ContactLaws`] they were made
/// from, the Hertz–Mindlin table that of the same world.
#[derive(Debug, Default)]
pub struct DeviceBodyTypes {
    pub(super) shapes: DeviceShapes,
    /// Per body type, its shape's index in `shapes` ([`NO_SHAPE`]: a sphere).
    pub(super) shape: Array<u32>,
    /// The spheres' Hertz–Mindlin table.
    pub(super) hertz: HertzTypes,
    /// The law of the spheres' contacts.
    round: RoundLaw,
    mass: Array<Real>,
    /// Principal moments, three per type.
    inertia: Array<Real>,
    /// 1 where the three moments are equal (`is_isotropic`).
    isotropic: Array<u8>,
    /// The law rows (`TYPE_LAW_DOUBLES` of volume_law.cuh).
    pub(super) law: Array<Real>,
    material: Array<u32>,
    material_count: u32,
    /// Per pair of materials, row-major (`MATERIAL_LAW_DOUBLES`).
    pub(super) material_law: Array<Real>,
}

impl DeviceBodyTypes {
    /// The launch arguments of what the volume law reads of the body types and
    /// materials: mass, principal moments, isotropy, law rows, material, the
    /// material count and the material pairs' rows.
    pub(super) fn law_args(&self) -> [Arg; 7] {
        [
            self.mass.arg(),
            self.inertia.arg(),
            self.isotropic.arg(),
            self.law.arg(),
            self.material.arg(),
            Arg::U32(self.material_count),
            self.material_law.arg(),
        ]
    }

    /// Whether spheres follow the volume law (else Hertz–Mindlin), as the kernels'
    /// `round_volume` reads it.
    pub(super) fn round_volume(&self) -> u32 {
        u32::from(self.round == RoundLaw::Volume)
    }

    /// The spheres' rolling resistance under Hertz–Mindlin (`ROLLING_*` of
    /// contact.cuh).
    pub(super) fn rolling(&self) -> u32 {
        match self.round {
            RoundLaw::Volume
            | RoundLaw::HertzMindlin {
                rolling: RollingModel::None,
            } => 0,
            RoundLaw::HertzMindlin {
                rolling: RollingModel::ConstantTorque,
            } => 1,
            RoundLaw::HertzMindlin {
                rolling: RollingModel::ElasticPlastic,
            } => 2,
        }
    }

    /// Whether every contact is a sphere's under Hertz–Mindlin without rolling
    /// resistance (`sphere_contacts` steps the pairs).
    pub(super) fn spheres_under_hertz(&self) -> bool {
        let hertz = RoundLaw::HertzMindlin {
            rolling: RollingModel::None,
        };
        self.shapes.is_empty() && self.round == hertz
    }

    /// Doubles of a contact's tangential history: the spring and its stiffness
    /// (4: spheres under Hertz–Mindlin alone), the twist (5), and with rolling
    /// resistance the rolling spring (8).
    pub(super) fn history_width(&self) -> usize {
        if self.rolling() != 0 {
            ROLLING_HISTORY
        } else if self.spheres_under_hertz() {
            SPRING
        } else {
            HISTORY
        }
    }

    /// Bytes of device memory held.
    pub fn bytes(&self, device: &dyn Device) -> usize {
        let doubles = [&self.mass, &self.inertia, &self.law, &self.material_law];
        self.shapes.bytes(device)
            + self.hertz.bytes(device)
            + doubles.iter().map(|a| a.bytes(device)).sum::<usize>()
            + self.shape.bytes(device)
            + self.material.bytes(device)
            + self.isotropic.bytes(device)
    }

    /// Uploads the body types and materials of `world`, the laws' rows made for
    /// the regularisation length `regularisation_length` (relative to each body's
    /// volume-equivalent radius, as [`crate::engine::params`]' field); body types
    /// sharing a shape share its copy on the device.
    pub fn upload(
        device: &mut dyn Device,
        world: &World,
        regularisation_length: Real,
        round: RoundLaw,
    ) -> Result<Self, ShapeTableError> {
        let mut laws = ContactLaws::default();
        laws.prepare(world, regularisation_length, round);
        let mut distinct: Vec<&ConvexPolyhedron> = Vec::new();
        let mut index_of: HashMap<*const ConvexPolyhedron, u32> = HashMap::new();
        let mut shape = Vec::new();
        for body in &world.body_types {
            let Some(polyhedron) = body.shape.as_polyhedron() else {
                shape.push(NO_SHAPE);
                continue;
            };
            let k = *index_of.entry(polyhedron).or_insert_with(|| {
                distinct.push(polyhedron);
                distinct.len() as u32 - 1
            });
            shape.push(k);
        }
        let types = &world.body_types;
        let mut law = Vec::with_capacity(TYPE_LAW * types.len());
        let mut material = Vec::with_capacity(types.len());
        for row in laws.type_rows() {
            law.extend([
                row.stiffness.normal,
                row.stiffness.tangential,
                row.regularisation.volume(),
                row.regularisation.cbrt(),
                row.inverse_inertia,
                row.radius,
                row.inertia,
            ]);
            material.push(row.material as u32);
        }
        let mut material_law = Vec::new();
        for (friction, table, wall_series) in laws.material_rows() {
            // No table where no contact follows the volume law (spheres under
            // Hertz–Mindlin): a row of zeros, never read.
            let none = [0.0; DAMPING_NODES];
            let (restitution, nodes) = table.map_or((0.0, &none), |t| (t.restitution(), t.nodes()));
            material_law.extend([friction, restitution]);
            material_law.extend(nodes);
            material_law.extend([wall_series.normal, wall_series.tangential]);
        }
        debug_assert_eq!(
            material_law.len(),
            MATERIAL_LAW * laws.material_count().pow(2)
        );
        let mut uploaded = DeviceBodyTypes {
            round,
            shapes: DeviceShapes::upload(device, &distinct)?,
            hertz: HertzTypes::upload(device, world)?,
            material_count: laws.material_count() as u32,
            ..Default::default()
        };
        uploaded.shape.write(device, &shape)?;
        let masses: Vec<Real> = types.iter().map(|b| b.mass).collect();
        uploaded.mass.write(device, &masses)?;
        let inertia: Vec<Real> = types
            .iter()
            .flat_map(|b| b.inertia.iter().copied())
            .collect();
        uploaded.inertia.write(device, &inertia)?;
        let isotropic: Vec<u8> = types
            .iter()
            .map(|b| is_isotropic(&b.inertia) as u8)
            .collect();
        uploaded.isotropic.write(device, &isotropic)?;
        uploaded.law.write(device, &law)?;
        uploaded.material.write(device, &material)?;
        uploaded.material_law.write(device, &material_law)?;
        Ok(uploaded)
    }
}
