//! The hostile-input corpus (`tests/data/hostile.toml`): each case runs the binary in a scratch
//! project after its edits and must exit with the stated code and print the stated fragment
//! within [`CASE_LIMIT`]; bad input (exit 2) and failed jobs (exit 1) must leave generated/
//! empty and write no file anywhere in the project.

mod common;

use common::*;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::io::Read;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The wall time a case may take, process start included. Every case is checked input or a
/// small job that finishes in well under a second on one core (the slowest, a 1-D fit run to
/// its failure, about 0.3 s); 5 s leaves room for a loaded two-core machine starting the
/// process. A case past it is killed, so an input that makes the binary hang fails the test
/// instead of stalling it.
const CASE_LIMIT: Duration = Duration::from_secs(5);

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Corpus {
    case: Vec<Case>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Case {
    name: String,
    args: Vec<String>,
    exit: i32,
    stderr: Option<String>,
    stdout: Option<String>,
    /// [want, tolerance]: the first number printed after " = " on stdout is within tolerance
    /// of want (the case's comment says what bounds the tolerance).
    value: Option<[f64; 2]>,
    #[serde(default)]
    edit: Vec<Edit>,
    /// Environment variables set for the run.
    #[serde(default)]
    env: BTreeMap<String, String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Edit {
    file: String,
    replace: Option<[String; 2]>,
    text: Option<String>,
    /// The file's bytes, in hexadecimal (binary inputs such as PNGs).
    hex: Option<String>,
    #[serde(default)]
    remove: bool,
}

fn apply(dir: &Path, case: &str, e: &Edit) {
    let p = dir.join(&e.file);
    if e.text.is_some() || e.hex.is_some() {
        // A created file may lie in a folder the scratch project lacks (generated/src, another
        // fits folder).
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
    }
    match (&e.replace, &e.text, &e.hex, e.remove) {
        (Some([old, new]), None, None, false) => {
            let t = std::fs::read_to_string(&p).unwrap_or_else(|_| panic!("{case}: no {}", e.file));
            assert!(t.contains(old.as_str()), "{case}: {} does not contain {old:?}", e.file);
            std::fs::write(&p, t.replacen(old.as_str(), new, 1)).unwrap();
        }
        (None, Some(text), None, false) => std::fs::write(&p, text).unwrap(),
        (None, None, Some(hex), false) => {
            assert!(hex.len() % 2 == 0, "{case}: odd hex in {}", e.file);
            let bytes: Vec<u8> = (0..hex.len())
                .step_by(2)
                .map(|i| u8::from_str_radix(&hex[i..i + 2], 16).unwrap_or_else(|_| panic!("{case}: bad hex in {}", e.file)))
                .collect();
            std::fs::write(&p, bytes).unwrap();
        }
        (None, None, None, true) => std::fs::remove_file(&p).unwrap_or_else(|_| panic!("{case}: no {}", e.file)),
        _ => panic!("{case}: an edit takes one of replace, text, hex, remove"),
    }
}

/// The entries directly in `dir` (files and folders; none when it does not exist).
fn entries_in(dir: &Path) -> Vec<std::ffi::OsString> {
    let mut out: Vec<_> = std::fs::read_dir(dir).map(|r| r.map(|e| e.unwrap().file_name()).collect()).unwrap_or_default();
    out.sort();
    out
}

/// What a run printed and how it ended: its exit code (`None` when killed at the limit) and
/// its wall time.
struct Run {
    code: Option<i32>,
    stdout: String,
    stderr: String,
    wall: Duration,
}

/// `shadefit ARGS` in `dir` with `env`, killed if it outlives `limit`. The pipes are drained
/// on their own threads so that a chatty run cannot block on a full pipe.
fn run_within(args: &[String], dir: &Path, env: &BTreeMap<String, String>, limit: Duration) -> Run {
    let start = Instant::now();
    let mut child = Command::new(env!("CARGO_BIN_EXE_shadefit"))
        .args(args)
        .envs(env)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary starts");
    let drain = |mut r: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut b = Vec::new();
            let _ = r.read_to_end(&mut b);
            String::from_utf8_lossy(&b).into_owned()
        })
    };
    let out = drain(Box::new(child.stdout.take().unwrap()));
    let err = drain(Box::new(child.stderr.take().unwrap()));
    let code = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status.code();
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let wall = start.elapsed();
    Run { code, stdout: out.join().unwrap(), stderr: err.join().unwrap(), wall }
}

#[test]
fn every_hostile_input_gets_its_exit_code_and_message() {
    let text = std::fs::read_to_string(root().join("tests/data/hostile.toml")).unwrap();
    let corpus: Corpus = toml::from_str(&text).unwrap();
    let mut failures = Vec::new();
    for c in &corpus.case {
        let d = scratch();
        copy_dir(&root().join("fits/scenes"), &d.path().join("fits/scenes"));
        for e in &c.edit {
            apply(d.path(), &c.name, e);
        }
        let before = snapshot(d.path());
        let generated_before = entries_in(&d.path().join("generated"));
        let r = run_within(&c.args, d.path(), &c.env, CASE_LIMIT);
        let (out, err) = (&r.stdout, &r.stderr);
        let mut why = Vec::new();
        match r.code {
            None => why.push(format!("killed after {:.1} s, past the limit of {} s", r.wall.as_secs_f64(), CASE_LIMIT.as_secs())),
            Some(code) if code != c.exit => why.push(format!("exit {code}, expected {}", c.exit)),
            Some(_) => {}
        }
        if let Some(f) = &c.stderr
            && !err.contains(f.as_str())
        {
            why.push(format!("stderr lacks {f:?}"));
        }
        if let Some(f) = &c.stdout
            && !out.contains(f.as_str())
        {
            why.push(format!("stdout lacks {f:?}"));
        }
        if let Some([want, tol]) = c.value {
            let got = out.split_once(" = ").and_then(|(_, v)| v.split_whitespace().next()).and_then(|v| v.parse::<f64>().ok());
            if !got.is_some_and(|v| (v - want).abs() <= tol) {
                why.push(format!("printed {got:?}, expected {want} ± {tol:e}"));
            }
        }
        // A case's edits may put files in generated/ (an index to keep): a failed run leaves
        // generated/ with the same entries and every file with the same bytes.
        if c.exit != 0 && entries_in(&d.path().join("generated")) != generated_before {
            why.push("wrote into generated/".into());
        }
        let after = snapshot(d.path());
        if c.exit != 0 && after != before {
            let mut changed: Vec<String> =
                after.iter().filter(|f| !before.contains(f)).map(|(p, _)| p.display().to_string()).collect();
            changed.extend(
                before.iter().filter(|(p, _)| !after.iter().any(|(q, _)| q == p)).map(|(p, _)| format!("removed {}", p.display())),
            );
            why.push(format!("wrote {}", changed.join(", ")));
        }
        if !why.is_empty() {
            failures.push(format!("{} ({:.2} s): {}\n  stderr: {}", c.name, r.wall.as_secs_f64(), why.join("; "), err.trim()));
        }
    }
    println!("{} hostile inputs", corpus.case.len());
    assert!(corpus.case.len() >= 50, "the corpus shrank to {}", corpus.case.len());
    assert!(failures.is_empty(), "{} of {} cases failed:\n{}", failures.len(), corpus.case.len(), failures.join("\n"));
}
