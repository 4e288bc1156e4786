//! WGSL and Rust for DFG LUTs, and the f32 lookup the Rust module performs (for verification).
//!
//! The texture `data/NAME.ktx2` is sampled at uv = (n·v, t) with t the roughness (or α, by the
//! spec's mapping), clamped to [0, 1] (NaN → 0): texel centres sit at (i + 0.5)/size, so the
//! parameters are the texture coordinates (no half-texel remap), and a linear, clamp-to-edge
//! sampler interpolates between the centres and holds the edge texels beyond them.
//!
//! WGSL `shadefit::NAME`: `F_uv`, `F_sample` (the stored channels), `F_scale_bias` (decoded
//! from the layout), `F_specular(f0)` = f0·scale + bias. Rust `src/NAME.rs`: the KTX2 bytes, the
//! texels decoded from them (`F_texel`, f16 → f32), and the same lookups on the CPU: bilinear
//! with exact f32 weights in the order of [`lookup_f32`].

use super::spec::Layout;
use crate::spec::TableTextureFormat;

/// One DFG LUT module to emit.
pub struct DfgLutCode<'a> {
    pub module: &'a str,
    pub function: &'a str,
    pub width: usize,
    pub height: usize,
    pub layout: Layout,
    pub format: TableTextureFormat,
    /// The row argument: "roughness" or "alpha".
    pub row: &'a str,
    /// Byte offset of the level data in the KTX2 file.
    pub level_offset: usize,
}

/// A parameter as the lookups take it: clamped to [0, 1], NaN → 0.
pub fn input_f32(v: f32) -> f32 {
    if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) }
}

/// The start of a LUT module's WGSL: the header, the import path, the doc lines and, after
/// `extra` (the size constant), `{module}_input` (clamp to [0, 1], NaN to 0).
pub fn wgsl_preamble(header: &[String], module: &str, doc: &str, layout_doc: &[String], extra: &str) -> String {
    let mut s = String::new();
    for line in header {
        s.push_str(&format!("// {line}\n"));
    }
    s.push_str(&format!("#define_import_path shadefit::{module}\n\n// {doc}\n"));
    for line in layout_doc {
        s.push_str(&format!("// {line}\n"));
    }
    s.push_str(extra);
    s.push_str(&format!(
        "// Clamp a parameter to [0, 1]; NaN (any exponent-all-ones pattern with a non-zero\n\
         // mantissa) maps to 0.\nfn {module}_input(v: f32) -> f32 {{\n    \
         let nan = (bitcast<u32>(v) & 0x7fffffffu) > 0x7f800000u;\n    \
         return select(clamp(v, 0f, 1f), 0f, nan);\n}}\n\n"
    ));
    s
}

/// Texel indices and weight of texture coordinate `p` ∈ [0, 1] on an axis of `n` texels
/// (centres at (i + 0.5)/n, clamp to edge), in f32: (i0, i1, f), value = t[i0](1 − f) + t[i1]f.
pub fn axis_f32(p: f32, n: usize) -> (usize, usize, f32) {
    let x = p * n as f32 - 0.5;
    let x0 = x.floor();
    let f = x - x0;
    let i0 = (x0.max(0.0) as usize).min(n - 1);
    let i1 = ((x0 + 1.0).max(0.0) as usize).min(n - 1);
    (i0, i1, f)
}

/// The emitted Rust lookup `F(n_dot_v, t)` in f32 over `texels` (stored channels, row-major).
pub fn lookup_f32(texels: &[[f32; 2]], (w, h): (usize, usize), n_dot_v: f32, t: f32) -> [f32; 2] {
    crate::emit::interp::multilinear(texels, &[w, h], &[axis_f32(input_f32(n_dot_v), w), axis_f32(input_f32(t), h)])
}

impl DfgLutCode<'_> {
    fn layout_doc(&self, mapping_doc: &str) -> Vec<String> {
        let [r, g] = self.layout.channels();
        vec![
            format!("Texture: {} n·v columns × {} {} rows, {}, layout \"{}\": R = {r}, G = {g}.", self.width, self.height, self.row, self.format.name(), self.layout.name()),
            format!("Texel (i, j) holds the integrals at n·v = (i + 0.5)/{} and {mapping_doc} (texel centres),", self.width),
            format!("so uv = ({}, {}) with no half-texel remap; bind with a linear, clamp-to-edge sampler.", "n·v", self.row),
        ]
    }


    /// The WGSL library `wgsl/NAME.wgsl`.
    pub fn render_wgsl(&self, header: &[String], doc: &str, mapping_doc: &str) -> String {
        let (m, f, row) = (self.module, self.function, self.row);
        let up = m.to_uppercase();
        let size = format!("\nconst {up}_SIZE: vec2<u32> = vec2<u32>({}u, {}u);\n\n", self.width, self.height);
        let mut s = wgsl_preamble(header, m, doc, &self.layout_doc(mapping_doc), &size);
        s.push_str(&format!(
            "// Texture coordinates of (n·v, {row}): the parameters themselves, clamped to [0, 1].\n\
             fn {f}_uv(n_dot_v: f32, {row}: f32) -> vec2<f32> {{\n    \
             return vec2<f32>({m}_input(n_dot_v), {m}_input({row}));\n}}\n\n"
        ));
        let [r, g] = self.layout.channels();
        s.push_str(&format!(
            "// The stored channels (R = {r}, G = {g}) through a linear, clamp-to-edge sampler.\n\
             fn {f}_sample(lut: texture_2d<f32>, lut_sampler: sampler, n_dot_v: f32, {row}: f32) -> vec2<f32> {{\n    \
             return textureSampleLevel(lut, lut_sampler, {f}_uv(n_dot_v, {row}), 0.0).rg;\n}}\n\n"
        ));
        s.push_str(&format!(
            "// (scale, bias) of the split sum: specular = F0·scale + bias (F90 = 1).\n\
             fn {f}_scale_bias(lut: texture_2d<f32>, lut_sampler: sampler, n_dot_v: f32, {row}: f32) -> vec2<f32> {{\n    \
             let t = {f}_sample(lut, lut_sampler, n_dot_v, {row});\n    \
             return {};\n}}\n\n",
            self.layout.decode_wgsl()
        ));
        s.push_str(&format!(
            "// The split-sum specular reflectance F0·scale + bias of a Schlick F0 (F90 = 1).\n\
             fn {f}_specular(lut: texture_2d<f32>, lut_sampler: sampler, f0: vec3<f32>, n_dot_v: f32, {row}: f32) -> vec3<f32> {{\n    \
             let sb = {f}_scale_bias(lut, lut_sampler, n_dot_v, {row});\n    \
             return f0 * sb.x + vec3<f32>(sb.y);\n}}\n"
        ));
        s
    }

    /// The Rust module `src/NAME.rs`: the KTX2 bytes and the CPU lookups over its texels.
    pub fn render_rust(&self, header: &[String], doc: &str, mapping_doc: &str) -> String {
        let (m, f, row) = (self.module, self.function, self.row);
        let up = m.to_uppercase();
        let (w, h) = (self.width, self.height);
        let mut s = String::new();
        for line in header {
            s.push_str(&format!("//! {line}\n"));
        }
        s.push_str(&format!("//!\n//! {doc}\n"));
        for line in self.layout_doc(mapping_doc) {
            s.push_str(&format!("//! {line}\n"));
        }
        s.push_str("//! The CPU lookups read the texels from the KTX2 bytes (f16 decoded exactly) and interpolate\n//! bilinearly in f32 with exact weights. A GPU's sampler may quantise its weights (Vulkan\n//! guarantees 4 fractional bits, common GPUs have 8) and filter 16-bit float texels at about\n//! their own precision (an NVIDIA H100 within 3.5e-4 of the 2-D lookups, 2.3e-3 of the 3-D one).\n\n");
        s.push_str(&format!("/// Texture size (width, height) in texels.\npub const {up}_SIZE: [u32; 2] = [{w}, {h}];\n"));
        s.push_str(&format!("/// Texel format of [`{up}_KTX2`] (WebGPU name).\npub const {up}_FORMAT: &str = \"{}\";\n", self.format.name()));
        let [r, g] = self.layout.channels();
        s.push_str(&format!("/// What the R and G channels hold.\npub const {up}_CHANNELS: [&str; 2] = [\"{r}\", \"{g}\"];\n"));
        s.push_str(&format!(
            "/// The LUT as a KTX2 texture (linear, row 0 first), as written by `shadefit build`.\n\
             pub const {up}_KTX2: &[u8] = include_bytes!(\"../data/{m}.ktx2\");\n"
        ));
        s.push_str(&format!("/// Byte offset of the texels in [`{up}_KTX2`].\nconst LEVEL_OFFSET: usize = {};\n", self.level_offset));
        s.push_str(&format!("/// f16 channels per texel in the file.\nconst STRIDE: usize = {};\n\n", self.format.texel_channels()));
        s.push_str(
            "/// An IEEE binary16 value as f32 (exact).\nfn f16_to_f32(h: u16) -> f32 {\n    \
             let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };\n    \
             let exp = ((h >> 10) & 0x1f) as i32;\n    \
             let man = (h & 0x3ff) as f32;\n    \
             match exp {\n        \
             0 => sign * man * (1.0 / 16_777_216.0),\n        \
             31 => if man == 0.0 { sign * f32::INFINITY } else { f32::NAN },\n        \
             _ => sign * (1.0 + man * (1.0 / 1024.0)) * f32::powi(2.0, exp - 15),\n    \
             }\n}\n\n",
        );
        s.push_str(&format!(
            "/// Texel (x, y) as stored (R, G), x < {w}, y < {h}.\npub fn {f}_texel(x: u32, y: u32) -> [f32; 2] {{\n    \
             let at = |c: usize| {{\n        \
             let k = LEVEL_OFFSET + 2 * ((y as usize * {w} + x as usize) * STRIDE + c);\n        \
             f16_to_f32(u16::from_le_bytes([{up}_KTX2[k], {up}_KTX2[k + 1]]))\n    \
             }};\n    [at(0), at(1)]\n}}\n\n"
        ));
        s.push_str("#[inline]\nfn input(v: f32) -> f32 {\n    if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) }\n}\n\n");
        s.push_str(
            "/// Texel indices and weight of coordinate p on an axis of n texels (centres at (i + 0.5)/n,\n\
             /// clamp to edge).\n#[inline]\nfn axis(p: f32, n: usize) -> (usize, usize, f32) {\n    \
             let x = p * n as f32 - 0.5;\n    let x0 = x.floor();\n    let f = x - x0;\n    \
             let i0 = (x0.max(0.0) as usize).min(n - 1);\n    \
             let i1 = ((x0 + 1.0).max(0.0) as usize).min(n - 1);\n    (i0, i1, f)\n}\n\n",
        );
        s.push_str(&format!(
            "/// Texture coordinates of (n·v, {row}) (WGSL `{f}_uv`): the parameters clamped to [0, 1].\n\
             pub fn {f}_uv(n_dot_v: f32, {row}: f32) -> [f32; 2] {{\n    [input(n_dot_v), input({row})]\n}}\n\n"
        ));
        s.push_str(&format!(
            "/// The stored channels (R = {r}, G = {g}) at (n·v, {row}): what a linear, clamp-to-edge sampler\n\
             /// returns from the texture (WGSL `{f}_sample`), up to its filter's precision.\n\
             pub fn {f}(n_dot_v: f32, {row}: f32) -> [f32; 2] {{\n    \
             let (i0, i1, fx) = axis(input(n_dot_v), {w});\n    \
             let (j0, j1, fy) = axis(input({row}), {h});\n    \
             let (a0, a1) = ({f}_texel(i0 as u32, j0 as u32), {f}_texel(i1 as u32, j0 as u32));\n    \
             let (b0, b1) = ({f}_texel(i0 as u32, j1 as u32), {f}_texel(i1 as u32, j1 as u32));\n    \
             std::array::from_fn(|c| {{\n        \
             let a = a0[c] * (1.0 - fx) + a1[c] * fx;\n        \
             let b = b0[c] * (1.0 - fx) + b1[c] * fx;\n        \
             a * (1.0 - fy) + b * fy\n    }})\n}}\n\n"
        ));
        let decode = self.layout.decode_rust();
        s.push_str(&format!(
            "/// (scale, bias) of the split sum at (n·v, {row}): specular = F0·scale + bias (F90 = 1).\n\
             pub fn {f}_scale_bias(n_dot_v: f32, {row}: f32) -> [f32; 2] {{\n    \
             let t = {f}(n_dot_v, {row});\n    {decode}\n}}\n\n"
        ));
        s.push_str(&format!(
            "/// The split-sum specular reflectance F0·scale + bias of a Schlick F0 (F90 = 1).\n\
             pub fn {f}_specular(f0: [f32; 3], n_dot_v: f32, {row}: f32) -> [f32; 3] {{\n    \
             let [scale, bias] = {f}_scale_bias(n_dot_v, {row});\n    \
             f0.map(|c| c * scale + bias)\n}}\n"
        ));
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookups_hit_texel_centres_and_clamp_at_the_edges() {
        // A plane in (column, row) is reproduced between the centres and held beyond them.
        let (w, h) = (4, 3);
        let t: Vec<[f32; 2]> = (0..w * h).map(|k| [(k % w) as f32, (k / w) as f32]).collect();
        assert_eq!(lookup_f32(&t, (w, h), 0.125, 0.5), [0.0, 1.0]);
        assert_eq!(lookup_f32(&t, (w, h), 0.875, 1.0 / 6.0), [3.0, 0.0]);
        assert_eq!(lookup_f32(&t, (w, h), 0.25, 0.5), [0.5, 1.0]);
        assert_eq!(lookup_f32(&t, (w, h), 0.0, 0.0), [0.0, 0.0]);
        assert_eq!(lookup_f32(&t, (w, h), 1.0, 1.0), [3.0, 2.0]);
        assert_eq!(lookup_f32(&t, (w, h), f32::NAN, 7.0), [0.0, 2.0]);
    }
}
