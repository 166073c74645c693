//! SVG drawings of the figures of a report, one module per kind of plot, with plotters' SVG
//! backend. Text stays text (`<text>` elements the viewer lays out), so no font library is
//! needed. The same figure always gives the same bytes.

mod envelope;
mod heat_map;
mod legend_place;
mod lines;
mod stacked;
mod structure;

use std::fmt::Display;
use std::ops::Range;

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::document::{Figure, Plot};
use super::validate::check_figure;
use crate::{CalibrateError, Result};

/// Width in pixels of every figure: readable when shown 800 to 1000 px wide.
pub(crate) const WIDTH: u32 = 960;

/// Draws `figure` as a standalone SVG document (an `<svg>` element with a `viewBox`, so it
/// scales to its container). Lines, bands and heat maps are drawn from the numbers the
/// figure holds; see the [`Plot`] variants for what each kind shows.
///
/// # Errors
/// Whatever [`check_figure`](super::validate::check_figure) finds wrong with the figure
/// (typed, naming the figure, the series and the index), or
/// [`CalibrateError::Render`] if the plotting library fails.
pub fn render_svg(figure: &Figure) -> Result<String> {
    check_figure(figure)?;
    let mut svg = String::new();
    let name = figure.name.as_str();
    match &figure.plot {
        Plot::Lines(p) => lines::draw(p, &mut svg, name)?,
        Plot::Envelope(p) => envelope::draw(p, &mut svg, name)?,
        Plot::HeatMap(p) => heat_map::draw(p, &mut svg, name)?,
        Plot::Stacked(p) => stacked::draw(p, &mut svg, name)?,
        Plot::Structure(p) => structure::draw(p, &mut svg, name)?,
    }
    Ok(svg)
}

/// The drawing area of a figure: an SVG document written into a string.
pub(crate) type Area<'a> = DrawingArea<SVGBackend<'a>, plotters::coord::Shift>;

/// Turns a plotters error into [`CalibrateError::Render`] naming the figure.
pub(crate) trait Drawn<T> {
    /// The value, or the error as [`CalibrateError::Render`] for figure `name`.
    fn drawn(self, name: &str) -> Result<T>;
}

impl<T, E: Display> Drawn<T> for std::result::Result<T, E> {
    fn drawn(self, name: &str) -> Result<T> {
        self.map_err(|e| CalibrateError::Render {
            figure: name.to_owned(),
            message: e.to_string(),
        })
    }
}

/// Curve colours (Okabe-Ito: distinguishable with the common colour-vision deficiencies).
/// The first, black, is the test's.
pub(crate) const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 0, 0),
    RGBColor(230, 159, 0),
    RGBColor(0, 114, 178),
    RGBColor(0, 158, 115),
    RGBColor(213, 94, 0),
    RGBColor(86, 180, 233),
    RGBColor(204, 121, 167),
    RGBColor(240, 228, 66),
];

/// The colour of series `i` (the palette repeats after eight).
pub(crate) fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Grey of structure points and neutral marks.
pub(crate) const GREY: RGBColor = RGBColor(150, 150, 150);

/// Fill of weight bars.
pub(crate) const BAR: RGBColor = RGBColor(70, 110, 160);

/// Fill of an envelope's band.
pub(crate) const BAND: RGBColor = RGBColor(120, 150, 200);

/// Fill of an envelope's marked intervals.
pub(crate) const MARK: RGBColor = RGBColor(213, 94, 0);

/// Outline of a heat map's marked cells.
pub(crate) const OUTLINE: RGBColor = RGBColor(220, 20, 60);

/// Colour of structure markers without a value.
pub(crate) const PLAIN: RGBColor = PALETTE[4];

/// Font family of every label (the viewer's sans-serif face).
pub(crate) const FAMILY: &str = "sans-serif";

/// Tick labels.
pub(crate) fn tick_font() -> TextStyle<'static> {
    (FAMILY, 17).into_font().color(&BLACK)
}

/// Axis descriptions and legends.
pub(crate) fn label_font() -> TextStyle<'static> {
    (FAMILY, 19).into_font().color(&BLACK)
}

/// Text centred on a point (cell annotations).
pub(crate) fn centred(style: TextStyle<'static>) -> TextStyle<'static> {
    style.pos(Pos::new(HPos::Center, VPos::Center))
}

/// Pixel sizes shared by panels that must line up: the left label area (ticks and the
/// rotated description), the bottom one, and the margin around each panel.
pub(crate) const LEFT_AREA: u32 = 90;
pub(crate) const BOTTOM_AREA: u32 = 60;
pub(crate) const MARGIN: u32 = 16;

/// A chart of `x` by `y` on `area` with a light grid, tick labels, and the axis
/// descriptions `x_desc` (none for a panel that shares the abscissa of the one below) and
/// `y_desc`.
pub(crate) fn cartesian<'a, 'b>(
    area: &'a Area<'b>,
    x: Range<f64>,
    y: Range<f64>,
    x_desc: Option<&str>,
    y_desc: &str,
    name: &str,
) -> Result<Chart<'a, 'b>> {
    let mut chart = ChartBuilder::on(area)
        .margin(MARGIN)
        .margin_right(2 * MARGIN)
        .x_label_area_size(BOTTOM_AREA)
        .y_label_area_size(LEFT_AREA)
        .build_cartesian_2d(x, y)
        .drawn(name)?;
    let mut mesh = chart.configure_mesh();
    mesh.x_labels(10)
        .y_labels(8)
        .max_light_lines(1)
        .light_line_style(RGBColor(238, 238, 238))
        .bold_line_style(RGBColor(215, 215, 215))
        .label_style(tick_font())
        .axis_desc_style(label_font())
        .y_desc(y_desc);
    if let Some(d) = x_desc {
        mesh.x_desc(d);
    }
    mesh.draw().drawn(name)?;
    Ok(chart)
}

/// A chart over `f64 x f64`.
pub(crate) type Chart<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// Draws `values` over `x` as a line of `colour`, with a legend entry `label`.
pub(crate) fn line(
    chart: &mut Chart<'_, '_>,
    x: &[f64],
    values: &[f64],
    label: &str,
    colour: RGBColor,
    name: &str,
) -> Result<()> {
    let style = colour.stroke_width(2);
    chart
        .draw_series(LineSeries::new(
            x.iter().copied().zip(values.iter().copied()),
            style,
        ))
        .drawn(name)?
        .label(label)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], style));
    Ok(())
}

/// Fills the region between `upper` and `lower` over `x` as one polygon (the upper edge
/// forwards, the lower edge backwards: `2 x.len()` vertices) in `fill`, with a legend entry
/// `label` drawn as a swatch.
pub(crate) fn band(
    chart: &mut Chart<'_, '_>,
    x: &[f64],
    upper: &[f64],
    lower: &[f64],
    label: &str,
    fill: ShapeStyle,
    name: &str,
) -> Result<()> {
    let outline: Vec<(f64, f64)> = x
        .iter()
        .copied()
        .zip(upper.iter().copied())
        .chain(x.iter().copied().zip(lower.iter().copied()).rev())
        .collect();
    chart
        .draw_series(std::iter::once(Polygon::new(outline, fill)))
        .drawn(name)?
        .label(label)
        .legend(move |(x, y)| Rectangle::new([(x, y - 7), (x + 24, y + 7)], fill));
    Ok(())
}

/// Draws the legend of `chart` in `corner` (see `legend_place`), over a translucent white
/// box.
pub(crate) fn legend_in<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    corner: SeriesLabelPosition,
    name: &str,
) -> Result<()> {
    chart
        .configure_series_labels()
        .position(corner)
        .background_style(WHITE.mix(0.85))
        .border_style(RGBColor(160, 160, 160))
        .label_font(label_font())
        .draw()
        .drawn(name)
}

/// The range `[min, max]` of `values` widened by 5 % on each side; a single value gets a
/// unit-wide (or 10 %-wide) range around it so that the axis is never degenerate.
pub(crate) fn padded(values: impl IntoIterator<Item = f64>) -> Range<f64> {
    let (lo, hi) = values
        .into_iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !lo.is_finite() || !hi.is_finite() {
        return 0.0..1.0;
    }
    let span = hi - lo;
    if span > 0.0 {
        (lo - 0.05 * span)..(hi + 0.05 * span)
    } else {
        let half = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
        (lo - half)..(hi + half)
    }
}

/// The abscissa range `[x_0, x_last]`, widened only if it is a single value.
pub(crate) fn abscissa(x: &[f64]) -> Range<f64> {
    match (x.first(), x.last()) {
        (Some(&a), Some(&b)) if b > a => a..b,
        _ => padded(x.iter().copied()),
    }
}

/// A sequential colour for `t` in `[0, 1]` (clamped): light yellow through orange and red to
/// dark purple, perceptually ordered.
pub(crate) fn sequential(t: f64) -> RGBColor {
    const STOPS: [(f64, [f64; 3]); 5] = [
        (0.0, [255.0, 255.0, 217.0]),
        (0.25, [199.0, 233.0, 180.0]),
        (0.5, [65.0, 182.0, 196.0]),
        (0.75, [34.0, 94.0, 168.0]),
        (1.0, [8.0, 29.0, 88.0]),
    ];
    interpolate(&STOPS, t)
}

/// A diverging colour for `t` in `[-1, 1]` (clamped): blue for negative, near-white at zero,
/// red for positive.
pub(crate) fn diverging(t: f64) -> RGBColor {
    const STOPS: [(f64, [f64; 3]); 5] = [
        (-1.0, [33.0, 102.0, 172.0]),
        (-0.5, [146.0, 197.0, 222.0]),
        (0.0, [247.0, 247.0, 247.0]),
        (0.5, [244.0, 165.0, 130.0]),
        (1.0, [178.0, 24.0, 43.0]),
    ];
    interpolate(&STOPS, t)
}

fn interpolate(stops: &[(f64, [f64; 3])], t: f64) -> RGBColor {
    let (first, last) = (stops[0], stops[stops.len() - 1]);
    let t = t.clamp(first.0, last.0);
    let k = stops
        .windows(2)
        .position(|w| t <= w[1].0)
        .unwrap_or(stops.len() - 2);
    let ((t0, c0), (t1, c1)) = (stops[k], stops[k + 1]);
    let f = (t - t0) / (t1 - t0);
    let channel = |i: usize| (c0[i] + f * (c1[i] - c0[i])).round().clamp(0.0, 255.0) as u8;
    RGBColor(channel(0), channel(1), channel(2))
}

/// Whether text on `background` reads better in white than in black.
pub(crate) fn dark(background: RGBColor) -> bool {
    let RGBColor(r, g, b) = background;
    0.299 * f64::from(r) + 0.587 * f64::from(g) + 0.114 * f64::from(b) < 128.0
}

/// Draws a vertical colour bar for values in `range` into `area`, coloured by `scale` of
/// the value's position `t in [0, 1]` along the range, with ticks on its right and, when
/// given, the description `desc` (quantity and unit) along them.
pub(crate) fn colour_bar<F>(
    area: &Area<'_>,
    range: (f64, f64),
    scale: F,
    desc: Option<&str>,
    name: &str,
) -> Result<()>
where
    F: Fn(f64) -> RGBColor,
{
    const STEPS: usize = 64;
    let (lo, hi) = range;
    let mut chart = ChartBuilder::on(area)
        .margin_top(MARGIN)
        .margin_bottom(BOTTOM_AREA + MARGIN)
        .margin_left(8)
        .right_y_label_area_size(if desc.is_some() { 90 } else { 60 })
        .build_cartesian_2d(0.0..1.0, lo..hi)
        .drawn(name)?;
    let mut mesh = chart.configure_mesh();
    mesh.disable_mesh()
        .disable_x_axis()
        .y_labels(6)
        .y_label_style(tick_font())
        .axis_desc_style(label_font());
    if let Some(d) = desc {
        mesh.y_desc(d);
    }
    mesh.draw().drawn(name)?;
    let step = (hi - lo) / STEPS as f64;
    chart
        .draw_series((0..STEPS).map(|k| {
            let a = lo + step * k as f64;
            let c = scale((k as f64 + 0.5) / STEPS as f64);
            Rectangle::new([(0.0, a), (1.0, a + step)], c.filled())
        }))
        .drawn(name)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn padded_widens_and_never_degenerates() {
        let r = padded([1.0, 3.0]);
        assert!((r.start - 0.9).abs() < 1e-12 && (r.end - 3.1).abs() < 1e-12);
        let r = padded([0.0]);
        assert!(r.start < 0.0 && r.end > 0.0);
        let r = padded([5.0, 5.0]);
        assert!((r.start - 4.5).abs() < 1e-12 && (r.end - 5.5).abs() < 1e-12);
        assert_eq!(abscissa(&[0.0, 2.0]), 0.0..2.0);
    }

    #[test]
    fn colour_scales_hit_their_stops_and_clamp() {
        assert_eq!(sequential(0.0), RGBColor(255, 255, 217));
        assert_eq!(sequential(1.0), RGBColor(8, 29, 88));
        assert_eq!(sequential(7.0), sequential(1.0));
        assert_eq!(diverging(0.0), RGBColor(247, 247, 247));
        assert_eq!(diverging(-1.0), RGBColor(33, 102, 172));
        assert_eq!(diverging(-3.0), diverging(-1.0));
        // Half way between two stops is their mean.
        assert_eq!(diverging(0.75), RGBColor(211, 95, 87));
        assert!(dark(sequential(1.0)) && !dark(sequential(0.0)));
    }
}
