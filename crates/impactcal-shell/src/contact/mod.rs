//! Segment contact between shells: the penalty contact of LS-DYNA's automatic contacts
//! (`*CONTACT_AUTOMATIC_SINGLE_SURFACE`, `_SURFACE_TO_SURFACE`, `_NODES_TO_SURFACE`).
//!
//! A contact interface checks nodes against shell segments. A segment is a shell's
//! mid-surface thickened by half its contact thickness on both sides, with rounded edges:
//! the set of points within `h_s` of the mid-surface polygon. A node carries a half
//! thickness `h_n` of its own, so a node penetrates a segment when its distance `d` to
//! the mid-surface polygon (a quad is split into four triangles about its centroid) is
//! below `h_n + h_s`; the penetration is `p = h_n + h_s - d` along the direction from the
//! closest point to the node.
//!
//! **Normal force** (SOFT = 0): `f_n = k p - c v_n`, never pulling (`f_n >= 0`), with
//! - the penalty stiffness `k = min(k_segment, k_node)` (PENOPT 1); a segment's
//!   `k = SLSFAC SF K A / D` with `K = E / (3 (1 - 2 nu))` the bulk modulus of its material,
//!   `A` its area and `D` its longest diagonal (longest side for a triangle) on the initial
//!   geometry, `SF` the surface's scale factor (SFS or SFM) and SLSFAC 0.1 by default; a
//!   node's stiffness is the mean of the segments of its surface that contain it;
//! - the viscous damping `c = (VDC / 100) 2 m w`, `w = sqrt(k (m_n + m_s) / (m_n m_s))`,
//!   `m = min(m_n, m_s)`, `m_s` the segment's nodal masses interpolated at the contact
//!   point, and `v_n` the normal relative velocity (negative while approaching).
//!
//! **Friction** (Coulomb, elastic-plastic): the tangential force of a node is carried from
//! cycle to cycle (projected onto the current tangent plane); each cycle the trial force
//! `F* = F - k de` (`de` the tangential slip of the node against the segment over the step)
//! is limited to `mu f_n`, with `mu = FD + (FS - FD) exp(-DC |v_t|)` and, when VC > 0, to
//! `VC A`.
//!
//! Each node takes the one segment it penetrates most; the forces are applied to the node
//! and, with the opposite sign, to the segment's nodes in proportion to the weights of the
//! closest point (momentum is conserved exactly). A node that goes through the mid-surface
//! of the segment it was in contact with in the previous cycle (or a neighbour of it) is
//! pushed back to the side it came from. Penetrations present at the start are kept as a
//! reference that only additional penetration acts against (LS-DYNA's IGNORE = 1; the
//! reference shrinks when the node moves out).
//!
//! Candidate pairs are found by a bucket sort (a hashed grid of cells, each segment in the
//! cells its box touches); the lists stay valid while no node has moved more than half the
//! search margin relative to the mean motion of the interface, so contacts are never
//! missed and the sort runs only every few tens of cycles. Nodes are processed in parallel
//! in fixed chunks and forces are added in node order, so results are bit-identical for
//! any number of threads.

mod geometry;
mod interface;
mod search;
mod solve;

pub(crate) use interface::{Interface, Model as ContactModel, compile};
pub(crate) use solve::{ContactState, Nodes as ContactNodes};

/// The kind of a contact interface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactKind {
    /// Every node of the surface against every segment of it that does not hold the node
    /// (`*CONTACT_AUTOMATIC_SINGLE_SURFACE`): self-contact of folding structures.
    SingleSurface,
    /// The nodes of each surface against the segments of the other, both ways
    /// (`*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE`).
    SurfaceToSurface,
    /// The slave nodes against the master segments only
    /// (`*CONTACT_AUTOMATIC_NODES_TO_SURFACE`).
    NodesToSurface,
}

/// A side of a contact interface: the shells (and their nodes) it consists of.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactSurface {
    /// The shells of the parts of a part set (SSTYP/MSTYP 2).
    PartSet(u64),
    /// The shells of one part (SSTYP/MSTYP 3).
    Part(u64),
    /// The nodes of a node set (SSTYP 4): slave nodes of a nodes-to-surface contact only.
    NodeSet(u64),
    /// Every shell of the model (SSTYP 5).
    All,
}

/// Coulomb friction of a contact interface: `mu = dynamic + (static - dynamic)
/// exp(-decay |v_t|)` with `v_t` the sliding speed, the friction force limited to
/// `viscous` times the segment's area when `viscous > 0` (FS, FD, DC, VC).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ContactFriction {
    /// Static coefficient FS, >= 0.
    pub static_coef: f64,
    /// Dynamic coefficient FD, >= 0.
    pub dynamic: f64,
    /// Exponential decay coefficient DC (time / length), >= 0.
    pub decay: f64,
    /// Viscous friction limit VC (stress), >= 0; 0 for none.
    pub viscous: f64,
}

/// One side's penalty and thickness settings (SFS, SST, SFST or SFM, MST, SFMT).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SideSettings {
    /// Scale factor on the penalty stiffness (SFS or SFM), > 0; 1 by default.
    pub stiffness_scale: f64,
    /// The contact thickness of the side's shells (SST or MST); 0 takes each shell's own
    /// thickness (times `thickness_scale`).
    pub thickness: f64,
    /// Scale factor on the shells' thickness (SFST or SFMT), > 0; 1 by default.
    pub thickness_scale: f64,
}

impl Default for SideSettings {
    fn default() -> Self {
        SideSettings {
            stiffness_scale: 1.0,
            thickness: 0.0,
            thickness_scale: 1.0,
        }
    }
}

/// A contact interface (`*CONTACT_AUTOMATIC_...`): penalty contact with shell thickness
/// offsets, Coulomb friction and viscous normal damping; see the [module](self) docs for
/// the formulas.
///
/// For a single-surface contact only `slave` and `slave_side` are used; a shell's contact
/// thickness is then limited to 0.4 of its shortest edge unless `slave_side.thickness`
/// gives one (so that a node never touches the segments next to its own).
#[derive(Debug, Clone, PartialEq)]
pub struct Contact {
    /// The interface id (`_ID` card CID); 0 gives it its 1-based position among the
    /// model's interfaces.
    pub id: u64,
    /// The kind.
    pub kind: ContactKind,
    /// The slave side (SSID, SSTYP).
    pub slave: ContactSurface,
    /// The master side (MSID, MSTYP); ignored by a single-surface contact.
    pub master: ContactSurface,
    /// Penalty and thickness settings of the slave side.
    pub slave_side: SideSettings,
    /// Penalty and thickness settings of the master side.
    pub master_side: SideSettings,
    /// Friction.
    pub friction: ContactFriction,
    /// Viscous damping of the normal motion in percent of critical (VDC), 0 to 100.
    pub damping: f64,
    /// The time the interface starts acting (BT).
    pub birth: f64,
    /// The time it stops acting (DT; `f64::INFINITY` for never).
    pub death: f64,
}

impl Contact {
    /// A frictionless, undamped single-surface contact over `surface` with the default
    /// scale factors, acting for the whole run.
    pub fn single_surface(surface: ContactSurface) -> Self {
        Contact {
            id: 0,
            kind: ContactKind::SingleSurface,
            slave: surface,
            master: ContactSurface::All,
            slave_side: SideSettings::default(),
            master_side: SideSettings::default(),
            friction: ContactFriction::default(),
            damping: 0.0,
            birth: 0.0,
            death: f64::INFINITY,
        }
    }

    /// A frictionless, undamped contact of `kind` between `slave` and `master` with the
    /// default scale factors, acting for the whole run.
    pub fn between(kind: ContactKind, slave: ContactSurface, master: ContactSurface) -> Self {
        Contact {
            kind,
            slave,
            master,
            ..Contact::single_surface(slave)
        }
    }
}

/// Settings shared by every contact interface (`*CONTROL_CONTACT`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactControl {
    /// The penalty scale factor SLSFAC (0.1 by default), > 0.
    pub penalty_scale: f64,
    /// Single-surface contacts use each shell's full contact thickness instead of at most
    /// 0.4 of its shortest edge (SSTHK 1; off by default).
    pub full_thickness: bool,
}

impl Default for ContactControl {
    fn default() -> Self {
        ContactControl {
            penalty_scale: 0.1,
            full_thickness: false,
        }
    }
}
