//! The tangential history of the particle–wall patches, kept in particle order from
//! step to step.
//!
//! The wall stage reads each particle's patches of the step before and writes this
//! step's, both in particle order. Kept as one array grouped by particle, a
//! particle's old patches are the slice beside its index, found without hashing a
//! key, and the new array is the chunks' contacts laid end to end. A hash map keyed by
//! the whole patch key (id, wall, rounded plane: 48 bytes) cost three hash operations
//! a contact, look-up, insert and remove, a fifth of the wall stage of a bed of spheres
//! in a box.

use crate::contact::TangentialHistory;
use crate::engine::backend::WallKey;

/// One patch's key and history.
pub(super) type WallEntry = (WallKey, TangentialHistory);

/// The wall patches' history of the last step, grouped by particle.
///
/// # Invariant
/// Where `aligned`, `entries[starts[k]..starts[k + 1]]` are the patches of the
/// particle at index `k`, whose id is `ids[k]` (every one of their keys starts with
/// it), each with a history that is not empty, `starts.len() == ids.len() + 1`, and
/// `holders` lists the indices whose groups are not empty, ascending.
/// Otherwise (a history set from outside) the groups are not made yet and `entries`
/// holds the patches in any order. `orphans` are patches of particles that were not in
/// the world when the groups were last made: they end at the next step.
#[derive(Clone, Debug, Default)]
pub(super) struct WallHistory {
    aligned: bool,
    ids: Vec<u64>,
    starts: Vec<u32>,
    entries: Vec<WallEntry>,
    holders: Vec<u32>,
    orphans: Vec<WallEntry>,
    /// Where the groups are made anew (kept to allocate nothing once grown).
    sorted: Vec<WallEntry>,
}

impl WallHistory {
    /// Replaces the history by `entries` (any order); the groups are made at the next
    /// [`Self::align`].
    pub(super) fn set(&mut self, entries: Vec<WallEntry>) {
        self.aligned = false;
        self.entries = entries;
        self.orphans.clear();
    }

    /// Every patch, sorted by key.
    pub(super) fn to_sorted(&self) -> Vec<WallEntry> {
        let mut all: Vec<WallEntry> = self.entries.iter().chain(&self.orphans).copied().collect();
        all.sort_unstable_by_key(|e| e.0);
        all
    }

    /// Whether the patches are grouped by the particles of `ids`.
    pub(super) fn is_aligned_to(&self, ids: &[u64]) -> bool {
        self.aligned && self.ids == ids
    }

    /// Groups the patches by the particles of `ids` (the world's particle ids, in
    /// index order) unless they are grouped so already: where particles were added,
    /// removed or reordered, or the history was set. Patches of ids not in the world
    /// become orphans.
    pub(super) fn align(&mut self, ids: &[u64]) {
        if self.is_aligned_to(ids) {
            return;
        }
        self.sorted.clear();
        self.sorted.append(&mut self.entries);
        self.sorted.append(&mut self.orphans);
        self.sorted.sort_unstable_by_key(|e| e.0);
        let mut taken = vec![false; self.sorted.len()];
        self.starts.clear();
        self.starts.push(0);
        self.holders.clear();
        for (k, &id) in ids.iter().enumerate() {
            let first = self.sorted.partition_point(|e| e.0.0 < id);
            let end = first + self.sorted[first..].partition_point(|e| e.0.0 == id);
            if end > first {
                self.holders.push(k as u32);
            }
            self.entries.extend_from_slice(&self.sorted[first..end]);
            taken[first..end].iter_mut().for_each(|t| *t = true);
            self.starts.push(self.entries.len() as u32);
        }
        let orphans = self.sorted.iter().zip(&taken).filter(|(_, t)| !**t);
        self.orphans.extend(orphans.map(|(e, _)| *e));
        self.ids.clear();
        self.ids.extend_from_slice(ids);
        self.aligned = true;
    }

    /// The patches of the particle at index `k` (the history must be aligned).
    #[inline]
    pub(super) fn of_particle(&self, k: usize) -> &[WallEntry] {
        debug_assert!(self.aligned);
        &self.entries[self.starts[k] as usize..self.starts[k + 1] as usize]
    }

    /// The indices of the particles that hold patches, ascending (the history must be
    /// aligned).
    #[inline]
    pub(super) fn holders(&self) -> &[u32] {
        debug_assert!(self.aligned);
        &self.holders
    }

    /// The patches of particles no longer in the world.
    pub(super) fn orphans(&self) -> &[WallEntry] {
        &self.orphans
    }

    /// Starts writing a history for the particles of `ids`.
    pub(super) fn begin(&mut self, ids: &[u64]) {
        self.aligned = false;
        self.ids.clear();
        self.ids.extend_from_slice(ids);
        self.starts.clear();
        self.starts.push(0);
        self.entries.clear();
        self.holders.clear();
        self.orphans.clear();
    }

    /// Adds a patch of the particle at index `k`, at or after the last one's.
    #[inline]
    pub(super) fn push(&mut self, k: usize, entry: WallEntry) {
        debug_assert!(self.starts.len() <= k + 1 && entry.0.0 == self.ids[k]);
        let end = self.entries.len() as u32;
        if self.holders.last() != Some(&(k as u32)) {
            self.holders.push(k as u32);
        }
        self.starts.resize(k + 1, end);
        self.entries.push(entry);
    }

    /// Ends the history begun by [`Self::begin`].
    pub(super) fn finish(&mut self) {
        let end = self.entries.len() as u32;
        self.starts.resize(self.ids.len() + 1, end);
        self.aligned = true;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry(id: u64, wall: u32, plane: i64) -> WallEntry {
        let mut h = TangentialHistory::default();
        h.spring.x = (id * 10 + wall as u64) as f64 + plane as f64 * 0.01;
        ((id, wall, [0, 0, 1, plane]), h)
    }

    /// A written history is grouped by index; particles without patches have none.
    #[test]
    fn written_patches_are_found_by_particle_index() {
        let mut h = WallHistory::default();
        h.begin(&[7, 3, 9]);
        h.push(0, entry(7, 0, 1));
        h.push(0, entry(7, 1, 1));
        h.push(2, entry(9, 0, 5));
        h.finish();
        h.align(&[7, 3, 9]);
        assert_eq!(h.of_particle(0), &[entry(7, 0, 1), entry(7, 1, 1)]);
        assert!(h.of_particle(1).is_empty());
        assert_eq!(h.of_particle(2), &[entry(9, 0, 5)]);
        assert_eq!(h.holders(), &[0, 2]);
        assert!(h.orphans().is_empty());
    }

    /// When the particles are reordered, removed or the history is set from outside,
    /// the patches follow their ids; those of ids gone become orphans, and the sorted
    /// export holds every patch once.
    #[test]
    fn patches_follow_their_ids_when_the_particles_change() {
        let mut h = WallHistory::default();
        h.begin(&[7, 3, 9]);
        h.push(0, entry(7, 0, 1));
        h.push(1, entry(3, 0, 2));
        h.push(2, entry(9, 0, 5));
        h.finish();
        let all = h.to_sorted();
        h.align(&[9, 7, 4]);
        assert_eq!(h.of_particle(0), &[entry(9, 0, 5)]);
        assert_eq!(h.of_particle(1), &[entry(7, 0, 1)]);
        assert!(h.of_particle(2).is_empty());
        assert_eq!(h.holders(), &[0, 1]);
        assert_eq!(h.orphans(), &[entry(3, 0, 2)]);
        assert_eq!(h.to_sorted(), all);

        h.set(vec![entry(4, 2, 0), entry(9, 0, 5)]);
        h.align(&[9, 7, 4]);
        assert_eq!(h.of_particle(0), &[entry(9, 0, 5)]);
        assert!(h.of_particle(1).is_empty());
        assert_eq!(h.of_particle(2), &[entry(4, 2, 0)]);
        assert_eq!(h.holders(), &[0, 2]);
        assert!(h.orphans().is_empty());
    }
}
