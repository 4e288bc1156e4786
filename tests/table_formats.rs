//! The table textures in every format their specs ask for (`[emit] formats`, `emit::formats`):
//! - every committed `generated/data/NAME.ktx2` has exactly the DDS and EXR siblings its spec
//!   names (by default both, EXR only for float texels of one level), is itself uncompressed,
//!   and a `ktx2-zstd` spec's `NAME.zstd.ktx2` is the same texture Zstandard-supercompressed;
//! - each DDS file, read by the `ddsfile` crate, has the KTX2's size, depth, level count, the
//!   `DXGI_FORMAT` of its `VkFormat` (the table below, from the Vulkan and DXGI enumerations) and,
//!   level after level, the same texel bytes as the KTX2 read by the `ktx2` crate (inflated by
//!   `ruzstd` where supercompressed). No tolerance: the bytes are the texels, which each family's
//!   tests compare with its JSON values. (The EXR files are read by OpenEXR's own library in
//!   tests/python/test_table_formats.py.)
//! - the bevy-layout spec's zstd file has the header fields and DFD of bevy's `dfg.ktx2`
//!   (tests/data/bevy) and texels close to bevy's;
//! - a bad `formats` list is a spec error naming the file, line and field, with nothing written.

mod common;

use common::{assert_nothing_written, root, scratch, shadefit, stderr};
use std::collections::BTreeSet;
use std::path::Path;

/// VkFormat → DXGI_FORMAT (the Vulkan `VkFormat` and DXGI `DXGI_FORMAT` enumerations).
fn dxgi_of(vk: u32) -> ddsfile::DxgiFormat {
    use ddsfile::DxgiFormat as D;
    match vk {
        76 => D::R16_Float,
        83 => D::R16G16_Float,
        97 => D::R16G16B16A16_Float,
        100 => D::R32_Float,
        103 => D::R32G32_Float,
        109 => D::R32G32B32A32_Float,
        16 => D::R8G8_UNorm,
        37 => D::R8G8B8A8_UNorm,
        77 => D::R16G16_UNorm,
        91 => D::R16G16B16A16_UNorm,
        other => panic!("VkFormat {other} is not one the tables use"),
    }
}

/// A KTX2 file through the `ktx2` crate: header and each level's texel bytes (level 0 first),
/// Zstandard levels inflated by `ruzstd`.
struct Ktx2 {
    header: ktx2::Header,
    float: bool,
    levels: Vec<Vec<u8>>,
}

fn read_ktx2(bytes: &[u8]) -> Ktx2 {
    let r = ktx2::Reader::new(bytes).expect("a valid KTX2 file");
    let header = r.header();
    let levels = r.levels().map(|l| common::ktx2_level_bytes("KTX2", header.supercompression_scheme, &l)).collect();
    // KHR_DF_SAMPLE_DATATYPE_FLOAT (0x80) in the first sample's channel byte.
    let float = r.basic_dfd().expect("a basic DFD").sample_information[0].channel_type_qualifiers.contains(ktx2::dfd::ChannelTypeQualifiers::FLOAT);
    Ktx2 { header, float, levels }
}

/// The spec that writes `stem` (`ltc_ggx_1_f32` → `ltc_ggx`): the longest spec name that is the
/// stem or a prefix of it followed by `_`; its `[emit] formats`, if any.
fn spec_formats(stem: &str) -> (String, Option<Vec<String>>) {
    let mut best: Option<(String, Option<Vec<String>>)> = None;
    for e in std::fs::read_dir(root().join("fits")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_none_or(|x| x != "toml") {
            continue;
        }
        let name = p.file_stem().unwrap().to_string_lossy().into_owned();
        if !(stem == name || stem.starts_with(&format!("{name}_"))) || best.as_ref().is_some_and(|b| b.0.len() > name.len()) {
            continue;
        }
        let v: toml::Value = toml::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
        let formats = v.get("emit").and_then(|e| e.get("formats")).map(|f| f.as_array().unwrap().iter().map(|s| s.as_str().unwrap().to_string()).collect());
        best = Some((name, formats));
    }
    best.unwrap_or_else(|| panic!("no spec writes {stem}.ktx2"))
}

#[test]
fn every_texture_has_the_files_its_spec_names_and_the_dds_holds_the_ktx2_texels() {
    let data = root().join("generated/data");
    let mut textures = 0;
    let mut names: BTreeSet<String> = BTreeSet::new();
    for e in std::fs::read_dir(&data).unwrap() {
        names.insert(e.unwrap().file_name().to_string_lossy().into_owned());
    }
    for file in names.iter().filter(|n| n.ends_with(".ktx2") && !n.ends_with(".zstd.ktx2")) {
        let stem = file.strip_suffix(".ktx2").unwrap();
        let k = read_ktx2(&std::fs::read(data.join(file)).unwrap());
        let (spec, listed) = spec_formats(stem);
        let formats = listed.clone().unwrap_or_else(|| {
            let mut f = vec!["ktx2".to_string(), "dds".into()];
            if k.float && k.levels.len() == 1 {
                f.push("exr".into());
            }
            f
        });
        assert!(k.header.supercompression_scheme.is_none(), "{file} ({spec}): the KTX2 the runtime reads is uncompressed");
        if formats.iter().any(|f| f == "ktx2-zstd") {
            let z = read_ktx2(&std::fs::read(data.join(format!("{stem}.zstd.ktx2"))).expect("the zstd KTX2 asked for"));
            assert_eq!(z.header.supercompression_scheme, Some(ktx2::SupercompressionScheme::Zstandard), "{stem}.zstd.ktx2");
            assert!(z.levels == k.levels, "{stem}.zstd.ktx2 inflates to other texels than {file}");
        } else {
            assert!(!names.contains(&format!("{stem}.zstd.ktx2")), "{stem}.zstd.ktx2 not asked for");
        }
        for (ext, want) in [("dds", formats.iter().any(|f| f == "dds")), ("exr", formats.iter().any(|f| f == "exr"))] {
            assert_eq!(names.contains(&format!("{stem}.{ext}")), want, "{file} ({spec}): {stem}.{ext} {}", if want { "missing" } else { "not asked for" });
        }
        if formats.iter().any(|f| f == "dds") {
            let dds = ddsfile::Dds::read(&std::fs::read(data.join(format!("{stem}.dds"))).unwrap()[..]).expect("ddsfile reads it");
            let h = &k.header;
            assert_eq!((dds.get_width(), dds.get_height()), (h.pixel_width, h.pixel_height), "{stem}.dds size");
            assert_eq!(dds.get_depth(), h.pixel_depth.max(1), "{stem}.dds depth");
            assert_eq!(dds.get_num_mipmap_levels(), h.level_count.max(1), "{stem}.dds levels");
            assert_eq!(dds.get_dxgi_format(), Some(dxgi_of(h.format.unwrap().value())), "{stem}.dds format");
            let h10 = dds.header10.as_ref().expect("a DX10 header");
            let dim = if h.pixel_depth > 0 { ddsfile::D3D10ResourceDimension::Texture3D } else { ddsfile::D3D10ResourceDimension::Texture2D };
            assert_eq!((h10.resource_dimension, h10.array_size), (dim, 1), "{stem}.dds");
            assert!(dds.data == k.levels.concat(), "{stem}.dds: texel bytes differ from the KTX2's");
        }
        textures += 1;
    }
    assert!(textures >= 20, "the committed tables: {textures} KTX2 files");
    // No DDS, EXR or zstd KTX2 without its KTX2.
    for n in names.iter().filter(|n| n.ends_with(".dds") || n.ends_with(".exr") || n.ends_with(".zstd.ktx2")) {
        let stem = n.strip_suffix(".zstd.ktx2").unwrap_or_else(|| n.rsplit_once('.').unwrap().0);
        assert!(names.contains(&format!("{stem}.ktx2")), "{n} has no KTX2 beside it");
    }
}

/// bevy's `dfg.ktx2` (tests/data/bevy): DFD, 60 bytes at 104 (its header gives offset and
/// length); the level index at 80.
fn dfd(bytes: &[u8]) -> &[u8] {
    let at = u32::from_le_bytes(bytes[48..52].try_into().unwrap()) as usize;
    let len = u32::from_le_bytes(bytes[52..56].try_into().unwrap()) as usize;
    &bytes[at..at + len]
}

#[test]
fn the_bevy_layout_lut_has_bevys_header_and_close_texels() {
    let ours_bytes = std::fs::read(root().join("generated/data/ggx_dfg_lut_bevy.zstd.ktx2")).unwrap();
    let bevy_bytes = std::fs::read(root().join("tests/data/bevy/dfg.ktx2")).unwrap();
    let (ours, bevy) = (read_ktx2(&ours_bytes), read_ktx2(&bevy_bytes));
    let fields = |h: &ktx2::Header| {
        (h.format.map(|f| f.value()), h.type_size, h.pixel_width, h.pixel_height, h.pixel_depth, h.layer_count, h.face_count, h.level_count, h.supercompression_scheme)
    };
    assert_eq!(fields(&ours.header), fields(&bevy.header));
    assert_eq!(fields(&bevy.header), (Some(83), 2, 64, 64, 0, 0, 1, 1, Some(ktx2::SupercompressionScheme::Zstandard)), "bevy's file as its README describes it");
    assert_eq!(dfd(&ours_bytes), dfd(&bevy_bytes), "the data format descriptor (RGBSDA, BT.709, linear, two float16 samples)");
    // Texel by texel: R = scale, G = bias at the same texel centres (tests/python/
    // test_table_formats.py checks this file's texels against an independent quadrature).
    // From n·v ≥ 16.5/64 the two agree to one f16 step (each side rounds by ≤ half of
    // 2⁻¹¹ for values in [0.5, 1)). Nearer grazing bevy's scale channel falls below the
    // integral: by 6.3e-3 at n·v = 0.5/64 (r = 14.5/64), 2.2e-3 at 4.5/64, 1e-3 at 8.5/64, its
    // bias channel by at most one f16 step; the bounds are those measured, rounded up.
    let texels = |l: &[u8]| l.chunks(2).map(|b| half::f16::from_le_bytes([b[0], b[1]]).to_f32()).collect::<Vec<f32>>();
    let (a, b) = (texels(&ours.levels[0]), texels(&bevy.levels[0]));
    let mut worst = [[0.0f32; 2]; 2]; // [n·v < 16.5/64, beyond][scale, bias]
    for (k, (x, y)) in a.iter().zip(&b).enumerate() {
        let (column, channel) = ((k / 2) % 64, k % 2);
        let w = &mut worst[usize::from(column >= 16)][channel];
        *w = w.max((x - y).abs());
    }
    eprintln!("ggx_dfg_lut_bevy vs bevy's dfg.ktx2, max |Δ| [scale, bias]: n·v < 16.5/64 {:?}, beyond {:?}", worst[0], worst[1]);
    let step = 2f32.powi(-11);
    assert!(worst[1][0] <= step && worst[1][1] <= step, "beyond grazing: {:?}", worst[1]);
    assert!(worst[0][0] <= 6.5e-3 && worst[0][1] <= step, "near grazing: {:?}", worst[0]);
}

fn set_formats(d: &Path, spec: &str, line: &str) -> String {
    let p = d.join(format!("fits/{spec}.toml"));
    let text = std::fs::read_to_string(&p).unwrap();
    let kept: Vec<&str> = text.lines().filter(|l| !l.starts_with("formats =")).collect();
    let text = kept.join("\n").replace("[emit]\n", &format!("[emit]\n{line}\n"));
    std::fs::write(&p, &text).unwrap();
    text
}

#[test]
fn a_formats_list_picks_the_files_and_bad_lists_are_bad_input() {
    // `gloss_table` (a one-channel R32F table): the KTX2 (always) and the EXR.
    let d = scratch();
    set_formats(d.path(), "gloss_table", "formats = [\"exr\"]");
    let o = shadefit(&["build", "--only", "gloss_table"], Some(d.path()));
    assert!(o.status.success(), "{}", stderr(&o));
    let g = d.path().join("generated/data");
    assert!(g.join("gloss_table.ktx2").exists() && g.join("gloss_table.exr").exists());
    assert!(!g.join("gloss_table.dds").exists(), "dds was not asked for");
    let o = shadefit(&["build", "--check", "--only", "gloss_table"], Some(d.path()));
    assert!(o.status.success(), "{}", stderr(&o));

    for (spec, line, why) in [
        ("gloss_table", "formats = [\"ktx2\", \"png\"]", "unknown table format 'png'"),
        ("gloss_table", "formats = [\"dds\", \"exr\", \"dds\"]", "listed twice"),
        // A fit writes no texture.
        ("gloss_length", "formats = [\"ktx2\"]", "writes no texture"),
    ] {
        let d = scratch();
        let text = set_formats(d.path(), spec, line);
        let o = shadefit(&["build", "--only", spec], Some(d.path()));
        assert_eq!(o.status.code(), Some(2), "{line}: {}", stderr(&o));
        let e = stderr(&o);
        let n = text.lines().position(|l| l.starts_with("formats =")).unwrap() + 1;
        assert!(e.contains(&format!("{spec}.toml:{n}")) && e.contains("formats") && e.contains(why), "{line}: {e}");
        assert_nothing_written(d.path());
    }
}

/// node on PATH; missing, a note (a failure under CI=true, where the test command installs it).
fn node() -> Option<std::path::PathBuf> {
    let found = std::env::var_os("PATH").and_then(|p| std::env::split_paths(&p).map(|d| d.join("node")).find(|p| p.is_file()));
    if found.is_none() {
        assert!(!std::env::var("CI").is_ok_and(|v| v == "true"), "node is not installed (bash scripts/setup-ktx-loaders installs it)");
        eprintln!("note: node is not installed; skipping the JavaScript form's check");
    }
    found
}

/// Level 0's bytes as lowercase hex.
fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

#[test]
fn the_c_and_js_forms_hold_the_ktx2_texels() {
    // A 32F (gloss_table, R32F) and a 16F table (gloss_combine_lut, R16F) in the C and
    // JavaScript forms, read as a C compiler and node read them: the array's bytes (x86 and
    // node's typed arrays are little-endian, as KTX2 is) are the KTX2 level's bytes.
    let d = scratch();
    for spec in ["gloss_table", "gloss_combine_lut"] {
        set_formats(d.path(), spec, "formats = [\"ktx2\", \"c\", \"js\"]");
    }
    let o = shadefit(&["build", "--only", "gloss_table,gloss_combine_lut"], Some(d.path()));
    assert!(o.status.success(), "{}", stderr(&o));
    let data = d.path().join("generated/data");
    let node = node();
    for name in ["gloss_table", "gloss_combine_lut"] {
        let k = read_ktx2(&std::fs::read(data.join(format!("{name}.ktx2"))).unwrap());
        assert!(!data.join(format!("{name}.dds")).exists(), "{name}: dds was not asked for");
        let up = name.to_uppercase();
        let (w, h) = (k.header.pixel_width, k.header.pixel_height);
        let c = d.path().join(format!("{name}_dump.c"));
        std::fs::write(
            &c,
            format!(
                "#include <stdio.h>\n#include \"{name}.h\"\nint main(void) {{\n    const unsigned char *p = (const unsigned char *){up}_DATA;\n    \
                 for (unsigned long i = 0; i < sizeof {up}_DATA; i++) printf(\"%02x\", p[i]);\n    \
                 printf(\" %d %d %d %d\\n\", {up}_WIDTH, {up}_HEIGHT, {up}_DEPTH, {up}_CHANNELS);\n    return 0;\n}}\n"
            ),
        )
        .unwrap();
        let exe = d.path().join(format!("{name}_dump"));
        let cc = std::process::Command::new("cc").args(["-std=c99", "-Wall", "-Werror", "-I"]).arg(&data).arg("-o").arg(&exe).arg(&c).output().unwrap();
        assert!(cc.status.success(), "{name}.h: {}", String::from_utf8_lossy(&cc.stderr));
        let out = String::from_utf8(std::process::Command::new(&exe).output().unwrap().stdout).unwrap();
        assert_eq!(out.trim_end(), format!("{} {w} {h} 0 1", hex(&k.levels[0])), "{name}.h");
        if let Some(node) = &node {
            let js = data.join(format!("{name}.js"));
            let script = format!(
                "import {{ {up} as t }} from {:?}; process.stdout.write(Buffer.from(t.data.buffer).toString('hex') + ` ${{t.width}} ${{t.height}} ${{t.depth}} ${{t.channels}}`);",
                format!("file://{}", js.display())
            );
            let o = std::process::Command::new(node).args(["--input-type=module", "-e", &script]).output().unwrap();
            assert!(o.status.success(), "{name}.js: {}", String::from_utf8_lossy(&o.stderr));
            assert_eq!(String::from_utf8(o.stdout).unwrap(), format!("{} {w} {h} 0 1", hex(&k.levels[0])), "{name}.js");
        }
    }
}
