//! `*PARAMETER` and `*PARAMETER_EXPRESSION`: the deck's named values.
//!
//! `*PARAMETER` cards hold pairs of 10-column fields, four pairs a line: the type letter
//! (`R` real, `I` integer) and the name, then the value. `*PARAMETER_EXPRESSION` cards hold
//! one definition each: the type and name in 10 columns, then an expression in 70 over the
//! parameters defined before it (by name, with or without `&`), numbers, `+ - * /`, `**`
//! or `^` (power, right-associative), parentheses and the functions `sin cos tan asin acos
//! atan atan2 sinh cosh tanh exp log log10 sqrt abs min max int aint nint anint mod sign`
//! (angles in radians; `int` and `aint` truncate toward zero, `nint` and `anint` round half
//! away from zero, `mod(a, b) = a - int(a / b) b`, `sign(a, b) = |a|` with the sign of `b`). An
//! integer parameter takes its value truncated toward zero.

use std::cell::RefCell;

use super::blocks::Block;
use super::cards::{Ctx, Params};
use super::source::Source;
use crate::error::Result;

/// A parameter of a deck (`*PARAMETER` or `*PARAMETER_EXPRESSION`): its name as written,
/// its value, whether it is an integer (`I`) or a real (`R`) parameter, the expression it
/// was computed from, and where it is defined.
#[derive(Debug, Clone, PartialEq)]
pub struct DeckParameter {
    /// The name, as written (references `&name` match it without regard to case).
    pub name: String,
    /// The value.
    pub value: f64,
    /// `I` parameter (integer) rather than `R` (real).
    pub integer: bool,
    /// The expression of a `*PARAMETER_EXPRESSION` definition (`None` for a plain value).
    pub expression: Option<String>,
    /// The file that defines it.
    pub file: String,
    /// Its line there.
    pub line: usize,
}

/// The `*PARAMETER` and `*PARAMETER_EXPRESSION` definitions of the blocks in deck order,
/// with `overrides` (upper-case names) in place of the deck's values; expressions are
/// evaluated with the values in force (overridden ones included).
pub(crate) fn parameters(
    src: &Source,
    blocks: &[Block<'_>],
    overrides: &Params,
) -> Result<(Vec<DeckParameter>, Params)> {
    let mut list: Vec<DeckParameter> = Vec::new();
    let mut values = Params::new();
    let notes = RefCell::new(Vec::new());
    for b in blocks
        .iter()
        .filter(|b| b.kw == "*PARAMETER" || b.kw == "*PARAMETER_EXPRESSION")
    {
        let empty = Params::new();
        let ctx = Ctx {
            file: &src.files[b.file],
            keyword: b.kw.clone(),
            params: &empty,
            format: b.format,
            notes: &notes,
        };
        let expression = b.kw == "*PARAMETER_EXPRESSION";
        for c in &b.cards {
            // (name field, value field or expression)
            let mut defs: Vec<(String, String, std::result::Result<f64, String>)> = Vec::new();
            if expression {
                let w = ctx.format.width(10);
                let head_has_comma = c.text.chars().take(w).any(|ch| ch == ',');
                let (head, rest) = if head_has_comma {
                    let (h, r) = c.text.split_once(',').unwrap_or((c.text, ""));
                    (h.trim().to_string(), r.trim().to_string())
                } else {
                    let cut = w.min(c.text.len());
                    let cut = (cut..=c.text.len())
                        .find(|&k| c.text.is_char_boundary(k))
                        .unwrap_or(c.text.len());
                    (
                        c.text[..cut].trim().to_string(),
                        c.text[cut..].trim().to_string(),
                    )
                };
                if head.is_empty() {
                    continue;
                }
                let value = evaluate(&rest, &values);
                defs.push((head, rest, value));
            } else {
                let f = ctx.fields(c, &[10]);
                for pair in 0..f.len().div_ceil(2) {
                    let k = 2 * pair;
                    let field = format!("PRMR{}", pair + 1);
                    let Some(head) = f.raw(k, &field)? else {
                        continue;
                    };
                    let value = f.real(k + 1, &format!("VAL{}", pair + 1), 0.0)?;
                    defs.push((head.to_string(), String::new(), Ok(value)));
                }
            }
            for (head, expr, value) in defs {
                let (kind, pname) = head.split_at(head.chars().next().map_or(0, char::len_utf8));
                let pname = pname.trim();
                let integer = match kind {
                    "R" | "r" => false,
                    "I" | "i" => true,
                    _ => {
                        return Err(ctx.err(
                            c.line,
                            format!(
                                "`{head}`: a parameter is `R name` (real) or `I name` \
                                 (integer); character parameters are not supported"
                            ),
                        ));
                    }
                };
                if pname.is_empty()
                    || !pname
                        .chars()
                        .all(|ch| ch.is_ascii_alphanumeric() || ch == '_')
                {
                    return Err(ctx.err(c.line, format!("`{head}` has no valid parameter name")));
                }
                let key = pname.to_uppercase();
                if let Some(p) = list.iter().find(|p| p.name.to_uppercase() == key) {
                    return Err(ctx.err(
                        c.line,
                        format!(
                            "parameter {pname} is already defined ({}: line {})",
                            p.file, p.line
                        ),
                    ));
                }
                let value = value
                    .map_err(|m| ctx.err(c.line, format!("parameter {pname} = `{expr}`: {m}")))?;
                if !value.is_finite() {
                    return Err(ctx.err(
                        c.line,
                        format!("parameter {pname} = `{expr}` is not finite ({value})"),
                    ));
                }
                let value = if integer { value.trunc() } else { value };
                let used = overrides
                    .get(&key)
                    .map_or(value, |&v| if integer { v.round() } else { v });
                values.insert(key, used);
                list.push(DeckParameter {
                    name: pname.to_string(),
                    value,
                    integer,
                    expression: expression.then_some(expr),
                    file: src.files[b.file].clone(),
                    line: c.line,
                });
            }
        }
    }
    Ok((list, values))
}

/// Evaluates an expression over the parameters `values` (upper-case names), or says what is
/// wrong with it.
pub(crate) fn evaluate(text: &str, values: &Params) -> std::result::Result<f64, String> {
    let tokens = tokenize(text)?;
    if tokens.is_empty() {
        return Err("empty expression".into());
    }
    let mut p = Parser {
        t: &tokens,
        k: 0,
        values,
    };
    let v = p.expr()?;
    match p.t.get(p.k) {
        None => Ok(v),
        Some(t) => Err(format!("unexpected `{}`", t.show())),
    }
}

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Num(f64),
    Name(String),
    Op(char),
    Pow,
    Open,
    Close,
    Comma,
}

impl Tok {
    fn show(&self) -> String {
        match self {
            Tok::Num(v) => v.to_string(),
            Tok::Name(n) => n.clone(),
            Tok::Op(c) => c.to_string(),
            Tok::Pow => "**".into(),
            Tok::Open => "(".into(),
            Tok::Close => ")".into(),
            Tok::Comma => ",".into(),
        }
    }
}

fn tokenize(s: &str) -> std::result::Result<Vec<Tok>, String> {
    let c: Vec<char> = s.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < c.len() {
        let ch = c[i];
        if ch.is_whitespace() {
            i += 1;
        } else if ch.is_ascii_digit()
            || (ch == '.' && c.get(i + 1).is_some_and(|d| d.is_ascii_digit()))
        {
            let start = i;
            while i < c.len() && (c[i].is_ascii_digit() || c[i] == '.') {
                i += 1;
            }
            if i < c.len()
                && matches!(c[i], 'e' | 'E' | 'd' | 'D')
                && (c.get(i + 1).is_some_and(|d| d.is_ascii_digit())
                    || (c.get(i + 1).is_some_and(|d| *d == '+' || *d == '-')
                        && c.get(i + 2).is_some_and(|d| d.is_ascii_digit())))
            {
                i += 2;
                while i < c.len() && c[i].is_ascii_digit() {
                    i += 1;
                }
            }
            let text: String = c[start..i]
                .iter()
                .collect::<String>()
                .replace(['d', 'D'], "e");
            out.push(Tok::Num(
                text.parse()
                    .map_err(|_| format!("`{text}` is not a number"))?,
            ));
        } else if ch.is_ascii_alphabetic() || ch == '_' || ch == '&' {
            let start = if ch == '&' { i + 1 } else { i };
            i += 1;
            while i < c.len() && (c[i].is_ascii_alphanumeric() || c[i] == '_') {
                i += 1;
            }
            let name: String = c[start..i].iter().collect();
            if name.is_empty() {
                return Err("`&` without a name".into());
            }
            out.push(Tok::Name(name));
        } else if ch == '*' && c.get(i + 1) == Some(&'*') {
            out.push(Tok::Pow);
            i += 2;
        } else {
            out.push(match ch {
                '+' | '-' | '*' | '/' => Tok::Op(ch),
                '^' => Tok::Pow,
                '(' => Tok::Open,
                ')' => Tok::Close,
                ',' => Tok::Comma,
                _ => return Err(format!("unexpected character `{ch}`")),
            });
            i += 1;
        }
    }
    Ok(out)
}

struct Parser<'a> {
    t: &'a [Tok],
    k: usize,
    values: &'a Params,
}

impl Parser<'_> {
    fn peek(&self) -> Option<&Tok> {
        self.t.get(self.k)
    }

    fn expr(&mut self) -> std::result::Result<f64, String> {
        let mut v = self.term()?;
        while let Some(Tok::Op(op @ ('+' | '-'))) = self.peek() {
            let op = *op;
            self.k += 1;
            let r = self.term()?;
            v = if op == '+' { v + r } else { v - r };
        }
        Ok(v)
    }

    fn term(&mut self) -> std::result::Result<f64, String> {
        let mut v = self.unary()?;
        while let Some(Tok::Op(op @ ('*' | '/'))) = self.peek() {
            let op = *op;
            self.k += 1;
            let r = self.unary()?;
            v = if op == '*' { v * r } else { v / r };
        }
        Ok(v)
    }

    fn unary(&mut self) -> std::result::Result<f64, String> {
        match self.peek() {
            Some(Tok::Op('-')) => {
                self.k += 1;
                Ok(-self.unary()?)
            }
            Some(Tok::Op('+')) => {
                self.k += 1;
                self.unary()
            }
            _ => self.power(),
        }
    }

    fn power(&mut self) -> std::result::Result<f64, String> {
        let base = self.atom()?;
        if self.peek() == Some(&Tok::Pow) {
            self.k += 1;
            let e = self.unary()?;
            return Ok(base.powf(e));
        }
        Ok(base)
    }

    fn atom(&mut self) -> std::result::Result<f64, String> {
        let Some(t) = self.t.get(self.k).cloned() else {
            return Err("the expression ends too early".into());
        };
        self.k += 1;
        match t {
            Tok::Num(v) => Ok(v),
            Tok::Open => {
                let v = self.expr()?;
                self.close()?;
                Ok(v)
            }
            Tok::Name(n) if self.peek() == Some(&Tok::Open) => {
                self.k += 1;
                let mut args = vec![self.expr()?];
                while self.peek() == Some(&Tok::Comma) {
                    self.k += 1;
                    args.push(self.expr()?);
                }
                self.close()?;
                function(&n, &args)
            }
            Tok::Name(n) => self
                .values
                .get(&n.to_uppercase())
                .copied()
                .ok_or_else(|| format!("`{n}` is no parameter defined before this one")),
            other => Err(format!("unexpected `{}`", other.show())),
        }
    }

    fn close(&mut self) -> std::result::Result<(), String> {
        if self.peek() == Some(&Tok::Close) {
            self.k += 1;
            Ok(())
        } else {
            Err("a `(` is not closed".into())
        }
    }
}

fn function(name: &str, a: &[f64]) -> std::result::Result<f64, String> {
    let one = |f: fn(f64) -> f64| -> std::result::Result<f64, String> {
        match a {
            [x] => Ok(f(*x)),
            _ => Err(format!("{name} takes one argument, got {}", a.len())),
        }
    };
    let two = |f: fn(f64, f64) -> f64| -> std::result::Result<f64, String> {
        match a {
            [x, y] => Ok(f(*x, *y)),
            _ => Err(format!("{name} takes two arguments, got {}", a.len())),
        }
    };
    match name.to_lowercase().as_str() {
        "sin" => one(f64::sin),
        "cos" => one(f64::cos),
        "tan" => one(f64::tan),
        "asin" => one(f64::asin),
        "acos" => one(f64::acos),
        "atan" => one(f64::atan),
        "atan2" => two(f64::atan2),
        "sinh" => one(f64::sinh),
        "cosh" => one(f64::cosh),
        "tanh" => one(f64::tanh),
        "exp" => one(f64::exp),
        "log" => one(f64::ln),
        "log10" => one(f64::log10),
        "sqrt" => one(f64::sqrt),
        "abs" => one(f64::abs),
        "int" | "aint" => one(f64::trunc),
        "nint" | "anint" => one(f64::round),
        "mod" => two(|x, y| x - (x / y).trunc() * y),
        "sign" => two(|x, y| if y >= 0.0 { x.abs() } else { -x.abs() }),
        "min" | "max" if !a.is_empty() => {
            let m = name.eq_ignore_ascii_case("min");
            Ok(a.iter().copied().fold(
                if m { f64::INFINITY } else { f64::NEG_INFINITY },
                |acc, x| if m { acc.min(x) } else { acc.max(x) },
            ))
        }
        _ => Err(format!("unknown function `{name}`")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expressions_follow_precedence_and_functions() {
        let mut v = Params::new();
        v.insert("T".into(), 2.0);
        v.insert("E".into(), 3.0);
        let e = |s: &str| evaluate(s, &v);
        assert_eq!(e("1+2*3"), Ok(7.0));
        assert_eq!(e("-2**2"), Ok(-4.0));
        assert_eq!(e("2**3**2"), Ok(512.0));
        assert_eq!(e("2^-1"), Ok(0.5));
        assert_eq!(e("(1+2)*&t/e"), Ok(2.0));
        assert_eq!(e("max(t, e, 1.5e0) + min(1,2)"), Ok(4.0));
        assert_eq!(
            e("mod(7, 3) + sign(2, -1) + int(-2.7) + nint(2.5)"),
            Ok(0.0)
        );
        assert!((e("sqrt(t)*sqrt(t)").unwrap() - 2.0).abs() < 1e-15);
        assert!((e("atan2(1, 1)*4").unwrap() - std::f64::consts::PI).abs() < 1e-15);
        assert!(e("thk*2").unwrap_err().contains("`thk` is no parameter"));
        assert!(e("foo(1)").unwrap_err().contains("unknown function `foo`"));
        assert!(e("(1+2").unwrap_err().contains("not closed"));
        assert!(e("1 2").unwrap_err().contains("unexpected `2`"));
        assert!(e("").unwrap_err().contains("empty"));
        assert!(e("1 $ 2").unwrap_err().contains("unexpected character"));
    }
}
