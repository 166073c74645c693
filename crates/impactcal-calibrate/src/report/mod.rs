//! Reports a person reads: a [`Report`] document of sections, tables and figures that keep
//! their numbers, rendered to one self-contained HTML file (inline SVG) and to Markdown with
//! SVG files beside it.
//!
//! A study or a closed loop builds the document; [`write()`] checks it (every fault is a typed
//! error naming the figure, series and index: nothing is drawn blank), draws each figure
//! once with plotters' SVG backend, and writes `report.html`, `report.md` and one
//! `<figure name>.svg` per figure. Text in SVG stays `<text>` for the viewer to lay out, so
//! no font library is involved, and the same document always gives the same bytes.
//!
//! ```
//! use impactcal_calibrate::report::{
//!     render_html, render_markdown, Axis, Block, Figure, Lines, Plot, Report, Section, Series,
//! };
//!
//! let t: Vec<f64> = (0..50).map(|k| k as f64 * 1e-3).collect();
//! let q: Vec<f64> = t.iter().map(|t| (300.0 * t).sin()).collect();
//! let figure = Figure {
//!     name: "fig-q".into(),
//!     caption: "Q(t) of the test".into(),
//!     plot: Plot::Lines(Lines {
//!         x: t,
//!         x_axis: Axis { label: "time (s)".into() },
//!         y_axis: Axis { label: "Q (in/s)".into() },
//!         series: vec![Series { name: "test".into(), values: q }],
//!     }),
//! };
//! let report = Report {
//!     title: "Study <A & B>".into(),
//!     lead: vec!["The model can explain the test.".into()],
//!     sections: vec![Section { heading: "M1".into(), blocks: vec![Block::Figure(figure)] }],
//! };
//! let html = render_html(&report)?;
//! assert!(html.contains("<title>Study &lt;A &amp; B&gt;</title>"));
//! assert!(html.contains("<figure id=\"fig-q\">\n<svg"));
//! assert!(render_markdown(&report)?.contains("![Q(t) of the test](fig-q.svg)"));
//! # Ok::<(), impactcal_calibrate::CalibrateError>(())
//! ```

mod document;
mod figure;
mod flags;
mod html;
mod markdown;
mod provenance;
mod validate;

#[cfg(test)]
mod tests;

use std::fs;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use impactcal_core::CoreError;

pub use document::{
    Axis, Block, Envelope, Figure, HeatMap, Lines, Marker, Plot, Report, Section, Series, Stacked,
    Structure, Table,
};
pub use figure::render_svg;
pub use flags::{AT_BOUND, bound_flag};
pub use html::{escape_html, render_html};
pub use markdown::{escape_markdown, render_markdown};
pub use provenance::{Provenance, utc_date};
pub use validate::{check_figure, check_report, check_table};

use crate::Result;

/// The files [`write()`] wrote.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReportFiles {
    /// `dir/report.html`: the whole report in one self-contained file.
    pub html: PathBuf,
    /// `dir/report.md`: the report in Markdown, linking the SVG files.
    pub markdown: PathBuf,
    /// `dir/<name>.svg` for each figure, in reading order.
    pub figures: Vec<PathBuf>,
}

/// Writes `report` into `dir` (created if missing): `report.html`, `report.md` and one
/// `<figure.name>.svg` per figure. Everything is rendered before the first file is written,
/// so a faulty document writes nothing; each file is written to a temporary name in `dir`
/// and renamed over its final name, so a reader never sees a half-written file.
///
/// # Errors
/// A fault of the document (see [`check_report`]); [`CoreError::Io`] naming the path if
/// `dir` cannot be created or a file cannot be written.
pub fn write(report: &Report, dir: &Path) -> Result<ReportFiles> {
    let html = render_html(report)?;
    let markdown = render_markdown(report)?;
    let mut svgs = Vec::new();
    for section in &report.sections {
        for block in &section.blocks {
            if let Block::Figure(f) = block {
                svgs.push((dir.join(format!("{}.svg", f.name)), render_svg(f)?));
            }
        }
    }
    fs::create_dir_all(dir).map_err(|source| CoreError::Io {
        path: dir.display().to_string(),
        source,
    })?;
    for (path, svg) in &svgs {
        write_atomically(path, svg)?;
    }
    let files = ReportFiles {
        html: dir.join("report.html"),
        markdown: dir.join("report.md"),
        figures: svgs.into_iter().map(|(path, _)| path).collect(),
    };
    write_atomically(&files.markdown, &markdown)?;
    write_atomically(&files.html, &html)?;
    Ok(files)
}

/// Writes `text` to a temporary file beside `path`, flushes it to disk and renames it to
/// `path`; on failure the temporary file is removed.
fn write_atomically(path: &Path, text: &str) -> Result<()> {
    let io = |p: &Path| {
        let p = p.display().to_string();
        move |source| CoreError::Io { path: p, source }
    };
    let file_name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = path.with_file_name(format!(".{file_name}.{}.tmp", std::process::id()));
    let result = fs::File::create(&tmp)
        .and_then(|mut f| {
            f.write_all(text.as_bytes())?;
            f.sync_all()
        })
        .map_err(io(&tmp))
        .and_then(|()| fs::rename(&tmp, path).map_err(io(path)));
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    Ok(result?)
}
