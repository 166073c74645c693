//! Curves over a common abscissa.

use plotters::prelude::*;

use super::legend_place::place;
use super::{Drawn, WIDTH, abscissa, cartesian, colour, legend_in, line, padded};
use crate::Result;
use crate::report::document::Lines;

/// Height of a lines figure in pixels.
const HEIGHT: u32 = 540;

/// Draws every series of `p` over its abscissa in palette order (the first in black), with
/// a legend in a corner where it covers no point (the ordinate range raised when every
/// corner holds some); the ordinate range covers every value with a 5 % margin.
pub(super) fn draw(p: &Lines, svg: &mut String, name: &str) -> Result<()> {
    let root = SVGBackend::with_string(svg, (WIDTH, HEIGHT)).into_drawing_area();
    root.fill(&WHITE).drawn(name)?;
    let y = padded(p.series.iter().flat_map(|s| s.values.iter().copied()));
    let points: Vec<(f64, f64)> = p
        .series
        .iter()
        .flat_map(|s| p.x.iter().copied().zip(s.values.iter().copied()))
        .collect();
    let labels: Vec<&str> = p.series.iter().map(|s| s.name.as_str()).collect();
    let placed = place(&labels, HEIGHT, abscissa(&p.x), y, &points);
    let mut chart = cartesian(
        &root,
        abscissa(&p.x),
        placed.y,
        Some(&p.x_axis.label),
        &p.y_axis.label,
        name,
    )?;
    for (i, s) in p.series.iter().enumerate() {
        line(&mut chart, &p.x, &s.values, &s.name, colour(i), name)?;
    }
    legend_in(&mut chart, placed.corner, name)?;
    root.present().drawn(name)
}
