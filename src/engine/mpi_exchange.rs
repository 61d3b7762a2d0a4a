//! The ranks of an MPI run (feature `mpi`): [`Exchange`] over a communicator, the
//! words of each message moved by one `MPI_Alltoallv` after the counts by one
//! `MPI_Alltoall`.

use std::time::{Duration, Instant};

use mpi::Count;
use mpi::datatype::{Partition, PartitionMut};
use mpi::environment::{Threading, Universe};
use mpi::point_to_point::{Destination, MatchedReceiveVec, Source};
use mpi::topology::SimpleCommunicator;
use mpi::traits::{Communicator, CommunicatorCollectives};

use super::exchange::{Exchange, Ranks};

/// The ranks of a communicator (usually `universe.world()`; the MPI universe must
/// outlive it). It may move to another thread: MPI was initialised with
/// [`Threading::Serialized`] or above ([`start`]), and an exchange is not `Sync`,
/// so its calls never overlap.
pub struct MpiExchange {
    comm: SimpleCommunicator,
}

// SAFETY: the communicator is a handle that any thread may use under
// `MPI_THREAD_SERIALIZED`, which `MpiExchange::new` checks; without `Sync`, only
// the thread that holds the exchange calls MPI through it.
unsafe impl Send for MpiExchange {}

impl std::fmt::Debug for MpiExchange {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "MpiExchange {{ rank: {}, size: {} }}",
            self.rank(),
            self.size()
        )
    }
}

/// Why MPI could not be started for a decomposed run.
#[derive(Debug, thiserror::Error)]
pub enum MpiStartError {
    #[error("MPI was initialised already in this process")]
    AlreadyStarted,
    #[error(
        "the MPI library grants calls from one thread only ({0:?}); a decomposed run \
         needs MPI_THREAD_SERIALIZED"
    )]
    Threading(Threading),
}

/// Initialises MPI with [`Threading::Serialized`]; returns the universe (MPI is
/// finalised when it is dropped) and the exchange over all its processes.
pub fn start() -> Result<(Universe, MpiExchange), MpiStartError> {
    let (universe, _) = mpi::initialize_with_threading(Threading::Serialized)
        .ok_or(MpiStartError::AlreadyStarted)?;
    let exchange = MpiExchange::new(universe.world())?;
    Ok((universe, exchange))
}

impl MpiExchange {
    /// The ranks of `comm`; MPI must grant [`Threading::Serialized`] or above.
    pub fn new(comm: SimpleCommunicator) -> Result<Self, MpiStartError> {
        let level = mpi::environment::threading_support();
        if level < Threading::Serialized {
            return Err(MpiStartError::Threading(level));
        }
        Ok(MpiExchange { comm })
    }
}

/// Offsets of consecutive lists of `counts` words.
fn offsets(counts: &[Count]) -> Vec<Count> {
    counts
        .iter()
        .scan(0, |at, &n| {
            let start = *at;
            *at += n;
            Some(start)
        })
        .collect()
}

impl Exchange for MpiExchange {
    fn rank(&self) -> usize {
        self.comm.rank() as usize
    }

    fn size(&self) -> usize {
        self.comm.size() as usize
    }

    fn all_to_all_words(&self, outgoing: Vec<Vec<u64>>) -> Vec<Vec<u64>> {
        let size = self.size();
        assert_eq!(outgoing.len(), size, "one list per rank");
        let counts: Vec<Count> = outgoing
            .iter()
            .map(|l| Count::try_from(l.len()).expect("a message under 2^31 words"))
            .collect();
        let mut incoming: Vec<Count> = vec![0; size];
        self.comm.all_to_all_into(&counts[..], &mut incoming[..]);
        let sent: Vec<u64> = outgoing.concat();
        let mut received = vec![0u64; incoming.iter().map(|&n| n as usize).sum()];
        let (send_at, receive_at) = (offsets(&counts), offsets(&incoming));
        {
            let send = Partition::new(&sent[..], &counts[..], &send_at[..]);
            let mut receive = PartitionMut::new(&mut received[..], &incoming[..], &receive_at[..]);
            self.comm.all_to_all_varcount_into(&send, &mut receive);
        }
        incoming
            .iter()
            .zip(&receive_at)
            .map(|(&n, &at)| received[at as usize..(at + n) as usize].to_vec())
            .collect()
    }
}

/// The tag of [`Ranks::announce`]'s messages.
const ANNOUNCE: mpi::Tag = 7001;

/// How long a rank waiting for an announcement polls without sleeping (requests
/// of a co-simulation master often follow each other closely), and the longest
/// sleep between polls after that.
const SPIN: Duration = Duration::from_micros(200);
const LONGEST_NAP: Duration = Duration::from_millis(1);

impl Ranks for MpiExchange {
    /// A duplicate of the communicator (`MPI_Comm_dup`, collective): messages of
    /// the new exchange never meet those of this one.
    fn another(&self) -> Box<dyn Ranks> {
        Box::new(MpiExchange {
            comm: self.comm.duplicate(),
        })
    }

    /// Point to point from rank 0; the others probe for it, sleeping between
    /// probes once it is late (an MPI collective would poll a core at full speed
    /// for as long as rank 0 waits for its next request).
    fn announce(&self, message: &[u8]) -> Vec<u8> {
        if self.rank() == 0 {
            for r in 1..self.comm.size() {
                self.comm
                    .process_at_rank(r)
                    .send_with_tag(message, ANNOUNCE);
            }
            return message.to_vec();
        }
        let first = self.comm.process_at_rank(0);
        let since = Instant::now();
        let mut nap = Duration::from_micros(10);
        loop {
            if let Some(sent) = first.immediate_matched_probe_with_tag(ANNOUNCE) {
                let (bytes, _) = sent.matched_receive_vec::<u8>();
                return bytes;
            }
            if since.elapsed() > SPIN {
                std::thread::sleep(nap);
                nap = (nap * 2).min(LONGEST_NAP);
            } else {
                std::hint::spin_loop();
            }
        }
    }
}
