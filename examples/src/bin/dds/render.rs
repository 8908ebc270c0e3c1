//! Text output: aligned columns, coloured headings when stdout is a terminal (and `NO_COLOR` is unset).

use std::io::IsTerminal;

use owo_colors::OwoColorize;

/// Whether to colour, decided once from stdout.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Style {
    colour: bool,
}

impl Style {
    /// Colour when stdout is a terminal and `NO_COLOR` is not set.
    pub(crate) fn detect() -> Self {
        Style {
            colour: std::io::stdout().is_terminal() && std::env::var_os("NO_COLOR").is_none(),
        }
    }

    /// A section heading.
    pub(crate) fn heading(self, s: &str) -> String {
        if self.colour {
            s.bold().underline().to_string()
        } else {
            s.to_string()
        }
    }

    /// A key value (topic name, GUID) that the eye should find.
    pub(crate) fn key(self, s: &str) -> String {
        if self.colour {
            s.cyan().to_string()
        } else {
            s.to_string()
        }
    }

    /// Secondary information.
    pub(crate) fn dim(self, s: &str) -> String {
        if self.colour {
            s.dimmed().to_string()
        } else {
            s.to_string()
        }
    }

    /// Whether output goes to a person watching (used to clear the screen between `--watch` updates).
    pub(crate) fn interactive(self) -> bool {
        self.colour
    }
}

/// Columns padded to the widest cell; the first row is the header. Widths count characters before styling.
pub(crate) fn table(style: Style, rows: &[Vec<String>]) -> String {
    let cols = rows.iter().map(Vec::len).max().unwrap_or(0);
    let widths: Vec<usize> = (0..cols)
        .map(|c| {
            rows.iter()
                .filter_map(|r| r.get(c))
                .map(|s| s.chars().count())
                .max()
                .unwrap_or(0)
        })
        .collect();
    let mut out = String::new();
    for (i, row) in rows.iter().enumerate() {
        let mut line = String::new();
        for (c, cell) in row.iter().enumerate() {
            let pad = widths[c] - cell.chars().count();
            let shown = if i == 0 {
                style.dim(cell)
            } else {
                cell.clone()
            };
            line.push_str(&shown);
            if c + 1 < row.len() {
                line.push_str(&" ".repeat(pad + 2));
            }
        }
        out.push_str(line.trim_end());
        out.push('\n');
    }
    out
}

/// `-` for what was not announced.
pub(crate) fn or_dash(v: &Option<String>) -> String {
    v.clone().unwrap_or_else(|| "-".to_string())
}
