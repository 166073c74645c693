//! Deck templates: where the parameters of a run enter its input files.
//!
//! Two conventions, usable together in any text input:
//! - **placeholders** `<<name>>` (LS-OPT's convention), replaced by the value in its shortest
//!   form that reads back exactly; `<<name:w>>` writes it right-aligned in exactly `w`
//!   columns (for fixed-format fields), rounded to the most precise form that fits;
//! - **`*PARAMETER` cards** (LS-DYNA's own): the value fields of the `R` (real) and `I`
//!   (integer) parameters named like a parameter of the batch are rewritten in place; the
//!   fixed format (four name/value pairs of 10 columns each per line) is kept, and a
//!   comma-separated line stays comma-separated. Character (`C`) parameters are left alone.
//!   Integer parameters take the value rounded to the nearest integer.
//!
//! Names are plain identifiers (`[A-Za-z_][A-Za-z0-9_]*`), matched exactly. Every parameter
//! of the batch must appear in the template and every placeholder must name a parameter;
//! `*PARAMETER` entries that no parameter names keep the template's value. The values
//! actually written (after rounding to fit a field) are returned so that they can be
//! recorded with the run.
//!
//! A template may also hold quantities at given values ([`Template::holding`]): a name a
//! run does not give is then written at its held value, as a closed loop needs for the
//! candidate effects it has not freed and the test conditions (an impact speed) it does not
//! change.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use crate::error::{Result, RunnerError};

/// Whether `name` is a plain identifier: an ASCII letter or `_`, then letters, digits or
/// `_`. Only such names may name parameters; nothing else ever reaches a file or a command.
pub fn is_identifier(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// How a field is written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Style {
    /// A placeholder, shortest form or a fixed width.
    Placeholder { width: Option<usize> },
    /// The value field of a `*PARAMETER` entry: fixed 10 columns, or free (comma) format.
    Parameter { integer: bool, fixed: bool },
}

/// One place a value goes: line, byte range in the line, the parameter, how.
#[derive(Debug, Clone)]
struct Field {
    line: usize,
    start: usize,
    end: usize,
    name: String,
    style: Style,
}

/// A parsed template: its text and the places parameters go.
#[derive(Debug, Clone)]
pub struct Template {
    file: String,
    lines: Vec<String>,
    fields: Vec<Field>,
    held: BTreeMap<String, f64>,
}

impl Template {
    /// Reads and parses a template file.
    ///
    /// # Errors
    /// [`RunnerError::Io`] when the file cannot be read; as [`Template::parse`].
    pub fn read(path: &Path) -> Result<Template> {
        let text = std::fs::read_to_string(path).map_err(crate::error::io(path))?;
        Template::parse(&text, &path.display().to_string())
    }

    /// Parses template text; `file` names it in messages.
    ///
    /// # Errors
    /// [`RunnerError::Template`] naming the line of a `<<` without `>>`, a placeholder whose
    /// name is not an identifier or whose width is not a number in 1..=80, a `*PARAMETER`
    /// entry whose type is not `R`, `I` or `C` or whose name is not an identifier, or a
    /// `*PARAMETER` line that is not ASCII (its columns would be ambiguous).
    pub fn parse(text: &str, file: &str) -> Result<Template> {
        let lines: Vec<String> = text.split_inclusive('\n').map(str::to_string).collect();
        let mut fields = Vec::new();
        let mut in_parameter = false;
        for (i, raw) in lines.iter().enumerate() {
            let line = raw.trim_end_matches(['\n', '\r']);
            let err = |message: String| RunnerError::Template {
                file: file.to_string(),
                line: i + 1,
                message,
            };
            placeholders(line, i, &mut fields).map_err(err)?;
            if line.starts_with('*') {
                let keyword = line.split_whitespace().next().unwrap_or("");
                in_parameter = keyword.eq_ignore_ascii_case("*PARAMETER");
                continue;
            }
            if in_parameter && !line.starts_with('$') && !line.trim().is_empty() {
                if !line.is_ascii() {
                    return Err(err("a *PARAMETER line must be ASCII".into()));
                }
                parameter_line(line, i, &mut fields).map_err(err)?;
            }
        }
        Ok(Template {
            file: file.to_string(),
            lines,
            fields,
            held: BTreeMap::new(),
        })
    }

    /// The same template holding the quantities `held` at their values: a field whose name
    /// a run does not give (neither a coordinate nor part of its condition) is written at
    /// the held value, and a placeholder naming a held quantity is not an unknown name.
    /// Names the template does not use are ignored. A run that gives a held name writes its
    /// own value.
    #[must_use]
    pub fn holding(mut self, held: &BTreeMap<String, f64>) -> Template {
        self.held = held.clone();
        self
    }

    /// The quantities held ([`Template::holding`]).
    pub fn held(&self) -> &BTreeMap<String, f64> {
        &self.held
    }

    /// The template's text as read.
    pub fn text(&self) -> String {
        self.lines.concat()
    }

    /// The file the template came from.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// Every parameter name the template can take (placeholders, `R`/`I` `*PARAMETER`
    /// entries), sorted.
    pub fn names(&self) -> BTreeSet<&str> {
        self.fields.iter().map(|f| f.name.as_str()).collect()
    }

    /// The names of the placeholders `<<name>>` (each must be a parameter of a batch or a
    /// held quantity), sorted.
    pub fn placeholder_names(&self) -> BTreeSet<&str> {
        self.fields
            .iter()
            .filter(|f| matches!(f.style, Style::Placeholder { .. }))
            .map(|f| f.name.as_str())
            .collect()
    }

    /// Checks the template against the parameter names of a batch (the union over every
    /// template of the batch is checked by [`check_names`]).
    ///
    /// # Errors
    /// [`RunnerError::Names`] listing the placeholders that name no parameter.
    fn check_placeholders(&self, names: &[String]) -> Result<()> {
        let unknown: Vec<&str> = self
            .placeholder_names()
            .into_iter()
            .filter(|n| !names.iter().any(|m| m == n) && !self.held.contains_key(*n))
            .collect();
        if unknown.is_empty() {
            Ok(())
        } else {
            Err(RunnerError::Names {
                file: self.file.clone(),
                message: format!(
                    "placeholder{} {} name{} no parameter (the parameters are: {})",
                    if unknown.len() > 1 { "s" } else { "" },
                    quoted(&unknown),
                    if unknown.len() > 1 { "" } else { "s" },
                    names.join(", ")
                ),
            })
        }
    }

    /// The text with every field filled from `values` (in the order of `names`), or from
    /// the held values for a name not among `names`, and the values as written (after
    /// rounding to fit), in the order of `names`. Names the template does not use are
    /// written nowhere and recorded as given.
    ///
    /// # Errors
    /// [`RunnerError::Value`] for run `run` when a value does not fit its field (an integer
    /// wider than 10 columns, a fixed width too narrow for any form of the number) or is not
    /// finite.
    pub fn render(
        &self,
        run: usize,
        names: &[String],
        values: &[f64],
    ) -> Result<(String, Vec<f64>)> {
        let mut lines = self.lines.clone();
        let mut written = values.to_vec();
        // Right to left within a line, so earlier byte ranges stay valid.
        let mut order: Vec<&Field> = self.fields.iter().collect();
        order.sort_by(|a, b| (a.line, b.start).cmp(&(b.line, a.start)));
        for f in order {
            let k = names.iter().position(|n| *n == f.name);
            let Some(value) = k
                .map(|k| values[k])
                .or_else(|| self.held.get(&f.name).copied())
            else {
                continue;
            };
            let fail = |message: String| RunnerError::Value {
                run,
                name: f.name.clone(),
                value,
                message,
            };
            let (text, as_written) = match f.style {
                Style::Placeholder { width: None } => fit(value, usize::MAX, false),
                Style::Placeholder { width: Some(w) } => fit(value, w, false),
                Style::Parameter { integer, fixed } => {
                    fit(value, if fixed { 10 } else { 20 }, integer)
                }
            }
            .map_err(fail)?;
            if let Some(k) = k {
                written[k] = as_written;
            }
            let text = match f.style {
                Style::Placeholder { width: Some(w) } => format!("{text:>w$}"),
                Style::Parameter { fixed: true, .. } => format!("{text:>10}"),
                _ => text,
            };
            let line = &mut lines[f.line];
            let ending_at = line.trim_end_matches(['\n', '\r']).len();
            let ending = line[ending_at..].to_string();
            let mut body = line[..ending_at].to_string();
            if body.len() < f.end {
                body.push_str(&" ".repeat(f.end - body.len()));
            }
            body.replace_range(f.start..f.end, &text);
            *line = body + &ending;
        }
        Ok((lines.concat(), written))
    }
}

/// Checks the parameter names of a batch against its templates: every name a plain
/// identifier, every name used by some template, every placeholder a name.
///
/// # Errors
/// [`RunnerError::Names`] listing every name at fault (a name that is not an identifier is
/// refused before anything is written or run).
pub fn check_names(templates: &[&Template], names: &[String]) -> Result<()> {
    let file = templates
        .iter()
        .map(|t| t.file.as_str())
        .collect::<Vec<_>>()
        .join(", ");
    let bad: Vec<&str> = names
        .iter()
        .map(String::as_str)
        .filter(|n| !is_identifier(n))
        .collect();
    if !bad.is_empty() {
        return Err(RunnerError::Names {
            file,
            message: format!(
                "parameter names must be plain identifiers (letters, digits, `_`): {}",
                quoted(&bad)
            ),
        });
    }
    for t in templates {
        t.check_placeholders(names)?;
    }
    let used: BTreeSet<&str> = templates.iter().flat_map(|t| t.names()).collect();
    let unused: Vec<&str> = names
        .iter()
        .map(String::as_str)
        .filter(|n| !used.contains(n))
        .collect();
    if !unused.is_empty() {
        return Err(RunnerError::Names {
            file,
            message: format!(
                "parameter{} {} appear{} nowhere in the template (neither a <<name>> placeholder nor an R/I *PARAMETER entry)",
                if unused.len() > 1 { "s" } else { "" },
                quoted(&unused),
                if unused.len() > 1 { "" } else { "s" },
            ),
        });
    }
    Ok(())
}

fn quoted(names: &[&str]) -> String {
    names
        .iter()
        .map(|n| format!("`{n}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Finds the placeholders of one line.
fn placeholders(
    line: &str,
    index: usize,
    fields: &mut Vec<Field>,
) -> std::result::Result<(), String> {
    let mut from = 0;
    while let Some(open) = line[from..].find("<<").map(|p| p + from) {
        let Some(close) = line[open + 2..].find(">>").map(|p| p + open + 2) else {
            return Err(format!("`<<` at column {} has no closing `>>`", open + 1));
        };
        let inner = &line[open + 2..close];
        let (name, width) = match inner.split_once(':') {
            Some((n, w)) => {
                let w = w.trim();
                match w.parse::<usize>() {
                    Ok(w) if (1..=80).contains(&w) => (n.trim(), Some(w)),
                    _ => {
                        return Err(format!(
                            "placeholder `<<{inner}>>`: the width `{w}` must be a whole number from 1 to 80"
                        ));
                    }
                }
            }
            None => (inner.trim(), None),
        };
        if !is_identifier(name) {
            return Err(format!(
                "placeholder `<<{inner}>>`: `{name}` is not a plain identifier (letters, digits, `_`)"
            ));
        }
        fields.push(Field {
            line: index,
            start: open,
            end: close + 2,
            name: name.to_string(),
            style: Style::Placeholder { width },
        });
        from = close + 2;
    }
    Ok(())
}

/// Finds the R/I entries of one `*PARAMETER` data line.
fn parameter_line(
    line: &str,
    index: usize,
    fields: &mut Vec<Field>,
) -> std::result::Result<(), String> {
    // (name field, value field byte range)
    let mut entries: Vec<(&str, usize, usize)> = Vec::new();
    let fixed = !line.contains(',');
    if fixed {
        for k in 0..4 {
            let (ns, vs, ve) = (20 * k, 20 * k + 10, 20 * k + 20);
            if ns >= line.len() || line[ns..(ns + 10).min(line.len())].trim().is_empty() {
                break;
            }
            entries.push((&line[ns..vs.min(line.len())], vs, ve));
        }
    } else {
        let mut offsets = Vec::new();
        let mut start = 0;
        for part in line.split(',') {
            offsets.push((start, start + part.len()));
            start += part.len() + 1;
        }
        for pair in offsets.chunks(2) {
            let (ns, ne) = pair[0];
            if line[ns..ne].trim().is_empty() {
                break;
            }
            let (vs, ve) = pair.get(1).copied().unwrap_or((line.len(), line.len()));
            entries.push((&line[ns..ne], vs, ve));
        }
    }
    for (name_field, vs, ve) in entries {
        let spec = name_field.trim();
        let mut chars = spec.chars();
        let kind = chars.next().map(|c| c.to_ascii_uppercase());
        let name = chars.as_str().trim();
        let integer = match kind {
            Some('R') => false,
            Some('I') => true,
            Some('C') => continue,
            _ => {
                return Err(format!(
                    "*PARAMETER entry `{spec}`: the type must be R, I or C followed by the name"
                ));
            }
        };
        if !is_identifier(name) {
            return Err(format!(
                "*PARAMETER entry `{spec}`: `{name}` is not a plain identifier"
            ));
        }
        fields.push(Field {
            line: index,
            start: vs,
            end: ve,
            name: name.to_string(),
            style: Style::Parameter { integer, fixed },
        });
    }
    Ok(())
}

/// The most precise text of `value` in at most `width` characters, and the value it reads
/// back as. Integers are rounded; reals try the shortest exact form, then fixed and
/// scientific forms of decreasing precision, keeping the one closest to `value`.
fn fit(value: f64, width: usize, integer: bool) -> std::result::Result<(String, f64), String> {
    if !value.is_finite() {
        return Err("not a finite number".into());
    }
    if integer {
        let r = value.round();
        let text = format!("{r}");
        return if text.len() <= width {
            Ok((text, r))
        } else {
            Err(format!(
                "the integer {text} does not fit in {width} columns"
            ))
        };
    }
    let exact = format!("{value}");
    if exact.len() <= width {
        return Ok((exact, value));
    }
    let mut best: Option<(String, f64)> = None;
    for p in 0..=17 {
        for text in [format!("{value:.p$e}"), format!("{value:.p$}")] {
            if text.len() > width {
                continue;
            }
            let Ok(back) = text.parse::<f64>() else {
                continue;
            };
            let better = best
                .as_ref()
                .is_none_or(|(_, b)| (back - value).abs() < (b - value).abs());
            if better {
                best = Some((text, back));
            }
        }
    }
    best.ok_or_else(|| format!("no form of the number fits in {width} columns"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(n: &[&str]) -> Vec<String> {
        n.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn placeholders_fill_exactly_or_to_width() {
        let t = Template::parse("a <<t>> b\n<<e:10>>|<<t>>\n", "d.k").unwrap();
        let (text, written) = t.render(0, &names(&["t", "e"]), &[0.1, 2.1e11]).unwrap();
        assert_eq!(text, "a 0.1 b\n    2.1e11|0.1\n");
        assert_eq!(written, vec![0.1, 2.1e11]);
        // A value with more digits than the width holds is rounded and recorded as written.
        let (text, written) = t
            .render(0, &names(&["t", "e"]), &[0.1, 0.000_160_996_894_379_984_87])
            .unwrap();
        let field = &text.lines().nth(1).unwrap()[..10];
        assert_eq!(field.len(), 10);
        assert_eq!(
            field.trim().parse::<f64>().unwrap().to_bits(),
            written[1].to_bits()
        );
        assert_eq!(field, "1.60997e-4");
    }

    #[test]
    fn parameter_cards_keep_their_columns() {
        let row = |a: &str, b: &str, c: &str, d: &str, e: &str, f: &str| {
            format!("{a:<10}{b:>10}{c:<10}{d:>10}{e:<10}{f:>10}")
        };
        let fixed = row("R   thick", "0.002", "I    nip", "5", "R      vel", "-5.0");
        let deck = format!(
            "*KEYWORD\n*PARAMETER\n$ name     value\n{fixed}\n*PARAMETER\nr e, 2.1e11, C mat, steel\n*NODE\n"
        );
        let t = Template::parse(&deck, "p.k").unwrap();
        assert_eq!(
            t.names().into_iter().collect::<Vec<_>>(),
            ["e", "nip", "thick", "vel"]
        );
        let (text, written) = t
            .render(3, &names(&["thick", "nip", "e"]), &[0.0031, 4.6, 2.0e11])
            .unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines[3],
            row("R   thick", "0.0031", "I    nip", "5", "R      vel", "-5.0")
        );
        assert_eq!(lines[5], "r e,200000000000, C mat, steel");
        assert_eq!(written, vec![0.0031, 5.0, 2.0e11]);
        // Untouched lines are kept byte for byte.
        assert_eq!(lines[2], "$ name     value");
    }

    #[test]
    fn held_quantities_fill_what_a_run_does_not_give() {
        let deck = "<<a>> <<damp>>\n*PARAMETER\nR fric,0.3\nR v,-5.0\n";
        let held: BTreeMap<String, f64> = [("damp".to_string(), 0.0), ("fric".to_string(), 0.25)]
            .into_iter()
            .collect();
        let t = Template::parse(deck, "d.k").unwrap().holding(&held);
        // `damp` is no unknown placeholder once held.
        check_names(&[&t], &names(&["a"])).unwrap();
        let (text, written) = t.render(0, &names(&["a"]), &[1.5]).unwrap();
        assert_eq!(text, "1.5 0\n*PARAMETER\nR fric,0.25\nR v,-5.0\n");
        assert_eq!(written, vec![1.5]);
        // A run that gives a held name (a freed candidate, a condition) writes its own value.
        let (text, written) = t
            .render(0, &names(&["a", "damp", "v"]), &[1.5, 40.25, -4.5])
            .unwrap();
        assert_eq!(text, "1.5 40.25\n*PARAMETER\nR fric,0.25\nR v,-4.5\n");
        assert_eq!(written, vec![1.5, 40.25, -4.5]);
        // Without holding, `damp` names nothing.
        let bare = Template::parse(deck, "d.k").unwrap();
        let e = check_names(&[&bare], &names(&["a"])).unwrap_err();
        assert!(e.to_string().contains("`damp` names no parameter"), "{e}");
    }

    #[test]
    fn names_are_checked_both_ways_and_must_be_identifiers() {
        let t = Template::parse("<<a>> <<b>>\n*PARAMETER\nR       c       1.0\n", "d.k").unwrap();
        check_names(&[&t], &names(&["a", "b", "c"])).unwrap();
        check_names(&[&t], &names(&["a", "b"])).unwrap();
        let e = check_names(&[&t], &names(&["a"])).unwrap_err();
        assert!(e.to_string().contains("`b` names no parameter"), "{e}");
        let e = check_names(&[&t], &names(&["a", "b", "d"])).unwrap_err();
        assert!(e.to_string().contains("`d` appears nowhere"), "{e}");
        let e = check_names(&[&t], &names(&["a", "b", "a;rm -rf"])).unwrap_err();
        assert!(e.to_string().contains("`a;rm -rf`"), "{e}");
        assert_eq!(e.kind(), impactcal_core::ErrorKind::BadInput);
        for bad in ["<<a;rm -rf ~>>", "<<a", "<<a:0>>", "<<1a>>"] {
            let e = Template::parse(&format!("x\n{bad}\n"), "d.k").unwrap_err();
            assert!(e.to_string().starts_with("d.k: line 2:"), "{e}");
        }
        let e = Template::parse("*PARAMETER\nX    thick       1.0\n", "d.k").unwrap_err();
        assert!(e.to_string().contains("line 2"), "{e}");
    }

    #[test]
    fn fit_rounds_to_the_closest_form() {
        assert_eq!(fit(123.456_789_012, 10, false).unwrap().0, "123.456789");
        assert_eq!(fit(-1.5e-7, 10, false).unwrap().0, "-1.5e-7");
        assert_eq!(
            fit(12_345_678_901.0, 10, true).unwrap_err(),
            "the integer 12345678901 does not fit in 10 columns"
        );
        assert!(fit(f64::NAN, 10, false).is_err());
    }
}
