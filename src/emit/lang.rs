//! The two languages a hand-written module is emitted in (WGSL and its CPU Rust twin): literals,
//! comments, signatures, the file's opening with the input clamp, and a form's body over its
//! clamped arguments.

use super::f32_literal;
use crate::fit::expr::Syntax;
use crate::fit::expr::program::Program;

/// The two languages a module is written in (shared with the family's other emitted modules).
#[derive(Clone, Copy, PartialEq)]
pub enum Lang {
    Wgsl,
    Rust,
}

impl Lang {
    pub fn lit(self, v: f64) -> String {
        let s = f32_literal(v as f32);
        match self {
            Lang::Wgsl => format!("{s}f"),
            Lang::Rust => format!("{s}_f32"),
        }
    }

    pub fn comment(self) -> &'static str {
        match self {
            Lang::Wgsl => "//",
            Lang::Rust => "///",
        }
    }

    /// `fn NAME(args) -> RET {` in the language: RET is f32 for `width` 1, else a vector of
    /// `width` lanes (`vecN<f32>`, `[f32; N]`).
    pub fn signature(self, name: &str, args: &[&str], width: usize) -> String {
        let a: Vec<String> = args.iter().map(|a| format!("{a}: f32")).collect();
        match self {
            Lang::Wgsl => format!("fn {name}({}) -> {} {{\n", a.join(", "), if width == 1 { "f32".to_string() } else { format!("vec{width}<f32>") }),
            Lang::Rust => format!("pub fn {name}({}) -> {} {{\n", a.join(", "), if width == 1 { "f32".to_string() } else { format!("[f32; {width}]") }),
        }
    }

    /// The file's opening: header, module doc (`doc` lines), the import path (WGSL) and the
    /// input clamp `MODULE_input` / `input` (NaN → the lower end).
    pub fn preamble(self, header: &[String], module: &str, doc: &[&str]) -> String {
        let mut s = String::new();
        match self {
            Lang::Wgsl => {
                for line in header {
                    s += &format!("// {line}\n");
                }
                s += &format!("#define_import_path shadefit::{module}\n\n");
                for line in doc {
                    s += &format!("// {line}\n");
                }
                s += &format!(
                    "\n// Clamp an input to [lo, hi]; NaN (any exponent-all-ones pattern with a non-zero\n\
                     // mantissa) maps to lo.\nfn {module}_input(v: f32, lo: f32, hi: f32) -> f32 {{\n    \
                     let nan = (bitcast<u32>(v) & 0x7fffffffu) > 0x7f800000u;\n    \
                     return select(clamp(v, lo, hi), lo, nan);\n}}\n"
                );
            }
            Lang::Rust => {
                for line in header {
                    s += &format!("//! {line}\n");
                }
                s += "//!\n";
                for line in doc {
                    s += &format!("//! {line}\n");
                }
                s += "//! CPU versions of the WGSL functions of the same names.\n\n";
                s += "#[inline]\nfn input(v: f32, lo: f32, hi: f32) -> f32 {\n    if v.is_nan() { lo } else { v.clamp(lo, hi) }\n}\n";
            }
        }
        s
    }

    pub fn clamp(self, module: &str, v: &str, lo: f64, hi: f64) -> String {
        match self {
            Lang::Wgsl => format!("{}({v}, {}, {})", crate::spec::names::input_helper(module), self.lit(lo), self.lit(hi)),
            Lang::Rust => format!("input({v}, {}, {})", self.lit(lo), self.lit(hi)),
        }
    }
}

impl Lang {
    pub fn syntax(self) -> Syntax {
        match self {
            Lang::Wgsl => Syntax::Wgsl,
            Lang::Rust => Syntax::Rust,
        }
    }
}

/// A form's body with its constants: the inputs clamped to `domain` (WGSL: the clamp call at
/// each use, Rust: the arguments rebound once, since Rust spells a vector lane by lane).
pub fn form_body(lang: Lang, module: &str, form: &Program, consts: &[f64], args: &[&str], domain: &[(f64, f64)]) -> String {
    let c32: Vec<f32> = consts.iter().map(|&v| v as f32).collect();
    let lit = |v: f32| lang.lit(v as f64);
    let input = |i: usize| match lang {
        Lang::Wgsl => lang.clamp(module, args[i], domain[i].0, domain[i].1),
        Lang::Rust => args[i].to_string(),
    };
    let rebound: String = match lang {
        Lang::Wgsl => String::new(),
        Lang::Rust => args.iter().zip(domain).map(|(a, d)| format!("    let {a} = {};\n", lang.clamp(module, a, d.0, d.1))).collect(),
    };
    rebound + &form.render(lang.syntax(), &input, &c32, &lit) + "}\n"
}

