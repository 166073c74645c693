//! The report of a closed loop: the verdict in short, then the nuisance terms, the noise
//! floor, detection before and after with the residual's sensor pattern `u_1` (a map over
//! the channels) and time pattern `v_1`, the ranked candidates, the selection with its
//! information criteria, the unattributed error when there is one, and the errors before
//! and after on the calibration test and the holdout.

mod candidates;
mod compared;

use crate::report::{
    Axis, Block, Figure, HeatMap, Lines, Marker, Plot, Provenance, Report, Section, Series,
    Structure, Table,
};
use crate::study::document::Geometry;

use super::result::{Errors, LoopResult, Stages, Verdict};

/// The unit of the compared histories, or `test units` when the test gave none.
fn unit_of(r: &LoopResult) -> &str {
    if r.unit.is_empty() {
        "test units"
    } else {
        &r.unit
    }
}

fn f(x: f64) -> String {
    if x.is_nan() {
        "-".into()
    } else if x != 0.0 && (x.abs() >= 1e5 || x.abs() < 1e-3) {
        format!("{x:.3e}")
    } else {
        format!("{x:.4}")
    }
}

fn table(caption: &str, header: &[&str], rows: Vec<Vec<String>>) -> Block {
    Block::Table(Table {
        caption: caption.into(),
        header: header.iter().map(|s| s.to_string()).collect(),
        rows,
    })
}

/// The report document of `r` without geometry or provenance: [`report_with`]`(r, None,
/// None)`.
pub fn report(r: &LoopResult) -> Report {
    report_with(r, None, None)
}

/// The report document of `r`: the lead (verdict and errors in short), what was compared,
/// the test against the three models on the channels that matter most, their M1 envelopes
/// and M2 matrices, then one section per stage of the loop (nuisance terms, noise floor,
/// detection with the residual's pattern drawn on `geometry` where it places the channels,
/// attribution, selection, the unattributed error when some remains, before and after),
/// the parameters with those that ended at a bound flagged, the candidates beyond the first
/// ten, and `provenance` last.
pub fn report_with(
    r: &LoopResult,
    geometry: Option<&Geometry>,
    provenance: Option<&Provenance>,
) -> Report {
    let mut sections = vec![compared::setting(r)];
    sections.extend(compared::histories(r));
    sections.extend(compared::agreement(r));
    sections.extend([
        nuisance(r),
        noise_floor(r),
        detection(r, geometry),
        candidates::attribution(r),
        candidates::selection(r),
    ]);
    sections.extend(unattributed(r));
    sections.push(before_after(r));
    sections.push(parameters(r));
    sections.extend(candidates::appendix(r));
    sections.extend(provenance.map(Provenance::section));
    Report {
        title: format!("Closed loop: {}", r.model),
        lead: lead(r),
        sections,
    }
}

/// The verdict, the relative L2 errors of the three models and how the test was prepared.
fn lead(r: &LoopResult) -> Vec<String> {
    let mut lead = vec![verdict(r)];
    let e = &r.errors.calibration;
    lead.push(format!(
        "Relative L2 on the calibration test: nominal {}, calibrated {}, enriched {}.",
        f(e.nominal),
        f(e.calibrated),
        f(e.enriched)
    ));
    if let Some(h) = &r.errors.holdout {
        lead.push(format!(
            "On the holdout test (never fitted): nominal {}, calibrated {}, enriched {}.",
            f(h.nominal),
            f(h.calibrated),
            f(h.enriched)
        ));
    }
    lead.push(format!("{}.", r.test_preparation.describe()));
    lead
}

/// The verdict in one sentence.
fn verdict(r: &LoopResult) -> String {
    match r.verdict {
        Verdict::NoModelFormError => format!(
            "No model-form error: the calibrated model explains the test to its noise floor \
             (chi2_red {} <= {}).",
            f(r.detection.chi2_red),
            f(r.detection.threshold)
        ),
        Verdict::Attributed => format!(
            "Model-form error found and attributed: added {}.",
            r.added
                .iter()
                .map(|a| format!(
                    "{} = {} [{}, {}]",
                    a.name,
                    f(a.value),
                    f(a.lower),
                    f(a.upper)
                ))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        Verdict::Unattributed => format!(
            "Unattributed model-form error remains (chi2_red {} > {}): no candidate explains \
             it{}.",
            f(r.detection_final.chi2_red),
            f(r.detection_final.threshold),
            if r.added.is_empty() {
                String::new()
            } else {
                format!(
                    " after adding {}",
                    r.added
                        .iter()
                        .map(|a| a.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            }
        ),
    }
}

/// The trigger offset, the gains and biases per channel and any units warning.
fn nuisance(r: &LoopResult) -> Section {
    let n = &r.nuisance;
    let mut blocks = vec![Block::Paragraph(format!(
        "Trigger offset tau = {} s (a test triggered late has tau > 0). Gains and biases per \
         channel map the model onto the test: test = g model(t - tau) + b. They are never \
         attributed to physics.",
        f(n.time_shift)
    ))];
    blocks.push(table(
        "Nuisance terms",
        &["channel", "gain", &format!("bias ({})", unit_of(r))],
        n.gains
            .iter()
            .map(|(l, g)| {
                vec![
                    l.clone(),
                    f(*g),
                    f(n.biases.get(l).copied().unwrap_or(f64::NAN)),
                ]
            })
            .collect(),
    ));
    for u in &n.units_flags {
        blocks.push(Block::Paragraph(format!(
            "Units warning: channel {} has gain {}, near {} ({}).",
            u.channel,
            f(u.gain),
            f(u.factor),
            u.meaning
        )));
    }
    Section {
        heading: "Nuisance terms".into(),
        blocks,
    }
}

/// The measurement noise per channel and the model's own simulation noise.
fn noise_floor(r: &LoopResult) -> Section {
    Section {
        heading: "Noise floor".into(),
        blocks: vec![table(
            "Measurement noise per channel and the model's own simulation noise",
            &[
                "channel",
                &format!("noise sigma ({})", unit_of(r)),
                "source",
                "lag-1 correlation",
                "AR order",
                &format!("model's own noise RMS ({})", unit_of(r)),
            ],
            r.noise_floor
                .channels
                .iter()
                .map(|c| {
                    vec![
                        c.label.clone(),
                        f(c.sigma),
                        c.source.describe().to_string(),
                        f(c.lag1),
                        c.ar.len().to_string(),
                        f(c.simulation_rms),
                    ]
                })
                .collect(),
        )],
    }
}

/// Detection before and after enrichment with the residual's sensor pattern (on the
/// structure where `geometry` places the channels, else as a map over the channels) and
/// its time pattern.
fn detection(r: &LoopResult, geometry: Option<&Geometry>) -> Section {
    let (d0, d1) = (&r.detection, &r.detection_final);
    let row = |name: &str, a: String, b: String| vec![name.to_string(), a, b];
    let labels: Vec<String> = d0.u1.keys().cloned().collect();
    let mut blocks = vec![table(
        "Detection on the calibrated model's residual, before and after enrichment",
        &["statistic", "calibrated", "enriched"],
        vec![
            row("reduced chi-square", f(d0.chi2_red), f(d1.chi2_red)),
            row("its threshold", f(d0.threshold), f(d1.threshold)),
            row("samples", d0.n.to_string(), d1.n.to_string()),
            row(
                "largest singular value (noise units)",
                f(d0.sigma1),
                f(d1.sigma1),
            ),
            row(
                "noise edge (noise units)",
                f(d0.noise_edge),
                f(d1.noise_edge),
            ),
            row("Ljung-Box Q", f(d0.ljung_box), f(d1.ljung_box)),
            row(
                "model-form error",
                d0.model_form_error.to_string(),
                d1.model_form_error.to_string(),
            ),
        ],
    )];
    match geometry.filter(|g| labels.iter().all(|l| g.channels.contains_key(l))) {
        Some(g) => {
            for (name, when, d) in [("before", "before", d0), ("after", "after", d1)] {
                blocks.push(Block::Figure(Figure {
                    name: format!("fig-residual-structure-{name}"),
                    caption: format!(
                        "Sensor pattern u1 of the residual {when} enrichment on the structure \
                         (largest singular value {} noise units; signed: blue negative, red \
                         positive)",
                        f(d.sigma1)
                    ),
                    plot: Plot::Structure(Structure {
                        points: g.points.clone(),
                        unit: g.unit.clone(),
                        marked: labels
                            .iter()
                            .map(|l| Marker {
                                label: l.clone(),
                                at: g.channels[l],
                                value: Some(d.u1.get(l).copied().unwrap_or(0.0)),
                            })
                            .collect(),
                        value_axis: Axis::new("u_1 entry (-)"),
                        limit: None,
                    }),
                }));
            }
        }
        None => blocks.push(sensor_map(r, &labels)),
    }
    blocks.push(Block::Figure(Figure {
        name: "fig-residual-time".into(),
        caption: "Time pattern v1 of the residual, scaled by its singular value, before and \
                  after enrichment"
            .into(),
        plot: Plot::Lines(Lines {
            x: (0..d0.v1.len())
                .map(|k| r.start + k as f64 * r.time_step)
                .collect(),
            x_axis: Axis::new("time (s)"),
            y_axis: Axis::new("sigma_1 v_1 (noise units)"),
            series: vec![
                Series::new("before", d0.v1.iter().map(|v| v * d0.sigma1).collect()),
                Series::new("after", d1.v1.iter().map(|v| v * d1.sigma1).collect()),
            ],
        }),
    }));
    Section {
        heading: "Detection".into(),
        blocks,
    }
}

/// The residual's sensor pattern before and after as a map over the channels (no geometry
/// places them): signed, on the diverging scale; values written in the cells up to 12
/// channels.
fn sensor_map(r: &LoopResult, labels: &[String]) -> Block {
    let (d0, d1) = (&r.detection, &r.detection_final);
    Block::Figure(Figure {
        name: "fig-residual-sensors".into(),
        caption: format!(
            "Sensor pattern u1 of the residual before (top row) and after (bottom row) \
             enrichment, signed (blue negative, red positive); columns are the channels {}",
            labels.join(", ")
        ),
        plot: Plot::HeatMap(HeatMap {
            values: vec![
                labels.iter().map(|l| d0.u1[l]).collect(),
                labels
                    .iter()
                    .map(|l| d1.u1.get(l).copied().unwrap_or(0.0))
                    .collect(),
            ],
            range: (-1.0, 1.0),
            row_axis: Axis::new("residual (before, after)"),
            column_axis: Axis::new(format!("channel, 1 to {}", labels.len())),
            row_weights: vec![d0.sigma1, d1.sigma1],
            column_weights: Vec::new(),
            row_weights_axis: Axis::new("sigma_1 (noise units)"),
            column_weights_axis: Axis::new("-"),
            marked: Vec::new(),
            annotate: labels.len() <= 12,
        }),
    })
}

/// The low-rank signature of the error no candidate explains, when there is one.
fn unattributed(r: &LoopResult) -> Option<Section> {
    r.unattributed.as_ref().map(|d| Section {
        heading: "Unattributed model-form error".into(),
        blocks: vec![
            Block::Paragraph(format!(
                "A low-rank discrepancy carries {} of the residual. It describes what the \
                     model lacks (where and when); it is not a physical effect.",
                f(d.energy_fraction)
            )),
            table(
                "Sensor signature of each component",
                &["component", "sigma", "sensors"],
                d.components
                    .iter()
                    .enumerate()
                    .map(|(i, c)| {
                        vec![
                            (i + 1).to_string(),
                            f(c.sigma),
                            c.sensors
                                .iter()
                                .map(|(l, v)| format!("{l} {}", f(*v)))
                                .collect::<Vec<_>>()
                                .join(", "),
                        ]
                    })
                    .collect(),
            ),
        ],
    })
}

/// The before/after metrics on the calibration test and the holdout.
fn before_after(r: &LoopResult) -> Section {
    let mut blocks = vec![stages_table("Calibration test", &r.metrics_calibration)];
    if let Some(h) = &r.metrics_holdout {
        blocks.push(stages_table("Holdout test (never fitted)", h));
    }
    blocks.push(Block::Paragraph(format!(
        "M1 exceedance: the fraction of samples at which the test's norm over the channels \
         leaves the envelope of {} predictive draws of the model (its linearised parameter \
         uncertainty where the loop fitted it, and the noise floor; no extra runs), observed \
         against the {} of the samples at which a draw of the ensemble leaves it (expected); \
         the probability that a draw leaves it at least as often (the study's beta-binomial \
         over effective samples), below {} when the model cannot explain the test. M2: \
         impact shapes of model and test paired above 0.9. {} true-model runs in all.",
        r.m1_members,
        f(2.0 / (r.m1_members as f64 + 1.0)),
        f(1.0 / (r.m1_members as f64 + 1.0)),
        r.runs
    )));
    Section {
        heading: "Before and after".into(),
        blocks,
    }
}

fn stages_table(caption: &str, s: &Stages<Errors>) -> Block {
    let row = |name: &str, g: fn(&Errors) -> f64| {
        vec![
            name.to_string(),
            f(g(&s.nominal)),
            f(g(&s.calibrated)),
            f(g(&s.enriched)),
        ]
    };
    table(
        caption,
        &["metric", "nominal", "calibrated", "enriched"],
        vec![
            row("relative L2", |e| e.rel_l2),
            row("chi2_red", |e| e.chi2_red),
            row("Sprague-Geers C", |e| e.sprague_geers_c),
            row("ISO/TS 18571 R", |e| e.iso18571_r),
            row("M1 exceedance (observed)", |e| e.m1_exceedance),
            row("M1 exceedance (expected)", |e| e.m1_expected),
            row("M1 probability", |e| e.m1_probability),
            vec![
                "M2 pairs above 0.9".to_string(),
                m2(&s.nominal),
                m2(&s.calibrated),
                m2(&s.enriched),
            ],
        ],
    )
}

/// `k of n` shapes paired above 0.9, or `-` when the shapes could not be formed.
fn m2(e: &Errors) -> String {
    e.m2_above_0_9
        .map_or_else(|| "-".into(), |k| format!("{k} of {}", e.m2_shapes))
}

/// The calibrated parameters with their range and nominal value; a value within 0.1 % of
/// the range's width from a bound is flagged: the data pushed it there, and the optimum may
/// lie beyond.
fn parameters(r: &LoopResult) -> Section {
    let rows = r
        .parameters
        .iter()
        .map(|p| {
            let v = r.calibrated.get(&p.name).copied().unwrap_or(f64::NAN);
            let flag = crate::report::bound_flag(p, v);
            vec![
                p.name.clone(),
                if p.unit.is_empty() {
                    "-".into()
                } else {
                    p.unit.clone()
                },
                f(p.lower),
                f(p.upper),
                f(p.nominal),
                f(v),
                flag.to_string(),
            ]
        })
        .collect();
    Section {
        heading: "Parameters".into(),
        blocks: vec![table(
            "The final model's parameters (declared, then added)",
            &[
                "parameter",
                "unit",
                "lower bound",
                "upper bound",
                "nominal",
                "calibrated",
                "bound",
            ],
            rows,
        )],
    }
}
