//! The OMG XTypes interoperability types (25 shape variants, `xtypes_shapes`): all 625 writer × reader pairs,
//! ours against ours. Matched or not as the suite's compatibility matrix says (but for the pairs listed in
//! [`DISAGREE`], with the reason), and where matched the reader shows the writer's data in its own type.
//!
//! The socket test runs inside `scripts/isolated`.
mod dcps_util;
#[macro_use]
mod xtypes_shapes;

use std::time::Duration;

use dcps_util::*;
use dds_runtime::prelude::*;
use dds_runtime::xtypes::assign::{is_assignable, local_types};
use dds_runtime::xtypes::XTypesType;
use xtypes_shapes::*;

fn minimal_ids() -> Vec<dds_runtime::xtypes::typeobject::TypeIdentifier> {
    let mut ids = Vec::new();
    macro_rules! push {
        ($t:ty) => {
            ids.push(
                <$t>::type_support()
                    .expect("type support")
                    .minimal_id()
                    .clone(),
            );
        };
    }
    for_each_variant!(push);
    ids
}

/// The 625 pairs through the assignability function alone (no sockets).
#[test]
fn assignability_follows_the_suite_matrix() {
    let ids = minimal_ids();
    let tce = TypeConsistencyEnforcement::default();
    let mut agree = 0;
    for w in 1..=25 {
        for r in 1..=25 {
            let ours = is_assignable(&ids[r - 1], &ids[w - 1], &tce, local_types()).is_ok();
            assert_eq!(ours, expected(w, r), "writer {w}, reader {r}");
            agree += usize::from(ours == matrix(w, r));
        }
    }
    assert_eq!(agree, 625 - DISAGREE.len());
}

/// All 625 pairs over DCPS: 25 writers on one participant, 25 readers on another, one topic.
#[test]
fn all_625_pairs_match_and_read_in_their_own_type() {
    // Announce type information (read once per process, before the first endpoint exists).
    std::env::set_var(dds_runtime::xtypes::ANNOUNCE_ENV, "on");
    let (pw, pr) = (participant(93), participant(93));
    let (wq, rq) = reliable_keep_all();
    let mut writers: Vec<Box<dyn AnyWriter>> = Vec::new();
    let mut readers: Vec<Box<dyn AnyReader>> = Vec::new();
    macro_rules! make {
        ($t:ty) => {
            writers.push(Box::new(writer::<$t>(&pw, "XTypesShapes", &wq)));
            readers.push(Box::new(reader::<$t>(&pr, "XTypesShapes", &rq)));
        };
    }
    for_each_variant!(make);
    let want_r = |r: usize| (1..=25).filter(|&w| expected(w, r)).count() as i32;
    let want_w = |w: usize| (1..=25).filter(|&r| expected(w, r)).count() as i32;
    let settled = wait_until(Duration::from_secs(30), || {
        (1..=25)
            .all(|k| readers[k - 1].matched() == want_r(k) && writers[k - 1].matched() == want_w(k))
    });
    let counts: Vec<_> = (1..=25)
        .map(|k| {
            (
                k,
                writers[k - 1].matched(),
                want_w(k),
                readers[k - 1].matched(),
                want_r(k),
            )
        })
        .filter(|(_, a, b, c, d)| a != b || c != d)
        .collect();
    assert!(
        settled,
        "(variant, writer matched, expected, reader matched, expected): {counts:?}"
    );
    // Every unmatched pair was reported as an incompatible TYPE_CONSISTENCY_ENFORCEMENT on both sides.
    for k in 1..=25 {
        let st = readers[k - 1].incompatible();
        assert_eq!(st.total_count as i32, 25 - want_r(k), "reader {k}");
        if st.total_count > 0 {
            assert_eq!(
                st.last_policy_id,
                Some(QosPolicyId::TypeConsistencyEnforcement)
            );
        }
        assert_eq!(
            writers[k - 1].incompatible().total_count as i32,
            25 - want_w(k),
            "writer {k}"
        );
    }
    for (i, w) in writers.iter().enumerate() {
        w.write(&Fields::of_writer(i + 1));
    }
    for (j, r) in readers.iter().enumerate() {
        let rk = j + 1;
        let mut want: Vec<Fields> = (1..=25)
            .filter(|&w| expected(w, rk))
            .map(|w| Fields::of_writer(w).as_read(writers[w - 1].has(), r.has()))
            .collect();
        let mut got = Vec::new();
        wait_until(Duration::from_secs(10), || {
            got.extend(r.take());
            got.len() >= want.len()
        });
        let key = |f: &Fields| f.x;
        got.sort_by_key(key);
        want.sort_by_key(key);
        assert_eq!(got, want, "reader {rk}");
    }
}
