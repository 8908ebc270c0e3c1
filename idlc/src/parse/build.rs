//! Builds the AST from pest pairs, attaching source locations, doc comments and legacy `//@key` comments.
use super::literal::{parse_int, unescape};
use super::{Rule, KEYWORDS};
use crate::ast::*;
use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::preprocess::Output;
use crate::source::Loc;
use pest::iterators::Pair;

pub(crate) struct Builder<'a> {
    pp: &'a Output,
    diags: &'a mut Diagnostics,
}

type P<'i> = Pair<'i, Rule>;

impl<'a> Builder<'a> {
    pub(crate) fn new(pp: &'a Output, diags: &'a mut Diagnostics) -> Self {
        Builder { pp, diags }
    }

    fn loc(&self, p: &P) -> Loc {
        let s = p.as_span();
        self.pp.map.loc(s.start(), s.end())
    }

    fn err(&mut self, code: Code, loc: Loc, msg: impl Into<String>, label: &str) {
        self.diags.push(Diagnostic::error(code, msg).at(loc, label));
    }

    pub(crate) fn specification(&mut self, p: P) -> Spec {
        let defs = p
            .into_inner()
            .filter(|p| p.as_rule() == Rule::definition)
            .map(|d| self.definition(d))
            .collect();
        Spec { defs }
    }

    /// Doc comments (`/** */`, `///`) that end right before `start` (only whitespace between).
    fn doc_before(&self, start: usize) -> Vec<String> {
        let cs = &self.pp.comments;
        let text = &self.pp.text;
        let mut i = cs.partition_point(|c| c.end <= start);
        let mut limit = start;
        let mut docs = Vec::new();
        while i > 0 {
            let c = &cs[i - 1];
            if !text.get(c.end..limit).is_some_and(|s| s.trim().is_empty()) {
                break;
            }
            let body = &text[c.start..c.end];
            if let Some(b) = body.strip_prefix("/**").and_then(|b| b.strip_suffix("*/")) {
                if b.starts_with('*') || b.is_empty() {
                    break;
                }
                let lines: Vec<String> = b
                    .lines()
                    .map(|l| l.trim().trim_start_matches('*').trim_start().to_string())
                    .collect();
                let lines = trim_blank(lines);
                docs.splice(0..0, lines);
            } else if let Some(b) = body.strip_prefix("///") {
                docs.insert(0, b.strip_prefix(' ').unwrap_or(b).trim_end().to_string());
            } else {
                break;
            }
            limit = c.start;
            i -= 1;
        }
        docs
    }

    /// `//@key` (or `//@Key`) on the same line after a member.
    fn legacy_key_after(&mut self, end: usize) -> Option<Annotation> {
        let cs = &self.pp.comments;
        let i = cs.partition_point(|c| c.start < end);
        let c = cs.get(i)?;
        let gap = self.pp.text.get(end..c.start)?;
        if gap.contains('\n') {
            return None;
        }
        let body = self.pp.text[c.start..c.end].trim_start_matches('/').trim();
        if !body.eq_ignore_ascii_case("@key") {
            return None;
        }
        let loc = self.pp.map.loc(c.start, c.end);
        self.diags.push(
            Diagnostic::warning(
                Code::LegacyAnnotation,
                "legacy comment annotation `//@key` treated as `@key`",
            )
            .at(loc, "comment annotation")
            .help("write `@key` before the member instead"),
        );
        let name = Ident {
            name: "key".into(),
            loc,
        };
        Some(Annotation {
            name: ScopedName {
                absolute: false,
                parts: vec![name],
                loc,
            },
            params: AnnotationParams::None,
            loc,
            legacy: true,
        })
    }

    fn definition(&mut self, p: P) -> Definition {
        let loc = self.loc(&p);
        let doc = self.doc_before(p.as_span().start());
        let mut annotations = Vec::new();
        let mut kind = None;
        for c in p.into_inner() {
            match c.as_rule() {
                Rule::annotation_appl => annotations.push(self.annotation(c)),
                Rule::pragma_keylist => kind = Some(self.keylist(c)),
                _ => kind = Some(self.def_kind(c)),
            }
        }
        let kind = kind.expect("grammar guarantees a definition body");
        Definition {
            annotations,
            kind,
            doc,
            loc,
        }
    }

    fn def_kind(&mut self, c: P) -> DefKind {
        match c.as_rule() {
            Rule::module_dcl => {
                let mut it = c.into_inner().skip(1);
                let name = self.ident(it.next().expect("module name"));
                let defs = it
                    .filter(|d| d.as_rule() == Rule::definition)
                    .map(|d| self.definition(d))
                    .collect();
                DefKind::Module { name, defs }
            }
            Rule::struct_def => DefKind::Struct(self.struct_def(c)),
            Rule::struct_forward => DefKind::Forward(
                ForwardKind::Struct,
                self.ident(c.into_inner().nth(1).expect("name")),
            ),
            Rule::union_def => DefKind::Union(self.union_def(c)),
            Rule::union_forward => DefKind::Forward(
                ForwardKind::Union,
                self.ident(c.into_inner().nth(1).expect("name")),
            ),
            Rule::enum_dcl => DefKind::Enum(self.enum_def(c)),
            Rule::bitmask_dcl => {
                let e = self.enum_def(c);
                DefKind::Bitmask(BitmaskDef {
                    name: e.name,
                    values: e.enumerators,
                })
            }
            Rule::bitset_dcl => DefKind::Bitset(self.bitset(c)),
            Rule::typedef_dcl => DefKind::Typedef(self.typedef(c)),
            Rule::const_dcl => DefKind::Const(self.const_dcl(c)),
            Rule::annotation_dcl => DefKind::Annotation(self.annotation_dcl(c)),
            Rule::native_dcl => DefKind::Unsupported {
                what: "native",
                name: self.ident(c.into_inner().nth(1).expect("name")),
            },
            Rule::interface_dcl | Rule::except_dcl | Rule::value_dcl => {
                let what = match c.as_rule() {
                    Rule::interface_dcl => "interface",
                    Rule::except_dcl => "exception",
                    _ => "valuetype",
                };
                let name = c
                    .into_inner()
                    .find(|p| p.as_rule() == Rule::identifier)
                    .expect("name");
                DefKind::Unsupported {
                    what,
                    name: self.ident(name),
                }
            }
            r => unreachable!("unexpected rule {r:?} in definition"),
        }
    }

    fn keylist(&mut self, p: P) -> DefKind {
        let mut it = p.into_inner();
        let ty = self.scoped_name(it.next().expect("type"));
        let keys = it
            .map(|k| k.into_inner().map(|i| self.ident(i)).collect())
            .collect();
        DefKind::Keylist { ty, keys }
    }

    pub(crate) fn ident(&mut self, p: P) -> Ident {
        let loc = self.loc(&p);
        let text = p.as_str();
        if let Some(esc) = text.strip_prefix('_') {
            return Ident {
                name: esc.to_string(),
                loc,
            };
        }
        if KEYWORDS.contains(&text) {
            self.diags.push(
                Diagnostic::error(
                    Code::Syntax,
                    format!("expected identifier, found keyword `{text}`"),
                )
                .at(loc, "keyword used as a name")
                .help(format!(
                    "`{text}` is a keyword; to use it as a name write `_{text}`"
                )),
            );
            return Ident {
                name: text.to_string(),
                loc,
            };
        }
        if let Some(kw) = KEYWORDS.iter().find(|k| k.eq_ignore_ascii_case(text)) {
            self.diags.push(
                Diagnostic::error(
                    Code::KeywordIdent,
                    format!("identifier `{text}` collides with the keyword `{kw}`"),
                )
                .at(loc, "differs from a keyword only in case")
                .help(format!(
                    "IDL compares identifiers with keywords ignoring case; escape it as `_{text}`"
                )),
            );
        }
        Ident {
            name: text.to_string(),
            loc,
        }
    }

    fn scoped_name(&mut self, p: P) -> ScopedName {
        let loc = self.loc(&p);
        let mut absolute = false;
        let mut parts = Vec::new();
        for c in p.into_inner() {
            match c.as_rule() {
                Rule::abs_scope => absolute = true,
                _ => parts.push(self.ident(c)),
            }
        }
        ScopedName {
            absolute,
            parts,
            loc,
        }
    }

    fn annotation(&mut self, p: P) -> Annotation {
        let loc = self.loc(&p);
        let mut it = p.into_inner();
        let n = it.next().expect("annotation name");
        let nloc = self.loc(&n);
        let text = n.as_str();
        let (absolute, body) = match text.strip_prefix("::") {
            Some(b) => (true, b),
            None => (false, text),
        };
        let parts = body
            .split("::")
            .map(|s| Ident {
                name: s.to_string(),
                loc: nloc,
            })
            .collect();
        let name = ScopedName {
            absolute,
            parts,
            loc: nloc,
        };
        let params = match it.next() {
            None => AnnotationParams::None,
            Some(ps) => {
                let inner: Vec<P> = ps.into_inner().collect();
                if inner.len() == 1 && inner[0].as_rule() == Rule::const_expr {
                    AnnotationParams::Single(
                        self.const_expr(inner.into_iter().next().expect("one")),
                    )
                } else {
                    let mut named = Vec::new();
                    for np in inner {
                        let mut i = np.into_inner();
                        let id = self.ident(i.next().expect("param name"));
                        let e = self.const_expr(i.next().expect("param value"));
                        named.push((id, e));
                    }
                    AnnotationParams::Named(named)
                }
            }
        };
        Annotation {
            name,
            params,
            loc,
            legacy: false,
        }
    }

    fn struct_def(&mut self, p: P) -> StructDef {
        let mut it = p.into_inner().skip(1);
        let name = self.ident(it.next().expect("struct name"));
        let mut base = None;
        let mut members = Vec::new();
        for c in it {
            match c.as_rule() {
                Rule::scoped_name => base = Some(self.scoped_name(c)),
                Rule::member => members.push(self.member(c)),
                _ => {}
            }
        }
        StructDef {
            name,
            base,
            members,
        }
    }

    fn member(&mut self, p: P) -> Member {
        let loc = self.loc(&p);
        let span = p.as_span();
        let doc = self.doc_before(span.start());
        let mut annotations = Vec::new();
        let mut ty = None;
        let mut declarators = Vec::new();
        for c in p.into_inner() {
            match c.as_rule() {
                Rule::annotation_appl => annotations.push(self.annotation(c)),
                Rule::type_spec => ty = Some(self.type_spec(c)),
                Rule::declarators => {
                    declarators = c.into_inner().map(|d| self.declarator(d)).collect()
                }
                _ => {}
            }
        }
        if let Some(a) = self.legacy_key_after(span.end()) {
            annotations.push(a);
        }
        Member {
            annotations,
            ty: ty.expect("member type"),
            declarators,
            doc,
            loc,
        }
    }

    fn declarator(&mut self, p: P) -> Declarator {
        let mut it = p.into_inner();
        let name = self.ident(it.next().expect("declarator name"));
        let dims = it
            .map(|a| self.const_expr(a.into_inner().next().expect("size")))
            .collect();
        Declarator { name, dims }
    }

    fn union_def(&mut self, p: P) -> UnionDef {
        let mut it = p.into_inner().skip(1);
        let name = self.ident(it.next().expect("union name"));
        let mut switch_annotations = Vec::new();
        let mut switch = None;
        let mut cases = Vec::new();
        for c in it {
            match c.as_rule() {
                Rule::annotation_appl => switch_annotations.push(self.annotation(c)),
                Rule::switch_type => {
                    let inner = c.into_inner().next().expect("switch type");
                    switch = Some(self.type_of(inner));
                }
                Rule::case_stmt => cases.push(self.case(c)),
                _ => {}
            }
        }
        UnionDef {
            name,
            switch_annotations,
            switch: switch.expect("switch"),
            cases,
        }
    }

    fn case(&mut self, p: P) -> Case {
        let loc = self.loc(&p);
        let span = p.as_span();
        let doc = self.doc_before(span.start());
        let mut labels = Vec::new();
        let mut annotations = Vec::new();
        let mut ty = None;
        let mut declarator = None;
        for c in p.into_inner() {
            match c.as_rule() {
                Rule::annotation_appl => annotations.push(self.annotation(c)),
                Rule::case_label => {
                    let l = c
                        .into_inner()
                        .find(|x| x.as_rule() != Rule::K_CASE)
                        .expect("label");
                    if l.as_rule() == Rule::default_label {
                        labels.push(CaseLabel::Default(self.loc(&l)));
                    } else {
                        labels.push(CaseLabel::Value(self.const_expr(l)));
                    }
                }
                Rule::type_spec => ty = Some(self.type_spec(c)),
                Rule::declarator => declarator = Some(self.declarator(c)),
                _ => {}
            }
        }
        if let Some(a) = self.legacy_key_after(span.end()) {
            annotations.push(a);
        }
        Case {
            labels,
            annotations,
            ty: ty.expect("case type"),
            declarator: declarator.expect("case declarator"),
            doc,
            loc,
        }
    }

    fn enum_def(&mut self, p: P) -> EnumDef {
        let mut it = p.into_inner().skip(1);
        let name = self.ident(it.next().expect("enum name"));
        let enumerators = it
            .map(|e| {
                let doc = self.doc_before(e.as_span().start());
                let mut annotations = Vec::new();
                let mut name = None;
                let mut value = None;
                for c in e.into_inner() {
                    match c.as_rule() {
                        Rule::annotation_appl => annotations.push(self.annotation(c)),
                        Rule::const_expr => value = Some(self.const_expr(c)),
                        _ => name = Some(self.ident(c)),
                    }
                }
                Enumerator {
                    annotations,
                    name: name.expect("enumerator name"),
                    value,
                    doc,
                }
            })
            .collect();
        EnumDef { name, enumerators }
    }

    fn bitset(&mut self, p: P) -> BitsetDef {
        let mut it = p.into_inner().skip(1);
        let name = self.ident(it.next().expect("bitset name"));
        let mut base = None;
        let mut fields = Vec::new();
        for c in it {
            match c.as_rule() {
                Rule::scoped_name => base = Some(self.scoped_name(c)),
                Rule::bitfield => {
                    let loc = self.loc(&c);
                    let mut annotations = Vec::new();
                    let mut width = None;
                    let mut dest = None;
                    let mut names = Vec::new();
                    for f in c.into_inner() {
                        match f.as_rule() {
                            Rule::annotation_appl => annotations.push(self.annotation(f)),
                            Rule::bitfield_spec => {
                                for s in f.into_inner() {
                                    match s.as_rule() {
                                        Rule::const_expr => width = Some(self.const_expr(s)),
                                        Rule::bitfield_type => {
                                            if let TypeSpec::Prim(p, _) =
                                                self.type_of(s.into_inner().next().expect("type"))
                                            {
                                                dest = Some(p);
                                            }
                                        }
                                        _ => {}
                                    }
                                }
                            }
                            Rule::identifier => names.push(self.ident(f)),
                            _ => {}
                        }
                    }
                    fields.push(Bitfield {
                        annotations,
                        width: width.expect("bitfield width"),
                        dest,
                        names,
                        loc,
                    });
                }
                _ => {}
            }
        }
        BitsetDef { name, base, fields }
    }

    fn typedef(&mut self, p: P) -> Typedef {
        let mut target = None;
        let mut declarators = Vec::new();
        let mut annotations = Vec::new();
        for c in p.into_inner() {
            match c.as_rule() {
                Rule::annotation_appl => annotations.push(self.annotation(c)),
                Rule::type_spec => target = Some(TypedefTarget::Spec(self.type_spec(c))),
                Rule::constr_type => {
                    let inner = c.into_inner().next().expect("constructed type");
                    let loc = self.loc(&inner);
                    let doc = self.doc_before(inner.as_span().start());
                    let kind = self.def_kind(inner);
                    let def = Definition {
                        annotations: std::mem::take(&mut annotations),
                        kind,
                        doc,
                        loc,
                    };
                    target = Some(TypedefTarget::Constructed(Box::new(def)));
                }
                Rule::declarators => {
                    declarators = c.into_inner().map(|d| self.declarator(d)).collect()
                }
                _ => {}
            }
        }
        Typedef {
            target: target.expect("typedef target"),
            declarators,
        }
    }

    fn const_dcl(&mut self, p: P) -> ConstDef {
        let mut it = p.into_inner().skip(1);
        let ty_pair = it.next().expect("const type");
        let ty = self.const_type(ty_pair);
        let name = self.ident(it.next().expect("const name"));
        let value = self.const_expr(it.next().expect("const value"));
        ConstDef { ty, name, value }
    }

    fn const_type(&mut self, p: P) -> TypeSpec {
        let loc = self.loc(&p);
        let inner = p.into_inner().next().expect("const type");
        match inner.as_rule() {
            Rule::fixed_pt_const_type => TypeSpec::Fixed {
                digits: None,
                scale: None,
                loc,
            },
            _ => self.type_of(inner),
        }
    }

    fn annotation_dcl(&mut self, p: P) -> AnnotationDef {
        let mut it = p.into_inner().skip(1);
        let name = self.ident(it.next().expect("annotation name"));
        let mut members = Vec::new();
        let mut inner = Vec::new();
        for b in it {
            let c = b.into_inner().next().expect("annotation body");
            let loc = self.loc(&c);
            match c.as_rule() {
                Rule::annotation_member => {
                    let mut m = c.into_inner();
                    let ty = self.const_type(m.next().expect("type"));
                    let name = self.ident(m.next().expect("name"));
                    let default = m
                        .find(|x| x.as_rule() == Rule::const_expr)
                        .map(|e| self.const_expr(e));
                    members.push(AnnotationMember { ty, name, default });
                }
                _ => {
                    let kind = self.def_kind(c);
                    inner.push(Definition {
                        annotations: vec![],
                        kind,
                        doc: vec![],
                        loc,
                    });
                }
            }
        }
        AnnotationDef {
            name,
            members,
            inner,
        }
    }

    fn type_spec(&mut self, p: P) -> TypeSpec {
        let inner = p.into_inner().next().expect("type");
        self.type_of(inner)
    }

    /// Any of the type rules (base types, template types, scoped names).
    fn type_of(&mut self, p: P) -> TypeSpec {
        let loc = self.loc(&p);
        match p.as_rule() {
            Rule::type_spec => self.type_spec(p),
            Rule::base_type | Rule::template_type | Rule::floating_type | Rule::integer_type => {
                let inner = p.into_inner().next().expect("type");
                self.type_of(inner)
            }
            Rule::scoped_name => TypeSpec::Named(self.scoped_name(p)),
            Rule::sequence_type => {
                let mut it = p
                    .into_inner()
                    .skip(1)
                    .filter(|x| x.as_rule() != Rule::annotation_appl);
                let elem = Box::new(self.type_spec(it.next().expect("element type")));
                let bound = it.next().map(|b| self.const_expr(b));
                TypeSpec::Sequence { elem, bound, loc }
            }
            Rule::string_type | Rule::wstring_type => {
                let wide = p.as_rule() == Rule::wstring_type;
                let bound = p.into_inner().nth(1).map(|b| self.const_expr(b));
                TypeSpec::String { wide, bound, loc }
            }
            Rule::map_type => {
                let mut it = p
                    .into_inner()
                    .skip(1)
                    .filter(|x| x.as_rule() != Rule::annotation_appl);
                let key = Box::new(self.type_spec(it.next().expect("key type")));
                let value = Box::new(self.type_spec(it.next().expect("value type")));
                let bound = it.next().map(|b| self.const_expr(b));
                TypeSpec::Map {
                    key,
                    value,
                    bound,
                    loc,
                }
            }
            Rule::fixed_pt_type => {
                let mut it = p.into_inner().skip(1);
                let digits = it.next().map(|b| self.const_expr(b));
                let scale = it.next().map(|b| self.const_expr(b));
                TypeSpec::Fixed { digits, scale, loc }
            }
            r => {
                let prim = match r {
                    Rule::long_double => Prim::F128,
                    Rule::double_type => Prim::F64,
                    Rule::float_type => Prim::F32,
                    Rule::ulonglong | Rule::uint64 => Prim::U64,
                    Rule::ulong | Rule::uint32 => Prim::U32,
                    Rule::ushort | Rule::uint16 => Prim::U16,
                    Rule::longlong | Rule::int64 => Prim::I64,
                    Rule::long_type | Rule::int32 => Prim::I32,
                    Rule::short_type | Rule::int16 => Prim::I16,
                    Rule::int8 => Prim::I8,
                    Rule::uint8 => Prim::U8,
                    Rule::char_type => Prim::Char,
                    Rule::wchar_type => Prim::WChar,
                    Rule::boolean_type => Prim::Bool,
                    Rule::octet_type => Prim::Octet,
                    Rule::any_type => Prim::Any,
                    Rule::object_type => Prim::Object,
                    r => unreachable!("unexpected type rule {r:?}"),
                };
                TypeSpec::Prim(prim, loc)
            }
        }
    }

    pub(crate) fn const_expr(&mut self, p: P) -> ConstExpr {
        let loc = self.loc(&p);
        match p.as_rule() {
            Rule::const_expr
            | Rule::xor_expr
            | Rule::and_expr
            | Rule::shift_expr
            | Rule::add_expr
            | Rule::mult_expr
            | Rule::tmpl_expr
            | Rule::tmpl_xor
            | Rule::tmpl_and
            | Rule::tmpl_shift => {
                let mut it = p.into_inner();
                let mut lhs = self.const_expr(it.next().expect("operand"));
                while let Some(op) = it.next() {
                    let rhs = self.const_expr(it.next().expect("operand"));
                    let op = match op.as_str() {
                        "|" => BinOp::Or,
                        "^" => BinOp::Xor,
                        "&" => BinOp::And,
                        "<<" => BinOp::Shl,
                        ">>" => BinOp::Shr,
                        "+" => BinOp::Add,
                        "-" => BinOp::Sub,
                        "*" => BinOp::Mul,
                        "/" => BinOp::Div,
                        _ => BinOp::Mod,
                    };
                    let l = Loc {
                        file: lhs.loc.file,
                        start: lhs.loc.start,
                        end: if rhs.loc.file == lhs.loc.file {
                            rhs.loc.end
                        } else {
                            lhs.loc.end
                        },
                    };
                    lhs = ConstExpr {
                        kind: ExprKind::Binary(op, Box::new(lhs), Box::new(rhs)),
                        loc: l,
                    };
                }
                lhs
            }
            Rule::unary_expr => {
                let mut it = p.into_inner();
                let first = it.next().expect("operand");
                if first.as_rule() == Rule::unary_op {
                    let op = match first.as_str() {
                        "-" => UnaryOp::Neg,
                        "+" => UnaryOp::Plus,
                        _ => UnaryOp::Not,
                    };
                    let e = self.const_expr(it.next().expect("operand"));
                    ConstExpr {
                        kind: ExprKind::Unary(op, Box::new(e)),
                        loc,
                    }
                } else {
                    self.const_expr(first)
                }
            }
            Rule::primary_expr => {
                let inner = p.into_inner().next().expect("primary");
                self.const_expr(inner)
            }
            Rule::scoped_name => ConstExpr {
                kind: ExprKind::Name(self.scoped_name(p)),
                loc,
            },
            Rule::literal => {
                let inner = p.into_inner().next().expect("literal");
                self.literal(inner)
            }
            r => unreachable!("unexpected expression rule {r:?}"),
        }
    }

    fn literal(&mut self, p: P) -> ConstExpr {
        let loc = self.loc(&p);
        let s = p.as_str();
        let lit = match p.as_rule() {
            Rule::int_lit => match parse_int(s) {
                Ok(v) => Literal::Int(v),
                Err(e) => {
                    self.err(Code::BadLiteral, loc, e, "this literal");
                    Literal::Int(0)
                }
            },
            Rule::float_lit => Literal::Float(s.parse().unwrap_or(f64::INFINITY)),
            Rule::fixed_lit => Literal::Fixed(s[..s.len() - 1].to_string()),
            Rule::bool_lit => Literal::Bool(s.eq_ignore_ascii_case("TRUE")),
            Rule::char_lit | Rule::wchar_lit => {
                let wide = p.as_rule() == Rule::wchar_lit;
                let body = &s[if wide { 2 } else { 1 }..s.len() - 1];
                let c = match unescape(body) {
                    Ok(u) if u.chars().count() == 1 => u.chars().next().unwrap_or('\0'),
                    Ok(_) => {
                        self.err(
                            Code::BadLiteral,
                            loc,
                            "character literal must hold exactly one character",
                            "here",
                        );
                        '\0'
                    }
                    Err(e) => {
                        self.err(Code::BadLiteral, loc, e, "in this literal");
                        '\0'
                    }
                };
                if wide {
                    Literal::WChar(c)
                } else {
                    if c as u32 > 0xFF {
                        self.err(
                            Code::BadLiteral,
                            loc,
                            "`char` literal out of range (max \\xFF); use a wide literal `L'…'`",
                            "here",
                        );
                    }
                    Literal::Char(c)
                }
            }
            Rule::string_lits | Rule::wstring_lits => {
                let wide = p.as_rule() == Rule::wstring_lits;
                let mut out = String::new();
                for part in p.into_inner() {
                    let t = part.as_str();
                    let body = &t[if wide { 2 } else { 1 }..t.len() - 1];
                    match unescape(body) {
                        Ok(u) => out.push_str(&u),
                        Err(e) => {
                            let l = self.loc(&part);
                            self.err(Code::BadLiteral, l, e, "in this string");
                        }
                    }
                }
                if !wide && out.contains('\0') {
                    self.err(
                        Code::BadLiteral,
                        loc,
                        "string literal contains a NUL character",
                        "here",
                    );
                }
                if wide {
                    Literal::WStr(out)
                } else {
                    Literal::Str(out)
                }
            }
            r => unreachable!("unexpected literal rule {r:?}"),
        };
        ConstExpr {
            kind: ExprKind::Literal(lit),
            loc,
        }
    }
}

fn trim_blank(mut v: Vec<String>) -> Vec<String> {
    while v.first().is_some_and(|l| l.is_empty()) {
        v.remove(0);
    }
    while v.last().is_some_and(|l| l.is_empty()) {
        v.pop();
    }
    v
}
