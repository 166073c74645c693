//! Writing results: JSON to stdout or a file, CSV to a file or stdout.

use std::io::Write;
use std::path::Path;

use crate::error::CliError;

/// Writes `value` as pretty JSON to `out`, or to stdout when `out` is `None`.
pub fn write_json(value: &impl serde::Serialize, out: Option<&Path>) -> Result<(), CliError> {
    let text = serde_json::to_string_pretty(value)
        .map_err(|e| CliError::failure(format!("cannot encode the result as JSON: {e}")))?;
    write_text(&(text + "\n"), out)
}

/// Writes `value` as compact JSON to `out` (for large results that programs read).
pub fn write_json_compact(value: &impl serde::Serialize, out: &Path) -> Result<(), CliError> {
    let (mut w, name) = writer(Some(out))?;
    serde_json::to_writer(&mut w, value)
        .map_err(|e| CliError::io(format!("{name}: cannot write the JSON: {e}")))?;
    w.flush().map_err(|e| CliError::io(format!("{name}: {e}")))
}

/// Writes `text` to `out`, or to stdout when `out` is `None`.
pub fn write_text(text: &str, out: Option<&Path>) -> Result<(), CliError> {
    match out {
        Some(path) => {
            std::fs::write(path, text).map_err(|e| CliError::io(format!("{}: {e}", path.display())))
        }
        None => std::io::stdout()
            .lock()
            .write_all(text.as_bytes())
            .map_err(|e| CliError::io(format!("stdout: {e}"))),
    }
}

/// A writer to `out`, or to stdout when `out` is `None`, with the name for messages.
pub fn writer(out: Option<&Path>) -> Result<(Box<dyn Write>, String), CliError> {
    match out {
        Some(path) => {
            let file = std::fs::File::create(path)
                .map_err(|e| CliError::io(format!("{}: {e}", path.display())))?;
            Ok((
                Box::new(std::io::BufWriter::new(file)),
                path.display().to_string(),
            ))
        }
        None => Ok((Box::new(std::io::stdout().lock()), "stdout".into())),
    }
}

/// Refuses an output folder `out` that names a file (or lies under one), before anything
/// runs.
///
/// # Errors
/// Exit 2, saying which path is a file and what `--out` takes.
pub fn check_out_folder(out: &Path) -> Result<(), CliError> {
    let file = out
        .ancestors()
        .find(|a| !a.as_os_str().is_empty() && a.is_file());
    match file {
        Some(f) => Err(CliError::input(format!(
            "--out {}: {} is a file; --out names a folder (created if needed) that will hold \
             the run journal, the JSON and the report",
            out.display(),
            if f == out {
                "it".to_string()
            } else {
                f.display().to_string()
            }
        ))),
        None => Ok(()),
    }
}

/// Creates the output folder `out` (and its parents) if needed.
///
/// # Errors
/// As [`check_out_folder`]; an I/O error when the folder cannot be created.
pub fn out_folder(out: &Path) -> Result<(), CliError> {
    check_out_folder(out)?;
    std::fs::create_dir_all(out).map_err(|e| CliError::io(format!("{}: {e}", out.display())))
}

/// Prints a finished study's or loop's lead lines (its verdicts in a few sentences) on
/// standard error, then `<prefix>wrote <json> and <report.html>`.
pub fn print_finished<R>(done: &impactcal::experiment::Finished<R>, prefix: &str) {
    for line in &done.report.lead {
        eprintln!("{line}");
    }
    eprintln!(
        "{prefix}wrote {} and {}",
        done.json.display(),
        done.files.html.display()
    );
}
