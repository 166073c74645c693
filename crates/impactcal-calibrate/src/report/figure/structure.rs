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

/// Width of the colour bar column (ticks and the values' description), present when a
/// marker carries a value.
const BAR_PANEL: u32 = 130;
/// Limits of a projection's plot height in pixels.
const MIN_PLOT: f64 = 160.0;
const MAX_PLOT: f64 = 380.0;
/// Radius of a marker and of a structure point.
const MARKER: i32 = 7;
const POINT: i32 = 2;
/// Label placement: rings of candidate places around a marker, `RING` pixels apart, the
/// first `MARKER + GAP + 1` from its centre; beyond the first ring a leader line joins label and
/// marker. Labels keep `GAP` pixels from each other and from every marker.
const RINGS: i32 = 6;
const RING: i32 = 15;
const GAP: i32 = 4;
/// Tick-font text box: height, and width per character (0.64 of the font size: the widest
/// digit of the common sans-serif faces is 0.56-0.64 em).
const TEXT_H: i32 = 21;
const CHAR_W: f64 = 0.64 * 17.0;

/// Draws the plan view above the side view, both at one scale per view (a unit of length
/// is as long across as up), structure points small and grey, markers large with their
/// labels (the labels are the key: no legend box hides a marker). Markers with values are
/// coloured by `value / L` on a blue-white-red scale, `L` the figure's `limit` or else
/// `max |value|`, with a colour bar from `-L` to `L` described by `value_axis`.
///
/// Labels never overlap each other or a marker: each goes to the first free place on rings
/// around its marker (right, left, above, below, then the diagonals, nearest ring first),
/// with a leader line when it is not on the first ring; a label with no free place within
/// the outer ring is left out of that view (thinned). The plan view is labelled first, and
/// the side view places first the labels the plan view left out, so that a marker left
/// unlabelled in one view is labelled in the other where there is room.
pub(super) fn draw(p: &Structure, svg: &mut String, name: &str) -> Result<()> {
    let largest = p
        .marked
        .iter()
        .filter_map(|m| m.value)
        .fold(None, |acc: Option<f64>, v| {
            Some(acc.unwrap_or(0.0).max(v.abs()))
        });
    let bar = if largest.is_some() { BAR_PANEL } else { 0 };
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
    let scale = largest.map(|l| match p.limit {
        Some(limit) => limit,
        None if l > 0.0 => l,
        None => 1.0,
    });
    let mut labelled = vec![false; p.marked.len()];
    for ((v, label, h, v_range), area) in views.into_iter().zip([plan, side]) {
        let (view, bar_area) = area.split_horizontally(left);
        draw_view(
            p,
            &view,
            (h, v_range),
            (v, label),
            scale,
            &mut labelled,
            name,
        )?;
        if let Some(l) = scale {
            colour_bar(
                &bar_area,
                (-l, l),
                |t| diverging(2.0 * t - 1.0),
                Some(&p.value_axis.label),
                name,
            )?;
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

/// A pixel rectangle `[x0, x1) x [y0, y1)`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Rect {
    x0: i32,
    y0: i32,
    x1: i32,
    y1: i32,
}

impl Rect {
    /// Whether the two rectangles, each grown by `gap` pixels, overlap.
    fn meets(&self, o: &Rect, gap: i32) -> bool {
        self.x0 < o.x1 + gap && o.x0 < self.x1 + gap && self.y0 < o.y1 + gap && o.y0 < self.y1 + gap
    }

    /// Whether it lies inside `outer`.
    fn inside(&self, outer: &Rect) -> bool {
        self.x0 >= outer.x0 && self.x1 <= outer.x1 && self.y0 >= outer.y0 && self.y1 <= outer.y1
    }

    /// The point of the rectangle nearest to `(x, y)`.
    fn nearest(&self, (x, y): (i32, i32)) -> (i32, i32) {
        (x.clamp(self.x0, self.x1), y.clamp(self.y0, self.y1))
    }
}

/// The estimated box of `label` in the tick font.
fn text_width(label: &str) -> i32 {
    (label.chars().count() as f64 * CHAR_W).ceil() as i32
}

/// The candidate boxes of a `w x h` label around a marker at `(cx, cy)`, nearest first:
/// on ring `k` the box's near edge is `MARKER + GAP + 1 + k RING` pixels from the centre, to the
/// right, left, above, below and on the four diagonals. Returns `(ring, box)`.
fn candidates((cx, cy): (i32, i32), w: i32, h: i32) -> impl Iterator<Item = (i32, Rect)> {
    (0..RINGS).flat_map(move |k| {
        let d = MARKER + GAP + 1 + k * RING;
        let right = cx + d;
        let left = cx - d - w;
        let centre = cx - w / 2;
        let above = cy - d - h;
        let below = cy + d;
        let middle = cy - h / 2;
        [
            (right, middle),
            (left, middle),
            (centre, above),
            (centre, below),
            (right, above),
            (right, below),
            (left, above),
            (left, below),
        ]
        .map(move |(x0, y0)| {
            (
                k,
                Rect {
                    x0,
                    y0,
                    x1: x0 + w,
                    y1: y0 + h,
                },
            )
        })
    })
}

/// Places the labels of markers at pixel positions `at` (labels `labels`, in the order
/// `order`) inside `frame`: each label takes its first candidate box that meets no placed
/// label and no marker. Returns, per marker, its box and ring, or `None` where no candidate
/// was free (or the label is empty).
fn place_labels(
    at: &[(i32, i32)],
    labels: &[&str],
    order: &[usize],
    frame: &Rect,
) -> Vec<Option<(i32, Rect)>> {
    let discs: Vec<Rect> = at
        .iter()
        .map(|&(x, y)| Rect {
            x0: x - MARKER,
            y0: y - MARKER,
            x1: x + MARKER,
            y1: y + MARKER,
        })
        .collect();
    let mut placed: Vec<Option<(i32, Rect)>> = vec![None; at.len()];
    let mut taken: Vec<Rect> = Vec::new();
    for &i in order {
        if labels[i].is_empty() {
            continue;
        }
        let w = text_width(labels[i]);
        let free = candidates(at[i], w, TEXT_H).find(|(_, b)| {
            b.inside(frame)
                && !taken.iter().any(|t| t.meets(b, GAP))
                && !discs.iter().any(|d| d.meets(b, GAP))
        });
        if let Some((k, b)) = free {
            taken.push(b);
            placed[i] = Some((k, b));
        }
    }
    placed
}

fn draw_view(
    p: &Structure,
    area: &Area<'_>,
    (h, v_range): (Range<f64>, Range<f64>),
    (v, v_label): (usize, &str),
    scale: Option<f64>,
    labelled: &mut [bool],
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
        }))
        .drawn(name)?;

    // Labels in pixels of this view's area.
    let (bx, by) = area.get_base_pixel();
    let (xs, ys) = chart.plotting_area().get_pixel_range();
    let frame = Rect {
        x0: xs.start - bx,
        y0: ys.start - by,
        x1: xs.end - bx,
        y1: ys.end - by,
    };
    let at: Vec<(i32, i32)> = p
        .marked
        .iter()
        .map(|m| {
            let (x, y) = chart.backend_coord(&(m.at[0], m.at[v]));
            (x - bx, y - by)
        })
        .collect();
    let labels: Vec<&str> = p.marked.iter().map(|m| m.label.as_str()).collect();
    let mut order: Vec<usize> = (0..at.len()).collect();
    order.sort_by_key(|&i| (labelled[i], at[i].0, at[i].1));
    let placed = place_labels(&at, &labels, &order, &frame);
    for (i, slot) in placed.iter().enumerate() {
        let Some((ring, b)) = slot else { continue };
        if *ring > 0 {
            let (tx, ty) = b.nearest(at[i]);
            area.draw(&PathElement::new(
                vec![at[i], (tx, ty)],
                GREY.stroke_width(1),
            ))
            .drawn(name)?;
        }
        area.draw(&Text::new(labels[i].to_string(), (b.x0, b.y0), tick_font()))
            .drawn(name)?;
        labelled[i] = true;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Forty markers crowded on a line 3 px apart, and pairs that coincide (mirror images
    /// seen from the side): no two placed labels meet, none covers a marker, every box
    /// stays in the frame, and the labels that found no place are the thinned ones.
    #[test]
    fn placed_labels_never_meet_or_cover_a_marker() {
        let frame = Rect {
            x0: 0,
            y0: 0,
            x1: 800,
            y1: 300,
        };
        let mut at: Vec<(i32, i32)> = (0..40).map(|i| (100 + 3 * i, 150)).collect();
        at.extend([(600, 100), (600, 100), (600, 100)]);
        let names: Vec<String> = (0..at.len()).map(|i| format!("{}.z", 1000 + i)).collect();
        let labels: Vec<&str> = names.iter().map(String::as_str).collect();
        let order: Vec<usize> = (0..at.len()).collect();
        let placed = place_labels(&at, &labels, &order, &frame);
        let boxes: Vec<Rect> = placed.iter().flatten().map(|(_, b)| *b).collect();
        assert!(boxes.len() >= 20, "only {} of 43 placed", boxes.len());
        for (a, x) in boxes.iter().enumerate() {
            assert!(x.inside(&frame));
            for y in &boxes[a + 1..] {
                assert!(!x.meets(y, GAP - 1), "{x:?} meets {y:?}");
            }
            for &(cx, cy) in &at {
                let disc = Rect {
                    x0: cx - MARKER,
                    y0: cy - MARKER,
                    x1: cx + MARKER,
                    y1: cy + MARKER,
                };
                assert!(
                    !x.meets(&disc, GAP - 1),
                    "{x:?} covers the marker at {cx}, {cy}"
                );
            }
        }
        // The three coincident markers all find a place (rings around a free spot).
        assert!(placed[40..].iter().all(Option::is_some));
        // A lone marker's label sits on the first ring, to the right.
        let lone = place_labels(&[(50, 50)], &["1.x"], &[0], &frame);
        let (ring, b) = lone[0].expect("a free place");
        assert_eq!((ring, b.x0), (0, 50 + MARKER + GAP + 1));
    }
}
