//! The split-sum LUT textures on a GPU through wgpu: the DFG LUTs (RG16F, 2-D; both layouts) and
//! the cone LUT (RG16F, 3-D), uploaded from their KTX2 bytes by `skin::create_lut_texture` and
//! read through `skin::lut_sampler` by the emitted `NAME_sample` and `NAME_specular` WGSL, against
//! the emitted CPU lookups, which interpolate the same f16 texels with exact weights. The two
//! differ by the sampler's weight quantisation and the filter's roundings, which a bound at each
//! point allows (from the texel steps around it). The same shader with its texture coordinates
//! moved by half a texel on one axis (a missing texel-centre or slice remap) must break that
//! bound somewhere, on every axis. Inputs cover the domain and 10 % beyond each end (the clamps)
//! and NaN. With no adapter the test is skipped, unless `CI` is set.

use shadefit_runtime::{compose, ggx_cone_lut as cone, ggx_dfg_lut as sb, ggx_dfg_lut_bevy as bevy, ggx_dfg_lut_filament as fil, gpu, skin};
use wgpu::util::DeviceExt;

#[path = "support/harness.rs"]
mod harness;
use harness::report;

const WORKGROUP: usize = 64;
/// Outputs per point: the sampled channels (2) and the specular reflectance at F0 = (1, 0, 0.04)
/// (3), which decodes the layout into scale + bias, bias and 0.04·scale + bias.
const OUTS: usize = 5;
const F0: [f32; 3] = [1.0, 0.0, 0.04];

/// One LUT module: its texture, its functions (WGSL and CPU) and its axes.
struct Lut {
    module: &'static str,
    /// Prefix of `_sample` and `_specular`.
    function: &'static str,
    /// The WGSL (and CPU) texture-coordinate function.
    uv: &'static str,
    ktx2: &'static [u8],
    cpu_uv: fn(&[f32]) -> Vec<f32>,
    cpu_sample: fn(&[f32]) -> [f32; 2],
    cpu_specular: fn(&[f32]) -> [f32; 3],
    /// `scale = G − R` (Filament's layout): the specular's error triples.
    difference: bool,
}

fn luts() -> Vec<Lut> {
    vec![
        Lut {
            module: "ggx_dfg_lut",
            function: "ggx_dfg",
            uv: "ggx_dfg_uv",
            ktx2: sb::GGX_DFG_LUT_KTX2,
            cpu_uv: |p| sb::ggx_dfg_uv(p[0], p[1]).to_vec(),
            cpu_sample: |p| sb::ggx_dfg(p[0], p[1]),
            cpu_specular: |p| sb::ggx_dfg_specular(F0, p[0], p[1]),
            difference: false,
        },
        Lut {
            module: "ggx_dfg_lut_filament",
            function: "ggx_dfg_filament",
            uv: "ggx_dfg_filament_uv",
            ktx2: fil::GGX_DFG_LUT_FILAMENT_KTX2,
            cpu_uv: |p| fil::ggx_dfg_filament_uv(p[0], p[1]).to_vec(),
            cpu_sample: |p| fil::ggx_dfg_filament(p[0], p[1]),
            cpu_specular: |p| fil::ggx_dfg_filament_specular(F0, p[0], p[1]),
            difference: true,
        },
        Lut {
            module: "ggx_dfg_lut_bevy",
            function: "ggx_dfg_bevy",
            uv: "ggx_dfg_bevy_uv",
            ktx2: bevy::GGX_DFG_LUT_BEVY_KTX2,
            cpu_uv: |p| bevy::ggx_dfg_bevy_uv(p[0], p[1]).to_vec(),
            cpu_sample: |p| bevy::ggx_dfg_bevy(p[0], p[1]),
            cpu_specular: |p| bevy::ggx_dfg_bevy_specular(F0, p[0], p[1]),
            difference: false,
        },
        Lut {
            module: "ggx_cone_lut",
            function: "ggx_cone_dfg",
            uv: "ggx_cone_dfg_uvw",
            ktx2: cone::GGX_CONE_LUT_KTX2,
            cpu_uv: |p| cone::ggx_cone_dfg_uvw(p[0], p[1], p[2]).to_vec(),
            cpu_sample: |p| cone::ggx_cone_dfg(p[0], p[1], p[2]),
            cpu_specular: |p| cone::ggx_cone_dfg_specular(F0, p[0], p[1], p[2]),
            difference: false,
        },
    ]
}

/// Texels per axis of the image: (width, height) or (width, height, depth).
fn size(img: &skin::Ktx2Image) -> Vec<u32> {
    if img.depth == 0 { vec![img.width, img.height] } else { vec![img.width, img.height, img.depth] }
}

/// The largest difference between neighbouring texels along each axis, over both channels,
/// among the texels a linear filter at texture coordinates `uv` reads and one more on each side
/// (so a coordinate that rounds across a texel centre on the GPU is covered too). The texels are
/// read by the runtime's KTX2 reader, which `tests/ggx.rs` checks against the emitted ones.
fn local_steps(img: &skin::Ktx2Image, uv: &[f32]) -> Vec<f32> {
    let size = size(img);
    let dims = size.len();
    // Per axis: the filter's pair i0, i0 + 1 at x = u·n − 0.5, widened by one texel each way.
    let span: Vec<(u32, u32)> = (0..dims)
        .map(|a| {
            let n = size[a] as i64;
            let i0 = (uv[a] * n as f32 - 0.5).floor() as i64;
            ((i0 - 1).clamp(0, n - 1) as u32, (i0 + 2).clamp(0, n - 1) as u32)
        })
        .collect();
    let range = |a: usize| if a < dims { span[a].0..=span[a].1 } else { 0..=0 };
    let mut steps = vec![0.0f32; dims];
    for z in range(2) {
        for y in range(1) {
            for x in range(0) {
                let here = img.texel_3d(x, y, z);
                let at = [x, y, z];
                for (a, s) in steps.iter_mut().enumerate() {
                    if at[a] < span[a].1 {
                        let mut next = at;
                        next[a] += 1;
                        let t = img.texel_3d(next[0], next[1], next[2]);
                        *s = s.max((t[0] - here[0]).abs()).max((t[1] - here[1]).abs());
                    }
                }
            }
        }
    }
    steps
}

/// Points over [−0.1, 1.1] on each axis (the parameters' domain is [0, 1]), and NaN on each.
fn points(dims: usize) -> Vec<f32> {
    let per_axis: usize = if dims == 2 { 241 } else { 41 };
    let across = |k: usize| -0.1 + 1.2 * k as f32 / (per_axis - 1) as f32;
    let mut pts = Vec::new();
    for k in 0..per_axis.pow(dims as u32) {
        let mut r = k;
        for _ in 0..dims {
            pts.push(across(r % per_axis));
            r /= per_axis;
        }
    }
    for a in 0..dims {
        pts.extend((0..dims).map(|b| if a == b { f32::NAN } else { 0.5 }));
    }
    pts
}

/// `library` with its texture-coordinate function `uv` moved by `shift` (in texture
/// coordinates): the emitted function renamed, a wrapper of the old name adding the shift.
fn shifted(library: &str, uv: &str, shift: &[f32]) -> String {
    let renamed = library.replace(&format!("fn {uv}("), &format!("fn {uv}_emitted("));
    let dims = shift.len();
    let params: Vec<String> = (0..dims).map(|k| format!("a{k}: f32")).collect();
    let args: Vec<String> = (0..dims).map(|k| format!("a{k}")).collect();
    let offset: Vec<String> = shift.iter().map(|v| format!("{v:?}")).collect();
    format!(
        "{renamed}\nfn {uv}({}) -> vec{dims}<f32> {{\n    return {uv}_emitted({}) + vec{dims}<f32>({});\n}}\n",
        params.join(", "),
        args.join(", "),
        offset.join(", ")
    )
}

/// Run `_sample` and `_specular` of `library` on the GPU at `pts`: OUTS values a point.
fn run_on_gpu(g: &gpu::Gpu, l: &Lut, dims: usize, view: &wgpu::TextureView, sampler: &wgpu::Sampler, library: &str, pts: &[f32]) -> Vec<f32> {
    let device = &g.device;
    let args: Vec<String> = (0..dims).map(|k| format!("inp[{dims}u * i + {k}u]")).collect();
    let args = args.join(", ");
    let shader = format!(
        "{library}\n@group(0) @binding(0) var<storage, read> inp: array<f32>;\n\
         @group(0) @binding(1) var<storage, read_write> outp: array<f32>;\n\
         @group(0) @binding(2) var lut: texture_{dims}d<f32>;\n\
         @group(0) @binding(3) var lut_sampler: sampler;\n\
         @compute @workgroup_size({WORKGROUP})\nfn main(@builtin(global_invocation_id) id: vec3<u32>) {{\n    \
         let i = id.x;\n    \
         let t = {f}_sample(lut, lut_sampler, {args});\n    \
         let s = {f}_specular(lut, lut_sampler, vec3<f32>({a:?}, {b:?}, {c:?}), {args});\n    \
         outp[{OUTS}u * i] = t.x;\n    outp[{OUTS}u * i + 1u] = t.y;\n    \
         outp[{OUTS}u * i + 2u] = s.x;\n    outp[{OUTS}u * i + 3u] = s.y;\n    outp[{OUTS}u * i + 4u] = s.z;\n}}\n",
        f = l.function,
        a = F0[0],
        b = F0[1],
        c = F0[2],
    );
    let n = pts.len() / dims;
    let padded = n.div_ceil(WORKGROUP) * WORKGROUP;
    let mut inputs = pts.to_vec();
    inputs.resize(padded * dims, 0.0);
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor { label: Some(l.module), source: wgpu::ShaderSource::Wgsl(shader.into()) });
    let view_dimension = if dims == 2 { wgpu::TextureViewDimension::D2 } else { wgpu::TextureViewDimension::D3 };
    let entries = [
        gpu::storage_entry(0, true),
        gpu::storage_entry(1, false),
        wgpu::BindGroupLayoutEntry {
            binding: 2,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Texture { sample_type: wgpu::TextureSampleType::Float { filterable: true }, view_dimension, multisampled: false },
            count: None,
        },
        wgpu::BindGroupLayoutEntry {
            binding: 3,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
            count: None,
        },
    ];
    let (bgl, pipeline) = gpu::compute_pipeline(device, l.module, &module, "main", &entries);
    let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("inputs"),
        contents: bytemuck::cast_slice(&inputs),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let size = (padded * OUTS * 4) as u64;
    let (output, readback) = gpu::output_and_readback(device, size);
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(l.module),
        layout: &bgl,
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: input.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: output.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(view) },
            wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::Sampler(sampler) },
        ],
    });
    let bytes = gpu::dispatch_and_read(g, l.module, &pipeline, &bind_group, (padded / WORKGROUP) as u32, &output, &readback);
    bytemuck::pod_collect_to_vec(&bytes)
}

/// What the GPU's outputs at a point are judged against: the CPU lookups and their bounds.
struct Reference {
    sample: [f32; 2],
    specular: [f32; 3],
    sample_bound: f32,
    specular_bound: f32,
}

/// The references at `pts`, computed once for the shader and its shifted versions.
fn references(l: &Lut, img: &skin::Ktx2Image, pts: &[f32]) -> Vec<Reference> {
    let dims = size(img).len();
    // Texel magnitudes: scale, bias and scale + bias of a split sum all lie in [0, 1] (the f16
    // storage can round 1 up by at most half an ulp of 1, 2^-11); 1 + 2^-10 bounds them.
    let vmax = 1.0 + 2f32.powi(-10);
    // The filter's lerps, one per texel pair merged (2-D: 3, 3-D: 7), each a product and a sum
    // rounded. Vulkan leaves the filter's arithmetic precision to the implementation, and
    // NVIDIA's driver filters these 16-bit float textures at about the texels' own precision (an
    // H100, driver 580.159.04, came within 2.9e-4 of the exact-weight f32 filter of the same
    // texels, 16 times an f32 rounding bound): each rounding taken in binary16, half an ulp, at
    // most 2^-11 of vmax.
    let lerps = if dims == 2 { 3.0 } else { 7.0 };
    let rounding = 2.0 * lerps * 2f32.powi(-11) * vmax;
    pts.chunks(dims)
        .map(|p| {
            // The sampler's weights quantised to the sub-texel precision Vulkan guarantees (>= 4
            // bits: each weight within 2^-5 of exact) on each axis, times that axis's texel step
            // here.
            let steps = local_steps(img, &(l.cpu_uv)(p));
            let sample_bound = rounding + steps.iter().map(|s| 2f32.powi(-5) * s).sum::<f32>();
            // specular = f0·scale + bias with |f0| <= 1: both channels' errors (Filament's scale =
            // G − R: three), and the product, the sum and the difference's roundings, 2 ulps of 2.
            let specular_bound = if l.difference { 3.0 } else { 2.0 } * sample_bound + 3.0 * 2f32.powi(-23);
            Reference { sample: (l.cpu_sample)(p), specular: (l.cpu_specular)(p), sample_bound, specular_bound }
        })
        .collect()
}

/// The largest |GPU − CPU| of the sample and of the specular over the points, and the largest
/// ratio of each to its bound.
struct Judged {
    /// Largest deviation / bound, sample and specular.
    ratio: [f32; 2],
    /// Largest deviation, sample and specular.
    worst: [f32; 2],
}

fn judge(module: &str, refs: &[Reference], out: &[f32]) -> Judged {
    let mut j = Judged { ratio: [0.0; 2], worst: [0.0; 2] };
    for (k, (r, o)) in refs.iter().zip(out.chunks(OUTS)).enumerate() {
        assert!(o.iter().all(|v| v.is_finite()), "{module} at point {k}: {o:?}");
        let ds = (0..2).map(|c| (o[c] - r.sample[c]).abs()).fold(0.0f32, f32::max);
        let dp = (0..3).map(|c| (o[2 + c] - r.specular[c]).abs()).fold(0.0f32, f32::max);
        j.worst = [j.worst[0].max(ds), j.worst[1].max(dp)];
        j.ratio = [j.ratio[0].max(ds / r.sample_bound), j.ratio[1].max(dp / r.specular_bound)];
    }
    j
}

#[test]
fn split_sum_lut_textures_sample_as_the_cpu_lookups_interpolate() {
    let Some(g) = harness::device("shadefit split-sum LUT texture test") else { return };
    // Every LUT is measured and reported before any assertion.
    let mut failures = Vec::new();
    for l in luts() {
        let img = skin::Ktx2Image::parse(l.ktx2).expect("the module's KTX2");
        let size = size(&img);
        let dims = size.len();
        assert_eq!(img.format, skin::LutFormat::Rg16Float, "{}", l.module);
        let texture = skin::create_lut_texture(&g.device, &g.queue, l.module, l.ktx2).expect("an RG16F texture uploads");
        let view = texture.create_view(&Default::default());
        let sampler = skin::lut_sampler(&g.device);
        let library = compose(&[l.module]).unwrap();
        let pts = points(dims);
        let refs = references(&l, &img, &pts);
        let j = judge(l.module, &refs, &run_on_gpu(&g, &l, dims, &view, &sampler, &library, &pts));
        report(&format!(
            "{} ({dims}-D RG16F {:?}, {} points): |sample - CPU| max {:.3e} (largest deviation/bound {:.3}); |specular - CPU| max {:.3e} ({:.3})",
            l.module,
            size,
            refs.len(),
            j.worst[0],
            j.ratio[0],
            j.worst[1],
            j.ratio[1]
        ));
        if j.ratio[0] > 1.0 || j.ratio[1] > 1.0 {
            failures.push(format!("{}: out of bound", l.module));
        }
        // Coordinates half a texel off on one axis: caught on every axis.
        for a in 0..dims {
            let shift: Vec<f32> = (0..dims).map(|b| if a == b { 0.5 / size[a] as f32 } else { 0.0 }).collect();
            let moved = shifted(&library, l.uv, &shift);
            let j = judge(l.module, &refs, &run_on_gpu(&g, &l, dims, &view, &sampler, &moved, &pts));
            report(&format!("{}: coordinates half a texel off on axis {a}: largest deviation/bound {:.1}", l.module, j.ratio[0]));
            if j.ratio[0] <= 1.0 {
                failures.push(format!("{}: half a texel off on axis {a} passes the bound", l.module));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("; "));
}
