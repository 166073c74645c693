//! A matrix as a heat map (row 0 at the top), with a bar of weights along each axis,
//! outlined cells (the optimal pairing) and a colour bar.

use plotters::coord::ranged1d::SegmentValue;
use plotters::prelude::*;

use super::OUTLINE;
use super::{
    Area, BAR, BOTTOM_AREA, Drawn, LEFT_AREA, MARGIN, WIDTH, centred, colour_bar, dark, diverging,
    label_font, sequential, tick_font,
};
use crate::Result;
use crate::report::document::HeatMap;

/// Width of the panel of row weights and of the colour bar, in pixels.
const ROW_PANEL: u32 = 200;
const BAR_PANEL: u32 = 100;
/// Height of the panel of column weights, and of the key strip when there is no such panel.
const COLUMN_PANEL: u32 = 200;
const KEY_STRIP: u32 = 44;

/// Draws the heat map of `p`: cells coloured over `p.range` (values outside it take the end
/// colours) on the sequential scale, or on the blue-white-red diverging scale with white at
/// zero when the range holds values of both signs (`low < 0 < high`, see [`scale`]), the marked cells outlined, values written in the
/// cells if asked, row weights as horizontal bars on the right, column weights as vertical
/// bars on top, each bar labelled with its value and each set of bars described by its own
/// axis label (`row_weights_axis`, `column_weights_axis`), and a colour bar.
pub(super) fn draw(p: &HeatMap, svg: &mut String, name: &str) -> Result<()> {
    let rows = p.values.len();
    let cols = p.values.first().map_or(0, Vec::len);
    let right = if p.row_weights.is_empty() {
        0
    } else {
        ROW_PANEL
    } + BAR_PANEL;
    let left = WIDTH - right;
    let plot_w = f64::from(left - LEFT_AREA - 2 * MARGIN);
    let cell = plot_w / cols as f64;
    let plot_h = (cell * rows as f64).clamp(220.0, 640.0).round() as u32;
    let top = if !p.column_weights.is_empty() {
        COLUMN_PANEL
    } else if !p.marked.is_empty() {
        KEY_STRIP
    } else {
        0
    };
    let height = top + plot_h + BOTTOM_AREA + 2 * MARGIN;

    let root = SVGBackend::with_string(svg, (WIDTH, height)).into_drawing_area();
    root.fill(&WHITE).drawn(name)?;
    let (upper, lower) = root.split_vertically(top);
    let (map_area, side) = lower.split_horizontally(left);
    let (weights_area, bar_area) = side.split_horizontally(right - BAR_PANEL);

    draw_cells(p, &map_area, name)?;
    if !p.row_weights.is_empty() {
        draw_row_weights(
            &p.row_weights,
            &p.row_weights_axis.label,
            &weights_area,
            name,
        )?;
    }
    let (column_area, key_area) = upper.split_horizontally(left);
    if !p.column_weights.is_empty() {
        draw_column_weights(
            &p.column_weights,
            &p.column_weights_axis.label,
            &column_area,
            name,
        )?;
    }
    if !p.marked.is_empty() {
        draw_key(&key_area, name)?;
    }
    let (lo, hi) = p.range;
    colour_bar(
        &bar_area,
        (lo, hi),
        |t| scale(p.range, lo + t * (hi - lo)),
        None,
        name,
    )?;
    root.present().drawn(name)
}

/// The colour of `v` on the scale of `range = (low, high)`: signed values (`low < 0 <
/// high`) on the diverging scale, `v / max(-low, high)` from blue (-1) through white (0) to
/// red (+1), so that the sign reads as hue and zero is white; otherwise the sequential scale
/// from `low` to `high`.
fn scale((lo, hi): (f64, f64), v: f64) -> RGBColor {
    if lo < 0.0 && hi > 0.0 {
        diverging(v / hi.max(-lo))
    } else {
        sequential((v - lo) / (hi - lo))
    }
}

/// `n` segments, one per cell: plotters' integer ranges include their end, so `0..n - 1`.
fn segments(
    n: usize,
) -> plotters::coord::ranged1d::SegmentedCoord<plotters::coord::types::RangedCoordusize> {
    (0..n.saturating_sub(1)).into_segmented()
}

/// `v` with three significant digits or so, for bar labels.
fn short(v: f64) -> String {
    match v.abs() {
        a if a >= 100.0 => format!("{v:.0}"),
        a if a >= 10.0 => format!("{v:.1}"),
        a if a >= 1.0 => format!("{v:.2}"),
        _ => format!("{v:.3}"),
    }
}

/// Segment `r` of the vertical axis holds matrix row `rows - 1 - r` (row 0 on top).
fn flip(rows: usize, i: usize) -> usize {
    rows - 1 - i
}

fn draw_cells(p: &HeatMap, area: &Area<'_>, name: &str) -> Result<()> {
    let rows = p.values.len();
    let cols = p.values.first().map_or(0, Vec::len);
    let mut chart = ChartBuilder::on(area)
        .margin(MARGIN)
        .x_label_area_size(BOTTOM_AREA)
        .y_label_area_size(LEFT_AREA)
        .build_cartesian_2d(segments(cols), segments(rows))
        .drawn(name)?;
    let column_label = |v: &SegmentValue<usize>| match v {
        SegmentValue::CenterOf(j) => (j + 1).to_string(),
        _ => String::new(),
    };
    let row_label = |v: &SegmentValue<usize>| match v {
        SegmentValue::CenterOf(r) if *r < rows => (flip(rows, *r) + 1).to_string(),
        _ => String::new(),
    };
    chart
        .configure_mesh()
        .disable_mesh()
        .x_labels(cols.min(30))
        .y_labels(rows.min(30))
        .x_label_formatter(&column_label)
        .y_label_formatter(&row_label)
        .label_style(tick_font())
        .axis_desc_style(label_font())
        .x_desc(p.column_axis.label.as_str())
        .y_desc(p.row_axis.label.as_str())
        .draw()
        .drawn(name)?;
    let corners = |i: usize, j: usize| {
        let r = flip(rows, i);
        [
            (SegmentValue::Exact(j), SegmentValue::Exact(r)),
            (SegmentValue::Exact(j + 1), SegmentValue::Exact(r + 1)),
        ]
    };
    let colour = |v: f64| scale(p.range, v);
    chart
        .draw_series(p.values.iter().enumerate().flat_map(|(i, row)| {
            row.iter()
                .enumerate()
                .map(move |(j, &v)| Rectangle::new(corners(i, j), colour(v).filled()))
        }))
        .drawn(name)?;
    if p.annotate {
        chart
            .draw_series(p.values.iter().enumerate().flat_map(|(i, row)| {
                row.iter().enumerate().map(move |(j, &v)| {
                    let ink: &'static RGBColor = if dark(colour(v)) { &WHITE } else { &BLACK };
                    let at = (
                        SegmentValue::CenterOf(j),
                        SegmentValue::CenterOf(flip(rows, i)),
                    );
                    Text::new(format!("{v:.2}"), at, centred(tick_font().color(ink)))
                })
            }))
            .drawn(name)?;
    }
    chart
        .draw_series(
            p.marked
                .iter()
                .map(|&(i, j)| Rectangle::new(corners(i, j), OUTLINE.stroke_width(4))),
        )
        .drawn(name)?;
    Ok(())
}

/// The largest weight, or 1 when every weight is zero or negative, widened by 25 % for the
/// value labels.
fn weight_limit(weights: &[f64]) -> f64 {
    let top = weights.iter().copied().fold(0.0, f64::max);
    if top > 0.0 { 1.25 * top } else { 1.0 }
}

fn draw_row_weights(weights: &[f64], desc: &str, area: &Area<'_>, name: &str) -> Result<()> {
    let rows = weights.len();
    let lowest = weights.iter().copied().fold(0.0, f64::min);
    let mut chart = ChartBuilder::on(area)
        .margin(MARGIN)
        .x_label_area_size(BOTTOM_AREA)
        .build_cartesian_2d(lowest..weight_limit(weights), segments(rows))
        .drawn(name)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .disable_y_axis()
        .x_labels(3)
        .label_style(tick_font())
        .axis_desc_style(label_font())
        .x_desc(desc)
        .draw()
        .drawn(name)?;
    chart
        .draw_series(weights.iter().enumerate().map(|(i, &w)| {
            let r = flip(rows, i);
            let mut bar = Rectangle::new(
                [
                    (0.0, SegmentValue::Exact(r)),
                    (w, SegmentValue::Exact(r + 1)),
                ],
                BAR.filled(),
            );
            bar.set_margin(3, 3, 0, 0);
            bar
        }))
        .drawn(name)?;
    chart
        .draw_series(weights.iter().enumerate().map(|(i, &w)| {
            let at = (w.max(0.0), SegmentValue::CenterOf(flip(rows, i)));
            let style = tick_font().pos(plotters::style::text_anchor::Pos::new(
                plotters::style::text_anchor::HPos::Left,
                plotters::style::text_anchor::VPos::Center,
            ));
            Text::new(format!(" {}", short(w)), at, style)
        }))
        .drawn(name)?;
    Ok(())
}

fn draw_column_weights(weights: &[f64], desc: &str, area: &Area<'_>, name: &str) -> Result<()> {
    let cols = weights.len();
    let lowest = weights.iter().copied().fold(0.0, f64::min);
    let mut chart = ChartBuilder::on(area)
        .margin(MARGIN)
        .y_label_area_size(LEFT_AREA)
        .build_cartesian_2d(segments(cols), lowest..weight_limit(weights))
        .drawn(name)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_labels(3)
        .label_style(tick_font())
        .axis_desc_style(label_font())
        .y_desc(desc)
        .draw()
        .drawn(name)?;
    chart
        .draw_series(weights.iter().enumerate().map(|(j, &w)| {
            let mut bar = Rectangle::new(
                [
                    (SegmentValue::Exact(j), 0.0),
                    (SegmentValue::Exact(j + 1), w),
                ],
                BAR.filled(),
            );
            bar.set_margin(0, 0, 3, 3);
            bar
        }))
        .drawn(name)?;
    if cols <= 16 {
        chart
            .draw_series(weights.iter().enumerate().map(|(j, &w)| {
                let style = tick_font().pos(plotters::style::text_anchor::Pos::new(
                    plotters::style::text_anchor::HPos::Center,
                    plotters::style::text_anchor::VPos::Bottom,
                ));
                Text::new(short(w), (SegmentValue::CenterOf(j), w.max(0.0)), style)
            }))
            .drawn(name)?;
    }
    Ok(())
}

/// The key of the outlined cells, top left of `area`.
fn draw_key(area: &Area<'_>, name: &str) -> Result<()> {
    area.draw(&Rectangle::new(
        [(12, 12), (32, 32)],
        OUTLINE.stroke_width(4),
    ))
    .drawn(name)?;
    area.draw(&Text::new("pairing", (40, 14), label_font()))
        .drawn(name)
}
