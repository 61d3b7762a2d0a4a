//! How the ranks of a decomposed run talk: a collective all-to-all of records and
//! a collective "does any rank say yes". An MPI communicator provides them across
//! processes; [`ThreadExchange`] provides them among threads of one process, which
//! is how the decomposition is tested without MPI and how one machine can run
//! ranks without it.

use std::sync::{Arc, Barrier, Mutex};

use super::wire::{Message, decode_list, encode_list};

/// Collective operations among the ranks of a run. Every rank calls each operation
/// in the same order (they block until all have).
pub trait Exchange {
    /// This rank, `0..size()`.
    fn rank(&self) -> usize;

    /// Number of ranks.
    fn size(&self) -> usize;

    /// Sends `outgoing[r]` to rank `r` (one list of words per rank; this rank's own
    /// is handed back too) and returns what every rank sent this one, in rank order.
    fn all_to_all_words(&self, outgoing: Vec<Vec<u64>>) -> Vec<Vec<u64>>;

    /// [`Exchange::all_to_all_words`] of messages.
    fn all_to_all<T: Message>(&self, outgoing: Vec<Vec<T>>) -> Vec<Vec<T>>
    where
        Self: Sized,
    {
        let words = outgoing.iter().map(|list| encode_list(list)).collect();
        self.all_to_all_words(words)
            .iter()
            .map(|w| decode_list(w))
            .collect()
    }

    /// Whether any rank passes `true`.
    fn any(&self, mine: bool) -> bool
    where
        Self: Sized,
    {
        let answers = self.all_to_all(vec![vec![mine]; self.size()]);
        answers.iter().flatten().any(|&b| b)
    }
}

/// The ranks of a run as threads of one process: [`ThreadExchange::group`] makes one
/// per rank, each moved to its own thread. Messages go through the same words as
/// under MPI.
#[derive(Clone)]
pub struct ThreadExchange {
    rank: usize,
    size: usize,
    /// A slot per (sender, receiver).
    slots: Arc<Mutex<Vec<Vec<Vec<u64>>>>>,
    barrier: Arc<Barrier>,
}

impl std::fmt::Debug for ThreadExchange {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "ThreadExchange {{ rank: {}, size: {} }}",
            self.rank, self.size
        )
    }
}

impl ThreadExchange {
    /// One exchange for each of `size` ranks.
    pub fn group(size: usize) -> Vec<ThreadExchange> {
        let slots = Arc::new(Mutex::new(vec![vec![Vec::new(); size]; size]));
        let barrier = Arc::new(Barrier::new(size));
        (0..size)
            .map(|rank| ThreadExchange {
                rank,
                size,
                slots: slots.clone(),
                barrier: barrier.clone(),
            })
            .collect()
    }
}

impl Exchange for ThreadExchange {
    fn rank(&self) -> usize {
        self.rank
    }

    fn size(&self) -> usize {
        self.size
    }

    fn all_to_all_words(&self, outgoing: Vec<Vec<u64>>) -> Vec<Vec<u64>> {
        assert_eq!(outgoing.len(), self.size, "one list per rank");
        self.slots.lock().expect("no rank panicked")[self.rank] = outgoing;
        self.barrier.wait();
        let received = {
            let mut slots = self.slots.lock().expect("no rank panicked");
            (0..self.size)
                .map(|from| std::mem::take(&mut slots[from][self.rank]))
                .collect()
        };
        // Nobody writes the next round's slots before everyone took this round's.
        self.barrier.wait();
        received
    }
}
