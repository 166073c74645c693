//! Split-Hopkinson (Kolsky) bar records in the Los Alamos layout: a tab-separated file whose
//! first two columns hold the set-up as key/value rows (test, specimen, striker, and for the
//! incident and the transmitted bar their gauge factor, gains, excitation voltage, modulus,
//! density, sound speeds, gauge location) and whose last two columns hold the waveforms in
//! volts, `Incident/Reflected Waveform` and `Transmitted Waveform`, the first two rows under
//! their names being the start time and the sampling interval.

use std::path::Path;

use crate::error::{CoreError, Result};
use crate::histories::Histories;
use crate::testdata::conversion::{Bridge, Conversion};

/// A tolerance scale for comparing start times written in text (at least a picosecond).
fn dt_scale(text: &str) -> f64 {
    text.parse::<f64>().map_or(1e-12, |v| v.abs().max(1e-12))
}

/// Which bar of a Kolsky set-up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Bar {
    /// The incident (input) bar: its gauge sees the incident and the reflected wave.
    Incident,
    /// The transmitted (output) bar.
    Transmitted,
}

impl Bar {
    fn prefix(self) -> &'static str {
        match self {
            Bar::Incident => "Incident",
            Bar::Transmitted => "Transmitted",
        }
    }
}

/// A Kolsky bar record (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct LanlBarRecord {
    /// The file (for messages).
    pub file: String,
    /// The set-up rows `(key, value)` in file order (1-based line beside each).
    pub header: Vec<(String, String, usize)>,
    /// The waveforms in volts: `incident` (incident and reflected) and `transmitted`.
    pub histories: Histories,
}

impl LanlBarRecord {
    /// Reads a record file.
    ///
    /// # Errors
    /// [`CoreError::Io`] when unreadable, otherwise as [`LanlBarRecord::parse`].
    pub fn read(path: impl AsRef<Path>) -> Result<LanlBarRecord> {
        let path = path.as_ref();
        let bytes = std::fs::read(path).map_err(|source| CoreError::Io {
            path: path.display().to_string(),
            source,
        })?;
        LanlBarRecord::parse(
            &String::from_utf8_lossy(&bytes),
            &path.display().to_string(),
        )
    }

    /// Parses record text (CRLF or LF lines).
    ///
    /// # Errors
    /// [`CoreError::Csv`] naming the line and column of a line with fewer than four fields,
    /// waveform names other than the layout's, a start time or interval that is not a
    /// positive finite number (the interval) or not finite (the start), or a waveform value
    /// that does not parse; [`CoreError::Empty`] for a record without samples.
    pub fn parse(text: &str, file: &str) -> Result<LanlBarRecord> {
        let err = |line: usize, column: usize, message: String| CoreError::Csv {
            file: file.to_string(),
            row: line,
            column,
            message,
        };
        let mut header = Vec::new();
        let (mut inc, mut tra) = (Vec::new(), Vec::new());
        let (mut start, mut dt) = (f64::NAN, f64::NAN);
        let mut data_row = 0;
        for (i, raw) in text.lines().enumerate() {
            let line = i + 1;
            let raw = raw.trim_end_matches('\r');
            if raw.trim().is_empty() {
                continue;
            }
            let f: Vec<&str> = raw.split('\t').collect();
            if f.len() < 4 {
                return Err(err(
                    line,
                    f.len() + 1,
                    format!(
                        "expected four tab-separated fields (key, value, incident, \
                         transmitted), found {}",
                        f.len()
                    ),
                ));
            }
            // Descriptions may hold tabs: the waveforms are the last two fields.
            let (a, b) = (f[f.len() - 2].trim(), f[f.len() - 1].trim());
            let (ca, cb) = (f.len() - 1, f.len());
            let key = f[0].trim();
            if !key.is_empty() {
                header.push((
                    key.to_string(),
                    f[1..f.len() - 2].join("\t").trim().to_string(),
                    line,
                ));
            }
            let num = |s: &str, column: usize| -> Result<f64> {
                s.parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| err(line, column, format!("`{s}` is not a finite number")))
            };
            match data_row {
                0 => {
                    if !a.starts_with("Incident") || !b.starts_with("Transmitted") {
                        return Err(err(
                            line,
                            ca,
                            format!(
                                "expected the waveform names `Incident/Reflected Waveform` and \
                                 `Transmitted Waveform`, found `{a}` and `{b}`"
                            ),
                        ));
                    }
                }
                1 => {
                    start = num(a, ca)?;
                    if (num(b, cb)? - start).abs() > 1e-12 * start.abs().max(dt_scale(a)) {
                        return Err(err(
                            line,
                            cb,
                            "the two waveforms start at different times".into(),
                        ));
                    }
                }
                2 => {
                    dt = num(a, ca)?;
                    if dt <= 0.0 || (num(b, cb)? - dt).abs() > 1e-9 * dt {
                        return Err(err(
                            line,
                            ca,
                            format!("sampling interval {a}, {b}: must be one positive number"),
                        ));
                    }
                }
                _ => {
                    inc.push(num(a, ca)?);
                    tra.push(num(b, cb)?);
                }
            }
            data_row += 1;
        }
        if inc.is_empty() {
            return Err(CoreError::Empty {
                what: format!("{file}: a bar record without waveform samples"),
            });
        }
        let histories = Histories::from_channels(
            vec!["incident".into(), "transmitted".into()],
            vec![inc, tra],
            dt,
            start,
            "V",
        )?;
        Ok(LanlBarRecord {
            file: file.to_string(),
            header,
            histories,
        })
    }

    /// Every header value whose key is `key` (several rows may share a key).
    pub fn values(&self, key: &str) -> Vec<(&str, usize)> {
        self.header
            .iter()
            .filter(|(k, _, _)| k == key)
            .map(|(_, v, l)| (v.as_str(), *l))
            .collect()
    }

    /// The first header value of `key` as a number.
    pub fn number(&self, key: &str) -> Option<f64> {
        self.values(key).first().and_then(|(v, _)| v.parse().ok())
    }

    /// The gains the header gives for `bar`: the test row (`Incident/Reflected Bar Gain` or
    /// `Transmitted Bar Gain`) and the calibration row (`... Bar Calibrated Gain`), each
    /// with its line, when present and numeric.
    pub fn gains(&self, bar: Bar) -> Vec<(f64, usize, String)> {
        let test_key = match bar {
            Bar::Incident => "Incident/Reflected Bar Gain",
            Bar::Transmitted => "Transmitted Bar Gain",
        };
        let cal_key = format!("{} Bar Calibrated Gain", bar.prefix());
        [test_key.to_string(), cal_key]
            .iter()
            .flat_map(|k| {
                self.values(k)
                    .into_iter()
                    .filter_map(|(v, l)| v.parse::<f64>().ok().map(|g| (g, l, k.clone())))
                    .collect::<Vec<_>>()
            })
            .collect()
    }

    /// The conversion of `bar`'s gauge signal to strain, with the gain `gain` (the header
    /// may give two: see [`LanlBarRecord::gains`]), the header's gauge factor and excitation
    /// voltage, through [`LanlBarRecord::BRIDGE`]: the one reading of this record, which
    /// `impactcal-models`' `kolsky::from_lanl` uses by default too.
    ///
    /// # Errors
    /// [`CoreError::File`] naming the missing or non-numeric header row.
    pub fn bridge(&self, bar: Bar, gain: f64) -> Result<Conversion> {
        self.bridge_as(bar, gain, Self::BRIDGE)
    }

    /// How the record's gauges are read: the header does not say how they are wired; the
    /// half bridge of two opposite axial gauges ([`Bridge::HalfAxial`]) is the usual bar
    /// set-up, and with it the copper record's plateau is 2.06e-3 of strain (a striker of
    /// about 20 m/s) and its front and back forces agree (0.999), where a quarter bridge
    /// would double both strains.
    pub const BRIDGE: Bridge = Bridge::HalfAxial;

    /// [`LanlBarRecord::bridge`] through another `bridge`.
    ///
    /// # Errors
    /// As [`LanlBarRecord::bridge`].
    pub fn bridge_as(&self, bar: Bar, gain: f64, bridge: Bridge) -> Result<Conversion> {
        let p = bar.prefix();
        let need = |key: String| -> Result<f64> {
            self.number(&key).ok_or_else(|| CoreError::File {
                file: self.file.clone(),
                message: format!("no numeric header row `{key}`"),
            })
        };
        Ok(Conversion::Bridge {
            bridge,
            gauge_factor: need(format!("{p} Bar Calibrated Gage Factor"))?,
            gain,
            excitation: need(format!("{p} Bar Excitation Voltage(V)"))?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "Test Date\t12/1/2006\tIncident/Reflected Waveform\tTransmitted Waveform\r\n\
        Test Time\t11:48\t-5.00E-05\t-5.00E-05\r\n\
        System ID\tHE\t1.00E-07\t1.00E-07\r\n\
        Transmitted Bar Gain\t200\t0.5\t-0.1\r\n\
        Incident Bar Calibrated Gage Factor\t2.061\t1.5\t0.0\r\n\
        Incident Bar Excitation Voltage(V)\t8\t3.0\t0.2\r\n\
        Transmitted Bar Calibrated Gain\t500\t0.1\t0.3\r\n\
        \t\t0\t0\r\n";

    #[test]
    fn reads_header_waveforms_and_the_contradicting_gains() {
        let r = LanlBarRecord::parse(TEXT, "cu.raw").unwrap();
        let h = &r.histories;
        assert_eq!(
            h.labels(),
            &["incident".to_string(), "transmitted".to_string()]
        );
        assert_eq!(h.samples(), 5);
        assert!((h.start() + 5e-5).abs() < 1e-18 && (h.dt() - 1e-7).abs() < 1e-20);
        assert_eq!(h.channel(0), &[0.5, 1.5, 3.0, 0.1, 0.0]);
        let g = r.gains(Bar::Transmitted);
        assert_eq!(
            g.iter().map(|x| (x.0, x.1)).collect::<Vec<_>>(),
            vec![(200.0, 4), (500.0, 7)]
        );
        let c = r.bridge(Bar::Incident, 200.0).unwrap();
        let vr: f64 = 3.0 / 1600.0;
        // The half bridge of two opposite axial gauges: `2 V_r / (GF (1 - V_r))`.
        assert!((c.apply(3.0) - 2.0 * vr / (2.061 * (1.0 - vr))).abs() < 1e-15);
        let q = r.bridge_as(Bar::Incident, 200.0, Bridge::Quarter).unwrap();
        assert!((q.apply(3.0) - 4.0 * vr / (2.061 * (1.0 - 2.0 * vr))).abs() < 1e-15);
        let e = r.bridge(Bar::Transmitted, 500.0).unwrap_err().to_string();
        assert!(e.contains("Transmitted Bar Calibrated Gage Factor"), "{e}");
    }

    #[test]
    fn malformed_records_are_positioned() {
        let pos = |t: &str| match LanlBarRecord::parse(t, "x.raw").unwrap_err() {
            CoreError::Csv { row, column, .. } => (row, column),
            e => panic!("unexpected {e}"),
        };
        assert_eq!(pos("a\tb\tc\n"), (1, 4));
        assert_eq!(pos("a\tb\tX\tY\n"), (1, 3));
        let bad = TEXT.replace("1.00E-07\t1.00E-07", "0\t0");
        assert_eq!(pos(&bad), (3, 3));
        let bad = TEXT.replace("\t3.0\t", "\tthree\t");
        assert_eq!(pos(&bad), (6, 3));
        let empty = TEXT.lines().take(3).collect::<Vec<_>>().join("\n");
        assert!(LanlBarRecord::parse(&empty, "x.raw").is_err());
    }

    #[test]
    fn the_los_alamos_copper_record_reads() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../tests/data/kolsky/cu_excerpt.raw"
        );
        let r = LanlBarRecord::read(path).unwrap();
        assert_eq!(r.histories.samples(), 2000);
        assert_eq!(r.gains(Bar::Transmitted).len(), 2);
        assert!((r.number("Incident Bar Calibrated Gage Factor").unwrap() - 2.061).abs() < 1e-12);
    }
}
