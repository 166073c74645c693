//! The run journal: every finished true-model run of a study, one file per run in the
//! output folder, written as it finishes, so that a study run again after a crash reuses
//! what was done.
//!
//! Layout: `<dir>/journal/fingerprint` holds the study's fingerprint (a hash of everything
//! that defines the study); `<dir>/journal/<stage>/<index>.run` one run. A run file is
//! little-endian binary: the magic `ICRUN01\n`, the point (`d` as u32, then `d` f64), then
//! either the histories (labels, samples, dt, start, unit, and the values as f32) or, for
//! a failed run, its message. Values are stored in single precision (half the disk of
//! double; 6e-8 relative, far below any simulation noise) and a study always works with
//! the stored values, whether it just ran them or read them back, so a resumed study is
//! bit-identical to an uninterrupted one. Files are written to a temporary name and
//! renamed, so a killed study never leaves half a run behind.

use std::fs;
use std::path::{Path, PathBuf};

use impactcal_core::Histories;

use crate::error::{CalibrateError, Result};

const MAGIC: &[u8; 8] = b"ICRUN01\n";

/// The outcome of one run as the journal keeps it: the histories (single precision) or the
/// failure's message.
pub type RunOutcome = std::result::Result<Histories, String>;

/// A study's run journal in an output folder.
#[derive(Debug, Clone)]
pub struct Journal {
    root: PathBuf,
}

impl Journal {
    /// Opens (or starts) the journal of the study with `fingerprint` in `dir`.
    ///
    /// # Errors
    /// [`CalibrateError::ForeignJournal`] when `dir` holds another study's journal (nothing
    /// is written then); [`CalibrateError::Journal`] when the folder cannot be created.
    pub fn open(dir: &Path, fingerprint: &str) -> Result<Journal> {
        let root = dir.join("journal");
        let stamp = root.join("fingerprint");
        match fs::read_to_string(&stamp) {
            Ok(found) if found.trim() == fingerprint => {}
            Ok(found) => {
                return Err(CalibrateError::ForeignJournal {
                    dir: dir.display().to_string(),
                    found: found.trim().to_string(),
                    expected: fingerprint.to_string(),
                });
            }
            Err(_) => {
                fs::create_dir_all(&root).map_err(|e| io(&root, e))?;
                write_atomic(&stamp, fingerprint.as_bytes())?;
            }
        }
        Ok(Journal { root })
    }

    /// The journal's folder.
    pub fn root(&self) -> &Path {
        &self.root
    }

    fn path(&self, stage: &str, index: usize) -> PathBuf {
        self.root.join(stage).join(format!("{index:05}.run"))
    }

    /// The recorded outcome of run `index` of `stage`, if it finished.
    ///
    /// # Errors
    /// [`CalibrateError::Journal`] for a file that cannot be read, is malformed, or holds
    /// another point than `point` (bit for bit).
    pub fn read(&self, stage: &str, index: usize, point: &[f64]) -> Result<Option<RunOutcome>> {
        let path = self.path(stage, index);
        let bytes = match fs::read(&path) {
            Ok(b) => b,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(io(&path, e)),
        };
        decode(&bytes, point)
            .map(Some)
            .map_err(|message| CalibrateError::Journal {
                path: path.display().to_string(),
                message,
            })
    }

    /// Records the outcome of run `index` of `stage` at `point` and returns it as the study
    /// must use it (histories rounded to the stored precision).
    ///
    /// # Errors
    /// [`CalibrateError::Journal`] when the file cannot be written.
    pub fn write(
        &self,
        stage: &str,
        index: usize,
        point: &[f64],
        outcome: &RunOutcome,
    ) -> Result<RunOutcome> {
        let path = self.path(stage, index);
        if let Some(parent) = path.parent() {
            fs::create_dir_all(parent).map_err(|e| io(parent, e))?;
        }
        let bytes = encode(point, outcome);
        write_atomic(&path, &bytes)?;
        decode(&bytes, point).map_err(|message| CalibrateError::Journal {
            path: path.display().to_string(),
            message,
        })
    }
}

fn io(path: &Path, e: std::io::Error) -> CalibrateError {
    CalibrateError::Journal {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

/// Writes `bytes` to `path` through a temporary file and a rename.
///
/// # Errors
/// [`CalibrateError::Journal`] naming the file.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = PathBuf::from(tmp);
    fs::write(&tmp, bytes).map_err(|e| io(&tmp, e))?;
    fs::rename(&tmp, path).map_err(|e| io(path, e))
}

fn put_u32(out: &mut Vec<u8>, v: usize) {
    out.extend_from_slice(&u32::try_from(v).unwrap_or(u32::MAX).to_le_bytes());
}

fn put_str(out: &mut Vec<u8>, s: &str) {
    put_u32(out, s.len());
    out.extend_from_slice(s.as_bytes());
}

fn encode(point: &[f64], outcome: &RunOutcome) -> Vec<u8> {
    let mut out = Vec::new();
    out.extend_from_slice(MAGIC);
    put_u32(&mut out, point.len());
    point
        .iter()
        .for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
    match outcome {
        Err(message) => {
            out.push(0);
            put_str(&mut out, message);
        }
        Ok(h) => {
            out.push(1);
            put_u32(&mut out, h.channels());
            h.labels().iter().for_each(|l| put_str(&mut out, l));
            put_u32(&mut out, h.samples());
            out.extend_from_slice(&h.dt().to_le_bytes());
            out.extend_from_slice(&h.start().to_le_bytes());
            put_str(&mut out, h.unit());
            h.data()
                .iter()
                .for_each(|v| out.extend_from_slice(&(*v as f32).to_le_bytes()));
        }
    }
    out
}

/// A cursor over a run file.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> std::result::Result<&'a [u8], String> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let end = end.ok_or_else(|| "truncated run file".to_string())?;
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }
    fn array<const N: usize>(&mut self) -> std::result::Result<[u8; N], String> {
        let mut a = [0u8; N];
        a.copy_from_slice(self.take(N)?);
        Ok(a)
    }
    fn u32(&mut self) -> std::result::Result<usize, String> {
        Ok(u32::from_le_bytes(self.array()?) as usize)
    }
    fn f64(&mut self) -> std::result::Result<f64, String> {
        Ok(f64::from_le_bytes(self.array()?))
    }
    fn string(&mut self) -> std::result::Result<String, String> {
        let n = self.u32()?;
        String::from_utf8(self.take(n)?.to_vec()).map_err(|_| "label is not UTF-8".to_string())
    }
}

fn decode(bytes: &[u8], point: &[f64]) -> std::result::Result<RunOutcome, String> {
    let mut r = Reader { bytes, at: 0 };
    if r.take(MAGIC.len())? != MAGIC {
        return Err("not a run file of this journal version".into());
    }
    let d = r.u32()?;
    let stored: Vec<f64> = (0..d).map(|_| r.f64()).collect::<Result<_, _>>()?;
    let same = stored.len() == point.len()
        && stored
            .iter()
            .zip(point)
            .all(|(a, b)| a.to_bits() == b.to_bits());
    if !same {
        return Err(format!(
            "holds the run at {stored:?}, not at {point:?}: the journal belongs to another \
             design"
        ));
    }
    match r.take(1)?[0] {
        0 => Ok(Err(r.string()?)),
        1 => {
            let channels = r.u32()?;
            let labels: Vec<String> = (0..channels)
                .map(|_| r.string())
                .collect::<Result<_, _>>()?;
            let samples = r.u32()?;
            let dt = r.f64()?;
            let start = r.f64()?;
            let unit = r.string()?;
            let raw = r.take(channels.saturating_mul(samples).saturating_mul(4))?;
            let data: Vec<f64> = raw
                .chunks_exact(4)
                .map(|c| f64::from(f32::from_le_bytes([c[0], c[1], c[2], c[3]])))
                .collect();
            Histories::new(labels, samples, dt, start, unit, data)
                .map(Ok)
                .map_err(|e| e.to_string())
        }
        _ => Err("unknown run record".into()),
    }
}

/// A 64-bit FNV-1a hash of `bytes`, as 16 hex digits: the study's fingerprint.
pub fn fingerprint(bytes: &[u8]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    format!("{h:016x}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_round_trip_in_single_precision_and_refuse_other_points() {
        let dir = tempfile::tempdir().unwrap();
        let j = Journal::open(dir.path(), "abc").unwrap();
        let h = Histories::from_channels(
            vec!["1.z".into(), "2.z".into()],
            vec![vec![0.1, 1.0 / 3.0], vec![-2.5, 1e-9]],
            1e-4,
            0.0,
            "in/s",
        )
        .unwrap();
        let used = j.write("ensemble", 3, &[1.0, 2.0], &Ok(h.clone())).unwrap();
        let read = j.read("ensemble", 3, &[1.0, 2.0]).unwrap().unwrap();
        assert_eq!(used, read);
        let used = used.unwrap();
        for (a, b) in used.data().iter().zip(h.data()) {
            assert_eq!(a.to_bits(), f64::from(*b as f32).to_bits());
        }
        assert!(j.read("ensemble", 4, &[1.0, 2.0]).unwrap().is_none());
        assert!(j.read("ensemble", 3, &[1.0, 2.5]).is_err());
        let failed = j
            .write("ensemble", 5, &[0.0, 0.0], &Err("diverged".into()))
            .unwrap();
        assert_eq!(failed, Err("diverged".to_string()));
        assert_eq!(j.read("ensemble", 5, &[0.0, 0.0]).unwrap(), Some(failed));
        // Another study's folder is refused.
        let e = Journal::open(dir.path(), "other").unwrap_err();
        assert!(matches!(e, CalibrateError::ForeignJournal { .. }), "{e}");
        assert_eq!(fingerprint(b""), "cbf29ce484222325");
    }
}
