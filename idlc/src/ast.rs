//! Syntax tree as written, before name resolution. Every node carries the [`Loc`] of its source text.
use crate::source::Loc;

#[derive(Clone, Debug)]
pub struct Ident {
    /// The name with an escaping leading `_` removed.
    pub name: String,
    pub loc: Loc,
}

#[derive(Clone, Debug)]
pub struct ScopedName {
    pub absolute: bool,
    pub parts: Vec<Ident>,
    pub loc: Loc,
}

impl ScopedName {
    pub fn text(&self) -> String {
        let s = self
            .parts
            .iter()
            .map(|p| p.name.as_str())
            .collect::<Vec<_>>()
            .join("::");
        if self.absolute {
            format!("::{s}")
        } else {
            s
        }
    }
}

#[derive(Clone, Debug)]
pub enum AnnotationParams {
    None,
    Single(ConstExpr),
    Named(Vec<(Ident, ConstExpr)>),
}

#[derive(Clone, Debug)]
pub struct Annotation {
    pub name: ScopedName,
    pub params: AnnotationParams,
    pub loc: Loc,
    /// Came from a `//@key` comment.
    pub legacy: bool,
}

#[derive(Clone, Debug)]
pub enum Literal {
    Int(u128),
    Float(f64),
    /// Decimal digits of a fixed-point literal, as written (without the `d`).
    Fixed(String),
    Char(char),
    WChar(char),
    Str(String),
    WStr(String),
    Bool(bool),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnaryOp {
    Neg,
    Plus,
    Not,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinOp {
    Or,
    Xor,
    And,
    Shl,
    Shr,
    Add,
    Sub,
    Mul,
    Div,
    Mod,
}

impl BinOp {
    pub fn symbol(self) -> &'static str {
        match self {
            BinOp::Or => "|",
            BinOp::Xor => "^",
            BinOp::And => "&",
            BinOp::Shl => "<<",
            BinOp::Shr => ">>",
            BinOp::Add => "+",
            BinOp::Sub => "-",
            BinOp::Mul => "*",
            BinOp::Div => "/",
            BinOp::Mod => "%",
        }
    }
}

#[derive(Clone, Debug)]
pub enum ExprKind {
    Literal(Literal),
    Name(ScopedName),
    Unary(UnaryOp, Box<ConstExpr>),
    Binary(BinOp, Box<ConstExpr>, Box<ConstExpr>),
}

#[derive(Clone, Debug)]
pub struct ConstExpr {
    pub kind: ExprKind,
    pub loc: Loc,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub enum Prim {
    Bool,
    Octet,
    Char,
    WChar,
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
    F128,
    Any,
    Object,
}

impl Prim {
    pub fn idl_name(self) -> &'static str {
        match self {
            Prim::Bool => "boolean",
            Prim::Octet => "octet",
            Prim::Char => "char",
            Prim::WChar => "wchar",
            Prim::I8 => "int8",
            Prim::U8 => "uint8",
            Prim::I16 => "short",
            Prim::U16 => "unsigned short",
            Prim::I32 => "long",
            Prim::U32 => "unsigned long",
            Prim::I64 => "long long",
            Prim::U64 => "unsigned long long",
            Prim::F32 => "float",
            Prim::F64 => "double",
            Prim::F128 => "long double",
            Prim::Any => "any",
            Prim::Object => "Object",
        }
    }
    pub fn is_integer(self) -> bool {
        matches!(
            self,
            Prim::I8
                | Prim::U8
                | Prim::I16
                | Prim::U16
                | Prim::I32
                | Prim::U32
                | Prim::I64
                | Prim::U64
        )
    }
    /// Inclusive range of an integer type.
    pub fn int_range(self) -> Option<(i128, i128)> {
        Some(match self {
            Prim::I8 => (i8::MIN as i128, i8::MAX as i128),
            Prim::U8 | Prim::Octet => (0, u8::MAX as i128),
            Prim::I16 => (i16::MIN as i128, i16::MAX as i128),
            Prim::U16 => (0, u16::MAX as i128),
            Prim::I32 => (i32::MIN as i128, i32::MAX as i128),
            Prim::U32 => (0, u32::MAX as i128),
            Prim::I64 => (i64::MIN as i128, i64::MAX as i128),
            Prim::U64 => (0, u64::MAX as i128),
            _ => return None,
        })
    }
}

#[derive(Clone, Debug)]
pub enum TypeSpec {
    Prim(Prim, Loc),
    String {
        wide: bool,
        bound: Option<ConstExpr>,
        loc: Loc,
    },
    Sequence {
        elem: Box<TypeSpec>,
        bound: Option<ConstExpr>,
        loc: Loc,
    },
    Map {
        key: Box<TypeSpec>,
        value: Box<TypeSpec>,
        bound: Option<ConstExpr>,
        loc: Loc,
    },
    Fixed {
        digits: Option<ConstExpr>,
        scale: Option<ConstExpr>,
        loc: Loc,
    },
    Named(ScopedName),
}

impl TypeSpec {
    pub fn loc(&self) -> Loc {
        match self {
            TypeSpec::Prim(_, l) => *l,
            TypeSpec::String { loc, .. }
            | TypeSpec::Sequence { loc, .. }
            | TypeSpec::Map { loc, .. }
            | TypeSpec::Fixed { loc, .. } => *loc,
            TypeSpec::Named(n) => n.loc,
        }
    }
}

#[derive(Clone, Debug)]
pub struct Declarator {
    pub name: Ident,
    pub dims: Vec<ConstExpr>,
}

#[derive(Clone, Debug)]
pub struct Member {
    pub annotations: Vec<Annotation>,
    pub ty: TypeSpec,
    pub declarators: Vec<Declarator>,
    pub doc: Vec<String>,
    pub loc: Loc,
}

#[derive(Clone, Debug)]
pub struct StructDef {
    pub name: Ident,
    pub base: Option<ScopedName>,
    pub members: Vec<Member>,
}

#[derive(Clone, Debug)]
pub enum CaseLabel {
    Value(ConstExpr),
    Default(Loc),
}

#[derive(Clone, Debug)]
pub struct Case {
    pub labels: Vec<CaseLabel>,
    pub annotations: Vec<Annotation>,
    pub ty: TypeSpec,
    pub declarator: Declarator,
    pub doc: Vec<String>,
    pub loc: Loc,
}

#[derive(Clone, Debug)]
pub struct UnionDef {
    pub name: Ident,
    pub switch_annotations: Vec<Annotation>,
    pub switch: TypeSpec,
    pub cases: Vec<Case>,
}

#[derive(Clone, Debug)]
pub struct Enumerator {
    pub annotations: Vec<Annotation>,
    pub name: Ident,
    /// `= value` after the name (C style, not IDL 4.2; enums only).
    pub value: Option<ConstExpr>,
    pub doc: Vec<String>,
}

#[derive(Clone, Debug)]
pub struct EnumDef {
    pub name: Ident,
    pub enumerators: Vec<Enumerator>,
}

#[derive(Clone, Debug)]
pub struct BitmaskDef {
    pub name: Ident,
    pub values: Vec<Enumerator>,
}

#[derive(Clone, Debug)]
pub struct Bitfield {
    pub annotations: Vec<Annotation>,
    pub width: ConstExpr,
    pub dest: Option<Prim>,
    /// Empty for an anonymous bitfield (padding).
    pub names: Vec<Ident>,
    pub loc: Loc,
}

#[derive(Clone, Debug)]
pub struct BitsetDef {
    pub name: Ident,
    pub base: Option<ScopedName>,
    pub fields: Vec<Bitfield>,
}

#[derive(Clone, Debug)]
pub enum TypedefTarget {
    Spec(TypeSpec),
    /// `typedef struct X {..} Y;` and friends: the inner definition comes first.
    Constructed(Box<Definition>),
}

#[derive(Clone, Debug)]
pub struct Typedef {
    pub target: TypedefTarget,
    pub declarators: Vec<Declarator>,
}

#[derive(Clone, Debug)]
pub struct ConstDef {
    pub ty: TypeSpec,
    pub name: Ident,
    pub value: ConstExpr,
}

#[derive(Clone, Debug)]
pub struct AnnotationMember {
    pub ty: TypeSpec,
    pub name: Ident,
    pub default: Option<ConstExpr>,
}

#[derive(Clone, Debug)]
pub struct AnnotationDef {
    pub name: Ident,
    pub members: Vec<AnnotationMember>,
    pub inner: Vec<Definition>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ForwardKind {
    Struct,
    Union,
}

#[derive(Clone, Debug)]
pub enum DefKind {
    Module {
        name: Ident,
        defs: Vec<Definition>,
    },
    Struct(StructDef),
    Union(UnionDef),
    Forward(ForwardKind, Ident),
    Enum(EnumDef),
    Bitmask(BitmaskDef),
    Bitset(BitsetDef),
    Typedef(Typedef),
    Const(ConstDef),
    Annotation(AnnotationDef),
    /// Interfaces, exceptions, native and value types: parsed, no Rust emitted.
    Unsupported {
        what: &'static str,
        name: Ident,
    },
    /// `#pragma keylist Type member...`
    Keylist {
        ty: ScopedName,
        keys: Vec<Vec<Ident>>,
    },
}

#[derive(Clone, Debug)]
pub struct Definition {
    pub annotations: Vec<Annotation>,
    pub kind: DefKind,
    pub doc: Vec<String>,
    pub loc: Loc,
}

#[derive(Clone, Debug, Default)]
pub struct Spec {
    pub defs: Vec<Definition>,
}
