//! DEADLINE against Cyclone DDS 11 (python peer), both directions, with shape_main's command line: the
//! writer prints `on_offered_deadline_missed()` and the reader `on_requested_deadline_missed()` when the
//! write period exceeds the deadline (the OMG suite's `Test_Deadline_3`, with shorter periods).

use std::time::Duration;

use super::harness::{require_netns, Proc, Skip};
use super::shapes::Prog;
use crate::check;

const WAIT: Duration = Duration::from_secs(20);

fn misses(p: &Proc, what: &str, n: usize) -> Option<Vec<String>> {
    p.wait_lines(WAIT, n, |l| l.starts_with(what))
}

/// The `(total = T, change = C)` counts of a deadline line.
fn counts(line: &str) -> Option<(u32, u32)> {
    let rest = line.split("(total = ").nth(1)?;
    let (t, rest) = rest.split_once(", change = ")?;
    Some((t.parse().ok()?, rest.trim_end_matches(')').parse().ok()?))
}

fn deadline_missed_both_sides(publ: Prog, sub: Prog, domain: u32) -> Result<(), Skip> {
    require_netns()?;
    let mut s = sub.spawn("sub", &format!("-S -t Square -d {domain} -r -f 300"))?;
    let mut p = publ.spawn(
        "pub",
        &format!("-P -t Square -d {domain} -r -c BLUE -f 300 -w --write-period 700"),
    )?;
    let offered = misses(&p, "on_offered_deadline_missed()", 2);
    let requested = misses(&s, "on_requested_deadline_missed()", 2);
    check!(
        offered.is_some() && requested.is_some(),
        &[&p, &s],
        "both sides print two deadline misses"
    );
    for l in offered.iter().chain(requested.iter()).flatten() {
        let c = counts(l);
        check!(
            c.is_some_and(|(t, c)| t >= 1 && c >= 1 && c <= t),
            &[&p, &s],
            "bad counts in {l:?}"
        );
        check!(
            l.contains("topic: 'Square'  type: 'ShapeType'"),
            &[&p, &s],
            "topic and type in {l:?}"
        );
    }
    let _ = p.interrupt(Duration::from_secs(10));
    let _ = s.interrupt(Duration::from_secs(10));
    Ok(())
}

#[test]
fn deadline_ours_to_cyclone() -> Result<(), Skip> {
    deadline_missed_both_sides(Prog::Ours, Prog::Cyclone, 180)
}

#[test]
fn deadline_cyclone_to_ours() -> Result<(), Skip> {
    deadline_missed_both_sides(Prog::Cyclone, Prog::Ours, 181)
}

#[test]
fn deadline_ours_to_ours() -> Result<(), Skip> {
    deadline_missed_both_sides(Prog::Ours, Prog::Ours, 182)
}
