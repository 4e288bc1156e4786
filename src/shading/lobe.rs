//! What a BRDF lobe tells the hemispherical operators ([`super::hemisphere`]).
//!
//! # The contract
//!
//! Normal n = +z, the view v = (sin θv, 0, μv) in the xz-plane, μv = n·v ∈ [0, 1], a light l
//! with μl = n·l and the half vector h = (v + l)/|v + l| at polar angle θh and azimuth φ. An
//! isotropic lobe is a BRDF f(μv, μl, n·h, v·h) ≥ 0. The operators integrate f μl over the
//! lights of the upper hemisphere (or of a cone about n) in the half vector: with
//! l = 2(v·h)h − v, dω_l = 4 (v·h) dω_h. They do not see f itself but its **weight** against a
//! probability measure of the half vector, dμ(h) = p(h) dω_h = dξ dφ/2π with ξ ∈ [0, 1] a
//! function of θh alone (the measure's CDF in θh):
//! ```text
//! w(h) = f μl dω_l / dμ = 4 f μl (v·h) / p(h),          ∫ f μl dω_l = ∫∫ w dξ dφ/2π.
//! ```
//! A lobe chooses its measure so that w is smooth where f has its mass: GGX takes p = D μh
//! (its importance sampler), so the spike of D at small α cancels and w = G2 (v·h)/(μv μh).
//! A lobe without a measure of its own takes the default, the cosine-weighted measure
//! p(h) = μh/π (ξ = sin²θh), so that a lobe is its [`Lobe::eval`] and nothing else.
//!
//! # What else the integrator needs to know
//!
//! - [`Lobe::switch_angle`]: the outer integral runs in ξ below θ* and in θh above it (where ξ
//!   crowds against 1 and a kink near θh = π/2 would sit within ulps of ξ = 1); the lobe says
//!   where its mass ends (GGX: θ* = atan(10α), ξ(θ*) = 100/101).
//! - [`Lobe::horizon_pole`]: the distance below μl = 0 of the weight's nearest singularity as a
//!   function of μl (GGX's G2 pole at grazing views or small α), a feature narrower than an
//!   azimuth panel that the error estimate cannot see; the azimuth panels are cut geometrically
//!   down to it. ∞ (the default): the weight is smooth in μl.
//! - [`Lobe::is_mirror`]: the δ limit (f = δ(l − mirror(v))/μl with unit masking), integrated
//!   exactly.

use std::f64::consts::PI;

/// A BRDF lobe, as data for the generic hemispherical operators (see the module doc).
pub trait Lobe: Sync {
    /// What [`Lobe::eval`] and [`Lobe::weight`] need at one view, computed once per view.
    type View: Sync;

    /// The per-view set-up at μv = n·v ∈ [0, 1].
    fn view(&self, mu_v: f64) -> Self::View;

    /// The BRDF f at a light of n·l = `mu_l` > 0, with n·h = `ch` and v·h = `vh`.
    fn eval(&self, view: &Self::View, vh: f64, ch: f64, mu_l: f64) -> f64;

    /// The density p(h) of the half-vector measure per unit solid angle at n·h = `ch` (default:
    /// the cosine-weighted measure μh/π).
    fn pdf(&self, ch: f64) -> f64 {
        ch / PI
    }

    /// (sin²θh, cos²θh) at the measure's CDF value ξ (default: ξ = sin²θh).
    fn half_angle(&self, xi: f64) -> (f64, f64) {
        (xi, 1.0 - xi)
    }

    /// The CDF ξ(θh) of the measure (default: sin²θh; 0 at θ ≤ 0).
    fn xi_of(&self, theta: f64) -> f64 {
        if theta <= 0.0 { 0.0 } else { theta.sin().powi(2).min(1.0) }
    }

    /// `dtheta`·dξ/dθh at (sin θh, cos θh) = (`sh`, `ch`): the measure of an outer node in θh
    /// whose map has Jacobian `dtheta` (default: dξ/dθh = 2 sin θh cos θh).
    fn xi_measure(&self, dtheta: f64, sh: f64, ch: f64) -> f64 {
        dtheta * 2.0 * sh * ch
    }

    /// θ*: below it the outer variable is ξ, above it θh (default π/2: ξ throughout).
    fn switch_angle(&self) -> f64 {
        0.5 * PI
    }

    /// w = 4 f μl (v·h)/p(h) (see the module doc); a lobe overrides it with a form that
    /// cancels its measure where that is more accurate.
    fn weight(&self, view: &Self::View, vh: f64, ch: f64, mu_l: f64) -> f64 {
        4.0 * self.eval(view, vh, ch, mu_l) * mu_l * vh / self.pdf(ch)
    }

    /// Distance below μl = 0 of the weight's nearest singularity in μl (∞: none).
    fn horizon_pole(&self, _view: &Self::View) -> f64 {
        f64::INFINITY
    }

    /// The δ limit: a perfect mirror with unit masking, integrated exactly.
    fn is_mirror(&self) -> bool {
        false
    }
}
