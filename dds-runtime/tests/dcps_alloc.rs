//! Allocations per sample in the steady state of the DCPS write and read paths, counted by a global
//! allocator: the writing thread (write: encode, history, datagram), the receive threads (decode, reader
//! cache) and the taking thread (take), for a fixed-size type over loopback between two participants.
mod dcps_util;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::time::Duration;

use dcps_util::*;
use dds_runtime::prelude::*;

struct Counting;

static TOTAL: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    static MINE: Cell<usize> = const { Cell::new(0) };
}

fn count() {
    TOTAL.fetch_add(1, Ordering::Relaxed);
    let _ = MINE.try_with(|c| c.set(c.get() + 1));
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(p, l, n) }
    }
}

#[global_allocator]
static A: Counting = Counting;

#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "test::Fixed", final)]
struct Fixed {
    seq: u64,
    data: [u8; 32],
}

/// Allocations per sample over one window of writes.
#[derive(Debug, Clone, Copy)]
struct Window {
    /// On the writing thread.
    write: f64,
    /// In the whole process (receive, timer and taking threads included).
    total: f64,
    /// The window began once the taker had let the writer get `lag` samples ahead (at depth).
    deep: bool,
}

/// What [`run`] measured: each window's figures and the taking thread's over the whole run.
struct Measured {
    windows: Vec<Window>,
    take: f64,
}

impl Measured {
    /// The quietest window's figures among those at depth: periodic work (heartbeats, SPDP, repair
    /// rounds) and the noise of a loaded machine land in some windows, not in all.
    fn least(&self) -> Window {
        let min = |f: fn(&Window) -> f64| {
            let deep = self.windows.iter().filter(|w| w.deep);
            deep.map(f).fold(f64::INFINITY, f64::min)
        };
        Window {
            write: min(|w| w.write),
            total: min(|w| w.total),
            deep: true,
        }
    }

    fn report(&self, what: &str) {
        let list = |f: fn(&Window) -> f64| {
            let v: Vec<String> = self
                .windows
                .iter()
                .map(|w| format!("{}{:.3}", if w.deep { "" } else { "~" }, f(w)))
                .collect();
            v.join(" ")
        };
        eprintln!(
            "{what}, allocations per sample by window: write path {}, whole process {}; take {:.3}",
            list(|w| w.write),
            list(|w| w.total),
            self.take
        );
    }
}

/// Writes `n` samples while another thread takes them in batches, and counts allocations per sample in
/// `windows` windows of `n / windows` writes each (on the writing thread and in the whole process), and
/// on the taking thread over the whole run. A window that begins before the writer got `lag` samples
/// ahead is not at depth yet (the reader's cache is filling); `report` marks it with `~`.
/// With `owned`, each sample goes through `write_owned` (a hand-over, no serialization) instead of `write`.
/// The taker lets the writer get `lag` samples ahead before it takes (0: it takes whatever is there).
fn run(
    w: &DataWriter<Fixed>,
    r: &DataReader<Fixed>,
    first: u64,
    n: u64,
    owned: bool,
    lag: u64,
    windows: u64,
) -> Measured {
    let written = AtomicU64::new(first);
    let per_window = n / windows.max(1);
    let (windows, taker) = std::thread::scope(|s| {
        let t = s.spawn(|| {
            let before = MINE.with(Cell::get);
            let mut expect = first;
            // The take's result vector is the caller's, reused (`take_into`).
            let mut batch = Vec::with_capacity(16_384);
            while expect < first + n {
                let ahead = |e: u64| {
                    let w = written.load(Ordering::Relaxed);
                    w >= e + lag || w == first + n
                };
                while !ahead(expect) {
                    std::thread::sleep(Duration::from_micros(200));
                }
                if !r.wait_for_data(Duration::from_secs(5)).unwrap() {
                    panic!("no data after {expect}");
                }
                batch.clear();
                r.take_into(&mut batch).unwrap();
                for smp in &batch {
                    assert_eq!(smp.data.as_ref().map(|d| d.seq), Some(expect));
                    expect += 1;
                }
            }
            MINE.with(Cell::get) - before
        });
        let mut windows = Vec::new();
        let mut mark = (MINE.with(Cell::get), TOTAL.load(Ordering::Relaxed));
        let mut start = first;
        let mut sample = Fixed::default();
        for seq in first..first + n {
            sample.seq = seq;
            if owned {
                w.write_owned(sample.clone()).unwrap();
            } else {
                w.write(&sample).unwrap();
            }
            written.store(seq + 1, Ordering::Relaxed);
            if (seq + 1 - first).is_multiple_of(per_window) {
                let now = (MINE.with(Cell::get), TOTAL.load(Ordering::Relaxed));
                windows.push(Window {
                    write: (now.0 - mark.0) as f64 / per_window as f64,
                    total: (now.1 - mark.1) as f64 / per_window as f64,
                    deep: start >= first + lag,
                });
                mark = now;
                start = seq + 1;
            }
        }
        (windows, t.join().unwrap())
    });
    Measured {
        windows,
        take: taker as f64 / n as f64,
    }
}

/// A reliable KEEP_ALL writer and reader of `Fixed` on `topic` in the two participants, matched, both
/// limited to `depth` samples; the writer blocks up to 10 s when its history is full.
fn kept_full(
    (p1, p2): (DomainParticipant, DomainParticipant),
    topic: &str,
    depth: u32,
) -> (
    (DomainParticipant, DomainParticipant),
    DataWriter<Fixed>,
    DataReader<Fixed>,
) {
    let (mut wq, mut rq) = reliable_keep_all_blocking(Duration::from_secs(10));
    wq.resource_limits.max_samples = Some(depth);
    rq.resource_limits.max_samples = Some(depth);
    let (w, r) = matched::<Fixed>(&p1, &p2, topic, &wq, &rq);
    ((p1, p2), w, r)
}

/// A participant of `domain` that announces itself (SPDP) at the default period of a second rather than the
/// tests' 200 ms: decoding a received announcement allocates, and five a second would be a tenth of what
/// this test measures.
fn announcing_every_second(domain: u32) -> DomainParticipant {
    require_netns();
    DomainParticipant::builder()
        .domain_id(domain)
        .interface("lo")
        .spdp_interval(Duration::from_secs(1))
        .build()
        .expect("participant")
}

/// Writes `n` samples (seq 0..n) with nobody taking, then takes them all.
fn write_then_take(w: &DataWriter<Fixed>, r: &DataReader<Fixed>, n: u64) {
    let mut sample = Fixed::default();
    for seq in 0..n {
        sample.seq = seq;
        w.write(&sample).unwrap();
    }
    let mut got = 0;
    while got < n {
        assert!(r.wait_for_data(Duration::from_secs(5)).unwrap());
        got += r.take().unwrap().len() as u64;
    }
}

#[test]
fn steady_state_allocations_per_sample() {
    let (_ps, w, r) = kept_full((participant(83), participant(83)), "Alloc", 2000);
    // Warm-up: buffers, pools and maps reach their working sizes. The writer's payload pool grows to the
    // most samples the writer has had in flight (up to its history's 2000): with nobody taking, the reader's
    // cache fills (2000) and then holds back its acknowledgements, so the writer's history fills too.
    let filled = 3900;
    write_then_take(&w, &r, filled);
    run(&w, &r, filled, 10_000, false, 0, 1);
    let m = run(&w, &r, filled + 10_000, 20_000, false, 0, 4);
    m.report("2 000 deep");
    let (Window { write, total, .. }, take) = (m.least(), m.take);
    // Zero per sample in the steady state (measured: write 0.000-0.010, take 0.000, whole process
    // 0.006-0.021 over one window of 20 000; the quietest of four windows of 5 000: 0.001): payloads come from the writer's and the receive path's buffer pools, the writer's history is a ring of slots,
    // the driver, the receive loop and the cache keep their working vectors, and `take_into` fills the
    // caller's vector. What is left is periodic (heartbeats, SPDP, an ACKNACK per timer round), not per
    // sample, and the pool's growth when the writer gets further ahead than ever before (at most to its
    // history). The bounds leave room for that and for the noise of a shared machine.
    assert!(
        write < 0.02,
        "write path: {write:.3} allocations per sample"
    );
    assert!(take < 0.001, "take: {take:.4} allocations per sample");
    assert!(
        total < 0.05,
        "whole process: {total:.3} allocations per sample"
    );
}

/// `write_owned` to a reader of the same participant: the sample is handed over (moved into the reader's
/// cache, no serialization, no decode, no datagram); the one allocation per sample is the hand-over box.
#[test]
fn intra_process_write_owned_allocations_per_sample() {
    let p = participant(84);
    let (wq, rq) = reliable_keep_all_blocking(Duration::from_secs(10));
    let (w, r) = matched::<Fixed>(&p, &p, "AllocLocal", &wq, &rq);
    run(&w, &r, 0, 10_000, true, 0, 1);
    let m = run(&w, &r, 10_000, 20_000, true, 0, 4);
    m.report("write_owned");
    let (Window { write, total, .. }, take) = (m.least(), m.take);
    assert!(
        write < 1.02,
        "write_owned path: {write:.3} allocations per sample"
    );
    assert!(take < 0.001, "take: {take:.4} allocations per sample");
    assert!(
        total < 1.05,
        "whole process: {total:.3} allocations per sample"
    );
}

/// Zero allocation per sample on the write path also with 10 000 samples in flight, more than the writer's
/// payload pool kept before (4096 buffers): KEEP_ALL, histories of 10 000 on both sides, and a taker that
/// lets the writer get 16 000 samples ahead (the reader's cache full, at least 6 000 unacknowledged in the
/// writer's history). The pool keeps the buffers it grew to; before, it forgot the oldest, still held, and
/// allocated two blocks for every write (measured 1.94 per write; now 0.000 to 0.100, repair work that the
/// writing thread runs for the core).
///
/// The whole process is near zero too. The reader, its cache full, keeps asking for samples again; the
/// writer's requested sequence numbers were a `BTreeSet` that grew with each request and was rebuilt
/// (`split_off`) on every acknowledgement: 4.7 to 6.4 allocations per sample. They are a bitmap window
/// now (`writer/bit_window.rs`), kept while the reader is behind: 0.14 to 0.29. Most of the rest was the
/// reader's: the changes it holds out of order (the ones after the change its full cache refused), copied
/// out of their datagrams into pooled buffers (`rtps/reader/reorder.rs`). The pool kept 1024 buffers, fewer
/// than the changes held and then cached at depth: beyond them, two allocations per change held (windows of
/// 1 to 10 per sample under load, session 25); it keeps up to 32 768 now, and the changes are held in a ring
/// by sequence number instead of a map that allocated a node every few. What is left at depth: the writer's
/// repair datagrams beyond the buffers its outbox keeps (a round that resends thousands of samples at
/// once, under load: windows of 5 to 15 per sample), a pool growing to a depth it never had, a received
/// SPDP announcement's decode, the timer thread's list of endpoints.
///
/// The test takes the quietest of five windows of 6 000 at depth; on a loaded machine a repair round can
/// land in all five, so a pass over the bounds is measured again, up to three passes. A per-sample
/// allocation fails all three.
#[test]
fn steady_state_allocations_with_10000_samples_in_flight() {
    const DEPTH: u32 = 10_000;
    // The taker waits until the writer is this far ahead: the reader's cache is full (10 000) and the
    // writer holds at least 6 000 unacknowledged samples in its history, well past the pool's 4096.
    const LAG: u64 = 16_000;
    const PASS: u64 = 48_000;
    let (_ps, w, r) = kept_full(
        (announcing_every_second(49), announcing_every_second(49)),
        "AllocDeep",
        DEPTH,
    );
    // Warm-up: the reader's cache (10 000) and the writer's history (up to the 512 KiB window, about 11 900
    // samples of 44 bytes) fill; pools and maps reach their working sizes.
    let filled = 19_000;
    write_then_take(&w, &r, filled);
    run(&w, &r, filled, 20_000, false, LAG, 1);
    let mut failed = String::new();
    for pass in 0..3 {
        let m = run(&w, &r, filled + 20_000 + pass * PASS, PASS, false, LAG, 8);
        m.report("10 000 in flight");
        let (Window { write, total, .. }, take) = (m.least(), m.take);
        // The writing thread's quietest window: 0.000 (a window in which the writer's pool grows to a
        // depth it never had before takes three allocations per new buffer, up to 0.38). The whole
        // process's: 0.000 to 0.012 (session 25, ten runs beside a release build).
        failed.clear();
        if write >= 0.02 {
            failed += &format!("write path: {write:.3} allocations per sample; ");
        }
        if take >= 0.001 {
            failed += &format!("take: {take:.4} allocations per sample; ");
        }
        if total >= 0.1 {
            failed += &format!("whole process: {total:.3} allocations per sample; ");
        }
        if failed.is_empty() {
            return;
        }
    }
    panic!("three passes over the bounds, the last: {failed}");
}

#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "test::Named", appendable)]
struct Named {
    seq: u64,
    name: String,
    data: Vec<u8>,
}

/// Writes `n` samples of `Named` from `first` on while another thread takes them (`take_into`), and gives
/// them back to the reader (`DataReader::recycle`) with `recycle`; allocations per sample in the whole
/// process, in each of `windows` windows of `n / windows` writes.
fn named_run(
    w: &DataWriter<Named>,
    r: &DataReader<Named>,
    first: u64,
    n: u64,
    recycle: bool,
    windows: u64,
) -> Vec<f64> {
    let mut sample = Named {
        seq: 0,
        name: "a name that needs a buffer of its own".into(),
        data: vec![7; 100],
    };
    let expected = sample.clone();
    // The writer stays at most this far ahead of the taker: the reader keeps up to 1 024 values given
    // back, so a taker further behind (a loaded machine) would have more samples decoded than values kept.
    const AHEAD: u64 = 512;
    let taken = AtomicU64::new(first);
    let per_window = n / windows.max(1);
    let mut rates = Vec::new();
    std::thread::scope(|s| {
        let taken = &taken;
        s.spawn(move || {
            let mut batch = Vec::with_capacity(16_384);
            let mut next = first;
            while next < first + n {
                assert!(
                    r.wait_for_data(Duration::from_secs(5)).unwrap(),
                    "no data after {next}"
                );
                r.take_into(&mut batch).unwrap();
                for smp in &batch {
                    let d = smp.data.as_ref().expect("data");
                    assert_eq!(
                        (d.seq, &d.name, &d.data),
                        (next, &expected.name, &expected.data)
                    );
                    next += 1;
                }
                if recycle {
                    r.recycle(batch.drain(..));
                } else {
                    batch.clear();
                }
                // Only once the batch is given back: a writer let go on before would have samples decoded
                // while the values the reader keeps are still in the taker's hands.
                taken.store(next, Ordering::Relaxed);
            }
        });
        // A window is counted once the taker has taken its last sample: each of them has been decoded by
        // then.
        let mut mark = TOTAL.load(Ordering::Relaxed);
        for seq in first..first + n {
            while seq >= taken.load(Ordering::Relaxed) + AHEAD {
                std::thread::sleep(Duration::from_micros(50));
            }
            sample.seq = seq;
            w.write(&sample).unwrap();
            if (seq + 1 - first).is_multiple_of(per_window) {
                while taken.load(Ordering::Relaxed) <= seq {
                    std::thread::sleep(Duration::from_micros(50));
                }
                let now = TOTAL.load(Ordering::Relaxed);
                rates.push((now - mark) as f64 / per_window as f64);
                mark = now;
            }
        }
    });
    rates
}

/// A type with a string and a sequence: each sample a reader decodes needs two buffers. A taker that gives
/// its samples back (`DataReader::recycle`) has them decoded into its old ones, and the read path allocates
/// nothing per sample; one that does not pays two allocations per sample. Each run is counted in five
/// windows and the quietest is compared: on a loaded machine the acknowledgements lag and the writer's
/// buffer pool grows to its new peak in flight (an allocation per buffer added, once), in some windows.
#[test]
fn recycled_samples_are_decoded_into_without_allocating() {
    let (p1, p2) = (announcing_every_second(126), announcing_every_second(126));
    let (wq, rq) = reliable_keep_all_blocking(Duration::from_secs(10));
    let (w, r) = matched::<Named>(&p1, &p2, "AllocNamed", &wq, &rq);
    named_run(&w, &r, 0, 5_000, true, 1);
    let recycled = named_run(&w, &r, 5_000, 10_000, true, 5);
    let fresh = named_run(&w, &r, 15_000, 10_000, false, 5);
    let show = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:.3}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    eprintln!(
        "allocations per sample by window: recycled {}, fresh {}",
        show(&recycled),
        show(&fresh)
    );
    let least = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
    // Fresh: two per sample, but the first window decodes into the values kept from the recycled run (up to
    // 1 024) first.
    let (recycled, fresh) = (least(&recycled), least(&fresh[1..]));
    assert!(
        fresh >= 1.5,
        "fresh values: {fresh:.3} allocations per sample"
    );
    assert!(
        recycled < 0.1,
        "recycled values: {recycled:.3} allocations per sample"
    );
}

/// A sample of 64 KiB: it leaves in fragments, each sent in pieces gathered from the sample's own buffer.
#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "test::Big", final)]
struct Big {
    seq: u64,
    data: Vec<u8>,
}

/// The pieces of a run of fragments are gathered on the stack (`transport::with_run_pieces`), and the
/// HEARTBEAT_FRAG after a fragmented sample borrows its destination list: writing 64 KiB samples allocates
/// nothing per sample on the writing thread once pools have grown. Before, each run of fragments collected
/// its pieces in a new `Vec` and the destination list was copied: 2.000 allocations per sample (1.000 each).
#[test]
fn fragmented_writes_allocate_nothing_per_sample() {
    let (p1, p2) = (participant(63), participant(63));
    let (wq, rq) = reliable_keep_all_blocking(Duration::from_secs(10));
    let (w, r) = matched::<Big>(&p1, &p2, "AllocBig", &wq, &rq);
    let mut sample = Big {
        seq: 0,
        data: vec![0x5a; 64 * 1024],
    };
    // Writes `n` samples from `first` while another thread takes them; the writing thread's allocations
    // per sample.
    let mut window = |first: u64, n: u64| -> f64 {
        std::thread::scope(|s| {
            s.spawn(|| {
                let mut expect = first;
                while expect < first + n {
                    assert!(r.wait_for_data(Duration::from_secs(5)).unwrap(), "no data");
                    for smp in r.take().unwrap() {
                        assert_eq!(smp.data.map(|d| d.seq), Some(expect));
                        expect += 1;
                    }
                }
            });
            let before = MINE.with(Cell::get);
            for seq in first..first + n {
                sample.seq = seq;
                w.write(&sample).unwrap();
            }
            (MINE.with(Cell::get) - before) as f64 / n as f64
        })
    };
    window(0, 500);
    let per_sample = (0..3).map(|i| window(500 + i * 500, 500));
    let least = per_sample.fold(f64::INFINITY, f64::min);
    eprintln!(
        "64 KiB writes: {least:.3} allocations per sample (quietest of three windows of 500)"
    );
    assert!(least < 0.05, "{least:.3} allocations per 64 KiB write");
}

/// A pair on shared memory (feature `shm`, two participants of this process with `Config::shm` on): the
/// writer's frames, the reader's holders of the frames it reads, its acknowledgements and the decode into
/// given-back samples reuse what they had: writing and taking allocates nothing per sample in the whole
/// process. Before session 25, five allocations per sample (a holder per frame, a node name per change,
/// the vectors of each drain pass and each flush, the acknowledging node's name).
#[cfg(feature = "shm")]
#[test]
fn a_shared_memory_pair_writes_and_takes_without_allocating() {
    require_netns();
    let shm = || {
        DomainParticipant::builder()
            .config(dds_runtime::config::Config {
                domain_id: 109,
                interface: dds_runtime::config::InterfaceSelection::Name("lo".into()),
                spdp_interval: Duration::from_secs(1),
                shm: true,
                ..dds_runtime::config::Config::default()
            })
            .build()
            .expect("participant")
    };
    let (p1, p2) = (shm(), shm());
    let (wq, rq) = reliable_keep_all_blocking(Duration::from_secs(10));
    let (w, r) = matched::<Named>(&p1, &p2, "AllocShm", &wq, &rq);
    named_run(&w, &r, 0, 5_000, true, 1);
    let sent = || p1.transport_stats().sent.load(Ordering::Relaxed);
    let before = sent();
    // The quietest of three windows: what is left is periodic (SPDP, the timer thread), and a loaded
    // machine stretches a window over more of it.
    let windows = named_run(&w, &r, 5_000, 15_000, true, 3);
    let per_sample = windows.iter().copied().fold(f64::INFINITY, f64::min);
    let datagrams = sent() - before;
    eprintln!(
        "shared-memory pair: {windows:.3?} allocations per sample by window of 5 000, {datagrams} datagrams for 15 000 samples"
    );
    // Over UDP each sample would take a datagram; SPDP and SEDP send a few.
    assert!(
        datagrams < 100,
        "{datagrams} datagrams: the pair is not on shared memory"
    );
    assert!(
        per_sample < 0.1,
        "shared-memory pair: {per_sample:.3} allocations per sample"
    );
}

/// Two idle participants, discovered, announcing themselves (SPDP) every 100 ms: what the process allocates
/// per second when nothing is written. A received re-announcement of a known participant is recognised by
/// a digest of its bytes before it is decoded, the periodic announcement goes to a kept list of
/// destinations, and the driver's timer thread ticks its endpoints from a kept vector: what is left is
/// work that is not per period (the once-per-SPDP-period trims give back nothing once settled).
#[test]
fn idle_participants_allocate_nothing_per_announcement() {
    require_netns();
    let quick = || {
        DomainParticipant::builder()
            .domain_id(120)
            .interface("lo")
            .spdp_interval(Duration::from_millis(100))
            .lease_duration(Duration::from_secs(5))
            .build()
            .expect("participant")
    };
    let (p1, p2) = (quick(), quick());
    assert!(
        wait_until(Duration::from_secs(10), || {
            p1.discovered_participants().len() == 1 && p2.discovered_participants().len() == 1
        }),
        "the participants did not discover each other"
    );
    // Settle: the SEDP exchange, the first trims, the queues' working sizes.
    std::thread::sleep(Duration::from_secs(2));
    let window = Duration::from_secs(3);
    // Three windows of 30 announcement periods; the quietest counts (a loaded machine's late timers land
    // in some windows, not in all).
    let counts: Vec<usize> = (0..3)
        .map(|_| {
            let before = TOTAL.load(Ordering::Relaxed);
            std::thread::sleep(window);
            TOTAL.load(Ordering::Relaxed) - before
        })
        .collect();
    let least = counts.iter().copied().min().unwrap();
    let periods = window.as_millis() / 100;
    eprintln!(
        "two idle participants: {counts:?} allocations per window of {periods} SPDP periods \
         (each participant sends one announcement and receives two, its own and its peer's, per period)"
    );
    // Measured: 0 in each window (session 26); before it, 1 683-1 740 per window, about 28 per period (the
    // decode of each received announcement, its re-encoding for the comparison, the destination list of
    // each sent one, the timer thread's vector of endpoints per tick). The bound, 10 in 30 periods (one in
    // three), fails on any allocation per announcement and leaves room for rare work that is not per
    // period.
    assert!(
        least <= periods as usize / 3,
        "{least} allocations in {periods} SPDP periods of two idle participants"
    );
    drop((p1, p2));
}
