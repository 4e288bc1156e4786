//! WGSL libraries. Each file names itself with a `#define_import_path shadefit::NAME`
//! directive (naga_oil/bevy convention); a composer strips directive lines before handing the
//! source to naga. Inputs are clamped to the fit domain, NaN maps to the domain's lower end
//! (tested on the bit pattern, which no compiler may fold away), so no input yields NaN or ±inf.

use super::expr::{render, Expr};
use super::f32_literal;
use super::interp::{step_scale, Placement};

/// What an emitted function computes.
pub enum Body<'a> {
    Fit { expr: &'a Expr, num: &'a [f32], den: &'a [f32], clamp: Option<(f32, f32)> },
    /// Multilinear interpolation in a table on a uniform grid of each axis (1 to 3 axes, first
    /// axis fastest: `values[((k * ny + j) * nx + i) * channels + c]`), `channels` values a
    /// point (1: the function returns f32; 2 to 4: vecN<f32>), each axis's points at its nodes
    /// or at texel centres (`placements`, one per axis).
    Table { values: &'a [f32], counts: &'a [usize], channels: usize, placements: &'a [Placement] },
}

/// The WGSL type of a table point's `channels` values.
fn value_type(channels: usize) -> String {
    if channels == 1 { "f32".into() } else { format!("vec{channels}<f32>") }
}

/// The swizzle taking a texel's `channels` (an RGBA `textureLoad` result).
fn swizzle(channels: usize) -> &'static str {
    ["", ".x", ".xy", ".xyz", ""][channels]
}

/// The texel of a const table `t` at offsets (dx, dy, dz) from the cell's first node, first
/// axis fastest: `t[i0 + 1]` in one axis, `t[k + offset]` from the flat index `k` in more;
/// `int` is the language's suffix of an index literal (`u` in WGSL).
pub(crate) fn flat_read<'a>(counts: &'a [usize], t: &'a str, int: &'a str) -> impl Fn(usize, usize, usize) -> String + 'a {
    let (nx, ny) = (counts[0], counts.get(1).copied().unwrap_or(1));
    move |dx, dy, dz| {
        let o = dx + nx * (dy + ny * dz);
        match (counts.len(), o) {
            (1, 0) => format!("{t}[i0]"),
            (1, _) => format!("{t}[i0 + 1{int}]"),
            (_, 0) => format!("{t}[k]"),
            _ => format!("{t}[k + {o}{int}]"),
        }
    }
}

/// The multilinear blend's lines over `axes` axes, `read(dx, dy, dz)` the texel at offsets
/// (0 or 1) from (i0, i1, i2), in [`super::interp::multilinear`]'s order: along the first axis,
/// then the second, then the third. `lerp(a, b, f)` is a · (1 − f) + b · f in the language.
pub(crate) fn blend_lines(axes: usize, read: &dyn Fn(usize, usize, usize) -> String, lerp: &dyn Fn(&str, &str, &str) -> String, ret: &dyn Fn(&str) -> String) -> String {
    let row = |dy: usize, dz: usize| lerp(&read(0, dy, dz), &read(1, dy, dz), "f0");
    match axes {
        1 => format!("{}\n}}\n", ret(&row(0, 0))),
        2 => format!("    let a = {};\n    let b = {};\n{}\n}}\n", row(0, 0), row(1, 0), ret(&lerp("a", "b", "f1"))),
        // Locals a0…a5: names no argument may take (spec::names).
        _ => format!(
            "    let a0 = {};\n    let a1 = {};\n    let a2 = {};\n    let a3 = {};\n    let a4 = {};\n    let a5 = {};\n{}\n}}\n",
            row(0, 0),
            row(1, 0),
            row(0, 1),
            row(1, 1),
            lerp("a0", "a1", "f1"),
            lerp("a2", "a3", "f1"),
            ret(&lerp("a4", "a5", "f2"))
        ),
    }
}

pub struct Function<'a> {
    pub module: &'a str,
    pub name: &'a str,
    pub args: &'a [String],
    /// Derived features, computed after the inputs are clamped (variables x{n_args + k}).
    pub derived: &'a [crate::fit::model::Derived],
    pub domain: &'a [(f32, f32)],
    pub body: Body<'a>,
}

fn lit(v: f32) -> String {
    format!("{}f", f32_literal(v))
}

/// A const array of `vecN<f32>` points, `channels` values each, three points a line.
fn vec_array(name: &str, values: &[f32], channels: usize) -> String {
    let ty = value_type(channels);
    let n = values.len() / channels;
    let mut s = format!("const {name}: array<{ty}, {n}> = array<{ty}, {n}>(");
    for (i, v) in values.chunks(channels).enumerate() {
        s.push_str(if i % 3 == 0 { "\n    " } else { " " });
        let items: Vec<String> = v.iter().map(|&x| lit(x)).collect();
        s.push_str(&format!("{ty}({}),", items.join(", ")));
    }
    s.push_str("\n);\n");
    s
}

fn array(name: &str, values: &[f32]) -> String {
    let mut s = format!("const {name}: array<f32, {n}> = array<f32, {n}>(", n = values.len());
    for (i, v) in values.iter().enumerate() {
        if i % 6 == 0 {
            s.push_str("\n    ");
        } else {
            s.push(' ');
        }
        s.push_str(&lit(*v));
        s.push(',');
    }
    s.push_str("\n);\n");
    s
}

pub fn render_module(header: &[String], f: &Function<'_>) -> String {
    render_table_module(header, f, None)
}

/// A table's texture, as the helpers of [`render_table_module`] read it.
pub struct TableTexture<'a> {
    /// The KTX2 file under generated/ (`data/NAME.ktx2`).
    pub file: &'a str,
    /// WebGPU name of the texel format (`r16float`, `r32float`).
    pub format: &'a str,
    /// Whether the module gets the linear-sampler helper: the format is filterable on the
    /// engine's device (r16float always; r32float only with `float32-filterable` requested).
    pub filterable: bool,
    /// Whether the module keeps the `const` array and the function reading it.
    pub keep_const: bool,
}

/// The module of a table function ([`Body::Table`]) with its texture helpers (see
/// [`table_texture_functions`]); without a texture, [`render_module`].
pub fn render_table_module(header: &[String], f: &Function<'_>, texture: Option<&TableTexture<'_>>) -> String {
    let mut s = prelude(header, f);
    if texture.is_none_or(|t| t.keep_const) {
        s.push_str(&body(f));
    }
    if let (Some(t), Body::Table { counts, .. }) = (texture, &f.body) {
        let helpers = table_texture_functions(f, counts, t);
        // After the prelude's blank line, no second one.
        s.push_str(if t.keep_const { &helpers } else { &helpers[1..] });
    }
    s
}

/// The header, the directive and the input clamp of a module.
fn prelude(header: &[String], f: &Function<'_>) -> String {
    let mut s = String::new();
    for h in header {
        s.push_str(&format!("// {h}\n"));
    }
    s.push_str(&format!("#define_import_path shadefit::{}\n\n", f.module));
    s.push_str(&format!(
        "// Clamp an input to [lo, hi]; NaN (any exponent-all-ones pattern with a non-zero\n\
         // mantissa) maps to lo.\nfn {helper}(v: f32, lo: f32, hi: f32) -> f32 {{\n    \
         let nan = (bitcast<u32>(v) & 0x7fffffffu) > 0x7f800000u;\n    \
         return select(clamp(v, lo, hi), lo, nan);\n}}\n\n",
        helper = crate::spec::names::input_helper(f.module)
    ));
    s
}

/// The `let xK = ...` lines: the clamped inputs, then the derived features.
fn input_lines(f: &Function<'_>) -> String {
    f.args
        .iter()
        .zip(f.domain)
        .enumerate()
        .map(|(i, (a, (lo, hi)))| format!("    let x{i} = {}({a}, {}, {});\n", crate::spec::names::input_helper(f.module), lit(*lo), lit(*hi)))
        .chain(f.derived.iter().enumerate().map(|(k, d)| {
            format!("    let x{} = {};\n", f.args.len() + k, derived_expr(d, &lit, &|fun, v| format!("{fun}({v})")))
        }))
        .collect()
}

/// `tK` (the argument in table steps), `iK` (the lower point) and `fK` (the weight of the upper,
/// clamped to [0, 1]) of each table axis, as the table function computes them. The clamp keeps
/// the interpolation convex where tK leaves [0, n − 1] by a rounding: at the top, where
/// (hi − lo)·scale rounds above n − 1, and at the bottom on a GPU that rewrites (x − lo)·scale
/// as fma(x, scale, −fl(lo·scale)) (an NVIDIA driver does; WGSL cannot forbid it), which made
/// a table of non-negative values return −8e-9 at its first point.
///
/// At texel centres tK counts steps from the first centre, tK = (xK − lo)·n/(hi − lo) − ½, and
/// iK = min(u32(max(tK, 0)), n − 2): below the first centre fK is 0, above the last 1, so the
/// lookup holds the edge value there as a clamp-to-edge sampler does.
fn table_index_lines(f: &Function<'_>, counts: &[usize], placements: &[Placement]) -> String {
    let mut s = String::new();
    for (i, (((lo, hi), n), p)) in f.domain.iter().zip(counts.iter()).zip(placements).enumerate() {
        let scale = lit(step_scale(*lo, *hi, *n, *p));
        let (lo, last) = (lit(*lo), n - 2);
        s.push_str(&match p {
            Placement::Nodes => format!("    let t{i} = (x{i} - {lo}) * {scale};\n    let i{i} = min(u32(t{i}), {last}u);\n"),
            Placement::Centres => format!("    let t{i} = (x{i} - {lo}) * {scale} - 0.5f;\n    let i{i} = min(u32(max(t{i}, 0.0f)), {last}u);\n"),
        });
        s.push_str(&format!("    let f{i} = clamp(t{i} - f32(i{i}), 0.0f, 1.0f);\n"));
    }
    s
}

pub(crate) fn wgsl_lerp(a: &str, b: &str, f: &str) -> String {
    format!("{a} * (1.0f - {f}) + {b} * {f}")
}

fn wgsl_return(v: &str) -> String {
    format!("    return {v};")
}

/// The functions reading a table from a texture (`texture_2d<f32>`, or `texture_3d<f32>` for
/// three axes; a table of axes n0 (× n1 (× n2)) is n0 × n1 (× n2) texels, texel (i, j, k) the
/// value at point i of the first axis, j of the second and k of the third, 1 row for one axis;
/// a point's channels the texel's first ones):
/// - `FUNCTION_load(lut, args)`: the table function with each `TABLE[k]` a `textureLoad` of the
///   same texel; same clamp, index, weights and order, so a 32-bit float texture gives the same
///   f32 arithmetic as the `const` array (no sampler; binds as unfilterable float);
/// - when `texture.filterable`: `MODULE_uv(args)`, texel-centre coordinates
///   u = (tK + 0.5) / nK with tK as the table function computes it (v = 0.5 for one axis), and
///   `FUNCTION_sample(lut, lut_sampler, args)` through a linear, clamp-to-edge sampler, which
///   interpolates the same two (four, eight) texels with the same weights up to the sampler's
///   weight precision (Vulkan guarantees 4 sub-texel bits, GPUs have 8).
pub fn table_texture_functions(f: &Function<'_>, counts: &[usize], texture: &TableTexture<'_>) -> String {
    let (channels, placements) = match &f.body {
        Body::Table { channels, placements, .. } => (*channels, *placements),
        Body::Fit { .. } => panic!("{}: texture helpers are for tables", f.name),
    };
    let params: Vec<String> = f.args.iter().map(|a| format!("{a}: f32")).collect();
    let inputs = input_lines(f);
    let index = table_index_lines(f, counts, placements);
    let axes = counts.len();
    let tex = if axes == 3 { "texture_3d<f32>" } else { "texture_2d<f32>" };
    let ty = value_type(channels);
    let load = |dx: usize, dy: usize, dz: usize| {
        let at = |d: usize, i: usize| if d == 0 { format!("i{i}") } else { format!("i{i} + 1u") };
        let coords = match axes {
            1 => format!("vec2<u32>({}, 0u)", at(dx, 0)),
            2 => format!("vec2<u32>({}, {})", at(dx, 0), at(dy, 1)),
            _ => format!("vec3<u32>({}, {}, {})", at(dx, 0), at(dy, 1), at(dz, 2)),
        };
        format!("textureLoad(lut, {coords}, 0){}", swizzle(channels))
    };
    let size = counts.iter().map(|n| n.to_string()).collect::<Vec<_>>();
    let size = if axes == 1 { format!("{}x1", size[0]) } else { size.join("x") };
    let same = if texture.format.ends_with("32float") {
        format!("// with {} texels the same f32 arithmetic on the same values as {}.\n", texture.format, f.name)
    } else {
        format!("// the values rounded to {} as stored.\n", texture.format)
    };
    let mut s = format!(
        "\n// The texture form of {name}: the table from `lut` ({file}, {fmt}, {size} texels,\n\
         // texel {ijk} the value at point i of the first axis{second}) by textureLoad, with the\n\
         // clamp, indices, weights and order of {name}; no sampler (bind as unfilterable float);\n\
         {same}\
         fn {name}_load(lut: {tex}, {p}) -> {ty} {{\n{inputs}{index}",
        name = f.name,
        file = texture.file,
        fmt = texture.format,
        ijk = if axes == 3 { "(i, j, k)" } else { "(i, j)" },
        second = match axes {
            1 => "; one row",
            2 => ", j of the second",
            _ => ", j of the second, k of the third",
        },
        p = params.join(", "),
    );
    s.push_str(&blend_lines(axes, &load, &wgsl_lerp, &wgsl_return));
    if texture.filterable {
        let t: Vec<String> = (0..axes).map(|i| format!("(t{i} + 0.5f) / {}", lit(counts[i] as f32))).collect();
        let uv = match axes {
            1 => format!("vec2<f32>({}, 0.5f)", t[0]),
            2 => format!("vec2<f32>({}, {})", t[0], t[1]),
            _ => format!("vec3<f32>({}, {}, {})", t[0], t[1], t[2]),
        };
        let uv_ty = if axes == 3 { "vec3<f32>" } else { "vec2<f32>" };
        // The index lines without iK and fK: tK alone.
        let ts: String = index.lines().filter(|l| l.trim_start().starts_with("let t")).map(|l| format!("{l}\n")).collect();
        let call: Vec<&str> = f.args.iter().map(String::as_str).collect();
        s.push_str(&format!(
            "\n// Texture coordinates of {name}'s arguments at texel centres: u = (t0 + 0.5) / n0,\n\
             // t0 the argument in table steps as {name} computes it{vnote}.\n\
             fn {m}_uv({p}) -> {uv_ty} {{\n{inputs}{ts}    return {uv};\n}}\n\
             \n// {name} from `lut` ({fmt}) through a linear, clamp-to-edge sampler at {m}_uv:\n\
             // the texels and weights of {name}, the weights to the sampler's sub-texel precision.\n\
             {f32note}\
             fn {name}_sample(lut: {tex}, lut_sampler: sampler, {p}) -> {ty} {{\n    \
             return textureSampleLevel(lut, lut_sampler, {m}_uv({c}), 0.0){sw};\n}}\n",
            name = f.name,
            m = f.module,
            fmt = texture.format,
            f32note = if texture.format.ends_with("32float") {
                format!("// {}: the device must have float32-filterable (the spec's float32_filterable = true).\n", texture.format)
            } else {
                String::new()
            },
            vnote = match axes {
                1 => "; v = 0.5, the one row",
                2 => ", v likewise",
                _ => ", v and w likewise",
            },
            p = params.join(", "),
            c = call.join(", "),
            sw = swizzle(channels),
        ));
    }
    s
}

/// The function of a module (after its prelude).
fn body(f: &Function<'_>) -> String {
    let upper = f.module.to_uppercase();
    let mut s = String::new();
    let params: Vec<String> = f.args.iter().map(|a| format!("{a}: f32")).collect();
    let inputs = input_lines(f);
    match &f.body {
        Body::Fit { expr, num, den, clamp } => {
            s.push_str(&array(&format!("{upper}_NUM"), num));
            if !den.is_empty() {
                s.push_str(&array(&format!("{upper}_DEN"), den));
            }
            let body = render(
                expr,
                &|i| format!("x{i}"),
                &|a, j| format!("{upper}_{}[{j}]", if a == 0 { "NUM" } else { "DEN" }),
                &lit,
            );
            let ret = match clamp {
                Some((lo, hi)) => format!("clamp({body}, {}, {})", lit(*lo), lit(*hi)),
                None => body,
            };
            s.push_str(&format!(
                "\nfn {}({}) -> f32 {{\n{inputs}    return {ret};\n}}\n",
                f.name,
                params.join(", ")
            ));
        }
        Body::Table { values, counts, channels, placements } => {
            let t = format!("{upper}_TABLE");
            s.push_str(&if *channels == 1 { array(&t, values) } else { vec_array(&t, values, *channels) });
            s.push_str(&format!("\nfn {}({}) -> {} {{\n{inputs}", f.name, params.join(", "), value_type(*channels)));
            s.push_str(&table_index_lines(f, counts, placements));
            let (nx, ny) = (counts[0], counts.get(1).copied().unwrap_or(1));
            match counts.len() {
                1 => {}
                2 => s.push_str(&format!("    let k = i1 * {nx}u + i0;\n")),
                _ => s.push_str(&format!("    let k = (i2 * {ny}u + i1) * {nx}u + i0;\n")),
            }
            let read = flat_read(counts, &t, "u");
            s.push_str(&blend_lines(counts.len(), &read, &wgsl_lerp, &wgsl_return));
        }
    }
    s
}

/// A derived feature as an expression in the language (`call(fun, var)` renders cos/sin).
pub fn derived_expr(
    d: &crate::fit::model::Derived,
    lit: &dyn Fn(f32) -> String,
    call: &dyn Fn(&str, &str) -> String,
) -> String {
    use crate::fit::model::DerivedExpr;
    match d.expr {
        DerivedExpr::Affine { input, offset, scale } => {
            let (o, s) = (offset as f32, scale as f32);
            if s == 1.0 {
                format!("{} + x{input}", lit(o))
            } else if s == -1.0 {
                format!("{} - x{input}", lit(o))
            } else {
                format!("{} + {} * x{input}", lit(o), lit(s))
            }
        }
        DerivedExpr::Cos(i) => call("cos", &format!("x{i}")),
        DerivedExpr::Sin(i) => call("sin", &format!("x{i}")),
    }
}

/// The source with `#`-directive lines removed (what a composer hands to naga).
pub fn strip_directives(src: &str) -> String {
    src.lines().filter(|l| !l.trim_start().starts_with('#')).collect::<Vec<_>>().join("\n")
}

/// The f32 interpreter of naga's IR that the runtime's GPU test takes as reference (CPU
/// semantics: the operations the source spells out, in f32), for the emitters' and the families' tests.
#[cfg(test)]
#[allow(dead_code)]
#[path = "../../generated/tests/support/bound.rs"]
pub(crate) mod interpreter;

#[cfg(test)]
mod tests {
    use super::*;

    /// Every shape of derived feature, rendered and evaluated by naga's constant evaluator
    /// (`const v = <expression of x0>;` with x0 a constant): the value is the feature's own f32
    /// evaluation (`Derived::eval_f32`) at x0 = 0.3.
    #[test]
    fn derived_features_evaluate_in_naga_as_in_f32() {
        let inputs = vec!["x".to_string()];
        for text in ["x", "0.5 - x", "0.25 + x", "2*x", "1 + 3*x", "1 - 2*x", "0 - x", "cos(x)", "sin(x)"] {
            let d = crate::fit::model::Derived::parse("d", text, &inputs).unwrap();
            let expr = derived_expr(&d, &lit, &|fun, v| format!("{fun}({v})"));
            let got = crate::emit::fixtures::naga_folded_f32("const x0: f32 = 0.3;\n", &expr);
            let want = d.eval_f32(&[0.3]);
            // One f32 operation or two (exact agreement), or naga's cos/sin against Rust's f32
            // ones: a few ulps of values ≤ 1.6.
            assert!((got - want).abs() <= 4.0 * f32::EPSILON, "{text}: naga {got} from '{expr}', f32 {want}");
        }
    }

    /// The published forms' nodes rendered as WGSL and folded by naga's constant evaluator
    /// (x0, x1 constants) give the f32 evaluator's value: exactly for the arithmetic, min, max,
    /// abs, sqrt and select; naga folds exp2, log2 and pow with Rust's f32 functions, the ones
    /// `eval_f32` calls, so those agree exactly too.
    #[test]
    fn published_form_nodes_fold_in_naga_as_in_f32() {
        let e = crate::fit::expr::every_node();
        let text = crate::fit::expr::render_in(crate::fit::expr::Syntax::Wgsl, &e, &|i| format!("x{i}"), &|_, j| format!("c{j}"), &lit);
        // Not at x1 < 0: WGSL's select evaluates both branches, and naga refuses to fold the
        // sqrt of a negative constant (at run time it is an indeterminate value the select
        // discards).
        for (x0, x1) in [(0.0f32, 0.0f32), (0.9, 0.05), (0.7, 0.6), (1.0, 1.0), (0.2, 0.31), (1.5, 0.2)] {
            let decls = format!("const x0: f32 = {};\nconst x1: f32 = {};\n", lit(x0), lit(x1));
            let got = crate::emit::fixtures::naga_folded_f32(&decls, &text);
            let want = crate::fit::expr::eval_f32(&e, &[x0, x1], &[], &[]);
            assert_eq!(got.to_bits(), want.to_bits(), "({x0}, {x1}): naga {got} from '{text}', f32 {want}");
        }
    }

    /// A program's WGSL (every vector node), its bindings made module constants and folded by
    /// naga's constant evaluator, gives the f32 evaluator's bits in each lane: the same
    /// operations per lane (naga folds exp2 with Rust's f32 function, the one the evaluator calls).
    #[test]
    fn program_vector_nodes_fold_in_naga_as_in_f32() {
        use crate::fit::expr::program::{EVERY_CONSTS, EVERY_POINTS, every_vector_node};
        let p = every_vector_node();
        let body = p.render(crate::fit::expr::Syntax::Wgsl, &|i| format!("x{i}"), &EVERY_CONSTS, &lit);
        let mut lets = String::new();
        let mut result = String::new();
        for line in body.lines() {
            if let Some(l) = line.trim().strip_prefix("let ") {
                lets += &format!("const {l}\n");
            } else if let Some(r) = line.trim().strip_prefix("return ") {
                result = r.trim_end_matches(';').to_string();
            }
        }
        for (x0, x1) in EVERY_POINTS {
            let decls = format!("const x0: f32 = {};\nconst x1: f32 = {};\n{lets}", lit(x0), lit(x1));
            let want = p.eval_f32(&[x0, x1], &EVERY_CONSTS);
            for (k, lane) in ["x", "y"].iter().enumerate() {
                let got = crate::emit::fixtures::naga_folded_f32(&decls, &format!("({result}).{lane}"));
                assert_eq!(got.to_bits(), want[k].to_bits(), "({x0}, {x1}) lane {lane}: naga {got}, f32 {}", want[k]);
            }
        }
    }

    /// A whole module: the header lines as comments, the import-path directive, then a
    /// source that naga validates (the directive stripped, as a composer does), whose table
    /// function passes its argument through the module's input clamp.
    #[test]
    fn a_rendered_module_names_itself_and_validates() {
        let args = vec!["x".to_string()];
        let f = Function {
            module: "m",
            name: "m_lut",
            args: &args,
            derived: &[],
            domain: &[(0.25, 2.0)],
            body: Body::Table { values: &[0.0, 1.0, 4.0, 9.0, 16.0], counts: &[5], channels: 1, placements: &[Placement::Nodes] },
        };
        let header = vec!["spec: fits/m.toml".to_string(), "measured error: max abs 0".to_string()];
        let src = render_module(&header, &f);
        let lines: Vec<&str> = src.lines().collect();
        assert_eq!(lines[..3], ["// spec: fits/m.toml", "// measured error: max abs 0", "#define_import_path shadefit::m"], "{src}");
        let plain = strip_directives(&src);
        let m = naga::front::wgsl::parse_str(&plain).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&plain)));
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
            .validate(&m)
            .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&plain)));
        let names: Vec<&str> = m.functions.iter().filter_map(|(_, f)| f.name.as_deref()).collect();
        assert_eq!(names, ["m_input", "m_lut"]);
        assert!(src.contains("let x0 = m_input(x, 2.5e-1f, 2e0f);"), "{src}");
    }

    use super::interpreter as bound;

    /// Emitted WGSL, interpreted, computes what the build's f32 evaluators compute, bit for bit:
    /// a fit with a denominator and a clamp and one without either (`expr::eval_f32` of the
    /// clamped inputs), a one- and a two-axis table (`rust::table_eval_f32`), at points inside,
    /// on and outside the domain, at ±inf and NaN. The tables' texture forms: `_load` with each
    /// `textureLoad` of texel (i, j) read as value i + j·n0 of the table (the KTX2 layout) gives
    /// the table function's value; every form validates in naga; the note says what an r16float
    /// texture changes.
    #[test]
    fn emitted_wgsl_computes_what_the_evaluators_compute() {
        use crate::emit::fixtures::{points, want, Four};
        let four = Four::new();
        let fs = four.functions();
        let header = ["spec: test".to_string()];
        for f in &fs {
            let program = bound::Program::new(&strip_directives(&render_module(&header, f)));
            let h = program.function(f.name);
            for p in points(f) {
                assert_eq!(program.eval(h, &p).0.to_bits(), want(f, &p).to_bits(), "{}{p:?}", f.name);
            }
            let Body::Table { counts, .. } = f.body else { continue };
            for (format, filterable) in [("r32float", false), ("r16float", true)] {
                let tex = TableTexture { file: "data/t.ktx2", format, filterable, keep_const: true };
                let src = strip_directives(&render_table_module(&header, f, Some(&tex)));
                let note = if format == "r32float" { "the same f32 arithmetic on the same values" } else { "the values rounded to r16float as stored" };
                assert!(src.contains(note), "{format}: no '{note}' in\n{src}");
                let mut names: Vec<String> = vec![format!("{}_input", f.module), f.name.to_string(), format!("{}_load", f.name)];
                if filterable {
                    names.extend([format!("{}_uv", f.module), format!("{}_sample", f.name)]);
                }
                let m = naga::front::wgsl::parse_str(&src).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&src)));
                naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
                    .validate(&m)
                    .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&src)));
                let got: Vec<String> = m.functions.iter().filter_map(|(_, g)| g.name.clone()).collect();
                assert_eq!(got, names, "{src}");
                // The `_load` function on the const array: texel (i, j) is value i + j·n0.
                let start = src.find(&format!("fn {}_load(", f.name)).unwrap();
                let end = start + src[start..].find("\n}").unwrap() + 2;
                let mut load = src[start..end].replace("lut: texture_2d<f32>, ", "").replace(&format!("fn {}_load(", f.name), "fn as_table(");
                let table = format!("{}_TABLE", f.module.to_uppercase());
                while let Some(at) = load.find("textureLoad(lut, vec2<u32>(") {
                    let rest = &load[at + "textureLoad(lut, vec2<u32>(".len()..];
                    let close = rest.find("), 0).x").unwrap();
                    let (i, j) = rest[..close].split_once(", ").unwrap();
                    let read = format!("{table}[({j}) * {}u + ({i})]", counts[0]);
                    load = format!("{}{read}{}", &load[..at], &rest[close + "), 0).x".len()..]);
                }
                let program = bound::Program::new(&format!("{}{load}", &src[..start]));
                let (h, g) = (program.function(f.name), program.function("as_table"));
                for p in points(f) {
                    assert_eq!(program.eval(g, &p).0.to_bits(), program.eval(h, &p).0.to_bits(), "{}_load{p:?} ({format})", f.name);
                }
            }
        }
    }

    /// The const form of a table read back from its texture form: every `textureLoad(lut,
    /// vecN<u32>(i, j[, k]), 0)[.swizzle]` of `src` replaced by the const array's texel
    /// ((k·n1 + j)·n0 + i), the function renamed `as_table` and its texture parameter dropped.
    fn load_as_table(src: &str, f: &Function<'_>, counts: &[usize]) -> String {
        let start = src.find(&format!("fn {}_load(", f.name)).unwrap();
        let end = start + src[start..].find("\n}").unwrap() + 2;
        let mut load = src[start..end].replace(&format!("fn {}_load(", f.name), "fn as_table(");
        for tex in ["lut: texture_2d<f32>, ", "lut: texture_3d<f32>, "] {
            load = load.replace(tex, "");
        }
        let table = format!("{}_TABLE", f.module.to_uppercase());
        while let Some(at) = load.find("textureLoad(lut, vec") {
            let open = at + load[at..].find('(').unwrap() + 1;
            let open = open + load[open..].find('(').unwrap() + 1;
            let close = open + load[open..].find("), 0)").unwrap();
            let ijk: Vec<&str> = load[open..close].split(", ").collect();
            let mut rest = close + "), 0)".len();
            for sw in [".xyz", ".xy", ".x"] {
                if load[rest..].starts_with(sw) {
                    rest += sw.len();
                    break;
                }
            }
            let k = if counts.len() == 3 { ijk[2] } else { "0u" };
            let read = format!("{table}[(({k}) * {}u + ({})) * {}u + ({})]", counts.get(1).copied().unwrap_or(1), ijk[1], counts[0], ijk[0]);
            load = format!("{}{read}{}", &load[..at], &load[rest..]);
        }
        format!("{}{load}", &src[..start])
    }

    /// Tables of several channels, three axes and texel-centre placement ([`Grids`]): the
    /// interpreted WGSL computes every channel as the build's f32 evaluator does, bit for bit,
    /// at points inside, on and outside the domain, at ±inf and NaN; with their texture forms
    /// (a 32-bit and a 16-bit format: `texture_3d` for three axes, the channels swizzled out of
    /// the texel) every module validates in naga with the helper functions named, and `_load`
    /// on the const array's texels gives the const function's bits.
    #[test]
    fn multichannel_and_three_axis_tables_compute_what_the_evaluator_computes() {
        use crate::emit::fixtures::{grid_points, want_all, Grids};
        let grids = Grids::new();
        let header = ["spec: test".to_string()];
        for f in &grids.functions() {
            let program = bound::Program::new(&strip_directives(&render_module(&header, f)));
            let h = program.function(f.name);
            for p in grid_points(f) {
                let got: Vec<u32> = program.eval_all(h, &p).iter().map(|(v, _)| v.to_bits()).collect();
                let want: Vec<u32> = want_all(f, &p).iter().map(|v| v.to_bits()).collect();
                assert_eq!(got, want, "{}{p:?}", f.name);
            }
            let Body::Table { counts, channels, .. } = f.body else { unreachable!() };
            let rgba = if channels == 1 { "r" } else if channels == 2 { "rg" } else { "rgba" };
            for (bits, filterable) in [("32float", false), ("16float", true)] {
                let format = format!("{rgba}{bits}");
                let tex = TableTexture { file: "data/t.ktx2", format: &format, filterable, keep_const: true };
                let src = strip_directives(&render_table_module(&header, f, Some(&tex)));
                let m = naga::front::wgsl::parse_str(&src).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&src)));
                naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
                    .validate(&m)
                    .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&src)));
                let mut names: Vec<String> = vec![format!("{}_input", f.module), f.name.to_string(), format!("{}_load", f.name)];
                if filterable {
                    names.extend([format!("{}_uv", f.module), format!("{}_sample", f.name)]);
                }
                let got: Vec<String> = m.functions.iter().filter_map(|(_, g)| g.name.clone()).collect();
                assert_eq!(got, names, "{src}");
                assert_eq!(src.contains("texture_3d<f32>"), counts.len() == 3, "{src}");
                let program = bound::Program::new(&load_as_table(&src, f, counts));
                let (h, g) = (program.function(f.name), program.function("as_table"));
                for p in grid_points(f) {
                    let a: Vec<u32> = program.eval_all(g, &p).iter().map(|(v, _)| v.to_bits()).collect();
                    let b: Vec<u32> = program.eval_all(h, &p).iter().map(|(v, _)| v.to_bits()).collect();
                    assert_eq!(a, b, "{}_load{p:?} ({format})", f.name);
                }
            }
        }
    }

    /// A constant array: its values read back through naga in order, six to a line.
    #[test]
    fn arrays_read_back_through_naga() {
        let values: Vec<f32> = (0..8).map(|i| 0.1 * i as f32 - 0.25).collect();
        let text = array("C", &values);
        assert_eq!(text.lines().count(), 4, "{text}");
        let m = naga::front::wgsl::parse_str(&text).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&text)));
        let (_, c) = m.constants.iter().next().unwrap();
        let naga::Expression::Compose { components, .. } = &m.global_expressions[c.init] else { panic!("{text}") };
        let got: Vec<f32> = components
            .iter()
            .map(|h| match m.global_expressions[*h] {
                naga::Expression::Literal(naga::Literal::F32(v)) => v,
                ref e => panic!("{e:?}"),
            })
            .collect();
        assert_eq!(got, values);
    }
}
