//! Cards and their fields: fixed-width or comma-separated splitting, the long and 10-digit
//! formats, numbers in LS-DYNA's forms, `&name` parameter references, and the check for
//! numbers that run across field boundaries.

use std::cell::RefCell;
use std::collections::HashMap;

use crate::error::{Result, ShellError};

/// The values of the deck's parameters by upper-case name.
pub(crate) type Params = HashMap<String, f64>;

/// One data card: its line number and text.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Card<'a> {
    pub line: usize,
    pub text: &'a str,
}

/// The field format of a keyword's cards: standard, long (`*KEYWORD LONG=Y` or a keyword
/// written with a `+` suffix: every field 20 columns or its standard width if wider) or
/// 10-digit ids (`*KEYWORD I10=Y` or a `%` suffix: 8-column fields take 10).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) struct Format {
    pub long: bool,
    pub i10: bool,
}

impl Format {
    /// The width of a field whose standard width is `w`.
    pub fn width(self, w: usize) -> usize {
        if self.long {
            w.max(20)
        } else if self.i10 && w == 8 {
            10
        } else {
            w
        }
    }
}

/// What the cards of one keyword are read with: its file, the keyword as written, the
/// parameter values, the card format, and where warnings about splitting go.
pub(crate) struct Ctx<'a> {
    pub file: &'a str,
    pub keyword: String,
    pub params: &'a Params,
    pub format: Format,
    /// Warnings raised while splitting cards (numbers across field boundaries).
    pub notes: &'a RefCell<Vec<String>>,
}

impl Ctx<'_> {
    /// A [`ShellError::Keyword`] at `line` of this keyword.
    pub fn err(&self, line: usize, message: impl Into<String>) -> ShellError {
        ShellError::Keyword {
            file: self.file.to_string(),
            line,
            keyword: self.keyword.clone(),
            message: message.into(),
        }
    }

    /// A warning at `line` of this keyword.
    pub fn warning(&self, line: usize, message: impl std::fmt::Display) -> String {
        format!("{}: line {line}: {}: {message}", self.file, self.keyword)
    }

    /// The fields of card `c` with the standard widths `widths` (the last repeats).
    pub fn fields<'c>(&'c self, c: &Card<'_>, widths: &[usize]) -> Fields<'c> {
        Fields::new(c, widths, self)
    }
}

/// The fields of a card, split by commas or by the fixed `widths` (the last width repeats),
/// each with its first column (0-based; 0 for comma-separated fields).
fn split<'a>(text: &'a str, widths: &[usize]) -> Vec<(&'a str, usize)> {
    if text.contains(',') {
        return text.split(',').map(|f| (f.trim(), 0)).collect();
    }
    let mut out = Vec::new();
    let mut pos = 0;
    let mut k = 0;
    let len = text.len();
    while pos < len {
        let w = widths[k.min(widths.len() - 1)].max(1);
        let mut end = (pos + w).min(len);
        while !text.is_char_boundary(end) {
            end += 1;
        }
        out.push((text.get(pos..end).unwrap_or("").trim(), pos));
        pos = end;
        k += 1;
    }
    out
}

/// A number in LS-DYNA's forms: Rust's, `d`/`D` exponents, and Fortran's exponent without
/// a letter (`2.00000-3` = 2e-3, `1.5+2` = 150).
pub(crate) fn parse_number(s: &str) -> Option<f64> {
    let t = s.replace(['d', 'D'], "e");
    if let Ok(v) = t.parse::<f64>() {
        return Some(v);
    }
    // A sign after a digit or a point starts the exponent.
    let b = t.as_bytes();
    let k = (1..b.len()).rev().find(|&k| {
        (b[k] == b'+' || b[k] == b'-') && (b[k - 1].is_ascii_digit() || b[k - 1] == b'.')
    })?;
    format!("{}e{}", t.get(..k)?, t.get(k..)?).parse().ok()
}

/// The fixed-format boundaries of `text` that a number runs across: a run of characters
/// that starts at the first column of a field, crosses at least one field boundary, ends
/// inside a later field and reads as a single number with a decimal point or an exponent
/// (a value wider than its field). Runs that end exactly at a field's end are fields that
/// touch: a right-aligned id against a full-width real (`11.00000E-7`, LS-PrePost's MID
/// and RO) or LS-PrePost's `0.01.000000E8`. Returns the run and the indices of the fields
/// it covers.
fn overflows(text: &str, f: &[(&str, usize)], widths: &[usize]) -> Vec<(String, usize, usize)> {
    let b = text.as_bytes();
    let starts: Vec<usize> = f.iter().map(|x| x.1).collect();
    let mut out: Vec<(String, usize, usize)> = Vec::new();
    let mut k = 1;
    while k < f.len() {
        let at = f[k].1;
        if at == 0 || at >= b.len() || b[at - 1] == b' ' || b[at] == b' ' {
            k += 1;
            continue;
        }
        let start = b[..at]
            .iter()
            .rposition(|&c| c == b' ')
            .map_or(0, |p| p + 1);
        let end = b[at..]
            .iter()
            .position(|&c| c == b' ')
            .map_or(b.len(), |p| at + p);
        let last = f.iter().rposition(|x| x.1 < end).unwrap_or(k);
        let ends_inside = end < f[last].1 + widths[last.min(widths.len() - 1)];
        let first = f.iter().rposition(|x| x.1 <= start).unwrap_or(0);
        if let Some(run) = text.get(start..end)
            && starts.contains(&start)
            && ends_inside
            && run.contains(['.', 'e', 'E'])
            && parse_number(run).is_some()
        {
            out.push((run.to_string(), first, last));
        }
        k = last + 1;
    }
    out
}

/// The fields of one card, with `&name` references replaced by the parameter values.
pub(crate) struct Fields<'c> {
    /// Each field's text after `&name` references are replaced, or the message of an
    /// unknown reference.
    f: Vec<std::result::Result<String, String>>,
    line: usize,
    ctx: &'c Ctx<'c>,
}

impl<'c> Fields<'c> {
    fn new(c: &Card<'_>, widths: &[usize], ctx: &'c Ctx<'c>) -> Fields<'c> {
        let widths: Vec<usize> = widths.iter().map(|&w| ctx.format.width(w)).collect();
        let raw = split(c.text, &widths);
        if !c.text.contains(',') {
            for (run, first, last) in overflows(c.text, &raw, &widths) {
                let read: Vec<String> = raw[first..=last]
                    .iter()
                    .map(|(s, _)| format!("`{s}`"))
                    .collect();
                ctx.notes.borrow_mut().push(format!(
                    "{}: line {}: {}: `{run}` runs across fields {} to {} (columns {} to {}), read as {}",
                    ctx.file,
                    c.line,
                    ctx.keyword,
                    first + 1,
                    last + 1,
                    raw[first].1 + 1,
                    raw[last].1 + widths[last.min(widths.len() - 1)],
                    read.join(", ")
                ));
            }
        }
        let f = raw
            .iter()
            .map(|(s, _)| {
                let (neg, name) = match s.strip_prefix("-&") {
                    Some(n) => (true, n),
                    None => match s.strip_prefix('&') {
                        Some(n) => (false, n),
                        None => return Ok((*s).to_string()),
                    },
                };
                match ctx.params.get(&name.trim().to_uppercase()) {
                    Some(v) => Ok(format!("{:e}", if neg { -v } else { *v })),
                    None => Err(format!("`{s}` refers to no *PARAMETER")),
                }
            })
            .collect();
        Fields {
            f,
            line: c.line,
            ctx,
        }
    }

    /// The number of fields of the card.
    pub fn len(&self) -> usize {
        self.f.len()
    }

    /// The text of field `i` (`None` when blank or past the end of the card).
    ///
    /// # Errors
    /// An unknown `&name` reference in the field.
    pub fn raw(&self, i: usize, name: &str) -> Result<Option<&str>> {
        match self.f.get(i) {
            None => Ok(None),
            Some(Ok(s)) => Ok(Some(s.as_str()).filter(|s| !s.is_empty())),
            Some(Err(m)) => Err(self
                .ctx
                .err(self.line, format!("field {name} (field {}): {m}", i + 1))),
        }
    }

    /// Three consecutive real fields from `first` (a vector such as VX, VY, VZ), each
    /// defaulting to 0.
    pub fn real3(&self, first: usize, names: [&str; 3]) -> Result<[f64; 3]> {
        Ok([
            self.real(first, names[0], 0.0)?,
            self.real(first + 1, names[1], 0.0)?,
            self.real(first + 2, names[2], 0.0)?,
        ])
    }

    /// A real field, `default` when blank.
    pub fn real(&self, i: usize, name: &str, default: f64) -> Result<f64> {
        match self.raw(i, name)? {
            None => Ok(default),
            Some(s) => {
                let v = parse_number(s).ok_or_else(|| {
                    self.ctx
                        .err(self.line, format!("field {name}: `{s}` is not a number"))
                })?;
                if v.is_finite() {
                    Ok(v)
                } else {
                    Err(self
                        .ctx
                        .err(self.line, format!("field {name}: `{s}` is not finite")))
                }
            }
        }
    }

    /// An integer field (a real with no fraction is accepted), `default` when blank.
    pub fn int(&self, i: usize, name: &str, default: i64) -> Result<i64> {
        match self.raw(i, name)? {
            None => Ok(default),
            Some(s) => s.parse::<i64>().or_else(|_| {
                let v = self.real(i, name, 0.0)?;
                if v.fract() == 0.0 && v.abs() < 9.0e15 {
                    Ok(v as i64)
                } else {
                    Err(self
                        .ctx
                        .err(self.line, format!("field {name}: `{s}` is not an integer")))
                }
            }),
        }
    }

    /// A positive id.
    pub fn id(&self, i: usize, name: &str) -> Result<u64> {
        let v = self.int(i, name, 0)?;
        if v <= 0 {
            return Err(self.ctx.err(
                self.line,
                format!("field {name}: id must be a positive integer, got {v}"),
            ));
        }
        Ok(v as u64)
    }

    /// An id or 0 (blank is 0).
    pub fn opt_id(&self, i: usize, name: &str) -> Result<u64> {
        let v = self.int(i, name, 0)?;
        if v < 0 {
            return Err(self
                .ctx
                .err(self.line, format!("field {name}: must be >= 0, got {v}")));
        }
        Ok(v as u64)
    }

    /// An error unless field `i` is blank or 0.
    pub fn must_be_zero(&self, i: usize, name: &str) -> Result<()> {
        if self.real(i, name, 0.0)? != 0.0 {
            return Err(self.ctx.err(
                self.line,
                format!("field {name}: non-zero values are not supported"),
            ));
        }
        Ok(())
    }

    /// An error naming this card's line.
    pub fn err(&self, message: impl Into<String>) -> ShellError {
        self.ctx.err(self.line, message)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn warned(text: &str, widths: &[usize]) -> Vec<String> {
        let notes = RefCell::new(Vec::new());
        let params = Params::new();
        let ctx = Ctx {
            file: "t.k",
            keyword: "*K".into(),
            params: &params,
            format: Format::default(),
            notes: &notes,
        };
        let _ = ctx.fields(&Card { line: 1, text }, widths);
        notes.into_inner()
    }

    #[test]
    fn touching_fields_are_not_overflows_but_wide_numbers_are() {
        // LS-PrePost: MID 1 right-aligned against RO 1.00000E-7 filling its field.
        assert!(warned("         11.00000E-7  200000.0       0.3", &[10]).is_empty());
        // ENDENG 0.0 against ENDMAS 1.000000E8.
        assert!(warned("      0.20         0       0.01.000000E8", &[10]).is_empty());
        // A 22-character number alone: fields 1 to 3.
        let w = warned("0.00016099689437998487", &[10]);
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(w[0].contains("fields 1 to 3"), "{w:?}");
        // An 11-character number at the start of field 2 spilling into field 3.
        let w = warned("1         -1.2345e+100       0.3", &[10]);
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(w[0].contains("fields 2 to 3"), "{w:?}");
    }

    #[test]
    fn long_and_ten_digit_formats_widen_the_fields() {
        let f = Format {
            long: true,
            i10: false,
        };
        assert_eq!(
            (f.width(10), f.width(8), f.width(20), f.width(80)),
            (20, 20, 20, 80)
        );
        let f = Format {
            long: false,
            i10: true,
        };
        assert_eq!((f.width(8), f.width(16), f.width(10)), (10, 16, 10));
        assert_eq!(parse_number("2.00000-3"), Some(2e-3));
        assert_eq!(parse_number("1.5+2"), Some(150.0));
        assert_eq!(parse_number("1.0D2"), Some(100.0));
    }
}
