//! Shader timing: each emitted WGSL function (helpers aside) and each table's texture accessor
//! over a 3840×2160 compute dispatch on the adapter wgpu picks from the environment:
//!
//!     cargo test --release -p shadefit-runtime --test timing -- --ignored --nocapture
//!
//! Operation counts of the same functions, next to their measured errors, are the shadefit
//! crate's `tests/op_counts.rs` (`cargo test --release --test op_counts -- --nocapture`);
//! `shadefit bench` ranks approximation forms by cost and error.

use shadefit_runtime::{compose, lut, wgsl};

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
fn targets() -> Vec<Target> {
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
            let bind = match (sampled, table, timing::ktx2(module)) {
                (true, Some(t), _) if !sampler => Ok(timing::Bind::TableKtx2(t)),
                (true, Some(_), _) => Err("a table's R32Float texture through a linear sampler"),
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
    let g = match pollster::block_on(shadefit_runtime::gpu::headless("shader timing")) {
        Ok(g) => g,
        Err(e) => {
            println!("timing SKIPPED: {e}");
            return;
        }
    };
    let info = g.adapter.get_info();
    let software = info.device_type == wgpu::DeviceType::Cpu;
    println!("adapter: {}{}", shadefit_runtime::gpu::describe(&info), if software { " -- SOFTWARE RENDERING: CPU time, trend only" } else { "" });
    let baseline = || timing::run(&g, "baseline", &timing::kernel("", "", "", "c0 + c1 + c2"), timing::Bind::None);
    let before = baseline();
    println!("\n| module | function | ms per 3840x2160 dispatch |\n|---|---|---:|");
    for t in targets() {
        let ms = match &t.bind {
            Err(why) => format!("- ({why})"),
            Ok(_) if software && t.const_array => "- (const array)".to_string(),
            Ok(bind) => format!("{:.3}", timing::time(&g, &t, bind)),
        };
        println!("| {} | {} | {ms} |", t.module, t.function);
    }
    let after = baseline();
    println!("\nbaseline kernel (arguments and write only): {before:.3} ms before, {after:.3} ms after the functions, per 3840x2160 dispatch");
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
        /// A skin LUT's KTX2 texture and a linear sampler, at 2 and 3.
        Ktx2(&'static [u8]),
        /// A table's own KTX2 texture at 2 (`lut::Table::upload_ktx2`), read by its
        /// `FUNCTION_load`.
        TableKtx2(&'static lut::Table),
    }

    /// `library`, extra declarations, and an entry point that runs the statement `call` and
    /// writes `reduce` (an f32 expression of c0, c1, c2 and what `call` defines).
    pub fn kernel(library: &str, decls: &str, call: &str, reduce: &str) -> String {
        format!(
            "{library}\n{decls}\n@group(0) @binding(1) var<storage, read_write> shadefit_out: array<f32>;\n\n\
             @compute @workgroup_size(8, 8)\n\
             fn shadefit_main(@builtin(global_invocation_id) id: vec3<u32>) {{\n    \
                 let c0 = f32(id.x) / {w}.0;\n    \
                 let c1 = f32(id.y) / {h}.0;\n    \
                 let c2 = fract(c0 * 7.0 + c1 * 3.0);\n    \
                 {call}\n    \
                 shadefit_out[id.y * {W}u + id.x] = {reduce};\n}}\n",
            w = W - 1,
            h = H - 1,
        )
    }

    /// The skin LUT texture a module's `_sample` function reads.
    pub fn ktx2(module: &str) -> Option<&'static [u8]> {
        match module {
            #[cfg(feature = "skin")]
            "skin_punctual_lut" => Some(shadefit_runtime::skin_punctual_lut::SKIN_PUNCTUAL_LUT_KTX2),
            #[cfg(feature = "skin")]
            "skin_sh_lut" => Some(shadefit_runtime::skin_sh_lut::SKIN_SH_LUT_KTX2),
            _ => None,
        }
    }

    /// Milliseconds for the target's function, with `bind` bound.
    pub fn time(g: &gpu::Gpu, t: &Target, bind: &Bind) -> f64 {
        let decls = match bind {
            Bind::Ktx2(_) => "@group(0) @binding(2) var shadefit_tex: texture_2d<f32>;\n@group(0) @binding(3) var shadefit_smp: sampler;\n",
            Bind::TableKtx2(_) => "@group(0) @binding(2) var shadefit_tex: texture_2d<f32>;\n",
            _ => "",
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
        run(g, &t.function, &kernel(&t.library, decls, &call, &reduce), bind.clone())
    }

    /// Compile, warm up, then the best of five timed dispatches (submit to completion), in ms.
    pub fn run(g: &gpu::Gpu, label: &str, shader: &str, bind: Bind) -> f64 {
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
            Bind::TableKtx2(t) => {
                table_ktx2 = t.upload_ktx2(device, &g.queue, false).expect("the table's KTX2").expect("KTX2");
                entries.push(wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&table_ktx2.view) });
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
        let dispatch = || {
            let mut encoder = device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_compute_pass(&Default::default());
                pass.set_pipeline(&pipeline);
                pass.set_bind_group(0, &bind_group, &[]);
                pass.dispatch_workgroups(W / 8, H / 8, 1);
            }
            let t0 = std::time::Instant::now();
            g.queue.submit([encoder.finish()]);
            device.poll(wgpu::PollType::wait_indefinitely()).expect("poll");
            t0.elapsed().as_secs_f64() * 1e3
        };
        dispatch();
        (0..5).map(|_| dispatch()).fold(f64::INFINITY, f64::min)
    }
}
