//! The host executor: runs the kernels of `kernels/`, compiled as C++ by `build.rs`,
//! on the CPU, as the driver launches them on a GPU: `threads` threads in blocks of
//! [`HostExecutor::block`], each thread's indices set before its call, the
//! parameters passed as an array of pointers to each argument. The blocks run in
//! parallel on the rayon pool (the threads of a block one after the other), so a
//! kernel whose threads race shows it here too.

use std::ffi::c_void;

use rayon::prelude::*;

use super::Kernel;
use crate::Real;
use crate::world::World;

/// A kernel's host trampoline: its parameters as an array of pointers.
type Trampoline = unsafe extern "C" fn(params: *mut *mut c_void);

unsafe extern "C" {
    fn talus_host_at(block: u32, thread: u32, block_dim: u32, grid_dim: u32);
    fn talus_host_kernel(name: *const std::ffi::c_char) -> Option<Trampoline>;
}

/// The parameters of one launch, shared by the threads that run its blocks.
struct Params(*mut *mut c_void);

// SAFETY: the pointers are read, never written, by the trampolines; what they point
// to outlives the launch (see `HostExecutor::launch`).
unsafe impl Sync for Params {}

/// Runs kernels on the CPU (see the module).
#[derive(Clone, Copy, Debug)]
pub struct HostExecutor {
    /// Threads per block.
    pub block: u32,
}

impl Default for HostExecutor {
    fn default() -> Self {
        HostExecutor { block: 128 }
    }
}

impl HostExecutor {
    /// Runs `kernel` on `threads` threads.
    ///
    /// # Safety
    /// `params` holds one pointer per parameter of the kernel, in order, each to a
    /// value of the parameter's type, and every array the kernel reaches holds what
    /// the kernel reads and writes for `threads` threads.
    pub unsafe fn launch(&self, kernel: Kernel, threads: u32, params: &mut [*mut c_void]) {
        let name = std::ffi::CString::new(kernel.name()).expect("a kernel name");
        // SAFETY: looks a name up in host.cpp's table.
        let trampoline = unsafe { talus_host_kernel(name.as_ptr()) }
            .unwrap_or_else(|| panic!("kernels/host.cpp lists no kernel {}", kernel.name()));
        let block = self.block.max(1);
        let blocks = threads.div_ceil(block);
        let params = Params(params.as_mut_ptr());
        (0..blocks).into_par_iter().for_each(|b| {
            let params = &params;
            for t in 0..block {
                // SAFETY: the caller's contract; the indices are this OS thread's.
                unsafe {
                    talus_host_at(b, t, block, blocks);
                    trampoline(params.0);
                }
            }
        });
    }

    /// The opening kick and drift of `world`'s owned particles over `dt` through
    /// [`Kernel::KickDrift`] (the CPU backend's first stage of a step).
    pub fn kick_drift(&self, world: &mut World, dt: Real) {
        let types = TypeArrays::of(world);
        let p = &mut world.particles;
        // nalgebra's points, vectors and quaternions are arrays of doubles (the
        // quaternion as i, j, k, w), and a bool is a byte of 0 or 1: the layouts the
        // kernel reads.
        let arrays = [
            p.position.as_mut_ptr().cast(),
            p.velocity.as_mut_ptr().cast(),
            p.orientation.as_mut_ptr().cast(),
            p.angular_momentum.as_mut_ptr().cast(),
            p.force.as_ptr().cast_mut().cast(),
            p.torque.as_ptr().cast_mut().cast(),
            p.body_type.as_ptr().cast_mut().cast(),
            p.frozen.as_ptr().cast_mut().cast(),
            types.mass.as_ptr().cast_mut().cast(),
            types.inertia.as_ptr().cast_mut().cast(),
        ];
        // SAFETY: the parameters of `kick_drift` in order; every array holds the
        // owned particles' (or the body types') entries.
        unsafe { self.launch_on_particles(Kernel::KickDrift, p.owned(), dt, arrays) };
    }

    /// The closing half kick of `world`'s owned particles over `dt` through
    /// [`Kernel::ClosingKick`] (the CPU backend's last stage of a step).
    pub fn closing_kick(&self, world: &mut World, dt: Real) {
        let types = TypeArrays::of(world);
        let p = &mut world.particles;
        let arrays = [
            p.velocity.as_mut_ptr().cast(),
            p.angular_momentum.as_mut_ptr().cast(),
            p.force.as_ptr().cast_mut().cast(),
            p.torque.as_ptr().cast_mut().cast(),
            p.body_type.as_ptr().cast_mut().cast(),
            p.frozen.as_ptr().cast_mut().cast(),
            types.mass.as_ptr().cast_mut().cast(),
        ];
        // SAFETY: the parameters of `closing_kick` in order, as above.
        unsafe { self.launch_on_particles(Kernel::ClosingKick, p.owned(), dt, arrays) };
    }

    /// Launches a kernel of parameters `(n, dt, arrays...)` on `n` threads.
    ///
    /// # Safety
    /// As [`Self::launch`]: `arrays` are the kernel's array parameters in order.
    unsafe fn launch_on_particles<const K: usize>(
        &self,
        kernel: Kernel,
        n: usize,
        mut dt: Real,
        mut arrays: [*mut c_void; K],
    ) {
        let mut n = u32::try_from(n).expect("fewer than 2^32 particles");
        let mut params: Vec<*mut c_void> = vec![(&raw mut n).cast(), (&raw mut dt).cast()];
        params.extend(arrays.iter_mut().map(|a| (a as *mut *mut c_void).cast()));
        // SAFETY: the caller's contract.
        unsafe { self.launch(kernel, n, &mut params) };
    }
}

/// Per body type, what the integration kernels read: the mass and the principal
/// moments of inertia (3 doubles each).
struct TypeArrays {
    mass: Vec<Real>,
    inertia: Vec<Real>,
}

impl TypeArrays {
    fn of(world: &World) -> Self {
        let types = &world.body_types;
        TypeArrays {
            mass: types.iter().map(|t| t.mass).collect(),
            inertia: types
                .iter()
                .flat_map(|t| t.inertia.iter().copied())
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use nalgebra::{Point3, UnitQuaternion, Vector3};
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    use super::HostExecutor;
    use crate::scene::Scene;

    /// Spheres (isotropic), flat cuboids and rods (three distinct moments), with
    /// random states and loads, every seventh frozen.
    fn world() -> crate::world::World {
        let text = r#"
[simulation]
dt = 1e-5
end_time = 1.0
[materials.m]
density = 2500.0
young = 1e7
poisson = 0.3
restitution = 0.5
friction = 0.5
[shapes.ball]
kind = "sphere"
radius = 0.005
[shapes.slab]
kind = "cuboid"
size = [0.02, 0.01, 0.004]
[shapes.rod]
kind = "cuboid"
size = [0.03, 0.005, 0.005]
[[particles]]
kind = "lattice"
shape = "ball"
material = "m"
min = [0.0, 0.0, 0.0]
max = [0.01, 0.01, 0.01]
[[particles]]
kind = "lattice"
shape = "slab"
material = "m"
min = [0.1, 0.0, 0.0]
max = [0.13, 0.03, 0.03]
[[particles]]
kind = "lattice"
shape = "rod"
material = "m"
min = [0.2, 0.0, 0.0]
max = [0.24, 0.04, 0.04]
"#;
        let mut world = Scene::parse(text, Path::new("kick.toml")).unwrap().world;
        assert_eq!(world.body_types.len(), 3);
        world.particles = Default::default();
        let mut rng = Pcg64::seed_from_u64(23);
        let mut v = |s: f64| Vector3::from_fn(|_, _| rng.random_range(-s..s));
        let mut samples = Vec::new();
        for k in 0..1000 {
            samples.push((k % 3, v(0.5), v(2.0), v(1e-3), v(1e-6), v(1e-5), v(1.0)));
        }
        let p = &mut world.particles;
        for (k, (kind, x, u, f, t, l, axis)) in samples.into_iter().enumerate() {
            let q = UnitQuaternion::from_scaled_axis(axis * 3.0);
            p.push(kind as u32, Point3::from(x), q, k as u64);
            let i = p.len() - 1;
            p.velocity[i] = u;
            p.force[i] = f;
            p.torque[i] = t;
            p.angular_momentum[i] = l;
            p.frozen[i] = k % 7 == 0;
        }
        world
    }

    /// The kernel, run by the host executor in blocks of 32 (the last one partly
    /// idle), moves every particle as the CPU backend's stage, to the bit: its
    /// vector and quaternion operations are nalgebra's in nalgebra's order
    /// (`kernels/vec.cuh`); frozen ones stay where they are.
    #[test]
    fn the_kick_drift_kernel_moves_particles_as_the_cpu_backend() {
        let before = world();
        let dt = 2e-4;
        let mut cpu = before.clone();
        crate::engine::cpu::motion::kick_drift(&mut cpu, dt, &mut Default::default());
        let mut kernel = before.clone();
        HostExecutor { block: 32 }.kick_drift(&mut kernel, dt);
        let (a, b) = (&cpu.particles, &kernel.particles);
        assert_eq!(a.position, b.position);
        assert_eq!(a.velocity, b.velocity);
        assert_eq!(a.orientation, b.orientation);
        assert_eq!(a.angular_momentum, b.angular_momentum);
        let mut turned = 0;
        for i in 0..a.len() {
            if before.particles.frozen[i] {
                assert_eq!(b.position[i], before.particles.position[i]);
                assert_eq!(b.orientation[i], before.particles.orientation[i]);
            } else {
                turned += usize::from(b.orientation[i] != before.particles.orientation[i]);
            }
        }
        assert!(turned > 800, "{turned} turned");
    }

    /// The closing kick keeps the CPU backend's operations in its order: the same
    /// bits, frozen particles untouched.
    #[test]
    fn the_closing_kick_kernel_gives_the_cpu_backends_bits() {
        let before = world();
        let dt = 2e-4;
        let mut cpu = before.clone();
        crate::engine::cpu::motion::closing_kick(&mut cpu, dt, &mut Default::default());
        let mut kernel = before.clone();
        HostExecutor { block: 64 }.closing_kick(&mut kernel, dt);
        let (a, b) = (&cpu.particles, &kernel.particles);
        assert!(a.velocity == b.velocity && a.angular_momentum == b.angular_momentum);
        assert!(a.velocity != before.particles.velocity);
        assert_eq!(a.position, b.position);
    }
}
