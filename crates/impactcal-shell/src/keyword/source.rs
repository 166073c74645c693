//! The lines of a deck and of the files it includes, each with its file and line number.
//!
//! A deck file that is not UTF-8 is decoded as Latin-1 (ISO 8859-1: every byte is the code
//! point of the same value), with a warning naming the line of the first byte that is not
//! UTF-8. `*INCLUDE` is replaced by the lines of every file it names: each line up to the
//! next keyword that is not a comment or blank names one file (a name ending in ` +`
//! continues on the next line, as LS-PrePost writes long names). A name is taken relative
//! to the directory of the including file, then to each directory of the `*INCLUDE_PATH`
//! (or `*INCLUDE_PATH_RELATIVE`) cards read before it, in order; an absolute name is taken
//! as it is. Includes nest; an included file ends at its own `*END`. A file that includes
//! itself, directly or through others, is an error naming the chain.

use std::path::{Path, PathBuf};

use crate::error::{Result, ShellError};

/// One line of a deck: the index of its file in [`Source::files`], its 1-based line number
/// and its text.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Line {
    pub file: usize,
    pub line: usize,
    pub text: String,
}

/// The lines of a deck with its includes expanded, and the names of the files they came
/// from (the deck first).
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct Source {
    pub files: Vec<String>,
    pub lines: Vec<Line>,
    pub warnings: Vec<String>,
    /// Directories of `*INCLUDE_PATH` cards, in the order read.
    paths: Vec<PathBuf>,
}

/// The text of a deck file: UTF-8, else Latin-1 with a warning naming the line of the first
/// byte that is not UTF-8.
fn decode(bytes: Vec<u8>, name: &str, warnings: &mut Vec<String>) -> String {
    match String::from_utf8(bytes) {
        Ok(s) => s,
        Err(e) => {
            let bytes = e.into_bytes();
            let bad = std::str::from_utf8(&bytes)
                .err()
                .map_or(0, |u| u.valid_up_to());
            let line = 1 + bytes[..bad].iter().filter(|&&b| b == b'\n').count();
            warnings.push(format!(
                "{name}: line {line}: the file is not UTF-8 (byte 0x{:02X}); read as Latin-1",
                bytes.get(bad).copied().unwrap_or(0)
            ));
            bytes.iter().map(|&b| char::from(b)).collect()
        }
    }
}

/// The upper-case keyword of a keyword line (`*INCLUDE_PATH` gives `INCLUDE_PATH`), or
/// `None` for a data or comment line.
fn keyword_of(line: &str) -> Option<String> {
    line.strip_prefix('*')
        .map(|k| k.split_whitespace().next().unwrap_or("").to_uppercase())
}

/// The names an `*INCLUDE` or `*INCLUDE_PATH` card lists: every line up to the next keyword
/// that is not a comment or blank, with ` +` continuations joined. Each name comes with the
/// 1-based line it starts on. The iterator stops ahead of the next keyword line.
fn names<'t>(
    lines: &mut std::iter::Peekable<impl Iterator<Item = (usize, &'t str)>>,
) -> Vec<(usize, String)> {
    let mut out: Vec<(usize, String)> = Vec::new();
    let mut open = false;
    while let Some(&(i, l)) = lines.peek() {
        if l.starts_with('*') {
            break;
        }
        lines.next();
        if l.starts_with('$') || (l.trim().is_empty() && !open) {
            continue;
        }
        let (text, more) = match l.trim_end().strip_suffix(" +") {
            Some(head) => (head.to_string(), true),
            None => (l.trim_end().to_string(), false),
        };
        match out.last_mut() {
            Some(last) if open => last.1.push_str(&text),
            _ => out.push((i + 1, text)),
        }
        open = more;
    }
    for n in &mut out {
        n.1 = n.1.trim().to_string();
    }
    out
}

impl Source {
    /// The lines of the deck file `path` and of every file it includes.
    ///
    /// # Errors
    /// [`ShellError::Io`] when the deck cannot be read; [`ShellError::Keyword`] (keyword
    /// `*INCLUDE`, naming the including file and line) when an included file cannot be
    /// read or includes itself.
    pub fn from_file(path: &Path) -> Result<Source> {
        let name = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|source| ShellError::Io {
            path: name.clone(),
            source,
        })?;
        let mut src = Source::default();
        let text = decode(bytes, &name, &mut src.warnings);
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        let mut chain = vec![canonical(path)];
        src.add(&text, name, &dir, &mut chain, false)?;
        Ok(src)
    }

    /// The lines of deck text held in memory, named `name` in messages; `*INCLUDE` paths
    /// are relative to the directory of `name`.
    ///
    /// # Errors
    /// As [`Source::from_file`] for the included files.
    pub fn from_text(text: &str, name: &str) -> Result<Source> {
        let mut src = Source::default();
        let dir = Path::new(name)
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default();
        let mut chain = vec![canonical(Path::new(name))];
        src.add(text, name.to_string(), &dir, &mut chain, false)?;
        Ok(src)
    }

    /// Adds the lines of one file (`included`: stop at its `*END`, which ends only it).
    fn add(
        &mut self,
        text: &str,
        name: String,
        dir: &Path,
        chain: &mut Vec<PathBuf>,
        included: bool,
    ) -> Result<()> {
        let file = self.files.len();
        self.files.push(name.clone());
        let mut lines = text.lines().enumerate().peekable();
        while let Some((i, l)) = lines.next() {
            match keyword_of(l).as_deref() {
                Some("END") if included => return Ok(()),
                Some("INCLUDE") => {
                    let targets = names(&mut lines);
                    if targets.is_empty() {
                        return Err(ShellError::Keyword {
                            file: name,
                            line: i + 1,
                            keyword: "*INCLUDE".into(),
                            message: "no file name after the keyword".into(),
                        });
                    }
                    for (line, target) in targets {
                        self.include(&target, &name, line, dir, chain)?;
                    }
                }
                Some("INCLUDE_PATH") | Some("INCLUDE_PATH_RELATIVE") => {
                    for (_, d) in names(&mut lines) {
                        self.paths.push(dir.join(d));
                    }
                }
                _ => self.lines.push(Line {
                    file,
                    line: i + 1,
                    text: l.to_string(),
                }),
            }
        }
        Ok(())
    }

    /// Adds the lines of the file `target` included by line `line` of `from`.
    fn include(
        &mut self,
        target: &str,
        from: &str,
        line: usize,
        dir: &Path,
        chain: &mut Vec<PathBuf>,
    ) -> Result<()> {
        let err = |message: String| ShellError::Keyword {
            file: from.to_string(),
            line,
            keyword: "*INCLUDE".into(),
            message,
        };
        let first = dir.join(target);
        let path = std::iter::once(first.clone())
            .chain(self.paths.iter().map(|d| d.join(target)))
            .find(|p| p.is_file())
            .unwrap_or(first);
        let bytes = std::fs::read(&path).map_err(|e| {
            let searched = if self.paths.is_empty() {
                String::new()
            } else {
                format!(
                    " (nor in the *INCLUDE_PATH directories {})",
                    self.paths
                        .iter()
                        .map(|p| format!("`{}`", p.display()))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            };
            err(format!("cannot read `{}`: {e}{searched}", path.display()))
        })?;
        let key = canonical(&path);
        if chain.contains(&key) {
            let names: Vec<String> = chain
                .iter()
                .chain(std::iter::once(&key))
                .map(|p| p.display().to_string())
                .collect();
            return Err(err(format!(
                "the files include each other: {}",
                names.join(" -> ")
            )));
        }
        let name = path.display().to_string();
        let text = decode(bytes, &name, &mut self.warnings);
        let sub = path.parent().map(Path::to_path_buf).unwrap_or_default();
        chain.push(key);
        self.add(&text, name, &sub, chain, true)?;
        chain.pop();
        Ok(())
    }
}

/// The canonical form of a path where it exists (else the path as given), to recognise a
/// file reached by two spellings.
fn canonical(p: &Path) -> PathBuf {
    std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn include_names_run_to_the_next_keyword_and_join_continuations() {
        let text = "a.k\n$ comment\n\nlong/ +\nname.k\n  b.k  \n*NODE\n";
        let mut it = text.lines().enumerate().peekable();
        let n = names(&mut it);
        assert_eq!(
            n,
            vec![
                (1, "a.k".to_string()),
                (4, "long/name.k".to_string()),
                (6, "b.k".to_string())
            ]
        );
        assert_eq!(it.next().map(|l| l.1), Some("*NODE"));
    }
}
