//! Integrals over the sphere: a product Gauss–Legendre rule, the microflake NDFs compared
//! ([`Ndf`]: SGGX lobes, their mixtures, LEAN made symmetric), SGGX parameter estimation and
//! the distances between normalised NDFs (conventions in the module doc of `super`).

use super::{Lean, Lobe, M3, V3, direction};
use std::f64::consts::PI;

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

#[cfg(test)]
mod tests {
    use super::super::sggx_from;
    use super::super::tests::texel;
    use super::*;

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
}
