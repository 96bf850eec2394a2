//! A grey-box model whose matrices are written as expressions of named parameters, as an
//! experiment file or Python gives them: `a = [["0", "1"], ["-k/m", "-damp/m"]]`.

use super::{StateMatrices, StateSpaceModel};
use crate::SignalError;
use jitterid_numeric::dual::Real;
use jitterid_numeric::expr::{reserved_names, Expr};

/// The registry name of grey-box models, which every error of this module names.
pub const GREY_BOX: &str = "grey-box";

/// One matrix entry as written: an expression's text or a number.
#[derive(Debug, Clone, PartialEq)]
pub enum Entry {
    /// An expression of the parameters and constants.
    Text(String),
    /// A number.
    Number(f64),
}

impl From<&str> for Entry {
    fn from(s: &str) -> Self {
        Entry::Text(s.to_string())
    }
}

impl From<f64> for Entry {
    fn from(x: f64) -> Self {
        Entry::Number(x)
    }
}

/// The four matrices as written, by rows: `a` (`n × n`), `b` (`n × 1`), `c` (`1 × n`) and
/// `d` (`1 × 1`, zero when absent).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct WrittenMatrices {
    /// `A`.
    pub a: Vec<Vec<Entry>>,
    /// `B`, one row per state.
    pub b: Vec<Vec<Entry>>,
    /// `C`, one row.
    pub c: Vec<Vec<Entry>>,
    /// `D`, one row of one entry, or none.
    pub d: Option<Vec<Vec<Entry>>>,
}

/// A [`StateSpaceModel`] whose matrices are expressions of named parameters (estimated) and
/// named constants (`fixed`: usable in the expressions, never estimated), with optional
/// bounds `[lo, hi]` on the parameters.
///
/// ```
/// use jitterid_signal::greybox::{ExprModel, StateSpaceModel, WrittenMatrices};
/// let m = WrittenMatrices {
///     a: vec![vec!["0".into(), "1".into()], vec!["-k/m".into(), "-damp/m".into()]],
///     b: vec![vec![0.0.into()], vec!["1/m".into()]],
///     c: vec![vec![1.0.into(), 0.0.into()]],
///     d: None,
/// };
/// let names = ["m", "damp", "k"].map(String::from);
/// let model = ExprModel::new(&names, &[], &[("m".into(), (0.0, 1e3))], &m).unwrap();
/// assert_eq!(model.matrices(&[2.0, 0.4, 1.0]).a[1], [-0.5, -0.2]);
/// assert!(model.check(&[-1.0, 0.4, 1.0]).is_err());
/// let bad = WrittenMatrices { a: vec![vec!["-k/mass".into()]], ..m.clone() };
/// let e = ExprModel::new(&names, &[], &[], &bad).unwrap_err();
/// assert_eq!(e.key(), Some("a"));
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct ExprModel {
    names: Vec<String>,
    fixed: Vec<(String, f64)>,
    bounds: Vec<(f64, f64)>,
    a: Vec<Vec<Expr>>,
    b: Vec<Expr>,
    c: Vec<Expr>,
    d: Expr,
}

fn invalid(key: &str, message: impl Into<String>) -> SignalError {
    SignalError::InvalidKey {
        kind: GREY_BOX.into(),
        key: key.into(),
        message: message.into(),
    }
}

impl ExprModel {
    /// Parses the matrices against the parameters `names` and the constants `fixed`, with
    /// `bounds` for some parameters (`(-∞, ∞)` for the others).
    ///
    /// # Errors
    ///
    /// An [`SignalError::InvalidKey`] naming the key (`params`, `fixed`, `bounds`, `a`, `b`,
    /// `c`, `d`) and, for an expression, its place and text: a name that is not an identifier
    /// or is reserved (a function, `pi`) or given twice, a bound on an unknown parameter or
    /// with `lo > hi`, a matrix of the wrong shape, an expression that does not parse or uses
    /// an unknown name, a non-finite number.
    pub fn new(
        names: &[String],
        fixed: &[(String, f64)],
        bounds: &[(String, (f64, f64))],
        written: &WrittenMatrices,
    ) -> Result<Self, SignalError> {
        if names.is_empty() {
            return Err(invalid("params", "expected at least one parameter"));
        }
        let mut all: Vec<&str> = Vec::new();
        for (key, name) in names
            .iter()
            .map(|n| ("params", n.as_str()))
            .chain(fixed.iter().map(|(n, _)| ("fixed", n.as_str())))
        {
            let ident = name
                .chars()
                .next()
                .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
                && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
            if !ident {
                return Err(invalid(
                    key,
                    format!("\"{name}\" is not a name (letters, digits and _, not starting with a digit)"),
                ));
            }
            if reserved_names().any(|r| r == name) {
                return Err(invalid(
                    key,
                    format!("\"{name}\" is reserved (a function or a constant of the expressions)"),
                ));
            }
            if all.contains(&name) {
                return Err(invalid(key, format!("\"{name}\" is given twice")));
            }
            all.push(name);
        }
        for (name, value) in fixed {
            if !value.is_finite() {
                return Err(invalid("fixed", format!("{name} = {value} is not finite")));
            }
        }
        let mut lims = vec![(f64::NEG_INFINITY, f64::INFINITY); names.len()];
        for (name, (lo, hi)) in bounds {
            let Some(i) = names.iter().position(|n| n == name) else {
                return Err(invalid(
                    "bounds",
                    format!(
                        "\"{name}\" is not a parameter (params: {})",
                        names.join(", ")
                    ),
                ));
            };
            if !(lo <= hi) {
                return Err(invalid(
                    "bounds",
                    format!("{name} = [{lo}, {hi}]: expected lo ≤ hi"),
                ));
            }
            lims[i] = (*lo, *hi);
        }
        let parse = |key: &str, i: usize, j: usize, e: &Entry| -> Result<Expr, SignalError> {
            match e {
                Entry::Number(x) if x.is_finite() => Ok(Expr::number(*x)),
                Entry::Number(x) => Err(invalid(
                    key,
                    format!("row {}, column {}: {x} is not finite", i + 1, j + 1),
                )),
                Entry::Text(t) => Expr::parse(t, &all)
                    .map_err(|err| invalid(key, format!("row {}, column {}: {err}", i + 1, j + 1))),
            }
        };
        let matrix = |key: &str, m: &[Vec<Entry>], rows: usize, cols: Option<usize>| {
            if m.len() != rows || rows == 0 {
                return Err(invalid(
                    key,
                    format!("expected {rows} row(s), got {}", m.len()),
                ));
            }
            let cols = cols.unwrap_or(rows);
            m.iter()
                .enumerate()
                .map(|(i, row)| {
                    if row.len() != cols {
                        return Err(invalid(
                            key,
                            format!("row {} has {} entries, expected {cols}", i + 1, row.len()),
                        ));
                    }
                    row.iter()
                        .enumerate()
                        .map(|(j, e)| parse(key, i, j, e))
                        .collect::<Result<Vec<_>, _>>()
                })
                .collect::<Result<Vec<_>, _>>()
        };
        let n = written.a.len();
        if n == 0 {
            return Err(invalid("a", "expected a square matrix of at least one row"));
        }
        let a = matrix("a", &written.a, n, Some(n))?;
        let b = matrix("b", &written.b, n, Some(1))?
            .into_iter()
            .flatten()
            .collect();
        let c = matrix("c", &written.c, 1, Some(n))?
            .into_iter()
            .flatten()
            .collect();
        let d = match &written.d {
            Some(d) => matrix("d", d, 1, Some(1))?
                .into_iter()
                .flatten()
                .next()
                .unwrap_or(Expr::number(0.0)),
            None => Expr::number(0.0),
        };
        Ok(Self {
            names: names.to_vec(),
            fixed: fixed.to_vec(),
            bounds: lims,
            a,
            b,
            c,
            d,
        })
    }

    /// The constants, as given.
    pub fn fixed(&self) -> &[(String, f64)] {
        &self.fixed
    }

    /// The bounds of each parameter (`(-∞, ∞)` where none was given).
    pub fn bounds(&self) -> &[(f64, f64)] {
        &self.bounds
    }

    /// The matrices' texts, by rows, in the written shapes (`b` a column, `c` and `d` a row).
    pub fn texts(&self) -> [Vec<Vec<String>>; 4] {
        let t = |e: &Expr| e.text().to_string();
        [
            self.a.iter().map(|r| r.iter().map(t).collect()).collect(),
            self.b.iter().map(|e| vec![t(e)]).collect(),
            vec![self.c.iter().map(t).collect()],
            vec![vec![t(&self.d)]],
        ]
    }
}

impl StateSpaceModel for ExprModel {
    fn param_names(&self) -> Vec<String> {
        self.names.clone()
    }

    fn matrices<R: Real>(&self, theta: &[R]) -> StateMatrices<R> {
        let vars: Vec<R> = theta
            .iter()
            .copied()
            .chain(self.fixed.iter().map(|(_, x)| R::constant(*x)))
            .collect();
        let ev = |e: &Expr| e.eval(&vars);
        StateMatrices {
            a: self.a.iter().map(|r| r.iter().map(ev).collect()).collect(),
            b: self.b.iter().map(ev).collect(),
            c: self.c.iter().map(ev).collect(),
            d: ev(&self.d),
        }
    }

    fn check(&self, theta: &[f64]) -> Result<(), SignalError> {
        for ((name, &x), &(lo, hi)) in self.names.iter().zip(theta).zip(&self.bounds) {
            if !(lo <= x && x <= hi) {
                return Err(invalid(
                    "params",
                    format!("{name} = {x} is outside its bounds [{lo}, {hi}]"),
                ));
            }
        }
        Ok(())
    }
}
