//! The deck as keyword blocks: each keyword with its data cards and its card format.
//!
//! A keyword line is `*NAME` followed, optionally, by a format suffix: `+` (long format,
//! 20-column fields), `-` (standard format) or `%` (10-digit ids), attached or as the next
//! word. `*KEYWORD` sets the format of every keyword after it: `LONG=Y` long, `LONG=S` or
//! `LONG=K` standard, `I10=Y` 10-digit ids; any other word on that line (a memory size) is
//! ignored, an unknown `NAME=VALUE` option is a warning. Comment lines (`$`) are dropped;
//! blank lines inside a keyword are cards (all fields blank), trailing blank lines are not.
//! Anything before the first keyword is skipped, as LS-DYNA does, and so is everything
//! after `*END`.

use super::cards::{Card, Format};
use super::source::Source;

/// A keyword and its cards: the keyword's file index and line, its upper-case name without
/// the format suffix, and the format of its cards.
pub(crate) struct Block<'a> {
    pub file: usize,
    pub line: usize,
    pub kw: String,
    pub format: Format,
    pub cards: Vec<Card<'a>>,
    /// The lines of the blank lines that ended the keyword: not cards, but a card the
    /// keyword requires may be one of them (a card of defaults written as a blank line).
    pub blank_tail: Vec<usize>,
}

/// The deck's blocks, and warnings about `*KEYWORD` options.
pub(crate) fn blocks(src: &Source) -> (Vec<Block<'_>>, Vec<String>) {
    let mut lines = src.lines.iter().peekable();
    let mut out = Vec::new();
    let mut warnings = Vec::new();
    let mut deck_format = Format::default();
    while let Some(l) = lines.next() {
        let Some(rest) = l.text.strip_prefix('*') else {
            continue;
        };
        let mut words = rest.split_whitespace();
        let mut name = words.next().unwrap_or("").to_uppercase();
        let mut format = deck_format;
        let mut suffix = name.chars().last().filter(|c| matches!(c, '+' | '-' | '%'));
        if suffix.is_some() {
            name.pop();
        }
        let others: Vec<&str> = words.collect();
        if suffix.is_none()
            && let Some(&w) = others.first()
            && matches!(w, "+" | "-" | "%")
        {
            suffix = w.chars().next();
        }
        match suffix {
            Some('+') => format.long = true,
            Some('-') => format = Format::default(),
            Some('%') => format.i10 = true,
            _ => {}
        }
        if name == "KEYWORD" {
            for w in &others {
                let Some((key, value)) = w.split_once('=') else {
                    continue;
                };
                match (key.to_uppercase().as_str(), value.to_uppercase().as_str()) {
                    ("LONG", "Y") => deck_format.long = true,
                    ("LONG", "S" | "K" | "N") => deck_format.long = false,
                    ("I10", "Y") => deck_format.i10 = true,
                    ("I10", "N") => deck_format.i10 = false,
                    _ => warnings.push(format!(
                        "{}: line {}: *KEYWORD option `{w}` ignored (LONG=Y|S|K and I10=Y|N are read)",
                        src.files[l.file], l.line
                    )),
                }
            }
        }
        let mut cards = Vec::new();
        while let Some(c) = lines.peek().filter(|_| name != "END") {
            if c.text.starts_with('*') {
                break;
            }
            if !c.text.starts_with('$') {
                cards.push(Card {
                    line: c.line,
                    text: c.text.trim_end(),
                });
            }
            lines.next();
        }
        // Trailing blank lines are not cards (unless a required card is missing).
        let mut blank_tail = Vec::new();
        while let Some(c) = cards.last().filter(|c| c.text.trim().is_empty()) {
            blank_tail.insert(0, c.line);
            cards.pop();
        }
        let end = name == "END";
        out.push(Block {
            file: l.file,
            line: l.line,
            kw: format!("*{name}"),
            format,
            cards,
            blank_tail,
        });
        if end {
            break;
        }
    }
    (out, warnings)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suffixes_and_keyword_options_set_the_format() {
        let text =
            "*KEYWORD LONG=Y\n*NODE\n*PART -\n*KEYWORD LONG=S\n*NODE +\n*NODE%\n*END\n*IGNORED\n";
        let src = Source::from_text(text, "t.k").unwrap();
        let (b, w) = blocks(&src);
        assert!(w.is_empty(), "{w:?}");
        let got: Vec<(&str, bool, bool)> = b
            .iter()
            .map(|b| (b.kw.as_str(), b.format.long, b.format.i10))
            .collect();
        assert_eq!(
            got,
            vec![
                ("*KEYWORD", false, false),
                ("*NODE", true, false),
                ("*PART", false, false),
                ("*KEYWORD", true, false),
                ("*NODE", true, false),
                ("*NODE", false, true),
                ("*END", false, false),
            ]
        );
        let src = Source::from_text("*KEYWORD MEMORY=2000m\n*END\n", "t.k").unwrap();
        assert_eq!(blocks(&src).1.len(), 1);
    }
}
