//! Two shipped sheen lookup tables regenerated with their own estimators (the formulas, not
//! the code, reproduced from the files named) and measured as tables against E of the lobe
//! their renderer shades with:
//!
//! - **Filament's DFG blue channel** (google/filament `libs/ibl/src/CubemapIBL.cpp`,
//!   `DFV_Charlie_Uniform` as `CubemapIBL::DFG` calls it with `cloth`):
//!   ```text
//!   texel (x, y) of an h × h image: coord = saturate((h − y + 0.5)/h), α = coord², NoV = (x + 0.5)/h
//!   for i < 4096: u = (i/N, radical_inverse₂(i)); H uniform on the hemisphere (φ = 2π u.x, cos θ = 1 − u.y)
//!     L = 2 (V·H) H − V; if N·L > 0: r += V_Ashikhmin(NoV, NoL) · D_Charlie(NoH, α) · NoL · VoH
//!   E = r · 8π/N                                  (uniform pdf 1/2π; 4 VoH from the Jacobian)
//!   ```
//!   stored RGB16F with GL's row flip, so GL row j holds roughness min((j + 1.5)/h, 1) and the
//!   shader reads it at (j + 0.5)/h: one texel off, as the split-sum channels beside it.
//! - **The glTF IBL Sampler's Charlie LUT** (KhronosGroup/glTF-IBL-Sampler
//!   `lib/source/shaders/filter.frag`, `LUT` with `cCharlie`; the Sample Viewer's
//!   `lut_charlie.png` is such an output): texel (x, y) at (NoV, r) = ((x + 0.5)/n, (y + 0.5)/n),
//!   1024 Hammersley points, H **importance-sampled** from D·cos θh at α = r² (sin θ = ξ^(α/(2α + 1))),
//!   but weighted as if uniform: C += V·D·NoL·VoH, E = 8π C/N, with D_Charlie at α = **r**
//!   (not r²) and V_Ashikhmin clamped to [0, 1], stored RGBA8 UNORM (saturated, 1/255 steps).

use super::QUANTITIES;
use crate::validate::Item;
use std::path::Path;
use rayon::prelude::*;
use std::f64::consts::PI;

/// The Hammersley point i of n: (i/n, radical inverse of i in base 2).
pub fn hammersley(i: u32, n: u32) -> (f64, f64) {
    (i as f64 / n as f64, i.reverse_bits() as f64 * (0.5 / 2147483648.0))
}

/// D_Charlie at n·h (both sources: (2 + 1/α) (1 − NoH²)^(1/(2α)) / 2π).
fn d_charlie(noh: f64, alpha: f64) -> f64 {
    crate::shading::charlie::d_charlie(alpha, (1.0 - noh * noh).max(0.0).sqrt())
}

fn v_ashikhmin(nov: f64, nol: f64) -> f64 {
    1.0 / (4.0 * (nol + nov - nol * nov))
}

/// The reflection of V about H and the cosines (NoL, NoH, VoH), saturated as both sources do.
fn reflect(nov: f64, h: [f64; 3]) -> (f64, f64, f64) {
    let v = [(1.0 - nov * nov).sqrt(), 0.0, nov];
    let voh = v[0] * h[0] + v[2] * h[2];
    let l_z = 2.0 * voh * h[2] - v[2];
    (l_z.clamp(0.0, 1.0), h[2].clamp(0.0, 1.0), voh.clamp(0.0, 1.0))
}

/// Filament's `DFV_Charlie_Uniform(NoV, α, n)` (in f64).
pub fn filament_dfv_charlie(nov: f64, alpha: f64, n: u32) -> f64 {
    let mut r = 0.0;
    for i in 0..n {
        let (ux, uy) = hammersley(i, n);
        let (phi, ct) = (2.0 * PI * ux, 1.0 - uy);
        let st = (1.0 - ct * ct).sqrt();
        let (nol, noh, voh) = reflect(nov, [st * phi.cos(), st * phi.sin(), ct]);
        if nol > 0.0 {
            r += v_ashikhmin(nov, nol) * d_charlie(noh, alpha) * nol * voh;
        }
    }
    r * (8.0 * PI / n as f64)
}

/// The IBL Sampler's Charlie `LUT(NoV, r)` blue channel before storage (in f64); `consistent`
/// weighs each importance sample by its own pdf instead (4 V NoL VoH/NoH), the estimator of E
/// at α = r² the sampling is made for.
pub fn ibl_sampler_charlie(nov: f64, r: f64, n: u32, consistent: bool) -> f64 {
    let alpha_s = r * r;
    let mut c = 0.0;
    for i in 0..n {
        let (ux, uy) = hammersley(i, n);
        let st = uy.powf(alpha_s / (2.0 * alpha_s + 1.0));
        let ct = (1.0 - st * st).sqrt();
        let phi = 2.0 * PI * ux;
        let (nol, noh, voh) = reflect(nov, [st * phi.cos(), st * phi.sin(), ct]);
        if nol > 0.0 {
            c += if consistent {
                4.0 * v_ashikhmin(nov, nol) * nol * voh / noh
            } else {
                v_ashikhmin(nov, nol).clamp(0.0, 1.0) * d_charlie(noh, r.max(1e-6)) * nol * voh * 8.0 * PI
            };
        }
    }
    c / n as f64
}

/// `v` stored as a UNORM texel of `max` + 1 levels (saturated, rounded to the nearest step).
pub fn unorm(v: f64, max: f64) -> f64 {
    (v.clamp(0.0, 1.0) * max).round() / max
}

/// shadefit's table in a shipped table's layout and UNORM format: `truth` (in [0, 1], the
/// integral at the same texel centres) stored with `max` + 1 levels, whose error is the format's
/// rounding only; recorded as the item's refit, and returned as (max, rms).
pub fn same_layout_unorm(item: &mut Item, pts: &[Vec<f64>], truth: &[f64], max: f64) -> (f64, f64) {
    let ours: Vec<f64> = truth.iter().map(|&e| unorm(e, max)).collect();
    let (m, rms, _) = crate::validate::measure(pts, truth, &ours);
    item.extra.push(("refit_max_abs_error".into(), m));
    item.extra.push(("refit_rms_error".into(), rms));
    (m, rms)
}

/// Filament's size (desktop 128²; 64² on mobile) and sample count.
pub const FILAMENT_SIZE: usize = 128;
pub const FILAMENT_SAMPLES: u32 = 4096;
/// The IBL Sampler's default sample count, and the LUT size measured here (its LUT is the
/// cube map's side, 256–1024 for the Sample Viewer's environments: the estimator's bias, not
/// its resolution, is what this measures).
pub const SAMPLER_SAMPLES: u32 = 1024;
pub const SAMPLER_SIZE: usize = 64;

/// Integrator tolerance of the tables' references: far below their Monte Carlo noise.
const TOL: f64 = 1e-7;

/// The least roughness measured: the least α of E under Ashikhmin's V (1e-6) at α = r².
fn r_min() -> f64 {
    super::ALPHA_WIDE.min.sqrt()
}

/// The first row of an n-row table whose texel centre (j + 0.5)/n is at least [`r_min`].
fn first_row(n: usize) -> usize {
    (0..n).find(|&j| (j as f64 + 0.5) / n as f64 >= r_min()).unwrap_or(n)
}

fn e_ashikhmin(nov: f64, alpha: f64) -> f64 {
    let q = QUANTITIES.iter().find(|q| q.name == "sheen-albedo-ashikhmin").expect("a sheen quantity");
    (q.eval)(&[alpha, nov], TOL).value
}

/// GL row j of an h-row Filament table holds roughness min((j + 1.5)/h, 1).
pub fn filament_row_roughness(j: usize, h: usize) -> f64 {
    ((j as f64 + 1.5) / h as f64).min(1.0)
}

pub fn items(generated: &Path) -> Vec<Item> {
    vec![filament_item(generated), sampler_item()]
}

/// The committed `sheen_dfg_filament` table's values (its JSON; storage order, n·v fastest).
fn committed_table(generated: &Path) -> Result<Vec<f64>, String> {
    let path = generated.join("json").join(format!("{}.json", TABLE));
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let json: serde_json::Value = serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    let values: Vec<f64> = json["values"].as_array().map(|v| v.iter().filter_map(|x| x.as_f64()).collect()).unwrap_or_default();
    if values.len() == FILAMENT_SIZE * FILAMENT_SIZE { Ok(values) } else { Err(format!("{} holds {} values, not {FILAMENT_SIZE}²", path.display(), values.len())) }
}

/// shadefit's table in Filament's layout (`fits/sheen_dfg_filament.toml`).
const TABLE: &str = "sheen_dfg_filament";

fn filament_item(generated: &Path) -> Item {
    let n = FILAMENT_SIZE;
    let first = first_row(n);
    let rows: Vec<(Vec<f64>, f64, f64, f64)> = (first * n..n * n)
        .into_par_iter()
        .map(|k| {
            let (i, j) = (k % n, k / n);
            let nov = (i as f64 + 0.5) / n as f64;
            let r_own = filament_row_roughness(j, n);
            let texel = half::f16::from_f64(filament_dfv_charlie(nov, r_own * r_own, FILAMENT_SAMPLES)).to_f64();
            let r_read = (j as f64 + 0.5) / n as f64;
            (vec![r_read, nov], texel, e_ashikhmin(nov, r_own * r_own), e_ashikhmin(nov, r_read * r_read))
        })
        .collect();
    let pts: Vec<Vec<f64>> = rows.iter().map(|r| r.0.clone()).collect();
    let texels: Vec<f64> = rows.iter().map(|r| r.1).collect();
    let own: Vec<f64> = rows.iter().map(|r| r.2).collect();
    let read: Vec<f64> = rows.iter().map(|r| r.3).collect();
    let mut item = Item::measured(
        "Filament DFG blue channel (cmgen, DFV_Charlie_Uniform, 128², 4096 samples, RGB16F)",
        "google/filament libs/ibl/src/CubemapIBL.cpp (DFV_Charlie_Uniform, CubemapIBL::DFG with cloth); regenerated here from its formulas",
        &format!("{n}² texels from row {first} (r ≥ {:.3}: the integrals' least α) as the shader reads them: (r, n·v) at texel centres, α = r²", r_min()),
        &pts,
        &read,
        &texels,
    );
    let (m_own, rms_own, at_own) = crate::validate::measure(&pts, &own, &texels);
    item.extra.push(("max_abs_error_at_stored_roughness".into(), m_own));
    item.extra.push(("rms_error_at_stored_roughness".into(), rms_own));
    let grazing = texels.iter().fold(0.0f64, |m, v| m.max(*v));
    let same_layout = match committed_table(generated) {
        Ok(table) => {
            // The committed table's texels (f16, as its R16Float texture) at the same points.
            let ours: Vec<f64> = (first * n..n * n).map(|k| half::f16::from_f64(table[k]).to_f64()).collect();
            let (m, rms, _) = crate::validate::measure(&pts, &read, &ours);
            item.extra.push(("refit_max_abs_error".into(), m));
            item.extra.push(("refit_rms_error".into(), rms));
            format!(
                "shadefit's table in the same layout (fits/{TABLE}.toml: the integral at the texel centres the shader reads, R16Float): \
                 max {m:.3e} ({:.3}× Filament's), rms {rms:.3e} at the same texels — f16 rounding only.",
                m / item.max_abs_error
            )
        }
        Err(why) => format!("shadefit's table in the same layout is not committed here: {why}."),
    };
    item.findings = vec![
        format!(
            "Each texel against E of Filament's cloth lobe (Charlie D × Ashikhmin V, α = r²) at the roughness it was computed for \
             (row j holds (j + 1.5)/128): max {m_own:.3e} at (r, n·v) = ({:.3}, {:.3}), rms {rms_own:.3e} — uniform hemisphere \
             samples miss the narrow Charlie peak of smooth cloth at grazing views.",
            (at_own[0] + 1.0 / n as f64).min(1.0),
            at_own[1]
        ),
        format!(
            "As the shader samples it (row j at (j + 0.5)/128, one texel off as the split-sum channels): max {:.3e}, rms {:.3e}. The \
             channel is not saturated: it reaches {grazing:.2} at the smoothest grazing texel (Filament's sheenScaling = \
             1 − max3(sheenColor)·dfg.z then goes negative there).",
            item.max_abs_error, item.rms_error
        ),
        same_layout,
    ];
    item
}

fn sampler_item() -> Item {
    let n = SAMPLER_SIZE;
    let first = first_row(n);
    let rows: Vec<(Vec<f64>, [f64; 4])> = (first * n..n * n)
        .into_par_iter()
        .map(|k| {
            let (i, j) = (k % n, k / n);
            let (nov, r) = ((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
            let raw = ibl_sampler_charlie(nov, r, SAMPLER_SAMPLES, false);
            let stored = unorm(raw, 255.0);
            let converged = ibl_sampler_charlie(nov, r, 16 * SAMPLER_SAMPLES, false);
            let consistent = ibl_sampler_charlie(nov, r, SAMPLER_SAMPLES, true);
            (vec![r, nov], [stored, converged, consistent, e_ashikhmin(nov, r * r)])
        })
        .collect();
    let pts: Vec<Vec<f64>> = rows.iter().map(|r| r.0.clone()).collect();
    let col = |c: usize| -> Vec<f64> { rows.iter().map(|r| r.1[c]).collect() };
    let (stored, converged, consistent, truth) = (col(0), col(1), col(2), col(3));
    let truth_sat: Vec<f64> = truth.iter().map(|e| e.min(1.0)).collect();
    let mut item = Item::measured(
        "glTF IBL Sampler Charlie LUT (lut_charlie blue channel, 1024 samples, RGBA8)",
        "KhronosGroup/glTF-IBL-Sampler lib/source/shaders/filter.frag (LUT, cCharlie; 08fa122); regenerated here from its formulas",
        &format!("{n}² texel centres (r, n·v) from row {first} (r ≥ {:.3}: the integrals' least α), α = r²", r_min()),
        &pts,
        &truth_sat,
        &stored,
    );
    let m = |v: &[f64], t: &[f64]| crate::validate::measure(&pts, t, v).0;
    let (m_conv, m_cons) = (m(&converged, &truth), m(&consistent, &truth));
    item.extra.push(("max_abs_error_16384_samples".into(), m_conv));
    item.extra.push(("max_abs_error_consistent_weight".into(), m_cons));
    // shadefit's table in the same layout and format (RGBA8 UNORM).
    let (m_ours, rms_ours) = same_layout_unorm(&mut item, &pts, &truth_sat, 255.0);
    item.findings = vec![
        format!(
            "Against min(1, E) of Charlie D × Ashikhmin V at α = r² (the lobe whose V the LUT uses, and glTF's α): max {:.3e}, rms {:.3e}. \
             With 16× the samples the unsaturated estimate is still {m_conv:.3e} off: the error is a bias, not noise.",
            item.max_abs_error, item.rms_error
        ),
        format!(
            "Why: H is drawn from D·cos θh at α = r², but each sample is weighted as a uniform one (8π V D NoL VoH), so the estimate is \
             the integral weighted by an extra 2π D cos θh; and the D it weighs with takes α = r, not r². Weighting each sample by its own \
             pdf (4 V NoL VoH/NoH) gives E within {m_cons:.3e} at the same 1024 samples."
        ),
        format!(
            "shadefit's table in the same layout and format (min(1, E) at the same texel centres, RGBA8 UNORM): max {m_ours:.3e}, \
             rms {rms_ours:.3e} — the 1/255 steps only."
        ),
        "The glTF Sample Renderer makes its Charlie LUT at load time with its own port of this sampler (it reads no lut_charlie.png); \
         the one sheen LUT it ships as a file, lut_sheen_E.png, is the next item."
            .into(),
    ];
    item
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One Hammersley point, u = (0, 0): Filament's H = n (cos θ = 1), so L is V's mirror,
    /// NoL = VoH = NoV, NoH = 1 and D(1) = 0 (sin θh = 0): the estimate is 0; two points add
    /// u = (½, ½): φ = π, cos θ = ½, H = (−√3/2, 0, ½), written out here (at n·v = 0.6 it
    /// reflects V below the horizon and counts nothing). 1e-12: a few operations in another
    /// order.
    #[test]
    fn filament_estimates_of_one_and_two_points_are_their_samples_by_hand() {
        assert_eq!(filament_dfv_charlie(0.6, 0.5, 1), 0.0);
        let (nov, a) = (0.6f64, 0.5f64);
        let (vx, vz) = ((1.0 - nov * nov).sqrt(), nov);
        let (hx, hz) = (-(3.0f64).sqrt() / 2.0, 0.5);
        let voh = vx * hx + vz * hz;
        let nol = 2.0 * voh * hz - vz;
        let want = if nol > 0.0 && voh > 0.0 {
            let d = (2.0 + 1.0 / a) * (1.0 - hz * hz).powf(0.5 / a) / (2.0 * PI);
            d / (4.0 * (nol + nov - nol * nov)) * nol * voh * 8.0 * PI / 2.0
        } else {
            0.0
        };
        assert!((filament_dfv_charlie(nov, a, 2) - want).abs() < 1e-12);
    }

    /// The consistent importance-sampled estimator converges to E (a 1e-3 band: 1024 points
    /// of a smooth integrand at α = 0.25, n·v = 0.5), and the sampler's own weighting does
    /// not (its bias is far above that band).
    #[test]
    fn the_samplers_weighting_is_biased_and_the_consistent_one_is_not() {
        let e = e_ashikhmin(0.5, 0.25);
        let consistent = ibl_sampler_charlie(0.5, 0.5, 1024, true);
        let as_shipped = ibl_sampler_charlie(0.5, 0.5, 16384, false);
        assert!((consistent - e).abs() < 1e-3, "{consistent} vs {e}");
        assert!((as_shipped - e).abs() > 1e-2, "{as_shipped} vs {e}");
    }

    /// Filament's uniform estimator converges to E at a rough texel (α = 0.5: a broad lobe;
    /// 4096 points to 2e-3).
    #[test]
    fn filaments_estimator_converges_to_the_albedo() {
        let e = e_ashikhmin(0.5, 0.5);
        let f = filament_dfv_charlie(0.5, 0.5, 4096);
        assert!((f - e).abs() < 2e-3, "{f} vs {e}");
    }
}
