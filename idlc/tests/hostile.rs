//! Hostile input gives an error value: no hang, no stack overflow, no crash, no unbounded allocation.
use idlc::driver::{compile_str, Options};
use idlc::preprocess::MemVfs;
use std::time::{Duration, Instant};

fn compile(text: &str) -> (bool, Vec<&'static str>, Duration) {
    compile_with(MemVfs::new(), text)
}

fn compile_with(files: MemVfs, text: &str) -> (bool, Vec<&'static str>, Duration) {
    let t = Instant::now();
    let mut c = compile_str("main.idl", text, &Options::default(), &files);
    let ok = c.rust().is_some();
    let codes = c.diags.iter().map(|d| d.code.as_str()).collect();
    (ok, codes, t.elapsed())
}

#[test]
fn deeply_nested_modules() {
    let n = 100_000;
    let text = format!(
        "{}struct A {{ long x; }};{}",
        "module m { ".repeat(n),
        "};".repeat(n)
    );
    let (ok, codes, _) = compile(&text);
    assert!(!ok);
    assert!(codes.contains(&"idlc::E0010"), "{codes:?}");
}

#[test]
fn deeply_nested_parentheses() {
    let n = 100_000;
    let text = format!("const long X = {}1{};", "(".repeat(n), ")".repeat(n));
    let (ok, codes, _) = compile(&text);
    assert!(!ok);
    assert!(codes.contains(&"idlc::E0010"), "{codes:?}");
}

#[test]
fn nesting_just_under_the_limit_is_accepted() {
    let n = 40;
    let text = format!("const long X = {}1{};", "(".repeat(n), ")".repeat(n));
    let (ok, codes, _) = compile(&text);
    assert!(ok, "{codes:?}");
}

#[test]
fn deeply_nested_templates() {
    let n = 50_000;
    let text = format!(
        "struct A {{ {}long{} x; }};",
        "sequence<".repeat(n),
        ">".repeat(n)
    );
    let (ok, codes, _) = compile(&text);
    assert!(!ok);
    assert!(codes.contains(&"idlc::E0010"), "{codes:?}");
}

#[test]
fn hundred_megabyte_token() {
    let digits = "9".repeat(100 << 20);
    let text = format!("const unsigned long long X = {digits};\n");
    let (ok, codes, took) = compile(&text);
    assert!(!ok);
    assert_eq!(codes, vec!["idlc::E0010"]);
    assert!(took < Duration::from_secs(60), "took {took:?}");
}

#[test]
fn hundred_megabyte_identifier() {
    let name = "a".repeat(100 << 20);
    let text = format!("struct A {{ {name} x; }};\n");
    let (ok, codes, took) = compile(&text);
    assert!(!ok);
    assert_eq!(codes, vec!["idlc::E0010"]);
    assert!(took < Duration::from_secs(60), "took {took:?}");
}

#[test]
fn long_but_allowed_literal() {
    let text = format!("const string S = \"{}\";\n", "x".repeat(500_000));
    let (ok, codes, _) = compile(&text);
    assert!(ok, "{codes:?}");
}

#[test]
fn include_cycle_without_guards() {
    let files = MemVfs::new().with("a.idl", "#include \"a.idl\"\nstruct A { long x; };\n");
    let (ok, codes, _) = compile_with(files, "#include \"a.idl\"\n");
    assert!(!ok);
    assert!(codes.contains(&"idlc::E0003"), "{codes:?}");
}

#[test]
fn include_cycle_with_pragma_once_is_fine() {
    let files = MemVfs::new()
        .with(
            "a.idl",
            "#pragma once\n#include \"b.idl\"\nstruct A { long x; };\n",
        )
        .with(
            "b.idl",
            "#pragma once\n#include \"a.idl\"\nstruct B { long y; };\n",
        );
    let (ok, codes, _) = compile_with(files, "#include \"a.idl\"\n#include \"b.idl\"\n");
    assert!(ok, "{codes:?}");
}

#[test]
fn exponential_macro_expansion_is_cut_off() {
    let mut text = String::new();
    for i in 0..40 {
        text.push_str(&format!("#define M{i} M{} M{}\n", i + 1, i + 1));
    }
    text.push_str("const long X = M0;\n");
    let (ok, codes, took) = compile(&text);
    assert!(!ok);
    assert!(codes.contains(&"idlc::E0008"), "{codes:?}");
    assert!(took < Duration::from_secs(30), "took {took:?}");
}

#[test]
fn self_referential_macro_terminates() {
    let (ok, codes, _) = compile("#define X X + 1\nconst long A = X;\n");
    assert!(!ok, "X stays an unknown name");
    assert!(codes.contains(&"idlc::E0201"), "{codes:?}");
}

#[test]
fn garbage_bytes() {
    let text: String = (0..20_000u32)
        .map(|i| char::from_u32((i * 7919) % 0x2FF + 1).unwrap_or('?'))
        .collect();
    let (ok, _, _) = compile(&text);
    assert!(!ok);
}

#[test]
fn unterminated_string_and_char() {
    let (ok, codes, _) = compile("const string S = \"abc\nconst char C = 'x\n");
    assert!(!ok);
    assert!(codes.iter().all(|c| *c == "idlc::E0009"), "{codes:?}");
}

#[test]
fn huge_array_and_bound() {
    let (ok, codes, _) = compile("struct A { octet big[4294967296][4294967296]; };\n");
    assert!(!ok, "{codes:?}");
    let (ok2, codes2, _) = compile("struct A { sequence<long, 99999999999999999999999> s; };\n");
    assert!(!ok2, "{codes2:?}");
}
