//! Functions of every body shape, for the emitters' tests: a fit with a denominator and a
//! clamp, one without either, a one- and a two-axis table; the points they are run at (inside,
//! on and outside the domain, ±inf, NaN); what the build's f32 evaluators give there; the
//! value naga's constant evaluator folds a WGSL expression to; and what a `main` compiled by
//! rustc prints.

use super::interp::Placement;
use super::rust::table_lookup_f32;
use super::wgsl::{Body, Function};
use crate::fit::expr::{self, Expr};
use crate::fit::model::RationalModel;

/// The data the functions borrow.
pub struct Four {
    a1: Vec<String>,
    a2: Vec<String>,
    e_rat: Expr,
    e_poly: Expr,
    t1: Vec<f32>,
    t2: Vec<f32>,
}

const RAT_NUM: [f32; 3] = [0.5, -1.25, 3.0];
const RAT_DEN: [f32; 1] = [0.75];
const POLY_NUM: [f32; 4] = [1.0, -0.5, 0.125, 2.0];
const D1: [(f32, f32); 1] = [(0.25, 2.0)];
const D2: [(f32, f32); 2] = [(0.0, 1.0), (-1.0, 3.0)];

/// Each argument's values: inside, on and outside [0.25, 2] and [0, 1] × [−1, 3].
const XS: [f32; 13] = [-1.0, 0.0, 0.25, 0.3, 0.5, 1.0, 1.37, 2.0, 3.0, 5.0, f32::INFINITY, f32::NEG_INFINITY, f32::NAN];

impl Four {
    pub fn new() -> Four {
        let form = |f| expr::model_expr(&RationalModel::parse_form(f, "x").unwrap());
        Four {
            a1: vec!["x".to_string()],
            a2: vec!["x".to_string(), "y".to_string()],
            e_rat: form("rational(2,1)"),
            e_poly: form("rational(3,0)"),
            t1: (0..7).map(|i| (i as f32).sqrt() * 0.3 - 0.4).collect(),
            t2: (0..12).map(|i| (i as f32 * 0.7).sin()).collect(),
        }
    }

    /// (0.5 − 1.25x + 3x²)/(1 + 0.75x) clamped to [0, 1.5] and 1 − 0.5x + 0.125x² + 2x³, on
    /// [0.25, 2]; a 7-point table on it and a 3 × 4 table on [0, 1] × [−1, 3].
    pub fn functions(&self) -> [Function<'_>; 4] {
        let fit = |name, expr, num, den, clamp| Function { module: name, name, args: &self.a1, derived: &[], domain: &D1, body: Body::Fit { expr, num, den, clamp } };
        [
            fit("m_rat", &self.e_rat, &RAT_NUM[..], &RAT_DEN[..], Some((0.0f32, 1.5f32))),
            fit("m_poly", &self.e_poly, &POLY_NUM[..], &[][..], None),
            Function { module: "m_t1", name: "m_t1", args: &self.a1, derived: &[], domain: &D1, body: Body::Table { values: &self.t1, counts: &[7], channels: 1, placements: &[Placement::Nodes] } },
            Function { module: "m_t2", name: "m_t2", args: &self.a2, derived: &[], domain: &D2, body: Body::Table { values: &self.t2, counts: &[3, 4], channels: 1, placements: &[Placement::Nodes; 2] } },
        ]
    }
}

/// The f32 that naga's constant evaluator folds the WGSL expression `expr` to (`const v: f32 =
/// EXPR;` after the declarations `decls`), for judging emitted expressions without a GPU.
pub fn naga_folded_f32(decls: &str, expr: &str) -> f32 {
    let src = format!("{decls}const v: f32 = {expr};\n");
    let m = naga::front::wgsl::parse_str(&src).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&src)));
    let c = m.constants.iter().find(|(_, c)| c.name.as_deref() == Some("v")).unwrap().1;
    let naga::Expression::Literal(naga::Literal::F32(v)) = m.global_expressions[c.init] else { panic!("{src} is not folded to a literal") };
    v
}

/// The points `f` is run at: every value of [`XS`] for each argument, all combinations.
pub fn points(f: &Function<'_>) -> Vec<Vec<f32>> {
    match f.args.len() {
        1 => XS.iter().map(|&x| vec![x]).collect(),
        _ => XS.iter().flat_map(|&x| XS.iter().map(move |&y| vec![x, y])).collect(),
    }
}

/// `f` at `p` as the build's f32 evaluators compute it: `expr::eval_f32` of the clamped inputs
/// (NaN to the lower end), then the clamp; `table_eval_f32`.
pub fn want(f: &Function<'_>, p: &[f32]) -> f32 {
    match &f.body {
        Body::Fit { expr, num, den, clamp } => {
            let x: Vec<f32> = p.iter().zip(f.domain).map(|(&v, &(lo, hi))| expr::sanitize(v, lo, hi)).collect();
            let v = expr::eval_f32(expr, &x, num, den);
            clamp.map_or(v, |(lo, hi)| v.clamp(lo, hi))
        }
        Body::Table { values, counts, channels, placements } => table_lookup_f32(values, *channels, counts, f.domain, placements, p)[0],
    }
}

/// Tables of the shapes beyond one value at the nodes of one or two axes: two channels at the
/// texel centres of one axis, one value over three axes (nodes, centres, nodes), three channels
/// at the centres of three axes, and four channels over two axes.
pub struct Grids {
    a1: Vec<String>,
    a2: Vec<String>,
    a3: Vec<String>,
    c2: Vec<f32>,
    s3: Vec<f32>,
    c3: Vec<f32>,
    c4: Vec<f32>,
}

const D3: [(f32, f32); 3] = [(0.0, 1.0), (-1.0, 3.0), (0.25, 2.0)];
const CENTRES: [Placement; 3] = [Placement::Centres; 3];
const MIXED: [Placement; 3] = [Placement::Nodes, Placement::Centres, Placement::Nodes];

impl Grids {
    pub fn new() -> Grids {
        let v = |n: usize, k: f32| (0..n).map(|i| ((i as f32 + k) * 0.7).sin()).collect::<Vec<f32>>();
        Grids {
            a1: vec!["x".to_string()],
            a2: vec!["x".to_string(), "y".to_string()],
            a3: vec!["x".to_string(), "y".to_string(), "z".to_string()],
            c2: v(5 * 2, 0.0),
            s3: v(3 * 2 * 4, 0.3),
            c3: v(2 * 3 * 2 * 3, 0.6),
            c4: v(3 * 4 * 4, 0.9),
        }
    }

    pub fn functions(&self) -> [Function<'_>; 4] {
        let t = |name, args, domain, values, counts, channels, placements| Function {
            module: name,
            name,
            args,
            derived: &[],
            domain,
            body: Body::Table { values, counts, channels, placements },
        };
        [
            t("m_c2", &self.a1, &D1[..], &self.c2[..], &[5][..], 2, &CENTRES[..1]),
            t("m_s3", &self.a3, &D3[..], &self.s3[..], &[3, 2, 4][..], 1, &MIXED[..]),
            t("m_c3", &self.a3, &D3[..], &self.c3[..], &[2, 3, 2][..], 3, &CENTRES[..]),
            t("m_c4", &self.a2, &D2[..], &self.c4[..], &[3, 4][..], 4, &MIXED[..2]),
        ]
    }
}

/// Fewer values an argument for three arguments: inside, on and outside each domain, ±inf, NaN.
const XS3: [f32; 8] = [-1.0, 0.25, 0.3, 1.37, 2.0, 5.0, f32::INFINITY, f32::NAN];

/// The points a table of [`Grids`] is run at (all combinations; [`XS3`] for three arguments).
pub fn grid_points(f: &Function<'_>) -> Vec<Vec<f32>> {
    match f.args.len() {
        3 => XS3.iter().flat_map(|&x| XS3.iter().flat_map(move |&y| XS3.iter().map(move |&z| vec![x, y, z]))).collect(),
        _ => points(f),
    }
}

/// Every channel of table `f` at `p` as the build's f32 evaluator computes it.
pub fn want_all(f: &Function<'_>, p: &[f32]) -> Vec<f32> {
    match &f.body {
        Body::Table { values, counts, channels, placements } => table_lookup_f32(values, *channels, counts, f.domain, placements, p),
        Body::Fit { .. } => vec![want(f, p)],
    }
}

/// `main` compiled by rustc with the modules `(name, text)` beside `main.rs` (`mod name;` in
/// it), and run: the u32 it prints, one a line.
pub fn compiled_bits_with(main: &str, modules: &[(String, String)]) -> Vec<u32> {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    for (name, text) in modules {
        std::fs::write(dir.join(format!("{name}.rs")), text).unwrap();
    }
    std::fs::write(dir.join("main.rs"), main).unwrap();
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let out = std::process::Command::new(rustc).args(["--edition", "2021", "-A", "warnings", "-o"]).arg(dir.join("main")).arg(dir.join("main.rs")).output().unwrap();
    assert!(out.status.success(), "rustc: {}\n{main}", String::from_utf8_lossy(&out.stderr));
    let run = std::process::Command::new(dir.join("main")).output().unwrap();
    String::from_utf8(run.stdout).unwrap().lines().map(|l| l.parse().unwrap()).collect()
}
