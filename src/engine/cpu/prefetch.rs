//! Software prefetch of the pair stage's kept overlap plans.
//!
//! The pairs are swept in list order, but only those whose bounding spheres overlap
//! read their plan, so the plans are read at an irregular stride that the hardware
//! prefetchers do not follow; with many distinct shapes in the caches each read went
//! to memory (scene (d) of `talus bench`: a third of the pair stage). Asking a few
//! pairs ahead hides that latency.

use crate::geometry::overlap::OverlapCache;

/// How many pairs ahead the plans are fetched: enough to cover a memory access at
/// the rate pairs apart are swept (a few tens of nanoseconds each).
const AHEAD: usize = 6;

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

    /// Starts fetching what a pair apart reads of the plan of pair `k + AHEAD`
    /// ([`OverlapCache::HOT_BYTES`]), if there is such a pair.
    #[inline(always)]
    pub(super) fn ahead(self, k: usize) {
        #[cfg(target_arch = "x86_64")]
        if k + AHEAD < self.len {
            use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
            let at = self.start + (k + AHEAD) * size_of::<OverlapCache>();
            for line in (0..OverlapCache::HOT_BYTES).step_by(64) {
                // SAFETY: SSE is part of x86_64; a prefetch reads nothing and cannot
                // fault.
                unsafe { _mm_prefetch::<_MM_HINT_T0>(std::ptr::without_provenance(at + line)) };
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = k;
    }
}
