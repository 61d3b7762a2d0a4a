//! An [`Exchange`] that measures what passes through it, for benchmarks: the
//! collective calls, the words sent to other ranks and the time spent inside, which
//! is the transfer and the wait for the slowest rank to arrive.

use std::cell::Cell;
use std::time::Instant;

use super::exchange::Exchange;

/// What a [`MeteredExchange`] counted since it was made or last reset.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ExchangeMeter {
    /// Collective calls.
    pub calls: u64,
    /// Words (8 bytes each) this rank sent to the others (not to itself).
    pub words_sent: u64,
    /// Seconds inside the calls (monotonic clock).
    pub seconds: f64,
}

/// Wraps an exchange and counts its traffic. Invariant: every call of the inner
/// exchange goes through [`Exchange::all_to_all_words`] here, so nothing is missed.
#[derive(Debug)]
pub struct MeteredExchange<E> {
    inner: E,
    meter: Cell<ExchangeMeter>,
}

impl<E: Exchange> MeteredExchange<E> {
    /// Measures `inner` from now on.
    pub fn new(inner: E) -> Self {
        MeteredExchange {
            inner,
            meter: Cell::new(ExchangeMeter::default()),
        }
    }

    /// What was counted so far.
    pub fn meter(&self) -> ExchangeMeter {
        self.meter.get()
    }

    /// Starts counting again from zero.
    pub fn reset(&self) {
        self.meter.set(ExchangeMeter::default());
    }
}

impl<E: Exchange> Exchange for MeteredExchange<E> {
    fn rank(&self) -> usize {
        self.inner.rank()
    }

    fn size(&self) -> usize {
        self.inner.size()
    }

    fn all_to_all_words(&self, outgoing: Vec<Vec<u64>>) -> Vec<Vec<u64>> {
        let me = self.rank();
        let sent: usize = outgoing
            .iter()
            .enumerate()
            .filter(|&(to, _)| to != me)
            .map(|(_, words)| words.len())
            .sum();
        let start = Instant::now();
        let received = self.inner.all_to_all_words(outgoing);
        let mut m = self.meter.get();
        m.calls += 1;
        m.words_sent += sent as u64;
        m.seconds += start.elapsed().as_secs_f64();
        self.meter.set(m);
        received
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::exchange::ThreadExchange;

    /// Two ranks, each sending 3 words to the other and 5 to itself: 3 words
    /// counted per call, and what arrives is what was sent.
    #[test]
    fn counts_the_words_sent_to_other_ranks() {
        let counted: Vec<ExchangeMeter> = std::thread::scope(|s| {
            let handles: Vec<_> = ThreadExchange::group(2)
                .into_iter()
                .map(|exchange| {
                    s.spawn(move || {
                        let metered = MeteredExchange::new(exchange);
                        let me = metered.rank() as u64;
                        for _ in 0..4 {
                            let out = (0..2)
                                .map(|to| vec![me; if to == me as usize { 5 } else { 3 }])
                                .collect();
                            let got = metered.all_to_all_words(out);
                            assert_eq!(got[1 - me as usize], vec![1 - me; 3]);
                            assert_eq!(got[me as usize], vec![me; 5]);
                        }
                        assert!(metered.any(me == 1));
                        metered.meter()
                    })
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        for m in counted {
            // Four rounds of 3 words, then `any`: a list of one flag (length and
            // value, 2 words) to the other rank.
            assert_eq!(m.calls, 5);
            assert_eq!(m.words_sent, 4 * 3 + 2);
            assert!(m.seconds > 0.0);
        }
    }
}
