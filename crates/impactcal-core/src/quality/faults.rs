//! The faults of a measured channel: the quiet part before the event, clipped runs, spikes,
//! baseline drift, and gaps or repeated time stamps of a time column.

use serde::{Deserialize, Serialize};

/// Fewest samples a quiet part must hold to measure noise on.
pub const MIN_QUIET: usize = 32;

/// The quantisation step of `x`: the smallest positive difference between two of its
/// distinct values (0 for a constant channel).
pub fn quantum(x: &[f64]) -> f64 {
    let mut v: Vec<f64> = x.to_vec();
    v.sort_by(f64::total_cmp);
    v.dedup();
    let q = v
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| *d > 0.0)
        .fold(f64::INFINITY, f64::min);
    if q.is_finite() { q } else { 0.0 }
}

/// Median of `v` (0 for none).
pub fn median(v: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let m = s.len() / 2;
    if s.len() % 2 == 1 {
        s[m]
    } else {
        0.5 * (s[m - 1] + s[m])
    }
}

/// `1.4826 * median |v - median(v)|`: the standard deviation of normal data, robustly.
pub fn robust_scale(v: &[f64]) -> f64 {
    let m = median(v);
    let dev: Vec<f64> = v.iter().map(|x| (x - m).abs()).collect();
    1.4826 * median(&dev)
}

/// The end of the quiet part of `x` found from the record alone: the reference is the
/// first `max(32, n / 20)` samples (median `m`, robust scale `s` floored at the quantum
/// `q`); the event starts at the first sample further than `8 max(s, q)` from `m` that is
/// followed, within the next 8 samples, by at least 3 more further than `5 max(s, q)` (a
/// lone spike does not start an event). The quiet part ends `max(4, onset / 20)` samples
/// before it. `None` when no such onset lies after the reference window: the record has no
/// quiet part it can show.
pub fn quiet_end(x: &[f64]) -> Option<usize> {
    let n = x.len();
    let n0 = MIN_QUIET.max(n / 20);
    if n < 2 * n0 {
        return None;
    }
    let m = median(&x[..n0]);
    let s = robust_scale(&x[..n0]).max(quantum(&x[..n0]));
    if s <= 0.0 {
        return None;
    }
    let onset = (0..n).find(|&k| {
        (x[k] - m).abs() > 8.0 * s
            && x[k + 1..(k + 9).min(n)]
                .iter()
                .filter(|v| (*v - m).abs() > 5.0 * s)
                .count()
                >= 3
    })?;
    let end = onset.saturating_sub(4.max(onset / 20));
    (end >= n0).then_some(end)
}

/// A run of equal samples at a channel's extreme.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClipRun {
    /// First sample of the run.
    pub first: usize,
    /// Last sample of the run.
    pub last: usize,
    /// The level (the channel's maximum or minimum).
    pub level: f64,
    /// The larger of the steps into and out of the run (the signal's unit): how fast the
    /// signal met the rail.
    pub step: f64,
}

/// Clipped runs of `x`, found without being told the rails: runs of at least two samples
/// equal (within half a quantum `q`) to the channel's maximum or minimum, away from the
/// record's ends, that a smooth peak cannot make (`tol = 4 max(q, noise)`, `noise` the
/// channel's noise standard deviation; `E_1`, `E_2` the steps into and out of the run,
/// `D_1`, `D_2` the distances of the samples two before and two after from the level):
///
/// - three or more equal samples: a smooth peak is that flat only where its curvature is
///   below a quantum, so its steps in and out are of a quantum: clipped when
///   `max(E_1, E_2) > tol`;
/// - two: a smooth peak sampled either side of its top has `D = 3 E` on each side (a
///   parabola); a rail stops the signal abruptly: clipped when `D > 2 (3 E + tol)` on
///   either side.
pub fn clipped_runs(x: &[f64], noise: f64) -> Vec<ClipRun> {
    let n = x.len();
    if n < 8 {
        return Vec::new();
    }
    let q = quantum(x);
    let tol = 4.0 * q.max(noise);
    let hi = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let lo = x.iter().copied().fold(f64::INFINITY, f64::min);
    if hi <= lo {
        return Vec::new();
    }
    let mut out = Vec::new();
    for level in [hi, lo] {
        let at = |k: usize| (x[k] - level).abs() <= 0.5 * q;
        let mut k = 0;
        while k < n {
            if !at(k) {
                k += 1;
                continue;
            }
            let first = k;
            while k + 1 < n && at(k + 1) {
                k += 1;
            }
            let last = k;
            k += 1;
            if last == first || first < 2 || last + 2 >= n {
                continue;
            }
            let d = |i: usize| (x[i] - level).abs();
            let (e1, e2) = (d(first - 1), d(last + 1));
            let clipped = if last - first >= 2 {
                e1.max(e2) > tol
            } else {
                d(first - 2) > 2.0 * (3.0 * e1 + tol) || d(last + 2) > 2.0 * (3.0 * e2 + tol)
            };
            if clipped {
                out.push(ClipRun {
                    first,
                    last,
                    level,
                    step: e1.max(e2),
                });
            }
        }
    }
    out.sort_by_key(|r| r.first);
    out
}

/// Half-width of the window of the spikes' local scale.
pub const SPIKE_WINDOW: usize = 16;

/// Threshold of a spike, in local robust standard deviations.
pub const SPIKE_THRESHOLD: f64 = 10.0;

/// Widest spike, in samples.
pub const SPIKE_WIDTH: usize = 3;

/// Isolated outliers of `x`, one to [`SPIKE_WIDTH`] samples wide, as inclusive spans: a
/// block `x_k .. x_{k+w-1}` every sample of which departs on the same side from the
/// straight line between its neighbours `x_{k-1}` and `x_{k+w}` by more than
/// [`SPIKE_THRESHOLD`] (one sample) or twice that (two or three) times the local robust
/// scale (`1.4826` times the median
/// `|x_{j+1} - 2 x_j + x_{j-1}| / sqrt 6` over the [`SPIKE_WINDOW`] samples either side,
/// the block and its neighbours left out, floored at the quantum and at `floor`), while the
/// neighbours agree with each other better than the block departs (`|x_{k+w} - x_{k-1}|`
/// below the smallest departure). The narrowest block that qualifies is taken. A fast but
/// real oscillation raises the local scale with it and is not taken for a spike.
pub fn spikes(x: &[f64], floor: f64) -> Vec<(usize, usize)> {
    let n = x.len();
    if n < 5 {
        return Vec::new();
    }
    let q = quantum(x);
    let d2: Vec<f64> = (0..n)
        .map(|k| {
            if k == 0 || k + 1 == n {
                0.0
            } else {
                (x[k + 1] - 2.0 * x[k] + x[k - 1]).abs() / 6f64.sqrt()
            }
        })
        .collect();
    let mut out = Vec::new();
    let mut k = 1;
    while k + 1 < n {
        let mut found = None;
        for w in 1..=SPIKE_WIDTH {
            if k + w >= n {
                break;
            }
            let (a, b) = (x[k - 1], x[k + w]);
            let dep: Vec<f64> = (0..w)
                .map(|i| x[k + i] - (a + (b - a) * (i + 1) as f64 / (w + 1) as f64))
                .collect();
            let same_side = dep.iter().all(|d| *d > 0.0) || dep.iter().all(|d| *d < 0.0);
            let smallest = dep.iter().map(|d| d.abs()).fold(f64::INFINITY, f64::min);
            if !same_side || (b - a).abs() >= smallest {
                continue;
            }
            let lo = k.saturating_sub(SPIKE_WINDOW).max(1);
            let hi = (k + w + SPIKE_WINDOW).min(n - 2);
            let local: Vec<f64> = (lo..=hi)
                .filter(|&j| j + 1 < k || j > k + w)
                .map(|j| d2[j])
                .collect();
            let scale = (1.4826 * median(&local)).max(q).max(floor);
            // A wider block has more ways to stand out by chance in coloured noise and in a
            // fast response: it must stand out twice as far.
            let threshold = SPIKE_THRESHOLD * if w == 1 { 1.0 } else { 2.0 };
            if scale > 0.0 && smallest > threshold * scale {
                found = Some(w);
                break;
            }
        }
        match found {
            Some(w) => {
                out.push((k, k + w - 1));
                k += w + 1;
            }
            None => k += 1,
        }
    }
    out
}

/// The baseline drift an acceleration record implies.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Drift {
    /// Start of the tail (s) over which the drift is measured: after the last sample whose
    /// departure from the offset exceeds 2 % of the largest (the event's end), or the
    /// last quarter of the record after the quiet part when that leaves under 16 samples.
    pub tail_start: f64,
    /// The velocity change over the tail that the record implies, offset removed: the
    /// least-squares slope of the velocity `v_k = sum_{i<=k} (a_i - offset) dt` over the
    /// tail times the tail's duration (the record's unit times seconds). Ringing that
    /// averages out leaves the slope; a shifted baseline does not.
    pub velocity_change: f64,
    /// What the pre-trigger noise allows: three standard deviations of the same statistic
    /// for noise alone, `3 sigma dt sqrt(6 m / 5 (1 + rho) / (1 - rho))` (`m` tail samples;
    /// the slope of a random walk of `m` steps has variance `6 / (5 m)` of a step's).
    pub allowed: f64,
    /// `|velocity_change| > allowed`.
    pub significant: bool,
}

/// The drift of acceleration `x` (sampled at `dt`, starting at `start`) after its quiet part
/// ends at `quiet` (see [`Drift`]), for noise of standard deviation `sigma` and lag-one
/// correlation `rho`. After an impact the body moves at a steady velocity (or rests): its
/// acceleration averages out; a baseline that shifted (a piezoelectric sensor after overload,
/// a zero that moved) keeps integrating into velocity. `None` for a tail under 16 samples.
pub fn drift(
    x: &[f64],
    dt: f64,
    start: f64,
    quiet: usize,
    offset: f64,
    sigma: f64,
    rho: f64,
) -> Option<Drift> {
    let n = x.len();
    if quiet >= n || (n - quiet) / 4 < 16 {
        return None;
    }
    let peak = x[quiet..]
        .iter()
        .map(|v| (v - offset).abs())
        .fold(0.0, f64::max);
    let end = (quiet..n)
        .rev()
        .find(|&k| (x[k] - offset).abs() > 0.02 * peak)
        .unwrap_or(quiet);
    let first = if n - end > 16 {
        end + 1
    } else {
        n - (n - quiet) / 4
    };
    let m = n - first;
    let mut v = 0.0;
    let vel: Vec<f64> = x[first..]
        .iter()
        .map(|a| {
            v += (a - offset) * dt;
            v
        })
        .collect();
    let tm = (m as f64 - 1.0) / 2.0;
    let vm = vel.iter().sum::<f64>() / m as f64;
    let (mut stv, mut stt) = (0.0, 0.0);
    for (k, y) in vel.iter().enumerate() {
        let t = k as f64 - tm;
        stv += t * (y - vm);
        stt += t * t;
    }
    let velocity_change = stv / stt * m as f64;
    let r = rho.clamp(-0.99, 0.99);
    let allowed = 3.0 * sigma * dt * (1.2 * m as f64 * (1.0 + r) / (1.0 - r)).sqrt();
    Some(Drift {
        tail_start: start + first as f64 * dt,
        velocity_change,
        allowed,
        significant: velocity_change.abs() > allowed,
    })
}

/// A fault of a time column.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum TimeFault {
    /// A time stamp equal to the previous one.
    Repeated {
        /// 0-based sample (row after the header).
        sample: usize,
        /// The time.
        time: f64,
    },
    /// A time stamp before the previous one.
    Backwards {
        /// 0-based sample.
        sample: usize,
        /// The time.
        time: f64,
        /// The previous time.
        previous: f64,
    },
    /// A step more than 1.5 times the median step: samples missing.
    Gap {
        /// 0-based sample after the gap.
        sample: usize,
        /// Time before the gap.
        from: f64,
        /// Time after it.
        to: f64,
        /// Samples missing at the median step.
        missing: usize,
    },
}

/// Repeated and backward time stamps and gaps (a step above 1.5 median steps) of `times`.
pub fn time_faults(times: &[f64]) -> Vec<TimeFault> {
    let steps: Vec<f64> = times
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| *d > 0.0)
        .collect();
    let step = median(&steps);
    let mut out = Vec::new();
    for k in 1..times.len() {
        let d = times[k] - times[k - 1];
        if d == 0.0 {
            out.push(TimeFault::Repeated {
                sample: k,
                time: times[k],
            });
        } else if d < 0.0 {
            out.push(TimeFault::Backwards {
                sample: k,
                time: times[k],
                previous: times[k - 1],
            });
        } else if step > 0.0 && d > 1.5 * step {
            out.push(TimeFault::Gap {
                sample: k,
                from: times[k - 1],
                to: times[k],
                missing: ((d / step).round() as usize).saturating_sub(1),
            });
        }
    }
    out
}
