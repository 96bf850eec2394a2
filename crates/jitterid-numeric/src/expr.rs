//! Arithmetic expressions of named parameters, parsed once and evaluated on any [`Real`]: on
//! `f64` for a value, on [`Dual`](crate::dual::Dual) for an exact derivative.
//!
//! The grammar (the usual precedence: `^` binds tighter than a unary sign, which binds tighter
//! than `* /`, then `+ −`; `^` groups to the right, the others to the left):
//!
//! ```text
//! sum     = product (("+" | "-") product)*
//! product = unary (("*" | "/") unary)*
//! unary   = ("-" | "+") unary | power
//! power   = atom ("^" unary)?
//! atom    = number | name | name "(" sum ")" | "(" sum ")"
//! ```
//!
//! Numbers are decimal with an optional exponent (`2`, `0.5`, `.5`, `1e-3`, `2.5E+4`); names are
//! `[A-Za-z_][A-Za-z0-9_]*`; the functions are `sqrt exp ln sin cos tan abs`, and `pi` is
//! `π` unless a parameter has that name. Parsing never panics: a malformed text, an unknown
//! name or an expression nested deeper than [`MAX_DEPTH`] is an [`ExprError`] that quotes the
//! expression.
//!
//! ```
//! use jitterid_numeric::expr::Expr;
//! use jitterid_numeric::dual::{Dual, Real};
//! let e = Expr::parse("-k/m + 1e-3*m^2", &["m", "k"]).unwrap();
//! assert_eq!(e.eval(&[2.0, 3.0]), -1.5 + 4e-3);
//! // ∂/∂m by one pass on duals seeded in m.
//! let d = e.eval(&[Dual::variable(2.0), Dual::constant(3.0)]);
//! assert!((d.derivative - (3.0 / 4.0 + 4e-3)).abs() < 1e-15);
//! assert!(Expr::parse("k/mass", &["m", "k"]).is_err());
//! ```

use crate::dual::Real;
use std::fmt;

/// The deepest nesting of parentheses, signs and powers accepted: far beyond what a physical
/// model needs, and well inside the parser's stack.
pub const MAX_DEPTH: usize = 64;

/// The longest expression accepted, in bytes.
pub const MAX_LEN: usize = 4096;

/// Why an expression was refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ExprError {
    /// The text is not an expression of the grammar.
    #[error("cannot parse \"{expression}\" at character {position}: {message}")]
    Syntax {
        /// The expression.
        expression: String,
        /// Where (0-based, in characters).
        position: usize,
        /// What was expected.
        message: String,
    },
    /// A name that is neither a parameter nor a known constant or function.
    #[error("unknown name \"{name}\" in \"{expression}\" (known: {known})")]
    UnknownName {
        /// The expression.
        expression: String,
        /// The name.
        name: String,
        /// The names it may use.
        known: String,
    },
}

/// A unary function of the grammar.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Func {
    Sqrt,
    Exp,
    Ln,
    Sin,
    Cos,
    Tan,
    Abs,
}

impl Func {
    const ALL: [(&'static str, Func); 7] = [
        ("sqrt", Func::Sqrt),
        ("exp", Func::Exp),
        ("ln", Func::Ln),
        ("sin", Func::Sin),
        ("cos", Func::Cos),
        ("tan", Func::Tan),
        ("abs", Func::Abs),
    ];

    fn named(name: &str) -> Option<Func> {
        Self::ALL.iter().find(|(n, _)| *n == name).map(|(_, f)| *f)
    }

    fn apply<R: Real>(self, x: R) -> R {
        match self {
            Func::Sqrt => x.sqrt(),
            Func::Exp => x.exp(),
            Func::Ln => x.ln(),
            Func::Sin => x.sin(),
            Func::Cos => x.cos(),
            Func::Tan => x.sin() / x.cos(),
            // |x| = x·sign(x): the derivative sign(x)·dx away from 0.
            Func::Abs => {
                if x.value() < 0.0 {
                    -x
                } else {
                    x
                }
            }
        }
    }
}

/// The names an expression may use besides the parameters: the functions and `pi`.
pub fn reserved_names() -> impl Iterator<Item = &'static str> {
    Func::ALL.iter().map(|(n, _)| *n).chain(["pi"])
}

#[derive(Debug, Clone, PartialEq)]
enum Node {
    Number(f64),
    Var(usize),
    Neg(Box<Node>),
    Add(Box<Node>, Box<Node>),
    Sub(Box<Node>, Box<Node>),
    Mul(Box<Node>, Box<Node>),
    Div(Box<Node>, Box<Node>),
    Pow(Box<Node>, Box<Node>),
    Call(Func, Box<Node>),
}

impl Node {
    fn eval<R: Real>(&self, vars: &[R]) -> R {
        match self {
            Node::Number(x) => R::constant(*x),
            // The parser only makes indices below the number of names; a caller that passes
            // fewer values gets NaN rather than a panic.
            Node::Var(i) => vars.get(*i).copied().unwrap_or(R::constant(f64::NAN)),
            Node::Neg(a) => -a.eval(vars),
            Node::Add(a, b) => a.eval(vars) + b.eval(vars),
            Node::Sub(a, b) => a.eval(vars) - b.eval(vars),
            Node::Mul(a, b) => a.eval(vars) * b.eval(vars),
            Node::Div(a, b) => a.eval(vars) / b.eval(vars),
            Node::Pow(a, b) => a.eval(vars).pow(b.eval(vars)),
            Node::Call(f, a) => f.apply(a.eval(vars)),
        }
    }

    fn uses_any(&self) -> bool {
        match self {
            Node::Number(_) => false,
            Node::Var(_) => true,
            Node::Neg(a) | Node::Call(_, a) => a.uses_any(),
            Node::Add(a, b)
            | Node::Sub(a, b)
            | Node::Mul(a, b)
            | Node::Div(a, b)
            | Node::Pow(a, b) => a.uses_any() || b.uses_any(),
        }
    }

    fn uses(&self, i: usize) -> bool {
        match self {
            Node::Number(_) => false,
            Node::Var(j) => *j == i,
            Node::Neg(a) | Node::Call(_, a) => a.uses(i),
            Node::Add(a, b)
            | Node::Sub(a, b)
            | Node::Mul(a, b)
            | Node::Div(a, b)
            | Node::Pow(a, b) => a.uses(i) || b.uses(i),
        }
    }
}

/// A parsed expression of named parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct Expr {
    text: String,
    root: Node,
}

impl Expr {
    /// Parses `text`, whose names are `names` (a value per name at evaluation, in this order).
    ///
    /// # Errors
    ///
    /// [`ExprError::Syntax`] for a malformed text (also an empty one, one longer than
    /// [`MAX_LEN`] or nested deeper than [`MAX_DEPTH`]), [`ExprError::UnknownName`] for a name
    /// that is not in `names`, a function or `pi`.
    pub fn parse(text: &str, names: &[&str]) -> Result<Expr, ExprError> {
        let mut p = Parser {
            text,
            chars: text.chars().collect(),
            pos: 0,
            depth: 0,
            names,
        };
        if text.len() > MAX_LEN {
            return Err(p.error(format!("longer than {MAX_LEN} bytes")));
        }
        let root = p.sum()?;
        p.skip_space();
        if p.pos < p.chars.len() {
            return Err(p.error(format!("unexpected '{}'", p.chars[p.pos])));
        }
        Ok(Expr {
            text: text.to_string(),
            root,
        })
    }

    /// A constant expression (a number given as such rather than as text).
    pub fn number(x: f64) -> Expr {
        Expr {
            text: format!("{x}"),
            root: Node::Number(x),
        }
    }

    /// The text it was parsed from.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The value at `vars` (one per name given to [`parse`](Self::parse), in that order).
    pub fn eval<R: Real>(&self, vars: &[R]) -> R {
        self.root.eval(vars)
    }

    /// Whether the expression uses the `i`-th name (its derivative is zero otherwise).
    pub fn uses(&self, i: usize) -> bool {
        self.root.uses(i)
    }

    /// The constant value when the expression uses no name.
    pub fn constant(&self) -> Option<f64> {
        (!self.root.uses_any()).then(|| self.eval::<f64>(&[]))
    }
}

impl fmt::Display for Expr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.text)
    }
}

struct Parser<'a> {
    text: &'a str,
    chars: Vec<char>,
    pos: usize,
    depth: usize,
    names: &'a [&'a str],
}

impl Parser<'_> {
    fn error(&self, message: String) -> ExprError {
        ExprError::Syntax {
            expression: self.text.to_string(),
            position: self.pos,
            message,
        }
    }

    fn skip_space(&mut self) {
        while self.chars.get(self.pos).is_some_and(|c| c.is_whitespace()) {
            self.pos += 1;
        }
    }

    /// The next non-space character, consumed when it is one of `ops`.
    fn eat(&mut self, ops: &[char]) -> Option<char> {
        self.skip_space();
        let c = *self.chars.get(self.pos)?;
        if ops.contains(&c) {
            self.pos += 1;
            Some(c)
        } else {
            None
        }
    }

    fn enter(&mut self) -> Result<(), ExprError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(self.error(format!("nested deeper than {MAX_DEPTH}")));
        }
        Ok(())
    }

    fn sum(&mut self) -> Result<Node, ExprError> {
        self.enter()?;
        let mut left = self.product()?;
        while let Some(op) = self.eat(&['+', '-']) {
            let right = self.product()?;
            left = if op == '+' {
                Node::Add(Box::new(left), Box::new(right))
            } else {
                Node::Sub(Box::new(left), Box::new(right))
            };
        }
        self.depth -= 1;
        Ok(left)
    }

    fn product(&mut self) -> Result<Node, ExprError> {
        let mut left = self.unary()?;
        while let Some(op) = self.eat(&['*', '/']) {
            let right = self.unary()?;
            left = if op == '*' {
                Node::Mul(Box::new(left), Box::new(right))
            } else {
                Node::Div(Box::new(left), Box::new(right))
            };
        }
        Ok(left)
    }

    fn unary(&mut self) -> Result<Node, ExprError> {
        self.enter()?;
        let node = match self.eat(&['-', '+']) {
            Some('-') => Node::Neg(Box::new(self.unary()?)),
            Some(_) => self.unary()?,
            None => self.power()?,
        };
        self.depth -= 1;
        Ok(node)
    }

    fn power(&mut self) -> Result<Node, ExprError> {
        let base = self.atom()?;
        if self.eat(&['^']).is_some() {
            // Right-associative, and the exponent may carry a sign: `2^-x`, `a^b^c = a^(b^c)`.
            let exponent = self.unary()?;
            return Ok(Node::Pow(Box::new(base), Box::new(exponent)));
        }
        Ok(base)
    }

    fn atom(&mut self) -> Result<Node, ExprError> {
        self.skip_space();
        let Some(&c) = self.chars.get(self.pos) else {
            return Err(self.error("expected a number, a name or '('".into()));
        };
        if c == '(' {
            self.pos += 1;
            let inner = self.sum()?;
            if self.eat(&[')']).is_none() {
                return Err(self.error("expected ')'".into()));
            }
            return Ok(inner);
        }
        if c.is_ascii_digit() || c == '.' {
            return self.number();
        }
        if c.is_ascii_alphabetic() || c == '_' {
            let start = self.pos;
            while self
                .chars
                .get(self.pos)
                .is_some_and(|c| c.is_ascii_alphanumeric() || *c == '_')
            {
                self.pos += 1;
            }
            let name: String = self.chars[start..self.pos].iter().collect();
            if let Some(i) = self.names.iter().position(|n| *n == name) {
                return Ok(Node::Var(i));
            }
            if let Some(f) = Func::named(&name) {
                if self.eat(&['(']).is_none() {
                    return Err(self.error(format!("expected '(' after the function {name}")));
                }
                let arg = self.sum()?;
                if self.eat(&[')']).is_none() {
                    return Err(self.error("expected ')'".into()));
                }
                return Ok(Node::Call(f, Box::new(arg)));
            }
            if name == "pi" {
                return Ok(Node::Number(std::f64::consts::PI));
            }
            let known: Vec<String> = self
                .names
                .iter()
                .map(|n| n.to_string())
                .chain(reserved_names().map(String::from))
                .collect();
            return Err(ExprError::UnknownName {
                expression: self.text.to_string(),
                name,
                known: known.join(", "),
            });
        }
        Err(self.error(format!("unexpected '{c}'")))
    }

    fn number(&mut self) -> Result<Node, ExprError> {
        let start = self.pos;
        let digits = |p: &mut Self| {
            let s = p.pos;
            while p.chars.get(p.pos).is_some_and(char::is_ascii_digit) {
                p.pos += 1;
            }
            p.pos - s
        };
        let mut mantissa = digits(self);
        if self.chars.get(self.pos) == Some(&'.') {
            self.pos += 1;
            mantissa += digits(self);
        }
        if mantissa == 0 {
            return Err(self.error("expected digits".into()));
        }
        if matches!(self.chars.get(self.pos), Some('e' | 'E')) {
            self.pos += 1;
            if matches!(self.chars.get(self.pos), Some('+' | '-')) {
                self.pos += 1;
            }
            if digits(self) == 0 {
                return Err(self.error("expected the exponent's digits".into()));
            }
        }
        let text: String = self.chars[start..self.pos].iter().collect();
        match text.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(Node::Number(x)),
            _ => Err(self.error(format!("\"{text}\" is not a finite number"))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dual::Dual;
    use proptest::prelude::*;

    fn value(text: &str, names: &[&str], vars: &[f64]) -> f64 {
        Expr::parse(text, names).unwrap().eval(vars)
    }

    #[test]
    fn numbers_precedence_and_associativity() {
        assert_eq!(value("1e-3", &[], &[]), 1e-3);
        assert_eq!(value("2.5E+2 + .5", &[], &[]), 250.5);
        assert_eq!(value("1 - 2 - 3", &[], &[]), -4.0);
        assert_eq!(value("8 / 4 / 2", &[], &[]), 1.0);
        assert_eq!(value("2^3^2", &[], &[]), 512.0);
        assert_eq!(value("-2^2", &[], &[]), -4.0);
        assert_eq!(value("(-2)^2", &[], &[]), 4.0);
        assert_eq!(value("2^-1", &[], &[]), 0.5);
        assert_eq!(value("1 + 2 * 3", &[], &[]), 7.0);
        assert_eq!(value("--3", &[], &[]), 3.0);
        assert_eq!(value("-k/m", &["m", "k"], &[4.0, 2.0]), -0.5);
        assert_eq!(value("2*pi", &[], &[]), 2.0 * std::f64::consts::PI);
        // A parameter named like a constant wins.
        assert_eq!(value("pi", &["pi"], &[3.0]), 3.0);
    }

    #[test]
    fn functions_and_their_derivatives() {
        let names = ["a", "b"];
        let e = Expr::parse(
            "sqrt(a) * exp(b) + ln(a) - sin(b) / cos(a) + tan(b) + abs(-a)",
            &names,
        )
        .unwrap();
        let f = |a: f64, b: f64| a.sqrt() * b.exp() + a.ln() - b.sin() / a.cos() + b.tan() + a;
        let (a, b) = (1.3, 0.4);
        assert!((e.eval(&[a, b]) - f(a, b)).abs() < 1e-14);
        let da = e.eval(&[Dual::variable(a), Dual::constant(b)]).derivative;
        let db = e.eval(&[Dual::constant(a), Dual::variable(b)]).derivative;
        let h = 1e-6;
        assert!((da - (f(a + h, b) - f(a - h, b)) / (2.0 * h)).abs() < 1e-7);
        assert!((db - (f(a, b + h) - f(a, b - h)) / (2.0 * h)).abs() < 1e-7);
        assert!(e.uses(0) && e.uses(1));
        assert!(!Expr::parse("2*b", &names).unwrap().uses(0));
        assert_eq!(Expr::parse("2*3", &names).unwrap().constant(), Some(6.0));
        assert_eq!(Expr::parse("2*b", &names).unwrap().constant(), None);
    }

    #[test]
    fn errors_name_the_expression() {
        for (text, what) in [
            ("", "expected a number"),
            ("1 +", "expected a number"),
            ("(1", "expected ')'"),
            ("1)", "unexpected ')'"),
            ("2 3", "unexpected '3'"),
            ("1e", "exponent"),
            ("sqrt 2", "expected '('"),
            ("1e999", "not a finite number"),
            ("3 $ 4", "unexpected '$'"),
        ] {
            let e = Expr::parse(text, &["m"]).unwrap_err();
            let msg = e.to_string();
            assert!(
                msg.contains(&format!("\"{text}\"")) && msg.contains(what),
                "{msg}"
            );
        }
        let e = Expr::parse("k/mass", &["m", "k"]).unwrap_err();
        assert_eq!(
            e,
            ExprError::UnknownName {
                expression: "k/mass".into(),
                name: "mass".into(),
                known: "m, k, sqrt, exp, ln, sin, cos, tan, abs, pi".into(),
            }
        );
        let deep = format!("{}1{}", "(".repeat(1000), ")".repeat(1000));
        assert!(Expr::parse(&deep, &[])
            .unwrap_err()
            .to_string()
            .contains("nested deeper"));
        let signs = "-".repeat(100_000);
        assert!(Expr::parse(&signs, &[]).is_err());
    }

    proptest! {
        /// Any text parses or is refused, never a panic; what parses evaluates without one.
        #[test]
        fn no_panic_on_arbitrary_text(text in "\\PC{0,40}") {
            if let Ok(e) = Expr::parse(&text, &["m", "k"]) {
                let _ = e.eval(&[1.5, -2.0]);
                let _ = e.eval(&[Dual::variable(1.5), Dual::constant(-2.0)]);
            }
        }

        /// Texts made of the grammar's own characters, which reach deeper into the parser.
        #[test]
        fn no_panic_on_grammar_soup(text in "[-+*/^() .e0-9mkpisqrtxlnco]{0,40}") {
            if let Ok(e) = Expr::parse(&text, &["m", "k"]) {
                let _ = e.eval(&[0.0, 0.0]);
            }
        }
    }
}
