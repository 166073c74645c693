//! The sections of the loop's report that show what was compared and how well each model
//! matches: the setting (model, window, filter, channels, holdout), the test against the
//! three models on the channels that matter most, and the M1 envelopes and M2 matrices.

use crate::report::{Axis, Block, Envelope, Figure, HeatMap, Lines, Plot, Section, Series};
use crate::study::m2::M2Result;

use super::super::result::{Evidence, LoopResult, Stages};
use super::{f, unit_of};

/// Model, window, filter, compared channels and the holdout's condition, in words.
pub(super) fn setting(r: &LoopResult) -> Section {
    let samples = r
        .metrics_calibration
        .enriched
        .evidence
        .as_ref()
        .map_or(0, |e| e.m1.time.len());
    let end = r.start + samples.saturating_sub(1) as f64 * r.time_step;
    let filter = r
        .cfc
        .map_or("no filter".to_string(), |c| format!("CFC {c} (SAE J211)"));
    let holdout = if r.holdout_condition.is_empty() {
        "No holdout test was given.".to_string()
    } else {
        format!(
            "The holdout test was taken at {} and is never fitted: its trigger offset and \
             biases are profiled, its gains are the calibration test's.",
            r.holdout_condition
                .iter()
                .map(|(n, v)| format!("{n} = {}{}", f(*v), unit_suffix(r, n)))
                .collect::<Vec<_>>()
                .join(", ")
        )
    };
    Section {
        heading: "What was compared".into(),
        blocks: vec![
            Block::Paragraph(format!(
                "Model: {}. Window: {} s to {} s, {} samples {} s apart. Filter: {}, applied \
                 to test and runs alike. {} channels compared, in {}: {}. {} The measurement \
                 noise per channel, with its source, is in the section Noise floor.",
                r.model,
                f(r.start),
                f(end),
                samples,
                f(r.time_step),
                filter,
                r.channels.len(),
                unit_of(r),
                r.channels.join(", "),
                holdout
            )),
            Block::Paragraph(format!(
                "Parameters: {}.",
                r.parameters
                    .iter()
                    .map(|p| format!(
                        "{} in [{}, {}]{}",
                        p.name,
                        f(p.lower),
                        f(p.upper),
                        if p.unit.is_empty() {
                            String::new()
                        } else {
                            format!(" {}", p.unit)
                        }
                    ))
                    .collect::<Vec<_>>()
                    .join(", ")
            )),
        ],
    }
}

/// ` unit` of parameter or candidate `name`, or nothing.
fn unit_suffix(r: &LoopResult, name: &str) -> String {
    r.parameters
        .iter()
        .find(|p| p.name == name)
        .map(|p| p.unit.clone())
        .or_else(|| r.catalogue.get(name).map(|c| c.unit.clone()))
        .filter(|u| !u.is_empty())
        .map_or_else(String::new, |u| format!(" {u}"))
}

/// Root mean square of `a - b` over channel `s` of `T = a.len() / channels` samples, in
/// units of that channel's noise `sigma` (1 when the noise is not known).
fn rms_of(a: &[f64], b: &[f64], s: usize, t: usize, sigma: f64) -> f64 {
    let ss: f64 = (s * t..(s + 1) * t).map(|i| (a[i] - b[i]).powi(2)).sum();
    (ss / t as f64).sqrt() / if sigma > 0.0 { sigma } else { 1.0 }
}

/// Index of the channel with the largest `key`, skipping `skip`.
fn largest(n: usize, key: impl Fn(usize) -> f64, skip: &[usize]) -> Option<usize> {
    (0..n)
        .filter(|s| !skip.contains(s))
        .max_by(|&a, &b| key(a).total_cmp(&key(b)))
}

/// The test against the nominal, calibrated and enriched models on the channel with the
/// largest residual of the calibrated model, the channel the enrichment changed most and
/// the holdout's channel with the largest calibrated residual; each residual and change
/// measured in units of the channel's noise.
pub(super) fn histories(r: &LoopResult) -> Option<Section> {
    let cal = evidence(&r.metrics_calibration)?;
    let n = r.channels.len();
    let t = cal.2.test.len() / n.max(1);
    if n == 0 || t == 0 {
        return None;
    }
    let sigma = |s: usize| {
        r.noise_floor
            .channels
            .iter()
            .find(|c| c.label == r.channels[s])
            .map_or(1.0, |c| c.sigma)
    };
    let residual = largest(
        n,
        |s| rms_of(&cal.1.test, &cal.1.model, s, t, sigma(s)),
        &[],
    )?;
    let change = largest(
        n,
        |s| rms_of(&cal.2.model, &cal.1.model, s, t, sigma(s)),
        &[residual],
    );
    let mut blocks = vec![Block::Paragraph(
        "Each figure shows one channel: the test (black, the enriched model's trigger \
         offset, gain and bias taken out) and the three models' responses after the filter. \
         Residuals and changes are measured in units of the channel's noise."
            .into(),
    )];
    let what = format!(
        "largest residual of the calibrated model ({} noise sigma RMS)",
        f(rms_of(
            &cal.1.test,
            &cal.1.model,
            residual,
            t,
            sigma(residual)
        ))
    );
    blocks.push(channel_figure(
        r,
        "fig-channel-residual",
        &cal,
        residual,
        &what,
        "calibration test",
    ));
    if let Some(c) = change {
        let what = format!(
            "largest change from calibrated to enriched ({} noise sigma RMS)",
            f(rms_of(&cal.2.model, &cal.1.model, c, t, sigma(c)))
        );
        blocks.push(channel_figure(
            r,
            "fig-channel-change",
            &cal,
            c,
            &what,
            "calibration test",
        ));
    }
    if let Some(h) = r.metrics_holdout.as_ref().and_then(evidence) {
        let th = h.1.test.len() / n;
        if th > 0
            && let Some(s) = largest(n, |s| rms_of(&h.1.test, &h.1.model, s, th, sigma(s)), &[])
        {
            blocks.push(channel_figure(
                r,
                "fig-channel-holdout",
                &h,
                s,
                "largest residual of the calibrated model on the holdout",
                "holdout test (never fitted)",
            ));
        }
    }
    Some(Section {
        heading: "Test against model".into(),
        blocks,
    })
}

/// The evidence of the three models, when the loop kept it.
fn evidence(s: &Stages<crate::closeloop::Errors>) -> Option<(&Evidence, &Evidence, &Evidence)> {
    Some((
        s.nominal.evidence.as_deref()?,
        s.calibrated.evidence.as_deref()?,
        s.enriched.evidence.as_deref()?,
    ))
}

/// One channel's test and the three models' responses.
fn channel_figure(
    r: &LoopResult,
    name: &str,
    (nom, cal, enr): &(&Evidence, &Evidence, &Evidence),
    s: usize,
    why: &str,
    test: &str,
) -> Block {
    let t = enr.test.len() / r.channels.len();
    let x: Vec<f64> = (0..t).map(|k| r.start + k as f64 * r.time_step).collect();
    let part = |v: &[f64]| v[s * t..(s + 1) * t].to_vec();
    Block::Figure(Figure {
        name: name.into(),
        caption: format!("Channel {} on the {test}: {why}", r.channels[s]),
        plot: Plot::Lines(Lines {
            x,
            x_axis: Axis::new("time (s)"),
            y_axis: Axis::new(format!("{} ({})", r.channels[s], unit_of(r))),
            series: vec![
                Series::new("test", part(&enr.test)),
                Series::new("nominal", part(&nom.model)),
                Series::new("calibrated", part(&cal.model)),
                Series::new("enriched", part(&enr.model)),
            ],
        }),
    })
}

/// M1 envelopes and M2 matrices of the three models on the calibration test.
pub(super) fn agreement(r: &LoopResult) -> Option<Section> {
    let (nom, cal, enr) = evidence(&r.metrics_calibration)?;
    let mut blocks = vec![Block::Paragraph(format!(
        "M1: the norm Q(t) over the {} compared channels; the band is the envelope of {} \
         predictive draws of each model (its linearised parameter uncertainty where the loop \
         fitted it, and the noise floor), the black curve the test's Q_e(t), shaded where it \
         leaves the band. M2: the modal assurance of each model's impact shapes (rows) \
         against the test's (columns), the optimal pairing outlined, each shape's share of \
         its response in % beside it.",
        r.channels.len(),
        r.m1_members
    ))];
    for (stage, e) in [("nominal", nom), ("calibrated", cal), ("enriched", enr)] {
        blocks.push(Block::Figure(Figure {
            name: format!("fig-m1-{stage}"),
            caption: format!(
                "M1 of the {stage} model: the test leaves the band at {} of the samples \
                 ({} expected of a right model)",
                f(e.m1.exceedance_fraction),
                f(e.m1.expected_exceedance)
            ),
            plot: Plot::Envelope(Envelope {
                x: e.m1.time.iter().map(|t| r.start + t).collect(),
                x_axis: Axis::new("time (s)"),
                y_axis: Axis::new(format!("Q, norm over the channels ({})", unit_of(r))),
                band_name: format!("{stage} model, {} draws", e.m1.n_runs),
                lower: e.m1.lower.clone(),
                upper: e.m1.upper.clone(),
                series: vec![Series::new("test", e.m1.test.clone())],
                marked: e
                    .m1
                    .intervals
                    .iter()
                    .map(|i| (r.start + i[0], r.start + i[1]))
                    .collect(),
            }),
        }));
    }
    for (stage, e) in [("nominal", nom), ("calibrated", cal), ("enriched", enr)] {
        if let Some(m) = &e.m2 {
            blocks.push(Block::Figure(Figure {
                name: format!("fig-m2-{stage}"),
                caption: format!(
                    "M2 of the {stage} model: {} of {} shape pairs above 0.9",
                    m.matched_above_0_9,
                    m.pairs.len()
                ),
                plot: m2_plot(m, stage),
            }));
        }
    }
    Some(Section {
        heading: "M1 and M2 of the three models".into(),
        blocks,
    })
}

/// The M2 matrix as a heat map with each side's shape contributions in %.
fn m2_plot(m: &M2Result, stage: &str) -> Plot {
    Plot::HeatMap(HeatMap {
        values: m.matrix.clone(),
        range: (0.0, 1.0),
        row_axis: Axis::new(format!("{stage} model shape")),
        column_axis: Axis::new("test shape"),
        row_weights: m.model_contributions.iter().map(|c| 100.0 * c).collect(),
        column_weights: m.test_contributions.iter().map(|c| 100.0 * c).collect(),
        row_weights_axis: Axis::new("contribution (%)"),
        column_weights_axis: Axis::new("contribution (%)"),
        marked: m.pairs.iter().map(|p| (p.0, p.1)).collect(),
        annotate: m.matrix.len() <= 12,
    })
}
