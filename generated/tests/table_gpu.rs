//! The texture form of every table module with a KTX2 texture, on a GPU through wgpu, against
//! the const-array function of the same module in the same shader:
//! - `FUNCTION_load` (the KTX2 uploaded by `Table::upload_ktx2`, read with textureLoad) does
//!   the const-array function's arithmetic on the stored texels: for R32Float the same values,
//!   so the two differ only where a compiler fuses a lerp's `a*b + c` in one and not the other;
//!   for R16Float also by the binary16 storage rounding;
//! - `FUNCTION_sample` (a linear, clamp-to-edge sampler at `MODULE_uv`, emitted only for a
//!   filterable format) adds the sampler's weight quantisation: a half-texel error in the
//!   texel-centre mapping would move it by half a texel step, which the bound excludes.
//!
//! The const array is moved to a storage buffer (same values, function body unchanged): a
//! software adapter (lavapipe) copies a dynamically indexed `const` array per access (see
//! tests/gpu.rs). Inputs cover the domain and beyond (the clamps) and NaN. With no adapter the
//! test is skipped, unless `CI` is set.

use shadefit_runtime::{compose, gpu, lut};
use wgpu::util::DeviceExt;

#[path = "support/harness.rs"]
mod harness;
use harness::report;

const WORKGROUP: usize = 64;

/// `library` with its `NAME_TABLE` const array moved into a storage buffer at binding 3.
fn table_in_buffer(library: &str, module: &str) -> String {
    harness::const_array_in_buffer(library, &format!("{}_TABLE", module.to_uppercase()), "f32")
}

/// Largest difference between neighbouring table values along either axis.
fn max_step(t: &lut::Table) -> f32 {
    let (w, h) = t.size();
    let (w, h) = (w as usize, h as usize);
    let v = t.values;
    let mut m = 0.0f32;
    for y in 0..h {
        for x in 0..w {
            if x + 1 < w {
                m = m.max((v[y * w + x + 1] - v[y * w + x]).abs());
            }
            if y + 1 < h {
                m = m.max((v[(y + 1) * w + x] - v[y * w + x]).abs());
            }
        }
    }
    m
}

/// Points over the domain and 10 % beyond each end, and a NaN per axis.
fn points(t: &lut::Table) -> Vec<f32> {
    let across = |[lo, hi]: [f32; 2], k: usize, n: usize| lo + (hi - lo) * (-0.1 + 1.2 * k as f32 / n as f32);
    let mut pts = Vec::new();
    match t.domain {
        [d] => {
            for k in 0..=4000 {
                pts.push(across(*d, k, 4000));
            }
            pts.push(f32::NAN);
        }
        [d0, d1] => {
            for a in 0..=300 {
                for b in 0..=300 {
                    pts.extend([across(*d0, a, 300), across(*d1, b, 300)]);
                }
            }
            pts.extend([f32::NAN, 0.5 * (d1[0] + d1[1]), 0.5 * (d0[0] + d0[1]), f32::NAN]);
        }
        _ => panic!("{}: tables have 1 or 2 axes", t.module),
    }
    pts
}

#[test]
fn table_textures_agree_with_the_const_arrays_on_the_gpu() {
    let Some(g) = harness::device("shadefit table texture test") else { return };
    let device = &g.device;
    let mut tested = 0;
    for t in lut::TABLES.iter().filter(|t| t.ktx2.is_some()) {
        let lib = table_in_buffer(&compose(&[t.module]).unwrap(), t.module);
        let sample = lib.contains(&format!("fn {}_sample(", t.function));
        let img = shadefit_runtime::skin::Ktx2Image::parse(t.ktx2.unwrap()).unwrap();
        let f16 = img.format == shadefit_runtime::skin::LutFormat::R16Float;
        // A linear sampler is only ever paired with R16Float here: an R32Float table's module has
        // no `_sample` unless its spec promised float32-filterable, and no committed one does.
        assert!(!sample || f16, "{}: linear sampler on {:?}", t.module, img.format);
        let texture = t.upload_ktx2(device, &g.queue, sample).unwrap().expect("KTX2 texture");
        let arity = t.domain.len();
        let args = |call: &str| {
            let a: Vec<String> = (0..arity).map(|k| format!("inp[{arity}u * i + {k}u]")).collect();
            format!("{call}{})", a.join(", "))
        };
        let shader = format!(
            "{lib}\n@group(0) @binding(0) var<storage, read> inp: array<f32>;\n\
             @group(0) @binding(1) var<storage, read_write> outp: array<f32>;\n\
             @group(0) @binding(2) var lut: texture_2d<f32>;\n{sampler}\
             @compute @workgroup_size({WORKGROUP})\nfn main(@builtin(global_invocation_id) id: vec3<u32>) {{\n    \
             let i = id.x;\n    outp[3u * i] = {c};\n    outp[3u * i + 1u] = {l};\n    outp[3u * i + 2u] = {s};\n}}\n",
            sampler = if sample { "@group(0) @binding(4) var lut_sampler: sampler;\n" } else { "" },
            c = args(&format!("{}(", t.function)),
            l = args(&format!("{}_load(lut, ", t.function)),
            s = if sample { args(&format!("{}_sample(lut, lut_sampler, ", t.function)) } else { "0.0".into() },
        );
        let pts = points(t);
        let n = pts.len() / arity;
        let padded = n.div_ceil(WORKGROUP) * WORKGROUP;
        let mut inputs = pts.clone();
        inputs.resize(padded * arity, 0.0);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(t.module),
            source: wgpu::ShaderSource::Wgsl(shader.into()),
        });
        let mut entries = vec![
            gpu::storage_entry(0, true),
            gpu::storage_entry(1, false),
            wgpu::BindGroupLayoutEntry {
                binding: 2,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: sample },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            },
            gpu::storage_entry(3, true),
        ];
        if sample {
            entries.push(wgpu::BindGroupLayoutEntry {
                binding: 4,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                count: None,
            });
        }
        let (bgl, pipeline) = gpu::compute_pipeline(device, t.module, &module, "main", &entries);
        let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("inputs"),
            contents: bytemuck::cast_slice(&inputs),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let table = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("table"),
            contents: bytemuck::cast_slice(t.values),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let size = (padded * 3 * 4) as u64;
        let (output, readback) = gpu::output_and_readback(device, size);
        let mut bind = vec![
            wgpu::BindGroupEntry { binding: 0, resource: input.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: output.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&texture.view) },
            wgpu::BindGroupEntry { binding: 3, resource: table.as_entire_binding() },
        ];
        if sample {
            bind.push(wgpu::BindGroupEntry { binding: 4, resource: wgpu::BindingResource::Sampler(&texture.sampler) });
        }
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(t.module), layout: &bgl, entries: &bind });
        let bytes = gpu::dispatch_and_read(&g, t.module, &pipeline, &bind_group, (padded / WORKGROUP) as u32, &output, &readback);
        let out: Vec<f32> = bytemuck::pod_collect_to_vec(&bytes);

        let vmax = t.values.iter().fold(0.0f32, |m, v| m.max(v.abs()));
        let step = max_step(t);
        // Two (2-D: three) lerps of values <= vmax, each a product and a sum that a compiler may
        // fuse in one function and not the other: 2 ulps of vmax per lerp, 6 in all (6 × 2⁻²⁴ × vmax).
        let lerps = 6.0 * 2f32.powi(-24) * vmax;
        // R16Float storage: round to nearest half, within 2⁻¹¹·|v| (normal halves) or 2⁻²⁵
        // (subnormal ones) of each texel, so of their weighted mean.
        let storage = if f16 { 2f32.powi(-11) * vmax + 2f32.powi(-25) } else { 0.0 };
        let load_bound = lerps + storage;
        // The sampler's weights quantised to the sub-texel precision Vulkan guarantees (>= 4
        // bits: each weight within 2⁻⁵ of exact) on each filtered axis, times a texel step.
        let sample_bound = load_bound + arity as f32 * 2f32.powi(-5) * step;
        let (mut worst_load, mut worst_sample) = (0.0f32, 0.0f32);
        for k in 0..n {
            let (c, l, s) = (out[3 * k], out[3 * k + 1], out[3 * k + 2]);
            let p = &pts[arity * k..arity * (k + 1)];
            assert!(c.is_finite() && l.is_finite() && s.is_finite(), "{} at {p:?}: {c} {l} {s}", t.module);
            worst_load = worst_load.max((l - c).abs());
            if sample {
                worst_sample = worst_sample.max((s - c).abs());
            }
        }
        report(&format!(
            "{} ({:?}, {n} points): |load - const| max {worst_load:.3e} (bound {load_bound:.3e}){}",
            t.module,
            img.format,
            if sample { format!("; |sample - const| max {worst_sample:.3e} (bound {sample_bound:.3e}; texel step {step:.3e})") } else { String::new() }
        ));
        assert!(worst_load <= load_bound, "{}: load {worst_load} > {load_bound}", t.module);
        if sample {
            assert!(worst_sample <= sample_bound, "{}: sample {worst_sample} > {sample_bound}", t.module);
            // A uv mapping off by half a texel would be caught: it moves a lookup by half a step.
            assert!(sample_bound < 0.5 * step, "{}: bound {sample_bound} too loose for step {step}", t.module);
        }
        tested += 1;
    }
    assert!(tested >= 1, "no table module with a KTX2 texture");
}
