//! Sensor placement on the ensemble's impact shapes, and the test expanded from the sensors
//! to every channel through the baseline's shapes (the paper's Eq. 4.8).

use faer::Mat;
use impactcal_core::Histories;
use impactcal_sensors::{CandidateShapes, PlacementOptions, place};
use impactcal_shapes::{Expansion, ImpactShapes, ShapeOptions};
use serde::{Deserialize, Serialize};

use super::channels::relative_error;
use crate::error::{CalibrateError, Result};

/// The sensors a study uses.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SensorsResult {
    /// Candidate channels (the objective channels the test has).
    pub candidates: usize,
    /// Impact shapes of the concatenated ensemble the placement kept.
    pub shapes: usize,
    /// The selected channels, in placement order.
    pub selected: Vec<String>,
    /// `det(Q_K) / det(Q_all)` of the Fisher information kept.
    pub determinant_ratio: f64,
    /// Condition number of the selected rows of the shapes.
    pub condition_number: f64,
    /// Relative L2 error of the test expanded from the sensors to the other objective
    /// channels through the baseline's shapes (`None` when no channel is left over).
    pub expansion_rel_error: Option<f64>,
    /// Condition number of the expansion's fit.
    pub expansion_condition: Option<f64>,
    /// Chosen sensors whose information other candidates repeat (on a symmetric structure,
    /// their mirror images), each with those candidates: the placement counted each such
    /// set once ([`impactcal_sensors::PlacementOptions::equivalence_tolerance`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub equivalents: Vec<impactcal_sensors::Equivalent>,
    /// Why fewer shapes were kept than the options ask for: the ensemble's data has a lower
    /// numerical rank (absent when the requested number was kept).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// Whether `count` sensors fit on `candidates` channels.
///
/// # Errors
/// [`CalibrateError::Study`] for more sensors than candidates.
pub fn check_count(count: usize, candidates: usize) -> Result<()> {
    if count > candidates {
        return Err(CalibrateError::study(
            "study.sensors",
            format!(
                "{count} sensors asked for, but only {candidates} channels can carry one (the \
                 predictable channels the test and the model share)"
            ),
        ));
    }
    Ok(())
}

/// Places `count` sensors on the impact shapes (`shapes` of them) of an ensemble of `runs`
/// runs restricted to `candidates`, and expands the test at the sensors to the other
/// candidates through the `baseline` run's shapes. `read(j)` gives run `j` on the
/// candidates' channels (in their order): the runs are read one at a time into the one
/// matrix the shapes need, `candidates x (runs samples)`, run after run in time (the
/// source paper's concatenated ensemble).
///
/// # Errors
/// [`CalibrateError::Study`] for more sensors than candidates or no run; a run that does not
/// have the candidates' channels and samples; placement and shape errors; `read`'s errors.
pub fn place_sensors(
    read: &dyn Fn(usize) -> Result<Histories>,
    runs: usize,
    candidates: &[String],
    count: usize,
    shapes: usize,
    baseline: &Histories,
    test: &Histories,
) -> Result<SensorsResult> {
    check_count(count, candidates.len())?;
    if runs == 0 {
        return Err(CalibrateError::study(
            "sensor placement",
            "no run to place on",
        ));
    }
    let samples = baseline.samples();
    let mut y = Mat::<f64>::zeros(candidates.len(), runs * samples);
    for j in 0..runs {
        let h = read(j)?.select(candidates)?;
        if h.samples() != samples {
            return Err(CalibrateError::study(
                "sensor placement",
                format!(
                    "run {j} has {} samples, the baseline {samples}",
                    h.samples()
                ),
            ));
        }
        for c in 0..candidates.len() {
            for (k, v) in h.channel(c).iter().enumerate() {
                y[(c, j * samples + k)] = *v;
            }
        }
    }
    // A number of shapes above what the ensemble's data can carry is lowered to its
    // numerical rank, with a note, rather than ending a study whose runs are done.
    let (ensemble, note) = match ImpactShapes::from_matrix(y.as_ref(), &ShapeOptions::count(shapes))
    {
        Err(impactcal_shapes::ShapesError::TooManyShapes { requested, rank }) if rank > 0 => (
            ImpactShapes::from_matrix(y.as_ref(), &ShapeOptions::count(rank))?,
            Some(format!(
                "{requested} shapes asked for, but the ensemble's data has numerical rank \
                 {rank}: {rank} shapes kept"
            )),
        ),
        other => (other?, None),
    };
    drop(y);
    let shapes = ensemble.len();
    let candidate_shapes = CandidateShapes::new(candidates.to_vec(), ensemble.shapes())?;
    // Fewer distinct channels than sensors (channels that repeat one another, as at a low
    // rank): the runs are done, so the sensors are placed by plain effective independence,
    // with a note, rather than ending the study.
    let (placement, note) = match place(&candidate_shapes, &PlacementOptions::new(count)) {
        Err(impactcal_sensors::SensorsError::TargetAboveCandidates {
            available,
            equivalent,
            ..
        }) if equivalent > 0 => {
            let plain = PlacementOptions::new(count).equivalence_tolerance(0.0)?;
            let extra = format!(
                "{count} sensors asked for, but only {available} channels carry distinct \
                 information ({equivalent} repeat others): placed counting repeats"
            );
            (
                place(&candidate_shapes, &plain)?,
                Some(match note {
                    Some(n) => format!("{n}; {extra}"),
                    None => extra,
                }),
            )
        }
        other => (other?, note),
    };
    let selected = placement.selected.clone();
    let rest: Vec<String> = candidates
        .iter()
        .filter(|c| !selected.contains(c))
        .cloned()
        .collect();
    let (expansion_rel_error, expansion_condition) = if rest.is_empty() {
        (None, None)
    } else {
        let base = ImpactShapes::from_histories(
            &baseline.select(candidates)?,
            &ShapeOptions::count(shapes.min(count)),
        )?;
        let e = Expansion::compute(&base, &test.select(&selected)?, None)?;
        (
            Some(relative_error(e.histories(), test, &rest)?),
            Some(e.condition()),
        )
    };
    Ok(SensorsResult {
        candidates: candidates.len(),
        shapes: ensemble.len(),
        selected,
        determinant_ratio: placement.determinant_ratio,
        condition_number: placement.condition_number,
        expansion_rel_error,
        expansion_condition,
        equivalents: placement
            .equivalents
            .iter()
            .filter(|e| e.chosen)
            .cloned()
            .collect(),
        note,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Histories of three proportional channels (`a`, `2 a`, `3 a`) scaled by `k`.
    fn rank_one(k: f64) -> Histories {
        let mut text = String::from("time,1.z,2.z,3.z\n");
        for i in 0..20 {
            let v = k * (0.3 * f64::from(i)).sin();
            text.push_str(&format!(
                "{},{},{},{}\n",
                f64::from(i) * 0.001,
                v,
                2.0 * v,
                3.0 * v
            ));
        }
        Histories::parse_csv(&text, "rank-one").unwrap()
    }

    /// An ensemble whose data has numerical rank 1: asking 3 shapes keeps 1, with a note,
    /// instead of stopping the study after its runs.
    #[test]
    fn shapes_above_the_ensembles_rank_are_lowered_with_a_note() {
        let labels: Vec<String> = ["1.z", "2.z", "3.z"].map(String::from).to_vec();
        let read = |j: usize| -> Result<Histories> { Ok(rank_one(1.0 + j as f64)) };
        let base = rank_one(1.0);
        let r = place_sensors(&read, 4, &labels, 3, 3, &base, &rank_one(1.5)).unwrap();
        assert_eq!(r.shapes, 1);
        assert_eq!(r.selected.len(), 3);
        let note = r.note.unwrap();
        assert!(
            note.contains("3 shapes asked for") && note.contains("numerical rank 1"),
            "{note}"
        );
        // Asking what the data carries leaves no note on the shapes; the three proportional
        // channels repeat one another, which the note says, and the three sensors are
        // placed counting the repeats.
        assert!(note.contains("2 repeat others"), "{note}");
        let r = place_sensors(&read, 4, &labels, 3, 1, &base, &rank_one(1.5)).unwrap();
        let note = r.note.unwrap();
        assert_eq!(r.shapes, 1);
        assert!(
            !note.contains("shapes asked for") && note.contains("2 repeat others"),
            "{note}"
        );
    }
}
