//! The report document of a study: the verdicts in words, the tables and every figure of
//! the source paper's study, each holding the numbers it plots.

use std::collections::BTreeMap;

use impactcal_core::ParameterSpace;

use super::result::{Errors, StudyResult};
use crate::report::{
    Axis, Block, Envelope, Figure, HeatMap, Lines, Marker, Plot, Provenance, Report, Section,
    Series, Stacked, Structure, Table,
};

/// Where the channels are, for the sensor figure: every point of the structure and the
/// position of each channel's node, keyed by channel label.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Geometry {
    /// Every node of the structure `[x, y, z]`.
    pub points: Vec<[f64; 3]>,
    /// Length unit of the coordinates.
    pub unit: String,
    /// Position of the node of each channel label.
    pub channels: BTreeMap<String, [f64; 3]>,
    /// The nodes of each named region of the structure (the airframe's parts, by the name
    /// its parameters start with: `belly_panel` for `belly_panel.t`): where a change of a
    /// region's parameter is drawn. Empty when the model names no regions.
    pub regions: BTreeMap<String, Vec<[f64; 3]>>,
}

fn axis(label: impl Into<String>) -> Axis {
    Axis {
        label: label.into(),
    }
}

fn series(name: impl Into<String>, values: Vec<f64>) -> Series {
    Series {
        name: name.into(),
        values,
    }
}

fn figure(name: &str, caption: String, plot: Plot) -> Block {
    Block::Figure(Figure {
        name: name.to_string(),
        caption,
        plot,
    })
}

fn table(caption: &str, header: &[&str], rows: Vec<Vec<String>>) -> Block {
    Block::Table(Table {
        caption: caption.to_string(),
        header: header.iter().map(|h| h.to_string()).collect(),
        rows,
    })
}

fn g(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.4}")
    } else {
        "-".into()
    }
}

fn pct(v: f64) -> String {
    if v.is_finite() {
        format!("{:.2} %", 100.0 * v)
    } else {
        "-".into()
    }
}

/// The report of a study without provenance: [`report_with`]`(r, geometry, None)`.
pub fn report(r: &StudyResult, geometry: Option<&Geometry>) -> Report {
    report_with(r, geometry, None)
}

/// The report of a study. `geometry` (when the model has one) places the sensors, the
/// test's first impact shapes and the calibrated change of each region's parameter on the
/// structure; without it those figures are left out and the sensors are listed.
/// `provenance`, when given, is the last section.
pub fn report_with(
    r: &StudyResult,
    geometry: Option<&Geometry>,
    provenance: Option<&Provenance>,
) -> Report {
    let mut lead = vec![
        format!("M1 verdict: {}. {}.", r.m1.verdict.as_str(), r.m1.statement),
        format!("{}.", r.test_preparation.describe()),
    ];
    if let Some(e) = &r.errors {
        lead.push(before_after_sentence(
            r,
            e.reduction,
            &e.baseline,
            &e.calibrated,
        ));
    }
    let mut sections = vec![setup(r), m1_section(r)];
    if r.sensors.is_some() {
        sections.push(sensors_section(r, geometry));
    }
    if r.m2.is_some() {
        sections.push(m2_section(r, geometry));
    }
    if r.surrogate.is_some() {
        sections.push(surrogate_section(r));
    }
    if r.sensitivity.is_some() {
        sections.push(sensitivity_section(r));
    }
    if r.errors.is_some() {
        sections.push(reconcile_section(r, geometry));
    }
    sections.extend(provenance.map(Provenance::section));
    Report {
        title: format!("Calibration study: {}", r.model),
        lead,
        sections,
    }
}

fn before_after_sentence(r: &StudyResult, reduction: f64, b: &Errors, c: &Errors) -> String {
    let m2 = |e: &Errors| e.m2_matched_above_0_9.map_or("-".into(), |n| n.to_string());
    format!(
        "Reconciliation: the prediction error over the {} sensors went from {} to {} ({} \
         reduction; the model's own noise there is {}); M2 shape pairs above 0.9: {} before, \
         {} after.",
        r.sensors.as_ref().map_or(0, |s| s.selected.len()),
        pct(b.prediction_error),
        pct(c.prediction_error),
        pct(reduction),
        pct(r.noise.relative_spread_sensors.unwrap_or(f64::NAN)),
        m2(b),
        m2(c)
    )
}

fn setup(r: &StudyResult) -> Section {
    let calibrated = r.reconcile.as_ref().map(|c| &c.calibrated_point);
    let rows = r
        .space
        .parameters()
        .iter()
        .enumerate()
        .map(|(i, p)| {
            vec![
                p.name.clone(),
                if p.unit.is_empty() {
                    "-".into()
                } else {
                    p.unit.clone()
                },
                g(p.lower),
                g(p.upper),
                g(p.nominal),
                calibrated.map_or("-".into(), |c| g(c[i])),
                calibrated
                    .map_or("", |c| crate::report::bound_flag(p, c[i]))
                    .into(),
            ]
        })
        .collect();
    let n = &r.noise;
    let noise_rows = vec![
        vec![
            "jitter runs (eps)".into(),
            format!("{} ({})", n.runs, n.eps),
        ],
        vec![
            "relative spread over the objective channels".into(),
            pct(n.relative_spread),
        ],
        vec![
            "relative spread over the sensors".into(),
            n.relative_spread_sensors.map_or("-".into(), pct),
        ],
        vec!["relative spread of Q(t)".into(), pct(n.relative_spread_q)],
        vec![
            format!(
                "median predictability horizon (spread > {} of the signal)",
                n.fraction
            ),
            n.median_horizon
                .map_or("beyond the window".into(), |h| format!("{h:.4} s")),
        ],
        vec![
            "shared channels left out as unpredictable".into(),
            format!(
                "{} of {}{}",
                r.channels.unpredictable.len(),
                r.channels.shared,
                if r.channels.kept_unpredictable {
                    " (kept on request)"
                } else {
                    ""
                }
            ),
        ],
    ];
    Section {
        heading: "Model, test and window".into(),
        blocks: vec![
            Block::Paragraph(format!(
                "Model: {}. Window {:.4}-{:.4} s, {} samples of {} s{}. The test shares {} of \
                 the model's {} channels; {} of them are predictable over the window and make \
                 the objective. A jitter ensemble at the nominal point (every parameter moved \
                 by at most {} relative) measures the model's own noise: it is the floor of \
                 every error below, and channels whose spread exceeds {} of their signal inside \
                 the window are not fitted.",
                r.model,
                r.window[0],
                r.window[1],
                r.samples,
                r.dt,
                r.cfc.map_or(String::new(), |c| format!(", CFC {c}")),
                r.channels.shared,
                r.channels.model,
                r.channels.objective.len(),
                r.noise.eps,
                r.noise.fraction
            )),
            table(
                "Parameters: bounds, nominal and calibrated values (a calibrated value \
                 within 0.1 % of the range's width from a bound is flagged)",
                &[
                    "parameter",
                    "unit",
                    "lower",
                    "upper",
                    "nominal",
                    "calibrated",
                    "bound",
                ],
                rows,
            ),
            table(
                "The model's own noise (jitter ensemble)",
                &["quantity", "value"],
                noise_rows,
            ),
        ],
    }
}

fn m1_section(r: &StudyResult) -> Section {
    let m = &r.m1;
    let mut blocks = vec![
        Block::Paragraph(format!("Verdict: {}. {}.", m.verdict.as_str(), m.statement)),
        figure(
            "fig-m1",
            format!(
                "M1: envelope of Q(t) over {} runs and the test's Q_e(t); shaded where Q_e leaves \
                 it ({:.1} % of the window)",
                m.n_runs,
                100.0 * m.exceedance_fraction
            ),
            Plot::Envelope(Envelope {
                x: m.time.clone(),
                x_axis: axis("time (s)"),
                y_axis: axis(format!("Q ({})", r.unit)),
                band_name: format!("ensemble min/max ({} runs)", m.n_runs),
                lower: m.lower.clone(),
                upper: m.upper.clone(),
                series: vec![
                    series("test Q_e", m.test.clone()),
                    series("baseline", r.curves.q_baseline.clone()),
                ],
                marked: m.intervals.iter().map(|i| (i[0], i[1])).collect(),
            }),
        ),
    ];
    let failed: Vec<Vec<String>> = r
        .ensemble
        .failed
        .iter()
        .map(|f| {
            vec![
                f.index.to_string(),
                f.point.iter().map(|v| g(*v)).collect::<Vec<_>>().join(", "),
                f.message.clone(),
            ]
        })
        .collect();
    blocks.push(Block::Paragraph(format!(
        "{} of {} ensemble runs succeeded; failed runs are kept out of the envelope and the \
         surrogates.",
        r.ensemble.succeeded, r.ensemble.requested
    )));
    if !failed.is_empty() {
        blocks.push(table("Failed runs", &["run", "point", "reason"], failed));
    }
    Section {
        heading: "M1: can the parameter set explain the test?".into(),
        blocks,
    }
}

fn sensors_section(r: &StudyResult, geometry: Option<&Geometry>) -> Section {
    let Some(s) = &r.sensors else {
        return Section {
            heading: "Sensors".into(),
            blocks: Vec::new(),
        };
    };
    let mut blocks = vec![Block::Paragraph(format!(
        "{} sensors placed by effective independence on {} impact shapes of the ensemble, \
         among {} candidate channels (information kept {:.3e}, condition number {:.2}). The \
         test at the sensors, expanded to the other {} channels through the baseline's shapes, \
         has a relative error of {} there (fit condition {}). Sensors: {}.",
        s.selected.len(),
        s.shapes,
        s.candidates,
        s.determinant_ratio,
        s.condition_number,
        s.candidates - s.selected.len(),
        s.expansion_rel_error.map_or("-".into(), pct),
        s.expansion_condition
            .map_or("-".into(), |c| format!("{c:.2}")),
        s.selected.join(", ")
    ))];
    if let Some(geo) = geometry {
        let marked = s
            .selected
            .iter()
            .filter_map(|l| {
                geo.channels.get(l).map(|at| Marker {
                    label: l.clone(),
                    at: *at,
                    value: None,
                })
            })
            .collect();
        blocks.push(figure(
            "fig-sensors",
            format!("Sensor locations ({} channels)", s.selected.len()),
            Plot::Structure(Structure {
                points: geo.points.clone(),
                unit: geo.unit.clone(),
                marked,
                value_axis: axis("-"),
                limit: None,
            }),
        ));
    }
    Section {
        heading: "Sensors".into(),
        blocks,
    }
}

fn heat(m: &super::m2::M2Result) -> Plot {
    Plot::HeatMap(HeatMap {
        values: m.matrix.clone(),
        range: (0.0, 1.0),
        row_axis: axis("model shape"),
        column_axis: axis("test shape"),
        row_weights: m.model_contributions.iter().map(|c| 100.0 * c).collect(),
        column_weights: m.test_contributions.iter().map(|c| 100.0 * c).collect(),
        row_weights_axis: axis("contribution (%)"),
        column_weights_axis: axis("contribution (%)"),
        marked: m.pairs.iter().map(|p| (p.0, p.1)).collect(),
        annotate: m.matrix.len() <= 12,
    })
}

fn m2_section(r: &StudyResult, geometry: Option<&Geometry>) -> Section {
    let mut blocks = Vec::new();
    if let Some(m) = &r.m2 {
        blocks.push(Block::Paragraph(format!(
            "M2, the cosine between model and test impact shapes over the objective channels: \
             {} of {} optimally paired shapes above 0.9 for the baseline{}.",
            m.baseline.matched_above_0_9,
            m.baseline.pairs.len(),
            m.calibrated.as_ref().map_or(String::new(), |c| format!(
                ", {} of {} for the calibrated model",
                c.matched_above_0_9,
                c.pairs.len()
            ))
        )));
        blocks.push(figure(
            "fig-m2-baseline",
            "M2 of the baseline: |cosine| of model (rows) and test (columns) shapes, \
             contributions (%) on the axes, optimal pairs outlined"
                .into(),
            heat(&m.baseline),
        ));
        if let Some(c) = &m.calibrated {
            blocks.push(figure(
                "fig-m2-calibrated",
                "M2 of the calibrated model".into(),
                heat(c),
            ));
        }
        if let Some(g) = geometry {
            blocks.extend(shape_figures(&m.baseline, &r.channels.objective, g));
        }
    }
    Section {
        heading: "M2: impact shapes of model and test".into(),
        blocks,
    }
}

fn surrogate_section(r: &StudyResult) -> Section {
    let mut blocks = Vec::new();
    if let Some(s) = &r.surrogate {
        let kinds: Vec<&String> = s.q.loo_by_kind.keys().chain(s.q.failed.keys()).collect();
        let rows = kinds
            .iter()
            .map(|k| {
                vec![
                    k.to_string(),
                    s.q.loo_by_kind.get(*k).map_or("failed".into(), |v| g(*v)),
                    s.sensors
                        .loo_by_kind
                        .get(*k)
                        .map_or("failed".into(), |v| g(*v)),
                ]
            })
            .collect();
        blocks.push(Block::Paragraph(format!(
            "Surrogates fitted to the ensemble, judged by leave-one-out error (RMS over the \
             pooled standard deviation). Used: {} for Q(t) (LOO {}), {} for the sensor \
             histories (LOO {}). The smoothing cubic RBF chose lambda = {} by LOO.",
            s.q.chosen,
            g(s.q.loo_rel_error),
            s.sensors.chosen,
            g(s.sensors.loo_rel_error),
            s.q.smoothing_lambda
                .map_or("-".into(), |l| format!("{l:e}"))
        )));
        let shapes = |c: &super::surrogates::SurrogateChoice| {
            c.shape_count.map_or("full histories".to_string(), |k| {
                format!("{k} impact shapes")
            })
        };
        blocks.push(Block::Paragraph(format!(
            "A `-shapes` surrogate predicts the coordinates of the histories on the \
             ensemble's impact shapes and rebuilds the histories from them; it is used when \
             its LOO error is within 1 % of the best. Q(t): {}; sensor histories: {}.",
            shapes(&s.q),
            shapes(&s.sensors)
        )));
        blocks.push(table(
            "Leave-one-out errors by surrogate",
            &["surrogate", "Q(t)", "sensor histories"],
            rows,
        ));
    }
    Section {
        heading: "Surrogates".into(),
        blocks,
    }
}

fn sensitivity_section(r: &StudyResult) -> Section {
    let mut blocks = Vec::new();
    if let Some(s) = &r.sensitivity {
        blocks.push(Block::Paragraph(format!(
            "Sobol' indices of Q(t) from {} surrogate evaluations ({}). Ranking by \
             variance-weighted total index: {}.",
            s.evaluations,
            s.estimator,
            s.ranking
                .iter()
                .map(|n| format!("{n} ({:.3})", s.aggregated_total[n]))
                .collect::<Vec<_>>()
                .join(", ")
        )));
        blocks.push(figure(
            "fig-sensitivity",
            "First-order Sobol' indices of Q(t) over time, stacked, with the baseline Q(t) above"
                .into(),
            Plot::Stacked(Stacked {
                x: s.time.clone(),
                x_axis: axis("time (s)"),
                y_axis: axis("first-order index (-)"),
                stacked: s
                    .first_order
                    .iter()
                    .map(|(n, v)| series(n.clone(), v.iter().map(|x| x.max(0.0)).collect()))
                    .collect(),
                top_axis: axis(format!("Q ({})", r.unit)),
                top: series("baseline Q", r.curves.q_baseline.clone()),
            }),
        ));
        blocks.push(table(
            "Dominant parameter per time window",
            &["from (s)", "to (s)", "parameter", "first-order index"],
            s.dominant
                .iter()
                .map(|d| vec![g(d.start), g(d.end), d.parameter.clone(), g(d.first_order)])
                .collect(),
        ));
    }
    Section {
        heading: "Sensitivity over time".into(),
        blocks,
    }
}

/// The test's first impact shapes on the structure (the source paper's Fig. 8): for each
/// shape, the entries of the channels along the direction that carries most of the
/// shape's energy (the label's suffix after its last `.`, `x`, `y` or `z` for nodal
/// channels), one marker per node, larger magnitudes drawn over smaller. Nothing when the
/// result kept no shapes or the geometry does not place the compared channels.
fn shape_figures(m: &super::m2::M2Result, labels: &[String], g: &Geometry) -> Vec<Block> {
    let placed = labels.iter().all(|l| g.channels.contains_key(l));
    if !placed {
        return Vec::new();
    }
    m.test_shapes
        .iter()
        .enumerate()
        .filter(|(_, s)| s.len() == labels.len())
        .map(|(j, shape)| {
            let direction = |l: &str| l.rsplit_once('.').map_or("", |(_, d)| d).to_string();
            let mut energy: BTreeMap<String, f64> = BTreeMap::new();
            for (l, v) in labels.iter().zip(shape) {
                *energy.entry(direction(l)).or_default() += v * v;
            }
            let (dir, share) = energy
                .iter()
                .max_by(|a, b| a.1.total_cmp(b.1))
                .map_or((String::new(), 0.0), |(d, e)| (d.clone(), *e));
            let mut marked: Vec<Marker> = labels
                .iter()
                .zip(shape)
                .filter(|(l, _)| direction(l) == dir)
                .map(|(l, v)| Marker {
                    label: String::new(),
                    at: g.channels[l],
                    value: Some(*v),
                })
                .collect();
            marked.sort_by(|a, b| {
                let size = |m: &Marker| m.value.map_or(0.0, f64::abs);
                size(a).total_cmp(&size(b))
            });
            let along = if dir.is_empty() {
                "every compared channel".to_string()
            } else {
                format!("the {dir} channels")
            };
            let contribution = m.test_contributions.get(j).copied().unwrap_or(f64::NAN);
            figure(
                &format!("fig-shape-{}", j + 1),
                format!(
                    "Impact shape {} of the test (contribution {}) on the structure: its \
                     entries at {along} ({} nodes, {:.0} % of the shape's energy); red and \
                     blue move in opposite directions, and the shape as a whole is fixed \
                     only up to sign",
                    j + 1,
                    pct(contribution),
                    marked.len(),
                    100.0 * share
                ),
                Plot::Structure(Structure {
                    points: g.points.clone(),
                    unit: g.unit.clone(),
                    marked,
                    value_axis: axis("shape entry (-)"),
                    limit: None,
                }),
            )
        })
        .collect()
}

/// The largest change from nominal a study of `space` allows to a parameter of a region of
/// `g`, in percent: the colour limit of every figure of changes on the structure, so that
/// the hidden and the calibrated change read on one scale and a full colour means a
/// parameter at the end of its range.
fn change_limit(space: &ParameterSpace, g: &Geometry) -> f64 {
    space
        .parameters()
        .iter()
        .filter(|p| region_of(&p.name, g).is_some() && p.nominal != 0.0)
        .map(|p| {
            100.0 * ((p.upper - p.nominal).abs().max((p.nominal - p.lower).abs()) / p.nominal.abs())
        })
        .fold(0.0, f64::max)
}

/// The region of `g` a parameter `name` (`<region>.<field>`) belongs to.
fn region_of<'a>(name: &str, g: &'a Geometry) -> Option<&'a Vec<[f64; 3]>> {
    name.split_once('.')
        .and_then(|(region, _)| g.regions.get(region))
}

/// A figure of relative changes `(parameter, change)` drawn on the regions of `g` the
/// parameters name (the source paper's Fig. 13): every node of a changed region a marker
/// coloured by the change in %, on the scale of [`change_limit`]. `None` when no changed
/// parameter names a region.
fn change_figure(
    name: &str,
    what: &str,
    changes: &[(String, f64)],
    threshold: f64,
    limit: f64,
    g: &Geometry,
) -> Option<Block> {
    let mut drawn: Vec<(&str, f64, &Vec<[f64; 3]>)> = changes
        .iter()
        .filter(|(_, c)| c.abs() > threshold)
        .filter_map(|(n, c)| region_of(n, g).map(|nodes| (n.as_str(), *c, nodes)))
        .collect();
    if drawn.is_empty() || limit.is_nan() || limit <= 0.0 {
        return None;
    }
    drawn.sort_by(|a, b| a.1.abs().total_cmp(&b.1.abs()));
    let marked = drawn
        .iter()
        .flat_map(|(_, c, nodes)| {
            nodes.iter().map(move |at| Marker {
                label: String::new(),
                at: *at,
                value: Some(100.0 * c),
            })
        })
        .collect();
    let listed = drawn
        .iter()
        .rev()
        .map(|(n, c, _)| format!("{n} {:+.1} %", 100.0 * c))
        .collect::<Vec<_>>()
        .join(", ");
    Some(figure(
        name,
        format!(
            "{what} on the structure: the nodes of each region whose parameter changed by              more than {:.0} % from nominal ({listed}), coloured by the change; the colour              scale ends at {limit:.0} %, the largest change the parameters' ranges allow",
            100.0 * threshold
        ),
        Plot::Structure(Structure {
            points: g.points.clone(),
            unit: g.unit.clone(),
            marked,
            value_axis: axis("change from nominal (%)"),
            limit: Some(limit),
        }),
    ))
}

/// The share by which calibration moved a parameter from nominal, below which a move is
/// not drawn on the structure (a move of 1 % is within what the search resolves).
const DRAWN_MOVE: f64 = 0.01;

fn reconcile_section(r: &StudyResult, geometry: Option<&Geometry>) -> Section {
    let mut blocks = Vec::new();
    if let (Some(e), Some(c)) = (&r.errors, &r.reconcile) {
        blocks.push(Block::Paragraph(format!(
            "CORS-RBF minimised ln(prediction error) over the sensors with {} new model runs \
             ({} at a time), started from the baseline and the ensemble ({} runs). The best point \
             is the {}. {}",
            c.runs,
            c.batch,
            c.warm_start,
            c.best_from,
            before_after_sentence(r, e.reduction, &e.baseline, &e.calibrated)
        )));
        if let Some(g) = geometry {
            let moves: Vec<(String, f64)> = r
                .space
                .parameters()
                .iter()
                .zip(&c.calibrated_point)
                .filter(|(p, _)| p.nominal != 0.0)
                .map(|(p, v)| (p.name.clone(), v / p.nominal - 1.0))
                .collect();
            blocks.extend(change_figure(
                "fig-calibrated-change",
                "The calibrated change",
                &moves,
                DRAWN_MOVE,
                change_limit(&r.space, g),
                g,
            ));
        }
        let (b, a) = (&e.baseline, &e.calibrated);
        let m2 = |x: &Errors| x.m2_matched_above_0_9.map_or("-".into(), |n| n.to_string());
        let noise = r.noise.relative_spread_sensors.unwrap_or(f64::NAN);
        blocks.push(table(
            "Before and after",
            &["measure", "baseline", "calibrated", "model's own noise"],
            vec![
                vec![
                    "prediction error (sensors)".into(),
                    pct(b.prediction_error),
                    pct(a.prediction_error),
                    pct(noise),
                ],
                vec![
                    "Q(t) error".into(),
                    pct(b.q_error),
                    pct(a.q_error),
                    pct(r.noise.relative_spread_q),
                ],
                vec!["M2 pairs above 0.9".into(), m2(b), m2(a), "-".into()],
                vec![
                    "mean relative L2 per sensor".into(),
                    g(b.rel_l2),
                    g(a.rel_l2),
                    "-".into(),
                ],
                vec![
                    "mean Sprague-Geers C".into(),
                    g(b.sprague_geers_c),
                    g(a.sprague_geers_c),
                    "-".into(),
                ],
                vec![
                    "mean ISO/TS 18571 R".into(),
                    g(b.iso18571_r),
                    g(a.iso18571_r),
                    "-".into(),
                ],
            ],
        ));
        let rows = b
            .per_sensor
            .iter()
            .filter_map(|s| {
                let after = a.per_sensor.iter().find(|x| x.label == s.label)?;
                Some(vec![
                    s.label.clone(),
                    g(s.rel_l2),
                    g(after.rel_l2),
                    g(s.sprague_geers_c),
                    g(after.sprague_geers_c),
                    g(s.iso18571_r),
                    g(after.iso18571_r),
                ])
            })
            .collect();
        blocks.push(table(
            "Per sensor",
            &[
                "sensor",
                "rel. L2 before",
                "after",
                "S-G C before",
                "after",
                "ISO R before",
                "after",
            ],
            rows,
        ));
        let mut q = vec![
            series("test Q_e", r.curves.q_test.clone()),
            series("baseline", r.curves.q_baseline.clone()),
        ];
        if let Some(qc) = &r.curves.q_calibrated {
            q.push(series("calibrated", qc.clone()));
        }
        blocks.push(figure(
            "fig-q",
            "Q(t) of the test, the baseline and the calibrated model".into(),
            Plot::Lines(Lines {
                x: r.curves.time.clone(),
                x_axis: axis("time (s)"),
                y_axis: axis(format!("Q ({})", r.unit)),
                series: q,
            }),
        ));
        if let Some(label) = &r.curves.sensor {
            let mut s = vec![
                series("test", r.curves.sensor_test.clone()),
                series("baseline", r.curves.sensor_baseline.clone()),
            ];
            if let Some(c) = &r.curves.sensor_calibrated {
                s.push(series("calibrated", c.clone()));
            }
            blocks.push(figure(
                "fig-sensor",
                format!("Sensor {label}: test, baseline and calibrated histories"),
                Plot::Lines(Lines {
                    x: r.curves.time.clone(),
                    x_axis: axis("time (s)"),
                    y_axis: axis(format!("{label} ({})", r.unit)),
                    series: s,
                }),
            ));
        }
    }
    Section {
        heading: "Reconciliation: before and after".into(),
        blocks,
    }
}

/// One parameter of a reveal: its nominal value, the value the test was made with, and the
/// value calibration found.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Revealed {
    /// The parameter.
    pub name: String,
    /// Nominal value (the baseline model's).
    pub nominal: f64,
    /// The value of the hidden test.
    pub hidden: f64,
    /// The calibrated value.
    pub calibrated: f64,
}

impl Revealed {
    /// Relative change of the test from nominal.
    pub fn changed_by(&self) -> f64 {
        self.hidden / self.nominal - 1.0
    }

    /// Relative move of calibration from nominal.
    pub fn moved_by(&self) -> f64 {
        self.calibrated / self.nominal - 1.0
    }
}

/// The reveal of a study on a synthetic test (the source paper's §5.4): what was changed to
/// make the test, against what calibration moved. A parameter counts as changed or moved
/// when it differs from nominal by more than `threshold` (relative). With `geometry` and
/// the study's `space`, the hidden change is drawn on the structure (the paper's Fig. 13a)
/// on the colour scale of the calibrated change the study's report draws (Fig. 13b).
pub fn reveal_section(
    items: &[Revealed],
    threshold: f64,
    structure: Option<(&Geometry, &ParameterSpace)>,
) -> Section {
    let changed: Vec<&str> = items
        .iter()
        .filter(|r| r.changed_by().abs() > threshold)
        .map(|r| r.name.as_str())
        .collect();
    let moved: Vec<&str> = items
        .iter()
        .filter(|r| r.moved_by().abs() > threshold)
        .map(|r| r.name.as_str())
        .collect();
    let both = changed.iter().filter(|c| moved.contains(c)).count();
    let rows = items
        .iter()
        .map(|r| {
            vec![
                r.name.clone(),
                g(r.nominal),
                g(r.hidden),
                pct(r.changed_by()),
                g(r.calibrated),
                pct(r.moved_by()),
            ]
        })
        .collect();
    let drawn = structure.and_then(|(g, space)| {
        let changes: Vec<(String, f64)> = items
            .iter()
            .map(|r| (r.name.clone(), r.changed_by()))
            .collect();
        change_figure(
            "fig-hidden-change",
            "The hidden change that made the test",
            &changes,
            threshold,
            change_limit(space, g),
            g,
        )
    });
    Section {
        heading: "The reveal: what was changed, what calibration moved".into(),
        blocks: vec![
            Block::Paragraph(format!(
                "The test was the model with {} changed ({}); calibration moved {} by more than \
                 {:.0} % ({}); {} of the changed parameters were among them.",
                changed.len(),
                changed.join(", "),
                moved.len(),
                100.0 * threshold,
                if moved.is_empty() {
                    "none".to_string()
                } else {
                    moved.join(", ")
                },
                both
            )),
            table(
                "Hidden and calibrated values",
                &[
                    "parameter",
                    "nominal",
                    "test (hidden)",
                    "change",
                    "calibrated",
                    "move",
                ],
                rows,
            ),
        ]
        .into_iter()
        .chain(drawn)
        .collect(),
    }
}
