//! Symbol tables and IDL name lookup (§7.5): nearest enclosing scope first, case-insensitive collisions.
use crate::ast::ScopedName;
use crate::model::DeclId;
use crate::source::Loc;
use std::collections::HashMap;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Sym {
    Module,
    Decl(DeclId),
    Enumerator(DeclId, usize),
    Annotation,
}

#[derive(Clone, Debug)]
pub(crate) struct Entry {
    pub name: String,
    pub sym: Sym,
    pub loc: Loc,
}

/// All scopes, keyed by their path joined with `::` (the root is "").
#[derive(Default, Debug)]
pub(crate) struct Scopes {
    scopes: HashMap<String, HashMap<String, Entry>>,
}

pub(crate) enum Lookup {
    Found(Sym),
    /// Found, but spelled with different case.
    CaseMismatch {
        found: String,
        sym: Sym,
        loc: Loc,
    },
    /// Stopped at `stop` (a scope that exists) where `missing` was not found.
    NotFound {
        missing: String,
        scope: String,
    },
    /// The first component resolved in a nearer scope that lacks the rest, while an outer scope has it all.
    Shadowed {
        near: String,
        far: String,
    },
}

pub(crate) fn key(path: &[String]) -> String {
    path.join("::")
}

impl Scopes {
    pub(crate) fn get(&self, scope: &str, name: &str) -> Option<&Entry> {
        self.scopes.get(scope)?.get(&name.to_ascii_lowercase())
    }

    /// Inserts, returning the existing entry that collides (same name ignoring case).
    pub(crate) fn insert(
        &mut self,
        scope: &str,
        name: &str,
        sym: Sym,
        loc: Loc,
    ) -> Result<(), Entry> {
        let s = self.scopes.entry(scope.to_string()).or_default();
        let k = name.to_ascii_lowercase();
        if let Some(e) = s.get(&k) {
            return Err(e.clone());
        }
        s.insert(
            k,
            Entry {
                name: name.to_string(),
                sym,
                loc,
            },
        );
        Ok(())
    }

    /// Names visible from `from` (for suggestions).
    pub(crate) fn visible_names(&self, from: &[String]) -> Vec<String> {
        let mut out = Vec::new();
        for i in (0..=from.len()).rev() {
            if let Some(s) = self.scopes.get(&key(&from[..i])) {
                out.extend(s.values().map(|e| e.name.clone()));
            }
        }
        out
    }

    /// Names declared directly in a scope.
    pub(crate) fn names_in(&self, scope: &str) -> Vec<String> {
        self.scopes
            .get(scope)
            .map(|s| s.values().map(|e| e.name.clone()).collect())
            .unwrap_or_default()
    }

    fn resolve_rest(
        &self,
        start_scope: &str,
        first: &Entry,
        rest: &[String],
        enum_members: &dyn Fn(DeclId, &str) -> Option<usize>,
    ) -> Result<(Sym, Loc, bool), (String, String)> {
        let mut cur = first.clone();
        let mut scope = if start_scope.is_empty() {
            first.name.clone()
        } else {
            format!("{start_scope}::{}", first.name)
        };
        let mut case_ok = true;
        for part in rest {
            match cur.sym {
                Sym::Module => match self.get(&scope, part) {
                    Some(e) => {
                        case_ok &= e.name == *part;
                        scope = format!("{scope}::{}", e.name);
                        cur = e.clone();
                    }
                    None => return Err((part.clone(), scope)),
                },
                // `Color::RED`: IDL puts enumerators in the enclosing scope, but the qualified form is common.
                Sym::Decl(d) => match enum_members(d, part) {
                    Some(i) => return Ok((Sym::Enumerator(d, i), cur.loc, case_ok)),
                    None => return Err((part.clone(), scope)),
                },
                _ => return Err((part.clone(), scope)),
            }
        }
        Ok((cur.sym, cur.loc, case_ok))
    }

    pub(crate) fn lookup(
        &self,
        name: &ScopedName,
        from: &[String],
        enum_members: &dyn Fn(DeclId, &str) -> Option<usize>,
    ) -> Lookup {
        let parts: Vec<String> = name.parts.iter().map(|p| p.name.clone()).collect();
        let starts: Vec<usize> = if name.absolute {
            vec![0]
        } else {
            (0..=from.len()).rev().collect()
        };
        let mut first_failure: Option<(String, String, String)> = None;
        for i in starts {
            let scope = key(&from[..i]);
            let Some(first) = self.get(&scope, &parts[0]) else {
                continue;
            };
            match self.resolve_rest(&scope, first, &parts[1..], enum_members) {
                Ok((sym, loc, case_ok)) => {
                    if let Some((_, _, near)) = first_failure {
                        let far = if scope.is_empty() {
                            format!("::{}", parts.join("::"))
                        } else {
                            format!("::{scope}::{}", parts.join("::"))
                        };
                        return Lookup::Shadowed { near, far };
                    }
                    if !case_ok || first.name != parts[0] {
                        let found = self
                            .spelled(&scope, &parts)
                            .unwrap_or_else(|| parts.join("::"));
                        return Lookup::CaseMismatch { found, sym, loc };
                    }
                    return Lookup::Found(sym);
                }
                Err((missing, sc)) => {
                    if first_failure.is_none() {
                        let near = if scope.is_empty() {
                            first.name.clone()
                        } else {
                            format!("{scope}::{}", first.name)
                        };
                        first_failure = Some((missing, sc, near));
                    }
                }
            }
        }
        match first_failure {
            Some((missing, scope, _)) => Lookup::NotFound { missing, scope },
            None => Lookup::NotFound {
                missing: parts[0].clone(),
                scope: String::new(),
            },
        }
    }

    /// The declared spelling of a path.
    fn spelled(&self, scope: &str, parts: &[String]) -> Option<String> {
        let mut out = Vec::new();
        let mut sc = scope.to_string();
        for p in parts {
            let e = self.get(&sc, p)?;
            out.push(e.name.clone());
            sc = if sc.is_empty() {
                e.name.clone()
            } else {
                format!("{sc}::{}", e.name)
            };
            if !matches!(e.sym, Sym::Module) {
                break;
            }
        }
        Some(out.join("::"))
    }
}
