//! Code generation from the checked model. The emitters each own one concern and only read the model:
//! [`encode`], [`decode`], [`key`] (key-only streams, the key hash's size scan), [`layout`] (compile-time
//! constants), [`describe`] (`DdsType` and its type descriptor) and [`fields`] (member access for content
//! filters); [`newtype`] covers typedefs and bitmasks.
//! This module puts their pieces together into the impls of one container.

mod decode;
mod describe;
mod encode;
mod fields;
mod key;
mod layout;
mod newtype;
mod xtypes;

use proc_macro2::TokenStream;
use quote::quote;
use syn::{Expr, Generics};

use crate::attrs::Ext;
use crate::model::{Container, Data, Enum, Field, MemberId, Struct, Union};
use crate::types::mentions;

/// Every impl (and the decoder's partial struct) for `c`.
pub(crate) fn container(c: &Container) -> TokenStream {
    let mut out = match &c.data {
        Data::Struct(s) => struct_impls(c, s),
        Data::Enum(e) => enum_impls(c, e),
        Data::Union(u) => union_impls(c, u),
        Data::Transparent(t) => newtype::transparent(c, t),
        Data::Bitmask(b) => newtype::bitmask(c, b),
    };
    out.extend(xtypes::xtypes_impl(c));
    out.extend(match &c.data {
        Data::Struct(s) => fields::struct_fields(c, s, &c.input.generics),
        Data::Enum(e) => fields::enum_fields(c, e),
        Data::Union(u) => fields::union_fields(c, u),
        Data::Transparent(_) => fields::transparent_fields(c),
        Data::Bitmask(_) => fields::bitmask_fields(c),
    });
    out
}

fn struct_impls(c: &Container, s: &Struct) -> TokenStream {
    let cdr = c.cdr();
    let name = c.ident();
    let generics = struct_generics(c);
    let (impl_g, ty_g, where_c) = generics.split_for_impl();
    let attrs = impl_attrs();
    let m = Members::of(s);
    let partial = decode::partial_ident(name);
    let partial_decl = decode::partial_struct(c, s, &m, &generics);
    let has_keys = key::has_keys(c, s, &m);
    let encode_members = encode::encode_members(c, s, &m);
    let decode_in_order = decode::decode_members_in_order(c, s, &m);
    let decode_by_id = decode::decode_member_by_id(c, s, &m);
    let finish = decode::finish(c, s);
    let key_members = key::key_members_max_end(c, s, &m);
    let min_size = layout::min_size(c, s, &m);
    let plain = layout::xcdr1_plain(c, s, &m);
    let key_has_mutable = key::struct_key_has_mutable(c, s, &m);
    let next_id = layout::next_member_id(c, s);
    let encode = encode::struct_encode(c, s.ext);
    let decode = decode::struct_decode(c, s);
    let decode_in_place = decode::struct_decode_in_place(c, s);
    let default_value = decode::struct_default_value(c, s);
    let key_max_end = key::struct_key_max_end(c, s.ext);
    let dds_type = describe::dds_type(
        c,
        &generics,
        s.ext,
        quote!(<Self as #cdr::StructMembers>::HAS_KEYS),
        describe::struct_members(c, s, &m),
    );
    quote! {
        #partial_decl

        #attrs
        impl #impl_g #cdr::StructMembers for #name #ty_g #where_c {
            type Partial = #partial #ty_g;
            const HAS_KEYS: bool = #has_keys;
            #encode_members
            #decode_in_order
            #decode_by_id
            #finish
            #key_members
        }

        #attrs
        impl #impl_g #cdr::CdrType for #name #ty_g #where_c {
            const LAYOUT: #cdr::Layout = #cdr::Layout::Other;
            const MIN_SIZE: usize = #min_size;
            const XCDR1_PLAIN: bool = #plain;
            const KEY_HAS_MUTABLE: bool = #key_has_mutable;
            const NEXT_MEMBER_ID: u32 = #next_id;
            #encode
            #decode
            #decode_in_place
            #default_value
            #key_max_end
        }

        #dds_type
    }
}

/// The struct's generics with `T: CdrType + FilterFields + Send + Sync + 'static` on every type parameter.
fn struct_generics(c: &Container) -> Generics {
    let cdr = c.cdr();
    let rt = c.runtime();
    let mut generics = c.input.generics.clone();
    let params: Vec<syn::Ident> = generics.type_params().map(|t| t.ident.clone()).collect();
    let wc = generics.make_where_clause();
    for p in params {
        wc.predicates.push(syn::parse_quote!(#p: #cdr::CdrType + #rt::filter::FilterFields + ::core::marker::Send + ::core::marker::Sync + 'static));
    }
    generics
}

fn enum_impls(c: &Container, e: &Enum) -> TokenStream {
    let cdr = c.cdr();
    let name = c.ident();
    let attrs = impl_attrs();
    let size = e.size();
    let encode = encode::enum_encode(c, e);
    let decode = decode::enum_decode(c, e);
    let default = e.default;
    let key_max_end = key::enum_key_max_end(c, e);
    let discriminator = enum_discriminator(c, e);
    let dds_type = describe::dds_type(
        c,
        &c.input.generics,
        e.ext,
        quote!(false),
        describe::enum_members(c, e),
    );
    quote! {
        #attrs
        impl #cdr::CdrType for #name {
            const LAYOUT: #cdr::Layout = #cdr::Layout::Enumerated(#size);
            #encode
            #decode

            fn default_value() -> Self {
                Self::#default
            }
            #key_max_end
        }

        #discriminator

        #dds_type
    }
}

/// An enum can discriminate a union: `cdr::Discriminator`.
fn enum_discriminator(c: &Container, e: &Enum) -> TokenStream {
    let cdr = c.cdr();
    let name = c.ident();
    let attrs = impl_attrs();
    let idents = e.enumerators.iter().map(|v| &v.variant.ident);
    let values: Vec<i64> = e
        .enumerators
        .iter()
        .map(|v| i64::from(v.wire(e.size())))
        .collect();
    let write = encode::enum_write(e.size());
    let read = decode::enum_read(e.size());
    quote! {
        #attrs
        impl #cdr::Discriminator for #name {
            const SEARCH: #cdr::DefaultSearch = #cdr::DefaultSearch::Enum;

            fn to_raw(&self) -> i64 {
                match self { #(Self::#idents => #values,)* }
            }

            fn write_raw(w: &mut #cdr::CdrWriter<'_>, raw: i64) -> ::core::result::Result<(), #cdr::EncodeError> {
                let v = raw as u32;
                #write;
                ::core::result::Result::Ok(())
            }

            fn read_raw(r: &mut #cdr::CdrReader<'_>) -> ::core::result::Result<i64, #cdr::DecodeError> {
                let v: u32 = #read;
                ::core::result::Result::Ok(i64::from(v))
            }

            fn enumerators() -> &'static [i64] {
                &[#(#values),*]
            }
        }
    }
}

fn union_impls(c: &Container, u: &Union) -> TokenStream {
    let cdr = c.cdr();
    let name = c.ident();
    let attrs = impl_attrs();
    let plain = layout::union_xcdr1_plain(c, u);
    let key_has_mutable = key::union_key_has_mutable(c, u);
    let encode = encode::union_encode(c, u);
    let decode = decode::union_decode(c, u);
    let default_value = decode::union_default_value(c, u);
    let key_max_end = key::union_key_max_end(c, u);
    let dds_type = describe::dds_type(
        c,
        &c.input.generics,
        u.ext,
        quote!(false),
        describe::union_members(c, u),
    );
    quote! {
        #attrs
        impl #cdr::CdrType for #name {
            const LAYOUT: #cdr::Layout = #cdr::Layout::Other;
            const XCDR1_PLAIN: bool = #plain;
            const KEY_HAS_MUTABLE: bool = #key_has_mutable;
            #encode
            #decode
            #default_value
            #key_max_end
        }

        #dds_type
    }
}

/// A struct's serialized members, in declaration order and in member-id order, with the key members apart.
struct Members<'m, 'a> {
    all: Vec<&'m Field<'a>>,
    all_by_id: Vec<&'m Field<'a>>,
    keys: Vec<&'m Field<'a>>,
    keys_by_id: Vec<&'m Field<'a>>,
}

impl<'m, 'a> Members<'m, 'a> {
    fn of(s: &'m Struct<'a>) -> Self {
        let all: Vec<&Field> = s.fields.iter().filter(|f| f.serialized()).collect();
        let keys: Vec<&Field> = all.iter().copied().filter(|f| f.key()).collect();
        let by_id = |v: &[&'m Field<'a>]| {
            let mut v = v.to_vec();
            v.sort_by_key(|f| f.id.order());
            v
        };
        Members {
            all_by_id: by_id(&all),
            keys_by_id: by_id(&keys),
            all,
            keys,
        }
    }

    /// The struct has key members of its own (its base may have others).
    fn own_keys(&self) -> bool {
        !self.keys.is_empty()
    }

    /// The members that may appear in the type's compile-time constants: those not naming the type itself.
    fn in_consts(&self) -> Vec<&'m Field<'a>> {
        self.all.iter().copied().filter(|f| !f.self_ref).collect()
    }
}

/// The base type, when it may appear in the type's compile-time constants.
fn base_in_consts<'a>(c: &Container, s: &Struct<'a>) -> Option<&'a syn::Type> {
    s.base
        .as_ref()
        .map(|b| b.ty)
        .filter(|bt| !mentions(bt, c.ident()))
}

/// `<T as CdrType>::NAME` for the payload type of every union case that may appear in constants.
fn union_case_consts(c: &Container, u: &Union, name: &str) -> Vec<TokenStream> {
    let cdr = c.cdr();
    let name = syn::Ident::new(name, proc_macro2::Span::call_site());
    u.cases
        .iter()
        .filter_map(|k| k.payload.as_ref())
        .filter(|p| !p.self_ref)
        .map(|p| {
            let ty = p.ty;
            quote!(<#ty as #cdr::CdrType>::#name)
        })
        .collect()
}

/// A struct member's id as an expression.
fn member_id(c: &Container, s: &Struct, id: MemberId) -> TokenStream {
    let cdr = c.cdr();
    match (id, &s.base) {
        (MemberId::AfterBase(k), Some(b)) => {
            let bt = b.ty;
            quote!((<#bt as #cdr::CdrType>::NEXT_MEMBER_ID + #k))
        }
        (MemberId::Absolute(k) | MemberId::AfterBase(k), _) => quote!(#k),
    }
}

/// A member's bound as a `usize` (`usize::MAX` when unbounded).
fn bound_limit(bound: Option<&Expr>) -> TokenStream {
    match bound {
        Some(b) => quote!((#b) as usize),
        None => quote!(usize::MAX),
    }
}

/// A member's bound as an `Option<usize>`.
fn bound_option(bound: Option<&Expr>) -> TokenStream {
    match bound {
        Some(b) => quote!(::core::option::Option::Some((#b) as usize)),
        None => quote!(::core::option::Option::None),
    }
}

/// The runtime's `Extensibility` value.
fn ext_tokens(c: &Container, ext: Ext) -> TokenStream {
    let cdr = c.cdr();
    match ext {
        Ext::Final => quote!(#cdr::Extensibility::Final),
        Ext::Appendable => quote!(#cdr::Extensibility::Appendable),
        Ext::Mutable => quote!(#cdr::Extensibility::Mutable),
    }
}

/// Attributes put on every generated impl: generated code must be warning- and clippy-free in user crates.
fn impl_attrs() -> TokenStream {
    quote! {
        #[automatically_derived]
        #[allow(clippy::all, clippy::pedantic, clippy::nursery, unused_qualifications, non_camel_case_types)]
    }
}
