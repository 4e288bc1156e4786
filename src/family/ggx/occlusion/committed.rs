//! The committed cone LUTs read as a shader reads them: the stored f16 texels, trilinear, at the
//! row coordinate of the table's roughness mapping.

use super::{cone_of_visibility, lut};
use std::path::Path;

/// The row coordinate of a committed cone LUT at α (its mapping inverted; gloss clamped to
/// [0, 1], where α below the smoothest row reads the smoothest row, as a sampler would).
pub fn row_of_alpha(row: &str, alpha: f64) -> f64 {
    match row {
        "gloss" => crate::shading::roughness::gloss_from_alpha(alpha).clamp(0.0, 1.0),
        "alpha" => alpha,
        _ => alpha.sqrt(),
    }
}

/// COD: WWII's 3-D table as a shader reads it: the stored f16 texels, trilinear (exact
/// weights), (scale, bias) at (n·v, α, cos θc).
pub struct LutReader {
    pub(super) lut: lut::plot::Committed,
    stored: Vec<[f64; 2]>,
}

impl LutReader {
    pub fn new(lut: lut::plot::Committed) -> LutReader {
        let f16 = |x: f64| half::f16::from_f32(x as f32).to_f32() as f64;
        // The stored channels rounded as the texture holds them, decoded back to (scale, bias).
        let filament = lut.layout == "filament";
        let stored = lut
            .values
            .iter()
            .map(|&[s, b]| if filament { [f16(s + b) - f16(b), f16(b)] } else { [f16(s), f16(b)] })
            .collect();
        LutReader { lut, stored }
    }

    pub fn name(&self) -> &str {
        &self.lut.name
    }

    /// (scale, bias) over the cone cos θc.
    pub fn scale_bias(&self, n_dot_v: f64, alpha: f64, cos_cone: f64) -> [f64; 2] {
        let l = &self.lut;
        lut::build::trilinear(&self.stored, (l.width, l.height, l.depth), n_dot_v, row_of_alpha(&l.row, alpha), cos_cone)
    }

    /// SO = (F0·scale_c + bias_c)/(F0·scale_0 + bias_0), both read from the table.
    pub fn so(&self, n_dot_v: f64, alpha: f64, v: f64, f0: f64) -> f64 {
        let [s0, b0] = self.scale_bias(n_dot_v, alpha, 0.0);
        let [sc, bc] = self.scale_bias(n_dot_v, alpha, cone_of_visibility(v));
        let den = f0 * s0 + b0;
        if den > 0.0 { (f0 * sc + bc) / den } else { 0.0 }
    }
}

/// The committed cone LUTs as shaders read them.
pub fn lut_readers(generated: &Path) -> Vec<LutReader> {
    lut::plot::committed(generated).unwrap_or_default().into_iter().map(LutReader::new).collect()
}

#[cfg(test)]
mod tests {
    use super::super::{EnvEstimate, F0, Shadowing, integrals, so_ratio};
    use super::*;

    /// The row mapping a committed cone LUT names by its row argument.
    fn row_mapping(l: &lut::plot::Committed) -> crate::family::ggx::lut::spec::RoughnessMapping {
        use crate::family::ggx::lut::spec::RoughnessMapping as M;
        [M::Perceptual, M::Alpha, M::Gloss].into_iter().find(|m| m.argument() == l.row).unwrap()
    }

    /// The readers are the committed cone LUTs, one for each spec of that kind in fits/
    /// (read here from the TOML files), and each reads back the hemisphere integral at its
    /// texel centres on slice 0 (cos θc = 0): `env` recomputed at 1e-9 against the stored f16
    /// texel; bound: f16's half ulp (2⁻¹¹ relative) plus the build's tolerance (1e-7) and
    /// the recomputation's.
    #[test]
    fn lut_readers_read_every_committed_cone_lut_back() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut specs: Vec<String> = std::fs::read_dir(root.join("fits"))
            .unwrap()
            .filter_map(|e| {
                let text = std::fs::read_to_string(e.ok()?.path()).ok()?;
                let t: toml::Table = text.parse().ok()?;
                (t.get("kind")?.as_str()? == "ggx-cone-lut").then(|| t["name"].as_str().unwrap().to_string())
            })
            .collect();
        specs.sort();
        let readers = lut_readers(&root.join("generated"));
        assert!(!specs.is_empty());
        assert_eq!(readers.iter().map(|r| r.name().to_string()).collect::<Vec<_>>(), specs);
        for reader in &readers {
            let l = &reader.lut;
            let mapping = row_mapping(l);
            for (i, j) in [(0, 0), (5, 17), (16, 3), (31, 31), (20, 28)] {
                let (u, t) = ((i as f64 + 0.5) / l.width as f64, (j as f64 + 0.5) / l.height as f64);
                let alpha = mapping.alpha(t);
                let got = reader.scale_bias(u, alpha, 0.0);
                let want = integrals::env(alpha, u, 0.0, Shadowing::HeightCorrelated, 1e-9);
                for (g, w) in got.iter().zip([want.scale, want.bias]) {
                    assert!((g - w).abs() <= w.abs() * 2f64.powi(-11) + 1e-7 + 1e-9, "{} texel ({i}, {j}): {got:?} vs {want:?}", reader.name());
                }
            }
        }
    }

    #[test]
    fn row_of_alpha_inverts_each_row_mapping() {
        // The cone LUT rows: α itself, r = √α, and gloss with α = alpha_from_gloss(g), so
        // alpha_from_gloss(row) must give α back (1e-12: the gloss inverse's round trip,
        // measured 1.1e-13 worst in gloss::integrals' tests).
        assert_eq!(row_of_alpha("alpha", 0.3), 0.3);
        assert_eq!(row_of_alpha("roughness", 0.25), 0.5);
        let g = row_of_alpha("gloss", 0.3);
        let back = crate::shading::roughness::alpha_from_gloss(g);
        assert!((0.0..=1.0).contains(&g) && (back - 0.3).abs() < 1e-12, "g={g} back={back}");
    }

    /// Where the unoccluded split sum is 0 the occlusion is 0 (the doc of `so_ratio`), not
    /// 0/0: from the integrals' estimates and from a table whose texels are all 0.
    #[test]
    fn occlusion_is_zero_where_the_unoccluded_sum_vanishes() {
        let zero = EnvEstimate { scale: 0.0, bias: 0.0, error: 0.0, evals: 0 };
        assert_eq!(so_ratio(&zero, &zero, F0), 0.0);
        let lut = lut::plot::Committed {
            name: "zero".into(),
            width: 2,
            height: 2,
            depth: 2,
            row: "alpha".into(),
            layout: "scale-bias".into(),
            values: vec![[0.0; 2]; 8],
            error_map: vec![0.0; 8],
        };
        let reader = LutReader::new(lut);
        assert_eq!(reader.so(0.5, 0.25, 0.5, F0), 0.0);
    }

    /// A committed table read as SO: at a texel centre (n·v, α row) on slice k (cos θc = k/(d − 1),
    /// V = 1 − cos²θc) the reader's SO is the cone model's (the integrals at 1e-9), for F0 = 4 % and
    /// F = 1. Bound: each stored channel is within 2⁻¹¹ relative of the integral (f16) plus the
    /// build's 1e-7; the filament layout derives the scale from two f16 values, so the numerator
    /// N and denominator D are each within 3·2⁻¹¹ of themselves plus 4e-7, and SO = N/D within
    /// (δN + SO·δD)/D. Slice 0 is the hemisphere itself: SO = 1 exactly.
    #[test]
    fn lut_readers_give_the_cone_models_occlusion_at_texel_centres() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let readers = lut_readers(&root.join("generated"));
        assert!(!readers.is_empty());
        for reader in &readers {
            let l = &reader.lut;
            let mapping = row_mapping(l);
            for (i, j, k) in [(5, 17, 0), (16, 3, 1), (20, 28, l.depth / 2), (9, 12, l.depth - 2), (30, 20, 2)] {
                let (u, alpha) = ((i as f64 + 0.5) / l.width as f64, mapping.alpha((j as f64 + 0.5) / l.height as f64));
                let c = k as f64 / (l.depth - 1) as f64;
                let v = 1.0 - c * c;
                for f0 in [F0, 1.0] {
                    let got = reader.so(u, alpha, v, f0);
                    if k == 0 {
                        assert_eq!(got, 1.0, "{} ({i}, {j}, {k})", reader.name());
                        continue;
                    }
                    let full = integrals::env(alpha, u, 0.0, Shadowing::HeightCorrelated, 1e-9);
                    let cone = integrals::env(alpha, u, c, Shadowing::HeightCorrelated, 1e-9);
                    let (n, d) = (f0 * cone.scale + cone.bias, f0 * full.scale + full.bias);
                    let want = n / d;
                    let bound = (3.0 * 2f64.powi(-11) * (n + want * d) + 4e-7 * (1.0 + want)) / d;
                    assert!((got - want).abs() <= bound, "{} ({i}, {j}, {k}) F0 {f0}: {got} vs {want} (bound {bound:.2e})", reader.name());
                }
            }
        }
    }
}
