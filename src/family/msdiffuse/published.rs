//! The talk's published approximations and three other diffuse models, measured against the
//! simulated slices (the committed `generated/json/ms_diffuse_slices.json`, Schlick F0 = 0.04 with
//! the specular share gone, and `ms_diffuse_slices_lambert.json`, F0 = 0: the white-furnace
//! surface), each in its own convention, all as π f/ρ at ρ = 1 (Lambert = 1):
//!
//! - the 15-coefficient rational fit of the gloss = 0 slice (slide "2D rational function fit of
//!   the BRDF slice"), x = n·h, y = l·h. Its values are f itself (1/sr) at ρ = 1: π f(1, 1) =
//!   0.989, Lambert's 1 up to the fit; so π·R is measured. Refitted here in the same form
//!   (least squares on the same slice) to show what the form can do;
//! - the shipped hand fit (slides "Hand fitting"): f_r = ρ/π (f_d + f_b), so π f/ρ = f_d + f_b
//!   with f₀ = l·h + (1 − l·h)⁵, f₁ = (1 − 0.75(1 − n·l)⁵)(1 − 0.75(1 − n·v)⁵), t = clamp(2.2g −
//!   0.5, 0, 1), f_d = f₀ + (f₁ − f₀)t, f_b = (34.5g² − 59g + 24.5)(l·h) 2^(−max(73.2g − 21.2,
//!   8.9)√(n·h)); g is the WWII gloss;
//! - Burley 2012 (Disney diffuse): (1 + (F_D90 − 1)(1 − n·l)⁵)(1 + (F_D90 − 1)(1 − n·v)⁵),
//!   F_D90 = ½ + 2 r (l·h)², roughness r = √α (Disney's α = r²);
//! - Hammon 2017 ("PBR diffuse lighting for GGX+Smith microsurfaces", GDC): at ρ = 1,
//!   mix(smooth, rough, α) + π·0.1159 α with facing = ½ + ½ l·v, rough = facing (0.9 − 0.4
//!   facing)(½ + n·h)/n·h, smooth = 1.05 (1 − (1 − n·l)⁵)(1 − (1 − n·v)⁵), α the GGX α;
//! - EON (Portsmouth, Kutz & Hill 2025, "EON: a practical energy-preserving rough diffuse BRDF",
//!   the OpenPBR diffuse): the energy-preserving Oren–Nayar with its exact albedo, roughness r =
//!   α (no published map between the two). It conserves energy at ρ = 1, so it is measured
//!   against the F0 = 0 slices.

use super::integrals::TALK_F0;
use crate::shading::roughness::alpha_from_gloss;
use crate::fit::{FitOptions, Objective, RationalModel, fit_rescaled};
use crate::validate::Item;
use serde_json::Value;
use std::f64::consts::{FRAC_PI_2, PI};
use std::path::Path;

/// The slide's numerator and denominator, terms [1, x, y, x², y², xy, x³, y³].
pub const RATIONAL_NUM: [f64; 8] = [0.568, -0.692, -0.938, 1.326, 0.301, 1.96, -0.98, 1.533];
pub const RATIONAL_DEN: [f64; 8] = [1.0, 1.731, -0.997, -0.998, -0.843, 9.905, -0.971, 0.948];
pub const TERMS: [&str; 8] = ["1", "x", "y", "x^2", "y^2", "x*y", "x^3", "y^3"];

/// The published rational R(x, y) (f in 1/sr at ρ = 1) with numerator and denominator
/// constants `num`, `den`: the form's program ([`super::refit::RATIONAL_FORM`]) in f64.
pub fn rational(num: &[f64; 8], den: &[f64; 8], x: f64, y: f64) -> f64 {
    let c: Vec<f64> = num.iter().chain(den).copied().collect();
    super::refit::RATIONAL_FORM.eval_f64(&[x, y], &c)[0]
}

fn pow5(x: f64) -> f64 {
    let x2 = x * x;
    x2 * x2 * x
}

/// The cosines a diffuse model needs at one slice point.
#[derive(Debug, Clone, Copy)]
pub struct Cosines {
    pub n_dot_l: f64,
    pub n_dot_v: f64,
    pub n_dot_h: f64,
    pub l_dot_h: f64,
    pub l_dot_v: f64,
}

impl Cosines {
    pub fn at(theta_h: f64, theta_d: f64, phi_d: f64) -> Option<Cosines> {
        let (l, v) = super::integrals::directions(theta_h, theta_d, phi_d)?;
        Some(Cosines {
            n_dot_l: l[2],
            n_dot_v: v[2],
            n_dot_h: theta_h.cos(),
            l_dot_h: theta_d.cos(),
            l_dot_v: l[0] * v[0] + l[1] * v[1] + l[2] * v[2],
        })
    }
}

/// The shipped hand fit, π f/ρ = f_d + f_b.
pub fn hand_fit(g: f64, c: &Cosines) -> f64 {
    let f0 = c.l_dot_h + pow5(1.0 - c.l_dot_h);
    let f1 = (1.0 - 0.75 * pow5(1.0 - c.n_dot_l)) * (1.0 - 0.75 * pow5(1.0 - c.n_dot_v));
    let t = (2.2 * g - 0.5).clamp(0.0, 1.0);
    let fd = f0 + (f1 - f0) * t;
    let fb = (34.5 * g * g - 59.0 * g + 24.5) * c.l_dot_h * (-(73.2 * g - 21.2).max(8.9) * c.n_dot_h.sqrt()).exp2();
    fd + fb
}

/// Burley 2012's diffuse, π f/ρ, roughness r.
pub fn burley(r: f64, c: &Cosines) -> f64 {
    let fd90 = 0.5 + 2.0 * r * c.l_dot_h * c.l_dot_h;
    (1.0 + (fd90 - 1.0) * pow5(1.0 - c.n_dot_l)) * (1.0 + (fd90 - 1.0) * pow5(1.0 - c.n_dot_v))
}

/// Hammon 2017's GGX-Smith diffuse, π f/ρ at ρ = 1, GGX α.
pub fn hammon(alpha: f64, c: &Cosines) -> f64 {
    let facing = 0.5 + 0.5 * c.l_dot_v;
    let rough = facing * (0.9 - 0.4 * facing) * ((0.5 + c.n_dot_h) / c.n_dot_h);
    let smooth = 1.05 * (1.0 - pow5(1.0 - c.n_dot_l)) * (1.0 - pow5(1.0 - c.n_dot_v));
    smooth + (rough - smooth) * alpha + PI * 0.1159 * alpha
}

const FON_1: f64 = 0.5 - 2.0 / (3.0 * PI);
const FON_2: f64 = 2.0 / 3.0 - 28.0 / (15.0 * PI);

/// EON's exact directional albedo of the single-scattering (FON) lobe.
fn e_fon(mu: f64, r: f64) -> f64 {
    let af = 1.0 / (1.0 + FON_1 * r);
    let bf = r * af;
    let si = (1.0 - mu * mu).max(0.0).sqrt();
    let g = si * (mu.acos() - si * mu) + (2.0 / 3.0) * ((si / mu) * (1.0 - si * si * si) - si);
    af + bf / PI * g
}

/// EON, π f/ρ at ρ = 1, roughness r.
pub fn eon(r: f64, c: &Cosines) -> f64 {
    let (mi, mo) = (c.n_dot_l, c.n_dot_v);
    let s = c.l_dot_v - mi * mo;
    let sovt = if s > 0.0 { s / mi.max(mo) } else { s };
    let af = 1.0 / (1.0 + FON_1 * r);
    let f_ss = af * (1.0 + r * sovt);
    let avg = af * (1.0 + FON_2 * r);
    let rho_ms = avg / (1.0 - (1.0 - avg));
    let eps = 1e-7;
    let f_ms = rho_ms * (1.0 - e_fon(mo, r)).max(eps) * (1.0 - e_fon(mi, r)).max(eps) / (1.0 - avg).max(eps);
    f_ss + f_ms
}

/// One committed slice table: its points (gloss, θh, θd), values and standard errors.
pub struct Slices {
    pub points: Vec<Vec<f64>>,
    pub cosines: Vec<Cosines>,
    pub values: Vec<f64>,
    pub se: Vec<f64>,
    pub phi_d: f64,
    pub f0: f64,
}

impl Slices {
    pub fn load(generated: &Path, name: &str) -> Option<Slices> {
        let text = std::fs::read_to_string(generated.join(format!("json/{name}.json"))).ok()?;
        let v: Value = serde_json::from_str(&text).ok()?;
        let gloss: Vec<f64> = serde_json::from_value(v["gloss"].clone()).ok()?;
        let w = v["axes"][0]["count"].as_u64()? as usize;
        let h = v["axes"][1]["count"].as_u64()? as usize;
        let phi_d = v["phi_d"].as_f64()?;
        let cells: Vec<[f64; 2]> = serde_json::from_value(v["slices"].clone()).ok()?;
        let mut s = Slices { points: vec![], cosines: vec![], values: vec![], se: vec![], phi_d, f0: v["f0"].as_f64()? };
        for (k, &g) in gloss.iter().enumerate() {
            for j in 0..h {
                for i in 0..w {
                    let (th, td) = ((i as f64 + 0.5) / w as f64 * FRAC_PI_2, (j as f64 + 0.5) / h as f64 * FRAC_PI_2);
                    let c = Cosines::at(th, td, phi_d)?;
                    let cell = cells.get((k * h + j) * w + i)?;
                    s.points.push(vec![g, th, td]);
                    s.cosines.push(c);
                    s.values.push(cell[0]);
                    s.se.push(cell[1]);
                }
            }
        }
        Some(s)
    }

    /// The points of one gloss.
    pub fn at_gloss(&self, g: f64) -> Vec<usize> {
        (0..self.points.len()).filter(|&k| self.points[k][0] == g).collect()
    }

    fn pick(&self, idx: &[usize]) -> (Vec<Vec<f64>>, Vec<f64>, Vec<Cosines>) {
        (idx.iter().map(|&k| self.points[k].clone()).collect(), idx.iter().map(|&k| self.values[k]).collect(), idx.iter().map(|&k| self.cosines[k]).collect())
    }

    fn rms_se(&self, idx: &[usize]) -> f64 {
        (idx.iter().map(|&k| self.se[k] * self.se[k]).sum::<f64>() / idx.len().max(1) as f64).sqrt()
    }
}

/// The published form as a rational model of features (x, y) = (n·h, l·h): [`TERMS`] over 1 +
/// the same but the constant; coefficients are numerator then denominator.
pub fn rational_model() -> Option<RationalModel> {
    let text = format!(
        "features = [\"x\", \"y\"]\nnumerator = [{}]\ndenominator = [{}]\n",
        TERMS.iter().map(|t| format!("\"{t}\"")).collect::<Vec<_>>().join(", "),
        TERMS[1..].iter().map(|t| format!("\"{t}\"")).collect::<Vec<_>>().join(", ")
    );
    let path = Path::new("ms-diffuse refit");
    let ms: crate::spec::ModelSpec = crate::spec::parse_toml(path, &text).ok()?;
    ms.build(path, &text, vec!["x".into(), "y".into()], &|_| None).ok()
}

/// The least-squares refit of the published form on (x, y) → f.
pub fn refit(xs: &[[f64; 2]], f: &[f64]) -> Option<([f64; 8], [f64; 8])> {
    let model = rational_model()?;
    let data = crate::fit::Data { x: xs.iter().map(|p| p.to_vec()).collect(), y: f.to_vec() };
    let fit = fit_rescaled(&model, &data, &FitOptions { objective: Objective::Lsq, ..FitOptions::default() }, "ms-diffuse refit").ok()?;
    let c = &fit.coefficients;
    let mut num = [0.0; 8];
    let mut den = [1.0; 8];
    for j in 0..8 {
        num[j] = c[j];
    }
    for j in 1..8 {
        den[j] = c[8 + j - 1];
    }
    Some((num, den))
}

/// The gloss-0 slice of committed slices: its points, the simulated π f there and the
/// rational's (n·h, l·h).
pub fn gloss_zero(s: &Slices) -> (Vec<Vec<f64>>, Vec<f64>, Vec<[f64; 2]>) {
    let (pts, truth, cos) = s.pick(&s.at_gloss(0.0));
    let xy = cos.iter().map(|c| [c.n_dot_h, c.l_dot_h]).collect();
    (pts, truth, xy)
}

/// The committed gloss-dependent fit (`generated/json/ms_diffuse_rational.json`) as its emitted
/// code evaluates it: the f32 coefficients, inputs clamped to the spec's axes, the result to
/// the model's clamp (evaluated in f64 here).
pub struct CommittedRational {
    num: Vec<(f64, Vec<(usize, i32)>)>,
    den: Vec<(f64, Vec<(usize, i32)>)>,
    ranges: Vec<[f64; 2]>,
    clamp: [f64; 2],
}

impl CommittedRational {
    pub fn load(generated: &Path) -> Option<CommittedRational> {
        let text = std::fs::read_to_string(generated.join("json/ms_diffuse_rational.json")).ok()?;
        let v: Value = serde_json::from_str(&text).ok()?;
        let m = &v["model"];
        let names: Vec<String> = serde_json::from_value(m["arguments"].clone()).ok()?;
        let terms = |key: &str, coef: &str| -> Option<Vec<(f64, Vec<(usize, i32)>)>> {
            let t: Vec<String> = serde_json::from_value(m[key].clone()).ok()?;
            let c: Vec<f64> = serde_json::from_value(m[coef].clone()).ok()?;
            (t.len() == c.len()).then_some(())?;
            t.iter().zip(c).map(|(t, c)| Some((c, parse_term(t, &names)?))).collect()
        };
        let ranges = v["axes"].as_array()?.iter().map(|a| serde_json::from_value(a["range"].clone()).ok()).collect::<Option<Vec<[f64; 2]>>>()?;
        Some(CommittedRational {
            num: terms("numerator", "numerator_f32")?,
            den: terms("denominator", "denominator_f32")?,
            ranges,
            clamp: serde_json::from_value(m["clamp"].clone()).ok()?,
        })
    }

    /// π f/ρ at (α, n·h, l·h).
    pub fn eval(&self, alpha: f64, n_dot_h: f64, l_dot_h: f64) -> f64 {
        let x: Vec<f64> = [alpha, n_dot_h, l_dot_h].iter().zip(&self.ranges).map(|(v, r)| v.clamp(r[0], r[1])).collect();
        let sum = |t: &[(f64, Vec<(usize, i32)>)]| t.iter().map(|(c, f)| c * f.iter().map(|&(i, k)| x[i].powi(k)).product::<f64>()).sum::<f64>();
        (sum(&self.num) / (1.0 + sum(&self.den))).clamp(self.clamp[0], self.clamp[1])
    }

    /// The lower end of the n·h and l·h axes (the fit's domain starts there).
    pub fn cosine_floor(&self) -> f64 {
        self.ranges[1][0].max(self.ranges[2][0])
    }
}

/// "alpha*n_dot_h^2" → [(0, 1), (1, 2)] over the argument names; "1" → [].
fn parse_term(t: &str, names: &[String]) -> Option<Vec<(usize, i32)>> {
    if t == "1" {
        return Some(vec![]);
    }
    t.split('*')
        .map(|f| {
            let (n, k) = f.split_once('^').unwrap_or((f, "1"));
            Some((names.iter().position(|x| x == n)?, k.parse().ok()?))
        })
        .collect()
}

fn missing(name: &str, source: &str, table: &str) -> Item {
    let mut it = Item::measured(name, source, "not measured", &[], &[], &[]);
    it.findings.push(format!("generated/json/{table}.json is missing or unreadable: run `shadefit build --only {table}`."));
    it
}

const SOURCE_TALK: &str = "Call of Duty: WWII, 'Multiscattering Diffuse BRDF' (slides '2D rational function fit', 'Hand fitting')";

pub fn items(generated: &Path) -> Vec<Item> {
    let mut out = Vec::new();
    let Some(fresnel_slices) = Slices::load(generated, "ms_diffuse_slices") else {
        return vec![missing("ms-diffuse slices", SOURCE_TALK, "ms_diffuse_slices")];
    };
    let lambert = Slices::load(generated, "ms_diffuse_slices_lambert");
    let domain_of = |s: &Slices, what: &str| format!("{what}: θh, θd cell centres of the committed slices at φd = {:.4} (π f/ρ, Lambert = 1)", s.phi_d);

    // (1) The published rational on the gloss = 0 slice, and the refit.
    let g0 = fresnel_slices.at_gloss(0.0);
    let (pts, truth, cos) = fresnel_slices.pick(&g0);
    let xy: Vec<[f64; 2]> = cos.iter().map(|c| [c.n_dot_h, c.l_dot_h]).collect();
    let published: Vec<f64> = xy.iter().map(|p| PI * rational(&RATIONAL_NUM, &RATIONAL_DEN, p[0], p[1])).collect();
    let mut it = Item::measured("ms-diffuse gloss-0 slice: published 15-coefficient rational (π·R)", SOURCE_TALK, &domain_of(&fresnel_slices, "gloss 0, F0 = 0.04"), &pts, &truth, &published);
    it.extra.push(("reference_rms_standard_error".into(), fresnel_slices.rms_se(&g0)));
    it.findings.push(format!(
        "R is the BRDF f (1/sr) at ρ = 1: π R(1, 1) = {:.3}. Against the F0 = 0.04 simulation (Schlick at both crossings of every facet) it is brighter everywhere.",
        PI * rational(&RATIONAL_NUM, &RATIONAL_DEN, 1.0, 1.0)
    ));
    if let Some(lam) = &lambert {
        let l0 = lam.at_gloss(0.0);
        let (lp, lt, lc) = lam.pick(&l0);
        let scaled: Vec<f64> = lt.iter().map(|v| v * (1.0 - TALK_F0).powi(2)).collect();
        let pub_l: Vec<f64> = lc.iter().map(|c| PI * rational(&RATIONAL_NUM, &RATIONAL_DEN, c.n_dot_h, c.l_dot_h)).collect();
        let (m, r, _) = crate::validate::measure(&lp, &scaled, &pub_l);
        let ratio: Vec<f64> = pub_l.iter().zip(&lt).map(|(p, t)| p / t).collect();
        let mut sorted = ratio.clone();
        sorted.sort_by(f64::total_cmp);
        it.extra.push(("max_abs_error_vs_f0_0_times_0.9216".into(), m));
        it.extra.push(("rms_error_vs_f0_0_times_0.9216".into(), r));
        it.findings.push(format!(
            "π R / (F0 = 0 simulation) has median {:.3} (quartiles {:.3}, {:.3}), near (1 − 0.04)² = 0.922: the talk's simulation looks like Lambertian facets with a constant (1 − F0) at the entry and the exit, not the angle-dependent Schlick factor at every facet crossing this family simulates (the slides do not say which). Against 0.9216 × the F0 = 0 slice: max {m:.3e}, rms {r:.3e} (the max at the grazing retroreflective peak, θh → π/2, which the rational does not follow).",
            sorted[sorted.len() / 2],
            sorted[sorted.len() / 4],
            sorted[3 * sorted.len() / 4]
        ));
    }
    match super::refit::committed(generated) {
        Ok((num, den)) => {
        let approx: Vec<f64> = xy.iter().map(|p| PI * rational(&num, &den, p[0], p[1])).collect();
        let (m, r, _) = crate::validate::measure(&pts, &truth, &approx);
        it.extra.push(("refit_max_abs_error".into(), m));
        it.extra.push(("refit_rms_error".into(), r));
        it.findings.push(format!(
            "Refitted in the same form (least squares on this slice): max {m:.3e} ({:.2}× the published), rms {r:.3e} ({:.2}×); numerator {:?}, denominator {:?}.",
            m / it.max_abs_error,
            r / it.rms_error,
            num.map(|c| (c * 1e4).round() / 1e4),
            den.map(|c| (c * 1e4).round() / 1e4)
        ));
        }
        Err(e) => it.findings.push(format!("The refit in the same form is not committed here: {e} (fits/{}.toml).", super::refit::SPEC)),
    }
    out.push(it);

    // (2) The hand fit over every gloss layer.
    let all: Vec<usize> = (0..fresnel_slices.points.len()).collect();
    let approx: Vec<f64> = all.iter().map(|&k| hand_fit(fresnel_slices.points[k][0], &fresnel_slices.cosines[k])).collect();
    let mut it = Item::measured("ms-diffuse slices: shipped hand fit (f_d + f_b)", SOURCE_TALK, &domain_of(&fresnel_slices, "every gloss layer, F0 = 0.04"), &fresnel_slices.points, &fresnel_slices.values, &approx);
    per_gloss(&mut it, &fresnel_slices, &approx);
    it.findings.push("f_r = ρ/π (f_d + f_b) per the slides' edit; g is the WWII gloss. The retroreflective bump f_b carries most of the error at grazing θh.".into());
    out.push(it);

    // (3) Burley 2012 and Hammon 2017 against the F0 = 0.04 slices.
    let approx: Vec<f64> = all.iter().map(|&k| burley(alpha_from_gloss(fresnel_slices.points[k][0]).sqrt(), &fresnel_slices.cosines[k])).collect();
    let mut it = Item::measured(
        "ms-diffuse slices: Burley 2012 diffuse (r = √α)",
        "Burley 2012, 'Physically-based shading at Disney', Eq. in §5.3 (F_D90 = 0.5 + 2 r cos²θd)",
        &domain_of(&fresnel_slices, "every gloss layer, F0 = 0.04"),
        &fresnel_slices.points,
        &fresnel_slices.values,
        &approx,
    );
    per_gloss(&mut it, &fresnel_slices, &approx);
    out.push(it);
    let approx: Vec<f64> = all.iter().map(|&k| hammon(alpha_from_gloss(fresnel_slices.points[k][0]), &fresnel_slices.cosines[k])).collect();
    let mut it = Item::measured(
        "ms-diffuse slices: Hammon 2017 GGX-Smith diffuse (ρ = 1)",
        "Hammon 2017, 'PBR diffuse lighting for GGX+Smith microsurfaces' (GDC)",
        &domain_of(&fresnel_slices, "every gloss layer, F0 = 0.04"),
        &fresnel_slices.points,
        &fresnel_slices.values,
        &approx,
    );
    per_gloss(&mut it, &fresnel_slices, &approx);
    it.findings.push("Hammon's multiple-scattering term 0.1159 α ρ² is at ρ = 1 here.".into());
    out.push(it);

    // (3b) shadefit's gloss-dependent rational (fits/ms_diffuse_rational.toml) over every layer,
    // on the cells its domain covers (n·h, l·h ≥ its floor), beside the hand fit there.
    match CommittedRational::load(generated) {
        Some(fit) => {
            let floor = fit.cosine_floor();
            let idx: Vec<usize> = all.iter().copied().filter(|&k| fresnel_slices.cosines[k].n_dot_h >= floor && fresnel_slices.cosines[k].l_dot_h >= floor).collect();
            let sub = Slices {
                points: idx.iter().map(|&k| fresnel_slices.points[k].clone()).collect(),
                cosines: idx.iter().map(|&k| fresnel_slices.cosines[k]).collect(),
                values: idx.iter().map(|&k| fresnel_slices.values[k]).collect(),
                se: idx.iter().map(|&k| fresnel_slices.se[k]).collect(),
                phi_d: fresnel_slices.phi_d,
                f0: fresnel_slices.f0,
            };
            let approx: Vec<f64> = (0..sub.points.len()).map(|k| fit.eval(alpha_from_gloss(sub.points[k][0]), sub.cosines[k].n_dot_h, sub.cosines[k].l_dot_h)).collect();
            let hand: Vec<f64> = (0..sub.points.len()).map(|k| hand_fit(sub.points[k][0], &sub.cosines[k])).collect();
            let mut it = Item::measured(
                "ms-diffuse slices: shadefit gloss-dependent rational (ms_diffuse_rational)",
                "fits/ms_diffuse_rational.toml (generated/json/ms_diffuse_rational.json, f32 coefficients)",
                &domain_of(&sub, &format!("every gloss layer, F0 = 0.04, n·h and l·h ≥ {floor}")),
                &sub.points,
                &sub.values,
                &approx,
            );
            per_gloss(&mut it, &sub, &approx);
            let (hm, hr, _) = crate::validate::measure(&sub.points, &sub.values, &hand);
            it.extra.push(("hand_fit_max_abs_error_same_cells".into(), hm));
            it.extra.push(("hand_fit_rms_error_same_cells".into(), hr));
            let z: Vec<f64> = (0..sub.points.len()).map(|k| (approx[k] - sub.values[k]) / sub.se[k].max(1e-12)).collect();
            let rms_z = (z.iter().map(|z| z * z).sum::<f64>() / z.len().max(1) as f64).sqrt();
            it.extra.push(("rms_error_over_standard_error".into(), rms_z));
            it.findings.push(format!(
                "On the same {} cells the hand fit has max {hm:.3e}, rms {hr:.3e}; the rational's rms error is {rms_z:.1} standard errors of the simulation (cell by cell): the error is the form's. Below n·h or l·h = {floor} the emitted function clamps its inputs and does not follow the grazing retroreflective peak.",
                sub.points.len()
            ));
            out.push(it);
        }
        None => out.push(missing("ms-diffuse slices: shadefit gloss-dependent rational", "fits/ms_diffuse_rational.toml", "ms_diffuse_rational")),
    }

    // (4) EON against the F0 = 0 slices (both conserve energy at ρ = 1).
    match &lambert {
        Some(lam) => {
            let all: Vec<usize> = (0..lam.points.len()).collect();
            let approx: Vec<f64> = all.iter().map(|&k| eon(alpha_from_gloss(lam.points[k][0]), &lam.cosines[k])).collect();
            let mut it = Item::measured(
                "ms-diffuse slices (F0 = 0): EON energy-preserving Oren–Nayar (r = α)",
                "Portsmouth, Kutz & Hill 2025, 'EON: a practical energy-preserving rough diffuse BRDF' (OpenPBR)",
                &domain_of(lam, "every gloss layer, F0 = 0 (no Fresnel: the white-furnace surface)"),
                &lam.points,
                &lam.values,
                &approx,
            );
            per_gloss(&mut it, lam, &approx);
            it.findings.push(format!(
                "Both conserve energy at ρ = 1 (the committed albedo of the F0 = 0 table is 1 at every n·v); F0 = {} in the reference.",
                lam.f0
            ));
            out.push(it);
        }
        None => out.push(missing("ms-diffuse slices (F0 = 0): EON", "Portsmouth et al. 2025", "ms_diffuse_slices_lambert")),
    }
    out
}

/// Per-gloss max and rms errors, and the reference's rms standard error.
fn per_gloss(it: &mut Item, s: &Slices, approx: &[f64]) {
    let mut gl: Vec<f64> = s.points.iter().map(|p| p[0]).collect();
    gl.dedup();
    for g in gl {
        let idx = s.at_gloss(g);
        let (m, r, _) = crate::validate::measure(&[], &idx.iter().map(|&k| s.values[k]).collect::<Vec<_>>(), &idx.iter().map(|&k| approx[k]).collect::<Vec<_>>());
        it.extra.push((format!("gloss_{g}_max_abs_error"), m));
        it.extra.push((format!("gloss_{g}_rms_error"), r));
    }
    let all: Vec<usize> = (0..s.points.len()).collect();
    it.extra.push(("reference_rms_standard_error".into(), s.rms_se(&all)));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::validate::{extra, number_after};

    /// Without the committed slices the validation is one item that says which file to build,
    /// measured on no points.
    #[test]
    fn without_the_committed_slices_the_item_names_the_missing_file() {
        let items = items(Path::new("no-such-folder"));
        assert_eq!(items.len(), 1);
        let it = &items[0];
        assert_eq!((it.name.as_str(), it.points), ("ms-diffuse slices", 0));
        assert_eq!(it.findings, ["generated/json/ms_diffuse_slices.json is missing or unreadable: run `shadefit build --only ms_diffuse_slices`."]);
    }

    /// A committed term as its doc reads it: "alpha*n_dot_h^2" → [(0, 1), (1, 2)] over the
    /// argument names, "1" → none; a name not among the arguments, or an exponent that is not
    /// an integer, leaves the term unread (None).
    #[test]
    fn terms_parse_into_argument_indices_and_powers() {
        let names: Vec<String> = ["alpha", "n_dot_h", "l_dot_h"].map(String::from).to_vec();
        assert_eq!(parse_term("alpha*n_dot_h^2", &names), Some(vec![(0, 1), (1, 2)]));
        assert_eq!(parse_term("l_dot_h^3*alpha", &names), Some(vec![(2, 3), (0, 1)]));
        assert_eq!(parse_term("1", &names), Some(vec![]));
        assert_eq!(parse_term("gloss*alpha", &names), None);
        assert_eq!(parse_term("alpha^x", &names), None);
    }

    /// The shipped hand fit at g = 0.5, l·h = 1, n·l = 0.5, n·v = 0.8, n·h = 0.64, by hand from
    /// the talk's formula: f0 = 1; f1 = (1 − 0.75/32)(1 − 0.75·0.2⁵) = 0.9765625·0.99976 =
    /// 0.976328125; t = 0.6, f_d = 1 − 0.6·0.023671875 = 0.985796875; f_b = 3.625·2^(−15.4·0.8)
    /// = 3.625·2^−12.32 = 7.0895466e-4. Total 0.98650582966.
    #[test]
    fn hand_fit_at_a_hand_computed_point() {
        let c = Cosines { n_dot_l: 0.5, n_dot_v: 0.8, n_dot_h: 0.64, l_dot_h: 1.0, l_dot_v: 0.0 };
        let v = hand_fit(0.5, &c);
        // The digits kept by hand: 1e-10.
        assert!((v - 0.98650582966).abs() < 1e-10, "{v}");
    }

    /// The items of the committed slices, computed once for the tests that read them (seconds).
    fn committed_items() -> &'static [Item] {
        static ITEMS: std::sync::OnceLock<Vec<Item>> = std::sync::OnceLock::new();
        ITEMS.get_or_init(|| items(&Path::new(env!("CARGO_MANIFEST_DIR")).join("generated")))
    }

    /// The reference's rms standard error reported beside the gloss-0 items, re-measured from
    /// the committed JSON alone: sqrt of the mean of the squared standard errors of the
    /// gloss-0 layer's cells (slices[j·w + i][1]).
    #[test]
    fn the_gloss_0_reference_standard_error_is_re_measured() {
        let generated = Path::new(env!("CARGO_MANIFEST_DIR")).join("generated");
        let v: Value = serde_json::from_str(&std::fs::read_to_string(generated.join("json/ms_diffuse_slices.json")).unwrap()).unwrap();
        assert_eq!(v["gloss"][0].as_f64(), Some(0.0));
        let n = (v["axes"][0]["count"].as_u64().unwrap() * v["axes"][1]["count"].as_u64().unwrap()) as usize;
        let se: Vec<f64> = (0..n).map(|k| v["slices"][k][1].as_f64().unwrap()).collect();
        let want = (se.iter().map(|s| s * s).sum::<f64>() / n as f64).sqrt();
        // Not vacuous: the simulation's errors are neither 0 nor 1.
        assert!(want > 1e-6 && want < 0.1, "{want}");
        let it = committed_items().iter().find(|it| it.name.starts_with("ms-diffuse gloss-0 slice: published")).unwrap();
        let got = it.extra.iter().find(|(k, _)| k == "reference_rms_standard_error").unwrap().1;
        // The same squares summed in the same order: 1e-14 relative.
        assert!((got - want).abs() <= 1e-14 * want, "reported {got}, re-measured {want}");
    }

    /// The committed F0 = 0 slices (gloss 0 first) and their θh, θd cell counts.
    fn lambert_slices() -> (Value, usize, usize) {
        let generated = Path::new(env!("CARGO_MANIFEST_DIR")).join("generated");
        let v: Value = serde_json::from_str(&std::fs::read_to_string(generated.join("json/ms_diffuse_slices_lambert.json")).unwrap()).unwrap();
        assert_eq!(v["gloss"][0].as_f64(), Some(0.0));
        let (w, h) = (v["axes"][0]["count"].as_u64().unwrap() as usize, v["axes"][1]["count"].as_u64().unwrap() as usize);
        (v, w, h)
    }

    #[test]
    fn talk_rational_against_the_lambert_slice_times_0_9216_is_re_measured() {
        // The talk's F0 = 0.04 with a constant (1 − F0) at entry and exit scales the F0 = 0 walk
        // by (1 − 0.04)² = 0.9216. Re-measured here from the committed JSON alone: the gloss-0
        // layer's cells at θh = (i + ½)/w·π/2, θd = (j + ½)/h·π/2, where the rational's
        // arguments are n·h = cos θh and l·h = cos θd. 1e-12: the same f64 sums in another order.
        let (v, w, h) = lambert_slices();
        let mut want = 0.0f64;
        for j in 0..h {
            for i in 0..w {
                let (th, td) = ((i as f64 + 0.5) / w as f64 * FRAC_PI_2, (j as f64 + 0.5) / h as f64 * FRAC_PI_2);
                let cell = v["slices"][j * w + i][0].as_f64().unwrap();
                let published = PI * rational(&RATIONAL_NUM, &RATIONAL_DEN, th.cos(), td.cos());
                want = want.max((published - 0.9216 * cell).abs());
            }
        }
        let it = committed_items().iter().find(|it| it.name.starts_with("ms-diffuse gloss-0 slice")).unwrap();
        let got = it.extra.iter().find(|(k, _)| k == "max_abs_error_vs_f0_0_times_0.9216").unwrap().1;
        assert!((got - want).abs() <= 1e-12 * want, "reported {got}, re-measured {want}");
    }

    /// The slide's rational as transcribed follows the physics it was fitted to: on the
    /// committed F0 = 0 gloss-0 slice (an independent walk), π R over the cell has its median
    /// within 3 % of (1 − 0.04)² = 0.9216, the constant (1 − F0) at entry and exit the talk's
    /// simulation appears to use, and its quartiles within 10 %: a 15-coefficient rational fit
    /// to its own data errs by a few percent off the grazing peak. A sign or digit of the
    /// transcription wrong moves whole regions of the slice by tens of percent.
    #[test]
    fn the_transcribed_rational_follows_the_lambert_walk_times_0_9216() {
        let (v, w, h) = lambert_slices();
        let mut ratio: Vec<f64> = (0..w * h)
            .map(|k| {
                let (th, td) = (((k % w) as f64 + 0.5) / w as f64 * FRAC_PI_2, ((k / w) as f64 + 0.5) / h as f64 * FRAC_PI_2);
                PI * rational(&RATIONAL_NUM, &RATIONAL_DEN, th.cos(), td.cos()) / v["slices"][k][0].as_f64().unwrap()
            })
            .collect();
        ratio.sort_by(f64::total_cmp);
        let q = |f: f64| ratio[(f * ratio.len() as f64) as usize];
        assert!((q(0.5) / 0.9216 - 1.0).abs() < 0.03, "median {}", q(0.5));
        assert!((q(0.25) / 0.9216 - 1.0).abs() < 0.1 && (q(0.75) / 0.9216 - 1.0).abs() < 0.1, "quartiles {} {}", q(0.25), q(0.75));
    }

    #[test]
    fn burley_at_grazing_is_fd90() {
        // Burley 2012: f_d ∝ (1 + (F_D90 − 1)(1 − cos θl)⁵)(1 + (F_D90 − 1)(1 − cos θv)⁵), F_D90 =
        // ½ + 2 r cos² θd. At n·l = 0, n·v = 1 the product is F_D90 (and symmetric in l, v).
        let (r, lh) = (0.5, 0.6);
        let fd90 = 0.5 + 2.0 * r * lh * lh;
        for (nl, nv) in [(0.0, 1.0), (1.0, 0.0)] {
            let c = Cosines { n_dot_l: nl, n_dot_v: nv, n_dot_h: 0.8, l_dot_h: lh, l_dot_v: 0.0 };
            // A few ulps of the arithmetic.
            assert!((burley(r, &c) - fd90).abs() < 1e-15, "n·l {nl} n·v {nv}: {} vs {fd90}", burley(r, &c));
        }
        // Both grazing: F_D90².
        let c = Cosines { n_dot_l: 0.0, n_dot_v: 0.0, n_dot_h: 0.8, l_dot_h: lh, l_dot_v: 0.0 };
        assert!((burley(r, &c) - fd90 * fd90).abs() < 1e-15);
    }

    #[test]
    fn at_gloss_picks_every_point_of_that_gloss() {
        let c = Cosines::at(0.3, 0.2, 1.0).unwrap();
        let glosses = [0.0, 0.5, 0.0, 1.0, 0.5, 0.0];
        let s = Slices {
            points: glosses.iter().map(|&g| vec![g, 0.3, 0.2]).collect(),
            cosines: vec![c; glosses.len()],
            values: vec![1.0; glosses.len()],
            se: vec![0.0; glosses.len()],
            phi_d: 1.0,
            f0: 0.04,
        };
        assert_eq!(s.at_gloss(0.0), vec![0, 2, 5]);
        assert_eq!(s.at_gloss(0.5), vec![1, 4]);
        assert_eq!(s.at_gloss(1.0), vec![3]);
        assert_eq!(s.at_gloss(0.25), Vec::<usize>::new());
    }

    #[test]
    fn models_at_known_points() {
        // Closed-form values by hand at l = v = n (θh = θd = 0): cosines all 1.
        let c = Cosines::at(0.0, 0.0, FRAC_PI_2).unwrap();
        // Hand fit at g = 0: f0 = 1, f_b = 24.5·2^−8.9.
        assert!((hand_fit(0.0, &c) - (1.0 + 24.5 * (-8.9f64).exp2())).abs() < 1e-14);
        // Burley: both factors 1.
        assert!((burley(0.7, &c) - 1.0).abs() < 1e-15);
        // Hammon at α = 1: facing = 1, rough = 0.5·1.5 = 0.75, + π·0.1159.
        assert!((hammon(1.0, &c) - (0.75 + PI * 0.1159)).abs() < 1e-14);
        // Hammon off the normal, n·l = 0.5, n·v = 0.8, n·h = 0.9, l·v = 0.2 (a formula check: the
        // cosines need not come from one pair of directions). α = 0 leaves the smooth term,
        // 1.05·(1 − 0.5⁵)·(1 − 0.2⁵) = 1.05·0.96875·0.99968; at α = 0.5, facing = 0.6, rough =
        // 0.6·(0.9 − 0.24)·(1.4/0.9) = 0.396·1.4/0.9, halfway between, plus π·0.1159·0.5.
        let off = Cosines { n_dot_l: 0.5, n_dot_v: 0.8, n_dot_h: 0.9, l_dot_h: 0.95, l_dot_v: 0.2 };
        let smooth = 1.05 * 0.96875 * 0.99968;
        assert!((hammon(0.0, &off) - smooth).abs() < 1e-14);
        let rough = 0.396 * 1.4 / 0.9;
        assert!((hammon(0.5, &off) - (0.5 * (smooth + rough) + PI * 0.1159 * 0.5)).abs() < 1e-14);
        // EON at r = 0 is Lambert, up to its ε = 1e-7 floor of the multiple-scattering term.
        let c2 = Cosines::at(0.4, 0.6, 1.0).unwrap();
        assert!((eon(0.0, &c2) - 1.0).abs() < 2e-7);
        // The slide's rational at (1, 1): Σnum/Σden.
        let want = RATIONAL_NUM.iter().sum::<f64>() / RATIONAL_DEN.iter().sum::<f64>();
        assert!((rational(&RATIONAL_NUM, &RATIONAL_DEN, 1.0, 1.0) - want).abs() < 1e-15);
    }

    #[test]
    fn committed_rational_against_an_independent_walk() {
        // The committed gloss-dependent fit at points off its grids against the walk re-run with
        // another RNG key at 2^16 paths. Bound: the fit's max error on its verification grid
        // (0.19, the spec's header) with 30% for points between grid nodes, plus 4 standard
        // errors of this re-simulation.
        use super::super::integrals::{Order, brdf, directions};
        use super::super::walk::{Specular, Surface, key_of};
        let fit = CommittedRational::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("generated")).expect("generated/json/ms_diffuse_rational.json");
        for (c, (alpha, nh, lh)) in [(1.0, 0.55, 0.7), (0.3, 0.9, 0.45), (0.05, 0.65, 0.95), (0.01, 0.35, 0.3)].into_iter().enumerate() {
            let s = Surface { alpha, rho: 1.0, f0: TALK_F0, specular: Specular::Gone };
            let (l, v) = directions(f64::acos(nh), f64::acos(lh), FRAC_PI_2).unwrap();
            let e = brdf(&s, l, v, Order::All, key_of("ms-diffuse rational test"), c as u64, 1 << 16, true);
            let got = fit.eval(alpha, nh, lh);
            assert!((got - e.value).abs() <= 0.19 * 1.3 + 4.0 * e.error, "alpha {alpha} n.h {nh} l.h {lh}: fit {got}, walk {} ± {}", e.value, e.error);
        }
    }

    #[test]
    fn eon_conserves_energy_at_unit_albedo() {
        // ∫ f cos dω = 1 at ρ = 1 (EON's design): a 400 × 400 midpoint rule over the hemisphere
        // of v (error ≲ 1e-4 from the kink of s at s = 0 and the max in s/max(μi, μo)).
        for (r, mu) in [(0.3, 0.8), (1.0, 0.4), (0.7, 0.1)] {
            let l = [(1.0f64 - mu * mu).sqrt(), 0.0, mu];
            let n = 400;
            let mut sum = 0.0;
            for i in 0..n {
                let ct = (i as f64 + 0.5) / n as f64;
                let st = (1.0 - ct * ct).sqrt();
                for j in 0..n {
                    let p = (j as f64 + 0.5) / n as f64 * 2.0 * PI;
                    let v = [st * p.cos(), st * p.sin(), ct];
                    let c = Cosines { n_dot_l: mu, n_dot_v: ct, n_dot_h: 0.0, l_dot_h: 0.0, l_dot_v: l[0] * v[0] + l[2] * v[2] };
                    sum += eon(r, &c) / PI * ct;
                }
            }
            let albedo = sum * (1.0 / n as f64) * (2.0 * PI / n as f64);
            assert!((albedo - 1.0).abs() < 2e-3, "r {r} mu {mu}: {albedo}");
        }
    }

    /// A cell of a slices file: gloss, cosines, value, standard error.
    type Cell = (f64, Cosines, f64, f64);

    /// A committed slices file read here: its glosses, its F0 and every cell as (gloss, the
    /// cosines at the cell's centre θh = (i + ½)/w·π/2, θd = (j + ½)/h·π/2, value, standard
    /// error), layer by layer (`slices[(k·h + j)·w + i]`, the layout the file states).
    fn cells_of(name: &str) -> (Vec<f64>, f64, Vec<Cell>) {
        let generated = Path::new(env!("CARGO_MANIFEST_DIR")).join("generated");
        let v: Value = serde_json::from_str(&std::fs::read_to_string(generated.join(format!("json/{name}.json"))).unwrap()).unwrap();
        let gloss: Vec<f64> = serde_json::from_value(v["gloss"].clone()).unwrap();
        let (w, h) = (v["axes"][0]["count"].as_u64().unwrap() as usize, v["axes"][1]["count"].as_u64().unwrap() as usize);
        let phi = v["phi_d"].as_f64().unwrap();
        let mut cells = Vec::new();
        for (k, &g) in gloss.iter().enumerate() {
            for j in 0..h {
                for i in 0..w {
                    let (th, td) = ((i as f64 + 0.5) / w as f64 * FRAC_PI_2, (j as f64 + 0.5) / h as f64 * FRAC_PI_2);
                    let cell = &v["slices"][(k * h + j) * w + i];
                    cells.push((g, Cosines::at(th, td, phi).unwrap(), cell[0].as_f64().unwrap(), cell[1].as_f64().unwrap()));
                }
            }
        }
        (gloss, v["f0"].as_f64().unwrap(), cells)
    }

    fn max_rms(e: &[f64]) -> (f64, f64) {
        (e.iter().fold(0.0f64, |m, v| m.max(v.abs())), (e.iter().map(|v| v * v).sum::<f64>() / e.len() as f64).sqrt())
    }

    /// 1e-12 relative: the same sums of squares in another order.
    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * b.abs()
    }

    /// An item measured on `cells` (every layer): its max, rms and point count, each gloss
    /// layer's max and rms, and the reference's rms standard error, against `model(gloss,
    /// cosines)` counted here.
    fn assert_measured(it: &Item, gloss: &[f64], cells: &[Cell], model: impl Fn(f64, &Cosines) -> f64) {
        let e: Vec<f64> = cells.iter().map(|(g, c, v, _)| model(*g, c) - v).collect();
        let (max, rms) = max_rms(&e);
        assert_eq!((it.points, it.max_abs_error), (cells.len(), max), "{}", it.name);
        assert!(close(it.rms_error, rms), "{}", it.name);
        for &g in gloss {
            let layer: Vec<f64> = cells.iter().zip(&e).filter(|(c, _)| c.0 == g).map(|(_, e)| *e).collect();
            assert_eq!(layer.len(), cells.len() / gloss.len());
            let (m, r) = max_rms(&layer);
            assert_eq!(extra(it, &format!("gloss_{g}_max_abs_error")), m, "{} at gloss {g}", it.name);
            assert!(close(extra(it, &format!("gloss_{g}_rms_error")), r), "{} at gloss {g}", it.name);
        }
        let se: Vec<f64> = cells.iter().map(|c| c.3).collect();
        assert!(close(extra(it, "reference_rms_standard_error"), max_rms(&se).1), "{}", it.name);
    }

    /// The validator's items restated from the committed files alone: the hand fit, Burley's and
    /// Hammon's diffuse on every F0 = 0.04 layer and EON on every F0 = 0 one (max, rms, each
    /// layer's, the reference's standard error); the gloss-dependent rational on the cells its
    /// domain covers (n·h and l·h at or above its axes' lower end, as many as its finding says),
    /// the hand fit on the same cells and the rms error in standard errors; the gloss-0 rational's
    /// π R(1, 1) = π ΣN/ΣD (every monomial is 1 there), its ratio's median and quartiles to the
    /// F0 = 0 walk and its refit's ratios, each to its printed digits.
    #[test]
    fn items_restate_the_slices_measures() {
        let items = committed_items();
        let item = |prefix: &str| items.iter().find(|i| i.name.starts_with(prefix)).unwrap_or_else(|| panic!("no item {prefix}"));
        let (gloss, f0, cells) = cells_of("ms_diffuse_slices");
        let (lgloss, lf0, lcells) = cells_of("ms_diffuse_slices_lambert");
        assert_eq!((f0, lf0), (TALK_F0, 0.0));
        assert_measured(item("ms-diffuse slices: shipped hand fit"), &gloss, &cells, hand_fit);
        assert_measured(item("ms-diffuse slices: Burley 2012"), &gloss, &cells, |g, c| burley(alpha_from_gloss(g).sqrt(), c));
        assert_measured(item("ms-diffuse slices: Hammon 2017"), &gloss, &cells, |g, c| hammon(alpha_from_gloss(g), c));
        let eon_item = item("ms-diffuse slices (F0 = 0): EON");
        assert_measured(eon_item, &lgloss, &lcells, |g, c| eon(alpha_from_gloss(g), c));
        assert!(eon_item.findings.iter().any(|f| f.ends_with(&format!("; F0 = {lf0} in the reference."))));

        // The gloss-dependent rational on the cells of its domain.
        let generated = Path::new(env!("CARGO_MANIFEST_DIR")).join("generated");
        let spec: Value = serde_json::from_str(&std::fs::read_to_string(generated.join("json/ms_diffuse_rational.json")).unwrap()).unwrap();
        let floor = spec["axes"][1]["range"][0].as_f64().unwrap().max(spec["axes"][2]["range"][0].as_f64().unwrap());
        let covered: Vec<_> = cells.iter().copied().filter(|c| c.1.n_dot_h >= floor && c.1.l_dot_h >= floor).collect();
        assert!(!covered.is_empty() && covered.len() < cells.len(), "the floor {floor} leaves some cells out");
        let fit = CommittedRational::load(&generated).unwrap();
        let rational_item = item("ms-diffuse slices: shadefit gloss-dependent rational");
        assert_measured(rational_item, &gloss, &covered, |g, c| fit.eval(alpha_from_gloss(g), c.n_dot_h, c.l_dot_h));
        let hand: Vec<f64> = covered.iter().map(|(g, c, v, _)| hand_fit(*g, c) - v).collect();
        let (hm, hr) = max_rms(&hand);
        assert_eq!(extra(rational_item, "hand_fit_max_abs_error_same_cells"), hm);
        assert!(close(extra(rational_item, "hand_fit_rms_error_same_cells"), hr));
        let z: Vec<f64> = covered.iter().map(|(g, c, v, se)| (fit.eval(alpha_from_gloss(*g), c.n_dot_h, c.l_dot_h) - v) / se).collect();
        assert!(close(extra(rational_item, "rms_error_over_standard_error"), max_rms(&z).1));
        let text = rational_item.findings.iter().find(|f| f.starts_with("On the same")).unwrap();
        assert_eq!(number_after(text, "On the same "), covered.len() as f64, "{text}");

        // The published rational on the gloss-0 layer.
        let it = item("ms-diffuse gloss-0 slice: published");
        let g0: Vec<_> = cells.iter().filter(|c| c.0 == 0.0).collect();
        let r = |c: &Cosines| PI * rational(&RATIONAL_NUM, &RATIONAL_DEN, c.n_dot_h, c.l_dot_h);
        let (max, rms) = max_rms(&g0.iter().map(|(_, c, v, _)| r(c) - v).collect::<Vec<f64>>());
        assert_eq!((it.points, it.max_abs_error), (g0.len(), max));
        assert!(close(it.rms_error, rms));
        let at_one = PI * RATIONAL_NUM.iter().sum::<f64>() / RATIONAL_DEN.iter().sum::<f64>();
        let f = &it.findings[0];
        assert!((number_after(f, "π R(1, 1) = ") - at_one).abs() <= 5e-4, "{f} against {at_one}");
        let mut ratio: Vec<f64> = lcells.iter().filter(|c| c.0 == 0.0).map(|(_, c, v, _)| r(c) / v).collect();
        ratio.sort_by(f64::total_cmp);
        let n = ratio.len();
        let f = it.findings.iter().find(|f| f.contains("has median")).unwrap();
        assert!((number_after(f, "has median ") - ratio[n / 2]).abs() <= 5e-4, "{f}");
        assert!((number_after(f, "(quartiles ") - ratio[n / 4]).abs() <= 5e-4, "{f}");
        assert!((number_after(f, &format!("{:.3}, ", ratio[n / 4])) - ratio[3 * n / 4]).abs() <= 5e-4, "{f}");
        let f = it.findings.iter().find(|f| f.starts_with("Refitted")).unwrap();
        let (rm, rr) = (extra(it, "refit_max_abs_error"), extra(it, "refit_rms_error"));
        assert!(rm < max && rr < rms, "a least-squares refit of the same form does better: {rm} {rr}");
        let tail = &f[f.find("max ").unwrap()..];
        assert!((number_after(tail, "max ") - rm).abs() <= 5e-4 * rm && (number_after(tail, " (") - rm / max).abs() <= 5e-3, "{f}");
        let tail = &f[f.find(", rms ").unwrap()..];
        assert!((number_after(tail, ", rms ") - rr).abs() <= 5e-4 * rr && (number_after(tail, " (") - rr / rms).abs() <= 5e-3, "{f}");
    }

    /// The shipped hand fit where l·h ≠ 1, so that f₀'s Schlick-like term and f_b's factor l·h
    /// both count (the points above have l·h = 1): g = 0.5, l·h = 0.5, n·l = 0.5, n·v = 0.8,
    /// n·h = 0.64, by hand from the talk's formula: f0 = 0.5 + 0.5⁵ = 0.53125; f1 = 0.976328125
    /// as above; t = 0.6, f_d = 0.53125 + 0.6·0.445078125 = 0.798296875; f_b = 3.625·0.5·2^−12.32
    /// = 3.5447733e-4. Total 0.79865135233.
    #[test]
    fn hand_fit_where_l_dot_h_is_not_one() {
        let c = Cosines { n_dot_l: 0.5, n_dot_v: 0.8, n_dot_h: 0.64, l_dot_h: 0.5, l_dot_v: 0.0 };
        let v = hand_fit(0.5, &c);
        // The digits kept by hand: 1e-10.
        assert!((v - 0.79865135233).abs() < 1e-10, "{v}");
    }

    /// The cosines of a slice point against the half/difference frame's closed forms: v is l
    /// mirrored about h (v = 2(l·h)h − l), so l·v = 2cos²θd − 1 = cos 2θd whatever θh and φd, and
    /// l + v = 2cos θd h gives n·l + n·v = 2 cos θd cos θh; n·h = cos θh, l·h = cos θd. At φd off
    /// 0, π/2 and π and θh > 0 every product in l·v is non-zero and n·l ≠ n·v.
    #[test]
    fn cosines_follow_the_half_and_difference_frame() {
        for (th, td, pd) in [(0.3, 0.5, 1.0), (0.7, 0.2, 2.5), (0.5, 0.6, 0.4), (0.2, 0.9, 2.0)] {
            let c = Cosines::at(th, td, pd).expect("above the horizon");
            // A few roundings of unit vectors' products: 1e-14.
            assert!((c.l_dot_v - (2.0 * td).cos()).abs() < 1e-14, "θh {th} θd {td} φd {pd}: l·v {} vs {}", c.l_dot_v, (2.0 * td).cos());
            assert!((c.n_dot_l + c.n_dot_v - 2.0 * td.cos() * th.cos()).abs() < 1e-14, "θh {th} θd {td} φd {pd}: {c:?}");
            assert!((c.n_dot_l - c.n_dot_v).abs() > 1e-3, "θh {th} θd {td} φd {pd}: {c:?}");
            assert_eq!((c.n_dot_h, c.l_dot_h), (th.cos(), td.cos()));
        }
    }

    /// ∫₀^{π/2} f by Simpson's rule on `n` panels of each of [0, split] and [split, π/2].
    fn simpson_split(split: f64, n: usize, f: impl Fn(f64) -> f64) -> f64 {
        let piece = |a: f64, b: f64| {
            let h = (b - a) / n as f64;
            (0..=n).map(|i| f(a + i as f64 * h) * if i == 0 || i == n { 1.0 } else if i % 2 == 1 { 4.0 } else { 2.0 }).sum::<f64>() * h / 3.0
        };
        piece(0.0, split) + piece(split, FRAC_PI_2)
    }

    /// EON's single-scattering lobe (Portsmouth, Kutz & Hill 2025) at ρ = 1: π f_ss = A (1 + r
    /// s/t), s = l·v − μi μo, t = max(μi, μo) where s > 0 and 1 elsewhere, A = 1/(1 + (½ −
    /// 2/(3π)) r). Its albedo by the test's own quadrature: s = sin θi sin θo cos φ, so over φ
    /// the lobe integrates to 2π + 2 r sin θi sin θo (1/max(μi, μo) − 1), and E(μi) = A [1 +
    /// (2 r sin θi/π) ∫₀^{π/2} sin²θ cos θ (1/max(μi, cos θ) − 1) dθ], the integrand smooth on
    /// each side of θ = θi (Simpson, 400 panels each: error ~1e-13).
    fn lobe_albedo(mu: f64, r: f64) -> f64 {
        let a = 1.0 / (1.0 + (0.5 - 2.0 / (3.0 * PI)) * r);
        let ti = mu.acos();
        let inner = simpson_split(ti, 400, |t| t.sin().powi(2) * t.cos() * (1.0 / mu.max(t.cos()) - 1.0));
        a * (1.0 + 2.0 * r * ti.sin() / PI * inner)
    }

    /// EON's lobe albedo E_FON(μ), its closed form in `e_fon` against the test's quadrature of
    /// the lobe; and EON itself at ρ = 1 as the lobe plus the energy it loses, A (1 + r s/t) +
    /// (1 − E(μo))(1 − E(μi))/(1 − Ē), with Ē = 2∫₀¹ E(μ) μ dμ also by quadrature (the
    /// multiple-scattering albedo ρ_ms is 1 at ρ = 1). Light and view off each other's plane
    /// both ways (s > 0 and s < 0) and μi ≠ μo. Bound 1e-9: the quadratures' ~1e-12, divided by
    /// 1 − Ē ≥ 0.05 at these r.
    #[test]
    fn eon_is_its_lobe_plus_the_energy_the_lobe_loses() {
        for r in [0.3, 0.7, 1.0] {
            for mu in [0.1, 0.4, 0.8, 1.0] {
                let (got, want) = (e_fon(mu, r), lobe_albedo(mu, r));
                assert!((got - want).abs() <= 1e-10, "r {r} μ {mu}: E_FON {got} vs {want}");
            }
            let avg = 2.0 * simpson_split(std::f64::consts::FRAC_PI_4, 100, |t| lobe_albedo(t.cos(), r) * t.cos() * t.sin());
            assert!(1.0 - avg >= 0.05, "r {r}: Ē {avg}");
            for (mi, mo, cos_phi) in [(0.8f64, 0.3f64, 0.6), (0.3, 0.8, -0.5), (0.5, 0.9, 0.2), (0.9, 0.2, -0.9)] {
                let (si, so) = ((1.0 - mi * mi).sqrt(), (1.0 - mo * mo).sqrt());
                let s = si * so * cos_phi;
                let c = Cosines { n_dot_l: mi, n_dot_v: mo, n_dot_h: 0.0, l_dot_h: 0.0, l_dot_v: s + mi * mo };
                let t = if s > 0.0 { mi.max(mo) } else { 1.0 };
                let a = 1.0 / (1.0 + (0.5 - 2.0 / (3.0 * PI)) * r);
                let want = a * (1.0 + r * s / t) + (1.0 - lobe_albedo(mo, r)) * (1.0 - lobe_albedo(mi, r)) / (1.0 - avg);
                assert!((eon(r, &c) - want).abs() <= 1e-9, "r {r} μi {mi} μo {mo} cos φ {cos_phi}: {} vs {want}", eon(r, &c));
            }
        }
    }

    /// The committed rational as `CommittedRational` evaluates it (f64 arithmetic on the JSON's
    /// f32 coefficients, inputs clamped to the axes, the result to the model's clamp) against the
    /// emitted Rust function of the runtime crate, a separate rendering of the same
    /// coefficients in f32: inside the axes and past them (α and n·h below their lower ends,
    /// which both clamp). Bound 1e-4: f32 rounding of 23 terms of size ≤ 4 (≲ 1e-5 in P and
    /// Q) over Q, which these points keep away from its lower bound 0.0033.
    #[test]
    fn the_committed_rational_evaluates_as_the_emitted_code() {
        use shadefit_runtime::ms_diffuse_rational::ms_diffuse_rational as emitted;
        let fit = CommittedRational::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("generated")).expect("generated/json/ms_diffuse_rational.json");
        for (alpha, nh, lh) in [(0.5, 0.7, 0.6), (0.05, 0.9, 0.3), (1.0, 0.4, 0.95), (0.2, 0.05, 0.5), (0.001, 0.5, 0.8), (0.8, 1.0, 1.0)] {
            let (got, want) = (fit.eval(alpha, nh, lh), emitted(alpha as f32, nh as f32, lh as f32) as f64);
            assert!(want > 0.1 && (got - want).abs() <= 1e-4, "α {alpha} n·h {nh} l·h {lh}: {got} vs the emitted {want}");
        }
    }
}
