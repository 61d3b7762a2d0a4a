//! A world of Hertz–Mindlin spheres stepped on a [`Device`]: the CPU backend's step
//! (`engine/cpu`) with every stage a kernel and the state in device memory between
//! steps. Through the host executor it gives the CPU backend's bits
//! (`tests/cuda_spheres.rs`).
//!
//! A step is [`DeviceSpheres::step`]: the opening kick and drift, then the force
//! evaluation (the list checked and rebuilt with its history carried, the pair
//! contacts, the gather), then the closing kick. Per step the host reads back one
//! word (whether the list is stale) and, when it was rebuilt, the pair count; the
//! particles come back by [`DeviceSpheres::download`].
//!
//! Walls (`device_walls.rs`) move on the host and are placed on the device; each
//! particle's wall contacts follow its pairs' gather. The walls' forces and the
//! contacts' energies are summed in a fixed tree (`device_sums.rs`).
//!
//! The device holds the particles in the order of their ids, whatever the host's
//! order (the list and the gather meet a particle's partners in that order, as the
//! CPU backend's sorted lists do); `order` maps each device slot to its host entry.
//! A rank's share of a decomposed world steps as the CPU backend steps it: ghosts
//! are felt and not moved, get no force and no wall contacts, and the figures
//! count the pairs the rank counts (`Particles::counts_pair`).
//!
//! What it does not take yet (refused by [`DeviceSpheres::new`]): polyhedra,
//! rolling resistance, a fluid.

use nalgebra::{Point3, UnitQuaternion, Vector3};

mod figures;
mod halo;
mod transfer;

use super::Kernel;
use super::device::{Arg, Array, Device, DeviceError};
use super::device_list::{DeviceList, ListInputs, run};
use super::device_sums::{PairTerms, RowSums, sum_energies};
use super::device_walls::{DeviceWalls, WallInputs, too_many_wall_contacts};
use super::readback::Readback;
use crate::Real;
use crate::contact::{RollingModel, pair_restitution};
use crate::engine::neighbours::automatic_skin;
use crate::engine::{RoundLaw, StepParams};
use crate::world::{Particles, World};

/// Doubles of a pair's tangential history on the device: the spring and the
/// stiffness it was stretched at.
const HISTORY: usize = 4;
/// Doubles of a pair's result (`kernels/spheres.cu`).
const RESULT: usize = 9;
/// Doubles of a pair's energy terms (`kernels/spheres.cu`).
const PAIR_ENERGY: usize = 2;
/// A particle's role byte (`kernels/contact.cuh`): frozen, a ghost, or both.
const FROZEN_ROLE: u8 = 1;
const GHOST_ROLE: u8 = 2;

/// Why a world cannot be stepped on the device.
#[derive(Debug, thiserror::Error)]
pub enum SpheresError {
    /// The world holds something the device stepper does not model yet.
    #[error("the cuda backend does not yet step {0}")]
    Unsupported(String),
    /// A device call failed.
    #[error(transparent)]
    Device(#[from] DeviceError),
}

/// Per body type and per pair of materials, what the kernels read.
#[derive(Debug, Default)]
struct TypeArrays {
    mass: Array<Real>,
    inertia: Array<Real>,
    radius: Array<Real>,
    inverse_mass: Array<Real>,
    inverse_inertia: Array<Real>,
    material: Array<u32>,
    /// Row-major over (material 1, material 2): E*, G*, β, √(4G*/E*), μ.
    material_pairs: Array<Real>,
    materials: u32,
}

/// The particles' state on the device, in the order of their ids (nalgebra's
/// layouts: 3 doubles per point or vector, a quaternion as i, j, k, w; the role as
/// a byte).
#[derive(Debug, Default)]
struct ParticleArrays {
    position: Array<Real>,
    velocity: Array<Real>,
    orientation: Array<Real>,
    angular_momentum: Array<Real>,
    force: Array<Real>,
    torque: Array<Real>,
    body_type: Array<u32>,
    /// Frozen, a ghost, or both: nonzero where nobody here moves the particle.
    role: Array<u8>,
    id: Array<u64>,
    /// Codes of the cells in the space order (each particle sums its pairs in the
    /// order of its partners' codes, then ids).
    cell_code: Array<u64>,
    touching: Array<u8>,
}

/// What the pair stage keeps and writes, aligned with the list's pairs.
#[derive(Debug, Default)]
struct PairArrays {
    history: Array<Real>,
    old_history: Array<Real>,
    results: Array<Real>,
    /// Each pair's elastic energy and dissipation.
    terms: Array<Real>,
    touching: Array<u8>,
}

/// A world of spheres on a device (see the module).
#[derive(Debug)]
pub struct DeviceSpheres {
    device: Box<dyn Device>,
    n: usize,
    /// The host world's entry of each device slot: the entries in id order.
    order: Vec<usize>,
    /// The device slot of each host entry (the inverse of `order`).
    slot_of: Vec<u32>,
    /// Owned entries of the host world (the ghosts follow them).
    owned: usize,
    /// Whether the list is stale, when asked since the particles last moved.
    stale: Option<bool>,
    /// The halo's slots and state records (`halo.rs`).
    halo: halo::HaloArrays,
    /// Scratch of the particles' figures (`figures.rs`).
    figures: figures::FigureSums,
    gravity: Vector3<Real>,
    time: Real,
    types: TypeArrays,
    particles: ParticleArrays,
    pairs: PairArrays,
    list: DeviceList,
    walls: DeviceWalls,
    /// Scratch of the energy sums.
    sums: RowSums,
    /// The step's sums and flag, read once a step.
    readback: Readback,
}

fn flat<const K: usize, T: Copy>(items: impl Iterator<Item = [T; K]>) -> Vec<T> {
    items.flatten().collect()
}

fn vectors(v: &[Vector3<Real>]) -> Vec<Real> {
    flat(v.iter().map(|x| [x.x, x.y, x.z]))
}

fn points(x: &[Point3<Real>]) -> Vec<Real> {
    flat(x.iter().map(|x| [x.x, x.y, x.z]))
}

/// Quaternions as the kernels read them: i, j, k, w.
fn quaternions(q: &[UnitQuaternion<Real>]) -> Vec<Real> {
    flat(q.iter().map(|q| q.coords.into()))
}

/// The host world's entries in the order of their ids.
fn id_order(p: &Particles) -> Vec<usize> {
    p.by_id((0..p.len()).collect())
}

/// `values` of the host entries `order`.
fn in_order<T: Copy>(values: &[T], order: &[usize]) -> Vec<T> {
    order.iter().map(|&i| values[i]).collect()
}

/// The device slot of each host entry, for the entries in device order `order`.
fn slots_of(order: &[usize]) -> Vec<u32> {
    let mut slot_of = vec![0; order.len()];
    for (k, &i) in order.iter().enumerate() {
        slot_of[i] = k as u32;
    }
    slot_of
}

/// The role bytes of the host entries `order`.
fn roles(p: &Particles, order: &[usize]) -> Vec<u8> {
    let role = |i: usize| {
        let ghost = if p.is_ghost(i) { GHOST_ROLE } else { 0 };
        ghost | if p.frozen[i] { FROZEN_ROLE } else { 0 }
    };
    order.iter().map(|&i| role(i)).collect()
}

impl DeviceSpheres {
    /// Uploads `world` to `device`, checking that it holds only what the device
    /// stepper models (see the module).
    pub fn new(
        mut device: Box<dyn Device>,
        world: &World,
        params: &StepParams,
    ) -> Result<Self, SpheresError> {
        Self::check(world, params)?;
        let p = &world.particles;
        let radii: Vec<Real> = world
            .body_types
            .iter()
            .map(|t| t.shape.as_sphere().map_or(0.0, |s| s.radius))
            .collect();
        let d = device.as_mut();
        let mut types = TypeArrays::default();
        let bodies = &world.body_types;
        types
            .mass
            .write(d, &bodies.iter().map(|t| t.mass).collect::<Vec<_>>())?;
        types.inertia.write(
            d,
            &vectors(&bodies.iter().map(|t| t.inertia).collect::<Vec<_>>()),
        )?;
        types.radius.write(d, &radii)?;
        types
            .inverse_mass
            .write(d, &bodies.iter().map(|t| 1.0 / t.mass).collect::<Vec<_>>())?;
        types.inverse_inertia.write(
            d,
            &bodies.iter().map(|t| 1.0 / t.inertia.x).collect::<Vec<_>>(),
        )?;
        types.material.write(
            d,
            &bodies.iter().map(|t| t.material as u32).collect::<Vec<_>>(),
        )?;
        // The rows of `engine::laws::ContactLaws::prepare`, by the same operations.
        let mut rows = Vec::new();
        for a in &world.materials {
            for b in &world.materials {
                let e = pair_restitution(a.restitution, b.restitution);
                let h = crate::contact::HertzMindlinPair::new(a, b, e);
                rows.extend([
                    h.young,
                    h.shear,
                    h.beta,
                    h.damping_ratio,
                    0.5 * (a.friction + b.friction),
                ]);
            }
        }
        types.material_pairs.write(d, &rows)?;
        types.materials = world.materials.len() as u32;

        let all_radii: Vec<Real> = p.body_type.iter().map(|&k| radii[k as usize]).collect();
        let skin = params.skin.unwrap_or_else(|| automatic_skin(&all_radii));
        let skin = if skin.is_finite() { skin.max(0.0) } else { 0.0 };
        let largest = radii.iter().copied().fold(0.0, Real::max);
        let list = DeviceList::new(skin, 2.0 * largest + skin);
        let walls = DeviceWalls::new(d, world, p.len())?;
        let readback = Readback::new(d, walls.sums_width())?;
        let order = id_order(p);
        let mut spheres = DeviceSpheres {
            device,
            n: p.len(),
            slot_of: slots_of(&order),
            order,
            owned: p.owned(),
            stale: None,
            halo: Default::default(),
            figures: Default::default(),
            gravity: world.gravity,
            time: world.time,
            types,
            particles: ParticleArrays::default(),
            pairs: PairArrays::default(),
            list,
            walls,
            sums: RowSums::default(),
            readback,
        };
        spheres.upload_particles(world)?;
        Ok(spheres)
    }

    /// Whether the stepper models `world` under `params`: `Err` names what it does
    /// not model yet.
    pub fn check(world: &World, params: &StepParams) -> Result<(), SpheresError> {
        let unsupported = |what: &str| Err(SpheresError::Unsupported(what.into()));
        if params.round_law
            != (RoundLaw::HertzMindlin {
                rolling: RollingModel::None,
            })
        {
            return unsupported("a law other than Hertz–Mindlin without rolling resistance");
        }
        if world.fluid.is_some() {
            return unsupported("a fluid");
        }
        if world
            .body_types
            .iter()
            .any(|t| t.shape.as_sphere().is_none())
        {
            return unsupported("polyhedra");
        }
        Ok(())
    }

    /// Copies the particles' state to the device, in the order of `self.order`.
    fn upload_particles(&mut self, world: &World) -> Result<(), DeviceError> {
        let (d, a, p) = (self.device.as_mut(), &mut self.particles, &world.particles);
        let order = &self.order;
        a.position
            .write(d, &points(&in_order(&p.position, order)))?;
        a.velocity
            .write(d, &vectors(&in_order(&p.velocity, order)))?;
        a.orientation
            .write(d, &quaternions(&in_order(&p.orientation, order)))?;
        a.angular_momentum
            .write(d, &vectors(&in_order(&p.angular_momentum, order)))?;
        a.force.write(d, &vectors(&in_order(&p.force, order)))?;
        a.torque.write(d, &vectors(&in_order(&p.torque, order)))?;
        a.body_type.write(d, &in_order(&p.body_type, order))?;
        a.role.write(d, &roles(p, order))?;
        a.id.write(d, &in_order(&p.id, order))?;
        a.cell_code.write(d, &in_order(&p.cell_code, order))?;
        a.touching.resize(d, p.len())?;
        self.list.invalidate();
        self.stale = None;
        Ok(())
    }

    /// What the device is.
    pub fn device(&self) -> String {
        self.device.description()
    }

    /// Pairs that touched at the last force evaluation.
    pub fn pair_contacts(&self) -> usize {
        self.stats().pair_contacts
    }

    /// Particles on the device.
    pub fn particles(&self) -> usize {
        self.n
    }

    /// Candidate pairs of the list.
    pub fn candidate_pairs(&self) -> usize {
        self.list.pair_count
    }

    /// List builds so far.
    pub fn list_builds(&self) -> u64 {
        self.list.builds
    }

    /// Evaluates the forces of the state as it is (before the first step).
    pub fn initialise(&mut self, dt: Real) -> Result<(), DeviceError> {
        self.forces(dt)
    }

    /// One velocity-Verlet step of length `dt`: the stages in order.
    pub fn step(&mut self, dt: Real) -> Result<(), DeviceError> {
        self.drift(dt)?;
        self.forces(dt)?;
        self.close(dt)
    }

    /// The first part of a step: the opening half kick and the drift of the
    /// particles that move here, and the walls moved to the step's end. A rank
    /// refreshes its ghosts after it (`halo.rs`), before [`Self::forces`].
    pub fn drift(&mut self, dt: Real) -> Result<(), DeviceError> {
        self.stale = None;
        let (d, p, t) = (self.device.as_mut(), &self.particles, &self.types);
        let n = Arg::U32(self.n as u32);
        // SAFETY: the parameters of kick_drift, each array sized for n particles or
        // the body types (integrate.cu).
        unsafe {
            run(
                d,
                Kernel::KickDrift,
                self.n,
                &[
                    n,
                    Arg::F64(dt),
                    p.position.arg(),
                    p.velocity.arg(),
                    p.orientation.arg(),
                    p.angular_momentum.arg(),
                    p.force.arg(),
                    p.torque.arg(),
                    p.body_type.arg(),
                    p.role.arg(),
                    t.mass.arg(),
                    t.inertia.arg(),
                ],
            )?;
        }
        self.walls.advance(self.device.as_mut(), dt)?;
        self.time = self.walls.time();
        Ok(())
    }

    /// The closing half kick of the particles that move here.
    pub fn close(&mut self, dt: Real) -> Result<(), DeviceError> {
        let n = Arg::U32(self.n as u32);
        let (d, p, t) = (self.device.as_mut(), &self.particles, &self.types);
        // SAFETY: closing_kick's parameters (integrate.cu), each array sized for n
        // particles or the body types.
        unsafe {
            run(
                d,
                Kernel::ClosingKick,
                self.n,
                &[
                    n,
                    Arg::F64(dt),
                    p.velocity.arg(),
                    p.angular_momentum.arg(),
                    p.force.arg(),
                    p.torque.arg(),
                    p.body_type.arg(),
                    p.role.arg(),
                    t.mass.arg(),
                ],
            )
        }
    }

    /// Whether the list must be built again before the next force evaluation
    /// (a particle moved half a skin since the build, or the list was invalidated).
    pub fn is_stale(&mut self) -> Result<bool, DeviceError> {
        if let Some(stale) = self.stale {
            return Ok(stale);
        }
        let d = self.device.as_mut();
        let stale = self.list.is_stale(d, self.n, &self.particles.position)?;
        self.stale = Some(stale);
        Ok(stale)
    }

    /// The force evaluation: the list brought up to date, the pair contacts, the
    /// gather, the walls, the sums.
    pub fn forces(&mut self, dt: Real) -> Result<(), DeviceError> {
        let stale = self.is_stale()?;
        self.stale = None;
        let d = self.device.as_mut();
        let (p, t, pairs, list) = (
            &self.particles,
            &self.types,
            &mut self.pairs,
            &mut self.list,
        );
        if stale {
            let inputs = ListInputs {
                n: self.n,
                position: &p.position,
                body_type: &p.body_type,
                id: &p.id,
                cell_code: &p.cell_code,
                type_radius: &t.radius,
            };
            // The tangential history carried over by the pairs' ids: from this list,
            // or from a history set from outside.
            if !list.pending {
                std::mem::swap(&mut pairs.history, &mut pairs.old_history);
            }
            list.build(d, &inputs)?;
            pairs.history.resize(d, HISTORY * list.pair_count)?;
            if list.old_pair_count == 0 {
                pairs.old_history.resize(d, 0)?;
            }
            // SAFETY: the keys of both lists and both histories hold their pairs.
            unsafe {
                run(
                    d,
                    Kernel::CarryHistory,
                    list.pair_count,
                    &[
                        Arg::U32(list.pair_count as u32),
                        Arg::U32(HISTORY as u32),
                        list.keys.arg(),
                        Arg::U32(list.old_pair_count as u32),
                        list.old_keys.arg(),
                        pairs.old_history.arg(),
                        pairs.history.arg(),
                    ],
                )?;
            }
            pairs.results.resize(d, RESULT * list.pair_count)?;
            pairs.terms.resize(d, PAIR_ENERGY * list.pair_count)?;
            pairs.touching.resize(d, list.pair_count)?;
        }
        let count = list.pair_count;
        // SAFETY: the parameters of sphere_contacts and gather_forces (spheres.cu),
        // every array sized for its pairs, particles or body types.
        unsafe {
            run(
                d,
                Kernel::SphereContacts,
                count,
                &[
                    Arg::U32(count as u32),
                    Arg::F64(dt),
                    list.pairs.arg(),
                    p.position.arg(),
                    p.velocity.arg(),
                    p.angular_momentum.arg(),
                    p.body_type.arg(),
                    p.role.arg(),
                    t.radius.arg(),
                    t.inverse_mass.arg(),
                    t.inverse_inertia.arg(),
                    t.material.arg(),
                    Arg::U32(t.materials),
                    t.material_pairs.arg(),
                    pairs.history.arg(),
                    pairs.results.arg(),
                    pairs.terms.arg(),
                    pairs.touching.arg(),
                ],
            )?;
            let g = self.gravity;
            run(
                d,
                Kernel::GatherForces,
                self.n,
                &[
                    Arg::U32(self.n as u32),
                    Arg::F64(g.x),
                    Arg::F64(g.y),
                    Arg::F64(g.z),
                    p.body_type.arg(),
                    t.mass.arg(),
                    p.role.arg(),
                    list.incident_starts.arg(),
                    list.incident.arg(),
                    pairs.results.arg(),
                    pairs.touching.arg(),
                    p.force.arg(),
                    p.torque.arg(),
                    p.touching.arg(),
                ],
            )?;
        }
        if !self.walls.is_empty() {
            let at = WallInputs {
                n: self.n,
                dt,
                position: &p.position,
                velocity: &p.velocity,
                orientation: &p.orientation,
                angular_momentum: &p.angular_momentum,
                body_type: &p.body_type,
                role: &p.role,
                type_radius: &t.radius,
                type_mass: &t.mass,
                type_inertia: &t.inertia,
                type_material: &t.material,
                materials: t.materials,
                material_pairs: &t.material_pairs,
                force: &p.force,
                torque: &p.torque,
                touching: &p.touching,
            };
            self.walls.contacts(d, &at, &self.readback)?;
        }
        let terms = PairTerms {
            count,
            terms: &pairs.terms,
            touching: &pairs.touching,
        };
        sum_energies(
            &mut self.sums,
            d,
            &terms,
            &self.walls,
            self.n,
            &self.readback,
        )?;
        self.readback.read(d)?;
        if self.readback.overflowed() {
            return Err(too_many_wall_contacts());
        }
        Ok(())
    }
}
