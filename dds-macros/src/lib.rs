//! `#[derive(DdsType)]`. See `docs/derive.md` for the attribute reference.
use proc_macro::TokenStream;

#[proc_macro_derive(DdsType, attributes(dds))]
pub fn derive_dds_type(input: TokenStream) -> TokenStream {
    let _ = input;
    TokenStream::new()
}
