//! Parsing of `#[dds(...)]` attributes into plain values. An attribute that cannot be read is reported to the
//! [`Ctxt`] and parsing goes on with the next one; whether the values fit the item they sit on is
//! [`check`](crate::check)'s business.

use proc_macro2::Span;
use syn::meta::ParseNestedMeta;
use syn::spanned::Spanned;
use syn::{Attribute, Expr, LitInt, LitStr, Path, Result, Type};

use crate::ctxt::Ctxt;

/// XTypes extensibility as written in the attribute.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum Ext {
    /// `@final`: no DHEADER, members in order.
    Final,
    /// `@appendable`: a DHEADER in XCDR2.
    Appendable,
    /// `@mutable`: member headers (EMHEADER or parameter list).
    Mutable,
}

/// `@hashid` on a member: absent, `hashid` (hash of the member name) or `hashid = "string"`.
#[derive(Clone, PartialEq, Eq, Debug, Default)]
pub(crate) enum HashId {
    /// No `hashid` attribute.
    #[default]
    Unset,
    /// `hashid`: the id is the hash of the member's wire name.
    OfName,
    /// `hashid = "string"`: the id is the hash of the given string.
    Of(String),
}

/// Type-level attributes.
#[derive(Default)]
pub(crate) struct TypeAttrs {
    pub(crate) name: Option<String>,
    pub(crate) ext: Option<Ext>,
    /// `autoid = "hash"`: members without an id take the hash of their name.
    pub(crate) autoid_hash: bool,
    /// `@nested`: not a topic type (IS_NESTED in the type object).
    pub(crate) nested: bool,
    pub(crate) bit_bound: Option<(u32, Span)>,
    pub(crate) discriminator: Option<Type>,
    pub(crate) bitmask: bool,
    pub(crate) transparent: bool,
    pub(crate) krate: Option<Path>,
}

/// Field (struct member, union case payload) attributes.
#[derive(Default)]
pub(crate) struct FieldAttrs {
    /// Where `key` was written, for errors.
    pub(crate) key: Option<Span>,
    pub(crate) id: Option<u32>,
    pub(crate) hashid: HashId,
    pub(crate) name: Option<String>,
    pub(crate) optional: bool,
    pub(crate) external: bool,
    pub(crate) must_understand: bool,
    pub(crate) default: Option<Expr>,
    pub(crate) bound: Option<Expr>,
    pub(crate) base: bool,
    pub(crate) non_serialized: bool,
    /// The field's type leads back to this type (mutual recursion): left out of the compile-time constants.
    pub(crate) recursive: bool,
    /// `u8` is IDL `octet` here (`TK_BYTE` in the type objects), not `uint8`.
    pub(crate) octet: bool,
    /// `xtypes = T`: the member is described as `T` (typedef markers, `Octet`, `Bounded`), not as its type.
    pub(crate) xtypes: Option<Type>,
}

/// Enum variant attributes (enumerators and union cases).
#[derive(Default)]
pub(crate) struct VariantAttrs {
    pub(crate) value: Option<i64>,
    pub(crate) cases: Vec<Expr>,
    pub(crate) default: bool,
    pub(crate) id: Option<u32>,
    pub(crate) name: Option<String>,
}

/// Runs `one` on every item of every `#[dds(...)]` attribute. An item `one` does not know is reported and
/// skipped; a malformed attribute is reported and the rest of that attribute skipped.
fn each_item(
    cx: &mut Ctxt,
    attrs: &[Attribute],
    what: &str,
    mut one: impl FnMut(&mut Ctxt, &ParseNestedMeta) -> Result<bool>,
) {
    for attr in attrs.iter().filter(|a| a.path().is_ident("dds")) {
        let parsed = attr.parse_nested_meta(|m| {
            if !one(cx, &m)? {
                cx.syn_error(m.error(format!("unknown {what} attribute; see docs/derive.md")));
                skip_value(&m)?;
            }
            Ok(())
        });
        cx.ok(parsed);
    }
}

/// Consumes `= value` or `(...)` after an unknown name, so that the items after it are still read.
fn skip_value(m: &ParseNestedMeta) -> Result<()> {
    if m.input.peek(syn::Token![=]) {
        m.value()?.parse::<Expr>()?;
    } else if m.input.peek(syn::token::Paren) {
        m.input.parse::<proc_macro2::TokenTree>()?;
    }
    Ok(())
}

fn lit_u32(cx: &mut Ctxt, m: &ParseNestedMeta) -> Result<Option<u32>> {
    let l: LitInt = m.value()?.parse()?;
    Ok(cx.ok(l.base10_parse::<u32>()))
}

fn lit_str(m: &ParseNestedMeta) -> Result<String> {
    Ok(m.value()?.parse::<LitStr>()?.value())
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

fn set_ext(cx: &mut Ctxt, slot: &mut Option<Ext>, v: Ext, at: &impl quote::ToTokens) {
    if slot.is_some() {
        cx.error_spanned_by(at, "extensibility given twice");
    }
    *slot = Some(v);
}

/// The attributes of the deriving type.
pub(crate) fn parse_type_attrs(cx: &mut Ctxt, attrs: &[Attribute]) -> TypeAttrs {
    let mut t = TypeAttrs::default();
    each_item(cx, attrs, "type", |cx, m| type_item(cx, &mut t, m));
    t
}

fn type_item(cx: &mut Ctxt, t: &mut TypeAttrs, m: &ParseNestedMeta) -> Result<bool> {
    let p = &m.path;
    let shorthand = [
        ("final", Ext::Final),
        ("appendable", Ext::Appendable),
        ("mutable", Ext::Mutable),
    ];
    if let Some((_, ext)) = shorthand.iter().find(|(n, _)| p.is_ident(n)) {
        set_ext(cx, &mut t.ext, *ext, p);
    } else if p.is_ident("name") {
        t.name = Some(lit_str(m)?);
    } else if p.is_ident("extensibility") {
        let s: LitStr = m.value()?.parse()?;
        if let Some(ext) = cx.ok(ext_from(&s)) {
            set_ext(cx, &mut t.ext, ext, &s);
        }
    } else if p.is_ident("nested") {
        // Every type can still be a topic type: this only marks the type object (IS_NESTED).
        t.nested = true;
    } else if p.is_ident("autoid") {
        let s: LitStr = m.value()?.parse()?;
        match s.value().as_str() {
            "sequential" => t.autoid_hash = false,
            "hash" => t.autoid_hash = true,
            _ => cx.error_spanned_by(&s, "autoid must be \"sequential\" or \"hash\""),
        }
    } else if p.is_ident("bit_bound") {
        let l: LitInt = m.value()?.parse()?;
        t.bit_bound = cx.ok(l.base10_parse::<u32>()).map(|b| (b, l.span()));
    } else if p.is_ident("discriminator") {
        t.discriminator = Some(m.value()?.parse::<Type>()?);
    } else if p.is_ident("bitmask") {
        t.bitmask = true;
    } else if p.is_ident("transparent") {
        t.transparent = true;
    } else if p.is_ident("crate") {
        let s: LitStr = m.value()?.parse()?;
        t.krate = cx.ok(s.parse());
    } else {
        return Ok(false);
    }
    Ok(true)
}

/// The attributes of a struct field or of a union case's payload.
pub(crate) fn parse_field_attrs(cx: &mut Ctxt, attrs: &[Attribute]) -> FieldAttrs {
    let mut f = FieldAttrs::default();
    each_item(cx, attrs, "field", |cx, m| field_item(cx, &mut f, m));
    f
}

fn field_item(cx: &mut Ctxt, f: &mut FieldAttrs, m: &ParseNestedMeta) -> Result<bool> {
    let p = &m.path;
    let flags = [
        ("optional", &mut f.optional),
        ("external", &mut f.external),
        ("must_understand", &mut f.must_understand),
        ("base", &mut f.base),
        ("non_serialized", &mut f.non_serialized),
        ("recursive", &mut f.recursive),
        ("octet", &mut f.octet),
    ];
    if let Some((_, flag)) = flags.into_iter().find(|(n, _)| p.is_ident(n)) {
        *flag = true;
    } else if p.is_ident("key") {
        f.key = Some(p.span());
    } else if p.is_ident("id") {
        f.id = lit_u32(cx, m)?;
    } else if p.is_ident("hashid") {
        f.hashid = if m.input.peek(syn::Token![=]) {
            HashId::Of(lit_str(m)?)
        } else {
            HashId::OfName
        };
    } else if p.is_ident("name") {
        f.name = Some(lit_str(m)?);
    } else if p.is_ident("default") {
        f.default = Some(m.value()?.parse::<Expr>()?);
    } else if p.is_ident("bound") {
        f.bound = Some(m.value()?.parse::<Expr>()?);
    } else if p.is_ident("xtypes") {
        f.xtypes = Some(m.value()?.parse::<Type>()?);
    } else {
        return Ok(false);
    }
    Ok(true)
}

/// The attributes of an enum variant (an enumerator or a union case).
pub(crate) fn parse_variant_attrs(cx: &mut Ctxt, attrs: &[Attribute]) -> VariantAttrs {
    let mut v = VariantAttrs::default();
    each_item(cx, attrs, "variant", |cx, m| variant_item(cx, &mut v, m));
    v
}

fn variant_item(cx: &mut Ctxt, v: &mut VariantAttrs, m: &ParseNestedMeta) -> Result<bool> {
    let p = &m.path;
    if p.is_ident("value") {
        let e: Expr = m.value()?.parse()?;
        v.value = cx.ok(parse_int_expr(&e));
    } else if p.is_ident("case") {
        v.cases.push(m.value()?.parse::<Expr>()?);
    } else if p.is_ident("default") {
        v.default = true;
    } else if p.is_ident("id") {
        v.id = lit_u32(cx, m)?;
    } else if p.is_ident("name") {
        v.name = Some(lit_str(m)?);
    } else {
        return Ok(false);
    }
    Ok(true)
}

/// An integer literal, possibly negated or parenthesized.
pub(crate) fn parse_int_expr(e: &Expr) -> Result<i64> {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_unknown_item_is_reported_and_the_items_after_it_still_read() {
        let attrs: [Attribute; 2] = [
            syn::parse_quote!(#[dds(keyy = 3, key, tag(x), bound = 4)]),
            syn::parse_quote!(#[dds(hashid = "h")]),
        ];
        let mut cx = Ctxt::default();
        let a = parse_field_attrs(&mut cx, &attrs);
        assert!(a.key.is_some() && a.bound.is_some());
        assert_eq!(a.hashid, HashId::Of("h".into()));
        let errors = cx.finish().unwrap_err();
        assert_eq!(errors.into_iter().count(), 2);
    }

    #[test]
    fn a_bad_value_is_reported_and_parsing_goes_on() {
        let attr: Attribute =
            syn::parse_quote!(#[dds(extensibility = "flexible", autoid = "x", id = 5, mutable)]);
        let mut cx = Ctxt::default();
        let t = parse_type_attrs(&mut cx, std::slice::from_ref(&attr));
        assert_eq!(t.ext, Some(Ext::Mutable));
        assert_eq!(cx.finish().unwrap_err().into_iter().count(), 3);
    }

    #[test]
    fn negative_and_parenthesized_integers() {
        assert_eq!(parse_int_expr(&syn::parse_quote!(-(3))).unwrap(), -3);
        assert!(parse_int_expr(&syn::parse_quote!(A::B)).is_err());
    }
}
