//! The impact-shape decomposition `Y = sum_i sigma_i phi_i g_i^T` (source paper Eq. 4.2).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::svd::{ComputeSvdVectors, svd, svd_scratch};
use faer::{Col, Mat, MatRef};
use impactcal_core::{CoreError, Histories, ParamGuard};

use crate::checks::{finite_nonempty, numerical_rank};
use crate::error::{Result, ShapesError};
use crate::randomized::{RandomizedSvd, randomized_svd};

/// How many shapes to keep.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Truncation {
    /// Every shape up to the numerical rank of the data.
    #[default]
    All,
    /// Exactly this many shapes (an error if it exceeds the numerical rank).
    Count(usize),
    /// The fewest shapes whose cumulative contribution `sum delta_i` reaches this fraction
    /// (in `(0, 1]`).
    Contribution(f64),
    /// The fewest shapes whose relative reconstruction error
    /// `||Y - Y_n||_F / ||Y||_F = sqrt(sum_{i>n} sigma_i^2 / sum_i sigma_i^2)` is at most this
    /// value (in `[0, 1)`).
    ReconstructionError(f64),
}

/// Which SVD algorithm computes the shapes.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum SvdMethod {
    /// The randomized solver when only `k` shapes are wanted ([`Truncation::Count`]) and
    /// `k + 10 <= min(m, L) / 4` with `min(m, L) >= 400`; the full thin SVD otherwise.
    #[default]
    Auto,
    /// faer's thin SVD of the whole matrix (bidiagonalisation and divide and conquer).
    Full,
    /// The randomized range finder of Halko, Martinsson and Tropp; needs
    /// [`Truncation::Count`].
    Randomized(RandomizedSvd),
}

/// Options of the decomposition.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ShapeOptions {
    /// How many shapes to keep.
    pub truncation: Truncation,
    /// Which solver to use.
    pub method: SvdMethod,
}

impl ShapeOptions {
    /// Options keeping exactly `k` shapes with the automatic solver choice.
    pub fn count(k: usize) -> Self {
        ShapeOptions {
            truncation: Truncation::Count(k),
            method: SvdMethod::Auto,
        }
    }
}

/// What the contributions `delta_i` are normalised by.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ContributionBasis {
    /// The sum of all singular values of the data (full SVD): the paper's Eq. 4.3.
    AllSingularValues,
    /// Only the computed singular values (truncated solver): an upper bound of the true
    /// contributions, exact when the discarded singular values vanish.
    ComputedOnly,
}

/// Impact shapes of a response matrix `Y` (m channels x L samples):
/// `Y = sum_i sigma_i phi_i g_i^T` with orthonormal shapes `phi_i` (columns of
/// [`shapes`](Self::shapes), m x n) and orthonormal time functions `g_i` (columns of
/// [`time_functions`](Self::time_functions), L x n), `sigma_1 >= sigma_2 >= ... > 0`.
///
/// Signs follow a fixed rule so that the same data always gives the same shapes: the entry
/// of largest magnitude of every `phi_i` is positive (the first such entry on ties), and
/// `g_i` flips with it, which leaves `Y` unchanged.
#[derive(Debug, Clone)]
pub struct ImpactShapes {
    labels: Vec<String>,
    start: f64,
    dt: f64,
    unit: String,
    sigma: Vec<f64>,
    u: Mat<f64>,
    v: Mat<f64>,
    sigma_sum: f64,
    frobenius_sq: f64,
    basis: ContributionBasis,
    rank: usize,
}

impl ImpactShapes {
    /// Decomposes histories; shapes are over its channels (labels kept), time functions over
    /// its samples.
    ///
    /// # Errors
    /// As [`ImpactShapes::from_matrix`].
    pub fn from_histories(h: &Histories, options: &ShapeOptions) -> Result<Self> {
        let samples = h.samples();
        let data = h.data();
        let y = Mat::from_fn(h.channels(), samples, |i, j| data[i * samples + j]);
        let mut s = Self::from_matrix(y.as_ref(), options)?;
        s.labels = h.labels().to_vec();
        s.start = h.start();
        s.dt = h.dt();
        s.unit = h.unit().to_string();
        Ok(s)
    }

    /// Decomposes a matrix `y` (m x L). Channels are labelled `0`, `1`, ... and the time
    /// base is `0, 1, 2, ...`.
    ///
    /// # Errors
    /// [`CoreError::Empty`] or [`CoreError::NonFinite`] for bad data;
    /// [`ShapesError::TooManyShapes`] when [`Truncation::Count`] exceeds the numerical rank;
    /// [`CoreError::InvalidOption`] for options refused by [`ParamGuard::check_ref`] (a
    /// fraction out of range, a zero count, the randomized method without a count);
    /// [`ShapesError::NoConvergence`] if the SVD fails.
    pub fn from_matrix(y: MatRef<'_, f64>, options: &ShapeOptions) -> Result<Self> {
        finite_nonempty("response matrix", y)?;
        ParamGuard::check_ref(options)?;
        let (m, l) = y.shape();
        let frobenius_sq = y.squared_norm_l2();
        let randomized = match (options.method, options.truncation) {
            (SvdMethod::Full, _) => None,
            (SvdMethod::Randomized(r), Truncation::Count(k)) => Some((r, k)),
            // Refused by the options' check above.
            (SvdMethod::Randomized(_), _) => None,
            (SvdMethod::Auto, Truncation::Count(k)) => {
                let small = m.min(l);
                (small >= 400 && k + 10 <= small / 4).then_some((RandomizedSvd::default(), k))
            }
            (SvdMethod::Auto, _) => None,
        };
        let (mut u, sigma_all, mut v, basis) = match randomized {
            Some((r, k)) => {
                if k > m.min(l) {
                    return Err(ShapesError::TooManyShapes {
                        requested: k,
                        rank: m.min(l),
                    });
                }
                let (u, s, v) = randomized_svd(y, k, &r)?;
                (u, s, v, ContributionBasis::ComputedOnly)
            }
            None => {
                let (u, s, v) = thin_svd(y)?;
                (u, s, v, ContributionBasis::AllSingularValues)
            }
        };
        let rank = numerical_rank(&sigma_all, m, l);
        let sigma_sum: f64 = sigma_all.iter().sum();
        let keep = match options.truncation {
            Truncation::All => rank,
            Truncation::Count(k) => {
                if k > rank {
                    return Err(ShapesError::TooManyShapes { requested: k, rank });
                }
                k
            }
            Truncation::Contribution(f) => {
                let mut acc = 0.0;
                let n = sigma_all[..rank]
                    .iter()
                    .position(|s| {
                        acc += s / sigma_sum;
                        acc >= f - 1e-12
                    })
                    .map_or(rank, |i| i + 1);
                n.min(rank)
            }
            Truncation::ReconstructionError(e) => {
                let mut tail: f64 = frobenius_sq;
                let mut n = rank;
                for (i, s) in sigma_all[..rank].iter().enumerate() {
                    tail -= s * s;
                    if tail.max(0.0).sqrt() <= e * frobenius_sq.sqrt() {
                        n = i + 1;
                        break;
                    }
                }
                n
            }
        }
        .max(1);
        let sigma = sigma_all[..keep].to_vec();
        fix_signs(&mut u, &mut v, keep);
        u.truncate(m, keep);
        v.truncate(l, keep);
        Ok(ImpactShapes {
            labels: (0..m).map(|i| i.to_string()).collect(),
            start: 0.0,
            dt: 1.0,
            unit: String::new(),
            sigma,
            u,
            v,
            sigma_sum,
            frobenius_sq,
            basis,
            rank,
        })
    }

    /// Number of shapes kept `n`.
    pub fn len(&self) -> usize {
        self.sigma.len()
    }

    /// Whether no shape is kept (never true for a successful decomposition).
    pub fn is_empty(&self) -> bool {
        self.sigma.is_empty()
    }

    /// Number of channels `m`.
    pub fn channels(&self) -> usize {
        self.u.nrows()
    }

    /// Number of samples `L`.
    pub fn samples(&self) -> usize {
        self.v.nrows()
    }

    /// Channel labels, one per row of the shapes.
    pub fn labels(&self) -> &[String] {
        &self.labels
    }

    /// Time of sample 0 of the time functions.
    pub fn start(&self) -> f64 {
        self.start
    }

    /// Time step of the time functions.
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// The numerical rank of the data (singular values above `max(m, L) eps sigma_1`).
    pub fn rank(&self) -> usize {
        self.rank
    }

    /// The singular values `sigma_i` kept, non-increasing.
    pub fn singular_values(&self) -> &[f64] {
        &self.sigma
    }

    /// The shapes `phi_i` as columns (m x n), orthonormal.
    pub fn shapes(&self) -> MatRef<'_, f64> {
        self.u.as_ref()
    }

    /// The time functions `g_i` as columns (L x n), orthonormal.
    pub fn time_functions(&self) -> MatRef<'_, f64> {
        self.v.as_ref()
    }

    /// Contributions `delta_i = sigma_i / sum_l sigma_l` (paper Eq. 4.3); see
    /// [`contribution_basis`](Self::contribution_basis) for the denominator.
    pub fn contributions(&self) -> Vec<f64> {
        self.sigma.iter().map(|s| s / self.sigma_sum).collect()
    }

    /// What the contributions are normalised by.
    pub fn contribution_basis(&self) -> ContributionBasis {
        self.basis
    }

    /// Energy fractions `sigma_i^2 / sum_l sigma_l^2 = sigma_i^2 / ||Y||_F^2` (exact for both
    /// solvers, since the Frobenius norm is computed from the data).
    pub fn energy_fractions(&self) -> Vec<f64> {
        self.sigma
            .iter()
            .map(|s| s * s / self.frobenius_sq)
            .collect()
    }

    /// The rank-`n` reconstruction `sum_{i<n} sigma_i phi_i g_i^T` (m x L); `n` is capped at
    /// the number of shapes kept.
    pub fn reconstruct(&self, n: usize) -> Mat<f64> {
        let n = n.min(self.len());
        let mut us = self.u.subcols(0, n).to_owned();
        for (j, s) in self.sigma[..n].iter().enumerate() {
            us.col_mut(j).iter_mut().for_each(|x| *x *= s);
        }
        &us * self.v.subcols(0, n).transpose()
    }

    /// The rank-`n` reconstruction as histories with the original labels and time base.
    ///
    /// # Errors
    /// Only if the stored labels were invalid, which a successful decomposition excludes.
    pub fn reconstruct_histories(&self, n: usize) -> Result<Histories> {
        let y = self.reconstruct(n);
        let (m, l) = y.shape();
        let data: Vec<f64> = (0..m)
            .flat_map(|i| (0..l).map(move |j| (i, j)))
            .map(|(i, j)| y[(i, j)])
            .collect();
        Ok(Histories::new(
            self.labels.clone(),
            l,
            self.dt,
            self.start,
            self.unit.clone(),
            data,
        )?)
    }
}

impl ParamGuard for ShapeOptions {
    type Checked = ShapeOptions;

    /// Checks the truncation and the solver on their own (the data are checked by the
    /// decomposition).
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] naming the option: a `shape count` of 0, a
    /// `contribution` outside `(0, 1]`, a `reconstruction error` outside `[0, 1)`, a
    /// randomized `method` without a fixed shape count, `power_iterations` of 0.
    fn check_ref(&self) -> impactcal_core::Result<()> {
        match self.truncation {
            Truncation::Count(0) => {
                return Err(CoreError::invalid_option(
                    "shape count",
                    0,
                    "the shape count must be at least 1",
                ));
            }
            Truncation::Contribution(f) if !(f > 0.0 && f <= 1.0) => {
                return Err(CoreError::invalid_option(
                    "contribution",
                    f,
                    "a cumulative contribution must lie in (0, 1]",
                ));
            }
            Truncation::ReconstructionError(e) if !(0.0..1.0).contains(&e) => {
                return Err(CoreError::invalid_option(
                    "reconstruction error",
                    e,
                    "a relative reconstruction error must lie in [0, 1)",
                ));
            }
            _ => {}
        }
        if let SvdMethod::Randomized(r) = self.method {
            if !matches!(self.truncation, Truncation::Count(_)) {
                return Err(CoreError::invalid_option(
                    "method",
                    "randomized",
                    "the randomized solver needs a fixed shape count (Truncation::Count)",
                ));
            }
            if r.power_iterations == 0 {
                return Err(CoreError::invalid_option(
                    "power_iterations",
                    0,
                    "the randomized solver needs at least one power iteration",
                ));
            }
        }
        Ok(())
    }

    fn check(self) -> impactcal_core::Result<ShapeOptions> {
        ParamGuard::check_ref(&self)?;
        Ok(self)
    }
}

/// Makes the largest-magnitude entry of each of the first `n` columns of `u` positive,
/// flipping the matching column of `v`.
/// The thin SVD `y = U diag(s) V^T` (`U` is `m x k`, `V` is `l x k`, `k = min(m, l)`,
/// `s` non-increasing), computed by faer straight into the returned matrices so that no
/// copy of the factors is made.
///
/// # Errors
/// [`ShapesError::NoConvergence`] when the iteration does not converge.
fn thin_svd(y: MatRef<'_, f64>) -> Result<(Mat<f64>, Vec<f64>, Mat<f64>)> {
    let (m, l) = y.shape();
    let k = m.min(l);
    let par = faer::get_global_parallelism();
    let mut u = Mat::<f64>::zeros(m, k);
    let mut v = Mat::<f64>::zeros(l, k);
    let mut s = Col::<f64>::zeros(k);
    let thin = ComputeSvdVectors::Thin;
    svd(
        y,
        s.as_diagonal_mut(),
        Some(u.as_mut()),
        Some(v.as_mut()),
        par,
        MemStack::new(&mut MemBuffer::new(svd_scratch::<f64>(
            m,
            l,
            thin,
            thin,
            par,
            Default::default(),
        ))),
        Default::default(),
    )
    .map_err(|_| ShapesError::NoConvergence)?;
    Ok((u, s.iter().copied().collect(), v))
}

pub(crate) fn fix_signs(u: &mut Mat<f64>, v: &mut Mat<f64>, n: usize) {
    for j in 0..n {
        let mut best = 0.0f64;
        let mut sign = 1.0;
        for &x in u.col(j).iter() {
            if x.abs() > best {
                best = x.abs();
                sign = x.signum();
            }
        }
        if sign < 0.0 {
            u.col_mut(j).iter_mut().for_each(|x| *x = -*x);
            v.col_mut(j).iter_mut().for_each(|x| *x = -*x);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each bad option is refused by `ParamGuard::check_ref` with
    /// `CoreError::InvalidOption` naming it, and the decomposition refuses it the same way.
    #[test]
    fn a_bad_value_is_refused_naming_its_key() {
        let randomized = |truncation, power_iterations| ShapeOptions {
            truncation,
            method: SvdMethod::Randomized(RandomizedSvd {
                power_iterations,
                ..RandomizedSvd::default()
            }),
        };
        let cases = [
            (ShapeOptions::count(0), "shape count"),
            (
                ShapeOptions {
                    truncation: Truncation::Contribution(1.5),
                    ..ShapeOptions::default()
                },
                "contribution",
            ),
            (
                ShapeOptions {
                    truncation: Truncation::ReconstructionError(-0.1),
                    ..ShapeOptions::default()
                },
                "reconstruction error",
            ),
            (randomized(Truncation::Contribution(0.9), 4), "method"),
            (randomized(Truncation::Count(2), 0), "power_iterations"),
        ];
        let y = Mat::from_fn(4, 6, |i, j| (i * 6 + j) as f64 + (i as f64).sin());
        for (o, key) in cases {
            match ParamGuard::check_ref(&o) {
                Err(CoreError::InvalidOption { name, .. }) => assert_eq!(name, key),
                other => panic!("{key}: {other:?}"),
            }
            match ImpactShapes::from_matrix(y.as_ref(), &o) {
                Err(ShapesError::Core(CoreError::InvalidOption { name, .. })) => {
                    assert_eq!(name, key);
                }
                other => panic!("{key}: {other:?}"),
            }
        }
        assert!(ParamGuard::check_ref(&randomized(Truncation::Count(2), 1)).is_ok());
        assert!(ParamGuard::check_ref(&ShapeOptions::default()).is_ok());
    }
}
