//! The GGX split-sum integrals: the environment BRDF ("DFG") scale and bias, the directional
//! albedo E(μ) and its cosine-weighted average E_avg, and the hemispherical Fresnel averages.
//!
//! # Conventions (the contract)
//!
//! Normal n = +z; the view v = (sin θv, 0, μv) lies in the xz-plane, μv = n·v ∈ [0, 1]; a light
//! direction l has μl = n·l. GGX (Trowbridge–Reitz) with α = perceptual roughness²:
//! ```text
//! D(h)   = α² / (π ((n·h)²(α² − 1) + 1)²)
//! Λ(μ)   = (−1 + sqrt(1 + α² tan²θ)) / 2,          tan²θ = (1 − μ²)/μ²
//! G2     = 1 / (1 + Λ(μv) + Λ(μl))                 (height-correlated Smith)
//! Fc     = (1 − v·h)⁵                              (Schlick's Fresnel weight)
//! f      = D G2 / (4 μv μl)
//! scale  = ∫_{μl ≥ c} (1 − Fc) f μl dω_l,    bias = ∫_{μl ≥ c} Fc f μl dω_l,    c = cos_cone
//! E(μv)  = scale + bias  (F = 1),            E_avg = 2 ∫₀¹ E(μ) μ dμ
//! ```
//! so that the split-sum specular of a Schlick F0 is F0·scale + bias (F90 = 1). c = 0 is the
//! hemisphere; c > 0 keeps the light directions in the visibility cone of half-angle acos c
//! about n (COD: WWII specular occlusion). A second shadowing model, [`Shadowing::Separable`],
//! is UE4's image-based-lighting G (Schlick–Smith G1(μ) = μ/(μ(1 − k) + k) for v and l,
//! multiplied, with k = α/2): the integral Karis's mobile fit was made against.
//!
//! # Integrating where the mass is
//!
//! The half vector h carries the peak. With l = 2(v·h)h − v, dω_l = 4 (v·h) dω_h, and
//! ```text
//! f μl dω_l = [D(h) μh dω_h] · G2 (v·h) / (μv μh).
//! ```
//! D μh dω_h is the GGX sampling measure; with ξ ∈ [0, 1] and tan²θh = α² ξ/(1 − ξ) it is
//! dξ dφ/2π exactly (the CDF of the visible-normal-free GGX sampler). In (ξ, φ) the integrand
//! G2 (v·h)/(μv μh) has no peak at any α: the spike at α = 10⁻³ unfolds into a smooth function
//! over the unit square. The integrand is even in φ; φ ∈ [0, π] counts twice (dξ dφ/π).
//!
//! The region μl ≥ c is exact in φ: with s = sin θv, v·h = s sin θh cos φ + μv μh and
//! μl = 2 μh (v·h) − μv, so μl ≥ c ⇔ cos φ ≥ κ(θh) = (c + μv − 2 μv μh²)/(2 μh s sin θh), and
//! φ runs over [0, acos κ] (all of [0, π] for κ ≤ −1, nothing for κ ≥ 1). In the plane of v
//! (φ = 0 and φ = π) the reflection is l at polar angle 2θh − θv and 2θh + θv: with θc = acos c
//! the valid θh are (θv − θc)/2 ≤ θh ≤ (θv + θc)/2 and φ is unrestricted for θh ≤ (θc − θv)/2.
//! Those θh are the breakpoints of the outer integral (where acos κ has square-root ends); on each
//! piece [a, b] of ξ the substitution ξ = a + (b − a)(3t² − 2t³) makes the square roots smooth.
//! The outer ξ integral (of the vector [scale, bias]) is adaptive G10/K21 with QUADPACK error
//! estimates to half the tolerance; the inner φ integral at each outer node goes to the other
//! half, so the error estimate of each of scale and bias is ≤ the tolerance (the inner errors
//! integrate with total weight ≤ 1, the ξ-measure). The inner integrand is a smooth function
//! of cos φ inside the region, so the inner rule is nested and doubles its nodes until two
//! levels agree ([`Inner::Nested`]): the periodic trapezoid rule when φ covers all of [0, π],
//! Clenshaw–Curtis on the even extension over [−φmax, φmax] when the cone or the horizon cuts
//! it; both converge geometrically there, and most inner integrals need 9 to 17 nodes where
//! one G10/K21 panel takes 21. Inner integrals that have not converged at 129 nodes (features
//! narrower than the node spacing: the G2 pole next to the horizon at small α or grazing n·v)
//! fall back to adaptive G10/K21 on geometric panels ([`Inner::Adaptive`], which is also
//! available throughout as an independent reference).
//!
//! # Limits
//! - μv → 0: G2/μv stays finite (μv Λ(μv) → α/2), so the integrand is evaluated in the product
//!   form 1/(μv + μvΛ(μv) + μvΛ(μl)) and n·v = 0 gives the limit, not 0/0.
//! - α → 0: D → δ(h − n), l → mirror(v): E → 1 and bias → (1 − μv)⁵ (for μv ≥ c); α = 0 gives
//!   this limit exactly.
//! - c → 1: the cone closes: scale = bias = 0 (c = 1 exactly: empty region, exact 0).
//! - E(μ = 1, α = 1) = 1 − ln 2 (height-correlated G2), derived in [`albedo_normal_rough`].

use crate::integrate::{integrate, Control, Estimate, Options, PanelError, Rule, Tolerance};
use std::cell::Cell;
use std::f64::consts::PI;

/// Default absolute tolerance of the integrators (a non-positive or NaN tolerance means this).
pub const DEFAULT_TOL: f64 = 1e-10;
/// Panels per adaptive level before the estimate is returned as is (with its error).
const MAX_PANELS: usize = 400;

/// The masking-shadowing term inside the integral.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shadowing {
    /// Height-correlated Smith G2 = 1/(1 + Λ(v) + Λ(l)) (the contract above).
    HeightCorrelated,
    /// Separable Schlick–Smith G1(v) G1(l), G1(μ) = μ/(μ(1 − k) + k) (UE4 IBL: k = α/2).
    Separable { k: f64 },
}

/// scale and bias with their error estimates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnvEstimate {
    pub scale: f64,
    pub bias: f64,
    /// Upper estimate of max(|scale − exact|, |bias − exact|).
    pub error: f64,
    pub evals: u64,
}

impl EnvEstimate {
    /// E = scale + bias, with the error of the sum.
    pub fn albedo(&self) -> Estimate {
        Estimate { value: self.scale + self.bias, error: 2.0 * self.error, evals: self.evals }
    }
}

fn tolerance(tol: f64) -> f64 {
    if tol > 0.0 { tol } else { DEFAULT_TOL }
}

/// μ Λ(μ) for the height-correlated G2: α² (1 − μ²) / (2 (sqrt(μ² + α²(1 − μ²)) + μ)),
/// finite at μ = 0 (= α/2) and free of cancellation near μ = 1.
fn mu_lambda(alpha2: f64, mu: f64) -> f64 {
    let s2 = (1.0 - mu) * (1.0 + mu);
    alpha2 * s2 / (2.0 * ((mu * mu + alpha2 * s2).sqrt() + mu))
}

/// Λ(μ) = μΛ(μ)/μ (μ > 0).
pub fn lambda(alpha: f64, mu: f64) -> f64 {
    mu_lambda(alpha * alpha, mu) / mu
}

/// sin²θ and cos²θ of the half vector at ξ: tan²θh = α² ξ/(1 − ξ).
fn half_angle(alpha2: f64, xi: f64) -> (f64, f64) {
    let one_minus = 1.0 - xi;
    let den = one_minus + alpha2 * xi;
    (alpha2 * xi / den, one_minus / den)
}

/// ξ of the half-vector polar angle θ: sin²θ/(sin²θ + α² cos²θ).
fn xi_of(alpha2: f64, theta: f64) -> f64 {
    if theta <= 0.0 {
        return 0.0;
    }
    let (s, c) = theta.sin_cos();
    let (s2, c2) = (s * s, c * c);
    (s2 / (s2 + alpha2 * c2)).min(1.0)
}

/// One point of the problem: everything the φ integrand needs at a fixed view.
struct View {
    alpha2: f64,
    mu_v: f64,
    sin_v: f64,
    /// μv Λ(μv) (height-correlated) or the separable G1(v)/μv denominator μv(1 − k) + k.
    v_term: f64,
    cos_cone: f64,
    shadowing: Shadowing,
}

impl View {
    fn new(alpha: f64, mu_v: f64, cos_cone: f64, shadowing: Shadowing) -> Self {
        let alpha2 = alpha * alpha;
        let v_term = match shadowing {
            Shadowing::HeightCorrelated => mu_lambda(alpha2, mu_v),
            Shadowing::Separable { k } => mu_v * (1.0 - k) + k,
        };
        View { alpha2, mu_v, sin_v: ((1.0 - mu_v) * (1.0 + mu_v)).sqrt(), v_term, cos_cone, shadowing }
    }

    /// [(1 − Fc) w, Fc w] with w = G (v·h)/(μv μh), at a half vector of polar sin/cos (sh, ch)
    /// and azimuth cosine cos φ; 0 outside μl ≥ c.
    #[inline]
    fn integrand(&self, sh: f64, ch: f64, cos_phi: f64) -> [f64; 2] {
        let vh = self.sin_v * sh * cos_phi + self.mu_v * ch;
        let mu_l = 2.0 * vh * ch - self.mu_v;
        if !(mu_l > 0.0 && mu_l >= self.cos_cone && vh > 0.0) {
            return [0.0, 0.0];
        }
        self.weights(vh, ch, mu_l)
    }

    /// [`View::integrand`] at a point known to lie in the region μl ≥ c (a node of the nested
    /// rules): μl is clamped to ≥ c, and to the limit 0 of the integrand at μl = 0.
    #[inline]
    fn integrand_inside(&self, sh: f64, ch: f64, cos_phi: f64) -> [f64; 2] {
        let vh = self.sin_v * sh * cos_phi + self.mu_v * ch;
        let mu_l = (2.0 * vh * ch - self.mu_v).max(self.cos_cone);
        if !(mu_l > 0.0 && vh > 0.0) {
            // μl = 0: G2 (and the separable G1(l)) vanish there.
            return [0.0, 0.0];
        }
        self.weights(vh, ch, mu_l)
    }

    #[inline]
    fn weights(&self, vh: f64, ch: f64, mu_l: f64) -> [f64; 2] {
        // w = (G/μv)·vh/ch in a form finite at μv = 0, with one division: height-correlated,
        // G/μv = 1/(μv + μvΛ(μv) + μv·μlΛ(μl)/μl) and μlΛ(μl) = α² s²/(2(S + μl)), s² = 1 − μl²,
        // S = sqrt(μl² + α² s²), so w = vh·2μl(S + μl) / (ch·((μv + μvΛ(μv))·2μl(S + μl) + μv α² s²)).
        let w = match self.shadowing {
            Shadowing::HeightCorrelated => {
                let s2 = (1.0 - mu_l) * (1.0 + mu_l);
                let a2s2 = self.alpha2 * s2;
                let q = 2.0 * mu_l * ((mu_l * mu_l + a2s2).sqrt() + mu_l);
                vh * q / (ch * ((self.mu_v + self.v_term) * q + self.mu_v * a2s2))
            }
            Shadowing::Separable { k } => vh * mu_l / (ch * (mu_l * (1.0 - k) + k) * self.v_term),
        };
        let m = 1.0 - vh;
        let m2 = m * m;
        let fc = m2 * m2 * m;
        [w - fc * w, fc * w]
    }

    /// The initial φ panels of [0, φmax]: geometric towards φmax when the horizon cuts the
    /// range. Near μl = 0 the integrand is a rational function of μl with a pole at
    /// μl ≈ −μv(α/2)/(μv + μvΛ(μv)) (height-correlated; −k/(1 − k) separable): at grazing n·v
    /// or small α a feature far narrower than one G10/K21 panel, which the error estimate
    /// cannot see. Breakpoints at μl − c = (μl_max − c)·16^{−j}, down to 16× the pole's distance
    /// from the boundary, put panels on every scale of it.
    fn phi_panels(&self, sh: f64, ch: f64, kappa: f64, phi_max: f64) -> Vec<(f64, f64)> {
        if phi_max >= PI {
            return vec![(0.0, PI)];
        }
        let slope = 2.0 * ch * self.sin_v * sh; // dμl / d(cos φ)
        let pole = match self.shadowing {
            Shadowing::HeightCorrelated => self.mu_v * (0.5 * self.alpha2.sqrt()) / (self.mu_v + self.v_term),
            Shadowing::Separable { k } => k / (1.0 - k),
        };
        let q_max = 1.0 - kappa;
        let q_pole = (self.cos_cone + pole) / slope;
        let mut out = Vec::new();
        let mut lo = 0.0;
        let mut q = q_max;
        for _ in 0..24 {
            if q <= 16.0 * q_pole {
                break;
            }
            q *= 0.0625;
            let phi = (kappa + q).min(1.0).acos();
            if phi > lo && phi < phi_max {
                out.push((lo, phi));
                lo = phi;
            }
        }
        out.push((lo, phi_max));
        out
    }

    /// κ(θh): the cosine of φ above which μl ≥ c (±∞ when s sin θh = 0).
    fn kappa(&self, sh: f64, ch: f64) -> f64 {
        let num = self.cos_cone + self.mu_v - 2.0 * self.mu_v * ch * ch;
        let den = 2.0 * ch * self.sin_v * sh;
        if den > 0.0 {
            num / den
        } else if num <= 0.0 {
            f64::NEG_INFINITY
        } else {
            f64::INFINITY
        }
    }
}

/// K21 with QUADPACK estimates on the sum of the first two components (scale and bias) to
/// max(abs, rel·|scale + bias|); a third component, if any, is integrated along unchecked.
fn options<const N: usize>(abs: f64, rel: f64) -> Options<'static, N> {
    let weights = std::array::from_fn(|i| if i < 2 { 1.0 } else { 0.0 });
    Options {
        rule: Rule::Kronrod21,
        estimate: PanelError::Quadpack,
        control: Control::Weighted { weights, abs, rel },
        max_panels: MAX_PANELS,
        stop_when_exhausted: true,
        stop_when_non_finite: true,
        sum_from_negative_zero: false,
    }
}

/// The split-sum scale and bias (see the module doc) to absolute tolerance `tol` on each.
/// Parameters are taken as given (the caller checks domains): α ∈ (0, 1], μv, c ∈ [0, 1].
pub fn env(alpha: f64, mu_v: f64, cos_cone: f64, shadowing: Shadowing, tol: f64) -> EnvEstimate {
    env_with(alpha, mu_v, cos_cone, shadowing, tol, Inner::Nested)
}

/// The inner (azimuth) rule of [`env_with`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Inner {
    /// Nested trapezoid (full range) or Clenshaw–Curtis (cut range) with doubling, falling
    /// back to `Adaptive` when it has not converged at 129 nodes (the default).
    Nested,
    /// Adaptive G10/K21 with QUADPACK estimates on geometric panels only (an independent
    /// reference for the nested rules).
    Adaptive,
}

/// [`env`] with a choice of the inner rule.
pub fn env_with(alpha: f64, mu_v: f64, cos_cone: f64, shadowing: Shadowing, tol: f64, inner: Inner) -> EnvEstimate {
    let tol = tolerance(tol);
    if cos_cone >= 1.0 {
        return EnvEstimate { scale: 0.0, bias: 0.0, error: 0.0, evals: 0 };
    }
    if alpha <= 0.0 {
        // The mirror limit: D = δ(h − n), G = 1 (either model), l = mirror(v) with μl = μv.
        if mu_v < cos_cone {
            return EnvEstimate { scale: 0.0, bias: 0.0, error: 0.0, evals: 0 };
        }
        let b = (1.0 - mu_v).powi(5);
        return EnvEstimate { scale: 1.0 - b, bias: b, error: 0.0, evals: 0 };
    }
    let view = View::new(alpha, mu_v, cos_cone, shadowing);
    let theta_v = mu_v.acos();
    let theta_c = cos_cone.acos();
    let lo = (0.5 * (theta_v - theta_c)).max(0.0);
    let hi = 0.5 * (theta_v + theta_c);
    let full = 0.5 * (theta_c - theta_v);
    let a2 = view.alpha2;
    let mut pieces: Vec<(f64, f64)> = Vec::with_capacity(2);
    if full > lo {
        pieces.push((lo, full));
        pieces.push((full, hi));
    } else {
        pieces.push((lo, hi));
    }
    let segments = segments(&pieces, alpha);
    if segments.is_empty() {
        return EnvEstimate { scale: 0.0, bias: 0.0, error: 0.0, evals: 0 };
    }
    let inner_evals = Cell::new(0u64);
    // The inner error target at an outer point of weight w (ξ-measure per unit s, over π) is
    // max(tol/(4 n w), (tol/4)·|inner value|) for n segments of unit length in s: integrated
    // with weight w it contributes ≤ tol/4 + (tol/4)·(scale + bias) ≤ tol/2. Points of small
    // weight (short segments, smoothstep ends) get looser targets. The relative part matters
    // at grazing n·v, where the φ integrand reaches ~1/(α n·v) over a small ξ range and an
    // absolute target alone sits below its rounding floor.
    let inner_tol = 0.25 * tol;
    let n = segments.len();
    let outer = |s: f64| -> [f64; 3] {
        let k = (s.floor() as usize).min(n - 1);
        let seg = &segments[k];
        let t = s - k as f64;
        let (u, du) = if seg.smooth { (t * t * (3.0 - 2.0 * t), 6.0 * t * (1.0 - t)) } else { (t, 1.0) };
        let x = seg.a + (seg.b - seg.a) * u;
        let jac = (seg.b - seg.a) * du;
        if jac == 0.0 {
            return [0.0; 3];
        }
        // (sin θh, cos θh) and the ξ-measure per unit s.
        let (sh, ch, weight) = if seg.in_xi {
            let (s2, c2) = half_angle(a2, x);
            (s2.sqrt(), c2.sqrt(), jac)
        } else {
            let (sh, ch) = x.sin_cos();
            let q = sh * sh + a2 * ch * ch;
            (sh, ch, jac * 2.0 * sh * ch * a2 / (q * q))
        };
        let kappa = view.kappa(sh, ch);
        let phi_max = if kappa <= -1.0 {
            PI
        } else if kappa >= 1.0 {
            return [0.0; 3];
        } else {
            kappa.acos()
        };
        let w = weight / PI;
        let abs = inner_tol / (n as f64 * w);
        let nested = match inner {
            Inner::Nested => nested_phi(&view, sh, ch, phi_max, abs, inner_tol),
            Inner::Adaptive => None,
        };
        let r = nested.unwrap_or_else(|| {
            let panels = view.phi_panels(sh, ch, kappa, phi_max);
            let r = integrate(&panels, &options::<2>(abs, inner_tol), |phi| view.integrand(sh, ch, phi.cos()));
            NestedResult { value: r.value, error: r.error, evals: r.evals }
        });
        inner_evals.set(inner_evals.get() + r.evals);
        [r.value[0] * w, r.value[1] * w, r.error * w]
    };
    let initial: Vec<(f64, f64)> = (0..n).map(|k| (k as f64, (k + 1) as f64)).collect();
    let r = integrate(&initial, &options::<3>(0.5 * tol, 0.0), outer);
    // The outer error of the sum bounds each component's; the third component is the inner
    // errors integrated over the segments.
    EnvEstimate { scale: r.value[0], bias: r.value[1], error: r.error + r.value[2], evals: r.evals + inner_evals.get() }
}

/// An inner integral: [scale, bias] per unit of the outer measure, the error estimate of their
/// sum, and the integrand evaluations.
struct NestedResult {
    value: [f64; 2],
    error: f64,
    evals: u64,
}

/// Levels of the nested azimuth rules: N = 4, 8, …, `NESTED_MAX` intervals.
const NESTED_MAX: usize = 128;

/// Node cosines and the weights of each level of the nested rules (computed once).
struct NestedRules {
    /// cos(jπ/NESTED_MAX), j = 0..=NESTED_MAX.
    cos: Vec<f64>,
    /// Clenshaw–Curtis weights on [0, 1] for an even integrand, per level N = 4·2^l: the node
    /// x_k = cos(kπ/N), k = 0..=N/2, weight w_k (k < N/2) and w_{N/2}/2 of the rule on [−1, 1].
    cc: Vec<Vec<f64>>,
}

fn nested_rules() -> &'static NestedRules {
    static RULES: std::sync::OnceLock<NestedRules> = std::sync::OnceLock::new();
    RULES.get_or_init(|| {
        let cos = (0..=NESTED_MAX).map(|j| (PI * j as f64 / NESTED_MAX as f64).cos()).collect();
        let mut cc = Vec::new();
        let mut n = 4;
        while n <= NESTED_MAX {
            // Clenshaw–Curtis on [−1, 1] (Waldvogel 2006, eq. 2.2 written out):
            // w_k = (c_k/N)(1 − Σ_{j=1}^{N/2} b_j cos(2jkπ/N)/(4j² − 1)), c = 1 at the ends
            // (else 2), b_{N/2} = 1 (else 2).
            let w: Vec<f64> = (0..=n / 2)
                .map(|k| {
                    let c = if k == 0 { 1.0 } else { 2.0 };
                    let mut sum = 0.0;
                    for j in 1..=n / 2 {
                        let b = if j == n / 2 { 1.0 } else { 2.0 };
                        sum += b * (2.0 * PI * (j * k) as f64 / n as f64).cos() / (4.0 * (j * j) as f64 - 1.0);
                    }
                    let wk = c / n as f64 * (1.0 - sum);
                    if k == n / 2 { 0.5 * wk } else { wk }
                })
                .collect();
            cc.push(w);
            n *= 2;
        }
        NestedRules { cos, cc }
    })
}

/// The azimuth integral ∫₀^φmax [scale, bias] integrand dφ by nested rules that double their
/// node count from N = 4 until two successive levels differ by at most max(abs, rel·|value|)
/// (sum of the two components); `None` when N = `NESTED_MAX` has not converged.
///
/// The integrand is a smooth function of cos φ inside the region (an even function of φ):
/// - φmax = π: on [0, π] it is an even 2π-periodic function, for which the trapezoid rule
///   T_N = (π/N)(g₀/2 + g₁ + … + g_{N−1} + g_N/2) converges geometrically (it integrates cos kφ
///   exactly for k < 2N);
/// - φmax < π: its even extension is smooth on [−φmax, φmax] (the cut at μl = c is an end, not
///   an interior kink), for which Clenshaw–Curtis converges geometrically; by symmetry only
///   the nodes φmax·cos(kπ/N), k ≤ N/2, are evaluated.
///
/// For geometric convergence the error of Q_N is far below |Q_N − Q_{N/2}| (roughly its square
/// in relative terms), so that difference is the (conservative) estimate returned. The
/// integrand is evaluated inside the region by construction: μl is clamped to ≥ c so that a
/// node on the cut that rounds outside it is not counted as 0.
fn nested_phi(view: &View, sh: f64, ch: f64, phi_max: f64, abs: f64, rel: f64) -> Option<NestedResult> {
    let rules = nested_rules();
    let full = phi_max >= PI;
    // Values at node index j (NESTED_MAX grid for the trapezoid, its first half for CC).
    let mut g = [[0.0f64; 2]; NESTED_MAX + 1];
    let mut evals = 0u64;
    let mut at = |j: usize, g: &mut [[f64; 2]; NESTED_MAX + 1]| {
        let cos_phi = if full { rules.cos[j] } else { (phi_max * rules.cos[j]).cos() };
        g[j] = view.integrand_inside(sh, ch, cos_phi);
        evals += 1;
    };
    let mut previous: Option<[f64; 2]> = None;
    let mut n = 4;
    let mut level = 0;
    while n <= NESTED_MAX {
        let stride = NESTED_MAX / n;
        let count = if full { n } else { n / 2 };
        // New nodes: all at the first level, the odd multiples of the stride after it.
        for k in 0..=count {
            if previous.is_none() || k % 2 == 1 {
                at(k * stride, &mut g);
            }
        }
        let mut q = [0.0; 2];
        if full {
            let h = PI / n as f64;
            for k in 0..=n {
                let w = if k == 0 || k == n { 0.5 * h } else { h };
                q[0] += w * g[k * stride][0];
                q[1] += w * g[k * stride][1];
            }
        } else {
            for (k, w) in rules.cc[level].iter().enumerate() {
                q[0] += phi_max * w * g[k * stride][0];
                q[1] += phi_max * w * g[k * stride][1];
            }
        }
        if let Some(p) = previous {
            let error = (q[0] - p[0]).abs() + (q[1] - p[1]).abs();
            if error <= abs.max(rel * (q[0] + q[1]).abs()) {
                return Some(NestedResult { value: q, error, evals });
            }
        }
        previous = Some(q);
        n *= 2;
        level += 1;
    }
    None
}

/// One initial panel of the outer integral: half-vector angles θh ∈ [a, b] (stored as ξ when
/// `in_xi`, else as θh). A segment with a kink at an end (a square root in the azimuth limit)
/// goes through the smoothstep u = 3t² − 2t³, which approaches both ends quadratically and so
/// makes the square root smooth.
#[derive(Debug, Clone, Copy)]
struct Segment {
    a: f64,
    b: f64,
    in_xi: bool,
    smooth: bool,
}

/// The outer panels of the pieces [θa, θb] between kinks.
///
/// - Variable: ξ below θ* = atan(10α), where D has its mass (ξ(θ*) = 100/101), θh above it:
///   there ξ crowds against 1 (1 − ξ ≈ α² cot²θh) and a kink near θh = π/2 would sit
///   within a few ulps of ξ = 1.
/// - Geometric breakpoints at each kink θk, at distances d·4^j with d = min(θk, π/2 − θk),
///   out to half the piece. Past a kink the azimuth limit varies on the scale of that distance:
///   at c = 0, cos φmax = −cot θv cot 2θh ≈ −(π/2 − θv)/(2θh) for grazing v, a function of
///   θh/θk near θk = (π/2 − θv)/2, and mirrored near θh = π/2. Uniform panels would not see it.
fn segments(pieces: &[(f64, f64)], alpha: f64) -> Vec<Segment> {
    let theta_star = (10.0 * alpha).atan();
    let a2 = alpha * alpha;
    let mut out = Vec::new();
    for &(p, q) in pieces {
        if q.partial_cmp(&p) != Some(std::cmp::Ordering::Greater) {
            continue;
        }
        let mut cuts = vec![p, q];
        for (kink, dir) in [(p, 1.0), (q, -1.0)] {
            let d0 = kink.min(0.5 * PI - kink);
            if d0 > 0.0 {
                let mut d = 4.0 * d0;
                while d < 0.5 * (q - p) {
                    cuts.push(kink + dir * d);
                    d *= 4.0;
                }
            }
        }
        if theta_star > p && theta_star < q {
            cuts.push(theta_star);
        }
        cuts.sort_by(f64::total_cmp);
        cuts.dedup();
        for w in cuts.windows(2) {
            let (a, b) = (w[0], w[1]);
            let in_xi = b <= theta_star;
            let (sa, sb) = if in_xi { (xi_of(a2, a), xi_of(a2, b)) } else { (a, b) };
            if sb > sa {
                out.push(Segment { a: sa, b: sb, in_xi, smooth: a == p || b == q });
            }
        }
    }
    out
}

/// E(μv) = scale + bias with F = 1 (height-correlated), to absolute tolerance `tol`.
pub fn albedo(alpha: f64, mu_v: f64, tol: f64) -> Estimate {
    let tol = tolerance(tol);
    env(alpha, mu_v, 0.0, Shadowing::HeightCorrelated, 0.5 * tol).albedo()
}

/// E_avg(α) = 2 ∫₀¹ E(μ) μ dμ to absolute tolerance `tol`: the outer μ integral (through the
/// same smoothstep map, which tames the μ → 1 end where θv = acos μ has a square root) to half,
/// each E to the other half.
pub fn albedo_avg(alpha: f64, tol: f64) -> Estimate {
    let tol = tolerance(tol);
    let inner = Cell::new((0u64, 0.0f64));
    let r = crate::integrate::adaptive(
        0.0,
        1.0,
        Tolerance { abs: 0.5 * tol, rel: 0.0, max_panels: MAX_PANELS },
        |t| {
            let mu = t * t * (3.0 - 2.0 * t);
            let jac = 6.0 * t * (1.0 - t);
            if jac == 0.0 {
                return 0.0;
            }
            let e = albedo(alpha, mu, 0.5 * tol);
            let (n, worst) = inner.get();
            inner.set((n + e.evals, worst.max(e.error)));
            2.0 * e.value * mu * jac
        },
    );
    let (n, worst) = inner.get();
    Estimate { value: r.value, error: r.error + worst, evals: r.evals + n }
}

/// E(1) at α = 1 in closed form: 1 − ln 2.
///
/// At α = 1, D = 1/π (uniform in n·h over the hemisphere) and Λ(μ) = (−1 + 1/μ)/2, so for
/// μv = 1 (Λ(v) = 0) G2 = 1/(1 + Λ(l)) = 2μl/(1 + μl) and
/// E = ∫ D G2/(4 μl) μl dω_l = (1/4π) ∫ 2μl/(1 + μl) dω_l = ∫₀¹ μ/(1 + μ) dμ = 1 − ln 2.
pub fn albedo_normal_rough() -> f64 {
    1.0 - std::f64::consts::LN_2
}

/// Hemispherical (cosine-weighted) average of Schlick's Fresnel, closed form:
/// 2∫₀¹ (F0 + (1 − F0)(1 − μ)⁵) μ dμ = F0 + (1 − F0)·2·B(2, 6) = F0 + (1 − F0)/21.
pub fn f_avg_schlick(f0: f64) -> f64 {
    f0 + (1.0 - f0) / 21.0
}

/// Unpolarised Fresnel reflectance of a dielectric interface of relative index η at incidence
/// cosine c (1 under total internal reflection).
pub fn fresnel_dielectric(c: f64, eta: f64) -> f64 {
    let g2 = eta * eta - 1.0 + c * c;
    if g2 <= 0.0 {
        return 1.0;
    }
    let g = g2.sqrt();
    let a = (g - c) / (g + c);
    let b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
    0.5 * a * a * (1.0 + b * b)
}

/// F_avg(η) = 2∫₀¹ F(μ, η) μ dμ (numerical: no closed form is used; the integrand has a
/// square-root kink at the critical angle μ = sqrt(1 − η²) when η < 1, a breakpoint here, and
/// each piece goes through the smoothstep map).
pub fn f_avg_dielectric(eta: f64, tol: f64) -> Estimate {
    let tol = tolerance(tol);
    let mut cuts = vec![0.0];
    if eta < 1.0 {
        cuts.push(((1.0 - eta) * (1.0 + eta)).sqrt());
    }
    cuts.push(1.0);
    let mut out = Estimate { value: 0.0, error: 0.0, evals: 0 };
    for w in cuts.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b <= a {
            continue;
        }
        let r = crate::integrate::adaptive(0.0, 1.0, Tolerance { abs: 0.5 * tol, rel: 0.0, max_panels: MAX_PANELS }, |t| {
            let mu = a + (b - a) * t * t * (3.0 - 2.0 * t);
            2.0 * fresnel_dielectric(mu, eta) * mu * 6.0 * (b - a) * t * (1.0 - t)
        });
        out.value += r.value;
        out.error += r.error;
        out.evals += r.evals;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const HC: Shadowing = Shadowing::HeightCorrelated;

    /// E_avg's evaluation count is its outer rule's and every inner E's: at least one 21-point
    /// Kronrod panel outside, and at each of its nodes (all inside (0, 1), where the smoothstep's
    /// Jacobian is not 0) an E of at least one 21-point panel of its own: 21 + 21·21.
    #[test]
    fn albedo_avgs_evaluations_count_its_inner_integrals() {
        let e = albedo(0.5, 0.5, 1e-4);
        assert!(e.evals >= 21, "{e:?}");
        let avg = albedo_avg(0.5, 1e-4);
        assert!(avg.evals >= 21 + 21 * 21, "{avg:?}");
    }

    /// E_avg's error and count add its inner E's to the outer rule's. At α = 0 every E is the
    /// mirror limit, exact (error 0) with no evaluation, and the outer integrand 2·E·μ·dμ/dt is
    /// a degree-5 polynomial in t (E = 1 to rounding), which the first G10/K21 panel on [0, 1]
    /// integrates to rounding: 21 evaluations and E_avg = 2∫₀¹ μ dμ = 1. At α = ½ the first
    /// panel's centre t = ½ is a node, at μ = ½·½·(3 − 1) = ½, so the reported error is at least
    /// that inner E's own (the outer error is not negative).
    #[test]
    fn albedo_avgs_error_and_count_add_the_inner_integrals() {
        let exact = albedo_avg(0.0, 1e-6);
        // The 21-term Kronrod sum of values ≤ 3 rounds to a few ε.
        assert!(exact.evals == 21 && (exact.value - 1.0).abs() < 1e-14, "{exact:?}");
        let (avg, mid) = (albedo_avg(0.5, 1e-4), albedo(0.5, 0.5, 0.5e-4));
        assert!(mid.error > 0.0 && avg.error >= mid.error, "E_avg {avg:?}, E(½) {mid:?}");
    }

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
            let a2 = alpha * alpha;
            for i in 1..100 {
                let theta = 0.5 * PI * i as f64 / 100.0;
                let (s2, c2) = (theta.sin().powi(2), theta.cos().powi(2));
                let xi = xi_of(a2, theta);
                let want = 1.0 / (1.0 + a2 / theta.tan().powi(2));
                assert!((xi - want).abs() < 1e-14, "α {alpha}, θ {theta}: ξ {xi} vs {want}");
                let (hs, hc) = half_angle(a2, xi);
                let tol = 1e-14 / xi.min(1.0 - xi);
                assert!((hs - s2).abs() < tol && (hc - c2).abs() < tol, "α {alpha}, θ {theta}: ({hs}, {hc}) vs ({s2}, {c2})");
                assert!((hs / hc - a2 * xi / (1.0 - xi)).abs() <= 1e-12 * (hs / hc), "α {alpha}, θ {theta}: tan²θ");
            }
            assert_eq!((xi_of(a2, 0.0), xi_of(a2, -0.3)), (0.0, 0.0));
            assert_eq!(half_angle(a2, 0.0), (0.0, 1.0));
            assert_eq!(half_angle(a2, 1.0), (1.0, 0.0));
        }
    }

    /// κ is where the integrand's own cut μl ≥ c falls in cos φ: just above it the integrand
    /// is on, just below off. Where s·sin θh = 0, μl does not depend on φ and κ is −∞ (every φ)
    /// when μl ≥ c holds, including μl = c exactly (view 0.5 and cone 0.5 at θh = 0, where
    /// the integrand is on), and +∞ (no φ) when it fails.
    #[test]
    fn kappa_is_the_integrands_own_cut_in_cos_phi() {
        let view = View::new(0.5, 0.5, 0.5, HC);
        assert_eq!(view.kappa(0.0, 1.0), f64::NEG_INFINITY);
        assert_ne!(view.integrand(0.0, 1.0, 0.3), [0.0, 0.0]);
        assert_eq!(View::new(0.5, 0.5, 0.4, HC).kappa(0.0, 1.0), f64::NEG_INFINITY);
        let narrow = View::new(0.5, 0.5, 0.6, HC);
        assert_eq!(narrow.kappa(0.0, 1.0), f64::INFINITY);
        assert_eq!(narrow.integrand(0.0, 1.0, 0.3), [0.0, 0.0]);
        // s·sin θh > 0: a cut inside (−1, 1), tested 1e-9 either side of it.
        for (mu_v, cone, theta_h) in [(0.5, 0.5, 0.3), (0.8, 0.2, 0.9), (0.3, 0.7, 0.6)] {
            let view = View::new(0.5, mu_v, cone, HC);
            let (sh, ch) = f64::sin_cos(theta_h);
            let k = view.kappa(sh, ch);
            assert!(k.abs() < 1.0 - 1e-6, "{k}");
            assert_ne!(view.integrand(sh, ch, k + 1e-9), [0.0, 0.0], "{mu_v} {cone} {theta_h}: above κ = {k}");
            assert_eq!(view.integrand(sh, ch, k - 1e-9), [0.0, 0.0], "{mu_v} {cone} {theta_h}: below κ = {k}");
        }
    }

    /// The φ integrand's pole just below μl = 0 (see `phi_panels`) at small α: on the initial
    /// panels of `phi_panels` the inner integral lies within its own error estimate (plus the
    /// reference's) of a reference on panels halving towards φmax down to 2⁻⁵⁹ of it, which
    /// resolve every scale of the pole without knowing where it is. On one panel [0, φmax] the
    /// G10/K21 estimate does not see the pole: at α = 1e-6 the result is off by up to ~1e5
    /// times its estimate (measured when this test was written).
    #[test]
    fn phi_panels_let_the_estimate_see_the_pole_below_the_horizon() {
        // [0, φmax] cut at φmax(1 − 2⁻ʲ), j = 1..59.
        let halving = |phi_max: f64| {
            let mut out = Vec::new();
            let mut lo = 0.0;
            for j in 1..60 {
                let b = phi_max - phi_max * 0.5f64.powi(j);
                if b > lo {
                    out.push((lo, b));
                    lo = b;
                }
            }
            out.push((lo, phi_max));
            out
        };
        let views = [HC, Shadowing::Separable { k: 0.15 }].into_iter().flat_map(|shadowing| {
            [1e-6, 1.5e-5, 1e-3].into_iter().flat_map(move |alpha| {
                [1e-4, 0.004, 0.2, 0.7].into_iter().flat_map(move |mu| [0.0, 0.3].map(|c| (shadowing, alpha, mu, c)))
            })
        });
        for (shadowing, alpha, mu, c) in views {
            let view = View::new(alpha, mu, c, shadowing);
            for k in 1..200 {
                let (sh, ch) = (0.5 * PI * k as f64 / 200.0).sin_cos();
                let kappa = view.kappa(sh, ch);
                if !(kappa > -1.0 && kappa < 1.0) {
                    continue;
                }
                let phi_max = kappa.acos();
                let f = |phi: f64| view.integrand(sh, ch, phi.cos());
                let t = integrate(&halving(phi_max), &options::<2>(0.0, 1e-13), f);
                let r = integrate(&view.phi_panels(sh, ch, kappa, phi_max), &options::<2>(0.0, 1e-9), f);
                let err = ((r.value[0] + r.value[1]) - (t.value[0] + t.value[1])).abs();
                assert!(
                    err <= r.error + t.error,
                    "{shadowing:?} α={alpha} μv={mu} c={c} θh at {k}/200 of π/2: off by {err:e}, estimates {:e} + {:e}",
                    r.error,
                    t.error
                );
            }
        }
    }

    /// Where `phi_panels` cuts, as its documentation states: in q = cos φ − κ (μl − c = slope·q,
    /// slope = 2 cos θh sin θv sin θh), breakpoints at q_max·16^−j from q_max = 1 − κ, each a
    /// sixteenth of the one before, the last the first at or below 16 q_pole, q_pole the pole's
    /// distance from the boundary, (c + p)/slope with p = μv(α/2)/(μv + μvΛ(μv))
    /// (height-correlated; Λ by the textbook form) or k/(1 − k) (separable); none when
    /// q_max ≤ 16 q_pole. The panels tile [0, φmax]. The breakpoints' q are recovered as
    /// cos φ − κ: a few ulps of 1 absolute, ≤ 1e-9 relative for q ≥ 1e-6 (q_pole here ≥ 1e-5).
    /// The views include ones where μvΛ(μv) is not small against μv (α = 0.1, μv = 0.05) and a
    /// separable k whose k/(1 − k) is 5 % above k; 399 half-vector angles a view put breakpoints
    /// near both ends of (q_pole, 16 q_pole], so a pole distance a few percent off is seen.
    #[test]
    fn phi_panels_cut_sixteen_fold_down_to_the_poles_distance() {
        let (mut cut, mut uncut) = (0, 0);
        for shadowing in [HC, Shadowing::Separable { k: 0.001 }, Shadowing::Separable { k: 0.05 }] {
            for alpha in [1e-3, 1e-2, 0.1] {
                for mu in [0.05f64, 0.2, 0.7] {
                    for c in [0.0, 0.3] {
                        let view = View::new(alpha, mu, c, shadowing);
                        let sin_v = (1.0 - mu * mu).sqrt();
                        let p = match shadowing {
                            Shadowing::HeightCorrelated => {
                                let lambda = 0.5 * ((1.0 + alpha * alpha * sin_v * sin_v / (mu * mu)).sqrt() - 1.0);
                                mu * (0.5 * alpha) / (mu + mu * lambda)
                            }
                            Shadowing::Separable { k } => k / (1.0 - k),
                        };
                        for j in 1..400 {
                            let (sh, ch) = (0.5 * PI * j as f64 / 400.0).sin_cos();
                            let kappa = view.kappa(sh, ch);
                            if !(kappa > -1.0 && kappa < 1.0) {
                                continue;
                            }
                            let phi_max = kappa.acos();
                            let panels = view.phi_panels(sh, ch, kappa, phi_max);
                            let what = format!("{shadowing:?} α={alpha} μv={mu} c={c} θh at {j}/400 of π/2: {panels:?}");
                            assert_eq!((panels[0].0, panels[panels.len() - 1].1), (0.0, phi_max), "{what}");
                            assert!(panels.windows(2).all(|w| w[0].1 == w[1].0 && w[0].0 < w[0].1), "{what}");
                            let q_max = 1.0 - kappa;
                            let q_pole = (c + p) / (2.0 * ch * sin_v * sh);
                            let qs: Vec<f64> = panels[1..].iter().map(|&(a, _)| a.cos() - kappa).collect();
                            if qs.is_empty() {
                                assert!(q_max <= 16.0 * q_pole, "{what}: q_max {q_max}, q_pole {q_pole}");
                                uncut += 1;
                                continue;
                            }
                            cut += 1;
                            let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b;
                            assert!(close(qs[0], q_max / 16.0), "{what}: first q {} of q_max {q_max}", qs[0]);
                            assert!(qs.windows(2).all(|w| close(w[1], w[0] / 16.0)), "{what}: {qs:?}");
                            let last = qs[qs.len() - 1];
                            assert!(last > q_pole && last <= 16.0 * q_pole, "{what}: last q {last}, q_pole {q_pole}");
                        }
                    }
                }
            }
        }
        // Both cases occur (a test passing on panels never cut would be vacuous).
        assert!(cut > 20 && uncut > 20, "{cut} cut, {uncut} uncut");
    }

    /// Smith's Λ of GGX against two references of its own. The textbook form
    /// Λ = (−1 + sqrt(1 + α² tan²θ))/2 (Heitz 2014, "Understanding the masking-shadowing
    /// function", GGX's Λ), to 1e-13 relative away from μ = 1 (where the textbook form cancels).
    /// And the projected area of the microsurface, ∫ ⟨ω·m⟩ D(m) dm = μ (1 + Λ(μ)) (Heitz 2014,
    /// the normalisation of G1 = 1/(1 + Λ)): the azimuth integral of ⟨ω·m⟩ in closed form,
    /// 2π a when b ≤ a, else 2(a φ* + b sin φ*) with cos φ* = −a/b (a = μ cos θm,
    /// b = sin θ sin θm), the polar one by the midpoint rule on 20 000 cells of θm ∈ [0, π/2],
    /// where D sin θm is smooth (finite at π/2) and the kink where b = a costs O(h²) too. The
    /// same rule gives ∫ D cos θm dm = 1 within 5.8e-9 (α = 0.3; bound 2e-8), and the identity
    /// within 5.7e-9 relative at these nine points: 1e-7 leaves a margin of 17.
    #[test]
    fn lambda_is_smiths_and_gives_the_microsurfaces_projected_area() {
        for &alpha in &[0.1f64, 0.5, 1.0, 2.0] {
            for &mu in &[0.05f64, 0.3, 0.7] {
                let tan2 = (1.0 - mu * mu) / (mu * mu);
                let want = 0.5 * ((1.0 + alpha * alpha * tan2).sqrt() - 1.0);
                assert!((lambda(alpha, mu) - want).abs() <= 1e-13 * want, "α {alpha}, μ {mu}: {} vs {want}", lambda(alpha, mu));
            }
        }
        let n = 20_000;
        let h = 0.5 * PI / n as f64;
        for &alpha in &[0.3, 0.7, 1.0] {
            let d = |t: f64| {
                let (s, c) = t.sin_cos();
                let x = (s / c).powi(2) / (alpha * alpha) + 1.0;
                1.0 / (PI * alpha * alpha * c.powi(4) * x * x)
            };
            let cells = || (0..n).map(|i| (i as f64 + 0.5) * h);
            let norm: f64 = cells().map(|t| d(t) * t.sin() * t.cos() * 2.0 * PI * h).sum();
            assert!((norm - 1.0).abs() < 2e-8, "α {alpha}: ∫ D cos = {norm}");
            for &mu in &[0.1f64, 0.5, 0.9] {
                let sin_o = (1.0 - mu * mu).sqrt();
                let area: f64 = cells()
                    .map(|t| {
                        let (a, b) = (mu * t.cos(), sin_o * t.sin());
                        let phi = if b <= a { 2.0 * PI * a } else {
                            let p = (-a / b).acos();
                            2.0 * (a * p + b * p.sin())
                        };
                        d(t) * t.sin() * phi * h
                    })
                    .sum();
                let want = mu * (1.0 + lambda(alpha, mu));
                assert!((area - want).abs() <= 1e-7 * want, "α {alpha}, μ {mu}: projected area {area} vs μ(1 + Λ) {want}");
            }
        }
    }

    #[test]
    fn normal_incidence_at_alpha_one_is_one_minus_ln2() {
        // The closed form of albedo_normal_rough; the tolerance is the integrator's requested 1e-12.
        let e = albedo(1.0, 1.0, 1e-12);
        assert!((e.value - albedo_normal_rough()).abs() < 2e-12, "{} vs {}", e.value, albedo_normal_rough());
    }

    #[test]
    fn albedo_never_exceeds_one_and_smooth_limit_holds() {
        for &alpha in &[1e-3, 1e-2, 0.1, 0.5, 1.0] {
            for &mu in &[0.0, 1e-4, 0.01, 0.3, 0.7, 1.0] {
                let e = albedo(alpha, mu, 1e-10);
                assert!(e.value <= 1.0 + e.error && e.value > 0.0, "α={alpha} μ={mu}: {e:?}");
            }
        }
        // α → 0: E → 1, bias → (1 − μ)⁵. At α = 1e-4 the deviation is O(α) at these μ (the
        // lobe's width); 1e-3 bounds it with margin.
        for &mu in &[0.2, 0.5, 0.9, 1.0] {
            let r = env(1e-4, mu, 0.0, HC, 1e-11);
            assert!((r.scale + r.bias - 1.0).abs() < 1e-3, "μ={mu}: {r:?}");
            assert!((r.bias - (1.0 - mu).powi(5)).abs() < 1e-3, "μ={mu}: {r:?}");
        }
    }

    #[test]
    fn the_closing_cone_removes_everything() {
        assert_eq!(env(0.3, 0.5, 1.0, HC, 1e-10).scale, 0.0);
        // Near c = 1 the region is a cap of solid angle 2π(1 − c): the integrals vanish with it.
        let r = env(0.3, 0.9, 0.9999, HC, 1e-12);
        assert!(r.scale < 1e-3 && r.bias < 1e-3, "{r:?}");
        let open = env(0.3, 0.9, 0.0, HC, 1e-12);
        let half = env(0.3, 0.9, 0.5, HC, 1e-12);
        assert!(half.scale < open.scale && half.bias <= open.bias);
    }

    #[test]
    fn nested_inner_rules_agree_with_adaptive_panels() {
        // The nested azimuth rules against the adaptive G10/K21 reference at 1e-12, over small
        // α, grazing n·v, cones and both shadowing models: each result is within its own error
        // estimate plus the reference's tolerance, and that estimate is within the requested
        // tolerance (the contract).
        for shadowing in [HC, Shadowing::Separable { k: 0.15 }] {
            for &alpha in &[1e-6, 1.5e-5, 1e-3, 0.05, 0.3, 0.8, 1.0] {
                for &mu in &[0.0, 1e-4, 0.004, 0.2, 0.7, 0.999, 1.0] {
                    for &c in &[0.0, 0.3, 0.9] {
                        for &tol in &[1e-7, 1e-10] {
                            let r = env(alpha, mu, c, shadowing, tol);
                            let t = env_with(alpha, mu, c, shadowing, 1e-12, Inner::Adaptive);
                            let err = (r.scale - t.scale).abs().max((r.bias - t.bias).abs());
                            assert!(r.error <= tol, "{shadowing:?} α={alpha} μ={mu} c={c} tol={tol}: {r:?}");
                            assert!(err <= r.error + 2e-12, "{shadowing:?} α={alpha} μ={mu} c={c} tol={tol}: {err:e} > {:e}", r.error);
                        }
                    }
                }
            }
        }
    }

    /// The exact Fresnel factor against the textbook s and p amplitudes, r_s = (c − η c_t)/(c +
    /// η c_t), r_p = (η c − c_t)/(η c + c_t), c_t from Snell's law, F = (r_s² + r_p²)/2, for
    /// external and internal incidence: the two are the same function written apart (Born &
    /// Wolf §1.5). Away from the critical angle (1e-3 in cosine, where both square roots
    /// amplify the rounding of their argument by up to 1/(2g), g ≥ 0.03) they agree to a few
    /// roundings: 1e-13. Below the critical cosine the reflection is total, exactly 1; at
    /// normal incidence ((η − 1)/(η + 1))².
    #[test]
    fn fresnel_dielectric_is_the_textbook_s_and_p_average() {
        let textbook = |c: f64, eta: f64| {
            let st = (1.0 - c * c).sqrt() / eta;
            let ct = (1.0 - st * st).sqrt();
            let rs = (c - eta * ct) / (c + eta * ct);
            let rp = (eta * c - ct) / (eta * c + ct);
            0.5 * (rs * rs + rp * rp)
        };
        for eta in [1.1f64, 1.5, 2.4, 0.7, 1.0 / 1.33] {
            let critical = if eta < 1.0 { (1.0 - eta * eta).sqrt() } else { 0.0 };
            for i in 0..400 {
                let c = (i as f64 + 0.5) / 400.0;
                let got = fresnel_dielectric(c, eta);
                if c < critical {
                    assert_eq!(got, 1.0, "η {eta}, c {c}: total internal reflection");
                } else if c > critical + 1e-3 {
                    let want = textbook(c, eta);
                    assert!((got - want).abs() < 1e-13, "η {eta}, c {c}: {got} vs {want}");
                }
            }
            let normal = ((eta - 1.0) / (eta + 1.0)).powi(2);
            assert!((fresnel_dielectric(1.0, eta) - normal).abs() < 1e-15, "η {eta}: {}", fresnel_dielectric(1.0, eta));
        }
    }

    /// F_avg(η) = 2∫₀¹ F μ dμ against its closed form for η > 1,
    ///   ½ + (η − 1)(3η + 1)/(6(η + 1)²) + η²(η² − 1)²/(η² + 1)³ · ln((η − 1)/(η + 1))
    ///   − 2η³(η² + 2η − 1)/((η² + 1)(η⁴ − 1)) + 8η⁴(η⁴ + 1)/((η² + 1)(η⁴ − 1)²) · ln η
    /// (the diffuse reflectance of a smooth dielectric lit from the rarer side, integrated term
    /// by term; it agrees with scipy's quad of the textbook F to 3e-16 at η = 1.1 … 3), and for
    /// η < 1 by reciprocity through the interface, F_avg(1/η) = 1 − (1 − F_avg(η))/η². The
    /// quadrature is asked for 1e-13; at η = 1.05 the closed form's terms reach 10 and cancel
    /// to 1e-2, 1e-14 of rounding: 1e-12 bounds both.
    #[test]
    fn dielectric_average_is_the_closed_form_and_reciprocal() {
        let closed = |n: f64| {
            let (n2, n4) = (n * n, n.powi(4));
            0.5 + (n - 1.0) * (3.0 * n + 1.0) / (6.0 * (n + 1.0).powi(2))
                + n2 * (n2 - 1.0).powi(2) / (n2 + 1.0).powi(3) * ((n - 1.0) / (n + 1.0)).ln()
                - 2.0 * n.powi(3) * (n2 + 2.0 * n - 1.0) / ((n2 + 1.0) * (n4 - 1.0))
                + 8.0 * n4 * (n4 + 1.0) / ((n2 + 1.0) * (n4 - 1.0).powi(2)) * n.ln()
        };
        for eta in [1.05, 1.33, 1.5, 2.0, 3.0] {
            let (got, want) = (f_avg_dielectric(eta, 1e-13).value, closed(eta));
            assert!((got - want).abs() < 1e-12, "η {eta}: {got} vs {want}");
            let inner = f_avg_dielectric(1.0 / eta, 1e-13).value;
            let want = 1.0 - (1.0 - want) / (eta * eta);
            assert!((inner - want).abs() < 1e-12, "η 1/{eta}: {inner} vs {want}");
        }
    }

    #[test]
    fn schlick_average_matches_quadrature() {
        // The closed form against the 1-D integral at 1e-14 (the integrator's requested tolerance).
        for &f0 in &[0.0, 0.04, 0.5, 1.0] {
            let r = crate::integrate::adaptive(0.0, 1.0, Tolerance { abs: 1e-15, rel: 0.0, max_panels: 100 }, |m| {
                2.0 * (f0 + (1.0 - f0) * (1.0 - m).powi(5)) * m
            });
            assert!((r.value - f_avg_schlick(f0)).abs() < 1e-14);
        }
        // η = 1: no reflection; η → ∞: total reflection.
        assert!(f_avg_dielectric(1.0, 1e-14).value.abs() < 1e-14);
        assert!(f_avg_dielectric(1e6, 1e-12).value > 0.999);
    }

    /// A non-positive or NaN tolerance means [`DEFAULT_TOL`] (its doc): the same estimate, bit
    /// for bit, as asking for it. A positive one is taken as given: 1e-4 is met with fewer
    /// evaluations than the default's 1e-10.
    #[test]
    fn non_positive_and_nan_tolerances_mean_the_default() {
        let at = |tol: f64| env(0.5, 0.5, 0.2, HC, tol);
        let default = at(DEFAULT_TOL);
        let loose = at(1e-4);
        assert!(loose.error <= 1e-4 && loose.evals < default.evals, "{loose:?} vs {default:?}");
        for tol in [f64::NAN, -1.0, 0.0] {
            assert_eq!(at(tol), default, "tol {tol}");
        }
    }

    /// E = scale + bias, each within env's error, so E's error is twice it, and `albedo` asks env
    /// for half its own tolerance: E is within `tol`, and within its error of the truth. At
    /// (α, μ) = (1, 1) the truth is 1 − ln 2 (`albedo_normal_rough`); at (0.1, 0.3) it is the
    /// integral with the adaptive azimuth rule at 1e-12 (independent of the nested rules), whose
    /// own 1e-12 (twice, for the sum) is added to the bound.
    #[test]
    fn albedo_is_within_its_tolerance_and_its_error_of_the_truth() {
        let reference = env_with(0.1, 0.3, 0.0, HC, 1e-12, Inner::Adaptive);
        for (alpha, mu, truth) in [(1.0, 1.0, albedo_normal_rough()), (0.1, 0.3, reference.scale + reference.bias)] {
            for tol in [1e-6, 1e-9] {
                let e = albedo(alpha, mu, tol);
                assert!(e.error <= tol, "α {alpha}, μ {mu}, tol {tol}: {e:?}");
                assert!((e.value - truth).abs() <= e.error + 2e-12, "α {alpha}, μ {mu}, tol {tol}: {e:?} vs {truth}");
            }
        }
    }

    /// α = 0 is the mirror limit exactly (module doc): l = mirror(v), μl = μv, Schlick's weight
    /// (1 − μv)⁵, so (scale, bias) = (1 − (1 − μv)⁵, (1 − μv)⁵) where the mirror direction is in
    /// the cone (μv ≥ c, its edge included), else nothing. By hand, exact in binary: μv = ½
    /// gives bias 1/32 and scale 31/32; μv = 0 at c = 0 (the horizon) bias 1 and scale 0.
    #[test]
    fn alpha_zero_is_the_mirror_limit_in_and_out_of_the_cone() {
        let mirror = |mu: f64, c: f64| {
            let r = env(0.0, mu, c, HC, 1e-10);
            (r.scale, r.bias, r.error)
        };
        assert_eq!(mirror(0.5, 0.0), (31.0 / 32.0, 1.0 / 32.0, 0.0));
        assert_eq!(mirror(0.5, 0.5), (31.0 / 32.0, 1.0 / 32.0, 0.0));
        assert_eq!(mirror(0.0, 0.0), (0.0, 1.0, 0.0));
        assert_eq!(mirror(0.5, 0.6), (0.0, 0.0, 0.0));
    }

    /// env counts every evaluation, the azimuth integrands' included. At μv = 1 (sin θv = 0)
    /// the azimuth integrand does not depend on φ and covers [0, π] at every outer node (all
    /// inside θh ∈ (0, π/4), where μl > 0 for every φ): the nested trapezoid takes N = 4 (5
    /// nodes) and N = 8 (4 new ones), which agree, so a node costs 1 + 9 evaluations and a
    /// 21-point Kronrod panel 210; with the adaptive azimuth rule one G10/K21 panel on [0, π]
    /// converges at once, 1 + 21 a node and 462 a panel. Both cover the same outer panels.
    #[test]
    fn env_counts_the_evaluations_of_its_inner_integrals() {
        for tol in [1e-3, 1e-10] {
            let nested = env(0.5, 1.0, 0.0, HC, tol).evals;
            let adaptive = env_with(0.5, 1.0, 0.0, HC, tol, Inner::Adaptive).evals;
            assert!(nested > 0 && nested % 210 == 0, "tol {tol}: {nested} evaluations (nested)");
            assert!(adaptive > 0 && adaptive % 462 == 0, "tol {tol}: {adaptive} evaluations (adaptive)");
            assert_eq!(nested / 210, adaptive / 462, "tol {tol}: outer panels");
        }
    }

    /// F_avg's estimate adds up its pieces (two for η < 1, split at the critical angle): at
    /// least one 21-point panel each, at most `MAX_PANELS` each (a bisection adds 42
    /// evaluations), and an error estimate that is positive (a quadrature of a non-polynomial
    /// is not certified exact) and within the tolerance.
    #[test]
    fn dielectric_average_adds_up_its_pieces_evaluations_and_errors() {
        for eta in [1.0 / 1.5, 1.5] {
            let pieces = if eta < 1.0 { 2 } else { 1 };
            let r = f_avg_dielectric(eta, 1e-10);
            assert!(r.evals >= 21 * pieces && r.evals <= pieces * (21 + 42 * MAX_PANELS as u64), "η {eta}: {r:?}");
            assert!(r.error > 0.0 && r.error <= 1e-10, "η {eta}: {r:?}");
        }
    }

    /// The outer segments are the ones `segments` documents. Read back in θh (ξ through the GGX
    /// CDF's inverse tan θ = α sqrt(ξ/(1 − ξ)), to 1e-12: ξ ≤ 100/101 there), each piece [p, q]
    /// with q > p is tiled in order by segments of positive length whose interior ends are
    /// exactly the geometric breakpoints p + 4ʲd_p and q − 4ʲd_q (j ≥ 1, d = min(θ, π/2 − θ) of
    /// that end, while 4ʲd < (q − p)/2) and θ* = atan(10α) when inside; a segment is in ξ
    /// exactly when it ends at or below θ*, and goes through the smoothstep exactly when it
    /// touches p or q. An empty piece has no segment.
    #[test]
    fn segments_cut_at_the_kinks_geometric_steps_and_theta_star() {
        // Ends by hand: (0, π/4) none inside (θ* = atan 5 above it); (0.1, 1.2) 0.5 and θ* =
        // atan ½; (0, 1.5) θ* = atan 0.01 and 1.5 − 4·(π/2 − 1.5); (0.3, 1.55) 1.55 − 4d and
        // 1.55 − 16d, d = π/2 − 1.55; (0.01, 1) 0.05 and 0.17; (0.2, 0.5) and (0.5, 1.3) none;
        // the empty and the reversed piece nothing.
        let cases: [(&[(f64, f64)], f64); 7] = [
            (&[(0.0, 0.25 * PI)], 0.5),
            (&[(0.1, 1.2)], 0.05),
            (&[(0.0, 1.5)], 1e-3),
            (&[(0.3, 1.55)], 0.01),
            (&[(0.01, 1.0)], 0.2),
            (&[(0.2, 0.5), (0.5, 1.3)], 0.02),
            (&[(0.7, 0.7), (0.9, 0.4)], 0.3),
        ];
        let mut ends_seen = 0;
        for (pieces, alpha) in cases {
            let theta_star = (10.0 * alpha).atan();
            let segs = segments(pieces, alpha);
            let what = format!("{pieces:?} α {alpha}: {segs:?}");
            let theta = |x: f64, in_xi: bool| if in_xi { (alpha * (x / (1.0 - x)).sqrt()).atan() } else { x };
            let mut k = 0;
            for &(p, q) in pieces.iter().filter(|(p, q)| q > p) {
                let mut want = vec![p, q];
                for (end, dir) in [(p, 1.0), (q, -1.0)] {
                    let d = end.min(0.5 * PI - end);
                    let mut j = 1;
                    while d > 0.0 && 4f64.powi(j) * d < 0.5 * (q - p) {
                        want.push(end + dir * 4f64.powi(j) * d);
                        j += 1;
                    }
                }
                if theta_star > p && theta_star < q {
                    want.push(theta_star);
                }
                want.sort_by(f64::total_cmp);
                ends_seen += want.len();
                for w in want.windows(2) {
                    let seg = segs.get(k).unwrap_or_else(|| panic!("{what}: no segment for {w:?}"));
                    k += 1;
                    let (a, b) = (theta(seg.a, seg.in_xi), theta(seg.b, seg.in_xi));
                    assert!(seg.b > seg.a, "{what}: segment {k} is empty");
                    assert!((a - w[0]).abs() <= 1e-12 && (b - w[1]).abs() <= 1e-12, "{what}: segment {k} spans θ ({a}, {b}), want {w:?}");
                    assert_eq!(seg.in_xi, w[1] <= theta_star, "{what}: segment {k}'s variable");
                    assert_eq!(seg.smooth, w[0] == p || w[1] == q, "{what}: segment {k}'s smoothstep");
                }
            }
            assert_eq!(k, segs.len(), "{what}: segments past the pieces");
        }
        assert_eq!(ends_seen, 2 + 4 + 4 + 4 + 4 + 2 + 2);
    }

    /// At n·v = 0 (c = 0) the height-correlated pole is on μl = 0 itself (its distance
    /// μv(α/2)/(μv + μvΛ(μv)) is 0), and κ = 0 (φmax = π/2) at every θh: the breakpoints
    /// cos φ = 16⁻ʲ go on until the loop's 24 steps end, the last ones rounding onto φmax
    /// (acos 16⁻¹⁴ rounds to π/2). The panels still tile [0, φmax], none of them empty, with
    /// one panel a breakpoint below φmax: acos 16⁻ʲ for j = 1..13, and the last to φmax.
    #[test]
    fn phi_panels_stay_non_empty_when_the_pole_reaches_the_horizon() {
        let view = View::new(0.3, 0.0, 0.0, HC);
        for theta_h in [0.2, 0.7, 1.3] {
            let (sh, ch) = f64::sin_cos(theta_h);
            let kappa = view.kappa(sh, ch);
            assert_eq!(kappa, 0.0);
            let phi_max = kappa.acos();
            let panels = view.phi_panels(sh, ch, kappa, phi_max);
            assert_eq!((panels[0].0, panels[panels.len() - 1].1, panels.len()), (0.0, phi_max, 14), "θh {theta_h}: {panels:?}");
            assert!(panels.windows(2).all(|w| w[0].1 == w[1].0) && panels.iter().all(|p| p.0 < p.1), "θh {theta_h}: {panels:?}");
        }
    }
}
