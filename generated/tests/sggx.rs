//! The SGGX decoder and NDF (`sggx_decode`: a struct result, so not in `FUNCTIONS`): the
//! emitted WGSL, interpreted from naga's IR in f32 through scalar wrappers, equals the Rust
//! CPU version bit for bit on a grid of channels and half-vector components (with ±0, the ends
//! and out-of-range values), and tests/support/bound.rs's GPU deviation bound stays small; the
//! Rust version is finite for every special f32 input.

#[path = "support/bound.rs"]
mod bound;

use shadefit_runtime::compose;
use shadefit_runtime::sggx_decode::{SggxAniso, sggx_d, sggx_decode};

const WRAPPERS: &str = "
fn t_alpha_t_sqr(x: f32, y: f32, z: f32) -> f32 { return sggx_decode(vec3<f32>(x, y, z)).alpha_t_sqr; }
fn t_alpha_b_sqr(x: f32, y: f32, z: f32) -> f32 { return sggx_decode(vec3<f32>(x, y, z)).alpha_b_sqr; }
fn t_alpha_tb(x: f32, y: f32, z: f32) -> f32 { return sggx_decode(vec3<f32>(x, y, z)).alpha_tb; }
fn t_cos_psi(x: f32, y: f32, z: f32) -> f32 { return sggx_decode(vec3<f32>(x, y, z)).cos_psi; }
fn t_sin_psi(x: f32, y: f32, z: f32) -> f32 { return sggx_decode(vec3<f32>(x, y, z)).sin_psi; }
fn t_d(x: f32, y: f32, z: f32, th: f32, bh: f32, nh: f32) -> f32 {
    return sggx_d(sggx_decode(vec3<f32>(x, y, z)), th, bh, nh);
}
";

fn channels() -> Vec<f32> {
    let mut v: Vec<f32> = (0..=12).map(|i| i as f32 / 12.0).collect();
    // No tiny channels: a subnormal Sxy may flush to zero on a GPU and flip the sign test
    // (harmlessly: the α's are then equal to rounding and the axis is arbitrary); the Rust side
    // is checked on them below.
    v.extend([-0.0, -0.5, 1.5, 0.999_999_94]);
    v
}

#[test]
fn wgsl_equals_rust_bit_for_bit() {
    let program = bound::Program::new(&(compose(&["sggx_decode"]).unwrap() + WRAPPERS));
    let fields: [(&str, fn(&SggxAniso) -> f32); 5] = [
        ("t_alpha_t_sqr", |a| a.alpha_t_sqr),
        ("t_alpha_b_sqr", |a| a.alpha_b_sqr),
        ("t_alpha_tb", |a| a.alpha_tb),
        ("t_cos_psi", |a| a.cos_psi),
        ("t_sin_psi", |a| a.sin_psi),
    ];
    let ch = channels();
    let mut worst: f64 = 0.0;
    for (name, field) in fields {
        let h = program.function(name);
        for &x in &ch {
            for &y in &ch {
                for &z in &ch {
                    let (v, d) = program.eval(h, &[x, y, z]);
                    let c = field(&sggx_decode([x, y, z]));
                    assert_eq!(v.to_bits(), c.to_bits(), "{name}({x}, {y}, {z}): WGSL {v:e} != Rust {c:e}");
                    assert!(c.is_finite() && d.is_finite());
                    worst = worst.max(d);
                }
            }
        }
    }
    eprintln!("decode: WGSL == Rust bit for bit; GPU bound up to {worst:.2e}");
    let h = program.function("t_d");
    let dots = [-1.0f32, -0.7, -0.3, 0.0, 0.2, 0.5, 0.9, 1.0, 1.5];
    let few = [0.0f32, 0.1, 0.5, 0.75, 1.0];
    let mut n = 0;
    let mut worst_d: f64 = 0.0;
    for &x in &few {
        for &y in &few {
            for &z in &few {
                let a = sggx_decode([x, y, z]);
                for &th in &dots {
                    for &bh in &dots {
                        for &nh in &dots {
                            let (v, d) = program.eval(h, &[x, y, z, th, bh, nh]);
                            let c = sggx_d(&a, th, bh, nh);
                            assert_eq!(v.to_bits(), c.to_bits(), "d({x}, {y}, {z}; {th}, {bh}, {nh}): WGSL {v:e} != Rust {c:e}");
                            // Relative GPU bound: D is a cube over a squared sum of the decoded α's.
                            // α_b² = ½(Sxx + Syy − discr) cancels: a GPU's few ulps on discr are
                            // relative to α_t², so α_b² deviates by ~κ = α_t²/α_b² times that; D
                            // amplifies it ~6×. 1e-5·κ covers both (measured ≤ 1.2e-5·κ).
                            let kappa = (a.alpha_t_sqr / a.alpha_b_sqr) as f64;
                            assert!(d <= 1e-5 * kappa * c.abs() as f64 + 1e-30, "bound {d:e} at {c:e}, κ {kappa}");
                            worst_d = worst_d.max(d / (kappa * (c.abs() as f64).max(1e-30)));
                            n += 1;
                        }
                    }
                }
            }
        }
    }
    eprintln!("D: {n} points, WGSL == Rust bit for bit; relative GPU bound up to {worst_d:.2e}·κ");
}

#[test]
fn rust_is_finite_for_special_inputs() {
    let sp = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, f32::MAX, f32::MIN, 0.0, -0.0, 1e-45, 1.0, 0.5, -2.0];
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
