//! The error type of `impactcal-shell`.

use impactcal_core::CoreError;

/// Everything that can go wrong while reading a deck, building a model or running it.
///
/// Build-time errors name the entity (node, element, part, section, material id) at fault;
/// keyword errors name the line; run-time errors name the time, the cycle and the element.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ShellError {
    /// A fault in a keyword deck at a known line.
    #[error("{file}: line {line}: {keyword}: {message}")]
    Keyword {
        /// The deck file (or the name given to text parsed from memory).
        file: String,
        /// 1-based line number.
        line: usize,
        /// The keyword whose card is at fault.
        keyword: String,
        /// What is wrong.
        message: String,
    },
    /// A keyword this reader does not support (and that is not output-only).
    #[error("{file}: line {line}: unsupported keyword {keyword}")]
    UnsupportedKeyword {
        /// The deck file.
        file: String,
        /// 1-based line number of the keyword.
        line: usize,
        /// The keyword as written.
        keyword: String,
    },
    /// Several keywords this reader does not support, all listed with their lines.
    #[error("{file}: {} unsupported keywords: {}", found.len(), list_unsupported(found))]
    UnsupportedKeywords {
        /// The deck file.
        file: String,
        /// Each unsupported keyword and where it stands, in the order of the deck.
        found: Vec<UnsupportedAt>,
    },
    /// An id that is referenced but never defined (or defined twice).
    #[error("{what} {id}: {message}")]
    Reference {
        /// The kind of entity (`node`, `part`, `section`, `material`, `node set`, `curve`).
        what: &'static str,
        /// Its id.
        id: u64,
        /// What is wrong (for example `referenced by shell 12 but not defined`).
        message: String,
    },
    /// An element whose geometry cannot be used: repeated nodes, zero area, inverted.
    #[error("shell {element}: {message}")]
    Element {
        /// The element id.
        element: u64,
        /// What is wrong.
        message: String,
    },
    /// A material, section or control value out of range.
    #[error("{what}: {message}")]
    Value {
        /// Where the value belongs (for example `material 3, nu`).
        what: String,
        /// What is wrong.
        message: String,
    },
    /// The run became unstable and was stopped; nothing of it was written.
    #[error("unstable at t = {time:.6e} (cycle {cycle}), shell {element}: {cause}")]
    Unstable {
        /// Simulation time of the failing cycle.
        time: f64,
        /// The cycle number.
        cycle: u64,
        /// The id of the element at fault (the one with the largest or first faulty value).
        element: u64,
        /// What went wrong (non-finite force, inverted element, energy growth, ...).
        cause: String,
    },
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The path involved.
        path: String,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// An error of the shared types (histories, tables).
    #[error(transparent)]
    Core(#[from] CoreError),
}

/// `Result` with [`ShellError`].
pub type Result<T, E = ShellError> = std::result::Result<T, E>;

impl ShellError {
    pub(crate) fn value(what: impl Into<String>, message: impl Into<String>) -> Self {
        ShellError::Value {
            what: what.into(),
            message: message.into(),
        }
    }
}

/// An unsupported keyword and where it stands.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnsupportedAt {
    /// The file (the deck or a file it includes).
    pub file: String,
    /// 1-based line number of the keyword.
    pub line: usize,
    /// The keyword as written (upper case).
    pub keyword: String,
}

fn list_unsupported(found: &[UnsupportedAt]) -> String {
    let parts: Vec<String> = found
        .iter()
        .map(|u| format!("{} ({}: line {})", u.keyword, u.file, u.line))
        .collect();
    parts.join(", ")
}

impl ShellError {
    /// What kind of fault this is: a deck, model or value that cannot be used is bad input,
    /// an unstable run a numerical failure, a file I/O.
    pub fn kind(&self) -> impactcal_core::ErrorKind {
        use impactcal_core::ErrorKind;
        match self {
            ShellError::Core(c) => c.kind(),
            ShellError::Keyword { .. }
            | ShellError::UnsupportedKeyword { .. }
            | ShellError::UnsupportedKeywords { .. }
            | ShellError::Reference { .. }
            | ShellError::Element { .. }
            | ShellError::Value { .. } => ErrorKind::BadInput,
            ShellError::Io { .. } => ErrorKind::Io,
            ShellError::Unstable { .. } => ErrorKind::Numerical,
        }
    }
}
