//! Blocks of candidate pairs: the pair sweep takes the pairs [`BLOCK`] at a time, with
//! a mask of one bit per pair (those with something to do, those holding a history).

/// Pairs per block of the pair sweep: one bit each in the block's masks.
pub(super) const BLOCK: usize = 64;

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
