//! The model description: nodes, shells, parts, sections, materials, masses, loads, the
//! rigid walls, contact interfaces, controls and output requests.
//!
//! A [`ShellModel`] is plain data with public fields, built in code or read from a keyword
//! deck ([`crate::keyword`]). Nothing is checked here: [`crate::Simulation::new`] validates
//! it once (undefined ids, missing nodes, degenerate elements, out-of-range values) and
//! returns a typed error naming the entity at fault. Ids are the user's (LS-DYNA style,
//! any positive integers, not necessarily contiguous).

/// A node: id and coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Node {
    /// Node id.
    pub id: u64,
    /// Coordinates `[x, y, z]`.
    pub x: [f64; 3],
}

/// A shell element: 4 nodes, or 3 (a triangle, written with `n4 == n3`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shell {
    /// Element id.
    pub id: u64,
    /// Part id.
    pub part: u64,
    /// Node ids, counter-clockwise seen from the positive normal; `nodes[3] == nodes[2]`
    /// makes a triangle.
    pub nodes: [u64; 4],
}

impl Shell {
    /// True when the element is a triangle (`n4 == n3`).
    pub fn is_triangle(&self) -> bool {
        self.nodes[3] == self.nodes[2]
    }
}

/// A part: a set of shells sharing a section and a material.
#[derive(Debug, Clone, PartialEq)]
pub struct Part {
    /// Part id.
    pub id: u64,
    /// Free-text title.
    pub title: String,
    /// Section id.
    pub section: u64,
    /// Material id.
    pub material: u64,
    /// Hourglass definition id (`*HOURGLASS` HGID, see [`HourglassDef`]); 0 takes the
    /// model's [`ShellModel::hourglass`].
    pub hourglass: u64,
}

/// Through-thickness integration rule.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ThicknessRule {
    /// Gauss-Legendre points (the default).
    #[default]
    Gauss,
    /// Gauss-Lobatto points (points on both surfaces; needs at least 2 points).
    Lobatto,
}

/// A shell section: thickness, through-thickness points, shear factor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Section {
    /// Section id.
    pub id: u64,
    /// Shell thickness (length unit), > 0.
    pub thickness: f64,
    /// Number of through-thickness integration points, 1 to 10 (1 = membrane only).
    pub nip: usize,
    /// Transverse shear correction factor (5/6 by default).
    pub shear_factor: f64,
    /// Integration rule through the thickness.
    pub rule: ThicknessRule,
}

impl Section {
    /// A section of thickness `t` with the defaults: 5 Gauss points, shear factor 5/6.
    pub fn new(id: u64, thickness: f64) -> Self {
        Section {
            id,
            thickness,
            nip: 5,
            shear_factor: 5.0 / 6.0,
            rule: ThicknessRule::Gauss,
        }
    }
}

/// Yield-stress strain-rate scaling of Cowper and Symonds:
/// `sigma_y,dyn = sigma_y (1 + (rate / c)^(1/p))`, with the element's effective strain rate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CowperSymonds {
    /// Rate constant C (1/time), > 0.
    pub c: f64,
    /// Exponent p, > 0.
    pub p: f64,
}

/// The hardening of [`MaterialLaw::PlasticCurve`]: the yield stress as a function of the
/// equivalent plastic strain, piecewise linear through its points and extended past the
/// last point with the last segment's slope (below the first point, the first value).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Hardening {
    /// A `*DEFINE_CURVE` of yield stress (ordinate) against equivalent plastic strain
    /// (abscissa), with its scale factors and offsets (`*MAT_024` LCSS).
    Curve(u64),
    /// Up to eight points `(plastic strain, yield stress)`, the first `len` of `points`
    /// (`*MAT_024` EPS1-EPS8, ES1-ES8).
    Points {
        /// The number of points used, 2 to 8.
        len: usize,
        /// The points; those past `len` are unused.
        points: [(f64, f64); 8],
    },
}

/// The global directions in which a rigid body's motion is held (`*MAT_RIGID` CMO = 1 with
/// CON1 and CON2): translations of its centre of mass along x, y, z, and rotations about x,
/// y, z.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RigidConstraints {
    /// Held translations `[x, y, z]`.
    pub translation: [bool; 3],
    /// Held rotations `[x, y, z]`.
    pub rotation: [bool; 3],
}

/// The material law of a [`Material`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MaterialLaw {
    /// Linear elastic (`*MAT_ELASTIC`).
    Elastic,
    /// Elastic-plastic, von Mises yield in plane stress, linear isotropic hardening
    /// (`*MAT_PLASTIC_KINEMATIC` with BETA = 1).
    Plastic {
        /// Initial yield stress, > 0.
        yield_stress: f64,
        /// Tangent modulus Et of the uniaxial curve, 0 <= Et < E; the plastic modulus is
        /// `H = E Et / (E - Et)`.
        tangent_modulus: f64,
        /// Optional Cowper-Symonds rate scaling.
        rate: Option<CowperSymonds>,
    },
    /// Elastic-plastic like [`MaterialLaw::Plastic`], with the yield stress a
    /// piecewise-linear function of the equivalent plastic strain
    /// (`*MAT_PIECEWISE_LINEAR_PLASTICITY` with LCSS or EPS/ES): `sigma_y(p)` from the
    /// [`Hardening`], which must not decrease, scaled by the Cowper-Symonds factor.
    PlasticCurve {
        /// The hardening curve.
        hardening: Hardening,
        /// Optional Cowper-Symonds rate scaling.
        rate: Option<CowperSymonds>,
    },
    /// Rigid (`*MAT_RIGID`): the part's nodes move as one rigid body (with the nodes of any
    /// spot weld or rigid part that shares a node with it); its shells add mass and inertia
    /// but no stiffness. The density gives the mass; Young's modulus and Poisson's ratio
    /// are kept for the deck (LS-DYNA uses them for contact stiffness).
    Rigid {
        /// Motion held in global directions.
        constraints: RigidConstraints,
    },
}

/// A material: density, elastic constants and law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Material id.
    pub id: u64,
    /// Mass density, > 0.
    pub density: f64,
    /// Young's modulus, > 0.
    pub youngs: f64,
    /// Poisson's ratio, -1 < nu < 0.5.
    pub poisson: f64,
    /// The law.
    pub law: MaterialLaw,
}

/// A concentrated mass added to a node (`*ELEMENT_MASS`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointMass {
    /// Element id.
    pub id: u64,
    /// Node id.
    pub node: u64,
    /// Mass, >= 0.
    pub mass: f64,
}

/// A named list of nodes (`*SET_NODE_LIST`).
#[derive(Debug, Clone, PartialEq)]
pub struct NodeSet {
    /// Set id.
    pub id: u64,
    /// Node ids.
    pub nodes: Vec<u64>,
}

/// Which nodes an initial velocity applies to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum VelocityTarget {
    /// Every node.
    All,
    /// The nodes of a node set.
    NodeSet(u64),
    /// One node.
    Node(u64),
    /// The nodes of the shells of a part.
    Part(u64),
    /// The nodes of the shells of the parts of a part set.
    PartSet(u64),
}

/// An initial velocity: `v = translation + omega * axis x (x - centre)` and the nodal
/// angular velocity `omega * axis + rotation`. Later entries override earlier ones.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InitialVelocity {
    /// The nodes it applies to.
    pub target: VelocityTarget,
    /// Translational velocity.
    pub translation: [f64; 3],
    /// Angular velocity vector given to the rotational degrees of freedom (rad/time).
    pub rotation: [f64; 3],
    /// Rigid spin rate about `axis` through `centre` (rad/time), 0 for none.
    pub omega: f64,
    /// Centre of the rigid spin.
    pub centre: [f64; 3],
    /// Unit spin axis (normalised when built).
    pub axis: [f64; 3],
}

impl InitialVelocity {
    /// A pure translational velocity for `target`.
    pub fn translation(target: VelocityTarget, v: [f64; 3]) -> Self {
        InitialVelocity {
            target,
            translation: v,
            rotation: [0.0; 3],
            omega: 0.0,
            centre: [0.0; 3],
            axis: [0.0, 0.0, 1.0],
        }
    }
}

/// Which nodes a constraint applies to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NodeTarget {
    /// One node.
    Node(u64),
    /// The nodes of a node set.
    NodeSet(u64),
}

/// A single-point constraint: the flagged degrees of freedom `[x, y, z, rx, ry, rz]` are
/// held at zero velocity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spc {
    /// The nodes.
    pub target: NodeTarget,
    /// Fixed degrees of freedom: translations x, y, z, rotations x, y, z.
    pub dofs: [bool; 6],
}

/// How a rigid wall enforces non-penetration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WallMethod {
    /// Kinematic constraint (the default): the normal velocity of a node that would cross
    /// the plane during the next step is set so that it lands on the plane.
    Kinematic,
    /// Penalty spring with mass-based stiffness `k = alpha m / dt_ref^2` on penetration,
    /// `dt_ref` the smallest element step of the undeformed model before the safety factor
    /// (fixed for the run, so the contact stiffness does not change with TSSFAC), with a
    /// normal dashpot `c = 2 zeta sqrt(k m)` (zeta = `damping`, LS-DYNA's VDC / 100) on the
    /// normal velocity while the node penetrates. The normal force never pulls: spring plus
    /// dashpot is clipped at zero. Each node is an oscillator of circular frequency
    /// `sqrt(alpha) / dt_ref`, stable for any TSSFAC <= 1 when alpha <= 1.
    Penalty {
        /// The stiffness factor alpha (0.1 is a safe choice), 0 < alpha <= 1.
        alpha: f64,
        /// Fraction of critical damping of the node-on-spring oscillator, 0 <= zeta <= 1.
        damping: f64,
    },
}

/// The shape of a [`RigidWall`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum WallShape {
    /// The plane through `point` with normal `head - point` (`*RIGIDWALL_PLANAR`): nodes
    /// stay on the side the normal points to.
    #[default]
    Plane,
    /// A cylinder of radius `radius` about the axis from `point` (the tail) toward `head`
    /// (`*RIGIDWALL_GEOMETRIC_CYLINDER`): nodes stay outside it. `length > 0` bounds it to
    /// the axial positions `0 <= s <= length` from the tail; 0 makes it infinite.
    Cylinder {
        /// Radius, > 0.
        radius: f64,
        /// Length along the axis from the tail (0: infinite).
        length: f64,
    },
}

/// A stationary rigid wall (`*RIGIDWALL_PLANAR`, `*RIGIDWALL_GEOMETRIC_CYLINDER`): the nodes
/// it checks may not pass into it. For a plane, the negative side of the plane through
/// `point` with normal `head - point`; for a cylinder, its inside.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidWall {
    /// The wall's id in outputs (`_ID` cards); 0 gives it its 1-based position among the
    /// model's walls.
    pub id: u64,
    /// The shape.
    pub shape: WallShape,
    /// The nodes checked: `None` for all nodes (NSID = 0), or a node set.
    pub nodes: Option<u64>,
    /// A point of the plane (the tail, XT YT ZT).
    pub point: [f64; 3],
    /// The head point (XH YH ZH); the normal is `head - point`.
    pub head: [f64; 3],
    /// Coulomb friction coefficient mu >= 0; `f64::INFINITY` (FRIC = 1) forbids sliding.
    pub friction: f64,
    /// Enforcement method.
    pub method: WallMethod,
}

impl RigidWall {
    /// A kinematic, frictionless plane through `point` with normal `head - point`, checking
    /// every node, with no id of its own.
    pub fn plane(point: [f64; 3], head: [f64; 3]) -> Self {
        RigidWall {
            id: 0,
            shape: WallShape::Plane,
            nodes: None,
            point,
            head,
            friction: 0.0,
            method: WallMethod::Kinematic,
        }
    }
}

/// A piecewise-linear curve `(abscissa, ordinate)` with constant extrapolation
/// (`*DEFINE_CURVE`), with scale factors and offsets as in LS-DYNA:
/// `f(t) = sfo * g(t / sfa - offa) + offo` where `g` interpolates `points`.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    /// Curve id.
    pub id: u64,
    /// Abscissa scale factor SFA (1 by default).
    pub sfa: f64,
    /// Ordinate scale factor SFO (1 by default).
    pub sfo: f64,
    /// Abscissa offset OFFA.
    pub offa: f64,
    /// Ordinate offset OFFO.
    pub offo: f64,
    /// Points, abscissae strictly increasing.
    pub points: Vec<(f64, f64)>,
}

impl Curve {
    /// A curve with unit scales and no offsets.
    pub fn new(id: u64, points: Vec<(f64, f64)>) -> Self {
        Curve {
            id,
            sfa: 1.0,
            sfo: 1.0,
            offa: 0.0,
            offo: 0.0,
            points,
        }
    }

    /// Evaluates the curve at `t` (linear interpolation, constant outside the points).
    pub fn eval(&self, t: f64) -> f64 {
        let s = t / self.sfa - self.offa;
        let p = &self.points;
        let g = match p.len() {
            0 => 0.0,
            _ if s <= p[0].0 => p[0].1,
            n if s >= p[n - 1].0 => p[n - 1].1,
            _ => {
                let k = p.partition_point(|q| q.0 <= s).saturating_sub(1);
                let (a, b) = (p[k], p[k + 1]);
                a.1 + (b.1 - a.1) * (s - a.0) / (b.0 - a.0)
            }
        };
        self.sfo * g + self.offo
    }
}

/// Body acceleration along z (`*LOAD_BODY_Z`): every node is accelerated by
/// `-scale * curve(t)` along z (a positive value pulls toward -z, as gravity does).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyLoadZ {
    /// Curve id.
    pub curve: u64,
    /// Scale factor SF.
    pub scale: f64,
}

/// Stiffness-proportional (Rayleigh beta) damping of the shells of one part
/// (`*DAMPING_PART_STIFFNESS`).
///
/// Each element adds the viscous resultants `beta (N, M, Q)(rates)`: its elastic stiffness
/// (membrane, bending, transverse shear and, in the stiffness form, the hourglass
/// stiffness) applied to its deformation rates. Strain and hourglass rates vanish on
/// rigid-body motion, so translation and rotation of the whole part are never damped.
/// A mode of circular frequency `omega` is damped at the fraction of critical
/// `zeta = beta omega / 2`.
///
/// `coef` follows the sign convention of LS-DYNA's COEF:
/// - `coef > 0`: `zeta = coef` at each element's highest frequency `omega_e = 2 / dt_e`
///   (`dt_e` its stable step), i.e. `beta_e = coef dt_e`; lower frequencies get
///   proportionally less (`zeta = coef omega / omega_e`). LS-DYNA recommends 0.01 to 0.25 for
///   its own (unpublished) positive-COEF formula, which this definition follows in spirit.
/// - `coef < 0`: `beta = |coef|` (time unit), the classic Rayleigh coefficient.
///
/// The stable step of a damped element shrinks to `dt_e (sqrt(1 + zeta_e^2) - zeta_e)`.
/// The energy removed is reported as damping energy.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PartStiffnessDamping {
    /// Part id.
    pub part: u64,
    /// The coefficient (see the type's docs); 0 switches the damping off.
    pub coef: f64,
}

/// Bulk viscosity of the shells (`*CONTROL_BULK_VISCOSITY` with TYPE -1 or -2): while an
/// element's area shrinks (areal strain rate `r = d_xx + d_yy < 0`), an in-plane pressure
/// `q = rho L (Q1^2 L r^2 - Q2 c r)` acts on its membrane, `L` its characteristic length and
/// `c` the plate wave speed; it spreads compressive membrane shocks over a few elements.
/// The element's stable step becomes `L / (Q + sqrt(Q^2 + c^2))`, `Q = Q1^2 L |r| + Q2 c`.
/// The energy it removes is reported as damping energy.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BulkViscosity {
    /// Quadratic coefficient Q1 (1.5 in LS-DYNA), >= 0.
    pub q1: f64,
    /// Linear coefficient Q2 (0.06 in LS-DYNA), >= 0.
    pub q2: f64,
}

impl Default for BulkViscosity {
    fn default() -> Self {
        BulkViscosity { q1: 1.5, q2: 0.06 }
    }
}

/// Hourglass control form.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum HourglassForm {
    /// Stiffness form (LS-DYNA IHQ 4-6), the default: generalised hourglass forces grow
    /// with the hourglass displacement; conservative.
    #[default]
    Stiffness,
    /// Viscous form (LS-DYNA IHQ 1-3): forces proportional to the hourglass velocity.
    Viscous,
}

/// Hourglass control: form and coefficients for the membrane, out-of-plane (w) and
/// rotational modes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hourglass {
    /// The form.
    pub form: HourglassForm,
    /// Coefficient of the membrane modes.
    pub membrane: f64,
    /// Coefficient of the out-of-plane (w) mode.
    pub transverse: f64,
    /// Coefficient of the rotational modes.
    pub rotation: f64,
}

impl Default for Hourglass {
    fn default() -> Self {
        Hourglass {
            form: HourglassForm::Stiffness,
            membrane: 0.05,
            transverse: 0.05,
            rotation: 0.05,
        }
    }
}

/// A hourglass control that parts refer to by id (`*HOURGLASS`, `Part::hourglass`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HourglassDef {
    /// Id (HGID), > 0.
    pub id: u64,
    /// The control.
    pub hourglass: Hourglass,
}

/// The thickness of one shell in place of its section's (`*ELEMENT_SHELL_THICKNESS`): the
/// nodal thicknesses `[t1, t2, t3, t4]`, a 0 standing for the section's thickness. The
/// shell takes the mean over its nodes (three for a triangle), as a section with unequal
/// nodal thicknesses does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElementThickness {
    /// The shell's id.
    pub shell: u64,
    /// Nodal thicknesses (0: the section's).
    pub nodal: [f64; 4],
}

/// A named list of parts (`*SET_PART_LIST`, `_GENERATE`).
#[derive(Debug, Clone, PartialEq)]
pub struct PartSet {
    /// Set id.
    pub id: u64,
    /// Part ids.
    pub parts: Vec<u64>,
}

/// What a prescribed motion drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MotionTarget {
    /// One node.
    Node(u64),
    /// The nodes of a node set.
    NodeSet(u64),
    /// The rigid body of a rigid part (its centre of mass and rotation).
    Rigid(u64),
}

/// Which quantity a prescribed-motion curve gives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MotionKind {
    /// Velocity (VAD 0).
    Velocity,
    /// Acceleration (VAD 1).
    Acceleration,
    /// Displacement from the initial position (VAD 2).
    Displacement,
}

/// A prescribed motion (`*BOUNDARY_PRESCRIBED_MOTION_NODE|SET|RIGID`): degree of freedom
/// `dof` (0-2 translations x, y, z; 3-5 rotations about x, y, z) of the target follows
/// `scale * curve(t)` as a velocity, acceleration or displacement while
/// `birth <= t <= death`; outside that window the degree of freedom is free.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PrescribedMotion {
    /// What is driven.
    pub target: MotionTarget,
    /// The degree of freedom, 0 to 5.
    pub dof: usize,
    /// What the curve gives.
    pub kind: MotionKind,
    /// Curve id.
    pub curve: u64,
    /// Scale factor on the curve.
    pub scale: f64,
    /// Start time.
    pub birth: f64,
    /// End time.
    pub death: f64,
}

/// The nodes of a [`SpotWeld`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WeldNodes {
    /// Two nodes (`*CONSTRAINED_SPOTWELD` N1, N2).
    Pair([u64; 2]),
    /// The nodes of a node set, at least 2 (`*CONSTRAINED_GENERALIZED_WELD_SPOT` NSID).
    Set(u64),
}

/// A spot weld (`*CONSTRAINED_SPOTWELD`, `*CONSTRAINED_GENERALIZED_WELD_SPOT`): its nodes
/// move as one rigid body (with any other weld or rigid part that shares a node), which
/// never fails.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SpotWeld {
    /// Weld id (0 when the deck gives none).
    pub id: u64,
    /// The welded nodes.
    pub nodes: WeldNodes,
}

/// Run controls.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Control {
    /// End time, > 0.
    pub end_time: f64,
    /// Largest number of cycles (0 = no limit).
    pub end_cycles: u64,
    /// Time-step safety factor applied to the smallest element step (0.9 by default).
    pub tssfac: f64,
    /// A fixed time step overriding the computed one (for verification of the stability
    /// limit); `None` by default.
    pub fixed_dt: Option<f64>,
    /// The run stops with an error when the step falls below `dtmin_factor` times the first
    /// step (0 = never; LS-DYNA's DTMIN).
    pub dtmin_factor: f64,
    /// Characteristic length rule: false = area / max(longest side, longest diagonal)
    /// (ISDO 0), true = area / longest diagonal (ISDO 1).
    pub isdo_diagonal: bool,
    /// Warping projection of the quads (on by default): rigid motions of warped elements
    /// give no strain and element forces are self-equilibrated.
    pub warping_projection: bool,
    /// Invariant node numbering of the quads (`*CONTROL_ACCURACY` INN 2; off by default):
    /// the corotational frame's first axis bisects the element's diagonals, so that the
    /// result of an element does not depend on which node is numbered first or on the
    /// direction of numbering (a mirrored mesh gives a mirrored result).
    pub invariant_numbering: bool,
    /// Stop the run on a quad whose corner Jacobian in its plane turns non-positive (a
    /// reentrant or crossed corner; on by default). The one-point quad is evaluated only at
    /// its centre, where the Jacobian is a quarter of the area in the diagonals' frame
    /// (positive by construction), so it can carry on through such a shape; LS-DYNA makes
    /// the check only when `*CONTROL_SHELL` NFAIL1 asks for it (off in a deck without it).
    pub distortion_check: bool,
    /// The run stops with an error when the energy ratio (total over initial plus external
    /// work) exceeds this bound (1.5 by default).
    pub energy_ratio_bound: f64,
}

impl Default for Control {
    fn default() -> Self {
        Control {
            end_time: 1.0e-3,
            end_cycles: 0,
            tssfac: 0.9,
            fixed_dt: None,
            dtmin_factor: 0.0,
            isdo_diagonal: false,
            warping_projection: true,
            invariant_numbering: false,
            distortion_check: true,
            energy_ratio_bound: 1.5,
        }
    }
}

/// Output requests: history nodes and the sampling interval of histories and energies.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Output {
    /// Nodes whose displacement, velocity and acceleration are sampled.
    pub history_nodes: Vec<u64>,
    /// Sampling interval of nodal histories and energies; 0 means end time / 1000.
    pub interval: f64,
}

/// A complete model.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ShellModel {
    /// Title (`*TITLE`).
    pub title: String,
    /// Nodes.
    pub nodes: Vec<Node>,
    /// Shell elements.
    pub shells: Vec<Shell>,
    /// Parts.
    pub parts: Vec<Part>,
    /// Sections.
    pub sections: Vec<Section>,
    /// Materials.
    pub materials: Vec<Material>,
    /// Concentrated masses.
    pub masses: Vec<PointMass>,
    /// Node sets.
    pub node_sets: Vec<NodeSet>,
    /// Initial velocities, applied in order (later ones override).
    pub initial_velocities: Vec<InitialVelocity>,
    /// Single-point constraints.
    pub spcs: Vec<Spc>,
    /// Rigid walls.
    pub walls: Vec<RigidWall>,
    /// Hourglass definitions that parts refer to.
    pub hourglass_defs: Vec<HourglassDef>,
    /// Shells whose thickness is their own rather than their section's.
    pub element_thickness: Vec<ElementThickness>,
    /// Part sets.
    pub part_sets: Vec<PartSet>,
    /// Prescribed motions.
    pub prescribed: Vec<PrescribedMotion>,
    /// Spot welds.
    pub spot_welds: Vec<SpotWeld>,
    /// Segment contact interfaces.
    pub contacts: Vec<crate::contact::Contact>,
    /// Settings shared by the contact interfaces.
    pub contact_control: crate::contact::ContactControl,
    /// Curves.
    pub curves: Vec<Curve>,
    /// Body acceleration along z (gravity).
    pub body_load_z: Option<BodyLoadZ>,
    /// Mass-proportional damping constant D (1/time): nodal force `-D m v`.
    pub damping: f64,
    /// Bulk viscosity of the shells (`None`: off, as in LS-DYNA, whose default bulk
    /// viscosity acts on solids only).
    pub bulk_viscosity: Option<BulkViscosity>,
    /// Stiffness-proportional damping per part (at most one entry per part; the reader
    /// expands `*DAMPING_PART_STIFFNESS_SET` to the parts of the set).
    pub stiffness_damping: Vec<PartStiffnessDamping>,
    /// Hourglass control.
    pub hourglass: Hourglass,
    /// Run controls.
    pub control: Control,
    /// Output requests.
    pub output: Output,
}

impl ShellModel {
    /// An empty model with default controls.
    pub fn new(title: impl Into<String>) -> Self {
        ShellModel {
            title: title.into(),
            ..Default::default()
        }
    }

    /// Checks the model as [`Simulation::new`](crate::Simulation::new) does before a run,
    /// without allocating the run's state: every id referenced and defined once, element
    /// geometry, and every value in range.
    ///
    /// # Errors
    /// As [`Simulation::new`](crate::Simulation::new).
    pub fn check(&self) -> crate::Result<()> {
        crate::setup::compile(self).map(|_| ())
    }

    /// Adds a node.
    pub fn add_node(&mut self, id: u64, x: [f64; 3]) -> &mut Self {
        self.nodes.push(Node { id, x });
        self
    }

    /// Adds a quad (or a triangle when `n4 == n3`).
    pub fn add_shell(&mut self, id: u64, part: u64, nodes: [u64; 4]) -> &mut Self {
        self.shells.push(Shell { id, part, nodes });
        self
    }

    /// Adds a part.
    pub fn add_part(&mut self, id: u64, section: u64, material: u64) -> &mut Self {
        self.parts.push(Part {
            id,
            title: format!("part {id}"),
            section,
            material,
            hourglass: 0,
        });
        self
    }

    /// Adds a concentrated mass at a node.
    pub fn add_mass(&mut self, id: u64, node: u64, mass: f64) -> &mut Self {
        self.masses.push(PointMass { id, node, mass });
        self
    }

    /// Sets gravity of magnitude `g` toward -z (a constant curve and `*LOAD_BODY_Z`). The
    /// curve takes the first id above the existing ones.
    pub fn set_gravity(&mut self, g: f64) -> &mut Self {
        let id = self.curves.iter().map(|c| c.id).max().unwrap_or(0) + 1;
        self.curves
            .push(Curve::new(id, vec![(0.0, 1.0), (1.0e30, 1.0)]));
        self.body_load_z = Some(BodyLoadZ {
            curve: id,
            scale: g,
        });
        self
    }

    /// The total mass of the shells (from density, thickness, area) and point masses, on
    /// the initial geometry; elements whose references are undefined are skipped.
    pub fn total_mass(&self) -> f64 {
        let mut m: f64 = self.masses.iter().map(|p| p.mass).sum();
        let node = |id: u64| self.nodes.iter().find(|n| n.id == id).map(|n| n.x);
        for s in &self.shells {
            let Some(part) = self.parts.iter().find(|p| p.id == s.part) else {
                continue;
            };
            let sec = self.sections.iter().find(|q| q.id == part.section);
            let mat = self.materials.iter().find(|q| q.id == part.material);
            let (Some(sec), Some(mat)) = (sec, mat) else {
                continue;
            };
            let xs: Option<Vec<[f64; 3]>> = s.nodes.iter().map(|&n| node(n)).collect();
            if let Some(xs) = xs {
                m += mat.density * sec.thickness * crate::geometry::polygon_area(&xs);
            }
        }
        m
    }
}
