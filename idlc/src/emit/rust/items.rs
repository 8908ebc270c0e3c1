//! Structs, unions, enums, typedefs and constants, each written as Rust items.
use super::names::{bare, ident, lit_str, snake, upper_camel};
use super::types::Pos;
use super::writer::Writer;
use super::{Dedup, Emitter};
use crate::ast::Prim;
use crate::model::{AutoId, Const, DeclId, Enum, Field, Struct, Type, Union, Value};

/// One struct field or union variant, ready to write.
struct Member {
    docs: Vec<String>,
    attrs: Vec<String>,
    name: String,
    ty: String,
}

/// A struct's members and the expression that initialises each in `Default::default()`.
struct StructBody {
    fields: Vec<Member>,
    defaults: Vec<(String, String)>,
    /// `Default` cannot be derived (an `@default` value, or an array without `Default`).
    manual_default: bool,
}

impl Emitter<'_> {
    pub(super) fn struct_item(&mut self, id: DeclId, s: &Struct, w: &mut Writer) {
        let mut attrs = self.type_attrs(id);
        attrs.push(s.extensibility.as_str().to_string());
        if s.nested {
            attrs.push("nested".into());
        }
        if s.autoid == AutoId::Hash {
            attrs.push("autoid = \"hash\"".into());
        }
        let body = self.struct_body(s);
        let eq = self.decl_eq_hash(id, &mut vec![]);
        let extra: &[&str] = if body.manual_default {
            &[]
        } else {
            &["Default"]
        };
        let d = &self.model.decls[id];
        let name = &self.names[id];
        self.item_head(id, &d.doc, w);
        w.derive(&self.derives(&["Debug", "Clone", "PartialEq"], eq, extra, true));
        w.attr("dds", &attrs);
        w.open(&format!("pub struct {name}"));
        for f in &body.fields {
            w.docs(&f.docs);
            w.attr("dds", &f.attrs);
            w.field(&format!("pub {}", f.name), &f.ty);
        }
        w.close("");
        if body.manual_default {
            self.default_impl(name, w, |w| {
                w.open("Self");
                for (field, expr) in &body.defaults {
                    w.line(&format!("{field}: {expr},"));
                }
                w.close("");
            });
        }
    }

    /// `impl Default for {name} { fn default() -> Self { <body> } }`.
    fn default_impl(&self, name: &str, w: &mut Writer, body: impl FnOnce(&mut Writer)) {
        w.item();
        w.open(&format!("impl {} for {name}", self.std("Default")));
        w.open("fn default() -> Self");
        body(w);
        w.close("");
        w.close("");
    }

    fn struct_body(&mut self, s: &Struct) -> StructBody {
        let mut used = Dedup::new();
        let mut body = StructBody {
            fields: Vec::new(),
            defaults: Vec::new(),
            manual_default: false,
        };
        if let Some(b) = s.base {
            let name = used.take(if s.fields.iter().any(|f| f.name == "base") {
                "base_".into()
            } else {
                "base".into()
            });
            body.fields.push(Member {
                docs: vec!["Members inherited from the base struct.".into()],
                attrs: vec!["base".into()],
                name: name.clone(),
                ty: self.path_to(b),
            });
            body.defaults
                .push((name, format!("{}::default()", self.std("Default"))));
        }
        for f in &s.fields {
            let name = used.take(ident(&snake(&f.name)));
            let (member, default, manual) = self.field(f, name);
            body.manual_default |= manual;
            body.defaults.push((member.name.clone(), default));
            body.fields.push(member);
        }
        body
    }

    /// A struct field, the expression of its default value, and whether that value needs a written `Default`.
    fn field(&self, f: &Field, name: String) -> (Member, String, bool) {
        let mut a = self.field_attrs(f, &name);
        let mut manual_default = false;
        let mut ty = self.rust_type(&f.ty, Pos::Field);
        let mut dexpr = if self.has_default(&f.ty) {
            format!("{}::default()", self.std("Default"))
        } else {
            self.default_expr(&f.ty)
        };
        if let Some(v) = &f.default {
            let e = self.value_expr(v, &f.ty, false);
            a.push(format!("default = {e}"));
            dexpr = e;
            manual_default = true;
        }
        if f.external {
            ty = format!("{}<{ty}>", self.std("Box"));
            dexpr = format!("{}::new({dexpr})", self.std("Box"));
        }
        if f.optional {
            ty = format!("{}<{ty}>", self.std("Option"));
            dexpr = if f.default.is_some() {
                format!("Some({dexpr})")
            } else {
                "None".into()
            };
        } else if !self.has_default(&f.ty) {
            manual_default = true;
        }
        let mut docs = f.doc.clone();
        if let Some(u) = &f.unit {
            docs.push(format!("Unit: {u}."));
        }
        if f.min.is_some() || f.max.is_some() {
            let show = |v: &Option<Value>| {
                v.as_ref()
                    .map(|v| self.value_expr(v, &f.ty, true))
                    .unwrap_or_default()
            };
            docs.push(format!("Range: {}..={}.", show(&f.min), show(&f.max)));
        }
        let member = Member {
            docs,
            attrs: a,
            name,
            ty,
        };
        (member, dexpr, manual_default)
    }

    /// `#[dds(...)]` arguments of a field, except `default`.
    fn field_attrs(&self, f: &Field, name: &str) -> Vec<String> {
        let mut a = Vec::new();
        if f.key {
            a.push("key".to_string());
        }
        if let Some(i) = f.id {
            a.push(format!("id = {i}"));
        }
        match f.hashid.as_deref() {
            Some("") => a.push("hashid".into()),
            Some(h) => a.push(format!("hashid = {}", lit_str(h))),
            None => {}
        }
        if bare(name) != f.name {
            a.push(format!("name = {}", lit_str(&f.name)));
        }
        if f.external {
            a.push("external".into());
        }
        if f.must_understand {
            a.push("must_understand".into());
        }
        if f.non_serialized {
            a.push("non_serialized".into());
        }
        if let Some(b) = self.field_bound(&f.ty) {
            a.push(format!("bound = {b}"));
        }
        // `xtypes` describes the member whole, octets included.
        if self.has_typedef(&f.ty) {
            a.push(format!("xtypes = {}", self.xtypes_type(&f.ty)));
        } else if self.is_octet(&f.ty) {
            a.push("octet".into());
        }
        a
    }

    pub(super) fn union_item(&mut self, id: DeclId, u: &Union, w: &mut Writer) {
        let disc = self.model.resolve_alias(&u.discriminator).clone();
        let disc_ty = match &disc {
            Type::Prim { prim: Prim::WChar } => format!("{}::cdr::WChar", self.opts.runtime_crate),
            t => self.rust_type(t, Pos::Nested),
        };
        let mut attrs = vec![format!("discriminator = {disc_ty}")];
        attrs.extend(self.type_attrs(id));
        attrs.push(u.extensibility.as_str().to_string());
        if u.nested {
            attrs.push("nested".into());
        }
        let variants = self.union_variants(u);
        let default = self.union_default(id, u, &variants);
        let eq = self.decl_eq_hash(id, &mut vec![]);
        let d = &self.model.decls[id];
        let name = &self.names[id];
        self.item_head(id, &d.doc, w);
        w.derive(&self.derives(&["Debug", "Clone", "PartialEq"], eq, &[], true));
        w.attr("dds", &attrs);
        w.open(&format!("pub enum {name}"));
        for v in &variants {
            w.docs(&v.docs);
            w.attr("dds", &v.attrs);
            w.line(&format!("{}({}),", v.name, v.ty));
        }
        w.close("");
        self.default_impl(name, w, |w| w.line(&default));
    }

    fn union_variants(&mut self, u: &Union) -> Vec<Member> {
        let mut used = Dedup::new();
        let mut variants = Vec::new();
        for c in &u.cases {
            let name = used.take(ident(&upper_camel(&c.name)));
            let mut a: Vec<String> = c
                .labels
                .iter()
                .map(|l| format!("case = {}", self.label_expr(l)))
                .collect();
            if c.is_default {
                a.push("default".into());
            }
            if let Some(i) = c.id {
                a.push(format!("id = {i}"));
            }
            if bare(&name) != c.name {
                a.push(format!("name = {}", lit_str(&c.name)));
            }
            let mut ty = self.rust_type(&c.ty, Pos::Nested);
            // The derive has no `external` for variants: the Box is the whole story.
            if c.external {
                ty = format!("{}<{ty}>", self.std("Box"));
            }
            if self.has_typedef(&c.ty) {
                ty = format!("#[dds(xtypes = {})] {ty}", self.xtypes_type(&c.ty));
            } else if self.is_octet(&c.ty) {
                ty = format!("#[dds(octet)] {ty}");
            }
            variants.push(Member {
                docs: c.doc.clone(),
                attrs: a,
                name,
                ty,
            });
        }
        variants
    }

    /// The body of the union's `Default::default()`: the first variant whose default value does not build
    /// the union itself again (`case 1: @external U next;`).
    fn union_default(&self, id: DeclId, u: &Union, variants: &[Member]) -> String {
        let pick = u
            .cases
            .iter()
            .position(|c| !self.default_builds(&c.ty, id, &mut vec![]))
            .unwrap_or(0);
        let (Some(c), Some(v)) = (u.cases.get(pick), variants.get(pick)) else {
            return "Self::()".into();
        };
        let mut e = if self.has_default(&c.ty) {
            format!("{}::default()", self.std("Default"))
        } else {
            self.default_expr(&c.ty)
        };
        if c.external {
            e = format!("{}::new({e})", self.std("Box"));
        }
        format!("Self::{}({e})", v.name)
    }

    pub(super) fn enum_item(&mut self, id: DeclId, e: &Enum, w: &mut Writer) {
        let mut attrs = self.type_attrs(id);
        if let Some(b) = e.bit_bound {
            attrs.push(format!("bit_bound = {b}"));
        }
        let derives = self.derives(
            &["Debug", "Clone", "Copy", "PartialEq"],
            true,
            &["PartialOrd", "Ord", "Default"],
            true,
        );
        let d = &self.model.decls[id];
        self.item_head(id, &d.doc, w);
        w.derive(&derives);
        w.attr("dds", &attrs);
        w.open(&format!("pub enum {}", self.names[id]));
        let names = self.enumerator_names(id);
        for (i, (en, name)) in e.enumerators.iter().zip(names).enumerate() {
            w.docs(&en.doc);
            if i == e.default_index {
                w.line("#[default]");
            }
            if bare(&name) != en.name {
                w.attr("dds", &[format!("name = {}", lit_str(&en.name))]);
            }
            w.line(&format!("{name} = {},", en.value));
        }
        w.close("");
    }

    pub(super) fn alias_item(&mut self, id: DeclId, ty: &Type, w: &mut Writer) {
        let d = &self.model.decls[id];
        let mut doc = d.doc.clone();
        if bare(&self.names[id]) != upper_camel(&d.name) {
            doc.push(format!(
                "IDL typedef `{}` (renamed: another declaration maps to the same Rust name).",
                d.name
            ));
        }
        if let Some(b) = self.field_bound(ty) {
            doc.push(format!(
                "IDL bound: {b} (carried by each field of this type)."
            ));
        }
        self.item_head(id, &doc, w);
        let rust = self.rust_type(ty, Pos::Field);
        w.assign(&format!("pub type {}", self.names[id]), &rust, ";");
        self.typedef_marker(id, ty, w);
    }

    /// The typedef's XTypes marker, which `#[dds(xtypes = ...)]` of the members of this type name, so that
    /// their type objects go through the typedef (`TK_ALIAS`) as Cyclone DDS's do.
    fn typedef_marker(&self, id: DeclId, ty: &Type, w: &mut Writer) {
        let marker = &self.typedef_markers[id];
        if marker.is_empty() {
            return;
        }
        let d = &self.model.decls[id];
        w.item();
        w.open(&format!("{}::typedef!", self.opts.runtime_crate));
        w.docs(&[format!(
            "The XTypes description of typedef `{}` (for `#[dds(xtypes = ...)]`).",
            self.names[id]
        )]);
        w.line(&format!(
            "pub {marker} = {} => {}",
            lit_str(&d.scoped_name()),
            self.xtypes_type(ty)
        ));
        w.close("");
    }

    pub(super) fn const_item(&mut self, id: DeclId, c: &Const, w: &mut Writer) {
        let resolved = self.model.resolve_alias(&c.ty).clone();
        let ty = match &resolved {
            Type::String { .. } | Type::Fixed { .. } => "&str".to_string(),
            Type::Prim { prim: Prim::WChar } => "char".into(),
            Type::Prim { prim: Prim::F128 } => "f64".into(),
            Type::Prim { .. } | Type::Named { .. } => match &c.ty {
                Type::Named { .. } if !matches!(resolved, Type::Named { .. }) => {
                    self.rust_type(&resolved, Pos::Field)
                }
                t => self.rust_type(t, Pos::Field),
            },
            _ => "()".into(),
        };
        let value = self.value_expr(&c.value, &resolved, true);
        let d = &self.model.decls[id];
        self.item_head(id, &d.doc, w);
        w.assign(&format!("pub const {}: {ty}", self.names[id]), &value, ";");
    }
}
