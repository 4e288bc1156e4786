//! SH lighting: spherical integration with the *radial* profile (units and conventions in the
//! module doc of `super`).
//!
//! On a sphere of radius r = 1/κ, convolving the incident irradiance with the kernel
//! K(γ) = R(2r·sin(γ/2)) (γ the angle between the two points, 2r·sin(γ/2) their Euclidean
//! distance), normalised over the sphere, is a zonal (rotationally symmetric) operator. By the
//! Funk–Hecke theorem every spherical harmonic Y_lm is an eigenfunction:
//!
//!   ∫_{S²} K(∠(ω, ω')) Y_lm(ω') dω' = [2π ∫_0^π K(γ) P_l(cos γ) sin γ dγ] · Y_lm(ω),
//!
//! so after normalisation the SH coefficients of the (clamped-cosine) irradiance in band l are
//! multiplied by
//!
//!   k_l(κ) = ∫_0^π K(γ) P_l(cos γ) sin γ dγ / ∫_0^π K(γ) sin γ dγ.
//!
//! The substitution s = 2r·sin(γ/2) (cos γ = 1 − s²κ²/2, sin γ dγ = κ² s ds) turns it into
//! a planar-looking integral over the chord:
//!
//!   k_l = 1 − ∫_0^{S} R(s) d_l(s²κ²/2) s ds / ∫_0^{S} R(s) s ds,   S = min(2r, s_max),
//!
//! with d_l(t) = 1 − P_l(1 − t), computed by a cancellation-free recurrence
//! (d_0 = 0, d_1 = t, d_{l+1} = [(2l+1)(t + d_l − t·d_l) − l·d_{l−1}]/(l+1)). The denominator is
//! the profile's mass within the chord 2r, in closed form. k_0 = 1 exactly (the kernel is
//! normalised over the sphere, i.e. light is conserved), |k_l| ≤ 1, k_l → 1 as κ → 0
//! (1 − k_l ≈ l(l+1)κ²⟨s²⟩/4, ⟨s²⟩ = Σ w_i·2v_i for Gaussians) and k_l → 0 for l ≥ 1 as κ → ∞.
//! The clamped-cosine irradiance bands themselves (π, 2π/3, π/4) are not included: multiply.
//!

use super::diffusion::{Kernel, PreparedKernel, Profile, ProfileError};
use super::{adaptive_vec, check_args, is_flat, lut_curvature};
use crate::integrate::{Estimate, Tolerance};
use rayon::prelude::*;
use std::f64::consts::PI;


/// d_l(t) = 1 − P_l(1 − t), t ∈ [0, 2], without cancellation for small t.
fn one_minus_legendre(l: u32, t: f64) -> f64 {
    if l == 0 {
        return 0.0;
    }
    let (mut d_prev, mut d) = (0.0, t);
    for k in 1..l {
        let kf = k as f64;
        let next = ((2.0 * kf + 1.0) * (t + d - t * d) - kf * d_prev) / (kf + 1.0);
        d_prev = d;
        d = next;
    }
    d
}

/// SH band-l scale factor k_l(κ) per channel (module docs): the factor by which subsurface
/// scattering on a sphere of radius 1/κ multiplies band l of the irradiance. Any l is
/// accepted (bands 0, 1, 2 are the usual ones); k_0 = 1 and κ = 0 give exactly 1.
///
/// The denominator (mass within chord 2/κ) is closed-form; the numerator is integrated to
/// tol.abs × denominator, so the error estimate applies to k_l directly.
pub fn sh_band(
    profile: &Profile,
    curvature_per_mm: f64,
    band: u32,
    tol: Tolerance,
) -> Result<[Estimate; 3], ProfileError> {
    check_args(curvature_per_mm, 0.0);
    profile.validate()?;
    if band == 0 || is_flat(curvature_per_mm, profile.support_mm()) {
        return Ok([Estimate::exact(1.0); 3]);
    }
    let k = PreparedKernel::new(profile, Kernel::Radial);
    sh_band_prepared(profile, &k, curvature_per_mm, band, tol)
}

fn sh_band_prepared(
    profile: &Profile,
    k: &PreparedKernel,
    kappa: f64,
    band: u32,
    tol: Tolerance,
) -> Result<[Estimate; 3], ProfileError> {
    let s_end = (2.0 / kappa).min(k.cutoff);
    // ∫_0^S R s ds = mass_within(S) / 2π.
    let den = profile.mass_within(s_end).map(|m| m / (2.0 * PI));
    for (channel, &d) in den.iter().enumerate() {
        if d.is_nan() || d <= 0.0 {
            return Err(ProfileError::NoMassWithinReach { channel, curvature_per_mm: kappa });
        }
    }
    let mut cuts = vec![0.0];
    cuts.extend(k.breaks.iter().copied().filter(|&s| s < s_end));
    cuts.push(s_end);
    let intervals: Vec<(f64, f64)> = cuts.windows(2).map(|w| (w[0], w[1])).collect();
    let abs: [f64; 3] = std::array::from_fn(|c| tol.abs * den[c]);
    let half_k2 = 0.5 * kappa * kappa;
    let num = adaptive_vec(&intervals, abs, tol.rel, tol.max_panels, |s| {
        let w = one_minus_legendre(band, half_k2 * s * s) * s;
        let r = k.eval(s);
        [w * r[0], w * r[1], w * r[2]]
    });
    Ok(std::array::from_fn(|c| Estimate {
        value: 1.0 - num[c].value / den[c],
        error: num[c].error / den[c],
        evals: num[c].evals,
    }))
}

/// SH scale factors for bands 0, 1, 2 on κ uniform in [0, κ_max] (ends included, see
/// [`lut_curvature`]): entry j is [k_0, k_1, k_2] (each RGB) at row j.
pub fn sh_lut(
    profile: &Profile,
    n_kappa: usize,
    kappa_max_per_mm: f64,
    tol: Tolerance,
) -> Result<Vec<[[f64; 3]; 3]>, ProfileError> {
    assert!(n_kappa >= 2, "a LUT needs at least 2 samples");
    assert!(kappa_max_per_mm.is_finite() && kappa_max_per_mm >= 0.0);
    let kappas: Vec<f64> = (0..n_kappa).map(|j| lut_curvature(j, n_kappa, kappa_max_per_mm)).collect();
    Ok(sh_bands_estimates(profile, &kappas, &[1, 2], tol)?
        .into_iter()
        .map(|b| [[1.0; 3], b[0].map(|e| e.value), b[1].map(|e| e.value)])
        .collect())
}

/// [`sh_band`] for each of `bands` at each curvature (any points): entry j holds the bands in
/// the order given, at κ = `curvature_per_mm[j]`. Curvatures in parallel, collected in order.
pub fn sh_bands_estimates(
    profile: &Profile,
    curvature_per_mm: &[f64],
    bands: &[u32],
    tol: Tolerance,
) -> Result<Vec<Vec<[Estimate; 3]>>, ProfileError> {
    for &kappa in curvature_per_mm {
        check_args(kappa, 0.0);
    }
    profile.validate()?;
    let k = PreparedKernel::new(profile, Kernel::Radial);
    let support = profile.support_mm();
    curvature_per_mm
        .par_iter()
        .map(|&kappa| {
            bands
                .iter()
                .map(|&band| {
                    if band == 0 || is_flat(kappa, support) {
                        Ok([Estimate::exact(1.0); 3])
                    } else {
                        sh_band_prepared(profile, &k, kappa, band, tol)
                    }
                })
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::tests::tight;
    use super::super::*;
    use super::*;

    /// d_l(t) = 1 − P_l(1 − t) against the Legendre polynomials written out (P₁ = x, P₂ =
    /// (3x² − 1)/2, P₃ = (5x³ − 3x)/2, P₄ = (35x⁴ − 30x² + 3)/8, P₅ = (63x⁵ − 70x³ + 15x)/8)
    /// over t ∈ [0, 2]: those lose up to 35 ulps of 1 to cancellation near x = ±1, so 1e-14.
    /// Near t = 0, where the recurrence is meant to keep its digits, d_l = l(l + 1)/2 · t (1 +
    /// O(l² t)): relative 1e-9 at t = 1e-12.
    #[test]
    fn one_minus_legendre_is_one_minus_the_legendre_polynomial() {
        let p = [
            |_: f64| 1.0,
            |x: f64| x,
            |x: f64| (3.0 * x * x - 1.0) / 2.0,
            |x: f64| (5.0 * x.powi(3) - 3.0 * x) / 2.0,
            |x: f64| (35.0 * x.powi(4) - 30.0 * x * x + 3.0) / 8.0,
            |x: f64| (63.0 * x.powi(5) - 70.0 * x.powi(3) + 15.0 * x) / 8.0,
        ];
        for (l, pl) in p.iter().enumerate() {
            for i in 0..=200 {
                let t = i as f64 / 100.0;
                let (got, want) = (one_minus_legendre(l as u32, t), 1.0 - pl(1.0 - t));
                assert!((got - want).abs() < 1e-14, "l {l}, t {t}: {got} vs {want}");
            }
            let t = 1e-12;
            let slope = (l * (l + 1)) as f64 / 2.0 * t;
            let got = one_minus_legendre(l as u32, t);
            assert!((got - slope).abs() <= 1e-9 * slope, "l {l}: {got:e} vs {slope:e}");
        }
    }

    #[test]
    fn sh_band0_and_limits() {
        let p = default_skin_profile();
        for kappa in [0.0, 0.1, 5.0] {
            assert!(
                sh_band(&p, kappa, 0, DEFAULT_TOLERANCE).unwrap().iter().all(|e| e.value == 1.0)
            );
        }
        for band in 0..=4 {
            assert!(
                sh_band(&p, 0.0, band, DEFAULT_TOLERANCE).unwrap().iter().all(|e| e.value == 1.0)
            );
        }
        // Small κ: 1 − k_l ≈ l(l+1)κ²·Σ w_i v_i / 2 (second moment ⟨s²⟩ = Σ w·2v); the next term
        // is O(κ⁴⟨s⁴⟩), relative O(κ²·v_max) ≈ 7e-6 at κ = 1e-3.
        let kappa = 1e-3;
        for band in 1..=2u32 {
            let k = sh_band(&p, kappa, band, tight()).unwrap();
            for c in 0..3 {
                let m: f64 = DEON_LUEBKE_SKIN.iter().map(|g| g.weight[c] * g.variance_mm2).sum();
                let l = band as f64;
                let approx = l * (l + 1.0) * kappa * kappa * m / 2.0;
                let got = 1.0 - k[c].value;
                assert!((got - approx).abs() < 1e-4 * approx, "l={band} c={c}: {got} vs {approx}");
            }
        }
        // Large κ: the kernel covers the whole sphere nearly uniformly; k_l → 0.
        let k = sh_band(&p, 1e3, 1, DEFAULT_TOLERANCE).unwrap();
        assert!(k.iter().all(|e| e.value.abs() < 1e-3));
    }

    #[test]
    fn sh_bands_decrease_with_curvature() {
        let p = default_skin_profile();
        let lut = sh_lut(&p, 41, 4.0, DEFAULT_TOLERANCE).unwrap();
        assert_eq!(lut[0], [[1.0; 3]; 3]);
        for j in 1..lut.len() {
            for c in 0..3 {
                assert_eq!(lut[j][0][c], 1.0);
                // Strictly below the previous κ, with k_2 < k_1 < 1 (blur damps higher bands
                // more); the margin is the 1e-10 tolerance.
                assert!(lut[j][1][c] < lut[j - 1][1][c] - 1e-10, "j={j} c={c}");
                assert!(lut[j][2][c] < lut[j - 1][2][c] - 1e-10, "j={j} c={c}");
                assert!(lut[j][2][c] < lut[j][1][c] && lut[j][1][c] < 1.0);
                assert!(lut[j][2][c] > -1e-10);
            }
        }
        eprintln!("k_l(κ = 1/mm) = {:?}", lut[10]);
    }

    #[test]
    fn sh_matches_closed_form_moments() {
        // Gaussians: ∫_0^S e^{−s²/(2v)} s^{2m+1} ds = v(2v)^m γ(m+1, W), W = S²/(2v), with
        // γ(m+1, W) = m!(1 − e^{−W} Σ_{j≤m} W^j/j!). k_1 = 1 − (κ²/2)·M3/M1 and
        // k_2 = 1 − (3κ²/2)·M3/M1 + (3κ⁴/8)·M5/M1 (d_2(t) = 3t − 3t²/2, t = s²κ²/2).
        let p = default_skin_profile();
        for kappa in [0.2_f64, 1.0, 3.0] {
            let s_end = (2.0 / kappa).min(p.support_mm());
            for c in 0..3 {
                let moment = |m: i32| -> f64 {
                    DEON_LUEBKE_SKIN
                        .iter()
                        .map(|g| {
                            let v = g.variance_mm2;
                            let w = s_end * s_end / (2.0 * v);
                            let mut sum = 0.0;
                            let mut term = 1.0;
                            let mut fact = 1.0;
                            for j in 0..=m {
                                if j > 0 {
                                    term *= w / j as f64;
                                    fact *= j as f64;
                                }
                                sum += term;
                            }
                            let gamma = fact * (1.0 - (-w).exp() * sum);
                            g.weight[c] / (2.0 * PI * v) * v * (2.0 * v).powi(m) * gamma
                        })
                        .sum()
                };
                let (m1, m3, m5) = (moment(0), moment(1), moment(2));
                let k1 = 1.0 - 0.5 * kappa * kappa * m3 / m1;
                let k2 = 1.0 - 1.5 * kappa * kappa * m3 / m1 + 0.375 * kappa.powi(4) * m5 / m1;
                let q1 = sh_band(&p, kappa, 1, DEFAULT_TOLERANCE).unwrap()[c].value;
                let q2 = sh_band(&p, kappa, 2, DEFAULT_TOLERANCE).unwrap()[c].value;
                // Tolerance 1e-10 plus the closed form's own cancellation (1 − e^{−W}Σ… for
                // small W loses ~1e-16/W relative on terms far below 1e-10): 2e-10.
                assert!((q1 - k1).abs() < 2e-10, "κ={kappa} c={c}: {q1} vs {k1}");
                assert!((q2 - k2).abs() < 2e-10, "κ={kappa} c={c}: {q2} vs {k2}");
            }
        }
    }

    #[test]
    fn sh_matches_brute_force_sphere_convolution() {
        // Convolve the zonal function P_l(cos ϑ) with the normalised kernel R(chord) centred at
        // a point at polar angle α, on a global (ϑ, φ) grid (Gauss–Legendre in cos ϑ,
        // trapezoid in φ): Funk–Hecke says the result is k_l·P_l(cos α).
        let p = default_skin_profile();
        let kappa = 1.0;
        let r = 1.0 / kappa;
        let alpha: f64 = 0.7;
        let centre = [alpha.sin(), 0.0, alpha.cos()];
        let (mu, wmu) = crate::integrate::gauss_legendre(1200);
        let n_phi = 1600;
        let mut num = [[0.0; 3]; 3];
        let mut den = [0.0; 3];
        for (&z, &wz) in mu.iter().zip(&wmu) {
            let sz = (1.0 - z * z).sqrt();
            for k in 0..n_phi {
                let phi = 2.0 * PI * k as f64 / n_phi as f64;
                let w = [sz * phi.cos(), sz * phi.sin(), z];
                let d2: f64 = (0..3).map(|i| (w[i] - centre[i]).powi(2)).sum();
                let kern = p.radial(r * d2.sqrt());
                let pl = [1.0, z, 0.5 * (3.0 * z * z - 1.0)];
                for c in 0..3 {
                    den[c] += wz * kern[c];
                    for l in 0..3 {
                        num[l][c] += wz * kern[c] * pl[l];
                    }
                }
            }
        }
        let ca = alpha.cos();
        let pl_alpha = [1.0, ca, 0.5 * (3.0 * ca * ca - 1.0)];
        let mut worst: f64 = 0.0;
        for l in 1..3u32 {
            let k = sh_band(&p, kappa, l, DEFAULT_TOLERANCE).unwrap();
            for c in 0..3 {
                let brute = num[l as usize][c] / den[c];
                worst = worst.max((k[c].value * pl_alpha[l as usize] - brute).abs());
            }
        }
        eprintln!("SH vs brute-force sphere (κ = 1/mm): max diff {worst:e}");
        // Bound: the 1e-10 requested tolerance (times |P_l(cos α)| ≤ 1) plus the grid's error.
        // The narrowest Gaussian (σ = 0.08 rad on the unit sphere) spans ~25 GL nodes and ~30
        // φ samples per σ, where both rules converge spectrally (measured total: ~1e-13).
        assert!(worst < 2e-10, "{worst}");
    }

    /// k_0 and κ = 0 are 1 by definition (module docs): exact estimates, nothing integrated,
    /// from `sh_band` and from `sh_bands_estimates` alike; band 1 at κ > 0 is integrated.
    #[test]
    fn sh_band_zero_and_flat_spheres_integrate_nothing() {
        let p = default_skin_profile();
        let exact = [Estimate::exact(1.0); 3];
        assert_eq!(sh_band(&p, 0.0, 2, DEFAULT_TOLERANCE).unwrap(), exact);
        assert_eq!(sh_band(&p, 0.5, 0, DEFAULT_TOLERANCE).unwrap(), exact);
        let rows = sh_bands_estimates(&p, &[0.0, 0.5], &[0, 1], DEFAULT_TOLERANCE).unwrap();
        assert_eq!((rows[0][0], rows[0][1], rows[1][0]), (exact, exact, exact));
        assert!(rows[1][1].iter().all(|e| e.evals > 0 && e.value < 1.0));
    }

    /// A sphere of radius 1 mm reaches chords ≤ 2 mm; a profile that is zero out to 5 mm has no
    /// mass there, and k_l is refused as D is (rather than 0/0).
    #[test]
    fn a_sphere_that_reaches_no_profile_mass_is_refused() {
        let far = Profile::Tabulated { radius_mm: vec![5.0, 6.0], value: vec![[0.0; 3], [1.0; 3]] };
        assert!(matches!(sh_band(&far, 1.0, 1, DEFAULT_TOLERANCE), Err(ProfileError::NoMassWithinReach { channel: 0, .. })));
        assert!(matches!(sh_bands_estimates(&far, &[1.0], &[2], DEFAULT_TOLERANCE), Err(ProfileError::NoMassWithinReach { channel: 0, .. })));
    }
}
