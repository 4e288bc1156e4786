//! The WESL package (`build --target wesl`, src/emit/targets.rs), linked with bevy's wesl version
//! (0.4.2): every committed module of
//! generated/wgsl as `wesl/NAME.wesl` plus `wesl/wesl.toml`, written to a folder and resolved
//! by wesl-rs (the WESL reference compiler in Rust) as the external package `shadefit`: a root
//! shader imports every module (`import shadefit::NAME;`) and calls every function of each as
//! `NAME::f(..)`; the linked WGSL validates in naga with every function present.

mod common;

#[path = "../generated/tests/support/calls.rs"]
mod calls;

use common::committed_modules as modules;
use shadefit::emit::targets::{package_files, translate, Target};
use std::path::Path;
use wesl::syntax::{ModulePath, PathOrigin};
use wesl::{FileResolver, Router, Wesl};

/// The package as `build --target wesl` writes it, under `dir`.
fn write_package(dir: &Path) -> Vec<(String, String)> {
    let mut files = Vec::new();
    for (name, text) in modules() {
        let arts = translate(&name, &text, &[Target::Wesl]).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(arts.len(), 1);
        assert_eq!(arts[0].path, Path::new("wesl").join(format!("{name}.wesl")));
        files.push((name, String::from_utf8(arts[0].contents.clone()).unwrap()));
    }
    let mut all = files.iter().map(|(n, t)| (Path::new("wesl").join(format!("{n}.wesl")), t.as_bytes().to_vec())).collect::<Vec<_>>();
    all.extend(package_files(&[Target::Wesl]).into_iter().map(|a| (a.path, a.contents)));
    for (p, bytes) in all {
        let p = dir.join(p);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, bytes).unwrap();
    }
    files
}

#[test]
fn wesl_resolves_the_package_and_every_function_links() {
    let d = tempfile::tempdir().unwrap();
    let files = write_package(d.path());
    let libs: Vec<(&str, &str)> = files.iter().map(|(n, t)| (n.as_str(), t.as_str())).collect();
    let main = calls::every_function(&libs, calls::Style::Wesl);
    let app = d.path().join("app");
    std::fs::create_dir(&app).unwrap();
    std::fs::write(app.join("main.wesl"), &main).unwrap();

    let mut router = Router::new();
    router.mount_resolver(ModulePath::new(PathOrigin::Package("shadefit".into()), vec![]), FileResolver::new(d.path().join("wesl")));
    router.mount_fallback_resolver(FileResolver::new(&app));
    // The spec's mandatory extensions (imports, conditional translation) and stripping.
    let compiler = Wesl::new(&app).set_custom_resolver(router);
    let out = compiler
        .compile(&"package::main".parse().unwrap())
        .unwrap_or_else(|e| panic!("{e}\n{main}"))
        .to_string();
    let m = calls::validate("the linked WESL", &out);
    let emitted: usize = libs.iter().map(|(_, s)| naga::front::wgsl::parse_str(&calls::plain(s)).unwrap().functions.len()).sum();
    assert!(m.functions.len() >= emitted, "{} functions linked, {emitted} emitted", m.functions.len());
    assert_eq!(m.entry_points.len(), 1);
}

#[test]
fn the_manifest_follows_the_wesl_toml_format() {
    // https://wesl-lang.dev/spec/WeslToml: a [package] table with the edition (mandatory) and
    // the root of `package::`; the include globs must match the module files.
    let d = tempfile::tempdir().unwrap();
    let files = write_package(d.path());
    let text = std::fs::read_to_string(d.path().join("wesl/wesl.toml")).unwrap();
    let t: toml::Table = toml::from_str(&text).unwrap();
    let p = t["package"].as_table().unwrap();
    assert_eq!(p["edition"].as_str(), Some("2026_pre"));
    let root = d.path().join("wesl").join(p["root"].as_str().unwrap());
    let include: Vec<&str> = p["include"].as_array().unwrap().iter().map(|v| v.as_str().unwrap()).collect();
    assert_eq!(include, ["*.wesl"]);
    for (name, _) in &files {
        assert!(root.join(format!("{name}.wesl")).is_file(), "{name}");
    }
    assert!(package_files(&[Target::Hlsl, Target::C]).is_empty(), "only the WESL target has a manifest");
}
