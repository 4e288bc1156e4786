//! Diffusion profiles: sums of Gaussians and tabulated radial profiles, their linear profiles
//! (the Abel transform of a tabulated profile exactly, segment by segment) and the kernels
//! K(chord) the ring and the sphere integrate (units and conventions in the module doc of
//! `super`).

#![allow(clippy::needless_range_loop)]

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

pub(super) struct PreparedKernel {
    k: Prepared,
    /// Chord distance beyond which K is zero (or dropped).
    pub(super) cutoff: f64,
    /// Chord distances where K changes scale or has kinks (ascending, all < cutoff).
    pub(super) breaks: Vec<f64>,
}

impl PreparedKernel {
    pub(super) fn new(p: &Profile, kernel: Kernel) -> PreparedKernel {
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
    pub(super) fn eval(&self, s: f64) -> [f64; 3] {
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

#[cfg(test)]
mod tests {
    use super::super::tests::three_segments;
    use super::*;
    use crate::integrate::{Tolerance, adaptive};

    /// Tent R(r) = c(1 − r/a) on [0, a]: exactly piecewise linear.
    fn tent(c: f64, a: f64) -> Profile {
        Profile::Tabulated { radius_mm: vec![0.0, a], value: vec![[c, 2.0 * c, 0.5 * c], [0.0; 3]] }
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
}
