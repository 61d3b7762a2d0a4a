//! The wall stage: every owned, moving particle against the facets its neighbour list
//! names, one contact per coplanar patch, in parallel over fixed chunks of particles,
//! each chunk adding its contacts to its particles as it finds them; then the
//! contacts are added to walls and facets in particle order, and their history is
//! kept in that order ([`WallHistory`]).
//!
//! Why the particles' sums in the chunks: added after the chunks, in one loop on one
//! thread, they read on two threads the force lines the other core had just
//! written, while that core waited (on the settled bed of 5000 spheres, the wall
//! stage's serial end was ~10 µs of a 0.55 ms step on two threads).
//!
//! The chunks keep their buffers between steps, so the stage allocates nothing once
//! the buffers have grown to the bed's needs.

use std::ops::Range;

use nalgebra::{Isometry3, Point3, Vector3};
use rayon::prelude::*;

use super::dispatch::{ContactGeometry, facet_geometry, pose_of};
use super::forces::{ContactForce, LawInputs, RelativeMotion, contact_force};
use super::hertz::{HertzInputs, rolling_inertia, round_contact_force};
use super::pairs::ContactTotals;
use super::patch::{FacetPlane, Merge, PatchSet};
use super::prefetch::fetch_shape;
use super::relative_motion::inverse_mass_at;
use super::shared_sums::SharedSums;
use super::type_table::TypeTable;
use super::wall_history::{WallEntry, WallHistory};
use crate::Real;
use crate::contact::TangentialHistory;
use crate::engine::RoundLaw;
use crate::engine::backend::WallKey;
use crate::engine::laws::ContactLaws;
use crate::engine::neighbours::NeighbourList;
use crate::geometry::Shape;
use crate::geometry::sphere::{inward_edge_normals, sphere_on_face};
use crate::geometry::wall::facet_normal;
use crate::world::{BodyType, Wall, World};

/// Particles near walls per chunk of the wall stage. Only the particles with listed
/// facets (or a patch to let go) are visited, and a particle's wall contacts can
/// cost as much as a hundred kick–drifts (a pellet against the facets of a tube), so
/// chunks are small enough for two threads to share them evenly.
const PARTICLES_PER_CHUNK: usize = 32;

/// How many visited particles ahead the shape of a particle near a wall is fetched: where
/// each particle has a shape of its own, the first read of each shape went to
/// memory (scene (d) of `talus bench`: the support query's scan of the vertices, 2 %
/// of a step), and a particle's facet contacts take long enough to cover a fetch.
const SHAPE_AHEAD: usize = 2;

/// One particle–wall contact: a coplanar patch of one wall's facets.
#[derive(Clone, Debug)]
struct WallContact {
    particle: u32,
    wall: u32,
    key: WallKey,
    force: ContactForce,
    /// The torque of the contact on the wall about its reference point.
    reaction: Vector3<Real>,
    /// The patch's facets with their shares of the overlap, in the chunk's `shares`.
    shares: Range<usize>,
}

/// The wall contacts of one chunk of particles, in particle order.
#[derive(Clone, Debug, Default)]
pub(super) struct WallChunk {
    contacts: Vec<WallContact>,
    shares: Vec<(u32, Real)>,
    patches: PatchSet,
    /// The patches of the step before that this step did not find, with their
    /// friction springs' energy.
    ended: Vec<(WallKey, Real)>,
}

/// What the wall stage reads besides the world.
#[derive(Clone, Copy, Debug)]
pub(super) struct WallInputs<'a> {
    pub list: &'a NeighbourList,
    pub laws: &'a ContactLaws,
    pub types: &'a TypeTable,
    /// The law of a sphere's contacts.
    pub round: RoundLaw,
    pub dt: Real,
}

/// One wall's facets in world coordinates with their unit normals and planes, as of
/// the pose they were placed at: a fixed wall's are placed once, a moving wall's once
/// a step, instead of once for every particle near a facet.
#[derive(Clone, Debug, Default)]
struct PlacedFacets {
    pose: Option<Isometry3<Real>>,
    triangles: Vec<[Point3<Real>; 3]>,
    normals: Vec<Vector3<Real>>,
    /// The triangles' inward edge normals (`geometry::sphere::inward_edge_normals`):
    /// whether a sphere's centre projects into a facet.
    edges: Vec<[Vector3<Real>; 3]>,
    planes: Vec<FacetPlane>,
}

impl PlacedFacets {
    /// Places `wall`'s facets unless they are placed at its pose already.
    fn update(&mut self, wall: &Wall) {
        if self.pose == Some(wall.pose) && self.triangles.len() == wall.triangles.len() {
            return;
        }
        self.pose = Some(wall.pose);
        self.triangles.clear();
        self.triangles
            .extend((0..wall.triangles.len()).map(|f| wall.facet_world(f)));
        self.normals.clear();
        self.normals.extend(self.triangles.iter().map(facet_normal));
        self.edges.clear();
        (self.edges).extend(
            (self.triangles.iter().zip(&self.normals)).map(|(t, n)| inward_edge_normals(t, n)),
        );
        self.planes.clear();
        (self.planes).extend(
            (self.triangles.iter().zip(&self.normals)).map(|(t, n)| FacetPlane::new(n, &t[0])),
        );
    }
}

/// The stage's buffers.
#[derive(Clone, Debug, Default)]
pub(super) struct WallWork {
    chunks: Vec<WallChunk>,
    /// Every wall's facets as placed in the world.
    placed: Vec<PlacedFacets>,
    /// The patches' history being written this step (swapped with the kept one).
    next_history: WallHistory,
    /// The contacts that ended this step, with their friction springs' energy.
    ended: Vec<(WallKey, Real)>,
    /// The particles the stage visits, ascending: those near walls and those that
    /// hold patches of the step before.
    visit: Vec<u32>,
}

/// Evaluates and applies the wall contacts: particle forces and torques, wall forces,
/// torques and facet forces, the touching flags; replaces `history` by the patches'
/// new history. Adds the contacts' count and energies to `totals` (the pairs'
/// figures: the energies are summed on in the same order as ever).
pub(super) fn wall_contacts(
    world: &mut World,
    inputs: WallInputs,
    history: &mut WallHistory,
    work: &mut WallWork,
    touching: &mut [bool],
    mut totals: ContactTotals,
) -> ContactTotals {
    for wall in &mut world.walls {
        wall.force = Vector3::zeros();
        wall.torque = Vector3::zeros();
        wall.facet_force
            .iter_mut()
            .for_each(|f| *f = Vector3::zeros());
    }
    // Aligned at the list's builds: the world's ids do not change without one.
    debug_assert!(history.is_aligned_to(&world.particles.id));
    union_ascending(inputs.list.near_walls(), history.holders(), &mut work.visit);
    let visit = &work.visit[..];
    let chunks = visit.len().div_ceil(PARTICLES_PER_CHUNK);
    if work.chunks.len() < chunks {
        work.chunks.resize_with(chunks, WallChunk::default);
    }
    work.placed
        .resize_with(world.walls.len(), PlacedFacets::default);
    for (placed, wall) in work.placed.iter_mut().zip(&world.walls) {
        placed.update(wall);
    }
    // The particles' sums are written outside the world while the contacts read it,
    // each by the chunk that visits the particle (`visit` has no repeats): a
    // particle's wall contacts are added after its pairs, in the order found.
    let mut force = std::mem::take(&mut world.particles.force);
    let mut torque = std::mem::take(&mut world.particles.torque);
    let sums = SharedSums::over(&mut force, &mut torque, touching);
    let w = &*world;
    let kept = &*history;
    let placed = &work.placed;
    work.chunks[..chunks]
        .par_iter_mut()
        .enumerate()
        .for_each(|(c, chunk)| {
            chunk.contacts.clear();
            chunk.shares.clear();
            chunk.ended.clear();
            let start = c * PARTICLES_PER_CHUNK;
            for v in start..(start + PARTICLES_PER_CHUNK).min(visit.len()) {
                if let Some(&ahead) = visit.get(v + SHAPE_AHEAD)
                    && inputs.types.fetch_shapes()
                {
                    fetch_shape(inputs.types, w.particles.body_type[ahead as usize]);
                }
                let i = visit[v] as usize;
                let (first, before) = (chunk.contacts.len(), kept.of_particle(i));
                if !w.particles.is_passive(i) {
                    particle_contacts(w, i, &inputs, placed, before, chunk);
                }
                if chunk.contacts.len() > first {
                    // SAFETY: particle `i` is this chunk's visit alone.
                    let (force, torque, touching) = unsafe { sums.of(i) };
                    for contact in &chunk.contacts[first..] {
                        *force += contact.force.force;
                        *torque += contact.force.torque;
                    }
                    *touching = true;
                }
                chunk.end_missing(before, first);
            }
        });
    world.particles.force = force;
    world.particles.torque = torque;

    let next = &mut work.next_history;
    next.begin(&world.particles.id);
    for chunk in &work.chunks[..chunks] {
        for contact in &chunk.contacts {
            let (i, c) = (contact.particle as usize, &contact.force);
            totals.contacts += 1;
            totals.energy += c.energy;
            totals.dissipated += c.dissipated;
            let wall = &mut world.walls[contact.wall as usize];
            wall.force -= c.force;
            wall.torque += contact.reaction;
            let facets = &chunk.shares[contact.shares.clone()];
            let total: Real = facets.iter().map(|f| f.1).sum();
            if total > 0.0 {
                for &(f, share) in facets {
                    wall.facet_force[f as usize] -= c.force * (share / total);
                }
            }
            if !c.history.is_empty() {
                next.push(i, (contact.key, c.history));
            }
        }
    }
    next.finish();
    // The contacts that ended let their friction springs go, in key order (the
    // energies are summed in an order that does not depend on the chunks).
    work.ended.clear();
    (work.ended).extend(
        history
            .orphans()
            .iter()
            .map(|(k, h)| (*k, h.spring_energy())),
    );
    for chunk in &work.chunks[..chunks] {
        work.ended.extend_from_slice(&chunk.ended);
    }
    work.ended.sort_unstable_by_key(|e| e.0);
    totals.dissipated += work.ended.iter().map(|e| e.1).sum::<Real>();
    std::mem::swap(history, next);
    totals
}

/// Sets `union` to the elements of `a` and `b` (each ascending, without repeats),
/// ascending, each once.
fn union_ascending(a: &[u32], b: &[u32], union: &mut Vec<u32>) {
    union.clear();
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        let (x, y) = (a[i], b[j]);
        union.push(x.min(y));
        i += usize::from(x <= y);
        j += usize::from(y <= x);
    }
    union.extend_from_slice(&a[i..]);
    union.extend_from_slice(&b[j..]);
}

/// Whether particle `i` has facets of some wall in its list.
#[inline]
fn near_walls(world: &World, inputs: &WallInputs, i: usize) -> bool {
    (0..world.walls.len()).any(|w| !inputs.list.facets(i, w).is_empty())
}

impl WallChunk {
    /// Ends the patches of `before` (a particle's of the step before) that none of
    /// the contacts from `first` on continues.
    #[inline]
    fn end_missing(&mut self, before: &[WallEntry], first: usize) {
        for (key, h) in before {
            if !self.contacts[first..].iter().any(|c| c.key == *key) {
                self.ended.push((*key, h.spring_energy()));
            }
        }
    }
}

/// Contacts of particle `i` with every wall, one per coplanar patch of facets, pushed
/// onto `chunk`; `before` holds the particle's patches of the step before.
fn particle_contacts(
    world: &World,
    i: usize,
    inputs: &WallInputs,
    placed: &[PlacedFacets],
    before: &[WallEntry],
    chunk: &mut WallChunk,
) {
    let WallInputs {
        list,
        laws,
        types,
        round,
        dt,
    } = *inputs;
    // Most particles of a bed are far from every wall: leave before anything else.
    if !near_walls(world, inputs, i) {
        return;
    }
    let p = &world.particles;
    let t = &world.body_types[p.body_type[i] as usize];
    let radius = types.radius(p.body_type[i]);
    // The angular velocity, once a patch is found: a particle listed near a wall
    // often touches none of its facets.
    let mut spin = None;
    for (w, wall) in world.walls.iter().enumerate() {
        let facets = list.facets(i, w);
        if facets.is_empty() {
            continue;
        }
        facet_patches(
            world,
            i,
            (t, radius),
            facets,
            &placed[w],
            &mut chunk.patches,
        );
        for (key, g, facet_shares) in chunk.patches.iter() {
            if !(g.area > 0.0) || !g.normal.iter().all(|x| x.is_finite()) {
                continue;
            }
            let spin = *spin.get_or_insert_with(|| world.angular_velocity(i));
            let wall_key = (p.id[i], w as u32, key);
            let h =
                (before.iter().find(|e| e.0 == wall_key)).map_or_else(Default::default, |e| e.1);
            let force = match (round, &t.shape, laws.sphere(p.body_type[i])) {
                (RoundLaw::HertzMindlin { rolling }, Shape::Sphere(s), Some(sphere)) => {
                    // The law's moment of inertia enters the volume law's torques
                    // alone.
                    let motion = RelativeMotion::of_wall(
                        world,
                        (i, &spin),
                        wall,
                        &g.point,
                        (sphere.inverse_mass, 0.0),
                    );
                    let law = HertzInputs {
                        materials: laws.materials(t.material, wall.material),
                        rolling,
                        radius: s.radius,
                        rolling_inertia: rolling_inertia(t, s.radius),
                        dt,
                    };
                    round_contact_force(
                        g.depth,
                        &g.normal,
                        &(g.point - p.position[i]),
                        &motion,
                        &law,
                        &h,
                    )
                }
                _ => patch_force(world, (i, &spin), w, g, h, laws, dt),
            };
            let start = chunk.shares.len();
            chunk.shares.extend_from_slice(facet_shares);
            chunk.contacts.push(WallContact {
                particle: i as u32,
                wall: w as u32,
                key: wall_key,
                reaction: force.reaction_torque(&wall.reference(), &p.position[i]),
                force,
                shares: start..chunk.shares.len(),
            });
        }
    }
}

/// Sets `patches` to the patches of particle `i` (body type `t` of bounding radius
/// `radius`) on the listed `facets` of one wall.
#[inline]
fn facet_patches(
    world: &World,
    i: usize,
    (t, radius): (&BodyType, Real),
    facets: &[u32],
    placed: &PlacedFacets,
    patches: &mut PatchSet,
) {
    patches.clear();
    let centre = world.particles.position[i];
    let merge = match t.shape {
        Shape::Polyhedron(_) => Merge::Sum,
        Shape::Sphere(_) => Merge::Deepest,
    };
    // The pose, once a facet needs the general test: a sphere whose centre
    // projects into a facet of each plane it touches needs none.
    let mut pose = None;
    for &f in facets {
        let (tri, n, plane) = (
            &placed.triangles[f as usize],
            &placed.normals[f as usize],
            &placed.planes[f as usize],
        );
        // Walls are one-sided: a particle whose centroid is behind a facet's plane
        // has passed it (or the mesh faces the wrong way) and is not pushed back
        // through from behind, where the half-infinite prism would meet it with
        // its whole volume at once. A centroid farther from the plane than the
        // bounding radius keeps the whole body off the facet.
        let height = n.dot(&(centre - tri[0]));
        if !(0.0..=radius).contains(&height) {
            continue;
        }
        let key = plane.key(radius);
        if let Shape::Sphere(s) = &t.shape {
            // A sphere over a flat patch: the plane's contact, from the first
            // facet the centre projects into; the patch's other facets are not
            // searched for their closest points.
            if patches.has_face(&key) {
                continue;
            }
            let edges = &placed.edges[f as usize];
            if let Some(c) = sphere_on_face(tri, n, edges, &centre, s.radius, height) {
                patches.add_face(key, f, c.into());
                continue;
            }
        }
        let pose = pose.get_or_insert_with(|| pose_of(world, i));
        if let Some(g) = facet_geometry(&t.shape, pose, tri) {
            patches.add(key, f, g, merge);
        }
    }
}

/// The volume law's contact of particle `i` (turning at `spin`) with its patch `g`
/// on wall `w`, holding history `h`.
pub(super) fn patch_force(
    world: &World,
    (i, spin): (usize, &Vector3<Real>),
    w: usize,
    g: &ContactGeometry,
    h: TangentialHistory,
    laws: &ContactLaws,
    dt: Real,
) -> ContactForce {
    let p = &world.particles;
    let wall = &world.walls[w];
    let law = laws.wall(p.body_type[i], wall.material);
    // A sphere's lever to its contact point lies along the normal, so its effective
    // mass there is its mass: nothing is turned into its body frame.
    let inverse_mass = laws.sphere(p.body_type[i]).map_or_else(
        || inverse_mass_at(world, i, &g.point, &g.normal),
        |s| s.inverse_mass,
    );
    let motion = RelativeMotion::of_wall(
        world,
        (i, spin),
        wall,
        &g.point,
        (inverse_mass, law.inertia),
    );
    contact_force(
        g,
        &motion,
        &LawInputs::new(laws, &law, dt),
        h,
        &p.position[i],
    )
}
