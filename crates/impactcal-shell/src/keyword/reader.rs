//! Reading keyword decks.

use std::path::Path;

use crate::error::{Result, ShellError};
use crate::model::{
    BodyLoadZ, BulkViscosity, CowperSymonds, Curve, HourglassForm, InitialVelocity, Material,
    MaterialLaw, NodeSet, NodeTarget, Part, PartStiffnessDamping, PointMass, RigidWall, Section,
    ShellModel, Spc, ThicknessRule, VelocityTarget, WallMethod,
};

/// Output-only keywords that are skipped with a warning (their cards are ignored).
pub const IGNORED_KEYWORDS: &[&str] = &[
    "*DATABASE_GLSTAT",
    "*DATABASE_MATSUM",
    "*DATABASE_RWFORC",
    "*DATABASE_ELOUT",
    "*DATABASE_SPCFORC",
    "*DATABASE_BNDOUT",
    "*DATABASE_DEFORC",
    "*DATABASE_SLEOUT",
    "*DATABASE_RCFORC",
    "*DATABASE_SECFORC",
    "*DATABASE_BINARY_D3PLOT",
    "*DATABASE_BINARY_D3THDT",
    "*DATABASE_EXTENT_BINARY",
    "*DATABASE_HISTORY_SHELL",
    "*DATABASE_FORMAT",
    "*CONTROL_OUTPUT",
    "*CONTROL_ENERGY",
];

/// A parsed deck: the model and the warnings raised while reading it.
#[derive(Debug, Clone)]
pub struct Deck {
    /// The model.
    pub model: ShellModel,
    /// Warnings (ignored output-only keywords, fields read with a simplification).
    pub warnings: Vec<String>,
}

/// Reads a deck file.
///
/// # Errors
/// [`ShellError::Io`] when the file cannot be read, otherwise as [`parse_deck`].
pub fn read_deck(path: impl AsRef<Path>) -> Result<Deck> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).map_err(|source| ShellError::Io {
        path: path.display().to_string(),
        source,
    })?;
    parse_deck(&text, &path.display().to_string())
}

/// One data card: its line number and fields.
struct Card<'a> {
    line: usize,
    text: &'a str,
}

struct Ctx<'a> {
    file: &'a str,
    keyword: String,
}

impl Ctx<'_> {
    fn err(&self, line: usize, message: impl Into<String>) -> ShellError {
        ShellError::Keyword {
            file: self.file.to_string(),
            line,
            keyword: self.keyword.clone(),
            message: message.into(),
        }
    }
}

/// The fields of a card, split by commas or by the fixed `widths` (the last width repeats).
fn fields<'a>(text: &'a str, widths: &[usize]) -> Vec<&'a str> {
    if text.contains(',') {
        return text.split(',').map(str::trim).collect();
    }
    let mut out = Vec::new();
    let mut pos = 0;
    let mut k = 0;
    let bytes = text.len();
    while pos < bytes {
        let w = widths[k.min(widths.len() - 1)];
        let end = (pos + w).min(bytes);
        out.push(text.get(pos..end).unwrap_or("").trim());
        pos = end;
        k += 1;
    }
    out
}

struct Fields<'a, 'c> {
    f: Vec<&'a str>,
    line: usize,
    ctx: &'c Ctx<'c>,
}

impl Fields<'_, '_> {
    fn raw(&self, i: usize) -> Option<&str> {
        self.f.get(i).copied().filter(|s| !s.is_empty())
    }

    /// Three consecutive real fields from `first` (a vector such as VX, VY, VZ), each
    /// defaulting to 0.
    fn real3(&self, first: usize, names: [&str; 3]) -> Result<[f64; 3]> {
        Ok([
            self.real(first, names[0], 0.0)?,
            self.real(first + 1, names[1], 0.0)?,
            self.real(first + 2, names[2], 0.0)?,
        ])
    }

    fn real(&self, i: usize, name: &str, default: f64) -> Result<f64> {
        match self.raw(i) {
            None => Ok(default),
            Some(s) => {
                let v: f64 = s.replace(['d', 'D'], "e").parse().map_err(|_| {
                    self.ctx
                        .err(self.line, format!("field {name}: `{s}` is not a number"))
                })?;
                if v.is_finite() {
                    Ok(v)
                } else {
                    Err(self
                        .ctx
                        .err(self.line, format!("field {name}: `{s}` is not finite")))
                }
            }
        }
    }

    fn int(&self, i: usize, name: &str, default: i64) -> Result<i64> {
        match self.raw(i) {
            None => Ok(default),
            Some(s) => s.parse::<i64>().or_else(|_| {
                let v = self.real(i, name, 0.0)?;
                if v.fract() == 0.0 && v.abs() < 9.0e15 {
                    Ok(v as i64)
                } else {
                    Err(self
                        .ctx
                        .err(self.line, format!("field {name}: `{s}` is not an integer")))
                }
            }),
        }
    }

    fn id(&self, i: usize, name: &str) -> Result<u64> {
        let v = self.int(i, name, 0)?;
        if v <= 0 {
            return Err(self.ctx.err(
                self.line,
                format!("field {name}: id must be a positive integer, got {v}"),
            ));
        }
        Ok(v as u64)
    }

    fn opt_id(&self, i: usize, name: &str) -> Result<u64> {
        let v = self.int(i, name, 0)?;
        if v < 0 {
            return Err(self
                .ctx
                .err(self.line, format!("field {name}: must be >= 0, got {v}")));
        }
        Ok(v as u64)
    }

    fn must_be_zero(&self, i: usize, name: &str) -> Result<()> {
        if self.real(i, name, 0.0)? != 0.0 {
            return Err(self.ctx.err(
                self.line,
                format!("field {name}: non-zero values are not supported"),
            ));
        }
        Ok(())
    }
}

const W10: &[usize] = &[10];

/// Parses a deck from text; `name` is used in messages.
///
/// # Errors
/// [`ShellError::Keyword`] for a malformed card (naming line, keyword and field),
/// [`ShellError::UnsupportedKeyword`] for a keyword outside the subset. References between
/// ids are checked later, by [`crate::Simulation::new`].
pub fn parse_deck<'a>(text: &'a str, name: &str) -> Result<Deck> {
    let mut model = ShellModel::new("");
    let mut warnings = Vec::new();
    // *CONTROL_CONTACT RWPNAL, applied to every rigid wall once all are read.
    let mut rwpnal = 0.0;
    let mut lines = text.lines().enumerate().peekable();
    // Skip anything before *KEYWORD (LS-DYNA ignores it too).
    let mut blocks: Vec<(usize, String, Vec<Card<'a>>)> = Vec::new();
    while let Some((i, l)) = lines.next() {
        if l.starts_with('$') {
            continue;
        }
        if let Some(kw) = l.strip_prefix('*') {
            let kw = format!(
                "*{}",
                kw.split_whitespace().next().unwrap_or("").to_uppercase()
            );
            let mut cards = Vec::new();
            while let Some((j, c)) = lines.peek() {
                if c.starts_with('*') {
                    break;
                }
                if !c.starts_with('$') {
                    cards.push(Card {
                        line: j + 1,
                        text: c.trim_end(),
                    });
                }
                lines.next();
            }
            // Trailing blank lines are not cards.
            while cards.last().is_some_and(|c| c.text.trim().is_empty()) {
                cards.pop();
            }
            let end = kw == "*END";
            blocks.push((i + 1, kw, cards));
            if end {
                break;
            }
        }
    }
    for (line, kw, cards) in blocks {
        let ctx = Ctx {
            file: name,
            keyword: kw.clone(),
        };
        let card = |c: &Card<'a>, widths: &[usize]| -> Fields<'a, '_> {
            Fields {
                f: fields(c.text, widths),
                line: c.line,
                ctx: &ctx,
            }
        };
        let need = |n: usize| -> Result<()> {
            if cards.len() < n {
                Err(ctx.err(line, format!("expected {n} card(s), found {}", cards.len())))
            } else {
                Ok(())
            }
        };
        match kw.as_str() {
            "*KEYWORD" | "*END" => {}
            "*TITLE" => {
                model.title = cards
                    .first()
                    .map(|c| c.text.trim().to_string())
                    .unwrap_or_default();
            }
            "*NODE" => {
                for c in &cards {
                    let f = card(c, &[8, 16, 16, 16, 8, 8]);
                    let id = f.id(0, "NID")?;
                    let x = f.real3(1, ["X", "Y", "Z"])?;
                    if f.int(4, "TC", 0)? != 0 || f.int(5, "RC", 0)? != 0 {
                        return Err(ctx.err(
                            c.line,
                            "nodal constraints TC/RC are not supported (use *BOUNDARY_SPC_NODE)",
                        ));
                    }
                    model.add_node(id, x);
                }
            }
            "*ELEMENT_SHELL" => {
                for c in &cards {
                    let f = card(c, &[8]);
                    let id = f.id(0, "EID")?;
                    let part = f.id(1, "PID")?;
                    let mut n = [0u64; 4];
                    for k in 0..3 {
                        n[k] = f.id(2 + k, &format!("N{}", k + 1))?;
                    }
                    n[3] = match f.opt_id(5, "N4")? {
                        0 => n[2],
                        v => v,
                    };
                    for k in 6..10 {
                        if f.opt_id(k, "N5-N8")? != 0 {
                            return Err(ctx.err(c.line, "mid-side nodes N5-N8 are not supported"));
                        }
                    }
                    model.add_shell(id, part, n);
                }
            }
            "*PART" => {
                if cards.len() % 2 != 0 {
                    return Err(ctx.err(line, "each part needs a title card and a data card"));
                }
                for pair in cards.chunks(2) {
                    let f = card(&pair[1], W10);
                    let id = f.id(0, "PID")?;
                    let section = f.id(1, "SECID")?;
                    let material = f.id(2, "MID")?;
                    f.must_be_zero(3, "EOSID")?;
                    if f.opt_id(4, "HGID")? != 0 {
                        warnings.push(format!(
                            "{name}: line {}: *PART {id}: HGID ignored, *CONTROL_HOURGLASS applies to all parts",
                            pair[1].line
                        ));
                    }
                    model.parts.push(Part {
                        id,
                        title: pair[0].text.trim().to_string(),
                        section,
                        material,
                    });
                }
            }
            "*SECTION_SHELL" => {
                if cards.len() % 2 != 0 {
                    return Err(ctx.err(line, "each section needs two cards"));
                }
                for pair in cards.chunks(2) {
                    let f = card(&pair[0], W10);
                    let id = f.id(0, "SECID")?;
                    let elform = f.int(1, "ELFORM", 2)?;
                    if ![0, 2, 4].contains(&elform) {
                        return Err(ctx.err(pair[0].line, format!("ELFORM {elform} is not supported (2: Belytschko-Tsay, 4: C0 triangle)")));
                    }
                    let shrf = f.real(2, "SHRF", 1.0)?;
                    let nip = f.int(3, "NIP", 2)?;
                    let nip = if nip == 0 { 2 } else { nip };
                    f.must_be_zero(5, "QR/IRID")?;
                    f.must_be_zero(6, "ICOMP")?;
                    let g = card(&pair[1], W10);
                    let t1 = g.real(0, "T1", 0.0)?;
                    let ts = [
                        t1,
                        g.real(1, "T2", t1)?,
                        g.real(2, "T3", t1)?,
                        g.real(3, "T4", t1)?,
                    ];
                    let ts = ts.map(|t| if t == 0.0 { t1 } else { t });
                    if ts.iter().any(|&t| (t - t1).abs() > 1e-12 * t1.abs()) {
                        warnings.push(format!(
                            "{name}: line {}: *SECTION_SHELL {id}: unequal nodal thicknesses replaced by their mean",
                            pair[1].line
                        ));
                    }
                    model.sections.push(Section {
                        id,
                        thickness: ts.iter().sum::<f64>() / 4.0,
                        nip: usize::try_from(nip).map_err(|_| {
                            ctx.err(pair[0].line, format!("NIP {nip} out of range"))
                        })?,
                        shear_factor: if shrf == 0.0 { 1.0 } else { shrf },
                        rule: ThicknessRule::Gauss,
                    });
                }
            }
            "*MAT_ELASTIC" | "*MAT_001" => {
                for c in &cards {
                    let f = card(c, W10);
                    model.materials.push(Material {
                        id: f.id(0, "MID")?,
                        density: f.real(1, "RO", 0.0)?,
                        youngs: f.real(2, "E", 0.0)?,
                        poisson: f.real(3, "PR", 0.0)?,
                        law: MaterialLaw::Elastic,
                    });
                }
            }
            "*MAT_PLASTIC_KINEMATIC" | "*MAT_003" => {
                if cards.len() % 2 != 0 {
                    return Err(ctx.err(line, "each material needs two cards"));
                }
                for pair in cards.chunks(2) {
                    let f = card(&pair[0], W10);
                    let id = f.id(0, "MID")?;
                    let beta = f.real(6, "BETA", 0.0)?;
                    if beta != 1.0 {
                        warnings.push(format!(
                            "{name}: line {}: *MAT_PLASTIC_KINEMATIC {id}: BETA = {beta}; isotropic hardening (BETA = 1) is used",
                            pair[0].line
                        ));
                    }
                    let g = card(&pair[1], W10);
                    let (src, srp) = (g.real(0, "SRC", 0.0)?, g.real(1, "SRP", 0.0)?);
                    if g.real(2, "FS", 0.0)? != 0.0 {
                        warnings.push(format!("{name}: line {}: material {id}: failure strain FS ignored (no erosion)", pair[1].line));
                    }
                    if g.real(3, "VP", 0.0)? != 0.0 {
                        return Err(ctx.err(
                            pair[1].line,
                            "VP = 1 (viscoplastic rate formulation) is not supported",
                        ));
                    }
                    model.materials.push(Material {
                        id,
                        density: f.real(1, "RO", 0.0)?,
                        youngs: f.real(2, "E", 0.0)?,
                        poisson: f.real(3, "PR", 0.0)?,
                        law: MaterialLaw::Plastic {
                            yield_stress: f.real(4, "SIGY", 0.0)?,
                            tangent_modulus: f.real(5, "ETAN", 0.0)?,
                            rate: (src != 0.0 || srp != 0.0)
                                .then_some(CowperSymonds { c: src, p: srp }),
                        },
                    });
                }
            }
            "*ELEMENT_MASS" => {
                for c in &cards {
                    let f = card(c, &[8, 8, 16, 8]);
                    model.masses.push(PointMass {
                        id: f.id(0, "EID")?,
                        node: f.id(1, "NID")?,
                        mass: f.real(2, "MASS", 0.0)?,
                    });
                }
            }
            "*SET_NODE_LIST" => {
                need(1)?;
                let id = card(&cards[0], W10).id(0, "SID")?;
                let mut nodes = Vec::new();
                for c in &cards[1..] {
                    let f = card(c, W10);
                    for k in 0..8 {
                        match f.opt_id(k, "NID")? {
                            0 => {}
                            n => nodes.push(n),
                        }
                    }
                }
                model.node_sets.push(NodeSet { id, nodes });
            }
            "*INITIAL_VELOCITY" => {
                need(2)?;
                let f = card(&cards[0], W10);
                let nsid = f.opt_id(0, "NSID")?;
                f.must_be_zero(1, "NSIDEX")?;
                f.must_be_zero(2, "BOXID")?;
                f.must_be_zero(4, "ICID")?;
                let g = card(&cards[1], W10);
                let mut iv = InitialVelocity::translation(
                    if nsid == 0 {
                        VelocityTarget::All
                    } else {
                        VelocityTarget::NodeSet(nsid)
                    },
                    g.real3(0, ["VX", "VY", "VZ"])?,
                );
                iv.rotation = g.real3(3, ["VXR", "VYR", "VZR"])?;
                model.initial_velocities.push(iv);
            }
            "*INITIAL_VELOCITY_GENERATION" => {
                if cards.len() % 2 != 0 {
                    return Err(ctx.err(line, "each generation needs two cards"));
                }
                for pair in cards.chunks(2) {
                    let f = card(&pair[0], W10);
                    let id = f.id(0, "ID")?;
                    let target = match f.int(1, "STYP", 0)? {
                        2 => VelocityTarget::Part(id),
                        3 => VelocityTarget::NodeSet(id),
                        s => {
                            return Err(ctx.err(
                                pair[0].line,
                                format!("STYP {s} is not supported (2: part, 3: node set)"),
                            ));
                        }
                    };
                    f.must_be_zero(6, "IVATN")?;
                    f.must_be_zero(7, "ICID")?;
                    let g = card(&pair[1], W10);
                    let mut iv =
                        InitialVelocity::translation(target, f.real3(3, ["VX", "VY", "VZ"])?);
                    iv.omega = f.real(2, "OMEGA", 0.0)?;
                    iv.centre = g.real3(0, ["XC", "YC", "ZC"])?;
                    iv.axis = g.real3(3, ["NX", "NY", "NZ"])?;
                    model.initial_velocities.push(iv);
                }
            }
            "*INITIAL_VELOCITY_NODE" => {
                for c in &cards {
                    let f = card(c, W10);
                    let mut iv = InitialVelocity::translation(
                        VelocityTarget::Node(f.id(0, "NID")?),
                        f.real3(1, ["VX", "VY", "VZ"])?,
                    );
                    iv.rotation = f.real3(4, ["VXR", "VYR", "VZR"])?;
                    model.initial_velocities.push(iv);
                }
            }
            "*BOUNDARY_SPC_NODE" | "*BOUNDARY_SPC_SET" => {
                for c in &cards {
                    let f = card(c, W10);
                    let id = f.id(0, if kw.ends_with("SET") { "NSID" } else { "NID" })?;
                    f.must_be_zero(1, "CID")?;
                    let mut dofs = [false; 6];
                    for (k, nm) in ["DOFX", "DOFY", "DOFZ", "DOFRX", "DOFRY", "DOFRZ"]
                        .iter()
                        .enumerate()
                    {
                        dofs[k] = match f.int(2 + k, nm, 0)? {
                            0 => false,
                            1 => true,
                            v => {
                                return Err(
                                    ctx.err(c.line, format!("field {nm}: must be 0 or 1, got {v}"))
                                );
                            }
                        };
                    }
                    let target = if kw.ends_with("SET") {
                        NodeTarget::NodeSet(id)
                    } else {
                        NodeTarget::Node(id)
                    };
                    model.spcs.push(Spc { target, dofs });
                }
            }
            "*RIGIDWALL_PLANAR" => {
                if cards.len() % 2 != 0 || cards.is_empty() {
                    return Err(ctx.err(line, "each wall needs two cards"));
                }
                for pair in cards.chunks(2) {
                    let f = card(&pair[0], W10);
                    let nsid = f.opt_id(0, "NSID")?;
                    f.must_be_zero(1, "NSIDEX")?;
                    f.must_be_zero(2, "BOXID")?;
                    f.must_be_zero(3, "OFFSET")?;
                    f.must_be_zero(4, "BIRTH")?;
                    let death = f.real(5, "DEATH", 1e20)?;
                    if death != 0.0 && death < 1e20 {
                        return Err(ctx.err(
                            pair[0].line,
                            "field DEATH: a finite death time is not supported",
                        ));
                    }
                    let g = card(&pair[1], W10);
                    let point = g.real3(0, ["XT", "YT", "ZT"])?;
                    let head = g.real3(3, ["XH", "YH", "ZH"])?;
                    let fric = g.real(6, "FRIC", 0.0)?;
                    let friction = if fric == 1.0 {
                        f64::INFINITY
                    } else if (0.0..1.0).contains(&fric) {
                        fric
                    } else {
                        return Err(ctx.err(
                            pair[1].line,
                            format!("field FRIC: {fric} is not supported (0 <= FRIC <= 1)"),
                        ));
                    };
                    model.walls.push(RigidWall {
                        nodes: (nsid != 0).then_some(nsid),
                        point,
                        head,
                        friction,
                        method: WallMethod::Kinematic,
                    });
                }
            }
            "*LOAD_BODY_Z" => {
                need(1)?;
                let f = card(&cards[0], W10);
                let curve = f.id(0, "LCID")?;
                let scale = f.real(1, "SF", 1.0)?;
                f.must_be_zero(2, "LCIDDR")?;
                f.must_be_zero(6, "CID")?;
                model.body_load_z = Some(BodyLoadZ { curve, scale });
            }
            "*DEFINE_CURVE" => {
                need(1)?;
                let f = card(&cards[0], W10);
                let id = f.id(0, "LCID")?;
                f.must_be_zero(1, "SIDR")?;
                f.must_be_zero(6, "DATTYP")?;
                let mut c = Curve::new(id, Vec::new());
                c.sfa = f.real(2, "SFA", 1.0)?;
                c.sfo = f.real(3, "SFO", 1.0)?;
                c.sfa = if c.sfa == 0.0 { 1.0 } else { c.sfa };
                c.sfo = if c.sfo == 0.0 { 1.0 } else { c.sfo };
                c.offa = f.real(4, "OFFA", 0.0)?;
                c.offo = f.real(5, "OFFO", 0.0)?;
                for p in &cards[1..] {
                    let g = card(p, &[20]);
                    c.points.push((g.real(0, "A", 0.0)?, g.real(1, "O", 0.0)?));
                }
                model.curves.push(c);
            }
            "*DAMPING_GLOBAL" => {
                need(1)?;
                let f = card(&cards[0], W10);
                f.must_be_zero(0, "LCID")?;
                model.damping = f.real(1, "VALDMP", 0.0)?;
                let s: Vec<f64> = (2..8)
                    .map(|k| f.real(k, "STX-SRZ", 0.0))
                    .collect::<Result<_>>()?;
                if s.iter().any(|&v| v != 0.0) && s[..3].iter().any(|&v| v != 1.0) {
                    return Err(ctx.err(
                        cards[0].line,
                        "direction scale factors STX..SRZ are not supported",
                    ));
                }
            }
            "*DAMPING_PART_STIFFNESS" => {
                for c in &cards {
                    let f = card(c, W10);
                    model.stiffness_damping.push(PartStiffnessDamping {
                        part: f.id(0, "PID")?,
                        coef: f.real(1, "COEF", 0.0)?,
                    });
                }
            }
            "*CONTROL_BULK_VISCOSITY" => {
                need(1)?;
                let f = card(&cards[0], W10);
                let q1 = f.real(0, "Q1", 1.5)?;
                let q2 = f.real(1, "Q2", 0.06)?;
                let b = BulkViscosity {
                    q1: if q1 == 0.0 { 1.5 } else { q1 },
                    q2: if q2 == 0.0 { 0.06 } else { q2 },
                };
                model.bulk_viscosity = match f.int(2, "TYPE", 1)? {
                    -2 | -1 => Some(b),
                    1 | 2 => {
                        warnings.push(format!(
                            "{name}: line {}: *CONTROL_BULK_VISCOSITY TYPE 1 or 2 acts on solids only: no bulk viscosity on the shells (TYPE -2 applies it to shells)",
                            cards[0].line
                        ));
                        None
                    }
                    v => {
                        return Err(ctx.err(
                            cards[0].line,
                            format!("field TYPE: {v} is not supported (1, 2, -1 or -2)"),
                        ));
                    }
                };
            }
            "*CONTROL_ACCURACY" => {
                need(1)?;
                let f = card(&cards[0], W10);
                if f.int(0, "OSU", 0)? != 0 {
                    warnings.push(format!(
                        "{name}: line {}: *CONTROL_ACCURACY OSU ignored (shell stresses are corotational)",
                        cards[0].line
                    ));
                }
                model.control.invariant_numbering = match f.int(1, "INN", 1)? {
                    0 | 1 => false,
                    2..=4 => true,
                    v => {
                        return Err(ctx.err(
                            cards[0].line,
                            format!("field INN: {v} is not supported (1 off, 2 to 4 on)"),
                        ));
                    }
                };
                f.must_be_zero(2, "PIDOSU")?;
                f.must_be_zero(3, "IACC")?;
            }
            "*CONTROL_CONTACT" => {
                need(1)?;
                let f = card(&cards[0], W10);
                rwpnal = f.real(1, "RWPNAL", 0.0)?;
                if !(0.0..=1.0).contains(&rwpnal) {
                    return Err(ctx.err(
                        cards[0].line,
                        format!(
                            "field RWPNAL: {rwpnal} is not supported (0: constraint method, \
                             0 < RWPNAL <= 1: penalty walls with that stiffness factor)"
                        ),
                    ));
                }
                let other = (0..8)
                    .filter(|&k| k != 1)
                    .map(|k| f.real(k, "SLSFAC-ENMASS", 0.0))
                    .collect::<Result<Vec<_>>>()?;
                if other.iter().any(|&v| v != 0.0) || cards.len() > 1 {
                    warnings.push(format!(
                        "{name}: line {}: *CONTROL_CONTACT: only RWPNAL is used (there are no contact interfaces)",
                        cards[0].line
                    ));
                }
            }
            "*CONTROL_TERMINATION" => {
                need(1)?;
                let f = card(&cards[0], W10);
                model.control.end_time = f.real(0, "ENDTIM", 0.0)?;
                model.control.end_cycles = f.opt_id(1, "ENDCYC")?;
                model.control.dtmin_factor = f.real(2, "DTMIN", 0.0)?;
                f.must_be_zero(3, "ENDENG")?;
                f.must_be_zero(4, "ENDMAS")?;
            }
            "*CONTROL_TIMESTEP" => {
                need(1)?;
                let f = card(&cards[0], W10);
                let tssfac = f.real(1, "TSSFAC", 0.9)?;
                model.control.tssfac = if tssfac == 0.0 { 0.9 } else { tssfac };
                model.control.isdo_diagonal = match f.int(2, "ISDO", 0)? {
                    0 => false,
                    1 => true,
                    v => {
                        return Err(ctx.err(
                            cards[0].line,
                            format!("field ISDO: {v} is not supported (0 or 1)"),
                        ));
                    }
                };
                f.must_be_zero(4, "DT2MS")?;
                f.must_be_zero(5, "LCTM")?;
            }
            "*CONTROL_HOURGLASS" => {
                need(1)?;
                let f = card(&cards[0], W10);
                let form = match f.int(0, "IHQ", 0)? {
                    0..=3 => HourglassForm::Viscous,
                    4..=6 => HourglassForm::Stiffness,
                    v => {
                        return Err(ctx.err(
                            cards[0].line,
                            format!("field IHQ: {v} is not supported (1-6)"),
                        ));
                    }
                };
                let qh = f.real(1, "QH", 0.1)?;
                let qh = if qh == 0.0 { 0.1 } else { qh };
                model.hourglass.form = form;
                model.hourglass.membrane = qh;
                model.hourglass.transverse = qh;
                model.hourglass.rotation = qh;
            }
            "*DATABASE_HISTORY_NODE" => {
                for c in &cards {
                    let f = card(c, W10);
                    for k in 0..8 {
                        match f.opt_id(k, "ID")? {
                            0 => {}
                            n => model.output.history_nodes.push(n),
                        }
                    }
                }
            }
            "*DATABASE_NODOUT" => {
                need(1)?;
                model.output.interval = card(&cards[0], W10).real(0, "DT", 0.0)?;
            }
            k if IGNORED_KEYWORDS.contains(&k) => {
                warnings.push(format!(
                    "{name}: line {line}: output-only keyword {k} ignored"
                ));
            }
            k => {
                return Err(ShellError::UnsupportedKeyword {
                    file: name.to_string(),
                    line,
                    keyword: k.to_string(),
                });
            }
        }
    }
    if rwpnal > 0.0 {
        for w in &mut model.walls {
            w.method = WallMethod::Penalty {
                alpha: rwpnal,
                damping: 0.0,
            };
        }
    }
    Ok(Deck { model, warnings })
}
