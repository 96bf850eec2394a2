//! Readable text of the model forms, in the layout of the usual `tf`/`zpk`/`ss` displays:
//! numerator over a rule over denominator, polynomials in `s`. The formatter's precision
//! (`{:.6}`) sets the decimals (default 4).

use super::{StateSpace, TfForm, ZpkForm};
use std::fmt;

/// Default decimals of a displayed coefficient.
const DEFAULT_DECIMALS: usize = 4;

/// `x` with `decimals` decimals, trailing zeros dropped; scientific outside `[1e-3, 1e5)`.
fn number(x: f64, decimals: usize) -> String {
    let a = x.abs();
    if x == x.trunc() && a < 1e9 {
        return format!("{x:.0}");
    }
    if (1e-3..1e5).contains(&a) {
        let s = format!("{x:.decimals$}");
        let s = s.trim_end_matches('0');
        return s.trim_end_matches('.').to_string();
    }
    format!("{x:.decimals$e}")
}

/// `c_0 s^n + … + c_n` with unit coefficients and zero terms omitted.
fn polynomial(c: &[f64], decimals: usize) -> String {
    let n = c.len().saturating_sub(1);
    let mut out = String::new();
    for (i, &x) in c.iter().enumerate() {
        if x == 0.0 {
            continue;
        }
        let power = n - i;
        let sign = if x < 0.0 { "-" } else { "+" };
        if out.is_empty() {
            if x < 0.0 {
                out.push('-');
            }
        } else {
            out.push_str(&format!(" {sign} "));
        }
        let a = x.abs();
        let variable = match power {
            0 => String::new(),
            1 => "s".to_string(),
            p => format!("s^{p}"),
        };
        if a != 1.0 || power == 0 {
            out.push_str(&number(a, decimals));
            if power > 0 {
                out.push(' ');
            }
        }
        out.push_str(&variable);
    }
    if out.is_empty() {
        out.push('0');
    }
    out
}

/// `top` over a rule over `bottom`, centred.
fn fraction(f: &mut fmt::Formatter<'_>, top: &str, bottom: &str) -> fmt::Result {
    let w = top.chars().count().max(bottom.chars().count());
    let centre = |s: &str| {
        let pad = (w - s.chars().count()) / 2;
        format!("  {}{s}", " ".repeat(pad))
    };
    writeln!(f, "{}", centre(top))?;
    writeln!(f, "  {}", "-".repeat(w))?;
    write!(f, "{}", centre(bottom))
}

impl fmt::Display for TfForm {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let d = f.precision().unwrap_or(DEFAULT_DECIMALS);
        fraction(f, &polynomial(self.num(), d), &polynomial(self.den(), d))
    }
}

/// `(s − r)` for real roots, `(s² − 2 Re r s + |r|²)` for each pair, `s` for a root at 0.
fn factors(roots: &[num_complex::Complex64], decimals: usize) -> String {
    roots
        .iter()
        .filter(|r| r.im >= 0.0)
        .map(|r| {
            if r.im > 0.0 {
                format!(
                    "({})",
                    polynomial(&[1.0, -2.0 * r.re, r.norm_sqr()], decimals)
                )
            } else if r.re == 0.0 {
                "s".to_string()
            } else {
                format!("({})", polynomial(&[1.0, -r.re], decimals))
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

impl fmt::Display for ZpkForm {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let d = f.precision().unwrap_or(DEFAULT_DECIMALS);
        let zeros = factors(self.zeros(), d);
        let gain = number(self.gain(), d);
        let top = match (zeros.is_empty(), self.gain() == 1.0) {
            (true, _) => gain,
            (false, true) => zeros,
            (false, false) => format!("{gain} {zeros}"),
        };
        fraction(f, &top, &factors(self.poles(), d))
    }
}

impl fmt::Display for StateSpace {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let d = f.precision().unwrap_or(DEFAULT_DECIMALS);
        let row = |r: &[f64]| {
            r.iter()
                .map(|&x| format!("{:>10}", number(x, d)))
                .collect::<String>()
        };
        writeln!(f, "  a =")?;
        for r in self.a() {
            writeln!(f, "  {}", row(r))?;
        }
        writeln!(f, "  b =")?;
        for &x in self.b() {
            writeln!(f, "  {}", row(&[x]))?;
        }
        writeln!(f, "  c =")?;
        writeln!(f, "  {}", row(self.c()))?;
        writeln!(f, "  d =")?;
        write!(f, "  {}", row(&[self.d()]))
    }
}
