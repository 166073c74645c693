//! `impactcal demo --car-pole DIR --runs RESULTS`: our car pole model's nine parameters
//! calibrated to LS-DYNA's four outputs at one design of the public parametric study, as if
//! they were a test (the scalar test form of `impactcal_calibrate::scalar`).
//!
//! DIR is the study's folder as the user keeps it (the data are GPL-3 and never shipped
//! with the project): `p9_problem.txt` (names and bounds), `p9_X.csv` (the designs),
//! `p9_Y_<output>.csv` (LS-DYNA's outputs per design) and `decks/` (the model, and
//! `MODIFICATIONS_LOG.md` with LS-DYNA's five repeats of the base design). RESULTS holds
//! our solver's outputs per design (`benches/peers/car_pole_crosscode.sh` writes it; a
//! column `row` with `base` or a row of `p9_X.csv`, and one column per output); the runs
//! there are reused, none is made here.
//!
//! The test: LS-DYNA's outputs at the target design (the base design, the box centre: the
//! mean of the five repeats). Each output's scale: the standard deviation of LS-DYNA's
//! output over the study's designs, the spread the nine parameters make, which puts the
//! four on one scale without looking at the target.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use impactcal::calibrate::scalar::{
    Scalar, ScalarCalibration, ScalarError, ScalarOptions, ScalarRuns, ScalarTest, calibrate,
};
use impactcal::core::{Parameter, ParameterSpace};
use serde::Serialize;

use crate::error::CliError;
use crate::output::write_text;

/// The study's four outputs, as its files name them.
pub const OUTPUTS: [&str; 4] = ["dmax", "fmax", "vfin", "IE"];

/// What the demo needs of the study's folder, read.
struct Study {
    names: Vec<String>,
    bounds: Vec<(f64, f64)>,
    designs: Vec<Vec<f64>>,
    lsdyna: BTreeMap<String, Vec<f64>>,
    base_repeats: BTreeMap<String, Vec<f64>>,
}

#[derive(Serialize)]
struct Summary<'a> {
    data: String,
    runs_file: String,
    target: &'a str,
    designs_reused: usize,
    rows_skipped: Vec<String>,
    test: &'a [Scalar],
    run_at_target: Option<Vec<ScalarError>>,
    calibration: &'a ScalarCalibration,
    factors: BTreeMap<String, f64>,
}

fn read(path: &Path) -> Result<String, CliError> {
    std::fs::read_to_string(path).map_err(|e| CliError::io(format!("{}: {e}", path.display())))
}

fn number(text: &str, path: &Path, line: usize) -> Result<f64, CliError> {
    let v: f64 = text.trim().parse().map_err(|_| {
        CliError::input(format!(
            "{}, line {line}: `{}` is not a number",
            path.display(),
            text.trim()
        ))
    })?;
    if !v.is_finite() {
        return Err(CliError::input(format!(
            "{}, line {line}: {v} is not a finite number",
            path.display()
        )));
    }
    Ok(v)
}

fn table(path: &Path) -> Result<Vec<Vec<f64>>, CliError> {
    read(path)?
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(i, l)| l.split(',').map(|v| number(v, path, i + 1)).collect())
        .collect()
}

/// Parameter names and their bounds.
type Problem = (Vec<String>, Vec<(f64, f64)>);

/// `p9_problem.txt`: a Python dict literal with `names` and `bounds`.
fn problem(path: &Path) -> Result<Problem, CliError> {
    #[derive(serde::Deserialize)]
    struct File {
        names: Vec<String>,
        bounds: Vec<[f64; 2]>,
    }
    let text = read(path)?.replace('\'', "\"");
    let p: File = serde_json::from_str(&text).map_err(|e| {
        CliError::input(format!(
            "{}: not the study's problem (names and bounds): {e}",
            path.display()
        ))
    })?;
    if p.names.len() != p.bounds.len() {
        return Err(CliError::input(format!(
            "{}: {} names but {} bounds",
            path.display(),
            p.names.len(),
            p.bounds.len()
        )));
    }
    Ok((p.names, p.bounds.iter().map(|b| (b[0], b[1])).collect()))
}

/// LS-DYNA's repeats of the base design: the `'<output>': value` entries (`array([v])`
/// for the energy) of the log's section `## base design output`.
fn base_repeats(path: &Path) -> Result<BTreeMap<String, Vec<f64>>, CliError> {
    let text = read(path)?;
    let mut lines = text.lines().enumerate();
    lines
        .by_ref()
        .find(|(_, l)| l.starts_with("## base design output"))
        .ok_or_else(|| {
            CliError::input(format!(
                "{}: no section `## base design output` (LS-DYNA's repeats of the base \
                 design); choose a row of p9_X.csv with --target",
                path.display()
            ))
        })?;
    let mut out: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    for (i, line) in lines.take_while(|(_, l)| !l.starts_with('#')) {
        for k in OUTPUTS {
            if let Some(rest) = line.split_once(&format!("'{k}':")).map(|s| s.1) {
                let v = rest
                    .trim()
                    .trim_start_matches("array([")
                    .trim_end_matches(',')
                    .trim_end_matches('}')
                    .trim_end_matches(')')
                    .trim_end_matches(']');
                out.entry(k.to_string())
                    .or_default()
                    .push(number(v, path, i + 1)?);
            }
        }
    }
    let counts: Vec<usize> = OUTPUTS
        .iter()
        .map(|k| out.get(*k).map_or(0, Vec::len))
        .collect();
    if counts[0] == 0 || counts.iter().any(|c| *c != counts[0]) {
        return Err(CliError::input(format!(
            "{}: the base design's repeats give {} values of {} (one per repeat expected)",
            path.display(),
            counts
                .iter()
                .map(|c| c.to_string())
                .collect::<Vec<_>>()
                .join(", "),
            OUTPUTS.join(", ")
        )));
    }
    Ok(out)
}

fn study(dir: &Path) -> Result<Study, CliError> {
    let problem_file = dir.join("p9_problem.txt");
    if !problem_file.is_file() {
        return Err(CliError::input(format!(
            "{}: no car pole study here (p9_problem.txt absent); --car-pole takes the folder \
             of the public LS-OPT car pole study (dbrizard/GSA-car-crash, LHS-330, with its \
             decks/), kept outside the project",
            dir.display()
        )));
    }
    let (names, bounds) = problem(&problem_file)?;
    let x_file = dir.join("p9_X.csv");
    let designs = table(&x_file)?;
    if let Some(i) = designs.iter().position(|r| r.len() != names.len()) {
        return Err(CliError::input(format!(
            "{}, design {i}: {} values, {} parameters",
            x_file.display(),
            designs[i].len(),
            names.len()
        )));
    }
    let mut lsdyna = BTreeMap::new();
    for k in OUTPUTS {
        let f = dir.join(format!("p9_Y_{k}.csv"));
        let col: Vec<f64> = table(&f)?.into_iter().flatten().collect();
        if col.len() != designs.len() {
            return Err(CliError::input(format!(
                "{}: {} values for {} designs",
                f.display(),
                col.len(),
                designs.len()
            )));
        }
        lsdyna.insert(k.to_string(), col);
    }
    let log = dir.join("decks").join("MODIFICATIONS_LOG.md");
    let base_repeats = if log.is_file() {
        base_repeats(&log)?
    } else {
        BTreeMap::new()
    };
    Ok(Study {
        names,
        bounds,
        designs,
        lsdyna,
        base_repeats,
    })
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

fn std_dev(v: &[f64]) -> f64 {
    let m = mean(v);
    (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt()
}

/// The design `label` (`base`: the box centre; else a row of `p9_X.csv`).
fn design(s: &Study, label: &str, what: &str) -> Result<Vec<f64>, CliError> {
    if label == "base" {
        return Ok(s.bounds.iter().map(|(a, b)| 0.5 * (a + b)).collect());
    }
    label
        .parse::<usize>()
        .ok()
        .and_then(|i| s.designs.get(i).cloned())
        .ok_or_else(|| {
            CliError::input(format!(
                "{what} `{label}`: neither `base` nor a row 0..{} of p9_X.csv",
                s.designs.len()
            ))
        })
}

/// Our runs: `row` and the four outputs per line; rows that name no design (the
/// controlled reruns of the cross-code script) are skipped and listed.
fn our_runs(s: &Study, path: &Path) -> Result<(ScalarRuns, Vec<String>, Vec<String>), CliError> {
    let text = read(path)?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let header: Vec<&str> = lines
        .next()
        .map(|(_, l)| l.split(',').map(str::trim).collect())
        .ok_or_else(|| CliError::input(format!("{}: empty", path.display())))?;
    let col = |name: &str| {
        header.iter().position(|h| *h == name).ok_or_else(|| {
            CliError::input(format!(
                "{}: no column `{name}` (it has: {})",
                path.display(),
                header.join(", ")
            ))
        })
    };
    let row_col = col("row")?;
    let cols = OUTPUTS
        .iter()
        .map(|k| col(k))
        .collect::<Result<Vec<_>, _>>()?;
    let (mut points, mut values, mut labels, mut skipped) = (vec![], vec![], vec![], vec![]);
    for (i, line) in lines {
        let cells: Vec<&str> = line.split(',').collect();
        if cells.len() != header.len() {
            return Err(CliError::input(format!(
                "{}, line {}: {} fields, the header has {}",
                path.display(),
                i + 1,
                cells.len(),
                header.len()
            )));
        }
        let label = cells[row_col].trim();
        if label != "base" && label.parse::<usize>().is_err() {
            skipped.push(label.to_string());
            continue;
        }
        if labels.iter().any(|l| l == label) {
            return Err(CliError::input(format!(
                "{}, line {}: design `{label}` given twice",
                path.display(),
                i + 1
            )));
        }
        points.push(design(
            s,
            label,
            &format!("{}, line {}", path.display(), i + 1),
        )?);
        values.push(
            cols.iter()
                .map(|&c| number(cells[c], path, i + 1))
                .collect::<Result<Vec<_>, _>>()?,
        );
        labels.push(label.to_string());
    }
    Ok((
        ScalarRuns {
            names: OUTPUTS.iter().map(|k| k.to_string()).collect(),
            points,
            values,
        },
        labels,
        skipped,
    ))
}

/// Runs the car pole demo.
pub fn run(dir: &Path, runs: Option<&Path>, target: &str, out: &Path) -> Result<(), CliError> {
    let s = study(dir)?;
    let runs_file: PathBuf = runs.map(Path::to_path_buf).ok_or_else(|| {
        CliError::input(
            "demo --car-pole: --runs RESULTS is needed: our solver's outputs per design \
             (benches/peers/car_pole_crosscode.sh N WORK writes WORK/results.csv)",
        )
    })?;
    let target_point = design(&s, target, "--target")?;
    // The nominal point is the target design: "before" is the model as given there.
    let space = ParameterSpace::new(
        s.names
            .iter()
            .zip(&s.bounds)
            .zip(&target_point)
            .map(|((n, (a, b)), x)| Parameter::new(n.clone(), *a, *b, *x))
            .collect::<Result<Vec<_>, _>>()?,
    )?;
    let test = ScalarTest::new(
        OUTPUTS
            .iter()
            .map(|k| -> Result<Scalar, CliError> {
                let y = if target == "base" {
                    let r = s.base_repeats.get(*k).ok_or_else(|| {
                        CliError::input(format!(
                            "{}: LS-DYNA's repeats of the base design are absent; choose a \
                             row of p9_X.csv with --target",
                            dir.join("decks/MODIFICATIONS_LOG.md").display()
                        ))
                    })?;
                    mean(r)
                } else {
                    let i: usize = target.parse().map_err(CliError::input)?;
                    s.lsdyna[*k][i]
                };
                Ok(Scalar::new(*k, y, std_dev(&s.lsdyna[*k])))
            })
            .collect::<Result<Vec<_>, _>>()?,
    )?;
    let (runs, labels, skipped) = our_runs(&s, &runs_file)?;
    let cal = calibrate(&space, &test, &runs, &ScalarOptions::default())
        .map_err(|e| CliError::from(e).context("demo --car-pole"))?;
    let run_at_target = labels
        .iter()
        .position(|l| l == target)
        .map(|i| {
            let o = OUTPUTS
                .iter()
                .map(|k| k.to_string())
                .zip(runs.values[i].iter().copied())
                .collect();
            test.errors(&o, &format!("our run at design {target}"))
        })
        .transpose()?;
    let factors: BTreeMap<String, f64> = s
        .names
        .iter()
        .zip(&target_point)
        .map(|(n, v)| (n.clone(), cal.calibrated[n] / v))
        .collect();
    crate::output::out_folder(out)?;
    let summary = Summary {
        data: dir.display().to_string(),
        runs_file: runs_file.display().to_string(),
        target,
        designs_reused: runs.points.len(),
        rows_skipped: skipped,
        test: test.scalars(),
        run_at_target,
        calibration: &cal,
        factors,
    };
    let json = serde_json::to_string_pretty(&summary)
        .map_err(|e| CliError::failure(format!("car-pole.json: {e}")))?;
    write_text(&json, Some(&out.join("car-pole.json")))?;
    let report = report_md(&summary);
    write_text(&report, Some(&out.join("report.md")))?;
    write_text(
        &deck(
            &s.names,
            &cal.calibrated_point,
            &dir.join("decks/car6_crash_v223.k"),
        ),
        Some(&out.join("calibrated.k")),
    )?;
    print!("{report}");
    Ok(())
}

/// The main deck of the calibrated point (`*PARAMETER` cards as the study wrote them and an
/// `*INCLUDE` of the model where the user keeps it), for the run that confirms the
/// calibration: `impactcal simulate --deck OUT/calibrated.k`.
fn deck(names: &[String], x: &[f64], include: &Path) -> String {
    let pairs: Vec<String> = names
        .iter()
        .zip(x)
        .map(|(n, v)| format!("r{n},{v}"))
        .collect();
    let mut s = String::from("*KEYWORD\n*PARAMETER\n");
    for chunk in pairs.chunks(4) {
        s.push_str(&chunk.join(","));
        s.push('\n');
    }
    // Every output is sampled at the *DATABASE_NODOUT interval: 1e-5 s, the study's rwforc
    // and glstat interval, so that the peak force is taken as often as LS-DYNA took it.
    let _ = write!(
        s,
        "*INCLUDE\n{}\n*DATABASE_NODOUT\n1.0e-5\n*END\n",
        include.display()
    );
    s
}

fn pct(e: &ScalarError) -> String {
    e.relative
        .map_or_else(|| "-".into(), |r| format!("{:+.1} %", 100.0 * r))
}

fn report_md(s: &Summary<'_>) -> String {
    let c = s.calibration;
    let mut r = String::new();
    let _ = writeln!(
        r,
        "# Car pole: our model calibrated to LS-DYNA at design {}\n\n{} of our runs \
         reused ({}); {} surrogate evaluations of CORS-RBF; scale of each output: LS-DYNA's \
         standard deviation over the study's designs.\n",
        s.target, s.designs_reused, s.runs_file, c.evaluations
    );
    let _ = writeln!(
        r,
        "| output | LS-DYNA | scale | surrogate as given | our run as given | \
         surrogate calibrated |\n|---|---|---|---|---|---|"
    );
    for (k, t) in s.test.iter().enumerate() {
        let run = s.run_at_target.as_ref().map_or_else(
            || "not run".into(),
            |e| format!("{:.5} ({})", e[k].model, pct(&e[k])),
        );
        let _ = writeln!(
            r,
            "| {} | {:.5} | {:.3} | {:.5} ({}) | {run} | {:.5} ({}) |",
            t.name,
            t.value,
            t.scale,
            c.before[k].model,
            pct(&c.before[k]),
            c.after[k].model,
            pct(&c.after[k]),
        );
    }
    let j_run = s
        .run_at_target
        .as_ref()
        .map(|e| {
            format!(
                ", our run {:.3}",
                impactcal::calibrate::scalar::misfit_of(e)
            )
        })
        .unwrap_or_default();
    let _ = writeln!(
        r,
        "\nMisfit J = sum ((ours - LS-DYNA) / scale)^2: surrogate as given {:.3}{j_run}; \
         surrogate calibrated {:.3}.\n\nSurrogates (leave-one-out error / standard \
         deviation): {}.\n\nCalibrated point (factor on the design): {}.\n\nConfirm with \
         our solver: `impactcal simulate --deck calibrated.k` in the output folder.",
        c.misfit_before,
        c.misfit_after,
        c.surrogates
            .iter()
            .map(|x| format!(
                "{} {} {:.3}",
                x.name, x.choice.chosen, x.choice.loo_rel_error
            ))
            .collect::<Vec<_>>()
            .join(", "),
        s.factors
            .iter()
            .map(|(n, f)| format!("{n} {:.4} ({f:.3})", c.calibrated[n]))
            .collect::<Vec<_>>()
            .join(", ")
    );
    r
}
