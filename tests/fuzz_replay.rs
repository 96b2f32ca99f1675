//! The fuzz target's function on stable (issue 6): `fuzz/src/lib.rs` (the body of the
//! cargo-fuzz target `spec`) is compiled in here and fed the seed corpus, any crash inputs the
//! fuzzer left in `fuzz/artifacts/spec/`, random bytes, and mutations of the seeds (bytes
//! flipped, inserted, deleted; numbers replaced by extreme ones; fields dropped; family names
//! swapped). It panics on any bug, so each case passes only without one.
#![cfg(not(target_arch = "wasm32"))]

#[path = "../fuzz/src/lib.rs"]
mod fuzz_spec;
mod strategies;

use proptest::prelude::*;
use std::path::Path;

fn files(dir: &str) -> Vec<(String, Vec<u8>)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let mut out: Vec<(String, Vec<u8>)> = std::fs::read_dir(&dir)
        .map(|entries| {
            entries
                .filter_map(|e| e.ok())
                .filter(|e| e.path().is_file())
                .filter_map(|e| {
                    let name = e.file_name().to_string_lossy().into_owned();
                    std::fs::read(e.path()).ok().map(|b| (name, b))
                })
                .collect()
        })
        .unwrap_or_default();
    out.sort();
    out
}

fn seeds() -> Vec<Vec<u8>> {
    files("fuzz/corpus/spec")
        .into_iter()
        .filter(|(name, _)| name.starts_with("seed-"))
        .map(|(_, b)| b)
        .collect()
}

/// The seeds are real specs: each parses as a design request, a simulation or a spectrum, and
/// runs without error (otherwise the fuzzer would start from nothing useful).
#[test]
fn seeds_are_valid_specs_and_run() {
    use input_shaping::scenario::SimulationSpec;
    use input_shaping::scenario::SpectrumSpec;
    let seeds = files("fuzz/corpus/spec");
    assert!(
        seeds.len() >= 25,
        "seed corpus missing ({} files)",
        seeds.len()
    );
    for (name, bytes) in seeds.iter().filter(|(n, _)| n.starts_with("seed-")) {
        let text = std::str::from_utf8(bytes).unwrap();
        let ran = if let Ok(r) = serde_json::from_str::<input_shaping::DesignRequest>(text) {
            input_shaping::design(&r)
                .map(|_| ())
                .map_err(|e| e.to_string())
        } else if let Ok(s) = serde_json::from_str::<SimulationSpec>(text) {
            input_shaping::scenario::run(&s)
                .map(|_| ())
                .map_err(|e| e.to_string())
        } else if let Ok(s) = serde_json::from_str::<SpectrumSpec>(text) {
            input_shaping::scenario::spectrum_for(&s)
                .map(|_| ())
                .map_err(|e| e.to_string())
        } else {
            Err("parses as no spec".into())
        };
        assert!(ran.is_ok(), "{name}: {ran:?}");
        fuzz_spec::spec(bytes);
    }
}

/// Crash inputs a fuzzing run saved (none are committed; after a fix, a crash input moved to
/// `fuzz/corpus/spec/seed-regression-*` stays a regression test).
#[test]
fn replay_artifacts() {
    for (_, bytes) in files("fuzz/artifacts/spec") {
        fuzz_spec::spec(&bytes);
    }
}

const NUMBERS: &[&str] = &[
    "0",
    "-0",
    "-1",
    "1e308",
    "-1e308",
    "1e309",
    "5e-324",
    "1e-320",
    "2.2250738585072014e-308",
    "99999999999999999999",
    "-99999999999999999999",
    "4294967296",
    "18446744073709551616",
    "0.9999999999999999",
    "1.0000000000000002",
    "1e9",
    "1e-9",
    "3",
    "100000",
    "0.5",
    "true",
    "null",
    "\"1\"",
    "[]",
    "{}",
];

const WORDS: &[&str] = &[
    "zv",
    "zvd",
    "zvdd",
    "zvdn",
    "ei",
    "ei2",
    "ei3",
    "eihump",
    "mzv",
    "umzv",
    "umzvd",
    "umei",
    "bangbang",
    "onoff",
    "custom",
    "si",
    "direct",
    "sampled",
    "modal",
    "twoMass",
    "pendulum",
    "vecianaTestBed",
    "step",
    "ramp",
    "trapezoid",
    "sCurve",
    "profile",
    "pulse",
    "triangle",
    "robustTrapezium",
    "multiMode",
    "hold",
    "linear",
    "velocity",
    "position",
    "acceleration",
    "minimumNorm",
    "controlError",
    "",
    "ZV",
    "\u{0}",
];

/// Replaces the `k`-th number literal of `text` by `by`.
fn replace_number(text: &str, k: usize, by: &str) -> String {
    let b = text.as_bytes();
    let mut spans = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let starts =
            b[i].is_ascii_digit() || (b[i] == b'-' && i + 1 < b.len() && b[i + 1].is_ascii_digit());
        if starts && (i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'.')) {
            let j0 = i;
            i += 1;
            while i < b.len()
                && (b[i].is_ascii_digit() || matches!(b[i], b'.' | b'e' | b'E' | b'+' | b'-'))
            {
                i += 1;
            }
            spans.push((j0, i));
        } else {
            i += 1;
        }
    }
    if spans.is_empty() {
        return text.to_string();
    }
    let (s, e) = spans[k % spans.len()];
    format!("{}{}{}", &text[..s], by, &text[e..])
}

/// Replaces the `k`-th string literal's contents by `by`.
fn replace_string(text: &str, k: usize, by: &str) -> String {
    let quotes: Vec<usize> = text.match_indices('"').map(|(i, _)| i).collect();
    let pairs: Vec<(usize, usize)> = quotes
        .chunks(2)
        .filter(|c| c.len() == 2)
        .map(|c| (c[0], c[1]))
        .collect();
    if pairs.is_empty() {
        return text.to_string();
    }
    let (s, e) = pairs[k % pairs.len()];
    format!("{}\"{}\"{}", &text[..s], by, &text[e + 1..])
}

#[derive(Debug, Clone)]
enum Mutation {
    Number(usize, usize),
    Word(usize, usize),
    Flip(usize, u8),
    Insert(usize, u8),
    Delete(usize, usize),
    Splice(usize, usize, usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        4 => (any::<usize>(), 0..NUMBERS.len()).prop_map(|(k, n)| Mutation::Number(k, n)),
        2 => (any::<usize>(), 0..WORDS.len()).prop_map(|(k, n)| Mutation::Word(k, n)),
        1 => (any::<usize>(), any::<u8>()).prop_map(|(k, b)| Mutation::Flip(k, b)),
        1 => (any::<usize>(), any::<u8>()).prop_map(|(k, b)| Mutation::Insert(k, b)),
        1 => (any::<usize>(), 1usize..8).prop_map(|(k, n)| Mutation::Delete(k, n)),
        1 => (any::<usize>(), any::<usize>(), any::<usize>()).prop_map(|(a, b, c)| Mutation::Splice(a, b, c)),
    ]
}

fn apply(seeds: &[Vec<u8>], seed: usize, mutations: &[Mutation]) -> Vec<u8> {
    let mut bytes = seeds[seed % seeds.len()].clone();
    for m in mutations {
        let text = String::from_utf8_lossy(&bytes).into_owned();
        bytes = match *m {
            Mutation::Number(k, n) => replace_number(&text, k, NUMBERS[n]).into_bytes(),
            Mutation::Word(k, n) => replace_string(&text, k, WORDS[n]).into_bytes(),
            Mutation::Flip(k, b) if !bytes.is_empty() => {
                let i = k % bytes.len();
                bytes[i] ^= b;
                bytes
            }
            Mutation::Insert(k, b) => {
                let i = k % (bytes.len() + 1);
                bytes.insert(i, b);
                bytes
            }
            Mutation::Delete(k, n) if !bytes.is_empty() => {
                let i = k % bytes.len();
                let j = (i + n).min(bytes.len());
                bytes.drain(i..j);
                bytes
            }
            Mutation::Splice(a, b, c) => {
                // Paste a slice of another seed into this one.
                let other = &seeds[a % seeds.len()];
                let from = b % (other.len() + 1);
                let to = (from + c % 40).min(other.len());
                let at = c % (bytes.len() + 1);
                bytes.splice(at..at, other[from..to].iter().copied());
                bytes
            }
            _ => bytes,
        };
    }
    bytes
}

proptest! {
    #![proptest_config(strategies::config(1500))]

    /// Mutated seeds: mostly still JSON, often still a spec, with odd values in it.
    #[test]
    fn mutated_seeds(seed in any::<usize>(), mutations in prop::collection::vec(mutation(), 1..5)) {
        let seeds = seeds();
        let input = apply(&seeds, seed, &mutations);
        fuzz_spec::spec(&input);
    }

    /// Raw random bytes and random printable text.
    #[test]
    fn random_bytes(bytes in prop::collection::vec(any::<u8>(), 0..200), text in "\\PC{0,80}") {
        fuzz_spec::spec(&bytes);
        fuzz_spec::spec(text.as_bytes());
    }
}
