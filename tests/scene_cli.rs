//! Scenes end to end through the binary: `build --scene` builds exactly the reachable nodes,
//! a second build is a no-op, a spec change rebuilds only what depends on it, bad manifests
//! exit 2 naming file, line and field, and the fixed-parameter constants are the integrals.

mod common;

use common::*;
use std::path::Path;

fn build_scene(dir: &Path, scene: &str, extra: &[&str]) -> (String, std::process::Output) {
    let file = format!("fits/scenes/{scene}.toml");
    let mut args = vec!["build", "--scene", file.as_str()];
    args.extend_from_slice(extra);
    let o = shadefit(&args, Some(dir));
    (String::from_utf8_lossy(&o.stdout).into_owned(), o)
}

/// The list after `label:` in the build report.
fn listed(out: &str, label: &str) -> Vec<String> {
    let line = out.lines().find(|l| l.trim_start().starts_with(label)).unwrap_or_else(|| panic!("no '{label}' in {out}"));
    let rest = line.trim_start()[label.len()..].trim();
    if rest == "-" { vec![] } else { rest.split(", ").map(str::to_string).collect() }
}

fn scratch_with_scenes() -> tempfile::TempDir {
    let d = scratch();
    let scenes = d.path().join("fits/scenes");
    std::fs::create_dir_all(&scenes).unwrap();
    for e in std::fs::read_dir(root().join("fits/scenes")).unwrap() {
        let p = e.unwrap().path();
        std::fs::copy(&p, scenes.join(p.file_name().unwrap())).unwrap();
    }
    d
}

#[test]
fn a_scene_builds_exactly_its_nodes_then_nothing_then_what_changed() {
    let d = scratch_with_scenes();
    // Cold: the skin character reaches the two skin LUTs and its own module, nothing else.
    let (out, o) = build_scene(d.path(), "skin_character", &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(listed(&out, "built:"), ["skin_punctual_lut", "skin_sh_lut", "scene_skin_character"]);
    let json: Vec<String> = std::fs::read_dir(d.path().join("generated/json"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect();
    assert_eq!(json, ["scene_skin_character.json", "skin_punctual_lut.json", "skin_sh_lut.json"]);
    assert!(listed(&out, "not reached:").contains(&"fuzz_r".to_string()));

    // Warm: everything up to date, nothing written.
    let before = snapshot(&d.path().join("generated"));
    let (out, o) = build_scene(d.path(), "skin_character", &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.starts_with("scene skin_character: 3 up to date, 0 built"), "{out}");
    assert_eq!(before, snapshot(&d.path().join("generated")));

    // A change to one spec rebuilds that node and the scene, not the other LUT.
    let p = d.path().join("fits/skin_sh_lut.toml");
    let t = std::fs::read_to_string(&p).unwrap();
    std::fs::write(&p, format!("{t}\n# edited\n")).unwrap();
    let (out, _) = build_scene(d.path(), "skin_character", &[]);
    assert_eq!(listed(&out, "built:"), ["skin_sh_lut", "scene_skin_character"]);
    assert_eq!(listed(&out, "up to date:"), ["skin_punctual_lut"]);

    // A file changed on disk is rebuilt too; --force rebuilds everything reached.
    std::fs::write(d.path().join("generated/wgsl/skin_punctual_lut.wgsl"), "// damaged\n").unwrap();
    let (out, _) = build_scene(d.path(), "skin_character", &[]);
    assert_eq!(listed(&out, "built:"), ["skin_punctual_lut", "scene_skin_character"]);
    let (out, _) = build_scene(d.path(), "skin_character", &["--force"]);
    assert_eq!(listed(&out, "built:"), ["skin_punctual_lut", "skin_sh_lut", "scene_skin_character"]);
}

#[test]
fn fixed_parameters_become_the_integrals() {
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(root().join("generated/json/scene_velvet_horse.json")).unwrap()).unwrap();
    let manifest = std::fs::read_to_string(root().join("fits/scenes/velvet_horse.toml")).unwrap();
    assert!(manifest.contains("alpha = 0.53") && manifest.contains("density = 0.2"));
    let eval = |args: &[&str]| -> f64 {
        let o = shadefit(args, None);
        assert!(o.status.success(), "{}", stderr(&o));
        serde_json::from_slice::<serde_json::Value>(&o.stdout).unwrap()["value"].as_f64().unwrap()
    };
    let rec = |what: &str| v["specialised"].as_array().unwrap().iter().find(|r| r["what"].as_str().unwrap().starts_with(what)).unwrap().clone();
    // R and Q: the integrals themselves (R's quadrature at 1e-10 and eval's at 1e-12: 1e-9 bounds both).
    let r = rec("R at fixed")["value"].as_f64().unwrap();
    let r_eval = eval(&["eval", "fuzz-r", "alpha=0.53", "theta_f=0.40142572795869574", "--json"]);
    assert!((r - r_eval).abs() < 1e-9, "{r} vs {r_eval}");
    let q = rec("Q = 2 E3")["value"].as_f64().unwrap();
    // Both are 2·E₃(0.2) from the same closed form: a few ulps.
    assert!((q - eval(&["eval", "fuzz-q", "d=0.2", "--json"])).abs() < 1e-15);
    // P_s: the six coefficients at (α, θf) against eval at directions of the verification grid;
    // their recorded max error must hold there, and beat the general fit's.
    let ps = rec("P_s coefficients");
    let c: Vec<f64> = ps["coefficients"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
    let recorded = ps["max_abs_error"].as_f64().unwrap();
    assert!(recorded < ps["general_fit_max_abs_error"].as_f64().unwrap());
    let tf: f64 = 0.40142572795869574;
    let mut worst = 0.0f64;
    for (i, j) in [(0, 0), (3, 7), (12, 12), (24, 5), (24, 24), (18, 20)] {
        // Verification grid: 25 × 25 over θu ∈ [0, π/2], φu ∈ [0, π] (fits/fuzz_ps.toml).
        let tu = std::f64::consts::FRAC_PI_2 * i as f64 / 24.0;
        let pu = std::f64::consts::PI * j as f64 / 24.0;
        let truth = eval(&["eval", "fuzz-ps", "alpha=0.53", &format!("theta_f={tf:e}"), &format!("theta_u={tu:e}"), &format!("phi_u={pu:e}"), "--json"]);
        let (nu, td) = (tu.cos(), tu.sin() * pu.cos() * tf.sin() + tu.cos() * tf.cos());
        let approx = (c[0] + c[1] * nu + c[2] * td + c[3] * nu * nu + c[4] * nu * td + c[5] * td * td).clamp(0.0, 1.0);
        worst = worst.max((approx - truth).abs());
    }
    // A subset of the points the recorded max was taken over (integrals to 1e-9 both times).
    assert!(worst <= recorded + 2e-9, "{worst} > {recorded}");
}

fn bad_scene(edit: impl Fn(&str) -> String, line: usize, field: &str) {
    let d = scratch_with_scenes();
    let p = d.path().join("fits/scenes/velvet_horse.toml");
    let t = std::fs::read_to_string(&p).unwrap();
    std::fs::write(&p, edit(&t)).unwrap();
    let o = shadefit(&["build", "--scene", "fits/scenes/velvet_horse.toml"], Some(d.path()));
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains(&format!("velvet_horse.toml:{line}:")), "names line {line}: {err}");
    assert!(err.contains(field), "names field {field}: {err}");
    assert_nothing_written(d.path());
}

#[test]
fn bad_manifests_exit_2_name_file_line_field_and_write_nothing() {
    let text = std::fs::read_to_string(root().join("fits/scenes/velvet_horse.toml")).unwrap();
    let line_of = |needle: &str| text.lines().position(|l| l.starts_with(needle)).unwrap() + 1;
    let m = line_of("[[material]]");
    bad_scene(|t| t.replace("features = [\"fuzz\"]", "features = [\"fur\"]"), m, "material[0].features");
    bad_scene(|t| t.replace("alpha = 0.53", "alpha = 0.05"), m, "material[0].params");
    bad_scene(|t| t.replace("alpha = 0.53", "alpha = nan"), m, "material[0].params");
    bad_scene(|t| t.replace("density = 0.2", "gloss = 0.2"), m, "material[0].params");
    bad_scene(|t| t.replace("density = 0.2", "density = [0.3, 0.1]"), m, "material[0].params");
    bad_scene(|t| t.replace("name = \"velvet_horse\"", "name = \"velvet\""), line_of("name ="), "name");
    bad_scene(|t| t.replace("features = [\"fuzz\"]", "features = [\"fuzz\"]\nshiny = true"), m + 3, "shiny");
}

#[test]
fn a_scene_naming_a_spec_fits_lacks_is_bad_input() {
    // cobblestone_gloss reaches gloss_combine_lut; without it the manifest (or fits/) must
    // change: exit 2 naming the spec, nothing written.
    let d = scratch_with_scenes();
    std::fs::remove_file(d.path().join("fits/gloss_combine_lut.toml")).unwrap();
    let (_, o) = build_scene(d.path(), "cobblestone_gloss", &[]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("gloss_combine_lut"), "{err}");
    assert_nothing_written(d.path());
}
