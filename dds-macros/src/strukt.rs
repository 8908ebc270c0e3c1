//! `#[derive(DdsType)]` for structs with named fields (IDL `struct`).

use proc_macro2::{Span, TokenStream};
use quote::{format_ident, quote};
use syn::{DataStruct, DeriveInput, Fields, Ident, Result, Type};

use crate::attrs::{hash_id, parse_field_attrs, Ext, FieldAttrs, TypeAttrs};
use crate::util::{box_inner, ext_tokens, impl_attrs, mentions, option_inner};

struct Field {
    ident: Ident,
    ty: Type,
    /// `T` for an optional `Option<T>` field, else the field type.
    inner: Type,
    attrs: FieldAttrs,
    optional: bool,
    key: bool,
    wire_name: String,
    /// Member id as an expression (may depend on the base's last id).
    id: TokenStream,
    /// Sort key for member-id order (exact unless ids mix base-relative and absolute values).
    id_order: u64,
    bound: TokenStream,
    bound_opt: TokenStream,
    self_ref: bool,
}

pub fn derive(
    input: &DeriveInput,
    data: &DataStruct,
    ta: &TypeAttrs,
    rt: &TokenStream,
) -> Result<TokenStream> {
    let cdr = quote!(#rt::cdr);
    let name = &input.ident;
    let Fields::Named(named) = &data.fields else {
        return Err(syn::Error::new_spanned(
            &input.ident,
            "DdsType structs need named fields; a one-field tuple struct needs #[dds(transparent)] or #[dds(bitmask)]",
        ));
    };
    if ta.bit_bound.is_some() || ta.discriminator.is_some() {
        return Err(syn::Error::new_spanned(
            &input.ident,
            "`bit_bound` and `discriminator` do not apply to structs",
        ));
    }
    let ext = ta.ext.unwrap_or(Ext::Appendable);
    let ext_t = ext_tokens(&cdr, ext);

    // Collect fields and member ids.
    let mut fields = Vec::new();
    let mut base: Option<(Ident, Type)> = None;
    let mut next_rel: u32 = 0;
    let mut relative = false;
    let mut absolute_ids: Vec<(u64, String)> = Vec::new();
    for (i, f) in named.named.iter().enumerate() {
        let ident = f.ident.clone().expect("named field");
        let attrs = parse_field_attrs(&f.attrs)?;
        if attrs.base {
            if i != 0 {
                return Err(syn::Error::new_spanned(
                    f,
                    "`#[dds(base)]` must be the first field",
                ));
            }
            if attrs.key.is_some() || attrs.optional || attrs.id.is_some() || attrs.non_serialized {
                return Err(syn::Error::new_spanned(
                    f,
                    "`#[dds(base)]` cannot be combined with other member attributes",
                ));
            }
            base = Some((ident, f.ty.clone()));
            relative = true;
            continue;
        }
        let opt_inner = option_inner(&f.ty).cloned();
        if attrs.optional && opt_inner.is_none() {
            return Err(syn::Error::new_spanned(
                &f.ty,
                "`#[dds(optional)]` needs a field of type `Option<T>`",
            ));
        }
        let optional = opt_inner.is_some();
        if let Some(span) = attrs.key {
            if optional {
                return Err(syn::Error::new(
                    span,
                    "`#[dds(key)]` cannot be applied to an optional member",
                ));
            }
            if attrs.non_serialized {
                return Err(syn::Error::new(
                    span,
                    "`#[dds(key)]` cannot be applied to a non_serialized member",
                ));
            }
        }
        let inner = opt_inner.unwrap_or_else(|| f.ty.clone());
        if attrs.external && box_inner(&inner).is_none() {
            return Err(syn::Error::new_spanned(
                &f.ty,
                "`#[dds(external)]` needs a field of type `Box<T>` or `Option<Box<T>>`",
            ));
        }
        let wire_name = attrs
            .name
            .clone()
            .unwrap_or_else(|| ident.to_string().trim_start_matches("r#").to_owned());
        let (id, id_order) = if let Some(id) = attrs.id {
            relative = false;
            next_rel = id + 1;
            (quote!(#id), u64::from(id))
        } else if attrs.hashid.is_some() || ta.autoid_hash {
            let h = attrs.hashid.clone().flatten();
            let id = hash_id(h.as_deref().unwrap_or(&wire_name));
            // A later member without an id continues from this one (XTypes 7.3.1.2.1.1), as libddsc does.
            relative = false;
            next_rel = id + 1;
            (quote!(#id), u64::from(id))
        } else {
            let k = next_rel;
            next_rel += 1;
            if relative {
                let (_, bt) = base.as_ref().expect("relative ids need a base");
                (
                    quote!((<#bt as #cdr::CdrType>::NEXT_MEMBER_ID + #k)),
                    u64::from(k),
                )
            } else {
                (quote!(#k), u64::from(k))
            }
        };
        if id_order > 0x0fff_ffff {
            return Err(syn::Error::new_spanned(
                f,
                "member ids are limited to 28 bits",
            ));
        }
        // Ids relative to a base are only known to the compiler; every other id is checked here, since two
        // members with one id would silently decode into the wrong field.
        let is_relative =
            relative && attrs.id.is_none() && attrs.hashid.is_none() && !ta.autoid_hash;
        if !is_relative && !attrs.non_serialized {
            if let Some((_, other)) = absolute_ids.iter().find(|(i, _)| *i == id_order) {
                return Err(syn::Error::new_spanned(
                    f,
                    format!("member id {id_order} is already used by `{other}`"),
                ));
            }
            absolute_ids.push((id_order, ident.to_string()));
        }
        let (bound, bound_opt) = match &attrs.bound {
            Some(b) => (
                quote!((#b) as usize),
                quote!(::core::option::Option::Some((#b) as usize)),
            ),
            None => (quote!(usize::MAX), quote!(::core::option::Option::None)),
        };
        // `recursive` marks a field whose type leads back here through another type (A -> Vec<B> -> A): its
        // constants would depend on this type's own, which rustc rejects as a cycle.
        let self_ref = attrs.recursive || mentions(&f.ty, name);
        fields.push(Field {
            key: attrs.key.is_some(),
            ident,
            ty: f.ty.clone(),
            inner,
            optional,
            wire_name,
            id,
            id_order,
            bound,
            bound_opt,
            self_ref,
            attrs,
        });
    }
    // The id after the last member.
    let next_id = if relative {
        let (_, bt) = base.as_ref().expect("base");
        quote!(<#bt as #cdr::CdrType>::NEXT_MEMBER_ID + #next_rel)
    } else {
        quote!(#next_rel)
    };

    let ser: Vec<&Field> = fields.iter().filter(|f| !f.attrs.non_serialized).collect();
    let keys: Vec<&Field> = ser.iter().copied().filter(|f| f.key).collect();
    let mut keys_by_id = keys.clone();
    keys_by_id.sort_by_key(|f| f.id_order);
    let own_keys = !keys.is_empty();

    // ---- encode ----
    let enc_field = |f: &Field| {
        let Field {
            ident,
            ty,
            inner,
            id,
            bound,
            ..
        } = f;
        let mu = f.attrs.must_understand;
        if f.optional {
            quote!(#cdr::members::encode_optional::<#inner>(w, ext, #id, #mu, &self.#ident, #bound)?;)
        } else if ext != Ext::Mutable {
            // Members of final/appendable structs have no member header (the key-hash stream, which forces
            // Final, is no different): write the value directly, without `encode_member`'s run-time checks.
            quote!(<#ty as #cdr::CdrType>::encode_bounded(&self.#ident, w, #bound)?;)
        } else {
            quote!(#cdr::members::encode_member::<#ty>(w, ext, #id, #mu, &self.#ident, #bound)?;)
        }
    };
    let enc_all: Vec<TokenStream> = ser.iter().map(|f| enc_field(f)).collect();
    let mut ser_by_id = ser.clone();
    ser_by_id.sort_by_key(|f| f.id_order);
    let enc_all_by_id: Vec<TokenStream> = ser_by_id.iter().map(|f| enc_field(f)).collect();
    let enc_keys: Vec<TokenStream> = keys.iter().map(|f| enc_field(f)).collect();
    let enc_keys_by_id: Vec<TokenStream> = keys_by_id.iter().map(|f| enc_field(f)).collect();
    let (enc_base_all, enc_base_keys, base_has_keys, base_partial_field, base_partial_default) =
        match &base {
            Some((bi, bt)) => (
                quote!(<#bt as #cdr::StructMembers>::encode_members(&self.#bi, w, ext)?;),
                quote!(if <#bt as #cdr::StructMembers>::HAS_KEYS {
                    <#bt as #cdr::StructMembers>::encode_members(&self.#bi, w, ext)?;
                }),
                quote!(<#bt as #cdr::StructMembers>::HAS_KEYS),
                quote!(#bi: <#bt as #cdr::StructMembers>::Partial,),
                quote!(#bi: ::core::default::Default::default(),),
            ),
            None => (quote!(), quote!(), quote!(false), quote!(), quote!()),
        };

    // ---- decode ----
    let dec_in_order = |f: &Field| {
        let Field {
            ident,
            ty,
            inner,
            bound,
            ..
        } = f;
        if f.optional {
            quote!(if st.has_more(r) {
                p.#ident = #cdr::members::decode_optional::<#inner>(r, #bound)?;
            })
        } else {
            quote!(if st.has_more(r) {
                #cdr::members::decode_into_slot::<#ty>(&mut p.#ident, r, #bound)?;
            })
        }
    };
    let dec_all: Vec<TokenStream> = ser.iter().map(|f| dec_in_order(f)).collect();
    let dec_keys: Vec<TokenStream> = keys.iter().map(|f| dec_in_order(f)).collect();
    let (dec_base_all, dec_base_keys) = match &base {
        Some((bi, bt)) => (
            quote!(<#bt as #cdr::StructMembers>::decode_members_in_order(r, st, &mut p.#bi)?;),
            quote!(if <#bt as #cdr::StructMembers>::HAS_KEYS {
                <#bt as #cdr::StructMembers>::decode_members_in_order(r, st, &mut p.#bi)?;
            }),
        ),
        None => (quote!(), quote!()),
    };
    let by_id_arms: Vec<TokenStream> = ser
        .iter()
        .map(|f| {
            let Field {
                ident,
                ty,
                inner,
                id,
                bound,
                ..
            } = f;
            let t = if f.optional { inner } else { ty };
            quote!(x if x == #id => {
                #cdr::members::decode_into_slot::<#t>(&mut p.#ident, r, #bound)?;
                ::core::result::Result::Ok(true)
            })
        })
        .collect();
    let by_id_fallback = match &base {
        Some((bi, bt)) => {
            quote!(_ => <#bt as #cdr::StructMembers>::decode_member_by_id(r, id, &mut p.#bi),)
        }
        None => quote!(_ => ::core::result::Result::Ok(false),),
    };

    // ---- partial / finish / default ----
    let partial = format_ident!("__DdsPartial{}", name);
    let partial_fields: Vec<TokenStream> = ser
        .iter()
        .map(|f| {
            let ident = &f.ident;
            let t = if f.optional { &f.inner } else { &f.ty };
            quote!(#ident: ::core::option::Option<#t>,)
        })
        .collect();
    let partial_defaults: Vec<TokenStream> = ser
        .iter()
        .map(|f| {
            let ident = &f.ident;
            quote!(#ident: ::core::option::Option::None,)
        })
        .collect();
    let default_of = |f: &Field| -> TokenStream {
        let ty = &f.ty;
        match &f.attrs.default {
            Some(e) => quote!(#e),
            None if f.optional => quote!(::core::option::Option::None),
            None if f.attrs.non_serialized => quote!(::core::default::Default::default()),
            None => quote!(<#ty as #cdr::CdrType>::default_value()),
        }
    };
    let finish_fields: Vec<TokenStream> = fields
        .iter()
        .map(|f| {
            let ident = &f.ident;
            if f.attrs.non_serialized {
                quote!(#ident: ::core::default::Default::default(),)
            } else if f.optional {
                quote!(#ident: p.#ident,)
            } else {
                let d = default_of(f);
                quote!(#ident: match p.#ident {
                    ::core::option::Option::Some(v) => v,
                    ::core::option::Option::None => #d,
                },)
            }
        })
        .collect();
    let default_fields: Vec<TokenStream> = fields
        .iter()
        .map(|f| {
            let ident = &f.ident;
            let d = default_of(f);
            quote!(#ident: #d,)
        })
        .collect();
    let (finish_base, default_base) = match &base {
        Some((bi, bt)) => (
            quote!(#bi: <#bt as #cdr::StructMembers>::finish(p.#bi),),
            quote!(#bi: <#bt as #cdr::CdrType>::default_value(),),
        ),
        None => (quote!(), quote!()),
    };

    // ---- key size scan ----
    let scan = |f: &Field| {
        let t = if f.optional { &f.inner } else { &f.ty };
        let bo = &f.bound_opt;
        let presence = if f.optional {
            quote!(if version == #cdr::XcdrVersion::Xcdr2 { p += 1; } else { p = ((p + 3) & !3) + 12; })
        } else {
            quote!()
        };
        quote!(
            #presence
            p = <#t as #cdr::CdrType>::key_max_end(p, version, #bo)?;
        )
    };
    let scan_keys: Vec<TokenStream> = keys_by_id.iter().map(|f| scan(f)).collect();
    let scan_all: Vec<TokenStream> = ser_by_id.iter().map(|f| scan(f)).collect();
    let (scan_base_all, scan_base_keys) = match &base {
        Some((_, bt)) => (
            quote!(p = <#bt as #cdr::StructMembers>::key_members_max_end(p, version, ext)?;),
            quote!(if <#bt as #cdr::StructMembers>::HAS_KEYS {
                p = <#bt as #cdr::StructMembers>::key_members_max_end(p, version, ext)?;
            }),
        ),
        None => (quote!(), quote!()),
    };

    // ---- constants ----
    let const_fields: Vec<&Field> = ser.iter().copied().filter(|f| !f.self_ref).collect();
    let min_terms: Vec<TokenStream> = const_fields
        .iter()
        .map(|f| {
            let ty = &f.ty;
            if f.optional {
                quote!(1usize)
            } else {
                quote!(<#ty as #cdr::CdrType>::MIN_SIZE)
            }
        })
        .collect();
    let plain_terms: Vec<TokenStream> = const_fields
        .iter()
        .map(|f| {
            let t = &f.inner;
            if f.optional {
                quote!(false)
            } else {
                quote!(<#t as #cdr::CdrType>::XCDR1_PLAIN)
            }
        })
        .collect();
    let key_final_fields: Vec<&Field> = if own_keys {
        const_fields.iter().copied().filter(|f| f.key).collect()
    } else {
        const_fields.clone()
    };
    let key_final_terms: Vec<TokenStream> = key_final_fields
        .iter()
        .map(|f| {
            let t = &f.inner;
            quote!(<#t as #cdr::CdrType>::KEY_HAS_MUTABLE)
        })
        .collect();
    let (base_min, base_plain, base_key_final) = match &base {
        Some((_, bt)) if !mentions(bt, name) => (
            quote!(+ <#bt as #cdr::CdrType>::MIN_SIZE),
            quote!(&& <#bt as #cdr::CdrType>::XCDR1_PLAIN),
            quote!(|| <#bt as #cdr::CdrType>::KEY_HAS_MUTABLE),
        ),
        _ => (quote!(), quote!(), quote!()),
    };
    let is_final = ext == Ext::Final;
    let is_mutable = ext == Ext::Mutable;
    let min_size = if is_final {
        quote!({
            let m = 0usize #(+ #min_terms)* #base_min;
            if m == 0 { 1 } else { m }
        })
    } else {
        quote!(1usize)
    };

    // ---- metadata ----
    let type_name = ta.name.clone().unwrap_or_else(|| name.to_string());
    let generic = !input.generics.params.is_empty();
    // Generic types cannot name their members in a `const`; they get none until TypeObjects arrive.
    let member_descs: Vec<TokenStream> = if generic {
        Vec::new()
    } else {
        ser.iter()
            .map(|f| {
                let n = &f.wire_name;
                let id = &f.id;
                let key = f.key;
                let opt = f.optional;
                let mu = f.attrs.must_understand;
                quote!(#cdr::MemberDescriptor { name: #n, id: #id, key: #key, optional: #opt, must_understand: #mu })
            })
            .collect()
    };

    // ---- generics ----
    let mut generics = input.generics.clone();
    {
        let params: Vec<Ident> = generics.type_params().map(|t| t.ident.clone()).collect();
        let wc = generics.make_where_clause();
        for p in params {
            wc.predicates.push(syn::parse_quote!(#p: #cdr::CdrType + ::core::marker::Send + ::core::marker::Sync + 'static));
        }
    }
    let (impl_g, ty_g, where_c) = generics.split_for_impl();
    let vis = &input.vis;
    let attrs = impl_attrs();
    let partial_generics = &input.generics;
    let span = Span::call_site();
    let _ = span;

    Ok(quote! {
        #[doc(hidden)]
        #attrs
        #vis struct #partial #partial_generics #where_c {
            #base_partial_field
            #(#partial_fields)*
        }

        #attrs
        impl #impl_g ::core::default::Default for #partial #ty_g #where_c {
            fn default() -> Self {
                Self { #base_partial_default #(#partial_defaults)* }
            }
        }

        #attrs
        impl #impl_g #cdr::StructMembers for #name #ty_g #where_c {
            type Partial = #partial #ty_g;
            const HAS_KEYS: bool = #own_keys || #base_has_keys;

            fn encode_members(
                &self,
                w: &mut #cdr::CdrWriter<'_>,
                ext: #cdr::Extensibility,
            ) -> ::core::result::Result<(), #cdr::EncodeError> {
                if w.key_only() && <Self as #cdr::StructMembers>::HAS_KEYS {
                    #enc_base_keys
                    if w.mode() == #cdr::EncodeMode::KeyHash {
                        #(#enc_keys_by_id)*
                    } else {
                        #(#enc_keys)*
                    }
                } else if w.mode() == #cdr::EncodeMode::KeyHash {
                    #enc_base_all
                    #(#enc_all_by_id)*
                } else {
                    #enc_base_all
                    #(#enc_all)*
                }
                let _ = (w, ext);
                ::core::result::Result::Ok(())
            }

            fn decode_members_in_order(
                r: &mut #cdr::CdrReader<'_>,
                st: &#cdr::members::StructDecoder,
                p: &mut Self::Partial,
            ) -> ::core::result::Result<(), #cdr::DecodeError> {
                if r.key_only() && <Self as #cdr::StructMembers>::HAS_KEYS {
                    #dec_base_keys
                    #(#dec_keys)*
                } else {
                    #dec_base_all
                    #(#dec_all)*
                }
                let _ = (r, st, p);
                ::core::result::Result::Ok(())
            }

            fn decode_member_by_id(
                r: &mut #cdr::CdrReader<'_>,
                id: u32,
                p: &mut Self::Partial,
            ) -> ::core::result::Result<bool, #cdr::DecodeError> {
                let _ = (&r, &p);
                match id {
                    #(#by_id_arms)*
                    #by_id_fallback
                }
            }

            fn finish(p: Self::Partial) -> Self {
                let _ = &p;
                Self { #finish_base #(#finish_fields)* }
            }

            fn key_members_max_end(
                start: usize,
                version: #cdr::XcdrVersion,
                ext: #cdr::Extensibility,
            ) -> ::core::option::Option<usize> {
                let mut p = start;
                if <Self as #cdr::StructMembers>::HAS_KEYS {
                    #scan_base_keys
                    #(#scan_keys)*
                } else {
                    #scan_base_all
                    #(#scan_all)*
                }
                let _ = (version, ext);
                ::core::option::Option::Some(p)
            }
        }

        #attrs
        impl #impl_g #cdr::CdrType for #name #ty_g #where_c {
            const LAYOUT: #cdr::Layout = #cdr::Layout::Other;
            const MIN_SIZE: usize = #min_size;
            const XCDR1_PLAIN: bool = #is_final #(&& #plain_terms)* #base_plain;
            const KEY_HAS_MUTABLE: bool = #is_mutable #(|| #key_final_terms)* #base_key_final;
            const NEXT_MEMBER_ID: u32 = #next_id;

            fn encode(&self, w: &mut #cdr::CdrWriter<'_>) -> ::core::result::Result<(), #cdr::EncodeError> {
                // The hashed key stream is plain whatever the extensibility.
                let ext = if w.mode() == #cdr::EncodeMode::KeyHash {
                    #cdr::Extensibility::Final
                } else {
                    #ext_t
                };
                let st = #cdr::members::begin_encode(w, ext)?;
                <Self as #cdr::StructMembers>::encode_members(self, w, ext)?;
                #cdr::members::end_encode(w, st)
            }

            fn decode(r: &mut #cdr::CdrReader<'_>) -> ::core::result::Result<Self, #cdr::DecodeError> {
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
            }

            // Only reached for members a sample lacks; kept out of line because inlining it copies the whole
            // default value of every nested struct into each caller (minutes of LLVM time for large types).
            #[cold]
            #[inline(never)]
            fn default_value() -> Self {
                Self { #default_base #(#default_fields)* }
            }

            fn key_max_end(
                start: usize,
                version: #cdr::XcdrVersion,
                _bound: ::core::option::Option<usize>,
            ) -> ::core::option::Option<usize> {
                if start > 64 {
                    return ::core::option::Option::None;
                }
                // The hashed key stream is plain: no DHEADER, EMHEADER or parameter list.
                <Self as #cdr::StructMembers>::key_members_max_end(start, version, #ext_t)
            }
        }

        #attrs
        impl #impl_g #cdr::DdsType for #name #ty_g #where_c {
            const TYPE_NAME: &'static str = #type_name;
            const EXTENSIBILITY: #cdr::Extensibility = #ext_t;
            const IS_KEYED: bool = <Self as #cdr::StructMembers>::HAS_KEYS;

            fn type_descriptor() -> #cdr::TypeDescriptor {
                #cdr::TypeDescriptor {
                    type_name: #type_name,
                    extensibility: #ext_t,
                    members: {
                        const MEMBERS: &[#cdr::MemberDescriptor] = &[#(#member_descs),*];
                        MEMBERS
                    },
                }
            }
        }
    })
}
