//! Shared memory through the DCPS API (feature `shm`, run inside `scripts/isolated`): a writer's readers in
//! participants on this host that can use shared memory get its samples through the writer's channel, not
//! as datagrams; a participant without it (shared memory off) gets the same writer's samples over UDP; a
//! writer process killed with `SIGKILL` leaks nothing and a new writer works after it. The second process
//! is this test binary run again with `DCPS_SHM_ROLE` set (see `child`). Plain-data samples written in
//! place through `DataWriter::loan` (or `loan_unzeroed`) and read in place (`InPlace`); loans held by the
//! user leave a buffer for the writer's ordinary writes; a durable reader that joins a writer whose channel its participant
//! already reads gets the history before the live samples.
mod dcps_util;

use std::io::{BufRead, BufReader, Write};
use std::process::{Child, ChildStdout, Command, Stdio};
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use dcps_util::*;
use dds_runtime::dcps::{InPlace, LoanError};
use dds_runtime::prelude::*;
use dds_runtime::rtps::shm::SHM_NODE_PROPERTY;
use dds_runtime::transport::shm::{node_status, remove_dead_nodes, NodeStatus};

const KIB: usize = 1024;

/// The byte at `i` of blob `id`.
fn pattern(id: u32, i: usize) -> u8 {
    (id as usize)
        .wrapping_mul(31)
        .wrapping_add(i.wrapping_mul(7)) as u8
}

fn blob(id: u32, len: usize) -> Blob {
    Blob {
        id,
        data: (0..len).map(|i| pattern(id, i)).collect(),
    }
}

fn intact(b: &Blob) -> bool {
    b.data
        .iter()
        .enumerate()
        .all(|(i, x)| *x == pattern(b.id, i))
}

/// Takes blobs until `n` arrived or `timeout` passed; panics on a damaged one. Their ids, in order.
fn take_blobs(r: &DataReader<Blob>, n: usize, timeout: Duration) -> Vec<u32> {
    let mut ids = Vec::new();
    wait_until(timeout, || {
        for s in r.take().unwrap() {
            if let Some(b) = s.data {
                assert!(intact(&b), "blob {} damaged", b.id);
                ids.push(b.id);
            }
        }
        ids.len() >= n
    });
    ids
}

fn sent(p: &DomainParticipant) -> u64 {
    p.transport_stats().sent.load(Ordering::Relaxed)
}

fn no_shm() -> Config {
    Config {
        interface: dds_runtime::config::InterfaceSelection::Name("lo".into()),
        shm: false,
        ..Config::default()
    }
}

fn with_shm() -> Config {
    Config {
        shm: true,
        ..no_shm()
    }
}

fn wait_matched<T: DdsType>(w: &DataWriter<T>, n: u32) {
    assert!(
        wait_until(MATCH_TIMEOUT, || w
            .publication_matched_status()
            .current_count
            == n),
        "writer matched {:?}, wanted {n}",
        w.publication_matched_status()
    );
}

#[test]
fn peers_on_shared_memory_get_no_datagram_and_a_peer_without_it_gets_udp() {
    let p = participant_with(111, with_shm());
    let near = participant_with(111, with_shm());
    let (wq, rq) = reliable_keep_all();
    let (w, r) = matched::<Blob>(&p, &near, "ShmMixed", &wq, &rq);
    let n = 200u32;
    let before = sent(&p);
    for id in 0..n {
        w.write(&blob(id, 16 * KIB)).unwrap();
    }
    assert_eq!(
        take_blobs(&r, n as usize, MATCH_TIMEOUT),
        (0..n).collect::<Vec<_>>()
    );
    // 200 samples of 16 KiB would be about 2600 fragments over UDP; SPDP may send a few datagrams.
    let during = sent(&p) - before;
    assert!(
        during < 20,
        "{during} datagrams sent for {n} samples on shared memory"
    );

    // A participant without shared memory: the same writer reaches it over UDP, the other one still not.
    let far = participant_with(111, no_shm());
    let fr = reader::<Blob>(&far, "ShmMixed", &rq);
    wait_matched(&w, 2);
    let before = sent(&p);
    for id in n..2 * n {
        w.write(&blob(id, 16 * KIB)).unwrap();
    }
    let want: Vec<u32> = (n..2 * n).collect();
    assert_eq!(take_blobs(&r, n as usize, MATCH_TIMEOUT), want);
    assert_eq!(take_blobs(&fr, n as usize, MATCH_TIMEOUT), want);
    let during = sent(&p) - before;
    // Over UDP each 16 KiB sample takes at least one datagram (fragments are packed together).
    assert!(
        during >= u64::from(n),
        "{during} datagrams: the UDP reader gets its samples over UDP"
    );
    w.wait_for_acknowledgments(Duration::from_secs(5)).unwrap();
}

#[test]
fn instance_states_history_and_late_joiners_over_shared_memory() {
    let p = participant_with(112, with_shm());
    let q = participant_with(112, with_shm());
    let wq = DataWriterQos::builder()
        .reliability(reliable())
        .durability(Durability::TransientLocal)
        .history(History::KeepLast(2))
        .build();
    let rq = DataReaderQos::builder()
        .reliability(reliable())
        .durability(Durability::TransientLocal)
        .history(History::KeepLast(2))
        .build();
    let w = writer::<Blob>(&p, "ShmStates", &wq);
    for id in 0..3 {
        for v in 0..3 {
            w.write(&Blob { id, data: vec![v] }).unwrap();
        }
    }
    // A durable late joiner gets the writer's history (the last two of each instance).
    let r = reader::<Blob>(&q, "ShmStates", &rq);
    wait_matched(&w, 1);
    let mut got = Vec::new();
    wait_until(MATCH_TIMEOUT, || {
        got.extend(r.read().unwrap());
        got.len() >= 6
    });
    let mut vals: Vec<(u32, u8)> = got
        .iter()
        .filter_map(|s| s.data.as_ref().map(|b| (b.id, b.data[0])))
        .collect();
    vals.sort();
    assert_eq!(vals, vec![(0, 1), (0, 2), (1, 1), (1, 2), (2, 1), (2, 2)]);
    // Dispose reaches the reader's instance state.
    w.dispose(&Blob {
        id: 1,
        data: vec![],
    })
    .unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || {
        r.read()
            .unwrap()
            .iter()
            .any(|s| s.info.instance_state == InstanceState::NotAliveDisposed && !s.info.valid_data)
    }));
    // The readers of the writer are the one on shared memory.
    assert_eq!(w.matched_subscription_guids().len(), 1);
    assert_eq!(r.matched_publications().len(), 1);
}

/// Runs this binary's `child` test as a second process in `role`; `vars` go to its environment.
fn spawn(role: &str, vars: &[(&str, String)]) -> (Child, BufReader<ChildStdout>) {
    let mut cmd = Command::new(std::env::current_exe().unwrap());
    cmd.args(["child", "--exact", "--nocapture", "--test-threads=1"])
        .env("DCPS_SHM_ROLE", role)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped());
    for (k, v) in vars {
        cmd.env(k, v);
    }
    let mut child = cmd.spawn().unwrap();
    let out = BufReader::new(child.stdout.take().unwrap());
    (child, out)
}

/// The rest of the first line from the child that contains `want` (libtest may print before it).
fn wait_line(out: &mut BufReader<ChildStdout>, want: &str) -> String {
    let mut line = String::new();
    loop {
        line.clear();
        assert!(
            out.read_line(&mut line).unwrap() > 0,
            "child ended before {want:?}"
        );
        if let Some(i) = line.find(want) {
            return line[i + want.len()..].trim().to_owned();
        }
    }
}

fn env_num(name: &str) -> usize {
    std::env::var(name).unwrap().parse().unwrap()
}

/// The second process. `reader`: takes COUNT blobs from the topic, checks them, prints "got" and their
/// ids, and waits for its stdin to close. `writer`: writes COUNT blobs of SIZE bytes from FIRST on (COUNT 0: until killed), prints
/// "writing" after the first; waits for its stdin to close.
#[test]
fn child() {
    let Ok(role) = std::env::var("DCPS_SHM_ROLE") else {
        return;
    };
    let domain = env_num("DCPS_SHM_DOMAIN") as u32;
    let topic = std::env::var("DCPS_SHM_TOPIC").unwrap();
    let count = env_num("DCPS_SHM_COUNT");
    let p = participant_with(domain, with_shm());
    let (wq, rq) = reliable_keep_all();
    if role == "reader" {
        let r = reader::<Blob>(&p, &topic, &rq);
        println!("ready");
        let ids = take_blobs(&r, count, Duration::from_secs(30));
        println!("got {ids:?}");
        std::io::stdout().flush().unwrap();
        let mut s = String::new();
        let _ = std::io::stdin().read_line(&mut s);
        return;
    }
    let size = env_num("DCPS_SHM_SIZE");
    let first = env_num("DCPS_SHM_FIRST") as u32;
    let w = writer::<Blob>(&p, &topic, &wq);
    wait_matched(&w, 1);
    let mut id = first;
    loop {
        w.write(&blob(id, size)).unwrap();
        if id == first {
            println!("writing");
            std::io::stdout().flush().unwrap();
        }
        id += 1;
        if count > 0 && id as usize == first as usize + count {
            break;
        }
    }
    println!("written");
    let mut s = String::new();
    let _ = std::io::stdin().read_line(&mut s);
}

#[test]
fn mixed_readers_in_two_processes_get_every_sample_intact_and_in_order() {
    let p = participant_with(113, with_shm());
    let far = participant_with(113, no_shm());
    let (wq, rq) = reliable_keep_all();
    let w = writer::<Blob>(&p, "ShmTwo", &wq);
    let n = 40usize;
    let vars = [
        ("DCPS_SHM_DOMAIN", "113".to_owned()),
        ("DCPS_SHM_TOPIC", "ShmTwo".to_owned()),
        ("DCPS_SHM_COUNT", n.to_string()),
    ];
    let (mut child, mut out) = spawn("reader", &vars);
    wait_line(&mut out, "ready");
    let fr = reader::<Blob>(&far, "ShmTwo", &rq);
    wait_matched(&w, 2);
    // The child's reader is on shared memory: its participant announced a node, and matched ours.
    for id in 0..n as u32 {
        w.write(&blob(id, 256 * KIB)).unwrap();
    }
    let want: Vec<u32> = (0..n as u32).collect();
    assert_eq!(take_blobs(&fr, n, MATCH_TIMEOUT), want);
    assert_eq!(wait_line(&mut out, "got "), format!("{want:?}"));
    drop(child.stdin.take());
    assert!(child.wait().unwrap().success());
}

/// The shared-memory node a discovered participant announced.
fn peer_node(p: &DomainParticipant, not: &[GuidPrefix]) -> Option<String> {
    p.discovered_participants()
        .into_iter()
        .filter(|d| !not.contains(&d.guid_prefix))
        .find_map(|d| {
            p.get_discovered_participant_data(d.handle)
                .ok()?
                .property(SHM_NODE_PROPERTY)
                .map(str::to_owned)
        })
}

#[test]
fn killed_writer_process_leaks_nothing_and_a_new_writer_works() {
    let p = participant_with(114, with_shm());
    let (_, rq) = reliable_keep_all();
    let r = reader::<Blob>(&p, "ShmKill", &rq);
    let vars = |first: u32, count: usize| {
        [
            ("DCPS_SHM_DOMAIN", "114".to_owned()),
            ("DCPS_SHM_TOPIC", "ShmKill".to_owned()),
            ("DCPS_SHM_COUNT", count.to_string()),
            ("DCPS_SHM_SIZE", (1024 * KIB).to_string()),
            ("DCPS_SHM_FIRST", first.to_string()),
        ]
    };
    // A writer of 1 MiB samples, killed while it writes (it holds a loan for most of each write).
    let (mut killed, mut out) = spawn("writer", &vars(0, 0));
    wait_line(&mut out, "writing");
    let ids = take_blobs(&r, 5, MATCH_TIMEOUT);
    assert_eq!(ids, (0..ids.len() as u32).collect::<Vec<_>>());
    let node = peer_node(&p, &[]).expect("the writer announced its node");
    killed.kill().unwrap(); // SIGKILL
    killed.wait().unwrap();
    // What it had sent is intact (take_blobs checks every byte) and in order.
    let rest = take_blobs(&r, usize::MAX, Duration::from_millis(500));
    let last = rest.last().copied().unwrap_or(ids[ids.len() - 1]);
    let all: Vec<u32> = ids.iter().chain(&rest).copied().collect();
    assert_eq!(all, (0..=last).collect::<Vec<_>>());
    // Its dead node is removed (by us or by whoever looked first), with its segments and loans.
    let end = Instant::now() + MATCH_TIMEOUT;
    while node_status(&node) != NodeStatus::Absent {
        remove_dead_nodes();
        assert!(Instant::now() < end, "dead node {node} still listed");
        std::thread::sleep(Duration::from_millis(50));
    }
    // A new writer process on the same topic works.
    let (mut next, mut out) = spawn("writer", &vars(1000, 20));
    wait_line(&mut out, "written");
    let ids = take_blobs(&r, 20, MATCH_TIMEOUT);
    assert_eq!(ids, (1000..1020).collect::<Vec<_>>());
    drop(next.stdin.take());
    assert!(next.wait().unwrap().success());
}

/// Deleting a writer waits for its shared-memory readers to acknowledge what it sent, but not for a
/// reader whose process was killed (its node is dead): with `connected`, the reader was killed after it
/// had taken a sample (the deletion's wait for acknowledgements), else right after matching (the first
/// send's wait for the reader to connect).
fn delete_writer_after_its_reader_is_killed(domain: u32, topic: &str, connected: bool) {
    let p = participant_with(domain, with_shm());
    let (wq, _) = reliable_keep_all();
    let w = writer::<Blob>(&p, topic, &wq);
    let taken = if connected { 1 } else { 1000 };
    let vars = [
        ("DCPS_SHM_DOMAIN", domain.to_string()),
        ("DCPS_SHM_TOPIC", topic.to_owned()),
        ("DCPS_SHM_COUNT", taken.to_string()),
    ];
    let (mut child, mut out) = spawn("reader", &vars);
    wait_line(&mut out, "ready");
    wait_matched(&w, 1);
    let node = peer_node(&p, &[]).expect("the reader announced its node");
    w.write(&blob(0, 4 * KIB)).unwrap();
    if connected {
        assert_eq!(wait_line(&mut out, "got "), "[0]");
    }
    child.kill().unwrap(); // SIGKILL: the reader acknowledges nothing that follows
    child.wait().unwrap();
    // Dead, or already removed by a cleanup in a test beside this one.
    assert!(matches!(
        node_status(&node),
        NodeStatus::Dead | NodeStatus::Absent
    ));
    // Still matched (its participant's lease has not expired): these go to its channel.
    for id in 1..4 {
        w.write(&blob(id, 4 * KIB)).unwrap();
    }
    let start = Instant::now();
    w.publisher().delete_datawriter(&w).unwrap();
    let took = start.elapsed();
    assert!(
        took < Duration::from_millis(1000),
        "deletion waited {took:?} for a dead reader"
    );
    remove_dead_nodes();
}

#[test]
fn deleting_a_writer_does_not_wait_for_a_killed_reader_to_acknowledge() {
    delete_writer_after_its_reader_is_killed(117, "ShmDeadAcks", true);
}

#[test]
fn deleting_a_writer_does_not_wait_for_a_killed_reader_to_connect() {
    delete_writer_after_its_reader_is_killed(118, "ShmDeadConnect", false);
}

/// A plain-data sample: its XCDR1 encoding is its memory image, so it can be loaned.
#[derive(DdsType, Debug, Clone, Copy, PartialEq)]
#[dds(name = "test::Plain", final)]
#[repr(C)]
struct Plain {
    #[dds(key)]
    id: u32,
    seq: u32,
    data: [u8; 4088],
}

// SAFETY: `repr(C)`, fields of plain integers with no padding between or after them (4 + 4 + 4088 bytes,
// alignment 4); every bit pattern is valid.
unsafe impl bytemuck::Zeroable for Plain {}
// SAFETY: as above.
unsafe impl bytemuck::Pod for Plain {}

/// Plain data, but a mutable type: its encoding (a parameter list) is not its memory image.
#[derive(DdsType, Debug, Clone, Copy, PartialEq)]
#[dds(name = "test::PlainMutable", mutable)]
#[repr(C)]
struct PlainMutable {
    a: u32,
    b: u32,
}

// SAFETY: `repr(C)`, two `u32`, no padding.
unsafe impl bytemuck::Zeroable for PlainMutable {}
// SAFETY: as above.
unsafe impl bytemuck::Pod for PlainMutable {}

fn fill_plain(p: &mut Plain, id: u32, seq: u32) {
    p.id = id;
    p.seq = seq;
    for (i, b) in p.data.iter_mut().enumerate() {
        *b = pattern(seq, i);
    }
}

/// Takes plain samples until `n` arrived or `timeout` passed; panics on a damaged one. Their `seq`s.
fn take_plain(r: &DataReader<Plain>, n: usize, timeout: Duration) -> Vec<u32> {
    take_checked(r, n, timeout, |p| p)
        .iter()
        .map(|p| p.seq)
        .collect()
}

/// Takes samples of `r` until `n` arrived or `timeout` passed, checking each one's pattern (`plain` views it
/// as a `Plain`); panics on a damaged one.
fn take_checked<S: DdsType>(
    r: &DataReader<S>,
    n: usize,
    timeout: Duration,
    plain: fn(&S) -> &Plain,
) -> Vec<S> {
    let mut got = Vec::new();
    wait_until(timeout, || {
        for s in r.take().unwrap() {
            if let Some(d) = s.data {
                let p = plain(&d);
                let ok = p
                    .data
                    .iter()
                    .enumerate()
                    .all(|(i, x)| *x == pattern(p.seq, i));
                assert!(ok, "plain sample {} damaged", p.seq);
                got.push(d);
            }
        }
        got.len() >= n
    });
    got
}

#[test]
fn loaned_samples_reach_shared_memory_readers_in_place_and_udp_readers_from_a_copy() {
    let p = participant_with(115, with_shm());
    let near = participant_with(115, with_shm());
    let off = participant_with(115, no_shm());
    let (wq, rq) = reliable_keep_all();
    let w = writer::<Plain>(&p, "ShmLoan", &wq);
    // Typed errors, for which the caller writes as usual.
    assert!(matches!(w.loan(), Err(LoanError::NoSharedMemoryReader)));
    let ow = writer::<Plain>(&off, "ShmLoanOff", &wq);
    assert!(matches!(ow.loan(), Err(LoanError::SharedMemoryOff)));
    let mw = writer::<PlainMutable>(&p, "ShmLoanMutable", &wq);
    assert!(matches!(mw.loan(), Err(LoanError::NotPlain)));

    let r = reader::<Plain>(&near, "ShmLoan", &rq);
    wait_matched(&w, 1);
    let n = 100u32;
    let before = sent(&p);
    for seq in 0..n {
        let mut loan = w.loan().unwrap();
        fill_plain(&mut loan, seq % 3, seq);
        if seq == 7 {
            // Dropped unwritten: the buffer goes back, nothing is published.
            drop(loan);
            loan = w.loan().unwrap();
            fill_plain(&mut loan, seq % 3, seq);
        }
        loan.write().unwrap();
    }
    assert_eq!(
        take_plain(&r, n as usize, MATCH_TIMEOUT),
        (0..n).collect::<Vec<_>>()
    );
    let during = sent(&p) - before;
    assert!(
        during < 20,
        "{during} datagrams sent for {n} loaned samples"
    );

    // A reader on UDP as well: it gets the loaned samples from a copy, the other still in place.
    let fr = reader::<Plain>(&off, "ShmLoan", &rq);
    wait_matched(&w, 2);
    let before = sent(&p);
    loan_write(&w, n..2 * n);
    let want: Vec<u32> = (n..2 * n).collect();
    assert_eq!(take_plain(&r, n as usize, MATCH_TIMEOUT), want);
    assert_eq!(take_plain(&fr, n as usize, MATCH_TIMEOUT), want);
    assert!(
        sent(&p) - before >= u64::from(n),
        "the UDP reader gets datagrams"
    );
    w.wait_for_acknowledgments(Duration::from_secs(5)).unwrap();
    // The keyed instances were registered by the loaned writes.
    assert!(w
        .lookup_instance(&Plain {
            id: 2,
            seq: 0,
            data: [0; 4088]
        })
        .unwrap()
        .is_some());
}

/// Takes in-place samples until `n` arrived or `timeout` passed; panics on a damaged one. The samples,
/// kept (each holds its buffer).
fn take_in_place(
    r: &DataReader<InPlace<Plain>>,
    n: usize,
    timeout: Duration,
) -> Vec<InPlace<Plain>> {
    take_checked(r, n, timeout, |p| p)
}

fn loan_write(w: &DataWriter<Plain>, seqs: std::ops::Range<u32>) {
    for seq in seqs {
        let mut loan = w.loan().unwrap();
        fill_plain(&mut loan, seq % 3, seq);
        loan.write().unwrap();
    }
}

/// `DataWriter::loan_unzeroed` gives buffers that hold earlier frames' bytes (it does not zero them);
/// samples written whole into them reach the reader intact and in order.
#[test]
fn samples_loaned_unzeroed_and_fully_written_reach_the_reader_intact() {
    let p = participant_with(121, with_shm());
    let near = participant_with(121, with_shm());
    let (wq, rq) = reliable_keep_all();
    let w = writer::<Plain>(&p, "ShmUnzeroed", &wq);
    let r = reader::<Plain>(&near, "ShmUnzeroed", &rq);
    wait_matched(&w, 1);
    let n = 40u32;
    loan_write(&w, 0..n);
    assert_eq!(
        take_plain(&r, n as usize, MATCH_TIMEOUT),
        (0..n).collect::<Vec<_>>()
    );
    w.wait_for_acknowledgments(Duration::from_secs(5)).unwrap();
    // The buffers come back with the bytes of the samples they carried.
    let mut stale = 0;
    for seq in n..3 * n {
        let mut loan = w.loan_unzeroed().unwrap();
        if loan.data.iter().any(|b| *b != 0) {
            stale += 1;
        }
        fill_plain(&mut loan, seq % 3, seq);
        loan.write().unwrap();
    }
    assert_eq!(
        take_plain(&r, 2 * n as usize, MATCH_TIMEOUT),
        (n..3 * n).collect::<Vec<_>>()
    );
    assert!(stale > 0, "no unzeroed loan held an earlier sample's bytes");
}

/// A user holding every loan a writer lends leaves one buffer for the writer's ordinary writes: they
/// neither fail nor lose a sample, and the loans written afterwards arrive too.
#[test]
fn loans_held_by_the_user_never_starve_an_ordinary_write() {
    let p = participant_with(122, with_shm());
    let near = participant_with(122, with_shm());
    let (wq, rq) = reliable_keep_all_blocking(Duration::from_millis(300));
    let w = writer::<Plain>(&p, "ShmLoansHeld", &wq);
    let r = reader::<Plain>(&near, "ShmLoansHeld", &rq);
    wait_matched(&w, 1);
    // Loan until the writer lends no more (after its max_blocking_time).
    let mut held = Vec::new();
    while let Ok(loan) = w.loan_unzeroed() {
        held.push(loan);
        assert!(held.len() < 16, "the writer lends without limit");
    }
    assert!(!held.is_empty());
    let n = 10u32;
    for seq in 0..n {
        let mut s = Plain {
            id: 0,
            seq: 0,
            data: [0; 4088],
        };
        fill_plain(&mut s, seq % 3, seq);
        w.write(&s).unwrap();
    }
    assert_eq!(
        take_plain(&r, n as usize, MATCH_TIMEOUT),
        (0..n).collect::<Vec<_>>()
    );
    let m = n + held.len() as u32;
    for (loan, seq) in held.iter_mut().zip(n..m) {
        fill_plain(loan, seq % 3, seq);
    }
    for loan in held {
        loan.write().unwrap();
    }
    assert_eq!(
        take_plain(&r, (m - n) as usize, MATCH_TIMEOUT),
        (n..m).collect::<Vec<_>>()
    );
    w.wait_for_acknowledgments(Duration::from_secs(5)).unwrap();
}

/// A reader of `InPlace<Plain>` reads loaned samples in the writer's shared-memory buffers; a reader on
/// UDP gets the same samples. A reader that keeps more samples than its participant may hold in place
/// gets the rest as copies, and the writer never waits for it; once it drops them, samples are read in
/// place again.
#[test]
fn plain_samples_are_read_in_place_and_a_reader_keeping_them_never_stalls_the_writer() {
    let p = participant_with(221, with_shm());
    let near = participant_with(221, with_shm());
    let off = participant_with(221, no_shm());
    let (wq, rq) = reliable_keep_all();
    let w = writer::<Plain>(&p, "ShmInPlace", &wq);
    let r = reader::<InPlace<Plain>>(&near, "ShmInPlace", &rq);
    let fr = reader::<InPlace<Plain>>(&off, "ShmInPlace", &rq);
    wait_matched(&w, 2);
    // 40 samples while the reader takes none: it keeps them all.
    let started = Instant::now();
    loan_write(&w, 0..40);
    assert!(
        started.elapsed() < Duration::from_secs(5),
        "the writer waited for the reader that keeps its samples: {:?}",
        started.elapsed()
    );
    let kept = take_in_place(&r, 40, MATCH_TIMEOUT);
    assert_eq!(
        kept.iter().map(|s| s.seq).collect::<Vec<_>>(),
        (0..40).collect::<Vec<_>>()
    );
    let shared = kept.iter().filter(|s| s.in_shared_memory()).count();
    assert!(
        (1..40).contains(&shared),
        "{shared} of 40 read in place: some must be, and not all while they are kept"
    );
    let udp = take_in_place(&fr, 40, MATCH_TIMEOUT);
    assert_eq!(
        udp.iter().map(|s| s.seq).collect::<Vec<_>>(),
        (0..40).collect::<Vec<_>>()
    );
    // Dropping them gives the buffers back: the next samples, taken as they come, are all in place.
    drop(kept);
    let mut seqs = Vec::new();
    for batch in 0..4 {
        loan_write(&w, 40 + batch * 5..45 + batch * 5);
        let got = take_in_place(&r, 5, MATCH_TIMEOUT);
        assert!(
            got.iter().all(|s| s.in_shared_memory()),
            "not read in place"
        );
        // A clone shares the buffer; a copy is on the heap.
        let first = got[0].clone();
        assert!(first.in_shared_memory() && first.to_box().seq == got[0].seq);
        seqs.extend(got.iter().map(|s| s.seq));
    }
    assert_eq!(seqs, (40..60).collect::<Vec<_>>());
    // Samples read in place and given back (`recycle`) are not kept to decode into: their buffers go
    // back to the writer. Kept, the fourth batch would pass the 12 frames a participant holds in place.
    for batch in 0..4 {
        loan_write(&w, 60 + batch * 5..65 + batch * 5);
        let mut got = Vec::new();
        wait_until(MATCH_TIMEOUT, || {
            r.take_into(&mut got).unwrap();
            got.len() >= 5
        });
        assert!(
            got.iter()
                .all(|s| s.data.as_ref().is_some_and(|d| d.in_shared_memory())),
            "batch {batch} not read in place"
        );
        r.recycle(got);
    }
}

/// A writer that sends a burst as soon as it matched: iceoryx2 skips a subscriber that has not connected
/// yet once its queue (16 frames) is full, so the writer must wait for the reader participant to say it is
/// connected. Before, samples from the 17th on were lost in about one run of this test in six with ten
/// writers. Thirty fresh writers (channels), each with a burst of 64.
#[test]
fn a_burst_right_after_matching_reaches_the_reader_whole() {
    let p = participant_with(222, with_shm());
    let near = participant_with(222, with_shm());
    let (wq, rq) = reliable_keep_all();
    for round in 0..30 {
        let topic = format!("ShmBurst{round}");
        let r = reader::<Blob>(&near, &topic, &rq);
        let w = writer::<Blob>(&p, &topic, &wq);
        wait_matched(&w, 1);
        for id in 0..64 {
            w.write(&blob(id, 64)).unwrap();
        }
        assert_eq!(
            take_blobs(&r, 64, MATCH_TIMEOUT),
            (0..64).collect::<Vec<_>>(),
            "round {round}"
        );
    }
}

/// A durable reader whose participant already reads the writer's channel (for another reader) gets the
/// writer's history first, then the live samples: none of the history is skipped because live samples
/// came first.
#[test]
fn a_durable_reader_joining_a_channel_already_read_gets_the_history_first() {
    let p = participant_with(116, with_shm());
    let q = participant_with(116, with_shm());
    let wq = DataWriterQos::builder()
        .reliability(reliable())
        .durability(Durability::TransientLocal)
        .history(History::KeepAll)
        .build();
    let live_q = DataReaderQos::builder()
        .reliability(reliable())
        .history(History::KeepAll)
        .build();
    let durable_q = DataReaderQos::builder()
        .reliability(reliable())
        .durability(Durability::TransientLocal)
        .history(History::KeepAll)
        .build();
    let w = writer::<Blob>(&p, "ShmDurableOrder", &wq);
    let _live = reader::<Blob>(&q, "ShmDurableOrder", &live_q);
    wait_matched(&w, 1);
    // The writer keeps writing while the durable reader joins.
    let written = Arc::new(AtomicU32::new(0));
    let stop = Arc::new(AtomicBool::new(false));
    let writing = {
        let (w, written, stop) = (w.clone(), written.clone(), stop.clone());
        std::thread::spawn(move || {
            let mut id = 0;
            while !stop.load(Ordering::Acquire) {
                w.write(&blob(id, 64)).unwrap();
                id += 1;
                written.store(id, Ordering::Release);
                std::thread::sleep(Duration::from_micros(200));
            }
            id
        })
    };
    wait_until(MATCH_TIMEOUT, || written.load(Ordering::Acquire) >= 50);
    let joined_at = written.load(Ordering::Acquire);
    let durable = reader::<Blob>(&q, "ShmDurableOrder", &durable_q);
    wait_matched(&w, 2);
    std::thread::sleep(Duration::from_millis(100));
    stop.store(true, Ordering::Release);
    let total = writing.join().unwrap();
    // One instance per id: every id from the first of the history to the last, each once, in order.
    let ids = take_blobs(&durable, total as usize, MATCH_TIMEOUT);
    assert_eq!(
        ids,
        (0..total).collect::<Vec<_>>(),
        "the durable reader (joined after {joined_at}) got the history, then the live samples"
    );
}

/// Writes blobs `ids` of `len(id)` bytes.
fn write_blobs(w: &DataWriter<Blob>, ids: std::ops::Range<u32>, len: impl Fn(u32) -> usize) {
    for id in ids {
        w.write(&blob(id, len(id))).unwrap();
    }
}

/// Large samples (from 100 KiB to 1.2 MiB, growing and shrinking) of a writer whose readers are all on
/// shared memory are serialized straight into its channel (`DataWriter::write_direct`: one buffer of the
/// last sample's length, a larger one written as usual); a reader on UDP then joins (the writer's
/// history keeps the bytes for it again), then leaves. Every sample reaches every reader byte for byte,
/// in order, and `wait_for_acknowledgments` holds in each phase.
#[test]
fn large_samples_serialized_into_shared_memory_reach_shared_memory_and_udp_readers_intact() {
    let p = participant_with(62, with_shm());
    let near = participant_with(62, with_shm());
    let (wq, rq) = reliable_keep_all();
    let (w, r) = matched::<Blob>(&p, &near, "ShmDirect", &wq, &rq);
    // Sizes that grow (a sample larger than the buffer goes the usual way), shrink (a shorter one leaves
    // a tail) and repeat (the usual case).
    let len = |id: u32| [300, 300, 1200, 100, 100, 700, 64, 65, 3][id as usize % 9] * KIB;
    let n = 36u32;
    let before = sent(&p);
    write_blobs(&w, 0..n, len);
    assert_eq!(
        take_blobs(&r, n as usize, MATCH_TIMEOUT),
        (0..n).collect::<Vec<_>>()
    );
    w.wait_for_acknowledgments(Duration::from_secs(10)).unwrap();
    let during = sent(&p) - before;
    assert!(during < 20, "{during} datagrams sent on shared memory");

    // A reader on UDP: the history needs the bytes, both readers get every sample.
    let far = participant_with(62, no_shm());
    let fr = reader::<Blob>(&far, "ShmDirect", &rq);
    wait_matched(&w, 2);
    write_blobs(&w, n..2 * n, len);
    let want: Vec<u32> = (n..2 * n).collect();
    assert_eq!(take_blobs(&r, n as usize, MATCH_TIMEOUT), want);
    assert_eq!(take_blobs(&fr, n as usize, MATCH_TIMEOUT), want);
    w.wait_for_acknowledgments(Duration::from_secs(10)).unwrap();

    // It leaves: straight into shared memory again.
    drop(fr);
    far.delete_contained_entities().unwrap();
    drop(far);
    wait_matched(&w, 1);
    write_blobs(&w, 2 * n..3 * n, len);
    assert_eq!(
        take_blobs(&r, n as usize, MATCH_TIMEOUT),
        (2 * n..3 * n).collect::<Vec<_>>()
    );
    w.wait_for_acknowledgments(Duration::from_secs(10)).unwrap();
}

/// Large samples written as soon as the pair matched, before the reader's participant connected to the
/// channel: the first goes the usual way (a copy into the channel when its turn comes), the next ones are
/// serialized into buffers loaned from the channel and wait there, behind it, as loans. When every loan
/// was taken by those, the first found none when its turn came (`ExceedsMaxLoans`) and was dropped: the
/// reader got ids from 1 on (`dcps_alloc::fragmented_writes_allocate_nothing_per_sample` failed 10 of 10
/// with `-F shm` that way). A writer now leaves a loan free for it.
#[test]
fn a_burst_of_large_samples_before_the_reader_connects_arrives_whole() {
    for round in 0..3u32 {
        let p = participant_with(109, with_shm());
        let near = participant_with(109, with_shm());
        let (wq, rq) = reliable_keep_all();
        let n = 24u32;
        // Made first: the writes must come faster than the reader's participant connects.
        let blobs: Vec<Blob> = (0..n).map(|id| blob(id, 80 * KIB)).collect();
        let topic = format!("ShmEarlyBurst{round}");
        let (w, r) = matched::<Blob>(&p, &near, &topic, &wq, &rq);
        for b in &blobs {
            w.write(b).unwrap();
        }
        assert_eq!(
            take_blobs(&r, n as usize, MATCH_TIMEOUT),
            (0..n).collect::<Vec<_>>(),
            "round {round}"
        );
    }
}
