//! A world stepped on a [`Device`]: Hertz–Mindlin spheres, convex polyhedra under
//! the volume law, or both; the CPU backend's step (`engine/cpu`) with every stage a
//! kernel and the state in device memory between steps. Through the host executor
//! spheres give the CPU backend's bits (`tests/cuda_spheres.rs`); polyhedra its
//! answers to round-off, as far as the CPU backend's own answers move when every
//! coordinate is nudged by an ulp (`tests/cuda_polyhedra.rs`: the kernel clips the
//! faces of an overlap afresh where the CPU evaluates a kept topology).
//!
//! A step is [`DeviceWorld::step`]: the opening kick and drift, then the force
//! evaluation (the list checked and rebuilt with its history carried, the pair
//! contacts, the gather), then the closing kick. Per step the host reads back one
//! word (whether the list is stale) and, when it was rebuilt, the pair count; the
//! particles come back by [`DeviceWorld::download`].
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
//! Spheres and polyhedra may share a world: two polyhedra meet under the volume
//! law, a sphere meets anything under the scene's law (the volume law, or
//! Hertz–Mindlin with its rolling resistance, a polyhedron as locally flat).
//!
//! What it does not take yet (refused by [`DeviceWorld::new`]): polyhedra of more
//! than 64 faces or vertices, a fluid.

use nalgebra::{Point3, UnitQuaternion, Vector3};

mod figures;
mod halo;
mod transfer;

use super::Kernel;
use super::device::{Arg, Array, Device, DeviceError};
use super::device_body_types::DeviceBodyTypes;
use super::device_list::{DeviceList, ListInputs, run};
use super::device_pair_contacts::{PairOutputs, pair_contacts};
use super::device_polyhedra::{MAX_SHAPE_PARTS, ShapeTableError, beyond_masks};
use super::device_states::{StateView, roles};
use super::device_sums::{PairTerms, RowSums, sum_energies};
use super::device_wall_patches::Loads;
use super::device_wall_slots::too_many_wall_contacts;
use super::device_walls::{DeviceWalls, WallInputs};
use super::readback::Readback;
use crate::Real;
use crate::engine::StepParams;
use crate::engine::neighbours::automatic_skin;
use crate::world::{Particles, World};

/// Doubles of a pair's result (`kernels/spheres.cu`).
const RESULT: usize = 9;
/// Doubles of a pair's energy terms (`kernels/spheres.cu`).
const PAIR_ENERGY: usize = 2;

/// Why a world cannot be stepped on the device.
#[derive(Debug, thiserror::Error)]
pub enum StepperError {
    /// The world holds something the device stepper does not model yet.
    #[error("the cuda backend does not yet step {0}")]
    Unsupported(String),
    /// A device call failed.
    #[error(transparent)]
    Device(#[from] DeviceError),
}

/// Per body type, what integration reads (mass, principal moments), and the
/// contact laws' rows and shapes.
#[derive(Debug)]
struct TypeArrays {
    mass: Array<Real>,
    inertia: Array<Real>,
    laws: Box<DeviceBodyTypes>,
}

impl TypeArrays {
    /// Whether every pair is two spheres under Hertz–Mindlin without rolling
    /// resistance (`sphere_contacts`), else any pair (`pair_contacts`).
    fn spheres_under_hertz(&self) -> bool {
        self.laws.spheres_under_hertz()
    }

    /// Doubles of a contact's tangential history.
    fn history_width(&self) -> usize {
        self.laws.history_width()
    }
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

/// A world on a device (see the module).
#[derive(Debug)]
pub struct DeviceWorld {
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

impl DeviceWorld {
    /// Uploads `world` to `device`, checking that it holds only what the device
    /// stepper models (see the module).
    pub fn new(
        mut device: Box<dyn Device>,
        world: &World,
        params: &StepParams,
    ) -> Result<Self, StepperError> {
        Self::check(world, params)?;
        let p = &world.particles;
        let radii: Vec<Real> = (world.body_types.iter())
            .map(|t| t.shape.circumradius())
            .collect();
        let d = device.as_mut();
        let bodies = &world.body_types;
        let laws =
            DeviceBodyTypes::upload(d, world, params.regularisation_length, params.round_law)
                .map_err(|e| match e {
                    ShapeTableError::Device(e) => StepperError::Device(e),
                    other => StepperError::Unsupported(other.to_string()),
                })?;
        let mut types = TypeArrays {
            mass: Array::default(),
            inertia: Array::default(),
            laws: Box::new(laws),
        };
        types
            .mass
            .write(d, &bodies.iter().map(|t| t.mass).collect::<Vec<_>>())?;
        types.inertia.write(
            d,
            &vectors(&bodies.iter().map(|t| t.inertia).collect::<Vec<_>>()),
        )?;

        let all_radii: Vec<Real> = p.body_type.iter().map(|&k| radii[k as usize]).collect();
        let skin = params.skin.unwrap_or_else(|| automatic_skin(&all_radii));
        let skin = if skin.is_finite() { skin.max(0.0) } else { 0.0 };
        let largest = radii.iter().copied().fold(0.0, Real::max);
        let list = DeviceList::new(skin, 2.0 * largest + skin);
        let walls = DeviceWalls::new(d, world, p.len(), types.history_width())?;
        let readback = Readback::new(d, walls.sums_width())?;
        let order = id_order(p);
        let mut stepper = DeviceWorld {
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
        stepper.upload_particles(world)?;
        Ok(stepper)
    }

    /// Whether the stepper models `world` under `params` (every contact law of the
    /// CPU backend is stepped: the world alone decides): `Err` names what it does
    /// not model yet.
    pub fn check(world: &World, _params: &StepParams) -> Result<(), StepperError> {
        let unsupported = |what: &str| Err(StepperError::Unsupported(what.into()));
        if world.fluid.is_some() {
            return unsupported("a fluid");
        }
        for (t, body) in world.body_types.iter().enumerate() {
            let parts = body.shape.as_polyhedron().and_then(beyond_masks);
            if let Some((vertices, faces)) = parts {
                return unsupported(&format!(
                    "body type {t}, a polyhedron of {vertices} vertices and {faces} faces (at \
                     most {MAX_SHAPE_PARTS} of each)"
                ));
            }
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
        a.role.write(d, &roles(p, order.iter().copied()))?;
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
        let width = self.history_width();
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
                type_radius: &t.laws.hertz.radius,
            };
            // The tangential history carried over by the pairs' ids: from this list,
            // or from a history set from outside.
            if !list.pending {
                std::mem::swap(&mut pairs.history, &mut pairs.old_history);
            }
            list.build(d, &inputs)?;
            pairs.history.resize(d, width * list.pair_count)?;
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
                        Arg::U32(width as u32),
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
        let states = p.view();
        if t.spheres_under_hertz() {
            let mut args = vec![
                Arg::U32(count as u32),
                Arg::F64(dt),
                list.pairs.arg(),
                p.position.arg(),
                p.velocity.arg(),
                p.angular_momentum.arg(),
                p.body_type.arg(),
                p.role.arg(),
            ];
            args.extend(t.laws.hertz.args());
            args.extend([
                pairs.history.arg(),
                pairs.results.arg(),
                pairs.terms.arg(),
                pairs.touching.arg(),
            ]);
            // SAFETY: the parameters of sphere_contacts (spheres.cu), every array
            // sized for its pairs, particles or body types.
            unsafe { run(d, Kernel::SphereContacts, count, &args)? };
        } else {
            let out = PairOutputs {
                history: &pairs.history,
                results: &pairs.results,
                energies: &pairs.terms,
                touching: &pairs.touching,
            };
            // SAFETY: the states hold every particle of the list's pairs, the types
            // every body type; the outputs sized for `count` pairs.
            unsafe { pair_contacts(d, &t.laws, &states, count, &list.pairs, &out, dt)? };
        }
        let g = self.gravity;
        // SAFETY: the parameters of gather_forces (spheres.cu), every array sized
        // for its pairs, particles or body types.
        unsafe {
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
                dt,
                states,
                type_mass: &t.mass,
                type_inertia: &t.inertia,
                laws: &t.laws,
                loads: Loads {
                    force: &p.force,
                    torque: &p.torque,
                    touching: &p.touching,
                },
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

    /// Doubles of a pair's tangential history: the spring and its stiffness, and
    /// under the volume law the twist.
    fn history_width(&self) -> usize {
        self.types.history_width()
    }
}

impl ParticleArrays {
    /// The states as the contact kernels read them.
    fn view(&self) -> StateView<'_> {
        StateView {
            position: &self.position,
            orientation: &self.orientation,
            velocity: &self.velocity,
            angular_momentum: &self.angular_momentum,
            body_type: &self.body_type,
            role: &self.role,
        }
    }
}
