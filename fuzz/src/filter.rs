//! Content-filter and query expressions (`dds_runtime::filter`, DDS 1.4 Annex B) as remote readers announce
//! them (`PID_CONTENT_FILTER_PROPERTY`: our writers parse and evaluate them for writer-side filtering).
//!
//! The input, read as lossy UTF-8, is split at newlines: the first line is the expression, the others (up to
//! twelve) its parameters. Whatever parses is evaluated on derived samples and on a dynamic sample of the same
//! type, both as a filter and as a query (ORDER BY comparisons), and its parameters are replaced by the same
//! list reversed. Nothing may panic, and the derived and dynamic samples must agree on every match.

use std::sync::OnceLock;

use dds_runtime::cdr::{self, ByteOrder, XcdrVersion};
use dds_runtime::filter::ContentFilter;
use dds_runtime::xtypes::dynamic::DynamicData;

use crate::cdr::{Either, Inner, Kind, MutOpt};
use crate::dynamic::dynamic_of;

fn samples() -> &'static (Vec<MutOpt>, Vec<DynamicData>) {
    static S: OnceLock<(Vec<MutOpt>, Vec<DynamicData>)> = OnceLock::new();
    S.get_or_init(|| {
        let full = MutOpt {
            id: 42,
            a: Some(-3),
            b: Some("RED".into()),
            c: u64::MAX,
            d: Some(vec![1, 2, 3]),
            e: Some(Either::Text("t".into())),
            f: Kind::Gamma,
            g: [1, 2, 3],
            h: Some(Inner {
                n: 7,
                tags: vec!["a".into(), "bc".into()],
            }),
        };
        let empty = MutOpt {
            id: 0,
            a: None,
            b: None,
            c: 0,
            d: None,
            e: None,
            f: Kind::Alpha,
            g: [0; 3],
            h: None,
        };
        let typed = vec![empty, full];
        let ty = dynamic_of::<MutOpt>();
        let dynamic = typed
            .iter()
            .map(|v| {
                let mut b = Vec::new();
                cdr::serialize(v, XcdrVersion::Xcdr2, ByteOrder::LittleEndian, &mut b)
                    .expect("encodes");
                DynamicData::deserialize(&ty, &b).expect("decodes dynamically")
            })
            .collect();
        (typed, dynamic)
    })
}

/// Runs one fuzz input (see the module documentation).
pub fn filter_one(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let mut lines = text.split('\n');
    let expression = lines.next().unwrap_or_default();
    let params: Vec<&str> = lines.take(12).collect();
    let (typed, dynamic) = samples();
    if let Ok(mut f) = ContentFilter::new(expression, &params) {
        for (t, d) in typed.iter().zip(dynamic) {
            let m = f.matches(t);
            // Enumerators: the derived code compares numbers, the dynamic one names; only check agreement
            // where the expression does not mention the enum member.
            if !expression.contains('f') {
                assert_eq!(m, f.matches(d), "typed and dynamic samples disagree");
            }
        }
        let reversed: Vec<&str> = params.iter().rev().copied().collect();
        if f.set_parameters(&reversed).is_ok() {
            typed.iter().for_each(|t| {
                f.matches(t);
            });
        }
    }
    if let Ok(q) = ContentFilter::query(expression, &params) {
        let _ = q.compare(&typed[0], &typed[1]);
        let _ = q.compare(&dynamic[0], &dynamic[1]);
        let _ = q.matches(&dynamic[1]);
    }
}
