//! The HTML renderer: one self-contained file (inline CSS and SVG, no scripts, no fonts or
//! anything else fetched), readable in any browser opened from disk.

use std::fmt::Write as _;

use super::document::{Block, Figure, Report, Table};
use super::figure::render_svg;
use super::validate::check_report;
use crate::Result;

/// The style sheet, inline: a readable column up to 1000 px wide, figures scaled to it.
const STYLE: &str = "\
body{font-family:system-ui,-apple-system,'Segoe UI',Roboto,'Helvetica Neue',Arial,sans-serif;\
line-height:1.5;color:#1a1a1a;background:#fff;margin:0}\
main{max-width:1000px;margin:0 auto;padding:1.5rem 1.25rem 3rem}\
h1{font-size:1.8rem;margin:.5rem 0 1rem}h2{font-size:1.35rem;margin:2.2rem 0 .8rem;\
border-bottom:1px solid #ddd;padding-bottom:.2rem}\
figure{margin:1.5rem 0}figure svg{display:block;width:100%;height:auto;max-width:1000px}\
figcaption{font-size:.95rem;color:#333;margin-top:.4rem}\
table{border-collapse:collapse;margin:1rem 0;font-size:.95rem}\
caption{text-align:left;font-weight:600;padding:.3rem 0}\
th,td{border:1px solid #ccc;padding:.25rem .6rem;text-align:left;vertical-align:top}\
th{background:#f3f3f3}tbody tr:nth-child(even){background:#fafafa}\
p{margin:.6rem 0}";

/// Renders `report` as one HTML5 document: the title, the lead paragraphs, then each
/// section with its paragraphs, tables (`<table>` with caption, header and body) and figures
/// (`<figure id="name">` holding the inline `<svg>` and a numbered `<figcaption>`). Text is
/// escaped (`& < > " '` become entities), so any text shows as written.
///
/// # Errors
/// The first fault of the document (see [`check_report`]), or a figure the plotting library
/// failed to draw.
pub fn render_html(report: &Report) -> Result<String> {
    check_report(report)?;
    let mut html = String::with_capacity(1 << 16);
    html.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
    html.push_str("<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n");
    push_line(&mut html, "<title>", &report.title, "</title>");
    html.push_str("<style>");
    html.push_str(STYLE);
    html.push_str("</style>\n</head>\n<body>\n<main>\n");
    push_line(&mut html, "<h1>", &report.title, "</h1>");
    for p in &report.lead {
        push_line(&mut html, "<p>", p, "</p>");
    }
    let mut number = 0;
    for section in &report.sections {
        html.push_str("<section>\n");
        push_line(&mut html, "<h2>", &section.heading, "</h2>");
        for block in &section.blocks {
            match block {
                Block::Paragraph(p) => push_line(&mut html, "<p>", p, "</p>"),
                Block::Table(t) => push_table(&mut html, t),
                Block::Figure(f) => {
                    number += 1;
                    push_figure(&mut html, f, number)?;
                }
            }
        }
        html.push_str("</section>\n");
    }
    html.push_str("</main>\n</body>\n</html>\n");
    Ok(html)
}

/// `text` with the five characters that mean markup in HTML replaced by entities.
pub fn escape_html(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

fn push_line(html: &mut String, open: &str, text: &str, close: &str) {
    html.push_str(open);
    html.push_str(&escape_html(text));
    html.push_str(close);
    html.push('\n');
}

fn push_table(html: &mut String, t: &Table) {
    html.push_str("<table>\n");
    if !t.caption.is_empty() {
        push_line(html, "<caption>", &t.caption, "</caption>");
    }
    html.push_str("<thead><tr>");
    for h in &t.header {
        let _ = write!(html, "<th>{}</th>", escape_html(h));
    }
    html.push_str("</tr></thead>\n<tbody>\n");
    for row in &t.rows {
        html.push_str("<tr>");
        for cell in row {
            let _ = write!(html, "<td>{}</td>", escape_html(cell));
        }
        html.push_str("</tr>\n");
    }
    html.push_str("</tbody>\n</table>\n");
}

fn push_figure(html: &mut String, f: &Figure, number: usize) -> Result<()> {
    let svg = render_svg(f)?;
    let _ = writeln!(html, "<figure id=\"{}\">", escape_html(&f.name));
    html.push_str(svg.trim_end());
    html.push('\n');
    let _ = writeln!(
        html,
        "<figcaption>Figure {number}. {}</figcaption>\n</figure>",
        escape_html(&f.caption)
    );
    Ok(())
}
