//! Small helpers shared by the derive back ends.

use proc_macro2::{Ident, TokenStream, TokenTree};
use quote::quote;
use syn::{GenericArgument, PathArguments, Type};

use crate::attrs::Ext;

/// `Some(T)` if `ty` is `Option<T>`.
pub fn option_inner(ty: &Type) -> Option<&Type> {
    generic_inner(ty, "Option")
}

/// `Some(T)` if `ty` is `Box<T>`.
pub fn box_inner(ty: &Type) -> Option<&Type> {
    generic_inner(ty, "Box")
}

fn generic_inner<'a>(ty: &'a Type, name: &str) -> Option<&'a Type> {
    let Type::Path(tp) = ty else { return None };
    if tp.qself.is_some() {
        return None;
    }
    let seg = tp.path.segments.last()?;
    if seg.ident != name {
        return None;
    }
    let PathArguments::AngleBracketed(args) = &seg.arguments else {
        return None;
    };
    if args.args.len() != 1 {
        return None;
    }
    match args.args.first()? {
        GenericArgument::Type(t) => Some(t),
        _ => None,
    }
}

/// Whether the type mentions `Self` or the type being derived (recursion through `Box`/`Vec`), whose constants
/// must not be used in the type's own constants.
pub fn mentions(ty: &Type, me: &Ident) -> bool {
    fn walk(ts: TokenStream, me: &Ident) -> bool {
        ts.into_iter().any(|t| match t {
            TokenTree::Ident(i) => i == *me || i == "Self",
            TokenTree::Group(g) => walk(g.stream(), me),
            _ => false,
        })
    }
    walk(quote!(#ty), me)
}

/// The runtime's `Extensibility` value.
pub fn ext_tokens(cdr: &TokenStream, ext: Ext) -> TokenStream {
    match ext {
        Ext::Final => quote!(#cdr::Extensibility::Final),
        Ext::Appendable => quote!(#cdr::Extensibility::Appendable),
        Ext::Mutable => quote!(#cdr::Extensibility::Mutable),
    }
}

/// Attributes put on every generated impl: generated code must be warning- and clippy-free in user crates.
pub fn impl_attrs() -> TokenStream {
    quote! {
        #[automatically_derived]
        #[allow(clippy::all, clippy::pedantic, clippy::nursery, unused_qualifications, non_camel_case_types)]
    }
}
