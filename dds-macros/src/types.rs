//! What the derive needs to know about a field's Rust type: `Option<T>`, `Box<T>`, whether it names the type itself.

use proc_macro2::{Ident, TokenStream, TokenTree};
use quote::quote;
use syn::{GenericArgument, PathArguments, Type};

/// `Some(T)` if `ty` is `Option<T>`.
pub(crate) fn option_inner(ty: &Type) -> Option<&Type> {
    generic_inner(ty, "Option")
}

/// `Some(T)` if `ty` is `Box<T>`.
pub(crate) fn box_inner(ty: &Type) -> Option<&Type> {
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
pub(crate) fn mentions(ty: &Type, me: &Ident) -> bool {
    fn walk(ts: TokenStream, me: &Ident) -> bool {
        ts.into_iter().any(|t| match t {
            TokenTree::Ident(i) => i == *me || i == "Self",
            TokenTree::Group(g) => walk(g.stream(), me),
            _ => false,
        })
    }
    walk(quote!(#ty), me)
}
