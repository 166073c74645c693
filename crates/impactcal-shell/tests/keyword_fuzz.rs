//! The keyword reader on mutated real decks: cards dropped, duplicated or cut short, fields
//! swapped, bytes flipped, includes that loop. For every input the reader must return,
//! never panic, and a deck it accepts must have had every one of its cards read: the
//! number of cards it reports equals the number of data cards counted here, independently,
//! in the deck and the files it includes.
//!
//! The decks: `examples/decks/strip_drop.k` and, where `../shared/data/car_pole/decks`
//! exists (GPL-3 decks, read there, never copied), the parameterised car deck with its
//! include. The number of cases is `IMPACTCAL_FUZZ_CASES` (default 64 per deck, which CI
//! runs); the long run by hand and its counts are in docs/validation.md.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

use impactcal_shell::keyword::read_deck;
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};

/// A deck as files: (name, bytes), the first the main file.
type Files = Vec<(String, Vec<u8>)>;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn decks() -> Vec<(&'static str, Files)> {
    let strip = std::fs::read(root().join("examples/decks/strip_drop.k")).unwrap();
    let mut out = vec![("strip_drop", vec![("main.k".to_string(), strip)])];
    let car = root().join("../shared/data/car_pole/decks");
    if car.join("main_v223_param.k").is_file() {
        out.push((
            "car_pole",
            vec![
                (
                    "main_v223_param.k".to_string(),
                    std::fs::read(car.join("main_v223_param.k")).unwrap(),
                ),
                (
                    "car6_crash_v223.k".to_string(),
                    std::fs::read(car.join("car6_crash_v223.k")).unwrap(),
                ),
            ],
        ));
    } else {
        eprintln!(
            "note: {} is absent: the car deck is not fuzzed",
            car.display()
        );
    }
    out
}

/// The text of a file as the reader decodes it: UTF-8, else Latin-1.
fn decode(b: &[u8]) -> String {
    match std::str::from_utf8(b) {
        Ok(s) => s.to_string(),
        Err(_) => b.iter().map(|&c| char::from(c)).collect(),
    }
}

/// The data cards of `file` and of the files it includes, counted without the reader: the
/// lines of each keyword that are not comments, less trailing blank lines, from the first
/// keyword to `*END`; the names under `*INCLUDE` / `*INCLUDE_PATH` are not cards, the
/// files they name are counted in place. `None` when an include cannot be followed (the
/// reader must then fail).
fn count(dir: &Path, file: &Path, depth: usize) -> Option<usize> {
    if depth > 20 {
        return None;
    }
    let text = decode(&std::fs::read(file).ok()?);
    let mut total = 0;
    let mut block: Option<(String, Vec<String>)> = None;
    let finish = |b: Option<(String, Vec<String>)>, total: &mut usize| -> Option<()> {
        if let Some((kw, lines)) = b {
            if kw == "INCLUDE" {
                let mut names: Vec<String> = Vec::new();
                let mut open = false;
                for l in lines {
                    if l.trim().is_empty() && !open {
                        continue;
                    }
                    let (t, more) = match l.trim_end().strip_suffix(" +") {
                        Some(h) => (h.to_string(), true),
                        None => (l.trim_end().to_string(), false),
                    };
                    if open {
                        names.last_mut()?.push_str(&t);
                    } else {
                        names.push(t);
                    }
                    open = more;
                }
                for n in names {
                    let p = file.parent().unwrap_or(dir).join(n.trim());
                    *total += count(dir, &p, depth + 1)?;
                }
            } else if kw != "INCLUDE_PATH" && kw != "INCLUDE_PATH_RELATIVE" {
                let mut lines = lines;
                while lines.last().is_some_and(|l| l.trim().is_empty()) {
                    lines.pop();
                }
                *total += lines.len();
            }
        }
        Some(())
    };
    for line in text.lines() {
        if let Some(rest) = line.strip_prefix('*') {
            finish(block.take(), &mut total)?;
            let name = rest
                .split_whitespace()
                .next()
                .unwrap_or("")
                .to_uppercase()
                .trim_end_matches(['+', '-', '%'])
                .to_string();
            if name == "END" {
                return Some(total);
            }
            block = Some((name, Vec::new()));
        } else if line.starts_with('$') {
            continue;
        } else if let Some((_, lines)) = block.as_mut() {
            lines.push(line.to_string());
        }
    }
    finish(block, &mut total)?;
    Some(total)
}

/// One mutation of one file's lines: what to do, and where (fractions of the file).
#[derive(Debug, Clone)]
enum Mutation {
    Drop(f64),
    Duplicate(f64),
    Truncate(f64, f64),
    SwapFields(f64, usize, usize),
    FlipByte(f64, u8),
    DropKeywordLine(f64),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (0.0..1.0f64).prop_map(Mutation::Drop),
        (0.0..1.0f64).prop_map(Mutation::Duplicate),
        (0.0..1.0f64, 0.0..1.0f64).prop_map(|(a, b)| Mutation::Truncate(a, b)),
        (0.0..1.0f64, 0..8usize, 0..8usize).prop_map(|(a, i, j)| Mutation::SwapFields(a, i, j)),
        (0.0..1.0f64, any::<u8>()).prop_map(|(a, b)| Mutation::FlipByte(a, b)),
        (0.0..1.0f64).prop_map(Mutation::DropKeywordLine),
    ]
}

fn apply(bytes: &[u8], m: &Mutation) -> Vec<u8> {
    let mut lines: Vec<Vec<u8>> = bytes.split(|&b| b == b'\n').map(<[u8]>::to_vec).collect();
    let n = lines.len();
    let at = |f: f64| ((f * n as f64) as usize).min(n.saturating_sub(1));
    match *m {
        Mutation::Drop(f) => {
            lines.remove(at(f));
        }
        Mutation::Duplicate(f) => {
            let k = at(f);
            let l = lines[k].clone();
            lines.insert(k, l);
        }
        Mutation::Truncate(f, g) => {
            let k = at(f);
            let len = lines[k].len();
            lines[k].truncate((g * len as f64) as usize);
        }
        Mutation::SwapFields(f, i, j) => {
            let k = at(f);
            let l = &mut lines[k];
            let (a, b) = (10 * i, 10 * j);
            if a + 10 <= l.len() && b + 10 <= l.len() && a != b {
                let (x, y) = (l[a..a + 10].to_vec(), l[b..b + 10].to_vec());
                l[a..a + 10].copy_from_slice(&y);
                l[b..b + 10].copy_from_slice(&x);
            }
        }
        Mutation::FlipByte(f, v) => {
            let k = at(f);
            if !lines[k].is_empty() {
                let p = ((f * 7919.0) as usize) % lines[k].len();
                lines[k][p] ^= v | 1;
            }
        }
        Mutation::DropKeywordLine(f) => {
            let start = at(f);
            if let Some(k) = (start..n)
                .chain(0..start)
                .find(|&k| lines[k].first() == Some(&b'*'))
            {
                lines.remove(k);
            }
        }
    }
    lines.join(&b'\n')
}

fn cases() -> u32 {
    std::env::var("IMPACTCAL_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(64)
}

#[test]
fn mutated_real_decks_never_panic_and_never_lose_a_card() {
    let base = std::env::temp_dir().join(format!("impactcal-fuzz-{}", std::process::id()));
    for (name, files) in decks() {
        let dir = base.join(name);
        std::fs::create_dir_all(&dir).unwrap();
        let mut runner = TestRunner::new(Config {
            cases: cases(),
            failure_persistence: None,
            ..Config::default()
        });
        let (accepted, refused) = (std::cell::Cell::new(0u32), std::cell::Cell::new(0u32));
        let result = runner.run(
            &(0..files.len(), proptest::collection::vec(mutation(), 1..4)),
            |(which, ms)| {
                for (f, bytes) in &files {
                    std::fs::write(dir.join(f), bytes).unwrap();
                }
                let mut b = files[which].1.clone();
                for m in &ms {
                    b = apply(&b, m);
                }
                std::fs::write(dir.join(&files[which].0), &b).unwrap();
                let main = dir.join(&files[0].0);
                match read_deck(&main) {
                    Ok(deck) => {
                        accepted.set(accepted.get() + 1);
                        let want = count(&dir, &main, 0);
                        prop_assert_eq!(Some(deck.cards), want, "mutations {:?}", ms);
                    }
                    Err(_) => refused.set(refused.get() + 1),
                }
                Ok(())
            },
        );
        eprintln!(
            "{name}: {} cases, {} accepted, {} refused",
            cases(),
            accepted.get(),
            refused.get()
        );
        result.unwrap();
        // The unmutated deck reads with every card counted.
        for (f, bytes) in &files {
            std::fs::write(dir.join(f), bytes).unwrap();
        }
        let main = dir.join(&files[0].0);
        let deck = read_deck(&main).map(|d| d.cards);
        assert_eq!(deck.ok(), count(&dir, &main, 0));
    }
    let _ = std::fs::remove_dir_all(&base);
}

#[test]
fn includes_that_loop_are_an_error_naming_the_chain() {
    let dir = std::env::temp_dir().join(format!("impactcal-loop-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("a.k"), "*KEYWORD\n*INCLUDE\nb.k\n*END\n").unwrap();
    std::fs::write(dir.join("b.k"), "*KEYWORD\n*INCLUDE\nc.k\na.k\n*END\n").unwrap();
    std::fs::write(dir.join("c.k"), "*KEYWORD\n*TITLE\nc\n*END\n").unwrap();
    let e = read_deck(dir.join("a.k")).unwrap_err().to_string();
    assert!(
        e.contains("include each other") && e.contains("a.k -> "),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
