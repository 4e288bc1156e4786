//! Anisotropic asperity scattering ("fuzz") layer of Ghost of Tsushima (Patry, SIGGRAPH 2020
//! course "Samurai Shading" and its supplemental material §1.1–1.4): reference values of the
//! integrals P_s, G, Q and R that the published shader approximations P̃_s, G̃, Q̃, R̃ fit.
//!
//! # Conventions (the contract)
//!
//! Surface normal n = +z. Fiber direction t = (sin θf, 0, cos θf): θf is the fiber polar angle
//! from n. Light u = (sin θu cos φu, sin θu sin φu, cos θu): φu is measured from the fiber
//! azimuth. μ = direction·n. Angles in radians, everything f64.
//!
//! SGGX "fiber" phase function (analytically normalised), α ∈ (0, 1]:
//! ```text
//! D_F(h) = α³ / (π ((h·t)²(1 − α²) + α²)²)      σ_F(u) = sqrt(1 − (u·t)²(1 − α²))
//! p(u, v) = D_F(h) / (4 σ_F(u))                  h = (u + v)/|u + v|
//! ```
//! D_F is the SGGX NDF of S = diag(α², 1, 1) in the fiber frame (flake projected area α along
//! t, 1 across it); with dω_v = 4|u·h| dω_h and ∫ D_F(h)(u·h)₊ dω_h = σ_F(u), p integrates to 1
//! over the sphere of v. D_F is largest (1/(πα)) for h ⟂ t: scattered light concentrates on the
//! specular cone v·t = −u·t, a band of width ~α.
//!
//! The quantities (Ω = upper hemisphere):
//! ```text
//! P_s(u)    = 1 − ∫_{v·n>0} p(u, v) dω_v = ∫_{v·n<0} p(u, v) dω_v
//! G(d, μv)  = (1/2π) ∫_Ω (1 − exp(−d (μu + μv)/(μu μv))) μu/(μu + μv) dω_u
//! Q(d)      = (1/π) ∫_Ω exp(−d/μu) μu dω_u = 2 E₃(d)
//! R(θf, α)  = (1/π) ∫_Ω P_s(u) μu dω_u
//! ```
//! P_s is the fraction of light scattered by the layer toward the base layer (published fit
//! domain α ∈ [0.15, 1], θf ∈ [0.1, π/2]; here any α ∈ (0, 1], tested down to 0.05, any θf
//! (θf = 0 included; θf outside [0, π/2] is folded with t ≡ −t) and any u, also below the
//! horizon). G is the hemispherical average of the Koenderink–Pont single-scattering layer of
//! optical thickness (density) d without albedo and phase function; the seed texts garble its
//! exponent, the form above is the decision. Q is the cosine-weighted mean penetration and R
//! the cosine-weighted mean of P_s. Published G̃, Q̃ domain: d ∈ [0, 0.5].
//!
//! G depends on v only through μv; the azimuth integrates out, and with x = 1/μ and
//! 1/(x²(1+cx)) = 1/x² − c/x + c²/(1+cx) it has a closed form in exponential integrals
//! E_n(x) = ∫₁^∞ e^{−xt} t^{−n} dt:
//! ```text
//! G(d, μv) = ∫₀¹ (1 − e^{−d/μv} e^{−d/μ}) μ/(μ + μv) dμ
//!          = 1 − c ln((1+c)/c) − e^{−d/c} E₂(d) + c e^{−d/c} E₁(d) − c E₁(d(1+c)/c),   c = μv
//! ```
//! Limits: G → 1 as μv → 0 (d > 0), with 1 − G ≈ μv ln(1/μv); as d → 0,
//! G = d/μv − (d²/2μv) ln(1/d) + O(d²) (logarithmic because e^{−d/μ} does not expand near μ = 0).
//! Likewise Q(d) = 2 ∫₀¹ e^{−d/μ} μ dμ = 2 E₃(d), Q(0) = 1.
//!
//! Tolerances are absolute; [`DEFAULT_TOL`] = 1e-9 (a non-positive or NaN tolerance means the
//! default). Each [`Estimate`] carries an error estimate meant as an upper estimate of
//! |value − exact|; for P_s and R it is floored at 1e-12 (below that QUADPACK's extrapolating
//! estimate was seen to under-estimate by up to 2×). `evals` counts scalar integrand
//! evaluations (closed-form arc integrals, see `ps.rs`).
//!
//! # Error estimates
//!
//! The adaptive integrals (K21 panels) run on `crate::integrate::integrate` with
//! `Options::quadpack`. Panels use QUADPACK's estimate (`crate::integrate::quadpack_error`)
//! resasc · min(1, (200 |Q_hi − Q_lo| / resasc)^{3/2}), floored at
//! 50 ε resabs (ε = f64 epsilon), with (Q_hi, Q_lo) = (K21, G10). For
//! the mapped integrands this is far closer to the true error than the raw |Q_hi − Q_lo| and
//! still above it: the tests compare default-tolerance values with tight ones and with
//! independent brute-force quadratures. Nested errors are propagated: R's error is the outer
//! estimate plus the integral of the inner estimates. G and Q use `crate::integrate::adaptive`
//! (raw |K21 − G10|), split at μ = d and μ = μv and graded logarithmically above.
//!
//! # Symmetries and special values (tested)
//!
//! - P_s(θu, −φu) = P_s(θu, φu) (mirror y → −y keeps t and n).
//! - P_s(−u) = 1 − P_s(u), since p(−u, −v) = p(u, v).
//! - (θf, φu) → (π − θf, π − φu) leaves P_s unchanged (mirror x → −x, and t ≡ −t); at θf = π/2
//!   P_s is therefore even in u·t, so the published coefficients c₂, c₄ of the odd terms u·t and
//!   (u·n)(u·t) should vanish there.
//! - α = 1: p = 1/(4π) is isotropic, so P_s ≡ ½ and R = ½ (the published forms build this in:
//!   c_i = s_i + β(…) and R̃ = ½ + β(…) with β = 1 − α).
//! - θf = 0: P_s depends on θu only (u·t = u·n), which is why the published 6-term fit in
//!   (u·n, u·t) degenerates there and the published P̃_s clamps θf ≥ 0.1.
//!
//! # Layout
//!
//! - `ps.rs`: P_s, its reduction to one dimension and the pieces of its w-range;
//! - `r.rs`: R over the whole sphere of light directions;
//! - `layer.rs`: G, Q and the exponential integrals;
//! - `grid.rs`: the data sets of the published fits;
//! - `atan.rs`: the fast arctangents of the closed-form arc integrals;
//! - `r_horizon.rs` (tests only): the previous formulation of R, the tests' reference.

#![allow(clippy::excessive_precision)]

use crate::integrate::{Estimate, Options, integrate};
use std::f64::consts::PI;

/// Default absolute tolerance of every quantity here.
pub const DEFAULT_TOL: f64 = 1e-9;
/// Smallest α of the published P_s and R fits.
pub const PUBLISHED_ALPHA_MIN: f64 = 0.15;
/// Smallest θf of the published P_s fit (R's fit starts at 0).
pub const PUBLISHED_THETA_F_MIN: f64 = 0.1;
/// Largest density d of the published G and Q fits.
pub const PUBLISHED_DENSITY_MAX: f64 = 0.5;

/// Smallest error reported for P_s and R (see the module doc).
const ERROR_FLOOR: f64 = 1e-12;

/// Most adaptive panels in one 1-D integral here (the estimate is returned either way).
const MAX_PANELS: usize = 2000;

/// Fiber-layer parameters: flake projected area α along the fiber and fiber polar angle θf.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FuzzParams {
    pub alpha: f64,
    pub theta_f: f64,
}

impl FuzzParams {
    pub fn new(alpha: f64, theta_f: f64) -> Self {
        FuzzParams { alpha, theta_f }
    }

    /// Fiber direction t = (sin θf, 0, cos θf).
    pub fn fiber(&self) -> [f64; 3] {
        [self.theta_f.sin(), 0.0, self.theta_f.cos()]
    }

    /// P_s for one light direction; see [`ps`].
    pub fn ps(&self, theta_u: f64, phi_u: f64, tol: f64) -> Estimate {
        ps(self.alpha, self.theta_f, theta_u, phi_u, tol)
    }

    /// P_s for many light directions; see [`ps_directions`].
    pub fn ps_directions(&self, dirs: &[(f64, f64)], tol: f64) -> Vec<Estimate> {
        ps_directions(self.alpha, self.theta_f, dirs, tol)
    }

    /// R; see [`r`].
    pub fn r(&self, tol: f64) -> Estimate {
        r(self.alpha, self.theta_f, tol)
    }
}

fn invalid() -> Estimate {
    Estimate { value: f64::NAN, error: f64::INFINITY, evals: 0 }
}

/// Tolerance actually used: non-positive or NaN → [`DEFAULT_TOL`]; never below 1e-15.
fn clean_tol(tol: f64) -> f64 {
    if tol > 0.0 { tol.max(1e-15) } else { DEFAULT_TOL }
}

fn alpha_ok(alpha: f64) -> bool {
    alpha > 0.0 && alpha <= 1.0
}

/// The SGGX fiber phase function p(u, v) = D_F(h)/(4σ_F(u)) for unit vectors t, u, v.
///
/// At v = −u the half vector is undefined; the value returned there is the limit along the
/// specular cone (h ⟂ t), D_F = 1/(πα). Returns NaN for α outside (0, 1].
pub fn sggx_phase(alpha: f64, t: [f64; 3], u: [f64; 3], v: [f64; 3]) -> f64 {
    if !alpha_ok(alpha) {
        return f64::NAN;
    }
    let dot = |x: [f64; 3], y: [f64; 3]| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
    let h = [u[0] + v[0], u[1] + v[1], u[2] + v[2]];
    let hh = dot(h, h);
    let ht2 = if hh > 0.0 { dot(h, t).powi(2) / hh } else { 0.0 };
    let k2 = (1.0 - alpha) * (1.0 + alpha);
    let x = ht2 * k2 + alpha * alpha;
    let d = alpha * alpha * alpha / (PI * x * x);
    let ut = dot(u, t);
    let sigma = (1.0 - ut * ut * k2).max(0.0).sqrt();
    d / (4.0 * sigma)
}

// ---------------------------------------------------------------------------------------------
// Adaptive quadrature: `crate::integrate::integrate` with QUADPACK estimates.

/// Adaptive G10/K21 over [a, b] of a vector integrand, QUADPACK panel estimates weighted by
/// `ew` (components with ew[i] = 0 are integrated along, unchecked) to absolute `tol`:
/// (values, weighted error, evals). See [`Options::quadpack`].
fn gk21_adaptive<const N: usize>(
    a: f64,
    b: f64,
    tol: f64,
    ew: &[f64; N],
    f: impl FnMut(f64) -> [f64; N],
) -> ([f64; N], f64, u64) {
    let r = integrate(&[(a, b)], &Options::quadpack(*ew, tol, MAX_PANELS), f);
    (r.value, r.error, r.evals)
}

/// Per-(α, θf) constants. θf is folded into [0, π/2] using t ≡ −t (p depends on t only through
/// (·t)²); folding may turn the fiber azimuth by π, kept in `phi_shift`.
#[derive(Debug, Clone, Copy)]
struct Layer {
    alpha: f64,
    a2: f64,
    /// 1 − α².
    k2: f64,
    ct: f64,
    st: f64,
    phi_shift: f64,
}

/// One light direction in fiber coordinates.
#[derive(Debug, Clone, Copy)]
struct Light {
    /// u·t
    a: f64,
    /// sqrt(1 − a²)
    sa: f64,
    /// η_u, and sin, cos of η_u/2
    eta: f64,
    sh: f64,
    ch: f64,
    sigma: f64,
}

impl Layer {
    fn new(alpha: f64, theta_f: f64) -> Self {
        let (s, c) = theta_f.sin_cos();
        let sign = if c < 0.0 { -1.0 } else { 1.0 };
        let tx = sign * s;
        Layer {
            alpha,
            a2: alpha * alpha,
            k2: (1.0 - alpha) * (1.0 + alpha),
            ct: c.abs(),
            st: tx.abs(),
            phi_shift: if tx < 0.0 { PI } else { 0.0 },
        }
    }

    /// Folded θf ∈ [0, π/2].
    fn theta(&self) -> f64 {
        self.st.atan2(self.ct)
    }

    fn light(&self, theta_u: f64, phi_u: f64) -> Light {
        let (su, cu) = theta_u.sin_cos();
        let (sp, cp) = (phi_u - self.phi_shift).sin_cos();
        let a = self.st * su * cp + self.ct * cu;
        let u1 = self.ct * su * cp - self.st * cu;
        let u2 = su * sp;
        let sa = u1.hypot(u2);
        self.light_fiber(a.clamp(-1.0, 1.0), sa, u2.atan2(u1))
    }

    fn light_fiber(&self, a: f64, sa: f64, eta: f64) -> Light {
        let (sh, ch) = (0.5 * eta).sin_cos();
        // σ² = 1 − a²(1 − α²) = s_a² + α² a², without cancellation.
        let sigma = (sa * sa + self.a2 * a * a).sqrt();
        Light { a, sa, eta, sh, ch, sigma }
    }

    /// Width of the specular peak in w around −a.
    fn peak_scale(&self, sa: f64) -> f64 {
        if self.k2 <= 0.0 {
            return 4.0;
        }
        (2.0 * self.alpha * (self.k2 * sa * sa + self.a2).sqrt() / self.k2).clamp(1e-12, 4.0)
    }
}

mod atan;
mod grid;
mod layer;
mod ps;
mod r;
pub use grid::{fitting_directions, linspace, ps_grid, r_grid};
pub use layer::{e3, expn, g, g_exact, q, q_exact};
pub use ps::{ps, ps_directions};
pub use r::r;

#[cfg(test)]
mod r_horizon;

#[cfg(test)]
#[allow(clippy::needless_range_loop)]
pub(crate) mod tests {
    use super::*;
    use crate::integrate::{adaptive, Tolerance};
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn fiber_is_the_unit_vector_at_theta_f_from_the_normal() {
        // t = (sin θf, 0, cos θf): at θf = π/3, t·n = cos(π/3) = 1/2 and |t| = 1 (1e-15: one
        // rounding in sin, cos and the squares).
        let t = FuzzParams::new(0.5, std::f64::consts::FRAC_PI_3).fiber();
        assert!((t[2] - 0.5).abs() < 1e-15 && t[1] == 0.0, "{t:?}");
        assert!((t[0] * t[0] + t[1] * t[1] + t[2] * t[2] - 1.0).abs() < 1e-15, "{t:?}");
        assert!(t[0] > 0.0, "{t:?}");
    }

    /// The parameter set's methods are P_s and R at its own (α, θf), bit for bit: α ≠ θf, so
    /// the two swapped would differ (here α = 1.2 is outside P_s's domain altogether).
    #[test]
    fn fuzz_params_evaluate_at_their_own_alpha_and_theta_f() {
        let p = FuzzParams::new(0.5, 1.2);
        let same = |a: &Estimate, b: &Estimate| (a.value.to_bits(), a.error.to_bits()) == (b.value.to_bits(), b.error.to_bits());
        let one = ps(0.5, 1.2, 0.7, 0.4, 1e-6);
        assert!(one.value > 0.0 && same(&p.ps(0.7, 0.4, 1e-6), &one), "{one:?}");
        let dirs = [(0.7, 0.4), (1.1, 2.0)];
        let many = p.ps_directions(&dirs, 1e-6);
        assert_eq!(many.len(), 2);
        for (e, &(tu, pu)) in many.iter().zip(&dirs) {
            assert!(same(e, &ps(0.5, 1.2, tu, pu, 1e-6)), "{e:?} at ({tu}, {pu})");
        }
        let rr = r(0.5, 1.2, 1e-6);
        assert!(rr.value > 0.0 && same(&p.r(1e-6), &rr), "{rr:?}");
    }

    /// Factor on P_s's error estimate where it serves as a tolerance: the estimate is the
    /// panels' |K21 − G10| summed, and near grazing, where a cone breakpoint u·t = ±sin θf
    /// approaches the horizon, it was measured ~5x below the true error (tests/stress.rs,
    /// `ps_error_estimates_bound_the_jump_at_seams`, ignored, with the case); 10 leaves a
    /// factor 2 over that.
    pub(super) const PS_ESTIMATE_SLACK: f64 = 10.0;

    pub(super) fn sph(theta: f64, phi: f64) -> [f64; 3] {
        [theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()]
    }

    /// Deterministic uniform numbers in [0, 1) (64-bit LCG, top 53 bits).
    pub(super) struct Lcg(pub(super) u64);
    impl Lcg {
        pub(super) fn next(&mut self) -> f64 {
            self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// Independent brute force: ∫ f(v) dω_v over the sphere (or its lower half) by nested
    /// adaptive G10/K21 from `crate::integrate`, in polar coordinates (β, ψ) about −u. There
    /// the phase function is smooth at its one singular point v = −u (the pole), and for each ψ
    /// the lower half is an interval of β found in closed form. Shares no code with the
    /// reduction above except `sggx_phase`.
    pub(super) fn brute_force(u: [f64; 3], f: &dyn Fn([f64; 3]) -> f64, lower_only: bool, tol: f64) -> f64 {
        let e = [-u[0], -u[1], -u[2]];
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
        };
        let tmp = if e[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
        let c = cross(e, tmp);
        let n = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
        let b1 = [c[0] / n, c[1] / n, c[2] / n];
        let b2 = cross(e, b1);
        let tl = Tolerance { abs: tol, rel: 0.0, max_panels: 20000 };
        adaptive(0.0, 2.0 * PI, tl, |psi| {
            let (sp, cp) = psi.sin_cos();
            let d = [cp * b1[0] + sp * b2[0], cp * b1[1] + sp * b2[1], cp * b1[2] + sp * b2[2]];
            let g = |b: f64| {
                let (sb, cb) = b.sin_cos();
                f([cb * e[0] + sb * d[0], cb * e[1] + sb * d[1], cb * e[2] + sb * d[2]]) * sb
            };
            if !lower_only {
                return adaptive(0.0, PI, tl, g).value;
            }
            // v_z = e_z cos β + d_z sin β = C cos(β − β*) < 0 for β − β* ∈ (π/2, 3π/2) mod 2π.
            let bs = d[2].atan2(e[2]);
            let mut total = 0.0;
            for k in -2..=2 {
                let lo = (bs + 0.5 * PI + 2.0 * PI * k as f64).max(0.0);
                let hi = (bs + 1.5 * PI + 2.0 * PI * k as f64).min(PI);
                if hi > lo {
                    total += adaptive(lo, hi, tl, g).value;
                }
            }
            total
        })
        .value
    }

    /// (α, θf, θu, φu) cases for the brute-force checks: small α, θf = 0 and π/2, light along
    /// the fiber, near-grazing and below-horizon lights.
    pub(super) const CASES: [(f64, f64, f64, f64); 9] = [
        (0.05, 0.0, 0.3, 0.0),
        (0.05, 0.8, 1.0, 2.0),
        (0.15, 0.3, 0.4, 0.5),
        (0.15, 1.2, 1.55, 0.3),
        (0.3, FRAC_PI_2, 1.3, 0.2),
        (0.5, 0.7, 0.7, 0.0),
        (0.2, 0.7, 2.0, 1.0),
        (0.8, 0.1, 0.05, 3.0),
        (1.0, 0.3, 0.4, 0.5),
    ];

    #[test]
    fn phase_function_integrates_to_one() {
        // Brute force at 1e-11 per level: ≤ 2π·1e-11 + 1e-11 quadrature error, so 1e-9 bounds it.
        for &(al, tf, tu, pu) in &CASES {
            let (t, u) = (sph(tf, 0.0), sph(tu, pu));
            let total = brute_force(u, &|v| sggx_phase(al, t, u, v), false, 1e-11);
            assert!((total - 1.0).abs() < 1e-9, "α={al} θf={tf} θu={tu} φu={pu}: ∫p = {total}");
        }
    }

    #[test]
    fn convergence_study() {
        // Max |value(tol) − value(tight)| over fixed points, for tol = 1e-5 … 1e-9 (the
        // default): the actual error must fall with the tolerance and stay below it. The tight
        // references are 1e-13 (P_s) and 1e-12 (R), whose own errors are below 1e-12.
        // `cargo test --release --lib convergence_study -- --nocapture` prints the table.
        let mut rng = Lcg(29);
        let ps_points: Vec<[f64; 4]> = (0..60)
            .map(|i| {
                let tu = if i % 4 == 0 { (10f64.powf(-5.0 + 4.0 * rng.next())).acos() } else { FRAC_PI_2 * rng.next() };
                [0.15 + 0.85 * rng.next(), if i % 7 == 0 { 0.0 } else { FRAC_PI_2 * rng.next() }, tu, PI * rng.next()]
            })
            .collect();
        let r_points = [(0.15, 0.1), (0.35, 0.8), (0.6, 1.5), (0.9, 0.3)];
        let ps_ref: Vec<f64> = ps_points.iter().map(|p| ps(p[0], p[1], p[2], p[3], 1e-13).value).collect();
        let r_ref: Vec<f64> = r_points.iter().map(|&(a, t)| r(a, t, 1e-12).value).collect();
        println!("tolerance   P_s max |err|   P_s max estimate   R max |err|   R max estimate");
        for tol in [1e-5, 1e-6, 1e-7, 1e-8, DEFAULT_TOL] {
            let (mut pe, mut pest, mut re, mut rest) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
            for (p, t) in ps_points.iter().zip(&ps_ref) {
                let e = ps(p[0], p[1], p[2], p[3], tol);
                pe = pe.max((e.value - t).abs());
                pest = pest.max(e.error);
            }
            for (&(a, th), t) in r_points.iter().zip(&r_ref) {
                let e = r(a, th, tol);
                re = re.max((e.value - t).abs());
                rest = rest.max(e.error);
            }
            println!("{tol:9.0e}   {pe:13.2e}   {pest:16.2e}   {re:11.2e}   {rest:14.2e}");
            // Each actual error is below its requested tolerance (plus the reference's 1e-12).
            assert!(pe <= tol + 1e-12 && re <= tol + 1e-12, "tol {tol:e}: P_s {pe:e}, R {re:e}");
        }
        // G and Q: quadrature against the closed forms at the default tolerance.
        let mut ge = 0.0f64;
        for i in 0..=20 {
            for j in 1..=20 {
                let (d, mu) = (0.5 * i as f64 / 20.0, j as f64 / 20.0);
                ge = ge.max((g(d, mu, DEFAULT_TOL).value - g_exact(d, mu)).abs());
            }
        }
        let qe = (0..=50).map(|i| 0.5 * i as f64 / 50.0).map(|d| (q(d, DEFAULT_TOL).value - q_exact(d)).abs()).fold(0.0, f64::max);
        println!("default tolerance: G max |quadrature − closed form| {ge:.2e}, Q max |quadrature − 2E₃| {qe:.2e}");
        // Closed forms are accurate to ~1e-15 (1 + |ln d|) (see g_matches_closed_form_and_limits).
        assert!(ge <= DEFAULT_TOL && qe <= DEFAULT_TOL);
    }

    /// The tolerance a caller gives is the one used (module doc): a looser one takes fewer
    /// evaluations and still holds against 2E₃; zero, a negative one and NaN mean
    /// DEFAULT_TOL, value and evaluations alike; one below 1e-15 means 1e-15.
    #[test]
    fn tolerances_are_used_as_given_and_cleaned_as_documented() {
        let d = 0.3;
        let (loose, tight) = (q(d, 1e-4), q(d, 1e-12));
        assert!(loose.evals < tight.evals, "{loose:?} {tight:?}");
        // 4 ulps of Q ≈ 0.5 bound q_exact's rounding beside the tolerance itself.
        assert!((loose.value - q_exact(d)).abs() <= 1e-4 && (tight.value - q_exact(d)).abs() <= 1e-12 + 4.0 * f64::EPSILON);
        let dflt = q(d, DEFAULT_TOL);
        for tol in [0.0, -1.0, f64::NAN] {
            let e = q(d, tol);
            assert_eq!((e.value.to_bits(), e.evals), (dflt.value.to_bits(), dflt.evals), "tol {tol}");
        }
        let (tiny, floor) = (q(d, 1e-30), q(d, 1e-15));
        assert_eq!((tiny.value.to_bits(), tiny.evals), (floor.value.to_bits(), floor.evals));
    }

    // ---------------------------------------------------------------------------------------
    // Published constants (supplemental material, Appendices A, C, E, G), transcribed as printed.

    /// Listing 1: per i = 0..5, [t_i, p_i (13), q_i (13)].
    pub(crate) const PUB_PS: [[f64; 27]; 6] = [
        [
            0.13756974,
            0.089967924,
            -0.043263807,
            0.012549466,
            -0.039043481,
            -0.18738464,
            0.019518992,
            -0.14037448,
            -0.018000072,
            0.080983287,
            -0.12573283,
            0.030190086,
            0.082546164,
            -0.067284671,
            -1.4158549,
            -0.8067329,
            -0.18696706,
            0.85672806,
            0.73143116,
            0.15639405,
            -0.3532818,
            -0.57225366,
            -0.12095449,
            0.036308587,
            0.72092589,
            0.60578342,
            -0.58250484,
        ],
        [
            -2.7184817,
            -5.8696774,
            8.0163004,
            -3.1600727,
            3.8612209,
            -5.1905628,
            -5.0022991,
            10.047277,
            0.18762356,
            0.37025318,
            2.4688789,
            -2.4440128,
            -4.838545,
            8.5374892,
            -8.0595452,
            -17.180627,
            1.0716076,
            4.4852769,
            29.035032,
            9.6089763,
            -0.85605057,
            -2.6545399,
            -7.9458921,
            4.995542,
            5.0528634,
            0.037475838,
            -13.311191,
        ],
        [
            -0.78639883,
            1.5746798,
            2.48243,
            1.3541003,
            -0.95093934,
            -4.1094587,
            -2.463887,
            -1.4678292,
            0.051742457,
            2.3265071,
            -0.58747343,
            0.95003155,
            0.80560378,
            0.92021804,
            -0.62641789,
            -4.2275626,
            1.2757363,
            -0.20707868,
            3.8802392,
            2.9039937,
            -2.079426,
            -0.067985356,
            -0.73187572,
            0.13138015,
            0.3012767,
            1.0202816,
            -2.2280816,
        ],
        [
            -0.24041982,
            -0.13259461,
            -0.38462128,
            0.026466062,
            0.19445785,
            1.0051305,
            0.48317105,
            0.10568307,
            0.012401867,
            -0.44645249,
            0.22808668,
            -0.23192799,
            -0.19285076,
            -0.2408241,
            -1.5432125,
            -1.3051729,
            -0.056543476,
            0.90136729,
            0.4311222,
            1.6008327,
            0.11762443,
            -0.17825185,
            0.016131527,
            -0.11530679,
            -0.44470983,
            -0.074847149,
            -0.47874924,
        ],
        [
            0.24779292,
            1.7000882,
            -2.1202227,
            1.0560525,
            -1.8178813,
            1.2658071,
            2.3142857,
            -3.0859394,
            0.29918169,
            0.30209918,
            -0.33373112,
            0.11488872,
            1.8913286,
            -2.3312817,
            -10.140274,
            -14.579435,
            1.7571963,
            6.8424411,
            18.456914,
            18.485136,
            1.7617207,
            -0.36251123,
            -2.8078648,
            2.7987085,
            -3.2621689,
            -4.0289481,
            -13.375577,
        ],
        [
            -1.7111756,
            1.1697807,
            -1.3136888,
            0.29216331,
            -2.4200667,
            5.5264719,
            4.008041,
            -1.9572698,
            -0.0043264307,
            -2.5938981,
            1.3983587,
            0.29401827,
            2.7673798,
            -4.331847,
            19.422409,
            -3.7802382,
            5.591913,
            -17.588813,
            6.7184933,
            -19.919567,
            -18.57141,
            0.13662077,
            -3.5379282,
            -1.3720354,
            15.545388,
            14.697374,
            2.0091252,
        ],
    ];
    /// Listing 3 (G̃), Listing 4 (Q̃), Listing 5 (R̃: t, p (13), q (3)).
    pub(crate) const PUB_G: [f64; 4] = [-0.94634516, 0.41691235, 0.70663116, -0.26154413];
    pub(crate) const PUB_Q: [f64; 2] = [-1.7280754, 1.2661427];
    pub(crate) const PUB_R: [f64; 17] = [
        -0.26805773,
        0.30887989,
        0.077007705,
        -0.12175263,
        -0.14202922,
        0.7331539,
        0.010009714,
        -0.25925012,
        -0.023091515,
        -0.31883099,
        0.25857198,
        -0.0031055288,
        0.20038139,
        -0.28705017,
        -0.37659157,
        -0.44286302,
        -0.35584712,
    ];

    /// Outside the domain every entry point answers the invalid estimate (value NaN, error ∞,
    /// no evaluations) instead of a number: α ∉ (0, 1] (0, −0.5, the double just above 1, 1.5,
    /// NaN), a non-finite θf, θu or φu alone, and G, Q at a negative or NaN argument. Where the
    /// formulas would run on they give numbers or at least spend evaluations (at α = 0.5 a NaN
    /// angle leaves no piece and a finite error floor), so the three fields are all checked.
    /// In a batch an invalid direction does not spoil the valid ones beside it.
    #[test]
    fn inputs_outside_the_domain_give_the_invalid_estimate() {
        let invalid = |e: &Estimate| e.value.is_nan() && e.error == f64::INFINITY && e.evals == 0;
        let (t, u, v) = (sph(0.9, 0.0), sph(0.7, 0.4), sph(2.0, 1.0));
        for alpha in [0.0, -0.5, 1f64.next_up(), 1.5, f64::NAN] {
            assert!(sggx_phase(alpha, t, u, v).is_nan(), "p at α = {alpha}");
            assert!(invalid(&ps(alpha, 0.9, 0.7, 0.4, 1e-6)), "P_s at α = {alpha}");
            assert!(ps_directions(alpha, 0.9, &[(0.7, 0.4)], 1e-6).iter().all(invalid), "P_s batch at α = {alpha}");
            assert!(invalid(&r(alpha, 0.9, 1e-6)), "R at α = {alpha}");
        }
        // The smallest α is inside: a finite, positive phase function.
        assert!(sggx_phase(1e-3, t, u, v) > 0.0);
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            assert!(invalid(&ps(0.5, bad, 0.7, 0.4, 1e-6)), "θf {bad}");
            assert!(invalid(&ps(0.5, 0.9, bad, 0.4, 1e-6)), "θu {bad}");
            assert!(invalid(&ps(0.5, 0.9, 0.7, bad, 1e-6)), "φu {bad}");
            assert!(ps_directions(0.5, bad, &[(0.7, 0.4)], 1e-6).iter().all(invalid), "batch θf {bad}");
            assert!(invalid(&r(0.5, bad, 1e-6)), "R θf {bad}");
            let batch = ps_directions(0.5, 0.9, &[(bad, 0.4), (0.7, bad), (0.7, 0.4)], 1e-6);
            assert!(invalid(&batch[0]) && invalid(&batch[1]), "batch direction {bad}: {batch:?}");
            let one = ps(0.5, 0.9, 0.7, 0.4, 1e-6);
            assert_eq!(batch[2].value.to_bits(), one.value.to_bits(), "batch beside {bad}");
        }
        // (−0.1, 0) and (0, −0.5): the limits G(d, 0) = 1 and G(0, μv) = 0 hold only inside.
        for (d, mu_v) in [(-0.1, 0.5), (0.1, -0.5), (f64::NAN, 0.5), (0.1, f64::NAN), (-0.1, 0.0), (0.0, -0.5)] {
            assert!(invalid(&g(d, mu_v, 1e-9)), "G({d}, {mu_v})");
            assert!(g_exact(d, mu_v).is_nan(), "closed-form G({d}, {mu_v})");
        }
        for d in [-1.0, -1e-300, f64::NAN] {
            assert!(invalid(&q(d, 1e-9)), "Q({d})");
        }
    }

    /// At v = −u the half vector is undefined and the doc gives the limit along the specular
    /// cone, h ⟂ t: D_F = 1/(πα), so p = 1/(πα · 4σ_F(u)), σ_F(u) = sqrt(1 − (u·t)²(1 − α²)).
    /// By hand at α = 0.5, t = n, u·t = 0.8: σ_F = sqrt(1 − 0.64·0.75) = sqrt(0.52). Nearby
    /// backward directions on the cone (v·t = −u·t) have the same value. A few roundings: 1e-14
    /// relative.
    #[test]
    fn sggx_phase_at_the_backward_direction_is_its_specular_cone_limit() {
        let (alpha, t, u) = (0.5, [0.0, 0.0, 1.0], [0.6, 0.0, 0.8]);
        let want = 1.0 / (PI * alpha * 4.0 * 0.52f64.sqrt());
        let got = sggx_phase(alpha, t, u, [-0.6, 0.0, -0.8]);
        assert!((got - want).abs() <= 1e-14 * want, "p(u, −u) = {got}, limit {want}");
        // On the cone v·t = −0.8 a little way round from −u: h ⟂ t exactly.
        let near = sggx_phase(alpha, t, u, [-0.6 * 1e-4f64.cos(), -0.6 * 1e-4f64.sin(), -0.8]);
        assert!((near - want).abs() <= 1e-14 * want, "p next to −u = {near}, limit {want}");
    }

    /// `evals` counts integrand evaluations (module doc): every piece of P_s and every inner
    /// w-integration of R is an adaptive G10/K21 run of 21 evaluations per panel and 42 per
    /// bisection, so the counts are positive multiples of 21; the doc's orders (60–250 per P_s,
    /// ~10⁴ per R at the default tolerance) bound them within a factor 40 and 10; a tighter
    /// tolerance takes no fewer. Lights: ordinary, grazing, below the horizon; directions that
    /// coincide in a batch report the count of the one integration they share.
    #[test]
    fn ps_and_r_count_their_evaluations() {
        for &(al, tf, tu, pu) in &[(0.3, 0.9, 0.7, 0.4), (0.15, 1.2, 1.55, 0.3), (0.5, 0.3, 2.0, 1.0), (0.8, 0.0, 0.4, 0.0)] {
            let (loose, dflt) = (ps(al, tf, tu, pu, 1e-5), ps(al, tf, tu, pu, DEFAULT_TOL));
            for e in [&loose, &dflt] {
                assert!(e.evals >= 21 && e.evals % 21 == 0 && e.evals <= 10_000, "α={al} θf={tf} θu={tu} φu={pu}: {e:?}");
            }
            assert!(loose.evals <= dflt.evals, "{loose:?} {dflt:?}");
        }
        let batch = ps_directions(0.3, 0.9, &[(0.0, 0.0), (0.0, 1.0)], DEFAULT_TOL);
        assert!(batch[0].evals == batch[1].evals && batch[0].evals >= 21, "{batch:?}");
        for &(al, tf) in &[(0.3, 0.9), (0.15, 0.0), (0.6, FRAC_PI_2)] {
            let (loose, dflt) = (r(al, tf, 1e-6), r(al, tf, DEFAULT_TOL));
            for e in [&loose, &dflt] {
                assert!(e.evals >= 21 && e.evals % 21 == 0 && e.evals <= 100_000, "α={al} θf={tf}: {e:?}");
            }
            assert!(loose.evals <= dflt.evals, "{loose:?} {dflt:?}");
        }
    }
}
