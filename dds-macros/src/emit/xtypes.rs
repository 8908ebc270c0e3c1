//! `impl XTypesType`: the type's XTypes description (members, ids, flags, bounds), from which the runtime builds
//! its type objects once. Generic types describe themselves as unsupported (their description would have to be
//! per instantiation).

use proc_macro2::TokenStream;
use quote::quote;
use syn::{Expr, Type};

use super::{ext_tokens, impl_attrs, member_id};
use crate::attrs::{FieldAttrs, HashId};
use crate::model::{Bitmask, Container, Data, Enum, Struct, Transparent, Union};

/// The `XTypesType` impl of `c`.
pub(super) fn xtypes_impl(c: &Container) -> TokenStream {
    let rt = c.runtime();
    let x = quote!(#rt::xtypes);
    let name = c.ident();
    let attrs = impl_attrs();
    let (impl_g, ty_g, where_c) = c.input.generics.split_for_impl();
    if !c.input.generics.params.is_empty() {
        return quote! {
            #attrs
            impl #impl_g #x::XTypesType for #name #ty_g #where_c {
                fn xtypes_desc() -> #x::TypeDesc {
                    #x::TypeDesc::Unsupported("generic Rust types have no XTypes description")
                }
            }
        };
    }
    let type_name = &c.type_name;
    let def = match &c.data {
        Data::Struct(s) => struct_def(c, s),
        Data::Enum(e) => enum_def(c, e),
        Data::Union(u) => union_def(c, u),
        Data::Bitmask(b) => bitmask_def(c, b),
        Data::Transparent(t) => return transparent(c, t),
    };
    quote! {
        #attrs
        impl #x::XTypesType for #name {
            fn xtypes_desc() -> #x::TypeDesc {
                fn def() -> #x::TypeDef {
                    #def
                }
                #x::TypeDesc::Named(#x::NamedRef { name: #type_name, def })
            }

            fn type_support() -> ::core::option::Option<&'static #x::TypeSupport> {
                static SUPPORT: ::std::sync::OnceLock<::core::option::Option<#x::TypeSupport>> =
                    ::std::sync::OnceLock::new();
                SUPPORT
                    .get_or_init(|| #x::TypeSupport::build(#x::TypeRef(<Self as #x::XTypesType>::xtypes_desc)).ok())
                    .as_ref()
            }
        }
    }
}

/// The description function of a member: the type its `#[dds(xtypes = T)]` names (which says all of it:
/// typedefs, bounds, octets), else its own type with its bound and `octet` mark.
fn member_ref(c: &Container, ty: &Type, a: &FieldAttrs) -> TokenStream {
    match &a.xtypes {
        Some(t) => {
            let rt = c.runtime();
            quote!(#rt::xtypes::TypeRef(<#t as #rt::xtypes::XTypesType>::xtypes_desc))
        }
        None => type_ref(c, ty, a.bound.as_ref(), a.octet),
    }
}

/// The description function of a member type, with its bound and `octet` mark.
fn type_ref(c: &Container, ty: &Type, bound: Option<&Expr>, octet: bool) -> TokenStream {
    let x = {
        let rt = c.runtime();
        quote!(#rt::xtypes)
    };
    match (bound, octet) {
        (Some(b), false) => quote!(#x::TypeRef(#x::bounded_desc::<#ty, { (#b) as u32 }>)),
        (Some(b), true) => quote!(#x::TypeRef(#x::bounded_octet_desc::<#ty, { (#b) as u32 }>)),
        (None, false) => quote!(#x::TypeRef(<#ty as #x::XTypesType>::xtypes_desc)),
        (None, true) => quote!(#x::TypeRef(#x::octet_desc::<#ty>)),
    }
}

fn member_flags(c: &Container, a: &FieldAttrs, key: bool, optional: bool) -> TokenStream {
    let rt = c.runtime();
    let mut flags = Vec::new();
    for (on, f) in [
        (key, "IS_KEY"),
        (optional, "IS_OPTIONAL"),
        (a.external, "IS_EXTERNAL"),
        (a.must_understand, "IS_MUST_UNDERSTAND"),
        (a.default.is_some(), "TRY_CONSTRUCT2"),
    ] {
        if on {
            let f = syn::Ident::new(f, proc_macro2::Span::call_site());
            flags.push(quote!(#rt::xtypes::typeobject::MemberFlag::#f));
        }
    }
    quote!(#rt::xtypes::typeobject::MemberFlag::empty() #(| #flags)*)
}

fn struct_def(c: &Container, s: &Struct) -> TokenStream {
    let rt = c.runtime();
    let x = quote!(#rt::xtypes);
    let ext = ext_tokens(c, s.ext);
    let autoid_hash = c.attrs.autoid_hash;
    let nested = c.attrs.nested;
    let base = match &s.base {
        Some(b) => {
            let r = type_ref(c, b.ty, None, false);
            quote!(::core::option::Option::Some(#r))
        }
        None => quote!(::core::option::Option::None),
    };
    let members = s
        .fields
        .iter()
        .filter(|f| !f.attrs.non_serialized)
        .map(|f| {
            let name = &f.wire_name;
            let id = member_id(c, s, f.id);
            let flags = member_flags(c, &f.attrs, f.key(), f.optional);
            let ty = member_ref(c, f.inner, &f.attrs);
            let hash_id = match &f.attrs.hashid {
                HashId::Unset => quote!(::core::option::Option::None),
                HashId::OfName => quote!(::core::option::Option::Some("")),
                HashId::Of(s) => quote!(::core::option::Option::Some(#s)),
            };
            quote!({
                let mut m = #x::MemberDef::new(#name, #id, #flags, #ty);
                m.hash_id = #hash_id;
                m
            })
        });
    quote!(#x::TypeDef::Struct(#x::StructDef {
        extensibility: #ext,
        autoid_hash: #autoid_hash,
        nested: #nested,
        base: #base,
        members: ::std::vec![#(#members),*],
    }))
}

fn enum_def(c: &Container, e: &Enum) -> TokenStream {
    let rt = c.runtime();
    let x = quote!(#rt::xtypes);
    let ext = ext_tokens(c, e.ext);
    let bit_bound = e.bit_bound as u16;
    let literals = e.enumerators.iter().map(|v| {
        let name = &v.name;
        let value = v.value as i32;
        let default = e.default == Some(&v.variant.ident);
        quote!((#name, #value, #default))
    });
    quote!(#x::TypeDef::Enum(#x::EnumDef {
        extensibility: #ext,
        bit_bound: #bit_bound,
        literals: ::std::vec![#(#literals),*],
    }))
}

fn union_def(c: &Container, u: &Union) -> TokenStream {
    let rt = c.runtime();
    let x = quote!(#rt::xtypes);
    let ext = ext_tokens(c, u.ext);
    let disc = &u.disc;
    let disc_ref = type_ref(c, disc, None, false);
    let cases = u.cases.iter().map(|k| {
        let name = &k.name;
        let id = k.id;
        let is_default = k.attrs.default;
        let labels = super::encode::labels(c, u, k)
            .into_iter()
            .map(|l| quote!((#l) as i32));
        let (ty, external) = match &k.payload {
            Some(p) => {
                let r = member_ref(c, p.ty, &p.attrs);
                (quote!(::core::option::Option::Some(#r)), p.attrs.external)
            }
            None => (quote!(::core::option::Option::None), false),
        };
        quote!(#x::CaseDef {
            name: #name,
            id: #id,
            labels: ::std::vec![#(#labels),*],
            is_default: #is_default,
            ty: #ty,
            external: #external,
        })
    });
    let nested = c.attrs.nested;
    quote!(#x::TypeDef::Union(#x::UnionDef {
        extensibility: #ext,
        nested: #nested,
        discriminator: #disc_ref,
        discriminator_key: false,
        cases: ::std::vec![#(#cases),*],
    }))
}

fn bitmask_def(c: &Container, b: &Bitmask) -> TokenStream {
    let rt = c.runtime();
    let x = quote!(#rt::xtypes);
    let name = c.ident();
    let bit_bound = b.bit_bound as u16;
    let ext = ext_tokens(c, c.attrs.ext.unwrap_or(crate::attrs::Ext::Final));
    // bitflags keeps the Rust constant names; idlc writes IDL flag names in upper case, so the IDL name is
    // taken to be the lower-case form (see docs/xtypes.md).
    quote!(#x::TypeDef::Bitmask(#x::BitmaskDef {
        extensibility: #ext,
        bit_bound: #bit_bound,
        flags: <#name as #rt::__private::bitflags::Flags>::FLAGS
            .iter()
            .map(|f| (f.name().to_lowercase(), f.value().bits().trailing_zeros() as u16))
            .collect(),
    }))
}

/// A typedef is described as the type it wraps.
fn transparent(c: &Container, t: &Transparent) -> TokenStream {
    let rt = c.runtime();
    let x = quote!(#rt::xtypes);
    let name = c.ident();
    let attrs = impl_attrs();
    let r = type_ref(c, t.ty, t.bound.as_ref(), t.octet);
    quote! {
        #attrs
        impl #x::XTypesType for #name {
            fn xtypes_desc() -> #x::TypeDesc {
                #r.desc()
            }
        }
    }
}
