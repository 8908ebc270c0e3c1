//! SIGINT/SIGTERM set a flag the programs' main loops poll, so they leave cleanly (dispose, unregister,
//! wait for acknowledgments, print their summary) when a test harness or a user stops them.

use std::sync::atomic::{AtomicBool, Ordering};

static STOP: AtomicBool = AtomicBool::new(false);

extern "C" fn on_signal(_sig: libc::c_int) {
    // Only an atomic store: async-signal-safe.
    STOP.store(true, Ordering::SeqCst);
}

/// Installs the handlers for SIGINT and SIGTERM.
pub fn install() {
    let handler = on_signal as extern "C" fn(libc::c_int);
    // SAFETY: the handler only performs an atomic store, which is async-signal-safe; `signal` is
    // called with valid signal numbers and a valid function pointer.
    unsafe {
        libc::signal(libc::SIGINT, handler as libc::sighandler_t);
        libc::signal(libc::SIGTERM, handler as libc::sighandler_t);
    }
}

/// Whether a stop was requested.
pub fn requested() -> bool {
    STOP.load(Ordering::SeqCst)
}

/// Requests a stop from inside the program (same effect as a signal).
pub fn request() {
    STOP.store(true, Ordering::SeqCst);
}

/// Sleeps up to `d`, waking early (in steps of at most 20 ms) when a stop is requested.
pub fn sleep(d: std::time::Duration) {
    let end = std::time::Instant::now() + d;
    while !requested() {
        let now = std::time::Instant::now();
        if now >= end {
            break;
        }
        std::thread::sleep((end - now).min(std::time::Duration::from_millis(20)));
    }
}
