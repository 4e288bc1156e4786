//! Lookup tables of the table modules as textures, with WGSL accessors.
//!
//! The emitted table functions (`gloss_to_normal_length_lut`, `combine_gloss_lut`, ...) read
//! their table from a WGSL `const` array, which is simple but puts the whole table in the
//! shader (a 64×64 table is 4096 constants, dynamically indexed). For real shaders the same
//! values can live in a texture: [`Table::wgsl`] writes an accessor `FUNCTION_tex(...)` doing
//! exactly the arithmetic of the emitted function (same clamp, same index and weight
//! computation, same interpolation order) but reading the values with `textureLoad`, and
//! (feature `gpu`) [`Table::create_texture`] uploads the table.
//!
//! # Layout
//! A table with axes of `n0 (× n1)` points, first axis fastest (the emitted layout), is a 2-D
//! texture of width `n0` and height `n1` (1 for a one-argument table): `gloss_table` is
//! 256×1, `gloss_inverse_table` 1024×1, `gloss_combine_lut` 64×64. The axis counts are read
//! from the emitted WGSL (`min(u32(tK), LASTu)` gives `nK = LAST + 2`) and checked against the
//! `*_TABLE` length and the number of domain axes, so the texture always matches the indexing.
//!
//! # Format and filtering
//! [`FORMAT`] is `R32Float`: the f32 table values exactly, so the texture accessor agrees
//! with the CPU function and the const-array WGSL. WebGPU classes R32Float as
//! *unfilterable-float* (linear filtering needs the optional `float32-filterable` feature),
//! so the accessor uses `textureLoad` on texel indices and interpolates in the shader, bound
//! as `TextureSampleType::Float { filterable: false }`. Hardware linear filtering was rejected
//! on precision grounds too: a filterable R16Float keeps 11 significant bits (relative error
//! 2^-11 ≈ 4.9e-4, fifty times the 8.4e-6 error of the `gloss_table` fit), and texture units
//! compute bilinear weights in fixed point (Vulkan guarantees only 4 bits of sub-texel
//! precision, most GPUs use 8), so a filtered lookup could be off by a sizeable fraction of a
//! table step. The [`LutTexture::sampler`] made alongside (nearest, clamp-to-edge,
//! `SamplerBindingType::NonFiltering`) is for shaders that prefer `textureSampleLevel` at
//! texel centres; the accessor itself needs no sampler.
//!
//! # Emitted texture form
//! A table spec with `[emit] form = "texture"` or `"both"` also has its table as a KTX2 file
//! (`generated/data/NAME.ktx2`, carried as `NAME_KTX2` and [`Table::ktx2`]): one channel, the
//! spec's `texture_format` (R32Float, the f32 values exactly, or R16Float, rounded to nearest
//! half), width `n0`, height `n1` (1 for one axis), texel (i, j) the value at point i of the
//! first axis and j of the second. The module gains `FUNCTION_load(lut, args)` (textureLoad and
//! the interpolation of `FUNCTION`, any format, no sampler) and, when the format is filterable
//! on the engine's device (R16Float; R32Float only with `float32_filterable = true` in the spec),
//! `FUNCTION_sample(lut, lut_sampler, args)` through a linear, clamp-to-edge sampler at texel
//! centres. [`Table::upload_ktx2`] uploads the file; asked for a linear sampler it refuses a
//! 32-bit float texture on a device without `FLOAT32_FILTERABLE`
//! ([`crate::skin::Ktx2Error::NeedsFloat32Filterable`]), as the skin LUTs do.

/// Texture format of the lookup tables (see the module documentation).
#[cfg(feature = "gpu")]
pub const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

/// One emitted lookup table: the module, the function that interpolates it, the domain of
/// its arguments and the values (uniform grid over the domain, first axis fastest).
#[derive(Clone, Copy, Debug)]
pub struct Table {
    pub module: &'static str,
    pub function: &'static str,
    pub domain: &'static [[f32; 2]],
    pub values: &'static [f32],
    /// The table's KTX2 texture (`NAME_KTX2`), when its spec asks for the texture form
    /// (`[emit] form = "texture"` or `"both"`): read by the emitted `FUNCTION_load` and, for a
    /// filterable format, `FUNCTION_sample`; [`Table::upload_ktx2`] (feature `gpu`) uploads it.
    pub ktx2: Option<&'static [u8]>,
}

/// Every table module compiled in.
///
/// Hand-written: emitted.rs lists the functions, not the tables; the test
/// `every_table_module_is_listed` fails when a new table module is emitted but not added here.
pub const TABLES: &[Table] = &[
    #[cfg(feature = "ggx")]
    Table {
        module: "ggx_albedo_avg_table",
        function: "ggx_albedo_avg_lut",
        domain: &crate::ggx_albedo_avg_table::GGX_ALBEDO_AVG_TABLE_DOMAIN,
        values: &crate::ggx_albedo_avg_table::GGX_ALBEDO_AVG_TABLE_TABLE,
        ktx2: Some(crate::ggx_albedo_avg_table::GGX_ALBEDO_AVG_TABLE_KTX2),
    },
    #[cfg(feature = "ggx")]
    Table {
        module: "ggx_albedo_table",
        function: "ggx_albedo_lut",
        domain: &crate::ggx_albedo_table::GGX_ALBEDO_TABLE_DOMAIN,
        values: &crate::ggx_albedo_table::GGX_ALBEDO_TABLE_TABLE,
        ktx2: Some(crate::ggx_albedo_table::GGX_ALBEDO_TABLE_KTX2),
    },
    #[cfg(feature = "gloss")]
    Table {
        module: "gloss_combine_lut",
        function: "combine_gloss_lut",
        domain: &crate::gloss_combine_lut::GLOSS_COMBINE_LUT_DOMAIN,
        values: &crate::gloss_combine_lut::GLOSS_COMBINE_LUT_TABLE,
        ktx2: Some(crate::gloss_combine_lut::GLOSS_COMBINE_LUT_KTX2),
    },
    #[cfg(feature = "gloss")]
    Table {
        module: "gloss_inverse_table",
        function: "normal_length_to_gloss_lut",
        domain: &crate::gloss_inverse_table::GLOSS_INVERSE_TABLE_DOMAIN,
        values: &crate::gloss_inverse_table::GLOSS_INVERSE_TABLE_TABLE,
        ktx2: Some(crate::gloss_inverse_table::GLOSS_INVERSE_TABLE_KTX2),
    },
    #[cfg(feature = "gloss")]
    Table {
        module: "gloss_table",
        function: "gloss_to_normal_length_lut",
        domain: &crate::gloss_table::GLOSS_TABLE_DOMAIN,
        values: &crate::gloss_table::GLOSS_TABLE_TABLE,
        ktx2: Some(crate::gloss_table::GLOSS_TABLE_KTX2),
    },
    #[cfg(feature = "sheen")]
    Table {
        module: "sheen_albedo_table",
        function: "sheen_albedo_lut",
        domain: &crate::sheen_albedo_table::SHEEN_ALBEDO_TABLE_DOMAIN,
        values: &crate::sheen_albedo_table::SHEEN_ALBEDO_TABLE_TABLE,
        ktx2: Some(crate::sheen_albedo_table::SHEEN_ALBEDO_TABLE_KTX2),
    },
    #[cfg(feature = "sheen")]
    Table {
        module: "sheen_dfg_filament",
        function: "sheen_dfg_lut",
        domain: &crate::sheen_dfg_filament::SHEEN_DFG_FILAMENT_DOMAIN,
        values: &crate::sheen_dfg_filament::SHEEN_DFG_FILAMENT_TABLE,
        ktx2: Some(crate::sheen_dfg_filament::SHEEN_DFG_FILAMENT_KTX2),
    },
];

/// The table of a module, if it is a table module compiled in.
pub fn table(module: &str) -> Option<&'static Table> {
    TABLES.iter().find(|t| t.module == module)
}

/// Text between `start` (included) and the first following line that is exactly `}`.
fn wgsl_fn<'a>(src: &'a str, start: &str) -> &'a str {
    let i = src.find(start).unwrap_or_else(|| panic!("emitted WGSL lacks `{start}`"));
    let len = src[i..].find("\n}\n").unwrap_or_else(|| panic!("unterminated `{start}`")) + 3;
    &src[i..i + len]
}

impl Table {
    /// The emitted WGSL library of the module.
    pub fn emitted_wgsl(&self) -> &'static str {
        crate::wgsl::module(self.module).expect("table modules have WGSL")
    }

    /// Points per axis, read from the emitted WGSL and checked against the table length and
    /// the domain (panics if the emitted code has another shape, which a test rules out).
    pub fn counts(&self) -> Vec<u32> {
        let src = self.emitted_wgsl();
        let counts: Vec<u32> = (0..self.domain.len())
            .map(|k| {
                // `let iK = min(u32(tK), LASTu);` at nodes, `min(u32(max(tK, 0.0f)), LASTu);` at
                // texel centres: LAST is the last cell's index, the count minus 2.
                let pat = format!("let i{k} = min(u32(");
                let at = src.find(&pat).unwrap_or_else(|| panic!("{}: no `{pat}` in the WGSL", self.module));
                let line = &src[at..at + src[at..].find('\n').expect("a line")];
                let last: u32 = line.rsplit(", ").next().and_then(|r| r.strip_suffix("u);")).and_then(|n| n.parse().ok()).expect("integer LAST");
                last + 2
            })
            .collect();
        assert!(
            !src.contains(&format!("let i{} = min(", self.domain.len())),
            "{}: more table axes than domain arguments",
            self.module
        );
        assert_eq!(counts.iter().product::<u32>() as usize, self.values.len(), "{}: axis counts vs table length", self.module);
        counts
    }

    /// Texture size (width, height): first axis across, second axis (if any) down.
    pub fn size(&self) -> (u32, u32) {
        let c = self.counts();
        assert!(c.len() <= 2, "{}: tables of more than 2 axes need a 3-D texture", self.module);
        (c[0], c.get(1).copied().unwrap_or(1))
    }

    /// Name of the texture variable declared by [`Table::wgsl`]: `MODULE_tex`.
    pub fn texture_name(&self) -> String {
        format!("{}_tex", self.module)
    }

    /// Name of the WGSL accessor declared by [`Table::wgsl`]: `FUNCTION_tex`.
    pub fn accessor_name(&self) -> String {
        format!("{}_tex", self.function)
    }

    /// Self-contained WGSL for the texture version of the table function (needs the module's
    /// const-array function: for a module emitted as a texture only, use its `FUNCTION_load`): the declaration
    /// `@group(group) @binding(binding) var MODULE_tex: texture_2d<f32>;`, a copy of the module's
    /// input clamp, a texel-fetch helper and `FUNCTION_tex(args) -> f32`, which is the emitted
    /// function with every `TABLE[i]` replaced by a `textureLoad` of texel `(i % width, i / width)`.
    /// Needs no import; it can sit next to the emitted library in the same shader.
    pub fn wgsl(&self, group: u32, binding: u32) -> String {
        let src = self.emitted_wgsl();
        let m = self.module;
        let (width, _) = self.size();
        let tex = self.texture_name();
        let load = format!("{m}_tex_load");
        let input = wgsl_fn(src, &format!("fn {m}_input(")).replace(&format!("{m}_input("), &format!("{m}_tex_input("));
        let func = wgsl_fn(src, &format!("fn {}(", self.function))
            .replace(&format!("fn {}(", self.function), &format!("fn {}(", self.accessor_name()))
            .replace(&format!("{m}_input("), &format!("{m}_tex_input("));
        // TABLE[expr] -> load(expr); the index expressions contain no brackets.
        let array = format!("{}_TABLE[", m.to_uppercase());
        let mut body = String::new();
        let mut rest = func.as_str();
        while let Some(i) = rest.find(&array) {
            let close = rest[i..].find(']').expect("closing bracket") + i;
            body.push_str(&rest[..i]);
            body.push_str(&format!("{load}({})", &rest[i + array.len()..close]));
            rest = &rest[close + 1..];
        }
        body.push_str(rest);
        format!(
            "// Texture version of shadefit::{m}::{f} (values in `{tex}`, R32Float, {w}x{h} texels).\n\
             @group({group}) @binding({binding}) var {tex}: texture_2d<f32>;\n\n\
             {input}\n\
             fn {load}(i: u32) -> f32 {{\n    return textureLoad({tex}, vec2<u32>(i % {width}u, i / {width}u), 0).x;\n}}\n\n\
             {body}",
            f = self.function,
            w = width,
            h = self.values.len() as u32 / width,
        )
    }
}

#[cfg(feature = "gpu")]
mod gpu {
    use super::{FORMAT, Table};
    use wgpu::util::DeviceExt;

    /// A table uploaded to the GPU: the texture (R32Float, [`Table::size`]), a view of it, and a
    /// nearest, clamp-to-edge sampler (non-filtering; the WGSL accessor does not use it).
    #[derive(Debug, Clone)]
    pub struct LutTexture {
        pub table: &'static Table,
        pub texture: wgpu::Texture,
        pub view: wgpu::TextureView,
        pub sampler: wgpu::Sampler,
    }

    impl Table {
        /// Upload the table as an R32Float texture (one mip level, `TEXTURE_BINDING | COPY_DST`).
        pub fn create_texture(&'static self, device: &wgpu::Device, queue: &wgpu::Queue) -> LutTexture {
            let (width, height) = self.size();
            let texture = device.create_texture_with_data(
                queue,
                &wgpu::TextureDescriptor {
                    label: Some(self.module),
                    size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format: FORMAT,
                    usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                    view_formats: &[],
                },
                wgpu::util::TextureDataOrder::LayerMajor,
                bytemuck::cast_slice(self.values),
            );
            let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
            let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some(self.module),
                address_mode_u: wgpu::AddressMode::ClampToEdge,
                address_mode_v: wgpu::AddressMode::ClampToEdge,
                address_mode_w: wgpu::AddressMode::ClampToEdge,
                mag_filter: wgpu::FilterMode::Nearest,
                min_filter: wgpu::FilterMode::Nearest,
                mipmap_filter: wgpu::MipmapFilterMode::Nearest,
                ..Default::default()
            });
            LutTexture { table: self, texture, view, sampler }
        }
    }

    impl Table {
        /// Upload the table's KTX2 texture ([`Table::ktx2`]; `None` for a table emitted as a
        /// `const` array only). `linear`: a linear, clamp-to-edge sampler for
        /// `FUNCTION_sample`, refused for an R32Float texture on a device without
        /// `FLOAT32_FILTERABLE`; otherwise a nearest one (`FUNCTION_load` needs none).
        pub fn upload_ktx2(
            &'static self,
            device: &wgpu::Device,
            queue: &wgpu::Queue,
            linear: bool,
        ) -> Option<Result<LutTexture, crate::skin::Ktx2Error>> {
            let bytes = self.ktx2?;
            Some(crate::runtime::skin::upload_ktx2(device, queue, self.module, bytes, linear).map(|texture| {
                let filter = if linear { wgpu::FilterMode::Linear } else { wgpu::FilterMode::Nearest };
                let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
                let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
                    label: Some(self.module),
                    address_mode_u: wgpu::AddressMode::ClampToEdge,
                    address_mode_v: wgpu::AddressMode::ClampToEdge,
                    address_mode_w: wgpu::AddressMode::ClampToEdge,
                    mag_filter: filter,
                    min_filter: filter,
                    mipmap_filter: wgpu::MipmapFilterMode::Nearest,
                    ..Default::default()
                });
                LutTexture { table: self, texture, view, sampler }
            }))
        }
    }

    impl LutTexture {
        /// Bind group layout entry for the texture (`texture_2d<f32>`, unfilterable float).
        pub fn texture_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
            wgpu::BindGroupLayoutEntry {
                binding,
                visibility,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            }
        }

        /// Bind group layout entry for [`LutTexture::sampler`] (non-filtering).
        pub fn sampler_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
            wgpu::BindGroupLayoutEntry {
                binding,
                visibility,
                ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::NonFiltering),
                count: None,
            }
        }
    }
}

#[cfg(feature = "gpu")]
pub use gpu::LutTexture;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_table_module_is_listed() {
        for name in crate::wgsl::NAMES {
            let src = crate::wgsl::module(name).unwrap();
            // A table module has a const array, a texture reader (`form = "texture"`), or both.
            let is_table = src.contains(&format!("const {}_TABLE:", name.to_uppercase()))
                || src.contains("_load(lut: texture_2d<f32>, ");
            assert_eq!(is_table, table(name).is_some(), "{name}: table module not in lut::TABLES (or listed but not one)");
        }
        for t in TABLES {
            let f = crate::FUNCTIONS.iter().find(|f| f.module == t.module).expect("table module has a function");
            assert_eq!((f.name, f.domain), (t.function, t.domain), "{}", t.module);
        }
    }

    #[cfg(feature = "gloss")]
    #[test]
    fn sizes_follow_the_emitted_tables() {
        assert_eq!(table("gloss_table").unwrap().size(), (256, 1));
        assert_eq!(table("gloss_inverse_table").unwrap().size(), (1024, 1));
        assert_eq!(table("gloss_combine_lut").unwrap().size(), (64, 64));
    }

    #[test]
    fn ktx2_textures_hold_the_table_values() {
        for t in TABLES {
            let load = format!("fn {}_load(lut: texture_2d<f32>", t.function);
            assert_eq!(t.ktx2.is_some(), t.emitted_wgsl().contains(&load), "{}: NAME_KTX2 iff the WGSL reads it", t.module);
            let Some(bytes) = t.ktx2 else { continue };
            let img = crate::skin::Ktx2Image::parse(bytes).unwrap();
            assert_eq!((img.width, img.height), t.size(), "{}", t.module);
            let sample = t.emitted_wgsl().contains(&format!("fn {}_sample(", t.function));
            for (k, &v) in t.values.iter().enumerate() {
                let got = img.texel(k as u32 % img.width, k as u32 / img.width)[0];
                match img.format {
                    crate::skin::LutFormat::R32Float => {
                        assert_eq!(got.to_bits(), v.to_bits(), "{} texel {k}", t.module);
                        // Never a linear sampler on R32Float unless the spec asked for it.
                        assert!(!sample || t.emitted_wgsl().contains("float32-filterable"), "{}", t.module);
                    }
                    crate::skin::LutFormat::R16Float => {
                        // Round to nearest half: within half a unit in the last place of the
                        // 11-bit significand, |v|·2^-11 for normal halves (|v| >= 2^-14), 2^-25
                        // below.
                        let bound = (v.abs() * 2f32.powi(-11)).max(2f32.powi(-25));
                        assert!((got - v).abs() <= bound, "{} texel {k}: {got} vs {v}", t.module);
                    }
                    other => panic!("{}: {other:?} is not a one-channel format", t.module),
                }
            }
        }
    }

    #[test]
    fn accessors_read_the_texture_only() {
        for t in TABLES {
            let w = t.wgsl(1, 2);
            assert!(w.contains(&format!("@group(1) @binding(2) var {}: texture_2d<f32>;", t.texture_name())));
            assert!(w.contains(&format!("fn {}(", t.accessor_name())));
            assert!(!w.contains("_TABLE"), "{w}");
            assert!(!w.contains(&format!("{}_input(", t.module)), "{w}");
        }
    }
}
