//! How the ranks of a decomposed run talk: a collective all-to-all of records and
//! a collective "does any rank say yes". An MPI communicator provides them across
//! processes; [`ThreadExchange`] provides them among threads of one process, which
//! is how the decomposition is tested without MPI and how one machine can run
//! ranks without it.

use std::any::Any;
use std::sync::{Arc, Barrier, Mutex};

/// Collective operations among the ranks of a run. Every rank calls each operation
/// in the same order (they block until all have).
pub trait Exchange {
    /// This rank, `0..size()`.
    fn rank(&self) -> usize;

    /// Number of ranks.
    fn size(&self) -> usize;

    /// Sends `outgoing[r]` to rank `r` (`outgoing` has one list per rank; this
    /// rank's own is handed back too) and returns what every rank sent this one, in
    /// rank order.
    fn all_to_all<T: Clone + Send + 'static>(&self, outgoing: Vec<Vec<T>>) -> Vec<Vec<T>>;

    /// Whether any rank passes `true`.
    fn any(&self, mine: bool) -> bool {
        let answers = self.all_to_all(vec![vec![mine]; self.size()]);
        answers.iter().flatten().any(|&b| b)
    }
}

/// A message slot per (sender, receiver) pair.
type Slots = Vec<Vec<Option<Box<dyn Any + Send>>>>;

/// The ranks of a run as threads of one process: [`ThreadExchange::group`] makes one
/// per rank, each moved to its own thread.
#[derive(Clone)]
pub struct ThreadExchange {
    rank: usize,
    size: usize,
    slots: Arc<Mutex<Slots>>,
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
        let slots = Arc::new(Mutex::new(
            (0..size)
                .map(|_| (0..size).map(|_| None).collect())
                .collect(),
        ));
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

    fn all_to_all<T: Clone + Send + 'static>(&self, outgoing: Vec<Vec<T>>) -> Vec<Vec<T>> {
        assert_eq!(outgoing.len(), self.size, "one list per rank");
        {
            let mut slots = self.slots.lock().expect("no rank panicked");
            for (to, list) in outgoing.into_iter().enumerate() {
                slots[self.rank][to] = Some(Box::new(list));
            }
        }
        self.barrier.wait();
        let received = {
            let mut slots = self.slots.lock().expect("no rank panicked");
            (0..self.size)
                .map(|from| {
                    let message = slots[from][self.rank].take().expect("every rank sent");
                    *message
                        .downcast::<Vec<T>>()
                        .expect("every rank sends the same type")
                })
                .collect()
        };
        // Nobody writes the next round's slots before everyone took this round's.
        self.barrier.wait();
        received
    }
}
