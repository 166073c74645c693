//! The phase-shift search of ISO/TS 18571: the time shift of the computed curve that
//! maximises its correlation with the reference.

/// The shift found: `samples > 0` moves the computed curve left (it lagged the reference),
/// `samples < 0` moves it right; `0` when no shift correlates better than none.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Shift {
    pub samples: isize,
    pub correlation: f64,
}

/// Prefix sums of a curve and of its square.
struct Prefix {
    sum: Vec<f64>,
    sq: Vec<f64>,
}

impl Prefix {
    fn new(x: &[f64]) -> Prefix {
        let mut sum = Vec::with_capacity(x.len() + 1);
        let mut sq = Vec::with_capacity(x.len() + 1);
        let (mut s, mut q) = (0.0, 0.0);
        sum.push(0.0);
        sq.push(0.0);
        for v in x {
            s += v;
            q += v * v;
            sum.push(s);
            sq.push(q);
        }
        Prefix { sum, sq }
    }

    /// Sum and sum of squares over `a..b`.
    fn range(&self, a: usize, b: usize) -> (f64, f64) {
        (self.sum[b] - self.sum[a], self.sq[b] - self.sq[a])
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    // Four independent sums let the compiler vectorise the loop.
    let mut acc = [0.0; 4];
    let mut ca = a.chunks_exact(4);
    let mut cb = b.chunks_exact(4);
    for (x, y) in (&mut ca).zip(&mut cb) {
        for i in 0..4 {
            acc[i] += x[i] * y[i];
        }
    }
    let tail: f64 = ca
        .remainder()
        .iter()
        .zip(cb.remainder())
        .map(|(x, y)| x * y)
        .sum();
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// Pearson correlation of `t[ta..ta+n]` and `c[ca..ca+n]`; `None` when either segment is
/// constant (the correlation is undefined there and never wins).
fn correlation(
    t: &[f64],
    c: &[f64],
    pt: &Prefix,
    pc: &Prefix,
    ta: usize,
    ca: usize,
    n: usize,
) -> Option<f64> {
    let nf = n as f64;
    let (st, qt) = pt.range(ta, ta + n);
    let (sc, qc) = pc.range(ca, ca + n);
    let vt = qt - st * st / nf;
    let vc = qc - sc * sc / nf;
    if !(vt > 0.0 && vc > 0.0) {
        return None;
    }
    let cov = dot(&t[ta..ta + n], &c[ca..ca + n]) - st * sc / nf;
    Some((cov / (vt * vc).sqrt()).clamp(-1.0, 1.0))
}

/// Searches shifts of `1..=max_shift` samples in both directions, as ISO/TS 18571 and
/// objective-rating-metrics do: for each size the computed curve is first moved left, then
/// right, and a shift replaces the best so far only if it correlates strictly better, so the
/// smallest shift wins a tie and a left shift wins over a right one of the same size.
///
/// Both curves are centred on their own means first: the correlation does not change, and the
/// sums of the overlapping segments lose no precision to cancellation.
pub(crate) fn best_shift(t: &[f64], c: &[f64], max_shift: usize) -> Shift {
    let n = t.len();
    let mean = |x: &[f64]| x.iter().sum::<f64>() / x.len() as f64;
    let (mt, mc) = (mean(t), mean(c));
    let t: Vec<f64> = t.iter().map(|v| v - mt).collect();
    let c: Vec<f64> = c.iter().map(|v| v - mc).collect();
    let (pt, pc) = (Prefix::new(&t), Prefix::new(&c));
    let mut best = Shift {
        samples: 0,
        correlation: correlation(&t, &c, &pt, &pc, 0, 0, n).unwrap_or(f64::NEG_INFINITY),
    };
    for d in 1..=max_shift.min(n.saturating_sub(2)) {
        let m = n - d;
        // Left: the reference's first n - d samples against the computed curve's last.
        if let Some(r) = correlation(&t, &c, &pt, &pc, 0, d, m) {
            if r > best.correlation {
                best = Shift {
                    samples: d as isize,
                    correlation: r,
                };
            }
        }
        if let Some(r) = correlation(&t, &c, &pt, &pc, d, 0, m) {
            if r > best.correlation {
                best = Shift {
                    samples: -(d as isize),
                    correlation: r,
                };
            }
        }
    }
    best
}

#[cfg(test)]
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;

    fn pulse(n: usize, at: f64) -> Vec<f64> {
        wide(n, at, 12.0)
    }

    fn wide(n: usize, at: f64, width: f64) -> Vec<f64> {
        (0..n)
            .map(|k| (-((k as f64 - at) / width).powi(2)).exp())
            .collect()
    }

    #[test]
    fn finds_the_delay_of_a_shifted_pulse() {
        let t = pulse(400, 150.0);
        let late = pulse(400, 167.0);
        assert_eq!(best_shift(&t, &late, 80).samples, 17);
        let early = pulse(400, 140.0);
        assert_eq!(best_shift(&t, &early, 80).samples, -10);
        assert_eq!(best_shift(&t, &t, 80).samples, 0);
        // Beyond the allowed range the best admissible shift is the limit.
        let t = wide(400, 150.0, 40.0);
        assert_eq!(best_shift(&t, &wide(400, 250.0, 40.0), 40).samples, 40);
    }

    #[test]
    fn correlation_matches_the_two_pass_formula() {
        let t: Vec<f64> = (0..50).map(|k| (k as f64 * 0.3).sin() + 1e6).collect();
        let c: Vec<f64> = (0..50)
            .map(|k| (k as f64 * 0.31).cos() * 2.0 - 5e5)
            .collect();
        let r = best_shift(&t, &c, 0).correlation;
        let (mt, mc) = (t.iter().sum::<f64>() / 50.0, c.iter().sum::<f64>() / 50.0);
        let cov: f64 = t.iter().zip(&c).map(|(a, b)| (a - mt) * (b - mc)).sum();
        let vt: f64 = t.iter().map(|a| (a - mt).powi(2)).sum();
        let vc: f64 = c.iter().map(|b| (b - mc).powi(2)).sum();
        assert!((r - cov / (vt * vc).sqrt()).abs() < 1e-9);
    }
}
