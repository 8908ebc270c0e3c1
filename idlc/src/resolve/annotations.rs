//! Built-in annotations (IDL 4.2 §8.3, XTypes §7.3.1.2): interpretation and placement checks.
use super::Resolver;
use crate::ast::{Annotation, AnnotationParams, ConstExpr, ExprKind, Literal};
use crate::diag::{Code, Diagnostic};
use crate::model::{AutoId, Extensibility, Value, Verbatim};
use crate::source::Loc;

/// Where an annotation is applied.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Place {
    Module,
    Struct,
    Union,
    Enum,
    Bitmask,
    Bitset,
    Typedef,
    Const,
    Member,
    UnionMember,
    Discriminator,
    Enumerator,
    BitFlag,
    Bitfield,
    Other,
}

const BUILTIN: &[(&str, &[Place])] = {
    use Place::*;
    &[
        ("id", &[Member, UnionMember]),
        ("autoid", &[Struct, Union, Module]),
        ("hashid", &[Member, UnionMember]),
        ("key", &[Member, Discriminator]),
        ("optional", &[Member]),
        ("external", &[Member, UnionMember]),
        ("must_understand", &[Member]),
        ("extensibility", &[Struct, Union, Enum, Bitmask, Bitset]),
        ("final", &[Struct, Union, Enum, Bitmask, Bitset]),
        ("appendable", &[Struct, Union, Enum, Bitmask, Bitset]),
        ("mutable", &[Struct, Union]),
        ("value", &[Enumerator]),
        ("position", &[BitFlag, Bitfield]),
        ("bit_bound", &[Enum, Bitmask, Bitfield]),
        ("default", &[Member, Typedef]),
        ("default_literal", &[Enumerator]),
        ("range", &[Member, Typedef]),
        ("min", &[Member, Typedef]),
        ("max", &[Member, Typedef]),
        ("unit", &[Member, Typedef, UnionMember]),
        ("nested", &[Struct, Union]),
        ("default_nested", &[Module]),
        ("topic", &[Struct, Union]),
        (
            "data_representation",
            &[Struct, Union, Enum, Bitmask, Bitset, Typedef],
        ),
        (
            "try_construct",
            &[Member, UnionMember, Discriminator, Struct, Union, Typedef],
        ),
        (
            "verbatim",
            &[
                Module,
                Struct,
                Union,
                Enum,
                Bitmask,
                Bitset,
                Typedef,
                Const,
                Member,
                UnionMember,
                Other,
            ],
        ),
        ("non_serialized", &[Member]),
        ("ignore_literal_names", &[Enum, Bitmask]),
        ("oneway", &[Other]),
        ("ami", &[Other]),
        ("service", &[Other]),
    ]
};

/// The interpreted annotations of one element.
#[derive(Default, Debug)]
pub(crate) struct Anns<'a> {
    pub id: Option<u32>,
    pub autoid: Option<AutoId>,
    pub hashid: Option<String>,
    pub key: bool,
    pub optional: bool,
    pub external: bool,
    pub must_understand: bool,
    pub extensibility: Option<Extensibility>,
    pub value: Option<&'a ConstExpr>,
    pub position: Option<&'a ConstExpr>,
    pub bit_bound: Option<&'a ConstExpr>,
    pub default: Option<&'a ConstExpr>,
    pub default_literal: bool,
    pub min: Option<&'a ConstExpr>,
    pub max: Option<&'a ConstExpr>,
    pub unit: Option<String>,
    pub nested: Option<bool>,
    pub default_nested: Option<bool>,
    pub topic: bool,
    pub verbatim: Vec<Verbatim>,
    pub non_serialized: bool,
    pub key_loc: Option<Loc>,
    pub optional_loc: Option<Loc>,
    pub id_loc: Option<Loc>,
    pub extensibility_loc: Option<Loc>,
}

impl Resolver<'_> {
    fn ann_err(&mut self, a: &Annotation, msg: String) {
        self.diags
            .push(Diagnostic::error(Code::AnnotationParam, msg).at(a.loc, "in this annotation"));
    }

    fn bool_param(&mut self, a: &Annotation) -> bool {
        match &a.params {
            AnnotationParams::None => true,
            AnnotationParams::Single(e) => match &e.kind {
                ExprKind::Literal(Literal::Bool(b)) => *b,
                _ => {
                    self.ann_err(a, format!("`@{}` takes TRUE or FALSE", a.name.text()));
                    true
                }
            },
            AnnotationParams::Named(ps) => match ps.iter().find(|(n, _)| n.name == "value") {
                Some((_, e)) => matches!(e.kind, ExprKind::Literal(Literal::Bool(true))),
                None => true,
            },
        }
    }

    fn single<'a>(&mut self, a: &'a Annotation) -> Option<&'a ConstExpr> {
        match &a.params {
            AnnotationParams::Single(e) => Some(e),
            AnnotationParams::Named(ps) if ps.len() == 1 && ps[0].0.name == "value" => {
                Some(&ps[0].1)
            }
            _ => {
                self.ann_err(a, format!("`@{}` needs one parameter", a.name.text()));
                None
            }
        }
    }

    /// An enumerated parameter such as `FINAL` or `HASH`: the bare identifier, upper-cased.
    fn word_param(&mut self, a: &Annotation) -> Option<String> {
        let e = self.single(a)?;
        match &e.kind {
            ExprKind::Name(n) => n.parts.last().map(|p| p.name.to_ascii_uppercase()),
            ExprKind::Literal(Literal::Str(s)) => Some(s.to_ascii_uppercase()),
            _ => {
                self.ann_err(
                    a,
                    format!("`@{}` expects a name such as FINAL", a.name.text()),
                );
                None
            }
        }
    }

    fn named<'a>(&mut self, a: &'a Annotation, name: &str) -> Option<&'a ConstExpr> {
        match &a.params {
            AnnotationParams::Named(ps) => ps
                .iter()
                .find(|(n, _)| n.name.eq_ignore_ascii_case(name))
                .map(|(_, e)| e),
            _ => None,
        }
    }

    fn string_of(&mut self, e: &ConstExpr) -> Option<String> {
        match self.eval(e, None)? {
            Value::Str(s) | Value::WStr(s) => Some(s),
            _ => None,
        }
    }

    pub(crate) fn annotations<'a>(&mut self, list: &'a [Annotation], place: Place) -> Anns<'a> {
        let mut r = Anns::default();
        for a in list {
            let name = a
                .name
                .parts
                .last()
                .map(|p| p.name.to_ascii_lowercase())
                .unwrap_or_default();
            if self.applies(a, &name, place) {
                self.apply(&mut r, a, &name);
            }
        }
        r
    }

    /// Whether the built-in annotation `a` (lower-cased `name`) has an effect at `place`; warns when it
    /// is unknown, misspelled or out of place.
    fn applies(&mut self, a: &Annotation, name: &str, place: Place) -> bool {
        let Some((_, places)) = BUILTIN.iter().find(|(n, _)| *n == name) else {
            if !self.user_annotations.contains(name) {
                let known: Vec<&str> = BUILTIN.iter().map(|(n, _)| *n).collect();
                let mut d = Diagnostic::warning(
                    Code::UnknownAnnotation,
                    format!("unknown annotation `@{}` ignored", a.name.text()),
                )
                .at(a.loc, "not a built-in annotation");
                if let Some(s) = crate::diag::suggest(name, known) {
                    d = d.help(format!("did you mean `@{s}`?"));
                }
                self.diags.push(d);
            }
            return false;
        };
        let spelled = a.name.parts.last().map_or("", |p| p.name.as_str());
        if spelled != name {
            // eProsima's examples write `@Key`; IDL names are case-sensitive and Cyclone rejects it.
            self.diags.push(
                Diagnostic::warning(
                    Code::AnnotationCase,
                    format!("`@{spelled}` is not the IDL spelling of `@{name}`"),
                )
                .at(a.loc, format!("read as `@{name}`"))
                .help(format!(
                    "write `@{name}`: built-in annotation names are lower case, and other compilers reject `@{spelled}`"
                )),
            );
        }
        if !places.contains(&place) {
            let mut d = Diagnostic::warning(
                Code::IgnoredAnnotation,
                format!("`@{}` has no effect here", a.name.text()),
            )
            .at(a.loc, "ignored");
            if name == "default" && place == Place::Discriminator {
                // eProsima's extension: the discriminator value of a default-constructed union.
                d = Diagnostic::warning(
                    Code::IgnoredAnnotation,
                    format!("`@{}` on a union discriminator is ignored", a.name.text()),
                )
                .at(a.loc, "ignored")
                .help("IDL 4.2 allows `@default` on members only; the union's `Default` selects its first member")
                .note("Cyclone's idlc rejects this annotation");
            }
            self.diags.push(d);
            return false;
        }
        true
    }

    /// Records the effect of the built-in annotation `a` (lower-cased `name`) in `r`.
    fn apply<'a>(&mut self, r: &mut Anns<'a>, a: &'a Annotation, name: &str) {
        match name {
            "id" => {
                if let Some(e) = self.single(a) {
                    r.id = self.eval_u64(e, "@id", 0).and_then(|v| self.id_range(a, v));
                    r.id_loc = Some(a.loc);
                }
            }
            "autoid" => {
                r.autoid = match &a.params {
                    AnnotationParams::None => Some(AutoId::Hash),
                    _ => match self.word_param(a).as_deref() {
                        Some("SEQUENTIAL") => Some(AutoId::Sequential),
                        Some("HASH") => Some(AutoId::Hash),
                        _ => {
                            self.ann_err(a, "`@autoid` takes SEQUENTIAL or HASH".into());
                            None
                        }
                    },
                }
            }
            "hashid" => {
                r.hashid = Some(match &a.params {
                    AnnotationParams::None => String::new(),
                    AnnotationParams::Single(e) => self.string_of(e).unwrap_or_default(),
                    AnnotationParams::Named(_) => String::new(),
                })
            }
            "key" => {
                r.key = self.bool_param(a);
                r.key_loc = Some(a.loc);
            }
            "optional" => {
                r.optional = self.bool_param(a);
                r.optional_loc = Some(a.loc);
            }
            "external" => r.external = self.bool_param(a),
            "must_understand" => r.must_understand = self.bool_param(a),
            "final" | "appendable" | "mutable" | "extensibility" => {
                r.extensibility_loc = Some(a.loc);
                r.extensibility = self.extensibility(a, name);
            }
            "value" => r.value = self.single(a),
            "position" => r.position = self.single(a),
            "bit_bound" => r.bit_bound = self.single(a),
            "default" => r.default = self.single(a),
            "default_literal" => r.default_literal = true,
            "range" => {
                r.min = self.named(a, "min");
                r.max = self.named(a, "max");
            }
            "min" => r.min = self.single(a),
            "max" => r.max = self.single(a),
            "unit" => {
                if let Some(e) = self.single(a) {
                    r.unit = self.string_of(e);
                }
            }
            "nested" => r.nested = Some(self.bool_param(a)),
            "default_nested" => r.default_nested = Some(self.bool_param(a)),
            "topic" => r.topic = true,
            "non_serialized" => r.non_serialized = self.bool_param(a),
            "verbatim" => r.verbatim.extend(self.verbatim(a)),
            // Accepted and recorded nowhere: they do not change the Rust mapping.
            _ => {}
        }
    }

    /// `@verbatim` text for Rust (language `*` or `rust`), with its placement.
    fn verbatim(&mut self, a: &Annotation) -> Option<Verbatim> {
        let lang = self
            .named(a, "language")
            .and_then(|e| self.string_of(e))
            .unwrap_or_else(|| "*".into());
        let placement = self
            .named(a, "placement")
            .and_then(|e| self.string_of(e))
            .unwrap_or_else(|| "BEFORE_DECLARATION".into());
        let text = match &a.params {
            AnnotationParams::Single(e) => self.string_of(e),
            _ => self.named(a, "text").and_then(|e| self.string_of(e)),
        };
        let rust = lang == "*" || lang.eq_ignore_ascii_case("rust");
        text.filter(|_| rust).map(|text| Verbatim {
            placement: placement.to_ascii_uppercase(),
            text,
        })
    }

    fn extensibility(&mut self, a: &Annotation, name: &str) -> Option<Extensibility> {
        match name {
            "final" => Some(Extensibility::Final),
            "appendable" => Some(Extensibility::Appendable),
            "mutable" => Some(Extensibility::Mutable),
            _ => match self.word_param(a).as_deref() {
                Some("FINAL") => Some(Extensibility::Final),
                Some("APPENDABLE") => Some(Extensibility::Appendable),
                Some("MUTABLE") => Some(Extensibility::Mutable),
                _ => {
                    self.ann_err(
                        a,
                        "`@extensibility` takes FINAL, APPENDABLE or MUTABLE".into(),
                    );
                    None
                }
            },
        }
    }

    fn id_range(&mut self, a: &Annotation, v: u64) -> Option<u32> {
        if v > 0x0FFF_FFFF {
            self.ann_err(
                a,
                format!("member id {v} is larger than the maximum 0x0FFFFFFF"),
            );
            return None;
        }
        Some(v as u32)
    }
}
