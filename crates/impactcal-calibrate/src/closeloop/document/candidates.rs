//! The sections of the loop's report on candidates: the ranking (the first ten in the body,
//! the rest in an appendix), every addition tried with the loop's decision, and the
//! parameters with those that ended at a bound flagged.

use crate::report::{Block, Section};

use super::super::attribution::Score;
use super::super::result::LoopResult;
use super::{f, table};

/// Candidates shown in the body; the others go to the appendix.
pub(super) const IN_BODY: usize = 10;

/// The header of the ranking, plain words with units.
const HEADER: [&str; 7] = [
    "rank",
    "candidate (unit)",
    "confounding with what is fitted (0-1, above 0.9 not identifiable)",
    "share of the residual it explains",
    "score statistic",
    "amplitude [95 % interval]",
    "loop's decision",
];

/// One ranking row of candidate `c` at `rank` (1-based).
fn row(r: &LoopResult, rank: usize, c: &Score) -> Vec<String> {
    let unit = r
        .catalogue
        .get(&c.name)
        .map(|i| i.unit.as_str())
        .filter(|u| !u.is_empty());
    let name = match (c.kind.as_str(), unit) {
        ("signature", _) => format!("{} (shape without a parameter)", c.name),
        (_, Some(u)) => format!("{} ({u})", c.name),
        _ => c.name.clone(),
    };
    vec![
        rank.to_string(),
        name,
        f(c.kappa),
        f(c.explained_fraction),
        f(c.score),
        c.amplitude.as_ref().map_or("-".into(), |a| {
            format!("{} [{}, {}]", f(a.value), f(a.lower), f(a.upper))
        }),
        c.status.clone(),
    ]
}

/// The first [`IN_BODY`] candidates ranked on the calibrated model's residual and the pairs
/// these sensors cannot tell apart.
pub(super) fn attribution(r: &LoopResult) -> Section {
    let shown = r.candidates.len().min(IN_BODY);
    let rest = r.candidates.len() - shown;
    let mut blocks = vec![table(
        &format!(
            "Candidates ranked on the calibrated model's residual: the first {shown} of {}{}",
            r.candidates.len(),
            if rest > 0 {
                " (the others in the appendix)"
            } else {
                ""
            }
        ),
        &HEADER,
        r.candidates
            .iter()
            .take(shown)
            .enumerate()
            .map(|(i, c)| row(r, i + 1, c))
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

/// The candidates ranked below the first [`IN_BODY`], when there are any.
pub(super) fn appendix(r: &LoopResult) -> Option<Section> {
    (r.candidates.len() > IN_BODY).then(|| Section {
        heading: "Appendix: the other candidates".into(),
        blocks: vec![table(
            "Candidates ranked below the first ten",
            &HEADER,
            r.candidates
                .iter()
                .enumerate()
                .skip(IN_BODY)
                .map(|(i, c)| row(r, i + 1, c))
                .collect(),
        )],
    })
}

/// Every model forward selection fitted, in order, with the loop's decision: the declared
/// model, each addition tried (kept, or refused with why), and the control (the model as it
/// stood recalibrated again without the refused candidate) where there was one.
pub(super) fn selection(r: &LoopResult) -> Section {
    let mut rows = Vec::new();
    let mut previous_bic: Option<f64> = None;
    for (i, m) in r.models.iter().enumerate() {
        let after_refusal = i > 0 && !r.models[i - 1].kept;
        let model = if m.added.is_empty() {
            "declared model".to_string()
        } else {
            format!("declared + {}", m.added.join(" + "))
        };
        let (what, decision) = if after_refusal {
            (
                format!("{model}, recalibrated again (control)"),
                "the result: the control fits better than the model before it".to_string(),
            )
        } else if i == 0 {
            (format!("{model}, calibrated"), "the start".to_string())
        } else if m.kept {
            (format!("{model}, recalibrated"), "kept".to_string())
        } else {
            (
                format!("{model}, recalibrated"),
                format!("refused: {}", r.stopped),
            )
        };
        let change = previous_bic.map_or("-".to_string(), |b| f(m.bic - b));
        if m.kept {
            previous_bic = Some(m.bic);
        }
        rows.push(vec![
            what,
            m.k.to_string(),
            f(m.rss),
            f(m.bic),
            change,
            decision,
        ]);
    }
    Section {
        heading: "Forward selection".into(),
        blocks: vec![
            Block::Paragraph(
                "Each addition is recalibrated and kept when the Bayesian information \
                 criterion (BIC = weighted residual sum of squares + k ln n) falls by more \
                 than 2 from the last model kept, against a control: the same recalibration \
                 without the candidate."
                    .into(),
            ),
            table(
                "Every model fitted, in order",
                &[
                    "model",
                    "fitted quantities k",
                    "weighted residual sum of squares",
                    "BIC",
                    "BIC change from the last model kept",
                    "decision",
                ],
                rows,
            ),
            Block::Paragraph(format!("Stopped: {}.", r.stopped)),
        ],
    }
}
