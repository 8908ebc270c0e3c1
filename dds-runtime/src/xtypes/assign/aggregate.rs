//! The rules for structs and unions (XTypes 1.3 §7.2.4.4.7-8), in the order Cyclone DDS 11 applies them.

use super::view::{extensibility, is_final};
use super::{Checker, NotAssignable};
use crate::xtypes::typeobject::{MemberFlag, StructMember, TypeBody, TypeFlag, UnionMember};

/// Whether a member is a non-optional `must_understand` one.
fn must_understand(f: MemberFlag) -> bool {
    f.contains(MemberFlag::IS_MUST_UNDERSTAND) && !f.contains(MemberFlag::IS_OPTIONAL)
}

/// Members with the same id have the same name and members with the same name the same id (§7.2.4.4.8,
/// unless `ignore_member_names`).
fn names_pair_up<'m>(
    id: u32,
    name: [u8; 4],
    others: impl Iterator<Item = (u32, [u8; 4])> + 'm,
) -> Result<(), NotAssignable> {
    for (oid, oname) in others {
        if (id == oid) != (name == oname) {
            return Err(NotAssignable::MemberName { id });
        }
    }
    Ok(())
}

impl Checker<'_> {
    /// §7.2.4.4.8: T1 (reader) struct is-assignable-from T2 (writer) struct.
    pub(super) fn struct_assignable(
        &mut self,
        b1: &TypeBody,
        b2: &TypeBody,
    ) -> Result<(), NotAssignable> {
        let (
            TypeBody::Struct {
                flags: f1,
                base: base1,
                members: own1,
                ..
            },
            TypeBody::Struct {
                flags: f2,
                base: base2,
                members: own2,
                ..
            },
        ) = (b1, b2)
        else {
            return Err(NotAssignable::Kind);
        };
        // Same extensibility kind.
        if extensibility(*f1) != extensibility(*f2) {
            return Err(NotAssignable::Extensibility);
        }
        let (m1s, m2s) = (
            self.flat_members(base1, own1)?,
            self.flat_members(base2, own2)?,
        );
        // Key members appear in both: checked by count here, by id below (only at the top level: members are
        // compared as KeyErased types).
        let top = self.stack.len() == 1;
        let keys = |ms: &[StructMember]| {
            ms.iter()
                .filter(|m| m.flags.contains(MemberFlag::IS_KEY))
                .count()
        };
        if top && keys(&m1s) != keys(&m2s) {
            return Err(NotAssignable::Key);
        }
        let is_final = is_final(*f1);
        let appendable = f1.contains(TypeFlag::IS_APPENDABLE);
        let mut any = false;
        for (i, m1) in m1s.iter().enumerate() {
            if !self.tce.ignore_member_names {
                names_pair_up(
                    m1.id,
                    m1.detail.name.hash(),
                    m2s.iter().map(|m| (m.id, m.detail.name.hash())),
                )?;
            }
            let m2 = m2s.iter().find(|m| m.id == m1.id);
            if let Some(m2) = m2 {
                any = true;
                // The member types: KeyErased(m1.type) is-assignable-from KeyErased(m2.type).
                self.assignable(&m1.type_id, &m2.type_id)?;
            } else {
                self.reader_member_missing(m1, top, is_final)?;
            }
            // Appendable: members at the same index have the same id and optionality, and the member type is
            // strongly assignable; final: the same, for every index.
            if is_final || (appendable && i < m2s.len()) {
                let Some(p2) = m2s.get(i) else {
                    return Err(NotAssignable::Member { id: m1.id });
                };
                let opt = |m: &StructMember| m.flags.contains(MemberFlag::IS_OPTIONAL);
                if p2.id != m1.id || opt(p2) != opt(m1) {
                    return Err(NotAssignable::Member { id: m1.id });
                }
                self.strongly_assignable(&m1.type_id, &p2.type_id)?;
            }
        }
        writer_members_known(&m1s, &m2s, top, is_final)?;
        // At least one member in common.
        if any {
            Ok(())
        } else {
            Err(NotAssignable::NoOverlap)
        }
    }

    /// A reader member the writer's type lacks: allowed unless it must be understood, is a key at the top
    /// level, or the type is final (or widening is prevented and the member is not optional).
    fn reader_member_missing(
        &self,
        m1: &StructMember,
        top: bool,
        is_final: bool,
    ) -> Result<(), NotAssignable> {
        if must_understand(m1.flags) {
            return Err(NotAssignable::MustUnderstand { id: m1.id });
        }
        if top && m1.flags.contains(MemberFlag::IS_KEY) {
            return Err(NotAssignable::Key);
        }
        let widening =
            self.tce.prevent_type_widening && !m1.flags.contains(MemberFlag::IS_OPTIONAL);
        if is_final || widening {
            return Err(NotAssignable::Member { id: m1.id });
        }
        Ok(())
    }

    /// §7.2.4.4.7: T1 (reader) union is-assignable-from T2 (writer) union.
    pub(super) fn union_assignable(
        &mut self,
        b1: &TypeBody,
        b2: &TypeBody,
    ) -> Result<(), NotAssignable> {
        let (
            TypeBody::Union {
                flags: f1,
                disc_flags: df1,
                disc_type: d1,
                members: m1s,
                ..
            },
            TypeBody::Union {
                flags: f2,
                disc_flags: df2,
                disc_type: d2,
                members: m2s,
                ..
            },
        ) = (b1, b2)
        else {
            return Err(NotAssignable::Kind);
        };
        if extensibility(*f1) != extensibility(*f2) {
            return Err(NotAssignable::Extensibility);
        }
        // The discriminators: strongly assignable, both keys or neither.
        self.strongly_assignable(d1, d2)?;
        if df1.contains(MemberFlag::IS_KEY) != df2.contains(MemberFlag::IS_KEY) {
            return Err(NotAssignable::Key);
        }
        let strict = is_final(*f1) || self.tce.prevent_type_widening;
        if is_final(*f1) && m1s.len() != m2s.len() {
            return Err(NotAssignable::MissingCase);
        }
        let default = |ms: &[UnionMember]| {
            ms.iter()
                .find(|m| m.flags.contains(MemberFlag::IS_DEFAULT))
                .cloned()
        };
        let (def1, def2) = (default(m1s), default(m2s));
        let selects =
            |a: &UnionMember, b: &UnionMember| a.labels.iter().any(|l| b.labels.contains(l));
        let mut any = false;
        for m1 in m1s {
            if !self.tce.ignore_member_names {
                names_pair_up(
                    m1.id,
                    m1.detail.name.hash(),
                    m2s.iter().map(|m| (m.id, m.detail.name.hash())),
                )?;
            }
            let same_id = m2s.iter().find(|m| m.id == m1.id);
            let hits = m2s.iter().any(|m2| selects(m1, m2));
            // Both default cases: the reader's from the writer's.
            if let (true, Some(d2)) = (m1.flags.contains(MemberFlag::IS_DEFAULT), &def2) {
                self.assignable(&m1.type_id, &d2.type_id)?;
            }
            // Labels of T1 that select T2's default case: the T1 case's type from the default's.
            if !m1.flags.contains(MemberFlag::IS_DEFAULT) && !hits {
                if let Some(d2) = &def2 {
                    self.assignable(&m1.type_id, &d2.type_id)?;
                }
            }
            // Final or prevent_type_widening: the same labels for the same case.
            if strict && !same_id.is_some_and(|m2| same_labels(m1, m2)) {
                return Err(NotAssignable::MissingCase);
            }
            any |= hits;
        }
        self.writer_labels_assignable(m1s, m2s, def1.as_ref())?;
        // At least one label in common.
        if any {
            Ok(())
        } else {
            Err(NotAssignable::NoOverlap)
        }
    }

    /// Every label of T2 that selects a case of T1 (its default included): T1's case type from T2's.
    fn writer_labels_assignable(
        &mut self,
        m1s: &[UnionMember],
        m2s: &[UnionMember],
        def1: Option<&UnionMember>,
    ) -> Result<(), NotAssignable> {
        for m2 in m2s
            .iter()
            .filter(|m| !m.flags.contains(MemberFlag::IS_DEFAULT))
        {
            for l in &m2.labels {
                match m1s.iter().find(|m| m.labels.contains(l)).or(def1) {
                    Some(m1) => self.assignable(&m1.type_id, &m2.type_id)?,
                    None if self.tce.prevent_type_widening => {
                        return Err(NotAssignable::MissingCase)
                    }
                    None => {}
                }
            }
        }
        Ok(())
    }
}

/// Every writer member the reader must know (must-understand ones, keys at the top level, all of a final
/// type) is among the reader's.
fn writer_members_known(
    m1s: &[StructMember],
    m2s: &[StructMember],
    top: bool,
    is_final: bool,
) -> Result<(), NotAssignable> {
    for m2 in m2s {
        let needed =
            must_understand(m2.flags) || (top && m2.flags.contains(MemberFlag::IS_KEY)) || is_final;
        if needed && !m1s.iter().any(|m| m.id == m2.id) {
            return Err(if must_understand(m2.flags) {
                NotAssignable::MustUnderstand { id: m2.id }
            } else {
                NotAssignable::Member { id: m2.id }
            });
        }
    }
    Ok(())
}

/// Two cases select the same set of labels.
fn same_labels(a: &UnionMember, b: &UnionMember) -> bool {
    let (mut a, mut b) = (a.labels.clone(), b.labels.clone());
    a.sort_unstable();
    b.sort_unstable();
    a == b
}
