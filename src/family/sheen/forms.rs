//! The published sheen forms, each written once as a [`Program`] over its own inputs (in its
//! source's argument order and roughness convention) with its published constants, copied from
//! the files named on each. Their f64 evaluation (what `validate` measures and a refit moves),
//! their f32 evaluation and their emitted text derive from the program. e^x is written
//! 2^(x·log₂e) and x^c as 2^(c·log₂x) (the IR has base-2 functions only; log₂e is an f32
//! literal, a relative error ≤ 3e-8 in the exponent).

use crate::fit::expr::Expr;
use crate::shading::charlie::{EK_P0, EK_P1};
use crate::fit::expr::program::{Program, build::*};
use std::sync::LazyLock;

fn exp(x: Expr) -> Expr {
    exp2(x * lit(std::f32::consts::LOG2_E))
}

fn log2(x: Expr) -> Expr {
    Expr::Log2(Box::new(x))
}

fn pow(x: Expr, p: f32) -> Expr {
    Expr::Pow(Box::new(x), p)
}

fn one() -> Expr {
    lit(1.0)
}

/// x^c for x ≥ 0 and c > 0: 2^(c·log₂x) where x > 0, else 0 (log₂0 is not defined in WGSL).
fn power(x: Expr, c: Expr) -> Expr {
    Expr::Select(Box::new(x.clone()), Box::new(exp2(c * log2(x))), Box::new(lit(0.0)))
}

/// Estevez–Kulla's Λ curve (KHR_materials_sheen "Sheen visibility"; the glTF Sample Viewer's
/// `lambdaSheen`), over (α, μ): L(x) = a/(1 + b x^c) + d x + e with (a, b, c, d, e) =
/// mix(P1, P0, (1 − α)²); Λ = e^L(μ) for μ < 0.5, else e^(2 L(0.5) − L(1 − μ)). Constants P0
/// (k0…k4), then P1 (k5…k9).
pub static EK_LAMBDA: LazyLock<Program> = LazyLock::new(|| {
    let t = || bind(0);
    let p = |i: usize| bind(1 + i);
    let l = |x: Expr, x_c: Expr| p(0) / (one() + p(1) * x_c) + p(3) * x + p(4);
    let mut lets = vec![("t".to_string(), (one() - var(0)) * (one() - var(0)))];
    for (i, n) in ["a", "b", "c", "d", "e"].iter().enumerate() {
        lets.push((n.to_string(), k(5 + i) + (k(i) - k(5 + i)) * t()));
    }
    let mu = || var(1);
    let rev = || one() - var(1);
    lets.push(("l_mu".into(), l(mu(), power(mu(), p(2)))));
    lets.push(("l_half".into(), l(lit(0.5), exp2(-p(2)))));
    lets.push(("l_rev".into(), l(rev(), power(rev(), p(2)))));
    Program { lets, result: less(var(1), lit(0.5), exp(bind(6)), exp(lit(2.0) * bind(7) - bind(8))) }
});

/// P0 (α = 0 end) and P1 (α = 1 end), KHR_materials_sheen's table.
pub const EK_PUBLISHED: [f64; 10] = {
    let mut c = [0.0; 10];
    let mut i = 0;
    while i < 5 {
        c[i] = EK_P0[i];
        c[5 + i] = EK_P1[i];
        i += 1;
    }
    c
};

/// three.js `IBLSheenBRDF` from r181 (mrdoob/three.js PR #32397, `lights_physical_pars_fragment`),
/// over (r, n·v), r = sheenRoughness (three.js's BRDF_Sheen takes α = r²):
/// r_inv = 1/(r + 0.1), a = a₀ + a₁r + a₂r² + a₃r_inv, b likewise, E = saturate(e^(a n·v + b)).
/// Constants a₀…a₃, b₀…b₃, then the 0.1.
pub static THREEJS_2025: LazyLock<Program> = LazyLock::new(|| {
    let r = || var(0);
    let poly = |c: usize| k(c) + k(c + 1) * r() + k(c + 2) * r() * r() + k(c + 3) * bind(0);
    Program {
        lets: vec![("r_inv".into(), one() / (r() + k(8))), ("a".into(), poly(0)), ("b".into(), poly(4))],
        result: clamp(exp(bind(1) * var(1) + bind(2)), lit(0.0), one()),
    }
});

pub const THREEJS_2025_PUBLISHED: [f64; 9] = [-1.9362, 1.0678, 0.4573, -0.8469, -0.6014, 0.5538, -0.4670, -0.1255, 0.1];

/// three.js `IBLSheenBRDF` of 2021 to r180 (PR #23069), over (r, n·v): piecewise at r = 0.25,
/// a = a₂r² + a₁r + a₀ and b = b₂r² + b₁r + b₀ on each side, DG = e^(a n·v + b) (+ c (r − 0.25)
/// from r = 0.25), E = saturate(DG/π). Constants (a₂, a₁, a₀, b₂, b₁, b₀) below 0.25, the same
/// above, then c.
pub static THREEJS_2021: LazyLock<Program> = LazyLock::new(|| {
    let r = || var(0);
    let quad = |c: usize| k(c) * bind(0) + k(c + 1) * r() + k(c + 2);
    let split = |lo: Expr, hi: Expr| less(r(), lit(0.25), lo, hi);
    Program {
        lets: vec![
            ("r2".into(), r() * r()),
            ("a".into(), split(quad(0), quad(6))),
            ("b".into(), split(quad(3), quad(9))),
            ("dg".into(), exp(bind(1) * var(1) + bind(2)) + split(lit(0.0), k(12) * (r() - lit(0.25)))),
        ],
        result: clamp(bind(3) * lit(std::f32::consts::FRAC_1_PI), lit(0.0), one()),
    }
});

pub const THREEJS_2021_PUBLISHED: [f64; 13] = [-339.2, 161.4, -25.9, 44.0, -23.7, 3.26, -8.48, 14.3, -9.95, 1.97, -3.27, 0.72, 0.1];

/// MaterialX `mx_imageworks_sheen_dir_albedo_analytic` (AcademySoftwareFoundation/MaterialX
/// libraries/pbrlib/genglsl/lib/mx_microfacet_sheen.glsl), over (n·v, roughness) with the
/// roughness MaterialX's sheen D takes as α itself (`invRoughness = 1/roughness`): a rational
/// quadratic in (μ, r), p/q with q's constant 1, clamped to [0, 1] by its caller
/// `mx_imageworks_sheen_dir_albedo`. Constants p over (1, μ, r, μr, μ², r²), then q over
/// (μ, r, μr, μ², r²).
pub static MATERIALX: LazyLock<Program> = LazyLock::new(|| {
    let (m, r) = (|| var(0), || var(1));
    let mono = |j: usize| match j {
        0 => m(),
        1 => r(),
        2 => m() * r(),
        3 => m() * m(),
        _ => r() * r(),
    };
    let p = (0..5).fold(k(0), |acc, j| acc + k(1 + j) * mono(j));
    let q = (0..5).fold(one(), |acc, j| acc + k(6 + j) * mono(j));
    Program { lets: vec![("p".into(), p), ("q".into(), q)], result: clamp(bind(0) / bind(1), lit(0.0), one()) }
});

pub const MATERIALX_PUBLISHED: [f64; 11] = [13.67300, -68.78018, 799.08825, -905.00061, 60.28956, 1086.96473, 61.57746, 442.78211, 2597.49308, 121.81241, 3045.55075];

/// Babylon.js `getBRDFLookupCharlieSheen` (pbrBRDFFunctions, "NOT USED", under SHEEN_SOFTER:
/// the lobe with Estevez–Kulla's visibility), over (n·v, perceptual roughness r; Babylon's D
/// takes α = r²): E = k₀ (1 − n·v)³ + 1/(k₁ + e^(k₂ r + k₃)).
pub static BABYLON: LazyLock<Program> = LazyLock::new(|| {
    Program {
        lets: vec![("c".into(), one() - var(0))],
        result: k(0) * pow(bind(0), 3.0) + one() / (k(1) + exp(k(2) * var(1) + k(3))),
    }
});

pub const BABYLON_PUBLISHED: [f64; 4] = [0.65584461, 4.16526551, -7.97291361, 6.33516894];

/// Filament `prefilteredDFG_Cloth_Charlie` (google/filament libs/ibl/src/CubemapIBL.cpp, marked
/// unused), first channel (the second is 0.0095 times it), over (n·v, roughness r):
/// a = 1 − n·v, b = 1 − r, c = (k₂ + a)⁶⁴ 2^(−k₁ (b − k₀)²) + k₄ (a + k₅) r + (b + k₃)² a⁸,
/// min(c, 18).
pub static FILAMENT_CHARLIE: LazyLock<Program> = LazyLock::new(|| {
    let (a, b) = (|| bind(0), || bind(1));
    Program {
        lets: vec![("a".into(), one() - var(0)), ("b".into(), one() - var(1)), ("e".into(), b() - k(0)), ("f".into(), b() + k(3))],
        result: min(
            pow(k(2) + a(), 64.0) * exp2(-(bind(2) * bind(2)) * k(1)) + k(4) * (a() + k(5)) * var(1) + bind(3) * bind(3) * pow(a(), 8.0),
            lit(18.0),
        ),
    }
});

pub const FILAMENT_CHARLIE_PUBLISHED: [f64; 6] = [0.95, 1250.0, 0.04, 0.2, 0.3, 0.2];

/// Filament `prefilteredDFG_Cloth_Ashikhmin` (same file, marked unused), first channel (the
/// second is 0.03 times it), over (n·v, roughness r): s = 1 − n·v,
/// g = k₀ 2^(−(s − k₁)²/(2 k₂)) + k₃ s, n = k₄ r + k₅, max(1 − n², k₆)·g.
pub static FILAMENT_ASHIKHMIN: LazyLock<Program> = LazyLock::new(|| {
    let s = || bind(0);
    Program {
        lets: vec![
            ("s".into(), one() - var(0)),
            ("e".into(), s() - k(1)),
            ("g".into(), k(0) * exp2(-(bind(1) * bind(1)) / (lit(2.0) * k(2))) + s() * k(3)),
            ("n".into(), var(1) * k(4) + k(5)),
        ],
        result: max(one() - bind(3) * bind(3), k(6)) * bind(2),
    }
});

pub const FILAMENT_ASHIKHMIN_PUBLISHED: [f64; 7] = [0.24, 0.93, 0.01, 0.20, 2.0, -1.3, 0.4];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shading::charlie::lambda_estevez_kulla;

    /// Each program is its source's formula, written out here a second time from the source
    /// text (the same operations in plain f64): 1e-6 relative bounds the f32 log₂e literal in
    /// the exponents (≤ 3e-8 relative on exponents ≤ 25 in size).
    #[test]
    fn the_programs_are_their_sources_formulas() {
        let close = |got: f64, want: f64, what: &str| assert!((got - want).abs() <= 1e-6 * want.abs().max(1e-3), "{what}: {got} vs {want}");
        for (a, m) in [(0.01, 0.0), (0.09, 0.3), (0.25, 0.5), (0.5, 0.7), (1.0, 1.0), (0.7, 0.49)] {
            close(EK_LAMBDA.eval_f64(&[a, m], &EK_PUBLISHED)[0], lambda_estevez_kulla(a, m), &format!("EK at ({a}, {m})"));
        }
        for (r, m) in [(0.1f64, 0.0f64), (0.2, 0.5), (0.25, 0.3), (0.6, 0.9), (1.0, 1.0)] {
            let ri = 1.0 / (r + 0.1);
            let a = -1.9362 + 1.0678 * r + 0.4573 * r * r - 0.8469 * ri;
            let b = -0.6014 + 0.5538 * r - 0.4670 * r * r - 0.1255 * ri;
            close(THREEJS_2025.eval_f64(&[r, m], &THREEJS_2025_PUBLISHED)[0], (a * m + b).exp().clamp(0.0, 1.0), "three.js 2025");
            let (a, b, c) = if r < 0.25 {
                (-339.2 * r * r + 161.4 * r - 25.9, 44.0 * r * r - 23.7 * r + 3.26, 0.0)
            } else {
                (-8.48 * r * r + 14.3 * r - 9.95, 1.97 * r * r - 3.27 * r + 0.72, 0.1 * (r - 0.25))
            };
            close(THREEJS_2021.eval_f64(&[r, m], &THREEJS_2021_PUBLISHED)[0], (((a * m + b).exp() + c) / std::f64::consts::PI).clamp(0.0, 1.0), "three.js 2021");
            let p = 13.67300 - 68.78018 * m + 799.08825 * r - 905.00061 * m * r + 60.28956 * m * m + 1086.96473 * r * r;
            let q = 1.0 + 61.57746 * m + 442.78211 * r + 2597.49308 * m * r + 121.81241 * m * m + 3045.55075 * r * r;
            close(MATERIALX.eval_f64(&[m, r], &MATERIALX_PUBLISHED)[0], (p / q).clamp(0.0, 1.0), "MaterialX");
            let c = 1.0 - m;
            close(BABYLON.eval_f64(&[m, r], &BABYLON_PUBLISHED)[0], 0.65584461 * c * c * c + 1.0 / (4.16526551 + (-7.97291361 * r + 6.33516894).exp()), "Babylon");
            let (a, b) = (1.0 - m, 1.0 - r);
            let cc = (0.04 + a).powf(64.0) * (-(b - 0.95) * (b - 0.95) * 1250.0).exp2() + 0.3 * (a + 0.2) * r + (b + 0.2) * (b + 0.2) * a.powi(8);
            close(FILAMENT_CHARLIE.eval_f64(&[m, r], &FILAMENT_CHARLIE_PUBLISHED)[0], cc.min(18.0), "Filament cloth Charlie");
            let s = 1.0 - m;
            let g = 0.24 * (-(s - 0.93) * (s - 0.93) / (2.0 * 0.01)).exp2() + s * 0.2;
            let n = r * 2.0 - 1.3;
            close(FILAMENT_ASHIKHMIN.eval_f64(&[m, r], &FILAMENT_ASHIKHMIN_PUBLISHED)[0], (1.0 - n * n).max(0.4) * g, "Filament cloth Ashikhmin");
        }
    }
}
