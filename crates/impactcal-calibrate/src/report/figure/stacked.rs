//! Series stacked over a common abscissa (first-order indices vs time) with a curve above
//! them on its own axis (Q(t)).

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::band;
use super::{
    Area, Drawn, LEFT_AREA, MARGIN, WIDTH, abscissa, cartesian, colour, label_font, line, padded,
};
use crate::Result;
use crate::report::document::Stacked;

/// Heights of the upper (curve) and lower (stack) panels in pixels.
const TOP_HEIGHT: u32 = 250;
const STACK_HEIGHT: u32 = 450;
/// The legend under the panels: height of a row, length of a swatch, the space between a
/// swatch and its name and between entries, and the estimated width of a character of the
/// label font (0.64 of its 19 px: the widest digits of the common sans-serif faces).
const LEGEND_ROW: i32 = 32;
const SWATCH: i32 = 24;
const SWATCH_GAP: i32 = 8;
const ENTRY_GAP: i32 = 28;
const LABEL_CHAR_W: f64 = 0.64 * 19.0;

/// How an entry of the legend is drawn.
#[derive(Clone, Copy)]
enum Swatch {
    /// A line of this colour (the curve of the upper panel).
    Line(RGBColor),
    /// A filled box of this colour (a stacked band).
    Fill(RGBColor),
}

/// The legend's entries placed in rows from the left edge of the plots: each entry's
/// top-left corner `(x, y)` relative to the legend's area, and the number of rows.
fn legend_layout(names: &[&str]) -> (Vec<(i32, i32)>, i32) {
    let start = (LEFT_AREA + MARGIN) as i32;
    let end = (WIDTH - 2 * MARGIN) as i32;
    let (mut x, mut row) = (start, 0);
    let mut at = Vec::with_capacity(names.len());
    for n in names {
        let w = SWATCH + SWATCH_GAP + (n.chars().count() as f64 * LABEL_CHAR_W).ceil() as i32;
        if x > start && x + w > end {
            x = start;
            row += 1;
        }
        at.push((x, row * LEGEND_ROW));
        x += w + ENTRY_GAP;
    }
    (at, if names.is_empty() { 0 } else { row + 1 })
}

/// Draws the legend `entries` into `area` at the places of [`legend_layout`].
fn draw_legend(area: &Area<'_>, entries: &[(&str, Swatch)], name: &str) -> Result<()> {
    let names: Vec<&str> = entries.iter().map(|e| e.0).collect();
    let (at, _) = legend_layout(&names);
    let middle = LEGEND_ROW / 2;
    for ((label, swatch), (x, y)) in entries.iter().zip(at) {
        let y = y + middle;
        match swatch {
            Swatch::Line(c) => area.draw(&PathElement::new(
                vec![(x, y), (x + SWATCH, y)],
                c.stroke_width(2),
            )),
            Swatch::Fill(c) => area.draw(&Rectangle::new(
                [(x, y - 8), (x + SWATCH, y + 8)],
                c.mix(0.85).filled(),
            )),
        }
        .drawn(name)?;
        let style = label_font().pos(Pos::new(HPos::Left, VPos::Center));
        area.draw(&Text::new(
            label.to_string(),
            (x + SWATCH + SWATCH_GAP, y),
            style,
        ))
        .drawn(name)?;
    }
    Ok(())
}

/// Draws `p.top` in black in an upper panel and, below it on the same abscissa, one filled
/// band per stacked series between the running sums before and after it (series `k` spans
/// `sum_{l<k} v_l` to `sum_{l<=k} v_l`), coloured in palette order from the second colour;
/// the stack's axis runs from 0 to at least 1. The legend (the curve and every stacked
/// series) sits in rows under the panels, where it covers no data.
pub(super) fn draw(p: &Stacked, svg: &mut String, name: &str) -> Result<()> {
    let mut entries = vec![(p.top.name.as_str(), Swatch::Line(colour(0)))];
    entries.extend(
        p.stacked
            .iter()
            .enumerate()
            .map(|(k, s)| (s.name.as_str(), Swatch::Fill(colour(k + 1)))),
    );
    let names: Vec<&str> = entries.iter().map(|e| e.0).collect();
    let (_, rows) = legend_layout(&names);
    let legend_h = (rows * LEGEND_ROW) as u32 + MARGIN;
    let root = SVGBackend::with_string(svg, (WIDTH, TOP_HEIGHT + STACK_HEIGHT + legend_h))
        .into_drawing_area();
    root.fill(&WHITE).drawn(name)?;
    let (panels, legend_area) = root.split_vertically(TOP_HEIGHT + STACK_HEIGHT);
    let (upper, lower) = panels.split_vertically(TOP_HEIGHT);
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
    draw_legend(&legend_area, &entries, name)?;
    root.present().drawn(name)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Entries fill a row from the plots' left edge and wrap before the figure's right
    /// margin; no two entries of a row overlap.
    #[test]
    fn legend_rows_wrap_inside_the_figure() {
        let names = [
            "baseline Q",
            "belly_panel.t",
            "keel_beam_stiffener.t",
            "back_panel.t",
            "upper_tail.t",
            "lower_tail.t",
            "side_skins.t",
        ];
        let (at, rows) = legend_layout(&names);
        assert!(rows >= 2, "{rows} rows");
        let width =
            |n: &str| SWATCH + SWATCH_GAP + (n.chars().count() as f64 * LABEL_CHAR_W).ceil() as i32;
        for (k, (n, &(x, y))) in names.iter().zip(&at).enumerate() {
            assert!(x + width(n) <= (WIDTH - 2 * MARGIN) as i32, "{n} runs off");
            if let Some(&(x2, y2)) = at.get(k + 1) {
                if y2 == y {
                    assert!(x2 >= x + width(n) + ENTRY_GAP, "{n} overlaps the next");
                }
            }
        }
        assert_eq!(legend_layout(&[]).1, 0);
    }
}
