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

use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};
use std::f64::consts::PI;

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

/// The slide's M_n: the rotation about k × n taking k = (0, 0, 1) onto n = (x, y, z), z > −1.
pub fn rotation_to(n: V3) -> M3 {
    let (x, y, z) = (n.x, n.y, n.z);
    let r = 1.0 / (1.0 + z);
    M3::new(z + y * y * r, -x * y * r, x, -x * y * r, z + x * x * r, y, -x, -y, z)
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

// ---------------------------------------------------------------------------------------------
// Storage

/// [√Sxx, ½ Sxy/√(Sxx Syy) + ½, √Syy] (the middle channel ½ where Sxx Syy = 0).
pub fn encode(a: Aniso) -> [f64; 3] {
    let (x, z) = (a.sxx.max(0.0).sqrt(), a.syy.max(0.0).sqrt());
    let r = if x * z > 0.0 { (a.sxy / (x * z)).clamp(-1.0, 1.0) } else { 0.0 };
    [x, 0.5 * r + 0.5, z]
}

/// Each channel rounded to the nearest `bits`-bit UNORM value.
pub fn quantize(v: [f64; 3], bits: u32) -> [f64; 3] {
    let q = ((1u64 << bits) - 1) as f64;
    v.map(|c| (c.clamp(0.0, 1.0) * q).round() / q)
}

/// The matrix of stored channels (no clamp: the inverse of [`encode`]).
pub fn decode_matrix(t: [f64; 3]) -> Aniso {
    Aniso { sxx: t[0] * t[0], sxy: t[0] * (2.0 * t[1] - 1.0) * t[2], syy: t[2] * t[2] }
}

/// What the course's `DecodeSggx` returns, besides the rotated frame: α_t², α_b², α_t α_b and
/// the cosine and sine of the α_t axis's angle from t_n.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Decoded {
    pub alpha_t_sqr: f64,
    pub alpha_b_sqr: f64,
    pub alpha_tb: f64,
    pub cos: f64,
    pub sin: f64,
}

impl Decoded {
    /// The 2×2 matrix the decoded values describe.
    pub fn aniso(&self) -> Aniso {
        let (c, s) = (self.cos, self.sin);
        let (a, b) = (self.alpha_t_sqr, self.alpha_b_sqr);
        Aniso { sxx: c * c * a + s * s * b, sxy: c * s * (a - b), syy: s * s * a + c * c * b }
    }
}

/// `DecodeSggx` in f64, line for line (`Sign` read as ±1, see the body): eigenvalues of the 2×2 matrix clamped to [α_min², 1]
/// (guarding the indefinite matrices that filtering the encoded channels produces), the
/// rotation from the half-angle identity cos²ψ = ½((Sxx − Syy)/discr + 1).
pub fn decode_course(t: [f64; 3], alpha_min: f64) -> Decoded {
    let a = decode_matrix(t);
    let discr = (4.0 * a.sxy * a.sxy + (a.sxx - a.syy).powi(2)).sqrt();
    let discr_rcp = 1.0 / discr.max(1e-6);
    let floor = alpha_min * alpha_min;
    let alpha_t_sqr = (0.5 * (a.sxx + a.syy + discr)).clamp(0.0, 1.0).max(floor);
    let alpha_b_sqr = (0.5 * (a.sxx + a.syy - discr)).clamp(0.0, 1.0).max(floor);
    let c_sqr = (0.5 * ((a.sxx - a.syy) * discr_rcp + 1.0)).clamp(0.0, 1.0);
    // The listing's `Sign` must not return 0: at Sxy = 0 with Sxx < Syy (an axis-aligned lobe
    // rougher along b_n, or the texture unit's halfway mix of ±ρ) cos ψ = 0, and HLSL's sign(0) = 0
    // would make the sine 0 too, collapsing the frame. Sign(x) = x < 0 ? −1 : 1 here.
    let sign = if a.sxy < 0.0 { -1.0 } else { 1.0 };
    Decoded {
        alpha_t_sqr,
        alpha_b_sqr,
        alpha_tb: (alpha_t_sqr * alpha_b_sqr).sqrt(),
        cos: c_sqr.sqrt(),
        sin: sign * (1.0 - c_sqr).sqrt(),
    }
}

// ---------------------------------------------------------------------------------------------
// NDFs

/// The anisotropic GGX NDF in the course's rearranged form, from h's components in the
/// (t, b, n) frame.
pub fn d_rearranged(th: f64, bh: f64, nh: f64, alpha_t_sqr: f64, alpha_b_sqr: f64, alpha_tb: f64) -> f64 {
    let den = th * th * alpha_b_sqr + bh * bh * alpha_t_sqr + nh * nh * alpha_tb * alpha_tb;
    alpha_tb.powi(3) / (PI * den * den)
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

// ---------------------------------------------------------------------------------------------
// Integrals over the sphere

/// A product rule on the sphere: composite Gauss–Legendre in θ ∈ [0, π] and φ ∈ [0, 2π], the
/// weights carrying sin θ. Smooth integrands with features wider than a panel converge at the
/// rule's order; lobes of width α need panels narrower than α.
#[derive(Debug, Clone)]
pub struct SphereRule {
    pub points: Vec<(V3, f64)>,
}

impl SphereRule {
    /// `theta_panels` × `phi_panels` panels of `order`-point rules.
    pub fn new(theta_panels: usize, phi_panels: usize, order: usize) -> SphereRule {
        let (x, w) = crate::integrate::gauss_legendre(order);
        let axis = |panels: usize, len: f64| -> Vec<(f64, f64)> {
            let h = len / panels as f64;
            (0..panels).flat_map(|p| x.iter().zip(&w).map(move |(xi, wi)| (h * (p as f64 + 0.5 * (xi + 1.0)), 0.5 * h * wi))).collect::<Vec<_>>()
        };
        let thetas = axis(theta_panels, PI);
        let phis = axis(phi_panels, 2.0 * PI);
        let mut points = Vec::with_capacity(thetas.len() * phis.len());
        for &(t, wt) in &thetas {
            for &(p, wp) in &phis {
                points.push((direction(t, p), wt * wp * t.sin()));
            }
        }
        SphereRule { points }
    }

    /// The rule the comparisons use: 2.4 mrad-wide nodes near the densest lobes (α ≥ 0.1).
    pub fn standard() -> SphereRule {
        SphereRule::new(160, 320, 8)
    }

    pub fn integrate(&self, f: impl Fn(&V3) -> f64) -> f64 {
        self.points.iter().map(|(m, w)| w * f(m)).sum()
    }
}

/// A microflake NDF to compare: an SGGX lobe, a mixture of them, or LEAN's (made symmetric).
pub trait Ndf: Sync {
    fn d(&self, m: &V3) -> f64;
}

impl Ndf for Lobe {
    fn d(&self, m: &V3) -> f64 {
        Lobe::d(self, m)
    }
}

/// A weighted sum of SGGX lobes, each with unit projected area along its own normal.
#[derive(Debug, Clone)]
pub struct Mixture {
    pub lobes: Vec<(f64, Lobe)>,
}

impl Ndf for Mixture {
    fn d(&self, m: &V3) -> f64 {
        let total: f64 = self.lobes.iter().map(|l| l.0).sum();
        self.lobes.iter().map(|(w, l)| w * l.d(m)).sum::<f64>() / total
    }
}

impl Mixture {
    /// σ(ω) = Σ wᵢ √(ωᵀSᵢω) / Σ wᵢ.
    pub fn projected_area(&self, w: &V3) -> f64 {
        let total: f64 = self.lobes.iter().map(|l| l.0).sum();
        self.lobes.iter().map(|(k, l)| k * l.projected_area(w)).sum::<f64>() / total
    }
}

/// LEAN's upper-half NDF mirrored to the lower half, as the microflakes are.
impl Ndf for Lean {
    fn d(&self, m: &V3) -> f64 {
        Lean::d(self, &if m.z < 0.0 { -m } else { *m })
    }
}

/// SGGX parameter estimation (Heitz et al. 2015): the axes are the eigenvectors of the
/// mixture's second moment ∫ m mᵀ D(m) dm (numerically, on `rule`), and the eigenvalue on each
/// axis ωₖ is the squared projected area σ(ωₖ)² of the mixture (exact: Σ wᵢ √(ωₖᵀSᵢωₖ)).
pub fn estimate(mix: &Mixture, rule: &SphereRule) -> M3 {
    use rayon::prelude::*;
    let d: Vec<f64> = rule.points.par_iter().map(|(m, _)| mix.d(m)).collect();
    let mut c = M3::zeros();
    for ((m, w), d) in rule.points.iter().zip(&d) {
        c += m * m.transpose() * (w * d);
    }
    let eig = nalgebra::SymmetricEigen::new(c);
    let mut s = M3::zeros();
    for k in 0..3 {
        let axis: V3 = eig.eigenvectors.column(k).into();
        let sigma = mix.projected_area(&axis);
        s += axis * axis.transpose() * (sigma * sigma);
    }
    s
}

/// How far apart two NDFs are, as normalised distributions p = D/∫D on the sphere.
#[derive(Debug, Clone, Copy)]
pub struct Distance {
    /// Total variation ½∫|p − q| (0: same shape, 1: disjoint).
    pub tv: f64,
    /// √∫(p − q)².
    pub l2: f64,
    /// max |p − q| on the rule's nodes, and where (θ, φ): the first node, in the rule's order,
    /// that reaches it.
    pub max: f64,
    pub worst: (f64, f64),
    /// ∫D of each.
    pub mass: (f64, f64),
}

/// [`Distance`] of `a` and `b` on `rule` (values in parallel, sums in node order).
pub fn distance(a: &dyn Ndf, b: &dyn Ndf, rule: &SphereRule) -> Distance {
    use rayon::prelude::*;
    let da: Vec<f64> = rule.points.par_iter().map(|(m, _)| a.d(m)).collect();
    let db: Vec<f64> = rule.points.par_iter().map(|(m, _)| b.d(m)).collect();
    let ma: f64 = rule.points.iter().zip(&da).map(|((_, w), d)| w * d).sum();
    let mb: f64 = rule.points.iter().zip(&db).map(|((_, w), d)| w * d).sum();
    let (mut tv, mut l2, mut max, mut worst) = (0.0, 0.0, 0.0, (0.0, 0.0));
    for ((m, w), (x, y)) in rule.points.iter().zip(da.iter().zip(&db)) {
        let e = (x / ma - y / mb).abs();
        tv += w * e;
        l2 += w * e * e;
        if e > max {
            max = e;
            worst = (m.z.clamp(-1.0, 1.0).acos(), m.y.atan2(m.x));
        }
    }
    Distance { tv: 0.5 * tv, l2: l2.sqrt(), max, worst, mass: (ma, mb) }
}

/// A deterministic stream in [0, 1) (xorshift64*), for seeded random cases.
#[derive(Debug, Clone)]
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545F4914F6CDD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn encode_of_a_singular_block_has_middle_channel_one_half() {
        // The doc: the middle channel is ½ where Sxx·Syy = 0; the others are √Sxx, √Syy.
        assert_eq!(encode(Aniso { sxx: 0.25, sxy: 0.0, syy: 0.0 }), [0.5, 0.5, 0.0]);
        assert_eq!(encode(Aniso { sxx: 0.0, sxy: 0.0, syy: 0.64 }), [0.0, 0.5, 0.8]);
        // And a regular one: Sxy/√(Sxx Syy) = 0.03/(0.5·0.3) = 0.2, stored 0.6.
        let e = encode(Aniso { sxx: 0.25, sxy: 0.03, syy: 0.09 });
        assert!((e[0] - 0.5).abs() < 1e-16 && (e[1] - 0.6).abs() < 1e-15 && (e[2] - 0.3).abs() < 1e-16, "{e:?}");
    }

    fn texel(theta: f64, phi: f64, at: f64, ab: f64, psi: f64) -> (V3, Aniso) {
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

    #[test]
    fn sggx_ndf_is_the_anisotropic_ggx_d_and_the_rearranged_form() {
        // D of S = M_n R diag(α_t², α_b², 1) Rᵀ M_nᵀ at h, against Burley's closed form in the
        // rotated frame (t, b, n) = M_n R; and the rearranged form against the same. Both are
        // rational expressions of a few terms in f64: agreement to 1e-12 relative.
        let mut rng = Rng(7);
        for _ in 0..200 {
            let n = direction(1.4 * rng.next(), 6.3 * rng.next());
            let (at, ab, psi) = (0.01 + 0.99 * rng.next(), 0.01 + 0.99 * rng.next(), 6.3 * rng.next());
            let lobe = Lobe::new(sggx_from(n, Aniso::from_alphas(at, ab, psi))).unwrap();
            let m = rotation_to(n);
            let (s, c) = psi.sin_cos();
            let t: V3 = m * V3::new(c, s, 0.0);
            let b: V3 = m * V3::new(-s, c, 0.0);
            let h = direction(1.5 * rng.next(), 6.3 * rng.next());
            let (th, bh, nh) = (t.dot(&h), b.dot(&h), n.dot(&h));
            let burley = d_burley(th, bh, nh, at, ab);
            let rearranged = d_rearranged(th, bh, nh, at * at, ab * ab, at * ab);
            assert!((lobe.d(&h) / burley - 1.0).abs() < 1e-12, "{} vs {burley}", lobe.d(&h));
            assert!((rearranged / burley - 1.0).abs() < 1e-12);
        }
    }

    /// An NDF given by a closure, for the distance tests.
    struct Field<G: Fn(&V3) -> f64 + Sync>(G);
    impl<G: Fn(&V3) -> f64 + Sync> Ndf for Field<G> {
        fn d(&self, m: &V3) -> f64 {
            (self.0)(m)
        }
    }

    /// `distance` compares two NDFs as distributions p = D/∫D:
    /// - a lobe and three times that lobe are the same distribution (to rounding: p ≤ 1.1, as
    ///   ∫D ≥ ∫D|m·n| = 2 and D ≤ 1/(π α_t α_b) = 2.2 here, so each |p − q| is a few ulps of 1,
    ///   and TV ≤ ½·4π of that; measured 4e-16 at most; bound 1e-14);
    /// - D_a = 1 against D_b = 3 above the horizon and 1 below: p = 1/4π, q = 3/8π above and
    ///   1/8π below, so |p − q| = 1/8π everywhere: TV ½·4π/8π = ¼, L2 √(4π)/8π = 1/(4√π), max
    ///   1/8π, masses 4π and 8π. The θ panels end at π/2, where the indicator jumps, so the rule
    ///   integrates both pieces at its order (8 points on panels of π/8 give sin θ to ~1e-16);
    ///   the sums over 16 384 nodes round by up to 3e-13 (measured, on 8π); bound 1e-12;
    /// - a narrow bump added to a constant: the worst node is the one nearest the bump, within
    ///   the node spacing (8-point panels of π/32: nodes at most 0.018 apart, so the nearest
    ///   is within 0.013 in θ and 0.013/sin θ in φ; bound 0.03 rad).
    #[test]
    fn distance_compares_normalised_distributions() {
        let rule = SphereRule::new(8, 16, 8);
        let (n, a) = texel(0.6, 1.1, 0.5, 0.3, 0.2);
        let lobe = Lobe::new(sggx_from(n, a)).unwrap();
        let thrice = Field(|m: &V3| 3.0 * lobe.d(m));
        let d = distance(&lobe, &thrice, &rule);
        assert!(d.tv < 1e-14 && d.l2 < 1e-14 && d.max < 1e-14, "{d:?}");
        assert!((d.mass.1 / d.mass.0 - 3.0).abs() < 1e-13, "{d:?}");

        let one = Field(|_: &V3| 1.0);
        let step = Field(|m: &V3| if m.z > 0.0 { 3.0 } else { 1.0 });
        let d = distance(&one, &step, &rule);
        let close = |x: f64, want: f64| (x - want).abs() < 1e-12;
        assert!(close(d.tv, 0.25) && close(d.l2, 0.25 / PI.sqrt()) && close(d.max, 0.125 / PI), "{d:?}");
        assert!(close(d.mass.0, 4.0 * PI) && close(d.mass.1, 8.0 * PI), "{d:?}");

        let rule = SphereRule::new(32, 64, 8);
        for (theta, phi) in [(0.9, 2.2), (2.4, -1.0)] {
            let peak = direction(theta, phi);
            let bump = Field(move |m: &V3| 1.0 + 50.0 * (40.0 * (m.dot(&peak) - 1.0)).exp());
            let d = distance(&one, &bump, &rule);
            let dphi = (d.worst.1 - phi + PI).rem_euclid(2.0 * PI) - PI;
            assert!((d.worst.0 - theta).abs() < 0.03 && dphi.abs() < 0.03, "({theta}, {phi}): {d:?}");
        }
    }

    #[test]
    fn ndf_is_normalised_and_projects_to_the_closed_form_area() {
        // ∫_{h·n>0} D(h)(h·n) dh = 1 and ∫ ⟨ω,m⟩₊ D dm = √(ωᵀSω), on the sphere rule. The lobes
        // (α ≥ 0.2) span > 80 nodes per α; the kink of ⟨·⟩₊ crosses panels, so the rule is
        // first-order there: measured error ≈ 2e-6 at this resolution, bounded by 1e-5.
        let rule = SphereRule::new(96, 192, 8);
        for (t, p, at, ab, psi) in [(0.0, 0.0, 0.2, 0.2, 0.0), (0.7, 0.4, 0.5, 0.2, 1.0), (1.2, 2.0, 1.0, 0.3, -0.4)] {
            let (n, a) = texel(t, p, at, ab, psi);
            let lobe = Lobe::new(sggx_from(n, a)).unwrap();
            let norm = rule.integrate(|m| lobe.d(m) * m.dot(&n).max(0.0));
            assert!((norm - 1.0).abs() < 1e-5, "normalisation {norm}");
            let w = direction(0.9, -1.0);
            let area = rule.integrate(|m| lobe.d(m) * m.dot(&w).max(0.0));
            assert!((area - lobe.projected_area(&w)).abs() < 1e-5, "{area} vs {}", lobe.projected_area(&w));
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
    fn filtering_keeps_spd_and_a_texel_filtered_with_itself_is_unchanged() {
        // Self-filter: S′ = S, so n′ is n to the power iteration's residual (1e-14 / (1 − λ₂/λ₁),
        // λ₂ ≤ 0.8² here: ≤ 3e-14) and the block to a few roundings of M_nᵀ S M_n: 1e-12.
        let mut rng = Rng(11);
        for _ in 0..500 {
            let (n, a) = texel(1.5 * rng.next(), 6.3 * rng.next(), 0.02 + 0.78 * rng.next(), 0.02 + 0.78 * rng.next(), 6.3 * rng.next());
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
                    let (n, a) = texel(1.2 * rng.next(), 6.3 * rng.next(), 0.02 + 0.9 * rng.next(), 0.02 + 0.9 * rng.next(), 6.3 * rng.next());
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

    #[test]
    fn encode_decode_round_trip() {
        // Unquantised: decode ∘ encode is the identity to f64 rounding of a product of three
        // values ≤ 1 (1e-15). Quantised to b bits, each channel moves ≤ 2^-(b+1); Sxx = x² moves
        // ≤ 2x·δ + δ² ≤ 2^-b + 2^-2(b+1), and Sxy = x(2y−1)z by ≤ (1 + 2 + 1)δ(1 + δ)².
        let mut rng = Rng(3);
        for bits in [8u32, 16] {
            let delta = 0.5 / ((1u64 << bits) - 1) as f64;
            let bound = 4.0 * delta * (1.0 + delta).powi(2);
            let mut worst: f64 = 0.0;
            for _ in 0..10_000 {
                let a = Aniso::from_alphas(rng.next(), rng.next(), 6.3 * rng.next());
                assert!(decode_matrix(encode(a)).max_diff(&a) < 1e-15);
                let e = decode_matrix(quantize(encode(a), bits)).max_diff(&a);
                worst = worst.max(e);
            }
            println!("{bits}-bit round trip: max |ΔS| {worst:.3e} (bound {bound:.3e})");
            assert!(worst <= bound && worst > 0.1 * bound, "{bits} bits: {worst} vs {bound}");
        }
    }

    #[test]
    fn course_decoder_recovers_alphas_and_axis_and_guards_indefinite_matrices() {
        // Exact channels: α², the axis and the matrix come back to f64 rounding amplified by
        // 1/discr where the eigenvalues nearly coincide (here discr ≥ 1e-3: 1e-12).
        let mut rng = Rng(5);
        for _ in 0..1000 {
            let (at, ab) = (0.05 + 0.95 * rng.next(), 0.05 + 0.95 * rng.next());
            if (at * at - ab * ab).abs() < 1e-3 {
                continue;
            }
            let a = Aniso::from_alphas(at, ab, 6.3 * rng.next());
            let d = decode_course(encode(a), ALPHA_MIN);
            assert!(d.aniso().max_diff(&a) < 1e-12, "{:?} vs {a:?}", d.aniso());
            assert!((d.alpha_t_sqr - at.max(ab).powi(2)).abs() < 1e-12);
            // α_t α_b, the product of the two roots (the same 1e-12 of rounding).
            assert!((d.alpha_tb - at * ab).abs() < 1e-12, "α_t α_b {} vs {}", d.alpha_tb, at * ab);
            assert!((d.cos * d.cos + d.sin * d.sin - 1.0).abs() < 1e-12);
        }
        // Channels in [0, 1] always decode to a positive semi-definite matrix: |2y − 1| ≤ 1 gives
        // Sxy² ≤ Sxx Syy. Filtering the channels (not S) therefore reaches singular matrices,
        // not indefinite ones: the mean of (1, 1, 1) (Sxy = +1, rank 1) and (0, 1, 0) is
        // (½, 1, ½), of rank 1, whose zero eigenvalue the decoder clamps to α_min².
        for _ in 0..10_000 {
            let m = decode_matrix([rng.next(), rng.next(), rng.next()]);
            assert!(m.sxx * m.syy - m.sxy * m.sxy >= -1e-16);
        }
        let mix = [0.5, 1.0, 0.5];
        let m = decode_matrix(mix);
        assert_eq!(m.sxx * m.syy - m.sxy * m.sxy, 0.0, "the average is singular");
        let d = decode_course(mix, ALPHA_MIN);
        assert_eq!(d.alpha_b_sqr, ALPHA_MIN * ALPHA_MIN);
        assert!((d.alpha_t_sqr - 0.5).abs() < 1e-15 && d.alpha_tb > 0.0);
    }

    #[test]
    fn decoder_keeps_the_frame_of_axis_aligned_lobes_rougher_along_b() {
        // Sxy = 0 exactly, Sxx < Syy (α 0.25 along t_n, 0.5 along b_n): cos ψ = 0, so sin ψ must
        // be ±1 (HLSL's sign(0) = 0 would give a zero tangent). Exact: the channels 0.25, 0.5,
        // 0.5 and every operation on them are exact in binary.
        // Sign(0) = +1 (the listing's Sign as read here, and the emitted decoder's): sin ψ = +1.
        let d = decode_course(encode(Aniso { sxx: 0.0625, sxy: 0.0, syy: 0.25 }), ALPHA_MIN);
        assert_eq!((d.cos, d.sin), (0.0, 1.0));
        assert_eq!((d.alpha_t_sqr, d.alpha_b_sqr), (0.25, 0.0625));
    }

    #[test]
    fn parameter_estimation_of_one_lobe_is_that_lobe() {
        // Heitz et al.: estimation returns an SGGX input unchanged. The axes come from the
        // quadrature of the second moment (exact eigenvectors up to its ~1e-6 error over the
        // eigenvalue gap ≥ 0.2) and the areas are closed forms, so S is recovered to 1e-5.
        let rule = SphereRule::new(96, 192, 8);
        let (n, a) = texel(0.6, 0.8, 0.5, 0.2, 0.7);
        let s = sggx_from(n, a);
        let mix = Mixture { lobes: vec![(1.0, Lobe::new(s).unwrap())] };
        let est = estimate(&mix, &rule);
        assert!((est - s).amax() < 1e-5, "{est} vs {s}");
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

    /// `quantize` returns the nearest of the 2^b values k/(2^b − 1): every 8-bit code k/255
    /// comes back exactly, and so does a value 0.3/255 either side of it; values outside
    /// [0, 1] clamp to the ends; at 16 bits the step is 1/65535.
    #[test]
    fn quantize_rounds_to_the_nearest_unorm_code() {
        for k in 0..=255u32 {
            let code = k as f64 / 255.0;
            let near = [code, (k as f64 + 0.3) / 255.0, (k as f64 - 0.3).max(0.0) / 255.0];
            assert_eq!(quantize(near, 8), [code; 3], "code {k}");
        }
        assert_eq!(quantize([-0.2, 1.7, 0.5], 8), [0.0, 1.0, 128.0 / 255.0]);
        assert_eq!(quantize([1000.4 / 65535.0, 0.0, 1.0], 16), [1000.0 / 65535.0, 0.0, 1.0]);
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

    /// A mixture's D is the weight-normalised sum of its lobes' (weights 1 and 3: a quarter and
    /// three quarters), and its projected area the same mean of the lobes' √(ωᵀSω); the sphere
    /// rule's ∫⟨ω, m⟩₊ D dm of the mixture is that area. The lobes (α ≥ 0.3) span > 40 nodes per
    /// α on this rule; the kink of ⟨·⟩₊ makes it first order there (2e-6 at twice the panels in
    /// the normalisation test, so ≈ 4e-6 here); bound 1e-4.
    #[test]
    fn a_mixture_is_the_weighted_mean_of_its_lobes() {
        let (n1, a1) = texel(0.3, 0.2, 0.5, 0.3, 0.4);
        let (n2, a2) = texel(1.0, 2.5, 0.8, 0.4, -1.0);
        let (s1, s2) = (sggx_from(n1, a1), sggx_from(n2, a2));
        let (l1, l2) = (Lobe::new(s1).unwrap(), Lobe::new(s2).unwrap());
        let mix = Mixture { lobes: vec![(1.0, l1), (3.0, l2)] };
        for m in [direction(0.3, 0.2), direction(1.0, 2.5), direction(2.0, -1.0)] {
            let want = 0.25 * l1.d(&m) + 0.75 * l2.d(&m);
            assert!((Ndf::d(&mix, &m) / want - 1.0).abs() < 1e-14, "{m}");
        }
        let rule = SphereRule::new(48, 96, 8);
        for w in [direction(0.9, -1.0), V3::z()] {
            let want = 0.25 * w.dot(&(s1 * w)).sqrt() + 0.75 * w.dot(&(s2 * w)).sqrt();
            assert!((mix.projected_area(&w) / want - 1.0).abs() < 1e-14, "{w}");
            let area = rule.integrate(|m| Ndf::d(&mix, m) * m.dot(&w).max(0.0));
            assert!((area - want).abs() < 1e-4, "{w}: ∫ {area} vs {want}");
        }
    }

    /// Where |p − q| ties across nodes, the worst point is the first node, in the rule's order,
    /// that reaches the maximum: against a step (3 above the horizon, 1 below) every node
    /// above has one value of |p − q| and every node below another; the worst is the first
    /// node of the larger group, found here from |1/m_a − D_b/m_b| at the masses `distance`
    /// reports (checked by the test above).
    #[test]
    fn the_worst_point_of_tied_nodes_is_the_first() {
        let rule = SphereRule::new(8, 16, 8);
        let step = Field(|m: &V3| if m.z > 0.0 { 3.0 } else { 1.0 });
        let d = distance(&Field(|_: &V3| 1.0), &step, &rule);
        let (ma, mb) = d.mass;
        let e = |m: &V3| (1.0 / ma - step.d(m) / mb).abs();
        let first = rule.points.iter().position(|(m, _)| e(m) == d.max).unwrap();
        let ties = rule.points.iter().filter(|(m, _)| e(m) == d.max).count();
        assert!(ties > 1, "no tie");
        let m = rule.points[first].0;
        assert_eq!(d.worst, (m.z.clamp(-1.0, 1.0).acos(), m.y.atan2(m.x)), "first of {ties} tied nodes is {first}");
    }

    /// `Rng` is xorshift64* (Vigna 2016: x ^= x >> 12, x ^= x << 25, x ^= x >> 27, output the
    /// top 53 bits of x·0x2545F4914F6CDD1D). From x = 1: 1 >> 12 = 0, then 1 ^ 2²⁵, and
    /// (2²⁵ + 1) >> 27 = 0, so x₁ = 2²⁵ + 1; then x ^= x >> 12 adds 2¹³, x ^= x << 25 adds 2⁵⁰ +
    /// 2³⁸ and cancels 2²⁵, x ^= x >> 27 adds 2²³ + 2¹¹: x₂ = 2⁵⁰ + 2³⁸ + 2²³ + 2¹³ + 2¹¹ + 1.
    /// The next two states and the outputs are Python's integer arithmetic of the same steps.
    #[test]
    fn rng_is_xorshift64_star() {
        let mut rng = Rng(1);
        let outputs: Vec<f64> = (0..4).map(|_| rng.next()).collect();
        let mut states = Vec::new();
        let mut rng = Rng(1);
        for _ in 0..4 {
            rng.next();
            states.push(rng.0);
        }
        assert_eq!(states, [(1u64 << 25) + 1, (1u64 << 50) + (1 << 38) + (1 << 23) + (1 << 13) + (1 << 11) + 1, 0xd004003202803, 0x200340a005480e81]);
        let want = [2529537253518747u64, 6045066965290796, 6537840858852963, 2733948884444000].map(|k| k as f64 / (1u64 << 53) as f64);
        assert_eq!(outputs, want);
    }
}
