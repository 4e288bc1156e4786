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
//! The decoder and D are written once, as programs ([`super::integrals::DECODE_FORM`], a
//! [`Record`](crate::fit::expr::program::Record) returning `SggxAniso`, and
//! [`super::integrals::D_FORM`]): their WGSL and Rust bodies, the struct's declaration, the f32
//! evaluation here ([`decode_f32`], [`d_f32`]) and the f64 formulas derive from them; the
//! arguments pass through the module's input helper first ([`DECODE_INPUTS`], [`D_INPUTS`]).
//!
//! The errors recorded are the f32 code's (the functions here, same operations as the emitted
//! ones) against the f64 formulas: the decode on a 65³ grid of channels (in α², cos, sin), D
//! relative to Burley's form on a grid of α pairs, axis angles and directions.

use super::integrals::{ALPHA_MIN, Aniso, D_CONSTS, D_FORM, DECODE_FORM, d_burley, decode_consts, decode_course, direction};
use crate::emit::{f32_literal, header_lines};
use crate::fit::expr::program::short_literal;
use crate::fit::expr::{Syntax, sanitize};
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

/// An argument of an emitted function as its body reads it: its spelling in WGSL and in Rust,
/// clamped to [lo, hi] by the module's input helper (NaN → lo) before the program sees it.
struct Input {
    wgsl: &'static str,
    rust: &'static str,
    lo: f32,
    hi: f32,
}

const ALPHA_MIN_SQR: f32 = (ALPHA_MIN * ALPHA_MIN) as f32;

const fn arg(wgsl: &'static str, rust: &'static str, lo: f32, hi: f32) -> Input {
    Input { wgsl, rust, lo, hi }
}

/// [`DECODE_FORM`]'s inputs: the three channels in [0, 1].
const DECODE_INPUTS: [Input; 3] = [arg("tex.x", "tex[0]", 0.0, 1.0), arg("tex.y", "tex[1]", 0.0, 1.0), arg("tex.z", "tex[2]", 0.0, 1.0)];

/// [`D_FORM`]'s inputs: the decoded α's in [α_min², 1], the dots in [−1, 1].
const D_INPUTS: [Input; 6] = [
    arg("a.alpha_t_sqr", "a.alpha_t_sqr", ALPHA_MIN_SQR, 1.0),
    arg("a.alpha_b_sqr", "a.alpha_b_sqr", ALPHA_MIN_SQR, 1.0),
    arg("a.alpha_tb", "a.alpha_tb", ALPHA_MIN_SQR, 1.0),
    arg("t_dot_h", "t_dot_h", -1.0, 1.0),
    arg("b_dot_h", "b_dot_h", -1.0, 1.0),
    arg("n_dot_h", "n_dot_h", -1.0, 1.0),
];

/// The arguments clamped as the emitted input helper clamps them.
fn clamped(inputs: &[Input], v: &[f32]) -> Vec<f32> {
    inputs.iter().zip(v).map(|(i, &x)| sanitize(x, i.lo, i.hi)).collect()
}

fn decode_consts_f32() -> [f32; 2] {
    decode_consts(ALPHA_MIN).map(|c| c as f32)
}

/// The emitted decoder: [`DECODE_FORM`] in f32 on the clamped channels.
pub fn decode_f32(tex: [f32; 3]) -> Decoded32 {
    let v = DECODE_FORM.eval_f32(&clamped(&DECODE_INPUTS, &tex), &decode_consts_f32());
    Decoded32 { alpha_t_sqr: v[0], alpha_b_sqr: v[1], alpha_tb: v[2], cos_psi: v[3], sin_psi: v[4] }
}

/// The emitted NDF: [`D_FORM`] in f32 on the clamped arguments.
pub fn d_f32(a: &Decoded32, th: f32, bh: f32, nh: f32) -> f32 {
    D_FORM.eval_f32(&clamped(&D_INPUTS, &[a.alpha_t_sqr, a.alpha_b_sqr, a.alpha_tb, th, bh, nh]), &D_CONSTS.map(|c| c as f32))[0]
}

/// A body of the emitted code, in WGSL or Rust: its arguments through the input helper
/// (`module`'s in WGSL, `input` in Rust), its constants with round-trip digits.
fn body(syntax: Syntax, module: &str, inputs: &[Input], render: impl Fn(&dyn Fn(usize) -> String, &dyn Fn(f32) -> String) -> String) -> String {
    let short = |v: f32| short_literal(syntax, v);
    let input = |i: usize| {
        let a = &inputs[i];
        match syntax {
            Syntax::Wgsl => format!("{module}_input({}, {}, {})", a.wgsl, short(a.lo), short(a.hi)),
            Syntax::Rust => format!("input({}, {}, {})", a.rust, short(a.lo), short(a.hi)),
        }
    };
    let constant = |v: f32| match syntax {
        Syntax::Wgsl => format!("{}f", f32_literal(v)),
        Syntax::Rust => format!("{}_f32", f32_literal(v)),
    };
    render(&input, &constant)
}

fn decode_body(syntax: Syntax, module: &str) -> String {
    body(syntax, module, &DECODE_INPUTS, |input, constant| DECODE_FORM.render(syntax, input, &decode_consts_f32(), constant))
}

fn d_body(syntax: Syntax, module: &str) -> String {
    body(syntax, module, &D_INPUTS, |input, constant| D_FORM.render(syntax, input, &D_CONSTS.map(|c| c as f32), constant))
}

/// The declaration of the struct [`DECODE_FORM`] returns, its fields scalars (`pub` in Rust).
fn decoded_struct(syntax: Syntax) -> String {
    let f = &*DECODE_FORM;
    assert!(f.widths().iter().all(|&w| w == 1), "SggxAniso's fields are scalars");
    let vis = if syntax == Syntax::Rust { "pub " } else { "" };
    let fields: String = f.fields.iter().map(|(name, _)| format!("    {vis}{name}: f32,\n")).collect();
    format!("{vis}struct {} {{\n{fields}}}\n", f.name)
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

fn render_wgsl(header: &[String], module: &str, p: &str, errs: [f64; 2]) -> String {
    let (record, decode, d) = (decoded_struct(Syntax::Wgsl), decode_body(Syntax::Wgsl, module), d_body(Syntax::Wgsl, module));
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
         {record}\n\
         // DecodeSggx: tex = the aniso map's [sqrt(Sxx), Sxy/sqrt(Sxx Syy)/2 + 1/2, sqrt(Syy)]; the 2x2\n\
         // matrix's eigenvalues clamped to [alpha_min^2, 1] (alpha_min = {ALPHA_MIN}), which guards the\n\
         // singular matrices that filtering the stored channels produces. Sign(Sxy) is +-1 (never 0).\n\
         // f32 code against the formula in f64: max abs {} (alpha^2, cos, sin; 65^3 channel triples).\n\
         fn {p}_decode(tex: vec3<f32>) -> SggxAniso {{\n{decode}}}\n\n\
         // The anisotropic tangent c t + s b (t, b: the normal-mapped tangent and bitangent).\n\
         fn {p}_tangent(a: SggxAniso, t: vec3<f32>, b: vec3<f32>) -> vec3<f32> {{\n    return a.cos_psi * t + a.sin_psi * b;\n}}\n\n\
         // The anisotropic bitangent -s t + c b.\n\
         fn {p}_bitangent(a: SggxAniso, t: vec3<f32>, b: vec3<f32>) -> vec3<f32> {{\n    return -a.sin_psi * t + a.cos_psi * b;\n}}\n\n\
         // Anisotropic GGX D(h) = (at ab)^3 / (pi ((t.h)^2 ab^2 + (b.h)^2 at^2 + (n.h)^2 (at ab)^2)^2), h's\n\
         // components in the anisotropic frame (t, b from {p}_tangent/{p}_bitangent). Dots clamped to\n\
         // [-1, 1], alphas to [alpha_min^2, 1]; the squared denominator kept >= 1e-30.\n\
         // f32 code against Burley's form in f64: max relative {}.\n\
         fn {p}_d(a: SggxAniso, t_dot_h: f32, b_dot_h: f32, n_dot_h: f32) -> f32 {{\n{d}}}\n",
        fmt_err(errs[0]),
        fmt_err(errs[1]),
    );
    s
}

fn render_rust(header: &[String], p: &str, errs: [f64; 2]) -> String {
    let (record, decode, d) = (decoded_struct(Syntax::Rust), decode_body(Syntax::Rust, ""), d_body(Syntax::Rust, ""));
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
         {record}\n\
         /// DecodeSggx: `tex` = the aniso map's [√Sxx, ½ Sxy/√(Sxx Syy) + ½, √Syy]; eigenvalues clamped\n\
         /// to [α_min², 1] (α_min = {ALPHA_MIN}); Sign(Sxy) is ±1 (never 0).\n\
         /// f32 code against the formula in f64: max abs {} (α², cos, sin; 65³ channel triples).\n\
         pub fn {p}_decode(tex: [f32; 3]) -> SggxAniso {{\n{decode}}}\n\n\
         /// The anisotropic tangent c t + s b.\n\
         pub fn {p}_tangent(a: &SggxAniso, t: [f32; 3], b: [f32; 3]) -> [f32; 3] {{\n    [0, 1, 2].map(|i| a.cos_psi * t[i] + a.sin_psi * b[i])\n}}\n\n\
         /// The anisotropic bitangent −s t + c b.\n\
         pub fn {p}_bitangent(a: &SggxAniso, t: [f32; 3], b: [f32; 3]) -> [f32; 3] {{\n    [0, 1, 2].map(|i| -a.sin_psi * t[i] + a.cos_psi * b[i])\n}}\n\n\
         /// Anisotropic GGX D(h) = (α_t α_b)³ / (π ((t·h)² α_b² + (b·h)² α_t² + (n·h)² (α_t α_b)²)²), h in the\n\
         /// anisotropic frame; dots clamped to [−1, 1], α's to [α_min², 1], the squared denominator ≥ 1e-30.\n\
         /// f32 code against Burley's form in f64: max relative {}.\n\
         pub fn {p}_d(a: &SggxAniso, t_dot_h: f32, b_dot_h: f32, n_dot_h: f32) -> f32 {{\n{d}}}\n",
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

/// The scalar wrappers the runtime's interpreter and GPU tests call the decoder and D through.
#[cfg(test)]
#[path = "../../../generated/tests/support/sggx.rs"]
mod runtime_wrappers;

#[cfg(test)]
mod tests {
    use super::*;
    use shadefit_runtime::sggx_decode as g;

    /// The decoder and D as written by hand before they were programs (the committed f32 code,
    /// operation for operation, with Rust's `clamp`): the reference the programs are held to.
    mod by_hand {
        use super::super::ALPHA_MIN_SQR;

        fn input(v: f32, lo: f32, hi: f32) -> f32 {
            if v.is_nan() { lo } else { v.clamp(lo, hi) }
        }

        pub fn decode(tex: [f32; 3]) -> [f32; 5] {
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
            [alpha_t_sqr, alpha_b_sqr, (alpha_t_sqr * alpha_b_sqr).sqrt(), c_sqr.sqrt(), sign * (1.0 - c_sqr).sqrt()]
        }

        pub fn d(a: [f32; 3], th: f32, bh: f32, nh: f32) -> f32 {
            let at2 = input(a[0], ALPHA_MIN_SQR, 1.0);
            let ab2 = input(a[1], ALPHA_MIN_SQR, 1.0);
            let atb = input(a[2], ALPHA_MIN_SQR, 1.0);
            let th = input(th, -1.0, 1.0);
            let bh = input(bh, -1.0, 1.0);
            let nh = input(nh, -1.0, 1.0);
            let den = th * th * ab2 + bh * bh * at2 + nh * nh * (atb * atb);
            atb * atb * atb / (std::f32::consts::PI * (den * den).max(1e-30))
        }

        /// The course's `DecodeSggx` in f64 as it was written (no clamp of the channels).
        pub fn decode_f64(t: [f64; 3], alpha_min: f64) -> [f64; 5] {
            let (sxx, sxy, syy) = (t[0] * t[0], t[0] * (2.0 * t[1] - 1.0) * t[2], t[2] * t[2]);
            let discr = (4.0 * sxy * sxy + (sxx - syy).powi(2)).sqrt();
            let discr_rcp = 1.0 / discr.max(1e-6);
            let floor = alpha_min * alpha_min;
            let alpha_t_sqr = (0.5 * (sxx + syy + discr)).clamp(0.0, 1.0).max(floor);
            let alpha_b_sqr = (0.5 * (sxx + syy - discr)).clamp(0.0, 1.0).max(floor);
            let c_sqr = (0.5 * ((sxx - syy) * discr_rcp + 1.0)).clamp(0.0, 1.0);
            let sign = if sxy < 0.0 { -1.0 } else { 1.0 };
            [alpha_t_sqr, alpha_b_sqr, (alpha_t_sqr * alpha_b_sqr).sqrt(), c_sqr.sqrt(), sign * (1.0 - c_sqr).sqrt()]
        }
    }

    fn fields(d: &Decoded32) -> [f32; 5] {
        [d.alpha_t_sqr, d.alpha_b_sqr, d.alpha_tb, d.cos_psi, d.sin_psi]
    }

    /// The programs' f32 evaluation (what the build measures and the tests compare with) is
    /// the hand-written decoder and D bit for bit, on every triple of special and ordinary
    /// values (NaN of both signs, ±inf, ±max, ±0, ±min normal, ±the least subnormal): the
    /// same operations in the same order, and the program's clamp max(lo)·min(hi) differs from
    /// Rust's `clamp` only at NaN, which the clamped channels never produce. D with the
    /// decoded values and with garbage in the struct, at the triple as dots.
    #[test]
    fn programs_are_the_hand_written_decoder_and_d_bit_for_bit() {
        let sp = specials();
        let bits = |v: [f32; 5]| v.map(f32::to_bits);
        for &x in &sp {
            for &y in &sp {
                for &z in &sp {
                    let got = decode_f32([x, y, z]);
                    assert_eq!(bits(fields(&got)), bits(by_hand::decode([x, y, z])), "decode({x}, {y}, {z})");
                    let garbage = Decoded32 { alpha_t_sqr: x, alpha_b_sqr: y, alpha_tb: z, cos_psi: 0.0, sin_psi: 0.0 };
                    for (a, dots) in [(got, [x, y, z]), (garbage, [z, x, y])] {
                        let want = by_hand::d([a.alpha_t_sqr, a.alpha_b_sqr, a.alpha_tb], dots[0], dots[1], dots[2]);
                        assert_eq!(d_f32(&a, dots[0], dots[1], dots[2]).to_bits(), want.to_bits(), "D({a:?}, {dots:?})");
                    }
                }
            }
        }
    }

    /// The f64 decoder (the program in f64) is the course's formula as it was written, bit for
    /// bit, on finite channels in and beyond [0, 1] (a 33-point grid of [−0.5, 1.5] per channel
    /// and 16-bit codes): 4·Sxy·Sxy and 4·(Sxy·Sxy) round alike (4 is a power of 2 and nothing
    /// here under- or overflows), 2y − 1 = y + y − 1 exactly, powi(2) is one product.
    #[test]
    fn the_f64_decoder_is_the_course_formula_as_written() {
        let grid: Vec<f64> = (0..=32).map(|i| -0.5 + i as f64 / 16.0).collect();
        let mut rng = crate::integrate::rng::SplitMix64(29);
        let codes: Vec<[f64; 3]> = (0..4096).map(|_| super::super::integrals::quantize([rng.next_f64(), rng.next_f64(), rng.next_f64()], 16)).collect();
        let mut triples = codes;
        for &x in &grid {
            for &y in &grid {
                triples.extend(grid.iter().map(|&z| [x, y, z]));
            }
        }
        for t in triples {
            let d = decode_course(t, ALPHA_MIN);
            let got = [d.alpha_t_sqr, d.alpha_b_sqr, d.alpha_tb, d.cos, d.sin];
            assert_eq!(got.map(f64::to_bits), by_hand::decode_f64(t, ALPHA_MIN).map(f64::to_bits), "{t:?}");
        }
    }

    /// The module's WGSL, rendered from the programs: naga parses and validates it (with the
    /// runtime tests' scalar wrappers), and its interpretation in f32 (CPU semantics: the
    /// operations the source spells out) is the programs' f32 evaluation bit for bit, input
    /// helper included, on every triple of the runtime tests' channels and NaN of both signs,
    /// ±inf and ±max; D at the decoded values of a triple and at the triple's dots. No tiny
    /// channels: the interpreter refuses a sign test a GPU's flushed subnormal may flip; and no
    /// NaN in the first channel, where the helper's lo = 0 is a literal the interpreter lets a
    /// driver distribute over y + y − 1, bounding Sxy = ±0 away from 0 (both zeros test alike,
    /// the sign test cannot flip; NaN there is held by the Rust and by-hand tests).
    #[test]
    fn rendered_wgsl_validates_and_computes_the_f32_evaluation() {
        let src = crate::emit::wgsl::strip_directives(&render_wgsl(&["spec: test".to_string()], "sggx_decode", "sggx", [0.0; 2])) + runtime_wrappers::WRAPPERS;
        let program = crate::emit::wgsl::interpreter::Program::new(&src);
        let wrappers: Vec<_> = DECODE_FORM.fields.iter().map(|(f, _)| (f, program.function(&format!("t_{f}")))).collect();
        let t_d = program.function("t_d");
        let mut sp = runtime_wrappers::channels();
        sp.extend([f32::NAN, -f32::NAN, f32::INFINITY, f32::NEG_INFINITY, f32::MAX, f32::MIN]);
        for &x in sp.iter().filter(|x| !x.is_nan()) {
            for &y in &sp {
                for &z in &sp {
                    let want = decode_f32([x, y, z]);
                    for ((f, h), w) in wrappers.iter().zip(fields(&want)) {
                        assert_eq!(program.eval(*h, &[x, y, z]).0.to_bits(), w.to_bits(), "{f}({x}, {y}, {z})");
                    }
                    let d = program.eval(t_d, &[x, y, z, z, x, y]).0;
                    assert_eq!(d.to_bits(), d_f32(&want, z, x, y).to_bits(), "D at ({x}, {y}, {z})");
                }
            }
        }
    }

    /// The bodies' WGSL folded by naga's constant evaluator (the bindings made module constants,
    /// the clamped arguments constants) gives the programs' f32 bits: every field of the
    /// decoder's struct constructor, and D, on a grid of channels and dots inside the clamps.
    #[test]
    fn rendered_bodies_fold_in_naga_to_the_f32_evaluation() {
        use crate::emit::fixtures::naga_folded_f32;
        let constant = |v: f32| format!("{}f", f32_literal(v));
        let consts = |body: String, ret: &str| -> (String, String) {
            let mut decls = String::new();
            let mut result = String::new();
            for line in body.lines() {
                if let Some(l) = line.trim().strip_prefix("let ") {
                    decls += &format!("const {l}\n");
                } else if let Some(r) = line.trim().strip_prefix("return ") {
                    result = format!("{}{ret}", r.trim_end_matches(';'));
                }
            }
            (decls, result)
        };
        let arg = |i: usize| format!("a{i}");
        let (decode_decls, decode) = consts(DECODE_FORM.render(Syntax::Wgsl, &arg, &decode_consts_f32(), &constant), "");
        let (d_decls, d) = consts(D_FORM.render(Syntax::Wgsl, &arg, &D_CONSTS.map(|c| c as f32), &constant), "");
        let declare = |args: &[f32]| args.iter().enumerate().map(|(i, v)| format!("const a{i}: f32 = {};\n", constant(*v))).collect::<String>();
        let axis = [0.0f32, 0.125, 0.3, 0.5, 0.75, 0.999_999_94, 1.0];
        for &x in &axis {
            for &y in &axis {
                for &z in &axis {
                    let want = fields(&decode_f32([x, y, z]));
                    let decls = format!("{}{}{decode_decls}", decoded_struct(Syntax::Wgsl), declare(&[x, y, z]));
                    for ((f, _), w) in DECODE_FORM.fields.iter().zip(want) {
                        let got = naga_folded_f32(&decls, &format!("{decode}.{f}"));
                        assert_eq!(got.to_bits(), w.to_bits(), "{f} at ({x}, {y}, {z})");
                    }
                    let (a, dots) = ([want[0], want[1], want[2]], [2.0 * x - 1.0, y, -z]);
                    let args = [a[0], a[1], a[2], dots[0], dots[1], dots[2]];
                    let got = naga_folded_f32(&format!("{}{d_decls}", declare(&args)), &d);
                    let a32 = Decoded32 { alpha_t_sqr: a[0], alpha_b_sqr: a[1], alpha_tb: a[2], cos_psi: 0.0, sin_psi: 0.0 };
                    assert_eq!(got.to_bits(), d_f32(&a32, dots[0], dots[1], dots[2]).to_bits(), "D{args:?}");
                }
            }
        }
    }

    /// The module's Rust, rendered from the programs, compiled by rustc and run, computes the
    /// programs' f32 evaluation bit for bit (Rust never contracts to FMA) on every triple of
    /// special and ordinary values: the five fields, D at the decoded values and D with
    /// garbage in the struct.
    #[test]
    fn rendered_rust_compiles_and_computes_the_f32_evaluation() {
        let module = render_rust(&["spec: test".to_string()], "sggx", [0.0; 2]);
        let sp = specials();
        let list: Vec<String> = sp.iter().map(|v| format!("{:#x}", v.to_bits())).collect();
        let main = format!(
            "mod sggx_decode;\nuse sggx_decode::*;\nconst S: [u32; {}] = [{}];\nfn main() {{\n\
             \x20   for x in S.map(f32::from_bits) {{ for y in S.map(f32::from_bits) {{ for z in S.map(f32::from_bits) {{\n\
             \x20       let a = sggx_decode([x, y, z]);\n\
             \x20       let g = SggxAniso {{ alpha_t_sqr: x, alpha_b_sqr: y, alpha_tb: z, cos_psi: 0.0, sin_psi: 0.0 }};\n\
             \x20       for v in [a.alpha_t_sqr, a.alpha_b_sqr, a.alpha_tb, a.cos_psi, a.sin_psi, sggx_d(&a, x, y, z), sggx_d(&g, z, x, y)] {{ println!(\"{{}}\", v.to_bits()); }}\n\
             \x20   }} }} }}\n}}\n",
            sp.len(),
            list.join(", ")
        );
        let got = crate::emit::fixtures::compiled_bits_with(&main, &[("sggx_decode".to_string(), module)]);
        let mut want = Vec::new();
        for &x in &sp {
            for &y in &sp {
                for &z in &sp {
                    let a = decode_f32([x, y, z]);
                    let g = Decoded32 { alpha_t_sqr: x, alpha_b_sqr: y, alpha_tb: z, cos_psi: 0.0, sin_psi: 0.0 };
                    want.extend(fields(&a).iter().chain(&[d_f32(&a, x, y, z), d_f32(&g, z, x, y)]).map(|v| v.to_bits()));
                }
            }
        }
        assert_eq!(got.len(), want.len());
        for (k, (g, w)) in got.iter().zip(&want).enumerate() {
            assert_eq!(g, w, "value {k} (triple {}, field {}): compiled {} vs evaluator {}", k / 7, k % 7, f32::from_bits(*g), f32::from_bits(*w));
        }
    }

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
