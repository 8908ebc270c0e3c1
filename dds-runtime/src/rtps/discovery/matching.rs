//! Writer/reader matching: topic names, types (by assignability when both sides announce type information,
//! else by name), partitions, then requested/offered QoS.

use super::{ReaderData, WriterData};
use crate::qos::{check_compatible, partitions_match, QosPolicyId, TypeConsistencyEnforcement};
use crate::xtypes::assign::{is_assignable, local_types, NotAssignable, TypeResolver};
use crate::xtypes::typeobject::TypeIdentifier;
use crate::xtypes::TypeInformation;

/// The outcome of matching a publication with a subscription.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MatchResult {
    /// Same topic, consistent types, same partition, and compatible QoS: the endpoints communicate.
    Match,
    /// Different topic or partition: not related at all, nothing to report.
    Unrelated,
    /// Same topic but a requested/offered conflict or inconsistent types: reported as incompatible QoS on both
    /// sides (types: `TYPE_CONSISTENCY_ENFORCEMENT`).
    Incompatible(QosPolicyId),
}

/// Matches a publication with a subscription (DDS 1.4 §2.2.3, RTPS 2.5 §8.5.5.1, XTypes 1.3 §7.6.3.4), resolving
/// types through the process-wide registry of local types.
pub fn match_endpoints(w: &WriterData, r: &ReaderData) -> MatchResult {
    match_endpoints_with(w, r, local_types())
}

/// [`match_endpoints`] with the types resolved by `types` (a TypeLookup store, for types of peers).
pub fn match_endpoints_with(
    w: &WriterData,
    r: &ReaderData,
    types: &dyn TypeResolver,
) -> MatchResult {
    if w.topic_name != r.topic_name {
        return MatchResult::Unrelated;
    }
    if !partitions_match(&w.qos.partition, &r.qos.partition) {
        return MatchResult::Unrelated;
    }
    match types_consistent(w, r, types) {
        Types::Consistent => {}
        Types::DifferentNames => return MatchResult::Unrelated,
        Types::Inconsistent => {
            return MatchResult::Incompatible(QosPolicyId::TypeConsistencyEnforcement)
        }
    }
    match check_compatible(&w.qos, &r.qos) {
        Ok(()) => MatchResult::Match,
        Err(p) => MatchResult::Incompatible(p),
    }
}

/// The minimal identifier of the topic type in announced type information, if it decodes.
fn minimal_id(ti: Option<&TypeInformation>) -> Option<TypeIdentifier> {
    let id = ti?.decode().ok()?.minimal.typeid_with_size.type_id;
    (id != TypeIdentifier::None).then_some(id)
}

/// How the writer's type relates to the reader's.
enum Types {
    /// The reader can take the writer's samples.
    Consistent,
    /// No type information to compare and different type names: different types, nothing to report.
    DifferentNames,
    /// Not assignable, or type validation forced without type information: incompatible QoS.
    Inconsistent,
}

/// Whether the writer's type is consistent with the reader's (XTypes 1.3 §7.6.3.4.2, as Cyclone DDS 11 does
/// it): with type information on both sides, assignability under the reader's TYPE_CONSISTENCY_ENFORCEMENT
/// and the type names are not compared; without (Fast DDS 2.9, older Cyclone), equal type names, unless the
/// reader forces type validation. A type that cannot be resolved yet falls back to the type names too.
///
/// Different type names without type information stay "unrelated" (no event), as before; Cyclone reports them
/// as an incompatible TYPE_CONSISTENCY_ENFORCEMENT instead.
fn types_consistent(w: &WriterData, r: &ReaderData, types: &dyn TypeResolver) -> Types {
    let tce: &TypeConsistencyEnforcement = &r.qos.reader.type_consistency;
    let by_name = || {
        if w.type_name == r.type_name {
            Types::Consistent
        } else {
            Types::DifferentNames
        }
    };
    let (wid, rid) = (
        minimal_id(w.type_information.as_deref()),
        minimal_id(r.type_information.as_deref()),
    );
    let (Some(wid), Some(rid)) = (wid, rid) else {
        if tce.force_type_validation {
            return Types::Inconsistent;
        }
        return by_name();
    };
    match is_assignable(&rid, &wid, tce, types) {
        Ok(()) => Types::Consistent,
        Err(NotAssignable::Unresolved(id)) => {
            tracing::debug!(topic = %r.topic_name, ?id, "type not resolvable yet: matching by type name");
            by_name()
        }
        Err(why) => {
            tracing::debug!(topic = %r.topic_name, %why, "writer type not assignable to reader type");
            Types::Inconsistent
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::qos::TypeConsistencyKind;
    use crate::xtypes::XTypesType;
    use crate::DdsType;
    use std::sync::Arc;

    #[derive(DdsType)]
    #[dds(appendable, name = "V1")]
    struct V1 {
        #[dds(key)]
        id: u32,
        a: i32,
    }
    #[derive(DdsType)]
    #[dds(appendable, name = "V2")]
    struct V2 {
        #[dds(key)]
        id: u32,
        a: i32,
        b: String,
    }
    #[derive(DdsType)]
    #[dds(mutable, name = "V1")]
    struct Other {
        #[dds(key)]
        id: u32,
        a: i32,
    }

    fn info<T: XTypesType>() -> Option<TypeInformation> {
        Some(TypeInformation(
            T::type_support().unwrap().information_bytes.clone(),
        ))
    }

    fn pair(
        wname: &str,
        wti: Option<TypeInformation>,
        rname: &str,
        rti: Option<TypeInformation>,
    ) -> (WriterData, ReaderData) {
        let w = WriterData {
            topic_name: "T".into(),
            type_name: wname.into(),
            type_information: wti.map(Into::into),
            ..Default::default()
        };
        let r = ReaderData {
            topic_name: "T".into(),
            type_name: rname.into(),
            type_information: rti.map(Into::into),
            ..Default::default()
        };
        (w, r)
    }

    #[test]
    fn assignable_types_match_whatever_their_names() {
        let (w, r) = pair("V1", info::<V1>(), "V2", info::<V2>());
        assert_eq!(match_endpoints(&w, &r), MatchResult::Match);
        let (w, r) = pair("V2", info::<V2>(), "V1", info::<V1>());
        assert_eq!(match_endpoints(&w, &r), MatchResult::Match);
    }

    #[test]
    fn unassignable_types_are_an_incompatible_type_consistency() {
        let (w, r) = pair("V1", info::<Other>(), "V1", info::<V1>());
        assert_eq!(
            match_endpoints(&w, &r),
            MatchResult::Incompatible(QosPolicyId::TypeConsistencyEnforcement)
        );
    }

    #[test]
    fn disallow_type_coercion_needs_the_same_type() {
        let (w, mut r) = pair("V2", info::<V2>(), "V1", info::<V1>());
        Arc::make_mut(&mut r.qos).reader.type_consistency.kind =
            TypeConsistencyKind::DisallowTypeCoercion;
        assert_eq!(
            match_endpoints(&w, &r),
            MatchResult::Incompatible(QosPolicyId::TypeConsistencyEnforcement)
        );
        let (w, mut r) = pair("V1", info::<V1>(), "V1", info::<V1>());
        Arc::make_mut(&mut r.qos).reader.type_consistency.kind =
            TypeConsistencyKind::DisallowTypeCoercion;
        assert_eq!(match_endpoints(&w, &r), MatchResult::Match);
    }

    #[test]
    fn without_type_information_the_names_decide() {
        let (w, r) = pair("V1", None, "V1", info::<V2>());
        assert_eq!(match_endpoints(&w, &r), MatchResult::Match);
        let (w, r) = pair("V1", info::<V1>(), "V2", None);
        assert_eq!(match_endpoints(&w, &r), MatchResult::Unrelated);
        let (w, mut r) = pair("V1", None, "V1", info::<V1>());
        Arc::make_mut(&mut r.qos)
            .reader
            .type_consistency
            .force_type_validation = true;
        assert_eq!(
            match_endpoints(&w, &r),
            MatchResult::Incompatible(QosPolicyId::TypeConsistencyEnforcement)
        );
    }

    #[test]
    fn unresolvable_or_garbled_type_information_falls_back_to_names() {
        let unknown = crate::xtypes::typeobject::TypeInformation {
            minimal: crate::xtypes::typeobject::TypeIdentifierWithDependencies {
                typeid_with_size: crate::xtypes::typeobject::TypeIdentifierWithSize {
                    type_id: TypeIdentifier::Minimal([0xAB; 14]),
                    typeobject_serialized_size: 10,
                },
                ..Default::default()
            },
            ..Default::default()
        };
        let bytes = crate::xtypes::typeobject::to_bytes(&unknown).unwrap();
        let (w, r) = pair("V1", Some(TypeInformation(bytes)), "V1", info::<V1>());
        assert_eq!(match_endpoints(&w, &r), MatchResult::Match);
        let (w, r) = pair(
            "V1",
            Some(TypeInformation(vec![1, 2, 3])),
            "V1",
            info::<V1>(),
        );
        assert_eq!(match_endpoints(&w, &r), MatchResult::Match);
    }
}
