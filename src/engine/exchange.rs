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

impl<E: Exchange + ?Sized> Exchange for Box<E> {
    fn rank(&self) -> usize {
        (**self).rank()
    }

    fn size(&self) -> usize {
        (**self).size()
    }

    fn all_to_all_words(&self, outgoing: Vec<Vec<u64>>) -> Vec<Vec<u64>> {
        (**self).all_to_all_words(outgoing)
    }
}

/// The ranks a long-lived host runs on (a component served by `mpirun talus
/// serve`): its own exchange for what it tells the ranks, and another for each
/// simulation it builds (at every initialisation and restore), since a
/// simulation owns its exchange.
pub trait Ranks: Exchange + Send + std::fmt::Debug {
    /// An exchange among the same ranks, for a new simulation (collective: every
    /// rank calls it at the same point).
    fn another(&self) -> Box<dyn Ranks>;

    /// Rank 0's `message` on every rank (the others' `message` is ignored), the
    /// other ranks waiting for it however long rank 0 takes: how a host hands its
    /// requests to ranks that idle in between. Collective; [`broadcast_bytes`]
    /// unless an exchange can wait without keeping a core busy.
    fn announce(&self, message: &[u8]) -> Vec<u8> {
        broadcast_bytes(self, message)
    }
}

/// Rank 0's `words` on every rank (collective; the others' `words` are ignored).
pub fn broadcast_words<E: Exchange + ?Sized>(exchange: &E, words: Vec<u64>) -> Vec<u64> {
    let mut outgoing = vec![Vec::new(); exchange.size()];
    if exchange.rank() == 0 {
        outgoing.fill(words);
    }
    exchange
        .all_to_all_words(outgoing)
        .into_iter()
        .next()
        .expect("at least one rank")
}

/// Rank 0's `bytes` on every rank (collective), as [`broadcast_words`].
pub fn broadcast_bytes<E: Exchange + ?Sized>(exchange: &E, bytes: &[u8]) -> Vec<u8> {
    let mut words = vec![bytes.len() as u64];
    words.extend(bytes.chunks(8).map(|c| {
        let mut w = [0u8; 8];
        w[..c.len()].copy_from_slice(c);
        u64::from_le_bytes(w)
    }));
    let words = broadcast_words(exchange, words);
    let (len, body) = words.split_first().expect("a length word");
    let mut bytes: Vec<u8> = body.iter().flat_map(|w| w.to_le_bytes()).collect();
    bytes.truncate(*len as usize);
    bytes
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

impl Ranks for ThreadExchange {
    /// The same slots: the ranks' collectives are called in one order on all of
    /// them, whichever exchange they go through, so one set of slots serves all.
    fn another(&self) -> Box<dyn Ranks> {
        Box::new(self.clone())
    }
}
