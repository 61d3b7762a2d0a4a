//! Where the pair sweep's parts begin, weighed by what the parts took.
//!
//! The parts of the sweep ([`super::fused`]) are runs of whole blocks of pairs, one a
//! thread, and the pair stage lasts as long as its slowest part. Weighed by counts
//! alone (a pair apart costs a distance, a contact [`CONTACT_COST`] times that), the
//! two parts of the settled bed of 5000 spheres (a 400–500 µs sweep on the 2-core
//! VM) ended on average 6–54 µs apart over a thousand steps, now one part late and
//! now the other: a contact does not cost the same everywhere in a bed, the second
//! part starts when its thread has taken it, and the cores of a VM are not alike.
//! So the sweep times each part's end, and where the ends, averaged over [`SETTLE`]
//! steps, lie further apart than [`TOLERANCE`] of the latest, the next step splits
//! again, each part's blocks now weighed at the rate its time showed (and a new
//! list's blocks at the rate of the part that held their place). The same runs with
//! this: the ends 0.2–2 µs apart on average, split again 28–59 times a thousand
//! steps (each time the particles' parts are found anew, ~20 µs).
//!
//! A split changes when the sums are ready, never their bits (`super::fused`).

use super::blocks::BLOCK;

/// What a pair in contact costs the sweep against a pair apart (a distance).
const CONTACT_COST: usize = 8;

/// Steps a split is timed before it is judged.
const SETTLE: usize = 16;

/// How far apart the parts' ends may lie, as a share of the latest end.
const TOLERANCE: f64 = 0.03;

/// The parts of the pair sweep: their first pairs, and each part's rate of time to
/// counted work.
///
/// Invariant: `starts` ascends from 0 to the number of pairs, each start but the
/// last the first pair of a block; `rates` and `ends` have one entry per part.
#[derive(Clone, Debug, Default)]
pub(super) struct PartSplit {
    /// The first pair of each part, ascending, and the number of pairs last.
    starts: Vec<usize>,
    /// What a unit of counted work took in each part, relative to the others.
    rates: Vec<f64>,
    /// Each part's end after the sweep began, s, averaged over the steps timed.
    ends: Vec<f64>,
    /// Steps timed since the split.
    timed: usize,
    /// The split before, while the next is found (kept for its capacity).
    before: (Vec<usize>, Vec<f64>),
    /// The list build and thread count the split was made for.
    made_for: Option<(u64, usize)>,
}

impl PartSplit {
    /// Whether the parts are to be found again for the list build and thread count
    /// of `made_for`: these changed, or the parts' ends drifted apart.
    pub(super) fn stale(&self, made_for: (u64, usize)) -> bool {
        self.made_for != Some(made_for) || self.unbalanced()
    }

    /// Whether the averaged ends lie further apart than [`TOLERANCE`].
    fn unbalanced(&self) -> bool {
        if self.timed < SETTLE {
            return false;
        }
        let last = self.ends.iter().copied().fold(0.0, f64::max);
        let first = self.ends.iter().copied().fold(f64::INFINITY, f64::min);
        last - first > TOLERANCE * last
    }

    /// Splits `pairs` pairs into `made_for.1` runs of whole blocks of about equal
    /// time: a block's counted work (its pairs, and [`CONTACT_COST`] for each that
    /// held a contact after the last step, `held` a mask a block: a guess serves) at
    /// the rate of the part that held its place before, corrected by that part's
    /// time if it was timed long enough.
    pub(super) fn split(&mut self, pairs: usize, held: &[u64], made_for: (u64, usize)) {
        let count = made_for.1.clamp(1, pairs.div_ceil(BLOCK).max(1));
        if self.made_for.map(|(_, threads)| threads) != Some(made_for.1) {
            self.starts.clear();
            self.rates.clear();
        } else if self.timed >= SETTLE {
            self.correct_rates();
        }
        std::mem::swap(&mut self.before.0, &mut self.starts);
        std::mem::swap(&mut self.before.1, &mut self.rates);
        let (before, before_rates) = (&self.before.0, &self.before.1);
        let rate_at = |pair: usize| {
            let part = before
                .get(1..)
                .map_or(0, |s| s.partition_point(|&s| s <= pair));
            before_rates.get(part).copied().unwrap_or(1.0)
        };
        let work = |b: usize| {
            let len = BLOCK.min(pairs - b * BLOCK);
            (len + CONTACT_COST * held.get(b).map_or(0, |h| h.count_ones() as usize)) as f64
        };
        let blocks = pairs.div_ceil(BLOCK);
        let total: f64 = (0..blocks).map(|b| work(b) * rate_at(b * BLOCK)).sum();
        let (starts, rates) = (&mut self.starts, &mut self.rates);
        starts.clear();
        starts.push(0);
        rates.clear();
        let (mut done, mut part_cost, mut part_work) = (0.0, 0.0, 0.0);
        for b in 0..blocks {
            let (w, cost) = (work(b), work(b) * rate_at(b * BLOCK));
            (done, part_cost, part_work) = (done + cost, part_cost + cost, part_work + w);
            // Block `b` ends part `m` where the cost so far passes its share.
            let (m, end) = (starts.len(), (b + 1) * BLOCK);
            if m < count && done * count as f64 >= total * m as f64 && end < pairs {
                starts.push(end);
                rates.push(part_cost / part_work);
                (part_cost, part_work) = (0.0, 0.0);
            }
        }
        starts.push(pairs);
        rates.push(if part_work > 0.0 {
            part_cost / part_work
        } else {
            1.0
        });
        self.ends.clear();
        self.ends.resize(self.count(), 0.0);
        self.timed = 0;
        self.made_for = Some(made_for);
    }

    /// Scales each part's rate by its averaged end against the parts' mean end.
    fn correct_rates(&mut self) {
        let mean = self.ends.iter().sum::<f64>() / self.ends.len() as f64;
        if mean > 0.0 && self.ends.iter().all(|&e| e > 0.0) {
            for (rate, end) in self.rates.iter_mut().zip(&self.ends) {
                *rate *= end / mean;
            }
        }
    }

    /// Takes the ends of this step's parts, s after the sweep began, in part order.
    pub(super) fn time(&mut self, ends: impl Iterator<Item = f64>) {
        self.timed += 1;
        // The mean of the steps so far, then a running mean of about SETTLE steps.
        let weight = 1.0 / self.timed.min(SETTLE) as f64;
        for (mean, end) in self.ends.iter_mut().zip(ends) {
            *mean += (end - *mean) * weight;
        }
    }

    /// The first pair of each part and the number of pairs last.
    pub(super) fn starts(&self) -> &[usize] {
        &self.starts
    }

    /// The number of parts.
    pub(super) fn count(&self) -> usize {
        self.starts.len() - 1
    }

    /// The part that holds pair `k`.
    #[inline]
    pub(super) fn of_pair(&self, k: usize) -> u32 {
        (self.starts[1..].partition_point(|&s| s <= k)) as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `blocks` full blocks of pairs apart (no contacts held).
    fn apart(blocks: usize) -> Vec<u64> {
        vec![0; blocks]
    }

    /// Times `split` for `steps` steps with parts ending at `ends`.
    fn time_for(split: &mut PartSplit, steps: usize, ends: &[f64]) {
        for _ in 0..steps {
            split.time(ends.iter().copied());
        }
    }

    /// Untimed, the parts hold equal counted work: a block of contacts weighs nine
    /// blocks apart (a pair and its contact, `1 + CONTACT_COST`).
    #[test]
    fn untimed_parts_share_the_counted_work() {
        let mut split = PartSplit::default();
        split.split(100 * BLOCK, &apart(100), (1, 2));
        assert_eq!(split.starts(), &[0, 50 * BLOCK, 100 * BLOCK]);
        let mut held = apart(100);
        held[..10].fill(u64::MAX);
        let mut split = PartSplit::default();
        split.split(100 * BLOCK, &held, (1, 2));
        // 10 blocks at 9 and 90 at 1: 180 in all, the first 90 are blocks 0..10.
        assert_eq!(split.starts(), &[0, 10 * BLOCK, 100 * BLOCK]);
        assert_eq!(split.of_pair(10 * BLOCK - 1), 0);
        assert_eq!(split.of_pair(10 * BLOCK), 1);
    }

    /// Where a part took twice as long for the same work, its blocks weigh twice as
    /// much at the next split, and a list build carries the rates over by place.
    #[test]
    fn a_slow_part_gets_less_work() {
        let mut split = PartSplit::default();
        split.split(90 * BLOCK, &apart(90), (1, 2));
        assert!(!split.stale((1, 2)), "nothing timed yet");
        time_for(&mut split, SETTLE - 1, &[1e-4, 2e-4]);
        assert!(!split.stale((1, 2)), "not timed long enough to judge");
        time_for(&mut split, 1, &[1e-4, 2e-4]);
        assert!(split.stale((1, 2)), "ends 50 % apart");
        split.split(90 * BLOCK, &apart(90), (1, 2));
        // Blocks 0..45 at rate 1 and 45..90 at 2: 135 in all, half of it by block
        // 45 + 11.25 (the part ends with the block that passes its share).
        assert_eq!(split.starts(), &[0, 57 * BLOCK, 90 * BLOCK]);
        // Balanced now: the split stays.
        time_for(&mut split, 2 * SETTLE, &[1.5e-4, 1.51e-4]);
        assert!(!split.stale((1, 2)));
        // A new list of the same pairs keeps the parts' mean rates (57 blocks at
        // (45 + 12 · 2) / 57, 33 at 2: half of it by block 55.8; the near-equal
        // times correct them by a third of a per cent).
        split.split(90 * BLOCK, &apart(90), (2, 2));
        assert_eq!(split.starts(), &[0, 56 * BLOCK, 90 * BLOCK]);
        // Another thread count starts afresh.
        assert!(split.stale((2, 3)));
        split.split(90 * BLOCK, &apart(90), (2, 3));
        assert_eq!(split.starts(), &[0, 30 * BLOCK, 60 * BLOCK, 90 * BLOCK]);
    }

    /// One thread, or fewer blocks than threads: as many parts as blocks allow.
    #[test]
    fn parts_are_whole_blocks() {
        let mut split = PartSplit::default();
        split.split(3 * BLOCK + 5, &apart(4), (1, 1));
        assert_eq!(split.starts(), &[0, 3 * BLOCK + 5]);
        split.split(BLOCK + 5, &apart(2), (1, 4));
        assert_eq!(split.count(), 2);
        assert_eq!(split.starts(), &[0, BLOCK, BLOCK + 5]);
        split.split(0, &[], (2, 4));
        assert_eq!(split.starts(), &[0, 0]);
    }
}
