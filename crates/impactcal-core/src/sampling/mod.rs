//! Space-filling samples of the unit cube and of a [`ParameterSpace`].
//!
//! Every method produces `n` points of `[0, 1)^dim`, one per row of an `n x dim` faer
//! matrix, reproducibly from a seed, and [`sample`] maps them affinely onto the box of a
//! parameter space (`x = lower + u (upper - lower)`,
//! [`ParameterSpace::from_unit_matrix`]).
//!
//! | [`Method`] | what | when |
//! |---|---|---|
//! | `Halton` | radical inverses in the first `dim` primes, index 0 first (the origin) | reproducing the source paper; low dimensions only (striping above ~10 dimensions at small `n`) |
//! | `ScrambledHalton` | the same with a random permutation of the digits at every digit position of every base | Halton with the correlation between high dimensions removed |
//! | `Sobol` | Sobol' sequence, Joe-Kuo D6 direction numbers, Gray-code order, index 0 first | deterministic low-discrepancy designs; `n` a power of two |
//! | `ScrambledSobol` | the same, Owen-scrambled (nested uniform scrambling) | the default for variance-based sensitivity; unbiased, replicates give error bars |
//! | `LatinHypercube` | one point per stratum `[k/n, (k+1)/n)` in every dimension, random pairing | training designs for surrogates |
//! | `SymmetricLatinHypercube` | a Latin hypercube at the cell centres whose rows come in mirrored pairs `u` and `1 - u` | initial designs of the CORS optimiser |
//! | `Random` | independent uniform points | reference |
//!
//! The generators themselves are public ([`Halton`], [`Sobol`], [`latin_hypercube`],
//! [`symmetric_latin_hypercube`]) for callers who need a point at a given index or their own
//! random number generator.
//!
//! ```
//! use impactcal_core::sampling::{sample, Method};
//! use impactcal_core::{Parameter, ParameterSpace};
//!
//! let space = ParameterSpace::new(vec![
//!     Parameter::new("t", 0.032, 0.064, 0.04)?,
//!     Parameter::new("E", 1.0e7, 1.1e7, 1.05e7)?,
//! ])?;
//! let s = sample(&space, Method::ScrambledSobol, 64, 7)?;
//! assert_eq!((s.points.nrows(), s.points.ncols()), (64, 2));
//! assert!(impactcal_core::points::to_rows(s.points.as_ref())
//!     .iter()
//!     .all(|x| space.contains(x)));
//! assert!(s.warnings.is_empty());
//! // 48 is not a power of two: the sample is made, with a warning.
//! assert_eq!(sample(&space, Method::Sobol, 48, 0)?.warnings.len(), 1);
//! # Ok::<(), impactcal_core::CoreError>(())
//! ```

mod halton;
mod latin;
mod sobol;

use std::fmt;

use faer::Mat;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::error::{CoreError, Result};
use crate::space::ParameterSpace;

pub use halton::Halton;
pub use latin::{latin_hypercube, symmetric_latin_hypercube};
pub use sobol::Sobol;

/// A sampling method; see the [module documentation](self) for what each one is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum Method {
    /// Plain Halton sequence from index 0.
    Halton,
    /// Halton with random digit permutations (the recommended Halton).
    ScrambledHalton,
    /// Plain Sobol' sequence (Joe-Kuo D6) from index 0.
    Sobol,
    /// Owen-scrambled Sobol' sequence from index 0.
    ScrambledSobol,
    /// Latin hypercube with random positions inside the strata.
    LatinHypercube,
    /// Symmetric Latin hypercube at the cell centres.
    SymmetricLatinHypercube,
    /// Independent uniform points.
    Random,
}

impl Method {
    /// Whether the method draws random numbers from the seed (the plain sequences do not).
    pub fn is_random(self) -> bool {
        !matches!(self, Method::Halton | Method::Sobol)
    }

    /// The largest dimension the method supports.
    pub fn max_dim(self) -> usize {
        match self {
            Method::Sobol | Method::ScrambledSobol => Sobol::MAX_DIM,
            Method::Halton | Method::ScrambledHalton => Halton::MAX_DIM,
            _ => usize::MAX,
        }
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Method::Halton => "plain Halton",
            Method::ScrambledHalton => "scrambled Halton",
            Method::Sobol => "plain Sobol'",
            Method::ScrambledSobol => "Owen-scrambled Sobol'",
            Method::LatinHypercube => "Latin hypercube",
            Method::SymmetricLatinHypercube => "symmetric Latin hypercube",
            Method::Random => "independent uniform",
        })
    }
}

/// Something legal but likely unintended about a requested sample.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[non_exhaustive]
pub enum SamplingWarning {
    /// A Sobol' sample whose size is not a power of two loses the balance of the sequence
    /// (every dyadic interval holding its share of points).
    SobolNotPowerOfTwo {
        /// The size asked for.
        n: usize,
        /// The nearest powers of two below and above.
        nearest: (usize, usize),
    },
}

impl fmt::Display for SamplingWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SamplingWarning::SobolNotPowerOfTwo { n, nearest } => write!(
                f,
                "a Sobol' sample of {n} points is not a power of two; its balance properties \
                 hold only for powers of two (use {} or {})",
                nearest.0, nearest.1
            ),
        }
    }
}

/// Points together with the warnings raised while making them.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// The points, one per row (`n x dim`).
    pub points: Mat<f64>,
    /// Warnings (empty when all is as recommended).
    pub warnings: Vec<SamplingWarning>,
}

/// The warnings that a sample of `n` points by `method` raises.
pub fn warnings_for(method: Method, n: usize) -> Vec<SamplingWarning> {
    let mut warnings = Vec::new();
    if matches!(method, Method::Sobol | Method::ScrambledSobol) && !n.is_power_of_two() && n > 0 {
        let above = n.next_power_of_two();
        warnings.push(SamplingWarning::SobolNotPowerOfTwo {
            n,
            nearest: (above / 2, above),
        });
    }
    warnings
}

/// The random number generator behind every seeded method: ChaCha8, whose stream is fixed
/// by its specification, so a seed gives the same points on every platform and version.
pub fn seeded_rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

/// `n` points of `[0, 1)^dim` by `method`.
///
/// The plain sequences ignore `seed`; the others are a deterministic function of it.
///
/// # Errors
/// [`CoreError::Invalid`] when `n` or `dim` is zero, when `dim` exceeds
/// [`Method::max_dim`], or when a Sobol' sample would need more than 2^32 points.
pub fn unit_sample(method: Method, n: usize, dim: usize, seed: u64) -> Result<Sample> {
    if n == 0 {
        return Err(CoreError::Invalid(
            "a sample needs at least one point".into(),
        ));
    }
    if dim == 0 {
        return Err(CoreError::Invalid(
            "a sample needs at least one dimension".into(),
        ));
    }
    if dim > method.max_dim() {
        return Err(CoreError::Invalid(format!(
            "the {method} method supports at most {} dimensions; {dim} were asked for",
            method.max_dim()
        )));
    }
    let mut rng = seeded_rng(seed);
    let points = match method {
        Method::Halton => Halton::new(dim)?.points(0, n),
        Method::ScrambledHalton => Halton::scrambled(dim, n, &mut rng)?.points(0, n),
        Method::Sobol => Sobol::new(dim)?.points(0, n)?,
        Method::ScrambledSobol => Sobol::owen_scrambled(dim, rng.random())?.points(0, n)?,
        Method::LatinHypercube => latin_hypercube(n, dim, &mut rng)?,
        Method::SymmetricLatinHypercube => symmetric_latin_hypercube(n, dim, &mut rng)?,
        Method::Random => {
            let data: Vec<f64> = (0..n * dim).map(|_| rng.random::<f64>()).collect();
            crate::points::from_row_major(n, dim, &data)?
        }
    };
    Ok(Sample {
        points,
        warnings: warnings_for(method, n),
    })
}

/// `n` points of the box of `space` by `method`: [`unit_sample`] in `space.dim()`
/// dimensions mapped by [`ParameterSpace::from_unit_matrix`].
///
/// # Errors
/// As [`unit_sample`].
pub fn sample(space: &ParameterSpace, method: Method, n: usize, seed: u64) -> Result<Sample> {
    let Sample { points, warnings } = unit_sample(method, n, space.dim(), seed)?;
    Ok(Sample {
        points: space.from_unit_matrix(points.as_ref())?,
        warnings,
    })
}

/// Largest `f64` below 1: where generators clamp values that round up to 1.
pub(crate) const BELOW_ONE: f64 = 1.0 - f64::EPSILON / 2.0;
