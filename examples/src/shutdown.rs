//! SIGINT/SIGTERM (through `ctrlc`) set a flag the programs' main loops poll, so they leave cleanly (dispose,
//! unregister, wait for acknowledgments, print their summary) when a test harness or a user stops them.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

static STOP: AtomicBool = AtomicBool::new(false);

/// Installs the handler for SIGINT and SIGTERM; a second call (or a failure to install) leaves the programs
/// stoppable only by their own means, which is reported on stderr.
pub fn install() {
    if let Err(e) = ctrlc::set_handler(request) {
        eprintln!("warning: no SIGINT/SIGTERM handler: {e}");
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
pub fn sleep(d: Duration) {
    let end = Instant::now() + d;
    while !requested() {
        let now = Instant::now();
        if now >= end {
            break;
        }
        std::thread::sleep((end - now).min(Duration::from_millis(20)));
    }
}
