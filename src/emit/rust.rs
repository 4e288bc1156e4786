//! Rust modules for the runtime crate: `pub const` coefficient arrays and `pub fn` CPU
//! versions of every emitted WGSL function, with the same operation order in f32.

use super::expr::render;
use super::f32_literal;
use super::interp::{step_scale, Placement};
use super::wgsl::{Body, Function};

fn lit(v: f32) -> String {
    format!("{}_f32", f32_literal(v))
}

fn array(name: &str, doc: &str, values: &[f32]) -> String {
    let mut s = format!("/// {doc}\npub const {name}: [f32; {}] = [", values.len());
    for (i, v) in values.iter().enumerate() {
        if i % 6 == 0 {
            s.push_str("\n    ");
        } else {
            s.push(' ');
        }
        s.push_str(&lit(*v));
        s.push(',');
    }
    s.push_str("\n];\n");
    s
}

/// A const array of `[f32; channels]` points, three points a line.
fn vec_array(name: &str, doc: &str, values: &[f32], channels: usize) -> String {
    let n = values.len() / channels;
    let mut s = format!("/// {doc}\npub const {name}: [[f32; {channels}]; {n}] = [");
    for (i, v) in values.chunks(channels).enumerate() {
        s.push_str(if i % 3 == 0 { "\n    " } else { " " });
        let items: Vec<String> = v.iter().map(|&x| lit(x)).collect();
        s.push_str(&format!("[{}],", items.join(", ")));
    }
    s.push_str("\n];\n");
    s
}

pub fn render_module(header: &[String], f: &Function<'_>, doc: &str) -> String {
    let upper = f.module.to_uppercase();
    let mut s = String::new();
    for h in header {
        s.push_str(&format!("//! {h}\n"));
    }
    s.push_str(&format!("//!\n//! {doc}\n\n"));
    s.push_str(&format!(
        "/// Domain of each argument; inputs are clamped to it (NaN maps to the lower end).\n\
         pub const {upper}_DOMAIN: [[f32; 2]; {}] = [{}];\n\n",
        f.domain.len(),
        f.domain.iter().map(|(a, b)| format!("[{}, {}]", lit(*a), lit(*b))).collect::<Vec<_>>().join(", ")
    ));
    s.push_str(
        "#[inline]\nfn input(v: f32, lo: f32, hi: f32) -> f32 {\n    if v.is_nan() { lo } else { v.clamp(lo, hi) }\n}\n\n",
    );
    let params: Vec<String> = f.args.iter().map(|a| format!("{a}: f32")).collect();
    let inputs: String = f
        .args
        .iter()
        .zip(f.domain)
        .enumerate()
        .map(|(i, (a, (lo, hi)))| format!("    let x{i} = input({a}, {}, {});\n", lit(*lo), lit(*hi)))
        .chain(f.derived.iter().enumerate().map(|(k, d)| {
            format!(
                "    let x{} = {};\n",
                f.args.len() + k,
                super::wgsl::derived_expr(d, &lit, &|fun, v| format!("{v}.{fun}()"))
            )
        }))
        .collect();
    match &f.body {
        Body::Fit { expr, num, den, clamp } => {
            s.push_str(&array(&format!("{upper}_NUM"), "Numerator coefficients, one per numerator term.", num));
            if !den.is_empty() {
                s.push_str(&array(
                    &format!("{upper}_DEN"),
                    "Denominator coefficients (the constant term 1 is implicit).",
                    den,
                ));
            }
            let body = render(
                expr,
                &|i| format!("x{i}"),
                &|a, j| format!("{upper}_{}[{j}]", if a == 0 { "NUM" } else { "DEN" }),
                &lit,
            );
            let ret = match clamp {
                Some((lo, hi)) => format!("({body}).clamp({}, {})", lit(*lo), lit(*hi)),
                None => body,
            };
            s.push_str(&format!(
                "\n/// CPU version of the WGSL function of the same name.\npub fn {}({}) -> f32 {{\n{inputs}    {ret}\n}}\n",
                f.name,
                params.join(", ")
            ));
        }
        Body::Table { values, counts, channels, placements } => {
            let t = format!("{upper}_TABLE");
            let c = *channels;
            if c == 1 {
                s.push_str(&array(&t, "Table values on a uniform grid (first axis fastest).", values));
            } else {
                s.push_str(&vec_array(&t, &format!("Table values on a uniform grid (first axis fastest), {c} channels a point."), values, c));
            }
            let ty = if c == 1 { "f32".to_string() } else { format!("[f32; {c}]") };
            s.push_str(&format!(
                "\n/// CPU version of the WGSL function of the same name (linear interpolation).\npub fn {}({}) -> {ty} {{\n{inputs}",
                f.name,
                params.join(", ")
            ));
            for (i, (((lo, hi), n), p)) in f.domain.iter().zip(counts.iter()).zip(placements.iter()).enumerate() {
                let (scale, lo, last) = (lit(step_scale(*lo, *hi, *n, *p)), lit(*lo), n - 2);
                s.push_str(&match p {
                    Placement::Nodes => format!("    let t{i} = (x{i} - {lo}) * {scale};\n    let i{i} = (t{i} as u32).min({last});\n"),
                    Placement::Centres => format!("    let t{i} = (x{i} - {lo}) * {scale} - 0.5;\n    let i{i} = (t{i}.max(0.0) as u32).min({last});\n"),
                });
                s.push_str(&format!("    let f{i} = (t{i} - i{i} as f32).clamp(0.0, 1.0);\n"));
            }
            let (nx, ny) = (counts[0], counts.get(1).copied().unwrap_or(1));
            match counts.len() {
                1 => s.push_str("    let i0 = i0 as usize;\n"),
                2 => s.push_str(&format!("    let k = (i1 * {nx} + i0) as usize;\n")),
                _ => s.push_str(&format!("    let k = ((i2 * {ny} + i1) * {nx} + i0) as usize;\n")),
            }
            let read = super::wgsl::flat_read(counts, &t, "");
            // Several channels: the lerp channel by channel (`c`: a name no argument may take).
            let lerp = |a: &str, b: &str, f: &str| {
                if c == 1 { format!("{a} * (1.0 - {f}) + {b} * {f}") } else { format!("std::array::from_fn::<f32, {c}, _>(|c| {a}[c] * (1.0 - {f}) + {b}[c] * {f})") }
            };
            s.push_str(&super::wgsl::blend_lines(counts.len(), &read, &lerp, &|v| format!("    {v}")));
        }
    }
    s
}

/// f32 evaluation of a one-value table lookup at its nodes with the emitted operation order
/// (see [`table_lookup_f32`]).
pub fn table_eval_f32(values: &[f32], counts: &[usize], domain: &[(f32, f32)], x: &[f32]) -> f32 {
    table_lookup_f32(values, 1, counts, domain, &[Placement::Nodes; 3][..counts.len()], x)[0]
}

/// f32 evaluation of a table lookup with the emitted operation order: each argument clamped to
/// its domain (NaN to the lower end), its address as the emitted code computes it
/// ([`super::interp::emitted_address`]), then [`super::interp::multilinear`] of the `channels`
/// values a point.
pub fn table_lookup_f32(values: &[f32], channels: usize, counts: &[usize], domain: &[(f32, f32)], placements: &[Placement], x: &[f32]) -> Vec<f32> {
    let mut at: [super::interp::Address<f32>; 3] = [(0, 0, 0.0); 3];
    for d in 0..counts.len() {
        let (lo, hi) = domain[d];
        let xd = super::expr::sanitize(x[d], lo, hi);
        at[d] = super::interp::emitted_address(xd, lo, hi, counts[d], placements[d]);
    }
    let at = &at[..counts.len()];
    use super::interp::multilinear;
    match channels {
        1 => multilinear(values.as_chunks::<1>().0, counts, at).to_vec(),
        2 => multilinear(values.as_chunks::<2>().0, counts, at).to_vec(),
        3 => multilinear(values.as_chunks::<3>().0, counts, at).to_vec(),
        4 => multilinear(values.as_chunks::<4>().0, counts, at).to_vec(),
        _ => panic!("a table point has 1 to 4 channels, not {channels}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emit::fixtures::compiled_bits_with;

    /// An emitted array: six values a line (so a 4096-entry table stays readable and its diffs
    /// local), each a literal that reads back to the same f32 bits, in order.
    #[test]
    fn arrays_hold_six_round_trip_literals_a_line() {
        let values: Vec<f32> = (0..20).map(|i| (i as f32 * 0.37).sin() / 3.0 + if i == 7 { f32::MIN_POSITIVE } else { 0.0 }).collect();
        let text = array("T", "Values.", &values);
        let body: Vec<&str> = text.lines().skip(2).take_while(|l| *l != "];").collect();
        assert_eq!(body.len(), 4, "{text}");
        let mut read = Vec::new();
        for line in &body {
            let items: Vec<&str> = line.split(',').map(str::trim).filter(|v| !v.is_empty()).collect();
            assert!(items.len() <= 6, "{line}");
            read.extend(items.iter().map(|v| v.trim_end_matches("_f32").parse::<f32>().unwrap()));
        }
        assert_eq!(read.iter().map(|v| v.to_bits()).collect::<Vec<_>>(), values.iter().map(|v| v.to_bits()).collect::<Vec<_>>());
    }

    /// The rendered modules, compiled by rustc and run, compute what the f32 evaluators the
    /// build validates with compute, bit for bit (Rust never contracts to FMA): a fit with a
    /// denominator and a clamp and one without a denominator or clamp (`expr::eval_f32` on the
    /// clamped inputs), a one- and a two-axis table (`table_eval_f32`), at points inside, on
    /// and outside the domain, at ±inf and at NaN (the lower end).
    #[test]
    fn rendered_modules_compile_and_compute_what_the_evaluators_compute() {
        use crate::emit::fixtures::{points, want, Four};
        let four = Four::new();
        let fs = four.functions();
        let mut modules = Vec::new();
        let mut main = String::from("fn main() {\n");
        for f in &fs {
            modules.push((f.module.to_string(), render_module(&["spec: test".to_string()], f, "A test module.")));
            main = format!("mod {m};\n{main}", m = f.module);
            for p in points(f) {
                let a: Vec<String> = p.iter().map(|v| format!("f32::from_bits({:#x})", v.to_bits())).collect();
                main.push_str(&format!("    println!(\"{{}}\", {m}::{n}({a}).to_bits());\n", m = f.module, n = f.name, a = a.join(", ")));
            }
        }
        main.push_str("}\n");
        let got = compiled_bits_with(&main, &modules);
        let expected: Vec<(String, u32)> = fs.iter().flat_map(|f| points(f).into_iter().map(move |p| (format!("{}{p:?}", f.name), want(f, &p).to_bits()))).collect();
        assert_eq!(got.len(), expected.len());
        for (g, (at, w)) in got.iter().zip(&expected) {
            assert_eq!(f32::from_bits(*g).to_bits(), *w, "{at}: compiled {} vs evaluator {}", f32::from_bits(*g), f32::from_bits(*w));
        }
    }

    /// `main` compiled by rustc and run: the u32 it prints, one a line.
    fn compiled_bits(main: &str) -> Vec<u32> {
        compiled_bits_with(main, &[])
    }

    /// Tables of several channels, three axes and texel-centre placement (`Grids`), rendered,
    /// compiled by rustc and run, compute every channel as [`table_lookup_f32`] does, bit for bit
    /// (Rust never contracts to FMA), at points inside, on and outside the domain, ±inf and NaN.
    #[test]
    fn multichannel_and_three_axis_tables_compile_and_compute_what_the_evaluator_computes() {
        use crate::emit::fixtures::{grid_points, want_all, Grids};
        let grids = Grids::new();
        let fs = grids.functions();
        let mut modules = Vec::new();
        let mut main = String::from("fn main() {\n");
        for f in &fs {
            modules.push((f.module.to_string(), render_module(&["spec: test".to_string()], f, "A test module.")));
            main = format!("mod {m};\n{main}", m = f.module);
            for p in grid_points(f) {
                let a: Vec<String> = p.iter().map(|v| format!("f32::from_bits({:#x})", v.to_bits())).collect();
                let Body::Table { channels, .. } = f.body else { unreachable!() };
                let value = if channels == 1 { format!("[{}::{}({})]", f.module, f.name, a.join(", ")) } else { format!("{}::{}({})", f.module, f.name, a.join(", ")) };
                main.push_str(&format!("    for v in {value} {{ println!(\"{{}}\", v.to_bits()); }}\n"));
            }
        }
        main.push_str("}\n");
        let got = compiled_bits_with(&main, &modules);
        let expected: Vec<(String, u32)> = fs
            .iter()
            .flat_map(|f| grid_points(f).into_iter().flat_map(move |p| want_all(f, &p).into_iter().enumerate().map(move |(c, w)| (format!("{}{p:?}[{c}]", f.name), w.to_bits()))))
            .collect();
        assert_eq!(got.len(), expected.len());
        for (g, (at, w)) in got.iter().zip(&expected) {
            assert_eq!(*g, *w, "{at}: compiled {} vs evaluator {}", f32::from_bits(*g), f32::from_bits(*w));
        }
    }

    /// At texel centres the lookup interpolates between centres and holds the edge texel
    /// outside them (clamp to edge), worked out by hand on values exact in binary: 4 centres on
    /// [0, 2] at 0.25, 0.75, 1.25, 1.75 with values 0, 1, 4, 9, two channels (v and −2v).
    #[test]
    fn centred_lookups_interpolate_between_centres_and_hold_the_edges() {
        let v = [0.0f32, -0.0, 1.0, -2.0, 4.0, -8.0, 9.0, -18.0];
        let at = |x: f32| table_lookup_f32(&v, 2, &[4], &[(0.0, 2.0)], &[Placement::Centres], &[x]);
        assert_eq!(at(0.25), [0.0, 0.0]);
        assert_eq!(at(0.5), [0.5, -1.0]); // halfway between the first two centres
        assert_eq!(at(1.375), [5.25, -10.5]); // a quarter of the way from 4 to 9
        assert_eq!(at(1.75), [9.0, -18.0]);
        for x in [0.0, 0.1, -5.0] {
            assert_eq!(at(x), [0.0, 0.0], "{x}: below the first centre");
        }
        for x in [1.9, 2.0, 7.0] {
            assert_eq!(at(x), [9.0, -18.0], "{x}: above the last centre");
        }
    }

    /// The published forms' nodes rendered as Rust, compiled by rustc and run, compute the
    /// f32 evaluator's bits (the same f32 operations; Rust never contracts to FMA).
    #[test]
    fn published_form_nodes_compile_and_compute_what_the_evaluator_computes() {
        let e = crate::fit::expr::every_node();
        let lit = |v: f32| format!("{}_f32", super::super::f32_literal(v));
        let text = crate::fit::expr::render_in(crate::fit::expr::Syntax::Rust, &e, &|i| format!("x{i}"), &|_, j| format!("c{j}"), &lit);
        let points = [(0.0f32, 0.0f32), (0.9, 0.05), (0.7, 0.6), (1.0, 1.0), (0.2, 0.31), (1.5, -0.2)];
        let mut main = format!("fn f(x0: f32, x1: f32) -> f32 {{\n    {text}\n}}\nfn main() {{\n");
        for (x0, x1) in points {
            main.push_str(&format!("    println!(\"{{}}\", f(f32::from_bits({:#x}), f32::from_bits({:#x})).to_bits());\n", x0.to_bits(), x1.to_bits()));
        }
        main.push_str("}\n");
        let got = compiled_bits(&main);
        for ((x0, x1), g) in points.iter().zip(&got) {
            let want = crate::fit::expr::eval_f32(&e, &[*x0, *x1], &[], &[]);
            assert_eq!(*g, want.to_bits(), "({x0}, {x1}): compiled {} vs evaluator {want} from '{text}'", f32::from_bits(*g));
        }
        assert_eq!(got.len(), points.len());
    }

    /// A program's Rust (every vector node, one lane at a time), compiled by rustc and run,
    /// computes the f32 evaluator's bits in each lane.
    #[test]
    fn program_vector_nodes_compile_and_compute_what_the_evaluator_computes() {
        use crate::fit::expr::program::{EVERY_CONSTS, EVERY_POINTS, every_vector_node};
        let p = every_vector_node();
        let lit = |v: f32| format!("{}_f32", super::super::f32_literal(v));
        let body = p.render(crate::fit::expr::Syntax::Rust, &|i| format!("x{i}"), &EVERY_CONSTS, &lit);
        let mut main = format!("fn f(x0: f32, x1: f32) -> [f32; 2] {{\n{body}}}\nfn main() {{\n");
        for (x0, x1) in EVERY_POINTS {
            main.push_str(&format!("    for v in f(f32::from_bits({:#x}), f32::from_bits({:#x})) {{ println!(\"{{}}\", v.to_bits()); }}\n", x0.to_bits(), x1.to_bits()));
        }
        main.push_str("}\n");
        let got = compiled_bits(&main);
        let want: Vec<u32> = EVERY_POINTS.iter().flat_map(|&(x0, x1)| p.eval_f32(&[x0, x1], &EVERY_CONSTS)).map(f32::to_bits).collect();
        assert_eq!(got, want, "{main}");
    }

    /// Linear and bilinear interpolation worked out by hand on values and positions exact in
    /// binary (so every product and sum below is exact in f32), clamped at the edges.
    #[test]
    fn table_lookups_interpolate_linearly() {
        // 1-D: 5 nodes on [0, 2] (spacing 0.5), values 0, 1, 4, 9, 16.
        let v = [0.0, 1.0, 4.0, 9.0, 16.0];
        let d = [(0.0f32, 2.0f32)];
        assert_eq!(table_eval_f32(&v, &[5], &d, &[0.75]), 2.5); // halfway between 1 and 4
        assert_eq!(table_eval_f32(&v, &[5], &d, &[1.625]), 10.75); // a quarter of the way from 9 to 16
        assert_eq!(table_eval_f32(&v, &[5], &d, &[2.0]), 16.0);
        assert_eq!(table_eval_f32(&v, &[5], &d, &[-3.0]), 0.0);
        assert_eq!(table_eval_f32(&v, &[5], &d, &[9.0]), 16.0);
        // 2-D: 3 × 2 nodes on [0, 1] × [0, 4], value x_i + 10 y_j at node (i, j), first axis
        // fastest; bilinear interpolation of a bilinear function is exact.
        let nodes: Vec<f32> = (0..2).flat_map(|j| (0..3).map(move |i| i as f32 * 0.5 + 10.0 * j as f32 * 4.0)).collect();
        let d2 = [(0.0f32, 1.0f32), (0.0f32, 4.0f32)];
        for (x, y) in [(0.25f32, 1.0f32), (0.75, 3.0), (1.0, 4.0), (0.0, 0.0), (0.5, 2.0)] {
            assert_eq!(table_eval_f32(&nodes, &[3, 2], &d2, &[x, y]), x + 10.0 * y, "({x}, {y})");
        }
        // x·y is bilinear too, and not separable: the cross term must come from four texels.
        let nodes: Vec<f32> = (0..2).flat_map(|j| (0..3).map(move |i| (i as f32 * 0.5) * (j as f32 * 4.0))).collect();
        assert_eq!(table_eval_f32(&nodes, &[3, 2], &d2, &[0.75, 1.0]), 0.75);
    }

    /// Where (hi − lo)·scale rounds above n − 1 in f32 (16 points on [0.1, 0.9]: 15.000001,
    /// worked out with numpy's float32), the upper weight would be 1.000001 and the lookup at
    /// hi would extrapolate past the last value; clamped, it returns the last value exactly
    /// and every lookup lies between its two neighbours.
    #[test]
    fn table_weights_stay_in_zero_one_where_the_index_rounds_past_the_last_point() {
        let (lo, hi) = (0.1f32, 0.9f32);
        let scale = 15.0f32 / (hi - lo);
        assert!((hi - lo) * scale > 15.0, "the case this test is about");
        let mut v = [0.0f32; 16];
        v[15] = 1000.0;
        assert_eq!(table_eval_f32(&v, &[16], &[(lo, hi)], &[hi]), 1000.0);
        // The same axis second in a 2-D table, values 1000 on its last row.
        let v2: Vec<f32> = (0..16).flat_map(|j| [if j == 15 { 1000.0 } else { 0.0 }; 2]).collect();
        assert_eq!(table_eval_f32(&v2, &[2, 16], &[(0.0, 1.0), (lo, hi)], &[0.5, hi]), 1000.0);
        for k in 0..=1000 {
            let x = lo + (hi - lo) * k as f32 / 1000.0;
            let y = table_eval_f32(&v, &[16], &[(lo, hi)], &[x]);
            assert!((0.0..=1000.0).contains(&y), "{y} at {x}");
        }
    }
}
