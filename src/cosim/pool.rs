//! A rayon thread pool owned by one component, whose threads are joined when it is
//! dropped.
//!
//! A host that loads talus as a shared library (an FMI master) may `dlclose` it right
//! after freeing the last instance. Rayon's global pool would keep threads running
//! library code after that, and dropping an ordinary `rayon::ThreadPool` only *asks*
//! its threads to stop. This pool spawns its workers itself and joins every one of
//! them on drop, so when a component is gone, no thread of the library is left.

use std::thread::JoinHandle;

use rayon::{ThreadPool, ThreadPoolBuildError, ThreadPoolBuilder};

/// A thread pool whose workers have all exited once it is dropped.
pub struct JoinedPool {
    pool: Option<ThreadPool>,
    workers: Vec<JoinHandle<()>>,
}

impl JoinedPool {
    /// A pool of `threads` workers (at least one).
    pub fn new(threads: usize) -> Result<Self, ThreadPoolBuildError> {
        let mut workers = Vec::new();
        let pool = ThreadPoolBuilder::new()
            .num_threads(threads.max(1))
            .thread_name(|i| format!("talus-{i}"))
            .spawn_handler(|thread| {
                let handle = std::thread::Builder::new()
                    .name(thread.name().unwrap_or("talus").to_string())
                    .spawn(move || thread.run())?;
                workers.push(handle);
                Ok(())
            })
            .build()?;
        Ok(JoinedPool {
            pool: Some(pool),
            workers,
        })
    }

    /// Number of worker threads.
    pub fn threads(&self) -> usize {
        self.workers.len()
    }

    /// Runs `f` with this pool as rayon's current pool.
    pub fn install<R: Send>(&self, f: impl FnOnce() -> R + Send) -> R {
        self.pool
            .as_ref()
            .expect("pool lives until drop")
            .install(f)
    }
}

impl Drop for JoinedPool {
    fn drop(&mut self) {
        // Dropping the pool tells the workers to finish; joining waits until they have.
        drop(self.pool.take());
        for worker in self.workers.drain(..) {
            let _ = worker.join();
        }
    }
}

impl std::fmt::Debug for JoinedPool {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "JoinedPool({} threads)", self.workers.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    #[test]
    fn runs_work_in_its_own_threads_and_joins_them() {
        let pool = JoinedPool::new(2).unwrap();
        assert_eq!(pool.threads(), 2);
        let names: Vec<String> = pool.install(|| {
            (0..64)
                .into_par_iter()
                .map(|_| std::thread::current().name().unwrap_or("").to_string())
                .collect()
        });
        assert!(names.iter().all(|n| n.starts_with("talus-")), "{names:?}");
        let sum: u64 = pool.install(|| (1..=100u64).into_par_iter().sum());
        assert_eq!(sum, 5050);
        drop(pool); // joins; a hang or panic here fails the test
    }
}
