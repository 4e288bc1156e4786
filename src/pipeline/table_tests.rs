//! The `table` kind beyond one value at the nodes of one or two axes, on quantities with closed
//! forms registered here: several channels, three axes, texel-centre placement, argument
//! mappings and the texture formats of their channels. Every claim is re-measured from the
//! written files against the closed forms.

use super::*;
use crate::integrate::Estimate;
use crate::quantity::{ParamSpec, QuantityDef};
use crate::spec::Catalog;

/// u = 1 + 2x − y + z/2 + xyz/4 (multilinear), v = 3 − xz (multilinear), w = x² (not).
fn tri(p: &[f64]) -> [f64; 3] {
    let (x, y, z) = (p[0], p[1], p[2]);
    [1.0 + 2.0 * x - y + 0.5 * z + 0.25 * x * y * z, 3.0 - x * z, x * x]
}

static TRI: QuantityDef = QuantityDef {
    name: "tri-closed",
    doc: "three closed forms over (x, y, z): two multilinear, one quadratic",
    params: &[
        ParamSpec { name: "x", min: 0.0, max: 2.0, doc: "first", integer: false, limit: None, default: None },
        ParamSpec { name: "y", min: -1.0, max: 1.0, doc: "second", integer: false, limit: None, default: Some(0.0) },
        ParamSpec { name: "z", min: 0.0, max: 1.0, doc: "third", integer: false, limit: None, default: Some(0.0) },
    ],
    aliases: &[],
    eval: &|p, _| Estimate { value: tri(p)[0], error: 0.0, evals: 1 },
    inverse: None,
    channels: &["u", "v", "w"],
    eval_channels: Some(&|p, _| tri(p).iter().map(|&value| Estimate { value, error: 0.0, evals: 1 }).collect()),
    basis: None,
};

/// The parameter itself (a scalar on [0, 1]): a table of it shows where its points were put.
static IDENT: QuantityDef = QuantityDef {
    name: "ident-closed",
    doc: "its parameter",
    params: &[ParamSpec { name: "a", min: 0.0, max: 1.0, doc: "the value", integer: false, limit: None, default: None }],
    aliases: &[],
    eval: &|p, _| Estimate { value: p[0], error: 0.0, evals: 1 },
    inverse: None,
    channels: &[],
    eval_channels: None,
    basis: None,
};

fn catalog() -> Catalog {
    Catalog { quantities: vec![&TRI, &IDENT], ..Catalog::default() }
}

fn parse(text: &str) -> Result<Spec, crate::spec::SpecError> {
    let name = text.split('"').nth(1).unwrap();
    Spec::parse(Path::new(&format!("fits/{name}.toml")), text.to_string(), &catalog())
}

fn built(text: &str) -> Built {
    build_spec(&parse(text).unwrap(), Mode::Fit, Path::new(""), &|_| None).unwrap()
}

fn file<'a>(b: &'a Built, path: &str) -> &'a [u8] {
    &b.artifacts.iter().find(|a| a.path == Path::new(path)).unwrap_or_else(|| panic!("no {path}")).contents
}

fn text<'a>(b: &'a Built, path: &str) -> &'a str {
    std::str::from_utf8(file(b, path)).unwrap()
}

fn json_of(b: &Built) -> Value {
    serde_json::from_slice(file(b, &format!("json/{}.json", b.name))).unwrap()
}

/// naga parses and validates a module (its directive stripped) and names these functions.
fn validates(src: &str, functions: &[&str]) {
    let plain = wgsl::strip_directives(src);
    let m = naga::front::wgsl::parse_str(&plain).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&plain)));
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
        .validate(&m)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&plain)));
    let names: Vec<&str> = m.functions.iter().filter_map(|(_, f)| f.name.as_deref()).collect();
    assert_eq!(names, functions, "{src}");
}

/// A KTX2 file through the `ktx2` crate: (vkFormat, width, height, depth, DFD samples, values).
fn read_ktx2(bytes: &[u8]) -> (u32, u32, u32, u32, usize, Vec<f32>) {
    let r = ktx2::Reader::new(bytes).expect("a valid KTX2 file");
    let h = r.header();
    let samples = r.basic_dfd().expect("a basic DFD block").sample_information.len();
    let vk = h.format.expect("a VkFormat").value();
    let data = r.levels().next().unwrap().data;
    let values = match vk {
        // R16_SFLOAT, R16G16_SFLOAT, R16G16B16A16_SFLOAT; R32_SFLOAT, R32G32_SFLOAT,
        // R32G32B32A32_SFLOAT (the Vulkan specification's enumerants).
        76 | 83 | 97 => data.chunks(2).map(|b| half::f16::from_le_bytes([b[0], b[1]]).to_f32()).collect(),
        100 | 103 | 109 => data.chunks(4).map(|b| f32::from_le_bytes(b.try_into().unwrap())).collect(),
        other => panic!("VkFormat {other} is not a float format of the tables"),
    };
    (vk, h.pixel_width, h.pixel_height, h.pixel_depth, samples, values)
}

const TRILINEAR: &str = r#"
name = "tri_lut"
kind = "table"
quantity = "tri-closed"
channels = ["v", "u"]
description = "Two multilinear channels over three axes"

[[axis]]
name = "x"
range = [0.0, 2.0]
count = 5
verify = 9

[[axis]]
name = "y"
placement = "centres"
range = [-1.0, 1.0]
count = 4
verify = 9

[[axis]]
name = "z"
range = [0.0, 1.0]
count = 3
verify = 5

[emit]
function = "tri_lut"
form = "both"
texture_format = "rg32float"
"#;

/// Two channels of a quantity (in the spec's order, v before u) over three axes, the second at
/// texel centres: the JSON's values are the closed forms at the nodes and centres; the emitted
/// f32 lookup reproduces both multilinear channels between the centres (exact up to f32
/// rounding) and holds the edge texels outside them, so the claimed max error is that hold at
/// y = ±1, worked out by hand; the committed JSON read back renders every file again; the RG32F
/// 3-D texture holds texel (i, j, k) channel c at ((k·4 + j)·5 + i)·2 + c; the WGSL validates.
#[test]
fn a_three_axis_table_of_two_channels_is_exact_between_its_centres() {
    let b = built(TRILINEAR);
    let j = json_of(&b);
    assert_eq!(j["channels"], serde_json::json!(["v", "u"]));
    assert!(j.get("channel").is_none());
    assert_eq!(j["axes"][1]["placement"], "centres");
    assert!(j["axes"][0].get("placement").is_none() && j["axes"][1].get("mapping").is_none());
    let values: Vec<[f64; 2]> = j["values"].as_array().unwrap().iter().map(|p| [p[0].as_f64().unwrap(), p[1].as_f64().unwrap()]).collect();
    assert_eq!(values.len(), 5 * 4 * 3);
    let (xs, ys, zs) = ([0.0, 0.5, 1.0, 1.5, 2.0], [-0.75, -0.25, 0.25, 0.75], [0.0, 0.5, 1.0]);
    for (n, v) in values.iter().enumerate() {
        let (x, y, z) = (xs[n % 5], ys[(n / 5) % 4], zs[n / 20]);
        let want = tri(&[x, y, z]);
        // The points are exact in binary and so are the closed forms there (sums of dyadic
        // numbers): equal.
        assert_eq!(*v, [want[1], want[0]], "point {n} at ({x}, {y}, {z})");
    }
    // Between the centres (|y| ≤ 0.75) the lookup of the f32 texels is the multilinear
    // function itself: values ≤ 8 carry the texels' f32 rounding (≤ 2^-21 each, weights summing
    // to 1) and three lerps of three roundings each (≤ 9 · 2^-21 through weights ≤ 1): 1e-5.
    let v32: Vec<f32> = values.iter().flat_map(|v| v.map(|x| x as f32)).collect();
    let domain = [(0.0f32, 2.0f32), (-1.0, 1.0), (0.0, 1.0)];
    let placements = [emit::interp::Placement::Nodes, emit::interp::Placement::Centres, emit::interp::Placement::Nodes];
    let mut rng = crate::integrate::rng::SplitMix64(7);
    for _ in 0..500 {
        let p = [2.0 * rng.next_f64(), -0.75 + 1.5 * rng.next_f64(), rng.next_f64()].map(|v| v as f32 as f64);
        let got = rust::table_lookup_f32(&v32, 2, &[5, 4, 3], &domain, &placements, &p.map(|v| v as f32));
        let want = tri(&p);
        for (c, w) in [(0, want[1]), (1, want[0])] {
            assert!((got[c] as f64 - w).abs() < 1e-5, "{p:?} channel {c}: {} vs {w}", got[c]);
        }
    }
    // Outside them the edge texel: below y = −0.75, u is held at its value there; u(y) −
    // u(−0.75) = (y + 0.75)·(−1 + xz/4), largest where xz = 0. The verification grid along y is
    // at the centres of 9 cells, the outermost at y = ±8/9, and has such (x, z) (x, z at nodes,
    // where both channels are exact; v does not depend on y): max 8/9 − 3/4 = 5/36 up to the
    // 1e-5 above.
    let ver = &j["verification"];
    let max = ver["max_abs_error_f32"].as_f64().unwrap();
    assert!((max - 5.0 / 36.0).abs() < 1e-5, "{max}");
    assert_eq!(ver["points"], 9 * 9 * 5);
    assert!((ver["worst_point"][1].as_f64().unwrap().abs() - 8.0 / 9.0).abs() < 1e-15);
    // Read back: the committed JSON alone renders the same files.
    let tmp = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(tmp.path().join("json")).unwrap();
    std::fs::write(tmp.path().join("json/tri_lut.json"), file(&b, "json/tri_lut.json")).unwrap();
    let again = build_spec(&parse(TRILINEAR).unwrap(), Mode::Committed, tmp.path(), &|_| None).unwrap();
    assert_eq!(again.artifacts, b.artifacts);
    // The texture: RG32F (VkFormat 103), 5 × 4 × 3, two DFD samples, the f32 values in order.
    let (vk, w, h, d, samples, texels) = read_ktx2(file(&b, "data/tri_lut.ktx2"));
    assert_eq!((vk, w, h, d, samples), (103, 5, 4, 3, 2));
    assert_eq!(texels.iter().map(|t| t.to_bits()).collect::<Vec<_>>(), v32.iter().map(|t| t.to_bits()).collect::<Vec<_>>());
    // The code: vec2<f32> / [f32; 2], a 3-D texture read by textureLoad, no sampler for RG32F.
    let wgsl = text(&b, "wgsl/tri_lut.wgsl");
    validates(wgsl, &["tri_lut_input", "tri_lut", "tri_lut_load"]);
    assert!(wgsl.contains("fn tri_lut(x: f32, y: f32, z: f32) -> vec2<f32>"), "{wgsl}");
    assert!(wgsl.contains("fn tri_lut_load(lut: texture_3d<f32>, x: f32, y: f32, z: f32) -> vec2<f32>"), "{wgsl}");
    assert!(text(&b, "src/tri_lut.rs").contains("pub fn tri_lut(x: f32, y: f32, z: f32) -> [f32; 2]"));
    assert!(text(&b, "data/tri_lut.csv").contains("\nx,y,z,v,u\n"));
    // Not a scalar function of the runtime's GPU check list.
    let index = runtime_index(&[parse(TRILINEAR).unwrap()]);
    assert!(!String::from_utf8(index.contents).unwrap().contains("name: \"tri_lut\""));
}

const MAPPED: &str = r#"
name = "ident_lut"
kind = "table"
quantity = "ident-closed"
description = "a over perceptual roughness r at texel centres"

[[axis]]
name = "a"
mapping = "perceptual"
placement = "centres"
range = [0.0, 1.0]
count = 9
verify = 37

[emit]
function = "ident_lut"
args = ["r"]
form = "both"
texture_format = "r16float"
"#;

/// An axis mapped from perceptual roughness (a = r²) at texel centres: the table holds a at
/// r_i = (i + ½)/9, i.e. r_i²; the lookup interpolates in r, so its largest error is where it
/// holds the edge texel, at r = 1: 1 − (17/18)²; the JSON names the mapping and the
/// parameter's range; the R16F texture holds each value rounded to a half.
#[test]
fn a_mapped_axis_tabulates_the_parameter_at_the_mapped_points() {
    let b = built(MAPPED);
    let j = json_of(&b);
    let values: Vec<f64> = j["values"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    for (i, v) in values.iter().enumerate() {
        let r = (i as f64 + 0.5) / 9.0;
        assert_eq!(*v, r * r, "centre {i}");
    }
    let axis = &j["axes"][0];
    assert_eq!((axis["mapping"].as_str(), axis["placement"].as_str()), (Some("perceptual"), Some("centres")));
    assert_eq!(axis["parameter_range"], serde_json::json!([0.0, 1.0]));
    // Inside the centres linear interpolation of r² errs by at most h²/4 = 1/324 ≈ 3.1e-3;
    // above the last centre the held value is (17/18)², and the outermost verification point
    // (the centre of the last of 37 cells) is r = 73/74: (73/74)² − (17/18)² ≈ 0.081. The f32
    // lookup adds rounding of values ≤ 1 (≤ 1e-6).
    let max = j["verification"]["max_abs_error_f32"].as_f64().unwrap();
    let edge = (73.0f64 / 74.0).powi(2) - (17.0f64 / 18.0).powi(2);
    assert!((max - edge).abs() < 1e-6, "{max} vs {edge}");
    assert!((j["verification"]["worst_point"][0].as_f64().unwrap() - 73.0 / 74.0).abs() < 1e-15);
    let (vk, w, h, d, samples, texels) = read_ktx2(file(&b, "data/ident_lut.ktx2"));
    assert_eq!((vk, w, h, d, samples), (76, 9, 1, 0, 1));
    for (t, v) in texels.iter().zip(&values) {
        assert_eq!(*t, half::f16::from_f32(*v as f32).to_f32());
    }
    // R16F is filterable: the sampler helpers come with it, in the argument r.
    validates(text(&b, "wgsl/ident_lut.wgsl"), &["ident_lut_input", "ident_lut", "ident_lut_load", "ident_lut_uv", "ident_lut_sample"]);
    assert!(text(&b, "wgsl/ident_lut.wgsl").contains("fn ident_lut(r: f32) -> f32"));
}

/// Three channels over one axis (y and z left at their defaults, 0): an RGBA16F texture of 5
/// texels, each [u, v, w] rounded to halves and alpha 1; the sampler helper returns the three
/// channels (`.xyz`) of a `texture_2d`.
#[test]
fn three_channels_fill_rgba_texels_with_alpha_one() {
    let spec = TRILINEAR
        .replace("channels = [\"v\", \"u\"]", "channels = [\"u\", \"v\", \"w\"]")
        .replace("texture_format = \"rg32float\"", "texture_format = \"rgba16float\"");
    let spec = format!("{}[emit]{}", &spec[..spec.find("\n[[axis]]\nname = \"y\"").unwrap()], spec.split("[emit]").nth(1).unwrap());
    let b = built(&spec);
    let (vk, w, h, d, samples, texels) = read_ktx2(file(&b, "data/tri_lut.ktx2"));
    assert_eq!((vk, w, h, d, samples), (97, 5, 1, 0, 4));
    for (i, t) in texels.chunks(4).enumerate() {
        let want = tri(&[0.5 * i as f64, 0.0, 0.0]).map(|v| half::f16::from_f32(v as f32).to_f32());
        assert_eq!(t, [want[0], want[1], want[2], 1.0], "texel {i}");
    }
    let wgsl = text(&b, "wgsl/tri_lut.wgsl");
    validates(wgsl, &["tri_lut_input", "tri_lut", "tri_lut_load", "tri_lut_uv", "tri_lut_sample"]);
    assert!(wgsl.contains("-> vec3<f32>") && wgsl.contains("0.0).xyz;"), "{wgsl}");
    // The quadratic channel w = x² interpolated linearly on nodes 0.5 apart: off by ≤ h²/4 =
    // 1/16 between them, which the verification (9 points, the midpoints among them) finds.
    let max = json_of(&b)["verification"]["max_abs_error_f32"].as_f64().unwrap();
    assert!((max - 0.0625).abs() < 1e-6, "{max}");
}

/// The table keys are checked, the error naming the line and field.
#[test]
fn bad_table_keys_are_refused_naming_the_field() {
    let bad = |text: String, field: &str, msg: &str| {
        let e = parse(&text).unwrap_err();
        assert_eq!(e.field, field, "{e}");
        assert!(e.msg.contains(msg), "{e}");
        assert_eq!(e.line, crate::spec::line_of(&text, field), "{e}");
    };
    let tri = |from: &str, to: &str| TRILINEAR.replace(from, to);
    let ident = |from: &str, to: &str| MAPPED.replace(from, to);
    bad(tri("[\"v\", \"u\"]", "[\"v\", \"q\"]"), "channels", "'q' is not a channel of 'tri-closed'");
    bad(tri("[\"v\", \"u\"]", "[\"v\", \"v\"]"), "channels", "'v' is given twice");
    bad(tri("channels = [\"v\", \"u\"]", "channels = [\"v\", \"u\"]\nchannel = \"u\""), "channels", "not both");
    bad(tri("texture_format = \"rg32float\"", "texture_format = \"r32float\""), "texture_format", "holds 1 channels a texel, the table 2");
    bad(ident("quantity = \"ident-closed\"", "quantity = \"ident-closed\"\nchannels = [\"u\"]"), "channels", "scalar quantity");
    bad(ident("\"perceptual\"", "\"cubic\""), "mapping", "unknown mapping 'cubic' (known: linear, perceptual, square, sqrt-one-minus)");
    // The square is monotone for t ≥ 0 only; r = 1.5 maps outside a ∈ [0, 1].
    bad(ident("range = [0.0, 1.0]", "range = [-0.5, 1.0]"), "range", "sampled inside [0, inf]");
    bad(ident("range = [0.0, 1.0]", "range = [0.0, 1.5]"), "range", "map inside [0, 1] (its outermost points");
    bad(ident("\"perceptual\"", "\"sqrt-one-minus\"").replace("range = [0.0, 1.0]", "range = [0.0, 1.25]"), "range", "inside [0, 1]");
    bad(ident("texture_format = \"r16float\"", "texture_format = \"rg16float\""), "texture_format", "holds 2 channels");
    let fit = "name = \"ident_fit\"\nkind = \"fit\"\nquantity = \"ident-closed\"\n\n[[axis]]\nname = \"a\"\nmapping = \"perceptual\"\nrange = [0.0, 1.0]\ncount = 8\n\n[model]\nnumerator = [\"1\", \"a\"]\n\n[fit]\nobjective = \"lsq\"\n\n[emit]\nfunction = \"ident_fit\"\nargs = [\"r\"]\n";
    bad(fit.to_string(), "mapping", "applies to kind = \"table\" only");
    bad(fit.replace("kind = \"fit\"", "kind = \"fit\"\nchannels = [\"u\"]").replace("mapping = \"perceptual\"\n", ""), "channels", "applies to kind = \"table\" only");
}

/// `order` stores the axes in another order than the quantity's parameters (first fastest,
/// the function's arguments in that order): y before x, point (j, i) at y_j, x_i; each axis
/// once, or the spec is refused.
#[test]
fn order_stores_the_axes_in_the_order_given() {
    let text = TRILINEAR.replace("channels = [\"v\", \"u\"]", "channels = [\"u\"]\norder = [\"y\", \"x\"]");
    let text = format!("{}[emit]{}", &text[..text.find("\n[[axis]]\nname = \"z\"").unwrap()], text.split("[emit]").nth(1).unwrap()).replace("rg32float", "r32float");
    let b = built(&text);
    let j = json_of(&b);
    let values: Vec<f64> = j["values"].as_array().unwrap().iter().map(|p| p.as_f64().unwrap()).collect();
    let (xs, ys) = ([0.0, 0.5, 1.0, 1.5, 2.0], [-0.75, -0.25, 0.25, 0.75]);
    assert_eq!(values.len(), 20);
    for (n, v) in values.iter().enumerate() {
        // z is left at its default, 0; the closed form at dyadic points is exact.
        assert_eq!(*v, tri(&[xs[n / 4], ys[n % 4], 0.0])[0], "point {n}");
    }
    assert_eq!((j["axes"][0]["name"].as_str(), j["axes"][1]["name"].as_str()), (Some("y"), Some("x")));
    assert!(text_of(&b).contains("fn tri_lut(y: f32, x: f32) -> f32"));
    let (vk, w, h, _, _, _) = read_ktx2(file(&b, "data/tri_lut.ktx2"));
    assert_eq!((vk, w, h), (100, 4, 5));
    let index = String::from_utf8(runtime_index(&[parse(&text).unwrap()]).contents).unwrap();
    assert!(index.contains("name: \"tri_lut\", domain: &[[-1e0, 1e0], [0e0, 2e0]]"), "{index}");
    for bad in ["[\"y\", \"y\"]", "[\"y\"]", "[\"y\", \"x\", \"z\"]"] {
        let e = parse(&text.replace("[\"y\", \"x\"]", bad)).unwrap_err();
        assert_eq!(e.field, "order", "{e}");
        assert!(e.msg.contains("needs each axis once: [x, y]"), "{e}");
    }
}

fn text_of(b: &Built) -> &str {
    text(b, &format!("wgsl/{}.wgsl", b.name))
}
