//! The CUDA driver as a [`Device`]: buffers in GPU memory, every kernel file
//! compiled by NVRTC for the GPU's own architecture when the device is opened, and
//! launches on the context's default stream in blocks of [`BLOCK`] threads.
//!
//! Not run in CI (there is no GPU there): `scripts/gpu-check.sh` is to run the
//! device stepper's parity tests through this device on a machine with one.

use std::collections::HashMap;
use std::sync::Arc;

use cudarc::driver::{
    CudaContext, CudaFunction, CudaSlice, CudaStream, LaunchConfig, PushKernelArg,
};
use cudarc::nvrtc::Ptx;

use super::device::{Arg, Buffer, Device, DeviceError, check_range};
use super::{FILES, Kernel};

/// Threads per block.
pub const BLOCK: u32 = 128;

/// A GPU through the CUDA driver.
pub struct CudaDevice {
    context: Arc<CudaContext>,
    stream: Arc<CudaStream>,
    functions: HashMap<Kernel, CudaFunction>,
    buffers: Vec<Option<CudaSlice<u8>>>,
    description: String,
}

impl std::fmt::Debug for CudaDevice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.description)
    }
}

fn driver(e: impl std::fmt::Debug) -> DeviceError {
    DeviceError::Driver(format!("{e:?}"))
}

impl CudaDevice {
    /// Whether a CUDA driver library can be loaded.
    pub fn is_present() -> bool {
        // SAFETY: only tries to open the library (cudarc panics on a missing one).
        unsafe { cudarc::driver::sys::is_culib_present() }
    }

    /// Opens the GPU of MPI rank `rank`: GPU `rank mod count` of the `count` GPUs
    /// this process sees.
    pub fn open_for_rank(rank: usize) -> Result<Self, DeviceError> {
        if !Self::is_present() {
            return Err(DeviceError::NoDriver);
        }
        let count = CudaContext::device_count().map_err(driver)?;
        if count <= 0 {
            return Err(DeviceError::Driver("the CUDA driver sees no GPU".into()));
        }
        Self::open(rank % count as usize)
    }

    /// Opens GPU `ordinal` and compiles every kernel for it.
    pub fn open(ordinal: usize) -> Result<Self, DeviceError> {
        if !Self::is_present() {
            return Err(DeviceError::NoDriver);
        }
        let context = CudaContext::new(ordinal).map_err(driver)?;
        let (major, minor) = context.compute_capability().map_err(driver)?;
        let arch = format!("sm_{major}{minor}");
        let mut functions = HashMap::new();
        for file in &FILES {
            let ptx = super::nvrtc::compile(file, &arch)?;
            let module = context
                .load_module(Ptx::from_src(ptx.to_string()))
                .map_err(driver)?;
            for kernel in Kernel::ALL
                .into_iter()
                .filter(|k| k.file().name == file.name)
            {
                functions.insert(kernel, module.load_function(kernel.name()).map_err(driver)?);
            }
        }
        let name = context.name().map_err(driver)?;
        Ok(CudaDevice {
            stream: context.default_stream(),
            context,
            functions,
            buffers: Vec::new(),
            description: format!("{name} (GPU {ordinal}, {arch})"),
        })
    }

    fn slice(&self, buffer: Buffer) -> &CudaSlice<u8> {
        self.buffers[buffer.0].as_ref().expect("a live buffer")
    }
}

impl Device for CudaDevice {
    fn description(&self) -> String {
        self.description.clone()
    }

    fn alloc(&mut self, bytes: usize) -> Result<Buffer, DeviceError> {
        let slice = self
            .stream
            .alloc_zeros::<u8>(bytes.max(1))
            .map_err(driver)?;
        let slot = self.buffers.iter().position(Option::is_none);
        let slot = slot.unwrap_or_else(|| {
            self.buffers.push(None);
            self.buffers.len() - 1
        });
        self.buffers[slot] = Some(slice);
        Ok(Buffer(slot))
    }

    fn free(&mut self, buffer: Buffer) {
        self.buffers[buffer.0] = None;
    }

    fn clear(&mut self) {
        self.buffers.clear();
    }

    fn size(&self, buffer: Buffer) -> usize {
        self.slice(buffer).len()
    }

    fn upload(&mut self, buffer: Buffer, offset: usize, data: &[u8]) -> Result<(), DeviceError> {
        let slice = self.buffers[buffer.0].as_mut().expect("a live buffer");
        check_range(offset, data.len(), slice.len())?;
        let mut view = slice.slice_mut(offset..offset + data.len());
        self.stream.memcpy_htod(data, &mut view).map_err(driver)
    }

    fn download(&self, buffer: Buffer, offset: usize, out: &mut [u8]) -> Result<(), DeviceError> {
        let slice = self.slice(buffer);
        check_range(offset, out.len(), slice.len())?;
        let view = slice.slice(offset..offset + out.len());
        self.stream.memcpy_dtoh(&view, out).map_err(driver)?;
        self.stream.synchronize().map_err(driver)
    }

    unsafe fn launch(
        &mut self,
        kernel: Kernel,
        threads: usize,
        args: &[Arg],
    ) -> Result<(), DeviceError> {
        let threads = u32::try_from(threads).map_err(|_| DeviceError::TooManyThreads(threads))?;
        if threads == 0 {
            return Ok(());
        }
        self.context.bind_to_thread().map_err(driver)?;
        let function = &self.functions[&kernel];
        let mut builder = self.stream.launch_builder(function);
        for arg in args {
            match arg {
                Arg::Buffer(b) => builder.arg(self.buffers[b.0].as_ref().expect("a live buffer")),
                Arg::U32(x) => builder.arg(x),
                Arg::F64(x) => builder.arg(x),
            };
        }
        let config = LaunchConfig {
            grid_dim: (threads.div_ceil(BLOCK), 1, 1),
            block_dim: (BLOCK, 1, 1),
            shared_mem_bytes: 0,
        };
        // SAFETY: the caller's contract.
        unsafe { builder.launch(config) }.map_err(driver)?;
        Ok(())
    }
}
