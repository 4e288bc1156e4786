//! P_s: reduction to one dimension (conventions in the module doc of `super`).
//!
//! Coordinates of v about the fiber: w = v·t and the azimuth η about t in the frame
//! e₁ = (cos θf, 0, −sin θf), e₂ = (0, 1, 0), so v = w t + s_w (cos η e₁ + sin η e₂), s_w =
//! sqrt(1 − w²), dω_v = dw dη. Likewise u = a t + s_a (cos η_u e₁ + sin η_u e₂), a = u·t. Then
//! 1 + u·v = m + ρ cos Δ (m = 1 + a w, ρ = s_a s_w, Δ = η − η_u) and (h·t)² = ε²/(2(1 + u·v))
//! with ε = a + w. With K = (1 − α²)ε² and z(Δ) = K + 2α²(m + ρ cos Δ) = R + S cos Δ:
//! ```text
//! D_F(h)    = (1/πα) (1 − K/z)²
//! ∫ dΔ/z    = 2/sqrt(R² − S²) · atan(τ tan(Δ/2)),   τ = sqrt((R − S)/(R + S))
//! ∫ dΔ/z²   = (R ∫ dΔ/z − S sin Δ / z) / (R² − S²)
//! ```
//! so the Δ-integral over any arc is elementary. Cancellation-free forms: m − ρ = ε²/(m + ρ),
//! hence R − S = ε²(1 − α² + 2α²/(m + ρ)); every 1/sqrt(R² − S²) ∝ 1/|ε| is paired with a
//! K ∝ ε² before evaluation; z = (R − S) + 2S cos²(Δ/2). With y = Δ/2, atan2(τ sin y, cos y) is a
//! continuous antiderivative growing by π per period, so arcs need no wrapping; the difference
//! of its two end values is one atan of a product.
//!
//! The horizon v_z = w cos θf − s_w sin θf cos η < 0 is, for fixed w, the whole circle for
//! w < −sin θf, nothing for w > sin θf, and the arc |η| < η₀(w) in between, so
//! ```text
//! P_s(u) = 1/(4 σ_F(u) π α) ∫_{−1}^{sin θf} I(w) dw,   I(w) = πα ∫_arc(w) D_F dΔ (closed form)
//! ```
//! The 1-D integrand has
//! - a cusp on the specular cone w = −a, with a peak of width
//!   L = 2α sqrt((1−α²)(1−a²) + α²)/(1−α²) (where K/z is of order one) and Cauchy-like tails;
//! - square-root points at w = ±sin θf (the arc opens and closes);
//! - when u grazes the horizon, a multi-scale feature near the cone: D_F has a dip of width
//!   ∝ |ε| around the forward direction v = −u, and the arc boundary passes close to it. Its
//!   smallest scale is s = min(|w* + a|, 8ε_δ): w* is where the arc boundary reaches the dip's
//!   azimuth, ε_δ = δ α s_a²/sqrt((1−α²)s_a² + α²) with δ the Δ-distance of the dip from the
//!   arc boundary at w = −a.
//!
//! The whole-circle range [−1, −sin θf] is integrated in ε, the arc range in φ with
//! w = −sin θf cos φ (both square roots are analytic in φ, wherever the cone lies). Both are
//! split at the cone and mapped by x = c + L_x sinh ξ about it: linear on the scale of the
//! peak, logarithmic beyond, so the peak and its tails span O(1) in ξ and, unlike a tan map
//! (whose pole at ξ = π/2 sits close to the far end of a piece many L_x long and cost a
//! quarter of the evaluations in bisections there), nothing is singular at finite ξ.
//! With a grazing scale s < L/2 the band s ≤ |w + a| ≤ L/2 is cut out and mapped
//! logarithmically, so the feature spans O(1) in ξ at every scale. Each piece: adaptive
//! Gauss–Kronrod. Typically 60–250 evaluations of I per P_s (about 105 on the fuzz_ps grid).

use super::atan::atan2_upper;
use super::{ERROR_FLOOR, Layer, Light, alpha_ok, clean_tol, gk21_adaptive, invalid};
use crate::integrate::Estimate;
use std::f64::consts::PI;

/// Quantities of the Δ-integral at one w (see the module doc).
#[derive(Debug, Clone, Copy)]
pub(super) struct WPoint {
    /// v·t
    pub(super) w: f64,
    /// sqrt(1 − w²)
    sw: f64,
    /// false when K = 0 (on the cone, or α = 1): D_F is then constant 1/(πα) in Δ.
    peaked: bool,
    /// coefficient of ΔΦ in −2K∫dΔ/z: 4(1−α²)|ε|/sqrt(c1 (R+S))
    f1: f64,
    /// K²/(R² − S²) / ε² = (1−α²)²/(c1 (R+S))
    f2: f64,
    /// 2R|ε|/sqrt(c1 (R+S))
    f3: f64,
    /// ε² S
    f4: f64,
    tau: f64,
    /// ε² c1 = R − S
    rms: f64,
    /// 2S
    s2: f64,
}

/// Which part of the circle in Δ a w-piece integrates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Region {
    /// w < −sin θf: the whole circle lies below the horizon.
    Full,
    /// |w| < sin θf: an arc.
    Arc,
}

/// One piece of the w-range, mapped from t ∈ [0, 1].
///
/// Whole-circle pieces use x = ε = w + a directly. Arc pieces use x = φ with
/// w = −sin θf cos φ, φ ∈ [0, π]: the arc opens and closes like sqrt(w ± sin θf), which is
/// analytic in φ, wherever the cone lies (an end map would only help at the piece ends).
/// Within a piece, x = c + L_x sinh ξ (the peak around the cone, linear on the scale L_x,
/// logarithmic beyond) or, in the grazing band, x = c ± e^ξ (multi-scale), ξ linear in t.
#[derive(Debug, Clone, Copy)]
pub(super) struct Piece {
    pub(super) region: Region,
    /// Logarithmic (grazing band) rather than sinh map.
    log: bool,
    /// Map centre c (0 for ε; φ of the cone, or the arc end nearest to it, for φ).
    center: f64,
    /// L_x, or the sign of x − c for a log piece.
    scale: f64,
    xa: f64,
    dx: f64,
    /// The cone −a and sin θf (to turn φ into ε without cancellation).
    w0: f64,
    st: f64,
    /// φ of the cone when it lies in the arc region.
    phi0: Option<f64>,
    /// sin, cos of φ₀/2 (0, 0 when none).
    sp0: f64,
    cp0: f64,
}

impl Piece {
    /// Piece for x ∈ [lo, hi] (x = ε or φ), not containing the map centre in its interior.
    #[allow(clippy::too_many_arguments)]
    fn new(
        region: Region,
        lo: f64,
        hi: f64,
        center: f64,
        scale: f64,
        log: bool,
        w0: f64,
        st: f64,
        phi0: Option<f64>,
    ) -> Self {
        let (sp0, cp0) = phi0.map_or((0.0, 0.0), |p| (0.5 * p).sin_cos());
        let base = Piece { region, log, center, scale, xa: 0.0, dx: 0.0, w0, st, phi0, sp0, cp0 };
        if log {
            // x − c keeps one sign; ξ = ln|x − c| runs from the end nearer the centre.
            let (el, eh) = (lo - center, hi - center);
            if el > 0.0 {
                Piece { scale: 1.0, xa: el.ln(), dx: eh.ln() - el.ln(), ..base }
            } else {
                let (xa, xb) = ((-eh).ln(), (-el).ln());
                Piece { scale: -1.0, xa, dx: xb - xa, ..base }
            }
        } else {
            let xa = ((lo - center) / scale).asinh();
            let xb = ((hi - center) / scale).asinh();
            Piece { xa, dx: xb - xa, ..base }
        }
    }

    /// (ε = a + w, |dw/dt|, sin²θf − w² (exact from φ on arc pieces)) at t ∈ [0, 1].
    pub(super) fn map(&self, t: f64) -> (f64, f64, f64) {
        let xi = self.xa + self.dx * t;
        let (x, dxdt) = if self.log {
            let e = xi.exp();
            (self.center + self.scale * e, e * self.dx)
        } else {
            // sinh and cosh from one expm1, accurate near ξ = 0 (|ξ| stays below ~30: a piece
            // spans at most 4/L_x ≤ 4e12).
            let em = xi.exp_m1();
            let inv = 1.0 / (1.0 + em);
            let (sh, ch) = (0.5 * em * (1.0 + inv), 1.0 + 0.5 * em * em * inv);
            (self.center + self.scale * sh, self.scale * ch * self.dx)
        };
        match self.region {
            Region::Full => {
                let w = self.w0 + x;
                (x, dxdt, (self.st - w) * (self.st + w))
            }
            Region::Arc => {
                let (s, c) = (0.5 * x).sin_cos();
                let sp = 2.0 * s * c;
                let eps = if self.phi0.is_some() {
                    // −sin θf (cos φ − cos φ₀) = 2 sin θf sin((φ+φ₀)/2) sin((φ−φ₀)/2), without
                    // cancellation near the cone.
                    let (sa, sd) = (s * self.cp0 + c * self.sp0, s * self.cp0 - c * self.sp0);
                    2.0 * self.st * sa * sd
                } else {
                    -self.st * (1.0 - 2.0 * s * s) - self.w0
                };
                let ss = self.st * sp;
                (eps, ss * dxdt, ss * ss)
            }
        }
    }
}

impl Layer {
    /// Smallest w-scale of the grazing feature of a light at azimuth η_u (∞ when none).
    ///
    /// Near the cone D_F has a dip of width ∝ |ε| in Δ around the forward direction v = −u
    /// (Δ = π, i.e. η = η_u + π). The horizon arc |η| < η₀(w) has its boundary at that azimuth
    /// at w* = −sin θf cos η_u / sqrt(cos²θf + sin²θf cos²η_u), and near the cone the arc
    /// integral varies like |ε| atan(τ(w)/(η₀(w) − (π − |η_u|))), τ ∝ |ε|. When u grazes the
    /// horizon, w* → −a and the feature lives on scales from s = min(|w* + a|, 8ε_δ) up to the
    /// peak width L (ε_δ = δ α s_a²/sqrt((1−α²)s_a² + α²): the |ε| at which τ reaches half the
    /// Δ-distance δ of the dip from the arc boundary at w = −a), far below the Kronrod node
    /// spacing near the peak.
    pub(super) fn graze_scale(&self, a: f64, sa: f64, eta_u: f64) -> f64 {
        let w0 = -a;
        let mut s = f64::INFINITY;
        let ce = eta_u.cos();
        let den = (self.ct * self.ct + self.st * self.st * ce * ce).sqrt();
        if den > 0.0 {
            s = (-self.st * ce / den - w0).abs();
        }
        let (eta0, _, _) = self.arc_half_width(w0, (self.st - w0) * (self.st + w0));
        if eta0 > 0.0 && eta0 < PI {
            let dist = |x: f64| (x - PI).rem_euclid(2.0 * PI).min((PI - x).rem_euclid(2.0 * PI));
            let delta = dist(-eta_u - eta0).min(dist(-eta_u + eta0));
            s = s.min(8.0 * delta * self.alpha * sa * sa / (self.k2 * sa * sa + self.a2).sqrt());
        }
        s
    }

    /// Lower edge of the grazing band: the band s ≤ |ε| ≤ L/2 gets the logarithmic map (so a
    /// feature at any scale in it spans O(1) in ξ); None when s is not well below the peak.
    pub(super) fn graze_band(&self, sa: f64, s: f64) -> Option<f64> {
        let scale = self.peak_scale(sa);
        let s = s.max(1e-12 * scale);
        if s < scale / 2.0 { Some(s) } else { None }
    }

    /// The pieces of the w-range [−1, sin θf] for a light with u·t = a: the whole-circle part
    /// [−1, −sin θf] in ε, the arc part in φ (see [`Piece`]); both split at the cone w = −a and,
    /// with a grazing band [s, L/2], at −a ± s and −a ± L/2 (log-mapped between).
    pub(super) fn pieces(&self, a: f64, sa: f64, band: Option<f64>) -> Vec<Piece> {
        let w0 = -a;
        let scale = self.peak_scale(sa);
        let st = self.st;
        let mut wcuts: Vec<f64> = vec![w0];
        if let Some(s) = band {
            wcuts.extend_from_slice(&[w0 - s, w0 + s, w0 - 0.5 * scale, w0 + 0.5 * scale]);
        }
        let in_band = |el: f64, eh: f64| {
            band.is_some_and(|s| {
                el * eh > 0.0
                    && el.abs().min(eh.abs()) >= s * (1.0 - 1e-9)
                    && el.abs().max(eh.abs()) <= 0.5 * scale * (1.0 + 1e-9)
            })
        };
        let mut out = Vec::with_capacity(8);
        // Whole circle: w ∈ [−1, −sin θf], x = ε.
        if st < 1.0 {
            let mut cuts: Vec<f64> = vec![-1.0, -st];
            cuts.extend(wcuts.iter().copied().filter(|&c| c > -1.0 && c < -st));
            cuts.sort_by(|x, y| x.total_cmp(y));
            cuts.dedup();
            for win in cuts.windows(2) {
                let (el, eh) = (win[0] - w0, win[1] - w0);
                if eh > el {
                    out.push(Piece::new(
                        Region::Full,
                        el,
                        eh,
                        0.0,
                        scale,
                        in_band(el, eh),
                        w0,
                        st,
                        None,
                    ));
                }
            }
        }
        // Arc: w = −sin θf cos φ, φ ∈ [0, π].
        if st > 0.0 {
            let phi_of = |w: f64| (-w / st).clamp(-1.0, 1.0).acos();
            let inside = w0 > -st && w0 < st;
            let phi0 = if inside { Some(phi_of(w0)) } else { None };
            // Peak width in φ: dw/dφ = sin θf sin φ, and w − w0 ≈ sin θf (φ² − φ₀²)/2 near the
            // ends; outside the arc region, the tail reaching the nearer end.
            let (center, lphi) = match phi0 {
                Some(p0) => (p0, scale / (st * (p0.sin().powi(2) + 2.0 * scale / st).sqrt())),
                None => {
                    let dist = w0.abs() - st;
                    (if w0 <= -st { 0.0 } else { PI }, (2.0 * (scale + dist) / st).sqrt())
                }
            };
            let lphi = lphi.clamp(1e-12, 4.0);
            let mut cuts: Vec<f64> = vec![0.0, PI];
            cuts.extend(wcuts.iter().copied().filter(|&c| c > -st && c < st).map(phi_of));
            cuts.sort_by(|x, y| x.total_cmp(y));
            cuts.dedup();
            for win in cuts.windows(2) {
                let (lo, hi) = (win[0], win[1]);
                if hi <= lo {
                    continue;
                }
                let (wl, wh) = (-st * lo.cos(), -st * hi.cos());
                let log = phi0.is_some() && in_band(wl - w0, wh - w0);
                out.push(Piece::new(Region::Arc, lo, hi, center, lphi, log, w0, st, phi0));
            }
        }
        out
    }

    pub(super) fn wpoint(&self, a: f64, sa: f64, eps: f64) -> WPoint {
        let w = (-a + eps).clamp(-1.0, 1.0);
        let sw = ((1.0 - w) * (1.0 + w)).max(0.0).sqrt();
        let m = 1.0 + a * w;
        let rho = sa * sw;
        let p = m + rho;
        let e = eps.abs();
        let mut wp = WPoint {
            w,
            sw,
            peaked: false,
            f1: 0.0,
            f2: 0.0,
            f3: 0.0,
            f4: 0.0,
            tau: 0.0,
            rms: 0.0,
            s2: 0.0,
        };
        if e == 0.0 || self.k2 == 0.0 || p <= 0.0 {
            return wp;
        }
        let k2 = self.k2;
        let kk = k2 * e * e;
        let r = kk + 2.0 * self.a2 * m;
        let s = 2.0 * self.a2 * rho;
        let c1 = k2 + 2.0 * self.a2 / p;
        let rps = kk + 2.0 * self.a2 * p;
        // 1/sqrt(c1 (R+S)): τ = |ε| sqrt(c1/(R+S)) = |ε| c1/sqrt(c1 (R+S)).
        let inv = 1.0 / (c1 * rps).sqrt();
        wp.peaked = true;
        wp.f1 = 4.0 * k2 * e * inv;
        wp.f2 = k2 * k2 * inv * inv;
        wp.f3 = 2.0 * r * e * inv;
        wp.f4 = e * e * s;
        wp.tau = e * c1 * inv;
        wp.rms = e * e * c1;
        wp.s2 = 2.0 * s;
        wp
    }

    /// πα × ∫ D_F dΔ over the whole circle.
    pub(super) fn full_circle(wp: &WPoint) -> f64 {
        if !wp.peaked {
            return 2.0 * PI;
        }
        2.0 * PI - PI * wp.f1 + wp.f2 * wp.f3 * PI
    }

    /// Half-width η₀ of the arc (in η) below the horizon at this w, with sin, cos of η₀/2;
    /// `prod` = sin²θf − w² (passed in exactly where known).
    pub(super) fn arc_half_width(&self, w: f64, prod: f64) -> (f64, f64, f64) {
        self.arc_half_width_sw(w, ((1.0 - w) * (1.0 + w)).max(0.0).sqrt(), prod)
    }

    /// [`Layer::arc_half_width`] with sqrt(1 − w²) given.
    fn arc_half_width_sw(&self, w: f64, sw: f64, prod: f64) -> (f64, f64, f64) {
        let b = sw * self.st;
        let c = w * self.ct;
        if b <= 0.0 {
            return if c < 0.0 { (PI, 1.0, 0.0) } else { (0.0, 0.0, 1.0) };
        }
        if c <= -b {
            return (PI, 1.0, 0.0);
        }
        if c >= b {
            return (0.0, 0.0, 1.0);
        }
        // η₀/2 = atan2(sqrt(b − c), sqrt(b + c)); (b − c)(b + c) = sin²θf − w² = prod, used for
        // the smaller factor.
        let (mut bm, mut bp) = (b - c, b + c);
        if c < 0.0 {
            bp = prod / bm;
        } else {
            bm = prod / bp;
        }
        let (bm, bp) = (bm.max(0.0), bp.max(0.0));
        let h = 1.0 / (bm + bp).sqrt();
        let (s0, c0) = (bm.sqrt() * h, bp.sqrt() * h);
        (2.0 * atan2_upper(s0, c0), s0, c0)
    }

    /// πα × ∫ D_F dΔ over the arc Δ ∈ (−η_u − η₀, −η_u + η₀), given sin, cos of η₀/2 and η_u/2.
    ///
    /// Uses the continuous antiderivative: with y = Δ/2 ∈ [−π, π], atan2(τ sin y, cos y) is
    /// continuous and grows by π per period of Δ, so no wrapping of the arc is needed.
    pub(super) fn arc(wp: &WPoint, eta0: f64, s0: f64, c0: f64, sh: f64, ch: f64) -> f64 {
        let len = 2.0 * eta0;
        if !wp.peaked || eta0 <= 0.0 {
            return len;
        }
        if eta0 >= PI {
            return Self::full_circle(wp);
        }
        // y_hi = (η₀ − η_u)/2, y_lo = (−η₀ − η_u)/2
        let (s_hi, c_hi) = (s0 * ch - c0 * sh, c0 * ch + s0 * sh);
        let (s_lo, c_lo) = (-(s0 * ch + c0 * sh), c0 * ch - s0 * sh);
        // Φ(y_hi) − Φ(y_lo) with Φ(y) = arg(cos y + iτ sin y), in (0, π) since η₀ < π:
        // one atan2 of the product (cos y_hi + iτ sin y_hi)(cos y_lo − iτ sin y_lo).
        let tau = wp.tau;
        // The imaginary part τ sin η₀ is ≥ 0 (η₀ ∈ (0, π)), so the angle lies in [0, π].
        let dphi = atan2_upper(
            (tau * (s_hi * c_lo - c_hi * s_lo)).max(0.0),
            c_hi * c_lo + tau * tau * s_hi * s_lo,
        );
        // sin Δ / z(Δ), z = (R − S) + 2S cos²(Δ/2)
        let q = |s: f64, c: f64| 2.0 * s * c / (wp.rms + wp.s2 * c * c);
        let sig = q(s_hi, c_hi) - q(s_lo, c_lo);
        len - wp.f1 * dphi + wp.f2 * (wp.f3 * dphi - wp.f4 * sig)
    }

    /// P_s for one light.
    pub(super) fn ps(&self, l: &Light, tol: f64) -> Estimate {
        let band = self.graze_band(l.sa, self.graze_scale(l.a, l.sa, l.eta));
        let pieces = self.pieces(l.a, l.sa, band);
        let norm = 1.0 / (4.0 * l.sigma * PI * self.alpha);
        let share = tol / norm / pieces.len().max(1) as f64;
        let mut value = 0.0;
        let mut error = 0.0;
        let mut evals = 0;
        for piece in &pieces {
            let (v, e, n) = gk21_adaptive(0.0, 1.0, share, &[1.0], |t| {
                let (eps, jac, prod) = piece.map(t);
                if jac == 0.0 {
                    return [0.0];
                }
                let wp = self.wpoint(l.a, l.sa, eps);
                let val = match piece.region {
                    Region::Full => Self::full_circle(&wp),
                    Region::Arc => {
                        let (eta0, s0, c0) = self.arc_half_width_sw(wp.w, wp.sw, prod);
                        Self::arc(&wp, eta0, s0, c0, l.sh, l.ch)
                    }
                };
                [val * jac]
            });
            value += v[0];
            error += e;
            evals += n;
        }
        Estimate { value: value * norm, error: (error * norm).max(ERROR_FLOOR), evals }
    }

}

/// P_s(u) = ∫_{v·n<0} p(u, v) dω_v for the light (θu, φu), to absolute tolerance `tol`
/// (≤ 0 or NaN: [`DEFAULT_TOL`]). NaN estimate for α outside (0, 1] or non-finite angles.
pub fn ps(alpha: f64, theta_f: f64, theta_u: f64, phi_u: f64, tol: f64) -> Estimate {
    if !alpha_ok(alpha) || !theta_f.is_finite() || !theta_u.is_finite() || !phi_u.is_finite() {
        return invalid();
    }
    let layer = Layer::new(alpha, theta_f);
    layer.ps(&layer.light(theta_u, phi_u), clean_tol(tol))
}

/// P_s for many light directions (θu, φu) of one (α, θf), in order.
///
/// P_s depends on a light only through its fiber coordinates (u·t, η_u), and not on η_u when
/// θf = 0 (no arc range): directions that coincide there (θu = 0 at every φu; every φu of a
/// θu at θf = 0) are integrated once, with the same bits as each alone.
pub fn ps_directions(alpha: f64, theta_f: f64, dirs: &[(f64, f64)], tol: f64) -> Vec<Estimate> {
    if !alpha_ok(alpha) || !theta_f.is_finite() {
        return vec![invalid(); dirs.len()];
    }
    let layer = Layer::new(alpha, theta_f);
    let tol = clean_tol(tol);
    let mut seen: std::collections::HashMap<[u64; 3], Estimate> = std::collections::HashMap::new();
    dirs.iter()
        .map(|&(tu, pu)| {
            if !(tu.is_finite() && pu.is_finite()) {
                return invalid();
            }
            let l = layer.light(tu, pu);
            let eta = if layer.st == 0.0 { 0.0 } else { l.eta };
            *seen.entry([l.a.to_bits(), l.sa.to_bits(), eta.to_bits()]).or_insert_with(|| layer.ps(&l, tol))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::tests::{CASES, Lcg, PS_ESTIMATE_SLACK, brute_force, sph};
    use super::super::{DEFAULT_TOL, fitting_directions, sggx_phase};
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    /// The grazing scale from its definition in the doc: s = min(|w* + a|, 8δ·α s_a²/sqrt((1−α²)s_a² + α²))
    /// with w* = −sin θf cos η_u / sqrt(cos²θf + sin²θf cos²η_u) and δ the distance in Δ from
    /// −η_u ± η₀ to π, η₀ = acos(w cos θf / (sqrt(1 − w²) sin θf)) at w = −a (here through acos,
    /// not the half-angle atan2 of the code). Lights chosen so each term is the smaller at least once.
    #[test]
    fn graze_scale_is_the_smaller_of_its_two_scales() {
        let alpha = 0.3f64;
        let dist = |x: f64| {
            let d = (x - PI).rem_euclid(2.0 * PI);
            d.min(2.0 * PI - d)
        };
        let expected = |theta_f: f64, a: f64, eta_u: f64| {
            let (st, ct) = f64::sin_cos(theta_f);
            let sa = (1.0 - a * a).sqrt();
            let ce = eta_u.cos();
            let s1 = (-st * ce / (ct * ct + st * st * ce * ce).sqrt() + a).abs();
            let w = -a;
            let cos_eta0 = w * ct / ((1.0 - w * w).sqrt() * st);
            if cos_eta0.abs() >= 1.0 {
                return (s1, f64::INFINITY);
            }
            let eta0 = cos_eta0.acos();
            let delta = dist(-eta_u - eta0).min(dist(-eta_u + eta0));
            (s1, 8.0 * delta * alpha * sa * sa / ((1.0 - alpha * alpha) * sa * sa + alpha * alpha).sqrt())
        };
        // (θf, a, η_u): outside the arc (no arc term); inside, far from the dip; inside, the arc
        // boundary 0.01 from the dip; a nearly flat fiber where the arc term is the smaller
        // (s ≈ 0.083 against 0.2, found by a scan over η_u).
        let cases = [(0.6, 0.9, 0.7), (0.6, 0.2, 2.5), (0.6, 0.2, 1.2779), (0.6, -0.3, 0.4), (1.4, 0.2, FRAC_PI_2), (1.4, 0.2, -1.4726)];
        let mut arc_won = false;
        for (theta_f, a, eta_u) in cases {
            let (s1, s2) = expected(theta_f, a, eta_u);
            arc_won |= s2 < s1;
            let got = Layer::new(alpha, theta_f).graze_scale(a, (1.0 - a * a).sqrt(), eta_u);
            // Two routes to η₀ (acos against a half-angle atan2) and a few roundings: 1e-12.
            assert!((got - s1.min(s2)).abs() <= 1e-12 * s1.min(s2).max(1e-3), "θf = {theta_f}, a = {a}, η_u = {eta_u}: {got} vs ({s1}, {s2})");
        }
        assert!(arc_won, "no case exercises the arc term");
    }

    /// No piece is empty: each takes a share of the tolerance, so an empty one would tighten
    /// the others for nothing. Two distinct cuts can still lie at the same offset from the cone
    /// in f64: with the cone at w₀ = 0.9 and a band of 1.9, the cut w₀ − 1.9 is the float just
    /// above −1, and both −1 − w₀ and that cut − w₀ round to −1.9. The whole-circle range
    /// between them is empty in ε and gets no piece.
    #[test]
    fn no_piece_is_empty_even_where_two_cuts_round_to_one_offset() {
        let (a, s) = (-0.9f64, 1.9);
        let w0 = -a;
        let cut = w0 - s;
        assert!(cut > -1.0 && cut - w0 == -1.0 - w0, "the construction needs the collision: {cut}");
        let layer = Layer::new(0.3, 0.6);
        let pieces = layer.pieces(a, (1.0 - a * a).sqrt(), Some(s));
        for p in &pieces {
            assert!(p.dx != 0.0, "an empty piece: {p:?}");
        }
        assert!(pieces.iter().any(|p| p.region == Region::Full), "{pieces:?}");
    }

    /// The pieces of a light's w-range tile [−1, sin θf] without gap or overlap, each end a cut:
    /// −1, −sin θf, sin θf, the cone w = −a and, with a grazing band [s, L/2], −a ± s and −a ± L/2
    /// (L = 2α sqrt((1−α²)s_a² + α²)/(1−α²), the peak width written out here), where they fall
    /// inside; the log-mapped pieces are the band's.
    #[test]
    fn pieces_tile_the_w_range_at_the_cuts() {
        for (alpha, theta_f, a, band) in [(0.3, 0.6, 0.7, Some(1e-4)), (0.3, 0.6, 0.7, None), (0.5, 1.2, -0.2, Some(1e-3)), (0.2, 0.9, 0.5, Some(2e-3))] {
            let layer = Layer::new(alpha, theta_f);
            let st = f64::sin(theta_f);
            let sa = (1.0f64 - a * a).sqrt();
            let l = 2.0 * alpha * ((1.0 - alpha * alpha) * sa * sa + alpha * alpha).sqrt() / (1.0 - alpha * alpha);
            let w0 = -a;
            let mut want = vec![-1.0, -st, st, w0];
            if let Some(s) = band {
                want.extend([w0 - s, w0 + s, w0 - 0.5 * l, w0 + 0.5 * l]);
            }
            want.retain(|&w| (-1.0..=st).contains(&w));
            want.sort_by(f64::total_cmp);
            want.dedup();
            // The ends of each piece, in w, sorted along the range.
            let mut ends: Vec<(f64, f64, bool, bool)> = layer
                .pieces(a, sa, band)
                .iter()
                .map(|p| {
                    let (e0, e1) = (p.map(0.0).0 + w0, p.map(1.0).0 + w0);
                    (e0.min(e1), e0.max(e1), p.log, matches!(p.region, Region::Full))
                })
                .collect();
            ends.sort_by(|x, y| x.0.total_cmp(&y.0));
            let mut cuts = vec![ends[0].0];
            for (k, e) in ends.iter().enumerate() {
                // Each end maps back from asinh/ln/φ coordinates: rounding ~1e-15, ~1e-12 at
                // the log pieces' tiny ends.
                if k > 0 {
                    assert!((e.0 - ends[k - 1].1).abs() < 1e-12, "gap or overlap at {}: {ends:?}", e.0);
                }
                cuts.push(e.1);
                if let Some(s) = band {
                    let (lo, hi) = ((e.0 - w0).abs().min((e.1 - w0).abs()), (e.0 - w0).abs().max((e.1 - w0).abs()));
                    // On the arc the band is log-mapped only when the cone itself is on the arc.
                    let mapped = e.3 || (w0 > -st && w0 < st);
                    let in_band = mapped && (e.0 - w0) * (e.1 - w0) > 0.0 && lo >= s * (1.0 - 1e-6) && hi <= 0.5 * l * (1.0 + 1e-6);
                    assert_eq!(e.2, in_band, "log map of [{}, {}] (band [{s}, {}])", e.0, e.1, 0.5 * l);
                } else {
                    assert!(!e.2);
                }
            }
            assert_eq!(cuts.len(), want.len(), "cuts {cuts:?}, expected {want:?}");
            for (c, w) in cuts.iter().zip(&want) {
                assert!((c - w).abs() < 1e-12, "cuts {cuts:?}, expected {want:?}");
            }
        }
    }

    #[test]
    fn ps_matches_brute_force() {
        // Brute force error ≤ ~1e-10 (as above); P_s at 1e-11: 1e-9 bounds the sum.
        for &(al, tf, tu, pu) in &CASES {
            let (t, u) = (sph(tf, 0.0), sph(tu, pu));
            let bf = brute_force(u, &|v| sggx_phase(al, t, u, v), true, 1e-11);
            let e = ps(al, tf, tu, pu, 1e-11);
            assert!(
                (e.value - bf).abs() < 1e-9,
                "α={al} θf={tf} θu={tu} φu={pu}: {} vs {bf}",
                e.value
            );
        }
    }

    #[test]
    fn ps_range_and_symmetries() {
        let mut rng = Lcg(7);
        for _ in 0..100 {
            let al = 0.05 + 0.95 * rng.next();
            let tf = FRAC_PI_2 * rng.next();
            let tu = PI * rng.next();
            let pu = 2.0 * PI * rng.next();
            let p = ps(al, tf, tu, pu, DEFAULT_TOL);
            // Each comparison: two estimates, each within its error (≤ 1e-9) of the truth, the
            // estimate taken PS_ESTIMATE_SLACK times (it can be ~5x low near grazing).
            let close = |q: Estimate, target: f64, what: &str| {
                assert!(
                    (q.value - target).abs() <= PS_ESTIMATE_SLACK * (p.error + q.error),
                    "{what}: α={al} θf={tf} θu={tu} φu={pu}: {} vs {target}",
                    q.value
                );
            };
            assert!(p.error <= DEFAULT_TOL);
            let slack = PS_ESTIMATE_SLACK * p.error;
            assert!(p.value >= -slack && p.value <= 1.0 + slack, "range: {}", p.value);
            close(ps(al, tf, tu, -pu, DEFAULT_TOL), p.value, "φu → −φu");
            close(ps(al, tf, PI - tu, pu + PI, DEFAULT_TOL), 1.0 - p.value, "u → −u");
            close(ps(al, PI - tf, tu, PI - pu, DEFAULT_TOL), p.value, "(θf, φu) → (π−θf, π−φu)");
            close(
                ps(al, 0.0, tu, pu, DEFAULT_TOL),
                ps(al, 0.0, tu, 0.0, DEFAULT_TOL).value,
                "θf = 0",
            );
            // α = 1: the phase function is the constant 1/(4π), P_s = ½ (the quadrature of the
            // horizon arc lengths is exact to within its estimate).
            let half = ps(1.0, tf, tu, pu, DEFAULT_TOL);
            assert!((half.value - 0.5).abs() <= PS_ESTIMATE_SLACK * half.error, "α = 1: {half:?}");
        }
    }

    #[test]
    fn ps_default_tolerance_is_honest() {
        // Default-tolerance values against 1e-13 ones: the difference must stay within the
        // two error estimates, which must meet the default tolerance.
        let mut rng = Lcg(11);
        for i in 0..200 {
            let al = if i % 3 == 0 { 0.05 + 0.1 * rng.next() } else { 0.05 + 0.95 * rng.next() };
            let tf = if i % 5 == 0 { 0.0 } else { FRAC_PI_2 * rng.next() };
            // Every fourth light grazes the horizon (μ from 1e-6 to 1e-2).
            let tu = if i % 4 == 0 {
                (10f64.powf(-6.0 + 4.0 * rng.next())).acos()
            } else {
                PI * rng.next()
            };
            let pu = 2.0 * PI * rng.next();
            let d = ps(al, tf, tu, pu, DEFAULT_TOL);
            let t = ps(al, tf, tu, pu, 1e-13);
            assert!(d.error <= DEFAULT_TOL, "estimate above tolerance: {d:?}");
            assert!(
                (d.value - t.value).abs() <= d.error + t.error,
                "α={al} θf={tf} θu={tu} φu={pu}: {d:?} vs {t:?}"
            );
        }
    }

    /// The estimates are honest on a regular grid too (random lights can miss a direction
    /// where a piece's map is tight): 4 α × 4 θf × 12 θu × 6 φu at the default tolerance
    /// against 1e-13, within the two estimates. (With the inside-arc peak width too narrow,
    /// α = 0.1, θf = 1.4, θu = 0.05 + 2.9/11, φu = π was off by 1.7e-10 against an estimate
    /// of 2.8e-11.)
    #[test]
    fn ps_estimates_are_honest_on_a_regular_grid() {
        for &al in &[0.05, 0.1, 0.3, 0.7] {
            for &tf in &[0.2, 0.6, 1.0, 1.4] {
                for i in 0..12 {
                    for j in 0..6 {
                        let (tu, pu) = (0.05 + 1.45 * i as f64 / 11.0, PI * j as f64 / 5.0);
                        let d = ps(al, tf, tu, pu, DEFAULT_TOL);
                        let t = ps(al, tf, tu, pu, 1e-13);
                        assert!(
                            (d.value - t.value).abs() <= d.error + t.error,
                            "α={al} θf={tf} θu={tu} φu={pu}: {d:?} vs {t:?}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn ps_grazing_lights_are_honest() {
        // Lights within μ = 2⁻¹…2⁻¹⁴ of the horizon, where the arc boundary passes the
        // forward-scattering dip of D_F: default estimates must bound the deviation from 1e-13.
        for &(al, tf) in &[(0.5, 0.3), (0.15, 1.2), (0.05, 0.8), (0.05, FRAC_PI_2)] {
            for k in (1..=14).step_by(3) {
                let mu = 2f64.powi(-k);
                for j in 0..8 {
                    let pu = PI * (j as f64 + 0.5) / 8.0;
                    let d = ps(al, tf, mu.acos(), pu, DEFAULT_TOL);
                    let t = ps(al, tf, mu.acos(), pu, 1e-13);
                    assert!(
                        (d.value - t.value).abs() <= d.error + t.error,
                        "α={al} θf={tf} μ={mu} φu={pu}: {d:?} vs {t:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn ps_directions_matches_ps() {
        // With the directions that coincide (θu = 0 at any φu; any φu at θf = 0), integrated
        // once: every value has the bits of its own `ps`. The mirror images φu → −φu about the
        // plane of n and the fiber (θf = 0.9 tilts the fiber towards φ = 0) share u·t but not
        // η_u: each is integrated on its own, and they agree by the mirror symmetry of the
        // layer, to the two estimates' tolerance.
        let mut dirs = fitting_directions(4, 5);
        dirs.extend((0..5).map(|j| (0.0, 0.7 * j as f64)));
        dirs.extend((0..5).map(|j| (0.4, 0.7 * j as f64)));
        dirs.extend((1..5).map(|j| (0.4, -0.7 * j as f64)));
        for tf in [0.9, 0.0] {
            let batch = ps_directions(0.3, tf, &dirs, DEFAULT_TOL);
            for (&(tu, pu), b) in dirs.iter().zip(&batch) {
                let one = ps(0.3, tf, tu, pu, DEFAULT_TOL);
                assert_eq!((b.value.to_bits(), b.error.to_bits()), (one.value.to_bits(), one.error.to_bits()), "θf {tf}, ({tu}, {pu})");
            }
            let n = dirs.len();
            for j in 1..5 {
                let (plus, minus) = (batch[n - 9 + j].value, batch[n - 5 + j].value);
                assert!((plus - minus).abs() <= 2.0 * DEFAULT_TOL, "θf {tf}, φu ±{}: {plus} {minus}", 0.7 * j as f64);
            }
        }
        assert!(ps(0.0, 0.9, 0.1, 0.1, DEFAULT_TOL).value.is_nan());
        assert!(ps(1.5, 0.9, 0.1, 0.1, DEFAULT_TOL).value.is_nan());
        assert!(ps(0.5, f64::NAN, 0.1, 0.1, DEFAULT_TOL).value.is_nan());
    }
}
