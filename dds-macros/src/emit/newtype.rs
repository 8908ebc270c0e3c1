//! One-field tuple structs: `transparent` (typedefs, bitset storage) and `bitmask` (`bitflags` structs).

use proc_macro2::TokenStream;
use quote::quote;

use super::{describe, impl_attrs, key};
use crate::attrs::Ext;
use crate::model::{Bitmask, Container, Transparent};

/// A typedef: encoded exactly as its field.
pub(super) fn transparent(c: &Container, t: &Transparent) -> TokenStream {
    let cdr = c.cdr();
    let name = c.ident();
    let ty = t.ty;
    let (enc, dec, bo) = match &t.bound {
        Some(b) => (
            quote!(<#ty as #cdr::CdrType>::encode_bounded(&self.0, w, (#b) as usize)),
            quote!(<#ty as #cdr::CdrType>::decode_bounded(r, (#b) as usize)),
            quote!(::core::option::Option::Some((#b) as usize)),
        ),
        None => (
            quote!(<#ty as #cdr::CdrType>::encode(&self.0, w)),
            quote!(<#ty as #cdr::CdrType>::decode(r)),
            quote!(bound),
        ),
    };
    let (impl_g, ty_g, where_c) = c.input.generics.split_for_impl();
    let attrs = impl_attrs();
    quote! {
        #attrs
        impl #impl_g #cdr::CdrType for #name #ty_g #where_c {
            const LAYOUT: #cdr::Layout = <#ty as #cdr::CdrType>::LAYOUT;
            const MIN_SIZE: usize = <#ty as #cdr::CdrType>::MIN_SIZE;
            const XCDR1_PLAIN: bool = <#ty as #cdr::CdrType>::XCDR1_PLAIN;
            const KEY_HAS_MUTABLE: bool = <#ty as #cdr::CdrType>::KEY_HAS_MUTABLE;

            #[inline]
            fn encode(&self, w: &mut #cdr::CdrWriter<'_>) -> ::core::result::Result<(), #cdr::EncodeError> {
                #enc
            }

            #[inline]
            fn decode(r: &mut #cdr::CdrReader<'_>) -> ::core::result::Result<Self, #cdr::DecodeError> {
                #dec.map(Self)
            }

            fn default_value() -> Self {
                Self(<#ty as #cdr::CdrType>::default_value())
            }

            fn key_max_end(
                start: usize,
                version: #cdr::XcdrVersion,
                bound: ::core::option::Option<usize>,
            ) -> ::core::option::Option<usize> {
                let _ = bound;
                <#ty as #cdr::CdrType>::key_max_end(start, version, #bo)
            }
        }
    }
}

/// A `bitflags` 2 struct: an unsigned integer sized by `bit_bound` (default 32) in both XCDR versions.
pub(super) fn bitmask(c: &Container, b: &Bitmask) -> TokenStream {
    let cdr = c.cdr();
    let rt = c.runtime();
    let name = c.ident();
    let (size, write, read): (u8, TokenStream, TokenStream) = match b.bit_bound {
        0..=8 => (
            1,
            quote!(w.write_u8(v as u8)),
            quote!(u64::from(r.read_u8("bitmask")?)),
        ),
        9..=16 => (
            2,
            quote!(w.write_u16(v as u16)),
            quote!(u64::from(r.read_u16("bitmask")?)),
        ),
        17..=32 => (
            4,
            quote!(w.write_u32(v as u32)),
            quote!(u64::from(r.read_u32("bitmask")?)),
        ),
        _ => (8, quote!(w.write_u64(v)), quote!(r.read_u64("bitmask")?)),
    };
    let size_usize = usize::from(size);
    let type_name = &c.type_name;
    let bf = quote!(#rt::__private::bitflags::Flags);
    let attrs = impl_attrs();
    let key_max_end = key::key_max_end_fn(
        c,
        quote!(::core::option::Option::Some(#cdr::members::prim_end(start, #size_usize, version))),
    );
    let dds_type = describe::dds_type(c, &c.input.generics, Ext::Final, quote!(false), quote!(&[]));
    quote! {
        #attrs
        impl #cdr::CdrType for #name {
            const LAYOUT: #cdr::Layout = #cdr::Layout::Enumerated(#size);
            const MIN_SIZE: usize = #size_usize;

            #[inline]
            fn encode(&self, w: &mut #cdr::CdrWriter<'_>) -> ::core::result::Result<(), #cdr::EncodeError> {
                let v: u64 = ::core::convert::Into::<u64>::into(<Self as #bf>::bits(self));
                #write;
                ::core::result::Result::Ok(())
            }

            #[inline]
            fn decode(r: &mut #cdr::CdrReader<'_>) -> ::core::result::Result<Self, #cdr::DecodeError> {
                let at = r.offset();
                let v: u64 = #read;
                match ::core::convert::TryFrom::try_from(v) {
                    ::core::result::Result::Ok(bits) => ::core::result::Result::Ok(<Self as #bf>::from_bits_retain(bits)),
                    ::core::result::Result::Err(_) => ::core::result::Result::Err(#cdr::DecodeError::new(
                        at,
                        concat!("bits of ", #type_name),
                        #cdr::DecodeErrorKind::InvalidValue { found: v },
                    )),
                }
            }

            fn default_value() -> Self {
                <Self as #bf>::empty()
            }

            #key_max_end
        }

        #dds_type
    }
}
