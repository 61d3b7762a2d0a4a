//! Where kernels run: a [`Device`] holds buffers and launches [`Kernel`]s on them,
//! either the CUDA driver ([`super::driver::CudaDevice`]) or the host executor
//! ([`HostDevice`]), which runs the same kernel sources compiled as C++ on the CPU.
//! The code that drives the kernels (uploads, launch order, downloads) is written
//! once against this trait.

use std::ffi::c_void;
use std::fmt;
use std::marker::PhantomData;

use bytemuck::Pod;

use super::Kernel;
use super::host::HostExecutor;

/// A buffer of device memory (a handle into its device).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Buffer(pub(super) usize);

/// One argument of a launch, in the kernel's parameter order.
#[derive(Clone, Copy, Debug)]
pub enum Arg {
    /// A pointer to the start of a buffer.
    Buffer(Buffer),
    /// An `unsigned`.
    U32(u32),
    /// A `double`.
    F64(f64),
}

/// Why a device call failed.
#[derive(Debug, thiserror::Error)]
pub enum DeviceError {
    /// The CUDA driver library is not found (no NVIDIA driver on this machine).
    #[error(
        "no CUDA driver (libcuda) is found: the cuda backend needs an NVIDIA GPU and its driver"
    )]
    NoDriver,
    /// The driver reported an error.
    #[error("CUDA driver: {0}")]
    Driver(String),
    /// A kernel did not compile.
    #[error(transparent)]
    Nvrtc(#[from] super::nvrtc::NvrtcError),
    /// A copy outside a buffer.
    #[error("a copy of {bytes} bytes at {offset} leaves a buffer of {len} bytes")]
    OutOfBounds {
        /// Where the copy starts.
        offset: usize,
        /// How many bytes it copies.
        bytes: usize,
        /// The buffer's size.
        len: usize,
    },
    /// More than the 2³² − 1 threads one launch of these kernels can index.
    #[error("{0} threads: more than one launch can index")]
    TooManyThreads(usize),
    /// The state outgrew what the device stepper holds.
    #[error("the device stepper holds no {0}")]
    Capacity(String),
}

/// Holds buffers and launches kernels on them.
pub trait Device: Send + fmt::Debug {
    /// What the device is, for reports.
    fn description(&self) -> String;

    /// A new buffer of `bytes` zero bytes.
    fn alloc(&mut self, bytes: usize) -> Result<Buffer, DeviceError>;

    /// Releases `buffer`.
    fn free(&mut self, buffer: Buffer);

    /// Releases every buffer.
    fn clear(&mut self);

    /// The size of `buffer` in bytes.
    fn size(&self, buffer: Buffer) -> usize;

    /// Copies `data` into `buffer` from byte `offset`.
    fn upload(&mut self, buffer: Buffer, offset: usize, data: &[u8]) -> Result<(), DeviceError>;

    /// Copies `out.len()` bytes of `buffer` from byte `offset` into `out`, once every
    /// launch before has finished.
    fn download(&self, buffer: Buffer, offset: usize, out: &mut [u8]) -> Result<(), DeviceError>;

    /// Launches `kernel` on `threads` threads with `args`.
    ///
    /// # Safety
    /// `args` are the kernel's parameters in order and of its types, and every
    /// buffer holds what the kernel reads and writes for `threads` threads.
    unsafe fn launch(
        &mut self,
        kernel: Kernel,
        threads: usize,
        args: &[Arg],
    ) -> Result<(), DeviceError>;
}

/// Checks that `bytes` bytes at `offset` lie within a buffer of `len` bytes.
pub(super) fn check_range(offset: usize, bytes: usize, len: usize) -> Result<(), DeviceError> {
    if offset.checked_add(bytes).is_some_and(|end| end <= len) {
        Ok(())
    } else {
        Err(DeviceError::OutOfBounds { offset, bytes, len })
    }
}

/// The host executor as a device: buffers in host memory (8-byte aligned, as
/// device allocations are at least), kernels run by [`HostExecutor`].
#[derive(Debug, Default)]
pub struct HostDevice {
    /// The executor (its block size).
    pub executor: HostExecutor,
    buffers: Vec<Option<(Vec<u64>, usize)>>,
}

impl HostDevice {
    /// A host device whose executor runs blocks of `block` threads.
    pub fn new(block: u32) -> Self {
        HostDevice {
            executor: HostExecutor { block },
            buffers: Vec::new(),
        }
    }

    fn storage(&self, buffer: Buffer) -> &(Vec<u64>, usize) {
        self.buffers[buffer.0].as_ref().expect("a live buffer")
    }
}

impl Device for HostDevice {
    fn description(&self) -> String {
        format!(
            "host executor ({} threads per block, on {} CPU threads)",
            self.executor.block,
            rayon::current_num_threads()
        )
    }

    fn alloc(&mut self, bytes: usize) -> Result<Buffer, DeviceError> {
        let words = vec![0u64; bytes.div_ceil(8)];
        let slot = self.buffers.iter().position(Option::is_none);
        let slot = slot.unwrap_or_else(|| {
            self.buffers.push(None);
            self.buffers.len() - 1
        });
        self.buffers[slot] = Some((words, bytes));
        Ok(Buffer(slot))
    }

    fn free(&mut self, buffer: Buffer) {
        self.buffers[buffer.0] = None;
    }

    fn clear(&mut self) {
        self.buffers.clear();
    }

    fn size(&self, buffer: Buffer) -> usize {
        self.storage(buffer).1
    }

    fn upload(&mut self, buffer: Buffer, offset: usize, data: &[u8]) -> Result<(), DeviceError> {
        let (words, len) = self.buffers[buffer.0].as_mut().expect("a live buffer");
        check_range(offset, data.len(), *len)?;
        let bytes: &mut [u8] = bytemuck::cast_slice_mut(words);
        bytes[offset..offset + data.len()].copy_from_slice(data);
        Ok(())
    }

    fn download(&self, buffer: Buffer, offset: usize, out: &mut [u8]) -> Result<(), DeviceError> {
        let (words, len) = self.storage(buffer);
        check_range(offset, out.len(), *len)?;
        let bytes: &[u8] = bytemuck::cast_slice(words);
        out.copy_from_slice(&bytes[offset..offset + out.len()]);
        Ok(())
    }

    unsafe fn launch(
        &mut self,
        kernel: Kernel,
        threads: usize,
        args: &[Arg],
    ) -> Result<(), DeviceError> {
        let threads = u32::try_from(threads).map_err(|_| DeviceError::TooManyThreads(threads))?;
        // Each argument's value in an 8-byte slot (a buffer as the pointer to its
        // storage), then a pointer to each slot: cuLaunchKernel's `void**`.
        let mut values: Vec<u64> = args
            .iter()
            .map(|a| match *a {
                Arg::Buffer(b) => {
                    let words = &mut self.buffers[b.0].as_mut().expect("a live buffer").0;
                    words.as_mut_ptr() as usize as u64
                }
                Arg::U32(x) => {
                    let mut slot = [0; 8];
                    slot[..4].copy_from_slice(&x.to_ne_bytes());
                    u64::from_ne_bytes(slot)
                }
                Arg::F64(x) => x.to_bits(),
            })
            .collect();
        let mut params: Vec<*mut c_void> =
            values.iter_mut().map(|v| (v as *mut u64).cast()).collect();
        // SAFETY: the caller's contract; `values` outlive the launch.
        unsafe { self.executor.launch(kernel, threads, &mut params) };
        Ok(())
    }
}

/// A device array of `T`: a buffer and how many `T` it holds.
#[derive(Debug)]
pub struct Array<T> {
    buffer: Option<Buffer>,
    len: usize,
    _t: PhantomData<T>,
}

impl<T> Default for Array<T> {
    fn default() -> Self {
        Array {
            buffer: None,
            len: 0,
            _t: PhantomData,
        }
    }
}

impl<T: Pod> Array<T> {
    /// The number of elements.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether it holds nothing.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Bytes of device memory it holds (its buffer's size, room to grow included).
    pub fn bytes(&self, device: &dyn Device) -> usize {
        self.buffer.map_or(0, |b| device.size(b))
    }

    /// The array as a launch argument (it must have been sized).
    pub fn arg(&self) -> Arg {
        Arg::Buffer(self.buffer.expect("a sized device array"))
    }

    /// Makes the array hold `len` elements: contents kept when the buffer is large
    /// enough, zeroed when a new one is allocated.
    pub fn resize(&mut self, device: &mut dyn Device, len: usize) -> Result<(), DeviceError> {
        if !self.has_room(device, len) {
            let bytes = len.max(1) * size_of::<T>();
            if let Some(b) = self.buffer.take() {
                device.free(b);
            }
            // Room to grow by half, so a list that grows step by step reallocates
            // rarely.
            self.buffer = Some(device.alloc(bytes + bytes / 2)?);
        }
        self.len = len;
        Ok(())
    }

    /// Whether the buffer holds `len` elements (at least one).
    fn has_room(&self, device: &dyn Device, len: usize) -> bool {
        self.buffer
            .is_some_and(|b| device.size(b) >= len.max(1) * size_of::<T>())
    }

    /// Appends `tail` after the elements when the buffer has room for them, and says
    /// whether it had (when not, the array is as it was).
    pub fn append(&mut self, device: &mut dyn Device, tail: &[T]) -> Result<bool, DeviceError> {
        let len = self.len + tail.len();
        if !self.has_room(device, len) {
            return Ok(false);
        }
        let first = self.len;
        self.len = len;
        self.write_at(device, first, tail)?;
        Ok(true)
    }

    /// Grows the array to `len` elements (at least its length), keeping its
    /// elements and zeroing the new ones; a buffer without room is replaced, the
    /// elements copied through the host.
    pub fn grow_zeroed(&mut self, device: &mut dyn Device, len: usize) -> Result<(), DeviceError> {
        let added = len.saturating_sub(self.len);
        if self.append(device, &vec![T::zeroed(); added])? {
            return Ok(());
        }
        let kept = self.read(device)?;
        // A new buffer (it had no room): zeroed.
        self.resize(device, len)?;
        self.write_at(device, 0, &kept)
    }

    /// Resizes to `data.len()` and copies `data` in.
    pub fn write(&mut self, device: &mut dyn Device, data: &[T]) -> Result<(), DeviceError> {
        self.resize(device, data.len())?;
        device.upload(self.buffer.expect("sized"), 0, bytemuck::cast_slice(data))
    }

    /// Copies `data` in from element `first` (within the array's length).
    pub fn write_at(
        &mut self,
        device: &mut dyn Device,
        first: usize,
        data: &[T],
    ) -> Result<(), DeviceError> {
        let size = size_of::<T>();
        check_range(first * size, std::mem::size_of_val(data), self.len * size)?;
        device.upload(
            self.buffer.expect("sized"),
            first * size,
            bytemuck::cast_slice(data),
        )
    }

    /// The elements.
    pub fn read(&self, device: &dyn Device) -> Result<Vec<T>, DeviceError> {
        let mut out = Vec::new();
        self.read_into(device, &mut out)?;
        Ok(out)
    }

    /// The elements, into `out` (its buffer kept, so a read of the same length
    /// allocates nothing).
    pub fn read_into(&self, device: &dyn Device, out: &mut Vec<T>) -> Result<(), DeviceError> {
        out.clear();
        out.resize(self.len, T::zeroed());
        if self.len > 0 {
            device.download(
                self.buffer.expect("sized"),
                0,
                bytemuck::cast_slice_mut(out),
            )?;
        }
        Ok(())
    }

    /// Element `k`.
    pub fn get(&self, device: &dyn Device, k: usize) -> Result<T, DeviceError> {
        let mut out = [T::zeroed()];
        let size = size_of::<T>();
        check_range(k * size, size, self.len * size)?;
        device.download(
            self.buffer.expect("sized"),
            k * size,
            bytemuck::cast_slice_mut(&mut out),
        )?;
        Ok(out[0])
    }
}
