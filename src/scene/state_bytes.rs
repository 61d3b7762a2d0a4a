//! The dynamic state of a [`crate::scene::Simulation`] ([`SimState`]) as bytes, and back.
//!
//! What is saved is everything that evolves: particles (with this step's forces, which
//! the next half kick uses, whether they are frozen, and their cell in the space
//! order), wall poses, velocities and forces, the tangential contact history, the
//! positions and wall poses the candidate lists were last built from, inlet
//! counters, box offsets and random generators, time, step count, the settling
//! clock, the bed height last measured, and a coupled fluid's inputs, particle
//! shares and exchange.
//! What a scene defines once (materials, shapes, wall meshes and their facet grids) is
//! not saved: a state is restored into a simulation of the same scene, and a
//! fingerprint of that scene in the header refuses any other. Restoring and stepping
//! on gives the same bits as never having saved.
//!
//! The format is little-endian, versioned by a magic string; every count is checked
//! against what is left, so garbage bytes give an error, never a panic or a huge
//! allocation. A container that holds a state (the Component's saved state, a run's
//! checkpoint) ends with a CRC-32 of everything before it ([`StateWriter::into_checked`],
//! [`StateReader::checked`]): a flipped or lost byte is refused before anything is
//! read.

use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion, Vector3};
use thiserror::Error;

use super::state::{FluidState, InletState, SimState, WallState};
use crate::Real;
use crate::contact::TangentialHistory;
use crate::engine::StepStats;
use crate::engine::{ContactHistory, ListAnchors};
use crate::scene::energy_ledger::EnergyLedger;
use crate::world::{CellShares, MomentumExchange, Particles};

/// The header of a state; the digit is the format's version (4: states in checked
/// containers; 5: the rolling spring in the contact history; 6: the fluid field; 7:
/// the energy account; 8: what the candidate lists were last built from, and each
/// particle's cell in the space order).
pub const STATE_MAGIC: &[u8; 8] = b"TALUSST8";

/// The header of version 7, still read: its lists are built from the restored world.
const STATE_MAGIC_7: &[u8; 8] = b"TALUSST7";

/// Whether `bytes` start with the header of a state this build reads.
pub fn starts_as_state(bytes: &[u8]) -> bool {
    bytes.starts_with(STATE_MAGIC) || bytes.starts_with(STATE_MAGIC_7)
}

/// Why bytes could not be restored as a state.
#[derive(Debug, Error, PartialEq)]
pub enum StateError {
    /// Not a talus state (or one of another format version).
    #[error("not a talus state (the bytes do not start with the state header)")]
    NotAState,
    /// A state of another scene.
    #[error("the state belongs to another scene (fingerprint {found:#x}, expected {expected:#x})")]
    OtherScene {
        /// The fingerprint in the bytes.
        found: u64,
        /// The current scene's.
        expected: u64,
    },
    /// The bytes end early or hold an impossible value.
    #[error("corrupt state: {0}")]
    Corrupt(String),
    /// The simulation is one rank's share of a decomposed run, whose states are
    /// not gathered and scattered yet.
    #[error("states are not restored on MPI ranks yet")]
    OnRanks,
    /// The checksum at the end does not match the bytes (damaged or truncated).
    #[error(
        "damaged state: its checksum is {found:#010x}, the bytes give {computed:#010x} (truncated or changed after it was written)"
    )]
    Checksum {
        /// The checksum stored at the end.
        found: u32,
        /// The checksum of the bytes before it.
        computed: u32,
    },
}

/// Appends values to a byte buffer.
#[derive(Debug, Default)]
pub struct StateWriter {
    bytes: Vec<u8>,
}

impl StateWriter {
    /// The bytes written.
    pub fn into_bytes(self) -> Vec<u8> {
        self.bytes
    }

    /// The bytes written followed by their CRC-32 (read back by
    /// [`StateReader::checked`]).
    pub fn into_checked(mut self) -> Vec<u8> {
        let crc = crate::checksum::crc32(&self.bytes);
        self.bytes.extend_from_slice(&crc.to_le_bytes());
        self.bytes
    }

    /// Magic bytes heading a container.
    pub fn magic(&mut self, magic: &[u8]) {
        self.bytes.extend_from_slice(magic);
    }

    /// An unsigned integer.
    pub fn u64(&mut self, x: u64) {
        self.bytes.extend_from_slice(&x.to_le_bytes());
    }

    /// A float, bit for bit.
    pub fn f64(&mut self, x: Real) {
        self.u64(x.to_bits());
    }

    /// A vector.
    pub fn vec3(&mut self, v: &Vector3<Real>) {
        v.iter().for_each(|x| self.f64(*x));
    }

    /// A quaternion (w, x, y, z).
    pub fn quat(&mut self, q: &UnitQuaternion<Real>) {
        [q.w, q.i, q.j, q.k].iter().for_each(|x| self.f64(*x));
    }

    /// A length-prefixed byte string.
    pub fn blob(&mut self, b: &[u8]) {
        self.u64(b.len() as u64);
        self.bytes.extend_from_slice(b);
    }
}

/// Reads values written by a [`StateWriter`].
#[derive(Debug)]
pub struct StateReader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> StateReader<'a> {
    /// A reader at the start of `bytes`.
    pub fn new(bytes: &'a [u8]) -> Self {
        StateReader { bytes, at: 0 }
    }

    /// A reader of bytes written by [`StateWriter::into_checked`], once their checksum
    /// matched; it reads up to the checksum.
    pub fn checked(bytes: &'a [u8]) -> Result<Self, StateError> {
        let Some(body_len) = bytes.len().checked_sub(4) else {
            return Err(StateError::Corrupt(format!(
                "{} bytes are too few for a state",
                bytes.len()
            )));
        };
        let (body, tail) = bytes.split_at(body_len);
        let found = u32::from_le_bytes(tail.try_into().expect("4 bytes"));
        let computed = crate::checksum::crc32(body);
        if found != computed {
            return Err(StateError::Checksum { found, computed });
        }
        Ok(StateReader::new(body))
    }

    /// Whether the next bytes are `magic` (taken when they are).
    pub fn magic(&mut self, magic: &[u8]) -> bool {
        let at = self.at;
        if self.take(magic.len()).ok() == Some(magic) {
            true
        } else {
            self.at = at;
            false
        }
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8], StateError> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let end = end.ok_or_else(|| {
            StateError::Corrupt(format!(
                "ends at byte {} of {} needed",
                self.bytes.len(),
                self.at + n
            ))
        })?;
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }

    /// An unsigned integer.
    pub fn u64(&mut self) -> Result<u64, StateError> {
        Ok(u64::from_le_bytes(
            self.take(8)?.try_into().expect("8 bytes"),
        ))
    }

    /// A count of items of at least `item_bytes` each, checked against what is left.
    pub fn count(&mut self, item_bytes: usize) -> Result<usize, StateError> {
        let n = self.u64()?;
        let left = (self.bytes.len() - self.at) as u64;
        if n.saturating_mul(item_bytes.max(1) as u64) > left {
            return Err(StateError::Corrupt(format!(
                "a count of {n} at byte {} exceeds the {left} bytes left",
                self.at - 8
            )));
        }
        Ok(n as usize)
    }

    /// A float.
    pub fn f64(&mut self) -> Result<Real, StateError> {
        Ok(Real::from_bits(self.u64()?))
    }

    /// A vector.
    pub fn vec3(&mut self) -> Result<Vector3<Real>, StateError> {
        Ok(Vector3::new(self.f64()?, self.f64()?, self.f64()?))
    }

    /// A unit quaternion (stored as written, not renormalised).
    pub fn quat(&mut self) -> Result<UnitQuaternion<Real>, StateError> {
        let (w, i, j, k) = (self.f64()?, self.f64()?, self.f64()?, self.f64()?);
        let q = Quaternion::new(w, i, j, k);
        if !((q.norm() - 1.0).abs() < 1e-6) {
            return Err(StateError::Corrupt(format!(
                "orientation {q:?} is not a unit quaternion"
            )));
        }
        Ok(UnitQuaternion::new_unchecked(q))
    }

    /// A length-prefixed byte string.
    pub fn blob(&mut self) -> Result<&'a [u8], StateError> {
        let n = self.count(1)?;
        self.take(n)
    }

    /// Whether every byte was read.
    pub fn is_done(&self) -> bool {
        self.at == self.bytes.len()
    }
}

fn write_history(w: &mut StateWriter, h: &TangentialHistory) {
    w.vec3(&h.spring);
    w.f64(h.stiffness);
    w.f64(h.twist);
    w.vec3(&h.rolling);
}

fn read_history(r: &mut StateReader) -> Result<TangentialHistory, StateError> {
    Ok(TangentialHistory {
        spring: r.vec3()?,
        stiffness: r.f64()?,
        twist: r.f64()?,
        rolling: r.vec3()?,
    })
}

impl SimState {
    /// Writes the state, headed by the scene's `fingerprint`.
    pub fn write(&self, fingerprint: u64, w: &mut StateWriter) {
        w.magic(STATE_MAGIC);
        w.u64(fingerprint);
        w.f64(self.time);
        w.f64(self.dt);
        w.u64(self.steps);
        w.u64(self.next_id);
        w.f64(self.quiet_since.unwrap_or(Real::NAN));
        w.f64(self.bed_height.unwrap_or(Real::NAN));
        w.u64(self.stats.contacts as u64);
        w.f64(self.stats.elastic_energy);
        self.energy.sums().iter().for_each(|x| w.f64(*x));

        let p = &self.particles;
        w.u64(p.len() as u64);
        for i in 0..p.len() {
            w.u64(p.id[i]);
            w.u64(p.body_type[i] as u64);
            w.vec3(&p.position[i].coords);
            w.quat(&p.orientation[i]);
            w.vec3(&p.velocity[i]);
            w.vec3(&p.angular_momentum[i]);
            w.vec3(&p.force[i]);
            w.vec3(&p.torque[i]);
            w.u64(p.frozen[i] as u64);
            w.u64(p.cell_code[i]);
        }

        w.u64(self.walls.len() as u64);
        for wall in &self.walls {
            w.vec3(&wall.pose.translation.vector);
            w.quat(&wall.pose.rotation);
            w.vec3(&wall.velocity);
            w.vec3(&wall.angular_velocity);
            w.vec3(&wall.force);
            w.vec3(&wall.torque);
            w.u64(wall.facet_force.len() as u64);
            wall.facet_force.iter().for_each(|f| w.vec3(f));
        }

        w.u64(self.inlets.len() as u64);
        for inlet in &self.inlets {
            w.u64(inlet.inserted as u64);
            w.u64(inlet.count as u64);
            w.vec3(&inlet.offset);
            w.blob(&inlet.rng);
        }

        let history = &self.history;
        w.u64(history.pairs.len() as u64);
        for ((a, b), h) in &history.pairs {
            w.u64(*a);
            w.u64(*b);
            write_history(w, h);
        }
        w.u64(history.walls.len() as u64);
        for ((id, wall, plane), h) in &history.walls {
            w.u64(*id);
            w.u64(*wall as u64);
            plane.iter().for_each(|x| w.u64(*x as u64));
            write_history(w, h);
        }
        write_fluid(w, self.fluid.as_ref());
        write_list(w, self.list.as_ref());
    }

    /// Reads a state written by [`SimState::write`] for the scene with this
    /// `fingerprint`, leaving the reader after it (the caller checks
    /// [`StateReader::is_done`] or reads on). Whether it fits the scene (body types,
    /// walls, facets, inlets) is checked when it is restored.
    pub fn read(fingerprint: u64, r: &mut StateReader) -> Result<SimState, StateError> {
        // Version 8 adds each particle's cell code and the lists' anchors.
        let has_list = if r.magic(STATE_MAGIC) {
            true
        } else if r.magic(STATE_MAGIC_7) {
            false
        } else {
            return Err(StateError::NotAState);
        };
        let found = r.u64()?;
        if found != fingerprint {
            return Err(StateError::OtherScene {
                found,
                expected: fingerprint,
            });
        }
        let time = r.f64()?;
        let dt = r.f64()?;
        let steps = r.u64()?;
        let next_id = r.u64()?;
        let quiet = r.f64()?;
        let height = r.f64()?;
        let stats = StepStats {
            contacts: r.u64()? as usize,
            elastic_energy: r.f64()?,
            ..StepStats::default()
        };
        let energy = EnergyLedger {
            start: r.f64()?,
            wall_work: r.f64()?,
            fluid_work: r.f64()?,
            dissipated: r.f64()?,
            host: r.f64()?,
            motion_in: r.f64()?,
        };
        if !energy.is_finite() {
            return Err(StateError::Corrupt(format!(
                "the energy account is not finite: {energy:?}"
            )));
        }

        let n = r.count(8 * (22 + usize::from(has_list)))?;
        let mut particles = Particles::default();
        for _ in 0..n {
            let id = r.u64()?;
            let body_type = r.u64()?;
            let body_type = u32::try_from(body_type).map_err(|_| {
                StateError::Corrupt(format!("particle {id} has body type {body_type}"))
            })?;
            let position = Point3::from(r.vec3()?);
            let orientation = r.quat()?;
            particles.push(body_type, position, orientation, id);
            let i = particles.len() - 1;
            particles.velocity[i] = r.vec3()?;
            particles.angular_momentum[i] = r.vec3()?;
            particles.force[i] = r.vec3()?;
            particles.torque[i] = r.vec3()?;
            particles.frozen[i] = match r.u64()? {
                0 => false,
                1 => true,
                x => {
                    return Err(StateError::Corrupt(format!(
                        "particle {id} has frozen flag {x}, not 0 or 1"
                    )));
                }
            };
            if has_list {
                particles.cell_code[i] = r.u64()?;
            }
        }

        let mut walls = Vec::new();
        for _ in 0..r.count(8 * 20)? {
            let t = r.vec3()?;
            let q = r.quat()?;
            let mut wall = WallState {
                pose: Isometry3::from_parts(Translation3::from(t), q),
                velocity: r.vec3()?,
                angular_velocity: r.vec3()?,
                force: r.vec3()?,
                torque: r.vec3()?,
                facet_force: Vec::new(),
            };
            for _ in 0..r.count(24)? {
                wall.facet_force.push(r.vec3()?);
            }
            walls.push(wall);
        }

        let mut inlets = Vec::new();
        for _ in 0..r.count(8 * 6)? {
            inlets.push(InletState {
                inserted: r.u64()? as usize,
                count: r.u64()? as usize,
                offset: r.vec3()?,
                rng: r.blob()?.to_vec(),
            });
        }

        let mut history = ContactHistory::default();
        for _ in 0..r.count(8 * 7)? {
            let key = (r.u64()?, r.u64()?);
            history.pairs.push((key, read_history(r)?));
        }
        for _ in 0..r.count(8 * 11)? {
            let id = r.u64()?;
            let wall = r.u64()? as u32;
            let mut plane = [0i64; 4];
            for x in &mut plane {
                *x = r.u64()? as i64;
            }
            history.walls.push(((id, wall, plane), read_history(r)?));
        }
        let fluid = read_fluid(r)?;
        let list = if has_list { read_list(r)? } else { None };
        Ok(SimState {
            time,
            dt,
            steps,
            next_id,
            quiet_since: (!quiet.is_nan()).then_some(quiet),
            bed_height: (!height.is_nan()).then_some(height),
            stats,
            energy,
            particles,
            walls,
            inlets,
            history,
            list,
            fluid,
        })
    }
}

fn write_list(w: &mut StateWriter, list: Option<&ListAnchors>) {
    let Some(list) = list else {
        w.u64(0);
        return;
    };
    w.u64(1);
    w.u64(list.particles.len() as u64);
    for (id, x) in &list.particles {
        w.u64(*id);
        w.vec3(&x.coords);
    }
    w.u64(list.wall_poses.len() as u64);
    for pose in &list.wall_poses {
        w.vec3(&pose.translation.vector);
        w.quat(&pose.rotation);
    }
}

fn read_list(r: &mut StateReader) -> Result<Option<ListAnchors>, StateError> {
    match r.u64()? {
        0 => return Ok(None),
        1 => {}
        x => return Err(StateError::Corrupt(format!("list flag {x}, not 0 or 1"))),
    }
    let mut list = ListAnchors::default();
    let finite = |v: Vector3<Real>, what: &dyn Fn() -> String| {
        if v.iter().all(|x| x.is_finite()) {
            Ok(v)
        } else {
            Err(StateError::Corrupt(format!(
                "{} is not finite: {v:?}",
                what()
            )))
        }
    };
    for _ in 0..r.count(32)? {
        let id = r.u64()?;
        let x = finite(r.vec3()?, &|| {
            format!("particle {id}'s position at the list build")
        })?;
        list.particles.push((id, Point3::from(x)));
    }
    for w in 0..r.count(56)? {
        let t = finite(r.vec3()?, &|| {
            format!("wall {w}'s position at the list build")
        })?;
        let q = r.quat()?;
        (list.wall_poses).push(Isometry3::from_parts(Translation3::from(t), q));
    }
    Ok(Some(list))
}

fn write_vec3s(w: &mut StateWriter, v: &[Vector3<Real>]) {
    w.u64(v.len() as u64);
    v.iter().for_each(|x| w.vec3(x));
}

fn read_vec3s(r: &mut StateReader) -> Result<Vec<Vector3<Real>>, StateError> {
    (0..r.count(24)?).map(|_| r.vec3()).collect()
}

fn write_fluid(w: &mut StateWriter, fluid: Option<&FluidState>) {
    let Some(f) = fluid else {
        w.u64(0);
        return;
    };
    w.u64(1);
    write_vec3s(w, &f.velocity);
    write_vec3s(w, &f.pressure_gradient);
    w.u64(f.solid_fraction.len() as u64);
    f.solid_fraction.iter().for_each(|&x| w.f64(x));
    write_vec3s(w, &f.particle_velocity);
    let (starts, cells, volumes, ids) = f.shares.parts();
    w.u64(ids.len() as u64);
    ids.iter().for_each(|&x| w.u64(x));
    starts.iter().for_each(|&x| w.u64(x as u64));
    w.u64(cells.len() as u64);
    for (&c, &v) in cells.iter().zip(volumes) {
        w.u64(c as u64);
        w.f64(v);
    }
    write_vec3s(w, &f.exchange.drag);
    write_vec3s(w, &f.exchange.impulse);
    w.f64(f.exchange.elapsed);
}

fn read_fluid(r: &mut StateReader) -> Result<Option<FluidState>, StateError> {
    match r.u64()? {
        0 => return Ok(None),
        1 => {}
        x => return Err(StateError::Corrupt(format!("fluid flag {x}, not 0 or 1"))),
    }
    let velocity = read_vec3s(r)?;
    let pressure_gradient = read_vec3s(r)?;
    let solid_fraction = (0..r.count(8)?)
        .map(|_| r.f64())
        .collect::<Result<_, _>>()?;
    let particle_velocity = read_vec3s(r)?;
    let ids: Vec<u64> = (0..r.count(16)?)
        .map(|_| r.u64())
        .collect::<Result<_, _>>()?;
    let starts = (0..=ids.len())
        .map(|_| r.u64().map(|x| x as u32))
        .collect::<Result<_, _>>()?;
    let (mut cells, mut volumes) = (Vec::new(), Vec::new());
    for _ in 0..r.count(16)? {
        cells.push(r.u64()? as u32);
        volumes.push(r.f64()?);
    }
    let shares = CellShares::from_parts(starts, cells, volumes, ids, u32::MAX as usize)
        .map_err(StateError::Corrupt)?;
    Ok(Some(FluidState {
        velocity,
        pressure_gradient,
        solid_fraction,
        particle_velocity,
        shares,
        exchange: MomentumExchange {
            drag: read_vec3s(r)?,
            impulse: read_vec3s(r)?,
            elapsed: r.f64()?,
        },
    }))
}
