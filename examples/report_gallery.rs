//! Writes a sample report with every kind of figure, drawn from synthetic data: the curves,
//! band, matrix, indices and structure of a small impact study. The headless-browser check
//! (`tests/browser/check_report.sh`) renders it.
//!
//! ```text
//! cargo run --example report_gallery -- OUT_DIR
//! ```

use std::f64::consts::PI;
use std::path::PathBuf;

use impactcal::calibrate::report::{
    self, Axis, Block, Envelope, Figure, HeatMap, Lines, Marker, Plot, Report, Section, Series,
    Stacked, Structure, Table,
};

/// A damped crash pulse: velocity norm of a structure that hits at `t = 0` and rings down.
fn pulse(t: f64, amplitude: f64, frequency: f64, decay: f64) -> f64 {
    amplitude * (-decay * t).exp() * (2.0 * PI * frequency * t).sin().abs() + 0.2 * amplitude
}

fn figure(name: &str, caption: &str, plot: Plot) -> Block {
    Block::Figure(Figure {
        name: name.to_owned(),
        caption: caption.to_owned(),
        plot,
    })
}

/// The ensemble's band of Q(t) and the intervals where the test leaves it.
fn envelope(t: &[f64], test: &[f64]) -> Envelope {
    let runs: Vec<Vec<f64>> = (0..40)
        .map(|r| {
            let f = 0.9 + 0.2 * (r as f64 / 39.0);
            let a = 180.0 + 40.0 * ((r * 7 % 40) as f64 / 39.0);
            t.iter().map(|&t| pulse(t, a, 40.0 * f, 35.0)).collect()
        })
        .collect();
    let lower: Vec<f64> = (0..t.len())
        .map(|k| runs.iter().map(|r| r[k]).fold(f64::INFINITY, f64::min))
        .collect();
    let upper: Vec<f64> = (0..t.len())
        .map(|k| runs.iter().map(|r| r[k]).fold(f64::NEG_INFINITY, f64::max))
        .collect();
    let mut marked = Vec::new();
    let mut start = None;
    for k in 0..t.len() {
        let out = test[k] < lower[k] || test[k] > upper[k];
        match (out, start) {
            (true, None) => start = Some(t[k]),
            (false, Some(s)) => {
                marked.push((s, t[k - 1]));
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        marked.push((s, t[t.len() - 1]));
    }
    Envelope {
        x: t.to_vec(),
        x_axis: Axis::new("time (s)"),
        y_axis: Axis::new("Q (in/s)"),
        band_name: "ensemble min/max (40 runs)".into(),
        lower,
        upper,
        series: vec![Series::new("test Q_e", test.to_vec())],
        marked,
    }
}

/// MAC values of two sets of sampled mode-like shapes, with the best match of each row
/// outlined.
fn mac_map() -> HeatMap {
    let n = 6;
    let shape = |k: usize, skew: f64| -> Vec<f64> {
        (0..64)
            .map(|i| {
                let s = i as f64 / 63.0;
                ((k + 1) as f64 * PI * s + skew * s * s).sin()
            })
            .collect()
    };
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let test: Vec<Vec<f64>> = (0..n).map(|k| shape(k, 0.6)).collect();
    let model: Vec<Vec<f64>> = (0..n).map(|k| shape(k, 0.0)).collect();
    let values: Vec<Vec<f64>> = test
        .iter()
        .map(|a| {
            model
                .iter()
                .map(|b| dot(a, b).powi(2) / (dot(a, a) * dot(b, b)))
                .collect()
        })
        .collect();
    let marked = values
        .iter()
        .enumerate()
        .map(|(i, row)| {
            let j = (0..n)
                .max_by(|&a, &b| row[a].total_cmp(&row[b]))
                .unwrap_or(0);
            (i, j)
        })
        .collect();
    let weights: Vec<f64> = (0..n).map(|k| 60.0 / (k as f64 + 1.0).powi(2)).collect();
    HeatMap {
        values,
        range: (0.0, 1.0),
        row_axis: Axis::new("test shape"),
        column_axis: Axis::new("baseline model shape"),
        row_weights: weights.clone(),
        column_weights: weights.iter().map(|w| 0.9 * w).collect(),
        row_weights_axis: Axis::new("contribution (%)"),
        column_weights_axis: Axis::new("contribution (%)"),
        marked,
        annotate: true,
    }
}

/// First-order indices of four parameters that take turns dominating.
fn indices(t: &[f64], q: &[f64]) -> Stacked {
    let bump = |c: f64, w: f64| -> Vec<f64> {
        t.iter()
            .map(|&t| 0.7 * (-((t - c) / w).powi(2)).exp() + 0.03)
            .collect()
    };
    Stacked {
        x: t.to_vec(),
        x_axis: Axis::new("time (s)"),
        y_axis: Axis::new("first-order index (-)"),
        stacked: vec![
            Series::new("floor thickness", bump(0.005, 0.006)),
            Series::new("frame thickness", bump(0.018, 0.008)),
            Series::new("skin thickness", bump(0.032, 0.008)),
            Series::new("mass of seats", bump(0.045, 0.006)),
        ],
        top_axis: Axis::new("Q (in/s)"),
        top: Series::new("baseline Q(t)", q.to_vec()),
    }
}

/// A fuselage-like frame: rings of points along x, and eight sensors.
fn airframe(values: bool) -> Structure {
    let mut points = Vec::new();
    for i in 0..=20 {
        let x = 10.0 * f64::from(i);
        for k in 0..16 {
            let a = 2.0 * PI * f64::from(k) / 16.0;
            points.push([x, 30.0 * a.cos(), 25.0 + 25.0 * a.sin()]);
        }
    }
    let marked = (0..8)
        .map(|s| {
            let x = 20.0 + 22.0 * f64::from(s);
            let a = PI * (1.25 + 0.5 * f64::from(s % 2));
            Marker {
                label: format!("{}.z", 1000 + 16 * s),
                at: [x, 30.0 * a.cos(), 25.0 + 25.0 * a.sin()],
                value: values.then(|| (0.8 * f64::from(s)).sin() * 12.0),
            }
        })
        .collect();
    Structure {
        points,
        unit: "in".into(),
        marked,
        value_axis: Axis::new("residual (noise units)"),
        limit: None,
    }
}

fn gallery() -> Report {
    let t: Vec<f64> = (0..=500).map(|k| f64::from(k) * 1e-4).collect();
    let test: Vec<f64> = t.iter().map(|&t| pulse(t, 235.0, 41.0, 30.0)).collect();
    let baseline: Vec<f64> = t.iter().map(|&t| pulse(t, 200.0, 40.0, 35.0)).collect();
    let calibrated: Vec<f64> = t.iter().map(|&t| pulse(t, 228.0, 41.0, 31.0)).collect();
    let sensor = |a: f64, f: f64| -> Vec<f64> {
        t.iter()
            .map(|&t| a * (-40.0 * t).exp() * (2.0 * PI * f * t).sin())
            .collect()
    };
    Report {
        title: "Calibration report <gallery> & sample".into(),
        lead: vec![
            "M1 verdict: cannot-explain (the test leaves the envelope for part of the window)."
                .into(),
            "Every figure below is drawn from synthetic data; the numbers mean nothing.".into(),
        ],
        sections: vec![
            Section {
                heading: "M1: can the parameter set explain the test?".into(),
                blocks: vec![
                    Block::Paragraph(
                        "Q(t) = ||v(t, p)||_2 over the sensors; the band is the ensemble's \
                         min/max and shaded strips mark where Q_e leaves it."
                            .into(),
                    ),
                    figure(
                        "fig-m1-envelope",
                        "M1 envelope of Q(t) with the test's Q_e(t).",
                        Plot::Envelope(envelope(&t, &test)),
                    ),
                ],
            },
            Section {
                heading: "Sensors and shapes".into(),
                blocks: vec![
                    figure(
                        "fig-sensors",
                        "Sensor locations on the airframe (plan and side view).",
                        Plot::Structure(airframe(false)),
                    ),
                    figure(
                        "fig-m2-baseline",
                        "M2: MAC of test shapes against baseline shapes, contributions on the axes; the pairing outlined.",
                        Plot::HeatMap(mac_map()),
                    ),
                ],
            },
            Section {
                heading: "Sensitivity over time".into(),
                blocks: vec![figure(
                    "fig-sobol",
                    "First-order Sobol' indices of Q(t), stacked, under the baseline Q(t).",
                    Plot::Stacked(indices(&t, &baseline)),
                )],
            },
            Section {
                heading: "Reconciliation".into(),
                blocks: vec![
                    Block::Table(Table {
                        caption: "Before and after | calibration".into(),
                        header: vec!["quantity".into(), "baseline".into(), "calibrated".into()],
                        rows: vec![
                            vec!["prediction error".into(), "0.412".into(), "0.379".into()],
                            vec!["M2 shapes > 0.9".into(), "1".into(), "7".into()],
                            vec!["a|b <c> & *d*".into(), "-".into(), "_e_".into()],
                        ],
                    }),
                    figure(
                        "fig-q-before-after",
                        "Q(t) of test, baseline and calibrated model.",
                        Plot::Lines(Lines {
                            x: t.clone(),
                            x_axis: Axis::new("time (s)"),
                            y_axis: Axis::new("Q (in/s)"),
                            series: vec![
                                Series::new("test", test.clone()),
                                Series::new("baseline", baseline.clone()),
                                Series::new("calibrated", calibrated),
                            ],
                        }),
                    ),
                    figure(
                        "fig-sensor-1021z",
                        "Sensor 1021.z: test, baseline and calibrated histories.",
                        Plot::Lines(Lines {
                            x: t.clone(),
                            x_axis: Axis::new("time (s)"),
                            y_axis: Axis::new("velocity (in/s)"),
                            series: vec![
                                Series::new("test", sensor(120.0, 42.0)),
                                Series::new("baseline", sensor(100.0, 40.0)),
                                Series::new("calibrated", sensor(115.0, 41.5)),
                            ],
                        }),
                    ),
                    figure(
                        "fig-residual-pattern",
                        "Residual pattern at the sensors (diverging colour scale).",
                        Plot::Structure(airframe(true)),
                    ),
                ],
            },
        ],
    }
}

fn main() {
    let Some(dir) = std::env::args_os().nth(1).map(PathBuf::from) else {
        eprintln!("usage: report_gallery OUT_DIR");
        std::process::exit(2);
    };
    match report::write(&gallery(), &dir) {
        Ok(files) => {
            println!("{}", files.html.display());
            println!("{}", files.markdown.display());
            for f in &files.figures {
                println!("{}", f.display());
            }
        }
        Err(e) => {
            eprintln!("report_gallery: {e}");
            std::process::exit(if e.kind() == impactcal::core::ErrorKind::BadInput {
                2
            } else {
                1
            });
        }
    }
}
