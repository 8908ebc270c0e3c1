//! The TypeLookup request/reply decoder (`dds_runtime::xtypes::typelookup`). Whatever decodes must re-encode
//! to bytes that decode to the same message; a decoded request goes through the server (with a store holding
//! a few types), a decoded reply through a client with requests in flight (objects are stored only if their
//! hash checks out). Nothing may panic or allocate beyond the input's size. A first byte of 0xff makes the rest
//! a bare type object (as replies carry them; seeds `bitset_*`: `TK_BITSET` objects), which must re-encode to
//! bytes that decode to the same object.

use std::time::Instant;

use dds_runtime::xtypes::store::{StoreLimits, TypeStore};
use dds_runtime::xtypes::typelookup::*;
use dds_runtime::xtypes::typeobject::{
    from_bytes, to_bytes, TypeIdentifier, TypeInformation, TypeMapping, TypeObject,
};
use dds_runtime::xtypes::XTypesType;

#[derive(dds_runtime::DdsType, Debug, Clone, PartialEq, Default)]
struct Leaf {
    a: i32,
    s: String,
}

#[derive(dds_runtime::DdsType, Debug, Clone, PartialEq, Default)]
#[dds(mutable)]
struct Node {
    #[dds(key)]
    id: u32,
    leaves: Vec<Leaf>,
    one: Leaf,
}

fn store() -> (TypeStore, TypeInformation) {
    let s = Node::type_support().expect("describable");
    let info: TypeInformation = from_bytes(&s.information_bytes).expect("own info");
    let mapping: TypeMapping = from_bytes(&s.mapping_bytes).expect("own mapping");
    let mut store = TypeStore::new(StoreLimits {
        max_learnt: 64,
        max_learnt_bytes: 64 << 10,
    });
    store.add_owned(&info, &mapping);
    (store, info)
}

/// One input: the first byte picks request (even) or reply (odd), the rest is the payload.
pub fn typelookup_one(data: &[u8]) {
    let Some((&sel, payload)) = data.split_first() else {
        return;
    };
    let now = Instant::now();
    if sel == 0xff {
        if let Ok(o) = from_bytes::<TypeObject>(payload) {
            let bytes = to_bytes(&o).expect("a decoded type object encodes");
            assert_eq!(
                from_bytes::<TypeObject>(&bytes).expect("re-encoded object"),
                o
            );
        }
    } else if sel % 2 == 0 {
        let Ok(req) = decode_request(payload) else {
            return;
        };
        if let Ok(bytes) = encode_request(&req) {
            assert_eq!(decode_request(&bytes).expect("re-encoded request"), req);
        }
        let (store, _) = store();
        let mut server = Server::new(ServerLimits::default());
        if let Some(rep) = server.handle(now, [1; 12], &store, &req) {
            let bytes = encode_reply(&rep).expect("our reply encodes");
            assert_eq!(decode_reply(&bytes).expect("our reply decodes"), rep);
        }
    } else {
        let Ok(rep) = decode_reply(payload) else {
            return;
        };
        if let Ok(bytes) = encode_reply(&rep) {
            assert_eq!(decode_reply(&bytes).expect("re-encoded reply"), rep);
        }
        // A client with requests 1.. in flight for every id the reply names, and a store lacking them.
        let mut empty = TypeStore::new(StoreLimits::default());
        let mut client = Client::new(rep.related_request_id.writer_guid, ClientLimits::default());
        let mut ids: Vec<TypeIdentifier> = Vec::new();
        if let Return::GetTypes(Ok(out)) = &rep.return_data {
            ids.extend(out.types.iter().map(|p| p.type_identifier.clone()));
        }
        client.want(&empty, ids);
        while client.poll_request(now).is_some() {}
        let before = empty.len();
        let out = client.handle_reply(&mut empty, &rep);
        assert_eq!(empty.len(), before + out.stored.len());
    }
}
