//! Emit targets beyond the WGSL module: plain WGSL, HLSL, GLSL (450 core and ES 300), MSL,
//! SPIR-V and a C/C++ header of the constants, all from the emitted WGSL module.
//!
//! The WGSL module (`wgsl/NAME.wgsl`, with its `#define_import_path`) is the source of every
//! target. Without its directive line it is plain WGSL (`wgsl-plain/NAME.wgsl`), and the same
//! text is the module `shadefit::NAME` of a WESL package (`wesl/NAME.wesl`, with the package's
//! `wesl/wesl.toml`, [`package_files`]). For the
//! shading languages, naga parses the plain WGSL with an entry point appended,
//! [`keep_entry_point_name`] (`NAME_keep_all`): a fragment stage (the one stage every language has, GLSL ES 3.00
//! included) that calls every function of the module once with zero arguments (textures and
//! samplers from globals of group 0), so that no backend drops a function as unreachable. naga
//! validates that module, then its backends write HLSL (shader model 5.1), GLSL 450 core,
//! GLSL ES 300, MSL 1.0 and SPIR-V 1.0. The C header holds the module's named constants (its
//! coefficients and tables) as `static const` arrays, read from naga's IR of the plain WGSL.
//!
//! Every file carries the module's header (generator, spec, input hash, measured error) in its
//! language's comments and one line naming what it was translated from; the SPIR-V module
//! carries its WGSL source, header included, in `OpSource` (naga's debug information).
//! Translation is a pure function of the WGSL text, so outputs are byte-identical whatever the
//! thread count.

use super::{f32_literal, include, Artifact};
use std::collections::BTreeSet;
use naga::{ArraySize, ImageClass, ImageDimension, Literal, Scalar, ScalarKind, TypeInner};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The entry point the shading-language targets of module `module` gain: it calls every
/// function of the module and computes nothing of use (in GLSL it is `main`). Named after the
/// module, as its globals are (`NAME_keep_binding_K`), so two modules' files do not clash.
pub fn keep_entry_point_name(module: &str) -> String {
    format!("{module}_keep_all")
}

/// The translator, as the headers name it (the major version is pinned in Cargo.toml).
pub const TRANSLATOR: &str = "naga 30";

/// One kind of output file per emitted WGSL module.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Target {
    /// The WGSL module with `#define_import_path shadefit::NAME` (always written).
    Wgsl,
    /// The same WGSL without the directive: naga and tint take it as is.
    WgslPlain,
    /// HLSL, shader model 5.1.
    Hlsl,
    /// GLSL 450 core.
    Glsl,
    /// GLSL ES 3.00.
    GlslEs,
    /// Metal Shading Language 1.0.
    Msl,
    /// SPIR-V 1.0 (binary).
    Spirv,
    /// C/C++ header of the named constants.
    C,
    /// The plain WGSL as a module of the WESL package `shadefit` (plus `wesl/wesl.toml`).
    Wesl,
}

impl Target {
    pub const ALL: [Target; 9] =
        [Target::Wgsl, Target::WgslPlain, Target::Hlsl, Target::Glsl, Target::GlslEs, Target::Msl, Target::Spirv, Target::C, Target::Wesl];

    /// The name `--target` and `[emit] targets` take; also the folder under generated/.
    pub fn name(self) -> &'static str {
        match self {
            Target::Wgsl => "wgsl",
            Target::WgslPlain => "wgsl-plain",
            Target::Hlsl => "hlsl",
            Target::Glsl => "glsl",
            Target::GlslEs => "glsl-es",
            Target::Msl => "msl",
            Target::Spirv => "spirv",
            Target::C => "c",
            Target::Wesl => "wesl",
        }
    }

    pub fn from_name(s: &str) -> Option<Target> {
        Target::ALL.into_iter().find(|t| t.name() == s)
    }

    fn extension(self) -> &'static str {
        match self {
            Target::Wgsl | Target::WgslPlain => "wgsl",
            Target::Hlsl => "hlsl",
            Target::Glsl | Target::GlslEs => "glsl",
            Target::Msl => "metal",
            Target::Spirv => "spv",
            Target::C => "h",
            Target::Wesl => "wesl",
        }
    }

    /// The file of module `module` under generated/.
    pub fn path(self, module: &str) -> PathBuf {
        Path::new(self.name()).join(format!("{module}.{}", self.extension()))
    }
}

/// Parse a list of target names (`--target wgsl,hlsl`): sorted, without repeats.
pub fn parse_list<S: AsRef<str>>(names: &[S]) -> Result<Vec<Target>, String> {
    let mut out = Vec::new();
    for n in names {
        let n = n.as_ref().trim();
        let t = Target::from_name(n).ok_or_else(|| {
            let known: Vec<&str> = Target::ALL.iter().map(|t| t.name()).collect();
            format!("unknown target '{n}' (known: {})", known.join(", "))
        })?;
        out.push(t);
    }
    out.sort();
    out.dedup();
    Ok(out)
}

#[derive(Debug, thiserror::Error)]
pub enum TargetError {
    #[error("{module}: {what} (targets other than wgsl need a self-contained module)")]
    Unsupported { module: String, what: String },
    #[error("{module}: naga rejects the emitted WGSL module (nothing is written): {message}")]
    Rejected { module: String, message: String },
    #[error("{module}: naga rejects the module with its entry point appended: {message}")]
    Invalid { module: String, message: String },
    #[error("{module}: naga's {target} backend: {message}")]
    Backend { module: String, target: &'static str, message: String },
}

/// The module's name and header lines (without `// `) and its code after the directive.
struct Source<'a> {
    header: Vec<&'a str>,
    code: &'a str,
}

fn split_module<'a>(module: &str, text: &'a str) -> Result<Source<'a>, TargetError> {
    let unsupported = |what: String| TargetError::Unsupported { module: module.to_string(), what };
    let mut header = Vec::new();
    let mut rest = text;
    loop {
        let (line, after) = rest.split_once('\n').unwrap_or((rest, ""));
        if let Some(h) = line.strip_prefix("// ") {
            header.push(h);
            rest = after;
        } else if line.starts_with("#define_import_path") {
            rest = after;
            break;
        } else {
            return Err(unsupported("no `#define_import_path` line after the header".into()));
        }
    }
    if let Some(l) = rest.lines().find(|l| l.trim_start().starts_with('#')) {
        return Err(unsupported(format!("it has a directive line `{}`", l.trim())));
    }
    Ok(Source { header, code: rest })
}

fn comment_header(header: &[&str], note: &str) -> String {
    let mut s = String::new();
    for h in header.iter().copied().chain(std::iter::once(note)) {
        s.push_str("// ");
        s.push_str(h);
        s.push('\n');
    }
    s
}

/// The WGSL source of a type, for the types emitted functions take and return.
fn wgsl_type(m: &naga::Module, ty: naga::Handle<naga::Type>) -> Option<String> {
    fn scalar(s: Scalar) -> Option<&'static str> {
        Some(match (s.kind, s.width) {
            (ScalarKind::Float, 4) => "f32",
            (ScalarKind::Uint, 4) => "u32",
            (ScalarKind::Sint, 4) => "i32",
            (ScalarKind::Bool, _) => "bool",
            _ => return None,
        })
    }
    Some(match &m.types[ty].inner {
        TypeInner::Scalar(s) => scalar(*s)?.to_string(),
        TypeInner::Vector { size, scalar: s } => format!("vec{}<{}>", *size as u8, scalar(*s)?),
        TypeInner::Matrix { columns, rows, scalar: s } => format!("mat{}x{}<{}>", *columns as u8, *rows as u8, scalar(*s)?),
        TypeInner::Array { base, size: ArraySize::Constant(n), .. } => format!("array<{}, {n}>", wgsl_type(m, *base)?),
        TypeInner::Image { dim, arrayed, class: ImageClass::Sampled { kind: ScalarKind::Float, multi: false } } => {
            let d = match dim {
                ImageDimension::D1 => "1d",
                ImageDimension::D2 => "2d",
                ImageDimension::D3 => "3d",
                ImageDimension::Cube => "cube",
            };
            format!("texture_{d}{}<f32>", if *arrayed { "_array" } else { "" })
        }
        TypeInner::Sampler { comparison } => (if *comparison { "sampler_comparison" } else { "sampler" }).to_string(),
        // A named struct of the module (its zero value `Name()` is a valid argument).
        TypeInner::Struct { .. } => m.types[ty].name.clone()?,
        _ => return None,
    })
}

/// The entry point [`keep_entry_point_name`] calling every function of `m`, with the globals it
/// binds for texture and sampler arguments.
fn keep_entry_point(module: &str, m: &naga::Module) -> Result<String, TargetError> {
    let mut globals: Vec<String> = Vec::new();
    let mut calls = String::new();
    for (_, f) in m.functions.iter() {
        let name = f.name.as_deref().unwrap_or_default();
        let mut args = Vec::new();
        for a in &f.arguments {
            let ty = wgsl_type(m, a.ty).ok_or_else(|| TargetError::Unsupported {
                module: module.to_string(),
                what: format!("function {name} takes an argument of a type the entry point cannot make"),
            })?;
            if matches!(m.types[a.ty].inner, TypeInner::Image { .. } | TypeInner::Sampler { .. }) {
                let k = match globals.iter().position(|g| *g == ty) {
                    Some(k) => k,
                    None => {
                        globals.push(ty);
                        globals.len() - 1
                    }
                };
                args.push(format!("{module}_keep_binding_{k}"));
            } else {
                // Zero: a literal for a scalar (naga writes `T()` of a scalar as a helper call
                // in HLSL), the zero-value constructor otherwise.
                let zero = match ty.as_str() {
                    "f32" => "0f".to_string(),
                    "u32" => "0u".to_string(),
                    "i32" => "0i".to_string(),
                    "bool" => "false".to_string(),
                    _ => format!("{ty}()"),
                };
                args.push(zero);
            }
        }
        let call = format!("{name}({})", args.join(", "));
        if f.result.is_some() {
            writeln!(calls, "    _ = {call};").unwrap();
        } else {
            writeln!(calls, "    {call};").unwrap();
        }
    }
    let mut s = String::from(
        "\n// Calls every function above once, so that no translation drops one as unreachable;\n\
         // it computes nothing of use.\n",
    );
    for (k, ty) in globals.iter().enumerate() {
        writeln!(s, "@group(0) @binding({k}) var {module}_keep_binding_{k}: {ty};").unwrap();
    }
    write!(s, "@fragment\nfn {}() {{\n{calls}}}\n", keep_entry_point_name(module)).unwrap();
    Ok(s)
}

fn parse(module: &str, text: &str) -> Result<(naga::Module, naga::valid::ModuleInfo), TargetError> {
    let invalid = |message: String| TargetError::Invalid { module: module.to_string(), message };
    let m = naga::front::wgsl::parse_str(text).map_err(|e| invalid(e.emit_to_string(text)))?;
    let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default())
        .validate(&m)
        .map_err(|e| invalid(e.emit_to_string(text)))?;
    Ok((m, info))
}

/// Checks the WGSL module `module` (the text of `wgsl/NAME.wgsl`) as naga parses and validates
/// it, so that no build writes a module the runtime crate or an engine would refuse.
pub fn check(module: &str, wgsl: &str) -> Result<(), TargetError> {
    let src = split_module(module, wgsl)?;
    let rejected = |message: String| TargetError::Rejected { module: module.to_string(), message };
    let m = naga::front::wgsl::parse_str(src.code).map_err(|e| rejected(e.emit_to_string(src.code)))?;
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default())
        .validate(&m)
        .map_err(|e| rejected(e.emit_to_string(src.code)))?;
    Ok(())
}

/// The files of `targets` for the WGSL module `module` (the text of `wgsl/NAME.wgsl`); the
/// module file itself ([`Target::Wgsl`]) is not among them.
pub fn translate(module: &str, wgsl: &str, targets: &[Target]) -> Result<Vec<Artifact>, TargetError> {
    let targets: Vec<Target> = targets.iter().copied().filter(|t| *t != Target::Wgsl).collect();
    if targets.is_empty() {
        return Ok(Vec::new());
    }
    let src = split_module(module, wgsl)?;
    let from = format!("wgsl/{module}.wgsl");
    let plain = format!(
        "{}{}",
        comment_header(&src.header, &format!("plain WGSL: {from} (the library shadefit::{module}) without its #define_import_path line")),
        src.code
    );
    let (plain_ir, _) = parse(module, &plain)?;
    let keep = format!("{plain}{}", keep_entry_point(module, &plain_ir)?);
    let (ir, info) = parse(module, &keep)?;
    let backend = |target: Target| {
        let module = module.to_string();
        move |e: &dyn std::fmt::Display| TargetError::Backend { module, target: target.name(), message: e.to_string() }
    };
    let note = |t: Target| match t {
        Target::Hlsl | Target::Glsl | Target::GlslEs | Target::Msl => format!(
            "{} translated from {from} by {TRANSLATOR}; include form{}: the module's functions and constants, naga's helpers named {module}_*; the harness {} (define {}) calls every function once",
            t.name(),
            glsl_version(t).map(|v| format!(" (include after {v})")).unwrap_or_default(),
            keep_entry_point_name(module),
            include::KEEP_ALL_MACRO
        ),
        _ => format!(
            "{} translated from {from} by {TRANSLATOR}; the entry point {} calls every function once so that none is dropped",
            t.name(),
            keep_entry_point_name(module)
        ),
    };
    let owned: BTreeSet<String> = plain_ir
        .functions
        .iter()
        .filter_map(|(_, f)| f.name.clone())
        .chain(plain_ir.constants.iter().filter_map(|(_, c)| c.name.clone()))
        .chain(plain_ir.types.iter().filter_map(|(_, t)| t.name.clone()))
        .collect();
    let included = |t: Target, lang: include::Lang, code: &str, entry: &str| -> Result<String, TargetError> {
        let inc = include::split(module, lang, code, &owned, entry).map_err(|message| backend(t)(&message))?;
        Ok(format!("{}{}", comment_header(&src.header, &note(t)), include::file_text(module, t.extension(), &inc)))
    };
    let mut out = Vec::new();
    for t in targets {
        let contents: Vec<u8> = match t {
            Target::Wgsl => unreachable!("filtered above"),
            Target::WgslPlain => plain.clone().into_bytes(),
            Target::Hlsl => {
                let options = naga::back::hlsl::Options::default();
                let pipeline = naga::back::hlsl::PipelineOptions { entry_point: None };
                let mut code = String::new();
                naga::back::hlsl::Writer::new(&mut code, &options, &pipeline)
                    .write(&ir, &info, None)
                    .map_err(|e| backend(t)(&e))?;
                let code = hlsl_sampler_registers(&hlsl_brace_initializers(&code));
                included(t, include::Lang::Hlsl, &code, &keep_entry_point_name(module))?.into_bytes()
            }
            Target::Glsl | Target::GlslEs => {
                let version = match t {
                    Target::Glsl => naga::back::glsl::Version::Desktop(450),
                    _ => naga::back::glsl::Version::new_gles(300),
                };
                let options = naga::back::glsl::Options {
                    version,
                    writer_flags: naga::back::glsl::WriterFlags::empty(),
                    ..Default::default()
                };
                let pipeline = naga::back::glsl::PipelineOptions {
                    shader_stage: naga::ShaderStage::Fragment,
                    entry_point: keep_entry_point_name(module),
                    multiview: None,
                };
                let mut code = String::new();
                naga::back::glsl::Writer::new(&mut code, &ir, &info, &options, &pipeline, Default::default())
                    .and_then(|mut w| w.write().map(|_| ()))
                    .map_err(|e| backend(t)(&e))?;
                // The include form has no `#version` line: the including shader's comes first.
                included(t, include::Lang::Glsl, &code, "main")?.into_bytes()
            }
            Target::Msl => {
                let options = naga::back::msl::Options::default();
                let pipeline = naga::back::msl::PipelineOptions::default();
                let (code, _) = naga::back::msl::write_string(&ir, &info, &options, &pipeline).map_err(|e| backend(t)(&e))?;
                included(t, include::Lang::Msl, &code, &keep_entry_point_name(module))?.into_bytes()
            }
            Target::Spirv => {
                use naga::back::spv;
                // The source (header first) rides along in OpSource; names of constants and
                // functions in OpName. Flags are explicit: naga's default depends on the build
                // profile. The language operand says Unknown: WGSL (10) is recent enough that
                // spirv-val releases still in distributions (SPIRV-Tools 2023.1) reject it.
                let options = spv::Options {
                    lang_version: (1, 0),
                    flags: spv::WriterFlags::DEBUG | spv::WriterFlags::LABEL_VARYINGS,
                    debug_info: Some(spv::DebugInfo { source_code: &keep, file_name: &from, language: spv::SourceLanguage::Unknown }),
                    ..Default::default()
                };
                let pipeline = spv::PipelineOptions { shader_stage: naga::ShaderStage::Fragment, entry_point: keep_entry_point_name(module) };
                let words = spv::write_vec(&ir, &info, &options, Some(&pipeline)).map_err(|e| backend(t)(&e))?;
                words.iter().flat_map(|w| w.to_le_bytes()).collect()
            }
            Target::C => c_header(module, &src.header, &from, &plain_ir)?.into_bytes(),
            Target::Wesl => format!(
                "{}{}",
                comment_header(&src.header, &format!("WESL module shadefit::{module} (package: wesl.toml): {from} without its #define_import_path line")),
                src.code
            )
            .into_bytes(),
        };
        out.push(Artifact { path: t.path(module), contents });
    }
    Ok(out)
}

/// naga initialises a `static const` array or struct by calling a generated constructor
/// function (`static const float A[2] = Constructarray2_float_(1.0, 2.0);`). HLSL compilers
/// differ on whether such a call is a constant initialiser: DXC runs it as static
/// initialisation, Slang rejects it ("static const global initializer must be a compile-time
/// constant"). An initialiser list (`= { 1.0, 2.0 };`) is a constant expression for all of them,
/// so the calls in `static const` initialisers become nested braces. The literals are untouched,
/// so every constant keeps its bits; the constructor functions stay for the code that calls them.
fn hlsl_brace_initializers(code: &str) -> String {
    let mut out = String::with_capacity(code.len());
    for line in code.split_inclusive('\n') {
        let Some((lhs, rhs)) = line.strip_prefix("static const ").and_then(|_| line.split_once(" = ")) else {
            out.push_str(line);
            continue;
        };
        if !rhs.starts_with("Construct") {
            out.push_str(line);
            continue;
        }
        out.push_str(lhs);
        out.push_str(" = ");
        // One entry per open parenthesis: whether it opened a constructor call (now a brace).
        let mut open: Vec<bool> = Vec::new();
        let mut rest = rhs;
        while let Some(c) = rest.chars().next() {
            if rest.starts_with("Construct") {
                let name_len = rest.find(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).unwrap_or(rest.len());
                if rest[name_len..].starts_with('(') {
                    out.push('{');
                    open.push(true);
                    rest = &rest[name_len + 1..];
                    continue;
                }
            }
            match c {
                '(' => open.push(false),
                ')' => {
                    if open.pop() == Some(true) {
                        out.push('}');
                        rest = &rest[1..];
                        continue;
                    }
                }
                _ => {}
            }
            out.push(c);
            rest = &rest[c.len_utf8()..];
        }
    }
    out
}

/// The `#version` line a GLSL target's include form is written for.
pub fn glsl_version(t: Target) -> Option<&'static str> {
    match t {
        Target::Glsl => Some("#version 450 core"),
        Target::GlslEs => Some("#version 300 es"),
        _ => None,
    }
}

/// A standalone shader of one include-form file `text` of module `module` with its harness on,
/// as the compiler checks build it: HLSL and MSL define [`include::KEEP_ALL_MACRO`] first (the
/// entry point is `NAME_keep_all`); GLSL also puts its `#version` first and a `main` calling
/// `NAME_keep_all` last.
pub fn check_source(module: &str, t: Target, text: &str) -> String {
    let define = format!("#define {}\n", include::KEEP_ALL_MACRO);
    match glsl_version(t) {
        Some(v) => format!("{v}\n{define}{text}\nvoid main() {{\n    {}();\n}}\n", keep_entry_point_name(module)),
        None => format!("{define}{text}"),
    }
}

/// The files a set of targets needs once, beside the modules' files: for [`Target::Wesl`], the
/// package manifest `wesl/wesl.toml` (format: <https://wesl-lang.dev/spec/WeslToml>; the
/// modules sit in its root, so a project that lists the folder as dependency `shadefit`
/// imports `shadefit::NAME::item`).
pub fn package_files(targets: &[Target]) -> Vec<Artifact> {
    let mut out = Vec::new();
    if targets.contains(&Target::Wesl) {
        let toml = format!(
            "# @generated by shadefit {}: do not edit; regenerate with `shadefit build --target wesl`.\n\
             # The WESL package of the emitted modules (wesl/NAME.wesl = wgsl/NAME.wgsl without its\n\
             # #define_import_path line). A project lists it in its own wesl.toml,\n\
             #   [dependencies]\n\
             #   shadefit = {{ path = \"path/to/generated/wesl\" }}\n\
             # and imports `shadefit::NAME::item`. Format: https://wesl-lang.dev/spec/WeslToml\n\
             [package]\n\
             edition = \"2026_pre\"\n\
             root = \".\"\n\
             include = [\"*.wesl\"]\n",
            env!("CARGO_PKG_VERSION")
        );
        out.push(Artifact { path: Path::new(Target::Wesl.name()).join("wesl.toml"), contents: toml.into_bytes() });
    }
    out
}

/// naga's HLSL binds samplers the way wgpu's Direct3D 12 backend does: every sampler of the
/// module is read from a heap (`nagaSamplerHeap`) through an index buffer per bind group, as
/// `static const SamplerState X = nagaSamplerHeap[nagaGroupGSamplerIndexArray[B]];`. An engine
/// including the file binds samplers itself, and a `static const` resource read from a buffer
/// is not a constant initialiser for every compiler (Slang rejects it). Each such global becomes
/// an ordinary register binding, `SamplerState X : register(sB, spaceG);` (the WGSL
/// `@group(G) @binding(B)`), and the heap and index-buffer declarations go once nothing reads
/// them. Only the entry point's own globals are bound this way: the emitted functions take
/// their textures and samplers as arguments.
fn hlsl_sampler_registers(code: &str) -> String {
    fn heap_global(line: &str) -> Option<(&str, &str, &str, &str)> {
        let rest = line.trim_end().strip_prefix("static const ")?;
        let (ty, rest) = rest.split_once(' ')?;
        if ty != "SamplerState" && ty != "SamplerComparisonState" {
            return None;
        }
        let (name, rest) = rest.split_once(" = ")?;
        let heap = if ty == "SamplerState" { "nagaSamplerHeap[" } else { "nagaComparisonSamplerHeap[" };
        let rest = rest.strip_prefix(heap)?.strip_prefix("nagaGroup")?;
        let (group, rest) = rest.split_once("SamplerIndexArray[")?;
        let binding = rest.strip_suffix("]];")?;
        let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
        (digits(group) && digits(binding)).then_some((ty, name, group, binding))
    }
    let mut lines: Vec<String> = code
        .split_inclusive('\n')
        .map(|line| match heap_global(line) {
            Some((ty, name, group, binding)) => format!("{ty} {name} : register(s{binding}, space{group});\n"),
            None => line.to_string(),
        })
        .collect();
    // Drop the heap and index-buffer declarations nothing else mentions any more.
    let declares = |line: &str| -> Option<String> {
        let t = line.trim_start();
        let name = if t.starts_with("SamplerState nagaSamplerHeap[") {
            "nagaSamplerHeap"
        } else if t.starts_with("SamplerComparisonState nagaComparisonSamplerHeap[") {
            "nagaComparisonSamplerHeap"
        } else {
            let rest = t.strip_prefix("StructuredBuffer<uint> ")?;
            let name = rest.split_whitespace().next()?;
            (name.starts_with("nagaGroup") && name.ends_with("SamplerIndexArray")).then_some(name)?
        };
        Some(name.to_string())
    };
    let used_elsewhere = |name: &str, lines: &[String]| lines.iter().filter(|l| l.contains(name)).count() > 1;
    let mut k = 0;
    while k < lines.len() {
        match declares(&lines[k]) {
            Some(name) if !used_elsewhere(&name, &lines) => {
                lines.remove(k);
            }
            _ => k += 1,
        }
    }
    lines.concat()
}

/// A named constant flattened: its scalars in order, and its array shape (outermost first).
pub struct Flat {
    pub name: String,
    pub scalar: Scalar,
    pub dims: Vec<usize>,
    pub values: Vec<Literal>,
}

/// The named constants of a module, flattened (`None` for one of a type with no C form).
pub fn named_constants(m: &naga::Module) -> Vec<Option<Flat>> {
    fn shape(m: &naga::Module, ty: naga::Handle<naga::Type>, dims: &mut Vec<usize>) -> Option<Scalar> {
        match &m.types[ty].inner {
            TypeInner::Scalar(s) => Some(*s),
            TypeInner::Vector { size, scalar } => {
                dims.push(*size as usize);
                Some(*scalar)
            }
            TypeInner::Matrix { columns, rows, scalar } => {
                dims.extend([*columns as usize, *rows as usize]);
                Some(*scalar)
            }
            TypeInner::Array { base, size: ArraySize::Constant(n), .. } => {
                dims.push(n.get() as usize);
                shape(m, *base, dims)
            }
            _ => None,
        }
    }
    fn flatten(m: &naga::Module, e: naga::Handle<naga::Expression>, count: usize, out: &mut Vec<Literal>) -> Option<()> {
        match &m.global_expressions[e] {
            naga::Expression::Literal(l) => out.push(*l),
            naga::Expression::Compose { components, .. } => {
                let each = count / components.len().max(1);
                for c in components {
                    flatten(m, *c, each, out)?;
                }
            }
            naga::Expression::Splat { value, .. } => {
                for _ in 0..count {
                    flatten(m, *value, 1, out)?;
                }
            }
            naga::Expression::Constant(c) => flatten(m, m.constants[*c].init, count, out)?,
            _ => return None,
        }
        Some(())
    }
    m.constants
        .iter()
        .filter_map(|(_, c)| c.name.clone().map(|n| (n, c)))
        .map(|(name, c)| {
            let mut dims = Vec::new();
            let scalar = shape(m, c.ty, &mut dims)?;
            let count = dims.iter().product();
            let mut values = Vec::new();
            flatten(m, c.init, count, &mut values)?;
            (values.len() == count).then_some(Flat { name, scalar, dims, values })
        })
        .collect()
}

fn c_literal(l: Literal) -> Option<String> {
    Some(match l {
        Literal::F32(v) if v.is_finite() => format!("{}f", f32_literal(v)),
        Literal::U32(v) => format!("{v}u"),
        Literal::I32(v) => format!("{v}"),
        Literal::Bool(b) => (if b { "1" } else { "0" }).to_string(),
        _ => return None,
    })
}

/// The C/C++ header: every named constant as `static const` (arrays of vectors as 2-D arrays);
/// a 1-D array six values to a line, so a long table diffs line by line.
fn c_header(module: &str, header: &[&str], from: &str, m: &naga::Module) -> Result<String, TargetError> {
    let guard = format!("SHADEFIT_{}_H", module.to_uppercase());
    let mut s = comment_header(
        header,
        &format!("c: the named constants of {from} (coefficients and tables), read from {TRANSLATOR}'s IR; src/{module}.rs evaluates them on the CPU"),
    );
    write!(s, "#ifndef {guard}\n#define {guard}\n\n#include <stdint.h>\n").unwrap();
    for flat in named_constants(m) {
        let unsupported = || TargetError::Unsupported { module: module.to_string(), what: "a constant with no C form".into() };
        let f = flat.ok_or_else(unsupported)?;
        let ty = match f.scalar.kind {
            ScalarKind::Float if f.scalar.width == 4 => "float",
            ScalarKind::Uint => "uint32_t",
            ScalarKind::Sint => "int32_t",
            ScalarKind::Bool => "int",
            _ => return Err(unsupported()),
        };
        let lits: Vec<String> = f.values.iter().map(|l| c_literal(*l).ok_or_else(unsupported)).collect::<Result<_, _>>()?;
        let dims: String = f.dims.iter().map(|d| format!("[{d}]")).collect();
        write!(s, "\nstatic const {ty} {}{dims} = ", f.name).unwrap();
        match f.dims.len() {
            0 => s.push_str(&lits[0]),
            1 => {
                s.push('{');
                for (i, l) in lits.iter().enumerate() {
                    s.push_str(if i % 6 == 0 { "\n    " } else { " " });
                    s.push_str(l);
                    s.push(',');
                }
                s.push_str("\n}");
            }
            _ => {
                // Rows of the innermost dimension, braces elided above it (C allows it).
                let inner = *f.dims.last().expect("two or more dimensions");
                s.push('{');
                for row in lits.chunks(inner) {
                    write!(s, "\n    {{{}}},", row.join(", ")).unwrap();
                }
                s.push_str("\n}");
            }
        }
        s.push_str(";\n");
    }
    write!(s, "\n#endif /* {guard} */\n").unwrap();
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// GLSL says its version (4.50 core, ES 3.00); SPIR-V is version 1.0 and carries the
    /// functions' names (OpName) and the WGSL source (OpSource), which the validators and
    /// debuggers read.
    #[test]
    fn glsl_and_spirv_carry_their_versions_names_and_source() {
        let src = "// h\n#define_import_path shadefit::m\nfn emitted_f(x: f32) -> f32 { return x * 2.0; }\n";
        let out = translate("m", src, &[Target::Glsl, Target::GlslEs, Target::Spirv]).unwrap();
        let texts: Vec<String> = out.iter().map(|a| String::from_utf8_lossy(&a.contents).into_owned()).collect();
        // The include forms name their version; the standalone check puts it first.
        assert!(texts[0].contains("include after #version 450 core") && texts[1].contains("include after #version 300 es"), "{texts:?}");
        assert!(check_source("m", Target::Glsl, &texts[0]).starts_with("#version 450 core\n#define SHADEFIT_KEEP_ALL\n// h\n"));
        assert!(check_source("m", Target::GlslEs, &texts[1]).ends_with("void main() {\n    m_keep_all();\n}\n"));
        assert!(check_source("m", Target::Hlsl, "x").starts_with("#define SHADEFIT_KEEP_ALL\nx"));
        let spv = out.iter().find(|a| a.contents.starts_with(&0x0723_0203u32.to_le_bytes())).expect("a SPIR-V module");
        let word = |k: usize| u32::from_le_bytes(spv.contents[4 * k..4 * k + 4].try_into().unwrap());
        assert_eq!(word(1), 0x0001_0000, "SPIR-V version 1.0");
        let bytes = &spv.contents;
        let has = |needle: &[u8]| bytes.windows(needle.len()).any(|w| w == needle);
        assert!(has(b"emitted_f"), "no OpName of the function");
        assert!(has(b"m_keep_all\0"), "no OpEntryPoint named m_keep_all (NAME_keep_all)");
        assert!(has(b"return x * 2.0"), "no OpSource text");
    }

    /// The entry point that keeps every function alive calls each one with a zero of each
    /// argument type (scalars, a vector, a struct) and binds one global per resource type: two
    /// functions taking a texture and a sampler share the same two bindings. The module with it
    /// appended parses and validates.
    #[test]
    fn the_keep_entry_point_calls_every_function_with_one_binding_per_resource_type() {
        let src = "struct P { x: f32 }\n\
                   fn a(x: f32, n: u32, i: i32, b: bool, v: vec3<f32>, p: P, m: mat2x3<f32>, r: array<f32, 4>) -> f32 { return x + p.x; }\n\
                   fn t(tex: texture_2d<f32>, s: sampler, uv: vec2<f32>) -> vec4<f32> { return textureSampleLevel(tex, s, uv, 0.0); }\n\
                   fn u(s: sampler, tex: texture_2d<f32>) -> vec4<f32> { return textureSampleLevel(tex, s, vec2<f32>(0.5), 0.0); }\n\
                   fn w() {}\n";
        let m = naga::front::wgsl::parse_str(src).unwrap();
        let ep = keep_entry_point("k", &m).unwrap();
        let (all, _) = parse("k", &format!("{src}{ep}")).unwrap_or_else(|e| panic!("{e}\n{ep}"));
        assert_eq!(all.global_variables.len(), 2, "{ep}");
        assert_eq!(all.entry_points.len(), 1);
        for call in ["_ = a(0f, 0u, 0i, false, vec3<f32>(), P(), mat2x3<f32>(), array<f32, 4>());", "_ = t(k_keep_binding_0, k_keep_binding_1, vec2<f32>());", "_ = u(k_keep_binding_1, k_keep_binding_0);", "    w();"] {
            assert!(ep.contains(call), "no '{call}' in {ep}");
        }
        assert!(ep.contains("var k_keep_binding_0: texture_2d<f32>;") && ep.contains("var k_keep_binding_1: sampler;"), "{ep}");
        // Named after the module, NAME_keep_all.
        assert!(ep.contains("@fragment\nfn k_keep_all() {\n"), "{ep}");
    }

    /// The C header holds every named constant with its values read back bit for bit, scalars,
    /// 1-D and 2-D arrays, under an include guard.
    #[test]
    fn the_c_header_holds_every_constant() {
        let wgsl = "const K: f32 = 0.1;\nconst A: array<f32, 3> = array<f32, 3>(1.5, -2.5e-8, 3.4028235e38);\n\
                    const V: array<vec2<f32>, 2> = array<vec2<f32>, 2>(vec2<f32>(0.25, 0.5), vec2<f32>(0.75, 1.0));\n\
                    const N: u32 = 7u;\nconst I: i32 = -3;\nconst B: bool = true;\n\
                    const M: mat2x3<f32> = mat2x3<f32>(1.0, 2.0, 3.0, 4.0, 5.0, 6.0);\n\
                    const S: vec3<f32> = vec3<f32>(0.125);\nconst R: array<f32, 2> = array<f32, 2>(K, 2.0);\n\
                    fn f() -> f32 { return K + A[1] + V[1].x + f32(N) + f32(I) + select(0.0, 1.0, B) + M[1].x + S.y + R[0]; }\n";
        let m = naga::front::wgsl::parse_str(wgsl).unwrap();
        let h = c_header("mod_x", &["line"], "mod_x.wgsl", &m).unwrap();
        assert!(h.contains("#ifndef SHADEFIT_MOD_X_H") && h.trim_end().ends_with("#endif /* SHADEFIT_MOD_X_H */"), "{h}");
        // Every number between `= ` and `;` of each declaration, parsed back as f32.
        let values = |name: &str| -> Vec<f32> {
            let at = h.find(&format!(" {name} =")).or_else(|| h.find(&format!(" {name}["))).unwrap_or_else(|| panic!("{name} missing:\n{h}"));
            let body = &h[at..];
            let body = &body[body.find('=').unwrap() + 1..body.find(';').unwrap()];
            body.split(|c: char| c == ',' || c == '{' || c == '}' || c.is_whitespace())
                .filter(|t| !t.is_empty())
                .map(|t| t.trim_end_matches(['f', 'u']).parse::<f32>().unwrap_or_else(|e| panic!("{t}: {e}")))
                .collect()
        };
        assert_eq!(values("K"), vec![0.1f32]);
        assert!(h.contains("static const float K ="), "{h}");
        assert_eq!(values("A").iter().map(|v| v.to_bits()).collect::<Vec<_>>(), [1.5f32, -2.5e-8, f32::MAX].map(f32::to_bits).to_vec());
        assert!(h.contains("static const float V[2][2] ="), "{h}");
        assert_eq!(values("V"), vec![0.25, 0.5, 0.75, 1.0]);
        assert_eq!(values("N"), vec![7.0]);
        assert!(h.contains("static const uint32_t N ="), "{h}");
        // A signed integer, a bool (C: int 1), a matrix (columns × rows, column-major as WGSL
        // stores it), a splat (one value repeated) and an array naming another constant.
        assert_eq!(values("I"), vec![-3.0]);
        assert!(h.contains("static const int32_t I ="), "{h}");
        assert_eq!(values("B"), vec![1.0]);
        assert!(h.contains("static const int B ="), "{h}");
        assert_eq!(values("M"), vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        assert!(h.contains("static const float M[2][3] ="), "{h}");
        assert_eq!(values("S"), vec![0.125; 3]);
        assert_eq!(values("R"), vec![0.1, 2.0]);
    }

    /// A 1-D array of 13 values is laid out six to a line, each line indented four spaces: lines
    /// of 6, 6 and 1 values between the braces.
    #[test]
    fn a_c_header_array_holds_six_values_to_a_line() {
        let wgsl = "const T: array<f32, 13> = array<f32, 13>(0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0, 12.0);\n\
                    fn f() -> f32 { return T[3]; }\n";
        let m = naga::front::wgsl::parse_str(wgsl).unwrap();
        let h = c_header("mod_t", &["line"], "mod_t.wgsl", &m).unwrap();
        let at = h.find("static const float T[13] = {\n").unwrap_or_else(|| panic!("{h}"));
        let body = &h[at..];
        let body = &body[body.find('{').unwrap() + 2..body.find("\n};").unwrap_or_else(|| panic!("{h}"))];
        let lines: Vec<&str> = body.split('\n').collect();
        assert!(lines.iter().all(|l| l.starts_with("    ") && !l.starts_with("     ")), "{body}");
        assert_eq!(lines.iter().map(|l| l.split(',').filter(|t| !t.trim().is_empty()).count()).collect::<Vec<_>>(), [6, 6, 1], "{body}");
    }

    /// Appends the named constant `name: ty = e` to a module built by hand (the WGSL front end
    /// folds or refuses what these tests need).
    fn constant(m: &mut naga::Module, name: &str, ty: naga::Handle<naga::Type>, e: naga::Expression) -> naga::Handle<naga::Constant> {
        let init = m.global_expressions.append(e, naga::Span::UNDEFINED);
        m.constants.append(naga::Constant { name: Some(name.into()), ty, init }, naga::Span::UNDEFINED)
    }

    /// A constant whose value is another constant (`Expression::Constant`: valid IR, which the
    /// WGSL front end folds away, so it is built here by hand) flattens to that constant's
    /// values, through a chain of two references and inside a composite.
    #[test]
    fn constants_naming_constants_flatten_to_their_values() {
        use naga::{Expression, Span, Type};
        let mut m = naga::Module::default();
        let f32t = m.types.insert(Type { name: None, inner: TypeInner::Scalar(Scalar::F32) }, Span::UNDEFINED);
        let pair = m.types.insert(Type { name: None, inner: TypeInner::Vector { size: naga::VectorSize::Bi, scalar: Scalar::F32 } }, Span::UNDEFINED);
        let k = constant(&mut m, "K", f32t, Expression::Literal(Literal::F32(0.5)));
        let r = constant(&mut m, "R", f32t, Expression::Constant(k));
        constant(&mut m, "RR", f32t, Expression::Constant(r));
        let (ref_r, two) = (m.global_expressions.append(Expression::Constant(r), Span::UNDEFINED), m.global_expressions.append(Expression::Literal(Literal::F32(2.0)), Span::UNDEFINED));
        constant(&mut m, "V", pair, Expression::Compose { ty: pair, components: vec![ref_r, two] });
        let flat: Vec<(String, Vec<Literal>)> = named_constants(&m).into_iter().map(|f| f.map(|f| (f.name, f.values)).unwrap()).collect();
        let half = Literal::F32(0.5);
        assert_eq!(flat, [("K".into(), vec![half]), ("R".into(), vec![half]), ("RR".into(), vec![half]), ("V".into(), vec![half, Literal::F32(2.0)])]);
    }

    /// A non-finite f32 constant has no C literal (`inf` and `NaN` are not C tokens, and
    /// `INFINITY` would need <math.h>): the header is refused, naming the module, rather than
    /// written with a token a C compiler rejects or reads as an identifier. The WGSL front end
    /// refuses such a constant, so the module is built here by hand; the same module with a
    /// finite value gives its header.
    #[test]
    fn a_non_finite_constant_has_no_c_form() {
        use naga::{Expression, Span, Type};
        let module = |v: f32| {
            let mut m = naga::Module::default();
            let ty = m.types.insert(Type { name: None, inner: TypeInner::Scalar(Scalar::F32) }, Span::UNDEFINED);
            constant(&mut m, "K", ty, Expression::Literal(Literal::F32(v)));
            m
        };
        let h = c_header("mod_k", &["line"], "mod_k.wgsl", &module(0.5)).unwrap();
        assert!(h.contains("static const float K = 5e-1f;"), "{h}");
        for v in [f32::INFINITY, f32::NEG_INFINITY, f32::NAN] {
            match c_header("mod_k", &["line"], "mod_k.wgsl", &module(v)) {
                Err(TargetError::Unsupported { module, what }) => {
                    assert_eq!((module.as_str(), what.as_str()), ("mod_k", "a constant with no C form"))
                }
                other => panic!("{v}: {other:?}"),
            }
        }
    }

    /// A splat inside a composite (`vec3<f32>(1.0)` in an array of vectors, kept as
    /// `Expression::Splat` by the WGSL front end) flattens to its value repeated once per
    /// component of its own vector, not of the whole array: the composite's count divided
    /// among its components.
    #[test]
    fn splats_inside_composites_fill_their_own_vector() {
        let wgsl = "const T = array<vec3<f32>, 2>(vec3<f32>(1.0), vec3<f32>(2.0, 3.0, 4.0));\n";
        let m = naga::front::wgsl::parse_str(wgsl).unwrap();
        let splats = m.global_expressions.iter().filter(|(_, e)| matches!(e, naga::Expression::Splat { .. })).count();
        assert_eq!(splats, 1, "the front end no longer keeps the splat: the test does not reach it");
        let flat: Vec<_> = named_constants(&m).into_iter().map(|f| f.map(|f| (f.name, f.dims, f.values))).collect();
        let v = [1.0, 1.0, 1.0, 2.0, 3.0, 4.0].map(Literal::F32).to_vec();
        assert_eq!(flat, [Some(("T".to_string(), vec![2, 3], v))]);
    }

    /// Each target's file is the one the README's target table names, written out here.
    #[test]
    fn each_target_writes_the_file_the_readme_names() {
        let want = [
            (Target::Wgsl, "wgsl/NAME.wgsl"),
            (Target::WgslPlain, "wgsl-plain/NAME.wgsl"),
            (Target::Hlsl, "hlsl/NAME.hlsl"),
            (Target::Glsl, "glsl/NAME.glsl"),
            (Target::GlslEs, "glsl-es/NAME.glsl"),
            (Target::Msl, "msl/NAME.metal"),
            (Target::Spirv, "spirv/NAME.spv"),
            (Target::C, "c/NAME.h"),
            (Target::Wesl, "wesl/NAME.wesl"),
        ];
        assert_eq!(want.map(|(t, _)| t), Target::ALL);
        for (t, path) in want {
            assert_eq!(t.path("NAME"), PathBuf::from(path), "{t:?}");
        }
    }

    #[test]
    fn target_names_round_trip_and_lists_are_sorted() {
        for t in Target::ALL {
            assert_eq!(Target::from_name(t.name()), Some(t));
        }
        assert_eq!(parse_list(&["spirv", "hlsl", "spirv"]).unwrap(), vec![Target::Hlsl, Target::Spirv]);
        assert!(parse_list(&["hlsl", "vulkan"]).unwrap_err().contains("unknown target 'vulkan'"));
    }

    /// `--target wesl` adds the package manifest `wesl/wesl.toml` once (WeslToml: a
    /// `[package]` whose root is the folder itself and which includes every `.wesl` file);
    /// the other targets add no file of their own.
    #[test]
    fn the_wesl_target_adds_its_package_manifest() {
        let files = package_files(&[Target::Hlsl, Target::Wesl, Target::Spirv]);
        assert_eq!(files.len(), 1);
        assert_eq!(files[0].path, Path::new("wesl").join("wesl.toml"));
        let v: toml::Value = toml::from_str(std::str::from_utf8(&files[0].contents).unwrap()).unwrap();
        assert_eq!(v["package"]["root"].as_str(), Some("."));
        assert_eq!(v["package"]["include"].as_array().map(|a| a.iter().filter_map(|s| s.as_str()).collect::<Vec<_>>()), Some(vec!["*.wesl"]));
        assert!(v["package"]["edition"].is_str());
        let others: Vec<Target> = Target::ALL.into_iter().filter(|t| *t != Target::Wesl).collect();
        assert!(package_files(&others).is_empty());
    }

    #[test]
    fn the_module_target_alone_adds_nothing() {
        assert!(translate("x", "not even WGSL", &[Target::Wgsl]).unwrap().is_empty());
    }

    #[test]
    fn hlsl_constant_initialisers_become_brace_lists() {
        let naga_hlsl = "typedef float ret_Constructarray2_float_[2];\n\
                         static const float A[2] = Constructarray2_float_(1.0, -2.5e-8);\n\
                         static const float2 B[1] = Constructarray1_float2_(float2(0.5, 1.0));\n\
                         static const S C = ConstructS(Constructarray2_float_(3.0, 4.0), 1u);\n\
                         static const float D = 0.25;\n\
                         float f() { float a[2] = Constructarray2_float_(1.0, 2.0); return a[0]; }\n";
        let out = hlsl_brace_initializers(naga_hlsl);
        let lines: Vec<&str> = out.lines().collect();
        assert_eq!(lines[0], "typedef float ret_Constructarray2_float_[2];");
        assert_eq!(lines[1], "static const float A[2] = {1.0, -2.5e-8};");
        assert_eq!(lines[2], "static const float2 B[1] = {float2(0.5, 1.0)};");
        assert_eq!(lines[3], "static const S C = {{3.0, 4.0}, 1u};");
        assert_eq!(lines[4], "static const float D = 0.25;");
        // A constructor call in a function body is an expression and stays one.
        assert_eq!(lines[5], "float f() { float a[2] = Constructarray2_float_(1.0, 2.0); return a[0]; }");
    }

    #[test]
    fn hlsl_heap_samplers_become_register_bindings() {
        let naga_hlsl = "Texture2D<float4> t : register(t0);\n\
                         SamplerState nagaSamplerHeap[2048]: register(s0, space0);\n\
                         SamplerComparisonState nagaComparisonSamplerHeap[2048]: register(s0, space1);\n\
                         StructuredBuffer<uint> nagaGroup0SamplerIndexArray : register(t0, space255);\n\
                         static const SamplerState m_keep_binding_1_ = nagaSamplerHeap[nagaGroup0SamplerIndexArray[1]];\n\
                         float4 f(Texture2D<float4> a, SamplerState s) { return a.SampleLevel(s, float2(0.0, 0.0), 0.0); }\n";
        let out = hlsl_sampler_registers(naga_hlsl);
        assert_eq!(
            out,
            "Texture2D<float4> t : register(t0);\n\
             SamplerState m_keep_binding_1_ : register(s1, space0);\n\
             float4 f(Texture2D<float4> a, SamplerState s) { return a.SampleLevel(s, float2(0.0, 0.0), 0.0); }\n"
        );
        // Only an index buffer, named both nagaGroup… and …SamplerIndexArray, goes: unread
        // buffers that have one half of that name stay as they were.
        let halves = "StructuredBuffer<uint> nagaGroup0Counts : register(t1, space0);\n\
                      StructuredBuffer<uint> userSamplerIndexArray : register(t2, space0);\n";
        assert_eq!(hlsl_sampler_registers(&format!("{naga_hlsl}{halves}")), format!("{out}{halves}"));
        // A heap still read elsewhere keeps its declaration.
        let shared = format!("{naga_hlsl}SamplerState g() {{ return nagaSamplerHeap[0]; }}\n");
        let out = hlsl_sampler_registers(&shared);
        assert!(out.contains("SamplerState nagaSamplerHeap[2048]") && !out.contains("nagaComparisonSamplerHeap"));
        // A comparison sampler is read from its own heap and bound the same way, with its type.
        let compare = "SamplerComparisonState nagaComparisonSamplerHeap[2048]: register(s0, space1);\n\
                       StructuredBuffer<uint> nagaGroup1SamplerIndexArray : register(t1, space255);\n\
                       static const SamplerComparisonState m_shadow = nagaComparisonSamplerHeap[nagaGroup1SamplerIndexArray[3]];\n";
        assert_eq!(hlsl_sampler_registers(compare), "SamplerComparisonState m_shadow : register(s3, space1);\n");
        // Group and binding are the decimal numbers of WGSL's @group(G) @binding(B): a global
        // read through an index that is not one (a letter, nothing) stays as it was, and so do
        // the declarations it reads.
        for (group, binding) in [("X", "1"), ("0", "")] {
            let odd = format!(
                "SamplerState nagaSamplerHeap[2048]: register(s0, space0);\n\
                 StructuredBuffer<uint> nagaGroup{group}SamplerIndexArray : register(t0, space255);\n\
                 static const SamplerState m_odd = nagaSamplerHeap[nagaGroup{group}SamplerIndexArray[{binding}]];\n"
            );
            assert_eq!(hlsl_sampler_registers(&odd), odd, "group '{group}', binding '{binding}'");
        }
    }

    /// The WGSL of each argument type the keep entry point can make a value of is the type
    /// itself: each type, declared as a function argument and parsed, is written back as it was
    /// declared. Types it cannot make (a depth or multisampled texture, an integer texture, a
    /// pointer) have none.
    #[test]
    fn argument_types_are_written_back_as_declared() {
        let made = [
            "f32", "u32", "i32", "bool", "vec2<f32>", "vec3<u32>", "vec4<i32>", "vec2<bool>", "mat2x3<f32>", "mat4x4<f32>",
            "array<f32, 4>", "array<vec3<f32>, 2>", "P", "texture_1d<f32>", "texture_2d<f32>", "texture_3d<f32>",
            "texture_cube<f32>", "texture_2d_array<f32>", "texture_cube_array<f32>", "sampler", "sampler_comparison",
        ];
        let unmade = ["texture_depth_2d", "texture_multisampled_2d<f32>", "texture_2d<i32>", "ptr<function, f32>"];
        for (ty, want) in made.iter().map(|t| (t, Some(t.to_string()))).chain(unmade.iter().map(|t| (t, None))) {
            let m = naga::front::wgsl::parse_str(&format!("struct P {{ x: f32 }}\nfn f(a: {ty}) {{}}\n")).unwrap_or_else(|e| panic!("{ty}: {e}"));
            let (_, f) = m.functions.iter().next().unwrap();
            assert_eq!(wgsl_type(&m, f.arguments[0].ty), want, "{ty}");
        }
    }

    /// Every text target begins with the module's header lines, then one line of its own
    /// naming the target and the file it came from. The WGSL without its directive keeps the
    /// module's code as it was.
    #[test]
    fn every_text_target_carries_the_header_and_its_provenance() {
        let code = "fn emitted_f(x: f32) -> f32 { return x * 2.0; }\n";
        let src = format!("// first line\n// second line\n#define_import_path shadefit::m\n{code}");
        let targets = [Target::WgslPlain, Target::Hlsl, Target::Glsl, Target::GlslEs, Target::Msl, Target::C, Target::Wesl];
        let out = translate("m", &src, &targets).unwrap();
        assert_eq!(out.len(), targets.len());
        for (t, a) in targets.iter().zip(&out) {
            assert_eq!(a.path, t.path("m"));
            let text = String::from_utf8(a.contents.clone()).unwrap();
            // The include form has no #version (the including shader's comes first); a
            // guard around its items and the harness behind the macro.
            assert!(!text.lines().any(|l| l.starts_with("#version")), "{t:?}");
            if matches!(t, Target::Hlsl | Target::Glsl | Target::GlslEs | Target::Msl) {
                let g = include::guard("m", t.extension());
                assert!(text.contains(&format!("#ifndef {g}\n#define {g}\n")) && text.trim_end().ends_with(&format!("#endif // {g}")), "{t:?}:\n{text}");
                let on = text.find("#ifdef SHADEFIT_KEEP_ALL").unwrap();
                assert!(text[on..].contains("m_keep_all(") && !text[..on].contains("m_keep_all("), "{t:?}:\n{text}");
            }
            let mut lines = text.lines();
            assert_eq!((lines.next(), lines.next()), (Some("// first line"), Some("// second line")), "{t:?}:\n{text}");
            let own = lines.next().unwrap();
            assert!(own.starts_with("// ") && own.contains("wgsl/m.wgsl"), "{t:?}: {own}");
            if !matches!(t, Target::WgslPlain | Target::Wesl | Target::C) {
                assert!(own.starts_with(&format!("// {} translated from wgsl/m.wgsl", t.name())), "{t:?}: {own}");
            }
            if matches!(t, Target::WgslPlain | Target::Wesl) {
                assert_eq!(lines.collect::<Vec<_>>().join("\n") + "\n", code, "{t:?}");
            }
        }
    }

    /// Text that is not a module file is refused for what it lacks or adds: no
    /// `#define_import_path` after the header, or a directive line in the code.
    #[test]
    fn a_module_file_needs_its_import_path_and_no_other_directive() {
        let why = |src: &str| match translate("x", src, &[Target::Hlsl]) {
            Err(TargetError::Unsupported { module, what }) => {
                assert_eq!(module, "x");
                what
            }
            other => panic!("{src:?}: {other:?}"),
        };
        assert_eq!(why("// h\nfn f() {}\n"), "no `#define_import_path` line after the header");
        assert_eq!(why("// h\n#define_import_path shadefit::x\nfn f() {}\n  #ifdef X\n"), "it has a directive line `#ifdef X`");
        assert!(translate("x", "#define_import_path shadefit::x\nfn f() {}\n", &[Target::Hlsl]).is_ok(), "no header lines at all is fine");
    }

    #[test]
    fn imports_are_refused() {
        let src = "// h\n#define_import_path shadefit::x\n#import shadefit::y\nfn f() {}\n";
        let e = translate("x", src, &[Target::Hlsl]).unwrap_err();
        assert!(matches!(e, TargetError::Unsupported { .. }), "{e}");
    }
}
