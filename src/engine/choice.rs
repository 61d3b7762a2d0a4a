//! The backend a scene asks for (`[simulation] backend`), checked when the scene is
//! read and opened when a simulation starts.

use serde::{Deserialize, Serialize};

use super::backend::Backend;
use super::cpu::CpuBackend;
use super::params::StepParams;
use crate::world::World;

/// What computes the steps of a scene (`[simulation] backend`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum BackendKind {
    /// The CPU backend (rayon): every scene.
    #[default]
    Cpu,
    /// The CUDA backend on GPU 0 (feature `cuda`): scenes of Hertz–Mindlin spheres
    /// without rolling resistance or a fluid, in one process.
    Cuda,
}

impl BackendKind {
    /// Every backend, in the order of their names in messages.
    pub const ALL: [BackendKind; 2] = [BackendKind::Cpu, BackendKind::Cuda];

    /// Its name in a scene file, on the command line and as a parameter.
    pub fn name(self) -> &'static str {
        match self {
            BackendKind::Cpu => "cpu",
            BackendKind::Cuda => "cuda",
        }
    }
}

impl std::str::FromStr for BackendKind {
    type Err = String;

    fn from_str(name: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|k| k.name() == name)
            .ok_or_else(|| format!("'{name}': the backends are cpu and cuda"))
    }
}

/// Whether `world` can be stepped by `backend` here: `Err` says why not (the
/// feature not built, a scene the backend does not model, no GPU driver).
pub fn check(backend: BackendKind, world: &World, params: &StepParams) -> Result<(), String> {
    match backend {
        BackendKind::Cpu => Ok(()),
        #[cfg(feature = "cuda")]
        BackendKind::Cuda => {
            super::cuda::spheres::DeviceSpheres::check(world, params).map_err(|e| e.to_string())?;
            if super::cuda::driver::CudaDevice::is_present() {
                Ok(())
            } else {
                Err(super::cuda::device::DeviceError::NoDriver.to_string())
            }
        }
        #[cfg(not(feature = "cuda"))]
        BackendKind::Cuda => {
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
    backend: BackendKind,
    world: &World,
    params: StepParams,
) -> Result<Box<dyn Backend>, String> {
    check(backend, world, &params)?;
    match backend {
        BackendKind::Cpu => Ok(Box::new(CpuBackend::new(params))),
        #[cfg(feature = "cuda")]
        BackendKind::Cuda => {
            let device = super::cuda::driver::CudaDevice::open(0).map_err(|e| e.to_string())?;
            let backend = super::cuda::backend::CudaBackend::new(Box::new(device), world, params)
                .map_err(|e| e.to_string())?;
            Ok(Box::new(backend))
        }
        #[cfg(not(feature = "cuda"))]
        BackendKind::Cuda => unreachable!("refused by check"),
    }
}
