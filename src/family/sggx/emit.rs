//! The run-time side as shader code: the spec kind `sggx-decode` (`fits/sggx_decode.toml`), one
//! WGSL library and one Rust module (no fit):
//!
//! - `PREFIX_decode(tex)`: the course's `DecodeSggx` on a sample of the aniso map (channels
//!   clamped to [0, 1], NaN → 0): α_t², α_b² clamped to [α_min², 1], α_t α_b, and cos ψ, sin ψ of
//!   the α_t axis in the normal-mapped frame (`Sign` read as ±1, see [`super::integrals::decode_course`]);
//! - `PREFIX_tangent(a, t, b)`, `PREFIX_bitangent(a, t, b)`: the rotated frame, c t + s b and
//!   −s t + c b;
//! - `PREFIX_d(a, t_dot_h, b_dot_h, n_dot_h)`: the anisotropic GGX NDF in the course's rearranged
//!   form (α_t α_b)³ / (π ((t·h)² α_b² + (b·h)² α_t² + (n·h)² (α_t α_b)²)²), with h in the rotated
//!   frame; its inputs clamped (dots to [−1, 1], α's to [α_min², 1]; NaN → the lower end) and the
//!   squared denominator kept ≥ 1e-30, so it is finite for every f32 input.
//!
//! The stored correlation is decoded as y + y − 1 (not 2y − 1): no product for a GPU to fuse,
//! so Sxy = 0 at y = ½ exactly on every device and the sign test agrees with the CPU's.
//!
//! The errors recorded are the f32 code's (the functions here, same operations as the emitted
//! ones) against the f64 formulas: the decode on a 65³ grid of channels (in α², cos, sin), D
//! relative to Burley's form on a grid of α pairs, axis angles and directions.

use super::integrals::{ALPHA_MIN, Aniso, d_burley, decode_course, direction};
use crate::emit::{f32_literal, header_lines};
use crate::family::SpecKind;
use crate::pipeline::module::{module_built, module_json};
use crate::pipeline::{BuildError, Built, Mode, committed_json_with_hash, fmt_err, input_hash, spec_rel_path};
use crate::spec::{KindDef, Spec, SpecError, SpecFile, module_spec_file};
use serde_json::json;
use std::path::Path;

pub const KIND: &str = "sggx-decode";

/// The spec kind (registered in the family's descriptor).
pub const DECODE: SpecKind = SpecKind {
    spec: KindDef { name: KIND, spec_file, samples_note: "{name} emits the course's decoder and NDF (exact formulas): it has no samples", input_hash },
    build,
    shard: None,
};

/// For `Spec::parse`: the common spec of a decoder spec, or `None`.
pub fn spec_file(path: &Path, text: &str) -> Result<Option<SpecFile>, SpecError> {
    // No samples: the quantity's parameters at their ends, as the common schema wants them.
    let axes = super::QUANTITIES[0].params.iter().map(|p| json!({"name": p.name, "range": [p.min, p.max], "count": 2, "verify": 2})).collect();
    module_spec_file(path, text, KIND, "sggx-filter", 1e-6, axes)
}

/// What `PREFIX_decode` returns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Decoded32 {
    pub alpha_t_sqr: f32,
    pub alpha_b_sqr: f32,
    pub alpha_tb: f32,
    pub cos_psi: f32,
    pub sin_psi: f32,
}

fn input(v: f32, lo: f32, hi: f32) -> f32 {
    if v.is_nan() { lo } else { v.clamp(lo, hi) }
}

const ALPHA_MIN_SQR: f32 = (ALPHA_MIN * ALPHA_MIN) as f32;

/// The emitted decoder, operation for operation.
pub fn decode_f32(tex: [f32; 3]) -> Decoded32 {
    let x = input(tex[0], 0.0, 1.0);
    let y = input(tex[1], 0.0, 1.0);
    let z = input(tex[2], 0.0, 1.0);
    let sxx = x * x;
    let sxy = x * (y + y - 1.0) * z;
    let syy = z * z;
    let discr = (4.0 * (sxy * sxy) + (sxx - syy) * (sxx - syy)).sqrt();
    let discr_rcp = 1.0 / discr.max(1e-6);
    let alpha_t_sqr = (0.5 * (sxx + syy + discr)).clamp(0.0, 1.0).max(ALPHA_MIN_SQR);
    let alpha_b_sqr = (0.5 * (sxx + syy - discr)).clamp(0.0, 1.0).max(ALPHA_MIN_SQR);
    let c_sqr = (0.5 * ((sxx - syy) * discr_rcp + 1.0)).clamp(0.0, 1.0);
    let sign = if sxy < 0.0 { -1.0 } else { 1.0 };
    Decoded32 { alpha_t_sqr, alpha_b_sqr, alpha_tb: (alpha_t_sqr * alpha_b_sqr).sqrt(), cos_psi: c_sqr.sqrt(), sin_psi: sign * (1.0 - c_sqr).sqrt() }
}

/// The emitted NDF, operation for operation.
pub fn d_f32(a: &Decoded32, th: f32, bh: f32, nh: f32) -> f32 {
    let at2 = input(a.alpha_t_sqr, ALPHA_MIN_SQR, 1.0);
    let ab2 = input(a.alpha_b_sqr, ALPHA_MIN_SQR, 1.0);
    let atb = input(a.alpha_tb, ALPHA_MIN_SQR, 1.0);
    let th = input(th, -1.0, 1.0);
    let bh = input(bh, -1.0, 1.0);
    let nh = input(nh, -1.0, 1.0);
    let den = th * th * ab2 + bh * bh * at2 + nh * nh * (atb * atb);
    atb * atb * atb / (std::f32::consts::PI * (den * den).max(1e-30))
}

/// Max |f32 − f64| of the decode (α², cos, sin) over 65³ channel triples, and max relative
/// |f32 − f64|/f64 of D over α pairs × axis angles × directions; point counts.
fn measure() -> ([f64; 2], usize) {
    let axis: Vec<f64> = (0..=64).map(|i| i as f64 / 64.0).collect();
    let mut dec: f64 = 0.0;
    for &x in &axis {
        for &y in &axis {
            for &z in &axis {
                let t32 = [x as f32, y as f32, z as f32];
                let got = decode_f32(t32);
                let want = decode_course(t32.map(|v| v as f64), ALPHA_MIN);
                // cos ψ, sin ψ are ill-conditioned where the eigenvalues meet (discr → 0: any
                // axis is right); measured where discr ≥ 1e-3.
                let a = super::integrals::decode_matrix(t32.map(|v| v as f64));
                let discr = (4.0 * a.sxy * a.sxy + (a.sxx - a.syy).powi(2)).sqrt();
                let mut e = (got.alpha_t_sqr as f64 - want.alpha_t_sqr).abs().max((got.alpha_b_sqr as f64 - want.alpha_b_sqr).abs()).max((got.alpha_tb as f64 - want.alpha_tb).abs());
                if discr >= 1e-3 {
                    e = e.max((got.cos_psi as f64 - want.cos).abs()).max((got.sin_psi as f64 - want.sin).abs());
                }
                dec = dec.max(e);
            }
        }
    }
    let alphas = [0.001, 0.01, 0.04, 0.1, 0.29, 0.5, 0.87, 1.0];
    let mut d: f64 = 0.0;
    let mut n = 0;
    for &at in &alphas {
        for &ab in &alphas {
            for i in 0..16 {
                for j in 0..32 {
                    let h = direction(std::f64::consts::FRAC_PI_2 * i as f64 / 15.0, std::f64::consts::TAU * j as f64 / 32.0);
                    let a = Decoded32 { alpha_t_sqr: (at * at) as f32, alpha_b_sqr: (ab * ab) as f32, alpha_tb: (at * ab) as f32, cos_psi: 1.0, sin_psi: 0.0 };
                    let (a64, b64) = ((a.alpha_t_sqr as f64).sqrt(), (a.alpha_b_sqr as f64).sqrt());
                    let h32 = [h.x as f32, h.y as f32, h.z as f32];
                    let got = d_f32(&a, h32[0], h32[1], h32[2]) as f64;
                    let want = d_burley(h32[0] as f64, h32[1] as f64, h32[2] as f64, a64, b64);
                    d = d.max((got / want - 1.0).abs());
                    n += 1;
                }
            }
        }
    }
    ([dec, d], axis.len().pow(3) + n)
}

fn lit(v: f64, wgsl: bool) -> String {
    let s = f32_literal(v as f32);
    if wgsl { format!("{s}f") } else { format!("{s}_f32") }
}

fn render_wgsl(header: &[String], module: &str, p: &str, errs: [f64; 2]) -> String {
    let amin2 = lit(ALPHA_MIN * ALPHA_MIN, true);
    let pi = lit(std::f64::consts::PI, true);
    let mut s = String::new();
    for line in header {
        s += &format!("// {line}\n");
    }
    s += &format!("#define_import_path shadefit::{module}\n\n");
    s += &format!(
        "// SGGX-encoded anisotropic roughness (Ghost of Tsushima): the course's DecodeSggx and the\n\
         // anisotropic GGX NDF in its rearranged form. Exact formulas; inputs clamped, NaN -> the\n\
         // lower end; finite for every input.\n\n\
         // Clamp an input to [lo, hi]; NaN (any exponent-all-ones pattern with a non-zero\n\
         // mantissa) maps to lo.\n\
         fn {module}_input(v: f32, lo: f32, hi: f32) -> f32 {{\n    let nan = (bitcast<u32>(v) & 0x7fffffffu) > 0x7f800000u;\n    return select(clamp(v, lo, hi), lo, nan);\n}}\n\n\
         // What {p}_decode returns: alpha_t^2 >= alpha_b^2 in [alpha_min^2, 1], their geometric mean\n\
         // alpha_t alpha_b, and the cosine and sine of the alpha_t axis's angle from the normal-mapped tangent.\n\
         struct SggxAniso {{\n    alpha_t_sqr: f32,\n    alpha_b_sqr: f32,\n    alpha_tb: f32,\n    cos_psi: f32,\n    sin_psi: f32,\n}}\n\n\
         // DecodeSggx: tex = the aniso map's [sqrt(Sxx), Sxy/sqrt(Sxx Syy)/2 + 1/2, sqrt(Syy)]; the 2x2\n\
         // matrix's eigenvalues clamped to [alpha_min^2, 1] (alpha_min = {ALPHA_MIN}), which guards the\n\
         // singular matrices that filtering the stored channels produces. Sign(Sxy) is +-1 (never 0).\n\
         // f32 code against the formula in f64: max abs {} (alpha^2, cos, sin; 65^3 channel triples).\n\
         fn {p}_decode(tex: vec3<f32>) -> SggxAniso {{\n\
         \x20   let x = {module}_input(tex.x, 0f, 1f);\n\
         \x20   let y = {module}_input(tex.y, 0f, 1f);\n\
         \x20   let z = {module}_input(tex.z, 0f, 1f);\n\
         \x20   let sxx = x * x;\n\
         \x20   let sxy = x * (y + y - 1f) * z;\n\
         \x20   let syy = z * z;\n\
         \x20   let discr = sqrt(4f * (sxy * sxy) + (sxx - syy) * (sxx - syy));\n\
         \x20   let discr_rcp = 1f / max(discr, 1e-6f);\n\
         \x20   let alpha_t_sqr = max(clamp(0.5f * (sxx + syy + discr), 0f, 1f), {amin2});\n\
         \x20   let alpha_b_sqr = max(clamp(0.5f * (sxx + syy - discr), 0f, 1f), {amin2});\n\
         \x20   let c_sqr = clamp(0.5f * ((sxx - syy) * discr_rcp + 1f), 0f, 1f);\n\
         \x20   let sign = select(1f, -1f, sxy < 0f);\n\
         \x20   return SggxAniso(alpha_t_sqr, alpha_b_sqr, sqrt(alpha_t_sqr * alpha_b_sqr), sqrt(c_sqr), sign * sqrt(1f - c_sqr));\n\
         }}\n\n\
         // The anisotropic tangent c t + s b (t, b: the normal-mapped tangent and bitangent).\n\
         fn {p}_tangent(a: SggxAniso, t: vec3<f32>, b: vec3<f32>) -> vec3<f32> {{\n    return a.cos_psi * t + a.sin_psi * b;\n}}\n\n\
         // The anisotropic bitangent -s t + c b.\n\
         fn {p}_bitangent(a: SggxAniso, t: vec3<f32>, b: vec3<f32>) -> vec3<f32> {{\n    return -a.sin_psi * t + a.cos_psi * b;\n}}\n\n\
         // Anisotropic GGX D(h) = (at ab)^3 / (pi ((t.h)^2 ab^2 + (b.h)^2 at^2 + (n.h)^2 (at ab)^2)^2), h's\n\
         // components in the anisotropic frame (t, b from {p}_tangent/{p}_bitangent). Dots clamped to\n\
         // [-1, 1], alphas to [alpha_min^2, 1]; the squared denominator kept >= 1e-30.\n\
         // f32 code against Burley's form in f64: max relative {}.\n\
         fn {p}_d(a: SggxAniso, t_dot_h: f32, b_dot_h: f32, n_dot_h: f32) -> f32 {{\n\
         \x20   let at2 = {module}_input(a.alpha_t_sqr, {amin2}, 1f);\n\
         \x20   let ab2 = {module}_input(a.alpha_b_sqr, {amin2}, 1f);\n\
         \x20   let atb = {module}_input(a.alpha_tb, {amin2}, 1f);\n\
         \x20   let th = {module}_input(t_dot_h, -1f, 1f);\n\
         \x20   let bh = {module}_input(b_dot_h, -1f, 1f);\n\
         \x20   let nh = {module}_input(n_dot_h, -1f, 1f);\n\
         \x20   let den = th * th * ab2 + bh * bh * at2 + nh * nh * (atb * atb);\n\
         \x20   return atb * atb * atb / ({pi} * max(den * den, 1e-30f));\n\
         }}\n",
        fmt_err(errs[0]),
        fmt_err(errs[1]),
    );
    s
}

fn render_rust(header: &[String], p: &str, errs: [f64; 2]) -> String {
    let amin2 = lit(ALPHA_MIN * ALPHA_MIN, false);
    let mut s = String::new();
    for line in header {
        s += &format!("//! {line}\n");
    }
    s += &format!(
        "//!\n//! SGGX-encoded anisotropic roughness (Ghost of Tsushima): the course's DecodeSggx and the\n\
         //! anisotropic GGX NDF in its rearranged form. Exact formulas; inputs clamped, NaN -> the\n\
         //! lower end; finite for every input.\n//! CPU versions of the WGSL functions of the same names.\n\n\
         #[inline]\nfn input(v: f32, lo: f32, hi: f32) -> f32 {{\n    if v.is_nan() {{ lo }} else {{ v.clamp(lo, hi) }}\n}}\n\n\
         /// What [`{p}_decode`] returns: α_t² ≥ α_b² in [α_min², 1], α_t α_b, and the cosine and sine of\n\
         /// the α_t axis's angle from the normal-mapped tangent.\n\
         #[derive(Debug, Clone, Copy, PartialEq)]\n\
         pub struct SggxAniso {{\n    pub alpha_t_sqr: f32,\n    pub alpha_b_sqr: f32,\n    pub alpha_tb: f32,\n    pub cos_psi: f32,\n    pub sin_psi: f32,\n}}\n\n\
         /// DecodeSggx: `tex` = the aniso map's [√Sxx, ½ Sxy/√(Sxx Syy) + ½, √Syy]; eigenvalues clamped\n\
         /// to [α_min², 1] (α_min = {ALPHA_MIN}); Sign(Sxy) is ±1 (never 0).\n\
         /// f32 code against the formula in f64: max abs {} (α², cos, sin; 65³ channel triples).\n\
         pub fn {p}_decode(tex: [f32; 3]) -> SggxAniso {{\n\
         \x20   let x = input(tex[0], 0.0, 1.0);\n\
         \x20   let y = input(tex[1], 0.0, 1.0);\n\
         \x20   let z = input(tex[2], 0.0, 1.0);\n\
         \x20   let sxx = x * x;\n\
         \x20   let sxy = x * (y + y - 1.0) * z;\n\
         \x20   let syy = z * z;\n\
         \x20   let discr = (4.0 * (sxy * sxy) + (sxx - syy) * (sxx - syy)).sqrt();\n\
         \x20   let discr_rcp = 1.0 / discr.max(1e-6);\n\
         \x20   let alpha_t_sqr = (0.5 * (sxx + syy + discr)).clamp(0.0, 1.0).max({amin2});\n\
         \x20   let alpha_b_sqr = (0.5 * (sxx + syy - discr)).clamp(0.0, 1.0).max({amin2});\n\
         \x20   let c_sqr = (0.5 * ((sxx - syy) * discr_rcp + 1.0)).clamp(0.0, 1.0);\n\
         \x20   let sign = if sxy < 0.0 {{ -1.0 }} else {{ 1.0 }};\n\
         \x20   SggxAniso {{ alpha_t_sqr, alpha_b_sqr, alpha_tb: (alpha_t_sqr * alpha_b_sqr).sqrt(), cos_psi: c_sqr.sqrt(), sin_psi: sign * (1.0 - c_sqr).sqrt() }}\n\
         }}\n\n\
         /// The anisotropic tangent c t + s b.\n\
         pub fn {p}_tangent(a: &SggxAniso, t: [f32; 3], b: [f32; 3]) -> [f32; 3] {{\n    [0, 1, 2].map(|i| a.cos_psi * t[i] + a.sin_psi * b[i])\n}}\n\n\
         /// The anisotropic bitangent −s t + c b.\n\
         pub fn {p}_bitangent(a: &SggxAniso, t: [f32; 3], b: [f32; 3]) -> [f32; 3] {{\n    [0, 1, 2].map(|i| -a.sin_psi * t[i] + a.cos_psi * b[i])\n}}\n\n\
         /// Anisotropic GGX D(h) = (α_t α_b)³ / (π ((t·h)² α_b² + (b·h)² α_t² + (n·h)² (α_t α_b)²)²), h in the\n\
         /// anisotropic frame; dots clamped to [−1, 1], α's to [α_min², 1], the squared denominator ≥ 1e-30.\n\
         /// f32 code against Burley's form in f64: max relative {}.\n\
         pub fn {p}_d(a: &SggxAniso, t_dot_h: f32, b_dot_h: f32, n_dot_h: f32) -> f32 {{\n\
         \x20   let at2 = input(a.alpha_t_sqr, {amin2}, 1.0);\n\
         \x20   let ab2 = input(a.alpha_b_sqr, {amin2}, 1.0);\n\
         \x20   let atb = input(a.alpha_tb, {amin2}, 1.0);\n\
         \x20   let th = input(t_dot_h, -1.0, 1.0);\n\
         \x20   let bh = input(b_dot_h, -1.0, 1.0);\n\
         \x20   let nh = input(n_dot_h, -1.0, 1.0);\n\
         \x20   let den = th * th * ab2 + bh * bh * at2 + nh * nh * (atb * atb);\n\
         \x20   atb * atb * atb / (std::f32::consts::PI * (den * den).max(1e-30))\n\
         }}\n",
        fmt_err(errs[0]),
        fmt_err(errs[1]),
    );
    s
}

fn build(spec: &Spec, mode: Mode, root: &Path) -> Result<Built, BuildError> {
    let name = spec.file.name.clone();
    let prefix = spec.file.emit.function.clone();
    let hash = input_hash(spec);
    let (errs, points) = match mode {
        Mode::Fit => measure(),
        Mode::Committed => {
            let v = committed_json_with_hash(root, spec, &hash)?;
            let bad = |why: &str| BuildError::NoCommitted { spec: name.clone(), why: why.into() };
            let dec = v["decode_max_abs_error_f32"].as_f64().ok_or_else(|| bad("no decode_max_abs_error_f32"))?;
            let d = v["d_max_relative_error_f32"].as_f64().ok_or_else(|| bad("no d_max_relative_error_f32"))?;
            let points = v["points"].as_u64().ok_or_else(|| bad("no points"))? as usize;
            ([dec, d], points)
        }
    };
    let err_line = format!(
        "decode max abs {}, D max relative {} (f32 code against the formulas in f64, {points} points)",
        fmt_err(errs[0]),
        fmt_err(errs[1])
    );
    let header = header_lines(&spec_rel_path(spec), &hash, &err_line);
    let mut json = module_json(spec, &hash, KIND);
    json.insert("points".into(), points.into());
    json.insert("alpha_min".into(), ALPHA_MIN.into());
    json.insert("decode_max_abs_error_f32".into(), errs[0].into());
    json.insert("d_max_relative_error_f32".into(), errs[1].into());
    json.insert("functions".into(), json!(["decode", "tangent", "bitangent", "d"].map(|f| format!("{prefix}_{f}"))));
    Ok(module_built(&name, render_wgsl(&header, &name, &prefix, errs), render_rust(&header, &prefix, errs), json, points, errs[0], 0.0))
}

/// The matrix a decoded texel describes, in f64 (for tests).
pub fn decoded_aniso(d: &Decoded32) -> Aniso {
    let (c, s) = (d.cos_psi as f64, d.sin_psi as f64);
    let (a, b) = (d.alpha_t_sqr as f64, d.alpha_b_sqr as f64);
    Aniso { sxx: c * c * a + s * s * b, sxy: c * s * (a - b), syy: s * s * a + c * c * b }
}

#[cfg(test)]
mod tests {
    use super::*;
    use shadefit_runtime::sggx_decode as g;

    fn specials() -> Vec<f32> {
        let mut v = vec![f32::NAN, -f32::NAN, f32::INFINITY, f32::NEG_INFINITY, f32::MAX, f32::MIN, 0.0, -0.0, f32::MIN_POSITIVE, -f32::MIN_POSITIVE, 1e-45, -1e-45, 1.0, -1.0, 0.5, 2.0, 1e-3, 1e-6, 1e30];
        v.extend((0..=8).map(|i| i as f32 / 8.0));
        v
    }

    #[test]
    fn emitted_functions_are_the_f32_code_measured_and_finite_for_every_input() {
        // The emitted Rust module against the f32 code the build measured: same operations in
        // the same order, so bit for bit; and finite (never NaN or ∞) on every combination of
        // special and ordinary values.
        let sp = specials();
        for &x in &sp {
            for &y in &sp {
                for &z in &sp {
                    let e = g::sggx_decode([x, y, z]);
                    let m = decode_f32([x, y, z]);
                    assert_eq!([e.alpha_t_sqr, e.alpha_b_sqr, e.alpha_tb, e.cos_psi, e.sin_psi].map(f32::to_bits), [m.alpha_t_sqr, m.alpha_b_sqr, m.alpha_tb, m.cos_psi, m.sin_psi].map(f32::to_bits));
                    assert!([e.alpha_t_sqr, e.alpha_b_sqr, e.alpha_tb, e.cos_psi, e.sin_psi].iter().all(|v| v.is_finite()), "decode({x}, {y}, {z}) = {e:?}");
                    // D with the decoded values and with garbage in the struct.
                    let garbage = g::SggxAniso { alpha_t_sqr: x, alpha_b_sqr: y, alpha_tb: z, cos_psi: 0.0, sin_psi: 0.0 };
                    for a in [e, garbage] {
                        let d = g::sggx_d(&a, x, y, z);
                        let m32 = Decoded32 { alpha_t_sqr: a.alpha_t_sqr, alpha_b_sqr: a.alpha_b_sqr, alpha_tb: a.alpha_tb, cos_psi: a.cos_psi, sin_psi: a.sin_psi };
                        assert_eq!(d.to_bits(), d_f32(&m32, x, y, z).to_bits());
                        assert!(d.is_finite() && d >= 0.0, "D({a:?}, {x}, {y}, {z}) = {d}");
                    }
                }
            }
        }
    }

    #[test]
    fn emitted_decoder_recovers_stored_matrices() {
        // 8-bit channels of random blocks, decoded by the emitted f32 code against the f64
        // decoder on the same channels. α² are sums of a few roundings of values ≤ 1 (1e-6).
        // The axis is not: sin ψ = √(1 − cos²ψ) cancels for nearly aligned lobes, where 1 − c²
        // carries an absolute f32 error ~2^-24, so sin ψ is off by up to √(2^-24) ≈ 2.4e-4 and
        // Sxy = cs(α_t² − α_b²) by as much (skipped where discr < 1e-2, the axis undefined).
        let mut rng = crate::integrate::rng::SplitMix64(23);
        let mut worst: f64 = 0.0;
        for _ in 0..20_000 {
            let a = Aniso::from_alphas(rng.next_f64(), rng.next_f64(), 6.3 * rng.next_f64());
            let t = super::super::integrals::quantize(super::super::integrals::encode(a), 8);
            let m = super::super::integrals::decode_matrix(t);
            if (4.0 * m.sxy * m.sxy + (m.sxx - m.syy).powi(2)).sqrt() < 1e-2 {
                continue;
            }
            let e = g::sggx_decode(t.map(|v| v as f32));
            let got = decoded_aniso(&Decoded32 { alpha_t_sqr: e.alpha_t_sqr, alpha_b_sqr: e.alpha_b_sqr, alpha_tb: e.alpha_tb, cos_psi: e.cos_psi, sin_psi: e.sin_psi });
            let want = decode_course(t, ALPHA_MIN).aniso();
            assert!((e.alpha_t_sqr as f64 - decode_course(t, ALPHA_MIN).alpha_t_sqr).abs() < 1e-6);
            assert!((e.alpha_b_sqr as f64 - decode_course(t, ALPHA_MIN).alpha_b_sqr).abs() < 1e-6);
            assert!(got.max_diff(&want) < 3e-4, "{got:?} vs {want:?}");
            worst = worst.max(got.max_diff(&want));
        }
        println!("emitted decoder on 8-bit channels: max |ΔS| {worst:.2e} against f64");
    }
}
