//! The backend a scene asks for (`[simulation] backend`), checked when the scene is
//! read and opened when a simulation starts.

use super::backend::Backend;
use super::cpu::CpuBackend;
use super::params::StepParams;
use crate::scene::spec::BackendSpec;
use crate::world::World;

/// Whether `world` can be stepped by `backend` here: `Err` says why not (the
/// feature not built, a scene the backend does not model, no GPU driver).
pub fn check(backend: BackendSpec, world: &World, params: &StepParams) -> Result<(), String> {
    match backend {
        BackendSpec::Cpu => Ok(()),
        #[cfg(feature = "cuda")]
        BackendSpec::Cuda => {
            super::cuda::spheres::DeviceSpheres::check(world, params).map_err(|e| e.to_string())?;
            if super::cuda::driver::CudaDevice::is_present() {
                Ok(())
            } else {
                Err(super::cuda::device::DeviceError::NoDriver.to_string())
            }
        }
        #[cfg(not(feature = "cuda"))]
        BackendSpec::Cuda => {
            let _ = (world, params);
            Err(
                "this talus was built without the cuda feature (cargo build --features cuda)"
                    .into(),
            )
        }
    }
}

/// The backend `backend` for `world` (checked by [`check`]); `Err` when the device
/// cannot be opened.
pub fn open(
    backend: BackendSpec,
    world: &World,
    params: StepParams,
) -> Result<Box<dyn Backend>, String> {
    check(backend, world, &params)?;
    match backend {
        BackendSpec::Cpu => Ok(Box::new(CpuBackend::new(params))),
        #[cfg(feature = "cuda")]
        BackendSpec::Cuda => {
            let device = super::cuda::driver::CudaDevice::open(0).map_err(|e| e.to_string())?;
            let backend = super::cuda::backend::CudaBackend::new(Box::new(device), world, params)
                .map_err(|e| e.to_string())?;
            Ok(Box::new(backend))
        }
        #[cfg(not(feature = "cuda"))]
        BackendSpec::Cuda => unreachable!("refused by check"),
    }
}
