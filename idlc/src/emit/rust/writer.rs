//! Writes Rust source line by line, laid out as `rustfmt` (default settings) lays out the few shapes idlc
//! emits: items separated by blank lines, four-space blocks, doc comments, attribute lists, and statements
//! broken after `=` or before a binary operator when they do not fit in 100 columns.
//!
//! Nothing is parsed or re-formatted afterwards: what the emitter writes is the output.

/// rustfmt's `max_width`.
const MAX_WIDTH: usize = 100;
/// rustfmt's `attr_fn_like_width`: an attribute's argument list longer than this goes one per line.
const ATTR_ARGS_WIDTH: usize = 70;
/// A `#[derive(...)]` line longer than this is broken (measured against rustfmt 1.8).
const DERIVE_LINE_WIDTH: usize = 96;
const INDENT: &str = "    ";

/// Rust source under construction.
#[derive(Debug, Default)]
pub(super) struct Writer {
    out: String,
    depth: usize,
    /// Nothing written yet in the current block: the next item needs no blank line before it.
    fresh: bool,
}

impl Writer {
    /// A writer whose output starts with `header` (a line) and a blank line.
    pub(super) fn with_header(header: &str) -> Self {
        let mut w = Writer {
            out: String::with_capacity(16 * 1024),
            depth: 0,
            fresh: false,
        };
        w.line(header);
        w
    }

    /// The text written.
    pub(super) fn finish(self) -> String {
        self.out
    }

    /// Column where the current block's lines start.
    fn indent_width(&self) -> usize {
        self.depth * INDENT.len()
    }

    fn fits(&self, text: &str) -> bool {
        self.indent_width() + text.len() <= MAX_WIDTH
    }

    /// One line at the current indentation.
    pub(super) fn line(&mut self, text: &str) {
        for _ in 0..self.depth {
            self.out.push_str(INDENT);
        }
        self.out.push_str(text);
        self.out.push('\n');
        self.fresh = false;
    }

    /// Starts a new item: a blank line unless it is the first thing in its block.
    pub(super) fn item(&mut self) {
        if !self.fresh {
            self.out.push('\n');
        }
        self.fresh = true;
    }

    /// `head {`, then what follows is one level deeper until [`Writer::close`].
    pub(super) fn open(&mut self, head: &str) {
        self.line(&format!("{head} {{"));
        self.depth += 1;
        self.fresh = true;
    }

    /// Ends the block opened last with `}` followed by `tail` (`""`, `","`, `");"`...). An empty block
    /// becomes `head {}`.
    pub(super) fn close(&mut self, tail: &str) {
        self.depth = self.depth.saturating_sub(1);
        if self.fresh && self.out.ends_with(" {\n") {
            self.out.pop();
            self.out.push_str(&format!("}}{tail}\n"));
            self.fresh = false;
        } else {
            self.line(&format!("}}{tail}"));
        }
    }

    /// `///` comments, one per line (an empty line is a bare `///`).
    pub(super) fn docs(&mut self, lines: &[String]) {
        for l in lines {
            for part in l.split('\n') {
                let part = part.trim_end_matches('\r').replace('\r', "");
                if part.is_empty() {
                    self.line("///");
                } else {
                    self.line(&format!("/// {part}"));
                }
            }
        }
    }

    /// Text written as it is, indented (`@verbatim` Rust code).
    pub(super) fn verbatim(&mut self, text: &str) {
        for l in text.lines() {
            if l.trim().is_empty() {
                self.out.push('\n');
            } else {
                self.line(l);
            }
        }
    }

    /// `#[name(a, b, c)]`, or one argument per line when the list is too long: as rustfmt does for attributes
    /// it can parse (every argument a path or `path = literal`), else when the line passes 100 columns.
    /// Nothing for an empty list.
    pub(super) fn attr(&mut self, name: &str, args: &[String]) {
        if args.is_empty() {
            return;
        }
        let joined = args.join(", ");
        let one_line = format!("#[{name}({joined})]");
        // rustfmt leaves other attributes as they are; those still go one argument per line when too long.
        let keep = if args.iter().all(|a| is_meta(a)) {
            joined.len() <= ATTR_ARGS_WIDTH && self.fits(&one_line)
        } else {
            self.fits(&one_line)
        };
        if keep || args.len() == 1 {
            self.line(&one_line);
            return;
        }
        self.line(&format!("#[{name}("));
        for (i, a) in args.iter().enumerate() {
            let sep = if i + 1 < args.len() { "," } else { "" };
            self.line(&format!("{INDENT}{a}{sep}"));
        }
        self.line(")]");
    }

    /// `#[derive(...)]`: one line when short, else the list on one indented line, else one per line.
    pub(super) fn derive(&mut self, traits: &[String]) {
        let joined = traits.join(", ");
        if self.indent_width() + joined.len() + "#[derive()]".len() <= DERIVE_LINE_WIDTH {
            self.line(&format!("#[derive({joined})]"));
            return;
        }
        self.line("#[derive(");
        if self.indent_width() + INDENT.len() + joined.len() <= MAX_WIDTH {
            self.line(&format!("{INDENT}{joined},"));
        } else {
            for t in traits {
                self.line(&format!("{INDENT}{t},"));
            }
        }
        self.line(")]");
    }

    /// `one` when it fits, else `first` and then `second` one level deeper when that fits. False (nothing
    /// written) when neither does.
    fn one_or_broken(&mut self, one: &str, first: &str, second: &str) -> bool {
        let second = format!("{INDENT}{second}");
        if self.fits(one) {
            self.line(one);
        } else if self.fits(&second) {
            self.line(first);
            self.line(&second);
        } else {
            return false;
        }
        true
    }

    /// `{lhs} = {rhs}{end}`, broken after `=` when it does not fit on one line.
    pub(super) fn assign(&mut self, lhs: &str, rhs: &str, end: &str) {
        let (first, second) = (format!("{lhs} ="), format!("{rhs}{end}"));
        if !self.one_or_broken(&format!("{lhs} = {rhs}{end}"), &first, &second) {
            self.line(&first);
            self.line(&format!("{INDENT}{second}"));
        }
    }

    /// A struct field `{head}: {ty},`; too long, the type goes on the next line, or its generic arguments one
    /// per line.
    pub(super) fn field(&mut self, head: &str, ty: &str) {
        let one = format!("{head}: {ty},");
        if self.one_or_broken(&one, &format!("{head}:"), &format!("{ty},")) {
            return;
        }
        let Some((outer, args)) = split_generics(ty) else {
            self.line(&one);
            return;
        };
        let open = format!("{head}: {outer}<");
        let pad = if self.fits(&open) {
            self.line(&open);
            ""
        } else {
            self.line(&format!("{head}:"));
            self.line(&format!("{INDENT}{outer}<"));
            INDENT
        };
        for a in args {
            self.line(&format!("{pad}{INDENT}{a},"));
        }
        self.line(&format!("{pad}>,"));
    }

    /// `{lhs} = {left} {op} {right};`: on one line, else broken after `=`, else before `op`.
    pub(super) fn assign_binary(&mut self, lhs: &str, left: &str, op: &str, right: &str) {
        let rhs = format!("{left} {op} {right};");
        if !self.one_or_broken(&format!("{lhs} = {rhs}"), &format!("{lhs} ="), &rhs) {
            self.line(&format!("{lhs} = {left}"));
            self.line(&format!("{INDENT}{op} {right};"));
        }
    }
}

/// `Outer<A, B<C, D>>` → (`Outer`, [`A`, `B<C, D>`]); `None` for a type without generic arguments.
fn split_generics(ty: &str) -> Option<(&str, Vec<&str>)> {
    let open = ty.find('<')?;
    let inner = ty.get(open + 1..)?.strip_suffix('>')?;
    let mut args = Vec::new();
    let (mut depth, mut start) = (0i32, 0);
    for (i, c) in inner.char_indices() {
        match c {
            '<' | '[' | '(' => depth += 1,
            '>' | ']' | ')' => depth -= 1,
            ',' if depth == 0 => {
                args.push(inner[start..i].trim());
                start = i + 1;
            }
            _ => {}
        }
    }
    args.push(inner[start..].trim());
    Some((&ty[..open], args))
}

/// Whether rustfmt can parse an attribute argument as meta (a path, or `path = literal`) and so reflows it.
fn is_meta(arg: &str) -> bool {
    let is_path = |s: &str| {
        !s.is_empty()
            && s.split("::")
                .all(|p| !p.is_empty() && p.chars().all(|c| c.is_alphanumeric() || c == '_'))
    };
    match arg.split_once(" = ") {
        None => is_path(arg),
        Some((key, value)) => {
            let literal = value.starts_with(['"', '\''])
                || value.starts_with(|c: char| c.is_ascii_digit())
                || value == "true"
                || value == "false";
            is_path(key) && literal
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn meta_arguments() {
        assert!(is_meta("key"));
        assert!(is_meta("id = 3"));
        assert!(is_meta("name = \"a::B\""));
        assert!(!is_meta("case = Color::Red"));
        assert!(!is_meta("default = -5"));
        assert!(!is_meta("discriminator = i32"));
    }

    #[test]
    fn generic_arguments_split_at_the_top_level() {
        assert_eq!(
            split_generics("Map<K<A, B>, [u8; 2]>"),
            Some(("Map", vec!["K<A, B>", "[u8; 2]"]))
        );
        assert_eq!(split_generics("u8"), None);
    }

    #[test]
    fn long_attribute_goes_one_argument_per_line() {
        let mut w = Writer::default();
        let args: Vec<String> = (0..12).map(|i| format!("name{i} = {i}")).collect();
        w.attr("dds", &args);
        let out = w.finish();
        assert!(out.starts_with("#[dds(\n    name0 = 0,\n"), "{out}");
        assert!(out.ends_with("    name11 = 11\n)]\n"), "{out}");
    }

    #[test]
    fn blank_line_between_items_only() {
        let mut w = Writer {
            fresh: true,
            ..Writer::default()
        };
        w.item();
        w.line("pub const A: u8 = 1;");
        w.item();
        w.open("pub mod m");
        w.item();
        w.line("pub const B: u8 = 2;");
        w.close("");
        assert_eq!(
            w.finish(),
            "pub const A: u8 = 1;\n\npub mod m {\n    pub const B: u8 = 2;\n}\n"
        );
    }
}
