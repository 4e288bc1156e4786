//! Ashikhmin's velvet distribution (Ashikhmin & Premože 2007, "Distribution-based BRDFs"), the
//! cloth D Filament shaded with before Charlie's and the one the glTF IBL Sampler's
//! `D_Ashikhmin` writes:
//! ```text
//! D(h) = (4 e^(−cot²θh/α²) + sin⁴θh) / (π (1 + 4α²) sin⁴θh)      (∫ D cos θh dω = 1)
//! ```
//! (α = r² of a perceptual roughness r in both), with Neubelt's V = 1/(4(n·l + n·v − n·l n·v)).
//! D is bounded (from 1/(π(1 + 4α²)) at the normal to 5× that at the horizon, where its rise
//! has width ~α in θh), so the lobe integrates in the default cosine measure.

use crate::shading::lobe::Lobe;
use std::f64::consts::PI;

pub struct Velvet {
    a2: f64,
}

impl Velvet {
    pub fn new(alpha: f64) -> Velvet {
        Velvet { a2: alpha * alpha }
    }

    /// D at n·h = `ch`.
    pub fn d(&self, ch: f64) -> f64 {
        let c2 = ch * ch;
        let s2 = (1.0 - c2).max(0.0);
        let norm = 1.0 / (PI * (1.0 + 4.0 * self.a2));
        // At the normal (s2 → 0) e^(−cot²/α²) vanishes faster than sin⁴: D → norm.
        if s2 == 0.0 { norm } else { norm * (4.0 * (-c2 / (self.a2 * s2)).exp() / (s2 * s2) + 1.0) }
    }
}

impl Lobe for Velvet {
    type View = f64;

    fn view(&self, mu_v: f64) -> f64 {
        mu_v
    }

    fn eval(&self, mu_v: &f64, _vh: f64, ch: f64, mu_l: f64) -> f64 {
        self.d(ch) / (4.0 * (mu_l + mu_v - mu_l * mu_v))
    }

    /// Neubelt's denominator vanishes at μl = −μv/(1 − μv).
    fn horizon_pole(&self, mu_v: &f64) -> f64 {
        if *mu_v < 1.0 { mu_v / (1.0 - mu_v) } else { f64::INFINITY }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shading::hemisphere::albedo;

    /// ∫ D cos θh dω = 1: a midpoint rule of 200000 nodes in θh (D is smooth and bounded; the
    /// rule's error is ~1e-11 here) to 1e-9.
    #[test]
    fn the_distribution_is_normalised() {
        for alpha in [0.05, 0.3, 1.0] {
            let v = Velvet::new(alpha);
            let n = 200_000;
            let h = 0.5 * PI / n as f64;
            let s: f64 = (0..n).map(|i| (i as f64 + 0.5) * h).map(|t| v.d(t.cos()) * t.cos() * t.sin()).sum::<f64>() * h * 2.0 * PI;
            assert!((s - 1.0).abs() < 1e-9, "α {alpha}: {s}");
        }
    }

    /// E at a light-direction product rule (1200 × 1200 midpoint nodes in (θl, φl); the
    /// integrand is bounded and smooth but for the kink of h at l = v) against the integrator,
    /// to 2e-5 (the product rule's error at α = 0.3).
    #[test]
    fn the_albedo_is_the_brute_force_over_light_directions() {
        let v = Velvet::new(0.3);
        for mu in [0.2f64, 0.7] {
            let view = [(1.0 - mu * mu).sqrt(), 0.0, mu];
            let n = 1200;
            let (dt, dp) = (0.5 * PI / n as f64, 2.0 * PI / n as f64);
            let mut s = 0.0;
            for i in 0..n {
                let t = (i as f64 + 0.5) * dt;
                for j in 0..n {
                    let p = (j as f64 + 0.5) * dp;
                    let l = [t.sin() * p.cos(), t.sin() * p.sin(), t.cos()];
                    let hs = [l[0] + view[0], l[1] + view[1], l[2] + view[2]];
                    let hn = (hs[0] * hs[0] + hs[1] * hs[1] + hs[2] * hs[2]).sqrt();
                    s += v.eval(&mu, 0.0, hs[2] / hn, l[2]) * l[2] * t.sin() * dt * dp;
                }
            }
            let e = albedo(&v, mu, 1e-10);
            assert!((e.value - s).abs() < 2e-5, "μ {mu}: {e:?} vs {s}");
        }
    }
}
