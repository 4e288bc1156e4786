//! Headless render of two glossy spheres whose GGX roughness comes from the emitted
//! `combine_gloss` (left: the rational fit, composed from `#import shadefit::gloss_combine`)
//! and `combine_gloss_lut` (right: the 64×64 table as an R32Float texture through
//! `lut::Table::wgsl`). The base gloss varies across each sphere (0 on the left, 1 on the
//! right); the detail gloss is fixed at 0.85, so the combined gloss (never above what the
//! detail allows) and the highlights' size vary along the fan of lights. The two spheres
//! should look the same.
//!
//!     cargo run --release -p shadefit-runtime --example gloss_sphere [-- OUT.png]
//!
//! Writes `target/gloss_sphere.png` by default. `WGPU_BACKEND=vulkan` on lavapipe works.

use shadefit_runtime::{compose_shader, gpu, lut};
use std::io::BufWriter;

const WIDTH: u32 = 768;
const HEIGHT: u32 = 384;
const DETAIL_GLOSS: f32 = 0.85;

fn shader(table: &lut::Table) -> String {
    let user = format!(
        r#"#import shadefit::gloss_combine
{accessor}

const DETAIL_GLOSS: f32 = {DETAIL_GLOSS:?};

struct VsOut {{
    @builtin(position) pos: vec4<f32>,
    @location(0) uv: vec2<f32>,
}};

// One triangle covering the screen; uv in [0, 2] x [0, 1], y up.
@vertex
fn vs(@builtin(vertex_index) i: u32) -> VsOut {{
    let p = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    var o: VsOut;
    o.pos = vec4<f32>(p * 2.0 - 1.0, 0.0, 1.0);
    o.uv = vec2<f32>(p.x * 2.0, p.y);
    return o;
}}

const PI: f32 = 3.14159265;

// GGX alpha for gloss g (the WWII parameterisation the gloss fits use).
fn alpha_from_gloss(g: f32) -> f32 {{
    return sqrt(2.0 / (1.0 + exp2(18.0 * g)));
}}

fn ggx_specular(n: vec3<f32>, v: vec3<f32>, l: vec3<f32>, alpha: f32) -> f32 {{
    let h = normalize(v + l);
    let nh = max(dot(n, h), 0.0);
    let nl = max(dot(n, l), 0.0);
    let nv = max(dot(n, v), 1e-4);
    let a2 = alpha * alpha;
    let t = nh * nh * (a2 - 1.0) + 1.0;
    let d = a2 / (PI * t * t);
    // Height-correlated Smith visibility.
    let gv = nl * sqrt(nv * nv * (1.0 - a2) + a2);
    let gl = nv * sqrt(nl * nl * (1.0 - a2) + a2);
    let vis = 0.5 / max(gv + gl, 1e-6);
    let f = 0.04 + 0.96 * pow(1.0 - max(dot(v, h), 0.0), 5.0);
    return d * vis * f * nl;
}}

@fragment
fn fs(in: VsOut) -> @location(0) vec4<f32> {{
    // Which sphere, and the position on it in [-1, 1]^2.
    let right = in.uv.x >= 1.0;
    let q = (vec2<f32>(fract(in.uv.x), in.uv.y) * 2.0 - 1.0) * 1.08;
    let r2 = dot(q, q);
    if r2 > 1.0 {{
        let bg = mix(vec3<f32>(0.015, 0.016, 0.02), vec3<f32>(0.05, 0.055, 0.065), in.uv.y);
        return vec4<f32>(bg, 1.0);
    }}
    let n = vec3<f32>(q, sqrt(1.0 - r2));
    let v = vec3<f32>(0.0, 0.0, 1.0);
    // Base gloss across the sphere: 0 (rough) at x = -0.6, 1 (mirror-like) at x = +0.6.
    let base = saturate(0.5 + q.x / 1.2);
    var gloss: f32;
    if right {{
        gloss = {lut_fn}(base, DETAIL_GLOSS);
    }} else {{
        gloss = combine_gloss(base, DETAIL_GLOSS);
    }}
    let alpha = alpha_from_gloss(gloss);
    let albedo = vec3<f32>(0.20, 0.035, 0.025);
    var c = albedo * (0.02 + 0.06 * (0.5 + 0.5 * n.y));
    // A fan of lights from the far left to the far right, slightly above: the highlights
    // (at the half vectors) sit at x ≈ -0.6 ... 0.6, each on a different base gloss.
    for (var k = 0; k < 7; k++) {{
        let th = radians(-78.0 + 26.0 * f32(k));
        let l = normalize(vec3<f32>(sin(th), 0.3, cos(th)));
        let nl = max(dot(n, l), 0.0);
        c += 0.5 * (albedo / PI * nl + vec3<f32>(ggx_specular(n, v, l, alpha)));
    }}
    c = c / (1.0 + c); // Reinhard
    return vec4<f32>(c, 1.0);
}}
"#,
        accessor = table.wgsl(0, 0),
        lut_fn = table.accessor_name(),
    );
    compose_shader(&user).expect("compose")
}

fn main() {
    let out_path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| concat!(env!("CARGO_MANIFEST_DIR"), "/../target/gloss_sphere.png").to_string());
    let gpu = match pollster::block_on(gpu::headless("gloss_sphere")) {
        Ok(g) => g,
        Err(e) => {
            eprintln!("gloss_sphere: {e}");
            std::process::exit(2);
        }
    };
    eprintln!("adapter: {}", gpu::describe(&gpu.adapter.get_info()));
    let (device, queue) = (&gpu.device, &gpu.queue);

    let table = lut::table("gloss_combine_lut").expect("gloss_combine_lut table");
    let lut_texture = table.create_texture(device, queue);
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("gloss_sphere"),
        source: wgpu::ShaderSource::Wgsl(shader(table).into()),
    });
    let bgl = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("lut"),
        entries: &[lut::LutTexture::texture_entry(0, wgpu::ShaderStages::FRAGMENT)],
    });
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("lut"),
        layout: &bgl,
        entries: &[wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&lut_texture.view) }],
    });
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("gloss_sphere"),
        bind_group_layouts: &[Some(&bgl)],
        immediate_size: 0,
    });
    let format = wgpu::TextureFormat::Rgba8UnormSrgb;
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("gloss_sphere"),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: None,
        multisample: wgpu::MultisampleState::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[Some(format.into())],
        }),
        multiview_mask: None,
        cache: None,
    });

    let target = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("target"),
        size: wgpu::Extent3d { width: WIDTH, height: HEIGHT, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let view = target.create_view(&Default::default());
    let row = (WIDTH * 4).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: (row * HEIGHT) as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });

    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("gloss_sphere"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::BLACK), store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
    encoder.copy_texture_to_buffer(
        target.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &readback,
            layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: Some(HEIGHT) },
        },
        wgpu::Extent3d { width: WIDTH, height: HEIGHT, depth_or_array_layers: 1 },
    );
    queue.submit([encoder.finish()]);
    let (tx, rx) = std::sync::mpsc::channel();
    readback.slice(..).map_async(wgpu::MapMode::Read, move |r| tx.send(r).unwrap());
    device.poll(wgpu::PollType::wait_indefinitely()).expect("poll");
    rx.recv().unwrap().expect("map");
    let mapped = readback.slice(..).get_mapped_range().expect("mapped range");
    let mut pixels = Vec::with_capacity((WIDTH * HEIGHT * 4) as usize);
    for y in 0..HEIGHT {
        let start = (y * row) as usize;
        pixels.extend_from_slice(&mapped[start..start + (WIDTH * 4) as usize]);
    }
    drop(mapped);
    readback.unmap();

    let file = std::fs::File::create(&out_path).unwrap_or_else(|e| panic!("{out_path}: {e}"));
    let mut enc = png::Encoder::new(BufWriter::new(file), WIDTH, HEIGHT);
    enc.set_color(png::ColorType::Rgba);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    let mut writer = enc.write_header().expect("png header");
    writer.write_image_data(&pixels).expect("png data");
    writer.finish().expect("png finish");
    eprintln!("wrote {out_path} ({WIDTH}x{HEIGHT}): left combine_gloss (rational), right combine_gloss_lut (R32Float texture)");
}
