//! The build of a fit spec and of a table spec, end to end, on a quantity with a closed form
//! (e^−x on [0, 2], with its inverse −ln y): every number the build writes is re-measured here
//! from the written coefficients or values against the closed form, and the committed JSON is
//! read back (and refused when it is tampered with).

use super::*;
use crate::integrate::Estimate;
use crate::quantity::{ParamSpec, QuantityDef};
use crate::spec::Catalog;

pub(crate) static EXP: QuantityDef = QuantityDef {
    name: "exp-decay",
    doc: "e^-x (a closed form the build's results are checked against)",
    params: &[ParamSpec { name: "x", min: 0.0, max: 2.0, doc: "argument", integer: false, limit: None, default: None }],
    aliases: &[],
    eval: &|p, _| Estimate { value: (-p[0]).exp(), error: 0.0, evals: 1 },
    inverse: Some(|y| -y.ln()),
    channels: &[],
    eval_channels: None,
    basis: None,
};

pub(crate) fn spec(text: &str) -> Spec {
    spec_in(text, &Catalog { quantities: vec![&EXP], kinds: vec![], features: vec![], mappings: vec![] })
}

/// A spec from its text, at `fits/NAME.toml` (NAME: the first quoted string, `name = "…"`).
fn spec_in(text: &str, catalog: &Catalog) -> Spec {
    let name = text.split('"').nth(1).unwrap();
    Spec::parse(Path::new(&format!("fits/{name}.toml")), text.to_string(), catalog).unwrap()
}

pub(crate) const FIT: &str = r#"
name = "exp_fit"
kind = "fit"
quantity = "exp-decay"
description = "e^-x by a 2/2 rational"

[[axis]]
name = "x"
range = [0.0, 2.0]
count = 64
verify = 501

[model]
numerator = ["1", "x", "x^2"]
denominator = ["x", "x^2"]

[fit]
objective = "minimax"

[emit]
function = "exp_fit"
"#;

fn file<'a>(b: &'a Built, path: &str) -> &'a [u8] {
    &b.artifacts.iter().find(|a| a.path == Path::new(path)).unwrap_or_else(|| panic!("no {path}")).contents
}

pub(crate) fn json_of(b: &Built) -> Value {
    serde_json::from_slice(file(b, &format!("json/{}.json", b.name))).unwrap()
}

pub(crate) fn floats(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

/// FIT's model, (c0 + c1 x + c2 x²)/(1 + c3 x + c4 x²), written out at x.
pub(crate) fn fit_rational(c: &[f64], x: f64) -> f64 {
    (c[0] + c[1] * x + c[2] * x * x) / (1.0 + c[3] * x + c[4] * x * x)
}

/// n uniform points over [0, 2], the last exactly 2: the specs' grids written out (501: the
/// verification grid; 64: the fitting samples).
pub(crate) fn uniform(n: usize) -> Vec<f64> {
    (0..n).map(|i| if i + 1 == n { 2.0 } else { 2.0 * i as f64 / (n - 1) as f64 }).collect()
}

#[test]
fn a_fit_spec_reports_the_errors_of_what_it_writes() {
    let s = spec(FIT);
    let tmp = tempfile::tempdir().unwrap();
    let b = build_spec(&s, Mode::Fit, tmp.path(), &|_| None).unwrap();
    let j = json_of(&b);
    let m = &j["model"];
    let c = floats(&m["coefficients"]);
    let (num, den) = (floats(&m["numerator_f32"]), floats(&m["denominator_f32"]));
    assert_eq!((c.len(), num.len(), den.len()), (5, 3, 2));
    let r64 = |x: f64| fit_rational(&c, x);
    let model = s.model.as_ref().unwrap();
    let e = expr::model_expr(model);
    let (n32, d32): (Vec<f32>, Vec<f32>) = (num.iter().map(|&v| v as f32).collect(), den.iter().map(|&v| v as f32).collect());
    let r32 = |x: f64| expr::eval_f32(&e, &[x as f32], &n32, &d32) as f64;
    let (mut m64, mut m32, mut mp, mut ss64, mut ss32) = (0.0f64, 0.0f64, 0.0f64, 0.0, 0.0);
    let mut worst = 0.0;
    for x in uniform(501) {
        let t = (-x).exp();
        let (e64, e32) = ((r64(x) - t).abs(), (r32(x) - t).abs());
        if e64 > m64 {
            worst = x;
        }
        m64 = m64.max(e64);
        m32 = m32.max(e32);
        mp = mp.max((-r64(x).ln() - x).abs());
        ss64 += e64 * e64;
        ss32 += e32 * e32;
    }
    let v = &b.verification;
    // The same residuals re-summed here (the f64 fit evaluated in another order): 1e-15 of
    // values ~1, far below the errors (~1e-5).
    assert_eq!(v.points, 501);
    assert!((v.max_abs_error - m64).abs() < 1e-15 && (v.rms_error - (ss64 / 501.0).sqrt()).abs() < 1e-15, "{v:?} vs {m64}");
    assert!((v.max_abs_error_f32 - m32).abs() < 1e-15 && (v.rms_error_f32 - (ss32 / 501.0).sqrt()).abs() < 1e-15, "{v:?} vs {m32}");
    assert!((v.max_abs_error_in_parameter.unwrap() - mp).abs() < 1e-13, "{v:?} vs {mp}");
    assert_eq!(v.worst_point, vec![worst]);
    // The JSON and the files' headers carry the same figures.
    assert_eq!(j["verification"]["max_abs_error_f32"].as_f64(), Some(v.max_abs_error_f32));
    let header = format!("max abs {:.3e}, rms {:.3e} over 501 points", v.max_abs_error, v.rms_error);
    for f in ["wgsl/exp_fit.wgsl", "src/exp_fit.rs"] {
        assert!(String::from_utf8_lossy(file(&b, f)).contains(&header), "{f} lacks '{header}'");
    }
    // The Rust module's doc opens with the sentence describing the fit's form.
    let module = String::from_utf8_lossy(file(&b, "src/exp_fit.rs")).into_owned();
    assert!(module.contains("//! e^-x by a 2/2 rational: `exp_fit` ≈ P/Q of quantity `exp-decay`"), "{module}");
    // A 2/2 rational of e^−x on [0, 2]: its minimax error is 3.2e-5 (measured; Padé [2/2] alone
    // is 4e-3 at x = 2); the f32 code adds rounding ~1e-7.
    assert!(m64 < 1e-4 && m32 < m64 + 1e-6, "{m64} {m32}");
    // The f32 coefficients are the rounded f64 ones moved by at most MAX_ULPS.
    for (a, b) in num.iter().chain(&den).zip(&c) {
        assert!(f32round::ulps_between(*b as f32, *a as f32).unsigned_abs() <= f32round::MAX_ULPS as u64, "{a} vs {b}");
    }
    // The denominator's bound is a lower bound, and positive: Q = 1 + c3 x + c4 x² sampled densely.
    let qmin = (0..=20000).map(|i| 2.0 * i as f64 / 20000.0).map(|x| 1.0 + c[3] * x + c[4] * x * x).fold(f64::MAX, f64::min);
    let lower = m["denominator_lower_bound"].as_f64().unwrap();
    assert!(lower > 0.0 && lower <= qmin, "bound {lower}, sampled min {qmin}");
    // The fitting report is the fit's: its max error on the 64 fitting samples, re-measured.
    let fit = b.fit.as_ref().unwrap();
    let on64 = uniform(64).into_iter().map(|x| (r64(x) - (-x).exp()).abs()).fold(0.0, f64::max);
    assert!((fit.max_abs_error - on64).abs() < 1e-15, "{} vs {on64}", fit.max_abs_error);
    assert_eq!(fit.samples, 64);
    // It is the spec's objective, minimax: its max error on the fitting samples is well below
    // that of the least-squares fit of the same samples (a minimax fit of a smooth function
    // gains ~2× on the max error; 0.8× is far from both).
    let x64: Vec<Vec<f64>> = uniform(64).into_iter().map(|x| vec![x]).collect();
    let data = Data { y: x64.iter().map(|x| (-x[0]).exp()).collect(), x: x64 };
    let lsq = fit::fit(model, &data, &FitOptions::default(), "lsq").unwrap();
    assert!(fit.max_abs_error < 0.8 * lsq.report.max_abs_error, "minimax {} vs least squares {}", fit.max_abs_error, lsq.report.max_abs_error);
    assert_eq!(m["objective"], json!("minimax"));
    // The re-optimisation's report: on the fitting samples, never worse than plain rounding.
    let fr = &j["f32_rounding"];
    assert_eq!(fr["fitting_samples"].as_u64(), Some(64));
    let (rounded, reopt) = (fr["rounded_f32"]["max_abs_error"].as_f64().unwrap(), fr["reoptimised_f32"]["max_abs_error"].as_f64().unwrap());
    assert!(reopt <= rounded, "{reopt} > {rounded}");
    // The f32 coefficients' own denominator bound: positive and below Q of the f32
    // coefficients (in f64) sampled densely.
    let q32 = (0..=20000).map(|i| 2.0 * i as f64 / 20000.0).map(|x| 1.0 + den[0] * x + den[1] * x * x).fold(f64::MAX, f64::min);
    let lower32 = fr["denominator_lower_bound"].as_f64().unwrap();
    assert!(lower32 > 0.0 && lower32 <= q32, "f32 bound {lower32}, sampled min {q32}");
}

/// A quartic on the narrow [1.75, 2], whose monomial terms cancel (like `fit::f32round`'s
/// quartic on [8, 9]): the f32 search moves some of its coefficients, not all. The report's
/// moves are each f32 coefficient's distance from the nearest f32 to its f64 coefficient,
/// counted here on the ordered line of f32 bit patterns; the count of those that moved, the
/// largest, and the documented cap of 64 ulps.
#[test]
fn a_fits_rounding_report_counts_the_moves_of_its_coefficients() {
    let text = FIT
        .replace("range = [0.0, 2.0]", "range = [1.75, 2.0]")
        .replace("numerator = [\"1\", \"x\", \"x^2\"]\ndenominator = [\"x\", \"x^2\"]", "numerator = [\"1\", \"x\", \"x^2\", \"x^3\", \"x^4\"]");
    assert!(text.contains("x^4") && text.contains("1.75"), "{text}");
    let b = build_spec(&spec(&text), Mode::Fit, tempfile::tempdir().unwrap().path(), &|_| None).unwrap();
    let j = json_of(&b);
    let (c, num) = (floats(&j["model"]["coefficients"]), floats(&j["model"]["numerator_f32"]));
    let ord = |v: f32| if v.is_sign_negative() { -((v.to_bits() & 0x7fff_ffff) as i64) } else { v.to_bits() as i64 };
    let moves: Vec<i64> = num.iter().zip(&c).map(|(&a, &b)| ord(a as f32) - ord(b as f32)).collect();
    let fr = &j["f32_rounding"];
    let reported: Vec<i64> = fr["moves_ulps"].as_array().unwrap().iter().map(|v| v.as_i64().unwrap()).collect();
    assert_eq!(reported, moves);
    let moved = moves.iter().filter(|m| **m != 0).count() as u64;
    assert!(moved > 0 && moved < 5, "some coefficients move, not all: {moves:?}");
    assert_eq!(fr["coefficients_moved"].as_u64(), Some(moved));
    assert_eq!(fr["max_move_ulps"].as_u64(), moves.iter().map(|m| m.unsigned_abs()).max());
    assert_eq!(fr["max_ulps_allowed"].as_u64(), Some(64));
}

#[test]
fn committed_fits_rebuild_byte_for_byte_and_tampering_is_refused() {
    let s = spec(FIT);
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path();
    let b = build_spec(&s, Mode::Fit, root, &|_| None).unwrap();
    write_all(root, &b.artifacts).unwrap();
    assert!(stale(root, &b.artifacts).is_empty());
    let again = build_spec(&s, Mode::Committed, root, &|_| None).unwrap();
    for (a, c) in b.artifacts.iter().zip(&again.artifacts) {
        assert_eq!(a.path, c.path);
        assert!(a.contents == c.contents, "{} differs when rebuilt from the committed JSON", a.path.display());
    }
    let path = root.join("json/exp_fit.json");
    let original = std::fs::read_to_string(&path).unwrap();
    let tamper = |f: &dyn Fn(&mut Value)| {
        let mut v: Value = serde_json::from_str(&original).unwrap();
        f(&mut v);
        std::fs::write(&path, json_text(&v)).unwrap();
        build_spec(&s, Mode::Committed, root, &|_| None)
    };
    // An f32 coefficient MAX_ULPS + 1 steps from its rounded f64 one; one MAX_ULPS away passes.
    let moved = |k: i64| {
        move |v: &mut Value| {
            let c0 = v["model"]["coefficients"][0].as_f64().unwrap() as f32;
            v["model"]["numerator_f32"][0] = json!(f32round::step_ulps(c0, k).unwrap());
        }
    };
    assert!(matches!(tamper(&moved(f32round::MAX_ULPS as i64 + 1)), Err(BuildError::F32Coefficients { .. })));
    assert!(tamper(&moved(f32round::MAX_ULPS as i64)).is_ok());
    assert!(matches!(tamper(&|v| v["input_hash"] = json!("sha256:0")), Err(BuildError::SpecChanged { .. })));
    assert!(matches!(tamper(&|v| v["model"]["coefficients"] = json!([1.0, 0.0])), Err(BuildError::NoCommitted { .. })));
    assert!(matches!(tamper(&|v| { v.as_object_mut().unwrap().remove("f32_rounding"); }), Err(BuildError::NoCommitted { .. })));
    std::fs::write(&path, &original).unwrap();
    // The spec's max_error bounds the f32 code's measured error, in either mode.
    let bound = b.verification.max_abs_error_f32;
    let tight = spec(&FIT.replace("description =", &format!("max_error = {:e}\ndescription =", bound * 0.5)));
    assert!(matches!(build_spec(&tight, Mode::Fit, root, &|_| None), Err(BuildError::ErrorBound { .. })));
    let loose = spec(&FIT.replace("description =", &format!("max_error = {:e}\ndescription =", bound * 1.01)));
    assert!(build_spec(&loose, Mode::Fit, root, &|_| None).is_ok());
    // A file no artifact is, in an output folder, is an orphan; a changed file is stale.
    std::fs::write(root.join("wgsl/left_over.wgsl"), "x").unwrap();
    assert_eq!(orphans(root, &b.artifacts), vec!["wgsl/left_over.wgsl".to_string()]);
    std::fs::write(root.join("src/exp_fit.rs"), "changed").unwrap();
    assert_eq!(stale(root, &b.artifacts), vec!["src/exp_fit.rs".to_string()]);
}

const TABLE: &str = r#"
name = "exp_table"
kind = "table"
quantity = "exp-decay"
description = "e^-x by a 17-point table"

[[axis]]
name = "x"
range = [0.0, 2.0]
count = 17
verify = 501

[emit]
function = "exp_table"
"#;

/// Linear interpolation of the f32 table at x, written out: e^−x at the nodes 2i/16.
fn lerp(values: &[f64], x: f64) -> f64 {
    let t = x / 0.125;
    let i = (t.floor() as usize).min(15);
    let f = t - i as f64;
    values[i] * (1.0 - f) + values[i + 1] * f
}

#[test]
fn a_table_spec_holds_the_quantity_and_reports_its_interpolation_error() {
    let s = spec(TABLE);
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path();
    let b = build_spec(&s, Mode::Fit, root, &|_| None).unwrap();
    let j = json_of(&b);
    let values = floats(&j["values"]);
    assert_eq!(values.len(), 17);
    for (i, v) in values.iter().enumerate() {
        assert_eq!(*v, (-(i as f64) / 8.0).exp(), "node {i}");
    }
    let v32: Vec<f64> = values.iter().map(|&v| v as f32 as f64).collect();
    let (mut m, mut ss) = (0.0f64, 0.0);
    for x in uniform(501) {
        let e = lerp(&v32, x) - (-x).exp();
        m = m.max(e.abs());
        ss += e * e;
    }
    // Interpolation error h²/8·max|f''| = 0.125²/8 ≈ 2e-3 (measured 1.83e-3); the emitted f32 interpolation
    // differs from this f64 one by f32 rounding of the weights and products (~1e-7).
    let v = &b.verification;
    assert!(m > 1e-3 && (v.max_abs_error_f32 - m).abs() < 1e-6, "{v:?} vs {m}");
    assert!((v.rms_error_f32 - (ss / 501.0).sqrt()).abs() < 1e-6, "{v:?}");
    // The CSV lists every node and its value.
    let csv = String::from_utf8(file(&b, "data/exp_table.csv").to_vec()).unwrap();
    let rows: Vec<&str> = csv.lines().filter(|l| !l.starts_with('#')).collect();
    assert_eq!(rows[0], "x,value");
    assert_eq!(rows.len(), 18);
    assert_eq!(rows[9], format!("1.0,{:?}", (-1.0f64).exp()));
    // Read back from the committed JSON: the same files; a table of another size is refused.
    write_all(root, &b.artifacts).unwrap();
    let again = build_spec(&s, Mode::Committed, root, &|_| None).unwrap();
    assert!(b.artifacts.iter().zip(&again.artifacts).all(|(a, c)| a.path == c.path && a.contents == c.contents));
    let other = spec(&TABLE.replace("count = 17", "count = 9"));
    // The spec text changed, so its hash did too: refused as changed before its size is read.
    assert!(matches!(build_spec(&other, Mode::Committed, root, &|_| None), Err(BuildError::SpecChanged { .. })));
    let path = root.join("json/exp_table.json");
    let mut t: Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    t["values"] = json!(values[..16]);
    std::fs::write(&path, json_text(&t)).unwrap();
    assert!(matches!(build_spec(&s, Mode::Committed, root, &|_| None), Err(BuildError::NoCommitted { .. })));
}

/// Exact fields c_k(o) = offset_k + (a_k + b_k o)/(1 + d_k o) of f(o, u) = c0 + c1 u + c2 u².
const FIELDS_TRUE: [[f64; 3]; 3] = [[1.0, 2.0, 0.5], [-0.3, 0.7, 0.2], [0.2, -0.1, -0.3]];
const FIELDS_OFFSETS: [f64; 3] = [0.5, 0.0, 0.0];

fn field_value(k: usize, o: f64) -> f64 {
    let [a, b, d] = FIELDS_TRUE[k];
    FIELDS_OFFSETS[k] + (a + b * o) / (1.0 + d * o)
}

fn fields_value(o: f64, u: f64) -> f64 {
    field_value(0, o) + field_value(1, o) * u + field_value(2, o) * u * u
}

static QUADRATIC: crate::quantity::InnerBasis = crate::quantity::InnerBasis {
    inner: 1,
    args: &["u"],
    arg_domain: &[(-1.0, 1.0)],
    terms: &["1", "u", "u^2"],
    to_args: |_, i| vec![i[0]],
    sample: |o, inner, _| inner.iter().map(|i| Estimate { value: fields_value(o[0], i[0]), error: 0.0, evals: 1 }).collect(),
    range: (-10.0, 10.0),
};

static FIELDS_Q: QuantityDef = QuantityDef {
    name: "quadratic-fields",
    doc: "a quadratic in u whose coefficients are rationals in o",
    params: &[
        ParamSpec { name: "o", min: 0.0, max: 1.0, doc: "outer", integer: false, limit: None, default: None },
        ParamSpec { name: "u", min: -1.0, max: 1.0, doc: "inner", integer: false, limit: None, default: None },
    ],
    aliases: &[],
    eval: &|p, _| Estimate { value: fields_value(p[0], p[1]), error: 0.0, evals: 1 },
    inverse: None,
    channels: &[],
    eval_channels: None,
    basis: Some(&QUADRATIC),
};

const FIELDS: &str = r#"
name = "quad_fields"
kind = "fields"
quantity = "quadratic-fields"
description = "three exact rational fields"

[[axis]]
name = "o"
range = [0.0, 1.0]
count = 17
verify = 33

[[axis]]
name = "u"
range = [-1.0, 1.0]
count = 9
verify = 11

[model]
numerator = ["1", "o"]
denominator = ["o"]

[fields]
offsets = [0.5, 0.0, 0.0]

[fit]
objective = "lsq"

[emit]
function = "quad_coeffs"
evaluator = "quad"
"#;

/// A fields spec whose fields are exactly representable: the build recovers them, says its
/// errors are at rounding level, proves each Q = 1 + d·o positive with a bound below its true
/// minimum on [0, 1], and rebuilds from its committed JSON byte for byte.
#[test]
fn a_fields_spec_recovers_exact_fields_and_reads_back() {
    let s = spec_in(FIELDS, &Catalog { quantities: vec![&FIELDS_Q], kinds: vec![], features: vec![], mappings: vec![] });
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path();
    let b = build_spec(&s, Mode::Fit, root, &|_| None).unwrap();
    let j = json_of(&b);
    let fields = j["fields"].as_array().unwrap();
    assert_eq!(fields.len(), 3);
    for (k, f) in fields.iter().enumerate() {
        let c = floats(&f["coefficients"]);
        assert_eq!(f["offset"].as_f64(), Some(FIELDS_OFFSETS[k]));
        // Exact data, a well-conditioned 3-term basis at every o: recovered to ~1e-12.
        for (got, want) in c.iter().zip(FIELDS_TRUE[k]) {
            assert!((got - want).abs() < 1e-9, "field {k}: {c:?}");
        }
        let d = FIELDS_TRUE[k][2];
        let qmin = (1.0f64).min(1.0 + d);
        let lower = f["denominator_lower_bound"].as_f64().unwrap();
        assert!(lower > 0.0 && lower <= qmin + 1e-12, "field {k}: bound {lower}, min {qmin}");
    }
    let v = &b.verification;
    // f64 fields equal to the truth to ~1e-12; the f32 code rounds coefficients and arithmetic
    // (values ≤ ~4: a few ulps of 2^-22), so its error is above 1e-9 and below 1e-5.
    assert_eq!(v.points, 33 * 11);
    assert!(v.max_abs_error < 1e-9, "{v:?}");
    assert!(v.max_abs_error_f32 > 1e-9 && v.max_abs_error_f32 < 1e-5, "{v:?}");
    assert!(v.rms_error <= v.max_abs_error && v.rms_error_f32 <= v.max_abs_error_f32);
    assert!(j["fit"]["max_abs_error"].as_f64().unwrap() < 1e-9, "{}", j["fit"]);
    assert_eq!(j["fit"]["grid_points"].as_u64(), Some(17));
    assert_eq!(j["fit"]["inner_samples"].as_u64(), Some(9));
    write_all(root, &b.artifacts).unwrap();
    let again = build_spec(&s, Mode::Committed, root, &|_| None).unwrap();
    for (a, c) in b.artifacts.iter().zip(&again.artifacts) {
        assert!(a.path == c.path && a.contents == c.contents, "{} differs when rebuilt", a.path.display());
    }
    let path = root.join("json/quad_fields.json");
    let mut t: Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    t["input_hash"] = json!("sha256:0");
    std::fs::write(&path, json_text(&t)).unwrap();
    assert!(matches!(build_spec(&s, Mode::Committed, root, &|_| None), Err(BuildError::SpecChanged { .. })));
}

/// A fields build's `f32_rounding` reports its errors on the fitting samples (17 × 9): the f64
/// ones are the JSON's fields' residuals there, re-measured here from their coefficients in the
/// documented form; the f32 ones are the emitted f32 code's at those samples, which the
/// verification grid (33 × 17 here, holding every fitting sample: o = i/16, u = −1 + l/4 are
/// on it exactly) evaluates too, so their max is at most the verification's f32 max.
#[test]
fn a_fields_builds_rounding_report_is_its_errors_on_the_fitting_samples() {
    let text = FIELDS.replace("count = 9\nverify = 11", "count = 9\nverify = 17");
    assert_ne!(text, FIELDS);
    let s = spec_in(&text, &Catalog { quantities: vec![&FIELDS_Q], kinds: vec![], features: vec![], mappings: vec![] });
    let tmp = tempfile::tempdir().unwrap();
    let b = build_spec(&s, Mode::Fit, tmp.path(), &|_| None).unwrap();
    let j = json_of(&b);
    let fr = &j["f32_rounding"];
    assert_eq!(fr["fitting_samples"].as_u64(), Some(17 * 9));
    assert_eq!(fr["reoptimised"], json!(false));
    let fields: Vec<(f64, Vec<f64>)> =
        j["fields"].as_array().unwrap().iter().map(|f| (f["offset"].as_f64().unwrap(), floats(&f["coefficients"]))).collect();
    let (mut max, mut ss) = (0.0f64, 0.0f64);
    for i in 0..17 {
        for l in 0..9 {
            let (o, u) = (i as f64 / 16.0, -1.0 + l as f64 / 4.0);
            let c: Vec<f64> = fields.iter().map(|(off, c)| off + (c[0] + c[1] * o) / (1.0 + c[2] * o)).collect();
            let r = c[0] + c[1] * u + c[2] * u * u - fields_value(o, u);
            max = max.max(r.abs());
            ss += r * r;
        }
    }
    // The residuals are ~1e-12 (exact data, a recovered fit); evaluated in another order here,
    // each moves by a few ulps of values ≤ 4 (~1e-15).
    let e64 = &fr["f64"];
    assert!((e64["max_abs_error"].as_f64().unwrap() - max).abs() < 1e-14, "{e64} vs max {max}");
    assert!((e64["rms_error"].as_f64().unwrap() - (ss / 153.0).sqrt()).abs() < 1e-14, "{e64} vs rms {}", (ss / 153.0).sqrt());
    // The spec's objective is least squares: the reported objective is the rms.
    assert_eq!(e64["objective"], e64["rms_error"]);
    let (e32, v) = (fr["rounded_f32"]["max_abs_error"].as_f64().unwrap(), &b.verification);
    assert_eq!(v.points, 33 * 17);
    assert!(e32 <= v.max_abs_error_f32, "fitting samples {e32} > verification {}", v.max_abs_error_f32);
    // f32 arithmetic on values ≤ ~4 (ulps of 2^-22 at most): above the f64 fit's 1e-12, far
    // below 1e-5; the truth at most samples is no f32 (its denominators 1 + d·o are not powers
    // of two), so the f32 code cannot be within 1e-9 of it at every sample.
    assert!(e32 > 1e-9 && e32 < 1e-5, "{e32}");
}

/// The Rust module of a fields spec states each field's f64 coefficients split as its model
/// is, the numerator's terms and then the denominator's: here one and one (P_k = a_k,
/// Q_k = 1 + d_k·o), each constant the JSON's coefficient of that term.
#[test]
fn a_fields_modules_f64_coefficients_split_at_the_numerator() {
    let text = FIELDS.replace("numerator = [\"1\", \"o\"]", "numerator = [\"1\"]");
    assert_ne!(text, FIELDS);
    let s = spec_in(&text, &Catalog { quantities: vec![&FIELDS_Q], kinds: vec![], features: vec![], mappings: vec![] });
    let b = build_spec(&s, Mode::Fit, tempfile::tempdir().unwrap().path(), &|_| None).unwrap();
    let j = json_of(&b);
    let module = String::from_utf8(file(&b, "src/quad_fields.rs").to_vec()).unwrap();
    for k in 0..3 {
        let c = floats(&j["fields"][k]["coefficients"]);
        assert_eq!(c.len(), 2, "field {k}");
        for (part, v) in [("NUM", c[0]), ("DEN", c[1])] {
            let decl = format!("pub const QUAD_FIELDS_{part}{k}_F64: [f64; 1] = [");
            let at = module.find(&decl).unwrap_or_else(|| panic!("no '{decl}' in\n{module}")) + decl.len();
            // One Rust literal, `1.5e0_f64`, on its own line: the exact f64.
            let literal = module[at..at + module[at..].find(']').unwrap()].trim().trim_end_matches(',').trim_end_matches("_f64");
            assert_eq!(literal.parse::<f64>().ok(), Some(v), "field {k} {part}: {literal}");
        }
    }
}

/// The inner variable v = (1 + 3o)·u: the stage-1 design [1, v, v²] on the 9 inner samples
/// changes with o, so its condition number does.
static SCALED: crate::quantity::InnerBasis = crate::quantity::InnerBasis {
    inner: 1,
    args: &["v"],
    arg_domain: &[(-4.0, 4.0)],
    terms: &["1", "v", "v^2"],
    to_args: |o, i| vec![(1.0 + 3.0 * o[0]) * i[0]],
    sample: |o, inner, _| {
        inner
            .iter()
            .map(|i| {
                let v = (1.0 + 3.0 * o[0]) * i[0];
                Estimate { value: field_value(0, o[0]) + field_value(1, o[0]) * v + field_value(2, o[0]) * v * v, error: 0.0, evals: 1 }
            })
            .collect()
    },
    range: (-100.0, 100.0),
};

static SCALED_Q: QuantityDef = QuantityDef { name: "scaled-fields", basis: Some(&SCALED), ..FIELDS_Q };

/// A fields build reports the stage-1 condition numbers of its outer points as their min,
/// median and max, worked out here in closed form: at o = i/16 the design's columns are
/// 1, s·u, s²·u² with s = 1 + 3o on u = −1 + l/4 (l = 0…8), whose Gram matrix is
/// [[9, 0, 3.75 s²], [0, 3.75 s², 0], [3.75 s², 0, 2.765625 s⁴]] (Σu² = 3.75, Σu⁴ = 2.765625):
/// eigenvalues 3.75 s² and those of the 2×2 block, and the condition is √(λmax/λmin). None is
/// above 1e8. The rest of the fit's report: its grids, objective (least squares: no outer
/// iterations), no rms cap, and LM evaluations.
#[test]
fn a_fields_build_reports_its_stage1_conditions() {
    let text = FIELDS.replace("quadratic-fields", "scaled-fields");
    let b = build_spec(&spec_in(&text, &Catalog { quantities: vec![&SCALED_Q], kinds: vec![], features: vec![], mappings: vec![] }), Mode::Fit, tempfile::tempdir().unwrap().path(), &|_| None)
        .unwrap();
    let fit = &json_of(&b)["fit"];
    let mut conds: Vec<f64> = (0..17)
        .map(|i| {
            let s2 = (1.0 + 3.0 * i as f64 / 16.0).powi(2);
            let (a, bb, d) = (9.0, 3.75 * s2, 2.765625 * s2 * s2);
            let hi = 0.5 * (a + d) + (0.25 * (a - d) * (a - d) + bb * bb).sqrt();
            // The smaller eigenvalue as det / λmax, free of the cancellation in (a + d)/2 − √….
            let lo = (a * d - bb * bb) / hi;
            let eig = [hi, lo, 3.75 * s2];
            let (max, min) = (eig.iter().copied().fold(0.0, f64::max), eig.iter().copied().fold(f64::INFINITY, f64::min));
            (max / min).sqrt()
        })
        .collect();
    conds.sort_by(f64::total_cmp);
    assert!(conds[16] > 2.0 * conds[0], "the conditions differ across o: {conds:?}");
    let c = &fit["stage1_condition"];
    // The SVD of a 9 × 3 matrix and the closed form above agree to a few ulps of the
    // condition (≤ 30 here) times its size: 1e-12 relative.
    for (key, want) in [("min", conds[0]), ("median", conds[8]), ("max_up_to_1e8", conds[16]), ("max", conds[16])] {
        let got = c[key].as_f64().unwrap_or_else(|| panic!("{key}: {c}"));
        assert!((got - want).abs() <= 1e-12 * want, "{key}: {got} vs {want}");
    }
    assert_eq!(c["points_above_1e8"].as_u64(), Some(0));
    assert_eq!((fit["grid_points"].as_u64(), fit["inner_samples"].as_u64()), (Some(17), Some(9)));
    assert_eq!((&fit["objective"], &fit["max_rms"], fit["outer_iterations"].as_u64()), (&json!("lsq"), &Value::Null, Some(0)));
    assert!(fit["lm_evaluations"].as_u64().is_some_and(|n| n > 0), "{fit}");
}

/// The committed fields read back by name (`committed::Fields::load`: fits/NAME.toml beside
/// generated/) evaluate the exact fields, at outer points off the fitting grid too; the fit
/// alone (`fields::fit`) gives the coefficients and the report the build wrote; a fit spec is
/// not read as fields.
#[test]
fn committed_fields_evaluate_the_exact_fields() {
    let catalog = Catalog { quantities: vec![&EXP, &FIELDS_Q], kinds: vec![], features: vec![], mappings: vec![] };
    let tmp = tempfile::tempdir().unwrap();
    let generated = tmp.path().join("generated");
    std::fs::create_dir_all(tmp.path().join("fits")).unwrap();
    std::fs::write(tmp.path().join("fits/quad_fields.toml"), FIELDS).unwrap();
    let s = spec_in(FIELDS, &catalog);
    let b = build_spec(&s, Mode::Fit, &generated, &|_| None).unwrap();
    write_all(&generated, &b.artifacts).unwrap();
    let f = committed::Fields::load(&generated, "quad_fields", &catalog).unwrap();
    for o in [0.0, 0.03, 0.5, 0.97, 1.0] {
        let c = f.eval(&[o]);
        assert_eq!(c.len(), 3);
        for (k, ck) in c.iter().enumerate() {
            // Recovered to ~1e-12 (the build test above); values ≤ 3.
            assert!((ck - field_value(k, o)).abs() < 1e-9, "field {k} at {o}: {ck} vs {}", field_value(k, o));
        }
    }
    let (coefficients, report) = fields::fit(&s).unwrap();
    let j = json_of(&b);
    assert_eq!(coefficients.len(), 3);
    for (k, c) in coefficients.iter().enumerate() {
        assert_eq!(c.as_slice(), floats(&j["fields"][k]["coefficients"]), "field {k}");
    }
    assert_eq!(report, j["fit"]);
    assert!(matches!(committed::Fields::of(&spec_in(FIT, &catalog), &generated), Err(BuildError::NotKind { .. })));
}

/// A table emitted as a texture too states its texture's storage error in its header: the
/// largest |r16(v) − v| over the f32 table (rounded here with the `half` crate), 0 for
/// r32float. The linear-sampler helper `_sample` is there for r16float (filterable in core
/// WebGPU) and for r32float only with `float32_filterable = true`.
#[test]
fn a_texture_table_states_its_storage_error_and_samples_where_it_filters() {
    let cases = [("texture_format = \"r16float\"", "r16float", true), ("texture_format = \"r32float\"", "r32float", false), ("texture_format = \"r32float\"\nfloat32_filterable = true", "r32float", true)];
    for (extra, format, sample) in cases {
        let s = spec(&TABLE.replace("[emit]", &format!("[emit]\nform = \"both\"\n{extra}")));
        let tmp = tempfile::tempdir().unwrap();
        let b = build_spec(&s, Mode::Fit, tmp.path(), &|_| None).unwrap();
        let storage = floats(&json_of(&b)["values"])
            .iter()
            .map(|&v| if format == "r16float" { (half::f16::from_f32(v as f32).to_f32() - v as f32).abs() } else { 0.0 })
            .fold(0.0f32, f32::max);
        assert!((format == "r16float") == (storage > 1e-5), "{format}: {storage} (r16float keeps 11 bits of values in (0.13, 1])");
        let wgsl = String::from_utf8(file(&b, "wgsl/exp_table.wgsl").to_vec()).unwrap();
        let line = format!("; {format} texture storage <= {}", fmt_err(storage as f64));
        assert!(wgsl.contains(&line), "{extra}: no '{line}' in\n{wgsl}");
        assert_eq!(wgsl.contains("fn exp_table_sample("), sample, "{extra}");
        assert!(wgsl.contains("fn exp_table_load("), "{extra}");
    }
}

/// Each function of the runtime index is called with its arity (`Cpu::One`, `Cpu::Two`) and
/// the domain of each argument, a spec's and a scene's alike.
#[test]
fn the_runtime_index_calls_each_function_with_its_arity() {
    let catalog = Catalog { quantities: vec![&EXP, &FIELDS_Q], kinds: vec![], features: vec![], mappings: vec![] };
    let two = "name = \"quad_table\"\nkind = \"table\"\nquantity = \"quadratic-fields\"\ndescription = \"a 2-D table\"\n\n\
               [[axis]]\nname = \"o\"\nrange = [0.0, 1.0]\ncount = 5\n\n[[axis]]\nname = \"u\"\nrange = [-1.0, 1.0]\ncount = 5\n\n\
               [emit]\nfunction = \"quad_lut\"\n";
    let specs = [spec_in(FIT, &catalog), spec_in(two, &catalog)];
    let scenes: Vec<SceneIndex> = vec![("scene_s".into(), vec![("s_one".into(), vec![(0.0, 0.5)]), ("s_two".into(), vec![(0.0, 0.5), (-2.0, 2.0)])])];
    let text = String::from_utf8(runtime_index_with_scenes(&specs, &scenes).contents).unwrap();
    for want in [
        "name: \"exp_fit\", domain: &[[0e0, 2e0]], cpu: Cpu::One(exp_fit::exp_fit)",
        "name: \"quad_lut\", domain: &[[0e0, 1e0], [-1e0, 1e0]], cpu: Cpu::Two(quad_table::quad_lut)",
        "name: \"s_one\", domain: &[[0e0, 5e-1]], cpu: Cpu::One(scene_s::s_one)",
        "name: \"s_two\", domain: &[[0e0, 5e-1], [-2e0, 2e0]], cpu: Cpu::Two(scene_s::s_two)",
    ] {
        assert!(text.contains(want), "no '{want}' in\n{text}");
    }
}

/// f(o, u) with a ripple 0.02·sin(7o)·u² that no rational field of this form follows: the
/// objectives disagree.
static RIPPLED: crate::quantity::InnerBasis = crate::quantity::InnerBasis {
    sample: |o, inner, _| {
        inner.iter().map(|i| Estimate { value: fields_value(o[0], i[0]) + 0.02 * (7.0 * o[0]).sin() * i[0] * i[0], error: 0.0, evals: 1 }).collect()
    },
    ..QUADRATIC
};

static RIPPLED_Q: QuantityDef = QuantityDef {
    name: "rippled-fields",
    eval: &|p, _| Estimate { value: fields_value(p[0], p[1]) + 0.02 * (7.0 * p[0]).sin() * p[1] * p[1], error: 0.0, evals: 1 },
    basis: Some(&RIPPLED),
    ..FIELDS_Q
};

/// The spec's objective and rms cap reach the fitters, in a fit spec and in a fields spec:
/// minimax has the lower max error on the fitting samples and least squares the lower rms, and
/// minimax under `max_rms` (set between the two, below the uncapped minimax rms) keeps its rms
/// within the cap.
#[test]
fn the_specs_objective_and_rms_cap_reach_the_fitters() {
    let catalog = Catalog { quantities: vec![&RIPPLED_Q, &EXP], kinds: vec![], features: vec![], mappings: vec![] };
    let tmp = tempfile::tempdir().unwrap();
    let build = |text: &str| build_spec(&spec_in(text, &catalog), Mode::Fit, tmp.path(), &|_| None).unwrap();
    for (text, kind) in [(FIELDS.replace("quadratic-fields", "rippled-fields"), "fields"), (FIT.to_string(), "fit")] {
        let with = |objective: &str, cap: Option<f64>| {
            let t = text.replace("objective = \"lsq\"", "objective = \"OBJ\"").replace("objective = \"minimax\"", "objective = \"OBJ\"");
            let t = t.replace("OBJ", objective);
            let t = match cap {
                Some(c) => t.replace(&format!("objective = \"{objective}\""), &format!("objective = \"{objective}\"\nmax_rms = {c:e}")),
                None => t,
            };
            build(&t)
        };
        // On the fitting samples: the fit report of a fit spec, the `fit` object of a fields
        // spec's JSON.
        let errors = |b: &Built| -> (f64, f64) {
            match &b.fit {
                Some(r) => (r.max_abs_error, r.rms_error),
                None => {
                    let j = json_of(b);
                    (j["fit"]["max_abs_error"].as_f64().unwrap(), j["fit"]["rms_error"].as_f64().unwrap())
                }
            }
        };
        let (lsq, mm) = (errors(&with("lsq", None)), errors(&with("minimax", None)));
        // Minimax lowers the max error by more than its stopping (1 %; measured 9 % on the
        // fields, more on the fit); least squares is the rms optimum, so any other fit's rms is
        // higher (by 0.7 % on the fields: the ripple is mostly outside the form).
        assert!(mm.0 < 0.99 * lsq.0 && lsq.1 < mm.1, "{kind}: least squares {lsq:?}, minimax {mm:?}");
        let cap = 0.5 * (lsq.1 + mm.1);
        let capped = errors(&with("minimax", Some(cap)));
        // Within the cap, and never worse in max than the least-squares start (on the fields
        // no reweighted iterate is within this cap: the start is kept).
        assert!(capped.1 <= cap && capped.0 <= lsq.0, "{kind}: capped {capped:?}, cap {cap}, least squares {lsq:?}");
    }
}

/// The runtime index lists for GPU verification the scalar functions only: a fit and a table
/// emitted as a constant, not a table emitted as a texture alone (its `_load` takes a texture)
/// nor a fields spec (it returns an array); every module is indexed all the same.
#[test]
fn the_runtime_index_lists_only_scalar_functions() {
    let catalog = Catalog { quantities: vec![&EXP, &FIELDS_Q], kinds: vec![], features: vec![], mappings: vec![] };
    let texture_only = TABLE.replace("exp_table", "exp_texture").replace("[emit]", "[emit]\nform = \"texture\"");
    let specs = [spec_in(FIT, &catalog), spec_in(TABLE, &catalog), spec_in(&texture_only, &catalog), spec_in(FIELDS, &catalog)];
    let text = String::from_utf8(runtime_index(&specs).contents).unwrap();
    let functions = &text[text.find("pub const FUNCTIONS").expect("the FUNCTIONS list")..];
    let listed: Vec<&str> = functions.lines().filter_map(|l| l.split("name: \"").nth(1)).map(|r| r.split('"').next().unwrap()).collect();
    assert_eq!(listed, ["exp_fit", "exp_table"], "{functions}");
    for s in &specs {
        assert!(text[..text.find("pub const FUNCTIONS").unwrap()].contains(&format!("\"{}\"", s.file.name)), "module {} not indexed:\n{text}", s.file.name);
    }
}

/// e^−x and e^−2x as the two channels of one quantity.
pub(crate) static EXP_PAIR: QuantityDef = QuantityDef {
    name: "exp-pair",
    doc: "e^-x (channel slow) and e^-2x (channel fast)",
    params: &[ParamSpec { name: "x", min: 0.0, max: 2.0, doc: "argument", integer: false, limit: None, default: None }],
    aliases: &[],
    eval: &|p, _| Estimate { value: (-p[0]).exp(), error: 0.0, evals: 1 },
    inverse: None,
    channels: &["slow", "fast"],
    eval_channels: Some(&|p, _| {
        [1.0f64, 2.0].iter().map(|k| Estimate { value: (-k * p[0]).exp(), error: 0.0, evals: 1 }).collect()
    }),
    basis: None,
};

/// A fit and a table of one channel of a vector quantity: each JSON names the channel, and
/// what was fitted or tabulated is that channel (e^−2x, re-measured from the written
/// coefficients and values); a scalar quantity's JSON names none.
#[test]
fn a_channel_spec_records_and_builds_its_channel() {
    let catalog = Catalog { quantities: vec![&EXP, &EXP_PAIR], kinds: vec![], features: vec![], mappings: vec![] };
    let tmp = tempfile::tempdir().unwrap();
    let fast = |text: &str| text.replace("quantity = \"exp-decay\"", "quantity = \"exp-pair\"\nchannel = \"fast\"");
    let fit = build_spec(&spec_in(&fast(FIT), &catalog), Mode::Fit, tmp.path(), &|_| None).unwrap();
    let j = json_of(&fit);
    assert_eq!(j["channel"], "fast");
    let c = floats(&j["model"]["coefficients"]);
    let r = |x: f64| fit_rational(&c, x);
    // A 2/2 minimax rational of e^−2x on [0, 2] is within 1e-3 (of e^−x: 1e-4); e^−x, the
    // other channel, is 0.23 away at x = 1.
    let worst = uniform(201).iter().map(|&x| (r(x) - (-2.0 * x).exp()).abs()).fold(0.0, f64::max);
    assert!(worst < 1e-3, "{worst}");
    let table = build_spec(&spec_in(&fast(TABLE), &catalog), Mode::Fit, tmp.path(), &|_| None).unwrap();
    let j = json_of(&table);
    assert_eq!(j["channel"], "fast");
    for (i, v) in floats(&j["values"]).iter().enumerate() {
        // f32 values of e^−2x at the nodes: within half an f32 ulp (≤ 2^-25 for values ≤ 1).
        assert!((v - (-2.0 * 0.125 * i as f64).exp()).abs() <= 2f64.powi(-25), "node {i}: {v}");
    }
    let scalar = build_spec(&spec(FIT), Mode::Fit, tmp.path(), &|_| None).unwrap();
    assert!(json_of(&scalar).get("channel").is_none());
}

/// A LUT's committed texels are read back in order, each its N numbers; a texel of another
/// length, a non-number, a missing `values` or another texel count is an error naming the
/// spec and what is wrong, never a table of zeros.
#[test]
fn committed_texels_read_back_each_texel_or_say_why_not() {
    let v = serde_json::json!({"values": [[1.5, -2.0], [3.0, 0.25], [1e-300, 7.0]]});
    let t: Vec<[f64; 2]> = committed_texels(&v, "lut_a", 3, "[scale, bias]").unwrap();
    assert_eq!(t, [[1.5, -2.0], [3.0, 0.25], [1e-300, 7.0]]);
    let err = |v: serde_json::Value, texels: usize| committed_texels::<2>(&v, "lut_a", texels, "[scale, bias]").unwrap_err().to_string();
    let no_array = "lut_a: generated/json/lut_a.json is missing or unreadable (no array 'values' of [scale, bias] numbers)";
    let count = err(v, 4);
    assert!(count.starts_with("lut_a: ") && count.contains("texel count differs from the spec"), "{count}");
    for bad in [
        serde_json::json!({"values": [[1.5, -2.0], [3.0], [1e-300, 7.0]]}),
        serde_json::json!({"values": [[1.5, -2.0], [3.0, 0.25, 1.0], [1e-300, 7.0]]}),
        serde_json::json!({"values": [[1.5, -2.0], [3.0, "x"], [1e-300, 7.0]]}),
        serde_json::json!({"values": [1.5, -2.0, 3.0]}),
        serde_json::json!({"texels": [[1.5, -2.0]]}),
    ] {
        assert!(err(bad.clone(), 3).starts_with(no_array), "{bad}: {}", err(bad.clone(), 3));
    }
}

/// The sentence that heads an emitted fit's documentation states the form the spec asks for,
/// read back from the spec's own text: the plain P/Q of FIT, and an offset, a factor, a clamp
/// and a denominator lead, each where the form puts it (the Rust module's doc line: see
/// `a_fit_spec_reports_the_errors_of_what_it_writes`).
#[test]
fn a_fit_is_described_by_the_form_its_spec_gives() {
    let plain = spec(FIT);
    assert_eq!(
        describe_fit(&plain, plain.model.as_ref().unwrap()),
        "e^-x by a 2/2 rational: `exp_fit` ≈ P/Q of quantity `exp-decay`, P = NUM · [(1), (x), (x^2)], Q = 1 + DEN · [(x), (x^2)]."
    );
    let full = spec(
        r#"
name = "exp_described"
kind = "fit"
quantity = "exp-decay"
description = "e^-x in every part of the form"

[[axis]]
name = "x"
range = [0.0, 2.0]
count = 16

[model]
offset = 0.25
factor = "x"
clamp = [0.0, 1.0]
numerator = ["1", "x"]
denominator_lead = "x^2"
denominator = ["1"]

[fit]
objective = "lsq"

[emit]
function = "exp_described"
"#,
    );
    assert_eq!(
        describe_fit(&full, full.model.as_ref().unwrap()),
        "e^-x in every part of the form: `exp_described` ≈ clamp(0.25 + (x)·P/Q) of quantity `exp-decay`, P = NUM · [(1), (x)], Q = (x^2) + DEN · [(1)]."
    );
}

/// A fit's JSON records the spec it came from (path, kind, quantity, description, function,
/// axes with both grids) and a model complete enough to evaluate: offset, factor, derived
/// feature, clamp and coefficients, read back here and evaluated by the form the JSON states,
/// reproduce the verification's error on its grid.
#[test]
fn a_fit_json_records_its_spec_and_a_model_that_evaluates() {
    let s = spec(
        r#"
name = "exp_recorded"
kind = "fit"
quantity = "exp-decay"
description = "e^-x through a derived feature"

[[axis]]
name = "x"
range = [0.0, 2.0]
count = 24
verify = 33

[model]
derived = { u = "2 - x" }
offset = 0.125
factor = "u"
clamp = [0.0, 1.0]
numerator = ["1", "u"]
denominator = ["u"]

[fit]
objective = "lsq"

[emit]
function = "exp_recorded"
"#,
    );
    let tmp = tempfile::tempdir().unwrap();
    let b = build_spec(&s, Mode::Fit, tmp.path(), &|_| None).unwrap();
    let j = json_of(&b);
    assert_eq!(j["spec"], json!("fits/exp_recorded.toml"));
    assert_eq!(j["kind"], json!("fit"));
    assert_eq!(j["quantity"], json!("exp-decay"));
    assert_eq!(j["description"], json!("e^-x through a derived feature"));
    assert_eq!(j["function"], json!("exp_recorded"));
    assert_eq!(j["axes"], json!([{"name": "x", "range": [0.0, 2.0], "count": 24, "verify": 33}]));
    let m = &j["model"];
    assert_eq!(m["features"], json!(["x", "u"]));
    assert_eq!(m["numerator"], json!(["1", "u"]));
    assert_eq!(m["denominator"], json!(["u"]));
    assert_eq!(m["denominator_lead"], json!("1"));
    assert_eq!(m["derived"][0]["name"], json!("u"));
    assert_eq!((m["offset"].as_f64(), m["factor"].as_str()), (Some(0.125), Some("u")));
    assert_eq!(m["clamp"], json!([0.0, 1.0]));
    assert_eq!(m["objective"], json!("lsq"));
    let c = floats(&m["coefficients"]);
    assert_eq!(c.len(), 3);
    // offset + factor · P/Q, P = c0 + c1 u, Q = 1 + c2 u, u = 2 − x, clamped to [0, 1].
    let f = |x: f64| {
        let u = 2.0 - x;
        (0.125 + u * (c[0] + c[1] * u) / (1.0 + c[2] * u)).clamp(0.0, 1.0)
    };
    let (mut worst, mut ss) = (0.0f64, 0.0);
    for x in uniform(33) {
        let e = (f(x) - (-x).exp()).abs();
        worst = worst.max(e);
        ss += e * e;
    }
    let v = &b.verification;
    // The same residuals in another operation order: 1e-15 of values ~1.
    assert_eq!(v.points, 33);
    assert!((v.max_abs_error - worst).abs() < 1e-15, "{} vs {worst}", v.max_abs_error);
    assert!((v.rms_error - (ss / 33.0).sqrt()).abs() < 1e-15, "{} vs {}", v.rms_error, (ss / 33.0).sqrt());
}
