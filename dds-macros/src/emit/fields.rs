//! Member access for content filters and queries: `impl filter::FilterFields`. A struct answers its members
//! by IDL name (and its base's, through the base), a union its active branch by name, an enum the
//! enumerator's name and value, a typedef its field, a bitmask its bits. Only serialized members are reachable.

use proc_macro2::TokenStream;
use quote::quote;
use syn::Generics;

use super::impl_attrs;
use crate::model::{Container, Enum, Struct, Union};

/// The `filter` module path, the impl header and the method signature shared by every kind.
fn wrap(c: &Container, generics: &Generics, body: TokenStream) -> TokenStream {
    let rt = c.runtime();
    let name = c.ident();
    let mut generics = generics.clone();
    let params: Vec<syn::Ident> = generics.type_params().map(|t| t.ident.clone()).collect();
    let wc = generics.make_where_clause();
    for p in params {
        wc.predicates
            .push(syn::parse_quote!(#p: #rt::filter::FilterFields));
    }
    let (impl_g, ty_g, where_c) = generics.split_for_impl();
    let attrs = impl_attrs();
    quote! {
        #attrs
        impl #impl_g #rt::filter::FilterFields for #name #ty_g #where_c {
            fn field_value(
                &self,
                path: &[#rt::filter::PathSegment],
            ) -> ::core::option::Option<#rt::filter::FieldValue<'_>> {
                #body
            }
        }
    }
}

/// A struct: the first path segment names a member; the rest goes to the member's own impl.
pub(super) fn struct_fields(c: &Container, s: &Struct, generics: &Generics) -> TokenStream {
    let rt = c.runtime();
    let ff = quote!(#rt::filter::FilterFields);
    let arms = s.fields.iter().filter(|f| f.serialized()).map(|f| {
        let name = &f.wire_name;
        let ident = f.ident;
        quote!(::core::option::Option::Some(#name) => #ff::field_value(&self.#ident, rest),)
    });
    let fallback = match &s.base {
        Some(b) => {
            let ident = b.ident;
            quote!(_ => #ff::field_value(&self.#ident, path),)
        }
        None => quote!(_ => ::core::option::Option::None,),
    };
    wrap(
        c,
        generics,
        quote! {
            let (first, rest) = path.split_first()?;
            match first.member() {
                #(#arms)*
                #fallback
            }
        },
    )
}

/// An enum: the empty path is the enumerator, comparable by name and by value.
pub(super) fn enum_fields(c: &Container, e: &Enum) -> TokenStream {
    let rt = c.runtime();
    let idents: Vec<_> = e.enumerators.iter().map(|v| &v.variant.ident).collect();
    let names = e.enumerators.iter().map(|v| &v.name);
    let values = e.enumerators.iter().map(|v| v.value);
    wrap(
        c,
        &c.input.generics,
        quote! {
            if !path.is_empty() {
                return ::core::option::Option::None;
            }
            let (name, value): (&'static str, i64) = match self {
                #(Self::#idents => (#names, #values),)*
            };
            ::core::option::Option::Some(#rt::filter::FieldValue::Enum { name, value })
        },
    )
}

/// A union: the first path segment names a branch, which answers only while it is the active one.
pub(super) fn union_fields(c: &Container, u: &Union) -> TokenStream {
    let rt = c.runtime();
    let ff = quote!(#rt::filter::FilterFields);
    let arms = u.cases.iter().filter(|k| k.payload.is_some()).map(|k| {
        let ident = &k.variant.ident;
        let name = &k.name;
        quote!(Self::#ident(v) if branch == #name => #ff::field_value(v, rest),)
    });
    wrap(
        c,
        &c.input.generics,
        quote! {
            let (first, rest) = path.split_first()?;
            let branch = first.member()?;
            #[allow(unreachable_patterns)]
            match self {
                #(#arms)*
                _ => ::core::option::Option::None,
            }
        },
    )
}

/// A typedef: its field.
pub(super) fn transparent_fields(c: &Container) -> TokenStream {
    let rt = c.runtime();
    wrap(
        c,
        &c.input.generics,
        quote!(#rt::filter::FilterFields::field_value(&self.0, path)),
    )
}

/// A bitmask: its bits as an unsigned integer.
pub(super) fn bitmask_fields(c: &Container) -> TokenStream {
    let rt = c.runtime();
    let bf = quote!(#rt::__private::bitflags::Flags);
    wrap(
        c,
        &c.input.generics,
        quote! {
            let bits: u64 = ::core::convert::Into::<u64>::into(<Self as #bf>::bits(self));
            path.is_empty().then_some(#rt::filter::FieldValue::UInt(bits))
        },
    )
}
