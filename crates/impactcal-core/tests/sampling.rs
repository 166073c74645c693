//! Sampling against scipy's sequences, stratification invariants and decorrelation.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

use faer::Mat;
use impactcal_core::points::{column, row, to_rows};
use impactcal_core::sampling::{
    Halton, Method, SamplingWarning, Sobol, latin_hypercube, sample, seeded_rng,
    symmetric_latin_hypercube, unit_sample,
};
use impactcal_core::{Parameter, ParameterSpace};
use proptest::prelude::*;

/// scipy.stats.qmc.Sobol(d=2048, scramble=False): selected dimensions, points 0..64 and
/// 1000..1003, as integers x * 2^32 (tests/data/scipy_sobol_points.txt).
#[test]
fn plain_sobol_equals_scipy() {
    let text = include_str!("data/scipy_sobol_points.txt");
    let sobol = Sobol::new(2048).unwrap();
    let head = sobol.points(0, 64).unwrap();
    let tail = sobol.points(1000, 3).unwrap();
    let mut checked = 0;
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        let mut fields = line.split_whitespace();
        let (block, first) = match fields.next().unwrap() {
            "ff" => (&tail, fields.next().unwrap()),
            dim => (&head, dim),
        };
        let dim: usize = first.parse().unwrap();
        let expected: Vec<f64> = fields
            .map(|v| v.parse::<f64>().unwrap() / 4_294_967_296.0)
            .collect();
        assert_eq!(column(block.as_ref(), dim), expected, "dimension {dim}");
        checked += 1;
    }
    assert_eq!(checked, 16);
}

/// scipy.stats.qmc.Halton(d=12, scramble=False).random(8), dimensions 1, 2 and 12.
#[test]
fn plain_halton_equals_scipy() {
    let p = Halton::new(12).unwrap().points(0, 8);
    let p = p.as_ref();
    assert_eq!(
        column(p, 0),
        [0.0, 0.5, 0.25, 0.75, 0.125, 0.625, 0.375, 0.875]
    );
    let third = 1.0 / 3.0;
    let expected = [
        0.0,
        third,
        2.0 * third,
        1.0 / 9.0,
        4.0 / 9.0,
        7.0 / 9.0,
        2.0 / 9.0,
        5.0 / 9.0,
    ];
    for (x, e) in column(p, 1).iter().zip(expected) {
        assert!((x - e).abs() < 1e-15);
    }
    for (i, x) in column(p, 11).iter().enumerate() {
        assert!((x - i as f64 / 37.0).abs() < 1e-15);
    }
}

fn correlation(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        sxy += (a - mx) * (b - my);
        sxx += (a - mx) * (a - mx);
        syy += (b - my) * (b - my);
    }
    sxy / (sxx * syy).sqrt()
}

fn max_abs_correlation(p: &Mat<f64>) -> f64 {
    let cols: Vec<Vec<f64>> = (0..p.ncols()).map(|j| column(p.as_ref(), j)).collect();
    let mut worst: f64 = 0.0;
    for i in 0..cols.len() {
        for j in i + 1..cols.len() {
            worst = worst.max(correlation(&cols[i], &cols[j]).abs());
        }
    }
    worst
}

/// sobol.md §2.1: the 12-dimensional design of a 6-parameter Saltelli study at 50 points is
/// strongly correlated between bases 29 and 31 when plain, not when scrambled.
#[test]
fn scrambling_removes_halton_correlation() {
    let plain = unit_sample(Method::Halton, 50, 12, 0).unwrap().points;
    let pair = correlation(&column(plain.as_ref(), 9), &column(plain.as_ref(), 10));
    assert!(pair > 0.7, "plain Halton corr(29, 31) = {pair}");
    assert!(max_abs_correlation(&plain) > 0.7);
    // 20 dimensions: bases 67 and 71 are almost collinear in the first 50 points.
    let plain20 = unit_sample(Method::Halton, 50, 20, 0).unwrap().points;
    assert!(max_abs_correlation(&plain20) > 0.99);
    for seed in 0..5 {
        let s = unit_sample(Method::ScrambledHalton, 50, 12, seed)
            .unwrap()
            .points;
        let pair = correlation(&column(s.as_ref(), 9), &column(s.as_ref(), 10)).abs();
        assert!(pair < 0.45, "seed {seed}: scrambled corr(29, 31) = {pair}");
        let s20 = unit_sample(Method::ScrambledHalton, 50, 20, seed)
            .unwrap()
            .points;
        assert!(max_abs_correlation(&s20) < 0.6, "seed {seed}");
    }
}

fn assert_latin(p: &Mat<f64>) {
    let n = p.nrows();
    for j in 0..p.ncols() {
        let mut cells: Vec<usize> = column(p.as_ref(), j)
            .iter()
            .map(|x| (x * n as f64) as usize)
            .collect();
        cells.sort_unstable();
        assert_eq!(cells, (0..n).collect::<Vec<_>>(), "dimension {j}");
    }
}

proptest! {
    #[test]
    fn latin_hypercubes_have_one_point_per_stratum(n in 1usize..60, dim in 1usize..6, seed: u64) {
        assert_latin(&latin_hypercube(n, dim, &mut seeded_rng(seed)).unwrap());
        let s = symmetric_latin_hypercube(n, dim, &mut seeded_rng(seed)).unwrap();
        assert_latin(&s);
        for i in 0..n {
            for j in 0..dim {
                let mirrored = 1.0 - row(s.as_ref(), n - 1 - i)[j];
                prop_assert!((row(s.as_ref(), i)[j] - mirrored).abs() < 1e-12);
                // Cell centres.
                let k = row(s.as_ref(), i)[j] * n as f64 - 0.5;
                prop_assert!((k - k.round()).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn every_method_stays_in_the_box_and_is_reproducible(n in 1usize..80, seed: u64, m in 0usize..7) {
        let method = [
            Method::Halton, Method::ScrambledHalton, Method::Sobol, Method::ScrambledSobol,
            Method::LatinHypercube, Method::SymmetricLatinHypercube, Method::Random,
        ][m];
        let space = ParameterSpace::new(vec![
            Parameter::new("a", -2.0, 3.0, 0.0).unwrap(),
            Parameter::new("b", 10.0, 10.5, 10.0).unwrap(),
            Parameter::new("c", 0.0, 1.0, 0.5).unwrap(),
        ]).unwrap();
        let s = sample(&space, method, n, seed).unwrap();
        prop_assert_eq!(s.points.nrows(), n);
        prop_assert!(to_rows(s.points.as_ref()).iter().all(|x| space.contains(x) && x[1] < 10.5));
        prop_assert_eq!(&s, &sample(&space, method, n, seed).unwrap());
        let sobol = matches!(method, Method::Sobol | Method::ScrambledSobol);
        prop_assert_eq!(s.warnings.len(), usize::from(sobol && !n.is_power_of_two()));
    }
}

#[test]
fn seeds_change_random_methods_only() {
    for method in [
        Method::ScrambledHalton,
        Method::ScrambledSobol,
        Method::LatinHypercube,
        Method::Random,
    ] {
        let a = unit_sample(method, 16, 3, 1).unwrap();
        let b = unit_sample(method, 16, 3, 2).unwrap();
        assert_ne!(a, b, "{method}");
    }
    assert_eq!(
        unit_sample(Method::Sobol, 16, 3, 1).unwrap(),
        unit_sample(Method::Sobol, 16, 3, 2).unwrap()
    );
}

#[test]
fn bad_requests_are_errors_and_odd_sizes_warn() {
    assert!(unit_sample(Method::Sobol, 0, 3, 0).is_err());
    assert!(unit_sample(Method::LatinHypercube, 4, 0, 0).is_err());
    assert!(unit_sample(Method::Sobol, 4, 2049, 0).is_err());
    assert!(unit_sample(Method::ScrambledHalton, 4, 1001, 0).is_err());
    let s = unit_sample(Method::ScrambledSobol, 100, 2, 0).unwrap();
    assert_eq!(
        s.warnings,
        vec![SamplingWarning::SobolNotPowerOfTwo {
            n: 100,
            nearest: (64, 128)
        }]
    );
    assert!(s.warnings[0].to_string().contains("power of two"));
}

/// Owen-scrambled Sobol' integrates a smooth function with an error far below Monte Carlo's:
/// the mean of prod_j (1 + (x_j - 1/2)) = 1 over 5 dimensions, 4096 points.
#[test]
fn scrambled_sobol_integrates_accurately() {
    for seed in 0..4 {
        let p = unit_sample(Method::ScrambledSobol, 4096, 5, seed)
            .unwrap()
            .points;
        let mean = p
            .row_iter()
            .map(|x| x.iter().map(|v| 0.5 + v).product::<f64>())
            .sum::<f64>()
            / 4096.0;
        // Monte Carlo's standard error here is about 0.0045.
        assert!((mean - 1.0).abs() < 2e-4, "seed {seed}: {mean}");
    }
}
