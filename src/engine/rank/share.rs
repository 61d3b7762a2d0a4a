//! What a host needs of a backend whose world is one rank's share of a
//! decomposed run: the collectives through which it reduces its whole-run figures
//! and gathers the whole world for outputs, and the insertion of the particles one
//! process would insert.

use super::RankStepper;
use super::stepper::ShareStepper;
use crate::engine::exchange::Exchange;
use crate::engine::wire::{Message, decode_list, encode_list};
use crate::world::{Inlet, World};

/// One rank's side of a decomposed run, as the host sees it. Every method is
/// collective: every rank calls it at the same point of the run.
pub trait Share {
    /// This rank, `0..ranks()`.
    fn rank(&self) -> usize;

    /// Number of ranks.
    fn ranks(&self) -> usize;

    /// Sends `outgoing[r]` to rank `r`; returns what every rank sent this one, in
    /// rank order (see [`Exchange::all_to_all_words`]).
    fn all_to_all_words(&self, outgoing: Vec<Vec<u64>>) -> Vec<Vec<u64>>;

    /// Lets the inlets insert what is due at the world's time: every rank places
    /// the particles one process places and keeps those in its box (see
    /// [`RankStepper::insert`]). Returns the particles placed on all ranks.
    fn insert(&self, world: &mut World, inlets: &mut [Inlet], next_id: &mut u64) -> usize;
}

/// Every rank's `mine`, in rank order, on every rank.
pub fn all_gather<T: Message>(share: &dyn Share, mine: &[T]) -> Vec<Vec<T>> {
    let words = encode_list(mine);
    share
        .all_to_all_words(vec![words; share.ranks()])
        .iter()
        .map(|w| decode_list(w))
        .collect()
}

/// Sends `outgoing[r]` to rank `r`; returns what every rank sent this one, in rank
/// order.
pub fn all_to_all<T: Message>(share: &dyn Share, outgoing: &[Vec<T>]) -> Vec<Vec<T>> {
    let words = outgoing.iter().map(|list| encode_list(list)).collect();
    share
        .all_to_all_words(words)
        .iter()
        .map(|w| decode_list(w))
        .collect()
}

/// Every rank's `mine`, in rank order, on rank 0 (empty elsewhere).
pub fn gather_to_first<T: Message>(share: &dyn Share, mine: &[T]) -> Vec<Vec<T>> {
    let mut outgoing = vec![Vec::new(); share.ranks()];
    outgoing[0] = encode_list(mine);
    let received = share.all_to_all_words(outgoing);
    if share.rank() == 0 {
        received.iter().map(|w| decode_list(w)).collect()
    } else {
        Vec::new()
    }
}

impl<E: Exchange, B: ShareStepper> Share for RankStepper<E, B> {
    fn rank(&self) -> usize {
        self.exchange.rank()
    }

    fn ranks(&self) -> usize {
        self.exchange.size()
    }

    fn all_to_all_words(&self, outgoing: Vec<Vec<u64>>) -> Vec<Vec<u64>> {
        self.exchange.all_to_all_words(outgoing)
    }

    fn insert(&self, world: &mut World, inlets: &mut [Inlet], next_id: &mut u64) -> usize {
        RankStepper::insert(self, world, inlets, next_id)
    }
}
