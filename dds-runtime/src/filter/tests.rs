use proptest::prelude::*;

use super::*;
use crate::DdsType;

#[derive(DdsType, Debug, Clone, Copy, PartialEq)]
enum Color {
    Red,
    #[dds(value = 7)]
    Green,
    Blue,
}

#[derive(DdsType, Debug, Clone, PartialEq)]
struct Point {
    x: i32,
    y: f64,
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(discriminator = i32)]
enum Payload {
    #[dds(case = 1)]
    Num(i64),
    #[dds(case = 2)]
    Text(String),
}

#[derive(DdsType, Debug, Clone, PartialEq)]
struct Sample {
    #[dds(key)]
    name: String,
    color: Color,
    count: u32,
    center: Point,
    path: Vec<Point>,
    corners: [i16; 3],
    #[dds(optional)]
    note: Option<String>,
    letter: char,
    on: bool,
    payload: Payload,
}

fn sample() -> Sample {
    Sample {
        name: "RED_SQUARE".into(),
        color: Color::Green,
        count: 42,
        center: Point { x: -5, y: 2.5 },
        path: vec![Point { x: 1, y: 1.0 }, Point { x: 2, y: 4.0 }],
        corners: [10, 20, 30],
        note: None,
        letter: 'q',
        on: true,
        payload: Payload::Text("hello".into()),
    }
}

fn holds(e: &str, p: &[&str]) -> bool {
    ContentFilter::new(e, p)
        .unwrap_or_else(|err| panic!("{e}: {err}"))
        .matches(&sample())
}

#[test]
fn every_predicate_of_annex_b() {
    for (e, want) in [
        ("count = 42", true),
        ("count <> 42", false),
        ("count != 41", true),
        (
            "count < 43 AND count <= 42 AND count > 41 AND count >= 42",
            true,
        ),
        ("count BETWEEN 40 AND 42", true),
        ("count NOT BETWEEN 40 AND 42", false),
        ("name LIKE 'RED%'", true),
        ("name LIKE 'RED_SQUAR_'", true),
        ("name NOT LIKE '%SQUARE'", false),
        ("name LIKE 'BLUE%'", false),
        ("on = TRUE", true),
        ("on = false", false),
        ("letter = 'q'", true),
        ("letter > 'a'", true),
        ("count = 0x2A", true),
        ("center.x = -5", true),
        ("center.y > 2.25E0", true),
        ("center.y < 2.5", false),
        ("path[1].y = 4", true),
        ("path[5].y = 4", false),
        ("corners[2] = 30", true),
        ("note = 'x'", false),
        ("NOT note = 'x'", true),
        ("payload.Text = 'hello'", true),
        ("payload.Num = 1", false),
        ("`RED_SQUARE' = name", true),
        ("count > center.x", true),
        ("(count = 1 OR count = 42) and NOT (name = 'x')", true),
        ("count = 1 OR count = 2 OR count = 42", true),
        ("missing = 1", false),
    ] {
        assert_eq!(holds(e, &[]), want, "{e}");
    }
}

#[test]
fn enumerators_compare_by_name_and_by_value() {
    assert!(holds("color = 'Green'", &[]));
    assert!(holds("color = 7", &[]));
    assert!(holds("color > 0", &[]));
    assert!(!holds("color = 'Red'", &[]));
    assert!(holds("color = %0", &["Green"]));
    assert!(holds("color = %0", &["'Green'"]));
    assert!(holds("color BETWEEN 7 AND 8", &[]));
}

#[test]
fn parameters_change_at_run_time() {
    let mut f = ContentFilter::new("count > %0 AND name = %1", &["10", "RED_SQUARE"]).unwrap();
    assert!(f.matches(&sample()));
    f.set_parameters(&["50", "RED_SQUARE"]).unwrap();
    assert!(!f.matches(&sample()));
    assert_eq!(
        f.set_parameters(&["1"]),
        Err(FilterError::MissingParameter { index: 1, given: 1 })
    );
    assert_eq!(f.parameters(), ["50", "RED_SQUARE"]);
    assert!(matches!(
        ContentFilter::new("count > %0", &[] as &[&str]),
        Err(FilterError::MissingParameter { index: 0, given: 0 })
    ));
}

#[test]
fn queries_sort_and_may_have_no_condition() {
    let q = ContentFilter::query("ORDER BY center.x, name", &[] as &[&str]).unwrap();
    assert!(q.matches(&sample()) && q.has_order_by());
    let mut a = sample();
    let mut b = sample();
    a.center.x = 3;
    b.center.x = 1;
    assert_eq!(q.compare(&a, &b), Ordering::Greater);
    b.center.x = 3;
    b.name = "A".into();
    assert_eq!(q.compare(&a, &b), Ordering::Greater);
    let q = ContentFilter::query("count > 1 ORDER BY count", &[] as &[&str]).unwrap();
    assert!(q.matches(&sample()));
    assert!(ContentFilter::query("", &[] as &[&str])
        .unwrap()
        .matches(&sample()));
    assert_eq!(
        ContentFilter::new("count > 1 ORDER BY count", &[] as &[&str]),
        Err(FilterError::OrderByInFilter)
    );
}

#[test]
fn bad_expressions_are_typed_errors() {
    let none: &[&str] = &[];
    let err = |e: &str| ContentFilter::new(e, none).unwrap_err();
    assert_eq!(err(""), FilterError::Empty);
    assert!(matches!(err("x >"), FilterError::Unexpected { pos: 3, .. }));
    assert!(matches!(err("(x > 1"), FilterError::Unexpected { .. }));
    assert!(matches!(err("x ! 1"), FilterError::UnexpectedChar { .. }));
    assert!(matches!(err("x > 1 y"), FilterError::Unexpected { .. }));
    assert!(matches!(
        err("'open = 1"),
        FilterError::UnterminatedString { pos: 0 }
    ));
    assert!(matches!(
        err("x = %100"),
        FilterError::BadParameterRef { .. }
    ));
    assert!(matches!(err("x = 12abc"), FilterError::BadNumber { .. }));
    assert!(matches!(err("a..b = 1"), FilterError::BadPath { .. }));
    assert!(matches!(err("a[x] = 1"), FilterError::BadPath { .. }));
    assert!(matches!(
        err("x MATCH 'a'"),
        FilterError::UnsupportedOperator { .. }
    ));
    assert!(matches!(err("x = 1 AND"), FilterError::Unexpected { .. }));
    assert!(matches!(err("AND = 1"), FilterError::Unexpected { .. }));
    let deep = format!("{}x = 1{}", "(".repeat(200), ")".repeat(200));
    assert_eq!(err(&deep), FilterError::TooDeep { limit: 64 });
    let nots = format!("{}x = 1", "NOT ".repeat(200));
    assert_eq!(err(&nots), FilterError::TooDeep { limit: 64 });
    let long = "x = 1 OR ".repeat(10_000) + "x = 1";
    assert!(matches!(err(&long), FilterError::TooLong { .. }));
    let many = vec!["1"; 101];
    assert!(matches!(
        ContentFilter::new("x = 1", &many),
        Err(FilterError::TooManyParameters { given: 101 })
    ));
}

#[test]
fn long_flat_chains_evaluate_without_deep_recursion() {
    let e = "count = 1 OR ".repeat(3000) + "count = 42";
    assert!(holds(&e, &[]));
}

#[test]
fn like_handles_wildcards_and_utf8() {
    for (p, s, want) in [
        ("%", "", true),
        ("_", "", false),
        ("a%b%c", "axxbyyc", true),
        ("a%b%c", "axxbyy", false),
        ("%%a", "ba", true),
        ("h_llo", "héllo", true),
        ("%é", "café", true),
        ("a_c", "abbc", false),
    ] {
        assert_eq!(eval::like(p.as_bytes(), s.as_bytes()), want, "{p} ~ {s}");
    }
}

proptest! {
    #[test]
    fn parser_never_panics_on_arbitrary_text(s in "\\PC{0,80}") {
        let _ = ContentFilter::query(&s, &["1", "'a'"]);
        let _ = ContentFilter::new(&s, &["1"]);
    }

    #[test]
    fn parser_never_panics_on_token_soup(
        toks in proptest::collection::vec(
            prop_oneof![
                Just("x"), Just("center.x"), Just("path[1].y"), Just("AND"), Just("OR"), Just("NOT"),
                Just("("), Just(")"), Just("="), Just("<>"), Just("<="), Just("BETWEEN"), Just("LIKE"),
                Just("'s'"), Just("%0"), Just("%1"), Just("-3"), Just("0x1f"), Just("1.5e3"), Just("TRUE"),
                Just("ORDER"), Just("BY"), Just(","), Just("`q'"), Just("["), Just("]"), Just("."),
            ],
            0..24,
        )
    ) {
        let e = toks.join(" ");
        if let Ok(f) = ContentFilter::query(&e, &["5", "'RED'"]) {
            let _ = f.matches(&sample());
            let _ = f.compare(&sample(), &sample());
        }
    }

    #[test]
    fn between_agrees_with_two_comparisons(v in any::<i32>(), lo in any::<i32>(), hi in any::<i32>()) {
        let mut s = sample();
        s.center.x = v;
        let (lo, hi) = (lo.to_string(), hi.to_string());
        let b = ContentFilter::new("center.x BETWEEN %0 AND %1", &[&lo, &hi]).unwrap();
        let c = ContentFilter::new("center.x >= %0 AND center.x <= %1", &[&lo, &hi]).unwrap();
        prop_assert_eq!(b.matches(&s), c.matches(&s));
        prop_assert_eq!(b.matches(&s), (i64::from(lo.parse::<i32>().unwrap())..=i64::from(hi.parse::<i32>().unwrap())).contains(&i64::from(v)));
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(transparent)]
struct Meters(f32);

#[derive(DdsType, Debug, Clone, PartialEq)]
struct Derived {
    #[dds(base)]
    base: Point,
    #[dds(name = "dist")]
    distance: Meters,
    #[dds(non_serialized)]
    cache: u8,
}

#[derive(DdsType, Debug, Clone, PartialEq)]
struct Wrapper<T> {
    inner: T,
}

#[test]
fn derive_reaches_base_members_typedefs_wire_names_and_generics() {
    let d = Derived {
        base: Point { x: 3, y: 0.5 },
        distance: Meters(12.5),
        cache: 1,
    };
    let f = |e: &str| ContentFilter::new(e, &[] as &[&str]).unwrap();
    assert!(f("x = 3 AND y = 0.5 AND dist > 12").matches(&d));
    assert!(
        !f("distance > 12").matches(&d),
        "the IDL name, not the Rust one"
    );
    assert!(
        !f("cache = 1").matches(&d),
        "non_serialized members are not reachable"
    );
    let w = Wrapper { inner: d };
    assert!(f("inner.dist BETWEEN 12 AND 13").matches(&w));
}
