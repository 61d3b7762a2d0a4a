//! What a step hands to the host, in one device buffer read once a step: a read
//! waits for every launch before it to finish, so each one costs the GPU a drained
//! queue.
//!
//! # Layout (doubles)
//! - `[0]`: the walls' overflow flag, a 32-bit word in the double's first bytes
//!   (`sphere_walls` sets it by `atomicOr`; zeroed before each evaluation);
//! - `[1..6]`: the contacts' sums (elastic energy, dissipated, wall contacts, pair
//!   contacts, candidate pairs: `device_sums.rs`);
//! - `[6..]`: per wall its force and torque, then per facet its force
//!   (`device_walls.rs`).

use super::Kernel;
use super::device::{Arg, Array, Device, DeviceError};
use super::device_list::run;
use crate::Real;

/// Where the contacts' sums start.
pub(super) const SUMS: usize = 1;
/// Where the walls' sums start.
pub(super) const WALLS: usize = SUMS + super::device_sums::ENERGY_RECORD;

/// The buffer on the device and its last copy on the host (see the module).
#[derive(Debug, Default)]
pub(super) struct Readback {
    pub device: Array<Real>,
    host: Vec<Real>,
}

impl Readback {
    /// A readback for walls' sums of `wall_width` doubles, zero on both sides.
    pub fn new(device: &mut dyn Device, wall_width: usize) -> Result<Self, DeviceError> {
        let host = vec![0.0; WALLS + wall_width];
        let mut buffer = Array::default();
        buffer.write(device, &host)?;
        Ok(Readback {
            device: buffer,
            host,
        })
    }

    /// Zeroes the overflow flag (before an evaluation).
    pub fn clear_flag(&self, device: &mut dyn Device) -> Result<(), DeviceError> {
        // SAFETY: the buffer holds at least one double, two words.
        unsafe {
            run(
                device,
                Kernel::ZeroWords,
                2,
                &[Arg::U32(2), self.device.arg()],
            )
        }
    }

    /// The flag as the kernels' `unsigned*` argument.
    pub fn flag(&self) -> Arg {
        self.device.arg()
    }

    /// Copies the buffer to the host (the step's one read).
    pub fn read(&mut self, device: &dyn Device) -> Result<(), DeviceError> {
        self.host = self.device.read(device)?;
        Ok(())
    }

    /// Whether a sphere touched the walls at more places than it has slots for.
    pub fn overflowed(&self) -> bool {
        self.host[0].to_bits() != 0
    }

    /// The contacts' sums of the last read.
    pub fn sums(&self) -> &[Real] {
        &self.host[SUMS..WALLS]
    }

    /// The walls' sums of the last read.
    pub fn walls(&self) -> &[Real] {
        &self.host[WALLS..]
    }
}
