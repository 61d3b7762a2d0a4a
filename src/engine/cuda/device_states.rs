//! The particles' states as the contact kernels read them: position, orientation
//! (i, j, k, w, as nalgebra stores it), velocity, angular momentum, body type and
//! role (`kernels/contact.cuh`: frozen, a ghost, or both).

use nalgebra::Vector3;

use super::device::{Arg, Array, Device, DeviceError};
use crate::Real;
use crate::world::Particles;

/// A particle's role byte (`kernels/contact.cuh`): frozen, a ghost, or both.
pub(super) const FROZEN_ROLE: u8 = 1;
pub(super) const GHOST_ROLE: u8 = 2;

/// The role bytes of the entries `order` of `p`.
pub(super) fn roles(p: &Particles, order: impl IntoIterator<Item = usize>) -> Vec<u8> {
    let role = |i: usize| {
        let ghost = if p.is_ghost(i) { GHOST_ROLE } else { 0 };
        ghost | if p.frozen[i] { FROZEN_ROLE } else { 0 }
    };
    order.into_iter().map(role).collect()
}

/// The arrays of the particles' states a contact kernel reads, wherever they are
/// held (a [`DeviceStates`], or a stepper's particles).
///
/// # Invariant
/// Every array holds the same particles: 3 doubles each of position, velocity and
/// angular momentum, 4 of orientation, a body type and a role each.
#[derive(Clone, Copy, Debug)]
pub(super) struct StateView<'a> {
    pub position: &'a Array<Real>,
    pub orientation: &'a Array<Real>,
    pub velocity: &'a Array<Real>,
    pub angular_momentum: &'a Array<Real>,
    pub body_type: &'a Array<u32>,
    pub role: &'a Array<u8>,
}

impl StateView<'_> {
    /// The particles.
    pub fn len(&self) -> usize {
        self.body_type.len()
    }

    /// The states as launch arguments: position, orientation, velocity, angular
    /// momentum, body type (the role apart: not every kernel reads it).
    pub fn args(&self) -> [Arg; 5] {
        [
            self.position.arg(),
            self.orientation.arg(),
            self.velocity.arg(),
            self.angular_momentum.arg(),
            self.body_type.arg(),
        ]
    }
}

/// The states of a world's particles on a device, in the world's order.
#[derive(Debug, Default)]
pub struct DeviceStates {
    position: Array<Real>,
    orientation: Array<Real>,
    velocity: Array<Real>,
    angular_momentum: Array<Real>,
    body_type: Array<u32>,
    role: Array<u8>,
}

impl DeviceStates {
    /// The states as the kernels read them.
    pub(super) fn view(&self) -> StateView<'_> {
        StateView {
            position: &self.position,
            orientation: &self.orientation,
            velocity: &self.velocity,
            angular_momentum: &self.angular_momentum,
            body_type: &self.body_type,
            role: &self.role,
        }
    }

    /// Copies the states of the particles `p` in.
    pub fn upload(&mut self, device: &mut dyn Device, p: &Particles) -> Result<(), DeviceError> {
        let flat = |v: &[Vector3<Real>]| -> Vec<Real> {
            v.iter().flat_map(|x| x.iter().copied()).collect()
        };
        let position: Vec<Real> = (p.position.iter())
            .flat_map(|x| x.coords.iter().copied())
            .collect();
        let orientation: Vec<Real> = (p.orientation.iter())
            .flat_map(|q| q.as_ref().coords.iter().copied())
            .collect();
        self.position.write(device, &position)?;
        self.orientation.write(device, &orientation)?;
        self.velocity.write(device, &flat(&p.velocity))?;
        self.angular_momentum
            .write(device, &flat(&p.angular_momentum))?;
        self.body_type.write(device, &p.body_type)?;
        self.role.write(device, &roles(p, 0..p.len()))
    }
}
