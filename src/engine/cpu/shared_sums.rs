//! The particles' sums (force, torque, touching flag) written side by side by tasks
//! that each own a disjoint set of particles: the parts of the pair sweep
//! ([`super::fused`]), the chunks of the wall stage ([`super::walls`]).
//!
//! Why not slices split between the tasks: a task's particles are not one run of
//! the arrays (a part of the sweep owns the particles whose first pair it holds, a
//! chunk of the wall stage the particles near walls among its visits).

use std::marker::PhantomData;

use nalgebra::Vector3;

use crate::Real;

/// The sums of every particle, borrowed for the tasks that write them.
///
/// Invariant: while the tasks run, each particle's sums are written by one task
/// alone, and read by none other.
#[derive(Clone, Copy)]
pub(super) struct SharedSums<'a> {
    force: *mut Vector3<Real>,
    torque: *mut Vector3<Real>,
    touching: *mut bool,
    len: usize,
    sums: PhantomData<&'a mut [Vector3<Real>]>,
}

// SAFETY: the tasks write disjoint particles (the invariant above).
unsafe impl Send for SharedSums<'_> {}
unsafe impl Sync for SharedSums<'_> {}

impl<'a> SharedSums<'a> {
    /// The sums of `force`, `torque` and `touching` (one entry a particle each).
    pub(super) fn over(
        force: &'a mut [Vector3<Real>],
        torque: &'a mut [Vector3<Real>],
        touching: &'a mut [bool],
    ) -> Self {
        assert!(force.len() == torque.len() && torque.len() == touching.len());
        SharedSums {
            force: force.as_mut_ptr(),
            torque: torque.as_mut_ptr(),
            touching: touching.as_mut_ptr(),
            len: force.len(),
            sums: PhantomData,
        }
    }

    /// Particle `k`'s force, torque and touching flag.
    ///
    /// # Safety
    /// `k` is below the number of particles, and no other task touches particle
    /// `k`'s sums while the returned borrows live.
    #[inline(always)]
    pub(super) unsafe fn of(
        self,
        k: usize,
    ) -> (&'a mut Vector3<Real>, &'a mut Vector3<Real>, &'a mut bool) {
        debug_assert!(k < self.len);
        // SAFETY: in bounds, and this task's alone (the caller's promise).
        unsafe {
            (
                &mut *self.force.add(k),
                &mut *self.torque.add(k),
                &mut *self.touching.add(k),
            )
        }
    }
}
