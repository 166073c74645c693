//! Where the files of an ISO-MME data set live: a folder or a zip archive.

use std::io::Read;
use std::path::{Path, PathBuf};

use crate::error::{CoreError, Result};

/// The files of one data set, named by `/`-separated paths relative to the folder or archive
/// root, matched without regard to case (writers differ on `.CHN` and `.chn`).
pub(crate) enum Source {
    Folder {
        root: PathBuf,
        names: Vec<String>,
    },
    Zip {
        path: String,
        archive: zip::ZipArchive<std::io::BufReader<std::fs::File>>,
        names: Vec<String>,
    },
}

impl Source {
    /// Opens `path` (a folder, a `.mme` file or a `.zip` archive) and returns the source and
    /// the name of its `.mme` file.
    pub(crate) fn open(path: &Path) -> Result<(Source, String)> {
        let shown = path.display().to_string();
        let io = |source| CoreError::Io {
            path: shown.clone(),
            source,
        };
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        if path.is_dir() {
            let names = walk(path).map_err(io)?;
            let source = Source::Folder {
                root: path.to_path_buf(),
                names,
            };
            let mme = source.single_mme(&shown)?;
            return Ok((source, mme));
        }
        match ext.as_deref() {
            Some("mme") => {
                let root = path
                    .parent()
                    .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
                let names = walk(&root).map_err(io)?;
                let file = path
                    .file_name()
                    .map(|f| f.to_string_lossy().to_string())
                    .unwrap_or_default();
                if !path.is_file() {
                    return Err(io(std::io::Error::from(std::io::ErrorKind::NotFound)));
                }
                Ok((Source::Folder { root, names }, file))
            }
            Some("zip") => {
                let file = std::fs::File::open(path).map_err(io)?;
                let archive = zip::ZipArchive::new(std::io::BufReader::new(file)).map_err(|e| {
                    CoreError::Archive {
                        file: shown.clone(),
                        message: format!("not a readable zip archive ({e})"),
                    }
                })?;
                let names = archive
                    .file_names()
                    .filter(|n| !n.ends_with('/'))
                    .map(|n| n.replace('\\', "/"))
                    .collect();
                let source = Source::Zip {
                    path: shown.clone(),
                    archive,
                    names,
                };
                let mme = source.single_mme(&shown)?;
                Ok((source, mme))
            }
            _ => Err(CoreError::File {
                file: shown,
                message:
                    "not an ISO-MME data set (expected a folder, a .mme file or a .zip archive)"
                        .into(),
            }),
        }
    }

    fn names(&self) -> &[String] {
        match self {
            Source::Folder { names, .. } | Source::Zip { names, .. } => names,
        }
    }

    fn single_mme(&self, shown: &str) -> Result<String> {
        let found: Vec<&String> = self
            .names()
            .iter()
            .filter(|n| n.to_ascii_lowercase().ends_with(".mme"))
            .collect();
        match found.as_slice() {
            [one] => Ok((*one).clone()),
            [] => Err(CoreError::File {
                file: shown.to_string(),
                message: "holds no .mme file".into(),
            }),
            many => Err(CoreError::File {
                file: shown.to_string(),
                message: format!(
                    "holds {} .mme files ({}); name the one to read",
                    many.len(),
                    many.iter()
                        .map(|s| s.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            }),
        }
    }

    /// The stored name equal to `wanted` apart from case.
    pub(crate) fn find(&self, wanted: &str) -> Option<String> {
        self.names()
            .iter()
            .find(|n| n.eq_ignore_ascii_case(wanted))
            .cloned()
    }

    /// How to show member `name` in messages.
    pub(crate) fn display(&self, name: &str) -> String {
        match self {
            Source::Folder { root, .. } => root.join(name).display().to_string(),
            Source::Zip { path, .. } => format!("{path}!{name}"),
        }
    }

    /// The bytes of member `name`.
    pub(crate) fn read(&mut self, name: &str) -> Result<Vec<u8>> {
        let shown = self.display(name);
        match self {
            Source::Folder { root, .. } => {
                std::fs::read(root.join(name)).map_err(|source| CoreError::Io {
                    path: shown,
                    source,
                })
            }
            Source::Zip { path, archive, .. } => {
                let archive_error = |e: &dyn std::fmt::Display| CoreError::Archive {
                    file: path.clone(),
                    message: format!("member `{name}` cannot be read ({e})"),
                };
                let mut member = archive.by_name(name).map_err(|e| archive_error(&e))?;
                let mut bytes = Vec::new();
                member
                    .read_to_end(&mut bytes)
                    .map_err(|e| archive_error(&e))?;
                Ok(bytes)
            }
        }
    }
}

/// Every file below `root`, as `/`-separated relative paths, sorted.
fn walk(root: &Path) -> std::io::Result<Vec<String>> {
    let mut out = Vec::new();
    let mut stack = vec![PathBuf::new()];
    while let Some(rel) = stack.pop() {
        for entry in std::fs::read_dir(root.join(&rel))? {
            let entry = entry?;
            let name = rel.join(entry.file_name());
            if entry.file_type()?.is_dir() {
                stack.push(name);
            } else {
                let parts: Vec<String> = name
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().to_string())
                    .collect();
                out.push(parts.join("/"));
            }
        }
    }
    out.sort();
    Ok(out)
}
