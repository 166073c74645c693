//! Points of a structure in plan (`x-y`) and side (`x-z`) view with labelled markers,
//! coloured on a diverging scale where they carry values.

use std::ops::Range;

use plotters::prelude::*;

use super::PLAIN;
use super::{
    Area, BOTTOM_AREA, Drawn, GREY, LEFT_AREA, MARGIN, WIDTH, cartesian, colour_bar, diverging,
    padded, tick_font,
};
use crate::Result;
use crate::report::document::Structure;

/// Width of the colour bar column, present when a marker carries a value.
const BAR_PANEL: u32 = 100;
/// Limits of a projection's plot height in pixels.
const MIN_PLOT: f64 = 160.0;
const MAX_PLOT: f64 = 380.0;
/// Radius of a marker and of a structure point.
const MARKER: i32 = 7;
const POINT: i32 = 2;

/// Draws the plan view above the side view, both at one scale per view (a unit of length
/// is as long across as up), structure points small and grey, markers large with their
/// labels (the labels are the key: no legend box hides a marker). Markers with values are coloured by `value / max |value|` on a blue-white-red
/// scale, with a colour bar from `-max |value|` to `max |value|`.
pub(super) fn draw(p: &Structure, svg: &mut String, name: &str) -> Result<()> {
    let limit = p
        .marked
        .iter()
        .filter_map(|m| m.value)
        .fold(None, |acc: Option<f64>, v| {
            Some(acc.unwrap_or(0.0).max(v.abs()))
        });
    let bar = if limit.is_some() { BAR_PANEL } else { 0 };
    let left = WIDTH - bar;
    let plot_w = f64::from(left - LEFT_AREA - 3 * MARGIN);
    let all = || p.points.iter().chain(p.marked.iter().map(|m| &m.at));
    let ranges = |axis: usize| padded(all().map(|q| q[axis]));
    let views = [(1, "y"), (2, "z")].map(|(v, label)| {
        let (h, v_range) = equal_scale(ranges(0), ranges(v), plot_w);
        (v, label, h, v_range)
    });
    let heights = views.clone().map(|(_, _, h, v)| {
        let plot_h = plot_w * (v.end - v.start) / (h.end - h.start);
        plot_h.round() as u32 + BOTTOM_AREA + 2 * MARGIN
    });
    let root = SVGBackend::with_string(svg, (WIDTH, heights[0] + heights[1])).into_drawing_area();
    root.fill(&WHITE).drawn(name)?;
    let (plan, side) = root.split_vertically(heights[0]);
    let scale = limit.map(|l| if l > 0.0 { l } else { 1.0 });
    for ((v, label, h, v_range), area) in views.into_iter().zip([plan, side]) {
        let (view, bar_area) = area.split_horizontally(left);
        draw_view(p, &view, (h, v_range), v, label, scale, name)?;
        if let Some(l) = scale {
            colour_bar(&bar_area, (-l, l), |t| diverging(2.0 * t - 1.0), name)?;
        }
    }
    root.present().drawn(name)
}

/// Ranges of the horizontal and vertical coordinates widened about their centres so that
/// one unit of length spans the same number of pixels both ways, for a plot `plot_w` wide
/// whose height is the natural one clamped to `[MIN_PLOT, MAX_PLOT]`.
fn equal_scale(h: Range<f64>, v: Range<f64>, plot_w: f64) -> (Range<f64>, Range<f64>) {
    let (hw, vw) = (h.end - h.start, v.end - v.start);
    let plot_h = (plot_w * vw / hw).clamp(MIN_PLOT, MAX_PLOT);
    let per_pixel = (hw / plot_w).max(vw / plot_h);
    let widen = |r: Range<f64>, pixels: f64| {
        let (mid, half) = (0.5 * (r.start + r.end), 0.5 * per_pixel * pixels);
        (mid - half)..(mid + half)
    };
    (widen(h, plot_w), widen(v, plot_h))
}

fn draw_view(
    p: &Structure,
    area: &Area<'_>,
    (h, v_range): (Range<f64>, Range<f64>),
    v: usize,
    v_label: &str,
    scale: Option<f64>,
    name: &str,
) -> Result<()> {
    let x_desc = format!("x ({})", p.unit);
    let y_desc = format!("{v_label} ({})", p.unit);
    let mut chart = cartesian(area, h, v_range, Some(&x_desc), &y_desc, name)?;
    if !p.points.is_empty() {
        chart
            .draw_series(
                p.points
                    .iter()
                    .map(|q| Circle::new((q[0], q[v]), POINT, GREY.filled())),
            )
            .drawn(name)?;
    }
    let fill = |value: Option<f64>| match (value, scale) {
        (Some(x), Some(l)) => diverging(x / l),
        _ => PLAIN,
    };
    chart
        .draw_series(p.marked.iter().map(|m| {
            EmptyElement::at((m.at[0], m.at[v]))
                + Circle::new((0, 0), MARKER, fill(m.value).filled())
                + Circle::new((0, 0), MARKER, BLACK.stroke_width(1))
                + Text::new(m.label.clone(), (MARKER + 2, -MARKER - 14), tick_font())
        }))
        .drawn(name)?;
    Ok(())
}
