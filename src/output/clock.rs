//! When a run writes its CSV rows and its frames: a clock of its own, so that every
//! rank of a decomposed run knows when rank 0 writes (gathering the world for it is
//! collective) without holding the files.

use crate::Real;

/// The rows and frames due after a step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Due {
    pub rows: bool,
    pub frame: bool,
}

impl Due {
    /// Whether anything is written.
    pub fn any(self) -> bool {
        self.rows || self.frame
    }
}

/// The schedule of the rows (every `csv_interval`, or every frame) and the frames
/// (every `frame_interval`) of a run, and where it stands.
///
/// Invariant: `next_row` and `next_frame` lie after the last row and frame written.
#[derive(Clone, Debug, PartialEq)]
pub struct OutputClock {
    pub(super) frame_interval: Option<Real>,
    pub(super) csv_interval: Option<Real>,
    pub(super) next_frame: Real,
    pub(super) next_row: Real,
    /// Time of the last row (the start before any).
    pub(super) last_row: Real,
    /// Rows written.
    pub(super) rows: usize,
}

impl OutputClock {
    /// The clock of a run that starts at `start` (rows every `csv_interval`, else
    /// with the frames).
    pub fn new(frame_interval: Option<Real>, csv_interval: Option<Real>, start: Real) -> Self {
        OutputClock {
            frame_interval,
            csv_interval: csv_interval.or(frame_interval),
            next_frame: start,
            next_row: start,
            last_row: start,
            rows: 0,
        }
    }

    /// What is due after a step of length `dt` that ended at `t` (`force`: the
    /// run's first or last record, which writes both unless that time is written
    /// already).
    pub fn due(&self, t: Real, dt: Real, force: bool) -> Due {
        let eps = 1e-9 * dt;
        Due {
            rows: self.csv_interval.is_some_and(|_| t >= self.next_row - eps)
                || (force && (t > self.last_row || self.rows == 0)),
            frame: force
                || self
                    .frame_interval
                    .is_some_and(|_| t >= self.next_frame - eps),
        }
    }

    /// Records that `due` was written at `t` after a step of length `dt`.
    pub fn advance(&mut self, due: Due, t: Real, dt: Real) {
        let eps = 1e-9 * dt;
        if due.rows {
            if let Some(i) = self.csv_interval {
                while self.next_row <= t + eps {
                    self.next_row += i;
                }
            }
            self.last_row = t;
            self.rows += 1;
        }
        if due.frame
            && let Some(i) = self.frame_interval
        {
            while self.next_frame <= t + eps {
                self.next_frame += i;
            }
        }
    }

    /// Time of the last row (the start before any).
    pub fn last_row(&self) -> Real {
        self.last_row
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_follow_their_interval_and_frames_theirs() {
        let mut clock = OutputClock::new(Some(0.1), Some(0.025), 0.0);
        let dt = 0.01;
        // The run's first record, at its start.
        let first = clock.due(0.0, 0.0, true);
        assert_eq!(
            first,
            Due {
                rows: true,
                frame: true
            }
        );
        clock.advance(first, 0.0, 0.0);
        let (mut rows, mut frames) = (1, 1);
        for k in 1..=100 {
            let t = k as Real * dt;
            let due = clock.due(t, dt, false);
            rows += usize::from(due.rows);
            frames += usize::from(due.frame);
            clock.advance(due, t, dt);
        }
        // After the first, a row at the first step past each multiple of 0.025 s
        // (0.03, 0.05, 0.08, 0.10, ...) and a frame at each multiple of 0.1 s.
        assert_eq!((rows, frames), (1 + 40, 1 + 10));
        // The last step's time is written already: a forced record writes a frame
        // but no second row.
        let due = clock.due(1.0, dt, true);
        assert_eq!(
            due,
            Due {
                rows: false,
                frame: true
            }
        );
    }
}
