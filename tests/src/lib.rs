//! Cross-crate tests live in `tests/tests/`; this library holds what several of them share.

/// Includes the Rust file that `build.rs` generated with our idlc (`$OUT_DIR/$stem.rs`) as module `$m`,
/// with the lints generated code is not held to. Attributes before the name (a `cfg`, a doc comment) go on
/// the module.
#[macro_export]
macro_rules! generated {
    ($(#[$a:meta])* $m:ident, $stem:expr) => {
        $(#[$a])*
        #[allow(
            clippy::all,
            clippy::pedantic,
            non_camel_case_types,
            non_snake_case,
            dead_code,
            unused_imports
        )]
        mod $m {
            include!(concat!(env!("OUT_DIR"), "/", $stem, ".rs"));
        }
    };
}
