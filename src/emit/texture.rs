//! Texture files: KTX2 containers of linear RGBA float texels (written here, byte for byte)
//! and sRGB-encoded PNG previews. Both are pure functions of their inputs (no clocks, no
//! randomness, fixed compression settings), so a build is byte-identical on every run.
//!
//! # KTX2 (Khronos KTX 2.0 specification, with the Khronos Data Format 1.3 descriptor)
//! One 2-D image (or one 3-D image: [`ktx2_volume`]), one mip level, one layer, one face, no supercompression:
//!
//! | bytes      | contents |
//! |------------|----------|
//! | 0..12      | identifier «KTX 20»\r\n\x1A\n |
//! | 12..48     | vkFormat, typeSize, width, height, depth (0 for 2-D), layers 0, faces 1, levels 1, supercompression 0 |
//! | 48..80     | index: DFD offset/length, key/value offset/length, no supercompression global data |
//! | 80..104    | level 0: byte offset, byte length, uncompressed byte length |
//! | 104..196   | DFD: total size, basic block (RGBSDA model, BT.709 primaries, *linear* transfer, straight alpha), 4 samples (R, G, B, A: float, signed) |
//! | 196..      | key/value data (sorted by key): `KTXorientation` = `rd` (`rdi` for 3-D), `KTXwriter`, `shadefit` (the generated-file header lines) |
//! | aligned    | level 0 texels, row by row from the top (row 0 first), slice after slice for 3-D, little-endian |
//!
//! The level data starts at a multiple of the texel size (8 bytes for RGBA16F, 16 for RGBA32F,
//! both multiples of 4 as the specification requires). Two-channel textures (RG16F, RG32F:
//! [`ktx2_texels`]) have two DFD samples (R, G), one-channel textures (R16F, R32F: the tables of
//! `kind = "table"` specs) one, and both start at a multiple of lcm(texel size, 4). Texel values are written as given:
//! no tonemapping, no gamma (the DFD says so with `KHR_DF_TRANSFER_LINEAR`).

use super::formats::Texture;
use serde::{Deserialize, Serialize};

/// Texel format of a KTX2 texture (WebGPU names).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum TextureFormat {
    /// RGBA, 16-bit IEEE half floats (`VK_FORMAT_R16G16B16A16_SFLOAT`): filterable in core
    /// WebGPU, 11 significant bits (relative rounding ≤ 2⁻¹¹ ≈ 4.9e-4).
    #[default]
    Rgba16float,
    /// RGBA, 32-bit floats (`VK_FORMAT_R32G32B32A32_SFLOAT`): the f32 values exactly; linear
    /// filtering needs WebGPU's optional `float32-filterable` feature.
    Rgba32float,
}

impl TextureFormat {
    /// `VkFormat` enumerant.
    pub fn vk_format(self) -> u32 {
        match self {
            TextureFormat::Rgba16float => 97,
            TextureFormat::Rgba32float => 109,
        }
    }

    /// Bytes per channel.
    pub fn type_size(self) -> u32 {
        match self {
            TextureFormat::Rgba16float => 2,
            TextureFormat::Rgba32float => 4,
        }
    }

    /// The WebGPU name (`rgba16float`, `rgba32float`).
    pub fn name(self) -> &'static str {
        match self {
            TextureFormat::Rgba16float => "rgba16float",
            TextureFormat::Rgba32float => "rgba32float",
        }
    }

    /// The value a texel channel holds for `v` (f32 → f16 rounds to nearest, ties to even).
    pub fn stored(self, v: f32) -> f32 {
        match self {
            TextureFormat::Rgba16float => half::f16::from_f32(v).to_f32(),
            TextureFormat::Rgba32float => v,
        }
    }

    fn push(self, out: &mut Vec<u8>, v: f32) {
        match self {
            TextureFormat::Rgba16float => out.extend_from_slice(&half::f16::from_f32(v).to_le_bytes()),
            TextureFormat::Rgba32float => out.extend_from_slice(&v.to_le_bytes()),
        }
    }
}

pub(crate) const KTX2_IDENTIFIER: [u8; 12] = [0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A];

fn put_u32(out: &mut Vec<u8>, v: u32) {
    out.extend_from_slice(&v.to_le_bytes());
}

/// The alignment of every level's data: lcm(texel block size, 4) (KTX 2.0 §3.9.7, the
/// level index, without supercompression).
pub(crate) fn level_alignment(texel_size: usize) -> usize {
    let (mut a, mut b) = (texel_size, 4);
    while b != 0 {
        (a, b) = (b, a % b);
    }
    texel_size / a * 4
}

/// Channel ids of an R (1), RG (2) or RGBA (4) texel: R = 0, G = 1, B = 2, A = 15.
fn channel_ids(channels: usize) -> &'static [u32] {
    match channels {
        1 => &[0],
        2 => &[0, 1],
        4 => &[0, 1, 2, 15],
        _ => panic!("KTX2 texels have 1 (R), 2 (RG) or 4 (RGBA) channels, not {channels}"),
    }
}

/// `VkFormat` of `channels` channels in the precision of `format` (Vulkan's `VkFormat`
/// enumerants): R16_SFLOAT (76), R16G16_SFLOAT (83), R16G16B16A16_SFLOAT (97), R32_SFLOAT (100),
/// R32G32_SFLOAT (103), R32G32B32A32_SFLOAT (109).
pub fn vk_format(format: TextureFormat, channels: usize) -> u32 {
    match (format, channels) {
        (TextureFormat::Rgba16float, 1) => 76,
        (TextureFormat::Rgba32float, 1) => 100,
        (TextureFormat::Rgba16float, 2) => 83,
        (TextureFormat::Rgba32float, 2) => 103,
        (f, 4) => f.vk_format(),
        _ => panic!("KTX2 texels have 1 (R), 2 (RG) or 4 (RGBA) channels, not {channels}"),
    }
}

/// A data format descriptor: total size, then one basic descriptor block (KDF 1.3 §5) of
/// `channels` samples of `bits` each; `sample(offset, channel id)` gives a sample's four words.
fn basic_dfd(channels: usize, bits: u32, sample: impl Fn(u32, u32) -> [u32; 4]) -> Vec<u8> {
    let ids = channel_ids(channels);
    let samples = ids.len() as u32;
    let block_size = 24 + 16 * samples;
    let mut d = Vec::with_capacity(4 + block_size as usize);
    put_u32(&mut d, 4 + block_size); // dfdTotalSize
    put_u32(&mut d, 0); // vendorId KHR (0), descriptorType BASICFORMAT (0)
    put_u32(&mut d, 2 | (block_size << 16)); // versionNumber KHR_DF_VERSIONNUMBER_1_3 = 2
    // colorModel RGBSDA (1), primaries BT709 (1), transfer LINEAR (1), flags ALPHA_STRAIGHT (0).
    d.extend_from_slice(&[1, 1, 1, 0]);
    d.extend_from_slice(&[0, 0, 0, 0]); // texelBlockDimension 1×1×1×1 (stored minus one)
    d.extend_from_slice(&[(samples * bits / 8) as u8, 0, 0, 0, 0, 0, 0, 0]); // bytesPlane0..7
    for (k, &channel) in ids.iter().enumerate() {
        for word in sample(k as u32 * bits, channel) {
            put_u32(&mut d, word);
        }
    }
    d
}

/// The data format descriptor of a float texture. Channel ids R = 0, G = 1, B = 2, A = 15, with
/// the FLOAT (0x80) and SIGNED (0x40) qualifiers; sampleLower/Upper are −1.0 and 1.0 as f32 bit
/// patterns (the convention for float samples of any width).
fn data_format_descriptor(format: TextureFormat, channels: usize) -> Vec<u8> {
    let bits = 8 * format.type_size();
    basic_dfd(channels, bits, |offset, channel| {
        // bitOffset, bitLength − 1, channel and qualifiers; samplePosition0..3; lower; upper.
        [offset | ((bits - 1) << 16) | ((channel | 0xC0) << 24), 0, 0xBF80_0000, 0x3F80_0000]
    })
}

/// Key/value entries sorted by key (each value with its NUL): `KTXorientation`, `KTXwriter` =
/// the generator, then `metadata`.
fn key_values(orientation: &str, metadata: &[(&str, &str)]) -> Vec<(String, Vec<u8>)> {
    let mut kv: Vec<(String, Vec<u8>)> = [("KTXorientation", orientation), ("KTXwriter", super::GENERATOR)]
        .iter()
        .chain(metadata)
        .map(|(k, v)| (k.to_string(), format!("{v}\0").into_bytes()))
        .collect();
    kv.sort_by(|a, b| a.0.as_bytes().cmp(b.0.as_bytes()));
    kv
}

/// A KTX2 file holding one `width`×`height` RGBA image, texels row by row from the top
/// (`texels[y * width + x]`), in `format`. `metadata` are extra key/value entries (after
/// `KTXorientation` = `rd` and `KTXwriter` = the generator).
pub fn ktx2_rgba(
    width: u32,
    height: u32,
    texels: &[[f32; 4]],
    format: TextureFormat,
    metadata: &[(&str, &str)],
) -> Vec<u8> {
    assert_eq!(texels.len(), (width * height) as usize, "texel count differs from width × height");
    let flat: Vec<f32> = texels.iter().flatten().copied().collect();
    ktx2_texels(width, height, 4, &flat, format, metadata)
}

/// A KTX2 file of one `width`×`height` image of `channels` (1: R, 2: RG, 4: RGBA) float channels
/// per texel, `values[(y * width + x) * channels + c]`, in the precision of `format` (the
/// layout of [`ktx2_rgba`], which is this with 4 channels).
pub fn ktx2_texels(
    width: u32,
    height: u32,
    channels: usize,
    values: &[f32],
    format: TextureFormat,
    metadata: &[(&str, &str)],
) -> Vec<u8> {
    ktx2_volume(width, height, 0, channels, values, format, metadata)
}

/// A KTX2 file of one `width`×`height`×`depth` 3-D image (pixelDepth = `depth`; 0 is a 2-D
/// image, as [`ktx2_texels`]), `values[((z * height + y) * width + x) * channels + c]`: the
/// slices one after the other (z = 0 first), each row by row from the top, as the KTX 2.0
/// specification orders a level's image. `KTXorientation` is `rd` for 2-D and `rdi` for 3-D
/// (x right, y down, z into the screen with the slice index).
pub fn ktx2_volume(
    width: u32,
    height: u32,
    depth: u32,
    channels: usize,
    values: &[f32],
    format: TextureFormat,
    metadata: &[(&str, &str)],
) -> Vec<u8> {
    assert_eq!(values.len(), (width * height * depth.max(1)) as usize * channels, "value count differs from width × height × depth × channels");
    let orientation = if depth == 0 { "rd" } else { "rdi" };
    let mut level = Vec::with_capacity(values.len() * format.type_size() as usize);
    for &c in values {
        format.push(&mut level, c);
    }
    Texture {
        vk_format: vk_format(format, channels),
        type_size: format.type_size(),
        width,
        height,
        depth,
        dfd: data_format_descriptor(format, channels),
        kv: key_values(orientation, metadata),
        levels: vec![level],
    }
    .ktx2(None)
}

/// `VkFormat` of a UNORM texture of `channels` (2: RG, 4: RGBA) and `bits` (8, 16) per channel:
/// R8G8_UNORM (16), R8G8B8A8_UNORM (37), R16G16_UNORM (77), R16G16B16A16_UNORM (91).
pub fn vk_format_unorm(channels: usize, bits: u32) -> u32 {
    match (channels, bits) {
        (2, 8) => 16,
        (4, 8) => 37,
        (2, 16) => 77,
        (4, 16) => 91,
        _ => panic!("UNORM KTX2 textures have 2 or 4 channels of 8 or 16 bits, not {channels} × {bits}"),
    }
}

/// The data format descriptor of a UNORM texture: samples without qualifiers, sampleLower 0 and
/// sampleUpper 2^bits − 1 (KDF 1.3 §5, integer samples).
fn data_format_descriptor_unorm(channels: usize, bits: u32) -> Vec<u8> {
    basic_dfd(channels, bits, |offset, channel| [offset | ((bits - 1) << 16) | (channel << 24), 0, 0, ((1u64 << bits) - 1) as u32])
}

/// One mip level of [`ktx2_unorm_mips`]: its size and `width × height × channels` values in
/// [0, 1] (row by row from the top), rounded to the nearest UNORM code.
pub struct UnormLevel {
    pub width: u32,
    pub height: u32,
    pub values: Vec<f64>,
}

/// A KTX2 file of a mip chain (level 0 first in `levels`, each half the previous, at least 1)
/// of `channels` (2, 4) UNORM channels of `bits` (8, 16). The level data are stored smallest
/// first, each at a multiple of lcm(texel size, 4) (KTX2 §3.9, mip padding).
pub fn ktx2_unorm_mips(levels: &[UnormLevel], channels: usize, bits: u32, metadata: &[(&str, &str)]) -> Vec<u8> {
    assert!(!levels.is_empty(), "a mip chain has at least one level");
    let type_size = bits / 8;
    let q = ((1u64 << bits) - 1) as f64;
    let data: Vec<Vec<u8>> = levels
        .iter()
        .map(|l| {
            assert_eq!(l.values.len(), (l.width * l.height) as usize * channels, "value count differs from width × height × channels");
            let mut out = Vec::with_capacity(l.values.len() * type_size as usize);
            for &v in &l.values {
                let code = (v.clamp(0.0, 1.0) * q).round() as u32;
                if bits == 8 { out.push(code as u8) } else { out.extend_from_slice(&(code as u16).to_le_bytes()) }
            }
            out
        })
        .collect();
    Texture {
        vk_format: vk_format_unorm(channels, bits),
        type_size,
        width: levels[0].width,
        height: levels[0].height,
        depth: 0,
        dfd: data_format_descriptor_unorm(channels, bits),
        kv: key_values("rd", metadata),
        levels: data,
    }
    .ktx2(None)
}

/// The sRGB transfer function (IEC 61966-2-1) of a linear value clamped to [0, 1], as 8 bits.
pub fn srgb8(linear: f64) -> u8 {
    let v = linear.clamp(0.0, 1.0);
    let e = if v <= 0.003_130_8 { 12.92 * v } else { 1.055 * v.powf(1.0 / 2.4) - 0.055 };
    (e * 255.0).round() as u8
}

/// An 8-bit sRGB PNG preview of linear RGB data (`rgb[y * width + x]`, clamped to [0, 1], no
/// tonemapping), each texel drawn as a `scale_x`×`scale_y` block, with an sRGB chunk and
/// `text` as tEXt chunks (Latin-1 keywords and text).
pub fn png_srgb_preview(
    width: usize,
    height: usize,
    rgb: &[[f64; 3]],
    scale_x: usize,
    scale_y: usize,
    text: &[(&str, String)],
) -> Vec<u8> {
    assert_eq!(rgb.len(), width * height, "texel count differs from width × height");
    let (w, h) = (width * scale_x, height * scale_y);
    let mut pixels = Vec::with_capacity(w * h * 3);
    for y in 0..h {
        for x in 0..w {
            let t = rgb[(y / scale_y) * width + x / scale_x];
            pixels.extend(t.iter().map(|&c| srgb8(c)));
        }
    }
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, w as u32, h as u32);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
        enc.set_compression(png::Compression::Balanced);
        for (k, v) in text {
            enc.add_text_chunk(k.to_string(), v.clone()).expect("Latin-1 keyword and text");
        }
        let mut wr = enc.write_header().expect("PNG header into memory");
        wr.write_image_data(&pixels).expect("PNG data into memory");
        wr.finish().expect("PNG end into memory");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn texels(w: u32, h: u32) -> Vec<[f32; 4]> {
        (0..w * h).map(|k| [k as f32 / 7.0, 0.25, -(k as f32), 1.0]).collect()
    }

    /// One channel value decoded from its little-endian bytes in `format`.
    fn channel(format: TextureFormat, b: &[u8]) -> f32 {
        match format {
            TextureFormat::Rgba16float => half::f16::from_le_bytes([b[0], b[1]]).to_f32(),
            TextureFormat::Rgba32float => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        }
    }

    /// The DFD's own size fields, read from the file as KDF 1.3 lays them out (the ktx2 crate
    /// reads the samples without checking them): dfdTotalSize, the header's dfdByteLength and
    /// the basic block's descriptorBlockSize (the high half of its second word) all follow
    /// from a 24-byte block header and 16 bytes a sample.
    fn dfd_sizes_follow_the_spec(bytes: &[u8], samples: u32) {
        let hd = ktx2::Reader::new(bytes).unwrap().header();
        let (at, len) = (hd.index.dfd_byte_offset as usize, hd.index.dfd_byte_length);
        let word = |k: usize| u32::from_le_bytes(bytes[at + 4 * k..at + 4 * k + 4].try_into().unwrap());
        assert_eq!((len, word(0)), (4 + 24 + 16 * samples, 4 + 24 + 16 * samples), "{samples} samples");
        assert_eq!(word(2) >> 16, 24 + 16 * samples, "{samples} samples");
    }

    /// The formats' names are the WebGPU specification's `GPUTextureFormat` values, which the
    /// spec files also take (serde's lowercase names).
    #[test]
    fn texture_formats_are_named_as_webgpu_names_them() {
        for (format, webgpu) in [(TextureFormat::Rgba16float, "rgba16float"), (TextureFormat::Rgba32float, "rgba32float")] {
            assert_eq!(format.name(), webgpu);
            assert_eq!(serde_json::to_string(&format).unwrap(), format!("\"{webgpu}\""));
        }
    }

    #[test]
    fn ktx2_reads_back_with_the_ktx2_crate() {
        // The VkFormat of each, as the ktx2 crate names Vulkan's enumerants (97 and 109), and
        // its bytes a channel (a half, a float).
        for (format, vk, size) in [(TextureFormat::Rgba16float, ktx2::Format::R16G16B16A16_SFLOAT, 2), (TextureFormat::Rgba32float, ktx2::Format::R32G32B32A32_SFLOAT, 4)] {
            let texel = 4 * size;
            let (w, h) = (5, 3);
            let t = texels(w, h);
            let bytes = ktx2_rgba(w, h, &t, format, &[("shadefit", "spec: fits/x.toml")]);
            let r = ktx2::Reader::new(&bytes[..]).expect("a valid KTX2 file");
            let hd = r.header();
            assert_eq!(hd.format, Some(vk));
            assert_eq!((hd.pixel_width, hd.pixel_height, hd.pixel_depth), (w, h, 0));
            assert_eq!((hd.layer_count, hd.face_count, hd.level_count), (0, 1, 1));
            assert_eq!(hd.type_size, size);
            assert!(hd.supercompression_scheme.is_none());
            assert_eq!(r.transfer_function(), Some(ktx2::TransferFunction::Linear));
            assert_eq!(r.color_model(), Some(ktx2::ColorModel::RGBSDA));
            assert_eq!(r.color_primaries(), Some(ktx2::ColorPrimaries::BT709));
            assert_eq!(r.is_alpha_premultiplied(), Some(false));
            // KTX2 string values are NUL-terminated.
            assert_eq!(r.writer(), Some(format!("{}\0", crate::emit::GENERATOR).as_str()));
            let basic = r.basic_dfd().expect("a basic DFD block");
            assert_eq!(basic.bytes_planes[0] as u32, texel);
            dfd_sizes_follow_the_spec(&bytes, 4);
            let samples = &basic.sample_information;
            assert_eq!(samples.len(), 4);
            for (k, s) in samples.iter().enumerate() {
                assert_eq!(s.bit_offset as u32, k as u32 * 8 * size);
                assert_eq!(s.bit_length.get() as u32, 8 * size);
                assert_eq!(s.channel_type, [0, 1, 2, 15][k]);
                assert!(s.channel_type_qualifiers.contains(ktx2::dfd::ChannelTypeQualifiers::FLOAT));
                assert!(s.channel_type_qualifiers.contains(ktx2::dfd::ChannelTypeQualifiers::SIGNED));
                assert_eq!((s.lower, s.upper), (0xBF80_0000, 0x3F80_0000));
            }
            let kv: Vec<(&str, &[u8])> = r.key_value_data().collect();
            let keys: Vec<&str> = kv.iter().map(|e| e.0).collect();
            assert_eq!(keys, ["KTXorientation", "KTXwriter", "shadefit"]);
            assert_eq!(kv[0].1, b"rd\0");
            assert_eq!(kv[2].1, b"spec: fits/x.toml\0");
            let levels: Vec<_> = r.levels().collect();
            assert_eq!(levels.len(), 1);
            let data = levels[0].data;
            assert_eq!(data.len(), t.len() * texel as usize);
            // The level starts at a multiple of the texel size.
            let at = data.as_ptr() as usize - bytes.as_ptr() as usize;
            assert_eq!(at % texel as usize, 0);
            let ts = size as usize;
            for (k, texel) in t.iter().enumerate() {
                for c in 0..4 {
                    let b = &data[(4 * k + c) * ts..(4 * k + c + 1) * ts];
                    let v = channel(format, b);
                    assert_eq!(v.to_bits(), format.stored(texel[c]).to_bits());
                }
            }
        }
    }

    #[test]
    fn r_and_rg_textures_read_back_with_the_ktx2_crate() {
        // VkFormat enumerants from the Vulkan specification: R16_SFLOAT 76, R16G16_SFLOAT 83,
        // R32_SFLOAT 100, R32G32_SFLOAT 103.
        for (format, channels, vk) in [
            (TextureFormat::Rgba16float, 1, 76),
            (TextureFormat::Rgba32float, 1, 100),
            (TextureFormat::Rgba16float, 2, 83),
            (TextureFormat::Rgba32float, 2, 103),
        ] {
            let (w, h) = (3, 5);
            let v: Vec<f32> = (0..channels as u32 * w * h).map(|k| k as f32 / 3.0 - 2.0).collect();
            let bytes = ktx2_texels(w, h, channels, &v, format, &[]);
            let r = ktx2::Reader::new(&bytes[..]).expect("a valid KTX2 file");
            assert_eq!(r.header().format.map(|f| f.value()), Some(vk));
            assert_eq!((r.header().pixel_width, r.header().pixel_height), (w, h));
            let basic = r.basic_dfd().expect("a basic DFD block");
            assert_eq!(basic.bytes_planes[0] as u32, channels as u32 * format.type_size());
            dfd_sizes_follow_the_spec(&bytes, channels as u32);
            let ids: Vec<u8> = basic.sample_information.iter().map(|s| s.channel_type).collect();
            assert_eq!(ids, [0u8, 1][..channels]);
            let level = r.levels().next().unwrap();
            assert_eq!((level.data.as_ptr() as usize - bytes.as_ptr() as usize) % 4, 0);
            let ts = format.type_size() as usize;
            for (k, &x) in v.iter().enumerate() {
                let b = &level.data[k * ts..(k + 1) * ts];
                let got = channel(format, b);
                assert_eq!(got.to_bits(), format.stored(x).to_bits());
            }
        }
    }

    /// A 3-D image reads back as one: its depth in the header, `KTXorientation` `rdi`, and the
    /// level holding the slices one after the other, z = 0 first, each row by row: the value at
    /// (x, y, z, c) is at ((z·h + y)·w + x)·channels + c. Values are chosen exact in f16 (k/8,
    /// |k| < 2048) so each one read back is the value written.
    #[test]
    fn a_volume_reads_back_slice_by_slice() {
        let (w, h, d, channels) = (3u32, 2u32, 4u32, 2usize);
        let value = |x: u32, y: u32, z: u32, c: usize| (x + 10 * y + 100 * z) as f32 / 8.0 - c as f32;
        let mut v = Vec::new();
        for z in 0..d {
            for y in 0..h {
                for x in 0..w {
                    for c in 0..channels {
                        v.push(value(x, y, z, c));
                    }
                }
            }
        }
        for format in [TextureFormat::Rgba16float, TextureFormat::Rgba32float] {
            let bytes = ktx2_volume(w, h, d, channels, &v, format, &[]);
            let r = ktx2::Reader::new(&bytes[..]).expect("a valid KTX2 file");
            let hd = r.header();
            assert_eq!((hd.pixel_width, hd.pixel_height, hd.pixel_depth, hd.level_count), (w, h, d, 1));
            let kv: Vec<(&str, &[u8])> = r.key_value_data().collect();
            assert_eq!(kv[0], ("KTXorientation", &b"rdi\0"[..]));
            let level = r.levels().next().unwrap();
            let ts = format.type_size() as usize;
            assert_eq!(level.data.len(), (w * h * d) as usize * channels * ts);
            for z in 0..d {
                for y in 0..h {
                    for x in 0..w {
                        for c in 0..channels {
                            let k = (((z * h + y) * w + x) as usize) * channels + c;
                            let b = &level.data[k * ts..(k + 1) * ts];
                            let got = channel(format, b);
                            assert_eq!(got, value(x, y, z, c), "{format:?} at ({x}, {y}, {z}, {c})");
                        }
                    }
                }
            }
        }
    }

    /// Key/value entries are sorted by key bytes whatever their order given (KTX 2.0 §3.11:
    /// uppercase sorts before lowercase), and each value is NUL-terminated.
    #[test]
    fn key_value_entries_are_sorted_by_key() {
        let bytes = ktx2_texels(1, 1, 1, &[0.5], TextureFormat::Rgba32float, &[("zeta", "1"), ("Beta", "2"), ("alpha", "3")]);
        let r = ktx2::Reader::new(&bytes[..]).expect("a valid KTX2 file");
        let kv: Vec<(&str, &[u8])> = r.key_value_data().collect();
        assert_eq!(kv, [("Beta", &b"2\0"[..]), ("KTXorientation", b"rd\0"), ("KTXwriter", format!("{}\0", crate::emit::GENERATOR).as_bytes()), ("alpha", b"3\0"), ("zeta", b"1\0")]);
    }

    #[test]
    fn srgb_encoding_matches_the_standard() {
        // IEC 61966-2-1 reference points: 0 → 0, 1 → 255, 0.5 → 0.7354 → 188, 0.0031308 (the
        // break) → 0.04045 → 10, 0.18 → 0.4614 → 118.
        assert_eq!(srgb8(0.0), 0);
        assert_eq!(srgb8(1.0), 255);
        assert_eq!(srgb8(0.5), 188);
        assert_eq!(srgb8(0.003_130_8), 10);
        assert_eq!(srgb8(0.18), 118);
        assert_eq!(srgb8(-1.0), 0);
        assert_eq!(srgb8(f64::NAN.max(2.0)), 255);
    }

    #[test]
    fn png_preview_decodes_to_the_encoded_values() {
        let rgb: Vec<[f64; 3]> = (0..6).map(|k| [k as f64 / 5.0, 0.5, 1.0 - k as f64 / 5.0]).collect();
        let bytes = png_srgb_preview(3, 2, &rgb, 2, 3, &[("Comment", "spec: x".into())]);
        assert_eq!(bytes, png_srgb_preview(3, 2, &rgb, 2, 3, &[("Comment", "spec: x".into())]));
        let dec = png::Decoder::new(std::io::Cursor::new(&bytes[..]));
        let mut reader = dec.read_info().unwrap();
        let info = reader.info();
        assert_eq!((info.width, info.height), (6, 6));
        assert!(info.srgb.is_some());
        assert_eq!(info.uncompressed_latin1_text[0].text, "spec: x");
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        reader.next_frame(&mut buf).unwrap();
        for y in 0..6 {
            for x in 0..6 {
                let t = rgb[(y / 3) * 3 + x / 2];
                let p = &buf[(y * 6 + x) * 3..][..3];
                assert_eq!(p, [srgb8(t[0]), srgb8(t[1]), srgb8(t[2])]);
            }
        }
    }

    #[test]
    fn unorm_mip_chains_read_back_with_the_ktx2_crate() {
        // 5×3 → 2×1 → 1×1; RG8, RGBA8, RG16 and RGBA16: the ktx2 crate's reader
        // (independent) finds the format, the three levels in order and the codes
        // (round(v · (2^bits − 1))). VkFormat enumerants from the Vulkan specification:
        // R8G8_UNORM 16, R8G8B8A8_UNORM 37, R16G16_UNORM 77, R16G16B16A16_UNORM 91; typeSize
        // (KTX 2.0 §3.3) the bytes of one channel, 1 for the 8-bit formats and 2 for the 16-bit.
        for (channels, bits, vk, type_size) in [(2usize, 8u32, 16u32, 1u32), (4, 8, 37, 1), (2, 16, 77, 2), (4, 16, 91, 2)] {
            let sizes = [(5u32, 3u32), (2, 1), (1, 1)];
            let levels: Vec<UnormLevel> = sizes
                .iter()
                .enumerate()
                .map(|(k, &(w, h))| UnormLevel { width: w, height: h, values: (0..(w * h) as usize * channels).map(|i| ((i + k) % 7) as f64 / 6.0).collect() })
                .collect();
            let bytes = ktx2_unorm_mips(&levels, channels, bits, &[]);
            let r = ktx2::Reader::new(&bytes[..]).expect("a valid KTX2 file");
            let hd = r.header();
            assert_eq!(hd.format.map(|f| f.value()), Some(vk));
            assert_eq!(hd.type_size, type_size);
            assert_eq!((hd.pixel_width, hd.pixel_height, hd.level_count), (5, 3, 3));
            // The DFD's integer samples (KDF 1.3 §5): no qualifiers, lower 0, upper 2^bits − 1.
            let basic = r.basic_dfd().expect("a basic DFD block");
            assert_eq!(basic.bytes_planes[0] as usize, channels * bits as usize / 8);
            let samples = &basic.sample_information;
            assert_eq!(samples.iter().map(|s| s.channel_type).collect::<Vec<_>>(), if channels == 2 { vec![0u8, 1] } else { vec![0, 1, 2, 15] });
            for (k, smp) in samples.iter().enumerate() {
                assert_eq!((smp.bit_offset as u32, smp.bit_length.get() as u32), (k as u32 * bits, bits));
                assert!(smp.channel_type_qualifiers.is_empty());
                assert_eq!((smp.lower, smp.upper), (0, (1u32 << bits) - 1));
            }
            let q = ((1u64 << bits) - 1) as f64;
            for (k, level) in r.levels().enumerate() {
                let want: Vec<u32> = levels[k].values.iter().map(|v| (v * q).round() as u32).collect();
                let got: Vec<u32> = if bits == 8 {
                    level.data.iter().map(|&b| b as u32).collect()
                } else {
                    level.data.chunks(2).map(|c| u16::from_le_bytes([c[0], c[1]]) as u32).collect()
                };
                assert_eq!(got, want, "level {k}");
            }
        }
    }

    /// KTX 2.0 §3.9.7 (Level Index): without supercompression every level's byteOffset is a
    /// multiple of lcm(texel block size, 4), e.g. 8 for R16G16B16A16 (libktx's
    /// `ktxTexture2_calcRequiredLevelAlignment` checks the same). Key/value data of every length
    /// mod 8 puts the end of the header on both sides of an 8-byte boundary, so an alignment of
    /// 4 is caught wherever it lands.
    #[test]
    fn level_offsets_are_multiples_of_the_lcm_of_the_texel_size_and_4() {
        let sizes = [(3u32, 3u32), (1, 2), (1, 1)];
        for (channels, bits) in [(2usize, 8u32), (4, 8), (2, 16), (4, 16)] {
            let levels: Vec<UnormLevel> =
                sizes.iter().map(|&(w, h)| UnormLevel { width: w, height: h, values: vec![0.5; (w * h) as usize * channels] }).collect();
            let block = channels * bits as usize / 8;
            for pad in 0..8 {
                let text = "x".repeat(pad);
                let bytes = ktx2_unorm_mips(&levels, channels, bits, &[("pad", &text)]);
                for k in 0..sizes.len() {
                    // The level index follows the header (KTX 2.0 §3.9.7).
                    let at = ktx2::Header::LENGTH + ktx2::LevelIndex::LENGTH * k;
                    let entry = ktx2::LevelIndex::from_bytes(bytes[at..at + ktx2::LevelIndex::LENGTH].try_into().unwrap());
                    let offset = entry.byte_offset as usize;
                    assert!(offset.is_multiple_of(lcm4(block)), "{channels} × {bits} bits, pad {pad}, level {k}: offset {offset}");
                }
            }
        }
    }

    /// lcm(b, 4) by search: the least positive multiple of both.
    fn lcm4(b: usize) -> usize {
        (1..).map(|m| m * b).find(|m| m.is_multiple_of(4)).unwrap()
    }

    #[test]
    fn level_alignment_is_the_least_common_multiple_of_the_texel_size_and_4() {
        // Every texel size up to 48 bytes: odd (3, 5: lcm 4b), 2 mod 4 (6: 12, which max(b, 4)
        // would get wrong), multiples of 4 (b itself).
        for b in 1..=48 {
            assert_eq!(level_alignment(b), lcm4(b), "texel size {b}");
        }
    }

    /// The float writer's level, as the UNORM mips' above: at a multiple of lcm(texel size, 4)
    /// for each channel count and precision, whatever the key/value data's length mod 16.
    #[test]
    fn a_float_level_lies_at_a_multiple_of_the_lcm_of_the_texel_size_and_4() {
        for format in [TextureFormat::Rgba16float, TextureFormat::Rgba32float] {
            for channels in [1usize, 2, 4] {
                let values = vec![0.25f32; 3 * 2 * channels];
                let block = channels * format.type_size() as usize;
                for pad in 0..16 {
                    let text = "x".repeat(pad);
                    let bytes = ktx2_texels(3, 2, channels, &values, format, &[("pad", &text)]);
                    let (h, l) = (ktx2::Header::LENGTH, ktx2::LevelIndex::LENGTH);
                    let header = ktx2::Header::from_bytes(bytes[..h].try_into().unwrap()).unwrap();
                    let offset = ktx2::LevelIndex::from_bytes(bytes[h..h + l].try_into().unwrap()).byte_offset as usize;
                    assert!(offset.is_multiple_of(lcm4(block)), "{} × {channels}, pad {pad}: offset {offset}", format.name());
                    // No more padding than the alignment needs: the level follows the key/value data.
                    let kvd_end = (header.index.kvd_byte_offset + header.index.kvd_byte_length) as usize;
                    assert!(offset >= kvd_end && offset - kvd_end < lcm4(block), "{} × {channels}, pad {pad}: {kvd_end} → {offset}", format.name());
                }
            }
        }
    }
}
