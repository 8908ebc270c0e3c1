//! Parsing of `#[dds(...)]` attributes.

use syn::spanned::Spanned;
use syn::{Attribute, Expr, LitInt, LitStr, Path, Result, Type};

/// XTypes extensibility as written in the attribute.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Ext {
    Final,
    Appendable,
    Mutable,
}

/// Type-level attributes.
#[derive(Default)]
pub struct TypeAttrs {
    pub name: Option<String>,
    pub ext: Option<Ext>,
    pub nested: bool,
    pub autoid_hash: bool,
    pub bit_bound: Option<(u32, proc_macro2::Span)>,
    pub discriminator: Option<Type>,
    pub bitmask: bool,
    pub transparent: bool,
    pub krate: Option<Path>,
}

/// Field (struct member, union case payload) attributes.
#[derive(Default)]
pub struct FieldAttrs {
    pub key: Option<proc_macro2::Span>,
    pub id: Option<u32>,
    pub hashid: Option<Option<String>>,
    pub name: Option<String>,
    pub optional: bool,
    pub external: bool,
    pub must_understand: bool,
    pub default: Option<Expr>,
    pub bound: Option<Expr>,
    pub base: bool,
    pub non_serialized: bool,
    /// The field's type leads back to this type (mutual recursion): left out of the compile-time constants.
    pub recursive: bool,
}

/// Enum variant attributes (enumerators and union cases).
#[derive(Default)]
pub struct VariantAttrs {
    pub value: Option<i64>,
    pub cases: Vec<Expr>,
    pub default: bool,
    pub id: Option<u32>,
    pub name: Option<String>,
}

fn lit_u32(l: &LitInt) -> Result<u32> {
    l.base10_parse::<u32>()
}

fn ext_from(s: &LitStr) -> Result<Ext> {
    match s.value().as_str() {
        "final" => Ok(Ext::Final),
        "appendable" => Ok(Ext::Appendable),
        "mutable" => Ok(Ext::Mutable),
        _ => Err(syn::Error::new_spanned(
            s,
            "extensibility must be \"final\", \"appendable\" or \"mutable\"",
        )),
    }
}

fn set_ext(slot: &mut Option<Ext>, v: Ext, span: &impl quote::ToTokens) -> Result<()> {
    if slot.is_some() {
        return Err(syn::Error::new_spanned(span, "extensibility given twice"));
    }
    *slot = Some(v);
    Ok(())
}

pub fn parse_type_attrs(attrs: &[Attribute]) -> Result<TypeAttrs> {
    let mut t = TypeAttrs::default();
    for attr in attrs.iter().filter(|a| a.path().is_ident("dds")) {
        attr.parse_nested_meta(|m| {
            let p = &m.path;
            if p.is_ident("name") {
                t.name = Some(m.value()?.parse::<LitStr>()?.value());
            } else if p.is_ident("extensibility") {
                let s: LitStr = m.value()?.parse()?;
                set_ext(&mut t.ext, ext_from(&s)?, &s)?;
            } else if p.is_ident("final") {
                set_ext(&mut t.ext, Ext::Final, p)?;
            } else if p.is_ident("appendable") {
                set_ext(&mut t.ext, Ext::Appendable, p)?;
            } else if p.is_ident("mutable") {
                set_ext(&mut t.ext, Ext::Mutable, p)?;
            } else if p.is_ident("nested") {
                t.nested = true;
            } else if p.is_ident("autoid") {
                let s: LitStr = m.value()?.parse()?;
                t.autoid_hash = match s.value().as_str() {
                    "sequential" => false,
                    "hash" => true,
                    _ => {
                        return Err(syn::Error::new_spanned(
                            &s,
                            "autoid must be \"sequential\" or \"hash\"",
                        ))
                    }
                };
            } else if p.is_ident("bit_bound") {
                let l: LitInt = m.value()?.parse()?;
                t.bit_bound = Some((lit_u32(&l)?, l.span()));
            } else if p.is_ident("discriminator") {
                t.discriminator = Some(m.value()?.parse::<Type>()?);
            } else if p.is_ident("bitmask") {
                t.bitmask = true;
            } else if p.is_ident("transparent") {
                t.transparent = true;
            } else if p.is_ident("crate") {
                let s: LitStr = m.value()?.parse()?;
                t.krate = Some(s.parse()?);
            } else {
                return Err(m.error("unknown type attribute; see docs/derive.md"));
            }
            Ok(())
        })?;
    }
    Ok(t)
}

pub fn parse_field_attrs(attrs: &[Attribute]) -> Result<FieldAttrs> {
    let mut f = FieldAttrs::default();
    for attr in attrs.iter().filter(|a| a.path().is_ident("dds")) {
        attr.parse_nested_meta(|m| {
            let p = &m.path;
            if p.is_ident("key") {
                f.key = Some(p.span());
            } else if p.is_ident("id") {
                f.id = Some(lit_u32(&m.value()?.parse::<LitInt>()?)?);
            } else if p.is_ident("hashid") {
                f.hashid = Some(if m.input.peek(syn::Token![=]) {
                    Some(m.value()?.parse::<LitStr>()?.value())
                } else {
                    None
                });
            } else if p.is_ident("name") {
                f.name = Some(m.value()?.parse::<LitStr>()?.value());
            } else if p.is_ident("optional") {
                f.optional = true;
            } else if p.is_ident("external") {
                f.external = true;
            } else if p.is_ident("must_understand") {
                f.must_understand = true;
            } else if p.is_ident("default") {
                f.default = Some(m.value()?.parse::<Expr>()?);
            } else if p.is_ident("bound") {
                f.bound = Some(m.value()?.parse::<Expr>()?);
            } else if p.is_ident("base") {
                f.base = true;
            } else if p.is_ident("non_serialized") {
                f.non_serialized = true;
            } else if p.is_ident("recursive") {
                f.recursive = true;
            } else {
                return Err(m.error("unknown field attribute; see docs/derive.md"));
            }
            Ok(())
        })?;
    }
    Ok(f)
}

pub fn parse_variant_attrs(attrs: &[Attribute]) -> Result<VariantAttrs> {
    let mut v = VariantAttrs::default();
    for attr in attrs.iter().filter(|a| a.path().is_ident("dds")) {
        attr.parse_nested_meta(|m| {
            let p = &m.path;
            if p.is_ident("value") {
                let e: Expr = m.value()?.parse()?;
                v.value = Some(parse_int_expr(&e)?);
            } else if p.is_ident("case") {
                v.cases.push(m.value()?.parse::<Expr>()?);
            } else if p.is_ident("default") {
                v.default = true;
            } else if p.is_ident("id") {
                v.id = Some(lit_u32(&m.value()?.parse::<LitInt>()?)?);
            } else if p.is_ident("name") {
                v.name = Some(m.value()?.parse::<LitStr>()?.value());
            } else {
                return Err(m.error("unknown variant attribute; see docs/derive.md"));
            }
            Ok(())
        })?;
    }
    Ok(v)
}

/// An integer literal, possibly negated.
pub fn parse_int_expr(e: &Expr) -> Result<i64> {
    match e {
        Expr::Lit(syn::ExprLit {
            lit: syn::Lit::Int(l),
            ..
        }) => l.base10_parse::<i64>(),
        Expr::Unary(syn::ExprUnary {
            op: syn::UnOp::Neg(_),
            expr,
            ..
        }) => parse_int_expr(expr).map(|v| -v),
        Expr::Group(g) => parse_int_expr(&g.expr),
        Expr::Paren(p) => parse_int_expr(&p.expr),
        _ => Err(syn::Error::new_spanned(e, "expected an integer literal")),
    }
}

/// `@hashid`: MD5 of the name, first 4 bytes little-endian, masked to 28 bits.
pub fn hash_id(name: &str) -> u32 {
    use md5::{Digest, Md5};
    let d = Md5::digest(name.as_bytes());
    u32::from_le_bytes([d[0], d[1], d[2], d[3]]) & 0x0fff_ffff
}
