//! The walls of a world of spheres on a device (`kernels/walls.cu`): their facets
//! as placed in the world, their motion, each particle's contacts with them and
//! their friction springs, and the walls' forces.
//!
//! The walls move on the host, by the CPU backend's own stage (their motions are
//! prescribed or set from outside, a few numbers a step): a copy of the world
//! without particles is advanced each step, and a wall whose pose changed has its
//! facets placed again and uploaded with its velocities.

use nalgebra::{Isometry3, Point3, Vector3};

use super::Kernel;
use super::device::{Arg, Array, Device, DeviceError};
use super::device_list::run;
use super::device_sums::{RowSums, first_rows};
use super::readback::{self, Readback};
use crate::Real;
use crate::engine::backend::WallKey;
use crate::engine::cpu::motion::advance_walls;
use crate::world::World;

/// Contacts a particle may have with the walls at once (`WALL_SLOTS` of triangle.cuh).
pub(super) const SLOTS: usize = 4;
/// Words of a contact's key: the wall and the plane's four rounded numbers.
const KEY: usize = 5;
/// Doubles of a contact's friction spring.
const SPRING: usize = 4;
/// Doubles of a contact's record for the sums.
const RECORD: usize = 9;

/// One set of per-particle contact slots: counts, keys, springs.
#[derive(Debug, Default)]
struct Slots {
    count: Array<u32>,
    keys: Array<i64>,
    springs: Array<Real>,
}

/// The error of a sphere touching walls at more places than it has slots for.
pub(super) fn too_many_wall_contacts() -> DeviceError {
    DeviceError::Capacity(format!(
        "sphere touching walls at more than {SLOTS} places at once"
    ))
}

/// Doubles the rows of the walls' first pass may take together (32 MiB): a row for
/// every 8 particles where that fits, fewer for walls of many facets (each row
/// holds every facet).
const WALL_ROWS_DOUBLES: usize = 1 << 22;

/// Rows of the walls' first pass over `n` particles, each `width` doubles.
fn wall_sum_rows(n: usize, width: usize) -> usize {
    (WALL_ROWS_DOUBLES / width.max(1)).clamp(1, first_rows(n))
}

/// The walls on a device and their host copy (see the module).
#[derive(Debug)]
pub(super) struct DeviceWalls {
    /// The world's walls, materials and clock, without particles: what moves them.
    host: World,
    /// The pose each wall's facets were placed at.
    placed: Vec<Option<Isometry3<Real>>>,
    wall_facets: Array<u32>,
    facets: Array<Real>,
    normals: Array<Real>,
    material: Array<u32>,
    /// Per wall: velocity, angular velocity, reference point.
    motion: Array<Real>,
    old: Slots,
    new: Slots,
    records: Array<Real>,
    record_facet: Array<u32>,
    /// Scratch of the walls' sums (folded into the readback: per wall its force
    /// and torque, then per facet its force).
    sums: RowSums,
}

/// What the wall kernel reads of the particles and their types.
pub(super) struct WallInputs<'a> {
    pub n: usize,
    pub dt: Real,
    pub position: &'a Array<Real>,
    pub velocity: &'a Array<Real>,
    pub orientation: &'a Array<Real>,
    pub angular_momentum: &'a Array<Real>,
    pub body_type: &'a Array<u32>,
    pub role: &'a Array<u8>,
    pub type_radius: &'a Array<Real>,
    pub type_mass: &'a Array<Real>,
    pub type_inertia: &'a Array<Real>,
    pub type_material: &'a Array<u32>,
    pub materials: u32,
    pub material_pairs: &'a Array<Real>,
    pub force: &'a Array<Real>,
    pub torque: &'a Array<Real>,
    pub touching: &'a Array<u8>,
}

impl DeviceWalls {
    /// The walls of `world`, placed and uploaded, for `n` particles.
    pub fn new(device: &mut dyn Device, world: &World, n: usize) -> Result<Self, DeviceError> {
        let mut host = world.clone();
        host.particles = Default::default();
        host.fluid = None;
        let mut starts = vec![0u32];
        for wall in &host.walls {
            starts.push(starts[starts.len() - 1] + wall.triangles.len() as u32);
        }
        let facets = *starts.last().expect("a start") as usize;
        let mut walls = DeviceWalls {
            placed: vec![None; host.walls.len()],
            wall_facets: Array::default(),
            facets: Array::default(),
            normals: Array::default(),
            material: Array::default(),
            motion: Array::default(),
            old: Slots::default(),
            new: Slots::default(),
            records: Array::default(),
            record_facet: Array::default(),
            sums: RowSums::default(),
            host,
        };
        walls.wall_facets.write(device, &starts)?;
        // Without walls the per-particle slots hold nothing (the energy sum still
        // takes them as arguments).
        let n = if walls.host.walls.is_empty() { 0 } else { n };
        let materials: Vec<u32> = walls.host.walls.iter().map(|w| w.material as u32).collect();
        walls.material.write(device, &materials)?;
        walls.facets.resize(device, 9 * facets)?;
        walls.normals.resize(device, 3 * facets)?;
        let count = walls.host.walls.len();
        walls.motion.resize(device, 9 * count)?;
        for slots in [&mut walls.old, &mut walls.new] {
            slots.count.resize(device, n)?;
            slots.keys.resize(device, KEY * SLOTS * n)?;
            slots.springs.resize(device, SPRING * SLOTS * n)?;
        }
        walls.records.resize(device, RECORD * SLOTS * n)?;
        walls.record_facet.resize(device, SLOTS * n)?;
        walls.upload_placement(device)?;
        Ok(walls)
    }

    /// Makes room for `n` particles, the first of them already here keeping their
    /// wall contacts and springs, the new ones without any.
    pub fn grow(&mut self, device: &mut dyn Device, n: usize) -> Result<(), DeviceError> {
        if self.is_empty() {
            return Ok(());
        }
        // The last evaluation's slots are the next one's history; the others are
        // written whole by every evaluation.
        self.new.count.grow_zeroed(device, n)?;
        self.new.keys.grow_zeroed(device, KEY * SLOTS * n)?;
        self.new.springs.grow_zeroed(device, SPRING * SLOTS * n)?;
        self.old.count.resize(device, n)?;
        self.old.keys.resize(device, KEY * SLOTS * n)?;
        self.old.springs.resize(device, SPRING * SLOTS * n)?;
        self.records.resize(device, RECORD * SLOTS * n)?;
        self.record_facet.resize(device, SLOTS * n)
    }

    /// Bytes of device memory the walls hold: their facets and, per particle,
    /// [`SLOTS`] contacts (two sets of keys and springs, and the records).
    pub fn bytes(&self, device: &dyn Device) -> usize {
        let doubles = [
            &self.facets,
            &self.normals,
            &self.motion,
            &self.old.springs,
            &self.new.springs,
            &self.records,
        ];
        let words = [
            &self.wall_facets,
            &self.material,
            &self.old.count,
            &self.new.count,
            &self.record_facet,
        ];
        doubles.iter().map(|a| a.bytes(device)).sum::<usize>()
            + words.iter().map(|a| a.bytes(device)).sum::<usize>()
            + self.old.keys.bytes(device)
            + self.new.keys.bytes(device)
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
        self.upload_placement(device)
    }

    /// Places the facets of every wall whose pose changed (as the CPU backend's wall
    /// stage places them: corners by the pose, unit normals of the placed corners)
    /// and uploads them, and every wall's velocities and reference point.
    fn upload_placement(&mut self, device: &mut dyn Device) -> Result<(), DeviceError> {
        let mut motion = Vec::with_capacity(9 * self.host.walls.len());
        let mut first = 0;
        for (w, wall) in self.host.walls.iter().enumerate() {
            let reference = wall.reference();
            motion.extend(
                wall.velocity
                    .iter()
                    .chain(wall.angular_velocity.iter())
                    .copied(),
            );
            motion.extend(reference.coords.iter().copied());
            let facets = wall.triangles.len();
            if self.placed[w] != Some(wall.pose) {
                self.placed[w] = Some(wall.pose);
                let triangles: Vec<[Point3<Real>; 3]> =
                    (0..facets).map(|f| wall.facet_world(f)).collect();
                let corners: Vec<Real> = triangles
                    .iter()
                    .flat_map(|t| t.iter().flat_map(|p| p.coords.iter().copied()))
                    .collect();
                let normals: Vec<Real> = triangles
                    .iter()
                    .flat_map(|t| {
                        let n: Vector3<Real> = (t[1] - t[0]).cross(&(t[2] - t[0])).normalize();
                        [n.x, n.y, n.z]
                    })
                    .collect();
                self.facets.write_at(device, 9 * first, &corners)?;
                self.normals.write_at(device, 3 * first, &normals)?;
            }
            first += facets;
        }
        self.motion.write(device, &motion)
    }

    /// The particles' wall contacts, added to their forces and torques (after the
    /// pairs' gather), and the walls' sums into the readback, whose flag says
    /// whether a particle had more than [`SLOTS`] wall contacts.
    pub fn contacts(
        &mut self,
        device: &mut dyn Device,
        at: &WallInputs,
        readback: &Readback,
    ) -> Result<(), DeviceError> {
        std::mem::swap(&mut self.old, &mut self.new);
        let (old, new) = (&self.old, &self.new);
        let walls = Arg::U32(self.host.walls.len() as u32);
        // SAFETY: the parameters of sphere_walls (walls.cu), every
        // array sized for its particles, slots, walls or facets.
        readback.clear_flag(device)?;
        unsafe {
            run(
                device,
                Kernel::SphereWalls,
                at.n,
                &[
                    Arg::U32(at.n as u32),
                    Arg::F64(at.dt),
                    at.position.arg(),
                    at.velocity.arg(),
                    at.orientation.arg(),
                    at.angular_momentum.arg(),
                    at.body_type.arg(),
                    at.role.arg(),
                    at.type_radius.arg(),
                    at.type_mass.arg(),
                    at.type_inertia.arg(),
                    at.type_material.arg(),
                    Arg::U32(at.materials),
                    at.material_pairs.arg(),
                    walls,
                    self.wall_facets.arg(),
                    self.facets.arg(),
                    self.normals.arg(),
                    self.material.arg(),
                    self.motion.arg(),
                    old.count.arg(),
                    old.keys.arg(),
                    old.springs.arg(),
                    new.count.arg(),
                    new.keys.arg(),
                    new.springs.arg(),
                    self.records.arg(),
                    self.record_facet.arg(),
                    at.force.arg(),
                    at.torque.arg(),
                    at.touching.arg(),
                    readback.flag(),
                ],
            )?;
        }
        // The walls' sums: rows of partial sums over every so-many particles, folded.
        let width = self.sums_width();
        let rows = wall_sum_rows(at.n, width);
        let partials = self.sums.rows(device, rows, width)?;
        // SAFETY: the parameters of wall_sum_rows (walls.cu): the slots hold n
        // particles', `partials` room for `rows` rows of `width`.
        unsafe {
            run(
                device,
                Kernel::WallSumRows,
                rows,
                &[
                    Arg::U32(at.n as u32),
                    at.position.arg(),
                    walls,
                    self.wall_facets.arg(),
                    self.motion.arg(),
                    new.count.arg(),
                    new.keys.arg(),
                    self.records.arg(),
                    self.record_facet.arg(),
                    Arg::U32(rows as u32),
                    partials.arg(),
                ],
            )?;
        }
        self.sums
            .fold(device, rows, width, &readback.device, readback::WALLS)
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
        // SAFETY: the parameters of wall_energy_terms (walls.cu); the slots hold n
        // particles', `terms` room for records up to first + n.
        unsafe {
            run(
                device,
                Kernel::WallEnergyTerms,
                n,
                &[
                    Arg::U32(n as u32),
                    self.new.count.arg(),
                    self.new.keys.arg(),
                    self.records.arg(),
                    self.old.count.arg(),
                    self.old.keys.arg(),
                    self.old.springs.arg(),
                    Arg::U32(first as u32),
                    terms.arg(),
                ],
            )
        }
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
        self.upload_placement(device)
    }

    /// Sets the patches' friction springs (sorted by key) as those of the last
    /// evaluation, for particles of `ids` (ascending).
    pub fn set_history(
        &mut self,
        device: &mut dyn Device,
        ids: &[u64],
        history: &[(WallKey, crate::contact::TangentialHistory)],
    ) -> Result<(), DeviceError> {
        if self.is_empty() {
            return Ok(());
        }
        let n = ids.len();
        let mut count = vec![0u32; n];
        let mut keys = vec![0i64; KEY * SLOTS * n];
        let mut springs = vec![0.0; SPRING * SLOTS * n];
        for ((id, wall, plane), h) in history {
            let Ok(i) = ids.binary_search(id) else {
                continue;
            };
            let s = count[i] as usize;
            if s == SLOTS {
                return Err(too_many_wall_contacts());
            }
            let slot = SLOTS * i + s;
            keys[KEY * slot] = *wall as i64;
            keys[KEY * slot + 1..KEY * slot + KEY].copy_from_slice(plane);
            springs[SPRING * slot..SPRING * slot + SPRING].copy_from_slice(&[
                h.spring.x,
                h.spring.y,
                h.spring.z,
                h.stiffness,
            ]);
            count[i] += 1;
        }
        self.new.count.write(device, &count)?;
        self.new.keys.write(device, &keys)?;
        self.new.springs.write(device, &springs)
    }

    /// Wall contacts at the last evaluation.
    pub fn contact_count(&self, device: &dyn Device) -> Result<usize, DeviceError> {
        Ok(self
            .new
            .count
            .read(device)?
            .iter()
            .map(|&c| c as usize)
            .sum())
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

    /// The patches' friction springs by key, for particles of `ids`.
    pub fn history(
        &self,
        device: &dyn Device,
        ids: &[u64],
    ) -> Result<Vec<(WallKey, [Real; 4])>, DeviceError> {
        let (count, keys) = (self.new.count.read(device)?, self.new.keys.read(device)?);
        let springs = self.new.springs.read(device)?;
        let mut out = Vec::new();
        for (i, &c) in count.iter().enumerate() {
            for s in 0..c as usize {
                let slot = SLOTS * i + s;
                let k = &keys[KEY * slot..KEY * slot + KEY];
                let h = &springs[SPRING * slot..SPRING * slot + SPRING];
                out.push((
                    (ids[i], k[0] as u32, [k[1], k[2], k[3], k[4]]),
                    [h[0], h[1], h[2], h[3]],
                ));
            }
        }
        out.sort_by_key(|e| e.0);
        Ok(out)
    }
}
