//! WGSL libraries. Each file names itself with a `#define_import_path shadefit::NAME`
//! directive (naga_oil/bevy convention); a composer strips directive lines before handing the
//! source to naga. Inputs are clamped to the fit domain, NaN maps to the domain's lower end
//! (tested on the bit pattern, which no compiler may fold away), so no input yields NaN or ±inf.

use super::expr::{render, Expr};
use super::f32_literal;

/// What an emitted function computes.
pub enum Body<'a> {
    Fit { expr: &'a Expr, num: &'a [f32], den: &'a [f32], clamp: Option<(f32, f32)> },
    /// Linear interpolation in a table on a uniform grid of each axis (1 or 2 axes; for two,
    /// `values[j * nx + i]` with i along the first axis).
    Table { values: &'a [f32], counts: &'a [usize] },
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
    let upper = f.module.to_uppercase();
    let mut s = String::new();
    for h in header {
        s.push_str(&format!("// {h}\n"));
    }
    s.push_str(&format!("#define_import_path shadefit::{}\n\n", f.module));
    s.push_str(&format!(
        "// Clamp an input to [lo, hi]; NaN (any exponent-all-ones pattern with a non-zero\n\
         // mantissa) maps to lo.\nfn {m}_input(v: f32, lo: f32, hi: f32) -> f32 {{\n    \
         let nan = (bitcast<u32>(v) & 0x7fffffffu) > 0x7f800000u;\n    \
         return select(clamp(v, lo, hi), lo, nan);\n}}\n\n",
        m = f.module
    ));
    let params: Vec<String> = f.args.iter().map(|a| format!("{a}: f32")).collect();
    let inputs: String = f
        .args
        .iter()
        .zip(f.domain)
        .enumerate()
        .map(|(i, (a, (lo, hi)))| format!("    let x{i} = {}_input({a}, {}, {});\n", f.module, lit(*lo), lit(*hi)))
        .chain(f.derived.iter().enumerate().map(|(k, d)| {
            format!("    let x{} = {};\n", f.args.len() + k, derived_expr(d, &lit, &|fun, v| format!("{fun}({v})")))
        }))
        .collect();
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
        Body::Table { values, counts } => {
            s.push_str(&array(&format!("{upper}_TABLE"), values));
            s.push_str(&format!("\nfn {}({}) -> f32 {{\n{inputs}", f.name, params.join(", ")));
            for (i, ((lo, hi), n)) in f.domain.iter().zip(counts.iter()).enumerate() {
                s.push_str(&format!(
                    "    let t{i} = (x{i} - {lo}) * {scale};\n    let i{i} = min(u32(t{i}), {last}u);\n    let f{i} = t{i} - f32(i{i});\n",
                    lo = lit(*lo),
                    scale = lit((*n as f32 - 1.0) / (hi - lo)),
                    last = n - 2
                ));
            }
            let t = format!("{upper}_TABLE");
            if counts.len() == 1 {
                s.push_str(&format!("    return {t}[i0] * (1.0f - f0) + {t}[i0 + 1u] * f0;\n}}\n"));
            } else {
                let nx = counts[0];
                s.push_str(&format!(
                    "    let k = i1 * {nx}u + i0;\n    \
                     let a = {t}[k] * (1.0f - f0) + {t}[k + 1u] * f0;\n    \
                     let b = {t}[k + {nx}u] * (1.0f - f0) + {t}[k + {nx1}u] * f0;\n    \
                     return a * (1.0f - f1) + b * f1;\n}}\n",
                    nx1 = nx + 1
                ));
            }
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
