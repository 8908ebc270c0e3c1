//! Front-end behaviour: preprocessor, grammar coverage, constant evaluation, annotations, name resolution.
use idlc::driver::{compile_str, Compilation, Options};
use idlc::model::{DeclKind, Extensibility, Type, Value};
use idlc::preprocess::MemVfs;

fn ok_with(files: MemVfs, opts: &Options, text: &str) -> Compilation {
    let mut c = compile_str("main.idl", text, opts, &files);
    let rendered = c.render_diagnostics(Default::default());
    assert!(!c.has_errors(), "unexpected errors:\n{rendered}");
    c
}

fn ok(text: &str) -> Compilation {
    ok_with(MemVfs::new(), &Options::default(), text)
}

fn decl<'a>(c: &'a Compilation, scoped: &str) -> &'a DeclKind {
    &c.model
        .decls
        .iter()
        .find(|d| d.scoped_name() == scoped)
        .unwrap_or_else(|| panic!("no {scoped}"))
        .kind
}

fn const_value(c: &Compilation, scoped: &str) -> Value {
    match decl(c, scoped) {
        DeclKind::Const(k) => k.value.clone(),
        other => panic!("{scoped} is {other:?}"),
    }
}

fn codes(text: &str) -> Vec<&'static str> {
    let c = compile_str("main.idl", text, &Options::default(), &MemVfs::new());
    c.diags.iter().map(|d| d.code.as_str()).collect()
}

#[test]
fn object_and_function_macros() {
    let c = ok(
        "#define N 4\n#define TWICE(x) ((x) * 2)\n#define CAT(a, b) a##b\n#define STR(s) #s\n\
                const long A = TWICE(N) + 1;\nconst long CAT(B, 2) = 3;\nconst string S = STR(hello);\n",
    );
    assert_eq!(const_value(&c, "A"), Value::Int(9));
    assert_eq!(const_value(&c, "B2"), Value::Int(3));
    assert_eq!(const_value(&c, "S"), Value::Str("hello".into()));
}

#[test]
fn conditionals_with_expressions() {
    let text = "#define V 3\n#if defined(V) && V >= 3 && !defined(NOPE)\nconst long A = 1;\n#elif V == 2\nconst long A = 2;\n#else\nconst long A = 3;\n#endif\n\
                #ifdef NOPE\nconst long B = 1;\n#elif (V << 2) == 12 || 0\nconst long B = 2;\n#endif\n#ifndef V\nstruct Never { long x; };\n#endif\n";
    let c = ok(text);
    assert_eq!(const_value(&c, "A"), Value::Int(1));
    assert_eq!(const_value(&c, "B"), Value::Int(2));
    assert!(c.model.decls.iter().all(|d| d.name != "Never"));
}

#[test]
fn command_line_defines_and_undefines() {
    let opts = Options {
        defines: vec!["SIZE=8".into(), "FLAG".into(), "GONE".into()],
        undefines: vec!["GONE".into()],
        ..Default::default()
    };
    let c = ok_with(
        MemVfs::new(),
        &opts,
        "const long S = SIZE;\n#ifdef FLAG\nconst long F = FLAG;\n#endif\n#ifdef GONE\n#error gone\n#endif\n",
    );
    assert_eq!(const_value(&c, "S"), Value::Int(8));
    assert_eq!(const_value(&c, "F"), Value::Int(1));
}

#[test]
fn undef_line_and_null_directives() {
    let c = ok("#define X 1\n#undef X\n#line 100 \"other.idl\"\n#\n#ifdef X\n#error still defined\n#endif\nconst long Y = 2;\n");
    assert_eq!(const_value(&c, "Y"), Value::Int(2));
}

#[test]
fn includes_quoted_and_angled_with_search_path() {
    let files = MemVfs::new()
        .with(
            "inc/common.idl",
            "#ifndef COMMON\n#define COMMON\nmodule m { struct Common { long x; }; };\n#endif\n",
        )
        .with(
            "inc/other.idl",
            "#pragma once\n#include <common.idl>\nmodule m { struct Other { Common c; }; };\n",
        );
    let mut opts = Options::default();
    opts.include_dirs.push("inc".into());
    let c = ok_with(files, &opts, "#include <other.idl>\n#include \"inc/common.idl\"\n#include <other.idl>\nmodule m { struct Top { Other o; }; };\n");
    assert_eq!(c.files.len(), 3, "{:?}", c.files);
    assert!(matches!(decl(&c, "m::Top"), DeclKind::Struct(_)));
}

#[test]
fn pragma_keylist_sets_keys() {
    let c = ok("module M { struct S { long a; long b; string c; };\n#pragma keylist S a c\n};\n");
    let DeclKind::Struct(s) = decl(&c, "M::S") else {
        panic!()
    };
    assert_eq!(
        s.fields
            .iter()
            .filter(|f| f.key)
            .map(|f| f.name.as_str())
            .collect::<Vec<_>>(),
        ["a", "c"]
    );
}

#[test]
fn legacy_key_comment_sets_key() {
    let c = ok("struct S {\n  long id; //@Key\n  long v; // not a key\n};\n");
    let DeclKind::Struct(s) = decl(&c, "S") else {
        panic!()
    };
    assert!(s.fields[0].key && !s.fields[1].key);
}

#[test]
fn literals_of_every_form() {
    let c = ok("const long H = 0x1F;\nconst long O = 017;\nconst long D = 42;\nconst double F1 = 1.5e-3;\nconst double F2 = .5;\nconst double F3 = 2.;\n\
                const char C1 = '\\n';\nconst char C2 = '\\x41';\nconst char C3 = '\\101';\nconst wchar W = L'\\u00e9';\n\
                const string S = \"a\\tb\" \"c\";\nconst wstring WS = L\"wide\";\nconst boolean T = TRUE;\nconst fixed FX = 12.50d;\n");
    assert_eq!(const_value(&c, "H"), Value::Int(31));
    assert_eq!(const_value(&c, "O"), Value::Int(15));
    assert_eq!(const_value(&c, "F1"), Value::Float(1.5e-3));
    assert_eq!(const_value(&c, "F2"), Value::Float(0.5));
    assert_eq!(const_value(&c, "F3"), Value::Float(2.0));
    assert_eq!(const_value(&c, "C1"), Value::Char('\n'));
    assert_eq!(const_value(&c, "C2"), Value::Char('A'));
    assert_eq!(const_value(&c, "C3"), Value::Char('A'));
    assert_eq!(const_value(&c, "W"), Value::WChar('é'));
    assert_eq!(const_value(&c, "S"), Value::Str("a\tbc".into()));
    assert_eq!(const_value(&c, "WS"), Value::WStr("wide".into()));
    assert_eq!(const_value(&c, "T"), Value::Bool(true));
    assert_eq!(const_value(&c, "FX"), Value::Fixed("12.50".into()));
}

#[test]
fn constant_expressions_full_operator_set() {
    let c = ok("const long A = (1 + 2) * 3 - 4 / 2 % 3;\nconst long B = 0xF0 | 0x0F & 0x3C ^ 1;\nconst long C = 1 << 4 >> 2;\n\
                const long D = -A;\nconst unsigned short E = ~0;\nconst short F = ~0;\nconst double G = 1.0 / 4 + 2;\nconst long H = +A;\n");
    assert_eq!(const_value(&c, "A"), Value::Int(7));
    assert_eq!(const_value(&c, "B"), Value::Int(0xF0 | (0x0F & 0x3C) ^ 1));
    assert_eq!(const_value(&c, "C"), Value::Int(4));
    assert_eq!(const_value(&c, "D"), Value::Int(-7));
    assert_eq!(const_value(&c, "E"), Value::Int(0xFFFF));
    assert_eq!(const_value(&c, "F"), Value::Int(-1));
    assert_eq!(const_value(&c, "G"), Value::Float(2.25));
    assert_eq!(const_value(&c, "H"), Value::Int(7));
}

#[test]
fn nested_templates_close_with_shift_token() {
    let c =
        ok("struct S { sequence<sequence<long, 3>> a; map<string, sequence<octet>> m; sequence<sequence<long>>b; };\n");
    let DeclKind::Struct(s) = decl(&c, "S") else {
        panic!()
    };
    assert!(
        matches!(&s.fields[0].ty, Type::Sequence { bound: None, elem } if matches!(**elem, Type::Sequence { bound: Some(3), .. }))
    );
}

#[test]
fn escaped_identifiers_and_modules_reopened() {
    let c = ok("module m { struct _struct { long _module; }; };\nmodule m { struct User { _struct s; m::_struct t; ::m::_struct u; }; };\n");
    assert!(matches!(decl(&c, "m::struct"), DeclKind::Struct(_)));
    assert!(matches!(decl(&c, "m::User"), DeclKind::Struct(_)));
}

#[test]
fn forward_declarations_and_recursion_through_sequences() {
    ok("struct Node;\ntypedef sequence<Node> Nodes;\nstruct Node { long v; Nodes children; };\nunion U;\nstruct H { sequence<U> us; };\nunion U switch (long) { case 1: long a; };\n");
}

#[test]
fn every_discriminator_kind() {
    ok("enum E { A, B };\ntypedef E EAlias;\ntypedef long LAlias;\n\
        union U1 switch (short) { case -1: long a; };\nunion U2 switch (unsigned long long) { case 1: long a; };\n\
        union U3 switch (char) { case 'x': long a; };\nunion U4 switch (wchar) { case L'y': long a; };\n\
        union U5 switch (boolean) { case TRUE: long a; case FALSE: short b; };\nunion U6 switch (octet) { case 255: long a; };\n\
        union U7 switch (EAlias) { case A: long a; default: short b; };\nunion U8 switch (LAlias) { case 1: case 2: long a; default: octet c; };\n\
        union U9 switch (int8) { case -128: long a; };\nunion U10 switch (uint8) { case 200: long a; };\n");
}

#[test]
fn bitmask_bitset_enum_annotations() {
    let c = ok("@bit_bound(8) enum E { @value(3) A, B, @default_literal C };\n@bit_bound(16) bitmask M { X, @position(9) Y, Z };\n\
                bitset Base { bitfield<3> a; };\nbitset S : Base { bitfield<2> b; bitfield<5>; bitfield<4, short> c; };\n");
    let DeclKind::Enum(e) = decl(&c, "E") else {
        panic!()
    };
    assert_eq!(
        e.enumerators.iter().map(|x| x.value).collect::<Vec<_>>(),
        [3, 4, 5]
    );
    assert_eq!(e.default_index, 2);
    let DeclKind::Bitmask(m) = decl(&c, "M") else {
        panic!()
    };
    assert_eq!(
        m.flags.iter().map(|f| f.position).collect::<Vec<_>>(),
        [0, 9, 10]
    );
    let DeclKind::Bitset(s) = decl(&c, "S") else {
        panic!()
    };
    assert_eq!(s.bits, 14);
    assert_eq!(
        s.fields
            .iter()
            .map(|f| (f.offset, f.width))
            .collect::<Vec<_>>(),
        [(0, 3), (3, 2), (5, 5), (10, 4)]
    );
}

#[test]
fn struct_annotations() {
    let c = ok("@mutable @autoid(HASH) struct S {\n  @key @must_understand long k;\n  @optional @external string o;\n  @id(7) @default(3) @range(min=0, max=9) @unit(\"m\") long r;\n  @hashid(\"other\") long h;\n  @non_serialized long n;\n};\n@final @nested struct F { long x; };\n@topic struct T { long x; };\n@default_nested(TRUE) module N { struct Q { long x; }; };\n");
    let DeclKind::Struct(s) = decl(&c, "S") else {
        panic!()
    };
    assert_eq!(s.extensibility, Extensibility::Mutable);
    assert!(s.fields[0].key && s.fields[0].must_understand);
    assert!(s.fields[1].optional && s.fields[1].external);
    assert_eq!(s.fields[2].id, Some(7));
    assert_eq!(s.fields[2].default, Some(Value::Int(3)));
    assert_eq!(s.fields[2].max, Some(Value::Int(9)));
    assert_eq!(s.fields[3].hashid.as_deref(), Some("other"));
    assert!(s.fields[4].non_serialized);
    let DeclKind::Struct(f) = decl(&c, "F") else {
        panic!()
    };
    assert!(f.nested && f.extensibility == Extensibility::Final);
    let DeclKind::Struct(q) = decl(&c, "N::Q") else {
        panic!()
    };
    assert!(q.nested);
    let DeclKind::Struct(t) = decl(&c, "T") else {
        panic!()
    };
    assert!(!t.nested);
}

#[test]
fn default_extensibility_option() {
    let opts = Options {
        default_extensibility: Extensibility::Final,
        ..Default::default()
    };
    let c = ok_with(
        MemVfs::new(),
        &opts,
        "struct S { long x; };\n@appendable struct A { long x; };\n",
    );
    let DeclKind::Struct(s) = decl(&c, "S") else {
        panic!()
    };
    assert_eq!(s.extensibility, Extensibility::Final);
}

#[test]
fn derived_struct_inherits_base_extensibility() {
    // The `-x`/default option must not override what the base dictates.
    let opts = Options {
        default_extensibility: Extensibility::Appendable,
        ..Default::default()
    };
    let c = ok_with(
        MemVfs::new(),
        &opts,
        "@mutable struct M { short s; };\nstruct DM : M { long l; };\nstruct DDM : DM { long m; };\n\
         @final struct F { short s; };\ntypedef F FAlias;\nstruct DF : FAlias { long l; };\n\
         @final struct DF2 : F { long l; };\nstruct P { long x; };\nstruct DP : P { long y; };\n",
    );
    let ext = |n: &str| match decl(&c, n) {
        DeclKind::Struct(s) => s.extensibility,
        other => panic!("{n} is {other:?}"),
    };
    assert_eq!(ext("DM"), Extensibility::Mutable);
    assert_eq!(ext("DDM"), Extensibility::Mutable);
    assert_eq!(ext("DF"), Extensibility::Final);
    assert_eq!(ext("DF2"), Extensibility::Final);
    assert_eq!(ext("DP"), Extensibility::Appendable);
    assert!(c.diags.iter().next().is_none());
    assert_eq!(
        codes("@mutable struct B { short s; };\n@appendable struct D : B { long l; };\n"),
        ["idlc::E0416"]
    );
}

#[test]
fn capitalised_key_still_makes_a_key_with_a_warning() {
    let c = ok("struct S { @Key long id; @key long b; long c; };\n");
    let DeclKind::Struct(s) = decl(&c, "S") else {
        panic!()
    };
    assert!(s.fields[0].key && s.fields[1].key && !s.fields[2].key);
    let w: Vec<_> = c.diags.iter().map(|d| d.code.as_str()).collect();
    assert_eq!(w, ["idlc::W0106"]);
}

#[test]
fn unsupported_constructs_warn_once_each() {
    let c = ok("interface I { void f(); };\nexception Ex { long code; };\nnative N;\nvaluetype V { public long x; };\nstruct S { long x; };\n");
    let w: Vec<_> = c.diags.iter().map(|d| d.code.as_str()).collect();
    assert_eq!(w, ["idlc::W0101"; 4]);
}

#[test]
fn annotation_declarations_are_accepted() {
    let c = ok(
        "@annotation MyAnn { long level default 1; string note; };\n@MyAnn(level = 2) struct S { @MyAnn long x; };\n",
    );
    assert!(c.diags.iter().next().is_none());
}

#[test]
fn typedefs_of_anonymous_and_array_types() {
    let c = ok("typedef struct Inner { long x; } InnerAlias, InnerArr[2];\ntypedef long Grid[2][3], Row[3];\nstruct S { InnerAlias a; InnerArr b; Grid g; };\n");
    assert!(matches!(decl(&c, "Inner"), DeclKind::Struct(_)));
    assert!(
        matches!(decl(&c, "Grid"), DeclKind::Alias { ty: Type::Array { dims, .. } } if dims == &vec![2, 3])
    );
}

#[test]
fn semantic_error_codes() {
    assert!(
        codes("struct A { @key long a; };\nstruct B : A { @key long b; };\n")
            .contains(&"idlc::E0406")
    );
    assert!(
        codes("union U switch (long) { case 1: long a; case 1: long b; };\n")
            .contains(&"idlc::E0401")
    );
    assert!(codes("const long X = 2147483648;\n").contains(&"idlc::E0301"));
    assert!(codes("struct S { @key @optional long a; };\n").contains(&"idlc::E0405"));
    assert!(codes("struct S { X x; };\n").contains(&"idlc::E0201"));
}

#[test]
fn locations_survive_includes_and_macros() {
    let files = MemVfs::new().with("inc.idl", "\n\nstruct Bad { Nope n; };\n");
    let c = compile_str(
        "main.idl",
        "#define T long\nstruct A { T a; };\n#include \"inc.idl\"\n",
        &Options::default(),
        &files,
    );
    let d = c.diags.iter().find(|d| d.is_error()).expect("an error");
    let loc = d.primary_loc().unwrap();
    assert_eq!(c.db.describe(loc), "inc.idl:3:14");
}

#[test]
fn json_model_output() {
    let c = ok("module M { @key struct S { @key long id; }; };\n");
    let j = c.json().unwrap();
    let v: serde_json::Value = serde_json::from_str(&j).unwrap();
    assert_eq!(v["decls"][0]["name"], "S");
    assert_eq!(v["decls"][0]["kind"]["decl"], "struct");
}

fn warning_codes(c: &Compilation) -> Vec<&'static str> {
    c.diags
        .iter()
        .filter(|d| !d.is_error())
        .map(|d| d.code.as_str())
        .collect()
}

#[test]
fn vendor_extensions_are_accepted_with_a_warning_each() {
    let c = ok("enum E { A = 2, B, C = 7 };\n\
         struct S { map<E, long> m; };\n\
         union U switch (char) { case 65: long a; case 'b': short b; };\n");
    match decl(&c, "E") {
        DeclKind::Enum(e) => {
            let v: Vec<i64> = e.enumerators.iter().map(|e| e.value).collect();
            assert_eq!(v, [2, 3, 7]);
        }
        other => panic!("{other:?}"),
    }
    match decl(&c, "U") {
        DeclKind::Union(u) => assert_eq!(u.cases[0].labels, [Value::Char('A')]),
        other => panic!("{other:?}"),
    }
    assert_eq!(warning_codes(&c), ["idlc::W0107"; 4]);
    // Both forms of a value on one enumerator, and a char label that does not fit, stay errors.
    assert!(codes("enum E { @value(1) A = 2 };").contains(&"idlc::W0107"));
    assert!(compile_str(
        "m.idl",
        "enum E { @value(1) A = 2 };",
        &Options::default(),
        &MemVfs::new()
    )
    .has_errors());
    assert_eq!(
        codes("union U switch (char) { case 300: long a; };"),
        ["idlc::E0403"]
    );
}

#[test]
fn function_like_macro_call_spans_lines() {
    let c = ok("#define MEMBER(t, n) t n;\n\
         struct S {\n\
             MEMBER(long,\n\
                    x)\n\
             MEMBER\n\
               (short, y) long z;\n\
         };\n");
    match decl(&c, "S") {
        DeclKind::Struct(s) => {
            let names: Vec<&str> = s.fields.iter().map(|f| f.name.as_str()).collect();
            assert_eq!(names, ["x", "y", "z"]);
        }
        other => panic!("{other:?}"),
    }
    // Positions after a multi-line call stay exact.
    let mut c = compile_str(
        "main.idl",
        "#define P(a, b) a b\nstruct S {\n  P(long,\n    w); nope q;\n};\n",
        &Options::default(),
        &MemVfs::new(),
    );
    let text = c.render_diagnostics(Default::default());
    assert!(text.contains("main.idl:4:9"), "{text}");
}

#[test]
fn a_session_parses_a_shared_include_once_and_keeps_results_exact() {
    use idlc::driver::Session;
    // `t.idl` means something else depending on a macro the includer sets: the cache must not mix them up.
    let files = MemVfs::new()
        .with(
            "t.idl",
            "#ifdef WIDE\nstruct T { long long v; };\n#else\nstruct T { short v; };\n#endif\n",
        )
        .with("bad.idl", "struct B { nope x; };\n");
    let mut s = Session::with_vfs(Options::default(), Box::new(files.clone()));
    let narrow = s.compile_str("a.idl", "#include \"t.idl\"\nstruct A { T t; };\n");
    let wide = s.compile_str(
        "b.idl",
        "#define WIDE\n#include \"t.idl\"\nstruct B2 { T t; };\n",
    );
    let again = s.compile_str("c.idl", "#include \"t.idl\"\nstruct C { T t; };\n");
    let ty = |c: &Compilation| match decl(c, "T") {
        DeclKind::Struct(st) => format!("{:?}", st.fields[0].ty),
        other => panic!("{other:?}"),
    };
    assert_eq!(ty(&narrow), ty(&again));
    assert_ne!(ty(&narrow), ty(&wide));
    // A diagnostic in a shared include renders the same from a session as from a fresh compilation.
    let main = "#include \"bad.idl\"\nstruct M { long y; };\n";
    let mut fresh = compile_str("m.idl", main, &Options::default(), &files);
    let _ = s.compile_str("n.idl", main);
    let mut cached = s.compile_str("m.idl", main);
    assert_eq!(
        fresh.render_diagnostics(Default::default()),
        cached.render_diagnostics(Default::default())
    );
}

#[test]
fn fixed_members_map_to_the_runtime_decimal() {
    let mut c = ok("struct A { fixed<5,2> price; sequence<fixed<31,0>> big; };\n");
    let code = c.rust().expect("rust");
    assert!(
        code.contains("price: ::dds_runtime::cdr::Fixed<5, 2>"),
        "{code}"
    );
    assert!(code.contains("::dds_runtime::cdr::Fixed<31, 0>"), "{code}");
}

#[test]
fn line_directive_moves_reported_positions() {
    let src = "struct A { long a; };\n#line 100 \"gen.idl\"\nstruct B { nope b; };\n#line 7\nstruct C { nope c; };\n";
    let c = compile_str("main.idl", src, &Options::default(), &MemVfs::new());
    let at: Vec<String> = c
        .diags
        .iter()
        .filter_map(|d| d.primary_loc())
        .map(|l| c.db.describe(l))
        .collect();
    assert_eq!(at, ["gen.idl:100:12", "gen.idl:7:12"]);
    assert!(codes("#line x\n").contains(&"idlc::E0005"));
    assert!(codes("#line 3 gen.idl\n").contains(&"idlc::E0005"));
}
