//! The TypeLookup service without a network: Cyclone DDS 11's own request and reply bytes (captured on the wire,
//! tests/fixtures/typelookup/README.md) decode and re-encode byte for byte, our server answers Cyclone's request
//! with exactly Cyclone's reply, a client fetches a whole type from a server (with `getTypeDependencies` paged
//! through continuation points), and hostile input is an error or is ignored, never a panic or an allocation
//! beyond its size.

use std::time::{Duration, Instant};

use dds_runtime::xtypes::store::{StoreError, StoreLimits, TypeStore};
use dds_runtime::xtypes::typelookup::*;
use dds_runtime::xtypes::typeobject::{from_bytes, TypeIdentifier, TypeInformation, TypeMapping};
use dds_runtime::xtypes::XTypesType;
use dds_runtime::DdsType;

fn fixture(name: &str) -> Vec<u8> {
    let p = format!(
        "{}/tests/fixtures/typelookup/{name}.bin",
        env!("CARGO_MANIFEST_DIR")
    );
    std::fs::read(&p).unwrap_or_else(|e| panic!("{p}: {e}"))
}

const REQUESTS: [&str; 2] = [
    "cyclone11_request_outer_complete",
    "cyclone11_request_inner_complete",
];
const REPLIES: [&str; 2] = [
    "cyclone11_reply_outer_complete",
    "cyclone11_reply_inner_complete",
];

#[test]
fn cyclone_requests_and_replies_round_trip_byte_for_byte() {
    for name in REQUESTS {
        let bytes = fixture(name);
        let req = decode_request(&bytes).unwrap();
        let Call::GetTypes(ids) = &req.call else {
            panic!("{name}: {:?}", req.call)
        };
        assert_eq!(ids.len(), 1, "{name}");
        assert!(matches!(ids[0], TypeIdentifier::Complete(_)), "{name}");
        assert!(req.instance_name.starts_with("dds.builtin.TOS."), "{name}");
        assert_eq!(encode_request(&req).unwrap(), bytes, "{name}");
    }
    for name in REPLIES {
        let bytes = fixture(name);
        let rep = decode_reply(&bytes).unwrap();
        let Return::GetTypes(Ok(out)) = &rep.return_data else {
            panic!("{name}: {:?}", rep.return_data)
        };
        assert_eq!(out.types.len(), 1, "{name}");
        assert_eq!(rep.remote_ex, RemoteExceptionCode::Ok);
        assert_eq!(encode_reply(&rep).unwrap(), bytes, "{name}");
    }
}

/// A store holding what Cyclone's replies carry (each object checked against its hash on the way in).
fn store_from_cyclone_replies() -> TypeStore {
    let mut store = TypeStore::new(StoreLimits::default());
    for name in REPLIES {
        let Return::GetTypes(Ok(out)) = decode_reply(&fixture(name)).unwrap().return_data else {
            panic!()
        };
        for p in out.types {
            assert_eq!(
                store.insert_verified(p.type_identifier, p.type_object),
                Ok(true)
            );
        }
    }
    store
}

#[test]
fn our_server_answers_cyclones_request_with_cyclones_reply() {
    let store = store_from_cyclone_replies();
    let mut server = Server::new(ServerLimits::default());
    for (req, rep) in REQUESTS.iter().zip(REPLIES) {
        let request = decode_request(&fixture(req)).unwrap();
        let reply = server
            .handle(Instant::now(), [1; 12], &store, &request)
            .unwrap();
        assert_eq!(encode_reply(&reply).unwrap(), fixture(rep), "{req}");
    }
}

#[test]
fn a_tampered_object_is_refused() {
    let Return::GetTypes(Ok(out)) = decode_reply(&fixture(REPLIES[0])).unwrap().return_data else {
        panic!()
    };
    let p = &out.types[0];
    let mut store = TypeStore::new(StoreLimits::default());
    // The other fixture's identifier with this object: the hash does not match.
    let Return::GetTypes(Ok(other)) = decode_reply(&fixture(REPLIES[1])).unwrap().return_data
    else {
        panic!()
    };
    let wrong = other.types[0].type_identifier.clone();
    assert_eq!(
        store.insert_verified(wrong, p.type_object.clone()),
        Err(StoreError::HashMismatch)
    );
    let TypeIdentifier::Complete(h) = p.type_identifier else {
        panic!()
    };
    assert_eq!(
        store.insert_verified(TypeIdentifier::Minimal(h), p.type_object.clone()),
        Err(StoreError::KindMismatch)
    );
    assert!(store.is_empty());
    // A full store refuses rather than grows.
    let mut tiny = TypeStore::new(StoreLimits {
        max_learnt: 0,
        max_learnt_bytes: 0,
    });
    assert_eq!(
        tiny.insert_verified(p.type_identifier.clone(), p.type_object.clone()),
        Err(StoreError::Full)
    );
}

#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(appendable)]
struct Leaf {
    a: i32,
    name: String,
}

#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(appendable)]
struct Middle {
    leaves: Vec<Leaf>,
    one: Leaf,
}

#[derive(DdsType, Debug, Clone, PartialEq, Default)]
struct Top {
    #[dds(key)]
    id: u32,
    m: Middle,
    extra: Vec<Middle>,
}

fn owned_store<T: XTypesType>() -> (TypeStore, TypeInformation) {
    let s = T::type_support().unwrap();
    let info: TypeInformation = from_bytes(&s.information_bytes).unwrap();
    let mapping: TypeMapping = from_bytes(&s.mapping_bytes).unwrap();
    let mut store = TypeStore::new(StoreLimits::default());
    store.add_owned(&info, &mapping);
    (store, info)
}

/// Carries every request of `client` to `server` and back, through the wire codec, until it has none left.
fn exchange(
    client: &mut Client,
    cstore: &mut TypeStore,
    server: &mut Server,
    sstore: &TypeStore,
) -> usize {
    let now = Instant::now();
    let mut rounds = 0;
    while let Some(req) = client.poll_request(now) {
        rounds += 1;
        assert!(rounds < 100, "the client keeps asking");
        let req = decode_request(&encode_request(&req).unwrap()).unwrap();
        let rep = server.handle(now, [7; 12], sstore, &req).unwrap();
        let rep = decode_reply(&encode_reply(&rep).unwrap()).unwrap();
        let out = client.handle_reply(cstore, &rep);
        assert!(out.rejected.is_empty(), "{out:?}");
    }
    rounds
}

#[test]
fn a_client_fetches_a_whole_type_and_verifies_every_hash() {
    let (sstore, info) = owned_store::<Top>();
    let mut server = Server::new(ServerLimits::default());
    let mut cstore = TypeStore::new(StoreLimits::default());
    let mut client = Client::new([9; 16], ClientLimits::default());
    let missing = cstore.missing(&info);
    // Top, Middle and Leaf, minimal and complete.
    assert_eq!(missing.len(), 6);
    client.want(&cstore, missing);
    exchange(&mut client, &mut cstore, &mut server, &sstore);
    assert!(cstore.missing(&info).is_empty());
    for id in [
        &info.complete.typeid_with_size.type_id,
        &info.minimal.typeid_with_size.type_id,
    ] {
        assert_eq!(cstore.get(id), sstore.get(id));
    }
}

#[test]
fn dependencies_are_paged_with_continuation_points() {
    let (sstore, info) = owned_store::<Top>();
    let mut server = Server::new(ServerLimits {
        dependencies_page: 1,
        ..ServerLimits::default()
    });
    let mut cstore = TypeStore::new(StoreLimits::default());
    let mut client = Client::new([9; 16], ClientLimits::default());
    let top = info.complete.typeid_with_size.type_id.clone();
    client.want(&cstore, [top.clone()]);
    client.want_dependencies(top.clone());
    let rounds = exchange(&mut client, &mut cstore, &mut server, &sstore);
    // Two pages of dependencies (Middle, then Leaf), then one getTypes for Top, Middle and Leaf.
    assert_eq!(rounds, 3);
    for d in &info.complete.dependent_typeids {
        assert!(cstore.contains(&d.type_id), "{d:?}");
    }
    assert!(cstore.contains(&top));
}

#[test]
fn unknown_types_get_an_empty_answer() {
    let (sstore, _) = owned_store::<Leaf>();
    let mut server = Server::new(ServerLimits::default());
    let req = Request {
        request_id: SampleIdentity::default(),
        instance_name: String::new(),
        call: Call::GetTypes(vec![
            TypeIdentifier::Complete([0xab; 14]),
            TypeIdentifier::Primitive(4),
        ]),
    };
    let rep = server
        .handle(Instant::now(), [1; 12], &sstore, &req)
        .unwrap();
    assert_eq!(rep.return_data, Return::GetTypes(Ok(TypesOut::default())));
    let unknown_op = Request {
        call: Call::Other(0x1234),
        ..req
    };
    let rep = server
        .handle(Instant::now(), [1; 12], &sstore, &unknown_op)
        .unwrap();
    assert_eq!(rep.remote_ex, RemoteExceptionCode::UnknownOperation);
    decode_reply(&encode_reply(&rep).unwrap()).unwrap();
}

#[test]
fn hostile_continuation_points_and_counts() {
    let (sstore, info) = owned_store::<Top>();
    let mut server = Server::new(ServerLimits::default());
    let top = info.complete.typeid_with_size.type_id.clone();
    for cp in [vec![0xff; 4], vec![1, 2, 3], vec![0xff; 32]] {
        let req = Request {
            request_id: SampleIdentity::default(),
            instance_name: String::new(),
            call: Call::GetTypeDependencies {
                type_ids: vec![top.clone()],
                continuation_point: cp,
            },
        };
        let rep = server
            .handle(Instant::now(), [1; 12], &sstore, &req)
            .unwrap();
        assert_eq!(rep.remote_ex, RemoteExceptionCode::InvalidArgument);
    }
    // A continuation point longer than its bound, and a list count far beyond the data, fail to decode.
    let mut bytes = fixture(REQUESTS[0]);
    let count_at = bytes.len() - 1 - 15 - 4; // the type_ids count, before one 15-byte identifier and a pad byte
    assert_eq!(&bytes[count_at..count_at + 4], &[1, 0, 0, 0]);
    for huge in [u32::MAX, 1 << 20, 257] {
        bytes[count_at..count_at + 4].copy_from_slice(&huge.to_le_bytes());
        assert!(decode_request(&bytes).is_err(), "{huge}");
    }
    let req = Request {
        request_id: SampleIdentity::default(),
        instance_name: String::new(),
        call: Call::GetTypes(vec![TypeIdentifier::Complete([1; 14]); 257]),
    };
    assert!(decode_request(&encode_request(&req).unwrap()).is_err());
}

#[test]
fn truncated_and_corrupted_messages_are_errors_not_panics() {
    for name in REQUESTS.iter().chain(&REPLIES) {
        let bytes = fixture(name);
        for n in 0..bytes.len() - 4 {
            assert!(decode_request(&bytes[..n]).is_err() || decode_reply(&bytes[..n]).is_err());
        }
        for i in 0..bytes.len() {
            let mut b = bytes.clone();
            b[i] ^= 0xff;
            let _ = decode_request(&b);
            let _ = decode_reply(&b);
        }
    }
    assert!(matches!(
        decode_request(&[0x00, 0x01, 0, 0, 0, 0]),
        Err(TypeLookupError::Representation(1))
    ));
}

#[test]
fn replies_not_asked_for_are_ignored() {
    let (sstore, info) = owned_store::<Leaf>();
    let mut server = Server::new(ServerLimits::default());
    let mut cstore = TypeStore::new(StoreLimits::default());
    let mut client = Client::new([9; 16], ClientLimits::default());
    client.want(&cstore, cstore.missing(&info));
    let now = Instant::now();
    let req = client.poll_request(now).unwrap();
    let mut rep = server.handle(now, [1; 12], &sstore, &req).unwrap();
    // An unknown sequence number: nothing is stored.
    let good = rep.related_request_id;
    rep.related_request_id.sequence_number = 99;
    assert_eq!(client.handle_reply(&mut cstore, &rep).stored.len(), 0);
    assert!(cstore.is_empty());
    // The request expires; the types can be asked for again.
    client.handle_timeout(now + Duration::from_secs(10));
    assert!(client.poll_request(now).is_none());
    client.want(&cstore, cstore.missing(&info));
    let again = client.poll_request(now).unwrap();
    // Cyclone DDS 0.10 answers with its own writer's GUID and our sequence number: accepted, hash-checked.
    let mut rep = server.handle(now, [1; 12], &sstore, &again).unwrap();
    rep.related_request_id = SampleIdentity {
        writer_guid: [8; 16],
        ..again.request_id
    };
    assert_ne!(good.sequence_number, again.request_id.sequence_number);
    assert_eq!(client.handle_reply(&mut cstore, &rep).stored.len(), 2);
    assert!(cstore.missing(&info).is_empty());
}

/// Over its rate, a participant's requests wait for later seconds (in order, bounded in number) instead
/// of being dropped: peers such as Cyclone send a burst when they discover many types and never ask again.
#[test]
fn requests_are_rate_limited_per_participant() {
    let (sstore, _) = owned_store::<Leaf>();
    let limits = ServerLimits {
        requests_per_second: 5,
        max_deferred: 12,
        ..ServerLimits::default()
    };
    let mut server = Server::new(limits);
    let req = decode_request(&fixture(REQUESTS[0])).unwrap();
    let now = Instant::now();
    let answered = (0..100)
        .filter(|_| server.handle(now, [1; 12], &sstore, &req).is_some())
        .count();
    assert_eq!(answered, 5);
    // Another participant has its own rate.
    assert!(server.handle(now, [2; 12], &sstore, &req).is_some());
    // 12 of the other 95 wait; none can be answered in this second.
    assert!(server.poll_deferred(now, &sstore).is_none());
    let second = now + Duration::from_secs(1);
    assert_eq!(server.next_deferred(), Some(second));
    // A request arriving now waits behind them (the peer's order is kept).
    assert!(server.handle(second, [1; 12], &sstore, &req).is_none());
    let mut drained = Vec::new();
    for s in 1..=4 {
        let t = now + Duration::from_secs(s);
        drained.push(std::iter::from_fn(|| server.poll_deferred(t, &sstore)).count());
    }
    assert_eq!(drained, vec![5, 5, 2, 0], "12 waiting, 5 per second");
    assert_eq!(server.next_deferred(), None);
}

/// The TypeInformation and TypeMapping Cyclone 11's Python binding computes for the recursive `Rec::Holder`
/// (tests/fixtures/typeinfo-recursive of the workspace): two strongly connected components, `Rec::Node` and
/// `Rec::A`/`Rec::B`.
fn binding_holder() -> (TypeInformation, TypeMapping) {
    let p = format!(
        "{}/../tests/fixtures/typeinfo-recursive/Holder.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{p}: {e}"));
    // The file is JSON; the two hex strings are read by their keys (no JSON parser among our dev-dependencies).
    let hex_of = |key: &str| -> Vec<u8> {
        let at = text.find(&format!("\"{key}\": \"")).expect(key) + key.len() + 5;
        let s = &text[at..at + text[at..].find('"').expect("end")];
        (0..s.len())
            .step_by(2)
            .map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap())
            .collect()
    };
    (
        from_bytes(&hex_of("type_information")).unwrap(),
        from_bytes(&hex_of("type_mapping")).unwrap(),
    )
}

/// A recursive type's objects go whole: asked for a component (index 0, as a TypeInformation lists it), the
/// server answers with every type of it, and the client stores them only once they hash, together, to the
/// component's hash; a tampered or partial component is refused.
#[test]
fn strongly_connected_components_are_fetched_whole_and_verified() {
    let (info, mapping) = binding_holder();
    let mut sstore = TypeStore::new(StoreLimits::default());
    sstore.add_owned(&info, &mapping);
    let components: Vec<TypeIdentifier> = info
        .complete
        .dependent_typeids
        .iter()
        .chain(&info.minimal.dependent_typeids)
        .map(|t| t.type_id.clone())
        .filter(|id| matches!(id, TypeIdentifier::StronglyConnected(c) if c.scc_index == 0))
        .collect();
    assert_eq!(components.len(), 4, "Node and A/B, minimal and complete");
    let mut server = Server::new(ServerLimits::default());
    let mut cstore = TypeStore::new(StoreLimits::default());
    let mut client = Client::new([9; 16], ClientLimits::default());
    client.want(&cstore, components.iter().cloned());
    exchange(&mut client, &mut cstore, &mut server, &sstore);
    for c in &components {
        assert!(cstore.contains(c), "{c:?}");
        assert_eq!(cstore.objects_of(c), sstore.objects_of(c));
    }
    // Node is one type, A/B two.
    let lens: Vec<usize> = components
        .iter()
        .map(|c| cstore.objects_of(c).unwrap().len())
        .collect();
    assert_eq!(lens.iter().sum::<usize>(), 6);

    let pairs: Vec<(TypeIdentifier, dds_runtime::xtypes::typeobject::TypeObject)> = sstore
        .objects_of(&components[1])
        .unwrap()
        .into_iter()
        .map(|(i, o)| (i, (*o).clone()))
        .collect();
    let mut fresh = TypeStore::new(StoreLimits::default());
    assert_eq!(
        fresh.insert_component(&pairs[..pairs.len() - 1]),
        Err(StoreError::Incomplete)
    );
    // Another component's hash on the same objects.
    let mut renamed = pairs.clone();
    for (id, _) in &mut renamed {
        if let TypeIdentifier::StronglyConnected(c) = id {
            c.hash[0] ^= 1;
        }
    }
    assert_eq!(
        fresh.insert_component(&renamed),
        Err(StoreError::HashMismatch)
    );
    // A single type asked for alone cannot be stored on its own.
    assert_eq!(
        fresh.insert_verified(pairs[0].0.clone(), pairs[0].1.clone()),
        Err(StoreError::NotHashed)
    );
    assert_eq!(fresh.insert_component(&pairs), Ok(true));
    assert_eq!(fresh.insert_component(&pairs), Ok(false));
    assert!(fresh.contains(&components[1]));
}
