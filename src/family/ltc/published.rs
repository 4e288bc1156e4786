//! ltc_code's published GGX tables (Heitz, Dupuy, Hill, Neubelt 2016; the tables three.js,
//! EEVEE, Godot, Unreal, Babylon and bevy ship), vendored in `assets/published/ltc_code`
//! (SOURCE.md: origin, hashes, licence, layout), measured against the lobe they fit: per cell
//! the distance δ of the normalised lobes (`super::fit`), the LTC's mass below the horizon, and
//! the magnitude and Fresnel texels against the split-sum integrals — beside shadefit's refit
//! of the same cells (δ minimised from ltc_code's own matrix, so never worse in δ).

use super::fit::{Cell, FIT_NODES, cell_parameters, fit_cell};
use super::transform::Ltc;
use crate::shading::trowbridge_reitz::{Ggx, Shadowing};
use crate::validate::Item;
use std::path::Path;

/// The table side.
pub const SIZE: usize = 64;
/// ltc_code's least α (`MIN_ALPHA`).
pub const MIN_ALPHA: f64 = 1e-5;

static LTC_1: &[u8] = include_bytes!("../../../assets/published/ltc_code/ltc_1.dds");
static LTC_2: &[u8] = include_bytes!("../../../assets/published/ltc_code/ltc_2.dds");

/// The texels of a 64 × 64 RGBA16F DDS as ltc_code writes it (see SOURCE.md), row-major.
pub fn read_dds(bytes: &[u8]) -> Result<Vec<[f64; 4]>, String> {
    let u32_at = |o: usize| u32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]);
    if bytes.len() < 128 || &bytes[0..4] != b"DDS " || u32_at(4) != 124 {
        return Err("not a DDS file".into());
    }
    let (height, width, fourcc) = (u32_at(12) as usize, u32_at(16) as usize, u32_at(84));
    if fourcc != 113 || (width, height) != (SIZE, SIZE) || bytes.len() != 128 + 8 * SIZE * SIZE {
        return Err(format!("expected 64x64 FourCC 113 (RGBA16F), got {width}x{height} FourCC {fourcc}"));
    }
    Ok(bytes[128..]
        .chunks(8)
        .map(|t| std::array::from_fn(|c| half::f16::from_le_bytes([t[2 * c], t[2 * c + 1]]).to_f64()))
        .collect())
}

/// ltc_code's (ltc_1, ltc_2) texels.
pub fn tables() -> (Vec<[f64; 4]>, Vec<[f64; 4]>) {
    (read_dds(LTC_1).expect("the vendored ltc_1.dds"), read_dds(LTC_2).expect("the vendored ltc_2.dds"))
}

/// The GGX lobe ltc_code fits (`fit/brdf_ggx.h`: D·G2/(4 μv) with height-correlated Smith G2).
pub fn ggx(alpha: f64) -> Ggx {
    Ggx::new(alpha, Shadowing::HeightCorrelated)
}

/// One audited cell.
#[derive(Debug, Clone, Copy)]
pub struct Audited {
    pub i: usize,
    pub j: usize,
    /// δ of ltc_code's LTC and of the refit (at 2 × [`FIT_NODES`]).
    pub published: f64,
    pub refit: f64,
    /// |δ(n) − δ(2n)| of the published δ: the quadrature's error estimate.
    pub published_error: f64,
    pub published_below: f64,
    pub refit_below: f64,
    pub magnitude: f64,
    pub fresnel: f64,
    pub published_magnitude: f64,
    pub published_fresnel: f64,
}

/// The audit of the cells (i, j) with i, j multiples of `step` and the last row and column.
pub fn audit(step: usize) -> Vec<Audited> {
    use rayon::prelude::*;
    let (t1, t2) = tables();
    let mut picks: Vec<usize> = (0..SIZE).step_by(step).collect();
    if picks.last() != Some(&(SIZE - 1)) {
        picks.push(SIZE - 1);
    }
    let cells: Vec<(usize, usize)> = picks.iter().flat_map(|&j| picks.iter().map(move |&i| (i, j))).collect();
    cells
        .par_iter()
        .map(|&(i, j)| {
            let k = i + SIZE * j;
            let (alpha, theta) = cell_parameters(i, j, SIZE, MIN_ALPHA);
            let lobe = ggx(alpha);
            let published = Ltc::from_texel(t1[k]);
            let cell = Cell::new(&lobe, theta, FIT_NODES);
            let (refit, _) = fit_cell(&cell, published, j == 0);
            let fine = Cell::new(&lobe, theta, 2 * FIT_NODES);
            let (p, r) = (fine.distance(&published), fine.distance(&refit));
            Audited {
                i,
                j,
                published: p,
                refit: r.min(p),
                published_error: (p - cell.distance(&published)).abs(),
                published_below: published.mass_below_horizon(),
                refit_below: if r < p { refit.mass_below_horizon() } else { published.mass_below_horizon() },
                magnitude: fine.magnitude,
                fresnel: fine.fresnel,
                published_magnitude: t2[k][0],
                published_fresnel: t2[k][1],
            }
        })
        .collect()
}

/// Cells audited per axis: every [`AUDIT_STEP`]th and the last (17 × 17).
pub const AUDIT_STEP: usize = 4;

/// The validate items (see the module doc).
pub fn items(_generated: &Path) -> Vec<Item> {
    let cells = audit(AUDIT_STEP);
    let (_, t2) = tables();
    let points: Vec<Vec<f64>> = cells.iter().map(|c| vec![c.i as f64 / (SIZE - 1) as f64, c.j as f64 / (SIZE - 1) as f64]).collect();
    let zero = vec![0.0; cells.len()];
    let source = "selfshadow/ltc_code fit/results/ltc_1.dds, ltc_2.dds (assets/published/ltc_code)";
    let domain = "roughness r = i/63, sqrt(1 - cos theta) = j/63, every 4th cell and the last (17 x 17 of 64 x 64)";
    let tv: Vec<f64> = cells.iter().map(|c| 0.5 * c.published).collect();
    let mut lobe = Item::measured("ltc_code GGX LTC: total variation to the lobe (worst light's relative error)", source, domain, &points, &zero, &tv);
    let refit_tv: Vec<f64> = cells.iter().map(|c| 0.5 * c.refit).collect();
    let (m, r, _) = crate::validate::measure(&points, &zero, &refit_tv);
    let better = cells.iter().filter(|c| c.refit < c.published).count();
    let below: Vec<f64> = cells.iter().map(|c| c.published_below).collect();
    let refit_below: Vec<f64> = cells.iter().map(|c| c.refit_below).collect();
    let max = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
    let quadrature = cells.iter().map(|c| 0.5 * c.published_error).fold(0.0, f64::max);
    lobe.extra.extend([
        ("refit_max_abs_error".to_string(), m),
        ("refit_rms_error".to_string(), r),
        ("cells_refit_closer".to_string(), better as f64),
        ("mass_below_horizon_max".to_string(), max(&below)),
        ("refit_mass_below_horizon_max".to_string(), max(&refit_below)),
        ("quadrature_error_estimate".to_string(), quadrature),
    ]);
    lobe.findings.push(format!(
        "the total variation between ltc_code's LTC and the GGX lobe it fits is up to {:.3} (rms {:.3}): a light shaped to the difference is off by that share of the lobe's energy; \
         refitted by deterministic quadrature of the L1 distance from the same start, {better} of {} cells come closer (max {m:.3}, rms {r:.3})",
        lobe.max_abs_error,
        lobe.rms_error,
        cells.len()
    ));
    let truth: Vec<f64> = cells.iter().map(|c| c.magnitude).collect();
    let got: Vec<f64> = cells.iter().map(|c| c.published_magnitude).collect();
    let mag = Item::measured("ltc_code magnitude (ltc_2.x) vs GGX E(mu)", source, domain, &points, &truth, &got);
    let truth: Vec<f64> = cells.iter().map(|c| c.fresnel).collect();
    let got: Vec<f64> = cells.iter().map(|c| c.published_fresnel).collect();
    let fres = Item::measured("ltc_code Fresnel term (ltc_2.y) vs GGX int f cos (1 - v.h)^5", source, domain, &points, &truth, &got);
    // ltc_2.w against the closed form of the clipped sphere form factor at every texel node.
    let w = super::sphere::table(SIZE);
    let points: Vec<Vec<f64>> = (0..SIZE * SIZE).map(|k| vec![(k % SIZE) as f64 / (SIZE - 1) as f64, (k / SIZE) as f64 / (SIZE - 1) as f64]).collect();
    let got: Vec<f64> = t2.iter().map(|t| t[3]).collect();
    let mut sphere = Item::measured(
        "ltc_code horizon-clipped sphere form factor (ltc_2.w) vs Snyder's closed form",
        source,
        "x = cos(omega)/2 + 1/2 = i/63, y = sin^2(sigma) = j/63, every texel",
        &points,
        &w,
        &got,
    );
    sphere.extra.push(("ltc_2_z_max_abs".to_string(), t2.iter().map(|t| t[2].abs()).fold(0.0, f64::max)));
    vec![lobe, mag, fres, sphere]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The vendored files decode as ltc_code's layout says: at normal incidence (j = 0) every
    /// ltc_1 texel is isotropic (1, 0, 0, m) with m rising with roughness to ≈ 1, and the
    /// magnitude at roughness 1, normal incidence is GGX's E there within its f16 rounding and
    /// ltc_code's 32² estimate (0.02: their midpoint rule's error, not a bound of ours).
    #[test]
    fn the_vendored_tables_decode_in_ltc_code_s_layout() {
        let (t1, t2) = tables();
        assert_eq!(t1.len(), 64 * 64);
        for i in 0..SIZE {
            let t = t1[i];
            assert!(t[0] == 1.0 && t[1] == 0.0 && t[2] == 0.0, "texel {i}: {t:?}");
        }
        assert!(t1[SIZE - 1][3] > 0.9 && t1[1][3] < 0.01, "{:?} {:?}", t1[SIZE - 1], t1[1]);
        let e = crate::shading::hemisphere::albedo(&ggx(1.0), 1.0, 1e-10).value;
        assert!((t2[SIZE - 1][0] - e).abs() < 0.02, "{} vs {e}", t2[SIZE - 1][0]);
        assert!(read_dds(&LTC_1[..100]).is_err());
    }
}

#[cfg(test)]
mod report {
    /// `cargo test --release --lib ltc_audit_cells -- --ignored --nocapture`: every audited
    /// cell's δ/2 (published, refit), mass below the horizon and quadrature estimate.
    #[test]
    #[ignore]
    fn ltc_audit_cells() {
        for c in super::audit(super::AUDIT_STEP) {
            println!(
                "i {:2} j {:2}  tv {:.4} refit {:.4}  below {:.4} refit {:.4}  est {:.1e}  E {:.4} vs {:.4}",
                c.i, c.j, 0.5 * c.published, 0.5 * c.refit, c.published_below, c.refit_below, 0.5 * c.published_error, c.magnitude, c.published_magnitude
            );
        }
    }
}
