//! The skin LUT helpers on a GPU through wgpu, against their CPU versions:
//! - `skin_punctual_lut` (the const-array lookup) and `skin_sh_lut` equal the Rust functions
//!   within f32 rounding of the coordinate and the lerps (a GPU may fuse `a*b + c`);
//! - `skin_punctual_lut_sample` / `skin_sh_lut_sample` (the KTX2 texture uploaded by
//!   `skin::create_lut_texture`, read through `skin::lut_sampler` at `NAME_uv`) equal the
//!   const-array lookup within the texture's storage rounding plus the sampler's weight
//!   quantisation: a half-texel error in the uv mapping would move them by half a texel step,
//!   several times that bound where the LUT is steep;
//! - the `skin_curvature` functions equal theirs within a few f32 ulps.
//!
//! The const array of each library is moved to a storage buffer (same values, function bodies
//! unchanged) because a software adapter (lavapipe) copies a dynamically indexed `const` array
//! per access (see tests/gpu.rs). With no adapter the test is skipped, unless `CI` is set.

// Channel loops index several arrays.
#![allow(clippy::needless_range_loop)]

use shadefit_runtime::{compose, gpu, skin, skin_punctual_lut as punctual, skin_sh_lut as sh};
use wgpu::util::DeviceExt;

#[path = "support/harness.rs"]
mod harness;
use harness::report;

const WORKGROUP: usize = 64;

/// `library` with its `NAME_RGB` const array moved into a storage buffer at binding 3.
fn rgb_in_buffer(library: &str, module: &str) -> String {
    harness::const_array_in_buffer(library, &format!("{}_RGB", module.to_uppercase()), "vec3f")
}

struct Run<'a> {
    shader: String,
    inputs: Vec<f32>,
    arity: usize,
    outputs: usize,
    table: Option<&'a [[f32; 3]]>,
    texture: Option<&'a [u8]>,
}

fn run(g: &gpu::Gpu, label: &str, r: Run) -> Vec<f32> {
    let device = &g.device;
    let n = r.inputs.len() / r.arity;
    let padded = n.div_ceil(WORKGROUP) * WORKGROUP;
    let mut inputs = r.inputs.clone();
    inputs.resize(padded * r.arity, 0.0);
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(r.shader.into()),
    });
    let storage = gpu::storage_entry;
    let mut entries = vec![storage(0, true), storage(1, false)];
    if r.texture.is_some() {
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: 2,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: true },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        });
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: 4,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
            count: None,
        });
    }
    if r.table.is_some() {
        entries.push(storage(3, true));
    }
    let (bgl, pipeline) = gpu::compute_pipeline(device, label, &module, "main", &entries);
    let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("inputs"),
        contents: bytemuck::cast_slice(&inputs),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let size = (padded * r.outputs * 4) as u64;
    let (output, readback) = gpu::output_and_readback(device, size);
    let mut bind = vec![
        wgpu::BindGroupEntry { binding: 0, resource: input.as_entire_binding() },
        wgpu::BindGroupEntry { binding: 1, resource: output.as_entire_binding() },
    ];
    let table = r.table.map(|t| {
        let padded: Vec<[f32; 4]> = t.iter().map(|v| [v[0], v[1], v[2], 0.0]).collect();
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("table"),
            contents: bytemuck::cast_slice(&padded),
            usage: wgpu::BufferUsages::STORAGE,
        })
    });
    let texture = r.texture.map(|bytes| skin::create_lut_texture(device, &g.queue, label, bytes).expect("KTX2 texture"));
    let view = texture.as_ref().map(|t| t.create_view(&Default::default()));
    let sampler = skin::lut_sampler(device);
    if let Some(v) = &view {
        bind.push(wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(v) });
        bind.push(wgpu::BindGroupEntry { binding: 4, resource: wgpu::BindingResource::Sampler(&sampler) });
    }
    if let Some(b) = &table {
        bind.push(wgpu::BindGroupEntry { binding: 3, resource: b.as_entire_binding() });
    }
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(label), layout: &bgl, entries: &bind });
    let bytes = gpu::dispatch_and_read(g, label, &pipeline, &bind_group, (padded / WORKGROUP) as u32, &output, &readback);
    let out: Vec<f32> = bytemuck::pod_collect_to_vec(&bytes);
    out[..n * r.outputs].to_vec()
}

const BINDINGS: &str = "@group(0) @binding(0) var<storage, read> inp: array<f32>;\n\
    @group(0) @binding(1) var<storage, read_write> outp: array<f32>;\n";
const TEXTURE: &str = "@group(0) @binding(2) var lut: texture_2d<f32>;\n@group(0) @binding(4) var lut_sampler: sampler;\n";

/// Largest difference between neighbouring texels along either axis.
fn max_step(rgb: &[[f32; 3]], w: usize, h: usize) -> f32 {
    let mut m = 0.0f32;
    for y in 0..h {
        for x in 0..w {
            for c in 0..3 {
                let v = rgb[y * w + x][c];
                if x + 1 < w {
                    m = m.max((rgb[y * w + x + 1][c] - v).abs());
                }
                if y + 1 < h {
                    m = m.max((rgb[(y + 1) * w + x][c] - v).abs());
                }
            }
        }
    }
    m
}

/// Texture vs const-array bound: binary16 storage (≤ 2⁻¹¹·|v| for v ≤ 1, plus the subnormal
/// half-ulp 2⁻²⁵) and the bilinear weights quantised to the sub-texel precision Vulkan
/// guarantees (≥ 4 bits: each weight within 2⁻⁵, on each of the two axes, of a texel step).
fn texture_bound(step: f32) -> f32 {
    2f32.powi(-11) + 2f32.powi(-25) + 2.0 * 2f32.powi(-5) * step
}

#[test]
fn skin_luts_and_curvature_on_the_gpu() {
    let Some(g) = harness::device("shadefit skin test") else { return };

    // Punctual: a grid over and beyond the domain (clamps included).
    let kmax = punctual::SKIN_PUNCTUAL_LUT_CURVATURE_MAX;
    let [w, h] = punctual::SKIN_PUNCTUAL_LUT_SIZE.map(|v| v as usize);
    let mut pts = Vec::new();
    for a in 0..=300 {
        for b in 0..=90 {
            pts.extend([-1.05 + 2.1 * a as f32 / 300.0, kmax * (-0.1 + 1.2 * b as f32 / 90.0)]);
        }
    }
    let lib = rgb_in_buffer(&compose(&["skin_punctual_lut"]).unwrap(), "skin_punctual_lut");
    let shader = format!(
        "{lib}\n{BINDINGS}{TEXTURE}@compute @workgroup_size({WORKGROUP})\nfn main(@builtin(global_invocation_id) id: vec3<u32>) {{\n    \
         let i = id.x;\n    let nl = inp[2u * i];\n    let k = inp[2u * i + 1u];\n    \
         let a = skin_punctual_lut(nl, k);\n    let t = skin_punctual_lut_sample(lut, lut_sampler, nl, k);\n    \
         outp[6u * i] = a.x; outp[6u * i + 1u] = a.y; outp[6u * i + 2u] = a.z;\n    \
         outp[6u * i + 3u] = t.x; outp[6u * i + 4u] = t.y; outp[6u * i + 5u] = t.z;\n}}\n"
    );
    let out = run(&g, "skin_punctual_lut", Run {
        shader,
        inputs: pts.clone(),
        arity: 2,
        outputs: 6,
        table: Some(&punctual::SKIN_PUNCTUAL_LUT_RGB),
        texture: Some(punctual::SKIN_PUNCTUAL_LUT_KTX2),
    });
    let step = max_step(&punctual::SKIN_PUNCTUAL_LUT_RGB, w, h);
    // Const-array lookup: the coordinate (≤ 64) may differ by 2 ulps (2⁻¹⁶ texels) through a
    // fused multiply-add, moving the weights by that much of a texel step; the lerps' own
    // rounding is a few ulps of values ≤ 1 (6 × 2⁻²⁴).
    let const_bound = 2f32.powi(-16) * step + 6.0 * 2f32.powi(-24);
    let tex_bound = texture_bound(step);
    let (mut worst_const, mut worst_tex) = (0.0f32, 0.0f32);
    for (k, p) in pts.chunks(2).enumerate() {
        let cpu = punctual::skin_punctual_lut(p[0], p[1]);
        for c in 0..3 {
            let (a, t) = (out[6 * k + c], out[6 * k + 3 + c]);
            assert!(a.is_finite() && t.is_finite(), "{p:?}");
            worst_const = worst_const.max((a - cpu[c]).abs());
            worst_tex = worst_tex.max((t - cpu[c]).abs());
        }
    }
    report(&format!(
        "skin_punctual_lut {} points: const-array |GPU-CPU| max {worst_const:.3e} (bound {const_bound:.3e}); \
         texture |GPU-CPU| max {worst_tex:.3e} (bound {tex_bound:.3e}; texel step {step:.3e})",
        pts.len() / 2
    ));
    assert!(worst_const <= const_bound, "{worst_const} > {const_bound}");
    assert!(worst_tex <= tex_bound, "{worst_tex} > {tex_bound}");
    // A uv mapping off by half a texel would be caught: it moves a lookup by half a step.
    assert!(tex_bound < 0.5 * step, "bound {tex_bound} too loose for step {step}");

    // SH: every band, κ over and beyond the domain.
    let kmax = sh::SKIN_SH_LUT_CURVATURE_MAX;
    let [w, _] = sh::SKIN_SH_LUT_SIZE.map(|v| v as usize);
    let mut pts = Vec::new();
    for b in 0..=400 {
        for band in 0..4 {
            pts.extend([kmax * (-0.1 + 1.2 * b as f32 / 400.0), band as f32]);
        }
    }
    let lib = rgb_in_buffer(&compose(&["skin_sh_lut"]).unwrap(), "skin_sh_lut");
    let shader = format!(
        "{lib}\n{BINDINGS}{TEXTURE}@compute @workgroup_size({WORKGROUP})\nfn main(@builtin(global_invocation_id) id: vec3<u32>) {{\n    \
         let i = id.x;\n    let k = inp[2u * i];\n    let band = u32(inp[2u * i + 1u]);\n    \
         let a = skin_sh_lut(k, band);\n    let t = skin_sh_lut_sample(lut, lut_sampler, k, band);\n    \
         outp[6u * i] = a.x; outp[6u * i + 1u] = a.y; outp[6u * i + 2u] = a.z;\n    \
         outp[6u * i + 3u] = t.x; outp[6u * i + 4u] = t.y; outp[6u * i + 5u] = t.z;\n}}\n"
    );
    let out = run(&g, "skin_sh_lut", Run {
        shader,
        inputs: pts.clone(),
        arity: 2,
        outputs: 6,
        table: Some(&sh::SKIN_SH_LUT_RGB),
        texture: Some(sh::SKIN_SH_LUT_KTX2),
    });
    let step = max_step(&sh::SKIN_SH_LUT_RGB[..w], w, 1).max(max_step(&sh::SKIN_SH_LUT_RGB[w..], w, 1));
    let const_bound = 2f32.powi(-16) * step + 6.0 * 2f32.powi(-24);
    // One filtered axis here (rows are sampled at their centres): weights on one axis.
    let tex_bound = 2f32.powi(-11) + 2f32.powi(-25) + 2f32.powi(-5) * step;
    let (mut worst_const, mut worst_tex) = (0.0f32, 0.0f32);
    for (k, p) in pts.chunks(2).enumerate() {
        let cpu = sh::skin_sh_lut(p[0], p[1] as u32);
        for c in 0..3 {
            worst_const = worst_const.max((out[6 * k + c] - cpu[c]).abs());
            worst_tex = worst_tex.max((out[6 * k + 3 + c] - cpu[c]).abs());
        }
    }
    report(&format!(
        "skin_sh_lut {} points: const-array |GPU-CPU| max {worst_const:.3e} (bound {const_bound:.3e}); \
         texture |GPU-CPU| max {worst_tex:.3e} (bound {tex_bound:.3e})",
        pts.len() / 2
    ));
    assert!(worst_const <= const_bound, "{worst_const} > {const_bound}");
    assert!(worst_tex <= tex_bound, "{worst_tex} > {tex_bound}");

    // Curvature: random frames, tensors and lights (|n·l| ≤ 0.99, so |l_t|² ≥ 0.0199).
    let mut s = 0x2545_f491_4f6c_dd1du64;
    let mut rnd = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut inputs = Vec::new();
    for _ in 0..4096 {
        let phi = std::f64::consts::TAU * rnd();
        let t = [phi.cos(), phi.sin(), 0.0];
        let b = [-phi.sin(), phi.cos(), 0.0];
        let c = [2.0 * rnd() - 0.5, rnd() - 0.5, 2.0 * rnd() - 0.5];
        let (az, z) = (std::f64::consts::TAU * rnd(), 1.98 * rnd() - 0.99);
        let r = (1.0 - z * z).sqrt();
        let l = [r * az.cos(), r * az.sin(), z];
        inputs.extend(t.iter().chain(&b).chain(&c).chain(&l).map(|&v| v as f32));
    }
    let shader = format!(
        "{}\n{BINDINGS}@compute @workgroup_size({WORKGROUP})\nfn main(@builtin(global_invocation_id) id: vec3<u32>) {{\n    \
         let i = id.x;\n    let o = 12u * i;\n    \
         let t = vec3<f32>(inp[o], inp[o + 1u], inp[o + 2u]);\n    let b = vec3<f32>(inp[o + 3u], inp[o + 4u], inp[o + 5u]);\n    \
         let c = vec3<f32>(inp[o + 6u], inp[o + 7u], inp[o + 8u]);\n    let l = vec3<f32>(inp[o + 9u], inp[o + 10u], inp[o + 11u]);\n    \
         outp[2u * i] = skin_curvature_from_light(t, b, c, l);\n    outp[2u * i + 1u] = skin_curvature_from_light_normalized(t, b, c, l);\n}}\n",
        compose(&["skin_curvature"]).unwrap()
    );
    let out = run(&g, "skin_curvature", Run { shader, inputs: inputs.clone(), arity: 12, outputs: 2, table: None, texture: None });
    let mut worst = [0.0f32; 2];
    for (k, v) in inputs.chunks(12).enumerate() {
        let a = |o: usize| [v[o], v[o + 1], v[o + 2]];
        let (t, b, c, l) = (a(0), a(3), a(6), a(9));
        let scale = c[0].abs() + 2.0 * c[1].abs() + c[2].abs();
        let cpu = [skin::skin_curvature_from_light(t, b, c, l), skin::skin_curvature_from_light_normalized(t, b, c, l)];
        for j in 0..2 {
            let dev = (out[2 * k + j] - cpu[j]).abs() / scale;
            worst[j] = worst[j].max(dev);
        }
    }
    report(&format!("skin_curvature 4096 points: |GPU-CPU|/(|k_tt|+2|k_tb|+|k_bb|) max {:.3e}, normalised {:.3e}", worst[0], worst[1]));
    // Two dot products and a quadratic form of terms ≤ the scale: a few ulps each, fused or
    // not (8 × 2⁻²⁴); the normalised form divides by |l_t|² ≥ 0.0199 (×50) and the GPU's
    // division may be 2.5 ulp off.
    assert!(worst[0] <= 8.0 * 2f32.powi(-24), "{}", worst[0]);
    assert!(worst[1] <= 50.0 * 8.0 * 2f32.powi(-24) + 3.0 * 2f32.powi(-24) * 50.0, "{}", worst[1]);
}

/// A 1×1 RGBA32F KTX2 file as the skin LUT reader expects it (KTX 2.0 header, one level).
fn rgba32f_ktx2(texel: [f32; 4]) -> Vec<u8> {
    let mut b = vec![0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A];
    // vkFormat R32G32B32A32_SFLOAT, typeSize, 1×1, depth 0, layers 0, faces 1, levels 1, scheme 0.
    for v in [109u32, 4, 1, 1, 0, 0, 1, 1, 0] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.resize(80, 0); // index: no DFD, key/value or supercompression data
    for v in [104u64, 16, 16] {
        b.extend_from_slice(&v.to_le_bytes()); // level 0: offset, length, uncompressed length
    }
    for v in texel {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b
}

#[test]
fn an_rgba32f_lut_needs_float32_filterable() {
    let Some(g) = harness::device("shadefit skin format test") else { return };
    let bytes = rgba32f_ktx2([0.25, 0.5, 0.75, 1.0]);
    assert_eq!(skin::Ktx2Image::parse(&bytes).expect("well-formed").format, skin::LutFormat::Rgba32Float);
    // `headless` requests no optional features: the linear sampler cannot filter this texture.
    assert!(!g.device.features().contains(wgpu::Features::FLOAT32_FILTERABLE));
    let e = skin::create_lut_texture(&g.device, &g.queue, "rgba32f", &bytes).expect_err("refused without the feature");
    assert_eq!(e, skin::Ktx2Error::NeedsFloat32Filterable);
    // The half-float LUTs need nothing.
    skin::create_lut_texture(&g.device, &g.queue, "rgba16f", punctual::SKIN_PUNCTUAL_LUT_KTX2).expect("rgba16f");
    // With the feature requested (where the adapter offers it) the texture is accepted.
    if g.adapter.features().contains(wgpu::Features::FLOAT32_FILTERABLE) {
        let (device, queue) = pollster::block_on(g.adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("shadefit float32-filterable"),
            required_features: wgpu::Features::FLOAT32_FILTERABLE,
            ..Default::default()
        }))
        .expect("device with FLOAT32_FILTERABLE");
        skin::create_lut_texture(&device, &queue, "rgba32f", &bytes).expect("accepted with the feature");
        report("skin format test: RGBA32F accepted with FLOAT32_FILTERABLE");
    } else {
        report("skin format test: the adapter does not offer FLOAT32_FILTERABLE");
    }
}
