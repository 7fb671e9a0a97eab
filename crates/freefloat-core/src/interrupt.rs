//! The one way a long engine call can be stopped: a hook the routine polls while it works.
//!
//! A long routine (a simulation, an estimator over many samples, a design loop) takes an optional
//! [`Hook`], called with the fraction done; it returns `false` to stop the run. The routine polls it
//! through a [`Poller`], which calls the hook at most every [`POLL_INTERVAL`] of wall time (so a
//! hook that takes the GIL and checks for Ctrl-C costs nothing measurable) and at least that often
//! as long as the routine calls [`Poller::poll`] once per unit of work (a step, a sample). A stop is
//! reported as [`FfError::Interrupted`], never as a numerical failure.

use crate::error::{FfError, Result};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Optional progress/interrupt hook: called with the fraction done (0..1), returns false to stop.
pub type Hook<'a> = &'a mut dyn FnMut(f64) -> bool;

/// Wall time between two calls of the hook: Ctrl-C is seen within this (plus one unit of work).
pub const POLL_INTERVAL: Duration = Duration::from_millis(20);

/// Calls a [`Hook`] at most every [`POLL_INTERVAL`]; the clock is read every few polls only, so that a
/// poll per step of a small model stays far below the cost of the step.
pub struct Poller<'a> {
    hook: Option<Hook<'a>>,
    last: Instant,
    count: u32,
}

impl<'a> Poller<'a> {
    /// A poller over `hook` (none: every poll succeeds at the cost of a branch).
    pub fn new(hook: Option<Hook<'a>>) -> Self {
        Poller { hook, last: Instant::now(), count: 0 }
    }

    /// Whether there is a hook to call.
    pub fn active(&self) -> bool {
        self.hook.is_some()
    }

    /// Poll after one unit of work, `fraction` done. Calls the hook when `POLL_INTERVAL` has passed since
    /// the last call; its `false` becomes `FfError::Interrupted` with the message `what()`.
    #[inline]
    pub fn poll(&mut self, fraction: f64, what: impl FnOnce() -> String) -> Result<()> {
        let Some(h) = self.hook.as_mut() else { return Ok(()) };
        self.count = self.count.wrapping_add(1);
        // reading the clock costs ~20 ns: every 8th unit of work is often enough for units of a few µs
        // and more (a simulation step, one sample of an estimator)
        if !self.count.is_multiple_of(8) {
            return Ok(());
        }
        let now = Instant::now();
        if now.duration_since(self.last) < POLL_INTERVAL {
            return Ok(());
        }
        self.last = now;
        if h(fraction) {
            Ok(())
        } else {
            Err(FfError::interrupted(what()))
        }
    }

    /// Call the hook now, whatever the time since the last call (e.g. at the end, with 1.0).
    pub fn now(&mut self, fraction: f64) -> bool {
        self.last = Instant::now();
        match self.hook.as_mut() {
            Some(h) => h(fraction),
            None => true,
        }
    }
}

/// Watch worker threads from the calling thread: while any of `handles` runs, call the hook at most every
/// [`POLL_INTERVAL`] (with `fraction()`); on its `false` raise `stop`, which the workers read between units
/// of work, and return `false` at once (the caller joins the workers, which then end within one unit).
/// Without a hook this returns `true` immediately and the caller just joins.
///
/// The naps start short (a small job finishes in a millisecond and must not wait out a long nap) and grow
/// to 5 ms. The calling thread is the one that may hold what the hook needs (e.g. the Python interpreter
/// for a Ctrl-C check), which is why the hook is never called from a worker.
pub fn supervise<T>(
    hook: &mut Option<Hook>,
    stop: &AtomicBool,
    handles: &[std::thread::ScopedJoinHandle<'_, T>],
    mut fraction: impl FnMut() -> f64,
) -> bool {
    let Some(h) = hook.as_mut() else { return true };
    let mut nap = Duration::from_micros(50);
    let mut last = Instant::now();
    while !handles.iter().all(|j| j.is_finished()) {
        std::thread::sleep(nap);
        nap = (nap * 2).min(Duration::from_millis(5));
        if last.elapsed() >= POLL_INTERVAL {
            last = Instant::now();
            if !h(fraction()) {
                stop.store(true, Ordering::Relaxed);
                return false;
            }
        }
    }
    true
}

/// Whether a worker should stop before its next unit of work (see [`supervise`]).
#[inline]
pub fn stopped(stop: Option<&AtomicBool>) -> bool {
    stop.is_some_and(|s| s.load(Ordering::Relaxed))
}
