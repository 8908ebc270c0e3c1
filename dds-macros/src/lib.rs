//! `#[derive(DdsType)]`. See `docs/derive.md` for the attribute reference.
//!
//! The generated code encodes and decodes directly through `dds_runtime::cdr` (no dynamic value detour) and
//! names the runtime as `::dds_runtime` unless `#[dds(crate = "...")]` says otherwise.

mod attrs;
mod enums;
mod newtype;
mod strukt;
mod util;

use proc_macro::TokenStream;
use quote::quote;
use syn::{parse_macro_input, Data, DeriveInput};

#[proc_macro_derive(DdsType, attributes(dds))]
pub fn derive_dds_type(input: TokenStream) -> TokenStream {
    let input = parse_macro_input!(input as DeriveInput);
    match expand(&input) {
        Ok(ts) => ts.into(),
        Err(e) => e.to_compile_error().into(),
    }
}

fn expand(input: &DeriveInput) -> syn::Result<proc_macro2::TokenStream> {
    let ta = attrs::parse_type_attrs(&input.attrs)?;
    let rt = match &ta.krate {
        Some(p) => quote!(#p),
        None => quote!(::dds_runtime),
    };
    match &input.data {
        Data::Struct(s) if ta.bitmask => newtype::derive_bitmask(input, s, &ta, &rt),
        Data::Struct(s) if ta.transparent => newtype::derive_transparent(input, s, &ta, &rt),
        Data::Struct(s) => strukt::derive(input, s, &ta, &rt),
        Data::Enum(e) => {
            if ta.bitmask || ta.transparent {
                return Err(syn::Error::new_spanned(
                    &input.ident,
                    "`bitmask` and `transparent` apply to tuple structs",
                ));
            }
            let unit_only = e.variants.iter().all(|v| matches!(v.fields, syn::Fields::Unit));
            if unit_only && ta.discriminator.is_none() {
                enums::derive_enum(input, e, &ta, &rt)
            } else {
                enums::derive_union(input, e, &ta, &rt)
            }
        }
        Data::Union(_) => Err(syn::Error::new_spanned(
            &input.ident,
            "Rust unions are not supported; an IDL union is an enum with `#[dds(discriminator = ...)]`",
        )),
    }
}
