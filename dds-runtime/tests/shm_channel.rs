//! Shared-memory channels between two processes (feature `shm`): a sample loaned, written in place and read
//! in place by another process; a publisher killed with `SIGKILL` while it holds loans leaks nothing and
//! delivers nothing it had not sent. The second process is this test binary run again with `SHM_ROLE` set
//! (see `child`).

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use dds_runtime::transport::shm::{remove_dead_nodes, ShmChannelConfig, ShmNode};

const MIB: usize = 1 << 20;

fn config() -> ShmChannelConfig {
    ShmChannelConfig {
        initial_max_sample: MIB,
        queue_depth: 8,
        max_loans: 4,
        max_subscribers: 4,
        delivery_timeout: None,
        max_publishers: 2,
        latest_only: false,
    }
}

/// The byte at `i` of sample `n`.
fn pattern(n: usize, i: usize) -> u8 {
    (n.wrapping_mul(31) ^ i.wrapping_mul(7)) as u8
}

fn channel(name: &str) -> String {
    format!("dds-test/{name}/{}", std::process::id())
}

/// Runs this binary's `child` test as a second process in `role`, on `channel`; it prints "ready" when set up.
fn spawn(role: &str, channel: &str, count: usize) -> (Child, BufReader<std::process::ChildStdout>) {
    let mut child = Command::new(std::env::current_exe().unwrap())
        .args(["child", "--exact", "--nocapture", "--test-threads=1"])
        .env("SHM_ROLE", role)
        .env("SHM_CHANNEL", channel)
        .env("SHM_COUNT", count.to_string())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let out = BufReader::new(child.stdout.take().unwrap());
    (child, out)
}

fn wait_line(out: &mut BufReader<std::process::ChildStdout>, want: &str) {
    let mut line = String::new();
    loop {
        line.clear();
        assert!(
            out.read_line(&mut line).unwrap() > 0,
            "child ended before {want:?}"
        );
        // libtest prints "test child ... " before the first line of the child.
        if line.trim().ends_with(want) {
            return;
        }
    }
}

/// The second process: `pub` sends SHM_COUNT samples of 1 MiB then waits; `hold` sends 2 samples, then loans
/// every buffer it may, half-writes them and waits to be killed.
#[test]
fn child() {
    let Ok(role) = std::env::var("SHM_ROLE") else {
        return;
    };
    let ch = std::env::var("SHM_CHANNEL").unwrap();
    let count: usize = std::env::var("SHM_COUNT").unwrap().parse().unwrap();
    let node = ShmNode::new().unwrap();
    let publisher = node.publisher(&ch, &config()).unwrap();
    println!("ready");
    // Wait for the parent's "go" (its subscriber exists before we start).
    let mut go = String::new();
    std::io::stdin().read_line(&mut go).unwrap();
    let sends = if role == "pub" { count } else { 2 };
    for n in 0..sends {
        let mut loan = publisher.loan(MIB).unwrap();
        loan.iter_mut()
            .enumerate()
            .for_each(|(i, b)| *b = pattern(n, i));
        loan.send().unwrap();
    }
    if role == "hold" {
        let mut held = Vec::new();
        while let Ok(mut loan) = publisher.loan(MIB) {
            loan[..MIB / 2].fill(0xee);
            held.push(loan);
        }
        assert!(!held.is_empty());
        println!("holding {}", held.len());
        println!("loaned");
    }
    println!("sent");
    std::thread::sleep(Duration::from_secs(60));
}

/// [`spawn`], once the child's publisher exists.
fn spawn_with_stdin(
    role: &str,
    ch: &str,
    count: usize,
) -> (Child, BufReader<std::process::ChildStdout>) {
    let mut command = spawn(role, ch, count);
    wait_line(&mut command.1, "ready");
    command
}

fn go(child: &mut Child) {
    use std::io::Write;
    child.stdin.as_mut().map(|s| s.write_all(b"go\n"));
}

/// Receives `n` samples numbered from `first` (10 s at most) and checks each byte.
fn receive_checked(
    sub: &dds_runtime::transport::shm::ShmSubscriber,
    first: usize,
    n: usize,
) -> usize {
    let end = Instant::now() + Duration::from_secs(10);
    let mut got = 0;
    while got < n && Instant::now() < end {
        match sub.receive().unwrap() {
            Some(s) => {
                assert_eq!(s.len(), MIB);
                assert!(
                    s.iter()
                        .enumerate()
                        .all(|(i, b)| *b == pattern(first + got, i)),
                    "sample {} intact",
                    first + got
                );
                got += 1;
            }
            None => std::thread::sleep(Duration::from_millis(1)),
        }
    }
    got
}

#[test]
fn a_loaned_sample_is_read_in_place_by_another_process() {
    let ch = channel("inplace");
    let node = ShmNode::new().unwrap();
    let (mut child, mut out) = spawn_with_stdin("pub", &ch, 20);
    let sub = node.subscriber(&ch, &config()).unwrap();
    go(&mut child);
    assert_eq!(receive_checked(&sub, 0, 20), 20);
    wait_line(&mut out, "sent");
    child.kill().unwrap();
    child.wait().unwrap();
}

#[test]
fn a_publisher_killed_while_holding_loans_leaks_and_corrupts_nothing() {
    let ch = channel("killed");
    let node = ShmNode::new().unwrap();
    let (mut child, mut out) = spawn_with_stdin("hold", &ch, 0);
    let sub = node.subscriber(&ch, &config()).unwrap();
    go(&mut child);
    wait_line(&mut out, "loaned");
    // SIGKILL while it holds every loan it could get, half-written.
    child.kill().unwrap();
    child.wait().unwrap();
    // Only what it sent arrives, intact; nothing it had loaned.
    assert_eq!(receive_checked(&sub, 0, 2), 2);
    assert!(sub.receive().unwrap().is_none());
    // Its node is dead and is removed with its segment and loans.
    assert!(remove_dead_nodes() >= 1);
    assert_eq!(remove_dead_nodes(), 0);
    // The channel still works: a new publisher sends more than its loan limit, all received intact.
    let publisher = node.publisher(&ch, &config()).unwrap();
    for n in 0..12 {
        let mut loan = publisher.loan(MIB).unwrap();
        loan.iter_mut()
            .enumerate()
            .for_each(|(i, b)| *b = pattern(n, i));
        loan.send().unwrap();
        assert_eq!(receive_checked(&sub, n, 1), 1, "sample {n}");
    }
}

#[test]
fn spdp_says_which_peers_can_use_shared_memory() {
    use dds_runtime::prelude::*;
    use dds_runtime::transport::shm::{peer_can_use_shm, SHM_HOST_PROPERTY};
    if std::env::var("DDS_IN_NETNS").as_deref() != Ok("1") {
        // Opens sockets: only inside scripts/isolated.
        return;
    }
    let build = || {
        DomainParticipant::builder()
            .domain_id(105)
            .interface("lo")
            .spdp_interval(Duration::from_millis(200))
            .build()
            .unwrap()
    };
    let (a, b) = (build(), build());
    let end = Instant::now() + Duration::from_secs(10);
    let peer = loop {
        if let Some(p) = a
            .discovered_participants()
            .into_iter()
            .find(|p| p.guid_prefix == b.guid_prefix())
        {
            break p;
        }
        assert!(Instant::now() < end, "b not discovered");
        std::thread::sleep(Duration::from_millis(20));
    };
    let data = a.get_discovered_participant_data(peer.handle).unwrap();
    assert!(data.property(SHM_HOST_PROPERTY).is_some());
    assert!(peer_can_use_shm(&data.properties));
}
