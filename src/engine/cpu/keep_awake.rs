//! The pool's other threads kept awake through a step.
//!
//! A step runs a handful of parallel stages with serial parts between them (the
//! walls' merge, the totals). An idle rayon worker yields a few dozen times, then
//! sleeps, and waking it goes through the host's scheduler: on the 2-core Intel VM of
//! the benchmarks a region that finds the other worker asleep waits 80–110 µs for it
//! (against 4 µs when it is awake), longer than a stage of a 5000-sphere step takes.
//! So stages began on one thread and the second joined late or not at all. While a
//! [`KeepAwake`] lives, every other thread of the current pool runs the pool's work
//! as it appears and otherwise yields its core, as rayon's own idle rounds do, but
//! without going to sleep: the pour of the LIGGGHTS comparison on two threads went
//! from 4.5e6–4.6e6 to 4.9e6 particle-steps/s, the same bits.
//!
//! # No deadlock
//! The wait is a job on each other thread. A thread picks it up when idle, or while
//! it waits inside a job of its own (a join whose other half was stolen): a wait
//! there would hold that job, and the step that ends the wait may need the job. So a
//! wait nested in a wait returns at once (the next step's wait, picked up inside the
//! last step's), and any wait ends once it has found no work for [`MOST_IDLE`],
//! which bounds the stall of the one case left (a wait picked up inside a job that is
//! not a wait's) and of a guard that is never dropped.

use std::cell::Cell;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// The longest a thread stays awake without finding work.
const MOST_IDLE: Duration = Duration::from_millis(2);

thread_local! {
    /// Whether this thread is inside [`stay_awake`].
    static AWAKE: Cell<bool> = const { Cell::new(false) };
}

/// What a guard shares with its waits.
#[derive(Debug, Default)]
struct Waits {
    /// Set when the guard is dropped.
    done: AtomicBool,
    /// Threads inside this guard's waits now.
    awake: AtomicUsize,
}

/// Keeps the current pool's other threads from sleeping until it is dropped.
///
/// Invariant: `done` is set once the guard is dropped, and every wait it started
/// ends at its next look at it.
#[derive(Debug)]
pub(super) struct KeepAwake {
    /// `None` on one thread, where there is no one to keep awake.
    waits: Option<Arc<Waits>>,
}

impl KeepAwake {
    /// Starts every other thread of the current pool (every thread, called from
    /// outside it) on a wait that runs the pool's jobs, until the guard is dropped.
    pub(super) fn start() -> Self {
        Self::start_with(MOST_IDLE)
    }

    /// [`Self::start`] with waits that end after `most_idle` without work.
    fn start_with(most_idle: Duration) -> Self {
        if rayon::current_num_threads() == 1 {
            return KeepAwake { waits: None };
        }
        let waits = Arc::new(Waits::default());
        let me = rayon::current_thread_index();
        let shared = Arc::clone(&waits);
        rayon::spawn_broadcast(move |thread| {
            if Some(thread.index()) != me {
                stay_awake(&shared, most_idle);
            }
        });
        KeepAwake { waits: Some(waits) }
    }
}

impl Drop for KeepAwake {
    fn drop(&mut self) {
        if let Some(waits) = &self.waits {
            waits.done.store(true, Ordering::Release);
        }
    }
}

/// Runs the pool's jobs as they come until `waits.done`, or until none came for
/// `most_idle`; returns at once inside another such wait (see the module docs).
fn stay_awake(waits: &Waits, most_idle: Duration) {
    if AWAKE.replace(true) {
        return;
    }
    waits.awake.fetch_add(1, Ordering::Relaxed);
    let mut idle_since = Instant::now();
    while !waits.done.load(Ordering::Acquire) {
        if rayon::yield_now() == Some(rayon::Yield::Executed) {
            idle_since = Instant::now();
        } else if idle_since.elapsed() > most_idle {
            break;
        } else {
            std::thread::yield_now();
        }
    }
    waits.awake.fetch_sub(1, Ordering::Relaxed);
    AWAKE.set(false);
}

#[cfg(test)]
mod tests {
    use rayon::prelude::*;

    use super::*;
    use crate::engine::cpu::test_pool;

    /// Waits up to a second for `waits` to have `n` threads awake, doing `work`
    /// meanwhile.
    fn awake_become(waits: &Waits, n: usize, work: impl Fn()) -> bool {
        let start = Instant::now();
        while start.elapsed() < Duration::from_secs(1) {
            if waits.awake.load(Ordering::Relaxed) == n {
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

    fn nothing() {
        std::thread::yield_now();
    }

    /// The other threads wait while the guard lives, do the pool's work meanwhile
    /// (the sums are right, nothing hangs), and stop once it is dropped.
    #[test]
    fn the_other_threads_wait_until_the_guard_is_dropped() {
        test_pool(3).install(|| {
            // Waits that no idle time ends: only the guard can.
            let guard = KeepAwake::start_with(Duration::from_secs(60));
            let waits = Arc::clone(guard.waits.as_ref().unwrap());
            assert!(awake_become(&waits, 2, nothing), "the other two wait");
            for _ in 0..100 {
                work();
            }
            assert_eq!(waits.awake.load(Ordering::Relaxed), 2, "they wait on");
            drop(guard);
            assert!(
                awake_become(&waits, 0, work),
                "they stop when it is dropped"
            );
        });
        test_pool(1).install(|| assert!(KeepAwake::start().waits.is_none()));
    }

    /// A guard that is never dropped lets its waits go once idle for their bound; back
    /// to back guards, as a run's steps take them, get their work done and leave no
    /// wait behind.
    #[test]
    fn waits_end_when_no_work_comes() {
        test_pool(2).install(|| {
            let forgotten = KeepAwake::start_with(Duration::from_millis(300));
            let waits = Arc::clone(forgotten.waits.as_ref().unwrap());
            std::mem::forget(forgotten);
            assert!(awake_become(&waits, 1, nothing), "the other one waits");
            assert!(awake_become(&waits, 0, nothing), "idle, the wait ends");
            let mut last = None;
            for _ in 0..200 {
                let guard = KeepAwake::start();
                let sum: u64 = (0..1000u64).into_par_iter().map(|x| x * 2).sum();
                assert_eq!(sum, 999_000);
                last = guard.waits.clone();
            }
            assert!(awake_become(&last.unwrap(), 0, nothing));
        });
    }
}
