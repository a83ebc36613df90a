//! Long calls off the GIL: the work runs on its own thread (on a rayon pool of the threads
//! asked for) while the calling thread, holding the GIL only for moments, reports progress
//! to an optional callback and stops the work on Ctrl-C (KeyboardInterrupt) or when the
//! callback raises.

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc;
use std::sync::{Arc, Mutex};
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

/// The worker pools made so far, by thread count (0: one per core), kept for the process's
/// life so that a call in a loop does not start threads each time.
static POOLS: Mutex<BTreeMap<usize, Arc<rayon::ThreadPool>>> = Mutex::new(BTreeMap::new());

/// A rayon pool of `threads` threads (one per core when `None`; at most
/// [`prism_math::limits::max_threads`], with a warning when clamped).
///
/// # Errors
/// `ArgumentError` for 0 threads; a `RuntimeError` if the threads cannot be started.
pub fn pool(threads: Option<usize>) -> PyResult<Arc<rayon::ThreadPool>> {
    if threads == Some(0) {
        return Err(crate::errors::argument(
            "threads: expected 1 or more (None: one per core)",
        ));
    }
    let most = prism_math::limits::max_threads();
    if let Some(t) = threads.filter(|&t| t > most) {
        Python::attach(|py| {
            let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
            let message = format!("threads={t}: more than four a core; using {most} threads");
            PyErr::warn(py, &category, &std::ffi::CString::new(message)?, 1)
        })?;
    }
    let key = threads.map_or(0, |t| t.min(most));
    let mut pools = POOLS
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    if let Some(p) = pools.get(&key) {
        return Ok(Arc::clone(p));
    }
    let made = rayon::ThreadPoolBuilder::new()
        .num_threads(key)
        .build()
        .map(Arc::new)
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?;
    pools.insert(key, Arc::clone(&made));
    Ok(made)
}

/// Runs `work` on another thread, inside a pool of `threads` workers (so that its parallel
/// loops start no threads), with the GIL released. Every
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
        let pool = &pool;
        scope.spawn(move || {
            let _ = sender.send(pool.install(|| work(control)));
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

/// Runs a short `work` (at most a few milliseconds) on this thread inside the pool of
/// `threads` workers, with the GIL released: no second thread and no polling, so that calls
/// made in a loop cost little more than the work. A Ctrl-C pressed during it is raised after.
///
/// # Errors
/// The exception a signal handler raised.
pub fn run_short<R: Send>(
    py: Python<'_>,
    threads: Option<usize>,
    work: impl FnOnce(&Control) -> R + Send,
) -> PyResult<R> {
    let pool = pool(threads)?;
    let control = Control::default();
    let result = py.detach(|| pool.install(|| work(&control)));
    py.check_signals()?;
    Ok(result)
}
