//! The refits of the published forms as shader code: `fits/ggx_published_refits.toml`, a spec
//! of the generic `kind = "refit"` (`pipeline::refit`) over the forms of [`super::refit::FORMS`],
//! built into `wgsl/NAME.wgsl`, `src/NAME.rs` and `json/NAME.json`:
//!
//! - `F_karis(roughness, n_dot_v)` and `F_karis_separable(roughness, n_dot_v)` → (scale, bias): Karis's
//!   EnvBRDFApprox refitted to the height-correlated integral and to UE4's separable G;
//! - `F_lazarov(gloss, n_dot_v)` → (scale, bias): Lazarov's Black Ops II form;
//! - `F_materialx(n_dot_v, alpha)` → (scale, bias): MaterialX's rational pair, clamped to
//!   [0, 1] as in its source;
//! - `F_fresnel_avg_dielectric(eta)`: Kulla–Conty's two branches.
//!
//! Inputs are clamped to the domain each refit was fitted on (NaN → the lower end): n·v, r, g
//! and α to [0, 1] except MaterialX's n·v, fitted on [1/128, 125/128] (its denominators are
//! proven positive on that box, not beyond), and η to [1/3, 3]. This module holds the common
//! reader of the family's module specs and the tests of the emitted refits.

use crate::spec::{SpecError, SpecFile};
use serde_json::Value;
use std::path::Path;

/// For `Spec::parse`: the common spec of a module spec of this family (`ggx-env`, the grid
/// tolerance) of kind `kind`, or `None` when the text is not of that kind.
pub(crate) fn module_spec_file(path: &Path, text: &str, kind: &'static str, axes: Vec<Value>) -> Result<Option<SpecFile>, SpecError> {
    crate::spec::module_spec_file(path, text, kind, "ggx-env", super::grid::TOL, axes)
}

#[cfg(test)]
mod tests {
    use super::super::forms::{KARIS_FORM, KULLA_CONTY_FORM, LAZAROV_FORM, MATERIALX_FORM, MaterialX};
    use super::super::refit::{ETA, FORMS, MATERIALX_N_DOT_V, SPEC, materialx_denominators_positive, materialx_refit, repository};
    use crate::fit::expr::program::Program;
    use crate::pipeline::refit::CommittedForm;
    use serde_json::Value;
    use shadefit_runtime::ggx_published_refits as g;

    /// A 33 × 33 grid of [0, 1]² and the special f32 values.
    fn grid() -> Vec<(f32, f32)> {
        (0..=32).flat_map(|i| (0..=32).map(move |j| (i as f32 / 32.0, j as f32 / 32.0))).collect()
    }

    const SPECIAL: [f32; 9] = [f32::NAN, -f32::NAN, f32::INFINITY, f32::NEG_INFINITY, f32::MAX, -1.0, -0.0, 1e-45, 2.0];

    /// The proven lower bound of the emitted MaterialX refit's denominators (r.z and r.w of the
    /// form, constant term 1) on its clamp box n·v ∈ [1/128, 125/128] × α ∈ [0, 1] is a lower
    /// bound: positive and never above their least value on a 257 × 257 grid of the box, each
    /// evaluated as Σ_k r[k][ch]·monomial_k (the form's monomials, not the proof's model). The same with r.w's x and x² terms set to −1.9
    /// and 1 (1 − 1.9x + x² ≈ 0.0975 at x = 0.95, α = 0, where the α terms add 12.45α + 69.15α²):
    /// the bound follows the coefficients down. With x's −3 (1 − 3x + x² = −0.25 at x = ½) and
    /// with a constant term other than the model's 1, the form is refused, naming the channel.
    #[test]
    fn the_materialx_denominator_bound_is_below_the_sampled_minimum() {
        let least = |m: &MaterialX| {
            let (lo, hi) = MATERIALX_N_DOT_V;
            let mut least = f64::INFINITY;
            for i in 0..=256 {
                for j in 0..=256 {
                    let t = super::super::forms::materialx_monomials(lo + (hi - lo) * i as f64 / 256.0, j as f64 / 256.0);
                    for ch in 2..4 {
                        least = least.min((0..9).map(|k| m.r[k][ch] * t[k]).sum::<f64>());
                    }
                }
            }
            least
        };
        let m = repository().emitted().materialx;
        let lower = materialx_denominators_positive(&m).expect("proven positive");
        assert!(lower > 0.0 && lower <= least(&m), "bound {lower}, sampled least {}", least(&m));
        let mut low = m;
        (low.r[1][3], low.r[4][3]) = (-1.9, 1.0);
        let lower = materialx_denominators_positive(&low).expect("proven positive");
        assert!(least(&low) < 0.1 && lower > 0.0 && lower <= least(&low), "bound {lower}, sampled least {}", least(&low));
        let mut negative = low;
        negative.r[1][3] = -3.0;
        let err = materialx_denominators_positive(&negative).expect_err("r.w < 0 at x = ½");
        assert!(err.starts_with("channel 3: interval bound "), "{err}");
        let mut constant = m;
        constant.r[0][2] = 2.0;
        let err = materialx_denominators_positive(&constant).expect_err("constant term 2");
        assert!(err.starts_with("channel 2: constant term 2 "), "{err}");
    }

    #[test]
    fn emitted_rust_equals_the_committed_forms_in_f64() {
        let e = repository().emitted();
        let mut worst = [0.0f64; 4];
        for (u, v) in grid() {
            let (x, y) = (u as f64, v as f64);
            let pairs = [
                (g::ggx_refit_karis(u, v), e.karis_hc.eval(x, y)),
                (g::ggx_refit_karis_separable(u, v), e.karis_ue4.eval(x, y)),
                (g::ggx_refit_lazarov(u, v), e.lazarov.eval(x, y)),
                (g::ggx_refit_materialx(u, v), materialx_refit(&e.materialx, x, y)),
            ];
            for (k, (a, b)) in pairs.iter().enumerate() {
                worst[k] = worst[k].max((a[0] as f64 - b[0]).abs()).max((a[1] as f64 - b[1]).abs());
            }
        }
        // Karis and Lazarov: a handful of f32 operations on values ≤ 2 and one exp2 (≤ 2 ulp):
        // well under 1e-6. MaterialX: sums of nine terms up to ~300 in magnitude (|R|·monomial)
        // in f32, so ~9 · 300 · 2⁻²⁴ ≈ 2e-4 in each of r.xy and r.zw, divided by r.zw ≥ 1 on
        // the box (its proven lower bound is in the JSON): ≤ 5e-4.
        assert!(worst[0] < 1e-6 && worst[1] < 1e-6 && worst[2] < 1e-6, "{worst:?}");
        assert!(worst[3] < 5e-4, "{worst:?}");
        for i in 0..=64 {
            let eta = 1.0 / 3.0 + (3.0 - 1.0 / 3.0) * i as f64 / 64.0;
            // A rational of degree 1 or a cubic on values ≤ 3: a few ulps of 1.
            assert!((g::ggx_refit_fresnel_avg_dielectric(eta as f32) as f64 - e.kulla_conty.eval(eta as f32 as f64)).abs() < 1e-6);
        }
    }

    /// The emitted Rust of every refit computes its form's f32 evaluation (`Program::eval_f32`
    /// of the clamped inputs with the emitted f32 constants) bit for bit, on the grid and at
    /// the special values: the renderer keeps the form's operations and their order.
    #[test]
    fn emitted_rust_is_the_forms_f32_evaluation_bit_for_bit() {
        let e = repository().emitted();
        let c32 = |p: Vec<f64>| p.iter().map(|&v| v as f32).collect::<Vec<f32>>();
        let clamp = |v: f32, (lo, hi): (f64, f64)| crate::fit::expr::sanitize(v, lo as f32, hi as f32);
        let unit = (0.0, 1.0);
        let all = grid().into_iter().chain(SPECIAL.iter().flat_map(|&s| [(s, 0.5), (0.5, s), (s, s)]));
        for (u, v) in all {
            let bits = |p: [f32; 2]| p.map(f32::to_bits).to_vec();
            let form = |f: &Program, c: Vec<f64>, d: [(f64, f64); 2]| f.eval_f32(&[clamp(u, d[0]), clamp(v, d[1])], &c32(c)).iter().map(|x| x.to_bits()).collect::<Vec<u32>>();
            assert_eq!(bits(g::ggx_refit_karis(u, v)), form(&KARIS_FORM, e.karis_hc.params(), [unit, unit]), "karis ({u}, {v})");
            assert_eq!(bits(g::ggx_refit_karis_separable(u, v)), form(&KARIS_FORM, e.karis_ue4.params(), [unit, unit]), "karis separable ({u}, {v})");
            assert_eq!(bits(g::ggx_refit_lazarov(u, v)), form(&LAZAROV_FORM, e.lazarov.params(), [unit, unit]), "lazarov ({u}, {v})");
            assert_eq!(bits(g::ggx_refit_materialx(u, v)), form(&MATERIALX_FORM, e.materialx.params(), [MATERIALX_N_DOT_V, unit]), "materialx ({u}, {v})");
            let kc = KULLA_CONTY_FORM.eval_f32(&[clamp(u, ETA)], &c32(e.kulla_conty.params()));
            assert_eq!(g::ggx_refit_fresnel_avg_dielectric(u).to_bits(), kc[0].to_bits(), "kulla-conty {u}");
        }
    }

    #[test]
    fn emitted_rust_is_finite_for_every_input_and_nan_is_the_lower_end() {
        let all = grid().into_iter().chain(SPECIAL.iter().flat_map(|&s| [(s, 0.5), (0.5, s), (s, s)]));
        for (u, v) in all {
            for p in [g::ggx_refit_karis(u, v), g::ggx_refit_karis_separable(u, v), g::ggx_refit_lazarov(u, v), g::ggx_refit_materialx(u, v)] {
                assert!(p.iter().all(|c| c.is_finite()), "({u}, {v}): {p:?}");
            }
            assert!(g::ggx_refit_fresnel_avg_dielectric(u).is_finite());
        }
        assert_eq!(g::ggx_refit_karis(f32::NAN, 0.5), g::ggx_refit_karis(0.0, 0.5));
        assert_eq!(g::ggx_refit_materialx(f32::NAN, 0.5), g::ggx_refit_materialx((MATERIALX_N_DOT_V.0) as f32, 0.5));
        assert_eq!(g::ggx_refit_fresnel_avg_dielectric(f32::NAN), g::ggx_refit_fresnel_avg_dielectric((1.0f64 / 3.0) as f32));
    }

    /// The committed JSON's errors: each refit at most 0.8× its published form's max error on
    /// the same grid (the aim), and, re-measured here through each form's measure with
    /// the committed constants as the emitted code carries them, exactly what the JSON records.
    /// The checks the JSON records (MaterialX's proven denominator bound) are the check's.
    #[test]
    fn every_refit_beats_its_published_form_and_the_json_says_so() {
        let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/generated/json/ggx_published_refits.json")).unwrap();
        let v: Value = serde_json::from_str(&text).unwrap();
        let functions: Vec<CommittedForm> = serde_json::from_value(v["functions"].clone()).unwrap();
        assert_eq!(functions.len(), FORMS.len());
        assert_eq!(v["name"], SPEC);
        let mut rows = 0;
        for (c, f) in functions.iter().zip(&FORMS) {
            assert_eq!(c.form, f.name);
            assert_eq!(c.published_constants, (f.published)());
            for r in &c.errors {
                assert!(r.refit.max_abs_error <= 0.8 * r.published.max_abs_error, "{}: {:?} vs {:?}", r.form, r.refit, r.published);
                rows += 1;
            }
            let generated = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("generated");
            let fresh = (f.measure)(&generated, &(f.published)(), &crate::fit::published::as_emitted(&c.constants)).unwrap();
            assert_eq!(fresh, c.errors, "{}", f.name);
        }
        assert_eq!(rows, 6);
        let m = MaterialX::from_params(&crate::fit::published::as_emitted(&functions[3].constants));
        assert_eq!(functions[3].checks.get("denominator_lower_bound"), Some(&materialx_denominators_positive(&m).unwrap()));
    }
}
