//! The pair stage's results on many threads, as the gather reads them.

use rayon::prelude::*;

use super::forces::PairResult;

/// Pairs per block of the pair stage: one bit each in the block's mask of busy pairs.
pub(super) const BLOCK: usize = 64;

/// Every candidate pair's result, aligned with the pair list, in blocks of [`BLOCK`]
/// pairs with a mask of the pairs evaluated in each.
///
/// Invariant: `results[k]` is pair `k`'s result where bit `k % BLOCK` of
/// `busy[k / BLOCK]` is set; elsewhere it is stale, and the pair's result is the
/// empty one that `results` holds last. Only the busy pairs' results are written,
/// and the others are read from that one entry, in the cache: in a bed of spheres
/// about half of the candidate pairs do not touch, and their 88-byte results were
/// written and read back from memory at every step.
#[derive(Clone, Debug, Default)]
pub(super) struct PairResults {
    results: Vec<PairResult>,
    busy: Vec<u64>,
}

impl PairResults {
    /// The blocks of `pairs` pairs, to be filled: each block's results and its mask,
    /// which the filler sets to the pairs whose results it wrote.
    pub(super) fn blocks_mut(
        &mut self,
        pairs: usize,
    ) -> impl IndexedParallelIterator<Item = (&mut [PairResult], &mut u64)> {
        self.results.resize(pairs + 1, PairResult::default());
        self.results[pairs] = PairResult::default();
        self.busy.resize(pairs.div_ceil(BLOCK), 0);
        self.results[..pairs]
            .par_chunks_mut(BLOCK)
            .zip(self.busy.par_iter_mut())
    }

    /// The result of pair `k`.
    #[inline(always)]
    pub(super) fn get(&self, k: usize) -> &PairResult {
        let busy = (self.busy[k / BLOCK] >> (k % BLOCK)) & 1;
        // The index chosen by arithmetic, not by a branch that the compiler might
        // keep: busy and idle pairs alternate at random. `idle` is all ones for an
        // idle pair, zero for a busy one.
        let idle = (busy as usize).wrapping_sub(1);
        let at = k ^ ((k ^ (self.results.len() - 1)) & idle);
        &self.results[at]
    }

    /// The results of the busy pairs in pair order, with their pair indices.
    pub(super) fn busy(&self) -> impl Iterator<Item = (usize, &PairResult)> {
        self.busy.iter().enumerate().flat_map(move |(b, &mask)| {
            BusyBits(mask).map(move |bit| {
                let k = b * BLOCK + bit;
                (k, &self.results[k])
            })
        })
    }
}

/// The set bits of a block's mask, lowest first.
#[derive(Clone, Copy, Debug)]
pub(super) struct BusyBits(pub u64);

impl Iterator for BusyBits {
    type Item = usize;

    #[inline]
    fn next(&mut self) -> Option<usize> {
        if self.0 == 0 {
            return None;
        }
        let bit = self.0.trailing_zeros() as usize;
        self.0 &= self.0 - 1;
        Some(bit)
    }
}
