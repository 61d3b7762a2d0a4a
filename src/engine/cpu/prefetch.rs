//! Software prefetch of the pair stage's kept overlap plans.
//!
//! The pairs are swept in list order, but only those whose bounding spheres overlap
//! read their plan, so the plans are read at an irregular stride that the hardware
//! prefetchers do not follow; with many distinct shapes in the caches each read went
//! to memory (scene (d) of `talus bench`: a third of the pair stage). Asking a few
//! pairs ahead hides that latency.
//!
//! In two stages: the first lines of a plan (what a pair apart reads) [`AHEAD`] pairs
//! ahead; then, [`REST_AHEAD`] pairs ahead, where those lines say that the plan keeps
//! a contact's decisions, the rest of it (the topology a contact evaluates). In the
//! dense dodecahedron bed (`talus bench` (a)) the loads of the topology's labels and
//! loops were a third of its evaluation's samples, and the second stage made a step
//! 3–9 % faster on one thread.

use crate::geometry::overlap::OverlapCache;

/// How many pairs ahead the plans are fetched: enough to cover a memory access at
/// the rate pairs apart are swept (a few tens of nanoseconds each).
const AHEAD: usize = 6;

/// How many pairs ahead a contact's plan is fetched whole: its first lines, asked
/// for `AHEAD − REST_AHEAD` pairs before, have then arrived.
const REST_AHEAD: usize = 3;

/// Where the plans lie, to prefetch from while they are borrowed elsewhere (an
/// address only: nothing is read through it).
#[derive(Clone, Copy, Debug)]
pub(super) struct PlanPrefetch {
    start: usize,
    len: usize,
}

impl PlanPrefetch {
    pub(super) fn of(plans: &[OverlapCache]) -> Self {
        PlanPrefetch {
            start: plans.as_ptr().addr(),
            len: plans.len(),
        }
    }

    /// Starts fetching what pairs a few ahead of pair `k` of a block will read of
    /// their plans: the first lines of pair `k + AHEAD` (that of the list, if there
    /// is one), and the rest of pair `k + REST_AHEAD`'s if it keeps a contact (in
    /// the block: `plans` are the block's, the first of them pair `first` of the
    /// list).
    #[inline(always)]
    pub(super) fn ahead(self, plans: &[OverlapCache], first: usize, k: usize) {
        self.fetch(first + k + AHEAD, 0..OverlapCache::HOT_BYTES);
        if plans
            .get(k + REST_AHEAD)
            .is_some_and(OverlapCache::keeps_contact)
        {
            let hot = OverlapCache::HOT_BYTES.next_multiple_of(64);
            self.fetch(first + k + REST_AHEAD, hot..size_of::<OverlapCache>());
        }
    }

    /// Starts fetching the cache lines that hold `bytes` of plan `k`, if there is
    /// such a plan.
    #[inline(always)]
    fn fetch(self, k: usize, bytes: std::ops::Range<usize>) {
        #[cfg(target_arch = "x86_64")]
        if k < self.len {
            use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
            let at = self.start + k * size_of::<OverlapCache>();
            for line in bytes.step_by(64) {
                // SAFETY: SSE is part of x86_64; a prefetch reads nothing and cannot
                // fault.
                unsafe { _mm_prefetch::<_MM_HINT_T0>(std::ptr::without_provenance(at + line)) };
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = (k, bytes);
    }
}
