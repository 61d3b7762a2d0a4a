//! The CPU backend's contact of one pair of particles, and the wall patches of one
//! particle, whole and alone: what the other backends' kernels are checked against
//! (`engine/cuda`'s tests).

use nalgebra::Vector3;

use super::dispatch::{ContactGeometry, facet_geometry, pair_geometry, pose_of};
use super::forces::{PairResult, pair_force};
use super::patch::{FacetPlane, Merge, PatchSet};
use super::walls::patch_force;
use crate::Real;
use crate::contact::TangentialHistory;
use crate::engine::cuda::device_wall_patches::WallPatch;
use crate::engine::cuda::device_wall_slots::WallContactResult;
use crate::engine::laws::ContactLaws;
use crate::geometry::overlap::OverlapCache;
use crate::geometry::wall::facet_normal;
use crate::world::World;

/// A pair's contact as the pair stage finds it: its result and the history it
/// leaves.
#[derive(Clone, Copy, Debug)]
pub(in crate::engine) struct ReferenceContact {
    /// Force on particle `j`; `i` gets the opposite.
    pub force: Vector3<Real>,
    /// Torques on `i` and on `j` about their centroids.
    pub torques: [Vector3<Real>; 2],
    pub energy: Real,
    pub dissipated: Real,
    pub touching: bool,
    pub history: TangentialHistory,
    /// The overlap's extent along the normal (0 apart).
    pub depth: Real,
}

/// The volume-law contact of particles `i` and `j` holding `history`, over a step
/// of `dt`, evaluated afresh (no kept overlap plan).
pub(in crate::engine) fn pair_contact(
    world: &World,
    i: usize,
    j: usize,
    history: &TangentialHistory,
    laws: &ContactLaws,
    dt: Real,
) -> ReferenceContact {
    let p = &world.particles;
    let mut plan = OverlapCache::default();
    let (result, history, depth) = match pair_geometry(world, i, j, &mut plan) {
        Some(g) => {
            let c = pair_force(world, i, j, &g, *history, laws, dt);
            let result = PairResult::new(&c, &p.position[i], &p.position[j]);
            (result, c.history, g.depth)
        }
        None => (
            PairResult::parted(history),
            TangentialHistory::default(),
            0.0,
        ),
    };
    ReferenceContact {
        force: result.force,
        torques: result.torques,
        energy: result.energy,
        dissipated: result.dissipated,
        touching: result.touching,
        history,
        depth,
    }
}

/// The patches of polyhedron `i` against every wall, as the wall stage assembles
/// them (`walls.rs`, `particle_contacts`): every facet of each wall in order, those
/// the centroid lies over within the bounding radius, summed by plane.
pub(in crate::engine) fn wall_patches(world: &World, i: usize) -> Vec<WallPatch> {
    let p = &world.particles;
    let shape = &world.body_types[p.body_type[i] as usize].shape;
    let (radius, pose) = (shape.circumradius(), pose_of(world, i));
    let mut found = Vec::new();
    let mut patches = PatchSet::default();
    for (w, wall) in world.walls.iter().enumerate() {
        patches.clear();
        for f in 0..wall.triangles.len() {
            let tri = wall.facet_world(f);
            let n = facet_normal(&tri);
            let height = n.dot(&(p.position[i] - tri[0]));
            if !(0.0..=radius).contains(&height) {
                continue;
            }
            if let Some(g) = facet_geometry(shape, &pose, &tri) {
                let key = FacetPlane::new(&n, &tri[0]).key(radius);
                patches.add(key, f as u32, g, Merge::Sum);
            }
        }
        found.extend(patches.iter().map(|(key, g, shares)| WallPatch {
            wall: w as u32,
            key,
            volume: g.volume,
            point: g.point,
            normal: g.normal,
            area: g.area,
            depth: g.depth,
            rotation_gradient: g.rotation_gradient.expect("a polyhedron's"),
            shares: shares.to_vec(),
        }));
    }
    found
}

/// The volume law's contacts of polyhedron `i`'s wall patches, as the wall stage
/// evaluates them (`walls.rs`, `particle_contacts`): each patch with an area and a
/// finite normal, holding the history `before(wall, key)` gives.
pub(in crate::engine) fn wall_contacts(
    world: &World,
    i: usize,
    laws: &ContactLaws,
    dt: Real,
    before: impl Fn(u32, [i64; 4]) -> TangentialHistory,
) -> Vec<WallContactResult> {
    let spin = world.angular_velocity(i);
    wall_patches(world, i)
        .into_iter()
        .filter(|p| p.area > 0.0 && p.normal.iter().all(|x| x.is_finite()))
        .map(|p| {
            let g = ContactGeometry {
                volume: p.volume,
                area: p.area,
                depth: p.depth,
                normal: p.normal,
                point: p.point,
                rotation_gradient: Some(p.rotation_gradient),
            };
            let c = patch_force(
                world,
                (i, &spin),
                p.wall as usize,
                &g,
                before(p.wall, p.key),
                laws,
                dt,
            );
            WallContactResult {
                wall: p.wall,
                key: p.key,
                force: c.force,
                torque: c.torque,
                energy: c.energy,
                dissipated: c.dissipated,
                history: c.history,
            }
        })
        .collect()
}
