//! Linearly transformed cosines (Heitz, Dupuy, Hill, Neubelt 2016): a clamped cosine
//! D_o(ω_o) = max(0, z_o)/π reshaped by a 3×3 matrix M, and its integral over a polygon.
//!
//! The distribution: ω = Mω_o/|Mω_o|, so with ω_o = M⁻¹ω/|M⁻¹ω|
//! ```text
//! D(ω) = D_o(ω_o) · ∂ω_o/∂ω = D_o(ω_o) · |det M⁻¹| / |M⁻¹ω|³,      ∫_{S²} D = 1,
//! ```
//! and D is unchanged when M is scaled, so a table stores M⁻¹ over its middle element
//! (ltc_code `fit/fitLTC.cpp`, `packTab`). Isotropic lobes seen from v = (sin θ, 0, cos θ) in
//! the xz-plane give an M⁻¹ with zero y-coupling:
//! ```text
//!        ⎡ a  0  b ⎤
//! M⁻¹ =  ⎢ 0  1  0 ⎥,      ltc_1 = (a, c, b, d) as ltc_code packs it (glm's [col][row]:
//!        ⎣ c  0  d ⎦        invM[0][0], invM[0][2], invM[2][0], invM[2][2]).
//! ```
//!
//! The polygon integral is D_o's over the transformed polygon M⁻¹P (projected on the sphere),
//! clipped to z_o ≥ 0: Lambert's formula (1/2π) Σ_edges acos(p_i·p_j) · n̂_ij·z, with n̂_ij the
//! unit normal of the great circle through the edge (the irradiance of a polygon, Lambert 1760;
//! Arvo 1995). Clipping happens in the transformed space, where D_o vanishes; the part of
//! D that falls below the real horizon (ω·z < 0) is counted by it — the shader's "light below
//! the horizon" ([`Ltc::mass_below_horizon`] measures it).

use std::f64::consts::PI;

pub type Vec3 = [f64; 3];

pub fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

pub fn norm(a: Vec3) -> f64 {
    dot(a, a).sqrt()
}

pub fn normalize(a: Vec3) -> Vec3 {
    let n = norm(a);
    [a[0] / n, a[1] / n, a[2] / n]
}

/// An LTC by its inverse matrix in the table's form (the middle element 1; see the module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ltc {
    /// M⁻¹ = [[a, 0, b], [0, 1, 0], [c, 0, d]].
    pub a: f64,
    pub b: f64,
    pub c: f64,
    pub d: f64,
}

impl Ltc {
    /// The clamped cosine itself (M = I).
    pub const IDENTITY: Ltc = Ltc { a: 1.0, b: 0.0, c: 0.0, d: 1.0 };

    /// From ltc_code's texel (ltc_1 = (a, c, b, d)).
    pub fn from_texel(t: [f64; 4]) -> Ltc {
        Ltc { a: t[0], c: t[1], b: t[2], d: t[3] }
    }

    /// ltc_code's texel (a, c, b, d).
    pub fn texel(&self) -> [f64; 4] {
        [self.a, self.c, self.b, self.d]
    }

    /// det M⁻¹ = ad − bc.
    pub fn det_inv(&self) -> f64 {
        self.a * self.d - self.b * self.c
    }

    /// Usable: M⁻¹ invertible with finite entries.
    pub fn is_valid(&self) -> bool {
        let det = self.det_inv();
        [self.a, self.b, self.c, self.d].iter().all(|x| x.is_finite()) && det.is_finite() && det.abs() > 1e-300
    }

    /// M⁻¹ω.
    pub fn to_cosine(&self, w: Vec3) -> Vec3 {
        [self.a * w[0] + self.b * w[2], w[1], self.c * w[0] + self.d * w[2]]
    }

    /// Mω (the inverse of the inverse).
    pub fn from_cosine(&self, o: Vec3) -> Vec3 {
        let det = self.det_inv();
        [(self.d * o[0] - self.b * o[2]) / det, o[1], (-self.c * o[0] + self.a * o[2]) / det]
    }

    /// D(ω) for a unit ω.
    pub fn eval(&self, w: Vec3) -> f64 {
        let o = self.to_cosine(w);
        let l2 = dot(o, o);
        let l = l2.sqrt();
        let z = o[2] / l;
        if z <= 0.0 {
            return 0.0;
        }
        z / PI * self.det_inv().abs() / (l2 * l)
    }

    /// The direction of the cosine-hemisphere point u ∈ [0, 1]² under M, and D there.
    pub fn sample(&self, u1: f64, u2: f64) -> (Vec3, f64) {
        let r = u1.sqrt();
        let (s, c) = (2.0 * PI * u2).sin_cos();
        let o = [r * c, r * s, (1.0 - u1).max(0.0).sqrt()];
        let w = normalize(self.from_cosine(o));
        (w, self.eval(w))
    }

    /// ∫_P D over the polygon with vertices `p` (directions from the shaded point, any length;
    /// positive when they wind counter-clockwise about the direction from the point to the
    /// polygon by the right-hand rule, i.e. clockwise as seen from the point), clipped in the cosine
    /// space; [`polygon_cosine`] of M⁻¹P.
    pub fn polygon(&self, p: &[Vec3]) -> f64 {
        let q: Vec<Vec3> = p.iter().map(|&v| self.to_cosine(v)).collect();
        polygon_cosine(&q)
    }

    /// ∫ D over ω·z < 0: the mass a shader counts below the real horizon. The lower hemisphere
    /// is the polygon-free half-space; in the cosine space it is the half-space
    /// {o : (M o)_z < 0} = {o : −c o_x + a o_z < 0}, whose clamped-cosine mass is
    /// (1 − cos γ)/2 with γ the angle between z and its inward normal (a lune integral).
    pub fn mass_below_horizon(&self) -> f64 {
        // Half-space n·o < 0 with n = (−c, 0, a)·sign(det) (the sign keeps the orientation of M).
        let s = self.det_inv().signum();
        let n = normalize([-self.c * s, 0.0, self.a * s]);
        // The clamped cosine's mass in {n·o < 0}: for a plane through the origin at angle γ
        // from z (cos γ = n_z), ∫_{n·o<0} max(0, o_z)/π dω = (1 − cos γ)/2.
        (1.0 - n[2]) / 2.0
    }
}

/// (1/2π) Σ acos(p_i·p_j) n̂_ij·z over the edges of the polygon `q` (vertices in order, any
/// length) clipped to z ≥ 0: the clamped cosine's integral over it, positive for a polygon
/// wound counter-clockwise about the direction from the origin to it (right-hand rule; seen
/// from the origin, clockwise) (a one-sided light takes max(0, ·), a two-sided |·|,
/// as ltc_code's shaders do).
pub fn polygon_cosine(q: &[Vec3]) -> f64 {
    let clipped = clip_to_horizon(q);
    let n = clipped.len();
    if n < 3 {
        return 0.0;
    }
    let mut sum = 0.0;
    for i in 0..n {
        let (u, v) = (normalize(clipped[i]), normalize(clipped[(i + 1) % n]));
        sum += edge(u, v);
    }
    sum / (2.0 * PI)
}

/// One edge's term acos(u·v)·(u × v)_z/|u × v| for unit u, v (0 for a degenerate edge).
pub fn edge(u: Vec3, v: Vec3) -> f64 {
    let c = cross(u, v);
    let s = norm(c);
    if s == 0.0 {
        return 0.0;
    }
    // atan2(|u × v|, u·v) is the angle without acos's loss near 0 and π.
    s.atan2(dot(u, v)) * c[2] / s
}

/// The polygon clipped to z ≥ 0 (Sutherland–Hodgman against one plane).
pub fn clip_to_horizon(q: &[Vec3]) -> Vec<Vec3> {
    let n = q.len();
    let mut out = Vec::with_capacity(n + 1);
    for i in 0..n {
        let (a, b) = (q[i], q[(i + 1) % n]);
        if a[2] >= 0.0 {
            out.push(a);
        }
        if (a[2] >= 0.0) != (b[2] >= 0.0) {
            let t = a[2] / (a[2] - b[2]);
            out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), 0.0]);
        }
    }
    out
}

/// The corners of a rectangle centred at `centre` with half-edge vectors `ex`, `ey`, in the
/// order (−−, +−, ++, −+): when ex × ey points away from the origin they wind counter-clockwise
/// about the direction from the origin to the rectangle (right-hand rule), the orientation in
/// which a one-sided light shines on the origin.
pub fn rectangle(centre: Vec3, ex: Vec3, ey: Vec3) -> [Vec3; 4] {
    let at = |sx: f64, sy: f64| [centre[0] + sx * ex[0] + sy * ey[0], centre[1] + sx * ex[1] + sy * ey[1], centre[2] + sx * ex[2] + sy * ey[2]];
    [at(-1.0, -1.0), at(1.0, -1.0), at(1.0, 1.0), at(-1.0, 1.0)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::gauss_legendre;

    /// ∫ over the sphere in (cos θ, φ), Gauss–Legendre n × n with the polar axis split at the
    /// given cosines (where a lobe is peaked or clipped).
    fn sphere(f: impl Fn(Vec3) -> f64, n: usize, cuts: &[f64]) -> f64 {
        let (x, w) = gauss_legendre(n);
        let mut edges = vec![-1.0];
        edges.extend_from_slice(cuts);
        edges.push(1.0);
        let mut sum = 0.0;
        for p in edges.windows(2) {
            let (lo, hi) = (p[0], p[1]);
            for (xi, wi) in x.iter().zip(&w) {
                let z = 0.5 * (lo + hi) + 0.5 * (hi - lo) * xi;
                let r = (1.0 - z * z).max(0.0).sqrt();
                for (xj, wj) in x.iter().zip(&w) {
                    let phi = PI * (1.0 + xj);
                    sum += wi * wj * 0.5 * (hi - lo) * PI * f([r * phi.cos(), r * phi.sin(), z]);
                }
            }
        }
        sum
    }

    const SKEWED: Ltc = Ltc { a: 3.0, b: -0.8, c: 0.4, d: 0.9 };

    /// D integrates to 1 for any invertible M⁻¹ (the change of variables): 1e-6 with 200²
    /// nodes a panel, whose error on the kink along D's zero set is O(n⁻²) ≈ 1e-6 of 1.
    #[test]
    fn the_distribution_has_unit_mass() {
        for l in [Ltc::IDENTITY, SKEWED, Ltc { a: 10.0, b: 0.0, c: 0.0, d: 1.0 }] {
            let m = sphere(|w| l.eval(w), 200, &[-0.5, 0.0, 0.5, 0.9, 0.99]);
            assert!((m - 1.0).abs() < 1e-5, "{l:?}: {m}");
        }
    }

    /// Lambert's polygon formula against direct quadrature of D over a rectangle light's
    /// directions (the indicator of the polygon on a 400² tensor grid: its boundary error is
    /// O(1/n) of the polygon's mass, ≈ 2e-3 here), and the clipped case: a light crossing the
    /// horizon, whose lower part is clipped away in the cosine space.
    #[test]
    fn the_polygon_integral_is_the_distribution_s_mass_over_the_polygon() {
        let lights = [
            rectangle([0.3, 0.2, 1.0], [0.5, 0.0, 0.0], [0.0, 0.4, 0.1]),
            rectangle([1.0, 0.1, 0.1], [0.0, 0.0, 0.6], [0.0, 0.7, 0.0]),
        ];
        for l in [Ltc::IDENTITY, SKEWED] {
            for p in &lights {
                let inside = |w: Vec3| {
                    // w hits the polygon's plane inside it (a convex quad: same side of all edges).
                    let nrm = cross([p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]], [p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]]);
                    let t = dot(nrm, p[0]) / dot(nrm, w);
                    if t <= 0.0 {
                        return false;
                    }
                    let x = [w[0] * t, w[1] * t, w[2] * t];
                    let signs: Vec<f64> = (0..4)
                        .map(|i| {
                            let (a, b) = (p[i], p[(i + 1) % 4]);
                            dot(nrm, cross([b[0] - a[0], b[1] - a[1], b[2] - a[2]], [x[0] - a[0], x[1] - a[1], x[2] - a[2]]))
                        })
                        .collect();
                    signs.iter().all(|&s| s > 0.0) || signs.iter().all(|&s| s < 0.0)
                };
                let direct = sphere(|w| if inside(w) { l.eval(w) } else { 0.0 }, 400, &[0.0]);
                let lambert = l.polygon(p).abs();
                assert!((direct - lambert).abs() < 5e-3 * lambert.max(0.05), "{l:?} {p:?}: {direct} vs {lambert}");
            }
        }
    }

    /// The clamped cosine's mass below the horizon against quadrature (200² a panel: 1e-5).
    #[test]
    fn the_mass_below_the_horizon_matches_quadrature() {
        for l in [Ltc::IDENTITY, SKEWED, Ltc { a: 1.0, b: 0.0, c: -0.7, d: 0.5 }] {
            let q = sphere(|w| if w[2] < 0.0 { l.eval(w) } else { 0.0 }, 200, &[-0.5, 0.0]);
            assert!((q - l.mass_below_horizon()).abs() < 1e-5, "{l:?}: {q} vs {}", l.mass_below_horizon());
        }
    }

    /// The sampler maps the cosine hemisphere onto D's support: D at the sample is the
    /// cosine's density carried over (z_o/π · ∂ω_o/∂ω) and the packing round-trips.
    #[test]
    fn samples_land_where_the_distribution_is_and_texels_round_trip() {
        let (w, dw) = SKEWED.sample(0.3, 0.7);
        assert!((norm(w) - 1.0).abs() < 1e-15 && dw > 0.0);
        assert_eq!(Ltc::from_texel(SKEWED.texel()), SKEWED);
        let back = SKEWED.to_cosine(SKEWED.from_cosine([0.1, 0.2, 0.3]));
        assert!((back[0] - 0.1).abs() < 1e-15 && (back[2] - 0.3).abs() < 1e-15);
    }
}
