//! The emitted libraries as bevy composes them: naga_oil (bevy's shader composer, on this
//! crate's naga major) takes every module of generated/wgsl as a composable module under its
//! `#define_import_path shadefit::NAME`, then composes a shader that imports every module
//! (`#import shadefit::NAME`) and calls every function of each as `NAME::f(..)`; naga
//! validates the result. The crate's own composer resolves the same shader, and the flat
//! style, to WGSL that naga validates with every function present.

#[path = "support/calls.rs"]
mod calls;

use calls::{every_function, validate, Style};
use naga_oil::compose::{ComposableModuleDescriptor, Composer, NagaModuleDescriptor};
use shadefit_runtime::{compose_shader, wgsl};

fn libraries() -> Vec<(&'static str, &'static str)> {
    let all: Vec<_> = wgsl::NAMES.iter().map(|n| (*n, wgsl::module(n).unwrap())).collect();
    assert!(all.len() >= 20, "the emitted modules ({})", all.len());
    all
}

/// Every function name declared by the libraries, as naga reads them.
fn function_names() -> Vec<String> {
    libraries()
        .iter()
        .flat_map(|(_, src)| naga::front::wgsl::parse_str(&calls::plain(src)).unwrap().functions.iter().map(|(_, f)| f.name.clone().unwrap()).collect::<Vec<_>>())
        .collect()
}

/// A naga_oil composer holding every emitted module under its `#define_import_path`.
fn composer() -> Composer {
    let mut composer = Composer::default();
    for (name, src) in libraries() {
        let path = format!("wgsl/{name}.wgsl");
        let first = src.lines().find(|l| l.starts_with('#')).unwrap();
        assert_eq!(first, format!("#define_import_path shadefit::{name}"), "{path}");
        if let Err(e) = composer.add_composable_module(ComposableModuleDescriptor { source: src, file_path: &path, ..Default::default() }) {
            panic!("{path}: {}", e.emit_to_string(&composer));
        }
    }
    composer
}

/// `shader` composed against every emitted module by naga_oil, then validated by naga.
fn compose_and_validate(shader: &str, file_path: &str) -> naga::Module {
    let mut composer = composer();
    let module = composer
        .make_naga_module(NagaModuleDescriptor { source: shader, file_path, ..Default::default() })
        .unwrap_or_else(|e| panic!("{}\n{shader}", e.emit_to_string(&composer)));
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default())
        .validate(&module)
        .unwrap_or_else(|e| panic!("{e:?}"));
    module
}

#[test]
fn naga_oil_composes_every_module_in_the_prefixed_style() {
    let shader = every_function(&libraries(), Style::Prefixed);
    let module = compose_and_validate(&shader, "every_function.wgsl");
    // naga_oil keeps what the entry point uses (and renames it): every function is there.
    assert_eq!(module.entry_points.len(), 1);
    // naga_oil names an imported item NAME followed by its module's encoded path.
    for f in function_names() {
        assert!(module.functions.iter().any(|(_, g)| g.name.as_deref().is_some_and(|g| g.starts_with(&f))), "{f} not composed");
    }
}

#[test]
fn the_runtime_composer_resolves_the_same_shader() {
    for style in [Style::Prefixed, Style::Flat] {
        let shader = every_function(&libraries(), style);
        let src = compose_shader(&shader).unwrap_or_else(|e| panic!("{style:?}: {e}"));
        let module = validate(&format!("{style:?}"), &src);
        for f in function_names() {
            assert!(module.functions.iter().any(|(_, g)| g.name.as_deref() == Some(&f)), "{style:?}: {f} missing");
        }
    }
}

#[test]
fn the_bevy_energy_recipe_composes() {
    // docs/recipes/bevy_energy.wgsl (README "Engine recipes": bevy): a user's shader importing four
    // emitted modules by naga_oil path and calling them prefixed, as a bevy material would.
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/recipes/bevy_energy.wgsl");
    let module = compose_and_validate(&std::fs::read_to_string(path).unwrap(), "bevy_energy.wgsl");
    assert_eq!(module.entry_points.iter().map(|e| e.name.as_str()).collect::<Vec<_>>(), ["energy_fs"]);
}
