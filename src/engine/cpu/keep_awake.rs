//! The pool's threads kept awake while steps follow one another.
//!
//! A step runs a handful of parallel stages with serial parts between them (the
//! walls' merge, the totals). An idle rayon worker yields a few dozen times, then
//! sleeps, and waking it goes through the host's scheduler: on the 2-core Intel VM of
//! the benchmarks a region that finds the other worker asleep waits 80–110 µs for it
//! (against 4 µs when it is awake), longer than a stage of a 5000-sphere step takes.
//! So stages began on one thread and the second joined late or not at all. While
//! steps come, every other thread of the pool waits in [`stay_awake`]: it runs the
//! pool's work as it appears and otherwise yields its core, as rayon's own idle
//! rounds do, but without going to sleep. The pour of the LIGGGHTS comparison on two threads
//! went from 4.5e6–4.6e6 to 4.9e6 particle-steps/s, the same bits.
//!
//! The waits are started once and kept from step to step (a step allocates
//! nothing: `tests/engine_allocation.rs`); they end when neither work nor a step
//! has come for a while ([`MOST_IDLE`]), so a host that stops stepping gets its
//! cores back soon after.
//!
//! # No deadlock
//! A wait is a job on each other thread. A thread picks it up when idle, or while it waits
//! inside a job of its own (a join whose other half was stolen): a wait there holds
//! that job, and the step may need the job. So a wait returns at once on a thread
//! that is stepping or already waiting, and otherwise ends once idle for
//! [`MOST_IDLE`] (no step can begin while one is held up), which bounds the stall of
//! the one case left: a wait picked up inside a job of a step on another thread.

use std::cell::Cell;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// How long a wait lasts without work or a new step.
const MOST_IDLE: Duration = Duration::from_millis(10);

thread_local! {
    /// Whether this thread is stepping (holds a [`Stepping`]) or inside a wait.
    static BUSY: Cell<bool> = const { Cell::new(false) };
}

/// What the waits share with the steps.
#[derive(Debug, Default)]
struct Waits {
    /// Steps begun; a wait that sees it move is not idle.
    steps: AtomicU64,
    /// Waits started and not yet ended (those yet to start included).
    live: AtomicUsize,
    /// How many times the waits were started (for the tests).
    starts: AtomicUsize,
}

/// Keeps the current pool's threads awake while steps follow one another.
///
/// Invariant: `waits.live` counts the waits spawned and not ended; new ones are
/// spawned only when none is left, so a run of steps spawns once.
#[derive(Debug)]
pub(super) struct KeepAwake {
    waits: Arc<Waits>,
    most_idle: Duration,
}

impl Default for KeepAwake {
    fn default() -> Self {
        Self::with_most_idle(MOST_IDLE)
    }
}

/// A copy starts waits of its own: two backends never share them.
impl Clone for KeepAwake {
    fn clone(&self) -> Self {
        Self::with_most_idle(self.most_idle)
    }
}

impl KeepAwake {
    fn with_most_idle(most_idle: Duration) -> Self {
        KeepAwake {
            waits: Arc::default(),
            most_idle,
        }
    }

    /// Marks a step's beginning on this thread, until the returned guard is dropped,
    /// and starts the waits on the current pool's other threads if none is left.
    pub(super) fn step(&self) -> Stepping {
        let threads = rayon::current_num_threads();
        if threads == 1 {
            return Stepping { marked: false };
        }
        let marked = !BUSY.replace(true);
        self.waits.steps.fetch_add(1, Ordering::Relaxed);
        if self.waits.live.load(Ordering::Acquire) == 0 {
            // Every thread but this one (all of them, called from outside the pool).
            let me = rayon::current_thread_index();
            let others = threads - usize::from(me.is_some());
            self.waits.live.fetch_add(others, Ordering::AcqRel);
            self.waits.starts.fetch_add(1, Ordering::Relaxed);
            let (waits, most_idle) = (Arc::clone(&self.waits), self.most_idle);
            rayon::spawn_broadcast(move |thread| {
                if Some(thread.index()) != me {
                    stay_awake(&waits, most_idle);
                    waits.live.fetch_sub(1, Ordering::AcqRel);
                }
            });
        }
        Stepping { marked }
    }
}

/// A step in progress on this thread: a wait picked up here returns at once.
#[derive(Debug)]
pub(super) struct Stepping {
    /// Whether this guard marked the thread (and so unmarks it).
    marked: bool,
}

impl Drop for Stepping {
    fn drop(&mut self) {
        if self.marked {
            BUSY.set(false);
        }
    }
}

/// Runs the pool's jobs as they come until neither a job nor a step has come for
/// `most_idle`; returns at once on a busy thread (see the module docs).
fn stay_awake(waits: &Waits, most_idle: Duration) {
    if BUSY.replace(true) {
        return;
    }
    let mut steps = waits.steps.load(Ordering::Relaxed);
    let mut idle_since = Instant::now();
    loop {
        if rayon::yield_now() == Some(rayon::Yield::Executed) {
            idle_since = Instant::now();
            continue;
        }
        let now = waits.steps.load(Ordering::Relaxed);
        if now != steps {
            (steps, idle_since) = (now, Instant::now());
        } else if idle_since.elapsed() > most_idle {
            break;
        }
        std::thread::yield_now();
    }
    BUSY.set(false);
}

#[cfg(test)]
mod tests {
    use rayon::prelude::*;

    use super::*;
    use crate::engine::cpu::test_pool;

    /// Waits up to a second for `waits` to have `n` waits live, doing `work`
    /// meanwhile.
    fn live_become(waits: &Waits, n: usize, work: impl Fn()) -> bool {
        let start = Instant::now();
        while start.elapsed() < Duration::from_secs(1) {
            if waits.live.load(Ordering::Acquire) == n {
                return true;
            }
            work();
        }
        false
    }

    /// Parallel work for every thread (its sum checked).
    fn work() {
        let sum: u64 = (0..10_000u64).into_par_iter().sum();
        assert_eq!(sum, 49_995_000);
    }

    /// Steps one after another start the waits once; the pool's work gets done
    /// meanwhile (the sums are right, nothing hangs); once steps stop coming, the
    /// waits end and the next step starts them again.
    #[test]
    fn a_run_of_steps_starts_the_waits_once() {
        test_pool(3).install(|| {
            let awake = KeepAwake::with_most_idle(Duration::from_millis(300));
            for _ in 0..200 {
                let _step = awake.step();
                work();
            }
            assert_eq!(awake.waits.starts.load(Ordering::Relaxed), 1);
            assert_eq!(awake.waits.live.load(Ordering::Acquire), 2, "they wait on");
            assert!(
                live_become(&awake.waits, 0, std::thread::yield_now),
                "no step for 300 ms: the waits end"
            );
            let _step = awake.step();
            assert_eq!(awake.waits.starts.load(Ordering::Relaxed), 2);
        });
        test_pool(1).install(|| {
            let awake = KeepAwake::default();
            let _step = awake.step();
            assert_eq!(awake.waits.starts.load(Ordering::Relaxed), 0);
        });
    }

    /// A wait run by a stepping thread (a join of the step taking it from the
    /// thread's queue) returns at once instead of holding the step for its bound.
    #[test]
    fn a_stepping_thread_does_not_wait() {
        test_pool(2).install(|| {
            let awake = KeepAwake::with_most_idle(Duration::from_millis(300));
            let stepping = awake.step();
            let start = Instant::now();
            stay_awake(&awake.waits, Duration::from_secs(60));
            assert!(start.elapsed() < Duration::from_secs(1));
            drop(stepping);
            // Not stepping any more, the same call waits out its (short) bound.
            let start = Instant::now();
            stay_awake(&awake.waits, Duration::from_millis(50));
            assert!(start.elapsed() >= Duration::from_millis(50));
        });
    }
}
