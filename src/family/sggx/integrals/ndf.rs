//! The NDFs: the anisotropic GGX D in the course's rearranged form and Burley's, SGGX lobes
//! (S, S⁻¹, √|S|) and LEAN mapping adapted to GGX (conventions in the module doc of `super`).

use super::{Aniso, M3, V3};
use crate::fit::expr::Expr;
use crate::fit::expr::program::{Program, build::*};
use std::sync::LazyLock;
use nalgebra::{Matrix2, Vector2};
use std::f64::consts::PI;

/// The anisotropic GGX NDF in the course's rearranged form written once, over (α_t², α_b²,
/// α_t α_b, t·h, b·h, n·h) (inputs 0–5, h's components in the (t, b, n) frame) with the
/// constants [`D_CONSTS`] = [π]:
/// ```text
/// den = (t·h)² α_b² + (b·h)² α_t² + (n·h)² (α_t α_b)²,   D = (α_t α_b)³ / (π max(den², 1e-30))
/// ```
/// Its f64 evaluation is [`d_rearranged`]; the emitted D (`super::super::emit`) is its WGSL,
/// Rust and f32 evaluation.
pub static D_FORM: LazyLock<Program> = LazyLock::new(|| {
    let (at2, ab2, atb, th, bh, nh, den) = (|| bind(0), || bind(1), || bind(2), || bind(3), || bind(4), || bind(5), || bind(6));
    let mut lets: Vec<(String, Expr)> = ["at2", "ab2", "atb", "th", "bh", "nh"].iter().enumerate().map(|(i, n)| (n.to_string(), var(i))).collect();
    lets.push(("den".into(), th() * th() * ab2() + bh() * bh() * at2() + nh() * nh() * (atb() * atb())));
    Program { lets, result: atb() * atb() * atb() / (k(0) * max(den() * den(), lit(1e-30))) }
});

/// The constants of [`D_FORM`].
pub const D_CONSTS: [f64; 1] = [PI];

/// The anisotropic GGX NDF in the course's rearranged form ([`D_FORM`] in f64), from h's
/// components in the (t, b, n) frame.
pub fn d_rearranged(th: f64, bh: f64, nh: f64, alpha_t_sqr: f64, alpha_b_sqr: f64, alpha_tb: f64) -> f64 {
    D_FORM.eval_f64(&[alpha_t_sqr, alpha_b_sqr, alpha_tb, th, bh, nh], &D_CONSTS)[0]
}

/// Burley's (2012) form 1 / (π α_t α_b ((t·h/α_t)² + (b·h/α_b)² + (n·h)²)²): the reference of
/// the rearranged form.
pub fn d_burley(th: f64, bh: f64, nh: f64, alpha_t: f64, alpha_b: f64) -> f64 {
    let q = (th / alpha_t).powi(2) + (bh / alpha_b).powi(2) + nh * nh;
    1.0 / (PI * alpha_t * alpha_b * q * q)
}

/// An SGGX lobe ready to evaluate: S, S⁻¹, √|S|.
#[derive(Debug, Clone, Copy)]
pub struct Lobe {
    pub s: M3,
    inv: M3,
    sqrt_det: f64,
}

impl Lobe {
    /// `None` unless S is symmetric positive definite.
    pub fn new(s: M3) -> Option<Lobe> {
        let det = s.determinant();
        if !(det > 0.0) || !is_spd(&s) {
            return None;
        }
        Some(Lobe { s, inv: s.try_inverse()?, sqrt_det: det.sqrt() })
    }

    /// D(m) = 1/(π √|S| (mᵀS⁻¹m)²), for a unit m.
    pub fn d(&self, m: &V3) -> f64 {
        let q = m.dot(&(self.inv * m));
        1.0 / (PI * self.sqrt_det * q * q)
    }

    /// σ(ω) = √(ωᵀ S ω).
    pub fn projected_area(&self, w: &V3) -> f64 {
        w.dot(&(self.s * w)).sqrt()
    }
}

/// Symmetric (to 1e-12 relative) with positive leading minors (Sylvester's criterion).
pub fn is_spd(s: &M3) -> bool {
    let scale = s.amax().max(f64::MIN_POSITIVE);
    (s - s.transpose()).amax() <= 1e-12 * scale
        && s[(0, 0)] > 0.0
        && s[(0, 0)] * s[(1, 1)] - s[(0, 1)] * s[(1, 0)] > 0.0
        && s.determinant() > 0.0
}

/// LEAN mapping (Olano and Baker 2010) adapted to GGX (σ = α/√2, so the second moment of a lobe
/// is its block over 2): the filtered first moment of the slopes μ = E[s] and second moment
/// E[ssᵀ + B/2], whose centred part times 2 is the filtered GGX slope matrix A. The NDF is the
/// GGX slope distribution centred on μ: P(s) = 1/(π √|A| (1 + (s−μ)ᵀA⁻¹(s−μ))²),
/// D(m) = P(s(m))/m_z⁴ with s(m) = (m_x/m_z, m_y/m_z), on the upper half.
#[derive(Debug, Clone, Copy)]
pub struct Lean {
    pub mean: Vector2<f64>,
    pub a: Matrix2<f64>,
    inv: Matrix2<f64>,
    sqrt_det: f64,
}

impl Lean {
    /// A texel's slope moments: the normal's slope and the block expressed as slopes of the
    /// macro-surface (LEAN adds the lobe's covariance in the tangent plane, unrotated).
    pub fn filter(texels: &[(f64, V3, Aniso)]) -> Option<Lean> {
        let total: f64 = texels.iter().map(|t| t.0).sum();
        let mut mean = Vector2::zeros();
        let mut second = Matrix2::zeros();
        for (w, n, a) in texels {
            let s = Vector2::new(n.x / n.z, n.y / n.z);
            mean += s * (*w / total);
            second += (s * s.transpose() + a.matrix() * 0.5) * (*w / total);
        }
        let a = (second - mean * mean.transpose()) * 2.0;
        let det = a.determinant();
        if !(det > 0.0) {
            return None;
        }
        Some(Lean { mean, a, inv: a.try_inverse()?, sqrt_det: det.sqrt() })
    }

    /// The filtered normal: (μ, 1) normalised (a normal n has the slope (n_x, n_y)/n_z here).
    pub fn normal(&self) -> V3 {
        V3::new(self.mean.x, self.mean.y, 1.0).normalize()
    }

    pub fn d(&self, m: &V3) -> f64 {
        if m.z <= 0.0 {
            return 0.0;
        }
        let s = Vector2::new(m.x / m.z, m.y / m.z) - self.mean;
        let q = 1.0 + s.dot(&(self.inv * s));
        1.0 / (PI * self.sqrt_det * q * q * m.z.powi(4))
    }
}

#[cfg(test)]
mod tests {
    use super::super::{direction, filter, rotation_to, sggx_from};
    use super::super::sphere::Ndf;
    use super::*;
    use crate::integrate::rng::SplitMix64;

    #[test]
    fn sggx_ndf_is_the_anisotropic_ggx_d_and_the_rearranged_form() {
        // D of S = M_n R diag(α_t², α_b², 1) Rᵀ M_nᵀ at h, against Burley's closed form in the
        // rotated frame (t, b, n) = M_n R; and the rearranged form against the same. The
        // rearranged form is a rational expression of a few terms in f64: agreement to 1e-12
        // relative. The lobe goes through S⁻¹: S is formed and inverted with errors δS of a few
        // ulps of ‖S‖ = 1, which move q = mᵀS⁻¹m by mᵀS⁻¹ δS S⁻¹m, at most ‖δS‖ q/α_min²
        // (‖S⁻¹m‖²/q ≤ λ_max(S⁻¹) = 1/min(α_t, α_b)²), and D ∝ q⁻² doubles that: the bound is
        // c·ε/α_min², c counting the roundings; c ≤ 6 was seen over 1200 random cases, 32 bounds it.
        let mut rng = SplitMix64(7);
        for _ in 0..200 {
            let n = direction(1.4 * rng.next_f64(), 6.3 * rng.next_f64());
            let (at, ab, psi) = (0.01 + 0.99 * rng.next_f64(), 0.01 + 0.99 * rng.next_f64(), 6.3 * rng.next_f64());
            let lobe = Lobe::new(sggx_from(n, Aniso::from_alphas(at, ab, psi))).unwrap();
            let m = rotation_to(n);
            let (s, c) = psi.sin_cos();
            let t: V3 = m * V3::new(c, s, 0.0);
            let b: V3 = m * V3::new(-s, c, 0.0);
            let h = direction(1.5 * rng.next_f64(), 6.3 * rng.next_f64());
            let (th, bh, nh) = (t.dot(&h), b.dot(&h), n.dot(&h));
            let burley = d_burley(th, bh, nh, at, ab);
            let rearranged = d_rearranged(th, bh, nh, at * at, ab * ab, at * ab);
            let cond = 1.0 / at.min(ab).powi(2);
            assert!((lobe.d(&h) / burley - 1.0).abs() < 32.0 * f64::EPSILON * cond, "{} vs {burley}", lobe.d(&h));
            assert!((rearranged / burley - 1.0).abs() < 1e-12);
        }
    }

    /// `is_spd` is Sylvester's criterion on a matrix symmetric to 1e-12 of its largest entry:
    /// an off-diagonal pair apart by 1e-13 of the scale passes and by 1e-10 fails, at scales 1e6
    /// and 1e-6 alike; a negative or zero first, second or third leading minor fails.
    #[test]
    fn is_spd_is_sylvesters_criterion_with_a_relative_symmetry_tolerance() {
        for scale in [1e6, 1e-6] {
            let with = |apart: f64| M3::new(1.0, 0.0, 0.0, apart, 2.0, 0.0, 0.0, 0.0, 3.0) * scale;
            assert!(is_spd(&with(0.0)) && is_spd(&with(1e-13)), "scale {scale}");
            assert!(!is_spd(&with(1e-10)), "scale {scale}");
        }
        let minors = [
            M3::new(-1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0),
            M3::new(1.0, 2.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0),
            M3::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -1.0),
            // Zero minors fail: the third (det 0), and the first or second even where the
            // asymmetry the tolerance admits (1e-14, 1e-13 of the scale 1) makes the later
            // minors positive: s₀₀ = 0 with second minor 1e-28 and det 1e-28; a singular leading
            // block [[1, 1], [1, 1]] with det 1e-26 (each exact in f64, nalgebra's cofactor sums).
            M3::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0),
            M3::new(0.0, -1e-14, 0.0, 1e-14, 1.0, 0.0, 0.0, 0.0, 1.0),
            M3::new(1.0, 1.0, 0.0, 1.0, 1.0, 1e-13, 1e-13, 0.0, 0.0),
        ];
        for m in minors {
            assert!(!is_spd(&m), "{m}");
        }
    }

    #[test]
    fn lean_equals_the_linear_filter_for_flat_normals() {
        // The course: "for flat normals, gives equivalent results". With n = k the slope mean is
        // 0 and A = Σ wᵢ Bᵢ, the linear filter's block; the NDFs agree to f64 rounding.
        let texels = [(1.0, V3::z(), Aniso::from_alphas(0.4, 0.1, 0.3)), (1.0, V3::z(), Aniso::from_alphas(0.2, 0.2, 0.0))];
        let lean = Lean::filter(&texels).unwrap();
        let s = filter(&texels.iter().map(|(w, n, a)| (*w, sggx_from(*n, *a))).collect::<Vec<_>>());
        let lobe = Lobe::new(s).unwrap();
        for m in [direction(0.1, 0.2), direction(0.5, 2.0), direction(1.3, -1.0)] {
            assert!((Ndf::d(&lean, &m) / lobe.d(&m) - 1.0).abs() < 1e-12);
        }
        // Tilted normals: LEAN's sheared lobe is no longer the rotated one.
        let tilted = [(1.0, direction(0.8, 0.0), Aniso::isotropic(0.2))];
        let lean = Lean::filter(&tilted).unwrap();
        let lobe = Lobe::new(sggx_from(tilted[0].1, tilted[0].2)).unwrap();
        let m = direction(0.8, 0.0);
        assert!((Ndf::d(&lean, &m) / lobe.d(&m) - 1.0).abs() > 0.1);
    }

    /// LEAN's filtered normal is the one of the mean slope: one texel gives its own normal back,
    /// and normals at ±0.5 rad about x with weights 3 and 1 give slopes ±tan 0.5 whose weighted
    /// mean, tan(0.5)/2, is the tangent of the filtered normal's angle (f64 rounding, 1e-15).
    #[test]
    fn lean_normal_is_the_mean_slopes_normal() {
        let n = direction(0.7, 2.0);
        let one = Lean::filter(&[(1.0, n, Aniso::isotropic(0.3))]).unwrap();
        assert!((one.normal() - n).norm() < 1e-15, "{} vs {n}", one.normal());
        let a = Aniso::isotropic(0.2);
        let two = Lean::filter(&[(3.0, direction(0.5, 0.0), a), (1.0, direction(0.5, PI), a)]).unwrap();
        let want = V3::new((0.5f64).tan() / 2.0, 0.0, 1.0).normalize();
        assert!((two.normal() - want).norm() < 1e-15, "{} vs {want}", two.normal());
    }

    /// LEAN's slope covariance: one tilted texel gives back its own block as A (its second
    /// moment s sᵀ + B/2 less μμᵀ, times 2), and its D is the GGX slope distribution centred on
    /// the normal's slope, written out here with the 2×2 inverse and determinant of B:
    /// 1/(π √|B| (1 + (s − μ)ᵀB⁻¹(s − μ))² m_z⁴), mirrored below the horizon. Two texels at
    /// ±0.5 rad about x with weights 3 and 1 (slopes ±t, t = tan 0.5) add twice the slopes'
    /// variance, 2(t² − (t/2)²) = 1.5 t², along x. 1e-14: rounding of a difference of
    /// second moments ≈ 1.
    #[test]
    fn lean_covariance_is_the_blocks_plus_twice_the_slopes() {
        let (n, b) = (direction(0.7, 2.0), Aniso::from_alphas(0.4, 0.15, 0.5));
        let lean = Lean::filter(&[(1.0, n, b)]).unwrap();
        assert!((lean.a - b.matrix()).amax() < 1e-14, "{} vs {}", lean.a, b.matrix());
        let det = b.sxx * b.syy - b.sxy * b.sxy;
        let mu = (n.x / n.z, n.y / n.z);
        for m in [n, direction(0.9, 2.3), direction(0.3, -1.0)] {
            let (sx, sy) = (m.x / m.z - mu.0, m.y / m.z - mu.1);
            let q = 1.0 + (b.syy * sx * sx - 2.0 * b.sxy * sx * sy + b.sxx * sy * sy) / det;
            let want = 1.0 / (PI * det.sqrt() * q * q * m.z.powi(4));
            // A rational expression of a few terms: 1e-12 relative.
            assert!((Lean::d(&lean, &m) / want - 1.0).abs() < 1e-12, "{m}: {} vs {want}", Lean::d(&lean, &m));
            assert_eq!(Ndf::d(&lean, &-m), Lean::d(&lean, &m));
        }
        let a = Aniso::isotropic(0.2);
        let t = (0.5f64).tan();
        let two = Lean::filter(&[(3.0, direction(0.5, 0.0), a), (1.0, direction(0.5, PI), a)]).unwrap();
        let want = Matrix2::new(0.04 + 1.5 * t * t, 0.0, 0.0, 0.04);
        assert!((two.a - want).amax() < 1e-14, "{} vs {want}", two.a);
    }
}
