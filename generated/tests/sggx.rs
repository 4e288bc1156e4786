//! The SGGX decoder and NDF (`sggx_decode`: a struct result, so not in `FUNCTIONS`): the
//! emitted WGSL, interpreted from naga's IR in f32 through the scalar wrappers of
//! tests/support/sggx.rs, equals the Rust CPU version bit for bit on a grid of channels and
//! half-vector components (with −0, out-of-range values and 1⁻), and tests/support/bound.rs's
//! GPU deviation bound stays small (tests/gpu.rs runs the same points on a device); the Rust
//! version is finite for every special f32 input.

#[path = "support/bound.rs"]
mod bound;
#[path = "support/sggx.rs"]
mod sggx;

use shadefit_runtime::compose;
use shadefit_runtime::sggx_decode::{sggx_d, sggx_decode};

#[test]
fn wgsl_equals_rust_bit_for_bit() {
    let program = bound::Program::new(&(compose(&["sggx_decode"]).unwrap() + sggx::WRAPPERS));
    let mut worst: f64 = 0.0;
    for (name, _) in sggx::FIELDS {
        let h = program.function(name);
        for p in sggx::decode_points().chunks(3) {
            let args: Vec<f32> = p.iter().map(|&b| f32::from_bits(b)).collect();
            let (v, d) = program.eval(h, &args);
            let c = sggx::cpu_field(name, &args);
            assert_eq!(v.to_bits(), c.to_bits(), "{name}({args:?}): WGSL {v:e} != Rust {c:e}");
            assert!(c.is_finite() && d.is_finite());
            worst = worst.max(d);
        }
    }
    eprintln!("decode: WGSL == Rust bit for bit; GPU bound up to {worst:.2e}");
    let h = program.function("t_d");
    let mut worst_d: f64 = 0.0;
    let pts = sggx::d_points();
    for p in pts.chunks(6) {
        let args: Vec<f32> = p.iter().map(|&b| f32::from_bits(b)).collect();
        let (v, d) = program.eval(h, &args);
        let c = sggx::cpu_d(&args);
        assert_eq!(v.to_bits(), c.to_bits(), "d({args:?}): WGSL {v:e} != Rust {c:e}");
        // Relative GPU bound: D is a cube over a squared sum of the decoded α's.
        // α_b² = ½(Sxx + Syy − discr) cancels: a GPU's few ulps on discr are relative to α_t²,
        // so α_b² deviates by ~κ = α_t²/α_b² times that; D amplifies it ~6×. 1e-5·κ covers
        // both (measured ≤ 6e-6·κ).
        let a = sggx_decode([args[0], args[1], args[2]]);
        let kappa = (a.alpha_t_sqr / a.alpha_b_sqr) as f64;
        assert!(d <= 1e-5 * kappa * c.abs() as f64 + 1e-30, "bound {d:e} at {c:e}, κ {kappa}");
        worst_d = worst_d.max(d / (kappa * (c.abs() as f64).max(1e-30)));
    }
    eprintln!("D: {} points, WGSL == Rust bit for bit; relative GPU bound up to {worst_d:.2e}·κ", pts.len() / 6);
}

#[test]
fn rust_is_finite_for_special_inputs() {
    let sp = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, f32::MAX, f32::MIN, 0.0, -0.0, 1e-45, 1e-20, 1.0, 0.5, -2.0];
    for &x in &sp {
        for &y in &sp {
            for &z in &sp {
                let a = sggx_decode([x, y, z]);
                assert!([a.alpha_t_sqr, a.alpha_b_sqr, a.alpha_tb, a.cos_psi, a.sin_psi].iter().all(|v| v.is_finite()));
                assert!(a.alpha_b_sqr <= a.alpha_t_sqr && a.alpha_t_sqr <= 1.0 && a.alpha_b_sqr >= 1e-6);
                for &w in &sp {
                    let d = sggx_d(&a, x, y, w);
                    assert!(d.is_finite() && d >= 0.0, "D = {d}");
                }
            }
        }
    }
}
