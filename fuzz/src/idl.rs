//! The `idl_parse` check: the idlc front end and back ends on arbitrary text must not panic.

use idlc::diag::RenderOptions;
use idlc::driver::{compile_str, Options};
use idlc::preprocess::MemVfs;

/// Runs one input (ignored unless it is UTF-8).
pub fn idl_one(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let mut c = compile_str("fuzz.idl", text, &Options::default(), &MemVfs::new());
    if c.has_errors() {
        let _ = c.render_diagnostics(RenderOptions::default());
    } else {
        let _ = c.json();
        let _ = c.rust();
        let _ = c.render_diagnostics(RenderOptions::default());
    }
}
