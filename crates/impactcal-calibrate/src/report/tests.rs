//! Tests of the renderers: every plot kind parses as SVG and draws what its data says (counts
//! of series paths, bands, cells, bars, markers), text is escaped, output is deterministic,
//! and every fault of a document is a typed error naming where it is.

use std::path::Path;

use impactcal_core::{CoreError, ErrorKind};
use proptest::prelude::*;

use super::figure::{BAND, BAR, MARK, OUTLINE, PALETTE, PLAIN, diverging, sequential};
use super::*;
use crate::CalibrateError;

// ----- building documents -----

fn time(n: usize) -> Vec<f64> {
    (0..n).map(|k| k as f64 * 1e-3).collect()
}

fn wave(n: usize, a: f64, f: f64) -> Vec<f64> {
    (0..n)
        .map(|k| a * (f * k as f64 * 1e-3).sin() + 2.0 * a)
        .collect()
}

fn lines(k: usize) -> Lines {
    Lines {
        x: time(100),
        x_axis: Axis::new("time (s)"),
        y_axis: Axis::new("Q (in/s)"),
        series: (0..k)
            .map(|i| Series::new(format!("curve {i}"), wave(100, 1.0 + i as f64, 40.0)))
            .collect(),
    }
}

fn envelope(marked: Vec<(f64, f64)>) -> Envelope {
    let mid = wave(100, 2.0, 50.0);
    Envelope {
        x: time(100),
        x_axis: Axis::new("time (s)"),
        y_axis: Axis::new("Q (in/s)"),
        band_name: "ensemble min/max (20 runs)".into(),
        lower: mid.iter().map(|v| v - 1.0).collect(),
        upper: mid.iter().map(|v| v + 1.0).collect(),
        series: vec![Series::new("test", wave(100, 2.5, 50.0))],
        marked,
    }
}

/// A `rows x cols` matrix of distinct values in (0, 1).
fn heat_map(rows: usize, cols: usize) -> HeatMap {
    HeatMap {
        values: (0..rows)
            .map(|i| {
                (0..cols)
                    .map(|j| 0.05 + 0.9 * (i * cols + j) as f64 / (rows * cols) as f64 + 0.0037)
                    .collect()
            })
            .collect(),
        range: (0.0, 1.0),
        row_axis: Axis::new("test shape"),
        column_axis: Axis::new("model shape"),
        row_weights: (0..rows).map(|i| 50.0 / (i + 1) as f64).collect(),
        column_weights: (0..cols).map(|j| 40.0 / (j + 1) as f64).collect(),
        row_weights_axis: Axis::new("test contribution (%)"),
        column_weights_axis: Axis::new("model contribution (%)"),
        marked: (0..rows.min(cols)).map(|i| (i, i)).collect(),
        annotate: true,
    }
}

fn stacked(k: usize) -> Stacked {
    Stacked {
        x: time(80),
        x_axis: Axis::new("time (s)"),
        y_axis: Axis::new("first-order index (-)"),
        stacked: (0..k)
            .map(|i| Series::new(format!("p{i}"), vec![0.8 / k as f64; 80]))
            .collect(),
        top_axis: Axis::new("Q (in/s)"),
        top: Series::new("baseline Q(t)", wave(80, 3.0, 30.0)),
    }
}

fn structure(points: usize, markers: usize, values: bool) -> Structure {
    Structure {
        points: (0..points)
            .map(|i| {
                let a = i as f64 * 0.7;
                [i as f64 * 2.0, 20.0 * a.cos(), 10.0 + 10.0 * a.sin()]
            })
            .collect(),
        unit: "in".into(),
        marked: (0..markers)
            .map(|m| Marker {
                label: format!("{}.z", 100 + m),
                at: [m as f64 * 10.0, 5.0, 3.0 * m as f64],
                value: values.then_some(m as f64 - 1.0),
            })
            .collect(),
        value_axis: Axis::new("residual (noise units)"),
        limit: None,
    }
}

fn fig(name: &str, plot: Plot) -> Figure {
    Figure {
        name: name.to_owned(),
        caption: format!("Caption of {name}"),
        plot,
    }
}

/// A report with one figure of every kind, a table and text that needs escaping.
fn sample() -> Report {
    Report {
        title: "Study <A> & \"B\"".into(),
        lead: vec!["Verdict: cannot-explain; 3 < 4 & 5 > 2.".into()],
        sections: vec![
            Section {
                heading: "M1 & M2".into(),
                blocks: vec![
                    Block::Paragraph("Plain *text* with _marks_ and a | pipe.".into()),
                    Block::Figure(fig(
                        "fig-envelope",
                        Plot::Envelope(envelope(vec![(0.01, 0.02)])),
                    )),
                    Block::Figure(fig("fig-m2", Plot::HeatMap(heat_map(3, 4)))),
                ],
            },
            Section {
                heading: "Sensitivity".into(),
                blocks: vec![
                    Block::Figure(fig("fig-sobol", Plot::Stacked(stacked(3)))),
                    Block::Table(Table {
                        caption: "Errors | before and after".into(),
                        header: vec!["sensor".into(), "rel L2".into()],
                        rows: vec![
                            vec!["a|b".into(), "0.12".into()],
                            vec!["<c> & d".into(), "line\nbreak".into()],
                        ],
                    }),
                    Block::Figure(fig("fig-lines", Plot::Lines(lines(3)))),
                    Block::Figure(fig("fig-sensors", Plot::Structure(structure(40, 4, true)))),
                ],
            },
        ],
    }
}

// ----- reading SVG -----

/// Parses `svg` as XML and returns the document's text for element queries.
fn parse(svg: &str) -> roxmltree::Document<'_> {
    match roxmltree::Document::parse(svg) {
        Ok(doc) => doc,
        Err(e) => panic!("not well-formed XML: {e}"),
    }
}

fn hex(c: plotters::style::RGBColor) -> String {
    format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2)
}

/// Elements named `tag` whose attributes include every `(name, value)` of `attrs`.
fn count(doc: &roxmltree::Document<'_>, tag: &str, attrs: &[(&str, &str)]) -> usize {
    doc.descendants()
        .filter(|n| n.has_tag_name(tag))
        .filter(|n| attrs.iter().all(|(a, v)| n.attribute(*a) == Some(*v)))
        .count()
}

/// Rects filled with `fill` that lie left of pixel column `right` (cells of a heat map,
/// not steps of its colour bar).
fn cells(doc: &roxmltree::Document<'_>, fill: &str, right: f64) -> usize {
    doc.descendants()
        .filter(|n| n.has_tag_name("rect") && n.attribute("fill") == Some(fill))
        .filter(|n| {
            let get = |a| n.attribute(a).and_then(|v| v.parse::<f64>().ok());
            matches!((get("x"), get("width")), (Some(x), Some(w)) if x + w <= right)
        })
        .count()
}

/// Text elements whose content, trimmed, is `text`.
fn texts(doc: &roxmltree::Document<'_>, text: &str) -> usize {
    doc.descendants()
        .filter(|n| n.has_tag_name("text") && n.text().map(str::trim) == Some(text))
        .count()
}

/// The heat map's colour bar occupies the last 100 pixels of the 960-pixel width.
const COLOUR_BAR_LEFT: f64 = 860.0;

fn svg_of(plot: Plot) -> String {
    match render_svg(&fig("fig-test", plot)) {
        Ok(svg) => svg,
        Err(e) => panic!("render failed: {e}"),
    }
}

// ----- each plot kind -----

#[test]
fn lines_draw_one_path_and_one_legend_entry_per_series_with_axis_labels() {
    for k in [1, 3, 5] {
        let svg = svg_of(Plot::Lines(lines(k)));
        let doc = parse(&svg);
        for (i, colour) in PALETTE.iter().take(k).enumerate() {
            let stroke = hex(*colour);
            let n = count(
                &doc,
                "polyline",
                &[("stroke", &stroke), ("stroke-width", "2")],
            );
            assert_eq!(n, 2, "series {i}: a curve and its legend sample");
            assert_eq!(texts(&doc, &format!("curve {i}")), 1);
        }
        let wide = count(&doc, "polyline", &[("stroke-width", "2")]);
        assert_eq!(wide, 2 * k);
        assert_eq!(texts(&doc, "time (s)"), 1);
        assert_eq!(texts(&doc, "Q (in/s)"), 1);
        let root = doc.root_element();
        assert_eq!(root.attribute("viewBox"), Some("0 0 960 540"));
    }
}

#[test]
fn envelope_draws_the_band_each_marked_interval_and_the_curves() {
    for marked in [
        vec![],
        vec![(0.01, 0.02)],
        vec![(0.0, 0.01), (0.03, 0.05), (0.07, 0.099)],
    ] {
        let m = marked.len();
        let svg = svg_of(Plot::Envelope(envelope(marked)));
        let doc = parse(&svg);
        let band = hex(BAND);
        assert_eq!(count(&doc, "polygon", &[("fill", &band)]), 1);
        let strip = hex(MARK);
        let legend = usize::from(m > 0);
        assert_eq!(count(&doc, "rect", &[("fill", &strip)]), m + legend);
        let black = hex(PALETTE[0]);
        assert_eq!(
            count(
                &doc,
                "polyline",
                &[("stroke", &black), ("stroke-width", "2")]
            ),
            2
        );
        assert_eq!(texts(&doc, "ensemble min/max (20 runs)"), 1);
        assert_eq!(texts(&doc, "outside the band"), legend);
    }
}

#[test]
fn envelope_band_follows_its_edges() {
    // The band polygon holds the upper edge forwards then the lower edge backwards: 2 n
    // vertices, and its topmost vertex (smallest pixel y) belongs to the upper edge's maximum.
    let p = envelope(vec![]);
    let n = p.x.len();
    let svg = svg_of(Plot::Envelope(p.clone()));
    let doc = parse(&svg);
    let band = hex(BAND);
    let poly = doc
        .descendants()
        .find(|e| e.has_tag_name("polygon") && e.attribute("fill") == Some(band.as_str()));
    let Some(points) = poly.and_then(|e| e.attribute("points")) else {
        panic!("no band polygon");
    };
    let vertices: Vec<(f64, f64)> = points
        .split_whitespace()
        .map(|pair| {
            let mut it = pair
                .split(',')
                .map(|v| v.parse::<f64>().unwrap_or(f64::NAN));
            (it.next().unwrap_or(f64::NAN), it.next().unwrap_or(f64::NAN))
        })
        .collect();
    assert_eq!(vertices.len(), 2 * n);
    let top = (0..2 * n)
        .min_by(|&a, &b| vertices[a].1.total_cmp(&vertices[b].1))
        .unwrap_or(usize::MAX);
    let upper_max = (0..n)
        .max_by(|&a, &b| p.upper[a].total_cmp(&p.upper[b]))
        .unwrap_or(usize::MAX);
    // Pixel rounding can tie neighbours: compare heights, not indices.
    assert!(upper_max < n);
    assert!((vertices[top].1 - vertices[upper_max].1).abs() < 0.5);
}

#[test]
fn heat_map_draws_every_cell_bar_outline_and_annotation() {
    for (rows, cols) in [(1, 1), (3, 4), (6, 6), (12, 9)] {
        let p = heat_map(rows, cols);
        let svg = svg_of(Plot::HeatMap(p.clone()));
        let doc = parse(&svg);
        for row in &p.values {
            for v in row {
                let fill = hex(sequential(*v));
                assert_eq!(cells(&doc, &fill, COLOUR_BAR_LEFT), 1, "cell {v}");
                let label = format!("{v:.2}");
                let same = p
                    .values
                    .iter()
                    .flatten()
                    .filter(|w| format!("{w:.2}") == label);
                assert_eq!(texts(&doc, &label), same.count(), "annotation {v}");
            }
        }
        let bar = hex(BAR);
        assert_eq!(count(&doc, "rect", &[("fill", &bar)]), rows + cols);
        let outline = hex(OUTLINE);
        // The outlined pairing plus the key's sample.
        assert_eq!(
            count(&doc, "rect", &[("stroke", &outline), ("fill", "none")]),
            rows.min(cols) + 1
        );
        assert_eq!(texts(&doc, "test shape"), 1);
        assert_eq!(texts(&doc, "model shape"), 1);
        // Tick labels name every row and column (1-based).
        assert!(texts(&doc, &rows.max(cols).to_string()) >= 1);
    }
}

#[test]
fn heat_map_without_weights_marks_or_annotation_draws_only_cells() {
    let mut p = heat_map(2, 3);
    p.row_weights.clear();
    p.column_weights.clear();
    p.marked.clear();
    p.annotate = false;
    let svg = svg_of(Plot::HeatMap(p.clone()));
    let doc = parse(&svg);
    assert_eq!(count(&doc, "rect", &[("fill", &hex(BAR))]), 0);
    assert_eq!(
        count(&doc, "rect", &[("fill", "none"), ("stroke-width", "4")]),
        0
    );
    for v in p.values.iter().flatten() {
        assert_eq!(cells(&doc, &hex(sequential(*v)), COLOUR_BAR_LEFT), 1);
        assert_eq!(texts(&doc, &format!("{v:.2}")), 0);
    }
}

#[test]
fn stacked_draws_one_band_per_series_under_the_curve() {
    for k in [1, 3, 6] {
        let svg = svg_of(Plot::Stacked(stacked(k)));
        let doc = parse(&svg);
        assert_eq!(count(&doc, "polygon", &[]), k);
        for i in 0..k {
            let fill = hex(PALETTE[(i + 1) % PALETTE.len()]);
            assert_eq!(count(&doc, "polygon", &[("fill", &fill)]), 1, "band {i}");
            assert_eq!(texts(&doc, &format!("p{i}")), 1);
        }
        let black = hex(PALETTE[0]);
        assert_eq!(
            count(
                &doc,
                "polyline",
                &[("stroke", &black), ("stroke-width", "2")]
            ),
            2
        );
        assert_eq!(texts(&doc, "Q (in/s)"), 1);
        assert_eq!(texts(&doc, "first-order index (-)"), 1);
        assert_eq!(
            texts(&doc, "time (s)"),
            1,
            "the shared abscissa is described once"
        );
    }
}

#[test]
fn stacked_bands_are_running_sums() {
    // Three constant series 0.2, 0.3, 0.5: the top band's upper edge lies at 1.0, the
    // first band's at 0.2; pixel heights are proportional.
    let mut p = stacked(3);
    for (s, v) in p.stacked.iter_mut().zip([0.2, 0.3, 0.5]) {
        s.values = vec![v; p.x.len()];
    }
    let svg = svg_of(Plot::Stacked(p));
    let doc = parse(&svg);
    let tops: Vec<(f64, f64)> = doc
        .descendants()
        .filter(|e| e.has_tag_name("polygon"))
        .map(|e| {
            let ys: Vec<f64> = e
                .attribute("points")
                .unwrap_or("")
                .split_whitespace()
                .filter_map(|p| p.split(',').nth(1)?.parse().ok())
                .collect();
            (
                ys.iter().copied().fold(f64::INFINITY, f64::min),
                ys.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            )
        })
        .collect();
    assert_eq!(tops.len(), 3);
    let zero = tops[0].1;
    let height = |k: usize| zero - tops[k].0;
    // Heights 0.2 : 0.5 : 1.0 within a pixel of rounding.
    assert!((height(1) / height(2) - 0.5).abs() < 0.01, "{tops:?}");
    assert!((height(0) / height(2) - 0.2).abs() < 0.01, "{tops:?}");
    // Each band starts where the one below ends.
    assert!((tops[1].1 - tops[0].0).abs() <= 1.0 && (tops[2].1 - tops[1].0).abs() <= 1.0);
}

#[test]
fn structure_draws_points_and_labelled_markers_in_two_views() {
    for (points, markers, values) in [(50, 3, false), (10, 5, true), (0, 2, false)] {
        let p = structure(points, markers, values);
        let svg = svg_of(Plot::Structure(p.clone()));
        let doc = parse(&svg);
        assert_eq!(count(&doc, "circle", &[("r", "2")]), 2 * points);
        // A filled disc and its outline per marker, in each of the two views.
        assert_eq!(count(&doc, "circle", &[("r", "7")]), 4 * markers);
        for m in &p.marked {
            assert_eq!(texts(&doc, &m.label), 2);
        }
        assert_eq!(texts(&doc, "x (in)"), 2);
        assert_eq!(texts(&doc, "y (in)"), 1);
        assert_eq!(texts(&doc, "z (in)"), 1);
        let plain = hex(PLAIN);
        let plain_discs = count(&doc, "circle", &[("r", "7"), ("fill", &plain)]);
        assert_eq!(plain_discs, if values { 0 } else { 2 * markers });
    }
}

#[test]
fn structure_values_take_the_diverging_scale() {
    // Values -1, 0, 1, 2, 3: the largest magnitude (3) is full red, -1 is a third of the
    // way to blue, 0 is the neutral colour.
    let p = structure(5, 5, true);
    let svg = svg_of(Plot::Structure(p));
    let doc = parse(&svg);
    for (v, t) in [(3.0, 1.0), (0.0, 0.0), (-1.0, -1.0 / 3.0)] {
        let fill = hex(diverging(t));
        assert_eq!(
            count(&doc, "circle", &[("r", "7"), ("fill", &fill)]),
            2,
            "marker with value {v}"
        );
    }
}

#[test]
fn structure_keeps_one_scale_across_and_up() {
    // A long thin structure: in the plan view, 100 in along x and 10 in along y must span
    // pixel lengths in the ratio 10 : 1.
    let p = Structure {
        points: vec![[0.0, 0.0, 0.0], [100.0, 10.0, 5.0]],
        unit: "in".into(),
        marked: vec![],
        value_axis: Axis::new("-"),
        limit: None,
    };
    let svg = svg_of(Plot::Structure(p));
    let doc = parse(&svg);
    let centres: Vec<(f64, f64)> = doc
        .descendants()
        .filter(|e| e.has_tag_name("circle"))
        .map(|e| {
            let get = |a| {
                e.attribute(a)
                    .and_then(|v| v.parse().ok())
                    .unwrap_or(f64::NAN)
            };
            (get("cx"), get("cy"))
        })
        .collect();
    assert_eq!(centres.len(), 4);
    let (dx, dy) = (
        (centres[1].0 - centres[0].0).abs(),
        (centres[1].1 - centres[0].1).abs(),
    );
    assert!((dx / dy - 10.0).abs() < 0.3, "dx {dx}, dy {dy}");
}

#[test]
fn svg_text_is_escaped_and_stays_text() {
    let mut p = lines(1);
    p.series[0].name = "a <b> & \"c\"".into();
    p.y_axis.label = "F < 5 & G (lbf)".into();
    let svg = svg_of(Plot::Lines(p));
    let doc = parse(&svg);
    assert_eq!(texts(&doc, "a <b> & \"c\""), 1);
    assert_eq!(texts(&doc, "F < 5 & G (lbf)"), 1);
    // No font is embedded or fetched: text is left to the viewer.
    assert!(!svg.contains("@font-face") && !svg.contains("<path"));
}

#[test]
fn degenerate_but_valid_data_renders() {
    // One sample, constant curves, a single cell, a structure of one marker.
    let one = Lines {
        x: vec![0.5],
        x_axis: Axis::new("t (s)"),
        y_axis: Axis::new("v (in/s)"),
        series: vec![Series::new("only", vec![3.0])],
    };
    parse(&svg_of(Plot::Lines(one)));
    let mut flat = lines(2);
    for s in &mut flat.series {
        s.values = vec![0.0; 100];
    }
    parse(&svg_of(Plot::Lines(flat)));
    parse(&svg_of(Plot::HeatMap(heat_map(1, 1))));
    parse(&svg_of(Plot::Structure(structure(0, 1, true))));
    let mut zero = stacked(2);
    for s in &mut zero.stacked {
        s.values = vec![0.0; 80];
    }
    parse(&svg_of(Plot::Stacked(zero)));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    /// Any finite data of any magnitude renders to well-formed SVG with every series drawn.
    #[test]
    fn any_finite_lines_render(
        n in 1usize..60,
        k in 1usize..5,
        scale in -12i32..12,
        seed in 0u64..1000,
    ) {
        let x: Vec<f64> = (0..n).map(|i| i as f64 * 10f64.powi(scale)).collect();
        let series = (0..k)
            .map(|j| {
                let values = (0..n)
                    .map(|i| ((i as u64 * 31 + j as u64 * 7 + seed) % 97) as f64 * 10f64.powi(-scale))
                    .collect();
                Series { name: format!("s{j}"), values }
            })
            .collect();
        let svg = svg_of(Plot::Lines(Lines { x, x_axis: Axis::new("x (m)"), y_axis: Axis::new("y (m)"), series }));
        let doc = parse(&svg);
        prop_assert_eq!(count(&doc, "polyline", &[("stroke-width", "2")]), 2 * k);
    }
}

// ----- documents -----

#[test]
fn html_is_one_self_contained_file_with_every_figure_inline() {
    let report = sample();
    let html = match render_html(&report) {
        Ok(h) => h,
        Err(e) => panic!("{e}"),
    };
    assert!(html.starts_with("<!DOCTYPE html>"));
    for name in [
        "fig-envelope",
        "fig-m2",
        "fig-sobol",
        "fig-lines",
        "fig-sensors",
    ] {
        assert_eq!(html.matches(&format!("<figure id=\"{name}\">")).count(), 1);
    }
    // Every inline SVG is well-formed XML on its own.
    let mut svgs = 0;
    for (start, _) in html.match_indices("<svg ") {
        let Some(len) = html[start..].find("</svg>") else {
            panic!("unclosed svg");
        };
        parse(&html[start..start + len + "</svg>".len()]);
        svgs += 1;
    }
    assert_eq!(svgs, 5);
    for n in 1..=5 {
        assert!(html.contains(&format!("<figcaption>Figure {n}. Caption of ")));
    }
    // Nothing loaded from elsewhere, nothing executed.
    for banned in ["<script", "src=", "href=", "url(", "@import", "<link"] {
        assert!(!html.contains(banned), "{banned}");
    }
    // Escaped text.
    assert!(html.contains("<title>Study &lt;A&gt; &amp; &quot;B&quot;</title>"));
    assert!(html.contains("<p>Verdict: cannot-explain; 3 &lt; 4 &amp; 5 &gt; 2.</p>"));
    assert!(html.contains("<td>&lt;c&gt; &amp; d</td>"));
    assert!(html.contains("<caption>Errors | before and after</caption>"));
    assert!(html.contains("<thead><tr><th>sensor</th><th>rel L2</th></tr></thead>"));
    assert_eq!(html.matches("<tr><td>").count(), 2);
}

#[test]
fn markdown_escapes_text_and_keeps_tables_whole() {
    let md = match render_markdown(&sample()) {
        Ok(m) => m,
        Err(e) => panic!("{e}"),
    };
    assert!(md.starts_with("# Study \\<A\\> \\& \"B\"\n"));
    assert!(md.contains("## M1 \\& M2\n"));
    assert!(md.contains("Plain \\*text\\* with \\_marks\\_ and a \\| pipe."));
    assert!(md.contains("**Errors \\| before and after**"));
    assert!(md.contains("| sensor | rel L2 |\n|---|---|\n"));
    assert!(md.contains("| a\\|b | 0.12 |\n"));
    assert!(md.contains("| \\<c\\> \\& d | line break |\n"));
    // Every table line has exactly columns + 1 unescaped pipes.
    for line in md.lines().filter(|l| l.starts_with('|')) {
        let unescaped = line
            .char_indices()
            .filter(|&(i, c)| c == '|' && !line[..i].ends_with('\\'))
            .count();
        assert_eq!(unescaped, 3, "{line}");
    }
    for (n, name) in [
        "fig-envelope",
        "fig-m2",
        "fig-sobol",
        "fig-lines",
        "fig-sensors",
    ]
    .iter()
    .enumerate()
    {
        assert!(md.contains(&format!("]({name}.svg)\n\n*Figure {}. Caption of ", n + 1)));
    }
}

#[test]
fn markdown_escapes_line_starts_that_would_become_markup() {
    for (text, escaped) in [
        ("# not a heading", "\\# not a heading"),
        ("- not a list", "\\- not a list"),
        ("+ no", "\\+ no"),
        ("12. not numbered", "12\\. not numbered"),
        ("3) neither", "3\\) neither"),
        ("3.5 mm is fine", "3.5 mm is fine"),
        ("a-b c#d 1. e", "a-b c#d 1. e"),
        ("`code` ~x~", "\\`code\\` \\~x\\~"),
    ] {
        assert_eq!(escape_markdown(text), escaped);
    }
    assert_eq!(
        escape_html("<a href='x'>&</a>"),
        "&lt;a href=&#39;x&#39;&gt;&amp;&lt;/a&gt;"
    );
}

#[test]
fn rendering_is_deterministic() {
    let report = sample();
    let (a, b) = (render_html(&report), render_html(&report.clone()));
    match (a, b) {
        (Ok(a), Ok(b)) => assert_eq!(a, b),
        _ => panic!("render failed"),
    }
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let (one, two) = (dir.path().join("one"), dir.path().join("two"));
    let files = write(&report, &one).unwrap_or_else(|e| panic!("{e}"));
    write(&report, &two).unwrap_or_else(|e| panic!("{e}"));
    let mut names: Vec<_> = std::fs::read_dir(&one)
        .unwrap_or_else(|e| panic!("{e}"))
        .filter_map(|e| e.ok().map(|e| e.file_name()))
        .collect();
    names.sort();
    assert_eq!(names.len(), 2 + files.figures.len());
    for name in names {
        let read = |d: &Path| std::fs::read(d.join(&name)).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(read(&one), read(&two), "{name:?}");
    }
}

#[test]
fn write_puts_html_markdown_and_one_svg_per_figure_in_the_folder() {
    let report = sample();
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let out = dir.path().join("nested").join("report");
    let files = write(&report, &out).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(files.html, out.join("report.html"));
    assert_eq!(files.markdown, out.join("report.md"));
    let names: Vec<String> = files
        .figures
        .iter()
        .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect();
    assert_eq!(
        names,
        [
            "fig-envelope.svg",
            "fig-m2.svg",
            "fig-sobol.svg",
            "fig-lines.svg",
            "fig-sensors.svg"
        ]
    );
    let md = std::fs::read_to_string(&files.markdown).unwrap_or_else(|e| panic!("{e}"));
    let html = std::fs::read_to_string(&files.html).unwrap_or_else(|e| panic!("{e}"));
    for (path, block) in files.figures.iter().zip(
        report
            .sections
            .iter()
            .flat_map(|s| &s.blocks)
            .filter_map(|b| match b {
                Block::Figure(f) => Some(f),
                _ => None,
            }),
    ) {
        let svg = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{e}"));
        parse(&svg);
        assert_eq!(Some(svg.clone()), render_svg(block).ok());
        assert!(
            html.contains(svg.trim_end()),
            "the HTML inlines the same drawing"
        );
        assert!(md.contains(&format!("]({}.svg)", block.name)));
    }
    // No temporary file is left behind.
    let leftovers = std::fs::read_dir(&out)
        .unwrap_or_else(|e| panic!("{e}"))
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().starts_with('.'))
        .count();
    assert_eq!(leftovers, 0);
}

// ----- faults -----

/// A fault case: which figure, how to break its plot, the message expected.
type Case = (usize, Box<dyn Fn(&mut Plot)>, &'static str);

/// The report with its `index`-th figure's plot changed by `f`.
fn broken(f: impl FnOnce(&mut Plot), index: usize) -> Report {
    let mut report = sample();
    let figure = report
        .sections
        .iter_mut()
        .flat_map(|s| s.blocks.iter_mut())
        .filter_map(|b| match b {
            Block::Figure(f) => Some(f),
            _ => None,
        })
        .nth(index);
    match figure {
        Some(fig) => f(&mut fig.plot),
        None => panic!("no figure {index}"),
    }
    report
}

/// Renders `report` every way and returns the error, checking all ways agree and that
/// `write` left no folder behind.
fn fault(report: &Report) -> CalibrateError {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let out = dir.path().join("out");
    let Err(e) = write(report, &out) else {
        panic!("a faulty report was written");
    };
    assert!(!out.exists(), "nothing is written for a faulty document");
    let (Err(h), Err(m)) = (render_html(report), render_markdown(report)) else {
        panic!("a faulty report rendered");
    };
    assert_eq!(h.to_string(), e.to_string());
    assert_eq!(m.to_string(), e.to_string());
    assert_eq!(e.kind(), ErrorKind::BadInput);
    e
}

#[test]
fn a_series_of_the_wrong_length_is_named() {
    let e = fault(&broken(
        |p| {
            if let Plot::Lines(l) = p {
                l.series[1].values.pop();
            }
        },
        3,
    ));
    assert!(
        matches!(&e, CalibrateError::Core(CoreError::DimensionMismatch { what, expected: 100, found: 99 })
            if what.contains("figure `fig-lines`") && what.contains("series `curve 1`")),
        "{e}"
    );
}

#[test]
fn nan_and_inf_are_named_by_figure_series_and_index() {
    let e = fault(&broken(
        |p| {
            if let Plot::Lines(l) = p {
                l.series[2].values[17] = f64::NAN;
            }
        },
        3,
    ));
    assert!(
        matches!(&e, CalibrateError::Core(CoreError::NonFinite { what, location, .. })
            if what.contains("`fig-lines`") && what.contains("`curve 2`") && location == "index 17"),
        "{e}"
    );
    let e = fault(&broken(
        |p| {
            if let Plot::Envelope(v) = p {
                v.upper[42] = f64::INFINITY;
            }
        },
        0,
    ));
    assert_eq!(
        e.to_string(),
        "figure `fig-envelope`, band upper edge: non-finite value inf at index 42"
    );
    let e = fault(&broken(
        |p| {
            if let Plot::HeatMap(h) = p {
                h.values[2][1] = f64::NEG_INFINITY;
            }
        },
        1,
    ));
    assert_eq!(
        e.to_string(),
        "figure `fig-m2`: matrix row 2: non-finite value -inf at index 1"
    );
    let e = fault(&broken(
        |p| {
            if let Plot::Structure(s) = p {
                s.marked[1].value = Some(f64::NAN);
            }
        },
        4,
    ));
    assert!(e.to_string().contains("marker 1 (`101.z`) value"), "{e}");
    let e = fault(&broken(
        |p| {
            if let Plot::Stacked(s) = p {
                s.top.values[5] = f64::NAN;
            }
        },
        2,
    ));
    assert!(e.to_string().contains("top series `baseline Q(t)`"), "{e}");
}

#[test]
fn figure_names_must_be_valid_and_unique() {
    for bad in [
        "",
        "Fig-1",
        "fig 1",
        "a/b",
        "../x",
        "-x",
        "fig.svg",
        &"x".repeat(65),
    ] {
        let mut report = sample();
        if let Some(Block::Figure(f)) = report.sections[0].blocks.get_mut(1) {
            f.name = bad.to_owned();
        }
        let e = fault(&report);
        assert!(
            matches!(&e, CalibrateError::Report { what, .. } if what.contains(&format!("`{bad}`"))),
            "{bad}: {e}"
        );
    }
    let mut report = sample();
    if let Some(Block::Figure(f)) = report.sections[1].blocks.get_mut(2) {
        f.name = "fig-m2".into();
    }
    let e = fault(&report);
    assert_eq!(
        e.to_string(),
        "figure `fig-m2`: the name is used by an earlier figure; figure names must be unique"
    );
}

#[test]
fn empty_data_and_blank_axes_are_refused() {
    let cases: Vec<Case> = vec![
        (
            3,
            Box::new(|p| {
                if let Plot::Lines(l) = p {
                    l.x.clear();
                    l.series.clear();
                }
            }),
            "figure `fig-lines`: abscissa is empty",
        ),
        (
            3,
            Box::new(|p| {
                if let Plot::Lines(l) = p {
                    l.series.clear();
                }
            }),
            "figure `fig-lines`: series list is empty",
        ),
        (
            2,
            Box::new(|p| {
                if let Plot::Stacked(s) = p {
                    s.stacked.clear();
                }
            }),
            "figure `fig-sobol`: stacked series list is empty",
        ),
        (
            1,
            Box::new(|p| {
                if let Plot::HeatMap(h) = p {
                    h.values = vec![vec![]];
                }
            }),
            "figure `fig-m2`: matrix (1 x 0) is empty",
        ),
        (
            4,
            Box::new(|p| {
                if let Plot::Structure(s) = p {
                    s.points.clear();
                    s.marked.clear();
                }
            }),
            "figure `fig-sensors`: structure (no points and no markers) is empty",
        ),
        (
            3,
            Box::new(|p| {
                if let Plot::Lines(l) = p {
                    l.y_axis.label = "  ".into();
                }
            }),
            "figure `fig-lines`: y axis: the axis label is blank; label it with its quantity and unit, e.g. `time (s)`",
        ),
        (
            4,
            Box::new(|p| {
                if let Plot::Structure(s) = p {
                    s.unit.clear();
                }
            }),
            "figure `fig-sensors`: length unit: the unit of the coordinates is blank",
        ),
    ];
    for (index, f, message) in cases {
        let e = fault(&broken(f, index));
        assert_eq!(e.to_string(), message);
    }
}

#[test]
fn kind_specific_faults_say_where() {
    let cases: Vec<Case> = vec![
        (
            0,
            Box::new(|p| {
                if let Plot::Envelope(v) = p {
                    v.upper[7] = v.lower[7] - 0.5;
                }
            }),
            "figure `fig-envelope`, band, index 7: the upper edge",
        ),
        (
            0,
            Box::new(|p| {
                if let Plot::Envelope(v) = p {
                    v.marked = vec![(0.05, 0.02)];
                }
            }),
            "figure `fig-envelope`, marked interval 0: [0.05, 0.02] is not an interval",
        ),
        (
            0,
            Box::new(|p| {
                if let Plot::Envelope(v) = p {
                    v.x.swap(10, 11);
                }
            }),
            "figure `fig-envelope`: abscissa, index 11: abscissa values must ascend",
        ),
        (
            1,
            Box::new(|p| {
                if let Plot::HeatMap(h) = p {
                    h.values[1].push(0.5);
                }
            }),
            "figure `fig-m2`: matrix row 1 (as long as row 0): expected 4, found 5",
        ),
        (
            1,
            Box::new(|p| {
                if let Plot::HeatMap(h) = p {
                    h.marked.push((3, 0));
                }
            }),
            "figure `fig-m2`: marked cell (3, 0): outside the 3 x 4 matrix",
        ),
        (
            1,
            Box::new(|p| {
                if let Plot::HeatMap(h) = p {
                    h.column_weights.pop();
                }
            }),
            "figure `fig-m2`, column weights: values (one per abscissa value): expected 4, found 3",
        ),
        (
            1,
            Box::new(|p| {
                if let Plot::HeatMap(h) = p {
                    h.range = (1.0, 1.0);
                }
            }),
            "figure `fig-m2`: colour range: (1, 1) must have low < high",
        ),
        (
            2,
            Box::new(|p| {
                if let Plot::Stacked(s) = p {
                    s.stacked[1].values[3] = -0.01;
                }
            }),
            "figure `fig-sobol`, series `p1`, index 3: stacked values must be non-negative",
        ),
    ];
    for (index, f, message) in cases {
        let e = fault(&broken(f, index));
        assert!(e.to_string().starts_with(message), "{e}");
    }
}

#[test]
fn a_table_row_of_the_wrong_width_is_named() {
    let mut report = sample();
    if let Some(Block::Table(t)) = report.sections[1].blocks.get_mut(1) {
        t.rows[1].push("extra".into());
    }
    let e = fault(&report);
    assert_eq!(
        e.to_string(),
        "section 2 (`Sensitivity`), table `Errors | before and after`, row 2: cells (one per \
         header column): expected 2, found 3"
    );
    let mut report = sample();
    if let Some(Block::Table(t)) = report.sections[1].blocks.get_mut(1) {
        t.header.clear();
    }
    assert!(fault(&report).to_string().ends_with("header is empty"));
}

#[test]
fn an_unwritable_folder_is_an_io_error_naming_the_path() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let file = dir.path().join("a-file");
    std::fs::write(&file, "x").unwrap_or_else(|e| panic!("{e}"));
    let out = file.join("report");
    let Err(e) = write(&sample(), &out) else {
        panic!("wrote under a file");
    };
    assert_eq!(e.kind(), ErrorKind::Io);
    assert!(
        matches!(&e, CalibrateError::Core(CoreError::Io { path, .. }) if path == &out.display().to_string()),
        "{e}"
    );
    // A figure whose file name is taken by a folder: the write fails on that file, names
    // it, and leaves no temporary file.
    let out = dir.path().join("taken");
    std::fs::create_dir_all(out.join("fig-m2.svg")).unwrap_or_else(|e| panic!("{e}"));
    let Err(e) = write(&sample(), &out) else {
        panic!("wrote over a folder");
    };
    assert_eq!(e.kind(), ErrorKind::Io);
    assert!(e.to_string().contains("fig-m2.svg"), "{e}");
    let temporaries = std::fs::read_dir(&out)
        .unwrap_or_else(|e| panic!("{e}"))
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        .count();
    assert_eq!(temporaries, 0);
}
