//! The WGSL side without a GPU: composed sources validate with naga, and each emitted WGSL
//! function, interpreted from naga's IR in f32, equals its Rust CPU version bit for bit on
//! the grid of tests/support/grid.rs (so the GPU test compares against the right thing).

#[path = "support/bound.rs"]
mod bound;
#[path = "support/grid.rs"]
mod grid;
#[cfg(feature = "fuzz")]
#[path = "support/fuzz_ps.rs"]
mod fuzz_ps;

use shadefit_runtime::{FUNCTIONS, compose, compose_shader, lut, wgsl};

fn validate(src: &str) -> naga::Module {
    let module = naga::front::wgsl::parse_str(src).unwrap_or_else(|e| panic!("{}\n{src}", e.emit_to_string(src)));
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
        .validate(&module)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(src)));
    module
}

#[test]
fn composed_libraries_validate_with_naga() {
    let all = compose(wgsl::NAMES).unwrap();
    let module = validate(&all);
    for f in FUNCTIONS {
        assert!(module.functions.iter().any(|(_, g)| g.name.as_deref() == Some(f.name)), "{} missing", f.name);
    }
    for name in wgsl::NAMES {
        validate(&compose(&[name]).unwrap());
    }
}

#[test]
fn shader_with_imports_validates_with_naga() {
    let mut shader = String::new();
    for name in wgsl::NAMES {
        shader.push_str(&format!("#import shadefit::{name}\n"));
    }
    if let Some(first) = wgsl::NAMES.first() {
        shader.push_str(&format!("#import shadefit::{first};\n")); // a repeat, with `;`
    }
    shader.push_str("@group(0) @binding(0) var<storage, read_write> out: array<f32>;\n");
    shader.push_str("@compute @workgroup_size(1)\nfn main() {\n");
    for (i, f) in FUNCTIONS.iter().enumerate() {
        let args = vec!["0.5"; f.domain.len()].join(", ");
        shader.push_str(&format!("    out[{i}] = {}({args});\n", f.name));
    }
    shader.push_str("}\n");
    let src = compose_shader(&shader).unwrap();
    assert_eq!(src.matches("// ---- shadefit::").count(), wgsl::NAMES.len(), "each library once");
    validate(&src);
}

#[test]
fn texture_accessors_validate_with_naga() {
    for (k, t) in lut::TABLES.iter().enumerate() {
        // Next to the emitted library (no name clashes), in a compute shader that calls both.
        let args = vec!["0.5"; t.domain.len()].join(", ");
        let shader = format!(
            "#import shadefit::{m}\n{acc}\n@group(0) @binding(0) var<storage, read_write> out: array<f32>;\n\
             @compute @workgroup_size(1)\nfn main() {{ out[0] = {f}({args}) - {tf}({args}); }}\n",
            m = t.module,
            acc = t.wgsl(1, k as u32),
            f = t.function,
            tf = t.accessor_name(),
        );
        validate(&compose_shader(&shader).unwrap());
    }
}

#[test]
fn wgsl_equals_rust_bit_for_bit() {
    let mut total = 0;
    for f in FUNCTIONS {
        let program = bound::Program::new(&compose(&[f.module]).unwrap());
        let h = program.function(f.name);
        let counts = lut::table(f.module).map(|t| t.counts()).unwrap_or_default();
        let pts = grid::points(f, &counts);
        let arity = f.domain.len();
        // Largest bound, absolute and in ulps of the value (the latter where |value| ≥ 2^-10:
        // near zero a rational loses its relative accuracy by cancellation, and ulps of a
        // tiny or subnormal value say nothing).
        let (mut worst_abs, mut worst_ulp) = (0f64, 0f64);
        for p in pts.chunks(arity) {
            let args: Vec<f32> = p.iter().map(|&b| f32::from_bits(b)).collect();
            let (v, d) = program.eval(h, &args);
            let c = grid::cpu(f, p);
            assert!(
                v.to_bits() == c.to_bits() || (v.is_nan() && c.is_nan()),
                "{}: WGSL (interpreted) {v:e} != Rust {c:e}",
                grid::show(f, p)
            );
            assert!(c.is_finite() && d.is_finite(), "{}: value {c:e}, GPU bound {d:e}", grid::show(f, p));
            worst_abs = worst_abs.max(d);
            if c.abs() >= 1.0 / 1024.0 {
                worst_ulp = worst_ulp.max(d / bound::ulp(c as f64));
            }
        }
        total += pts.len() / arity;
        eprintln!(
            "{}: {} points, WGSL == Rust bit for bit; GPU bound up to {worst_abs:.2e} ({worst_ulp:.1} ulp where |value| >= 2^-10)",
            f.name,
            pts.len() / arity
        );
    }
    eprintln!("{} functions, {total} points", FUNCTIONS.len());
}

/// The bound of tests/support/bound.rs holds for simulated conforming GPUs: FMA contraction of
/// every `a*b ± c`, divisions off by ±2 ulp, subnormals flushed to zero, sin/cos off by up to
/// 0.999·2^-11 (each combination over the whole grid). A rule missing from the bound would
/// show up here without a GPU.
#[test]
fn bound_covers_simulated_gpus() {
    let gpus = [
        bound::Gpu { fuse: true, div_ulps: 2, flush_subnormals: true, trig: 0.999, distribute: true },
        bound::Gpu { fuse: true, div_ulps: -2, flush_subnormals: false, trig: -0.999, distribute: false },
        bound::Gpu { fuse: false, div_ulps: -2, flush_subnormals: true, trig: 0.5, distribute: true },
    ];
    for f in FUNCTIONS {
        let program = bound::Program::new(&compose(&[f.module]).unwrap());
        let h = program.function(f.name);
        let counts = lut::table(f.module).map(|t| t.counts()).unwrap_or_default();
        let pts = grid::points(f, &counts);
        for gpu in gpus {
            let (mut worst, mut differs) = (0f64, 0usize);
            for p in pts.chunks(f.domain.len()) {
                let args: Vec<f32> = p.iter().map(|&b| f32::from_bits(b)).collect();
                let (v, g, d) = program.simulate(h, &args, gpu);
                let dev = (g as f64 - v as f64).abs();
                assert!(dev <= d, "{} on {gpu:?}: simulated {g:e}, CPU {v:e}, deviation {dev:e} > bound {d:e}", grid::show(f, p));
                differs += (g != v) as usize;
                if d > 0.0 {
                    worst = worst.max(dev / d);
                }
            }
            eprintln!("{} on {gpu:?}: {differs} of {} values differ from the CPU, max deviation/bound {worst:.2}", f.name, pts.len() / f.domain.len());
        }
    }
}

/// The P̃_s pair (array result and argument, so not in `FUNCTIONS`) through the scalar
/// wrappers of tests/support/fuzz_ps.rs: interpreted WGSL equals Rust bit for bit, and the
/// bound covers the simulated GPUs of `bound_covers_simulated_gpus`.
#[cfg(feature = "fuzz")]
#[test]
fn fuzz_ps_pair_equals_rust_and_is_bounded() {
    let program = bound::Program::new(&(compose(&["fuzz_ps"]).unwrap() + fuzz_ps::WRAPPERS));
    let gpus = [
        bound::Gpu::default(),
        bound::Gpu { fuse: true, div_ulps: 2, flush_subnormals: true, trig: 0.999, distribute: false },
        bound::Gpu { fuse: true, div_ulps: -2, flush_subnormals: false, trig: -0.999, distribute: false },
    ];
    for case in fuzz_ps::cases() {
        let h = program.function(case.name);
        let (mut worst_abs, mut worst_ratio, mut n) = (0f64, 0f64, 0usize);
        for (k, p) in case.points.chunks(case.arity).enumerate() {
            let args: Vec<f32> = p.iter().map(|&b| f32::from_bits(b)).collect();
            let cpu = (case.cpu)(&args);
            // The default GPU everywhere; the others on every 7th point (the chained case costs
            // one interpretation of the coefficients per point).
            for gpu in if k % 7 == 0 { &gpus[..] } else { &gpus[..1] } {
                let got = program.simulate_all(h, &args, *gpu);
                assert_eq!(got.len(), case.outputs, "{}", fuzz_ps::show(case.name, p));
                for ((v, g, d), c) in got.into_iter().zip(&cpu) {
                    assert!(v.to_bits() == c.to_bits(), "{}: WGSL (interpreted) {v:e} != Rust {c:e}", fuzz_ps::show(case.name, p));
                    assert!(c.is_finite() && d.is_finite(), "{}: value {c:e}, bound {d:e}", fuzz_ps::show(case.name, p));
                    let dev = (g as f64 - v as f64).abs();
                    assert!(dev <= d, "{} on {gpu:?}: simulated {g:e}, CPU {v:e}, deviation {dev:e} > bound {d:e}", fuzz_ps::show(case.name, p));
                    worst_abs = worst_abs.max(d);
                    if d > 0.0 {
                        worst_ratio = worst_ratio.max(dev / d);
                    }
                }
            }
            n += 1;
        }
        eprintln!(
            "{}: {n} points x {} values, WGSL == Rust bit for bit; GPU bound up to {worst_abs:.2e}, simulated GPUs at most {worst_ratio:.2} of it",
            case.name, case.outputs
        );
    }
}

/// The gloss inverse table at the lower end of its domain on a GPU that distributes its index
/// `(x − c)·k` into `fma(x, k, −fl(c·k))`. As the module was when an NVIDIA H200 ran it
/// (Vulkan, driver 580.159, `tests/gpu.rs` on 2026-11-25), with the upper weight `f0 = t0 −
/// f32(i0)` unclamped, the simulated GPU returns, bit for bit, what the H200 returned:
/// −7.984941e-9 where the CPU returns 0, i.e. the first table step 3.9132943e-4 times the index
/// c·k − fl(c·k) = −2.04e-5. The bound covers it; without the distribution rule it is 0 there.
/// The module as emitted now clamps that weight to [0, 1], and the same GPU returns 0.
#[cfg(feature = "gloss")]
#[test]
fn a_distributing_gpu_gives_what_an_h200_gave() {
    let now = compose(&["gloss_inverse_table"]).unwrap();
    let clamped = "let f0 = clamp(t0 - f32(i0), 0.0f, 1.0f);";
    assert_eq!(now.matches(clamped).count(), 2, "the const-array and texture forms clamp their weight");
    let then = now.replace(clamped, "let f0 = t0 - f32(i0);");
    let distributing = bound::Gpu { distribute: true, ..Default::default() };
    for (text, gpu_value) in [(&then, -7.984941e-9), (&now, 0.0)] {
        let program = bound::Program::new(text);
        let h = program.function("normal_length_to_gloss_lut");
        for x in [0.0, 0.5, 2.0 / 3.0] {
            let (v, g, d) = program.simulate(h, &[x], distributing);
            assert_eq!(v, 0.0, "CPU at {x}");
            assert_eq!(g, gpu_value, "distributing GPU at {x}");
            assert!((g as f64 - v as f64).abs() <= d, "bound {d:e} at {x}");
        }
        let (_, strict, _) = program.simulate(h, &[0.0], bound::Gpu::default());
        assert_eq!(strict, 0.0, "a GPU that evaluates as written");
    }
}
