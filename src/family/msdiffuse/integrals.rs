//! The multiple-scattering diffuse BRDF of Call of Duty: WWII ("Multiscattering Diffuse BRDF"):
//! a GGX microsurface whose microfacets are Lambertian reflectors, light walking between them
//! (Heitz, Hanika, d'Eon & Dachsbacher 2016, "Multiple-scattering microfacet BSDFs with the
//! Smith model"), Fresnel taking the specular share away from the diffuse.
//!
//! # The walk (Heitz et al. 2016, §4 and their reference implementation's diffuse microsurface)
//! - The Smith height model: a ray leaving height CDF u = C1(h) in direction ω (Λ = Λ(ω), with
//!   Λ(ω) = −1 − Λ(−ω) below the horizon) escapes with probability G1 = u^Λ when ω_z > 0, else
//!   meets the surface at u·(1 − ξ)^(−1/Λ); downward rays always meet it. The BSDF does not depend
//!   on the height distribution, so the walk works in u directly. A path starts above the
//!   surface (u = 1) along −l.
//! - At each meeting the microfacet normal m is drawn from the visible normals of the arriving
//!   direction (Heitz 2018's sampler, valid for arrivals from below the horizon too), and the
//!   facet scatters diffusely: the next direction is cosine-distributed about m.
//! - Next-event estimation toward v at each event: weight · ρ (1 − F(ωi·m)) (v·m)⁺/π (1 − F(v·m))
//!   · u^Λ(v). The sum over events estimates f(l, v)·(n·v); the family's quantities report
//!   π f/ρ at ρ = 1 (Lambert = 1).
//!
//! # Fresnel (F0 = 0.04 in the talk; Schlick's form)
//! Light crosses a facet's interface twice: in, where the share F(ωi·m) is reflected
//! specularly, and out toward the next direction ωo, where F(ωo·m) is reflected back. The
//! diffuse share of one event is ρ (1 − F(ωi·m))(1 − F(ωo·m)), symmetric in (ωi, ωo): the walk
//! stays reciprocal. The specular share F(ωi·m):
//! - `Specular::Gone` (the talk: "energy reflected specularly and unable to participate in
//!   diffuse reflectance"): it leaves the diffuse term. The default.
//! - `Specular::Walks`: it continues as a mirror reflection about m (chosen with probability F),
//!   and its later events count once the path has been diffused (the mirror next-event term
//!   D_ωi(h) F(ωi·h)/(4 |ωi·h|) · u^Λ(v), Heitz et al. 2016 Eq. 32, counts only then); light that
//!   only ever reflects specularly is the specular BRDF, not this one.
//! F0 = 0 makes the facets ideal Lambertian reflectors: with ρ = 1 nothing is absorbed and the
//! directional albedo is 1 (the white furnace).
//!
//! # Single scattering (the first event), in closed form up to one integral
//! The first meeting height has density (1 + Λl) u^Λl (start at u = 1), so E[u^Λv] = (1 + Λl)/(1
//! + Λl + Λv) and the visible-normal density ⟨l, m⟩ D(m)/((1 + Λl) l_z) gives
//!
//! ```text
//!   f₁(l, v) = ∫ D(m) ⟨l,m⟩ ⟨v,m⟩ (1 − F(l·m))(1 − F(v·m)) dm / (π l_z v_z (1 + Λl + Λv))
//! ```
//!
//! (Heitz 2015's Lambertian microfacets with the height-correlated G2). [`single_scattering`]
//! takes the integral in the GGX CDF variable ξ (tan²θm = α² ξ/(1 − ξ), D m_z dω = dξ dφ/2π) by the
//! adaptive engine, the azimuth on the arcs between the zeros of l·m and v·m by Gauss–Legendre
//! (smooth there). At l = v = n it is L(α)/π at F0 = 0, the gloss family's normal length.
//!
//! # Coordinates
//! Rusinkiewicz's (θh, θd, φd): h = (sin θh, 0, cos θh), the light at (θd, φd) about h, the view
//! its mirror image about h. φd = π/2 is the slice BRDF Explorer shows (its default). Gloss g
//! maps to α as in the gloss family: α = √(2/(1 + 2^(18 g))).
//!
//! # Estimates
//! A cell's paths are summed in chunks of [`CHUNK`] paths (each sequential, chunks combined in
//! their order), so the bits do not depend on threads or shards; every value carries its
//! standard error, √(sample variance/n).

use super::walk::{PathRng, Specular, Surface, fresnel, lambda_any};
use crate::shading::roughness::alpha_from_gloss;
use crate::integrate::{Estimate, Tolerance, adaptive, gauss_legendre};
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::OnceLock;

pub type V3 = [f64; 3];

/// Paths per chunk: the unit of summation (and of parallel work within one cell).
pub const CHUNK: u64 = 1024;

/// The talk's implicit F0.
pub const TALK_F0: f64 = 0.04;

/// The surface of the family's quantities: ρ = 1, GGX α from gloss.
pub fn surface(gloss: f64, f0: f64, specular: Specular) -> Surface {
    Surface { alpha: alpha_from_gloss(gloss), rho: 1.0, f0, specular }
}

/// (l, v) of Rusinkiewicz's (θh, θd, φd) with φh = 0, or None when either is at or below the
/// horizon.
pub fn directions(theta_h: f64, theta_d: f64, phi_d: f64) -> Option<(V3, V3)> {
    let (sh, ch) = theta_h.sin_cos();
    let (sd, cd) = theta_d.sin_cos();
    let (sp, cp) = phi_d.sin_cos();
    // d about h, then rotated by θh about y.
    let d = [sd * cp, sd * sp, cd];
    let l = [ch * d[0] + sh * d[2], d[1], -sh * d[0] + ch * d[2]];
    let h = [sh, 0.0, ch];
    let k = 2.0 * (l[0] * h[0] + l[1] * h[1] + l[2] * h[2]);
    let v = [k * h[0] - l[0], k * h[1] - l[1], k * h[2] - l[2]];
    (l[2] > 0.0 && v[2] > 0.0).then_some((l, v))
}

/// The direction at cosine `mu` in the x-z plane.
pub fn at_cosine(mu: f64) -> V3 {
    [(1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu]
}

/// Running sums of one estimate.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Sums {
    pub n: u64,
    pub s: f64,
    pub s2: f64,
}

impl Sums {
    pub fn add(&mut self, x: f64) {
        self.n += 1;
        self.s += x;
        self.s2 += x * x;
    }

    pub fn merge(&mut self, o: &Sums) {
        self.n += o.n;
        self.s += o.s;
        self.s2 += o.s2;
    }

    pub fn mean(&self) -> f64 {
        self.s / self.n.max(1) as f64
    }

    /// Standard error of the mean.
    pub fn se(&self) -> f64 {
        if self.n < 2 {
            return f64::INFINITY;
        }
        let n = self.n as f64;
        let var = ((self.s2 - self.s * self.s / n) / (n - 1.0)).max(0.0);
        (var / n).sqrt()
    }

    /// `scale`·mean with its standard error, `evals` = paths.
    pub fn estimate(&self, scale: f64) -> Estimate {
        Estimate { value: scale * self.mean(), error: scale.abs() * self.se(), evals: self.n }
    }
}

/// The sums of `paths` paths, by chunks of [`CHUNK`] (the last one shorter), each chunk by
/// `chunk`, chunks in parallel when `parallel`, combined in order.
pub fn chunked(paths: u64, parallel: bool, chunk: impl Fn(u64, u64) -> Sums + Sync) -> Sums {
    let chunks = paths.div_ceil(CHUNK).max(1);
    let run = |c: u64| chunk(c * CHUNK, ((c + 1) * CHUNK).min(paths));
    let parts: Vec<Sums> = if parallel { (0..chunks).into_par_iter().map(run).collect() } else { (0..chunks).map(run).collect() };
    let mut total = Sums::default();
    for p in &parts {
        total.merge(p);
    }
    total
}

/// What a BRDF cell estimates: the full walk, or its first event only.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Order {
    All,
    Single,
}

/// π f(l, v)/ρ by `paths` paths keyed by (key, cell): the walk's next-event sums over n·v.
pub fn brdf(s: &Surface, l: V3, v: V3, order: Order, key: u64, cell: u64, paths: u64, parallel: bool) -> Estimate {
    let sums = chunked(paths, parallel, |a, b| {
        let mut t = Sums::default();
        for i in a..b {
            let mut rng = PathRng::for_path(key, cell, i);
            let r = s.path(l, Some(v), &mut rng);
            t.add(match order {
                Order::All => r.nee,
                Order::Single => r.nee_single,
            });
        }
        t
    });
    sums.estimate(PI / (s.rho * v[2]))
}

/// The directional albedo at view v (light leaving toward any direction): the weights of the
/// paths as they leave the surface.
pub fn albedo(s: &Surface, v: V3, key: u64, cell: u64, paths: u64, parallel: bool) -> Estimate {
    let sums = chunked(paths, parallel, |a, b| {
        let mut t = Sums::default();
        for i in a..b {
            let mut rng = PathRng::for_path(key, cell, i);
            t.add(s.path(v, None, &mut rng).escaped);
        }
        t
    });
    sums.estimate(1.0)
}

/// The directional albedo through the next-event estimates instead: each path draws its own
/// exit direction o cosine-distributed over the hemisphere and scores nee(o)·π/o_z, whose mean is
/// ∫ f cos θo dωo. Independent of the escape weights: the white-furnace test compares them.
pub fn albedo_by_next_events(s: &Surface, v: V3, key: u64, cell: u64, paths: u64, parallel: bool) -> Estimate {
    let sums = chunked(paths, parallel, |a, b| {
        let mut t = Sums::default();
        for i in a..b {
            let mut rng = PathRng::for_path(key, cell, i);
            let (u1, u2) = (rng.next_f64(), rng.next_f64());
            let r = u1.sqrt();
            let (sp, cp) = (2.0 * PI * u2).sin_cos();
            let oz = (1.0 - u1).sqrt();
            if oz <= 0.0 {
                t.add(0.0);
                continue;
            }
            let o = [r * cp, r * sp, oz];
            t.add(s.path(v, Some(o), &mut rng).nee * PI / oz);
        }
        t
    });
    sums.estimate(1.0)
}

/// π f₁(l, v) (see the module doc), the single-scattering term, to an absolute tolerance.
pub fn single_scattering(alpha: f64, f0: f64, l: V3, v: V3, tol: f64) -> Estimate {
    if l[2] <= 0.0 || v[2] <= 0.0 {
        return Estimate::exact(0.0);
    }
    static GL: OnceLock<(Vec<f64>, Vec<f64>)> = OnceLock::new();
    let (gx, gw) = GL.get_or_init(|| gauss_legendre(24));
    let phase = |w: V3| w[1].atan2(w[0]);
    let a2 = alpha * alpha;
    let inner = |xi: f64| -> f64 {
        if xi >= 1.0 {
            return 0.0;
        }
        let t2 = a2 * xi / (1.0 - xi);
        let cm = 1.0 / (1.0 + t2).sqrt();
        let sm = cm * t2.sqrt();
        // l·m = A cos(φ − φl) + B: its zeros.
        let mut cuts = vec![-PI, PI];
        for w in [l, v] {
            let a = sm * (w[0] * w[0] + w[1] * w[1]).sqrt();
            let b = cm * w[2];
            if a > b.abs() {
                let d = (-b / a).acos();
                for p in [phase(w) + d, phase(w) - d] {
                    cuts.push((p + PI).rem_euclid(2.0 * PI) - PI);
                }
            }
        }
        cuts.sort_by(f64::total_cmp);
        let f = |phi: f64| {
            let (sp, cp) = phi.sin_cos();
            let m = [sm * cp, sm * sp, cm];
            let cl = l[0] * m[0] + l[1] * m[1] + l[2] * m[2];
            let cv = v[0] * m[0] + v[1] * m[1] + v[2] * m[2];
            if cl <= 0.0 || cv <= 0.0 {
                return 0.0;
            }
            cl * cv * (1.0 - fresnel(f0, cl)) * (1.0 - fresnel(f0, cv)) / cm
        };
        let mut sum = 0.0;
        for w in cuts.windows(2) {
            let (lo, hi) = (w[0], w[1]);
            if hi <= lo {
                continue;
            }
            let (c, r) = (0.5 * (lo + hi), 0.5 * (hi - lo));
            sum += r * gx.iter().zip(gw).map(|(x, wt)| wt * f(c + r * x)).sum::<f64>();
        }
        sum / (2.0 * PI)
    };
    let e = adaptive(0.0, 1.0, Tolerance { abs: tol, rel: 0.0, max_panels: 4000 }, inner);
    let g = 1.0 / (1.0 + lambda_any(alpha, l[2]) + lambda_any(alpha, v[2]));
    let scale = g / (l[2] * v[2]);
    Estimate { value: e.value * scale, error: e.error * scale, evals: e.evals }
}

/// Paths of `eval` at tolerance `tol`: (1/tol)², within [CHUNK, 2^20] (eval asks 1e-12: 2^20).
pub fn eval_paths(tol: f64) -> u64 {
    let want = (1.0 / tol.max(1e-300)).powi(2);
    if want >= (1u64 << 20) as f64 { 1 << 20 } else { (want.ceil() as u64).max(CHUNK) }
}

/// The specular convention from the quantities' `specular_walks` flag.
pub fn specular_of(flag: f64) -> Specular {
    if flag >= 0.5 { Specular::Walks } else { Specular::Gone }
}

/// The cell number of a quantity point: a hash of its parameters' bits.
pub fn cell_of(p: &[f64]) -> u64 {
    p.iter().fold(0x5151_u64, |h, x| super::walk::mix64(h ^ x.to_bits()))
}

#[cfg(test)]
mod tests {
    use super::*;

    const KEY: u64 = 0x5eed;

    /// The sums' mean and standard error against the textbook ones of a small sample: 1, 2, 3,
    /// 4 has mean 5/2, sample variance Σ(x − 5/2)²/3 = 5/3 and standard error sqrt(5/3/4) =
    /// sqrt(5/12); merged from two halves, the same; scaled by −2, value −5 and error
    /// 2·sqrt(5/12). One or no sample has no standard error (infinite). Exact sums of small
    /// integers, then a few roundings: 1e-15.
    #[test]
    fn sums_give_the_sample_mean_and_its_standard_error() {
        let mut all = Sums::default();
        let (mut a, mut b) = (Sums::default(), Sums::default());
        for (i, x) in [1.0, 2.0, 3.0, 4.0].into_iter().enumerate() {
            all.add(x);
            if i < 2 { a.add(x) } else { b.add(x) }
        }
        a.merge(&b);
        for s in [all, a] {
            assert_eq!((s.n, s.mean()), (4, 2.5));
            assert!((s.se() - (5.0f64 / 12.0).sqrt()).abs() <= 1e-15, "{}", s.se());
        }
        let e = all.estimate(-2.0);
        assert_eq!((e.value, e.evals), (-5.0, 4));
        assert!((e.error - 2.0 * (5.0f64 / 12.0).sqrt()).abs() <= 1e-15, "{}", e.error);
        let mut one = Sums::default();
        one.add(3.0);
        assert_eq!((one.mean(), one.se()), (3.0, f64::INFINITY));
        assert_eq!((Sums::default().mean(), Sums::default().se()), (0.0, f64::INFINITY));
    }

    /// The paths of `eval` at a tolerance, by hand: (1/tol)² rounded up, at least one chunk and
    /// at most 2^20 (a tolerance of 0, of 2^-10 or less, or NaN asks the most).
    #[test]
    fn eval_paths_are_the_inverse_square_of_the_tolerance_within_their_bounds() {
        assert_eq!(eval_paths(0.1), CHUNK); // 100 paths: one chunk of 1024
        assert_eq!(eval_paths(0.03), 1112); // 1111.1…, rounded up
        assert_eq!(eval_paths(1e-2), 10_000);
        assert_eq!(eval_paths(2e-3), 250_000);
        assert_eq!(eval_paths(1e-3), 1_000_000); // below 2^20 = 1 048 576
        for tol in [9.7e-4, 1e-12, 0.0, f64::NAN] {
            assert_eq!(eval_paths(tol), 1 << 20, "{tol}");
        }
    }

    /// The `specular_walks` flag: at or above ½ the light reflected by a facet walks on, below
    /// it is gone; the cell of a point hashes its parameters' bits, in order.
    #[test]
    fn the_flag_picks_the_convention_and_cells_follow_the_bits() {
        for (flag, want) in [(1.0, Specular::Walks), (0.5, Specular::Walks), (0.49, Specular::Gone), (0.0, Specular::Gone)] {
            assert_eq!(specular_of(flag), want, "{flag}");
        }
        let p = [0.3, 0.7, 1.0];
        assert_eq!(cell_of(&p), cell_of(&[0.3, 0.7, 1.0]));
        for other in [[0.7, 0.3, 1.0], [0.3, 0.7, f64::from_bits(1.0f64.to_bits() + 1)], [0.3, -0.0, 1.0], [0.3, 0.0, 1.0]] {
            assert_ne!(cell_of(&p), cell_of(&other), "{other:?}");
        }
        assert_ne!(cell_of(&[0.0]), cell_of(&[-0.0]));
        assert_ne!(cell_of(&[0.3]), cell_of(&[0.3, 0.0]));
    }

    #[test]
    fn directions_are_mirror_images_about_the_half_vector() {
        let (l, v) = directions(0.3, 0.7, 1.1).unwrap();
        let h = [0.3f64.sin(), 0.0, 0.3f64.cos()];
        let s = [l[0] + v[0], l[1] + v[1], l[2] + v[2]];
        let n = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
        for k in 0..3 {
            // f64 rounding of a few trig products.
            assert!((s[k] / n - h[k]).abs() < 1e-14);
        }
        let cd = l[0] * h[0] + l[1] * h[1] + l[2] * h[2];
        assert!((cd - 0.7f64.cos()).abs() < 1e-14);
        assert!(directions(1.2, 1.2, 0.0).is_none());
    }

    #[test]
    fn single_scattering_at_normal_incidence_is_the_normal_length() {
        // l = v = n, F0 = 0: ∫ D m_z² dm = L(α), GGX's average normal length in closed form
        // (COD: WWII): L = (1 − α² atanh(√k)/√k)/k, k = 1 − α², and L = 2/3 at α = 1; Λ(n) = 0.
        let normal_length = |a: f64| {
            let k = 1.0 - a * a;
            if k == 0.0 { 2.0 / 3.0 } else { (1.0 - a * a * k.sqrt().atanh() / k.sqrt()) / k }
        };
        for g in [0.0, 0.3, 0.6] {
            let a = alpha_from_gloss(g);
            let e = single_scattering(a, 0.0, [0.0, 0.0, 1.0], [0.0, 0.0, 1.0], 1e-11);
            // The adaptive tolerance 1e-11 and its estimate bound the quadrature; the closed
            // form at k ≥ 0.5 loses a few roundings of 1 (1e-15).
            assert!((e.value - normal_length(a)).abs() < 1e-9, "g {g}: {} vs {}", e.value, normal_length(a));
        }
    }

    #[test]
    fn single_scattering_quadrature_agrees_with_a_product_rule() {
        // Independent: a 2000 × 2000 midpoint rule in (θm, φm) over the upper hemisphere with
        // D(m) directly (no change of variables, no breakpoints): the kinks at l·m = 0 and
        // v·m = 0 cost O(h²) per cell crossing them; measured agreement ≲ 1e-6.
        let a = 0.6;
        let (l, v) = directions(0.4, 0.9, 2.0).unwrap();
        let e = single_scattering(a, TALK_F0, l, v, 1e-10).value;
        let n = 2000;
        let mut s = 0.0;
        for i in 0..n {
            let th = (i as f64 + 0.5) / n as f64 * PI / 2.0;
            let (st, ct) = th.sin_cos();
            let t = 1.0 + (a * a - 1.0) * ct * ct;
            let d = a * a / (PI * t * t);
            for j in 0..n {
                let ph = (j as f64 + 0.5) / n as f64 * 2.0 * PI;
                let m = [st * ph.cos(), st * ph.sin(), ct];
                let cl = l[0] * m[0] + l[1] * m[1] + l[2] * m[2];
                let cv = v[0] * m[0] + v[1] * m[1] + v[2] * m[2];
                if cl > 0.0 && cv > 0.0 {
                    s += d * cl * cv * (1.0 - fresnel(TALK_F0, cl)) * (1.0 - fresnel(TALK_F0, cv)) * st;
                }
            }
        }
        s *= (PI / 2.0 / n as f64) * (2.0 * PI / n as f64);
        let g = 1.0 / (1.0 + lambda_any(a, l[2]) + lambda_any(a, v[2]));
        let product = s * g / (l[2] * v[2]);
        assert!((e - product).abs() < 1e-5, "{e} vs {product}");
    }

    #[test]
    fn first_events_of_the_walk_are_the_analytic_single_scattering() {
        // The walk's order-1 next-event estimate against f₁ by quadrature: within 4 standard
        // errors (2^17 paths, seed fixed) plus the quadrature tolerance.
        for (g, th, td, pd) in [(0.0, 0.3, 0.8, 1.0), (0.0, 0.9, 0.2, 0.0), (0.4, 0.1, 1.2, 2.5), (0.7, 0.05, 0.5, 1.57)] {
            let s = surface(g, TALK_F0, Specular::Gone);
            let (l, v) = directions(th, td, pd).unwrap();
            let mc = brdf(&s, l, v, Order::Single, KEY, 1, 1 << 17, true);
            let exact = single_scattering(s.alpha, TALK_F0, l, v, 1e-10).value;
            assert!((mc.value - exact).abs() < 4.0 * mc.error + 1e-9, "g {g} ({th}, {td}, {pd}): {} ± {} vs {exact}", mc.value, mc.error);
        }
    }

    #[test]
    fn white_furnace_albedo_is_one() {
        // ρ = 1, F0 = 0: nothing is absorbed. The escape weights are all exactly 1 (every path
        // leaves: none is cut at MAX_ORDER), and the next-event estimate integrated over the
        // hemisphere (independent of the escape bookkeeping) is 1 within 4 standard errors
        // (2^16 paths per point, seed fixed).
        for g in [0.0, 0.25, 0.5, 1.0] {
            let s = surface(g, 0.0, Specular::Gone);
            for mu in [1.0, 0.7, 0.3, 0.05] {
                let v = at_cosine(mu);
                let e = albedo(&s, v, KEY, 2, 1 << 14, true);
                assert_eq!((e.value, e.error), (1.0, 0.0), "g {g} mu {mu}");
                let n = albedo_by_next_events(&s, v, KEY, 3, 1 << 16, true);
                println!("furnace g {g} n·v {mu}: escape {} ; next events {:.5} ± {:.5}", e.value, n.value, n.error);
                assert!((n.value - 1.0).abs() < 4.0 * n.error, "g {g} mu {mu}: {} ± {}", n.value, n.error);
            }
        }
    }

    #[test]
    fn both_albedo_estimators_agree_with_fresnel() {
        // F0 = 0.04, both conventions: the escape weights and the integrated next events
        // estimate the same albedo; within 4 combined standard errors (seeds fixed).
        for spec in [Specular::Gone, Specular::Walks] {
            for (g, mu) in [(0.0, 0.5), (0.5, 0.9), (0.8, 0.2)] {
                let s = surface(g, TALK_F0, spec);
                let v = at_cosine(mu);
                let a = albedo(&s, v, KEY, 4, 1 << 15, true);
                let b = albedo_by_next_events(&s, v, KEY, 5, 1 << 16, true);
                assert!(a.value < 1.0 - 0.03, "Fresnel removes at least F0-ish: {}", a.value);
                let k = 4.0 * (a.error.powi(2) + b.error.powi(2)).sqrt();
                assert!((a.value - b.value).abs() < k, "{spec:?} g {g} mu {mu}: {} ± {} vs {} ± {}", a.value, a.error, b.value, b.error);
            }
        }
    }

    #[test]
    fn walk_is_reciprocal() {
        // f(l, v) = f(v, l): two independent estimates (different keys) agree within 4
        // combined standard errors, at asymmetric pairs, both conventions, F0 = 0.04.
        let pairs: [(f64, f64, f64, f64); 4] = [(0.0, 1.2, 0.3, 0.0), (0.0, 0.6, 1.3, 2.0), (0.5, 1.0, 0.2, 1.0), (0.3, 1.45, 0.4, 3.0)];
        for spec in [Specular::Gone, Specular::Walks] {
            for (g, tl, tv, phi) in pairs {
                let s = surface(g, TALK_F0, spec);
                let l = [tl.sin(), 0.0, tl.cos()];
                let v = [tv.sin() * f64::cos(phi), tv.sin() * f64::sin(phi), tv.cos()];
                let a = brdf(&s, l, v, Order::All, 21, 0, 1 << 16, true);
                let b = brdf(&s, v, l, Order::All, 22, 0, 1 << 16, true);
                println!("reciprocity {spec:?} g {g} θl {tl} θv {tv} φ {phi}: {:.5} ± {:.5} vs {:.5} ± {:.5}", a.value, a.error, b.value, b.error);
                let k = 4.0 * (a.error.powi(2) + b.error.powi(2)).sqrt();
                assert!((a.value - b.value).abs() < k, "{spec:?} g {g}: {} ± {} vs {} ± {}", a.value, a.error, b.value, b.error);
            }
        }
    }

    #[test]
    fn smooth_limit_is_the_lambertian_plane() {
        // α = 1e-5: facets are the plane; one event, π f/ρ = (1 − F(n·l))(1 − F(n·v)) (F0 = 0.04)
        // and 1 (F0 = 0). Second events need tan θ > 1/α (probability ~1e-10): within 4 standard
        // errors plus 1e-6 (the O(α²) slope spread).
        for f0 in [0.0, TALK_F0] {
            let s = Surface { alpha: 1e-5, rho: 1.0, f0, specular: Specular::Gone };
            for (tl, tv) in [(0.0, 0.0), (0.5, 1.0), (1.3, 0.2)] {
                let l = at_cosine(f64::cos(tl));
                let v = [-f64::sin(tv), 0.0, f64::cos(tv)];
                let e = brdf(&s, l, v, Order::All, 23, 0, 1 << 12, true);
                let want = (1.0 - fresnel(f0, l[2])) * (1.0 - fresnel(f0, v[2]));
                assert!((e.value - want).abs() < 4.0 * e.error + 1e-6, "f0 {f0} ({tl}, {tv}): {} ± {} vs {want}", e.value, e.error);
            }
        }
    }

    #[test]
    fn estimates_do_not_depend_on_threads() {
        let s = surface(0.2, TALK_F0, Specular::Gone);
        let (l, v) = directions(0.5, 0.7, 1.0).unwrap();
        let seq = brdf(&s, l, v, Order::All, 5, 9, 8 * CHUNK, false);
        let pool = rayon::ThreadPoolBuilder::new().num_threads(3).build().unwrap();
        let par = pool.install(|| brdf(&s, l, v, Order::All, 5, 9, 8 * CHUNK, true));
        assert_eq!(seq.value.to_bits(), par.value.to_bits());
        assert_eq!(seq.error.to_bits(), par.error.to_bits());
    }

    /// Rusinkiewicz's coordinates by their definition: h = (sin θh, 0, cos θh); in the frame
    /// (t, b, h) about it, t = (cos θh, 0, −sin θh) (x turned by θh about y) and b = y, the
    /// light is d = (sin θd cos φd, sin θd sin φd, cos θd) and the view its mirror image about h,
    /// (−d_t, −d_b, d_h); both unit. The mirror test above reads only l·h and the direction of
    /// l + v, which do not see d's azimuth nor the length of v. And a point by hand: θh = 0,
    /// θd = π/3, φd = π/2 gives l = (0, √3/2, ½), v = (0, −√3/2, ½). Products of a few
    /// rounded sines and cosines: 1e-15.
    #[test]
    fn directions_are_rusinkiewiczs_coordinates() {
        for (th, td, pd) in [(0.3, 0.7, 1.1), (0.9, 0.4, 2.8), (0.2, 1.1, 0.4), (1.2, 0.1, 3.0), (0.6, 0.6, 0.0)] {
            let (l, v) = directions(th, td, pd).unwrap();
            let (t, b, h) = ([th.cos(), 0.0, -th.sin()], [0.0, 1.0, 0.0], [th.sin(), 0.0, th.cos()]);
            let dot = |a: V3, c: V3| a[0] * c[0] + a[1] * c[1] + a[2] * c[2];
            let d = [td.sin() * pd.cos(), td.sin() * pd.sin(), td.cos()];
            for (what, got, want) in [
                ("l·t", dot(l, t), d[0]),
                ("l·b", dot(l, b), d[1]),
                ("l·h", dot(l, h), d[2]),
                ("v·t", dot(v, t), -d[0]),
                ("v·b", dot(v, b), -d[1]),
                ("v·h", dot(v, h), d[2]),
                ("|l|²", dot(l, l), 1.0),
                ("|v|²", dot(v, v), 1.0),
            ] {
                assert!((got - want).abs() < 1e-15, "({th}, {td}, {pd}): {what} = {got}, want {want}");
            }
        }
        let (l, v) = directions(0.0, PI / 3.0, PI / 2.0).unwrap();
        let r3 = 3.0f64.sqrt() / 2.0;
        for (got, want) in l.iter().chain(&v).zip([0.0, r3, 0.5, 0.0, -r3, 0.5]) {
            assert!((got - want).abs() < 1e-15, "{l:?} {v:?}");
        }
    }

    /// The direction at cosine μ in the x–z plane, by hand: (0.8, 0, 0.6) at μ = 0.6 (3-4-5:
    /// a rounding of 0.36 and of its root), the normal at μ = 1, and a cosine past 1 keeps its
    /// z with no x (the clamp of 1 − μ²).
    #[test]
    fn at_cosine_by_hand() {
        let a = at_cosine(0.6);
        assert!((a[0] - 0.8).abs() < 1e-15 && a[1] == 0.0 && a[2] == 0.6, "{a:?}");
        assert_eq!(at_cosine(1.0), [0.0, 0.0, 1.0]);
        assert_eq!(at_cosine(1.0 + 1e-12), [0.0, 0.0, 1.0 + 1e-12]);
    }

    /// Two samples are the fewest with a standard error: 1 and 3 have mean 2, sample variance
    /// ((1 − 2)² + (3 − 2)²)/1 = 2 and standard error √(2/2) = 1, exactly in f64.
    #[test]
    fn two_samples_have_a_standard_error() {
        let mut s = Sums::default();
        s.add(1.0);
        s.add(3.0);
        assert_eq!((s.mean(), s.se()), (2.0, 1.0));
    }

    /// `chunked` hands each path index to exactly one chunk: [0, 1024), [1024, 2048), … with
    /// the last one shorter (a single empty chunk for no paths), listed here by hand. Every
    /// chunk sums its indices, so the total holds n = paths, Σ i = P(P − 1)/2 and Σ i² =
    /// (P − 1)P(2P − 1)/6 (integers below 2^53: exact), sequential and parallel.
    #[test]
    fn chunks_cover_every_path_once() {
        let cases: [(u64, &[(u64, u64)]); 6] = [
            (0, &[(0, 0)]),
            (1, &[(0, 1)]),
            (1023, &[(0, 1023)]),
            (1024, &[(0, 1024)]),
            (1025, &[(0, 1024), (1024, 1025)]),
            (3000, &[(0, 1024), (1024, 2048), (2048, 3000)]),
        ];
        for (paths, want) in cases {
            for parallel in [false, true] {
                let seen = std::sync::Mutex::new(Vec::new());
                let sums = chunked(paths, parallel, |a, b| {
                    seen.lock().unwrap().push((a, b));
                    let mut t = Sums::default();
                    for i in a..b {
                        t.add(i as f64);
                    }
                    t
                });
                let mut ranges = seen.into_inner().unwrap();
                ranges.sort();
                assert_eq!(ranges, want, "{paths} paths, parallel {parallel}");
                let p = paths as f64;
                let hand = Sums { n: paths, s: p * (p - 1.0) / 2.0, s2: (p - 1.0) * p * (2.0 * p - 1.0) / 6.0 };
                assert_eq!(sums, hand, "{paths} paths, parallel {parallel}");
            }
        }
    }

    /// The BRDF is zero unless both directions are above the horizon, whichever of the two is
    /// not (and on it: cos θ = 0).
    #[test]
    fn single_scattering_vanishes_unless_both_directions_are_above() {
        let (up, down, flat) = (at_cosine(0.6), [0.8, 0.0, -0.6], [1.0, 0.0, 0.0]);
        for (l, v) in [(up, down), (down, up), (up, flat), (flat, up), (down, down)] {
            assert_eq!(single_scattering(0.5, TALK_F0, l, v, 1e-8).value, 0.0, "l {l:?} v {v:?}");
        }
    }

    /// At F0 = 0.5 half the light a facet meets at normal incidence is mirrored, so in the
    /// walking convention the mirror events carry much of what a diffused path does next: the
    /// escape weights and the next events (diffuse and mirror terms) must still estimate the
    /// same albedo, within 4 combined standard errors (seeds fixed). At F0 = 0.04 the mirror
    /// share is too small for this balance to see a wrong mirror term.
    #[test]
    fn strong_fresnel_walks_keep_the_albedo_balance() {
        for (g, mu) in [(0.0, 0.4), (0.3, 0.8)] {
            let s = surface(g, 0.5, Specular::Walks);
            let v = at_cosine(mu);
            let a = albedo(&s, v, KEY, 6, 1 << 15, true);
            let b = albedo_by_next_events(&s, v, KEY, 7, 1 << 16, true);
            let k = 4.0 * (a.error.powi(2) + b.error.powi(2)).sqrt();
            assert!((a.value - b.value).abs() < k, "g {g} mu {mu}: {} ± {} vs {} ± {}", a.value, a.error, b.value, b.error);
        }
    }

    /// The smooth limit (α = 1e-5: one event, see `smooth_limit_is_the_lambertian_plane`) with
    /// absorption and Fresnel. At ρ = ½ the BRDF π f/ρ is still (1 − F(n·l))(1 − F(n·v)) (the
    /// estimate divides by ρ; within 4 standard errors plus 1e-6), and at F0 = 0 every path
    /// leaves with the weight ρ = ½ exactly (albedo ½, error 0). By the next events, at ρ = 1
    /// and F0 = 0.04, the albedo is (1 − F(n·v))·2∫(1 − F(μ))μ dμ = (1 − F(n·v))(1 − F0)(1 −
    /// 2/42) (∫(1 − μ)⁵μ dμ = B(2, 6) = 1/42), within 4 standard errors plus 1e-6.
    #[test]
    fn smooth_limit_with_absorption_and_fresnel() {
        let plane = |rho, f0| Surface { alpha: 1e-5, rho, f0, specular: Specular::Gone };
        for (tl, tv) in [(0.5, 1.0), (1.3, 0.2)] {
            let (l, v) = (at_cosine(f64::cos(tl)), [-f64::sin(tv), 0.0, f64::cos(tv)]);
            let e = brdf(&plane(0.5, TALK_F0), l, v, Order::All, 24, 0, 1 << 12, true);
            let want = (1.0 - fresnel(TALK_F0, l[2])) * (1.0 - fresnel(TALK_F0, v[2]));
            assert!((e.value - want).abs() < 4.0 * e.error + 1e-6, "({tl}, {tv}): {} ± {} vs {want}", e.value, e.error);
        }
        for mu in [0.9, 0.3] {
            let e = albedo(&plane(0.5, 0.0), at_cosine(mu), KEY, 8, 1 << 12, true);
            assert_eq!((e.value, e.error), (0.5, 0.0), "mu {mu}");
            let n = albedo_by_next_events(&plane(1.0, TALK_F0), at_cosine(mu), KEY, 9, 1 << 16, true);
            let want = (1.0 - fresnel(TALK_F0, mu)) * (1.0 - TALK_F0) * (1.0 - 2.0 / 42.0);
            assert!((n.value - want).abs() < 4.0 * n.error + 1e-6, "mu {mu}: {} ± {} vs {want}", n.value, n.error);
        }
    }
}
