//! The walls of a world on a device: their facets as placed in the world
//! ([`PlacedWalls`]), each particle's contacts with them and their tangential
//! history ([`WallSlots`]), and the walls' forces. A sphere's contacts follow
//! Hertz–Mindlin or the volume law (`kernels/walls.cu`), a polyhedron's the volume
//! law, patch by patch (`kernels/polyhedra.cu`, `device_wall_patches.rs`).
//!
//! The walls move on the host, by the CPU backend's own stage (their motions are
//! prescribed or set from outside, a few numbers a step): a copy of the world
//! without particles is advanced each step, and a wall whose pose changed has its
//! facets placed again and uploaded with its velocities.

use nalgebra::Vector3;

use super::Kernel;
use super::device::{Arg, Array, Device, DeviceError};
use super::device_body_types::DeviceBodyTypes;
use super::device_list::run;
use super::device_states::StateView;
use super::device_sums::{RowSums, first_rows};
use super::device_wall_patches::{
    DeviceWallPatches, Loads, PolyhedronSums, polyhedron_wall_contacts, polyhedron_wall_sum_rows,
};
use super::device_wall_placement::PlacedWalls;
use super::device_wall_slots::WallSlots;
use super::readback::{self, Readback};
use crate::Real;
use crate::contact::TangentialHistory;
use crate::engine::backend::WallKey;
use crate::engine::cpu::motion::advance_walls;
use crate::world::World;

/// Doubles the rows of the walls' first pass may take together (32 MiB): a row for
/// every 8 particles where that fits, fewer for walls of many facets (each row
/// holds every facet).
const WALL_ROWS_DOUBLES: usize = 1 << 22;

/// Rows of the walls' first pass over `n` particles, each `width` doubles.
fn wall_sum_rows(n: usize, width: usize) -> usize {
    (WALL_ROWS_DOUBLES / width.max(1)).clamp(1, first_rows(n))
}

/// What the wall contacts read and add to.
pub(super) struct WallInputs<'a> {
    pub dt: Real,
    pub states: StateView<'a>,
    /// Per body type its mass and principal moments.
    pub type_mass: &'a Array<Real>,
    pub type_inertia: &'a Array<Real>,
    /// The contact laws' rows and the shapes.
    pub laws: &'a DeviceBodyTypes,
    pub loads: Loads<'a>,
}

/// The walls on a device and their host copy (see the module).
#[derive(Debug)]
pub(super) struct DeviceWalls {
    /// The world's walls, materials and clock, without particles: what moves them.
    host: World,
    placed: PlacedWalls,
    slots: WallSlots,
    /// Whether the world has spheres.
    spheres: bool,
    /// The patches of polyhedra (none without polyhedra).
    patches: Option<DeviceWallPatches>,
    /// Scratch of the walls' sums (folded into the readback: per wall its force
    /// and torque, then per facet its force).
    sums: RowSums,
}

impl DeviceWalls {
    /// The walls of `world`, placed and uploaded, for `n` particles whose contacts
    /// keep histories of `width` doubles (`DeviceBodyTypes::history_width`: 4, 5
    /// with the twist, 8 with a rolling spring).
    pub fn new(
        device: &mut dyn Device,
        world: &World,
        n: usize,
        width: usize,
    ) -> Result<Self, DeviceError> {
        let shapes = || world.body_types.iter().map(|t| &t.shape);
        let spheres = shapes().any(|s| s.as_sphere().is_some());
        let polyhedra = shapes().any(|s| s.as_polyhedron().is_some());
        let mut host = world.clone();
        host.particles = Default::default();
        host.fluid = None;
        // Without walls the per-particle slots hold nothing (the energy sum still
        // takes them as arguments).
        let n = if host.walls.is_empty() { 0 } else { n };
        Ok(DeviceWalls {
            placed: PlacedWalls::new(device, &host.walls)?,
            slots: WallSlots::new(device, n, width)?,
            spheres,
            patches: polyhedra.then(DeviceWallPatches::default),
            sums: RowSums::default(),
            host,
        })
    }

    /// Makes room for `n` particles, the first of them already here keeping their
    /// wall contacts and springs, the new ones without any.
    pub fn grow(&mut self, device: &mut dyn Device, n: usize) -> Result<(), DeviceError> {
        if self.is_empty() {
            return Ok(());
        }
        self.slots.grow(device, n)
    }

    /// Bytes of device memory the walls hold: their facets and, per particle,
    /// [`super::device_wall_slots::SLOTS`] contacts (and polyhedra's patches).
    pub fn bytes(&self, device: &dyn Device) -> usize {
        self.placed.bytes(device)
            + self.slots.bytes(device)
            + self.patches.as_ref().map_or(0, |p| p.bytes(device))
            + self.sums.bytes(device)
    }

    /// Whether there are walls.
    pub fn is_empty(&self) -> bool {
        self.host.walls.is_empty()
    }

    /// The walls' clock.
    pub fn time(&self) -> Real {
        self.host.time
    }

    /// Moves the walls over `dt` (the CPU backend's stage) and uploads what moved.
    pub fn advance(&mut self, device: &mut dyn Device, dt: Real) -> Result<(), DeviceError> {
        advance_walls(&mut self.host, dt);
        self.placed.update(device, &self.host.walls)
    }

    /// The particles' wall contacts, added to their forces and torques (after the
    /// pairs' gather), and the walls' sums into the readback, whose flag says
    /// whether a particle had more than its slots of wall contacts.
    pub fn contacts(
        &mut self,
        device: &mut dyn Device,
        at: &WallInputs,
        readback: &Readback,
    ) -> Result<(), DeviceError> {
        self.slots.turn();
        readback.clear_flag(device)?;
        let n = at.states.len();
        let width = self.sums_width();
        let rows = wall_sum_rows(n, width);
        let walls = &self.placed;
        // Each particle's contacts come from one kernel: a polyhedron's from the
        // patches', a sphere's from sphere_walls, after (polyhedron_wall_contacts
        // leaves a sphere no contact).
        if let Some(patches) = &mut self.patches {
            let types = at.laws;
            // SAFETY: the patches' arrays sized for the states' particles.
            unsafe { patches.launch_find(device, types, &at.states, walls, readback.flag())? };
            let (states, slots) = (&at.states, &self.slots);
            polyhedron_wall_contacts(
                device, types, states, walls, patches, slots, &at.loads, at.dt,
            )?;
        }
        if self.spheres {
            self.sphere_contacts(device, at, readback)?;
        }
        let partials = self.sums.rows(device, rows, width)?;
        let (new, slots) = (&self.slots.new, &self.slots);
        match &self.patches {
            Some(patches) => {
                let types = at.laws;
                // SAFETY: `partials` has room for `rows` rows of the walls' width;
                // the patches and slots hold the particles' of `at`.
                unsafe {
                    let sums = PolyhedronSums {
                        states: &at.states,
                        shape: &types.shape,
                        walls,
                        patches,
                        slots,
                    };
                    polyhedron_wall_sum_rows(device, &sums, rows, partials)?;
                }
            }
            None => {
                // SAFETY: the parameters of wall_sum_rows (walls.cu): the slots hold n
                // particles', `partials` room for `rows` rows of `width`.
                unsafe {
                    run(
                        device,
                        Kernel::WallSumRows,
                        rows,
                        &[
                            Arg::U32(n as u32),
                            at.states.position.arg(),
                            walls.count_arg(),
                            walls.wall_facets.arg(),
                            walls.motion.arg(),
                            new.count.arg(),
                            new.keys.arg(),
                            slots.records.arg(),
                            slots.record_index.arg(),
                            Arg::U32(rows as u32),
                            partials.arg(),
                        ],
                    )?;
                }
            }
        }
        self.sums
            .fold(device, rows, width, &readback.device, readback::WALLS)
    }

    /// The contacts of spheres with the walls (`sphere_walls` of walls.cu, under
    /// Hertz–Mindlin or the volume law), the readback's flag set where a sphere
    /// has too many.
    fn sphere_contacts(
        &self,
        device: &mut dyn Device,
        at: &WallInputs,
        readback: &Readback,
    ) -> Result<(), DeviceError> {
        let (s, w, h) = (&at.states, &self.placed, &at.laws.hertz);
        let mut args = vec![
            Arg::U32(s.len() as u32),
            Arg::F64(at.dt),
            s.position.arg(),
            s.velocity.arg(),
            s.orientation.arg(),
            s.angular_momentum.arg(),
            s.body_type.arg(),
            s.role.arg(),
            h.sphere.arg(),
            h.radius.arg(),
            at.type_mass.arg(),
            at.type_inertia.arg(),
            h.rolling_inertia.arg(),
            h.material.arg(),
            Arg::U32(h.materials),
            h.material_pairs.arg(),
            Arg::U32(at.laws.round_volume()),
            Arg::U32(at.laws.rolling()),
            at.laws.law.arg(),
            at.laws.material_law.arg(),
            w.count_arg(),
            w.wall_facets.arg(),
        ];
        args.extend(w.facet_args());
        args.extend([
            w.material.arg(),
            w.motion.arg(),
            Arg::U32(self.slots.width() as u32),
        ]);
        args.extend(self.slots.args());
        args.extend([
            at.loads.force.arg(),
            at.loads.torque.arg(),
            at.loads.touching.arg(),
            readback.flag(),
        ]);
        // SAFETY: the parameters of sphere_walls (walls.cu), every array sized for
        // its particles, slots, walls or facets.
        unsafe { run(device, Kernel::SphereWalls, s.len(), &args) }
    }

    /// Doubles of the walls' sums: per wall its force and torque, per facet its
    /// force.
    pub fn sums_width(&self) -> usize {
        let facets: usize = self.host.walls.iter().map(|w| w.triangles.len()).sum();
        6 * self.host.walls.len() + 3 * facets
    }

    /// Launches the energy terms of `n` particles' wall contacts into records
    /// `first..first + n` of `terms` (`device_sums.rs`).
    pub fn energy_terms(
        &self,
        device: &mut dyn Device,
        n: usize,
        terms: &Array<Real>,
        first: usize,
    ) -> Result<(), DeviceError> {
        self.slots.energy_terms(device, n, terms, first)
    }

    /// Takes the walls' poses, velocities, motions and the clock from `world` and
    /// uploads what moved.
    pub fn set_from(&mut self, device: &mut dyn Device, world: &World) -> Result<(), DeviceError> {
        for (mine, theirs) in self.host.walls.iter_mut().zip(&world.walls) {
            mine.pose = theirs.pose;
            mine.velocity = theirs.velocity;
            mine.angular_velocity = theirs.angular_velocity;
            mine.motion = theirs.motion.clone();
        }
        self.host.time = world.time;
        self.placed.update(device, &self.host.walls)
    }

    /// Sets the contacts' tangential history (sorted by key) as that of the last
    /// evaluation, for particles of `ids` (ascending).
    pub fn set_history(
        &mut self,
        device: &mut dyn Device,
        ids: &[u64],
        history: &[(WallKey, TangentialHistory)],
    ) -> Result<(), DeviceError> {
        if self.is_empty() {
            return Ok(());
        }
        self.slots.set_history(device, ids, history)
    }

    /// Wall contacts at the last evaluation.
    pub fn contact_count(&self, device: &dyn Device) -> Result<usize, DeviceError> {
        self.slots.contact_count(device)
    }

    /// Copies the walls' poses and velocities, and their forces, torques and facet
    /// forces of the last read `readback`, into `world`.
    pub fn to_host(&self, readback: &Readback, world: &mut World) {
        let (walls, facet_force) = readback.walls().split_at(6 * self.host.walls.len());
        let mut first = 0;
        for (w, (wall, moved)) in world.walls.iter_mut().zip(&self.host.walls).enumerate() {
            wall.pose = moved.pose;
            wall.velocity = moved.velocity;
            wall.angular_velocity = moved.angular_velocity;
            wall.force = Vector3::from_column_slice(&walls[6 * w..6 * w + 3]);
            wall.torque = Vector3::from_column_slice(&walls[6 * w + 3..6 * w + 6]);
            for (f, out) in wall.facet_force.iter_mut().enumerate() {
                let k = 3 * (first + f);
                *out = Vector3::from_column_slice(&facet_force[k..k + 3]);
            }
            first += wall.triangles.len();
        }
    }

    /// The contacts' tangential history by key, for particles of `ids`, sorted
    /// (empty histories left out).
    pub fn history(
        &self,
        device: &dyn Device,
        ids: &[u64],
    ) -> Result<Vec<(WallKey, TangentialHistory)>, DeviceError> {
        if self.is_empty() {
            return Ok(Vec::new());
        }
        self.slots.history(device, ids)
    }
}
