//! Syntax tree as written, before name resolution. Every node carries the [`Loc`] of its source text.
use crate::source::Loc;

/// A name as written.
#[derive(Clone, Debug)]
pub struct Ident {
    /// The name with an escaping leading `_` removed.
    pub name: String,
    /// Where it is written.
    pub loc: Loc,
}

/// A possibly qualified name (`a::b`, `::a`).
#[derive(Clone, Debug)]
pub struct ScopedName {
    /// Starts with `::` (from the global scope).
    pub absolute: bool,
    /// The parts between `::`.
    pub parts: Vec<Ident>,
    /// Where the whole name is written.
    pub loc: Loc,
}

impl ScopedName {
    /// The name as written, with `::` between parts.
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

/// Parameters of an annotation application.
#[derive(Clone, Debug)]
pub enum AnnotationParams {
    /// `@a`: none.
    None,
    /// `@a(expr)`: one unnamed value.
    Single(ConstExpr),
    /// `@a(name = expr, ...)`.
    Named(Vec<(Ident, ConstExpr)>),
}

/// An annotation application (`@key`, `@id(3)`, ...).
#[derive(Clone, Debug)]
pub struct Annotation {
    /// The annotation's name.
    pub name: ScopedName,
    /// Its parameters.
    pub params: AnnotationParams,
    /// Where it is written.
    pub loc: Loc,
    /// Came from a `//@key` comment.
    pub legacy: bool,
}

/// A literal value.
#[derive(Clone, Debug)]
pub enum Literal {
    /// Integer (magnitude; a minus sign is a unary operator).
    Int(u128),
    /// Floating point.
    Float(f64),
    /// Decimal digits of a fixed-point literal, as written (without the `d`).
    Fixed(String),
    /// `'c'`.
    Char(char),
    /// `L'c'`.
    WChar(char),
    /// `"text"` (adjacent literals joined).
    Str(String),
    /// `L"text"`.
    WStr(String),
    /// `TRUE` / `FALSE`.
    Bool(bool),
}

/// Unary operators.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnaryOp {
    /// `-`
    Neg,
    /// `+`
    Plus,
    /// `~`
    Not,
}

/// Binary operators, lowest precedence first.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinOp {
    /// `|`
    Or,
    /// `^`
    Xor,
    /// `&`
    And,
    /// `<<`
    Shl,
    /// `>>`
    Shr,
    /// `+`
    Add,
    /// `-`
    Sub,
    /// `*`
    Mul,
    /// `/`
    Div,
    /// `%`
    Mod,
}

impl BinOp {
    /// The operator as written.
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

/// What a constant expression is.
#[derive(Clone, Debug)]
pub enum ExprKind {
    /// A literal.
    Literal(Literal),
    /// A constant or enumerator, by name.
    Name(ScopedName),
    /// An operator applied to one operand.
    Unary(UnaryOp, Box<ConstExpr>),
    /// An operator applied to two operands.
    Binary(BinOp, Box<ConstExpr>, Box<ConstExpr>),
}

/// A constant expression.
#[derive(Clone, Debug)]
pub struct ConstExpr {
    /// Its form.
    pub kind: ExprKind,
    /// Where it is written.
    pub loc: Loc,
}

/// Basic (primitive) types.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub enum Prim {
    /// `boolean`
    Bool,
    /// `octet`
    Octet,
    /// `char`
    Char,
    /// `wchar`
    WChar,
    /// `int8`
    I8,
    /// `uint8`
    U8,
    /// `short`, `int16`
    I16,
    /// `unsigned short`, `uint16`
    U16,
    /// `long`, `int32`
    I32,
    /// `unsigned long`, `uint32`
    U32,
    /// `long long`, `int64`
    I64,
    /// `unsigned long long`, `uint64`
    U64,
    /// `float`
    F32,
    /// `double`
    F64,
    /// `long double`
    F128,
    /// `any`
    Any,
    /// `Object`
    Object,
}

impl Prim {
    /// The IDL spelling.
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
    /// An integer type (not `octet`, `char` or `boolean`).
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

/// A type as written.
#[derive(Clone, Debug)]
pub enum TypeSpec {
    /// A basic type.
    Prim(Prim, Loc),
    /// `string`, `string<N>`, `wstring`, ...
    String {
        /// `wstring`.
        wide: bool,
        /// `<N>`, if any.
        bound: Option<ConstExpr>,
        /// Where it is written.
        loc: Loc,
    },
    /// `sequence<T>` or `sequence<T, N>`.
    Sequence {
        /// Element type.
        elem: Box<TypeSpec>,
        /// `N`, if any.
        bound: Option<ConstExpr>,
        /// Where it is written.
        loc: Loc,
    },
    /// `map<K, V>` or `map<K, V, N>`.
    Map {
        /// Key type.
        key: Box<TypeSpec>,
        /// Value type.
        value: Box<TypeSpec>,
        /// `N`, if any.
        bound: Option<ConstExpr>,
        /// Where it is written.
        loc: Loc,
    },
    /// `fixed<D, S>`, or bare `fixed` in a constant declaration.
    Fixed {
        /// `D`: total digits.
        digits: Option<ConstExpr>,
        /// `S`: digits after the point.
        scale: Option<ConstExpr>,
        /// Where it is written.
        loc: Loc,
    },
    /// A declared type, by name.
    Named(ScopedName),
}

impl TypeSpec {
    /// Where the type is written.
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

/// A declared name with optional array dimensions (`a[3][4]`).
#[derive(Clone, Debug)]
pub struct Declarator {
    /// The name.
    pub name: Ident,
    /// Array sizes, outermost first.
    pub dims: Vec<ConstExpr>,
}

/// A struct member declaration (one type, one or more declarators).
#[derive(Clone, Debug)]
pub struct Member {
    /// Annotations before it.
    pub annotations: Vec<Annotation>,
    /// The type.
    pub ty: TypeSpec,
    /// The names declared.
    pub declarators: Vec<Declarator>,
    /// Doc comment lines before it.
    pub doc: Vec<String>,
    /// Where it is written.
    pub loc: Loc,
}

/// `struct Name [: Base] { ... }`.
#[derive(Clone, Debug)]
pub struct StructDef {
    /// The name.
    pub name: Ident,
    /// The base struct, if any.
    pub base: Option<ScopedName>,
    /// The members.
    pub members: Vec<Member>,
}

/// A union case label.
#[derive(Clone, Debug)]
pub enum CaseLabel {
    /// `case expr:`
    Value(ConstExpr),
    /// `default:` and where it is written.
    Default(Loc),
}

/// A union case: labels and one member.
#[derive(Clone, Debug)]
pub struct Case {
    /// Its labels.
    pub labels: Vec<CaseLabel>,
    /// Annotations on the member.
    pub annotations: Vec<Annotation>,
    /// The member's type.
    pub ty: TypeSpec,
    /// The member's name.
    pub declarator: Declarator,
    /// Doc comment lines before it.
    pub doc: Vec<String>,
    /// Where it is written.
    pub loc: Loc,
}

/// `union Name switch (T) { ... }`.
#[derive(Clone, Debug)]
pub struct UnionDef {
    /// The name.
    pub name: Ident,
    /// Annotations inside `switch (...)`.
    pub switch_annotations: Vec<Annotation>,
    /// The discriminator type.
    pub switch: TypeSpec,
    /// The cases.
    pub cases: Vec<Case>,
}

/// An enumerator (or a bitmask flag).
#[derive(Clone, Debug)]
pub struct Enumerator {
    /// Annotations before it.
    pub annotations: Vec<Annotation>,
    /// The name.
    pub name: Ident,
    /// `= value` after the name (C style, not IDL 4.2; enums only).
    pub value: Option<ConstExpr>,
    /// Doc comment lines before it.
    pub doc: Vec<String>,
}

/// `enum Name { ... }`.
#[derive(Clone, Debug)]
pub struct EnumDef {
    /// The name.
    pub name: Ident,
    /// The enumerators.
    pub enumerators: Vec<Enumerator>,
}

/// `bitmask Name { ... }`.
#[derive(Clone, Debug)]
pub struct BitmaskDef {
    /// The name.
    pub name: Ident,
    /// The flags.
    pub values: Vec<Enumerator>,
}

/// `bitfield<W[, T]> names;` inside a bitset.
#[derive(Clone, Debug)]
pub struct Bitfield {
    /// Annotations before it.
    pub annotations: Vec<Annotation>,
    /// `W`: width in bits.
    pub width: ConstExpr,
    /// `T`: the type it is read as, if given.
    pub dest: Option<Prim>,
    /// Empty for an anonymous bitfield (padding).
    pub names: Vec<Ident>,
    /// Where it is written.
    pub loc: Loc,
}

/// `bitset Name [: Base] { ... }`.
#[derive(Clone, Debug)]
pub struct BitsetDef {
    /// The name.
    pub name: Ident,
    /// The base bitset, if any.
    pub base: Option<ScopedName>,
    /// The bitfields.
    pub fields: Vec<Bitfield>,
}

/// What a typedef names.
#[derive(Clone, Debug)]
pub enum TypedefTarget {
    /// A type.
    Spec(TypeSpec),
    /// `typedef struct X {..} Y;` and friends: the inner definition comes first.
    Constructed(Box<Definition>),
}

/// `typedef T a, b[3];`.
#[derive(Clone, Debug)]
pub struct Typedef {
    /// What the names stand for.
    pub target: TypedefTarget,
    /// The names declared.
    pub declarators: Vec<Declarator>,
}

/// `const T NAME = expr;`.
#[derive(Clone, Debug)]
pub struct ConstDef {
    /// The declared type.
    pub ty: TypeSpec,
    /// The name.
    pub name: Ident,
    /// The value.
    pub value: ConstExpr,
}

/// A member of an annotation declaration.
#[derive(Clone, Debug)]
pub struct AnnotationMember {
    /// Its type.
    pub ty: TypeSpec,
    /// Its name.
    pub name: Ident,
    /// `default expr`, if any.
    pub default: Option<ConstExpr>,
}

/// `@annotation Name { ... }`.
#[derive(Clone, Debug)]
pub struct AnnotationDef {
    /// The name.
    pub name: Ident,
    /// Its members.
    pub members: Vec<AnnotationMember>,
    /// Enums, constants and typedefs declared inside.
    pub inner: Vec<Definition>,
}

/// What a forward declaration announces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ForwardKind {
    /// `struct X;`
    Struct,
    /// `union X;`
    Union,
}

/// The kinds of definition.
#[derive(Clone, Debug)]
pub enum DefKind {
    /// `module name { ... }`.
    Module {
        /// The module name.
        name: Ident,
        /// Its definitions.
        defs: Vec<Definition>,
    },
    /// A struct.
    Struct(StructDef),
    /// A union.
    Union(UnionDef),
    /// A forward declaration.
    Forward(ForwardKind, Ident),
    /// An enum.
    Enum(EnumDef),
    /// A bitmask.
    Bitmask(BitmaskDef),
    /// A bitset.
    Bitset(BitsetDef),
    /// A typedef.
    Typedef(Typedef),
    /// A constant.
    Const(ConstDef),
    /// An annotation declaration.
    Annotation(AnnotationDef),
    /// Interfaces, exceptions, native and value types: parsed, no Rust emitted.
    Unsupported {
        /// `interface`, `exception`, ...
        what: &'static str,
        /// The name declared.
        name: Ident,
    },
    /// `#pragma keylist Type member...`
    Keylist {
        /// The type named.
        ty: ScopedName,
        /// Key member paths (`a.b`), each split at `.`.
        keys: Vec<Vec<Ident>>,
    },
}

/// One definition with what precedes it.
#[derive(Clone, Debug)]
pub struct Definition {
    /// Annotations before it.
    pub annotations: Vec<Annotation>,
    /// What it defines.
    pub kind: DefKind,
    /// Doc comment lines before it.
    pub doc: Vec<String>,
    /// Where it is written.
    pub loc: Loc,
}

/// A parsed specification (or piece of one): top-level definitions in order.
#[derive(Clone, Debug, Default)]
pub struct Spec {
    /// The definitions.
    pub defs: Vec<Definition>,
}
