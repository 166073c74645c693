//! The report of a closed loop: the verdict in short, then the nuisance terms, the noise
//! floor, detection before and after with the residual's sensor pattern `u_1` (a map over
//! the channels) and time pattern `v_1`, the ranked candidates, the selection with its
//! information criteria, the unattributed error when there is one, and the errors before
//! and after on the calibration test and the holdout.

use crate::report::{Axis, Block, Figure, HeatMap, Lines, Plot, Report, Section, Series, Table};

use super::result::{Errors, LoopResult, Stages, Verdict};

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

/// The report document of `r`: the lead (verdict and errors in short), then one section per
/// stage of the loop (`nuisance`, `noise_floor`, `detection`, `attribution`, `selection`,
/// `unattributed` when error remains, `before_after`).
pub fn report(r: &LoopResult) -> Report {
    let mut sections = vec![
        nuisance(r),
        noise_floor(r),
        detection(r),
        attribution(r),
        selection(r),
    ];
    sections.extend(unattributed(r));
    sections.push(before_after(r));
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
        &["channel", "gain", "bias"],
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
                "sigma",
                "source",
                "lag-1",
                "AR order",
                "simulation RMS",
            ],
            r.noise_floor
                .channels
                .iter()
                .map(|c| {
                    vec![
                        c.label.clone(),
                        f(c.sigma),
                        format!("{:?}", c.source),
                        f(c.lag1),
                        c.ar.len().to_string(),
                        f(c.simulation_rms),
                    ]
                })
                .collect(),
        )],
    }
}

/// Detection before and after enrichment with the residual's sensor and time patterns.
fn detection(r: &LoopResult) -> Section {
    let (dt, start) = (r.time_step, r.start);
    let (d0, d1) = (&r.detection, &r.detection_final);
    let row = |name: &str, a: String, b: String| vec![name.to_string(), a, b];
    let labels: Vec<String> = d0.u1.keys().cloned().collect();
    let time: Vec<f64> = (0..d0.v1.len()).map(|k| start + k as f64 * dt).collect();
    Section {
        heading: "Detection".into(),
        blocks: vec![
            table(
                "Detection on the calibrated model's residual, before and after enrichment",
                &["statistic", "calibrated", "enriched"],
                vec![
                    row("chi2_red", f(d0.chi2_red), f(d1.chi2_red)),
                    row("threshold", f(d0.threshold), f(d1.threshold)),
                    row("samples", d0.n.to_string(), d1.n.to_string()),
                    row("sigma_1", f(d0.sigma1), f(d1.sigma1)),
                    row("noise edge", f(d0.noise_edge), f(d1.noise_edge)),
                    row("Ljung-Box Q", f(d0.ljung_box), f(d1.ljung_box)),
                    row(
                        "model-form error",
                        d0.model_form_error.to_string(),
                        d1.model_form_error.to_string(),
                    ),
                ],
            ),
            Block::Figure(Figure {
                name: "fig-residual-sensors".into(),
                caption: format!(
                    "Sensor pattern u1 of the residual before (top row) and after (bottom \
                     row) enrichment, channels {}",
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
                    column_axis: Axis::new(format!("channel ({})", labels.join(", "))),
                    row_weights: vec![d0.sigma1, d1.sigma1],
                    column_weights: Vec::new(),
                    marked: Vec::new(),
                    annotate: true,
                }),
            }),
            Block::Figure(Figure {
                name: "fig-residual-time".into(),
                caption: "Time pattern v1 of the residual, scaled by sigma_1, before and after"
                    .into(),
                plot: Plot::Lines(Lines {
                    x: time,
                    x_axis: Axis::new("time (s)"),
                    y_axis: Axis::new("sigma_1 v_1 (noise units)"),
                    series: vec![
                        Series::new("before", d0.v1.iter().map(|v| v * d0.sigma1).collect()),
                        Series::new("after", d1.v1.iter().map(|v| v * d1.sigma1).collect()),
                    ],
                }),
            }),
        ],
    }
}

/// The ranked candidates and the pairs these sensors cannot tell apart.
fn attribution(r: &LoopResult) -> Section {
    let mut blocks = vec![table(
        "Candidates ranked on the calibrated model's residual",
        &[
            "name",
            "kind",
            "kappa",
            "explained",
            "score",
            "amplitude [95 %]",
            "status",
        ],
        r.candidates
            .iter()
            .map(|c| {
                vec![
                    c.name.clone(),
                    c.kind.clone(),
                    f(c.kappa),
                    f(c.explained_fraction),
                    f(c.score),
                    c.amplitude.as_ref().map_or("-".into(), |a| {
                        format!("{} [{}, {}]", f(a.value), f(a.lower), f(a.upper))
                    }),
                    c.status.clone(),
                ]
            })
            .collect(),
    )];
    for (a, b, mu) in &r.indistinguishable {
        blocks.push(Block::Paragraph(format!(
            "{a} and {b} are indistinguishable with these sensors (coherence {}): a new \
             sensor or test condition is needed to tell them apart.",
            f(*mu)
        )));
    }
    Section {
        heading: "Attribution".into(),
        blocks,
    }
}

/// The models of forward selection with their information criteria.
fn selection(r: &LoopResult) -> Section {
    Section {
        heading: "Forward selection".into(),
        blocks: vec![
            table(
                "Models of the sequence",
                &["added", "k", "RSS", "AIC", "BIC", "Akaike weight", "kept"],
                r.models
                    .iter()
                    .map(|m| {
                        vec![
                            if m.added.is_empty() {
                                "-".into()
                            } else {
                                m.added.join(", ")
                            },
                            m.k.to_string(),
                            f(m.rss),
                            f(m.aic),
                            f(m.bic),
                            f(m.akaike_weight),
                            m.kept.to_string(),
                        ]
                    })
                    .collect(),
            ),
            Block::Paragraph(format!("Stopped: {}.", r.stopped)),
        ],
    }
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
