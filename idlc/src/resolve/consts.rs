//! Constant expressions: evaluation with the full IDL operator set, type checks and overflow checks.
use super::Resolver;
use crate::ast::{BinOp, ConstExpr, ExprKind, Literal, Prim, UnaryOp};
use crate::diag::{Code, Diagnostic};
use crate::model::{DeclKind, Type, Value};
use crate::source::Loc;

const MIN: i128 = i64::MIN as i128;
const MAX: i128 = u64::MAX as i128;

impl Resolver<'_> {
    fn cerr(&mut self, code: Code, loc: Loc, msg: String, label: &str) -> Option<Value> {
        self.diags.push(Diagnostic::error(code, msg).at(loc, label));
        None
    }

    /// Evaluates `e` and converts it to `ty`, reporting range and type errors.
    pub(crate) fn eval_as(&mut self, e: &ConstExpr, ty: &Type) -> Option<Value> {
        let target = self.model.resolve_alias(ty).clone();
        let unsigned_max = match &target {
            Type::Prim { prim } => prim.int_range().filter(|r| r.0 == 0).map(|r| r.1),
            _ => None,
        };
        let v = self.eval(e, unsigned_max)?;
        self.coerce(v, &target, e.loc)
    }

    /// Evaluates an expression that must be a non-negative integer (bounds, sizes, ids).
    pub(crate) fn eval_u64(&mut self, e: &ConstExpr, what: &str, min: u64) -> Option<u64> {
        match self.eval(e, None)? {
            Value::Int(v) if v >= min as i128 && v <= u64::MAX as i128 => Some(v as u64),
            Value::Int(v) => {
                let msg = format!("{what} must be at least {min}, but is {v}");
                self.cerr(Code::BadBound, e.loc, msg, "this value");
                None
            }
            other => {
                let msg = format!("{what} must be an integer, found {}", describe(&other));
                self.cerr(Code::ConstType, e.loc, msg, "not an integer");
                None
            }
        }
    }

    pub(crate) fn coerce(&mut self, v: Value, target: &Type, loc: Loc) -> Option<Value> {
        let tname = self.type_name(target);
        match (target, v) {
            (Type::Prim { prim }, Value::Int(i)) if prim.int_range().is_some() => {
                let (lo, hi) = prim.int_range().expect("integer");
                if i < lo || i > hi {
                    let msg = format!("value {i} does not fit in `{tname}` (range {lo}..={hi})");
                    return self.cerr(Code::Overflow, loc, msg, "out of range");
                }
                Some(Value::Int(i))
            }
            (
                Type::Prim {
                    prim: Prim::F32 | Prim::F64 | Prim::F128,
                },
                Value::Int(i),
            ) => Some(Value::Float(i as f64)),
            (Type::Prim { prim }, Value::Float(f))
                if matches!(prim, Prim::F32 | Prim::F64 | Prim::F128) =>
            {
                if *prim == Prim::F32 && f.is_finite() && f.abs() > f32::MAX as f64 {
                    return self.cerr(
                        Code::Overflow,
                        loc,
                        format!("value {f} does not fit in `float`"),
                        "out of range",
                    );
                }
                Some(Value::Float(f))
            }
            (Type::Prim { prim: Prim::Bool }, Value::Bool(b)) => Some(Value::Bool(b)),
            (Type::Prim { prim: Prim::Char }, Value::Char(c)) => Some(Value::Char(c)),
            (Type::Prim { prim: Prim::WChar }, Value::Char(c) | Value::WChar(c)) => {
                Some(Value::WChar(c))
            }
            (Type::String { wide, bound }, Value::Str(s) | Value::WStr(s)) => {
                if let Some(b) = bound {
                    if s.chars().count() as u64 > *b {
                        let msg = format!(
                            "string of length {} does not fit in `{tname}`",
                            s.chars().count()
                        );
                        return self.cerr(Code::Overflow, loc, msg, "too long");
                    }
                }
                Some(if *wide { Value::WStr(s) } else { Value::Str(s) })
            }
            (Type::Fixed { .. }, Value::Fixed(s)) => Some(Value::Fixed(s)),
            (Type::Fixed { .. }, Value::Int(i)) => Some(Value::Fixed(i.to_string())),
            (Type::Fixed { .. }, Value::Float(f)) => Some(Value::Fixed(f.to_string())),
            (Type::Named { decl, .. }, Value::Enum(d, i)) if *decl == d => Some(Value::Enum(d, i)),
            (Type::Error, _) => None,
            (_, v) => {
                let msg = format!("expected a value of type `{tname}`, found {}", describe(&v));
                self.cerr(Code::ConstType, loc, msg, "wrong type")
            }
        }
    }

    /// Untyped evaluation. `unsigned_max` gives `~` its meaning for unsigned targets.
    pub(crate) fn eval(&mut self, e: &ConstExpr, unsigned_max: Option<i128>) -> Option<Value> {
        match &e.kind {
            ExprKind::Literal(l) => Some(match l {
                Literal::Int(v) => Value::Int(*v as i128),
                Literal::Float(f) => Value::Float(*f),
                Literal::Fixed(s) => Value::Fixed(s.clone()),
                Literal::Char(c) => Value::Char(*c),
                Literal::WChar(c) => Value::WChar(*c),
                Literal::Str(s) => Value::Str(s.clone()),
                Literal::WStr(s) => Value::WStr(s.clone()),
                Literal::Bool(b) => Value::Bool(*b),
            }),
            ExprKind::Name(n) => {
                let sym = self.lookup_value(n)?;
                Some(sym)
            }
            ExprKind::Unary(op, inner) => {
                let v = self.eval(inner, unsigned_max)?;
                match (op, v) {
                    (UnaryOp::Plus, v @ (Value::Int(_) | Value::Float(_))) => Some(v),
                    (UnaryOp::Neg, Value::Int(i)) => self.check_range(-i, e.loc),
                    (UnaryOp::Neg, Value::Float(f)) => Some(Value::Float(-f)),
                    (UnaryOp::Neg, Value::Fixed(s)) => Some(Value::Fixed(
                        s.strip_prefix('-')
                            .map(str::to_string)
                            .unwrap_or(format!("-{s}")),
                    )),
                    (UnaryOp::Not, Value::Int(i)) => Some(Value::Int(match unsigned_max {
                        Some(m) if i >= 0 => m ^ i,
                        _ => !i,
                    })),
                    (op, v) => {
                        let sym = match op {
                            UnaryOp::Neg => "-",
                            UnaryOp::Plus => "+",
                            UnaryOp::Not => "~",
                        };
                        let msg = format!("operator `{sym}` cannot be applied to {}", describe(&v));
                        self.cerr(Code::ConstType, e.loc, msg, "invalid operand")
                    }
                }
            }
            ExprKind::Binary(op, l, r) => {
                let a = self.eval(l, unsigned_max)?;
                let b = self.eval(r, unsigned_max)?;
                self.binary(*op, a, b, e.loc, r.loc)
            }
        }
    }

    fn check_range(&mut self, v: i128, loc: Loc) -> Option<Value> {
        if !(MIN..=MAX).contains(&v) {
            let msg =
                format!("constant expression overflows: {v} is outside every IDL integer type");
            return self.cerr(Code::Overflow, loc, msg, "overflows here");
        }
        Some(Value::Int(v))
    }

    fn binary(&mut self, op: BinOp, a: Value, b: Value, loc: Loc, rloc: Loc) -> Option<Value> {
        use BinOp::*;
        match (a, b) {
            (Value::Int(x), Value::Int(y)) => {
                let r = match op {
                    Or => Some(x | y),
                    Xor => Some(x ^ y),
                    And => Some(x & y),
                    Shl | Shr if !(0..64).contains(&y) => {
                        let msg = format!("shift amount {y} is out of range (0..64)");
                        return self.cerr(Code::Overflow, rloc, msg, "shift amount");
                    }
                    Shl => x.checked_shl(y as u32),
                    Shr => Some(x >> y),
                    Add => x.checked_add(y),
                    Sub => x.checked_sub(y),
                    Mul => x.checked_mul(y),
                    Div | Mod if y == 0 => {
                        return self.cerr(
                            Code::DivZero,
                            rloc,
                            "division by zero".into(),
                            "this is zero",
                        )
                    }
                    Div => x.checked_div(y),
                    Mod => x.checked_rem(y),
                };
                match r {
                    Some(v) => self.check_range(v, loc),
                    None => self.cerr(
                        Code::Overflow,
                        loc,
                        "constant expression overflows".into(),
                        "overflows here",
                    ),
                }
            }
            (a @ (Value::Int(_) | Value::Float(_)), b @ (Value::Int(_) | Value::Float(_)))
                if matches!(op, Add | Sub | Mul | Div) =>
            {
                let (x, y) = (as_f64(&a), as_f64(&b));
                if op == Div && y == 0.0 {
                    return self.cerr(
                        Code::DivZero,
                        rloc,
                        "division by zero".into(),
                        "this is zero",
                    );
                }
                let r = match op {
                    Add => x + y,
                    Sub => x - y,
                    Mul => x * y,
                    _ => x / y,
                };
                if !r.is_finite() {
                    return self.cerr(
                        Code::Overflow,
                        loc,
                        "floating-point constant overflows".into(),
                        "overflows here",
                    );
                }
                Some(Value::Float(r))
            }
            (a, b) => {
                let msg = format!(
                    "operator `{}` cannot be applied to {} and {}",
                    op.symbol(),
                    describe(&a),
                    describe(&b)
                );
                self.cerr(Code::ConstType, loc, msg, "invalid operands")
            }
        }
    }

    fn lookup_value(&mut self, n: &crate::ast::ScopedName) -> Option<Value> {
        let sym = self.resolve_name(n, "constant")?;
        match sym {
            super::scope::Sym::Enumerator(d, i) => Some(Value::Enum(d, i)),
            super::scope::Sym::Decl(d) => match &self.model.decls[d].kind {
                DeclKind::Const(c) => Some(c.value.clone()),
                _ => {
                    let msg = format!("`{}` is a type, not a constant", n.text());
                    self.cerr(Code::NotAType, n.loc, msg, "not a constant")
                }
            },
            _ => {
                let msg = format!("`{}` is not a constant", n.text());
                self.cerr(Code::NotAType, n.loc, msg, "not a constant")
            }
        }
    }
}

fn as_f64(v: &Value) -> f64 {
    match v {
        Value::Int(i) => *i as f64,
        Value::Float(f) => *f,
        _ => 0.0,
    }
}

pub(crate) fn describe(v: &Value) -> String {
    match v {
        Value::Int(i) => format!("integer {i}"),
        Value::Float(f) => format!("floating-point {f}"),
        Value::Fixed(s) => format!("fixed-point {s}d"),
        Value::Char(c) => format!("character {c:?}"),
        Value::WChar(c) => format!("wide character {c:?}"),
        Value::Str(s) => format!("string {s:?}"),
        Value::WStr(s) => format!("wide string {s:?}"),
        Value::Bool(b) => format!("boolean {}", if *b { "TRUE" } else { "FALSE" }),
        Value::Enum(..) => "an enumerator".into(),
    }
}
