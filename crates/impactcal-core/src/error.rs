//! The error type of `impactcal-core`, and the kinds of error shared by every crate.
//!
//! The method crates do not define their own variants for faults that are the same on every
//! path (a wrong length, a NaN, an option out of range, an empty input, a file that cannot be
//! read): they wrap [`CoreError`], so that a wrong-length input is
//! [`CoreError::DimensionMismatch`] whichever crate finds it. Every error of the workspace
//! says its [`ErrorKind`], which is what a program (the `impactcal` command among them)
//! needs to decide between "fix your input" and "something failed".

use std::error::Error as StdError;
use std::fmt;

/// What kind of fault an error is, for deciding what to do about it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum ErrorKind {
    /// The input is wrong (a malformed file, a wrong length, NaN, an impossible option, a
    /// request the data cannot support): the user can fix it.
    BadInput,
    /// A computation failed on valid input (a factorisation that did not converge, a
    /// singular system, a model run that failed).
    Numerical,
    /// The operating system could not read or write a file.
    Io,
}

impl fmt::Display for ErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ErrorKind::BadInput => "bad input",
            ErrorKind::Numerical => "numerical failure",
            ErrorKind::Io => "I/O error",
        })
    }
}

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
    /// An option or setting outside its admissible range.
    #[error("option `{name}` = {value}: {message}")]
    InvalidOption {
        /// The option, as the user knows it (for example `gamma` or `stopping.patience`).
        name: String,
        /// The value given, as text.
        value: String,
        /// What is required.
        message: String,
    },
    /// An input with nothing in it where at least one item is needed.
    #[error("{what} is empty")]
    Empty {
        /// The input (for example `training set (N = 0)`).
        what: String,
    },
    /// The header of a table does not hold the columns a reader needs: columns missing, or
    /// columns it does not know what to do with.
    #[error("{file}: {}", columns_message(missing, unexpected, expected))]
    Columns {
        /// The file.
        file: String,
        /// Columns required but absent.
        missing: Vec<String>,
        /// Columns present but not expected.
        unexpected: Vec<String>,
        /// Every column the reader expects, in order.
        expected: Vec<String>,
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

    /// An [`InvalidOption`](CoreError::InvalidOption) error.
    pub fn invalid_option(
        name: impl Into<String>,
        value: impl fmt::Display,
        message: impl Into<String>,
    ) -> Self {
        CoreError::InvalidOption {
            name: name.into(),
            value: value.to_string(),
            message: message.into(),
        }
    }

    /// What kind of fault this is: [`ErrorKind::Io`] for [`CoreError::Io`],
    /// [`ErrorKind::Numerical`] for a failed model run ([`CoreError::Simulation`]), and
    /// [`ErrorKind::BadInput`] for everything else.
    pub fn kind(&self) -> ErrorKind {
        match self {
            CoreError::Io { .. } => ErrorKind::Io,
            CoreError::Simulation(_) => ErrorKind::Numerical,
            _ => ErrorKind::BadInput,
        }
    }
}

/// An [`InvalidOption`](CoreError::InvalidOption) error as any error type that wraps
/// [`CoreError`] (the error of the calling function, by inference).
pub fn invalid_option<E: From<CoreError>>(
    name: impl Into<String>,
    value: impl fmt::Display,
    message: impl Into<String>,
) -> E {
    CoreError::invalid_option(name, value, message).into()
}

/// A [`DimensionMismatch`](CoreError::DimensionMismatch) error as any error type that wraps
/// [`CoreError`] (the error of the calling function, by inference).
pub fn dimension_mismatch<E: From<CoreError>>(
    what: impl Into<String>,
    expected: usize,
    found: usize,
) -> E {
    CoreError::DimensionMismatch {
        what: what.into(),
        expected,
        found,
    }
    .into()
}

/// The message of [`CoreError::Columns`]: the missing columns, then the unexpected ones.
fn columns_message(missing: &[String], unexpected: &[String], expected: &[String]) -> String {
    let list = |names: &[String]| {
        names
            .iter()
            .map(|n| format!("`{n}`"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut parts = Vec::new();
    match missing.len() {
        0 => {}
        1 => parts.push(format!("no column {}", list(missing))),
        _ => parts.push(format!("no columns {}", list(missing))),
    }
    match unexpected.len() {
        0 => {}
        1 => parts.push(format!("unexpected column {}", list(unexpected))),
        _ => parts.push(format!("unexpected columns {}", list(unexpected))),
    }
    format!(
        "{} (the header must name exactly these columns, in any order: {})",
        parts.join("; "),
        expected.join(", ")
    )
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

/// Checks that every entry of a matrix is finite, naming `what` and the first offending
/// entry (column by column) as `row r, column c (0-based)`.
///
/// # Errors
/// [`CoreError::NonFinite`].
pub fn check_finite_mat(what: &str, m: faer::MatRef<'_, f64>) -> Result<()> {
    for j in 0..m.ncols() {
        if m.col(j)
            .try_as_col_major()
            .is_some_and(|c| all_finite(c.as_slice()))
        {
            continue;
        }
        for i in 0..m.nrows() {
            let value = m[(i, j)];
            if !value.is_finite() {
                return Err(CoreError::NonFinite {
                    what: what.to_string(),
                    location: format!("row {i}, column {j} (0-based)"),
                    value,
                });
            }
        }
    }
    Ok(())
}

/// Whether every entry of `xs` is finite, without a branch per entry: `0 x` is 0 for a
/// finite `x` and NaN otherwise, summed in eight independent lanes (which the compiler
/// vectorises), so one NaN lane marks the slice.
fn all_finite(xs: &[f64]) -> bool {
    let mut lanes = [0.0f64; 8];
    let mut chunks = xs.chunks_exact(8);
    for chunk in &mut chunks {
        for (lane, x) in lanes.iter_mut().zip(chunk) {
            *lane += x * 0.0;
        }
    }
    for (lane, x) in lanes.iter_mut().zip(chunks.remainder()) {
        *lane += x * 0.0;
    }
    !lanes.iter().any(|lane| lane.is_nan())
}

/// A configuration checked once into a form that only valid values can take (the
/// `ParamGuard` pattern of linfa).
///
/// An options struct with public fields implements it with `Checked` its validated newtype;
/// the validated type implements it too (checking nothing), so a function that takes
/// `impl ParamGuard<Checked = V>` accepts either and works only with `V`.
pub trait ParamGuard {
    /// The checked form.
    type Checked;

    /// Checks the configuration without consuming it.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] naming the first option out of range.
    fn check_ref(&self) -> Result<()>;

    /// Checks the configuration and returns its checked form.
    ///
    /// # Errors
    /// As [`check_ref`](Self::check_ref).
    fn check(self) -> Result<Self::Checked>;
}

/// Defines the checked form of an options type that implements [`ParamGuard`]: a newtype
/// that only a successful check creates, read through `Deref`, serialised as the plain
/// options and checked again when deserialised, and itself a [`ParamGuard`] that checks
/// nothing (so that functions taking `impl ParamGuard<Checked = ...>` accept both forms).
///
/// `valid_options!(#[derive(...)] pub struct ValidFoo(Foo));` expects `Foo` to implement
/// `ParamGuard<Checked = ValidFoo>` with `check` written as `ValidFoo::checked(self)`, and
/// the caller to depend on `serde` (the newtype is serialised as the plain options).
#[macro_export]
macro_rules! valid_options {
    ($(#[$meta:meta])* $vis:vis struct $valid:ident($options:ty);) => {
        $(#[$meta])*
        $vis struct $valid($options);

        impl ::serde::Serialize for $valid {
            fn serialize<S: ::serde::Serializer>(
                &self,
                serializer: S,
            ) -> ::std::result::Result<S::Ok, S::Error> {
                ::serde::Serialize::serialize(&self.0, serializer)
            }
        }

        impl<'de> ::serde::Deserialize<'de> for $valid {
            fn deserialize<D: ::serde::Deserializer<'de>>(
                deserializer: D,
            ) -> ::std::result::Result<Self, D::Error> {
                let options = <$options as ::serde::Deserialize>::deserialize(deserializer)?;
                $valid::checked(options).map_err(::serde::de::Error::custom)
            }
        }

        impl $valid {
            /// Checks `options` ([`ParamGuard::check_ref`]) and wraps them.
            ///
            /// # Errors
            /// [`CoreError::InvalidOption`]($crate::CoreError::InvalidOption) naming the
            /// first option out of range.
            pub fn checked(options: $options) -> $crate::Result<Self> {
                $crate::ParamGuard::check_ref(&options)?;
                Ok($valid(options))
            }
        }

        impl ::std::ops::Deref for $valid {
            type Target = $options;
            fn deref(&self) -> &$options {
                &self.0
            }
        }

        impl ::std::convert::TryFrom<$options> for $valid {
            type Error = $crate::CoreError;
            fn try_from(options: $options) -> $crate::Result<Self> {
                $valid::checked(options)
            }
        }

        impl ::std::convert::From<$valid> for $options {
            fn from(valid: $valid) -> Self {
                valid.0
            }
        }

        impl $crate::ParamGuard for $valid {
            type Checked = $valid;
            fn check_ref(&self) -> $crate::Result<()> {
                Ok(())
            }
            fn check(self) -> $crate::Result<$valid> {
                Ok(self)
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_and_column_messages() {
        let io = CoreError::Io {
            path: "a.csv".into(),
            source: std::io::Error::from(std::io::ErrorKind::NotFound),
        };
        assert_eq!(io.kind(), ErrorKind::Io);
        assert_eq!(
            CoreError::invalid_option("gamma", -1.0, "must be positive").kind(),
            ErrorKind::BadInput
        );
        let e = CoreError::Columns {
            file: "p.csv".into(),
            missing: vec!["b".into()],
            unexpected: vec!["c".into(), "d".into()],
            expected: vec!["a".into(), "b".into()],
        };
        assert_eq!(
            e.to_string(),
            "p.csv: no column `b`; unexpected columns `c`, `d` (the header must name exactly \
             these columns, in any order: a, b)"
        );
        let m = faer::Mat::from_fn(2, 2, |i, j| if (i, j) == (1, 1) { f64::NAN } else { 1.0 });
        let e = check_finite_mat("points", m.as_ref()).unwrap_err();
        assert_eq!(
            e.to_string(),
            "points: non-finite value NaN at row 1, column 1 (0-based)"
        );
    }

    /// Every position of a column (the eight lanes and the remainder), contiguous or
    /// strided, and each kind of non-finite value is found and named; extreme finite
    /// values (the largest, the smallest subnormal, signed zeros) pass.
    #[test]
    fn every_non_finite_entry_is_found_and_named() {
        let finite = [f64::MAX, -f64::MAX, 4.9e-324, -0.0, 0.0, 1.0];
        for rows in 1..20 {
            let m = faer::Mat::from_fn(rows, 3, |i, j| finite[(i + j) % finite.len()]);
            assert!(check_finite_mat("v", m.as_ref()).is_ok());
            assert!(check_finite_mat("v", m.transpose().transpose()).is_ok());
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                for r in 0..rows {
                    let mut b = m.clone();
                    b[(r, 2)] = bad;
                    let strided = b.transpose().to_owned();
                    for view in [b.as_ref(), strided.transpose()] {
                        let e = check_finite_mat("v", view).unwrap_err();
                        assert!(
                            e.to_string().contains(&format!("row {r}, column 2 ")),
                            "{e}"
                        );
                    }
                }
            }
        }
    }
}
