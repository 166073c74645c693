//! The whitened Jacobian of a fit, held in factored form.
//!
//! With `S` channels of `T` samples (`n = S T`), the whitened Jacobian of a fit is
//! `J = [A | B]`: `A` (`n x q`) holds the dense columns, the parameters' finite differences
//! and the trigger offset `tau`; `B` the per-channel nuisance columns, channel `s`'s bias
//! (`w_s`) and gain (`w_s y_s(t - tau)`), which are zero outside that channel's `T` rows.
//! Held as dense columns, `B` alone is `2 S` vectors of length `n`: for 1,215 channels of
//! 501 samples, 2,430 columns of 4.9 MB, and a dense factorisation of `J` copies them again.
//!
//! Here `B` is never formed. Its column space is the direct sum of the channels' blocks, so
//! its orthogonal projector `P_B` is block diagonal: channel `s`'s block is `Q_s Q_s^T`, `Q_s`
//! (`T x r_s`, `r_s <= 2`) the channel's nuisance columns orthonormalised (Gram-Schmidt,
//! twice). The dense columns with `B` projected out, `A~ = (I - P_B) A`, have the thin SVD
//! `A~ = U_a S_a V_a^T`, and since `U_a` is orthogonal to every `Q_s`,
//!
//! `P_J = P_B + U_a U_a^T`,  `J = [Q_1 ... Q_S | U_a] (orthonormal basis of col J)`.
//!
//! Eliminating the nuisance coefficients (variable projection: the Schur complement of
//! `B^T B` in `J^T J`) leaves the dense coefficients of the least-squares solution,
//! `x_A = V_a S_a^-1 U_a^T y`, and their covariance for unit white noise,
//! `[(J^T J)^-1]_AA = (A~^T A~)^-1 = V_a S_a^-2 V_a^T`. Both equal the corresponding part of
//! `J^+ y` and `(J^T J)^+` to round-off when `A~` has full column rank; when it does not (a
//! parameter without effect, or a dense column inside the nuisance span), the minimum norm
//! is taken over the dense coefficients alone. Memory is `n (q + 2)` values instead of
//! `n (q + 2 S)`, and every operation below is `O(n q)`.
//!
//! Numerical rank: a column whose part independent of those before it is at most `1e-10`
//! times the largest column norm of `J` is dropped (in a channel's Gram-Schmidt), and so is
//! a singular value of `A~` at most `1e-10` times that norm.
//!
//! Every operation takes any whitened vector of length `n`: a later linear operator on the
//! whitened space (a prewhitening of coloured noise) composes with it.

use faer::Mat;

use super::linalg::dot;
use crate::error::{CalibrateError, Result};

/// Relative size below which a direction of `J` counts as numerically absent.
const RANK_TOLERANCE: f64 = 1e-10;

/// The factored whitened Jacobian of a fit (see the module docs).
#[derive(Debug, Clone)]
pub(crate) struct Jacobian {
    samples: usize,
    /// Per channel, its orthonormal nuisance basis `Q_s`, column after column (`r_s T`
    /// values).
    local: Vec<Vec<f64>>,
    /// `U_a`, `n x r_a`.
    ua: Mat<f64>,
    /// `S_a`, the `r_a` singular values kept.
    sa: Vec<f64>,
    /// `V_a`, `q x r_a`.
    va: Mat<f64>,
}

impl Jacobian {
    /// Factors `J = [A | B]` with dense columns `dense` (`q` vectors of length `n`, taken
    /// over) and per-channel columns `local`: vector `k` of `local` (length `n`) holds
    /// column `k` of every channel, channel `s`'s on its rows `s T..(s + 1) T`.
    ///
    /// # Errors
    /// [`CalibrateError::Study`] for no column, vectors whose length is not a multiple of
    /// `samples` or differ, a non-finite entry, or an SVD that does not converge.
    pub fn new(samples: usize, dense: Vec<Vec<f64>>, local: &[&[f64]]) -> Result<Self> {
        let n = dense
            .first()
            .map(Vec::len)
            .or_else(|| local.first().map(|l| l.len()))
            .unwrap_or(0);
        let bad = |why: &str| Err(CalibrateError::study("least squares", why.to_string()));
        if n == 0 || samples == 0 || n % samples != 0 {
            return bad("no columns, or columns that are not whole channels");
        }
        if dense.iter().any(|c| c.len() != n) || local.iter().any(|c| c.len() != n) {
            return bad("columns of different lengths");
        }
        if dense
            .iter()
            .flatten()
            .chain(local.iter().copied().flatten())
            .any(|v| !v.is_finite())
        {
            return bad("a non-finite entry in the Jacobian (a run that diverged?)");
        }
        let channels = n / samples;
        let mut scale: f64 = dense.iter().map(|c| dot(c, c).sqrt()).fold(0.0, f64::max);
        for l in local {
            for ch in l.chunks(samples) {
                scale = scale.max(dot(ch, ch).sqrt());
            }
        }
        let tol = RANK_TOLERANCE * scale;
        let t = samples;
        let mut bases = Vec::with_capacity(channels);
        for s in 0..channels {
            let mut basis: Vec<f64> = Vec::with_capacity(local.len() * t);
            for l in local {
                let mut v = l[s * t..(s + 1) * t].to_vec();
                for _ in 0..2 {
                    for b in basis.chunks(t) {
                        let c = dot(b, &v);
                        v.iter_mut().zip(b).for_each(|(x, bi)| *x -= c * bi);
                    }
                }
                let norm = dot(&v, &v).sqrt();
                if norm > tol {
                    basis.extend(v.iter().map(|x| x / norm));
                }
            }
            bases.push(basis);
        }
        let q = dense.len();
        let mut a = Mat::<f64>::zeros(n, q);
        for (j, mut col) in dense.into_iter().enumerate() {
            for (s, basis) in bases.iter().enumerate() {
                let ch = &mut col[s * t..(s + 1) * t];
                for _ in 0..2 {
                    for b in basis.chunks(t) {
                        let c = dot(b, ch);
                        ch.iter_mut().zip(b).for_each(|(x, bi)| *x -= c * bi);
                    }
                }
            }
            a.col_mut(j)
                .iter_mut()
                .zip(col)
                .for_each(|(dst, v)| *dst = v);
        }
        let (ua, sa, va) = if q == 0 {
            (Mat::zeros(n, 0), Vec::new(), Mat::zeros(0, 0))
        } else {
            let svd = a
                .thin_svd()
                .map_err(|e| CalibrateError::study("least squares", format!("SVD: {e:?}")))?;
            let s_all: Vec<f64> = svd.S().column_vector().iter().copied().collect();
            let r = s_all.iter().filter(|&&x| x > tol).count();
            (
                svd.U().subcols(0, r).to_owned(),
                s_all[..r].to_vec(),
                svd.V().subcols(0, r).to_owned(),
            )
        };
        Ok(Jacobian {
            samples,
            local: bases,
            ua,
            sa,
            va,
        })
    }

    /// The numerical rank of `J`: `r_a` plus every channel's `r_s`.
    pub fn rank(&self) -> usize {
        self.sa.len()
            + self
                .local
                .iter()
                .map(|b| b.len() / self.samples)
                .sum::<usize>()
    }

    /// `U_a^T y` (length `r_a`): the coordinates of `y` on the dense part of the basis.
    pub fn coefficients(&self, y: &[f64]) -> Vec<f64> {
        (0..self.sa.len())
            .map(|j| {
                self.ua
                    .col(j)
                    .iter()
                    .zip(y)
                    .map(|(u, v)| u * v)
                    .sum::<f64>()
            })
            .collect()
    }

    /// `U_a^T y` over channel `s`'s rows only, for `ys` that channel's `T` values: the
    /// coefficients of a vector that is zero on every other channel.
    pub fn coefficients_channel(&self, s: usize, ys: &[f64]) -> Vec<f64> {
        let r = s * self.samples..(s + 1) * self.samples;
        (0..self.sa.len())
            .map(|j| {
                self.ua
                    .col(j)
                    .iter()
                    .skip(r.start)
                    .take(r.len())
                    .zip(ys)
                    .map(|(u, v)| u * v)
                    .sum::<f64>()
            })
            .collect()
    }

    /// `P_J y = P_B y + U_a U_a^T y`, the part of `y` the columns can reproduce.
    pub fn project(&self, y: &[f64]) -> Vec<f64> {
        let t = self.samples;
        let mut out = vec![0.0; y.len()];
        for (s, basis) in self.local.iter().enumerate() {
            let (ys, os) = (&y[s * t..(s + 1) * t], &mut out[s * t..(s + 1) * t]);
            for b in basis.chunks(t) {
                let c = dot(b, ys);
                os.iter_mut().zip(b).for_each(|(o, bi)| *o += c * bi);
            }
        }
        let c = self.coefficients(y);
        for (j, cj) in c.iter().enumerate() {
            out.iter_mut()
                .zip(self.ua.col(j).iter())
                .for_each(|(o, u)| *o += cj * u);
        }
        out
    }

    /// `(I - P_J) y`, the part of `y` no change of the fitted quantities reproduces.
    pub fn unfitted(&self, y: &[f64]) -> Vec<f64> {
        let p = self.project(y);
        y.iter().zip(p).map(|(a, b)| a - b).collect()
    }

    /// `(I - P_Bs) g_s` for channel `s`'s values `g_s` of a direction that is zero on every
    /// other channel: the part of it the channel's own nuisance terms cannot reproduce.
    pub fn channel_unfitted(&self, s: usize, gs: &[f64]) -> Vec<f64> {
        let mut v = gs.to_vec();
        for b in self.local[s].chunks(self.samples) {
            let c = dot(b, gs);
            v.iter_mut().zip(b).for_each(|(x, bi)| *x -= c * bi);
        }
        v
    }

    /// The dense coefficients of the least-squares solution of `J x = y` (the parameters,
    /// then `tau`), the nuisance coefficients eliminated: `V_a S_a^-1 U_a^T y`.
    pub fn solve(&self, y: &[f64]) -> Vec<f64> {
        let c = self.coefficients(y);
        (0..self.va.nrows())
            .map(|i| {
                (0..self.sa.len())
                    .map(|j| self.va[(i, j)] * c[j] / self.sa[j])
                    .sum()
            })
            .collect()
    }

    /// The diagonal of `[(J^T J)^+]_AA = V_a S_a^-2 V_a^T`: the variances of the dense
    /// coefficients for unit white noise. A coefficient the data do not determine (one with
    /// a part in the null space of `A~`, `1 - ||V_a[i, :]||^2 > 1e-8`: a parameter without
    /// effect, or one whose column lies in the span of the others) has variance `+inf`, not
    /// the pseudo-inverse's finite value.
    pub fn variances(&self) -> Vec<f64> {
        (0..self.va.nrows())
            .map(|i| {
                let in_range: f64 = (0..self.sa.len()).map(|j| self.va[(i, j)].powi(2)).sum();
                if 1.0 - in_range > 1e-8 {
                    return f64::INFINITY;
                }
                (0..self.sa.len())
                    .map(|j| (self.va[(i, j)] / self.sa[j]).powi(2))
                    .sum()
            })
            .collect()
    }

    /// `U z` for `z` of length [`rank`](Self::rank), `U = [U_a | Q_1 ... Q_S]` the
    /// orthonormal basis of the column space: with `z ~ N(0, I)` it is `J delta` for
    /// `delta ~ N(0, (J^T J)^+)`.
    pub fn span(&self, z: &[f64]) -> Vec<f64> {
        let t = self.samples;
        let ra = self.sa.len();
        let mut out = vec![0.0; self.ua.nrows()];
        for (j, zj) in z.iter().take(ra).enumerate() {
            out.iter_mut()
                .zip(self.ua.col(j).iter())
                .for_each(|(o, u)| *o += zj * u);
        }
        let mut at = ra;
        for (s, basis) in self.local.iter().enumerate() {
            for b in basis.chunks(t) {
                let zj = z.get(at).copied().unwrap_or(0.0);
                out[s * t..(s + 1) * t]
                    .iter_mut()
                    .zip(b)
                    .for_each(|(o, bi)| *o += zj * bi);
                at += 1;
            }
        }
        out
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The dense reference: the thin SVD of the whole `n x (q + k S)` matrix, truncated at
    /// `1e-10 s_max` (what the loop did before the factored form).
    struct Dense {
        u: Mat<f64>,
        s: Vec<f64>,
        v: Mat<f64>,
    }

    impl Dense {
        fn new(cols: &[Vec<f64>]) -> Self {
            let n = cols[0].len();
            let a = Mat::from_fn(n, cols.len(), |i, j| cols[j][i]);
            let svd = a.thin_svd().unwrap();
            let s: Vec<f64> = svd.S().column_vector().iter().copied().collect();
            let r = s.iter().filter(|&&x| x > 1e-10 * s[0]).count();
            Dense {
                u: svd.U().subcols(0, r).to_owned(),
                s: s[..r].to_vec(),
                v: svd.V().subcols(0, r).to_owned(),
            }
        }
        fn ut(&self, y: &[f64]) -> Vec<f64> {
            (0..self.s.len())
                .map(|j| self.u.col(j).iter().zip(y).map(|(a, b)| a * b).sum())
                .collect()
        }
        fn project(&self, y: &[f64]) -> Vec<f64> {
            let c = self.ut(y);
            (0..y.len())
                .map(|i| (0..self.s.len()).map(|j| self.u[(i, j)] * c[j]).sum())
                .collect()
        }
        fn solve(&self, y: &[f64]) -> Vec<f64> {
            let c = self.ut(y);
            (0..self.v.nrows())
                .map(|i| {
                    (0..self.s.len())
                        .map(|j| self.v[(i, j)] * c[j] / self.s[j])
                        .sum()
                })
                .collect()
        }
        fn variances(&self) -> Vec<f64> {
            (0..self.v.nrows())
                .map(|i| {
                    (0..self.s.len())
                        .map(|j| (self.v[(i, j)] / self.s[j]).powi(2))
                        .sum()
                })
                .collect()
        }
    }

    fn normal(rng: &mut ChaCha8Rng) -> f64 {
        let u1: f64 = rng.random_range(1e-12..1.0);
        let u2: f64 = rng.random();
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }

    /// A loop-like Jacobian: `q` smooth dense columns, per channel a bias (the weights) and
    /// a gain (a pulse times the weights), weights varying over time and channel.
    fn problem(
        channels: usize,
        t: usize,
        q: usize,
        seed: u64,
    ) -> (Vec<Vec<f64>>, Vec<f64>, Vec<f64>) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let n = channels * t;
        let w: Vec<f64> = (0..n)
            .map(|i| 1.0 + 0.5 * ((i % t) as f64 / t as f64) + 0.1 * (i / t) as f64)
            .collect();
        let gain: Vec<f64> = (0..n)
            .map(|i| {
                let (s, k) = (i / t, (i % t) as f64 / t as f64);
                w[i] * ((1.0 + s as f64) * 3.0 * k).sin() * (-(k - 0.4).powi(2) * 8.0).exp()
            })
            .collect();
        let dense: Vec<Vec<f64>> = (0..q)
            .map(|j| {
                (0..n)
                    .map(|i| {
                        w[i] * (((j + 1) * (i % t)) as f64 * 0.013 + (i / t) as f64).cos()
                            + 0.01 * normal(&mut rng)
                    })
                    .collect()
            })
            .collect();
        (dense, w, gain)
    }

    fn close(a: &[f64], b: &[f64], tol: f64) {
        let scale = b.iter().map(|x| x.abs()).fold(0.0, f64::max).max(1e-300);
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= tol * scale, "{x} vs {y} (scale {scale})");
        }
    }

    /// Every operation agrees with the dense SVD of the whole matrix to round-off.
    #[test]
    fn the_factored_form_gives_the_dense_numbers() {
        for (channels, t, q, gains) in [(3, 40, 2, true), (7, 25, 4, true), (5, 30, 3, false)] {
            let (dense, w, gain) = problem(channels, t, q, channels as u64);
            let n = channels * t;
            let mut cols = dense.clone();
            for s in 0..channels {
                let mut b = vec![0.0; n];
                let mut g = vec![0.0; n];
                for k in 0..t {
                    b[s * t + k] = w[s * t + k];
                    g[s * t + k] = gain[s * t + k];
                }
                if gains {
                    cols.push(g);
                }
                cols.push(b);
            }
            let reference = Dense::new(&cols);
            let local: Vec<&[f64]> = if gains { vec![&w, &gain] } else { vec![&w] };
            let j = Jacobian::new(t, dense, &local).unwrap();
            assert_eq!(j.rank(), reference.s.len());
            let mut rng = ChaCha8Rng::seed_from_u64(9);
            let y: Vec<f64> = (0..n).map(|_| normal(&mut rng)).collect();
            close(&j.project(&y), &reference.project(&y), 1e-11);
            close(&j.solve(&y), &reference.solve(&y)[..q], 1e-10);
            close(&j.variances(), &reference.variances()[..q], 1e-10);
            let u = j.unfitted(&y);
            // (I - P_J) y is orthogonal to every column.
            for c in &cols {
                assert!(dot(c, &u).abs() <= 1e-10 * dot(c, c).sqrt() * dot(&y, &y).sqrt());
            }
            // U z has the norm of z: an orthonormal basis of the column space.
            let z: Vec<f64> = (0..j.rank()).map(|_| normal(&mut rng)).collect();
            let v = j.span(&z);
            assert!((dot(&v, &v) - dot(&z, &z)).abs() <= 1e-10 * dot(&z, &z));
            close(&j.project(&v), &v, 1e-11);
        }
    }

    /// A constant channel makes its gain column a multiple of its bias column, and a
    /// parameter without effect a zero column: both are dropped from the rank as the dense
    /// SVD drops them, and the projection is unchanged.
    #[test]
    fn dependent_columns_are_dropped_as_the_dense_svd_drops_them() {
        let (channels, t, q) = (4, 30, 3);
        let (mut dense, w, mut gain) = problem(channels, t, q, 5);
        let n = channels * t;
        for k in 0..t {
            gain[t + k] = 2.5 * w[t + k];
        }
        dense[2] = vec![0.0; n];
        let mut cols = dense.clone();
        for s in 0..channels {
            let mut b = vec![0.0; n];
            let mut g = vec![0.0; n];
            for k in 0..t {
                b[s * t + k] = w[s * t + k];
                g[s * t + k] = gain[s * t + k];
            }
            cols.push(g);
            cols.push(b);
        }
        let reference = Dense::new(&cols);
        let j = Jacobian::new(t, dense, &[&w, &gain]).unwrap();
        assert_eq!(j.rank(), reference.s.len());
        assert_eq!(j.rank(), 2 + 2 * channels - 1);
        let y: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        close(&j.project(&y), &reference.project(&y), 1e-11);
        // The parameter without effect is not determined: infinite variance, where the
        // pseudo-inverse would say 0; the others keep theirs.
        let v = j.variances();
        assert!(v[2].is_infinite());
        assert!(v[0].is_finite() && v[1].is_finite() && v[0] > 0.0);
        close(&j.solve(&y)[..2], &reference.solve(&y)[..2], 1e-10);
    }

    #[test]
    fn bad_columns_are_typed_errors() {
        assert!(Jacobian::new(10, vec![], &[]).is_err());
        assert!(Jacobian::new(10, vec![vec![1.0; 25]], &[]).is_err());
        assert!(Jacobian::new(10, vec![vec![1.0; 20]], &[&[1.0; 30]]).is_err());
        let mut c = vec![1.0; 20];
        c[3] = f64::NAN;
        let e = Jacobian::new(10, vec![c], &[]).unwrap_err();
        assert!(e.to_string().contains("non-finite"), "{e}");
    }
}
