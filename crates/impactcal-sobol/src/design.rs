//! The Saltelli (pick-freeze) design and its row layout.

use faer::{Mat, MatRef};
use impactcal_core::ParameterSpace;
use impactcal_core::sampling::{Method, SamplingWarning, unit_sample};

use crate::error::{Result, SobolError};
use impactcal_core::error::{dimension_mismatch, invalid_option};

/// Where each model run of a Saltelli design sits: the row layout shared with SALib's
/// `sample.sobol` / `sample.saltelli` and `analyze.sobol`.
///
/// With `A` and `B` two independent `N x d` samples, `AB_i` equal to `A` with column `i`
/// taken from `B`, and `BA_i` equal to `B` with column `i` taken from `A`, the design
/// interleaves them per base row `j = 0..N` in blocks of `stride` rows:
///
/// ```text
/// row j*stride + 0            A_j
/// row j*stride + 1 + i        AB_i,j        i = 0..d
/// row j*stride + 1 + d + i    BA_i,j        i = 0..d   (second order only)
/// row j*stride + stride - 1   B_j
/// ```
///
/// so `stride = d + 2` (first and total indices, `N (d + 2)` runs) or `2d + 2` (with second
/// order, `N (2d + 2)` runs). Outputs computed by either tool on the same rows can be analysed
/// by the other.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct DesignLayout {
    n: usize,
    d: usize,
    second_order: bool,
}

impl DesignLayout {
    /// The layout of `n` base rows and `d` parameters.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`](impactcal_core::CoreError::InvalidOption) when `n < 2`
    /// or `d == 0`; [`SobolError::TooSmallForSecondOrder`] when `second_order` and `d < 2`.
    pub fn new(n: usize, d: usize, second_order: bool) -> Result<Self> {
        if d == 0 {
            return Err(invalid_option(
                "parameters",
                d,
                "a design needs at least one parameter",
            ));
        }
        if n < 2 {
            return Err(invalid_option(
                "base rows",
                n,
                "a design needs at least 2 base rows to estimate a variance",
            ));
        }
        if second_order && d < 2 {
            return Err(SobolError::TooSmallForSecondOrder {
                needs: "at least 2 parameters".into(),
                has: format!("{d}"),
            });
        }
        Ok(DesignLayout { n, d, second_order })
    }

    /// The layout that `rows` model runs of `d` parameters must have.
    ///
    /// # Errors
    /// [`SobolError::RowCount`] when `rows` is not a multiple of the stride (the message
    /// says whether the other choice of `second_order` would fit), otherwise as
    /// [`DesignLayout::new`].
    pub fn from_rows(rows: usize, d: usize, second_order: bool) -> Result<Self> {
        if d == 0 {
            return Err(invalid_option(
                "parameters",
                d,
                "a design needs at least one parameter",
            ));
        }
        let stride = if second_order { 2 * d + 2 } else { d + 2 };
        if rows % stride != 0 || rows == 0 {
            let other = if second_order { d + 2 } else { 2 * d + 2 };
            let hint = if rows > 0 && rows % other == 0 {
                format!(
                    "; it fits {} second order ({} base rows of {other})",
                    if second_order {
                        "a design without"
                    } else {
                        "a design with"
                    },
                    rows / other
                )
            } else {
                String::new()
            };
            return Err(SobolError::RowCount {
                rows,
                d,
                detail: format!(
                    "expected a multiple of {stride} (N x ({}){}){hint}",
                    if second_order { "2d + 2" } else { "d + 2" },
                    if second_order {
                        ", with second order"
                    } else {
                        ""
                    },
                ),
            });
        }
        DesignLayout::new(rows / stride, d, second_order)
    }

    /// Base rows `N`.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Parameters `d`.
    pub fn d(&self) -> usize {
        self.d
    }

    /// Whether the design has the `BA_i` blocks for second-order indices.
    pub fn second_order(&self) -> bool {
        self.second_order
    }

    /// Rows per base row: `d + 2`, or `2d + 2` with second order.
    pub fn stride(&self) -> usize {
        if self.second_order {
            2 * self.d + 2
        } else {
            self.d + 2
        }
    }

    /// Total model runs `N * stride`.
    pub fn rows(&self) -> usize {
        self.n * self.stride()
    }

    /// Row of `A_j`.
    pub fn a_row(&self, j: usize) -> usize {
        j * self.stride()
    }

    /// Row of `B_j`.
    pub fn b_row(&self, j: usize) -> usize {
        j * self.stride() + self.stride() - 1
    }

    /// Row of `AB_i,j` (A with parameter `i` from B).
    pub fn ab_row(&self, j: usize, i: usize) -> usize {
        j * self.stride() + 1 + i
    }

    /// Row of `BA_i,j` (B with parameter `i` from A); meaningful with second order only.
    pub fn ba_row(&self, j: usize, i: usize) -> usize {
        j * self.stride() + 1 + self.d + i
    }

    /// The design rows (`rows() x d`, one model run per row) assembled from the two base
    /// samples `a` and `b` (`N x d` each, one point per row).
    ///
    /// # Errors
    /// [`CoreError::DimensionMismatch`](impactcal_core::CoreError::DimensionMismatch) when
    /// `a` or `b` is not `N x d`.
    pub fn assemble(&self, a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Result<Mat<f64>> {
        for (name, m) in [("A", a), ("B", b)] {
            if m.nrows() != self.n || m.ncols() != self.d {
                return Err(dimension_mismatch(
                    format!("shape of base sample {name} (rows x parameters)"),
                    self.n * self.d,
                    m.nrows() * m.ncols(),
                ));
            }
        }
        let d = self.d;
        let mut data = Vec::with_capacity(self.rows() * d);
        for j in 0..self.n {
            let ra: Vec<f64> = a.row(j).iter().copied().collect();
            let rb: Vec<f64> = b.row(j).iter().copied().collect();
            data.extend_from_slice(&ra);
            for i in 0..d {
                data.extend(
                    ra.iter()
                        .enumerate()
                        .map(|(k, &x)| if k == i { rb[k] } else { x }),
                );
            }
            if self.second_order {
                for i in 0..d {
                    data.extend(
                        rb.iter()
                            .enumerate()
                            .map(|(k, &x)| if k == i { ra[k] } else { x }),
                    );
                }
            }
            data.extend_from_slice(&rb);
        }
        Ok(impactcal_core::points::from_row_major(
            self.rows(),
            d,
            &data,
        )?)
    }

    /// Checks that `points` (`rows() x d`, one model run per row) has the pick-freeze
    /// structure of this layout: every `AB_i` row
    /// equals its `A` row except in parameter `i`, where it equals the `B` row, and likewise
    /// for `BA_i`. This catches parameter files whose rows were shuffled, truncated or made
    /// for another layout (outputs are matched to parameters by row position only).
    ///
    /// Values are compared with a relative tolerance of 1e-9, so designs written to CSV with
    /// 10 or more significant digits pass.
    ///
    /// # Errors
    /// [`CoreError::DimensionMismatch`](impactcal_core::CoreError::DimensionMismatch) for a
    /// wrong shape; [`SobolError::DesignStructure`] naming the first row and parameter that
    /// break the pattern.
    pub fn check_points(&self, points: MatRef<'_, f64>) -> Result<()> {
        if points.nrows() != self.rows() || points.ncols() != self.d {
            return Err(dimension_mismatch(
                format!(
                    "parameter matrix shape (rows x parameters) for {} base rows",
                    self.n
                ),
                self.rows() * self.d,
                points.nrows() * points.ncols(),
            ));
        }
        let same = |x: f64, y: f64| (x - y).abs() <= 1e-9 * x.abs().max(y.abs());
        let row = |r: usize| -> Vec<f64> { points.row(r).iter().copied().collect() };
        for j in 0..self.n {
            let (a, b) = (row(self.a_row(j)), row(self.b_row(j)));
            let (a, b) = (a.as_slice(), b.as_slice());
            let mut blocks = vec![("AB", a, b, 0)];
            if self.second_order {
                blocks.push(("BA", b, a, self.d));
            }
            for (name, base, donor, offset) in blocks {
                for i in 0..self.d {
                    let row = j * self.stride() + 1 + offset + i;
                    let r: Vec<f64> = points.row(row).iter().copied().collect();
                    for k in 0..self.d {
                        let (expected, source) = if k == i {
                            (donor[k], if name == "AB" { "B" } else { "A" })
                        } else {
                            (base[k], if name == "AB" { "A" } else { "B" })
                        };
                        if !same(r[k], expected) {
                            return Err(SobolError::DesignStructure {
                                row,
                                parameter: k,
                                detail: format!(
                                    "a {name}_{i} row should copy {source} row {} here ({expected}) but holds {}; \
                                     the rows are not in the Saltelli/SALib order for {} parameters{}",
                                    if source == "A" {
                                        self.a_row(j)
                                    } else {
                                        self.b_row(j)
                                    },
                                    r[k],
                                    self.d,
                                    if self.second_order {
                                        " with second order"
                                    } else {
                                        ""
                                    }
                                ),
                            });
                        }
                    }
                }
            }
        }
        Ok(())
    }
}

/// A Saltelli design generated from one of the core sampling methods, in parameter units.
///
/// The base sample is one `2d`-dimensional point set of `N` points (the recommended
/// construction: its first `d` coordinates give `A`, the last `d` give `B`), so `A` and `B`
/// are jointly low-discrepancy. With `Method::Sobol` (plain) the rows equal SALib's
/// `sample.sobol(problem, N, scramble=False)`.
#[derive(Debug, Clone, PartialEq)]
pub struct SaltelliDesign {
    /// The row layout.
    pub layout: DesignLayout,
    /// `layout.rows() x d`: one model run per row, in parameter units, in the layout's
    /// order.
    pub points: Mat<f64>,
    /// Warnings of the base sample (for example a Sobol' size that is not a power of two).
    pub warnings: Vec<SamplingWarning>,
}

impl SaltelliDesign {
    /// Generates the design of `n` base rows over `space` with `method` and `seed`.
    ///
    /// # Errors
    /// As [`DesignLayout::new`] and [`unit_sample`] (for example more than 1024 parameters
    /// with Sobol', whose table has 2048 dimensions).
    pub fn generate(
        space: &ParameterSpace,
        n: usize,
        method: Method,
        second_order: bool,
        seed: u64,
    ) -> Result<Self> {
        let d = space.dim();
        let layout = DesignLayout::new(n, d, second_order)?;
        let base = unit_sample(method, n, 2 * d, seed)?;
        let (a, b) = (base.points.subcols(0, d), base.points.subcols(d, d));
        let unit = layout.assemble(a, b)?;
        Ok(SaltelliDesign {
            layout,
            points: space.from_unit_matrix(unit.as_ref())?,
            warnings: base.warnings,
        })
    }
}
