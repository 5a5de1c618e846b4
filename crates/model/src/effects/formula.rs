//! The formula language of custom terms: a small arithmetic parser and a compiled evaluator.
//!
//! Hand-written because evaluation is on the simulator's hot path (every right-hand side of every step
//! of every shot of a fit): a formula compiles once into a postfix program over a value stack whose depth
//! is known at compile time, so evaluating it allocates nothing and costs a few nanoseconds per operation,
//! whatever the number of names it uses. Parsing reports every problem with its character position, so
//! the model file's error can put a caret under it.
//!
//! Grammar (usual precedence; `^` binds tighter than a unary minus and groups to the right, so
//! `-x^2 = -(x^2)` and `2^3^2 = 2^9`):
//!
//! ```text
//! expr   := term (('+' | '-') term)*
//! term   := unary (('*' | '/') unary)*
//! unary  := ('-' | '+') unary | power
//! power  := atom ('^' unary)?
//! atom   := number | name | name '(' expr (',' expr)* ')' | '(' expr ')'
//! number := digits ['.' digits] [('e' | 'E') ['+' | '-'] digits]   (also '.5', '5.')
//! ```

use std::cell::RefCell;
use std::fmt;

/// Longest formula accepted, in characters (bounds parsing time and nesting).
pub(crate) const MAX_FORMULA_CHARS: usize = 2000;
/// Deepest nesting of parentheses, function calls and unary signs accepted (bounds the parser's recursion).
const MAX_NESTING: usize = 200;

/// A problem in a formula: where (character index) and what.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SyntaxError {
    /// Character index of the problem (the formula's length for "ends too early").
    pub pos: usize,
    /// What is wrong, as a sentence fragment for a person.
    pub message: String,
}

impl fmt::Display for SyntaxError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "at character {}: {}", self.pos + 1, self.message)
    }
}

/// A function of one argument.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Func1 {
    Abs,
    Signum,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Sinh,
    Cosh,
    Tanh,
    Asinh,
    Acosh,
    Atanh,
    Floor,
    Round,
    Ceil,
    Trunc,
    Fract,
    Exp,
    Sqrt,
    Cbrt,
    Ln,
    Log2,
    Log10,
}

/// A function of two arguments.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Func2 {
    Min,
    Max,
    Atan2,
}

const FUNCS1: [(&str, Func1); 26] = [
    ("abs", Func1::Abs),
    ("signum", Func1::Signum),
    ("sin", Func1::Sin),
    ("cos", Func1::Cos),
    ("tan", Func1::Tan),
    ("asin", Func1::Asin),
    ("acos", Func1::Acos),
    ("atan", Func1::Atan),
    ("sinh", Func1::Sinh),
    ("cosh", Func1::Cosh),
    ("tanh", Func1::Tanh),
    ("asinh", Func1::Asinh),
    ("acosh", Func1::Acosh),
    ("atanh", Func1::Atanh),
    ("floor", Func1::Floor),
    ("round", Func1::Round),
    ("ceil", Func1::Ceil),
    ("trunc", Func1::Trunc),
    ("fract", Func1::Fract),
    ("exp", Func1::Exp),
    ("sqrt", Func1::Sqrt),
    ("cbrt", Func1::Cbrt),
    ("ln", Func1::Ln),
    ("log", Func1::Ln),
    ("log2", Func1::Log2),
    ("log10", Func1::Log10),
];

const FUNCS2: [(&str, Func2); 3] = [("min", Func2::Min), ("max", Func2::Max), ("atan2", Func2::Atan2)];

/// Named constants, used when a name is neither a state variable nor a parameter.
const CONSTANTS: [(&str, f64); 7] = [
    ("PI", std::f64::consts::PI),
    ("pi", std::f64::consts::PI),
    ("π", std::f64::consts::PI),
    ("E", std::f64::consts::E),
    ("e", std::f64::consts::E),
    ("TAU", std::f64::consts::TAU),
    ("τ", std::f64::consts::TAU),
];

/// The function names, for messages.
pub(crate) fn function_names() -> String {
    let mut v: Vec<String> = FUNCS1.iter().map(|(n, _)| format!("{n}(x)")).collect();
    v.extend(FUNCS2.iter().map(|(n, _)| format!("{n}(a, b)")));
    v.join(", ")
}

/// The names of the named constants, for messages.
pub(crate) fn constant_names() -> String {
    CONSTANTS.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ")
}

impl Func1 {
    #[inline]
    fn apply(self, a: f64) -> f64 {
        match self {
            Func1::Abs => a.abs(),
            Func1::Signum => a.signum(),
            Func1::Sin => a.sin(),
            Func1::Cos => a.cos(),
            Func1::Tan => a.tan(),
            Func1::Asin => a.asin(),
            Func1::Acos => a.acos(),
            Func1::Atan => a.atan(),
            Func1::Sinh => a.sinh(),
            Func1::Cosh => a.cosh(),
            Func1::Tanh => a.tanh(),
            Func1::Asinh => a.asinh(),
            Func1::Acosh => a.acosh(),
            Func1::Atanh => a.atanh(),
            Func1::Floor => a.floor(),
            Func1::Round => a.round(),
            Func1::Ceil => a.ceil(),
            Func1::Trunc => a.trunc(),
            Func1::Fract => a.fract(),
            Func1::Exp => a.exp(),
            Func1::Sqrt => a.sqrt(),
            Func1::Cbrt => a.cbrt(),
            Func1::Ln => a.ln(),
            Func1::Log2 => a.log2(),
            Func1::Log10 => a.log10(),
        }
    }
}

impl Func2 {
    #[inline]
    fn apply(self, a: f64, b: f64) -> f64 {
        match self {
            Func2::Min => a.min(b),
            Func2::Max => a.max(b),
            Func2::Atan2 => a.atan2(b),
        }
    }
}

/// A parsed formula, before names are bound.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Ast {
    Num(f64),
    /// A name and the character index where it first appears.
    Name(String, usize),
    Neg(Box<Ast>),
    Add(Box<Ast>, Box<Ast>),
    Sub(Box<Ast>, Box<Ast>),
    Mul(Box<Ast>, Box<Ast>),
    Div(Box<Ast>, Box<Ast>),
    Pow(Box<Ast>, Box<Ast>),
    Call1(Func1, Box<Ast>),
    Call2(Func2, Box<Ast>, Box<Ast>),
}

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Num(f64),
    Name(String),
    Op(char),
    Open,
    Close,
    Comma,
}

fn is_name_start(c: char) -> bool {
    c.is_alphabetic() || c == '_'
}

fn is_name_char(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// Splits `text` into tokens with their character positions.
fn lex(text: &str) -> Result<Vec<(Tok, usize)>, SyntaxError> {
    let chars: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let start = i;
        if c.is_whitespace() {
            i += 1;
            continue;
        }
        if c.is_ascii_digit() || (c == '.' && chars.get(i + 1).is_some_and(|d| d.is_ascii_digit())) {
            while i < chars.len() && chars[i].is_ascii_digit() {
                i += 1;
            }
            if i < chars.len() && chars[i] == '.' {
                i += 1;
                while i < chars.len() && chars[i].is_ascii_digit() {
                    i += 1;
                }
            }
            // An exponent only if digits follow (`2e` or `2exp(…)` are not numbers with exponents).
            if i < chars.len() && (chars[i] == 'e' || chars[i] == 'E') {
                let mut j = i + 1;
                if j < chars.len() && (chars[j] == '+' || chars[j] == '-') {
                    j += 1;
                }
                if j < chars.len() && chars[j].is_ascii_digit() {
                    while j < chars.len() && chars[j].is_ascii_digit() {
                        j += 1;
                    }
                    i = j;
                }
            }
            let s: String = chars[start..i].iter().collect();
            let v: f64 = s.parse().map_err(|_| SyntaxError {
                pos: start,
                message: format!("`{s}` is not a number"),
            })?;
            if !v.is_finite() {
                return Err(SyntaxError {
                    pos: start,
                    message: format!("the number `{s}` is too large for a 64-bit float"),
                });
            }
            if i < chars.len() && is_name_start(chars[i]) {
                return Err(SyntaxError {
                    pos: i,
                    message: format!(
                        "a name right after the number `{s}`: write the product with `*` (e.g. `{s} * {}`), or an exponent as `{s}e3`",
                        chars[i..].iter().take_while(|c| is_name_char(**c)).collect::<String>()
                    ),
                });
            }
            out.push((Tok::Num(v), start));
            continue;
        }
        if is_name_start(c) {
            while i < chars.len() && is_name_char(chars[i]) {
                i += 1;
            }
            out.push((Tok::Name(chars[start..i].iter().collect()), start));
            continue;
        }
        let tok = match c {
            '+' | '-' | '*' | '/' | '^' => Tok::Op(c),
            '−' => Tok::Op('-'),
            '·' | '×' => Tok::Op('*'),
            '(' => Tok::Open,
            ')' => Tok::Close,
            ',' => Tok::Comma,
            _ => {
                return Err(SyntaxError {
                    pos: i,
                    message: format!(
                        "unexpected character `{c}` (a formula uses numbers, names, + - * / ^, parentheses and commas)"
                    ),
                });
            }
        };
        out.push((tok, start));
        i += 1;
    }
    Ok(out)
}

struct Parser {
    toks: Vec<(Tok, usize)>,
    i: usize,
    end: usize,
    depth: usize,
}

impl Parser {
    fn peek(&self) -> Option<&Tok> {
        self.toks.get(self.i).map(|(t, _)| t)
    }

    fn pos(&self) -> usize {
        self.toks.get(self.i).map(|(_, p)| *p).unwrap_or(self.end)
    }

    fn err<T>(&self, pos: usize, message: impl Into<String>) -> Result<T, SyntaxError> {
        Err(SyntaxError {
            pos,
            message: message.into(),
        })
    }

    fn enter(&mut self) -> Result<(), SyntaxError> {
        self.depth += 1;
        if self.depth > MAX_NESTING {
            return self.err(self.pos(), format!("nested more than {MAX_NESTING} levels deep"));
        }
        Ok(())
    }

    fn expr(&mut self) -> Result<Ast, SyntaxError> {
        let mut lhs = self.term()?;
        while let Some(Tok::Op(op @ ('+' | '-'))) = self.peek() {
            let op = *op;
            self.i += 1;
            let rhs = self.term()?;
            lhs = if op == '+' {
                Ast::Add(Box::new(lhs), Box::new(rhs))
            } else {
                Ast::Sub(Box::new(lhs), Box::new(rhs))
            };
        }
        Ok(lhs)
    }

    fn term(&mut self) -> Result<Ast, SyntaxError> {
        let mut lhs = self.unary()?;
        while let Some(Tok::Op(op @ ('*' | '/'))) = self.peek() {
            let op = *op;
            self.i += 1;
            let rhs = self.unary()?;
            lhs = if op == '*' {
                Ast::Mul(Box::new(lhs), Box::new(rhs))
            } else {
                Ast::Div(Box::new(lhs), Box::new(rhs))
            };
        }
        Ok(lhs)
    }

    fn unary(&mut self) -> Result<Ast, SyntaxError> {
        match self.peek() {
            Some(Tok::Op(op @ ('-' | '+'))) => {
                let neg = *op == '-';
                self.i += 1;
                self.enter()?;
                let inner = self.unary()?;
                self.depth -= 1;
                Ok(if neg { Ast::Neg(Box::new(inner)) } else { inner })
            }
            _ => self.power(),
        }
    }

    fn power(&mut self) -> Result<Ast, SyntaxError> {
        let base = self.atom()?;
        if let Some(Tok::Op('^')) = self.peek() {
            self.i += 1;
            self.enter()?;
            let exp = self.unary()?;
            self.depth -= 1;
            return Ok(Ast::Pow(Box::new(base), Box::new(exp)));
        }
        Ok(base)
    }

    fn atom(&mut self) -> Result<Ast, SyntaxError> {
        let pos = self.pos();
        let Some(tok) = self.peek().cloned() else {
            return self.err(pos, "the formula ends where a number, a name or `(` is expected");
        };
        self.i += 1;
        match tok {
            Tok::Num(v) => Ok(Ast::Num(v)),
            Tok::Open => {
                self.enter()?;
                let inner = self.expr()?;
                self.depth -= 1;
                match self.peek() {
                    Some(Tok::Close) => {
                        self.i += 1;
                        Ok(inner)
                    }
                    Some(Tok::Comma) => self.err(self.pos(), "a `,` outside the arguments of a function"),
                    _ => self.err(self.pos(), "an operator (+ - * / ^) or `)` is missing here"),
                }
            }
            Tok::Name(name) => {
                if self.peek() != Some(&Tok::Open) {
                    return Ok(Ast::Name(name, pos));
                }
                self.i += 1;
                self.enter()?;
                let mut args = vec![self.expr()?];
                while self.peek() == Some(&Tok::Comma) {
                    self.i += 1;
                    args.push(self.expr()?);
                }
                self.depth -= 1;
                if self.peek() != Some(&Tok::Close) {
                    return self.err(self.pos(), "an operator (+ - * / ^), `,` or `)` is missing here");
                }
                self.i += 1;
                let n = args.len();
                if let Some((_, f)) = FUNCS1.iter().find(|(s, _)| *s == name) {
                    if n != 1 {
                        return self.err(pos, format!("`{name}` takes 1 argument, not {n}"));
                    }
                    return Ok(Ast::Call1(*f, Box::new(args.pop().expect("one argument"))));
                }
                if let Some((_, f)) = FUNCS2.iter().find(|(s, _)| *s == name) {
                    if n != 2 {
                        return self.err(pos, format!("`{name}` takes 2 arguments, not {n}"));
                    }
                    let b = args.pop().expect("two arguments");
                    let a = args.pop().expect("two arguments");
                    return Ok(Ast::Call2(*f, Box::new(a), Box::new(b)));
                }
                self.err(
                    pos,
                    format!(
                        "unknown function `{name}` (known: {}); a product needs `*`",
                        function_names()
                    ),
                )
            }
            Tok::Close => self.err(pos, "this `)` closes nothing, or a value is missing before it"),
            Tok::Comma => self.err(pos, "a `,` outside the arguments of a function"),
            Tok::Op(c) => self.err(pos, format!("a value is missing before `{c}`")),
        }
    }
}

/// Parses `text` into an expression tree.
pub(crate) fn parse(text: &str) -> Result<Ast, SyntaxError> {
    let n_chars = text.chars().count();
    if n_chars > MAX_FORMULA_CHARS {
        return Err(SyntaxError {
            pos: 0,
            message: format!("formula longer than {MAX_FORMULA_CHARS} characters"),
        });
    }
    let toks = lex(text)?;
    // Parentheses first, so an unbalanced one is named where it is, not where the parser gives up.
    let mut open = Vec::new();
    for (t, p) in &toks {
        match t {
            Tok::Open => open.push(*p),
            Tok::Close if open.pop().is_none() => {
                return Err(SyntaxError {
                    pos: *p,
                    message: "this `)` closes nothing".into(),
                });
            }
            _ => {}
        }
    }
    if let Some(p) = open.pop() {
        return Err(SyntaxError {
            pos: p,
            message: "this `(` is never closed".into(),
        });
    }
    if toks.is_empty() {
        return Err(SyntaxError {
            pos: 0,
            message: "the formula is empty".into(),
        });
    }
    let mut p = Parser {
        toks,
        i: 0,
        end: n_chars,
        depth: 0,
    };
    let ast = p.expr()?;
    if let Some(tok) = p.peek() {
        let pos = p.pos();
        let message = match tok {
            Tok::Close => "this `)` closes nothing".to_string(),
            Tok::Comma => "a `,` outside the arguments of a function".to_string(),
            _ => "an operator (+ - * / ^) is missing before this".to_string(),
        };
        return Err(SyntaxError { pos, message });
    }
    Ok(ast)
}

/// The value of a named constant.
pub(crate) fn constant(name: &str) -> Option<f64> {
    CONSTANTS.iter().find(|(n, _)| *n == name).map(|(_, v)| *v)
}

/// One instruction of a compiled formula; `V` says where a name's value comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Op<V> {
    Const(f64),
    Load(V),
    Neg,
    Add,
    Sub,
    Mul,
    Div,
    Pow,
    Call1(Func1),
    Call2(Func2),
}

/// A formula compiled into a postfix program over a value stack.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Program<V> {
    ops: Vec<Op<V>>,
    /// Largest number of values on the stack at once.
    depth: usize,
}

/// Values on the stack held in an array on the machine stack; deeper formulas use a per-thread buffer.
const INLINE_STACK: usize = 32;

thread_local! {
    static DEEP_STACK: RefCell<Vec<f64>> = const { RefCell::new(Vec::new()) };
}

impl<V: Copy> Program<V> {
    /// Compiles `ast`, binding each name with `bind` (which returns `None` for a name it does not know; the
    /// name and its position are then returned as the error).
    pub(crate) fn compile(ast: &Ast, bind: &mut impl FnMut(&str) -> Option<V>) -> Result<Program<V>, (String, usize)> {
        let mut ops = Vec::new();
        emit(ast, bind, &mut ops)?;
        let mut depth = 0usize;
        let mut max = 0usize;
        for op in &ops {
            match op {
                Op::Const(_) | Op::Load(_) => depth += 1,
                Op::Neg | Op::Call1(_) => {}
                _ => depth -= 1,
            }
            max = max.max(depth);
        }
        Ok(Program { ops, depth: max })
    }

    /// Evaluates the program, reading each loaded value with `load`. Allocates nothing (after a thread's
    /// first formula deeper than 32 pending values).
    #[inline]
    pub(crate) fn eval(&self, load: impl Fn(V) -> f64) -> f64 {
        if self.depth <= INLINE_STACK {
            let mut stack = [0.0f64; INLINE_STACK];
            self.run(&mut stack, &load)
        } else {
            DEEP_STACK.with(|s| {
                let mut s = s.borrow_mut();
                if s.len() < self.depth {
                    s.resize(self.depth, 0.0);
                }
                self.run(&mut s, &load)
            })
        }
    }

    #[inline]
    fn run(&self, stack: &mut [f64], load: &impl Fn(V) -> f64) -> f64 {
        let mut n = 0usize;
        for op in &self.ops {
            match *op {
                Op::Const(v) => {
                    stack[n] = v;
                    n += 1;
                }
                Op::Load(v) => {
                    stack[n] = load(v);
                    n += 1;
                }
                Op::Neg => stack[n - 1] = -stack[n - 1],
                Op::Call1(f) => stack[n - 1] = f.apply(stack[n - 1]),
                Op::Add => {
                    n -= 1;
                    stack[n - 1] += stack[n];
                }
                Op::Sub => {
                    n -= 1;
                    stack[n - 1] -= stack[n];
                }
                Op::Mul => {
                    n -= 1;
                    stack[n - 1] *= stack[n];
                }
                Op::Div => {
                    n -= 1;
                    stack[n - 1] /= stack[n];
                }
                Op::Pow => {
                    n -= 1;
                    stack[n - 1] = stack[n - 1].powf(stack[n]);
                }
                Op::Call2(f) => {
                    n -= 1;
                    stack[n - 1] = f.apply(stack[n - 1], stack[n]);
                }
            }
        }
        stack[0]
    }
}

fn emit<V: Copy>(
    ast: &Ast,
    bind: &mut impl FnMut(&str) -> Option<V>,
    ops: &mut Vec<Op<V>>,
) -> Result<(), (String, usize)> {
    let mut binary = |x: &Ast, y: &Ast, op: Op<V>, ops: &mut Vec<Op<V>>| -> Result<(), (String, usize)> {
        emit(x, bind, ops)?;
        emit(y, bind, ops)?;
        ops.push(op);
        Ok(())
    };
    match ast {
        Ast::Num(v) => ops.push(Op::Const(*v)),
        Ast::Name(n, p) => match bind(n) {
            Some(v) => ops.push(Op::Load(v)),
            None => match constant(n) {
                Some(c) => ops.push(Op::Const(c)),
                None => return Err((n.clone(), *p)),
            },
        },
        Ast::Neg(x) => {
            emit(x, bind, ops)?;
            ops.push(Op::Neg);
        }
        Ast::Call1(f, x) => {
            emit(x, bind, ops)?;
            ops.push(Op::Call1(*f));
        }
        Ast::Add(x, y) => binary(x, y, Op::Add, ops)?,
        Ast::Sub(x, y) => binary(x, y, Op::Sub, ops)?,
        Ast::Mul(x, y) => binary(x, y, Op::Mul, ops)?,
        Ast::Div(x, y) => binary(x, y, Op::Div, ops)?,
        Ast::Pow(x, y) => binary(x, y, Op::Pow, ops)?,
        Ast::Call2(f, x, y) => binary(x, y, Op::Call2(*f), ops)?,
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn eval_with(text: &str, vars: &[(&str, f64)]) -> Result<f64, String> {
        let ast = parse(text).map_err(|e| e.to_string())?;
        let prog = Program::compile(&ast, &mut |n: &str| vars.iter().position(|(v, _)| *v == n))
            .map_err(|(n, _)| format!("unbound {n}"))?;
        Ok(prog.eval(|i| vars[i].1))
    }

    fn val(text: &str) -> f64 {
        eval_with(text, &[("x", 3.0), ("delta", 2e-3)]).unwrap()
    }

    #[test]
    fn precedence_and_associativity_are_the_usual_ones() {
        assert_eq!(val("1 + 2 * 3"), 7.0);
        assert_eq!(val("(1 + 2) * 3"), 9.0);
        assert_eq!(val("8 / 4 / 2"), 1.0);
        assert_eq!(val("8 - 4 - 2"), 2.0);
        assert_eq!(val("2 ^ 3 ^ 2"), 512.0);
        assert_eq!(val("-x ^ 2"), -9.0);
        assert_eq!(val("2 ^ -1"), 0.5);
        assert_eq!(val("- - x"), 3.0);
        assert_eq!(val("x * -2"), -6.0);
        assert_eq!(val("max(x, 4) + min(1, x) + atan2(0, 1)"), 5.0);
        assert_eq!(val("2 · x − 1"), 5.0);
    }

    #[test]
    fn scientific_notation_is_a_number() {
        assert_eq!(val("1e3*delta"), 2.0);
        assert_eq!(val("2.5E-4"), 2.5e-4);
        assert_eq!(val("1e+2"), 100.0);
        assert_eq!(val(".5 + 5."), 5.5);
        assert_eq!(val("exp(0)"), 1.0);
        // `e` alone is Euler's number; `2e` is a number followed by a name, which needs a `*`.
        assert_eq!(val("e"), std::f64::consts::E);
        let err = parse("2e").unwrap_err();
        assert_eq!(err.pos, 1, "{err}");
        assert!(err.message.contains("`*`"), "{err}");
    }

    #[test]
    fn errors_point_at_the_problem() {
        let cases = [
            ("2 * (delta + ", 4, "never closed"),
            ("delta)", 5, "closes nothing"),
            ("foo(delta)", 0, "unknown function `foo`"),
            ("sin(1, 2)", 0, "takes 1 argument"),
            ("2delta", 1, "name right after the number"),
            ("2 delta", 2, "operator"),
            ("x x", 2, "operator"),
            ("x +", 3, "ends where"),
            ("x # 2", 2, "unexpected character `#`"),
            ("", 0, "empty"),
            ("   ", 0, "empty"),
            ("* x", 0, "missing before `*`"),
            ("1e999", 0, "too large"),
            ("(1, 2)", 2, ","),
        ];
        for (text, pos, needle) in cases {
            let e = parse(text).unwrap_err();
            assert_eq!(e.pos, pos, "{text:?}: {e}");
            assert!(e.message.contains(needle), "{text:?}: {e}");
        }
        let deep = format!("{}x{}", "(".repeat(500), ")".repeat(500));
        assert!(parse(&deep).unwrap_err().message.contains("nested"));
        let long = "x+".repeat(1200) + "x";
        assert!(parse(&long).unwrap_err().message.contains("longer than"));
    }

    #[test]
    fn any_number_of_names_and_deep_stacks_evaluate() {
        let names: Vec<String> = (0..100).map(|i| format!("p{i}")).collect();
        let vars: Vec<(&str, f64)> = names.iter().enumerate().map(|(i, n)| (n.as_str(), i as f64)).collect();
        let sum = names.join(" + ");
        assert_eq!(eval_with(&sum, &vars).unwrap(), 4950.0);
        // Right-nested: every operand waits on the stack (deeper than the inline stack).
        let nested = names.iter().map(|n| format!("({n} + ")).collect::<String>() + "0" + &")".repeat(100);
        assert_eq!(eval_with(&nested, &vars).unwrap(), 4950.0);
    }

    /// A random expression tree over two variables, with its text.
    fn arb_ast() -> impl Strategy<Value = Ast> {
        let leaf = prop_oneof![
            (-1e3f64..1e3).prop_map(Ast::Num),
            (1e-6f64..1e6).prop_map(Ast::Num),
            Just(Ast::Name("x".into(), 0)),
            Just(Ast::Name("delta".into(), 0)),
        ];
        leaf.prop_recursive(6, 48, 2, |inner| {
            prop_oneof![
                inner.clone().prop_map(|a| Ast::Neg(Box::new(a))),
                (inner.clone(), inner.clone()).prop_map(|(a, b)| Ast::Add(Box::new(a), Box::new(b))),
                (inner.clone(), inner.clone()).prop_map(|(a, b)| Ast::Sub(Box::new(a), Box::new(b))),
                (inner.clone(), inner.clone()).prop_map(|(a, b)| Ast::Mul(Box::new(a), Box::new(b))),
                (inner.clone(), inner.clone()).prop_map(|(a, b)| Ast::Div(Box::new(a), Box::new(b))),
                (inner.clone(), inner.clone()).prop_map(|(a, b)| Ast::Pow(Box::new(a), Box::new(b))),
                inner.clone().prop_map(|a| Ast::Call1(Func1::Sin, Box::new(a))),
                inner.clone().prop_map(|a| Ast::Call1(Func1::Exp, Box::new(a))),
                (inner.clone(), inner).prop_map(|(a, b)| Ast::Call2(Func2::Max, Box::new(a), Box::new(b))),
            ]
        })
    }

    /// Writes `a` fully parenthesised, numbers in Rust's shortest round-trip form (scientific when long).
    fn text_of(a: &Ast) -> String {
        match a {
            Ast::Num(v) if v.is_sign_negative() => format!("({v:e})"),
            Ast::Num(v) => format!("{v:e}"),
            Ast::Name(n, _) => n.clone(),
            Ast::Neg(x) => format!("(-{})", text_of(x)),
            Ast::Add(x, y) => format!("({} + {})", text_of(x), text_of(y)),
            Ast::Sub(x, y) => format!("({} - {})", text_of(x), text_of(y)),
            Ast::Mul(x, y) => format!("({} * {})", text_of(x), text_of(y)),
            Ast::Div(x, y) => format!("({} / {})", text_of(x), text_of(y)),
            Ast::Pow(x, y) => format!("({} ^ {})", text_of(x), text_of(y)),
            Ast::Call1(f, x) => {
                let name = FUNCS1.iter().find(|(_, g)| g == f).map(|(n, _)| *n).unwrap_or("?");
                format!("{name}({})", text_of(x))
            }
            Ast::Call2(_, x, y) => format!("max({}, {})", text_of(x), text_of(y)),
        }
    }

    /// The reference: the tree evaluated directly by Rust.
    fn reference(a: &Ast, x: f64, d: f64) -> f64 {
        match a {
            Ast::Num(v) => *v,
            Ast::Name(n, _) => {
                if n == "x" {
                    x
                } else {
                    d
                }
            }
            Ast::Neg(p) => -reference(p, x, d),
            Ast::Add(p, q) => reference(p, x, d) + reference(q, x, d),
            Ast::Sub(p, q) => reference(p, x, d) - reference(q, x, d),
            Ast::Mul(p, q) => reference(p, x, d) * reference(q, x, d),
            Ast::Div(p, q) => reference(p, x, d) / reference(q, x, d),
            Ast::Pow(p, q) => reference(p, x, d).powf(reference(q, x, d)),
            Ast::Call1(f, p) => f.apply(reference(p, x, d)),
            Ast::Call2(f, p, q) => f.apply(reference(p, x, d), reference(q, x, d)),
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

        #[test]
        fn random_text_never_panics(s in "[ -~πδω·−]{0,60}") {
            if let Ok(ast) = parse(&s) {
                let prog = Program::compile(&ast, &mut |_: &str| Some(0usize));
                if let Ok(p) = prog {
                    let _ = p.eval(|_| 1.5);
                }
            }
        }

        #[test]
        fn random_formula_like_text_never_panics(
            parts in proptest::collection::vec(
                prop_oneof![
                    Just("x"), Just("delta"), Just("1e3"), Just("2.5E-4"), Just("("), Just(")"), Just("+"),
                    Just("-"), Just("*"), Just("/"), Just("^"), Just("sin("), Just("max("), Just(","), Just(" "),
                    Just("e"), Just("."), Just("7"),
                ],
                0..40,
            )
        ) {
            let s: String = parts.concat();
            if let Ok(ast) = parse(&s)
                && let Ok(p) = Program::compile(&ast, &mut |n: &str| (n == "x" || n == "delta").then_some(0usize)) {
                    let _ = p.eval(|_| 0.25);
                }
        }

        #[test]
        fn compiled_formulas_match_the_tree_evaluated_directly(ast in arb_ast(), x in -10.0f64..10.0, d in 0.0f64..0.01) {
            let text = text_of(&ast);
            let parsed = parse(&text).map_err(|e| TestCaseError::fail(format!("{text}: {e}")))?;
            let prog = Program::compile(&parsed, &mut |n: &str| match n {
                "x" => Some(0usize),
                "delta" => Some(1usize),
                _ => None,
            })
            .map_err(|(n, _)| TestCaseError::fail(format!("unbound {n}")))?;
            let got = prog.eval(|i| if i == 0 { x } else { d });
            let want = reference(&ast, x, d);
            prop_assert!(
                got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()),
                "{} = {} (reference {})", text, got, want
            );
        }
    }
}
