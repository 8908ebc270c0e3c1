//! Macro table and expansion (object-like and function-like, `#` and `##`), with C's rule that a macro is
//! not expanded again inside its own expansion.
use super::lex::{lex, Kind, Tok};
use std::collections::HashMap;

/// Expansion limits: hostile input must not blow up time or memory.
const MAX_DEPTH: usize = 64;
const MAX_TOKENS: usize = 1 << 20;

#[derive(Clone, Debug)]
pub(crate) struct Macro {
    pub params: Option<Vec<String>>,
    pub variadic: bool,
    pub body: Vec<Tok>,
}

#[derive(Default, Debug)]
pub(crate) struct MacroTable {
    pub defs: HashMap<String, Macro>,
}

impl MacroTable {
    pub(crate) fn is_defined(&self, name: &str) -> bool {
        self.defs.contains_key(name)
    }

    /// Parses the text after `#define`.
    pub(crate) fn define(&mut self, text: &str) -> Result<(), String> {
        let text = text.trim_start();
        let name_len = text
            .bytes()
            .take_while(|b| super::lex::is_ident_char(*b))
            .count();
        if name_len == 0 || !super::lex::is_ident_start(text.as_bytes()[0]) {
            return Err("#define needs a macro name".into());
        }
        let name = &text[..name_len];
        let rest = &text[name_len..];
        let (params, variadic, body) = if let Some(after) = rest.strip_prefix('(') {
            let close = after
                .find(')')
                .ok_or("missing `)` in macro parameter list")?;
            let mut params = Vec::new();
            let mut variadic = false;
            for p in after[..close]
                .split(',')
                .map(str::trim)
                .filter(|p| !p.is_empty())
            {
                if p == "..." {
                    variadic = true;
                } else if p.bytes().all(super::lex::is_ident_char) {
                    params.push(p.to_string());
                } else {
                    return Err(format!("invalid macro parameter `{p}`"));
                }
            }
            (Some(params), variadic, &after[close + 1..])
        } else {
            (None, false, rest)
        };
        let body = lex(body.trim());
        self.defs.insert(
            name.to_string(),
            Macro {
                params,
                variadic,
                body,
            },
        );
        Ok(())
    }

    /// Expands a token list fully.
    pub(crate) fn expand(&self, toks: &[Tok]) -> Result<Vec<Tok>, String> {
        let mut hide = Vec::new();
        let mut budget = MAX_TOKENS;
        self.expand_in(toks, &mut hide, &mut budget)
    }

    fn expand_in(
        &self,
        toks: &[Tok],
        hide: &mut Vec<String>,
        budget: &mut usize,
    ) -> Result<Vec<Tok>, String> {
        if hide.len() > MAX_DEPTH {
            return Err("macro expansion nested too deeply".into());
        }
        let mut out = Vec::new();
        let mut i = 0;
        while i < toks.len() {
            let t = &toks[i];
            i += 1;
            let m = match (t.kind, self.defs.get(&t.text)) {
                (Kind::Ident, Some(m)) if !hide.contains(&t.text) => m,
                _ => {
                    out.push(t.clone());
                    continue;
                }
            };
            let replaced = match &m.params {
                None => m.body.clone(),
                Some(params) => {
                    let mut j = i;
                    while j < toks.len() && toks[j].kind == Kind::Ws {
                        j += 1;
                    }
                    if j >= toks.len() || !toks[j].is("(") {
                        out.push(t.clone());
                        continue;
                    }
                    let (args, end) = collect_args(toks, j)?;
                    i = end;
                    let args = if args.len() == 1
                        && args[0].iter().all(|t| t.kind == Kind::Ws)
                        && params.is_empty()
                    {
                        vec![]
                    } else {
                        args
                    };
                    if args.len() != params.len() && !(m.variadic && args.len() >= params.len()) {
                        return Err(format!(
                            "macro `{}` takes {} argument(s) but {} were given",
                            t.text,
                            params.len(),
                            args.len()
                        ));
                    }
                    self.substitute(m, params, &args, hide, budget)?
                }
            };
            hide.push(t.text.clone());
            let expanded = self.expand_in(&replaced, hide, budget)?;
            hide.pop();
            *budget = budget
                .checked_sub(expanded.len())
                .ok_or("macro expansion too large")?;
            out.extend(expanded);
        }
        Ok(out)
    }

    fn substitute(
        &self,
        m: &Macro,
        params: &[String],
        args: &[Vec<Tok>],
        hide: &mut Vec<String>,
        budget: &mut usize,
    ) -> Result<Vec<Tok>, String> {
        let arg_of = |name: &str| -> Option<Vec<Tok>> {
            if let Some(k) = params.iter().position(|p| p == name) {
                return Some(args[k].clone());
            }
            if m.variadic && name == "__VA_ARGS__" {
                let mut v = Vec::new();
                for (n, a) in args.iter().skip(params.len()).enumerate() {
                    if n > 0 {
                        v.push(Tok::new(Kind::Punct, ","));
                    }
                    v.extend(a.iter().cloned());
                }
                return Some(v);
            }
            None
        };
        let body = &m.body;
        let mut out: Vec<Tok> = Vec::new();
        let mut k = 0;
        let next_sig = |from: usize| (from..body.len()).find(|&x| body[x].kind != Kind::Ws);
        while k < body.len() {
            let t = &body[k];
            if t.is("#") {
                if let Some(n) = next_sig(k + 1) {
                    if let Some(a) = arg_of(&body[n].text) {
                        let s: String = a.iter().map(|t| t.text.as_str()).collect::<String>();
                        let s = s.trim().replace('\\', "\\\\").replace('"', "\\\"");
                        out.push(Tok::new(Kind::Str, format!("\"{s}\"")));
                        k = n + 1;
                        continue;
                    }
                }
            }
            if t.is("##") {
                // paste the previous significant token with the next one
                while out.last().is_some_and(|t| t.kind == Kind::Ws) {
                    out.pop();
                }
                let left = out.pop().map(|t| t.text).unwrap_or_default();
                let Some(n) = next_sig(k + 1) else { break };
                let right: String = match arg_of(&body[n].text) {
                    Some(a) => a
                        .iter()
                        .map(|t| t.text.as_str())
                        .collect::<String>()
                        .trim()
                        .to_string(),
                    None => body[n].text.clone(),
                };
                out.extend(lex(&format!("{left}{right}")));
                k = n + 1;
                continue;
            }
            if t.kind == Kind::Ident {
                if let Some(a) = arg_of(&t.text) {
                    let pasted = next_sig(k + 1).is_some_and(|n| body[n].is("##"));
                    if pasted {
                        out.extend(a);
                    } else {
                        out.extend(self.expand_in(&a, hide, budget)?);
                    }
                    k += 1;
                    continue;
                }
            }
            out.push(t.clone());
            k += 1;
        }
        Ok(out)
    }
}

/// Collects the arguments of a call whose `(` is at `open`; returns them and the index after `)`.
pub(crate) fn collect_args(toks: &[Tok], open: usize) -> Result<(Vec<Vec<Tok>>, usize), String> {
    let mut args = vec![Vec::new()];
    let mut depth = 0usize;
    let mut i = open + 1;
    while i < toks.len() {
        let t = &toks[i];
        i += 1;
        if t.is("(") {
            depth += 1;
        } else if t.is(")") {
            if depth == 0 {
                return Ok((args, i));
            }
            depth -= 1;
        } else if t.is(",") && depth == 0 {
            args.push(Vec::new());
            continue;
        }
        args.last_mut().expect("non-empty").push(t.clone());
    }
    Err("unterminated macro argument list".into())
}
