//! `#[derive(DdsType)]`: makes a Rust struct or enum a DDS topic or member type, with direct XCDR1/XCDR2
//! encoding and decoding through `dds_runtime::cdr` (no dynamic value detour), key-only streams, the key hash
//! and type metadata. `dds_runtime` re-exports the derive as `dds_runtime::DdsType`; the attribute reference is
//! `docs/derive.md`.
//!
//! ```
//! use dds_runtime::cdr::{self, ByteOrder, XcdrVersion};
//! use dds_runtime::DdsType;
//!
//! #[derive(DdsType, Debug, PartialEq)]
//! #[dds(name = "Demo::Reading", mutable)]
//! struct Reading {
//!     #[dds(key)]
//!     sensor: u32,
//!     #[dds(bound = 16)]
//!     label: String,
//!     celsius: Option<f64>,
//! }
//!
//! let r = Reading { sensor: 7, label: "hall".into(), celsius: Some(21.5) };
//! let mut wire = Vec::new();
//! cdr::serialize(&r, XcdrVersion::Xcdr2, ByteOrder::LittleEndian, &mut wire)?;
//! assert_eq!(cdr::deserialize::<Reading>(&wire)?, r);
//! assert_eq!(<Reading as cdr::DdsType>::TYPE_NAME, "Demo::Reading");
//! assert!(<Reading as cdr::DdsType>::IS_KEYED);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! The generated code names the runtime as `::dds_runtime` unless `#[dds(crate = "...")]` says otherwise.
//!
//! # How it works
//!
//! As in serde_derive, the input is first read into a model and checked, and only then is code generated:
//!
//! - `attrs.rs` parses the `#[dds(...)]` attributes, `model.rs` builds the model of the type (member ids,
//!   wire names, the kind of IDL type), `check.rs` validates it. All of them report into one error collector
//!   (`ctxt.rs`), so every error of a derive shows at once.
//! - `emit/` generates the impls from the model alone: `encode`, `decode`, `key`, `layout` and `describe`.

mod attrs;
mod check;
mod ctxt;
mod emit;
mod model;
mod types;

use proc_macro::TokenStream;
use syn::{parse_macro_input, DeriveInput};

/// Implements `cdr::CdrType` and `cdr::DdsType` (and, for structs, `cdr::StructMembers`; for enums,
/// `cdr::Discriminator`) for a struct with named fields (IDL `struct`), a unit-only enum (IDL `enum`), an enum
/// with `#[dds(discriminator = T)]` (IDL `union`), or a one-field tuple struct marked `transparent` or
/// `bitmask`. See `docs/derive.md` for the `#[dds(...)]` attributes.
#[proc_macro_derive(DdsType, attributes(dds))]
pub fn derive_dds_type(input: TokenStream) -> TokenStream {
    let input = parse_macro_input!(input as DeriveInput);
    match expand(&input) {
        Ok(ts) => ts.into(),
        Err(e) => e.to_compile_error().into(),
    }
}

/// Model, check, emit; all errors at once.
fn expand(input: &DeriveInput) -> syn::Result<proc_macro2::TokenStream> {
    let mut cx = ctxt::Ctxt::default();
    let model = model::Container::from_ast(&mut cx, input);
    if let Some(c) = &model {
        check::check(&mut cx, c);
    }
    cx.finish()?;
    Ok(model.map(|c| emit::container(&c)).unwrap_or_default())
}
