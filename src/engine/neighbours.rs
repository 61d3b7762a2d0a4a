//! Verlet lists: the candidate particle pairs and particle–facet candidates of the
//! last broad phase, kept while no particle has moved far enough to make a new
//! contact that the lists miss.
//!
//! # Invariant
//! The lists were built with every reach widened by the skin `s`: a pair `(i, j)` is
//! listed when `|x_i − x_j| < r_i + r_j + s`, and a facet of wall `w` is listed for
//! particle `i` when its bounding box meets the ball of radius `r_i + s` about `x_i` in
//! the wall's frame. They are rebuilt before any particle has moved more than `s / 2`
//! in the world since the build (then two particles have approached by less than `s`)
//! or more than `s` in the frame of a wall (a wall frame carries its facets rigidly),
//! and whenever the particles or the walls' meshes change. So every pair whose bounding
//! spheres overlap, and every facet a particle's bounding sphere can reach, is listed.
//!
//! # Order
//! Pairs are sorted by the space keys of their two particles (the smaller, then the
//! larger: the cell code of the particle's place at the last refresh of the space
//! order, then its id, see [`crate::world::SpaceOrder`]), and a pair's first
//! particle is the one of smaller id; each particle's facets are sorted by index.
//! So the contacts found through the lists come in an order that depends on the
//! state alone, neither on when the lists were built (a run restored from a saved
//! state continues bit for bit) nor on where the particles lie in the arrays: a pair
//! is evaluated with the same particle first, and each particle gathers its pairs
//! in the order of its partners' keys, whether the particles are stored in that
//! order or not (a rank of a domain decomposition keeps its own particles first and
//! copies of its neighbours' after them).
//!
//! # Why
//! Rebuilding the grid, counting and writing the pairs every step cost as much as the
//! sphere contacts themselves; a settled bed keeps its lists for hundreds of steps,
//! and a falling one for a few dozen at the suggested step.

use nalgebra::{Isometry3, Point3};
use rayon::prelude::*;

use super::broad_phase::BroadPhase;
use super::pair_sort::PairSort;
use crate::Real;
use crate::world::{Particles, World};

/// One particle's share in a listed pair: the pair's index into
/// [`NeighbourList::pairs`] and whether the particle is the pair's first (`i` of
/// `[i, j]`), packed in 32 bits (the role in the top bit) so that the gather reads one
/// word per pair and never the pair itself.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Incidence(u32);

impl Incidence {
    const FIRST: u32 = 1 << 31;

    /// Pair `index` (below 2³¹) with the particle as its first (`first`) or second.
    fn new(index: usize, first: bool) -> Self {
        debug_assert!(index < Self::FIRST as usize);
        Incidence(index as u32 | if first { Self::FIRST } else { 0 })
    }

    /// Index of the pair in [`NeighbourList::pairs`].
    #[inline]
    pub fn pair(self) -> usize {
        (self.0 & !Self::FIRST) as usize
    }

    /// Whether the particle is the pair's first.
    #[inline]
    pub fn is_first(self) -> bool {
        self.0 & Self::FIRST != 0
    }
}

/// What a build of the lists started from: each particle's id and position, in the
/// order the world held them, and each wall's pose.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ListAnchors {
    /// Id and position of every particle at the build.
    pub particles: Vec<(u64, Point3<Real>)>,
    /// Pose of every wall at the build.
    pub wall_poses: Vec<Isometry3<Real>>,
}

/// Skin as a fraction of the smallest bounding radius when none is set.
pub const DEFAULT_SKIN: Real = 0.2;

/// Particles per task of the facet lists' build.
const FACET_CHUNK: usize = 256;

/// Particles per task of the look whether the lists are stale.
const STALE_CHUNK: usize = 1024;

/// The candidate lists of one engine (see the module docs for the invariant).
#[derive(Clone, Debug, Default)]
pub struct NeighbourList {
    /// Skin width; `None`: [`DEFAULT_SKIN`] times the smallest bounding radius.
    pub skin: Option<Real>,
    broad: BroadPhase,
    /// Candidate pairs `[i, j]`, `id[i] < id[j]`, sorted by the space keys of their
    /// particles (the smaller, then the larger).
    pairs: Vec<[u32; 2]>,
    /// `incident[incident_starts[k]..incident_starts[k + 1]]`: the pairs holding
    /// particle `k`, ascending (so its partners come in the order of their keys).
    incident_starts: Vec<u32>,
    incident: Vec<Incidence>,
    /// `facets[facet_starts[k * walls + w]..facet_starts[k * walls + w + 1]]`: the
    /// facets of wall `w` near particle `k`, ascending.
    facet_starts: Vec<u32>,
    facets: Vec<u32>,
    /// The particles with a facet of some wall in their lists, ascending.
    near_walls: Vec<u32>,
    /// What the lists were built from: particle ids and positions, positions in every
    /// wall's frame (particle-major), and each wall's facet count and pose.
    ids: Vec<u64>,
    anchors: Vec<Point3<Real>>,
    wall_anchors: Vec<Point3<Real>>,
    wall_facets: Vec<usize>,
    wall_poses: Vec<Isometry3<Real>>,
    /// Skin the lists were built with.
    built_skin: Real,
    valid: bool,
    builds: u64,
    /// A saved build to start the next build from, where the particles have not
    /// moved beyond its limits since ([`Self::resume_from`]).
    resumed: Option<ListAnchors>,
    /// The buffers of the pairs' sort by index.
    sort: PairSort,
    /// Whether the pairs ascend by their particles' indices (each pair read smaller
    /// index first): the particles were stored in the order of their space keys.
    by_index: bool,
}

impl NeighbourList {
    /// Makes the lists stale ([`Self::is_stale`]) until the next build.
    pub fn invalidate(&mut self) {
        self.valid = false;
    }

    /// Candidate pairs, the particle of smaller id first, sorted by the space keys
    /// of the two particles (the smaller, then the larger).
    pub fn pairs(&self) -> &[[u32; 2]] {
        &self.pairs
    }

    /// Whether the pairs, each read smaller index first, ascend, and were found
    /// among particles of `ids` (index by index): a list built next for the same
    /// particles in the same order pairs them as this one would, so that a pair's
    /// history is found by walking the two lists side by side.
    pub fn ascends_by_index_of(&self, ids: &[u64]) -> bool {
        self.by_index && self.ids == ids
    }

    /// What the last build started from (or the saved build the next one will start
    /// from); `None` when the lists are stale for other particles or walls.
    pub fn anchors(&self) -> Option<ListAnchors> {
        if !self.valid {
            return self.resumed.clone();
        }
        Some(ListAnchors {
            particles: self
                .ids
                .iter()
                .copied()
                .zip(self.anchors.iter().copied())
                .collect(),
            wall_poses: self.wall_poses.clone(),
        })
    }

    /// Makes the next build start from `anchors` (a saved [`Self::anchors`]) if the
    /// world then holds the same particles in the same order and walls as many, and
    /// no particle has moved beyond the lists' limits from them; otherwise it starts
    /// from the world as it is.
    pub fn resume_from(&mut self, anchors: ListAnchors) {
        self.valid = false;
        self.resumed = Some(anchors);
    }

    /// Particles of the world the lists were built for.
    pub fn particle_count(&self) -> usize {
        self.incident_starts.len().saturating_sub(1)
    }

    /// The pairs holding particle `k`, ascending.
    pub fn incident(&self, k: usize) -> &[Incidence] {
        &self.incident[self.incident_starts[k] as usize..self.incident_starts[k + 1] as usize]
    }

    /// Facets of wall `w` that particle `k` may touch, ascending.
    pub fn facets(&self, k: usize, w: usize) -> &[u32] {
        let slot = k * self.wall_facets.len() + w;
        &self.facets[self.facet_starts[slot] as usize..self.facet_starts[slot + 1] as usize]
    }

    /// The particles with a facet of some wall in their lists, ascending: the only
    /// ones that may touch a wall (in a bed a wall's neighbours are a few of its
    /// particles, and the wall stage visits these alone).
    pub fn near_walls(&self) -> &[u32] {
        &self.near_walls
    }

    /// The ids of the two particles of a listed pair (as they were at the build).
    pub fn pair_ids(&self, [i, j]: [u32; 2]) -> (u64, u64) {
        (self.ids[i as usize], self.ids[j as usize])
    }

    /// Number of builds so far.
    pub fn builds(&self) -> u64 {
        self.builds
    }

    /// Whether the lists must be rebuilt before they are used for `world`: never
    /// built or invalidated, other particles or wall meshes, or moved too far.
    pub fn is_stale(&self, world: &World) -> bool {
        let p = &world.particles;
        if !self.valid
            || p.id.len() != self.ids.len()
            || world.walls.len() != self.wall_facets.len()
            || world
                .walls
                .iter()
                .zip(&self.wall_facets)
                .any(|(w, &n)| w.triangles.len() != n)
        {
            return true;
        }
        let s = self.built_skin;
        let (pair_limit, wall_limit) = ((0.5 * s) * (0.5 * s), s * s);
        let walls = self.wall_facets.len();
        // A wall at its pose of the build sees a particle move as far as the world
        // does, and the pairs' limit is the stricter: only moved walls are checked.
        let moved = |w: usize| world.walls[w].pose != self.wall_poses[w];
        let any_moved = (0..walls).any(moved);
        let n = p.len();
        (0..n.div_ceil(STALE_CHUNK)).into_par_iter().any(|c| {
            let chunk = c * STALE_CHUNK..n.min((c + 1) * STALE_CHUNK);
            // Without a branch per particle: the displacements are compared in a
            // fold, and the chunk asks once (one thread's look at the pour of 5000
            // spheres took 25 µs a step with a branch each, 2026-12-07). The ids are
            // compared chunk by chunk too, on the threads side by side.
            let far = (p.position[chunk.clone()].iter())
                .zip(&self.anchors[chunk.clone()])
                .fold(false, |far, (x, a)| {
                    far | ((x - a).norm_squared() >= pair_limit)
                });
            far || p.id[chunk.clone()] != self.ids[chunk.clone()]
                || any_moved
                    && chunk.into_iter().any(|k| {
                        world.walls.iter().enumerate().any(|(w, wall)| {
                            moved(w) && {
                                let local = wall.pose.inverse_transform_point(&p.position[k]);
                                (local - self.wall_anchors[k * walls + w]).norm_squared()
                                    >= wall_limit
                            }
                        })
                    })
        })
    }

    /// Builds the lists for `world` (`radii`: each particle's bounding radius).
    pub fn build(&mut self, world: &World, radii: &[Real]) {
        let p = &world.particles;
        let n = p.len();
        let skin = self.skin.unwrap_or_else(|| automatic_skin(radii));
        let skin = if skin.is_finite() { skin.max(0.0) } else { 0.0 };
        self.built_skin = skin;
        let resumed = (self.resumed.take()).is_some_and(|a| self.anchor_at_saved(world, a));
        if !resumed {
            self.anchor_at(world);
        }

        self.broad
            .find_pairs(&self.anchors, radii, skin, &mut self.pairs);
        self.by_index = sort_pairs(&mut self.pairs, p, &mut self.sort);
        self.index_incident(n);

        // Each chunk of particles' facets laid end to end, with where each slot's
        // end (a list per slot cost an allocation per particle and wall).
        let walls = world.walls.len();
        let chunks: Vec<(Vec<u32>, Vec<u32>)> = (0..n.div_ceil(FACET_CHUNK))
            .into_par_iter()
            .map(|c| {
                let (mut facets, mut ends, mut found) = (Vec::new(), Vec::new(), Vec::new());
                for slot in c * FACET_CHUNK * walls..((c + 1) * FACET_CHUNK).min(n) * walls {
                    let (k, w) = (slot / walls, slot % walls);
                    world.walls[w].grid.query(
                        &self.wall_anchors[slot],
                        radii[k] + skin,
                        &mut found,
                    );
                    facets.extend_from_slice(&found);
                    ends.push(facets.len() as u32);
                }
                (facets, ends)
            })
            .collect();
        self.facet_starts.clear();
        self.facet_starts.push(0);
        self.facets.clear();
        for (facets, ends) in chunks {
            let base = self.facets.len() as u32;
            self.facet_starts.extend(ends.iter().map(|&end| base + end));
            self.facets.extend_from_slice(&facets);
        }
        self.near_walls.clear();
        if walls > 0 {
            let starts = self.facet_starts.chunks_exact(walls);
            let ends = self.facet_starts[1..].chunks_exact(walls);
            (self.near_walls).extend(
                (starts.zip(ends).enumerate())
                    .filter(|(_, (s, e))| s[0] != e[walls - 1])
                    .map(|(k, _)| k as u32),
            );
        }
        self.valid = true;
        self.builds += 1;
    }

    /// Takes the world's particles and walls as they are as the build's anchors.
    fn anchor_at(&mut self, world: &World) {
        let p = &world.particles;
        self.ids.clone_from(&p.id);
        self.anchors.clone_from(&p.position);
        self.wall_poses.clear();
        self.wall_poses.extend(world.walls.iter().map(|w| w.pose));
        self.anchor_walls(world);
    }

    /// Takes `saved` as the build's anchors if they fit the world (see
    /// [`Self::resume_from`]); returns whether they did.
    fn anchor_at_saved(&mut self, world: &World, saved: ListAnchors) -> bool {
        let p = &world.particles;
        if saved.particles.len() != p.len()
            || saved.wall_poses.len() != world.walls.len()
            || saved.particles.iter().zip(&p.id).any(|(a, &id)| a.0 != id)
        {
            return false;
        }
        self.ids.clone_from(&p.id);
        self.anchors.clear();
        self.anchors.extend(saved.particles.iter().map(|a| a.1));
        self.wall_poses = saved.wall_poses;
        self.anchor_walls(world);
        self.valid = true;
        let fits = !self.is_stale(world);
        self.valid = false;
        fits
    }

    /// The anchors in every wall's frame at the build, and the walls' facet counts.
    fn anchor_walls(&mut self, world: &World) {
        self.wall_anchors.clear();
        self.wall_anchors.extend(
            (self.anchors.iter())
                .flat_map(|x| self.wall_poses.iter().map(move |pose| (x, pose)))
                .map(|(x, pose)| pose.inverse_transform_point(x)),
        );
        self.wall_facets.clear();
        self.wall_facets
            .extend(world.walls.iter().map(|w| w.triangles.len()));
    }

    /// Fills the per-particle incidence lists of the (sorted) pairs: each list
    /// ascending, so a particle meets its partners in the order of their keys.
    fn index_incident(&mut self, n: usize) {
        assert!(
            self.pairs.len() < Incidence::FIRST as usize,
            "{} candidate pairs: at most 2³¹ fit the incidence lists",
            self.pairs.len()
        );
        self.incident_starts.clear();
        self.incident_starts.resize(n + 1, 0);
        for &[i, j] in &self.pairs {
            self.incident_starts[i as usize + 1] += 1;
            self.incident_starts[j as usize + 1] += 1;
        }
        for k in 0..n {
            self.incident_starts[k + 1] += self.incident_starts[k];
        }
        self.incident.clear();
        self.incident
            .resize(self.incident_starts[n] as usize, Incidence(0));
        let mut fill = self.incident_starts.clone();
        for (index, &[i, j]) in self.pairs.iter().enumerate() {
            for (k, first) in [(i as usize, true), (j as usize, false)] {
                self.incident[fill[k] as usize] = Incidence::new(index, first);
                fill[k] += 1;
            }
        }
    }
}

/// The skin when none is set: [`DEFAULT_SKIN`] times the smallest of the bounding
/// `radii` (0 for none).
pub fn automatic_skin(radii: &[Real]) -> Real {
    let skin = DEFAULT_SKIN * radii.iter().copied().fold(Real::INFINITY, Real::min);
    if skin.is_finite() { skin.max(0.0) } else { 0.0 }
}

/// Sorts the pairs (each given with `i < j`) by the space keys of their two
/// particles, the smaller first (see [`crate::world::SpaceOrder`]), then orients
/// each so that its first particle has the smaller id (a contact is evaluated from
/// that side, and its history kept under it, whatever the keys). Where the keys
/// ascend with the index (particles stored in key order) that is the order of the
/// indices, and sorted as such. Returns whether it was.
fn sort_pairs(pairs: &mut Vec<[u32; 2]>, p: &Particles, sort: &mut PairSort) -> bool {
    let key = |i: u32| p.space_key(i as usize);
    let by_index = (0..p.len()).map(|i| p.space_key(i)).is_sorted();
    if by_index {
        sort.sort(pairs, p.len());
    } else {
        pairs.par_iter_mut().for_each(|pair| {
            if key(pair[0]) > key(pair[1]) {
                pair.swap(0, 1);
            }
        });
        pairs.par_sort_unstable_by_key(|&[i, j]| (key(i), key(j)));
    }
    pairs.par_iter_mut().for_each(|pair| {
        if p.id[pair[0] as usize] > p.id[pair[1] as usize] {
            pair.swap(0, 1);
        }
    });
    by_index
}

#[cfg(test)]
mod tests {
    use nalgebra::UnitQuaternion;
    use rand::{Rng, SeedableRng};

    use super::*;
    use crate::contact::Material;
    use crate::geometry::{Shape, Sphere};
    use crate::world::BodyType;

    /// 300 spheres of radius 0.01 at random in a 0.2 m cube.
    fn random_spheres() -> World {
        let material = Material::of_tests("m", 1000.0, 1e7, 0.3);
        let mut world = World::default();
        world.body_types.push(BodyType::new(
            Shape::Sphere(Sphere::new(0.01).unwrap()),
            &material,
            0,
        ));
        world.materials.push(material);
        let mut rng = rand_pcg::Pcg64::seed_from_u64(4);
        for id in 0..300 {
            let x = Point3::new(
                rng.random_range(0.0..0.2),
                rng.random_range(0.0..0.2),
                rng.random_range(0.0..0.2),
            );
            world.particles.push(0, x, UnitQuaternion::identity(), id);
        }
        world
    }

    /// Every particle's incidence list names exactly the listed pairs that hold it,
    /// ascending, each with the particle's role in it; and every pair within reach
    /// plus skin is listed.
    #[test]
    fn incidence_lists_name_each_pair_of_a_particle_with_its_role() {
        let world = random_spheres();
        let radii = vec![0.01; 300];
        let mut list = NeighbourList {
            skin: Some(0.002),
            ..Default::default()
        };
        list.build(&world, &radii);
        let pairs = list.pairs();
        let x = &world.particles.position;
        let within = (0..300)
            .flat_map(|i| (i + 1..300).map(move |j| (i, j)))
            .filter(|&(i, j)| (x[i] - x[j]).norm() < 0.022)
            .count();
        assert!(within > 100, "{within} pairs within reach: a sparse test");
        assert_eq!(pairs.len(), within);
        for k in 0..300 {
            let holding: Vec<usize> = (0..pairs.len())
                .filter(|&p| pairs[p].contains(&(k as u32)))
                .collect();
            let listed: Vec<usize> = list.incident(k).iter().map(|e| e.pair()).collect();
            assert_eq!(listed, holding, "particle {k}");
            for e in list.incident(k) {
                assert_eq!(e.is_first(), pairs[e.pair()][0] as usize == k);
            }
        }
    }

    /// With the particles coded in the space order, pairs are sorted by their
    /// particles' keys and evaluated from the particle of smaller id, and each
    /// particle meets its partners in the order of their keys: the same pairs, in
    /// the same order, whether the particles are stored by id or by key.
    #[test]
    fn pairs_follow_the_space_keys_wherever_the_particles_are_stored() {
        let radii = vec![0.01; 300];
        let built = |world: &World| {
            let mut list = NeighbourList {
                skin: Some(0.002),
                ..Default::default()
            };
            list.build(world, &radii);
            list
        };
        let mut by_id = random_spheres();
        by_id.refresh_space_order(false);
        let mut by_key = by_id.clone();
        by_key.refresh_space_order(true);
        let (a, b) = (&by_id.particles, &by_key.particles);
        assert!(a.id.is_sorted() && !b.id.is_sorted(), "stored two ways");
        let distinct: std::collections::HashSet<_> = a.cell_code.iter().collect();
        assert!(
            distinct.len() > 50,
            "{} cells: the keys order",
            distinct.len()
        );

        let (la, lb) = (built(&by_id), built(&by_key));
        let ids = |p: &Particles, l: &NeighbourList| -> Vec<[u64; 2]> {
            (l.pairs().iter())
                .map(|&[i, j]| [p.id[i as usize], p.id[j as usize]])
                .collect()
        };
        let pairs = ids(a, &la);
        assert_eq!(pairs, ids(b, &lb), "the same pairs in the same order");
        let key = |id: u64| a.space_key(a.index_of(id).unwrap());
        let sort_key = |&[x, y]: &[u64; 2]| (key(x).min(key(y)), key(x).max(key(y)));
        assert!(pairs.iter().all(|[x, y]| x < y), "the smaller id first");
        assert!(pairs.is_sorted_by_key(sort_key), "sorted by the keys");
        assert!(!pairs.is_sorted(), "not by the ids");
        for k in 0..300 {
            let partners: Vec<(u64, u64)> = (la.incident(k).iter())
                .map(|e| la.pairs()[e.pair()][usize::from(e.is_first())] as usize)
                .map(|j| a.space_key(j))
                .collect();
            assert!(partners.is_sorted(), "particle {k}: {partners:?}");
        }
    }

    /// Lists resumed from a saved build are that build's lists while the particles
    /// stay within its limits; a particle beyond them, or other particles, make the
    /// build start from the world as it is.
    #[test]
    fn a_resumed_build_starts_from_the_saved_positions_while_they_hold() {
        let mut world = random_spheres();
        let radii = vec![0.01; 300];
        let fresh = || NeighbourList {
            skin: Some(0.002),
            ..Default::default()
        };
        let mut saved = fresh();
        saved.build(&world, &radii);
        let anchors = saved.anchors().unwrap();
        assert_eq!(anchors.particles.len(), 300);
        // Every particle moved by 0.9 of half the skin, in turn along each axis.
        for (k, x) in world.particles.position.iter_mut().enumerate() {
            x[k % 3] += 0.9 * 0.001 * if k % 2 == 0 { 1.0 } else { -1.0 };
        }
        let mut moved = fresh();
        moved.build(&world, &radii);
        assert_ne!(
            moved.pairs(),
            saved.pairs(),
            "another list from the new places"
        );
        let mut resumed = fresh();
        resumed.resume_from(anchors.clone());
        assert_eq!(resumed.anchors(), Some(anchors.clone()), "kept until built");
        resumed.build(&world, &radii);
        assert_eq!(resumed.pairs(), saved.pairs());
        assert_eq!(resumed.anchors(), Some(anchors.clone()));
        assert!(!resumed.is_stale(&world));

        // One particle a little beyond half the skin (it moved along −z): built
        // from the world.
        world.particles.position[17].z -= 0.0002;
        let mut beyond = fresh();
        beyond.resume_from(anchors.clone());
        beyond.build(&world, &radii);
        assert_eq!(beyond.pairs(), moved_pairs(&world, &radii));
        assert_ne!(beyond.anchors(), Some(anchors.clone()));

        // Particles in another order: built from the world.
        world.particles.position[17].z += 0.0002;
        world.particles.id.swap(3, 4);
        world.particles.reindex();
        let mut other = fresh();
        other.resume_from(anchors);
        other.build(&world, &radii);
        assert_eq!(other.pairs(), moved_pairs(&world, &radii));
    }

    /// The particles near walls are exactly those with a listed facet of some wall,
    /// ascending: two planes (the floor and a side) under random spheres, some near
    /// one, some near both, most near neither.
    #[test]
    fn particles_near_walls_are_those_with_listed_facets() {
        use crate::geometry::surfaces;
        use crate::world::Wall;
        let mut world = random_spheres();
        for (centre, normal) in [
            (Point3::new(0.1, 0.1, 0.0), nalgebra::Vector3::z()),
            (Point3::new(0.0, 0.1, 0.1), nalgebra::Vector3::x()),
        ] {
            let s = surfaces::plane(centre, normal, 0.2).unwrap();
            world
                .walls
                .push(Wall::new("plane", 0, s.vertices, s.triangles, 0.02));
        }
        let radii = vec![0.01; 300];
        let mut list = NeighbourList {
            skin: Some(0.002),
            ..Default::default()
        };
        list.build(&world, &radii);
        let near = |k: usize, w: usize| !list.facets(k, w).is_empty();
        let expected: Vec<u32> = (0..300)
            .filter(|&k| near(k, 0) || near(k, 1))
            .map(|k| k as u32)
            .collect();
        assert_eq!(list.near_walls(), expected);
        let both = (0..300).filter(|&k| near(k, 0) && near(k, 1)).count();
        assert!(
            expected.len() > 20 && expected.len() < 150 && both > 0,
            "{} near, {both} near both",
            expected.len()
        );
        // Every particle within reach plus skin of the floor is near it (the grid may
        // list a few more: it finds facets by cells of 0.02).
        for k in 0..300 {
            let z = world.particles.position[k].z;
            assert!(near(k, 0) || z >= 0.012, "particle {k} at z = {z}");
            assert!(!near(k, 0) || z < 0.012 + 0.04, "particle {k} at z = {z}");
        }
    }

    /// The pairs of lists built from `world` as it is.
    fn moved_pairs(world: &World, radii: &[Real]) -> Vec<[u32; 2]> {
        let mut list = NeighbourList {
            skin: Some(0.002),
            ..Default::default()
        };
        list.build(world, radii);
        list.pairs().to_vec()
    }
}
