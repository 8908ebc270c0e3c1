//! idlc-generated types from the real IDL corpus against libddsc 11.0.1 (`tests/fixtures/idlc-golden/`).
//!
//! `build.rs` compiles corpus files (`../shared/idl-corpus`, or `$DDS_IDL_CORPUS`) with idlc; the fixtures hold
//! libddsc's bytes for the same IDL types (`scripts/golden/corpus_idl.py`, run by `scripts/gen-golden`). For
//! every type and sample, built here by hand: `serialize` gives libddsc's bytes (each XCDR version and byte order
//! the fixture holds), `deserialize` of them gives the sample back, and for keyed types `serialize_key` and
//! `key_hash` give libddsc's key payload and key hash. The type's constants (name, extensibility, keyed, default
//! version) must agree with libddsc too. Without the corpus every test prints SKIP and passes; a file idlc
//! rejects fails its types' tests with idlc's diagnostics. Findings: `tests/fixtures/idlc-golden/FINDINGS.md`.

// Without the corpus only the skip path is compiled.
#![cfg_attr(not(idl_corpus), allow(dead_code, unused_imports, unused_macros))]

use dds_runtime::cdr::{BoundedSeq, BoundedString};

#[path = "golden/explain.rs"]
mod explain;

/// Includes one generated file as a module, when idlc accepted it.
macro_rules! idl {
    ($m:ident, $stem:literal) => {
        dds_tests::generated!(
            #[cfg(idlc_ok = $stem)]
            $m,
            $stem
        );
    };
}

idl!(shape, "shape");
idl!(ddsperf, "ddsperf_types");
idl!(structures, "structures");
idl!(inheritance, "inheritance");
idl!(enumerations, "enumerations");
idl!(unions, "unions");
idl!(key, "key");
idl!(mutable, "mutable");
idl!(final_, "final");
idl!(member_id, "member_id");
idl!(optional, "optional");
idl!(arrays, "arrays");
idl!(sequences, "sequences");
idl!(key_ext, "CdrStreamKeyExt");
idl!(signed_union, "CdrStreamSignedUnion");
idl!(struct_keys, "test_struct_keys");
idl!(inherit_mutable_keys, "test_struct_inherit_mutable_keys");
idl!(pose_stamped, "PoseStamped");
idl!(imu, "Imu");
idl!(diagnostic_status, "DiagnosticStatus");
// The same ROS files with unannotated types @final, as Cyclone's idlc (and rmw_cyclonedds) reads them.
idl!(pose_stamped_final, "final/PoseStamped");
idl!(imu_final, "final/Imu");
idl!(diagnostic_status_final, "final/DiagnosticStatus");

/// One test per fixture:
/// `golden! { test_name: "idl file stem" / "fixture" => Type, "sample" => value, ... }`, optionally preceded by
/// attributes for the test (`#[ignore = "..."]` for an open finding).
macro_rules! golden {
    ($(#[$meta:meta])* $test:ident: $stem:literal / $fixture:literal => $ty:ty,
     $($name:literal => $value:expr),+ $(,)?) => {
        #[cfg(idlc_ok = $stem)]
        #[test]
        $(#[$meta])*
        fn $test() {
            check::check::<$ty>($fixture, vec![$(($name, $value)),+]);
        }

        #[cfg(not(idlc_ok = $stem))]
        #[test]
        fn $test() {
            check::not_generated($stem, $fixture);
        }
    };
}

mod check {
    use std::fmt::Debug;
    use std::path::PathBuf;

    use dds_runtime::cdr::{self, ByteOrder, DdsType, Extensibility, XcdrVersion};
    use serde_json::Value;

    /// The test of a type whose IDL file was not compiled: a skip without the corpus, else idlc's error.
    #[allow(dead_code)] // unused when idlc accepted every file
    pub fn not_generated(stem: &str, fixture: &str) {
        if !cfg!(idl_corpus) {
            println!(
                "SKIP {fixture}: IDL corpus not found (expected at ../shared/idl-corpus from the workspace \
                 root, or set DDS_IDL_CORPUS)"
            );
            return;
        }
        let path = PathBuf::from(env!("OUT_DIR")).join(format!("{stem}.idlc-error"));
        let why =
            std::fs::read_to_string(&path).unwrap_or_else(|e| format!("({}: {e})", path.display()));
        panic!("{fixture}: idlc did not generate {stem}.rs:\n{why}");
    }

    fn fixture(name: &str) -> Value {
        let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("fixtures/idlc-golden")
            .join(format!("{name}.json"));
        let text =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
    }

    fn unhex(s: &str) -> Vec<u8> {
        assert!(s.len() & 1 == 0, "odd hex length");
        (0..s.len())
            .step_by(2)
            .map(|i| u8::from_str_radix(&s[i..i + 2], 16).expect("hex digit"))
            .collect()
    }

    fn hex(b: &[u8]) -> String {
        b.iter().map(|x| format!("{x:02x}")).collect()
    }

    /// "xcdr2_be" -> (Xcdr2, BigEndian); key hash tags ("xcdr1") carry no order.
    fn encoding(tag: &str) -> (XcdrVersion, ByteOrder) {
        let version = if tag.starts_with("xcdr1") {
            XcdrVersion::Xcdr1
        } else {
            XcdrVersion::Xcdr2
        };
        let order = if tag.ends_with("_be") {
            ByteOrder::BigEndian
        } else {
            ByteOrder::LittleEndian
        };
        (version, order)
    }

    fn describe(expected: &[u8], got: &[u8]) -> String {
        let at = expected
            .iter()
            .zip(got)
            .position(|(a, b)| a != b)
            .unwrap_or(expected.len().min(got.len()));
        format!(
            "first difference at byte {at} (lengths {} vs {})\n      expected {}\n      got      {}",
            expected.len(),
            got.len(),
            hex(expected),
            hex(got)
        )
    }

    fn entries(v: &Value) -> Vec<(String, Vec<u8>)> {
        v.as_object()
            .map(|m| {
                m.iter()
                    .map(|(k, v)| (k.clone(), unhex(v.as_str().unwrap_or_default())))
                    .collect()
            })
            .unwrap_or_default()
    }

    /// The type's constants against libddsc's view of the same IDL type.
    fn check_constants<T: DdsType>(fx: &Value, bad: &mut Vec<String>) {
        let typename = fx["typename"].as_str().unwrap_or_default();
        if T::TYPE_NAME != typename {
            bad.push(format!("TYPE_NAME {:?}, IDL {typename:?}", T::TYPE_NAME));
        }
        let ext = match fx["extensibility"].as_str() {
            Some("final") => Extensibility::Final,
            Some("appendable") => Extensibility::Appendable,
            _ => Extensibility::Mutable,
        };
        if T::EXTENSIBILITY != ext {
            bad.push(format!(
                "EXTENSIBILITY {:?}, expected {ext:?}",
                T::EXTENSIBILITY
            ));
        }
        let keyed = fx["keyed"].as_bool().unwrap_or_default();
        if T::IS_KEYED != keyed {
            bad.push(format!("IS_KEYED {}, libddsc {keyed}", T::IS_KEYED));
        }
        if let Some(v) = fx["libddsc_default_version"].as_u64() {
            let want = if v == 1 {
                XcdrVersion::Xcdr1
            } else {
                XcdrVersion::Xcdr2
            };
            if T::DEFAULT_VERSION != want {
                bad.push(format!(
                    "DEFAULT_VERSION {:?}, libddsc writes {want:?} by default",
                    T::DEFAULT_VERSION
                ));
            }
        }
    }

    /// Types whose TypeInformation differs from Cyclone's Python binding for a stated reason. The check fails if
    /// one of them starts to agree, so the list stays true.
    const KNOWN_TYPE_INFORMATION: &[(&str, &str)] = &[
        ("InnerStructureHelperChildChild", "the binding's subclass inherits @nested from its base class; the IDL does not mark the derived struct @nested, and Cyclone's idlc, like us, does not inherit it (idlc_typedefs::structs_deriving_from_nested_structs_are_not_nested)"),
        ("test_struct_inherit_mutable_keys", "the binding's subclass inherits @nested from its base class; the IDL does not mark the derived struct @nested, and Cyclone's idlc, like us, does not inherit it (idlc_typedefs::structs_deriving_from_nested_structs_are_not_nested)"),
    ];

    /// Our TypeInformation and TypeMapping against Cyclone's for the same IDL type
    /// (`fixtures/typeinfo/idlc.<fixture>.json`, from `scripts/golden/typeinfo.py`); see
    /// [`KNOWN_TYPE_INFORMATION`].
    fn check_type_information<T: DdsType>(name: &str, bad: &mut Vec<String>) {
        round_trip::<T>(bad);
        let mut differs = Vec::new();
        type_information_differences::<T>(name, &mut differs);
        match KNOWN_TYPE_INFORMATION.iter().find(|(n, _)| *n == name) {
            Some((_, why)) if differs.is_empty() => bad.push(format!(
                "type information is listed as differing ({why}) but agrees: drop it from the list"
            )),
            Some(_) => {}
            None => bad.extend(differs),
        }
    }

    /// The derived type's objects -> a dynamic type -> its objects: the same bytes.
    fn round_trip<T: DdsType>(bad: &mut Vec<String>) {
        use dds_runtime::xtypes::dynamic::DynamicType;
        use dds_runtime::xtypes::typeobject::from_bytes;
        let (Some(info), Some(map)) = (T::type_information(), T::type_mapping()) else {
            return bad.push("no type information".into());
        };
        let rebuilt = match (from_bytes(info), from_bytes(map)) {
            (Ok(i), Ok(m)) => DynamicType::from_type_mapping(&i, &m)
                .map_err(|e| e.to_string())
                .and_then(|t| t.type_support().map_err(|e| e.to_string())),
            _ => Err("our type information does not decode".into()),
        };
        match rebuilt {
            Ok(s) if s.information_bytes == info && s.mapping_bytes == map => {}
            Ok(_) => bad.push("the type objects of its dynamic type differ".into()),
            Err(e) => bad.push(format!("no dynamic type support: {e}")),
        }
    }

    fn type_information_differences<T: DdsType>(name: &str, bad: &mut Vec<String>) {
        let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("fixtures/typeinfo")
            .join(format!("idlc.{name}.json"));
        let text =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let fx: Value = serde_json::from_str(&text).expect("typeinfo json");
        let ours = [T::type_information(), T::type_mapping()];
        for (what, mine) in ["type_information", "type_mapping"].into_iter().zip(ours) {
            let want = unhex(fx[what].as_str().unwrap_or_default());
            match mine {
                Some(got) if got == want.as_slice() => {}
                Some(got) if what == "type_mapping" => bad.push(format!(
                    "{what}: {}{}",
                    describe(&want, got),
                    super::explain::explain(got, &hex(&want))
                )),
                Some(got) => bad.push(format!("{what}: {}", describe(&want, got))),
                None => bad.push(format!("{what}: none")),
            }
        }
    }

    /// Checks one type against its fixture; panics listing every mismatch.
    pub fn check<T: DdsType + PartialEq + Debug>(name: &str, samples: Vec<(&str, T)>) {
        let fx = fixture(name);
        let mut bad = Vec::new();
        let mut checked = 0usize;
        check_constants::<T>(&fx, &mut bad);
        check_type_information::<T>(name, &mut bad);
        let keyed = fx["keyed"].as_bool().unwrap_or_default();

        let fixture_samples = fx["samples"].as_array().cloned().unwrap_or_default();
        let names: Vec<_> = fixture_samples
            .iter()
            .map(|s| s["name"].as_str().unwrap_or_default())
            .collect();
        let ours: Vec<_> = samples.iter().map(|(n, _)| *n).collect();
        assert_eq!(
            names, ours,
            "{name}: the samples here and in the fixture differ"
        );

        for ((sname, value), fs) in samples.iter().zip(&fixture_samples) {
            let here = format!("{name}/{sname}");
            for (tag, want) in entries(&fs["data"]) {
                let (version, order) = encoding(&tag);
                let mut out = Vec::new();
                checked += 2;
                match cdr::serialize(value, version, order, &mut out) {
                    Ok(()) if out == want => {}
                    Ok(()) => {
                        bad.push(format!("{here} {tag} serialize: {}", describe(&want, &out)))
                    }
                    Err(e) => bad.push(format!("{here} {tag} serialize: error {e}")),
                }
                match cdr::deserialize::<T>(&want) {
                    Ok(v) if &v == value => {}
                    Ok(v) => bad.push(format!("{here} {tag} deserialize: got {v:?}")),
                    Err(e) => bad.push(format!("{here} {tag} deserialize: error {e}")),
                }
            }
            for (tag, bytes) in entries(&fs["decode_also"]) {
                checked += 1;
                match cdr::deserialize::<T>(&bytes) {
                    Ok(v) if &v == value => {}
                    Ok(v) => bad.push(format!("{here} {tag} deserialize (decode_also): got {v:?}")),
                    Err(e) => {
                        bad.push(format!("{here} {tag} deserialize (decode_also): error {e}"))
                    }
                }
            }
            if !keyed {
                continue;
            }
            for (tag, want) in entries(&fs["key"]) {
                let (version, order) = encoding(&tag);
                let mut out = Vec::new();
                checked += 2;
                match cdr::serialize_key(value, version, order, &mut out) {
                    Ok(()) if out == want => {}
                    Ok(()) => bad.push(format!(
                        "{here} {tag} serialize_key: {}",
                        describe(&want, &out)
                    )),
                    Err(e) => bad.push(format!("{here} {tag} serialize_key: error {e}")),
                }
                // libddsc's key payload decodes to a key-only sample that encodes to the same key again.
                let mut again = Vec::new();
                match cdr::deserialize_key::<T>(&want)
                    .map_err(|e| e.to_string())
                    .and_then(|k| {
                        cdr::serialize_key(&k, version, order, &mut again)
                            .map_err(|e| e.to_string())
                    }) {
                    Ok(()) if again == want => {}
                    Ok(()) => bad.push(format!(
                        "{here} {tag} deserialize_key+serialize_key: {}",
                        describe(&want, &again)
                    )),
                    Err(e) => bad.push(format!("{here} {tag} deserialize_key: error {e}")),
                }
            }
            for (tag, want) in entries(&fs["key_hash"]) {
                let (version, _) = encoding(&tag);
                checked += 1;
                match cdr::key_hash(value, version) {
                    Ok(h) if h.as_slice() == want.as_slice() => {}
                    Ok(h) => bad.push(format!(
                        "{here} {tag} key_hash: expected {}, got {}",
                        hex(&want),
                        hex(&h)
                    )),
                    Err(e) => bad.push(format!("{here} {tag} key_hash: error {e}")),
                }
            }
        }
        assert!(checked > 0, "{name}: the fixture holds nothing to check");
        assert!(
            bad.is_empty(),
            "{name} ({}: {}): {} of {} checks failed:\n  {}",
            fx["corpus_file"].as_str().unwrap_or_default(),
            fx["corpus_type"].as_str().unwrap_or_default(),
            bad.len(),
            checked + 6, // and the four constants, the type information and mapping
            bad.join("\n  ")
        );
    }
}

// ---------------------------------------------------------------- omg-dds-rtps/srcCxx/shape.idl

golden! { shape_type: "shape" / "ShapeType" => shape::ShapeType,
    "blue" => shape::ShapeType {
        color: "BLUE".into(), x: 10, y: 20, shapesize: 30, additional_payload_size: vec![],
    },
    "payload" => shape::ShapeType {
        color: "RED".into(), x: -5, y: 250, shapesize: 1,
        additional_payload_size: vec![1, 2, 3, 255, 0],
    },
    "long_color" => shape::ShapeType {
        color: "C".repeat(128), x: 0, y: 0, shapesize: 0, additional_payload_size: vec![7],
    },
}

// ---------------------------------------------------------------- cyclonedds/src/tools/ddsperf/ddsperf_types.idl

golden! { ddsperf_keyed_seq: "ddsperf_types" / "KeyedSeq" => ddsperf::KeyedSeq,
    "empty" => ddsperf::KeyedSeq { seq: 1, keyval: 42, baggage: vec![] },
    "baggage" => ddsperf::KeyedSeq { seq: u32::MAX, keyval: 7, baggage: (0..13).collect() },
}

golden! { ddsperf_keyed256: "ddsperf_types" / "Keyed256" => ddsperf::Keyed256,
    "ramp" => ddsperf::Keyed256 {
        seq: 3,
        keyval: 0x0102_0304,
        baggage: std::array::from_fn(|i| ((i * 7) & 0xff) as u8),
    },
}

golden! { ddsperf_cpu_stats: "ddsperf_types" / "CPUStats" => ddsperf::CPUStats,
    "two_threads" => ddsperf::CPUStats {
        hostname: "node-1".into(), pid: 4242, maxrss: 1.5e6, vcsw: 10, ivcsw: 2, some_above: true,
        cpu: vec![
            ddsperf::CPUStatThread { name: "main".into(), u_pct: 12, s_pct: 3 },
            ddsperf::CPUStatThread { name: "recv".into(), u_pct: 0, s_pct: 100 },
        ],
    },
    "empty" => ddsperf::CPUStats::default(),
}

// ---------------------------------------------------------------- eprosima-dds-types-test/IDL

golden! { eprosima_root: "structures" / "root" => structures::Root,
    "basic" => structures::Root {
        var_root1: structures::Root1 {
            foo_struct: structures::testing_1::Foo { a: 1, b: -2 },
            c: 0.5,
        },
        var_root2: structures::Root2 {
            foo_struct: structures::testing_2::Foo { d: true },
            bar_struct: structures::Bar { e: -1.25 },
        },
    },
}

golden! { eprosima_inheritance_child_child:
    "inheritance" / "InnerStructureHelperChildChild" => inheritance::InnerStructureHelperChildChild,
    "basic" => inheritance::InnerStructureHelperChildChild {
        base: inheritance::InnerStructureHelperChild {
            base: inheritance::InnerStructureHelper { field1: -7, field2: 2.5 },
            var_child_longlong: i64::MIN,
            var_child_ulonglong: u64::MAX,
        },
        var_child_childlonglong2: 1,
        var_childchild_ulonglong2: 2,
    },
}

golden! { eprosima_enum_structure:
    "enumerations" / "EnumStructure" => enumerations::EnumStructure,
    "mixed" => enumerations::EnumStructure {
        var_inner_enum_helper: enumerations::InnerEnumHelper::EnumValue3,
        var_scoped_inner_enum_helper: enumerations::test::InnerEnumHelper::EnumValue2,
    },
    "first" => enumerations::EnumStructure {
        var_inner_enum_helper: enumerations::InnerEnumHelper::EnumValue1,
        var_scoped_inner_enum_helper: enumerations::test::InnerEnumHelper::EnumValue1,
    },
}

golden! { eprosima_enum_with_values:
    "enumerations" / "EnumWithValuesStructure" => enumerations::EnumWithValuesStructure,
    "negative" => enumerations::EnumWithValuesStructure {
        var_enumwithvalues: enumerations::EnumWithValues::EnumValue1,
    },
    "positive" => enumerations::EnumWithValuesStructure {
        var_enumwithvalues: enumerations::EnumWithValues::EnumValue3,
    },
}

golden! { eprosima_bitmask: "enumerations" / "BitMaskStructure" => enumerations::BitMaskStructure,
    "some" => enumerations::BitMaskStructure {
        var_inner_bit_mask_helper: enumerations::InnerBitMaskHelper::FLAG0
            | enumerations::InnerBitMaskHelper::FLAG6,
    },
    "none" => enumerations::BitMaskStructure::default(),
}

golden! { eprosima_bounded_bitmask:
    "enumerations" / "BoundedBitMaskStructure" => enumerations::BoundedBitMaskStructure,
    "all" => enumerations::BoundedBitMaskStructure {
        var_inner_bounded_bit_mask_helper: enumerations::InnerBoundedBitMaskHelper::all(),
    },
    "one" => enumerations::BoundedBitMaskStructure {
        var_inner_bounded_bit_mask_helper: enumerations::InnerBoundedBitMaskHelper::BFLAG4,
    },
}

// No sample of case -2: libddsc 11.0.1 cannot read it (FINDINGS.md).
golden! { eprosima_union_discriminator_short:
    "unions" / "UnionDiscriminatorShort" => unions::UnionDiscriminatorShort,
    "first" => unions::UnionDiscriminatorShort {
        var_union_discriminator_short: unions::UnionDiscriminatorShort2::First(5),
    },
}

golden! { eprosima_union_discriminator_enum:
    "unions" / "UnionDiscriminatorEnum" => unions::UnionDiscriminatorEnum,
    "first" => unions::UnionDiscriminatorEnum {
        var_union_discriminator_enum: unions::UnionDiscriminatorEnum2::First(-1),
    },
    "second" => unions::UnionDiscriminatorEnum {
        var_union_discriminator_enum: unions::UnionDiscriminatorEnum2::Second(i64::MAX),
    },
    // written with ENUM_VALUE_3, the first enumerator no label uses
    "default" => unions::UnionDiscriminatorEnum {
        var_union_discriminator_enum: unions::UnionDiscriminatorEnum2::Third(0xab),
    },
}

golden! { eprosima_union_several_fields_with_default:
    "unions" / "UnionSeveralFieldsWithDefault" => unions::UnionSeveralFieldsWithDefault,
    "struct" => several(unions::UnionSeveralFieldsWithDefault2::A(unions::InnerStructureHelper {
        field1: 1,
        field2: 2.0,
    })),
    "bounded_string" => several(unions::UnionSeveralFieldsWithDefault2::C(BoundedString::from(
        "ten chars!",
    ))),
    "array" => several(unions::UnionSeveralFieldsWithDefault2::D([1, -1])),
    "sequence" => several(unions::UnionSeveralFieldsWithDefault2::E(vec![3, 2, 1])),
    // written with discriminator -1, the first value no label uses
    "default" => several(unions::UnionSeveralFieldsWithDefault2::F(BoundedSeq::from(vec![
        10, -20, 30,
    ]))),
}

#[cfg(idlc_ok = "unions")]
fn several(u: unions::UnionSeveralFieldsWithDefault2) -> unions::UnionSeveralFieldsWithDefault {
    unions::UnionSeveralFieldsWithDefault {
        var_union_several_fields_with_default: u,
    }
}

golden! { eprosima_keyed_inheritance: "key" / "KeyedInheritanceStruct" => key::KeyedInheritanceStruct,
    "basic" => key::KeyedInheritanceStruct {
        base: key::KeyedShortStruct { key_short: -3, var_short: 4 },
        key_str: "k".into(),
        var_str: "v".into(),
    },
}

golden! { eprosima_keyed_final: "key" / "KeyedFinal" => key::KeyedFinal,
    "basic" => key::KeyedFinal { key_long: 1, key_short: 2, key_string: "three".into() },
    "long_string" => key::KeyedFinal {
        key_long: -1, key_short: -1, key_string: "a key longer than sixteen".into(),
    },
}

golden! { eprosima_keyed_mutable: "key" / "KeyedMutable" => key::KeyedMutable,
    "basic" => key::KeyedMutable { key_long: 1, key_short: 2, key_string: "three".into() },
    "empty" => key::KeyedMutable::default(),
}

golden! { eprosima_mutable_inheritance:
    "mutable" / "MutableInheritanceStruct" => mutable::MutableInheritanceStruct,
    "basic" => mutable::MutableInheritanceStruct {
        base: mutable::MutableShortStruct { var_short: -1 },
        var_str: "mutable".into(),
    },
}

// An unannotated struct takes its base's extensibility (as Cyclone's idlc has it): mutable here.
golden! {
    eprosima_mutable_extensibility_inheritance:
    "mutable" / "MutableExtensibilityInheritance" => mutable::MutableExtensibilityInheritance,
    "basic" => mutable::MutableExtensibilityInheritance {
        base: mutable::MutableShortStruct { var_short: -1 },
        var_long: 0x0102_0304,
    },
}

// The same, final (eprosima final.idl).
golden! {
    eprosima_final_extensibility_inheritance:
    "final" / "FinalExtensibilityInheritance" => final_::FinalExtensibilityInheritance,
    "basic" => final_::FinalExtensibilityInheritance {
        base: final_::FinalShortStruct { var_short: -1 },
        var_long: 0x0102_0304,
    },
}

golden! { eprosima_fix_id: "member_id" / "FixId" => member_id::FixId,
    "basic" => member_id::FixId { o: 1, s: -2, l: 3, ll: -4 },
}

golden! { eprosima_fix_hashid_default: "member_id" / "FixHashidDefault" => member_id::FixHashidDefault,
    "basic" => member_id::FixHashidDefault { o: 0xfe, s: -2, l: 3, ll: i64::MIN },
}

golden! { eprosima_opt_struct_align_2:
    "optional" / "opt_struct_align_2_optional" => optional::OptStructAlign2Optional,
    "absent" => optional::OptStructAlign2Optional { align: 1, value: None },
    "inner_absent" => optional::OptStructAlign2Optional {
        align: 2,
        value: Some(optional::InnerStructOptional { s: 3, l: None }),
    },
    "present" => optional::OptStructAlign2Optional {
        align: 0xffff,
        value: Some(optional::InnerStructOptional { s: -1, l: Some(7) }),
    },
}

golden! { eprosima_array_multi_dimension_short:
    "arrays" / "ArrayMultiDimensionLiteralsShort" => arrays::ArrayMultiDimensionLiteralsShort,
    // element [i][j][k] = 100*i + 10*j + k - 250, as in corpus_idl.py
    "ramp" => arrays::ArrayMultiDimensionLiteralsShort {
        var_array_short: std::array::from_fn(|i| {
            std::array::from_fn(|j| std::array::from_fn(|k| (100 * i + 10 * j + k) as i16 - 250))
        }),
    },
}

golden! { eprosima_sequence_union: "sequences" / "SequenceUnion" => sequences::SequenceUnion,
    "mixed" => sequences::SequenceUnion {
        var_sequence_union: vec![
            sequences::InnerUnionHelper::LongValue(-9),
            sequences::InnerUnionHelper::FloatValue(0.5),
            sequences::InnerUnionHelper::ShortValue(77),
        ],
    },
    "empty" => sequences::SequenceUnion::default(),
}

golden! { eprosima_sequence_of_aliased_bounded_sequences:
    "sequences" / "NoCommon_Module.My_Structure" => sequences::no_common_module::MyStructure,
    "basic" => sequences::no_common_module::MyStructure {
        list: vec![
            BoundedSeq::from(vec!['a', 'b']),
            BoundedSeq::from(vec![]),
            BoundedSeq::from(vec!['x'; 20]),
        ],
    },
}

// ---------------------------------------------------------------- cyclonedds/src/core/ddsc/tests/CdrStreamKeyExt.idl
// @key long a (0x11223344), and a member b of a nested struct (b.a = -2), keyed or not, key or not.

#[cfg(idlc_ok = "CdrStreamKeyExt")]
use key_ext::cdr_stream_key_ext as ke;

golden! { keyext_t1: "CdrStreamKeyExt" / "CdrStreamKeyExt.t1" => ke::T1,
    "basic" => ke::T1 { a: 0x1122_3344 },
}
golden! { keyext_t1a: "CdrStreamKeyExt" / "CdrStreamKeyExt.t1a" => ke::T1a,
    "basic" => ke::T1a { a: Box::new(0x1122_3344) },
}
golden! { keyext_t2: "CdrStreamKeyExt" / "CdrStreamKeyExt.t2" => ke::T2,
    "basic" => ke::T2 { a: 0x1122_3344 },
}
golden! { keyext_t3: "CdrStreamKeyExt" / "CdrStreamKeyExt.t3" => ke::T3,
    "basic" => ke::T3 { a: 0x1122_3344 },
}
golden! { keyext_t4: "CdrStreamKeyExt" / "CdrStreamKeyExt.t4" => ke::T4,
    "basic" => ke::T4 { a: 0x1122_3344, b: ke::Nested4 { a: -2 } },
}
golden! { keyext_t4a: "CdrStreamKeyExt" / "CdrStreamKeyExt.t4a" => ke::T4a,
    "basic" => ke::T4a { a: 0x1122_3344, b: ke::Nested4a { a: -2 } },
}
golden! { keyext_t4b: "CdrStreamKeyExt" / "CdrStreamKeyExt.t4b" => ke::T4b,
    "basic" => ke::T4b { a: 0x1122_3344, b: ke::Nested4b { a: -2 } },
}
golden! { keyext_t5: "CdrStreamKeyExt" / "CdrStreamKeyExt.t5" => ke::T5,
    "basic" => ke::T5 { a: 0x1122_3344, b: ke::Nested5 { a: -2 } },
}
golden! { keyext_t5a: "CdrStreamKeyExt" / "CdrStreamKeyExt.t5a" => ke::T5a,
    "basic" => ke::T5a { a: 0x1122_3344, b: ke::Nested5a { a: -2 } },
}
golden! { keyext_t5b: "CdrStreamKeyExt" / "CdrStreamKeyExt.t5b" => ke::T5b,
    "basic" => ke::T5b { a: 0x1122_3344, b: ke::Nested5b { a: -2 } },
}
golden! { keyext_t6: "CdrStreamKeyExt" / "CdrStreamKeyExt.t6" => ke::T6,
    "basic" => ke::T6 { a: 0x1122_3344, b: ke::Nested6 { a: -2 } },
}
golden! { keyext_t6a: "CdrStreamKeyExt" / "CdrStreamKeyExt.t6a" => ke::T6a,
    "basic" => ke::T6a { a: 0x1122_3344, b: ke::Nested6a { a: -2 } },
}
golden! { keyext_t6b: "CdrStreamKeyExt" / "CdrStreamKeyExt.t6b" => ke::T6b,
    "basic" => ke::T6b { a: 0x1122_3344, b: ke::Nested6b { a: -2 } },
}

// ---------------------------------------------------------------- cyclonedds/src/core/ddsc/tests/CdrStreamSignedUnion.idl
// Negative labels only on the 32-bit discriminator: libddsc 11.0.1 cannot read the others (FINDINGS.md).

#[cfg(idlc_ok = "CdrStreamSignedUnion")]
use signed_union::cdr_stream_signed_union as su;

golden! { cdrstream_signed_union_t4: "CdrStreamSignedUnion" / "CdrStreamSignedUnion.t4" => su::T4,
    "positive" => su::T4 { f1: su::T1::F3(5), f2: su::T2::F4(1.5), f3: su::T3::F4(2.5) },
    "max" => su::T4 { f1: su::T1::F4(0.25), f2: su::T2::F3(-7), f3: su::T3::F3(7) },
    "minus_one_32" => su::T4 { f1: su::T1::F3(1), f2: su::T2::F3(2), f3: su::T3::F2(-3) },
    "min_32" => su::T4 { f1: su::T1::F4(-0.5), f2: su::T2::F4(0.5), f3: su::T3::F1('c') },
}

// ---------------------------------------------------------------- cyclonedds/src/tools/idlc/xtests

golden! { xtest_struct_keys: "test_struct_keys" / "test_struct_keys" => struct_keys::TestStructKeys,
    // the values of the C part of the same file
    "xtest" => struct_keys::TestStructKeys {
        f1: struct_keys::U::U1(struct_keys::E::E2),
        f2: 'a',
        f3: struct_keys::U::U1(struct_keys::E::E3),
        f4: ['b', 'c'],
    },
    // `ud` is written with discriminator -1
    "default" => struct_keys::TestStructKeys {
        f1: struct_keys::U::Ud(-5),
        f2: 'z',
        f3: struct_keys::U::U1(struct_keys::E::E1),
        f4: ['\0', 'y'],
    },
}

golden! { xtest_struct_inherit_mutable_keys:
    "test_struct_inherit_mutable_keys" / "test_struct_inherit_mutable_keys"
        => inherit_mutable_keys::TestStructInheritMutableKeys,
    "xtest" => inherit_mutable_keys::TestStructInheritMutableKeys {
        base: inherit_mutable_keys::TBase {
            base: inherit_mutable_keys::TBaseBase { bb1: 3 },
            b1: 2,
        },
        f1: 1,
    },
}

// ---------------------------------------------------------------- rti-ros-data-types
// Each file twice: with our idlc's default (@appendable) and with Cyclone idlc's (@final); same samples.

macro_rules! pose_stamped_basic {
    ($m:ident) => {{
        use $m::geometry_msgs::msg::{Point, Pose, PoseStamped, Quaternion};
        use $m::std_msgs::msg::{Header, Time};
        PoseStamped {
            header: Header {
                stamp: Time {
                    sec: 1_700_000_000,
                    nanosec: 123_456_789,
                },
                frame_id: "map".into(),
            },
            pose: Pose {
                position: Point {
                    x: 1.0,
                    y: -2.0,
                    z: 3.5,
                },
                orientation: Quaternion {
                    x: 0.0,
                    y: 0.0,
                    z: 0.5f64.sqrt(),
                    w: 0.5f64.sqrt(),
                },
            },
        }
    }};
}

macro_rules! imu_basic {
    ($m:ident) => {{
        use $m::geometry_msgs::msg::{Quaternion, Vector3};
        use $m::std_msgs::msg::{Header, Time};
        let mut angular = [0.0; 9];
        angular[0] = -1.0;
        $m::sensor_msgs::msg::Imu {
            header: Header {
                stamp: Time {
                    sec: -1,
                    nanosec: 999_999_999,
                },
                frame_id: "imu_link".into(),
            },
            orientation: Quaternion {
                x: 0.0,
                y: 0.0,
                z: 0.0,
                w: 1.0,
            },
            orientation_covariance: std::array::from_fn(|i| i as f64),
            angular_velocity: Vector3 {
                x: 0.1,
                y: 0.2,
                z: 0.3,
            },
            angular_velocity_covariance: angular,
            linear_acceleration: Vector3 {
                x: 0.0,
                y: 0.0,
                z: 9.81,
            },
            linear_acceleration_covariance: std::array::from_fn(|i| 0.5f64.powi(i as i32)),
        }
    }};
}

macro_rules! diagnostic_status_basic {
    ($m:ident) => {{
        use $m::diagnostic_msgs::msg::{DiagnosticStatus, KeyValue};
        DiagnosticStatus {
            level: 2,
            name: "motor".into(),
            message: "overheat".into(),
            hardware_id: "hw-7".into(),
            values: vec![
                KeyValue {
                    key: "temp".into(),
                    value: "97".into(),
                },
                KeyValue {
                    key: "limit".into(),
                    value: "90".into(),
                },
            ],
        }
    }};
}

golden! { ros_pose_stamped:
    "PoseStamped" / "geometry_msgs.msg.PoseStamped" => pose_stamped::geometry_msgs::msg::PoseStamped,
    "basic" => pose_stamped_basic!(pose_stamped),
}

golden! { ros_imu: "Imu" / "sensor_msgs.msg.Imu" => imu::sensor_msgs::msg::Imu,
    "basic" => imu_basic!(imu),
}

golden! { ros_diagnostic_status:
    "DiagnosticStatus" / "diagnostic_msgs.msg.DiagnosticStatus"
        => diagnostic_status::diagnostic_msgs::msg::DiagnosticStatus,
    "basic" => diagnostic_status_basic!(diagnostic_status),
    "empty" => Default::default(),
}

golden! { ros_pose_stamped_final:
    "final/PoseStamped" / "geometry_msgs.msg.PoseStamped.final"
        => pose_stamped_final::geometry_msgs::msg::PoseStamped,
    "basic" => pose_stamped_basic!(pose_stamped_final),
}

golden! { ros_imu_final: "final/Imu" / "sensor_msgs.msg.Imu.final" => imu_final::sensor_msgs::msg::Imu,
    "basic" => imu_basic!(imu_final),
}

golden! { ros_diagnostic_status_final:
    "final/DiagnosticStatus" / "diagnostic_msgs.msg.DiagnosticStatus.final"
        => diagnostic_status_final::diagnostic_msgs::msg::DiagnosticStatus,
    "basic" => diagnostic_status_basic!(diagnostic_status_final),
    "empty" => Default::default(),
}
