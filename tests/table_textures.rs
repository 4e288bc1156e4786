//! The texture form of `kind = "table"` specs (`[emit] form`, `texture_format`,
//! `float32_filterable`):
//! - every committed table KTX2 (`generated/data/NAME.ktx2`) reads back through the `ktx2` crate
//!   (an independent parser) as a one-channel R32F or R16F image of the table's shape whose
//!   texels are the committed JSON values: R32F bit for bit as f32, R16F within binary16 rounding
//!   to nearest;
//! - a scratch build of each form: `texture` drops the const array, `both` keeps it; the WGSL
//!   validates with naga; the linear-sampler helper is emitted for r16float and for r32float only
//!   with `float32_filterable = true`;
//! - misplaced options are bad input (exit 2, file, line and field; nothing written).

mod common;

use common::{assert_nothing_written, root, scratch, shadefit, stderr};
use std::path::Path;

/// The committed table specs that ask for a texture (name, json).
fn texture_tables() -> Vec<(String, serde_json::Value)> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(root().join("fits")).unwrap() {
        let p = e.unwrap().path();
        let text = std::fs::read_to_string(&p).unwrap_or_default();
        if p.extension().is_some_and(|x| x == "toml") && text.contains("kind = \"table\"") && text.contains("\nform = \"") {
            let name = p.file_stem().unwrap().to_string_lossy().into_owned();
            let json = std::fs::read_to_string(root().join(format!("generated/json/{name}.json"))).unwrap();
            out.push((name, serde_json::from_str(&json).unwrap()));
        }
    }
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

/// The texels of a one-channel KTX2 file through the `ktx2` crate: (vkFormat, width, height, values).
fn read_ktx2(bytes: &[u8]) -> (u32, u32, u32, Vec<f32>) {
    let r = ktx2::Reader::new(bytes).expect("a valid KTX2 file");
    let h = r.header();
    assert_eq!((h.pixel_depth, h.layer_count, h.face_count, h.level_count), (0, 0, 1, 1));
    assert!(h.supercompression_scheme.is_none());
    let basic = r.basic_dfd().expect("a basic DFD block");
    assert_eq!(basic.sample_information.len(), 1, "one channel");
    let vk = h.format.expect("a VkFormat").value();
    let data = r.levels().next().unwrap().data;
    let values = match vk {
        // VK_FORMAT_R32_SFLOAT and VK_FORMAT_R16_SFLOAT (Vulkan specification).
        100 => data.chunks(4).map(|b| f32::from_le_bytes(b.try_into().unwrap())).collect(),
        76 => data.chunks(2).map(|b| half::f16::from_le_bytes([b[0], b[1]]).to_f32()).collect(),
        other => panic!("VkFormat {other} is not R32_SFLOAT or R16_SFLOAT"),
    };
    (vk, h.pixel_width, h.pixel_height, values)
}

/// |stored − v| for round to nearest binary16: half an ulp, 2⁻¹¹·|v| for normal halves
/// (|v| ≥ 2⁻¹⁴), 2⁻²⁵ (half the subnormal spacing 2⁻²⁴) below.
fn f16_bound(v: f32) -> f32 {
    (v.abs() * 2f32.powi(-11)).max(2f32.powi(-25))
}

#[test]
fn committed_table_textures_hold_the_json_values() {
    let tables = texture_tables();
    assert!(tables.len() >= 5, "the five table specs emit a texture: {}", tables.len());
    for (name, json) in tables {
        let bytes = std::fs::read(root().join(format!("generated/data/{name}.ktx2"))).unwrap();
        let (vk, w, h, texels) = read_ktx2(&bytes);
        let counts: Vec<u32> = json["axes"].as_array().unwrap().iter().map(|a| a["count"].as_u64().unwrap() as u32).collect();
        assert_eq!((w, h), (counts[0], counts.get(1).copied().unwrap_or(1)), "{name}");
        let values: Vec<f64> = json["values"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
        assert_eq!(texels.len(), values.len(), "{name}");
        let wgsl = std::fs::read_to_string(root().join(format!("generated/wgsl/{name}.wgsl"))).unwrap();
        let format = if vk == 100 { "r32float" } else { "r16float" };
        assert!(wgsl.contains(&format!("{format} texture storage")), "{name}: the header names {format}");
        for (k, (&t, &v)) in texels.iter().zip(&values).enumerate() {
            let v = v as f32;
            if vk == 100 {
                assert_eq!(t.to_bits(), v.to_bits(), "{name} texel {k}");
            } else {
                assert!((t - v).abs() <= f16_bound(v), "{name} texel {k}: {t} vs {v}");
            }
        }
        // A linear sampler never meets an R32F texture unless the spec promised the feature.
        let sample = wgsl.contains("_sample(lut: texture_2d<f32>, lut_sampler: sampler");
        assert_eq!(sample, vk == 76 || wgsl.contains("float32-filterable"), "{name}");
    }
}

fn set_emit(d: &Path, spec: &str, lines: &str) -> String {
    let p = d.join(format!("fits/{spec}.toml"));
    let text = std::fs::read_to_string(&p).unwrap();
    // Drop the committed form lines, then add `lines` after [emit].
    let kept: Vec<&str> = text.lines().filter(|l| !l.starts_with("form =") && !l.starts_with("texture_format =")).collect();
    let text = kept.join("\n").replace("[emit]\n", &format!("[emit]\n{lines}"));
    std::fs::write(&p, &text).unwrap();
    text
}

fn naga_validates(src: &str) {
    let plain: String = src.lines().filter(|l| !l.starts_with('#')).collect::<Vec<_>>().join("\n");
    let m = naga::front::wgsl::parse_str(&plain).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&plain)));
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all()).validate(&m).unwrap();
}

#[test]
fn each_form_builds_and_validates() {
    for (lines, has_const, sample, vk) in [
        ("form = \"texture\"\n", false, false, 100),
        ("form = \"both\"\ntexture_format = \"r16float\"\n", true, true, 76),
        ("form = \"texture\"\nfloat32_filterable = true\n", false, true, 100),
        ("form = \"const\"\n", true, false, 0),
    ] {
        let d = scratch();
        set_emit(d.path(), "gloss_table", lines);
        let o = shadefit(&["build", "--only", "gloss_table"], Some(d.path()));
        assert!(o.status.success(), "{lines}: {}", stderr(&o));
        let g = d.path().join("generated");
        let wgsl = std::fs::read_to_string(g.join("wgsl/gloss_table.wgsl")).unwrap();
        naga_validates(&wgsl);
        assert_eq!(wgsl.contains("const GLOSS_TABLE_TABLE"), has_const, "{lines}");
        assert_eq!(wgsl.contains("fn gloss_to_normal_length_lut("), has_const, "{lines}");
        assert_eq!(wgsl.contains("fn gloss_to_normal_length_lut_load(lut: texture_2d<f32>, gloss: f32)"), vk != 0, "{lines}");
        assert_eq!(wgsl.contains("fn gloss_to_normal_length_lut_sample("), sample, "{lines}");
        // The runtime index lists the scalar WGSL function for GPU verification only where it exists.
        let index = std::fs::read_to_string(g.join("src/emitted.rs")).unwrap();
        assert_eq!(index.contains("name: \"gloss_to_normal_length_lut\""), has_const, "{lines}");
        let ktx2 = std::fs::read(g.join("data/gloss_table.ktx2"));
        assert_eq!(ktx2.is_ok(), vk != 0, "{lines}");
        if let Ok(bytes) = ktx2 {
            let (got, w, h, texels) = read_ktx2(&bytes);
            assert_eq!((got, w, h), (vk, 256, 1), "{lines}");
            let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(g.join("json/gloss_table.json")).unwrap()).unwrap();
            for (t, v) in texels.iter().zip(json["values"].as_array().unwrap()) {
                let v = v.as_f64().unwrap() as f32;
                assert!((t - v).abs() <= if vk == 76 { f16_bound(v) } else { 0.0 }, "{lines}: {t} vs {v}");
            }
            let rust = std::fs::read_to_string(g.join("src/gloss_table.rs")).unwrap();
            assert!(rust.contains("pub const GLOSS_TABLE_KTX2: &[u8] = include_bytes!(\"../data/gloss_table.ktx2\");"), "{lines}");
        }
        // The build's own check holds on what it wrote.
        let o = shadefit(&["build", "--check", "--only", "gloss_table"], Some(d.path()));
        assert!(o.status.success(), "{lines}: {}", stderr(&o));
    }
}

#[test]
fn misplaced_texture_options_are_bad_input() {
    for (spec, lines, field) in [
        ("gloss_length", "form = \"texture\"\n", "form"),
        ("gloss_table", "texture_format = \"r16float\"\n", "texture_format"),
        ("gloss_table", "form = \"both\"\ntexture_format = \"r16float\"\nfloat32_filterable = true\n", "float32_filterable"),
        ("gloss_table", "form = \"const\"\nfloat32_filterable = true\n", "float32_filterable"),
        ("gloss_table", "form = \"atlas\"\n", "form"),
    ] {
        let d = scratch();
        let text = set_emit(d.path(), spec, lines);
        let o = shadefit(&["build", "--only", spec], Some(d.path()));
        assert_eq!(o.status.code(), Some(2), "{lines}: {}", stderr(&o));
        let e = stderr(&o);
        let line = text.lines().position(|l| l.starts_with(&format!("{field} ="))).unwrap() + 1;
        assert!(e.contains(&format!("{spec}.toml:{line}")) && e.contains(field), "{lines}: {e}");
        assert_nothing_written(d.path());
    }
}
