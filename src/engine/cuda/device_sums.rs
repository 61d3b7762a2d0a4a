//! Deterministic sums on the device (`kernels/sums.cu`): a first pass writes rows of
//! partial sums (each of its threads sums up to [`FIRST_FAN_IN`] terms), then passes
//! of many threads fold [`FAN_IN`] rows into one until one is left. The order of the
//! additions is fixed by the number of terms, rows and their width, so every run and
//! every block size gives the same bits; they differ from the CPU backend's serial
//! sums by round-off.
//!
//! Summed so: the contacts' elastic energy and dissipation and the wall and pair
//! contact counts ([`sum_energies`]: the pairs' energy terms folded into rows, one
//! row a particle for its wall contacts), and the walls' forces, torques and facet
//! forces (`device_walls.rs`). For a million particles with six million pairs, four
//! passes after the first.

use super::Kernel;
use super::device::{Arg, Array, Device, DeviceError};
use super::device_list::run;
use super::device_walls::DeviceWalls;
use super::readback::{self, Readback};
use crate::Real;

/// Doubles of a row of the energy sums: elastic energy, dissipated energy, wall
/// contacts, pair contacts, candidate pairs (`ENERGY_RECORD` in
/// `kernels/contact.cuh`). The pairs' terms are those the world counts (all of
/// them in one process; see `Particles::counts_pair`).
pub(super) const ENERGY_RECORD: usize = 5;

/// The rows a thread of a pass folds into one, at most.
const FAN_IN: usize = 32;

/// The terms a thread of a first pass sums into a row, at most: fewer than a fold
/// takes, for more threads to hide the latency of loads scattered over the pairs or
/// the particles' slots.
const FIRST_FAN_IN: usize = 8;

/// Threads (or groups of `width` threads) of a pass over `rows` rows: at least one,
/// so that no rows sum to zero.
fn groups(rows: usize) -> usize {
    rows.div_ceil(FAN_IN).max(1)
}

/// Rows of a first pass over `terms` terms: at least one.
pub(super) fn first_rows(terms: usize) -> usize {
    terms.div_ceil(FIRST_FAN_IN).max(1)
}

/// How a pass folds rows into one.
#[derive(Clone, Copy, Debug)]
pub(super) enum Fold {
    /// Each column's sum.
    Sum,
    /// Each column's largest, `lowest` where there is no row.
    Max { lowest: Real },
}

/// The rows of a sum on the device, in two arrays used in turn.
#[derive(Debug, Default)]
pub(super) struct RowSums {
    rows: Array<Real>,
    folded: Array<Real>,
}

impl RowSums {
    /// Device memory held, bytes.
    pub fn bytes(&self, device: &dyn Device) -> usize {
        self.rows.bytes(device) + self.folded.bytes(device)
    }

    /// The array for the first pass's `rows` rows of `width` doubles.
    pub fn rows(
        &mut self,
        device: &mut dyn Device,
        rows: usize,
        width: usize,
    ) -> Result<&Array<Real>, DeviceError> {
        self.rows.resize(device, rows * width)?;
        self.folded.resize(device, groups(rows) * width)?;
        Ok(&self.rows)
    }

    /// Folds the `rows` rows of `width` doubles written into [`rows`](Self::rows)
    /// into one, written to `out` from double `at` (`out` holds `at + width`).
    pub fn fold(
        &mut self,
        device: &mut dyn Device,
        rows: usize,
        width: usize,
        out: &Array<Real>,
        at: usize,
    ) -> Result<(), DeviceError> {
        self.fold_by(Fold::Sum, device, rows, width, out, at)
    }

    /// [`fold`](Self::fold) by `fold`: each column's sum, or its largest.
    pub fn fold_by(
        &mut self,
        fold: Fold,
        device: &mut dyn Device,
        mut rows: usize,
        width: usize,
        out: &Array<Real>,
        at: usize,
    ) -> Result<(), DeviceError> {
        if out.len() < at + width {
            return Err(DeviceError::Capacity(format!(
                "sums of {width} doubles from {at} into {}",
                out.len()
            )));
        }
        loop {
            let g = groups(rows);
            let (into, offset) = if g == 1 { (out, at) } else { (&self.folded, 0) };
            let (kernel, lowest) = match fold {
                Fold::Sum => (Kernel::SumRecords, None),
                Fold::Max { lowest } => (Kernel::MaxRecords, Some(Arg::F64(lowest))),
            };
            let args = [
                Arg::U32(rows as u32),
                Arg::U32(width as u32),
                self.rows.arg(),
                Arg::U32(g as u32),
                into.arg(),
                Arg::U32(offset as u32),
                lowest.unwrap_or(Arg::U32(0)),
            ];
            let args = if lowest.is_some() {
                &args[..]
            } else {
                &args[..6]
            };
            // SAFETY: the parameters of sum_records, or of max_records with its
            // lowest value (sums.cu): `rows` holds `rows` rows of `width`, `into`
            // room for `g`.
            unsafe {
                run(device, kernel, g * width, args)?;
            }
            if g == 1 {
                return Ok(());
            }
            std::mem::swap(&mut self.rows, &mut self.folded);
            rows = g;
        }
    }
}

/// The candidate pairs' share of the energy sums: their energy terms (`spheres.cu`)
/// and whether each touches.
pub(super) struct PairTerms<'a> {
    pub count: usize,
    pub terms: &'a Array<Real>,
    pub touching: &'a Array<u8>,
}

/// Sums the elastic energy and dissipation of the `pairs` and of the wall contacts
/// of `walls` for `n` particles into the readback's sums (elastic energy,
/// dissipated energy, wall contacts, pair contacts, candidate pairs), by the
/// scratch `sums`.
pub(super) fn sum_energies(
    sums: &mut RowSums,
    device: &mut dyn Device,
    pairs: &PairTerms,
    walls: &DeviceWalls,
    n: usize,
    readback: &Readback,
) -> Result<(), DeviceError> {
    let first = first_rows(pairs.count);
    let wall_rows = if walls.is_empty() { 0 } else { n };
    let rows = sums.rows(device, first + wall_rows, ENERGY_RECORD)?;
    // SAFETY: the parameters of pair_energy_partials (sums.cu): `terms` and
    // `touching` hold the pairs', `rows` room for the `first` rows written.
    unsafe {
        run(
            device,
            Kernel::PairEnergyPartials,
            first,
            &[
                Arg::U32(pairs.count as u32),
                pairs.terms.arg(),
                pairs.touching.arg(),
                Arg::U32(first as u32),
                rows.arg(),
            ],
        )?;
    }
    if wall_rows > 0 {
        walls.energy_terms(device, n, rows, first)?;
    }
    sums.fold(
        device,
        first + wall_rows,
        ENERGY_RECORD,
        &readback.device,
        readback::SUMS,
    )
}
