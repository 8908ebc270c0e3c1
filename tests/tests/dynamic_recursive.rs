//! Recursive *dynamic* types: built with a forward reference, imported from the strongly connected component
//! objects of Cyclone DDS 11.0.1's Python binding (`tests/fixtures/typeinfo-recursive`), and written as IDL.
//! Their type objects must be byte-identical to the binding's; their values must decode from the binding's
//! serializer (`tests/fixtures/samples-recursive`, `scripts/golden/recursive_samples.py`) and encode to the
//! bytes of the derived types; hostile nesting is refused at the decoder's depth limit.

use std::path::PathBuf;

use dds_runtime::cdr::{serialize, ByteOrder, DecodeErrorKind, XcdrVersion};
use dds_runtime::xtypes::dynamic::{
    types_from_idl, DynamicData, DynamicType, MemberBuilder, Primitive, StructBuilder,
};
use dds_runtime::xtypes::typeobject::{from_bytes, TypeIdentifier, TypeInformation, TypeMapping};
use serde_json::Value as Json;

mod recursive_types;
use recursive_types::*;

const TYPES: [&str; 6] = ["Node", "A", "B", "Tree", "Holder", "Chain"];

fn fixture_dir(dir: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures")
        .join(dir)
}

fn read_json(path: PathBuf) -> Json {
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).expect("json")
}

fn unhex(s: &str) -> Vec<u8> {
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).expect("hex"))
        .collect()
}

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

/// The binding's TypeInformation and TypeMapping bytes of `name` (hex).
fn golden(name: &str) -> (String, String) {
    let fx = read_json(fixture_dir("typeinfo-recursive").join(format!("{name}.json")));
    let s = |k: &str| fx[k].as_str().expect(k).to_string();
    (s("type_information"), s("type_mapping"))
}

/// The type `name` from the binding's objects.
fn imported(name: &str) -> DynamicType {
    let (info, map) = golden(name);
    let info: TypeInformation = from_bytes(&unhex(&info)).expect("TypeInformation");
    let map: TypeMapping = from_bytes(&unhex(&map)).expect("TypeMapping");
    DynamicType::from_type_mapping(&info, &map).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn long() -> DynamicType {
    DynamicType::primitive(Primitive::Int32)
}

/// The types of `scripts/golden/rec_golden`, built with the builder.
struct Built {
    node: DynamicType,
    a: DynamicType,
    b: DynamicType,
    tree: DynamicType,
    holder: DynamicType,
    chain: DynamicType,
}

fn built() -> Built {
    use dds_runtime::cdr::Extensibility;
    let node = DynamicType::recursive("Rec::Node", |node| {
        StructBuilder::new("Rec::Node")
            .extensibility(Extensibility::Final)
            .member("value", long())
            .member("children", DynamicType::sequence(node, None))
            .build()
    })
    .unwrap();
    // A and B: one component; B is built first, with a forward reference to A.
    let fwd_a = DynamicType::forward("Rec::A");
    let b = StructBuilder::new("Rec::B")
        .extensibility(Extensibility::Final)
        .member("y", long())
        .member("as_", DynamicType::sequence(fwd_a.clone(), None))
        .build()
        .unwrap();
    let a = StructBuilder::new("Rec::A")
        .extensibility(Extensibility::Final)
        .member("x", long())
        .member("bs", DynamicType::sequence(b.clone(), None))
        .build()
        .unwrap();
    fwd_a.define(a.clone()).unwrap();
    let leaf = StructBuilder::new("Rec::Leaf")
        .extensibility(Extensibility::Final)
        .member("name", DynamicType::string(None))
        .build()
        .unwrap();
    let tree = DynamicType::recursive("Rec::Tree", |tree| {
        StructBuilder::new("Rec::Tree")
            .extensibility(Extensibility::Appendable)
            .member("v", long())
            .member("leaf", leaf)
            .member("kids", DynamicType::sequence(tree, Some(4)))
            .build()
    })
    .unwrap();
    let holder = StructBuilder::new("Rec::Holder")
        .extensibility(Extensibility::Final)
        .with(MemberBuilder::new("id", long()).key())
        .member("root", node.clone())
        .member("a", a.clone())
        .build()
        .unwrap();
    let chain = DynamicType::recursive("Rec::Chain", |chain| {
        StructBuilder::new("Rec::Chain")
            .extensibility(Extensibility::Mutable)
            .member("v", long())
            .with(MemberBuilder::new("next", chain).optional())
            .build()
    })
    .unwrap();
    Built {
        node,
        a,
        b,
        tree,
        holder,
        chain,
    }
}

fn by_name<'a>(b: &'a Built, name: &str) -> &'a DynamicType {
    match name {
        "Node" => &b.node,
        "A" => &b.a,
        "B" => &b.b,
        "Tree" => &b.tree,
        "Holder" => &b.holder,
        "Chain" => &b.chain,
        other => panic!("no type {other}"),
    }
}

fn same_as_the_binding(name: &str, ty: &DynamicType, how: &str) {
    let s = ty
        .type_support()
        .unwrap_or_else(|e| panic!("{name} ({how}): {e}"));
    let (info, map) = golden(name);
    assert_eq!(
        hex(&s.information_bytes),
        info,
        "{name} ({how}): TypeInformation"
    );
    assert_eq!(hex(&s.mapping_bytes), map, "{name} ({how}): TypeMapping");
}

#[test]
fn built_recursive_types_have_the_bindings_type_objects() {
    let b = built();
    for name in TYPES {
        same_as_the_binding(name, by_name(&b, name), "builder");
    }
    let TypeIdentifier::StronglyConnected(scc) =
        b.node.type_support().unwrap().complete_id().clone()
    else {
        panic!("Node: not a component id")
    };
    assert_eq!((scc.scc_length, scc.scc_index), (1, 1));
}

#[test]
fn component_identifiers_import_to_the_same_types() {
    let b = built();
    for name in TYPES {
        let ty = imported(name);
        // `to_object` of the imported type gives back the binding's bytes ...
        same_as_the_binding(name, &ty, "imported");
        // ... and it is the type the builder makes (structural equality ends on the cycles).
        assert_eq!(&ty, by_name(&b, name), "{name}");
    }
    assert_ne!(imported("Node"), imported("Tree"));
    assert_ne!(b.a, b.b);
}

#[test]
fn recursive_types_written_as_idl_compile_back_to_the_same_objects() {
    let b = built();
    // Our IDL front end (as Cyclone's idlc) takes a member `@optional Chain next` inside `Chain` for a value of
    // infinite size (idlc::E0207: only `@external` or a sequence break a cycle there), so `Chain` is left out.
    let chain = imported("Chain").to_idl();
    let e = types_from_idl("rec.idl", &chain).unwrap_err();
    assert!(
        e.to_string().contains("E0207") || e.to_string().contains("infinite"),
        "{e}"
    );
    for name in TYPES.into_iter().filter(|n| *n != "Chain") {
        let ty = imported(name);
        let idl = ty.to_idl();
        let types =
            types_from_idl("rec.idl", &idl).unwrap_or_else(|e| panic!("{name}: {e}\n{idl}"));
        let back = types
            .get(&format!("Rec::{name}"))
            .unwrap_or_else(|| panic!("{name}: not in\n{idl}"));
        same_as_the_binding(name, back, "IDL");
        assert_eq!(back, by_name(&b, name), "{name}:\n{idl}");
        assert_eq!(back.to_idl(), idl, "{name}: a fixed point");
    }
    let idl = imported("B").to_idl();
    assert!(idl.contains("struct B;"), "B uses A, which uses B:\n{idl}");
}

/// Encodes a derived value, then checks the dynamic type decodes it to `json` and encodes the same bytes.
fn same_as_the_derive<T: dds_runtime::cdr::DdsType>(ty: &DynamicType, v: &T, json: &Json) {
    for version in [XcdrVersion::Xcdr1, XcdrVersion::Xcdr2] {
        for order in [ByteOrder::LittleEndian, ByteOrder::BigEndian] {
            let mut derived = Vec::new();
            serialize(v, version, order, &mut derived).unwrap();
            let d = DynamicData::deserialize(ty, &derived)
                .unwrap_or_else(|e| panic!("{ty:?} {version:?} {order:?}: {e}"));
            assert_eq!(&d.to_json(), json, "{ty:?} {version:?} {order:?}");
            let mut ours = Vec::new();
            d.serialize(version, order, &mut ours).unwrap();
            assert_eq!(hex(&ours), hex(&derived), "{ty:?} {version:?} {order:?}");
        }
    }
}

#[test]
fn the_bindings_bytes_decode_to_its_values_and_match_the_derive() {
    let doc = read_json(fixture_dir("samples-recursive").join("samples.json"));
    let samples = doc["samples"].as_array().expect("samples");
    assert_eq!(samples.len(), 5);
    for s in samples {
        let name = s["type"].as_str().unwrap();
        let ty = imported(name);
        let json = &s["json"];
        for (enc, bytes) in s["bytes"].as_object().unwrap() {
            let bytes = unhex(bytes.as_str().unwrap());
            let d = DynamicData::deserialize(&ty, &bytes)
                .unwrap_or_else(|e| panic!("{name} {enc}: {e}"));
            assert_eq!(&d.to_json(), json, "{name} {enc}");
        }
        // The value, from JSON, encodes as the derived type encodes it, and decodes back.
        let d = DynamicData::from_json(&ty, json).unwrap();
        let check = |v: &dyn Fn(&DynamicType, &Json)| v(&ty, &d.to_json());
        match name {
            "Node" => check(&|t, j| same_as_the_derive(t, &node_value(), j)),
            "A" => check(&|t, j| same_as_the_derive(t, &a_value(), j)),
            "Tree" => check(&|t, j| same_as_the_derive(t, &tree_value(), j)),
            "Holder" => check(&|t, j| {
                same_as_the_derive(
                    t,
                    &Holder {
                        id: 7,
                        root: node_value(),
                        a: a_value(),
                    },
                    j,
                )
            }),
            "Chain" => check(&|t, j| same_as_the_derive(t, &chain_value(), j)),
            other => panic!("{other}"),
        }
    }
}

fn a_value() -> A {
    A {
        x: 1,
        bs: vec![
            B {
                y: 2,
                as_: vec![A { x: 3, bs: vec![] }],
            },
            B { y: 4, as_: vec![] },
        ],
    }
}

fn tree_value() -> Tree {
    let tree = |v, name: &str, kids| Tree {
        v,
        leaf: Leaf { name: name.into() },
        kids,
    };
    tree(
        1,
        "root",
        vec![
            tree(2, "k", vec![]),
            tree(3, "", vec![tree(4, "x", vec![])]),
        ],
    )
}

fn chain_value() -> Chain {
    let link = |v, next| Chain { v, next };
    link(1, Some(Box::new(link(2, Some(Box::new(link(3, None)))))))
}

#[test]
fn hostile_nesting_is_refused_at_the_depth_limit() {
    let node = imported("Node");
    assert!(DynamicData::deserialize(&node, &nested_node_bytes(10)).is_ok());
    for depth in [100, 10_000, 1_000_000] {
        let e = DynamicData::deserialize(&node, &nested_node_bytes(depth)).unwrap_err();
        assert!(
            matches!(e.kind, DecodeErrorKind::DepthExceeded { .. }),
            "{depth}: {e}"
        );
    }
    // The encoder refuses a value nested past the limit too (a typed error, no stack overflow).
    let chain = imported("Chain");
    let mut j = serde_json::json!({"v": 0, "next": null});
    for v in 1..200 {
        j = serde_json::json!({"v": v, "next": j});
    }
    // serde_json's own recursion limit (128) stops a deeper document before it reaches us.
    let d = DynamicData::from_json(&chain, &j).unwrap();
    let mut out = Vec::new();
    assert!(d
        .serialize(XcdrVersion::Xcdr2, ByteOrder::LittleEndian, &mut out)
        .is_err());
}

#[test]
fn forward_references_are_checked() {
    // A cycle with no sequence, map or optional member has no finite value.
    let fwd = DynamicType::forward("Loop");
    let looped = StructBuilder::new("Loop")
        .member("again", fwd.clone())
        .build()
        .unwrap();
    assert!(fwd.define(looped).is_err());
    // Only an undefined forward reference of the same name can be defined, once.
    let fwd = DynamicType::forward("N");
    let other = StructBuilder::new("M").member("x", long()).build().unwrap();
    assert!(fwd.define(other).is_err());
    let n = StructBuilder::new("N")
        .with(MemberBuilder::new("next", fwd.clone()).optional())
        .build()
        .unwrap();
    fwd.define(n.clone()).unwrap();
    assert!(fwd.define(n.clone()).is_err());
    assert!(long().define(n.clone()).is_err());
    assert_eq!(fwd.resolved(), &n);
    // An undefined reference has no type objects.
    let dangling = StructBuilder::new("D")
        .member("d", DynamicType::sequence(DynamicType::forward("D"), None))
        .build()
        .unwrap();
    assert!(dangling.type_support().is_err());
}

#[test]
fn component_objects_that_do_not_hash_to_their_identifier_are_refused() {
    let (info, map) = golden("Node");
    let info: TypeInformation = from_bytes(&unhex(&info)).unwrap();
    let mut map: TypeMapping = from_bytes(&unhex(&map)).unwrap();
    // Another struct name in the complete object: the component's hash no longer covers it.
    for p in &mut map.identifier_object_pair_complete {
        let TypeIdentifier::StronglyConnected(_) = &p.type_identifier else {
            continue;
        };
        let mut bytes = dds_runtime::xtypes::typeobject::to_bytes(&p.type_object).unwrap();
        let at = bytes
            .windows(4)
            .position(|w| w == b"Node")
            .expect("the name");
        bytes[at] = b'M';
        p.type_object = from_bytes(&bytes).unwrap();
    }
    map.identifier_object_pair_minimal.clear();
    let e = DynamicType::from_type_mapping(&info, &map).unwrap_err();
    assert!(e.to_string().contains("hash"), "{e}");
}
