//! A particle placed in the bed frame ([`AxialBody`]: its volume clipped to slabs
//! of the tube and to discs about the axis is integrated there).

use nalgebra::Isometry3;

use crate::geometry::axial_volumes::AxialBody;
use crate::world::World;

/// Particle `i` of `world` placed in the bed frame `frame`.
pub(super) fn place<'a>(
    world: &'a World,
    i: usize,
    frame: &Isometry3<crate::Real>,
) -> AxialBody<'a> {
    let p = &world.particles;
    let pose = frame * Isometry3::from_parts(p.position[i].coords.into(), p.orientation[i]);
    AxialBody::new(&world.body_types[p.body_type[i] as usize].shape, &pose)
}
