//! Misuse of `#[derive(DdsType)]` is a compile error pointing at the offending field or attribute.

#[test]
fn compile_errors() {
    let t = trybuild::TestCases::new();
    t.compile_fail("tests/ui/*.rs");
}
