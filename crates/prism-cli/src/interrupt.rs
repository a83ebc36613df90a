//! Ctrl-C (SIGINT) and SIGTERM: the temporary files being written are removed before the
//! process exits (130 or 143, as a shell reports a signal), so an interrupted command leaves
//! no hidden `.NAME.tmp` beside its outputs. The handler only writes the signal's number
//! to a pipe; a thread waiting on the pipe does the work.

use std::sync::atomic::{AtomicI32, Ordering};

/// The pipe's write end, for the handler.
static PIPE: AtomicI32 = AtomicI32::new(-1);

extern "C" fn on_signal(signal: libc::c_int) {
    let byte = signal as u8;
    // SAFETY: write(2) is async-signal-safe; the descriptor stays open for the process's
    // life and the byte outlives the call.
    unsafe {
        libc::write(PIPE.load(Ordering::Relaxed), (&raw const byte).cast(), 1);
    }
}

/// Installs the handler for SIGINT and SIGTERM and starts the thread that cleans up. If
/// the pipe cannot be made, signals keep their default action.
pub fn clean_up_on_signals() {
    let mut fds = [0; 2];
    // SAFETY: pipe(2) writes two descriptors into the array it is given.
    if unsafe { libc::pipe(fds.as_mut_ptr()) } != 0 {
        return;
    }
    PIPE.store(fds[1], Ordering::Relaxed);
    let read_end = fds[0];
    let started = std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            let mut byte = 0u8;
            loop {
                // SAFETY: reads at most one byte into `byte`.
                let n = unsafe { libc::read(read_end, (&raw mut byte).cast(), 1) };
                if n == 1 {
                    break;
                }
                if n == 0
                    || std::io::Error::last_os_error().kind() != std::io::ErrorKind::Interrupted
                {
                    return;
                }
            }
            prism_image::remove_temporaries_before_exit();
            eprintln!();
            std::process::exit(128 + i32::from(byte));
        });
    if started.is_err() {
        return;
    }
    let handler = on_signal as extern "C" fn(libc::c_int) as libc::sighandler_t;
    // SAFETY: the handler only calls write(2), which is async-signal-safe.
    unsafe {
        libc::signal(libc::SIGINT, handler);
        libc::signal(libc::SIGTERM, handler);
    }
}
