//! The halo of an MPI rank's share (`kernels/halo.cu`): in a step without a
//! renewal, only the states of the owned particles other ranks hold as ghosts go
//! down to the host, and only the ghosts' states come up.

use nalgebra::{Point3, Quaternion, UnitQuaternion, Vector3};

use super::DeviceWorld;
use crate::Real;
use crate::engine::cuda::Kernel;
use crate::engine::cuda::device::{Arg, Array, DeviceError};
use crate::engine::cuda::device_list::run;
use crate::world::World;

/// Doubles of a state record (`HALO_DOUBLES` in `kernels/halo.cu`): position,
/// orientation (i, j, k, w), velocity, angular momentum, frozen.
const HALO: usize = 14;

/// The device slots of a halo transfer and its state records, with the host's copies
/// (kept between steps: a step's halo allocates nothing once they have grown).
#[derive(Debug, Default)]
pub(super) struct HaloArrays {
    slots: Array<u32>,
    records: Array<Real>,
    host_slots: Vec<u32>,
    host_records: Vec<Real>,
}

impl HaloArrays {
    /// Device memory held, bytes.
    pub(super) fn bytes(&self, device: &dyn crate::engine::cuda::device::Device) -> usize {
        self.slots.bytes(device) + self.records.bytes(device)
    }
}

impl DeviceWorld {
    /// Copies the motion state (position, orientation, velocity, angular momentum)
    /// of the host entries `entries` (owned particles sent as ghosts) into `world`.
    pub fn states_to_host(
        &mut self,
        world: &mut World,
        entries: &[usize],
    ) -> Result<(), DeviceError> {
        if entries.is_empty() {
            return Ok(());
        }
        let (d, a, h) = (self.device.as_mut(), &self.particles, &mut self.halo);
        h.host_slots.clear();
        h.host_slots
            .extend(entries.iter().map(|&i| self.slot_of[i]));
        let slots = &h.host_slots;
        h.slots.write(d, slots)?;
        h.records.resize(d, HALO * slots.len())?;
        // SAFETY: the parameters of pack_states (halo.cu): the slots index the
        // particles' arrays, the records hold a record per slot.
        unsafe {
            run(
                d,
                Kernel::PackStates,
                slots.len(),
                &[
                    Arg::U32(slots.len() as u32),
                    h.slots.arg(),
                    a.position.arg(),
                    a.orientation.arg(),
                    a.velocity.arg(),
                    a.angular_momentum.arg(),
                    a.role.arg(),
                    h.records.arg(),
                ],
            )?;
        }
        h.records.read_into(d, &mut h.host_records)?;
        let p = &mut world.particles;
        for (&i, r) in entries.iter().zip(h.host_records.chunks_exact(HALO)) {
            p.position[i] = Point3::new(r[0], r[1], r[2]);
            p.orientation[i] =
                UnitQuaternion::new_unchecked(Quaternion::new(r[6], r[3], r[4], r[5]));
            p.velocity[i] = Vector3::new(r[7], r[8], r[9]);
            p.angular_momentum[i] = Vector3::new(r[10], r[11], r[12]);
        }
        Ok(())
    }

    /// Takes the ghosts' states (motion and frozen flag) from `world`, whose
    /// ghosts are the stepper's (the same ids at the same entries).
    pub fn ghosts_from_host(&mut self, world: &World) -> Result<(), DeviceError> {
        let p = &world.particles;
        let ghosts = self.owned..self.n;
        if ghosts.is_empty() {
            return Ok(());
        }
        let (d, a, h) = (self.device.as_mut(), &self.particles, &mut self.halo);
        h.host_slots.clear();
        h.host_slots.extend(ghosts.clone().map(|i| self.slot_of[i]));
        h.host_records.clear();
        h.host_records.extend(ghosts.flat_map(|i| {
            let (x, q) = (p.position[i], p.orientation[i].coords);
            let (v, l) = (p.velocity[i], p.angular_momentum[i]);
            let frozen = if p.frozen[i] { 1.0 } else { 0.0 };
            [
                x.x, x.y, x.z, q[0], q[1], q[2], q[3], v.x, v.y, v.z, l.x, l.y, l.z, frozen,
            ]
        }));
        let slots = &h.host_slots;
        h.slots.write(d, slots)?;
        h.records.write(d, &h.host_records)?;
        // SAFETY: the parameters of unpack_ghost_states (halo.cu): the slots index
        // the particles' arrays, the records hold a record per slot.
        unsafe {
            run(
                d,
                Kernel::UnpackGhostStates,
                slots.len(),
                &[
                    Arg::U32(slots.len() as u32),
                    h.slots.arg(),
                    h.records.arg(),
                    a.position.arg(),
                    a.orientation.arg(),
                    a.velocity.arg(),
                    a.angular_momentum.arg(),
                    a.role.arg(),
                ],
            )?;
        }
        self.stale = None;
        Ok(())
    }
}
