//! A table texture in the file formats engines import, all from the one KTX2 image a family
//! writes ([`super::texture`]): the same texel bytes, re-wrapped.
//!
//! | format      | file            | for | layout |
//! |-------------|-----------------|-----|--------|
//! | `ktx2`      | `NAME.ktx2`     | wgpu, bevy, three.js (KTX2Loader), Vulkan | as written, no supercompression; always written |
//! | `ktx2-zstd` | `NAME.zstd.ktx2` | bevy (its `dfg.ktx2` is stored so), three.js | the same with every level Zstandard-compressed (scheme 2, level [`ZSTD_LEVEL`]) |
//! | `dds`       | `NAME.dds`      | Unity, Godot, Direct3D, DirectXTex | `DDS ` + DDS_HEADER + DDS_HEADER_DXT10, levels largest first |
//! | `exr`       | `NAME.exr`      | Unreal, Unity, Nuke | one scanline part, channels R (G, B, A) as half or float, uncompressed |
//! | `c`         | `NAME.h`        | C/C++ engines, tools | `NAME_DATA`: level 0's texels as `uint16_t` (16F bit patterns, UNORM16), `uint8_t` or round-trip `float` literals |
//! | `js`        | `NAME.js`       | three.js `DataTexture` | `export const NAME` with `data` a `Uint16Array` (16F bits: `HalfFloatType`), `Float32Array` or `Uint8Array` |
//!
//! Every format keeps the KTX2 texel bits (16F as 16F, 32F as 32F; no conversion), rows from
//! the top (KTX2 `KTXorientation` `rd`, DDS rows, EXR increasing y, all row 0 first). A 3-D
//! texture is a DX10 `TEXTURE3D` in DDS and, in EXR (no volumes), its slices stacked
//! downwards: a `width × (height·depth)` image, slice 0 on top. EXR holds floats only: a UNORM
//! texture has no EXR file (asked for by name, it is a spec error). KTX2 and EXR carry the
//! generated-file header (`shadefit` key, EXR `comments`); DDS has no place for it, and its
//! provenance is the JSON of the same name.
//!
//! Sources: KTX 2.0 specification §3 (header, level index, supercompression scheme 2 =
//! Zstandard, levels unaligned when supercompressed); Microsoft's "DDS file layout" and
//! `DDS_HEADER_DXT10` documentation (flags, caps, `DXGI_FORMAT` values); OpenEXR file layout
//! (written by the `exr` crate).

use std::fmt;

/// Zstandard level of `ktx2-zstd` (`ktx create --zstd 22`, as bevy's `dfg.ktx2` records in
/// `KTXwriterScParams`): the files are small, so the slowest level costs milliseconds.
pub const ZSTD_LEVEL: i32 = 22;

/// A table file format of `[emit] formats`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum TableFormat {
    Ktx2,
    Ktx2Zstd,
    Dds,
    Exr,
    C,
    Js,
}

impl TableFormat {
    pub const ALL: [TableFormat; 6] = [TableFormat::Ktx2, TableFormat::Ktx2Zstd, TableFormat::Dds, TableFormat::Exr, TableFormat::C, TableFormat::Js];

    pub fn name(self) -> &'static str {
        match self {
            TableFormat::Ktx2 => "ktx2",
            TableFormat::Ktx2Zstd => "ktx2-zstd",
            TableFormat::Dds => "dds",
            TableFormat::Exr => "exr",
            TableFormat::C => "c",
            TableFormat::Js => "js",
        }
    }

    pub fn extension(self) -> &'static str {
        match self {
            TableFormat::Ktx2 => "ktx2",
            TableFormat::Ktx2Zstd => "zstd.ktx2",
            TableFormat::Dds => "dds",
            TableFormat::Exr => "exr",
            TableFormat::C => "h",
            TableFormat::Js => "js",
        }
    }
}

impl fmt::Display for TableFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// `[emit] formats` parsed: each name once, in [`TableFormat`] order, `ktx2` whether listed or not
/// (the WGSL accessors, the Rust modules and the runtime crate read the uncompressed
/// `NAME.ktx2`, so it is always written).
pub fn parse_list(names: &[String]) -> Result<Vec<TableFormat>, String> {
    let mut out = vec![TableFormat::Ktx2];
    let mut seen = Vec::new();
    for n in names {
        let f = TableFormat::ALL
            .into_iter()
            .find(|f| f.name() == n)
            .ok_or_else(|| format!("unknown table format '{n}' (known: ktx2, ktx2-zstd, dds, exr, c, js)"))?;
        if seen.contains(&f) {
            return Err(format!("'{n}' is listed twice"));
        }
        seen.push(f);
        if f != TableFormat::Ktx2 {
            out.push(f);
        }
    }
    out.sort();
    Ok(out)
}

/// The formats of a texture when its spec names none: KTX2, DDS, and EXR when the texels are
/// floats of one level.
pub fn default_formats(texture: &Texture) -> Vec<TableFormat> {
    let mut f = vec![TableFormat::Ktx2, TableFormat::Dds];
    if texture.texel().float && texture.levels.len() == 1 {
        f.push(TableFormat::Exr);
    }
    f
}

/// What a texel is: channels, bits per channel, float or UNORM, and its `DXGI_FORMAT`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Texel {
    pub channels: usize,
    pub bits: u32,
    pub float: bool,
    pub dxgi: u32,
}

/// The texel of a `VkFormat` this project writes (Vulkan `VkFormat` and DXGI `DXGI_FORMAT`
/// enumerants).
pub fn texel_of(vk_format: u32) -> Option<Texel> {
    let t = |channels, bits, float, dxgi| Some(Texel { channels, bits, float, dxgi });
    match vk_format {
        76 => t(1, 16, true, 54),   // R16_SFLOAT → R16_FLOAT
        83 => t(2, 16, true, 34),   // R16G16_SFLOAT → R16G16_FLOAT
        97 => t(4, 16, true, 10),   // R16G16B16A16_SFLOAT → R16G16B16A16_FLOAT
        100 => t(1, 32, true, 41),  // R32_SFLOAT → R32_FLOAT
        103 => t(2, 32, true, 16),  // R32G32_SFLOAT → R32G32_FLOAT
        109 => t(4, 32, true, 2),   // R32G32B32A32_SFLOAT → R32G32B32A32_FLOAT
        16 => t(2, 8, false, 49),   // R8G8_UNORM → R8G8_UNORM
        37 => t(4, 8, false, 28),   // R8G8B8A8_UNORM → R8G8B8A8_UNORM
        77 => t(2, 16, false, 35),  // R16G16_UNORM → R16G16_UNORM
        91 => t(4, 16, false, 11),  // R16G16B16A16_UNORM → R16G16B16A16_UNORM
        _ => None,
    }
}

/// An uncompressed KTX2 file as [`super::texture`] writes it, taken apart: the header fields,
/// the DFD and key/value data as written, and each level's bytes (level 0 first).
#[derive(Debug, Clone, PartialEq)]
pub struct Texture {
    pub vk_format: u32,
    pub type_size: u32,
    pub width: u32,
    pub height: u32,
    /// 0 for a 2-D texture.
    pub depth: u32,
    pub dfd: Vec<u8>,
    /// Key/value entries in file order (sorted by key), values with their NUL.
    pub kv: Vec<(String, Vec<u8>)>,
    pub levels: Vec<Vec<u8>>,
}

/// Level 0's texels as array literals: the element type of C and of JavaScript, and the values
/// (16F as their binary16 bit patterns, 32F as round-trip decimal literals, UNORM as codes).
fn array_elements(t: &Texture) -> (&'static str, &'static str, Vec<String>) {
    let texel = t.texel();
    let data = &t.levels[0];
    match (texel.float, texel.bits) {
        (true, 32) => ("float", "Float32Array", data.chunks_exact(4).map(|b| super::f32_literal(f32::from_le_bytes(b.try_into().unwrap()))).collect()),
        (_, 16) => ("uint16_t", "Uint16Array", data.chunks_exact(2).map(|b| format!("0x{:04x}", u16::from_le_bytes([b[0], b[1]]))).collect()),
        _ => ("uint8_t", "Uint8Array", data.iter().map(|b| b.to_string()).collect()),
    }
}

/// The values 8 a line, each followed by `suffix` (C's `f` on float literals).
fn rows(values: &[String], suffix: &str) -> String {
    values.chunks(8).map(|c| format!("    {},\n", c.iter().map(|v| format!("{v}{suffix}")).collect::<Vec<_>>().join(", "))).collect()
}

impl Texture {
    /// What the array files say of the texture: size, channels, format.
    fn array_comment(&self, name: &str) -> String {
        let t = self.texel();
        let kind = if t.float { format!("{}-bit float", t.bits) } else { format!("{}-bit UNORM", t.bits) };
        let size = if self.depth > 0 { format!("{}x{}x{}", self.width, self.height, self.depth) } else { format!("{}x{}", self.width, self.height) };
        let channels = if t.channels == 1 { "1 channel".to_string() } else { format!("{} channels", t.channels) };
        format!("{name}: {size} texels, {channels}, {kind} (VkFormat {}); row 0 first, slice after slice, the channels of a texel together", self.vk_format)
    }

    /// What the array forms share, for a one-level texture: the name in capitals, the elements
    /// ([`array_elements`]) and the comment lines (the generated-file header, the layout).
    fn array_parts(&self, name: &str) -> Option<(String, (&'static str, &'static str, Vec<String>), String)> {
        if self.levels.len() != 1 {
            return None;
        }
        let mut preamble: String = self.value("shadefit").map(|h| String::from_utf8_lossy(h).lines().map(|l| format!("// {l}\n")).collect()).unwrap_or_default();
        preamble.push_str(&format!("// {}\n", self.array_comment(name)));
        Some((name.to_uppercase(), array_elements(self), preamble))
    }

    /// The C header: `NAME_WIDTH`, `_HEIGHT`, `_DEPTH`, `_CHANNELS` and `NAME_DATA`, level 0.
    /// `None` for a mip chain.
    pub fn c_header(&self, name: &str) -> Option<String> {
        let (up, (ty, _, values), mut s) = self.array_parts(name)?;
        s.push_str(&format!("#ifndef {up}_H\n#define {up}_H\n\n#include <stdint.h>\n\n"));
        for (k, v) in [("WIDTH", self.width), ("HEIGHT", self.height), ("DEPTH", self.depth), ("CHANNELS", self.texel().channels as u32)] {
            s.push_str(&format!("#define {up}_{k} {v}\n"));
        }
        s.push_str(&format!("\nstatic const {ty} {up}_DATA[{}] = {{\n{}}};\n\n#endif\n", values.len(), rows(&values, if ty == "float" { "f" } else { "" })));
        Some(s)
    }

    /// The JavaScript module: `export const NAME = { width, height, depth, channels, vkFormat,
    /// data }`, level 0. `None` for a mip chain.
    pub fn js_module(&self, name: &str) -> Option<String> {
        let (up, (_, array, values), mut s) = self.array_parts(name)?;
        s.push_str(&format!(
            "export const {up} = {{\n  width: {}, height: {}, depth: {}, channels: {}, vkFormat: {},\n  data: new {array}([\n{}  ]),\n}};\n",
            self.width,
            self.height,
            self.depth,
            self.texel().channels,
            self.vk_format,
            rows(&values, "")
        ));
        Some(s)
    }
}

fn u32_at(b: &[u8], at: usize) -> Result<u32, String> {
    b.get(at..at + 4).map(|s| u32::from_le_bytes(s.try_into().unwrap())).ok_or_else(|| format!("truncated at byte {at}"))
}

fn u64_at(b: &[u8], at: usize) -> Result<usize, String> {
    b.get(at..at + 8).map(|s| u64::from_le_bytes(s.try_into().unwrap()) as usize).ok_or_else(|| format!("truncated at byte {at}"))
}

fn slice(b: &[u8], at: usize, len: usize) -> Result<&[u8], String> {
    b.get(at..at + len).ok_or_else(|| format!("{len} bytes at {at} past the end ({})", b.len()))
}

impl Texture {
    /// Take apart an uncompressed, single-layer, single-face KTX2 file of a [`texel_of`] format.
    pub fn parse(bytes: &[u8]) -> Result<Texture, String> {
        if bytes.get(..12) != Some(&super::texture::KTX2_IDENTIFIER[..]) {
            return Err("not a KTX2 file".into());
        }
        let h: Vec<u32> = (0..9).map(|i| u32_at(bytes, 12 + 4 * i)).collect::<Result<_, _>>()?;
        let [vk_format, type_size, width, height, depth, layers, faces, levels, scheme] = h[..] else { unreachable!() };
        if texel_of(vk_format).is_none() || layers != 0 || faces != 1 || levels == 0 || scheme != 0 {
            return Err(format!("vkFormat {vk_format}, {layers} layers, {faces} faces, {levels} levels, supercompression {scheme}: not a texture this module converts"));
        }
        let (dfd_at, dfd_len) = (u32_at(bytes, 48)? as usize, u32_at(bytes, 52)? as usize);
        let (kvd_at, kvd_len) = (u32_at(bytes, 56)? as usize, u32_at(bytes, 60)? as usize);
        let mut level_data = Vec::new();
        for l in 0..levels as usize {
            let at = 80 + 24 * l;
            level_data.push(slice(bytes, u64_at(bytes, at)?, u64_at(bytes, at + 8)?)?.to_vec());
        }
        let kvd = slice(bytes, kvd_at, kvd_len)?;
        let mut kv = Vec::new();
        let mut at = 0;
        while at < kvd.len() {
            let len = u32_at(kvd, at)? as usize;
            let entry = slice(kvd, at + 4, len)?;
            let nul = entry.iter().position(|&c| c == 0).ok_or("a key without its NUL")?;
            kv.push((String::from_utf8_lossy(&entry[..nul]).into_owned(), entry[nul + 1..].to_vec()));
            at = (at + 4 + len).next_multiple_of(4);
        }
        Ok(Texture { vk_format, type_size, width, height, depth, dfd: slice(bytes, dfd_at, dfd_len)?.to_vec(), kv, levels: level_data })
    }

    pub fn texel(&self) -> Texel {
        texel_of(self.vk_format).expect("a Texture holds a known format")
    }

    /// The value of key `key` without its NUL.
    pub fn value(&self, key: &str) -> Option<&[u8]> {
        self.kv.iter().find(|(k, _)| k == key).map(|(_, v)| v.strip_suffix(&[0]).unwrap_or(v))
    }

    /// The KTX2 file: uncompressed (levels at multiples of lcm(texel size, 4)), or with every
    /// level compressed by Zstandard at `zstd` (levels unaligned, `KTXwriterScParams` =
    /// `--zstd LEVEL` added). Levels are stored smallest first, as the specification orders them.
    pub fn ktx2(&self, zstd: Option<i32>) -> Vec<u8> {
        let mut kv = self.kv.clone();
        if let Some(level) = zstd {
            kv.push(("KTXwriterScParams".into(), format!("--zstd {level}\0").into_bytes()));
            kv.sort_by(|a, b| a.0.as_bytes().cmp(b.0.as_bytes()));
        }
        let mut kvd = Vec::new();
        for (k, v) in &kv {
            kvd.extend_from_slice(&((k.len() + 1 + v.len()) as u32).to_le_bytes());
            kvd.extend_from_slice(k.as_bytes());
            kvd.push(0);
            kvd.extend_from_slice(v);
            kvd.resize(kvd.len().next_multiple_of(4), 0);
        }
        let data: Vec<Vec<u8>> = match zstd {
            // A fixed level on one thread: the same bytes on every run and machine.
            Some(level) => self.levels.iter().map(|l| zstd::bulk::compress(l, level).expect("Zstandard compresses in memory")).collect(),
            None => self.levels.clone(),
        };
        let align = if zstd.is_some() { 1 } else { super::texture::level_alignment(self.texel().channels * self.type_size as usize) };
        let dfd_at = 80 + 24 * self.levels.len();
        let kvd_at = dfd_at + self.dfd.len();
        let mut offsets = vec![0; data.len()];
        let mut at = kvd_at + kvd.len();
        for i in (0..data.len()).rev() {
            at = at.next_multiple_of(align);
            offsets[i] = at;
            at += data[i].len();
        }
        let mut out = Vec::with_capacity(at);
        out.extend_from_slice(&super::texture::KTX2_IDENTIFIER);
        let scheme = if zstd.is_some() { 2 } else { 0 };
        for v in [self.vk_format, self.type_size, self.width, self.height, self.depth, 0, 1, data.len() as u32, scheme] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for v in [dfd_at, self.dfd.len(), kvd_at, kvd.len()] {
            out.extend_from_slice(&(v as u32).to_le_bytes());
        }
        out.extend_from_slice(&[0; 16]); // no supercompression global data
        for ((o, d), l) in offsets.iter().zip(&data).zip(&self.levels) {
            for v in [*o, d.len(), l.len()] {
                out.extend_from_slice(&(v as u64).to_le_bytes());
            }
        }
        out.extend_from_slice(&self.dfd);
        out.extend_from_slice(&kvd);
        for i in (0..data.len()).rev() {
            out.resize(offsets[i], 0);
            out.extend_from_slice(&data[i]);
        }
        out
    }

    /// The DDS file: magic, DDS_HEADER (124 bytes), DDS_HEADER_DXT10 (20 bytes), then the levels
    /// largest first, each slice after slice, row after row from the top.
    pub fn dds(&self) -> Vec<u8> {
        let t = self.texel();
        let pitch = self.width * t.channels as u32 * t.bits / 8;
        let mips = self.levels.len() as u32;
        // DDSD_CAPS | HEIGHT | WIDTH | PITCH | PIXELFORMAT, MIPMAPCOUNT with mips, DEPTH for 3-D.
        let mut flags = 0x1 | 0x2 | 0x4 | 0x8 | 0x1000;
        // DDSCAPS_TEXTURE; COMPLEX | MIPMAP with mips; COMPLEX for a volume.
        let mut caps = 0x1000;
        let mut caps2 = 0;
        if mips > 1 {
            flags |= 0x20000;
            caps |= 0x8 | 0x40_0000;
        }
        if self.depth > 0 {
            flags |= 0x80_0000;
            caps |= 0x8;
            caps2 |= 0x20_0000; // DDSCAPS2_VOLUME
        }
        let mut h: Vec<u32> = vec![124, flags, self.height, self.width, pitch, self.depth, mips];
        h.extend([0; 11]); // dwReserved1
        // DDS_PIXELFORMAT: size 32, DDPF_FOURCC, "DX10", no masks.
        h.extend([32, 0x4, u32::from_le_bytes(*b"DX10"), 0, 0, 0, 0, 0]);
        h.extend([caps, caps2, 0, 0, 0]);
        debug_assert_eq!(h.len() * 4, 124);
        // DXGI format, resource dimension (3: TEXTURE2D, 4: TEXTURE3D), misc flags, array size 1,
        // alpha mode unknown (0).
        h.extend([t.dxgi, if self.depth > 0 { 4 } else { 3 }, 0, 1, 0]);
        let mut out = b"DDS ".to_vec();
        for v in h {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for l in &self.levels {
            out.extend_from_slice(l);
        }
        out
    }

    /// The OpenEXR file of a float texture: one uncompressed scanline part of `width ×
    /// height·max(depth, 1)` pixels, channels R (G, B, A) as half (16F) or float (32F), the
    /// generated-file header in `comments`. `None` for a UNORM texture or a mip chain.
    pub fn exr(&self) -> Option<Vec<u8>> {
        use exr::prelude::*;
        let t = self.texel();
        if !t.float || self.levels.len() != 1 {
            return None;
        }
        let data = &self.levels[0];
        let (w, h) = (self.width as usize, self.height as usize * self.depth.max(1) as usize);
        let names = &["R", "G", "B", "A"][..t.channels];
        let channel = |c: usize| {
            let samples = if t.bits == 16 {
                FlatSamples::F16(data.chunks_exact(2).skip(c).step_by(t.channels).map(|b| f16::from_le_bytes([b[0], b[1]])).collect())
            } else {
                FlatSamples::F32(data.chunks_exact(4).skip(c).step_by(t.channels).map(|b| f32::from_le_bytes(b.try_into().unwrap())).collect())
            };
            AnyChannel::new(names[c], samples)
        };
        let channels = AnyChannels::sort((0..t.channels).map(channel).collect());
        let mut attributes = LayerAttributes::default();
        if let Some(header) = self.value("shadefit") {
            let mut text = header.to_vec();
            if self.depth > 0 {
                text.extend_from_slice(format!("\n{} slices of {}x{} stacked downwards, slice 0 on top", self.depth, self.width, self.height).as_bytes());
            }
            attributes.comments = Some(Text::from_slice_unchecked(&text));
        }
        let encoding = Encoding { compression: Compression::Uncompressed, blocks: Blocks::ScanLines, line_order: LineOrder::Increasing };
        let image = Image::from_layer(Layer::new((w, h), attributes, encoding, channels));
        let mut out = std::io::Cursor::new(Vec::new());
        image.write().non_parallel().to_buffered(&mut out).expect("an image in memory writes");
        Some(out.into_inner())
    }
}

/// Why a `formats` list is refused on a spec that writes no texture.
pub const NO_TEXTURE: &str = "this spec writes no texture (data/NAME.ktx2) to write in other formats";

/// The files of one KTX2 texture `path` (`data/NAME.ktx2`) in `formats`, or in its
/// [`default_formats`] for `None` (`ktx2`: the file as given); `Err` names a format the texture
/// cannot take.
pub fn files(path: &std::path::Path, ktx2: &[u8], formats: Option<&[TableFormat]>) -> Result<Vec<(std::path::PathBuf, Vec<u8>)>, String> {
    let t = Texture::parse(ktx2).map_err(|e| format!("{}: {e}", path.display()))?;
    let defaults;
    let formats = match formats {
        Some(f) => f,
        None => {
            defaults = default_formats(&t);
            &defaults
        }
    };
    let mut out = Vec::new();
    for &f in formats {
        let bytes = match f {
            TableFormat::Ktx2 => ktx2.to_vec(),
            TableFormat::Ktx2Zstd => t.ktx2(Some(ZSTD_LEVEL)),
            TableFormat::Dds => t.dds(),
            TableFormat::Exr => t.exr().ok_or_else(|| {
                format!("{}: OpenEXR holds float texels of one level; this texture is {}-bit {} with {} level(s)", path.display(), t.texel().bits, if t.texel().float { "float" } else { "UNORM" }, t.levels.len())
            })?,
            TableFormat::C | TableFormat::Js => {
                let name = path.file_stem().and_then(|s| s.to_str()).unwrap_or("table");
                let text = if f == TableFormat::C { t.c_header(name) } else { t.js_module(name) };
                text.ok_or_else(|| format!("{}: the {f} form holds one level; this texture has {}", path.display(), t.levels.len()))?.into_bytes()
            }
        };
        out.push((path.with_extension(f.extension()), bytes));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emit::texture::{TextureFormat, UnormLevel, ktx2_texels, ktx2_unorm_mips, ktx2_volume};

    #[test]
    fn a_texture_taken_apart_writes_back_the_same_bytes() {
        let values: Vec<f32> = (0..4 * 3 * 2).map(|i| i as f32 * 0.25 - 1.0).collect();
        for bytes in [
            ktx2_texels(4, 3, 2, &values, TextureFormat::Rgba16float, &[("shadefit", "h")]),
            ktx2_volume(2, 3, 2, 2, &values, TextureFormat::Rgba32float, &[]),
            ktx2_unorm_mips(
                &[UnormLevel { width: 2, height: 2, values: vec![0.5; 8] }, UnormLevel { width: 1, height: 1, values: vec![1.0; 2] }],
                2,
                8,
                &[],
            ),
        ] {
            assert_eq!(Texture::parse(&bytes).unwrap().ktx2(None), bytes);
        }
    }

    #[test]
    fn zstd_levels_inflate_to_the_texels_and_record_the_level() {
        let values: Vec<f32> = (0..64).map(|i| (i as f32).sin()).collect();
        let plain = ktx2_texels(8, 4, 2, &values, TextureFormat::Rgba16float, &[("shadefit", "h")]);
        let t = Texture::parse(&plain).unwrap();
        let z = t.ktx2(Some(ZSTD_LEVEL));
        // Offsets from the KTX 2.0 header: scheme at 44, level 0 at 80 (offset, length, full length).
        assert_eq!(u32_at(&z, 44).unwrap(), 2);
        let (at, len, full) = (u64_at(&z, 80).unwrap(), u64_at(&z, 88).unwrap(), u64_at(&z, 96).unwrap());
        assert_eq!(full, 8 * 4 * 4);
        assert_eq!(zstd::bulk::decompress(&z[at..at + len], full).unwrap(), t.levels[0]);
        let needle = b"KTXwriterScParams\0--zstd 22\0";
        assert!(z.windows(needle.len()).any(|w| w == needle));
    }

    #[test]
    fn format_lists_need_one_ktx2_form_and_known_names() {
        let p = |v: &[&str]| parse_list(&v.iter().map(|s| s.to_string()).collect::<Vec<_>>());
        assert_eq!(p(&["exr", "ktx2"]).unwrap(), [TableFormat::Ktx2, TableFormat::Exr]);
        // The uncompressed KTX2 is written whether listed or not.
        assert_eq!(p(&["ktx2-zstd", "dds"]).unwrap(), [TableFormat::Ktx2, TableFormat::Ktx2Zstd, TableFormat::Dds]);
        assert!(p(&["ktx2", "png"]).unwrap_err().contains("unknown table format 'png'"));
        assert!(p(&["ktx2", "ktx2"]).unwrap_err().contains("twice"));
    }

    #[test]
    fn unorm_mips_have_no_exr_and_a_volume_is_a_dx10_texture3d() {
        let mips = ktx2_unorm_mips(&[UnormLevel { width: 1, height: 1, values: vec![0.0; 2] }], 2, 8, &[]);
        assert!(files("data/x.ktx2".as_ref(), &mips, Some(&[TableFormat::Ktx2, TableFormat::Exr])).unwrap_err().contains("UNORM"));
        let vol = ktx2_volume(2, 2, 3, 1, &[0.5; 12], TextureFormat::Rgba32float, &[]);
        let dds = Texture::parse(&vol).unwrap().dds();
        // DDS_HEADER_DXT10 starts at 4 + 124: resource dimension 4 (TEXTURE3D); dwDepth at 4 + 20.
        assert_eq!((u32_at(&dds, 132).unwrap(), u32_at(&dds, 24).unwrap()), (4, 3));
        assert_eq!(dds.len(), 4 + 124 + 20 + 12 * 4);
    }
}
