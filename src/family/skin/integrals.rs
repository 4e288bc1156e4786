//! Pre-integrated skin shading: diffusion profiles, the punctual-light LUT D(n·l, κ) and the
//! SH-band scale factors k_l(κ) (Ghost of Tsushima course notes, "Skin shading improvements",
//! revising Penner & Borshukov, "Pre-Integrated Skin Shading", GPU Pro 2, 2011).
//!
//! # Units and conventions
//! - Distances in millimetres (mm), curvature κ = 1/r in 1/mm, variances in mm².
//! - Gaussian: G(v, r) = exp(−r²/(2v)) / (2πv), normalised in 2-D: ∫ G(v, r) 2πr dr = 1.
//! - Radial profile R(r) (1/mm²): light leaving the surface at distance r from a unit point
//!   source of irradiance; for a sum of Gaussians R(r) = Σ_i w_i G(v_i, r) per RGB channel, so
//!   ∫ R 2πr dr = Σ_i w_i (= 1 when the weights of a channel sum to 1).
//! - Linear profile P(x) (1/mm): response at distance x from an infinite line source,
//!   P(x) = ∫ R(√(x² + y²)) dy. For one Gaussian P(x) = exp(−x²/(2v)) / √(2πv), so
//!   ∫ P dx = Σ_i w_i. For a tabulated (piecewise-linear) R it is an Abel transform, which this
//!   module evaluates exactly segment by segment (see [`Profile::linear`]).
//! - Channels are linear RGB; nothing here applies tonemapping or gamma.
//!
//! # Punctual lights: ring (cylinder) integration with the *linear* profile
//! A directional light hits a cylinder of radius r = 1/κ perpendicular to its axis; the
//! irradiance at angle x around the axis from the point of interest is max(cos(θ + x), 0),
//! θ = acos(n·l). The 3-D distance between two points of the cylinder, at angular offset x
//! and axial offset y, is √(c² + y²) with chord c = 2r·sin(|x|/2), so integrating the radial
//! profile over the axial direction gives *exactly* the linear profile of the chord:
//!
//!   D(θ, κ) = ∫_{−π}^{π} max(cos(θ + x), 0) · K(2r·sin(|x|/2)) dx / ∫_{−π}^{π} K(2r·sin(|x|/2)) dx,
//!
//! with K = P ([`Kernel::Linear`], the seed's recommendation). [`Kernel::Radial`] uses K = R,
//! Penner's original ring, which applies the 2-D (point-source) profile to a 1-D cross-section
//! of the surface and so under-counts the scattering along the cylinder's axis. The denominator normalises the kernel over the ring, so the overall scale of a
//! profile never matters. D ∈ [0, 1]; κ → 0 gives max(n·l, 0) (κ = 0 is returned exactly);
//! κ → ∞ gives the ring average 1/π.
//!
//! Numerics. The integration variable is the arc length u = r·x (mm), folded onto u ≥ 0 by the
//! evenness of K: N = ∫_0^{u_max} [max(cos(θ + κu), 0) + max(cos(θ − κu), 0)] K(c(u)) du and
//! Den = 2 ∫_0^{u_max} K(c(u)) du, c(u) = 2 sin(κu/2)/κ. The domain stops where the kernel
//! vanishes: for Gaussians at chord 9σ_max (tail mass beyond it < 3e-18 of the weight), for a
//! table at its last radius; u_max = min(πr, 2r·asin(c_max/(2r))). So for small κ the
//! quadrature sits where the mass is, whatever r. The interval is split at the kinks of the
//! clamped cosine (κu = π/2 − θ, 3π/2 − θ, θ − π/2, θ + π/2, where inside), at the chord
//! distances 2σ_i and 5σ_i of every Gaussian (or at every table knot), and panels where the
//! clamped cosine is identically zero are skipped; a globally adaptive Gauss–Kronrod (G10/K21)
//! rule, run on all three channels at once, refines from there.
//!
//! # SH lighting: spherical integration with the *radial* profile
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
//! # Tolerances
//! Every result carries a per-channel [`Estimate`]; the adaptive rule stops when each channel's
//! summed |Kronrod − Gauss| estimate is ≤ max(tol.abs, tol.rel·|value|) of the *final* quantity
//! (the ratio's error is propagated from numerator and denominator). [`DEFAULT_TOLERANCE`]
//! (abs 1e-10) costs ≈ 400 integrand evaluations (≈ 10 µs) per RGB texel: a 256×256 LUT with
//! κ ≤ 1/mm takes ≈ 0.6 s on one core. The estimate is pessimistic: the reported estimates stay
//! ≤ 3e-11 and the actual difference to abs-1e-14 results is at rounding level (~1e-15).
//!
//! # LUTs and specs
//! [`punctual_grid_estimates`] and [`sh_bands_estimates`] tabulate the two quantities on any
//! grid (rows in parallel, collected in order); [`CurvatureMapping`] spreads the curvature
//! rows (linear or sqrt). The specs `fits/skin_punctual_lut.toml` (D, 65 n·l × 64 κ ≤ 1/mm) and
//! `fits/skin_sh_lut.toml` (k_1, k_2, 64 κ ≤ 1/mm) are `kind = "skin-lut"` (`spec::skin`, with
//! the profile from `spec::profile`), built by `pipeline::skin` into textures and lookups. The
//! curvature to look them up with is the directional one along the light (shadefit-runtime's
//! `skin::skin_curvature_from_light*`).
//!
//! # Seed notes
//! The seed's slide formula D(r, cos θ_l) = ∫ cos(θ_l − θ) R(2r sin(θ/2)) dθ / ∫ R(…) dθ omits the
//! clamp max(·, 0) on the cosine (Penner's code saturates it); the speaker notes say to use the
//! linear profile for the ring ("which can be obtained by pre-integrating the radial profile"),
//! and the radial profile with spherical integration for SH ("cylinders are not radially
//! symmetric"). The curvature must be the directional curvature κ_l = lᵀ II l in the light's
//! projected direction, not the mean curvature; concave curvature is clamped to 0 in the seed,
//! and this module requires κ ≥ 0.

// RGB loops index several arrays by channel; the QUADPACK constants keep their published digits.
#![allow(clippy::needless_range_loop, clippy::excessive_precision)]

use crate::integrate::{Estimate, Options, Tolerance, integrate};
use rayon::prelude::*;
use std::f64::consts::PI;
use std::fmt;

/// One Gaussian term of a sum-of-Gaussians diffusion profile:
/// R(r) = Σ weight · exp(−r²/(2·variance)) / (2π·variance).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gaussian {
    /// Variance v (mm²) of the 2-D Gaussian (σ² per axis).
    pub variance_mm2: f64,
    /// RGB weight (dimensionless; the weights of a channel sum to its total diffuse reflectance
    /// share, 1 for the default profile).
    pub weight: [f64; 3],
}

/// d'Eon & Luebke's six-Gaussian fit of a three-layer skin diffusion profile (E. d'Eon and
/// D. Luebke, "Advanced Techniques for Realistic Real-Time Skin Rendering", GPU Gems 3,
/// chapter 14, 2007: the sum-of-Gaussians parameters of their three-layer skin model).
/// Variances in mm², with their Gaussian G(v, r) = exp(−r²/(2v))/(2πv):
///
/// | variance (mm²) | red   | green | blue  |
/// |----------------|-------|-------|-------|
/// | 0.0064         | 0.233 | 0.455 | 0.649 |
/// | 0.0484         | 0.100 | 0.336 | 0.344 |
/// | 0.187          | 0.118 | 0.198 | 0.000 |
/// | 0.567          | 0.113 | 0.007 | 0.007 |
/// | 1.99           | 0.358 | 0.004 | 0.000 |
/// | 7.41           | 0.078 | 0.000 | 0.000 |
///
/// Each channel's weights sum to 1.000. (Some public shaders evaluate these with
/// exp(−r²/v) and no 1/(2πv): that is a different, unnormalised kernel.)
pub const DEON_LUEBKE_SKIN: [Gaussian; 6] = [
    Gaussian { variance_mm2: 0.0064, weight: [0.233, 0.455, 0.649] },
    Gaussian { variance_mm2: 0.0484, weight: [0.100, 0.336, 0.344] },
    Gaussian { variance_mm2: 0.187, weight: [0.118, 0.198, 0.0] },
    Gaussian { variance_mm2: 0.567, weight: [0.113, 0.007, 0.007] },
    Gaussian { variance_mm2: 1.99, weight: [0.358, 0.004, 0.0] },
    Gaussian { variance_mm2: 7.41, weight: [0.078, 0.0, 0.0] },
];

/// A diffusion profile.
#[derive(Debug, Clone, PartialEq)]
pub enum Profile {
    /// Sum of 2-D normalised Gaussians with RGB weights.
    Gaussians(Vec<Gaussian>),
    /// Tabulated radial profile R(r_i) (1/mm², any overall scale), linearly interpolated in r,
    /// held at R(r_0) for r < r_0 and zero beyond the last radius. Radii strictly increasing,
    /// r_0 ≥ 0.
    Tabulated { radius_mm: Vec<f64>, value: Vec<[f64; 3]> },
}

/// The default profile: [`DEON_LUEBKE_SKIN`].
pub fn default_skin_profile() -> Profile {
    Profile::Gaussians(DEON_LUEBKE_SKIN.to_vec())
}

/// Which profile the ring integration of [`punctual`] uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kernel {
    /// Linear (line-source) profile P: exact for a cylinder (the seed's recommendation).
    Linear,
    /// Radial profile R on the ring (Penner & Borshukov 2011 as published).
    Radial,
}

/// Default tolerance of this module: 1e-10 absolute per channel on the final quantity.
pub const DEFAULT_TOLERANCE: Tolerance = Tolerance { abs: 1e-10, rel: 0.0, max_panels: 2000 };

const CHANNELS: [&str; 3] = ["red", "green", "blue"];

/// Why a profile (or the ring/sphere a curvature gives) cannot be used.
#[derive(Debug, Clone, PartialEq)]
pub enum ProfileError {
    /// A Gaussian profile with no terms.
    NoGaussians,
    /// Variance zero, negative, NaN or infinite.
    BadVariance { index: usize, variance_mm2: f64 },
    /// A weight (Gaussian) or tabulated value that is negative, NaN or infinite.
    BadWeight { index: usize, channel: usize, value: f64 },
    /// A channel whose profile is identically zero (cannot be normalised).
    ZeroChannel { channel: usize },
    /// Radii and values of a table differ in length.
    LengthMismatch { radii: usize, values: usize },
    /// Fewer than two table samples.
    TooFewSamples { len: usize },
    /// A table radius that is negative, NaN or infinite.
    BadRadius { index: usize, radius_mm: f64 },
    /// A table radius not strictly greater than the previous one.
    NonMonotoneRadius { index: usize, previous_mm: f64, radius_mm: f64 },
    /// The ring/sphere of this curvature holds none of the channel's profile (all of it lies
    /// beyond chord distance 2/κ).
    NoMassWithinReach { channel: usize, curvature_per_mm: f64 },
}

impl fmt::Display for ProfileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            ProfileError::NoGaussians => write!(f, "Gaussian profile has no terms"),
            ProfileError::BadVariance { index, variance_mm2 } => {
                write!(f, "Gaussian {index}: variance {variance_mm2} mm² must be finite and > 0")
            }
            ProfileError::BadWeight { index, channel, value } => write!(
                f,
                "item {index}, {} channel: value {value} must be finite and >= 0",
                CHANNELS[channel]
            ),
            ProfileError::ZeroChannel { channel } => {
                write!(f, "{} channel of the profile is identically zero", CHANNELS[channel])
            }
            ProfileError::LengthMismatch { radii, values } => {
                write!(f, "table has {radii} radii but {values} values")
            }
            ProfileError::TooFewSamples { len } => {
                write!(f, "table has {len} samples; at least 2 are needed")
            }
            ProfileError::BadRadius { index, radius_mm } => {
                write!(f, "table radius {index}: {radius_mm} mm must be finite and >= 0")
            }
            ProfileError::NonMonotoneRadius { index, previous_mm, radius_mm } => write!(
                f,
                "table radius {index}: {radius_mm} mm is not greater than radius {} ({previous_mm} mm)",
                index - 1
            ),
            ProfileError::NoMassWithinReach { channel, curvature_per_mm } => write!(
                f,
                "{} channel: no profile mass within chord 2/κ = {} mm (κ = {curvature_per_mm}/mm)",
                CHANNELS[channel],
                2.0 / curvature_per_mm
            ),
        }
    }
}

impl std::error::Error for ProfileError {}

impl Profile {
    /// Checks the profile: see [`ProfileError`] for what is rejected.
    pub fn validate(&self) -> Result<(), ProfileError> {
        let check_w = |index: usize, w: &[f64; 3]| -> Result<(), ProfileError> {
            for (channel, &value) in w.iter().enumerate() {
                if !(value.is_finite() && value >= 0.0) {
                    return Err(ProfileError::BadWeight { index, channel, value });
                }
            }
            Ok(())
        };
        match self {
            Profile::Gaussians(gs) => {
                if gs.is_empty() {
                    return Err(ProfileError::NoGaussians);
                }
                for (index, g) in gs.iter().enumerate() {
                    let v = g.variance_mm2;
                    if !(v.is_finite() && v > 0.0) {
                        return Err(ProfileError::BadVariance { index, variance_mm2: v });
                    }
                    check_w(index, &g.weight)?;
                }
            }
            Profile::Tabulated { radius_mm, value } => {
                if radius_mm.len() != value.len() {
                    return Err(ProfileError::LengthMismatch {
                        radii: radius_mm.len(),
                        values: value.len(),
                    });
                }
                if radius_mm.len() < 2 {
                    return Err(ProfileError::TooFewSamples { len: radius_mm.len() });
                }
                for (index, &r) in radius_mm.iter().enumerate() {
                    if !(r.is_finite() && r >= 0.0) {
                        return Err(ProfileError::BadRadius { index, radius_mm: r });
                    }
                    if index > 0 && r <= radius_mm[index - 1] {
                        return Err(ProfileError::NonMonotoneRadius {
                            index,
                            previous_mm: radius_mm[index - 1],
                            radius_mm: r,
                        });
                    }
                }
                for (index, w) in value.iter().enumerate() {
                    check_w(index, w)?;
                }
            }
        }
        let total = self.total();
        for (channel, &t) in total.iter().enumerate() {
            if t.is_nan() || t <= 0.0 {
                return Err(ProfileError::ZeroChannel { channel });
            }
        }
        Ok(())
    }

    /// Radial profile R(r) (1/mm²) at distance r (mm), per channel.
    pub fn radial(&self, r_mm: f64) -> [f64; 3] {
        let r = r_mm.abs();
        match self {
            Profile::Gaussians(gs) => {
                let mut out = [0.0; 3];
                for g in gs {
                    let v = g.variance_mm2;
                    let e = (-r * r / (2.0 * v)).exp() / (2.0 * PI * v);
                    for c in 0..3 {
                        out[c] += g.weight[c] * e;
                    }
                }
                out
            }
            Profile::Tabulated { .. } => Table::new(self).radial(r),
        }
    }

    /// Linear (line-source) profile P(x) = ∫ R(√(x² + y²)) dy (1/mm), per channel.
    ///
    /// Gaussians: exp(−x²/(2v))/√(2πv). Tables: with R(s) = a + b·s on a segment and
    /// q = √(s² − x²), ∫ R(s)·s/q ds = a·q + b·(s·q + x²·ln(s + q))/2, summed over the segments
    /// beyond |x| (P(x) = 2∫_{|x|} R(s) s/√(s² − x²) ds): exact, O(number of samples) per call.
    pub fn linear(&self, x_mm: f64) -> [f64; 3] {
        let x = x_mm.abs();
        match self {
            Profile::Gaussians(gs) => {
                let mut out = [0.0; 3];
                for g in gs {
                    let v = g.variance_mm2;
                    let e = (-x * x / (2.0 * v)).exp() / (2.0 * PI * v).sqrt();
                    for c in 0..3 {
                        out[c] += g.weight[c] * e;
                    }
                }
                out
            }
            Profile::Tabulated { .. } => Table::new(self).linear(x),
        }
    }

    /// ∫ R(r) 2πr dr over the plane (= ∫ P(x) dx), per channel, in closed form.
    pub fn total(&self) -> [f64; 3] {
        self.mass_within(f64::INFINITY)
    }

    /// ∫_0^{s} R(r) 2πr dr: the profile's mass within distance s (mm), in closed form.
    pub fn mass_within(&self, s_mm: f64) -> [f64; 3] {
        match self {
            Profile::Gaussians(gs) => {
                let mut out = [0.0; 3];
                for g in gs {
                    // ∫_0^s G(v, r) 2πr dr = 1 − exp(−s²/(2v)).
                    let m = -(-s_mm * s_mm / (2.0 * g.variance_mm2)).exp_m1();
                    for c in 0..3 {
                        out[c] += g.weight[c] * m;
                    }
                }
                out
            }
            Profile::Tabulated { .. } => Table::new(self).mass_within(s_mm),
        }
    }

    /// Distance (mm) beyond which the profile is zero (a table's last radius) or negligible
    /// (Gaussians: 9σ of the widest term, where exp(−r²/(2v)) < 2.6e-18).
    pub fn support_mm(&self) -> f64 {
        match self {
            Profile::Gaussians(gs) => {
                GAUSS_CUTOFF_SIGMAS
                    * gs.iter()
                        .filter(|g| g.weight.iter().any(|&w| w != 0.0))
                        .map(|g| g.variance_mm2.sqrt())
                        .fold(0.0, f64::max)
            }
            Profile::Tabulated { radius_mm, .. } => *radius_mm.last().unwrap_or(&0.0),
        }
    }
}

/// Gaussians are cut at this many σ: exp(−9²/2) = 2.6e-18.
const GAUSS_CUTOFF_SIGMAS: f64 = 9.0;
/// Exponent beyond which a Gaussian term is dropped (the same 9σ cut).
const GAUSS_CUTOFF_EXPONENT: f64 = 0.5 * GAUSS_CUTOFF_SIGMAS * GAUSS_CUTOFF_SIGMAS;

/// A tabulated profile prepared for evaluation: knots (with r = 0 prepended when r_0 > 0) and
/// per-segment lines R(s) = c0 + b·s.
struct Table {
    s: Vec<f64>,
    val: Vec<[f64; 3]>,
    c0: Vec<[f64; 3]>,
    b: Vec<[f64; 3]>,
}

impl Table {
    fn new(p: &Profile) -> Table {
        let Profile::Tabulated { radius_mm, value } = p else {
            unreachable!("Table::new on a Gaussian profile")
        };
        let mut s = Vec::with_capacity(radius_mm.len() + 1);
        let mut val = Vec::with_capacity(radius_mm.len() + 1);
        if radius_mm[0] > 0.0 {
            s.push(0.0);
            val.push(value[0]);
        }
        s.extend_from_slice(radius_mm);
        val.extend_from_slice(value);
        let n = s.len() - 1;
        let mut c0 = Vec::with_capacity(n);
        let mut b = Vec::with_capacity(n);
        for k in 0..n {
            let mut bk = [0.0; 3];
            let mut ck = [0.0; 3];
            for c in 0..3 {
                bk[c] = (val[k + 1][c] - val[k][c]) / (s[k + 1] - s[k]);
                ck[c] = val[k][c] - bk[c] * s[k];
            }
            b.push(bk);
            c0.push(ck);
        }
        Table { s, val, c0, b }
    }

    fn last(&self) -> f64 {
        *self.s.last().expect("validated table")
    }

    fn radial(&self, r: f64) -> [f64; 3] {
        let idx = self.s.partition_point(|&x| x <= r);
        if idx == 0 {
            return self.val[0];
        }
        if idx == self.s.len() {
            return if r == self.last() { *self.val.last().unwrap() } else { [0.0; 3] };
        }
        let k = idx - 1;
        let t = (r - self.s[k]) / (self.s[k + 1] - self.s[k]);
        std::array::from_fn(|c| self.val[k][c] + t * (self.val[k + 1][c] - self.val[k][c]))
    }

    fn linear(&self, x: f64) -> [f64; 3] {
        let mut out = [0.0; 3];
        if x >= self.last() {
            return out;
        }
        let first = self.s.partition_point(|&v| v <= x).saturating_sub(1);
        let x2 = x * x;
        for k in first..self.s.len() - 1 {
            let lo = self.s[k].max(x);
            let hi = self.s[k + 1];
            if hi <= lo {
                continue;
            }
            let q_lo = ((lo - x) * (lo + x)).max(0.0).sqrt();
            let q_hi = ((hi - x) * (hi + x)).sqrt();
            let dq = q_hi - q_lo;
            let log_term = if x2 > 0.0 { x2 * ((hi + q_hi) / (lo + q_lo)).ln() } else { 0.0 };
            let quad = 0.5 * (hi * q_hi - lo * q_lo + log_term);
            for c in 0..3 {
                out[c] += 2.0 * (self.c0[k][c] * dq + self.b[k][c] * quad);
            }
        }
        out
    }

    fn mass_within(&self, s_max: f64) -> [f64; 3] {
        let mut out = [0.0; 3];
        for k in 0..self.s.len() - 1 {
            let lo = self.s[k];
            let hi = self.s[k + 1].min(s_max);
            if hi <= lo {
                break;
            }
            // ∫ (c0 + b s) 2πs ds
            let d2 = (hi - lo) * (hi + lo) / 2.0;
            let d3 = (hi - lo) * (hi * hi + hi * lo + lo * lo) / 3.0;
            for c in 0..3 {
                out[c] += 2.0 * PI * (self.c0[k][c] * d2 + self.b[k][c] * d3);
            }
        }
        out
    }
}

/// A profile prepared as one kernel K(chord) (linear or radial).
enum Prepared {
    /// (coefficient per channel, 1/(2v)) per Gaussian with a nonzero weight.
    Gauss(Vec<([f64; 3], f64)>),
    TabRadial(Table),
    TabLinear(Table),
}

struct PreparedKernel {
    k: Prepared,
    /// Chord distance beyond which K is zero (or dropped).
    cutoff: f64,
    /// Chord distances where K changes scale or has kinks (ascending, all < cutoff).
    breaks: Vec<f64>,
}

impl PreparedKernel {
    fn new(p: &Profile, kernel: Kernel) -> PreparedKernel {
        let cutoff = p.support_mm();
        match p {
            Profile::Gaussians(gs) => {
                let mut terms = Vec::new();
                let mut breaks = Vec::new();
                for g in gs.iter().filter(|g| g.weight.iter().any(|&w| w != 0.0)) {
                    let v = g.variance_mm2;
                    let norm = match kernel {
                        Kernel::Linear => 1.0 / (2.0 * PI * v).sqrt(),
                        Kernel::Radial => 1.0 / (2.0 * PI * v),
                    };
                    terms.push((std::array::from_fn(|c| g.weight[c] * norm), 0.5 / v));
                    let sigma = v.sqrt();
                    breaks.extend([2.0 * sigma, 5.0 * sigma]);
                }
                breaks.retain(|&b| b < cutoff);
                breaks.sort_by(f64::total_cmp);
                breaks.dedup_by(|a, b| (*a - *b).abs() <= 1e-9 * b.abs());
                PreparedKernel { k: Prepared::Gauss(terms), cutoff, breaks }
            }
            Profile::Tabulated { .. } => {
                let t = Table::new(p);
                let breaks = t.s.iter().copied().filter(|&s| s > 0.0 && s < cutoff).collect();
                let k = match kernel {
                    Kernel::Linear => Prepared::TabLinear(t),
                    Kernel::Radial => Prepared::TabRadial(t),
                };
                PreparedKernel { k, cutoff, breaks }
            }
        }
    }

    #[inline]
    fn eval(&self, s: f64) -> [f64; 3] {
        match &self.k {
            Prepared::Gauss(terms) => {
                let s2 = s * s;
                let mut out = [0.0; 3];
                for (coef, a) in terms {
                    let x = a * s2;
                    if x < GAUSS_CUTOFF_EXPONENT {
                        let e = (-x).exp();
                        out[0] += coef[0] * e;
                        out[1] += coef[1] * e;
                        out[2] += coef[2] * e;
                    }
                }
                out
            }
            Prepared::TabRadial(t) => t.radial(s),
            Prepared::TabLinear(t) => t.linear(s),
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Vector-valued globally adaptive Gauss–Kronrod (G10/K21), all channels on shared panels.

/// Integrates the N-channel `f` over the union of `intervals` (disjoint; empty or reversed
/// ones are skipped) with `crate::integrate::integrate` and [`Options::per_component`]:
/// raw |K21 − G10| estimates, bisecting the panel that is worst relative to its channel's
/// target until every channel's summed error estimate is ≤ max(abs[c], rel·|value[c]|), or
/// `max_panels` is reached. Deterministic: ties broken by position, final sums in position order.
fn adaptive_vec<const N: usize>(
    intervals: &[(f64, f64)],
    abs: [f64; N],
    rel: f64,
    max_panels: usize,
    f: impl FnMut(f64) -> [f64; N],
) -> [Estimate; N] {
    let intervals: Vec<(f64, f64)> = intervals.iter().copied().filter(|(a, b)| b > a).collect();
    let r = integrate(&intervals, &Options::per_component(abs, rel, max_panels), f);
    std::array::from_fn(|i| Estimate { value: r.value[i], error: r.errors[i], evals: r.evals })
}

// ---------------------------------------------------------------------------------------------
// Punctual lights: the ring.

/// A ring of curvature κ > 0 with its kernel normalisation, reusable for every n·l.
struct Ring<'k> {
    kernel: &'k PreparedKernel,
    kappa: f64,
    /// Arc length (mm) beyond which the kernel vanishes (≤ πr).
    u_max: f64,
    /// Chord breakpoints mapped to arc length, with 0 and u_max: ascending.
    u_breaks: Vec<f64>,
    den: [Estimate; 3],
}

impl<'k> Ring<'k> {
    fn new(
        kernel: &'k PreparedKernel,
        kappa: f64,
        tol: Tolerance,
    ) -> Result<Ring<'k>, ProfileError> {
        let r = 1.0 / kappa;
        let arc = |chord: f64| 2.0 * (0.5 * chord * kappa).asin() / kappa;
        let u_max = if kernel.cutoff >= 2.0 * r { PI * r } else { arc(kernel.cutoff) };
        let mut u_breaks = vec![0.0];
        u_breaks.extend(kernel.breaks.iter().filter(|&&s| s < 2.0 * r).map(|&s| arc(s)));
        u_breaks.push(u_max);
        u_breaks.retain(|&u| u <= u_max);
        u_breaks.sort_by(f64::total_cmp);
        u_breaks.dedup();
        let intervals: Vec<(f64, f64)> = u_breaks.windows(2).map(|w| (w[0], w[1])).collect();
        // Relative accuracy of the denominator: its share of the final error is D·rel ≤ rel.
        let rel = (0.25 * tol.abs.max(tol.rel)).max(1e-15);
        let half = adaptive_vec(&intervals, [0.0; 3], rel, tol.max_panels, |u| {
            kernel.eval(2.0 * (0.5 * kappa * u).sin() / kappa)
        });
        let den =
            half.map(|e| Estimate { value: 2.0 * e.value, error: 2.0 * e.error, evals: e.evals });
        for (channel, d) in den.iter().enumerate() {
            if d.value.is_nan() || d.value <= 0.0 {
                return Err(ProfileError::NoMassWithinReach { channel, curvature_per_mm: kappa });
            }
        }
        Ok(Ring { kernel, kappa, u_max, u_breaks, den })
    }

    fn eval(&self, n_dot_l: f64, tol: Tolerance) -> [Estimate; 3] {
        let kappa = self.kappa;
        let ct = n_dot_l;
        let st = ((1.0 - n_dot_l) * (1.0 + n_dot_l)).sqrt();
        let theta = st.atan2(ct);
        // Kinks of max(cos(θ ± κu), 0) on κu ∈ (0, π].
        let mut cuts = self.u_breaks.clone();
        for k in [PI / 2.0 - theta, 1.5 * PI - theta, theta - PI / 2.0, theta + PI / 2.0] {
            let u = k / kappa;
            if u > 0.0 && u < self.u_max {
                cuts.push(u);
            }
        }
        cuts.sort_by(f64::total_cmp);
        cuts.dedup();
        let integrand_weight = |u: f64| -> (f64, f64) {
            let (sh, ch) = (0.5 * kappa * u).sin_cos();
            let cu = 1.0 - 2.0 * sh * sh;
            let su = 2.0 * sh * ch;
            let w = (ct * cu - st * su).max(0.0) + (ct * cu + st * su).max(0.0);
            (w, 2.0 * sh / kappa)
        };
        // Keep only panels where the clamped cosines are not identically zero.
        let intervals: Vec<(f64, f64)> = cuts
            .windows(2)
            .map(|w| (w[0], w[1]))
            .filter(|&(a, b)| integrand_weight(0.5 * (a + b)).0 > 0.0)
            .collect();
        let den = self.den;
        let abs: [f64; 3] = std::array::from_fn(|c| 0.5 * tol.abs * den[c].value);
        let num = adaptive_vec(&intervals, abs, 0.5 * tol.rel, tol.max_panels, |u| {
            let (w, chord) = integrand_weight(u);
            if w == 0.0 {
                return [0.0; 3];
            }
            let k = self.kernel.eval(chord);
            [w * k[0], w * k[1], w * k[2]]
        });
        std::array::from_fn(|c| {
            let d = den[c].value;
            let value = num[c].value / d;
            Estimate {
                value,
                error: num[c].error / d + value.abs() * den[c].error / d,
                evals: num[c].evals + den[c].evals,
            }
        })
    }
}

fn check_args(curvature_per_mm: f64, n_dot_l: f64) -> f64 {
    assert!(
        curvature_per_mm.is_finite() && curvature_per_mm >= 0.0,
        "curvature must be finite and >= 0 (clamp concave curvature to 0), got {curvature_per_mm}/mm"
    );
    assert!(!n_dot_l.is_nan(), "n·l is NaN");
    assert!(n_dot_l.abs() <= 1.0 + 1e-12, "n·l = {n_dot_l} is outside [-1, 1]");
    n_dot_l.clamp(-1.0, 1.0)
}

/// Curvatures this small are treated as exactly 0: the ring result then differs from
/// max(n·l, 0) by at most ~κ·support ≤ 1e-200.
fn is_flat(kappa: f64, support_mm: f64) -> bool {
    kappa * support_mm.max(1.0) < 1e-200
}

/// Punctual-light scattering D(θ, κ) per channel: the ring integral of the module docs, with
/// θ = acos(n·l) and curvature κ (1/mm) along the projected light direction.
///
/// κ = 0 returns max(n·l, 0) exactly. Panics on κ < 0, non-finite κ, or n·l outside [−1, 1]
/// (beyond 1e-12 of rounding, which is clamped).
pub fn punctual(
    profile: &Profile,
    kernel: Kernel,
    curvature_per_mm: f64,
    n_dot_l: f64,
    tol: Tolerance,
) -> Result<[Estimate; 3], ProfileError> {
    let nl = check_args(curvature_per_mm, n_dot_l);
    profile.validate()?;
    if is_flat(curvature_per_mm, profile.support_mm()) {
        return Ok([Estimate::exact(nl.max(0.0)); 3]);
    }
    let k = PreparedKernel::new(profile, kernel);
    let ring = Ring::new(&k, curvature_per_mm, tol)?;
    Ok(ring.eval(nl, tol))
}

/// n·l of LUT column i of n: uniform on [−1, 1], both ends included (θ = acos(n·l)).
pub fn lut_n_dot_l(i: usize, n: usize) -> f64 {
    -1.0 + 2.0 * i as f64 / (n - 1) as f64
}

/// κ (1/mm) of LUT row j of n: uniform on [0, κ_max], both ends included.
pub fn lut_curvature(j: usize, n: usize, kappa_max_per_mm: f64) -> f64 {
    kappa_max_per_mm * j as f64 / (n - 1) as f64
}

/// How LUT rows spread over κ ∈ [0, κ_max]: row j of n sits at the mapped coordinate
/// t_j = j/(n − 1) (ends included), and a lookup interpolates linearly in t.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum CurvatureMapping {
    /// t = κ/κ_max: uniform in curvature (Penner's LUT, uniform in 1/r).
    #[default]
    Linear,
    /// t = √(κ/κ_max): rows denser at small κ, where most of a face's curvature lies (a quarter
    /// of the rows below κ_max/16); costs a square root per lookup.
    Sqrt,
}

impl CurvatureMapping {
    /// κ/κ_max of t ∈ [0, 1].
    pub fn from_unit(self, t: f64) -> f64 {
        match self {
            CurvatureMapping::Linear => t,
            CurvatureMapping::Sqrt => t * t,
        }
    }

    /// The spec name ("linear", "sqrt").
    pub fn name(self) -> &'static str {
        match self {
            CurvatureMapping::Linear => "linear",
            CurvatureMapping::Sqrt => "sqrt",
        }
    }
}

/// κ (1/mm) at the mapped coordinate `t` ∈ [0, 1] (t = 1 gives κ_max exactly).
pub fn mapped_curvature(t: f64, kappa_max_per_mm: f64, mapping: CurvatureMapping) -> f64 {
    if t >= 1.0 { kappa_max_per_mm } else { kappa_max_per_mm * mapping.from_unit(t) }
}

/// Punctual-light LUT with per-texel estimates; row-major: index = j·n_nl + i, row j at
/// κ = [`lut_curvature`]`(j, n_kappa, κ_max)`, column i at n·l = [`lut_n_dot_l`]`(i, n_nl)`.
/// Samples sit on the grid points (ends included): a shader sampling with bilinear filtering
/// uses u = (0.5 + (n_nl − 1)·(n·l + 1)/2)/n_nl and v = (0.5 + (n_kappa − 1)·κ/κ_max)/n_kappa.
/// Rows are computed in parallel; the result does not depend on the thread count.
pub fn punctual_lut_estimates(
    profile: &Profile,
    kernel: Kernel,
    n_nl: usize,
    n_kappa: usize,
    kappa_max_per_mm: f64,
    tol: Tolerance,
) -> Result<Vec<[Estimate; 3]>, ProfileError> {
    assert!(n_nl >= 2 && n_kappa >= 2, "a LUT needs at least 2×2 samples");
    assert!(
        kappa_max_per_mm.is_finite() && kappa_max_per_mm >= 0.0,
        "κ_max must be finite and >= 0, got {kappa_max_per_mm}"
    );
    let nls: Vec<f64> = (0..n_nl).map(|i| lut_n_dot_l(i, n_nl)).collect();
    let kappas: Vec<f64> = (0..n_kappa).map(|j| lut_curvature(j, n_kappa, kappa_max_per_mm)).collect();
    punctual_grid_estimates(profile, kernel, &nls, &kappas, tol)
}

/// [`punctual`] on the tensor grid `n_dot_l` × `curvature_per_mm` (any points, e.g. a
/// non-uniform curvature mapping or a verification grid): index = j·n_dot_l.len() + i for
/// n·l = `n_dot_l[i]` and κ = `curvature_per_mm[j]`. One ring (kernel normalisation) per
/// curvature, rows in parallel, collected in order: the result does not depend on the thread
/// count. Panics on the arguments [`punctual`] panics on.
pub fn punctual_grid_estimates(
    profile: &Profile,
    kernel: Kernel,
    n_dot_l: &[f64],
    curvature_per_mm: &[f64],
    tol: Tolerance,
) -> Result<Vec<[Estimate; 3]>, ProfileError> {
    let nls: Vec<f64> = n_dot_l.iter().map(|&nl| check_args(0.0, nl)).collect();
    for &kappa in curvature_per_mm {
        check_args(kappa, 0.0);
    }
    profile.validate()?;
    let k = PreparedKernel::new(profile, kernel);
    let support = profile.support_mm();
    let rows: Vec<Result<Vec<[Estimate; 3]>, ProfileError>> = curvature_per_mm
        .par_iter()
        .map(|&kappa| {
            if is_flat(kappa, support) {
                return Ok(nls.iter().map(|nl| [Estimate::exact(nl.max(0.0)); 3]).collect());
            }
            let ring = Ring::new(&k, kappa, tol)?;
            Ok(nls.iter().map(|&nl| ring.eval(nl, tol)).collect())
        })
        .collect();
    let mut out = Vec::with_capacity(n_dot_l.len() * curvature_per_mm.len());
    for row in rows {
        out.extend(row?);
    }
    Ok(out)
}

/// Punctual-light LUT values (RGB), layout as in [`punctual_lut_estimates`].
pub fn punctual_lut(
    profile: &Profile,
    kernel: Kernel,
    n_nl: usize,
    n_kappa: usize,
    kappa_max_per_mm: f64,
    tol: Tolerance,
) -> Result<Vec<[f64; 3]>, ProfileError> {
    Ok(punctual_lut_estimates(profile, kernel, n_nl, n_kappa, kappa_max_per_mm, tol)?
        .into_iter()
        .map(|e| e.map(|x| x.value))
        .collect())
}

// ---------------------------------------------------------------------------------------------
// SH lighting: the sphere.

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
    use super::*;

    /// The spec names of the curvature mappings (what the skin specs write and read).
    #[test]
    fn curvature_mappings_are_named_as_in_the_specs() {
        assert_eq!(CurvatureMapping::Linear.name(), "linear");
        assert_eq!(CurvatureMapping::Sqrt.name(), "sqrt");
    }

    #[test]
    fn punctual_error_estimates_cover_the_error() {
        // At a loose tolerance the reported error must cover the distance to the same integral
        // at 1e-13 (whose own reported error is added; 1e-15 for rounding of values ≤ 1).
        let p = default_skin_profile();
        let loose = Tolerance { abs: 1e-4, rel: 0.0, max_panels: 2000 };
        let tight = Tolerance { abs: 1e-13, rel: 0.0, max_panels: 20_000 };
        for kernel in [Kernel::Linear, Kernel::Radial] {
            for kappa in [0.05, 0.3, 1.0, 3.0] {
                for nl in [-0.3, 0.0, 0.2, 0.7, 1.0] {
                    let a = punctual(&p, kernel, kappa, nl, loose).unwrap();
                    let b = punctual(&p, kernel, kappa, nl, tight).unwrap();
                    for c in 0..3 {
                        assert!(a[c].error >= 0.0, "{kernel:?} κ {kappa} n·l {nl} channel {c}: error {}", a[c].error);
                        let d = (a[c].value - b[c].value).abs();
                        assert!(d <= a[c].error + b[c].error + 1e-15, "{kernel:?} κ {kappa} n·l {nl} channel {c}: |Δ| {d:e} > error {:e}", a[c].error);
                    }
                }
            }
        }
    }
    use crate::integrate::adaptive;
    use std::time::Instant;

    fn tight() -> Tolerance {
        Tolerance { abs: 1e-14, rel: 0.0, max_panels: 20_000 }
    }

    /// Tent R(r) = c(1 − r/a) on [0, a]: exactly piecewise linear.
    fn tent(c: f64, a: f64) -> Profile {
        Profile::Tabulated { radius_mm: vec![0.0, a], value: vec![[c, 2.0 * c, 0.5 * c], [0.0; 3]] }
    }

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
    fn deon_luebke_constants_are_the_published_table() {
        // GPU Gems 3, chapter 14 (d'Eon & Luebke 2007), Table 14-1: "the sum-of-Gaussians
        // parameters for a three-layer skin model", variance (mm²) then red, green, blue weights,
        // as printed (three decimals), typed here from the table rather than from the constant.
        let table: [(f64, [f64; 3]); 6] = [
            (0.0064, [0.233, 0.455, 0.649]),
            (0.0484, [0.100, 0.336, 0.344]),
            (0.187, [0.118, 0.198, 0.0]),
            (0.567, [0.113, 0.007, 0.007]),
            (1.99, [0.358, 0.004, 0.0]),
            (7.41, [0.078, 0.0, 0.0]),
        ];
        assert_eq!(DEON_LUEBKE_SKIN.len(), table.len());
        for (g, (v, w)) in DEON_LUEBKE_SKIN.iter().zip(table) {
            // The same decimal literals parse to the same f64: exact equality.
            assert_eq!(g.variance_mm2, v);
            assert_eq!(g.weight, w);
        }
        // The chapter's own consistency: the variances grow, each channel's weights sum to 1
        // (a normalised profile, white total diffuse reflectance), and the profile the default
        // preset loads is this table.
        assert!(DEON_LUEBKE_SKIN.windows(2).all(|p| p[0].variance_mm2 < p[1].variance_mm2));
        assert_eq!(default_skin_profile(), Profile::Gaussians(table.iter().map(|&(v, w)| Gaussian { variance_mm2: v, weight: w }).collect()));
    }

    #[test]
    fn default_weights_sum_to_one() {
        // The published weights are given to 3 decimals and sum to 1.000 exactly in decimal;
        // in f64 the sum is within a few ulps.
        let t = default_skin_profile().total();
        for c in 0..3 {
            assert!((t[c] - 1.0).abs() < 1e-15, "channel {c}: {}", t[c]);
        }
        default_skin_profile().validate().unwrap();
    }

    #[test]
    fn gaussian_profiles_are_normalised() {
        let p = default_skin_profile();
        let tol = Tolerance { abs: 1e-15, rel: 1e-15, max_panels: 5000 };
        let end = 40.0; // 14.7σ of the widest term: the tail beyond is < 1e-40.
        for c in 0..3 {
            let radial = adaptive(0.0, end, tol, |r| p.radial(r)[c] * 2.0 * PI * r).value;
            let linear = 2.0 * adaptive(0.0, end, tol, |x| p.linear(x)[c]).value;
            // Quadrature to 1e-15 plus summation rounding: 1e-12 is a loose bound.
            assert!((radial - 1.0).abs() < 1e-12, "radial {c}: {radial}");
            assert!((linear - 1.0).abs() < 1e-12, "linear {c}: {linear}");
        }
    }

    #[test]
    fn linear_profile_is_line_integral_of_radial() {
        let tol = Tolerance { abs: 1e-14, rel: 1e-14, max_panels: 5000 };
        let tent_p = tent(3.0, 2.0);
        for p in [default_skin_profile(), tent_p.clone()] {
            for x in [0.0, 0.05, 0.3, 1.0, 1.9, 4.0] {
                let lin = p.linear(x);
                // Integrate y only over the support (r ≤ support): the tent ends with a kink at
                // r = a, and a G10/K21 panel reaching far beyond it can converge falsely.
                let s = p.support_mm();
                let y_end = ((s - x) * (s + x)).max(0.0).sqrt();
                for c in 0..3 {
                    let brute = 2.0
                        * adaptive(0.0, y_end, tol, |y| p.radial((x * x + y * y).sqrt())[c]).value;
                    // Quadrature tolerance 1e-14 on a smooth integrand (Gaussians: the 9σ cut
                    // drops < 3e-18); 1e-11 leaves room for rounding in the Abel sums.
                    assert!((lin[c] - brute).abs() < 1e-11, "x={x} c={c}: {} vs {brute}", lin[c]);
                }
            }
        }
        // Tent in closed form: P(x) = c[√(a²−x²) − (x²/a)·ln((a + √(a²−x²))/x)].
        let (c, a, x) = (3.0, 2.0, 0.7_f64);
        let q = (a * a - x * x).sqrt();
        let exact = c * (q - x * x / a * ((a + q) / x).ln());
        assert!((tent_p.linear(x)[0] - exact).abs() < 1e-14);
    }

    /// A tabulated profile is linear between its knots (|r|: radial), its last value at the last
    /// knot itself and 0 past it (R is 0 outside the measured radius).
    #[test]
    fn a_tabulated_profile_is_linear_between_knots_and_zero_past_the_last() {
        let p = Profile::Tabulated { radius_mm: vec![0.0, 1.0, 2.0], value: vec![[3.0, 6.0, 1.5], [2.0, 4.0, 1.0], [1.0, 2.0, 0.5]] };
        // Halfway: (3 + 2)/2 and the like, exact in binary.
        assert_eq!(p.radial(0.5), [2.5, 5.0, 1.25]);
        assert_eq!(p.radial(-1.5), [1.5, 3.0, 0.75]);
        assert_eq!(p.radial(2.0), [1.0, 2.0, 0.5]);
        assert_eq!(p.radial(2.0 + 1e-12), [0.0; 3]);
    }

    #[test]
    fn tabulated_normalisation_is_exact() {
        // ∫ c(1 − r/a) 2πr dr = πca²/3; piecewise-linear data integrate exactly (rounding only).
        let (c, a) = (3.0, 2.0);
        let t = tent(c, a).total();
        assert!((t[0] - PI * c * a * a / 3.0).abs() < 1e-13);
        let tol = Tolerance { abs: 1e-15, rel: 1e-15, max_panels: 5000 };
        let lin = 2.0 * adaptive(0.0, a, tol, |x| tent(c, a).linear(x)[0]).value;
        // P has an integrable log-type behaviour near x = a only in its derivative; 1e-11.
        assert!((lin - t[0]).abs() < 1e-11, "{lin} vs {}", t[0]);
    }

    #[test]
    fn zero_curvature_is_lambert() {
        let p = default_skin_profile();
        for kernel in [Kernel::Linear, Kernel::Radial] {
            for i in 0..=20 {
                let nl = -1.0 + i as f64 / 10.0;
                let d = punctual(&p, kernel, 0.0, nl, DEFAULT_TOLERANCE).unwrap();
                assert_eq!(d[0].value, nl.max(0.0));
                // κ = 1e-6/mm: the blur is ~κ·⟨|u|⟩ ≲ 1e-6 at the terminator and
                // κ²⟨u²⟩/2 ≲ 1e-11 elsewhere.
                let d = punctual(&p, kernel, 1e-6, nl, DEFAULT_TOLERANCE).unwrap();
                for c in 0..3 {
                    assert!((d[c].value - nl.max(0.0)).abs() < 2e-6, "{nl} {c} {:?}", d[c]);
                }
            }
        }
    }

    #[test]
    fn large_curvature_tends_to_ring_average() {
        // κ = 1e3/mm: r = 1 µm, the kernel is flat over the ring to (chord/σ_min)² ~ 4e-4.
        let p = default_skin_profile();
        for kernel in [Kernel::Linear, Kernel::Radial] {
            let d = punctual(&p, kernel, 1e3, 0.3, DEFAULT_TOLERANCE).unwrap();
            for c in 0..3 {
                assert!((d[c].value - 1.0 / PI).abs() < 1e-3, "{:?}", d[c]);
            }
        }
    }

    #[test]
    fn lut_range_monotonicity_and_kappa_zero_row() {
        let p = default_skin_profile();
        let (n_nl, n_k, kmax) = (65, 17, 2.0);
        for kernel in [Kernel::Linear, Kernel::Radial] {
            let lut = punctual_lut(&p, kernel, n_nl, n_k, kmax, DEFAULT_TOLERANCE).unwrap();
            assert_eq!(lut.len(), n_nl * n_k);
            for j in 0..n_k {
                for i in 0..n_nl {
                    let v = lut[j * n_nl + i];
                    for c in 0..3 {
                        // [0, 1] up to the 1e-10 tolerance.
                        assert!(v[c] >= -1e-10 && v[c] <= 1.0 + 1e-10, "{j} {i} {c} {}", v[c]);
                        if j == 0 {
                            assert_eq!(v[c], lut_n_dot_l(i, n_nl).max(0.0));
                        }
                        if i > 0 {
                            // Non-decreasing in n·l (a symmetric-decreasing kernel against a
                            // shifted clamped cosine); slack = twice the tolerance.
                            assert!(v[c] >= lut[j * n_nl + i - 1][c] - 2e-10);
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn convergence_default_vs_tight() {
        let p = default_skin_profile();
        let mut max_diff: f64 = 0.0;
        let mut max_est: f64 = 0.0;
        for kernel in [Kernel::Linear, Kernel::Radial] {
            for kappa in [1e-3, 0.01, 0.07, 0.3, 1.0, 3.0, 20.0] {
                for nl in [-1.0, -0.6, -0.1, -0.003, 0.0, 0.004, 0.2, 0.7, 1.0] {
                    let a = punctual(&p, kernel, kappa, nl, DEFAULT_TOLERANCE).unwrap();
                    let b = punctual(&p, kernel, kappa, nl, tight()).unwrap();
                    for c in 0..3 {
                        max_diff = max_diff.max((a[c].value - b[c].value).abs());
                        max_est = max_est.max(a[c].error);
                    }
                }
            }
        }
        eprintln!("punctual: max |default − tight| = {max_diff:e}, max estimate = {max_est:e}");
        // The requirement is 1e-6; the default asks for 1e-10 and the estimate must honour it.
        assert!(max_diff <= 1e-10, "{max_diff}");
        assert!(max_est <= 1e-10, "{max_est}");
    }

    #[test]
    fn lut_convergence_default_vs_tight() {
        // The LUTs as `shadefit build` tabulates them (fits/skin_*_lut.toml: 65 n·l × 64 κ on
        // [0, 1]/mm, 64 κ for SH), at the default tolerance and at 1e-14, over every texel and
        // channel; plus a tabulated profile and a sqrt curvature mapping on coarser grids.
        let p = default_skin_profile();
        let nls: Vec<f64> = (0..65).map(|i| lut_n_dot_l(i, 65)).collect();
        let kappas: Vec<f64> = (0..64).map(|j| lut_curvature(j, 64, 1.0)).collect();
        let diff = |a: &[[Estimate; 3]], b: &[[Estimate; 3]]| -> (f64, f64) {
            let d = a.iter().zip(b).flat_map(|(x, y)| (0..3).map(move |c| (x[c].value - y[c].value).abs()));
            let e = a.iter().flat_map(|x| x.iter().map(|e| e.error));
            (d.fold(0.0, f64::max), e.fold(0.0, f64::max))
        };
        let mut worst: f64 = 0.0;
        let mut worst_est: f64 = 0.0;
        for kernel in [Kernel::Linear, Kernel::Radial] {
            let a = punctual_grid_estimates(&p, kernel, &nls, &kappas, DEFAULT_TOLERANCE).unwrap();
            let b = punctual_grid_estimates(&p, kernel, &nls, &kappas, tight()).unwrap();
            let (d, e) = diff(&a, &b);
            eprintln!("punctual LUT 65×64 ({kernel:?}): max |default − tight| = {d:e}, max estimate {e:e}");
            worst = worst.max(d);
            worst_est = worst_est.max(e);
        }
        let sh_a = sh_bands_estimates(&p, &kappas, &[1, 2], DEFAULT_TOLERANCE).unwrap();
        let sh_b = sh_bands_estimates(&p, &kappas, &[1, 2], tight()).unwrap();
        let flat = |v: &[Vec<[Estimate; 3]>]| -> Vec<[Estimate; 3]> { v.iter().flatten().copied().collect() };
        let (d, e) = diff(&flat(&sh_a), &flat(&sh_b));
        eprintln!("SH LUT 64 (bands 1, 2): max |default − tight| = {d:e}, max estimate {e:e}");
        worst = worst.max(d);
        worst_est = worst_est.max(e);
        // The default profile sampled as a table (Abel-transformed kernel, knots as breaks) and
        // κ on a sqrt mapping up to 4/mm.
        let n = 120;
        let radius_mm: Vec<f64> = (0..=n).map(|i| 25.0 * (i as f64 / n as f64).powi(2)).collect();
        let value: Vec<[f64; 3]> = radius_mm.iter().map(|&r| p.radial(r)).collect();
        let t = Profile::Tabulated { radius_mm, value };
        let nls17: Vec<f64> = (0..17).map(|i| lut_n_dot_l(i, 17)).collect();
        let sqrt_k: Vec<f64> = (0..16).map(|j| mapped_curvature(j as f64 / 15.0, 4.0, CurvatureMapping::Sqrt)).collect();
        for kernel in [Kernel::Linear, Kernel::Radial] {
            let a = punctual_grid_estimates(&t, kernel, &nls17, &sqrt_k, DEFAULT_TOLERANCE).unwrap();
            let b = punctual_grid_estimates(&t, kernel, &nls17, &sqrt_k, tight()).unwrap();
            let (d, e) = diff(&a, &b);
            eprintln!("tabulated profile 17×16 sqrt κ ≤ 4 ({kernel:?}): max |default − tight| = {d:e}, max estimate {e:e}");
            worst = worst.max(d);
            worst_est = worst_est.max(e);
        }
        // The requirement is 1e-6 per channel; the default asks for 1e-10 and the adaptive rule's
        // estimate (a bound on |Kronrod − Gauss| summed over panels) must honour it; the tight
        // reference is itself within 1e-14, so the difference is bounded by 1e-10 + 1e-14.
        assert!(worst_est <= 1e-10, "{worst_est}");
        assert!(worst <= 1e-10 + 1e-14, "{worst}");
    }

    #[test]
    fn gaussian_weight_scale_cancels() {
        // D and k_l are normalised by the kernel's own integral: scaling every weight by 3
        // changes nothing beyond rounding (a few ulps of values ≤ 1, summed over ~400 nodes).
        let p = default_skin_profile();
        let scaled = Profile::Gaussians(
            DEON_LUEBKE_SKIN.iter().map(|g| Gaussian { weight: g.weight.map(|w| 3.0 * w), ..*g }).collect(),
        );
        assert_eq!(scaled.total().map(|t| (t - 3.0).abs() < 1e-15), [true; 3]);
        for (kappa, nl) in [(0.2, -0.1), (0.7, 0.4), (3.0, 0.0)] {
            let a = punctual(&p, Kernel::Linear, kappa, nl, DEFAULT_TOLERANCE).unwrap();
            let b = punctual(&scaled, Kernel::Linear, kappa, nl, DEFAULT_TOLERANCE).unwrap();
            let c = sh_band(&p, kappa, 2, DEFAULT_TOLERANCE).unwrap();
            let d = sh_band(&scaled, kappa, 2, DEFAULT_TOLERANCE).unwrap();
            for ch in 0..3 {
                assert!((a[ch].value - b[ch].value).abs() < 1e-13, "{kappa} {nl}");
                assert!((c[ch].value - d[ch].value).abs() < 1e-13, "{kappa}");
            }
        }
    }

    /// The seed's ring formula with the clamp, by composite Simpson over x ∈ [−π, π] in the
    /// raw angle (no folding, no cut-off, no chord mapping).
    fn brute_ring(p: &Profile, kernel: Kernel, kappa: f64, nl: f64, n: usize) -> [f64; 3] {
        let r = 1.0 / kappa;
        let theta = nl.acos();
        let h = 2.0 * PI / n as f64;
        let mut num = [0.0; 3];
        let mut den = [0.0; 3];
        for i in 0..=n {
            let x = -PI + i as f64 * h;
            let w = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            let chord = (2.0 * r * (0.5 * x).sin()).abs();
            let k = match kernel {
                Kernel::Linear => p.linear(chord),
                Kernel::Radial => p.radial(chord),
            };
            let cl = (theta + x).cos().max(0.0);
            for c in 0..3 {
                num[c] += w * cl * k[c];
                den[c] += w * k[c];
            }
        }
        std::array::from_fn(|c| num[c] / den[c])
    }

    #[test]
    fn punctual_matches_brute_force_ring() {
        let p = default_skin_profile();
        let mut worst: f64 = 0.0;
        for kernel in [Kernel::Linear, Kernel::Radial] {
            for kappa in [0.05, 0.5, 2.0] {
                for nl in [-0.5, 0.0, 0.35, 0.9] {
                    let d = punctual(&p, kernel, kappa, nl, DEFAULT_TOLERANCE).unwrap();
                    let b = brute_ring(&p, kernel, kappa, nl, 400_000);
                    for c in 0..3 {
                        worst = worst.max((d[c].value - b[c]).abs());
                    }
                }
            }
        }
        eprintln!("punctual vs brute-force Simpson ring: max diff {worst:e}");
        // Simpson with h = 1.6e-5 rad: the clamped cosine's kink costs O(h²) ≈ 3e-10 at most;
        // the narrowest Gaussian at κ = 0.05 spans 0.004 rad = 250 steps (negligible error).
        assert!(worst < 1e-9, "{worst}");
    }

    #[test]
    fn linear_and_radial_kernels_differ() {
        // The two variants agree at the limits but not in between; the radial kernel is
        // narrower in 1-D (it lacks the axial integration), so it scatters less.
        let p = default_skin_profile();
        let a = punctual(&p, Kernel::Linear, 0.5, 0.0, DEFAULT_TOLERANCE).unwrap();
        let b = punctual(&p, Kernel::Radial, 0.5, 0.0, DEFAULT_TOLERANCE).unwrap();
        eprintln!(
            "D(n·l=0, κ=0.5): linear {:?} radial {:?}",
            a.map(|e| e.value),
            b.map(|e| e.value)
        );
        for c in 0..3 {
            assert!(a[c].value > b[c].value + 1e-3);
        }
    }

    #[test]
    fn lut_timing_256() {
        let p = default_skin_profile();
        let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        let t0 = Instant::now();
        let est = pool
            .install(|| {
                punctual_lut_estimates(&p, Kernel::Linear, 256, 256, 1.0, DEFAULT_TOLERANCE)
            })
            .unwrap();
        let dt = t0.elapsed();
        let evals: u64 = est.iter().map(|e| e[0].evals).sum();
        let max_err = est.iter().flat_map(|e| e.iter().map(|x| x.error)).fold(0.0, f64::max);
        eprintln!(
            "256×256 LUT (κ ≤ 1/mm), 1 thread: {dt:?}, {:.0} evals/texel, max estimate {max_err:e}",
            evals as f64 / est.len() as f64
        );
        assert!(max_err <= 1e-10);
        // The run time is printed, not asserted: a timed assertion fails on a loaded machine
        // (12 s under an instrumented build beside others); the benchmarks measure it.
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

    #[test]
    fn tabulated_profiles_work_end_to_end() {
        // Sampled default profile on a grid dense near 0 (r_i = 25 (i/N)²): agrees with the
        // Gaussian result to the piecewise-linear interpolation error (measured ~1e-5).
        let n = 300;
        let radius_mm: Vec<f64> = (0..=n).map(|i| 25.0 * (i as f64 / n as f64).powi(2)).collect();
        let g = default_skin_profile();
        let value: Vec<[f64; 3]> = radius_mm.iter().map(|&r| g.radial(r)).collect();
        let t = Profile::Tabulated { radius_mm: radius_mm.clone(), value: value.clone() };
        t.validate().unwrap();
        let scaled = Profile::Tabulated {
            radius_mm,
            value: value.iter().map(|v| v.map(|x| 7.0 * x)).collect(),
        };
        let mut worst: f64 = 0.0;
        for kernel in [Kernel::Linear, Kernel::Radial] {
            for (kappa, nl) in [(0.3, 0.1), (1.0, -0.2), (2.0, 0.6)] {
                let a = punctual(&t, kernel, kappa, nl, DEFAULT_TOLERANCE).unwrap();
                let b = punctual(&g, kernel, kappa, nl, DEFAULT_TOLERANCE).unwrap();
                let s = punctual(&scaled, kernel, kappa, nl, DEFAULT_TOLERANCE).unwrap();
                for c in 0..3 {
                    worst = worst.max((a[c].value - b[c].value).abs());
                    // Overall scale cancels in the ratio: rounding only.
                    assert!((a[c].value - s[c].value).abs() < 1e-12);
                    assert!(a[c].error <= 1e-10);
                }
            }
        }
        let a = sh_band(&t, 1.0, 2, DEFAULT_TOLERANCE).unwrap();
        let b = sh_band(&g, 1.0, 2, DEFAULT_TOLERANCE).unwrap();
        for c in 0..3 {
            worst = worst.max((a[c].value - b[c].value).abs());
        }
        eprintln!("tabulated (301 samples) vs Gaussians: max diff {worst:e}");
        // Interpolation error of R relative to itself is ≤ h²|R''|/(8R) ≈ h²/(8v): with
        // h ≈ 10√r/N this is ≈ 2e-3 around r = σ_min (v = 0.0064) and smaller elsewhere. D and
        // k_l are normalised averages of the kernel, so their error is a fraction of that:
        // bound 1e-3 (measured 3.2e-4).
        assert!(worst < 1e-3, "{worst}");
        assert_eq!(
            punctual(&t, Kernel::Linear, 0.0, 0.5, DEFAULT_TOLERANCE).unwrap()[1].value,
            0.5
        );
    }

    #[test]
    fn bad_profiles_rejected() {
        let g = |v: f64, w: [f64; 3]| Gaussian { variance_mm2: v, weight: w };
        let cases: Vec<(Profile, ProfileError, &str)> = vec![
            (Profile::Gaussians(vec![]), ProfileError::NoGaussians, "no terms"),
            (
                Profile::Gaussians(vec![g(1.0, [1.0; 3]), g(-0.5, [1.0; 3])]),
                ProfileError::BadVariance { index: 1, variance_mm2: -0.5 },
                "Gaussian 1",
            ),
            (
                Profile::Gaussians(vec![g(0.0, [1.0; 3])]),
                ProfileError::BadVariance { index: 0, variance_mm2: 0.0 },
                "variance 0",
            ),
            (
                Profile::Gaussians(vec![g(1.0, [1.0, -0.1, 1.0])]),
                ProfileError::BadWeight { index: 0, channel: 1, value: -0.1 },
                "green",
            ),
            (
                Profile::Gaussians(vec![g(1.0, [1.0, 1.0, 0.0])]),
                ProfileError::ZeroChannel { channel: 2 },
                "blue channel",
            ),
            (
                Profile::Tabulated { radius_mm: vec![0.0, 1.0, 1.0], value: vec![[1.0; 3]; 3] },
                ProfileError::NonMonotoneRadius { index: 2, previous_mm: 1.0, radius_mm: 1.0 },
                "radius 2",
            ),
            (
                Profile::Tabulated { radius_mm: vec![0.0, 1.0], value: vec![[1.0; 3]] },
                ProfileError::LengthMismatch { radii: 2, values: 1 },
                "2 radii",
            ),
            (
                Profile::Tabulated { radius_mm: vec![0.5], value: vec![[1.0; 3]] },
                ProfileError::TooFewSamples { len: 1 },
                "at least 2",
            ),
            (
                Profile::Tabulated { radius_mm: vec![-1.0, 1.0], value: vec![[1.0; 3]; 2] },
                ProfileError::BadRadius { index: 0, radius_mm: -1.0 },
                "radius 0",
            ),
        ];
        for (p, want, text) in cases {
            let err = p.validate().unwrap_err();
            assert_eq!(err, want);
            let msg = err.to_string();
            assert!(msg.contains(text), "message '{msg}' lacks '{text}'");
            assert!(punctual(&p, Kernel::Linear, 0.5, 0.5, DEFAULT_TOLERANCE).is_err());
            assert!(sh_band(&p, 0.5, 1, DEFAULT_TOLERANCE).is_err());
        }
        // NaN is caught (NaN != NaN, so match on the variant).
        let p = Profile::Gaussians(vec![g(f64::NAN, [1.0; 3])]);
        assert!(matches!(p.validate(), Err(ProfileError::BadVariance { index: 0, .. })));
        let p = Profile::Tabulated { radius_mm: vec![0.0, f64::NAN], value: vec![[1.0; 3]; 2] };
        assert!(matches!(p.validate(), Err(ProfileError::BadRadius { index: 1, .. })));
        let p =
            Profile::Tabulated { radius_mm: vec![0.0, 1.0], value: vec![[1.0, f64::NAN, 1.0]; 2] };
        let e = p.validate().unwrap_err();
        assert!(matches!(e, ProfileError::BadWeight { index: 0, channel: 1, .. }));
        assert!(e.to_string().contains("NaN"));
        // A profile that lies entirely beyond the ring's reach.
        let far = Profile::Tabulated { radius_mm: vec![5.0, 6.0], value: vec![[0.0; 3], [1.0; 3]] };
        far.validate().unwrap();
        assert!(matches!(
            punctual(&far, Kernel::Radial, 1.0, 0.5, DEFAULT_TOLERANCE),
            Err(ProfileError::NoMassWithinReach { .. })
        ));
    }

    /// A Gaussian profile's support is 9σ of its widest term with a nonzero weight: a term
    /// weighted 0 in every channel does not widen it, one nonzero channel is enough (9·√1 = 9,
    /// 9·√4 = 18 by hand); a table's is its last radius.
    #[test]
    fn support_is_nine_sigma_of_the_widest_weighted_term() {
        let g = |v: f64, w: [f64; 3]| Gaussian { variance_mm2: v, weight: w };
        assert_eq!(Profile::Gaussians(vec![g(1.0, [1.0; 3]), g(100.0, [0.0; 3])]).support_mm(), 9.0);
        assert_eq!(Profile::Gaussians(vec![g(1.0, [1.0; 3]), g(4.0, [0.0, 1.0, 0.0])]).support_mm(), 18.0);
        assert_eq!(tent(1.0, 2.5).support_mm(), 2.5);
    }

    /// A radius that goes back names the radius before it (2 mm), not itself (1.5 mm).
    #[test]
    fn a_decreasing_radius_names_the_previous_one() {
        let p = Profile::Tabulated { radius_mm: vec![0.0, 2.0, 1.5], value: vec![[1.0; 3]; 3] };
        let e = p.validate().unwrap_err();
        assert_eq!(e, ProfileError::NonMonotoneRadius { index: 2, previous_mm: 2.0, radius_mm: 1.5 });
        assert!(e.to_string().contains("not greater than radius 1 (2 mm)"), "{e}");
    }

    /// A three-segment table (first radius 0.5 mm, held below it), with the profile's radial
    /// values integrated by the test piece by piece between the knots, where R is smooth.
    fn three_segments() -> (Profile, [f64; 4]) {
        let p = Profile::Tabulated {
            radius_mm: vec![0.5, 1.0, 2.5],
            value: vec![[2.0, 1.0, 3.0], [1.5, 1.0, 0.5], [0.0, 0.2, 0.0]],
        };
        (p, [0.0, 0.5, 1.0, 2.5])
    }

    /// A table's line profile P(x) = ∫ R(√(x² + y²)) dy over several segments (the Abel sums
    /// beyond the first, where the segment starts past |x|), against the test's quadrature of
    /// R along the line, split where the line crosses a knot.
    #[test]
    fn a_tabulated_line_profile_is_the_line_integral_over_every_segment() {
        let (p, knots) = three_segments();
        let tol = Tolerance { abs: 1e-14, rel: 1e-14, max_panels: 5000 };
        for x in [0.0, 0.3, 0.5, 0.7, 1.0, 1.2, 2.0, 2.6] {
            let lin = p.linear(x);
            let mut ys: Vec<f64> = knots.iter().filter(|&&s| s > x).map(|&s| ((s - x) * (s + x)).sqrt()).collect();
            ys.insert(0, 0.0);
            for c in 0..3 {
                let brute: f64 = ys
                    .windows(2)
                    .map(|w| 2.0 * adaptive(w[0], w[1], tol, |y| p.radial((x * x + y * y).sqrt())[c]).value)
                    .sum();
                // Quadrature to 1e-14 per smooth piece, values ≤ 3 over ≤ 2.5 mm: 1e-11.
                assert!((lin[c] - brute).abs() < 1e-11, "x {x} channel {c}: {} vs {brute}", lin[c]);
            }
        }
    }

    /// A table's mass within s, ∫_0^s R(r) 2πr dr, over several segments (segments that start
    /// past r = 0), against the test's quadrature between the knots.
    #[test]
    fn a_tabulated_mass_within_is_the_integral_over_every_segment() {
        let (p, knots) = three_segments();
        let tol = Tolerance { abs: 1e-14, rel: 1e-14, max_panels: 5000 };
        for s in [0.3, 0.5, 0.8, 1.0, 1.7, 2.5, 4.0] {
            let m = p.mass_within(s);
            for c in 0..3 {
                let brute: f64 = knots
                    .windows(2)
                    .filter(|w| w[0] < s)
                    .map(|w| adaptive(w[0], w[1].min(s), tol, |r| p.radial(r)[c] * 2.0 * PI * r).value)
                    .sum();
                // Quadrature to 1e-14 per smooth piece of a quadratic in r: 1e-12.
                assert!((m[c] - brute).abs() < 1e-12, "s {s} channel {c}: {} vs {brute}", m[c]);
            }
        }
    }

    /// A flat disk profile (R = 1 within a, 0 beyond) on a ring of angle x = κu: D is the
    /// average of max(cos(θ + x), 0) over |x| ≤ X, X = 2·asin(aκ/2) (π once aκ ≥ 2), in closed
    /// form: the lobe [−π/2, π/2] gives sin(min(θ + X, π/2)) − sin(max(θ − X, −π/2)) when not
    /// empty, the lobe from 3π/2 gives sin(θ + X) + 1 when θ + X > 3π/2. On either side of every
    /// kink of the clamp, over n·l ∈ [−1, 1] and rings shorter and longer than the disk.
    #[test]
    fn a_flat_disk_on_a_ring_is_the_clamped_cosine_average() {
        let nls: Vec<f64> = (0..=40).map(|i| -1.0 + i as f64 / 20.0).collect();
        for (a, kappa) in [(0.5, 1.0), (1.0, 0.5), (0.6, 1.0), (1.5, 1.0), (1.99, 1.0), (3.0, 1.0), (0.25, 4.0)] {
            let disk = Profile::Tabulated { radius_mm: vec![0.0, a], value: vec![[1.0, 2.0, 0.5]; 2] };
            let got = punctual_grid_estimates(&disk, Kernel::Radial, &nls, &[kappa], DEFAULT_TOLERANCE).unwrap();
            let big_x = if a * kappa >= 2.0 { PI } else { 2.0 * (0.5 * a * kappa).asin() };
            for (i, &nl) in nls.iter().enumerate() {
                let theta = nl.acos();
                let lo = (theta - big_x).max(-PI / 2.0);
                let hi = (theta + big_x).min(PI / 2.0);
                let mut integral = if hi > lo { hi.sin() - lo.sin() } else { 0.0 };
                if theta + big_x > 1.5 * PI {
                    integral += (theta + big_x).sin() + 1.0;
                }
                let exact = integral / (2.0 * big_x);
                for c in 0..3 {
                    let e = got[i][c];
                    // The requested 1e-10, which the estimate must cover and honour; the closed
                    // form rounds at ~1e-16.
                    assert!((e.value - exact).abs() <= 1e-10, "a {a} κ {kappa} n·l {nl} channel {c}: {} vs {exact}", e.value);
                    assert!((e.value - exact).abs() <= e.error + 1e-15 && e.error <= 1e-10, "a {a} κ {kappa} n·l {nl} channel {c}: error {:e}", e.error);
                }
            }
        }
    }

    /// Lit from behind (n·l = −1) on a ring that spans less than a quarter turn (X = 2·asin(1/4)
    /// = 0.505 < π/2), both clamped cosines are 0 everywhere: D is 0 exactly, with no error, and
    /// the only evaluations counted are the ring's normalisation.
    #[test]
    fn a_ring_lit_only_from_behind_spends_nothing_on_the_numerator() {
        let disk = Profile::Tabulated { radius_mm: vec![0.0, 0.5], value: vec![[1.0; 3]; 2] };
        let k = PreparedKernel::new(&disk, Kernel::Radial);
        let ring = Ring::new(&k, 1.0, DEFAULT_TOLERANCE).unwrap();
        let d = ring.eval(-1.0, DEFAULT_TOLERANCE);
        for c in 0..3 {
            assert!(ring.den[c].evals > 0);
            assert_eq!((d[c].value, d[c].error, d[c].evals), (0.0, 0.0, ring.den[c].evals), "channel {c}");
        }
    }

    /// D and k_l are ratios of two integrals of the profile: scaling every weight by 2¹⁰ or
    /// 2⁻¹⁰ (exact in binary) scales numerators, denominators and their error targets exactly,
    /// so values, error estimates and evaluation counts stay the same bit for bit.
    #[test]
    fn a_power_of_two_scale_of_the_profile_changes_no_bit() {
        let scaled = |p: &Profile, f: f64| match p {
            Profile::Gaussians(gs) => Profile::Gaussians(gs.iter().map(|g| Gaussian { weight: g.weight.map(|w| f * w), ..*g }).collect()),
            Profile::Tabulated { radius_mm, value } => {
                Profile::Tabulated { radius_mm: radius_mm.clone(), value: value.iter().map(|v| v.map(|x| f * x)).collect() }
            }
        };
        let loose = Tolerance { abs: 1e-6, rel: 0.0, max_panels: 2000 };
        let mut nonzero_errors = 0;
        for p in [default_skin_profile(), three_segments().0] {
            for f in [1024.0, 1.0 / 1024.0] {
                let q = scaled(&p, f);
                for (kappa, nl) in [(0.3, 0.2), (1.0, -0.1), (3.0, 0.7)] {
                    for tol in [DEFAULT_TOLERANCE, loose] {
                        for kernel in [Kernel::Linear, Kernel::Radial] {
                            let a = punctual(&p, kernel, kappa, nl, tol).unwrap();
                            let b = punctual(&q, kernel, kappa, nl, tol).unwrap();
                            assert_eq!(a, b, "{kernel:?} κ {kappa} n·l {nl} scale {f}");
                            nonzero_errors += a.iter().filter(|e| e.error > 0.0).count();
                        }
                        for band in [1, 2] {
                            let a = sh_band(&p, kappa, band, tol).unwrap();
                            let b = sh_band(&q, kappa, band, tol).unwrap();
                            assert_eq!(a, b, "band {band} κ {kappa} scale {f}");
                            nonzero_errors += a.iter().filter(|e| e.error > 0.0).count();
                        }
                    }
                }
            }
        }
        // The comparison must hold error estimates that are not all 0.
        assert!(nonzero_errors > 0);
    }

    /// The LUT grids, by hand: n·l column i of 65 is −1 + i/32, κ row j of 64 is κ_max·j/63
    /// (3·21/63 = 1), the sqrt mapping puts t at κ_max·t² and t = 1 at κ_max exactly.
    #[test]
    fn lut_grids_sit_where_their_docs_say() {
        assert_eq!([0, 16, 32, 48, 64].map(|i| lut_n_dot_l(i, 65)), [-1.0, -0.5, 0.0, 0.5, 1.0]);
        assert_eq!([0, 1].map(|i| lut_n_dot_l(i, 2)), [-1.0, 1.0]);
        assert_eq!([0, 21, 63].map(|j| lut_curvature(j, 64, 3.0)), [0.0, 1.0, 3.0]);
        assert_eq!(CurvatureMapping::Sqrt.from_unit(0.5), 0.25);
        assert_eq!(CurvatureMapping::Linear.from_unit(0.5), 0.5);
        assert_eq!(mapped_curvature(0.5, 4.0, CurvatureMapping::Sqrt), 1.0);
        assert_eq!(mapped_curvature(0.25, 16.0, CurvatureMapping::Sqrt), 1.0);
        assert_eq!(mapped_curvature(0.5, 4.0, CurvatureMapping::Linear), 2.0);
        assert_eq!(mapped_curvature(0.0, 4.0, CurvatureMapping::Sqrt), 0.0);
        assert_eq!(mapped_curvature(1.0, 0.3, CurvatureMapping::Sqrt), 0.3);
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

    /// The flat test is κ·max(support, 1 mm) < 1e-200, strictly: the support scales the
    /// threshold above 1 mm only, and the product 1e-200 itself is not flat.
    #[test]
    fn flatness_is_curvature_times_the_support_below_1e_200() {
        assert!(is_flat(0.0, 24.5));
        assert!(is_flat(1e-201, 1.0));
        assert!(is_flat(1e-201, 0.5));
        assert!(!is_flat(1e-201, 100.0));
        assert!(!is_flat(1e-200, 0.5));
        assert!(!is_flat(1e-200, 1.0));
    }
}
