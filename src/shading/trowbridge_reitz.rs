//! The Trowbridge–Reitz (GGX) lobe: its distribution D, Smith's Λ, the masking models, its
//! sampling measure and the narrow features the hemispherical operators must see.
//!
//! ```text
//! D(h)   = α² / (π ((n·h)²(α² − 1) + 1)²)
//! Λ(μ)   = (−1 + sqrt(1 + α² tan²θ)) / 2,          tan²θ = (1 − μ²)/μ²
//! G2     = 1 / (1 + Λ(μv) + Λ(μl))                 (height-correlated Smith)
//! G      = G1(μv) G1(μl),  G1(μ) = μ/(μ(1 − k) + k)  (separable Schlick–Smith; UE4: k = α/2)
//! f      = D G / (4 μv μl)
//! ```
//! Its measure is D μh dω_h, the GGX sampler: with tan²θh = α² ξ/(1 − ξ) it is dξ dφ/2π
//! exactly (Walter et al. 2007, Eq. 35 solved for ξ), and the weight is
//! w = G (v·h)/(μv μh), which has no peak at any α. Below θ* = atan(10α) (ξ = 100/101) the
//! outer variable is ξ, above it θh. Near μl = 0 the weight is a rational function of μl
//! with a pole at μl ≈ −μv(α/2)/(μv + μvΛ(μv)) (height-correlated; −k/(1 − k) separable):
//! the lobe's horizon pole. At α = 0 the lobe is the mirror.

use super::lobe::Lobe;
use std::f64::consts::PI;

/// The masking-shadowing term of the lobe.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shadowing {
    /// Height-correlated Smith G2 = 1/(1 + Λ(v) + Λ(l)).
    HeightCorrelated,
    /// Separable Schlick–Smith G1(v) G1(l), G1(μ) = μ/(μ(1 − k) + k) (UE4 IBL: k = α/2).
    Separable { k: f64 },
}

/// D(m) at cos θm = `c`.
#[inline]
pub fn d(alpha: f64, c: f64) -> f64 {
    let a2 = alpha * alpha;
    let t = 1.0 + (a2 - 1.0) * c * c;
    a2 / (PI * t * t)
}

/// μ Λ(μ) for the height-correlated G2: α² (1 − μ²) / (2 (sqrt(μ² + α²(1 − μ²)) + μ)),
/// finite at μ = 0 (= α/2) and free of cancellation near μ = 1.
pub fn mu_lambda(alpha2: f64, mu: f64) -> f64 {
    let s2 = (1.0 - mu) * (1.0 + mu);
    alpha2 * s2 / (2.0 * ((mu * mu + alpha2 * s2).sqrt() + mu))
}

/// Λ(μ) = μΛ(μ)/μ (μ > 0).
pub fn lambda(alpha: f64, mu: f64) -> f64 {
    mu_lambda(alpha * alpha, mu) / mu
}

/// The GGX lobe at roughness α (α = perceptual roughness²) with a masking model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ggx {
    alpha: f64,
    alpha2: f64,
    shadowing: Shadowing,
}

impl Ggx {
    pub fn new(alpha: f64, shadowing: Shadowing) -> Self {
        Ggx { alpha, alpha2: alpha * alpha, shadowing }
    }

    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    pub fn shadowing(&self) -> Shadowing {
        self.shadowing
    }
}

/// The view terms of the weight.
#[derive(Debug, Clone, Copy)]
pub struct GgxView {
    mu_v: f64,
    /// μv Λ(μv) (height-correlated) or the separable G1(v)/μv denominator μv(1 − k) + k.
    v_term: f64,
}

impl Lobe for Ggx {
    type View = GgxView;

    fn view(&self, mu_v: f64) -> GgxView {
        let v_term = match self.shadowing {
            Shadowing::HeightCorrelated => mu_lambda(self.alpha2, mu_v),
            Shadowing::Separable { k } => mu_v * (1.0 - k) + k,
        };
        GgxView { mu_v, v_term }
    }

    fn eval(&self, view: &GgxView, _vh: f64, ch: f64, mu_l: f64) -> f64 {
        let g = match self.shadowing {
            Shadowing::HeightCorrelated => view.mu_v / (view.mu_v + view.v_term + view.mu_v * mu_lambda(self.alpha2, mu_l) / mu_l),
            Shadowing::Separable { k } => view.mu_v * mu_l / (view.v_term * (mu_l * (1.0 - k) + k)),
        };
        d(self.alpha, ch) * g / (4.0 * view.mu_v * mu_l)
    }

    fn pdf(&self, ch: f64) -> f64 {
        d(self.alpha, ch) * ch
    }

    /// tan²θh = α² ξ/(1 − ξ).
    fn half_angle(&self, xi: f64) -> (f64, f64) {
        let one_minus = 1.0 - xi;
        let den = one_minus + self.alpha2 * xi;
        (self.alpha2 * xi / den, one_minus / den)
    }

    /// sin²θ/(sin²θ + α² cos²θ).
    fn xi_of(&self, theta: f64) -> f64 {
        if theta <= 0.0 {
            return 0.0;
        }
        let (s, c) = theta.sin_cos();
        let (s2, c2) = (s * s, c * c);
        (s2 / (s2 + self.alpha2 * c2)).min(1.0)
    }

    /// dξ/dθ = 2 sin θ cos θ α² / (sin²θ + α² cos²θ)².
    fn xi_measure(&self, dtheta: f64, sh: f64, ch: f64) -> f64 {
        let q = sh * sh + self.alpha2 * ch * ch;
        dtheta * 2.0 * sh * ch * self.alpha2 / (q * q)
    }

    fn switch_angle(&self) -> f64 {
        (10.0 * self.alpha).atan()
    }

    /// w = (G/μv)·vh/ch in a form finite at μv = 0, with one division: height-correlated,
    /// G/μv = 1/(μv + μvΛ(μv) + μv·μlΛ(μl)/μl) and μlΛ(μl) = α² s²/(2(S + μl)), s² = 1 − μl²,
    /// S = sqrt(μl² + α² s²), so w = vh·2μl(S + μl) / (ch·((μv + μvΛ(μv))·2μl(S + μl) + μv α² s²)).
    #[inline]
    fn weight(&self, view: &GgxView, vh: f64, ch: f64, mu_l: f64) -> f64 {
        match self.shadowing {
            Shadowing::HeightCorrelated => {
                let s2 = (1.0 - mu_l) * (1.0 + mu_l);
                let a2s2 = self.alpha2 * s2;
                let q = 2.0 * mu_l * ((mu_l * mu_l + a2s2).sqrt() + mu_l);
                vh * q / (ch * ((view.mu_v + view.v_term) * q + view.mu_v * a2s2))
            }
            Shadowing::Separable { k } => vh * mu_l / (ch * (mu_l * (1.0 - k) + k) * view.v_term),
        }
    }

    fn horizon_pole(&self, view: &GgxView) -> f64 {
        match self.shadowing {
            Shadowing::HeightCorrelated => view.mu_v * (0.5 * self.alpha2.sqrt()) / (view.mu_v + view.v_term),
            Shadowing::Separable { k } => k / (1.0 - k),
        }
    }

    fn is_mirror(&self) -> bool {
        self.alpha <= 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The GGX CDF variable: ξ of a half-vector angle θ is sin²θ/(sin²θ + α² cos²θ), and
    /// `half_angle` maps ξ back to (sin²θ, cos²θ) with tan²θ = α² ξ/(1 − ξ), the GGX NDF's
    /// cumulative distribution in cos²θ (Walter et al. 2007, Eq. 35 solved for ξ). Round trips
    /// θ → ξ → θ over (0, π/2) at four roughnesses, and the ends: ξ = 0 at θ ≤ 0, (0, 1) at ξ =
    /// 0, (1, 0) at ξ = 1. ξ holds 1 − ξ to half an ulp of 1, so near ξ = 1 (small α) cos²θ
    /// comes back to relative ε/(2(1 − ξ)), near ξ = 0 sin²θ likewise: 1e-14/min(ξ, 1 − ξ)
    /// bounds both with a few roundings.
    #[test]
    fn xi_and_half_angle_are_the_ggx_cdf_and_its_inverse() {
        for alpha in [0.02f64, 0.3, 1.0, 2.5] {
            let lobe = Ggx::new(alpha, Shadowing::HeightCorrelated);
            let a2 = alpha * alpha;
            for i in 1..100 {
                let theta = 0.5 * PI * i as f64 / 100.0;
                let (s2, c2) = (theta.sin().powi(2), theta.cos().powi(2));
                let xi = lobe.xi_of(theta);
                let want = 1.0 / (1.0 + a2 / theta.tan().powi(2));
                assert!((xi - want).abs() < 1e-14, "α {alpha}, θ {theta}: ξ {xi} vs {want}");
                let (hs, hc) = lobe.half_angle(xi);
                let tol = 1e-14 / xi.min(1.0 - xi);
                assert!((hs - s2).abs() < tol && (hc - c2).abs() < tol, "α {alpha}, θ {theta}: ({hs}, {hc}) vs ({s2}, {c2})");
                assert!((hs / hc - a2 * xi / (1.0 - xi)).abs() <= 1e-12 * (hs / hc), "α {alpha}, θ {theta}: tan²θ");
            }
            assert_eq!((lobe.xi_of(0.0), lobe.xi_of(-0.3)), (0.0, 0.0));
            assert_eq!(lobe.half_angle(0.0), (0.0, 1.0));
            assert_eq!(lobe.half_angle(1.0), (1.0, 0.0));
        }
    }

    /// The measure's density is the derivative of its CDF: dξ/dθ · dθ/dω_h = p(h)·2π (the
    /// measure is dξ dφ/2π), i.e. xi_measure(1, sin θ, cos θ) = 2π D(θ) cos θ sin θ, against a
    /// central difference of ξ(θ) (step 1e-6: truncation ~1e-12 relative, rounding ~1e-10).
    #[test]
    fn the_measure_is_d_cos_and_its_density_the_cdfs_derivative() {
        for alpha in [0.05f64, 0.4, 1.0] {
            let lobe = Ggx::new(alpha, Shadowing::HeightCorrelated);
            for i in 1..50 {
                let theta = 0.5 * PI * i as f64 / 50.0;
                let (sh, ch) = theta.sin_cos();
                let dens = lobe.xi_measure(1.0, sh, ch);
                let want = 2.0 * PI * lobe.pdf(ch) * sh;
                assert!((dens - want).abs() <= 1e-12 * want.max(1e-300), "α {alpha} θ {theta}: {dens} vs {want}");
                let h = 1e-6;
                let fd = (lobe.xi_of(theta + h) - lobe.xi_of(theta - h)) / (2.0 * h);
                assert!((fd - dens).abs() <= 1e-8 * dens.max(1.0), "α {alpha} θ {theta}: {fd} vs {dens}");
            }
        }
    }

    /// The weight in its cancelled form is the generic 4 f μl (v·h)/p(h) of the BRDF written out
    /// (`eval`), for both masking models, at views and lights spread over the hemisphere: the
    /// two are the same expression rearranged, ~10 roundings apart (1e-13 relative).
    #[test]
    fn the_weight_is_the_brdf_against_the_measure() {
        for shadowing in [Shadowing::HeightCorrelated, Shadowing::Separable { k: 0.2 }] {
            for alpha in [0.03f64, 0.5, 1.0] {
                let lobe = Ggx::new(alpha, shadowing);
                for mu_v in [0.05f64, 0.5, 0.99] {
                    let view = lobe.view(mu_v);
                    let sin_v = (1.0 - mu_v * mu_v).sqrt();
                    for (th, phi) in [(0.1f64, 0.3f64), (0.5, 1.0), (0.7, 2.5), (0.3, 3.0)] {
                        let (sh, ch) = th.sin_cos();
                        let vh = sin_v * sh * phi.cos() + mu_v * ch;
                        let mu_l = 2.0 * vh * ch - mu_v;
                        if !(mu_l > 0.0 && vh > 0.0) {
                            continue;
                        }
                        let w = lobe.weight(&view, vh, ch, mu_l);
                        let want = 4.0 * lobe.eval(&view, vh, ch, mu_l) * mu_l * vh / lobe.pdf(ch);
                        assert!((w - want).abs() <= 1e-13 * want, "{shadowing:?} α {alpha} μv {mu_v}: {w} vs {want}");
                    }
                }
            }
        }
    }
}
