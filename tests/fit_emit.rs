//! `shadefit fit --data … --emit DIR`: the user's own data fitted and emitted like a spec.
//!
//! References: NIST StRD Kirby2's certified solution (a rational (2,2) fit), a closed-form
//! rational the data is sampled from, and the outputs' own invariants (clamping to the data's
//! box, the positivity proof refusing a pole, all-or-nothing writes, determinism).

mod common;

use common::*;
use std::path::Path;

/// Kirby2's certified parameters (NIST StRD): numerator b1..b3, denominator b4, b5.
const KIRBY2_NUM: [f64; 3] = [1.6745063063, -1.3927397867e-1, 2.5961181191e-3];
const KIRBY2_DEN: [f64; 2] = [-1.7241811870e-3, 2.1664802578e-5];

fn emit(csv: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec!["fit", "--data", csv.to_str().unwrap(), "--x", "x", "--y", "y", "--model", "rational(2,2)"];
    args.extend_from_slice(&["--emit", out.to_str().unwrap()]);
    args.extend_from_slice(extra);
    shadefit(&args, None)
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn floats(v: &serde_json::Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

#[test]
fn kirby2_is_emitted_with_the_certified_coefficients_and_its_data_box() {
    let d = tempfile::tempdir().unwrap();
    let csv = nist_csv("Kirby2", d.path());
    let out = d.path().join("out");
    let o = emit(&csv, &out, &["--function", "kirby2_fit", "--target", "wgsl-plain,c"]);
    assert!(o.status.success(), "{}", stderr(&o));
    for f in ["wgsl/kirby2.wgsl", "src/kirby2.rs", "json/kirby2.json", "wgsl-plain/kirby2.wgsl", "c/kirby2.h"] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let j = json(&out.join("json/kirby2.json"));
    // The f64 coefficients: NIST's acceptance, 1e-6 relative to the certified values.
    let c = floats(&j["model"]["coefficients"]);
    for (got, want) in c.iter().zip(KIRBY2_NUM.iter().chain(&KIRBY2_DEN)) {
        assert!((got - want).abs() < 1e-6 * want.abs(), "{got} vs certified {want}");
    }
    // The box is the data's x range (Kirby2: 9.65 to 78.87), and the emitted code clamps to it.
    let x: Vec<f64> = std::fs::read_to_string(&csv).unwrap().lines().skip(1).map(|l| l.split(',').next().unwrap().parse().unwrap()).collect();
    let (lo, hi) = x.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    assert_eq!(floats(&j["axes"][0]["range"]), vec![lo, hi]);
    let wgsl = std::fs::read_to_string(out.join("wgsl/kirby2.wgsl")).unwrap();
    assert!(wgsl.contains("fn kirby2_fit(x: f32) -> f32"), "{wgsl}");
    // The clamp's bounds, read back from `kirby2_input(x, LO, HI)`, are the box in f32.
    let call = wgsl.split("kirby2_input(x, ").nth(1).expect("the argument is clamped");
    let bounds: Vec<f32> = call.split(')').next().unwrap().split(", ").map(|b| b.trim_end_matches('f').parse().unwrap()).collect();
    assert_eq!(bounds, vec![lo as f32, hi as f32], "clamped to the data's box");
    // Kirby2's certified denominator has no real root (discriminant b4² − 4·b5 < 0): the proof
    // must find a positive lower bound on the box.
    assert!(KIRBY2_DEN[0] * KIRBY2_DEN[0] - 4.0 * KIRBY2_DEN[1] < 0.0);
    assert!(j["model"]["denominator_lower_bound"].as_f64().unwrap() > 0.0);
    // The verification is over the rows themselves: its max error is the certified solution's
    // largest residual, to the same 1e-6 relative (the fits agree to that).
    let rows: Vec<(f64, f64)> = std::fs::read_to_string(&csv)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| {
            let (a, b) = l.split_once(',').unwrap();
            (a.parse().unwrap(), b.parse().unwrap())
        })
        .collect();
    let certified = |x: f64| (KIRBY2_NUM[0] + KIRBY2_NUM[1] * x + KIRBY2_NUM[2] * x * x) / (1.0 + KIRBY2_DEN[0] * x + KIRBY2_DEN[1] * x * x);
    let max_res = rows.iter().map(|&(x, y)| (certified(x) - y).abs()).fold(0.0, f64::max);
    let v = &j["verification"];
    assert_eq!(v["points"].as_u64().unwrap() as usize, rows.len());
    let got = v["max_abs_error"].as_f64().unwrap();
    // Certified and emitted coefficients differ by ≤ 1e-6 relative; y ≤ 92, so the residuals
    // differ by well under 1e-3 of the largest (≈ 0.47).
    assert!((got - max_res).abs() < 1e-3 * max_res, "max abs error {got} vs the certified solution's {max_res}");
    // naga parses and validates the plain WGSL as is.
    let plain = std::fs::read_to_string(out.join("wgsl-plain/kirby2.wgsl")).unwrap();
    let m = naga::front::wgsl::parse_str(&plain).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&plain)));
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default())
        .validate(&m)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&plain)));
    // The header names the command that made the file.
    assert!(wgsl.lines().nth(1).unwrap().starts_with("// spec: shadefit fit --data Kirby2.csv --x x --y y --model rational(2,2)"), "{wgsl}");
}

#[test]
fn a_closed_form_rational_is_recovered_and_its_f32_code_is_exact_to_rounding() {
    // y = (1 + 2x + 0.5x²)/(1 + 0.25x − 0.125x²) on x ∈ [−1, 1]: its own form fits it exactly.
    let d = tempfile::tempdir().unwrap();
    let f = |x: f64| (1.0 + 2.0 * x + 0.5 * x * x) / (1.0 + 0.25 * x - 0.125 * x * x);
    let mut csv = String::from("x,y\n");
    for i in 0..=40 {
        let x = -1.0 + i as f64 / 20.0;
        csv.push_str(&format!("{x:?},{:?}\n", f(x)));
    }
    let p = d.path().join("closed.csv");
    std::fs::write(&p, csv).unwrap();
    let out = d.path().join("out");
    let o = emit(&p, &out, &["--objective", "minimax"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let j = json(&out.join("json/closed.json"));
    // Exact data: the f64 fit matches the true coefficients to the solver's convergence (the
    // condition number on [−1, 1] is ~10: 1e-9 leaves a wide margin over double rounding).
    let c = floats(&j["model"]["coefficients"]);
    for (got, want) in c.iter().zip([1.0, 2.0, 0.5, 0.25, -0.125]) {
        assert!((got - want).abs() < 1e-9, "{c:?}");
    }
    // The f32 code: coefficients and arithmetic in f32, |y| ≤ 4 and ~10 operations: its error
    // is a few f32 ulps of 4 (2^-21 each); 1e-5 bounds it with room.
    let e32 = j["verification"]["max_abs_error_f32"].as_f64().unwrap();
    assert!(e32 < 1e-5, "f32 code error {e32}");
    // Module name and function default to the CSV's stem.
    let wgsl = std::fs::read_to_string(out.join("wgsl/closed.wgsl")).unwrap();
    assert!(wgsl.contains("fn closed(x: f32) -> f32"), "{wgsl}");
}

#[test]
fn a_denominator_with_a_root_in_the_box_is_refused_and_nothing_is_written() {
    // y = 1/(1 − 2x) sampled on x ∈ [0, 0.4] and [0.6, 1], fitted with the denominator's
    // coefficient fixed at −2 (README: `fixed`, "den:TERM"): the fit is exact and its
    // denominator vanishes at x = 0.5, inside the data's box [0, 1]. Emitted, it would divide by
    // zero there; the positivity proof must refuse it.
    let d = tempfile::tempdir().unwrap();
    let mut csv = String::from("x,y\n");
    for i in 0..=20 {
        let x = i as f64 / 20.0;
        if (x - 0.5).abs() > 0.05 {
            csv.push_str(&format!("{x:?},{:?}\n", 1.0 / (1.0 - 2.0 * x)));
        }
    }
    let p = d.path().join("pole.csv");
    std::fs::write(&p, csv).unwrap();
    let model = d.path().join("pole_model.toml");
    std::fs::write(&model, "features = [\"x\"]\nnumerator = [\"1\"]\ndenominator = [\"x\"]\nfixed = { \"den:x\" = -2.0 }\n").unwrap();
    let out = d.path().join("out");
    let args = ["fit", "--data", p.to_str().unwrap(), "--x", "x", "--y", "y", "--model", model.to_str().unwrap()];
    // Without --emit the fit is printed (the rational is exact: rss 0).
    let o = shadefit(&args, None);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = shadefit(&[&args[..], &["--emit", out.to_str().unwrap()]].concat(), None);
    assert_eq!(o.status.code(), Some(1), "a pole in the box must be refused: {}", stderr(&o));
    assert!(stderr(&o).contains("not provably positive"), "{}", stderr(&o));
    assert!(!out.exists(), "nothing written");
}

#[test]
fn bad_options_exit_2_naming_the_option_and_write_nothing() {
    let d = tempfile::tempdir().unwrap();
    let csv = nist_csv("Kirby2", d.path());
    let out = d.path().join("out");
    for (extra, want) in [
        (&["--name", "9lives"][..], "--name"),
        (&["--function", "fn"][..], "--function"),
        (&["--target", "vulkan"][..], "--target"),
        (&["--args", "a,b"][..], "--args"),
    ] {
        let o = emit(&csv, &out, extra);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(want), "{extra:?}: {}", stderr(&o));
        assert!(!out.exists(), "{extra:?}: nothing written");
    }
}

#[test]
fn the_files_are_byte_identical_at_any_thread_count_and_on_a_rerun() {
    let d = tempfile::tempdir().unwrap();
    let csv = nist_csv("Kirby2", d.path());
    let run = |threads: &str, dir: &str| {
        let out = d.path().join(dir);
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_shadefit"))
            .args(["fit", "--data", csv.to_str().unwrap(), "--x", "x", "--y", "y", "--model", "rational(2,2)", "--emit"])
            .arg(&out)
            .args(["--target", "spirv"])
            .env("RAYON_NUM_THREADS", threads)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
        snapshot(&out)
    };
    let one = run("1", "one");
    assert_eq!(one.len(), 4, "wgsl, rs, json, spv");
    assert!(one.iter().any(|(p, _)| p.ends_with("wgsl/kirby2.wgsl")), "the name defaults to the CSV's stem, lowercased");
    assert_eq!(one, run("2", "two"));
    assert_eq!(one, run("2", "two"), "a rerun into the same folder");
}
