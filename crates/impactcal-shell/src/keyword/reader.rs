//! Reading keyword decks.

use std::cell::RefCell;
use std::collections::HashMap;
use std::path::Path;

use super::source::Source;

use crate::error::{Result, ShellError, UnsupportedAt};
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

/// A parameter of a deck (`*PARAMETER`): its name as written, its value, whether it is an
/// integer (`I`) or a real (`R`) parameter, and where it is defined.
#[derive(Debug, Clone, PartialEq)]
pub struct DeckParameter {
    /// The name, as written (references `&name` match it without regard to case).
    pub name: String,
    /// The value.
    pub value: f64,
    /// `I` parameter (integer) rather than `R` (real).
    pub integer: bool,
    /// The file that defines it.
    pub file: String,
    /// Its line there.
    pub line: usize,
}

/// A parsed deck: the model, its parameters and the warnings raised while reading it.
#[derive(Debug, Clone)]
pub struct Deck {
    /// The model.
    pub model: ShellModel,
    /// Warnings (ignored output-only keywords, fields read with a simplification, defaults
    /// used for missing control cards, numbers running across field boundaries).
    pub warnings: Vec<String>,
    /// The `*PARAMETER` definitions of the deck and its includes, in the order read.
    pub parameters: Vec<DeckParameter>,
    /// The deck's lines, to read it again with other parameter values.
    source: Source,
}

impl Deck {
    /// The deck read again with the parameters `values` (name, value) in place of the
    /// values of its `*PARAMETER` cards (names without regard to case; integer parameters
    /// take the value rounded to the nearest integer).
    ///
    /// # Errors
    /// [`ShellError::Value`] naming a parameter the deck does not define, otherwise as
    /// [`parse_deck`].
    pub fn with_parameters(&self, values: &[(&str, f64)]) -> Result<Deck> {
        let mut overrides = HashMap::new();
        for (name, v) in values {
            let key = name.to_uppercase();
            if !self.parameters.iter().any(|p| p.name.to_uppercase() == key) {
                return Err(ShellError::value(
                    format!("parameter {name}"),
                    "is not defined by the deck (*PARAMETER)",
                ));
            }
            overrides.insert(key, *v);
        }
        parse_source(self.source.clone(), &overrides)
    }
}

/// Reads a deck file (with the files it includes).
///
/// # Errors
/// [`ShellError::Io`] when the file cannot be read, otherwise as [`parse_deck`].
pub fn read_deck(path: impl AsRef<Path>) -> Result<Deck> {
    parse_source(Source::from_file(path.as_ref())?, &HashMap::new())
}

/// One data card: its line number and text.
struct Card<'a> {
    line: usize,
    text: &'a str,
}

/// The values of the deck's parameters by upper-case name.
type Params = HashMap<String, f64>;

struct Ctx<'a> {
    file: &'a str,
    keyword: String,
    params: &'a Params,
    /// Warnings raised while splitting cards (numbers across field boundaries).
    notes: &'a RefCell<Vec<String>>,
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

/// The fields of a card, split by commas or by the fixed `widths` (the last width repeats),
/// each with its first column (0-based; 0 for comma-separated fields).
fn fields<'a>(text: &'a str, widths: &[usize]) -> Vec<(&'a str, usize)> {
    if text.contains(',') {
        return text.split(',').map(|f| (f.trim(), 0)).collect();
    }
    let mut out = Vec::new();
    let mut pos = 0;
    let mut k = 0;
    let bytes = text.len();
    while pos < bytes {
        let w = widths[k.min(widths.len() - 1)];
        let end = (pos + w).min(bytes);
        out.push((text.get(pos..end).unwrap_or("").trim(), pos));
        pos = end;
        k += 1;
    }
    out
}

/// A number in LS-DYNA's forms: Rust's, `d`/`D` exponents, and Fortran's exponent without
/// a letter (`2.00000-3` = 2e-3, `1.5+2` = 150).
fn parse_number(s: &str) -> Option<f64> {
    let t = s.replace(['d', 'D'], "e");
    if let Ok(v) = t.parse::<f64>() {
        return Some(v);
    }
    // A sign after a digit or a point starts the exponent.
    let b = t.as_bytes();
    let k = (1..b.len()).rev().find(|&k| {
        (b[k] == b'+' || b[k] == b'-') && (b[k - 1].is_ascii_digit() || b[k - 1] == b'.')
    })?;
    format!("{}e{}", &t[..k], &t[k..]).parse().ok()
}

/// The fixed-format boundaries of `text` that a number runs across: where the last column
/// of one field and the first of the next are both part of one run of characters that
/// reads as a single number with a decimal point or an exponent (a value wider than its
/// field). Returns the run and the indices of the fields it covers.
fn overflows(text: &str, f: &[(&str, usize)]) -> Vec<(String, usize, usize)> {
    let b = text.as_bytes();
    // (run, first field, last field, start column)
    let mut out: Vec<(String, usize, usize, usize)> = Vec::new();
    for k in 1..f.len() {
        let at = f[k].1;
        if at == 0 || at >= b.len() || b[at - 1] == b' ' || b[at] == b' ' {
            continue;
        }
        let start = b[..at]
            .iter()
            .rposition(|&c| c == b' ')
            .map_or(0, |p| p + 1);
        if let Some(o) = out.last_mut().filter(|o| o.3 == start) {
            o.2 = k;
            continue;
        }
        let end = b[at..]
            .iter()
            .position(|&c| c == b' ')
            .map_or(b.len(), |p| at + p);
        let Some(run) = text.get(start..end) else {
            continue;
        };
        if run.contains(['.', 'e', 'E']) && parse_number(run).is_some() {
            let first = f.iter().rposition(|x| x.1 <= start).unwrap_or(0);
            out.push((run.to_string(), first, k, start));
        }
    }
    out.into_iter().map(|(r, a, z, _)| (r, a, z)).collect()
}

struct Fields<'c> {
    /// Each field's text after `&name` references are replaced, or the message of an
    /// unknown reference.
    f: Vec<std::result::Result<String, String>>,
    line: usize,
    ctx: &'c Ctx<'c>,
}

impl Fields<'_> {
    fn new<'c>(c: &Card<'_>, widths: &[usize], ctx: &'c Ctx<'c>) -> Fields<'c> {
        let raw = fields(c.text, widths);
        if !c.text.contains(',') {
            for (run, first, last) in overflows(c.text, &raw) {
                let read: Vec<String> = raw[first..=last]
                    .iter()
                    .map(|(s, _)| format!("`{s}`"))
                    .collect();
                ctx.notes.borrow_mut().push(format!(
                    "{}: line {}: {}: `{run}` runs across fields {} to {} (columns {} to {}), read as {}",
                    ctx.file,
                    c.line,
                    ctx.keyword,
                    first + 1,
                    last + 1,
                    raw[first].1 + 1,
                    raw[last].1 + widths[last.min(widths.len() - 1)],
                    read.join(", ")
                ));
            }
        }
        let f = raw
            .iter()
            .map(|(s, _)| {
                let (neg, name) = match s.strip_prefix("-&") {
                    Some(n) => (true, n),
                    None => match s.strip_prefix('&') {
                        Some(n) => (false, n),
                        None => return Ok((*s).to_string()),
                    },
                };
                match ctx.params.get(&name.trim().to_uppercase()) {
                    Some(v) => Ok(format!("{:e}", if neg { -v } else { *v })),
                    None => Err(format!("`{s}` refers to no *PARAMETER")),
                }
            })
            .collect();
        Fields {
            f,
            line: c.line,
            ctx,
        }
    }

    fn raw(&self, i: usize, name: &str) -> Result<Option<&str>> {
        match self.f.get(i) {
            None => Ok(None),
            Some(Ok(s)) => Ok(Some(s.as_str()).filter(|s| !s.is_empty())),
            Some(Err(m)) => Err(self
                .ctx
                .err(self.line, format!("field {name} (field {}): {m}", i + 1))),
        }
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
        match self.raw(i, name)? {
            None => Ok(default),
            Some(s) => {
                let v = parse_number(s).ok_or_else(|| {
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
        match self.raw(i, name)? {
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

/// Keywords with a `_TITLE` variant (a title line ahead of each definition) and the number
/// of cards of one definition (0: one definition per keyword, title first).
const TITLED: &[(&str, usize)] = &[
    ("*SECTION_SHELL", 2),
    ("*MAT_ELASTIC", 1),
    ("*MAT_001", 1),
    ("*MAT_PLASTIC_KINEMATIC", 2),
    ("*MAT_003", 2),
    ("*DEFINE_CURVE", 0),
    ("*SET_NODE_LIST", 0),
];

/// Keywords with an `_ID` variant and the number of cards of one definition after its id
/// card `ID, HEADING` (0: one id card for the whole keyword, then as many data cards as
/// necessary). LS-DYNA's manual: `*RIGIDWALL_PLANAR_ID` has an id card ahead of each wall;
/// `*BOUNDARY_SPC_{NODE|SET}_ID` one id card (the SPC set's id and heading) and then any
/// number of node or set cards, all of that SPC set. `*DATABASE_HISTORY_NODE_ID` is
/// different: one node per card, its id in columns 1-10 and a heading in 11-80.
const WITH_ID: &[(&str, usize)] = &[
    ("*RIGIDWALL_PLANAR", 2),
    ("*BOUNDARY_SPC_NODE", 0),
    ("*BOUNDARY_SPC_SET", 0),
];

/// Every keyword this reader reads (beside the `_TITLE` and `_ID` variants above and the
/// output-only ones it skips).
const SUPPORTED: &[&str] = &[
    "*KEYWORD",
    "*END",
    "*TITLE",
    "*PARAMETER",
    "*NODE",
    "*ELEMENT_SHELL",
    "*PART",
    "*SECTION_SHELL",
    "*MAT_ELASTIC",
    "*MAT_001",
    "*MAT_PLASTIC_KINEMATIC",
    "*MAT_003",
    "*ELEMENT_MASS",
    "*SET_NODE_LIST",
    "*INITIAL_VELOCITY",
    "*INITIAL_VELOCITY_GENERATION",
    "*INITIAL_VELOCITY_NODE",
    "*BOUNDARY_SPC_NODE",
    "*BOUNDARY_SPC_SET",
    "*RIGIDWALL_PLANAR",
    "*LOAD_BODY_Z",
    "*DEFINE_CURVE",
    "*DAMPING_GLOBAL",
    "*DAMPING_PART_STIFFNESS",
    "*CONTROL_BULK_VISCOSITY",
    "*CONTROL_ACCURACY",
    "*CONTROL_CONTACT",
    "*CONTROL_TERMINATION",
    "*CONTROL_TIMESTEP",
    "*CONTROL_HOURGLASS",
    "*DATABASE_HISTORY_NODE",
    "*DATABASE_NODOUT",
];

/// A keyword's base name and the number of cards of one definition ahead of which a title
/// or id card stands (`Some(0)`: one title card first), or `None` for a plain keyword.
fn variant(kw: &str) -> (String, Option<usize>, bool) {
    if kw == "*DATABASE_HISTORY_NODE_ID" {
        return ("*DATABASE_HISTORY_NODE".into(), None, true);
    }
    for (suffix, table) in [("_TITLE", TITLED), ("_ID", WITH_ID)] {
        if let Some(base) = kw.strip_suffix(suffix) {
            if let Some(&(b, n)) = table.iter().find(|(b, _)| *b == base) {
                return (b.to_string(), Some(n), false);
            }
        }
    }
    (kw.to_string(), None, false)
}

/// Parses a deck from text; `name` is used in messages, and `*INCLUDE` paths are relative
/// to its directory.
///
/// What the reader accepts beyond the plain cards: the `_TITLE` variants of the sections,
/// materials, curves and node sets and the `_ID` variants of the walls, constraints and
/// history nodes; `*INCLUDE` (nested); `*PARAMETER` (`R`/`I` names, in pairs of 10-column
/// fields, 4 pairs a line) and `&name` / `-&name` references in any numeric field;
/// Fortran exponents (`2.00000-3`); LS-PrePost's `ENDMAS` 1.0e8.
///
/// # Errors
/// [`ShellError::Keyword`] for a malformed card (naming file, line, keyword and field), an
/// unknown parameter reference, an unreadable or circular include;
/// [`ShellError::UnsupportedKeyword`] for a keyword outside the subset, or
/// [`ShellError::UnsupportedKeywords`] listing all of them with their lines when there are
/// several. References between ids are checked later, by [`crate::Simulation::new`].
pub fn parse_deck(text: &str, name: &str) -> Result<Deck> {
    parse_source(Source::from_text(text, name)?, &HashMap::new())
}

/// A keyword and its cards: the keyword's file index and line, its upper-case name.
struct Block<'a> {
    file: usize,
    line: usize,
    kw: String,
    cards: Vec<Card<'a>>,
}

/// The deck's blocks, from the first keyword to `*END` (anything before the first keyword
/// is skipped, as LS-DYNA does).
fn blocks(src: &Source) -> Vec<Block<'_>> {
    let mut lines = src.lines.iter().peekable();
    let mut blocks = Vec::new();
    while let Some(l) = lines.next() {
        let Some(kw) = l.text.strip_prefix('*') else {
            continue;
        };
        let kw = format!(
            "*{}",
            kw.split_whitespace().next().unwrap_or("").to_uppercase()
        );
        let mut cards = Vec::new();
        while let Some(c) = lines.peek() {
            if c.text.starts_with('*') {
                break;
            }
            if !c.text.starts_with('$') {
                cards.push(Card {
                    line: c.line,
                    text: c.text.trim_end(),
                });
            }
            lines.next();
        }
        // Trailing blank lines are not cards.
        while cards.last().is_some_and(|c| c.text.trim().is_empty()) {
            cards.pop();
        }
        let end = kw == "*END";
        blocks.push(Block {
            file: l.file,
            line: l.line,
            kw,
            cards,
        });
        if end {
            break;
        }
    }
    blocks
}

/// The `*PARAMETER` definitions of the blocks, with `overrides` (upper-case names) in
/// place of the deck's values.
fn parameters(
    src: &Source,
    blocks: &[Block<'_>],
    overrides: &Params,
) -> Result<(Vec<DeckParameter>, Params)> {
    let mut list: Vec<DeckParameter> = Vec::new();
    let mut values = Params::new();
    let empty = Params::new();
    let notes = RefCell::new(Vec::new());
    for b in blocks.iter().filter(|b| b.kw == "*PARAMETER") {
        let ctx = Ctx {
            file: &src.files[b.file],
            keyword: b.kw.clone(),
            params: &empty,
            notes: &notes,
        };
        for c in &b.cards {
            let f = Fields::new(c, W10, &ctx);
            for pair in 0..f.f.len().div_ceil(2) {
                let k = 2 * pair;
                let field = format!("PRMR{}", pair + 1);
                let Some(head) = f.raw(k, &field)? else {
                    continue;
                };
                let (kind, pname) = head.split_at(1);
                let pname = pname.trim();
                let integer = match kind {
                    "R" | "r" => false,
                    "I" | "i" => true,
                    _ => {
                        return Err(ctx.err(
                            c.line,
                            format!(
                                "field {field}: `{head}`: a parameter is `R name` (real) or \
                                 `I name` (integer); character parameters are not supported"
                            ),
                        ));
                    }
                };
                if pname.is_empty()
                    || !pname
                        .chars()
                        .all(|ch| ch.is_ascii_alphanumeric() || ch == '_')
                {
                    return Err(ctx.err(
                        c.line,
                        format!("field {field}: `{head}` has no valid parameter name"),
                    ));
                }
                let key = pname.to_uppercase();
                if let Some(p) = list.iter().find(|p| p.name.to_uppercase() == key) {
                    return Err(ctx.err(
                        c.line,
                        format!(
                            "parameter {pname} is already defined ({}: line {})",
                            p.file, p.line
                        ),
                    ));
                }
                let value = f.real(k + 1, &format!("VAL{}", pair + 1), 0.0)?;
                let used = overrides
                    .get(&key)
                    .map_or(value, |&v| if integer { v.round() } else { v });
                values.insert(key, used);
                list.push(DeckParameter {
                    name: pname.to_string(),
                    value,
                    integer,
                    file: src.files[b.file].clone(),
                    line: c.line,
                });
            }
        }
    }
    Ok((list, values))
}

/// Parses the lines of a deck with the parameter values `overrides` (upper-case names).
fn parse_source(src: Source, overrides: &Params) -> Result<Deck> {
    let mut model = ShellModel::new("");
    let mut warnings = src.warnings.clone();
    let blocks = blocks(&src);
    // Every unsupported keyword, before any card is read.
    let unsupported: Vec<UnsupportedAt> = blocks
        .iter()
        .filter(|b| {
            let (base, _, _) = variant(&b.kw);
            !SUPPORTED.contains(&base.as_str()) && !IGNORED_KEYWORDS.contains(&b.kw.as_str())
        })
        .map(|b| UnsupportedAt {
            file: src.files[b.file].clone(),
            line: b.line,
            keyword: b.kw.clone(),
        })
        .collect();
    match unsupported.len() {
        0 => {}
        1 => {
            let u = &unsupported[0];
            return Err(ShellError::UnsupportedKeyword {
                file: u.file.clone(),
                line: u.line,
                keyword: u.keyword.clone(),
            });
        }
        _ => {
            return Err(ShellError::UnsupportedKeywords {
                file: src.files[0].clone(),
                found: unsupported,
            });
        }
    }
    let (parameters, params) = parameters(&src, &blocks, overrides)?;
    let notes = RefCell::new(Vec::new());
    let (mut termination, mut hourglass) = (false, false);
    // *CONTROL_CONTACT RWPNAL, applied to every rigid wall once all are read.
    let mut rwpnal = 0.0;
    for Block {
        file,
        line,
        kw: written,
        cards,
    } in &blocks
    {
        let (line, name) = (*line, src.files[*file].as_str());
        let (kw, titled, history_id) = variant(written);
        let ctx = Ctx {
            file: name,
            keyword: written.clone(),
            params: &params,
            notes: &notes,
        };
        // Drop the title or id cards of the _TITLE and _ID variants.
        let cards: Vec<&Card<'_>> = match titled {
            None => cards.iter().collect(),
            Some(0) => cards.iter().skip(1).collect(),
            Some(n) => {
                if cards.len() % (n + 1) != 0 {
                    return Err(ctx.err(
                        line,
                        format!(
                            "each definition needs a title or id card and {n} data card(s), found {} card(s)",
                            cards.len()
                        ),
                    ));
                }
                cards
                    .iter()
                    .enumerate()
                    .filter(|(i, _)| i % (n + 1) != 0)
                    .map(|(_, c)| c)
                    .collect()
            }
        };
        termination |= kw == "*CONTROL_TERMINATION";
        hourglass |= kw == "*CONTROL_HOURGLASS";
        let card = |c: &Card<'_>, widths: &[usize]| -> Fields<'_> { Fields::new(c, widths, &ctx) };
        let need = |n: usize| -> Result<()> {
            if cards.len() < n {
                Err(ctx.err(line, format!("expected {n} card(s), found {}", cards.len())))
            } else {
                Ok(())
            }
        };
        match kw.as_str() {
            "*KEYWORD" | "*END" | "*PARAMETER" => {}
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
                    let f = card(pair[1], W10);
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
                    let f = card(pair[0], W10);
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
                    let g = card(pair[1], W10);
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
                    let f = card(pair[0], W10);
                    let id = f.id(0, "MID")?;
                    let beta = f.real(6, "BETA", 0.0)?;
                    if beta != 1.0 {
                        warnings.push(format!(
                            "{name}: line {}: *MAT_PLASTIC_KINEMATIC {id}: BETA = {beta}; isotropic hardening (BETA = 1) is used",
                            pair[0].line
                        ));
                    }
                    let g = card(pair[1], W10);
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
                let id = card(cards[0], W10).id(0, "SID")?;
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
                let f = card(cards[0], W10);
                let nsid = f.opt_id(0, "NSID")?;
                f.must_be_zero(1, "NSIDEX")?;
                f.must_be_zero(2, "BOXID")?;
                f.must_be_zero(4, "ICID")?;
                let g = card(cards[1], W10);
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
                    let f = card(pair[0], W10);
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
                    let g = card(pair[1], W10);
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
                    let f = card(pair[0], W10);
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
                    let g = card(pair[1], W10);
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
                let f = card(cards[0], W10);
                let curve = f.id(0, "LCID")?;
                let scale = f.real(1, "SF", 1.0)?;
                f.must_be_zero(2, "LCIDDR")?;
                f.must_be_zero(6, "CID")?;
                model.body_load_z = Some(BodyLoadZ { curve, scale });
            }
            "*DEFINE_CURVE" => {
                need(1)?;
                let f = card(cards[0], W10);
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
                let f = card(cards[0], W10);
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
                let f = card(cards[0], W10);
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
                let f = card(cards[0], W10);
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
                let f = card(cards[0], W10);
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
                let f = card(cards[0], W10);
                model.control.end_time = f.real(0, "ENDTIM", 0.0)?;
                model.control.end_cycles = f.opt_id(1, "ENDCYC")?;
                model.control.dtmin_factor = f.real(2, "DTMIN", 0.0)?;
                f.must_be_zero(3, "ENDENG")?;
                // ENDMAS acts only with mass scaling, which this solver does not do;
                // LS-PrePost writes 1.0e8 by default.
                let endmas = f.real(4, "ENDMAS", 0.0)?;
                if endmas != 0.0 && endmas != 1.0e8 {
                    warnings.push(format!(
                        "{name}: line {}: *CONTROL_TERMINATION ENDMAS {endmas} ignored (it acts only with mass scaling)",
                        cards[0].line
                    ));
                }
            }
            "*CONTROL_TIMESTEP" => {
                need(1)?;
                let f = card(cards[0], W10);
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
                let f = card(cards[0], W10);
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
                    // The _ID variant: one node a card, then its heading.
                    for k in 0..if history_id { 1 } else { 8 } {
                        match f.opt_id(k, "ID")? {
                            0 => {}
                            n => model.output.history_nodes.push(n),
                        }
                    }
                }
            }
            "*DATABASE_NODOUT" => {
                need(1)?;
                model.output.interval = card(cards[0], W10).real(0, "DT", 0.0)?;
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
    let top = &src.files[0];
    if !termination {
        warnings.push(format!(
            "{top}: no *CONTROL_TERMINATION: the run ends at the default time {:e}",
            model.control.end_time
        ));
    }
    if !hourglass {
        let h = &model.hourglass;
        warnings.push(format!(
            "{top}: no *CONTROL_HOURGLASS: the default hourglass control is used ({} form, coefficient {})",
            match h.form {
                HourglassForm::Stiffness => "stiffness",
                HourglassForm::Viscous => "viscous",
            },
            h.membrane
        ));
    }
    warnings.extend(notes.into_inner());
    if rwpnal > 0.0 {
        for w in &mut model.walls {
            w.method = WallMethod::Penalty {
                alpha: rwpnal,
                damping: 0.0,
            };
        }
    }
    Ok(Deck {
        model,
        warnings,
        parameters,
        source: src,
    })
}
