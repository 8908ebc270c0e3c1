//! The resolved type model: every name is resolved to a declaration, every constant evaluated, every
//! annotation interpreted. This is what the back ends read (and what `--emit json` prints).
use crate::ast::Prim;
use crate::source::Loc;
use serde::Serialize;

pub type DeclId = usize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Extensibility {
    Final,
    Appendable,
    Mutable,
}

impl Extensibility {
    pub fn as_str(self) -> &'static str {
        match self {
            Extensibility::Final => "final",
            Extensibility::Appendable => "appendable",
            Extensibility::Mutable => "mutable",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum AutoId {
    #[default]
    Sequential,
    Hash,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Type {
    Prim {
        prim: Prim,
    },
    String {
        wide: bool,
        bound: Option<u64>,
    },
    Sequence {
        elem: Box<Type>,
        bound: Option<u64>,
    },
    Map {
        key: Box<Type>,
        value: Box<Type>,
        bound: Option<u64>,
    },
    Array {
        elem: Box<Type>,
        dims: Vec<u64>,
    },
    Fixed {
        digits: u32,
        scale: u32,
    },
    Named {
        decl: DeclId,
        name: String,
    },
    /// A reference that failed to resolve (an error was reported).
    Error,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", content = "value", rename_all = "lowercase")]
pub enum Value {
    Int(i128),
    Float(f64),
    Fixed(String),
    Char(char),
    WChar(char),
    Str(String),
    WStr(String),
    Bool(bool),
    /// Enumerator `index` of enum `decl`.
    Enum(DeclId, usize),
}

#[derive(Clone, Debug, Serialize)]
pub struct Field {
    pub name: String,
    pub ty: Type,
    pub key: bool,
    pub optional: bool,
    pub external: bool,
    pub must_understand: bool,
    pub non_serialized: bool,
    pub id: Option<u32>,
    /// `@hashid` (`Some("")` for the member's own name).
    pub hashid: Option<String>,
    pub default: Option<Value>,
    pub min: Option<Value>,
    pub max: Option<Value>,
    pub unit: Option<String>,
    pub doc: Vec<String>,
    #[serde(skip)]
    pub loc: Loc,
}

#[derive(Clone, Debug, Serialize)]
pub struct Struct {
    pub base: Option<DeclId>,
    pub fields: Vec<Field>,
    pub extensibility: Extensibility,
    pub autoid: AutoId,
    pub nested: bool,
}

#[derive(Clone, Debug, Serialize)]
pub struct UnionCase {
    pub name: String,
    pub labels: Vec<Value>,
    pub is_default: bool,
    pub ty: Type,
    pub external: bool,
    pub id: Option<u32>,
    pub doc: Vec<String>,
    #[serde(skip)]
    pub loc: Loc,
    #[serde(skip)]
    pub label_locs: Vec<Loc>,
    /// Where a second `default:` label would be reported.
    #[serde(skip)]
    pub default_loc: Option<Loc>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Union {
    pub discriminator: Type,
    pub disc_key: bool,
    pub cases: Vec<UnionCase>,
    pub extensibility: Extensibility,
    pub nested: bool,
}

#[derive(Clone, Debug, Serialize)]
pub struct Enumerator {
    pub name: String,
    pub value: i64,
    pub doc: Vec<String>,
    #[serde(skip)]
    pub loc: Loc,
}

#[derive(Clone, Debug, Serialize)]
pub struct Enum {
    pub enumerators: Vec<Enumerator>,
    pub bit_bound: Option<u32>,
    pub default_index: usize,
    pub extensibility: Extensibility,
}

#[derive(Clone, Debug, Serialize)]
pub struct Flag {
    pub name: String,
    pub position: u32,
    pub doc: Vec<String>,
    #[serde(skip)]
    pub loc: Loc,
}

#[derive(Clone, Debug, Serialize)]
pub struct Bitmask {
    pub flags: Vec<Flag>,
    pub bit_bound: u32,
}

#[derive(Clone, Debug, Serialize)]
pub struct BitField {
    /// `None` for anonymous padding.
    pub name: Option<String>,
    pub offset: u32,
    pub width: u32,
    pub dest: Prim,
    #[serde(skip)]
    pub loc: Loc,
}

#[derive(Clone, Debug, Serialize)]
pub struct Bitset {
    pub base: Option<DeclId>,
    /// All fields including the base's, in bit order.
    pub fields: Vec<BitField>,
    pub bits: u32,
}

#[derive(Clone, Debug, Serialize)]
pub struct Const {
    pub ty: Type,
    pub value: Value,
}

#[derive(Clone, Debug, Serialize)]
#[serde(tag = "decl", rename_all = "lowercase")]
pub enum DeclKind {
    Struct(Struct),
    Union(Union),
    Enum(Enum),
    Bitmask(Bitmask),
    Bitset(Bitset),
    Alias {
        ty: Type,
    },
    Const(Const),
    /// Declared forward and (so far) not defined.
    Forward {
        union: bool,
    },
}

#[derive(Clone, Debug, Serialize)]
pub struct Verbatim {
    pub placement: String,
    pub text: String,
}

#[derive(Clone, Debug, Serialize)]
pub struct Decl {
    /// Enclosing modules, outermost first (IDL names).
    pub scope: Vec<String>,
    pub name: String,
    pub kind: DeclKind,
    pub doc: Vec<String>,
    pub verbatim: Vec<Verbatim>,
    #[serde(skip)]
    pub loc: Loc,
}

impl Decl {
    /// `Mod::Sub::Name`.
    pub fn scoped_name(&self) -> String {
        let mut s = self.scope.join("::");
        if !s.is_empty() {
            s.push_str("::");
        }
        s.push_str(&self.name);
        s
    }
}

#[derive(Clone, Debug, Default, Serialize)]
pub struct Module {
    pub name: String,
    pub decls: Vec<DeclId>,
    pub modules: Vec<Module>,
}

impl Module {
    pub fn module_mut(&mut self, path: &[String]) -> &mut Module {
        let mut m = self;
        for p in path {
            let i = match m.modules.iter().position(|x| &x.name == p) {
                Some(i) => i,
                None => {
                    m.modules.push(Module {
                        name: p.clone(),
                        ..Default::default()
                    });
                    m.modules.len() - 1
                }
            };
            m = &mut m.modules[i];
        }
        m
    }
}

#[derive(Clone, Debug, Default, Serialize)]
pub struct Model {
    pub root: Module,
    pub decls: Vec<Decl>,
}

impl Model {
    pub fn decl(&self, id: DeclId) -> &Decl {
        &self.decls[id]
    }

    /// Follows aliases to the underlying type.
    pub fn resolve_alias<'a>(&'a self, mut t: &'a Type) -> &'a Type {
        for _ in 0..64 {
            match t {
                Type::Named { decl, .. } => match &self.decls[*decl].kind {
                    DeclKind::Alias { ty } => t = ty,
                    _ => return t,
                },
                _ => return t,
            }
        }
        t
    }
}
