//! What the Hertz–Mindlin contacts of spheres read on a device
//! (`HertzTable` of `kernels/contact.cuh`): per body type its bounding radius (a
//! sphere's radius), 1/m, 1/I, rolling inertia and material, and whether it is a
//! sphere; per pair of materials its row.

use super::device::{Arg, Array, Device, DeviceError};
use crate::Real;
use crate::contact::{HertzMindlinPair, RollingParameters, pair_restitution};
use crate::world::World;

/// The Hertz–Mindlin table of a world's body types and materials on a device.
///
/// # Invariant
/// One entry per body type of the world it was made from in `radius`,
/// `inverse_mass`, `inverse_inertia`, `rolling_inertia`, `material` and `sphere`;
/// `material_pairs` holds `materials²` rows (row-major) of E*, G*, β, √(4G*/E*),
/// the mean friction coefficient and the mean rolling friction and damping, by the
/// operations of `engine::laws::ContactLaws::prepare`.
#[derive(Debug, Default)]
pub(super) struct HertzTypes {
    pub radius: Array<Real>,
    pub inverse_mass: Array<Real>,
    pub inverse_inertia: Array<Real>,
    /// `I + m r²` about a contact on a sphere's surface (`engine/cpu/hertz.rs`,
    /// `rolling_inertia`, I the smallest principal moment).
    pub rolling_inertia: Array<Real>,
    pub material: Array<u32>,
    pub material_pairs: Array<Real>,
    pub materials: u32,
    /// Per body type, 1 where it is a sphere.
    pub sphere: Array<u8>,
}

impl HertzTypes {
    /// The table of `world`'s body types (a polyhedron's radius is its
    /// circumradius; its other entries go unread).
    pub fn upload(d: &mut dyn Device, world: &World) -> Result<Self, DeviceError> {
        let bodies = &world.body_types;
        let per_type = |f: &dyn Fn(&crate::world::BodyType) -> Real| -> Vec<Real> {
            bodies.iter().map(f).collect()
        };
        let mut types = HertzTypes::default();
        types
            .radius
            .write(d, &per_type(&|t| t.shape.circumradius()))?;
        types.inverse_mass.write(d, &per_type(&|t| 1.0 / t.mass))?;
        types
            .inverse_inertia
            .write(d, &per_type(&|t| 1.0 / t.inertia.x))?;
        types.rolling_inertia.write(
            d,
            &per_type(&|t| {
                let r = t.shape.circumradius();
                t.inertia.min() + t.mass * r * r
            }),
        )?;
        let material: Vec<u32> = bodies.iter().map(|t| t.material as u32).collect();
        types.material.write(d, &material)?;
        let sphere: Vec<u8> = (bodies.iter())
            .map(|t| u8::from(t.shape.as_sphere().is_some()))
            .collect();
        types.sphere.write(d, &sphere)?;
        let mut rows = Vec::new();
        for a in &world.materials {
            for b in &world.materials {
                let e = pair_restitution(a.restitution, b.restitution);
                let h = HertzMindlinPair::new(a, b, e);
                let rolling = RollingParameters::mean(a, b);
                rows.extend([
                    h.young,
                    h.shear,
                    h.beta,
                    h.damping_ratio,
                    0.5 * (a.friction + b.friction),
                    rolling.friction,
                    rolling.damping,
                ]);
            }
        }
        types.material_pairs.write(d, &rows)?;
        types.materials = world.materials.len() as u32;
        Ok(types)
    }

    /// The table as launch arguments, as `HertzTable`: radius, 1/m, 1/I, rolling
    /// inertia, material, the material count, the pairs' rows.
    pub fn args(&self) -> [Arg; 7] {
        [
            self.radius.arg(),
            self.inverse_mass.arg(),
            self.inverse_inertia.arg(),
            self.rolling_inertia.arg(),
            self.material.arg(),
            Arg::U32(self.materials),
            self.material_pairs.arg(),
        ]
    }

    /// Bytes of device memory held.
    pub fn bytes(&self, d: &dyn Device) -> usize {
        let doubles = [
            &self.radius,
            &self.inverse_mass,
            &self.inverse_inertia,
            &self.rolling_inertia,
            &self.material_pairs,
        ];
        doubles.iter().map(|a| a.bytes(d)).sum::<usize>()
            + self.material.bytes(d)
            + self.sphere.bytes(d)
    }
}
