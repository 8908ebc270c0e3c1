//! tshark's RTPS dissector decodes every kind of packet we send without a malformed-packet or warning
//! mark. Traffic: a reliable transient-local shape pair with 100 kB samples (DATA_FRAG, NACK_FRAG,
//! HEARTBEAT_FRAG), dispose (key-only DATA), a best-effort pair, and dds-perf ping/pong.

use std::collections::BTreeSet;
use std::process::Command;
use std::time::Duration;

use super::harness::{our_bin, require_netns, root, tshark, Proc, Skip};
use crate::check;

/// Our vendor id in the RTPS header (`VendorId::THIS`).
const OUR_VENDOR: &str = "0x01dd";

fn spawn(label: &str, bin: &str, args: &str) -> Result<Proc, Skip> {
    let mut c = Command::new(our_bin(bin)?);
    c.args(args.split_whitespace());
    Ok(Proc::spawn(label, c))
}

fn tshark_fields(cap: &str, filter: &str, fields: &[&str]) -> Vec<String> {
    let mut c = Command::new("tshark");
    c.args(["-r", cap, "-Y", filter, "-T", "fields", "-E", "separator=|"]);
    for f in fields {
        c.args(["-e", f]);
    }
    let out = c.output().expect("running tshark -r");
    // A rejected filter would otherwise read as "nothing found".
    assert!(
        out.status.success(),
        "tshark -r -Y {filter:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(String::from)
        .collect()
}

#[test]
fn dissector_accepts_all_our_packets() {
    let _ = run();
}

/// Starts tshark capturing on `lo` into `target/interop/NAME-PID.pcapng`; returns it once it captures,
/// with the capture's path.
pub(super) fn start_capture(name: &str) -> Result<(Proc, String), Skip> {
    let ts = tshark()?;
    let dir = root().join("target/interop");
    std::fs::create_dir_all(&dir).expect("target/interop");
    let cap = dir.join(format!("{name}-{}.pcapng", std::process::id()));
    let cap_s = cap.to_string_lossy().to_string();
    let mut c = Command::new(ts);
    c.args(["-i", "lo", "-w", &cap_s]);
    let t = Proc::spawn("tshark", c);
    let started = t.wait_line(Duration::from_secs(15), |l| l.contains("Capturing on"));
    check!(started.is_some(), &[&t], "tshark did not start capturing");
    Ok((t, cap_s))
}

fn run() -> Result<(), Skip> {
    require_netns()?;
    let (mut t, cap_s) = start_capture("rtps")?;

    let d = 120;
    let mut sub = spawn("sub", "shape_main", &format!("-S -t Square -d {d} -D l -r"))?;
    let mut publ = spawn(
        "pub",
        "shape_main",
        &format!("-P -t Square -d {d} -c BLUE -D l -r --additional-payload-size 100000 --num-iterations 60 --final-instance-state d"),
    )?;
    let mut be_sub = spawn("be-sub", "shape_main", &format!("-S -t Circle -d {d} -b"))?;
    let mut be_pub = spawn(
        "be-pub",
        "shape_main",
        &format!("-P -t Circle -d {d} -c RED -b --num-iterations 60"),
    )?;
    let mut pong = spawn("pong", "dds-perf", &format!("-i {d} -D 4 pong"))?;
    let mut ping = spawn("ping", "dds-perf", &format!("-i {d} -D 3 ping"))?;
    let disposed = sub.wait_line(Duration::from_secs(30), |l| {
        l.contains("NOT_ALIVE_DISPOSED_INSTANCE_STATE")
    });
    check!(
        disposed.is_some(),
        &[&publ, &sub],
        "shape exchange did not complete"
    );
    let _ = publ.wait_exit(Duration::from_secs(15));
    let _ = be_pub.wait_exit(Duration::from_secs(15));
    let _ = ping.wait_exit(Duration::from_secs(15));
    let _ = pong.wait_exit(Duration::from_secs(15));
    let _ = sub.interrupt(Duration::from_secs(10));
    let _ = be_sub.interrupt(Duration::from_secs(10));
    std::thread::sleep(Duration::from_millis(500));
    let _ = t.interrupt(Duration::from_secs(10));

    let ours = format!("rtps.vendorId == {OUR_VENDOR}");
    let kinds: BTreeSet<String> = tshark_fields(&cap_s, &ours, &["rtps.sm.id"])
        .iter()
        .flat_map(|l| {
            l.split(',')
                .map(|s| s.trim().to_string())
                .collect::<Vec<_>>()
        })
        .filter(|s| !s.is_empty())
        .collect();
    let bad = tshark_fields(
        &cap_s,
        &format!("{ours} && (_ws.malformed || _ws.expert.severity >= \"Warning\")"),
        &["frame.number", "_ws.col.Info", "_ws.expert.message"],
    );
    check!(
        bad.is_empty(),
        &[&t],
        "tshark flags our packets ({} of them): {:?}",
        bad.len(),
        &bad[..bad.len().min(10)]
    );
    // DATA, DATA_FRAG, HEARTBEAT, ACKNACK, INFO_TS, INFO_DST must all have been sent (and decoded).
    for (id, name) in [
        ("0x15", "DATA"),
        ("0x16", "DATA_FRAG"),
        ("0x07", "HEARTBEAT"),
        ("0x06", "ACKNACK"),
        ("0x09", "INFO_TS"),
        ("0x0e", "INFO_DST"),
    ] {
        check!(
            kinds.contains(id),
            &[&t],
            "no {name} ({id}) from us in the capture; kinds seen: {kinds:?}"
        );
    }
    eprintln!("submessage kinds we sent, all decoded cleanly: {kinds:?}");
    let _ = std::fs::remove_file(&cap_s);
    Ok(())
}
