//! Dynamic data against derived code and against Cyclone DDS 11, on the whole CDR golden corpus.
//!
//! Each type's `DynamicType` is built from Cyclone's own type objects (`fixtures/typeinfo/<Type>.json`: the
//! TypeInformation and TypeMapping the Python binding computes), never from our derive. Then, for every sample
//! of the Rust mirror (`golden/types.rs`) and every XCDR version and byte order the derived encoder accepts:
//! - decoding the derived bytes dynamically and re-encoding them gives the same bytes (both directions);
//! - libddsc's bytes of the fixture, decoded and re-encoded dynamically, give libddsc's bytes;
//! - the fixture's sample value as JSON, converted to `DynamicData`, encodes to the derived bytes, and
//!   `to_json` → `from_json` is lossless;
//! - the key payload, key hash and instance key equal the derived ones (and libddsc's key hash).

#[path = "golden/types.rs"]
mod types;

use std::fmt::Debug;
use std::path::PathBuf;

use dds_runtime::cdr::{self, ByteOrder, DdsType, XcdrVersion};
use dds_runtime::xtypes::dynamic::{default_version, DynamicData, DynamicType};
use dds_runtime::xtypes::typeobject::{from_bytes, TypeInformation, TypeMapping};
use serde_json::Value as Json;

fn read_json(dir: &str, name: &str) -> Json {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join(dir)
        .join(format!("{name}.json"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn unhex(s: &str) -> Vec<u8> {
    (0..s.len() / 2)
        .map(|i| u8::from_str_radix(&s[2 * i..2 * i + 2], 16).expect("hex"))
        .collect()
}

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

/// The type as Cyclone describes it.
pub fn cyclone_type(name: &str) -> DynamicType {
    let fx = read_json("fixtures/typeinfo", name);
    let info: TypeInformation =
        from_bytes(&unhex(fx["type_information"].as_str().expect("ti"))).expect("TypeInformation");
    let map: TypeMapping =
        from_bytes(&unhex(fx["type_mapping"].as_str().expect("tm"))).expect("TypeMapping");
    DynamicType::from_type_mapping(&info, &map).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The binding's JSON spelling of a sample, in ours: bitmasks are `{"mask": n}` there, and a negative zero
/// `{"float": "-0x0.0p+0"}` (the only special float of the corpus).
fn adapt(j: &Json) -> Json {
    match j {
        Json::Object(o) if o.len() == 1 && o.contains_key("mask") => o["mask"].clone(),
        Json::Object(o) if o.len() == 1 && o["float"] == "-0x0.0p+0" => Json::from(-0.0f64),
        Json::Object(o) => Json::Object(o.iter().map(|(k, v)| (k.clone(), adapt(v))).collect()),
        Json::Array(a) => Json::Array(a.iter().map(adapt).collect()),
        other => other.clone(),
    }
}

const ENCODINGS: [(&str, XcdrVersion, ByteOrder); 4] = [
    ("xcdr1_le", XcdrVersion::Xcdr1, ByteOrder::LittleEndian),
    ("xcdr1_be", XcdrVersion::Xcdr1, ByteOrder::BigEndian),
    ("xcdr2_le", XcdrVersion::Xcdr2, ByteOrder::LittleEndian),
    ("xcdr2_be", XcdrVersion::Xcdr2, ByteOrder::BigEndian),
];

struct Report {
    name: String,
    bad: Vec<String>,
    checked: usize,
}

impl Report {
    fn eq(&mut self, what: String, want: &[u8], got: Result<Vec<u8>, String>) {
        self.checked += 1;
        match got {
            Ok(g) if g == want => {}
            Ok(g) => self.bad.push(format!(
                "{what}:\n      want {}\n      got  {}",
                hex(want),
                hex(&g)
            )),
            Err(e) => self.bad.push(format!("{what}: {e}")),
        }
    }
}

fn ser(d: &DynamicData, v: XcdrVersion, o: ByteOrder) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    d.serialize(v, o, &mut out).map_err(|e| e.to_string())?;
    Ok(out)
}

fn check_sample<T: DdsType>(
    rep: &mut Report,
    ty: &DynamicType,
    sname: &str,
    sample: &T,
    fx: Option<&Json>,
) {
    for (tag, v, o) in ENCODINGS {
        let mut derived = Vec::new();
        if cdr::serialize(sample, v, o, &mut derived).is_err() {
            continue;
        }
        let what = format!("{sname} {tag}");
        let dynamic = match DynamicData::deserialize(ty, &derived) {
            Ok(d) => d,
            Err(e) => {
                rep.eq(format!("{what} decode"), &derived, Err(e.to_string()));
                continue;
            }
        };
        rep.eq(
            format!("{what} decode+encode"),
            &derived,
            ser(&dynamic, v, o),
        );
        let back = DynamicData::from_json(ty, &dynamic.to_json()).map_err(|e| e.to_string());
        rep.eq(
            format!("{what} to_json+from_json"),
            &derived,
            back.and_then(|d| ser(&d, v, o)),
        );
        if let Some(j) = fx.map(|s| adapt(&s["value"])) {
            let d = DynamicData::from_json(ty, &j).map_err(|e| e.to_string());
            rep.eq(
                format!("{what} fixture JSON"),
                &derived,
                d.and_then(|d| ser(&d, v, o)),
            );
        }
        if let Some(c) = fx.and_then(|s| s["data"][tag].as_str()) {
            let c = unhex(c);
            let d = DynamicData::deserialize(ty, &c).map_err(|e| e.to_string());
            rep.eq(
                format!("{what} libddsc bytes"),
                &c,
                d.and_then(|d| ser(&d, v, o)),
            );
        }
        if !T::IS_KEYED {
            continue;
        }
        let mut dk = Vec::new();
        if cdr::serialize_key(sample, v, o, &mut dk).is_ok() {
            let mut k = Vec::new();
            let got = dynamic
                .serialize_key(v, o, &mut k)
                .map(|_| k)
                .map_err(|e| e.to_string());
            rep.eq(format!("{what} key"), &dk, got);
            let back = DynamicData::deserialize_key(ty, &dk).map_err(|e| e.to_string());
            rep.eq(
                format!("{what} key decode+encode"),
                &dk,
                back.and_then(|d| {
                    let mut k = Vec::new();
                    d.serialize_key(v, o, &mut k)
                        .map(|_| k)
                        .map_err(|e| e.to_string())
                }),
            );
        }
        if let Ok(h) = cdr::key_hash(sample, v) {
            rep.eq(
                format!("{what} key hash"),
                &h,
                dynamic
                    .key_hash(v)
                    .map(|h| h.to_vec())
                    .map_err(|e| e.to_string()),
            );
            let vtag = if v == XcdrVersion::Xcdr1 {
                "xcdr1"
            } else {
                "xcdr2"
            };
            if let Some(c) = fx.and_then(|s| s["key_hash"][vtag].as_str()) {
                rep.eq(
                    format!("{what} libddsc key hash"),
                    &unhex(c),
                    dynamic
                        .key_hash(v)
                        .map(|h| h.to_vec())
                        .map_err(|e| e.to_string()),
                );
            }
        }
        let mut ik = Vec::new();
        cdr::instance_key(sample, &mut ik).expect("instance key");
        let mut dik = Vec::new();
        rep.eq(
            format!("{what} instance key"),
            &ik,
            dynamic
                .instance_key(&mut dik)
                .map(|_| dik)
                .map_err(|e| e.to_string()),
        );
    }
}

/// Called by every test of `golden/types.rs`.
pub fn check<T: DdsType + PartialEq + Debug>(name: &str, samples: Vec<(&str, T)>) {
    let fx = read_json("fixtures/golden", name);
    let ty = cyclone_type(name);
    let mut rep = Report {
        name: name.to_string(),
        bad: Vec::new(),
        checked: 0,
    };
    if ty.name() != T::TYPE_NAME
        || ty.is_keyed() != T::IS_KEYED
        || ty.extensibility() != T::EXTENSIBILITY
    {
        rep.bad.push(format!(
            "type {} keyed {} {:?}",
            ty.name(),
            ty.is_keyed(),
            ty.extensibility()
        ));
    }
    if default_version(&ty) != T::DEFAULT_VERSION {
        rep.bad
            .push(format!("default version {:?}", default_version(&ty)));
    }
    let fx_samples = fx["samples"].as_array().cloned().unwrap_or_default();
    for (sname, sample) in &samples {
        let f = fx_samples.iter().find(|s| s["name"] == *sname);
        check_sample(&mut rep, &ty, sname, sample, f);
    }
    assert!(rep.checked > 0, "{}: nothing checked", rep.name);
    println!("{}: {} checks", rep.name, rep.checked);
    assert!(
        rep.bad.is_empty(),
        "{}: {} of {} checks failed:\n  {}",
        rep.name,
        rep.bad.len(),
        rep.checked,
        rep.bad.join("\n  ")
    );
}
