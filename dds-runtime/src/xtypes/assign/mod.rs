//! Assignability (XTypes 1.3 §7.2.4): whether a reader of type T1 can take the samples of a writer of type T2,
//! as a pure function over minimal type objects, honouring the reader's `TypeConsistencyEnforcement` QoS
//! (§7.6.3.4).
//!
//! The rules follow the spec clause by clause; where Cyclone DDS 11 reads a clause differently we follow
//! Cyclone (a peer we meet on the wire) and say so at the rule:
//! - a struct's base type is flattened into its members before the struct rules apply (§7.2.2.4.5);
//! - map bounds are not compared; enum `bit_bound`s are not compared;
//! - key members are compared by id and count; the key-holder check of key members of aggregated type is not
//!   done.
//!
//! Types that refer to others by hash are looked up through a [`TypeResolver`]: the process-wide
//! [`LocalTypes`] registry knows every type this process built its type support for; a TypeLookup store
//! implements the same trait for types discovered from peers.

mod aggregate;
mod registry;
mod simple;
mod view;

#[cfg(test)]
mod tests;

use std::sync::Arc;

use thiserror::Error;

use super::typeobject::{TypeIdentifier, TypeObject};
use crate::qos::{TypeConsistencyEnforcement, TypeConsistencyKind};

pub use registry::{local_types, LocalTypes};

/// Looks up the type object a hashed [`TypeIdentifier`] (minimal or complete) stands for.
pub trait TypeResolver {
    /// The type object of `id`, if known.
    fn resolve(&self, id: &TypeIdentifier) -> Option<Arc<TypeObject>>;
}

impl<F> TypeResolver for F
where
    F: Fn(&TypeIdentifier) -> Option<Arc<TypeObject>>,
{
    fn resolve(&self, id: &TypeIdentifier) -> Option<Arc<TypeObject>> {
        self(id)
    }
}

/// Why a writer's type is not assignable to a reader's type.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum NotAssignable {
    /// A type the check needs is not known to the resolver (not an incompatibility: the answer is unknown).
    #[error("type {0:?} is not known")]
    Unresolved(TypeIdentifier),
    /// `DISALLOW_TYPE_COERCION`: the types must be equal and are not.
    #[error("type coercion is disallowed and the types differ")]
    NotEqual,
    /// The kinds differ (a struct and a union, a long and a short...).
    #[error("the type kinds differ")]
    Kind,
    /// Final, appendable and mutable do not mix.
    #[error("the extensibility kinds differ")]
    Extensibility,
    /// A string, sequence or array bound does not fit.
    #[error("a bound does not fit")]
    Bound,
    /// Two members with the same id have different names, or the same name different ids.
    #[error("member {id}: names and ids do not pair up")]
    MemberName {
        /// The reader's member id.
        id: u32,
    },
    /// The key members differ.
    #[error("the key members differ")]
    Key,
    /// A non-optional `must_understand` member of one side is missing on the other.
    #[error("must_understand member {id} is missing on one side")]
    MustUnderstand {
        /// Its id.
        id: u32,
    },
    /// Members at the same position of a final or appendable struct differ (id or optionality), or a final
    /// struct's member sets differ.
    #[error("member {id} does not correspond")]
    Member {
        /// The reader's member id (or the writer's, when the reader has none there).
        id: u32,
    },
    /// No member (struct) or label (union) in common.
    #[error("no member in common")]
    NoOverlap,
    /// A union case or enumerator one side needs is missing.
    #[error("a case or enumerator is missing")]
    MissingCase,
    /// A writer member type is not delimited where strong assignability needs it (§7.2.4.2).
    #[error("the writer's member type is not delimited")]
    NotDelimited,
    /// The types nest deeper than the check follows (hostile or broken type objects).
    #[error("types nest too deeply")]
    TooDeep,
    /// A type object is inconsistent (a base that is not a struct, an alias loop...).
    #[error("malformed type object")]
    Malformed,
}

/// Nesting depth the check follows before giving up.
const MAX_DEPTH: usize = 64;

/// Total steps one check may take, so that hostile type objects cannot make it run for long.
const MAX_STEPS: usize = 100_000;

/// Whether a sample of the writer's type `writer` can be read as the reader's type `reader`
/// (T1 `is-assignable-from` T2, XTypes 1.3 §7.2.4), under the reader's `tce`.
///
/// `Ok(())` when assignable. [`NotAssignable::Unresolved`] means the answer is not known yet; every other error
/// is a real incompatibility.
pub fn is_assignable(
    reader: &TypeIdentifier,
    writer: &TypeIdentifier,
    tce: &TypeConsistencyEnforcement,
    resolver: &dyn TypeResolver,
) -> Result<(), NotAssignable> {
    if reader == writer {
        return Ok(());
    }
    // §7.6.3.4.1 (and Cyclone's qosmatch): without coercion the (minimal) identifiers must be equal.
    if tce.kind == TypeConsistencyKind::DisallowTypeCoercion {
        return Err(NotAssignable::NotEqual);
    }
    Checker::new(tce, resolver).assignable(reader, writer)
}

/// One assignability check: its options, its resolver and its recursion state.
pub(crate) struct Checker<'a> {
    tce: &'a TypeConsistencyEnforcement,
    resolver: &'a dyn TypeResolver,
    /// Pairs being checked: a pair met again inside itself is assumed assignable (recursive types).
    stack: Vec<(TypeIdentifier, TypeIdentifier)>,
    steps: usize,
}

impl<'a> Checker<'a> {
    pub(crate) fn new(tce: &'a TypeConsistencyEnforcement, resolver: &'a dyn TypeResolver) -> Self {
        Checker {
            tce,
            resolver,
            stack: Vec::new(),
            steps: 0,
        }
    }

    /// T1 is-assignable-from T2 (§7.2.4.1 table, §7.2.4.4).
    pub(crate) fn assignable(
        &mut self,
        t1: &TypeIdentifier,
        t2: &TypeIdentifier,
    ) -> Result<(), NotAssignable> {
        if t1 == t2 {
            return Ok(());
        }
        let pair = (t1.clone(), t2.clone());
        if self.stack.contains(&pair) {
            return Ok(());
        }
        self.steps += 1;
        if self.stack.len() >= MAX_DEPTH || self.steps > MAX_STEPS {
            return Err(NotAssignable::TooDeep);
        }
        self.stack.push(pair);
        let r = self.assignable_views(t1, t2);
        self.stack.pop();
        r
    }

    /// T1 is strongly assignable from T2 (§7.2.4.2): assignable, and T2 delimited.
    pub(crate) fn strongly_assignable(
        &mut self,
        t1: &TypeIdentifier,
        t2: &TypeIdentifier,
    ) -> Result<(), NotAssignable> {
        if t1 == t2 {
            return Ok(());
        }
        if !self.is_delimited(t2, 0)? {
            return Err(NotAssignable::NotDelimited);
        }
        self.assignable(t1, t2)
    }

    fn assignable_views(
        &mut self,
        t1: &TypeIdentifier,
        t2: &TypeIdentifier,
    ) -> Result<(), NotAssignable> {
        let (v1, v2) = (self.view(t1)?, self.view(t2)?);
        self.assignable_resolved(&v1, &v2)
    }
}
