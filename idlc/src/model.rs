//! The resolved type model: every name is resolved to a declaration, every constant evaluated, every
//! annotation interpreted. This is what the back ends read (and what `--emit json` prints).
use crate::ast::Prim;
use crate::source::Loc;
use serde::Serialize;

/// Index of a declaration in [`Model::decls`].
pub type DeclId = usize;

/// XTypes extensibility kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Extensibility {
    /// `@final`
    Final,
    /// `@appendable`
    Appendable,
    /// `@mutable`
    Mutable,
}

impl Extensibility {
    /// The `#[dds(...)]` spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            Extensibility::Final => "final",
            Extensibility::Appendable => "appendable",
            Extensibility::Mutable => "mutable",
        }
    }
}

/// `@autoid`: how member ids are assigned when not given.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum AutoId {
    /// One after the other (the default).
    #[default]
    Sequential,
    /// A hash of the member name.
    Hash,
}

/// A resolved type.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Type {
    /// A basic type.
    Prim {
        /// Which one.
        prim: Prim,
    },
    /// `string` or `wstring`.
    String {
        /// `wstring`.
        wide: bool,
        /// Maximum length, if bounded.
        bound: Option<u64>,
    },
    /// `sequence<T[, N]>`.
    Sequence {
        /// Element type.
        elem: Box<Type>,
        /// Maximum length, if bounded.
        bound: Option<u64>,
    },
    /// `map<K, V[, N]>`.
    Map {
        /// Key type.
        key: Box<Type>,
        /// Value type.
        value: Box<Type>,
        /// Maximum entries, if bounded.
        bound: Option<u64>,
    },
    /// An array (from declarator dimensions).
    Array {
        /// Element type.
        elem: Box<Type>,
        /// Sizes, outermost first.
        dims: Vec<u64>,
    },
    /// `fixed<D, S>`.
    Fixed {
        /// `D`: total digits.
        digits: u32,
        /// `S`: digits after the point.
        scale: u32,
    },
    /// A declared type (struct, union, enum, alias, ...).
    Named {
        /// The declaration.
        decl: DeclId,
        /// Its scoped name (for messages).
        name: String,
    },
    /// A reference that failed to resolve (an error was reported).
    Error,
}

/// A constant value.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", content = "value", rename_all = "lowercase")]
pub enum Value {
    /// Any integer type.
    Int(i128),
    /// `float`, `double`, `long double`.
    Float(f64),
    /// Fixed point: the decimal digits as written.
    Fixed(String),
    /// `char`.
    Char(char),
    /// `wchar`.
    WChar(char),
    /// `string`.
    Str(String),
    /// `wstring`.
    WStr(String),
    /// `boolean`.
    Bool(bool),
    /// Enumerator `index` of enum `decl`.
    Enum(DeclId, usize),
}

/// A struct member.
#[derive(Clone, Debug, Serialize)]
pub struct Field {
    /// Its IDL name.
    pub name: String,
    /// Its type.
    pub ty: Type,
    /// `@key`.
    pub key: bool,
    /// `@optional`.
    pub optional: bool,
    /// `@external`.
    pub external: bool,
    /// `@must_understand`.
    pub must_understand: bool,
    /// `@non_serialized`.
    pub non_serialized: bool,
    /// `@id`, if given (ids are otherwise assigned by the back end).
    pub id: Option<u32>,
    /// `@hashid` (`Some("")` for the member's own name).
    pub hashid: Option<String>,
    /// `@default`.
    pub default: Option<Value>,
    /// `@min`.
    pub min: Option<Value>,
    /// `@max`.
    pub max: Option<Value>,
    /// `@unit`.
    pub unit: Option<String>,
    /// Doc comment lines.
    pub doc: Vec<String>,
    /// Where it is declared.
    #[serde(skip)]
    pub loc: Loc,
}

/// A struct.
#[derive(Clone, Debug, Serialize)]
pub struct Struct {
    /// The base struct, if any.
    pub base: Option<DeclId>,
    /// Its members (without the base's).
    pub fields: Vec<Field>,
    /// Its extensibility.
    pub extensibility: Extensibility,
    /// How member ids are assigned.
    pub autoid: AutoId,
    /// `@nested`: not a topic type.
    pub nested: bool,
}

/// One case of a union.
#[derive(Clone, Debug, Serialize)]
pub struct UnionCase {
    /// Its member name.
    pub name: String,
    /// Its labels (empty for `default` alone).
    pub labels: Vec<Value>,
    /// Carries the `default` label.
    pub is_default: bool,
    /// Its member type.
    pub ty: Type,
    /// `@external`.
    pub external: bool,
    /// `@id`, if given.
    pub id: Option<u32>,
    /// Doc comment lines.
    pub doc: Vec<String>,
    /// Where the member is declared.
    #[serde(skip)]
    pub loc: Loc,
    /// Where each label is written.
    #[serde(skip)]
    pub label_locs: Vec<Loc>,
    /// Where a second `default:` label would be reported.
    #[serde(skip)]
    pub default_loc: Option<Loc>,
}

/// A union.
#[derive(Clone, Debug, Serialize)]
pub struct Union {
    /// The discriminator type.
    pub discriminator: Type,
    /// `@key` on the discriminator.
    pub disc_key: bool,
    /// The cases.
    pub cases: Vec<UnionCase>,
    /// Its extensibility.
    pub extensibility: Extensibility,
    /// `@nested`: not a topic type.
    pub nested: bool,
}

/// An enumerator.
#[derive(Clone, Debug, Serialize)]
pub struct Enumerator {
    /// Its name.
    pub name: String,
    /// Its value.
    pub value: i64,
    /// Doc comment lines.
    pub doc: Vec<String>,
    /// Where it is declared.
    #[serde(skip)]
    pub loc: Loc,
}

/// An enum.
#[derive(Clone, Debug, Serialize)]
pub struct Enum {
    /// The enumerators, in order.
    pub enumerators: Vec<Enumerator>,
    /// `@bit_bound`, if given.
    pub bit_bound: Option<u32>,
    /// Index of the `@default_literal` (0 when none).
    pub default_index: usize,
    /// Its extensibility.
    pub extensibility: Extensibility,
}

/// A bitmask flag.
#[derive(Clone, Debug, Serialize)]
pub struct Flag {
    /// Its name.
    pub name: String,
    /// Its bit position.
    pub position: u32,
    /// Doc comment lines.
    pub doc: Vec<String>,
    /// Where it is declared.
    #[serde(skip)]
    pub loc: Loc,
}

/// A bitmask.
#[derive(Clone, Debug, Serialize)]
pub struct Bitmask {
    /// The flags.
    pub flags: Vec<Flag>,
    /// `@bit_bound` (32 by default).
    pub bit_bound: u32,
}

/// A bitfield of a bitset.
#[derive(Clone, Debug, Serialize)]
pub struct BitField {
    /// `None` for anonymous padding.
    pub name: Option<String>,
    /// First bit, counted from the least significant.
    pub offset: u32,
    /// Width in bits.
    pub width: u32,
    /// The type it is read as.
    pub dest: Prim,
    /// Where it is declared.
    #[serde(skip)]
    pub loc: Loc,
}

/// A bitset.
#[derive(Clone, Debug, Serialize)]
pub struct Bitset {
    /// The base bitset, if any.
    pub base: Option<DeclId>,
    /// All fields including the base's, in bit order.
    pub fields: Vec<BitField>,
    /// Total bits, base included.
    pub bits: u32,
}

/// A constant.
#[derive(Clone, Debug, Serialize)]
pub struct Const {
    /// Its type.
    pub ty: Type,
    /// Its value.
    pub value: Value,
}

/// What a declaration declares.
#[derive(Clone, Debug, Serialize)]
#[serde(tag = "decl", rename_all = "lowercase")]
pub enum DeclKind {
    /// A struct.
    Struct(Struct),
    /// A union.
    Union(Union),
    /// An enum.
    Enum(Enum),
    /// A bitmask.
    Bitmask(Bitmask),
    /// A bitset.
    Bitset(Bitset),
    /// A typedef.
    Alias {
        /// The type it names.
        ty: Type,
    },
    /// A constant.
    Const(Const),
    /// Declared forward and (so far) not defined.
    Forward {
        /// A union (not a struct).
        union: bool,
    },
}

/// `@verbatim` text for the back end.
#[derive(Clone, Debug, Serialize)]
pub struct Verbatim {
    /// Where it goes (`BEGIN_FILE`, `BEFORE_DECLARATION`, ...).
    pub placement: String,
    /// The text.
    pub text: String,
}

/// A declaration in the model.
#[derive(Clone, Debug, Serialize)]
pub struct Decl {
    /// Enclosing modules, outermost first (IDL names).
    pub scope: Vec<String>,
    /// Its name in its scope.
    pub name: String,
    /// What it declares.
    pub kind: DeclKind,
    /// Doc comment lines.
    pub doc: Vec<String>,
    /// `@verbatim` texts.
    pub verbatim: Vec<Verbatim>,
    /// Where it is declared.
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

/// A module and what it contains.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Module {
    /// Its name (empty for the root).
    pub name: String,
    /// Declarations directly in it, in order.
    pub decls: Vec<DeclId>,
    /// Nested modules, in order.
    pub modules: Vec<Module>,
}

impl Module {
    /// The module at `path` below this one, created when missing.
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

/// The resolved model of a whole specification.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Model {
    /// The root module.
    pub root: Module,
    /// Every declaration; [`DeclId`] indexes this.
    pub decls: Vec<Decl>,
}

impl Model {
    /// The declaration `id`.
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
