//! The previous formulation of R, kept as an independent reference for the tests of
//! [`super::r`]: u over the upper hemisphere only, in fiber coordinates (a = u·t = cos A, η_u),
//!
//! ```text
//! R = (2/π) ∫ sin A J(A) dA,   J(A) = ∫_{η_min}^{π} μu P_s dη_u
//! ```
//!
//! with P_s by the 1-D w-integral of [`super::Layer::ps`]. For fixed A the cone w = −a and all
//! breakpoints in w are the same for every η_u, and the whole-circle part of I does not depend
//! on η_u: it is integrated once, times ∫ μu dη_u (closed form). The arc part is integrated in w
//! once for all 15 nodes of a G7/K15 rule in η_u together (error control on every node,
//! weighted as in the rule); nodes with a grazing scale below L/16 get their own banded
//! integration. μu P_s is smooth in η_u, so G7/K15 panels suffice, bisected while the rule's
//! estimate exceeds its share. The A-integral is split at π/2 − θf (the u-circle touches the
//! horizon, the cone crosses w = −sin θf) and the second piece, up to π/2 + θf, carries a
//! smoothstep end map; GL32/GL24 panels. A triple integral (A, η_u, w) around the closed-form
//! Δ-integral: 0.1–0.4·10⁶ arc evaluations per R at 1e-7, which is why the production R
//! integrates over the whole sphere instead (two dimensions fewer, module doc of `super`).
//! It shares the P_s machinery (pieces, arc integrals) with the production code but none of
//! R's reduction.

#![allow(clippy::excessive_precision)]

use super::*;
use super::atan::atan2_upper;
use std::f64::consts::FRAC_PI_2;
use super::ps::{Piece, Region};
use crate::integrate::{GaussPair, Rule, quadpack_error};

/// End map of [0, 1] onto itself with vanishing derivative at the flagged ends (removes
/// square-root endpoint behaviour): (g(t), g'(t)).
fn end_map(t: f64, lo: bool, hi: bool) -> (f64, f64) {
    match (lo, hi) {
        (false, false) => (t, 1.0),
        (true, false) => (t * t, 2.0 * t),
        (false, true) => (t * (2.0 - t), 2.0 * (1.0 - t)),
        (true, true) => (t * t * (3.0 - 2.0 * t), 6.0 * t * (1.0 - t)),
    }
}


/// GL32/GL24: the outer A-integral (its analytic integrand usually needs one panel, where
/// G10/K21 needs several bisections because its estimate is the G10 error).
fn gl_pair_32() -> &'static GaussPair {
    static RULES: std::sync::OnceLock<GaussPair> = std::sync::OnceLock::new();
    RULES.get_or_init(|| GaussPair::new(32, 24))
}


// G7/K15 on [-1, 1] (QUADPACK qk15), used for the η_u rule.
const XGK15: [f64; 8] = [
    0.991455371120812639206854697526329,
    0.949107912342758524526189684047851,
    0.864864423359769072789712788640926,
    0.741531185599394439863864773280788,
    0.586087235467691130294144845693013,
    0.405845151377397166906606412076961,
    0.207784955007898467600689403773245,
    0.000000000000000000000000000000000,
];
const WGK15: [f64; 8] = [
    0.022935322010529224963732008058970,
    0.063092092629978553290700663189204,
    0.104790010322250183839876322541518,
    0.140653259715525918745189590510238,
    0.169004726639267902826583426598550,
    0.190350578064785409913256402421014,
    0.204432940075298892414161999234649,
    0.209482141084727828012999174891714,
];
/// Gauss 7-point weights of the Kronrod nodes 1, 3, 5 and the centre.
const WG7: [f64; 4] = [
    0.129484966168869693270611432679082,
    0.279705391489276667901467771423780,
    0.381830050505118944950369775488975,
    0.417959183673469387755102040816327,
];

/// The 15 nodes of G7/K15 on [-1, 1] with Kronrod and Gauss weights (0 where not a Gauss node).
fn k15_rule() -> [(f64, f64, f64); 15] {
    let mut r = [(0.0, 0.0, 0.0); 15];
    for j in 0..7 {
        let g = if j % 2 == 1 { WG7[j / 2] } else { 0.0 };
        r[j] = (-XGK15[j], WGK15[j], g);
        r[14 - j] = (XGK15[j], WGK15[j], g);
    }
    r[7] = (0.0, WGK15[7], WG7[3]);
    r
}


/// acos(c/b) for b > 0, |c| < b, accurate near both ends: 2·atan2(sqrt(b − c), sqrt(b + c)),
/// with the smaller of b ∓ c recomputed from (b − c)(b + c) = prod when given.
fn half_width(b: f64, c: f64, prod: f64) -> f64 {
    let (mut bm, mut bp) = (b - c, b + c);
    if c < 0.0 {
        bp = prod / bm;
    } else {
        bm = prod / bp;
    }
    2.0 * atan2_upper(bm.max(0.0).sqrt(), bp.max(0.0).sqrt())
}


impl Layer {
    /// ∫ I dw over the arc region only, for one light with the grazing band given:
    /// (value, error, evals), in the raw units of `ps` (before the 1/(4σπα) factor).
    fn arc_part(&self, l: &Light, band: Option<f64>, tol: f64) -> (f64, f64, u64) {
        let pieces = self.pieces(l.a, l.sa, band);
        let n = pieces.iter().filter(|p| p.region == Region::Arc).count().max(1);
        let (mut value, mut error, mut evals) = (0.0, 0.0, 0);
        for piece in pieces.iter().filter(|p| p.region == Region::Arc) {
            let (v, e, k) = gk21_adaptive(0.0, 1.0, tol / n as f64, &[1.0], |t| {
                let (eps, jac, prod) = piece.map(t);
                if jac == 0.0 {
                    return [0.0];
                }
                let wp = self.wpoint(l.a, l.sa, eps);
                let (eta0, s0, c0) = self.arc_half_width(wp.w, prod);
                [Self::arc(&wp, eta0, s0, c0, l.sh, l.ch) * jac]
            });
            value += v[0];
            error += e;
            evals += k;
        }
        (value, error, evals)
    }

    /// One G7/K15 panel [lo, hi] in η_u of the arc part of J (raw units):
    /// (lo, hi, Σ k_j μ_j ∫_arc I(w; η_j) dw, its w-error, the rule's error estimate).
    /// `share` bounds the w-error; the shared vector integration controls every node.
    #[allow(clippy::too_many_arguments)]
    fn eta_panel(
        &self,
        a: f64,
        sa: f64,
        lo: f64,
        hi: f64,
        share: f64,
        pieces: &[Piece],
        n_arc: usize,
        evals: &mut u64,
    ) -> (f64, f64, f64, f64, f64) {
        let rule = k15_rule();
        let (b, c) = (sa * self.st, a * self.ct);
        let hl = 0.5 * (hi - lo);
        let c_eta = 0.5 * (hi + lo);
        let mut lights = [self.light_fiber(a, sa, 0.0); 15];
        let mut mu = [0.0; 15];
        let mut grazing = [false; 15];
        let mut bands = [None; 15];
        let mut ew = [0.0; 15];
        let scale = self.peak_scale(sa);
        let mut s_shared = f64::INFINITY;
        for j in 0..15 {
            let eta = c_eta + hl * rule[j].0;
            lights[j] = self.light_fiber(a, sa, eta);
            mu[j] = (c - b * eta.cos()).max(0.0);
            // A grazing feature below scale s changes the node's arc integral by at most
            // ≈ 4π s²/(α s_a) (within |ε| < s the arc integral departs from its smooth
            // continuation by ≤ 2π f1 ≤ 4π sqrt(1−α²)|ε|/(α s_a)); the node needs its own
            // banded integration only when that, weighted, could exceed a part of the share.
            // Scales below s_f are harmless: cut the band there.
            let wj = hl * rule[j].1 * mu[j];
            let s_f = if wj > 0.0 {
                (0.05 * share / 15.0 * self.alpha * sa / (4.0 * PI * wj)).sqrt()
            } else {
                f64::INFINITY
            };
            // Feature scales s < L/16: the node gets its own banded integration; up to L/2:
            // the shared integration gets a (short) band reaching down to the smallest of them.
            let s = self.graze_scale(a, sa, eta).max(s_f);
            bands[j] = self.graze_band(sa, s);
            grazing[j] = s < scale / 16.0;
            if !grazing[j] && bands[j].is_some() {
                s_shared = s_shared.min(s);
            }
            ew[j] = if grazing[j] { 0.0 } else { wj };
        }
        let n_graze = grazing.iter().filter(|&&g| g).count();
        let shared =
            if s_shared.is_finite() { self.pieces(a, sa, Some(s_shared)) } else { pieces.to_vec() };
        let n_arc = shared.iter().filter(|p| p.region == Region::Arc).count().max(n_arc);
        // Node integrals ∫_arc I(w; η_j) dw.
        let (mut node, mut err) = ([0.0; 15], 0.0);
        if n_graze < 15 {
            for piece in shared.iter().filter(|p| p.region == Region::Arc) {
                let frac = (15 - n_graze) as f64 / 15.0;
                let (v, e, n) = gk21_adaptive(0.0, 1.0, frac * share / n_arc as f64, &ew, |t| {
                    let mut out = [0.0; 15];
                    let (eps, jac, prod) = piece.map(t);
                    if jac == 0.0 {
                        return out;
                    }
                    let wp = self.wpoint(a, sa, eps);
                    let (eta0, s0, c0) = self.arc_half_width(wp.w, prod);
                    for j in 0..15 {
                        if !grazing[j] {
                            let l = &lights[j];
                            out[j] = Self::arc(&wp, eta0, s0, c0, l.sh, l.ch) * jac;
                        }
                    }
                    out
                });
                for (nv, vv) in node.iter_mut().zip(v) {
                    *nv += vv;
                }
                err += e;
                *evals += (15 - n_graze) as u64 * n;
            }
        }
        for j in (0..15).filter(|&j| grazing[j]) {
            let wj = hl * rule[j].1 * mu[j];
            if wj <= 0.0 {
                continue;
            }
            let (v, e, n) = self.arc_part(&lights[j], bands[j], share / (15.0 * wj));
            node[j] = v;
            err += wj * e;
            *evals += n;
        }
        // η_u-rule value and error (QUADPACK estimate).
        let f: Vec<f64> = (0..15).map(|j| mu[j] * node[j]).collect();
        let resk: f64 = (0..15).map(|j| rule[j].1 * f[j]).sum();
        let resg: f64 = (0..15).map(|j| rule[j].2 * f[j]).sum();
        let mean = 0.5 * resk;
        let resasc: f64 = (0..15).map(|j| rule[j].1 * (f[j] - mean).abs()).sum();
        let resabs: f64 = (0..15).map(|j| rule[j].1 * f[j].abs()).sum();
        let ee = quadpack_error(((resk - resg) * hl).abs(), resasc * hl, resabs * hl);
        (lo, hi, resk * hl, err, ee)
    }

    /// J(A) = ∫_{η_min}^{π} μu P_s dη_u for u·t = a = cos A: (value, error, evals).
    ///
    /// J = 1/(4σπα) [M ∫_full I dw + Σ_j k_j μ_j ∫_arc I(w; η_j) dw], M = ∫ μu dη_u (closed
    /// form), k_j the G7/K15 weights on [η_min, π] (split in 2, 4, … panels while the rule's
    /// estimate exceeds its share). The non-grazing nodes share one adaptive w-integration
    /// (error control on every node); nodes whose grazing band is active get their own.
    fn j_of_a(&self, a: f64, sa: f64, tol: f64) -> (f64, f64, u64) {
        // u above the horizon: s_a sin θf cos η_u < a cos θf.
        let b = sa * self.st;
        let c = a * self.ct;
        let eta_min = if c >= b {
            0.0
        } else if c <= -b {
            return (0.0, 0.0, 0);
        } else {
            // (b − c)(b + c) = s_a² sin²θf − a² cos²θf = sin²θf − a²
            half_width(b, c, (self.st - a) * (self.st + a))
        };
        let m_eta = a * self.ct * (PI - eta_min) + b * eta_min.sin();
        let sigma = self.light_fiber(a, sa, 0.0).sigma;
        let norm = 1.0 / (4.0 * sigma * PI * self.alpha);
        let pieces = self.pieces(a, sa, None);
        let n_full = pieces.iter().filter(|p| p.region == Region::Full).count();
        let n_arc = pieces.len() - n_full;
        // Raw-unit budgets: 10% for the whole-circle part (one panel or two, its estimate
        // tiny), 45% each for the arc w-integrations and the η_u rule.
        let budget = 0.45 * tol / norm;
        let mut evals = 0;

        // Whole-circle part: independent of η_u.
        let (mut w_full, mut e_full) = (0.0, 0.0);
        if m_eta > 0.0 {
            for piece in pieces.iter().filter(|p| p.region == Region::Full) {
                let (v, e, n) = gk21_adaptive(
                    0.0,
                    1.0,
                    0.1 * tol / norm / m_eta / n_full as f64,
                    &[1.0],
                    |t| {
                        let (eps, jac, _) = piece.map(t);
                        if jac == 0.0 {
                            return [0.0];
                        }
                        [Self::full_circle(&self.wpoint(a, sa, eps)) * jac]
                    },
                );
                w_full += v[0];
                e_full += e;
                evals += n;
            }
        }

        // Arc part: G7/K15 panels in η_u, the worst bisected while the rule's estimate exceeds
        // its share (at most 16 panels).
        let (mut w_arc, mut e_arc, mut e_eta) = (0.0, 0.0, 0.0);
        if n_arc > 0 {
            let span = PI - eta_min;
            // (lo, hi, value, w-error, η-error)
            let mut panels =
                vec![self.eta_panel(a, sa, eta_min, PI, budget, &pieces, n_arc, &mut evals)];
            loop {
                let ee: f64 = panels.iter().map(|p| p.4).sum();
                if ee <= budget || panels.len() >= 16 {
                    break;
                }
                let (worst, _) = panels
                    .iter()
                    .enumerate()
                    .max_by(|(_, p), (_, q)| p.4.total_cmp(&q.4).then(q.0.total_cmp(&p.0)))
                    .unwrap_or((0, &panels[0]));
                let p = panels.swap_remove(worst);
                let mid = 0.5 * (p.0 + p.1);
                let share = budget * (mid - p.0) / span;
                panels.push(self.eta_panel(a, sa, p.0, mid, share, &pieces, n_arc, &mut evals));
                panels.push(self.eta_panel(a, sa, mid, p.1, share, &pieces, n_arc, &mut evals));
            }
            panels.sort_by(|p, q| p.0.total_cmp(&q.0));
            for p in &panels {
                w_arc += p.2;
                e_arc += p.3;
                e_eta += p.4;
            }
        }
        let value = norm * (m_eta * w_full + w_arc);
        let error = norm * (m_eta * e_full + e_arc + e_eta);
        (value, error, evals)
    }

    /// R = (2/π) ∫ sin A J(A) dA.
    pub(super) fn r_horizon(&self, tol: f64) -> Estimate {
        let theta = self.theta();
        let split = FRAC_PI_2 - theta;
        let mut pieces = Vec::with_capacity(2);
        if split > 0.0 {
            pieces.push((0.0, split, false, false));
        }
        if theta > 0.0 {
            pieces.push((split, FRAC_PI_2 + theta, true, true));
        }
        // Inner budget: the propagated inner error ∫₀¹ (2/π) sin A (dA/dt) e_J dt stays below
        // 0.9 tol when each node's e_J ≤ 0.9 tol/(n_pieces (2/π) sin A dA/dt) (loose where the
        // outer weight is small); the outer panels (whose estimates are tiny) get 0.1 tol.
        let mut value = 0.0;
        let mut error = 0.0;
        let mut evals = 0;
        for &(lo, hi, ls, hs) in &pieces {
            let d = hi - lo;
            // Component 1 carries the inner errors along (weight 0: integrated, not checked).
            let opts = Options {
                rule: Rule::GaussPair(gl_pair_32()),
                ..Options::quadpack([1.0, 0.0], 0.1 * tol / pieces.len() as f64, 64)
            };
            let est = integrate(&[(0.0, 1.0)], &opts, |t| {
                let (g, gp) = end_map(t, ls, hs);
                let jac = d * gp;
                if jac == 0.0 {
                    return [0.0, 0.0];
                }
                let (sa, a) = (lo + d * g).sin_cos();
                let wgt = 2.0 / PI * sa * jac;
                let tol_j = (0.9 * tol / pieces.len() as f64 / wgt).min(1.0);
                let (j, ej, n) = self.j_of_a(a, sa, tol_j);
                evals += n;
                [wgt * j, wgt * ej]
            });
            value += est.value[0];
            error += est.error + est.value[1];
        }
        Estimate { value, error: error.max(ERROR_FLOOR), evals }
    }
}
