//! A compute shader that calls every function of the given WGSL libraries once, in a chosen
//! import style (naga_oil's `#import shadefit::NAME` with `NAME::f(..)`, WESL's
//! `import shadefit::NAME;`, or the flat names), so that a composer or linker must resolve
//! every library and every function. Arguments are constants of each parameter's type read
//! from naga's IR of the library; textures and samplers are globals of group 0.

#![allow(dead_code)] // each test uses the styles it needs

use std::fmt::Write as _;

/// How a shader imports library `NAME` and qualifies its names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    /// `#import shadefit::NAME`, calls `NAME::f(..)` (naga_oil, bevy).
    Prefixed,
    /// `#import shadefit::NAME`, calls `f(..)` (this crate's original style).
    Flat,
    /// `import shadefit::NAME;`, calls `NAME::f(..)` (WESL).
    Wesl,
}

/// The library's source without preprocessor lines, as naga parses it.
pub fn plain(src: &str) -> String {
    src.lines().filter(|l| !l.trim_start().starts_with('#')).collect::<Vec<_>>().join("\n")
}

/// A WGSL expression of type `ty` (None: a type with no such constant, e.g. a matrix).
/// Handles (textures, samplers) become globals, declared once in `globals`.
fn value(m: &naga::Module, ty: naga::Handle<naga::Type>, qual: &str, globals: &mut Vec<(String, String)>) -> Option<String> {
    use naga::{ImageClass, ImageDimension, ScalarKind, TypeInner};
    let scalar = |s: naga::Scalar| match (s.kind, s.width) {
        (ScalarKind::Float, 4) => Some(("f32", "0.5f")),
        (ScalarKind::Uint, 4) => Some(("u32", "1u")),
        (ScalarKind::Sint, 4) => Some(("i32", "1i")),
        (ScalarKind::Bool, _) => Some(("bool", "false")),
        _ => None,
    };
    fn handle(globals: &mut Vec<(String, String)>, ty: &str) -> Option<String> {
        if let Some(g) = globals.iter().find(|g| g.1 == ty) {
            return Some(g.0.clone());
        }
        globals.push((format!("shadefit_test_handle_{}", globals.len()), ty.to_string()));
        Some(globals.last().unwrap().0.clone())
    }
    match &m.types[ty].inner {
        TypeInner::Scalar(s) => scalar(*s).map(|(_, v)| v.to_string()),
        TypeInner::Vector { size, scalar: s } => scalar(*s).map(|(t, v)| format!("vec{}<{t}>({v})", *size as u8)),
        TypeInner::Struct { members, .. } => {
            let name = m.types[ty].name.as_ref()?;
            let fields: Option<Vec<String>> = members.iter().map(|f| value(m, f.ty, qual, globals)).collect();
            Some(format!("{qual}{name}({})", fields?.join(", ")))
        }
        TypeInner::Image { dim, arrayed, class: ImageClass::Sampled { kind: ScalarKind::Float, multi: false } } => {
            let d = match dim {
                ImageDimension::D2 => "2d",
                ImageDimension::D3 => "3d",
                ImageDimension::Cube => "cube",
                ImageDimension::D1 => "1d",
            };
            handle(globals, &format!("texture_{d}{}<f32>", if *arrayed { "_array" } else { "" }))
        }
        TypeInner::Array { base, size: naga::ArraySize::Constant(n), .. } => {
            let v = value(m, *base, qual, globals)?;
            Some(format!("array({})", vec![v; n.get() as usize].join(", ")))
        }
        TypeInner::Sampler { comparison: false } => handle(globals, "sampler"),
        _ => None,
    }
}

/// The shader: one call per function of each `(name, source)` library, in `style`.
pub fn every_function(libraries: &[(&str, &str)], style: Style) -> String {
    let (mut imports, mut body, mut globals) = (String::new(), String::new(), Vec::new());
    let mut calls = 0;
    for (name, src) in libraries {
        let ir = naga::front::wgsl::parse_str(&plain(src)).unwrap_or_else(|e| panic!("{name}: {e}"));
        match style {
            Style::Prefixed | Style::Flat => writeln!(imports, "#import shadefit::{name}").unwrap(),
            Style::Wesl => writeln!(imports, "import shadefit::{name};").unwrap(),
        }
        let qual = if style == Style::Flat { String::new() } else { format!("{name}::") };
        for (_, f) in ir.functions.iter() {
            let args: Option<Vec<String>> = f.arguments.iter().map(|a| value(&ir, a.ty, &qual, &mut globals)).collect();
            let fname = f.name.as_deref().unwrap();
            let args = args.unwrap_or_else(|| panic!("{name}::{fname}: an argument type the test cannot build"));
            if f.result.is_some() {
                writeln!(body, "    _ = {qual}{fname}({});", args.join(", ")).unwrap();
            } else {
                writeln!(body, "    {qual}{fname}({});", args.join(", ")).unwrap();
            }
            calls += 1;
        }
    }
    assert!(calls >= libraries.len(), "{calls} calls for {} libraries", libraries.len());
    let mut s = imports;
    for (i, (g, ty)) in globals.iter().enumerate() {
        writeln!(s, "@group(0) @binding({i}) var {g}: {ty};").unwrap();
    }
    write!(s, "\n@compute @workgroup_size(1)\nfn main() {{\n{body}}}\n").unwrap();
    s
}

/// naga's validation of a WGSL source (all flags, default capabilities).
pub fn validate(what: &str, src: &str) -> naga::Module {
    let m = naga::front::wgsl::parse_str(src).unwrap_or_else(|e| panic!("{what}: {}", e.emit_to_string(src)));
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default())
        .validate(&m)
        .unwrap_or_else(|e| panic!("{what}: {}", e.emit_to_string(src)));
    m
}
