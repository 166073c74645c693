//! The explicit solver: central-difference time integration, assembly, rigid walls,
//! constraints, energies and sampled outputs.
//!
//! One cycle, from `x^n`, `v^{n+1/2}`, `omega^{n+1/2}` and the step `dt^{n+1/2}`:
//!
//! 1. `x^{n+1} = x^n + dt^{n+1/2} v^{n+1/2}`, `t^{n+1} = t^n + dt^{n+1/2}`.
//! 2. Element loop (rayon, one force slot per element) on `x^{n+1}` with the mid-step
//!    velocities: stresses, internal forces, element steps, energy increments.
//! 3. Gather of the element outputs at each node in a fixed order (node-to-element lists sorted by
//!    element), so results are bit-identical for any thread count.
//! 4. `a = (f_ext - f_int) / m - D v^{n+1/2}`, `alpha = -m_int / I`.
//! 5. Next step `dt^{n+3/2} = TSSFAC min_e dt_e` and the velocity step
//!    `dt^{n+1} = (dt^{n+1/2} + dt^{n+3/2}) / 2`.
//! 6. Rigid walls correct `a` of nodes that would cross the plane; constraints zero the
//!    fixed components.
//! 7. `v^{n+1} = v^{n+1/2} + dt^{n+1/2}/2 a` (output), `v^{n+3/2} = v^{n+1/2} + dt^{n+1} a`.
//! 8. Energies at `t^{n+1}`.
//!
//! The run starts stress-free with `a^0 = f_ext / m` and `v^{1/2} = v^0 + dt^{1/2}/2 a^0`.

use impactcal_core::{Histories, NodalQuantity};
use rayon::prelude::*;

use crate::contact::{ContactNodes, ContactState};
use crate::element::quad_lanes::{Block, LANES, quad_block};
use crate::element::{
    self, ElementFault, ElementOutput, KernelOptions, STATE_HEAD, STATE_PER_POINT,
};
use crate::error::{Result, ShellError};
use crate::geometry::{dot, sub};
use crate::model::{Curve, MotionKind, ShellModel, WallMethod};
use crate::rigid::{RigidState, cross, inverse, mul, rotation};
use crate::setup::{Compiled, DriveTarget, Elem, compile, wall_gap};

/// Elements per rayon task in the element loop; fixed so that scheduling never changes the
/// arithmetic.
const ELEMENT_CHUNK: usize = 256;
/// Nodes per rayon task in the node loops.
const NODE_CHUNK: usize = 1024;
/// Values per part in a part sample: four energies and three momentum components.
const PART_SAMPLE: usize = 7;

/// Energies at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Energies {
    /// Kinetic energy (translational and rotational).
    pub kinetic: f64,
    /// Internal (strain and plastic) energy.
    pub internal: f64,
    /// Hourglass energy.
    pub hourglass: f64,
    /// Energy removed by the rigid walls (normal impact and friction).
    pub contact: f64,
    /// The friction share of `contact`.
    pub friction: f64,
    /// Energy removed by damping: mass-proportional (`*DAMPING_GLOBAL`) and
    /// stiffness-proportional (`*DAMPING_PART_STIFFNESS`).
    pub damping: f64,
    /// Work of the external (body) forces.
    pub external_work: f64,
    /// Initial energy (kinetic at t = 0).
    pub initial: f64,
}

impl Energies {
    /// Total: `kinetic + internal + hourglass + contact + damping`.
    pub fn total(&self) -> f64 {
        self.kinetic + self.internal + self.hourglass + self.contact + self.damping
    }

    /// Energy ratio `total / (initial + external_work)` (1 for a balanced run; 1 when the
    /// reference is zero and nothing moved).
    pub fn ratio(&self) -> f64 {
        let r = self.initial + self.external_work;
        if r.abs() > 0.0 { self.total() / r } else { 1.0 }
    }
}

/// A summary of a completed run.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSummary {
    /// Number of cycles.
    pub cycles: u64,
    /// Time reached.
    pub end_time: f64,
    /// Time step of the first cycle.
    pub dt_first: f64,
    /// Smallest time step used.
    pub dt_min: f64,
    /// Largest time step used.
    pub dt_max: f64,
    /// Final energy ratio.
    pub energy_ratio: f64,
    /// Final hourglass energy over internal energy (0 when there is no internal energy).
    pub hourglass_share: f64,
    /// Largest normal force of all walls together over the samples of [`RunResult::walls`]
    /// (interval means, not the force of a single cycle).
    pub peak_wall_force: f64,
    /// Each wall's id and its largest sampled normal force.
    pub wall_peaks: Vec<(u64, f64)>,
    /// Final energies.
    pub energies: Energies,
    /// Number of shells.
    pub elements: usize,
    /// Total nodal mass.
    pub mass: f64,
}

/// Energies of one part, summed over its shells.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PartEnergies {
    /// Part id.
    pub part: u64,
    /// Internal (strain and plastic) energy.
    pub internal: f64,
    /// Hourglass energy.
    pub hourglass: f64,
    /// Energy removed by stiffness-proportional damping.
    pub damping: f64,
}

/// The outputs of a run: sampled nodal histories (when history nodes were requested), the
/// energy table and a summary.
#[derive(Debug, Clone)]
pub struct RunResult {
    /// Displacements at the history nodes, labels `<node>.<x|y|z>`.
    pub displacement: Option<Histories>,
    /// Velocities at the history nodes.
    pub velocity: Option<Histories>,
    /// Accelerations at the history nodes.
    pub acceleration: Option<Histories>,
    /// Energies and the wall force, sampled at the output interval. Channels:
    /// `kinetic, internal, hourglass, contact, friction, damping, external_work, total,
    /// energy_ratio, wall_force, wall_fx, wall_fy, wall_fz` (the wall force is the force of
    /// the walls on the structure; `wall_force` is its normal component).
    pub energies: Histories,
    /// The force of each rigid wall on the structure, sampled at the output interval as
    /// the mean over each interval (LS-DYNA's `rwforc` quantities): channels
    /// `<wall id>.fx, .fy, .fz` (global components) and `<wall id>.f` (normal force). A
    /// wall's id is its `_ID` card's, else its 1-based position among the walls. `None`
    /// for a model without walls.
    pub walls: Option<Histories>,
    /// The energies of each contact interface sampled at the output interval (LS-DYNA's
    /// `sleout`): channels `<id>.energy` (the work its forces took from the structure:
    /// spring energy stored now plus what damping and friction dissipated) and
    /// `<id>.friction` (the friction share). An interface's id is its `_ID` card's, else
    /// its 1-based position among the interfaces. `None` for a model without contact.
    pub contacts: Option<Histories>,
    /// The forces of each contact interface sampled at the output interval as the mean over
    /// each interval (like [`RunResult::walls`]; LS-DYNA's `rcforc` resultants): channels
    /// `<id>.fx, <id>.fy, <id>.fz`, the resultant of the interface's forces on its slave
    /// side (the master side takes the opposite: the forces conserve momentum), and
    /// `<id>.fn`, the sum of the normal (penalty and damping) force over every contact of
    /// the interface. The slave side of a nodes-to-surface contact is its slave nodes; of a
    /// surface-to-surface contact, the slave surface's nodes. A single-surface contact's
    /// forces all act within its one side, so its resultant is zero (to round-off) and
    /// `<id>.fn` is the measure of its load. `None` for a model without contact.
    pub contact_forces: Option<Histories>,
    /// The energies of each part sampled at the output interval (LS-DYNA's `matsum`):
    /// channels `<part>.internal, <part>.kinetic, <part>.hourglass, <part>.damping`.
    /// Concentrated masses belong to no part.
    pub part_energies: Histories,
    /// The velocity of each part's centre of mass sampled at the output interval
    /// (LS-DYNA's `matsum` rigid-body velocities): channels `<part>.vx, <part>.vy,
    /// <part>.vz`, each `sum m v / sum m` over the mass the part's shells give their nodes
    /// (a node shared by two parts counts in each with its share). Concentrated masses
    /// belong to no part.
    pub part_velocities: Histories,
    /// Final energies of each part, in model order.
    pub parts: Vec<PartEnergies>,
    /// Summary figures.
    pub summary: RunSummary,
}

impl RunResult {
    /// The nodal histories of one quantity, if history nodes were requested.
    pub fn histories(&self, q: NodalQuantity) -> Option<&Histories> {
        match q {
            NodalQuantity::Displacement => self.displacement.as_ref(),
            NodalQuantity::Velocity => self.velocity.as_ref(),
            NodalQuantity::Acceleration => self.acceleration.as_ref(),
        }
    }
}

/// Progress of a run, passed to the callback of [`Simulation::run_with_progress`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// Current time.
    pub time: f64,
    /// End time.
    pub end_time: f64,
    /// Cycles so far.
    pub cycle: u64,
    /// Current time step.
    pub dt: f64,
}

/// The labels of the energy table, in order.
pub const ENERGY_LABELS: [&str; 13] = [
    "kinetic",
    "internal",
    "hourglass",
    "contact",
    "friction",
    "damping",
    "external_work",
    "total",
    "energy_ratio",
    "wall_force",
    "wall_fx",
    "wall_fy",
    "wall_fz",
];

/// A validated model with its state: build it with [`Simulation::new`], then
/// [`run`](Simulation::run) it (or [`step`](Simulation::step) it cycle by cycle).
pub struct Simulation {
    c: Compiled,
    body: Option<(Curve, f64)>,
    damping: f64,
    control: crate::model::Control,
    kernel: KernelOptions,
    interval: f64,
    stride: usize,
    state: Vec<f64>,
    /// Per-element outputs of the last element pass (forces, step, energies).
    out: Vec<ElementOutput>,
    /// Per-element faults of the last element pass.
    faults: Vec<Option<ElementFault>>,
    /// Per-element accumulated internal, hourglass and damping energy.
    elem_energy: Vec<[f64; 3]>,
    chunks: Vec<ChunkSum>,
    /// Per-chunk partial sums of the node loops.
    node_sums: Vec<f64>,
    /// Per-chunk kinetic energies and finiteness of the velocity update.
    kick_sums: Vec<KickSum>,
    /// A velocity of the last update is not finite.
    v_bad: bool,
    /// `1 / m` per node, 0 where the node has no mass.
    inv_mass: Vec<f64>,
    /// `1 / I` per node, 0 where the node has no rotary inertia.
    inv_inertia: Vec<f64>,
    csr_start: Vec<u32>,
    csr: Vec<u32>,
    x: Vec<[f64; 3]>,
    v: Vec<[f64; 3]>,
    w: Vec<[f64; 3]>,
    a: Vec<[f64; 3]>,
    alpha: Vec<[f64; 3]>,
    v_int: Vec<[f64; 3]>,
    w_int: Vec<[f64; 3]>,
    time: f64,
    cycle: u64,
    dt_half: f64,
    dt_first: f64,
    /// The smallest element step of the undeformed model (before TSSFAC): the reference
    /// step of penalty walls.
    dt_ref: f64,
    dt_min: f64,
    dt_max: f64,
    energies: Energies,
    wall_force: [f64; 3],
    wall_normal: f64,
    /// Per wall, the impulse given to the structure since the start: `[x, y, z, normal]`.
    wall_impulse: Vec<[f64; 4]>,
    /// The rigid bodies' states.
    bodies: Vec<RigidState>,
    /// Per element, the mass and rotary inertia it gives each of its nodes.
    elem_mass: Vec<[f64; 2]>,
    /// The state of each contact interface.
    contacts: Vec<ContactState>,
    /// Per contact interface, the impulse of its force on the slave side since the start
    /// and the integral of its total normal force: `[x, y, z, normal]`.
    contact_impulse: Vec<[f64; 4]>,
    started: bool,
}

/// Per-chunk results of the velocity update: translational and rotational kinetic energy,
/// and whether a velocity is not finite.
#[derive(Debug, Clone, Copy, Default)]
struct KickSum {
    kt: f64,
    kr: f64,
    bad: bool,
}

/// Per-chunk reductions of the element loop, combined in chunk order.
#[derive(Debug, Clone, Copy)]
struct ChunkSum {
    internal: f64,
    hourglass: f64,
    damping: f64,
    dt_min: f64,
    /// Element (global index) of `dt_min`.
    arg: usize,
    /// First element of the chunk with a fault or a non-finite step.
    problem: Option<usize>,
}

impl Default for ChunkSum {
    fn default() -> Self {
        ChunkSum {
            internal: 0.0,
            hourglass: 0.0,
            damping: 0.0,
            dt_min: f64::INFINITY,
            arg: 0,
            problem: None,
        }
    }
}

impl Simulation {
    /// Validates `model` and prepares the run (masses, inertias, initial velocities, first
    /// time step).
    ///
    /// # Errors
    /// [`ShellError::Reference`] for undefined or duplicate ids, [`ShellError::Element`] for
    /// repeated nodes, degenerate or inverted elements, [`ShellError::Value`] for values out
    /// of range (thickness, density, nu, NIP, friction, controls) and for nodes that start
    /// behind a rigid wall.
    pub fn new(model: &ShellModel) -> Result<Self> {
        let c = compile(model)?;
        let max_nip = c.parts.iter().map(|p| p.z.len()).max().unwrap_or(1);
        let stride = STATE_HEAD + STATE_PER_POINT * max_nip;
        let ne = c.elems.len();
        let nn = c.x0.len();
        // Node-to-slot lists, in element order.
        let mut count = vec![0u32; nn + 1];
        for e in &c.elems {
            for &n in &e.nodes[..if e.tri { 3 } else { 4 }] {
                count[n as usize + 1] += 1;
            }
        }
        for i in 0..nn {
            count[i + 1] += count[i];
        }
        let mut fill = count.clone();
        let mut csr = vec![0u32; count[nn] as usize];
        for (k, e) in c.elems.iter().enumerate() {
            for (s, &n) in e.nodes[..if e.tri { 3 } else { 4 }].iter().enumerate() {
                csr[fill[n as usize] as usize] = (k * 4 + s) as u32;
                fill[n as usize] += 1;
            }
        }
        let body = match &model.body_load_z {
            Some(b) => model
                .curves
                .iter()
                .find(|c| c.id == b.curve)
                .map(|c| (c.clone(), b.scale)),
            None => None,
        };
        let interval = if model.output.interval > 0.0 {
            model.output.interval
        } else {
            model.control.end_time / 1000.0
        };
        let x = c.x0.clone();
        let v = c.v0.clone();
        let w = c.w0.clone();
        let mut sim = Simulation {
            body,
            damping: model.damping,
            control: model.control,
            kernel: KernelOptions {
                projection: model.control.warping_projection,
                isdo_diagonal: model.control.isdo_diagonal,
                invariant: model.control.invariant_numbering,
                distortion_check: model.control.distortion_check,
            },
            interval,
            stride,
            state: vec![0.0; stride * ne],
            out: vec![ElementOutput::default(); ne],
            faults: vec![None; ne],
            elem_energy: vec![[0.0; 3]; ne],
            chunks: vec![ChunkSum::default(); ne.div_ceil(ELEMENT_CHUNK)],
            node_sums: vec![0.0; nn.div_ceil(NODE_CHUNK)],
            kick_sums: vec![KickSum::default(); nn.div_ceil(NODE_CHUNK)],
            v_bad: false,
            inv_mass: c
                .mass
                .iter()
                .map(|&m| if m > 0.0 { 1.0 / m } else { 0.0 })
                .collect(),
            inv_inertia: c
                .inertia
                .iter()
                .map(|&m| if m > 0.0 { 1.0 / m } else { 0.0 })
                .collect(),
            csr_start: count,
            csr,
            x,
            v_int: v.clone(),
            w_int: w.clone(),
            v,
            w,
            a: vec![[0.0; 3]; nn],
            alpha: vec![[0.0; 3]; nn],
            time: 0.0,
            cycle: 0,
            dt_half: 0.0,
            dt_first: 0.0,
            dt_ref: 0.0,
            dt_min: f64::INFINITY,
            dt_max: 0.0,
            energies: Energies::default(),
            wall_force: [0.0; 3],
            wall_normal: 0.0,
            wall_impulse: vec![[0.0; 4]; c.walls.len()],
            bodies: c
                .rigid
                .iter()
                .map(|b| RigidState::initial(b, &c.mass, &c.inertia, &c.v0, &c.w0))
                .collect(),
            elem_mass: element_masses(&c),
            contacts: c
                .contacts
                .iter()
                .map(|f| ContactState::new(f, &c.x0))
                .collect(),
            contact_impulse: vec![[0.0; 4]; c.contacts.len()],
            started: false,
            c,
        };
        sim.start()?;
        Ok(sim)
    }

    /// Node ids, in the order of [`positions`](Self::positions).
    pub fn node_ids(&self) -> &[u64] {
        &self.c.node_ids
    }

    /// Shell ids, in model order.
    pub fn element_ids(&self) -> &[u64] {
        &self.c.elem_ids
    }

    /// Current nodal positions.
    pub fn positions(&self) -> &[[f64; 3]] {
        &self.x
    }

    /// Velocities at the last completed cycle's time `t^n` (averaged from the half steps).
    pub fn velocities(&self) -> &[[f64; 3]] {
        &self.v_int
    }

    /// Lumped nodal masses (shells and point masses).
    pub fn masses(&self) -> &[f64] {
        &self.c.mass
    }

    /// Current time.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Completed cycles.
    pub fn cycle(&self) -> u64 {
        self.cycle
    }

    /// The time step of the next cycle.
    pub fn dt(&self) -> f64 {
        self.dt_half
    }

    /// The energies at the current time.
    pub fn energies(&self) -> Energies {
        self.energies
    }

    /// The force of the walls on the structure at the current time (sum over walls).
    pub fn wall_force(&self) -> [f64; 3] {
        self.wall_force
    }

    /// Each contact interface's id, energy and friction energy now (see
    /// [`RunResult::contacts`]), in model order.
    pub fn contact_energies(&self) -> Vec<(u64, f64, f64)> {
        self.c
            .contacts
            .iter()
            .zip(&self.contacts)
            .map(|(f, s)| (f.id, s.energy, s.friction))
            .collect()
    }

    /// The contact search alone, for timing (the criterion benchmark of the contact
    /// kernels): rebuilds every interface's candidate lists by the bucket sort on the
    /// current positions, as a cycle does when nodes have moved far enough, and returns the
    /// number of candidate pairs. The lists hold every pair within the search margin
    /// whenever they are built, so calling it only moves the run's next sort.
    pub fn contact_search(&mut self) -> usize {
        let mut pairs = 0;
        for (st, f) in self.contacts.iter_mut().zip(&self.c.contacts) {
            pairs += st.sort(f, &self.x);
        }
        pairs
    }

    /// The contact forces alone, for timing (the criterion benchmark of the contact
    /// kernels): one pass of every interface over its checked nodes on the current
    /// positions and velocities with the next step (penetration, penalty, damping, friction,
    /// the forces added in node order), and returns the summed normal force of the pass.
    /// The pass advances the interfaces' memory (friction, contact references) and energy
    /// as a cycle would, so a run continued after it books the extra pass: keep a
    /// simulation used for timing for timing only.
    pub fn contact_pass(&mut self) -> f64 {
        let nodes = ContactNodes {
            x: &self.x,
            v: &self.v,
            mass: &self.c.mass,
        };
        let mut normal = 0.0;
        for (st, f) in self.contacts.iter_mut().zip(&self.c.contacts) {
            st.cycle(f, &nodes, self.time, self.dt_half, &mut self.a);
            normal += st.resultant[3];
        }
        normal
    }

    /// Each contact interface's id, the number of its nodes that penetrated a segment at
    /// the start and the largest such penetration. These penetrations are kept as a
    /// reference that only additional penetration acts against (nodes are not moved).
    pub fn initial_penetrations(&self) -> Vec<(u64, usize, f64)> {
        self.c
            .contacts
            .iter()
            .zip(&self.contacts)
            .map(|(f, s)| {
                let (n, max) = s.initial_penetrations();
                (f.id, n, max)
            })
            .collect()
    }

    /// The accumulated internal, hourglass and damping energies of each part, in model
    /// order (sums over its shells in element order).
    pub fn part_energies(&self) -> Vec<PartEnergies> {
        let mut parts: Vec<PartEnergies> = self
            .c
            .part_ids
            .iter()
            .map(|&part| PartEnergies {
                part,
                ..Default::default()
            })
            .collect();
        for (e, acc) in self.c.elems.iter().zip(&self.elem_energy) {
            let p = &mut parts[e.part as usize];
            p.internal += acc[0];
            p.hourglass += acc[1];
            p.damping += acc[2];
        }
        parts
    }

    /// The elastic (recoverable) strain energy stored in the shells now: at every thickness
    /// point `(s_xx^2 + s_yy^2 - 2 nu s_xx s_yy) / (2 E) + s_xy^2 / (2 G)` integrated over
    /// the thickness and the current area, plus the transverse shear `Q^2 / (2 k_s G t)` per
    /// unit area. The internal energy less this is the plastic work (hourglass energy is
    /// booked apart).
    pub fn elastic_energy(&self) -> f64 {
        let mut total = 0.0;
        for (k, e) in self.c.elems.iter().enumerate() {
            let p = &self.c.parts[e.props as usize];
            let n = if e.tri { 3 } else { 4 };
            let xs: Vec<[f64; 3]> = e.nodes[..n].iter().map(|&i| self.x[i as usize]).collect();
            let area = crate::geometry::polygon_area(&xs);
            let st = &self.state[k * self.stride..(k + 1) * self.stride];
            let (ym, nu, g) = (p.mat.e, p.mat.nu, p.mat.g);
            let mut density = 0.0;
            for (j, w) in p.w.iter().enumerate() {
                let s = &st[STATE_HEAD + STATE_PER_POINT * j..];
                density += w
                    * ((s[0] * s[0] + s[1] * s[1] - 2.0 * nu * s[0] * s[1]) / (2.0 * ym)
                        + s[2] * s[2] / (2.0 * g));
            }
            let shear = (st[0] * st[0] + st[1] * st[1]) / (2.0 * p.shear_factor * g * p.t);
            total += area * (p.t * density + shear);
        }
        total
    }

    /// Stress state `[s_xx, s_yy, s_xy, eps_p]` of thickness point `k` of element index `e`
    /// (model order), in the element frame.
    pub fn point_state(&self, e: usize, k: usize) -> Option<[f64; 4]> {
        let nip = self.c.parts[self.c.elems.get(e)?.props as usize].z.len();
        if k >= nip {
            return None;
        }
        let s = &self.state[e * self.stride + STATE_HEAD + STATE_PER_POINT * k..][..4];
        Some([s[0], s[1], s[2], s[3]])
    }

    fn body_accel(&self, t: f64) -> f64 {
        match &self.body {
            Some((curve, sf)) => -sf * curve.eval(t),
            None => 0.0,
        }
    }

    /// Runs the element loop for a step `dt` on the current positions and mid-step
    /// velocities: fills the element outputs and the chunk reductions. Each fixed chunk of
    /// `ELEMENT_CHUNK` elements is one task; inside it, runs of up to `LANES` consecutive
    /// quads of one part go through the blocked kernel, triangles one by one.
    fn element_loop(&mut self, dt: f64) {
        let (x, v, w) = (&self.x, &self.v, &self.w);
        let (parts, elems) = (&self.c.parts, &self.c.elems);
        let kernel = self.kernel;
        let stride = self.stride;
        self.state
            .par_chunks_mut(stride * ELEMENT_CHUNK)
            .zip(self.out.par_chunks_mut(ELEMENT_CHUNK))
            .zip(self.faults.par_chunks_mut(ELEMENT_CHUNK))
            .zip(self.elem_energy.par_chunks_mut(ELEMENT_CHUNK))
            .zip(self.chunks.par_iter_mut())
            .enumerate()
            .for_each(|(ci, ((((st, out), faults), acc), sum))| {
                let first = ci * ELEMENT_CHUNK;
                let n = out.len();
                let mut k = 0;
                while k < n {
                    let e = &elems[first + k];
                    let props = &parts[e.props as usize];
                    if props.rigid {
                        out[k] = ElementOutput {
                            dt: f64::INFINITY,
                            ..ElementOutput::default()
                        };
                        faults[k] = None;
                        k += 1;
                        continue;
                    }
                    if e.tri {
                        let g = |a: &[[f64; 3]]| {
                            [
                                a[e.nodes[0] as usize],
                                a[e.nodes[1] as usize],
                                a[e.nodes[2] as usize],
                            ]
                        };
                        let es = &mut st[k * stride..(k + 1) * stride];
                        (out[k], faults[k]) =
                            match element::triangle(&g(x), &g(v), &g(w), props, es, dt, kernel) {
                                Ok(o) => (o, None),
                                Err(f) => (ElementOutput::default(), Some(f)),
                            };
                        k += 1;
                        continue;
                    }
                    let mut blk = Block {
                        nodes: [e.nodes; LANES],
                        slot: [k; LANES],
                        active: 1,
                    };
                    while blk.active < LANES && k + blk.active < n {
                        let f = &elems[first + k + blk.active];
                        if f.tri || f.props != e.props {
                            break;
                        }
                        blk.nodes[blk.active] = f.nodes;
                        blk.slot[blk.active] = k + blk.active;
                        blk.active += 1;
                    }
                    quad_block(&blk, x, v, w, props, st, stride, out, faults, dt, kernel);
                    k += blk.active;
                }
                let mut cs = ChunkSum::default();
                for (j, (o, f)) in out.iter().zip(faults.iter()).enumerate() {
                    acc[j][0] += o.internal;
                    acc[j][1] += o.hourglass;
                    acc[j][2] += o.damping;
                    cs.internal += o.internal;
                    cs.hourglass += o.hourglass;
                    cs.damping += o.damping;
                    if cs.problem.is_none() && (f.is_some() || !(o.dt >= 0.0)) {
                        cs.problem = Some(first + j);
                    }
                    if o.dt < cs.dt_min {
                        cs.dt_min = o.dt;
                        cs.arg = first + j;
                    }
                }
                *sum = cs;
            });
    }

    /// Gathers slot forces into accelerations (before walls and constraints).
    fn gather(&mut self, t: f64) {
        let g = self.body_accel(t);

        let (out, csr, start) = (&self.out, &self.csr, &self.csr_start);
        let (inv_mass, inv_inertia) = (&self.inv_mass, &self.inv_inertia);
        let damping = self.damping;
        let v = &self.v;
        self.a
            .par_iter_mut()
            .zip(self.alpha.par_iter_mut())
            .enumerate()
            .with_min_len(NODE_CHUNK)
            .for_each(|(i, (a, al))| {
                let mut f = [0.0; 6];
                for &k in &csr[start[i] as usize..start[i + 1] as usize] {
                    let s = &out[k as usize / 4].f[k as usize % 4];
                    for d in 0..6 {
                        f[d] += s[d];
                    }
                }
                let im = inv_mass[i];
                if im > 0.0 {
                    for d in 0..3 {
                        a[d] = -f[d] * im - damping * v[i][d];
                    }
                    a[2] += g;
                } else {
                    *a = [0.0; 3];
                }
                let ii = inv_inertia[i];
                *al = [-f[3] * ii, -f[4] * ii, -f[5] * ii];
            });
    }

    /// Rigid walls, constraints and the velocity update over `dt_v` (from `v^{n-1/2}` to
    /// `v^{n+1/2}`), with `h_prev` the part of it before `t^n` and `dt_next` the next
    /// position step. Adds the work of the walls (contact, friction) and of the global
    /// damping over the step to the running energies and sets the kinetic energy of the new
    /// velocities; returns nothing.
    fn kick(&mut self, h_prev: f64, dt_next: f64) {
        let dt_v = h_prev + 0.5 * dt_next;
        self.walls(dt_v, dt_next);
        self.rigid(dt_v, dt_next);
        self.drive_nodes(dt_v, dt_next);
        for &(i, mask) in &self.c.fixed {
            let i = i as usize;
            for d in 0..3 {
                if mask[d] {
                    self.a[i][d] = 0.0;
                }
                if mask[3 + d] {
                    self.alpha[i][d] = 0.0;
                }
            }
        }
        // Damping energy over the kick, with the mid-step velocities.
        if self.damping > 0.0 {
            let e: f64 = chunked_sum(&self.v, &self.c.mass, |v, m| m * dot(*v, *v));
            self.energies.damping += self.damping * e * dt_v;
        }
        // Velocity update, kinetic energy and the finiteness check in one pass over fixed
        // node chunks, summed in chunk order.
        let half = 0.5 * dt_next;
        let (a, al) = (&self.a, &self.alpha);
        let (mass, inertia) = (&self.c.mass, &self.c.inertia);
        self.v
            .par_chunks_mut(NODE_CHUNK)
            .zip(self.w.par_chunks_mut(NODE_CHUNK))
            .zip(self.v_int.par_chunks_mut(NODE_CHUNK))
            .zip(self.w_int.par_chunks_mut(NODE_CHUNK))
            .zip(self.kick_sums.par_iter_mut())
            .enumerate()
            .for_each(|(c, ((((v, w), vi), wi), sum))| {
                let first = c * NODE_CHUNK;
                let (mut kt, mut kr, mut bad) = (0.0, 0.0, false);
                for j in 0..v.len() {
                    let i = first + j;
                    for d in 0..3 {
                        vi[j][d] = v[j][d] + h_prev * a[i][d];
                        v[j][d] = vi[j][d] + half * a[i][d];
                        wi[j][d] = w[j][d] + h_prev * al[i][d];
                        w[j][d] = wi[j][d] + half * al[i][d];
                    }
                    kt += 0.5 * mass[i] * dot(vi[j], vi[j]);
                    kr += 0.5 * inertia[i] * dot(wi[j], wi[j]);
                    bad |= v[j].iter().any(|x| !x.is_finite());
                }
                *sum = KickSum { kt, kr, bad };
            });
        let (mut ke_t, mut ke_r) = (0.0, 0.0);
        self.v_bad = false;
        for s in &self.kick_sums {
            ke_t += s.kt;
            ke_r += s.kr;
            self.v_bad |= s.bad;
        }
        self.energies.kinetic = ke_t + ke_r;
    }

    /// Segment contact: each interface's forces on the current positions with the mid-step
    /// velocities added to the accelerations (before walls, rigid bodies and constraints),
    /// its work over the step `dt` just taken booked as contact (and friction) energy, and
    /// its impulse over the velocity step `dt / 2 + dt_next / 2` the forces act on.
    fn contact(&mut self, dt: f64, dt_next: f64) {
        let dt_v = 0.5 * (dt + dt_next);
        let nodes = ContactNodes {
            x: &self.x,
            v: &self.v,
            mass: &self.c.mass,
        };
        for (st, f) in self.contacts.iter_mut().zip(&self.c.contacts) {
            let (e0, f0) = (st.energy, st.friction);
            st.cycle(f, &nodes, self.time, dt, &mut self.a);
            self.energies.contact += st.energy - e0;
            self.energies.friction += st.friction - f0;
        }
        for (j, st) in self.contact_impulse.iter_mut().zip(&self.contacts) {
            for k in 0..4 {
                j[k] += st.resultant[k] * dt_v;
            }
        }
    }

    /// Rigid walls: corrects the accelerations of the nodes that would enter a wall in the
    /// next step (kinematic) or that are in it (penalty), books the energy they remove and
    /// the impulse each wall gives.
    fn walls(&mut self, dt_v: f64, dt_next: f64) {
        let mut force = [0.0; 3];
        let mut normal_force = 0.0;
        for (w, wall) in self.c.walls.iter().enumerate() {
            let mut impulse = [0.0; 4];
            for &i in &wall.nodes {
                let i = i as usize;
                let m = self.c.mass[i];
                let (d0, n) = wall_gap(wall.shape, self.x[i], wall.point, wall.normal);
                if !d0.is_finite() {
                    continue;
                }
                let vold = self.v[i];
                let mut vs = [0.0; 3];
                for k in 0..3 {
                    vs[k] = vold[k] + dt_v * self.a[i][k];
                }
                let vn = dot(vs, n);
                let mut vt = [vs[0] - vn * n[0], vs[1] - vn * n[1], vs[2] - vn * n[2]];
                let vt_len = dot(vt, vt).sqrt();
                let (vn_new, dvn) = match wall.method {
                    WallMethod::Kinematic => {
                        let vmin = -d0 / dt_next;
                        if vn >= vmin {
                            continue;
                        }
                        (vmin, vmin - vn)
                    }
                    WallMethod::Penalty { alpha, damping } => {
                        if d0 >= 0.0 {
                            continue;
                        }
                        // Spring k = alpha m / dt_ref^2 and dashpot c = 2 zeta sqrt(k m) on
                        // the predicted normal velocity; together they never pull the node
                        // toward the wall.
                        let w2 = alpha / (self.dt_ref * self.dt_ref);
                        let spring = -w2 * d0 * dt_v;
                        // Dashpot on the mean of the normal velocities before and after.
                        let c = 2.0 * damping * w2.sqrt() * dt_v;
                        let dvn = ((spring - c * vn) / (1.0 + 0.5 * c)).max(0.0);
                        (vn + dvn, dvn)
                    }
                };
                let reduce = wall.mu * dvn;
                let keep = if wall.mu.is_infinite() || reduce >= vt_len {
                    0.0
                } else {
                    1.0 - reduce / vt_len
                };
                for k in 0..3 {
                    vt[k] *= keep;
                }
                let vnew = [
                    vt[0] + vn_new * n[0],
                    vt[1] + vn_new * n[1],
                    vt[2] + vn_new * n[2],
                ];
                // Work of the wall impulse with the mean velocity over the kick (the power
                // of a force in the central-difference energy balance).
                let vbar = [
                    0.5 * (vold[0] + vnew[0]),
                    0.5 * (vold[1] + vnew[1]),
                    0.5 * (vold[2] + vnew[2]),
                ];
                let imp = [
                    m * (vnew[0] - vs[0]),
                    m * (vnew[1] - vs[1]),
                    m * (vnew[2] - vs[2]),
                ];
                let work = dot(imp, vbar);
                let imp_n = dot(imp, n);
                let work_t = work - imp_n * dot(vbar, n);
                self.energies.contact -= work;
                self.energies.friction -= work_t;
                for k in 0..3 {
                    let f = m * (vnew[k] - vs[k]) / dt_v;
                    force[k] += f;
                    impulse[k] += imp[k];
                    self.a[i][k] = (vnew[k] - vold[k]) / dt_v;
                }
                normal_force += m * dvn / dt_v;
                impulse[3] += m * dvn;
            }
            for k in 0..4 {
                self.wall_impulse[w][k] += impulse[k];
            }
        }
        self.wall_force = force;
        self.wall_normal = normal_force;
    }

    /// The value of drive `d` at time `t` on the scale of its curve, and whether it acts.
    fn drive_value(&self, d: &crate::setup::Drive, t: f64) -> Option<f64> {
        (t >= d.birth && t <= d.death).then(|| d.scale * d.curve.eval(t))
    }

    /// Rigid bodies: from the accelerations the nodes have (internal forces of the shells
    /// around them, gravity, damping), advances each body's velocity and angular momentum,
    /// applies held directions and prescribed motions, moves its pose to the end of the
    /// next step and gives each of its nodes the velocity and angular velocity that take it
    /// there. The work of held and prescribed motions is booked as external work.
    fn rigid(&mut self, dt_v: f64, dt_next: f64) {
        let t = self.time;
        for b in 0..self.bodies.len() {
            let def = &self.c.rigid[b];
            let st = self.bodies[b];
            let mut f = [0.0; 3];
            let mut torque = [0.0; 3];
            for &i in &def.nodes {
                let i = i as usize;
                let m = self.c.mass[i];
                let fi = [m * self.a[i][0], m * self.a[i][1], m * self.a[i][2]];
                let r = crate::rigid::sub(self.x[i], st.centre);
                let ri = cross(r, fi);
                for d in 0..3 {
                    f[d] += fi[d];
                    torque[d] += ri[d] + self.c.inertia[i] * self.alpha[i][d];
                }
            }
            let j = st.inertia(def);
            let l = mul(&j, st.w);
            let mut v = [0.0; 3];
            let mut lnew = [0.0; 3];
            for d in 0..3 {
                v[d] = st.v[d] + dt_v * f[d] / def.mass;
                lnew[d] = l[d] + dt_v * torque[d];
            }
            let mut w = mul(&inverse(&j), lnew);
            let (free_v, free_w) = (v, w);
            let mut held = st;
            held.v = v;
            held.w = w;
            held.hold(&def.constraints);
            v = held.v;
            w = held.w;
            for dr in &self.c.drives {
                if !matches!(dr.target, DriveTarget::Body(k) if k == b) {
                    continue;
                }
                let (k, lin) = if dr.dof < 3 {
                    (dr.dof, true)
                } else {
                    (dr.dof - 3, false)
                };
                let cur = if lin { st.v[k] } else { st.w[k] };
                let target = match dr.kind {
                    MotionKind::Velocity => self.drive_value(dr, t + 0.5 * dt_next),
                    MotionKind::Acceleration => self.drive_value(dr, t).map(|a| cur + dt_v * a),
                    MotionKind::Displacement => self
                        .drive_value(dr, t + dt_next)
                        .map(|u| (def.centre[k] + u - st.centre[k]) / dt_next),
                };
                if let Some(val) = target {
                    if lin {
                        v[k] = val;
                    } else {
                        w[k] = val;
                    }
                }
            }
            // Work of the held and prescribed components: the impulse that changed the
            // free motion into the imposed one, with the mean velocity over the kick.
            let dl = mul(&j, [w[0] - free_w[0], w[1] - free_w[1], w[2] - free_w[2]]);
            for d in 0..3 {
                self.energies.external_work +=
                    def.mass * (v[d] - free_v[d]) * 0.5 * (st.v[d] + v[d]);
                self.energies.external_work += dl[d] * 0.5 * (st.w[d] + w[d]);
            }
            let centre = [
                st.centre[0] + dt_next * v[0],
                st.centre[1] + dt_next * v[1],
                st.centre[2] + dt_next * v[2],
            ];
            let rot = crate::rigid::matmul(
                &rotation([dt_next * w[0], dt_next * w[1], dt_next * w[2]]),
                &st.rotation,
            );
            for (k, &i) in def.nodes.iter().enumerate() {
                let i = i as usize;
                let r = mul(&rot, def.offsets[k]);
                for d in 0..3 {
                    let target = (centre[d] + r[d] - self.x[i][d]) / dt_next;
                    self.a[i][d] = (target - self.v[i][d]) / dt_v;
                    self.alpha[i][d] = (w[d] - self.w[i][d]) / dt_v;
                }
            }
            self.bodies[b] = RigidState {
                centre,
                rotation: rot,
                v,
                w,
            };
        }
    }

    /// Prescribed motions of nodes: sets the driven components of the accelerations so
    /// that velocity, displacement or acceleration follow their curves over the next step,
    /// booking the work of the imposed change as external work.
    fn drive_nodes(&mut self, dt_v: f64, dt_next: f64) {
        let t = self.time;
        for dr in &self.c.drives {
            let DriveTarget::Nodes(nodes) = &dr.target else {
                continue;
            };
            let (k, lin) = if dr.dof < 3 {
                (dr.dof, true)
            } else {
                (dr.dof - 3, false)
            };
            for &i in nodes {
                let i = i as usize;
                let (vcur, acur, m) = if lin {
                    (self.v[i][k], self.a[i][k], self.c.mass[i])
                } else {
                    (self.w[i][k], self.alpha[i][k], self.c.inertia[i])
                };
                let a = match dr.kind {
                    MotionKind::Velocity => self
                        .drive_value(dr, t + 0.5 * dt_next)
                        .map(|v| (v - vcur) / dt_v),
                    MotionKind::Acceleration => self.drive_value(dr, t),
                    MotionKind::Displacement => self.drive_value(dr, t + dt_next).map(|u| {
                        let target = (self.c.x0[i][k] + u - self.x[i][k]) / dt_next;
                        (target - vcur) / dt_v
                    }),
                };
                let Some(a) = a else { continue };
                let vnew = vcur + dt_v * a;
                self.energies.external_work += m * (a - acur) * dt_v * 0.5 * (vcur + vnew);
                if lin {
                    self.a[i][k] = a;
                } else {
                    self.alpha[i][k] = a;
                }
            }
        }
    }

    /// First step: stress-free forces, time step, `a^0` and the half-step velocities.
    fn start(&mut self) -> Result<()> {
        self.element_loop(0.0);
        let dt = self.next_dt()?;
        self.dt_ref = self
            .chunks
            .iter()
            .map(|c| c.dt_min)
            .fold(f64::INFINITY, f64::min);
        self.gather(0.0);
        self.contact(0.0, dt);
        self.kick(0.0, dt);
        self.energies.initial = self.energies.kinetic;
        self.dt_half = dt;
        self.dt_first = dt;
        self.started = true;
        Ok(())
    }

    /// The next stable step from the element outputs (`TSSFAC min dt_e`, or the fixed step), checking
    /// for faults.
    fn next_dt(&self) -> Result<f64> {
        let mut min = f64::INFINITY;
        let mut arg = 0;
        for c in &self.chunks {
            if let Some(k) = c.problem {
                let cause = match self.faults[k] {
                    Some(f) => f.to_string(),
                    None => "non-finite element time step".into(),
                };
                return Err(self.unstable(k, cause));
            }
            if c.dt_min < min {
                min = c.dt_min;
                arg = c.arg;
            }
        }
        let dt = match self.control.fixed_dt {
            Some(dt) => dt,
            None => self.control.tssfac * min,
        };

        if dt.is_infinite() && min.is_infinite() {
            return Err(ShellError::value(
                "time step",
                "every part is rigid, so no element sets a stable step: give a fixed step (Control::fixed_dt)",
            ));
        }
        if !(dt > 0.0 && dt.is_finite()) {
            return Err(self.unstable(arg, format!("time step {dt} is not positive")));
        }
        if self.started
            && self.control.dtmin_factor > 0.0
            && dt < self.control.dtmin_factor * self.dt_first
        {
            return Err(self.unstable(
                arg,
                format!(
                    "time step {dt:.3e} fell below DTMIN x first step ({:.3e})",
                    self.control.dtmin_factor * self.dt_first
                ),
            ));
        }
        Ok(dt)
    }

    fn unstable(&self, element: usize, cause: String) -> ShellError {
        ShellError::Unstable {
            time: self.time,
            cycle: self.cycle,
            element: self.c.elem_ids.get(element).copied().unwrap_or(0),
            cause,
        }
    }

    /// Advances one cycle.
    ///
    /// # Errors
    /// [`ShellError::Unstable`] when an element degenerates or inverts, a force or velocity
    /// becomes non-finite, the time step collapses below DTMIN, or the energy ratio exceeds
    /// the bound; the state is then not usable.
    pub fn step(&mut self) -> Result<()> {
        let dt = self.dt_half;
        let g0 = self.body_accel(self.time);
        // Positions, and the vertical momentum for the work of the body load, in fixed
        // chunks summed in order.
        let mass = &self.c.mass;
        self.x
            .par_chunks_mut(NODE_CHUNK)
            .zip(self.v.par_chunks(NODE_CHUNK))
            .zip(mass.par_chunks(NODE_CHUNK))
            .zip(self.node_sums.par_iter_mut())
            .for_each(|(((xs, vs), ms), sum)| {
                let mut mdz = 0.0;
                for ((x, v), m) in xs.iter_mut().zip(vs).zip(ms) {
                    for d in 0..3 {
                        x[d] += dt * v[d];
                    }
                    mdz += m * dt * v[2];
                }
                *sum = mdz;
            });
        let mdz: f64 = self.node_sums.iter().sum();
        self.time += dt;
        self.cycle += 1;
        self.element_loop(dt);
        let dt_next = self.next_dt()?;
        let (mut die, mut dhg, mut ddp) = (0.0, 0.0, 0.0);
        for c in &self.chunks {
            die += c.internal;
            dhg += c.hourglass;
            ddp += c.damping;
        }
        self.energies.internal += die;
        self.energies.hourglass += dhg;
        self.energies.damping += ddp;
        let g1 = self.body_accel(self.time);
        self.energies.external_work += 0.5 * (g0 + g1) * mdz;
        self.gather(self.time);
        self.contact(dt, dt_next);
        self.kick(0.5 * dt, dt_next);
        self.dt_half = dt_next;
        self.dt_min = self.dt_min.min(dt);
        self.dt_max = self.dt_max.max(dt);
        self.check_health(die, dhg)
    }

    fn check_health(&self, die: f64, dhg: f64) -> Result<()> {
        let e = &self.energies;
        let total = e.total();
        if !(total.is_finite() && die.is_finite() && dhg.is_finite()) {
            let k = self
                .out
                .iter()
                .position(|o| {
                    o.f.iter().flatten().any(|f| !f.is_finite()) || !o.internal.is_finite()
                })
                .unwrap_or(0);
            return Err(self.unstable(k, "non-finite force or energy".into()));
        }
        if self.v_bad
            && let Some(i) = self.v.iter().position(|v| v.iter().any(|c| !c.is_finite()))
        {
            return Err(ShellError::Unstable {
                time: self.time,
                cycle: self.cycle,
                element: self.element_at_node(i),
                cause: format!("non-finite velocity at node {}", self.c.node_ids[i]),
            });
        }
        let reference = e.initial + e.external_work;
        if reference > 0.0 && total > self.control.energy_ratio_bound * reference {
            let k = self
                .out
                .iter()
                .enumerate()
                .max_by(|a, b| {
                    let ea = (a.1.internal + a.1.hourglass).abs();
                    let eb = (b.1.internal + b.1.hourglass).abs();
                    ea.total_cmp(&eb)
                })
                .map_or(0, |(k, _)| k);
            return Err(self.unstable(
                k,
                format!(
                    "energy ratio {:.3} exceeds the bound {} (energy is being created)",
                    total / reference,
                    self.control.energy_ratio_bound
                ),
            ));
        }
        Ok(())
    }

    fn element_at_node(&self, i: usize) -> u64 {
        self.csr
            .get(self.csr_start[i] as usize)
            .map_or(0, |&k| self.c.elem_ids[k as usize / 4])
    }

    /// Runs to the end time (or the cycle limit) and returns the sampled outputs.
    ///
    /// # Errors
    /// As [`step`](Self::step); histories are only returned for a completed run.
    pub fn run(&mut self) -> Result<RunResult> {
        self.run_with_progress(|_| {})
    }

    /// As [`run`](Self::run), calling `progress` about every 1 % of the end time.
    ///
    /// # Errors
    /// As [`step`](Self::step).
    pub fn run_with_progress(&mut self, mut progress: impl FnMut(&Progress)) -> Result<RunResult> {
        let end = self.control.end_time;
        let interval = self.interval;
        let n_samples = ((end / interval) * (1.0 + 1e-12)).floor() as usize + 1;
        let hist = self.c.history.clone();
        let nh = hist.len();
        let mut samples: Vec<Vec<f64>> = Vec::with_capacity(n_samples);
        // The per-part energies of every sample, interpolated like the rest between the
        // cycles around it; they cost a pass over elements and nodes, so they are taken
        // only ahead of a step that may reach a sample.
        let mut part_samples: Vec<Vec<f64>> = Vec::with_capacity(n_samples);
        let mut prev_t = self.time;
        let mut prev = self.snapshot(&hist);
        let mut prev_parts = (self.time, self.part_snapshot());
        let mut next = 0usize;
        let mut next_report = 0.0;
        while next < n_samples {
            let ts = next as f64 * interval;
            if ts <= self.time * (1.0 + 1e-12) {
                let cur = self.snapshot(&hist);
                let span = self.time - prev_t;
                let s = if span > 0.0 {
                    ((ts - prev_t) / span).clamp(0.0, 1.0)
                } else {
                    1.0
                };
                samples.push(
                    prev.iter()
                        .zip(&cur)
                        .map(|(a, b)| a + s * (b - a))
                        .collect(),
                );
                let cur_parts = self.part_snapshot();
                let from = if prev_parts.0.to_bits() == prev_t.to_bits() {
                    &prev_parts.1
                } else {
                    &cur_parts
                };
                part_samples.push(
                    from.iter()
                        .zip(&cur_parts)
                        .map(|(a, b)| a + s * (b - a))
                        .collect(),
                );
                next += 1;
                continue;
            }
            if self.control.end_cycles > 0 && self.cycle >= self.control.end_cycles {
                break;
            }
            prev_t = self.time;
            prev = self.snapshot(&hist);
            if ts <= (self.time + self.dt_half) * (1.0 + 1e-9) {
                prev_parts = (self.time, self.part_snapshot());
            }
            self.step()?;
            if self.time >= next_report {
                progress(&Progress {
                    time: self.time,
                    end_time: end,
                    cycle: self.cycle,
                    dt: self.dt_half,
                });
                next_report = self.time + 0.01 * end;
            }
        }
        if samples.is_empty() {
            samples.push(self.snapshot(&hist));
            part_samples.push(self.part_snapshot());
        }
        let column = |r: usize| -> Vec<f64> { samples.iter().map(|s| s[r]).collect() };
        let axes = ["x", "y", "z"];
        let mut nodal = Vec::with_capacity(3);
        for q in 0..3 {
            if nh == 0 {
                nodal.push(None);
                continue;
            }
            let mut labels = Vec::with_capacity(3 * nh);
            let mut chans = Vec::with_capacity(3 * nh);
            for (j, &i) in hist.iter().enumerate() {
                for (d, ax) in axes.iter().enumerate() {
                    labels.push(format!("{}.{}", self.c.node_ids[i as usize], ax));
                    chans.push(column(9 * j + 3 * q + d));
                }
            }
            let unit = ["displacement", "velocity", "acceleration"][q];
            nodal.push(Some(Histories::from_channels(
                labels, chans, interval, 0.0, unit,
            )?));
        }
        let energies = Histories::from_channels(
            ENERGY_LABELS.iter().map(|s| s.to_string()).collect(),
            (0..ENERGY_LABELS.len())
                .map(|k| column(9 * nh + k))
                .collect(),
            interval,
            0.0,
            "energy",
        )?;
        let walls = self.wall_histories(&samples, 9 * nh + ENERGY_LABELS.len(), interval)?;
        let (contacts, contact_forces) = self
            .contact_histories(
                &samples,
                9 * nh + ENERGY_LABELS.len() + 4 * self.c.walls.len(),
                interval,
            )?
            .unzip();
        let (part_energies, part_velocities) = self.part_histories(&part_samples, interval)?;
        let mut wall_peaks = Vec::with_capacity(self.c.walls.len());
        let mut peak_total: f64 = 0.0;
        if let Some(walls) = &walls {
            for k in 0..walls.samples() {
                let total: f64 = (0..self.c.walls.len())
                    .map(|w| walls.value(4 * w + 3, k))
                    .sum();
                peak_total = peak_total.max(total);
            }
            for (w, wall) in self.c.walls.iter().enumerate() {
                let peak = walls
                    .channel(4 * w + 3)
                    .iter()
                    .fold(0.0_f64, |a, &b| a.max(b));
                wall_peaks.push((wall.id, peak));
            }
        }
        let e = self.energies;
        let mut it = nodal.into_iter();
        Ok(RunResult {
            walls,
            contacts,
            contact_forces,
            part_energies,
            part_velocities,
            parts: self.part_energies(),
            displacement: it.next().flatten(),
            velocity: it.next().flatten(),
            acceleration: it.next().flatten(),
            energies,
            summary: RunSummary {
                cycles: self.cycle,
                end_time: self.time,
                dt_first: self.dt_first,
                dt_min: if self.dt_min.is_finite() {
                    self.dt_min
                } else {
                    self.dt_first
                },
                dt_max: self.dt_max.max(self.dt_first),
                energy_ratio: e.ratio(),
                hourglass_share: if e.internal.abs() > 0.0 {
                    e.hourglass / e.internal
                } else {
                    0.0
                },
                peak_wall_force: peak_total,
                wall_peaks,
                energies: e,
                elements: self.c.elems.len(),
                mass: self.c.mass.iter().sum(),
            },
        })
    }

    fn snapshot(&self, hist: &[u32]) -> Vec<f64> {
        let mut s = Vec::with_capacity(9 * hist.len() + ENERGY_LABELS.len());
        for &i in hist {
            let i = i as usize;
            let u = sub(self.x[i], self.c.x0[i]);
            s.extend_from_slice(&u);
            s.extend_from_slice(&self.v_int[i]);
            s.extend_from_slice(&self.a[i]);
        }
        let e = self.energies;
        s.extend_from_slice(&[
            e.kinetic,
            e.internal,
            e.hourglass,
            e.contact,
            e.friction,
            e.damping,
            e.external_work,
            e.total(),
            e.ratio(),
            self.wall_normal,
            self.wall_force[0],
            self.wall_force[1],
            self.wall_force[2],
        ]);
        for j in &self.wall_impulse {
            s.extend_from_slice(j);
        }
        for (c, j) in self.contacts.iter().zip(&self.contact_impulse) {
            s.extend_from_slice(&[c.energy, c.friction]);
            s.extend_from_slice(j);
        }
        s
    }

    /// Per part, `[internal, kinetic, hourglass, damping]` now: the element sums of the
    /// accumulated energies, and the kinetic energy of the mass (and rotary inertia) each
    /// element gives its nodes, at the velocities of the last completed cycle.
    /// Per part, `PART_SAMPLE` values: internal, kinetic, hourglass and damping energy and
    /// the momentum `[px, py, pz]` of the mass its shells give their nodes.
    fn part_snapshot(&self) -> Vec<f64> {
        let np = self.c.part_ids.len();
        let mut out = vec![0.0; PART_SAMPLE * np];
        for (k, (e, acc)) in self.c.elems.iter().zip(&self.elem_energy).enumerate() {
            let p = PART_SAMPLE * e.part as usize;
            out[p] += acc[0];
            out[p + 2] += acc[1];
            out[p + 3] += acc[2];
            let [m, inr] = self.elem_mass[k];
            let n = if e.tri { 3 } else { 4 };
            for &i in &e.nodes[..n] {
                let (v, w) = (self.v_int[i as usize], self.w_int[i as usize]);
                out[p + 1] += 0.5 * (m * dot(v, v) + inr * dot(w, w));
                for d in 0..3 {
                    out[p + 4 + d] += m * v[d];
                }
            }
        }
        out
    }

    /// The force of each wall on the structure sampled at the output interval: sample `k`
    /// is the impulse the wall gave between samples `k - 1` and `k` over the interval (0 at
    /// `t = 0`, the impulse of the first cycle counting in the first interval); channels
    /// `<id>.fx, <id>.fy, <id>.fz` (global components) and `<id>.f` (the normal force: the
    /// sum over nodes of the force along the wall's normal at each node).
    fn wall_histories(
        &self,
        samples: &[Vec<f64>],
        at: usize,
        dt: f64,
    ) -> Result<Option<Histories>> {
        let nw = self.c.walls.len();
        if nw == 0 {
            return Ok(None);
        }
        let mut labels = Vec::with_capacity(4 * nw);
        let mut chans = Vec::with_capacity(4 * nw);
        for (w, wall) in self.c.walls.iter().enumerate() {
            for (k, name) in ["fx", "fy", "fz", "f"].iter().enumerate() {
                labels.push(format!("{}.{name}", wall.id));
                chans.push(mean_over_intervals(samples, at + 4 * w + k, dt));
            }
        }
        Ok(Some(Histories::from_channels(
            labels, chans, dt, 0.0, "force",
        )?))
    }

    /// The energies and the forces of each contact interface sampled at the output
    /// interval, from column `at` of the samples (six columns per interface: energy,
    /// friction, and the impulses `[x, y, z, normal]` since the start); see
    /// [`RunResult::contacts`] and [`RunResult::contact_forces`].
    fn contact_histories(
        &self,
        samples: &[Vec<f64>],
        at: usize,
        dt: f64,
    ) -> Result<Option<(Histories, Histories)>> {
        if self.c.contacts.is_empty() {
            return Ok(None);
        }
        let (mut labels, mut chans) = (Vec::new(), Vec::new());
        let (mut f_labels, mut f_chans) = (Vec::new(), Vec::new());
        for (k, f) in self.c.contacts.iter().enumerate() {
            for (j, name) in ["energy", "friction", "fx", "fy", "fz", "fn"]
                .iter()
                .enumerate()
            {
                let col = at + 6 * k + j;
                if j < 2 {
                    labels.push(format!("{}.{name}", f.id));
                    chans.push(samples.iter().map(|s| s[col]).collect());
                } else {
                    f_labels.push(format!("{}.{name}", f.id));
                    f_chans.push(mean_over_intervals(samples, col, dt));
                }
            }
        }
        Ok(Some((
            Histories::from_channels(labels, chans, dt, 0.0, "energy")?,
            Histories::from_channels(f_labels, f_chans, dt, 0.0, "force")?,
        )))
    }

    /// The per-part energies sampled at the output interval: channels
    /// `<part>.internal, <part>.kinetic, <part>.hourglass, <part>.damping`.
    /// The per-part energies and centre-of-mass velocities (see
    /// [`RunResult::part_energies`] and [`RunResult::part_velocities`]) from the part
    /// samples.
    fn part_histories(&self, samples: &[Vec<f64>], dt: f64) -> Result<(Histories, Histories)> {
        let np = self.c.part_ids.len();
        let mut mass = vec![0.0; np];
        for (e, [m, _]) in self.c.elems.iter().zip(&self.elem_mass) {
            mass[e.part as usize] += m * if e.tri { 3.0 } else { 4.0 };
        }
        let (mut labels, mut chans) = (Vec::new(), Vec::new());
        let (mut vlabels, mut vchans) = (Vec::new(), Vec::new());
        for (p, id) in self.c.part_ids.iter().enumerate() {
            let at = PART_SAMPLE * p;
            for (k, name) in ["internal", "kinetic", "hourglass", "damping"]
                .iter()
                .enumerate()
            {
                labels.push(format!("{id}.{name}"));
                chans.push(samples.iter().map(|s| s[at + k]).collect());
            }
            for (d, name) in ["vx", "vy", "vz"].iter().enumerate() {
                vlabels.push(format!("{id}.{name}"));
                // A part without shells has no mass and no centre: its channels are 0.
                vchans.push(
                    samples
                        .iter()
                        .map(|s| {
                            if mass[p] > 0.0 {
                                s[at + 4 + d] / mass[p]
                            } else {
                                0.0
                            }
                        })
                        .collect(),
                );
            }
        }
        Ok((
            Histories::from_channels(labels, chans, dt, 0.0, "energy")?,
            Histories::from_channels(vlabels, vchans, dt, 0.0, "velocity")?,
        ))
    }

    /// Estimates the largest natural circular frequency `omega_max` of the undeformed,
    /// stress-free model by power iteration on `M^-1 K` (translations and rotations, with
    /// the hourglass stiffness; constraints applied), where `K u` is the internal-force
    /// response to a small velocity `u` over a unit step. The stability limit of the
    /// central-difference method is `2 / omega_max`.
    ///
    /// The state of the simulation is not changed.
    pub fn max_frequency(&self, iterations: usize) -> f64 {
        let nn = self.c.x0.len();
        let mut free = vec![[true; 6]; nn];
        for &(i, m) in &self.c.fixed {
            for d in 0..6 {
                free[i as usize][d] = !m[d];
            }
        }
        // Deterministic start vector.
        let mut u: Vec<[f64; 6]> = (0..nn)
            .map(|i| {
                let mut r = [0.0; 6];
                for d in 0..6 {
                    let h = ((i * 6 + d) as f64 * 0.618_033_988_749_895).fract() - 0.5;
                    r[d] = if free[i][d] { h } else { 0.0 };
                }
                r
            })
            .collect();
        let mut lambda = 0.0;
        let eps = 1e-9;
        for _ in 0..iterations {
            let norm: f64 = u.iter().flatten().map(|c| c * c).sum::<f64>().sqrt();
            if norm == 0.0 {
                return 0.0;
            }
            for r in u.iter_mut() {
                for c in r.iter_mut() {
                    *c *= eps / norm;
                }
            }
            let vel: Vec<[f64; 3]> = u.iter().map(|r| [r[0], r[1], r[2]]).collect();
            let om: Vec<[f64; 3]> = u.iter().map(|r| [r[3], r[4], r[5]]).collect();
            let mut f = vec![[0.0; 6]; nn];
            for e in &self.c.elems {
                if self.c.parts[e.props as usize].rigid {
                    continue;
                }
                let mut st = vec![0.0; self.stride];
                let out = eval_element(
                    e,
                    &self.c.x0,
                    &vel,
                    &om,
                    &self.c.parts[e.props as usize],
                    &mut st,
                    1.0,
                    self.kernel,
                );
                for (s, &n) in e.nodes[..if e.tri { 3 } else { 4 }].iter().enumerate() {
                    for d in 0..6 {
                        f[n as usize][d] += out.f[s][d];
                    }
                }
            }
            let mut next = vec![[0.0; 6]; nn];
            let mut num = 0.0;
            let mut den = 0.0;
            for i in 0..nn {
                for d in 0..6 {
                    if !free[i][d] {
                        continue;
                    }
                    let m = if d < 3 {
                        self.c.mass[i]
                    } else {
                        self.c.inertia[i]
                    };
                    if m <= 0.0 {
                        continue;
                    }
                    next[i][d] = f[i][d] / m;
                    // Rayleigh quotient in the mass metric: u.K u / u.M u.
                    num += u[i][d] * f[i][d];
                    den += u[i][d] * m * u[i][d];
                }
            }
            lambda = if den > 0.0 { num / den } else { 0.0 };
            u = next;
        }
        lambda.max(0.0).sqrt()
    }
}

/// Per element, the mass `rho t A / n` and rotary inertia `m max(t^2/12, A/8)` it gives
/// each of its `n` nodes, on the initial geometry (as the model's set-up lumps them).
fn element_masses(c: &Compiled) -> Vec<[f64; 2]> {
    c.elems
        .iter()
        .map(|e| {
            let n = if e.tri { 3 } else { 4 };
            let xs: Vec<[f64; 3]> = e.nodes[..n].iter().map(|&i| c.x0[i as usize]).collect();
            let area = crate::geometry::polygon_area(&xs);
            let p = &c.parts[e.props as usize];
            let m = p.mat.rho * p.t * area / n as f64;
            [m, m * (p.t * p.t / 12.0).max(area / 8.0)]
        })
        .collect()
}

#[allow(clippy::too_many_arguments)]
fn eval_element(
    e: &Elem,
    x: &[[f64; 3]],
    v: &[[f64; 3]],
    w: &[[f64; 3]],
    props: &element::PartProps,
    st: &mut [f64],
    dt: f64,
    kernel: KernelOptions,
) -> ElementOutput {
    let n = e.nodes.map(|i| i as usize);
    let res = if e.tri {
        let g = |a: &[[f64; 3]]| [a[n[0]], a[n[1]], a[n[2]]];
        element::triangle(&g(x), &g(v), &g(w), props, st, dt, kernel)
    } else {
        let g = |a: &[[f64; 3]]| [a[n[0]], a[n[1]], a[n[2]], a[n[3]]];
        element::quad(&g(x), &g(v), &g(w), props, st, dt, kernel)
    };
    res.unwrap_or_default()
}

/// `sum_i f(a_i, b_i)` in fixed chunks, so the rounding does not depend on threads.
fn chunked_sum<A: Sync>(a: &[A], b: &[f64], f: impl Fn(&A, f64) -> f64 + Sync) -> f64 {
    let parts: Vec<f64> = a
        .par_chunks(NODE_CHUNK)
        .zip(b.par_chunks(NODE_CHUNK))
        .map(|(ca, cb)| ca.iter().zip(cb).map(|(x, &m)| f(x, m)).sum())
        .collect();
    parts.iter().sum()
}

/// The mean force over each output interval of length `dt` from the impulse since the start
/// held in column `col` of the samples: sample `k` is the impulse between samples `k - 1`
/// and `k` over `dt` (0 at `t = 0`).
fn mean_over_intervals(samples: &[Vec<f64>], col: usize, dt: f64) -> Vec<f64> {
    let mut prev = 0.0;
    samples
        .iter()
        .enumerate()
        .map(|(j, s)| {
            let f = if j == 0 { 0.0 } else { (s[col] - prev) / dt };
            prev = s[col];
            f
        })
        .collect()
}
