//! The parametric airframe: a light-helicopter fuselage of shells in the manner of the
//! source paper's simplified MD-500 model, and the same airframe as an
//! [`impactcal_core::Model`].
//!
//! Units are inch, lbf, second (mass in lbf s^2/in). Axes: x forward, y to the left, z up;
//! the rigid ground is the plane z = 0 and the belly starts `ground_gap` above it.
//!
//! The structure ([`AirframePart`]) is aluminium 2024-T3 (elastic-plastic with linear
//! hardening and Cowper-Symonds rate scaling) except the nose (fibreglass) and the engine
//! fairing (Kevlar): cabin floor, belly panel, two keel beams (webs and vertical
//! stiffeners) under the floor, five subfloor ribs, side skins, roof, back panel (the rear
//! cabin bulkhead, which carries the rotor and transmission), engine fairing, a tapered
//! tail boom with the upper tail (fin), the lower tail (stinger) and a horizontal
//! stabiliser. Five concentrated masses (rotor and transmission, engine, fuel, seats and
//! occupants, tail) are spread evenly over the nodes of the structure that carries them and
//! make up about 80 % of the total mass at nominal values.
//!
//! The impact is the paper's: level attitude, 26 ft/s (312 in/s) down and 40 ft/s
//! (480 in/s) forward onto a rigid surface with Coulomb friction, under gravity; nodal
//! velocities of the sensor nodes are sampled at 10 kHz for 0.08 s.
//!
//! ```
//! use impactcal_shell::airframe::{Airframe, AirframeOptions, AirframeValues, MeshDensity};
//!
//! let af = Airframe::new(AirframeOptions::new(MeshDensity::Coarse))?;
//! assert!((1500..2500).contains(&af.shell_count()));
//! let mut values = AirframeValues::nominal();
//! values.assign("belly_panel.t=0.1")?;
//! let model = af.model(&values)?;
//! let structure = af.structural_mass(&values)?;
//! let share = 1.0 - structure / model.total_mass();
//! assert!((0.75..0.85).contains(&share), "ballast share {share}");
//! # Ok::<(), impactcal_shell::ShellError>(())
//! ```

mod catalogue;
pub(crate) mod enrich;
mod mesh;
mod svg;

use impactcal_core::{CoreError, Histories, Model, ParamGuard, ParameterSpace};

pub use catalogue::{
    Adjustable, AirframeValues, GRAVITY, Preset, catalogue, space_of, structural_space,
};

use crate::error::{Result, ShellError};
use crate::model::{
    BulkViscosity, CowperSymonds, InitialVelocity, Material, MaterialLaw, Part, RigidWall, Section,
    ShellModel, VelocityTarget,
};
use crate::simulation::{RunResult, Simulation};
use mesh::{Counts, MassSite, Mesh};

/// Through-thickness integration points of every section (Gauss).
pub const THICKNESS_POINTS: usize = 3;

/// The named parts of the airframe.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum AirframePart {
    /// Fibreglass nose with a domed front.
    Nose,
    /// Cabin floor, over the subfloor.
    CabinFloor,
    /// Flat belly panel under the subfloor: the first structure to strike the ground.
    BellyPanel,
    /// The two keel beam webs, fore and aft under the floor.
    KeelBeamWeb,
    /// Vertical stiffeners on both sides of the keel beam webs.
    KeelBeamStiffener,
    /// Five transverse subfloor ribs (bulkheads), belly to floor.
    SubfloorRibs,
    /// Side skins from the belly to the roof.
    SideSkins,
    /// Cabin roof.
    Roof,
    /// The rear cabin bulkhead above the floor.
    BackPanel,
    /// Kevlar engine fairing between the cabin and the tail boom.
    EngineFairing,
    /// Tapered tail boom.
    TailBoom,
    /// Vertical fin above the end of the boom.
    UpperTail,
    /// Ventral fin (stinger) below the end of the boom.
    LowerTail,
    /// Horizontal stabiliser.
    HorizontalStabilizer,
}

impl AirframePart {
    /// Every part, in part-id order (id = position + 1).
    pub const ALL: [AirframePart; 14] = [
        AirframePart::Nose,
        AirframePart::CabinFloor,
        AirframePart::BellyPanel,
        AirframePart::KeelBeamWeb,
        AirframePart::KeelBeamStiffener,
        AirframePart::SubfloorRibs,
        AirframePart::SideSkins,
        AirframePart::Roof,
        AirframePart::BackPanel,
        AirframePart::EngineFairing,
        AirframePart::TailBoom,
        AirframePart::UpperTail,
        AirframePart::LowerTail,
        AirframePart::HorizontalStabilizer,
    ];

    /// The name used in the catalogue and as the keyword deck's part title.
    pub fn name(self) -> &'static str {
        use AirframePart as P;
        match self {
            P::Nose => "nose",
            P::CabinFloor => "cabin_floor",
            P::BellyPanel => "belly_panel",
            P::KeelBeamWeb => "keel_beam_web",
            P::KeelBeamStiffener => "keel_beam_stiffener",
            P::SubfloorRibs => "subfloor_ribs",
            P::SideSkins => "side_skins",
            P::Roof => "roof",
            P::BackPanel => "back_panel",
            P::EngineFairing => "engine_fairing",
            P::TailBoom => "tail_boom",
            P::UpperTail => "upper_tail",
            P::LowerTail => "lower_tail",
            P::HorizontalStabilizer => "horizontal_stabilizer",
        }
    }

    /// A readable label.
    pub fn label(self) -> String {
        self.name().replace('_', " ")
    }

    /// The part id in the generated model (1-based).
    pub fn id(self) -> u64 {
        Self::ALL.iter().position(|&p| p == self).unwrap_or(0) as u64 + 1
    }

    /// The part with the given name.
    pub fn from_name(name: &str) -> Option<AirframePart> {
        Self::ALL.iter().copied().find(|p| p.name() == name)
    }
}

/// Mesh density of the generated airframe.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MeshDensity {
    /// About 2,000 shells (element size about 5 in): tests and demonstrations.
    #[default]
    Coarse,
    /// About 6,000 shells.
    Medium,
    /// At least 20,000 shells, like the paper's 27,000-element model.
    Fine,
}

impl MeshDensity {
    fn factor(self) -> f64 {
        match self {
            MeshDensity::Coarse => 1.0,
            MeshDensity::Medium => 1.75,
            MeshDensity::Fine => 3.4,
        }
    }

    /// The density's name: `coarse`, `medium` or `fine`.
    pub fn name(self) -> &'static str {
        match self {
            MeshDensity::Coarse => "coarse",
            MeshDensity::Medium => "medium",
            MeshDensity::Fine => "fine",
        }
    }

    /// Parses `coarse`, `medium` or `fine`.
    ///
    /// # Errors
    /// [`ShellError::Value`] for any other name.
    pub fn parse(name: &str) -> Result<MeshDensity> {
        match name.to_ascii_lowercase().as_str() {
            "coarse" => Ok(MeshDensity::Coarse),
            "medium" => Ok(MeshDensity::Medium),
            "fine" => Ok(MeshDensity::Fine),
            _ => Err(ShellError::value(
                "mesh density",
                format!("`{name}` is not one of coarse, medium, fine"),
            )),
        }
    }
}

/// Settings of the generated airframe that are not physical quantities.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AirframeOptions {
    /// Mesh density.
    pub mesh: MeshDensity,
    /// Simulated time (0.08 s by default).
    pub end_time: f64,
    /// Output sampling interval (1e-4 s = 10 kHz by default).
    pub output_interval: f64,
    /// Number of candidate sensor nodes (405 by default, as in the paper).
    pub sensors: usize,
    /// Clearance between the lowest node and the ground at t = 0 (0.25 in by default).
    pub ground_gap: f64,
}

impl AirframeOptions {
    /// The defaults with the given mesh density.
    pub fn new(mesh: MeshDensity) -> Self {
        AirframeOptions {
            mesh,
            end_time: 0.08,
            output_interval: 1e-4,
            sensors: 405,
            ground_gap: 0.25,
        }
    }
}

impl Default for AirframeOptions {
    fn default() -> Self {
        Self::new(MeshDensity::Coarse)
    }
}

impl ParamGuard for AirframeOptions {
    /// The options themselves: nothing downstream needs a separate checked form.
    type Checked = AirframeOptions;

    /// Checks each option on its own (the number of sensors against the mesh's nodes is
    /// checked by [`Airframe::new`], which builds the mesh).
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] naming the option as `airframe.<key>`: an `end_time`
    /// not finite and positive, an `output_interval` not in `(0, end_time]`, a
    /// `ground_gap` not finite and non-negative, no `sensors`.
    fn check_ref(&self) -> impactcal_core::Result<()> {
        let bad = |key: &str, value: &dyn std::fmt::Display, why: String| {
            Err(CoreError::invalid_option(
                format!("airframe.{key}"),
                value,
                why,
            ))
        };
        if !(self.end_time.is_finite() && self.end_time > 0.0) {
            return bad(
                "end_time",
                &self.end_time,
                "must be finite and positive (s)".into(),
            );
        }
        if !(self.output_interval > 0.0 && self.output_interval <= self.end_time) {
            return bad(
                "output_interval",
                &self.output_interval,
                format!("must lie in (0, end_time = {}] (s)", self.end_time),
            );
        }
        if !(self.ground_gap.is_finite() && self.ground_gap >= 0.0) {
            return bad(
                "ground_gap",
                &self.ground_gap,
                "must be finite and non-negative (in)".into(),
            );
        }
        if self.sensors == 0 {
            return bad("sensors", &0, "must be at least 1".into());
        }
        Ok(())
    }

    fn check(self) -> impactcal_core::Result<AirframeOptions> {
        ParamGuard::check_ref(&self)?;
        Ok(self)
    }
}

/// A generated airframe: the mesh (fixed for a density), its sensor nodes, and the map from
/// [`AirframeValues`] to a runnable [`ShellModel`].
#[derive(Debug, Clone)]
pub struct Airframe {
    options: AirframeOptions,
    mesh: Mesh,
    sensors: Vec<u64>,
}

impl Airframe {
    /// Generates the mesh and chooses the sensor nodes (farthest-point sampling over all
    /// nodes from the cabin centre; they depend only on the mesh, never on parameter values).
    ///
    /// # Errors
    /// [`ShellError::Core`] with [`CoreError::InvalidOption`] naming the option
    /// (`airframe.<key>`): options refused by [`ParamGuard::check_ref`], or more sensors
    /// than the mesh has nodes.
    pub fn new(options: AirframeOptions) -> Result<Self> {
        ParamGuard::check_ref(&options)?;
        let mesh = mesh::build(&Counts::for_factor(options.mesh.factor()));
        if options.sensors > mesh.nodes.len() {
            return Err(CoreError::invalid_option(
                "airframe.sensors",
                options.sensors,
                format!(
                    "the {} mesh has {} nodes: at most that many sensors",
                    options.mesh.name(),
                    mesh.nodes.len()
                ),
            )
            .into());
        }
        let centre = [
            0.5 * mesh::CABIN_LENGTH,
            0.0,
            mesh::FLOOR_HEIGHT + mesh::HALF_WIDTH,
        ];
        let sensors = mesh::spread_nodes(&mesh.nodes, options.sensors, centre)
            .into_iter()
            .map(|i| i as u64 + 1)
            .collect();
        Ok(Airframe {
            options,
            mesh,
            sensors,
        })
    }

    /// The options it was built with.
    pub fn options(&self) -> &AirframeOptions {
        &self.options
    }

    /// Number of shells.
    pub fn shell_count(&self) -> usize {
        self.mesh.shells.len()
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.mesh.nodes.len()
    }

    /// Number of shells of each part, in [`AirframePart::ALL`] order.
    pub fn part_counts(&self) -> Vec<(AirframePart, usize)> {
        AirframePart::ALL
            .iter()
            .map(|&p| (p, self.mesh.shells.iter().filter(|s| s.1 == p).count()))
            .collect()
    }

    /// The sensor node ids, ascending.
    pub fn sensor_nodes(&self) -> &[u64] {
        &self.sensors
    }

    /// The sensor channel labels `<node>.<x|y|z>`, in the order of the velocity histories.
    pub fn sensor_labels(&self) -> Vec<String> {
        self.sensors
            .iter()
            .flat_map(|n| ["x", "y", "z"].map(|a| format!("{n}.{a}")))
            .collect()
    }

    /// The part a node belongs to (the first part, in [`AirframePart::ALL`] order, with a
    /// shell on it), for grouping sensor channels; `None` for an unknown node id.
    pub fn part_of_node(&self, node: u64) -> Option<AirframePart> {
        let i = usize::try_from(node.checked_sub(1)?).ok()?;
        self.mesh
            .shells
            .iter()
            .filter(|(n, _)| n.contains(&(i as u32)))
            .map(|(_, p)| *p)
            .min()
    }

    /// The undeformed node coordinates at level attitude (id = index + 1).
    pub fn node_positions(&self) -> &[[f64; 3]] {
        &self.mesh.nodes
    }

    /// The shells as `(node ids, part)`; a triangle repeats its third node.
    pub fn shells(&self) -> impl Iterator<Item = ([u64; 4], AirframePart)> + '_ {
        self.mesh
            .shells
            .iter()
            .map(|(n, p)| (n.map(|i| i as u64 + 1), *p))
    }

    /// A labelled SVG picture of the parts: a side view with the near (left-hand) skins cut
    /// away and a plan view without the roof.
    pub fn parts_svg(&self) -> String {
        svg::parts_svg(self)
    }

    /// The mass of the shells alone (density x thickness x area) at `values`.
    ///
    /// # Errors
    /// As [`model`](Self::model).
    pub fn structural_mass(&self, values: &AirframeValues) -> Result<f64> {
        let mut m = self.model(values)?;
        m.masses.clear();
        Ok(m.total_mass())
    }

    /// The runnable model at `values`: sections, materials, masses, attitude, initial
    /// velocity, gravity, the ground, damping and the sensor outputs, with invariant node
    /// numbering and shell bulk viscosity (Q1 1.5, Q2 0.06) switched on.
    ///
    /// The airframe is rotated by the pitch (nose up) and roll (right side down) about the
    /// cabin centre, then lifted so that its lowest node lies `ground_gap` above the ground.
    ///
    /// # Errors
    /// [`ShellError::Value`] for values that cannot make a model: a non-positive thickness,
    /// modulus, yield stress or rate constant, `Et` outside `[0, E)`, a negative mass,
    /// friction or damping.
    pub fn model(&self, values: &AirframeValues) -> Result<ShellModel> {
        check_values(values)?;
        let o = &self.options;
        let mut m = ShellModel::new(format!("impactcal parametric airframe ({:?} mesh)", o.mesh));
        let pitch = values.global("attitude.pitch").to_radians();
        let roll = values.global("attitude.roll").to_radians();
        let c = [
            0.5 * mesh::CABIN_LENGTH,
            0.0,
            mesh::FLOOR_HEIGHT + mesh::HALF_WIDTH,
        ];
        let (sp, cp) = pitch.sin_cos();
        let (sr, cr) = roll.sin_cos();
        let rotated: Vec<[f64; 3]> = self
            .mesh
            .nodes
            .iter()
            .map(|p| {
                let (x, y, z) = (p[0] - c[0], p[1] - c[1], p[2] - c[2]);
                // Pitch about y (nose up), then roll about x (right side, -y, down).
                let (x1, z1) = (x * cp - z * sp, x * sp + z * cp);
                let (y2, z2) = (y * cr - z1 * sr, y * sr + z1 * cr);
                [x1 + c[0], y2 + c[1], z2 + c[2]]
            })
            .collect();
        let zmin = rotated.iter().map(|p| p[2]).fold(f64::INFINITY, f64::min);
        for (i, p) in rotated.iter().enumerate() {
            m.add_node(i as u64 + 1, [p[0], p[1], p[2] - zmin + o.ground_gap]);
        }
        for (k, (n, part)) in self.mesh.shells.iter().enumerate() {
            m.add_shell(k as u64 + 1, part.id(), n.map(|i| i as u64 + 1));
        }
        let rate = CowperSymonds {
            c: values.global("rate.c"),
            p: values.global("rate.p"),
        };
        for part in AirframePart::ALL {
            let (data, _) = part.nominal();
            let id = part.id();
            m.parts.push(Part {
                id,
                title: part.name().to_string(),
                section: id,
                material: id,
                hourglass: 0,
            });
            m.sections.push(Section {
                nip: THICKNESS_POINTS,
                ..Section::new(id, values.part(part, "t"))
            });
            m.materials.push(Material {
                id,
                density: data.density,
                youngs: values.part(part, "E"),
                poisson: data.poisson,
                law: MaterialLaw::Plastic {
                    yield_stress: values.part(part, "sigy"),
                    tangent_modulus: values.part(part, "Et"),
                    rate: data.rate_sensitive.then_some(rate),
                },
            });
        }
        let mut mass_id = 1;
        for (site, nodes) in &self.mesh.sites {
            let total = values.global(&format!("mass.{}", site_name(*site)));
            let each = total / nodes.len().max(1) as f64;
            for &n in nodes {
                m.add_mass(mass_id, n as u64 + 1, each);
                mass_id += 1;
            }
        }
        m.initial_velocities.push(InitialVelocity::translation(
            VelocityTarget::All,
            [
                values.global("impact.horizontal"),
                0.0,
                -values.global("impact.vertical"),
            ],
        ));
        m.set_gravity(GRAVITY);
        m.damping = values.global("damping");
        // Invariant node numbering keeps the mirror-symmetric mesh's response symmetric
        // (the edge-based frames of mirrored elements differ); bulk viscosity spreads the
        // membrane shock of the impact, which makes the first 10 ms insensitive to the
        // time step (docs/airframe.md, "Predictability").
        m.control.invariant_numbering = true;
        m.bulk_viscosity = Some(BulkViscosity::default());
        m.walls.push(RigidWall {
            friction: values.global("ground.friction"),
            ..RigidWall::plane([0.0; 3], [0.0, 0.0, 1.0])
        });
        m.control.end_time = o.end_time;
        m.output.interval = o.output_interval;
        m.output.history_nodes = self.sensors.clone();
        Ok(m)
    }

    /// Builds the model at `values` and runs it.
    ///
    /// # Errors
    /// As [`model`](Self::model) and [`Simulation::run`].
    pub fn run(&self, values: &AirframeValues) -> Result<RunResult> {
        Simulation::new(&self.model(values)?)?.run()
    }
}

fn site_name(site: MassSite) -> &'static str {
    match site {
        MassSite::RotorTransmission => "rotor_transmission",
        MassSite::Engine => "engine",
        MassSite::Fuel => "fuel",
        MassSite::Occupants => "occupants",
        MassSite::Tail => "tail",
    }
}

fn check_values(values: &AirframeValues) -> Result<()> {
    let bad = |name: &str, v: f64, why: &str| {
        Err(ShellError::value(
            format!("airframe quantity `{name}`"),
            format!("{why}, got {v}"),
        ))
    };
    for (name, v) in values.iter() {
        let field = name.rsplit('.').next().unwrap_or("");
        let positive = matches!(field, "t" | "E" | "sigy" | "c" | "p");
        if positive && v <= 0.0 {
            return bad(name, v, "must be positive");
        }
        let non_negative = name.starts_with("mass.")
            || matches!(name, "ground.friction" | "damping" | "impact.vertical")
            || field == "Et";
        if non_negative && v < 0.0 {
            return bad(name, v, "must be non-negative");
        }
        if field == "Et" {
            let e = values.get(&name.replace(".Et", ".E"))?;
            if v >= e {
                return bad(name, v, &format!("must be below E = {e}"));
            }
        }
        if name.starts_with("attitude.") && v.abs() > 45.0 {
            return bad(name, v, "must lie within +-45 degrees");
        }
    }
    Ok(())
}

/// The airframe as a [`Model`]: the quantities of a [`ParameterSpace`] (catalogue names)
/// vary, the others keep the values of a base set (nominal unless overridden). The output
/// is the velocity histories of the sensor nodes (labels `<node>.<x|y|z>`, unit
/// `velocity`, in/s).
#[derive(Debug, Clone)]
pub struct AirframeModel {
    airframe: Airframe,
    base: AirframeValues,
    space: ParameterSpace,
}

impl AirframeModel {
    /// A model varying `space` (every name must be in the catalogue) about nominal values.
    ///
    /// # Errors
    /// [`ShellError::Value`] naming the first parameter that is not in the catalogue.
    pub fn new(airframe: Airframe, space: ParameterSpace) -> Result<Self> {
        let base = AirframeValues::nominal();
        for p in space.parameters() {
            base.get(&p.name)?;
        }
        Ok(AirframeModel {
            airframe,
            base,
            space,
        })
    }

    /// A model varying the quantities of a preset (the paper's Table 1 or Table 2).
    ///
    /// # Errors
    /// Never for the built-in presets.
    pub fn preset(airframe: Airframe, preset: Preset) -> Result<Self> {
        Self::new(airframe, preset.space()?)
    }

    /// Replaces the values of the quantities that do not vary.
    #[must_use]
    pub fn with_base(mut self, base: AirframeValues) -> Self {
        self.base = base;
        self
    }

    /// The airframe.
    pub fn airframe(&self) -> &Airframe {
        &self.airframe
    }

    /// The base values.
    pub fn base(&self) -> &AirframeValues {
        &self.base
    }

    /// The complete values at a point of the space.
    ///
    /// # Errors
    /// A dimension mismatch or a non-finite coordinate.
    pub fn values_at(&self, point: &[f64]) -> Result<AirframeValues> {
        let mut v = self.base.clone();
        v.set_point(&self.space, point)?;
        Ok(v)
    }

    /// Runs the point and returns everything the solver produced.
    ///
    /// # Errors
    /// As [`values_at`](Self::values_at) and [`Airframe::run`].
    pub fn run(&self, point: &[f64]) -> Result<RunResult> {
        self.airframe.run(&self.values_at(point)?)
    }
}

impl Model for AirframeModel {
    fn space(&self) -> &ParameterSpace {
        &self.space
    }

    fn simulate(&self, params: &[f64]) -> impactcal_core::Result<Histories> {
        let r = self.run(params).map_err(CoreError::simulation)?;
        r.velocity.ok_or_else(|| {
            CoreError::Invalid("the airframe run produced no sensor histories".into())
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The defaults pass; each bad option is refused, by the check and by
    /// [`Airframe::new`], with `CoreError::InvalidOption` naming its key.
    #[test]
    fn a_bad_option_is_refused_naming_its_key() {
        let base = AirframeOptions::default();
        assert!(ParamGuard::check_ref(&base).is_ok());
        let cases = [
            (
                AirframeOptions {
                    end_time: -0.01,
                    ..base
                },
                "airframe.end_time",
            ),
            (
                AirframeOptions {
                    end_time: f64::NAN,
                    ..base
                },
                "airframe.end_time",
            ),
            (
                AirframeOptions {
                    output_interval: 0.0,
                    ..base
                },
                "airframe.output_interval",
            ),
            (
                AirframeOptions {
                    end_time: 0.01,
                    output_interval: 0.02,
                    ..base
                },
                "airframe.output_interval",
            ),
            (
                AirframeOptions {
                    ground_gap: -0.1,
                    ..base
                },
                "airframe.ground_gap",
            ),
            (
                AirframeOptions {
                    ground_gap: f64::INFINITY,
                    ..base
                },
                "airframe.ground_gap",
            ),
            (AirframeOptions { sensors: 0, ..base }, "airframe.sensors"),
        ];
        for (o, key) in cases {
            match ParamGuard::check_ref(&o) {
                Err(CoreError::InvalidOption { name, .. }) => assert_eq!(name, key),
                other => panic!("{key}: {other:?}"),
            }
            match Airframe::new(o) {
                Err(ShellError::Core(CoreError::InvalidOption { name, .. })) => {
                    assert_eq!(name, key)
                }
                other => panic!("{key}: {other:?}"),
            }
        }
    }

    /// More sensors than the mesh has nodes is refused, naming the number of nodes, rather
    /// than silently giving fewer; exactly that many is accepted.
    #[test]
    fn more_sensors_than_nodes_is_refused_naming_the_node_count() {
        let nodes = match Airframe::new(AirframeOptions {
            sensors: 1,
            ..AirframeOptions::default()
        }) {
            Ok(af) => af.node_count(),
            Err(e) => panic!("{e}"),
        };
        let all = AirframeOptions {
            sensors: nodes,
            ..AirframeOptions::default()
        };
        assert!(ParamGuard::check(all).is_ok());
        match Airframe::new(AirframeOptions {
            sensors: nodes + 1,
            ..all
        }) {
            Err(e @ ShellError::Core(CoreError::InvalidOption { .. })) => {
                let e = e.to_string();
                assert!(
                    e.contains("`airframe.sensors`")
                        && e.contains(&format!("the coarse mesh has {nodes} nodes")),
                    "{e}"
                );
            }
            other => panic!("{other:?}"),
        }
    }
}
