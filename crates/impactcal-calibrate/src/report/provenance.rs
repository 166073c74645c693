//! Where a report came from: the program's version, the command line, the digest of the
//! configuration, the seed, the date and the wall time, as the report's last section.

use std::time::{SystemTime, UNIX_EPOCH};

use super::document::{Block, Section, Table};

/// How a report was made, written as its last section ("Provenance").
#[derive(Debug, Clone, PartialEq)]
pub struct Provenance {
    /// The program and its version, e.g. `impactcal 0.1.0`.
    pub version: String,
    /// The command line as typed (arguments joined by spaces).
    pub command: String,
    /// The digest of the configuration (model, parameters, options, test data).
    pub digest: String,
    /// The seed of every random draw.
    pub seed: u64,
    /// When the report was written, UTC, ISO 8601 (`2026-11-28T21:30:12Z`).
    pub date: String,
    /// Wall time of the whole run (s).
    pub wall_time_s: f64,
}

impl Provenance {
    /// The provenance of a run of this library's version with `command`, `digest` and
    /// `seed`, dated now, that took `wall_time_s`.
    pub fn now(command: String, digest: String, seed: u64, wall_time_s: f64) -> Self {
        Provenance {
            version: format!("impactcal {}", env!("CARGO_PKG_VERSION")),
            command,
            digest,
            seed,
            date: utc_date(SystemTime::now()),
            wall_time_s,
        }
    }

    /// The section "Provenance": one table of the six items.
    pub fn section(&self) -> Section {
        let row = |k: &str, v: String| vec![k.to_string(), v];
        Section {
            heading: "Provenance".into(),
            blocks: vec![Block::Table(Table {
                caption: "How this report was made".into(),
                header: vec!["item".into(), "value".into()],
                rows: vec![
                    row("version", self.version.clone()),
                    row("command line", self.command.clone()),
                    row("configuration digest", self.digest.clone()),
                    row("seed", self.seed.to_string()),
                    row("date (UTC)", self.date.clone()),
                    row("wall time (s)", format!("{:.0}", self.wall_time_s)),
                ],
            })],
        }
    }
}

/// `t` as an ISO 8601 UTC date and time to the second; the epoch for a time before it.
pub fn utc_date(t: SystemTime) -> String {
    let secs = t.duration_since(UNIX_EPOCH).map_or(0, |d| d.as_secs());
    let (days, rem) = (secs / 86_400, secs % 86_400);
    let (y, m, d) = civil_from_days(days as i64);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

/// The proleptic Gregorian date `(year, month, day)` of `z` days after 1970-01-01 (Howard
/// Hinnant's `civil_from_days`: eras of 400 years, years starting on 1 March).
fn civil_from_days(z: i64) -> (i64, u32, u32) {
    let z = z + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    (yoe + era * 400 + i64::from(m <= 2), m, d)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    /// Known dates: the epoch, a leap day, the turn of the century, and this one.
    #[test]
    fn dates_match_the_calendar() {
        let at = |s: u64| utc_date(UNIX_EPOCH + Duration::from_secs(s));
        assert_eq!(at(0), "1970-01-01T00:00:00Z");
        assert_eq!(at(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(at(946_684_799), "1999-12-31T23:59:59Z");
        assert_eq!(at(1_795_901_412), "2026-11-28T21:30:12Z");
    }
}
