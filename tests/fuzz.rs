//! A fuzz pass over the inputs a user hands the tool: spec text, CSV rows and shard bytes, each
//! made by proptest from the committed examples and a vocabulary of hostile tokens (fixed ChaCha
//! seed, no persistence, a bounded number of cases: every run draws the same inputs, in seconds).
//!
//! What must hold for every input: no panic and no abort. Spec text is parsed in process (a
//! panic fails the case); CSV and shard inputs run the binary, whose exit must be 0, 1 or 2
//! (101 is a panic, 134 an abort, a signal has none), and an input error must name its file.
//! A case found here belongs in `tests/data/hostile.toml` once fixed.

mod common;

use common::*;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, RngSeed, TestCaseError, TestRunner};
use std::path::Path;
use std::time::{Duration, Instant};

fn runner(cases: u32) -> TestRunner {
    TestRunner::new(Config {
        cases,
        rng_algorithm: RngAlgorithm::ChaCha,
        rng_seed: RngSeed::Fixed(0xF022_5EED),
        failure_persistence: None,
        // A failing input is reported as drawn; shrinking would re-run the binary many times.
        max_shrink_iters: 0,
        ..Config::default()
    })
}

/// Tokens a hostile edit inserts: extreme and malformed numbers, TOML structure out of place,
/// names the emitted code takes, unbounded exponents, control and non-ASCII characters.
const TOKENS: &[&str] = &[
    "nan", "inf", "-inf", "1e300", "-1e300", "1e-310", "-0.0", "0", "-1", "2", "0.5", "99999999999999999999", "1e39",
    "\"\"", "\"x\"", "[", "]", "{", "}", "=", ",", "\n", "\"", "#", "[[axis]]\n", "[[model.pin]]\nat = [0.5]\n",
    "[emit]\n", "gloss^99", "x^2", "count = 0\n", "count = 100001\n", "range = [1.0, 0.0]\n", "range = [0.0, 1e300]\n",
    "args = [\"min\"]\n", "function = \"lut\"\n", "name = \"lib\"\n", "tolerance = 0\n", "verify = 1\n", "\u{0}", "é",
    "𝛼", "\t", "\r\n", "true", "[0.0, 1.0, 2.0]", "{ a = 1 }",
];

/// One edit of a text: (kind, position, token), positions taken modulo the text's length.
fn edits() -> impl Strategy<Value = Vec<(u8, usize, usize)>> {
    prop::collection::vec((0u8..5, any::<usize>(), 0..TOKENS.len()), 1..5)
}

/// The edits applied in order at character boundaries: insert a token, delete a run, replace a
/// number, duplicate a line, or cut the text short.
fn mutate(text: &str, edits: &[(u8, usize, usize)]) -> String {
    let mut t: Vec<char> = text.chars().collect();
    for &(kind, pos, tok) in edits {
        let at = if t.is_empty() { 0 } else { pos % t.len() };
        let token: Vec<char> = TOKENS[tok].chars().collect();
        match kind {
            0 => {
                t.splice(at..at, token);
            }
            1 => {
                let end = (at + 1 + pos % 24).min(t.len());
                t.drain(at..end);
            }
            2 => {
                // The number (digits, '.', 'e', sign) at or after `at`, replaced by the token.
                if let Some(start) = (at..t.len()).find(|&i| t[i].is_ascii_digit()) {
                    let end = (start..t.len()).find(|&i| !(t[i].is_ascii_digit() || matches!(t[i], '.' | 'e' | '-' | '+'))).unwrap_or(t.len());
                    t.splice(start..end, token);
                }
            }
            3 => {
                let start = t[..at].iter().rposition(|&c| c == '\n').map_or(0, |i| i + 1);
                let end = t[at..].iter().position(|&c| c == '\n').map_or(t.len(), |i| at + i + 1);
                let line: Vec<char> = t[start..end].to_vec();
                t.splice(end..end, line);
            }
            _ => t.truncate(at),
        }
    }
    t.into_iter().collect()
}

/// Committed spec texts (every kind the tool reads), parsed as the build parses them after
/// hostile edits: a parse returns a spec or an error naming the spec's file, and takes well
/// under a second (a parse integrates at most a pin's value or a lobe's domain check; 5 s is
/// the corpus's limit for a whole process).
#[test]
fn mutated_spec_text_parses_or_is_refused_naming_its_file() {
    let root = root();
    shadefit::family::register_lobes(&root.join("fits")).unwrap();
    let catalog = shadefit::family::catalog();
    let mut specs: Vec<(std::path::PathBuf, String)> = std::fs::read_dir(root.join("fits"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .map(|p| {
            let text = std::fs::read_to_string(&p).unwrap();
            (p, text)
        })
        .collect();
    specs.sort();
    assert!(specs.len() > 30, "{} committed specs", specs.len());
    let (refused, parsed) = (std::cell::Cell::new(0), std::cell::Cell::new(0));
    runner(2000)
        .run(&(0..specs.len(), edits()), |(i, e)| {
            let (path, text) = &specs[i];
            let hostile = mutate(text, &e);
            let t = Instant::now();
            let result = shadefit::spec::Spec::parse(path, hostile.clone(), catalog);
            let took = t.elapsed();
            prop_assert!(took < Duration::from_secs(5), "{}: {took:?} to parse\n{hostile}", path.display());
            match result {
                Ok(_) => parsed.set(parsed.get() + 1),
                Err(err) => {
                    let msg = err.to_string();
                    let stem = path.file_name().unwrap().to_string_lossy().to_string();
                    prop_assert!(msg.contains(&stem), "{}: the error does not name the file: {msg}\n{hostile}", path.display());
                    refused.set(refused.get() + 1);
                }
            }
            Ok(())
        })
        .unwrap();
    // The pass reached both outcomes: edits that still parse (a changed number in range) and
    // ones that are refused.
    let (refused, parsed) = (refused.get(), parsed.get());
    eprintln!("spec text: {parsed} parsed, {refused} refused");
    assert!(refused > 100 && parsed > 10, "{refused} refused, {parsed} parsed");
}

/// Runs the binary in `dir` with `args` and checks the outcome is an exit of its own (0, 1
/// or 2), not a panic (101), an abort or a signal; an input error (2) names `file`.
fn exits_cleanly(dir: &Path, args: &[&str], file: &str, input: &str) -> Result<i32, TestCaseError> {
    let out = shadefit(args, Some(dir));
    let err = stderr(&out);
    let code = out.status.code();
    prop_assert!(matches!(code, Some(0..=2)), "{args:?} exited {code:?} on\n{input}\n{err}");
    if code == Some(2) {
        prop_assert!(err.contains(file), "{args:?}: the error does not name {file}: {err}\n{input}");
    }
    Ok(code.unwrap())
}

/// A CSV cell: a number in [0, 2], an extreme or malformed one, text, empty, a quote.
fn cell() -> impl Strategy<Value = String> {
    prop_oneof![
        12 => (0.0f64..2.0).prop_map(|v| format!("{v}")),
        1 => prop::sample::select(vec!["", "nan", "inf", "-inf", "1e300", "-1e300", "1e-310", "0", "x", "\"1\"", "\"", "1,", " 1 ", "1e", "--1", "0x10"]).prop_map(String::from),
    ]
}

/// `fit` on small CSV files whose header and cells are drawn from hostile vocabularies, with a
/// one- or two-column model, with and without `--emit`.
#[test]
fn fit_on_hostile_csv_rows_exits_cleanly() {
    let dir = scratch();
    let header = prop_oneof![
        4 => Just("x,y".to_string()),
        1 => prop::sample::select(vec!["x,x,y", "x", "x,y,z", ",y", "x^2,y", "x,y,", "é,y", "x;y", "", "\"x\",y"]).prop_map(String::from),
    ];
    let row = prop_oneof![6 => prop::collection::vec(cell(), 2..=2), 1 => prop::collection::vec(cell(), 1..4)];
    let rows = prop::collection::vec(row, 0..12);
    let model = prop::sample::select(vec!["rational(1,1)", "rational(2,0)", "rational(0,1)", "rational(3,3)"]);
    let emit = any::<bool>();
    let t = Instant::now();
    let codes = std::cell::RefCell::new([0usize; 3]);
    runner(300)
        .run(&(header, rows, model, emit), |(h, rows, model, emit)| {
            let text = std::iter::once(h).chain(rows.iter().map(|r| r.join(","))).collect::<Vec<_>>().join("\n") + "\n";
            let csv = dir.path().join("d.csv");
            std::fs::write(&csv, &text).unwrap();
            let mut args = vec!["fit", "--data", "d.csv", "--x", "x", "--y", "y", "--model", model];
            if emit {
                args.extend(["--emit", "out", "--name", "fuzzed", "--function", "fuzzed_fit"]);
            }
            let code = exits_cleanly(dir.path(), &args, "d.csv", &text)?;
            codes.borrow_mut()[code as usize] += 1;
            Ok(())
        })
        .unwrap();
    let codes = codes.into_inner();
    eprintln!("fit: exits 0/1/2: {codes:?}");
    // Both outcomes were reached: fits that ran and inputs refused.
    assert!(codes[0] > 5 && codes[2] > 20, "exits 0/1/2: {codes:?}");
    // 300 small fits: a few seconds; the bound says a case did not run away.
    assert!(t.elapsed() < Duration::from_secs(120), "{:?}", t.elapsed());
}

/// A small Monte Carlo table, built in 3 shards; each fuzz case corrupts one shard (its header
/// JSON or its payload, with the checksum made to match again half the time: a forged file)
/// and merges the set, which must end in an exit of the tool's own.
#[test]
fn merge_of_corrupted_shards_exits_cleanly() {
    const SPEC: &str = "name = \"msd_f\"\nkind = \"ms-diffuse-table\"\nquantity = \"ms-diffuse\"\n\
        resolution = [4, 3, 2]\npaths = 256\nalbedo_resolution = 3\nalbedo_paths = 300\n\n[emit]\nfunction = \"msd_f\"\n";
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("fits")).unwrap();
    std::fs::write(dir.path().join("fits/msd_f.toml"), SPEC).unwrap();
    for k in 0..3 {
        let out = shadefit(&["build", "--shard", &format!("{k}/3"), "--shard-dir", "shards"], Some(dir.path()));
        assert!(out.status.success(), "{}", stderr(&out));
    }
    let mut shards: Vec<std::path::PathBuf> = std::fs::read_dir(dir.path().join("shards")).unwrap().map(|e| e.unwrap().path()).collect();
    shards.sort();
    assert_eq!(shards.len(), 3);
    let original: Vec<Vec<u8>> = shards.iter().map(|p| std::fs::read(p).unwrap()).collect();
    let names: Vec<String> = shards.iter().map(|p| p.strip_prefix(dir.path()).unwrap().display().to_string()).collect();
    let (merged, refused) = (std::cell::Cell::new(0), std::cell::Cell::new(0));
    runner(150)
        .run(&(0..3usize, any::<bool>(), edits(), any::<bool>()), |(which, in_header, e, forge)| {
            for (p, b) in shards.iter().zip(&original) {
                std::fs::write(p, b).unwrap();
            }
            let bytes = &original[which];
            let mut parts: Vec<Vec<u8>> = bytes.splitn(3, |&b| b == b'\n').map(<[u8]>::to_vec).collect();
            prop_assert_eq!(parts.len(), 3);
            if in_header {
                parts[1] = mutate(&String::from_utf8_lossy(&parts[1]), &e).into_bytes();
            } else {
                // The payload's bytes: each edit flips one byte to a token's first byte.
                for &(_, pos, tok) in &e {
                    if !parts[2].is_empty() {
                        let n = parts[2].len();
                        parts[2][pos % n] = TOKENS[tok].as_bytes().first().copied().unwrap_or(0);
                    }
                }
                if forge {
                    let sum = shadefit::pipeline::sha256_hex(&parts[2]);
                    let header = String::from_utf8_lossy(&parts[1]).to_string();
                    let mut h: serde_json::Value = serde_json::from_str(&header).unwrap();
                    h["payload_sha256"] = serde_json::Value::String(sum);
                    parts[1] = serde_json::to_vec(&h).unwrap();
                }
            }
            let hostile = parts.join(&b'\n');
            std::fs::write(&shards[which], &hostile).unwrap();
            let mut args = vec!["merge"];
            args.extend(names.iter().map(String::as_str));
            let shown = String::from_utf8_lossy(&hostile[..hostile.len().min(400)]).to_string();
            match exits_cleanly(dir.path(), &args, &names[which], &shown)? {
                0 => merged.set(merged.get() + 1),
                _ => refused.set(refused.get() + 1),
            }
            Ok(())
        })
        .unwrap();
    let (refused, merged) = (refused.get(), merged.get());
    eprintln!("shards: {merged} merged, {refused} refused");
    assert!(refused > 10, "{refused} refused, {merged} merged");
}
