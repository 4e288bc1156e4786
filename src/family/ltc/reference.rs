//! The end-to-end check of an LTC table: what a shader computes for a polygon light against the
//! *true* lobe integrated over the same polygon.
//!
//! The reference is I = ∫_P f(v, l) max(0, n·l) dl, the polygon P clipped to the horizon in
//! its own plane and fanned into triangles, each integrated over its area,
//! ```text
//! dl = |n_P · x̂| / |x|² dA,    x(u, w) = A + u(B − A) + u w (C − B),   dA = u |(B − A) × (C − B)| du dw,
//! ```
//! by nested adaptive G10/K21 (outer u, inner w: both zoom onto the lobe's peak; the integrand
//! is smooth on a triangle above the horizon). Its error is estimated by a convergence study
//! (relative tolerances [`TOLERANCE`] and a hundredth of it).
//!
//! The shader's value is ltc_code's: the table's texels bilinearly interpolated at
//! (roughness, sqrt(1 − cos θ)) (texel nodes at i/(n − 1): ltc_code's `uv·(63/64) + 0.5/64`),
//! the LTC's polygon integral clipped in its cosine space ([`Ltc::polygon`]) times the
//! magnitude (ltc_2.x; F0 = 1, so the Fresnel texel drops out), or the sphere path: the
//! unclipped polygon's vector form factor F, then |F| · w(F_z/|F|, |F|) with w the clipped
//! sphere form factor ([`super::sphere`]). The error a user sees is reported as a share of the
//! lobe's energy E(μv) (|LTC − I|/E: comparable across roughness, bounded by δ/2 + the
//! interpolation error), and as a relative error where I ≥ E/20.
//!
//! The committed set: [`lights`] (in the shading frame: normal z, view in the xz-plane) and
//! [`views`] (between the table's nodes, where interpolation adds to the fit's error).

use super::sphere;
use super::transform::{Ltc, Vec3, clip_to_horizon, cross, dot, norm, normalize};
use crate::integrate::{Tolerance, adaptive};
use crate::shading::Lobe;

/// Relative tolerance of the reference (its error estimate is the change at a hundredth).
pub const TOLERANCE: f64 = 1e-6;

/// A committed light: a convex polygon facing the shaded point (the origin), one-sided.
#[derive(Debug, Clone)]
pub struct Light {
    pub name: &'static str,
    pub vertices: Vec<Vec3>,
}

/// A rectangle of `width` × `height` centred at `centre`, facing the origin (its vertices wound
/// counter-clockwise about the direction from the origin to it, as a one-sided light that
/// shines on the origin), its width along the horizontal tangent of the direction to it.
pub fn facing_rectangle(centre: Vec3, width: f64, height: f64) -> Vec<Vec3> {
    let t = normalize(centre);
    let side = if t[2].abs() > 0.999 { [0.0, 1.0, 0.0] } else { normalize(cross([0.0, 0.0, 1.0], t)) };
    let up = cross(t, side);
    let at = |sx: f64, sy: f64| std::array::from_fn(|k| centre[k] + sx * 0.5 * width * side[k] + sy * 0.5 * height * up[k]);
    vec![at(-1.0, -1.0), at(1.0, -1.0), at(1.0, 1.0), at(-1.0, 1.0)]
}

/// The committed lights: small and large rectangles overhead, at the reflection side, across
/// the horizon and to the side, a long strip, a tilted panel and a triangle.
pub fn lights() -> Vec<Light> {
    let tri = {
        let c = [0.4, 1.2, 0.9];
        let t = normalize(c);
        let a = normalize(cross(t, [1.0, 0.0, 0.0]));
        let b = cross(t, a);
        let p = |u: f64, v: f64| std::array::from_fn(|k| c[k] + u * a[k] + v * b[k]);
        vec![p(0.0, 0.5), p(-0.45, -0.3), p(0.45, -0.3)]
    };
    vec![
        Light { name: "small overhead square", vertices: facing_rectangle([0.0, 0.0, 3.0], 0.5, 0.5) },
        Light { name: "large overhead panel", vertices: facing_rectangle([0.0, 0.0, 1.0], 2.5, 2.5) },
        Light { name: "reflection side, 45 degrees", vertices: facing_rectangle([-1.5, 0.0, 1.5], 0.8, 0.6) },
        Light { name: "reflection side, 70 degrees", vertices: facing_rectangle([-2.0, 0.2, 0.73], 0.9, 0.5) },
        Light { name: "across the horizon, reflection side", vertices: facing_rectangle([-1.8, 0.0, 0.15], 1.0, 0.8) },
        Light { name: "view side, 40 degrees", vertices: facing_rectangle([1.2, 0.3, 1.4], 0.7, 0.7) },
        Light { name: "long strip to the side", vertices: facing_rectangle([0.3, 1.5, 1.0], 2.0, 0.1) },
        Light { name: "triangle to the side", vertices: tri },
    ]
}

/// A view: the table's roughness (√α) and the polar angle θ of v.
#[derive(Debug, Clone, Copy)]
pub struct View {
    pub roughness: f64,
    pub theta: f64,
}

/// The committed views: roughness 0.2–0.9 and θ 0–85°, none on a table node of 64.
pub fn views() -> Vec<View> {
    let mut out = Vec::new();
    for roughness in [0.2, 0.35, 0.5, 0.7, 0.9] {
        for deg in [0.0f64, 25.0, 50.0, 70.0, 85.0] {
            out.push(View { roughness, theta: deg.to_radians() });
        }
    }
    out
}

/// I = ∫_P f(v, l) max(0, l_z) dl for the lobe at view angle θ (see the module doc), with the
/// estimate of its error.
pub fn reference<L: Lobe>(lobe: &L, theta: f64, vertices: &[Vec3]) -> (f64, f64) {
    let coarse = integrate_polygon(lobe, theta, vertices, TOLERANCE);
    let fine = integrate_polygon(lobe, theta, vertices, TOLERANCE * 1e-2);
    (fine, (fine - coarse).abs())
}

fn integrate_polygon<L: Lobe>(lobe: &L, theta: f64, vertices: &[Vec3], rel: f64) -> f64 {
    let (s, mu_v) = theta.sin_cos();
    let v = [s, 0.0, mu_v];
    let view = lobe.view(mu_v);
    let p = clip_to_horizon(vertices);
    if p.len() < 3 {
        return 0.0;
    }
    let n_p = normalize(cross(sub(p[1], p[0]), sub(p[2], p[0])));
    let f = |x: Vec3| {
        let r2 = dot(x, x);
        let l = normalize(x);
        if l[2] <= 0.0 {
            return 0.0;
        }
        let h = normalize([v[0] + l[0], v[1] + l[1], v[2] + l[2]]);
        let vh = dot(v, h);
        if vh <= 0.0 {
            return 0.0;
        }
        lobe.eval(&view, vh, h[2], l[2]) * l[2] * dot(n_p, l).abs() / r2
    };
    let tol = Tolerance { abs: 0.0, rel, max_panels: 4000 };
    let mut sum = 0.0;
    for k in 1..p.len() - 1 {
        let (a, b, c) = (p[0], p[k], p[k + 1]);
        let (ab, bc) = (sub(b, a), sub(c, b));
        let area2 = norm(cross(ab, bc));
        sum += adaptive(0.0, 1.0, tol, |u| {
            u * area2 * adaptive(0.0, 1.0, tol, |w| f(std::array::from_fn(|i| a[i] + u * ab[i] + u * w * bc[i]))).value
        })
        .value;
    }
    sum
}

fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Bilinear interpolation of an `n` × `n` table (texel i + j·n at nodes i/(n − 1), j/(n − 1))
/// at (x, y), clamped to [0, 1]² as a clamp-to-edge sampler does.
pub fn lookup(texels: &[[f64; 4]], n: usize, x: f64, y: f64) -> [f64; 4] {
    let at = |t: f64| {
        let s = t.clamp(0.0, 1.0) * (n - 1) as f64;
        let i = (s.floor() as usize).min(n - 2);
        (i, s - i as f64)
    };
    let ((i, fx), (j, fy)) = (at(x), at(y));
    let t = |i: usize, j: usize| texels[i + j * n];
    std::array::from_fn(|c| {
        let lo = t(i, j)[c] * (1.0 - fx) + t(i + 1, j)[c] * fx;
        let hi = t(i, j + 1)[c] * (1.0 - fx) + t(i + 1, j + 1)[c] * fx;
        lo * (1.0 - fy) + hi * fy
    })
}

/// The shader's two results (clipped polygon, sphere path) for the texels `t1`, `t2` looked up at
/// a view of polar angle θ ≤ π/2 in the xz-plane: ∫ over the polygon of the LTC × magnitude.
pub fn shaded(t1: [f64; 4], t2: [f64; 4], vertices: &[Vec3]) -> (f64, f64) {
    let ltc = Ltc::from_texel(t1);
    let clipped = ltc.polygon(vertices).max(0.0) * t2[0];
    let q: Vec<Vec3> = vertices.iter().map(|&p| normalize(ltc.to_cosine(p))).collect();
    let mut f = [0.0; 3];
    for i in 0..q.len() {
        let (a, b) = (q[i], q[(i + 1) % q.len()]);
        let c = cross(a, b);
        let s = norm(c);
        if s > 0.0 {
            let angle = s.atan2(dot(a, b));
            for k in 0..3 {
                f[k] += angle * c[k] / s / (2.0 * std::f64::consts::PI);
            }
        }
    }
    let len = norm(f);
    let sphere_path = if len > 0.0 { len.min(1.0) * sphere::clipped_ratio(f[2] / len, len.min(1.0)) } else { 0.0 };
    (clipped, sphere_path * t2[0])
}

/// One measured (light, view) pair.
#[derive(Debug, Clone, Copy)]
pub struct Measured {
    pub light: usize,
    pub view: usize,
    pub reference: f64,
    pub reference_error: f64,
    /// E(μv) of the lobe (the share's denominator).
    pub energy: f64,
    pub clipped: f64,
    pub sphere: f64,
}

/// The reference integrals and lobe energies of every committed (light, view) for a lobe made
/// per α by `lobe` (α = roughness²), in parallel, light fastest.
pub fn references<L: Lobe>(lobe: &(dyn Fn(f64) -> L + Sync)) -> Vec<(f64, f64, f64)> {
    use rayon::prelude::*;
    let (ls, vs) = (lights(), views());
    (0..ls.len() * vs.len())
        .into_par_iter()
        .map(|k| {
            let (light, view) = (&ls[k % ls.len()], vs[k / ls.len()]);
            let l = lobe(view.roughness * view.roughness);
            let (r, e) = reference(&l, view.theta, &light.vertices);
            let energy = crate::shading::hemisphere::albedo(&l, view.theta.cos(), 1e-10).value;
            (r, e, energy)
        })
        .collect()
}

/// The shader's results for the tables `t1`, `t2` (n × n) against `refs` ([`references`]).
pub fn measure(t1: &[[f64; 4]], t2: &[[f64; 4]], n: usize, refs: &[(f64, f64, f64)]) -> Vec<Measured> {
    let (ls, vs) = (lights(), views());
    refs.iter()
        .enumerate()
        .map(|(k, &(reference, reference_error, energy))| {
            let (light, view) = (k % ls.len(), k / ls.len());
            let v = vs[view];
            let (x, y) = (v.roughness, (1.0 - v.theta.cos()).max(0.0).sqrt());
            let (clipped, sphere) = shaded(lookup(t1, n, x, y), lookup(t2, n, x, y), &ls[light].vertices);
            Measured { light, view, reference, reference_error, energy, clipped, sphere }
        })
        .collect()
}

/// Summary of a set of measured pairs: (max, rms) of |LTC − I|/E for the clipped path and the
/// sphere path, the largest relative error |LTC − I|/I over pairs with I ≥ E/20 (clipped path),
/// and the largest reference error estimate over E.
pub fn summary(m: &[Measured]) -> [f64; 6] {
    let share = |x: f64, r: &Measured| (x - r.reference).abs() / r.energy;
    let stats = |f: &dyn Fn(&Measured) -> f64| {
        let v: Vec<f64> = m.iter().map(f).collect();
        (v.iter().copied().fold(0.0, f64::max), (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt())
    };
    let (cm, cr) = stats(&|r| share(r.clipped, r));
    let (sm, sr) = stats(&|r| share(r.sphere, r));
    let rel = m.iter().filter(|r| r.reference >= r.energy / 20.0).map(|r| (r.clipped - r.reference).abs() / r.reference).fold(0.0, f64::max);
    let est = m.iter().map(|r| r.reference_error / r.energy).fold(0.0, f64::max);
    [cm, cr, sm, sr, rel, est]
}

/// Least roughness of [`per_cell`]: below it the lobe's peak is narrower than the reference's
/// panel budget resolves over a whole light.
pub const PER_CELL_MIN_ROUGHNESS: f64 = 0.25;

/// Per cell of an `n` × `n` table at its nodes, roughness ≥ [`PER_CELL_MIN_ROUGHNESS`] (`None`
/// below): for each of `tables` (ltc_1, ltc_2 texels) the largest |LTC − I|/E over the committed
/// lights through the cell's own texels (clipped path, no interpolation), and the largest
/// reference error estimate over E. Cells in parallel, in order.
#[allow(clippy::type_complexity)]
pub fn per_cell<L: Lobe>(lobe: &(dyn Fn(f64) -> L + Sync), n: usize, min_alpha: f64, tables: &[(&[[f64; 4]], &[[f64; 4]])]) -> Vec<Option<(Vec<f64>, f64)>> {
    use rayon::prelude::*;
    let ls = lights();
    (0..n * n)
        .into_par_iter()
        .map(|k| {
            let (i, j) = (k % n, k / n);
            if (i as f64) < PER_CELL_MIN_ROUGHNESS * (n - 1) as f64 {
                return None;
            }
            let (alpha, theta) = super::fit::cell_parameters(i, j, n, min_alpha);
            let l = lobe(alpha);
            let energy = crate::shading::hemisphere::albedo(&l, theta.cos(), 1e-10).value;
            let mut worst = vec![0.0f64; tables.len()];
            let mut estimate = 0.0f64;
            for light in &ls {
                let (r, e) = reference(&l, theta, &light.vertices);
                for (w, (t1, t2)) in worst.iter_mut().zip(tables) {
                    *w = w.max((shaded(t1[k], t2[k], &light.vertices).0 - r).abs() / energy);
                }
                estimate = estimate.max(e / energy);
            }
            Some((worst, estimate))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shading::lambert::Lambert;

    /// For a Lambertian lobe the reference is the polygon's clipped irradiance, whose closed
    /// form is Lambert's edge sum: the quadrature agrees to 1e-9 relative (its tolerance is
    /// 1e-8) on every committed light, the one across the horizon included; and the identity
    /// LTC with magnitude 1 is exact through both shader paths where the light is above the
    /// horizon (the sphere path approximates the clipping only).
    #[test]
    fn the_reference_of_a_clamped_cosine_is_lambert_s_formula() {
        for light in lights() {
            let (r, e) = reference(&Lambert, 0.4, &light.vertices);
            let exact = super::super::transform::polygon_cosine(&light.vertices);
            assert!((r - exact).abs() < 1e-9 * exact.max(1e-3) && e < 1e-6 * exact, "{}: {r} vs {exact} (± {e})", light.name);
            let (clipped, sphere_path) = shaded(Ltc::IDENTITY.texel(), [1.0, 0.0, 0.0, 0.0], &light.vertices);
            assert!((clipped - exact).abs() < 1e-12, "{}: {clipped} vs {exact}", light.name);
            if light.vertices.iter().all(|p| p[2] > 0.0) {
                assert!((sphere_path - exact).abs() < 1e-12, "{}: {sphere_path} vs {exact}", light.name);
            }
        }
    }

    /// For a peaked GGX lobe (α = 0.04) the reference is additive: a rectangle's integral is
    /// the sum of its four quarters' to 1e-7 relative (each is converged to 1e-8; the quarters'
    /// shared edges cut the peak differently).
    #[test]
    fn the_reference_is_additive_for_a_peaked_lobe() {
        let g = crate::shading::trowbridge_reitz::Ggx::new(0.04, crate::shading::trowbridge_reitz::Shadowing::HeightCorrelated);
        let (c, w) = ([-1.5, 0.0, 1.5], 0.8);
        let whole = facing_rectangle(c, w, w);
        let (r, _) = reference(&g, 0.7, &whole);
        let mid = |a: Vec3, b: Vec3| -> Vec3 { std::array::from_fn(|k| 0.5 * (a[k] + b[k])) };
        let centre = mid(whole[0], whole[2]);
        let mut sum = 0.0;
        for k in 0..4 {
            let (a, b, d) = (whole[k], whole[(k + 1) % 4], whole[(k + 3) % 4]);
            sum += reference(&g, 0.7, &[a, mid(a, b), centre, mid(a, d)]).0;
        }
        assert!(r > 0.01 && (sum - r).abs() < 1e-7 * r, "{r} vs {sum}");
    }

    /// Bilinear lookup hits the texel values at the nodes and is linear between them.
    #[test]
    fn lookup_interpolates_between_nodes() {
        let n = 4;
        let t: Vec<[f64; 4]> = (0..n * n).map(|k| [(k % n) as f64, (k / n) as f64, 1.0, 0.0]).collect();
        assert_eq!(lookup(&t, n, 1.0 / 3.0, 2.0 / 3.0), [1.0, 2.0, 1.0, 0.0]);
        let m = lookup(&t, n, 0.5, 0.25);
        assert!((m[0] - 1.5).abs() < 1e-12 && (m[1] - 0.75).abs() < 1e-12);
        assert_eq!(lookup(&t, n, 2.0, -1.0)[0], 3.0);
    }
}

/// `cargo test --release --lib ltc_end_to_end_report -- --ignored --nocapture`: the committed
/// lights and views through ltc_code's tables and through shadefit's 64² GGX fit (both in
/// binary16, as a filterable texture holds them), against the reference.
#[cfg(test)]
mod report {
    use super::*;
    use crate::family::ltc::{fit, published};

    #[test]
    #[ignore]
    fn ltc_end_to_end_report() {
        let t0 = std::time::Instant::now();
        let refs = references(&published::ggx);
        eprintln!("references: {:?}", t0.elapsed());
        let (p1, p2) = published::tables();
        let t = fit::fit_table(64, published::MIN_ALPHA, fit::FIT_NODES, &published::ggx);
        let h = |x: f64| half::f16::from_f64(x).to_f64();
        let w = super::sphere::table(64);
        let s1: Vec<[f64; 4]> = t.cells.iter().map(|c| c.ltc.texel().map(h)).collect();
        let s2: Vec<[f64; 4]> = t.cells.iter().zip(&w).map(|(c, &w)| [c.magnitude, c.fresnel, 0.0, w].map(h)).collect();
        for (name, t1, t2) in [("ltc_code", &p1, &p2), ("shadefit", &s1, &s2)] {
            let m = measure(t1, t2, 64, &refs);
            let s = summary(&m);
            eprintln!("{name}: clipped max {:.4} rms {:.4}; sphere max {:.4} rms {:.4}; rel max {:.4}; ref est {:.1e}", s[0], s[1], s[2], s[3], s[4], s[5]);
            for r in &m {
                eprintln!("  light {} view {:2}: ref {:.5} E {:.4} clipped {:.5} sphere {:.5}", r.light, r.view, r.reference, r.energy, r.clipped, r.sphere);
            }
        }
    }
}
