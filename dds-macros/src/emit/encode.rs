//! Encoding: a struct's `encode_members` and `encode`, an enum's and a union's `encode`.

use proc_macro2::TokenStream;
use quote::quote;

use super::{bound_limit, ext_tokens, member_id, Members};
use crate::attrs::Ext;
use crate::model::{Case, Container, Enum, Field, Struct, Union};

/// `StructMembers::encode_members`: all members, or the key members of a key-only stream, in declaration order
/// (member-id order for the key hash). The base's members come first.
pub(super) fn encode_members(c: &Container, s: &Struct, m: &Members) -> TokenStream {
    let cdr = c.cdr();
    let one = |fields: &[&Field]| -> Vec<TokenStream> {
        fields.iter().map(|f| encode_field(c, s, f)).collect()
    };
    let (all, all_by_id) = (one(&m.all), one(&m.all_by_id));
    let (keys, keys_by_id) = (one(&m.keys), one(&m.keys_by_id));
    let (base_all, base_keys) = match &s.base {
        Some(b) => {
            let (bi, bt) = (b.ident, b.ty);
            (
                quote!(<#bt as #cdr::StructMembers>::encode_members(&self.#bi, w, ext)?;),
                quote!(if <#bt as #cdr::StructMembers>::HAS_KEYS {
                    <#bt as #cdr::StructMembers>::encode_members(&self.#bi, w, ext)?;
                }),
            )
        }
        None => (quote!(), quote!()),
    };
    quote! {
        fn encode_members(
            &self,
            w: &mut #cdr::CdrWriter<'_>,
            ext: #cdr::Extensibility,
        ) -> ::core::result::Result<(), #cdr::EncodeError> {
            if w.key_only() && <Self as #cdr::StructMembers>::HAS_KEYS {
                #base_keys
                if w.mode() == #cdr::EncodeMode::KeyHash {
                    #(#keys_by_id)*
                } else {
                    #(#keys)*
                }
            } else if w.mode() == #cdr::EncodeMode::KeyHash {
                #base_all
                #(#all_by_id)*
            } else {
                #base_all
                #(#all)*
            }
            let _ = (w, ext);
            ::core::result::Result::Ok(())
        }
    }
}

fn encode_field(c: &Container, s: &Struct, f: &Field) -> TokenStream {
    let cdr = c.cdr();
    let (ident, ty, inner) = (f.ident, f.ty, f.inner);
    let id = member_id(c, s, f.id);
    let bound = bound_limit(f.attrs.bound.as_ref());
    let mu = f.attrs.must_understand;
    if f.optional {
        quote!(#cdr::members::encode_optional::<#inner>(w, ext, #id, #mu, &self.#ident, #bound)?;)
    } else if s.ext != Ext::Mutable {
        // Members of final/appendable structs have no member header (the key-hash stream, which forces Final,
        // is no different): write the value directly, without `encode_member`'s run-time checks.
        quote!(<#ty as #cdr::CdrType>::encode_bounded(&self.#ident, w, #bound)?;)
    } else {
        quote!(#cdr::members::encode_member::<#ty>(w, ext, #id, #mu, &self.#ident, #bound)?;)
    }
}

/// `CdrType::encode` of a struct or union: the framing, then `body`.
fn framed_encode(c: &Container, ext: Ext, prologue: TokenStream, body: TokenStream) -> TokenStream {
    let cdr = c.cdr();
    let ext_t = ext_tokens(c, ext);
    quote! {
        fn encode(&self, w: &mut #cdr::CdrWriter<'_>) -> ::core::result::Result<(), #cdr::EncodeError> {
            #prologue
            // The hashed key stream is plain whatever the extensibility.
            let ext = if w.mode() == #cdr::EncodeMode::KeyHash {
                #cdr::Extensibility::Final
            } else {
                #ext_t
            };
            let st = #cdr::members::begin_encode(w, ext)?;
            #body
            #cdr::members::end_encode(w, st)
        }
    }
}

/// A struct's `CdrType::encode`.
pub(super) fn struct_encode(c: &Container, ext: Ext) -> TokenStream {
    let cdr = c.cdr();
    let body = quote!(<Self as #cdr::StructMembers>::encode_members(self, w, ext)?;);
    framed_encode(c, ext, quote!(), body)
}

/// A union's `CdrType::encode`: the discriminator, then the case's member.
pub(super) fn union_encode(c: &Container, u: &Union) -> TokenStream {
    let all_labels: Vec<TokenStream> = u.cases.iter().flat_map(|k| labels(c, u, k)).collect();
    let n_labels = all_labels.len();
    let arms = u.cases.iter().map(|k| union_arm(c, u, k));
    let prologue = quote! {
        let labels: [i64; #n_labels] = [#(#all_labels),*];
        #[allow(non_snake_case)]
        let LABELS: &[i64] = &labels;
        let _ = LABELS;
    };
    framed_encode(c, u.ext, prologue, quote!(match self { #(#arms)* }))
}

fn union_arm(c: &Container, u: &Union, k: &Case) -> TokenStream {
    let cdr = c.cdr();
    let disc = &u.disc;
    let vi = &k.variant.ident;
    let id = k.id;
    let disc_expr = match labels(c, u, k).first() {
        Some(first) => quote!(#first),
        None => quote!(#cdr::members::default_discriminator::<#disc>(LABELS)?),
    };
    match &k.payload {
        None => quote!(Self::#vi => {
            #cdr::members::encode_discriminator::<#disc>(w, ext, #disc_expr)?;
        }),
        Some(p) => {
            let ty = p.ty;
            let bound = bound_limit(p.attrs.bound.as_ref());
            let mu = p.attrs.must_understand;
            quote!(Self::#vi(v) => {
                #cdr::members::encode_discriminator::<#disc>(w, ext, #disc_expr)?;
                #cdr::members::encode_member::<#ty>(w, ext, #id, #mu, v, #bound)?;
            })
        }
    }
}

/// A case's labels as raw discriminator values.
pub(super) fn labels(c: &Container, u: &Union, k: &Case) -> Vec<TokenStream> {
    let cdr = c.cdr();
    let disc = &u.disc;
    k.attrs
        .cases
        .iter()
        .map(|l| {
            // idlc writes wchar labels as char literals.
            let is_char_lit = matches!(
                l,
                syn::Expr::Lit(syn::ExprLit {
                    lit: syn::Lit::Char(_),
                    ..
                })
            );
            if is_char_lit && u.disc_is_wchar {
                quote!(<#disc as #cdr::Discriminator>::to_raw(&#cdr::WChar((#l) as u16)))
            } else {
                quote!(<#disc as #cdr::Discriminator>::to_raw(&(#l)))
            }
        })
        .collect()
}

/// An enum's `CdrType::encode`.
pub(super) fn enum_encode(c: &Container, e: &Enum) -> TokenStream {
    let cdr = c.cdr();
    let idents = e.enumerators.iter().map(|v| &v.variant.ident);
    let values = e.enumerators.iter().map(|v| v.wire(e.size()));
    let write = enum_write(e.size());
    quote! {
        #[inline]
        fn encode(&self, w: &mut #cdr::CdrWriter<'_>) -> ::core::result::Result<(), #cdr::EncodeError> {
            let v: u32 = match self { #(Self::#idents => #values,)* };
            #write;
            ::core::result::Result::Ok(())
        }
    }
}

/// Writes the enum value `v: u32` in the enum's size.
pub(super) fn enum_write(size: u8) -> TokenStream {
    match size {
        1 => quote!(w.write_u8(v as u8)),
        2 => quote!(w.write_u16(v as u16)),
        _ => quote!(w.write_u32(v)),
    }
}
