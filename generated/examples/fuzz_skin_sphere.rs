//! Headless renders of spheres lit by one directional light, shaded with the emitted fuzz
//! functions and the pre-integrated skin LUT, each in a compute shader that composes only the
//! WGSL libraries it imports. The shaders write linear radiance (f32 RGB) to a storage buffer;
//! the CPU checks every pixel is finite, then tonemaps (exposure, x/(1+x)) and encodes sRGB
//! for the PNG only.
//!
//!     cargo run --release -p shadefit-runtime --example fuzz_skin_sphere [-- OUTDIR]
//!
//! Writes `OUTDIR/fuzz_sphere.png` and `OUTDIR/skin_sphere.png` (default OUTDIR:
//! `target/fuzz_skin_sphere/`). `WGPU_BACKEND=vulkan` on lavapipe works. Exits 1 if a pixel is
//! NaN or infinite, 2 without a GPU adapter.
//!
//! # fuzz_sphere.png: Ghost of Tsushima's anisotropic asperity scattering
//! Left to right: the base layer alone (Lambert, albedo c_b); base + fuzz layer with the
//! fibers along the parallels (horizontal circles); the same with the fibers along the
//! meridians. The fibers lie in the tangent plane (θf = π/2), so one coefficient set
//! c = `fuzz_ps_coeffs(α, π/2)` serves every pixel: it is evaluated once on the CPU (the Rust
//! function computes what the WGSL one does) and passed in a uniform, as a material would.
//! The model is the course notes' ("Anisotropic Asperity Scattering"), with u the light, v the
//! view, μ = direction·n, d the layer's density, c_f the fiber albedo and E the irradiance:
//!
//! ```text
//! fuzz layer:  L_f = c_f p(u, v) g(u, v) E                       (Koenderink–Pont single scattering)
//!              g(u, v) = (1 − exp(−d (μu + μv)/(μu μv))) μu/(μu + μv)
//!              p(u, v) = D_F(h)/(4 σ_F(u)),  D_F(h) = α³/(π((h·t)²(1 − α²) + α²)²),  σ_F(u) = sqrt(1 − (u·t)²(1 − α²))
//! base layer:  L_b = (c_b/π) [P_p(u) + c_f (1 − P_p(u)) P̃_s(u)] P_e(v) μu E
//!              P_p(u) = exp(−d/μu) (light through the layer unscattered), P_e(v) = exp(−d/μv)
//!              (light leaving the base unscattered), P̃_s(u) = fuzz_ps(c, μu, u·t): the
//!              fraction the layer scatters down toward the base
//! ambient (uniform sky of radiance L_a, irradiance E_a = π L_a):
//!              L_f,amb = c_f G̃(μv, d) L_a (1 − P̃_s(v))           G̃ = fuzz_g
//!              L_b,amb = (c_b/π) P_e(v) [Q̃(d) + c_f R̃(α, θf)(1 − Q̃(d))] E_a
//!                                                                Q̃ = fuzz_average_penetration, R̃ = fuzz_average_ps
//! ```
//! The fuzz spheres have the left one's base under a velvet-like layer: a pale sheen over a
//! darker base, shaped by the fiber direction (D_F is largest where the half vector is
//! perpendicular to the fibers: a vertical band for fibers along the parallels, a horizontal
//! one for the meridians, where it reaches the lit silhouette as g grows toward grazing
//! view), and a faint rim on the unlit side from the ambient G̃ term. The poles, where the
//! combing turns around, show a small whorl.
//!
//! # skin_sphere.png: pre-integrated skin diffusion
//! Left to right: Lambert (max(n·l, 0)), then the punctual LUT D(n·l, κ) for spheres of radius
//! 10, 2.5 and 1 mm (κ = 0.1, 0.4, 1 /mm; all drawn the same size). κ comes from
//! `skin_curvature_from_light_normalized` with the sphere's tensor I/r (which gives 1/r for
//! any light); D is read from the KTX2 texture (`skin::create_lut_texture`, `skin::lut_sampler`,
//! `skin_punctual_lut_sample`). Radiance (albedo/π) D E + albedo L_a: the smaller the sphere,
//! the more light bleeds past the terminator, reddest there (red scatters farthest).

use shadefit_runtime::{compose_shader, fuzz_ps, gpu, skin, skin_punctual_lut};
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use wgpu::util::DeviceExt;

/// Pixel size of one sphere's square cell.
const CELL: u32 = 320;
const WORKGROUP: u32 = 8;

/// Fuzz material: GGX spread of the fibers, their tilt from the normal, layer density.
const ALPHA: f32 = 0.35;
const THETA_F: f32 = std::f32::consts::FRAC_PI_2;
const DENSITY: f32 = 0.35;
const BASE_ALBEDO: [f32; 3] = [0.30, 0.035, 0.05];
const FIBER_ALBEDO: [f32; 3] = [0.95, 0.45, 0.50];

/// Skin: albedo and the sphere radii in mm (0: Lambert).
const SKIN_ALBEDO: [f32; 3] = [0.80, 0.55, 0.45];
const SKIN_RADII_MM: [f32; 4] = [0.0, 10.0, 2.5, 1.0];

/// Shared by both pictures: the light (unit vector toward it; irradiance E), sky radiance.
const LIGHT_IRRADIANCE: f32 = std::f32::consts::PI;
const SKY_RADIANCE: f32 = 0.06;

/// Common WGSL: output buffer, parameters, the sphere at a pixel.
const COMMON: &str = r#"
struct Params {
    // fuzz: c0..c3 | c4, c5, alpha, theta_f | base rgb, density | fiber rgb, - | light xyz, E | sky L_a, -, -, -
    // skin: radii (mm) of spheres 0..3 | albedo rgb, - | - | - | light xyz, E | sky L_a, -, -, -
    a: vec4<f32>,
    b: vec4<f32>,
    c: vec4<f32>,
    d: vec4<f32>,
    light: vec4<f32>,
    sky: vec4<f32>,
    size: vec4<u32>, // width, height, cell, -
};

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(3) var<storage, read_write> radiance: array<vec4<f32>>;

const PI: f32 = 3.14159265;

struct Hit {
    // Which sphere (cell), whether the pixel is on it, its normal.
    index: u32,
    on: bool,
    n: vec3<f32>,
};

// Orthographic view along -z; one sphere per square cell, filling 90% of it.
fn sphere_at(px: vec2<u32>) -> Hit {
    let cell = params.size.z;
    let local = (vec2<f32>(f32(px.x % cell), f32(px.y)) + 0.5) / f32(cell);
    let q = vec2<f32>(local.x * 2.0 - 1.0, 1.0 - local.y * 2.0) / 0.9;
    let r2 = dot(q, q);
    var hit: Hit;
    hit.index = px.x / cell;
    hit.on = r2 < 1.0;
    hit.n = vec3<f32>(q, sqrt(max(1.0 - r2, 0.0)));
    return hit;
}

fn background(px: vec2<u32>) -> vec3<f32> {
    let t = f32(px.y) / f32(params.size.y);
    return mix(vec3<f32>(0.03, 0.032, 0.04), vec3<f32>(0.008, 0.008, 0.01), t);
}
"#;

const FUZZ: &str = r#"
#import shadefit::fuzz_ps
#import shadefit::fuzz_g
#import shadefit::fuzz_q
#import shadefit::fuzz_r

// SGGX fiber phase function p(u, v) = D_F(h) / (4 sigma_F(u)) (fiber direction t).
fn fiber_phase(u: vec3<f32>, v: vec3<f32>, t: vec3<f32>, alpha: f32) -> f32 {
    let s = u + v;
    let h = s * inverseSqrt(max(dot(s, s), 1e-12)); // u = -v: h = 0, D_F finite
    let a2 = alpha * alpha;
    let ht = dot(h, t);
    let k = ht * ht * (1.0 - a2) + a2;
    let d = a2 * alpha / (PI * k * k);
    let ut = dot(u, t);
    let sigma = sqrt(max(1.0 - ut * ut * (1.0 - a2), a2)); // >= alpha
    return d / (4.0 * sigma);
}

// Unit fiber direction in the tangent plane: along the parallels (mode 0) or the meridians.
fn fiber_direction(n: vec3<f32>, meridian: bool) -> vec3<f32> {
    let up = vec3<f32>(0.0, 1.0, 0.0);
    var t = cross(up, n);
    var fallback = vec3<f32>(1.0, 0.0, 0.0);
    if meridian {
        t = up - n * n.y;
        fallback = vec3<f32>(0.0, 0.0, 1.0);
    }
    let len2 = dot(t, t);
    return select(fallback, t * inverseSqrt(len2), len2 > 1e-10);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.size.x || id.y >= params.size.y {
        return;
    }
    let px = id.xy;
    let hit = sphere_at(px);
    var c = background(px);
    if hit.on {
        let n = hit.n;
        let v = vec3<f32>(0.0, 0.0, 1.0);
        let l = params.light.xyz;
        let e = params.light.w;
        let sky = params.sky.x;
        let coeffs = array<f32, 6>(params.a.x, params.a.y, params.a.z, params.a.w, params.b.x, params.b.y);
        let alpha = params.b.z;
        let theta_f = params.b.w;
        let base = params.c.rgb;
        let density = params.c.w;
        let fiber = params.d.rgb;
        let mu_l = dot(n, l);
        let mu_v = max(dot(n, v), 1e-4);
        if hit.index == 0u {
            // Base layer alone.
            c = base / PI * (max(mu_l, 0.0) * e + PI * sky);
        } else {
            let t = fiber_direction(n, hit.index == 2u);
            let p_e = exp(-density / mu_v);
            var direct = vec3<f32>(0.0);
            if mu_l > 0.0 {
                let mu_u = max(mu_l, 1e-4);
                let g = (1.0 - exp(-density * (mu_u + mu_v) / (mu_u * mu_v))) * mu_u / (mu_u + mu_v);
                let layer = fiber * fiber_phase(l, v, t, alpha) * g;
                let p_p = exp(-density / mu_u);
                let p_s = fuzz_ps(coeffs, mu_l, dot(l, t));
                let under = base / PI * (p_p + fiber * (1.0 - p_p) * p_s) * p_e * mu_l;
                direct = (layer + under) * e;
            }
            // Ambient: the fuzz layer's G, the base's Q and R (uniform sky, E_a = pi L_a).
            let layer_amb = fiber * fuzz_g(mu_v, density) * sky * (1.0 - fuzz_ps(coeffs, mu_v, dot(v, t)));
            let q = fuzz_average_penetration(density);
            let r = fuzz_average_ps(alpha, theta_f);
            let base_amb = base / PI * p_e * (q + fiber * r * (1.0 - q)) * PI * sky;
            c = direct + layer_amb + base_amb;
        }
    }
    radiance[px.y * params.size.x + px.x] = vec4<f32>(c, 1.0);
}
"#;

const SKIN: &str = r#"
#import shadefit::skin_punctual_lut
#import shadefit::skin_curvature

@group(0) @binding(1) var lut: texture_2d<f32>;
@group(0) @binding(2) var lut_sampler: sampler;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.size.x || id.y >= params.size.y {
        return;
    }
    let px = id.xy;
    let hit = sphere_at(px);
    var c = background(px);
    if hit.on {
        let n = hit.n;
        let l = params.light.xyz;
        let albedo = params.b.rgb;
        let radius = params.a[min(hit.index, 3u)];
        var d = vec3<f32>(max(dot(n, l), 0.0));
        if radius > 0.0 {
            // Any tangent frame: the sphere's curvature tensor is I / r.
            let t = normalize(select(cross(vec3<f32>(0.0, 1.0, 0.0), n), vec3<f32>(1.0, 0.0, 0.0), abs(n.y) > 0.999));
            let b = cross(n, t);
            let kappa = skin_curvature_from_light_normalized(t, b, vec3<f32>(1.0 / radius, 0.0, 1.0 / radius), l);
            d = skin_punctual_lut_sample(lut, lut_sampler, dot(n, l), kappa);
        }
        c = albedo / PI * d * params.light.w + albedo * params.sky.x;
    }
    radiance[px.y * params.size.x + px.x] = vec4<f32>(c, 1.0);
}
"#;

/// The WGSL `Params`: seven vec4s (the last of u32).
struct Params {
    a: [f32; 4],
    b: [f32; 4],
    c: [f32; 4],
    d: [f32; 4],
    light: [f32; 4],
    sky: [f32; 4],
    size: [u32; 4],
}

impl Params {
    /// Uniform buffer contents (little-endian words, in declaration order).
    fn bytes(&self) -> Vec<u8> {
        let floats = [self.a, self.b, self.c, self.d, self.light, self.sky];
        let words = floats.iter().flatten().map(|x| x.to_bits()).chain(self.size);
        words.flat_map(u32::to_le_bytes).collect()
    }
}

fn normalize(v: [f32; 3]) -> [f32; 3] {
    let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / len, v[1] / len, v[2] / len]
}

/// Run `shader` (entry `main`, one invocation per pixel) and read back the radiance. With
/// `lut`, the skin LUT texture and its sampler are bound at 1 and 2.
fn render(g: &gpu::Gpu, label: &str, shader: &str, params: &Params, lut: Option<&wgpu::Texture>) -> Vec<[f32; 4]> {
    let device = &g.device;
    let (width, height) = (params.size[0], params.size[1]);
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(shader.into()),
    });
    let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("params"),
        contents: &params.bytes(),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let size = width as u64 * height as u64 * 16;
    let (output, readback) = gpu::output_and_readback(device, size);
    let stage = wgpu::ShaderStages::COMPUTE;
    let mut layout_entries = vec![
        wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: stage,
            ty: wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Uniform, has_dynamic_offset: false, min_binding_size: None },
            count: None,
        },
        wgpu::BindGroupLayoutEntry {
            binding: 3,
            visibility: stage,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: false },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        },
    ];
    let view = lut.map(|t| t.create_view(&Default::default()));
    let sampler = lut.map(|_| skin::lut_sampler(device));
    let mut entries = vec![
        wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
        wgpu::BindGroupEntry { binding: 3, resource: output.as_entire_binding() },
    ];
    if let (Some(view), Some(sampler)) = (&view, &sampler) {
        layout_entries.push(wgpu::BindGroupLayoutEntry {
            binding: 1,
            visibility: stage,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: true },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        });
        layout_entries.push(wgpu::BindGroupLayoutEntry {
            binding: 2,
            visibility: stage,
            ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
            count: None,
        });
        entries.push(wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(view) });
        entries.push(wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::Sampler(sampler) });
    }
    let (bgl, pipeline) = gpu::compute_pipeline(device, label, &module, "main", &layout_entries);
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(label), layout: &bgl, entries: &entries });
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(label), timestamp_writes: None });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups(width.div_ceil(WORKGROUP), height.div_ceil(WORKGROUP), 1);
    }
    encoder.copy_buffer_to_buffer(&output, 0, &readback, 0, size);
    g.queue.submit([encoder.finish()]);
    let (tx, rx) = std::sync::mpsc::channel();
    readback.slice(..).map_async(wgpu::MapMode::Read, move |r| tx.send(r).unwrap());
    device.poll(wgpu::PollType::wait_indefinitely()).expect("poll");
    rx.recv().unwrap().expect("map readback buffer");
    let pixels = bytemuck::cast_slice::<u8, [f32; 4]>(&readback.slice(..).get_mapped_range().expect("mapped range")).to_vec();
    readback.unmap();
    pixels
}

/// sRGB encoding of a linear value in [0, 1].
fn srgb(x: f32) -> u8 {
    let x = x.clamp(0.0, 1.0);
    let s = if x <= 0.003_130_8 { 12.92 * x } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 };
    (s * 255.0 + 0.5) as u8
}

/// Exposure and x/(1+x) per channel, sRGB, 8-bit PNG.
fn write_png(path: &Path, width: u32, height: u32, pixels: &[[f32; 4]], exposure: f32) {
    let mut bytes = Vec::with_capacity(pixels.len() * 4);
    for p in pixels {
        for &x in &p[..3] {
            let x = x * exposure;
            bytes.push(srgb(x / (1.0 + x)));
        }
        bytes.push(255);
    }
    let file = std::fs::File::create(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut enc = png::Encoder::new(BufWriter::new(file), width, height);
    enc.set_color(png::ColorType::Rgba);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    let mut writer = enc.write_header().expect("png header");
    writer.write_image_data(&bytes).expect("png data");
    writer.finish().expect("png finish");
}

/// Number of pixels with a NaN or infinite channel, and the largest channel value.
fn inspect(pixels: &[[f32; 4]]) -> (usize, f32) {
    let bad = pixels.iter().filter(|p| p.iter().any(|x| !x.is_finite())).count();
    let max = pixels.iter().flat_map(|p| &p[..3]).filter(|x| x.is_finite()).fold(0f32, |m, &x| m.max(x));
    (bad, max)
}

fn main() {
    let out_dir = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../target/fuzz_skin_sphere")));
    std::fs::create_dir_all(&out_dir).unwrap_or_else(|e| panic!("{}: {e}", out_dir.display()));
    let g = match pollster::block_on(gpu::headless("fuzz_skin_sphere")) {
        Ok(g) => g,
        Err(e) => {
            eprintln!("fuzz_skin_sphere: {e}");
            std::process::exit(2);
        }
    };
    eprintln!("adapter: {}", gpu::describe(&g.adapter.get_info()));

    // Fuzz: three spheres, light from the upper left, in front.
    let light = normalize([-0.55, 0.45, 0.70]);
    let c = fuzz_ps::fuzz_ps_coeffs(ALPHA, THETA_F);
    let (w, h) = (3 * CELL, CELL);
    let params = Params {
        a: [c[0], c[1], c[2], c[3]],
        b: [c[4], c[5], ALPHA, THETA_F],
        c: [BASE_ALBEDO[0], BASE_ALBEDO[1], BASE_ALBEDO[2], DENSITY],
        d: [FIBER_ALBEDO[0], FIBER_ALBEDO[1], FIBER_ALBEDO[2], 0.0],
        light: [light[0], light[1], light[2], LIGHT_IRRADIANCE],
        sky: [SKY_RADIANCE, 0.0, 0.0, 0.0],
        size: [w, h, CELL, 0],
    };
    let shader = compose_shader(&format!("{COMMON}{FUZZ}")).expect("compose the fuzz shader");
    let fuzz = render(&g, "fuzz", &shader, &params, None);

    // Skin: four spheres, light from the right so the terminator crosses each.
    let light = normalize([0.80, 0.25, 0.45]);
    let r = SKIN_RADII_MM;
    let params = Params {
        a: [r[0], r[1], r[2], r[3]],
        b: [SKIN_ALBEDO[0], SKIN_ALBEDO[1], SKIN_ALBEDO[2], 0.0],
        c: [0.0; 4],
        d: [0.0; 4],
        light: [light[0], light[1], light[2], LIGHT_IRRADIANCE],
        sky: [0.25 * SKY_RADIANCE, 0.0, 0.0, 0.0],
        size: [4 * CELL, CELL, CELL, 0],
    };
    let lut = skin::create_lut_texture(&g.device, &g.queue, "skin_punctual_lut", skin_punctual_lut::SKIN_PUNCTUAL_LUT_KTX2)
        .expect("skin LUT KTX2");
    let shader = compose_shader(&format!("{COMMON}{SKIN}")).expect("compose the skin shader");
    let skin_px = render(&g, "skin", &shader, &params, Some(&lut));

    let mut failed = false;
    for (name, pixels, width, what) in [
        ("fuzz_sphere.png", &fuzz, w, "base alone | fuzz, fibers along parallels | fuzz, fibers along meridians"),
        ("skin_sphere.png", &skin_px, 4 * CELL, "Lambert | skin LUT, r = 10 mm | r = 2.5 mm | r = 1 mm"),
    ] {
        let (bad, max) = inspect(pixels);
        let path = out_dir.join(name);
        write_png(&path, width, CELL, pixels, 1.0);
        eprintln!("wrote {} ({width}x{CELL}): {what}; max radiance {max:.3}, {bad} non-finite pixels", path.display());
        failed |= bad > 0;
    }
    if failed {
        eprintln!("fuzz_skin_sphere: non-finite radiance");
        std::process::exit(1);
    }
}
