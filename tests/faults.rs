//! Faults while a build writes generated/: an injected I/O failure at every swap, a kill at every
//! swap, and two builds at once. Afterwards generated/ is entirely old or entirely new, nothing
//! is left behind, and `build --check` says which.

mod common;

use common::*;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Every file under generated/ with its bytes.
fn files(d: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    snapshot(&d.join("generated"))
}

/// A project with the committed generated/ and a gloss table spec edited, so that a build
/// replaces its files (and the runtime index, which lists the scenes of fits/scenes too, keeps
/// its bytes).
fn project() -> tempfile::TempDir {
    let d = scratch();
    copy_dir(&root().join("fits/scenes"), &d.path().join("fits/scenes"));
    copy_dir(&root().join("generated"), &d.path().join("generated"));
    let p = d.path().join("fits/gloss_table.toml");
    let t = std::fs::read_to_string(&p).unwrap().replace("count = 256", "count = 128");
    std::fs::write(&p, t).unwrap();
    d
}

fn build(d: &Path, env: &[(&str, String)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_shadefit"));
    c.args(["build", "--only", "gloss_table"]).current_dir(d);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().unwrap()
}

/// Old and new states of generated/ and the number of files the build replaces.
fn states() -> (Vec<(PathBuf, Vec<u8>)>, Vec<(PathBuf, Vec<u8>)>, usize) {
    let d = project();
    let old = files(d.path());
    let o = build(d.path(), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let new = files(d.path());
    let changed = new.iter().filter(|f| !old.contains(f)).count();
    assert!(changed >= 3, "the edit must replace several files (csv, json, wgsl, rs): {changed}");
    assert!(!d.path().join("generated/.staging").exists());
    (old, new, changed)
}

#[test]
fn an_injected_write_failure_at_any_swap_leaves_the_old_files() {
    let (old, _, changed) = states();
    for k in 0..changed {
        let d = project();
        let o = build(d.path(), &[("SHADEFIT_FAULT_AFTER_SWAPS", k.to_string())]);
        assert_eq!(o.status.code(), Some(1), "fault after {k} swaps: {}", stderr(&o));
        assert!(stderr(&o).contains("injected write failure"), "{}", stderr(&o));
        assert!(files(d.path()) == old, "fault after {k} swaps: generated/ changed");
        assert!(!d.path().join("generated/.staging").exists(), "fault after {k} swaps: staging left");
    }
}

#[test]
fn a_kill_at_any_swap_is_undone_by_the_next_build() {
    let (old, new, changed) = states();
    for k in 0..changed {
        let d = project();
        let o = build(d.path(), &[("SHADEFIT_ABORT_AFTER_SWAPS", k.to_string())]);
        assert!(!o.status.success(), "abort after {k} swaps");
        // The killed build left its journal: --check says so.
        let c = shadefit(&["build", "--check", "--only", "gloss_table"], Some(d.path()));
        assert_eq!(c.status.code(), Some(1), "{}", stderr(&c));
        assert!(stderr(&c).contains("interrupted build"), "abort after {k}: {}", stderr(&c));
        // The next build first restores the old files, then writes the new ones whole.
        let o = build(d.path(), &[("SHADEFIT_FAULT_AFTER_SWAPS", "0".into())]);
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        assert!(files(d.path()) == old, "abort after {k} swaps: not restored to the old files");
        let o = build(d.path(), &[]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(files(d.path()) == new, "abort after {k} swaps: the rebuild differs");
    }
}

#[test]
fn two_builds_at_once_both_succeed_and_agree() {
    let (_, new, _) = states();
    let d = project();
    let spawn = || {
        Command::new(env!("CARGO_BIN_EXE_shadefit"))
            .args(["build", "--only", "gloss_table"])
            .current_dir(d.path())
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap()
    };
    let (a, b) = (spawn(), spawn());
    for o in [a.wait_with_output().unwrap(), b.wait_with_output().unwrap()] {
        assert!(o.status.success(), "{}", stderr(&o));
    }
    assert!(files(d.path()) == new);
    assert!(!d.path().join("generated/.staging").exists());
    let c = shadefit(&["build", "--check", "--only", "gloss_table"], Some(d.path()));
    assert!(c.status.success(), "{}", stderr(&c));
}
