//! Progress and timing of long runs, kept out of their results.
//!
//! A long run (a diagnosis, a benchmark, a sweep of walks) takes an [`Observer`] and reports
//! to it as it goes — the pattern of argmin's observers: the run's signature names one
//! add-on instead of a closure per kind of news, and whoever watches (the CLI's progress
//! bars, the Python binding, a test that wants silence: [`Silent`]) implements only what it
//! shows. What a run returns never depends on its observer.
//!
//! [`Stopwatch`] measures the wall-clock seconds a run reports beside its result (they are
//! not part of it: two runs give the same answer in different times).
//!
//! Depends on nothing of ours: every layer may use it.

use std::time::Instant;

/// Watches a long run: the run reports to it, and nothing the run computes depends on it.
/// `Sync` because runs report from their rayon workers.
///
/// ```
/// use std::sync::atomic::{AtomicUsize, Ordering};
/// use robot_survey::progress::{Observer, Silent};
///
/// /// Counts the walks.
/// struct Walks(AtomicUsize);
/// impl Observer for Walks {
///     fn tick(&self) {
///         self.0.fetch_add(1, Ordering::Relaxed);
///     }
/// }
///
/// fn run(progress: &dyn Observer) {
///     progress.stage("walking");
///     (0..3).for_each(|_| progress.tick());
/// }
/// let walks = Walks(AtomicUsize::new(0));
/// run(&walks);
/// assert_eq!(walks.0.into_inner(), 3);
/// run(&Silent);
/// ```
pub trait Observer: Sync {
    /// One unit of work finished (a walk, a case): advances a progress bar.
    fn tick(&self) {}

    /// A stage of the run begins, or has news: `what` is a line for a log or a progress
    /// bar's message.
    fn stage(&self, _what: &str) {}
}

/// An observer that shows nothing (tests, batch callers, runs nested in a larger one).
#[derive(Clone, Copy, Debug, Default)]
pub struct Silent;

impl Observer for Silent {}

/// Wall-clock time since it was started, in seconds: one place where a run's timings are
/// read, instead of an `Instant` and an `elapsed().as_secs_f64()` per stage.
#[derive(Clone, Copy, Debug)]
pub struct Stopwatch(Instant);

impl Stopwatch {
    /// Starts now.
    pub fn start() -> Self {
        Self(Instant::now())
    }

    /// Seconds since [`Stopwatch::start`].
    pub fn seconds(&self) -> f64 {
        self.0.elapsed().as_secs_f64()
    }
}
