//! The candidate list of a world of spheres, built and kept on a device
//! (`kernels/list.cu`, `kernels/scan.cu`): the CPU backend's Verlet list
//! ([`crate::engine::neighbours`]), pair for pair, for particles stored in the order
//! of their ids.
//!
//! # Invariant
//! After a build, `pairs` holds every pair `(i, j)`, `i < j`, whose centres are
//! closer than `r_i + r_j + skin`, sorted; `incident` lists for each particle the
//! pairs that hold it in the order of its partners' space keys (cell code, then
//! id: the CPU backend's order); `keys` the ids of each pair's particles, and
//! `old_keys` those of the list before (for carrying the tangential history over).
//! The list is rebuilt before any particle has moved half a skin since the build.

use super::Kernel;
use super::device::{Arg, Array, Device, DeviceError};
use crate::Real;

/// The device arrays of the list and what it was built with.
#[derive(Debug, Default)]
pub(super) struct DeviceList {
    /// Skin width.
    pub skin: Real,
    /// Edge of a grid cell: the largest reach, `2 r_max + skin`.
    pub cell: Real,
    bucket: Array<u32>,
    bucket_starts: Array<u32>,
    sorted: Array<u32>,
    fill: Array<u32>,
    offsets: Array<u32>,
    /// Candidate pairs, 2 per pair.
    pub pairs: Array<u32>,
    /// `incident[incident_starts[k]..incident_starts[k + 1]]`: the pairs holding
    /// particle `k` (top bit: it is the pair's first).
    pub incident_starts: Array<u32>,
    pub incident: Array<u32>,
    /// Ids of each pair's particles, at this build and at the one before.
    pub keys: Array<u64>,
    pub old_keys: Array<u64>,
    anchors: Array<Real>,
    moved: Array<u32>,
    chunks: Array<u32>,
    /// Number of candidate pairs, and of the list before.
    pub pair_count: usize,
    pub old_pair_count: usize,
    /// Builds so far.
    pub builds: u64,
    valid: bool,
    /// `old_keys` were set from outside (a restored history): the next build
    /// carries from them instead of from this list.
    pub pending: bool,
}

/// Launches `kernel` on `threads` threads.
///
/// # Safety
/// As [`Device::launch`].
pub(super) unsafe fn run(
    device: &mut dyn Device,
    kernel: Kernel,
    threads: usize,
    args: &[Arg],
) -> Result<(), DeviceError> {
    // SAFETY: the caller's contract.
    unsafe { device.launch(kernel, threads, args) }
}

/// Threads of a scan's chunk passes over `n` values (`kernels/scan.cu`).
fn scan_chunks(n: usize) -> usize {
    n / 256 + 1
}

/// Turns `values[..n]` into their exclusive prefix sums and `values[n]` into their
/// total (`values` holds `n + 1` entries), which it returns.
fn scan(
    device: &mut dyn Device,
    values: &Array<u32>,
    n: usize,
    chunks: &mut Array<u32>,
) -> Result<usize, DeviceError> {
    let n_arg = count(n);
    chunks.resize(device, scan_chunks(n))?;
    // SAFETY: `values` holds n + 1 entries, `chunks` one per chunk (scan.cu).
    unsafe {
        run(
            device,
            Kernel::ScanChunkTotals,
            scan_chunks(n),
            &[n_arg, values.arg(), chunks.arg()],
        )?;
        run(device, Kernel::ScanChunkOffsets, 1, &[n_arg, chunks.arg()])?;
        run(
            device,
            Kernel::ScanApply,
            scan_chunks(n),
            &[n_arg, values.arg(), chunks.arg()],
        )?;
    }
    Ok(values.get(device, n)? as usize)
}

/// The count `n` as a kernel's `unsigned` argument (a launch of more than 2³² − 1
/// threads fails before its arguments are read).
fn count(n: usize) -> Arg {
    Arg::U32(n as u32)
}

/// Sets `values[..n]` to zero.
fn zero(device: &mut dyn Device, values: &Array<u32>, n: usize) -> Result<(), DeviceError> {
    // SAFETY: `values` holds at least n entries.
    unsafe { run(device, Kernel::ZeroWords, n, &[count(n), values.arg()]) }
}

/// What the list is built from: the particles' positions, body types, ids and cell
/// codes, and each body type's bounding radius.
pub(super) struct ListInputs<'a> {
    pub n: usize,
    pub position: &'a Array<Real>,
    pub body_type: &'a Array<u32>,
    pub id: &'a Array<u64>,
    pub cell_code: &'a Array<u64>,
    pub type_radius: &'a Array<Real>,
}

impl DeviceList {
    /// An empty list of `skin`, on cells of edge `cell` (at least the largest reach).
    pub fn new(skin: Real, cell: Real) -> Self {
        DeviceList {
            skin,
            cell,
            ..Default::default()
        }
    }

    /// Bytes of device memory the list holds.
    pub fn bytes(&self, device: &dyn Device) -> usize {
        let words = [
            &self.bucket,
            &self.bucket_starts,
            &self.sorted,
            &self.fill,
            &self.offsets,
            &self.pairs,
            &self.incident_starts,
            &self.incident,
            &self.moved,
            &self.chunks,
        ];
        words.iter().map(|a| a.bytes(device)).sum::<usize>()
            + self.keys.bytes(device)
            + self.old_keys.bytes(device)
            + self.anchors.bytes(device)
    }

    /// Makes the list stale until the next build.
    pub fn invalidate(&mut self) {
        self.valid = false;
    }

    /// Whether the list must be rebuilt: never built, or a particle moved half a
    /// skin since (one word read back).
    pub fn is_stale(
        &mut self,
        device: &mut dyn Device,
        n: usize,
        position: &Array<Real>,
    ) -> Result<bool, DeviceError> {
        if !self.valid {
            return Ok(true);
        }
        self.moved.resize(device, 1)?;
        zero(device, &self.moved, 1)?;
        let limit = (0.5 * self.skin) * (0.5 * self.skin);
        // SAFETY: positions and anchors hold 3 n doubles.
        unsafe {
            run(
                device,
                Kernel::MovedTooFar,
                n,
                &[
                    count(n),
                    position.arg(),
                    self.anchors.arg(),
                    Arg::F64(limit),
                    self.moved.arg(),
                ],
            )?;
        }
        Ok(self.moved.get(device, 0)? != 0)
    }

    /// Builds the list (see the module's invariant).
    pub fn build(&mut self, device: &mut dyn Device, at: &ListInputs) -> Result<(), DeviceError> {
        let n = at.n;
        let buckets = (2 * n).next_power_of_two().max(1024);
        let mask = Arg::U32((buckets - 1) as u32);
        let cell = Arg::F64(self.cell);
        let skin = Arg::F64(self.skin);
        self.bucket.resize(device, n)?;
        self.sorted.resize(device, n)?;
        self.bucket_starts.resize(device, buckets + 1)?;
        self.fill.resize(device, buckets.max(n) + 1)?;
        self.offsets.resize(device, n + 1)?;
        zero(device, &self.bucket_starts, buckets + 1)?;
        // SAFETY: every array is sized above for the launch's threads (list.cu).
        unsafe {
            run(
                device,
                Kernel::BinParticles,
                n,
                &[
                    count(n),
                    at.position.arg(),
                    cell,
                    mask,
                    self.bucket.arg(),
                    self.bucket_starts.arg(),
                ],
            )?;
        }
        scan(device, &self.bucket_starts, buckets, &mut self.chunks)?;
        let grid = [self.bucket_starts.arg(), self.sorted.arg()];
        let reach = [
            at.position.arg(),
            at.body_type.arg(),
            at.type_radius.arg(),
            skin,
            cell,
            mask,
        ];
        // SAFETY: as above.
        unsafe {
            run(
                device,
                Kernel::CopyWords,
                buckets + 1,
                &[
                    count(buckets + 1),
                    self.bucket_starts.arg(),
                    self.fill.arg(),
                ],
            )?;
            run(
                device,
                Kernel::ScatterParticles,
                n,
                &[
                    count(n),
                    self.bucket.arg(),
                    self.fill.arg(),
                    self.sorted.arg(),
                ],
            )?;
            let args: Vec<Arg> = [count(n)]
                .into_iter()
                .chain(reach)
                .chain(grid)
                .chain([self.offsets.arg()])
                .collect();
            run(device, Kernel::CountPartners, n, &args)?;
        }
        let pairs = scan(device, &self.offsets, n, &mut self.chunks)?;
        if !self.pending {
            std::mem::swap(&mut self.keys, &mut self.old_keys);
            self.old_pair_count = if self.builds == 0 { 0 } else { self.pair_count };
        }
        self.pending = false;
        self.old_keys.resize(device, 2 * self.old_pair_count)?;
        self.pair_count = pairs;
        self.pairs.resize(device, 2 * pairs)?;
        self.incident.resize(device, 2 * pairs)?;
        self.incident_starts.resize(device, n + 1)?;
        self.keys.resize(device, 2 * pairs)?;
        self.anchors.resize(device, 3 * n)?;
        zero(device, &self.incident_starts, n + 1)?;
        let pair_arg = count(pairs);
        // SAFETY: as above; the pair arrays hold `pairs` pairs.
        unsafe {
            let args: Vec<Arg> = [count(n)]
                .into_iter()
                .chain(reach)
                .chain(grid)
                .chain([self.offsets.arg(), self.pairs.arg()])
                .collect();
            run(device, Kernel::WritePartners, n, &args)?;
            run(
                device,
                Kernel::CountIncident,
                pairs,
                &[pair_arg, self.pairs.arg(), self.incident_starts.arg()],
            )?;
        }
        scan(device, &self.incident_starts, n, &mut self.chunks)?;
        // SAFETY: as above.
        unsafe {
            run(
                device,
                Kernel::CopyWords,
                n + 1,
                &[count(n + 1), self.incident_starts.arg(), self.fill.arg()],
            )?;
            run(
                device,
                Kernel::FillIncident,
                pairs,
                &[
                    pair_arg,
                    self.pairs.arg(),
                    self.fill.arg(),
                    self.incident.arg(),
                ],
            )?;
            run(
                device,
                Kernel::SortIncident,
                n,
                &[
                    count(n),
                    self.pairs.arg(),
                    at.cell_code.arg(),
                    self.incident_starts.arg(),
                    self.incident.arg(),
                ],
            )?;
            run(
                device,
                Kernel::PairKeys,
                pairs,
                &[pair_arg, self.pairs.arg(), at.id.arg(), self.keys.arg()],
            )?;
            run(
                device,
                Kernel::CopyDoubles,
                3 * n,
                &[count(3 * n), at.position.arg(), self.anchors.arg()],
            )?;
        }
        self.valid = true;
        self.builds += 1;
        Ok(())
    }
}
