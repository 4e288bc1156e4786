//! Shader timing: each emitted WGSL function (helpers aside) and each table's texture accessor
//! over a 3840×2160 compute dispatch on the adapter wgpu picks from the environment:
//!
//!     cargo test --release -p shadefit-runtime --test timing -- --ignored --nocapture
//!
//! Each invocation (one a pixel) calls the function `reps` times in a loop, on inputs that move
//! with the iteration (so no call can be hoisted), and writes the sum of the results; `reps` is
//! `SHADEFIT_TIMING_REPS` (default 64 on a GPU, 1 on a software adapter), except for a function
//! reading a `const` array at a computed index whose one call a pixel takes over 1 ms (tens of
//! ms for a large table: naga copies the array at each such read), timed at one. Two times per kernel, each the
//! best of five dispatches after a warm-up: the GPU's own, from timestamps written at the start
//! and the end of the compute pass (where the adapter offers `TIMESTAMP_QUERY`; the launch and
//! the submission excluded), and submit to completion as the host sees it. The cost of one call
//! over the 3840×2160 pixels is the GPU time less that of the baseline kernel with the same
//! loop (inputs and sum only), divided by `reps`: with one call a pixel an H100 reads about
//! 0.083 ms for every kernel, the loop's floor, and a single call hides under it.
//! Textures are bound from the modules' KTX2 bytes (skin LUTs, split-sum DFG and cone LUTs,
//! tables); a linear sampler on a 32-bit float texture needs `FLOAT32_FILTERABLE`, requested where
//! the adapter offers it.
//!
//! Operation counts of the same functions, next to their measured errors, are the shadefit
//! crate's `tests/op_counts.rs` (`cargo test --release --test op_counts -- --nocapture`);
//! `shadefit bench` ranks approximation forms by cost and error.

use shadefit_runtime::{compose, lut, skin, wgsl};

/// What a timed function needs: its library (self-contained WGSL) and what to bind.
struct Target {
    module: String,
    function: String,
    library: String,
    /// What to bind, or why it is not timed (printed in the table).
    bind: Result<timing::Bind, &'static str>,
    /// It indexes a module-scope `const` array at a computed index (a table in the shader).
    const_array: bool,
}

/// Helpers of an emitted library (its input clamp, texel coordinates) and of a table's texture
/// accessor: not timed on their own.
fn is_helper(module: &str, name: &str) -> bool {
    (name.starts_with(module) && name.ends_with("_input")) || name.ends_with("_coords") || name.ends_with("_uv") || name.ends_with("_tex_input") || name.ends_with("_tex_load")
}

fn parse(src: &str) -> naga::Module {
    naga::front::wgsl::parse_str(src).unwrap_or_else(|e| panic!("{}", e.emit_to_string(src)))
}

/// Whether `f` (or a function it calls) loads from a `const` array at a computed index.
fn reads_const_array(m: &naga::Module, f: &naga::Function) -> bool {
    use naga::Expression as E;
    f.expressions.iter().any(|(_, e)| match e {
        E::Access { base, .. } => matches!(f.expressions[*base], E::Constant(_)),
        E::CallResult(callee) => reads_const_array(m, &m.functions[*callee]),
        _ => false,
    })
}

/// Every emitted function and every table's texture accessor.
/// `features`: those the device was granted (a 32-bit float table sampled linearly needs
/// `FLOAT32_FILTERABLE`).
fn targets(features: wgpu::Features) -> Vec<Target> {
    let mut out = Vec::new();
    for &module in wgsl::NAMES {
        let library = compose(&[module]).unwrap();
        let m = parse(&library);
        for (_, f) in m.functions.iter() {
            let name = f.name.clone().unwrap_or_default();
            if is_helper(module, &name) {
                continue;
            }
            let sampled = f.arguments.iter().any(|a| matches!(m.types[a.ty].inner, naga::TypeInner::Image { .. }));
            let sampler = f.arguments.iter().any(|a| matches!(m.types[a.ty].inner, naga::TypeInner::Sampler { .. }));
            let table = lut::table(module).filter(|t| t.ktx2.is_some());
            let float32 = |t: &lut::Table| skin::Ktx2Image::parse(t.ktx2.expect("a KTX2 table")).expect("the table's KTX2").format.needs_float32_filterable();
            let bind = match (sampled, table, timing::ktx2(module)) {
                (true, Some(t), _) if !sampler => Ok(timing::Bind::TableKtx2 { table: t, linear: false }),
                (true, Some(t), _) if float32(t) && !features.contains(wgpu::Features::FLOAT32_FILTERABLE) => {
                    Err("a 32-bit float texture through a linear sampler; the adapter lacks FLOAT32_FILTERABLE")
                }
                (true, Some(t), _) => Ok(timing::Bind::TableKtx2 { table: t, linear: true }),
                (true, None, Some(k)) => Ok(timing::Bind::Ktx2(k)),
                (true, None, None) => Err("a texture this harness does not upload"),
                (false, ..) => Ok(timing::Bind::None),
            };
            out.push(Target { module: module.into(), const_array: reads_const_array(&m, f), function: name, library: library.clone(), bind });
        }
    }
    for t in lut::TABLES {
        out.push(Target {
            module: format!("{} (lut::Table::wgsl)", t.module),
            function: t.accessor_name(),
            library: t.wgsl(0, 2),
            bind: Ok(timing::Bind::Table(t)),
            const_array: false,
        });
    }
    out
}

#[test]
#[ignore = "timing: run with --ignored --nocapture"]
fn timing_over_a_4k_dispatch() {
    let optional = wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::FLOAT32_FILTERABLE;
    let g = match pollster::block_on(shadefit_runtime::gpu::headless_with("shader timing", optional)) {
        Ok(g) => g,
        Err(e) => {
            println!("timing SKIPPED: {e}");
            return;
        }
    };
    let info = g.adapter.get_info();
    let software = info.device_type == wgpu::DeviceType::Cpu;
    let features = g.device.features();
    println!("adapter: {}{}", shadefit_runtime::gpu::describe(&info), if software { " -- SOFTWARE RENDERING: CPU time, trend only" } else { "" });
    println!(
        "timestamp queries: {}; FLOAT32_FILTERABLE: {}",
        if features.contains(wgpu::Features::TIMESTAMP_QUERY) { "yes (GPU column: end-of-pass minus start-of-pass timestamp)" } else { "no (GPU column empty)" },
        if features.contains(wgpu::Features::FLOAT32_FILTERABLE) { "yes" } else { "no" }
    );
    let reps: u32 = match std::env::var("SHADEFIT_TIMING_REPS") {
        Ok(v) => v.parse().ok().filter(|&r| r >= 1).expect("SHADEFIT_TIMING_REPS: a whole number >= 1"),
        Err(_) if software => 1,
        Err(_) => 64,
    };
    let baseline = |reps: u32| timing::run(&g, "baseline", &timing::kernel("", "", "", "c0 + c1 + c2", reps), timing::Bind::None);
    let before = [baseline(1), baseline(reps)];
    println!(
        "\n| module | function | calls a pixel | GPU ms (timestamps) | GPU ms a call, baseline loop subtracted | ms submit to completion |\n|---|---|---:|---:|---:|---:|"
    );
    for t in targets(features) {
        let mut r = reps;
        let (gpu_ms, per_call, host_ms) = match &t.bind {
            Err(why) => ("-".to_string(), "-".to_string(), format!("- ({why})")),
            Ok(_) if software && t.const_array => ("-".to_string(), "-".to_string(), "- (const array)".to_string()),
            Ok(bind) => {
                // A const-array read: one call a pixel first, the loop only if that is cheap.
                let once = (t.const_array && reps > 1).then(|| timing::time(&g, &t, bind, 1));
                let times = match once {
                    Some(once) if once.gpu_ms.unwrap_or(once.host_ms) > 1.0 => {
                        r = 1;
                        once
                    }
                    _ => timing::time(&g, &t, bind, reps),
                };
                let base = if r == 1 { &before[0] } else { &before[1] };
                let per_call = times.gpu_ms.zip(base.gpu_ms).map_or("-".to_string(), |(f, b)| format!("{:.4}", (f - b) / r as f64));
                (times.gpu_text(), per_call, format!("{:.3}", times.host_ms))
            }
        };
        let calls = if host_ms.starts_with('-') { "-".to_string() } else { r.to_string() };
        println!("| {} | {} | {calls} | {gpu_ms} | {per_call} | {host_ms} |", t.module, t.function);
    }
    let after = [baseline(1), baseline(reps)];
    for (k, r) in [1, reps].into_iter().enumerate() {
        println!(
            "\nbaseline kernel (inputs and sum only, {r} a pixel), per 3840x2160 dispatch: GPU {} ms before, {} ms after the functions; submit to completion {:.3} ms before, {:.3} ms after",
            before[k].gpu_text(),
            after[k].gpu_text(),
            before[k].host_ms,
            after[k].host_ms
        );
    }
}

mod timing {
    use super::Target;
    use shadefit_runtime::{gpu, lut, skin};

    pub const W: u32 = 3840;
    pub const H: u32 = 2160;

    /// What a kernel binds besides its output buffer (binding 1).
    #[derive(Clone)]
    pub enum Bind {
        None,
        /// A table's R32Float texture at binding 2 (declared by `lut::Table::wgsl`).
        Table(&'static lut::Table),
        /// A LUT module's KTX2 texture (2-D or 3-D) and a linear sampler, at 2 and 3.
        Ktx2(&'static [u8]),
        /// A table's own KTX2 texture at 2 (`lut::Table::upload_ktx2`), read by its
        /// `FUNCTION_load`, or with `linear` by its `FUNCTION_sample` through the sampler at 3.
        TableKtx2 { table: &'static lut::Table, linear: bool },
    }

    /// One function's times per dispatch, each the best of five.
    pub struct Times {
        /// Submit to completion, as the host sees it.
        pub host_ms: f64,
        /// Between the pass's start and end timestamps; None without `TIMESTAMP_QUERY`.
        pub gpu_ms: Option<f64>,
    }

    impl Times {
        pub fn gpu_text(&self) -> String {
            self.gpu_ms.map_or("-".to_string(), |ms| format!("{ms:.4}"))
        }
    }

    /// `library`, extra declarations, and an entry point that runs the statement `call` `reps`
    /// times and writes the sum of `reduce` (an f32 expression of c0, c1, c2 and what `call`
    /// defines); c0 and c1 start at the pixel's position in [0, 1] and move by irrational steps
    /// with the iteration, c2 mixes them.
    pub fn kernel(library: &str, decls: &str, call: &str, reduce: &str, reps: u32) -> String {
        format!(
            "{library}\n{decls}\n@group(0) @binding(1) var<storage, read_write> shadefit_out: array<f32>;\n\n\
             @compute @workgroup_size(8, 8)\n\
             fn shadefit_main(@builtin(global_invocation_id) id: vec3<u32>) {{\n    \
                 let shadefit_b0 = f32(id.x) / {w}.0;\n    \
                 let shadefit_b1 = f32(id.y) / {h}.0;\n    \
                 var shadefit_sum = 0.0;\n    \
                 for (var shadefit_k = 0u; shadefit_k < {reps}u; shadefit_k++) {{\n        \
                     let c0 = select(fract(shadefit_b0 + f32(shadefit_k) * 0.618034), shadefit_b0, shadefit_k == 0u);\n        \
                     let c1 = select(fract(shadefit_b1 + f32(shadefit_k) * 0.414214), shadefit_b1, shadefit_k == 0u);\n        \
                     let c2 = fract(c0 * 7.0 + c1 * 3.0);\n        \
                     {call}\n        \
                     shadefit_sum += {reduce};\n    \
                 }}\n    \
                 shadefit_out[id.y * {W}u + id.x] = shadefit_sum;\n}}\n",
            w = W - 1,
            h = H - 1,
        )
    }

    /// The LUT texture a module's `_sample` functions read.
    pub fn ktx2(module: &str) -> Option<&'static [u8]> {
        match module {
            #[cfg(feature = "ggx")]
            "ggx_dfg_lut" => Some(shadefit_runtime::ggx_dfg_lut::GGX_DFG_LUT_KTX2),
            #[cfg(feature = "ggx")]
            "ggx_dfg_lut_filament" => Some(shadefit_runtime::ggx_dfg_lut_filament::GGX_DFG_LUT_FILAMENT_KTX2),
            #[cfg(feature = "ggx")]
            "ggx_cone_lut" => Some(shadefit_runtime::ggx_cone_lut::GGX_CONE_LUT_KTX2),
            #[cfg(feature = "skin")]
            "skin_punctual_lut" => Some(shadefit_runtime::skin_punctual_lut::SKIN_PUNCTUAL_LUT_KTX2),
            #[cfg(feature = "skin")]
            "skin_sh_lut" => Some(shadefit_runtime::skin_sh_lut::SKIN_SH_LUT_KTX2),
            _ => None,
        }
    }

    /// Times of the target's function, `reps` calls a pixel, with `bind` bound.
    pub fn time(g: &gpu::Gpu, t: &Target, bind: &Bind, reps: u32) -> Times {
        let sampler = "@group(0) @binding(3) var shadefit_smp: sampler;\n";
        let decls = match bind {
            Bind::Ktx2(bytes) => {
                let dims = if skin::Ktx2Image::parse(bytes).expect("the module's KTX2").depth == 0 { 2 } else { 3 };
                format!("@group(0) @binding(2) var shadefit_tex: texture_{dims}d<f32>;\n{sampler}")
            }
            Bind::TableKtx2 { linear, .. } => format!("@group(0) @binding(2) var shadefit_tex: texture_2d<f32>;\n{}", if *linear { sampler } else { "" }),
            _ => String::new(),
        };
        let m = super::parse(&t.library);
        let f = m.functions.iter().map(|(_, f)| f).find(|f| f.name.as_deref() == Some(t.function.as_str())).expect("the target's function");
        let floats = ["c0", "c1", "c2", "1.0 - c0"];
        let mut k = 0;
        let args: Vec<String> = f
            .arguments
            .iter()
            .map(|a| {
                let ty = &m.types[a.ty].inner;
                match ty {
                    naga::TypeInner::Scalar(s) if s.kind == naga::ScalarKind::Float => {
                        k += 1;
                        floats[(k - 1) % floats.len()].to_string()
                    }
                    naga::TypeInner::Scalar(s) if s.kind == naga::ScalarKind::Uint => "1u + (id.x & 1u)".into(),
                    naga::TypeInner::Vector { size: naga::VectorSize::Tri, .. } => "vec3<f32>(c0, c1, c2)".into(),
                    naga::TypeInner::Array { .. } => "array<f32, 6>(c0, c1, c2, 0.1, 0.2, 0.3)".into(),
                    naga::TypeInner::Image { .. } => "shadefit_tex".into(),
                    naga::TypeInner::Sampler { .. } => "shadefit_smp".into(),
                    // A struct of f32 fields (a decoded texel): the pixel's floats in turn.
                    naga::TypeInner::Struct { members, .. } => {
                        let name = m.types[a.ty].name.clone().expect("a named struct");
                        let fields: Vec<&str> = (0..members.len()).map(|i| floats[i % floats.len()]).collect();
                        format!("{name}({})", fields.join(", "))
                    }
                    other => panic!("{}: no timing argument for {other:?}", t.function),
                }
            })
            .collect();
        let result = f.result.as_ref().map(|res| &m.types[res.ty].inner);
        let reduce = match result {
            Some(naga::TypeInner::Scalar(_)) => "r".to_string(),
            Some(naga::TypeInner::Vector { size, .. }) => (0..*size as usize).map(|i| format!("r[{i}]")).collect::<Vec<_>>().join(" + "),
            Some(naga::TypeInner::Array { size: naga::ArraySize::Constant(n), .. }) => {
                (0..n.get() as usize).map(|i| format!("r[{i}]")).collect::<Vec<_>>().join(" + ")
            }
            Some(naga::TypeInner::Struct { members, .. }) => {
                members.iter().map(|m| format!("r.{}", m.name.as_deref().unwrap_or_default())).collect::<Vec<_>>().join(" + ")
            }
            other => panic!("{}: no reduction of {other:?}", t.function),
        };
        let call = format!("let r = {}({});", t.function, args.join(", "));
        run(g, &t.function, &kernel(&t.library, &decls, &call, &reduce, reps), bind.clone())
    }

    /// Compile, warm up, then five timed dispatches: the best of each time.
    pub fn run(g: &gpu::Gpu, label: &str, shader: &str, bind: Bind) -> Times {
        let device = &g.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(label),
            source: wgpu::ShaderSource::Wgsl(shader.into()),
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(label),
            layout: None,
            module: &module,
            entry_point: Some("shadefit_main"),
            compilation_options: Default::default(),
            cache: None,
        });
        let out = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("out"),
            size: W as u64 * H as u64 * 4,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let table;
        let table_ktx2;
        let ktx;
        let view;
        let sampler;
        let mut entries = vec![wgpu::BindGroupEntry { binding: 1, resource: out.as_entire_binding() }];
        match bind {
            Bind::None => {}
            Bind::Table(t) => {
                table = t.create_texture(device, &g.queue);
                entries.push(wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&table.view) });
            }
            Bind::TableKtx2 { table: t, linear } => {
                table_ktx2 = t.upload_ktx2(device, &g.queue, linear).expect("the table's KTX2").expect("KTX2");
                entries.push(wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&table_ktx2.view) });
                if linear {
                    entries.push(wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::Sampler(&table_ktx2.sampler) });
                }
            }
            Bind::Ktx2(bytes) => {
                ktx = skin::create_lut_texture(device, &g.queue, label, bytes).expect("KTX2");
                view = ktx.create_view(&Default::default());
                sampler = skin::lut_sampler(device);
                entries.push(wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&view) });
                entries.push(wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::Sampler(&sampler) });
            }
        }
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(label),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &entries,
        });
        // Two timestamps a dispatch (start and end of the pass), resolved into a buffer and
        // copied to one the host maps; ticks × `get_timestamp_period()` ns.
        let stamps = device.features().contains(wgpu::Features::TIMESTAMP_QUERY).then(|| {
            let set = device.create_query_set(&wgpu::QuerySetDescriptor { label: Some(label), ty: wgpu::QueryType::Timestamp, count: 2 });
            let resolve = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamps"),
                size: 16,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let read = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamps read back"),
                size: 16,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            });
            (set, resolve, read)
        });
        let period_ns = g.queue.get_timestamp_period() as f64;
        let dispatch = || -> (f64, Option<f64>) {
            let mut encoder = device.create_command_encoder(&Default::default());
            {
                let timestamp_writes = stamps.as_ref().map(|(set, ..)| wgpu::ComputePassTimestampWrites {
                    query_set: set,
                    beginning_of_pass_write_index: Some(0),
                    end_of_pass_write_index: Some(1),
                });
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(label), timestamp_writes });
                pass.set_pipeline(&pipeline);
                pass.set_bind_group(0, &bind_group, &[]);
                pass.dispatch_workgroups(W / 8, H / 8, 1);
            }
            if let Some((set, resolve, read)) = &stamps {
                encoder.resolve_query_set(set, 0..2, resolve, 0);
                encoder.copy_buffer_to_buffer(resolve, 0, read, 0, 16);
            }
            let t0 = std::time::Instant::now();
            g.queue.submit([encoder.finish()]);
            device.poll(wgpu::PollType::wait_indefinitely()).expect("poll");
            let host = t0.elapsed().as_secs_f64() * 1e3;
            let gpu = stamps.as_ref().map(|(_, _, read)| {
                let (tx, rx) = std::sync::mpsc::channel();
                read.slice(..).map_async(wgpu::MapMode::Read, move |r| tx.send(r).unwrap());
                device.poll(wgpu::PollType::wait_indefinitely()).expect("poll");
                rx.recv().unwrap().expect("map the timestamps");
                let ticks: [u64; 2] = bytemuck::pod_read_unaligned(&read.slice(..).get_mapped_range().expect("mapped")[..16]);
                read.unmap();
                ticks[1].wrapping_sub(ticks[0]) as f64 * period_ns * 1e-6
            });
            (host, gpu)
        };
        dispatch();
        let runs: Vec<(f64, Option<f64>)> = (0..5).map(|_| dispatch()).collect();
        Times {
            host_ms: runs.iter().map(|r| r.0).fold(f64::INFINITY, f64::min),
            gpu_ms: runs.iter().map(|r| r.1).collect::<Option<Vec<f64>>>().map(|v| v.into_iter().fold(f64::INFINITY, f64::min)),
        }
    }
}
