//! The hostile-input corpus (`tests/data/hostile.toml`): each case runs the binary in a scratch
//! project after its edits and must exit with the stated code and print the stated fragment;
//! bad input (exit 2) and failed jobs (exit 1) must leave generated/ empty.

mod common;

use common::*;
use serde::Deserialize;
use std::path::Path;

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
    #[serde(default)]
    edit: Vec<Edit>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Edit {
    file: String,
    replace: Option<[String; 2]>,
    text: Option<String>,
    #[serde(default)]
    remove: bool,
}

fn apply(dir: &Path, case: &str, e: &Edit) {
    let p = dir.join(&e.file);
    match (&e.replace, &e.text, e.remove) {
        (Some([old, new]), None, false) => {
            let t = std::fs::read_to_string(&p).unwrap_or_else(|_| panic!("{case}: no {}", e.file));
            assert!(t.contains(old.as_str()), "{case}: {} does not contain {old:?}", e.file);
            std::fs::write(&p, t.replacen(old.as_str(), new, 1)).unwrap();
        }
        (None, Some(text), false) => std::fs::write(&p, text).unwrap(),
        (None, None, true) => std::fs::remove_file(&p).unwrap_or_else(|_| panic!("{case}: no {}", e.file)),
        _ => panic!("{case}: an edit takes one of replace, text, remove"),
    }
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
        let args: Vec<&str> = c.args.iter().map(String::as_str).collect();
        let o = shadefit(&args, Some(d.path()));
        let (out, err) = (String::from_utf8_lossy(&o.stdout), stderr(&o));
        let mut why = Vec::new();
        if o.status.code() != Some(c.exit) {
            why.push(format!("exit {:?}, expected {}", o.status.code(), c.exit));
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
        if c.exit != 0 && std::fs::read_dir(d.path().join("generated")).map(|r| r.count()).unwrap_or(0) != 0 {
            why.push("wrote into generated/".into());
        }
        if !why.is_empty() {
            failures.push(format!("{}: {}\n  stderr: {}", c.name, why.join("; "), err.trim()));
        }
    }
    println!("{} hostile inputs", corpus.case.len());
    assert!(corpus.case.len() >= 50, "the corpus shrank to {}", corpus.case.len());
    assert!(failures.is_empty(), "{} of {} cases failed:\n{}", failures.len(), corpus.case.len(), failures.join("\n"));
}
