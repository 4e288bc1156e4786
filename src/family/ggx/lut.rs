//! The DFG lookup table: its spec kind (`kind = "ggx-dfg-lut"`, [`spec`]), build ([`build`]),
//! emitted files ([`emit`]), figures ([`plot`]) and benchmark row.

pub mod build;
pub mod emit;
pub mod plot;
pub mod spec;

use crate::bench::tables::{Ladder, Params, Shape, TableBench};
use crate::family::SpecKind;
use crate::plot::PlotError;
use crate::spec::KindDef;
use std::path::{Path, PathBuf};

/// The `ggx-dfg-lut` spec kind: checked and spelled out by [`spec`], built by [`build`].
pub const DFG_LUT: SpecKind = SpecKind {
    spec: KindDef {
        name: spec::KIND,
        spec_file: crate::spec::preset_spec_file::<spec::DfgLut>,
        samples_note: "{name} is a DFG LUT: its samples are its texels, \"values\" ([scale, bias]) in generated/json/{name}.json",
        input_hash: crate::pipeline::input_hash,
    },
    build: build::build,
    shard: None,
};

/// Table benchmark rows: the default DFG LUT against numpy (Filament's Hammersley estimator,
/// Gauss–Legendre in the sampling variables).
pub static TABLES: &[TableBench] = &[TableBench {
    spec: "ggx_dfg_lut",
    order: 9,
    samples: (16, 64),
    ladder: Ladder::Tolerances(&[1e-6, 1e-8], &[1e-5, 1e-6, 1e-7, 1e-8, 1e-10]),
    reference_tolerance: 1e-12,
    // (alpha, n_dot_v, cos_cone = 0) → (scale, bias); the script takes (n_dot_v, alpha).
    shape: Shape { params: Params::Pick(&[(1, "n_dot_v"), (0, "alpha")]), channels: 2, fold_last_axis: false },
}];

/// Figures of the LUTs into `out` from the committed outputs in `generated`.
pub fn figures(out: &Path, generated: &Path) -> Result<Vec<PathBuf>, PlotError> {
    plot::figures(out, generated)
}

#[cfg(test)]
mod tests {
    use crate::spec::Preset;
    use super::build::{build, tabulate};
    use super::spec::DfgLut;
    use crate::family::ggx::integrals::{Inner, env_with};
    use crate::pipeline::{Built, Mode};
    use crate::spec::Spec;
    use std::path::Path;

    const SPEC: &str = "name = \"ggx_t\"\nkind = \"ggx-dfg-lut\"\nquantity = \"ggx-env\"\n\
        resolution = [10, 7]\ntolerance = 1e-8\n\n[emit]\nfunction = \"ggx_t\"\n";

    fn spec(text: &str) -> Spec {
        Spec::parse(Path::new("fits/ggx_t.toml"), text.to_string(), crate::family::catalog()).unwrap()
    }

    fn built(text: &str) -> Built {
        build(&spec(text), Mode::Fit, Path::new("")).unwrap()
    }

    #[test]
    fn verify_samples_the_unit_square_four_times_denser() {
        // The verification points are the centres of a grid VERIFY_DENSITY (4) times denser than
        // the 10 × 7 texels: 40 × 28 points, all in [0, 1]², 38 × 26 of them in the interior
        // (between the outer texel centres), where bilinear filtering of a curved E cannot be
        // exact, so the interior error is positive.
        let lut = DfgLut::parse(Path::new("fits/ggx_t.toml"), SPEC).unwrap();
        let (values, _) = tabulate(&lut);
        let m = super::build::verify(&lut, &values).unwrap();
        assert_eq!(m.points, 40 * 28);
        for x in [&m.texture.worst_point, &m.texture_interior.worst_point] {
            assert!(x.len() == 2 && x.iter().all(|c| (0.0..=1.0).contains(c)), "{x:?}");
        }
        assert!(m.texture_interior.max_abs_error > 0.0, "{:?}", m.texture_interior);
    }

    /// The verification's interpolation error (the encoded f64 texels, bilinear), re-measured
    /// at the same 40 × 28 points: the integral by `integrate` at 1e-10 (the texels are judged
    /// against an independent quadrature in `texels_match_the_integral_with_adaptive_azimuth_panels`),
    /// interpolated by this test's own lookup (texel centres at (i + ½)/n, clamped at the edges).
    /// The build's reference asks 1e-6 (VERIFY_TOLERANCE): the maxima agree within 1e-6 + 1e-10,
    /// and so does the error at the worst point the build states.
    #[test]
    fn verification_is_re_measured_against_the_integral() {
        let lut = DfgLut::parse(Path::new("fits/ggx_t.toml"), SPEC).unwrap();
        let (values, _) = tabulate(&lut);
        let m = super::build::verify(&lut, &values).unwrap();
        let (w, h) = (lut.width, lut.height);
        let us: Vec<f64> = (0..4 * w).map(|k| (k as f64 + 0.5) / (4 * w) as f64).collect();
        let ts: Vec<f64> = (0..4 * h).map(|k| (k as f64 + 0.5) / (4 * h) as f64).collect();
        let truth = super::build::integrate(&lut, &us, &ts, 1e-10);
        let enc: Vec<[f64; 2]> = values.iter().map(|v| lut.layout.encode(*v)).collect();
        let coord = |p: f64, n: usize| {
            let x = (p * n as f64 - 0.5).clamp(0.0, (n - 1) as f64);
            let i = (x.floor() as usize).min(n - 2);
            (i, x - i as f64)
        };
        let error_at = |u: f64, t: f64, e: &crate::family::ggx::integrals::EnvEstimate| {
            let ((i, fx), (j, fy)) = (coord(u, w), coord(t, h));
            let want = lut.layout.encode([e.scale, e.bias]);
            (0..2)
                .map(|c| {
                    let row = |j: usize| enc[j * w + i][c] * (1.0 - fx) + enc[j * w + i + 1][c] * fx;
                    (row(j) * (1.0 - fy) + row(j + 1) * fy - want[c]).abs()
                })
                .fold(0.0f64, f64::max)
        };
        let mut max = 0.0f64;
        for (l, &t) in ts.iter().enumerate() {
            for (k, &u) in us.iter().enumerate() {
                max = max.max(error_at(u, t, &truth[l * us.len() + k]));
            }
        }
        let bound = 1e-6 + 1e-10;
        assert!((m.interpolation.max_abs_error - max).abs() <= bound, "claimed {:e}, re-measured {max:e}", m.interpolation.max_abs_error);
        assert!(max > 100.0 * bound, "not a vacuous comparison: {max:e}");
        let (u, t) = (m.interpolation.worst_point[0], m.interpolation.worst_point[1]);
        let (k, l) = (us.iter().position(|&x| x == u).unwrap(), ts.iter().position(|&x| x == t).unwrap());
        assert!((error_at(u, t, &truth[l * us.len() + k]) - m.interpolation.max_abs_error).abs() <= bound);
    }

    fn artifact<'a>(b: &'a Built, suffix: &str) -> &'a [u8] {
        &b.artifacts.iter().find(|a| a.path.to_str().unwrap().ends_with(suffix)).unwrap().contents
    }

    /// The KTX2 texels (f16 → f32), row-major, `channels` per texel.
    fn ktx2_values(bytes: &[u8], channels: usize) -> Vec<f32> {
        let r = ktx2::Reader::new(bytes).expect("a valid KTX2 file");
        let vk = r.header().format.map(|f| f.value());
        assert_eq!(vk, Some(if channels == 2 { 83 } else { 97 }), "R16G16_SFLOAT or R16G16B16A16_SFLOAT");
        let data = r.levels().next().unwrap().data;
        data.chunks(2).map(|b| half::f16::from_le_bytes([b[0], b[1]]).to_f32()).collect()
    }

    #[test]
    fn texels_match_the_integral_with_adaptive_azimuth_panels() {
        // Independent of the nested azimuth rules: G10/K21 panels at 1e-12. Each texel is
        // within the spec's tolerance 1e-8 (the contract of env) plus the reference's 1e-12;
        // also with a cone and in alpha rows.
        for text in [
            SPEC.to_string(),
            SPEC.replace("[10, 7]", "[10, 7]\ncos_cone = 0.4\nroughness_mapping = \"alpha\""),
            SPEC.replace("ggx-env", "ggx-env-ue4"),
        ] {
            let lut = DfgLut::parse(Path::new("fits/ggx_t.toml"), &text).unwrap();
            let (values, q) = tabulate(&lut);
            assert!(q.max_error_estimate <= 1e-8, "{q:?}");
            for (k, v) in values.iter().enumerate() {
                let (i, j) = (k % lut.width, k / lut.width);
                let alpha = lut.alpha(j);
                let r = env_with(alpha, lut.n_dot_v(i), lut.cos_cone, lut.shadowing_at(alpha), 1e-12, Inner::Adaptive);
                assert!((v[0] - r.scale).abs() <= 1e-8 + 1e-12 && (v[1] - r.bias).abs() <= 1e-8 + 1e-12, "texel ({i}, {j}): {v:?} vs {r:?}");
            }
        }
    }

    #[test]
    fn ktx2_holds_the_f16_texels_in_the_layout_and_filament_g_is_scale_plus_bias() {
        let sb = built(SPEC);
        let fil = built(&SPEC.replace("[10, 7]", "[10, 7]\nlayout = \"filament\"\ntexture_format = \"rgba16float\""));
        let json: serde_json::Value = serde_json::from_slice(artifact(&sb, ".json")).unwrap();
        let values: Vec<[f64; 2]> = serde_json::from_value(json["values"].clone()).unwrap();
        let t_sb = ktx2_values(artifact(&sb, ".ktx2"), 2);
        let t_fil = ktx2_values(artifact(&fil, ".ktx2"), 4);
        let f16 = |x: f64| half::f16::from_f32(x as f32).to_f32();
        for (k, &[scale, bias]) in values.iter().enumerate() {
            // Scale-bias: R = scale, G = bias, each rounded f64 → f32 → f16 (nearest).
            assert_eq!((t_sb[2 * k], t_sb[2 * k + 1]), (f16(scale), f16(bias)), "texel {k}");
            // Filament: R = bias, G = scale + bias (summed in f64, then rounded), B = 0, A = 1.
            assert_eq!(&t_fil[4 * k..4 * k + 4], &[f16(bias), f16(scale + bias), 0.0, 1.0], "texel {k}");
            // Decoding Filament's G − R gives the scale to within the two f16 roundings
            // (half an ulp each: 2⁻¹² relative of values ≤ 1, plus subnormal spacing 2⁻²⁴).
            let decoded = (t_fil[4 * k + 1] - t_fil[4 * k]) as f64;
            assert!((decoded - scale).abs() <= 2.0 * (2f64.powi(-12) * (scale + bias) + 2f64.powi(-25)), "texel {k}");
        }
        // The measured texture errors are in the JSON and the summary (the Built verification).
        let m = &json["verification"];
        assert_eq!(m["points"], 40 * 28);
        assert_eq!(sb.verification.max_abs_error, m["texture"]["max_abs_error"].as_f64().unwrap());
        assert!(m["texture_interior"]["max_abs_error"].as_f64().unwrap() <= sb.verification.max_abs_error);
    }

    #[test]
    fn build_is_deterministic_across_threads_and_committed_mode_rerenders_it() {
        let s = spec(SPEC);
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| build(&s, Mode::Fit, Path::new("")).unwrap())
        };
        let (one, two) = (run(1), run(2));
        assert_eq!(one.artifacts.len(), 5);
        for (a, b) in one.artifacts.iter().zip(&two.artifacts) {
            assert!(a.path == b.path && a.contents == b.contents, "{} differs between 1 and 2 threads", a.path.display());
        }
        // build --check: everything re-rendered from the committed JSON, byte for byte.
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(dir.path().join("json")).unwrap();
        std::fs::write(dir.path().join("json/ggx_t.json"), artifact(&one, ".json")).unwrap();
        let again = build(&s, Mode::Committed, dir.path()).unwrap();
        for (a, b) in one.artifacts.iter().zip(&again.artifacts) {
            assert!(a.path == b.path && a.contents == b.contents, "{} differs when re-rendered", a.path.display());
        }
    }

    /// `cargo test --release -p shadefit --lib dfg_lut_128_timing -- --ignored --nocapture`:
    /// the texels of fits/ggx_dfg_lut.toml (128², tol 1e-7), wall time and evaluations.
    #[test]
    #[ignore]
    fn dfg_lut_128_timing() {
        let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/fits/ggx_dfg_lut.toml")).unwrap();
        let lut = DfgLut::parse(Path::new("fits/ggx_dfg_lut.toml"), &text).unwrap();
        for _ in 0..3 {
            let t0 = std::time::Instant::now();
            let (_, q) = tabulate(&lut);
            println!(
                "{}x{} texels at tol {:e}: {:.3} s wall on {} thread(s), {} evals/texel, max error estimate {:.2e}",
                lut.width, lut.height, lut.tolerance, t0.elapsed().as_secs_f64(), rayon::current_num_threads(), q.evals_per_texel, q.max_error_estimate
            );
        }
    }

    /// `cargo test --release -p shadefit --lib dfg_lut_128_error -- --ignored --nocapture`:
    /// every texel of fits/ggx_dfg_lut.toml against the adaptive-panel reference at 1e-12.
    #[test]
    #[ignore]
    fn dfg_lut_128_error() {
        use rayon::prelude::*;
        let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/fits/ggx_dfg_lut.toml")).unwrap();
        let lut = DfgLut::parse(Path::new("fits/ggx_dfg_lut.toml"), &text).unwrap();
        let (values, q) = tabulate(&lut);
        let worst = (0..values.len())
            .into_par_iter()
            .map(|k| {
                let (i, j) = (k % lut.width, k / lut.width);
                let alpha = lut.alpha(j);
                let r = env_with(alpha, lut.n_dot_v(i), 0.0, lut.shadowing_at(alpha), 1e-12, Inner::Adaptive);
                ((values[k][0] - r.scale).abs().max((values[k][1] - r.bias).abs()), k)
            })
            .reduce(|| (0.0, 0), |a, b| if b.0 > a.0 { b } else { a });
        println!("max |texel − reference| = {:.3e} at texel {:?}; largest estimate {:.3e}", worst.0, (worst.1 % lut.width, worst.1 / lut.width), q.max_error_estimate);
        assert!(worst.0 <= lut.tolerance);
    }
}
