//! Helpers shared by the binary's integration tests (each test file uses a subset).
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub fn shadefit(args: &[&str], dir: Option<&Path>) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_shadefit"));
    // `validate`'s cache in the build's scratch folder, not the user's.
    c.args(args).env("SHADEFIT_CACHE", Path::new(env!("CARGO_TARGET_TMPDIR")).join("shadefit-cache"));
    if let Some(d) = dir {
        c.current_dir(d);
    }
    c.output().expect("the binary runs")
}

/// `shadefit ARGS` in a scratch copy of fits/ (plus `setup`) with RAYON_NUM_THREADS = `threads`:
/// what it wrote under generated/.
pub fn build_snapshot(args: &[&str], threads: &str, setup: impl Fn(&Path)) -> Vec<(PathBuf, Vec<u8>)> {
    let d = scratch();
    setup(d.path());
    let o = Command::new(env!("CARGO_BIN_EXE_shadefit"))
        .args(args)
        .current_dir(d.path())
        .env("RAYON_NUM_THREADS", threads)
        .output()
        .expect("the binary runs");
    assert!(o.status.success(), "{}", stderr(&o));
    snapshot(&d.path().join("generated"))
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A scratch project: a copy of fits/ plus an empty generated/ folder.
pub fn scratch() -> tempfile::TempDir {
    let d = tempfile::tempdir().unwrap();
    std::fs::create_dir(d.path().join("fits")).unwrap();
    for e in std::fs::read_dir(root().join("fits")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "toml") {
            std::fs::copy(&p, d.path().join("fits").join(p.file_name().unwrap())).unwrap();
        }
    }
    d
}

pub fn assert_nothing_written(d: &Path) {
    let g = d.join("generated");
    let n = std::fs::read_dir(&g).map(|r| r.count()).unwrap_or(0);
    assert_eq!(n, 0, "a failed build must write nothing");
}

pub fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            copy_dir(&p, &to.join(p.file_name().unwrap()));
        } else {
            std::fs::copy(&p, to.join(p.file_name().unwrap())).unwrap();
        }
    }
}

pub fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.push((p.strip_prefix(dir).unwrap().to_path_buf(), std::fs::read(&p).unwrap()));
            }
        }
    }
    out.sort();
    out
}

/// NIST StRD data set NAME (tests/data/nist/NAME.dat) as a CSV with columns x, y in `dir`.
pub fn nist_csv(name: &str, dir: &Path) -> PathBuf {
    // NIST StRD .dat: data rows after the "Data:  y  x" line; columns y then x.
    let text = std::fs::read_to_string(root().join("tests/data/nist").join(format!("{name}.dat")))
        .expect("NIST data in tests/data/nist");
    let mut csv = String::from("x,y\n");
    let mut on = false;
    for line in text.lines() {
        let cols: Vec<&str> = line.split_whitespace().collect();
        if on && cols.len() == 2 {
            csv.push_str(&format!("{},{}\n", cols[1], cols[0]));
        }
        if line.starts_with("Data:") && cols.get(1) == Some(&"y") {
            on = true;
        }
    }
    let p = dir.join(format!("{name}.csv"));
    std::fs::write(&p, csv).unwrap();
    p
}

/// Every committed WGSL module of generated/wgsl (name, text), in name order.
pub fn committed_modules() -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = std::fs::read_dir(root().join("generated/wgsl"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "wgsl"))
        .map(|p| (p.file_stem().unwrap().to_string_lossy().into_owned(), std::fs::read_to_string(&p).unwrap()))
        .collect();
    out.sort();
    assert!(out.len() >= 20, "the committed modules ({})", out.len());
    out
}

/// A KTX2 level's texel bytes as the `ktx2` crate gives them, Zstandard levels inflated by
/// `ruzstd` (frames back to back: a level may hold more than one); the level index's
/// uncompressedByteLength checked for either scheme.
pub fn ktx2_level_bytes(name: &str, scheme: Option<ktx2::SupercompressionScheme>, level: &ktx2::Level) -> Vec<u8> {
    use std::io::Read;
    let data = match scheme {
        None => level.data.to_vec(),
        Some(ktx2::SupercompressionScheme::Zstandard) => {
            let (mut src, mut out) = (level.data, Vec::new());
            while !src.is_empty() {
                let mut frame = ruzstd::decoding::StreamingDecoder::new(&mut src).expect("a zstd frame header");
                frame.read_to_end(&mut out).expect("a whole zstd frame");
            }
            out
        }
        Some(s) => panic!("{name}: supercompression {s:?} is neither none nor zstd"),
    };
    assert_eq!(data.len() as u64, level.uncompressed_byte_length, "{name}: uncompressedByteLength");
    data
}
