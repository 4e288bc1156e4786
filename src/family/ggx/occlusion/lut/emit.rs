//! WGSL and Rust for cone LUTs, and the f32 lookup the Rust module performs (for verification).
//!
//! Filtering convention: the texture `data/NAME.ktx2` is a 3-D texture (width n·v columns ×
//! height roughness rows × depth cone slices). On the n·v and roughness axes the texel centres
//! sit at (i + 0.5)/size, as in the 2-D table: the parameters are the texture coordinates (no
//! half-texel remap) and clamp-to-edge holds the edge texels beyond the outer centres. On the
//! cone axis slice k holds cos θc = k/(depth − 1), so the first and last centres are the open
//! and the closed cone:
//!
//! ```text
//! w = (cos θc (depth − 1) + 0.5) / depth
//! ```
//!
//! and a linear sampler (w·depth − 0.5 = cos θc (depth − 1)) interpolates linearly in cos θc
//! between the two slices around it: trilinear filtering, as COD: WWII's 3-D table is read.
//! Every parameter is clamped to [0, 1] first (NaN → 0).
//!
//! WGSL `shadefit::NAME`: `F_uvw`, `F_sample` (the stored channels), `F_scale_bias` (decoded from
//! the layout), `F_specular(f0)` = f0·scale + bias. Rust `src/NAME.rs`: the KTX2 bytes, the
//! texels decoded from them (`F_texel`, f16 → f32), and the same lookups on the CPU: trilinear
//! with exact f32 weights in the order of [`lookup_f32`].

use crate::family::ggx::lut::emit::{axis_f32, input_f32, wgsl_preamble};
use crate::family::ggx::lut::spec::Layout;
use crate::spec::TableTextureFormat;

/// One cone LUT module to emit.
pub struct ConeLutCode<'a> {
    pub module: &'a str,
    pub function: &'a str,
    pub width: usize,
    pub height: usize,
    pub depth: usize,
    pub layout: Layout,
    pub format: TableTextureFormat,
    /// The row argument: "gloss", "roughness" or "alpha".
    pub row: &'a str,
    /// Byte offset of the level data in the KTX2 file.
    pub level_offset: usize,
}

/// Slice indices and weight of cone cosine `c` ∈ [0, 1] on `d` slices at c = k/(d − 1), in f32:
/// (k0, k1, f), value = s[k0](1 − f) + s[k1]f.
pub fn cone_axis_f32(c: f32, d: usize) -> (usize, usize, f32) {
    let x = c * (d - 1) as f32;
    let x0 = x.floor();
    let k0 = (x0 as usize).min(d - 1);
    (k0, (k0 + 1).min(d - 1), x - x0)
}

/// The emitted Rust lookup `F(n_dot_v, t, cos_cone)` in f32 over `texels` (stored channels,
/// slice-major, then row-major).
pub fn lookup_f32(texels: &[[f32; 2]], (w, h, d): (usize, usize, usize), n_dot_v: f32, t: f32, cos_cone: f32) -> [f32; 2] {
    let at = [axis_f32(input_f32(n_dot_v), w), axis_f32(input_f32(t), h), cone_axis_f32(input_f32(cos_cone), d)];
    crate::emit::interp::multilinear(texels, &[w, h, d], &at)
}

impl ConeLutCode<'_> {
    fn layout_doc(&self, mapping_doc: &str) -> Vec<String> {
        let [r, g] = self.layout.channels();
        let (w, h, d) = (self.width, self.height, self.depth);
        vec![
            format!("Texture: 3-D, {w} n·v columns × {h} {} rows × {d} cone slices, {}, layout \"{}\": R = {r}, G = {g}.", self.row, self.format.name(), self.layout.name()),
            format!("Texel (i, j, k) holds the integrals at n·v = (i + 0.5)/{w}, {mapping_doc} and cos θc = k/{} (light", d - 1),
            "directions in the cone n·l ≥ cos θc). Sampling: u = n·v, v = the row parameter (texel centres, no".to_string(),
            format!("remap), w = (cos θc·{} + 0.5)/{d} (slice centres on cos θc = 0 and 1); linear, clamp-to-edge sampler.", d - 1),
        ]
    }


    /// The WGSL library `wgsl/NAME.wgsl`.
    pub fn render_wgsl(&self, header: &[String], doc: &str, mapping_doc: &str) -> String {
        let (m, f, row) = (self.module, self.function, self.row);
        let up = m.to_uppercase();
        let d = self.depth;
        let size = format!("\nconst {up}_SIZE: vec3<u32> = vec3<u32>({}u, {}u, {d}u);\n\n", self.width, self.height);
        let mut s = wgsl_preamble(header, m, doc, &self.layout_doc(mapping_doc), &size);
        s.push_str(&format!(
            "// Texture coordinates of (n·v, {row}, cos θc): the first two clamped to [0, 1], the cone's\n\
             // w = (cos θc·{} + 0.5)/{d} on the slice centres.\n\
             fn {f}_uvw(n_dot_v: f32, {row}: f32, cos_cone: f32) -> vec3<f32> {{\n    \
             return vec3<f32>({m}_input(n_dot_v), {m}_input({row}), ({m}_input(cos_cone) * {}f + 0.5f) / {d}f);\n}}\n\n",
            d - 1,
            d - 1
        ));
        let [r, g] = self.layout.channels();
        s.push_str(&format!(
            "// The stored channels (R = {r}, G = {g}) through a linear, clamp-to-edge sampler.\n\
             fn {f}_sample(lut: texture_3d<f32>, lut_sampler: sampler, n_dot_v: f32, {row}: f32, cos_cone: f32) -> vec2<f32> {{\n    \
             return textureSampleLevel(lut, lut_sampler, {f}_uvw(n_dot_v, {row}, cos_cone), 0.0).rg;\n}}\n\n"
        ));
        s.push_str(&format!(
            "// (scale, bias) of the split sum over the cone: specular = F0·scale + bias (F90 = 1).\n\
             fn {f}_scale_bias(lut: texture_3d<f32>, lut_sampler: sampler, n_dot_v: f32, {row}: f32, cos_cone: f32) -> vec2<f32> {{\n    \
             let t = {f}_sample(lut, lut_sampler, n_dot_v, {row}, cos_cone);\n    \
             return {};\n}}\n\n",
            self.layout.decode_wgsl()
        ));
        s.push_str(&format!(
            "// The occluded split-sum specular reflectance F0·scale + bias of a Schlick F0 (F90 = 1).\n\
             fn {f}_specular(lut: texture_3d<f32>, lut_sampler: sampler, f0: vec3<f32>, n_dot_v: f32, {row}: f32, cos_cone: f32) -> vec3<f32> {{\n    \
             let sb = {f}_scale_bias(lut, lut_sampler, n_dot_v, {row}, cos_cone);\n    \
             return f0 * sb.x + vec3<f32>(sb.y);\n}}\n"
        ));
        s
    }

    /// The Rust module `src/NAME.rs`: the KTX2 bytes and the CPU lookups over its texels.
    pub fn render_rust(&self, header: &[String], doc: &str, mapping_doc: &str) -> String {
        let (m, f, row) = (self.module, self.function, self.row);
        let up = m.to_uppercase();
        let (w, h, d) = (self.width, self.height, self.depth);
        let mut s = String::new();
        for line in header {
            s.push_str(&format!("//! {line}\n"));
        }
        s.push_str(&format!("//!\n//! {doc}\n"));
        for line in self.layout_doc(mapping_doc) {
            s.push_str(&format!("//! {line}\n"));
        }
        s.push_str("//! The CPU lookups read the texels from the KTX2 bytes (f16 decoded exactly) and interpolate\n//! trilinearly in f32 with exact weights. A GPU's sampler may quantise its weights (Vulkan\n//! guarantees 4 fractional bits, common GPUs have 8) and filter 16-bit float texels at about\n//! their own precision (an NVIDIA H100 within 3.5e-4 of the 2-D lookups, 2.3e-3 of the 3-D one).\n\n");
        s.push_str(&format!("/// Texture size (width, height, depth) in texels.\npub const {up}_SIZE: [u32; 3] = [{w}, {h}, {d}];\n"));
        s.push_str(&format!("/// Texel format of [`{up}_KTX2`] (WebGPU name).\npub const {up}_FORMAT: &str = \"{}\";\n", self.format.name()));
        let [r, g] = self.layout.channels();
        s.push_str(&format!("/// What the R and G channels hold.\npub const {up}_CHANNELS: [&str; 2] = [\"{r}\", \"{g}\"];\n"));
        s.push_str(&format!(
            "/// The LUT as a KTX2 3-D texture (linear, slice 0 first, each row 0 first), as written by\n\
             /// `shadefit build`.\npub const {up}_KTX2: &[u8] = include_bytes!(\"../data/{m}.ktx2\");\n"
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
            "/// Texel (x, y, z) as stored (R, G), x < {w}, y < {h}, z < {d} (slice z: cos θc = z/{}).\n\
             pub fn {f}_texel(x: u32, y: u32, z: u32) -> [f32; 2] {{\n    \
             let at = |c: usize| {{\n        \
             let k = LEVEL_OFFSET + 2 * (((z as usize * {h} + y as usize) * {w} + x as usize) * STRIDE + c);\n        \
             f16_to_f32(u16::from_le_bytes([{up}_KTX2[k], {up}_KTX2[k + 1]]))\n    \
             }};\n    [at(0), at(1)]\n}}\n\n",
            d - 1
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
            "/// Slice indices and weight of cone cosine c ∈ [0, 1] (slice k at c = k/{}).\n#[inline]\n\
             fn cone_axis(c: f32) -> (usize, usize, f32) {{\n    \
             let x = c * {}.0;\n    let x0 = x.floor();\n    let k0 = (x0 as usize).min({});\n    \
             (k0, (k0 + 1).min({}), x - x0)\n}}\n\n",
            d - 1,
            d - 1,
            d - 1,
            d - 1
        ));
        s.push_str(&format!(
            "/// Texture coordinates of (n·v, {row}, cos θc) (WGSL `{f}_uvw`): the first two clamped to\n\
             /// [0, 1], w = (cos θc·{} + 0.5)/{d}.\n\
             pub fn {f}_uvw(n_dot_v: f32, {row}: f32, cos_cone: f32) -> [f32; 3] {{\n    \
             [input(n_dot_v), input({row}), (input(cos_cone) * {}.0 + 0.5) / {d}.0]\n}}\n\n",
            d - 1,
            d - 1
        ));
        s.push_str(&format!(
            "/// The stored channels (R = {r}, G = {g}) at (n·v, {row}, cos θc): what a linear, clamp-to-edge\n\
             /// sampler returns from the texture (WGSL `{f}_sample`), up to its filter's precision.\n\
             pub fn {f}(n_dot_v: f32, {row}: f32, cos_cone: f32) -> [f32; 2] {{\n    \
             let (i0, i1, fx) = axis(input(n_dot_v), {w});\n    \
             let (j0, j1, fy) = axis(input({row}), {h});\n    \
             let (k0, k1, fz) = cone_axis(input(cos_cone));\n    \
             let plane = |z: usize| -> [f32; 2] {{\n        \
             let (a0, a1) = ({f}_texel(i0 as u32, j0 as u32, z as u32), {f}_texel(i1 as u32, j0 as u32, z as u32));\n        \
             let (b0, b1) = ({f}_texel(i0 as u32, j1 as u32, z as u32), {f}_texel(i1 as u32, j1 as u32, z as u32));\n        \
             std::array::from_fn(|c| {{\n            \
             let a = a0[c] * (1.0 - fx) + a1[c] * fx;\n            \
             let b = b0[c] * (1.0 - fx) + b1[c] * fx;\n            \
             a * (1.0 - fy) + b * fy\n        }})\n    }};\n    \
             let (p0, p1) = (plane(k0), plane(k1));\n    \
             std::array::from_fn(|c| p0[c] * (1.0 - fz) + p1[c] * fz)\n}}\n\n"
        ));
        let decode = self.layout.decode_rust();
        s.push_str(&format!(
            "/// (scale, bias) of the split sum over the cone at (n·v, {row}, cos θc): specular = F0·scale + bias.\n\
             pub fn {f}_scale_bias(n_dot_v: f32, {row}: f32, cos_cone: f32) -> [f32; 2] {{\n    \
             let t = {f}(n_dot_v, {row}, cos_cone);\n    {decode}\n}}\n\n"
        ));
        s.push_str(&format!(
            "/// The occluded split-sum specular reflectance F0·scale + bias of a Schlick F0 (F90 = 1).\n\
             pub fn {f}_specular(f0: [f32; 3], n_dot_v: f32, {row}: f32, cos_cone: f32) -> [f32; 3] {{\n    \
             let [scale, bias] = {f}_scale_bias(n_dot_v, {row}, cos_cone);\n    \
             f0.map(|c| c * scale + bias)\n}}\n"
        ));
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookup_is_linear_in_the_cone_between_slices_and_holds_the_ends() {
        // Texel value = slice index: the lookup returns cos θc (d − 1) exactly where the weights
        // are exact (multiples of 1/8 here), and clamps outside [0, 1].
        let (w, h, d) = (2, 2, 5);
        let t: Vec<[f32; 2]> = (0..w * h * d).map(|k| [(k / (w * h)) as f32, 1.0]).collect();
        assert_eq!(lookup_f32(&t, (w, h, d), 0.3, 0.6, 0.0), [0.0, 1.0]);
        assert_eq!(lookup_f32(&t, (w, h, d), 0.3, 0.6, 0.5), [2.0, 1.0]);
        assert_eq!(lookup_f32(&t, (w, h, d), 0.3, 0.6, 0.625), [2.5, 1.0]);
        assert_eq!(lookup_f32(&t, (w, h, d), 0.3, 0.6, 1.0), [4.0, 1.0]);
        assert_eq!(lookup_f32(&t, (w, h, d), 0.3, 0.6, 7.0), [4.0, 1.0]);
        assert_eq!(lookup_f32(&t, (w, h, d), 0.3, 0.6, f32::NAN), [0.0, 1.0]);
        // The GPU's w coordinate lands on the same place: w·d − 0.5 = c (d − 1).
        for c in [0.0f32, 0.25, 0.5, 1.0] {
            let wc = (c * (d - 1) as f32 + 0.5) / d as f32;
            assert_eq!(wc * d as f32 - 0.5, c * (d - 1) as f32);
        }
    }
}
