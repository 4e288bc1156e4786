//! The LTC light functions (`shadefit::ltc_ggx`) on a GPU through wgpu, against their CPU twin:
//! a rectangle through the clipped polygon and through the sphere path, a triangle, and the
//! closed-form ltc_2.w, for table texels across the table (read from the RGBA32F KTX2), views
//! from normal to grazing, lights overhead, at the reflection side, across the horizon and
//! facing away, and special inputs (NaN, ±inf, huge, zero). A control run with the ltc_1 texel
//! read in the wrong order (b and c swapped, ltc_code's packing misread) must break the bound.
//! With no adapter the test is skipped, unless `CI` is set.

use shadefit_runtime::ltc_ggx as l;
use shadefit_runtime::skin::Ktx2Image;
use shadefit_runtime::{compose, gpu};
use wgpu::util::DeviceExt;

#[path = "support/harness.rs"]
mod harness;
use harness::report;

const WORKGROUP: usize = 64;
/// Inputs a point: ltc_1 (4), n, v, p, centre, half_x, half_y (3 each), two-sided, z, s.
const INS: usize = 25;
const OUTS: usize = 4;

/// The bound on |GPU − CPU| of each output. WGSL lets atan2, acos and atan err by far more
/// than f32 rounding (4096 ulp); the bound takes each edge's angle within 2⁻¹¹ of its value
/// (the allowance tests/support/bound.rs grants sin and cos), at most π: over at most 5 edges
/// divided by 2π, 5·2⁻¹² ≈ 1.2e-3, and the same for the sphere path's closed form. A misread
/// texel or frame moves results by 1e-2 and more (the control run).
const BOUND: f32 = 5.0 / 4096.0;

struct Case {
    t1: [f32; 4],
    n: [f32; 3],
    v: [f32; 3],
    p: [f32; 3],
    c: [f32; 3],
    hx: [f32; 3],
    hy: [f32; 3],
    two: bool,
    z: f32,
    s: f32,
}

impl Case {
    fn flat(&self) -> Vec<f32> {
        let mut f = self.t1.to_vec();
        for x in [self.n, self.v, self.p, self.c, self.hx, self.hy] {
            f.extend(x);
        }
        f.extend([if self.two { 1.0 } else { 0.0 }, self.z, self.s]);
        f
    }

    fn cpu(&self) -> [f32; OUTS] {
        let add = |a: [f32; 3], b: [f32; 3]| std::array::from_fn(|i| a[i] + b[i]);
        let sub = |a: [f32; 3], b: [f32; 3]| std::array::from_fn(|i| a[i] - b[i]);
        let tri = [sub(self.c, self.hx), add(self.c, self.hx), add(self.c, self.hy)];
        [
            l::ltc_ggx_rect(self.t1, self.n, self.v, self.p, self.c, self.hx, self.hy, self.two),
            l::ltc_ggx_rect_sphere(self.t1, self.n, self.v, self.p, self.c, self.hx, self.hy, self.two),
            l::ltc_ggx_polygon(self.t1, self.n, self.v, self.p, &tri, self.two),
            l::ltc_ggx_sphere_clip(self.z, self.s),
        ]
    }
}

fn cases() -> Vec<Case> {
    let img = Ktx2Image::parse(l::LTC_GGX_1_F32_KTX2).expect("the module's RGBA32F KTX2");
    let lights: [([f32; 3], [f32; 3], [f32; 3]); 5] = [
        ([0.0, 0.0, 2.0], [0.5, 0.0, 0.0], [0.0, 0.5, 0.0]),
        ([-1.5, 0.2, 1.5], [0.0, 0.4, 0.0], [0.3, 0.0, 0.3]),
        ([-1.8, 0.0, 0.15], [0.0, -0.5, 0.0], [0.0, 0.0, 0.4]),
        ([0.3, 1.5, 1.0], [1.0, 0.0, 0.0], [0.0, -0.02, 0.05]),
        ([0.0, 0.0, 2.0], [0.0, 0.5, 0.0], [0.5, 0.0, 0.0]),
    ];
    let mut out = Vec::new();
    let mut k = 0usize;
    for j in (0..64).step_by(7) {
        for i in (0..64).step_by(7) {
            let t1 = img.texel_3d(i, j, 0);
            let x = j as f32 / 63.0;
            let cos = 1.0 - x * x;
            let v = [(1.0 - cos * cos).max(0.0).sqrt(), 0.0, cos];
            for &(c, hx, hy) in &lights {
                k += 1;
                let (z, s) = (-1.0 + 2.0 * ((k * 37) % 101) as f32 / 100.0, ((k * 53) % 97) as f32 / 96.0);
                // A tilted normal and an offset point now and then: the frame's construction.
                let (n, p) = if k % 3 == 0 { ([0.1, 0.2, 0.97], [0.05, -0.1, 0.0]) } else { ([0.0, 0.0, 1.0], [0.0; 3]) };
                out.push(Case { t1, n, v, p, c, hx, hy, two: k % 2 == 0, z, s });
            }
        }
    }
    let specials = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 1e30, -1e30, 0.0];
    for (m, &x) in specials.iter().enumerate() {
        let t1 = [1.0, 0.0, 0.0, 1.0];
        let base = Case { t1, n: [0.0, 0.0, 1.0], v: [0.6, 0.0, 0.8], p: [0.0; 3], c: [0.0, 0.0, 2.0], hx: [0.5, 0.0, 0.0], hy: [0.0, 0.5, 0.0], two: false, z: x, s: 0.5 };
        out.push(Case { t1: [x, 0.0, 0.0, 1.0], ..base });
        out.push(Case { n: [x, 0.0, 1.0], s: x, ..base_copy(&base) });
        out.push(Case { v: [x, x, x], ..base_copy(&base) });
        out.push(Case { p: [0.0, x, 0.0], two: m % 2 == 0, ..base_copy(&base) });
        out.push(Case { c: [x, 0.0, 2.0], hx: [x, x, 0.0], ..base_copy(&base) });
        out.push(base);
    }
    out
}

fn base_copy(b: &Case) -> Case {
    Case { t1: b.t1, n: b.n, v: b.v, p: b.p, c: b.c, hx: b.hx, hy: b.hy, two: b.two, z: b.z, s: b.s }
}

fn run_on_gpu(g: &gpu::Gpu, library: &str, inputs: &[f32], n: usize) -> Vec<f32> {
    let device = &g.device;
    let shader = format!(
        "{library}\n@group(0) @binding(0) var<storage, read> inp: array<f32>;\n\
         @group(0) @binding(1) var<storage, read_write> outp: array<f32>;\n\
         fn at3(o: u32) -> vec3<f32> {{ return vec3<f32>(inp[o], inp[o + 1u], inp[o + 2u]); }}\n\
         @compute @workgroup_size({WORKGROUP})\nfn main(@builtin(global_invocation_id) id: vec3<u32>) {{\n    \
         let b = {INS}u * id.x;\n    \
         let t1 = vec4<f32>(inp[b], inp[b + 1u], inp[b + 2u], inp[b + 3u]);\n    \
         let n = at3(b + 4u);\n    let v = at3(b + 7u);\n    let p = at3(b + 10u);\n    \
         let c = at3(b + 13u);\n    let hx = at3(b + 16u);\n    let hy = at3(b + 19u);\n    \
         let two = inp[b + 22u] > 0.5f;\n    \
         var tri: array<vec3<f32>, 8>;\n    tri[0] = c - hx;\n    tri[1] = c + hx;\n    tri[2] = c + hy;\n    \
         let o = {OUTS}u * id.x;\n    \
         outp[o] = ltc_ggx_rect(t1, n, v, p, c, hx, hy, two);\n    \
         outp[o + 1u] = ltc_ggx_rect_sphere(t1, n, v, p, c, hx, hy, two);\n    \
         outp[o + 2u] = ltc_ggx_polygon(t1, n, v, p, tri, 3u, two);\n    \
         outp[o + 3u] = ltc_ggx_sphere_clip(inp[b + 23u], inp[b + 24u]);\n}}\n"
    );
    let padded = n.div_ceil(WORKGROUP) * WORKGROUP;
    let mut data = inputs.to_vec();
    data.resize(padded * INS, 0.0);
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor { label: Some("ltc_ggx"), source: wgpu::ShaderSource::Wgsl(shader.into()) });
    let entries = [gpu::storage_entry(0, true), gpu::storage_entry(1, false)];
    let (bgl, pipeline) = gpu::compute_pipeline(device, "ltc_ggx", &module, "main", &entries);
    let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some("inputs"), contents: bytemuck::cast_slice(&data), usage: wgpu::BufferUsages::STORAGE });
    let (output, readback) = gpu::output_and_readback(device, (padded * OUTS * 4) as u64);
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("ltc_ggx"),
        layout: &bgl,
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: input.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: output.as_entire_binding() },
        ],
    });
    let bytes = gpu::dispatch_and_read(g, "ltc_ggx", &pipeline, &bind_group, (padded / WORKGROUP) as u32, &output, &readback);
    let all: Vec<f32> = bytemuck::pod_collect_to_vec(&bytes);
    all[..n * OUTS].to_vec()
}

/// The largest |GPU − CPU| per output over the cases; every GPU value must be in [0, 1].
fn worst(cases: &[Case], out: &[f32]) -> [f32; OUTS] {
    let mut w = [0.0f32; OUTS];
    for (k, (c, o)) in cases.iter().zip(out.chunks(OUTS)).enumerate() {
        assert!(o.iter().all(|x| (0.0..=1.0).contains(x)), "case {k}: GPU {o:?}");
        let r = c.cpu();
        for m in 0..OUTS {
            w[m] = w[m].max((o[m] - r[m]).abs());
        }
    }
    w
}

#[test]
fn ltc_light_functions_agree_with_their_cpu_twin_on_the_gpu() {
    let Some(g) = harness::device("shadefit LTC light test") else { return };
    let library = compose(&["ltc_ggx"]).expect("the ltc_ggx module");
    let cases = cases();
    let inputs: Vec<f32> = cases.iter().flat_map(|c| c.flat()).collect();
    let w = worst(&cases, &run_on_gpu(&g, &library, &inputs, cases.len()));
    report(&format!(
        "ltc_ggx on the GPU vs the CPU twin over {} cases: rect {:.2e}, rect_sphere {:.2e}, triangle {:.2e}, sphere_clip {:.2e} (bound {BOUND:.2e})",
        cases.len(),
        w[0],
        w[1],
        w[2],
        w[3]
    ));
    // The control: ltc_1's b and c swapped in the shader's reading of the texel.
    let misread = library.replace("return vec3<f32>(q.x * l.x + q.z * l.z, l.y, q.y * l.x + q.w * l.z);", "return vec3<f32>(q.x * l.x + q.y * l.z, l.y, q.z * l.x + q.w * l.z);");
    assert_ne!(misread, library, "the control's edit must apply");
    let c = worst(&cases, &run_on_gpu(&g, &misread, &inputs, cases.len()));
    report(&format!("control (ltc_1 misread): rect {:.2e}, rect_sphere {:.2e}, triangle {:.2e}", c[0], c[1], c[2]));
    assert!(w.iter().all(|&x| x <= BOUND), "GPU vs CPU {w:?} over the bound {BOUND}");
    assert!(c[..3].iter().all(|&x| x > BOUND), "the misread texel stays within the bound: {c:?}");
}
