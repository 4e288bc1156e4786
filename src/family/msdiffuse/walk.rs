//! The counter-based random numbers and the random walk on the microsurface (see the module
//! doc of `super::integrals` for the model and its conventions).
//!
//! Random numbers: the draws of path `s` of cell `c` under key `k` come from a SplitMix64
//! sequence (Steele, Lea & Flood 2014, the `java.util.SplittableRandom` finaliser) started at a
//! seed that hashes (k, c, s) with the same finaliser. The bits of a path depend on nothing but
//! those three numbers: not on the thread, the shard or the order in which paths run.

use crate::shading::trowbridge_reitz::{self, lambda};
use std::f64::consts::PI;

type V3 = [f64; 3];

pub use crate::integrate::rng::mix64;

/// The random numbers of one path: SplitMix64 from a seed hashed from (key, cell, sample)
/// (`SplitMix64::for_path`; draws by `next_f64`).
pub use crate::integrate::rng::SplitMix64 as PathRng;

/// A 64-bit key from a text (FNV-1a, then the finaliser): spec names, quantity names.
pub fn key_of(text: &str) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in text.as_bytes() {
        h ^= *b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    mix64(h)
}

#[inline]
fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
fn normalize(a: V3) -> V3 {
    let l = dot(a, a).sqrt();
    [a[0] / l, a[1] / l, a[2] / l]
}

#[inline]
fn cross(a: V3, b: V3) -> V3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// An orthonormal basis (t, b) about the unit vector n (Duff et al. 2017, "Building an
/// orthonormal basis, revisited").
#[inline]
fn basis(n: V3) -> (V3, V3) {
    let sign = 1f64.copysign(n[2]);
    let a = -1.0 / (sign + n[2]);
    let b = n[0] * n[1] * a;
    ([1.0 + sign * n[0] * n[0] * a, sign * b, -sign * n[0]], [b, sign + n[1] * n[1] * a, -n[1]])
}

/// Smith Λ of GGX for any direction: Λ(ω) for ω_z > 0 (`shading::trowbridge_reitz::lambda`), and
/// Λ(ω) = −1 − Λ(−ω) below the horizon (Heitz et al. 2016, §4.1). Infinite at ω_z = 0.
#[inline]
pub fn lambda_any(alpha: f64, wz: f64) -> f64 {
    if wz > 0.0 {
        lambda(alpha, wz.min(1.0))
    } else {
        -1.0 - lambda(alpha, (-wz).min(1.0))
    }
}

/// A GGX visible normal for the direction `wi` (pointing away from the surface; any
/// hemisphere): Heitz 2018, "Sampling the GGX Distribution of Visible Normals" (JCGT 7(4)),
/// isotropic α. The map from the disk covers the projected visible hemisphere for views below
/// the horizon too (its lower boundary t₂ = (1 − 2s)√(1 − t₁²) = −ω_z √(1 − t₁²) is then the
/// projected horizon of the hemisphere).
#[inline]
pub fn sample_vndf(alpha: f64, wi: V3, u1: f64, u2: f64) -> V3 {
    let vh = normalize([alpha * wi[0], alpha * wi[1], wi[2]]);
    let lensq = vh[0] * vh[0] + vh[1] * vh[1];
    let t1v = if lensq > 0.0 { let l = lensq.sqrt(); [-vh[1] / l, vh[0] / l, 0.0] } else { [1.0, 0.0, 0.0] };
    let t2v = cross(vh, t1v);
    let r = u1.sqrt();
    let (s_phi, c_phi) = (2.0 * PI * u2).sin_cos();
    let t1 = r * c_phi;
    let mut t2 = r * s_phi;
    let s = 0.5 * (1.0 + vh[2]);
    t2 = (1.0 - s) * (1.0 - t1 * t1).max(0.0).sqrt() + s * t2;
    let t3 = (1.0 - t1 * t1 - t2 * t2).max(0.0).sqrt();
    let nh = [t1 * t1v[0] + t2 * t2v[0] + t3 * vh[0], t1 * t1v[1] + t2 * t2v[1] + t3 * vh[1], t1 * t1v[2] + t2 * t2v[2] + t3 * vh[2]];
    normalize([alpha * nh[0], alpha * nh[1], nh[2].max(0.0)])
}

/// A cosine-distributed direction about the unit vector m.
#[inline]
fn sample_cosine(m: V3, u1: f64, u2: f64) -> V3 {
    let r = u1.sqrt();
    let (s, c) = (2.0 * PI * u2).sin_cos();
    let (x, y) = (r * c, r * s);
    let z = (1.0 - u1).max(0.0).sqrt();
    let (t, b) = basis(m);
    normalize([x * t[0] + y * b[0] + z * m[0], x * t[1] + y * b[1] + z * m[1], x * t[2] + y * b[2] + z * m[2]])
}

/// Schlick's Fresnel at the cosine c.
#[inline]
pub fn schlick(f0: f64, c: f64) -> f64 {
    let x = (1.0 - c).clamp(0.0, 1.0);
    let x2 = x * x;
    f0 + (1.0 - f0) * x2 * x2 * x
}

/// The facets' Fresnel: Schlick's form, except that F0 = 0 means no interface (η = 1, where
/// the exact Fresnel factor vanishes; Schlick's (1 − c)⁵ term would not).
#[inline]
pub fn fresnel(f0: f64, c: f64) -> f64 {
    if f0 > 0.0 { schlick(f0, c) } else { 0.0 }
}

/// What happens to the share F of the light that a microfacet reflects specularly.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Specular {
    /// Gone: it leaves the diffuse term (the talk: energy reflected specularly is "unable to
    /// participate in diffuse reflectance").
    Gone,
    /// It continues the walk as a mirror reflection about the microfacet and counts once it
    /// has been scattered diffusely at least once.
    Walks,
}

/// The microsurface and its facets.
#[derive(Debug, Clone, Copy)]
pub struct Surface {
    pub alpha: f64,
    /// Diffuse albedo of a microfacet.
    pub rho: f64,
    /// Schlick F0 of the facets' interface (0: no Fresnel).
    pub f0: f64,
    pub specular: Specular,
}

/// Walks longer than this many scattering events are cut (none is, at the family's settings:
/// `ms_diffuse_paths_end` is tested). At ρ = 1, F0 = 0 and α = 1 the mean is about 2.
pub const MAX_ORDER: u32 = 4096;

/// Heitz et al. 2016's height sampling in the height CDF u = C1(h) ∈ [0, 1] (any height
/// distribution gives the same BSDF; working in u avoids choosing one): the next intersection
/// of a ray leaving height u in direction w, or None when it escapes.
#[inline]
fn next_height(alpha: f64, wz: f64, u: f64, xi: f64) -> Option<f64> {
    if wz >= 1.0 {
        return None;
    }
    let lam = lambda_any(alpha, wz);
    if wz > 0.0 {
        // Escapes with probability G1 = u^Λ; else the hit is at u (1 − ξ)^(−1/Λ) ≤ 1.
        let g1 = u.powf(lam);
        if xi >= 1.0 - g1 {
            return None;
        }
        Some((u * (1.0 - xi).powf(-1.0 / lam)).min(1.0))
    } else if wz < 0.0 {
        // Always hits: u (1 − ξ)^(1/|Λ|), Λ ≤ −1.
        Some(u * (1.0 - xi).powf(-1.0 / lam))
    } else {
        Some(u)
    }
}

/// What one path of [`Surface::path`] returned.
#[derive(Debug, Clone, Copy, Default)]
pub struct PathResult {
    /// Σ over scattering events of the next-event estimate of f(wi, wo)·cos θo (at wo).
    pub nee: f64,
    /// The same restricted to the first scattering event (single scattering).
    pub nee_single: f64,
    /// The path's weight when it left the surface (0 if it did not), diffuse paths only.
    pub escaped: f64,
    /// Scattering events.
    pub order: u32,
}

impl Surface {
    /// One path entering along −wi (wi: unit, above the surface), with next-event estimates
    /// toward `wo` (unit; None: no estimate).
    pub fn path(&self, wi: V3, wo: Option<V3>, rng: &mut PathRng) -> PathResult {
        let alpha = self.alpha;
        let mut w = [-wi[0], -wi[1], -wi[2]];
        let mut u = 1.0f64;
        let mut weight = 1.0f64;
        let mut diffused = false;
        let mut out = PathResult::default();
        let lam_o = wo.map(|o| lambda_any(alpha, o[2]));
        loop {
            match next_height(alpha, w[2], u, rng.next_f64()) {
                None => {
                    if diffused {
                        out.escaped = weight;
                    }
                    return out;
                }
                Some(h) => u = h,
            }
            out.order += 1;
            if out.order > MAX_ORDER {
                return out;
            }
            let wi_local = [-w[0], -w[1], -w[2]];
            let m = sample_vndf(alpha, wi_local, rng.next_f64(), rng.next_f64());
            let c_in = dot(wi_local, m).max(0.0);
            let f_in = fresnel(self.f0, c_in);
            // Next-event estimate toward wo: diffuse share of this event (always), specular
            // share (only once the path has been diffused, in the walking convention).
            if let (Some(o), Some(lo)) = (wo, lam_o) {
                if o[2] > 0.0 {
                    let g1 = u.powf(lo);
                    let c_o = dot(o, m);
                    let mut e = 0.0;
                    if c_o > 0.0 {
                        let f_out = fresnel(self.f0, c_o);
                        e += (1.0 - f_in) * self.rho * c_o / PI * (1.0 - f_out);
                    }
                    if self.specular == Specular::Walks && diffused && self.f0 > 0.0 {
                        e += specular_phase(alpha, self.f0, wi_local, o);
                    }
                    let contribution = weight * e * g1;
                    out.nee += contribution;
                    if out.order == 1 {
                        out.nee_single = contribution;
                    }
                }
            }
            // The next direction.
            let xi = rng.next_f64();
            let (u1, u2) = (rng.next_f64(), rng.next_f64());
            match self.specular {
                Specular::Walks if xi < f_in => {
                    // Mirror reflection about m; the weight is unchanged (chosen with probability F).
                    let d = 2.0 * c_in;
                    w = normalize([d * m[0] - wi_local[0], d * m[1] - wi_local[1], d * m[2] - wi_local[2]]);
                }
                Specular::Walks => {
                    w = sample_cosine(m, u1, u2);
                    let f_out = fresnel(self.f0, dot(w, m).max(0.0));
                    weight *= self.rho * (1.0 - f_out);
                    diffused = true;
                }
                Specular::Gone => {
                    w = sample_cosine(m, u1, u2);
                    let f_out = fresnel(self.f0, dot(w, m).max(0.0));
                    weight *= (1.0 - f_in) * self.rho * (1.0 - f_out);
                    diffused = true;
                }
            }
            if weight == 0.0 {
                return out;
            }
        }
    }
}

/// The microfacet mirror phase function of a GGX microsurface seen from wi (any hemisphere)
/// toward wo: D_wi(h) F(wi·h) / (4 |wi·h|) with D_wi(h) = ⟨wi, h⟩ D(h) / A(wi), A(wi) = (1 +
/// Λ(wi)) wi_z the projected area (Heitz et al. 2016, Eq. 32 with Fresnel).
pub fn specular_phase(alpha: f64, f0: f64, wi: V3, wo: V3) -> f64 {
    let s = [wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]];
    let l = dot(s, s).sqrt();
    if l == 0.0 {
        return 0.0;
    }
    let h = [s[0] / l, s[1] / l, s[2] / l];
    let h = if h[2] < 0.0 { return 0.0 } else { h };
    let c = dot(wi, h);
    if c <= 0.0 {
        return 0.0;
    }
    let area = (1.0 + lambda_any(alpha, wi[2])) * wi[2];
    if !(area > 0.0) {
        return 0.0;
    }
    trowbridge_reitz::d(alpha, h[2]) * schlick(f0, c) / (4.0 * area)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rng_depends_on_key_cell_and_sample_only() {
        let a: Vec<f64> = (0..4).map(|_| 0.0).scan(PathRng::for_path(1, 2, 3), |r, _| Some(r.next_f64())).collect();
        let b: Vec<f64> = (0..4).map(|_| 0.0).scan(PathRng::for_path(1, 2, 3), |r, _| Some(r.next_f64())).collect();
        assert_eq!(a, b);
        assert_ne!(PathRng::for_path(1, 2, 3).next_f64(), PathRng::for_path(1, 2, 4).next_f64());
        assert_ne!(PathRng::for_path(1, 2, 3).next_f64(), PathRng::for_path(1, 3, 3).next_f64());
        assert_ne!(PathRng::for_path(1, 2, 3).next_f64(), PathRng::for_path(2, 2, 3).next_f64());
        // Uniform: mean of 2^16 draws within 5 standard errors (1/sqrt(12·2^16) ≈ 1.1e-3) of 1/2.
        let mut r = PathRng::for_path(7, 0, 0);
        let mean = (0..1 << 16).map(|_| r.next_f64()).sum::<f64>() / 65536.0;
        assert!((mean - 0.5).abs() < 5.0 * 1.13e-3, "{mean}");
    }

    /// A text's key is its 64-bit FNV-1a hash (Fowler, Noll & Vo; the test vectors of the FNV
    /// reference test_fnv.c: "" → cbf29ce484222325, the offset basis; "a" → af63dc4c8601ec8c;
    /// "foobar" → 85944171f73967e8) through the finaliser, itself pinned to SplitMix64 above.
    #[test]
    fn keys_are_fnv1a_through_the_finaliser() {
        for (text, fnv) in [("", 0xcbf2_9ce4_8422_2325u64), ("a", 0xaf63_dc4c_8601_ec8c), ("foobar", 0x8594_4171_f739_67e8)] {
            assert_eq!(key_of(text), mix64(fnv), "{text:?}");
        }
    }

    /// The heights of the next intersection follow Smith's masking in the height CDF (Heitz et
    /// al. 2016, §5: a ray from height u is unoccluded up to height v with probability (u/v)^Λ
    /// going up, (v/u)^|Λ| going down, Λ(−ω) = −1 − Λ(ω)), with Λ = (√(1 + α² tan²θ) − 1)/2
    /// written out here. Over N stratified draws ξ = (i + ½)/N the share of escapes and of hits
    /// at or below v is a share of the ξ below a threshold, so each is within 1/(2N) of its
    /// probability; the bound 1/N leaves the rounding of the thresholds room. A ray along the
    /// normal escapes; a horizontal one stays at its height.
    #[test]
    fn next_heights_follow_smiths_masking_in_the_height_cdf() {
        const N: usize = 4096;
        let smith = |alpha: f64, mu: f64| ((1.0 + alpha * alpha * (1.0 - mu * mu) / (mu * mu)).sqrt() - 1.0) / 2.0;
        for alpha in [0.3, 1.0] {
            for mu in [0.2, 0.7] {
                let lam = smith(alpha, mu);
                for u in [0.35, 0.8] {
                    let share = |wz: f64, pred: &dyn Fn(Option<f64>) -> bool| {
                        (0..N).filter(|&i| pred(next_height(alpha, wz, u, (i as f64 + 0.5) / N as f64))).count() as f64 / N as f64
                    };
                    let at = format!("α {alpha}, μ {mu}, u {u}");
                    // Up: escapes with u^Λ; a hit is in (u, 1], at or below v with 1 − (u/v)^Λ.
                    let escaped = share(mu, &|h| h.is_none());
                    assert!((escaped - u.powf(lam)).abs() < 1.0 / N as f64, "{at}: escaped {escaped} vs {}", u.powf(lam));
                    assert_eq!(share(mu, &|h| h.is_some_and(|h| h < u || h > 1.0)), 0.0, "{at}");
                    for v in [u + 0.25 * (1.0 - u), u + 0.75 * (1.0 - u)] {
                        let (got, want) = (share(mu, &|h| h.is_some_and(|h| h <= v)), 1.0 - (u / v).powf(lam));
                        assert!((got - want).abs() < 1.0 / N as f64, "{at}, up to {v}: {got} vs {want}");
                    }
                    // Down (Λ(−ω) = −1 − Λ(ω)): always hits, in [0, u], at or below v with (v/u)^(1 + Λ).
                    assert_eq!(share(-mu, &|h| h.is_none_or(|h| !(0.0..=u).contains(&h))), 0.0, "{at}");
                    for v in [0.25 * u, 0.75 * u] {
                        let (got, want) = (share(-mu, &|h| h.is_some_and(|h| h <= v)), (v / u).powf(1.0 + lam));
                        assert!((got - want).abs() < 1.0 / N as f64, "{at}, down to {v}: {got} vs {want}");
                    }
                }
            }
        }
        assert_eq!(next_height(0.5, 1.0, 0.4, 0.3), None);
        assert_eq!(next_height(0.5, 0.0, 0.4, 0.3), Some(0.4));
    }

    /// The vector helpers by hand: the cross products of the axes and of (1, 2, 3) × (4, 5, 6)
    /// = (−3, 6, −3), their dot product 32, and (3, 0, 4)/5. Small integers: exact.
    #[test]
    fn vector_helpers_by_hand() {
        let (x, y, z) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
        assert_eq!((cross(x, y), cross(y, z), cross(z, x)), (z, x, y));
        assert_eq!(cross([1.0, 2.0, 3.0], [4.0, 5.0, 6.0]), [-3.0, 6.0, -3.0]);
        assert_eq!(dot([1.0, 2.0, 3.0], [4.0, 5.0, 6.0]), 32.0);
        assert_eq!(normalize([3.0, 0.0, -4.0]), [0.6, 0.0, -0.8]);
    }

    /// Unit vectors about every octant, the poles and near the south pole, where Frisvad's
    /// original basis lost its accuracy and Duff et al.'s sign choice keeps it.
    fn normals() -> Vec<V3> {
        let mut n = vec![[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], normalize([1e-4, -2e-4, -1.0]), normalize([1e-9, 0.0, 1.0])];
        for sx in [-1.0, 1.0] {
            for sy in [-1.0, 1.0] {
                for sz in [-1.0, 1.0] {
                    n.push(normalize([0.3 * sx, 0.5 * sy, 0.8 * sz]));
                    n.push(normalize([0.9 * sx, 0.1 * sy, 0.05 * sz]));
                }
            }
        }
        n
    }

    /// Duff et al. 2017's basis is orthonormal and right-handed, t × b = n, for every normal
    /// (their Listing 3 is accurate to a few ulps everywhere: bound 1e-15).
    #[test]
    fn basis_is_orthonormal_and_right_handed() {
        for n in normals() {
            let (t, b) = basis(n);
            for (what, got, want) in [("t·t", dot(t, t), 1.0), ("b·b", dot(b, b), 1.0), ("t·b", dot(t, b), 0.0), ("t·n", dot(t, n), 0.0), ("b·n", dot(b, n), 0.0)] {
                assert!((got - want).abs() < 1e-15, "n {n:?}: {what} = {got}");
            }
            let tb = cross(t, b);
            assert!((0..3).all(|k| (tb[k] - n[k]).abs() < 1e-15), "n {n:?}: t × b = {tb:?}");
        }
    }

    /// Cosine-weighted directions about m, over a midpoint grid of (u1, u2) (256 × 64): each is
    /// a unit vector in m's hemisphere, and their moments are those of the cosine lobe whatever
    /// basis carries them: E[w·m] = 2/3, E[w] = (2/3) m, E[w wᵀ] = ¼ I + ¼ m mᵀ (transverse
    /// share u1·cos²φ with mean ¼ per axis, (w·m)² = 1 − u1 with mean ½). The grid integrates
    /// u1, cos² and cos exactly (rounding only: 1e-13); E[w·m] = ∫√(1 − u1) takes the midpoint
    /// rule's error at the square root's end, ζ(−½, ½) h^(3/2) ≈ 0.061 h^(3/2) (Navot's
    /// expansion), below h^(3/2)/4 = 6.1e-5.
    #[test]
    fn cosine_samples_have_the_cosine_lobes_moments() {
        let (n1, n2) = (256usize, 64usize);
        let root_tol = (1.0 / n1 as f64).powf(1.5) / 4.0;
        for m in normals() {
            let (mut mean_c, mut mean, mut second) = (0.0, [0.0; 3], [[0.0; 3]; 3]);
            for i in 0..n1 {
                for j in 0..n2 {
                    let w = sample_cosine(m, (i as f64 + 0.5) / n1 as f64, (j as f64 + 0.5) / n2 as f64);
                    assert!((dot(w, w) - 1.0).abs() < 1e-15 && dot(w, m) > 0.0, "m {m:?}: {w:?}");
                    mean_c += dot(w, m);
                    for a in 0..3 {
                        mean[a] += w[a];
                        for b in 0..3 {
                            second[a][b] += w[a] * w[b];
                        }
                    }
                }
            }
            let count = (n1 * n2) as f64;
            assert!((mean_c / count - 2.0 / 3.0).abs() < root_tol, "m {m:?}: E[w·m] = {}", mean_c / count);
            for a in 0..3 {
                let got = mean[a] / count;
                assert!((got - 2.0 / 3.0 * m[a]).abs() < root_tol, "m {m:?}: E[w]_{a} = {got}");
                for b in 0..3 {
                    let want = 0.25 * (a == b) as u8 as f64 + 0.25 * m[a] * m[b];
                    let got = second[a][b] / count;
                    assert!((got - want).abs() < 1e-13, "m {m:?}: E[w wᵀ]_{a}{b} = {got} vs {want}");
                }
            }
        }
    }

    /// Schlick's form at its ends and a hand point: F0 at normal incidence, 1 at grazing,
    /// F0 + (1 − F0)/32 at c = ½ (0.04 + 0.03: a few ulps of 0.07); cosines past [0, 1] read as its ends. Without an
    /// interface (F0 = 0) the facets reflect nothing, grazing included.
    #[test]
    fn schlick_and_the_facets_fresnel_by_hand() {
        for f0 in [0.0, 0.04, 0.5, 1.0] {
            assert_eq!(schlick(f0, 1.0), f0);
            assert_eq!(schlick(f0, 0.0), 1.0);
            assert_eq!(schlick(f0, 1.7), f0);
            assert_eq!(schlick(f0, -0.4), 1.0);
        }
        assert!((schlick(0.04, 0.5) - 0.07).abs() < 1e-16, "{}", schlick(0.04, 0.5));
        assert!((schlick(0.5, 0.75) - (0.5 + 0.5 / 1024.0)).abs() < 1e-16, "{}", schlick(0.5, 0.75));
        for c in [0.0, 0.3, 1.0] {
            assert_eq!(fresnel(0.0, c), 0.0);
            assert_eq!(fresnel(0.04, c), schlick(0.04, c));
        }
    }

    /// GGX D is normalised as a distribution of projected area, ∫ D(m) cos θm dω = 1, which in
    /// t = cos²θm is ∫₀¹ π D dt; by the adaptive rule asked for 1e-12 (the integrand is
    /// smooth, its scale α²; bound 1e-10). At the pole D = 1/(π α²), at the horizon α²/π (a
    /// few roundings there: 1e-15).
    #[test]
    fn ggx_d_is_normalised_with_its_closed_form_ends() {
        let tol = crate::integrate::Tolerance { abs: 1e-12, rel: 0.0, max_panels: 1000 };
        for alpha in [0.2, 0.5, 1.0, 1.7] {
            let sum = crate::integrate::adaptive(0.0, 1.0, tol, |t| PI * trowbridge_reitz::d(alpha, t.sqrt())).value;
            assert!((sum - 1.0).abs() < 1e-10, "α {alpha}: {sum}");
            let a2 = alpha * alpha;
            // At the pole 1 + (α² − 1) cancels to α²: the rounding of α² − 1 (an ulp of 1) is
            // relative 2⁻⁵³/α² in it and twice that in its square, plus a few roundings.
            let pole_tol = 4.0 * f64::EPSILON / a2 + 1e-15;
            let pole = trowbridge_reitz::d(alpha, 1.0) * PI * a2;
            assert!((pole - 1.0).abs() < pole_tol, "α {alpha}: {pole}");
            assert!((trowbridge_reitz::d(alpha, 0.0) * PI / a2 - 1.0).abs() < 1e-15, "α {alpha}");
        }
    }

    /// Unit vector (sin θ cos φ, sin θ sin φ, cos θ).
    fn dir(theta: f64, phi: f64) -> V3 {
        crate::shading::direction(theta, phi)
    }

    /// With F = 1 (f0 = 1) the mirror phase function is a distribution over wo: by wo = 2(wi·h)h −
    /// wi, dwo = 4|wi·h| dh, so ∫ p dwo = ∫ D_wi(h) dh = 1 (Heitz et al. 2016, §4). Integrated
    /// over h ∈ the upper hemisphere for views off the x–z plane, above and below the horizon,
    /// by a Gauss–Legendre product rule. The integrand has a kink where wi·h = 0, so the rule is
    /// first-order there and the difference of two resolutions bounds the finer one's error:
    /// measured 6e-7 apart and 7e-8 from 1, both bounded by 2e-6. And p is isotropic: rotating
    /// wi and wo together about the normal leaves it unchanged (measured 1.5e-15 relative,
    /// rounding of the turned vectors; bound 1e-13).
    #[test]
    fn specular_phase_is_a_distribution_and_isotropic() {
        let (x, w) = crate::integrate::gauss_legendre(8);
        let integral = |alpha: f64, wi: V3, panels: usize| {
            let (ht, hp) = (0.5 * PI / panels as f64, 2.0 * PI / (2 * panels) as f64);
            let mut sum = 0.0;
            for i in 0..panels {
                for (xi, wti) in x.iter().zip(&w) {
                    let t = ht * (i as f64 + 0.5 * (xi + 1.0));
                    for j in 0..2 * panels {
                        for (xj, wpj) in x.iter().zip(&w) {
                            let ph = hp * (j as f64 + 0.5 * (xj + 1.0));
                            let h = dir(t, ph);
                            let c = dot(wi, h);
                            if c <= 0.0 {
                                continue;
                            }
                            let wo = [2.0 * c * h[0] - wi[0], 2.0 * c * h[1] - wi[1], 2.0 * c * h[2] - wi[2]];
                            let jac = 4.0 * c * t.sin() * 0.25 * ht * hp * wti * wpj;
                            sum += specular_phase(alpha, 1.0, wi, wo) * jac;
                        }
                    }
                }
            }
            sum
        };
        for (alpha, wi) in [(0.5, normalize([0.3, 0.5, 0.8])), (0.8, normalize([-0.6, 0.4, -0.3])), (0.3, normalize([0.1, -0.9, 0.4]))] {
            let (coarse, fine) = (integral(alpha, wi, 24), integral(alpha, wi, 48));
            assert!((fine - coarse).abs() < 2e-6, "alpha {alpha} wi {wi:?}: {coarse} vs {fine}");
            assert!((fine - 1.0).abs() < 2e-6, "alpha {alpha} wi {wi:?}: {fine}");
        }
        // Rotation about z: in the x–z plane and turned by φ.
        for (ti, to, phi) in [(0.4, 1.1, 0.7), (2.0, 0.9, 2.5), (0.8, 1.9, -1.3)] {
            let (a, b) = (dir(ti, 0.0), dir(to, PI));
            let (ra, rb) = (dir(ti, phi), dir(to, PI + phi));
            let (p, q) = (specular_phase(0.4, 0.04, a, b), specular_phase(0.4, 0.04, ra, rb));
            assert!(p > 0.0 && (p - q).abs() <= 1e-13 * p, "θi {ti} θo {to} φ {phi}: {p} vs {q}");
        }
    }

    /// ∫ over visible m (wi·m > 0) of ⟨wi, m⟩ D(m) m_z dm, in the GGX CDF variable ξ (D m_z dω
    /// = dξ dφ/2π, tan²θ = α² ξ/(1 − ξ)) with the azimuth in closed form:
    /// ∫ (sin θi sin θm sin φ₀ + cos θi cos θm φ₀)/π dξ, cos φ₀ = −cos θi cos θm/(sin θi sin θm)
    /// clamped; midpoint rule on 2·10⁵ points (the kink where φ₀ saturates costs O(h²)
    /// locally: error ≲ 1e-6).
    fn visible_mass(alpha: f64, wz: f64) -> f64 {
        let n = 200_000;
        let si = (1.0 - wz * wz).sqrt();
        (0..n)
            .map(|k| {
                let xi = (k as f64 + 0.5) / n as f64;
                let t2 = alpha * alpha * xi / (1.0 - xi);
                let cm = 1.0 / (1.0 + t2).sqrt();
                let sm = (t2 / (1.0 + t2)).sqrt();
                let phi0 = (-wz * cm / (si * sm)).clamp(-1.0, 1.0).acos();
                (si * sm * phi0.sin() + wz * cm * phi0) / PI
            })
            .sum::<f64>()
            / n as f64
    }

    #[test]
    fn vndf_samples_have_the_visible_normal_moments() {
        // E over D_wi of m_z = ∫_{wi·m>0} ⟨wi, m⟩ D(m) m_z dm / A(wi), A(wi) = (1 + Λ(wi)) wi_z
        // (the projected area, Heitz 2014 §2); the right side by the quadrature above. Above and
        // below the horizon; 2^18 samples, within 5 standard errors plus the quadrature's 1e-6.
        for (alpha, wz) in [(1.0, 0.8), (0.5, 0.3), (0.3, -0.4), (1.0, -0.9), (0.6, -0.2), (0.05, 0.05)] {
            let wi = [(1.0f64 - wz * wz).sqrt(), 0.0, wz];
            let mut r = PathRng::for_path(11, 0, 0);
            let n = 1 << 18;
            let (mut s, mut s2) = (0.0, 0.0);
            for _ in 0..n {
                let m = sample_vndf(alpha, wi, r.next_f64(), r.next_f64());
                let c = dot(wi, m);
                assert!(m[2] >= 0.0 && c >= -1e-12, "{m:?}");
                let x = m[2];
                s += x;
                s2 += x * x;
            }
            let mean = s / n as f64;
            let se = ((s2 / n as f64 - mean * mean) / n as f64).sqrt();
            let area = (1.0 + lambda_any(alpha, wz)) * wz;
            let want = visible_mass(alpha, wz) / area;
            assert!((mean - want).abs() < 5.0 * se + 1e-6 / area, "alpha {alpha} wz {wz}: {mean} vs {want} (se {se})");
        }
    }

    /// The visible-normal sampler has no preferred azimuth: turning the view about the normal
    /// turns each sample with it, draw for draw (Heitz 2018's frame (t1, t2, v_h) is built from
    /// the stretched view and turns with it; the stretch by α commutes with the turn). The moment
    /// test above uses views in the x–z plane, where every y term is a zero: here views off it,
    /// above and below the horizon. Bound: a few roundings of unit vectors, 1e-13.
    #[test]
    fn visible_normals_turn_with_the_view_about_the_normal() {
        let turn = |v: V3, phi: f64| {
            let (s, c) = phi.sin_cos();
            [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]]
        };
        for (alpha, wi) in [(0.5, normalize([0.3, 0.5, 0.8])), (0.8, normalize([-0.6, 0.4, -0.3])), (0.3, normalize([0.1, -0.9, 0.4])), (1.4, normalize([0.7, 0.2, -0.6]))] {
            for phi in [0.9, 2.6, -1.7] {
                for (u1, u2) in [(0.1, 0.2), (0.5, 0.7), (0.9, 0.45), (0.33, 0.95)] {
                    let want = turn(sample_vndf(alpha, wi, u1, u2), phi);
                    let got = sample_vndf(alpha, turn(wi, phi), u1, u2);
                    assert!((0..3).all(|k| (got[k] - want[k]).abs() < 1e-13), "α {alpha} wi {wi:?} φ {phi} u ({u1}, {u2}): {got:?} vs {want:?}");
                }
            }
        }
    }

    /// F0 = 0 is no interface: no light is reflected specularly, so what becomes of that share
    /// cannot matter. The two conventions are then one walk, path for path and bit for bit
    /// (Gone keeps (1 − 0)·ρ·(1 − 0) = ρ of the weight, Walks ρ·(1 − 0) = ρ; neither adds a
    /// mirror term), at ρ = 0.8 and α 0.2 and 1.
    #[test]
    fn without_an_interface_the_specular_conventions_are_one_walk() {
        let bits = |r: PathResult| (r.nee.to_bits(), r.nee_single.to_bits(), r.escaped.to_bits(), r.order);
        for alpha in [0.2, 1.0] {
            let at = |specular| Surface { alpha, rho: 0.8, f0: 0.0, specular };
            for (wi, wo) in [(normalize([0.6, 0.0, 0.8]), normalize([-0.3, 0.4, 0.5])), (normalize([0.1, -0.2, 0.3]), [0.0, 0.0, 1.0])] {
                for sample in 0..2000 {
                    let gone = at(Specular::Gone).path(wi, Some(wo), &mut PathRng::for_path(3, 0, sample));
                    let walks = at(Specular::Walks).path(wi, Some(wo), &mut PathRng::for_path(3, 0, sample));
                    assert_eq!(bits(gone), bits(walks), "α {alpha} wi {wi:?} path {sample}: {gone:?} vs {walks:?}");
                }
            }
        }
    }

    /// Each diffuse event keeps the share ρ of what reaches it: with ρ = ½ a path is the same
    /// walk (its directions do not depend on ρ), its escape weight 2^−order of that at ρ = 1
    /// (every event diffuses in the Gone convention) and its first next-event estimate half of
    /// it; its whole next-event sum lies between 2^−order and ½ of that at ρ = 1. Scaling by a
    /// power of two is exact in floating point: bit for bit. F0 0 and 0.04.
    #[test]
    fn each_diffuse_event_keeps_rho_of_the_weight() {
        for f0 in [0.0, 0.04] {
            let at = |rho| Surface { alpha: 0.6, rho, f0, specular: Specular::Gone };
            let (wi, wo) = (normalize([0.5, 0.1, 0.6]), normalize([-0.2, -0.3, 0.7]));
            let mut longer = 0;
            for sample in 0..2000 {
                let one = at(1.0).path(wi, Some(wo), &mut PathRng::for_path(9, 4, sample));
                let half = at(0.5).path(wi, Some(wo), &mut PathRng::for_path(9, 4, sample));
                let scale = 0.5f64.powi(one.order as i32);
                assert_eq!(half.order, one.order, "F0 {f0} path {sample}");
                assert_eq!(half.escaped, one.escaped * scale, "F0 {f0} path {sample}: {half:?} vs {one:?}");
                assert_eq!(half.nee_single, 0.5 * one.nee_single, "F0 {f0} path {sample}: {half:?} vs {one:?}");
                // The sum over k of 2^−k times event k's estimate, rounded: bounds widened by 1e-15.
                assert!(half.nee >= scale * one.nee * (1.0 - 1e-15) && half.nee <= 0.5 * one.nee * (1.0 + 1e-15), "F0 {f0} path {sample}: {half:?} vs {one:?}");
                longer += (one.order > 1) as u32;
            }
            assert!(longer > 100, "F0 {f0}: {longer} paths of two events or more");
        }
    }

    /// A walk that never leaves is cut: the event past the MAX_ORDER-th ends it (order
    /// MAX_ORDER + 1, nothing escapes). A ray without a direction (NaN) is such a walk: it
    /// neither rises nor falls, so it meets the surface at its own height every time.
    #[test]
    fn a_walk_that_never_leaves_is_cut_after_max_order_events() {
        let s = Surface { alpha: 0.5, rho: 1.0, f0: 0.0, specular: Specular::Gone };
        let r = s.path([f64::NAN; 3], None, &mut PathRng::for_path(1, 1, 1));
        assert_eq!((r.order, r.escaped), (MAX_ORDER + 1, 0.0), "{r:?}");
    }

    /// The mirror phase at its boundaries. Facets are those with h_z ≥ 0, D = α²/π at the
    /// horizon: for wi + wo horizontal (h = x) the phase is its limit from above (wo tilted by
    /// 1e-9: D and F move by O(1e-9), bound 1e-6 relative), not 0. And a flat microsurface (α =
    /// 0) shows no area to a view below its horizon (A(wi) = (1 + Λ) wi_z = 0): nothing to
    /// reflect, 0.
    #[test]
    fn the_mirror_phase_at_horizontal_facets_and_for_an_unseen_plane() {
        let (wi, wo) = ([0.6, 0.0, -0.8], [0.6, 0.0, 0.8]);
        for alpha in [0.3, 1.0] {
            let at = specular_phase(alpha, 0.04, wi, wo);
            let above = specular_phase(alpha, 0.04, wi, normalize([0.6, 0.0, 0.8 + 1e-9]));
            assert!(above > 0.0 && (at - above).abs() <= 1e-6 * above, "α {alpha}: {at} vs {above}");
        }
        assert_eq!(specular_phase(0.0, 0.04, [0.8, 0.0, -0.6], [0.6, 0.0, 0.8]), 0.0);
    }
}
