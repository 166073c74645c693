//! A band (an ensemble's min/max) with curves over it and shaded intervals (where the test
//! leaves the band).

use plotters::prelude::*;

use super::legend_place::place;
use super::{BAND, MARK, band};
use super::{Drawn, WIDTH, abscissa, cartesian, colour, legend_in, line, padded};
use crate::Result;
use crate::report::document::Envelope;

/// Height of an envelope figure in pixels.
const HEIGHT: u32 = 540;

/// Draws the marked intervals as translucent full-height strips, then the band as one
/// filled polygon (upper edge forwards, lower edge backwards), then the curves in palette
/// order; one legend entry each for the band, the intervals (if any) and every curve, in a
/// corner where the legend covers no point (the ordinate range raised when none is free).
pub(super) fn draw(p: &Envelope, svg: &mut String, name: &str) -> Result<()> {
    let root = SVGBackend::with_string(svg, (WIDTH, HEIGHT)).into_drawing_area();
    root.fill(&WHITE).drawn(name)?;
    let all = p
        .lower
        .iter()
        .chain(&p.upper)
        .chain(p.series.iter().flat_map(|s| &s.values))
        .copied();
    let y = padded(all);
    let points: Vec<(f64, f64)> = [&p.lower, &p.upper]
        .into_iter()
        .chain(p.series.iter().map(|s| &s.values))
        .flat_map(|v| p.x.iter().copied().zip(v.iter().copied()))
        .collect();
    let mut labels = vec![p.band_name.as_str()];
    if !p.marked.is_empty() {
        labels.push("outside the band");
    }
    labels.extend(p.series.iter().map(|s| s.name.as_str()));
    let placed = place(&labels, HEIGHT, abscissa(&p.x), y, &points);
    let y = placed.y;
    let mut chart = cartesian(
        &root,
        abscissa(&p.x),
        y.clone(),
        Some(&p.x_axis.label),
        &p.y_axis.label,
        name,
    )?;
    if !p.marked.is_empty() {
        let strip = MARK.mix(0.15).filled();
        chart
            .draw_series(
                p.marked
                    .iter()
                    .map(|&(a, b)| Rectangle::new([(a, y.start), (b, y.end)], strip)),
            )
            .drawn(name)?
            .label("outside the band")
            .legend(move |(x, y)| Rectangle::new([(x, y - 7), (x + 24, y + 7)], strip));
    }
    let fill = BAND.mix(0.45).filled();
    band(
        &mut chart,
        &p.x,
        &p.upper,
        &p.lower,
        &p.band_name,
        fill,
        name,
    )?;
    for (i, s) in p.series.iter().enumerate() {
        line(&mut chart, &p.x, &s.values, &s.name, colour(i), name)?;
    }
    legend_in(&mut chart, placed.corner, name)?;
    root.present().drawn(name)
}
