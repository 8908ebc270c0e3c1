//! Snapshot tests of rendered diagnostics: the exact text users see (colorless, 100 columns).
use idlc::diag::RenderOptions;
use idlc::driver::{compile_str, Options};
use idlc::preprocess::MemVfs;

fn render_with(files: MemVfs, text: &str) -> String {
    let mut c = compile_str("main.idl", text, &Options::default(), &files);
    let _ = c.rust();
    let out = c.render_diagnostics(RenderOptions {
        color: false,
        width: 100,
    });
    assert!(!out.is_empty(), "expected at least one diagnostic");
    out
}

fn render(text: &str) -> String {
    render_with(MemVfs::new(), text)
}

macro_rules! diag_test {
    ($name:ident, $code:literal, $src:expr) => {
        #[test]
        fn $name() {
            let out = render($src);
            assert!(out.contains($code), "expected {} in:\n{out}", $code);
            insta::assert_snapshot!(stringify!($name), out);
        }
    };
}

// ---- syntax ----
diag_test!(
    syntax_missing_semicolon,
    "E0101",
    "struct A {\n  long x\n};\n"
);
diag_test!(
    syntax_missing_closing_semicolon,
    "E0101",
    "module M {\n  struct A { long x; }\n};\n"
);
diag_test!(
    syntax_keyword_as_member_name,
    "E0101",
    "struct A {\n  long map;\n};\n"
);
diag_test!(
    keyword_case_collision,
    "E0103",
    "struct String {\n  long x;\n};\n"
);
diag_test!(bad_octal_literal, "E0102", "const long X = 08;\n");
diag_test!(
    huge_integer_literal,
    "E0102",
    "const unsigned long long X = 123456789012345678901234567890;\n"
);
// ---- names ----
diag_test!(
    unresolved_type_suggestion,
    "E0201",
    "struct Point { long x; };\nstruct B {\n  Piont p;\n};\n"
);
diag_test!(
    unresolved_scoped_name,
    "E0201",
    "module M { struct Alpha { long x; }; };\nstruct B { M::Alpah a; };\n"
);
diag_test!(
    unresolved_constant,
    "E0201",
    "const long SIZE = 4;\nstruct B { long a[SIZ]; };\n"
);
diag_test!(ambiguous_shadowed_module, "E0202", "module A { struct X { long a; }; };\nmodule B {\n  module A { struct Other { long b; }; };\n  struct Y { A::X x; };\n};\n");
diag_test!(
    duplicate_declaration,
    "E0203",
    "struct A { long x; };\nstruct A { long y; };\n"
);
diag_test!(
    case_collision_declaration,
    "E0204",
    "struct Foo { long x; };\nstruct foo { long y; };\n"
);
diag_test!(
    case_mismatch_reference,
    "E0204",
    "struct Foo { long x; };\nstruct B { foo f; };\n"
);
diag_test!(
    constant_used_as_type,
    "E0205",
    "const long N = 3;\nstruct B { N x; };\n"
);
diag_test!(
    incomplete_forward,
    "E0206",
    "struct Fwd;\nstruct B { sequence<Fwd> s; };\n"
);
diag_test!(
    infinite_struct,
    "E0207",
    "struct Node {\n  long value;\n  Node next;\n};\n"
);
// ---- constants ----
diag_test!(octet_overflow, "E0301", "const octet O = 256;\n");
diag_test!(
    expression_overflow,
    "E0301",
    "const unsigned long long X = 18446744073709551615 * 2;\n"
);
diag_test!(
    short_overflow_via_shift,
    "E0301",
    "const short S = 1 << 15;\n"
);
diag_test!(const_type_mismatch, "E0302", "const long L = \"text\";\n");
diag_test!(bitwise_on_float, "E0302", "const double D = 1.5 | 2;\n");
diag_test!(division_by_zero, "E0303", "const long D = 10 / (5 - 5);\n");
diag_test!(zero_string_bound, "E0304", "struct A { string<0> s; };\n");
// ---- types ----
diag_test!(
    duplicate_union_label,
    "E0401",
    "union U switch (long) {\n  case 1: long a;\n  case 2: case 1: short b;\n};\n"
);
diag_test!(
    several_default_labels,
    "E0402",
    "union U switch (long) {\n  default: long a;\n  case 1: default: short b;\n};\n"
);
diag_test!(unreachable_default, "E0415", "enum Bit { ZERO, ONE };\nunion U switch (Bit) {\n  case ZERO: long a;\n  case ONE: short b;\n  default: octet c;\n};\n");
diag_test!(label_of_wrong_enum, "E0403", "enum Color { RED, GREEN };\nenum Shape { SQUARE, CIRCLE };\nunion U switch (Color) {\n  case SQUARE: long a;\n};\n");
diag_test!(
    label_out_of_range,
    "E0403",
    "union U switch (octet) {\n  case 300: long a;\n};\n"
);
diag_test!(
    float_discriminator,
    "E0404",
    "union U switch (float) {\n  case 1: long a;\n};\n"
);
diag_test!(
    key_on_optional,
    "E0405",
    "struct A {\n  @key @optional long id;\n};\n"
);
diag_test!(
    derived_struct_adds_key,
    "E0406",
    "struct Base { @key long id; };\nstruct Derived : Base {\n  @key long id2;\n};\n"
);
diag_test!(
    derived_extensibility_mismatch,
    "E0416",
    "@mutable struct Base { short s; };\n@final\nstruct Derived : Base {\n  long l;\n};\n"
);
diag_test!(
    derived_extensibility_mismatch_via_extensibility,
    "E0416",
    "@final struct Base { short s; };\n@extensibility(APPENDABLE) struct Derived : Base { long l; };\n"
);
diag_test!(
    capitalised_builtin_annotation,
    "W0106",
    "struct S {\n  @Key long id;\n  long x;\n};\n"
);
diag_test!(
    default_on_discriminator,
    "W0104",
    "union U switch (@default(1) long) {\n  case 0: octet a;\n  case 1: short b;\n};\n"
);
diag_test!(
    duplicate_member_id,
    "E0407",
    "@mutable struct A {\n  @id(1) long a;\n  @id(1) long b;\n};\n"
);
diag_test!(
    bad_extensibility_param,
    "E0408",
    "@extensibility(SOMETIMES) struct A { long x; };\n"
);
diag_test!(
    base_not_a_struct,
    "E0409",
    "enum E { ONE };\nstruct D : E { long x; };\n"
);
diag_test!(
    bitmask_position_out_of_bound,
    "E0410",
    "@bit_bound(8) bitmask M {\n  A,\n  @position(9) B\n};\n"
);
diag_test!(
    bitset_too_wide,
    "E0410",
    "bitset B {\n  bitfield<40> a;\n  bitfield<30> b;\n};\n"
);
diag_test!(
    duplicate_enum_value,
    "E0411",
    "enum E {\n  @value(1) A,\n  @value(1) B\n};\n"
);
diag_test!(
    duplicate_member,
    "E0413",
    "struct A {\n  long x;\n  short x;\n};\n"
);
diag_test!(
    float_map_key,
    "E0414",
    "struct A { map<double, long> m; };\n"
);
diag_test!(
    fixed_digits_out_of_range,
    "E0304",
    "struct A { fixed<32,2> price; };\n"
);
diag_test!(
    vendor_enumerator_value,
    "W0107",
    "enum E {\n  A = 1,\n  B\n};\n"
);
diag_test!(any_is_not_data, "E0414", "struct A { any value; };\n");
// ---- preprocessor ----
diag_test!(
    include_not_found,
    "E0002",
    "#include \"missing.idl\"\nstruct A { long x; };\n"
);
diag_test!(
    error_directive,
    "E0004",
    "#ifndef FEATURE\n#error \"FEATURE must be defined\"\n#endif\n"
);
diag_test!(
    unknown_directive,
    "E0005",
    "#frobnicate\nstruct A { long x; };\n"
);
diag_test!(
    unterminated_if,
    "E0006",
    "#ifdef X\nstruct A { long x; };\n"
);
diag_test!(else_without_if, "E0006", "struct A { long x; };\n#else\n");
diag_test!(bad_if_expression, "E0007", "#if 1 +\n#endif\n");
diag_test!(
    macro_argument_count,
    "E0008",
    "#define PAIR(a, b) a b\nconst long X = PAIR(1);\n"
);
diag_test!(
    unterminated_comment,
    "E0009",
    "struct A { long x; };\n/* never closed\n"
);
// ---- warnings ----
diag_test!(
    unknown_annotation_suggestion,
    "W0103",
    "struct A {\n  @optinal long x;\n};\n"
);
diag_test!(
    interface_not_emitted,
    "W0101",
    "interface Calculator {\n  long add(in long a, in long b);\n};\n"
);
diag_test!(
    legacy_key_comment,
    "W0102",
    "struct A {\n  long id; //@key\n  long value;\n};\n"
);
diag_test!(
    unknown_pragma,
    "W0001",
    "#pragma frobnicate on\nstruct A { long x; };\n"
);
diag_test!(
    warning_directive,
    "W0002",
    "#warning \"deprecated file\"\nstruct A { long x; };\n"
);
diag_test!(
    misplaced_annotation,
    "W0104",
    "@key struct A { long x; };\n"
);

#[test]
fn error_in_included_file_points_into_that_file() {
    let files = MemVfs::new().with("inc.idl", "// helper\nstruct Inner {\n  lnog x;\n};\n");
    let out = render_with(files, "#include \"inc.idl\"\nstruct Outer { Inner i; };\n");
    assert!(out.contains("inc.idl:3:3"), "{out}");
    insta::assert_snapshot!("error_in_included_file", out);
}

#[test]
fn include_cycle_is_reported() {
    let files = MemVfs::new()
        .with("a.idl", "#include \"b.idl\"\n")
        .with("b.idl", "#include \"a.idl\"\n");
    let out = render_with(files, "#include \"a.idl\"\n");
    assert!(out.contains("E0003"), "{out}");
    insta::assert_snapshot!("include_cycle", out);
}

#[test]
fn every_error_of_a_run_is_reported() {
    let out =
        render("struct A { Missing1 a; };\nstruct B { Missing2 b; };\nconst octet C = 999;\n");
    assert_eq!(out.matches("idlc::E0201").count(), 2, "{out}");
    assert_eq!(out.matches("idlc::E0301").count(), 1, "{out}");
    insta::assert_snapshot!("several_errors", out);
}

#[test]
fn macro_expansion_errors_point_at_the_invocation() {
    let out = render("#define BAD_TYPE lnog\nstruct A {\n  BAD_TYPE x;\n};\n");
    assert!(out.contains("main.idl:3:3"), "{out}");
    insta::assert_snapshot!("macro_expansion_location", out);
}

#[test]
fn codes_are_unique() {
    let mut seen = std::collections::HashSet::new();
    for c in idlc::diag::Code::ALL {
        assert!(seen.insert(c.as_str()), "duplicate code {}", c.as_str());
    }
}

#[test]
fn line_directive_renames_and_renumbers_the_snippet() {
    // The error is at `}` on physical line 4, which `#line` presents as line 42 of `gen.idl`.
    let out = render("#line 40 \"gen.idl\"\nstruct A {\n  long x\n};\n");
    assert!(
        out.contains("gen.idl:42:1"),
        "expected the presumed position in:\n{out}"
    );
    assert!(
        out.contains(" 42 │ };"),
        "expected the presumed line number in the gutter:\n{out}"
    );
    assert!(
        out.contains(" 41 │   long x"),
        "expected the context line renumbered too:\n{out}"
    );
    assert!(
        !out.contains("main.idl"),
        "the physical file name leaked:\n{out}"
    );
}
