//! The white-furnace validator: each scheme's directional albedo over (roughness, n·v) with
//! F = 1 and with Schlick F0 = 0.04 and 0.5, its reciprocity, and the same schemes read
//! through the committed 32×32 E and 32-entry E_avg tables (the emitted f32 bilinear lookup).
//!
//! Everything is computed on a small grid (11 roughnesses × 17 n·v) at moderate tolerances
//! (A, B at 1e-9, E_avg at 1e-8): the items are about effects of 1e-3 and larger, and
//! `validate` runs in the tests. Points are evaluated in parallel and collected in grid order.

use super::{exact_inputs, furnace, view_factor, asymmetry, Inputs, Scheme};
use crate::emit::rust::table_eval_f32;
use crate::family::ggx::integrals;
use crate::integrate::gauss_legendre;
use crate::validate::Item;
use rayon::prelude::*;
use serde_json::Value;
use std::path::Path;

/// Perceptual roughness of the grid (α = r²): from a near-mirror to fully rough.
pub const ROUGHNESS: [f64; 11] = [0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0];
/// n·v samples per roughness (uniform on [0, 1]).
pub const MU_COUNT: usize = 17;
/// Tolerance of A and B (each); the furnace formulas move by a few times it.
pub const TOL_ENV: f64 = 1e-9;
/// Tolerance of E_avg (a nested integral; 1e-8 keeps it ~0.1 s per roughness).
pub const TOL_AVG: f64 = 1e-8;
/// The Schlick F0 values besides F = 1.
pub const F0S: [f64; 2] = [0.04, 0.5];
/// The tables measured (committed outputs of fits/).
pub const E_TABLE: &str = "ggx_albedo_table";
pub const E_AVG_TABLE: &str = "ggx_albedo_avg_table";

/// The exact inputs on a (roughness × n·v) grid, n·v fastest.
#[derive(Debug, Clone)]
pub struct Grid {
    pub roughness: Vec<f64>,
    pub mu: Vec<f64>,
    pub inputs: Vec<Inputs>,
}

impl Grid {
    /// The integrals on `roughness` × `mu` (in parallel, collected in order).
    pub fn exact(roughness: &[f64], mu: &[f64]) -> Grid {
        let e_avg: Vec<f64> =
            roughness.par_iter().map(|&r| integrals::albedo_avg(r * r, TOL_AVG).value).collect();
        let points: Vec<(usize, f64)> =
            (0..roughness.len()).flat_map(|j| mu.iter().map(move |&m| (j, m))).collect();
        let inputs = points
            .par_iter()
            .map(|&(j, m)| exact_inputs(roughness[j] * roughness[j], m, e_avg[j], TOL_ENV))
            .collect();
        Grid { roughness: roughness.to_vec(), mu: mu.to_vec(), inputs }
    }

    pub fn at(&self, j: usize, i: usize) -> &Inputs {
        &self.inputs[j * self.mu.len() + i]
    }

    /// The furnace albedo of `scheme` at Schlick `f0` on the grid (n·v fastest), with the exact
    /// Kulla–Conty integral 2∫(1 − E)μ dμ = 1 − E_avg.
    pub fn furnace(&self, scheme: Scheme, f0: f64) -> Vec<f64> {
        self.inputs.iter().map(|x| furnace(scheme, f0, x, 1.0 - x.e_avg)).collect()
    }

    /// The largest relative asymmetry |f(o,i) − f(i,o)|/max over every pair of grid n·v at each
    /// roughness, with its (roughness, μo, μi): the first such pair in grid order (a pair and its
    /// swap tie, so μo is the earlier sample); None for reciprocal schemes.
    pub fn asymmetry(&self, scheme: Scheme, f0: f64) -> Option<(f64, [f64; 3])> {
        let mut worst: Option<(f64, [f64; 3])> = None;
        for (j, &r) in self.roughness.iter().enumerate() {
            let c: Vec<f64> = (0..self.mu.len()).map(|i| view_factor(scheme, f0, self.at(j, i))).collect::<Option<_>>()?;
            for (o, &co) in c.iter().enumerate() {
                for (i, &ci) in c.iter().enumerate() {
                    let a = asymmetry(co, ci);
                    if worst.is_none_or(|w| a > w.0) {
                        worst = Some((a, [r, self.mu[o], self.mu[i]]));
                    }
                }
            }
        }
        worst
    }
}

/// The n·v samples of the validator.
pub fn mu_grid() -> Vec<f64> {
    (0..MU_COUNT).map(|i| i as f64 / (MU_COUNT - 1) as f64).collect()
}

/// A committed table (`generated/json/NAME.json`) evaluated the way the emitted f32 code is.
#[derive(Debug, Clone)]
pub struct Table {
    pub values: Vec<f32>,
    pub counts: Vec<usize>,
    pub domain: Vec<(f32, f32)>,
}

impl Table {
    /// Reads a committed table; None when it is missing or malformed.
    pub fn load(generated: &Path, name: &str) -> Option<Table> {
        let text = std::fs::read_to_string(generated.join("json").join(format!("{name}.json"))).ok()?;
        let v: Value = serde_json::from_str(&text).ok()?;
        let values: Vec<f32> = v["values"].as_array()?.iter().map(|x| x.as_f64().map(|x| x as f32)).collect::<Option<_>>()?;
        let mut counts = Vec::new();
        let mut domain = Vec::new();
        for a in v["axes"].as_array()? {
            counts.push(a["count"].as_u64()? as usize);
            let r = a["range"].as_array()?;
            domain.push((r.first()?.as_f64()? as f32, r.get(1)?.as_f64()? as f32));
        }
        (counts.iter().product::<usize>() == values.len() && (1..=2).contains(&counts.len())).then_some(Table { values, counts, domain })
    }

    pub fn eval(&self, x: &[f64]) -> f64 {
        let xs: Vec<f32> = x.iter().map(|&v| v as f32).collect();
        table_eval_f32(&self.values, &self.counts, &self.domain, &xs) as f64
    }
}

/// E(μ) and E_avg read from the committed tables (axes α and n·v) at one α, with the Kulla–Conty
/// integral 2∫(1 − E_t(μ))μ dμ of the table's interpolant (2-point Gauss–Legendre per table
/// cell along n·v: exact for the piecewise-linear interpolant times μ, up to f32 rounding).
#[derive(Debug, Clone)]
pub struct Tabulated {
    pub e: Vec<f64>,
    pub e_avg: f64,
    pub ms_integral: f64,
}

pub fn tabulated(e: &Table, avg: &Table, alpha: f64, mu: &[f64]) -> Tabulated {
    let n = e.counts[1];
    let (lo, hi) = (e.domain[1].0 as f64, e.domain[1].1 as f64);
    let (gx, gw) = gauss_legendre(2);
    let mut ms = 0.0;
    for k in 0..n - 1 {
        let (a, b) = (lo + (hi - lo) * k as f64 / (n - 1) as f64, lo + (hi - lo) * (k + 1) as f64 / (n - 1) as f64);
        for (x, w) in gx.iter().zip(&gw) {
            let m = 0.5 * (a + b) + 0.5 * (b - a) * x;
            ms += 0.5 * (b - a) * w * 2.0 * (1.0 - e.eval(&[alpha, m])) * m;
        }
    }
    Tabulated { e: mu.iter().map(|&m| e.eval(&[alpha, m])).collect(), e_avg: avg.eval(&[alpha]), ms_integral: ms }
}

/// The furnace albedo of a scheme whose compensation reads E and E_avg from tables while the
/// single-scattering lobe is exact (a renderer's analytic f_ss): Kulla–Conty, Turquin, Cycles.
/// None for the others (Fdez-Agüera reads its single scattering from the same table, so the
/// table cancels at F = 1; bevy's reads A of a DFG table, measured elsewhere).
pub fn furnace_tabulated(scheme: Scheme, f0: f64, exact: &Inputs, e_t: f64, e_avg_t: f64, ms_t: f64) -> Option<f64> {
    let t = Inputs { a: e_t, b: 0.0, e_avg: e_avg_t };
    let e_f = f0 * exact.a + exact.b;
    match scheme {
        Scheme::KullaConty => {
            let f_avg = integrals::f_avg_schlick(f0);
            Some(e_f + super::kc_f_ms(f_avg, e_avg_t) * (1.0 - e_t) * ms_t / (1.0 - e_avg_t))
        }
        Scheme::Turquin | Scheme::Cycles => Some(e_f * super::scale_factor(scheme, f0, &t)),
        _ => None,
    }
}

/// Kulla–Conty at F = 1 with 2∫(1 − E)μ dμ from an independent rule (48-point Gauss–Legendre
/// in μ = t², E at [`TOL_ENV`]) instead of the identity 1 − E_avg: max |albedo − 1| over the
/// grid, with its point. It measures how well E_avg's nested integrator and this rule agree,
/// amplified by (1 − E(μo))/(1 − E_avg).
pub fn kc_quadrature_check(grid: &Grid) -> (f64, Vec<f64>) {
    let (x, w) = gauss_legendre(48);
    let ms: Vec<f64> = grid
        .roughness
        .par_iter()
        .map(|&r| {
            x.iter()
                .zip(&w)
                .map(|(&xi, &wi)| {
                    let t = 0.5 * (xi + 1.0);
                    let mu = t * t;
                    let e = integrals::albedo(r * r, mu, TOL_ENV).value;
                    0.5 * wi * 2.0 * (1.0 - e) * mu * 2.0 * t
                })
                .sum()
        })
        .collect();
    let mut worst = (0.0f64, vec![]);
    for (j, &r) in grid.roughness.iter().enumerate() {
        for (i, &m) in grid.mu.iter().enumerate() {
            let d = (furnace(Scheme::KullaConty, 1.0, grid.at(j, i), ms[j]) - 1.0).abs();
            if d > worst.0 {
                worst = (d, vec![r, m]);
            }
        }
    }
    worst
}

/// Signed extremes of `v − 1` with their points: (max gain, its point, max loss, its point).
fn gain_loss(points: &[Vec<f64>], v: &[f64]) -> (f64, Vec<f64>, f64, Vec<f64>) {
    let mut g = (0.0f64, vec![]);
    let mut l = (0.0f64, vec![]);
    for (p, &x) in points.iter().zip(v) {
        if x - 1.0 > g.0 {
            g = (x - 1.0, p.clone());
        }
        if 1.0 - x > l.0 {
            l = (1.0 - x, p.clone());
        }
    }
    (g.0, g.1, l.0, l.1)
}

fn fmt_point(p: &[f64]) -> String {
    if p.is_empty() {
        return "nowhere".into();
    }
    format!("(r = {:.2}, n·v = {:.4})", p[0], p[1])
}

/// One row of the furnace table (what the summary prints and the tests read).
#[derive(Debug, Clone)]
pub struct Row {
    pub scheme: Scheme,
    /// max |albedo − 1| at F = 1 (exact E, E_avg).
    pub f1_max_dev: f64,
    pub f1_gain: f64,
    pub f1_loss: f64,
    /// (min, max) albedo at each F0 of [`F0S`].
    pub f0_range: Vec<(f64, f64)>,
    /// max |albedo − Kulla–Conty's| at each F0 of [`F0S`].
    pub f0_vs_kc: Vec<f64>,
    /// Largest relative asymmetry at F0 = 1 (None: reciprocal).
    pub asymmetry: Option<(f64, [f64; 3])>,
    /// max |albedo − 1| at F = 1 with E, E_avg from the committed tables (None: not applicable
    /// or tables missing).
    pub tables_f1_max_dev: Option<f64>,
}

/// The furnace table on the validator's grid (and the committed tables when present).
pub fn rows(generated: &Path) -> (Vec<Row>, Grid, Vec<Vec<f64>>) {
    let mu = mu_grid();
    let grid = Grid::exact(&ROUGHNESS, &mu);
    let points: Vec<Vec<f64>> = ROUGHNESS.iter().flat_map(|&r| mu.iter().map(move |&m| vec![r, m])).collect();
    let tables = Table::load(generated, E_TABLE).zip(Table::load(generated, E_AVG_TABLE));
    let tab: Option<Vec<Tabulated>> = tables.as_ref().map(|(e, a)| ROUGHNESS.iter().map(|&r| tabulated(e, a, r * r, &mu)).collect());
    let kc: Vec<Vec<f64>> = F0S.iter().map(|&f0| grid.furnace(Scheme::KullaConty, f0)).collect();
    let rows = Scheme::ALL
        .iter()
        .map(|&s| {
            let f1 = grid.furnace(s, 1.0);
            let (g, _, l, _) = gain_loss(&points, &f1);
            let f0_vals: Vec<Vec<f64>> = F0S.iter().map(|&f0| grid.furnace(s, f0)).collect();
            let tables_f1_max_dev = tab.as_ref().and_then(|t| {
                let mut worst: Option<f64> = None;
                for (j, tj) in t.iter().enumerate() {
                    for (i, &e_t) in tj.e.iter().enumerate() {
                        let v = furnace_tabulated(s, 1.0, grid.at(j, i), e_t, tj.e_avg, tj.ms_integral)?;
                        worst = Some(worst.unwrap_or(0.0).max((v - 1.0).abs()));
                    }
                }
                worst
            });
            Row {
                scheme: s,
                f1_max_dev: g.max(l),
                f1_gain: g,
                f1_loss: l,
                f0_range: f0_vals.iter().map(|v| crate::plot::min_max(v.iter().copied())).collect(),
                f0_vs_kc: f0_vals
                    .iter()
                    .zip(&kc)
                    .map(|(v, k)| v.iter().zip(k).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max))
                    .collect(),
                asymmetry: grid.asymmetry(s, 1.0),
                tables_f1_max_dev,
            }
        })
        .collect();
    (rows, grid, points)
}

fn domain() -> String {
    format!("roughness {:?} (α = r²) × n·v ∈ [0, 1] ({MU_COUNT}); F = 1 and Schlick F0 ∈ {:?}", ROUGHNESS, F0S)
}

/// The furnace validator's items: a summary table, then one item per scheme (deviation from 1
/// at F = 1, measured on the grid).
pub fn items(generated: &Path) -> Vec<Item> {
    let (rows, grid, points) = rows(generated);
    let mut summary = Item {
        name: "ggx_furnace (white furnace of the energy-compensation schemes)".into(),
        source: "Kulla-Conty 2017, Turquin 2019, Fdez-Aguera 2019, Cycles, Filament, bevy (see each item)".into(),
        domain: domain(),
        points: points.len(),
        max_abs_error: 0.0,
        rms_error: 0.0,
        worst_point: vec![],
        extra: vec![],
        findings: vec![format!(
            "scheme | F=1 max|A-1| | F=1 gain | F0=0.04 [min, max] | F0=0.5 [min, max] | F0=0.5 max|A-A_KC| | asym (F0=1) | tables F=1 max|A-1|"
        )],
    };
    for r in &rows {
        let asym = r.asymmetry.map_or("reciprocal".to_string(), |a| format!("{:.3}", a.0));
        let tables = r.tables_f1_max_dev.map_or("-".to_string(), |t| format!("{t:.2e}"));
        summary.findings.push(format!(
            "{} | {:.2e} | {:.2e} | [{:.4}, {:.4}] | [{:.4}, {:.4}] | {:.2e} | {asym} | {tables}",
            r.scheme.id(),
            r.f1_max_dev,
            r.f1_gain,
            r.f0_range[0].0,
            r.f0_range[0].1,
            r.f0_range[1].0,
            r.f0_range[1].1,
            r.f0_vs_kc[1],
        ));
    }
    summary.findings.push(
        "Exact E and E_avg: Kulla-Conty, Turquin, Fdez-Aguera and Cycles conserve energy exactly at F = 1 (albedo 1 to the \
         integrators' tolerance); single scattering loses 1 - E; bevy's 1/A gains B/A. Only Kulla-Conty (and the baseline) \
         is reciprocal: the others scale by a function of the view alone."
            .into(),
    );
    let mut out = vec![summary];
    for r in &rows {
        let f1 = grid.furnace(r.scheme, 1.0);
        let truth = vec![1.0; f1.len()];
        let mut it = Item::measured(
            &format!("ggx_furnace_{}", r.scheme.id()),
            r.scheme.source(),
            &format!("{}; error = albedo − 1 at F = 1", domain()),
            &points,
            &truth,
            &f1,
        );
        let (g, gp, l, lp) = gain_loss(&points, &f1);
        it.extra.push(("f1_max_gain".into(), g));
        it.extra.push(("f1_max_loss".into(), l));
        for (k, &f0) in F0S.iter().enumerate() {
            it.extra.push((format!("f0_{f0}_min_albedo"), r.f0_range[k].0));
            it.extra.push((format!("f0_{f0}_max_albedo"), r.f0_range[k].1));
            it.extra.push((format!("f0_{f0}_max_abs_vs_kulla_conty"), r.f0_vs_kc[k]));
        }
        if let Some((a, p)) = r.asymmetry {
            it.extra.push(("max_rel_asymmetry_f0_1".into(), a));
            let what = if r.scheme == Scheme::FdezAguera {
                "Not reciprocal (read as a BRDF, its extra lobe Fms Ems(n·v)/π depends on the view alone): the lobe's \
                 |g(o,i) - g(i,o)|/max"
            } else {
                "Not reciprocal (f_ss times a factor of the view alone): |f(o,i) - f(i,o)|/max"
            };
            it.findings.push(format!(
                "{what} reaches {a:.3} at r = {:.2}, n·v = {:.4}, n·l = {:.4} (F0 = 1).",
                p[0], p[1], p[2]
            ));
        } else {
            it.findings.push("Reciprocal: f_ss and f_ms are symmetric in (o, i).".into());
        }
        if r.scheme == Scheme::KullaConty {
            let (d, p) = kc_quadrature_check(&grid);
            it.extra.push(("f1_max_abs_dev_independent_quadrature".into(), d));
            it.findings.push(format!(
                "Numerical check of ∫ f_ms μi dωi = 1 - E(μo): with 2∫(1 - E)μ dμ from an independent 48-point Gauss-Legendre \
                 rule in μ = t² instead of 1 - E_avg, the albedo at F = 1 is 1 within {d:.2e} (worst at {}).",
                fmt_point(&p)
            ));
        }
        if let Some(t) = r.tables_f1_max_dev {
            it.extra.push(("tables_f1_max_abs_dev".into(), t));
            it.findings.push(format!(
                "With E and E_avg from the committed {E_TABLE} (32×32 over α, n·v) and {E_AVG_TABLE} (32 over α) through the \
                 emitted f32 lookup, the albedo at F = 1 is off 1 by up to {t:.2e}."
            ));
        }
        it.findings.push(energy_finding(r.scheme, r.f1_max_dev, (g, &fmt_point(&gp)), (l, &fmt_point(&lp))));
        out.push(it);
    }
    out
}

/// What a scheme does to energy at F = 1: single scattering's loss and bevy's old gain (each with
/// its worst point), otherwise conservation when the albedo's largest deviation from 1 is below
/// 1e-6 (the integrators' residual through factors ≤ 1/E), else that deviation.
fn energy_finding(scheme: Scheme, f1_max_dev: f64, (g, gp): (f64, &str), (l, lp): (f64, &str)) -> String {
    match scheme {
        Scheme::Single => format!("Loses 1 - E(μ): up to {l:.3} at {lp}."),
        Scheme::BevyOld => format!(
            "Gains B/A at F0 = 1: up to {g:.3} at {gp} on this grid, unbounded as n·v → 0 and α → 0 (A → 1 - (1 - n·v)^5 → 0): \
             the fireflies of bevy PR #22833. With A + B (PR #23514) it is Turquin's scheme, exact at F = 1."
        ),
        _ if f1_max_dev < 1e-6 => "Conserves energy at F = 1 (algebraically exact; the residual is the integrators').".into(),
        _ => format!("Deviates from 1 by up to {f1_max_dev:.2e} at F = 1."),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The n·v samples are the stated domain's: MU_COUNT uniform values from 0 to 1, both
    /// ends included (the grazing end is where the schemes differ most).
    #[test]
    fn mu_grid_spans_the_stated_domain() {
        let mu = mu_grid();
        assert_eq!(mu.len(), MU_COUNT);
        assert!(domain().contains(&format!("n·v ∈ [0, 1] ({MU_COUNT})")), "{}", domain());
        assert_eq!((mu[0], mu[MU_COUNT - 1]), (0.0, 1.0));
        // Uniform: each the same quotient i/(MU_COUNT − 1), to the bit.
        assert!(mu.iter().enumerate().all(|(i, &m)| m == i as f64 / (MU_COUNT - 1) as f64), "{mu:?}");
    }

    /// The grid is roughness-major: point (j, i) is input j·len(μ) + i.
    #[test]
    fn grid_points_are_roughness_major() {
        let inputs = (0..6).map(|k| Inputs { a: k as f64, b: 0.0, e_avg: 0.0 }).collect();
        let g = Grid { roughness: vec![0.2, 0.8], mu: vec![0.1, 0.5, 1.0], inputs };
        assert_eq!((g.at(0, 2).a, g.at(1, 0).a, g.at(1, 2).a), (2.0, 3.0, 5.0));
    }

    /// With tables equal to the exact inputs and 2∫(1 − E)μ dμ = 1 − E_avg, the tabulated
    /// Kulla–Conty and Turquin albedos at F = 1 are 1 (E = A + B = 0.8, E_avg = 0.75:
    /// 0.8 + 1·0.2·0.25/0.25 and 0.8·(1 + 0.2/0.8)); the schemes without a tabulated form are None.
    #[test]
    fn tabulated_furnace_conserves_energy_at_f1_with_exact_tables() {
        let exact = Inputs { a: 0.7, b: 0.1, e_avg: 0.75 };
        for s in [Scheme::KullaConty, Scheme::Turquin] {
            let v = furnace_tabulated(s, 1.0, &exact, 0.8, 0.75, 0.25).unwrap();
            // A few roundings of values ~1.
            assert!((v - 1.0).abs() < 1e-15, "{s:?}: {v}");
        }
        assert!(furnace_tabulated(Scheme::Cycles, 1.0, &exact, 0.8, 0.75, 0.25).is_some());
        for s in [Scheme::Single, Scheme::BevyOld, Scheme::FdezAguera] {
            assert_eq!(furnace_tabulated(s, 1.0, &exact, 0.8, 0.75, 0.25), None, "{s:?}");
        }
    }

    /// At F0 = 1 Turquin's and Cycles' view factors are both 1/E (Cycles' f_ms is 1 there), so
    /// a pair's asymmetry |1/E_o − 1/E_i|/max(1/E_o, 1/E_i) is |E_o − E_i|/max(E_o, E_i), and
    /// the grid's largest is the widest row's (max E − min E)/max E, between that row's n·v of
    /// least and greatest E. Rounding of a few operations on values ~1: 1e-12.
    #[test]
    fn scaling_schemes_asymmetry_is_the_relative_spread_of_e() {
        let grid = Grid::exact(&[0.3, 0.8], &[0.05, 0.4, 1.0]);
        let (mut want, mut at) = (0.0f64, [0.0; 3]);
        for (j, &r) in grid.roughness.iter().enumerate() {
            let e: Vec<f64> = (0..grid.mu.len()).map(|i| grid.at(j, i).e()).collect();
            let (lo, hi) = (e.iter().copied().fold(f64::MAX, f64::min), e.iter().copied().fold(0.0, f64::max));
            let spread = (hi - lo) / hi;
            if spread > want {
                let mu_of = |v: f64| grid.mu[e.iter().position(|&x| x == v).unwrap()];
                (want, at) = (spread, [r, mu_of(lo), mu_of(hi)]);
            }
        }
        // A rough surface's E varies with n·v by far more than rounding: the test has a point.
        assert!(want > 0.01, "{want}");
        for s in [Scheme::Turquin, Scheme::Cycles] {
            let (a, p) = grid.asymmetry(s, 1.0).expect("not reciprocal");
            assert!((a - want).abs() <= 1e-12, "{s:?}: {a} vs {want}");
            // The worst pair is the row's least and greatest E, in either order.
            assert!(p[0] == at[0] && ((p[1], p[2]) == (at[1], at[2]) || (p[1], p[2]) == (at[2], at[1])), "{s:?}: {p:?} vs {at:?}");
            // Of the two orders, which tie, the first in grid order: μo is the earlier sample.
            let index = |m: f64| grid.mu.iter().position(|&x| x == m).unwrap();
            assert!(index(p[1]) < index(p[2]), "{s:?}: {p:?}");
        }
        assert_eq!(grid.asymmetry(Scheme::KullaConty, 1.0), None);
    }

    #[test]
    fn kc_quadrature_check_agrees_with_the_identity() {
        // Kulla–Conty at F = 1 is exactly 1 with the identity 2∫(1 − E)μ dμ = 1 − E_avg; with
        // the integral re-measured by 48-point Gauss–Legendre (E at 1e-9, E_avg at 1e-8) the
        // two agree to the integrators' tolerance times the amplification (1 − E)/(1 − E_avg)
        // (< 10 at r = 0.5), so 1e-5 leaves a wide margin while a wrong sign in 1 − E is O(1).
        let grid = Grid::exact(&[0.5], &[0.2, 0.8]);
        let (dev, at) = kc_quadrature_check(&grid);
        assert!((0.0..1e-5).contains(&dev), "{dev} at {at:?}");
        // The worst point is a point of the grid, (roughness, n·v) (none when every deviation
        // is 0).
        assert!(at == [0.5, 0.2] || at == [0.5, 0.8] || (dev == 0.0 && at.is_empty()), "{dev} at {at:?}");
    }

    #[test]
    fn table_integral_of_a_linear_interpolant_is_exact() {
        // A 1 × 2-point "E" that is linear in μ: E = 1 − μ/2 ⇒ 2∫(μ/2)μ dμ = 1/3 (2-point GL
        // is exact for the quadratic; f32 storage of 1 and 0.5 is exact).
        let e = Table { values: vec![1.0, 1.0, 0.5, 0.5], counts: vec![2, 2], domain: vec![(0.0, 1.0), (0.0, 1.0)] };
        let avg = Table { values: vec![0.9, 0.9], counts: vec![2], domain: vec![(0.0, 1.0)] };
        let t = tabulated(&e, &avg, 0.5, &[0.0, 1.0]);
        // f32 arithmetic of the interpolation at the GL nodes: a few ulps of f32.
        assert!((t.ms_integral - 1.0 / 3.0).abs() < 1e-6, "{}", t.ms_integral);
        assert_eq!(t.e, vec![1.0, 0.5]);
        // The same E on two cells of n·v ∈ [1/4, 1] (nodes 1/4, 5/8, 1: E = 7/8, 11/16, 1/2, exact
        // in f32), so each cell is weighed by its own width: 2∫_{1/4}^1 (μ/2)μ dμ = (1 − 1/64)/3.
        let e = Table { values: vec![0.875, 0.875, 0.6875, 0.6875, 0.5, 0.5], counts: vec![2, 3], domain: vec![(0.0, 1.0), (0.25, 1.0)] };
        let t = tabulated(&e, &avg, 0.5, &[0.25, 1.0]);
        assert!((t.ms_integral - 63.0 / 192.0).abs() < 1e-6, "{}", t.ms_integral);
        assert_eq!(t.e, vec![0.875, 0.5]);
    }

    #[test]
    fn committed_tables_agree_with_the_integrals() {
        // The E table's corner (α = 1, n·v = 1) is a grid point: 1 − ln 2 to the f32 rounding
        // of a value ≈ 0.3 (3e-8) plus the spec's integrator tolerance. E_avg at a grid point
        // of its table against albedo_avg directly: f32 rounding (6e-8) plus both tolerances.
        let generated = Path::new(env!("CARGO_MANIFEST_DIR")).join("generated");
        let e = Table::load(&generated, E_TABLE).expect("committed E table");
        let avg = Table::load(&generated, E_AVG_TABLE).expect("committed E_avg table");
        assert!((e.eval(&[1.0, 1.0]) - integrals::albedo_normal_rough()).abs() < 1e-7);
        let a_lo = avg.domain[0].0 as f64;
        let (a_hi, n) = (avg.domain[0].1 as f64, avg.counts[0]);
        for k in [0, n / 3, n - 1] {
            let a = if k + 1 == n { a_hi } else { a_lo + (a_hi - a_lo) * k as f64 / (n - 1) as f64 };
            let want = integrals::albedo_avg(a, 1e-9).value;
            assert!((avg.eval(&[a]) - want).abs() < 1e-7, "α = {a}: {} vs {want}", avg.eval(&[a]));
        }
        // E → 1 at n·v = 1 as α → 0 (the table's first row, α = 1e-4: 1 − E = O(α)).
        assert!((e.eval(&[e.domain[0].0 as f64, 1.0]) - 1.0).abs() < 1e-3);
    }

    #[test]
    fn furnace_table_says_what_the_module_doc_does() {
        let generated = Path::new(env!("CARGO_MANIFEST_DIR")).join("generated");
        let (rows, grid, _) = rows(&generated);
        // Read through the committed tables, Turquin's and Cycles' albedos at F = 1 are both
        // E·(1 + (1 − E_t)/E_t) = E/E_t (Cycles' f_ms is 1 at F_avg = 1), so their tables'
        // deviation is max |E/E_t − 1| over the grid, E_t the emitted f32 lookup at (r², n·v).
        // Relative rounding of a few operations on values ~1: 1e-12.
        let e_t = Table::load(&generated, E_TABLE).expect("committed E table");
        let mut want = 0.0f64;
        for (j, &r) in grid.roughness.iter().enumerate() {
            for (i, &m) in grid.mu.iter().enumerate() {
                want = want.max((grid.at(j, i).e() / e_t.eval(&[r * r, m]) - 1.0).abs());
            }
        }
        // The tables are a 32×32 bilinear interpolant of E: off it by more than the exact
        // integrals' 1e-7 near the mirror limit, by far less than E itself.
        assert!(want > 1e-6 && want < 0.5, "{want}");
        for r in &rows {
            match r.scheme {
                Scheme::Turquin | Scheme::Cycles => {
                    let t = r.tables_f1_max_dev.expect("tables read");
                    assert!((t - want).abs() <= 1e-12, "{:?}: {t} vs max |E/E_t − 1| = {want}", r.scheme);
                }
                // Kulla–Conty reads E, E_avg and the table's own integral: some deviation.
                Scheme::KullaConty => assert!(r.tables_f1_max_dev.is_some_and(|t| t > 0.0 && t < 0.5), "{r:?}"),
                Scheme::Single | Scheme::BevyOld | Scheme::FdezAguera => assert_eq!(r.tables_f1_max_dev, None),
            }
            match r.scheme {
                // Exact at F = 1 up to the inputs' tolerances (1e-9, 1e-8) through factors ≤ 1/E.
                Scheme::KullaConty | Scheme::Turquin | Scheme::FdezAguera | Scheme::Cycles => {
                    assert!(r.f1_max_dev < 1e-7, "{:?}: {}", r.scheme, r.f1_max_dev)
                }
                // E ≤ 1 up to the integrators' tolerance (E rounds to 1 + 1e-15 near mirrors).
                Scheme::Single => assert!(r.f1_loss > 0.5 && r.f1_gain < 1e-9),
                Scheme::BevyOld => assert!(r.f1_gain > 0.5 && r.f1_loss < 1e-9),
            }
            assert_eq!(r.asymmetry.is_none(), r.scheme.reciprocal());
            // Energy is never created at F0 < 1 except by bevy's variant.
            if r.scheme != Scheme::BevyOld {
                assert!(r.f0_range.iter().all(|&(_, hi)| hi <= 1.0 + 1e-7), "{:?}", r);
            }
        }
        // max |albedo − Kulla–Conty's| at each F0: 0 for Kulla–Conty against itself; for the
        // others the largest difference of the two schemes' albedos re-taken here (the same f64
        // values: exact), and not 0 for single scattering, which lacks the F_ms (1 − E) term.
        let kc: Vec<Vec<f64>> = F0S.iter().map(|&f0| grid.furnace(Scheme::KullaConty, f0)).collect();
        for r in &rows {
            for (k, &f0) in F0S.iter().enumerate() {
                let want = grid.furnace(r.scheme, f0).iter().zip(&kc[k]).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
                assert_eq!(r.f0_vs_kc[k], want, "{:?} at F0 = {f0}", r.scheme);
            }
            match r.scheme {
                Scheme::KullaConty => assert_eq!(r.f0_vs_kc, vec![0.0; F0S.len()]),
                Scheme::Single => assert!(r.f0_vs_kc.iter().all(|&d| d > 1e-3), "{:?}", r.f0_vs_kc),
                _ => {}
            }
        }
    }

    /// The items restate the furnace table: a summary line per scheme (its id first), then one
    /// item per scheme, named by its id and sourced by its source, whose max error at F = 1 is
    /// the row's largest deviation and whose gain and loss extras are the row's. Single
    /// scattering's finding names where it loses most, re-found here from its albedo on the
    /// grid (r and n·v to the printed 2 and 4 decimals); Kulla–Conty's independent quadrature
    /// check is within 1e-5 of 1 (kc_quadrature_check's own bound).
    #[test]
    fn items_restate_the_furnace_table() {
        let generated = Path::new(env!("CARGO_MANIFEST_DIR")).join("generated");
        let items = items(&generated);
        let (rows, grid, points) = rows(&generated);
        assert_eq!(items.len(), 1 + rows.len());
        for (r, line) in rows.iter().zip(&items[0].findings[1..]) {
            assert!(line.starts_with(&format!("{} | ", r.scheme.id())), "{line}");
        }
        for (r, it) in rows.iter().zip(&items[1..]) {
            assert_eq!((it.name.as_str(), it.source.as_str()), (format!("ggx_furnace_{}", r.scheme.id()).as_str(), r.scheme.source()));
            let extra = |k: &str| it.extra.iter().find(|e| e.0 == k).unwrap_or_else(|| panic!("{k}")).1;
            assert_eq!((it.max_abs_error, extra("f1_max_gain"), extra("f1_max_loss")), (r.f1_max_dev, r.f1_gain, r.f1_loss));
            // The reciprocity finding: Fdez-Agüera's extra lobe, the scaling schemes' factor of
            // the view, the others' symmetry; the printed asymmetry is the row's (3 decimals).
            let says = |key: &str| it.findings.iter().any(|f| f.contains(key));
            assert_eq!(says("its extra lobe"), r.scheme == Scheme::FdezAguera, "{:?}", it.findings);
            assert_eq!(says("f_ss times a factor of the view alone"), matches!(r.scheme, Scheme::Turquin | Scheme::Cycles | Scheme::BevyOld), "{:?}", it.findings);
            assert_eq!(says("Reciprocal: "), r.scheme.reciprocal(), "{:?}", it.findings);
            if let Some((a, _)) = r.asymmetry {
                let text = it.findings.iter().find(|f| f.contains(" reaches ")).unwrap();
                assert!((crate::validate::number_after(text, " reaches ") - a).abs() <= 5e-4, "{a}: {text}");
            }
        }
        let single = grid.furnace(Scheme::Single, 1.0);
        let (k, _) = single.iter().enumerate().fold((0, 0.0), |b, (k, &a)| if 1.0 - a > b.1 { (k, 1.0 - a) } else { b });
        let text = items[1].findings.last().unwrap();
        let (r, m) = (crate::validate::number_after(text, "(r = "), crate::validate::number_after(text, "n·v = "));
        assert!((r - points[k][0]).abs() <= 5e-3 && (m - points[k][1]).abs() <= 5e-5, "{text}: worst loss at {:?}", points[k]);
        let kc = items.iter().find(|i| i.name.ends_with("kulla_conty")).unwrap();
        assert!(kc.extra.iter().any(|e| e.0 == "f1_max_abs_dev_independent_quadrature" && e.1 < 1e-5));
    }

    /// The grid holds the integrals at α = r² (not r): E = A + B against `albedo` and E_avg
    /// against `albedo_avg`, both at α = 0.25 for r = 0.5 (integrated separately at 1e-10 and
    /// 1e-9). Bound: the grid's tolerances (1e-9 on A and B each, 1e-8 on E_avg) plus these.
    #[test]
    fn grid_inputs_are_the_integrals_at_alpha_r_squared() {
        let grid = Grid::exact(&[0.5], &[0.3, 1.0]);
        let want_avg = integrals::albedo_avg(0.25, 1e-9).value;
        for (i, &m) in grid.mu.iter().enumerate() {
            let x = grid.at(0, i);
            let want = integrals::albedo(0.25, m, 1e-10).value;
            assert!((x.e() - want).abs() < 2e-9 + 1e-10, "n·v = {m}: E {} vs {want}", x.e());
            assert!((x.e_avg - want_avg).abs() < 1e-8 + 1e-9, "E_avg {} vs {want_avg}", x.e_avg);
        }
    }

    /// The independent-quadrature check measures what it states: on a grid whose inputs are
    /// planted (E = 0.9 at n·v = 0.2 and 0.6 at 0.8, E_avg with 1 − E_avg half the true
    /// 1 − E_avg(0.25)), Kulla–Conty's albedo with the re-measured 2∫(1 − E)μ dμ is
    /// E + 2(1 − E) = 2 − E, so the deviation is 1 − E: largest, 0.4, at (r = 0.5, n·v = 0.8).
    /// Bound: the rule against 1 − E_avg (integrals at 1e-9, 1e-10) to ~1e-8 relative, times
    /// 2(1 − E) ≤ 0.8; 1e-5 as the check's own bound.
    #[test]
    fn kc_quadrature_check_measures_a_planted_identity_error() {
        let e_avg = integrals::albedo_avg(0.25, 1e-10).value;
        let planted = 1.0 - 0.5 * (1.0 - e_avg);
        let inputs = vec![Inputs { a: 0.5, b: 0.4, e_avg: planted }, Inputs { a: 0.4, b: 0.2, e_avg: planted }];
        let grid = Grid { roughness: vec![0.5], mu: vec![0.2, 0.8], inputs };
        let (dev, at) = kc_quadrature_check(&grid);
        assert!((dev - 0.4).abs() < 1e-5, "{dev} at {at:?}");
        assert_eq!(at, vec![0.5, 0.8]);
    }

    /// Signed extremes by hand (dyadic values, exact): v − 1 = 0, 0.25, −0.5, 0.125 gains most
    /// (0.25) at the second point and loses most (0.5) at the third. Where nothing gains or
    /// loses (every v exactly 1) both are 0 and have no point, which the findings print as
    /// "nowhere".
    #[test]
    fn gain_loss_finds_signed_extremes_and_no_point_when_there_is_none() {
        let points = vec![vec![0.1, 0.0], vec![0.2, 0.5], vec![0.3, 1.0], vec![0.4, 0.25]];
        let (g, gp, l, lp) = gain_loss(&points, &[1.0, 1.25, 0.5, 1.125]);
        assert_eq!((g, gp, l, lp), (0.25, vec![0.2, 0.5], 0.5, vec![0.3, 1.0]));
        let (g, gp, l, lp) = gain_loss(&points, &[1.0; 4]);
        assert_eq!((g, l), (0.0, 0.0));
        assert_eq!((fmt_point(&gp), fmt_point(&lp)), ("nowhere".to_string(), "nowhere".to_string()));
    }

    /// A committed table is read only when its axes' counts multiply to its number of values
    /// and it has one or two axes: a 2 × 2 table with 3 values and a 1 × 1 × 2 table (2 values,
    /// three axes) are refused, the same 2 × 2 table with 4 values is read.
    #[test]
    fn table_load_refuses_shapes_that_do_not_match_their_values() {
        let dir = std::env::temp_dir().join(format!("shadefit-furnace-load-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("json")).unwrap();
        let axis = |n: usize| format!("{{\"count\": {n}, \"range\": [0.0, 1.0]}}");
        let write = |name: &str, values: &str, axes: &[usize]| {
            let axes: Vec<String> = axes.iter().map(|&n| axis(n)).collect();
            let text = format!("{{\"values\": [{values}], \"axes\": [{}]}}", axes.join(", "));
            std::fs::write(dir.join("json").join(format!("{name}.json")), text).unwrap();
        };
        write("short", "0.1, 0.2, 0.3", &[2, 2]);
        write("three_axes", "0.1, 0.2", &[1, 1, 2]);
        write("good", "0.1, 0.2, 0.3, 0.4", &[2, 2]);
        let (short, three, good) = (Table::load(&dir, "short"), Table::load(&dir, "three_axes"), Table::load(&dir, "good"));
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(short.is_none() && three.is_none(), "{short:?} {three:?}");
        assert_eq!(good.map(|t| (t.counts, t.values.len())), Some((vec![2, 2], 4)));
    }

    /// The energy finding names the loss, the gain, conservation below 1e-6 and a deviation
    /// above it (with the numbers it is given, printed as the report prints them).
    #[test]
    fn energy_finding_says_conserves_only_below_its_threshold() {
        let (g, l) = ((0.25, "r = 0.1"), (0.125, "r = 0.9"));
        assert_eq!(energy_finding(Scheme::Single, 0.125, g, l), "Loses 1 - E(μ): up to 0.125 at r = 0.9.");
        assert!(energy_finding(Scheme::BevyOld, 0.25, g, l).starts_with("Gains B/A at F0 = 1: up to 0.250 at r = 0.1 on this grid"));
        for s in [Scheme::KullaConty, Scheme::Turquin, Scheme::FdezAguera, Scheme::Cycles] {
            assert!(energy_finding(s, 3e-9, g, l).starts_with("Conserves energy at F = 1"), "{s:?}");
            assert!(energy_finding(s, 9.9e-7, g, l).starts_with("Conserves energy"), "{s:?}");
            assert_eq!(energy_finding(s, 2e-6, g, l), "Deviates from 1 by up to 2.00e-6 at F = 1.", "{s:?}");
            // "Below 1e-6": the threshold itself is a deviation.
            assert_eq!(energy_finding(s, 1e-6, g, l), "Deviates from 1 by up to 1.00e-6 at F = 1.", "{s:?}");
        }
    }
}
