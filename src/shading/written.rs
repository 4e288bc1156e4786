//! A lobe given as its BRDF alone — a function of (n·v, n·l, n·h, v·h), e.g. a user's lobe
//! written as an expression (`kind = "lobe"`, `src/pipeline/lobe.rs`) — and the measure of the
//! half vector it is integrated in: the cosine-weighted measure (a broad lobe: Lambert, Charlie's cloth)
//! or GGX's importance measure D μh at a roughness α (a lobe whose peak follows GGX's), so that
//! the weight w = 4 f μl (v·h)/p(h) stays smooth where f has its mass (see [`super::lobe`]).
//!
//! # What the integrator cannot know about a written lobe
//!
//! Nothing says where its weight has narrow features, so the lobe declares the most cautious
//! [`Lobe::horizon_pole`], 0: when an inner φ integral has not converged on the nested rule's
//! 129 nodes, the adaptive fallback cuts its panels on every scale towards the horizon (24
//! geometric levels) instead of down to a known pole. A written lobe therefore converges with
//! honest error estimates wherever a built-in one does, at the cost of more evaluations where
//! the fallback runs (grazing views of narrow lobes), and of the function call itself (the
//! `lobe` rows of `shadefit bench` measure both against the built-in GGX).
//!
//! The mirror limit (α → 0) is not a written lobe's: its domain must keep α > 0.

use super::lobe::Lobe;
use super::trowbridge_reitz::{Ggx, Shadowing};

/// The half-vector measure a written lobe is integrated in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Measure {
    /// p(h) = μh/π.
    Cosine,
    /// p(h) = D_GGX(α, μh) μh at this α (> 0).
    Ggx(f64),
}

/// The arguments of a written BRDF, in this order.
pub const ARGS: [&str; 4] = ["n_dot_v", "n_dot_l", "n_dot_h", "v_dot_h"];

/// A lobe whose BRDF is `f([n·v, n·l, n·h, v·h])`, integrated in `measure`.
pub struct Written<F> {
    f: F,
    measure: Option<Ggx>,
}

impl<F: Fn([f64; 4]) -> f64 + Sync> Written<F> {
    pub fn new(f: F, measure: Measure) -> Self {
        let measure = match measure {
            Measure::Cosine => None,
            Measure::Ggx(alpha) => Some(Ggx::new(alpha, Shadowing::HeightCorrelated)),
        };
        Written { f, measure }
    }
}

impl<F: Fn([f64; 4]) -> f64 + Sync> Lobe for Written<F> {
    type View = f64;

    fn view(&self, mu_v: f64) -> f64 {
        mu_v
    }

    fn eval(&self, mu_v: &f64, vh: f64, ch: f64, mu_l: f64) -> f64 {
        (self.f)([*mu_v, mu_l, ch, vh])
    }

    fn pdf(&self, ch: f64) -> f64 {
        self.measure.as_ref().map_or(ch / std::f64::consts::PI, |g| g.pdf(ch))
    }

    fn half_angle(&self, xi: f64) -> (f64, f64) {
        self.measure.as_ref().map_or((xi, 1.0 - xi), |g| g.half_angle(xi))
    }

    fn xi_of(&self, theta: f64) -> f64 {
        match &self.measure {
            Some(g) => g.xi_of(theta),
            None if theta <= 0.0 => 0.0,
            None => theta.sin().powi(2).min(1.0),
        }
    }

    fn xi_measure(&self, dtheta: f64, sh: f64, ch: f64) -> f64 {
        self.measure.as_ref().map_or(dtheta * 2.0 * sh * ch, |g| g.xi_measure(dtheta, sh, ch))
    }

    fn switch_angle(&self) -> f64 {
        self.measure.as_ref().map_or(0.5 * std::f64::consts::PI, Ggx::switch_angle)
    }

    /// 4 f μl (v·h)/p(h); 0 where the measure has no density (the measure's tail underflows
    /// only where a lobe that follows it has no mass either).
    fn weight(&self, view: &f64, vh: f64, ch: f64, mu_l: f64) -> f64 {
        let p = self.pdf(ch);
        if p > 0.0 { 4.0 * self.eval(view, vh, ch, mu_l) * mu_l * vh / p } else { 0.0 }
    }

    fn horizon_pole(&self, _view: &f64) -> f64 {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shading::hemisphere::{albedo, albedo_avg, split_sum};
    use crate::shading::trowbridge_reitz::d;
    use std::f64::consts::PI;

    /// Lambert's lobe written out, f = 1/π in the cosine measure: its weight is 4 μl (v·h)/μh
    /// = 4(2(v·h)μh − μv)(v·h)/μh, a polynomial on each side of the horizon cut, so the
    /// integrator's rules are exact up to rounding: E(μ) = 1 and E_avg = 1 to 1e-12.
    #[test]
    fn lambert_written_out_has_unit_albedo() {
        let lobe = Written::new(|_| 1.0 / PI, Measure::Cosine);
        for mu in [0.0, 0.01, 0.3, 0.7, 1.0] {
            let e = albedo(&lobe, mu, 1e-13);
            assert!((e.value - 1.0).abs() < 1e-12, "μ {mu}: E {}", e.value);
        }
        assert!((albedo_avg(&lobe, 1e-13).value - 1.0).abs() < 1e-12);
    }

    /// GGX written as D·V (height-correlated V in Heitz's form) in GGX's measure is the
    /// built-in lobe: the split sum agrees to the two error estimates' sum.
    #[test]
    fn ggx_written_out_is_the_built_in_lobe() {
        for alpha in [0.02f64, 0.3, 1.0] {
            let a2 = alpha * alpha;
            let f = move |[nv, nl, nh, _]: [f64; 4]| {
                let v = 0.5 / (nl * (nv * nv * (1.0 - a2) + a2).sqrt() + nv * (nl * nl * (1.0 - a2) + a2).sqrt());
                d(alpha, nh) * v
            };
            let written = Written::new(f, Measure::Ggx(alpha));
            let built_in = Ggx::new(alpha, Shadowing::HeightCorrelated);
            for mu in [0.0, 0.05, 0.5, 1.0] {
                let (a, b) = (split_sum(&written, mu, 0.0, 1e-10), split_sum(&built_in, mu, 0.0, 1e-10));
                let tol = a.error + b.error;
                assert!((a.scale - b.scale).abs() <= tol && (a.bias - b.bias).abs() <= tol, "α {alpha} μ {mu}: {a:?} vs {b:?}");
            }
        }
    }
}
