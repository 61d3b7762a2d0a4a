//! A multiply–rotate hasher (the scheme of rustc's FxHash) for the engine's contact
//! history maps.
//!
//! Their keys are particle ids and rounded patch planes made by the simulation, not
//! by an adversary, so the flooding resistance of the standard SipHash buys nothing;
//! its cost does show: the wall history is looked up and rebuilt at every step, and
//! with SipHash its 44-byte keys took a tenth of a step of a bed resting on a floor.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// Odd multiplier with well-spread bits (rustc's FxHash constant for 64 bits).
const SEED: u64 = 0x51_7c_c1_b7_27_22_0a_95;

/// Hashes word by word: `h = (rotl(h, 5) ^ word) * SEED`.
#[derive(Clone, Copy, Debug, Default)]
pub struct FastHasher(u64);

impl FastHasher {
    #[inline]
    fn add(&mut self, word: u64) {
        self.0 = (self.0.rotate_left(5) ^ word).wrapping_mul(SEED);
    }
}

impl Hasher for FastHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        let mut chunks = bytes.chunks_exact(8);
        for chunk in &mut chunks {
            self.add(u64::from_le_bytes(chunk.try_into().expect("8 bytes")));
        }
        let rest = chunks.remainder();
        if !rest.is_empty() {
            let mut word = [0u8; 8];
            word[..rest.len()].copy_from_slice(rest);
            self.add(u64::from_le_bytes(word));
        }
    }

    #[inline]
    fn write_u32(&mut self, x: u32) {
        self.add(u64::from(x));
    }

    #[inline]
    fn write_u64(&mut self, x: u64) {
        self.add(x);
    }

    #[inline]
    fn write_i64(&mut self, x: i64) {
        self.add(x as u64);
    }

    #[inline]
    fn write_usize(&mut self, x: usize) {
        self.add(x as u64);
    }

    #[inline]
    fn finish(&self) -> u64 {
        self.0
    }
}

/// A `HashMap` with [`FastHasher`].
pub type FastMap<K, V> = HashMap<K, V, BuildHasherDefault<FastHasher>>;

#[cfg(test)]
mod tests {
    use std::collections::HashSet;
    use std::hash::BuildHasher;

    use super::*;

    #[test]
    fn wall_keys_of_a_bed_spread_over_buckets() {
        // The keys of a floor: particle ids 0..10 000, one wall, one plane. Their
        // hashes must differ, and their low bits (hashbrown's bucket index) must fill
        // a table of 16 384 buckets about as a random function would (1 − 1/e ≈ 46 %
        // of the keys' worth of distinct buckets for n = 10 000, m = 16 384).
        let build = BuildHasherDefault::<FastHasher>::default();
        let hashes: Vec<u64> = (0..10_000u64)
            .map(|id| build.hash_one((id, 0u32, [0i64, 0, 1_000_000_000, 12_345])))
            .collect();
        assert_eq!(hashes.iter().collect::<HashSet<_>>().len(), hashes.len());
        let buckets: HashSet<u64> = hashes.iter().map(|h| h & 16_383).collect();
        let expected = 16_384.0 * (1.0 - (-10_000.0f64 / 16_384.0).exp());
        let ratio = buckets.len() as f64 / expected;
        assert!(
            (0.95..1.05).contains(&ratio),
            "{} buckets, {expected:.0} expected",
            buckets.len()
        );
    }
}
