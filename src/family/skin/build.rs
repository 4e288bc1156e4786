//! The build of a skin LUT spec (`kind = "skin-lut"`, see `super::spec`): tabulate, verify,
//! emit.
//!
//! - tabulate: every texel is the integral of `super::integrals` (punctual: the ring, RGB, with
//!   the spec's kernel; SH: bands 1 and 2 of the sphere) at the grid point, to the spec's
//!   tolerance per channel; curvature rows in parallel, collected in order (byte-identical at
//!   any thread count);
//! - verify: the integral again on the grid that adds every midpoint (2n − 1 per axis, in the
//!   mapped coordinates), against bilinear interpolation of the f64 texels and against the
//!   emitted f32 lookup; the texture's storage error (f16 or f32 rounding of the texels); the
//!   largest quadrature error estimate;
//! - emit: `wgsl/NAME.wgsl` and `src/NAME.rs` (const arrays and lookups, `super::emit`),
//!   `data/NAME.ktx2` (linear RGBA, alpha 1), `data/NAME.png` (sRGB preview, κ = 0 row at the
//!   top) and `json/NAME.json` (provenance: profile, kernel, mapping, tolerance, texel values in
//!   f64, measured errors).
//!
//! `Mode::Committed` (build --check) takes the texel values and the measured errors from the
//! committed JSON and re-renders every file without integrating.

use crate::spec::Preset;
use crate::pipeline::{BuildError, Built, Mode, Quadrature, Verification, committed_texels, compact_json, fmt_err, spec_rel_path};
use super::emit::{Layout, SkinLutCode};
use crate::emit::texture::{ktx2_rgba, png_srgb_preview};
use crate::emit::interp::{multilinear, nodes};
use crate::emit::{Artifact, GENERATOR, header_lines};
use crate::integrate::{Estimate, Tolerance};
use super::integrals::{
    self as skin, DEFAULT_TOLERANCE, Kernel, punctual_grid_estimates, sh_bands_estimates,
};
use crate::spec::Spec;
use super::spec::{SkinLut, SkinLutKind};
use serde_json::{Value, json};
use sha2::{Digest, Sha256};
use std::path::Path;

/// Input hash of a skin LUT: the generator, the spec text and, for a CSV profile, its bytes.
pub fn input_hash(spec: &Spec, lut: &SkinLut) -> String {
    let mut h = Sha256::new();
    h.update(GENERATOR.as_bytes());
    h.update(b"\n");
    h.update(spec.text.as_bytes());
    let extra = lut.profile.hash_input();
    if !extra.is_empty() {
        h.update(b"\n");
        h.update(extra);
    }
    format!("sha256:{}", h.finalize().iter().map(|b| format!("{b:02x}")).collect::<String>())
}

fn layout(lut: &SkinLut) -> Layout {
    match lut.kind {
        SkinLutKind::Punctual { n_dot_l, .. } => Layout::Punctual { n_dot_l, curvature: lut.curvature_count },
        SkinLutKind::Sh => Layout::Sh { curvature: lut.curvature_count },
    }
}

fn tolerance(lut: &SkinLut) -> Tolerance {
    Tolerance { abs: lut.tolerance, rel: 0.0, max_panels: DEFAULT_TOLERANCE.max_panels }
}

fn profile_err(spec: &Spec, e: skin::ProfileError) -> BuildError {
    BuildError::Input { spec: spec.file.name.clone(), msg: e.to_string() }
}

/// The integrals at n·l ∈ `nls` × κ ∈ `kappas` (punctual) or at κ ∈ `kappas` for bands 1, 2
/// (SH: `nls` unused), in texel order (rows: κ for punctual, band for SH).
fn integrate(
    spec: &Spec,
    lut: &SkinLut,
    nls: &[f64],
    kappas: &[f64],
) -> Result<Vec<[Estimate; 3]>, BuildError> {
    let tol = tolerance(lut);
    let p = &lut.profile.profile;
    match lut.kind {
        SkinLutKind::Punctual { kernel, .. } => {
            punctual_grid_estimates(p, kernel, nls, kappas, tol).map_err(|e| profile_err(spec, e))
        }
        SkinLutKind::Sh => {
            let per_kappa = sh_bands_estimates(p, kappas, &[1, 2], tol).map_err(|e| profile_err(spec, e))?;
            Ok((0..2).flat_map(|b| per_kappa.iter().map(move |bands| bands[b])).collect())
        }
    }
}

fn lut_n_dot_ls(lut: &SkinLut) -> Vec<f64> {
    match lut.kind {
        SkinLutKind::Punctual { n_dot_l, .. } => SkinLut::n_dot_l_axis(n_dot_l).arguments(),
        SkinLutKind::Sh => Vec::new(),
    }
}

/// Bilinear interpolation in f64 at continuous texel coordinates (x, y).
fn bilinear(values: &[[f64; 3]], (w, h): (usize, usize), x: f64, y: f64) -> [f64; 3] {
    if h == 1 {
        return multilinear(values, &[w], &[nodes(x, w)]);
    }
    multilinear(values, &[w, h], &[nodes(x, w), nodes(y, h)])
}

/// Measured errors on the grid with every midpoint added (see the module docs), one
/// verification per emitted lookup in `codes` (the integral is computed once).
fn verify(
    spec: &Spec,
    lut: &SkinLut,
    values: &[[f64; 3]],
    codes: &[&SkinLutCode<'_>],
) -> Result<Vec<Verification>, BuildError> {
    let n = lut.curvature_count;
    let m = 2 * n - 1;
    // Mapped coordinate t = k/(m − 1) of the fine grid: even k are the texels.
    let kappas = lut.curvatures_at(m);
    let mut points: Vec<Vec<f64>> = Vec::new();
    let mut approx64: Vec<[f64; 3]> = Vec::new();
    let mut approx32: Vec<Vec<[f32; 3]>> = vec![Vec::new(); codes.len()];
    let truth: Vec<[f64; 3]> = match lut.kind {
        SkinLutKind::Punctual { n_dot_l, .. } => {
            let mu = 2 * n_dot_l - 1;
            let nls = SkinLut::n_dot_l_axis(mu).arguments();
            for (b, &kappa) in kappas.iter().enumerate() {
                for (a, &nl) in nls.iter().enumerate() {
                    points.push(vec![kappa, nl]);
                    approx64.push(bilinear(values, (n_dot_l, n), a as f64 / 2.0, b as f64 / 2.0));
                    for (a32, code) in approx32.iter_mut().zip(codes) {
                        a32.push(code.punctual_f32(nl as f32, kappa as f32));
                    }
                }
            }
            integrate(spec, lut, &nls, &kappas)?.iter().map(|e| e.map(|x| x.value)).collect()
        }
        SkinLutKind::Sh => {
            let t = integrate(spec, lut, &[], &kappas)?;
            for band in 1..=2u32 {
                for (a, &kappa) in kappas.iter().enumerate() {
                    points.push(vec![kappa, band as f64]);
                    let row = &values[(band as usize - 1) * n..band as usize * n];
                    approx64.push(bilinear(row, (n, 1), a as f64 / 2.0, 0.0));
                    for (a32, code) in approx32.iter_mut().zip(codes) {
                        a32.push(code.sh_f32(kappa as f32, band));
                    }
                }
            }
            t.iter().map(|e| e.map(|x| x.value)).collect()
        }
    };
    let mut worst = (0usize, 0.0f64);
    let mut ss = 0.0;
    for (k, want) in truth.iter().enumerate() {
        for c in 0..3 {
            let e = (approx64[k][c] - want[c]).abs();
            if e > worst.1 {
                worst = (k, e);
            }
            ss += e * e;
        }
    }
    let count = (3 * truth.len()) as f64;
    approx32
        .iter()
        .map(|a32| {
            let (mut ss32, mut max32) = (0.0, 0.0f64);
            for (k, want) in truth.iter().enumerate() {
                for c in 0..3 {
                    let e32 = (a32[k][c] as f64 - want[c]).abs();
                    if !e32.is_finite() {
                        return Err(BuildError::NonFinite { spec: spec.file.name.clone(), at: points[k].clone() });
                    }
                    ss32 += e32 * e32;
                    max32 = max32.max(e32);
                }
            }
            Ok(Verification {
                points: truth.len(),
                max_abs_error: worst.1,
                rms_error: (ss / count).sqrt(),
                worst_point: points[worst.0].clone(),
                max_abs_error_f32: max32,
                rms_error_f32: (ss32 / count).sqrt(),
                max_abs_error_in_parameter: None,
            })
        })
        .collect()
}

fn committed_parts(v: &Value, name: &str, texels: usize) -> Result<(Vec<[f64; 3]>, Verification, Quadrature), BuildError> {
    let bad = |why: &str| BuildError::NoCommitted { spec: name.into(), why: why.into() };
    let values = committed_texels::<3>(v, name, texels, "[r, g, b]")?;
    let ver = &v["verification"];
    let num = |x: &Value, k: &str| x[k].as_f64().ok_or_else(|| bad(&format!("no number '{k}'")));
    let verification = Verification {
        points: ver["points"].as_u64().ok_or_else(|| bad("no verification.points"))? as usize,
        max_abs_error: num(ver, "max_abs_error")?,
        rms_error: num(ver, "rms_error")?,
        worst_point: ver["worst_point"]
            .as_array()
            .and_then(|a| a.iter().map(Value::as_f64).collect())
            .ok_or_else(|| bad("no verification.worst_point"))?,
        max_abs_error_f32: num(ver, "max_abs_error_f32")?,
        rms_error_f32: num(ver, "rms_error_f32")?,
        max_abs_error_in_parameter: None,
    };
    let quadrature: Quadrature = serde_json::from_value(v["quadrature"].clone()).map_err(|e| bad(&format!("quadrature: {e}")))?;
    Ok((values, verification, quadrature))
}

/// Build one skin LUT spec (see the module docs).
pub fn build(spec: &Spec, mode: Mode, root: &Path) -> Result<Built, BuildError> {
    Ok(build_verified(spec, mode, root, false)?.0)
}

/// Tabulate and build a skin LUT spec (as [`build`] in `Mode::Fit`), and verify on the same
/// grid the lookup over the texels as the texture stores them (the spec's texture format,
/// interpolated in f32): what a linear sampler returns, up to its filter-weight precision.
pub fn build_with_texture_error(spec: &Spec) -> Result<(Built, Verification), BuildError> {
    let (built, texture) = build_verified(spec, Mode::Fit, Path::new(""), true)?;
    Ok((built, texture.expect("verified with the stored texels")))
}

fn build_verified(spec: &Spec, mode: Mode, root: &Path, texture: bool) -> Result<(Built, Option<Verification>), BuildError> {
    let lut = SkinLut::from_spec(spec)?;
    let name = spec.file.name.clone();
    let hash = input_hash(spec, &lut);
    let layout = layout(&lut);
    let (w, h) = layout.size();
    let kappas = lut.curvatures();
    let nls = lut_n_dot_ls(&lut);
    let precision = crate::pipeline::stored_precision(lut.format);

    let (values, fresh) = match mode {
        Mode::Fit => {
            let est = integrate(spec, &lut, &nls, &kappas)?;
            let evals: u64 = est.iter().map(|e| e[0].evals).sum();
            let q = Quadrature {
                tolerance: lut.tolerance,
                max_error_estimate: est.iter().flat_map(|e| e.iter().map(|x| x.error)).fold(0.0, f64::max),
                evals_per_texel: (evals as f64 / est.len() as f64).round(),
            };
            (est.iter().map(|e| e.map(|x| x.value)).collect::<Vec<[f64; 3]>>(), Some(q))
        }
        Mode::Committed => (Vec::new(), None),
    };
    let (values, verification, quadrature, texture) = match fresh {
        Some(q) => {
            let values32: Vec<[f32; 3]> = values.iter().map(|v| v.map(|x| x as f32)).collect();
            let stored: Vec<[f32; 3]> = values32.iter().map(|v| v.map(|x| precision.stored(x))).collect();
            let (emitted, sampled) = (code(&lut, &name, layout, &values32), code(&lut, &name, layout, &stored));
            let codes: &[&SkinLutCode] = if texture { &[&emitted, &sampled] } else { &[&emitted] };
            let mut ver = verify(spec, &lut, &values, codes)?.into_iter();
            let emitted_ver = ver.next().expect("one verification per lookup");
            (values, emitted_ver, q, ver.next())
        }
        None => {
            let (values, ver, q) = committed_parts(&crate::pipeline::committed_json_with_hash(root, spec, &hash)?, &name, w * h)?;
            (values, ver, q, None)
        }
    };
    if let Some(k) = values.iter().position(|v| v.iter().any(|x| !x.is_finite())) {
        return Err(BuildError::NonFinite { spec: name, at: vec![k as f64] });
    }
    let values32: Vec<[f32; 3]> = values.iter().map(|v| v.map(|x| x as f32)).collect();
    let code = code(&lut, &name, layout, &values32);
    let storage = values
        .iter()
        .flat_map(|v| v.iter().map(|&x| (precision.stored(x as f32) as f64 - x).abs()))
        .fold(0.0, f64::max);
    let (lo, hi) = values.iter().flat_map(|v| v.iter()).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)));

    let err_line = format!(
        "bilinear lookup of the f32 texels: max abs {}, rms {} over {} points x 3 channels; quadrature estimate <= {}; {} storage <= {}",
        fmt_err(verification.max_abs_error_f32),
        fmt_err(verification.rms_error_f32),
        verification.points,
        fmt_err(quadrature.max_error_estimate),
        lut.format.name(),
        fmt_err(storage),
    );
    let header = header_lines(&spec_rel_path(spec), &hash, &err_line);
    let doc = describe(&lut);
    let wgsl = code.render_wgsl(&header, &doc);
    let rust = code.render_rust(&header, &doc);
    let texels: Vec<[f32; 4]> = values32.iter().map(|v| [v[0], v[1], v[2], 1.0]).collect();
    let provenance = header.join("\n");
    let ktx2 = ktx2_rgba(w as u32, h as u32, &texels, precision, &[("shadefit", &provenance)]);
    let (sx, sy) = preview_scale(layout);
    let png = png_srgb_preview(w, h, &values, sx, sy, &[("Software", GENERATOR.to_string()), ("Comment", provenance.clone())]);

    let axes = match lut.kind {
        SkinLutKind::Punctual { n_dot_l, .. } => json!([
            {"name": "n_dot_l", "texture_axis": "x", "range": [-1.0, 1.0], "count": n_dot_l, "mapping": "linear"},
            {"name": "curvature", "unit": "1/mm", "texture_axis": "y", "range": [0.0, lut.curvature_max], "count": lut.curvature_count, "mapping": lut.curvature_mapping.name(), "values": kappas},
        ]),
        SkinLutKind::Sh => json!([
            {"name": "curvature", "unit": "1/mm", "texture_axis": "x", "range": [0.0, lut.curvature_max], "count": lut.curvature_count, "mapping": lut.curvature_mapping.name(), "values": kappas},
            {"name": "band", "texture_axis": "y", "values": [1, 2]},
        ]),
    };
    let kernel = match lut.kind {
        SkinLutKind::Punctual { kernel: Kernel::Linear, .. } => "linear",
        SkinLutKind::Punctual { kernel: Kernel::Radial, .. } => "radial",
        SkinLutKind::Sh => "radial (sphere)",
    };
    let json = json!({
        "generator": GENERATOR,
        "spec": spec_rel_path(spec),
        "input_hash": hash,
        "name": name,
        "kind": "skin-lut",
        "quantity": lut.quantity,
        "description": lut.description,
        "function": lut.function,
        "profile": lut.profile.provenance(),
        "kernel": kernel,
        "tolerance": lut.tolerance,
        "axes": axes,
        "texture": {
            "width": w,
            "height": h,
            "format": lut.format.name(),
            "ktx2": format!("data/{name}.ktx2"),
            "preview": format!("data/{name}.png"),
            "encoding": "linear RGB, alpha 1, no tonemapping (the PNG preview is sRGB-encoded)",
            "max_abs_storage_error": storage,
        },
        "layout": "row-major, x fastest: values[y * width + x]",
        "channels": ["red", "green", "blue"],
        "range": [lo, hi],
        "quadrature": quadrature,
        "verification": verification,
        "values": values,
    });
    let artifacts = vec![
        Artifact { path: format!("wgsl/{name}.wgsl").into(), contents: wgsl.into() },
        Artifact { path: format!("src/{name}.rs").into(), contents: rust.into() },
        Artifact { path: format!("json/{name}.json").into(), contents: compact_json(&json).into() },
        Artifact { path: format!("data/{name}.ktx2").into(), contents: ktx2 },
        Artifact { path: format!("data/{name}.png").into(), contents: png },
    ];
    Ok((Built { name, artifacts, verification, fit: None }, texture))
}

fn code<'a>(lut: &'a SkinLut, name: &'a str, layout: Layout, values: &'a [[f32; 3]]) -> SkinLutCode<'a> {
    SkinLutCode {
        module: name,
        function: &lut.function,
        layout,
        curvature_max: lut.curvature_max,
        mapping: lut.curvature_mapping,
        format: lut.format,
        values,
    }
}

/// Preview scale: each texel a block of whole pixels, as many as fit in 256 across (at least
/// one); SH rows 16 times taller than wide.
fn preview_scale(layout: Layout) -> (usize, usize) {
    let (w, _) = layout.size();
    let s = (256 / w).max(1);
    match layout {
        Layout::Punctual { .. } => (s, s),
        Layout::Sh { .. } => (s, 16 * s),
    }
}

fn describe(lut: &SkinLut) -> String {
    let what = match lut.kind {
        SkinLutKind::Punctual { kernel, .. } => format!(
            "pre-integrated skin diffusion D(n·l, κ) for punctual lights ({} profile on a ring)",
            match kernel {
                Kernel::Linear => "linear",
                Kernel::Radial => "radial",
            }
        ),
        SkinLutKind::Sh => "factors k_1(κ), k_2(κ) scaling SH bands 1 and 2 of the irradiance (radial profile on a sphere)".into(),
    };
    let desc = if lut.description.is_empty() { String::new() } else { format!("{}: ", lut.description) };
    format!("{desc}`{}` looks up {what}, quantity `{}`.", lut.function, lut.quantity)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn input_hash_is_a_sha256_that_follows_the_spec_text() {
        let text = "name = \"skin_t\"\nkind = \"skin-lut\"\nquantity = \"skin-sh\"\nresolution = [6]\n\
             curvature_max = 2.0\ntolerance = 1e-9\n\n[emit]\nfunction = \"skin_t\"\n";
        let hash_of = |t: &str| {
            let spec = crate::spec::Spec::parse(Path::new("fits/skin_t.toml"), t.to_string(), crate::family::catalog()).unwrap();
            let lut = SkinLut::from_spec(&spec).unwrap();
            input_hash(&spec, &lut)
        };
        let h = hash_of(text);
        // "sha256:" and 32 bytes in lowercase hex (the header format of every generated file).
        let hex = h.strip_prefix("sha256:").unwrap_or_else(|| panic!("{h:?}"));
        assert!(hex.len() == 64 && hex.bytes().all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b)), "{h:?}");
        // Same text, same hash; an edited tolerance makes the generated files stale.
        assert_eq!(hash_of(text), h);
        assert_ne!(hash_of(&text.replace("1e-9", "1e-8")), h);
    }

    #[test]
    fn compact_json_keeps_numbers_on_one_line() {
        let v = json!({"a": [1.0, 2.5], "b": [[0.1, 0.2, 0.3], [1e-20, 2.0, -3.0]], "c": {"d": []}, "e": ["x", "y"]});
        let s = compact_json(&v);
        assert!(s.contains("\"a\": [1.0, 2.5],"), "{s}");
        assert!(s.contains("    [0.1, 0.2, 0.3],\n    [1e-20, 2.0, -3.0]\n"), "{s}");
        assert!(s.contains("\"x\",\n"), "{s}");
        let back: Value = serde_json::from_str(&s).unwrap();
        assert_eq!(back, v);
    }

    /// A small spec of each kind, built from scratch; its JSON's verification claims are then
    /// re-measured here from the JSON alone (texels, axes) against the integral evaluated point
    /// by point (`skin::punctual`, `skin::sh_band`), with this test's own interpolation; and the
    /// JSON read back in check mode renders the same artifacts.
    fn remeasure(text: &str) {
        let spec = crate::spec::Spec::parse(Path::new("fits/skin_t.toml"), text.to_string(), crate::family::catalog())
            .expect("a valid skin spec");
        let lut = SkinLut::from_spec(&spec).unwrap();
        let built = build(&spec, Mode::Fit, Path::new("")).unwrap();
        let json = built.artifacts.iter().find(|a| a.path.to_str().unwrap().ends_with(".json")).unwrap();
        let v: Value = serde_json::from_slice(&json.contents).unwrap();
        // The committed read-back: with this JSON alone written under a root, a check-mode build
        // renders every artifact again, byte for byte.
        let dir = tempfile::tempdir().unwrap();
        assert!(json.path.is_relative(), "{}", json.path.display());
        let at = dir.path().join(&json.path);
        std::fs::create_dir_all(at.parent().unwrap()).unwrap();
        std::fs::write(&at, &json.contents).unwrap();
        let again = build(&spec, Mode::Committed, dir.path()).unwrap();
        assert_eq!(again.artifacts.len(), built.artifacts.len());
        for (a, b) in built.artifacts.iter().zip(&again.artifacts) {
            assert!(a.path == b.path && a.contents == b.contents, "{} differs when read back", a.path.display());
        }
        let texels: Vec<[f64; 3]> = v["values"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| std::array::from_fn(|c| t[c].as_f64().unwrap()))
            .collect();
        let (w, h) = (v["texture"]["width"].as_u64().unwrap() as usize, v["texture"]["height"].as_u64().unwrap() as usize);
        let tol = tolerance(&lut);
        let p = &lut.profile.profile;
        // Fine grid: every texel and every midpoint, 2n − 1 points per axis of the mapped
        // coordinate (the grid the claims are stated on); at each point the texel coordinate
        // (x, y), the integral, and the interpolation in f64 and over the f32 texels.
        let n = lut.curvature_count;
        let kappa_at = |t: f64| skin::mapped_curvature(t, lut.curvature_max, lut.curvature_mapping);
        let lerp = |a: f64, b: f64, f: f64| a + (b - a) * f;
        let interp = |row: &[[f64; 3]], x: f64, c: usize| {
            let i = (x.floor() as usize).min(row.len() - 2);
            lerp(row[i][c], row[i + 1][c], x - i as f64)
        };
        let texel32 = |t: &[f64; 3]| t.map(|x| x as f32 as f64);
        let (mut max64, mut max32, mut ss64, mut ss32, mut count) = (0.0f64, 0.0f64, 0.0, 0.0, 0usize);
        let mut see = |approx: f64, approx32: f64, want: f64| {
            let (e, e32) = ((approx - want).abs(), (approx32 - want).abs());
            max64 = max64.max(e);
            max32 = max32.max(e32);
            ss64 += e * e;
            ss32 += e32 * e32;
            count += 1;
        };
        match lut.kind {
            SkinLutKind::Punctual { kernel, n_dot_l, .. } => {
                assert_eq!((w, h), (n_dot_l, n));
                let rows: Vec<Vec<[f64; 3]>> = texels.chunks(w).map(<[_]>::to_vec).collect();
                let rows32: Vec<Vec<[f64; 3]>> = rows.iter().map(|r| r.iter().map(texel32).collect()).collect();
                for b in 0..2 * n - 1 {
                    let kappa = kappa_at(b as f64 / (2 * n - 2) as f64);
                    let y = b as f64 / 2.0;
                    let j = (y.floor() as usize).min(n - 2);
                    for a in 0..2 * n_dot_l - 1 {
                        let nl = -1.0 + 2.0 * a as f64 / (2 * n_dot_l - 2) as f64;
                        let x = a as f64 / 2.0;
                        let want = skin::punctual(p, kernel, kappa, nl, tol).unwrap();
                        for c in 0..3 {
                            let two = |rs: &[Vec<[f64; 3]>]| lerp(interp(&rs[j], x, c), interp(&rs[j + 1], x, c), y - j as f64);
                            see(two(&rows), two(&rows32), want[c].value);
                        }
                    }
                }
            }
            SkinLutKind::Sh => {
                assert_eq!((w, h), (n, 2));
                for band in 1..=2u32 {
                    let row = &texels[(band as usize - 1) * n..band as usize * n];
                    let row32: Vec<[f64; 3]> = row.iter().map(texel32).collect();
                    for a in 0..2 * n - 1 {
                        let kappa = kappa_at(a as f64 / (2 * n - 2) as f64);
                        let want = skin::sh_band(p, kappa, band, tol).unwrap();
                        for c in 0..3 {
                            see(interp(row, a as f64 / 2.0, c), interp(&row32, a as f64 / 2.0, c), want[c].value);
                        }
                    }
                }
            }
        }
        let ver = &v["verification"];
        let claim = |k: &str| ver[k].as_f64().unwrap();
        assert_eq!(ver["points"].as_u64().unwrap() as usize * 3, count);
        // Both sides take the integral to the spec's tolerance (1e-9 per texel and point), and
        // the texels enter the interpolation with weights summing to 1: the f64 claims agree
        // with ours to 2·tol; interpolation order differs only by f64 rounding (1e-16).
        let bound64 = 2.0 * lut.tolerance + 1e-15;
        // The f32 lookup computes its coordinates in f32 (a few ulps of coordinates below 2n:
        // 1e-5 of a texel at most here) and interpolates in f32 (three roundings of values
        // ≤ 1: 2e-7): with texel steps ≤ 0.3 here, 1e-5 bounds the difference.
        let bound32 = bound64 + 1e-5;
        let rms = |ss: f64| (ss / count as f64).sqrt();
        for (k, ours, bound) in [
            ("max_abs_error", max64, bound64),
            ("rms_error", rms(ss64), bound64),
            ("max_abs_error_f32", max32, bound32),
            ("rms_error_f32", rms(ss32), bound32),
        ] {
            assert!((claim(k) - ours).abs() <= bound, "{k}: claimed {:e}, re-measured {ours:e}", claim(k));
        }
        // Not a vacuous comparison: interpolation on these coarse grids errs by far more than
        // the bounds above, and halving the claim would be visible.
        assert!(max64 > 100.0 * bound32, "{max64:e}");

        // The JSON's other figures, re-measured from its texels: their range, the f16 storage
        // error (the spec's default format, rounded here by the `half` crate), the curvature
        // axis (κ at t = j/(n − 1) of the spec's mapping), and each texel's quadrature estimate
        // within the spec's tolerance.
        let all = texels.iter().flat_map(|t| t.iter().copied());
        let (lo, hi) = all.clone().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
        assert_eq!((v["range"][0].as_f64().unwrap(), v["range"][1].as_f64().unwrap()), (lo, hi));
        assert_eq!(v["texture"]["format"], "rgba16float");
        let storage = all.map(|x| (half::f16::from_f64(x as f32 as f64).to_f64() - x).abs()).fold(0.0f64, f64::max);
        // f32 → f16 and f64 → f16 of an f32 agree (f16 values are exact in f32): exact.
        assert_eq!(v["texture"]["max_abs_storage_error"].as_f64().unwrap(), storage);
        assert!(storage > 0.0, "f16 rounds some texel");
        let axis = v["axes"].as_array().unwrap().iter().find(|a| a["name"] == "curvature").unwrap();
        let kappas: Vec<f64> = axis["values"].as_array().unwrap().iter().map(|k| k.as_f64().unwrap()).collect();
        assert_eq!(axis["count"].as_u64().unwrap() as usize, n);
        assert_eq!(kappas, (0..n).map(|j| kappa_at(j as f64 / (n - 1) as f64)).collect::<Vec<f64>>());
        let q = v["quadrature"]["max_error_estimate"].as_f64().unwrap();
        assert!(q > 0.0 && q <= lut.tolerance, "quadrature estimate {q:e} against tolerance {:e}", lut.tolerance);

        // The sRGB preview: each texel a block of whole pixels, as many as fit in 256 across
        // (at least one), and for SH rows 16 times taller than wide. The PNG's size is in its
        // IHDR chunk, big-endian at bytes 16..24.
        let png = &built.artifacts.iter().find(|a| a.path.to_str().unwrap().ends_with(".png")).unwrap().contents;
        let be = |at: usize| u32::from_be_bytes(png[at..at + 4].try_into().unwrap()) as usize;
        let (pw, ph) = (be(16), be(20));
        let s = pw / w;
        assert!(pw == s * w && s >= 1 && (s * w <= 256 || s == 1) && (s + 1) * w > 256, "preview {pw} px across {w} texels");
        let tall = if matches!(lut.kind, SkinLutKind::Sh) { 16 } else { 1 };
        assert_eq!(ph, h * s * tall, "preview height");

        // The code's doc says what it looks up: the function's name, the quantity, the kernel.
        let wgsl = std::str::from_utf8(&built.artifacts.iter().find(|a| a.path.to_str().unwrap().ends_with(".wgsl")).unwrap().contents).unwrap().to_string();
        let kernel = match lut.kind {
            SkinLutKind::Punctual { kernel: Kernel::Linear, .. } => "linear profile on a ring",
            SkinLutKind::Punctual { kernel: Kernel::Radial, .. } => "radial profile on a ring",
            SkinLutKind::Sh => "radial profile on a sphere",
        };
        for want in [format!("`{}` looks up", lut.function), format!("quantity `{}`", lut.quantity), kernel.to_string()] {
            assert!(wgsl.contains(&want), "the WGSL's doc lacks {want:?}");
        }
    }

    #[test]
    fn verification_claims_are_re_measured_punctual() {
        remeasure(
            "name = \"skin_t\"\nkind = \"skin-lut\"\nquantity = \"skin-punctual\"\nresolution = [9, 5]\n\
             curvature_max = 1.0\ncurvature_mapping = \"sqrt\"\nkernel = \"linear\"\ntolerance = 1e-9\n\n\
             [emit]\nfunction = \"skin_t\"\n",
        );
    }

    #[test]
    fn verification_claims_are_re_measured_sh() {
        remeasure(
            "name = \"skin_t\"\nkind = \"skin-lut\"\nquantity = \"skin-sh\"\nresolution = [6]\n\
             curvature_max = 2.0\ntolerance = 1e-9\n\n[emit]\nfunction = \"skin_t\"\n",
        );
    }

    #[test]
    fn bilinear_reproduces_planes() {
        let (w, h) = (4, 3);
        let v: Vec<[f64; 3]> = (0..w * h).map(|k| [(k % w) as f64, (k / w) as f64, 2.0]).collect();
        assert_eq!(bilinear(&v, (w, h), 1.5, 0.5), [1.5, 0.5, 2.0]);
        assert_eq!(bilinear(&v, (w, h), 3.0, 2.0), [3.0, 2.0, 2.0]);
        assert_eq!(bilinear(&v[..w], (w, 1), 2.5, 0.0), [2.5, 0.0, 2.0]);
    }
}
