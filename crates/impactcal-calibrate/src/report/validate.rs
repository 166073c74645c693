//! Checks a [`Report`] before anything is drawn or written, so that a fault in the document
//! is a typed error naming the figure, the series and the index, never a panic or a blank
//! figure.

use std::collections::BTreeSet;

use impactcal_core::CoreError;

use super::document::{
    Axis, Block, Envelope, Figure, HeatMap, Lines, Plot, Report, Series, Stacked, Structure, Table,
};
use crate::{CalibrateError, Result};

/// Checks every table and figure of `report` (see [`check_figure`] and [`check_table`]) and
/// that figure names are unique.
///
/// # Errors
/// The first fault found, in reading order.
pub fn check_report(report: &Report) -> Result<()> {
    let mut names = BTreeSet::new();
    for (s, section) in report.sections.iter().enumerate() {
        for block in &section.blocks {
            match block {
                Block::Paragraph(_) => {}
                Block::Table(table) => check_table(table, s, &section.heading)?,
                Block::Figure(figure) => {
                    check_figure(figure)?;
                    if !names.insert(figure.name.as_str()) {
                        return Err(document_error(
                            format!("figure `{}`", figure.name),
                            "the name is used by an earlier figure; figure names must be unique",
                        ));
                    }
                }
            }
        }
    }
    Ok(())
}

/// Checks a table: at least one column, every row as wide as the header.
///
/// # Errors
/// [`CoreError::Empty`] for a table without columns; [`CoreError::DimensionMismatch`] naming
/// the section, the table's caption and the row (1-based) for a row of the wrong width.
pub fn check_table(table: &Table, section: usize, heading: &str) -> Result<()> {
    let what = format!(
        "section {} (`{heading}`), table `{}`",
        section + 1,
        table.caption
    );
    if table.header.is_empty() {
        return Err(CoreError::Empty {
            what: format!("{what}: header"),
        }
        .into());
    }
    for (r, row) in table.rows.iter().enumerate() {
        if row.len() != table.header.len() {
            return Err(CoreError::DimensionMismatch {
                what: format!("{what}, row {}: cells (one per header column)", r + 1),
                expected: table.header.len(),
                found: row.len(),
            }
            .into());
        }
    }
    Ok(())
}

/// Checks one figure: a valid name (`[a-z0-9-]+`, at most 64 characters, not starting with
/// `-`), labelled axes, data to draw, every series as long as its abscissa, every number
/// finite, abscissae ascending, and kind-specific rules (band `upper >= lower`, marked
/// intervals and cells inside the plot, stacked values non-negative, colour range
/// increasing).
///
/// # Errors
/// [`CoreError::Empty`], [`CoreError::DimensionMismatch`], [`CoreError::NonFinite`] (with the
/// index) or [`CalibrateError::Report`], each naming the figure and the series.
pub fn check_figure(figure: &Figure) -> Result<()> {
    check_name(&figure.name)?;
    let fig = format!("figure `{}`", figure.name);
    match &figure.plot {
        Plot::Lines(p) => check_lines(&fig, p),
        Plot::Envelope(p) => check_envelope(&fig, p),
        Plot::HeatMap(p) => check_heat_map(&fig, p),
        Plot::Stacked(p) => check_stacked(&fig, p),
        Plot::Structure(p) => check_structure(&fig, p),
    }
}

fn document_error(what: String, reason: &str) -> CalibrateError {
    CalibrateError::Report {
        what,
        reason: reason.to_owned(),
    }
}

fn check_name(name: &str) -> Result<()> {
    let valid = !name.is_empty()
        && name.len() <= 64
        && !name.starts_with('-')
        && name
            .bytes()
            .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'-');
    if valid {
        Ok(())
    } else {
        Err(document_error(
            format!("figure name `{name}`"),
            "a figure name is a file stem of 1 to 64 characters from [a-z0-9-], not starting with `-`",
        ))
    }
}

fn check_axis(fig: &str, which: &str, axis: &Axis) -> Result<()> {
    if axis.label.trim().is_empty() {
        return Err(document_error(
            format!("{fig}: {which} axis"),
            "the axis label is blank; label it with its quantity and unit, e.g. `time (s)`",
        ));
    }
    Ok(())
}

fn check_finite(what: impl Fn() -> String, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(CoreError::NonFinite {
            what: what(),
            location: format!("index {i}"),
            value: values[i],
        }
        .into()),
    }
}

/// The abscissa: non-empty, finite, non-decreasing.
fn check_abscissa(fig: &str, x: &[f64]) -> Result<()> {
    if x.is_empty() {
        return Err(CoreError::Empty {
            what: format!("{fig}: abscissa"),
        }
        .into());
    }
    check_finite(|| format!("{fig}: abscissa"), x)?;
    if let Some(i) = x.windows(2).position(|w| w[1] < w[0]) {
        return Err(document_error(
            format!("{fig}: abscissa, index {}", i + 1),
            &format!(
                "abscissa values must ascend ({} follows {})",
                x[i + 1],
                x[i]
            ),
        ));
    }
    Ok(())
}

/// A named sequence as long as the abscissa, all finite.
fn check_values(what: impl Fn() -> String, values: &[f64], len: usize) -> Result<()> {
    if values.len() != len {
        return Err(CoreError::DimensionMismatch {
            what: format!("{}: values (one per abscissa value)", what()),
            expected: len,
            found: values.len(),
        }
        .into());
    }
    check_finite(what, values)
}

fn check_series(fig: &str, kind: &str, series: &[Series], len: usize) -> Result<()> {
    if series.is_empty() {
        return Err(CoreError::Empty {
            what: format!("{fig}: {kind}"),
        }
        .into());
    }
    for s in series {
        check_values(|| format!("{fig}, series `{}`", s.name), &s.values, len)?;
    }
    Ok(())
}

fn check_lines(fig: &str, p: &Lines) -> Result<()> {
    check_axis(fig, "x", &p.x_axis)?;
    check_axis(fig, "y", &p.y_axis)?;
    check_abscissa(fig, &p.x)?;
    check_series(fig, "series list", &p.series, p.x.len())
}

fn check_envelope(fig: &str, p: &Envelope) -> Result<()> {
    check_axis(fig, "x", &p.x_axis)?;
    check_axis(fig, "y", &p.y_axis)?;
    check_abscissa(fig, &p.x)?;
    let n = p.x.len();
    check_values(|| format!("{fig}, band lower edge"), &p.lower, n)?;
    check_values(|| format!("{fig}, band upper edge"), &p.upper, n)?;
    if let Some(i) = p.lower.iter().zip(&p.upper).position(|(lo, up)| up < lo) {
        return Err(document_error(
            format!("{fig}, band, index {i}"),
            &format!(
                "the upper edge {} lies below the lower edge {}",
                p.upper[i], p.lower[i]
            ),
        ));
    }
    for s in &p.series {
        check_values(|| format!("{fig}, series `{}`", s.name), &s.values, n)?;
    }
    let (x0, x1) = (p.x[0], p.x[n - 1]);
    for (k, &(a, b)) in p.marked.iter().enumerate() {
        check_finite(|| format!("{fig}, marked interval {k}"), &[a, b])?;
        if b < a || a < x0 || b > x1 {
            return Err(document_error(
                format!("{fig}, marked interval {k}"),
                &format!("[{a}, {b}] is not an interval inside the abscissa [{x0}, {x1}]"),
            ));
        }
    }
    Ok(())
}

fn check_heat_map(fig: &str, p: &HeatMap) -> Result<()> {
    check_axis(fig, "row", &p.row_axis)?;
    check_axis(fig, "column", &p.column_axis)?;
    let rows = p.values.len();
    let cols = p.values.first().map_or(0, Vec::len);
    if rows == 0 || cols == 0 {
        return Err(CoreError::Empty {
            what: format!("{fig}: matrix ({rows} x {cols})"),
        }
        .into());
    }
    for (i, row) in p.values.iter().enumerate() {
        if row.len() != cols {
            return Err(CoreError::DimensionMismatch {
                what: format!("{fig}: matrix row {i} (as long as row 0)"),
                expected: cols,
                found: row.len(),
            }
            .into());
        }
        check_finite(|| format!("{fig}: matrix row {i}"), row)?;
    }
    let (lo, hi) = p.range;
    check_finite(|| format!("{fig}: colour range"), &[lo, hi])?;
    if hi <= lo {
        return Err(document_error(
            format!("{fig}: colour range"),
            &format!("({lo}, {hi}) must have low < high"),
        ));
    }
    for (what, weights, len, axis) in [
        ("row weights", &p.row_weights, rows, &p.row_weights_axis),
        (
            "column weights",
            &p.column_weights,
            cols,
            &p.column_weights_axis,
        ),
    ] {
        if !weights.is_empty() {
            check_values(|| format!("{fig}, {what}"), weights, len)?;
            check_axis(fig, what, axis)?;
        }
    }
    if let Some(&(i, j)) = p.marked.iter().find(|&&(i, j)| i >= rows || j >= cols) {
        return Err(document_error(
            format!("{fig}: marked cell ({i}, {j})"),
            &format!("outside the {rows} x {cols} matrix"),
        ));
    }
    Ok(())
}

fn check_stacked(fig: &str, p: &Stacked) -> Result<()> {
    check_axis(fig, "x", &p.x_axis)?;
    check_axis(fig, "y", &p.y_axis)?;
    check_axis(fig, "top", &p.top_axis)?;
    check_abscissa(fig, &p.x)?;
    check_series(fig, "stacked series list", &p.stacked, p.x.len())?;
    for s in &p.stacked {
        if let Some(i) = s.values.iter().position(|v| *v < 0.0) {
            return Err(document_error(
                format!("{fig}, series `{}`, index {i}", s.name),
                &format!(
                    "stacked values must be non-negative, found {} (clip estimates at 0 \
                     before stacking)",
                    s.values[i]
                ),
            ));
        }
    }
    check_values(
        || format!("{fig}, top series `{}`", p.top.name),
        &p.top.values,
        p.x.len(),
    )
}

fn check_structure(fig: &str, p: &Structure) -> Result<()> {
    if p.points.is_empty() && p.marked.is_empty() {
        return Err(CoreError::Empty {
            what: format!("{fig}: structure (no points and no markers)"),
        }
        .into());
    }
    if p.unit.trim().is_empty() {
        return Err(document_error(
            format!("{fig}: length unit"),
            "the unit of the coordinates is blank",
        ));
    }
    for (i, pt) in p.points.iter().enumerate() {
        check_finite(|| format!("{fig}: point {i}"), pt)?;
    }
    for (i, m) in p.marked.iter().enumerate() {
        check_finite(|| format!("{fig}: marker {i} (`{}`)", m.label), &m.at)?;
        if let Some(v) = m.value {
            check_finite(|| format!("{fig}: marker {i} (`{}`) value", m.label), &[v])?;
        }
    }
    if p.marked.iter().any(|m| m.value.is_some()) {
        check_axis(fig, "value", &p.value_axis)?;
    }
    if let Some(l) = p.limit {
        if !(l.is_finite() && l > 0.0) {
            return Err(document_error(
                format!("{fig}: colour limit"),
                &format!("{l} must be a finite number above 0"),
            ));
        }
    }
    Ok(())
}
