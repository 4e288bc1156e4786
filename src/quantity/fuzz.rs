//! Anisotropic asperity scattering ("fuzz") quantities: P_s, G, Q, R (draft).

use crate::integrate::{adaptive, Estimate, Tolerance};
use std::f64::consts::PI;

pub const DEFAULT_TOL: f64 = 1e-9;

/// Fiber-layer parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FuzzParams {
    pub alpha: f64,
    pub theta_f: f64,
}

/// Per-(α, θf) constants.
#[derive(Debug, Clone, Copy)]
struct Layer {
    alpha: f64,
    a2: f64,
    k2: f64,
    ct: f64,
    st: f64,
}

impl Layer {
    fn new(alpha: f64, theta_f: f64) -> Self {
        let (st, ct) = theta_f.sin_cos();
        Layer { alpha, a2: alpha * alpha, k2: (1.0 - alpha) * (1.0 + alpha), ct, st }
    }
}

/// Light geometry in the fiber frame.
#[derive(Debug, Clone, Copy)]
struct Light {
    a: f64,
    sa: f64,
    eta: f64,
    sigma: f64,
}

impl Layer {
    fn light(&self, theta_u: f64, phi_u: f64) -> Light {
        let (su, cu) = theta_u.sin_cos();
        let (sp, cp) = phi_u.sin_cos();
        let a = self.st * su * cp + self.ct * cu;
        let u1 = self.ct * su * cp - self.st * cu;
        let u2 = su * sp;
        let sa = u1.hypot(u2);
        let eta = u2.atan2(u1);
        let sigma = (sa * sa + self.a2 * a * a).sqrt();
        Light { a, sa, eta, sigma }
    }

    /// Δ-integral of D_F over an arc set, times πα.
    /// eps = a + w, w = -a + eps.
    fn inner(&self, l: &Light, eps: f64, arc: Arc) -> f64 {
        let w = -l.a + eps;
        let sw = ((1.0 - w) * (1.0 + w)).max(0.0).sqrt();
        let m = 1.0 + l.a * w;
        let rho = l.sa * sw;
        let p = m + rho;
        let len = match arc {
            Arc::Full => 2.0 * PI,
            Arc::Part(d1, d2) => d2 - d1,
            Arc::Wrap(d1, d2) => 2.0 * PI - (d2 - d1),
            Arc::Empty => return 0.0,
        };
        let e = eps.abs();
        if e == 0.0 || self.k2 == 0.0 || p <= 0.0 {
            return len;
        }
        let k2 = self.k2;
        let kk = k2 * e * e;
        let r = kk + 2.0 * self.a2 * m;
        let s = 2.0 * self.a2 * rho;
        let c1 = k2 + 2.0 * self.a2 / p;
        let rps = kk + 2.0 * self.a2 * p;
        let root = (c1 * rps).sqrt();
        let tau = e * (c1 / rps).sqrt();
        let phi = |x: f64| {
            let (sh, ch) = (0.5 * x).sin_cos();
            (tau * sh).atan2(ch)
        };
        let z = |x: f64| {
            let ch = (0.5 * x).cos();
            e * e * c1 + 2.0 * s * ch * ch
        };
        // (Δ length, Φ difference, sin/z difference) over the arc (or its complement).
        let terms = |d1: f64, d2: f64| -> (f64, f64) {
            (phi(d2) - phi(d1), d2.sin() / z(d2) - d1.sin() / z(d1))
        };
        let (dphi, sig) = match arc {
            Arc::Full => (PI, 0.0),
            Arc::Part(d1, d2) => terms(d1, d2),
            Arc::Wrap(d1, d2) => {
                let (dp, sg) = terms(d1, d2);
                (PI - dp, -sg)
            }
            Arc::Empty => unreachable!(),
        };
        let kj1 = 2.0 * k2 * e * dphi / root;
        let kkj2 = k2 * k2 / (c1 * rps) * (2.0 * r * e * dphi / root - e * e * s * sig);
        len - 2.0 * kj1 + kkj2
    }

    /// Arc of Δ = η − η_u where v_z < 0, for v·t = w.
    fn arc(&self, l: &Light, eps: f64) -> Arc {
        let w = -l.a + eps;
        let sw = ((1.0 - w) * (1.0 + w)).max(0.0).sqrt();
        let b = sw * self.st;
        let c = w * self.ct;
        if b <= 0.0 {
            return if c < 0.0 { Arc::Full } else { Arc::Empty };
        }
        // cos η > c/b ; η0 = acos(c/b) = 2 atan2(sqrt(b - c), sqrt(b + c))
        if c <= -b {
            return Arc::Full;
        }
        if c >= b {
            return Arc::Empty;
        }
        let eta0 = 2.0 * (b - c).sqrt().atan2((b + c).sqrt());
        let center = -l.eta;
        let lo = center - eta0;
        let hi = center + eta0;
        if lo < -PI {
            Arc::Wrap(hi, lo + 2.0 * PI)
        } else if hi > PI {
            Arc::Wrap(hi - 2.0 * PI, lo)
        } else {
            Arc::Part(lo, hi)
        }
    }

    fn ps(&self, l: &Light, tol: f64) -> Estimate {
        let integ = |tol: f64, f: &dyn Fn(f64) -> f64| if std::env::var("QAG").is_ok() { qag(0.0, 1.0, tol, f) } else { adaptive(0.0, 1.0, Tolerance { abs: tol, rel: 0.0, max_panels: 4000 }, f) };
        let w0 = -l.a;
        let st = self.st;
        let scale = if self.k2 > 0.0 {
            (2.0 * self.alpha * (self.k2 * l.sa * l.sa + self.a2).sqrt() / self.k2).clamp(1e-12, 4.0)
        } else {
            4.0
        };
        // pieces in w: (lo, hi, full?, sing_lo, sing_hi)
        let mut pieces: Vec<(f64, f64, bool, bool)> = Vec::with_capacity(4);
        let mut push = |lo: f64, hi: f64, sl: bool, sh: bool, pieces: &mut Vec<(f64, f64, bool, bool)>| {
            if hi <= lo {
                return;
            }
            if w0 > lo && w0 < hi {
                pieces.push((lo, w0, sl, false));
                pieces.push((w0, hi, false, sh));
            } else {
                pieces.push((lo, hi, sl, sh));
            }
        };
        let partial_sing = st > 0.0;
        push(-1.0, -st, false, false, &mut pieces);
        push(-st, st, partial_sing, partial_sing, &mut pieces);
        let n = pieces.len().max(1) as f64;
        let sub_tol = tol * 4.0 * l.sigma / n;
        let mut value = 0.0;
        let mut error = 0.0;
        let mut evals = 0;
        for &(lo, hi, sl, sh) in &pieces {
            let xa = ((lo - w0) / scale).atan();
            let xb = ((hi - w0) / scale).atan();
            let dx = xb - xa;
            let est = integ(sub_tol, &|t: f64| {
                let (g, gp) = match (sl, sh) {
                    (false, false) => (t, 1.0),
                    (true, false) => (t * t, 2.0 * t),
                    (false, true) => (1.0 - (1.0 - t) * (1.0 - t), 2.0 * (1.0 - t)),
                    (true, true) => (t * t * (3.0 - 2.0 * t), 6.0 * t * (1.0 - t)),
                };
                let xi = xa + dx * g;
                let tn = xi.tan();
                let eps = scale * tn;
                let jac = scale * (1.0 + tn * tn) * dx * gp;
                if jac == 0.0 {
                    return 0.0;
                }
                let arc = self.arc(l, eps);
                self.inner(l, eps, arc) * jac
            });
            if std::env::var("PSDBG").is_ok() { eprintln!("  piece {lo:.4} {hi:.4} {sl} {sh} w0 {w0:.4} L {scale:.3e} evals {} err {:.2e}", est.evals, est.error); }
            value += est.value;
            error += est.error;
            evals += est.evals;
        }
        let norm = 1.0 / (4.0 * l.sigma * PI * self.alpha);
        Estimate { value: value * norm, error: error * norm + 8.0 * f64::EPSILON, evals }
    }
}


// Gauss–Kronrod 10/21 (QUADPACK qk21).
const XGK: [f64; 11] = [
    0.995657163025808080735527280689003,
    0.973906528517171720077964012084452,
    0.930157491355708226001207180059508,
    0.865063366688984510732096688423493,
    0.780817726586416897063717578345042,
    0.679409568299024406234327365114874,
    0.562757134668604683339000099272694,
    0.433395394129247190799265943165784,
    0.294392862701460198131126603103866,
    0.148874338981631210884826001129720,
    0.000000000000000000000000000000000,
];
const WGK: [f64; 11] = [
    0.011694638867371874278064396062192,
    0.032558162307964727478818972459390,
    0.054755896574351996031381300244580,
    0.075039674810919952767043140916190,
    0.093125454583697605535065465083366,
    0.109387158802297641899210590325805,
    0.123491976262065851077208626368508,
    0.134709217311473325928054001771707,
    0.142775938577060080797094273138717,
    0.147739104901338491374841515972068,
    0.149445554002916905664936468389821,
];
const WG: [f64; 5] = [
    0.066671344308688137593568809893332,
    0.149451349150580593145776339657697,
    0.219086362515982043995534934228163,
    0.269266719309996355091226921569469,
    0.295524224714752870173892994651338,
];

fn qk21(a: f64, b: f64, f: &mut impl FnMut(f64) -> f64) -> (f64, f64) {
    let c = 0.5 * (a + b);
    let h = 0.5 * (b - a);
    let mut fv = [0.0f64; 21];
    fv[10] = f(c);
    for j in 0..10 {
        let dx = h * XGK[j];
        fv[j] = f(c - dx);
        fv[20 - j] = f(c + dx);
    }
    let mut resk = fv[10] * WGK[10];
    let mut resg = 0.0;
    for j in 0..10 {
        resk += WGK[j] * (fv[j] + fv[20 - j]);
        if j % 2 == 1 {
            resg += WG[j / 2] * (fv[j] + fv[20 - j]);
        }
    }
    let mean = 0.5 * resk;
    let mut resasc = WGK[10] * (fv[10] - mean).abs();
    for j in 0..10 {
        resasc += WGK[j] * ((fv[j] - mean).abs() + (fv[20 - j] - mean).abs());
    }
    let resasc = resasc * h.abs();
    let mut err = ((resk - resg) * h).abs();
    if resasc != 0.0 && err != 0.0 {
        err = resasc * (200.0 * err / resasc).powf(1.5).min(1.0);
    }
    (resk * h, err)
}

fn qag(a: f64, b: f64, tol: f64, mut f: impl FnMut(f64) -> f64) -> Estimate {
    let mut panels: Vec<(f64, f64, f64, f64)> = Vec::with_capacity(16);
    let (v, e) = qk21(a, b, &mut f);
    panels.push((a, b, v, e));
    let mut evals = 21u64;
    loop {
        let error: f64 = panels.iter().map(|p| p.3).sum();
        if error <= tol || panels.len() >= 4000 {
            panels.sort_by(|p, q| p.0.total_cmp(&q.0));
            let value = panels.iter().map(|p| p.2).sum();
            return Estimate { value, error, evals };
        }
        let (worst, _) = panels.iter().enumerate().max_by(|(_, p), (_, q)| p.3.total_cmp(&q.3).then(q.0.total_cmp(&p.0))).unwrap();
        let (pa, pb, _, pe) = panels.swap_remove(worst);
        let mid = 0.5 * (pa + pb);
        if mid <= pa || mid >= pb { panels.push((pa, pb, panels.len() as f64 * 0.0 + 0.0, 0.0)); let _ = pe; continue; }
        let (v1, e1) = qk21(pa, mid, &mut f);
        let (v2, e2) = qk21(mid, pb, &mut f);
        evals += 42;
        panels.push((pa, mid, v1, e1));
        panels.push((mid, pb, v2, e2));
    }
}

#[derive(Debug, Clone, Copy)]
enum Arc {
    Full,
    Empty,
    Part(f64, f64),
    /// Full circle minus the arc (d1, d2).
    Wrap(f64, f64),
}

pub fn ps(alpha: f64, theta_f: f64, theta_u: f64, phi_u: f64, tol: f64) -> Estimate {
    let layer = Layer::new(alpha, theta_f);
    let l = layer.light(theta_u, phi_u);
    layer.ps(&l, tol)
}

pub fn sggx_phase(alpha: f64, t: [f64; 3], u: [f64; 3], v: [f64; 3]) -> f64 {
    let h = [u[0] + v[0], u[1] + v[1], u[2] + v[2]];
    let hn2 = h[0] * h[0] + h[1] * h[1] + h[2] * h[2];
    let ht2 = if hn2 > 0.0 {
        let ht = h[0] * t[0] + h[1] * t[1] + h[2] * t[2];
        ht * ht / hn2
    } else {
        0.0
    };
    let a2 = alpha * alpha;
    let k2 = (1.0 - alpha) * (1.0 + alpha);
    let x = ht2 * k2 + a2;
    let d = alpha * a2 / (PI * x * x);
    let ut = u[0] * t[0] + u[1] * t[1] + u[2] * t[2];
    let sigma = (1.0 - ut * ut * k2).max(0.0).sqrt();
    d / (4.0 * sigma)
}


pub fn r_nested(alpha: f64, theta_f: f64, tol: f64) -> Estimate {
    let layer = Layer::new(alpha, theta_f);
    let mut max_inner = 0.0f64;
    let mut evals = 0u64;
    let outer = adaptive(0.0, 1.0, Tolerance { abs: tol / 4.0, rel: 0.0, max_panels: 2000 }, |mu| {
        let th = mu.acos();
        let mut max_ps = 0.0f64;
        let mut ev = 0;
        let inner = adaptive(0.0, PI, Tolerance { abs: PI * tol / 8.0, rel: 0.0, max_panels: 2000 }, |phi| {
            let l = layer.light(th, phi);
            let e = layer.ps(&l, tol / 8.0);
            max_ps = max_ps.max(e.error);
            ev += e.evals;
            e.value
        });
        evals += ev;
        max_inner = max_inner.max(inner.error + PI * max_ps);
        2.0 / PI * mu * inner.value
    });
    Estimate { value: outer.value, error: outer.error + max_inner / PI, evals }
}


/// Trapezoid in φ on [0, π] (even periodic integrand), doubling until converged.
fn trap_phi(tol: f64, mut f: impl FnMut(f64) -> f64) -> (f64, f64, u64) {
    let mut n = 8usize;
    let mut sum = 0.5 * (f(0.0) + f(PI));
    for j in 1..n {
        sum += f(PI * j as f64 / n as f64);
    }
    let mut t = sum * PI / n as f64;
    let mut evals = (n + 1) as u64;
    loop {
        for j in 0..n {
            sum += f(PI * (2 * j + 1) as f64 / (2 * n) as f64);
        }
        evals += n as u64;
        n *= 2;
        let t2 = sum * PI / n as f64;
        let err = (t2 - t).abs();
        t = t2;
        if err <= tol || n >= 1 << 14 {
            return (t, err, evals);
        }
    }
}

pub fn r_trap(alpha: f64, theta_f: f64, tol: f64) -> Estimate {
    let layer = Layer::new(alpha, theta_f);
    let mut max_inner = 0.0f64;
    let mut evals = 0u64;
    let mut nps = 0u64;
    let outer = adaptive(0.0, 1.0, Tolerance { abs: tol / 4.0, rel: 0.0, max_panels: 2000 }, |s| {
        let mu = s * s;
        let th = mu.acos();
        let mut max_ps = 0.0f64;
        let mut ev = 0;
        let (v, e, n) = trap_phi(PI * tol / 8.0, |phi| {
            let l = layer.light(th, phi);
            let e = layer.ps(&l, tol / 8.0);
            max_ps = max_ps.max(e.error);
            ev += e.evals;
            e.value
        });
        nps += n;
        evals += ev;
        max_inner = max_inner.max(e + PI * max_ps);
        2.0 / PI * mu * 2.0 * s * v
    });
    eprintln!("outer evals {} ps evals {}", outer.evals, nps);
    Estimate { value: outer.value, error: outer.error + max_inner / PI, evals }
}


pub fn r_at(alpha: f64, theta_f: f64, tol: f64) -> Estimate {
    let layer = Layer::new(alpha, theta_f);
    let (st, ct) = theta_f.sin_cos();
    let mut max_inner = 0.0f64;
    let mut evals = 0u64;
    let mut nps = 0u64;
    let use_qag = std::env::var("QAG").is_ok();
    let integ = |a: f64, b: f64, tol: f64, f: &mut dyn FnMut(f64) -> f64| if use_qag { qag(a, b, tol, f) } else { adaptive(a, b, Tolerance { abs: tol, rel: 0.0, max_panels: 4000 }, f) };
    let split = 0.5 * PI - theta_f;
    let pieces: Vec<(f64, f64, bool, bool)> = if theta_f > 0.0 { vec![(0.0, split, false, false), (split, 0.5 * PI + theta_f, true, true)] } else { vec![(0.0, 0.5 * PI, false, false)] };
    let mut value = 0.0;
    let mut error = 0.0;
    for &(lo, hi, sl, sh) in &pieces {
        let d = hi - lo;
        let outer = integ(0.0, 1.0, tol / 4.0 / pieces.len() as f64, &mut |t| {
            let (g, gp) = endmap(t, sl, sh);
            let aa = lo + d * g;
            let jac = d * gp;
            let (sa, a) = aa.sin_cos();
            let cu = a * ct / (sa * st);
            let emin = if !(cu < 1.0) { 0.0 } else { cu.max(-1.0).acos() };
            let partial = emin > 0.0;
            let de = PI - emin;
            let sigma = (sa * sa + layer.a2 * a * a).sqrt();
            let mut max_ps = 0.0f64;
            let mut ev = 0;
            let inner = integ(0.0, 1.0, PI * tol / 8.0, &mut |s| {
                let (g2, gp2) = endmap(s, partial, false);
                let eta = emin + de * g2;
                let mu = a * ct - sa * st * eta.cos();
                let l = Light { a, sa, eta, sigma };
                let e = layer.ps(&l, tol / 8.0);
                max_ps = max_ps.max(e.error);
                ev += e.evals;
                nps += 1;
                mu.max(0.0) * e.value * de * gp2
            });
            evals += ev;
            max_inner = max_inner.max(inner.error + PI * max_ps);
            if std::env::var("RDBG").is_ok() { eprintln!("A {aa:.5} t {t:.5} J {:.10} inner evals {} err {:.2e}", 2.0 / PI * sa * inner.value, inner.evals, inner.error); }
            2.0 / PI * sa * inner.value * jac
        });
        value += outer.value;
        error += outer.error;
    }
    eprintln!("ps evals {}", nps);
    Estimate { value, error: error + max_inner / PI, evals }
}

fn endmap(t: f64, sl: bool, sh: bool) -> (f64, f64) {
    match (sl, sh) {
        (false, false) => (t, 1.0),
        (true, false) => (t * t, 2.0 * t),
        (false, true) => (1.0 - (1.0 - t) * (1.0 - t), 2.0 * (1.0 - t)),
        (true, true) => (t * t * (3.0 - 2.0 * t), 6.0 * t * (1.0 - t)),
    }
}

pub fn r_gl(alpha: f64, theta_f: f64, na: usize, ne: usize, ps_tol: f64) -> (f64, u64) {
    let layer = Layer::new(alpha, theta_f);
    let (st, ct) = theta_f.sin_cos();
    let ra = crate::integrate::FixedRule::new(na);
    let re = crate::integrate::FixedRule::new(ne);
    let split = 0.5 * PI - theta_f;
    let pieces: Vec<(f64, f64, bool, bool)> = if theta_f > 0.0 { vec![(0.0, split, false, false), (split, 0.5 * PI + theta_f, true, true)] } else { vec![(0.0, 0.5 * PI, false, false)] };
    let mut value = 0.0;
    let mut evals = 0;
    for &(lo, hi, sl, sh) in &pieces {
        let d = hi - lo;
        for (t, wt) in ra.points(0.0, 1.0) {
            let (g, gp) = endmap(t, sl, sh);
            let aa = lo + d * g;
            let jac = d * gp;
            let (sa, a) = aa.sin_cos();
            let cu = a * ct / (sa * st);
            let emin = if !(cu < 1.0) { 0.0 } else { cu.max(-1.0).acos() };
            let de = PI - emin;
            let sigma = (sa * sa + layer.a2 * a * a).sqrt();
            let mut inner = 0.0;
            for (s, ws) in re.points(0.0, 1.0) {
                let eta = emin + de * s;
                let mu = a * ct - sa * st * eta.cos();
                let l = Light { a, sa, eta, sigma };
                let e = layer.ps(&l, ps_tol);
                evals += e.evals;
                inner += ws * mu.max(0.0) * e.value * de;
            }
            value += wt * 2.0 / PI * sa * inner * jac;
        }
    }
    (value, evals)
}
#[cfg(test)]
mod tests {
    use super::*;

    fn sph(theta: f64, phi: f64) -> [f64; 3] {
        [theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()]
    }

    /// Brute force ∫ f(v) dω_v over the part of the sphere where `keep(v)`, polar coordinates
    /// about axis e (nested adaptive G10/K21; the region in β for each ψ is found by scanning).
    fn bf_lower(u: [f64; 3], f: &dyn Fn([f64; 3]) -> f64, lower_only: bool, tol: f64) -> f64 {
        let e = [-u[0], -u[1], -u[2]];
        // orthonormal b1, b2
        let tmp = if e[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
        let cross = |a: [f64; 3], b: [f64; 3]| [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
        let nrm = |a: [f64; 3]| { let n = (a[0]*a[0]+a[1]*a[1]+a[2]*a[2]).sqrt(); [a[0]/n, a[1]/n, a[2]/n] };
        let b1 = nrm(cross(e, tmp));
        let b2 = cross(e, b1);
        let tl = Tolerance { abs: tol, rel: 0.0, max_panels: 20000 };
        adaptive(0.0, 2.0 * PI, tl, |psi| {
            let (sp, cp) = psi.sin_cos();
            let d = [cp * b1[0] + sp * b2[0], cp * b1[1] + sp * b2[1], cp * b1[2] + sp * b2[2]];
            let v = |b: f64| { let (sb, cb) = b.sin_cos(); [cb * e[0] + sb * d[0], cb * e[1] + sb * d[1], cb * e[2] + sb * d[2]] };
            let g = |b: f64| f(v(b)) * b.sin();
            if !lower_only {
                return adaptive(0.0, PI, tl, g).value;
            }
            // v_z = A cos b + B sin b = C cos(b - b*)
            let (aa, bb) = (e[2], d[2]);
            let bs = bb.atan2(aa);
            // v_z < 0 for b - bs in (π/2, 3π/2) mod 2π; intersect with [0, π]
            let mut total = 0.0;
            for k in -2..=2 {
                let lo = (bs + PI / 2.0 + 2.0 * PI * k as f64).max(0.0);
                let hi = (bs + 1.5 * PI + 2.0 * PI * k as f64).min(PI);
                if hi > lo { total += adaptive(lo, hi, tl, g).value; }
            }
            total
        }).value
    }

    #[test]
    fn psdiag() {
        for &(al, tf) in &[(0.15, 1.5707963267948966), (0.15, 0.3)] {
            let layer = Layer::new(al, tf);
            for &(tu, pu) in &[(0.3, 0.2), (0.8, 1.0), (1.2, 2.5), (1.5, 0.1), (1.0, 1.57)] {
                let l = layer.light(tu, pu);
                let e = layer.ps(&l, 1e-9 / 8.0);
                eprintln!("{al} {tf} {tu} {pu}: a {:.4} {:?}", l.a, e);
            }
        }
    }

    #[test]
    fn ediag() {
        let (al, tf) = (0.15f64, 0.3f64);
        let layer = Layer::new(al, tf);
        for &aa in &[1.2625f64, 1.2705] {
            let (sa, a) = aa.sin_cos();
            for i in 0..=30 {
                let eta = PI * (i as f64 / 30.0).powi(2);
                let l = Light { a, sa, eta, sigma: (sa * sa + al * al * a * a).sqrt() };
                let mu = a * tf.cos() - sa * tf.sin() * eta.cos();
                let e = layer.ps(&l, 1e-13);
                println!("A {aa} eta {eta:.5} mu {mu:.6} ps {:.12} f {:.12}", e.value, mu * e.value);
            }
        }
    }

    #[test]
    fn hdiag() {
        for &(al, tf, pu) in &[(0.15f64, 0.3f64, 0.5f64), (0.5, 1.0, 2.0), (0.15, 1.2, 0.3)] {
            let f = |mu: f64| ps(al, tf, mu.acos(), pu, 1e-14).value;
            let p0 = f(0.0);
            for k in 1..9 {
                let mu = 10f64.powi(-k);
                let d = (f(mu) - p0) / mu;
                println!("{al} {tf} mu {mu:e}: P0 {p0:.12} slope {d:.10}  f(-mu) slope {:.10}", (f(-mu)-p0)/mu);
            }
        }
    }

    #[test]
    fn adiag() {
        let (al, tf) = (0.15f64, 0.3f64);
        let layer = Layer::new(al, tf);
        let st = tf.sin();
        // u from (a, eta_u): u = a t + sa (cos eta e1 + sin eta e2)
        let ps_at = |a: f64, eta: f64| {
            let sa = ((1.0 - a) * (1.0 + a)).sqrt();
            let l = Light { a, sa, eta, sigma: (sa * sa + al * al * a * a).sqrt() };
            layer.ps(&l, 1e-12).value
        };
        for i in 0..=40 {
            let a = -st + (1.0 + st) * i as f64 / 40.0;
            let sa = ((1.0 - a) * (1.0 + a)).sqrt();
            let cu = a * tf.cos() / (sa * tf.sin());
            let emin = if cu >= 1.0 { 0.0 } else { cu.max(-1.0).acos() };
            let mut row = String::new();
            for j in 0..=8 {
                let eta = emin + (PI - emin) * j as f64 / 8.0;
                row += &format!(" {:.6}", ps_at(a, eta));
            }
            println!("a {a:.4} emin {emin:.3}:{row}");
        }
    }

    #[test]
    fn rdiag() {
        let layer = Layer::new(0.15, 0.3);
        for &mu in &[1e-6, 1e-3, 0.01, 0.1, 0.3, 0.6, 0.9, 0.999] {
            let th = f64::acos(mu);
            let mut n = 0;
            let inner = adaptive(0.0, PI, Tolerance { abs: PI * 1e-9 / 8.0, rel: 0.0, max_panels: 2000 }, |phi| {
                n += 1;
                let l = layer.light(th, phi);
                layer.ps(&l, 1e-9 / 8.0).value
            });
            println!("mu {mu}: inner {:?} n {n}", inner);
        }
        for i in 0..=20 {
            let mu: f64 = 0.6; let phi = PI * i as f64 / 20.0;
            let l = layer.light(mu.acos(), phi);
            println!("phi {phi:.3} ps {:.12}", layer.ps(&l, 1e-12).value);
        }
    }

    #[test]
    fn rgl() {
        for &(al, tf) in &[(0.5, 0.3), (0.15, 0.3), (0.15, 1.5707963267948966), (0.15, 0.1), (0.05, 0.8), (0.15, 1.0)] {
            let refv = r_gl(al, tf, 96, 96, 1e-13).0;
            let mut s = format!("{al} {tf} ref {refv:.15}:");
            for &n in &[8usize, 12, 16, 20, 24, 32, 48] {
                let (v, _) = r_gl(al, tf, n, n, 1e-13);
                s += &format!(" {n}:{:.1e}", v - refv);
            }
            for &n in &[8usize, 12, 16, 24] {
                let (v, _) = r_gl(al, tf, 48, n, 1e-13);
                s += &format!(" e{n}:{:.1e}", v - refv);
            }
            for &n in &[8usize, 12, 16, 24] {
                let (v, _) = r_gl(al, tf, n, 48, 1e-13);
                s += &format!(" a{n}:{:.1e}", v - refv);
            }
            println!("{s}");
        }
    }

    #[test]
    fn rtime() {
        for &(al, tf) in &[(1.0, 0.3), (0.5, 0.3), (0.15, 0.3), (0.15, 0.0), (0.15, 1.5707963267948966), (0.05, 0.8)] {
            let t0 = std::time::Instant::now();
            let e = r_nested(al, tf, 1e-9);
            let dt = t0.elapsed();
            let e2 = r_nested(al, tf, 1e-11);
            let t0 = std::time::Instant::now();
            let e3 = r_at(al, tf, 1e-9);
            println!("   trap {:?} {:?} diff {:e}", e3, t0.elapsed(), e3.value - e2.value);
            println!("R {al} {tf}: {:?} {:?} tight diff {:e}", e, dt, e.value - e2.value);
        }
    }

    #[test]
    fn quick() {
        for &(al, tf, tu, pu) in &[(1.0, 0.3, 0.4, 0.5), (0.5, 0.3, 0.4, 0.5), (0.15, 0.3, 0.4, 0.5), (0.15, 0.0, 0.4, 0.5), (0.05, 1.2, 1.0, 2.0), (0.3, 1.5707963267948966, 1.3, 0.2), (0.2, 0.7, 2.0, 1.0)] {
            let e = ps(al, tf, tu, pu, 1e-9);
            let e2 = ps(al, tf, tu, pu, 1e-13);
            let t = sph(tf, 0.0);
            let u = sph(tu, pu);
            let f = |v: [f64; 3]| sggx_phase(al, t, u, v);
            let bf = bf_lower(u, &f, true, 1e-11);
            let tot = bf_lower(u, &f, false, 1e-11);
            println!("{al} {tf} {tu} {pu}: {:?}  tight diff {:e} bf diff {:e} total {:e}", e, e.value - e2.value, e2.value - bf, tot - 1.0);
        }
    }
}
