//! The build of a DFG LUT spec (`kind = "ggx-dfg-lut"`, see `super::spec`): tabulate, verify,
//! emit.
//!
//! - tabulate: every texel is [`integrals::env`] (scale, bias) at its centre to the spec's
//!   tolerance, rows in parallel and collected in order (byte-identical at any thread count);
//! - verify: the integral again at the centres of a grid [`VERIFY_DENSITY`] times denser per
//!   axis (off the texel grid everywhere, and past the outer texel centres, where
//!   clamp-to-edge holds the edge texels) to [`VERIFY_TOLERANCE`], against the texture as a
//!   linear sampler reads it: the f16 texels (the spec's layout) interpolated bilinearly with
//!   exact weights. Recorded: max, rms and worst point of that error (the texture's storage
//!   error under bilinear filtering), the same for the emitted f32 lookup and for the f64
//!   texels (interpolation alone), per channel, and the map of its largest value per texel
//!   footprint; the f16 rounding of the texels alone; the texels' quadrature error estimates;
//! - emit: `wgsl/NAME.wgsl`, `src/NAME.rs` (`super::emit`), `data/NAME.ktx2` (RG16F or
//!   RGBA16F), `data/NAME.png` (sRGB preview: R, G as stored, B = 0; row 0 at the top) and
//!   `json/NAME.json` (provenance, settings, errors, texels in f64).
//!
//! `Mode::Committed` (build --check) takes the texels and the measured errors from the
//! committed JSON and re-renders every file without integrating.

use crate::spec::Preset;
use super::emit::{DfgLutCode, lookup_f32};
use super::spec::{DfgLut, RoughnessMapping};
use crate::emit::texture::{TextureFormat, ktx2_texels, png_srgb_preview};
use crate::emit::interp::{centred, multilinear};
use crate::emit::{Artifact, GENERATOR, header_lines};
use crate::family::ggx::integrals::EnvEstimate;
use crate::pipeline::{BuildError, Built, Grid, Mode, Verification, committed_texels, compact_json, fmt_err, spec_rel_path};
use crate::spec::{Spec, TableTextureFormat};
use serde::{Deserialize, Serialize};
use serde_json::{Value, json};
use std::path::Path;

/// Verification points per texel footprint and axis.
pub const VERIFY_DENSITY: usize = 4;
/// Quadrature tolerance of the verification integrals: their measured error (≲ 3e-8 against a
/// 1e-12 reference, see the tests) is far below the f16 and interpolation errors measured
/// (≳ 1e-5 at the worst points).
pub const VERIFY_TOLERANCE: f64 = 1e-6;

/// The integrals at the points `per_axis` of the LUT's grid (n·v values, row coordinates, and
/// for ggx-env cone cosines; first fastest), through the table kind's grid sampler, in order.
pub fn sample(lut: &DfgLut, mut per_axis: Vec<Vec<f64>>, tol: f64) -> Vec<EnvEstimate> {
    let grid = lut.grid();
    if grid.axes.len() > per_axis.len() {
        per_axis.push(vec![lut.cos_cone]);
    }
    let points = Grid::product(per_axis);
    grid.sample(&lut.sampler(tol), &[0, 1], &points)
        .into_iter()
        .map(|e| EnvEstimate { scale: e[0].value, bias: e[1].value, error: e[0].error, evals: e[0].evals })
        .collect()
}

/// The integrals at row coordinates `ts` × n·v values `us` (row-major, n·v fastest).
pub fn integrate(lut: &DfgLut, us: &[f64], ts: &[f64], tol: f64) -> Vec<EnvEstimate> {
    sample(lut, vec![us.to_vec(), ts.to_vec()], tol)
}

/// The texels (scale, bias) with their quadrature work.
pub fn tabulate(lut: &DfgLut) -> (Vec<[f64; 2]>, Quadrature) {
    let est = sample(lut, lut.grid().axes.iter().take(2).map(|a| a.arguments()).collect(), lut.tolerance);
    let evals: u64 = est.iter().map(|e| e.evals).sum();
    let q = Quadrature {
        tolerance: lut.tolerance,
        max_error_estimate: est.iter().map(|e| e.error).fold(0.0, f64::max),
        evals_per_texel: (evals as f64 / est.len() as f64).round(),
    };
    (est.iter().map(|e| [e.scale, e.bias]).collect(), q)
}

/// Quadrature of the texels (the table kind's).
pub use crate::pipeline::Quadrature;

/// One error measure on the verification grid.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Measure {
    pub max_abs_error: f64,
    pub rms_error: f64,
    /// (n·v, roughness or α[, cos θc]) of the largest error.
    pub worst_point: Vec<f64>,
    /// Largest error per stored channel (R, G).
    pub max_abs_error_per_channel: [f64; 2],
}

/// What the verification measured (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Measured {
    pub density: usize,
    pub points: usize,
    pub reference_tolerance: f64,
    pub reference_max_error_estimate: f64,
    /// The f16 texture, bilinear with exact weights (the storage error under filtering).
    pub texture: Measure,
    /// The same between the outer texel centres only (no clamp-to-edge extrapolation).
    pub texture_interior: Measure,
    /// The emitted f32 lookup over the f16 texels.
    pub lookup_f32: Measure,
    /// The f64 texels, bilinear (interpolation alone).
    pub interpolation: Measure,
    /// Largest |f16(texel) − texel| over texels and channels (rounding alone).
    pub max_abs_storage_error: f64,
    /// Largest texture error per texel footprint (row-major, like the texels), 3 digits.
    pub error_map: Vec<f64>,
}

/// The precision the texture stores (the table kind's: f16 for both DFG formats).
pub fn f16_texture(format: TableTextureFormat) -> TextureFormat {
    crate::pipeline::stored_precision(format)
}

/// The stored channels in f32, as the texture holds them (f64 → f32 → f16).
pub fn stored(lut: &DfgLut, values: &[[f64; 2]]) -> Vec<[f32; 2]> {
    let f = f16_texture(lut.format);
    values.iter().map(|v| lut.layout.encode(*v).map(|x| f.stored(x as f32))).collect()
}

/// Bilinear interpolation in f64 of `texels` at texture coordinates (u, t) (texel centres,
/// clamp to edge, exact weights).
fn bilinear(texels: &[[f64; 2]], (w, h): (usize, usize), u: f64, t: f64) -> [f64; 2] {
    multilinear(texels, &[w, h], &[centred(u, w), centred(t, h)])
}

/// Max, sum of squares, worst point and per-channel max of (got − want) over points.
pub struct Accumulator {
    max: f64,
    ss: f64,
    worst: Vec<f64>,
    per_channel: [f64; 2],
}

impl Default for Accumulator {
    fn default() -> Self {
        Self::new()
    }
}

impl Accumulator {
    pub fn new() -> Self {
        Accumulator { max: -1.0, ss: 0.0, worst: Vec::new(), per_channel: [0.0; 2] }
    }

    /// Add one point; returns its larger channel error.
    pub fn add(&mut self, got: [f64; 2], want: [f64; 2], at: &[f64]) -> f64 {
        let mut m = 0.0f64;
        for c in 0..2 {
            let e = (got[c] - want[c]).abs();
            self.ss += e * e;
            self.per_channel[c] = self.per_channel[c].max(e);
            m = m.max(e);
        }
        if m > self.max {
            self.max = m;
            self.worst = at.to_vec();
        }
        m
    }

    /// The measure over `count` points (2 channels each).
    pub fn finish(self, count: usize) -> Measure {
        Measure {
            max_abs_error: self.max.max(0.0),
            rms_error: (self.ss / (2 * count) as f64).sqrt(),
            worst_point: self.worst,
            max_abs_error_per_channel: self.per_channel,
        }
    }
}

/// Three significant digits (the error map is a picture, not a claim).
pub fn digits3(x: f64) -> f64 {
    format!("{x:.2e}").parse().expect("a formatted float parses")
}

/// The verification of the texels `values` (see the module docs).
pub fn verify(lut: &DfgLut, values: &[[f64; 2]]) -> Result<Measured, BuildError> {
    let (w, h) = (lut.width, lut.height);
    let d = VERIFY_DENSITY;
    let grid = lut.grid();
    let (us, ts) = (grid.axes[0].cell_centres(d * w), grid.axes[1].cell_centres(d * h));
    let truth = integrate(lut, &us, &ts, VERIFY_TOLERANCE);
    let encoded: Vec<[f64; 2]> = values.iter().map(|v| lut.layout.encode(*v)).collect();
    let stored32 = stored(lut, values);
    let stored64: Vec<[f64; 2]> = stored32.iter().map(|v| v.map(f64::from)).collect();
    let (mut tex, mut l32, mut interp) = (Accumulator::new(), Accumulator::new(), Accumulator::new());
    let (mut inner, mut inner_count) = (Accumulator::new(), 0);
    let inside = |p: f64, n: usize| p >= 0.5 / n as f64 && p <= 1.0 - 0.5 / n as f64;
    let mut map = vec![0.0f64; w * h];
    for (l, &t) in ts.iter().enumerate() {
        for (k, &u) in us.iter().enumerate() {
            let e = &truth[l * us.len() + k];
            if !(e.scale.is_finite() && e.bias.is_finite()) {
                return Err(BuildError::NonFinite { spec: lut.name.clone(), at: vec![u, t] });
            }
            let want = lut.layout.encode([e.scale, e.bias]);
            let got = bilinear(&stored64, (w, h), u, t);
            let m = tex.add(got, want, &[u, t]);
            if inside(u, w) && inside(t, h) {
                inner.add(got, want, &[u, t]);
                inner_count += 1;
            }
            let cell = &mut map[(l / d) * w + k / d];
            *cell = cell.max(m);
            l32.add(lookup_f32(&stored32, (w, h), u as f32, t as f32).map(f64::from), want, &[u, t]);
            interp.add(bilinear(&encoded, (w, h), u, t), want, &[u, t]);
        }
    }
    let n = truth.len();
    let storage = encoded
        .iter()
        .zip(&stored64)
        .flat_map(|(a, b)| (0..2).map(move |c| (a[c] - b[c]).abs()))
        .fold(0.0, f64::max);
    Ok(Measured {
        density: d,
        points: n,
        reference_tolerance: VERIFY_TOLERANCE,
        reference_max_error_estimate: truth.iter().map(|e| e.error).fold(0.0, f64::max),
        texture: tex.finish(n),
        texture_interior: inner.finish(inner_count.max(1)),
        lookup_f32: l32.finish(n),
        interpolation: interp.finish(n),
        max_abs_storage_error: storage,
        error_map: map.into_iter().map(digits3).collect(),
    })
}

fn committed_parts(v: &Value, lut: &DfgLut) -> Result<(Vec<[f64; 2]>, Quadrature, Measured), BuildError> {
    let bad = |why: String| BuildError::NoCommitted { spec: lut.name.clone(), why };
    let values = committed_texels::<2>(v, &lut.name, lut.width * lut.height, "[scale, bias]")?;
    let quadrature: Quadrature = serde_json::from_value(v["quadrature"].clone()).map_err(|e| bad(format!("quadrature: {e}")))?;
    let measured: Measured = serde_json::from_value(v["verification"].clone()).map_err(|e| bad(format!("verification: {e}")))?;
    if measured.error_map.len() != values.len() {
        return Err(bad("error_map size differs from the texel count".into()));
    }
    Ok((values, quadrature, measured))
}

fn describe(lut: &DfgLut) -> String {
    let g = if lut.ue4 {
        "UE4's separable Schlick–Smith G (k = α/2)".to_string()
    } else {
        "height-correlated Smith G2".to_string()
    };
    let cone = if lut.cos_cone > 0.0 { format!(", lights in the cone n·l ≥ {}", lut.cos_cone) } else { String::new() };
    let desc = if lut.description.is_empty() { String::new() } else { format!("{}: ", lut.description) };
    format!(
        "{desc}`{}` looks up the GGX split-sum environment BRDF (scale, bias) of quantity `{}` ({g}, Schlick Fc{cone}).",
        lut.function, lut.quantity
    )
}

/// The row mapping in words, for the emitted files' docs.
pub fn mapping_doc(lut: &DfgLut) -> String {
    match lut.mapping {
        RoughnessMapping::Perceptual => format!("roughness r = (j + 0.5)/{}, α = r²", lut.height),
        RoughnessMapping::Alpha => format!("α = (j + 0.5)/{}", lut.height),
        RoughnessMapping::Gloss => format!("gloss g = (j + 0.5)/{}, α = sqrt(2/(1 + 2^(18 g)))", lut.height),
    }
}

/// α of the row coordinate t in the JSON's words.
pub fn alpha_of_t(mapping: RoughnessMapping) -> &'static str {
    match mapping {
        RoughnessMapping::Perceptual => "alpha = t^2",
        RoughnessMapping::Alpha => "alpha = t",
        RoughnessMapping::Gloss => "alpha = sqrt(2/(1 + 2^(18 t))) (gloss)",
    }
}

/// Build one DFG LUT spec (see the module docs).
pub fn build(spec: &Spec, mode: Mode, root: &Path) -> Result<Built, BuildError> {
    let lut = DfgLut::from_spec(spec)?;
    let name = spec.file.name.clone();
    let hash = crate::pipeline::input_hash(spec);
    let (w, h) = (lut.width, lut.height);
    let (values, quadrature, measured) = match mode {
        Mode::Fit => {
            let (values, q) = tabulate(&lut);
            if let Some(k) = values.iter().position(|v| !(v[0].is_finite() && v[1].is_finite())) {
                return Err(BuildError::NonFinite { spec: name, at: vec![lut.n_dot_v(k % w), lut.row_coordinate(k / w)] });
            }
            let m = verify(&lut, &values)?;
            (values, q, m)
        }
        Mode::Committed => committed_parts(&crate::pipeline::committed_json_with_hash(root, spec, &hash)?, &lut)?,
    };
    let stored32 = stored(&lut, &values);
    let t = &measured.texture;
    let err_line = format!(
        "{} texture, bilinear (texel centres, clamp to edge) against the integral at {}x denser points: max abs {}, rms {} over {} points x 2 channels (between the outer texel centres: max abs {}); f64 texels bilinear: max abs {}; f16 storage <= {}; quadrature estimate <= {}",
        lut.format.name(),
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
    let channels = lut.format.texel_channels();
    let flat: Vec<f32> = stored32
        .iter()
        .flat_map(|v| if channels == 2 { vec![v[0], v[1]] } else { vec![v[0], v[1], 0.0, 1.0] })
        .collect();
    let ktx2 = ktx2_texels(w as u32, h as u32, channels, &flat, f16_texture(lut.format), &[("shadefit", &provenance)]);
    let level_offset = u64::from_le_bytes(ktx2[80..88].try_into().expect("eight bytes")) as usize;
    let code = DfgLutCode {
        module: &name,
        function: &lut.function,
        width: w,
        height: h,
        layout: lut.layout,
        format: lut.format,
        row: lut.mapping.argument(),
        level_offset,
    };
    let doc = describe(&lut);
    let mdoc = mapping_doc(&lut);
    let wgsl = code.render_wgsl(&header, &doc, &mdoc);
    let rust = code.render_rust(&header, &doc, &mdoc);
    let preview: Vec<[f64; 3]> = values.iter().map(|v| {
        let [r, g] = lut.layout.encode(*v);
        [r, g, 0.0]
    }).collect();
    let s = (256 / w.max(h)).max(1);
    let png = png_srgb_preview(w, h, &preview, s, s, &[("Software", GENERATOR.to_string()), ("Comment", provenance.clone())]);
    let (lo, hi) = values.iter().flat_map(|v| lut.layout.encode(*v)).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
    let json = json!({
        "generator": GENERATOR,
        "spec": spec_rel_path(spec),
        "input_hash": hash,
        "name": name,
        "kind": super::spec::KIND,
        "quantity": lut.quantity,
        "description": lut.description,
        "function": lut.function,
        "shadowing": if lut.ue4 { "separable Schlick-Smith, k = alpha/2 (UE4)" } else { "height-correlated Smith G2" },
        "cos_cone": lut.cos_cone,
        "layout": {"name": lut.layout.name(), "channels": lut.layout.channels()},
        "axes": [
            {"name": "n_dot_v", "texture_axis": "x", "count": w, "mapping": "linear", "texel_centres": "n_dot_v = (i + 0.5)/width"},
            {"name": lut.mapping.argument(), "texture_axis": "y", "count": h, "mapping": lut.mapping.name(),
             "texel_centres": format!("t = (j + 0.5)/height, {}", alpha_of_t(lut.mapping))},
        ],
        "texture": {
            "width": w,
            "height": h,
            "format": lut.format.name(),
            "ktx2": format!("data/{name}.ktx2"),
            "preview": format!("data/{name}.png"),
            "encoding": "linear, R and G as the layout says (RGBA: B = 0, A = 1); the PNG preview is sRGB-encoded with B = 0, row 0 at the top",
            "sampling": "uv = (n_dot_v, t) clamped to [0, 1], linear filter, clamp to edge",
        },
        "range": [lo, hi],
        "quadrature": quadrature,
        "verification": measured,
        "values_layout": "row-major, n_dot_v fastest: values[j * width + i] = [scale, bias] in f64 (the texture stores the layout's channels of these, rounded to f32 then f16)",
        "values": values,
    });
    Ok(lut_built(name, [wgsl, rust, compact_json(&json)], ktx2, png, measured.points, t, &measured.lookup_f32))
}

/// A LUT build's outputs: the WGSL, Rust and JSON texts, the KTX2 texture and the PNG preview,
/// with the verification of the filtered texture (`texture`) and the emitted f32 lookup.
pub fn lut_built(
    name: String,
    [wgsl, rust, json]: [String; 3],
    ktx2: Vec<u8>,
    png: Vec<u8>,
    points: usize,
    texture: &Measure,
    lookup_f32: &Measure,
) -> Built {
    let verification = Verification {
        points,
        max_abs_error: texture.max_abs_error,
        rms_error: texture.rms_error,
        worst_point: texture.worst_point.clone(),
        max_abs_error_f32: lookup_f32.max_abs_error,
        rms_error_f32: lookup_f32.rms_error,
        max_abs_error_in_parameter: None,
    };
    let artifacts = vec![
        Artifact { path: format!("wgsl/{name}.wgsl").into(), contents: wgsl.into() },
        Artifact { path: format!("src/{name}.rs").into(), contents: rust.into() },
        Artifact { path: format!("json/{name}.json").into(), contents: json.into() },
        Artifact { path: format!("data/{name}.ktx2").into(), contents: ktx2 },
        Artifact { path: format!("data/{name}.png").into(), contents: png },
    ];
    Built { name, artifacts, verification, fit: None }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::family::ggx::integrals::env;

    /// Filament's layout of a texel (scale, bias): [bias, scale + bias].
    pub(crate) fn filament([s, b]: [f64; 2]) -> [f64; 2] {
        [b, s + b]
    }

    /// Texels in Filament's layout, exact and as f16 stores them (rounded by the `half` crate,
    /// through f32 as the texture is written), with the largest rounding: what the LUTs'
    /// verification tests re-measure their claims from.
    pub(crate) fn filament_texels(values: &[[f64; 2]]) -> (Vec<[f64; 2]>, Vec<[f64; 2]>, f64) {
        let f16 = |x: f64| f64::from(half::f16::from_f32(x as f32).to_f32());
        let exact: Vec<[f64; 2]> = values.iter().map(|v| filament(*v)).collect();
        let stored: Vec<[f64; 2]> = exact.iter().map(|v| v.map(f16)).collect();
        let storage = exact.iter().flat_map(|v| v.map(|x| (x - f16(x)).abs())).fold(0.0, f64::max);
        (exact, stored, storage)
    }

    /// A linear sampler along an axis of n texels at texture coordinate p (texel centres, clamp
    /// to edge): the lower texel of the pair and the upper one's weight.
    pub(crate) fn coord(p: f64, n: usize) -> (usize, f64) {
        let x = (p * n as f64 - 0.5).clamp(0.0, (n - 1) as f64);
        let i = (x.floor() as usize).min(n - 2);
        (i, x - i as f64)
    }

    /// A DFG LUT spec `ggx_t` of the default quantity at `resolution` (n·v × rows).
    fn spec_text([w, h]: [usize; 2]) -> String {
        format!("name = \"ggx_t\"\nkind = \"ggx-dfg-lut\"\nquantity = \"ggx-env\"\nresolution = [{w}, {h}]\n\n[emit]\nfunction = \"ggx_t\"\n")
    }

    /// The generic table kind computes this LUT's texture: `kind = "table"` with the channels
    /// [scale, bias] of `ggx-env`, n·v's axis and α's at texel centres, α's over perceptual
    /// roughness (`mapping = "perceptual"`), stored n·v fastest (`order = ["n_dot_v", "alpha"]`,
    /// this LUT's layout), holds each texel of a `ggx-dfg-lut` of the same resolution and
    /// tolerance bit for bit (the same integrals at the same points), and its RG16F KTX2 holds
    /// the same level bytes; its module (with the sampler helpers: RG16F filters) validates.
    #[test]
    fn a_generic_table_at_texel_centres_is_the_dfg_texture() {
        let (w, h) = (6, 5);
        let text = spec_text([w, h]).replace("resolution", "tolerance = 1e-7\ntexture_format = \"rg16float\"\nresolution");
        let dfg_spec = crate::spec::Spec::parse(std::path::Path::new("fits/ggx_t.toml"), text.clone(), crate::family::catalog()).unwrap();
        let lut = DfgLut::parse(std::path::Path::new("fits/ggx_t.toml"), &text).unwrap();
        let (texels, _) = tabulate(&lut);
        let table = format!(
            "name = \"ggx_table_t\"\nkind = \"table\"\nquantity = \"ggx-env\"\nchannels = [\"scale\", \"bias\"]\norder = [\"n_dot_v\", \"alpha\"]\ntolerance = 1e-7\n\n\
             [[axis]]\nname = \"alpha\"\nmapping = \"perceptual\"\nplacement = \"centres\"\nrange = [0.0, 1.0]\ncount = {h}\nverify = {h}\n\n\
             [[axis]]\nname = \"n_dot_v\"\nplacement = \"centres\"\nrange = [0.0, 1.0]\ncount = {w}\nverify = {w}\n\n\
             [emit]\nfunction = \"ggx_table_t\"\nargs = [\"n_dot_v\", \"roughness\"]\nform = \"both\"\ntexture_format = \"rg16float\"\n"
        );
        let spec = crate::spec::Spec::parse(std::path::Path::new("fits/ggx_table_t.toml"), table, crate::family::catalog()).unwrap();
        let values = crate::pipeline::table_sample(&spec, &crate::pipeline::table_points(&spec));
        let pairs: Vec<[f64; 2]> = values.chunks(2).map(|p| [p[0], p[1]]).collect();
        assert_eq!(pairs, texels);
        let level = |ktx2: &[u8]| {
            let at = |k: usize| u64::from_le_bytes(ktx2[k..k + 8].try_into().unwrap()) as usize;
            ktx2[at(80)..at(80) + at(88)].to_vec()
        };
        let ktx2_of = |b: &Built, name: &str| b.artifacts.iter().find(|a| a.path.ends_with(format!("data/{name}.ktx2"))).unwrap().contents.clone();
        let b = crate::pipeline::build_spec(&spec, Mode::Fit, std::path::Path::new(""), &|_| None).unwrap();
        let dfg = build(&dfg_spec, Mode::Fit, std::path::Path::new("")).unwrap();
        assert_eq!(level(&ktx2_of(&b, "ggx_table_t")), level(&ktx2_of(&dfg, "ggx_t")));
        let wgsl = b.artifacts.iter().find(|a| a.path.ends_with("wgsl/ggx_table_t.wgsl")).unwrap();
        let src = crate::emit::wgsl::strip_directives(std::str::from_utf8(&wgsl.contents).unwrap());
        let m = naga::front::wgsl::parse_str(&src).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&src)));
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
            .validate(&m)
            .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&src)));
        assert!(src.contains("fn ggx_table_t_sample(lut: texture_2d<f32>, lut_sampler: sampler, n_dot_v: f32, roughness: f32) -> vec2<f32>"), "{src}");
    }

    /// The module doc names the function, the quantity, the G it integrates and the light cone.
    #[test]
    fn the_description_names_the_g_and_the_cone() {
        let text = spec_text([10, 7]);
        let path = std::path::Path::new("fits/ggx_t.toml");
        let hc = describe(&DfgLut::parse(path, &text).unwrap());
        assert_eq!(hc, "`ggx_t` looks up the GGX split-sum environment BRDF (scale, bias) of quantity `ggx-env` (height-correlated Smith G2, Schlick Fc).");
        let ue4 = describe(&DfgLut::parse(path, &text.replace("ggx-env", "ggx-env-ue4")).unwrap());
        assert!(ue4.contains("`ggx-env-ue4` (UE4's separable Schlick–Smith G (k = α/2), Schlick Fc)"), "{ue4}");
        let cone = describe(&DfgLut::parse(path, &text.replace("resolution", "cos_cone = 0.5\nresolution")).unwrap());
        assert!(cone.contains("Schlick Fc, lights in the cone n·l ≥ 0.5)."), "{cone}");
    }

    /// The quadrature figures `tabulate` reports are those of the texels' own integrals: each
    /// texel is `env` at its n·v and its row's α (row-major, n·v fastest), the evaluations a
    /// texel are their total over the texel count (rounded: the JSON's figure), between the
    /// fewest and the most one texel took, and the error estimate is the largest one.
    #[test]
    fn tabulate_reports_the_texels_own_quadrature() {
        let text = spec_text([4, 3]);
        let lut = DfgLut::parse(std::path::Path::new("fits/ggx_t.toml"), &text).unwrap();
        let (texels, q) = tabulate(&lut);
        let each: Vec<EnvEstimate> = (0..lut.height)
            .flat_map(|j| {
                let alpha = lut.mapping.alpha(lut.row_coordinate(j));
                let lut = &lut;
                (0..lut.width).map(move |i| env(alpha, lut.n_dot_v(i), lut.cos_cone, lut.shadowing_at(alpha), lut.tolerance))
            })
            .collect();
        assert_eq!(texels, each.iter().map(|e| [e.scale, e.bias]).collect::<Vec<_>>());
        let evals: Vec<f64> = each.iter().map(|e| e.evals as f64).collect();
        let n = evals.len() as f64;
        assert_eq!(q.evals_per_texel, (evals.iter().sum::<f64>() / n).round());
        // Every texel takes more evaluations than there are texels, so a remainder (< their count) or a
        // total (> the most) is told from the mean.
        let (fewest, most) = (evals.iter().copied().fold(f64::INFINITY, f64::min), evals.iter().copied().fold(0.0, f64::max));
        assert!(fewest <= q.evals_per_texel && q.evals_per_texel <= most && fewest > n, "{q:?}: {evals:?}");
        assert_eq!(q.max_error_estimate, each.iter().map(|e| e.error).fold(0.0, f64::max));
        assert_eq!(q.tolerance, lut.tolerance);
    }

    /// Each cell of the error map is the largest texture error over its own texel footprint of
    /// VERIFY_DENSITY² points. On a 2 × 2 LUT texel (i, j) is raised by P = 100·(1 + i + 2j);
    /// the texture's error at (u, t) is then that raise read bilinearly, 100·(1 + x + 2y) with
    /// x = clamp(2u − 0.5, 0, 1) and y = clamp(2t − 0.5, 0, 1) (linear between the texel
    /// centres, clamped past them), plus the table's interpolation error (its values are in
    /// [0, 1], so below 1). The raise grows with x and y: each cell's largest error is at its
    /// footprint's last point on each axis. Tolerance 2: the table's error (< 1), f16 rounding
    /// of values ≤ 401 (≤ 0.125) and the map's 3 significant digits (≤ 0.5 below 1000).
    #[test]
    fn each_error_map_cell_is_the_largest_error_of_its_own_footprint() {
        let text = spec_text([2, 2]);
        let lut = DfgLut::parse(std::path::Path::new("fits/ggx_t.toml"), &text).unwrap();
        let (w, h, n) = (lut.width, lut.height, VERIFY_DENSITY);
        let (mut values, _) = tabulate(&lut);
        for j in 0..h {
            for i in 0..w {
                values[j * w + i] = values[j * w + i].map(|x| x + 100.0 * (1 + i + 2 * j) as f64);
            }
        }
        let m = verify(&lut, &values).unwrap();
        assert_eq!(m.error_map.len(), w * h);
        // The last verification point of footprint i along an axis of `count` texels.
        let last = |i: usize, count: usize| ((i * n + n - 1) as f64 + 0.5) / (n * count) as f64;
        for j in 0..h {
            for i in 0..w {
                let (x, y) = ((2.0 * last(i, w) - 0.5).clamp(0.0, 1.0), (2.0 * last(j, h) - 0.5).clamp(0.0, 1.0));
                let want = 100.0 * (1.0 + x + 2.0 * y);
                let got = m.error_map[j * w + i];
                assert!((got - want).abs() < 2.0, "cell (i {i}, j {j}): {got} against {want}; map {:?}", m.error_map);
            }
        }
    }

    /// Every figure of the verification re-measured by this test's own means (the 2-D twin of
    /// the cone LUT's test): the integral by `env_with` with adaptive azimuth panels at 1e-10
    /// (independent of the nested rules the build integrates with), the f16 texels by the
    /// `half` crate, bilinear weights written out (clamped texel coordinates). A 6 × 5 LUT in
    /// Filament's layout (R = bias, G = scale + bias: the encoding is judged too),
    /// VERIFY_DENSITY (4) points a texel and axis: 24 × 20 points, 20 × 16 of them between the
    /// outer texel centres (two points per axis end lie past them). The build's reference asks
    /// 1e-6: every maximum, channel maximum and rms agrees within 1e-6 + 1e-10 (each point's
    /// error moves by at most the two references' difference), the emitted f32 lookup within
    /// 1e-6 more (f32 coordinates and arithmetic on values ≤ 2: a few ulps of 2^-23 times the
    /// table's slope), and the texture's error at its stated worst point is its maximum. The
    /// f16 rounding is recomputed exactly.
    #[test]
    fn every_verification_figure_is_re_measured() {
        use crate::family::ggx::integrals::{Inner, Shadowing, env_with};
        let lut = DfgLut::parse(std::path::Path::new("fits/ggx_t.toml"), &spec_text([6, 5]).replace("[6, 5]", "[6, 5]\nlayout = \"filament\"")).unwrap();
        let (w, h) = (lut.width, lut.height);
        let (values, _) = tabulate(&lut);
        let m = verify(&lut, &values).unwrap();
        let (exact, stored, storage) = filament_texels(&values);
        assert_eq!(m.max_abs_storage_error, storage);
        assert!(storage > 0.0);
        let read = |tex: &[[f64; 2]], u: f64, t: f64| -> [f64; 2] {
            let ((i, fx), (j, fy)) = (coord(u, w), coord(t, h));
            std::array::from_fn(|c| {
                let row = |j: usize| tex[j * w + i][c] * (1.0 - fx) + tex[j * w + i + 1][c] * fx;
                row(j) * (1.0 - fy) + row(j + 1) * fy
            })
        };
        let centres = |count: usize| -> Vec<f64> { (0..count).map(|k| (k as f64 + 0.5) / count as f64).collect() };
        let (us, ts) = (centres(4 * w), centres(4 * h));
        /// Max, per-channel max, sum of squares and count of the errors of some points.
        #[derive(Default)]
        struct Errors {
            max: f64,
            channel: [f64; 2],
            ss: f64,
            count: usize,
        }
        impl Errors {
            fn add(&mut self, got: [f64; 2], want: [f64; 2]) {
                for c in 0..2 {
                    let e = (got[c] - want[c]).abs();
                    self.channel[c] = self.channel[c].max(e);
                    self.max = self.max.max(e);
                    self.ss += e * e;
                }
                self.count += 1;
            }
            fn rms(&self) -> f64 {
                (self.ss / (2 * self.count) as f64).sqrt()
            }
        }
        let (mut tex, mut inner, mut interp) = (Errors::default(), Errors::default(), Errors::default());
        let truth = |u: f64, t: f64| {
            let r = env_with(lut.mapping.alpha(t), u, 0.0, Shadowing::HeightCorrelated, 1e-10, Inner::Adaptive);
            filament([r.scale, r.bias])
        };
        for &t in &ts {
            for &u in &us {
                let want = truth(u, t);
                let got = read(&stored, u, t);
                tex.add(got, want);
                let between = |p: f64, n: usize| p > 0.5 / n as f64 && p < 1.0 - 0.5 / n as f64;
                if between(u, w) && between(t, h) {
                    inner.add(got, want);
                }
                interp.add(read(&exact, u, t), want);
            }
        }
        assert_eq!((m.points, tex.count, inner.count), (24 * 20, 24 * 20, 20 * 16));
        let bound = 1e-6 + 1e-10;
        for (what, claimed, measured) in [
            ("texture max", m.texture.max_abs_error, tex.max),
            ("texture R max", m.texture.max_abs_error_per_channel[0], tex.channel[0]),
            ("texture G max", m.texture.max_abs_error_per_channel[1], tex.channel[1]),
            ("texture rms", m.texture.rms_error, tex.rms()),
            ("interior max", m.texture_interior.max_abs_error, inner.max),
            ("interior rms", m.texture_interior.rms_error, inner.rms()),
            ("interpolation max", m.interpolation.max_abs_error, interp.max),
            ("interpolation rms", m.interpolation.rms_error, interp.rms()),
            ("f32 lookup max", m.lookup_f32.max_abs_error, tex.max),
            ("f32 lookup rms", m.lookup_f32.rms_error, tex.rms()),
        ] {
            let slack = if what.starts_with("f32") { 2.0 * bound } else { bound };
            assert!((claimed - measured).abs() <= slack, "{what}: claimed {claimed:e}, re-measured {measured:e}");
            assert!(measured > 100.0 * slack, "{what}: not a vacuous comparison ({measured:e})");
        }
        // The interior leaves out the clamped border, where filtering is worst: a smaller max.
        assert!(inner.max < tex.max && inner.rms() != tex.rms(), "{} vs {}", inner.max, tex.max);
        let p = &m.texture.worst_point;
        let e = read(&stored, p[0], p[1]).iter().zip(truth(p[0], p[1])).map(|(g, t)| (g - t).abs()).fold(0.0, f64::max);
        assert!((e - m.texture.max_abs_error).abs() <= bound, "at {p:?}: {e:e} vs {:e}", m.texture.max_abs_error);
        assert!(m.reference_max_error_estimate > 0.0 && m.reference_max_error_estimate <= VERIFY_TOLERANCE, "{}", m.reference_max_error_estimate);
        assert_eq!((m.density, m.reference_tolerance), (VERIFY_DENSITY, VERIFY_TOLERANCE));
    }

    /// The accumulator's figures by hand. Three points, errors (0.5, 0), (0, 0.5) and (0.25, 0):
    /// the largest 0.5 first reached at the first point, which stays the worst point when the
    /// second ties it (the first point reaching the maximum is stated, as in a scan); each
    /// channel's largest 0.5; rms over 3 points × 2 channels √(0.5625/6). Each `add` returns its
    /// point's larger channel error (what the error map keeps). All exact in binary but the
    /// rms's square root: 1e-15.
    #[test]
    fn the_accumulator_keeps_the_first_worst_point_and_counts_both_channels() {
        let mut a = Accumulator::new();
        let steps = [a.add([1.0, 0.5], [0.5, 0.5], &[0.1]), a.add([0.0, 0.0], [0.0, -0.5], &[0.2]), a.add([0.25, 0.0], [0.0, 0.0], &[0.3])];
        assert_eq!(steps, [0.5, 0.5, 0.25]);
        let m = a.finish(3);
        assert_eq!((m.max_abs_error, m.worst_point, m.max_abs_error_per_channel), (0.5, vec![0.1], [0.5, 0.5]));
        assert!((m.rms_error - (0.5625f64 / 6.0).sqrt()).abs() < 1e-15, "{}", m.rms_error);
        // No point at all: a zero maximum, no worst point.
        let none = Accumulator::new().finish(1);
        assert_eq!((none.max_abs_error, none.worst_point.len(), none.rms_error), (0.0, 0, 0.0));
    }

    /// The row mapping as the emitted files' docs and the JSON state it, each formula evaluated
    /// here at every row of a 7-row table and compared with the row's α: t = (j + ½)/7 and
    /// α = t² (perceptual), α = t, α = sqrt(2/(1 + 2^(18 t))) (gloss, with the gloss family's
    /// exponent 18). 1e-15 relative: the same few roundings in another order.
    #[test]
    fn the_mapping_docs_state_each_rows_coordinate_and_alpha() {
        let cases: [(&str, &str, &str, fn(f64) -> f64); 3] = [
            ("perceptual", "roughness r = (j + 0.5)/7, α = r²", "alpha = t^2", |t| t * t),
            ("alpha", "α = (j + 0.5)/7", "alpha = t", |t| t),
            ("gloss", "gloss g = (j + 0.5)/7, α = sqrt(2/(1 + 2^(18 g)))", "alpha = sqrt(2/(1 + 2^(18 t))) (gloss)", |t| (2.0 / (1.0 + (18.0 * t).exp2())).sqrt()),
        ];
        for (name, doc, json, alpha) in cases {
            let text = spec_text([10, 7]).replace("resolution", &format!("roughness_mapping = \"{name}\"\nresolution"));
            let lut = DfgLut::parse(std::path::Path::new("fits/ggx_t.toml"), &text).unwrap();
            assert_eq!((mapping_doc(&lut).as_str(), alpha_of_t(lut.mapping)), (doc, json), "{name}");
            for j in 0..7 {
                let t = (j as f64 + 0.5) / 7.0;
                assert!((lut.alpha(j) - alpha(t)).abs() <= 1e-15 * alpha(t), "{name} row {j}: {} vs {}", lut.alpha(j), alpha(t));
            }
        }
    }

    /// The PNG preview draws each texel as an s × s block, s the largest whole scale that keeps
    /// the longer side within 256 pixels (25 for 10 × 7: 250 × 175), with row 0 at the top,
    /// R and G the stored channels sRGB-encoded (IEC 61966-2-1, 8 bits), B = 0. Within one
    /// level: the 8-bit rounding of the same encoding.
    #[test]
    fn the_preview_draws_each_texel_as_a_block_within_256_pixels() {
        let spec = Spec::parse(std::path::Path::new("fits/ggx_t.toml"), spec_text([10, 7]), crate::family::catalog()).unwrap();
        let built = build(&spec, Mode::Fit, Path::new("")).unwrap();
        let file = |suffix: &str| &built.artifacts.iter().find(|a| a.path.to_str().unwrap().ends_with(suffix)).unwrap().contents;
        let json: Value = serde_json::from_slice(file(".json")).unwrap();
        let values: Vec<[f64; 2]> = serde_json::from_value(json["values"].clone()).unwrap();
        let (w, h) = (10, 7);
        let s = (1..).take_while(|s| w.max(h) * s <= 256).last().unwrap();
        let mut reader = png::Decoder::new(std::io::Cursor::new(&file(".png")[..])).read_info().unwrap();
        assert_eq!((reader.info().width, reader.info().height), ((w * s) as u32, (h * s) as u32));
        let mut px = vec![0; reader.output_buffer_size().unwrap()];
        reader.next_frame(&mut px).unwrap();
        let srgb = |x: f64| {
            let e = if x <= 0.0031308 { 12.92 * x } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 };
            e.clamp(0.0, 1.0) * 255.0
        };
        for j in 0..h {
            for i in 0..w {
                // Scale-bias layout: R = scale, G = bias.
                let v = values[j * w + i];
                for (x, y) in [(i * s, j * s), (i * s + s - 1, j * s + s - 1)] {
                    let p = &px[3 * (y * w * s + x)..3 * (y * w * s + x) + 3];
                    let ok = (p[0] as f64 - srgb(v[0])).abs() <= 1.0 && (p[1] as f64 - srgb(v[1])).abs() <= 1.0 && p[2] == 0;
                    assert!(ok, "texel ({i}, {j}) at pixel ({x}, {y}): {p:?} for {v:?}");
                }
            }
        }
    }

    /// Bilinear filtering of texels that are linear in the texel index, f(i, j) = i + 10j (and
    /// 2i − j), returns the same linear function at the texel-space point (u·w − ½, t·h − ½),
    /// clamped to the edge texels outside their centres.
    #[test]
    fn bilinear_reproduces_a_linear_function_and_clamps_at_the_edges() {
        let (w, h) = (4usize, 3usize);
        let texels: Vec<[f64; 2]> = (0..h).flat_map(|j| (0..w).map(move |i| [i as f64 + 10.0 * j as f64, 2.0 * i as f64 - j as f64])).collect();
        // The last four lie outside [0, 1]², where clamp to edge reads the border texels.
        for (u, t) in [(0.3, 0.4), (0.5, 0.5), (0.7, 0.2), (0.05, 0.9), (0.99, 0.01), (1.3, 0.5), (-0.2, 1.4), (2.0, -1.0), (0.6, 1.0 + 1e-9)] {
            let x = (u * w as f64 - 0.5).clamp(0.0, (w - 1) as f64);
            let y = (t * h as f64 - 0.5).clamp(0.0, (h - 1) as f64);
            let got = bilinear(&texels, (w, h), u, t);
            // Weights and products of small integers: a few ulps.
            assert!((got[0] - (x + 10.0 * y)).abs() < 1e-12 && (got[1] - (2.0 * x - y)).abs() < 1e-12, "({u}, {t}): {got:?}");
        }
    }
}
