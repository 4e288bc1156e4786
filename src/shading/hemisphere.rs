//! The hemispherical operators over any lobe ([`Lobe`]): the split-sum scale and bias (the
//! environment BRDF, "DFG"), optionally limited to a visibility cone; the directional albedo
//! E(μ); and its cosine-weighted average E_avg.
//!
//! # Definitions
//!
//! With the lobe's BRDF f and Schlick's Fresnel weight Fc = (1 − v·h)⁵ (see [`super::lobe`]
//! for the frame):
//! ```text
//! scale  = ∫_{μl ≥ c} (1 − Fc) f μl dω_l,    bias = ∫_{μl ≥ c} Fc f μl dω_l,    c = cos_cone
//! E(μv)  = scale + bias  (F = 1, c = 0),     E_avg = 2 ∫₀¹ E(μ) μ dμ
//! ```
//! so that the split-sum specular of a Schlick F0 is F0·scale + bias (F90 = 1). c = 0 is the
//! hemisphere; c > 0 keeps the light directions in the visibility cone of half-angle acos c
//! about n (specular occlusion by a cone).
//!
//! # Integrating where the mass is
//!
//! The integral runs over the half vector in the lobe's measure (ξ, φ), dμ = dξ dφ/2π, of the
//! weight w = f μl dω_l/dμ (see [`super::lobe`]). The weight is even in φ; φ ∈ [0, π] counts
//! twice (dξ dφ/π).
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
//! narrower than the node spacing: a pole of the weight next to the horizon, such as GGX's G2
//! pole at small α or grazing n·v) fall back to adaptive G10/K21 on panels cut geometrically
//! down to the lobe's [`Lobe::horizon_pole`] ([`Inner::Adaptive`], which is also available
//! throughout as an independent reference).
//!
//! # What makes it slow
//!
//! A weight that is not smooth in ξ (a lobe integrated in a measure that does not follow its
//! peak: the cosine measure of a narrow lobe) costs outer panels; features in φ narrower than
//! 1/128 of the range (a pole at the horizon the lobe does not declare) cost the adaptive
//! fallback. Both are still integrated to the tolerance, with honest estimates, up to
//! `MAX_PANELS` panels a level.
//!
//! # Limits
//! - μv → 0: the weight is evaluated at μv = 0 as the lobe writes it (GGX: in a product form
//!   finite there, so n·v = 0 gives the limit, not 0/0).
//! - The mirror lobe ([`Lobe::is_mirror`]): l = mirror(v): E → 1 and bias → (1 − μv)⁵ (for
//!   μv ≥ c), exactly.
//! - c → 1: the cone closes: scale = bias = 0 (c = 1 exactly: empty region, exact 0).

use super::lobe::Lobe;
use crate::integrate::{integrate, Control, Estimate, Options, PanelError, Rule, Tolerance};
use std::cell::Cell;
use std::f64::consts::PI;

/// Default absolute tolerance of the integrators (a non-positive or NaN tolerance means this).
pub const DEFAULT_TOL: f64 = 1e-10;
/// Panels per adaptive level before the estimate is returned as is (with its error).
pub const MAX_PANELS: usize = 400;

/// scale and bias with their error estimates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SplitSum {
    pub scale: f64,
    pub bias: f64,
    /// Upper estimate of max(|scale − exact|, |bias − exact|).
    pub error: f64,
    pub evals: u64,
}

impl SplitSum {
    /// E = scale + bias, with the error of the sum.
    pub fn albedo(&self) -> Estimate {
        Estimate { value: self.scale + self.bias, error: 2.0 * self.error, evals: self.evals }
    }

    /// [scale, bias] as a vector quantity's channels: each carries the pair's error; the
    /// evaluations are counted once, on the first.
    pub fn channels(&self) -> Vec<Estimate> {
        vec![Estimate { value: self.scale, error: self.error, evals: self.evals }, Estimate { value: self.bias, error: self.error, evals: 0 }]
    }
}

/// `tol`, or [`DEFAULT_TOL`] where it is not positive (or NaN).
pub fn tolerance(tol: f64) -> f64 {
    if tol > 0.0 { tol } else { DEFAULT_TOL }
}

/// One point of the problem: everything the φ integrand needs at a fixed view.
struct View<'a, L: Lobe> {
    lobe: &'a L,
    terms: L::View,
    mu_v: f64,
    sin_v: f64,
    cos_cone: f64,
}

impl<'a, L: Lobe> View<'a, L> {
    fn new(lobe: &'a L, mu_v: f64, cos_cone: f64) -> Self {
        View { lobe, terms: lobe.view(mu_v), mu_v, sin_v: ((1.0 - mu_v) * (1.0 + mu_v)).sqrt(), cos_cone }
    }

    /// [(1 − Fc) w, Fc w] with w the lobe's weight, at a half vector of polar sin/cos (sh, ch)
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
            // μl = 0: the weight's limit there (f μl → 0 for a finite f; GGX's G2 and the
            // separable G1(l) vanish there).
            return [0.0, 0.0];
        }
        self.weights(vh, ch, mu_l)
    }

    #[inline]
    fn weights(&self, vh: f64, ch: f64, mu_l: f64) -> [f64; 2] {
        let w = self.lobe.weight(&self.terms, vh, ch, mu_l);
        let m = 1.0 - vh;
        let m2 = m * m;
        let fc = m2 * m2 * m;
        [w - fc * w, fc * w]
    }

    /// The initial φ panels of [0, φmax]: geometric towards φmax when the horizon cuts the
    /// range. Near μl = 0 the weight may have a pole at a distance p below μl = 0 (the
    /// lobe's [`Lobe::horizon_pole`]; GGX: μv(α/2)/(μv + μvΛ(μv)) height-correlated,
    /// k/(1 − k) separable): at grazing n·v or small α a feature far narrower than one
    /// G10/K21 panel, which the error estimate cannot see. Breakpoints at μl − c = (μl_max − c)·16^{−j}, down to 16× the pole's distance
    /// from the boundary, put panels on every scale of it.
    fn phi_panels(&self, sh: f64, ch: f64, kappa: f64, phi_max: f64) -> Vec<(f64, f64)> {
        if phi_max >= PI {
            return vec![(0.0, PI)];
        }
        let slope = 2.0 * ch * self.sin_v * sh; // dμl / d(cos φ)
        let pole = self.lobe.horizon_pole(&self.terms);
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

/// The split-sum scale and bias of `lobe` (see the module doc) to absolute tolerance `tol` on
/// each. Parameters are taken as given (the caller checks domains): μv, c ∈ [0, 1].
pub fn split_sum<L: Lobe>(lobe: &L, mu_v: f64, cos_cone: f64, tol: f64) -> SplitSum {
    split_sum_with(lobe, mu_v, cos_cone, tol, Inner::Nested)
}

/// The inner (azimuth) rule of [`split_sum_with`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Inner {
    /// Nested trapezoid (full range) or Clenshaw–Curtis (cut range) with doubling, falling
    /// back to `Adaptive` when it has not converged at 129 nodes (the default).
    Nested,
    /// Adaptive G10/K21 with QUADPACK estimates on geometric panels only (an independent
    /// reference for the nested rules).
    Adaptive,
}

/// [`split_sum`] with a choice of the inner rule.
pub fn split_sum_with<L: Lobe>(lobe: &L, mu_v: f64, cos_cone: f64, tol: f64, inner: Inner) -> SplitSum {
    let tol = tolerance(tol);
    if cos_cone >= 1.0 {
        return SplitSum { scale: 0.0, bias: 0.0, error: 0.0, evals: 0 };
    }
    if lobe.is_mirror() {
        // The mirror limit: D = δ(h − n), G = 1, l = mirror(v) with μl = μv.
        if mu_v < cos_cone {
            return SplitSum { scale: 0.0, bias: 0.0, error: 0.0, evals: 0 };
        }
        let b = (1.0 - mu_v).powi(5);
        return SplitSum { scale: 1.0 - b, bias: b, error: 0.0, evals: 0 };
    }
    let view = View::new(lobe, mu_v, cos_cone);
    let theta_v = mu_v.acos();
    let theta_c = cos_cone.acos();
    let lo = (0.5 * (theta_v - theta_c)).max(0.0);
    let hi = 0.5 * (theta_v + theta_c);
    let full = 0.5 * (theta_c - theta_v);
    let mut pieces: Vec<(f64, f64)> = Vec::with_capacity(2);
    if full > lo {
        pieces.push((lo, full));
        pieces.push((full, hi));
    } else {
        pieces.push((lo, hi));
    }
    let segments = segments(&pieces, lobe);
    if segments.is_empty() {
        return SplitSum { scale: 0.0, bias: 0.0, error: 0.0, evals: 0 };
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
            let (s2, c2) = lobe.half_angle(x);
            (s2.sqrt(), c2.sqrt(), jac)
        } else {
            let (sh, ch) = x.sin_cos();
            (sh, ch, lobe.xi_measure(jac, sh, ch))
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
    SplitSum { scale: r.value[0], bias: r.value[1], error: r.error + r.value[2], evals: r.evals + inner_evals.get() }
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
fn nested_phi<L: Lobe>(view: &View<'_, L>, sh: f64, ch: f64, phi_max: f64, abs: f64, rel: f64) -> Option<NestedResult> {
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
/// - Variable: ξ below the lobe's θ* ([`Lobe::switch_angle`]), where the measure has its
///   mass (GGX: atan(10α), ξ(θ*) = 100/101), θh above it: there ξ crowds against 1
///   (GGX: 1 − ξ ≈ α² cot²θh) and a kink near θh = π/2 would sit within a few ulps of ξ = 1.
/// - Geometric breakpoints at each kink θk, at distances d·4^j with d = min(θk, π/2 − θk),
///   out to half the piece. Past a kink the azimuth limit varies on the scale of that distance:
///   at c = 0, cos φmax = −cot θv cot 2θh ≈ −(π/2 − θv)/(2θh) for grazing v, a function of
///   θh/θk near θk = (π/2 − θv)/2, and mirrored near θh = π/2. Uniform panels would not see it.
fn segments<L: Lobe>(pieces: &[(f64, f64)], lobe: &L) -> Vec<Segment> {
    let theta_star = lobe.switch_angle();
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
            let (sa, sb) = if in_xi { (lobe.xi_of(a), lobe.xi_of(b)) } else { (a, b) };
            if sb > sa {
                out.push(Segment { a: sa, b: sb, in_xi, smooth: a == p || b == q });
            }
        }
    }
    out
}

/// E(μv) = scale + bias with F = 1, to absolute tolerance `tol`.
pub fn albedo<L: Lobe>(lobe: &L, mu_v: f64, tol: f64) -> Estimate {
    let tol = tolerance(tol);
    split_sum(lobe, mu_v, 0.0, 0.5 * tol).albedo()
}

/// E_avg = 2 ∫₀¹ E(μ) μ dμ to absolute tolerance `tol`: the outer μ integral (through the
/// smoothstep map, which tames the μ → 1 end where θv = acos μ has a square root) to half,
/// each E to the other half.
pub fn albedo_avg<L: Lobe>(lobe: &L, tol: f64) -> Estimate {
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
            let e = albedo(lobe, mu, 0.5 * tol);
            let (n, worst) = inner.get();
            inner.set((n + e.evals, worst.max(e.error)));
            2.0 * e.value * mu * jac
        },
    );
    let (n, worst) = inner.get();
    Estimate { value: r.value, error: r.error + worst, evals: r.evals + n }
}

/// How the leading parameters of a quantity make a lobe (its roughness, a user parameter…):
/// the evaluators below take the view (n·v) and the cone after them, so that a family serves a
/// lobe's E, E_avg and split sum as quantities with no integrator code of its own.
pub trait LobeParams {
    type Lobe: Lobe;
    /// How many leading parameters are the lobe's.
    const COUNT: usize;
    /// The lobe at those parameters (inside the quantity's domain).
    fn lobe(p: &[f64]) -> Self::Lobe;
}

/// E at p = [lobe parameters…, n·v], to absolute tolerance `tol` (a quantity's `eval`).
pub fn eval_albedo<P: LobeParams>(p: &[f64], tol: f64) -> Estimate {
    albedo(&P::lobe(p), p[P::COUNT], tol)
}

/// E_avg at p = [lobe parameters…] (a quantity's `eval`).
pub fn eval_albedo_avg<P: LobeParams>(p: &[f64], tol: f64) -> Estimate {
    albedo_avg(&P::lobe(p), tol)
}

/// [scale, bias] at p = [lobe parameters…, n·v, cos_cone (0 when left out)] (a quantity's
/// `eval_channels`): each channel carries the pair's error; the evaluations are counted once,
/// on the first.
pub fn eval_split_sum<P: LobeParams>(p: &[f64], tol: f64) -> Vec<Estimate> {
    split_sum(&P::lobe(p), p[P::COUNT], p.get(P::COUNT + 1).copied().unwrap_or(0.0), tol).channels()
}

/// Channel 0 (scale) of [`eval_split_sum`] (a vector quantity's `eval`).
pub fn eval_split_sum_scale<P: LobeParams>(p: &[f64], tol: f64) -> Estimate {
    eval_split_sum::<P>(p, tol)[0]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shading::lambert::Lambert;
    use crate::shading::trowbridge_reitz::{Ggx, Shadowing};

    const HC: Shadowing = Shadowing::HeightCorrelated;

    /// A lobe with a closed-form directional albedo, written as its BRDF alone (the cosine
    /// measure, no quadrature knowledge): f = (3/2π) μv μl, reciprocal, with
    /// E(μv) = (3/2π) μv ∫ μl² dω_l = μv and, in a cone μl ≥ c, μv (1 − c³); E_avg = 2∫μ² dμ = 2/3.
    struct Linear;

    impl Lobe for Linear {
        type View = f64;
        fn view(&self, mu_v: f64) -> f64 {
            mu_v
        }
        fn eval(&self, mu_v: &f64, _vh: f64, _ch: f64, mu_l: f64) -> f64 {
            1.5 / PI * mu_v * mu_l
        }
    }

    /// ∫ 8s(2s² − 1)(1 − s)⁵ ds from s₀ to 1 by its antiderivative: Lambert's bias at normal
    /// incidence, where v·h = s = sqrt((1 + μl)/2), μl = 2s² − 1, dμl = 4s ds, and the cone
    /// μl ≥ c starts at s₀ = sqrt((1 + c)/2). Expanded with u = 1 − s (s = 1 − u, ds = −du):
    /// 8(1 − u)(1 − 4u + 2u²)u⁵ = 8(u⁵ − 5u⁶ + 6u⁷ − 2u⁸), integrated from 0 to u₀ = 1 − s₀.
    fn lambert_bias_at_normal_incidence(c: f64) -> f64 {
        let u = 1.0 - ((1.0 + c) / 2.0).sqrt();
        8.0 * (u.powi(6) / 6.0 - 5.0 * u.powi(7) / 7.0 + 6.0 * u.powi(8) / 8.0 - 2.0 * u.powi(9) / 9.0)
    }

    /// The generic operators on two lobes given by their BRDF only, against closed forms: the
    /// albedo table of each over n·v (Lambert's 1; the linear lobe's μv), the split-sum table
    /// over n·v × cone (scale + bias = 1 − c² for Lambert, μv(1 − c³) for the linear lobe; the
    /// bias of Lambert at normal incidence by its antiderivative), and E_avg (1 and 2/3). Each
    /// is asked for 1e-10 and held to it plus its own error estimate: the estimate is honest
    /// when the difference stays inside it.
    #[test]
    fn lobes_written_as_their_brdf_get_exact_albedo_split_sum_and_average() {
        let tol = 1e-10;
        let mus: Vec<f64> = (0..=16).map(|i| i as f64 / 16.0).collect();
        let cones = [0.0, 0.3, 0.8];
        let albedo_table: Vec<Estimate> = mus.iter().map(|&mu| albedo(&Lambert, mu, tol)).collect();
        for (mu, e) in mus.iter().zip(&albedo_table) {
            assert!((e.value - 1.0).abs() <= tol + e.error, "Lambert E({mu}) = {e:?}");
        }
        let albedo_table: Vec<Estimate> = mus.iter().map(|&mu| albedo(&Linear, mu, tol)).collect();
        for (mu, e) in mus.iter().zip(&albedo_table) {
            assert!((e.value - mu).abs() <= tol + e.error, "linear E({mu}) = {e:?}");
        }
        for &c in &cones {
            for &mu in &mus {
                let s = split_sum(&Lambert, mu, c, tol);
                let sum = s.albedo();
                assert!((sum.value - (1.0 - c * c)).abs() <= 2.0 * tol + sum.error, "Lambert μv {mu} c {c}: {s:?}");
                let s = split_sum(&Linear, mu, c, tol);
                let sum = s.albedo();
                assert!((sum.value - mu * (1.0 - c.powi(3))).abs() <= 2.0 * tol + sum.error, "linear μv {mu} c {c}: {s:?}");
            }
            let s = split_sum(&Lambert, 1.0, c, tol);
            let want = lambert_bias_at_normal_incidence(c);
            assert!((s.bias - want).abs() <= tol + s.error, "Lambert bias at μv 1, c {c}: {s:?} vs {want}");
            assert!((s.scale - (1.0 - c * c - want)).abs() <= tol + s.error, "Lambert scale at μv 1, c {c}: {s:?}");
        }
        for (lobe_avg, want) in [(albedo_avg(&Lambert, tol), 1.0), (albedo_avg(&Linear, tol), 2.0 / 3.0)] {
            assert!((lobe_avg.value - want).abs() <= tol + lobe_avg.error, "E_avg {lobe_avg:?} vs {want}");
        }
        // The bias is six orders above the tolerance (8.19e-5 at c = 0): the closed form is
        // checked where it matters.
        assert!(lambert_bias_at_normal_incidence(0.0) > 5e-5, "{}", lambert_bias_at_normal_incidence(0.0));
    }

    /// κ is where the integrand's own cut μl ≥ c falls in cos φ: just above it the integrand
    /// is on, just below off. Where s·sin θh = 0, μl does not depend on φ and κ is −∞ (every φ)
    /// when μl ≥ c holds, including μl = c exactly (view 0.5 and cone 0.5 at θh = 0, where
    /// the integrand is on), and +∞ (no φ) when it fails.
    #[test]
    fn kappa_is_the_integrands_own_cut_in_cos_phi() {
        let lobe = Ggx::new(0.5, HC);
        let view = View::new(&lobe, 0.5, 0.5);
        assert_eq!(view.kappa(0.0, 1.0), f64::NEG_INFINITY);
        assert_ne!(view.integrand(0.0, 1.0, 0.3), [0.0, 0.0]);
        assert_eq!(View::new(&lobe, 0.5, 0.4).kappa(0.0, 1.0), f64::NEG_INFINITY);
        let narrow = View::new(&lobe, 0.5, 0.6);
        assert_eq!(narrow.kappa(0.0, 1.0), f64::INFINITY);
        assert_eq!(narrow.integrand(0.0, 1.0, 0.3), [0.0, 0.0]);
        // s·sin θh > 0: a cut inside (−1, 1), tested 1e-9 either side of it.
        for (mu_v, cone, theta_h) in [(0.5, 0.5, 0.3), (0.8, 0.2, 0.9), (0.3, 0.7, 0.6)] {
            let view = View::new(&lobe, mu_v, cone);
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
            let lobe = Ggx::new(alpha, shadowing);
            let view = View::new(&lobe, mu, c);
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
                        let lobe = Ggx::new(alpha, shadowing);
            let view = View::new(&lobe, mu, c);
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
            let segs = segments(pieces, &Ggx::new(alpha, HC));
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
        let lobe = Ggx::new(0.3, HC);
        let view = View::new(&lobe, 0.0, 0.0);
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
