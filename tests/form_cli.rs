//! Form specs (`kind = "form"`) from the command line: `measure` of Karis's EnvBRDFApprox
//! written as a form gives the built-in validate item's figures exactly; the committed example
//! is refitted no worse than its published constants; `validate --only` runs form specs; bad
//! form specs are the user's input (exit 2, file:line, field, column) and write nothing.

mod common;

use common::snapshot as files;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_shadefit"))
}

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn run(dir: &Path, args: &[&str]) -> Output {
    bin().current_dir(dir).args(args).output().unwrap()
}

fn json(out: &Output) -> Value {
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

/// The same form on the same grid against the same integral gives the same numbers: the form
/// spec of Karis's EnvBRDFApprox (tests/data/forms) measured by `measure` equals the built-in
/// `ggx-env-ue4: Karis` item of `validate` in max, rms and worst point, bit for bit (both sum
/// the same f64 errors in the same order).
#[test]
fn karis_as_a_form_spec_reproduces_the_built_in_item() {
    let m = json(&run(&repo(), &["measure", "tests/data/forms/karis_env_brdf.toml", "--json"]));
    let v = json(&run(&repo(), &["validate", "--family", "ggx", "--json"]));
    let item = v["items"].as_array().unwrap().iter().find(|i| i["name"].as_str().unwrap().starts_with("ggx-env-ue4: Karis")).expect("the Karis item");
    let all = &m["published"]["all"];
    assert_eq!(all["points"], item["points"]);
    assert_eq!(all["max_abs_error"].as_f64().unwrap().to_bits(), item["max_abs_error"].as_f64().unwrap().to_bits(), "{all} vs {item}");
    assert_eq!(all["rms_error"].as_f64().unwrap().to_bits(), item["rms_error"].as_f64().unwrap().to_bits());
    // The item's worst point is [n·v, r, channel]; the form's names its arguments and output.
    let w = item["worst_point"].as_array().unwrap();
    assert_eq!(all["worst"]["n_dot_v"], w[0]);
    assert_eq!(all["worst"]["roughness"], w[1]);
    assert_eq!(all["worst_output"], ["scale", "bias"][w[2].as_f64().unwrap() as usize]);
}

/// The committed example: its refit (f32 constants) is no worse than the published constants in
/// max error, its JSON's published figures are what `measure` computes now, and `validate
/// --only` measures it alone, naming its worst point in (n·v, r).
#[test]
fn the_example_form_is_refitted_no_worse_and_validated_alone() {
    let committed: Value = serde_json::from_str(&std::fs::read_to_string(repo().join("generated/json/studio_env_brdf.json")).unwrap()).unwrap();
    let form = &committed["form"];
    let (p, r) = (form["published_errors"]["all"]["max_abs_error"].as_f64().unwrap(), form["refit_errors"]["all"]["max_abs_error"].as_f64().unwrap());
    assert!(r <= p, "refit {r} vs published {p}");
    let m = json(&run(&repo(), &["measure", "fits/studio_env_brdf.toml", "--json"]));
    assert_eq!(m["published"], form["published_errors"]);
    let v = json(&run(&repo(), &["validate", "--only", "studio_env_brdf", "--json"]));
    let items = v["items"].as_array().unwrap();
    assert_eq!(items.len(), 1, "{v}");
    assert_eq!(items[0]["max_abs_error"].as_f64().unwrap(), p);
    assert!(items[0]["domain"].as_str().unwrap().contains("worst point is [roughness, n_dot_v, output (scale, bias)]"), "{}", items[0]);
    let refit = items[0]["extra"].as_array().unwrap().iter().find(|e| e[0] == "refit_max_abs_error").expect("the committed refit")[1].as_f64().unwrap();
    assert_eq!(refit, r);
    let bad = run(&repo(), &["validate", "--only", "no_such_form"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("no form spec 'no_such_form'"), "{}", String::from_utf8_lossy(&bad.stderr));
}

/// A bad form spec in a fits folder: `measure` and `build` exit 2 naming the file, the line, the
/// field and the column, and `build` writes nothing; `measure` of a spec of another kind is
/// refused too.
#[test]
fn bad_form_specs_exit_2_naming_the_place_and_write_nothing() {
    let good = std::fs::read_to_string(repo().join("fits/studio_env_brdf.toml")).unwrap();
    let line = good.lines().position(|l| l.starts_with("bias = ")).unwrap() + 1;
    for (from, to, want) in [
        ("d2 * t5 * roughness", "d2 * t5 * rough", format!("studio_env_brdf.toml:{line}: field 'bias': column 34: unknown name 'rough'")),
        ("d2 * t5 * roughness", "d2 * (t5 * roughness", format!("studio_env_brdf.toml:{line}: field 'bias': column 44: expected ')'")),
        ("d2 * t5 * roughness", "d3 * t5 * roughness", format!("studio_env_brdf.toml:{line}: field 'bias': column 24: unknown name 'd3'")),
    ] {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(dir.path().join("fits")).unwrap();
        std::fs::write(dir.path().join("fits/studio_env_brdf.toml"), good.replace(from, to)).unwrap();
        for args in [&["measure", "fits/studio_env_brdf.toml"][..], &["build"][..]] {
            let out = run(dir.path(), args);
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
            assert!(err.contains(&want), "{args:?}: {err}\n(wanted {want})");
        }
        assert!(!dir.path().join("generated").exists(), "nothing written: {:?}", dir.path().join("generated").exists().then(|| files(&dir.path().join("generated"))));
    }
    let out = run(&repo(), &["measure", "fits/ggx_albedo_table.toml"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("not a form spec"));
}

/// Spec axes may be named by an alias of their parameter (`roughness` for α = r², as `eval`
/// takes it): a table over roughness holds bit for bit the values of the same table over α with
/// the perceptual mapping, and a form over roughness measures exactly what the committed form
/// (α, mapping = "perceptual") measures. An alias's own domain bounds the axis.
#[test]
fn spec_axes_may_be_named_by_an_alias() {
    let d = tempfile::tempdir().unwrap();
    let fits = d.path().join("fits");
    std::fs::create_dir(&fits).unwrap();
    let table = |name: &str, axis: &str| {
        format!(
            "name = \"{name}\"\nkind = \"table\"\nquantity = \"ggx-albedo\"\ntolerance = 1e-8\n\n[[axis]]\n{axis}\nrange = [0.05, 1.0]\ncount = 9\nverify = 9\n\n\
             [[axis]]\nname = \"n_dot_v\"\nrange = [0.0, 1.0]\ncount = 9\nverify = 9\n\n[emit]\nfunction = \"{name}\"\n"
        )
    };
    std::fs::write(fits.join("t_alias.toml"), table("t_alias", "name = \"roughness\"")).unwrap();
    std::fs::write(fits.join("t_mapped.toml"), table("t_mapped", "name = \"alpha\"\nmapping = \"perceptual\"")).unwrap();
    let form = std::fs::read_to_string(repo().join("fits/studio_env_brdf.toml")).unwrap();
    let aliased = form.replacen("name = \"alpha\"\nmapping = \"perceptual\"", "name = \"roughness\"", 1).replace("order = [\"n_dot_v\", \"alpha\"]", "order = [\"n_dot_v\", \"roughness\"]");
    assert_ne!(aliased, form, "the committed form's axis is alpha with the perceptual mapping");
    std::fs::write(fits.join("studio_env_brdf.toml"), &aliased).unwrap();
    let b = run(d.path(), &["build", "--only", "t_alias,t_mapped"]);
    assert!(b.status.success(), "{}", String::from_utf8_lossy(&b.stderr));
    let values = |n: &str| -> Value { serde_json::from_str::<Value>(&std::fs::read_to_string(d.path().join(format!("generated/json/{n}.json"))).unwrap()).unwrap()["values"].clone() };
    assert_eq!(values("t_alias"), values("t_mapped"));
    let (mine, committed) = (json(&run(d.path(), &["measure", "fits/studio_env_brdf.toml", "--json"])), json(&run(&repo(), &["measure", "fits/studio_env_brdf.toml", "--json"])));
    assert_eq!(mine["published"], committed["published"]);
    // ggx-albedo's roughness alias starts at 1e-3 (no mirror limit there): r = 0 is refused.
    std::fs::write(fits.join("t_alias.toml"), table("t_alias", "name = \"roughness\"").replace("range = [0.05, 1.0]", "range = [0.0, 1.0]")).unwrap();
    let e = run(d.path(), &["build", "--only", "t_alias"]);
    assert_eq!(e.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&e.stderr).contains("field 'range': axis 'roughness' range [0, 1] must be finite, increasing and inside [0.001, 1]"), "{}", String::from_utf8_lossy(&e.stderr));
}
