//! Type description: the `DdsType` impl (type name, extensibility, keyed) and its `TypeDescriptor`, the hook for
//! XTypes TypeObject generation.

use proc_macro2::TokenStream;
use quote::quote;
use syn::Generics;

use super::{ext_tokens, impl_attrs, member_id, Members};
use crate::attrs::Ext;
use crate::model::{Container, Enum, Struct, Union};

/// `impl DdsType`; `members` is the descriptor's member list expression.
pub(super) fn dds_type(
    c: &Container,
    generics: &Generics,
    ext: Ext,
    is_keyed: TokenStream,
    members: TokenStream,
) -> TokenStream {
    let cdr = c.cdr();
    let rt = c.runtime();
    let name = c.ident();
    let type_name = &c.type_name;
    let ext_t = ext_tokens(c, ext);
    let (impl_g, ty_g, where_c) = generics.split_for_impl();
    let attrs = impl_attrs();
    quote! {
        #attrs
        impl #impl_g #cdr::DdsType for #name #ty_g #where_c {
            const TYPE_NAME: &'static str = #type_name;
            const EXTENSIBILITY: #cdr::Extensibility = #ext_t;
            const IS_KEYED: bool = #is_keyed;

            fn type_descriptor() -> #cdr::TypeDescriptor {
                #cdr::TypeDescriptor {
                    type_name: #type_name,
                    extensibility: #ext_t,
                    members: #members,
                }
            }

            fn type_information() -> ::core::option::Option<&'static [u8]> {
                <Self as #rt::xtypes::XTypesType>::type_support().map(|s| s.information_bytes.as_slice())
            }

            fn type_mapping() -> ::core::option::Option<&'static [u8]> {
                <Self as #rt::xtypes::XTypesType>::type_support().map(|s| s.mapping_bytes.as_slice())
            }
        }
    }
}

fn descriptor(
    c: &Container,
    name: &str,
    id: TokenStream,
    key: bool,
    optional: bool,
    mu: bool,
) -> TokenStream {
    let cdr = c.cdr();
    quote!(#cdr::MemberDescriptor { name: #name, id: #id, key: #key, optional: #optional, must_understand: #mu })
}

/// A struct's serialized members. Ids after a base are constant expressions, which a `&[...]` literal cannot
/// promote to `'static`: the list is a `const`. Generic types cannot name their members in a `const`; they get
/// none until TypeObjects arrive.
pub(super) fn struct_members(c: &Container, s: &Struct, m: &Members) -> TokenStream {
    let cdr = c.cdr();
    let descs: Vec<TokenStream> = if c.input.generics.params.is_empty() {
        m.all
            .iter()
            .map(|f| {
                let id = member_id(c, s, f.id);
                descriptor(
                    c,
                    &f.wire_name,
                    id,
                    f.key(),
                    f.optional,
                    f.attrs.must_understand,
                )
            })
            .collect()
    } else {
        Vec::new()
    };
    quote!({
        const MEMBERS: &[#cdr::MemberDescriptor] = &[#(#descs),*];
        MEMBERS
    })
}

/// An enum's enumerators, with their values as ids.
pub(super) fn enum_members(c: &Container, e: &Enum) -> TokenStream {
    let descs = e.enumerators.iter().map(|v| {
        let value = v.wire(e.size());
        descriptor(c, &v.name, quote!(#value), false, false, false)
    });
    quote!(&[#(#descs),*])
}

/// A union's cases, with their member ids.
pub(super) fn union_members(c: &Container, u: &Union) -> TokenStream {
    let descs = u.cases.iter().map(|k| {
        let id = k.id;
        descriptor(c, &k.name, quote!(#id), false, false, false)
    });
    quote!(&[#(#descs),*])
}
