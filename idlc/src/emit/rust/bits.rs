//! Bitmasks (a `bitflags!` type) and bitsets (an integer newtype with a getter and setter per field).
use super::names::{bare, ident, screaming, snake};
use super::writer::Writer;
use super::{Dedup, Emitter};
use crate::ast::Prim;
use crate::model::{BitField, Bitmask, Bitset, DeclId};

/// The unsigned integer that holds `bits` bits.
fn uint_repr(bits: u32) -> &'static str {
    match bits {
        0..=8 => "u8",
        9..=16 => "u16",
        17..=32 => "u32",
        _ => "u64",
    }
}

impl Emitter<'_> {
    pub(super) fn bitmask_item(&mut self, id: DeclId, b: &Bitmask, w: &mut Writer) {
        let mut attrs = vec!["bitmask".to_string()];
        if b.bit_bound != 32 {
            attrs.push(format!("bit_bound = {}", b.bit_bound));
        }
        attrs.extend(self.type_attrs(id));
        let derives = self.derives(
            &["Debug", "Clone", "Copy", "PartialEq"],
            true,
            &["PartialOrd", "Ord"],
            false,
        );
        let d = &self.model.decls[id];
        let name = &self.names[id];
        w.item();
        // rustfmt leaves the body of a macro call alone: it is laid out as rustfmt lays out an item.
        w.open(&format!(
            "{}::__private::bitflags::bitflags!",
            self.opts.runtime_crate
        ));
        w.docs(&d.doc);
        w.derive(&derives);
        w.attr("dds", &attrs);
        w.open(&format!("pub struct {name}: {}", uint_repr(b.bit_bound)));
        let mut used = Dedup::new();
        for f in &b.flags {
            w.docs(&f.doc);
            let flag = used.take(ident(&screaming(&f.name)));
            w.line(&format!("const {flag} = 1 << {};", f.position));
        }
        w.close("");
        w.close("");
        w.item();
        w.open(&format!("impl {} for {name}", self.std("Default")));
        w.open("fn default() -> Self");
        w.line("Self::empty()");
        w.close("");
        w.close("");
    }

    pub(super) fn bitset_item(&mut self, id: DeclId, b: &Bitset, w: &mut Writer) {
        let repr = uint_repr(b.bits.max(1));
        let derives = self.derives(
            &["Debug", "Clone", "Copy", "PartialEq"],
            true,
            &["Default"],
            true,
        );
        let d = &self.model.decls[id];
        let name = &self.names[id];
        let mut doc = d.doc.clone();
        if !doc.is_empty() {
            doc.push(String::new());
        }
        doc.push("Bitset: the fields are packed into one integer; use the accessors.".into());
        w.item();
        w.docs(&doc);
        w.derive(&derives);
        w.line("#[dds(transparent)]");
        w.line(&format!("pub struct {name}(pub {repr});"));
        w.item();
        w.open(&format!("impl {name}"));
        let mut used = Dedup::new();
        for f in &b.fields {
            let Some(n) = &f.name else { continue };
            let getter = used.take(ident(&snake(n)));
            let setter = used.take(format!("set_{}", bare(&getter)));
            self.bitfield_accessors(f, n, (&getter, &setter), repr, w);
        }
        w.close("");
    }

    /// The getter and setter of one named bitfield `n`, in a bitset held in a `repr`.
    fn bitfield_accessors(
        &self,
        f: &BitField,
        n: &str,
        (getter, setter): (&str, &str),
        repr: &str,
        w: &mut Writer,
    ) {
        let ty = self.prim(f.dest);
        let (off, width) = (f.offset, f.width);
        let mask = if width >= 64 {
            u64::MAX
        } else {
            (1u64 << width) - 1
        };
        let shifted = if off == 0 {
            "self.0".to_string()
        } else {
            format!("(self.0 >> {off})")
        };
        let get_expr = match f.dest {
            Prim::Bool => format!("({shifted} & 1) != 0"),
            Prim::I8 | Prim::I16 | Prim::I32 | Prim::I64 => {
                let s = 64 - width;
                format!("((((({shifted} as u64) & {mask:#x}) << {s}) as i64) >> {s}) as {ty}")
            }
            _ => format!("({shifted} & {mask:#x}) as {ty}"),
        };
        let value = if f.dest == Prim::Bool {
            format!("(value as {repr})")
        } else {
            format!("((value as u64 & {mask:#x}) as {repr})")
        };
        let place = |e: String| {
            if off == 0 {
                e
            } else {
                format!("({e} << {off})")
            }
        };
        let range = if width == 1 {
            format!("bit {off}")
        } else {
            format!("bits {off}..{}", off + width)
        };
        w.item();
        w.docs(&[format!("`{n}`: {range}.")]);
        w.open(&format!("pub const fn {getter}(&self) -> {ty}"));
        w.line(&get_expr);
        w.close("");
        w.item();
        w.docs(&[format!(
            "Sets `{n}` ({range}); excess high bits are dropped."
        )]);
        w.open(&format!("pub fn {setter}(&mut self, value: {ty})"));
        let clear = format!("(self.0 & !{})", place(format!("({mask:#x} as {repr})")));
        w.assign_binary("self.0", &clear, "|", &place(value));
        w.close("");
    }
}
