//! What a study or a loop tells the person waiting for it, in words: the journal's stage
//! names (`r1-gn0-jac`) as a reader says them ("recalibration 1, Gauss-Newton step 1,
//! Jacobian"), and the loop's estimate of the runs it will make.

use crate::closeloop::LoopOptions;

/// The journal stage `name` of a study or a loop in words.
///
/// Study stages: `nominal`, `noise` (the jitter ensemble), `ensemble` (the sample over the
/// parameter space), `reconcile` (the CORS-RBF search). Loop stages: `r<k>-...` is round
/// `k`'s fit (`r0` the calibration of the declared model, `r<k>` for `k >= 1` the
/// recalibration with the `k`-th addition, `r<k>-control` the same recalibration without
/// it), followed by `start`, `cors`, `gn<i>-jac`, `gn<i>-try<a>`, `gn<i>-ext<e>` (Gauss-Newton
/// step `i + 1`: its Jacobian, its trial steps, its longer steps), `warm-...` (the second
/// polish from the best start) or `candidates` (the attribution's run per candidate);
/// `holdout-...` runs at the holdout's condition. A name it does not know is returned as
/// it is.
pub fn stage_title(name: &str) -> String {
    match name {
        "nominal" => return "nominal run".into(),
        "noise" => return "jitter ensemble (the model's own noise)".into(),
        "ensemble" => return "ensemble over the parameter space".into(),
        "reconcile" => return "reconciliation, CORS-RBF search".into(),
        _ => {}
    }
    if let Some(rest) = name.strip_prefix("holdout-") {
        let what = match rest {
            "nominal" => "nominal run".to_string(),
            "calibrated" => "calibrated model's run".to_string(),
            "enriched" => "enriched model's run".to_string(),
            "noise" => "jitter ensemble (the model's own noise)".to_string(),
            other => other.to_string(),
        };
        return format!("holdout, {what}");
    }
    round_title(name).unwrap_or_else(|| name.to_string())
}

/// `r<k>[-control][-warm]-<what>` in words, `None` for another name.
fn round_title(name: &str) -> Option<String> {
    let mut parts = name.split('-');
    let round: usize = parts.next()?.strip_prefix('r')?.parse().ok()?;
    let mut words = vec![if round == 0 {
        "calibration".to_string()
    } else {
        format!("recalibration {round}")
    }];
    let mut rest: Vec<&str> = parts.collect();
    if rest.first() == Some(&"control") {
        rest.remove(0);
        words[0] = format!("recalibration {round}, control (without the addition)");
    }
    if rest.first() == Some(&"warm") {
        rest.remove(0);
        words.push("second polish from the best start".into());
    }
    match rest.as_slice() {
        ["start"] => words.push("starting points".into()),
        ["cors"] => words.push("CORS-RBF search".into()),
        ["candidates"] => {
            words[0] = format!("attribution {}", round + 1);
            words.push("two runs per candidate effect".into());
        }
        [gn, what] => {
            let i: usize = gn.strip_prefix("gn")?.parse().ok()?;
            words.push(format!("Gauss-Newton step {}", i + 1));
            words.push(if *what == "jac" {
                "Jacobian".to_string()
            } else if let Some(a) = what.strip_prefix("try") {
                format!("trial step {}", a.parse::<usize>().ok()? + 1)
            } else if let Some(e) = what.strip_prefix("ext") {
                format!("longer step {}", e.parse::<usize>().ok()?)
            } else {
                return None;
            });
        }
        _ => return None,
    }
    Some(words.join(", "))
}

/// The runs a loop is estimated to make from where it stands: every stage whose size is
/// known counted at its size, each Gauss-Newton polish at its iteration limit (`polish`
/// iterations of a Jacobian of `d` runs and one trial step, and the last Jacobian), and
/// one more addition (its recalibration, its control and the next attribution) while the
/// loop may still add one. A polish that converges early or a second polish from the best
/// start moves the figure; the loop revises it as stages end.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LoopRunEstimate {
    /// Declared parameters of the model.
    pub declared: usize,
    /// Candidate effects the loop may consider.
    pub candidates: usize,
    /// Runs of the jitter ensemble.
    pub ensemble: usize,
    /// CORS runs of the first calibration.
    pub reconcile: usize,
    /// CORS runs of each recalibration.
    pub recalibrate: usize,
    /// Gauss-Newton iterations at most per polish.
    pub polish: usize,
    /// Whether the loop has a holdout (its three runs and its jitter ensemble).
    pub holdout: bool,
}

impl LoopRunEstimate {
    /// The estimate for a loop of `options` on a model of `declared` parameters and
    /// `candidates` candidate effects allowed.
    pub fn new(options: &LoopOptions, declared: usize, candidates: usize, holdout: bool) -> Self {
        LoopRunEstimate {
            declared,
            candidates,
            ensemble: options.ensemble,
            reconcile: options.reconcile,
            recalibrate: options.recalibrate,
            polish: options.polish,
            holdout,
        }
    }

    /// A fit of `d` parameters from `starts` points with `budget` CORS runs.
    pub fn calibration(&self, d: usize, starts: usize, budget: usize) -> usize {
        starts + budget + self.polish * (d + 1) + d
    }

    /// The fits of one addition to a model of `d` parameters: the recalibration with it
    /// (three starts: the held value, the linear estimate, the far end of its range) and
    /// the control without it.
    pub fn recalibrations(&self, d: usize) -> usize {
        self.calibration(d + 1, 3, self.recalibrate) + self.calibration(d, 1, self.recalibrate)
    }

    /// The holdout's runs.
    pub fn holdout_runs(&self) -> usize {
        if self.holdout { 3 + self.ensemble } else { 0 }
    }

    /// Runs left after the nominal run: the jitter ensemble, the first calibration, the
    /// first attribution, one addition, the holdout.
    pub fn after_nominal(&self) -> usize {
        let d = self.declared;
        self.ensemble
            + self.calibration(d, 1, self.reconcile)
            + 2 * self.candidates
            + self.recalibrations(d)
            + self.holdout_runs()
    }

    /// Runs left at the start of a round on a model of `d` parameters: an attribution of
    /// two runs per candidate (`candidates` of them) when the round has one, one addition
    /// when the loop `may_add`, and the holdout.
    pub fn rest_of_round(&self, d: usize, candidates: usize, may_add: bool) -> usize {
        2 * candidates + if may_add { self.recalibrations(d) } else { 0 } + self.holdout_runs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn loop_stages_read_as_words() {
        for (name, words) in [
            ("nominal", "nominal run"),
            ("r0-start", "calibration, starting points"),
            ("r0-cors", "calibration, CORS-RBF search"),
            ("r0-gn1-jac", "calibration, Gauss-Newton step 2, Jacobian"),
            (
                "r2-gn0-try1",
                "recalibration 2, Gauss-Newton step 1, trial step 2",
            ),
            (
                "r1-warm-gn3-ext2",
                "recalibration 1, second polish from the best start, Gauss-Newton step 4, \
                 longer step 2",
            ),
            (
                "r1-control-cors",
                "recalibration 1, control (without the addition), CORS-RBF search",
            ),
            (
                "r0-candidates",
                "attribution 1, two runs per candidate effect",
            ),
            ("holdout-enriched", "holdout, enriched model's run"),
            ("reconcile", "reconciliation, CORS-RBF search"),
            // Names it does not know stay as they are.
            ("r1-gnx-jac", "r1-gnx-jac"),
            ("custom", "custom"),
        ] {
            assert_eq!(stage_title(name), words, "{name}");
        }
    }

    /// The estimate by hand for 2 declared parameters, 3 candidates, polish 2:
    /// calibration(2, 1, 8) = 1 + 8 + 2*3 + 2 = 17; recalibrations(2) = calibration(3, 3, 6)
    /// (3 + 6 + 8 + 3 = 20) + calibration(2, 1, 6) (1 + 6 + 6 + 2 = 15) = 35; an
    /// attribution runs two per candidate.
    #[test]
    fn the_loop_estimate_adds_its_stages() {
        let e = LoopRunEstimate {
            declared: 2,
            candidates: 3,
            ensemble: 4,
            reconcile: 8,
            recalibrate: 6,
            polish: 2,
            holdout: true,
        };
        assert_eq!(e.calibration(2, 1, 8), 17);
        assert_eq!(e.recalibrations(2), 35);
        assert_eq!(e.after_nominal(), 4 + 17 + 2 * 3 + 35 + 7);
        assert_eq!(e.rest_of_round(3, 0, false), 7);
        assert_eq!(e.rest_of_round(2, 2, true), 2 * 2 + 35 + 7);
    }
}
