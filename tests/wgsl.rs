//! naga parses and validates every emitted WGSL file (no GPU needed).

use std::path::PathBuf;

#[test]
fn every_emitted_wgsl_file_validates() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("generated/wgsl");
    let mut n = 0;
    let mut entries: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
    entries.sort();
    for p in entries.iter().filter(|p| p.extension().is_some_and(|e| e == "wgsl")) {
        let src = std::fs::read_to_string(p).unwrap();
        let first = src.lines().find(|l| l.starts_with('#')).unwrap_or("");
        let stem = p.file_stem().unwrap().to_str().unwrap();
        assert_eq!(first, format!("#define_import_path shadefit::{stem}"), "{} names itself", p.display());
        let stripped = shadefit::emit::wgsl::strip_directives(&src);
        let module = naga::front::wgsl::parse_str(&stripped)
            .unwrap_or_else(|e| panic!("{}: {}", p.display(), e.emit_to_string(&stripped)));
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
            .validate(&module)
            .unwrap_or_else(|e| panic!("{}: {e:?}", p.display()));
        n += 1;
    }
    assert!(n >= 5, "expected the gloss family's files, found {n}");
}
