//! The three waves of a bar test: the incident gauge's record split into the incident and
//! the reflected wave, the records resampled to what the bars carry, and waves moved from
//! a gauge to a specimen face.
//!
//! **Separation.** The incident gauge sees the incident pulse, then, a round trip
//! `T = 2 x_i / c_i` later (`x_i` the gauge distance, `c_i` the wave speed), its
//! reflection. The pulse's onset and end are the first and last samples whose compressive
//! strain exceeds [`ONSET_FRACTION`] of its peak; its window is the round trip `T` long,
//! centred on the pulse (equal quiet margins before and after), so that the incident wave
//! is the record inside the window and the reflected wave the record in the next window; the
//! transmitted wave is the transmitted gauge's record in the incident window moved by the
//! travel from one gauge to the other, `x_i / c_i + x_t / c_t`. A pulse
//! longer than `T` overlaps its reflection and cannot be separated: an error.
//!
//! **Resampling.** A bar carries one-dimensional waves only down to wavelengths of about its
//! diameter `D`: shorter waves are the Pochhammer-Chree regime, where the phase velocity has
//! fallen towards the Rayleigh speed and higher modes appear, and the gauges (a few
//! millimetres long) average them out. The highest frequency worth keeping is therefore
//! `f_bar = c / D`, and a record is kept at a rate whose Nyquist frequency is at least
//! `2 f_bar`, i.e. at an interval of at most `D / (4 c)` (the smaller over both bars). A
//! record sampled `m >= 2` times finer is low-passed (a zero-phase windowed-sinc filter with
//! a Blackman window, cut off at 0.8 of the new Nyquist frequency) and every `m`-th sample
//! kept; the result says so ([`Resampling`]).

use crate::error::{ModelsError, Result};
use crate::kolsky::form::{BarSetup, KolskyTest};

/// The fraction of the incident peak that marks the pulse's onset and end.
pub const ONSET_FRACTION: f64 = 0.05;

/// How a record was resampled.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Resampling {
    /// The recorded sampling interval (s).
    pub from_dt: f64,
    /// The interval kept (s).
    pub to_dt: f64,
    /// The decimation factor `m` (`to_dt = m from_dt`).
    pub factor: usize,
    /// The low-pass cut-off applied first (Hz).
    pub cutoff: f64,
}

/// The largest sampling interval that keeps what the bars carry: `min D / (4 c)` over both
/// bars (see the module docs).
pub fn bar_interval(incident: &BarSetup, transmitted: &BarSetup) -> f64 {
    [incident, transmitted]
        .iter()
        .map(|b| 2.0 * b.section.radius() / (4.0 * b.wave_speed()))
        .fold(f64::INFINITY, f64::min)
}

/// Decimates `channels` (sampled at `dt`) to the largest multiple of `dt` not above
/// `max_dt`, after a zero-phase low-pass; `None` (and the channels untouched) when the
/// factor would be 1.
pub fn resample(channels: &mut [Vec<f64>], dt: f64, max_dt: f64) -> Option<Resampling> {
    let m = (max_dt / dt * (1.0 + 1e-9)).floor() as usize;
    if m < 2 {
        return None;
    }
    let to_dt = m as f64 * dt;
    let cutoff = 0.8 * 0.5 / to_dt;
    // Windowed sinc, half-width 4m samples, normalised to unit gain at zero frequency.
    let half = 4 * m;
    let fc = cutoff * dt; // cycles per sample
    let mut taps: Vec<f64> = (0..=2 * half)
        .map(|j| {
            let k = j as f64 - half as f64;
            let sinc = if j == half {
                2.0 * fc
            } else {
                (2.0 * std::f64::consts::PI * fc * k).sin() / (std::f64::consts::PI * k)
            };
            let w = 2.0 * std::f64::consts::PI * j as f64 / (2 * half) as f64;
            sinc * (0.42 - 0.5 * w.cos() + 0.08 * (2.0 * w).cos())
        })
        .collect();
    let sum: f64 = taps.iter().sum();
    taps.iter_mut().for_each(|t| *t /= sum);
    for ch in channels.iter_mut() {
        let n = ch.len();
        // The record's end values held beyond its ends.
        let at = |i: isize| ch[i.clamp(0, n as isize - 1) as usize];
        let out: Vec<f64> = (0..n.div_ceil(m))
            .map(|q| {
                let c = (q * m) as isize;
                taps.iter()
                    .enumerate()
                    .map(|(j, t)| t * at(c + j as isize - half as isize))
                    .sum()
            })
            .collect();
        *ch = out;
    }
    Some(Resampling {
        from_dt: dt,
        to_dt,
        factor: m,
        cutoff,
    })
}

/// The value of `x` (sampled at `dt` from time `start`) at time `t`, linearly interpolated,
/// zero outside the record.
pub fn at_time(x: &[f64], start: f64, dt: f64, t: f64) -> f64 {
    let s = (t - start) / dt;
    if !(s >= 0.0 && s <= (x.len() - 1) as f64) {
        return 0.0;
    }
    let k = (s.floor() as usize).min(x.len().saturating_sub(2));
    let f = s - k as f64;
    if x.len() == 1 {
        return x[0];
    }
    x[k] * (1.0 - f) + x[k + 1] * f
}

/// The incident gauge's record split into its waves, on the record's time base.
#[derive(Debug, Clone, PartialEq)]
pub struct Separated {
    /// The sampling interval (s).
    pub dt: f64,
    /// The time of the first sample (s).
    pub start: f64,
    /// The incident wave at the incident gauge (the record inside the window, zero outside).
    pub incident: Vec<f64>,
    /// The reflected wave at the incident gauge (the record in the round trip after the
    /// window, zero elsewhere).
    pub reflected: Vec<f64>,
    /// The transmitted wave at its gauge: the record in the incident window moved by the
    /// travel `x_i / c_i + x_t / c_t`, zero elsewhere.
    pub transmitted: Vec<f64>,
    /// The first sample of the incident window.
    pub window_start: usize,
    /// The number of samples in the window (the round trip).
    pub window_len: usize,
    /// How the record was resampled, if it was.
    pub resampling: Option<Resampling>,
    /// The gauges' noise: the standard deviation of each channel's strain (incident,
    /// transmitted) about its mean over the quiet start of the record, where neither gauge
    /// has a wave yet, after the resampling: the samples before the incident pulse's onset
    /// less one rise time (onset to peak) for its foot; `None` when fewer than
    /// [`MIN_QUIET`] samples are quiet.
    pub noise: Option<[f64; 2]>,
    /// The number of quiet samples [`Separated::noise`] is measured on.
    pub quiet: usize,
}

/// The fewest quiet samples before the incident window that give a noise level.
pub const MIN_QUIET: usize = 32;

/// The standard deviation of `x` about its mean.
fn spread(x: &[f64]) -> f64 {
    let m = x.iter().sum::<f64>() / x.len() as f64;
    (x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (x.len() - 1) as f64).sqrt()
}

/// Splits a test's gauge strains into the three waves (see the module docs), after
/// resampling to what the bars carry.
///
/// # Errors
/// [`ModelsError::Record`] when the incident gauge holds no compressive pulse, the pulse is
/// longer than the round trip (it overlaps its reflection), or the record ends before the
/// reflection has passed the gauge; the core error of a bar's channel.
pub fn separate(test: &KolskyTest) -> Result<Separated> {
    let strains = test.strains()?;
    let mut ch = vec![strains.channel(0).to_vec(), strains.channel(1).to_vec()];
    let resampling = resample(
        &mut ch,
        strains.dt(),
        bar_interval(&test.incident, &test.transmitted),
    );
    let dt = resampling.map_or(strains.dt(), |r| r.to_dt);
    let [inc, tra]: [Vec<f64>; 2] = ch
        .try_into()
        .map_err(|_| ModelsError::record(&test.source, "two gauge channels expected"))?;
    let what = || format!("{}: incident gauge", test.source);
    let peak = inc.iter().fold(0.0_f64, |m, v| m.max(*v));
    if peak <= 0.0 {
        return Err(ModelsError::record(what(), "holds no compressive pulse"));
    }
    let level = ONSET_FRACTION * peak;
    let on = inc.iter().position(|v| *v > level).unwrap_or(0);
    let peak_at = inc
        .iter()
        .enumerate()
        .fold(
            (0, f64::MIN),
            |m, (k, v)| if *v > m.1 { (k, *v) } else { m },
        )
        .0;
    // The pulse ends where it last exceeds the level before falling below it for good
    // (within one round trip of the onset: the reflection follows).
    let round_trip = 2.0 * test.incident.gauge_distance / test.incident.wave_speed();
    let window_len = (round_trip / dt).round() as usize;
    let horizon = (on + window_len).min(inc.len());
    let end = (peak_at..horizon)
        .rev()
        .find(|k| inc[*k] > level)
        .unwrap_or(peak_at);
    let duration = end + 1 - on;
    if duration >= window_len {
        return Err(ModelsError::record(
            what(),
            format!(
                "the incident pulse lasts {:.1} us, the gauge's round trip 2 x / c only \
                 {:.1} us: the pulse overlaps its reflection",
                duration as f64 * dt * 1e6,
                round_trip * 1e6
            ),
        ));
    }
    let margin = (window_len - duration) / 2;
    let window_start = on.saturating_sub(margin);
    let window_end = window_start + window_len;
    if window_end + window_len > inc.len() {
        return Err(ModelsError::record(
            what(),
            format!(
                "the record ends {:.1} us after the incident onset, before the reflection \
                 ({:.1} us after it) has passed",
                (inc.len() - on) as f64 * dt * 1e6,
                (margin + window_len) as f64 * dt * 1e6 + round_trip * 1e6
            ),
        ));
    }
    let incident = (0..inc.len())
        .map(|k| {
            if (window_start..window_end).contains(&k) {
                inc[k]
            } else {
                0.0
            }
        })
        .collect();
    let reflected = (0..inc.len())
        .map(|k| {
            if (window_end..window_end + window_len).contains(&k) {
                inc[k]
            } else {
                0.0
            }
        })
        .collect();
    // The transmitted wave's window: the incident window moved by both bars' travel.
    let travel = test.incident.gauge_distance / test.incident.wave_speed()
        + test.transmitted.gauge_distance / test.transmitted.wave_speed();
    let t_start = window_start + (travel / dt).round() as usize;
    let transmitted = (0..tra.len())
        .map(|k| {
            if (t_start..t_start + window_len).contains(&k) {
                tra[k]
            } else {
                0.0
            }
        })
        .collect();
    let quiet = on.saturating_sub(peak_at.saturating_sub(on));
    let noise = (quiet >= MIN_QUIET).then(|| [spread(&inc[..quiet]), spread(&tra[..quiet])]);
    Ok(Separated {
        noise,
        quiet,
        dt,
        start: strains.start(),
        incident,
        reflected,
        transmitted,
        window_start,
        window_len,
        resampling,
    })
}
