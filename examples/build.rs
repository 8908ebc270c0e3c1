//! Generates the topic types from the IDL in `../idl` with idlc (see `src/lib.rs`).
fn main() {
    idlc::Builder::new()
        .include_dir("../idl")
        .compile(&[
            "../idl/shapes.idl",
            "../idl/ddsperf_types.idl",
            "../idl/hello.idl",
        ])
        .unwrap();
}
