//! The binout reader on mutated LS-DYNA files: bytes flipped, the file cut short, chunks
//! duplicated or dropped. Every input must give branches and histories or a typed error,
//! never a panic. The number of cases is `IMPACTCAL_FUZZ_CASES` (default 64, which CI
//! runs); the long run by hand is recorded in docs/validation.md.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;

use impactcal_runner::Binout;
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};

#[derive(Debug, Clone)]
enum Mutation {
    Flip(f64, u8),
    Cut(f64),
    Duplicate(f64, usize),
    Drop(f64, usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (0.0..1.0f64, any::<u8>()).prop_map(|(a, v)| Mutation::Flip(a, v)),
        (0.0..1.0f64).prop_map(Mutation::Cut),
        (0.0..1.0f64, 1..64usize).prop_map(|(a, n)| Mutation::Duplicate(a, n)),
        (0.0..1.0f64, 1..64usize).prop_map(|(a, n)| Mutation::Drop(a, n)),
    ]
}

fn apply(b: &mut Vec<u8>, m: &Mutation) {
    let at = |f: f64, len: usize| ((f * len as f64) as usize).min(len.saturating_sub(1));
    match *m {
        Mutation::Flip(f, v) if !b.is_empty() => {
            let k = at(f, b.len());
            b[k] ^= v | 1;
        }
        Mutation::Cut(f) => b.truncate((f * b.len() as f64) as usize),
        Mutation::Duplicate(f, n) if !b.is_empty() => {
            let k = at(f, b.len());
            let chunk: Vec<u8> = b[k..(k + n).min(b.len())].to_vec();
            b.splice(k..k, chunk);
        }
        Mutation::Drop(f, n) if !b.is_empty() => {
            let k = at(f, b.len());
            b.drain(k..(k + n).min(b.len()));
        }
        _ => {}
    }
}

#[test]
fn mutated_binouts_never_panic() {
    let cases = std::env::var("IMPACTCAL_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(64);
    let data = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/lsdyna/binout");
    let dir = tempfile::tempdir().unwrap();
    for v in ["R7_1_2", "R12_2_1"] {
        let bytes = std::fs::read(data.join(v).join("binout")).unwrap();
        let (read, refused) = (std::cell::Cell::new(0u32), std::cell::Cell::new(0u32));
        let mut runner = TestRunner::new(Config {
            cases,
            failure_persistence: None,
            ..Config::default()
        });
        let path = dir.path().join(format!("{v}-binout"));
        runner
            .run(&proptest::collection::vec(mutation(), 1..4), |ms| {
                let mut b = bytes.clone();
                for m in &ms {
                    apply(&mut b, m);
                }
                std::fs::write(&path, &b).unwrap();
                let outcome = Binout::open(&path).and_then(|bin| {
                    for branch in bin.branches() {
                        let _ = bin.variables(&branch)?;
                        // A branch may fail on its own (a state cut away); the others read.
                        let _ = bin.histories(&branch, &[]);
                    }
                    Ok(())
                });
                match outcome {
                    Ok(()) => read.set(read.get() + 1),
                    Err(e) => {
                        prop_assert!(!e.to_string().is_empty());
                        refused.set(refused.get() + 1)
                    }
                }
                Ok(())
            })
            .unwrap();
        eprintln!(
            "{v}: {cases} cases, {} read, {} refused at opening",
            read.get(),
            refused.get()
        );
    }
}
