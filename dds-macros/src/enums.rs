//! `#[derive(DdsType)]` for enums: unit-only enums are IDL enums, enums with data are IDL unions.

use proc_macro2::TokenStream;
use quote::quote;
use syn::{DataEnum, DeriveInput, Fields, Result};

use crate::attrs::{parse_field_attrs, parse_int_expr, parse_variant_attrs, Ext, TypeAttrs};
use crate::util::{ext_tokens, impl_attrs, mentions};

/// IDL enum.
pub fn derive_enum(
    input: &DeriveInput,
    data: &DataEnum,
    ta: &TypeAttrs,
    rt: &TokenStream,
) -> Result<TokenStream> {
    let cdr = quote!(#rt::cdr);
    let name = &input.ident;
    if !input.generics.params.is_empty() {
        return Err(syn::Error::new_spanned(
            &input.generics,
            "DdsType enums cannot be generic",
        ));
    }
    if ta.ext == Some(Ext::Mutable) {
        return Err(syn::Error::new_spanned(name, "an enum cannot be mutable"));
    }
    if data.variants.is_empty() {
        return Err(syn::Error::new_spanned(
            name,
            "an IDL enum needs at least one enumerator",
        ));
    }
    let bit_bound = match ta.bit_bound {
        Some((b, span)) if !(1..=32).contains(&b) => {
            return Err(syn::Error::new(
                span,
                "an enum's bit_bound must be in 1..=32",
            ));
        }
        Some((b, _)) => b,
        None => 32,
    };
    let size: u8 = if bit_bound <= 8 {
        1
    } else if bit_bound <= 16 {
        2
    } else {
        4
    };
    let mut next: i64 = 0;
    let mut idents = Vec::new();
    let mut values = Vec::new();
    let mut names = Vec::new();
    for v in &data.variants {
        let va = parse_variant_attrs(&v.attrs)?;
        if !va.cases.is_empty() || va.default || va.id.is_some() {
            return Err(syn::Error::new_spanned(
                v,
                "`case`, `default` and `id` belong to union variants",
            ));
        }
        let value = match (va.value, &v.discriminant) {
            (Some(x), _) => x,
            (None, Some((_, e))) => parse_int_expr(e)?,
            (None, None) => next,
        };
        // IDL enumerators are signed (int8/int16/int32 holders); accept the unsigned range of the bit bound too.
        let lo = -(1i64 << (bit_bound - 1));
        let hi = (1i64 << bit_bound) - 1;
        if value < lo || value > hi {
            return Err(syn::Error::new_spanned(
                v,
                "enumerator value out of range for the bit_bound",
            ));
        }
        next = value + 1;
        // The value on the wire, in the enum's size (two's complement for negative values).
        let mask = if size == 4 {
            u64::from(u32::MAX)
        } else {
            (1u64 << (8 * size)) - 1
        };
        let wire = (value as u64 & mask) as u32;
        if values.contains(&wire) {
            return Err(syn::Error::new_spanned(v, "duplicate enumerator value"));
        }
        idents.push(v.ident.clone());
        values.push(wire);
        names.push(va.name.unwrap_or_else(|| v.ident.to_string()));
    }
    let values_i64: Vec<i64> = values.iter().map(|&v| i64::from(v)).collect();
    // `#[default]` (IDL @default_literal) picks the default enumerator, else the first one.
    let first = data
        .variants
        .iter()
        .find(|v| v.attrs.iter().any(|a| a.path().is_ident("default")))
        .map_or(&idents[0], |v| &v.ident);
    let type_name = ta.name.clone().unwrap_or_else(|| name.to_string());
    let attrs = impl_attrs();
    let ext_t = ext_tokens(&cdr, ta.ext.unwrap_or(Ext::Final));
    let write_v2 = match size {
        1 => quote!(w.write_u8(v as u8)),
        2 => quote!(w.write_u16(v as u16)),
        _ => quote!(w.write_u32(v)),
    };
    let read_v2 = match size {
        1 => quote!(u32::from(r.read_u8("enum")?)),
        2 => quote!(u32::from(r.read_u16("enum")?)),
        _ => quote!(r.read_u32("enum")?),
    };
    let size_usize = size as usize;
    Ok(quote! {
        #attrs
        impl #cdr::CdrType for #name {
            const LAYOUT: #cdr::Layout = #cdr::Layout::Enumerated(#size);

            #[inline]
            fn encode(&self, w: &mut #cdr::CdrWriter<'_>) -> ::core::result::Result<(), #cdr::EncodeError> {
                let v: u32 = match self { #(Self::#idents => #values,)* };
                #write_v2;
                ::core::result::Result::Ok(())
            }

            #[inline]
            fn decode(r: &mut #cdr::CdrReader<'_>) -> ::core::result::Result<Self, #cdr::DecodeError> {
                let at = r.offset();
                let v: u32 = #read_v2;
                match v {
                    #(#values => ::core::result::Result::Ok(Self::#idents),)*
                    other => ::core::result::Result::Err(#cdr::DecodeError::new(
                        at,
                        concat!("an enumerator of ", #type_name),
                        #cdr::DecodeErrorKind::InvalidValue { found: u64::from(other) },
                    )),
                }
            }

            fn default_value() -> Self {
                Self::#first
            }

            fn key_max_end(
                start: usize,
                version: #cdr::XcdrVersion,
                _bound: ::core::option::Option<usize>,
            ) -> ::core::option::Option<usize> {
                let size = #size_usize;
                ::core::option::Option::Some(#cdr::members::prim_end(start, size, version))
            }
        }

        #attrs
        impl #cdr::Discriminator for #name {
            const SEARCH: #cdr::DefaultSearch = #cdr::DefaultSearch::Enum;

            fn to_raw(&self) -> i64 {
                match self { #(Self::#idents => #values_i64,)* }
            }

            fn write_raw(w: &mut #cdr::CdrWriter<'_>, raw: i64) -> ::core::result::Result<(), #cdr::EncodeError> {
                let v = raw as u32;
                #write_v2;
                ::core::result::Result::Ok(())
            }

            fn read_raw(r: &mut #cdr::CdrReader<'_>) -> ::core::result::Result<i64, #cdr::DecodeError> {
                let v: u32 = #read_v2;
                ::core::result::Result::Ok(i64::from(v))
            }

            fn enumerators() -> &'static [i64] {
                &[#(#values_i64),*]
            }
        }

        #attrs
        impl #cdr::DdsType for #name {
            const TYPE_NAME: &'static str = #type_name;
            const EXTENSIBILITY: #cdr::Extensibility = #ext_t;
            const IS_KEYED: bool = false;

            fn type_descriptor() -> #cdr::TypeDescriptor {
                #cdr::TypeDescriptor {
                    type_name: #type_name,
                    extensibility: #ext_t,
                    members: &[#(#cdr::MemberDescriptor {
                        name: #names, id: #values, key: false, optional: false, must_understand: false
                    }),*],
                }
            }
        }
    })
}

/// IDL union.
pub fn derive_union(
    input: &DeriveInput,
    data: &DataEnum,
    ta: &TypeAttrs,
    rt: &TokenStream,
) -> Result<TokenStream> {
    let cdr = quote!(#rt::cdr);
    let name = &input.ident;
    if !input.generics.params.is_empty() {
        return Err(syn::Error::new_spanned(
            &input.generics,
            "DdsType unions cannot be generic",
        ));
    }
    let Some(disc) = &ta.discriminator else {
        return Err(syn::Error::new_spanned(
            name,
            "a union (enum with data) needs `#[dds(discriminator = Type)]`",
        ));
    };
    let ext = ta.ext.unwrap_or(Ext::Appendable);
    let ext_t = ext_tokens(&cdr, ext);
    let disc_is_wchar = matches!(disc, syn::Type::Path(p) if p.path.segments.last().is_some_and(|s| s.ident == "WChar"));
    let mut enc_arms = Vec::new();
    let mut dec_arms = Vec::new();
    let mut all_labels = Vec::new();
    let mut default_arm = None;
    let mut default_value = None;
    let mut plain_terms = Vec::new();
    let mut mut_terms = Vec::new();
    let mut descs = Vec::new();
    let mut next_id: u32 = 1;
    let mut scan_terms = Vec::new();
    for v in &data.variants {
        let va = parse_variant_attrs(&v.attrs)?;
        if va.value.is_some() {
            return Err(syn::Error::new_spanned(
                v,
                "`value` belongs to enumerators, not union cases",
            ));
        }
        if va.cases.is_empty() && !va.default {
            return Err(syn::Error::new_spanned(
                v,
                "a union variant needs `#[dds(case = ...)]` or `#[dds(default)]`",
            ));
        }
        let id = va.id.unwrap_or(next_id);
        next_id = id + 1;
        let vi = &v.ident;
        let labels: Vec<TokenStream> = va
            .cases
            .iter()
            .map(|c| {
                // idlc writes wchar labels as char literals.
                let is_char_lit = matches!(
                    c,
                    syn::Expr::Lit(syn::ExprLit {
                        lit: syn::Lit::Char(_),
                        ..
                    })
                );
                if is_char_lit && disc_is_wchar {
                    quote!(<#disc as #cdr::Discriminator>::to_raw(&#cdr::WChar((#c) as u16)))
                } else {
                    quote!(<#disc as #cdr::Discriminator>::to_raw(&(#c)))
                }
            })
            .collect();
        all_labels.extend(labels.iter().cloned());
        let vname = va.name.clone().unwrap_or_else(|| vi.to_string());
        descs.push(quote!(#cdr::MemberDescriptor { name: #vname, id: #id, key: false, optional: false, must_understand: false }));
        let disc_expr = if let Some(first) = labels.first() {
            quote!(#first)
        } else {
            quote!(#cdr::members::default_discriminator::<#disc>(LABELS)?)
        };
        match &v.fields {
            Fields::Unit => {
                enc_arms.push(quote!(Self::#vi => {
                    #cdr::members::encode_discriminator::<#disc>(w, ext, #disc_expr)?;
                }));
                let build = quote!(Self::#vi);
                if va.default {
                    default_arm = Some(build.clone());
                }
                if !labels.is_empty() {
                    dec_arms.push(quote!(x if #(x == #labels)||* => #build,));
                }
                if default_value.is_none() {
                    default_value = Some(build);
                }
            }
            Fields::Unnamed(u) if u.unnamed.len() == 1 => {
                let f = &u.unnamed[0];
                let fa = parse_field_attrs(&f.attrs)?;
                if fa.key.is_some()
                    || fa.optional
                    || fa.base
                    || fa.non_serialized
                    || fa.id.is_some()
                {
                    return Err(syn::Error::new_spanned(
                        f,
                        "a union case accepts only `bound`, `external`, `name`, `must_understand` and `recursive`",
                    ));
                }
                let ty = &f.ty;
                let bound = match &fa.bound {
                    Some(b) => quote!((#b) as usize),
                    None => quote!(usize::MAX),
                };
                let mu = fa.must_understand;
                enc_arms.push(quote!(Self::#vi(v) => {
                    #cdr::members::encode_discriminator::<#disc>(w, ext, #disc_expr)?;
                    #cdr::members::encode_member::<#ty>(w, ext, #id, #mu, v, #bound)?;
                }));
                let build = quote!(Self::#vi(#cdr::members::decode_union_member::<#ty>(r, &mut st, #bound)?));
                if va.default {
                    default_arm = Some(build.clone());
                }
                if !labels.is_empty() {
                    dec_arms.push(quote!(x if #(x == #labels)||* => #build,));
                }
                let bo = match &fa.bound {
                    Some(b) => quote!(::core::option::Option::Some((#b) as usize)),
                    None => quote!(::core::option::Option::None),
                };
                scan_terms.push(quote!({
                    end = end.max(<#ty as #cdr::CdrType>::key_max_end(p, version, #bo)?);
                }));
                if !fa.recursive && !mentions(ty, name) {
                    plain_terms.push(quote!(<#ty as #cdr::CdrType>::XCDR1_PLAIN));
                    mut_terms.push(quote!(<#ty as #cdr::CdrType>::KEY_HAS_MUTABLE));
                    if default_value.is_none() {
                        default_value =
                            Some(quote!(Self::#vi(<#ty as #cdr::CdrType>::default_value())));
                    }
                }
            }
            _ => {
                return Err(syn::Error::new_spanned(
                    v,
                    "a union variant carries exactly one unnamed field (or none)",
                ))
            }
        }
    }
    let default_value = match default_value {
        Some(d) => d,
        None => {
            return Err(syn::Error::new_spanned(
                name,
                "a union needs a variant that is not recursive",
            ))
        }
    };
    let type_name = ta.name.clone().unwrap_or_else(|| name.to_string());
    let type_name_lit = &type_name;
    let fallback = match default_arm {
        Some(b) => quote!(_ => #b,),
        None => quote!(other => {
            return ::core::result::Result::Err(#cdr::DecodeError::new(
                at,
                concat!("a case label of ", #type_name_lit),
                #cdr::DecodeErrorKind::InvalidValue { found: other as u64 },
            ));
        }),
    };
    let is_final = ext == Ext::Final;
    let is_mutable = ext == Ext::Mutable;
    let attrs = impl_attrs();
    let n_labels = all_labels.len();
    Ok(quote! {
        #attrs
        impl #cdr::CdrType for #name {
            const LAYOUT: #cdr::Layout = #cdr::Layout::Other;
            const XCDR1_PLAIN: bool = #is_final && <#disc as #cdr::CdrType>::XCDR1_PLAIN #(&& #plain_terms)*;
            const KEY_HAS_MUTABLE: bool = #is_mutable #(|| #mut_terms)*;

            fn encode(&self, w: &mut #cdr::CdrWriter<'_>) -> ::core::result::Result<(), #cdr::EncodeError> {
                let labels: [i64; #n_labels] = [#(#all_labels),*];
                #[allow(non_snake_case)]
                let LABELS: &[i64] = &labels;
                let _ = LABELS;
                // The hashed key stream is plain whatever the extensibility.
                let ext = if w.mode() == #cdr::EncodeMode::KeyHash {
                    #cdr::Extensibility::Final
                } else {
                    #ext_t
                };
                let st = #cdr::members::begin_encode(w, ext)?;
                match self { #(#enc_arms)* }
                #cdr::members::end_encode(w, st)
            }

            fn decode(r: &mut #cdr::CdrReader<'_>) -> ::core::result::Result<Self, #cdr::DecodeError> {
                let mut st = #cdr::members::begin_decode(r, #ext_t)?;
                let at = r.offset();
                let d = #cdr::members::decode_discriminator::<#disc>(r, &mut st)?;
                let _ = at;
                let v = match d {
                    #(#dec_arms)*
                    #fallback
                };
                st.end(r);
                ::core::result::Result::Ok(v)
            }

            fn default_value() -> Self {
                #default_value
            }

            fn key_max_end(
                start: usize,
                version: #cdr::XcdrVersion,
                _bound: ::core::option::Option<usize>,
            ) -> ::core::option::Option<usize> {
                if start > 64 {
                    return ::core::option::Option::None;
                }
                // The hashed key stream is plain: no DHEADER or member headers.
                let p = <#disc as #cdr::CdrType>::key_max_end(start, version, ::core::option::Option::None)?;
                let mut end = p;
                #(#scan_terms)*
                ::core::option::Option::Some(end)
            }
        }

        #attrs
        impl #cdr::DdsType for #name {
            const TYPE_NAME: &'static str = #type_name;
            const EXTENSIBILITY: #cdr::Extensibility = #ext_t;
            const IS_KEYED: bool = false;

            fn type_descriptor() -> #cdr::TypeDescriptor {
                #cdr::TypeDescriptor {
                    type_name: #type_name,
                    extensibility: #ext_t,
                    members: &[#(#descs),*],
                }
            }
        }
    })
}
