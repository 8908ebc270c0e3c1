//! Checks on the finished model: what cannot be told from one attribute alone (an attribute on the wrong kind
//! of item, member ids that collide, enumerator values out of range...). Every problem goes into the [`Ctxt`].

use crate::attrs::Ext;
use crate::ctxt::Ctxt;
use crate::model::{is_boxed, Container, Data, Enum, Field, MemberId, Struct, Union};

/// Reports every problem of `c`.
pub(crate) fn check(cx: &mut Ctxt, c: &Container) {
    match &c.data {
        Data::Struct(s) => check_struct(cx, c, s),
        Data::Enum(e) => {
            enum_shape(cx, c, "enums");
            check_enum(cx, c, e);
        }
        Data::Union(u) => {
            enum_shape(cx, c, "unions");
            check_union(cx, c, u);
        }
        Data::Bitmask(_) => {
            if let Some((b, span)) = c.attrs.bit_bound {
                if !(1..=64).contains(&b) {
                    cx.error_at(span, "a bitmask's bit_bound must be in 1..=64");
                }
            }
        }
        Data::Transparent(_) => {}
    }
}

fn check_struct(cx: &mut Ctxt, c: &Container, s: &Struct) {
    if c.attrs.bit_bound.is_some() || c.attrs.discriminator.is_some() {
        cx.error_spanned_by(
            c.ident(),
            "`bit_bound` and `discriminator` do not apply to structs",
        );
    }
    // Ids relative to a base are only known to the compiler; every other id is checked here, since two members
    // with one id would silently decode into the wrong field.
    let mut seen: Vec<&Field> = Vec::new();
    for f in &s.fields {
        check_field(cx, f);
        if f.id.order() > 0x0fff_ffff {
            cx.error_spanned_by(f.field, "member ids are limited to 28 bits");
            continue;
        }
        let MemberId::Absolute(id) = f.id else {
            continue;
        };
        if f.serialized() {
            if let Some(other) = seen.iter().find(|o| o.id == f.id) {
                cx.error_spanned_by(
                    f.field,
                    format!("member id {id} is already used by `{}`", other.ident),
                );
            }
            seen.push(f);
        }
    }
}

fn check_field(cx: &mut Ctxt, f: &Field) {
    let a = &f.attrs;
    if a.optional && !f.optional {
        cx.error_spanned_by(f.ty, "`#[dds(optional)]` needs a field of type `Option<T>`");
    }
    if let Some(span) = a.key {
        if f.optional {
            cx.error_at(
                span,
                "`#[dds(key)]` cannot be applied to an optional member",
            );
        }
        if a.non_serialized {
            cx.error_at(
                span,
                "`#[dds(key)]` cannot be applied to a non_serialized member",
            );
        }
    }
    if a.external && !is_boxed(f) {
        cx.error_spanned_by(
            f.ty,
            "`#[dds(external)]` needs a field of type `Box<T>` or `Option<Box<T>>`",
        );
    }
}

/// What IDL enums and unions have in common: not generic, not a `bitmask` or `transparent`.
fn enum_shape(cx: &mut Ctxt, c: &Container, what: &str) {
    if c.attrs.bitmask || c.attrs.transparent {
        cx.error_spanned_by(
            c.ident(),
            "`bitmask` and `transparent` apply to tuple structs",
        );
    }
    if !c.input.generics.params.is_empty() {
        cx.error_spanned_by(
            &c.input.generics,
            format!("DdsType {what} cannot be generic"),
        );
    }
}

fn check_enum(cx: &mut Ctxt, c: &Container, e: &Enum) {
    if e.ext == Ext::Mutable {
        cx.error_spanned_by(c.ident(), "an enum cannot be mutable");
    }
    if e.enumerators.is_empty() {
        cx.error_spanned_by(c.ident(), "an IDL enum needs at least one enumerator");
    }
    if let Some((b, span)) = c.attrs.bit_bound {
        if !(1..=32).contains(&b) {
            cx.error_at(span, "an enum's bit_bound must be in 1..=32");
        }
    }
    // IDL enumerators are signed (int8/int16/int32 holders); accept the unsigned range of the bit bound too.
    let lo = -(1i64 << (e.bit_bound - 1));
    let hi = (1i64 << e.bit_bound) - 1;
    let mut seen = Vec::new();
    for v in &e.enumerators {
        let a = &v.attrs;
        if !a.cases.is_empty() || a.default || a.id.is_some() {
            cx.error_spanned_by(
                v.variant,
                "`case`, `default` and `id` belong to union variants",
            );
        }
        if v.value < lo || v.value > hi {
            cx.error_spanned_by(v.variant, "enumerator value out of range for the bit_bound");
            continue;
        }
        let wire = v.wire(e.size());
        if seen.contains(&wire) {
            cx.error_spanned_by(v.variant, "duplicate enumerator value");
        }
        seen.push(wire);
    }
}

fn check_union(cx: &mut Ctxt, c: &Container, u: &Union) {
    for case in &u.cases {
        let a = &case.attrs;
        if a.value.is_some() {
            cx.error_spanned_by(
                case.variant,
                "`value` belongs to enumerators, not union cases",
            );
        }
        if a.cases.is_empty() && !a.default {
            cx.error_spanned_by(
                case.variant,
                "a union variant needs `#[dds(case = ...)]` or `#[dds(default)]`",
            );
        }
        if let Some(p) = &case.payload {
            let fa = &p.attrs;
            if fa.key.is_some() || fa.optional || fa.base || fa.non_serialized || fa.id.is_some() {
                cx.error_spanned_by(
                    p.field,
                    "a union case accepts only `bound`, `octet`, `xtypes`, `external`, `name`, `must_understand` and `recursive`",
                );
            }
        }
    }
    if u.default_value_case().is_none() {
        cx.error_spanned_by(c.ident(), "a union needs a variant that is not recursive");
    }
    check_unit_cases(cx, u);
}

/// XTypes has no member-less case: the type objects leave a unit variant out, so its labels fall to the
/// default case, whose member a peer would then read. Refused when a default case carries a member.
fn check_unit_cases(cx: &mut Ctxt, u: &Union) {
    let default_has_member = u
        .cases
        .iter()
        .any(|c| c.attrs.default && c.payload.is_some());
    if !default_has_member {
        return;
    }
    for case in u.cases.iter().filter(|c| c.payload.is_none()) {
        cx.error_spanned_by(
            case.variant,
            "a unit variant cannot sit beside a `default` variant with a member: XTypes has no member-less \
             case, so peers decoding by the type objects would read the default member for its labels; \
             give it a member or drop the default",
        );
    }
}
