//! Long calls off the GIL: the work runs on its own thread (on a rayon pool of the threads
//! asked for) while the calling thread, holding the GIL only for moments, reports progress
//! to an optional callback and stops the work on Ctrl-C (KeyboardInterrupt) or when the
//! callback raises.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc;
use std::time::Duration;

use pyo3::prelude::*;

/// How often the calling thread looks for a signal and reports progress.
const TICK: Duration = Duration::from_millis(50);

/// What the work and the calling thread share: a stop flag and the work done so far.
#[derive(Debug, Default)]
pub struct Control {
    stop: AtomicBool,
    done: AtomicU64,
}

impl Control {
    /// True once the caller has asked the work to stop; the work returns soon after.
    pub fn stopped(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }

    /// The stop flag, for library calls that take one.
    pub fn flag(&self) -> &AtomicBool {
        &self.stop
    }

    /// Records the work done so far (in the units of the call's total).
    pub fn set_done(&self, done: u64) {
        self.done.fetch_max(done, Ordering::Relaxed);
    }
}

/// A rayon pool of `threads` threads (the global pool's size when `None`), at least 1.
///
/// # Errors
/// `ArgumentError` for 0 threads; a `RuntimeError` if the threads cannot be started.
pub fn pool(threads: Option<usize>) -> PyResult<Option<rayon::ThreadPool>> {
    match threads {
        None => Ok(None),
        Some(0) => Err(crate::errors::argument(
            "threads: expected 1 or more (None: one per core)",
        )),
        Some(t) => rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .map(Some)
            .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string())),
    }
}

/// Runs `work` on another thread, on `threads` workers, with the GIL released. Every
/// [`TICK`] the calling thread checks for signals and calls `progress(done, total)` when
/// the work has moved on. A signal's exception (KeyboardInterrupt) or the callback's stops
/// the work: the flag is set, the work is waited for, and the exception is raised.
///
/// # Errors
/// The exception a signal handler or the progress callback raised.
pub fn run<R: Send>(
    py: Python<'_>,
    threads: Option<usize>,
    progress: Option<&Bound<'_, PyAny>>,
    total: u64,
    work: impl FnOnce(&Control) -> R + Send,
) -> PyResult<R> {
    let pool = pool(threads)?;
    let control = Control::default();
    std::thread::scope(|scope| {
        let (sender, receiver) = mpsc::channel();
        // Shared with the GIL-free closures below, which must be `Send`.
        let receiver = std::sync::Mutex::new(receiver);
        let wait = |timeout: Option<Duration>| {
            let r = receiver
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner);
            match timeout {
                Some(t) => r.recv_timeout(t),
                None => r.recv().map_err(|_| mpsc::RecvTimeoutError::Disconnected),
            }
        };
        let control = &control;
        let pool = pool.as_ref();
        scope.spawn(move || {
            let result = match pool {
                Some(p) => p.install(|| work(control)),
                None => work(control),
            };
            let _ = sender.send(result);
        });
        let mut reported = u64::MAX;
        loop {
            match py.detach(|| wait(Some(TICK))) {
                Ok(result) => {
                    let done = control.done.load(Ordering::Relaxed);
                    if let (Some(cb), true) = (progress, done != reported) {
                        cb.call1((total, total))?;
                    }
                    return Ok(result);
                }
                Err(mpsc::RecvTimeoutError::Disconnected) => {
                    return Err(pyo3::exceptions::PyRuntimeError::new_err(
                        "the work stopped without a result",
                    ))
                }
                Err(mpsc::RecvTimeoutError::Timeout) => {}
            }
            let mut checked = py.check_signals();
            if checked.is_ok() {
                let done = control.done.load(Ordering::Relaxed);
                if let (Some(cb), true) = (progress, done != reported) {
                    reported = done;
                    checked = cb.call1((done.min(total), total)).map(drop);
                }
            }
            if let Err(e) = checked {
                control.stop.store(true, Ordering::Relaxed);
                // The work ends at its next check; its result is dropped.
                let _ = py.detach(|| wait(None));
                return Err(e);
            }
        }
    })
}
