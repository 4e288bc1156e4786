//! Every emitted CPU function, fed special f32 values (±0, denormals, ±inf, NaN, just outside
//! the domain) and a dense grid: finite and inside the range the function can reach.

use shadefit_runtime::*;

fn specials() -> Vec<f32> {
    let mut v = vec![
        0.0, -0.0, f32::MIN_POSITIVE, -f32::MIN_POSITIVE, 1e-45, -1e-45, f32::INFINITY,
        f32::NEG_INFINITY, f32::NAN, -f32::NAN, f32::MAX, f32::MIN, 1.0, -1.0,
        1.0 + f32::EPSILON, -f32::EPSILON, 0.5, 2.0 / 3.0, 0.99999,
    ];
    v.extend((0..=1000).map(|i| i as f32 / 1000.0));
    v
}

/// Range a function may return: gloss and normal lengths are in [0, 1] by definition; the
/// allowance covers f32 rounding of a rational near the ends (a few ulps of 1) and a fit's
/// own error, bounded by its measured max error in the header (< 0.03 for all gloss items).
fn in_range(v: f32) -> bool {
    v.is_finite() && (-0.03..=1.03).contains(&v)
}

#[test]
fn one_argument_functions_are_finite_for_every_input() {
    let fns: [(&str, fn(f32) -> f32); 3] = [
        ("gloss_to_normal_length", gloss_length::gloss_to_normal_length),
        ("gloss_to_normal_length_lut", gloss_table::gloss_to_normal_length_lut),
        ("normal_length_to_gloss_lut", gloss_inverse_table::normal_length_to_gloss_lut),
    ];
    for (name, f) in fns {
        for x in specials() {
            let v = f(x);
            assert!(in_range(v), "{name}({x:e}) = {v}");
        }
    }
    // NaN maps to the lower end of the domain, like a clamp would.
    assert_eq!(gloss_length::gloss_to_normal_length(f32::NAN), gloss_length::gloss_to_normal_length(0.0));
}

#[test]
fn two_argument_functions_are_finite_for_every_input() {
    let fns: [(&str, fn(f32, f32) -> f32); 2] = [
        ("combine_gloss", gloss_combine::combine_gloss),
        ("combine_gloss_lut", gloss_combine_lut::combine_gloss_lut),
    ];
    let s = specials();
    for (name, f) in fns {
        for &x in s.iter().step_by(7) {
            for &y in s.iter().step_by(11) {
                let v = f(x, y);
                assert!(in_range(v), "{name}({x:e}, {y:e}) = {v}");
            }
        }
    }
}

#[test]
fn wgsl_index_lists_every_module() {
    for name in wgsl::NAMES {
        let src = wgsl::module(name).expect("listed modules resolve");
        assert!(src.contains(&format!("#define_import_path shadefit::{name}")));
    }
    assert!(wgsl::NAMES.len() >= 5);
}
