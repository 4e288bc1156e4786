//! What differs from the files under generated/, and what no spec writes there any more.

use super::*;

/// Compare artifacts with the files under `root`: the paths that differ or are missing.
pub fn stale(root: &Path, artifacts: &[Artifact]) -> Vec<String> {
    artifacts
        .iter()
        .filter(|a| std::fs::read(root.join(&a.path)).map_or(true, |old| old != a.contents))
        .map(|a| a.path.display().to_string())
        .collect()
}

/// Hand-written files of the runtime crate under generated/src (never reported as orphans).
pub const HAND_WRITTEN: &[&str] = &["src/lib.rs"];

/// The folders under generated/ every build writes (other targets add theirs).
pub const OUTPUT_DIRS: &[&str] = &["wgsl", "src", "json", "data"];

/// Files under generated/{wgsl,src,json,data} that no spec produces (directories below
/// generated/src, and the files in [`HAND_WRITTEN`], are the runtime crate's own code).
pub fn orphans(root: &Path, artifacts: &[Artifact]) -> Vec<String> {
    orphans_in(root, artifacts, OUTPUT_DIRS)
}

/// Files directly under the folders `dirs` of generated/ that no artifact is (see [`orphans`]).
pub fn orphans_in(root: &Path, artifacts: &[Artifact], dirs: &[&str]) -> Vec<String> {
    let mut out = Vec::new();
    for &dir in dirs {
        let Ok(rd) = std::fs::read_dir(root.join(dir)) else { continue };
        let mut names: Vec<_> = rd.filter_map(|e| e.ok()).map(|e| e.path()).collect();
        names.sort();
        for p in names {
            let rel = p.strip_prefix(root).unwrap_or(&p).to_path_buf();
            let hand_written = HAND_WRITTEN.iter().any(|h| rel == Path::new(h));
            if p.is_file() && !hand_written && !artifacts.iter().any(|a| a.path == rel) {
                out.push(rel.display().to_string());
            }
        }
    }
    out
}
