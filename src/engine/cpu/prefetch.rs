//! Software prefetch of the pair stage: the kept overlap plans, the tangential
//! histories, and the shapes of the contacts the plans keep.
//!
//! The pairs are swept in list order, but only those whose bounding spheres overlap
//! read their plan, so the plans are read at an irregular stride that the hardware
//! prefetchers do not follow; with many distinct shapes in the caches each read went
//! to memory (scene (d) of `talus bench`: a third of the pair stage). Asking a few
//! pairs ahead hides that latency.
//!
//! A plan's first lines (what a pair apart reads) are asked for [`AHEAD`] pairs
//! ahead, and where the plan keeps a contact's decisions (a bit beside the plans
//! says so: [`super::overlap_plans`]) the rest of it (the topology a contact
//! evaluates) and what the contact reads of its two shapes (the templates, their
//! vertices and planes, found through the [`TypeTable`] without reading the
//! shapes). In the dense dodecahedron bed (`talus bench` (a)) the loads of the
//! topology's labels and loops were a third of its evaluation's samples, and
//! fetching the rest of the plan made a step 3–9 % faster on one thread. Where every
//! particle has a shape of its own (scene (d)), a contact's reads of the shapes
//! waited on memory link by link (template, then its vertices and planes): placing
//! B's points took a tenth of the step. A pair's history (one line, read by every
//! pair) is asked for with its plan: the hardware prefetchers alone left the dense
//! bed 2–4 % slower, and with many shapes its load was a tenth of the pair stage.

use std::ops::Range;
use std::sync::atomic::AtomicU64;

use super::blocks::BLOCK;
use super::overlap_plans::{OverlapPlans, keeps_contact};
use super::type_table::TypeTable;
use crate::contact::TangentialHistory;
use crate::geometry::overlap::OverlapCache;

/// How many pairs ahead the plans are fetched: enough to cover a memory access at
/// the rate pairs apart are swept (a few tens of nanoseconds each).
const AHEAD: usize = 6;

/// Where the plans lie, and how to find a pair's shapes, to prefetch from while the
/// plans are borrowed elsewhere (the plans by address only: nothing is read through
/// it).
#[derive(Clone, Copy, Debug)]
pub(super) struct PairPrefetch<'a> {
    start: usize,
    len: usize,
    /// Where the pairs' tangential histories lie (read by every pair, apart or not).
    history: usize,
    /// Per block of pairs, which plans keep a contact (see
    /// [`super::overlap_plans::OverlapPlans`]).
    keeps_contact: &'a [AtomicU64],
    /// The list's pairs, the particles' body types and the types' table.
    pairs: &'a [[u32; 2]],
    body_type: &'a [u32],
    types: &'a TypeTable,
}

impl<'a> PairPrefetch<'a> {
    /// The `plans` of the list's `pairs` to evaluate, and the prefetch for them (and
    /// for the pairs' `history`), of particles of `body_type`.
    pub(super) fn over(
        plans: &'a mut OverlapPlans,
        history: &[TangentialHistory],
        pairs: &'a [[u32; 2]],
        body_type: &'a [u32],
        types: &'a TypeTable,
    ) -> (&'a mut [OverlapCache], Self) {
        let (plans, keeps_contact) = plans.split();
        let prefetch = PairPrefetch {
            start: plans.as_ptr().addr(),
            len: plans.len(),
            history: history.as_ptr().addr(),
            keeps_contact,
            pairs,
            body_type,
            types,
        };
        (plans, prefetch)
    }

    /// The word of the block of pairs starting at pair `first` (a multiple of
    /// [`BLOCK`]) that says which of their plans keep a contact.
    pub(super) fn keeps_contact_word(self, first: usize) -> &'a AtomicU64 {
        &self.keeps_contact[first / BLOCK]
    }

    /// Starts fetching what the pair [`AHEAD`] pairs after pair `k` of a block (the
    /// first of which is pair `first` of the list) will read: its history, the first
    /// lines of its plan, and, if the plan keeps a contact, the rest of it and what
    /// its contact reads of its shapes.
    #[inline(always)]
    pub(super) fn ahead(self, first: usize, k: usize) {
        let pair = first + k + AHEAD;
        if pair >= self.len {
            return;
        }
        let size = size_of::<TangentialHistory>();
        fetch(self.history + pair * size..self.history + (pair + 1) * size);
        let hot = OverlapCache::HOT_BYTES.next_multiple_of(64);
        if !keeps_contact(self.keeps_contact, pair) {
            self.fetch_plan(pair, 0..hot);
            return;
        }
        self.fetch_plan(pair, 0..size_of::<OverlapCache>());
        if self.types.fetch_shapes() {
            // The pairs are sorted by their first particle: where the pair before
            // kept a contact with the same first particle, its shape is on its way.
            let [i, j] = self.pairs[pair];
            if !(keeps_contact(self.keeps_contact, pair - 1) && self.pairs[pair - 1][0] == i) {
                self.fetch_shape(i);
            }
            self.fetch_shape(j);
        }
    }

    /// Starts fetching the cache lines that hold `bytes` of plan `k` (a plan starts a
    /// line; the bytes are constants, so the lines are a few prefetches in a row).
    #[inline(always)]
    fn fetch_plan(self, k: usize, bytes: Range<usize>) {
        let at = self.start + k * size_of::<OverlapCache>();
        for line in bytes.step_by(64) {
            fetch_line(at + line);
        }
    }

    /// Starts fetching what a kept contact reads of particle `k`'s shape.
    #[inline(always)]
    fn fetch_shape(self, k: u32) {
        fetch_shape(self.types, self.body_type[k as usize]);
    }
}

/// Starts fetching what a contact reads of body type `t`'s shape (a kept contact
/// between particles, or a particle's contact with a wall facet: the template's
/// first line, its vertices and planes). The callers ask only where
/// [`TypeTable::fetch_shapes`] says it is worth it, before finding `t`.
#[inline(always)]
pub(super) fn fetch_shape(types: &TypeTable, t: u32) {
    for range in types.contact_memory(t) {
        fetch(range.clone());
    }
}

/// Starts fetching the cache lines that hold the addresses `bytes`.
#[inline(always)]
fn fetch(bytes: Range<usize>) {
    for line in (bytes.start & !63..bytes.end).step_by(64) {
        fetch_line(line);
    }
}

/// Starts fetching the cache line that holds the address `at`.
#[inline(always)]
fn fetch_line(at: usize) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        // SAFETY: SSE is part of x86_64; a prefetch reads nothing and cannot fault.
        unsafe { _mm_prefetch::<_MM_HINT_T0>(std::ptr::without_provenance(at)) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = at;
}
