//! The Markdown renderer: the report as CommonMark with pipe tables, each figure an image
//! link to its SVG file beside the Markdown file.

use std::fmt::Write as _;

use super::document::{Block, Report, Table};
use super::validate::check_report;
use crate::Result;

/// Renders `report` as Markdown: `# title`, the lead, `## heading` per section, paragraphs,
/// tables as pipe tables under a bold caption, and each figure as `![caption](name.svg)`
/// with a numbered caption below. Text is escaped so that it shows as written: ASCII
/// punctuation that could start markup is backslash-escaped (`|` too, so cells never split)
/// and line breaks inside table cells become spaces.
///
/// # Errors
/// The first fault of the document (see [`check_report`]).
pub fn render_markdown(report: &Report) -> Result<String> {
    check_report(report)?;
    let mut md = String::with_capacity(1 << 14);
    let _ = writeln!(md, "# {}\n", escape_markdown(&one_line(&report.title)));
    for p in &report.lead {
        push_paragraph(&mut md, p);
    }
    let mut number = 0;
    for section in &report.sections {
        let _ = writeln!(md, "## {}\n", escape_markdown(&one_line(&section.heading)));
        for block in &section.blocks {
            match block {
                Block::Paragraph(p) => push_paragraph(&mut md, p),
                Block::Table(t) => push_table(&mut md, t),
                Block::Figure(f) => {
                    number += 1;
                    let caption = escape_markdown(&one_line(&f.caption));
                    let _ = writeln!(
                        md,
                        "![{caption}]({}.svg)\n\n*Figure {number}. {caption}*\n",
                        f.name
                    );
                }
            }
        }
    }
    Ok(md)
}

/// One line of `text` made safe for Markdown, so that it shows as written: characters that
/// open or close inline markup anywhere (`` \ ` * _ [ ] < > | & ~ ``) are backslash-escaped
/// (CommonMark allows it before any ASCII punctuation), and so is what would make the line a
/// heading, list item, quote or rule (a leading `#`, `-`, `+`, `=`, or the `.`/`)` after
/// leading digits that ends a list number). `|` is escaped too, so a table cell never splits.
pub fn escape_markdown(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + 8);
    let digits = text.bytes().take_while(u8::is_ascii_digit).count();
    for (i, c) in text.char_indices() {
        let always = matches!(
            c,
            '\\' | '`' | '*' | '_' | '[' | ']' | '<' | '>' | '|' | '&' | '~'
        );
        let at_start = i == 0 && matches!(c, '#' | '-' | '+' | '=');
        let list_number = digits > 0
            && i == digits
            && matches!(c, '.' | ')')
            && text[i + 1..].chars().next().is_none_or(char::is_whitespace);
        if always || at_start || list_number {
            out.push('\\');
        }
        out.push(c);
    }
    out
}

fn one_line(text: &str) -> String {
    text.split(['\n', '\r'])
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join(" ")
}

fn push_paragraph(md: &mut String, text: &str) {
    let lines: Vec<String> = text
        .lines()
        .map(|l| escape_markdown(l.trim_start()))
        .filter(|l| !l.is_empty())
        .collect();
    if lines.is_empty() {
        return;
    }
    md.push_str(&lines.join("\n"));
    md.push_str("\n\n");
}

fn push_table(md: &mut String, t: &Table) {
    if !t.caption.is_empty() {
        let _ = writeln!(md, "**{}**\n", escape_markdown(&one_line(&t.caption)));
    }
    let row = |cells: &[String]| {
        let inner: Vec<String> = cells
            .iter()
            .map(|c| escape_markdown(&one_line(c)))
            .collect();
        format!("| {} |", inner.join(" | "))
    };
    let _ = writeln!(md, "{}", row(&t.header));
    let _ = writeln!(md, "|{}", "---|".repeat(t.header.len()));
    for r in &t.rows {
        let _ = writeln!(md, "{}", row(r));
    }
    md.push('\n');
}
