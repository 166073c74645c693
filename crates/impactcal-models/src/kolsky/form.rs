//! The neutral Kolsky bar test form: a TOML file in SI units that describes the bars, their
//! gauges, the specimen and the striker, and names a signals file in volts, as recorded.
//!
//! ```toml
//! [incident]                  # the incident bar and its gauges
//! modulus = 109.3e9           # Pa
//! density = 4416.0            # kg/m^3
//! poisson = 0.33
//! diameter = 9.47e-3          # m; a square bar gives `side` instead
//! wave_speed = 4866.0         # m/s, optional (default sqrt(modulus / density))
//! gauge_distance = 0.381      # m, from the gauge to the specimen face
//! gauge_factor = 2.061
//! gain = 200.0
//! excitation = 8.0            # V
//! bridge = "half"             # "quarter", "half" or "full"
//! polarity = 1                # +1 if compression reads positive in volts, else -1
//! channels = ["inc"]          # columns of the signals file; two are opposite gauges, averaged
//! [transmitted]               # the same keys
//! [specimen]
//! diameter = 6.34e-3          # or `width` and `depth` for a rectangular specimen
//! length = 3.204e-3
//! density = 8960.0
//! [striker]                   # optional
//! length = 0.127
//! [signals]
//! file = "signals.csv"        # `time,<channel>,...` in seconds and volts, as recorded
//! ```
//!
//! The signals file is read relative to the test file's folder. Unknown keys are refused
//! (a misspelt optional key would otherwise be silently ignored).
//!
//! **Bridges.** With the bridge ratio `V_r = polarity V / (G V_ex)` (`V` the amplified
//! output, `G` the gain, `V_ex` the excitation) and the gauge factor `GF`, the compressive
//! strain is `-epsilon` of:
//! - `quarter`: one axial gauge, [`Bridge::Quarter`] of `impactcal-core`:
//!   `epsilon = 4 V_r / (GF (1 - 2 V_r))`;
//! - `half`: two axial gauges on opposite faces of the bar in opposite arms of the bridge
//!   (the usual bar set-up; bending cancels): the arm resistances `R (1 + GF epsilon)` in
//!   arms 1 and 3 give `V_r = GF epsilon / (2 + GF epsilon)`, so
//!   `epsilon = 2 V_r / (GF (1 - V_r))` (exact; core's linear half-bridge forms differ from
//!   it by the factor `1 - V_r`);
//! - `full`: two axial and two transverse gauges, [`Bridge::FullPoisson`] with the bar's
//!   Poisson ratio: `epsilon = 2 V_r / (GF ((1 + nu) - V_r (1 - nu)))`.
//!
//! The sign: a bridge reads positive in tension, so `polarity = +1` (compression reads
//! positive in volts) means the bridge is wired the other way; the form's `polarity` says
//! which, and the converted strain is compression positive either way.

use std::path::{Path, PathBuf};

use impactcal_core::Histories;
use impactcal_core::testdata::Bridge;

use crate::error::{ModelsError, Result};
use crate::keys::Keys;

/// How the gauges of a bar are wired (see the module docs for the equations).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GaugeBridge {
    /// One axial gauge.
    Quarter,
    /// Two axial gauges on opposite faces, in opposite arms.
    Half,
    /// Two axial and two transverse gauges.
    Full,
}

impl GaugeBridge {
    /// The name written in the test form.
    pub fn as_str(self) -> &'static str {
        match self {
            GaugeBridge::Quarter => "quarter",
            GaugeBridge::Half => "half",
            GaugeBridge::Full => "full",
        }
    }

    /// The tensile strain a bridge ratio `vr` gives (the module docs' equations), for gauge
    /// factor `gf` and the bar's Poisson ratio `nu` (used by `full` only).
    pub fn strain(self, vr: f64, gf: f64, nu: f64) -> f64 {
        self.core(nu).strain(vr, gf)
    }

    /// The bridge of `impactcal-core`'s conversions this wiring is, on a bar of Poisson
    /// ratio `nu`: `quarter` [`Bridge::Quarter`], `half` [`Bridge::HalfAxial`], `full`
    /// [`Bridge::FullPoisson`].
    pub fn core(self, nu: f64) -> Bridge {
        match self {
            GaugeBridge::Quarter => Bridge::Quarter,
            GaugeBridge::Half => Bridge::HalfAxial,
            GaugeBridge::Full => Bridge::FullPoisson { poisson: nu },
        }
    }
}

/// The cross-section of a bar or a specimen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Section {
    /// A circle of this diameter (m).
    Round {
        /// Diameter (m).
        diameter: f64,
    },
    /// A rectangle (a square bar has `width == depth`), m.
    Rectangle {
        /// Width (m).
        width: f64,
        /// Depth (m).
        depth: f64,
    },
}

impl Section {
    /// The area (m^2): `pi d^2 / 4` or `w h`.
    pub fn area(&self) -> f64 {
        match *self {
            Section::Round { diameter } => std::f64::consts::PI * diameter * diameter / 4.0,
            Section::Rectangle { width, depth } => width * depth,
        }
    }

    /// The radius of the round section, or of the round section of equal area (m).
    pub fn radius(&self) -> f64 {
        (self.area() / std::f64::consts::PI).sqrt()
    }
}

/// One bar with its gauges.
#[derive(Debug, Clone, PartialEq)]
pub struct BarSetup {
    /// Young's modulus `E` (Pa).
    pub modulus: f64,
    /// Density `rho` (kg/m^3).
    pub density: f64,
    /// Poisson's ratio `nu`.
    pub poisson: f64,
    /// The section.
    pub section: Section,
    /// The measured wave speed (m/s), when the test gives one.
    pub wave_speed: Option<f64>,
    /// Distance from the gauge to the specimen face (m).
    pub gauge_distance: f64,
    /// Gauge factor `GF`.
    pub gauge_factor: f64,
    /// Amplifier gain `G`.
    pub gain: f64,
    /// Bridge excitation `V_ex` (V).
    pub excitation: f64,
    /// How the gauges are wired.
    pub bridge: GaugeBridge,
    /// `+1.0` when compression reads positive in volts, `-1.0` otherwise.
    pub polarity: f64,
    /// The columns of the signals file this bar's gauges were recorded in (one, or two
    /// opposite gauges that are averaged).
    pub channels: Vec<String>,
}

impl BarSetup {
    /// The wave speed (m/s): the measured one when given, else the rod speed
    /// `c0 = sqrt(E / rho)`.
    pub fn wave_speed(&self) -> f64 {
        self.wave_speed
            .unwrap_or_else(|| (self.modulus / self.density).sqrt())
    }

    /// The rod speed `c0 = sqrt(E / rho)` (m/s).
    pub fn rod_speed(&self) -> f64 {
        (self.modulus / self.density).sqrt()
    }

    /// The section's area `A` (m^2).
    pub fn area(&self) -> f64 {
        self.section.area()
    }

    /// The mechanical impedance `Z = E A / c` (kg/s) with the bar's wave speed: a wave of
    /// particle velocity `v` carries the force `Z v`.
    pub fn impedance(&self) -> f64 {
        self.modulus * self.area() / self.wave_speed()
    }

    /// The compressive strain a gauge reading of `volts` gives (see the module docs).
    pub fn strain(&self, volts: f64) -> f64 {
        let vr = -self.polarity * volts / (self.gain * self.excitation);
        -self.bridge.strain(vr, self.gauge_factor, self.poisson)
    }
}

/// The specimen.
#[derive(Debug, Clone, PartialEq)]
pub struct SpecimenSetup {
    /// The section before the test.
    pub section: Section,
    /// The length before the test (m).
    pub length: f64,
    /// Density (kg/m^3).
    pub density: f64,
}

/// A Kolsky bar test: the set-up and the signals as recorded.
#[derive(Debug, Clone, PartialEq)]
pub struct KolskyTest {
    /// The incident bar.
    pub incident: BarSetup,
    /// The transmitted bar.
    pub transmitted: BarSetup,
    /// The specimen.
    pub specimen: SpecimenSetup,
    /// The striker's length (m), when given.
    pub striker_length: Option<f64>,
    /// The signals in volts, as recorded (the channels the bars name, maybe others).
    pub signals: Histories,
    /// Where the test came from (a file, or a description of a conversion).
    pub source: String,
}

/// The two gauge strains of a test, compression positive, on the signals' time base:
/// channel `incident` (incident and reflected waves) and `transmitted`.
pub const STRAIN_CHANNELS: [&str; 2] = ["incident", "transmitted"];

impl KolskyTest {
    /// Reads a test file (see the module docs); the signals file is read relative to its
    /// folder.
    ///
    /// # Errors
    /// [`ModelsError::Io`] when the file cannot be read; otherwise as [`KolskyTest::parse`].
    pub fn read(path: impl AsRef<Path>) -> Result<KolskyTest> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| ModelsError::Io {
            path: path.display().to_string(),
            source,
        })?;
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        KolskyTest::parse(&text, &path.display().to_string(), &dir)
    }

    /// Parses test text named `file`, reading the signals file relative to `dir`.
    ///
    /// # Errors
    /// [`ModelsError::Toml`] for text that is not TOML; [`ModelsError::Key`] naming the file
    /// and key for: a missing key or table, a value of the wrong type, an unknown key, a
    /// modulus, density, length, distance, gauge factor, gain or excitation that is not
    /// positive and finite, a Poisson ratio outside (-1, 0.5), a polarity other than +1 or
    /// -1, an unknown bridge, a bar or specimen with both or neither of its section keys,
    /// no channel or more than two, a channel not in the signals file; the core error of
    /// the signals file (unreadable, malformed CSV), with its path.
    pub fn parse(text: &str, file: &str, dir: &Path) -> Result<KolskyTest> {
        let root: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| ModelsError::Toml {
                file: file.to_string(),
                message: e.to_string().trim().to_string(),
            })?;
        let r = Keys { file };
        r.known(
            &root,
            "",
            &["incident", "transmitted", "specimen", "striker", "signals"],
        )?;
        let incident = r.bar(r.table(&root, "", "incident")?, "incident")?;
        let transmitted = r.bar(r.table(&root, "", "transmitted")?, "transmitted")?;
        let spec = r.table(&root, "", "specimen")?;
        r.known(
            spec,
            "specimen",
            &["diameter", "width", "depth", "length", "density"],
        )?;
        let specimen = SpecimenSetup {
            section: r.section(spec, "specimen", "diameter", &["width", "depth"])?,
            length: r.positive(spec, "specimen", "length")?,
            density: r.positive(spec, "specimen", "density")?,
        };
        let striker_length = match root.get("striker") {
            None => None,
            Some(_) => {
                let s = r.table(&root, "", "striker")?;
                r.known(s, "striker", &["length"])?;
                Some(r.positive(s, "striker", "length")?)
            }
        };
        let sig = r.table(&root, "", "signals")?;
        r.known(sig, "signals", &["file"])?;
        let name = r.string(sig, "signals", "file")?;
        let path: PathBuf = dir.join(&name);
        let signals = Histories::read_csv(&path)?;
        for (bar, label) in [(&incident, "incident"), (&transmitted, "transmitted")] {
            for ch in &bar.channels {
                if signals.index_of(ch).is_none() {
                    return Err(r.key(
                        &format!("{label}.channels"),
                        format!(
                            "channel `{ch}` is not a column of the signals file {} (columns: {})",
                            path.display(),
                            signals.labels().join(", ")
                        ),
                    ));
                }
            }
        }
        Ok(KolskyTest {
            incident,
            transmitted,
            specimen,
            striker_length,
            signals,
            source: file.to_string(),
        })
    }

    /// The gauge strains, compression positive, on the signals' time base: channels
    /// [`STRAIN_CHANNELS`], each the average of its bar's channels converted by the bar's
    /// bridge (see the module docs).
    ///
    /// # Errors
    /// [`ModelsError::Core`] when a bar names a channel the signals do not hold.
    pub fn strains(&self) -> Result<Histories> {
        let mut out = Vec::with_capacity(2);
        for bar in [&self.incident, &self.transmitted] {
            let mut sum = vec![0.0; self.signals.samples()];
            for ch in &bar.channels {
                for (s, v) in sum.iter_mut().zip(self.signals.channel_by_label(ch)?) {
                    *s += bar.strain(*v);
                }
            }
            let n = bar.channels.len().max(1) as f64;
            out.push(sum.into_iter().map(|s| s / n).collect());
        }
        Ok(Histories::from_channels(
            STRAIN_CHANNELS.iter().map(|s| s.to_string()).collect(),
            out,
            self.signals.dt(),
            self.signals.start(),
            "1",
        )?)
    }

    /// Writes the test in the neutral form: `<dir>/<stem>.toml` and its signals file
    /// `<dir>/<stem>-signals.csv` (every value written so that it reads back bit for bit).
    ///
    /// # Errors
    /// [`ModelsError::Io`] when a file cannot be written.
    pub fn write(&self, dir: impl AsRef<Path>, stem: &str) -> Result<PathBuf> {
        let dir = dir.as_ref();
        let io = |path: &Path| {
            let p = path.display().to_string();
            move |source| ModelsError::Io { path: p, source }
        };
        let csv_name = format!("{stem}-signals.csv");
        let csv_path = dir.join(&csv_name);
        let file = std::fs::File::create(&csv_path).map_err(io(&csv_path))?;
        self.signals.write_csv_to(
            std::io::BufWriter::new(file),
            &csv_path.display().to_string(),
        )?;
        let mut t = String::new();
        for (name, bar) in [
            ("incident", &self.incident),
            ("transmitted", &self.transmitted),
        ] {
            t += &format!(
                "[{name}]\nmodulus = {:?}\ndensity = {:?}\npoisson = {:?}\n",
                bar.modulus, bar.density, bar.poisson
            );
            t += &section_keys(&bar.section, "side");
            if let Some(c) = bar.wave_speed {
                t += &format!("wave_speed = {c:?}\n");
            }
            t += &format!(
                "gauge_distance = {:?}\ngauge_factor = {:?}\ngain = {:?}\nexcitation = {:?}\n\
                 bridge = \"{}\"\npolarity = {}\nchannels = [{}]\n\n",
                bar.gauge_distance,
                bar.gauge_factor,
                bar.gain,
                bar.excitation,
                bar.bridge.as_str(),
                if bar.polarity > 0.0 { 1 } else { -1 },
                bar.channels
                    .iter()
                    .map(|c| format!("{c:?}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
        t += "[specimen]\n";
        t += &section_keys(&self.specimen.section, "");
        t += &format!(
            "length = {:?}\ndensity = {:?}\n\n",
            self.specimen.length, self.specimen.density
        );
        if let Some(l) = self.striker_length {
            t += &format!("[striker]\nlength = {l:?}\n\n");
        }
        t += &format!("[signals]\nfile = {csv_name:?}\n");
        let path = dir.join(format!("{stem}.toml"));
        std::fs::write(&path, t).map_err(io(&path))?;
        Ok(path)
    }
}

/// The section's keys in the form (`side` for a square bar; `width`/`depth` otherwise).
fn section_keys(s: &Section, square_key: &str) -> String {
    match *s {
        Section::Round { diameter } => format!("diameter = {diameter:?}\n"),
        Section::Rectangle { width, depth } if !square_key.is_empty() => {
            debug_assert!(width.to_bits() == depth.to_bits());
            format!("{square_key} = {width:?}\n")
        }
        Section::Rectangle { width, depth } => format!("width = {width:?}\ndepth = {depth:?}\n"),
    }
}

impl Keys<'_> {
    /// A round section by `round_key`, or a rectangle by `rect` (one key for a square
    /// side, two for width and depth); exactly one of the forms.
    fn section(
        &self,
        t: &toml::Table,
        table: &str,
        round_key: &str,
        rect: &[&str],
    ) -> Result<Section> {
        let has_round = t.contains_key(round_key);
        let given: Vec<&str> = rect
            .iter()
            .copied()
            .filter(|k| t.contains_key(*k))
            .collect();
        let forms = format!(
            "`{round_key}` or {}",
            rect.iter()
                .map(|k| format!("`{k}`"))
                .collect::<Vec<_>>()
                .join(" and ")
        );
        if has_round && !given.is_empty() {
            return Err(self.key(
                &Self::path(table, given[0]),
                format!("given with `{round_key}`: the section takes one of {forms}"),
            ));
        }
        if has_round {
            return Ok(Section::Round {
                diameter: self.positive(t, table, round_key)?,
            });
        }
        if given.is_empty() {
            return Err(self.key(
                &Self::path(table, round_key),
                format!("missing: the section needs {forms}"),
            ));
        }
        if given.len() < rect.len() {
            let missing = rect
                .iter()
                .find(|k| !given.contains(k))
                .copied()
                .unwrap_or(round_key);
            return Err(self.key(&Self::path(table, missing), "missing"));
        }
        let w = self.positive(t, table, rect[0])?;
        let d = if rect.len() > 1 {
            self.positive(t, table, rect[1])?
        } else {
            w
        };
        Ok(Section::Rectangle { width: w, depth: d })
    }

    fn bar(&self, t: &toml::Table, name: &str) -> Result<BarSetup> {
        self.known(
            t,
            name,
            &[
                "modulus",
                "density",
                "poisson",
                "diameter",
                "side",
                "wave_speed",
                "gauge_distance",
                "gauge_factor",
                "gain",
                "excitation",
                "bridge",
                "polarity",
                "channels",
            ],
        )?;
        let poisson = self.number(t, name, "poisson")?;
        if !(poisson > -1.0 && poisson < 0.5) {
            return Err(self.key(
                &Self::path(name, "poisson"),
                format!("{poisson} is outside (-1, 0.5), the range of an isotropic solid"),
            ));
        }
        let bridge = match self.string(t, name, "bridge")?.as_str() {
            "quarter" => GaugeBridge::Quarter,
            "half" => GaugeBridge::Half,
            "full" => GaugeBridge::Full,
            other => {
                return Err(self.key(
                    &Self::path(name, "bridge"),
                    format!("unknown bridge `{other}` (known: \"quarter\", \"half\", \"full\")"),
                ));
            }
        };
        let polarity = match self.get(t, name, "polarity")?.as_integer() {
            Some(1) => 1.0,
            Some(-1) => -1.0,
            _ => {
                return Err(self.key(
                    &Self::path(name, "polarity"),
                    format!("must be 1 or -1, found {}", self.get(t, name, "polarity")?),
                ));
            }
        };
        let ch_key = Self::path(name, "channels");
        let channels = self
            .get(t, name, "channels")?
            .as_array()
            .and_then(|a| {
                a.iter()
                    .map(|v| v.as_str().map(str::to_string))
                    .collect::<Option<Vec<_>>>()
            })
            .ok_or_else(|| self.key(&ch_key, "must be an array of column names"))?;
        if channels.is_empty() || channels.len() > 2 {
            return Err(self.key(
                &ch_key,
                format!(
                    "names {} channels: give one, or two opposite gauges to average",
                    channels.len()
                ),
            ));
        }
        let wave_speed = if t.contains_key("wave_speed") {
            Some(self.positive(t, name, "wave_speed")?)
        } else {
            None
        };
        Ok(BarSetup {
            modulus: self.positive(t, name, "modulus")?,
            density: self.positive(t, name, "density")?,
            poisson,
            section: self.section(t, name, "diameter", &["side"])?,
            wave_speed,
            gauge_distance: self.positive(t, name, "gauge_distance")?,
            gauge_factor: self.positive(t, name, "gauge_factor")?,
            gain: self.positive(t, name, "gain")?,
            excitation: self.positive(t, name, "excitation")?,
            bridge,
            polarity,
            channels,
        })
    }
}
