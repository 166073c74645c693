//! The bar engineer's section of a closed loop's report on a Kolsky bar test
//! (`[model] kind = "kolsky-bar"`): the measured and modelled waves before and after
//! enrichment, the residual's spectrum before and after, the classic stress-strain curve
//! beside the calibrated model's, and the added effects with their intervals.
//!
//! Everything is drawn from the loop's result (its evidence: each stage's test under that
//! stage's own trigger offset and biases, and the model's response) and from the bar model
//! itself (the classic three-wave analysis of the test, and the specimen's stress and strain
//! at the calibrated points). With more than one effect added, the spectrum after is the
//! last model's: the loop keeps the responses of the declared and the final models.

use impactcal_calibrate::closeloop::{Evidence, LoopResult};
use impactcal_calibrate::report::{Axis, Block, Figure, Lines, Plot, Section, Series, Table};
use impactcal_core::{Enrichable, Model, Parameter};
use impactcal_models::kolsky::{ClassicAnalysis, KolskyModel};

use crate::error::Result;

/// The frequency bands (Hz) of the residual's energy table: the ringing of the first
/// Pochhammer-Chree mode sits in 100-200 kHz on a 10 mm bar.
pub const BANDS: [f64; 6] = [0.0, 20e3, 50e3, 100e3, 200e3, f64::INFINITY];

/// Points of the stress-strain figure's common strain axis.
const CURVE_POINTS: usize = 200;

/// The one-sided amplitude spectrum of `x` sampled at `dt`: frequencies `m / (T dt)` for
/// `m = 0 .. T / 2` and amplitudes `|X_m| / T` (doubled strictly between 0 and the Nyquist
/// frequency, so that a sinusoid of amplitude `a` on a bin reads `a`),
/// `X_m = sum_k x_k exp(-2 pi i m k / T)` (a plain DFT: a record is a few thousand
/// samples). Parseval: `sum_k x_k^2 = T (a_0^2 + sum_(0<m<T/2) a_m^2 / 2 + a_(T/2)^2)`,
/// the last term for an even `T` only.
pub fn amplitude_spectrum(x: &[f64], dt: f64) -> (Vec<f64>, Vec<f64>) {
    let t = x.len();
    if t == 0 {
        return (Vec::new(), Vec::new());
    }
    let (mut freq, mut amp) = (Vec::new(), Vec::new());
    for m in 0..=t / 2 {
        let (mut re, mut im) = (0.0, 0.0);
        for (k, v) in x.iter().enumerate() {
            let w = -2.0 * std::f64::consts::PI * ((m * k) % t) as f64 / t as f64;
            re += v * w.cos();
            im += v * w.sin();
        }
        let scale = if m == 0 || 2 * m == t { 1.0 } else { 2.0 };
        freq.push(m as f64 / (t as f64 * dt));
        amp.push(scale * (re * re + im * im).sqrt() / t as f64);
    }
    (freq, amp)
}

/// The share of the spectrum's energy (`amp^2`, the mean left out) in each band of
/// [`BANDS`]; zeros for a spectrum without energy.
pub fn band_shares(freq: &[f64], amp: &[f64]) -> Vec<f64> {
    let mut e = vec![0.0; BANDS.len() - 1];
    for (f, a) in freq.iter().zip(amp).skip(1) {
        if let Some(b) = BANDS.windows(2).position(|w| w[0] <= *f && *f < w[1]) {
            e[b] += a * a;
        }
    }
    let total: f64 = e.iter().sum();
    if total > 0.0 {
        e.iter_mut().for_each(|v| *v /= total);
    }
    e
}

/// Channel `s` of a stage's evidence: the test and the model, `T` samples each.
fn wave(e: &Evidence, s: usize, channels: usize) -> (&[f64], &[f64]) {
    let t = e.test.len() / channels.max(1);
    (&e.test[s * t..(s + 1) * t], &e.model[s * t..(s + 1) * t])
}

/// The residual `test - model` of wave `s` of a stage's evidence.
pub fn residual(e: &Evidence, s: usize, channels: usize) -> Vec<f64> {
    let (test, model) = wave(e, s, channels);
    test.iter().zip(model).map(|(a, b)| a - b).collect()
}

/// `y(x)` of the loading branch `(xs, ys)` (up to its largest `x`, the running maximum
/// keeping it monotone) at `x`, linearly; `None` beyond the branch.
fn on_branch(xs: &[f64], ys: &[f64], x: f64) -> Option<f64> {
    let end = xs
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map_or(0, |(i, _)| i);
    let mut prev: Option<(f64, f64)> = None;
    let mut top = f64::NEG_INFINITY;
    for i in 0..=end.min(xs.len().saturating_sub(1)) {
        if xs[i] <= top {
            continue;
        }
        top = xs[i];
        if let Some((x0, y0)) = prev
            && x0 <= x
            && x <= xs[i]
        {
            let f = (x - x0) / (xs[i] - x0);
            return Some(y0 + f * (ys[i] - y0));
        }
        prev = Some((xs[i], ys[i]));
    }
    None
}

/// The model of `base` with the loop's `added` candidates, and its point from the loop's
/// calibrated `values` (by name).
fn at_values(
    base: &KolskyModel,
    added: &[String],
    values: &std::collections::BTreeMap<String, f64>,
) -> Result<(KolskyModel, Vec<f64>)> {
    let params: Vec<Parameter> = added
        .iter()
        .filter_map(|n| {
            base.candidates()
                .into_iter()
                .find(|c| c.name() == n)
                .map(|c| c.parameter)
        })
        .collect();
    let m = base.enrich(&params)?;
    let p = m
        .space()
        .parameters()
        .iter()
        .map(|p| values.get(&p.name).copied().unwrap_or(p.nominal))
        .collect();
    Ok((m, p))
}

/// The specimen's true stress-strain curves on a common strain axis: the classic
/// three-wave analysis of the test, the plain calibrated model and the enriched one, from
/// the largest of their first strains (zero where a branch starts below) to the smallest of
/// their largest loading strains. Returns the strains and the three stresses (MPa).
///
/// # Errors
/// The classic analysis' errors and the model's at the calibrated points.
pub fn stress_strain(base: &KolskyModel, r: &LoopResult) -> Result<(Vec<f64>, [Vec<f64>; 3])> {
    let classic = ClassicAnalysis::of(base.test())?;
    let (ce, cs) = classic.true_curve();
    let plain = r
        .rounds
        .first()
        .map_or_else(|| r.calibrated.clone(), |round| round.calibrated.clone());
    let (m0, p0) = at_values(base, &[], &plain)?;
    let added: Vec<String> = r.added.iter().map(|a| a.name.clone()).collect();
    let (m1, p1) = at_values(base, &added, &r.calibrated)?;
    let f0 = m0.faces(&p0)?;
    let f1 = m1.faces(&p1)?;
    let top = |x: &[f64]| x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let first = |x: &[f64]| x.first().copied().unwrap_or(0.0).max(0.0);
    let hi = top(&ce).min(top(&f0.strain)).min(top(&f1.strain));
    let lo = first(&ce).max(first(&f0.strain)).max(first(&f1.strain));
    // `lo + (k / (N - 1)) (hi - lo)` ends on `hi` exactly: no point beyond a branch.
    let strain: Vec<f64> = (0..CURVE_POINTS)
        .map(|k| lo + (k as f64 / (CURVE_POINTS - 1) as f64) * (hi - lo))
        .collect();
    let on = |xs: &[f64], ys: &[f64]| -> Vec<f64> {
        strain
            .iter()
            .map(|&x| on_branch(xs, ys, x).map_or(f64::NAN, |y| y / 1e6))
            .collect()
    };
    Ok((
        strain.clone(),
        [
            on(&ce, &cs),
            on(&f0.strain, &f0.stress),
            on(&f1.strain, &f1.stress),
        ],
    ))
}

/// The bar engineer's section of the loop's report `r` on the bar model `base` (see the
/// module docs).
///
/// # Errors
/// As [`stress_strain`].
pub fn section(base: &KolskyModel, r: &LoopResult) -> Result<Section> {
    let n = r.channels.len();
    let mut blocks = vec![Block::Paragraph(
        "The bar test as a bar engineer reads it: each wave measured (black) against the \
         model before enrichment (the declared model calibrated) and after (with the added \
         effects), each stage under its own trigger offset and biases; the residual's \
         amplitude spectrum before and after, with its energy per band; the specimen's true \
         stress against true strain from the classic three-wave analysis of the record \
         beside the calibrated models'; the added effects with their 95 % intervals."
            .into(),
    )];
    let m = &r.metrics_calibration;
    let stages = [
        (
            "calibrated",
            "before enrichment",
            m.calibrated.evidence.as_deref(),
        ),
        (
            "enriched",
            "after enrichment",
            m.enriched.evidence.as_deref(),
        ),
    ];
    let us = |t: usize| -> Vec<f64> {
        (0..t)
            .map(|k| (r.start + k as f64 * r.time_step) * 1e6)
            .collect()
    };
    for (s, label) in r.channels.iter().enumerate() {
        for (stage, words, e) in stages {
            let Some(e) = e else { continue };
            let (test, model) = wave(e, s, n);
            blocks.push(Block::Figure(Figure {
                name: format!("fig-bar-{label}-{stage}"),
                caption: format!(
                    "The {label} wave, measured and modelled {words} (relative L2 {:.1} %)",
                    100.0 * rel_l2(test, model)
                ),
                plot: Plot::Lines(Lines {
                    x: us(test.len()),
                    x_axis: Axis::new("time (us)"),
                    y_axis: Axis::new(format!("{label} strain ({})", unit(r))),
                    series: vec![
                        Series::new("measured", test.to_vec()),
                        Series::new(format!("model, {stage}"), model.to_vec()),
                    ],
                }),
            }));
        }
    }
    let additions = if r.added.is_empty() {
        "nothing added".to_string()
    } else {
        format!(
            "+ {}",
            r.added
                .iter()
                .map(|a| a.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        )
    };
    let mut rows = Vec::new();
    for (s, label) in r.channels.iter().enumerate() {
        let mut series = Vec::new();
        let mut freq = Vec::new();
        for (stage, _, e) in stages {
            let Some(e) = e else { continue };
            let (f, a) = amplitude_spectrum(&residual(e, s, n), r.time_step);
            let shares = band_shares(&f, &a);
            let name = if stage == "calibrated" {
                "before (declared model)".to_string()
            } else {
                format!("after ({additions})")
            };
            let mut row = vec![label.clone(), name.clone()];
            row.extend(shares.iter().map(|v| format!("{:.0} %", 100.0 * v)));
            rows.push(row);
            freq = f.iter().map(|x| x / 1e3).collect();
            series.push(Series::new(name, a));
        }
        if series.is_empty() {
            continue;
        }
        blocks.push(Block::Figure(Figure {
            name: format!("fig-bar-spectrum-{label}"),
            caption: format!(
                "The {label} wave's residual (measured less modelled), its amplitude spectrum \
                 before enrichment and after every addition ({additions})"
            ),
            plot: Plot::Lines(Lines {
                x: freq,
                x_axis: Axis::new("frequency (kHz)"),
                y_axis: Axis::new(format!("residual amplitude ({})", unit(r))),
                series,
            }),
        }));
    }
    let mut header = vec!["wave".to_string(), "residual".to_string()];
    header.extend(BANDS.windows(2).map(|w| {
        if w[1].is_finite() {
            format!("{:.0}-{:.0} kHz", w[0] / 1e3, w[1] / 1e3)
        } else {
            format!("above {:.0} kHz", w[0] / 1e3)
        }
    }));
    blocks.push(Block::Table(Table {
        caption: "The residual's energy per frequency band (its mean left out)".into(),
        header,
        rows,
    }));
    let (strain, [classic, plain, enriched]) = stress_strain(base, r)?;
    blocks.push(Block::Figure(Figure {
        name: "fig-bar-stress-strain".into(),
        caption: "True stress against true strain of the specimen: the classic three-wave \
                  analysis of the record and the model calibrated before and after \
                  enrichment (loading branches)"
            .into(),
        plot: Plot::Lines(Lines {
            x: strain,
            x_axis: Axis::new("true strain"),
            y_axis: Axis::new("true stress (MPa)"),
            series: vec![
                Series::new("classic three-wave analysis", classic),
                Series::new("model, calibrated", plain),
                Series::new(format!("model, enriched ({additions})"), enriched),
            ],
        }),
    }));
    blocks.push(Block::Table(Table {
        caption: "The added effects, with their 95 % intervals".into(),
        header: ["effect", "value", "95 % interval", "unit", "what it is"]
            .iter()
            .map(|s| s.to_string())
            .collect(),
        rows: r
            .added
            .iter()
            .map(|a| {
                let info = r.catalogue.get(&a.name);
                vec![
                    a.name.clone(),
                    format!("{:.4}", a.value),
                    format!("[{:.4}, {:.4}]", a.lower, a.upper),
                    info.map_or(String::new(), |i| i.unit.clone()),
                    info.map_or(String::new(), |i| i.description.clone()),
                ]
            })
            .collect(),
    }));
    Ok(Section {
        heading: "The bar test".into(),
        blocks,
    })
}

/// `sqrt(sum (test - model)^2 / sum test^2)`.
fn rel_l2(test: &[f64], model: &[f64]) -> f64 {
    let num: f64 = test.iter().zip(model).map(|(a, b)| (a - b).powi(2)).sum();
    let den: f64 = test.iter().map(|a| a * a).sum();
    (num / den).sqrt()
}

fn unit(r: &LoopResult) -> &str {
    if r.unit.is_empty() { "1" } else { &r.unit }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sinusoid of amplitude 0.3 on bin 7 plus a mean of 0.1 reads 0.3 at 7 / (T dt)
    /// and 0.1 at 0; the spectrum carries the record's energy (Parseval, even and odd `T`);
    /// its energy lies in the band of 7 / (T dt).
    #[test]
    fn a_sinusoid_reads_its_amplitude_and_the_energy_is_kept() {
        for t in [64usize, 65] {
            let dt = 1e-6;
            let x: Vec<f64> = (0..t)
                .map(|k| 0.1 + 0.3 * (2.0 * std::f64::consts::PI * 7.0 * k as f64 / t as f64).cos())
                .collect();
            let (f, a) = amplitude_spectrum(&x, dt);
            assert_eq!(f.len(), t / 2 + 1);
            assert!(
                (a[0] - 0.1).abs() < 1e-12 && (a[7] - 0.3).abs() < 1e-12,
                "{a:?}"
            );
            assert!((f[7] - 7.0 / (t as f64 * dt)).abs() < 1e-6);
            let energy: f64 = x.iter().map(|v| v * v).sum();
            let parseval: f64 = (0..a.len())
                .map(|m| {
                    if m == 0 || 2 * m == t {
                        a[m] * a[m]
                    } else {
                        a[m] * a[m] / 2.0
                    }
                })
                .sum::<f64>()
                * t as f64;
            assert!(
                (energy - parseval).abs() < 1e-9 * energy,
                "{energy} {parseval}"
            );
            let shares = band_shares(&f, &a);
            let band = BANDS
                .windows(2)
                .position(|w| w[0] <= f[7] && f[7] < w[1])
                .unwrap();
            assert!((shares[band] - 1.0).abs() < 1e-12, "{shares:?}");
        }
    }

    /// A loading branch is read between its samples linearly, up to its largest abscissa
    /// only (the unloading after it is left out), and not beyond.
    #[test]
    fn a_loading_branch_is_interpolated_up_to_its_peak() {
        let xs = [0.0, 0.1, 0.2, 0.3, 0.25];
        let ys = [0.0, 10.0, 20.0, 40.0, 5.0];
        assert_eq!(on_branch(&xs, &ys, 0.15), Some(15.0));
        assert!((on_branch(&xs, &ys, 0.28).unwrap() - 36.0).abs() < 1e-9);
        assert_eq!(on_branch(&xs, &ys, 0.31), None);
    }
}
