//! TRANSIENT and PERSISTENT durability across processes: the durability order against Cyclone DDS (both
//! directions), and a test that kills things: persistent samples survive `kill -9` of their writer and of
//! the `dds-durability` service, and a reader that joins after the service restarted gets each sample
//! written before the kill exactly once.

use std::collections::BTreeMap;
use std::process::Command;
use std::time::Duration;

use super::harness::{our_bin, require_netns, Proc, Skip};
use super::shapes::Prog;
use crate::check;

const WAIT: Duration = Duration::from_secs(20);

/// A sample line of `shape_main` (`Square     RED        012 034 [30]`), as printed by a writer with `-w`
/// and by a reader.
fn samples(p: &Proc, color: &str) -> Vec<String> {
    let prefix = format!("{:<10} {color:<10} ", "Square");
    p.grep(|l| l.starts_with(&prefix) && l.contains(" [") && !l.contains("NOT_ALIVE"))
}

/// A writer offering `offered` and a reader requesting `requested`, with the durability order deciding:
/// incompatible pairs print the DURABILITY lines and exchange nothing, compatible pairs exchange data.
fn durability_pair(
    publ: Prog,
    sub: Prog,
    domain: u32,
    offered: char,
    requested: char,
) -> Result<(), Skip> {
    require_netns()?;
    let mut s = sub.spawn(
        "sub",
        &format!("-S -t Square -d {domain} -r -D {requested}"),
    )?;
    let mut p = publ.spawn(
        "pub",
        &format!("-P -t Square -d {domain} -r -c ORANGE -D {offered}"),
    )?;
    let compatible = "vltp".find(offered) >= "vltp".find(requested);
    if compatible {
        let got = s.wait_line(WAIT, |l| l.starts_with("Square     ORANGE"));
        check!(
            got.is_some(),
            &[&p, &s],
            "-D {offered} to -D {requested}: no data"
        );
    } else {
        let sl = s.wait_line(WAIT, |l| l.starts_with("on_requested_incompatible_qos()"));
        let pl = p.wait_line(WAIT, |l| l.starts_with("on_offered_incompatible_qos()"));
        check!(
            sl.as_deref().is_some_and(|l| l.ends_with("(DURABILITY)")),
            &[&p, &s],
            "reader incompatible line"
        );
        check!(
            pl.as_deref().is_some_and(|l| l.ends_with("(DURABILITY)")),
            &[&p, &s],
            "writer incompatible line"
        );
        check!(
            samples(&s, "ORANGE").is_empty(),
            &[&p, &s],
            "incompatible pair exchanged data"
        );
    }
    let _ = p.interrupt(WAIT);
    let _ = s.interrupt(WAIT);
    Ok(())
}

#[test]
fn transient_writer_persistent_reader_incompatible_us_to_cyclone() {
    let _ = durability_pair(Prog::Ours, Prog::Cyclone, 190, 't', 'p');
}

#[test]
fn transient_writer_persistent_reader_incompatible_cyclone_to_us() {
    let _ = durability_pair(Prog::Cyclone, Prog::Ours, 191, 't', 'p');
}

#[test]
fn persistent_writer_transient_reader_match_us_to_cyclone() {
    let _ = durability_pair(Prog::Ours, Prog::Cyclone, 192, 'p', 't');
}

#[test]
fn persistent_writer_transient_local_reader_match_cyclone_to_us() {
    let _ = durability_pair(Prog::Cyclone, Prog::Ours, 193, 'p', 'l');
}

fn service(domain: u32, store: &std::path::Path) -> Result<Proc, Skip> {
    service_with(domain, Some(store))
}

/// `dds-durability` on `domain`, with a persistent store or without.
fn service_with(domain: u32, store: Option<&std::path::Path>) -> Result<Proc, Skip> {
    let mut c = Command::new(our_bin("dds-durability")?);
    c.args(["--domain", &domain.to_string()]);
    if let Some(store) = store {
        c.arg("--store").arg(store);
    }
    let p = Proc::spawn("dds-durability", c);
    check!(
        p.wait_line(WAIT, |l| l.ends_with("ready")).is_some(),
        &[&p],
        "service not ready"
    );
    Ok(p)
}

#[test]
fn persistent_samples_survive_kill_9_of_writer_and_service() {
    let _ = kill_test(194);
}

fn kill_test(domain: u32) -> Result<(), Skip> {
    require_netns()?;
    let dir = std::env::temp_dir().join(format!("dds-durability-kill-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let store = dir.join("domain.redb");
    let _ = std::fs::remove_file(&store);
    let svc = service(domain, &store)?;
    let writer = serviceless_writer(domain, "GREEN", "p", "0", 30, &svc)?;
    // kill -9 the writer (Proc's drop sends SIGKILL), keeping what it printed before.
    let written = samples(&writer, "GREEN");
    drop(writer);
    // The service stores each batch with an fsync'ed commit; give it a moment to receive the last ones.
    std::thread::sleep(Duration::from_secs(1));
    drop(svc);
    let svc = service(domain, &store)?;
    let mut r = Prog::Ours.spawn("reader", &format!("-S -t Square -d {domain} -r -D p -k 0"))?;
    let all = r
        .wait_lines(WAIT, written.len(), |l| l.starts_with("Square     GREEN"))
        .is_some();
    std::thread::sleep(Duration::from_secs(1));
    let got = samples(&r, "GREEN");
    eprintln!(
        "kill test: {} samples written before kill -9, {} received after the restart",
        written.len(),
        got.len()
    );
    let mut counts: BTreeMap<&str, usize> = BTreeMap::new();
    for l in &got {
        *counts.entry(l.as_str()).or_default() += 1;
    }
    let missing: Vec<&String> = written
        .iter()
        .filter(|l| !counts.contains_key(l.as_str()))
        .collect();
    let repeated: Vec<(&&str, &usize)> = counts.iter().filter(|(_, n)| **n > 1).collect();
    check!(
        all && missing.is_empty(),
        &[&svc, &r],
        "{} written, missing {missing:?}",
        written.len()
    );
    check!(
        repeated.is_empty(),
        &[&svc, &r],
        "received more than once: {repeated:?}"
    );
    let _ = r.interrupt(WAIT);
    drop(svc);
    let _ = std::fs::remove_dir_all(&dir);
    Ok(())
}

/// Cyclone sends no key hash. `dds-durability` keeps a Cyclone TRANSIENT writer's changes by instance all the
/// same, computing each key hash from the payload through the type Cyclone announced (and TypeLookup
/// fetched): with Cyclone's default DURABILITY_SERVICE history (KEEP_LAST 1), a reader that joins after the
/// writer was killed gets one sample of the instance, the last one written, not one per change.
#[test]
fn the_service_keeps_a_cyclone_writers_changes_by_instance() {
    let _ = keyed_without_key_hash(197);
}

fn keyed_without_key_hash(domain: u32) -> Result<(), Skip> {
    require_netns()?;
    let svc = service_with(domain, None)?;
    let writer = Prog::Cyclone.spawn(
        "writer",
        &format!("-P -t Square -d {domain} -c RED -r -D t -k 0 -w"),
    )?;
    let enough = writer
        .wait_lines(WAIT, 10, |l| l.starts_with("Square     RED"))
        .is_some();
    check!(enough, &[&svc, &writer], "Cyclone did not write 10 samples");
    // Let the service receive what was printed, then kill -9 the writer.
    std::thread::sleep(Duration::from_secs(1));
    let written = samples(&writer, "RED");
    drop(writer);
    let mut r = Prog::Ours.spawn("reader", &format!("-S -t Square -d {domain} -r -D t -k 0"))?;
    let got_one = r
        .wait_line(WAIT, |l| l.starts_with("Square     RED"))
        .is_some();
    std::thread::sleep(Duration::from_secs(2));
    let got = samples(&r, "RED");
    check!(got_one, &[&svc, &r], "no sample from the service");
    check!(
        got.len() == 1 && written.last() == got.first(),
        &[&svc, &r],
        "expected the last of {} written ({:?}), got {got:?}",
        written.len(),
        written.last()
    );
    let _ = r.interrupt(WAIT);
    Ok(())
}

/// The Cyclone shape peer's type (`tests/peers/cyclone_shape.py`), for a writer in this process.
#[derive(dds_runtime::prelude::DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "ShapeType", appendable)]
struct ShapeType {
    #[dds(key)]
    color: String,
    x: i32,
    y: i32,
    shapesize: i32,
    additional_payload_size: Vec<u8>,
}

/// A TRANSIENT writer in this process (its participant's own service keeps its data, KEEP_LAST 2, cleanup
/// delay 60 s) writes three samples of BLUE, GREEN and RED on `Final`, unregisters BLUE, disposes RED and is
/// deleted (which unregisters GREEN and RED). A late `shape_main` reader (`reader`, requesting `durability`)
/// must print, per instance, the last two samples and then the final state: NOT_ALIVE_NO_WRITERS for BLUE
/// and GREEN, NOT_ALIVE_DISPOSED for RED.
fn final_states(reader: Prog, durability: char, domain: u32) -> Result<(), Skip> {
    use dds_runtime::prelude::*;
    require_netns()?;
    let p = super::harness::loopback_participant(domain);
    let qos = DataWriterQos::builder()
        .reliability(Reliability::RELIABLE)
        .durability(Durability::Transient)
        .data_representation(DataRepresentation::xcdr1())
        .history(History::KeepLast(2))
        .durability_service(DurabilityService {
            history: History::KeepLast(2),
            service_cleanup_delay: Duration::from_secs(60),
            ..DurabilityService::default()
        })
        .writer_data_lifecycle(WriterDataLifecycle {
            autodispose_unregistered_instances: false,
        })
        .build();
    let topic = p
        .create_topic::<ShapeType>("Final", &TopicQos::default())
        .expect("topic");
    let publisher = p
        .create_publisher(&PublisherQos::default())
        .expect("publisher");
    let w = publisher.create_datawriter(&topic, &qos).expect("writer");
    let shape = |color: &str, x: i32| ShapeType {
        color: color.into(),
        x,
        y: 2 * x,
        shapesize: 30,
        additional_payload_size: Vec::new(),
    };
    for x in 1..=3 {
        for color in ["BLUE", "GREEN", "RED"] {
            w.write(&shape(color, x)).expect("write");
        }
    }
    w.unregister_instance(&shape("BLUE", 0))
        .expect("unregister");
    w.dispose(&shape("RED", 0)).expect("dispose");
    drop(w);
    std::thread::sleep(Duration::from_millis(300));
    let mut r = reader.spawn(
        "reader",
        &format!("-S -t Final -d {domain} -r -D {durability} -k 0"),
    )?;
    let state_line =
        |c: &str, s: &str| format!("{:<10} {c:<10} NOT_ALIVE_{s}_INSTANCE_STATE", "Final");
    let expected = [
        ("BLUE", "NO_WRITERS"),
        ("GREEN", "NO_WRITERS"),
        ("RED", "DISPOSED"),
    ];
    let all = r.wait_lines(WAIT, 3, |l| l.contains("NOT_ALIVE")).is_some();
    std::thread::sleep(Duration::from_secs(1));
    for (color, state) in expected {
        let prefix = format!("{:<10} {color:<10} ", "Final");
        let lines = r.grep(|l| l.starts_with(&prefix));
        let (states, data): (Vec<&String>, Vec<&String>) =
            lines.iter().partition(|l| l.contains("NOT_ALIVE"));
        let want = [
            format!("{prefix}002 004 [30]"),
            format!("{prefix}003 006 [30]"),
        ];
        // A reader prints the instance state with each sample it takes while the instance is not alive,
        // and once more for the state change when it took the samples before.
        check!(
            all && data == want.iter().collect::<Vec<_>>()
                && !states.is_empty()
                && states.iter().all(|l| **l == state_line(color, state))
                && lines.last() == states.last().copied(),
            &[&r],
            "{color}: expected {want:?} then {state}, got {lines:?}"
        );
    }
    let _ = r.interrupt(WAIT);
    Ok(())
}

/// Cyclone handles only TRANSIENT_LOCAL readers as durable on the wire: a TRANSIENT one starts at the
/// writer's newest change (it expects a durability service of its own), so its late joiner is TRANSIENT_LOCAL.
#[test]
fn a_late_cyclone_reader_gets_the_kept_samples_then_the_final_state() {
    let _ = final_states(Prog::Cyclone, 'l', 198);
}

#[test]
fn a_late_reader_of_ours_gets_the_kept_samples_then_the_final_state() {
    let _ = final_states(Prog::Ours, 't', 199);
}

/// Sorted `shape_main` sample lines of topic `topic` that `p` printed.
fn sorted_data(p: &Proc, topic: &str) -> Vec<String> {
    let prefix = format!("{topic:<10} ");
    let mut v = p.grep(|l| l.starts_with(&prefix) && l.ends_with("[30]"));
    v.sort();
    v
}

/// The lines a reader prints for BLUE, GREEN and RED at each `x` of `xs` (y = 2x, size 30), sorted.
fn want_lines(topic: &str, xs: std::ops::RangeInclusive<i32>) -> Vec<String> {
    let mut v: Vec<String> = ["BLUE", "GREEN", "RED"]
        .iter()
        .flat_map(|c| {
            xs.clone()
                .map(move |x| format!("{topic:<10} {c:<10} {x:03} {:03} [30]", 2 * x))
        })
        .collect();
    v.sort();
    v
}

/// Waits until `r` printed `n` sample lines of `topic`, then 2 s more for repeats that would follow.
fn settle(r: &Proc, topic: &str, n: usize) {
    let prefix = format!("{topic:<10} ");
    let _ = r.wait_lines(WAIT, n, |l| l.starts_with(&prefix) && l.ends_with("[30]"));
    std::thread::sleep(Duration::from_secs(2));
}

/// A TRANSIENT writer in this process (its participant's own service keeps its data, the writer and the
/// service both KEEP_LAST 3) writes three samples each of BLUE, GREEN and RED on `Once`. A late `reader`
/// (TRANSIENT_LOCAL) that joins while the writer lives matches the writer and the service's stand-in: it
/// must print each sample exactly once (the stand-in holds it: another vendor's reader cannot drop the
/// repeats itself), and so for a fourth sample of each written while it runs. The writer is then deleted:
/// the first reader prints no repeat (the stand-in releases it with everything served), and a second late
/// reader prints each kept sample (the last three of each) exactly once, from the stand-in.
fn once_while_the_writer_lives(reader: Prog, domain: u32) -> Result<(), Skip> {
    use dds_runtime::prelude::*;
    require_netns()?;
    let p = super::harness::loopback_participant(domain);
    let depth = History::KeepLast(3);
    let qos = DataWriterQos::builder()
        .reliability(Reliability::RELIABLE)
        .durability(Durability::Transient)
        .data_representation(DataRepresentation::xcdr1())
        .history(depth)
        .durability_service(DurabilityService {
            history: depth,
            ..DurabilityService::default()
        })
        .build();
    let topic = p
        .create_topic::<ShapeType>("Once", &TopicQos::default())
        .expect("topic");
    let publisher = p
        .create_publisher(&PublisherQos::default())
        .expect("publisher");
    let w = publisher.create_datawriter(&topic, &qos).expect("writer");
    let write = |xs: std::ops::RangeInclusive<i32>| {
        for x in xs {
            for color in ["BLUE", "GREEN", "RED"] {
                let s = ShapeType {
                    color: color.into(),
                    x,
                    y: 2 * x,
                    shapesize: 30,
                    additional_payload_size: Vec::new(),
                };
                w.write(&s).expect("write");
            }
        }
    };
    write(1..=3);
    let args = format!("-S -t Once -d {domain} -r -D l -k 0");
    let mut first = reader.spawn("reader1", &args)?;
    settle(&first, "Once", 9);
    let got = sorted_data(&first, "Once");
    check!(
        got == want_lines("Once", 1..=3),
        &[&first],
        "history while the writer lives: {got:?}"
    );
    write(4..=4);
    settle(&first, "Once", 12);
    let got = sorted_data(&first, "Once");
    check!(
        got == want_lines("Once", 1..=4),
        &[&first],
        "live while the writer lives: {got:?}"
    );
    drop(w);
    let mut second = reader.spawn("reader2", &args)?;
    settle(&second, "Once", 9);
    let got = sorted_data(&second, "Once");
    check!(
        got == want_lines("Once", 2..=4),
        &[&second],
        "after the writer: {got:?}"
    );
    let got = sorted_data(&first, "Once");
    check!(
        got == want_lines("Once", 1..=4),
        &[&first],
        "repeats after the writer: {got:?}"
    );
    let _ = first.interrupt(WAIT);
    let _ = second.interrupt(WAIT);
    Ok(())
}

#[test]
fn a_cyclone_transient_local_reader_gets_each_sample_once_while_the_writer_lives() {
    let _ = once_while_the_writer_lives(Prog::Cyclone, 117);
}

#[test]
fn a_transient_local_reader_of_ours_gets_each_sample_once_while_the_writer_lives() {
    let _ = once_while_the_writer_lives(Prog::Ours, 118);
}

/// `dds-durability` keeps the data of a TRANSIENT `shape_main` writer of ours (without its own service),
/// which is killed with `kill -9`. A Cyclone TRANSIENT_LOCAL reader joins right after, while the dead
/// writer's participant is still known (its lease, 10 s, has not expired): the stand-in holds it, since the
/// original writer still seems to serve it, and releases it when the lease expires. It must then get the
/// kept samples (the last of each instance: KEEP_LAST 1) from the stand-in.
#[test]
fn a_cyclone_reader_joining_after_a_kill_9_of_the_writer_gets_the_history() {
    let _ = history_after_kill_9(119);
}

fn history_after_kill_9(domain: u32) -> Result<(), Skip> {
    require_netns()?;
    let svc = service_with(domain, None)?;
    let writer = serviceless_writer(domain, "BLUE", "t", "1", 10, &svc)?;
    std::thread::sleep(Duration::from_secs(1));
    let written = samples(&writer, "BLUE");
    // kill -9 (Proc's drop sends SIGKILL): the writer's participant stays known until its lease expires.
    drop(writer);
    let mut r = Prog::Cyclone.spawn("reader", &format!("-S -t Square -d {domain} -r -D l -k 0"))?;
    let got_one = r
        .wait_line(3 * WAIT, |l| l.starts_with("Square     BLUE"))
        .is_some();
    std::thread::sleep(Duration::from_secs(2));
    let got = samples(&r, "BLUE");
    check!(got_one, &[&svc, &r], "no sample from the service");
    check!(
        got.len() == 1,
        &[&svc, &r],
        "expected the last sample the service kept (of {} written and more), got {got:?}",
        written.len()
    );
    let _ = r.interrupt(WAIT);
    Ok(())
}

/// Our `shape_main` writing `color` (durability `kind`, history depth `depth`, 0 for keep-all) without an
/// in-process service, so that only the `dds-durability` of `svc` keeps its data; returned once it has
/// printed `n` samples.
fn serviceless_writer(
    domain: u32,
    color: &str,
    kind: &str,
    depth: &str,
    n: usize,
    svc: &Proc,
) -> Result<Proc, Skip> {
    let mut c = Command::new(our_bin("shape_main")?);
    c.args([
        "-P", "-t", "Square", "-c", color, "-r", "-D", kind, "-k", depth,
    ])
    .args(["-w", "-z", "0", "-d", &domain.to_string()])
    .env("DDS_DURABILITY_SERVICE", "off");
    let writer = Proc::spawn("writer", c);
    let prefix = format!("Square     {color}");
    let enough = writer
        .wait_lines(WAIT, n, |l| l.starts_with(&prefix))
        .is_some();
    check!(enough, &[svc, &writer], "writer did not write {n} samples");
    Ok(writer)
}
