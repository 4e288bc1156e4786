//! Emitted code of a two-stage fit (`kind = "fields"`): a function returning the k
//! coefficients c_k(outer) (one rational field each, like the published `CalcFuzzPsCoeffs`,
//! meant to be evaluated once per material), an evaluator Σ c_k b_k(args) of the inner basis
//! (per light direction), and in Rust an f64 version of the coefficient function for
//! evaluation at build time with the full-precision coefficients.
//!
//! Outer inputs are clamped to the fit domain (NaN → lower end), the evaluator's arguments to
//! their domain, and its result to the quantity's range with NaN → the range's lower end, so no
//! f32 input (coefficients included) yields NaN or ±inf.

use super::expr::{eval_f32, render, sanitize, Expr};
use super::f32_literal;
use crate::fit::model::{Derived, Term};

/// One field: its expression (offset + factor·P/Q) and f32 coefficient arrays.
pub struct Field {
    pub expr: Expr,
    pub num: Vec<f32>,
    pub den: Vec<f32>,
}

pub struct FieldsFunction<'a> {
    pub module: &'a str,
    /// Name of the coefficient function.
    pub name: &'a str,
    pub args: &'a [String],
    pub derived: &'a [Derived],
    pub domain: &'a [(f32, f32)],
    pub fields: &'a [Field],
    /// The inner basis: evaluator name, its argument names and domain, terms (monomials in
    /// those arguments) and output range.
    pub evaluator: &'a str,
    pub eval_args: &'a [String],
    pub eval_domain: &'a [(f32, f32)],
    pub terms: &'a [Term],
    pub range: (f32, f32),
}

/// Products of the arguments of one monomial, left to right (None for the constant).
fn monomial_factors(t: &Term) -> Option<Vec<usize>> {
    let m = &t.monomials[0];
    let v: Vec<usize> = m.exps.iter().enumerate().flat_map(|(i, &e)| std::iter::repeat_n(i, e as usize)).collect();
    (!v.is_empty()).then_some(v)
}

/// The evaluator's sum c0·b0 + c1·b1 + … as text; `c(k)` names coefficient k, `a(i)` argument i.
fn basis_sum(terms: &[Term], c: &dyn Fn(usize) -> String, a: &dyn Fn(usize) -> String) -> String {
    let parts: Vec<String> = terms
        .iter()
        .enumerate()
        .map(|(k, t)| match monomial_factors(t) {
            None => c(k),
            Some(f) if f.len() == 1 => format!("{} * {}", c(k), a(f[0])),
            Some(f) => format!("{} * ({})", c(k), f.iter().map(|&i| a(i)).collect::<Vec<_>>().join(" * ")),
        })
        .collect();
    parts.join(" + ")
}

/// The evaluator in f32 with the emitted operation order (before the output clamp).
pub fn basis_sum_f32(terms: &[Term], c: &[f32], args: &[f32]) -> f32 {
    let mut sum = 0.0f32;
    for (k, t) in terms.iter().enumerate() {
        let v = match monomial_factors(t) {
            None => c[k],
            Some(f) => {
                let mut p = args[f[0]];
                for &i in &f[1..] {
                    p *= args[i];
                }
                c[k] * p
            }
        };
        sum = if k == 0 { v } else { sum + v };
    }
    sum
}

/// The whole emitted evaluator in f32: arguments sanitised, sum, result clamped (NaN → lo).
pub fn evaluator_f32(f: &FieldsFunction<'_>, c: &[f32], args: &[f32]) -> f32 {
    let a: Vec<f32> = args.iter().zip(f.eval_domain).map(|(&v, &(lo, hi))| sanitize(v, lo, hi)).collect();
    sanitize(basis_sum_f32(f.terms, c, &a), f.range.0, f.range.1)
}

/// The emitted coefficient function in f32 (features as `expr::features_f32` computes them).
pub fn coefficients_f32(f: &FieldsFunction<'_>, features: &[f32]) -> Vec<f32> {
    f.fields.iter().map(|fl| eval_f32(&fl.expr, features, &fl.num, &fl.den)).collect()
}

fn wlit(v: f32) -> String {
    format!("{}f", f32_literal(v))
}

fn rlit(v: f32) -> String {
    format!("{}_f32", f32_literal(v))
}

fn rlit64(v: f64) -> String {
    format!("{v:e}_f64")
}

fn list(values: impl Iterator<Item = String>) -> String {
    let mut s = String::new();
    for (i, v) in values.enumerate() {
        s.push_str(if i % 6 == 0 { "\n    " } else { " " });
        s.push_str(&v);
        s.push(',');
    }
    s.push('\n');
    s
}

fn inputs(f: &FieldsFunction<'_>, clamp_fn: &str, lit: &dyn Fn(f32) -> String, call: &dyn Fn(&str, &str) -> String) -> String {
    f.args
        .iter()
        .zip(f.domain)
        .enumerate()
        .map(|(i, (a, (lo, hi)))| format!("    let x{i} = {clamp_fn}({a}, {}, {});\n", lit(*lo), lit(*hi)))
        .chain(f.derived.iter().enumerate().map(|(k, d)| {
            format!("    let x{} = {};\n", f.args.len() + k, super::wgsl::derived_expr(d, lit, call))
        }))
        .collect()
}

/// One line per field, `        EXPR,`, coefficients named `{UPPER}_NUM{k}{suffix}[j]`.
fn field_lines(f: &FieldsFunction<'_>, suffix: &str, lit: &dyn Fn(f32) -> String) -> String {
    let upper = f.module.to_uppercase();
    f.fields
        .iter()
        .enumerate()
        .map(|(k, fl)| {
            let e = render(
                &fl.expr,
                &|i| format!("x{i}"),
                &|a, j| format!("{upper}_{}{k}{suffix}[{j}]", if a == 0 { "NUM" } else { "DEN" }),
                lit,
            );
            format!("        {e},\n")
        })
        .collect()
}

/// The evaluator's argument lines `    let a{i} = CLAMP(arg, lo, hi);`.
fn evaluator_inputs(f: &FieldsFunction<'_>, clamp_fn: &str, lit: &dyn Fn(f32) -> String) -> String {
    f.eval_args
        .iter()
        .zip(f.eval_domain)
        .enumerate()
        .map(|(i, (a, (lo, hi)))| format!("    let a{i} = {clamp_fn}({a}, {}, {});\n", lit(*lo), lit(*hi)))
        .collect()
}

pub fn render_wgsl(header: &[String], f: &FieldsFunction<'_>) -> String {
    let upper = f.module.to_uppercase();
    let m = f.module;
    let nk = f.fields.len();
    let mut s = String::new();
    for h in header {
        s.push_str(&format!("// {h}\n"));
    }
    s.push_str(&format!("#define_import_path shadefit::{m}\n\n"));
    s.push_str(&format!(
        "// Clamp a value to [lo, hi]; NaN (any exponent-all-ones pattern with a non-zero\n\
         // mantissa) maps to lo.\nfn {m}_input(v: f32, lo: f32, hi: f32) -> f32 {{\n    \
         let nan = (bitcast<u32>(v) & 0x7fffffffu) > 0x7f800000u;\n    \
         return select(clamp(v, lo, hi), lo, nan);\n}}\n\n"
    ));
    for (k, fl) in f.fields.iter().enumerate() {
        s.push_str(&format!("const {upper}_NUM{k}: array<f32, {n}> = array<f32, {n}>({});\n", list(fl.num.iter().map(|v| wlit(*v))), n = fl.num.len()));
        if !fl.den.is_empty() {
            s.push_str(&format!("const {upper}_DEN{k}: array<f32, {n}> = array<f32, {n}>({});\n", list(fl.den.iter().map(|v| wlit(*v))), n = fl.den.len()));
        }
    }
    let params: Vec<String> = f.args.iter().map(|a| format!("{a}: f32")).collect();
    let body = field_lines(f, "", &wlit);
    s.push_str(&format!(
        "\n// The {nk} coefficients at ({args}); evaluate once per material and pass them to {ev}.\n\
         fn {name}({params}) -> array<f32, {nk}> {{\n{inputs}    return array<f32, {nk}>(\n{body}    );\n}}\n",
        args = f.args.join(", "),
        ev = f.evaluator,
        name = f.name,
        params = params.join(", "),
        inputs = inputs(f, &format!("{m}_input"), &wlit, &|fun, v| format!("{fun}({v})")),
        body = body,
    ));
    let eparams: Vec<String> = f.eval_args.iter().map(|a| format!("{a}: f32")).collect();
    let eins = evaluator_inputs(f, &format!("{m}_input"), &wlit);
    let sum = basis_sum(f.terms, &|k| format!("c[{k}]"), &|i| format!("a{i}"));
    s.push_str(&format!(
        "\n// Σ c_k b_k({eargs}), clamped to [{lo}, {hi}].\nfn {ev}(c: array<f32, {nk}>, {eparams}) -> f32 {{\n{eins}    \
         return {m}_input({sum}, {lo}, {hi});\n}}\n",
        eargs = f.eval_args.join(", "),
        ev = f.evaluator,
        eparams = eparams.join(", "),
        lo = wlit(f.range.0),
        hi = wlit(f.range.1),
    ));
    s
}

/// Rust module: f32 constants and functions mirroring the WGSL, plus `{name}_f64` with the
/// full-precision coefficients `c64[k] = (numerator, denominator)`.
pub fn render_rust(header: &[String], f: &FieldsFunction<'_>, doc: &str, c64: &[(Vec<f64>, Vec<f64>)]) -> String {
    let upper = f.module.to_uppercase();
    let nk = f.fields.len();
    let mut s = String::new();
    for h in header {
        s.push_str(&format!("//! {h}\n"));
    }
    s.push_str(&format!("//!\n//! {doc}\n\n"));
    s.push_str(&format!(
        "/// Domain of each argument of [`{name}`]; inputs are clamped to it (NaN maps to the lower end).\n\
         pub const {upper}_DOMAIN: [[f32; 2]; {}] = [{}];\n\n",
        f.domain.len(),
        f.domain.iter().map(|(a, b)| format!("[{}, {}]", rlit(*a), rlit(*b))).collect::<Vec<_>>().join(", "),
        name = f.name,
    ));
    s.push_str("#[inline]\nfn input(v: f32, lo: f32, hi: f32) -> f32 {\n    if v.is_nan() { lo } else { v.clamp(lo, hi) }\n}\n\n");
    for (k, fl) in f.fields.iter().enumerate() {
        s.push_str(&format!("/// Field {k}: numerator coefficients.\npub const {upper}_NUM{k}: [f32; {}] = [{}];\n", fl.num.len(), list(fl.num.iter().map(|v| rlit(*v)))));
        if !fl.den.is_empty() {
            s.push_str(&format!(
                "/// Field {k}: denominator coefficients (the lead term has none).\npub const {upper}_DEN{k}: [f32; {}] = [{}];\n",
                fl.den.len(),
                list(fl.den.iter().map(|v| rlit(*v)))
            ));
        }
    }
    let params: Vec<String> = f.args.iter().map(|a| format!("{a}: f32")).collect();
    let body = field_lines(f, "", &rlit);
    s.push_str(&format!(
        "\n/// CPU version of the WGSL function of the same name: the {nk} coefficients at ({args}).\n\
         pub fn {name}({params}) -> [f32; {nk}] {{\n{inputs}    [\n{body}    ]\n}}\n",
        args = f.args.join(", "),
        name = f.name,
        params = params.join(", "),
        inputs = inputs(f, "input", &rlit, &|fun, v| format!("{v}.{fun}()")),
        body = body,
    ));
    // The f64 version: same expressions, full-precision coefficients, no f32 rounding.
    for (k, (num, den)) in c64.iter().enumerate() {
        s.push_str(&format!("/// Field {k}, f64 numerator.\npub const {upper}_NUM{k}_F64: [f64; {}] = [{}];\n", num.len(), list(num.iter().map(|v| rlit64(*v)))));
        if !den.is_empty() {
            s.push_str(&format!("/// Field {k}, f64 denominator.\npub const {upper}_DEN{k}_F64: [f64; {}] = [{}];\n", den.len(), list(den.iter().map(|v| rlit64(*v)))));
        }
    }
    let params64: Vec<String> = f.args.iter().map(|a| format!("{a}: f64")).collect();
    let inputs64: String = f
        .args
        .iter()
        .zip(f.domain)
        .enumerate()
        .map(|(i, (a, (lo, hi)))| format!("    let x{i} = if {a}.is_nan() {{ {lo:e}_f64 }} else {{ {a}.clamp({lo:e}_f64, {hi:e}_f64) }};\n", lo = *lo as f64, hi = *hi as f64))
        .chain(f.derived.iter().enumerate().map(|(k, d)| {
            format!(
                "    let x{} = {};\n",
                f.args.len() + k,
                super::wgsl::derived_expr(d, &|v| rlit64(v as f64), &|fun, v| format!("{v}.{fun}()"))
            )
        }))
        .collect();
    let body64 = field_lines(f, "_F64", &|v| rlit64(v as f64));
    s.push_str(&format!(
        "\n/// The coefficients in f64 from the unrounded fit, for evaluation at build time (e.g. to\n\
         /// bake them into a material's uniforms); rounds to f32 at most once, at the caller.\n\
         pub fn {name}_f64({params}) -> [f64; {nk}] {{\n{inputs64}    [\n{body}    ]\n}}\n",
        name = f.name,
        params = params64.join(", "),
        body = body64,
    ));
    let eparams: Vec<String> = f.eval_args.iter().map(|a| format!("{a}: f32")).collect();
    let eins = evaluator_inputs(f, "input", &rlit);
    let sum = basis_sum(f.terms, &|k| format!("c[{k}]"), &|i| format!("a{i}"));
    s.push_str(&format!(
        "\n/// CPU version of the WGSL function of the same name: Σ c_k b_k({eargs}), clamped to [{lo}, {hi}].\n\
         pub fn {ev}(c: &[f32; {nk}], {eparams}) -> f32 {{\n{eins}    input({sum}, {lo}, {hi})\n}}\n",
        eargs = f.eval_args.join(", "),
        ev = f.evaluator,
        eparams = eparams.join(", "),
        lo = rlit(f.range.0),
        hi = rlit(f.range.1),
    ));
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Coefficient lists as the emitted arrays hold them: six literals a line (a long array
    /// stays readable and its diffs local), every one in order.
    #[test]
    fn lists_hold_six_literals_a_line() {
        let text = list((0..14).map(|i| format!("{i}.5")));
        let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
        assert_eq!(lines.iter().map(|l| l.matches(',').count()).collect::<Vec<_>>(), [6, 6, 2], "{text}");
        let read: Vec<String> = lines.iter().flat_map(|l| l.split(',').map(str::trim).filter(|v| !v.is_empty())).map(String::from).collect();
        assert_eq!(read, (0..14).map(|i| format!("{i}.5")).collect::<Vec<_>>());
    }

    /// The evaluator's sum Σ c_k b_k with b = (1, u, u²·v) at (u, v) = (0.5, 4) and c = (1, 2, 3):
    /// 1 + 2·0.5 + 3·(0.25·4) = 5, exact in f32; in f32 and as the emitted WGSL text (its
    /// coefficients and arguments written as literals, folded by naga), every factor of a
    /// monomial multiplied in (3·0.5 alone would give 3.5).
    #[test]
    fn basis_sum_multiplies_each_monomials_arguments() {
        let args = vec!["u".to_string(), "v".to_string()];
        let terms: Vec<Term> = ["1", "u", "u^2*v"].iter().map(|s| Term::parse(s, &args).unwrap()).collect();
        assert_eq!(basis_sum_f32(&terms, &[1.0, 2.0, 3.0], &[0.5, 4.0]), 5.0);
        assert_eq!(basis_sum_f32(&terms[1..], &[2.0, 3.0], &[0.5, 4.0]), 4.0);
        let (c, a) = ([1.0, 2.0, 3.0], [0.5, 4.0]);
        let text = basis_sum(&terms, &|k| wlit(c[k]), &|i| wlit(a[i]));
        assert_eq!(crate::emit::fixtures::naga_folded_f32("", &text), 5.0, "{text}");
    }

    /// Two fields (n₀ + n₁o)/(1 + d₀o) of the outer input o ∈ [0, 1] and the evaluator
    /// c₀ + c₁u, u ∈ [−1, 1], clamped to [−4, 4].
    struct Quad {
        fields: [Field; 2],
        args: Vec<String>,
        eval_args: Vec<String>,
        terms: Vec<Term>,
    }

    impl Quad {
        fn new([(n0, d0), (n1, d1)]: [(Vec<f32>, Vec<f32>); 2]) -> Quad {
            let e = crate::fit::expr::model_expr(&crate::fit::model::RationalModel::rational_1d("o", 1, 1));
            let fields = [Field { expr: e.clone(), num: n0, den: d0 }, Field { expr: e, num: n1, den: d1 }];
            let eval_args = vec!["u".to_string()];
            let terms = ["1", "u"].iter().map(|s| Term::parse(s, &eval_args).unwrap()).collect();
            Quad { fields, args: vec!["o".to_string()], eval_args, terms }
        }

        fn function(&self) -> FieldsFunction<'_> {
            FieldsFunction {
                module: "quad",
                name: "quad_coeffs",
                args: &self.args,
                derived: &[],
                domain: &[(0.0, 1.0)],
                fields: &self.fields,
                evaluator: "quad",
                eval_args: &self.eval_args,
                eval_domain: &[(-1.0, 1.0)],
                terms: &self.terms,
                range: (-4.0, 4.0),
            }
        }
    }

    /// The Rust module declares the domain, each field's f32 arrays and the f64 coefficients,
    /// every literal reading back to the value it was given; the WGSL module of the same
    /// fields validates in naga and returns every field.
    #[test]
    fn the_rust_module_carries_every_coefficient() {
        let q = Quad::new([(vec![0.1, -2.5], vec![0.3]), (vec![1.0 / 3.0, 7.0], vec![-0.2])]);
        let f = q.function();
        let c64 = vec![(vec![0.1, -2.5], vec![0.3]), (vec![1.0 / 3.0, 7.0], vec![-0.2])];
        // The WGSL module validates in naga, and its coefficient function returns one composed
        // value per field (an empty body would be `array<f32, 2>()`, the zero value).
        let wgsl = crate::emit::wgsl::strip_directives(&render_wgsl(&["header line".to_string()], &f));
        let m = naga::front::wgsl::parse_str(&wgsl).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&wgsl)));
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all()).validate(&m).unwrap();
        let (_, coeffs) = m.functions.iter().find(|(_, g)| g.name.as_deref() == Some("quad_coeffs")).unwrap();
        let returned = coeffs.body.iter().find_map(|st| match st {
            naga::Statement::Return { value: Some(v) } => Some(*v),
            _ => None,
        });
        let naga::Expression::Compose { components, .. } = &coeffs.expressions[returned.unwrap()] else { panic!("{wgsl}") };
        assert_eq!(components.len(), 2, "{wgsl}");
        let text = render_rust(&["header line".to_string()], &f, "the doc", &c64);
        assert!(text.starts_with("//! header line\n"), "{text}");
        // The literals of one `pub const NAME: [...] = [...];`, read back.
        let array = |name: &str| -> Vec<f64> {
            let start = text.find(&format!("pub const {name}:")).unwrap_or_else(|| panic!("no {name} in {text}"));
            let body = &text[start..];
            let body = &body[body.find("= [").unwrap() + 3..];
            let body = &body[..body.find("];").unwrap()];
            body.replace(['[', ']'], "")
                .split(',')
                .map(str::trim)
                .filter(|v| !v.is_empty())
                .map(|v| match v.strip_suffix("_f32") {
                    Some(l) => l.parse::<f32>().unwrap() as f64,
                    None => v.trim_end_matches("_f64").parse().unwrap(),
                })
                .collect()
        };
        let f32s = |v: &[f64]| v.iter().map(|&x| x as f32 as f64).collect::<Vec<_>>();
        assert_eq!(array("QUAD_DOMAIN"), vec![0.0, 1.0]);
        assert_eq!(array("QUAD_NUM0"), f32s(&[0.1, -2.5]));
        assert_eq!(array("QUAD_DEN0"), f32s(&[0.3]));
        assert_eq!(array("QUAD_NUM1"), f32s(&[1.0 / 3.0, 7.0]));
        assert_eq!(array("QUAD_DEN1"), f32s(&[-0.2]));
        assert_eq!(array("QUAD_NUM0_F64"), vec![0.1, -2.5]);
        assert_eq!(array("QUAD_DEN0_F64"), vec![0.3]);
        assert_eq!(array("QUAD_NUM1_F64"), vec![1.0 / 3.0, 7.0]);
        assert_eq!(array("QUAD_DEN1_F64"), vec![-0.2]);
        assert!(text.contains("pub fn quad_coeffs(") && text.contains("pub fn quad("), "{text}");
    }

    /// The coefficient function evaluates each field's rational (n₀ + n₁o)/(1 + d₀o) at the
    /// outer input, in field order, and the evaluator sums c₀ + c₁u and clamps it to the range;
    /// at o = 0.5 the fields below are 2/2 = 1 and 2/0.5 = 4, exact in f32 (by hand).
    #[test]
    fn coefficients_and_evaluator_compute_the_fields_rationals() {
        let q = Quad::new([(vec![1.0, 2.0], vec![2.0]), (vec![3.0, -2.0], vec![-1.0])]);
        let f = q.function();
        let c = coefficients_f32(&f, &[0.5]);
        assert_eq!(c, [1.0, 4.0]);
        assert_eq!(evaluator_f32(&f, &c, &[0.5]), 3.0); // 1 + 4·0.5
        assert_eq!(evaluator_f32(&f, &c, &[1.0]), 4.0); // 5, clamped to the range's top
        assert_eq!(evaluator_f32(&f, &c, &[-3.0]), -3.0); // u clamped to −1: 1 − 4
    }

    /// A monomial's factors are its arguments repeated by their exponents, in argument order.
    #[test]
    fn monomial_factors_repeat_each_argument_by_its_exponent() {
        let args = vec!["u".to_string(), "v".to_string()];
        let t = |s: &str| Term::parse(s, &args).unwrap();
        assert_eq!(monomial_factors(&t("1")), None);
        assert_eq!(monomial_factors(&t("v")), Some(vec![1]));
        assert_eq!(monomial_factors(&t("u^2*v^3")), Some(vec![0, 0, 1, 1, 1]));
    }

    /// f64 literals read back to the same bits (Rust parses `1e-3_f64` like `1e-3`).
    #[test]
    fn f64_literals_round_trip() {
        for v in [0.1, -2.5e-300, 1.0 / 3.0, 6.02214076e23, f64::MIN_POSITIVE, 0.0] {
            let l = rlit64(v);
            let back: f64 = l.strip_suffix("_f64").unwrap_or_else(|| panic!("{l}")).parse().unwrap();
            assert_eq!(back.to_bits(), v.to_bits(), "{l}");
        }
    }
}
