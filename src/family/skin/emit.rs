//! WGSL and Rust for skin LUTs (RGB textures over n·l and curvature, or over curvature and SH
//! band), plus the f32 evaluation of the emitted lookup in the emitted operation order (for
//! verification).
//!
//! Each module `NAME` holds the texels as a const array `NAME_RGB` (row-major, first axis
//! fastest), its size, κ_max, and four functions:
//! - `NAME_coords(..)`: continuous texel coordinates of the inputs (0 at the first texel
//!   centre, n − 1 at the last), after clamping them to the LUT's domain (NaN → lower end,
//!   concave κ < 0 → 0, κ > κ_max → κ_max) and applying the curvature mapping;
//! - `NAME(..)`: bilinear interpolation of the const array (the WGSL and the Rust versions do
//!   the same f32 operations in the same order);
//! - `NAME_uv(..)`: texture coordinates with half-texel offsets, uv = (coords + 0.5)/size, so
//!   that texel centres sit on the grid points and a linear sampler interpolates exactly like
//!   `NAME` (up to the texture's storage precision and the sampler's weight precision);
//! - WGSL only, `NAME_sample(lut, lut_sampler, ..)`: `textureSampleLevel` at `NAME_uv`, for the
//!   KTX2 texture (generated/data/NAME.ktx2) bound with a linear, clamp-to-edge sampler.

use crate::fit::expr::sanitize;
use crate::emit::f32_literal;
use crate::spec::TableTextureFormat as TextureFormat;
use super::integrals::CurvatureMapping;

/// Texel layout of a skin LUT.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    /// D(n·l, κ): `n_dot_l` columns (n·l ∈ [−1, 1] uniform) × `curvature` rows.
    Punctual { n_dot_l: usize, curvature: usize },
    /// k_l(κ): `curvature` columns × 2 rows (bands 1 and 2; band 0 is 1).
    Sh { curvature: usize },
}

impl Layout {
    /// Texture size (width, height).
    pub fn size(self) -> (usize, usize) {
        match self {
            Layout::Punctual { n_dot_l, curvature } => (n_dot_l, curvature),
            Layout::Sh { curvature } => (curvature, 2),
        }
    }
}

/// One skin LUT module to emit.
pub struct SkinLutCode<'a> {
    pub module: &'a str,
    pub function: &'a str,
    pub layout: Layout,
    pub curvature_max: f64,
    pub mapping: CurvatureMapping,
    pub format: TextureFormat,
    /// Texels, row-major (`values[y * width + x]`), f32.
    pub values: &'a [[f32; 3]],
}

/// f32 constants of the coordinate computation, rounded once here and emitted as literals.
struct Consts {
    kmax: f32,
    /// n·l → column: (n·l + 1)·s0, s0 = (n − 1)/2.
    s0: f32,
    /// Linear: κ·scale, scale = (n − 1)/κ_max. Sqrt: √(κ·inv)·last, inv = 1/κ_max.
    k_scale: f32,
    k_inv: f32,
    k_last: f32,
}

impl SkinLutCode<'_> {
    fn curvature_count(&self) -> usize {
        match self.layout {
            Layout::Punctual { curvature, .. } | Layout::Sh { curvature } => curvature,
        }
    }

    fn consts(&self) -> Consts {
        let n = self.curvature_count() as f64;
        let s0 = match self.layout {
            Layout::Punctual { n_dot_l, .. } => ((n_dot_l - 1) as f64 / 2.0) as f32,
            Layout::Sh { .. } => 0.0,
        };
        Consts {
            kmax: self.curvature_max as f32,
            s0,
            k_scale: ((n - 1.0) / self.curvature_max) as f32,
            k_inv: (1.0 / self.curvature_max) as f32,
            k_last: (n - 1.0) as f32,
        }
    }

    /// Continuous κ coordinate, f32, in the emitted order.
    fn kappa_coord_f32(&self, c: &Consts, curvature: f32) -> f32 {
        let x = sanitize(curvature, 0.0, c.kmax);
        match self.mapping {
            CurvatureMapping::Linear => x * c.k_scale,
            CurvatureMapping::Sqrt => (x * c.k_inv).sqrt() * c.k_last,
        }
    }

    /// `NAME_coords` in f32 (punctual: (n·l, κ); SH: (κ, 0)).
    pub fn coords_f32(&self, a: f32, b: f32) -> [f32; 2] {
        let c = self.consts();
        match self.layout {
            Layout::Punctual { .. } => [(sanitize(a, -1.0, 1.0) + 1.0) * c.s0, self.kappa_coord_f32(&c, b)],
            Layout::Sh { .. } => [self.kappa_coord_f32(&c, a), 0.0],
        }
    }

    /// The emitted lookup `NAME(n_dot_l, curvature)` (punctual) in f32.
    pub fn punctual_f32(&self, n_dot_l: f32, curvature: f32) -> [f32; 3] {
        let Layout::Punctual { n_dot_l: nx, curvature: ny } = self.layout else { panic!("not a punctual LUT") };
        let [c0, c1] = self.coords_f32(n_dot_l, curvature);
        let i0 = (c0 as u32).min(nx as u32 - 2);
        let f0 = c0 - i0 as f32;
        let i1 = (c1 as u32).min(ny as u32 - 2);
        let f1 = c1 - i1 as f32;
        let (i0, i1) = (i0 as usize, i1 as usize);
        crate::emit::interp::multilinear(self.values, &[nx, ny], &[(i0, i0 + 1, f0), (i1, i1 + 1, f1)])
    }

    /// The emitted lookup `NAME(curvature, band)` (SH) in f32.
    pub fn sh_f32(&self, curvature: f32, band: u32) -> [f32; 3] {
        let Layout::Sh { curvature: nx } = self.layout else { panic!("not an SH LUT") };
        if band == 0 {
            return [1.0; 3];
        }
        let [c0, _] = self.coords_f32(curvature, 0.0);
        let i0 = (c0 as u32).min(nx as u32 - 2);
        let f0 = c0 - i0 as f32;
        let row = (band.min(2) - 1) as usize * nx;
        let i0 = i0 as usize;
        crate::emit::interp::multilinear(&self.values[row..row + nx], &[nx], &[(i0, i0 + 1, f0)])
    }

    fn mapping_doc(&self) -> String {
        let n = self.curvature_count() - 1;
        let k = f32_literal(self.curvature_max as f32);
        match self.mapping {
            CurvatureMapping::Linear => format!("κ = {k}·j/{n} (1/mm), uniform in κ"),
            CurvatureMapping::Sqrt => format!("κ = {k}·(j/{n})² (1/mm), denser at small κ"),
        }
    }

    fn layout_doc(&self) -> Vec<String> {
        let (w, h) = self.layout.size();
        match self.layout {
            Layout::Punctual { .. } => vec![
                format!("Texels: {w} n·l columns × {h} curvature rows, row-major, n·l fastest; texel (i, j) holds"),
                format!("D (RGB) at n·l = -1 + 2i/{} and {}.", w - 1, self.mapping_doc()),
            ],
            Layout::Sh { .. } => vec![
                format!("Texels: {w} curvature columns × 2 rows (row 0: band 1, row 1: band 2; band 0 is 1);"),
                format!("texel (j, row) holds k_l (RGB) at {}.", self.mapping_doc()),
            ],
        }
    }

    /// The WGSL library `wgsl/NAME.wgsl`.
    pub fn render_wgsl(&self, header: &[String], doc: &str) -> String {
        let m = self.module;
        let up = m.to_uppercase();
        let f = self.function;
        let c = self.consts();
        let lit = |v: f32| format!("{}f", f32_literal(v));
        let (w, h) = self.layout.size();
        let mut s = String::new();
        for line in header {
            s.push_str(&format!("// {line}\n"));
        }
        s.push_str(&format!("#define_import_path shadefit::{m}\n\n"));
        s.push_str(&format!("// {doc}\n"));
        for line in self.layout_doc() {
            s.push_str(&format!("// {line}\n"));
        }
        s.push_str(&format!(
            "// The texture generated/data/{m}.ktx2 ({}, linear, alpha 1) holds the same texels, for {f}_sample.\n",
            self.format.name()
        ));
        if self.format == TextureFormat::Rgba32float {
            // The spec promised the feature (`float32_filterable = true`): say so where it binds.
            s.push_str(&format!(
                "// {f}_sample filters a 32-bit float texture: the device needs FLOAT32_FILTERABLE (float32-filterable).\n"
            ));
        }
        s.push('\n');
        s.push_str(&format!("const {up}_SIZE: vec2<u32> = vec2<u32>({w}u, {h}u);\n"));
        s.push_str(&format!("const {up}_CURVATURE_MAX: f32 = {};\n", lit(c.kmax)));
        s.push_str(&format!("const {up}_RGB: array<vec3f, {n}> = array<vec3f, {n}>(\n", n = self.values.len()));
        for v in self.values {
            s.push_str(&format!("    vec3f({}, {}, {}),\n", lit(v[0]), lit(v[1]), lit(v[2])));
        }
        s.push_str(");\n\n");
        s.push_str(&format!(
            "// Clamp an input to [lo, hi]; NaN (any exponent-all-ones pattern with a non-zero\n\
             // mantissa) maps to lo.\nfn {m}_input(v: f32, lo: f32, hi: f32) -> f32 {{\n    \
             let nan = (bitcast<u32>(v) & 0x7fffffffu) > 0x7f800000u;\n    \
             return select(clamp(v, lo, hi), lo, nan);\n}}\n\n"
        ));
        let kappa = |x: &str| match self.mapping {
            CurvatureMapping::Linear => format!("{x} * {}", lit(c.k_scale)),
            CurvatureMapping::Sqrt => format!("sqrt({x} * {}) * {}", lit(c.k_inv), lit(c.k_last)),
        };
        let kin = format!("{m}_input(curvature, 0f, {})", lit(c.kmax));
        match self.layout {
            Layout::Punctual { .. } => {
                s.push_str(&format!(
                    "// Continuous texel coordinates of (n·l, κ): 0 at the first texel centre, size - 1 at the last.\n\
                     // n·l is clamped to [-1, 1] and κ (1/mm) to [0, κ_max] (concave κ < 0 reads the κ = 0 row).\n\
                     fn {f}_coords(n_dot_l: f32, curvature: f32) -> vec2<f32> {{\n    \
                     let x0 = {m}_input(n_dot_l, -1f, 1f);\n    \
                     let x1 = {kin};\n    \
                     return vec2<f32>((x0 + 1f) * {s0}, {k1});\n}}\n\n",
                    s0 = lit(c.s0),
                    k1 = kappa("x1"),
                ));
                s.push_str(&format!(
                    "// D(n·l, κ) (RGB) by bilinear interpolation of {up}_RGB (the Rust version computes the same).\n\
                     fn {f}(n_dot_l: f32, curvature: f32) -> vec3<f32> {{\n    \
                     let c = {f}_coords(n_dot_l, curvature);\n    \
                     let i0 = min(u32(c.x), {lx}u);\n    let f0 = c.x - f32(i0);\n    \
                     let i1 = min(u32(c.y), {ly}u);\n    let f1 = c.y - f32(i1);\n    \
                     let k = i1 * {w}u + i0;\n    \
                     let a = {up}_RGB[k] * (1f - f0) + {up}_RGB[k + 1u] * f0;\n    \
                     let b = {up}_RGB[k + {w}u] * (1f - f0) + {up}_RGB[k + {w1}u] * f0;\n    \
                     return a * (1f - f1) + b * f1;\n}}\n\n",
                    lx = w - 2,
                    ly = h - 2,
                    w1 = w + 1,
                ));
                s.push_str(&format!(
                    "// Texture coordinates of (n·l, κ) with half-texel offsets: texel centres sit on the grid points.\n\
                     fn {f}_uv(n_dot_l: f32, curvature: f32) -> vec2<f32> {{\n    \
                     let c = {f}_coords(n_dot_l, curvature);\n    \
                     return (c + vec2<f32>(0.5f)) / vec2<f32>({wf}, {hf});\n}}\n\n",
                    wf = lit(w as f32),
                    hf = lit(h as f32),
                ));
                s.push_str(&format!(
                    "// D(n·l, κ) (RGB) from the LUT texture ({m}.ktx2) through a linear, clamp-to-edge sampler.\n\
                     fn {f}_sample(lut: texture_2d<f32>, lut_sampler: sampler, n_dot_l: f32, curvature: f32) -> vec3<f32> {{\n    \
                     return textureSampleLevel(lut, lut_sampler, {f}_uv(n_dot_l, curvature), 0.0).rgb;\n}}\n"
                ));
            }
            Layout::Sh { .. } => {
                s.push_str(&format!(
                    "// Continuous texel column of κ (1/mm), clamped to [0, κ_max] (concave κ < 0 reads κ = 0).\n\
                     fn {f}_coords(curvature: f32) -> f32 {{\n    \
                     let x0 = {kin};\n    \
                     return {k0};\n}}\n\n",
                    k0 = kappa("x0"),
                ));
                s.push_str(&format!(
                    "// k_l(κ) (RGB), the factor scaling SH band l of the irradiance: 1 for band 0, bands above 2\n\
                     // read band 2. Linear interpolation of {up}_RGB (the Rust version computes the same).\n\
                     fn {f}(curvature: f32, band: u32) -> vec3<f32> {{\n    \
                     if (band == 0u) {{\n        return vec3<f32>(1f);\n    }}\n    \
                     let c = {f}_coords(curvature);\n    \
                     let i0 = min(u32(c), {lx}u);\n    let f0 = c - f32(i0);\n    \
                     let k = (min(band, 2u) - 1u) * {w}u + i0;\n    \
                     return {up}_RGB[k] * (1f - f0) + {up}_RGB[k + 1u] * f0;\n}}\n\n",
                    lx = w - 2,
                ));
                s.push_str(&format!(
                    "// Texture coordinates of (κ, band ≥ 1) with half-texel offsets: texel centres sit on the grid points.\n\
                     fn {f}_uv(curvature: f32, band: u32) -> vec2<f32> {{\n    \
                     let row = f32(clamp(band, 1u, 2u) - 1u);\n    \
                     return vec2<f32>(({f}_coords(curvature) + 0.5f) / {wf}, (row + 0.5f) / 2f);\n}}\n\n",
                    wf = lit(w as f32),
                ));
                s.push_str(&format!(
                    "// k_l(κ) (RGB) from the LUT texture ({m}.ktx2) through a linear, clamp-to-edge sampler.\n\
                     fn {f}_sample(lut: texture_2d<f32>, lut_sampler: sampler, curvature: f32, band: u32) -> vec3<f32> {{\n    \
                     if (band == 0u) {{\n        return vec3<f32>(1f);\n    }}\n    \
                     return textureSampleLevel(lut, lut_sampler, {f}_uv(curvature, band), 0.0).rgb;\n}}\n"
                ));
            }
        }
        s
    }

    /// The Rust module `src/NAME.rs` (same arithmetic as the WGSL, in f32).
    pub fn render_rust(&self, header: &[String], doc: &str) -> String {
        let m = self.module;
        let up = m.to_uppercase();
        let f = self.function;
        let c = self.consts();
        let lit = |v: f32| format!("{}_f32", f32_literal(v));
        let (w, h) = self.layout.size();
        let mut s = String::new();
        for line in header {
            s.push_str(&format!("//! {line}\n"));
        }
        s.push_str(&format!("//!\n//! {doc}\n"));
        for line in self.layout_doc() {
            s.push_str(&format!("//! {line}\n"));
        }
        s.push('\n');
        s.push_str(&format!("/// Texture size (width, height) in texels.\npub const {up}_SIZE: [u32; 2] = [{w}, {h}];\n"));
        s.push_str(&format!(
            "/// Largest curvature (1/mm) of the LUT; larger values read the last texel.\npub const {up}_CURVATURE_MAX: f32 = {};\n",
            lit(c.kmax)
        ));
        s.push_str(&format!(
            "/// Texel format of [`{up}_KTX2`] (WebGPU name).\npub const {up}_FORMAT: &str = \"{}\";\n",
            self.format.name()
        ));
        s.push_str(&format!(
            "/// The LUT as a KTX2 texture (linear RGBA, alpha 1, row 0 first), as written by `shadefit build`.\n\
             pub const {up}_KTX2: &[u8] = include_bytes!(\"../data/{m}.ktx2\");\n"
        ));
        s.push_str(&format!(
            "/// Texels (RGB), row-major: `{up}_RGB[y * {w} + x]` (a static: one copy, not inlined at each use).\npub static {up}_RGB: [[f32; 3]; {n}] = [\n",
            n = self.values.len()
        ));
        for v in self.values {
            s.push_str(&format!("    [{}, {}, {}],\n", f32_literal(v[0]), f32_literal(v[1]), f32_literal(v[2])));
        }
        s.push_str("];\n\n");
        s.push_str("#[inline]\nfn input(v: f32, lo: f32, hi: f32) -> f32 {\n    if v.is_nan() { lo } else { v.clamp(lo, hi) }\n}\n\n");
        let kappa = |x: &str| match self.mapping {
            CurvatureMapping::Linear => format!("{x} * {}", lit(c.k_scale)),
            CurvatureMapping::Sqrt => format!("({x} * {}).sqrt() * {}", lit(c.k_inv), lit(c.k_last)),
        };
        let kin = format!("input(curvature, 0.0, {})", lit(c.kmax));
        match self.layout {
            Layout::Punctual { .. } => {
                s.push_str(&format!(
                    "/// Continuous texel coordinates of (n·l, κ) (WGSL `{f}_coords`): n·l clamped to [-1, 1], κ to\n\
                     /// [0, κ_max] (concave κ < 0 reads the κ = 0 row), NaN to the lower end.\n\
                     pub fn {f}_coords(n_dot_l: f32, curvature: f32) -> [f32; 2] {{\n    \
                     let x0 = input(n_dot_l, -1.0, 1.0);\n    \
                     let x1 = {kin};\n    \
                     [(x0 + 1.0) * {s0}, {k1}]\n}}\n\n",
                    s0 = lit(c.s0),
                    k1 = kappa("x1"),
                ));
                s.push_str(&format!(
                    "/// D(n·l, κ) (RGB): CPU version of the WGSL function of the same name (bilinear interpolation).\n\
                     pub fn {f}(n_dot_l: f32, curvature: f32) -> [f32; 3] {{\n    \
                     let [c0, c1] = {f}_coords(n_dot_l, curvature);\n    \
                     let i0 = (c0 as u32).min({lx});\n    let f0 = c0 - i0 as f32;\n    \
                     let i1 = (c1 as u32).min({ly});\n    let f1 = c1 - i1 as f32;\n    \
                     let k = (i1 * {w} + i0) as usize;\n    \
                     let t = &{up}_RGB;\n    \
                     std::array::from_fn(|ch| {{\n        \
                     let a = t[k][ch] * (1.0 - f0) + t[k + 1][ch] * f0;\n        \
                     let b = t[k + {w}][ch] * (1.0 - f0) + t[k + {w1}][ch] * f0;\n        \
                     a * (1.0 - f1) + b * f1\n    }})\n}}\n\n",
                    lx = w - 2,
                    ly = h - 2,
                    w1 = w + 1,
                ));
                s.push_str(&format!(
                    "/// Texture coordinates with half-texel offsets (WGSL `{f}_uv`).\n\
                     pub fn {f}_uv(n_dot_l: f32, curvature: f32) -> [f32; 2] {{\n    \
                     let [c0, c1] = {f}_coords(n_dot_l, curvature);\n    \
                     [(c0 + 0.5) / {wf}, (c1 + 0.5) / {hf}]\n}}\n",
                    wf = lit(w as f32),
                    hf = lit(h as f32),
                ));
            }
            Layout::Sh { .. } => {
                s.push_str(&format!(
                    "/// Continuous texel column of κ (WGSL `{f}_coords`), κ clamped to [0, κ_max], NaN to 0.\n\
                     pub fn {f}_coords(curvature: f32) -> f32 {{\n    \
                     let x0 = {kin};\n    \
                     {k0}\n}}\n\n",
                    k0 = kappa("x0"),
                ));
                s.push_str(&format!(
                    "/// k_l(κ) (RGB): CPU version of the WGSL function of the same name (1 for band 0; bands\n\
                     /// above 2 read band 2).\n\
                     pub fn {f}(curvature: f32, band: u32) -> [f32; 3] {{\n    \
                     if band == 0 {{\n        return [1.0; 3];\n    }}\n    \
                     let c0 = {f}_coords(curvature);\n    \
                     let i0 = (c0 as u32).min({lx});\n    let f0 = c0 - i0 as f32;\n    \
                     let k = ((band.min(2) - 1) * {w} + i0) as usize;\n    \
                     let t = &{up}_RGB;\n    \
                     std::array::from_fn(|ch| t[k][ch] * (1.0 - f0) + t[k + 1][ch] * f0)\n}}\n\n",
                    lx = w - 2,
                ));
                s.push_str(&format!(
                    "/// Texture coordinates with half-texel offsets (WGSL `{f}_uv`), for band ≥ 1.\n\
                     pub fn {f}_uv(curvature: f32, band: u32) -> [f32; 2] {{\n    \
                     let row = (band.clamp(1, 2) - 1) as f32;\n    \
                     [({f}_coords(curvature) + 0.5) / {wf}, (row + 0.5) / 2.0]\n}}\n",
                    wf = lit(w as f32),
                ));
            }
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn code(layout: Layout, mapping: CurvatureMapping, values: &[[f32; 3]]) -> SkinLutCode<'_> {
        SkinLutCode {
            module: "skin_t",
            function: "skin_t",
            layout,
            curvature_max: 2.0,
            mapping,
            format: TextureFormat::Rgba16float,
            values,
        }
    }

    #[test]
    fn lookups_hit_the_texels_and_interpolate() {
        // A plane in (column, row) is reproduced exactly by bilinear interpolation.
        let (w, h) = (5, 4);
        let vals: Vec<[f32; 3]> = (0..w * h).map(|k| [(k % w) as f32, (k / w) as f32, 1.0]).collect();
        for mapping in [CurvatureMapping::Linear, CurvatureMapping::Sqrt] {
            let c = code(Layout::Punctual { n_dot_l: w, curvature: h }, mapping, &vals);
            assert_eq!(c.punctual_f32(-1.0, 0.0), [0.0, 0.0, 1.0]);
            assert_eq!(c.punctual_f32(1.0, 2.0), [4.0, 3.0, 1.0]);
            assert_eq!(c.punctual_f32(f32::NAN, f32::NAN), [0.0, 0.0, 1.0]);
            assert_eq!(c.punctual_f32(5.0, -3.0), [4.0, 0.0, 1.0]);
            assert_eq!(c.punctual_f32(0.0, f32::INFINITY), [2.0, 3.0, 1.0]);
            // Row 1 sits at t = 1/3: κ = 2/3 (linear) or 2/9 (sqrt).
            let k1 = match mapping {
                CurvatureMapping::Linear => 2.0 / 3.0,
                CurvatureMapping::Sqrt => 2.0 / 9.0,
            };
            let v = c.punctual_f32(-0.25, k1);
            assert!((v[0] - 1.5).abs() < 1e-6 && (v[1] - 1.0).abs() < 1e-6, "{v:?}");
        }
        let sh: Vec<[f32; 3]> = (0..2 * w).map(|k| [(k % w) as f32, (k / w) as f32, 0.5]).collect();
        let c = code(Layout::Sh { curvature: w }, CurvatureMapping::Linear, &sh);
        assert_eq!(c.sh_f32(1.0, 0), [1.0; 3]);
        assert_eq!(c.sh_f32(1.0, 1), [2.0, 0.0, 0.5]);
        assert_eq!(c.sh_f32(1.0, 2), [2.0, 1.0, 0.5]);
        assert_eq!(c.sh_f32(1.0, 7), [2.0, 1.0, 0.5]);
    }

    #[test]
    fn emitted_code_names_itself_and_declares_its_functions() {
        let vals = [[0.5f32; 3]; 12];
        for (layout, n) in [(Layout::Punctual { n_dot_l: 4, curvature: 3 }, 12), (Layout::Sh { curvature: 6 }, 12)] {
            let c = code(layout, CurvatureMapping::Sqrt, &vals[..n]);
            let w = c.render_wgsl(&["h1".into()], "doc");
            assert!(w.starts_with("// h1\n#define_import_path shadefit::skin_t\n"));
            for f in ["fn skin_t_coords(", "fn skin_t(", "fn skin_t_uv(", "fn skin_t_sample(", "sqrt("] {
                assert!(w.contains(f), "{f}");
            }
            let r = c.render_rust(&["h1".into()], "doc");
            for f in ["pub fn skin_t_coords(", "pub fn skin_t(", "pub fn skin_t_uv(", "include_bytes!(\"../data/skin_t.ktx2\")"] {
                assert!(r.contains(f), "{f}");
            }
        }
    }
}
