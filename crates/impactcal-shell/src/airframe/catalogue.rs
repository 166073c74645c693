//! The catalogue of adjustable quantities of the airframe, the values a run uses, and the
//! presets of the source paper (Tables 1 and 2).

use impactcal_core::{Parameter, ParameterSpace};

use super::AirframePart;
use crate::error::{Result, ShellError};

/// One adjustable quantity: its name (`<part>.<field>` or a global name), nominal value,
/// a physically sensible range for studies, unit and meaning.
#[derive(Debug, Clone, PartialEq)]
pub struct Adjustable {
    /// The name, for example `belly_panel.t` or `ground.friction`.
    pub name: String,
    /// The value used unless overridden.
    pub nominal: f64,
    /// Lower end of the study range.
    pub lower: f64,
    /// Upper end of the study range.
    pub upper: f64,
    /// Unit (inch, lbf, second system).
    pub unit: &'static str,
    /// What it is.
    pub description: String,
    /// Its kind: `condition` (impact speeds, attitude), `friction`, `damping`,
    /// `strain-rate` (Cowper-Symonds constants), `mass`, `thickness` or `material` (a part's
    /// `E`, `Et`, `sigy`).
    pub group: &'static str,
}

impl Adjustable {
    /// The quantity as a core [`Parameter`] with its range and nominal value.
    ///
    /// # Errors
    /// Never for catalogue entries (their ranges are valid); the core check is kept.
    pub fn parameter(&self) -> Result<Parameter> {
        Ok(
            Parameter::new(self.name.clone(), self.lower, self.upper, self.nominal)?
                .with_unit(self.unit),
        )
    }
}

/// Aluminium 2024-T3 in lbf, inch, second units.
pub(crate) struct MaterialData {
    pub density: f64,
    pub poisson: f64,
    pub youngs: f64,
    pub tangent: f64,
    pub yield_stress: f64,
    /// Whether Cowper-Symonds rate scaling applies (metals only).
    pub rate_sensitive: bool,
}

const ALUMINIUM: MaterialData = MaterialData {
    density: 2.59e-4,
    poisson: 0.33,
    youngs: 1.0e7,
    tangent: 134_200.0,
    yield_stress: 47_000.0,
    rate_sensitive: true,
};

const FIBREGLASS: MaterialData = MaterialData {
    density: 1.75e-4,
    poisson: 0.2,
    youngs: 2.5e6,
    tangent: 2.5e5,
    yield_stress: 30_000.0,
    rate_sensitive: false,
};

const KEVLAR: MaterialData = MaterialData {
    density: 1.30e-4,
    poisson: 0.25,
    youngs: 3.5e6,
    tangent: 3.5e5,
    yield_stress: 40_000.0,
    rate_sensitive: false,
};

impl AirframePart {
    /// The material data and nominal thickness of the part.
    pub(crate) fn nominal(self) -> (MaterialData, f64) {
        use AirframePart as P;
        let al = |e: f64, t: f64| {
            (
                MaterialData {
                    youngs: e,
                    ..ALUMINIUM
                },
                t,
            )
        };
        match self {
            P::Nose => (FIBREGLASS, 0.060),
            P::CabinFloor => al(1.0e7, 0.040),
            P::BellyPanel => al(1.0e7, 0.090),
            P::KeelBeamWeb => al(9.88e6, 0.040),
            P::KeelBeamStiffener => al(1.0e7, 0.020),
            P::SubfloorRibs => al(1.0e7, 0.032),
            P::SideSkins => al(1.0e7, 0.025),
            P::Roof => al(1.0e7, 0.032),
            P::BackPanel => al(1.0e7, 0.020),
            P::EngineFairing => (KEVLAR, 0.050),
            P::TailBoom => al(1.0e7, 0.040),
            P::UpperTail => al(1.0e7, 0.020),
            P::LowerTail => al(1.0e7, 0.040),
            P::HorizontalStabilizer => al(1.0e7, 0.032),
        }
    }
}

/// Nominal concentrated masses (lbf s^2/in; weight / 386.09 in/s^2).
pub(crate) const MASSES: [(&str, f64, &str); 5] = [
    (
        "rotor_transmission",
        0.55,
        "main rotor, mast and transmission over the roof at the back panel",
    ),
    ("engine", 0.25, "engine on the lower engine fairing"),
    ("fuel", 0.30, "fuel over the aft cabin floor"),
    (
        "occupants",
        0.70,
        "seats and occupants over the cabin floor",
    ),
    (
        "tail",
        0.07,
        "tail rotor, gearbox and equipment at the end of the tail boom",
    ),
];

/// The 386.09 in/s^2 of standard gravity.
pub const GRAVITY: f64 = 386.088;

/// `v * f` rounded to 12 significant digits, so that +-20 % bounds print as written.
fn scaled(v: f64, f: f64) -> f64 {
    format!("{:.11e}", v * f).parse().unwrap_or(v * f)
}

/// The full catalogue, in a fixed order: the globals, the concentrated masses, then each
/// part's `t`, `E`, `Et`, `sigy`.
///
/// Ranges: +-20 % about the nominal for moduli, thicknesses, yield stresses and masses
/// (the source paper's Table 1 width), with the paper's own bounds where it gives them (the
/// Table 2 thicknesses); the globals as stated on each entry.
pub fn catalogue() -> Vec<Adjustable> {
    let mut c = Vec::new();
    let mut add = |name: &str, nominal: f64, lower: f64, upper: f64, unit, d: String| {
        c.push(Adjustable {
            name: name.to_string(),
            nominal,
            lower,
            upper,
            unit,
            description: d,
            group: group_of(name),
        });
    };
    add(
        "impact.vertical",
        312.0,
        240.0,
        384.0,
        "in/s",
        "sink speed at first contact (26 ft/s)".into(),
    );
    add(
        "impact.horizontal",
        480.0,
        0.0,
        600.0,
        "in/s",
        "forward speed at first contact (40 ft/s)".into(),
    );
    add(
        "attitude.pitch",
        0.0,
        -10.0,
        10.0,
        "deg",
        "nose-up pitch at contact".into(),
    );
    add(
        "attitude.roll",
        0.0,
        -10.0,
        10.0,
        "deg",
        "right-side-down roll at contact".into(),
    );
    add(
        "ground.friction",
        0.3,
        0.0,
        0.8,
        "",
        "Coulomb friction coefficient of the rigid ground".into(),
    );
    add(
        "damping",
        0.0,
        0.0,
        50.0,
        "1/s",
        "mass-proportional damping constant".into(),
    );
    add(
        "rate.c",
        6500.0,
        1000.0,
        100_000.0,
        "1/s",
        "Cowper-Symonds rate constant C of the aluminium parts".into(),
    );
    add(
        "rate.p",
        4.0,
        2.0,
        8.0,
        "",
        "Cowper-Symonds exponent p of the aluminium parts".into(),
    );
    for (name, m, d) in MASSES {
        add(
            &format!("mass.{name}"),
            m,
            scaled(m, 0.8),
            scaled(m, 1.2),
            "lbf s^2/in",
            d.into(),
        );
    }
    for part in AirframePart::ALL {
        let (mat, t) = part.nominal();
        let p = part.name();
        let (tl, tu) = table2_bounds(part).unwrap_or((scaled(t, 0.8), scaled(t, 1.2)));
        add(
            &format!("{p}.t"),
            t,
            tl,
            tu,
            "in",
            format!("{} thickness", part.label()),
        );
        add(
            &format!("{p}.E"),
            mat.youngs,
            scaled(mat.youngs, 0.8),
            scaled(mat.youngs, 1.2),
            "lbf/in^2",
            format!("{} Young's modulus", part.label()),
        );
        add(
            &format!("{p}.Et"),
            mat.tangent,
            scaled(mat.tangent, 0.8),
            scaled(mat.tangent, 1.2),
            "lbf/in^2",
            format!("{} tangent modulus", part.label()),
        );
        add(
            &format!("{p}.sigy"),
            mat.yield_stress,
            scaled(mat.yield_stress, 0.8),
            scaled(mat.yield_stress, 1.2),
            "lbf/in^2",
            format!("{} yield stress", part.label()),
        );
    }
    c
}

/// The group of a catalogue name (see [`Adjustable::group`]).
fn group_of(name: &str) -> &'static str {
    match name.split_once('.').map_or(name, |(head, _)| head) {
        "impact" | "attitude" => "condition",
        "ground" => "friction",
        "damping" => "damping",
        "rate" => "strain-rate",
        "mass" => "mass",
        _ if name.ends_with(".t") => "thickness",
        _ => "material",
    }
}

/// The thickness bounds of the source paper's Table 2, where it gives them.
fn table2_bounds(part: AirframePart) -> Option<(f64, f64)> {
    use AirframePart as P;
    match part {
        P::KeelBeamStiffener | P::BackPanel | P::UpperTail => Some((0.015, 0.025)),
        P::BellyPanel => Some((0.08, 0.135)),
        P::KeelBeamWeb | P::LowerTail => Some((0.035, 0.045)),
        _ => None,
    }
}

/// The parameter sets of the source paper.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Preset {
    /// Table 1, the initial set: five moduli and three tangent moduli (+-20 %).
    Table1,
    /// Table 2, the revised set: six thicknesses with the paper's bounds.
    Table2,
}

impl Preset {
    /// The preset's names, in the order of the paper's table.
    pub fn names(self) -> &'static [&'static str] {
        match self {
            Preset::Table1 => &[
                "back_panel.E",
                "subfloor_ribs.E",
                "keel_beam_web.E",
                "upper_tail.E",
                "lower_tail.E",
                "subfloor_ribs.Et",
                "keel_beam_web.Et",
                "lower_tail.Et",
            ],
            Preset::Table2 => &[
                "keel_beam_stiffener.t",
                "belly_panel.t",
                "keel_beam_web.t",
                "lower_tail.t",
                "back_panel.t",
                "upper_tail.t",
            ],
        }
    }

    /// The preset as a parameter space (catalogue nominal values and ranges).
    ///
    /// # Errors
    /// Never for the built-in presets.
    pub fn space(self) -> Result<ParameterSpace> {
        space_of(self.names())
    }

    /// Parses `table1` / `table2` (case-insensitive).
    ///
    /// # Errors
    /// [`ShellError::Value`] for any other name.
    pub fn parse(name: &str) -> Result<Preset> {
        match name.to_ascii_lowercase().as_str() {
            "table1" => Ok(Preset::Table1),
            "table2" => Ok(Preset::Table2),
            _ => Err(ShellError::value(
                "airframe preset",
                format!("`{name}` is not a preset (table1, table2)"),
            )),
        }
    }
}

/// The structural quantities of the catalogue: the five concentrated masses and every part's
/// `t`, `E`, `Et` and `sigy`, in catalogue order (61 quantities). These make up "the model"
/// as opposed to the test conditions (impact, attitude, ground) and the solver settings,
/// and are what a jitter ensemble perturbs to measure the airframe's own noise.
///
/// # Errors
/// Never (the catalogue's ranges are valid).
pub fn structural_space() -> Result<ParameterSpace> {
    let names: Vec<String> = catalogue()
        .into_iter()
        .map(|a| a.name)
        .filter(|n| {
            n.starts_with("mass.") || [".t", ".E", ".Et", ".sigy"].iter().any(|f| n.ends_with(f))
        })
        .collect();
    space_of(&names)
}

/// A parameter space of catalogue entries by name, with their nominal values and ranges.
///
/// # Errors
/// [`ShellError::Value`] for a name not in the catalogue; core errors for repeated names.
pub fn space_of<S: AsRef<str>>(names: &[S]) -> Result<ParameterSpace> {
    let cat = catalogue();
    let params = names
        .iter()
        .map(|n| {
            let n = n.as_ref();
            cat.iter()
                .find(|a| a.name == n)
                .ok_or_else(|| unknown(n))
                .and_then(Adjustable::parameter)
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(ParameterSpace::new(params)?)
}

fn unknown(name: &str) -> ShellError {
    ShellError::value(
        format!("airframe quantity `{name}`"),
        "not in the catalogue (`impactcal airframe --list` prints it)",
    )
}

/// The values of every catalogue quantity for one run, nominal unless set.
#[derive(Debug, Clone, PartialEq)]
pub struct AirframeValues {
    names: Vec<String>,
    values: Vec<f64>,
}

impl Default for AirframeValues {
    fn default() -> Self {
        Self::nominal()
    }
}

impl AirframeValues {
    /// Every quantity at its nominal value.
    pub fn nominal() -> Self {
        let cat = catalogue();
        AirframeValues {
            names: cat.iter().map(|a| a.name.clone()).collect(),
            values: cat.iter().map(|a| a.nominal).collect(),
        }
    }

    /// The value of `name`.
    ///
    /// # Errors
    /// [`ShellError::Value`] for a name not in the catalogue.
    pub fn get(&self, name: &str) -> Result<f64> {
        self.index(name).map(|i| self.values[i])
    }

    /// Sets `name` to `value` (which may lie outside the study range; physical validity,
    /// such as a positive thickness or `Et < E`, is checked when the model is built).
    ///
    /// # Errors
    /// [`ShellError::Value`] for an unknown name or a non-finite value.
    pub fn set(&mut self, name: &str, value: f64) -> Result<()> {
        let i = self.index(name)?;
        if !value.is_finite() {
            return Err(ShellError::value(
                format!("airframe quantity `{name}`"),
                format!("value {value} is not finite"),
            ));
        }
        self.values[i] = value;
        Ok(())
    }

    /// Applies an assignment `name=value`, as given on the command line.
    ///
    /// # Errors
    /// [`ShellError::Value`] when there is no `=`, the value does not parse, or as
    /// [`set`](Self::set).
    pub fn assign(&mut self, text: &str) -> Result<()> {
        let (name, value) = text.split_once('=').ok_or_else(|| {
            ShellError::value(
                format!("assignment `{text}`"),
                "expected <name>=<value>, for example belly_panel.t=0.1",
            )
        })?;
        let v: f64 = value.trim().parse().map_err(|_| {
            ShellError::value(
                format!("assignment `{text}`"),
                format!("`{}` is not a number", value.trim()),
            )
        })?;
        self.set(name.trim(), v)
    }

    /// Sets the points of `space` (names must be catalogue names) from `point`.
    ///
    /// # Errors
    /// As [`set`](Self::set), and a dimension mismatch.
    pub fn set_point(&mut self, space: &ParameterSpace, point: &[f64]) -> Result<()> {
        if point.len() != space.dim() {
            return Err(impactcal_core::CoreError::DimensionMismatch {
                what: "airframe parameter vector".into(),
                expected: space.dim(),
                found: point.len(),
            }
            .into());
        }
        for (p, &v) in space.parameters().iter().zip(point) {
            self.set(&p.name, v)?;
        }
        Ok(())
    }

    /// `(name, value)` pairs in catalogue order.
    pub fn iter(&self) -> impl Iterator<Item = (&str, f64)> {
        self.names
            .iter()
            .map(String::as_str)
            .zip(self.values.iter().copied())
    }

    /// Applies an assignment `name=value` as [`assign`](Self::assign) does, and refuses a
    /// value outside the quantity's study range in the catalogue (`lower..=upper`), which
    /// is the range the airframe is meant to run in (a value far outside, such as a
    /// thickness of `1e9`, makes the explicit solver unstable rather than giving an answer).
    ///
    /// # Errors
    /// As [`assign`](Self::assign); [`ShellError::Value`] naming the quantity, the value and
    /// its range with the unit.
    pub fn assign_in_range(&mut self, text: &str) -> Result<()> {
        let mut changed = self.clone();
        changed.assign(text)?;
        let name = text.split_once('=').map_or(text, |(n, _)| n).trim();
        let value = changed.get(name)?;
        if let Some(a) = catalogue().into_iter().find(|a| a.name == name)
            && !(a.lower <= value && value <= a.upper)
        {
            return Err(ShellError::value(
                format!("airframe quantity `{name}`"),
                format!(
                    "{value} lies outside its range {} to {} {} (nominal {}); give a value in \
                     that range (`impactcal airframe --list` lists every range)",
                    a.lower, a.upper, a.unit, a.nominal
                ),
            ));
        }
        *self = changed;
        Ok(())
    }

    fn index(&self, name: &str) -> Result<usize> {
        self.names
            .iter()
            .position(|n| n == name)
            .ok_or_else(|| unknown(name))
    }

    /// The value of a field of a part (catalogue names are always present).
    pub(crate) fn part(&self, part: AirframePart, field: &str) -> f64 {
        self.get(&format!("{}.{field}", part.name()))
            .unwrap_or(f64::NAN)
    }

    /// The value of a global (catalogue names are always present).
    pub(crate) fn global(&self, name: &str) -> f64 {
        self.get(name).unwrap_or(f64::NAN)
    }
}
