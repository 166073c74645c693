//! The Los Alamos bar record ([`LanlBarRecord`] of `impactcal-core`) converted into the
//! neutral test form ([`KolskyTest`]).
//!
//! The header's rows map to the form's keys (`<Bar> Bar Young's Modulus(GPa)` to `modulus`
//! in Pa, `... Density(kg/m^3)` to `density`, `... Poisson Ratio`, `... Diameter(mm)`,
//! `... Strain Gage Location(mm)` to `gauge_distance`, `... Calibrated Gage Factor`,
//! `... Excitation Voltage(V)`; the incident bar's `Reflected Time Sound Speed(m/s)`, a
//! measured speed, to `wave_speed` of both bars when the transmitted bar has none;
//! `Initial Sample Diameter(mm)`, `Initial Sample Length(mm)`, `Striker Length(mm)`). What
//! the header does not say the caller chooses ([`LanlOptions`]): the bridge, the polarity,
//! which of the header's gain rows to believe, and the specimen's density.
//!
//! Two checks a bar engineer would make are made, and their outcome is reported in
//! [`LanlConversion::notes`]:
//! - the density against the header's rod sound speed: a density that gives
//!   `sqrt(E / rho)` a thousandfold too slow was written in g/cm^3 whatever its label says,
//!   and is read as such (the copper record writes `4.416` under `kg/m^3` beside a rod
//!   speed of 4,975 m/s, which `4,416 kg/m^3` gives);
//! - the gain rows: when a bar has two that differ, the conversion uses the one the options
//!   name and says that the other exists.

use impactcal_core::testdata::LanlBarRecord;
use impactcal_core::testdata::lanl_bar::Bar;

use crate::error::{ModelsError, Result};
use crate::kolsky::form::{BarSetup, GaugeBridge, KolskyTest, Section, SpecimenSetup};

/// Which of a bar's gain rows to use.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GainRow {
    /// The test row (`Incident/Reflected Bar Gain`, `Transmitted Bar Gain`).
    Test,
    /// The calibration row (`<Bar> Bar Calibrated Gain`).
    Calibrated,
}

/// What the Los Alamos header does not say.
#[derive(Debug, Clone, PartialEq)]
pub struct LanlOptions {
    /// How the gauges are wired (the header does not say; the default is
    /// [`GaugeBridge::Half`], two opposite axial gauges, the usual bar set-up: the reading
    /// of `LanlBarRecord::BRIDGE` in `impactcal-core`, so that both read a record alike).
    pub bridge: GaugeBridge,
    /// `+1` when compression reads positive in volts (as in the copper record, whose
    /// incident pulse is positive), `-1` otherwise.
    pub polarity: f64,
    /// The gain row of the incident bar.
    pub incident_gain: GainRow,
    /// The gain row of the transmitted bar.
    pub transmitted_gain: GainRow,
    /// The specimen's density (kg/m^3); the header names the material but gives none.
    pub specimen_density: f64,
}

impl Default for LanlOptions {
    /// Half bridge, compression positive, the test gain rows, copper's density 8,960 kg/m^3.
    fn default() -> Self {
        LanlOptions {
            bridge: GaugeBridge::Half,
            polarity: 1.0,
            incident_gain: GainRow::Test,
            transmitted_gain: GainRow::Test,
            specimen_density: 8960.0,
        }
    }
}

/// A converted record and what the conversion found and decided.
#[derive(Debug, Clone)]
pub struct LanlConversion {
    /// The test in the neutral form (channels `incident` and `transmitted`).
    pub test: KolskyTest,
    /// What the conversion decided from the physics where the header contradicts itself
    /// or is mislabelled, one sentence each.
    pub notes: Vec<String>,
}

/// Converts a Los Alamos record (see the module docs).
///
/// # Errors
/// [`ModelsError::Key`] naming the file and the header row that is missing or not a
/// positive number (or the gain row the options ask for); [`ModelsError::Invalid`] for a
/// polarity other than +-1 or a specimen density that is not positive.
pub fn from_lanl(record: &LanlBarRecord, options: &LanlOptions) -> Result<LanlConversion> {
    if options.polarity.abs().to_bits() != 1.0_f64.to_bits() {
        return Err(ModelsError::invalid(
            "polarity",
            options.polarity,
            "must be 1 or -1",
        ));
    }
    if !(options.specimen_density.is_finite() && options.specimen_density > 0.0) {
        return Err(ModelsError::invalid(
            "specimen_density",
            options.specimen_density,
            "must be positive (kg/m^3)",
        ));
    }
    let missing = |key: &str, message: &str| ModelsError::Key {
        file: record.file.clone(),
        key: key.to_string(),
        message: message.to_string(),
    };
    let positive = |key: &str| -> Result<f64> {
        match record.number(key) {
            Some(v) if v.is_finite() && v > 0.0 => Ok(v),
            Some(v) => Err(missing(key, &format!("{v} is not a positive number"))),
            None => Err(missing(key, "no numeric header row")),
        }
    };
    let mut notes = Vec::new();
    let measured = record
        .number("Incident Bar Reflected Time Sound Speed(m/s)")
        .filter(|c| c.is_finite() && *c > 0.0);
    let mut bar = |which: Bar, gain_row: GainRow| -> Result<BarSetup> {
        let p = match which {
            Bar::Incident => "Incident",
            Bar::Transmitted => "Transmitted",
        };
        let modulus = positive(&format!("{p} Bar Young's Modulus(GPa)"))? * 1e9;
        let mut density = positive(&format!("{p} Bar Density(kg/m^3)"))?;
        if let Some(rod) = record.number(&format!("{p} Bar Rod Sound Speed(m/s)")) {
            let as_given = (modulus / density).sqrt();
            let as_gcc = (modulus / (1000.0 * density)).sqrt();
            if (as_given / rod - 1.0).abs() > 0.01 && (as_gcc / rod - 1.0).abs() <= 0.01 {
                notes.push(format!(
                    "{p} bar: the density row reads {density} `kg/m^3`, which with the \
                     modulus gives a rod speed of {as_given:.0} m/s against the header's \
                     {rod:.0} m/s; read as g/cm^3 ({} kg/m^3, rod speed {as_gcc:.0} m/s)",
                    density * 1000.0
                ));
                density *= 1000.0;
            }
        }
        let gains = record.gains(which);
        let wanted = match gain_row {
            GainRow::Test => "test",
            GainRow::Calibrated => "calibration",
        };
        let pick = gains
            .iter()
            .find(|(_, _, key)| key.contains("Calibrated") == (gain_row == GainRow::Calibrated))
            .ok_or_else(|| missing(&format!("{p} gain"), &format!("no {wanted} gain row")))?;
        for (g, line, key) in &gains {
            if g.to_bits() != pick.0.to_bits() {
                notes.push(format!(
                    "{p} bar: the header gives two gains, {} (`{}`, line {}) and {g} (`{key}`, \
                     line {line}); the {wanted} row, {}, is used",
                    pick.0, pick.2, pick.1, pick.0
                ));
            }
        }
        Ok(BarSetup {
            modulus,
            density,
            poisson: positive(&format!("{p} Bar Poisson Ratio"))?,
            section: Section::Round {
                diameter: positive(&format!("{p} Bar Diameter(mm)"))? * 1e-3,
            },
            wave_speed: measured,
            gauge_distance: positive(&format!("{p} Bar Strain Gage Location(mm)"))? * 1e-3,
            gauge_factor: positive(&format!("{p} Bar Calibrated Gage Factor"))?,
            gain: pick.0,
            excitation: positive(&format!("{p} Bar Excitation Voltage(V)"))?,
            bridge: options.bridge,
            polarity: options.polarity,
            channels: vec![
                match which {
                    Bar::Incident => "incident",
                    Bar::Transmitted => "transmitted",
                }
                .to_string(),
            ],
        })
    };
    let incident = bar(Bar::Incident, options.incident_gain)?;
    let transmitted = bar(Bar::Transmitted, options.transmitted_gain)?;
    if let Some(c) = measured {
        notes.push(format!(
            "wave speed: the incident bar's reflection-time speed, {c} m/s, for both bars (the \
             rod speed from modulus and density is {:.1} m/s)",
            incident.rod_speed()
        ));
    }
    let specimen = SpecimenSetup {
        section: Section::Round {
            diameter: positive("Initial Sample Diameter(mm)")? * 1e-3,
        },
        length: positive("Initial Sample Length(mm)")? * 1e-3,
        density: options.specimen_density,
    };
    let striker_length = record
        .number("Striker Length(mm)")
        .filter(|l| l.is_finite() && *l > 0.0)
        .map(|l| l * 1e-3);
    Ok(LanlConversion {
        test: KolskyTest {
            incident,
            transmitted,
            specimen,
            striker_length,
            signals: record.histories.clone(),
            source: format!("{} (Los Alamos layout, converted)", record.file),
        },
        notes,
    })
}
