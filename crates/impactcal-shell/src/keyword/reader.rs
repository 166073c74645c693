//! Reading keyword decks: the blocks of a deck dispatched, keyword by keyword, to the card
//! parser of its family through one table ([`TABLE`]). A new keyword is one parser function
//! (in `families/`) and one table line.

use std::cell::RefCell;
use std::collections::HashMap;
use std::path::Path;

use super::blocks::{Block, blocks};
use super::cards::{Card, Ctx, Fields, Params};
use super::families as fam;
use super::params::{DeckParameter, parameters};
use super::source::Source;

use crate::error::{Result, ShellError, UnsupportedAt};
use crate::model::{HourglassForm, ShellModel, WallMethod};

/// Output-only keywords that are skipped with a warning (their cards are ignored), with
/// their `_ID` variants. Keywords starting with `*SENSOR` are skipped with a warning too
/// (sensors switch features this solver does not have).
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
    "*DATABASE_ABSTAT",
    "*DATABASE_RBDOUT",
    "*DATABASE_JNTFORC",
    "*DATABASE_SBTOUT",
    "*DATABASE_SSSTAT",
    "*DATABASE_SWFORC",
    "*DATABASE_NCFORC",
    "*DATABASE_GCEOUT",
    "*DATABASE_BINARY_D3PLOT",
    "*DATABASE_BINARY_D3THDT",
    "*DATABASE_BINARY_D3DUMP",
    "*DATABASE_BINARY_RUNRSF",
    "*DATABASE_BINARY_INTFOR",
    "*DATABASE_EXTENT_BINARY",
    "*DATABASE_HISTORY_SHELL",
    "*DATABASE_FORMAT",
    "*CONTROL_OUTPUT",
    "*CONTROL_ENERGY",
    "*CONTROL_PARALLEL",
];

/// A parsed deck: the model, its parameters and the warnings raised while reading it.
#[derive(Debug, Clone)]
pub struct Deck {
    /// The model.
    pub model: ShellModel,
    /// Warnings (ignored output-only keywords, fields read with a simplification, defaults
    /// used for missing control cards, numbers running across field boundaries).
    pub warnings: Vec<String>,
    /// The `*PARAMETER` and `*PARAMETER_EXPRESSION` definitions of the deck and its
    /// includes, in the order read.
    pub parameters: Vec<DeckParameter>,
    /// The number of data cards read: every card of every keyword of the deck and its
    /// includes (those of skipped keywords included, which are warned).
    pub cards: usize,
    /// The deck's lines, to read it again with other parameter values.
    source: Source,
}

impl Deck {
    /// The deck read again with the parameters `values` (name, value) in place of the
    /// values of its `*PARAMETER` cards (names without regard to case; integer parameters
    /// take the value rounded to the nearest integer). Expressions are evaluated again
    /// with the new values.
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

/// Parses a deck from text; `name` is used in messages, and `*INCLUDE` paths are relative
/// to its directory.
///
/// What the reader accepts beyond the plain cards: the `_TITLE` and `_ID` variants listed
/// in `docs/shell-solver.md`; `*INCLUDE` (every file it names, nested) and
/// `*INCLUDE_PATH`; `*PARAMETER` and `*PARAMETER_EXPRESSION` and `&name` / `-&name`
/// references in any numeric field; the long format (`*KEYWORD LONG=Y`, a `+` suffix) and
/// 10-digit ids (`I10=Y`, a `%` suffix); Fortran exponents (`2.00000-3`); LS-PrePost's
/// `ENDMAS` 1.0e8.
///
/// # Errors
/// [`ShellError::Keyword`] for a malformed card (naming file, line, keyword and field), a
/// card a keyword does not take, an unknown parameter reference, an unreadable or circular
/// include; [`ShellError::UnsupportedKeyword`] for a keyword outside the subset, or
/// [`ShellError::UnsupportedKeywords`] listing all of them with their lines when there are
/// several. References between ids are checked later, by [`crate::Simulation::new`].
pub fn parse_deck(text: &str, name: &str) -> Result<Deck> {
    parse_source(Source::from_text(text, name)?, &HashMap::new())
}

/// What the parsers build while the blocks are read.
pub(super) struct Reader<'a> {
    pub model: ShellModel,
    pub warnings: Vec<String>,
    params: &'a Params,
    notes: RefCell<Vec<String>>,
    /// Keywords read so far (table names).
    pub seen: Vec<&'static str>,
    /// `*CONTROL_CONTACT` RWPNAL, applied to every rigid wall once all are read.
    pub rwpnal: f64,
    /// `*CONTROL_CONTACT` SFRIC, DFRIC, EDC, VFC: the friction of interfaces that give
    /// none (FS = FD = DC = VC = 0), applied once all are read.
    pub default_friction: crate::contact::ContactFriction,
    /// Per interface read, its friction scale factors FSF and VSF (applied to the
    /// defaults too).
    pub friction_scales: Vec<(f64, f64)>,
}

/// One keyword block as its parser sees it: the options written after the keyword's name
/// (`TITLE`, `ID`, ...) and a cursor over its cards.
pub(super) struct Kw<'b> {
    pub ctx: Ctx<'b>,
    /// The line of the keyword.
    pub line: usize,
    options: Vec<String>,
    cards: &'b [Card<'b>],
    pos: usize,
    /// The trailing blank lines still available as required cards.
    blank: &'b [usize],
}

impl<'b> Kw<'b> {
    /// True when the keyword was written with option `o` (`*SECTION_SHELL_TITLE` has
    /// `TITLE`).
    pub fn has(&self, o: &str) -> bool {
        self.options.iter().any(|x| x == o)
    }

    /// The next card, if any.
    pub fn next(&mut self) -> Option<Card<'b>> {
        let c = self.cards.get(self.pos).copied();
        self.pos += usize::from(c.is_some());
        c
    }

    /// The next card (a trailing blank line when the cards are used up: a card of
    /// defaults), or an error saying which card is missing.
    pub fn take(&mut self, what: &str) -> Result<Card<'b>> {
        if self.pos == self.cards.len()
            && let Some((&line, rest)) = self.blank.split_first()
        {
            self.blank = rest;
            return Ok(Card { line, text: "" });
        }
        self.next().ok_or_else(|| {
            self.ctx.err(
                self.line,
                format!("expected {what}, found {} card(s)", self.cards.len()),
            )
        })
    }

    /// The number of cards not taken yet.
    pub fn remaining(&self) -> usize {
        self.cards.len() - self.pos
    }

    /// True when cards remain.
    pub fn more(&self) -> bool {
        self.pos < self.cards.len()
    }

    /// The fields of `c` with the standard widths `widths`.
    pub fn fields(&self, c: &Card<'_>, widths: &[usize]) -> Fields<'_> {
        self.ctx.fields(c, widths)
    }

    /// A [`ShellError::Keyword`] at `line`.
    pub fn err(&self, line: usize, message: impl Into<String>) -> ShellError {
        self.ctx.err(line, message)
    }

    /// A warning at `line`.
    pub fn warning(&self, line: usize, message: impl std::fmt::Display) -> String {
        self.ctx.warning(line, message)
    }
}

/// A card parser: reads the cards of one keyword block into the model.
pub(super) type Parse = fn(&mut Reader<'_>, &mut Kw<'_>) -> Result<()>;

/// A supported keyword: its base name, the options it may be written with (`_TITLE`,
/// `_ID`, ... in any order), and its parser.
pub(super) struct Entry {
    pub name: &'static str,
    pub options: &'static [&'static str],
    pub parse: Parse,
}

const fn e(name: &'static str, options: &'static [&'static str], parse: Parse) -> Entry {
    Entry {
        name,
        options,
        parse,
    }
}

/// Every keyword this reader reads, by family.
pub(super) const TABLE: &[Entry] = &[
    // Deck structure.
    e("*KEYWORD", &[], fam::controls::nothing),
    e("*END", &[], fam::controls::nothing),
    e("*TITLE", &[], fam::controls::title),
    e("*PARAMETER", &[], fam::controls::nothing),
    e("*PARAMETER_EXPRESSION", &[], fam::controls::nothing),
    // Mesh and parts.
    e("*NODE", &[], fam::mesh::node),
    e("*ELEMENT_SHELL", &[], fam::mesh::element_shell),
    e(
        "*ELEMENT_SHELL_THICKNESS",
        &[],
        fam::mesh::element_shell_thickness,
    ),
    e("*ELEMENT_MASS", &[], fam::mesh::element_mass),
    e("*PART", &[], fam::mesh::part),
    e("*SECTION_SHELL", &["TITLE"], fam::mesh::section_shell),
    e("*HOURGLASS", &["TITLE"], fam::mesh::hourglass),
    // Materials and curves.
    e("*MAT_ELASTIC", &["TITLE"], fam::materials::elastic),
    e("*MAT_001", &["TITLE"], fam::materials::elastic),
    e(
        "*MAT_PLASTIC_KINEMATIC",
        &["TITLE"],
        fam::materials::plastic_kinematic,
    ),
    e("*MAT_003", &["TITLE"], fam::materials::plastic_kinematic),
    e(
        "*MAT_PIECEWISE_LINEAR_PLASTICITY",
        &["TITLE"],
        fam::materials::piecewise,
    ),
    e("*MAT_024", &["TITLE"], fam::materials::piecewise),
    e("*MAT_RIGID", &["TITLE"], fam::materials::rigid),
    e("*MAT_020", &["TITLE"], fam::materials::rigid),
    e("*DEFINE_CURVE", &["TITLE"], fam::materials::define_curve),
    // Sets.
    e(
        "*SET_NODE",
        &["LIST", "TITLE", "GENERATE"],
        fam::sets::node_set,
    ),
    e(
        "*SET_PART",
        &["LIST", "TITLE", "GENERATE"],
        fam::sets::part_set,
    ),
    // Initial and boundary conditions, loads, damping.
    e("*INITIAL_VELOCITY", &[], fam::loads::initial_velocity),
    e(
        "*INITIAL_VELOCITY_GENERATION",
        &[],
        fam::loads::initial_velocity_generation,
    ),
    e(
        "*INITIAL_VELOCITY_NODE",
        &[],
        fam::loads::initial_velocity_node,
    ),
    e("*BOUNDARY_SPC_NODE", &["ID"], fam::loads::spc),
    e("*BOUNDARY_SPC_SET", &["ID"], fam::loads::spc),
    e(
        "*BOUNDARY_PRESCRIBED_MOTION_NODE",
        &["ID"],
        fam::loads::prescribed,
    ),
    e(
        "*BOUNDARY_PRESCRIBED_MOTION_SET",
        &["ID"],
        fam::loads::prescribed,
    ),
    e(
        "*BOUNDARY_PRESCRIBED_MOTION_RIGID",
        &["ID"],
        fam::loads::prescribed,
    ),
    e("*LOAD_BODY_Z", &[], fam::loads::load_body_z),
    e("*DAMPING_GLOBAL", &[], fam::loads::damping_global),
    e(
        "*DAMPING_PART_STIFFNESS",
        &["SET"],
        fam::loads::damping_part_stiffness,
    ),
    // Walls and constraints.
    e("*RIGIDWALL_PLANAR", &["ID"], fam::walls::planar),
    e(
        "*RIGIDWALL_GEOMETRIC_CYLINDER",
        &["ID", "DISPLAY"],
        fam::walls::cylinder,
    ),
    e("*CONSTRAINED_SPOTWELD", &["ID"], fam::walls::spotweld),
    e(
        "*CONSTRAINED_GENERALIZED_WELD_SPOT",
        &["ID"],
        fam::walls::generalized_weld,
    ),
    // Contact interfaces.
    e(
        "*CONTACT_AUTOMATIC_SINGLE_SURFACE",
        &["ID", "TITLE"],
        fam::contacts::single_surface,
    ),
    e(
        "*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE",
        &["ID", "TITLE"],
        fam::contacts::surface_to_surface,
    ),
    e(
        "*CONTACT_AUTOMATIC_NODES_TO_SURFACE",
        &["ID", "TITLE"],
        fam::contacts::nodes_to_surface,
    ),
    // Controls and output requests.
    e(
        "*CONTROL_BULK_VISCOSITY",
        &[],
        fam::controls::bulk_viscosity,
    ),
    e("*CONTROL_ACCURACY", &[], fam::controls::accuracy),
    e("*CONTROL_CONTACT", &[], fam::controls::contact),
    e("*CONTROL_SHELL", &[], fam::controls::shell),
    e("*CONTROL_TERMINATION", &[], fam::controls::termination),
    e("*CONTROL_TIMESTEP", &[], fam::controls::timestep),
    e("*CONTROL_HOURGLASS", &[], fam::controls::hourglass),
    e(
        "*DATABASE_HISTORY_NODE",
        &["ID"],
        fam::controls::history_node,
    ),
    e("*DATABASE_NODOUT", &[], fam::controls::nodout),
];

/// How a keyword as written is read: a table entry with its options, an output-only or
/// sensor keyword that is skipped with a warning, or nothing (unsupported).
enum Resolved {
    Read(&'static Entry, Vec<String>),
    Skip(&'static str),
}

fn resolve(kw: &str) -> Option<Resolved> {
    let mut best: Option<(&'static Entry, Vec<String>)> = None;
    for entry in TABLE {
        let options: Vec<String> = if kw == entry.name {
            Vec::new()
        } else if let Some(rest) = kw
            .strip_prefix(entry.name)
            .and_then(|r| r.strip_prefix('_'))
        {
            let words: Vec<String> = rest.split('_').map(str::to_string).collect();
            if !words.iter().all(|w| entry.options.contains(&w.as_str())) {
                continue;
            }
            words
        } else {
            continue;
        };
        if best
            .as_ref()
            .is_none_or(|b| b.0.name.len() < entry.name.len())
        {
            best = Some((entry, options));
        }
    }
    if let Some((entry, options)) = best {
        return Some(Resolved::Read(entry, options));
    }
    let base = kw.strip_suffix("_ID").unwrap_or(kw);
    if IGNORED_KEYWORDS.contains(&base) {
        return Some(Resolved::Skip("output-only keyword"));
    }
    if kw.starts_with("*SENSOR") {
        return Some(Resolved::Skip(
            "sensor keyword (sensors switch nothing here)",
        ));
    }
    None
}

/// Parses the lines of a deck with the parameter values `overrides` (upper-case names).
fn parse_source(src: Source, overrides: &Params) -> Result<Deck> {
    let (blocks, mut warnings) = blocks(&src);
    warnings.splice(0..0, src.warnings.iter().cloned());
    let mut resolved = Vec::with_capacity(blocks.len());
    let mut unsupported: Vec<UnsupportedAt> = Vec::new();
    for b in &blocks {
        match resolve(&b.kw) {
            Some(r) => resolved.push(r),
            None => unsupported.push(UnsupportedAt {
                file: src.files[b.file].clone(),
                line: b.line,
                keyword: b.kw.clone(),
            }),
        }
    }
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
    // LS-DYNA's Belytschko-Tsay shell has no warping treatment unless *CONTROL_SHELL asks
    // for one (BWC 2, its default): a deck starts without the projection. Nor does it stop
    // on a distorted one-point shell unless NFAIL1 asks for the check.
    let mut model = ShellModel::new("");
    model.control.warping_projection = false;
    model.control.distortion_check = false;
    let mut r = Reader {
        model,
        warnings,
        params: &params,
        notes: RefCell::new(Vec::new()),
        seen: Vec::new(),
        rwpnal: 0.0,
        default_friction: crate::contact::ContactFriction::default(),
        friction_scales: Vec::new(),
    };
    let mut cards = 0;
    for (b, how) in blocks.iter().zip(resolved) {
        cards += b.cards.len();
        read_block(&mut r, &src, b, how)?;
    }
    finish(r, src, parameters, cards)
}

/// Reads one block through its parser; every card must be taken by it.
fn read_block(r: &mut Reader<'_>, src: &Source, b: &Block<'_>, how: Resolved) -> Result<()> {
    let file = src.files[b.file].as_str();
    let (entry, options) = match how {
        Resolved::Skip(why) => {
            r.warnings
                .push(format!("{file}: line {}: {why} {} ignored", b.line, b.kw));
            return Ok(());
        }
        Resolved::Read(entry, options) => (entry, options),
    };
    let notes = std::mem::take(&mut r.notes);
    let params = r.params;
    let mut kw = Kw {
        ctx: Ctx {
            file,
            keyword: b.kw.clone(),
            params,
            format: b.format,
            notes: &notes,
        },
        line: b.line,
        options,
        cards: &b.cards,
        pos: 0,
        blank: &b.blank_tail,
    };
    let result = (entry.parse)(r, &mut kw);
    let left = kw.more().then(|| {
        let c = kw.cards[kw.pos];
        let left = kw.cards.len() - kw.pos;
        kw.err(
            c.line,
            format!(
                "{left} card(s) the keyword does not take, from this line on \
                 (a keyword or file name missing above it?)"
            ),
        )
    });
    drop(kw);
    r.notes = notes;
    result?;
    if let Some(e) = left {
        return Err(e);
    }
    if !r.seen.contains(&entry.name) {
        r.seen.push(entry.name);
    }
    Ok(())
}

/// The warnings for defaults the deck did not set, and the model completed.
fn finish(
    mut r: Reader<'_>,
    src: Source,
    parameters: Vec<DeckParameter>,
    cards: usize,
) -> Result<Deck> {
    let top = &src.files[0];
    if !r.seen.contains(&"*CONTROL_TERMINATION") {
        r.warnings.push(format!(
            "{top}: no *CONTROL_TERMINATION: the run ends at the default time {:e}",
            r.model.control.end_time
        ));
    }
    let every_part_has_its_own =
        !r.model.parts.is_empty() && r.model.parts.iter().all(|p| p.hourglass != 0);
    if !r.seen.contains(&"*CONTROL_HOURGLASS") && !every_part_has_its_own {
        let h = &r.model.hourglass;
        r.warnings.push(format!(
            "{top}: no *CONTROL_HOURGLASS: the default hourglass control is used ({} form, coefficient {})",
            match h.form {
                HourglassForm::Stiffness => "stiffness",
                HourglassForm::Viscous => "viscous",
            },
            h.membrane
        ));
    }
    let notes = r.notes.into_inner();
    r.warnings.extend(notes);
    let d = r.default_friction;
    for (c, &(fsf, vsf)) in r.model.contacts.iter_mut().zip(&r.friction_scales) {
        let f = &mut c.friction;
        for (v, default, scale) in [
            (&mut f.static_coef, d.static_coef, fsf),
            (&mut f.dynamic, d.dynamic, fsf),
            (&mut f.decay, d.decay, 1.0),
            (&mut f.viscous, d.viscous, vsf),
        ] {
            if *v == 0.0 {
                *v = default;
            }
            *v *= scale;
        }
    }
    if r.rwpnal > 0.0 {
        for w in &mut r.model.walls {
            w.method = WallMethod::Penalty {
                alpha: r.rwpnal,
                damping: 0.0,
            };
        }
    }
    Ok(Deck {
        model: r.model,
        warnings: r.warnings,
        parameters,
        cards,
        source: src,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keywords_resolve_with_their_options_only() {
        let read = |kw: &str| match resolve(kw) {
            Some(Resolved::Read(e, o)) => Some((e.name, o)),
            _ => None,
        };
        assert_eq!(
            read("*RIGIDWALL_GEOMETRIC_CYLINDER_DISPLAY_ID"),
            Some((
                "*RIGIDWALL_GEOMETRIC_CYLINDER",
                vec!["DISPLAY".to_string(), "ID".to_string()]
            ))
        );
        assert_eq!(read("*SET_PART_LIST_GENERATE").unwrap().0, "*SET_PART");
        assert_eq!(
            read("*ELEMENT_SHELL_THICKNESS").unwrap().0,
            "*ELEMENT_SHELL_THICKNESS"
        );
        assert_eq!(
            read("*MAT_PLASTIC_KINEMATIC_TITLE").unwrap().0,
            "*MAT_PLASTIC_KINEMATIC"
        );
        assert!(read("*ELEMENT_SHELL_BETA").is_none());
        assert!(read("*RIGIDWALL_GEOMETRIC_CYLINDER_MOTION").is_none());
        assert!(matches!(
            resolve("*DATABASE_RBDOUT"),
            Some(Resolved::Skip(_))
        ));
        assert!(matches!(
            resolve("*SENSOR_DEFINE_FORCE"),
            Some(Resolved::Skip(_))
        ));
        assert_eq!(
            read("*CONTACT_AUTOMATIC_SINGLE_SURFACE_ID").unwrap().0,
            "*CONTACT_AUTOMATIC_SINGLE_SURFACE"
        );
        assert!(resolve("*CONTACT_AUTOMATIC_SINGLE_SURFACE_MPP").is_none());
        assert!(resolve("*CONTACT_SINGLE_SURFACE").is_none());
        // Every table name is unique.
        for (i, a) in TABLE.iter().enumerate() {
            assert!(
                TABLE[i + 1..].iter().all(|b| b.name != a.name),
                "{}",
                a.name
            );
        }
    }
}
