//! The ranks of an MPI run (feature `mpi`): [`Exchange`] over a communicator, the
//! words of each message moved by one `MPI_Alltoallv` after the counts by one
//! `MPI_Alltoall`.

use mpi::Count;
use mpi::datatype::{Partition, PartitionMut};
use mpi::topology::SimpleCommunicator;
use mpi::traits::{Communicator, CommunicatorCollectives};

use super::exchange::Exchange;

/// The ranks of a communicator (usually `universe.world()`; the MPI universe must
/// outlive it).
pub struct MpiExchange {
    comm: SimpleCommunicator,
}

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

impl MpiExchange {
    /// The ranks of `comm`.
    pub fn new(comm: SimpleCommunicator) -> Self {
        MpiExchange { comm }
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
