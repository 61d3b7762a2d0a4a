//! The CUDA backend's kernels (feature `cuda`; issue 23): CUDA C sources in
//! `kernels/`, compiled at run time through NVRTC ([`nvrtc`]) and, where no GPU is
//! at hand, compiled as C++ and run on the CPU by the [`host`] executor, which
//! launches them as the driver does (blocks of threads, the parameters as an array
//! of pointers), the blocks in parallel.
//!
//! What exists: the kernels of the opening kick and drift ([`Kernel::KickDrift`])
//! and of the closing kick ([`Kernel::ClosingKick`]), checked against the CPU
//! backend's stages through the host executor, and every
//! kernel compiled by NVRTC for [`nvrtc::ARCHITECTURES`]. The rest of the step, the
//! driver device and the backend behind the seam are to come.

pub mod host;
pub mod nvrtc;

/// A kernel of `kernels/`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kernel {
    /// `kick_drift` of `integrate.cu`: the opening kick and drift of the owned
    /// particles, one thread per particle.
    KickDrift,
    /// `closing_kick` of `integrate.cu`: the closing half kick of the owned
    /// particles, one thread per particle.
    ClosingKick,
}

impl Kernel {
    /// Every kernel.
    pub const ALL: [Kernel; 2] = [Kernel::KickDrift, Kernel::ClosingKick];

    /// Its name in the source (`extern "C"`, so the PTX entry has it too).
    pub fn name(self) -> &'static str {
        match self {
            Kernel::KickDrift => "kick_drift",
            Kernel::ClosingKick => "closing_kick",
        }
    }

    /// The source file in `kernels/` that holds it.
    pub fn file(self) -> &'static str {
        match self {
            Kernel::KickDrift | Kernel::ClosingKick => "integrate.cu",
        }
    }

    /// The text of its source file.
    pub fn source(self) -> &'static str {
        match self {
            Kernel::KickDrift | Kernel::ClosingKick => {
                include_str!("../../../kernels/integrate.cu")
            }
        }
    }
}
