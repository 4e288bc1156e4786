//! The `table` kind: a spec's quantity tabulated (or read back), verified through the
//! emitted f32 interpolation, and emitted as const arrays and textures.
//!
//! A table has one to three axes and one to four values a point (a scalar quantity, one
//! `channel`, or several `channels` of a vector quantity). Each axis's points lie at its nodes
//! (ends included) or at texel centres, uniform in the axis's argument, whose `mapping` gives
//! the quantity's parameter there (`spec::table`). The one interpolator (`emit::interp`) is
//! the emitted code's arithmetic in f32 (`rust::table_lookup_f32`, which the verification runs)
//! and the reference's in f64.

use super::*;
use crate::emit::interp::Placement as Addressing;
use crate::spec::{Placement, TableLayout, TableTextureFormat};

/// The layout of a table spec (one made in memory without one: one value a point, nodes, the
/// parameters themselves).
pub fn table_layout(spec: &Spec) -> TableLayout {
    spec.table.clone().unwrap_or_else(|| TableLayout {
        channels: Vec::new(),
        axes: spec.file.axis.iter().map(|_| (Placement::Nodes, &spec::table::LINEAR)).collect(),
        order: (0..spec.file.axis.len()).collect(),
    })
}

/// A table's axes in storage order (first fastest): each `[[axis]]` with its placement and
/// mapping.
pub fn table_axes<'a>(spec: &'a Spec, layout: &TableLayout) -> Vec<(&'a spec::AxisSpec, Placement, &'static spec::AxisMapping)> {
    layout.order.iter().map(|&k| (&spec.file.axis[k], layout.axes[k].0, layout.axes[k].1)).collect()
}

/// The argument ranges of a table's emitted function, in storage order.
pub fn table_domain(spec: &Spec) -> Vec<[f64; 2]> {
    table_axes(spec, &table_layout(spec)).iter().map(|(a, _, _)| a.range).collect()
}

/// Values a point of a table spec (its channels, or 1).
pub fn table_width(spec: &Spec) -> usize {
    table_layout(spec).width()
}

/// The emitted code's addressing of each axis, in storage order.
fn addressing(layout: &TableLayout) -> Vec<Addressing> {
    layout
        .order
        .iter()
        .map(|&k| match layout.axes[k].0 {
            Placement::Nodes => Addressing::Nodes,
            Placement::Centres => Addressing::Centres,
        })
        .collect()
}

/// The values of a table's JSON: one number a point, or one array of its channels a point.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum TableValues {
    One(Vec<f64>),
    Channels(Vec<Vec<f64>>),
}

impl TableValues {
    /// `width` values a point, flat (point by point).
    fn of_flat(values: &[f64], width: usize) -> TableValues {
        if width == 1 { TableValues::One(values.to_vec()) } else { TableValues::Channels(values.chunks(width).map(<[f64]>::to_vec).collect()) }
    }

    /// The values flat, if every point has `width` of them.
    fn flat(self, width: usize) -> Option<Vec<f64>> {
        match self {
            TableValues::One(v) if width == 1 => Some(v),
            TableValues::Channels(v) if width > 1 && v.iter().all(|p| p.len() == width) => Some(v.concat()),
            _ => None,
        }
    }
}

/// An axis of a table's JSON.
#[derive(Debug, Serialize)]
struct AxisJson<'a> {
    name: &'a str,
    /// The argument's range (the mapped coordinate's, with a mapping).
    range: [f64; 2],
    count: usize,
    verify: usize,
    /// At texel centres ("centres"; absent at the nodes).
    #[serde(skip_serializing_if = "Option::is_none")]
    placement: Option<&'static str>,
    /// The argument-to-parameter mapping (absent for the parameter itself).
    #[serde(skip_serializing_if = "Option::is_none")]
    mapping: Option<&'static str>,
    /// The parameter at the range's ends, with a mapping.
    #[serde(skip_serializing_if = "Option::is_none")]
    parameter_range: Option<[f64; 2]>,
}

/// A table's JSON (`generated/json/NAME.json`). Written through `serde_json::Value`, whose map
/// orders the keys by name.
#[derive(Debug, Serialize)]
struct TableJson<'a> {
    generator: &'a str,
    spec: String,
    input_hash: &'a str,
    name: &'a str,
    kind: &'static str,
    quantity: &'a str,
    #[serde(skip_serializing_if = "Option::is_none")]
    channel: Option<&'a str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    channels: Option<Vec<&'a str>>,
    description: &'a str,
    function: &'a str,
    axes: Vec<AxisJson<'a>>,
    layout: &'static str,
    values: TableValues,
    verification: &'a Verification,
}

/// What a check-mode build reads back from a table's JSON (its hash is checked on the way).
#[derive(Debug, Deserialize)]
struct CommittedTable {
    values: TableValues,
}

/// The committed values of a table spec (flat, [`table_width`] a point), checked against the
/// spec's hash and grid.
pub fn committed_values(spec: &Spec, root: &Path) -> Result<Vec<f64>, BuildError> {
    let name = &spec.file.name;
    let v = committed_json(root, spec)?;
    let bad = |why: String| BuildError::NoCommitted { spec: name.clone(), why };
    let c: CommittedTable = serde_json::from_value(v).map_err(|e| bad(format!("no table 'values': {e}")))?;
    let width = table_width(spec);
    let vals = c.values.flat(width).ok_or_else(|| bad(format!("'values' do not hold {width} numbers a point")))?;
    if vals.len() != table_points(spec).len() * width {
        return Err(bad("table size differs from the spec".into()));
    }
    Ok(vals)
}

/// The grid of a table spec: its axes in storage order, each over its range at its placement,
/// mapped to its parameter.
pub fn table_grid(spec: &Spec) -> Grid {
    let layout = table_layout(spec);
    Grid {
        axes: layout
            .order
            .iter()
            .map(|&k| {
                let a = &spec.file.axis[k];
                GridAxis { range: a.range, count: a.count, placement: layout.axes[k].0, mapping: layout.axes[k].1, param: k }
            })
            .collect(),
    }
}

/// The grid points of a table spec in its arguments (`count` per axis at its placement, first
/// axis fastest).
pub fn table_points(spec: &Spec) -> Vec<Vec<f64>> {
    table_grid(spec).points()
}

/// The table's values at `points` (its arguments, in storage order), flat: each point mapped to
/// the quantity's parameters (in their order), its channels evaluated once; in parallel, in
/// order.
pub fn table_sample(spec: &Spec, points: &[Vec<f64>]) -> Vec<f64> {
    let layout = table_layout(spec);
    table_grid(spec).sample(&spec.sampler(), &layout.channels, points).into_iter().flatten().map(|e| e.value).collect()
}

/// The integral on a table's verification grid, [`table_width`] values a point: `verify` points
/// an axis in the arguments, placed as the table's (ends included at nodes; at texel centres
/// the centres of `verify` cells, which also lie where the lookup holds an edge texel, and
/// never at the ends, where a mapped parameter may leave the quantity's domain).
pub fn table_reference(spec: &Spec) -> Reference {
    let grid = table_grid(spec);
    let verify: Vec<usize> = table_layout(spec).order.iter().map(|&k| spec.file.axis[k].verify_count()).collect();
    let points = Grid::product(grid.axes.iter().zip(verify).map(|(a, n)| a.placement.points(a.range, n)).collect());
    let values = table_sample(spec, &points);
    Reference { points, values }
}

pub(super) fn build_table(spec: &Spec, mode: Mode, root: &Path) -> Result<Built, BuildError> {
    let values: Vec<f64> = match mode {
        Mode::Fit => table_sample(spec, &table_points(spec)),
        Mode::Committed => committed_values(spec, root)?,
    };
    table_from_values(spec, values, &table_reference(spec))
}

/// The texel format's precision (what a channel holds).
pub fn stored_precision(format: TableTextureFormat) -> emit::texture::TextureFormat {
    if format.is_32bit() { emit::texture::TextureFormat::Rgba32float } else { emit::texture::TextureFormat::Rgba16float }
}

/// Verify a table with the given values (at [`table_points`], [`table_width`] a point) against
/// `reference` (as many a point), through the emitted f32 interpolation, and render its files.
pub fn table_from_values(spec: &Spec, values: Vec<f64>, reference: &Reference) -> Result<Built, BuildError> {
    let name = spec.file.name.clone();
    let layout = table_layout(spec);
    let width = layout.width();
    let placements = addressing(&layout);
    let axes = table_axes(spec, &layout);
    let counts: Vec<usize> = axes.iter().map(|(a, _, _)| a.count).collect();
    let points = table_points(spec);
    assert_eq!(values.len(), points.len() * width, "{name}: {width} values a table point");
    // f32 values as the emitted code and textures carry them; subnormals flushed to zero of
    // the same sign (GPUs flush them, so a subnormal constant is not what a shader computes
    // with; the change is below 1.2e-38).
    let v32: Vec<f32> = values.iter().map(|&v| v as f32).map(|v| if v.is_subnormal() { 0.0f32.copysign(v) } else { v }).collect();
    let d32: Vec<(f32, f32)> = axes.iter().map(|(a, _, _)| (a.range[0] as f32, a.range[1] as f32)).collect();
    let (vx, truth) = (&reference.points, &reference.values);
    let approx32: Vec<f32> = vx
        .iter()
        .flat_map(|x| {
            let xs: Vec<f32> = x.iter().map(|&v| v as f32).collect();
            rust::table_lookup_f32(&v32, width, &counts, &d32, &placements, &xs)
        })
        .collect();
    let approx64: Vec<f64> = approx32.iter().map(|&v| v as f64).collect();
    let linear = layout.axes.iter().all(|(_, m)| m.name == spec::table::LINEAR.name);
    let verification = if width == 1 {
        verify(inverse_1d(spec, vx).filter(|_| linear), vx, truth, &approx64, &approx32)
    } else {
        // Every channel of a point is a value measured at that point.
        let each: Vec<Vec<f64>> = vx.iter().flat_map(|x| std::iter::repeat_n(x.clone(), width)).collect();
        Verification { points: vx.len(), ..verify(None, &each, truth, &approx64, &approx32) }
    };
    let hash = input_hash(spec);
    let form = spec.file.emit.form.unwrap_or_default();
    let tex_format = spec.file.emit.texture_format.unwrap_or(TableTextureFormat::default_for(width));
    let stored = stored_precision(tex_format);
    let per_point = if width == 1 { String::new() } else { format!(" x {width} channels") };
    let mut err_line = format!(
        "linear interpolation of the f32 table: max abs {}, rms {} over {} points{per_point}",
        fmt_err(verification.max_abs_error_f32),
        fmt_err(verification.rms_error_f32),
        verification.points
    );
    if form.has_texture() {
        let storage = v32.iter().map(|&v| (stored.stored(v) - v).abs()).fold(0.0f32, f32::max);
        err_line.push_str(&format!("; {} texture storage <= {}", tex_format.name(), fmt_err(storage as f64)));
    }
    let header = header_lines(&spec_rel_path(spec), &hash, &err_line);
    // `[emit] args` name the arguments in storage order; by default the axes' names.
    let a = spec.file.emit.args.clone().unwrap_or_else(|| axes.iter().map(|(x, _, _)| x.name.clone()).collect());
    let func = wgsl::Function {
        module: &name,
        name: &spec.file.emit.function,
        args: &a,
        derived: &[],
        domain: &d32,
        body: wgsl::Body::Table { values: &v32, counts: &counts, channels: width, placements: &placements },
    };
    let channel_names: Vec<&str> = layout.channels.iter().map(|&c| spec.quantity.channels[c]).collect();
    let label = if channel_names.is_empty() { spec.quantity_label() } else { format!("{}[{}]", spec.quantity.name, channel_names.join(", ")) };
    let doc = format!(
        "{}: `{}` interpolates a {} table of quantity `{}`.",
        spec.file.description,
        spec.file.emit.function,
        counts.iter().map(|c| c.to_string()).collect::<Vec<_>>().join("×"),
        label
    );
    let axes: Vec<AxisJson> = axes
        .iter()
        .map(|&(a, p, m)| {
            let mapped = m.name != spec::table::LINEAR.name;
            AxisJson {
                name: &a.name,
                range: a.range,
                count: a.count,
                verify: a.verify_count(),
                placement: (p != Placement::Nodes).then(|| p.name()),
                mapping: mapped.then_some(m.name),
                parameter_range: mapped.then(|| a.range.map(m.to_parameter)),
            }
        })
        .collect();
    let json = TableJson {
        generator: GENERATOR,
        spec: spec_rel_path(spec),
        input_hash: &hash,
        name: &name,
        kind: "table",
        quantity: &spec.file.quantity,
        channel: spec.channel_name(),
        channels: (!channel_names.is_empty()).then(|| channel_names.clone()),
        description: &spec.file.description,
        function: &spec.file.emit.function,
        axes,
        layout: if width == 1 { "first axis fastest" } else { "first axis fastest, the channels of a point in order" },
        values: TableValues::of_flat(&values, width),
        verification: &verification,
    };
    let json = serde_json::to_value(&json).expect("a table's JSON serialises");
    // Several channels a point: one point a line.
    let json_file = if width == 1 { json_text(&json) } else { compact_json(&json) };
    let mut csv = String::new();
    for h in &header {
        csv.push_str(&format!("# {h}\n"));
    }
    let columns = if channel_names.is_empty() { "value".to_string() } else { channel_names.join(",") };
    csv.push_str(&format!("{},{columns}\n", a.join(",")));
    for (p, v) in points.iter().zip(values.chunks(width)) {
        let cols: Vec<String> = p.iter().chain(v).map(|x| format!("{x:?}")).collect();
        csv.push_str(&format!("{}\n", cols.join(",")));
    }
    let ktx2_file = format!("data/{name}.ktx2");
    let texture = form.has_texture().then(|| wgsl::TableTexture {
        file: &ktx2_file,
        format: tex_format.name(),
        filterable: !tex_format.is_32bit() || spec.file.emit.float32_filterable,
        keep_const: form.has_const(),
    });
    let mut rust_text = rust::render_module(&header, &func, &doc);
    let mut ktx2 = None;
    if let Some(t) = &texture {
        let (w, h) = (counts[0] as u32, counts.get(1).copied().unwrap_or(1) as u32);
        let depth = counts.get(2).copied().unwrap_or(0) as u32;
        let shadefit = header.join("\n");
        let texel = tex_format.texel_channels();
        // Three channels fill RGB of an RGBA texel, alpha 1.
        let texels: Vec<f32> = if texel == width { v32.clone() } else { v32.chunks(width).flat_map(|p| [p[0], p[1], p[2], 1.0]).collect() };
        ktx2 = Some(emit::texture::ktx2_volume(w, h, depth, texel, &texels, stored, &[("shadefit", &shadefit)]));
        let upper = name.to_uppercase();
        let (size, which) = if depth == 0 {
            (format!("{w}x{h}"), "texel (i, j) the value at\n/// point i of the first axis, j of the second")
        } else {
            (format!("{w}x{h}x{depth}"), "texel (i, j, k) the value at\n/// point i of the first axis, j of the second, k of the third")
        };
        rust_text.push_str(&format!(
            "\n/// The table as a KTX2 texture ({fmt}, {size} texels, one level; {which}), as written by `shadefit build`; read by the\n\
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
        Artifact { path: format!("json/{name}.json").into(), contents: json_file.into() },
        Artifact { path: format!("data/{name}.csv").into(), contents: csv.into() },
    ];
    if let Some(bytes) = ktx2 {
        artifacts.push(Artifact { path: ktx2_file.clone().into(), contents: bytes });
    }
    Ok(Built { name, artifacts, verification, fit: None })
}
