//! Keys: whether a struct has keys, the size scan behind the key hash (`key_max_end`: the largest end offset
//! the plain key stream can reach, to tell whether it fits in 16 bytes) and `KEY_HAS_MUTABLE`.
//!
//! Key-only encoding and decoding are in [`encode`](super::encode) and [`decode`](super::decode), beside the
//! full ones they share their member code with.

use proc_macro2::TokenStream;
use quote::quote;

use super::{base_in_consts, bound_option, ext_tokens, union_case_consts, Members};
use crate::attrs::Ext;
use crate::model::{Container, Enum, Field, Struct, Union};

/// `StructMembers::HAS_KEYS`: own key members, or a base with keys.
pub(super) fn has_keys(c: &Container, s: &Struct, m: &Members) -> TokenStream {
    let cdr = c.cdr();
    let own = m.own_keys();
    let base = match &s.base {
        Some(b) => {
            let bt = b.ty;
            quote!(<#bt as #cdr::StructMembers>::HAS_KEYS)
        }
        None => quote!(false),
    };
    quote!(#own || #base)
}

/// `StructMembers::key_members_max_end`: the key members in member-id order, or all members of a struct
/// without keys.
pub(super) fn key_members_max_end(c: &Container, s: &Struct, m: &Members) -> TokenStream {
    let cdr = c.cdr();
    let keys = m.keys_by_id.iter().map(|f| scan(c, f));
    let all = m.all_by_id.iter().map(|f| scan(c, f));
    let (base_all, base_keys) = match &s.base {
        Some(b) => {
            let bt = b.ty;
            (
                quote!(p = <#bt as #cdr::StructMembers>::key_members_max_end(p, version, ext)?;),
                quote!(if <#bt as #cdr::StructMembers>::HAS_KEYS {
                    p = <#bt as #cdr::StructMembers>::key_members_max_end(p, version, ext)?;
                }),
            )
        }
        None => (quote!(), quote!()),
    };
    quote! {
        fn key_members_max_end(
            start: usize,
            version: #cdr::XcdrVersion,
            ext: #cdr::Extensibility,
        ) -> ::core::option::Option<usize> {
            let mut p = start;
            if <Self as #cdr::StructMembers>::HAS_KEYS {
                #base_keys
                #(#keys)*
            } else {
                #base_all
                #(#all)*
            }
            let _ = (version, ext);
            ::core::option::Option::Some(p)
        }
    }
}

/// One member's contribution to the scan: an optional member's presence flag, then its value.
fn scan(c: &Container, f: &Field) -> TokenStream {
    let cdr = c.cdr();
    let t = f.value_ty();
    let bo = bound_option(f.attrs.bound.as_ref());
    let presence = if f.optional {
        quote!(if version == #cdr::XcdrVersion::Xcdr2 { p += 1; } else { p = ((p + 3) & !3) + 12; })
    } else {
        quote!()
    };
    quote!(
        #presence
        p = <#t as #cdr::CdrType>::key_max_end(p, version, #bo)?;
    )
}

/// A struct's `CdrType::key_max_end`.
pub(super) fn struct_key_max_end(c: &Container, ext: Ext) -> TokenStream {
    let cdr = c.cdr();
    let ext_t = ext_tokens(c, ext);
    key_max_end_fn(
        c,
        quote! {
            if start > 64 {
                return ::core::option::Option::None;
            }
            // The hashed key stream is plain: no DHEADER, EMHEADER or parameter list.
            <Self as #cdr::StructMembers>::key_members_max_end(start, version, #ext_t)
        },
    )
}

/// A struct's `CdrType::KEY_HAS_MUTABLE`: a mutable type on the key path (the struct itself, its key members
/// or, without keys, any member, and its base).
pub(super) fn struct_key_has_mutable(c: &Container, s: &Struct, m: &Members) -> TokenStream {
    let cdr = c.cdr();
    let is_mutable = s.ext == Ext::Mutable;
    let own_keys = m.own_keys();
    let terms = m
        .in_consts()
        .into_iter()
        .filter(|f| !own_keys || f.key())
        .map(|f| {
            let t = f.inner;
            quote!(<#t as #cdr::CdrType>::KEY_HAS_MUTABLE)
        });
    let base = base_in_consts(c, s).map(|bt| quote!(|| <#bt as #cdr::CdrType>::KEY_HAS_MUTABLE));
    quote!(#is_mutable #(|| #terms)* #base)
}

/// A union's `CdrType::KEY_HAS_MUTABLE`.
pub(super) fn union_key_has_mutable(c: &Container, u: &Union) -> TokenStream {
    let is_mutable = u.ext == Ext::Mutable;
    let terms = union_case_consts(c, u, "KEY_HAS_MUTABLE");
    quote!(#is_mutable #(|| #terms)*)
}

/// A union's `CdrType::key_max_end`: the discriminator, then the largest case.
pub(super) fn union_key_max_end(c: &Container, u: &Union) -> TokenStream {
    let cdr = c.cdr();
    let disc = &u.disc;
    let terms = u.cases.iter().filter_map(|k| k.payload.as_ref()).map(|p| {
        let ty = p.ty;
        let bo = bound_option(p.attrs.bound.as_ref());
        quote!({
            end = end.max(<#ty as #cdr::CdrType>::key_max_end(p, version, #bo)?);
        })
    });
    key_max_end_fn(
        c,
        quote! {
            if start > 64 {
                return ::core::option::Option::None;
            }
            // The hashed key stream is plain: no DHEADER or member headers.
            let p = <#disc as #cdr::CdrType>::key_max_end(start, version, ::core::option::Option::None)?;
            let mut end = p;
            #(#terms)*
            ::core::option::Option::Some(end)
        },
    )
}

/// An enum's `CdrType::key_max_end`: one primitive of the enum's size.
pub(super) fn enum_key_max_end(c: &Container, e: &Enum) -> TokenStream {
    let cdr = c.cdr();
    let size = usize::from(e.size());
    key_max_end_fn(
        c,
        quote! {
            let size = #size;
            ::core::option::Option::Some(#cdr::members::prim_end(start, size, version))
        },
    )
}

/// `CdrType::key_max_end` (the largest end of the plain key stream from `start`, or `None` past 16 bytes'
/// reach) with `body`; the bound argument is not used.
pub(super) fn key_max_end_fn(c: &Container, body: TokenStream) -> TokenStream {
    let cdr = c.cdr();
    quote! {
        fn key_max_end(
            start: usize,
            version: #cdr::XcdrVersion,
            _bound: ::core::option::Option<usize>,
        ) -> ::core::option::Option<usize> {
            #body
        }
    }
}
