//! When a receive thread busy-polls its socket instead of sleeping in the kernel ([`PollPolicy`]), and the
//! probes that feed it: the thread's involuntary context switches, the host's CPU pressure, and how many of
//! the process's receive threads poll at once ([`PollerSlot`]).
//!
//! Polling saves a thread wake-up per datagram (tens of microseconds on an idle host whose cores sleep), but
//! only while a core is free: on a contended host a polling thread takes the core from the very thread it
//! waits for (session 18 in `docs/performance.md`). So a thread polls only
//! - after a batch that followed the one before within [`DENSE`] windows (dense traffic; discovery never
//!   polls). Wider than the window itself: on an idle host a round trip whose ends sleep takes longer than
//!   the window (about 65 µs here), and would never start polling, which is what makes it short;
//! - while its polling episodes are not preempted: an involuntary context switch during an episode
//!   (the kernel ran something else in its place, or it yielded to a runnable thread) pauses polling,
//!   for twice as long as the pause before, up to [`MAX_PAUSE`]; an episode without one halves the next
//!   pause, so that a contended core stays paused most of the time;
//! - while the host's CPU pressure (Linux PSI, "some avg10") is below [`PRESSURE_LIMIT`]; where it cannot
//!   be read (not Linux, or a kernel without PSI), never: the thread switches alone were not enough to keep
//!   a loaded host's 64 KiB round trips from 1 ms tails (`docs/performance.md`, session 25);
//! - while fewer than all but one of the cores hold a polling thread of this process.
//!
//! An episode that ends with nothing arriving halves the next one (down to 1/64 of the window); one that
//! ends with a datagram restores the whole window.

use std::cell::Cell;
use std::sync::atomic::{AtomicU32, AtomicU64, AtomicUsize, Ordering};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// The shortest pause after a contended episode; it doubles per contended episode, halves per other one.
const FIRST_PAUSE: Duration = Duration::from_millis(1);
/// The longest pause: under sustained load a thread tries to poll a few times a second at most.
pub(super) const MAX_PAUSE: Duration = Duration::from_millis(256);
/// Batches at most this many windows apart are dense traffic, after which a thread may poll. Polling that
/// finds nothing shrinks fast ([`MAX_HALVINGS`]), so a stream this sparse costs little.
pub(super) const DENSE: u32 = 8;
/// An episode is at least the window divided by this (halved per unproductive episode in a row).
const MAX_HALVINGS: u32 = 6;
/// CPU pressure (percent of the last 10 s in which some runnable task waited for a core) above which
/// nothing polls.
pub(super) const PRESSURE_LIMIT: f32 = 10.0;
/// The pressure is read at most this often per process.
const PRESSURE_EVERY: Duration = Duration::from_millis(500);
/// A thread looks at the process's last reading at most this often.
const LOOK_EVERY: Duration = Duration::from_millis(20);

/// How a polling episode ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Episode {
    /// A datagram arrived while polling.
    Productive,
    /// The window closed with nothing queued.
    Empty,
}

/// The decisions of one receive thread: fed with what happened and the clock, it says whether to poll after
/// a batch, and until when. No I/O: see the module's probes for the observations.
#[derive(Debug)]
pub(super) struct PollPolicy {
    /// The configured window; zero: never poll.
    max: Duration,
    /// Unproductive episodes in a row (the next episode is `max >> empties`).
    empties: u32,
    /// Until when a batch follows the last one closely enough to count as dense traffic (`DENSE` windows
    /// after it).
    dense_until: Option<Instant>,
    /// The thread's involuntary context switches when the current episode began.
    switches: Option<u64>,
    /// No polling before this (after a contended episode).
    paused_until: Option<Instant>,
    /// The next pause, should the next episode be contended too.
    pause: Duration,
}

impl PollPolicy {
    /// A policy polling for up to `max` after each batch of dense traffic.
    pub(super) fn new(max: Duration) -> Self {
        PollPolicy {
            max,
            empties: 0,
            dense_until: None,
            switches: None,
            paused_until: None,
            pause: FIRST_PAUSE,
        }
    }

    /// Whether this policy ever polls.
    pub(super) fn enabled(&self) -> bool {
        !self.max.is_zero()
    }

    /// A batch was handled at `now`; `pressured`: the host's cores are contended. Returns the end of the
    /// polling episode to run now, or `None` to wait in the kernel.
    pub(super) fn after_batch(&mut self, now: Instant, pressured: bool) -> Option<Instant> {
        if !self.enabled() {
            return None;
        }
        let dense = self.dense_until.is_some_and(|t| now <= t);
        self.dense_until = now.checked_add(self.max * DENSE);
        let paused = self.paused_until.is_some_and(|t| now < t);
        (dense && !paused && !pressured).then(|| now + self.max / (1 << self.empties))
    }

    /// A polling episode begins; `switches`: the thread's involuntary context switches so far (`None` where
    /// they cannot be read). Only switches during the episode count: between episodes a thread that sends
    /// is preempted by the very thread it wakes, which says nothing about polling.
    pub(super) fn began(&mut self, switches: Option<u64>) {
        self.switches = switches;
    }

    /// A polling episode ended at `now` as `how`; `switches`: the thread's involuntary context switches so
    /// far.
    pub(super) fn ended(&mut self, now: Instant, how: Episode, switches: Option<u64>) {
        self.empties = match how {
            Episode::Productive => 0,
            Episode::Empty => (self.empties + 1).min(MAX_HALVINGS),
        };
        let before = self.switches.take();
        let contended = matches!((before, switches), (Some(b), Some(s)) if s > b);
        if contended {
            self.paused_until = Some(now + self.pause);
            self.pause = (self.pause * 2).min(MAX_PAUSE);
        } else {
            self.pause = (self.pause / 2).max(FIRST_PAUSE);
        }
    }
}

/// The calling thread's involuntary context switches so far (`getrusage(RUSAGE_THREAD)`), where Linux
/// counts them.
pub(super) fn thread_switches() -> Option<u64> {
    #[cfg(target_os = "linux")]
    {
        // SAFETY: rusage is a plain C struct for which all-zero is valid; getrusage writes into it.
        let mut ru: libc::rusage = unsafe { std::mem::zeroed() };
        // SAFETY: a valid pointer to a rusage.
        let r = unsafe { libc::getrusage(libc::RUSAGE_THREAD, &mut ru) };
        (r == 0).then_some(ru.ru_nivcsw as u64)
    }
    #[cfg(not(target_os = "linux"))]
    None
}

/// Whether the host's CPU pressure is above [`PRESSURE_LIMIT`]: read from `/proc/pressure/cpu` by whichever
/// thread finds the last reading older than [`PRESSURE_EVERY`], shared by all through atomics. Where the
/// file cannot be read, always.
pub(super) fn pressured(now: Instant) -> bool {
    thread_local! {
        /// This thread's last answer and when it expires: the shared reading is looked at a few times a
        /// second per thread, not per batch (a clock subtraction and a 128-bit division each).
        static LOOKED: Cell<Option<(Instant, bool)>> = const { Cell::new(None) };
    }
    LOOKED.with(|l| match l.get() {
        Some((until, p)) if now < until => p,
        _ => {
            let p = pressured_shared(now);
            l.set(Some((now + LOOK_EVERY, p)));
            p
        }
    })
}

/// [`pressured`] from the reading shared by the process's threads.
fn pressured_shared(now: Instant) -> bool {
    static EPOCH: OnceLock<Instant> = OnceLock::new();
    /// Milliseconds after `EPOCH` of the last reading, plus one (0: never read).
    static READ_AT: AtomicU64 = AtomicU64::new(0);
    /// The last reading ("some avg10" in hundredths of a percent); `u32::MAX` where there is none.
    static SOME: AtomicU32 = AtomicU32::new(u32::MAX);
    let epoch = *EPOCH.get_or_init(|| now);
    let ms = now.saturating_duration_since(epoch).as_millis() as u64 + 1;
    let at = READ_AT.load(Ordering::Relaxed);
    let due = at == 0 || ms >= at + PRESSURE_EVERY.as_millis() as u64;
    if due
        && READ_AT
            .compare_exchange(at, ms, Ordering::Relaxed, Ordering::Relaxed)
            .is_ok()
    {
        let some = read_pressure().map_or(u32::MAX, |p| (p * 100.0) as u32);
        SOME.store(some, Ordering::Relaxed);
    }
    SOME.load(Ordering::Relaxed) as f32 / 100.0 > PRESSURE_LIMIT
}

/// "some avg10" of `/proc/pressure/cpu`, without allocating.
fn read_pressure() -> Option<f32> {
    use std::io::Read;
    let mut buf = [0u8; 256];
    let n = std::fs::File::open("/proc/pressure/cpu")
        .and_then(|mut f| f.read(&mut buf))
        .ok()?;
    parse_pressure(std::str::from_utf8(&buf[..n]).ok()?)
}

/// "some avg10" of a PSI file's text.
fn parse_pressure(text: &str) -> Option<f32> {
    let some = text.lines().find(|l| l.starts_with("some "))?;
    let avg10 = some.split(' ').find_map(|f| f.strip_prefix("avg10="))?;
    avg10.parse().ok()
}

/// The process's polling threads.
static POLLING: AtomicUsize = AtomicUsize::new(0);

/// A right to poll, one of all but one of the cores per process (at least one); given back on drop.
pub(super) struct PollerSlot(());

impl PollerSlot {
    /// A slot, if one is free.
    pub(super) fn take() -> Option<Self> {
        static MOST: OnceLock<usize> = OnceLock::new();
        let most = *MOST.get_or_init(|| {
            std::thread::available_parallelism().map_or(1, |n| n.get().saturating_sub(1).max(1))
        });
        POLLING
            .fetch_update(Ordering::Acquire, Ordering::Relaxed, |n| {
                (n < most).then_some(n + 1)
            })
            .ok()
            .map(|_| PollerSlot(()))
    }
}

impl Drop for PollerSlot {
    fn drop(&mut self) {
        POLLING.fetch_sub(1, Ordering::Release);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const WINDOW: Duration = Duration::from_micros(50);
    const GAP: Duration = Duration::from_micros(10);

    /// Batches `GAP` apart from `t`, each followed by an episode ending as `how` with `switches`; returns
    /// how many of them polled, and the time after the last.
    fn run(
        p: &mut PollPolicy,
        mut t: Instant,
        n: usize,
        how: Episode,
        switches: &mut dyn FnMut() -> Option<u64>,
    ) -> (usize, Instant) {
        let mut polled = 0;
        for _ in 0..n {
            if let Some(until) = p.after_batch(t, false) {
                polled += 1;
                assert!(until > t && until <= t + WINDOW);
                p.began(switches());
                p.ended(t + GAP / 2, how, switches());
            }
            t += GAP;
        }
        (polled, t)
    }

    #[test]
    fn sparse_traffic_never_polls() {
        let mut p = PollPolicy::new(WINDOW);
        let mut t = Instant::now();
        for _ in 0..100 {
            assert_eq!(p.after_batch(t, false), None);
            t += WINDOW * DENSE + Duration::from_micros(1);
        }
    }

    #[test]
    fn off_never_polls() {
        let mut p = PollPolicy::new(Duration::ZERO);
        let t = Instant::now();
        let (polled, _) = run(&mut p, t, 100, Episode::Productive, &mut || Some(0));
        assert_eq!(polled, 0);
    }

    #[test]
    fn productive_polling_keeps_the_window() {
        let mut p = PollPolicy::new(WINDOW);
        let t = Instant::now();
        let (polled, t) = run(&mut p, t, 1000, Episode::Productive, &mut || Some(7));
        assert_eq!(polled, 999, "every batch but the first polls");
        assert_eq!(p.after_batch(t, false), Some(t + WINDOW));
    }

    #[test]
    fn unproductive_polling_shrinks_then_a_datagram_restores_the_window() {
        let mut p = PollPolicy::new(WINDOW);
        let t = Instant::now();
        let (_, t) = run(&mut p, t, 20, Episode::Empty, &mut || Some(0));
        assert_eq!(
            p.after_batch(t, false),
            Some(t + WINDOW / (1 << MAX_HALVINGS))
        );
        p.ended(t, Episode::Productive, Some(0));
        let t = t + GAP;
        assert_eq!(p.after_batch(t, false), Some(t + WINDOW));
    }

    #[test]
    fn contention_stops_polling_for_longer_and_longer() {
        let mut p = PollPolicy::new(WINDOW);
        let mut n = 0;
        let mut rising = || {
            n += 1;
            Some(n)
        };
        let t = Instant::now();
        // The first episode sees a switch while it polls, and pauses.
        let (polled, t) = run(&mut p, t, 3, Episode::Productive, &mut rising);
        assert_eq!(polled, 1);
        let (polled, t) = run(&mut p, t, 50, Episode::Productive, &mut rising);
        assert_eq!(polled, 0, "paused for {FIRST_PAUSE:?}");
        // Contended again after the pause: twice as long, and so on up to the cap.
        let mut t = t + FIRST_PAUSE;
        assert!(p.after_batch(t - GAP, false).is_none());
        let mut pause = FIRST_PAUSE * 2;
        for _ in 0..12 {
            assert!(p.after_batch(t, false).is_some());
            p.began(rising());
            p.ended(t, Episode::Productive, rising());
            assert!(p.after_batch(t + GAP, false).is_none());
            assert!(p.after_batch(t + pause - GAP, false).is_none());
            t += pause;
            pause = (pause * 2).min(MAX_PAUSE);
        }
        assert_eq!(p.pause, MAX_PAUSE);
        // Uncontended episodes: polling goes on, and the next pause halves per episode.
        assert!(p.after_batch(t, false).is_some());
        p.began(Some(n));
        p.ended(t, Episode::Productive, Some(n));
        assert_eq!(p.pause, MAX_PAUSE / 2);
        let (polled, _) = run(&mut p, t + GAP, 10, Episode::Productive, &mut || Some(n));
        assert_eq!(polled, 10);
        assert_eq!(p.pause, FIRST_PAUSE);
    }

    #[test]
    fn pressure_stops_polling() {
        let mut p = PollPolicy::new(WINDOW);
        let t = Instant::now();
        assert!(p.after_batch(t, false).is_none());
        assert!(p.after_batch(t + GAP, true).is_none());
        assert!(p.after_batch(t + GAP * 2, false).is_some());
    }

    #[test]
    fn pressure_files_parse() {
        let text = "some avg10=81.73 avg60=38.49 avg300=12.70 total=4266048007\n\
                    full avg10=0.00 avg60=0.00 avg300=0.00 total=0\n";
        assert_eq!(parse_pressure(text), Some(81.73));
        assert_eq!(parse_pressure("full avg10=1.00\n"), None);
        assert_eq!(parse_pressure(""), None);
    }

    #[test]
    fn at_most_all_cores_but_one_poll() {
        let most =
            std::thread::available_parallelism().map_or(1, |n| n.get().saturating_sub(1).max(1));
        let slots: Vec<_> = std::iter::from_fn(PollerSlot::take)
            .take(most + 5)
            .collect();
        // Other tests of this process may hold slots too: never more than `most` in all.
        assert!(slots.len() <= most);
    }
}
