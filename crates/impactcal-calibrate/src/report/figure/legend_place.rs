//! Where a legend goes so that it covers no data: the first corner of the plot whose
//! legend box holds no plotted point, else the upper right with the ordinate range raised
//! until the box sits above every point.

use std::ops::Range;

use plotters::prelude::SeriesLabelPosition;

use super::{BOTTOM_AREA, LEFT_AREA, MARGIN, WIDTH};

/// A legend's place: its corner and the ordinate range that keeps it clear of the data.
pub(crate) struct Placed {
    pub corner: SeriesLabelPosition,
    pub y: Range<f64>,
}

/// The legend box of `labels` in pixels, `(width, height)`: the key, the longest label at
/// about 0.6 em per character of the 19 px face, padding; one 25 px row per label.
fn legend_box(labels: &[&str]) -> (f64, f64) {
    let chars = labels.iter().map(|l| l.chars().count()).max().unwrap_or(0);
    (
        24.0 + 30.0 + 0.6 * 19.0 * chars as f64,
        12.0 + 25.0 * labels.len() as f64,
    )
}

/// The place of the legend of `labels` on a chart `height` px tall over `x` by `y`,
/// where `points` are every plotted `(x, y)` (curves and band edges).
pub(crate) fn place(
    labels: &[&str],
    height: u32,
    x: Range<f64>,
    y: Range<f64>,
    points: &[(f64, f64)],
) -> Placed {
    let plot_w = f64::from(WIDTH - LEFT_AREA - 2 * MARGIN);
    let plot_h = f64::from(height - BOTTOM_AREA - 2 * MARGIN);
    let (w, h) = legend_box(labels);
    // Box as fractions of the plot, with the 10 px margin plotters leaves at the edge.
    let (fw, fh) = ((w + 10.0) / plot_w, (h + 10.0) / plot_h);
    let (xs, ys) = (x.end - x.start, y.end - y.start);
    let covers = |right: bool, upper: bool| {
        let (x0, x1) = if right {
            (x.end - fw * xs, x.end)
        } else {
            (x.start, x.start + fw * xs)
        };
        let (y0, y1) = if upper {
            (y.end - fh * ys, y.end)
        } else {
            (y.start, y.start + fh * ys)
        };
        points
            .iter()
            .any(|&(px, py)| px >= x0 && px <= x1 && py >= y0 && py <= y1)
    };
    for (corner, right, upper) in [
        (SeriesLabelPosition::UpperRight, true, true),
        (SeriesLabelPosition::UpperLeft, false, true),
        (SeriesLabelPosition::LowerRight, true, false),
        (SeriesLabelPosition::LowerLeft, false, false),
    ] {
        if !covers(right, upper) {
            return Placed { corner, y };
        }
    }
    // Raise the top so that the box's share of the new range lies above the old top.
    let fh = fh.min(0.6);
    Placed {
        corner: SeriesLabelPosition::UpperRight,
        y: y.start..y.start + ys / (1.0 - fh),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn corner_name(c: &SeriesLabelPosition) -> &'static str {
        match c {
            SeriesLabelPosition::UpperRight => "upper right",
            SeriesLabelPosition::UpperLeft => "upper left",
            SeriesLabelPosition::LowerRight => "lower right",
            SeriesLabelPosition::LowerLeft => "lower left",
            _ => "other",
        }
    }

    /// A rising line leaves the upper left free; a line through every corner raises the top
    /// until the box is above every point.
    #[test]
    fn the_legend_goes_where_no_point_is() {
        let rising: Vec<(f64, f64)> = (0..=100).map(|k| (k as f64, k as f64)).collect();
        let p = place(&["test", "model"], 540, 0.0..100.0, 0.0..100.0, &rising);
        assert_eq!(corner_name(&p.corner), "upper left");
        assert_eq!(p.y, 0.0..100.0);
        let mut full = rising.clone();
        full.extend((0..=100).map(|k| (k as f64, 100.0 - k as f64)));
        full.extend((0..=100).map(|k| (k as f64, 100.0)));
        full.extend((0..=100).map(|k| (k as f64, 0.0)));
        let p = place(&["test", "model"], 540, 0.0..100.0, 0.0..100.0, &full);
        assert_eq!(corner_name(&p.corner), "upper right");
        let (_, h) = legend_box(&["test", "model"]);
        let plot_h = f64::from(540 - BOTTOM_AREA - 2 * MARGIN);
        // The box's part of the raised range starts above 100.
        let bottom = p.y.end - (h + 10.0) / plot_h * (p.y.end - p.y.start);
        assert!(bottom >= 100.0 - 1e-9, "{:?} {bottom}", p.y);
    }
}
