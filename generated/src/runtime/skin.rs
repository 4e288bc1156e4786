//! Skin LUT glue: the directional curvature a LUT lookup needs, and the KTX2 textures.
//!
//! # Curvature
//! The skin LUTs (`skin_punctual_lut`, `skin_sh_lut`, feature `skin`) take the curvature κ
//! (1/mm) of the surface *along the light*. [`skin_curvature_from_light`] and
//! [`skin_curvature_from_light_normalized`] compute it from a curvature tensor, on the CPU here
//! and in WGSL in the library [`CURVATURE_WGSL`] (`#import shadefit::skin_curvature`, resolved
//! by [`crate::compose_shader`]); both versions do the same f32 operations in the same order.
//!
//! `curv_tensor` = (k_tt, k_tb, k_bb) is the symmetric tensor C = [[k_tt, k_tb], [k_tb, k_bb]]
//! of the surface's second fundamental form in an orthonormal tangent frame (tangent,
//! bitangent), positive where the surface bends away from its normal (a sphere of radius r:
//! C = I/r). With l_t = (l·t, l·b), the light direction projected onto the tangent plane:
//! - [`skin_curvature_from_light`]: κ = l_tᵀ C l_t = (curvature along l_t)·(1 − (n·l)²), which
//!   fades to 0 as the light nears the normal (where the LUTs depend least on κ); no division;
//! - [`skin_curvature_from_light_normalized`]: κ = l_tᵀ C l_t / |l_t|², the normal curvature
//!   along the projected light direction (Euler's k₁cos²ψ + k₂sin²ψ), the curvature of the
//!   cylinder the punctual LUT's ring integral assumes; the mean curvature (k_tt + k_bb)/2 when
//!   |l_t|² < 1e-8 (the light along the normal has no tangent direction).
//!
//! Units: the LUTs tabulate κ in 1/mm; a tensor estimated in a mesh's units (1/m, 1/cm) must be
//! scaled (×0.001, ×0.1). Neither function clamps: the LUT lookups map concave κ < 0 to the
//! κ = 0 row, i.e. max(n·l, 0).
//!
//! # Textures
//! Each skin LUT module carries its texture as KTX2 bytes (`NAME_KTX2`: linear RGBA16F or
//! RGBA32F, alpha 1, one level), as do the split-sum DFG LUTs (RG16F, 2-D) and the cone LUT
//! (RG16F, 3-D). [`Ktx2Image::parse`] reads the header this crate's generator writes (no
//! supercompression, one 2-D or 3-D level); with the `gpu` feature [`create_lut_texture`]
//! uploads it and [`lut_sampler`] makes the linear, clamp-to-edge sampler the emitted
//! `NAME_sample` functions expect. RGBA16F is filterable in core WebGPU; RGBA32F needs the
//! `FLOAT32_FILTERABLE` feature for a linear sampler, so [`create_lut_texture`] refuses an
//! RGBA32F texture on a device created without it ([`Ktx2Error::NeedsFloat32Filterable`];
//! request the feature, or use the const-array lookup `NAME`).

/// The WGSL library `shadefit::skin_curvature` (hand-written, see the module docs).
pub const CURVATURE_WGSL: &str = include_str!("skin_curvature.wgsl");

#[inline]
fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// κ = l_tᵀ C l_t: the curvature along the projected light direction times 1 − (n·l)² (see the
/// module docs). CPU version of the WGSL function of the same name.
pub fn skin_curvature_from_light(tangent: [f32; 3], bitangent: [f32; 3], curv_tensor: [f32; 3], light_dir: [f32; 3]) -> f32 {
    let x = dot(light_dir, tangent);
    let y = dot(light_dir, bitangent);
    curv_tensor[0] * x * x + 2.0 * curv_tensor[1] * x * y + curv_tensor[2] * y * y
}

/// κ = l_tᵀ C l_t / |l_t|²: the normal curvature along the projected light direction (mean
/// curvature when the light is within ~1e-4 rad of the normal). CPU version of the WGSL
/// function of the same name.
pub fn skin_curvature_from_light_normalized(
    tangent: [f32; 3],
    bitangent: [f32; 3],
    curv_tensor: [f32; 3],
    light_dir: [f32; 3],
) -> f32 {
    let x = dot(light_dir, tangent);
    let y = dot(light_dir, bitangent);
    let q = curv_tensor[0] * x * x + 2.0 * curv_tensor[1] * x * y + curv_tensor[2] * y * y;
    let len2 = x * x + y * y;
    if len2 > 1e-8 { q / len2 } else { 0.5 * (curv_tensor[0] + curv_tensor[2]) }
}

/// Why KTX2 bytes were not read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Ktx2Error {
    /// Not a KTX2 file, or shorter than its header says.
    Malformed(&'static str),
    /// A `VkFormat` other than R16F (76), R32F (100), RG16F (83), RG32F (103), RGBA16F (97)
    /// and RGBA32F (109).
    Format(u32),
    /// Supercompressed, layered, cube or mipmapped: not what shadefit writes.
    Unsupported(&'static str),
    /// A 32-bit float texture for a linear sampler on a device without `FLOAT32_FILTERABLE`.
    NeedsFloat32Filterable,
}

impl std::fmt::Display for Ktx2Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Ktx2Error::Malformed(why) => write!(f, "malformed KTX2: {why}"),
            Ktx2Error::Format(v) => {
                write!(f, "KTX2 VkFormat {v} is not R16F (76), R32F (100), RG16F (83), RG32F (103), RGBA16F (97) or RGBA32F (109)")
            }
            Ktx2Error::Unsupported(what) => write!(f, "unsupported KTX2: {what}"),
            Ktx2Error::NeedsFloat32Filterable => write!(
                f,
                "a 32-bit float LUT is sampled linearly: create the device with wgpu::Features::FLOAT32_FILTERABLE"
            ),
        }
    }
}

impl std::error::Error for Ktx2Error {}

/// Texel format of a LUT texture: RGBA for the skin LUTs, RG for the split-sum (DFG) and cone
/// LUTs (scale, bias), one channel for the table modules (`crate::lut`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LutFormat {
    Rgba16Float,
    Rgba32Float,
    Rg16Float,
    Rg32Float,
    R16Float,
    R32Float,
}

impl LutFormat {
    /// Whether a linear sampler on this format needs the optional `float32-filterable`
    /// feature (WebGPU: 32-bit float formats are unfilterable in core).
    pub fn needs_float32_filterable(self) -> bool {
        matches!(self, LutFormat::Rgba32Float | LutFormat::Rg32Float | LutFormat::R32Float)
    }

    /// Channels per texel.
    pub fn channels(self) -> usize {
        match self {
            LutFormat::Rgba16Float | LutFormat::Rgba32Float => 4,
            LutFormat::Rg16Float | LutFormat::Rg32Float => 2,
            LutFormat::R16Float | LutFormat::R32Float => 1,
        }
    }

    /// Bytes per channel.
    pub fn channel_size(self) -> usize {
        match self {
            LutFormat::Rgba16Float | LutFormat::Rg16Float | LutFormat::R16Float => 2,
            LutFormat::Rgba32Float | LutFormat::Rg32Float | LutFormat::R32Float => 4,
        }
    }

    #[cfg(feature = "gpu")]
    fn wgpu(self) -> wgpu::TextureFormat {
        match self {
            LutFormat::Rgba16Float => wgpu::TextureFormat::Rgba16Float,
            LutFormat::Rgba32Float => wgpu::TextureFormat::Rgba32Float,
            LutFormat::Rg16Float => wgpu::TextureFormat::Rg16Float,
            LutFormat::Rg32Float => wgpu::TextureFormat::Rg32Float,
            LutFormat::R16Float => wgpu::TextureFormat::R16Float,
            LutFormat::R32Float => wgpu::TextureFormat::R32Float,
        }
    }
}

/// The one level of a KTX2 file: size, format and the texels (little-endian, row 0 of slice 0
/// first).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Ktx2Image<'a> {
    pub width: u32,
    pub height: u32,
    /// The file's `pixelDepth`: 0 for a 2-D image, the slice count of a 3-D one (the cone LUT).
    pub depth: u32,
    pub format: LutFormat,
    /// Borrowed from the file, or inflated from a Zstandard-supercompressed one.
    pub data: std::borrow::Cow<'a, [u8]>,
}

impl<'a> Ktx2Image<'a> {
    /// Read the header and the level index of an uncompressed, single-level 2-D or 3-D KTX2 file
    /// (KTX 2.0 §3: the identifier, `vkFormat` at byte 12, `pixelWidth`/`Height`/`Depth` at 20,
    /// 24, 28, the level index at 80).
    pub fn parse(bytes: &'a [u8]) -> Result<Ktx2Image<'a>, Ktx2Error> {
        const ID: [u8; 12] = [0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A];
        if bytes.len() < 104 || bytes[..12] != ID {
            return Err(Ktx2Error::Malformed("no KTX 20 identifier"));
        }
        let u32_at = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().expect("4 bytes"));
        let u64_at = |o: usize| u64::from_le_bytes(bytes[o..o + 8].try_into().expect("8 bytes"));
        let format = match u32_at(12) {
            97 => LutFormat::Rgba16Float,
            109 => LutFormat::Rgba32Float,
            83 => LutFormat::Rg16Float,
            103 => LutFormat::Rg32Float,
            76 => LutFormat::R16Float,
            100 => LutFormat::R32Float,
            other => return Err(Ktx2Error::Format(other)),
        };
        let (width, height, depth, layers, faces, levels, scheme) =
            (u32_at(20), u32_at(24), u32_at(28), u32_at(32), u32_at(36), u32_at(40), u32_at(44));
        // Supercompression scheme 0 (none) or 2 (Zstandard, as bevy's dfg.ktx2 and the
        // `ktx2-zstd` table format store it).
        if scheme != 0 && scheme != 2 {
            return Err(Ktx2Error::Unsupported("supercompression other than Zstandard"));
        }
        if layers > 1 || faces != 1 || levels > 1 || height == 0 || width == 0 {
            return Err(Ktx2Error::Unsupported("not a single-level 2-D or 3-D image"));
        }
        let (offset, length, full) = (u64_at(80) as usize, u64_at(88) as usize, u64_at(96) as usize);
        let texel = format.channels() * format.channel_size();
        let expected = (width as usize).checked_mul(height as usize).and_then(|n| n.checked_mul(depth.max(1) as usize)).and_then(|n| n.checked_mul(texel));
        if Some(full) != expected || (scheme == 0 && length != full) {
            return Err(Ktx2Error::Malformed("level length differs from width × height × depth × texel size"));
        }
        let stored = offset.checked_add(length).and_then(|end| bytes.get(offset..end)).ok_or(Ktx2Error::Malformed("level data beyond the end"))?;
        let data = if scheme == 0 {
            std::borrow::Cow::Borrowed(stored)
        } else {
            let mut out = Vec::with_capacity(full);
            ruzstd::decoding::FrameDecoder::new().decode_all_to_vec(stored, &mut out).map_err(|_| Ktx2Error::Malformed("the Zstandard level data does not decode"))?;
            if out.len() != full {
                return Err(Ktx2Error::Malformed("the Zstandard level data inflate to another length than uncompressedByteLength"));
            }
            std::borrow::Cow::Owned(out)
        };
        Ok(Ktx2Image { width, height, depth, format, data })
    }

    /// Texel (x, y) of a 2-D image (of slice 0 of a 3-D one) as f32 RGBA: [`Ktx2Image::texel_3d`]
    /// at z = 0.
    pub fn texel(&self, x: u32, y: u32) -> [f32; 4] {
        self.texel_3d(x, y, 0)
    }

    /// Texel (x, y, z) as f32 RGBA (f16 widened exactly; missing channels as WGSL reads them:
    /// a one-channel texel is (r, 0, 0, 1), a two-channel one (r, g, 0, 1)).
    pub fn texel_3d(&self, x: u32, y: u32, z: u32) -> [f32; 4] {
        let k = ((z as usize * self.height as usize + y as usize) * self.width as usize) + x as usize;
        let (n, size) = (self.format.channels(), self.format.channel_size());
        std::array::from_fn(|c| {
            if c >= n {
                return if c == 3 { 1.0 } else { 0.0 };
            }
            let o = (n * k + c) * size;
            match size {
                2 => f16_to_f32(u16::from_le_bytes([self.data[o], self.data[o + 1]])),
                _ => f32::from_le_bytes(self.data[o..o + 4].try_into().expect("4 bytes")),
            }
        })
    }
}

/// IEEE binary16 bits to f32 (exact: every half is an f32).
pub fn f16_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exp = ((h >> 10) & 0x1f) as i32;
    let man = (h & 0x3ff) as f32;
    sign * match exp {
        0 => man * 2f32.powi(-24),
        31 if man == 0.0 => f32::INFINITY,
        31 => f32::NAN,
        e => (1.0 + man / 1024.0) * 2f32.powi(e - 15),
    }
}

#[cfg(feature = "gpu")]
mod gpu {
    use super::{Ktx2Error, Ktx2Image};
    use wgpu::util::DeviceExt;

    /// Upload a LUT's KTX2 bytes (`NAME_KTX2`: the skin LUTs, RGBA; the split-sum DFG LUTs, RG
    /// 2-D; the cone LUT, RG 3-D) as a texture of its format, one level, `TEXTURE_BINDING |
    /// COPY_DST`, 3-D where the file's `pixelDepth` is non-zero (bind a `texture_3d` view). A
    /// 32-bit float texture is refused unless the device has `FLOAT32_FILTERABLE`:
    /// [`lut_sampler`] filters linearly.
    pub fn create_lut_texture(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        label: &str,
        ktx2: &[u8],
    ) -> Result<wgpu::Texture, Ktx2Error> {
        upload(device, queue, label, ktx2, true)
    }

    /// Upload KTX2 bytes of any [`LutFormat`] as a 2-D or 3-D texture; `linear`: the texture is to be
    /// read through a linear sampler, so a 32-bit float format needs `FLOAT32_FILTERABLE`.
    pub(crate) fn upload(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        label: &str,
        ktx2: &[u8],
        linear: bool,
    ) -> Result<wgpu::Texture, Ktx2Error> {
        let img = Ktx2Image::parse(ktx2)?;
        if linear && img.format.needs_float32_filterable() && !device.features().contains(wgpu::Features::FLOAT32_FILTERABLE) {
            return Err(Ktx2Error::NeedsFloat32Filterable);
        }
        let format = img.format.wgpu();
        Ok(device.create_texture_with_data(
            queue,
            &wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width: img.width, height: img.height, depth_or_array_layers: img.depth.max(1) },
                mip_level_count: 1,
                sample_count: 1,
                dimension: if img.depth == 0 { wgpu::TextureDimension::D2 } else { wgpu::TextureDimension::D3 },
                format,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            &img.data,
        ))
    }

    /// The sampler the emitted `NAME_sample` functions expect: linear, clamp-to-edge, one level
    /// (bind as `SamplerBindingType::Filtering`).
    pub fn lut_sampler(device: &wgpu::Device) -> wgpu::Sampler {
        device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("shadefit skin LUT"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            address_mode_w: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Nearest,
            ..Default::default()
        })
    }
}

#[cfg(feature = "gpu")]
pub use gpu::{create_lut_texture, lut_sampler};
#[cfg(feature = "gpu")]
pub(crate) use gpu::upload as upload_ktx2;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_decoding() {
        assert_eq!(f16_to_f32(0x3C00), 1.0);
        assert_eq!(f16_to_f32(0xC000), -2.0);
        assert_eq!(f16_to_f32(0x3555), 0.333_251_95);
        assert_eq!(f16_to_f32(0x0001), 2f32.powi(-24));
        assert_eq!(f16_to_f32(0x7BFF), 65504.0);
        assert_eq!(f16_to_f32(0x7C00), f32::INFINITY);
        assert!(f16_to_f32(0x7E00).is_nan());
    }

    #[test]
    fn malformed_ktx2_is_refused() {
        assert!(matches!(Ktx2Image::parse(b"not a texture"), Err(Ktx2Error::Malformed(_))));
    }

    /// A KTX 2.0 file by its header fields (KTX 2.0 §3: vkFormat, typeSize, pixel width, height,
    /// depth, layerCount, faceCount, levelCount, supercompressionScheme; then one level's offset
    /// and length) and its level bytes, placed at byte 104.
    fn ktx2(format: u32, [w, h, d]: [u32; 3], layers: u32, levels: u32, level: (u64, u64), data: &[u8]) -> Vec<u8> {
        let mut b = vec![0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A];
        for v in [format, 4, w, h, d, layers, 1, levels, 0] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b.resize(80, 0);
        for v in [level.0, level.1, level.1] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b.extend_from_slice(data);
        b
    }

    #[test]
    fn a_3d_rg_image_reads_slice_major() {
        // 2×2×3 RG32F, texel (x, y, z) = (x + 10y + 100z, −that), stored slice by slice, each
        // row by row (KTX 2.0 §4: z, then y, then x, the fastest).
        let mut data = Vec::new();
        for z in 0..3 {
            for y in 0..2 {
                for x in 0..2 {
                    let v = (x + 10 * y + 100 * z) as f32;
                    data.extend_from_slice(&v.to_le_bytes());
                    data.extend_from_slice(&(-v).to_le_bytes());
                }
            }
        }
        let bytes = ktx2(103, [2, 2, 3], 0, 1, (104, data.len() as u64), &data);
        let img = Ktx2Image::parse(&bytes).expect("well-formed");
        assert_eq!((img.width, img.height, img.depth, img.format), (2, 2, 3, LutFormat::Rg32Float));
        for (x, y, z) in [(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 2), (0, 1, 1)] {
            let v = (x + 10 * y + 100 * z) as f32;
            assert_eq!(img.texel_3d(x, y, z), [v, -v, 0.0, 1.0], "({x}, {y}, {z})");
        }
        assert_eq!(img.texel(1, 1), img.texel_3d(1, 1, 0));
    }

    #[test]
    fn inconsistent_or_unsupported_ktx2_headers_are_refused_without_panicking() {
        let data = [0u8; 16];
        let rg16 = |size: [u32; 3], layers: u32, levels: u32, level: (u64, u64)| Ktx2Image::parse(&ktx2(83, size, layers, levels, level, &data)).map(|i| i.depth);
        // 2×2 RG16F is 16 bytes: well-formed; as 2×2×2 it would need 32.
        assert_eq!(rg16([2, 2, 0], 0, 1, (104, 16)), Ok(0));
        assert!(matches!(rg16([2, 2, 2], 0, 1, (104, 16)), Err(Ktx2Error::Malformed(_))));
        // A size whose byte count overflows, and a level beyond the end or at an offset that
        // overflows: refused, not a panic.
        assert!(matches!(rg16([u32::MAX, u32::MAX, u32::MAX], 0, 1, (104, 16)), Err(Ktx2Error::Malformed(_))));
        assert!(matches!(rg16([2, 2, 0], 0, 1, (112, 16)), Err(Ktx2Error::Malformed(_))));
        assert!(matches!(rg16([2, 2, 0], 0, 1, (u64::MAX, 16)), Err(Ktx2Error::Malformed(_))));
        // Arrays, mip chains and empty images are not what the generator writes.
        assert!(matches!(rg16([2, 2, 0], 2, 1, (104, 16)), Err(Ktx2Error::Unsupported(_))));
        assert!(matches!(rg16([2, 2, 0], 0, 2, (104, 16)), Err(Ktx2Error::Unsupported(_))));
        assert!(matches!(rg16([0, 2, 0], 0, 1, (104, 0)), Err(Ktx2Error::Unsupported(_))));
        // A format it does not read (R8G8_UNORM, 16) is named.
        assert_eq!(Ktx2Image::parse(&ktx2(16, [2, 2, 0], 0, 1, (104, 16), &data)), Err(Ktx2Error::Format(16)));
    }
}
