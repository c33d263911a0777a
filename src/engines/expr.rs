//! The expression language of procedural motion units: arithmetic in `f64` over the unit's time
//! and named parameters, compiled once into a tree and evaluated every frame. Written here
//! because no maintained evaluator with a compatible licence has functions of more than two
//! arguments (`exmex` has unary and binary operators only, `mathexpr` no user functions;
//! `evalexpr` is AGPL), and units need `if(c, a, b)`, `hermite(…)` with five and `tcb(…)` with
//! eight.
//!
//! Grammar, loosest first: `||`; `&&`; `==` `!=` `<` `<=` `>` `>=`; `+` `-`; `*` `/` `%`;
//! unary `-` `+` `!`; `^` (right-associative, binding tighter than unary minus on its left:
//! `-2^2` is −4); numbers (`1`, `0.5`, `2e-3`), names and calls `f(a, b, …)`. Truth is non-zero;
//! comparisons and logic give 1 or 0. Functions: `sin cos tan asin acos atan sinh cosh tanh sqrt
//! exp ln abs sign floor ceil round` (one argument), `atan2(y, x)`, `log(x)` (base 10) and
//! `log(b, x)`, `min` and `max` (one or more), `pi` or `pi()`, `e()`, and the curves
//! `if(c, a, b)`, [`hermite`], [`tcb`] and [`perlin`] (one or two arguments). Any other name
//! is a variable, looked up when the expression is evaluated.

use std::fmt;

/// Deepest nesting of parentheses, calls and unary operators (so that no data file can make
/// the recursive parser or evaluator overflow the stack).
pub const MAX_DEPTH: usize = 64;

/// A compiled expression and the text it came from.
#[derive(Clone)]
pub struct Expr {
    text: String,
    root: Node,
}

impl fmt::Debug for Expr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:?}", self.text)
    }
}

#[derive(Debug, Clone)]
enum Node {
    Num(f64),
    Var(String),
    Neg(Box<Node>),
    Not(Box<Node>),
    Bin(Op, Box<Node>, Box<Node>),
    Call(Func, Vec<Node>),
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Op {
    Or,
    And,
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
    Add,
    Sub,
    Mul,
    Div,
    Rem,
    Pow,
}

#[derive(Debug, Clone, Copy)]
enum Func {
    One(fn(f64) -> f64),
    Atan2,
    Log,
    Min,
    Max,
    Pi,
    E,
    If,
    Hermite,
    Tcb,
    Perlin,
}

impl Func {
    /// The function a call names and the argument counts it takes.
    fn named(name: &str) -> Option<(Func, std::ops::RangeInclusive<usize>)> {
        let one = |f: fn(f64) -> f64| Some((Func::One(f), 1..=1));
        match name {
            "sin" => one(f64::sin),
            "cos" => one(f64::cos),
            "tan" => one(f64::tan),
            "asin" => one(f64::asin),
            "acos" => one(f64::acos),
            "atan" => one(f64::atan),
            "sinh" => one(f64::sinh),
            "cosh" => one(f64::cosh),
            "tanh" => one(f64::tanh),
            "sqrt" => one(f64::sqrt),
            "exp" => one(f64::exp),
            "ln" => one(f64::ln),
            "abs" => one(f64::abs),
            "sign" => one(f64::signum),
            "floor" => one(f64::floor),
            "ceil" => one(f64::ceil),
            "round" => one(f64::round),
            "atan2" => Some((Func::Atan2, 2..=2)),
            "log" => Some((Func::Log, 1..=2)),
            "min" => Some((Func::Min, 1..=usize::MAX)),
            "max" => Some((Func::Max, 1..=usize::MAX)),
            "pi" => Some((Func::Pi, 0..=0)),
            "e" => Some((Func::E, 0..=0)),
            "if" => Some((Func::If, 3..=3)),
            "hermite" => Some((Func::Hermite, 5..=5)),
            "tcb" => Some((Func::Tcb, 8..=8)),
            "perlin" => Some((Func::Perlin, 1..=2)),
            _ => None,
        }
    }

    fn apply(self, a: &[f64]) -> f64 {
        match self {
            Func::One(f) => f(a[0]),
            Func::Atan2 => a[0].atan2(a[1]),
            Func::Log if a.len() == 1 => a[0].log10(),
            Func::Log => a[1].log(a[0]),
            Func::Min => a.iter().copied().fold(f64::INFINITY, f64::min),
            Func::Max => a.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            Func::Pi => std::f64::consts::PI,
            Func::E => std::f64::consts::E,
            Func::If => unreachable!("if is evaluated lazily"),
            Func::Hermite => hermite(a[0], a[1], a[2], a[3], a[4]),
            Func::Tcb => tcb([a[0], a[1], a[2], a[3]], a[4], a[5], a[6], a[7]),
            Func::Perlin => perlin(a[0], a.get(1).copied().unwrap_or(0.0)),
        }
    }
}

impl Expr {
    /// Compiles `text`; the error says what is wrong and where (a character offset).
    pub fn compile(text: &str) -> Result<Expr, String> {
        let tokens = tokens(text).map_err(|(at, what)| format!("'{text}': {what} at {at}"))?;
        let mut p = Parser { tokens, at: 0 };
        let root = p
            .expr(0)
            .and_then(|root| match p.peek() {
                None => Ok(root),
                Some(t) => Err(format!("unexpected {t}")),
            })
            .map_err(|e| format!("'{text}' is not an expression: {e}"))?;
        Ok(Expr {
            text: text.to_string(),
            root,
        })
    }

    /// The value with the variables `var` gives; an unknown variable or a value that is not a
    /// finite number is an error naming the expression.
    pub fn eval(&self, var: &dyn Fn(&str) -> Option<f64>) -> Result<f64, String> {
        match eval(&self.root, var) {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(v) => Err(format!("'{}' gives {v}", self.text)),
            Err(name) => Err(format!("'{}': unknown name '{name}'", self.text)),
        }
    }
}

/// Evaluates a node; `Err` names an unknown variable.
fn eval(node: &Node, var: &dyn Fn(&str) -> Option<f64>) -> Result<f64, String> {
    let truth = |b: bool| if b { 1.0 } else { 0.0 };
    Ok(match node {
        Node::Num(v) => *v,
        Node::Var(name) => var(name).ok_or_else(|| name.clone())?,
        Node::Neg(a) => -eval(a, var)?,
        Node::Not(a) => truth(eval(a, var)? == 0.0),
        Node::Bin(Op::And, a, b) => truth(eval(a, var)? != 0.0 && eval(b, var)? != 0.0),
        Node::Bin(Op::Or, a, b) => truth(eval(a, var)? != 0.0 || eval(b, var)? != 0.0),
        Node::Bin(op, a, b) => {
            let (a, b) = (eval(a, var)?, eval(b, var)?);
            match op {
                Op::Eq => truth(a == b),
                Op::Ne => truth(a != b),
                Op::Lt => truth(a < b),
                Op::Le => truth(a <= b),
                Op::Gt => truth(a > b),
                Op::Ge => truth(a >= b),
                Op::Add => a + b,
                Op::Sub => a - b,
                Op::Mul => a * b,
                Op::Div => a / b,
                Op::Rem => a % b,
                Op::Pow => a.powf(b),
                Op::And | Op::Or => unreachable!("handled above"),
            }
        }
        Node::Call(Func::If, args) => {
            let branch = if eval(&args[0], var)? != 0.0 { 1 } else { 2 };
            eval(&args[branch], var)?
        }
        Node::Call(f, args) => {
            let values = args
                .iter()
                .map(|a| eval(a, var))
                .collect::<Result<Vec<f64>, String>>()?;
            f.apply(&values)
        }
    })
}

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Num(f64),
    Name(String),
    Op(&'static str),
}

impl fmt::Display for Tok {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Tok::Num(v) => write!(f, "number {v}"),
            Tok::Name(n) => write!(f, "name '{n}'"),
            Tok::Op(o) => write!(f, "'{o}'"),
        }
    }
}

/// The operators and punctuation, longest first (so that `<=` is not read as `<`).
const SYMBOLS: [&str; 19] = [
    "&&", "||", "==", "!=", "<=", ">=", "<", ">", "+", "-", "*", "/", "%", "^", "!", "(", ")", ",",
    "=",
];

/// Splits `text` into tokens; an error gives the character offset and what is there.
fn tokens(text: &str) -> Result<Vec<Tok>, (usize, String)> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(c) = rest.chars().next() {
        let at = text.len() - rest.len();
        if c.is_whitespace() {
            rest = &rest[c.len_utf8()..];
        } else if c.is_ascii_digit() || c == '.' {
            let len = number_len(rest);
            let v = rest[..len]
                .parse::<f64>()
                .map_err(|_| (at, format!("a bad number '{}'", &rest[..len])))?;
            out.push(Tok::Num(v));
            rest = &rest[len..];
        } else if c.is_alphabetic() || c == '_' {
            let len = rest
                .find(|c: char| !(c.is_alphanumeric() || c == '_'))
                .unwrap_or(rest.len());
            out.push(Tok::Name(rest[..len].to_string()));
            rest = &rest[len..];
        } else if let Some(s) = SYMBOLS.iter().find(|s| rest.starts_with(**s)) {
            if *s == "=" {
                return Err((at, "'=' (compare with '==')".into()));
            }
            out.push(Tok::Op(s));
            rest = &rest[s.len()..];
        } else {
            return Err((at, format!("an unexpected '{c}'")));
        }
    }
    Ok(out)
}

/// The length of the number at the start of `s`: digits and a point, then an exponent.
fn number_len(s: &str) -> usize {
    let b = s.as_bytes();
    let mut i = b
        .iter()
        .position(|c| !(c.is_ascii_digit() || *c == b'.'))
        .unwrap_or(b.len());
    if matches!(b.get(i), Some(b'e' | b'E')) {
        let sign = usize::from(matches!(b.get(i + 1), Some(b'+' | b'-')));
        let digits = b[(i + 1 + sign).min(b.len())..]
            .iter()
            .take_while(|c| c.is_ascii_digit())
            .count();
        if digits > 0 {
            i += 1 + sign + digits;
        }
    }
    i
}

/// Binding power of each binary operator (higher binds tighter) and whether it groups right.
fn binary(op: &str) -> Option<(Op, u8, bool)> {
    Some(match op {
        "||" => (Op::Or, 1, false),
        "&&" => (Op::And, 2, false),
        "==" => (Op::Eq, 3, false),
        "!=" => (Op::Ne, 3, false),
        "<" => (Op::Lt, 3, false),
        "<=" => (Op::Le, 3, false),
        ">" => (Op::Gt, 3, false),
        ">=" => (Op::Ge, 3, false),
        "+" => (Op::Add, 4, false),
        "-" => (Op::Sub, 4, false),
        "*" => (Op::Mul, 5, false),
        "/" => (Op::Div, 5, false),
        "%" => (Op::Rem, 5, false),
        "^" => (Op::Pow, 7, true),
        _ => return None,
    })
}

/// Binding power of the unary operators: above `*`, below `^`.
const UNARY: u8 = 6;

/// A precedence-climbing parser over the tokens.
struct Parser {
    tokens: Vec<Tok>,
    at: usize,
}

impl Parser {
    fn peek(&self) -> Option<&Tok> {
        self.tokens.get(self.at)
    }

    fn next(&mut self) -> Result<Tok, String> {
        let t = self.tokens.get(self.at).cloned();
        self.at += 1;
        t.ok_or_else(|| "the expression ends too soon".to_string())
    }

    fn expect(&mut self, op: &str) -> Result<(), String> {
        match self.next()? {
            Tok::Op(o) if o == op => Ok(()),
            t => Err(format!("expected '{op}', found {t}")),
        }
    }

    /// An expression whose operators all bind tighter than `min`, `depth` levels down.
    fn expr(&mut self, depth: usize) -> Result<Node, String> {
        self.climb(0, depth)
    }

    fn climb(&mut self, min: u8, depth: usize) -> Result<Node, String> {
        if depth > MAX_DEPTH {
            return Err(format!("nested deeper than {MAX_DEPTH}"));
        }
        let mut left = self.operand(depth)?;
        while let Some(Tok::Op(o)) = self.peek() {
            let Some((op, power, right)) = binary(o) else {
                break;
            };
            if power <= min {
                break;
            }
            self.at += 1;
            let rhs = self.climb(if right { power - 1 } else { power }, depth + 1)?;
            left = Node::Bin(op, Box::new(left), Box::new(rhs));
        }
        Ok(left)
    }

    /// A number, name, call, parenthesised expression or unary operator with its operand.
    fn operand(&mut self, depth: usize) -> Result<Node, String> {
        match self.next()? {
            Tok::Num(v) => Ok(Node::Num(v)),
            Tok::Op("(") => {
                let e = self.expr(depth + 1)?;
                self.expect(")")?;
                Ok(e)
            }
            Tok::Op(u @ ("-" | "+" | "!")) => {
                let a = self.climb(UNARY, depth + 1)?;
                Ok(match u {
                    "-" => Node::Neg(Box::new(a)),
                    "!" => Node::Not(Box::new(a)),
                    _ => a,
                })
            }
            Tok::Name(name) if self.peek() == Some(&Tok::Op("(")) => {
                self.at += 1;
                self.call(&name, depth)
            }
            Tok::Name(name) if name == "pi" => Ok(Node::Num(std::f64::consts::PI)),
            Tok::Name(name) => Ok(Node::Var(name)),
            t => Err(format!("unexpected {t}")),
        }
    }

    /// The arguments of a call to `name`, after its `(`.
    fn call(&mut self, name: &str, depth: usize) -> Result<Node, String> {
        let (func, arity) =
            Func::named(name).ok_or_else(|| format!("unknown function '{name}'"))?;
        let mut args = Vec::new();
        if self.peek() == Some(&Tok::Op(")")) {
            self.at += 1;
        } else {
            loop {
                args.push(self.expr(depth + 1)?);
                match self.next()? {
                    Tok::Op(",") => continue,
                    Tok::Op(")") => break,
                    t => return Err(format!("expected ',' or ')' in {name}(…), found {t}")),
                }
            }
        }
        if !arity.contains(&args.len()) {
            return Err(format!(
                "{name}(…) takes {arity:?} arguments, not {}",
                args.len()
            ));
        }
        Ok(Node::Call(func, args))
    }
}

/// The cubic Hermite curve from `p0` (tangent `m0`) to `p1` (tangent `m1`) at `s` ∈ [0, 1].
pub fn hermite(p0: f64, p1: f64, m0: f64, m1: f64, s: f64) -> f64 {
    let (s2, s3) = (s * s, s * s * s);
    (2.0 * s3 - 3.0 * s2 + 1.0) * p0
        + (s3 - 2.0 * s2 + s) * m0
        + (-2.0 * s3 + 3.0 * s2) * p1
        + (s3 - s2) * m1
}

/// The Kochanek–Bartels (TCB) spline segment from `p[1]` to `p[2]` at `s` ∈ [0, 1], with `p[0]` and
/// `p[3]` as neighbours; tension, continuity and bias 0 give Catmull–Rom.
pub fn tcb(p: [f64; 4], tension: f64, continuity: f64, bias: f64, s: f64) -> f64 {
    let (t, c, b) = (tension, continuity, bias);
    let out1 = (1.0 - t) * (1.0 + b) * (1.0 + c) / 2.0 * (p[1] - p[0])
        + (1.0 - t) * (1.0 - b) * (1.0 - c) / 2.0 * (p[2] - p[1]);
    let in2 = (1.0 - t) * (1.0 + b) * (1.0 - c) / 2.0 * (p[2] - p[1])
        + (1.0 - t) * (1.0 - b) * (1.0 + c) / 2.0 * (p[3] - p[2]);
    hermite(p[1], p[2], out1, in2, s)
}

/// One-dimensional gradient (Perlin) noise: smooth (C²), zero at every integer, within [−1, 1];
/// `seed` picks an independent sequence.
pub fn perlin(x: f64, seed: f64) -> f64 {
    // a gradient in [-1, 1] per lattice point, from an integer hash of (point, seed)
    let gradient = |i: f64| {
        let mut h = (i as i64 as u64) ^ (seed.to_bits().rotate_left(17));
        h = (h ^ (h >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        h = (h ^ (h >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        h ^= h >> 31;
        (h >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    };
    let i = x.floor();
    let f = x - i;
    let fade = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    let (a, b) = (gradient(i) * f, gradient(i + 1.0) * (f - 1.0));
    // the two ramps meet at most 0.5 apart: doubling keeps the result within [-1, 1]
    2.0 * (a + fade * (b - a))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn value(text: &str) -> f64 {
        let vars = |n: &str| match n {
            "t" => Some(0.25),
            "a" => Some(3.0),
            _ => None,
        };
        Expr::compile(text).unwrap().eval(&vars).unwrap()
    }

    #[test]
    fn precedence_and_associativity_are_those_of_arithmetic() {
        for (text, want) in [
            ("1 + 2 * 3", 7.0),
            ("(1 + 2) * 3", 9.0),
            ("2 ^ 3 ^ 2", 512.0),
            ("-2 ^ 2", -4.0),
            ("(-2) ^ 2", 4.0),
            ("8 / 4 / 2", 1.0),
            ("7 % 4 * 2", 6.0),
            ("1 - 2 - 3", -4.0),
            ("2 * -3", -6.0),
            ("1 < 2 && 3 > 4 || 5 >= 5", 1.0),
            ("!(1 == 1) + (2 != 3)", 1.0),
            ("1 + 2 < 4", 1.0),
            ("2e-1 + .5 + 1E2", 100.7),
        ] {
            assert!(
                (value(text) - want).abs() < 1e-12,
                "{text} = {}",
                value(text)
            );
        }
    }

    #[test]
    fn functions_variables_and_curves() {
        assert!(
            (value("a * sin(pi * t)") - 3.0 * (std::f64::consts::PI * 0.25).sin()).abs() < 1e-12
        );
        assert_eq!(value("if(t < 0.5, a, 1 / 0)"), 3.0); // the branch not taken is not evaluated
        assert_eq!(value("max(1, a, 2) + min(4)"), 7.0);
        assert!((value("log(100) + log(2, 8) + ln(e())") - 6.0).abs() < 1e-12);
        assert_eq!(value("pi()"), std::f64::consts::PI);
        assert_eq!(value("hermite(0, 1, 0, 0, 0.5)"), 0.5);
        assert_eq!(value("tcb(0, 1, 2, 3, 0, 0, 0, 1)"), 2.0);
        assert_eq!(value("perlin(2) + perlin(3, 7)"), 0.0);
        assert_eq!(value("atan2(0, 1) + abs(-2) + floor(1.5)"), 3.0);
    }

    #[test]
    fn bad_text_is_refused_and_unknown_names_are_found_when_evaluated() {
        for (text, words) in [
            ("1 +", "ends too soon"),
            ("(1", "ends too soon"),
            ("1 2", "unexpected number"),
            ("a = 1", "'=='"),
            ("sin(1, 2)", "takes"),
            ("print(1)", "unknown function 'print'"),
            ("1 $ 2", "unexpected '$'"),
            ("if(1, 2)", "takes"),
        ] {
            let e = Expr::compile(text).unwrap_err();
            assert!(e.contains(words), "{text}: {e}");
        }
        let deep = format!("{}1{}", "(".repeat(100), ")".repeat(100));
        assert!(Expr::compile(&deep).unwrap_err().contains("deeper"));
        let minus = format!("{}1", "-".repeat(100));
        assert!(Expr::compile(&minus).unwrap_err().contains("deeper"));
        let vars = |_: &str| None;
        let e = Expr::compile("b + 1").unwrap().eval(&vars).unwrap_err();
        assert!(e.contains("unknown name 'b'"), "{e}");
        let e = Expr::compile("1 / 0").unwrap().eval(&vars).unwrap_err();
        assert!(e.contains("gives inf"), "{e}");
    }
}
