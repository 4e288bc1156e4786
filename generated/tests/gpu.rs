//! Every emitted function, run on a GPU through wgpu, equals its CPU version within a bound
//! derived from f32 rounding; so does the texture version of every lookup table.
//!
//! For each entry of `FUNCTIONS` a compute shader is composed from the function's WGSL
//! library and a generated entry point that reads each argument as a `u32` bit pattern from a
//! storage buffer (`bitcast<f32>`: WGSL literals cannot spell NaN, ±inf or every subnormal) and
//! writes the result's bits. Inputs per argument (tests/support/grid.rs): the domain edges and
//! their f32 neighbours, values outside, ±0, subnormals, ±MIN_POSITIVE, ±1, ±MAX, ±inf, five
//! NaN patterns, a dense grid over the domain (2^16 points for one argument, 256 per axis for
//! two, 16 for three) and, for tables, every node and cell centre (at most 8 intervals per axis
//! for three arguments); all combinations for two and three arguments.
//!
//! # Bound
//! Per point, |GPU − CPU| ≤ d, with d computed by interpreting the same WGSL (naga IR) in f32
//! and carrying, in affine form so that correlated deviations cancel, what the WGSL spec (and
//! Vulkan) allow a GPU to do differently (tests/support/bound.rs): `+ − ×` correctly rounded
//! (1 ulp of the result once the operands differ), FMA contraction of any `a*b ± c` (½ ulp of
//! the product + 1 ulp of the result), division within 2.5 ulp on the GPU versus 0.5 ulp on
//! the CPU (3 ulp of the quotient, plus the operands' deviations through (Δa − qΔb)/b),
//! subnormals possibly flushed to zero, sin/cos within 2^-11 absolute on [−π, π] (plus the
//! CPU libm's own error, measured against f64 at each point). Over this grid d is at most
//! 4.5 ulp of the value for the `gloss_table` lerp and 19 ulp for the `gloss_length` rational
//! (a dozen operations, one divide), more in ulps only where a value is small or a table step
//! large: the index math `t − f32(i)` may itself be fused on a GPU, which moves the lerp
//! weight by ½ ulp of t. The interpreter's value is the CPU value bit for bit, and d holds for
//! simulated GPUs that fuse everything, misround divisions by 2 ulp, flush subnormals and
//! move sin/cos by 0.999·2^-11 (tests/wgsl_cpu.rs). A
//! GPU NaN or inf is always a failure: the emitted functions are finite for every input.
//!
//! The sin/cos allowance dominates where the fuzz family uses them (`fuzz_average_ps`,
//! `fuzz_ps_coeffs`: θf enters through sin θf and cos θf): d reaches 1.8e-3 and 0.14 there,
//! above the fits' own errors, because WGSL promises no more. Next to the pass/fail ratio the
//! test prints the ratio to the bound with a 2^-22 allowance instead, to show how close a GPU
//! came. On a software adapter (lavapipe in CI, whose sin/cos are LLVM's f32 libm calls, within
//! an ulp or two) that ratio must stay below 1: asserted, so a regression of the emitted trig
//! arithmetic that WGSL's loose 2^-11 would hide still fails in CI.
//!
//! # fuzz_ps
//! `fuzz_ps_coeffs` (array result) and `fuzz_ps` (array argument) are not in `FUNCTIONS`; the
//! second test runs them through the scalar wrappers of tests/support/fuzz_ps.rs: the six
//! coefficients over (α, θf), the evaluator on exact coefficients over (n·u, t·u), and the two
//! chained, each point with its special values, against the same bound.
//!
//! # Tables on software adapters
//! On a CPU adapter (lavapipe in CI) the table functions run with their `const` table moved to
//! a storage buffer (same values, parsed from the WGSL; function body unchanged), because
//! lavapipe needs minutes per shader for a dynamically indexed 4096-entry `const` array (see
//! `table_in_buffer`). Hardware adapters run the emitted text as it is. The texture version
//! of each table (`lut::Table::wgsl`, R32Float) is checked against the same bound everywhere.
//!
//! # Import styles
//! The shaders above are the crate's flat form: `compose(&[MODULE])`, then an entry point
//! calling `f(..)`. For every function the first `STYLE_POINTS` points also run through the
//! two other forms an engine uses, and their result bits must equal the flat run's: naga_oil's
//! prefixed style (`#import shadefit::MODULE` and a call to `MODULE::f(..)`, resolved by
//! `compose_shader`), and the plain WGSL (the module without its `#define_import_path` line,
//! what `build --target wgsl-plain` writes) with the entry point appended. Same arithmetic, so
//! any difference is a composition error, never rounding.
//!
//! # Adapter
//! wgpu picks the adapter from the environment (`WGPU_BACKEND=vulkan` in CI, where lavapipe
//! from scripts/setup-vulkan provides it; `WGPU_ADAPTER_NAME` to choose among several). With
//! no adapter the test fails if `CI` is set (non-empty, not `0`/`false`) and is skipped with
//! a message otherwise. The adapter, the counts and the deviations are written to stderr
//! directly (not captured by the test harness, so they appear in `scripts/test`'s log).

#[path = "support/bound.rs"]
mod bound;
#[path = "support/grid.rs"]
mod grid;
#[path = "support/harness.rs"]
mod harness;
#[cfg(feature = "fuzz")]
#[path = "support/fuzz_ps.rs"]
mod fuzz_ps;
#[cfg(feature = "sggx")]
#[path = "support/sggx.rs"]
mod sggx;

use shadefit_runtime::lut::{self, LutTexture};
use shadefit_runtime::{EmittedFunction, FUNCTIONS, compose, compose_shader, gpu, wgsl};
use harness::{device, report};
use wgpu::util::DeviceExt;

const WORKGROUP: u32 = 64;

/// WGSL entry point: `out[i] = bits(call(in[i*arity .. i*arity+arity]))`, or for a function
/// returning `array<f32, outputs>` its elements at `out[i*outputs ..]`. No bounds test: the
/// inputs are padded to whole workgroups (a branch around a call that indexes a large `const`
/// array makes lavapipe's LLVM coroutine lowering take many minutes).
fn entry_point(call: &str, arity: usize, outputs: usize) -> String {
    let args: Vec<String> = (0..arity).map(|k| format!("bitcast<f32>(shadefit_in[i * {arity}u + {k}u])")).collect();
    let body = if outputs == 1 {
        format!("shadefit_out[i] = bitcast<u32>({call}({}));", args.join(", "))
    } else {
        let mut b = format!("let r = {call}({});", args.join(", "));
        for k in 0..outputs {
            b += &format!("\n    shadefit_out[i * {outputs}u + {k}u] = bitcast<u32>(r[{k}]);");
        }
        b
    };
    format!(
        "\n@group(0) @binding(0) var<storage, read> shadefit_in: array<u32>;\n\
         @group(0) @binding(1) var<storage, read_write> shadefit_out: array<u32>;\n\n\
         @compute @workgroup_size({WORKGROUP})\n\
         fn shadefit_main(@builtin(global_invocation_id) id: vec3<u32>) {{\n    \
             let i = id.x;\n    \
             {body}\n}}\n"
    )
}

/// The library with its `const NAME_TABLE: array<f32, N> = array<f32, N>(...);` replaced by
/// `@group(0) @binding(3) var<storage, read> NAME_TABLE: array<f32, N>;`, and the values of the
/// const (parsed from the WGSL literals) to put in that buffer. The function body is unchanged.
///
/// Why: naga compiles a dynamic index into a `const` array by copying the whole array into a
/// function-local variable at each indexing expression, and lavapipe (Mesa 22.3) keeps those
/// copies: 4 × 4096 stores per invocation for the 64×64 table. Measured here on 2 cores: 569 s
/// for `combine_gloss_lut` (even with `var<private>`), 54 s for `normal_length_to_gloss_lut`.
/// Used on software adapters only; hardware adapters run the emitted text as it is.
fn table_in_buffer(library: &str, module: &str) -> (String, Vec<f32>) {
    let upper = module.to_uppercase();
    let head = format!("const {upper}_TABLE: array<f32, ");
    let start = library.find(&head).unwrap_or_else(|| panic!("{module}: no `{head}`"));
    let open = library[start..].find('(').unwrap() + start;
    let close = library[open..].find(");").unwrap() + open;
    let n = &library[start + head.len()..library[start..].find('>').unwrap() + start];
    let values: Vec<f32> = library[open + 1..close]
        .split(',')
        .map(str::trim)
        .filter(|v| !v.is_empty())
        .map(|v| v.trim_end_matches('f').parse().unwrap_or_else(|e| panic!("{module}: table literal {v:?}: {e}")))
        .collect();
    assert_eq!(values.len().to_string(), n, "{module}: table length");
    let decl = format!("@group(0) @binding(3) var<storage, read> {upper}_TABLE: array<f32, {n}>;");
    (format!("{}{decl}{}", &library[..start], &library[close + 2..]), values)
}

/// What a shader binds besides its input and output buffers.
enum Extra<'a> {
    None,
    /// A lookup texture at binding 2.
    Lut(&'a LutTexture),
    /// A read-only f32 storage buffer at binding 3.
    Table(&'a [f32]),
}

struct Runner {
    gpu: gpu::Gpu,
}

impl Runner {
    /// Run `shader` (entry `shadefit_main`) over `inputs` (arity words per point, `outputs`
    /// words out); `extra` is bound at binding 2 or 3 when given.
    fn run(&self, label: &str, shader: &str, arity: usize, outputs: usize, inputs: &[u32], extra: Extra) -> Vec<u32> {
        let device = &self.gpu.device;
        let n = inputs.len() / arity;
        let padded = (n as u32).div_ceil(WORKGROUP) as usize * WORKGROUP as usize;
        let mut inputs = inputs.to_vec();
        for _ in n..padded {
            inputs.extend_from_within(..arity);
        }
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(label),
            source: wgpu::ShaderSource::Wgsl(shader.into()),
        });
        let storage = gpu::storage_entry;
        let mut entries = vec![storage(0, true), storage(1, false)];
        match extra {
            Extra::None => {}
            Extra::Lut(_) => entries.push(LutTexture::texture_entry(2, wgpu::ShaderStages::COMPUTE)),
            Extra::Table(_) => entries.push(storage(3, true)),
        }
        let (bgl, pipeline) = gpu::compute_pipeline(device, label, &module, "shadefit_main", &entries);
        let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("inputs"),
            contents: bytemuck::cast_slice(&inputs),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let size = (padded * outputs * 4) as u64;
        let (output, readback) = gpu::output_and_readback(device, size);
        let mut bind = vec![
            wgpu::BindGroupEntry { binding: 0, resource: input.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: output.as_entire_binding() },
        ];
        let table = match extra {
            Extra::Table(values) => Some(device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("table"),
                contents: bytemuck::cast_slice(values),
                usage: wgpu::BufferUsages::STORAGE,
            })),
            _ => None,
        };
        match (&extra, &table) {
            (Extra::Lut(l), _) => {
                bind.push(wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&l.view) })
            }
            (Extra::Table(_), Some(b)) => bind.push(wgpu::BindGroupEntry { binding: 3, resource: b.as_entire_binding() }),
            _ => {}
        }
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(label), layout: &bgl, entries: &bind });
        let bytes = gpu::dispatch_and_read(&self.gpu, label, &pipeline, &bind_group, padded as u32 / WORKGROUP, &output, &readback);
        let out: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
        out[..n * outputs].to_vec()
    }
}

/// Deviations of one run: the largest |GPU − CPU| (and the CPU value there), the largest
/// ratio deviation / bound over the points, and for code with sin/cos the largest ratio to
/// the bound with a sin/cos allowance of 2^-22 instead of WGSL's 2^-11 (information only).
struct Stats {
    max_abs: f64,
    value_at_max: f32,
    max_ratio: f64,
    tight_ratio: Option<f64>,
}

/// The tighter sin/cos allowance of `Stats::tight_ratio`: about 2 ulp at magnitude 1.
const TIGHT_TRIG: f64 = 1.0 / (1u64 << 22) as f64;

impl std::fmt::Display for Stats {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.max_abs == 0.0 {
            write!(f, "max |GPU-CPU| 0 (bit-identical), max deviation/bound 0")?;
        } else {
            write!(
                f,
                "max |GPU-CPU| {:.3e} (= {:.1} ulp of the CPU value {:.3e}), max deviation/bound {:.2e}",
                self.max_abs,
                self.max_abs / bound::ulp(self.value_at_max as f64),
                self.value_at_max,
                self.max_ratio
            )?;
        }
        if let Some(t) = self.tight_ratio {
            write!(f, " (bound with sin/cos within 2^-22 instead of 2^-11: max deviation/bound {t:.2e})")?;
        }
        Ok(())
    }
}

/// On a software adapter, the deviation of code with sin/cos within the bound with the 2^-22
/// allowance (module docs); hardware GPUs may use WGSL's whole 2^-11.
fn assert_tight_on_software(software: bool, name: &str, st: &Stats) {
    if let (true, Some(t)) = (software, st.tight_ratio) {
        assert!(t <= 1.0, "{name}: on a software adapter the deviation exceeds the bound with sin/cos within 2^-22 (ratio {t:.2e})");
    }
}

/// Compare GPU results with the CPU at every point against the bound; `Err` lists the first
/// points out of bound.
fn check(f: &EmittedFunction, what: &str, pts: &[u32], gpu_bits: &[u32], program: &bound::Program) -> Result<Stats, String> {
    let h = program.function(f.name);
    check_points(program, h, f.domain.len(), 1, pts, gpu_bits, &|p| vec![grid::cpu(f, p)], &|p| grid::show(f, p), what)
}

/// [`check`] for `h` in `program` with `arity` arguments and `outputs` results per point;
/// `cpu` gives the CPU values of a point, `show` names it in messages.
#[allow(clippy::too_many_arguments)]
fn check_points(
    program: &bound::Program,
    h: naga::Handle<naga::Function>,
    arity: usize,
    outputs: usize,
    pts: &[u32],
    gpu_bits: &[u32],
    cpu: &dyn Fn(&[u32]) -> Vec<f32>,
    show: &dyn Fn(&[u32]) -> String,
    what: &str,
) -> Result<Stats, String> {
    let trig = program.uses_trig(h);
    let mut st = Stats { max_abs: 0.0, value_at_max: 0.0, max_ratio: 0.0, tight_ratio: trig.then_some(0.0) };
    let mut failures = Vec::new();
    for (p, g) in pts.chunks(arity).zip(gpu_bits.chunks(outputs)) {
        let args: Vec<f32> = p.iter().map(|&b| f32::from_bits(b)).collect();
        let c = cpu(p);
        let bounds = program.eval_all(h, &args);
        let tight = if trig {
            program.set_trig_allowance(TIGHT_TRIG);
            let t = program.eval_all(h, &args);
            program.set_trig_allowance(bound::WGSL_TRIG_ALLOWANCE);
            t
        } else {
            Vec::new()
        };
        for k in 0..outputs {
            let (c, d) = (c[k], bounds[k].1);
            let gv = f32::from_bits(g[k]);
            let dev = (gv as f64 - c as f64).abs();
            if !(gv.is_finite() && dev <= d) {
                failures.push(format!("{}[{k}] [{what}]: GPU {gv:e}, CPU {c:e}, deviation {dev:e} > bound {d:e}", show(p)));
                continue;
            }
            if dev > st.max_abs {
                st.max_abs = dev;
                st.value_at_max = c;
            }
            if d > 0.0 {
                st.max_ratio = st.max_ratio.max(dev / d);
            }
            if let (Some(r), Some((_, t))) = (st.tight_ratio.as_mut(), tight.get(k))
                && *t > 0.0
            {
                *r = r.max(dev / t);
            }
        }
    }
    if !failures.is_empty() {
        return Err(format!(
            "{} of {} values out of bound, first ones:\n{}",
            failures.len(),
            gpu_bits.len(),
            failures[..failures.len().min(20)].join("\n")
        ));
    }
    Ok(st)
}

/// Every GPU result of a table lookup lies within the range [lo, hi] of the table's values,
/// less 8 ulp of |lo| below and more 8 ulp of |hi| above: a lerp `a·(1 − f) + b·f` with f in
/// [0, 1] stays within [min(a, b), max(a, b)] but for the rounding of `1 − f`, the two products
/// and the sum (each ≤ ½ ulp, relative), at each of at most two levels, so by at most 6·2^-24
/// of the bound, under 8 ulp of it, whatever a GPU fuses. A weight outside [0, 1] (an index a
/// GPU rounds past a node, the H200's −7.98e-9 below a table of values ≥ 0) leaves the range
/// by a share of a table step, far more where the bound is 0 or small.
fn within_table_range(t: &lut::Table, what: &str, pts: &[u32], arity: usize, gpu_bits: &[u32]) -> Result<(), String> {
    let lo = t.values.iter().copied().fold(f32::INFINITY, f32::min) as f64;
    let hi = t.values.iter().copied().fold(f32::NEG_INFINITY, f32::max) as f64;
    let (lo_ok, hi_ok) = (lo - 8.0 * bound::ulp(lo.abs()), hi + 8.0 * bound::ulp(hi.abs()));
    let outside: Vec<String> = pts
        .chunks(arity)
        .zip(gpu_bits)
        .filter(|&(_, &g)| !(lo_ok..=hi_ok).contains(&(f32::from_bits(g) as f64)))
        .map(|(p, &g)| format!("{:?} [{what}]: GPU {:e} outside the table's [{lo:e}, {hi:e}]", p.iter().map(|&b| f32::from_bits(b)).collect::<Vec<_>>(), f32::from_bits(g)))
        .collect();
    match outside.len() {
        0 => Ok(()),
        n => Err(format!("{n} of {} values outside the table's range, first ones:\n{}", gpu_bits.len(), outside[..n.min(20)].join("\n"))),
    }
}

/// Report one run of `name` over `n` points: its deviations, or that it is out of bound (the
/// points then go to `failed`, for the test to list every such run before it fails).
fn outcome(name: &str, n: usize, note: &str, secs: f64, software: bool, result: Result<Stats, String>, failed: &mut Vec<String>) {
    match result {
        Ok(st) => {
            report(&format!("gpu {name:<30} {n:>7} points: {st}{note} [{secs:.1} s]"));
            assert_tight_on_software(software, name, &st);
        }
        Err(e) => {
            report(&format!("gpu {name:<30} {n:>7} points: OUT OF BOUND{note} [{secs:.1} s]"));
            failed.push(format!("{name}: {e}"));
        }
    }
}

#[test]
fn every_emitted_function_equals_its_cpu_version_on_the_gpu() {
    let Some(gpu) = device("shadefit-runtime gpu test") else { return };
    let software = gpu.adapter.get_info().device_type == wgpu::DeviceType::Cpu;
    let runner = Runner { gpu };
    let (mut functions, mut points, mut runs) = (0, 0, 0);
    // Every function runs whatever an earlier one gave: one run lists all that fail.
    let mut failed = Vec::new();
    for f in FUNCTIONS {
        let library = compose(&[f.module]).unwrap();
        let program = bound::Program::new(&library);
        let table = lut::table(f.module);
        let counts = table.map(|t| t.counts()).unwrap_or_default();
        let pts = grid::points(f, &counts);
        let arity = f.domain.len();
        let n = pts.len() / arity;

        let moved = table.filter(|_| software).map(|t| table_in_buffer(&library, t.module));
        let (shader, extra, note) = match &moved {
            Some((lib, values)) => (lib.clone(), Extra::Table(values), " (table in a storage buffer)"),
            None => (library.clone(), Extra::None, ""),
        };
        let shader = shader + &entry_point(f.name, arity, 1);
        let t0 = std::time::Instant::now();
        let out = runner.run(f.name, &shader, arity, 1, &pts, extra);
        let secs = t0.elapsed().as_secs_f64();
        outcome(f.name, n, note, secs, software, check(f, "const", &pts, &out, &program), &mut failed);
        if let Some(Err(e)) = table.map(|t| within_table_range(t, "const", &pts, arity, &out)) {
            failed.push(format!("{}: {e}", f.name));
        }
        same_in_every_style(&runner, f, &pts, &out, moved.as_ref().map(|(_, v)| v.as_slice()));
        functions += 1;
        points += n;
        runs += 1;

        if let Some(t) = table {
            let lut = t.create_texture(&runner.gpu.device, &runner.gpu.queue);
            let shader = t.wgsl(0, 2) + &entry_point(&t.accessor_name(), arity, 1);
            let t0 = std::time::Instant::now();
            let out = runner.run(&t.accessor_name(), &shader, arity, 1, &pts, Extra::Lut(&lut));
            let secs = t0.elapsed().as_secs_f64();
            // Same arithmetic as the emitted function, values fetched from the texture: same bound.
            let (w, h) = t.size();
            let note = format!(" (R32Float {w}x{h} texture)");
            outcome(&t.accessor_name(), n, &note, secs, software, check(f, "texture", &pts, &out, &program), &mut failed);
            if let Err(e) = within_table_range(t, "texture", &pts, arity, &out) {
                failed.push(format!("{}: {e}", t.accessor_name()));
            }
            points += n;
            runs += 1;
        }
    }
    assert!(failed.is_empty(), "{} of {runs} runs out of bound:\n\n{}", failed.len(), failed.join("\n\n"));
    report(&format!("gpu: {functions} emitted functions + {} texture versions, {points} points, all within bound, the tables' within their values' range", runs - functions));
}

/// How many points of each function run in the other import styles (a pipeline each; the
/// points are the first ones of the grid of tests/support/grid.rs).
const STYLE_POINTS: usize = 512;

/// `f` composed in naga_oil's prefixed style and as plain WGSL gives the flat run's bits `out`
/// on the first `STYLE_POINTS` points. `table`: on software adapters, the table in a storage
/// buffer as in the flat run.
fn same_in_every_style(runner: &Runner, f: &EmittedFunction, pts: &[u32], out: &[u32], table: Option<&[f32]>) {
    let arity = f.domain.len();
    let k = (pts.len() / arity).min(STYLE_POINTS);
    let prefixed = format!("#import shadefit::{}\n{}", f.module, entry_point(&format!("{}::{}", f.module, f.name), arity, 1));
    let prefixed = compose_shader(&prefixed).unwrap_or_else(|e| panic!("{}: {e}", f.name));
    let src = wgsl::module(f.module).unwrap();
    assert_eq!(src.lines().filter(|l| l.starts_with('#')).count(), 1, "{}: one directive", f.module);
    let plain: String = src.lines().filter(|l| !l.starts_with("#define_import_path")).map(|l| format!("{l}\n")).collect();
    let plain = plain + &entry_point(f.name, arity, 1);
    for (style, shader) in [("prefixed", prefixed), ("plain", plain)] {
        let (shader, extra) = match table {
            Some(_) => (table_in_buffer(&shader, f.module).0, table.map_or(Extra::None, Extra::Table)),
            None => (shader, Extra::None),
        };
        let got = runner.run(&format!("{} ({style})", f.name), &shader, arity, 1, &pts[..k * arity], extra);
        let differ = (0..k).filter(|&i| got[i] != out[i]).count();
        assert_eq!(differ, 0, "{}: {differ} of {k} results differ between the flat and the {style} composition", f.name);
    }
}

/// The P̃_s pair of the fuzz family (array result and argument, so not in `FUNCTIONS`): the
/// coefficients, the evaluator on exact coefficients and the two chained, through the scalar
/// wrappers of tests/support/fuzz_ps.rs, against the same bound.
#[cfg(feature = "fuzz")]
#[test]
fn fuzz_ps_pair_equals_its_cpu_version_on_the_gpu() {
    let Some(gpu) = device("shadefit-runtime gpu test (fuzz_ps)") else { return };
    let software = gpu.adapter.get_info().device_type == wgpu::DeviceType::Cpu;
    let runner = Runner { gpu };
    let library = compose(&["fuzz_ps"]).unwrap() + fuzz_ps::WRAPPERS;
    let program = bound::Program::new(&library);
    for case in fuzz_ps::cases() {
        let shader = library.clone() + &entry_point(case.name, case.arity, case.outputs);
        let t0 = std::time::Instant::now();
        let out = runner.run(case.name, &shader, case.arity, case.outputs, &case.points, Extra::None);
        let secs = t0.elapsed().as_secs_f64();
        let h = program.function(case.name);
        let cpu = |p: &[u32]| (case.cpu)(&p.iter().map(|&b| f32::from_bits(b)).collect::<Vec<_>>());
        let show = |p: &[u32]| fuzz_ps::show(case.name, p);
        let st = check_points(&program, h, case.arity, case.outputs, &case.points, &out, &cpu, &show, "const").unwrap_or_else(|e| panic!("{}: {e}", case.name));
        let n = case.points.len() / case.arity;
        report(&format!("gpu {:<30} {n:>7} points x {}: {st} [{secs:.1} s]", case.name, case.outputs));
        assert_tight_on_software(software, case.name, &st);
    }
}

/// The SGGX decoder (one wrapper per decoded field) and D of a decoded texel, through the scalar
/// wrappers of tests/support/sggx.rs, against the same bound.
#[cfg(feature = "sggx")]
#[test]
fn sggx_decoder_and_ndf_equal_their_cpu_versions_on_the_gpu() {
    let Some(gpu) = device("shadefit-runtime gpu test (sggx_decode)") else { return };
    let software = gpu.adapter.get_info().device_type == wgpu::DeviceType::Cpu;
    let runner = Runner { gpu };
    let library = compose(&["sggx_decode"]).unwrap() + sggx::WRAPPERS;
    let program = bound::Program::new(&library);
    let mut cases: Vec<(&str, usize, Vec<u32>)> = sggx::FIELDS.iter().map(|f| (f.0, 3, sggx::decode_points())).collect();
    cases.push(("t_d", 6, sggx::d_points()));
    for (name, arity, points) in cases {
        let shader = library.clone() + &entry_point(name, arity, 1);
        let out = runner.run(name, &shader, arity, 1, &points, Extra::None);
        let h = program.function(name);
        let cpu = |p: &[u32]| {
            let a: Vec<f32> = p.iter().map(|&b| f32::from_bits(b)).collect();
            vec![if name == "t_d" { sggx::cpu_d(&a) } else { sggx::cpu_field(name, &a) }]
        };
        let show = |p: &[u32]| format!("{name}{:?}", p.iter().map(|&b| f32::from_bits(b)).collect::<Vec<_>>());
        let st = check_points(&program, h, arity, 1, &points, &out, &cpu, &show, "const").unwrap_or_else(|e| panic!("{name}: {e}"));
        report(&format!("gpu {name:<30} {:>7} points: {st}", points.len() / arity));
        assert_tight_on_software(software, name, &st);
    }
}
