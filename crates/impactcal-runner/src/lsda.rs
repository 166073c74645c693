//! LSDA, the container of LS-DYNA's `binout` files: a tree of directories holding typed
//! arrays.
//!
//! What is read (and everything else is refused with [`RunnerError::Result`], never a
//! panic):
//!
//! - the header: its length (at least 8 bytes), the sizes of the length, offset, command
//!   and type fields (1, 2, 4 or 8 bytes each), the byte order (0 big-endian, otherwise
//!   little-endian) and the floating-point format (0, IEEE 754; others are refused);
//! - the commands, each `length, code, payload` with `length` counting the whole command:
//!   `SYMBOLTABLEOFFSET` (7, first, giving the offset of the first symbol table),
//!   `BEGINSYMBOLTABLE` (5), `CD` (2, a directory path, absolute or relative with `..`),
//!   `VARIABLE` (4, a name, type, data offset and number of items), `ENDSYMBOLTABLE` (6,
//!   followed by the offset of the next symbol table, 0 for the last) and the `DATA`
//!   records (3: type, name length, name, items) the variables point to;
//! - the item types `I1 I2 I4 I8 U1 U2 U4 U8` (integers), `R4 R8` (reals); `LINK` (11)
//!   variables are listed but reading one is refused;
//! - several files as one tree: a family `binout`, `binout%001`, `binout%002`, ... (files
//!   that LS-DYNA continues past a size limit) and the per-process files `binout0000`,
//!   `binout0001`, ... of a parallel run; a variable defined in two files takes the later
//!   file's, as LS-DYNA's own reader does.
//!
//! Data is read from the files when asked for; the tree holds only names, types and
//! offsets.

use std::collections::BTreeMap;
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use crate::error::{Result, RunnerError};

const CD: u64 = 2;
const DATA: u64 = 3;
const VARIABLE: u64 = 4;
const BEGIN_SYMBOL_TABLE: u64 = 5;
const END_SYMBOL_TABLE: u64 = 6;
const SYMBOL_TABLE_OFFSET: u64 = 7;

/// The type of an LSDA variable's items.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ItemType {
    /// Signed integers of 1, 2, 4 or 8 bytes.
    Int(u8),
    /// Unsigned integers of 1, 2, 4 or 8 bytes.
    Uint(u8),
    /// IEEE reals of 4 or 8 bytes.
    Real(u8),
    /// A link to another variable (not read).
    Link,
}

impl ItemType {
    fn from_code(code: u64) -> Option<ItemType> {
        Some(match code {
            1 => ItemType::Int(1),
            2 => ItemType::Int(2),
            3 => ItemType::Int(4),
            4 => ItemType::Int(8),
            5 => ItemType::Uint(1),
            6 => ItemType::Uint(2),
            7 => ItemType::Uint(4),
            8 => ItemType::Uint(8),
            9 => ItemType::Real(4),
            10 => ItemType::Real(8),
            11 => ItemType::Link,
            _ => return None,
        })
    }

    /// Bytes per item.
    pub fn size(self) -> u64 {
        match self {
            ItemType::Int(s) | ItemType::Uint(s) | ItemType::Real(s) => u64::from(s),
            ItemType::Link => 1,
        }
    }
}

/// A variable: the file it is in, its type, the offset of its `DATA` record and its number
/// of items.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Variable {
    file: usize,
    /// The item type.
    pub item: ItemType,
    offset: u64,
    /// The number of items.
    pub len: u64,
}

/// A directory entry: a subdirectory or a variable.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Entry {
    /// A directory and its entries by name.
    Dir(BTreeMap<String, Entry>),
    /// A variable.
    Var(Variable),
}

/// The layout of one file: field sizes and byte order.
#[derive(Debug, Clone, Copy)]
struct Layout {
    length: u8,
    offset: u8,
    command: u8,
    typ: u8,
    big: bool,
}

/// An LSDA file (or family of files) opened: its tree of directories and variables.
#[derive(Debug)]
pub struct Lsda {
    files: Vec<(PathBuf, Layout, u64)>,
    root: Entry,
}

fn fault(path: &Path, message: String) -> RunnerError {
    RunnerError::Result {
        path: path.to_path_buf(),
        message,
    }
}

/// A reader of one file with bounds checks: every read names the offset where it failed.
struct Cursor<'a> {
    file: std::fs::File,
    path: &'a Path,
    size: u64,
    pos: u64,
}

impl Cursor<'_> {
    fn bytes(&mut self, n: u64) -> Result<Vec<u8>> {
        if n > self.size || self.pos > self.size - n {
            return Err(fault(
                self.path,
                format!(
                    "byte {}: {} bytes needed past the end of the file ({} bytes; cut short?)",
                    self.pos, n, self.size
                ),
            ));
        }
        self.file
            .seek(SeekFrom::Start(self.pos))
            .and_then(|_| {
                let mut b = vec![0u8; n as usize];
                self.file.read_exact(&mut b).map(|_| b)
            })
            .inspect(|_| self.pos += n)
            .map_err(|e| fault(self.path, format!("byte {}: {e}", self.pos)))
    }

    fn uint(&mut self, size: u8, big: bool) -> Result<u64> {
        let b = self.bytes(u64::from(size))?;
        Ok(uint(&b, big))
    }
}

fn uint(b: &[u8], big: bool) -> u64 {
    let mut v = 0u64;
    if big {
        for &x in b {
            v = (v << 8) | u64::from(x);
        }
    } else {
        for &x in b.iter().rev() {
            v = (v << 8) | u64::from(x);
        }
    }
    v
}

/// The files of the family of `path`: itself, its continuations `path%001`, ... and, when
/// its name ends in four digits (`binout0000`), its siblings that differ only in those
/// digits, in name order.
pub fn family(path: &Path) -> Vec<PathBuf> {
    let mut out = vec![path.to_path_buf()];
    let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
        return out;
    };
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let stem = name
        .len()
        .checked_sub(4)
        .filter(|&k| name.is_char_boundary(k) && name[k..].bytes().all(|b| b.is_ascii_digit()))
        .map(|k| &name[..k]);
    let Ok(listing) = std::fs::read_dir(dir) else {
        return out;
    };
    let mut names: Vec<String> = listing
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| {
            let continuation = n
                .strip_prefix(name)
                .and_then(|r| r.strip_prefix('%'))
                .is_some_and(|r| !r.is_empty() && r.bytes().all(|b| b.is_ascii_digit()));
            let sibling = stem.is_some_and(|s| {
                n.len() == name.len()
                    && n != name
                    && n.starts_with(s)
                    && n[s.len()..].bytes().all(|b| b.is_ascii_digit())
            });
            continuation || sibling
        })
        .collect();
    names.sort();
    out.extend(names.into_iter().map(|n| dir.join(n)));
    out.sort();
    out
}

impl Lsda {
    /// Opens the LSDA files `paths` as one tree (see the module docs).
    ///
    /// # Errors
    /// [`RunnerError::Io`] when a file cannot be opened; [`RunnerError::Result`] naming the
    /// file and the byte offset when its header or symbol tables are not LSDA or use a
    /// feature the reader does not cover.
    pub fn open(paths: &[PathBuf]) -> Result<Lsda> {
        if paths.is_empty() {
            return Err(RunnerError::Config {
                file: "binout".into(),
                message: "no file given".into(),
            });
        }
        let mut lsda = Lsda {
            files: Vec::new(),
            root: Entry::Dir(BTreeMap::new()),
        };
        for p in paths {
            lsda.add(p)?;
        }
        Ok(lsda)
    }

    /// The root directory's entries.
    pub fn root(&self) -> &BTreeMap<String, Entry> {
        match &self.root {
            Entry::Dir(d) => d,
            Entry::Var(_) => unreachable_dir(),
        }
    }

    /// The entry at `path` (`/nodout/metadata/ids`, or without the leading `/`).
    pub fn get(&self, path: &str) -> Option<&Entry> {
        let mut e = &self.root;
        for part in path.split('/').filter(|p| !p.is_empty()) {
            match e {
                Entry::Dir(d) => e = d.get(part)?,
                Entry::Var(_) => return None,
            }
        }
        Some(e)
    }

    fn add(&mut self, path: &Path) -> Result<()> {
        let file = std::fs::File::open(path).map_err(crate::error::io(path))?;
        let size = file.metadata().map_err(crate::error::io(path))?.len();
        let mut c = Cursor {
            file,
            path,
            size,
            pos: 0,
        };
        let h = c.bytes(8).map_err(|_| {
            fault(
                path,
                format!("{size} bytes: too short for an LSDA header (8 bytes)"),
            )
        })?;
        let sizes = [h[1], h[2], h[3], h[4]];
        if h[0] < 8 || sizes.iter().any(|s| ![1, 2, 4, 8].contains(s)) {
            return Err(fault(
                path,
                format!(
                    "byte 0: not an LSDA (binout) header: header length {}, field sizes {:?} (each must be 1, 2, 4 or 8)",
                    h[0], sizes
                ),
            ));
        }
        if h[6] != 0 {
            return Err(fault(
                path,
                format!(
                    "byte 6: floating-point format {} is not IEEE 754 (0); not supported",
                    h[6]
                ),
            ));
        }
        let lay = Layout {
            length: h[1],
            offset: h[2],
            command: h[3],
            typ: h[4],
            big: h[5] == 0,
        };
        let index = self.files.len();
        self.files.push((path.to_path_buf(), lay, size));
        c.pos = u64::from(h[0]);
        let (_, cmd) = self.command(&mut c, lay)?;
        if cmd != SYMBOL_TABLE_OFFSET {
            // A file with no symbol table holds nothing yet (a run that wrote no data).
            return Ok(());
        }
        let mut seen = std::collections::HashSet::new();
        loop {
            let at = c.pos;
            let next = c.uint(lay.offset, lay.big)?;
            if next == 0 {
                return Ok(());
            }
            if !seen.insert(next) || next >= size {
                return Err(fault(
                    path,
                    format!("byte {at}: symbol table offset {next} is past the end or loops"),
                ));
            }
            c.pos = next;
            let (_, cmd) = self.command(&mut c, lay)?;
            if cmd != BEGIN_SYMBOL_TABLE {
                return Err(fault(
                    path,
                    format!("byte {next}: command {cmd} where a symbol table begins (5)"),
                ));
            }
            let mut cwd: Vec<String> = Vec::new();
            loop {
                let start = c.pos;
                let (len, cmd) = self.command(&mut c, lay)?;
                let head = u64::from(lay.length) + u64::from(lay.command);
                let body = len.checked_sub(head).ok_or_else(|| {
                    fault(
                        path,
                        format!("byte {start}: command length {len} below its header"),
                    )
                })?;
                match cmd {
                    CD => {
                        let p = c.bytes(body)?;
                        let p = String::from_utf8_lossy(&p).into_owned();
                        change_dir(&mut cwd, &p);
                    }
                    VARIABLE => {
                        let tail =
                            u64::from(lay.typ) + u64::from(lay.offset) + u64::from(lay.length);
                        let name_len = body.checked_sub(tail).ok_or_else(|| {
                            fault(
                                path,
                                format!(
                                    "byte {start}: variable record of {len} bytes is too short"
                                ),
                            )
                        })?;
                        let name = c.bytes(name_len)?;
                        let name = String::from_utf8_lossy(&name).into_owned();
                        let code = c.uint(lay.typ, lay.big)?;
                        let offset = c.uint(lay.offset, lay.big)?;
                        let n = c.uint(lay.length, lay.big)?;
                        let item = ItemType::from_code(code).ok_or_else(|| {
                            fault(path, format!("byte {start}: variable `{name}` has type code {code} (1 to 11 are known)"))
                        })?;
                        let bytes = n
                            .checked_mul(item.size())
                            .filter(|&b| offset < size && b <= size);
                        if bytes.is_none() {
                            return Err(fault(
                                path,
                                format!(
                                    "byte {start}: variable `{name}`: {n} items at offset {offset} do not fit in the file"
                                ),
                            ));
                        }
                        self.insert(
                            &cwd,
                            name,
                            Variable {
                                file: index,
                                item,
                                offset,
                                len: n,
                            },
                        );
                    }
                    END_SYMBOL_TABLE => break,
                    other => {
                        return Err(fault(
                            path,
                            format!(
                                "byte {start}: command {other} inside a symbol table (2, 4 or 6 expected)"
                            ),
                        ));
                    }
                }
            }
        }
    }

    fn command(&self, c: &mut Cursor<'_>, lay: Layout) -> Result<(u64, u64)> {
        let len = c.uint(lay.length, lay.big)?;
        let cmd = c.uint(lay.command, lay.big)?;
        Ok((len, cmd))
    }

    fn insert(&mut self, dir: &[String], name: String, var: Variable) {
        let mut e = &mut self.root;
        for part in dir {
            let Entry::Dir(d) = e else { return };
            e = d
                .entry(part.clone())
                .or_insert_with(|| Entry::Dir(BTreeMap::new()));
            if matches!(e, Entry::Var(_)) {
                return;
            }
        }
        if let Entry::Dir(d) = e {
            d.insert(name, Entry::Var(var));
        }
    }

    /// The items of the variable at `path` as reals (integers converted exactly where they
    /// fit in 53 bits).
    ///
    /// # Errors
    /// [`RunnerError::Result`] when there is no such variable, it is a link, or its data
    /// record is not where the symbol table says (file cut short, wrong name).
    pub fn read(&self, path: &str) -> Result<Vec<f64>> {
        let fail = |m: String| {
            fault(
                &self.files.first().map(|f| f.0.clone()).unwrap_or_default(),
                m,
            )
        };
        let var = match self.get(path) {
            Some(Entry::Var(v)) => v,
            Some(Entry::Dir(_)) => {
                return Err(fail(format!("`{path}` is a directory, not a variable")));
            }
            None => return Err(fail(format!("no variable `{path}`"))),
        };
        if var.item == ItemType::Link {
            return Err(fail(format!("`{path}` is a link; links are not followed")));
        }
        let (file, lay, size) = &self.files[var.file];
        let mut c = Cursor {
            file: std::fs::File::open(file).map_err(crate::error::io(file))?,
            path: file,
            size: *size,
            pos: var.offset,
        };
        let (_, cmd) = self.command(&mut c, *lay)?;
        let code = c.uint(lay.typ, lay.big)?;
        let name_len = c.uint(1, lay.big)?;
        let name = c.bytes(name_len)?;
        let want = path.rsplit('/').next().unwrap_or(path);
        if cmd != DATA || ItemType::from_code(code) != Some(var.item) || name != want.as_bytes() {
            return Err(fault(
                file,
                format!(
                    "byte {}: the data record of `{path}` is not there (command {cmd}, type {code}, name `{}`)",
                    var.offset,
                    String::from_utf8_lossy(&name)
                ),
            ));
        }
        let b = c.bytes(var.len * var.item.size())?;
        let big = lay.big;
        let s = var.item.size() as usize;
        Ok(b.chunks_exact(s)
            .map(|x| match var.item {
                ItemType::Real(4) => {
                    let bits = uint(x, big) as u32;
                    f64::from(f32::from_bits(bits))
                }
                ItemType::Real(_) => f64::from_bits(uint(x, big)),
                ItemType::Int(_) => {
                    let v = uint(x, big);
                    let shift = 64 - 8 * s as u32;
                    (((v << shift) as i64) >> shift) as f64
                }
                _ => uint(x, big) as f64,
            })
            .collect())
    }

    /// The text of an `I1`/`U1` variable (titles, dates), trailing blanks dropped.
    ///
    /// # Errors
    /// As [`Lsda::read`].
    pub fn read_text(&self, path: &str) -> Result<String> {
        let v = self.read(path)?;
        let bytes: Vec<u8> = v.iter().map(|&x| x as i64 as u8).collect();
        Ok(String::from_utf8_lossy(&bytes).trim_end().to_string())
    }
}

fn unreachable_dir() -> &'static BTreeMap<String, Entry> {
    static EMPTY: std::sync::OnceLock<BTreeMap<String, Entry>> = std::sync::OnceLock::new();
    EMPTY.get_or_init(BTreeMap::new)
}

/// Applies a `CD` path to the current directory.
fn change_dir(cwd: &mut Vec<String>, path: &str) {
    if path.starts_with('/') {
        cwd.clear();
    }
    for part in path.split('/').filter(|p| !p.is_empty() && *p != ".") {
        if part == ".." {
            cwd.pop();
        } else {
            cwd.push(part.to_string());
        }
    }
}

/// Writes LSDA files for tests: little- or big-endian, 8-byte fields or 4-byte ones.
#[cfg(test)]
pub(crate) mod write {
    /// One variable to write: directory, name, type code and raw item bytes.
    pub struct Var<'a> {
        pub dir: &'a str,
        pub name: &'a str,
        pub code: u8,
        pub items: Vec<u8>,
        pub len: u64,
    }

    fn put(out: &mut Vec<u8>, v: u64, size: usize, big: bool) {
        let b = v.to_le_bytes();
        if big {
            out.extend(b[..size].iter().rev());
        } else {
            out.extend(&b[..size]);
        }
    }

    /// The bytes of an LSDA file with the variables `vars`, field size `w` (length and
    /// offset), one symbol table.
    pub fn file(vars: &[Var<'_>], w: usize, big: bool) -> Vec<u8> {
        let mut out = vec![8, w as u8, w as u8, 1, 1, u8::from(!big), 0, 0];
        // SYMBOLTABLEOFFSET, patched at the end.
        put(&mut out, (w + 1 + w) as u64, w, big);
        out.push(7);
        let st_at = out.len();
        put(&mut out, 0, w, big);
        let mut offsets = Vec::new();
        for v in vars {
            offsets.push(out.len() as u64);
            let len = w + 1 + 1 + 1 + v.name.len() + v.items.len();
            put(&mut out, len as u64, w, big);
            out.push(3);
            out.push(v.code);
            out.push(v.name.len() as u8);
            out.extend(v.name.as_bytes());
            out.extend(&v.items);
        }
        let st = out.len() as u64;
        put(&mut out, 0, w, big);
        out.push(5);
        for (v, &o) in vars.iter().zip(&offsets) {
            put(&mut out, (w + 1 + v.dir.len()) as u64, w, big);
            out.push(2);
            out.extend(v.dir.as_bytes());
            put(&mut out, (w + 1 + v.name.len() + 1 + w + w) as u64, w, big);
            out.push(4);
            out.extend(v.name.as_bytes());
            out.push(v.code);
            put(&mut out, o, w, big);
            put(&mut out, v.len, w, big);
        }
        put(&mut out, (w + 1 + w) as u64, w, big);
        out.push(6);
        put(&mut out, 0, w, big);
        let mut patch = Vec::new();
        put(&mut patch, st, w, big);
        out[st_at..st_at + w].copy_from_slice(&patch);
        out
    }

    /// `f64` items in the byte order.
    pub fn reals(v: &[f64], big: bool) -> Vec<u8> {
        v.iter()
            .flat_map(|x| {
                let b = x.to_bits().to_le_bytes();
                if big {
                    b.iter().rev().copied().collect::<Vec<_>>()
                } else {
                    b.to_vec()
                }
            })
            .collect()
    }

    /// `i32` items in the byte order.
    pub fn ints(v: &[i32], big: bool) -> Vec<u8> {
        v.iter()
            .flat_map(|x| {
                let b = x.to_le_bytes();
                if big {
                    b.iter().rev().copied().collect::<Vec<_>>()
                } else {
                    b.to_vec()
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::write::{Var, file, ints, reals};
    use super::*;

    #[test]
    fn both_byte_orders_and_field_sizes_read_back() {
        let dir = tempfile::tempdir().unwrap();
        for (w, big) in [(8, false), (4, true), (8, true), (4, false)] {
            let vars = [
                Var {
                    dir: "/nodout/metadata",
                    name: "ids",
                    code: 3,
                    items: ints(&[7, -3], big),
                    len: 2,
                },
                Var {
                    dir: "/nodout/d000001",
                    name: "x_velocity",
                    code: 10,
                    items: reals(&[1.5, -2.25], big),
                    len: 2,
                },
            ];
            let p = dir.path().join(format!("b{w}{big}"));
            std::fs::write(&p, file(&vars, w, big)).unwrap();
            let l = Lsda::open(&[p]).unwrap();
            assert_eq!(l.read("/nodout/metadata/ids").unwrap(), [7.0, -3.0]);
            assert_eq!(l.read("nodout/d000001/x_velocity").unwrap(), [1.5, -2.25]);
            assert!(l.read("/nodout/none").is_err());
        }
    }

    #[test]
    fn families_join_continuations_and_process_files() {
        let dir = tempfile::tempdir().unwrap();
        for n in [
            "binout",
            "binout%001",
            "binout%002",
            "binoutx",
            "b0000",
            "b0001",
            "b0002x",
        ] {
            std::fs::write(dir.path().join(n), b"").unwrap();
        }
        let names = |p: &str| -> Vec<String> {
            family(&dir.path().join(p))
                .iter()
                .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
                .collect()
        };
        assert_eq!(names("binout"), ["binout", "binout%001", "binout%002"]);
        assert_eq!(names("b0001"), ["b0000", "b0001"]);
    }
}
