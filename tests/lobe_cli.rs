//! Lobe specs (`kind = "lobe"`): a user's BRDF written as an expression, integrated by the
//! generic operators. GGX written out (tests/data/lobes/ggx_written.toml) reproduces the built-in
//! ggx-env, ggx-albedo and ggx-albedo-avg within the two error estimates at 50 random points,
//! and its split-sum table the committed ggx_dfg_lut texels to 1e-7; Lambert written out has
//! albedo ρ to 1e-12; the committed cloth example is the sheen family's Charlie–Neubelt lobe;
//! the build emits the BRDF as WGSL that naga validates.

use rayon::prelude::*;
use serde_json::Value;
use shadefit::family::catalog;
use shadefit::pipeline::lobe::{LobeDef, quantities};
use shadefit::quantity::QuantityDef;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_shadefit")).current_dir(repo()).args(args).output().unwrap()
}

fn json(out: &Output) -> Value {
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

/// The quantities of the lobe spec at `path` (relative to the repository), by suffix.
fn written(path: &str) -> Vec<&'static QuantityDef> {
    let path = repo().join(path);
    let text = std::fs::read_to_string(&path).unwrap();
    quantities(Box::leak(Box::new(LobeDef::parse(&path, &text).unwrap())))
}

fn pick<'a>(qs: &[&'a QuantityDef], name: &str) -> &'a QuantityDef {
    qs.iter().copied().find(|q| q.name == name).unwrap_or_else(|| panic!("no quantity {name}"))
}

/// `build --only SPECS` of the lobe specs in tests/data/lobes into a fresh folder.
fn build_lobes(specs: &str) -> tempfile::TempDir {
    let out = tempfile::tempdir().unwrap();
    let r = run(&["--fits", "tests/data/lobes", "--generated", out.path().to_str().unwrap(), "build", "--only", specs]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    out
}

/// A deterministic uniform sample in [0, 1) (SplitMix64).
fn uniform(state: &mut u64) -> f64 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
}

/// Both lobes are the same function of the same variables in the same measure; they differ in
/// rounding only (~1e-14), far below the integrators' error estimates at tolerance 1e-10. So
/// each value must agree with the built-in's to the sum of the two estimates (plus 1e-13 of
/// rounding, the estimates being bounds on the truncation error alone).
#[test]
fn written_ggx_reproduces_the_built_in_quantities_at_50_points() {
    let qs = written("tests/data/lobes/ggx_written.toml");
    let cat = catalog();
    let pairs = [
        (pick(&qs, "ggx_written-env"), cat.lookup("ggx-env").unwrap()),
        (pick(&qs, "ggx_written-albedo"), cat.lookup("ggx-albedo").unwrap()),
        (pick(&qs, "ggx_written-albedo-avg"), cat.lookup("ggx-albedo-avg").unwrap()),
    ];
    let mut state = 7u64;
    let points: Vec<[f64; 3]> = (0..50).map(|_| [1e-3 + (1.0 - 1e-3) * uniform(&mut state), uniform(&mut state), 0.9 * uniform(&mut state)]).collect();
    let bad: Vec<String> = points
        .par_iter()
        .flat_map_iter(|&[alpha, nv, cone]| {
            pairs.iter().filter_map(move |(w, b)| {
                let p: Vec<f64> = [alpha, nv, cone][..w.params.len()].to_vec();
                let (x, y): (Vec<_>, Vec<_>) = match (w.eval_channels, b.eval_channels) {
                    (Some(wc), Some(bc)) => (wc(&p, 1e-10), bc(&p, 1e-10)),
                    _ => (vec![(w.eval)(&p, 1e-10)], vec![(b.eval)(&p, 1e-10)]),
                };
                x.iter().zip(&y).find(|(x, y)| (x.value - y.value).abs() > x.error + y.error + 1e-13).map(|(x, y)| format!("{} at {p:?}: {x:?} vs {} {y:?}", w.name, b.name))
            })
        })
        .collect();
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// `eval` serves a lobe spec's quantities by name from the --fits folder, with the library's
/// value, and lists them in `eval --help`.
#[test]
fn eval_serves_lobe_quantities_by_name() {
    let v = json(&run(&["--fits", "tests/data/lobes", "eval", "ggx_written-albedo", "alpha=0.3", "n_dot_v=0.5", "--json"]));
    let lib = (pick(&written("tests/data/lobes/ggx_written.toml"), "ggx_written-albedo").eval)(&[0.3, 0.5], 1e-12);
    assert_eq!(v["value"].as_f64().unwrap().to_bits(), lib.value.to_bits());
    let help = String::from_utf8(run(&["--fits", "tests/data/lobes", "eval", "--help"]).stdout).unwrap();
    assert!(help.contains("ggx_written-env") && help.contains("lambert_written-albedo-avg"), "{help}");
}

/// f = ρ/π: every weight the integrator sees is a polynomial on each piece of its panels, so
/// E(μ) = ρ to rounding (1e-12), at grazing and normal views, and E_avg = ρ.
#[test]
fn lambert_written_out_has_albedo_rho() {
    for (rho, mu) in [(1.0, 0.0), (1.0, 0.37), (1.0, 1.0), (0.25, 0.8)] {
        let v = json(&run(&["--fits", "tests/data/lobes", "eval", "lambert_written-albedo", &format!("rho={rho}"), &format!("n_dot_v={mu}"), "--json"]));
        assert!((v["value"].as_f64().unwrap() - rho).abs() < 1e-12, "ρ {rho} μ {mu}: {v}");
    }
    let v = json(&run(&["--fits", "tests/data/lobes", "eval", "lambert_written-albedo-avg", "rho=1", "--json"]));
    assert!((v["value"].as_f64().unwrap() - 1.0).abs() < 1e-12, "{v}");
}

/// The split-sum table of the written lobe, built by the generic table kind at ggx_dfg_lut's
/// texel centres and tolerance (1e-7 per texel), against the committed texels of ggx_dfg_lut
/// (the built-in lobe through the DFG kind): each texel carries ≤ 1e-7 of quadrature error on
/// each side, and they agree to 1e-7.
#[test]
fn written_ggx_split_sum_table_matches_ggx_dfg_lut() {
    let out = build_lobes("ggx_written_dfg");
    let mine: Value = serde_json::from_str(&std::fs::read_to_string(out.path().join("json/ggx_written_dfg.json")).unwrap()).unwrap();
    let lut: Value = serde_json::from_str(&std::fs::read_to_string(repo().join("generated/json/ggx_dfg_lut.json")).unwrap()).unwrap();
    let (a, b) = (mine["values"].as_array().unwrap(), lut["values"].as_array().unwrap());
    assert_eq!((a.len(), b.len()), (128 * 128, 128 * 128));
    let worst = a.iter().zip(b).flat_map(|(x, y)| (0..2).map(move |c| (x[c].as_f64().unwrap() - y[c].as_f64().unwrap()).abs())).fold(0.0, f64::max);
    assert!(worst <= 1e-7, "largest texel difference {worst:e}");
}

/// The committed cloth example is the sheen family's Charlie lobe with Neubelt's visibility
/// over α = roughness²: the same integral in another measure and code path, equal to the two
/// estimates (tolerance 1e-10) plus rounding.
#[test]
fn the_cloth_example_is_the_charlie_neubelt_lobe() {
    let qs = written("fits/studio_cloth.toml");
    let (mine, theirs) = (pick(&qs, "studio_cloth-albedo"), catalog().lookup("sheen-albedo-ashikhmin").unwrap());
    for (r, mu) in [(0.1, 0.01), (0.3, 0.5), (0.7, 0.9), (1.0, 0.0)] {
        let (x, y) = ((mine.eval)(&[r, mu], 1e-10), (theirs.eval)(&[r * r, mu], 1e-10));
        assert!((x.value - y.value).abs() <= x.error + y.error + 1e-13, "r {r} μ {mu}: {x:?} vs {y:?}");
    }
}

/// The build of a lobe spec: the BRDF as a WGSL function of the four cosines and the
/// parameters that naga parses and validates, the Rust twin, and an albedo summary (Lambert:
/// E = ρ at every corner, to its error estimate).
#[test]
fn a_lobe_spec_builds_its_brdf_as_a_shader_function() {
    let out = build_lobes("ggx_written,lambert_written");
    for (name, function) in [("ggx_written", "fn ggx_written(n_dot_v: f32, n_dot_l: f32, n_dot_h: f32, v_dot_h: f32, alpha: f32) -> f32 {"), ("lambert_written", "fn lambert_written(")] {
        let wgsl = std::fs::read_to_string(out.path().join(format!("wgsl/{name}.wgsl"))).unwrap();
        assert!(wgsl.contains(function), "{wgsl}");
        let module = naga::front::wgsl::parse_str(&wgsl.replace(&format!("#define_import_path shadefit::{name}"), "")).unwrap_or_else(|e| panic!("{name}: {e}\n{wgsl}"));
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all()).validate(&module).unwrap();
        assert!(Path::new(&out.path().join(format!("src/{name}.rs"))).exists());
    }
    let j: Value = serde_json::from_str(&std::fs::read_to_string(out.path().join("json/lambert_written.json")).unwrap()).unwrap();
    for s in j["albedo_summary"].as_array().unwrap() {
        let rho = s["at"]["rho"].as_f64().unwrap();
        for e in s["albedo_at_n_dot_v_0_half_1"].as_array().unwrap() {
            assert!((e.as_f64().unwrap() - rho).abs() <= 1e-12, "{s}");
        }
    }
}

/// `plot` in a user's project (only their own form and lobe specs, built into their own
/// generated folder): the figures of both specs are drawn, the families whose committed files
/// are absent are skipped with one note each (naming the file once), and the run succeeds.
#[test]
fn plot_draws_a_users_own_specs_from_their_generated_folder() {
    let d = tempfile::tempdir().unwrap();
    std::fs::create_dir(d.path().join("fits")).unwrap();
    for s in ["studio_env_brdf", "studio_cloth"] {
        std::fs::copy(repo().join(format!("fits/{s}.toml")), d.path().join(format!("fits/{s}.toml"))).unwrap();
    }
    let in_dir = |args: &[&str]| Command::new(env!("CARGO_BIN_EXE_shadefit")).current_dir(d.path()).args(args).output().unwrap();
    let b = in_dir(&["--generated", "mine", "build"]);
    assert!(b.status.success(), "{}", String::from_utf8_lossy(&b.stderr));
    let p = in_dir(&["--generated", "mine", "plot", "--out", "figs"]);
    let err = String::from_utf8_lossy(&p.stderr);
    assert!(p.status.success(), "{err}");
    for f in ["forms/studio_env_brdf_scale_published.png", "forms/studio_env_brdf_bias_refit.svg", "lobes/studio_cloth_albedo.png"] {
        assert!(d.path().join("figs").join(f).is_file(), "{f} missing; stderr:\n{err}");
    }
    assert!(err.contains("note: gloss: figures left out from here on (mine/json/"), "{err}");
    assert!(err.lines().all(|l| l.matches("No such file").count() <= 1), "{err}");
}
