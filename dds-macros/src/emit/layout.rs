//! Compile-time layout constants: `MIN_SIZE`, `XCDR1_PLAIN` and `NEXT_MEMBER_ID`. Members whose type names the
//! type itself are left out (rustc would see a cycle).

use proc_macro2::TokenStream;
use quote::quote;

use super::{base_in_consts, union_case_consts, Members};
use crate::attrs::Ext;
use crate::model::{Container, MemberId, Struct, Union};

/// A struct's `MIN_SIZE`: the sum of its members' for a final struct (at least 1), else 1.
pub(super) fn min_size(c: &Container, s: &Struct, m: &Members) -> TokenStream {
    if s.ext != Ext::Final {
        return quote!(1usize);
    }
    let cdr = c.cdr();
    let terms = m.in_consts().into_iter().map(|f| {
        let ty = f.ty;
        if f.optional {
            quote!(1usize)
        } else {
            quote!(<#ty as #cdr::CdrType>::MIN_SIZE)
        }
    });
    let base = base_in_consts(c, s).map(|bt| quote!(+ <#bt as #cdr::CdrType>::MIN_SIZE));
    quote!({
        let m = 0usize #(+ #terms)* #base;
        if m == 0 { 1 } else { m }
    })
}

/// A struct's `XCDR1_PLAIN`: final, and every member (and the base) plain.
pub(super) fn xcdr1_plain(c: &Container, s: &Struct, m: &Members) -> TokenStream {
    let cdr = c.cdr();
    let is_final = s.ext == Ext::Final;
    let terms = m.in_consts().into_iter().map(|f| {
        let t = f.inner;
        if f.optional {
            quote!(false)
        } else {
            quote!(<#t as #cdr::CdrType>::XCDR1_PLAIN)
        }
    });
    let base = base_in_consts(c, s).map(|bt| quote!(&& <#bt as #cdr::CdrType>::XCDR1_PLAIN));
    quote!(#is_final #(&& #terms)* #base)
}

/// A struct's `NEXT_MEMBER_ID`: the id after its last member.
pub(super) fn next_member_id(c: &Container, s: &Struct) -> TokenStream {
    let cdr = c.cdr();
    match (s.next_id, &s.base) {
        (MemberId::AfterBase(k), Some(b)) => {
            let bt = b.ty;
            quote!(<#bt as #cdr::CdrType>::NEXT_MEMBER_ID + #k)
        }
        (MemberId::Absolute(k) | MemberId::AfterBase(k), _) => quote!(#k),
    }
}

/// A union's `XCDR1_PLAIN`: final, and the discriminator and every case plain.
pub(super) fn union_xcdr1_plain(c: &Container, u: &Union) -> TokenStream {
    let cdr = c.cdr();
    let is_final = u.ext == Ext::Final;
    let disc = &u.disc;
    let terms = union_case_consts(c, u, "XCDR1_PLAIN");
    quote!(#is_final && <#disc as #cdr::CdrType>::XCDR1_PLAIN #(&& #terms)*)
}
