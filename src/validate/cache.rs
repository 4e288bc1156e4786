//! `validate`'s cache: each section of the report (one family's items, or one form spec's item)
//! stored under a key that names everything it was computed from — the running executable's
//! bytes (so any change of code, registered constants or embedded published tables misses) and
//! every spec and committed JSON a section can read (`fits/*.toml`, the `fits/` beside
//! `generated/`, and `generated/json/`). The measures are deterministic, so a hit prints what a
//! fresh run would, byte for byte; `--no-cache` recomputes (and rewrites) every section.
//!
//! The cache lives in `$SHADEFIT_CACHE/validate`, else `$XDG_CACHE_HOME/shadefit/validate`,
//! else `~/.cache/shadefit/validate`. Entries are written to a temporary file and renamed; an
//! unreadable, unparsable or unwritable entry is a miss, never an error.

use super::Item;
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// The folder of the cache entries, when one can be named.
pub fn dir() -> Option<PathBuf> {
    let var = |k: &str| std::env::var_os(k).filter(|v| !v.is_empty()).map(PathBuf::from);
    var("SHADEFIT_CACHE")
        .or_else(|| var("XDG_CACHE_HOME").map(|d| d.join("shadefit")))
        .or_else(|| var("HOME").map(|d| d.join(".cache").join("shadefit")))
        .map(|d| d.join("validate"))
}

/// The files under `dir` (recursively) whose name ends in one of `exts`, sorted.
fn files(dir: &Path, exts: &[&str], out: &mut Vec<PathBuf>) {
    let Ok(rd) = std::fs::read_dir(dir) else { return };
    let mut entries: Vec<PathBuf> = rd.filter_map(|e| e.ok().map(|e| e.path())).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            files(&p, exts, out);
        } else if p.extension().and_then(|e| e.to_str()).is_some_and(|e| exts.contains(&e)) {
            out.push(p);
        }
    }
}

/// The digest every key of one run starts from: the executable and the inputs (`None` when the
/// executable cannot be read: then nothing is cached).
pub fn base(fits: &Path, generated: &Path) -> Option<String> {
    let exe = std::fs::read(std::env::current_exe().ok()?).ok()?;
    let mut h = Sha256::new();
    h.update(b"shadefit validate cache 1\n");
    h.update(Sha256::digest(&exe));
    let mut inputs = Vec::new();
    files(fits, &["toml"], &mut inputs);
    if let Some(beside) = generated.parent().map(|p| p.join("fits")) {
        files(&beside, &["toml"], &mut inputs);
    }
    files(&generated.join("json"), &["json"], &mut inputs);
    for p in inputs {
        let bytes = std::fs::read(&p).ok()?;
        h.update(format!("\n{}\n{}\n", p.display(), bytes.len()).as_bytes());
        h.update(&bytes);
    }
    Some(crate::pipeline::hex(&h.finalize()))
}

/// The entry of one section (`family:NAME` or `form:NAME`).
fn entry(dir: &Path, base: &str, section: &str) -> PathBuf {
    let key = crate::pipeline::hex(&Sha256::digest(format!("{base}\n{section}").as_bytes()));
    dir.join(format!("{key}.json"))
}

/// The cached items of a section, if any.
pub fn read(dir: &Path, base: &str, section: &str) -> Option<Vec<Item>> {
    serde_json::from_slice(&std::fs::read(entry(dir, base, section)).ok()?).ok()
}

/// Store a section's items (a failure is silent: the next run recomputes). Items that would not
/// read back as they are (a NaN or an infinity, which JSON cannot hold) are not stored.
pub fn write(dir: &Path, base: &str, section: &str, items: &[Item]) {
    let Ok(text) = serde_json::to_vec(items) else { return };
    if serde_json::from_slice::<Vec<Item>>(&text).ok().as_deref() != Some(items) {
        return;
    }
    let path = entry(dir, base, section);
    let Ok(()) = std::fs::create_dir_all(dir) else { return };
    let Ok(mut tmp) = tempfile::NamedTempFile::new_in(dir) else { return };
    if std::io::Write::write_all(&mut tmp, &text).is_ok() {
        let _ = tmp.persist(path);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn item(v: f64) -> Item {
        Item {
            name: "n".into(),
            source: "s".into(),
            domain: "d".into(),
            points: 3,
            max_abs_error: v,
            rms_error: 0.1,
            worst_point: vec![0.25, 1.0 / 3.0],
            extra: vec![("x".into(), 1e-300)],
            findings: vec!["f".into()],
        }
    }

    /// A stored section reads back equal (every f64 to the bit); another section or another base
    /// misses; a NaN item is not stored.
    #[test]
    fn a_section_reads_back_as_stored_and_only_under_its_key() {
        let d = tempfile::tempdir().unwrap();
        let items = vec![item(0.1 + 0.2), item(5e-324)];
        write(d.path(), "b", "family:x", &items);
        assert_eq!(read(d.path(), "b", "family:x"), Some(items));
        assert_eq!(read(d.path(), "b", "family:y"), None);
        assert_eq!(read(d.path(), "c", "family:x"), None);
        write(d.path(), "b", "family:nan", &[item(f64::NAN)]);
        assert_eq!(read(d.path(), "b", "family:nan"), None);
    }

    /// The base changes with any input file's bytes, and with a new input file.
    #[test]
    fn the_base_names_every_input() {
        let d = tempfile::tempdir().unwrap();
        let (fits, generated) = (d.path().join("fits"), d.path().join("generated"));
        std::fs::create_dir_all(generated.join("json")).unwrap();
        std::fs::create_dir_all(&fits).unwrap();
        std::fs::write(fits.join("a.toml"), "x = 1").unwrap();
        let b0 = base(&fits, &generated).unwrap();
        assert_eq!(base(&fits, &generated).unwrap(), b0);
        std::fs::write(fits.join("a.toml"), "x = 2").unwrap();
        let b1 = base(&fits, &generated).unwrap();
        assert_ne!(b1, b0);
        std::fs::write(generated.join("json/t.json"), "{}").unwrap();
        assert_ne!(base(&fits, &generated).unwrap(), b1);
    }
}
