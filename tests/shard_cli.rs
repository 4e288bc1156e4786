//! `build --shard K/N` and `merge`: N shard processes run side by side, merged, give exactly the
//! bytes of one build; bad shard sets are the user's input (exit 2) and write nothing.

mod common;

use common::snapshot as files;
use std::path::Path;
use std::process::Command;

const SPEC: &str = "name = \"msd_s\"\nkind = \"ms-diffuse-table\"\nquantity = \"ms-diffuse\"\n\
    resolution = [6, 5, 2]\npaths = 512\nalbedo_resolution = 3\nalbedo_paths = 300\n\n[emit]\nfunction = \"msd_s\"\n";

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_shadefit"))
}

fn project(spec: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("fits")).unwrap();
    std::fs::write(dir.path().join("fits/msd_s.toml"), spec).unwrap();
    dir
}

fn run(dir: &Path, args: &[&str]) -> std::process::Output {
    bin().current_dir(dir).args(args).output().unwrap()
}

#[test]
fn shards_merged_are_the_single_build_byte_for_byte() {
    let one = project(SPEC);
    let r = run(one.path(), &["build"]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let want = files(&one.path().join("generated"));
    assert!(want.iter().any(|(p, _)| p.ends_with("json/msd_s.json")));

    for n in [1u64, 3, 7] {
        let many = project(SPEC);
        // N processes at once, as an array job runs them (one thread each).
        let children: Vec<_> = (0..n)
            .map(|k| {
                bin()
                    .current_dir(many.path())
                    .env("RAYON_NUM_THREADS", "1")
                    .args(["build", "--shard", &format!("{k}/{n}"), "--shard-dir", "shards"])
                    .spawn()
                    .unwrap()
            })
            .collect();
        for mut c in children {
            assert!(c.wait().unwrap().success());
        }
        assert!(!many.path().join("generated/json").exists(), "--shard writes nothing under generated/");
        let mut shards: Vec<String> = std::fs::read_dir(many.path().join("shards")).unwrap().map(|e| e.unwrap().path().display().to_string()).collect();
        shards.sort();
        shards.reverse(); // merge sorts them itself
        assert_eq!(shards.len() as u64, n);
        let mut args = vec!["merge".to_string()];
        args.extend(shards);
        let r = bin().current_dir(many.path()).args(&args).output().unwrap();
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        let got = files(&many.path().join("generated"));
        assert_eq!(got.len(), want.len());
        for ((pa, a), (pb, b)) in want.iter().zip(&got) {
            assert!(pa == pb && a == b, "{} differs after merging {n} shards", pa.display());
        }
    }
}

#[test]
fn bad_shard_sets_are_input_errors_and_write_nothing() {
    let p = project(SPEC);
    for k in 0..3 {
        assert!(run(p.path(), &["build", "--shard", &format!("{k}/3")]).status.success());
    }
    let shard = |k: u64| format!("shards/msd_s.{k}-of-3.shard");
    let expect_2 = |args: &[&str], fragment: &str| {
        let r = run(p.path(), args);
        let err = String::from_utf8_lossy(&r.stderr).to_string();
        assert_eq!(r.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(fragment), "{args:?}: {err}");
        assert!(!p.path().join("generated/json").exists(), "{args:?} wrote files");
    };
    expect_2(&["merge", &shard(0), &shard(2)], "shard 1 is missing");
    expect_2(&["merge", &shard(0), &shard(1)], "2 of 3 shards given");
    expect_2(&["merge", &shard(0), &shard(1), &shard(1)], "shard 1 is given twice");
    expect_2(&["merge", &shard(0), &shard(1), &shard(1), &shard(2)], "shard 1 is given twice");
    // Header fields that do not belong: another generator, three cell bounds.
    for (from, to, fragment) in [("\"generator\":\"shadefit ", "\"generator\":\"shadefit 9", "run its shards again"), ("\"cells\":[", "\"cells\":[0,", "'cells'")] {
        let bytes = std::fs::read(p.path().join(shard(0))).unwrap();
        // The magic and header lines are text; the payload after them is kept byte for byte.
        let end = bytes.iter().enumerate().filter(|(_, b)| **b == b'\n').nth(1).unwrap().0;
        let head = String::from_utf8(bytes[..end].to_vec()).unwrap();
        assert!(head.contains(from), "{from} is not in the header {head}");
        let mut edited = head.replacen(from, to, 1).into_bytes();
        edited.extend_from_slice(&bytes[end..]);
        std::fs::write(p.path().join("shards/edited.shard"), edited).unwrap();
        expect_2(&["merge", "shards/edited.shard", &shard(1), &shard(2)], fragment);
    }
    expect_2(&["build", "--shard", "3/3"], "0 <= K < N");
    expect_2(&["build", "--shard", "x"], "K/N");
    std::fs::write(p.path().join("shards/junk.shard"), "not a shard\n").unwrap();
    expect_2(&["merge", "shards/junk.shard"], "not a shard file");
    // A shard of an edited spec is stale.
    std::fs::write(p.path().join("fits/msd_s.toml"), SPEC.replace("paths = 512", "paths = 600")).unwrap();
    expect_2(&["merge", &shard(0), &shard(1), &shard(2)], "another version");
}

/// `merge` builds from the shards' cells, not by computing them again: a shard whose first
/// cell's value is changed in its payload (one mantissa bit, the payload's size kept) is refused
/// for its checksum; with the checksum of the changed payload it merges into a JSON that differs
/// from the single build's, and only in that value.
#[test]
fn merge_builds_from_the_shards_cells() {
    let one = project(SPEC);
    assert!(run(one.path(), &["build"]).status.success());
    let want = std::fs::read_to_string(one.path().join("generated/json/msd_s.json")).unwrap();
    let many = project(SPEC);
    assert!(run(many.path(), &["build", "--shard", "0/1", "--shard-dir", "shards"]).status.success());
    let path = std::fs::read_dir(many.path().join("shards")).unwrap().next().unwrap().unwrap().path();
    let mut bytes = std::fs::read(&path).unwrap();
    // The payload follows the magic line and the JSON header; a cell is its value then its
    // standard error, f64 little-endian: byte 2 holds mantissa bits 16..23 of the value (bit 20:
    // a relative change of 2^-32).
    let start = bytes.iter().enumerate().filter(|(_, b)| **b == b'\n').nth(1).unwrap().0 + 1;
    let cell = f64::from_le_bytes(bytes[start..start + 8].try_into().unwrap());
    bytes[start + 2] ^= 0x10;
    let changed = f64::from_le_bytes(bytes[start..start + 8].try_into().unwrap());
    assert!(changed != cell && (changed - cell).abs() <= 2f64.powi(-31) * cell.abs(), "{cell} → {changed}");
    std::fs::write(&path, &bytes).unwrap();
    // The payload's checksum no longer matches: refused, naming the file.
    let r = run(many.path(), &["merge", path.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&r.stderr).to_string();
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(err.contains("checksum") && err.contains(&path.file_name().unwrap().to_string_lossy().to_string()), "{err}");
    // With the checksum of the changed payload in the header, the changed cell is merged.
    use sha2::Digest;
    let header_end = start - 1;
    let header_start = bytes.iter().position(|b| *b == b'\n').unwrap() + 1;
    let header: serde_json::Value = serde_json::from_slice(&bytes[header_start..header_end]).unwrap();
    // The shard file of these bytes with its header's checksum made to match their payload.
    let rechecksummed = |b: &[u8]| -> Vec<u8> {
        let mut h = header.clone();
        let sum: String = sha2::Sha256::digest(&b[start..]).iter().map(|x| format!("{x:02x}")).collect();
        h["payload_sha256"] = serde_json::json!(sum);
        let mut out = b[..header_start].to_vec();
        out.extend(h.to_string().into_bytes());
        out.extend(&b[header_end..]);
        out
    };
    std::fs::write(&path, rechecksummed(&bytes)).unwrap();
    let r = run(many.path(), &["merge", path.to_str().unwrap()]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let got = std::fs::read_to_string(many.path().join("generated/json/msd_s.json")).unwrap();
    assert_ne!(got, want, "the merged build ignored the shard's cells");
    assert!(got.contains(&format!("{changed:?}")) && !want.contains(&format!("{changed:?}")), "the changed cell {changed:?} is not in the merged JSON");
    // A forged NaN cell (its checksum recomputed) passes the shard checks; the merged build then
    // fails (exit 1), naming the shard files it was merging, and writes nothing new.
    let before = files(&many.path().join("generated"));
    let mut forged = bytes.clone();
    forged[start..start + 8].copy_from_slice(&f64::NAN.to_le_bytes());
    std::fs::write(&path, rechecksummed(&forged)).unwrap();
    let r = run(many.path(), &["merge", path.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&r.stderr).to_string();
    assert_eq!(r.status.code(), Some(1), "{err}");
    assert!(err.contains(&format!("merging {}", path.display())), "{err}");
    assert_eq!(files(&many.path().join("generated")), before, "a failed merge wrote files");
}
