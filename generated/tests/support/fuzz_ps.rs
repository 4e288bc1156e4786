//! The P̃_s pair of the fuzz family for the GPU test and its CPU side. `fuzz_ps_coeffs`
//! returns an array and `fuzz_ps` takes one, so neither is in `FUNCTIONS` (scalar functions
//! of scalars); they are run through WGSL wrappers with scalar arguments ([`WRAPPERS`],
//! composed after the library, interpreted by tests/support/bound.rs like the emitted code):
//! - `fuzz_ps_coeffs(alpha, theta_f)` itself, six results per point, over grid.rs's axes;
//! - `shadefit_fuzz_ps_given(c0, …, c5, n_dot_u, t_dot_u)`: the evaluator on exact coefficients
//!   (the CPU `fuzz_ps_coeffs` of materials across the domain and just inside its edges) over
//!   (n·u, t·u) axes with their special values. Coefficients are finite: `fuzz_ps` does
//!   arithmetic on them before its clamp, and WGSL leaves inf/NaN arithmetic indeterminate;
//! - `shadefit_fuzz_ps_at(alpha, theta_f, n_dot_u, t_dot_u)`: the two chained, as a shader
//!   calls them, with special values on all four arguments.
//!
//! Needs the including test to have grid.rs as `mod grid`.

#![allow(dead_code)]

use super::grid;
use shadefit_runtime::fuzz_ps::{FUZZ_PS_DOMAIN, fuzz_ps, fuzz_ps_coeffs};

/// Scalar-argument wrappers around the emitted pair.
pub const WRAPPERS: &str = "
fn shadefit_fuzz_ps_given(c0: f32, c1: f32, c2: f32, c3: f32, c4: f32, c5: f32, n_dot_u: f32, t_dot_u: f32) -> f32 {
    return fuzz_ps(array<f32, 6>(c0, c1, c2, c3, c4, c5), n_dot_u, t_dot_u);
}

fn shadefit_fuzz_ps_at(alpha: f32, theta_f: f32, n_dot_u: f32, t_dot_u: f32) -> f32 {
    return fuzz_ps(fuzz_ps_coeffs(alpha, theta_f), n_dot_u, t_dot_u);
}
";

/// One GPU run: a function of `arity` f32 arguments with `outputs` f32 results (an array for
/// more than one), its points (f32 bits, `arity` words each) and its CPU version.
pub struct Case {
    pub name: &'static str,
    pub arity: usize,
    pub outputs: usize,
    pub points: Vec<u32>,
    pub cpu: fn(&[f32]) -> Vec<f32>,
}

fn bits(v: &[f32]) -> Vec<u32> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn cpu_coeffs(a: &[f32]) -> Vec<f32> {
    fuzz_ps_coeffs(a[0], a[1]).to_vec()
}

fn cpu_given(a: &[f32]) -> Vec<f32> {
    vec![fuzz_ps(&[a[0], a[1], a[2], a[3], a[4], a[5]], a[6], a[7])]
}

fn cpu_at(a: &[f32]) -> Vec<f32> {
    vec![fuzz_ps(&fuzz_ps_coeffs(a[0], a[1]), a[2], a[3])]
}

/// Materials (α, θf) whose coefficients feed the evaluator: corners, edges, interior.
pub fn materials() -> Vec<(f32, f32)> {
    let [[a0, a1], [t0, t1]] = FUZZ_PS_DOMAIN;
    let alphas = [a0, 0.3, 0.5, 0.8, a1.next_down(), a1];
    let thetas = [t0, 0.1, std::f32::consts::FRAC_PI_4, 1.3, t1.next_down(), t1];
    alphas.iter().flat_map(|&a| thetas.iter().map(move |&t| (a, t))).collect()
}

/// The three cases, in the order of the module docs.
pub fn cases() -> Vec<Case> {
    let [[a0, a1], [t0, t1]] = FUZZ_PS_DOMAIN;
    // Coefficients: the special values and 128 points per axis (all pairs).
    let (alpha, theta) = (grid::axis(a0, a1, 128, 1), grid::axis(t0, t1, 128, 1));
    let mut coeffs = Vec::new();
    for &t in &theta {
        for &a in &alpha {
            coeffs.extend([a, t]);
        }
    }
    // Evaluator: every material, (n·u, t·u) over the specials of [-1, 1] and 64 points each.
    let dirs = grid::axis(-1.0, 1.0, 64, 8);
    let mut given = Vec::new();
    for (a, t) in materials() {
        let c = bits(&fuzz_ps_coeffs(a, t));
        for &tu in &dirs {
            for &nu in &dirs {
                given.extend_from_slice(&c);
                given.extend([nu, tu]);
            }
        }
    }
    // Chained: the specials of α and θf, a few directions with their specials.
    let few: Vec<u32> = bits(&[-1.5, -1.0, -0.3, 0.0, 0.4, 1.0, f32::from_bits(1)])
        .into_iter()
        .chain([0x7fc0_0000, 0xff80_0000])
        .collect();
    let mut at = Vec::new();
    for &t in &grid::specials(t0, t1) {
        for &a in &grid::specials(a0, a1) {
            for &tu in &few {
                for &nu in &few {
                    at.extend([a, t, nu, tu]);
                }
            }
        }
    }
    vec![
        Case { name: "fuzz_ps_coeffs", arity: 2, outputs: 6, points: coeffs, cpu: cpu_coeffs },
        Case { name: "shadefit_fuzz_ps_given", arity: 8, outputs: 1, points: given, cpu: cpu_given },
        Case { name: "shadefit_fuzz_ps_at", arity: 4, outputs: 1, points: at, cpu: cpu_at },
    ]
}

/// A point for messages.
pub fn show(name: &str, p: &[u32]) -> String {
    let args: Vec<String> = p.iter().map(|&b| format!("{:e}", f32::from_bits(b))).collect();
    format!("{name}({})", args.join(", "))
}
