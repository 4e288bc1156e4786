//! The glTF Sample Viewer's shipped sheen albedo table, `lut_sheen_E.png`, measured as a table.
//!
//! The file (`assets/published/gltf-sample-viewer/`, Apache-2.0, with its provenance) is a
//! 1024 × 1024 16-bit RGB PNG with R = G = B. The Sample Renderer
//! (KhronosGroup/glTF-Sample-Renderer `source/ResourceLoader/resource_loader.js`,
//! `_loadEnvironmentFromPanorama`) loads it as a *linear* 2-D texture (`gltfTextureInfo(…, 0,
//! true)`) and its shader reads `texture(u_SheenELUT, vec2(NdotV, sheenRoughness)).r` for
//! KHR_materials_sheen's albedo scaling, so texel (x, y) stands for (n·v, r) = ((x + ½)/1024,
//! (y + ½)/1024) with the file's first row at r ≈ 0, and α = r² (the extension's convention).
//! Its lut_ggx and lut_charlie are made at load time by the IBL sampler (the Charlie one is
//! [`super::lut`]'s second item); this is the one LUT the viewer ships as a file.

use super::QUANTITIES;
use crate::validate::Item;
use rayon::prelude::*;

/// The file, embedded so that `validate` needs nothing outside the binary.
const PNG: &[u8] = include_bytes!("../../../assets/published/gltf-sample-viewer/lut_sheen_E.png");
const SIZE: usize = 1024;
/// Every STRIDE-th texel on each axis is measured (64² texels; the table is smooth at that
/// spacing, and the rows that are not are what the findings are about).
const STRIDE: usize = 16;
/// Integrator tolerance of the reference: below a tenth of the 16-bit steps (1.5e-5), the
/// least error reported here.
const TOL: f64 = 1e-7;

/// The red channel as stored, u16 / 65535, rows from the file's first; or why it is not the
/// expected image.
pub fn stored() -> Result<Vec<f64>, String> {
    let mut dec = png::Decoder::new(std::io::Cursor::new(PNG));
    dec.set_transformations(png::Transformations::IDENTITY);
    let mut reader = dec.read_info().map_err(|e| format!("lut_sheen_E.png: {e}"))?;
    let info = reader.info();
    if (info.width as usize, info.height as usize, info.color_type, info.bit_depth)
        != (SIZE, SIZE, png::ColorType::Rgb, png::BitDepth::Sixteen)
    {
        return Err(format!("lut_sheen_E.png is {}×{} {:?} {:?}, not 1024² 16-bit RGB", info.width, info.height, info.color_type, info.bit_depth));
    }
    let mut buf = vec![0; reader.output_buffer_size().ok_or("lut_sheen_E.png: no buffer size")?];
    reader.next_frame(&mut buf).map_err(|e| format!("lut_sheen_E.png: {e}"))?;
    // Big-endian u16 R, G, B per texel.
    Ok(buf.chunks_exact(6).map(|p| u16::from_be_bytes([p[0], p[1]]) as f64 / 65535.0).collect())
}

/// The sRGB transfer function's inverse (IEC 61966-2-1), the encoding the file's iCCP chunk
/// declares.
pub fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

fn e_ek(nov: f64, alpha: f64) -> f64 {
    let q = QUANTITIES.iter().find(|q| q.name == "sheen-albedo-ek").expect("a sheen quantity");
    (q.eval)(&[alpha, nov], TOL).value
}

fn centre(k: usize) -> f64 {
    (k as f64 + 0.5) / SIZE as f64
}

pub fn item() -> Item {
    let name = "glTF Sample Viewer lut_sheen_E.png (1024² RGB16, read as a linear texture)";
    let source = "KhronosGroup/glTF-Sample-Viewer assets/images/lut_sheen_E.png (as vendored, see assets/published/gltf-sample-viewer/SOURCE.md); \
                  read by glTF-Sample-Renderer source/ResourceLoader/resource_loader.js";
    let table = match stored() {
        Ok(t) => t,
        Err(why) => {
            let mut item = Item::measured(name, source, "not read", &[], &[], &[]);
            item.findings.push(why);
            return item;
        }
    };
    let ks: Vec<usize> = (STRIDE / 2..SIZE).step_by(STRIDE).collect();
    let cells: Vec<(usize, usize)> = ks.iter().flat_map(|&y| ks.iter().map(move |&x| (x, y))).collect();
    let albedo: Vec<f64> = cells.par_iter().map(|&(x, y)| e_ek(centre(x), centre(y) * centre(y))).collect();
    // A UNORM texel holds [0, 1]; E under Estevez–Kulla's Λ exceeds 1 for smooth sheen at
    // grazing views (the curve's G is not bounded by the exact one), so the table is measured
    // against min(1, E), as the IBL sampler's saturated LUT is.
    let truth: Vec<f64> = albedo.iter().map(|&e| e.min(1.0)).collect();
    let e_max = albedo.iter().cloned().fold(0.0, f64::max);
    let pts: Vec<Vec<f64>> = cells.iter().map(|&(x, y)| vec![centre(y), centre(x)]).collect();
    let raw: Vec<f64> = cells.iter().map(|&(x, y)| table[y * SIZE + x]).collect();
    let decoded: Vec<f64> = raw.iter().map(|&c| srgb_to_linear(c)).collect();
    let mut item = Item::measured(
        name,
        source,
        &format!("{}² texel centres (every {STRIDE}th texel of 1024²): (r, n·v), α = r², against min(1, E) under Estevez–Kulla's Λ (KHR_materials_sheen)", ks.len()),
        &pts,
        &truth,
        &raw,
    );
    // The decoded table, over the rows above and below the roughness where its rows stop changing.
    let split = |lo: f64, hi: f64| -> (f64, f64, Vec<f64>) {
        let idx: Vec<usize> = (0..pts.len()).filter(|&i| pts[i][0] >= lo && pts[i][0] < hi).collect();
        let p: Vec<Vec<f64>> = idx.iter().map(|&i| pts[i].clone()).collect();
        let t: Vec<f64> = idx.iter().map(|&i| truth[i]).collect();
        let d: Vec<f64> = idx.iter().map(|&i| decoded[i]).collect();
        crate::validate::measure(&p, &t, &d)
    };
    let (m_dec, rms_dec, _) = crate::validate::measure(&pts, &truth, &decoded);
    let brighter = raw.iter().zip(&decoded).map(|(r, d)| r - d).fold(0.0, f64::max);
    let (m_hi, rms_hi, at_hi) = split(0.4, 2.0);
    let (m_lo, _, at_lo) = split(0.0, 0.3);
    item.extra.push(("max_abs_error_srgb_decoded".into(), m_dec));
    item.extra.push(("rms_error_srgb_decoded".into(), rms_dec));
    item.extra.push(("max_abs_error_srgb_decoded_r_ge_0.4".into(), m_hi));
    item.extra.push(("max_abs_error_srgb_decoded_r_lt_0.3".into(), m_lo));
    // How flat the rows below r = 0.3 are: the decoded table's largest change down a column
    // there, against the integral's.
    let column_range = |v: &[f64]| -> f64 {
        ks.iter()
            .enumerate()
            .map(|(xi, _)| {
                let col: Vec<f64> = (0..ks.len()).filter(|&yi| centre(ks[yi]) < 0.25).map(|yi| v[yi * ks.len() + xi]).collect();
                col.iter().cloned().fold(f64::NEG_INFINITY, f64::max) - col.iter().cloned().fold(f64::INFINITY, f64::min)
            })
            .fold(0.0, f64::max)
    };
    let (flat_table, flat_truth) = (column_range(&decoded), column_range(&truth));
    item.extra.push(("decoded_column_range_r_lt_0.25".into(), flat_table));
    // shadefit's equivalent in the same layout and format (16-bit UNORM, linear).
    let (m_ours, rms_ours) = super::lut::same_layout_unorm(&mut item, &pts, &truth, 65535.0);
    item.findings = vec![
        format!(
            "As the Sample Renderer samples it (the stored numbers as linear values) against min(1, E) (E itself reaches {e_max:.2} at the \
             smoothest grazing texel): max {:.3e}, rms {:.3e} — not E. The file's iCCP \
             chunk declares sRGB, and its numbers are close to E's sRGB encoding: decoded, max {m_dec:.3e}, rms {rms_dec:.3e}; for r ≥ 0.4 \
             max {m_hi:.3e} at (r, n·v) = ({:.3}, {:.3}), rms {rms_hi:.3e}. So a linear read of this file brightens E (by up to \
             {brighter:.3}) and darkens the layer under the sheen by up to that much times max3(sheenColor).",
            item.max_abs_error,
            item.rms_error,
            at_hi[0],
            at_hi[1],
        ),
        format!(
            "Below r ≈ 0.3 the rows stop following E: decoded, each column changes by at most {flat_table:.3e} over r < 0.25 where E \
             changes by up to {flat_truth:.3e}; max {m_lo:.3e} at (r, n·v) = ({:.3}, {:.3}). The rows there hold about E at r ≈ 0.27–0.29, \
             as if the table's generator (not published) clamped the roughness; no single r fits every column.",
            at_lo[0], at_lo[1]
        ),
        format!(
            "shadefit's table in the same layout and format (the integral at the same texel centres, 16-bit UNORM, linear): max {m_ours:.3e}, \
             rms {rms_ours:.3e} — the format's rounding only."
        ),
    ];
    item
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The decoder reads the embedded file as its header says (1024², only R is used), and
    /// three stored numbers are those of an independent reading of the same file (Python's
    /// zlib and the PNG filters written out by hand, printed to 5 digits: hence 1e-5).
    #[test]
    fn the_embedded_png_decodes_to_its_published_numbers() {
        let t = stored().unwrap();
        assert_eq!(t.len(), SIZE * SIZE);
        assert!((t[0] - 0.92378).abs() < 1e-5, "{}", t[0]);
        assert!((t[896] - 0.04692).abs() < 1e-5, "{}", t[896]);
        assert!((t[1023 * SIZE + 1023] - 0.44625).abs() < 1e-5, "{}", t[1023 * SIZE + 1023]);
    }

    /// The sRGB decoding's two pieces meet at 0.04045 (to 1e-7, the standard's rounded
    /// constants) and map 1 to 1.
    #[test]
    fn srgb_decoding_is_the_standards() {
        assert!((srgb_to_linear(0.04045) - 0.04045 / 12.92).abs() < 1e-7);
        assert!((srgb_to_linear(0.040451) - srgb_to_linear(0.04045)).abs() < 1e-6);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-15);
    }
}
