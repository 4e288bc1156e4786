//! Every committed KTX2 file (`generated/data/*.ktx2`) loads in two loaders written elsewhere, and
//! each reads what the `ktx2` crate reads:
//! - libktx, Khronos's reference library (KTX-Software v4.0.0, tests/loaders/libktx), loading the
//!   image data (it inflates zstd itself);
//! - ktx-parse, the parser of three.js's KTX2Loader (tests/loaders/ktx-parse), with zstd levels
//!   inflated by fzstd;
//! - for each file: vkFormat, width, height, depth, layers, faces, levels and the
//!   supercompression scheme equal the header fields the `ktx2` crate parses, and each level's
//!   SHA-256 equals that of the level bytes the `ktx2` crate returns (inflated with `ruzstd`
//!   where the file says zstd): byte equality, no tolerance;
//! - each loader sees every file of the folder, once.
//!
//! The loaders come from `bash scripts/setup-ktx-loaders`; without them a test skips with a note,
//! except under CI=true, where it fails.

mod common;

use common::{root, stderr};
use serde_json::{json, Value};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

const HINT: &str = "bash scripts/setup-ktx-loaders builds them";

/// Every committed KTX2 file, in name order.
fn ktx2_files() -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(root().join("generated/data"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "ktx2"))
        .collect();
    out.sort();
    assert!(out.len() >= 20, "the committed KTX2 files ({})", out.len());
    out
}

/// A loader that is not set up: a note outside CI, a failure under CI=true.
fn skip(what: &str) {
    assert!(!std::env::var("CI").is_ok_and(|v| v == "true"), "{what} is not set up, and CI runs every loader ({HINT})");
    eprintln!("note: {what} is not set up; skipping its check ({HINT})");
}

/// The line a loader must print for `path`, from the `ktx2` crate.
fn expected(path: &Path) -> Value {
    let name = path.file_name().unwrap().to_string_lossy().into_owned();
    let bytes = std::fs::read(path).unwrap();
    let r = ktx2::Reader::new(&bytes[..]).unwrap_or_else(|e| panic!("{name}: the ktx2 crate: {e:?}"));
    let h = r.header();
    let scheme = h.supercompression_scheme.map_or(0, |s| s.value());
    let level_sha256: Vec<String> = r
        .levels()
        .enumerate()
        .map(|(i, l)| format!("{:x}", Sha256::digest(common::ktx2_level_bytes(&format!("{name} level {i}"), h.supercompression_scheme, &l))))
        .collect();
    json!({
        "file": name,
        "vkFormat": h.format.map_or(0, |f| f.value()),
        "width": h.pixel_width,
        "height": h.pixel_height,
        "depth": h.pixel_depth,
        "layers": h.layer_count,
        "faces": h.face_count,
        "levels": h.level_count,
        "supercompression": scheme,
        "level_sha256": level_sha256,
    })
}

/// Runs `cmd` on every committed KTX2 file at once and compares its lines with `expected`.
fn check_loader(what: &str, mut cmd: Command) {
    let files = ktx2_files();
    let o = cmd.args(&files).output().unwrap_or_else(|e| panic!("{what}: {e}"));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{what} refused a file:\n{out}{}", stderr(&o));
    let mut seen: BTreeMap<String, Value> = BTreeMap::new();
    for line in out.lines() {
        let v: Value = serde_json::from_str(line).unwrap_or_else(|e| panic!("{what}: {e}: {line}"));
        let name = v["file"].as_str().unwrap_or_else(|| panic!("{what}: no file name: {line}")).to_string();
        assert!(seen.insert(name.clone(), v).is_none(), "{what}: {name} twice");
    }
    assert_eq!(seen.len(), files.len(), "{what}: one line per file");
    for f in &files {
        let want = expected(f);
        let name = want["file"].as_str().unwrap();
        let got = seen.get(name).unwrap_or_else(|| panic!("{what}: no line for {name}"));
        // Whole-object equality, no tolerance: every header field, every level hash (of the bytes),
        // no field more or less.
        assert_eq!(got, &want, "{what} on {name} (left) against the ktx2 crate (right)");
    }
    eprintln!("{what}: {} KTX2 files read as the ktx2 crate reads them", files.len());
}

#[test]
fn libktx_reads_every_committed_ktx2_file() {
    let bin = root().join("target/loaders/debug/libktx-check");
    if !bin.is_file() {
        return skip("libktx (target/loaders/debug/libktx-check)");
    }
    check_loader("libktx", Command::new(bin));
}

#[test]
fn ktx_parse_reads_every_committed_ktx2_file() {
    let dir = root().join("tests/loaders/ktx-parse");
    let node = Command::new("node").arg("--version").output().is_ok_and(|o| o.status.success());
    if !node || !["ktx-parse", "fzstd"].iter().all(|m| dir.join("node_modules").join(m).join("package.json").is_file()) {
        return skip("ktx-parse (node and tests/loaders/ktx-parse/node_modules)");
    }
    let mut cmd = Command::new("node");
    cmd.arg(dir.join("check.mjs"));
    check_loader("ktx-parse", cmd);
}
