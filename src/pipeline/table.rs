//! The `table` kind: a spec's quantity tabulated (or read back), verified through the
//! emitted f32 interpolation, and emitted as const arrays and textures.

use super::*;

/// The committed values of a table spec, checked against the spec's hash and grid.
pub fn committed_values(spec: &Spec, root: &Path) -> Result<Vec<f64>, BuildError> {
    let name = &spec.file.name;
    let v = committed_json(root, spec)?;
    let vals = f64_array(&v, name, "values")?;
    if vals.len() != table_points(spec).len() {
        return Err(BuildError::NoCommitted { spec: name.clone(), why: "table size differs from the spec".into() });
    }
    Ok(vals)
}

/// The grid points of a table spec (`count` per axis, first axis fastest).
pub fn table_points(spec: &Spec) -> Vec<Vec<f64>> {
    let counts: Vec<usize> = spec.file.axis.iter().map(|a| a.count).collect();
    grid(spec, &counts)
}

pub(super) fn build_table(spec: &Spec, mode: Mode, root: &Path) -> Result<Built, BuildError> {
    let values: Vec<f64> = match mode {
        Mode::Fit => sample(spec, &table_points(spec)),
        Mode::Committed => committed_values(spec, root)?,
    };
    table_from_values(spec, values, &Reference::of_spec(spec))
}

/// Verify a table with the given values (at [`table_points`]) against `reference`, through
/// the emitted f32 interpolation, and render its files.
pub fn table_from_values(spec: &Spec, values: Vec<f64>, reference: &Reference) -> Result<Built, BuildError> {
    let name = spec.file.name.clone();
    let counts: Vec<usize> = spec.file.axis.iter().map(|a| a.count).collect();
    let points = table_points(spec);
    assert_eq!(values.len(), points.len(), "{name}: one value per table point");
    let v32: Vec<f32> = values.iter().map(|&v| v as f32).collect();
    let d32 = domain_f32(spec);
    let (vx, truth) = (&reference.points, &reference.values);
    let approx32: Vec<f32> = vx
        .iter()
        .map(|x| {
            let xs: Vec<f32> = x.iter().map(|&v| v as f32).collect();
            rust::table_eval_f32(&v32, &counts, &d32, &xs)
        })
        .collect();
    let approx64: Vec<f64> = approx32.iter().map(|&v| v as f64).collect();
    let verification = verify(inverse_1d(spec, vx), vx, truth, &approx64, &approx32);
    let hash = input_hash(spec);
    let form = spec.file.emit.form.unwrap_or_default();
    let tex_format = spec.file.emit.texture_format.unwrap_or_default();
    let precision = match tex_format {
        spec::TableTextureFormat::R16float => emit::texture::TextureFormat::Rgba16float,
        spec::TableTextureFormat::R32float => emit::texture::TextureFormat::Rgba32float,
    };
    let mut err_line = format!(
        "linear interpolation of the f32 table: max abs {}, rms {} over {} points",
        fmt_err(verification.max_abs_error_f32),
        fmt_err(verification.rms_error_f32),
        verification.points
    );
    if form.has_texture() {
        let storage = v32.iter().map(|&v| (precision.stored(v) - v).abs()).fold(0.0f32, f32::max);
        err_line.push_str(&format!("; {} texture storage <= {}", tex_format.name(), fmt_err(storage as f64)));
    }
    let header = header_lines(&spec_rel_path(spec), &hash, &err_line);
    let a = args(spec);
    let func = wgsl::Function {
        module: &name,
        name: &spec.file.emit.function,
        args: &a,
        derived: &[],
        domain: &d32,
        body: wgsl::Body::Table { values: &v32, counts: &counts },
    };
    let doc = format!(
        "{}: `{}` interpolates a {} table of quantity `{}`.",
        spec.file.description,
        spec.file.emit.function,
        counts.iter().map(|c| c.to_string()).collect::<Vec<_>>().join("×"),
        spec.quantity_label()
    );
    let mut json = json!({
        "generator": GENERATOR,
        "spec": spec_rel_path(spec),
        "input_hash": hash,
        "name": name,
        "kind": "table",
        "quantity": spec.file.quantity,
        "description": spec.file.description,
        "function": spec.file.emit.function,
        "axes": axes_json(spec),
        "layout": "first axis fastest",
        "values": values,
        "verification": verification,
    });
    with_channel(&mut json, spec);
    let mut csv = String::new();
    for h in &header {
        csv.push_str(&format!("# {h}\n"));
    }
    csv.push_str(&format!("{},value\n", a.join(",")));
    for (p, v) in points.iter().zip(&values) {
        let cols: Vec<String> = p.iter().map(|x| format!("{x:?}")).collect();
        csv.push_str(&format!("{},{v:?}\n", cols.join(",")));
    }
    let ktx2_file = format!("data/{name}.ktx2");
    let texture = form.has_texture().then(|| wgsl::TableTexture {
        file: &ktx2_file,
        format: tex_format.name(),
        filterable: tex_format == spec::TableTextureFormat::R16float || spec.file.emit.float32_filterable,
        keep_const: form.has_const(),
    });
    let mut rust_text = rust::render_module(&header, &func, &doc);
    let mut ktx2 = None;
    if let Some(t) = &texture {
        let (w, h) = (counts[0] as u32, counts.get(1).copied().unwrap_or(1) as u32);
        let shadefit = header.join("\n");
        ktx2 = Some(emit::texture::ktx2_texels(w, h, 1, &v32, precision, &[("shadefit", &shadefit)]));
        let upper = name.to_uppercase();
        rust_text.push_str(&format!(
            "\n/// The table as a KTX2 texture ({fmt}, {w}x{h} texels, one level; texel (i, j) the value at\n\
             /// point i of the first axis, j of the second), as written by `shadefit build`; read by the\n\
             /// WGSL function `{f}_load`{sample}.\n\
             pub const {upper}_KTX2: &[u8] = include_bytes!(\"../{file}\");\n\
             /// Texel format of [`{upper}_KTX2`] (WebGPU name).\n\
             pub const {upper}_TEXTURE_FORMAT: &str = \"{fmt}\";\n",
            fmt = t.format,
            f = spec.file.emit.function,
            sample = if t.filterable { format!(" and, through a linear sampler, `{}_sample`", spec.file.emit.function) } else { String::new() },
            file = ktx2_file,
        ));
    }
    let mut artifacts = vec![
        Artifact { path: format!("wgsl/{name}.wgsl").into(), contents: wgsl::render_table_module(&header, &func, texture.as_ref()).into() },
        Artifact { path: format!("src/{name}.rs").into(), contents: rust_text.into() },
        Artifact { path: format!("json/{name}.json").into(), contents: json_text(&json).into() },
        Artifact { path: format!("data/{name}.csv").into(), contents: csv.into() },
    ];
    if let Some(bytes) = ktx2 {
        artifacts.push(Artifact { path: ktx2_file.clone().into(), contents: bytes });
    }
    Ok(Built { name, artifacts, verification, fit: None })
}
