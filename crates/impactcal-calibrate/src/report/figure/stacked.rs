//! Series stacked over a common abscissa (first-order indices vs time) with a curve above
//! them on its own axis (Q(t)).

use plotters::prelude::*;

use super::band;
use super::{Drawn, WIDTH, abscissa, cartesian, colour, legend, line, padded};
use crate::Result;
use crate::report::document::Stacked;

/// Heights of the upper (curve) and lower (stack) panels in pixels.
const TOP_HEIGHT: u32 = 250;
const STACK_HEIGHT: u32 = 450;

/// Draws `p.top` in black in an upper panel and, below it on the same abscissa, one filled
/// band per stacked series between the running sums before and after it (series `k` spans
/// `sum_{l<k} v_l` to `sum_{l<=k} v_l`), coloured in palette order from the second colour;
/// the stack's axis runs from 0 to at least 1.
pub(super) fn draw(p: &Stacked, svg: &mut String, name: &str) -> Result<()> {
    let root = SVGBackend::with_string(svg, (WIDTH, TOP_HEIGHT + STACK_HEIGHT)).into_drawing_area();
    root.fill(&WHITE).drawn(name)?;
    let (upper, lower) = root.split_vertically(TOP_HEIGHT);
    let x = abscissa(&p.x);

    let mut chart = cartesian(
        &upper,
        x.clone(),
        padded(p.top.values.iter().copied()),
        None,
        &p.top_axis.label,
        name,
    )?;
    line(
        &mut chart,
        &p.x,
        &p.top.values,
        &p.top.name,
        colour(0),
        name,
    )?;
    legend(&mut chart, name)?;

    let n = p.x.len();
    let mut below = vec![0.0; n];
    let mut sums = Vec::with_capacity(p.stacked.len());
    for s in &p.stacked {
        let above: Vec<f64> = below.iter().zip(&s.values).map(|(b, v)| b + v).collect();
        sums.push((below, above.clone()));
        below = above;
    }
    let peak = below.iter().copied().fold(1.0, f64::max);
    let mut chart = cartesian(
        &lower,
        x,
        0.0..1.05 * peak,
        Some(&p.x_axis.label),
        &p.y_axis.label,
        name,
    )?;
    for (k, (s, (from, to))) in p.stacked.iter().zip(&sums).enumerate() {
        let fill = colour(k + 1).mix(0.85).filled();
        band(&mut chart, &p.x, to, from, &s.name, fill, name)?;
    }
    legend(&mut chart, name)?;
    root.present().drawn(name)
}
