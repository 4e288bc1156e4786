//! Integrators: method × tolerance (or resolution) → wall time, integrand evaluations and max
//! error against a converged reference, for every quantity family.
//!
//! Each quantity gets its own production integrator (the one `shadefit build` samples with) at
//! a ladder of tolerances, next to the straightforward alternatives a user would write: a fixed
//! Gauss–Legendre product rule, plain Monte Carlo, an unsplit adaptive rule. The reference of
//! every row is named in the row: a closed form where one exists (G, Q, the gloss length, each
//! checked elsewhere against independent quadratures), otherwise the production integrator at a
//! tolerance 2–4 orders below the tightest row. Everything runs on one thread, so the times
//! compare methods rather than thread counts.

use super::{Mode, SplitMix, time_it};
use crate::integrate::{Estimate, Tolerance, adaptive, gauss_legendre};
use crate::family::fuzz::integrals as fuzz;
use crate::family::gloss::integrals as gloss;
use crate::family::skin::integrals as skin;
use serde::Serialize;
use std::f64::consts::{FRAC_PI_2, PI};

/// One (method, setting) of one quantity's integrator.
#[derive(Debug, Clone, Serialize)]
pub struct IntegratorRow {
    pub quantity: &'static str,
    pub method: String,
    pub setting: String,
    pub points: usize,
    /// Wall time per point (one thread).
    pub seconds_per_point: f64,
    /// Integrand evaluations per point (mean).
    pub evals_per_point: f64,
    pub max_error: f64,
    /// Largest error estimate the method reported (adaptive methods only).
    pub max_estimate: Option<f64>,
    pub reference: String,
}

/// Outcome of one method at one setting on all points: values, estimates, evaluations.
struct Run {
    values: Vec<f64>,
    estimates: Option<Vec<f64>>,
    evals: u64,
}

impl Run {
    fn from_estimates(e: Vec<Estimate>) -> Run {
        Run {
            values: e.iter().map(|e| e.value).collect(),
            estimates: Some(e.iter().map(|e| e.error).collect()),
            evals: e.iter().map(|e| e.evals).sum(),
        }
    }

    fn fixed(values: Vec<f64>, evals_per_point: u64) -> Run {
        let evals = evals_per_point * values.len() as u64;
        Run {
            values,
            estimates: None,
            evals,
        }
    }
}

/// Time `run` over all points and compare with `reference`.
fn row(
    mode: &Mode,
    quantity: &'static str,
    method: &str,
    setting: String,
    reference: (&str, &[f64]),
    run: impl Fn() -> Run,
) -> IntegratorRow {
    let (seconds, r) = time_it(mode.min_seconds, run);
    let n = r.values.len();
    let max_error = r
        .values
        .iter()
        .zip(reference.1)
        .map(|(v, t)| (v - t).abs())
        .fold(0.0, f64::max);
    IntegratorRow {
        quantity,
        method: method.to_string(),
        setting,
        points: n,
        seconds_per_point: seconds / n as f64,
        evals_per_point: r.evals as f64 / n as f64,
        max_error,
        max_estimate: r.estimates.map(|e| e.iter().copied().fold(0.0, f64::max)),
        reference: reference.0.to_string(),
    }
}

/// The production integrator `eval` at each tolerance of `ladder`, against itself at `ref_tol`:
/// the reference values (for the other methods) and the rows.
fn self_ladder(
    mode: &Mode,
    quantity: &'static str,
    method: &str,
    ref_tol: f64,
    ladder: Vec<f64>,
    eval: impl Fn(f64) -> Vec<Estimate>,
) -> (Vec<f64>, Vec<IntegratorRow>) {
    let truth: Vec<f64> = eval(ref_tol).iter().map(|e| e.value).collect();
    let label = format!("adaptive at tol {ref_tol:.0e}");
    let rows = ladder
        .into_iter()
        .map(|tol| row(mode, quantity, method, format!("tol {tol:.0e}"), (&label, &truth), || Run::from_estimates(eval(tol))))
        .collect();
    (truth, rows)
}

/// Every integrator's table.
pub fn all(mode: &Mode) -> Vec<IntegratorRow> {
    let mut rows = Vec::new();
    rows.extend(fuzz_ps(mode));
    rows.extend(fuzz_r(mode));
    rows.extend(fuzz_g(mode));
    rows.extend(fuzz_q(mode));
    rows.extend(gloss_length(mode));
    rows.extend(skin_punctual(mode));
    rows.extend(skin_sh(mode));
    rows
}

/// The quick or the full list of settings.
fn pick<T: Copy>(mode: &Mode, quick: &[T], full: &[T]) -> Vec<T> {
    if mode.quick { quick.to_vec() } else { full.to_vec() }
}

// ---------------------------------------------------------------------------------------------
// Fuzz: P_s

fn ps_points(mode: &Mode) -> Vec<[f64; 4]> {
    let (alphas, thetas, tus, pus): (&[f64], &[f64], &[f64], &[f64]) = if mode.quick {
        (
            &[0.15, 0.5, 0.9],
            &[0.0, 0.7, 1.5],
            &[0.4, 1.2, FRAC_PI_2 - 1e-3],
            &[0.3, 2.5],
        )
    } else {
        (
            &[0.05, 0.15, 0.3, 0.5, 0.7, 0.9],
            &[0.0, 0.1, 0.5, 1.0, FRAC_PI_2],
            &[0.1, 0.6, 1.1, 1.5, FRAC_PI_2 - 1e-4],
            &[0.0, 1.0, 2.0, PI],
        )
    };
    let mut out = Vec::new();
    for &a in alphas {
        for &t in thetas {
            for &tu in tus {
                for &pu in pus {
                    out.push([a, t, tu, pu]);
                }
            }
        }
    }
    out
}

fn unit(theta: f64, phi: f64) -> [f64; 3] {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    [st * cp, st * sp, ct]
}

/// P_s by an n_μ × 2n_μ Gauss–Legendre product rule over the lower hemisphere in (μ = cos θ, φ).
fn ps_gauss_legendre(
    p: &[f64; 4],
    rule: &(Vec<f64>, Vec<f64>),
    rule_phi: &(Vec<f64>, Vec<f64>),
) -> f64 {
    let t = unit(p[1], 0.0);
    let u = unit(p[2], p[3]);
    let mut sum = 0.0;
    for (xm, wm) in rule.0.iter().zip(&rule.1) {
        let mu = -0.5 * (1.0 + xm); // μ ∈ (−1, 0)
        let s = (1.0 - mu * mu).sqrt();
        for (xp, wp) in rule_phi.0.iter().zip(&rule_phi.1) {
            let phi = PI * (1.0 + xp);
            let v = [s * phi.cos(), s * phi.sin(), mu];
            sum += wm * wp * fuzz::sggx_phase(p[0], t, u, v);
        }
    }
    // Jacobians: dμ = ½ dx, dφ = π dx.
    sum * 0.5 * PI
}

/// P_s by Monte Carlo with N directions uniform on the lower hemisphere (fixed seed per point).
fn ps_monte_carlo(p: &[f64; 4], n: usize, seed: u64) -> f64 {
    let t = unit(p[1], 0.0);
    let u = unit(p[2], p[3]);
    let mut rng = SplitMix(seed);
    let mut sum = 0.0;
    for _ in 0..n {
        let mu = -rng.next_f64();
        let phi = 2.0 * PI * rng.next_f64();
        let s = (1.0 - mu * mu).sqrt();
        sum += fuzz::sggx_phase(p[0], t, u, [s * phi.cos(), s * phi.sin(), mu]);
    }
    2.0 * PI * sum / n as f64
}

fn fuzz_ps(mode: &Mode) -> Vec<IntegratorRow> {
    const REF_TOL: f64 = 1e-13;
    let pts = ps_points(mode);
    let eval = |tol: f64| -> Vec<Estimate> {
        pts.iter()
            .map(|p| fuzz::ps(p[0], p[1], p[2], p[3], tol))
            .collect()
    };
    let (truth, mut rows) = self_ladder(
        mode,
        "fuzz P_s",
        "adaptive G10/K21 on the reduced 1-D integral (shadefit)",
        REF_TOL,
        pick(mode, &[1e-4, 1e-7, 1e-9], &[1e-3, 1e-5, 1e-7, 1e-9, 1e-11]),
        eval,
    );
    let reference = ("adaptive at tol 1e-13", truth.as_slice());
    for n in pick(mode, &[16, 64, 256], &[16, 64, 256, 1024]) {
        let rule = gauss_legendre(n);
        let rule_phi = gauss_legendre(2 * n);
        rows.push(row(
            mode,
            "fuzz P_s",
            "Gauss–Legendre product over the hemisphere (μ, φ)",
            format!("{n}×{}", 2 * n),
            reference,
            || {
                Run::fixed(
                    pts.iter()
                        .map(|p| ps_gauss_legendre(p, &rule, &rule_phi))
                        .collect(),
                    (2 * n * n) as u64,
                )
            },
        ));
    }
    for n in pick(mode, &[1_000, 10_000], &[1_000, 10_000, 100_000, 1_000_000]) {
        rows.push(row(
            mode,
            "fuzz P_s",
            "Monte Carlo, uniform on the hemisphere",
            format!("N = {n}"),
            reference,
            || {
                Run::fixed(
                    pts.iter()
                        .enumerate()
                        .map(|(i, p)| ps_monte_carlo(p, n, i as u64 + 1))
                        .collect(),
                    n as u64,
                )
            },
        ));
    }
    rows
}

// ---------------------------------------------------------------------------------------------
// Fuzz: R

fn fuzz_r(mode: &Mode) -> Vec<IntegratorRow> {
    const REF_TOL: f64 = 1e-12;
    let pts: Vec<[f64; 2]> = if mode.quick {
        vec![[0.15, 0.3], [0.6, 1.2]]
    } else {
        vec![
            [0.15, 0.0],
            [0.15, 0.8],
            [0.3, FRAC_PI_2],
            [0.6, 0.4],
            [0.9, 1.2],
        ]
    };
    let eval =
        |tol: f64| -> Vec<Estimate> { pts.iter().map(|p| fuzz::r(p[0], p[1], tol)).collect() };
    let (truth, mut rows) = self_ladder(
        mode,
        "fuzz R",
        "nested adaptive: A by GL32/GL24, η by G7/K15, w by G10/K21 (shadefit)",
        REF_TOL,
        pick(mode, &[1e-5, 1e-7, 1e-9], &[1e-4, 1e-5, 1e-7, 1e-9, 1e-10]),
        eval,
    );
    let reference = ("adaptive at tol 1e-12", truth.as_slice());
    // The straightforward nesting: a product rule over the light directions of adaptive P_s.
    for n in pick(mode, &[4, 8, 16], &[4, 8, 16, 32]) {
        let (x, w) = gauss_legendre(n);
        let (xp, wp) = gauss_legendre(2 * n);
        rows.push(row(
            mode,
            "fuzz R",
            "Gauss–Legendre product over u (μ, φ) of adaptive P_s (tol 1e-9)",
            format!("{n}×{}", 2 * n),
            reference,
            || {
                let mut evals = 0;
                let values = pts
                    .iter()
                    .map(|p| {
                        let mut sum = 0.0;
                        for (xm, wm) in x.iter().zip(&w) {
                            let mu = 0.5 * (1.0 + xm);
                            let dirs: Vec<(f64, f64)> =
                                xp.iter().map(|xf| (mu.acos(), PI * (1.0 + xf))).collect();
                            let ps = fuzz::ps_directions(p[0], p[1], &dirs, 1e-9);
                            for (e, wf) in ps.iter().zip(&wp) {
                                evals += e.evals;
                                sum += wm * wf * e.value * mu;
                            }
                        }
                        // (1/π) ∫ P_s μ dω: dμ = ½ dx, dφ = π dx.
                        sum * 0.5
                    })
                    .collect();
                Run {
                    values,
                    estimates: None,
                    evals,
                }
            },
        ));
    }
    rows
}

// ---------------------------------------------------------------------------------------------
// Fuzz: G and Q

fn fuzz_g(mode: &Mode) -> Vec<IntegratorRow> {
    let mut pts = Vec::new();
    for mu in [0.001, 0.01, 0.1, 0.5, 1.0] {
        for d in [1e-4, 0.01, 0.1, 0.5, 5.0] {
            pts.push([mu, d]);
        }
    }
    let exact: Vec<f64> = pts.iter().map(|p| fuzz::g_exact(p[1], p[0])).collect();
    let quad_ref: Vec<f64> = pts
        .iter()
        .map(|p| fuzz::g(p[1], p[0], 1e-14).value)
        .collect();
    let mut rows = Vec::new();
    let closed = ("closed form in E₁, E₂", exact.as_slice());
    for tol in pick(mode, &[1e-6, 1e-9, 1e-12], &[1e-4, 1e-6, 1e-9, 1e-12]) {
        rows.push(row(
            mode,
            "fuzz G",
            "adaptive G10/K21, split at μ = d, μv, log-graded (shadefit)",
            format!("tol {tol:.0e}"),
            closed,
            || Run::from_estimates(pts.iter().map(|p| fuzz::g(p[1], p[0], tol)).collect()),
        ));
        rows.push(row(
            mode,
            "fuzz G",
            "adaptive G10/K21 on [0, 1], unsplit",
            format!("tol {tol:.0e}"),
            closed,
            || {
                Run::from_estimates(
                    pts.iter()
                        .map(|p| {
                            let (mu_v, d) = (p[0], p[1]);
                            adaptive(
                                0.0,
                                1.0,
                                Tolerance {
                                    abs: tol,
                                    rel: 0.0,
                                    max_panels: 2000,
                                },
                                |mu| {
                                    if mu <= 0.0 {
                                        0.0
                                    } else {
                                        -(-d * (1.0 / mu_v + 1.0 / mu)).exp_m1() * mu / (mu + mu_v)
                                    }
                                },
                            )
                        })
                        .collect(),
                )
            },
        ));
    }
    rows.push(row(
        mode,
        "fuzz G",
        "closed form in E₁, E₂",
        "-".into(),
        ("adaptive (shadefit) at tol 1e-14", &quad_ref),
        || Run::fixed(pts.iter().map(|p| fuzz::g_exact(p[1], p[0])).collect(), 0),
    ));
    rows
}

fn fuzz_q(mode: &Mode) -> Vec<IntegratorRow> {
    let pts = [0.0, 1e-6, 1e-3, 0.01, 0.1, 0.25, 0.5, 2.0, 10.0];
    let exact: Vec<f64> = pts.iter().map(|&d| fuzz::q_exact(d)).collect();
    let quad_ref: Vec<f64> = pts.iter().map(|&d| fuzz::q(d, 1e-14).value).collect();
    let mut rows = Vec::new();
    let closed = ("closed form 2E₃(d)", exact.as_slice());
    for tol in pick(mode, &[1e-6, 1e-9, 1e-12], &[1e-4, 1e-6, 1e-9, 1e-12]) {
        rows.push(row(
            mode,
            "fuzz Q",
            "adaptive G10/K21, split at μ = d, log-graded (shadefit)",
            format!("tol {tol:.0e}"),
            closed,
            || Run::from_estimates(pts.iter().map(|&d| fuzz::q(d, tol)).collect()),
        ));
    }
    rows.push(row(
        mode,
        "fuzz Q",
        "closed form 2E₃(d)",
        "-".into(),
        ("adaptive (shadefit) at tol 1e-14", &quad_ref),
        || Run::fixed(pts.iter().map(|&d| fuzz::q_exact(d)).collect(), 0),
    ));
    rows
}

// ---------------------------------------------------------------------------------------------
// Gloss

fn gloss_length(mode: &Mode) -> Vec<IntegratorRow> {
    let gs: Vec<f64> = (0..=32).map(|i| i as f64 / 32.0).collect();
    let closed: Vec<f64> = gs.iter().map(|&g| gloss::length_from_gloss(g)).collect();
    let quad_ref: Vec<f64> = gs
        .iter()
        .map(|&g| gloss::normal_length_quadrature(gloss::alpha_from_gloss(g), 1e-15).value)
        .collect();
    let mut rows = Vec::new();
    rows.push(row(
        mode,
        "gloss length",
        "closed form: series / logarithm (shadefit)",
        "-".into(),
        ("adaptive at tol 1e-15", &quad_ref),
        || Run::fixed(gs.iter().map(|&g| gloss::length_from_gloss(g)).collect(), 0),
    ));
    let reference = ("closed form", closed.as_slice());
    for tol in pick(mode, &[1e-6, 1e-9, 1e-12], &[1e-4, 1e-6, 1e-9, 1e-12]) {
        rows.push(row(
            mode,
            "gloss length",
            "adaptive G10/K21 on t ∈ [0, 1]",
            format!("tol {tol:.0e}"),
            reference,
            || {
                Run::from_estimates(
                    gs.iter()
                        .map(|&g| gloss::normal_length_quadrature(gloss::alpha_from_gloss(g), tol))
                        .collect(),
                )
            },
        ));
    }
    for n in pick(mode, &[16, 256], &[16, 64, 256, 1024]) {
        let rule = gauss_legendre(n);
        rows.push(row(
            mode,
            "gloss length",
            "Gauss–Legendre on t ∈ [0, 1]",
            format!("n = {n}"),
            reference,
            || {
                Run::fixed(
                    gs.iter()
                        .map(|&g| {
                            let a2 = gloss::alpha_from_gloss(g).powi(2);
                            rule.0
                                .iter()
                                .zip(&rule.1)
                                .map(|(x, w)| {
                                    let t = 0.5 * (1.0 + x);
                                    let den = (1.0 - t) * (1.0 + t) + a2 * t * t;
                                    w * 0.5 * 2.0 * a2 * t * t / (den * den)
                                })
                                .sum()
                        })
                        .collect(),
                    n as u64,
                )
            },
        ));
    }
    rows
}

// ---------------------------------------------------------------------------------------------
// Skin

fn skin_punctual(mode: &Mode) -> Vec<IntegratorRow> {
    let profile = skin::default_skin_profile();
    let mut pts = Vec::new();
    for kappa in [0.05, 0.25, 0.5, 1.0] {
        for nl in [-0.5, -0.1, 0.0, 0.3, 0.9] {
            pts.push([kappa, nl]);
        }
    }
    let eval = |tol: f64| -> Vec<[Estimate; 3]> {
        pts.iter()
            .map(|p| {
                skin::punctual(
                    &profile,
                    skin::Kernel::Linear,
                    p[0],
                    p[1],
                    Tolerance {
                        abs: tol,
                        rel: 0.0,
                        max_panels: 2000,
                    },
                )
                .expect("the preset profile is valid")
            })
            .collect()
    };
    // One value per point and channel, point-major.
    let flat = |e: Vec<[Estimate; 3]>| -> Vec<Estimate> { e.into_iter().flatten().collect() };
    let (truth, mut rows) = self_ladder(
        mode,
        "skin punctual (RGB)",
        "adaptive G10/K21 split at the kinks (shadefit)",
        1e-14,
        pick(mode, &[1e-6, 1e-8, 1e-10], &[1e-4, 1e-6, 1e-8, 1e-10, 1e-12]),
        |tol| flat(eval(tol)),
    );
    let reference = ("adaptive at tol 1e-14", truth.as_slice());
    // The straightforward ring integral: Gauss–Legendre over x ∈ [−π, π], unsplit.
    for n in pick(mode, &[64, 1024], &[64, 256, 1024, 4096]) {
        let (x, w) = gauss_legendre(n);
        rows.push(row(
            mode,
            "skin punctual (RGB)",
            "Gauss–Legendre over the ring angle x ∈ [−π, π]",
            format!("n = {n}"),
            reference,
            || {
                let values = pts
                    .iter()
                    .flat_map(|p| {
                        let (kappa, nl) = (p[0], p[1]);
                        let theta = nl.acos();
                        let r = 1.0 / kappa;
                        let (mut num, mut den) = ([0.0; 3], [0.0; 3]);
                        for (xi, wi) in x.iter().zip(&w) {
                            let xa = PI * xi;
                            let k = profile.linear(2.0 * r * (0.5 * xa.abs()).sin());
                            let c = (theta + xa).cos().max(0.0);
                            for ch in 0..3 {
                                num[ch] += wi * c * k[ch];
                                den[ch] += wi * k[ch];
                            }
                        }
                        (0..3).map(move |ch| num[ch] / den[ch])
                    })
                    .collect();
                Run::fixed(values, 3 * n as u64)
            },
        ));
    }
    rows
}

fn skin_sh(mode: &Mode) -> Vec<IntegratorRow> {
    let profile = skin::default_skin_profile();
    let mut pts = Vec::new();
    for kappa in [0.05, 0.25, 0.5, 1.0] {
        for band in [1u32, 2] {
            pts.push((kappa, band));
        }
    }
    let eval = |tol: f64| -> Vec<Estimate> {
        pts.iter()
            .flat_map(|&(kappa, band)| {
                skin::sh_band(
                    &profile,
                    kappa,
                    band,
                    Tolerance {
                        abs: tol,
                        rel: 0.0,
                        max_panels: 2000,
                    },
                )
                .expect("the preset profile is valid")
            })
            .collect()
    };
    self_ladder(
        mode,
        "skin SH bands (RGB)",
        "adaptive G10/K21 over the chord (shadefit)",
        1e-14,
        pick(mode, &[1e-6, 1e-8, 1e-10], &[1e-4, 1e-6, 1e-8, 1e-10, 1e-12]),
        eval,
    )
    .1
}
