//! The backend a scene asks for (`[simulation] backend`), checked when the scene is
//! read and opened when a simulation starts.

use serde::{Deserialize, Serialize};

use super::backend::{Backend, ContactHistory};
use super::cpu::CpuBackend;
use super::decomposition::Decomposition;
use super::exchange::Exchange;
use super::params::StepParams;
use super::rank::RankStepper;
use super::stats::StepStats;
use crate::Real;
use crate::world::World;

/// What computes the steps of a scene (`[simulation] backend`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum BackendKind {
    /// The CPU backend (rayon): every scene.
    #[default]
    Cpu,
    /// The CUDA backend (feature `cuda`): scenes of Hertz–Mindlin spheres without
    /// rolling resistance or a fluid, on GPU 0 in one process, and on MPI ranks
    /// a GPU each ([`ShareBackend`]).
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

/// Why a build without the feature refuses the CUDA backend.
#[cfg(not(feature = "cuda"))]
const WITHOUT_CUDA: &str =
    "this talus was built without the cuda feature (cargo build --features cuda)";

/// Whether `world` can be stepped by `backend` here: `Err` says why not (the
/// feature not built, a scene the backend does not model, no GPU driver).
pub fn check(backend: BackendKind, world: &World, params: &StepParams) -> Result<(), String> {
    match backend {
        BackendKind::Cpu => Ok(()),
        #[cfg(feature = "cuda")]
        BackendKind::Cuda => {
            super::cuda::stepper::DeviceWorld::check(world, params).map_err(|e| e.to_string())?;
            if super::cuda::driver::CudaDevice::is_present() {
                Ok(())
            } else {
                Err(super::cuda::device::DeviceError::NoDriver.to_string())
            }
        }
        #[cfg(not(feature = "cuda"))]
        BackendKind::Cuda => {
            let _ = (world, params);
            Err(WITHOUT_CUDA.into())
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

/// What steps one rank's share of a decomposed run, opened before the share is
/// cut (the device can fail to open; the share's stepper cannot).
pub enum ShareBackend {
    /// The CPU backend.
    Cpu,
    /// A GPU (feature `cuda`).
    #[cfg(feature = "cuda")]
    Cuda(Box<dyn super::cuda::device::Device>),
}

impl ShareBackend {
    /// The backend `kind` for rank `rank`: a GPU opens as GPU `rank mod count` of
    /// the GPUs this process sees (one GPU a rank, on nodes with as many GPUs as
    /// ranks). The scene is checked before ([`check`]).
    pub fn open(kind: BackendKind, rank: usize) -> Result<Self, String> {
        match kind {
            BackendKind::Cpu => Ok(ShareBackend::Cpu),
            #[cfg(feature = "cuda")]
            BackendKind::Cuda => {
                let device = super::cuda::driver::CudaDevice::open_for_rank(rank)
                    .map_err(|e| e.to_string())?;
                Ok(ShareBackend::Cuda(Box::new(device)))
            }
            #[cfg(not(feature = "cuda"))]
            BackendKind::Cuda => {
                let _ = rank;
                Err(WITHOUT_CUDA.into())
            }
        }
    }

    /// This rank's stepper of its share of `world` (see
    /// [`RankStepper::restored_with`]), bisecting again above `rebalance_above`.
    pub fn stepper<E: Exchange + Send + std::fmt::Debug + 'static>(
        self,
        at: (E, Decomposition, StepParams),
        world: &mut World,
        history: &ContactHistory,
        stats: StepStats,
        rebalance_above: Real,
    ) -> Box<dyn Backend> {
        match self {
            ShareBackend::Cpu => Box::new(
                RankStepper::restored_with(at, world, history, stats, CpuBackend::new)
                    .rebalance_above(rebalance_above),
            ),
            #[cfg(feature = "cuda")]
            ShareBackend::Cuda(device) => {
                let make = |params| super::cuda::backend::CudaBackend::idle(device, params);
                Box::new(
                    RankStepper::restored_with(at, world, history, stats, make)
                        .rebalance_above(rebalance_above),
                )
            }
        }
    }
}
