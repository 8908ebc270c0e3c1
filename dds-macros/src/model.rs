//! The input as the emitters see it: a [`Container`] (struct, enum, union, typedef or bitmask) whose members
//! carry their resolved wire names, member ids and attributes. Built from the syntax tree by [`Container::from_ast`],
//! which reports what it cannot read to the [`Ctxt`] and goes on; [`check`](crate::check) then validates the whole.

use proc_macro2::TokenStream;
use quote::quote;
use syn::{Data as SynData, DeriveInput, Expr, Fields, Ident, Type};

use crate::attrs::{
    parse_field_attrs, parse_int_expr, parse_type_attrs, parse_variant_attrs, Ext, FieldAttrs,
    HashId, TypeAttrs, VariantAttrs,
};
use crate::ctxt::Ctxt;
use crate::types::{box_inner, mentions, option_inner};

/// The type being derived.
pub(crate) struct Container<'a> {
    pub(crate) input: &'a DeriveInput,
    pub(crate) attrs: TypeAttrs,
    /// The scoped IDL name.
    pub(crate) type_name: String,
    pub(crate) data: Data<'a>,
}

/// What kind of IDL type the container is.
pub(crate) enum Data<'a> {
    Struct(Struct<'a>),
    Enum(Enum<'a>),
    Union(Union<'a>),
    /// A one-field tuple struct encoded as its field (typedef).
    Transparent(Transparent<'a>),
    /// A `bitflags` struct.
    Bitmask(Bitmask),
}

/// An IDL struct.
pub(crate) struct Struct<'a> {
    pub(crate) ext: Ext,
    pub(crate) base: Option<Base<'a>>,
    /// The members after the base, in declaration order (`non_serialized` ones included).
    pub(crate) fields: Vec<Field<'a>>,
    /// The id after the last member (`NEXT_MEMBER_ID`, which a derived struct continues from).
    pub(crate) next_id: MemberId,
}

/// The `#[dds(base)]` field holding the base struct.
pub(crate) struct Base<'a> {
    pub(crate) ident: &'a Ident,
    pub(crate) ty: &'a Type,
}

/// A struct member's id.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum MemberId {
    /// Known here.
    Absolute(u32),
    /// The base's `NEXT_MEMBER_ID` plus this offset: known to the compiler only.
    AfterBase(u32),
}

impl MemberId {
    /// Sort key for member-id order (exact unless ids mix base-relative and absolute values).
    pub(crate) fn order(self) -> u64 {
        match self {
            MemberId::Absolute(v) | MemberId::AfterBase(v) => u64::from(v),
        }
    }
}

/// A struct member.
pub(crate) struct Field<'a> {
    pub(crate) field: &'a syn::Field,
    pub(crate) ident: &'a Ident,
    pub(crate) ty: &'a Type,
    /// `T` for an optional `Option<T>` field, else the field type.
    pub(crate) inner: &'a Type,
    pub(crate) optional: bool,
    pub(crate) wire_name: String,
    pub(crate) id: MemberId,
    /// The type names this one (directly, or through `recursive`): left out of the compile-time constants.
    pub(crate) self_ref: bool,
    pub(crate) attrs: FieldAttrs,
}

impl Field<'_> {
    /// On the wire (not `non_serialized`).
    pub(crate) fn serialized(&self) -> bool {
        !self.attrs.non_serialized
    }

    /// A key member.
    pub(crate) fn key(&self) -> bool {
        self.attrs.key.is_some()
    }

    /// The type the wire holds: `T` for an optional member, else the field type.
    pub(crate) fn value_ty(&self) -> &Type {
        if self.optional {
            self.inner
        } else {
            self.ty
        }
    }
}

/// An IDL enum.
pub(crate) struct Enum<'a> {
    pub(crate) ext: Ext,
    /// The `bit_bound` in effect (32 unless given and valid).
    pub(crate) bit_bound: u32,
    pub(crate) enumerators: Vec<Enumerator<'a>>,
    /// The default enumerator: marked with std's `#[default]` (IDL `@default_literal`), else the first.
    pub(crate) default: Option<&'a Ident>,
}

impl Enum<'_> {
    /// Bytes on the wire: 1, 2 or 4, from the bit bound as libddsc does.
    pub(crate) fn size(&self) -> u8 {
        match self.bit_bound {
            0..=8 => 1,
            9..=16 => 2,
            _ => 4,
        }
    }
}

/// One enumerator.
pub(crate) struct Enumerator<'a> {
    pub(crate) variant: &'a syn::Variant,
    pub(crate) value: i64,
    pub(crate) name: String,
    pub(crate) attrs: VariantAttrs,
}

impl Enumerator<'_> {
    /// The value on the wire in `size` bytes (two's complement for negative values).
    pub(crate) fn wire(&self, size: u8) -> u32 {
        let mask = if size == 4 {
            u64::from(u32::MAX)
        } else {
            (1u64 << (8 * size)) - 1
        };
        (self.value as u64 & mask) as u32
    }
}

/// An IDL union.
pub(crate) struct Union<'a> {
    pub(crate) ext: Ext,
    /// The discriminator type (a placeholder after the "needs a discriminator" error, never emitted).
    pub(crate) disc: Type,
    /// The discriminator is `WChar`, whose labels idlc writes as char literals.
    pub(crate) disc_is_wchar: bool,
    pub(crate) cases: Vec<Case<'a>>,
}

impl<'a> Union<'a> {
    /// The case `default_value()` builds: the first one without a payload or with a payload that is not
    /// recursive.
    pub(crate) fn default_value_case(&self) -> Option<&Case<'a>> {
        self.cases
            .iter()
            .find(|c| c.payload.as_ref().is_none_or(|p| !p.self_ref))
    }
}

/// One union case (a variant).
pub(crate) struct Case<'a> {
    pub(crate) variant: &'a syn::Variant,
    pub(crate) id: u32,
    pub(crate) name: String,
    pub(crate) payload: Option<Payload<'a>>,
    pub(crate) attrs: VariantAttrs,
}

/// The one unnamed field of a union case.
pub(crate) struct Payload<'a> {
    pub(crate) field: &'a syn::Field,
    pub(crate) ty: &'a Type,
    pub(crate) self_ref: bool,
    pub(crate) attrs: FieldAttrs,
}

/// A `#[dds(transparent)]` tuple struct.
pub(crate) struct Transparent<'a> {
    pub(crate) ty: &'a Type,
    pub(crate) bound: Option<Expr>,
    /// `#[dds(octet)]` on the field.
    pub(crate) octet: bool,
}

/// A `#[dds(bitmask)]` tuple struct made by `bitflags!`.
pub(crate) struct Bitmask {
    /// The `bit_bound` in effect (32 unless given and valid).
    pub(crate) bit_bound: u32,
}

impl<'a> Container<'a> {
    /// The model of `input`, or `None` when its shape cannot be derived at all (the reason is in `cx`).
    pub(crate) fn from_ast(cx: &mut Ctxt, input: &'a DeriveInput) -> Option<Self> {
        let attrs = parse_type_attrs(cx, &input.attrs);
        let data = match &input.data {
            SynData::Struct(s) if attrs.bitmask => {
                single_field(cx, input, &s.fields, "bitmask")?;
                let bit_bound = match attrs.bit_bound {
                    Some((b, _)) if (1..=64).contains(&b) => b,
                    _ => 32,
                };
                Data::Bitmask(Bitmask { bit_bound })
            }
            SynData::Struct(s) if attrs.transparent => {
                let f = single_field(cx, input, &s.fields, "transparent")?;
                let fa = parse_field_attrs(cx, &f.attrs);
                Data::Transparent(Transparent {
                    ty: &f.ty,
                    bound: fa.bound,
                    octet: fa.octet,
                })
            }
            SynData::Struct(s) => Data::Struct(Struct::from_ast(cx, input, &attrs, &s.fields)?),
            SynData::Enum(e) => {
                let unit_only = e.variants.iter().all(|v| matches!(v.fields, Fields::Unit));
                if unit_only && attrs.discriminator.is_none() {
                    Data::Enum(Enum::from_ast(cx, &attrs, e))
                } else {
                    Data::Union(Union::from_ast(cx, input, &attrs, e))
                }
            }
            SynData::Union(_) => {
                cx.error_spanned_by(
                    &input.ident,
                    "Rust unions are not supported; an IDL union is an enum with `#[dds(discriminator = ...)]`",
                );
                return None;
            }
        };
        let type_name = attrs
            .name
            .clone()
            .unwrap_or_else(|| input.ident.to_string());
        Some(Container {
            input,
            attrs,
            type_name,
            data,
        })
    }

    /// The Rust identifier.
    pub(crate) fn ident(&self) -> &'a Ident {
        &self.input.ident
    }

    /// The path of the runtime's `cdr` module in generated code.
    pub(crate) fn cdr(&self) -> TokenStream {
        let rt = self.runtime();
        quote!(#rt::cdr)
    }

    /// The path of the runtime crate in generated code (`::dds_runtime` unless `crate = "..."`).
    pub(crate) fn runtime(&self) -> TokenStream {
        match &self.attrs.krate {
            Some(p) => quote!(#p),
            None => quote!(::dds_runtime),
        }
    }
}

fn single_field<'a>(
    cx: &mut Ctxt,
    input: &DeriveInput,
    fields: &'a Fields,
    what: &str,
) -> Option<&'a syn::Field> {
    match fields {
        Fields::Unnamed(u) if u.unnamed.len() == 1 => Some(&u.unnamed[0]),
        _ => {
            cx.error_spanned_by(
                &input.ident,
                format!("`#[dds({what})]` needs a tuple struct with exactly one field"),
            );
            None
        }
    }
}

/// Member-id assignment (XTypes 7.3.1.2.1.1, as libddsc computes them): sequential from 0 or after the base,
/// and after an explicit or hashed id the next member continues from it.
struct IdAllocator {
    next: u32,
    after_base: bool,
    autoid_hash: bool,
}

impl IdAllocator {
    fn next(&mut self, attrs: &FieldAttrs, wire_name: &str) -> MemberId {
        let fixed = match (&attrs.id, &attrs.hashid) {
            (Some(id), _) => Some(*id),
            (None, HashId::Of(s)) => Some(hash_id(s)),
            (None, HashId::OfName) => Some(hash_id(wire_name)),
            (None, HashId::Unset) if self.autoid_hash => Some(hash_id(wire_name)),
            (None, HashId::Unset) => None,
        };
        match fixed {
            Some(id) => {
                self.after_base = false;
                self.next = id.saturating_add(1);
                MemberId::Absolute(id)
            }
            None => {
                let k = self.next;
                self.next = k.saturating_add(1);
                if self.after_base {
                    MemberId::AfterBase(k)
                } else {
                    MemberId::Absolute(k)
                }
            }
        }
    }

    /// The id after the last member.
    fn end(&self) -> MemberId {
        if self.after_base {
            MemberId::AfterBase(self.next)
        } else {
            MemberId::Absolute(self.next)
        }
    }
}

/// `@hashid`: MD5 of the name, first 4 bytes little-endian, masked to 28 bits.
fn hash_id(name: &str) -> u32 {
    use md5::{Digest, Md5};
    let d = Md5::digest(name.as_bytes());
    u32::from_le_bytes([d[0], d[1], d[2], d[3]]) & 0x0fff_ffff
}

impl<'a> Struct<'a> {
    fn from_ast(
        cx: &mut Ctxt,
        input: &'a DeriveInput,
        ta: &TypeAttrs,
        fields: &'a Fields,
    ) -> Option<Self> {
        let Fields::Named(named) = fields else {
            cx.error_spanned_by(
                &input.ident,
                "DdsType structs need named fields; a one-field tuple struct needs #[dds(transparent)] or #[dds(bitmask)]",
            );
            return None;
        };
        let mut base = None;
        let mut ids = IdAllocator {
            next: 0,
            after_base: false,
            autoid_hash: ta.autoid_hash,
        };
        let mut out = Vec::new();
        for (i, f) in named.named.iter().enumerate() {
            let Some(ident) = f.ident.as_ref() else {
                continue;
            };
            let attrs = parse_field_attrs(cx, &f.attrs);
            if attrs.base {
                check_base(cx, f, &attrs, i);
                if i == 0 {
                    base = Some(Base { ident, ty: &f.ty });
                    ids.after_base = true;
                }
                continue;
            }
            let inner = option_inner(&f.ty);
            let wire_name = attrs
                .name
                .clone()
                .unwrap_or_else(|| ident.to_string().trim_start_matches("r#").to_owned());
            out.push(Field {
                field: f,
                ident,
                ty: &f.ty,
                inner: inner.unwrap_or(&f.ty),
                optional: inner.is_some(),
                id: ids.next(&attrs, &wire_name),
                wire_name,
                // `recursive` marks a field whose type leads back here through another type (A -> Vec<B> -> A):
                // its constants would depend on this type's own, which rustc rejects as a cycle.
                self_ref: attrs.recursive || mentions(&f.ty, &input.ident),
                attrs,
            });
        }
        Some(Struct {
            ext: ta.ext.unwrap_or(Ext::Appendable),
            base,
            fields: out,
            next_id: ids.end(),
        })
    }
}

/// `base` is the first field and carries nothing else.
fn check_base(cx: &mut Ctxt, f: &syn::Field, attrs: &FieldAttrs, index: usize) {
    if index != 0 {
        cx.error_spanned_by(f, "`#[dds(base)]` must be the first field");
    }
    if attrs.key.is_some() || attrs.optional || attrs.id.is_some() || attrs.non_serialized {
        cx.error_spanned_by(
            f,
            "`#[dds(base)]` cannot be combined with other member attributes",
        );
    }
}

impl<'a> Enum<'a> {
    fn from_ast(cx: &mut Ctxt, ta: &TypeAttrs, data: &'a syn::DataEnum) -> Self {
        let bit_bound = match ta.bit_bound {
            Some((b, _)) if (1..=32).contains(&b) => b,
            _ => 32,
        };
        let mut next: i64 = 0;
        let mut enumerators = Vec::new();
        for v in &data.variants {
            let attrs = parse_variant_attrs(cx, &v.attrs);
            let value = match (attrs.value, &v.discriminant) {
                (Some(x), _) => x,
                (None, Some((_, e))) => cx.ok(parse_int_expr(e)).unwrap_or(next),
                (None, None) => next,
            };
            next = value.saturating_add(1);
            enumerators.push(Enumerator {
                variant: v,
                value,
                name: attrs.name.clone().unwrap_or_else(|| v.ident.to_string()),
                attrs,
            });
        }
        let marked = data
            .variants
            .iter()
            .find(|v| v.attrs.iter().any(|a| a.path().is_ident("default")));
        Enum {
            ext: ta.ext.unwrap_or(Ext::Final),
            bit_bound,
            default: marked.or(data.variants.first()).map(|v| &v.ident),
            enumerators,
        }
    }
}

impl<'a> Union<'a> {
    fn from_ast(
        cx: &mut Ctxt,
        input: &'a DeriveInput,
        ta: &TypeAttrs,
        data: &'a syn::DataEnum,
    ) -> Self {
        let disc = ta.discriminator.clone().unwrap_or_else(|| {
            cx.error_spanned_by(
                &input.ident,
                "a union (enum with data) needs `#[dds(discriminator = Type)]`",
            );
            syn::parse_quote!(i32)
        });
        let disc_is_wchar = matches!(&disc, Type::Path(p) if p.path.segments.last().is_some_and(|s| s.ident == "WChar"));
        // dds_runtime's `UnionType::first_member_id` (the same rule, written down there): from 0 as Cyclone
        // DDS 11 numbers them, from 1 in mutable unions (the discriminator is member 0 on the wire).
        let mut next_id: u32 = u32::from(matches!(ta.ext, Some(Ext::Mutable)));
        let mut cases = Vec::new();
        for v in &data.variants {
            let attrs = parse_variant_attrs(cx, &v.attrs);
            let id = attrs.id.unwrap_or(next_id);
            next_id = id.saturating_add(1);
            let payload = match &v.fields {
                Fields::Unit => None,
                Fields::Unnamed(u) if u.unnamed.len() == 1 => {
                    let f = &u.unnamed[0];
                    let fa = parse_field_attrs(cx, &f.attrs);
                    Some(Payload {
                        field: f,
                        ty: &f.ty,
                        self_ref: fa.recursive || mentions(&f.ty, &input.ident),
                        attrs: fa,
                    })
                }
                _ => {
                    cx.error_spanned_by(
                        v,
                        "a union variant carries exactly one unnamed field (or none)",
                    );
                    continue;
                }
            };
            cases.push(Case {
                variant: v,
                id,
                name: attrs.name.clone().unwrap_or_else(|| v.ident.to_string()),
                payload,
                attrs,
            });
        }
        Union {
            ext: ta.ext.unwrap_or(Ext::Appendable),
            disc,
            disc_is_wchar,
            cases,
        }
    }
}

/// `Box<T>` or `Option<Box<T>>`, as `external` needs.
pub(crate) fn is_boxed(f: &Field) -> bool {
    box_inner(f.inner).is_some()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn struct_ids(input: DeriveInput) -> (Vec<MemberId>, MemberId) {
        let mut cx = Ctxt::default();
        let c = Container::from_ast(&mut cx, &input).expect("a struct");
        assert!(cx.finish().is_ok());
        let Data::Struct(s) = c.data else {
            panic!("not a struct")
        };
        (s.fields.iter().map(|f| f.id).collect(), s.next_id)
    }

    #[test]
    fn ids_are_sequential_and_continue_after_an_explicit_or_hashed_id() {
        use MemberId::Absolute as A;
        let (ids, next) = struct_ids(syn::parse_quote! {
            struct S { a: u8, #[dds(id = 10)] b: u8, c: u8, #[dds(hashid)] d: u8, e: u8 }
        });
        let h = hash_id("d");
        assert_eq!(ids, [A(0), A(10), A(11), A(h), A(h + 1)]);
        assert_eq!(next, A(h + 2));
    }

    #[test]
    fn hashid_of_a_string_and_autoid_hash() {
        let (ids, _) = struct_ids(syn::parse_quote! {
            #[dds(autoid = "hash")]
            struct S { #[dds(name = "wire")] a: u8, #[dds(hashid = "other")] b: u8, #[dds(id = 3)] c: u8 }
        });
        let expected = [hash_id("wire"), hash_id("other"), 3].map(MemberId::Absolute);
        assert_eq!(ids, expected);
    }

    #[test]
    fn ids_after_a_base_are_relative_until_an_explicit_id() {
        use MemberId::{Absolute as A, AfterBase as B};
        let (ids, next) = struct_ids(syn::parse_quote! {
            struct D { #[dds(base)] base: Base, a: u8, b: u8, #[dds(id = 7)] c: u8, d: u8 }
        });
        assert_eq!(ids, [B(0), B(1), A(7), A(8)]);
        assert_eq!(next, A(9));
    }

    #[test]
    fn hash_id_is_md5_little_endian_masked_to_28_bits() {
        // MD5("color") = 70dda5df...: 0xdfa5dd70 & 0x0fffffff.
        assert_eq!(hash_id("color"), 0x0fa5_dd70);
    }
}
