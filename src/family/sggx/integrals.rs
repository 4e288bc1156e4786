//! SGGX filtering and storage of anisotropic GGX roughness (Ghost of Tsushima, "Anisotropic
//! specular maps and filtering"; Heitz et al. 2015, "The SGGX microflake distribution").
//!
//! Conventions. A texel holds a unit normal n = (x, y, z) in tangent space (z > −1) and a
//! symmetric 2×2 GGX matrix B = [[Sxx, Sxy], [Sxy, Syy]] in the normal-mapped frame
//! (t_n, b_n, n) = columns of M_n, where M_n rotates k = (0, 0, 1) onto n (the slide's matrix,
//! [`rotation_to`]). An anisotropic GGX lobe with roughness α_t, α_b along the direction at angle
//! ψ from t_n is B = R(ψ) diag(α_t², α_b²) R(ψ)ᵀ ([`Aniso::from_alphas`]).
//!
//! The SGGX matrix is S = M_n [[B, 0], [0, 1]] M_nᵀ; its NDF is
//!
//! ```text
//! D(m) = 1 / (π √|S| (mᵀ S⁻¹ m)²),
//! ```
//!
//! which is the anisotropic GGX NDF on the upper half (S = diag(α_t², α_b², 1) gives
//! 1/(π α_t α_b (x²/α_t² + y²/α_b² + z²)²)). The projected area of the microflakes along ω is
//! σ(ω) = ∫ ⟨ω, m⟩₊ D(m) dm = √(ωᵀ S ω); with S₃₃ = 1 in the normal's frame this is the GGX
//! normalisation ∫ D(h)(h·n) dh = 1. The course's rearranged form multiplies numerator and
//! denominator of Burley's form by (α_t α_b)⁴:
//!
//! ```text
//! D(h) = (α_t α_b)³ / (π ((t·h)² α_b² + (b·h)² α_t² + (n·h)² (α_t α_b)²)²).
//! ```
//!
//! Filtering: S′ = Σ wᵢ Sᵢ / Σ wᵢ (linear, so S′ stays symmetric positive definite: a convex
//! combination of SPD matrices); n′ is its dominant eigenvector, found by power iteration from
//! k (the normal is the axis of largest projected area as long as every α ≤ 1); the new block
//! is M_n′ᵀ S′ M_n′ divided by its (3, 3) entry (the corrected slide; without the division the
//! projected area along n′ would not be 1). Storage: [√Sxx, ½ Sxy/√(Sxx Syy) + ½, √Syy], each in
//! [0, 1] because the normalised block has eigenvalues ≤ 1 and |Sxy| ≤ √(Sxx Syy).
//!
//! The comparison of filters (the course's animation) measures distances between NDFs as
//! integrals over the sphere ([`SphereRule`]); every NDF is treated as a microflake
//! distribution, symmetric (D(m) = D(−m)), and normalised to unit mass before comparing shapes.
//!
//! Layout: here the matrices, frames, filtering, power iteration and block extraction;
//! `storage.rs` the 8/16-bit encoding and the course's decoder; `ndf.rs` the D forms, SGGX
//! lobes and LEAN; `sphere.rs` the sphere rule, mixtures, parameter estimation and distances.

use nalgebra::{Matrix2, Matrix3, Vector3};

mod ndf;
mod sphere;
mod storage;
pub use ndf::{D_CONSTS, D_FORM, Lean, Lobe, d_burley, d_rearranged, is_spd};
pub use sphere::{Distance, Mixture, Ndf, SphereRule, distance, estimate};
pub use storage::{DECODE_FORM, Decoded, decode_consts, decode_course, decode_matrix, encode, quantize};


pub type M3 = Matrix3<f64>;
pub type V3 = Vector3<f64>;

/// The smallest α the decoder returns: the course clamps to `GgxAlphaFromGloss(1.0)`, "an alpha
/// value of ~0.001" (the speaker notes); the gloss mapping itself is not given.
pub const ALPHA_MIN: f64 = 1e-3;

/// A symmetric 2×2 GGX matrix in the normal-mapped frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aniso {
    pub sxx: f64,
    pub sxy: f64,
    pub syy: f64,
}

impl Aniso {
    /// R(ψ) diag(α_t², α_b²) R(ψ)ᵀ: roughness α_t along (cos ψ, sin ψ) of the frame, α_b across.
    pub fn from_alphas(alpha_t: f64, alpha_b: f64, psi: f64) -> Aniso {
        let (s, c) = psi.sin_cos();
        let (a, b) = (alpha_t * alpha_t, alpha_b * alpha_b);
        Aniso { sxx: c * c * a + s * s * b, sxy: c * s * (a - b), syy: s * s * a + c * c * b }
    }

    pub fn isotropic(alpha: f64) -> Aniso {
        Aniso { sxx: alpha * alpha, sxy: 0.0, syy: alpha * alpha }
    }

    pub fn matrix(&self) -> Matrix2<f64> {
        Matrix2::new(self.sxx, self.sxy, self.sxy, self.syy)
    }

    /// Eigenvalues (α_t² ≥ α_b²) and the angle ψ of the α_t axis, in closed form.
    pub fn alphas(&self) -> (f64, f64, f64) {
        let discr = (4.0 * self.sxy * self.sxy + (self.sxx - self.syy).powi(2)).sqrt();
        let mean = 0.5 * (self.sxx + self.syy);
        let psi = 0.5 * (2.0 * self.sxy).atan2(self.sxx - self.syy);
        (mean + 0.5 * discr, mean - 0.5 * discr, psi)
    }

    /// Largest absolute difference of the three entries.
    pub fn max_diff(&self, o: &Aniso) -> f64 {
        (self.sxx - o.sxx).abs().max((self.sxy - o.sxy).abs()).max((self.syy - o.syy).abs())
    }
}

/// The slide's M_n: the rotation about k × n taking k = (0, 0, 1) onto the unit n = (x, y, z),
/// for every n on the sphere.
///
/// The slide writes its entries with r = 1/(1 + z), which loses every digit as n → −k (1 + z
/// cancels; at z = −1 it divides by zero). On the unit sphere 1 + z = (x² + y²)/(1 − z), so for
/// z < 0 the same entries are written with the azimuth (c, s) = (x, y)/ρ, ρ = √(x² + y²):
/// y² r = (1 − z) s², x y r = (1 − z) c s, x² r = (1 − z) c², each bounded by 2 and accurate to
/// a few ulps. At n = −k itself (ρ = 0) the axis k × n is undefined; the limit along φ = 0 is
/// taken (c, s) = (1, 0): the half turn about y, diag(−1, 1, −1). For z ≥ 0 the slide's
/// arithmetic is kept as it is.
pub fn rotation_to(n: V3) -> M3 {
    let (x, y, z) = (n.x, n.y, n.z);
    let (yy, xy, xx) = if z >= 0.0 {
        let r = 1.0 / (1.0 + z);
        (y * y * r, x * y * r, x * x * r)
    } else {
        let rho = x.hypot(y);
        let (c, s) = if rho > 0.0 { (x / rho, y / rho) } else { (1.0, 0.0) };
        let w = 1.0 - z;
        (w * s * s, w * c * s, w * c * c)
    };
    M3::new(z + yy, -xy, x, -xy, z + xx, y, -x, -y, z)
}

/// S = M_n [[B, 0], [0, 1]] M_nᵀ.
pub fn sggx_from(n: V3, a: Aniso) -> M3 {
    let m = rotation_to(n);
    let block = M3::new(a.sxx, a.sxy, 0.0, a.sxy, a.syy, 0.0, 0.0, 0.0, 1.0);
    m * block * m.transpose()
}

/// A unit vector from spherical angles (θ from z, φ from x).
pub fn direction(theta: f64, phi: f64) -> V3 {
    V3::from(crate::shading::direction(theta, phi))
}

/// The weighted mean Σ wᵢ Sᵢ / Σ wᵢ.
pub fn filter(texels: &[(f64, M3)]) -> M3 {
    let total: f64 = texels.iter().map(|t| t.0).sum();
    texels.iter().fold(M3::zeros(), |acc, (w, s)| acc + s * (*w / total))
}

/// The result of [`power_iteration`].
#[derive(Debug, Clone, Copy)]
pub struct Dominant {
    /// The unit dominant eigenvector, oriented to z ≥ 0.
    pub n: V3,
    /// Its Rayleigh quotient nᵀ S n.
    pub lambda: f64,
    pub iterations: usize,
    /// ‖S n − λ n‖ / λ at the end.
    pub residual: f64,
    pub converged: bool,
}

/// Relative residual ‖S n − λn‖/λ at which the power iteration stops: the eigenvector's angular
/// error is then about residual / (1 − λ₂/λ₁), and one more step costs nothing measurable.
pub const POWER_TOL: f64 = 1e-14;
pub const POWER_MAX_ITER: usize = 100_000;

/// Power iteration n_i = S n_{i−1} / ‖S n_{i−1}‖ from n_0 = (0, 0, 1) (the slide). Converges at
/// the rate λ₂/λ₁ per step: fast for a sharp dominant axis, slowly when a second axis has
/// nearly the normal's projected area (α → 1).
pub fn power_iteration(s: &M3) -> Dominant {
    let mut n = V3::new(0.0, 0.0, 1.0);
    let mut out = Dominant { n, lambda: 0.0, iterations: 0, residual: f64::INFINITY, converged: false };
    for i in 0..=POWER_MAX_ITER {
        let sn = s * n;
        let lambda = n.dot(&sn);
        let residual = (sn - lambda * n).norm() / lambda.abs().max(f64::MIN_POSITIVE);
        out = Dominant { n, lambda, iterations: i, residual, converged: residual <= POWER_TOL };
        if out.converged || i == POWER_MAX_ITER {
            break;
        }
        n = sn / sn.norm();
    }
    if out.n.z < 0.0 {
        out.n = -out.n;
    }
    out
}

/// A texel recovered from a filtered S′.
#[derive(Debug, Clone, Copy)]
pub struct Extracted {
    pub n: V3,
    pub aniso: Aniso,
    pub power: Dominant,
    /// The largest |(M_n′ᵀ S′ M_n′)ᵢ₃|/λ, i < 3: zero when n′ is exactly an eigenvector.
    pub off_block: f64,
}

/// n′ by power iteration, then the block of M_n′ᵀ S′ M_n′ divided by its (3, 3) entry.
pub fn extract(s: &M3) -> Extracted {
    let power = power_iteration(s);
    let m = rotation_to(power.n);
    let b = m.transpose() * s * m;
    let d = b[(2, 2)];
    let sym = |i: usize, j: usize| 0.5 * (b[(i, j)] + b[(j, i)]) / d;
    Extracted {
        n: power.n,
        aniso: Aniso { sxx: sym(0, 0), sxy: sym(0, 1), syy: sym(1, 1) },
        power,
        off_block: (b[(0, 2)].abs().max(b[(1, 2)].abs())) / d,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::rng::SplitMix64;
    use std::f64::consts::PI;

    #[test]
    fn alphas_invert_from_alphas() {
        // R(ψ) diag(α_t², α_b²) R(ψ)ᵀ has eigenvalues α_t², α_b² and its α_t axis at ψ
        // (ψ ∈ (−π/2, π/2]); 1e-15: a few ulps of entries ≤ 1.
        for (at, ab, psi) in [(0.8, 0.3, 0.4), (0.5, 0.1, -1.2), (0.9, 0.6, 1.5), (0.2, 0.05, 0.0)] {
            let (t2, b2, p) = Aniso::from_alphas(at, ab, psi).alphas();
            assert!((t2 - at * at).abs() < 1e-15 && (b2 - ab * ab).abs() < 1e-15, "{at} {ab} {psi}: {t2} {b2}");
            assert!((p - psi).abs() < 1e-12, "{at} {ab} {psi}: ψ {p}");
        }
    }

    pub(super) fn texel(theta: f64, phi: f64, at: f64, ab: f64, psi: f64) -> (V3, Aniso) {
        (direction(theta, phi), Aniso::from_alphas(at, ab, psi))
    }

    #[test]
    fn rotation_is_orthonormal_and_takes_k_to_n() {
        // Exact algebra in f64: entries of order 1, a few roundings each.
        for (t, p) in [(0.0, 0.0), (0.3, 1.0), (1.2, -2.0), (1.5, 3.0)] {
            let n = direction(t, p);
            let m = rotation_to(n);
            assert!((m * m.transpose() - M3::identity()).amax() < 1e-14);
            assert!((m.determinant() - 1.0).abs() < 1e-14);
            assert!((m * V3::z() - n).amax() < 1e-15);
        }
    }

    /// Over the whole sphere, the south pole and its neighbourhood included (where the slide's
    /// 1/(1 + z) loses every digit): orthonormal, proper, k onto n, and a rotation about k × n
    /// (the axis is fixed). 4e-15: entries bounded by 2, each a few roundings; the axis is
    /// normalised from a cross product whose length is sin θ ≥ 1e-9 / 2 here.
    #[test]
    fn rotation_is_exact_at_every_polar_angle_up_to_the_south_pole() {
        let mut thetas: Vec<f64> = (0..=64).map(|i| PI * i as f64 / 64.0).collect();
        thetas.extend([PI / 2.0 + 1e-12, PI - 1e-3, PI - 1e-6, PI - 1e-9, PI - 5e-10, 3.1415926, 3.14159265]);
        for &t in &thetas {
            for p in [0.0, 0.7, -2.5, PI] {
                let n = direction(t, p);
                let m = rotation_to(n);
                assert!((m * m.transpose() - M3::identity()).amax() < 4e-15, "θ {t}, φ {p}: {m}");
                assert!((m.determinant() - 1.0).abs() < 4e-15, "θ {t}, φ {p}");
                assert!((m * V3::z() - n).amax() < 4e-15, "θ {t}, φ {p}");
                let axis = V3::z().cross(&n);
                if axis.norm() > 1e-10 {
                    let u = axis / axis.norm();
                    assert!((m * u - u).amax() < 4e-15, "θ {t}, φ {p}: axis");
                }
            }
        }
        // n = −k exactly: the half turn about y (the limit along φ = 0).
        let m = rotation_to(V3::new(0.0, 0.0, -1.0));
        assert_eq!(m, M3::new(-1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -1.0));
    }

    #[test]
    fn filtering_keeps_spd_and_a_texel_filtered_with_itself_is_unchanged() {
        // Self-filter: S′ = S, so n′ is n to the power iteration's residual (1e-14 / (1 − λ₂/λ₁),
        // λ₂ ≤ 0.8² here: ≤ 3e-14) and the block to a few roundings of M_nᵀ S M_n: 1e-12.
        let mut rng = SplitMix64(11);
        for _ in 0..500 {
            let (n, a) = texel(1.5 * rng.next_f64(), 6.3 * rng.next_f64(), 0.02 + 0.78 * rng.next_f64(), 0.02 + 0.78 * rng.next_f64(), 6.3 * rng.next_f64());
            let s = sggx_from(n, a);
            let f = filter(&[(0.25, s), (0.75, s)]);
            assert!(is_spd(&f));
            let e = extract(&f);
            assert!(e.power.converged);
            assert!((e.n - n).amax() < 1e-12, "normal {:?} vs {n:?}", e.n);
            assert!(e.aniso.max_diff(&a) < 1e-12, "{:?} vs {a:?}", e.aniso);
        }
        // Random 2×2 footprints: S′ symmetric positive definite, the power iteration converges,
        // the extracted block's eigenvalues lie in (0, 1] (normalised by the largest projected
        // area) and n′ is the dominant eigenvector of nalgebra's symmetric eigensolver.
        let mut worst_iters = 0;
        for _ in 0..500 {
            let texels: Vec<(f64, M3)> = (0..4)
                .map(|_| {
                    let (n, a) = texel(1.2 * rng.next_f64(), 6.3 * rng.next_f64(), 0.02 + 0.9 * rng.next_f64(), 0.02 + 0.9 * rng.next_f64(), 6.3 * rng.next_f64());
                    (1.0, sggx_from(n, a))
                })
                .collect();
            let f = filter(&texels);
            assert!(is_spd(&f));
            let e = extract(&f);
            assert!(e.power.converged, "{:?}", e.power);
            worst_iters = worst_iters.max(e.power.iterations);
            let eig = nalgebra::SymmetricEigen::new(f);
            let k = eig.eigenvalues.imax();
            let v: V3 = eig.eigenvectors.column(k).into();
            let gap = 1.0 - {
                let mut l: Vec<f64> = eig.eigenvalues.iter().copied().collect();
                l.sort_by(f64::total_cmp);
                l[1] / l[2]
            };
            // Eigenvector angle ≈ residual / relative gap; 1e-14 residual over gaps ≥ 1e-4 here.
            assert!((1.0 - v.dot(&e.n).abs()) < 1e-12 + (1e-14 / gap).powi(2), "gap {gap}");
            let (l1, l2, _) = e.aniso.alphas();
            assert!(l2 > 0.0 && l1 <= 1.0 + 1e-12, "{l1} {l2}");
            // The block's off-diagonal column vanishes with the residual.
            assert!(e.off_block < 1e-13);
        }
        println!("power iteration: at most {worst_iters} iterations over 500 random 2×2 footprints");
        assert!(worst_iters > 3, "the test footprints never needed iterating");
    }

    /// The eigenvector is oriented to z ≥ 0 even where the iterates alternate in sign: a
    /// symmetric S whose dominant eigenvalue is negative (−3, its axis v = (1, 1, 1)/√3; 1 and
    /// 0.5 on the axes across it), turned a little each time so that the iteration ends on
    /// either parity. The result is +v to the residual.
    #[test]
    fn the_eigenvector_is_oriented_up_even_when_the_iterates_alternate() {
        let v = V3::new(1.0, 1.0, 1.0).normalize();
        // Two unit axes across v, turned by 0.1·k about it at turn k.
        let u0 = V3::new(1.0, -1.0, 0.0).normalize();
        let w0 = v.cross(&u0);
        let mut flipped = 0;
        for k in 0..8 {
            let (sn, cs) = (0.1 * k as f64).sin_cos();
            let (u, w) = (u0 * cs + w0 * sn, w0 * cs - u0 * sn);
            let s = -3.0 * v * v.transpose() + u * u.transpose() + 0.5 * w * w.transpose();
            let p = power_iteration(&s);
            assert!(p.converged, "turn {k}: {p:?}");
            assert!(p.n.z >= 0.0 && (p.n - v).norm() < 1e-12, "turn {k}: n = {}", p.n);
            // The raw iterate's sign: odd iteration counts end on −v (its z below 0).
            flipped += p.iterations % 2;
        }
        assert!(flipped > 0, "no turn ended on an odd iteration");
    }

    #[test]
    fn power_iteration_counts_follow_the_eigenvalue_ratio() {
        // The residual shrinks by λ₂/λ₁ per step: from 1 to 1e-14 takes ≈ ln(1e-14)/ln(λ₂/λ₁)
        // steps; a tilted isotropic lobe with α = 0.5 (ratio 0.25) needs ~23, α = 0.9 (0.81) ~150.
        // The counts are checked within a factor 1.5 of that estimate (the start's projection
        // on the other axes sets the constant).
        for alpha in [0.5f64, 0.9] {
            let s = sggx_from(direction(0.6, 0.3), Aniso::isotropic(alpha));
            let p = power_iteration(&s);
            let predicted = (1e-14f64).ln() / (alpha * alpha).ln();
            assert!(p.converged);
            assert!((p.iterations as f64) < 1.5 * predicted && (p.iterations as f64) > predicted / 1.5, "α {alpha}: {} vs {predicted}", p.iterations);
        }
        // Flat normals: k is an eigenvector and the start is the answer.
        assert_eq!(power_iteration(&sggx_from(V3::z(), Aniso::from_alphas(0.5, 0.1, 0.3))).iterations, 0);
    }

    /// A power iteration cut off at POWER_MAX_ITER reports the residual of its last iterate,
    /// ‖S n − λn‖/λ with λ = nᵀS n (recomputed here), and `extract` the off-block column of that
    /// n over λ: the column (M_nᵀ S n)₀,₁ is M_nᵀ r for r = S n − λn ⊥ n, so its largest entry
    /// lies in [‖r‖/√2, ‖r‖]. The lobe (α = 0.99999: the residual shrinks by α² a step, ≈ 1.6
    /// million steps to converge, ≈ e^-2 of the way at the cut) is scaled by 4 so that λ ≈ 4 and
    /// a missing division by λ shows; 4 is
    /// a power of two, so the iterates, and the block divided by its (3, 3) entry, are exactly
    /// those of the unscaled lobe.
    #[test]
    fn a_cut_off_iteration_reports_its_own_residual_and_off_block_column() {
        let s1 = sggx_from(direction(0.6, 0.3), Aniso::isotropic(0.99999));
        let s = s1 * 4.0;
        let e = extract(&s);
        let p = e.power;
        assert!(!p.converged && p.iterations == POWER_MAX_ITER, "{p:?}");
        let sn = s * p.n;
        let lambda = p.n.dot(&sn);
        let residual = (sn - lambda * p.n).norm() / lambda;
        // λ: one dot product (1e-15 relative). The residual (≈ 2e-6: the start's distance from n
        // is itself ≈ 1 − α²): r ≈ 7e-6 from entries ≈ 4 rounded to ≈ 1e-15 each, so ≈ 1e-9
        // relative; bound 1e-6 (the mutants are off by factors ≥ 4).
        assert!((p.lambda / lambda - 1.0).abs() < 1e-15 && (lambda - 4.0).abs() < 1e-3, "λ {} vs {lambda}", p.lambda);
        assert!(residual > 1e-7 && (p.residual / residual - 1.0).abs() < 1e-6, "residual {} vs {residual}", p.residual);
        // The column through M_nᵀ S M_n rounds apart from r by the same ≈ 1e-9 relative.
        assert!(e.off_block > residual / 2f64.sqrt() * (1.0 - 1e-6) && e.off_block < residual * (1.0 + 1e-6), "off-block {} vs residual {residual}", e.off_block);
        let e1 = extract(&s1);
        assert_eq!((e.n, e.aniso), (e1.n, e1.aniso));
    }

    /// The block is normalised by the projected area along n′ (the module doc): two isotropic
    /// α = 0.3 lobes at ±30° about z filter to S′ = α²I + (1 − α²)·mean(n nᵀ) = diag(α² + ¼(1 −
    /// α²), α², α² + ¾(1 − α²)) = diag(0.3175, 0.09, 0.7725), whose dominant axis is z with
    /// λ = 0.7725; M_z is the identity, so the block is diag(0.3175, 0.09)/0.7725 (1e-12: a
    /// few roundings of entries ≤ 1; the off-diagonal entries cancel to rounding).
    #[test]
    fn the_extracted_block_is_divided_by_the_normals_projected_area() {
        let a = Aniso::isotropic(0.3);
        let tilt = std::f64::consts::FRAC_PI_6;
        let f = filter(&[(1.0, sggx_from(direction(tilt, 0.0), a)), (1.0, sggx_from(direction(tilt, PI), a))]);
        let e = extract(&f);
        assert!((e.n - V3::z()).norm() < 1e-12 && (e.power.lambda - 0.7725).abs() < 1e-12, "{:?}", e.power);
        let want = Aniso { sxx: 0.3175 / 0.7725, sxy: 0.0, syy: 0.09 / 0.7725 };
        assert!(e.aniso.max_diff(&want) < 1e-12, "{:?} vs {want:?}", e.aniso);
    }
}
