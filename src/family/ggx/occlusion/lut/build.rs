//! The build of a cone LUT spec (`kind = "ggx-cone-lut"`, see `super::spec`): tabulate, verify,
//! emit.
//!
//! - tabulate: slice k is the 2-D DFG table of the spec's resolution and mapping at
//!   cos θc = k/(slices − 1), by the 2-D table's own [`tabulate`] (so slice 0 is that table);
//! - verify: the integral at the centres of a grid [`VERIFY_DENSITY`] times denser on every axis
//!   (off the texel grid everywhere: n·v and the row parameter between the texel centres and past
//!   the outer ones, cos θc between the slices) to [`VERIFY_TOLERANCE`], against the texture as a
//!   linear sampler reads it: the f16 texels interpolated trilinearly with exact weights (the
//!   hardware-filtering error of the stored table). Recorded as for the 2-D table: max, rms,
//!   worst point [n·v, row, cos θc] of the texture, of the emitted f32 lookup and of the f64
//!   texels (interpolation alone), the same between the outer texel centres, the f16 rounding,
//!   and the map of the largest texture error per texel footprint and slice interval;
//! - emit: `wgsl/NAME.wgsl`, `src/NAME.rs` (`super::emit`), `data/NAME.ktx2` (3-D, RG16F or
//!   RGBA16F), `data/NAME.png` (sRGB preview: the slices left to right, cos θc = 0 first; R, G
//!   as stored, B = 0; row 0 at the top) and `json/NAME.json`.
//!
//! `Mode::Committed` (build --check) takes the texels and the measured errors from the
//! committed JSON and re-renders every file without integrating.

use crate::spec::Preset;
use super::emit::{ConeLutCode, lookup_f32};
use super::spec::ConeLut;
use crate::emit::texture::{ktx2_volume, png_srgb_preview};
use crate::emit::interp::{centred, multilinear};
use crate::emit::{GENERATOR, header_lines};
use crate::family::ggx::lut::build::{Accumulator, Measure, lut_built, Quadrature, alpha_of_t, digits3, f16_texture, mapping_doc, sample, stored};
use crate::pipeline::GridAxis;
use crate::pipeline::{BuildError, Built, Mode, committed_texels, compact_json, fmt_err, spec_rel_path};
use crate::spec::Spec;
use serde::{Deserialize, Serialize};
use serde_json::{Value, json};
use std::path::Path;

/// Verification points per texel footprint (n·v, row) and per slice interval.
pub const VERIFY_DENSITY: usize = 2;
/// Quadrature tolerance of the verification integrals (as the 2-D table's): far below the
/// interpolation errors measured (≳ 1e-3 at the worst points).
pub const VERIFY_TOLERANCE: f64 = 1e-6;

/// The texels (scale, bias), slice after slice (each row-major, n·v fastest), with the
/// quadrature work of all slices.
pub fn tabulate(lut: &ConeLut) -> (Vec<[f64; 2]>, Quadrature) {
    let b = &lut.base;
    let est = sample(b, vec![axis(lut, 0).arguments(), axis(lut, 1).arguments(), axis(lut, 2).arguments()], b.tolerance);
    // The work per texel of each slice, rounded, then their mean (the 2-D table's figure per slice).
    let evals: f64 = est.chunks(b.width * b.height).map(|s| (s.iter().map(|e| e.evals).sum::<u64>() as f64 / s.len() as f64).round()).sum();
    let max_err = est.iter().map(|e| e.error).fold(0.0f64, f64::max);
    let q = Quadrature { tolerance: b.tolerance, max_error_estimate: max_err, evals_per_texel: (evals / lut.depth as f64).round() };
    (est.iter().map(|e| [e.scale, e.bias]).collect(), q)
}

/// Axis `k` of the table's grid (n·v, rows, cone slices).
fn axis(lut: &ConeLut, k: usize) -> GridAxis {
    lut.grid().axes.swap_remove(k)
}

/// Trilinear interpolation in f64 of `texels` at (u, t) (texel centres, clamp to edge) and
/// cone cosine c (slices at k/(d − 1)), exact weights.
pub fn trilinear(texels: &[[f64; 2]], (w, h, d): (usize, usize, usize), u: f64, t: f64, c: f64) -> [f64; 2] {
    // The slices sit at k/(d − 1); at c = 1 the last slice alone (weight 0 on nothing past it).
    let z = c.clamp(0.0, 1.0) * (d - 1) as f64;
    let k0 = (z.floor() as usize).min(d - 1);
    let slices = ((k0 + 1).min(d - 1), z - z.floor());
    multilinear(texels, &[w, h, d], &[centred(u.clamp(0.0, 1.0), w), centred(t.clamp(0.0, 1.0), h), (k0, slices.0, slices.1)])
}

/// What the verification measured (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Measured {
    pub density: usize,
    pub points: usize,
    pub reference_tolerance: f64,
    pub reference_max_error_estimate: f64,
    /// The f16 texture, trilinear with exact weights (the storage error under filtering).
    pub texture: Measure,
    /// The same between the outer texel centres of n·v and the rows only.
    pub texture_interior: Measure,
    /// The emitted f32 lookup over the f16 texels.
    pub lookup_f32: Measure,
    /// The f64 texels, trilinear (interpolation alone).
    pub interpolation: Measure,
    /// Largest |f16(texel) − texel| over texels and channels (rounding alone).
    pub max_abs_storage_error: f64,
    /// Largest texture error per texel footprint and slice interval: index
    /// (k·height + j)·width + i for slice interval k (between slices k and k + 1), 3 digits.
    pub error_map: Vec<f64>,
}

/// The verification of the texels `values` (see the module docs).
pub fn verify(lut: &ConeLut, values: &[[f64; 2]]) -> Result<Measured, BuildError> {
    let b = &lut.base;
    let (w, h, d) = (b.width, b.height, lut.depth);
    let n = VERIFY_DENSITY;
    let grid = lut.grid();
    let (us, ts, cs) = (grid.axes[0].cell_centres(n * w), grid.axes[1].cell_centres(n * h), grid.axes[2].cell_centres(n * (d - 1)));
    let all = sample(b, vec![us.clone(), ts.clone(), cs.clone()], VERIFY_TOLERANCE);
    let stored32 = stored(b, values);
    let stored64: Vec<[f64; 2]> = stored32.iter().map(|v| v.map(f64::from)).collect();
    let encoded: Vec<[f64; 2]> = values.iter().map(|v| b.layout.encode(*v)).collect();
    let (mut tex, mut inner, mut l32, mut interp) = (Accumulator::new(), Accumulator::new(), Accumulator::new(), Accumulator::new());
    let (mut inner_count, mut ref_err) = (0, 0.0f64);
    let inside = |p: f64, n: usize| p >= 0.5 / n as f64 && p <= 1.0 - 0.5 / n as f64;
    let mut map = vec![0.0f64; w * h * (d - 1)];
    for (m, &c) in cs.iter().enumerate() {
        let truth = &all[m * us.len() * ts.len()..(m + 1) * us.len() * ts.len()];
        for (l, &t) in ts.iter().enumerate() {
            for (k, &u) in us.iter().enumerate() {
                let e = &truth[l * us.len() + k];
                if !(e.scale.is_finite() && e.bias.is_finite()) {
                    return Err(BuildError::NonFinite { spec: b.name.clone(), at: vec![u, t, c] });
                }
                ref_err = ref_err.max(e.error);
                let want = b.layout.encode([e.scale, e.bias]);
                let at = [u, t, c];
                let got = trilinear(&stored64, (w, h, d), u, t, c);
                let err = tex.add(got, want, &at);
                if inside(u, w) && inside(t, h) {
                    inner.add(got, want, &at);
                    inner_count += 1;
                }
                let cell = &mut map[((m / n) * h + l / n) * w + k / n];
                *cell = cell.max(err);
                l32.add(lookup_f32(&stored32, (w, h, d), u as f32, t as f32, c as f32).map(f64::from), want, &at);
                interp.add(trilinear(&encoded, (w, h, d), u, t, c), want, &at);
            }
        }
    }
    let points = us.len() * ts.len() * cs.len();
    let storage = encoded.iter().zip(&stored64).flat_map(|(a, s)| (0..2).map(move |c| (a[c] - s[c]).abs())).fold(0.0, f64::max);
    Ok(Measured {
        density: n,
        points,
        reference_tolerance: VERIFY_TOLERANCE,
        reference_max_error_estimate: ref_err,
        texture: tex.finish(points),
        texture_interior: inner.finish(inner_count.max(1)),
        lookup_f32: l32.finish(points),
        interpolation: interp.finish(points),
        max_abs_storage_error: storage,
        error_map: map.into_iter().map(digits3).collect(),
    })
}

fn committed_parts(v: &Value, lut: &ConeLut) -> Result<(Vec<[f64; 2]>, Quadrature, Measured), BuildError> {
    let b = &lut.base;
    let bad = |why: String| BuildError::NoCommitted { spec: b.name.clone(), why };
    let values = committed_texels::<2>(v, &b.name, b.width * b.height * lut.depth, "[scale, bias]")?;
    let quadrature: Quadrature = serde_json::from_value(v["quadrature"].clone()).map_err(|e| bad(format!("quadrature: {e}")))?;
    let measured: Measured = serde_json::from_value(v["verification"].clone()).map_err(|e| bad(format!("verification: {e}")))?;
    if measured.error_map.len() != b.width * b.height * (lut.depth - 1) {
        return Err(bad("error_map size differs from texel footprints × slice intervals".into()));
    }
    Ok((values, quadrature, measured))
}

/// Build one cone LUT spec (see the module docs).
pub fn build(spec: &Spec, mode: Mode, root: &Path) -> Result<Built, BuildError> {
    let lut = ConeLut::from_spec(spec)?;
    let b = &lut.base;
    let name = spec.file.name.clone();
    let hash = crate::pipeline::input_hash(spec);
    let (w, h, d) = (b.width, b.height, lut.depth);
    let (values, quadrature, measured) = match mode {
        Mode::Fit => {
            let (values, q) = tabulate(&lut);
            if let Some(k) = values.iter().position(|v| !(v[0].is_finite() && v[1].is_finite())) {
                return Err(BuildError::NonFinite { spec: name, at: vec![b.n_dot_v(k % w), b.row_coordinate((k / w) % h), lut.cos_cone(k / (w * h))] });
            }
            let m = verify(&lut, &values)?;
            (values, q, m)
        }
        Mode::Committed => committed_parts(&crate::pipeline::committed_json_with_hash(root, spec, &hash)?, &lut)?,
    };
    let stored32 = stored(b, &values);
    let t = &measured.texture;
    let err_line = format!(
        "{} 3-D texture, trilinear (texel centres in n·v and {}, slices at cos_cone = k/{}, clamp to edge) against the integral at {}x denser points: max abs {}, rms {} over {} points x 2 channels (between the outer texel centres: max abs {}); f64 texels trilinear: max abs {}; f16 storage <= {}; quadrature estimate <= {}",
        b.format.name(),
        b.mapping.argument(),
        d - 1,
        measured.density,
        fmt_err(t.max_abs_error),
        fmt_err(t.rms_error),
        measured.points,
        fmt_err(measured.texture_interior.max_abs_error),
        fmt_err(measured.interpolation.max_abs_error),
        fmt_err(measured.max_abs_storage_error),
        fmt_err(quadrature.max_error_estimate),
    );
    let header = header_lines(&spec_rel_path(spec), &hash, &err_line);
    let provenance = header.join("\n");
    let channels = b.format.texel_channels();
    let flat: Vec<f32> = stored32.iter().flat_map(|v| if channels == 2 { vec![v[0], v[1]] } else { vec![v[0], v[1], 0.0, 1.0] }).collect();
    let ktx2 = ktx2_volume(w as u32, h as u32, d as u32, channels, &flat, f16_texture(b.format), &[("shadefit", &provenance)]);
    let level_offset = u64::from_le_bytes(ktx2[80..88].try_into().expect("eight bytes")) as usize;
    let code = ConeLutCode { module: &name, function: &b.function, width: w, height: h, depth: d, layout: b.layout, format: b.format, row: b.mapping.argument(), level_offset };
    let desc = if b.description.is_empty() { String::new() } else { format!("{}: ", b.description) };
    let doc = format!(
        "{desc}`{}` looks up the GGX split-sum environment BRDF (scale, bias) of quantity `{}` over the light directions in a visibility cone (height-correlated Smith G2, Schlick Fc), COD: WWII's 3-D table for cone-based specular occlusion.",
        b.function, b.quantity
    );
    let mdoc = mapping_doc(b);
    let wgsl = code.render_wgsl(&header, &doc, &mdoc);
    let rust = code.render_rust(&header, &doc, &mdoc);
    // Preview: the slices side by side (slice k in columns k·w .. (k + 1)·w).
    let preview: Vec<[f64; 3]> = (0..h)
        .flat_map(|j| (0..d).flat_map(move |k| (0..w).map(move |i| (k * h + j) * w + i)))
        .map(|idx| {
            let [r, g] = b.layout.encode(values[idx]);
            [r, g, 0.0]
        })
        .collect();
    let s = (1024 / (w * d).max(h)).max(1);
    let png = png_srgb_preview(w * d, h, &preview, s, s, &[("Software", GENERATOR.to_string()), ("Comment", provenance.clone())]);
    let (lo, hi) = values.iter().flat_map(|v| b.layout.encode(*v)).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, c), x| (a.min(x), c.max(x)));
    let json = json!({
        "generator": GENERATOR,
        "spec": spec_rel_path(spec),
        "input_hash": hash,
        "name": name,
        "kind": super::spec::KIND,
        "quantity": b.quantity,
        "description": b.description,
        "function": b.function,
        "shadowing": "height-correlated Smith G2",
        "layout": {"name": b.layout.name(), "channels": b.layout.channels()},
        "axes": [
            {"name": "n_dot_v", "texture_axis": "x", "count": w, "mapping": "linear", "texel_centres": "n_dot_v = (i + 0.5)/width"},
            {"name": b.mapping.argument(), "texture_axis": "y", "count": h, "mapping": b.mapping.name(),
             "texel_centres": format!("t = (j + 0.5)/height, {}", alpha_of_t(b.mapping))},
            {"name": "cos_cone", "texture_axis": "z", "count": d, "mapping": "linear", "slices": "cos_cone = k/(depth - 1): slice 0 the hemisphere, the last a closed cone"},
        ],
        "texture": {
            "width": w,
            "height": h,
            "depth": d,
            "format": b.format.name(),
            "ktx2": format!("data/{name}.ktx2"),
            "preview": format!("data/{name}.png"),
            "encoding": "linear 3-D texture, R and G as the layout says (RGBA: B = 0, A = 1); the PNG preview is sRGB-encoded with the slices left to right (cos_cone = 0 first), B = 0, row 0 at the top",
            "sampling": format!("uvw = (n_dot_v, t, (cos_cone * {} + 0.5) / {d}) with the parameters clamped to [0, 1], linear filter, clamp to edge", d - 1),
        },
        "range": [lo, hi],
        "quadrature": quadrature,
        "verification": measured,
        "values_layout": "slice-major, then row-major, n_dot_v fastest: values[(k * height + j) * width + i] = [scale, bias] in f64 (the texture stores the layout's channels of these, rounded to f32 then f16)",
        "values": values,
    });
    Ok(lut_built(name, [wgsl, rust, compact_json(&json)], ktx2, png, measured.points, t, &measured.lookup_f32))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::family::ggx::lut::build::tests::{coord, filament, filament_texels};
    use crate::family::ggx::lut::build::tabulate as tabulate_2d;

    /// The verification samples the cone cosine between the slices, at the centres of
    /// VERIFY_DENSITY (2) intervals in each: 0.25 and 0.75 on a 2 × 2 × 2 LUT. With slice 1's
    /// texels (c = 1) raised by 100 in both channels, the texture's error is 100·c plus the
    /// table's own (its values are in [0, 1], so it is below 1, f16 rounding at 100 included):
    /// largest at c = 0.75, ≈ 75.
    #[test]
    fn the_verification_samples_the_cone_cosine_between_the_slices() {
        let text = super::super::spec::tests::SPEC.replace("[8, 4, 3]", "[2, 2, 2]");
        let lut = ConeLut::parse(Path::new("fits/ggx_c.toml"), &text).unwrap();
        let (mut values, _) = tabulate(&lut);
        for v in &mut values[4..] {
            *v = v.map(|x| x + 100.0);
        }
        let m = verify(&lut, &values).unwrap();
        assert_eq!(m.points, 4 * 4 * 2);
        assert_eq!(m.texture.worst_point[2], 0.75, "{:?}", m.texture);
        assert!((m.texture.max_abs_error - 75.0).abs() < 1.0, "{:?}", m.texture);
    }

    /// Each cell of the error map is the largest texture error over its own block of
    /// VERIFY_DENSITY³ points: texel footprint (i, j) and slice interval k. On a 2 × 2 × 3 LUT
    /// the last slice's texel (i, j) is raised by P = 100·(1 + i + 2j). The texture's error at
    /// (u, t, c) is then that raise read trilinearly, 100·(1 + x + 2y)·max(0, 2c − 1) with
    /// x = clamp(2u − 0.5, 0, 1) and y = clamp(2t − 0.5, 0, 1) (a linear field between texel
    /// centres, clamped past them; the last slice's weight), plus the table's own error (its
    /// values are in [0, 1], so below 1). Slice interval 0 never reads the last slice: its cells
    /// stay below 1; interval 1's cells grow with i and j. Tolerance 2: the table's error (< 1),
    /// f16 rounding of values ≤ 401 (≤ 0.125) and the map's 3 significant digits (≤ 0.5 below
    /// 1000).
    #[test]
    fn each_error_map_cell_is_the_largest_error_of_its_own_block() {
        let text = super::super::spec::tests::SPEC.replace("[8, 4, 3]", "[2, 2, 3]");
        let lut = ConeLut::parse(Path::new("fits/ggx_c.toml"), &text).unwrap();
        let (w, h, d, n) = (lut.base.width, lut.base.height, lut.depth, VERIFY_DENSITY);
        let (mut values, _) = tabulate(&lut);
        for j in 0..h {
            for i in 0..w {
                let raise = 100.0 * (1 + i + 2 * j) as f64;
                values[(2 * h + j) * w + i] = values[(2 * h + j) * w + i].map(|x| x + raise);
            }
        }
        let m = verify(&lut, &values).unwrap();
        assert_eq!(m.error_map.len(), w * h * (d - 1));
        for k in 0..d - 1 {
            for j in 0..h {
                for i in 0..w {
                    let mut want = 0.0f64;
                    for (a, b, e) in block_offsets(n) {
                        let u = centre(i * n + a, n * w);
                        let t = centre(j * n + b, n * h);
                        let c = centre(k * n + e, n * (d - 1));
                        let (x, y) = ((2.0 * u - 0.5).clamp(0.0, 1.0), (2.0 * t - 0.5).clamp(0.0, 1.0));
                        want = want.max(100.0 * (1.0 + x + 2.0 * y) * (2.0 * c - 1.0).max(0.0));
                    }
                    let got = m.error_map[(k * h + j) * w + i];
                    assert!((got - want).abs() < 2.0, "cell (i {i}, j {j}, k {k}): {got} against {want}; map {:?}", m.error_map);
                }
            }
        }
    }

    /// Every figure of the verification re-measured by this test's own means: the integral by
    /// `env_with` with adaptive azimuth panels at 1e-10 (independent of the nested rules the
    /// build integrates with), the f16 texels by the `half` crate, trilinear weights written out
    /// (clamped texel coordinates, slices at k/(d − 1)). A 6 × 5 × 4 LUT in Filament's layout
    /// (R = bias, G = scale + bias: the encoding is judged too), VERIFY_DENSITY (2) points a
    /// texel and a slice interval: 12 × 10 × 6 points, 10 × 8 × 6 of them between the outer texel
    /// centres. The build's reference asks 1e-6: every maximum and rms agrees within
    /// 1e-6 + 1e-10 (each point's error moves by at most the two references' difference), and
    /// the emitted f32 lookup within 1e-6 more (f32 coordinates and arithmetic on values ≤ 2:
    /// a few ulps of 2^-23 times the table's slope, far below 1e-6). The f16 rounding is
    /// recomputed exactly.
    #[test]
    fn every_verification_figure_is_re_measured() {
        use crate::family::ggx::integrals::{Inner, Shadowing, env_with};
        let text = super::super::spec::tests::SPEC.replace("[8, 4, 3]", "[6, 5, 4]\nlayout = \"filament\"");
        let lut = ConeLut::parse(Path::new("fits/ggx_c.toml"), &text).unwrap();
        let (w, h, d) = (lut.base.width, lut.base.height, lut.depth);
        let (values, _) = tabulate(&lut);
        let m = verify(&lut, &values).unwrap();
        let (exact, stored, storage) = filament_texels(&values);
        assert_eq!(m.max_abs_storage_error, storage);
        assert!(storage > 0.0);
        let read = |tex: &[[f64; 2]], u: f64, t: f64, c: f64| -> [f64; 2] {
            let ((i, fx), (j, fy)) = (coord(u, w), coord(t, h));
            let z = c * (d - 1) as f64;
            let k = (z.floor() as usize).min(d - 2);
            let fz = z - k as f64;
            std::array::from_fn(|ch| {
                let at = |i: usize, j: usize, k: usize| tex[(k * h + j) * w + i][ch];
                let plane = |k: usize| {
                    let row = |j: usize| at(i, j, k) * (1.0 - fx) + at(i + 1, j, k) * fx;
                    row(j) * (1.0 - fy) + row(j + 1) * fy
                };
                plane(k) * (1.0 - fz) + plane(k + 1) * fz
            })
        };
        let centres = |count: usize| -> Vec<f64> { (0..count).map(|k| centre(k, count)).collect() };
        let (us, ts, cs) = (centres(2 * w), centres(2 * h), centres(2 * (d - 1)));
        let err = |got: [f64; 2], want: [f64; 2]| (got[0] - want[0]).abs().max((got[1] - want[1]).abs());
        let (mut tex, mut inner, mut interp, mut ss, mut inner_points) = (0.0f64, 0.0f64, 0.0f64, 0.0, 0);
        let (mut inner_ss, mut interp_ss) = (0.0, 0.0);
        let sq = |got: [f64; 2], want: [f64; 2]| (got[0] - want[0]).powi(2) + (got[1] - want[1]).powi(2);
        for &c in &cs {
            for &t in &ts {
                for &u in &us {
                    let r = env_with(lut.base.mapping.alpha(t), u, c, Shadowing::HeightCorrelated, 1e-10, Inner::Adaptive);
                    let want = filament([r.scale, r.bias]);
                    let got = read(&stored, u, t, c);
                    let e = err(got, want);
                    tex = tex.max(e);
                    ss += (got[0] - want[0]).powi(2) + (got[1] - want[1]).powi(2);
                    let between = |p: f64, n: usize| p > 0.5 / n as f64 && p < 1.0 - 0.5 / n as f64;
                    if between(u, w) && between(t, h) {
                        inner = inner.max(e);
                        inner_ss += sq(got, want);
                        inner_points += 1;
                    }
                    interp = interp.max(err(read(&exact, u, t, c), want));
                    interp_ss += sq(read(&exact, u, t, c), want);
                }
            }
        }
        let points = us.len() * ts.len() * cs.len();
        assert_eq!((m.points, inner_points), (12 * 10 * 6, 10 * 8 * 6));
        let bound = 1e-6 + 1e-10;
        let rms = (ss / (2 * points) as f64).sqrt();
        for (what, claimed, measured) in [
            ("texture max", m.texture.max_abs_error, tex),
            ("texture rms", m.texture.rms_error, rms),
            ("interior max", m.texture_interior.max_abs_error, inner),
            ("interior rms", m.texture_interior.rms_error, (inner_ss / (2 * inner_points) as f64).sqrt()),
            ("interpolation max", m.interpolation.max_abs_error, interp),
            ("interpolation rms", m.interpolation.rms_error, (interp_ss / (2 * points) as f64).sqrt()),
            ("f32 lookup max", m.lookup_f32.max_abs_error, tex),
        ] {
            let slack = if what.starts_with("f32") { 2.0 * bound } else { bound };
            assert!((claimed - measured).abs() <= slack, "{what}: claimed {claimed:e}, re-measured {measured:e}");
            assert!(measured > 100.0 * slack, "{what}: not a vacuous comparison ({measured:e})");
        }
        // The interior leaves out the clamped border, where filtering is worst: a smaller max.
        assert!(inner < tex, "{inner:e} vs {tex:e}");
        assert!(m.reference_max_error_estimate > 0.0 && m.reference_max_error_estimate <= VERIFY_TOLERANCE, "{}", m.reference_max_error_estimate);
        assert_eq!((m.density, m.reference_tolerance), (VERIFY_DENSITY, VERIFY_TOLERANCE));
    }

    /// The PNG preview sets the slices side by side, cos θc = 0 first: texel (i, j) of slice k
    /// is the s × s block at column k·w + i, row j (row 0 at the top), s the largest whole scale
    /// that keeps the longer side within 1024 pixels (113 for 3 slices of 3 × 2: 1017 × 226);
    /// R and G are the stored channels sRGB-encoded (IEC 61966-2-1, 8 bits), B = 0. Within one
    /// level: the 8-bit rounding of the same encoding.
    #[test]
    fn the_preview_sets_the_slices_side_by_side() {
        let text = super::super::spec::tests::SPEC.replace("[8, 4, 3]", "[3, 2, 3]");
        let spec = Spec::parse(Path::new("fits/ggx_c.toml"), text, crate::family::catalog()).unwrap();
        let built = build(&spec, Mode::Fit, Path::new("")).unwrap();
        let file = |suffix: &str| &built.artifacts.iter().find(|a| a.path.to_str().unwrap().ends_with(suffix)).unwrap().contents;
        let json: Value = serde_json::from_slice(file(".json")).unwrap();
        let values: Vec<[f64; 2]> = serde_json::from_value(json["values"].clone()).unwrap();
        let (w, h, d) = (3, 2, 3);
        let s = (1..).take_while(|s| (w * d).max(h) * s <= 1024).last().unwrap();
        let mut reader = png::Decoder::new(std::io::Cursor::new(&file(".png")[..])).read_info().unwrap();
        assert_eq!((reader.info().width, reader.info().height), ((w * d * s) as u32, (h * s) as u32));
        let mut px = vec![0; reader.output_buffer_size().unwrap()];
        reader.next_frame(&mut px).unwrap();
        let srgb = |x: f64| {
            let e = if x <= 0.0031308 { 12.92 * x } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 };
            e.clamp(0.0, 1.0) * 255.0
        };
        let row = w * d * s;
        for k in 0..d {
            for j in 0..h {
                for i in 0..w {
                    // Scale-bias layout: R = scale, G = bias.
                    let v = values[(k * h + j) * w + i];
                    let x0 = (k * w + i) * s;
                    for (x, y) in [(x0, j * s), (x0 + s - 1, j * s + s - 1)] {
                        let p = &px[3 * (y * row + x)..3 * (y * row + x) + 3];
                        let ok = (p[0] as f64 - srgb(v[0])).abs() <= 1.0 && (p[1] as f64 - srgb(v[1])).abs() <= 1.0 && p[2] == 0;
                        assert!(ok, "texel ({i}, {j}, {k}) at pixel ({x}, {y}): {p:?} for {v:?}");
                    }
                }
            }
        }
    }

    /// The quadrature a cone LUT reports is that of its slices, each the 2-D table's own: the
    /// largest error estimate of any slice and the slices' evaluations a texel, averaged and
    /// rounded. The closed cone (the last slice) takes no evaluation at all, so a sum or the
    /// first slice's figure would differ from the mean.
    #[test]
    fn tabulate_reports_its_slices_quadrature() {
        let text = super::super::spec::tests::SPEC.replace("[8, 4, 3]", "[6, 5, 4]");
        let lut = ConeLut::parse(Path::new("fits/ggx_c.toml"), &text).unwrap();
        let (values, q) = tabulate(&lut);
        assert_eq!(values.len(), 6 * 5 * 4);
        let slices: Vec<Quadrature> = (0..4).map(|k| tabulate_2d(&lut.slice(k)).1).collect();
        assert_eq!(slices[3].evals_per_texel, 0.0, "{slices:?}");
        let worst = slices.iter().map(|s| s.max_error_estimate).fold(0.0, f64::max);
        assert!(worst > 0.0 && slices.iter().any(|s| s.max_error_estimate < worst), "{slices:?}");
        assert_eq!(q.max_error_estimate, worst);
        let mean = slices.iter().map(|s| s.evals_per_texel).sum::<f64>() / 4.0;
        assert_eq!(q.evals_per_texel, mean.round());
        assert!(slices.iter().all(|s| s.evals_per_texel != q.evals_per_texel), "{slices:?}");
        assert_eq!(q.tolerance, lut.base.tolerance);
    }

    /// The centre of cell k of `count` equal cells of [0, 1]: where the verification samples.
    fn centre(k: usize, count: usize) -> f64 {
        (k as f64 + 0.5) / count as f64
    }

    /// The (a, b, e) offsets of the points of one block, each in 0..n.
    fn block_offsets(n: usize) -> impl Iterator<Item = (usize, usize, usize)> {
        (0..n).flat_map(move |a| (0..n).flat_map(move |b| (0..n).map(move |e| (a, b, e))))
    }

    #[test]
    fn trilinear_reproduces_a_linear_field_with_slices_at_k_over_d_minus_1() {
        // Texels holding channel 0 = k (the slice index) and channel 1 = i + 10 j on a
        // 4 × 3 × 3 volume. Slices sit at c = k/(d − 1), so c = 0.75 reads 1.5; texel centres
        // sit at (i + 0.5)/w, so u = 0.5 reads i = 1.5 and t = 0.5 reads j = 1. Trilinear
        // weights reproduce a linear field; 1e-14: a few roundings on values ≤ 12.
        let (w, h, d) = (4, 3, 3);
        let mut texels = vec![[0.0; 2]; w * h * d];
        for k in 0..d {
            for j in 0..h {
                for i in 0..w {
                    texels[(k * h + j) * w + i] = [k as f64, i as f64 + 10.0 * j as f64];
                }
            }
        }
        let v = trilinear(&texels, (w, h, d), 0.5, 0.5, 0.75);
        assert!((v[0] - 1.5).abs() < 1e-14 && (v[1] - 11.5).abs() < 1e-14, "{v:?}");
        // Clamped to edge and to the last slice.
        let v = trilinear(&texels, (w, h, d), 1.0, 0.0, 1.0);
        assert!((v[0] - 2.0).abs() < 1e-14 && (v[1] - 3.0).abs() < 1e-14, "{v:?}");
    }
}
