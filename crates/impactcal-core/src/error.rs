//! The error type of `impactcal-core`.

use std::error::Error as StdError;

/// Everything that can go wrong in the shared types: reading files, validating parameter
/// spaces and histories, and running a [`Model`](crate::Model).
///
/// File positions are 1-based: `row` counts lines of the file (the header is row 1) and
/// `column` counts comma-separated fields.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CoreError {
    /// A fault at a known position of a CSV file.
    #[error("{file}: row {row}, column {column}: {message}")]
    Csv {
        /// The file (or the name given to text parsed from memory).
        file: String,
        /// 1-based line number; the header is row 1.
        row: usize,
        /// 1-based field number.
        column: usize,
        /// What is wrong there.
        message: String,
    },
    /// A fault that concerns a whole file rather than one cell (for example an empty file).
    #[error("{file}: {message}")]
    File {
        /// The file.
        file: String,
        /// What is wrong with it.
        message: String,
    },
    /// The operating system could not read or write a file.
    #[error("{path}: {source}")]
    Io {
        /// The path involved.
        path: String,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// A parameter definition or value is invalid.
    #[error("parameter `{name}`: {message}")]
    Parameter {
        /// The parameter's name.
        name: String,
        /// What is wrong.
        message: String,
    },
    /// A length or count does not match what the context requires.
    #[error("{what}: expected {expected}, found {found}")]
    DimensionMismatch {
        /// The quantity whose size is wrong.
        what: String,
        /// The size required.
        expected: usize,
        /// The size given.
        found: usize,
    },
    /// A NaN or infinite value where finite numbers are required.
    #[error("{what}: non-finite value {value} at {location}")]
    NonFinite {
        /// The quantity.
        what: String,
        /// Where in it (for example `channel 3, sample 10`).
        location: String,
        /// The offending value.
        value: f64,
    },
    /// A channel label that is not present.
    #[error("no channel labelled `{label}` (available: {available})")]
    UnknownLabel {
        /// The label asked for.
        label: String,
        /// A short list of the labels that exist.
        available: String,
    },
    /// A fault at a known line of a text file that is not CSV (the header and sample lines
    /// of an ISO-MME data set).
    #[error("{file}: line {line}: {message}")]
    Line {
        /// The file (inside an archive: `archive.zip!member`).
        file: String,
        /// 1-based line number.
        line: usize,
        /// What is wrong there.
        message: String,
    },
    /// A file that another file refers to is absent (an ISO-MME `.chn` index naming a channel
    /// file that does not exist).
    #[error("{file}: line {line}: names `{missing}`, which does not exist")]
    MissingFile {
        /// The file holding the reference.
        file: String,
        /// 1-based line of the reference.
        line: usize,
        /// The file that is missing.
        missing: String,
    },
    /// An archive that cannot be opened or read (truncated, not a zip file, corrupt member).
    #[error("{file}: {message}")]
    Archive {
        /// The archive.
        file: String,
        /// What is wrong with it.
        message: String,
    },
    /// A channel frequency class the sampling rate cannot carry: the filter's pre-warped
    /// analogue corner `2.0833 CFC` lies at or above the Nyquist frequency `1 / (2 dt)`.
    #[error(
        "{what}: CFC {cfc} needs a sampling rate above {min_rate_hz:.0} Hz; the data are sampled at {rate_hz:.0} Hz"
    )]
    FilterClass {
        /// The data being filtered (a file or channel).
        what: String,
        /// The channel frequency class asked for.
        cfc: u32,
        /// The data's sampling rate `1 / dt`.
        rate_hz: f64,
        /// The lowest rate that carries the class.
        min_rate_hz: f64,
    },
    /// Test and model time ranges do not overlap at all.
    #[error(
        "{what}: no overlap in time: the test covers [{test_start}, {test_end}] and the model [{model_start}, {model_end}]"
    )]
    NoTimeOverlap {
        /// The channel or data compared.
        what: String,
        /// First test time.
        test_start: f64,
        /// Last test time.
        test_end: f64,
        /// First model time.
        model_start: f64,
        /// Last model time.
        model_end: f64,
    },
    /// Test time points fall outside the model's time range, so the model cannot be
    /// interpolated onto them (it is never extrapolated).
    #[error(
        "{what}: the test covers [{test_start}, {test_end}] but the model only [{model_start}, {model_end}]; restrict the comparison window to the model's range"
    )]
    OutsideModelTime {
        /// The channel or data compared.
        what: String,
        /// First test time.
        test_start: f64,
        /// Last test time.
        test_end: f64,
        /// First model time.
        model_start: f64,
        /// Last model time.
        model_end: f64,
    },
    /// A channel map names a label that the test or the model does not have.
    #[error(
        "{file}: line {line}: {side} label `{label}` is not a channel of the {side} (available: {available})"
    )]
    MapLabel {
        /// The map file.
        file: String,
        /// 1-based line of the map.
        line: usize,
        /// `test` or `model`.
        side: &'static str,
        /// The unknown label.
        label: String,
        /// A short list of the labels that exist on that side.
        available: String,
    },
    /// Input that is structurally invalid in a way not covered above.
    #[error("{0}")]
    Invalid(String),
    /// A model run failed; the source says why.
    #[error("simulation failed: {0}")]
    Simulation(#[source] Box<dyn StdError + Send + Sync>),
}

/// `Result` with [`CoreError`].
pub type Result<T, E = CoreError> = std::result::Result<T, E>;

impl CoreError {
    /// Wraps any error raised by a model's own code as [`CoreError::Simulation`].
    pub fn simulation(err: impl StdError + Send + Sync + 'static) -> Self {
        CoreError::Simulation(Box::new(err))
    }
}

/// Checks that every value is finite, naming `what` and the first offending index.
pub fn check_finite(what: &str, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(CoreError::NonFinite {
            what: what.to_string(),
            location: format!("index {i}"),
            value: values[i],
        }),
    }
}
