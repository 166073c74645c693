//! The lumped system as a file: masses, springs, dashpots and gap contacts between them or
//! to the base, the test channel that drives the base and the outputs.
//!
//! ```toml
//! [base]
//! channel = "accel bottom"   # the test channel holding the base acceleration
//! unit = 9806.65             # m/s^2 per unit of the record (here 1,000 g); optional, 1
//!
//! [masses]                   # name = kg
//! board = 0.05
//! shell = 0.2
//!
//! [springs.mount]            # one table per spring, named
//! between = ["base", "shell"]
//! stiffness = 2.0e7          # N/m
//! range = [5.0e6, 8.0e7]     # optional calibration range; default [k / 4, 4 k]
//! damping_ratio = 0.02       # optional dashpot beside it, c = 2 zeta sqrt(k mu); default 0
//! damping_range = [0.0, 0.3] # optional; default [0, 0.5]
//!
//! [dashpots.potting]         # optional: a dashpot of fixed coefficient
//! between = ["shell", "board"]
//! coefficient = 3.0          # N s/m
//!
//! [gaps.stop]                # optional: a penalty contact that acts past a clearance
//! between = ["shell", "board"]
//! gap = 1.0e-4               # m
//! stiffness = 1.0e8          # N/m
//! sides = "both"             # "both" (a rattle), "closing" or "opening"; default "both"
//!
//! [outputs]                  # test channel = mass whose acceleration it measures
//! "accel 1" = "board"
//! ```
//!
//! Units are SI (kg, N/m, N s/m, m); accelerations in and out are in the record's unit,
//! `unit` m/s^2 each. Every element joins two different nodes, each `"base"` or a mass.
//! `mu` in a spring's dashpot is the reduced mass `m_a m_b / (m_a + m_b)` of its ends (the
//! mass itself when the other end is the base), so `damping_ratio` is the ratio of a
//! single oscillator of that spring. Names of masses, springs, dashpots and gaps are unique
//! across all four kinds; elements are taken in name order. Unknown keys are refused.

use std::path::Path;

use crate::error::{ModelsError, Result};
use crate::keys::Keys;

/// The name of the base node in a system file.
pub const BASE: &str = "base";

/// A node of the system: the moving base or a mass (index into [`LumpedSystem::masses`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Node {
    /// The base, moved by the measured acceleration.
    Base,
    /// A mass.
    Mass(usize),
}

/// Which way a gap contact acts, in the displacement `d = u_b - u_a` of its second node
/// relative to its first.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GapSides {
    /// Both ways: a part rattling in a slot, force when `|d| > gap`.
    Both,
    /// Only as the nodes approach: force when `d < -gap`.
    Closing,
    /// Only as they part: force when `d > gap`.
    Opening,
}

impl GapSides {
    /// The penetration past the gap (positive in contact) and the sign of the force on the
    /// second node (`+1` pushes it along `d`).
    pub fn penetration(self, d: f64, gap: f64) -> (f64, f64) {
        match self {
            GapSides::Both if d < 0.0 => (-d - gap, 1.0),
            GapSides::Both => (d - gap, -1.0),
            GapSides::Closing => (-d - gap, 1.0),
            GapSides::Opening => (d - gap, -1.0),
        }
    }
}

/// A linear spring, with its calibration range and an optional dashpot beside it.
#[derive(Debug, Clone, PartialEq)]
pub struct Spring {
    /// Its name.
    pub name: String,
    /// Its ends.
    pub between: [Node; 2],
    /// Stiffness `k` (N/m): the nominal.
    pub stiffness: f64,
    /// Range of `k` for calibration (N/m).
    pub range: [f64; 2],
    /// Damping ratio `zeta` of the dashpot beside it: the nominal.
    pub damping_ratio: f64,
    /// Range of `zeta` for calibration.
    pub damping_range: [f64; 2],
}

/// A dashpot of fixed coefficient.
#[derive(Debug, Clone, PartialEq)]
pub struct Dashpot {
    /// Its name.
    pub name: String,
    /// Its ends.
    pub between: [Node; 2],
    /// Coefficient `c` (N s/m).
    pub coefficient: f64,
}

/// A penalty contact past a clearance: force `k p` with `p` the penetration past `gap`.
#[derive(Debug, Clone, PartialEq)]
pub struct Gap {
    /// Its name.
    pub name: String,
    /// Its ends.
    pub between: [Node; 2],
    /// Clearance (m).
    pub gap: f64,
    /// Penalty stiffness (N/m).
    pub stiffness: f64,
    /// Which way it acts.
    pub sides: GapSides,
}

/// A measured channel and the mass whose absolute acceleration it records.
#[derive(Debug, Clone, PartialEq)]
pub struct Output {
    /// The test channel's label.
    pub channel: String,
    /// The mass (index into [`LumpedSystem::masses`]).
    pub mass: usize,
}

/// A driven lumped system, as read from its file (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct LumpedSystem {
    /// The test channel of the base acceleration.
    pub base_channel: String,
    /// m/s^2 per unit of the record's accelerations.
    pub unit: f64,
    /// Masses `(name, kg)`, in name order.
    pub masses: Vec<(String, f64)>,
    /// Springs, in name order.
    pub springs: Vec<Spring>,
    /// Dashpots, in name order.
    pub dashpots: Vec<Dashpot>,
    /// Gap contacts, in name order.
    pub gaps: Vec<Gap>,
    /// Outputs, in channel order.
    pub outputs: Vec<Output>,
}

impl LumpedSystem {
    /// Reads a system file.
    ///
    /// # Errors
    /// [`ModelsError::Io`] when it cannot be read; otherwise as [`LumpedSystem::parse`].
    pub fn read(path: impl AsRef<Path>) -> Result<LumpedSystem> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| ModelsError::Io {
            path: path.display().to_string(),
            source,
        })?;
        LumpedSystem::parse(&text, &path.display().to_string())
    }

    /// Parses system text named `file`.
    ///
    /// # Errors
    /// [`ModelsError::Toml`] for text that is not TOML (a name given twice in one table is
    /// refused there, with its line); [`ModelsError::Key`] naming the file and the key for:
    /// a missing key or table, a value of the wrong type, an unknown key, a mass that is not
    /// positive and finite, a stiffness, coefficient or penalty stiffness that is not
    /// positive and finite, a negative gap or damping ratio, a range that is not
    /// `[lower, upper]` with `lower < upper` around its nominal, an element whose end names
    /// no mass (nor the base), an element joining a node to itself (a loop of springs with
    /// no mass in it), a name used by two kinds of element or named `base`, a mass that no
    /// path of springs ties to the base (its motion would be undetermined), no mass, no
    /// output, an output naming no mass.
    pub fn parse(text: &str, file: &str) -> Result<LumpedSystem> {
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
            &["base", "masses", "springs", "dashpots", "gaps", "outputs"],
        )?;
        let base = r.table(&root, "", "base")?;
        r.known(base, "base", &["channel", "unit"])?;
        let base_channel = r.string(base, "base", "channel")?;
        let unit = if base.contains_key("unit") {
            r.positive(base, "base", "unit")?
        } else {
            1.0
        };

        let mass_table = r.table(&root, "", "masses")?;
        if mass_table.is_empty() {
            return Err(r.key("masses", "names no mass: give at least one (name = kg)"));
        }
        let mut masses = Vec::with_capacity(mass_table.len());
        for name in mass_table.keys() {
            r.not_base(name, "masses")?;
            masses.push((name.clone(), r.positive(mass_table, "masses", name)?));
        }
        let names: Vec<&str> = masses.iter().map(|m| m.0.as_str()).collect();
        let mut used: Vec<(String, &str)> =
            masses.iter().map(|m| (m.0.clone(), "masses")).collect();

        let mut springs = Vec::new();
        for (name, t, path) in r.elements(&root, "springs", &mut used)? {
            r.known(
                t,
                &path,
                &[
                    "between",
                    "stiffness",
                    "range",
                    "damping_ratio",
                    "damping_range",
                ],
            )?;
            let between = r.between(t, &path, &names)?;
            let stiffness = r.positive(t, &path, "stiffness")?;
            let range = r.range(
                t,
                &path,
                "range",
                stiffness,
                [stiffness / 4.0, 4.0 * stiffness],
            )?;
            if range[0] <= 0.0 {
                return Err(r.key(
                    &Keys::path(&path, "range"),
                    format!("lower bound {} must be positive", range[0]),
                ));
            }
            let damping_ratio = if t.contains_key("damping_ratio") {
                r.non_negative(t, &path, "damping_ratio")?
            } else {
                0.0
            };
            let damping_range = r.range(t, &path, "damping_range", damping_ratio, [0.0, 0.5])?;
            if damping_range[0] < 0.0 {
                return Err(r.key(
                    &Keys::path(&path, "damping_range"),
                    format!("lower bound {} must not be negative", damping_range[0]),
                ));
            }
            springs.push(Spring {
                name,
                between,
                stiffness,
                range,
                damping_ratio,
                damping_range,
            });
        }

        let mut dashpots = Vec::new();
        for (name, t, path) in r.elements(&root, "dashpots", &mut used)? {
            r.known(t, &path, &["between", "coefficient"])?;
            dashpots.push(Dashpot {
                name,
                between: r.between(t, &path, &names)?,
                coefficient: r.positive(t, &path, "coefficient")?,
            });
        }

        let mut gaps = Vec::new();
        for (name, t, path) in r.elements(&root, "gaps", &mut used)? {
            r.known(t, &path, &["between", "gap", "stiffness", "sides"])?;
            let sides = if t.contains_key("sides") {
                match r.string(t, &path, "sides")?.as_str() {
                    "both" => GapSides::Both,
                    "closing" => GapSides::Closing,
                    "opening" => GapSides::Opening,
                    other => {
                        return Err(r.key(
                            &Keys::path(&path, "sides"),
                            format!(
                                "unknown `{other}` (known: \"both\", \"closing\", \"opening\")"
                            ),
                        ));
                    }
                }
            } else {
                GapSides::Both
            };
            gaps.push(Gap {
                name,
                between: r.between(t, &path, &names)?,
                gap: r.non_negative(t, &path, "gap")?,
                stiffness: r.positive(t, &path, "stiffness")?,
                sides,
            });
        }

        let out_table = r.table(&root, "", "outputs")?;
        if out_table.is_empty() {
            return Err(r.key(
                "outputs",
                "names no output: give at least one (\"test channel\" = \"mass\")",
            ));
        }
        let mut outputs = Vec::with_capacity(out_table.len());
        for channel in out_table.keys() {
            let mass_name = r.string(out_table, "outputs", channel)?;
            let mass = r.mass(&mass_name, &Keys::path("outputs", channel), &names, false)?;
            let Node::Mass(mass) = mass else {
                return Err(r.key(&Keys::path("outputs", channel), "names no mass"));
            };
            outputs.push(Output {
                channel: channel.clone(),
                mass,
            });
        }

        let system = LumpedSystem {
            base_channel,
            unit,
            masses,
            springs,
            dashpots,
            gaps,
            outputs,
        };
        if let Some(free) = system.untied_mass() {
            return Err(r.key(
                &Keys::path("masses", &system.masses[free].0),
                "no path of springs ties this mass to the base, so its motion is undetermined \
                 (add a spring; a gap or a dashpot alone does not hold it)",
            ));
        }
        Ok(system)
    }

    /// The first mass (in name order) that no chain of springs joins to the base.
    fn untied_mass(&self) -> Option<usize> {
        let n = self.masses.len();
        let mut tied = vec![false; n];
        let mut changed = true;
        while changed {
            changed = false;
            for s in &self.springs {
                let is_tied = |node: Node| match node {
                    Node::Base => true,
                    Node::Mass(i) => tied[i],
                };
                let [a, b] = s.between;
                let (ta, tb) = (is_tied(a), is_tied(b));
                for (node, other) in [(a, tb), (b, ta)] {
                    if let Node::Mass(i) = node {
                        if other && !tied[i] {
                            tied[i] = true;
                            changed = true;
                        }
                    }
                }
            }
        }
        tied.iter().position(|t| !t)
    }

    /// The index of the mass named `name`.
    pub fn mass_index(&self, name: &str) -> Option<usize> {
        self.masses.iter().position(|m| m.0 == name)
    }

    /// The name of a node (`base` or the mass's).
    pub fn node_name(&self, node: Node) -> &str {
        match node {
            Node::Base => BASE,
            Node::Mass(i) => &self.masses[i].0,
        }
    }
}

impl Keys<'_> {
    fn not_base(&self, name: &str, table: &str) -> Result<()> {
        if name == BASE {
            Err(self.key(
                &Self::path(table, name),
                "`base` names the moving base; give the element another name",
            ))
        } else {
            Ok(())
        }
    }

    /// The named tables of `[kind.<name>]`, each recorded in `used` (refusing a name that
    /// another kind already uses), with its dotted path.
    fn elements<'t>(
        &self,
        root: &'t toml::Table,
        kind: &'static str,
        used: &mut Vec<(String, &'static str)>,
    ) -> Result<Vec<(String, &'t toml::Table, String)>> {
        let Some(v) = root.get(kind) else {
            return Ok(Vec::new());
        };
        let t = v
            .as_table()
            .ok_or_else(|| self.key(kind, "must be a table of named elements (`[kind.name]`)"))?;
        let mut out = Vec::with_capacity(t.len());
        for (name, value) in t {
            let path = Self::path(kind, name);
            self.not_base(name, kind)?;
            if let Some((_, other)) = used.iter().find(|(n, _)| n == name) {
                return Err(self.key(
                    &path,
                    format!("the name `{name}` is already used in [{other}]; names are unique"),
                ));
            }
            used.push((name.clone(), kind));
            let table = value
                .as_table()
                .ok_or_else(|| self.key(&path, "must be a table (`[kind.name]`)"))?;
            out.push((name.clone(), table, path));
        }
        Ok(out)
    }

    fn mass(&self, name: &str, path: &str, names: &[&str], base_ok: bool) -> Result<Node> {
        if name == BASE && base_ok {
            return Ok(Node::Base);
        }
        names
            .iter()
            .position(|n| *n == name)
            .map(Node::Mass)
            .ok_or_else(|| {
                self.key(
                    path,
                    format!(
                        "`{name}` names no mass (masses: {}{})",
                        names.join(", "),
                        if base_ok { "; or `base`" } else { "" }
                    ),
                )
            })
    }

    fn between(&self, t: &toml::Table, table: &str, names: &[&str]) -> Result<[Node; 2]> {
        let path = Self::path(table, "between");
        let ends = self
            .get(t, table, "between")?
            .as_array()
            .and_then(|a| a.iter().map(|v| v.as_str()).collect::<Option<Vec<_>>>())
            .filter(|a| a.len() == 2)
            .ok_or_else(|| self.key(&path, "must be two node names, [\"a\", \"b\"]"))?;
        let a = self.mass(ends[0], &path, names, true)?;
        let b = self.mass(ends[1], &path, names, true)?;
        if a == b {
            return Err(self.key(
                &path,
                format!(
                    "joins `{}` to itself: an element needs two different nodes (a loop \
                     with no mass in it moves nothing)",
                    ends[0]
                ),
            ));
        }
        Ok([a, b])
    }

    /// `[lower, upper]` at `key` (or `default` when absent), containing `nominal`.
    fn range(
        &self,
        t: &toml::Table,
        table: &str,
        key: &str,
        nominal: f64,
        default: [f64; 2],
    ) -> Result<[f64; 2]> {
        let path = Self::path(table, key);
        let [lo, hi] = match t.get(key) {
            None => default,
            Some(v) => {
                let a = v
                    .as_array()
                    .filter(|a| a.len() == 2)
                    .ok_or_else(|| self.key(&path, "must be [lower, upper]"))?;
                [self.as_number(&a[0], &path)?, self.as_number(&a[1], &path)?]
            }
        };
        if !(lo < hi && lo <= nominal && nominal <= hi) {
            return Err(self.key(
                &path,
                format!("[{lo}, {hi}] must have lower < upper and hold the nominal {nominal}"),
            ));
        }
        Ok([lo, hi])
    }
}
