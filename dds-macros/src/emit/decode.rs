//! Decoding. A struct decodes into a partial struct (one `Option` per member) that `finish` completes with
//! defaults, so that appendable and mutable samples may lack members; enums and unions decode directly.

use proc_macro2::TokenStream;
use quote::{format_ident, quote};
use syn::{Generics, Ident};

use super::{bound_limit, encode::labels, ext_tokens, impl_attrs, member_id, Members};
use crate::attrs::Ext;
use crate::model::{Case, Container, Enum, Field, Struct, Union};

/// The name of a struct's partial struct.
pub(super) fn partial_ident(name: &Ident) -> Ident {
    format_ident!("__DdsPartial{}", name)
}

/// The partial struct and its `Default`.
pub(super) fn partial_struct(c: &Container, s: &Struct, m: &Members, g: &Generics) -> TokenStream {
    let cdr = c.cdr();
    let partial = partial_ident(c.ident());
    let (impl_g, ty_g, where_c) = g.split_for_impl();
    let (vis, own_generics) = (&c.input.vis, &c.input.generics);
    let attrs = impl_attrs();
    let (base_field, base_default) = match &s.base {
        Some(b) => {
            let (bi, bt) = (b.ident, b.ty);
            (
                quote!(#bi: <#bt as #cdr::StructMembers>::Partial,),
                quote!(#bi: ::core::default::Default::default(),),
            )
        }
        None => (quote!(), quote!()),
    };
    let fields = m.all.iter().map(|f| {
        let (ident, t) = (f.ident, f.value_ty());
        quote!(#ident: ::core::option::Option<#t>,)
    });
    let defaults = m.all.iter().map(|f| {
        let ident = f.ident;
        quote!(#ident: ::core::option::Option::None,)
    });
    quote! {
        #[doc(hidden)]
        #attrs
        #vis struct #partial #own_generics #where_c {
            #base_field
            #(#fields)*
        }

        #attrs
        impl #impl_g ::core::default::Default for #partial #ty_g #where_c {
            fn default() -> Self {
                Self { #base_default #(#defaults)* }
            }
        }
    }
}

/// `StructMembers::decode_members_in_order` (final and appendable encodings).
pub(super) fn decode_members_in_order(c: &Container, s: &Struct, m: &Members) -> TokenStream {
    let cdr = c.cdr();
    let one = |fields: &[&Field]| -> Vec<TokenStream> {
        fields.iter().map(|f| decode_in_order(c, f)).collect()
    };
    let (all, keys) = (one(&m.all), one(&m.keys));
    let (base_all, base_keys) = match &s.base {
        Some(b) => {
            let (bi, bt) = (b.ident, b.ty);
            (
                quote!(<#bt as #cdr::StructMembers>::decode_members_in_order(r, st, &mut p.#bi)?;),
                quote!(if <#bt as #cdr::StructMembers>::HAS_KEYS {
                    <#bt as #cdr::StructMembers>::decode_members_in_order(r, st, &mut p.#bi)?;
                }),
            )
        }
        None => (quote!(), quote!()),
    };
    quote! {
        fn decode_members_in_order(
            r: &mut #cdr::CdrReader<'_>,
            st: &#cdr::members::StructDecoder,
            p: &mut Self::Partial,
        ) -> ::core::result::Result<(), #cdr::DecodeError> {
            if r.key_only() && <Self as #cdr::StructMembers>::HAS_KEYS {
                #base_keys
                #(#keys)*
            } else {
                #base_all
                #(#all)*
            }
            let _ = (r, st, p);
            ::core::result::Result::Ok(())
        }
    }
}

fn decode_in_order(c: &Container, f: &Field) -> TokenStream {
    let cdr = c.cdr();
    let (ident, ty, inner) = (f.ident, f.ty, f.inner);
    let bound = bound_limit(f.attrs.bound.as_ref());
    if f.optional {
        quote!(if st.has_more(r) {
            p.#ident = #cdr::members::decode_optional::<#inner>(r, #bound)?;
        })
    } else {
        quote!(if st.has_more(r) {
            #cdr::members::decode_into_slot::<#ty>(&mut p.#ident, r, #bound)?;
        })
    }
}

/// `StructMembers::decode_member_by_id` (mutable encodings); ids it does not know go to the base.
pub(super) fn decode_member_by_id(c: &Container, s: &Struct, m: &Members) -> TokenStream {
    let cdr = c.cdr();
    let arms = m.all.iter().map(|f| {
        let (ident, t) = (f.ident, f.value_ty());
        let id = member_id(c, s, f.id);
        let bound = bound_limit(f.attrs.bound.as_ref());
        quote!(x if x == #id => {
            #cdr::members::decode_into_slot::<#t>(&mut p.#ident, r, #bound)?;
            ::core::result::Result::Ok(true)
        })
    });
    let fallback = match &s.base {
        Some(b) => {
            let (bi, bt) = (b.ident, b.ty);
            quote!(_ => <#bt as #cdr::StructMembers>::decode_member_by_id(r, id, &mut p.#bi),)
        }
        None => quote!(_ => ::core::result::Result::Ok(false),),
    };
    quote! {
        fn decode_member_by_id(
            r: &mut #cdr::CdrReader<'_>,
            id: u32,
            p: &mut Self::Partial,
        ) -> ::core::result::Result<bool, #cdr::DecodeError> {
            let _ = (&r, &p);
            match id {
                #(#arms)*
                #fallback
            }
        }
    }
}

/// `StructMembers::finish`: the partial struct completed with defaults.
pub(super) fn finish(c: &Container, s: &Struct) -> TokenStream {
    let cdr = c.cdr();
    let base = s.base.as_ref().map(|b| {
        let (bi, bt) = (b.ident, b.ty);
        quote!(#bi: <#bt as #cdr::StructMembers>::finish(p.#bi),)
    });
    let fields = s.fields.iter().map(|f| {
        let ident = f.ident;
        if f.attrs.non_serialized {
            quote!(#ident: ::core::default::Default::default(),)
        } else if f.optional {
            quote!(#ident: p.#ident,)
        } else {
            let d = default_of(c, f);
            quote!(#ident: match p.#ident {
                ::core::option::Option::Some(v) => v,
                ::core::option::Option::None => #d,
            },)
        }
    });
    quote! {
        fn finish(p: Self::Partial) -> Self {
            let _ = &p;
            Self { #base #(#fields)* }
        }
    }
}

/// The value of a member a sample lacks.
fn default_of(c: &Container, f: &Field) -> TokenStream {
    let cdr = c.cdr();
    let ty = f.ty;
    match &f.attrs.default {
        Some(e) => quote!(#e),
        None if f.optional => quote!(::core::option::Option::None),
        None if f.attrs.non_serialized => quote!(::core::default::Default::default()),
        None => quote!(<#ty as #cdr::CdrType>::default_value()),
    }
}

/// A struct's `CdrType::decode`: members by id (mutable), through the partial struct (a derived struct, or a
/// key-only payload), or in order straight into the struct.
pub(super) fn struct_decode(c: &Container, s: &Struct) -> TokenStream {
    let cdr = c.cdr();
    let ext_t = ext_tokens(c, s.ext);
    let partial = quote! {
        let mut st = #cdr::members::begin_decode(r, #ext_t)?;
        let mut p = <<Self as #cdr::StructMembers>::Partial as ::core::default::Default>::default();
        if #ext_t == #cdr::Extensibility::Mutable {
            while let ::core::option::Option::Some(m) = st.next_member(r)? {
                if <Self as #cdr::StructMembers>::decode_member_by_id(r, m.id, &mut p)? {
                    #cdr::members::end_member(r, m);
                } else {
                    #cdr::members::skip_member(r, m)?;
                }
            }
        } else {
            <Self as #cdr::StructMembers>::decode_members_in_order(r, &st, &mut p)?;
        }
        st.end(r);
        ::core::result::Result::Ok(<Self as #cdr::StructMembers>::finish(p))
    };
    let body = if s.ext == Ext::Mutable || s.base.is_some() {
        partial
    } else {
        let direct = decode_direct(c, s);
        quote! {
            if r.key_only() {
                #partial
            } else {
                #direct
            }
        }
    };
    quote! {
        fn decode(r: &mut #cdr::CdrReader<'_>) -> ::core::result::Result<Self, #cdr::DecodeError> {
            #body
        }
    }
}

/// A final or appendable struct without a base decoded member by member into locals, then built: no partial
/// struct of `Option`s to fill and unwrap. A member an older appendable sample lacks gets its default.
fn decode_direct(c: &Container, s: &Struct) -> TokenStream {
    let cdr = c.cdr();
    let ext_t = ext_tokens(c, s.ext);
    let local = |i: usize| format_ident!("__dds_m{}", i);
    let reads = s.fields.iter().enumerate().map(|(i, f)| {
        let (v, ty, inner) = (local(i), f.ty, f.inner);
        let d = default_of(c, f);
        let bound = bound_limit(f.attrs.bound.as_ref());
        if f.attrs.non_serialized {
            quote!(let #v = ::core::default::Default::default();)
        } else if f.optional {
            quote!(let #v = if st.has_more(r) {
                #cdr::members::decode_optional::<#inner>(r, #bound)?
            } else {
                #d
            };)
        } else {
            quote!(let #v = if st.has_more(r) {
                <#ty as #cdr::CdrType>::decode_bounded(r, #bound)?
            } else {
                #d
            };)
        }
    });
    let fields = s.fields.iter().enumerate().map(|(i, f)| {
        let (ident, v) = (f.ident, local(i));
        quote!(#ident: #v,)
    });
    quote! {
        let st = #cdr::members::begin_decode(r, #ext_t)?;
        #(#reads)*
        st.end(r);
        ::core::result::Result::Ok(Self { #(#fields)* })
    }
}

/// A final or appendable struct's `CdrType::decode_in_place`: each member decoded over the old one (strings
/// and sequences keep their buffers), a member the sample lacks set to its default. Mutable structs, derived
/// structs and key-only payloads keep the trait's default (decode, then replace).
pub(super) fn struct_decode_in_place(c: &Container, s: &Struct) -> TokenStream {
    if s.ext == Ext::Mutable || s.base.is_some() {
        return quote!();
    }
    let cdr = c.cdr();
    let ext_t = ext_tokens(c, s.ext);
    let fields = s.fields.iter().map(|f| {
        let (ident, ty, inner) = (f.ident, f.ty, f.inner);
        let d = default_of(c, f);
        let bound = bound_limit(f.attrs.bound.as_ref());
        if f.attrs.non_serialized {
            quote!(self.#ident = ::core::default::Default::default();)
        } else if f.optional {
            quote!(self.#ident = if st.has_more(r) {
                #cdr::members::decode_optional::<#inner>(r, #bound)?
            } else {
                #d
            };)
        } else {
            quote!(if st.has_more(r) {
                <#ty as #cdr::CdrType>::decode_in_place(&mut self.#ident, r, #bound)?;
            } else {
                self.#ident = #d;
            })
        }
    });
    quote! {
        fn decode_in_place(
            &mut self,
            r: &mut #cdr::CdrReader<'_>,
            bound: usize,
        ) -> ::core::result::Result<(), #cdr::DecodeError> {
            let _ = bound;
            if r.key_only() {
                *self = <Self as #cdr::CdrType>::decode(r)?;
                return ::core::result::Result::Ok(());
            }
            let st = #cdr::members::begin_decode(r, #ext_t)?;
            #(#fields)*
            st.end(r);
            ::core::result::Result::Ok(())
        }
    }
}

/// A struct's `CdrType::default_value`.
pub(super) fn struct_default_value(c: &Container, s: &Struct) -> TokenStream {
    let cdr = c.cdr();
    let base = s.base.as_ref().map(|b| {
        let (bi, bt) = (b.ident, b.ty);
        quote!(#bi: <#bt as #cdr::CdrType>::default_value(),)
    });
    let fields = s.fields.iter().map(|f| {
        let ident = f.ident;
        let d = default_of(c, f);
        quote!(#ident: #d,)
    });
    quote! {
        // Only reached for members a sample lacks; kept out of line because inlining it copies the whole
        // default value of every nested struct into each caller (minutes of LLVM time for large types).
        #[cold]
        #[inline(never)]
        fn default_value() -> Self {
            Self { #base #(#fields)* }
        }
    }
}

/// A union's `CdrType::decode`: the discriminator selects the case; no match selects the `default` case or is
/// an error.
pub(super) fn union_decode(c: &Container, u: &Union) -> TokenStream {
    let cdr = c.cdr();
    let (disc, type_name) = (&u.disc, &c.type_name);
    let ext_t = ext_tokens(c, u.ext);
    let arms = u.cases.iter().filter_map(|k| {
        let labels = labels(c, u, k);
        let build = build_case(c, k);
        (!labels.is_empty()).then(|| quote!(x if #(x == #labels)||* => #build,))
    });
    let fallback = match u.cases.iter().rev().find(|k| k.attrs.default) {
        Some(k) => {
            let build = build_case(c, k);
            quote!(_ => #build,)
        }
        None => quote!(other => {
            return ::core::result::Result::Err(#cdr::DecodeError::new(
                at,
                concat!("a case label of ", #type_name),
                #cdr::DecodeErrorKind::InvalidValue { found: other as u64 },
            ));
        }),
    };
    quote! {
        fn decode(r: &mut #cdr::CdrReader<'_>) -> ::core::result::Result<Self, #cdr::DecodeError> {
            let mut st = #cdr::members::begin_decode(r, #ext_t)?;
            let at = r.offset();
            let d = #cdr::members::decode_discriminator::<#disc>(r, &mut st)?;
            let _ = at;
            let v = match d {
                #(#arms)*
                #fallback
            };
            st.end(r);
            ::core::result::Result::Ok(v)
        }
    }
}

/// The case's value, its payload read from `r`.
fn build_case(c: &Container, k: &Case) -> TokenStream {
    let cdr = c.cdr();
    let vi = &k.variant.ident;
    match &k.payload {
        None => quote!(Self::#vi),
        Some(p) => {
            let ty = p.ty;
            let bound = bound_limit(p.attrs.bound.as_ref());
            quote!(Self::#vi(#cdr::members::decode_union_member::<#ty>(r, &mut st, #bound)?))
        }
    }
}

/// A union's `CdrType::default_value`.
pub(super) fn union_default_value(c: &Container, u: &Union) -> TokenStream {
    let cdr = c.cdr();
    let value = u.default_value_case().map(|k| {
        let vi = &k.variant.ident;
        match &k.payload {
            None => quote!(Self::#vi),
            Some(p) => {
                let ty = p.ty;
                quote!(Self::#vi(<#ty as #cdr::CdrType>::default_value()))
            }
        }
    });
    quote! {
        fn default_value() -> Self {
            #value
        }
    }
}

/// An enum's `CdrType::decode`: an unknown value is an error.
pub(super) fn enum_decode(c: &Container, e: &Enum) -> TokenStream {
    let cdr = c.cdr();
    let type_name = &c.type_name;
    let idents = e.enumerators.iter().map(|v| &v.variant.ident);
    let values = e.enumerators.iter().map(|v| v.wire(e.size()));
    let read = enum_read(e.size());
    quote! {
        #[inline]
        fn decode(r: &mut #cdr::CdrReader<'_>) -> ::core::result::Result<Self, #cdr::DecodeError> {
            let at = r.offset();
            let v: u32 = #read;
            match v {
                #(#values => ::core::result::Result::Ok(Self::#idents),)*
                other => ::core::result::Result::Err(#cdr::DecodeError::new(
                    at,
                    concat!("an enumerator of ", #type_name),
                    #cdr::DecodeErrorKind::InvalidValue { found: u64::from(other) },
                )),
            }
        }
    }
}

/// Reads an enum value, in the enum's size, as a `u32`.
pub(super) fn enum_read(size: u8) -> TokenStream {
    match size {
        1 => quote!(u32::from(r.read_u8("enum")?)),
        2 => quote!(u32::from(r.read_u16("enum")?)),
        _ => quote!(r.read_u32("enum")?),
    }
}
