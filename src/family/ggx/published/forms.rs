//! The published forms, constants and formulas copied from their sources (named on each).
//!
//! All return the split-sum pair [scale, bias] = [A, B] of `super::super::integrals` (the
//! environment BRDF of a Schlick F0 is F0·A + B), except the Fresnel average.
//!
//! Each form is written once, as a [`Program`] over its inputs and its constants (`params()`
//! order): its f64 evaluation here, the refits (`super::refit`), the emitted refits
//! (`super::emit`) and the bench's shader forms all derive from it.

use crate::fit::expr::program::{Program, build::*};
use crate::fit::expr::tape::Compiled;
use std::array::from_fn;
use std::sync::LazyLock;

/// The pair forms compiled (the refits' objectives evaluate them at every point of every step).
pub static KARIS_TAPE: Compiled = Compiled::of(&KARIS_FORM);
pub static LAZAROV_TAPE: Compiled = Compiled::of(&LAZAROV_FORM);
pub static MATERIALX_TAPE: Compiled = Compiled::of(&MATERIALX_FORM);

/// Karis 2014, "Physically Based Shading on Mobile" (Unreal Engine blog), `EnvBRDFApprox`
/// (as in UE's `BRDF.ush`; bevy's `F_AB` up to v0.18.1 is the same text):
/// ```text
/// c0 = (−1, −0.0275, −0.572, 0.022),  c1 = (1, 0.0425, 1.04, −0.04)
/// r = Roughness·c0 + c1
/// a004 = min(r.x², exp2(−9.28 n·v))·r.x + r.y
/// AB = (−1.04, 1.04)·a004 + r.zw
/// ```
/// with perceptual `Roughness` (α = Roughness²). `k` is the −9.28 and `s` the 1.04: the
/// same form with new constants is a [`Karis`] too. UE's `saturate(50·F0.g)` on B (the
/// "specular occlusion" of F0 < 2 %) is a shading choice, not part of the fit, and is left out.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Karis {
    pub c0: [f64; 4],
    pub c1: [f64; 4],
    pub k: f64,
    pub s: f64,
}

pub const KARIS: Karis = Karis { c0: [-1.0, -0.0275, -0.572, 0.022], c1: [1.0, 0.0425, 1.04, -0.04], k: -9.28, s: 1.04 };

/// Karis's form over (roughness, n·v) with constants c0, c1, k, s ([`Karis::params`]).
pub static KARIS_FORM: LazyLock<Program> = LazyLock::new(|| {
    let r = || bind(2);
    Program {
        lets: vec![
            ("c0".into(), constants(0, 4)),
            ("c1".into(), constants(4, 4)),
            ("r".into(), var(0) * bind(0) + bind(1)),
            ("a004".into(), min(swz(r(), "x") * swz(r(), "x"), exp2(k(8) * var(1))) * swz(r(), "x") + swz(r(), "y")),
        ],
        result: vector(vec![-k(9), k(9)]) * bind(3) + swz(r(), "zw"),
    }
});

impl Karis {
    /// [A, B] at perceptual roughness `r` and n·v.
    pub fn eval(&self, r: f64, n_dot_v: f64) -> [f64; 2] {
        KARIS_TAPE.pair([r, n_dot_v], &self.params())
    }

    pub fn params(&self) -> Vec<f64> {
        self.c0.iter().chain(&self.c1).copied().chain([self.k, self.s]).collect()
    }

    pub fn from_params(p: &[f64]) -> Karis {
        Karis { c0: from_fn(|i| p[i]), c1: from_fn(|i| p[4 + i]), k: p[8], s: p[9] }
    }
}

/// bevy's `F_AB` from v0.19 (PR #22833): Karis's pair clamped below at 0.00005
/// ("Keep F_ab positive to avoid divide-by-zero in downstream BRDF terms").
pub fn bevy_clamped(r: f64, n_dot_v: f64) -> [f64; 2] {
    KARIS.eval(r, n_dot_v).map(|v| v.max(0.00005))
}

/// Lazarov 2013, "Getting More Physical in Call of Duty: Black Ops II" (SIGGRAPH course), the
/// environment BRDF of gloss g, as carried by OpenXRay `pbr_brdf_blinn.h` (`EnvBlops2`, "credit
/// to Treyarch"):
/// ```text
/// t = (1/0.96, 0.475, (0.0275 − 0.25·0.04)/0.96, 0.25)·g + (0, 0, (0.015 − 0.75·0.04)/0.96, 0.75)
/// a0 = t.x·min(t.y, exp2(−9.28 n·v)) + t.z,   a1 = t.w
/// env(F0) = a0 + F0·(a1 − a0)
/// ```
/// so A = a1 − a0 and B = a0 (Lazarov's `saturate` of the sum is left out: the pair is what
/// is fitted). `slope` is the g-multiplied vector, `offset` its two constant terms (z, w) and
/// `k` the −9.28.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lazarov {
    pub slope: [f64; 4],
    pub offset: [f64; 2],
    pub k: f64,
}

pub const LAZAROV: Lazarov = Lazarov {
    slope: [1.0 / 0.96, 0.475, (0.0275 - 0.25 * 0.04) / 0.96, 0.25],
    offset: [(0.015 - 0.75 * 0.04) / 0.96, 0.75],
    k: -9.28,
};

/// Lazarov's form over (gloss, n·v) with constants slope, offset, k ([`Lazarov::params`]).
pub static LAZAROV_FORM: LazyLock<Program> = LazyLock::new(|| {
    let t = |lanes| swz(bind(0), lanes);
    Program {
        lets: vec![
            ("t".into(), var(0) * constants(0, 4) + vector(vec![lit(0.0), lit(0.0), k(4), k(5)])),
            ("a0".into(), t("x") * min(t("y"), exp2(k(6) * var(1))) + t("z")),
        ],
        result: vector(vec![t("w") - bind(1), bind(1)]),
    }
});

impl Lazarov {
    /// [A, B] at gloss g and n·v.
    pub fn eval(&self, g: f64, n_dot_v: f64) -> [f64; 2] {
        LAZAROV_TAPE.pair([g, n_dot_v], &self.params())
    }

    pub fn params(&self) -> Vec<f64> {
        self.slope.iter().chain(&self.offset).copied().chain([self.k]).collect()
    }

    pub fn from_params(p: &[f64]) -> Lazarov {
        Lazarov { slope: from_fn(|i| p[i]), offset: [p[4], p[5]], k: p[6] }
    }
}

/// Black Ops II's gloss → Blinn-Phong exponent, m = 8192^g = 2^(13 g) (Lazarov 2013 slides).
pub fn blinn_phong_exponent(g: f64) -> f64 {
    (13.0 * g).exp2()
}

/// The Blinn-Phong ↔ microfacet correspondence m = 2/α² − 2 (Walter et al. 2007's
/// Phong–Beckmann relation, commonly reused for GGX): α = sqrt(2/(m + 2)). Used to measure
/// Lazarov's Blinn-Phong fit against the GGX integral: g ∈ [0, 1] is α ∈ [0.0156, 0.816].
pub fn alpha_of_gloss(g: f64) -> f64 {
    (2.0 / (blinn_phong_exponent(g) + 2.0)).sqrt()
}

/// MaterialX `mx_ggx_dir_albedo_analytic` (libraries/pbrlib/genglsl/lib/mx_microfacet_specular.glsl,
/// v1.39.5): "Rational quadratic fit to Monte Carlo data for GGX directional albedo", x = NdotV,
/// y = alpha (GGX α),
/// ```text
/// r = R[0] + R[1] x + R[2] y + R[3] x y + R[4] x² + R[5] y² + R[6] x² y + R[7] x y² + R[8] x² y²
/// AB = clamp(r.xy / r.zw, 0, 1)
/// ```
/// Rows are the vec4 constants in the source's order; `R[0]` = (0.1003, 0.9345, 1.0, 1.0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaterialX {
    pub r: [[f64; 4]; 9],
}

pub const MATERIALX: MaterialX = MaterialX {
    r: [
        [0.1003, 0.9345, 1.0, 1.0],
        [-0.6303, -2.323, -1.765, 0.2281],
        [9.748, 2.229, 8.263, 15.94],
        [-2.038, -3.748, 11.53, -55.83],
        [29.34, 1.424, 28.96, 13.08],
        [-8.245, -0.7684, -7.507, 41.26],
        [-26.44, 1.436, -36.11, 54.9],
        [19.99, 0.2913, 15.86, 300.2],
        [-5.448, 0.6286, 33.37, -285.1],
    ],
};

/// The monomials of MaterialX's form at (x, y) = (n·v, α), in the order of [`MaterialX::r`].
pub fn materialx_monomials(x: f64, y: f64) -> [f64; 9] {
    let (x2, y2) = (x * x, y * y);
    [1.0, x, y, x * y, x2, y2, x2 * y, x * y2, x2 * y2]
}

/// MaterialX's form over (n·v, α) with constants the rows of R ([`MaterialX::params`]):
/// the monomials of [`materialx_monomials`], each row's vector times its monomial, summed in
/// the source's order.
pub static MATERIALX_FORM: LazyLock<Program> = LazyLock::new(|| {
    let (x, y, x2, y2) = (|| bind(0), || bind(1), || bind(2), || bind(3));
    let row = |i: usize| constants(4 * i, 4);
    // vec4 · x · y as the source writes it: (row · x) · y.
    let r = row(0) + row(1) * x() + row(2) * y() + row(3) * x() * y() + row(4) * x2() + row(5) * y2() + row(6) * x2() * y() + row(7) * x() * y2() + row(8) * x2() * y2();
    Program {
        lets: vec![
            ("x".into(), var(0)),
            ("y".into(), var(1)),
            ("x2".into(), bind(0) * bind(0)),
            ("y2".into(), bind(1) * bind(1)),
            ("r".into(), r),
        ],
        result: clamp(swz(bind(4), "xy") / swz(bind(4), "zw"), splat(2, lit(0.0)), splat(2, lit(1.0))),
    }
});

impl MaterialX {
    /// [A, B] at n·v and α.
    pub fn eval(&self, n_dot_v: f64, alpha: f64) -> [f64; 2] {
        MATERIALX_TAPE.pair([n_dot_v, alpha], &self.params())
    }

    /// The rows of R, one after another.
    pub fn params(&self) -> Vec<f64> {
        self.r.iter().flatten().copied().collect()
    }

    pub fn from_params(p: &[f64]) -> MaterialX {
        MaterialX { r: from_fn(|i| from_fn(|c| p[4 * i + c])) }
    }
}

/// Kulla & Conty 2017, "Revisiting Physically Based Shading at Imageworks" (SIGGRAPH PBS course),
/// the fit of the dielectric Fresnel average F_avg(η) = 2∫₀¹ F(μ, η) μ dμ, as in Cycles
/// (`bsdf_util.h`, "a numerical fit from 'Revisiting …'"):
/// ```text
/// η ≥ 1:  (η − 1)/(4.08567 + 1.00071 η)
/// η < 1:  0.997118 + 0.1014 η − 0.965241 η² − 0.130607 η³
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KullaConty {
    /// η ≥ 1: (η − 1)/(above[0] + above[1] η).
    pub above: [f64; 2],
    /// η < 1: below[0] + below[1] η + below[2] η² + below[3] η³.
    pub below: [f64; 4],
}

pub const KULLA_CONTY: KullaConty = KullaConty { above: [4.08567, 1.00071], below: [0.997118, 0.1014, -0.965241, -0.130607] };

/// Kulla–Conty's two branches over η with constants above, below ([`KullaConty::params`]).
pub static KULLA_CONTY_FORM: LazyLock<Program> = LazyLock::new(|| {
    let e = || bind(0);
    Program {
        lets: vec![
            ("e".into(), var(0)),
            ("below".into(), k(2) + e() * (k(3) + e() * (k(4) + e() * k(5)))),
            ("above".into(), (e() - lit(1.0)) / (k(0) + k(1) * e())),
        ],
        result: less(e(), lit(1.0), bind(1), bind(2)),
    }
});

impl KullaConty {
    pub fn eval(&self, eta: f64) -> f64 {
        KULLA_CONTY_FORM.eval(&[eta], &self.params()).v[0]
    }

    /// above, then below.
    pub fn params(&self) -> Vec<f64> {
        self.above.iter().chain(&self.below).copied().collect()
    }

    pub fn from_params(p: &[f64]) -> KullaConty {
        KullaConty { above: [p[0], p[1]], below: [p[2], p[3], p[4], p[5]] }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The compiled pair forms are their programs bit for bit (what the refits' objectives and
    /// `validate` evaluate is the form as written).
    #[test]
    fn the_compiled_pair_forms_are_their_programs() {
        assert_eq!(crate::fit::expr::tape::same_bits(&KARIS_FORM, &KARIS.params()), 2);
        assert_eq!(crate::fit::expr::tape::same_bits(&LAZAROV_FORM, &LAZAROV.params()), 2);
        assert_eq!(crate::fit::expr::tape::same_bits(&MATERIALX_FORM, &MATERIALX.params()), 2);
    }
}
