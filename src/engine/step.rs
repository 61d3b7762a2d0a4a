//! One time step on the CPU: kick and drift, broad phase, narrow phase and contact
//! forces (in parallel over pairs and over particles), accumulation in a fixed order,
//! and the closing kick.

use super::fast_hash::FastMap;

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use super::integrate::{RotationState, free_rotation, half_kick};
use super::laws::{ContactLaws, pair_restitution};
use super::neighbours::NeighbourList;
use crate::Real;
use crate::contact::{
    DampingTable, NormalContact, PairStiffness, TangentialHistory, normal_force, rocking_damping,
    tangential_force, twisting_friction,
};
use crate::geometry::Shape;
use crate::geometry::overlap::{OverlapCache, overlap_cached};
use crate::geometry::sphere::{sphere_polyhedron, sphere_sphere, sphere_triangle};
use crate::geometry::wall::polyhedron_triangle;
use crate::world::World;

/// Geometry of one contact in world coordinates, body 1 → body 2.
#[derive(Clone, Copy, Debug)]
struct ContactGeometry {
    volume: Real,
    area: Real,
    depth: Real,
    normal: Vector3<Real>,
    point: Point3<Real>,
    /// Derivative of the volume with respect to rotating body 2 about its centroid,
    /// where the kernel provides it (polyhedra): the elastic torque then derives from
    /// the same potential as the force.
    rotation_gradient: Option<Vector3<Real>>,
}

/// The force and torque one contact puts on its second body; the first body gets the
/// opposite force and the torque that balances angular momentum.
#[derive(Clone, Copy, Debug)]
struct ContactForce {
    force: Vector3<Real>,
    /// Torque on body 2 about its centroid.
    torque: Vector3<Real>,
    history: TangentialHistory,
    /// Elastic energy stored in the contact's normal law.
    energy: Real,
}

impl ContactForce {
    /// Torque on body 1 about `x1`, given body 2's centroid `x2`: what keeps the
    /// pair's angular momentum.
    fn reaction_torque(&self, x1: &Point3<Real>, x2: &Point3<Real>) -> Vector3<Real> {
        -(self.torque + (x2 - x1).cross(&self.force))
    }
}

/// Key of a particle–wall contact patch: particle id, wall, and the patch plane
/// (normal and offset rounded), so that friction history survives sliding from facet
/// to facet of a flat wall.
pub type WallKey = (u64, u32, [i64; 4]);

/// The tangential contact history of an engine, sorted by key: what must be saved
/// with the particles for a run to continue bit for bit.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ContactHistory {
    /// Particle pairs, keyed by the two particle ids.
    pub pairs: Vec<((u64, u64), TangentialHistory)>,
    /// Particle–wall patches.
    pub walls: Vec<(WallKey, TangentialHistory)>,
}

/// The CPU engine: time step, contact history and reusable buffers.
#[derive(Clone, Debug)]
pub struct Engine {
    /// Time step.
    pub dt: Real,
    /// Length, relative to the smaller equivalent radius of a contact, below whose
    /// cube the volume law is regularised (see [`crate::contact::normal_force`]).
    pub regularisation_length: Real,
    /// Verlet lists of candidate pairs and facets (see [`NeighbourList`]).
    pub neighbours: NeighbourList,
    /// Tangential history of each candidate pair, aligned with the pair list.
    history: Vec<TangentialHistory>,
    /// What each candidate pair's exact overlap decided at some pose, aligned with
    /// the pair list: it changes the cost, never the answer (see [`OverlapCache`]), so
    /// it is neither saved nor carried over a list build.
    overlap_plans: Vec<OverlapCache>,
    /// History set from outside, to be matched to the pairs at the next list build.
    pending_history: Option<FastMap<(u64, u64), TangentialHistory>>,
    /// Bounding radius of every particle, and the pair results of the last step
    /// (buffers kept between steps).
    radii: Vec<Real>,
    results: Vec<Option<ContactForce>>,
    /// Whether each particle touched another or a wall at the last force evaluation.
    touching: Vec<bool>,
    wall_history: FastMap<WallKey, TangentialHistory>,
    laws: ContactLaws,
    /// Number of particle–particle and particle–wall contacts in the last step.
    pub contacts: usize,
    /// Elastic energy stored in all contacts' normal laws at the last force
    /// evaluation (the potential of the overlap volumes).
    pub elastic_energy: Real,
}

impl Engine {
    /// An engine stepping by `dt`.
    pub fn new(dt: Real) -> Self {
        Engine {
            dt,
            regularisation_length: REGULARISATION_LENGTH,
            neighbours: NeighbourList::default(),
            history: Vec::new(),
            overlap_plans: Vec::new(),
            pending_history: None,
            radii: Vec::new(),
            results: Vec::new(),
            touching: Vec::new(),
            wall_history: FastMap::default(),
            laws: ContactLaws::default(),
            contacts: 0,
            elastic_energy: 0.0,
        }
    }

    /// Candidate particle pairs (bounding spheres widened by the skin overlapping)
    /// of the last step.
    pub fn candidate_pairs(&self) -> usize {
        self.neighbours.pairs().len()
    }

    /// Whether each particle touched another particle or a wall at the last force
    /// evaluation (particles inserted since are not listed).
    pub fn touching(&self) -> &[bool] {
        &self.touching
    }

    /// The tangential history of the particle pairs, keyed by the two ids.
    fn pair_history(&self) -> FastMap<(u64, u64), TangentialHistory> {
        if let Some(pending) = &self.pending_history {
            return pending.clone();
        }
        let list = &self.neighbours;
        list.pairs()
            .iter()
            .zip(&self.history)
            .filter(|(_, h)| !h.is_empty())
            .map(|(&pair, h)| (list.pair_ids(pair), *h))
            .collect()
    }

    /// The tangential contact history, sorted by key.
    pub fn history(&self) -> ContactHistory {
        let mut pairs: Vec<_> = self.pair_history().into_iter().collect();
        let mut walls: Vec<_> = self.wall_history.iter().map(|(k, h)| (*k, *h)).collect();
        pairs.sort_by_key(|e| e.0);
        walls.sort_by_key(|e| e.0);
        ContactHistory { pairs, walls }
    }

    /// Replaces the tangential contact history (see [`Engine::history`]).
    pub fn set_history(&mut self, history: ContactHistory) {
        self.pending_history = Some(history.pairs.into_iter().collect());
        self.neighbours.invalidate();
        self.wall_history = history.walls.into_iter().collect();
    }

    /// Computes the forces of the current state (call once before the first step).
    pub fn initialise(&mut self, world: &mut World) {
        self.compute_forces(world);
    }

    /// Advances the world by one step.
    pub fn step(&mut self, world: &mut World) {
        let dt = self.dt;
        let types = &world.body_types;
        let p = &mut world.particles;
        (
            &mut p.position,
            &mut p.velocity,
            &mut p.orientation,
            &mut p.angular_momentum,
        )
            .into_par_iter()
            .zip((&p.force, &p.torque, &p.body_type, &p.frozen))
            .with_min_len(PARTICLES_PER_TASK)
            .for_each(|((x, v, q, l), (f, t, &kind, &frozen))| {
                if frozen {
                    return;
                }
                let kind = &types[kind as usize];
                *v += f * (0.5 * dt / kind.mass);
                *x += *v * dt;
                let mut rot = RotationState {
                    orientation: *q,
                    angular_momentum: *l,
                };
                half_kick(&mut rot, t, dt);
                free_rotation(&mut rot, &kind.inertia, dt);
                *q = rot.orientation;
                *l = rot.angular_momentum;
            });
        for wall in &mut world.walls {
            wall.advance(world.time, dt);
        }
        world.follow_leaders();
        world.time += dt;
        self.compute_forces(world);
        let types = &world.body_types;
        let p = &mut world.particles;
        (&mut p.velocity, &mut p.angular_momentum)
            .into_par_iter()
            .zip((&p.force, &p.torque, &p.body_type, &p.frozen))
            .with_min_len(PARTICLES_PER_TASK)
            .for_each(|((v, l), (f, t, &kind, &frozen))| {
                if frozen {
                    return;
                }
                *v += f * (0.5 * dt / types[kind as usize].mass);
                *l += t * (0.5 * dt);
            });
    }

    /// Brings the candidate lists up to date, carrying the pairs' tangential history
    /// over to a new list.
    fn update_neighbours(&mut self, world: &World) {
        let types = &world.body_types;
        self.radii.clear();
        self.radii.extend(
            world
                .particles
                .body_type
                .iter()
                .map(|&k| types[k as usize].shape.circumradius()),
        );
        if !self.neighbours.is_stale(world) {
            return;
        }
        let carried = match self.pending_history.take() {
            Some(pending) => pending,
            None => self.pair_history(),
        };
        self.neighbours.build(world, &self.radii);
        let list = &self.neighbours;
        self.overlap_plans.clear();
        self.overlap_plans
            .resize(list.pairs().len(), OverlapCache::default());
        self.history.clear();
        self.history.extend(list.pairs().iter().map(|&pair| {
            carried
                .get(&list.pair_ids(pair))
                .copied()
                .unwrap_or_default()
        }));
    }

    /// Forces and torques of the current positions and velocities.
    fn compute_forces(&mut self, world: &mut World) {
        self.laws.prepare(world, self.regularisation_length);
        self.update_neighbours(world);
        for wall in &mut world.walls {
            wall.force = Vector3::zeros();
            wall.torque = Vector3::zeros();
            wall.facet_force
                .iter_mut()
                .for_each(|f| *f = Vector3::zeros());
        }

        // Particle pairs, in parallel over the candidate pairs; each pair's history
        // is replaced by the one its contact leaves (empty when they do not touch).
        // Two frozen particles push on nothing that moves: their pair is skipped.
        let w = &*world;
        let (radii, laws, dt) = (&self.radii, &self.laws, self.dt);
        let pairs = self.neighbours.pairs();
        self.results.clear();
        self.results.par_extend(
            pairs
                .par_iter()
                .zip(&mut self.history)
                .zip(&mut self.overlap_plans)
                .with_min_len(PAIRS_PER_TASK)
                .map(|((&[i, j], history), plan)| {
                    let (i, j) = (i as usize, j as usize);
                    let reach = radii[i] + radii[j];
                    let frozen = &w.particles.frozen;
                    let c = if !(frozen[i] && frozen[j])
                        && (w.particles.position[j] - w.particles.position[i]).norm_squared()
                            < reach * reach
                    {
                        pair_force(w, i, j, *history, plan, laws, dt)
                    } else {
                        None
                    };
                    *history = c.map(|c| c.history).unwrap_or_default();
                    c
                }),
        );

        // Each particle gathers its pairs' forces in pair order (what a serial sweep
        // over the pairs would add), so the sums do not depend on the threads.
        let list = &self.neighbours;
        let results = &self.results;
        let p = &mut world.particles;
        let (types, gravity, position) = (&world.body_types, world.gravity, &p.position);
        self.touching.resize(p.len(), false);
        (&mut p.force, &mut p.torque, &mut self.touching)
            .into_par_iter()
            .enumerate()
            .with_min_len(PARTICLES_PER_TASK)
            .for_each(|(k, (force, torque, touching))| {
                *force = gravity * types[p.body_type[k] as usize].mass;
                *torque = Vector3::zeros();
                // A frozen particle is part of a bed, whether or not its contacts are
                // evaluated.
                *touching = p.frozen[k];
                for &index in list.incident(k) {
                    let Some(c) = &results[index as usize] else {
                        continue;
                    };
                    *touching = true;
                    let [i, j] = list.pairs()[index as usize].map(|x| x as usize);
                    if j == k {
                        *force += c.force;
                        *torque += c.torque;
                    } else {
                        *force -= c.force;
                        *torque += c.reaction_torque(&position[i], &position[j]);
                    }
                }
            });
        let (mut contacts, mut energy) = (0, 0.0);
        for c in self.results.iter().flatten() {
            contacts += 1;
            energy += c.energy;
        }

        // Particles against walls, in parallel over particles.
        let w = &*world;
        let wall_history = &self.wall_history;
        let list = &self.neighbours;
        let law = LawParams {
            dt,
            regularisation_length: self.regularisation_length,
        };
        let wall_results: Vec<Vec<WallContact>> = (0..w.particles.len())
            .into_par_iter()
            .with_min_len(WALL_PARTICLES_PER_TASK)
            .with_max_len(WALL_PARTICLES_MAX_PER_TASK)
            .map(|i| {
                if w.particles.frozen[i] {
                    Vec::new()
                } else {
                    wall_contacts(w, i, list, wall_history, laws, &law)
                }
            })
            .collect();
        let mut next_wall_history =
            FastMap::with_capacity_and_hasher(self.wall_history.len(), Default::default());
        for (i, list) in wall_results.into_iter().enumerate() {
            for WallContact {
                wall,
                key,
                force: c,
                facets,
            } in list
            {
                contacts += 1;
                energy += c.energy;
                self.touching[i] = true;
                let p = &mut world.particles;
                p.force[i] += c.force;
                p.torque[i] += c.torque;
                let wall = &mut world.walls[wall as usize];
                wall.force -= c.force;
                wall.torque += c.reaction_torque(&wall.reference(), &p.position[i]);
                let total: Real = facets.iter().map(|f| f.1).sum();
                if total > 0.0 {
                    for (f, share) in facets {
                        wall.facet_force[f as usize] -= c.force * (share / total);
                    }
                }
                if !c.history.is_empty() {
                    next_wall_history.insert(key, c.history);
                }
            }
        }
        self.wall_history = next_wall_history;
        self.contacts = contacts;
        self.elastic_energy = energy;
    }
}

/// Smallest share of particles and of pairs one rayon task takes: below it the
/// scheduling costs more than the work. A particle's wall contacts can cost as much
/// as a hundred kick-drifts (a pellet against the facets of a tube), so their share
/// is smaller: with 256, a bed of 1000 pellets kept 16 cores to 4 tasks.
const PARTICLES_PER_TASK: usize = 256;
const WALL_PARTICLES_PER_TASK: usize = 32;
/// Largest share of particles one wall task takes. The particles touching a wall
/// are bunched (a bed sorted by height has its whole floor layer first), and rayon
/// splits a range only as far as idle threads steal from it: without a cap one
/// thread was left with the floor (2 threads scaled the wall stage by 1.5×).
const WALL_PARTICLES_MAX_PER_TASK: usize = 256;
const PAIRS_PER_TASK: usize = 64;

/// Default regularisation length: below this fraction of the smaller equivalent
/// radius, cubed, the volume law is continued quadratically (see
/// [`crate::contact::normal_force`]); it bounds the stiffness of flat contacts.
pub const REGULARISATION_LENGTH: Real = 1e-2;

/// Parameters of the contact law that the engine sets.
#[derive(Clone, Copy, Debug)]
struct LawParams {
    dt: Real,
    regularisation_length: Real,
}

impl LawParams {
    /// The regularisation volume of a contact whose smaller body has equivalent
    /// radius `r`.
    fn regularisation_volume(&self, r: Real) -> Real {
        (self.regularisation_length * r).powi(3)
    }
}

/// Inverse of the effective mass of particle `i` at `point` along `n`: the lever
/// `r × n` taken into the body frame, where the inertia is diagonal.
fn inverse_mass_at(world: &World, i: usize, point: &Point3<Real>, n: &Vector3<Real>) -> Real {
    let p = &world.particles;
    let t = &world.body_types[p.body_type[i] as usize];
    let lever = p.orientation[i].inverse_transform_vector(&(point - p.position[i]).cross(n));
    1.0 / t.mass + lever.component_div(&t.inertia).dot(&lever)
}

/// Velocity of particle `i`'s material at `point`, given its angular velocity.
fn velocity_at(
    world: &World,
    i: usize,
    angular_velocity: &Vector3<Real>,
    point: &Point3<Real>,
) -> Vector3<Real> {
    world.particles.velocity[i] + angular_velocity.cross(&(point - world.particles.position[i]))
}

/// Contact geometry of particles `i` and `j` in world coordinates (normal i → j);
/// `plan` is the pair's kept overlap plan.
fn pair_geometry(
    world: &World,
    i: usize,
    j: usize,
    plan: &mut OverlapCache,
) -> Option<ContactGeometry> {
    let p = &world.particles;
    let (si, sj) = (
        &world.body_types[p.body_type[i] as usize].shape,
        &world.body_types[p.body_type[j] as usize].shape,
    );
    let pose =
        |k: usize| nalgebra::Isometry3::from_parts(p.position[k].coords.into(), p.orientation[k]);
    match (si, sj) {
        (Shape::Polyhedron(a), Shape::Polyhedron(b)) => {
            let (pi, pj) = (pose(i), pose(j));
            let o = overlap_cached(a, b, &(pi.inverse() * pj), plan)?;
            Some(ContactGeometry {
                volume: o.volume,
                area: o.area,
                depth: o.depth,
                normal: pi.rotation * o.normal,
                point: pi * o.centroid,
                rotation_gradient: Some(pi.rotation * o.rotation_gradient_b),
            })
        }
        (Shape::Sphere(a), Shape::Sphere(b)) => {
            let c = sphere_sphere(a.radius, b.radius, &(p.position[j] - p.position[i]))?;
            Some(ContactGeometry {
                volume: c.volume,
                area: c.area,
                depth: c.depth,
                normal: c.normal,
                point: p.position[i] + c.point.coords,
                rotation_gradient: None,
            })
        }
        (Shape::Polyhedron(a), Shape::Sphere(b)) => {
            let pi = pose(i);
            let c = sphere_polyhedron(a, &pi.inverse_transform_point(&p.position[j]), b.radius)?;
            Some(ContactGeometry {
                volume: c.volume,
                area: c.area,
                depth: c.depth,
                normal: pi.rotation * c.normal,
                point: pi * c.point,
                rotation_gradient: None,
            })
        }
        (Shape::Sphere(_), Shape::Polyhedron(_)) => {
            // Body 2 here is the polyhedron's partner sphere: the cap model's point lies
            // on the line through the sphere's centre, so it carries no torque model.
            let mut g = pair_geometry(world, j, i, plan)?;
            g.normal = -g.normal;
            g.rotation_gradient = None;
            Some(g)
        }
    }
}

/// How body 2 moves relative to body 1 at a contact, and how hard it is to move.
#[derive(Clone, Copy, Debug)]
struct RelativeMotion {
    /// Velocity at the contact point.
    velocity: Vector3<Real>,
    /// Angular velocity.
    spin: Vector3<Real>,
    /// Inverse effective mass at the contact point along the normal.
    inverse_mass: Real,
    /// Effective moment of inertia `1/(1/I₁ + 1/I₂)` (smallest principal moments).
    inertia: Real,
}

/// Normal and tangential force on body 2 of a contact.
#[allow(clippy::too_many_arguments)]
fn contact_force(
    g: &ContactGeometry,
    motion: &RelativeMotion,
    stiffness: PairStiffness,
    damping: &DampingTable,
    friction: Real,
    history: TangentialHistory,
    regularisation: Real,
    centre: &Point3<Real>,
    dt: Real,
) -> ContactForce {
    let relative_velocity = motion.velocity;
    let effective_mass = 1.0 / motion.inverse_mass;
    let normal = normal_force(
        &NormalContact {
            volume: g.volume,
            area: g.area,
            depth: g.depth,
            normal: g.normal,
            relative_velocity,
            effective_mass,
            stiffness: stiffness.normal,
            regularisation,
            dt,
        },
        damping,
    );
    let kt = stiffness.tangential * g.area;
    let ct = 2.0 * damping.zeta(1.0) * (effective_mass * kt).sqrt();
    let t = tangential_force(
        &history,
        &g.normal,
        &relative_velocity,
        dt,
        kt,
        ct,
        friction * normal.force.norm(),
    );
    let force = normal.force + t.force;
    let rocking = if g.depth > 0.0 {
        rocking_damping(
            &motion.spin,
            &g.normal,
            g.area,
            normal.exponent * normal.elastic / g.depth,
            motion.inertia,
            damping.zeta(1.0),
            dt,
        )
    } else {
        Vector3::zeros()
    };
    let (twisting, twist) = twisting_friction(
        history.twist,
        &motion.spin,
        &g.normal,
        g.area,
        kt,
        motion.inertia,
        friction * normal.force.norm(),
        dt,
    );
    let torque = rocking
        + twisting
        + match g.rotation_gradient {
            // Elastic part from the potential (U' = elastic / area); damping and friction,
            // measured at the contact point, act there.
            Some(rotation) if g.area > 0.0 => {
                let elastic = g.normal * normal.elastic;
                -(normal.elastic / g.area) * rotation + (g.point - centre).cross(&(force - elastic))
            }
            _ => (g.point - centre).cross(&force),
        };
    ContactForce {
        force,
        torque,
        history: TangentialHistory { twist, ..t.history },
        energy: normal.energy,
    }
}

fn pair_force(
    world: &World,
    i: usize,
    j: usize,
    history: TangentialHistory,
    plan: &mut OverlapCache,
    laws: &ContactLaws,
    dt: Real,
) -> Option<ContactForce> {
    let g = pair_geometry(world, i, j, plan)?;
    let p = &world.particles;
    let law = laws.pair(p.body_type[i], p.body_type[j]);
    let (wi, wj) = (world.angular_velocity(i), world.angular_velocity(j));
    let motion = RelativeMotion {
        velocity: velocity_at(world, j, &wj, &g.point) - velocity_at(world, i, &wi, &g.point),
        spin: wj - wi,
        inverse_mass: inverse_mass_at(world, i, &g.point, &g.normal)
            + inverse_mass_at(world, j, &g.point, &g.normal),
        inertia: law.inertia,
    };
    Some(contact_force(
        &g,
        &motion,
        law.stiffness,
        laws.damping(law),
        law.friction,
        history,
        law.regularisation,
        &p.position[j],
        dt,
    ))
}

/// A patch being assembled: its plane key, summed geometry, and facet shares.
type Patch = ([i64; 4], ContactGeometry, Vec<(u32, Real)>);

/// One particle–wall contact: a coplanar patch of one wall's facets.
struct WallContact {
    wall: u32,
    key: WallKey,
    force: ContactForce,
    /// The patch's facets with their shares of the overlap (volumes).
    facets: Vec<(u32, Real)>,
}

/// Contacts of particle `i` with every wall, one per coplanar patch of facets.
fn wall_contacts(
    world: &World,
    i: usize,
    list: &NeighbourList,
    history: &FastMap<WallKey, TangentialHistory>,
    laws: &ContactLaws,
    law: &LawParams,
) -> Vec<WallContact> {
    let p = &world.particles;
    let t = &world.body_types[p.body_type[i] as usize];
    let radius = t.shape.circumradius();
    let pose = nalgebra::Isometry3::from_parts(p.position[i].coords.into(), p.orientation[i]);
    let mut out = Vec::new();
    for (w, wall) in world.walls.iter().enumerate() {
        let facets = list.facets(i, w);
        if facets.is_empty() {
            continue;
        }
        // Patches: facets sharing a plane (to 1e-9 in the normal, 1e-9 R in offset).
        let mut patches: Vec<Patch> = Vec::new();
        for &f in facets {
            let tri = wall.facet_world(f as usize);
            let n = (tri[1] - tri[0]).cross(&(tri[2] - tri[0])).normalize();
            // Walls are one-sided: a particle whose centroid is behind a facet's plane
            // has passed it (or the mesh faces the wrong way) and is not pushed back
            // through from behind, where the half-infinite prism would meet it with
            // its whole volume at once.
            if n.dot(&(p.position[i] - tri[0])) < 0.0 {
                continue;
            }
            let key = [
                (n.x * 1e9).round() as i64,
                (n.y * 1e9).round() as i64,
                (n.z * 1e9).round() as i64,
                (n.dot(&tri[0].coords) / radius * 1e9).round() as i64,
            ];
            let g = match &t.shape {
                Shape::Polyhedron(poly) => {
                    let local = tri.map(|x| pose.inverse_transform_point(&x));
                    polyhedron_triangle(poly, &local).map(|o| {
                        let area = o.volume_gradient.norm();
                        ContactGeometry {
                            volume: o.volume,
                            area,
                            depth: o.depth,
                            // The force on the particle is along −∇V: out of the wall.
                            normal: -(pose.rotation * o.volume_gradient) / area,
                            point: pose * o.centroid,
                            rotation_gradient: Some(pose.rotation * o.rotation_gradient),
                        }
                    })
                }
                Shape::Sphere(s) => {
                    sphere_triangle(&tri, &p.position[i], s.radius).map(|(c, _)| ContactGeometry {
                        volume: c.volume,
                        area: c.area,
                        depth: c.depth,
                        normal: c.normal,
                        point: c.point,
                        rotation_gradient: None,
                    })
                }
            };
            let Some(g) = g else { continue };
            match patches.iter_mut().find(|(k, _, _)| *k == key) {
                None => patches.push((key, g, vec![(f, g.volume)])),
                Some((_, acc, shares)) => match &t.shape {
                    // Polyhedra: the facets' prisms tile the patch; sum them.
                    Shape::Polyhedron(_) => {
                        let v = acc.volume + g.volume;
                        acc.point = Point3::from(
                            (acc.point.coords * acc.volume + g.point.coords * g.volume) / v,
                        );
                        let sum = acc.normal * acc.area + g.normal * g.area;
                        acc.area = sum.norm();
                        acc.normal = sum / acc.area;
                        acc.volume = v;
                        acc.depth = acc.depth.max(g.depth);
                        acc.rotation_gradient = acc
                            .rotation_gradient
                            .zip(g.rotation_gradient)
                            .map(|(a, b)| a + b);
                        shares.push((f, g.volume));
                    }
                    // Spheres: the deepest facet of a flat patch is the plane contact.
                    Shape::Sphere(_) => {
                        if g.depth > acc.depth {
                            *acc = g;
                            *shares = vec![(f, 1.0)];
                        }
                    }
                },
            }
        }
        let wm = &world.materials[wall.material];
        let pm = &world.materials[t.material];
        let stiffness = PairStiffness::particle_wall(pm, t.shape.equivalent_radius(), wm);
        let e = pair_restitution(pm.restitution, wm.restitution);
        let table = laws.damping_of(e);
        let spin = world.angular_velocity(i);
        for (key, g, facets) in patches {
            if !(g.area > 0.0) || !g.normal.iter().all(|x| x.is_finite()) {
                continue;
            }
            let motion = RelativeMotion {
                velocity: velocity_at(world, i, &spin, &g.point) - wall.velocity_at(&g.point),
                spin: spin - wall.angular_velocity,
                inverse_mass: inverse_mass_at(world, i, &g.point, &g.normal),
                inertia: t.inertia.min(),
            };
            let wall_key = (p.id[i], w as u32, key);
            let h = history.get(&wall_key).copied().unwrap_or_default();
            let c = contact_force(
                &g,
                &motion,
                stiffness,
                &table,
                0.5 * (pm.friction + wm.friction),
                h,
                law.regularisation_volume(t.shape.equivalent_radius()),
                &p.position[i],
                law.dt,
            );
            out.push(WallContact {
                wall: w as u32,
                key: wall_key,
                force: c,
                facets,
            });
        }
    }
    out
}
