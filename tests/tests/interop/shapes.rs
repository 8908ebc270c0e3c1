//! shape_main against the Cyclone DDS (python) and Fast DDS (C++) peers, both directions: discovery and
//! matching, reliability kinds, dispose/unregister, transient-local late joiners, fragmented samples,
//! XCDR1/XCDR2, partitions and an incompatible-QoS pair.

use std::process::Command;
use std::time::Duration;

use super::harness::{cyclone_peer, fastdds_peer, our_bin, require_netns, Proc, Skip};
use crate::check;

/// A program implementing shape_main's contract.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Prog {
    Ours,
    Cyclone,
    FastDds,
}

impl Prog {
    fn command(self) -> Result<Command, Skip> {
        Ok(match self {
            Prog::Ours => Command::new(our_bin("shape_main")?),
            Prog::Cyclone => {
                let mut c = Command::new("python3");
                c.arg("-u").arg(cyclone_peer()?);
                c
            }
            Prog::FastDds => Command::new(fastdds_peer()?),
        })
    }

    /// Spawns with `args` (whitespace-separated).
    pub fn spawn(self, role: &str, args: &str) -> Result<Proc, Skip> {
        let mut c = self.command()?;
        c.args(args.split_whitespace());
        Ok(Proc::spawn(&format!("{role} {self:?}: {args}"), c))
    }
}

const WAIT: Duration = Duration::from_secs(20);
const EXIT: Duration = Duration::from_secs(15);

/// A sample line `%-10s %-10s %03d %03d [%d]` for `topic` and `color`.
fn is_sample(line: &str, topic: &str, color: &str) -> bool {
    line.starts_with(&format!("{topic:<10} {color:<10} "))
        && line.contains(" [")
        && !line.contains("NOT_ALIVE")
}

fn stop(p: &mut Proc) {
    let _ = p.interrupt(EXIT);
}

/// Publisher and subscriber match and the subscriber prints at least `n` samples.
pub fn exchange(
    publ: Prog,
    sub: Prog,
    domain: u32,
    pub_extra: &str,
    sub_extra: &str,
    n: usize,
) -> Result<(), Skip> {
    require_netns()?;
    let mut s = sub.spawn("sub", &format!("-S -t Square -d {domain} {sub_extra}"))?;
    let mut p = publ.spawn(
        "pub",
        &format!("-P -t Square -d {domain} -c BLUE {pub_extra}"),
    )?;
    let got = s.wait_lines(WAIT, n, |l| is_sample(l, "Square", "BLUE"));
    check!(
        got.is_some(),
        &[&p, &s],
        "subscriber did not print {n} BLUE samples"
    );
    let pm = p.wait_line(Duration::from_secs(5), |l| {
        l.starts_with("on_publication_matched()") && l.contains("matched readers 1")
    });
    let sm = s.wait_line(Duration::from_secs(5), |l| {
        l.starts_with("on_subscription_matched()") && l.contains("matched writers 1")
    });
    check!(
        pm.is_some() && sm.is_some(),
        &[&p, &s],
        "matched lines missing"
    );
    stop(&mut p);
    stop(&mut s);
    check!(
        p.grep(|l| l == "Done.").len() == 1,
        &[&p],
        "publisher did not finish cleanly"
    );
    Ok(())
}

/// The publisher ends with dispose (`d`) or unregister (`u`); the subscriber prints the matching
/// NOT_ALIVE instance state for the instance.
pub fn final_state(publ: Prog, sub: Prog, domain: u32, which: char, xcdr: u8) -> Result<(), Skip> {
    require_netns()?;
    let mut s = sub.spawn("sub", &format!("-S -t Circle -d {domain} -x {xcdr}"))?;
    let mut p = publ.spawn(
        "pub",
        &format!("-P -t Circle -d {domain} -c RED -x {xcdr} --num-iterations 150 --final-instance-state {which}"),
    )?;
    let expect = match which {
        'd' => "NOT_ALIVE_DISPOSED_INSTANCE_STATE",
        _ => "NOT_ALIVE_NO_WRITERS_INSTANCE_STATE",
    };
    let seen = s.wait_lines(WAIT, 3, |l| is_sample(l, "Circle", "RED"));
    check!(
        seen.is_some(),
        &[&p, &s],
        "no RED samples before the final state"
    );
    let line = s.wait_line(WAIT, |l| l.contains(expect));
    check!(
        line.is_some(),
        &[&p, &s],
        "subscriber did not report {expect}"
    );
    let line = line.expect("checked");
    check!(
        line == format!("{:<10} {:<10} {expect}", "Circle", "RED"),
        &[&p, &s],
        "state line names the instance: {line:?}"
    );
    let st = p.wait_exit(EXIT);
    check!(
        st.is_some_and(|s| s.success()),
        &[&p],
        "publisher exit {st:?}"
    );
    stop(&mut s);
    Ok(())
}

/// A transient-local reader that joins after the first write receives that sample from the writer's
/// history (a volatile reader never could: the writer writes it only once).
pub fn late_joiner(publ: Prog, sub: Prog, domain: u32) -> Result<(), Skip> {
    require_netns()?;
    let mut p = publ.spawn(
        "pub",
        &format!("-P -t Triangle -d {domain} -c GREEN -D l -k 1 -w --write-period 6000 --num-iterations 3"),
    )?;
    let first = p.wait_line(WAIT, |l| is_sample(l, "Triangle", "GREEN"));
    check!(first.is_some(), &[&p], "publisher wrote nothing");
    let first = first.expect("checked");
    let mut s = sub.spawn("sub", &format!("-S -t Triangle -d {domain} -D l -k 1"))?;
    let got = s.wait_line(Duration::from_secs(5), |l| l == first);
    check!(
        got.is_some(),
        &[&p, &s],
        "late joiner did not receive the historical sample {first:?}"
    );
    stop(&mut p);
    stop(&mut s);
    Ok(())
}

/// 100 kB samples (fragmented on the wire) arrive whole: the subscriber prints the last payload byte.
pub fn large(publ: Prog, sub: Prog, domain: u32, xcdr: u8) -> Result<(), Skip> {
    require_netns()?;
    let mut s = sub.spawn("sub", &format!("-S -t Square -d {domain} -x {xcdr}"))?;
    let mut p = publ.spawn(
        "pub",
        &format!("-P -t Square -d {domain} -c ORANGE -x {xcdr} --write-period 100 --additional-payload-size 100000"),
    )?;
    let got = s.wait_lines(WAIT, 3, |l| {
        is_sample(l, "Square", "ORANGE") && l.ends_with(" {255}")
    });
    check!(got.is_some(), &[&p, &s], "no complete 100 kB samples");
    stop(&mut p);
    stop(&mut s);
    Ok(())
}

/// `--cft`: the subscriber reads a content-filtered topic and prints only samples with `x <= 100`, while the
/// publisher's shapes range further.
pub fn content_filter(publ: Prog, sub: Prog, domain: u32) -> Result<(), Skip> {
    require_netns()?;
    let x_of = |l: &str| {
        l.split_whitespace()
            .nth(2)
            .and_then(|x| x.parse::<i32>().ok())
    };
    let mut s = sub.spawn("sub", &format!("-S -t Square -d {domain} -r --cft x<=100"))?;
    let mut p = publ.spawn(
        "pub",
        &format!("-P -t Square -d {domain} -c BLUE -r --write-period 10"),
    )?;
    let got = s.wait_lines(WAIT, 10, |l| is_sample(l, "Square", "BLUE"));
    check!(
        got.is_some(),
        &[&p, &s],
        "subscriber printed no filtered samples"
    );
    let _ = p.wait_line(Duration::from_secs(3), |l| {
        is_sample(l, "Square", "BLUE") && x_of(l).is_some_and(|x| x > 100)
    });
    stop(&mut p);
    stop(&mut s);
    let printed = s.grep(|l| is_sample(l, "Square", "BLUE"));
    let outside: Vec<&String> = printed
        .iter()
        .filter(|l| x_of(l).is_none_or(|x| x > 100))
        .collect();
    check!(
        outside.is_empty(),
        &[&p, &s],
        "samples outside the filter printed: {outside:?}"
    );
    check!(
        s.grep(|l| l.contains("Create reader for topic: Square_filtered"))
            .len()
            == 1,
        &[&s],
        "the reader is not on the content-filtered topic"
    );
    Ok(())
}

/// Partition "A" matches "A" but not "B".
pub fn partitions(publ: Prog, sub: Prog, domain: u32) -> Result<(), Skip> {
    require_netns()?;
    let mut sa = sub.spawn("subA", &format!("-S -t Square -d {domain} -p A"))?;
    let mut sb = sub.spawn("subB", &format!("-S -t Square -d {domain} -p B"))?;
    let mut p = publ.spawn("pub", &format!("-P -t Square -d {domain} -c PURPLE -p A"))?;
    let got = sa.wait_lines(WAIT, 5, |l| is_sample(l, "Square", "PURPLE"));
    check!(
        got.is_some(),
        &[&p, &sa],
        "same-partition subscriber got nothing"
    );
    // Give the other partition time to (wrongly) match.
    std::thread::sleep(Duration::from_secs(2));
    let wrong = sb.grep(|l| is_sample(l, "Square", "PURPLE") || l.contains("matched writers 1"));
    check!(
        wrong.is_empty(),
        &[&p, &sb],
        "partition B matched or received: {wrong:?}"
    );
    stop(&mut p);
    stop(&mut sa);
    stop(&mut sb);
    Ok(())
}

/// A best-effort writer and a reliable reader must not match; both sides print their
/// incompatible-QoS line naming RELIABILITY, and no data flows.
pub fn incompatible(publ: Prog, sub: Prog, domain: u32) -> Result<(), Skip> {
    require_netns()?;
    let mut s = sub.spawn("sub", &format!("-S -t Square -d {domain} -r"))?;
    let mut p = publ.spawn("pub", &format!("-P -t Square -d {domain} -c YELLOW -b"))?;
    let sl = s.wait_line(WAIT, |l| l.starts_with("on_requested_incompatible_qos()"));
    let pl = p.wait_line(WAIT, |l| l.starts_with("on_offered_incompatible_qos()"));
    check!(
        sl.as_deref().is_some_and(|l| l.ends_with("(RELIABILITY)")),
        &[&p, &s],
        "reader incompatible line"
    );
    check!(
        pl.as_deref().is_some_and(|l| l.ends_with("(RELIABILITY)")),
        &[&p, &s],
        "writer incompatible line"
    );
    std::thread::sleep(Duration::from_secs(1));
    let data = s.grep(|l| is_sample(l, "Square", "YELLOW"));
    check!(
        data.is_empty(),
        &[&p, &s],
        "incompatible pair exchanged data"
    );
    stop(&mut p);
    stop(&mut s);
    Ok(())
}

/// Our XCDR2 writer against a reader that accepts only XCDR1 (what every Fast DDS 2.9 reader
/// announces): the writer must report DATAREPRESENTATION incompatibility, and nothing matches.
pub fn representation_mismatch(publ: Prog, sub: Prog, domain: u32) -> Result<(), Skip> {
    require_netns()?;
    let mut s = sub.spawn("sub", &format!("-S -t Square -d {domain} -x 1"))?;
    let mut p = publ.spawn("pub", &format!("-P -t Square -d {domain} -c CYAN -x 2"))?;
    let pl = p.wait_line(WAIT, |l| l.starts_with("on_offered_incompatible_qos()"));
    check!(
        pl.as_deref()
            .is_some_and(|l| l.ends_with("(DATAREPRESENTATION)")),
        &[&p, &s],
        "writer incompatible line"
    );
    let data = s.grep(|l| is_sample(l, "Square", "CYAN"));
    check!(
        data.is_empty(),
        &[&p, &s],
        "mismatched representations exchanged data"
    );
    stop(&mut p);
    stop(&mut s);
    Ok(())
}

/// Generates the scenario tests for one peer, both directions. Each test gets its own domain ids.
macro_rules! shape_tests {
    ($modname:ident, $peer:expr, $base:expr) => {
        mod $modname {
            use super::*;
            const PEER: Prog = $peer;
            const US: Prog = Prog::Ours;
            const D: u32 = $base;

            #[test]
            fn reliable_us_to_peer() {
                let _ = exchange(US, PEER, D, "-r", "-r", 10);
            }
            #[test]
            fn reliable_peer_to_us() {
                let _ = exchange(PEER, US, D + 1, "-r", "-r", 10);
            }
            #[test]
            fn best_effort_us_to_peer() {
                let _ = exchange(US, PEER, D + 2, "-b", "-b", 10);
            }
            #[test]
            fn best_effort_peer_to_us() {
                let _ = exchange(PEER, US, D + 3, "-b", "-b", 10);
            }
            #[test]
            fn dispose_us_to_peer() {
                let _ = final_state(US, PEER, D + 4, 'd', 1);
            }
            #[test]
            fn dispose_peer_to_us() {
                let _ = final_state(PEER, US, D + 5, 'd', 1);
            }
            #[test]
            fn unregister_us_to_peer() {
                let _ = final_state(US, PEER, D + 6, 'u', 1);
            }
            #[test]
            fn unregister_peer_to_us() {
                let _ = final_state(PEER, US, D + 7, 'u', 1);
            }
            #[test]
            fn transient_local_late_joiner_us_to_peer() {
                let _ = late_joiner(US, PEER, D + 8);
            }
            #[test]
            fn transient_local_late_joiner_peer_to_us() {
                let _ = late_joiner(PEER, US, D + 9);
            }
            #[test]
            fn large_100k_us_to_peer() {
                let _ = large(US, PEER, D + 10, 1);
            }
            #[test]
            fn large_100k_peer_to_us() {
                let _ = large(PEER, US, D + 11, 1);
            }
            #[test]
            fn xcdr1_us_to_peer() {
                let _ = exchange(US, PEER, D + 12, "-x 1", "-x 1", 5);
            }
            #[test]
            fn xcdr1_peer_to_us() {
                let _ = exchange(PEER, US, D + 13, "-x 1", "-x 1", 5);
            }
            #[test]
            fn partitions_us_to_peer() {
                let _ = partitions(US, PEER, D + 14);
            }
            #[test]
            fn partitions_peer_to_us() {
                let _ = partitions(PEER, US, D + 15);
            }
            #[test]
            fn incompatible_qos_us_to_peer() {
                let _ = incompatible(US, PEER, D + 16);
            }
            #[test]
            fn incompatible_qos_peer_to_us() {
                let _ = incompatible(PEER, US, D + 17);
            }
        }
    };
}

shape_tests!(cyclone, Prog::Cyclone, 10);
shape_tests!(fastdds, Prog::FastDds, 40);

/// XCDR2 needs a peer that announces it: Cyclone does, both ways, including fragmented samples and
/// dispose (key-only payloads in XCDR2).
mod cyclone_xcdr2 {
    use super::*;
    #[test]
    fn xcdr2_us_to_peer() {
        let _ = exchange(Prog::Ours, Prog::Cyclone, 70, "-x 2", "-x 2", 5);
    }
    #[test]
    fn xcdr2_peer_to_us() {
        let _ = exchange(Prog::Cyclone, Prog::Ours, 71, "-x 2", "-x 2", 5);
    }
    #[test]
    fn xcdr2_large_us_to_peer() {
        let _ = large(Prog::Ours, Prog::Cyclone, 72, 2);
    }
    #[test]
    fn xcdr2_large_peer_to_us() {
        let _ = large(Prog::Cyclone, Prog::Ours, 73, 2);
    }
    #[test]
    fn xcdr2_dispose_us_to_peer() {
        let _ = final_state(Prog::Ours, Prog::Cyclone, 74, 'd', 2);
    }
    #[test]
    fn xcdr2_dispose_peer_to_us() {
        let _ = final_state(Prog::Cyclone, Prog::Ours, 75, 'd', 2);
    }
}

/// `shape_main --cft`: Cyclone as a plain writer to our filtering subscriber, and ours to ours (where the
/// writer filters on the wire).
mod content_filters {
    use super::*;
    #[test]
    fn cft_peer_to_us() {
        let _ = content_filter(Prog::Cyclone, Prog::Ours, 78);
    }
    #[test]
    fn cft_us_to_us() {
        let _ = content_filter(Prog::Ours, Prog::Ours, 79);
    }
}

/// Fast DDS 2.9 never announces a data representation (its SEDP omits PID_DATA_REPRESENTATION), so
/// peers see XCDR1 offered and requested. Its writer with `-x 2` still encodes D_CDR2 payloads: our
/// XCDR1 reader must decode them by their encapsulation header. In the other direction our XCDR2 writer
/// must refuse its XCDR1-only reader.
mod fastdds_xcdr2 {
    use super::*;
    #[test]
    fn xcdr2_payload_peer_to_us() {
        let _ = exchange(Prog::FastDds, Prog::Ours, 76, "-x 2", "-x 1", 5);
    }
    #[test]
    fn xcdr2_us_to_peer_is_incompatible() {
        let _ = representation_mismatch(Prog::Ours, Prog::FastDds, 77);
    }
}
