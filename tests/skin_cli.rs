//! The skin LUT capability end to end through the binary: `eval` with a profile of your own,
//! bad profiles (exit 2, file/line/field named, nothing written), CSV profiles in specs and the
//! staleness they cause, determinism across thread counts, and the committed LUTs' limits.

mod common;

use common::*;
use std::path::Path;
use std::process::Output;

fn json(o: &Output) -> serde_json::Value {
    assert!(o.status.success(), "{}", stderr(o));
    serde_json::from_slice(&o.stdout).unwrap()
}

fn rgb(v: &serde_json::Value) -> Vec<f64> {
    v["value"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

const SIX_GAUSSIANS: &str = "[profile]\ngaussians = [\n\
    { variance = 0.0064, weights = [0.233, 0.455, 0.649] },\n\
    { variance = 0.0484, weights = [0.100, 0.336, 0.344] },\n\
    { variance = 0.187, weights = [0.118, 0.198, 0.0] },\n\
    { variance = 0.567, weights = [0.113, 0.007, 0.007] },\n\
    { variance = 1.99, weights = [0.358, 0.004, 0.0] },\n\
    { variance = 7.41, weights = [0.078, 0.0, 0.0] },\n]\n";

#[test]
fn eval_with_profiles_and_kernels() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("six.toml");
    std::fs::write(&p, SIX_GAUSSIANS).unwrap();
    let args = ["eval", "skin-punctual", "curvature=0.5", "n_dot_l=0.1", "--json"];
    let default = json(&shadefit(&args, None));
    let own = json(&shadefit(&[&args[..], &["--profile", p.to_str().unwrap()]].concat(), None));
    // The same six Gaussians written out: the same integral, bit for bit.
    assert_eq!(rgb(&default), rgb(&own));
    assert_eq!(own["profile"]["source"], "gaussians");
    assert_eq!(own["kernel"], "linear");
    let radial = json(&shadefit(&[&args[..], &["--kernel", "radial"]].concat(), None));
    // The radial ring kernel scatters less across the terminator (family::skin::integrals tests).
    for (a, b) in rgb(&default).iter().zip(rgb(&radial)) {
        assert!(a > &(b + 1e-3), "{a} vs {b}");
    }
    // A CSV radial profile: a tent R(r) = 1 − r/2 on [0, 2] mm, all channels alike.
    let csv = d.path().join("tent.csv");
    std::fs::write(&csv, "radius_mm,red,green,blue\n0,1,1,1\n2,0,0,0\n").unwrap();
    let t = json(&shadefit(&["eval", "skin-sh", "curvature=0.3", "band=1", "--json", "--profile", csv.to_str().unwrap()], None));
    let v = rgb(&t);
    assert!(v[0] == v[1] && v[1] == v[2] && v[0] < 1.0 && v[0] > 0.9, "{v:?}");
    assert_eq!(t["profile"]["source"], "csv");
    // --kernel is for skin-punctual, --profile for skin quantities.
    for bad in [
        vec!["eval", "skin-sh", "curvature=0.3", "band=1", "--kernel", "radial"],
        vec!["eval", "skin-punctual", "curvature=0.3", "n_dot_l=0", "--kernel", "cubic"],
        vec!["eval", "gloss-length", "gloss=0.5", "--profile", p.to_str().unwrap()],
        vec!["eval", "skin-punctual", "curvature=-1", "n_dot_l=0", "--profile", p.to_str().unwrap()],
    ] {
        let o = shadefit(&bad, None);
        assert_eq!(o.status.code(), Some(2), "{bad:?}: {}", stderr(&o));
    }
}

#[test]
fn eval_rejects_bad_profiles_naming_file_line_and_field() {
    let d = tempfile::tempdir().unwrap();
    let cases: [(&str, &str, usize, &str); 6] = [
        ("neg.toml", "[profile]\ngaussians = [\n  { variance = 0.5, weights = [1, -0.2, 1] },\n]\n", 3, "profile.gaussians[0].weights"),
        ("zero.toml", "[profile]\ngaussians = [\n  { variance = 0.5, weights = [1, 1, 1] },\n  { variance = 0.0, weights = [1, 1, 1] },\n]\n", 4, "profile.gaussians[1].variance"),
        ("nan.toml", "[profile]\ngaussians = [{ variance = nan, weights = [1, 1, 1] }]\n", 2, "profile.gaussians[0].variance"),
        ("order.csv", "radius_mm,red,green,blue\n0,1,1,1\n0.5,1,1,1\n0.4,0,0,0\n", 4, "radius_mm"),
        ("nan.csv", "radius_mm,red,green,blue\n0,1,nan,1\n1,0,0,0\n", 2, "green"),
        ("neg.csv", "# comment\nradius_mm,red,green,blue\n0,1,1,1\n1,-1,0,0\n", 4, "red"),
    ];
    for (name, body, line, field) in cases {
        let p = d.path().join(name);
        std::fs::write(&p, body).unwrap();
        let o = shadefit(&["eval", "skin-punctual", "curvature=0.5", "n_dot_l=0.2", "--profile", p.to_str().unwrap()], None);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{name}: {e}");
        assert!(e.contains(&format!("{name}:{line}:")), "{name}: names file and line {line}: {e}");
        assert!(e.contains(&format!("'{field}'")), "{name}: names field {field}: {e}");
        assert!(o.stdout.is_empty(), "{name}: prints no value");
    }
}

/// Edit the scratch copy of a spec, run `build`, expect exit 2 naming `file:line:` and `field`.
fn bad_build(edit: impl Fn(&str) -> String, extra: &[(&str, &str)], file: &str, line: usize, field: &str) {
    let d = scratch();
    let p = d.path().join("fits/skin_punctual_lut.toml");
    let text = std::fs::read_to_string(&p).unwrap();
    std::fs::write(&p, edit(&text)).unwrap();
    for (name, body) in extra {
        let q = d.path().join("fits").join(name);
        std::fs::create_dir_all(q.parent().unwrap()).unwrap();
        std::fs::write(q, body).unwrap();
    }
    let o = shadefit(&["build"], Some(d.path()));
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.contains(&format!("{file}:{line}:")), "names {file}:{line}: {e}");
    assert!(e.contains(&format!("'{field}'")), "names field {field}: {e}");
    assert_nothing_written(d.path());
}

fn with_profile(text: &str, profile: &str) -> String {
    let start = text.find("[profile]").unwrap();
    let end = text.find("[emit]").unwrap();
    format!("{}{profile}\n{}", &text[..start], &text[end..])
}

#[test]
fn build_rejects_bad_profiles_and_writes_nothing() {
    let spec = std::fs::read_to_string(root().join("fits/skin_punctual_lut.toml")).unwrap();
    let at = spec.find("[profile]").unwrap();
    let l0 = spec[..at].lines().count() + 1; // line of [profile]
    let gauss = |entries: &str| with_profile(&spec, &format!("[profile]\ngaussians = [\n{entries}]\n"));
    let ok = "  { variance = 0.5, weights = [1, 1, 1] },\n";
    // Negative weight, zero variance, NaN variance: the entry's line (l0 + 2 + index).
    bad_build(|_| gauss(&format!("{ok}  {{ variance = 0.1, weights = [0.2, -0.1, 0.3] }},\n")), &[], "skin_punctual_lut.toml", l0 + 3, "profile.gaussians[1].weights");
    bad_build(|_| gauss("  { variance = 0, weights = [1, 1, 1] },\n"), &[], "skin_punctual_lut.toml", l0 + 2, "profile.gaussians[0].variance");
    bad_build(|_| gauss(&format!("{ok}{ok}  {{ variance = nan, weights = [1, 1, 1] }},\n")), &[], "skin_punctual_lut.toml", l0 + 4, "profile.gaussians[2].variance");
    // A CSV profile whose radius goes back: the CSV file, its line and column.
    let csv = "radius_mm,red,green,blue\n0,1,1,1\n0.3,0.5,0.5,0.5\n0.2,0.1,0.1,0.1\n1,0,0,0\n";
    bad_build(|t| with_profile(t, "[profile]\ncsv = \"profiles/bad.csv\""), &[("profiles/bad.csv", csv)], "bad.csv", 4, "radius_mm");
    let csv = "radius_mm,red,green,blue\n0,1,1,1\n1,NaN,0,0\n";
    bad_build(|t| with_profile(t, "[profile]\ncsv = \"profiles/bad.csv\""), &[("profiles/bad.csv", csv)], "bad.csv", 3, "red");
    // A missing CSV: the spec's line of `csv`.
    bad_build(|t| with_profile(t, "[profile]\ncsv = \"profiles/none.csv\""), &[], "skin_punctual_lut.toml", l0 + 1, "profile.csv");
    // Spec fields.
    let line = |key: &str| spec.lines().position(|l| l.starts_with(key)).unwrap() + 1;
    bad_build(|t| t.replace("curvature_max = 1.0", "curvature_max = 0.0"), &[], "skin_punctual_lut.toml", line("curvature_max"), "curvature_max");
    bad_build(|t| t.replace("resolution = [65, 64]", "resolution = [65]"), &[], "skin_punctual_lut.toml", line("resolution"), "resolution");
    bad_build(|t| t.replace("kernel = \"linear\"", "kernel = \"gaussian\""), &[], "skin_punctual_lut.toml", line("kernel"), "kernel");
}

#[test]
fn skin_luts_are_byte_identical_at_any_thread_count_and_match_the_committed_ones() {
    let run = |threads: &str| build_snapshot(&["build", "--only", "skin_punctual_lut,skin_sh_lut"], threads, |_| {});
    let one = run("1");
    let names: Vec<String> = one.iter().map(|(p, _)| p.display().to_string()).collect();
    for f in ["data/skin_punctual_lut.ktx2", "data/skin_punctual_lut.png", "json/skin_sh_lut.json", "src/skin_sh_lut.rs", "wgsl/skin_punctual_lut.wgsl"] {
        assert!(names.iter().any(|n| n == f), "{f} missing from {names:?}");
    }
    assert_eq!(one, run("2"), "RAYON_NUM_THREADS=1 and =2 must give the same bytes");
    // Integrated again from scratch, the texels agree with the committed ones to 1e-12 (the
    // 1e-10 tolerance bounds each; same algorithm and inputs, so only another libm's last-ulp
    // differences in exp/sin could move them).
    for name in ["skin_punctual_lut", "skin_sh_lut"] {
        let read = |bytes: &[u8]| -> Vec<f64> {
            let v: serde_json::Value = serde_json::from_slice(bytes).unwrap();
            v["values"].as_array().unwrap().iter().flat_map(|t| t.as_array().unwrap().iter().map(|x| x.as_f64().unwrap())).collect()
        };
        let fresh = &one.iter().find(|(p, _)| p == Path::new(&format!("json/{name}.json"))).unwrap().1;
        let committed = std::fs::read(root().join(format!("generated/json/{name}.json"))).unwrap();
        let (a, b) = (read(fresh), read(&committed));
        assert_eq!(a.len(), b.len());
        let worst = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        assert!(worst <= 1e-12, "{name}: {worst}");
    }
}

#[test]
fn csv_profile_spec_builds_checks_and_goes_stale_when_the_csv_changes() {
    let d = scratch();
    let spec = std::fs::read_to_string(d.path().join("fits/skin_sh_lut.toml")).unwrap();
    // The default profile sampled on 0..25 mm (dense near 0) as a CSV table.
    let mut csv = String::from("radius_mm,red,green,blue\n");
    let g = [(0.0064, [0.233, 0.455, 0.649]), (0.0484, [0.1, 0.336, 0.344]), (0.187, [0.118, 0.198, 0.0]), (0.567, [0.113, 0.007, 0.007]), (1.99, [0.358, 0.004, 0.0]), (7.41, [0.078, 0.0, 0.0])];
    for i in 0..=200 {
        let r = 25.0 * (i as f64 / 200.0).powi(2);
        let v: Vec<String> = (0..3)
            .map(|c| {
                let s: f64 = g.iter().map(|(var, w)| w[c] * (-r * r / (2.0 * var)).exp() / (2.0 * std::f64::consts::PI * var)).sum();
                format!("{s:e}")
            })
            .collect();
        csv.push_str(&format!("{r},{}\n", v.join(",")));
    }
    std::fs::create_dir(d.path().join("fits/profiles")).unwrap();
    std::fs::write(d.path().join("fits/profiles/skin.csv"), &csv).unwrap();
    std::fs::write(d.path().join("fits/skin_sh_lut.toml"), with_profile(&spec, "[profile]\ncsv = \"profiles/skin.csv\"")).unwrap();
    let o = shadefit(&["build", "--only", "skin_sh_lut"], Some(d.path()));
    assert!(o.status.success(), "{}", stderr(&o));
    let o = shadefit(&["build", "--check", "--only", "skin_sh_lut"], Some(d.path()));
    assert!(o.status.success(), "{}{}", String::from_utf8_lossy(&o.stdout), stderr(&o));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.path().join("generated/json/skin_sh_lut.json")).unwrap()).unwrap();
    assert_eq!(v["profile"]["source"], "csv");
    assert_eq!(v["profile"]["csv"], "profiles/skin.csv");
    // The sampled profile gives nearly the committed Gaussian LUT: piecewise-linear
    // interpolation of R on 201 samples (family::skin::integrals tests bound it by 1e-3).
    let committed: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(root().join("generated/json/skin_sh_lut.json")).unwrap()).unwrap();
    let flat = |v: &serde_json::Value| -> Vec<f64> {
        v["values"].as_array().unwrap().iter().flat_map(|t| t.as_array().unwrap().iter().map(|x| x.as_f64().unwrap())).collect()
    };
    let worst = flat(&v).iter().zip(flat(&committed)).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(worst < 1e-3, "{worst}");
    // Editing the CSV (not the spec) makes the outputs stale: the input hash covers it.
    std::fs::write(d.path().join("fits/profiles/skin.csv"), csv.replace("radius_mm,red,green,blue\n0,", "radius_mm,red,green,blue\n0.0,")).unwrap();
    let o = shadefit(&["build", "--check", "--only", "skin_sh_lut"], Some(d.path()));
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("skin_sh_lut"), "{}", stderr(&o));
}

#[test]
fn samples_and_list_know_skin_luts() {
    let o = shadefit(&["samples", "skin_punctual_lut"], Some(&root()));
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("generated/json/skin_punctual_lut.json"), "{}", stderr(&o));
    let o = shadefit(&["list"], Some(&root()));
    assert!(o.status.success());
    let out = String::from_utf8_lossy(&o.stdout);
    let line = out.lines().find(|l| l.starts_with("skin_punctual_lut")).unwrap();
    assert!(line.contains("skin-lut") && line.contains("up to date"), "{line}");
}

#[test]
fn committed_luts_respect_the_limits() {
    let read = |name: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(root().join(format!("generated/json/{name}.json"))).unwrap()).unwrap()
    };
    let p = read("skin_punctual_lut");
    let (w, h) = (p["texture"]["width"].as_u64().unwrap() as usize, p["texture"]["height"].as_u64().unwrap() as usize);
    let vals = p["values"].as_array().unwrap();
    assert_eq!(vals.len(), w * h);
    let tol = p["tolerance"].as_f64().unwrap();
    for (k, t) in vals.iter().enumerate() {
        let (i, j) = (k % w, k / w);
        let nl = -1.0 + 2.0 * i as f64 / (w - 1) as f64;
        for c in t.as_array().unwrap() {
            let v = c.as_f64().unwrap();
            // In [0, 1] up to the quadrature tolerance (each texel's error estimate ≤ tol).
            assert!((-tol..=1.0 + tol).contains(&v), "texel ({i}, {j}) = {v}");
            // κ = 0 is Lambert, exactly.
            if j == 0 {
                assert_eq!(v, nl.max(0.0), "texel ({i}, 0)");
            }
        }
    }
    // The quadrature estimate honours the tolerance the spec asks for.
    assert!(p["quadrature"]["max_error_estimate"].as_f64().unwrap() <= tol);
    let s = read("skin_sh_lut");
    let n = s["texture"]["width"].as_u64().unwrap() as usize;
    for (k, t) in s["values"].as_array().unwrap().iter().enumerate() {
        for c in t.as_array().unwrap() {
            let v = c.as_f64().unwrap();
            // k_l ∈ (0, 1], and exactly 1 at κ = 0.
            assert!(v > 0.0 && v <= 1.0, "{k}: {v}");
            if k % n == 0 {
                assert_eq!(v, 1.0);
            }
        }
    }
}
