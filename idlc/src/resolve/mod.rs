//! Name resolution and lowering of the AST to the [`crate::model`]. One pass in declaration order, as IDL
//! requires declaration before use (forward declarations excepted).
mod annotations;
mod consts;
mod scope;

use crate::ast::{self, DefKind, Definition, ForwardKind, Prim, ScopedName, TypeSpec};
use crate::diag::{suggest, Code, Diagnostic, Diagnostics};
use crate::model::*;
use crate::source::Loc;
use annotations::Place;
use scope::{Lookup, Scopes, Sym};
use std::collections::HashSet;

/// What resolution needs besides the syntax trees.
#[derive(Clone, Debug)]
pub struct Options {
    /// Extensibility of types without an annotation.
    pub default_extensibility: Extensibility,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            default_extensibility: Extensibility::Appendable,
        }
    }
}

pub(crate) struct Resolver<'a> {
    pub model: Model,
    pub diags: &'a mut Diagnostics,
    opts: Options,
    scopes: Scopes,
    cur: Vec<String>,
    user_annotations: HashSet<String>,
    default_nested: Vec<bool>,
    /// Forward declarations and where they were made.
    forwards: Vec<(DeclId, Loc)>,
}

/// Resolves one or more specifications (e.g. several files of one build) into a single model.
pub fn resolve<'s>(
    specs: impl IntoIterator<Item = &'s ast::Spec>,
    opts: &Options,
    diags: &mut Diagnostics,
) -> Model {
    let mut r = Resolver {
        model: Model::default(),
        diags,
        opts: opts.clone(),
        scopes: Scopes::default(),
        cur: vec![],
        user_annotations: HashSet::new(),
        default_nested: vec![false],
        forwards: vec![],
    };
    for s in specs {
        r.definitions(&s.defs);
    }
    for (id, loc) in std::mem::take(&mut r.forwards) {
        if let DeclKind::Forward { union } = r.model.decls[id].kind {
            let d = &r.model.decls[id];
            let what = if union { "union" } else { "struct" };
            let msg = format!("{what} `{}` is declared but never defined", d.scoped_name());
            r.diags.push(
                Diagnostic::error(Code::IncompleteForward, msg)
                    .at(loc, "forward declaration")
                    .help(format!(
                        "define `{what} {} {{ ... }};` in the same scope",
                        d.name
                    )),
            );
        }
    }
    r.model
}

impl<'a> Resolver<'a> {
    fn scope_key(&self) -> String {
        scope::key(&self.cur)
    }

    fn definitions(&mut self, defs: &[Definition]) {
        for d in defs {
            self.definition(d);
        }
    }

    /// Declares `name` in the current scope; reports collisions.
    fn declare(&mut self, name: &ast::Ident, sym: Sym) -> bool {
        let key = self.scope_key();
        match self.scopes.insert(&key, &name.name, sym, name.loc) {
            Ok(()) => true,
            Err(prev) => {
                let (code, msg) = if prev.name == name.name {
                    (
                        Code::Duplicate,
                        format!("`{}` is declared twice in this scope", name.name),
                    )
                } else {
                    (
                        Code::CaseCollision,
                        format!(
                            "`{}` collides with `{}`: IDL names must differ by more than case",
                            name.name, prev.name
                        ),
                    )
                };
                self.diags.push(
                    Diagnostic::error(code, msg)
                        .at(name.loc, "redeclared here")
                        .also(prev.loc, "first declared here"),
                );
                false
            }
        }
    }

    fn new_decl(&mut self, name: &ast::Ident, kind: DeclKind, doc: &[String], loc: Loc) -> DeclId {
        self.model.decls.push(Decl {
            scope: self.cur.clone(),
            name: name.name.clone(),
            kind,
            doc: doc.to_vec(),
            verbatim: vec![],
            loc,
        });
        let id = self.model.decls.len() - 1;
        let cur = self.cur.clone();
        self.model.root.module_mut(&cur).decls.push(id);
        id
    }

    /// Declares a new type, or completes a forward declaration of it.
    fn type_decl(
        &mut self,
        name: &ast::Ident,
        doc: &[String],
        loc: Loc,
        forward_kind: Option<ForwardKind>,
    ) -> Option<DeclId> {
        let key = self.scope_key();
        if let Some(e) = self.scopes.get(&key, &name.name).cloned() {
            if let Sym::Decl(id) = e.sym {
                if let DeclKind::Forward { union } = self.model.decls[id].kind {
                    let kind_ok = matches!(
                        (forward_kind, union),
                        (Some(ForwardKind::Union), true) | (Some(ForwardKind::Struct), false)
                    );
                    if kind_ok && e.name == name.name {
                        self.model.decls[id].doc = doc.to_vec();
                        self.model.decls[id].loc = loc;
                        return Some(id);
                    }
                }
            }
        }
        let id = self.new_decl(name, DeclKind::Forward { union: false }, doc, loc);
        if !self.declare(name, Sym::Decl(id)) {
            return None;
        }
        Some(id)
    }

    fn nested_default(&self) -> bool {
        *self.default_nested.last().unwrap_or(&false)
    }

    fn definition(&mut self, d: &Definition) {
        match &d.kind {
            DefKind::Module { name, defs } => {
                let anns = self.annotations(&d.annotations, Place::Module);
                let key = self.scope_key();
                match self.scopes.get(&key, &name.name).cloned() {
                    Some(e) if e.sym == Sym::Module && e.name == name.name => {}
                    _ => {
                        self.declare(name, Sym::Module);
                    }
                }
                let nested = anns.default_nested.unwrap_or(self.nested_default());
                self.default_nested.push(nested);
                self.cur.push(name.name.clone());
                self.model.root.module_mut(&self.cur.clone());
                self.definitions(defs);
                self.cur.pop();
                self.default_nested.pop();
            }
            DefKind::Forward(kind, name) => {
                let key = self.scope_key();
                if let Some(e) = self.scopes.get(&key, &name.name) {
                    if matches!(e.sym, Sym::Decl(_)) && e.name == name.name {
                        return; // forward declaration after the definition, or repeated: harmless
                    }
                }
                let id = self.new_decl(
                    name,
                    DeclKind::Forward {
                        union: *kind == ForwardKind::Union,
                    },
                    &d.doc,
                    d.loc,
                );
                if self.declare(name, Sym::Decl(id)) {
                    self.forwards.push((id, name.loc));
                }
            }
            DefKind::Struct(s) => self.struct_def(s, d),
            DefKind::Union(u) => self.union_def(u, d),
            DefKind::Enum(e) => self.enum_def(e, d),
            DefKind::Bitmask(b) => self.bitmask_def(b, d),
            DefKind::Bitset(b) => self.bitset_def(b, d),
            DefKind::Typedef(t) => self.typedef(t, d),
            DefKind::Const(c) => self.const_def(c, d),
            DefKind::Annotation(a) => {
                self.user_annotations
                    .insert(a.name.name.to_ascii_lowercase());
                if BUILTIN_NAMES.contains(&a.name.name.to_ascii_lowercase().as_str()) {
                    return; // re-declaring a built-in (common in vendor IDL) changes nothing
                }
                self.declare(&a.name, Sym::Annotation);
            }
            DefKind::Unsupported { what, name } => {
                self.declare(name, Sym::Annotation);
                self.diags.push(
                    Diagnostic::warning(
                        Code::NotEmitted,
                        format!("{what} `{}` is parsed but no Rust is emitted for it", name.name),
                    )
                    .at(name.loc, format!("{what} skipped"))
                    .help("idlc generates data types only; DDS-RPC and CORBA constructs have no Rust mapping"),
                );
            }
            DefKind::Keylist { ty, keys } => self.keylist(ty, keys),
        }
    }

    // ---- names ---------------------------------------------------------------------------------------------

    /// Looks a name up from the current scope, reporting failures (with suggestions).
    pub(crate) fn resolve_name(&mut self, n: &ScopedName, what: &str) -> Option<Sym> {
        let decls = &self.model.decls;
        let enum_members = |d: DeclId, part: &str| -> Option<usize> {
            match &decls[d].kind {
                DeclKind::Enum(e) => e.enumerators.iter().position(|x| x.name == part),
                _ => None,
            }
        };
        match self.scopes.lookup(n, &self.cur, &enum_members) {
            Lookup::Found(sym) => Some(sym),
            Lookup::CaseMismatch { found, sym, loc } => {
                self.diags.push(
                    Diagnostic::error(
                        Code::CaseCollision,
                        format!("`{}` differs only in case from `{found}`", n.text()),
                    )
                    .at(n.loc, "wrong case")
                    .also(loc, "declared here")
                    .help(format!("did you mean `{found}`?")),
                );
                Some(sym)
            }
            Lookup::Shadowed { near, far } => {
                self.diags.push(
                    Diagnostic::error(
                        Code::Ambiguous,
                        format!(
                            "`{}` is ambiguous: `{near}` hides the outer declaration",
                            n.text()
                        ),
                    )
                    .at(
                        n.loc,
                        format!("resolves through `{near}`, which has no such member"),
                    )
                    .help(format!("write the absolute name `{far}`")),
                );
                None
            }
            Lookup::NotFound { missing, scope } => {
                let candidates: Vec<String> =
                    if n.parts.len() == 1 || scope.is_empty() && n.absolute {
                        self.scopes.visible_names(&self.cur)
                    } else {
                        self.scopes.names_in(&scope)
                    };
                let where_ = if scope.is_empty() || n.parts.len() == 1 {
                    String::new()
                } else {
                    format!(" in `{scope}`")
                };
                let mut diag = Diagnostic::error(
                    Code::Unresolved,
                    format!("cannot find {what} `{missing}`{where_}"),
                )
                .at(n.loc, "not found");
                if let Some(s) = suggest(&missing, candidates.iter().map(String::as_str)) {
                    diag = diag.help(format!("did you mean `{s}`?"));
                } else if let Some(later) = self.find_anywhere(&missing) {
                    diag = diag.help(format!(
                        "a declaration `{later}` exists elsewhere; qualify the name or check the include"
                    ));
                }
                self.diags.push(diag);
                None
            }
        }
    }

    fn find_anywhere(&self, name: &str) -> Option<String> {
        self.model
            .decls
            .iter()
            .find(|d| d.name == name)
            .map(|d| d.scoped_name())
    }

    pub(crate) fn type_name(&self, t: &Type) -> String {
        match t {
            Type::Prim { prim } => prim.idl_name().to_string(),
            Type::String { wide, bound } => {
                let s = if *wide { "wstring" } else { "string" };
                match bound {
                    Some(b) => format!("{s}<{b}>"),
                    None => s.to_string(),
                }
            }
            Type::Sequence { elem, .. } => format!("sequence<{}>", self.type_name(elem)),
            Type::Map { key, value, .. } => {
                format!("map<{}, {}>", self.type_name(key), self.type_name(value))
            }
            Type::Array { elem, dims } => format!(
                "{}{}",
                self.type_name(elem),
                dims.iter().map(|d| format!("[{d}]")).collect::<String>()
            ),
            Type::Fixed { digits, scale } => format!("fixed<{digits},{scale}>"),
            Type::Named { name, .. } => name.clone(),
            Type::Error => "{error}".into(),
        }
    }

    // ---- types ---------------------------------------------------------------------------------------------

    pub(crate) fn lower_type(&mut self, t: &TypeSpec) -> Type {
        match t {
            TypeSpec::Prim(p, loc) => {
                if matches!(p, Prim::Any | Prim::Object) {
                    self.diags.push(
                        Diagnostic::error(
                            Code::BadMemberType,
                            format!("type `{}` cannot be used in a DDS data type", p.idl_name()),
                        )
                        .at(*loc, "not a data type"),
                    );
                    return Type::Error;
                }
                Type::Prim { prim: *p }
            }
            TypeSpec::String { wide, bound, .. } => {
                let bound = bound
                    .as_ref()
                    .and_then(|b| self.eval_u64(b, "string bound", 1));
                Type::String { wide: *wide, bound }
            }
            TypeSpec::Sequence { elem, bound, .. } => {
                let elem = Box::new(self.lower_type(elem));
                let bound = bound
                    .as_ref()
                    .and_then(|b| self.eval_u64(b, "sequence bound", 1));
                Type::Sequence { elem, bound }
            }
            TypeSpec::Map {
                key, value, bound, ..
            } => {
                let key = Box::new(self.map_key(key));
                let value = Box::new(self.lower_type(value));
                let bound = bound
                    .as_ref()
                    .and_then(|b| self.eval_u64(b, "map bound", 1));
                Type::Map { key, value, bound }
            }
            TypeSpec::Fixed { digits, scale, loc } => {
                // Bare `fixed` only occurs as a constant type; the value carries its own digits.
                let (Some(d), Some(s)) = (digits, scale) else {
                    return Type::Fixed {
                        digits: 0,
                        scale: 0,
                    };
                };
                let dv = self.eval_u64(d, "fixed digits", 1).unwrap_or(1);
                let sv = self.eval_u64(s, "fixed scale", 0).unwrap_or(0);
                if dv > 31 || sv > dv {
                    let msg =
                        format!("fixed<{dv},{sv}>: digits must be 1..=31 and scale at most digits");
                    self.diags.push(
                        Diagnostic::error(Code::BadBound, msg).at(*loc, "invalid fixed-point type"),
                    );
                }
                Type::Fixed {
                    digits: dv as u32,
                    scale: sv as u32,
                }
            }
            TypeSpec::Named(n) => self.named_type(n),
        }
    }

    /// The type a name refers to; an error (and [`Type::Error`]) when it names something else.
    fn named_type(&mut self, n: &ast::ScopedName) -> Type {
        match self.resolve_name(n, "type") {
            Some(Sym::Decl(id)) => match &self.model.decls[id].kind {
                DeclKind::Const(_) => {
                    let msg = format!("`{}` is a constant, not a type", n.text());
                    self.diags.push(
                        Diagnostic::error(Code::NotAType, msg)
                            .at(n.loc, "expected a type")
                            .also(self.model.decls[id].loc, "declared here"),
                    );
                    Type::Error
                }
                _ => Type::Named {
                    decl: id,
                    name: self.model.decls[id].scoped_name(),
                },
            },
            Some(sym) => {
                let what = match sym {
                    Sym::Module => "a module",
                    Sym::Enumerator(..) => "an enumerator",
                    _ => "not a data type",
                };
                self.diags.push(
                    Diagnostic::error(
                        Code::NotAType,
                        format!("`{}` is {what}, not a type", n.text()),
                    )
                    .at(n.loc, "expected a type"),
                );
                Type::Error
            }
            None => Type::Error,
        }
    }

    /// A map's key type: integers and strings; an enum is accepted as a vendor extension (with a warning).
    fn map_key(&mut self, key: &TypeSpec) -> Type {
        let k = self.lower_type(key);
        let kr = self.model.resolve_alias(&k);
        let key_ok = matches!(kr, Type::Prim { prim } if prim.is_integer() || *prim == Prim::Octet)
            || matches!(kr, Type::String { .. } | Type::Error);
        let enum_key = matches!(kr, Type::Named { decl, .. }
            if matches!(self.model.decls[*decl].kind, DeclKind::Enum(_)));
        if enum_key {
            let msg = format!(
                "map key type `{}` is an enum, which IDL 4.2 does not allow",
                self.type_name(&k)
            );
            self.diags.push(
                Diagnostic::warning(Code::Extension, msg)
                    .at(key.loc(), "accepted as a vendor extension")
                    .help("IDL 4.2 map keys are integers or strings"),
            );
        } else if !key_ok {
            let msg = format!("map key type `{}` is not allowed", self.type_name(&k));
            self.diags.push(
                Diagnostic::error(Code::BadMemberType, msg)
                    .at(key.loc(), "map key")
                    .help("map keys must be integers or strings"),
            );
        }
        k
    }

    fn with_dims(&mut self, ty: Type, dims: &[ast::ConstExpr]) -> Type {
        if dims.is_empty() {
            return ty;
        }
        let dims: Vec<u64> = dims
            .iter()
            .map(|e| self.eval_u64(e, "array size", 1).unwrap_or(1))
            .collect();
        if dims
            .iter()
            .try_fold(1u64, |a, d| a.checked_mul(*d))
            .is_none_or(|n| n > 1 << 32)
        {
            let msg = "array has more than 2^32 elements".to_string();
            self.diags
                .push(Diagnostic::error(Code::BadBound, msg).at(Loc::default(), "here"));
        }
        Type::Array {
            elem: Box::new(ty),
            dims,
        }
    }

    fn is_struct(&self, t: &Type) -> bool {
        matches!(self.model.resolve_alias(t), Type::Named { decl, .. } if matches!(self.model.decls[*decl].kind, DeclKind::Struct(_) | DeclKind::Forward { union: false }))
    }

    // ---- declarations -----------------------------------------------------------------------------------------

    fn struct_def(&mut self, s: &ast::StructDef, d: &Definition) {
        let anns = self.annotations(&d.annotations, Place::Struct);
        let Some(id) = self.type_decl(&s.name, &d.doc, d.loc, Some(ForwardKind::Struct)) else {
            return;
        };
        let base = s.base.as_ref().and_then(|b| {
            let t = self.lower_type(&TypeSpec::Named(b.clone()));
            if matches!(t, Type::Error) {
                return None;
            }
            let resolved = self.model.resolve_alias(&t).clone();
            match resolved {
                Type::Named { decl, .. }
                    if matches!(self.model.decls[decl].kind, DeclKind::Struct(_)) && decl != id =>
                {
                    Some(decl)
                }
                _ => {
                    let msg = format!(
                        "`{}` cannot be a base of a struct: it is not a (defined) struct",
                        b.text()
                    );
                    self.diags
                        .push(Diagnostic::error(Code::BadBase, msg).at(b.loc, "not a struct"));
                    None
                }
            }
        });
        let mut fields = Vec::new();
        for m in &s.members {
            fields.extend(self.member(m));
        }
        let nested = anns.nested.unwrap_or(!anns.topic && self.nested_default());
        let extensibility = self.struct_extensibility(s, &anns, base);
        let st = Struct {
            base,
            fields,
            extensibility,
            autoid: anns.autoid.unwrap_or_default(),
            nested,
        };
        self.model.decls[id].kind = DeclKind::Struct(st);
        self.model.decls[id].verbatim = anns.verbatim;
    }

    /// XTypes (§7.2.2.4.4.4.3) requires a derived struct to have its base's extensibility: without an annotation
    /// it inherits it (as Cyclone's idlc does), and a different explicit one is an error.
    fn struct_extensibility(
        &mut self,
        s: &ast::StructDef,
        anns: &annotations::Anns,
        base: Option<DeclId>,
    ) -> Extensibility {
        let base_ext = base.and_then(|b| match &self.model.decls[b].kind {
            DeclKind::Struct(bs) => Some((b, bs.extensibility)),
            _ => None,
        });
        match (anns.extensibility, base_ext) {
            (None, Some((_, be))) => be,
            (None, None) => self.opts.default_extensibility,
            (Some(e), Some((b, be))) if e != be => {
                let bd = &self.model.decls[b];
                let msg = format!(
                    "`{}` is {} but its base `{}` is {}",
                    s.name.name,
                    e.as_str(),
                    bd.scoped_name(),
                    be.as_str()
                );
                let base_loc = s.base.as_ref().map_or(bd.loc, |b| b.loc);
                let d = Diagnostic::error(Code::ExtensibilityMismatch, msg)
                    .at(
                        anns.extensibility_loc.unwrap_or(s.name.loc),
                        format!("{} here", e.as_str()),
                    )
                    .also(base_loc, format!("this base is {}", be.as_str()))
                    .help(format!(
                        "a derived struct must have its base's extensibility: use `@{}` or no annotation",
                        be.as_str()
                    ));
                self.diags.push(d);
                e
            }
            (Some(e), _) => e,
        }
    }

    fn member(&mut self, m: &ast::Member) -> Vec<Field> {
        let anns = self.annotations(&m.annotations, Place::Member);
        let base_ty = self.lower_type(&m.ty);
        let mut out = Vec::new();
        for dcl in &m.declarators {
            let ty = self.with_dims(base_ty.clone(), &dcl.dims);
            let default = anns.default.and_then(|e| self.eval_as(e, &ty));
            let min = anns.min.and_then(|e| self.eval_as(e, &ty));
            let max = anns.max.and_then(|e| self.eval_as(e, &ty));
            if anns.key && anns.optional {
                let mut diag = Diagnostic::error(
                    Code::KeyOptional,
                    format!("key member `{}` cannot be optional", dcl.name.name),
                )
                .at(dcl.name.loc, "declared here");
                if let Some(l) = anns.optional_loc {
                    diag = diag.also(l, "made optional here");
                }
                self.diags
                    .push(diag.help("a key must always be present: remove `@optional` or `@key`"));
            }
            out.push(Field {
                name: dcl.name.name.clone(),
                ty,
                key: anns.key,
                optional: anns.optional,
                external: anns.external,
                must_understand: anns.must_understand,
                non_serialized: anns.non_serialized,
                id: anns
                    .id
                    .filter(|_| m.declarators.len() == 1 || out.is_empty()),
                hashid: anns.hashid.clone(),
                default,
                min,
                max,
                unit: anns.unit.clone(),
                doc: m.doc.clone(),
                loc: dcl.name.loc,
            });
        }
        out
    }

    fn union_def(&mut self, u: &ast::UnionDef, d: &Definition) {
        let anns = self.annotations(&d.annotations, Place::Union);
        let sanns = self.annotations(&u.switch_annotations, Place::Discriminator);
        let disc = self.lower_type(&u.switch);
        let resolved = self.model.resolve_alias(&disc).clone();
        let disc_ok = match &resolved {
            Type::Prim { prim } => {
                prim.is_integer()
                    || matches!(prim, Prim::Char | Prim::WChar | Prim::Bool | Prim::Octet)
            }
            Type::Named { decl, .. } => matches!(self.model.decls[*decl].kind, DeclKind::Enum(_)),
            Type::Error => true,
            _ => false,
        };
        if !disc_ok {
            let msg = format!(
                "`{}` cannot be a union discriminator",
                self.type_name(&disc)
            );
            self.diags.push(
                Diagnostic::error(Code::BadDiscriminator, msg)
                    .at(u.switch.loc(), "invalid discriminator type")
                    .help("use an integer type, char, wchar, boolean, octet or an enum"),
            );
        }
        let Some(id) = self.type_decl(&u.name, &d.doc, d.loc, Some(ForwardKind::Union)) else {
            return;
        };
        let mut cases = Vec::new();
        for c in &u.cases {
            let canns = self.annotations(&c.annotations, Place::UnionMember);
            let base = self.lower_type(&c.ty);
            let ty = self.with_dims(base, &c.declarator.dims);
            let mut labels = Vec::new();
            let mut label_locs = Vec::new();
            let mut is_default = false;
            let mut default_loc = None;
            for l in &c.labels {
                match l {
                    ast::CaseLabel::Default(loc) => {
                        if is_default {
                            self.diags.push(
                                Diagnostic::error(
                                    Code::SeveralDefaults,
                                    "union has more than one `default` label",
                                )
                                .at(*loc, "second default"),
                            );
                        }
                        is_default = true;
                        default_loc = Some(*loc);
                    }
                    ast::CaseLabel::Value(e) => {
                        if !disc_ok {
                            continue;
                        }
                        if let Some(v) = self.label_value(e, &disc, &resolved) {
                            labels.push(v);
                            label_locs.push(e.loc);
                        }
                    }
                }
            }
            cases.push(UnionCase {
                name: c.declarator.name.name.clone(),
                labels,
                is_default,
                ty,
                external: canns.external,
                id: canns.id,
                doc: c.doc.clone(),
                loc: c.declarator.name.loc,
                label_locs,
                default_loc,
            });
        }
        let un = Union {
            discriminator: if disc_ok { disc } else { Type::Error },
            disc_key: sanns.key,
            cases,
            extensibility: anns
                .extensibility
                .unwrap_or(self.opts.default_extensibility),
            nested: anns.nested.unwrap_or(!anns.topic && self.nested_default()),
        };
        self.model.decls[id].kind = DeclKind::Union(un);
        self.model.decls[id].verbatim = anns.verbatim;
    }

    fn label_value(&mut self, e: &ast::ConstExpr, disc: &Type, resolved: &Type) -> Option<Value> {
        if let Type::Named { decl, .. } = resolved {
            let v = self.eval(e, None)?;
            return match v {
                Value::Enum(d, i) if d == *decl => Some(Value::Enum(d, i)),
                Value::Enum(d, i) => {
                    let other = self.model.decls[d].scoped_name();
                    let en = match &self.model.decls[d].kind {
                        DeclKind::Enum(x) => x.enumerators[i].name.clone(),
                        _ => String::new(),
                    };
                    let want = self.model.decls[*decl].scoped_name();
                    let mut diag = Diagnostic::error(
                        Code::LabelType,
                        format!("case label `{en}` is an enumerator of `{other}`, but the discriminator is `{want}`"),
                    )
                    .at(e.loc, format!("expected an enumerator of `{want}`"));
                    let names: Vec<String> = match &self.model.decls[*decl].kind {
                        DeclKind::Enum(x) => x.enumerators.iter().map(|e| e.name.clone()).collect(),
                        _ => vec![],
                    };
                    if let Some(s) = suggest(&en, names.iter().map(String::as_str)) {
                        diag = diag.help(format!("did you mean `{s}`?"));
                    }
                    self.diags.push(diag);
                    None
                }
                other => {
                    let want = self.model.decls[*decl].scoped_name();
                    let msg = format!(
                        "case label must be an enumerator of `{want}`, found {}",
                        consts::describe(&other)
                    );
                    self.diags.push(
                        Diagnostic::error(Code::LabelType, msg).at(e.loc, "wrong label type"),
                    );
                    None
                }
            };
        }
        let v = self.eval(e, None)?;
        let ok = match (resolved, &v) {
            (Type::Prim { prim: Prim::Bool }, Value::Bool(_)) => true,
            (Type::Prim { prim: Prim::Char }, Value::Char(_)) => true,
            (Type::Prim { prim: Prim::Char }, Value::Int(i)) if (0..=255).contains(i) => {
                let msg =
                    format!("integer case label {i} on a `char` discriminator is not IDL 4.2");
                self.diags.push(
                    Diagnostic::warning(Code::Extension, msg)
                        .at(e.loc, format!("taken as {:?}", char::from(*i as u8)))
                        .help("write a character literal"),
                );
                return Some(Value::Char(char::from(*i as u8)));
            }
            (Type::Prim { prim: Prim::WChar }, Value::Char(_) | Value::WChar(_)) => true,
            (Type::Prim { prim }, Value::Int(i)) => match prim.int_range() {
                Some((lo, hi)) => {
                    if *i < lo || *i > hi {
                        let msg = format!(
                            "case label {i} is out of range for discriminator type `{}`",
                            self.type_name(disc)
                        );
                        self.diags.push(
                            Diagnostic::error(Code::LabelType, msg).at(e.loc, "out of range"),
                        );
                        return None;
                    }
                    true
                }
                None => false,
            },
            _ => false,
        };
        if !ok {
            let msg = format!(
                "case label {} does not match discriminator type `{}`",
                consts::describe(&v),
                self.type_name(disc)
            );
            self.diags
                .push(Diagnostic::error(Code::LabelType, msg).at(e.loc, "wrong label type"));
            return None;
        }
        Some(match (resolved, v) {
            (Type::Prim { prim: Prim::WChar }, Value::Char(c)) => Value::WChar(c),
            (_, v) => v,
        })
    }

    fn enum_def(&mut self, e: &ast::EnumDef, d: &Definition) {
        let anns = self.annotations(&d.annotations, Place::Enum);
        let Some(id) = self.type_decl(&e.name, &d.doc, d.loc, None) else {
            return;
        };
        let bit_bound = anns
            .bit_bound
            .and_then(|b| self.eval_u64(b, "@bit_bound", 1))
            .map(|b| b as u32);
        if let Some(b) = bit_bound {
            if b > 32 {
                let msg = format!("@bit_bound({b}) on an enum must be 1..=32");
                self.diags
                    .push(Diagnostic::error(Code::BitBound, msg).at(d.loc, "in this enum"));
            }
        }
        let mut enumerators: Vec<Enumerator> = Vec::new();
        let mut next: i64 = 0;
        let mut default_index = 0;
        self.model.decls[id].kind = DeclKind::Enum(Enum {
            enumerators: vec![],
            bit_bound,
            default_index: 0,
            extensibility: anns.extensibility.unwrap_or(Extensibility::Final),
        });
        let int32 = Type::Prim { prim: Prim::I32 };
        for (i, en) in e.enumerators.iter().enumerate() {
            let ea = self.annotations(&en.annotations, Place::Enumerator);
            if let Some(v) = &en.value {
                self.c_style_value(en, v, ea.value.is_some());
            }
            let value = match ea
                .value
                .or(en.value.as_ref())
                .and_then(|v| self.eval_as(v, &int32))
            {
                Some(Value::Int(v)) => v as i64,
                _ => next,
            };
            // XTypes encodes an enum with @bit_bound(b) as a signed integer of that width.
            if let Some(b) = bit_bound.filter(|b| (1..32).contains(b)) {
                if value < -(1i64 << (b - 1)) || value >= 1i64 << (b - 1) {
                    let msg = format!("enumerator value {value} does not fit in @bit_bound({b})");
                    self.diags
                        .push(Diagnostic::error(Code::BitBound, msg).at(en.name.loc, "too large"));
                }
            }
            if ea.default_literal {
                default_index = i;
            }
            next = value.wrapping_add(1);
            enumerators.push(Enumerator {
                name: en.name.name.clone(),
                value,
                doc: en.doc.clone(),
                loc: en.name.loc,
            });
            // Enumerators live in the enum's enclosing scope (IDL 4.2 §7.4.1.4.4.4.3).
            if let DeclKind::Enum(x) = &mut self.model.decls[id].kind {
                x.enumerators = enumerators.clone();
            }
            self.declare(&en.name, Sym::Enumerator(id, i));
        }
        if let DeclKind::Enum(x) = &mut self.model.decls[id].kind {
            x.default_index = default_index;
        }
        self.model.decls[id].verbatim = anns.verbatim;
    }

    /// Reports a C-style `NAME = value` enumerator: accepted with a warning, an error next to `@value`.
    fn c_style_value(&mut self, en: &ast::Enumerator, v: &ast::ConstExpr, annotated: bool) {
        let d = if annotated {
            Diagnostic::error(
                Code::Extension,
                format!(
                    "enumerator `{}` has both `@value` and `= value`",
                    en.name.name
                ),
            )
            .at(v.loc, "second value")
            .help("keep only `@value(...)`")
        } else {
            Diagnostic::warning(
                Code::Extension,
                format!(
                    "C-style enumerator value `{} = ...` is not IDL 4.2",
                    en.name.name
                ),
            )
            .at(v.loc, "accepted as `@value`")
            .help("write `@value(...)` before the enumerator instead")
        };
        self.diags.push(d);
    }

    fn bitmask_def(&mut self, b: &ast::BitmaskDef, d: &Definition) {
        let anns = self.annotations(&d.annotations, Place::Bitmask);
        let Some(id) = self.type_decl(&b.name, &d.doc, d.loc, None) else {
            return;
        };
        let bit_bound = anns
            .bit_bound
            .and_then(|e| self.eval_u64(e, "@bit_bound", 1))
            .unwrap_or(32) as u32;
        if !(1..=64).contains(&bit_bound) {
            let msg = format!("@bit_bound({bit_bound}) on a bitmask must be 1..=64");
            self.diags
                .push(Diagnostic::error(Code::BitBound, msg).at(d.loc, "in this bitmask"));
        }
        let mut flags = Vec::new();
        let mut next = 0u64;
        for v in &b.values {
            let va = self.annotations(&v.annotations, Place::BitFlag);
            let pos = va
                .position
                .and_then(|e| self.eval_u64(e, "@position", 0))
                .unwrap_or(next);
            if pos >= bit_bound as u64 {
                let msg = format!(
                    "bit position {pos} of `{}` is outside @bit_bound({bit_bound})",
                    v.name.name
                );
                self.diags.push(
                    Diagnostic::error(Code::BitBound, msg).at(v.name.loc, "position too large"),
                );
            }
            next = pos + 1;
            flags.push(Flag {
                name: v.name.name.clone(),
                position: pos.min(63) as u32,
                doc: v.doc.clone(),
                loc: v.name.loc,
            });
        }
        self.model.decls[id].kind = DeclKind::Bitmask(Bitmask { flags, bit_bound });
        self.model.decls[id].verbatim = anns.verbatim;
    }

    fn bitset_def(&mut self, b: &ast::BitsetDef, d: &Definition) {
        let anns = self.annotations(&d.annotations, Place::Bitset);
        let Some(id) = self.type_decl(&b.name, &d.doc, d.loc, None) else {
            return;
        };
        let mut fields = Vec::new();
        let mut offset = 0u32;
        let mut base_id = None;
        if let Some(bn) = &b.base {
            let t = self.lower_type(&TypeSpec::Named(bn.clone()));
            match self.model.resolve_alias(&t).clone() {
                Type::Named { decl, .. } => match &self.model.decls[decl].kind {
                    DeclKind::Bitset(bs) => {
                        fields = bs.fields.clone();
                        offset = bs.bits;
                        base_id = Some(decl);
                    }
                    _ => {
                        let msg = format!("`{}` is not a bitset", bn.text());
                        self.diags
                            .push(Diagnostic::error(Code::BadBase, msg).at(bn.loc, "not a bitset"));
                    }
                },
                Type::Error => {}
                _ => {
                    let msg = format!("`{}` is not a bitset", bn.text());
                    self.diags
                        .push(Diagnostic::error(Code::BadBase, msg).at(bn.loc, "not a bitset"));
                }
            }
        }
        for f in &b.fields {
            let _ = self.annotations(&f.annotations, Place::Bitfield);
            let width = self.eval_u64(&f.width, "bitfield width", 1).unwrap_or(1);
            if width > 64 {
                self.diags.push(
                    Diagnostic::error(Code::BitBound, format!("bitfield width {width} exceeds 64"))
                        .at(f.width.loc, "too wide"),
                );
                continue;
            }
            let width = width as u32;
            let dest = f.dest.unwrap_or(match width {
                1 => Prim::Bool,
                2..=8 => Prim::Octet,
                9..=16 => Prim::U16,
                17..=32 => Prim::U32,
                _ => Prim::U64,
            });
            let cap = match dest {
                Prim::Bool => 1,
                Prim::Octet | Prim::I8 | Prim::U8 => 8,
                Prim::I16 | Prim::U16 => 16,
                Prim::I32 | Prim::U32 => 32,
                _ => 64,
            };
            if width > cap {
                let msg = format!(
                    "bitfield<{width}> does not fit in its type `{}`",
                    dest.idl_name()
                );
                self.diags.push(
                    Diagnostic::error(Code::BitBound, msg).at(f.loc, "too wide for the type"),
                );
            }
            let names: Vec<Option<String>> = if f.names.is_empty() {
                vec![None]
            } else {
                f.names.iter().map(|n| Some(n.name.clone())).collect()
            };
            for name in names {
                fields.push(BitField {
                    name,
                    offset,
                    width,
                    dest,
                    loc: f.loc,
                });
                offset += width;
            }
        }
        if offset > 64 {
            let msg = format!(
                "bitset `{}` holds {offset} bits; at most 64 are allowed",
                b.name.name
            );
            self.diags
                .push(Diagnostic::error(Code::BitBound, msg).at(b.name.loc, "too many bits"));
        }
        self.model.decls[id].kind = DeclKind::Bitset(Bitset {
            base: base_id,
            fields,
            bits: offset,
        });
        self.model.decls[id].verbatim = anns.verbatim;
    }

    fn typedef(&mut self, t: &ast::Typedef, d: &Definition) {
        let anns = self.annotations(&d.annotations, Place::Typedef);
        let base = match &t.target {
            ast::TypedefTarget::Spec(s) => self.lower_type(s),
            ast::TypedefTarget::Constructed(inner) => {
                let before = self.model.decls.len();
                self.definition(inner);
                match self.model.decls.get(before) {
                    Some(_) => Type::Named {
                        decl: before,
                        name: self.model.decls[before].scoped_name(),
                    },
                    None => Type::Error,
                }
            }
        };
        let _ = anns;
        for dcl in &t.declarators {
            let ty = self.with_dims(base.clone(), &dcl.dims);
            let Some(id) = self.type_decl(&dcl.name, &d.doc, d.loc, None) else {
                continue;
            };
            self.model.decls[id].kind = DeclKind::Alias { ty };
        }
    }

    fn const_def(&mut self, c: &ast::ConstDef, d: &Definition) {
        let _ = self.annotations(&d.annotations, Place::Const);
        let ty = self.lower_type(&c.ty);
        let resolved = self.model.resolve_alias(&ty).clone();
        let ok = matches!(
            resolved,
            Type::Prim { .. } | Type::String { .. } | Type::Fixed { .. } | Type::Error
        ) || matches!(&resolved, Type::Named { decl, .. } if matches!(self.model.decls[*decl].kind, DeclKind::Enum(_)));
        if !ok {
            let msg = format!(
                "constants of type `{}` are not allowed",
                self.type_name(&ty)
            );
            self.diags.push(
                Diagnostic::error(Code::ConstType, msg).at(c.ty.loc(), "invalid constant type"),
            );
        }
        let value = if ok {
            self.eval_as(&c.value, &ty)
        } else {
            None
        };
        let Some(id) = self.type_decl(&c.name, &d.doc, d.loc, None) else {
            return;
        };
        match value {
            Some(value) => self.model.decls[id].kind = DeclKind::Const(Const { ty, value }),
            None => {
                // Keep a placeholder so later uses do not cascade into "not found".
                let zero = match resolved {
                    Type::String { .. } => Value::Str(String::new()),
                    Type::Prim { prim: Prim::Bool } => Value::Bool(false),
                    Type::Prim {
                        prim: Prim::F32 | Prim::F64 | Prim::F128,
                    } => Value::Float(0.0),
                    _ => Value::Int(0),
                };
                self.model.decls[id].kind = DeclKind::Const(Const {
                    ty: Type::Error,
                    value: zero,
                });
            }
        }
    }

    fn keylist(&mut self, ty: &ScopedName, keys: &[Vec<ast::Ident>]) {
        let Some(sym) = self.resolve_name(ty, "type") else {
            return;
        };
        let Sym::Decl(id) = sym else { return };
        let DeclKind::Struct(st) = &mut self.model.decls[id].kind else {
            let msg = format!(
                "`#pragma keylist` names `{}`, which is not a struct",
                ty.text()
            );
            self.diags
                .push(Diagnostic::error(Code::NotAType, msg).at(ty.loc, "not a struct"));
            return;
        };
        let mut missing = Vec::new();
        for k in keys {
            let first = &k[0];
            match st.fields.iter_mut().find(|f| f.name == first.name) {
                Some(f) => f.key = true,
                None => missing.push(first.clone()),
            }
        }
        let names: Vec<String> = st.fields.iter().map(|f| f.name.clone()).collect();
        for m in missing {
            let mut diag = Diagnostic::error(
                Code::Unresolved,
                format!(
                    "`#pragma keylist`: `{}` has no member `{}`",
                    ty.text(),
                    m.name
                ),
            )
            .at(m.loc, "no such member");
            if let Some(s) = suggest(&m.name, names.iter().map(String::as_str)) {
                diag = diag.help(format!("did you mean `{s}`?"));
            }
            self.diags.push(diag);
        }
    }
}

const BUILTIN_NAMES: &[&str] = &[
    "id",
    "autoid",
    "hashid",
    "key",
    "optional",
    "external",
    "must_understand",
    "extensibility",
    "final",
    "appendable",
    "mutable",
    "value",
    "position",
    "bit_bound",
    "default",
    "default_literal",
    "range",
    "min",
    "max",
    "unit",
    "nested",
    "default_nested",
    "topic",
    "data_representation",
    "try_construct",
    "verbatim",
    "non_serialized",
];

impl Resolver<'_> {
    #[allow(dead_code)]
    fn struct_check(&self, t: &Type) -> bool {
        self.is_struct(t)
    }
}
