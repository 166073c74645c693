//! Placement straight from an ensemble of simulations: histories -> impact shapes ->
//! effective independence.

use impactcal_core::{CoreError, Histories};
use impactcal_shapes::{ImpactShapes, ShapeOptions};

use crate::candidates::CandidateShapes;
use crate::error::Result;
use crate::options::PlacementOptions;
use crate::place::{Placement, place};

/// The impact shapes of an ensemble and the sensors placed on them.
#[derive(Debug, Clone)]
pub struct EnsemblePlacement {
    /// Impact shapes of the concatenated runs (channels = candidate DOFs).
    pub shapes: ImpactShapes,
    /// The placement on those shapes.
    pub placement: Placement,
}

/// Concatenates runs in time: channel `c` of the result is channel `c` of the first run
/// followed by the channel of the same label in each later run, so one SVD of the result
/// gives shapes that cover every run. The time base (`dt`, start, unit) is the first run's
/// (it carries no meaning after concatenation).
///
/// # Errors
/// [`CoreError::Invalid`] for no runs; [`CoreError::UnknownLabel`] when a later run lacks a
/// channel of the first; [`CoreError::DimensionMismatch`] when a later run has a different
/// number of channels.
pub fn concatenate_runs(runs: &[Histories]) -> Result<Histories> {
    let Some(first) = runs.first() else {
        return Err(CoreError::Invalid("an ensemble needs at least one run".into()).into());
    };
    let labels = first.labels().to_vec();
    let mut channels: Vec<Vec<f64>> = (0..first.channels())
        .map(|c| first.channel(c).to_vec())
        .collect();
    for (r, run) in runs.iter().enumerate().skip(1) {
        if run.channels() != labels.len() {
            return Err(CoreError::DimensionMismatch {
                what: format!("channels of run {}", r + 1),
                expected: labels.len(),
                found: run.channels(),
            }
            .into());
        }
        let aligned = run.select(&labels)?;
        for (c, ch) in channels.iter_mut().enumerate() {
            ch.extend_from_slice(aligned.channel(c));
        }
    }
    Ok(Histories::from_channels(
        labels,
        channels,
        first.dt(),
        first.start(),
        first.unit(),
    )?)
}

/// Places sensors straight from an ensemble of simulated histories, as the source paper
/// does: the runs are concatenated in time ([`concatenate_runs`]), their impact shapes
/// `Y = U S V^T` are truncated by `shape_options`, and [`place`] runs on the candidate
/// matrix `U_k` (channels x shapes, labelled by channel). Because effective independence
/// depends only on the column space, using `U_k` or `U_k S_k` gives the same sensors.
///
/// # Errors
/// As [`concatenate_runs`], [`ImpactShapes::from_histories`] (wrapped in
/// [`SensorsError::Shapes`](crate::SensorsError::Shapes)) and [`place`]; in particular
/// [`SensorsError::TargetBelowShapes`](crate::SensorsError::TargetBelowShapes) when more shapes are kept than sensors are asked
/// for.
///
/// ```
/// use impactcal_core::Histories;
/// use impactcal_sensors::{PlacementOptions, place_from_histories};
/// use impactcal_shapes::ShapeOptions;
///
/// // Six channels, two spatial patterns with different time functions.
/// let labels: Vec<String> = (1..=6).map(|n| format!("{n}.z")).collect();
/// let channels: Vec<Vec<f64>> = (1..=6)
///     .map(|n| {
///         (0..50)
///             .map(|t| {
///                 let t = t as f64 * 0.01;
///                 (n as f64 * 0.5).sin() * (9.0 * t).sin() + (n as f64).cos() * (23.0 * t).sin()
///             })
///             .collect()
///     })
///     .collect();
/// let run = Histories::from_channels(labels, channels, 0.01, 0.0, "in/s")?;
/// let result = place_from_histories(&[run], &ShapeOptions::count(2), &PlacementOptions::new(3))?;
/// assert_eq!(result.shapes.len(), 2);
/// assert_eq!(result.placement.selected.len(), 3);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn place_from_histories(
    runs: &[Histories],
    shape_options: &ShapeOptions,
    options: &PlacementOptions,
) -> Result<EnsemblePlacement> {
    let y = concatenate_runs(runs)?;
    let shapes = ImpactShapes::from_histories(&y, shape_options)?;
    let candidates = CandidateShapes::new(shapes.labels().to_vec(), shapes.shapes())?;
    let placement = place(&candidates, options)?;
    Ok(EnsemblePlacement { shapes, placement })
}
