//! `shadefit aniso-mip`: the mip chain of a normal map and an aniso map by SGGX filtering.
//!
//! Inputs: a tangent-space normal map (PNG, RGB or RGBA, 8 or 16 bits; n = normalize(2c − 1);
//! a normal with z ≤ 0, at or below the surface, is refused naming its pixel, and z is clamped
//! to ≥ 1e-3) and an aniso map in the course's encoding (PNG, RGB or RGBA, 8 or 16
//! bits: [√Sxx, ½ Sxy/√(Sxx Syy) + ½, √Syy], decoded as `DecodeSggx` does, so α ≥ α_min), of the
//! same size, at most [`MAX_SIDE`] texels a side (checked on the PNG header, before the image
//! is decoded). Every texel becomes S = M_n [[B, 0], [0, 1]] M_nᵀ; each level's S is the mean of
//! a `footprint` × `footprint` box of the previous level's (2: the 2×2 children; 4: those and
//! a ring around them, edges clamped); n′ by power iteration, the block normalised, encoded.
//!
//! Outputs: `OUT.normal.ktx2` (RG, n′.xy as ½n + ½) and `OUT.aniso.ktx2` (RGBA, the encoding
//! and A = 1), both UNORM of `bits` (8 or 16), the full chain down to 1×1. Nothing is written
//! unless both files are complete (temporary files, then renames). Per-texel work runs in
//! parallel and is collected in texel order: the files are the same at any thread count.

use super::integrals::{ALPHA_MIN, M3, V3, decode_course, encode, extract, sggx_from};
use crate::emit::texture::{UnormLevel, ktx2_unorm_mips};
use crate::family::{CommandError, FamilyCommand};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

pub const COMMAND: FamilyCommand = FamilyCommand {
    name: "aniso-mip",
    about: "SGGX-filtered mip chain of a normal map + aniso map (PNG in, KTX2 out)",
    run,
};

const USAGE: &str = "usage: shadefit aniso-mip --normal NORMAL.png --aniso ANISO.png --out PREFIX [--bits 8|16] [--footprint 2|4]
  writes PREFIX.normal.ktx2 (RG UNORM) and PREFIX.aniso.ktx2 (RGBA UNORM), every mip level;
  the maps: RGB or RGBA PNGs of one size, at most 8192 texels a side; normals with z > 0";

/// The most texels a side of an input map may have: WebGPU's default `maxTextureDimension2D`
/// (8192), the largest texture the emitted chains are sure to load. A map that size takes
/// about 8 GB here (an SGGX matrix and the samples in f64 per texel).
pub const MAX_SIDE: u32 = 8192;

/// Options of one run.
#[derive(Debug, Clone)]
pub struct Options {
    pub normal: PathBuf,
    pub aniso: PathBuf,
    pub out: PathBuf,
    pub bits: u32,
    pub footprint: usize,
}

fn input(msg: impl Into<String>) -> CommandError {
    CommandError::Input(msg.into())
}

pub fn parse(args: &[String]) -> Result<Options, CommandError> {
    let (mut normal, mut aniso, mut out, mut bits, mut footprint) = (None, None, None, 8, 2);
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut value = |flag: &str| it.next().cloned().ok_or_else(|| input(format!("aniso-mip: {flag} needs a value\n{USAGE}")));
        match a.as_str() {
            "--normal" => normal = Some(PathBuf::from(value(a)?)),
            "--aniso" => aniso = Some(PathBuf::from(value(a)?)),
            "--out" => out = Some(PathBuf::from(value(a)?)),
            "--bits" => {
                bits = match value(a)?.as_str() {
                    "8" => 8,
                    "16" => 16,
                    v => return Err(input(format!("aniso-mip: --bits: '{v}' is not 8 or 16"))),
                }
            }
            "--footprint" => {
                footprint = match value(a)?.as_str() {
                    "2" => 2,
                    "4" => 4,
                    v => return Err(input(format!("aniso-mip: --footprint: '{v}' is not 2 or 4"))),
                }
            }
            other => return Err(input(format!("aniso-mip: unknown argument '{other}'\n{USAGE}"))),
        }
    }
    let need = |v: Option<PathBuf>, flag: &str| v.ok_or_else(|| input(format!("aniso-mip: {flag} is required\n{USAGE}")));
    Ok(Options { normal: need(normal, "--normal")?, aniso: need(aniso, "--aniso")?, out: need(out, "--out")?, bits, footprint })
}

/// A PNG's channels as values in [0, 1]: (width, height, channels, values).
fn read_png(path: &Path, what: &str) -> Result<(u32, u32, usize, Vec<f64>), CommandError> {
    let bad = |field: &str, why: String| input(format!("{}: {field}: {why} ({what})", path.display()));
    let (file, _) = crate::spec::input::open_regular(path).map_err(|e| bad("file", e.to_string()))?;
    let decoder = png::Decoder::new(std::io::BufReader::new(file));
    let mut reader = decoder.read_info().map_err(|e| bad("png", e.to_string()))?;
    let info = reader.info().clone();
    if info.width > MAX_SIDE || info.height > MAX_SIDE {
        let why = format!("{}×{} texels; each side must be at most {MAX_SIDE}", info.width, info.height);
        return Err(bad("size", why));
    }
    let channels = match info.color_type {
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        c => return Err(bad("color type", format!("{c:?}; RGB or RGBA expected"))),
    };
    let depth = match info.bit_depth {
        png::BitDepth::Eight => 8,
        png::BitDepth::Sixteen => 16,
        d => return Err(bad("bit depth", format!("{d:?}; 8 or 16 expected"))),
    };
    let mut buf = vec![0; reader.output_buffer_size().ok_or_else(|| bad("size", "too large".into()))?];
    let frame = reader.next_frame(&mut buf).map_err(|e| bad("png", e.to_string()))?;
    let bytes = &buf[..frame.buffer_size()];
    let values: Vec<f64> = if depth == 8 {
        bytes.iter().map(|&b| b as f64 / 255.0).collect()
    } else {
        bytes.chunks(2).map(|c| u16::from_be_bytes([c[0], c[1]]) as f64 / 65535.0).collect()
    };
    Ok((info.width, info.height, channels, values))
}

/// Statistics of a run.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Report {
    pub levels: usize,
    pub texels: usize,
    pub max_iterations: usize,
    pub not_converged: usize,
    /// Filtered blocks with an eigenvalue > 1 (clamped by the encoding).
    pub clamped: usize,
}

/// The two KTX2 files' bytes and the run's statistics.
pub fn mip_chain(width: u32, height: u32, s0: Vec<M3>, bits: u32, footprint: usize, progress: &dyn Fn(u64)) -> (Vec<u8>, Vec<u8>, Report) {
    let mut report = Report::default();
    let mut normals: Vec<UnormLevel> = Vec::new();
    let mut anisos: Vec<UnormLevel> = Vec::new();
    let (mut w, mut h, mut s) = (width as usize, height as usize, s0);
    loop {
        let texels: Vec<super::integrals::Extracted> = s.par_iter().map(extract).collect();
        let mut nv = Vec::with_capacity(w * h * 2);
        let mut av = Vec::with_capacity(w * h * 4);
        for e in &texels {
            report.max_iterations = report.max_iterations.max(e.power.iterations);
            report.not_converged += !e.power.converged as usize;
            report.clamped += (e.aniso.alphas().0 > 1.0 + 1e-12) as usize;
            nv.extend([0.5 * e.n.x + 0.5, 0.5 * e.n.y + 0.5]);
            let t = encode(e.aniso);
            av.extend([t[0], t[1], t[2], 1.0]);
        }
        report.texels += texels.len();
        progress(texels.len() as u64);
        normals.push(UnormLevel { width: w as u32, height: h as u32, values: nv });
        anisos.push(UnormLevel { width: w as u32, height: h as u32, values: av });
        if w == 1 && h == 1 {
            break;
        }
        let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
        let prev = &s;
        let next: Vec<M3> = (0..nw * nh)
            .into_par_iter()
            .map(|k| {
                let (x, y) = (k % nw, k / nw);
                // The children (2x, 2y)…(2x+1, 2y+1) and, for footprint 4, one texel around them.
                let r = (footprint as isize - 2) / 2;
                let mut acc = M3::zeros();
                let mut count = 0.0;
                for dy in -r..2 + r {
                    for dx in -r..2 + r {
                        let sx = (2 * x as isize + dx).clamp(0, w as isize - 1) as usize;
                        let sy = (2 * y as isize + dy).clamp(0, h as isize - 1) as usize;
                        acc += prev[sy * w + sx];
                        count += 1.0;
                    }
                }
                acc / count
            })
            .collect();
        (w, h, s) = (nw, nh, next);
    }
    report.levels = normals.len();
    let meta = [("shadefit", "aniso-mip: SGGX-filtered normal map (n.xy as n/2 + 1/2)")];
    let normal = ktx2_unorm_mips(&normals, 2, bits, &meta);
    let meta = [("shadefit", "aniso-mip: SGGX aniso map [sqrt(Sxx), Sxy/sqrt(Sxx Syy)/2 + 1/2, sqrt(Syy), 1]")];
    let aniso = ktx2_unorm_mips(&anisos, 4, bits, &meta);
    (normal, aniso, report)
}

/// The first texel (x, y) of a `width`-wide normal map whose normal has z ≤ 0 (at or below the
/// surface, which a tangent-space normal cannot be), with its z.
pub fn first_downward(normal: &[f64], nc: usize, width: u32) -> Option<((usize, usize), f64)> {
    let w = width as usize;
    normal.chunks_exact(nc).map(|c| 2.0 * c[2] - 1.0).enumerate().find(|&(_, z)| !(z > 0.0)).map(|(i, z)| ((i % w, i / w), z))
}

/// The texels' SGGX matrices from the two maps' values (normals with z > 0: [`first_downward`]).
pub fn texels(normal: &[f64], nc: usize, aniso: &[f64], ac: usize, count: usize) -> Vec<M3> {
    (0..count)
        .into_par_iter()
        .map(|i| {
            let c = &normal[i * nc..i * nc + 3];
            let mut n = V3::new(2.0 * c[0] - 1.0, 2.0 * c[1] - 1.0, (2.0 * c[2] - 1.0).max(1e-3));
            n /= n.norm();
            let t = &aniso[i * ac..i * ac + 3];
            sggx_from(n, decode_course([t[0], t[1], t[2]], ALPHA_MIN).aniso())
        })
        .collect()
}

fn write_atomically(files: &[(PathBuf, Vec<u8>)]) -> Result<(), CommandError> {
    let mut temps = Vec::new();
    for (path, bytes) in files {
        let tmp = path.with_extension("ktx2.tmp");
        if let Err(e) = std::fs::write(&tmp, bytes) {
            for t in &temps {
                let _ = std::fs::remove_file(t);
            }
            let _ = std::fs::remove_file(&tmp);
            return Err(CommandError::Failed(format!("{}: {e}", tmp.display())));
        }
        temps.push(tmp);
    }
    for ((path, _), tmp) in files.iter().zip(&temps) {
        std::fs::rename(tmp, path).map_err(|e| CommandError::Failed(format!("{}: {e}", path.display())))?;
    }
    Ok(())
}

pub fn run(args: &[String]) -> Result<String, CommandError> {
    if args.iter().any(|a| a == "-h" || a == "--help") {
        return Ok(USAGE.into());
    }
    let o = parse(args)?;
    let (w, h, nc, nv) = read_png(&o.normal, "normal map")?;
    let (aw, ah, ac, avals) = read_png(&o.aniso, "aniso map")?;
    if (aw, ah) != (w, h) {
        return Err(input(format!("{}: size: {aw}×{ah} differs from the normal map's {w}×{h} ({})", o.aniso.display(), o.normal.display())));
    }
    let total: u64 = {
        let (mut w, mut h, mut t) = (w as u64, h as u64, 0);
        loop {
            t += w * h;
            if w == 1 && h == 1 {
                break t;
            }
            (w, h) = ((w / 2).max(1), (h / 2).max(1));
        }
    };
    let bar = if total >= 1 << 20 { indicatif::ProgressBar::new(total) } else { indicatif::ProgressBar::hidden() };
    if let Some(((x, y), z)) = first_downward(&nv, nc, w) {
        let c = &nv[(y * w as usize + x) * nc..][..3];
        let n = [c[0], c[1], c[2]].map(|v| 2.0 * v - 1.0);
        return Err(input(format!(
            "{}: pixel ({x}, {y}): the normal ({:.4}, {:.4}, {:.4}) has z = {z:.4} ≤ 0, at or below the surface; \
             a tangent-space normal map needs z > 0 (normal map)",
            o.normal.display(),
            n[0],
            n[1],
            n[2]
        )));
    }
    let s0 = texels(&nv, nc, &avals, ac, (w * h) as usize);
    let (normal, aniso, r) = mip_chain(w, h, s0, o.bits, o.footprint, &|n| bar.inc(n));
    bar.finish_and_clear();
    let stem = o.out.to_string_lossy().to_string();
    let files = [(PathBuf::from(format!("{stem}.normal.ktx2")), normal), (PathBuf::from(format!("{stem}.aniso.ktx2")), aniso)];
    write_atomically(&files)?;
    Ok(format!(
        "{}\n{}\n{} levels, {} texels; power iteration: at most {} iterations, {} not converged; {} blocks clamped by the encoding",
        files[0].0.display(),
        files[1].0.display(),
        r.levels,
        r.texels,
        r.max_iterations,
        r.not_converged,
        r.clamped
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texels_read_each_texel_s_own_channels() {
        // Two RGBA texels. Texel 0: n = +z, channels [0.6, ½, 0.3] decode to Sxx = 0.36, Sxy = 0,
        // Syy = 0.09, so S = diag(0.36, 0.09, 1). Texel 1: n = (0.6, 0, 0.8) (stored n/2 + ½) and
        // [0.4, ½, 0.7]: α_t along y with α_t² = 0.49, α_b² = 0.16; the frame turns about y, so
        // S ŷ = 0.49 ŷ, S n = n and tr S = 1.65. 1e-12: f64 rounding of entries ≤ 1 through a
        // normalisation and two products.
        let normal = [0.5, 0.5, 1.0, 0.25, 0.8, 0.5, 0.9, 0.25];
        let aniso = [0.6, 0.5, 0.3, 1.0, 0.4, 0.5, 0.7, 1.0];
        let s = texels(&normal, 4, &aniso, 4, 2);
        assert_eq!(s.len(), 2);
        let want0 = M3::new(0.36, 0.0, 0.0, 0.0, 0.09, 0.0, 0.0, 0.0, 1.0);
        assert!((s[0] - want0).abs().max() < 1e-12, "{}", s[0]);
        let n = V3::new(0.6, 0.0, 0.8);
        let y = V3::new(0.0, 1.0, 0.0);
        assert!((s[1] * n - n).norm() < 1e-12, "{}", s[1]);
        assert!((s[1] * y - 0.49 * y).norm() < 1e-12, "{}", s[1]);
        assert!((s[1].trace() - 1.65).abs() < 1e-12, "{}", s[1]);
    }
    use crate::family::sggx::integrals::{Aniso, direction, sggx_from};

    /// A normal at or below the surface is found at its pixel: in a 2-wide RGB map, (0, 1)
    /// holds the 8-bit codes (128, 128, 0), z = −1, and (1, 1) (200, 128, 30); an 8-bit code
    /// cannot give z = 0 exactly (2c/255 − 1 = 0 needs c = 127.5), so 127 is the largest below
    /// the surface and 128 the smallest above it. The help names the size limit.
    #[test]
    fn normals_at_or_below_the_surface_are_found_at_their_pixel() {
        let map = |codes: &[[u8; 3]]| codes.iter().flatten().map(|&c| c as f64 / 255.0).collect::<Vec<_>>();
        let up = [128, 128, 255];
        assert_eq!(first_downward(&map(&[up, up, up, up]), 3, 2), None);
        assert_eq!(first_downward(&map(&[up, up, [128, 128, 128], up]), 3, 2), None);
        let (at, z) = first_downward(&map(&[up, up, [128, 128, 0], [200, 128, 30]]), 3, 2).unwrap();
        assert_eq!((at, z), ((0, 1), -1.0));
        let (at, z) = first_downward(&map(&[up, up, up, [200, 128, 127]]), 3, 2).unwrap();
        assert_eq!(at, (1, 1));
        assert!(z < 0.0 && z > -0.004, "{z}");
        assert!(USAGE.contains(&format!("at most {MAX_SIDE} texels a side")));
    }

    /// A PNG written here with the png crate: `data` is its samples in row order (big-endian
    /// pairs at 16 bits).
    fn write_png(path: &Path, (w, h): (u32, u32), color: png::ColorType, depth: png::BitDepth, data: &[u8]) {
        let mut enc = png::Encoder::new(std::fs::File::create(path).unwrap(), w, h);
        enc.set_color(color);
        enc.set_depth(depth);
        enc.write_header().unwrap().write_image_data(data).unwrap();
    }

    /// The maps are read as (width, height, channels, samples as UNORM values in row order):
    /// v/255 at 8 bits, v/65535 at 16; a grey map is refused, naming the file and the field.
    #[test]
    fn maps_read_back_as_unorm_samples() {
        let dir = tempfile::tempdir().unwrap();
        let rgb8 = dir.path().join("rgb8.png");
        let bytes = [0u8, 51, 255, 128, 1, 2];
        write_png(&rgb8, (2, 1), png::ColorType::Rgb, png::BitDepth::Eight, &bytes);
        let (w, h, c, v) = read_png(&rgb8, "normal map").unwrap();
        assert_eq!((w, h, c), (2, 1, 3));
        assert_eq!(v, bytes.map(|b| b as f64 / 255.0));
        let rgba16 = dir.path().join("rgba16.png");
        let words = [0u16, 65535, 32768, 1, 258, 4660, 65534, 7];
        let be: Vec<u8> = words.iter().flat_map(|w| w.to_be_bytes()).collect();
        write_png(&rgba16, (1, 2), png::ColorType::Rgba, png::BitDepth::Sixteen, &be);
        let (w, h, c, v) = read_png(&rgba16, "aniso map").unwrap();
        assert_eq!((w, h, c), (1, 2, 4));
        assert_eq!(v, words.map(|x| x as f64 / 65535.0));
        let grey = dir.path().join("grey.png");
        write_png(&grey, (1, 1), png::ColorType::Grayscale, png::BitDepth::Eight, &[9]);
        let e = read_png(&grey, "aniso map").unwrap_err().to_string();
        assert!(e.contains("grey.png") && e.contains("color type") && e.contains("(aniso map)"), "{e}");
    }

    /// The report counts what it names, on 1×1 textures (one level, one texel):
    /// - a lobe whose normal's eigenvalue 1 is the start's (z) but not the largest (α_t = 1.2 in
    ///   the plane): the iteration stops at once on z, and the block's α_t² = 1.44 passes 1, so
    ///   the encoding clamps it;
    /// - a tilted lobe of α = 0.9999: the residual shrinks by λ₂/λ₁ = α² a step, so reaching
    ///   POWER_TOL would take ln(1e-14)/ln(α²) ≈ 161 000 steps, past POWER_MAX_ITER (100 000):
    ///   not converged, and the block (within e^-20 of the converged one) stays under 1;
    /// - an α = 1 lobe (S = I): its block's eigenvalue is exactly 1, which the encoding stores
    ///   (√1 = 1), so it is not counted as clamped.
    #[test]
    fn the_report_counts_unconverged_and_clamped_texels() {
        use super::super::integrals::{Aniso, POWER_MAX_ITER, direction};
        let count = |s: M3| {
            let r = mip_chain(1, 1, vec![s], 8, 2, &|_| {}).2;
            (r.levels, r.texels, r.max_iterations, r.not_converged, r.clamped)
        };
        assert_eq!(count(sggx_from(V3::z(), Aniso::from_alphas(1.2, 0.5, 0.0))), (1, 1, 0, 0, 1));
        let predicted = (1e-14f64).ln() / (0.9999f64 * 0.9999).ln();
        assert!(predicted > 1.5 * POWER_MAX_ITER as f64, "{predicted}");
        assert_eq!(count(sggx_from(direction(0.6, 0.3), Aniso::isotropic(0.9999))), (1, 1, POWER_MAX_ITER, 1, 0));
        assert_eq!(count(M3::identity()), (1, 1, 0, 0, 0));
    }

    /// The 8-bit codes of a texel with normal n and block a, as the two maps store them:
    /// (n.x, n.y)/2 + ½ and [encode(a), 1], each v → round(255 v).
    fn codes8(n: V3, a: Aniso) -> ([u8; 2], [u8; 4]) {
        let t = encode(a);
        let code = |v: f64| (v * 255.0).round() as u8;
        ([0.5 * n.x + 0.5, 0.5 * n.y + 0.5].map(code), [t[0], t[1], t[2], 1.0].map(code))
    }

    #[test]
    fn a_uniform_texture_keeps_its_texel_at_every_level() {
        // Every level's S is the mean of equal matrices, so every texel is the input's to the
        // power iteration's residual (1e-12 after encoding, far below an 8-bit step); 5×3 → 2×1 →
        // 1×1, footprint 4 (edges clamped) alike.
        let n = direction(0.5, 1.0);
        let a = Aniso::from_alphas(0.6, 0.1, 0.4);
        let s = sggx_from(n, a);
        for footprint in [2, 4] {
            let (normal, aniso, r) = mip_chain(5, 3, vec![s; 15], 8, footprint, &|_| {});
            assert_eq!((r.levels, r.texels, r.not_converged, r.clamped), (3, 15 + 2 + 1, 0, 0));
            let (want_n, want_a) = codes8(n, a);
            let rn = ktx2::Reader::new(&normal[..]).unwrap();
            let ra = ktx2::Reader::new(&aniso[..]).unwrap();
            for (ln, la) in rn.levels().zip(ra.levels()) {
                assert!(ln.data.chunks(2).all(|c| c == want_n), "{:?} vs {want_n:?}", &ln.data[..2]);
                assert!(la.data.chunks(4).all(|c| c == want_a));
            }
        }
    }

    /// Each texel of a level is the mean of its own footprint of the level below (module doc:
    /// 2, the 2×2 children; 4, those and one texel around them, edges clamped; any even
    /// footprint f is the f × f box, (f − 2)/2 texels around the children: 6 here): a 4 × 4
    /// texture whose sixteen lobes all differ (tilt, azimuth and roughness by texel), filtered
    /// to 2 × 2, against the box means formed here texel by texel and taken through the same
    /// extraction and encoding (judged by their own tests). 8-bit codes, within one: the sums
    /// may round apart in their last bit and move a code that sits on a boundary.
    #[test]
    fn each_texel_is_the_mean_of_its_own_footprint() {
        let (w, h) = (4usize, 4usize);
        let s0: Vec<M3> = (0..w * h)
            .map(|k| {
                let (x, y) = ((k % w) as f64, (k / w) as f64);
                let a = Aniso::from_alphas(0.2 + 0.1 * y, 0.1 + 0.05 * x, 0.3 * x + 0.2 * y);
                sggx_from(direction(0.1 + 0.15 * x + 0.05 * y, 0.4 * y + 1.3 * x), a)
            })
            .collect();
        for (footprint, offsets) in [(2usize, vec![0isize, 1]), (4, vec![-1, 0, 1, 2]), (6, vec![-2, -1, 0, 1, 2, 3])] {
            let (normal, aniso, _) = mip_chain(w as u32, h as u32, s0.clone(), 8, footprint, &|_| {});
            let level = |bytes: &[u8]| ktx2::Reader::new(bytes).unwrap().levels().nth(1).unwrap().data.to_vec();
            let (ln, la) = (level(&normal), level(&aniso));
            for (k, (x, y)) in [(0isize, 0isize), (1, 0), (0, 1), (1, 1)].into_iter().enumerate() {
                let mut sum = M3::zeros();
                for dy in &offsets {
                    for dx in &offsets {
                        let (sx, sy) = ((2 * x + dx).clamp(0, w as isize - 1), (2 * y + dy).clamp(0, h as isize - 1));
                        sum += s0[sy as usize * w + sx as usize];
                    }
                }
                let e = extract(&(sum / (offsets.len() * offsets.len()) as f64));
                let (want_n, want_a) = codes8(e.n, e.aniso);
                let got_n = &ln[2 * k..2 * k + 2];
                let got_a = &la[4 * k..4 * k + 4];
                let near = |got: &[u8], want: &[u8]| got.iter().zip(want).all(|(&g, &w)| g.abs_diff(w) <= 1);
                assert!(near(got_n, &want_n) && near(got_a, &want_a), "footprint {footprint}, texel ({x}, {y}): {got_n:?} {got_a:?} vs {want_n:?} {want_a:?}");
            }
        }
    }

    #[test]
    fn two_tilted_texels_filter_to_the_mixture_s_normal() {
        // A 2×1 texture of normals at ±30° about z (isotropic α = 0.3): its 1×1 level has the
        // normal z (the mean of S is symmetric under the mirror x → −x) and a block wider along
        // x than y; 16-bit codes.
        let a = Aniso::isotropic(0.3);
        let tilt = std::f64::consts::FRAC_PI_6;
        let s = vec![sggx_from(direction(tilt, 0.0), a), sggx_from(direction(tilt, std::f64::consts::PI), a)];
        let (normal, aniso, r) = mip_chain(2, 1, s, 16, 2, &|_| {});
        assert_eq!(r.levels, 2);
        let rn = ktx2::Reader::new(&normal[..]).unwrap();
        let top = rn.levels().nth(1).unwrap().data;
        let n: Vec<u16> = top.chunks(2).map(|c| u16::from_le_bytes([c[0], c[1]])).collect();
        // n′ = z: both codes ½·65535 = 32767.5, rounded either way by the residual's 1e-16.
        assert!(n.iter().all(|&c| c == 32767 || c == 32768), "{n:?}");
        let ra = ktx2::Reader::new(&aniso[..]).unwrap();
        let top = ra.levels().nth(1).unwrap().data;
        let v: Vec<u16> = top.chunks(2).map(|c| u16::from_le_bytes([c[0], c[1]])).collect();
        assert!(v[0] > v[2], "√Sxx {} > √Syy {}", v[0], v[2]);
    }

    /// The command end to end on a uniform 4×2 texture (normal codes (191, 128, 230), aniso
    /// codes (153, 128, 77), about [0.6, ½, 0.3]): its help; both files written, each a full chain 4×2, 2×1, 1×1 of 16-bit
    /// texels that keep the input's normal (every level the mean of equal matrices: within one
    /// 16-bit code of ½n + ½ with n = normalize(2c/255 − 1)); the report counts 8 + 2 + 1
    /// texels. An aniso map of another size is refused naming both maps, and nothing is written.
    #[test]
    fn run_writes_both_chains_or_nothing() {
        let args = |v: &[&str]| v.iter().map(|a| a.to_string()).collect::<Vec<_>>();
        assert_eq!(run(&args(&["--out", "x", "--help"])).unwrap(), USAGE);
        let dir = tempfile::tempdir().unwrap();
        let (normal, aniso, small) = (dir.path().join("n.png"), dir.path().join("a.png"), dir.path().join("small.png"));
        write_png(&normal, (4, 2), png::ColorType::Rgb, png::BitDepth::Eight, &[191u8, 128, 230].repeat(8));
        write_png(&aniso, (4, 2), png::ColorType::Rgb, png::BitDepth::Eight, &[153u8, 128, 77].repeat(8));
        write_png(&small, (2, 2), png::ColorType::Rgb, png::BitDepth::Eight, &[153u8, 128, 77].repeat(4));
        let out = dir.path().join("m");
        let (n_path, a_path) = (dir.path().join("m.normal.ktx2"), dir.path().join("m.aniso.ktx2"));
        let path = |p: &Path| p.display().to_string();
        let e = run(&args(&["--normal", &path(&normal), "--aniso", &path(&small), "--out", &path(&out)])).unwrap_err().to_string();
        assert!(e.contains("small.png: size: 2×2") && e.contains("4×2") && e.contains("n.png"), "{e}");
        assert!(!n_path.exists() && !a_path.exists());
        let msg = run(&args(&["--normal", &path(&normal), "--aniso", &path(&aniso), "--out", &path(&out), "--bits", "16"])).unwrap();
        let lines: Vec<&str> = msg.lines().collect();
        assert_eq!(lines[..2], [path(&n_path), path(&a_path)]);
        assert!(lines[2].starts_with("3 levels, 11 texels;") && lines[2].ends_with("0 not converged; 0 blocks clamped by the encoding"), "{msg}");
        let c = [191.0, 128.0, 230.0].map(|v: f64| 2.0 * v / 255.0 - 1.0);
        let len = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
        let want = [c[0] / len, c[1] / len].map(|x| (0.5 * x + 0.5) * 65535.0);
        let bytes = std::fs::read(&n_path).unwrap();
        let r = ktx2::Reader::new(&bytes[..]).unwrap();
        let sizes: Vec<usize> = r.levels().map(|l| l.data.len()).collect();
        assert_eq!(sizes, [8 * 4, 2 * 4, 4]);
        for l in r.levels() {
            let codes: Vec<f64> = l.data.chunks(2).map(|b| u16::from_le_bytes([b[0], b[1]]) as f64).collect();
            assert!(codes.chunks(2).all(|p| (p[0] - want[0]).abs() <= 1.0 && (p[1] - want[1]).abs() <= 1.0), "{codes:?} vs {want:?}");
        }
        let a = std::fs::read(&a_path).unwrap();
        assert_eq!(ktx2::Reader::new(&a[..]).unwrap().levels().map(|l| l.data.len()).collect::<Vec<_>>(), [8 * 8, 2 * 8, 8]);
    }
}
