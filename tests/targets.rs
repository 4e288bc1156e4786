//! The emit targets besides the WGSL modules (src/emit/targets.rs), on every committed module
//! of generated/wgsl (`build --check` proves those are what the build emits):
//! - every named f32 constant of the WGSL (the coefficients and tables) reads back bit for bit
//!   from each target: from the text of HLSL, GLSL 450, GLSL ES 300, MSL and the C header, from
//!   the SPIR-V words, from the SPIR-V again through naga's SPIR-V front end, and from the C
//!   header as compiled by the system C compiler;
//! - every function of the module is in every shading-language output;
//! - glslangValidator compiles every GLSL file, spirv-val passes every SPIR-V module, the Slang
//!   compiler compiles every HLSL file (parsed as HLSL, generated to SPIR-V), naga validates the
//!   plain WGSL as is and reads the SPIR-V back (MSL: naga validated the module it was written
//!   from and its constants are compared as text; there is no Metal compiler on Linux); all the
//!   plain files together validate as one source (no name declared twice);
//! - the WESL modules are the plain WGSL (tests/wesl.rs links the package with wesl-rs);
//! - `build --target` and `[emit] targets` through the binary, byte-identical at any thread count.
//!
//! The validators come from `bash scripts/setup-shader-tools` (Slang into
//! target/shader-tools/slang); without them a test skips with a note, except under CI=true,
//! where it fails.

mod common;

use common::{committed_modules as modules, copy_dir, root, scratch, shadefit, snapshot, stderr};
use shadefit::emit::targets::{check_source, glsl_version, keep_entry_point_name, named_constants, translate, Flat, Target};
use shadefit::emit::Artifact;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

struct Module {
    name: String,
    /// naga's IR of the plain WGSL.
    ir: naga::Module,
    /// The header lines of the WGSL module (without `// `).
    header: Vec<String>,
    files: BTreeMap<Target, Vec<u8>>,
}

/// Every module in every target, translated once for all tests.
fn translated() -> &'static [Module] {
    static ALL: OnceLock<Vec<Module>> = OnceLock::new();
    ALL.get_or_init(|| {
        let out: Vec<Module> = modules()
            .into_iter()
            .map(|(name, text)| {
                let arts: Vec<Artifact> = translate(&name, &text, &Target::ALL).unwrap_or_else(|e| panic!("{e}"));
                let files: BTreeMap<Target, Vec<u8>> = Target::ALL[1..]
                    .iter()
                    .map(|t| {
                        let a = arts.iter().find(|a| a.path == t.path(&name)).unwrap_or_else(|| panic!("{name}: no {}", t.name()));
                        (*t, a.contents.clone())
                    })
                    .collect();
                assert_eq!(files.len(), arts.len(), "{name}: one file per target");
                let plain = String::from_utf8(files[&Target::WgslPlain].clone()).unwrap();
                let ir = naga::front::wgsl::parse_str(&plain).unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&plain)));
                let header = text.lines().take_while(|l| l.starts_with("// ")).map(|l| l[3..].to_string()).collect();
                Module { name, ir, header, files }
            })
            .collect();
        assert!(out.len() >= 20, "the committed modules ({})", out.len());
        out
    })
}

fn text(m: &Module, t: Target) -> &str {
    std::str::from_utf8(&m.files[&t]).unwrap()
}

/// The named constants whose scalars are all f32, flattened.
fn f32_constants(m: &Module) -> Vec<(String, Vec<f32>)> {
    named_constants(&m.ir)
        .into_iter()
        .map(|f| f.expect("every constant has a flat form"))
        .filter_map(|Flat { name, values, .. }| {
            let v: Option<Vec<f32>> = values.iter().map(|l| if let naga::Literal::F32(x) = l { Some(*x) } else { None }).collect();
            Some((name, v?))
        })
        .collect()
}

/// The float literals (with a '.' or an exponent) of a piece of source, in order: each parsed
/// as f32 directly and through f64 (as compilers that read literals as double do), which must
/// agree.
fn float_literals(src: &str) -> Vec<f32> {
    let b = src.as_bytes();
    let ident = |c: u8| c.is_ascii_alphanumeric() || c == b'_' || c == b'.';
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_digit() && (i == 0 || !ident(b[i - 1])) {
            let neg = i > 0 && b[i - 1] == b'-' && (i < 2 || !(ident(b[i - 2]) || b[i - 2] == b')' || b[i - 2] == b']'));
            let start = i;
            while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'.' || b[i] == b'e' || b[i] == b'E' || ((b[i] == b'-' || b[i] == b'+') && (b[i - 1] == b'e' || b[i - 1] == b'E'))) {
                i += 1;
            }
            let tok = &src[start..i];
            if tok.contains(['.', 'e', 'E']) {
                let s = if neg { format!("-{tok}") } else { tok.to_string() };
                let v: f32 = s.parse().unwrap_or_else(|_| panic!("literal {s}"));
                let via_f64 = s.parse::<f64>().unwrap() as f32;
                assert_eq!(v.to_bits(), via_f64.to_bits(), "{s} reads differently through f64");
                out.push(v);
            }
        } else {
            i += 1;
        }
    }
    out
}

/// The initialiser of the declaration of `name` in `src` (from `=` to `;`).
fn initialiser<'a>(src: &'a str, name: &str) -> Option<&'a str> {
    let mut from = 0;
    while let Some(k) = src[from..].find(name) {
        let at = from + k;
        from = at + name.len();
        let before = src[..at].chars().next_back();
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            continue;
        }
        // Between the name and `=`: array sizes (C, GLSL, HLSL) or `: TYPE` (WGSL), on one line.
        let rest = &src[from..];
        let Some(eq) = rest.find('=') else { continue };
        if rest[..eq].contains([';', '(', ')', '{', '}', '\n']) || rest[..eq].trim_start().starts_with(|c: char| c.is_alphanumeric()) {
            continue;
        }
        let init = &rest[eq + 1..];
        return Some(&init[..init.find(';')?]);
    }
    None
}

fn same_bits(a: &[f32], b: &[f32]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

#[test]
fn every_f32_constant_survives_each_text_target_bit_for_bit() {
    let mut checked = 0;
    for m in translated() {
        for t in [Target::WgslPlain, Target::Hlsl, Target::Glsl, Target::GlslEs, Target::Msl, Target::C] {
            let src = text(m, t);
            for (name, want) in f32_constants(m) {
                let init = initialiser(src, &name).unwrap_or_else(|| panic!("{}: {name} is not declared in {}", m.name, t.name()));
                let got = float_literals(init);
                assert!(same_bits(&got, &want), "{}: {name} in {}: {} values read back, not the {} of the WGSL bit for bit", m.name, t.name(), got.len(), want.len());
                checked += want.len();
            }
        }
    }
    // The skin punctual LUT alone has 65·64·3 texels, in six targets.
    assert!(checked > 6 * 12_480, "{checked} values checked");
}

#[test]
fn every_function_is_in_each_shading_language() {
    for m in translated() {
        for (_, f) in m.ir.functions.iter() {
            let name = f.name.as_deref().unwrap();
            for t in [Target::Hlsl, Target::Glsl, Target::GlslEs, Target::Msl] {
                assert!(text(m, t).contains(&format!(" {name}(")), "{}: {name} is not defined in {}", m.name, t.name());
            }
        }
    }
}

#[test]
fn every_file_carries_the_module_header() {
    for m in translated() {
        for (t, bytes) in &m.files {
            let hay = String::from_utf8_lossy(bytes);
            for h in &m.header {
                // Text targets as `// line`; SPIR-V in its OpSource string (the WGSL source).
                let want = if *t == Target::Spirv { h.clone() } else { format!("// {h}\n") };
                assert!(hay.contains(&want), "{}: {} lacks header line {h:?}", m.name, t.name());
            }
        }
    }
}

#[test]
fn plain_wgsl_is_accepted_by_naga_as_is() {
    for m in translated() {
        let src = text(m, Target::WgslPlain);
        assert!(!src.lines().any(|l| l.trim_start().starts_with('#')), "{}: a directive line", m.name);
        let ir = naga::front::wgsl::parse_str(src).unwrap();
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default())
            .validate(&ir)
            .unwrap_or_else(|e| panic!("{}: {}", m.name, e.emit_to_string(src)));
        assert!(ir.entry_points.is_empty(), "{}: the plain library has no entry point", m.name);
    }
    // All plain files at once, as one source (an engine that concatenates them): no name is
    // declared twice, and naga validates the whole.
    let all: String = translated().iter().map(|m| text(m, Target::WgslPlain)).collect::<Vec<_>>().join("\n");
    let ir = naga::front::wgsl::parse_str(&all).unwrap_or_else(|e| panic!("every plain file together: {}", e.emit_to_string(&all)));
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default())
        .validate(&ir)
        .unwrap_or_else(|e| panic!("every plain file together: {}", e.emit_to_string(&all)));
    let functions: usize = translated().iter().map(|m| m.ir.functions.len()).sum();
    assert_eq!(ir.functions.len(), functions);
}

#[test]
fn wesl_modules_are_the_plain_wgsl() {
    // The WESL module differs from the plain WGSL in its last header line only (what it is).
    for m in translated() {
        let (plain, wesl) = (text(m, Target::WgslPlain), text(m, Target::Wesl));
        let code = |s: &str| s.lines().skip(m.header.len() + 1).collect::<Vec<_>>().join("\n");
        assert_eq!(code(plain), code(wesl), "{}", m.name);
        let note = wesl.lines().nth(m.header.len()).unwrap();
        assert!(note.starts_with(&format!("// WESL module shadefit::{} (package: wesl.toml)", m.name)), "{note}");
    }
}

/// SPIR-V instructions: (opcode, operands).
fn spirv_instructions(bytes: &[u8]) -> Vec<(u16, Vec<u32>)> {
    let words: Vec<u32> = bytes.chunks(4).map(|c| u32::from_le_bytes(c.try_into().unwrap())).collect();
    assert_eq!(words[0], 0x0723_0203, "SPIR-V magic");
    let mut out = Vec::new();
    let mut i = 5;
    while i < words.len() {
        let (count, op) = ((words[i] >> 16) as usize, (words[i] & 0xffff) as u16);
        out.push((op, words[i + 1..i + count].to_vec()));
        i += count;
    }
    out
}

/// The module without its OpSource and OpSourceContinued instructions.
fn without_source(bytes: &[u8]) -> Vec<u8> {
    const SOURCE_CONTINUED: u32 = 2;
    const SOURCE: u32 = 3;
    let words: Vec<u32> = bytes.chunks(4).map(|c| u32::from_le_bytes(c.try_into().unwrap())).collect();
    let mut out: Vec<u32> = words[..5].to_vec();
    let mut i = 5;
    while i < words.len() {
        let count = (words[i] >> 16) as usize;
        if !matches!(words[i] & 0xffff, SOURCE | SOURCE_CONTINUED) {
            out.extend_from_slice(&words[i..i + count]);
        }
        i += count;
    }
    out.iter().flat_map(|w| w.to_le_bytes()).collect()
}

fn spirv_string(words: &[u32]) -> String {
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).take_while(|&b| b != 0).collect();
    String::from_utf8(bytes).unwrap()
}

#[test]
fn every_f32_constant_survives_spirv_bit_for_bit() {
    const NAME: u16 = 5;
    const TYPE_FLOAT: u16 = 22;
    const CONSTANT: u16 = 43;
    const CONSTANT_COMPOSITE: u16 = 44;
    let mut checked = 0;
    for m in translated() {
        let ins = spirv_instructions(&m.files[&Target::Spirv]);
        let mut names: BTreeMap<String, Vec<u32>> = BTreeMap::new();
        let mut float_types = Vec::new();
        let mut scalars: BTreeMap<u32, u32> = BTreeMap::new();
        let mut composites: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
        for (op, w) in &ins {
            match *op {
                NAME => names.entry(spirv_string(&w[1..])).or_default().push(w[0]),
                TYPE_FLOAT if w[1] == 32 => float_types.push(w[0]),
                CONSTANT if float_types.contains(&w[0]) => {
                    scalars.insert(w[1], w[2]);
                }
                CONSTANT_COMPOSITE => {
                    composites.insert(w[1], w[2..].to_vec());
                }
                _ => {}
            }
        }
        fn flatten(id: u32, s: &BTreeMap<u32, u32>, c: &BTreeMap<u32, Vec<u32>>, out: &mut Vec<f32>) -> bool {
            if let Some(bits) = s.get(&id) {
                out.push(f32::from_bits(*bits));
                true
            } else if let Some(parts) = c.get(&id) {
                parts.iter().all(|p| flatten(*p, s, c, out))
            } else {
                false
            }
        }
        for (name, want) in f32_constants(m) {
            let ids = names.get(&name).unwrap_or_else(|| panic!("{}: no OpName {name}", m.name));
            let found = ids.iter().any(|id| {
                let mut got = Vec::new();
                flatten(*id, &scalars, &composites, &mut got) && same_bits(&got, &want)
            });
            assert!(found, "{}: {name} in SPIR-V is not the WGSL's bit for bit", m.name);
            checked += want.len();
        }
    }
    assert!(checked > 12_480, "{checked} values checked");
}

#[test]
fn spirv_reads_back_through_naga_with_every_function_and_constant() {
    for m in translated() {
        // naga's SPIR-V front end does not read OpSourceContinued (a source over one
        // instruction's length, as skin_punctual_lut's): drop the debug source instructions,
        // which have no semantic impact, before reading back.
        let bytes = without_source(&m.files[&Target::Spirv]);
        let back = naga::front::spv::parse_u8_slice(&bytes, &Default::default())
            .unwrap_or_else(|e| panic!("{}: {e:?}", m.name));
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default())
            .validate(&back)
            .unwrap_or_else(|e| panic!("{}: {e:?}", m.name));
        let names: Vec<&str> = back.functions.iter().filter_map(|(_, f)| f.name.as_deref()).collect();
        for (_, f) in m.ir.functions.iter() {
            let n = f.name.as_deref().unwrap();
            assert!(names.contains(&n), "{}: {n} is not among the functions read back ({names:?})", m.name);
        }
        // Every f32 the WGSL's constants hold is an f32 literal of the module read back.
        let mut lits: Vec<u32> = back
            .global_expressions
            .iter()
            .filter_map(|(_, e)| if let naga::Expression::Literal(naga::Literal::F32(v)) = e { Some(v.to_bits()) } else { None })
            .collect();
        lits.sort();
        for (name, values) in f32_constants(m) {
            for v in values {
                assert!(lits.binary_search(&v.to_bits()).is_ok(), "{}: {name} value {v:e} is not in the SPIR-V read back", m.name);
            }
        }
    }
}

/// A validator on PATH, or `None` (with a note) where it is missing outside CI.
fn tool(name: &str) -> Option<PathBuf> {
    let found = std::env::var_os("PATH")
        .and_then(|p| std::env::split_paths(&p).map(|d| d.join(name)).find(|p| p.is_file()));
    if found.is_none() {
        let hint = "bash scripts/setup-shader-tools installs glslang-tools and spirv-tools";
        if std::env::var("CI").is_ok_and(|v| v == "true") {
            panic!("{name} is not installed, and CI runs every validator ({hint})");
        }
        eprintln!("note: {name} is not installed; skipping its checks ({hint})");
    }
    found
}

fn run_ok(cmd: &mut Command, what: &str) {
    let o = cmd.output().unwrap_or_else(|e| panic!("{what}: {e}"));
    assert!(o.status.success(), "{what}:\n{}{}", String::from_utf8_lossy(&o.stdout), stderr(&o));
}

#[test]
fn glslang_compiles_every_glsl_file() {
    let Some(glslang) = tool("glslangValidator") else { return };
    let d = tempfile::tempdir().unwrap();
    let mut n = 0;
    for m in translated() {
        for t in [Target::Glsl, Target::GlslEs] {
            // The include form with its harness on, a #version first and a main last.
            let p = d.path().join(format!("{}.{}.frag", m.name, t.name()));
            std::fs::write(&p, check_source(&m.name, t, text(m, t))).unwrap();
            run_ok(Command::new(&glslang).arg(&p), &format!("glslangValidator {}", p.display()));
            n += 1;
        }
    }
    eprintln!("glslangValidator: {n} GLSL files compiled");
    assert_eq!(n, 2 * translated().len());
}

/// python3 and Slang's libraries (target/shader-tools/slang) for scripts/slang-hlsl-check, or
/// `None` (with a note) where they are missing outside CI.
fn slang() -> Option<(PathBuf, PathBuf)> {
    let python = tool("python3")?;
    let libs = root().join("target/shader-tools/slang");
    let have = std::fs::read_dir(&libs)
        .map(|d| d.flatten().any(|e| e.file_name().to_string_lossy().starts_with("libslang-compiler.so")))
        .unwrap_or(false);
    if !have {
        let hint = "bash scripts/setup-shader-tools unpacks Slang into target/shader-tools/slang";
        assert!(!std::env::var("CI").is_ok_and(|v| v == "true"), "Slang is not installed, and CI runs every validator ({hint})");
        eprintln!("note: Slang is not installed; skipping the HLSL check ({hint})");
        return None;
    }
    Some((python, libs))
}

/// A shader `shadefit_all` of every module's file of target `t` (HLSL: written to `dir` as
/// `NAME.EXT` and `#include`d; GLSL: inlined), each twice (the include guards), with the harnesses on, and calls every
/// module's harness from `shadefit_all_keep_all`.
fn all_in_one(dir: &Path, t: Target, ext: &str) -> String {
    let mut includes = String::new();
    let mut calls = String::new();
    for m in translated() {
        if glsl_version(t).is_some() {
            // glslangValidator processes #include only when it targets Vulkan (-V), which the
            // harness's unbound samplers do not fit: the text goes in as the preprocessor would
            // put it.
            includes.push_str(text(m, t));
        } else {
            std::fs::write(dir.join(format!("{}.{ext}", m.name)), &m.files[&t]).unwrap();
            includes.push_str(&format!("#include \"{}.{ext}\"\n", m.name));
        }
        calls.push_str(&format!("    {}();\n", keep_entry_point_name(&m.name)));
    }
    let twice = format!("{includes}{includes}");
    match glsl_version(t) {
        Some(v) => format!("{v}\n#define SHADEFIT_KEEP_ALL\n{twice}\nvoid main() {{\n{calls}}}\n"),
        None => format!("#define SHADEFIT_KEEP_ALL\n{twice}\nvoid shadefit_all_keep_all() {{\n{calls}}}\n"),
    }
}

#[test]
fn every_module_includes_beside_every_other_in_one_shader() {
    // An engine includes several modules in one shader: the HLSL files all in one Slang
    // compilation, the GLSL 450 and GLSL ES 300 files all in one glslangValidator run (each
    // file included twice, so the include guards are exercised too).
    let d = tempfile::tempdir().unwrap();
    if let Some((python, libs)) = slang() {
        let p = d.path().join("shadefit_all.hlsl");
        std::fs::write(&p, all_in_one(d.path(), Target::Hlsl, "hlsl")).unwrap();
        run_ok(Command::new(&python).arg(root().join("scripts/slang-hlsl-check")).arg(&libs).arg(&p), "Slang, every HLSL module in one shader");
    }
    if let Some(glslang) = tool("glslangValidator") {
        for t in [Target::Glsl, Target::GlslEs] {
            let sub = d.path().join(t.name());
            std::fs::create_dir(&sub).unwrap();
            let p = sub.join("shadefit_all.frag");
            std::fs::write(&p, all_in_one(&sub, t, "glsl")).unwrap();
            run_ok(Command::new(&glslang).arg(&p), &format!("glslangValidator, every {} module in one shader", t.name()));
        }
    }
    // MSL (no Metal compiler here): across all files together, no name is declared twice at
    // the top level. A top-level declaration starts in column 0 with a type and names itself
    // before `(`, ` =`, ` {` or `;`.
    let mut seen: BTreeMap<String, String> = BTreeMap::new();
    for m in translated() {
        let src = text(m, Target::Msl);
        let mut depth = 0i32;
        for line in src.lines() {
            if depth == 0 && !line.is_empty() && !line.starts_with([' ', '#', '/', '}', ')', ',']) && !line.starts_with("using ") {
                let end = line.find(['(', '=', '{', ';', '[']).unwrap_or(line.len());
                let name = line[..end].trim_end().rsplit([' ', '*', '&']).next().unwrap().to_string();
                if let Some(other) = seen.insert(name.clone(), m.name.clone()) {
                    panic!("MSL: {name} is declared by both {other} and {}", m.name);
                }
            }
            depth += line.matches('{').count() as i32 - line.matches('}').count() as i32;
        }
    }
    assert!(seen.len() > 200, "{} top-level MSL names", seen.len());
}

#[test]
fn the_kulla_conty_recipes_compile_against_the_include_forms() {
    // docs/recipes: a shader of the user's own that includes three emitted modules (E, E_avg,
    // F_avg) by their paths under generated/ and uses them, compiled as an engine would: Slang
    // resolves the HLSL includes from its search path (entry kulla_conty_ps), glslangValidator
    // the GLSL 450 ones for Vulkan (-V, its mode that processes #include).
    let d = tempfile::tempdir().unwrap();
    for m in translated() {
        for t in [Target::Hlsl, Target::Glsl] {
            let p = d.path().join(t.path(&m.name));
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(p, &m.files[&t]).unwrap();
        }
    }
    let recipes = root().join("docs/recipes");
    if let Some((python, libs)) = slang() {
        run_ok(
            Command::new(&python)
                .arg(root().join("scripts/slang-hlsl-check"))
                .arg("--entry=kulla_conty_ps")
                .arg(&libs)
                .arg(recipes.join("kulla_conty.hlsl"))
                .env("SLANG_INCLUDE", d.path()),
            "Slang, docs/recipes/kulla_conty.hlsl",
        );
    }
    if let Some(glslang) = tool("glslangValidator") {
        let spv = d.path().join("kulla_conty.spv");
        run_ok(
            Command::new(&glslang).arg("-V").arg(format!("-I{}", d.path().display())).arg("-o").arg(&spv).arg(recipes.join("kulla_conty.frag")),
            "glslangValidator -V docs/recipes/kulla_conty.frag",
        );
        if let Some(val) = tool("spirv-val") {
            run_ok(Command::new(&val).arg(&spv), "spirv-val of the Kulla–Conty recipe");
        }
    }
}

#[test]
fn the_godot_recipe_compiles_as_a_compute_shader() {
    // docs/recipes/godot_energy.glsl: a Godot RenderingDevice compute shader including two GLSL
    // 450 modules. Godot takes its `#[compute]` line before handing the rest to glslang, so the
    // check drops that line and compiles the rest for Vulkan as a compute stage.
    let Some(glslang) = tool("glslangValidator") else { return };
    let d = tempfile::tempdir().unwrap();
    for m in translated() {
        let p = d.path().join(Target::Glsl.path(&m.name));
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, &m.files[&Target::Glsl]).unwrap();
    }
    let text = std::fs::read_to_string(root().join("docs/recipes/godot_energy.glsl")).unwrap();
    let body = text.strip_prefix("#[compute]\n").expect("the recipe starts with Godot's section line");
    let src = d.path().join("godot_energy.comp");
    std::fs::write(&src, body).unwrap();
    let spv = d.path().join("godot_energy.spv");
    run_ok(
        Command::new(&glslang).arg("-V").arg("-S").arg("comp").arg(format!("-I{}", d.path().display())).arg("-o").arg(&spv).arg(&src),
        "glslangValidator -V -S comp docs/recipes/godot_energy.glsl",
    );
    if let Some(val) = tool("spirv-val") {
        run_ok(Command::new(&val).arg(&spv), "spirv-val of the Godot recipe");
    }
}

#[test]
fn slang_compiles_every_hlsl_file() {
    // The Slang compiler parses each HLSL file as HLSL, type-checks it and generates SPIR-V from
    // its entry point (scripts/slang-hlsl-check); there is no DXC or FXC on Linux here.
    let Some((python, libs)) = slang() else { return };
    let d = tempfile::tempdir().unwrap();
    let mut files = Vec::new();
    for m in translated() {
        let p = d.path().join(format!("{}.hlsl", m.name));
        std::fs::write(&p, check_source(&m.name, Target::Hlsl, text(m, Target::Hlsl))).unwrap();
        files.push(p);
    }
    run_ok(
        Command::new(&python).arg(root().join("scripts/slang-hlsl-check")).arg(&libs).args(&files),
        "scripts/slang-hlsl-check",
    );
    eprintln!("Slang: {} HLSL files compiled", files.len());
}

#[test]
fn spirv_val_passes_every_module() {
    let Some(val) = tool("spirv-val") else { return };
    let d = tempfile::tempdir().unwrap();
    for m in translated() {
        let p = d.path().join(format!("{}.spv", m.name));
        std::fs::write(&p, &m.files[&Target::Spirv]).unwrap();
        // Vulkan 1.0 environment: SPIR-V 1.0 and Vulkan's rules on top of the core ones.
        run_ok(Command::new(&val).args(["--target-env", "vulkan1.0"]).arg(&p), &format!("spirv-val {}", p.display()));
    }
    eprintln!("spirv-val: {} SPIR-V modules valid", translated().len());
}

#[test]
fn c_headers_compile_together_and_hold_the_wgsl_constants_bit_for_bit() {
    // The system C compiler reads every header (all in one translation unit: no clashes) and a
    // program prints the bits of each f32 constant; C and C++ both compile them warning-free.
    let Some(cc) = tool("cc") else { return };
    let d = tempfile::tempdir().unwrap();
    let mut main = String::from("#include <stdio.h>\n#include <string.h>\n");
    let mut body = String::new();
    let mut want: BTreeMap<String, Vec<f32>> = BTreeMap::new();
    for m in translated() {
        std::fs::write(d.path().join(format!("{}.h", m.name)), &m.files[&Target::C]).unwrap();
        main.push_str(&format!("#include \"{}.h\"\n", m.name));
        let f32s = f32_constants(m);
        for f in named_constants(&m.ir).into_iter().flatten() {
            if f32s.iter().any(|(n, _)| *n == f.name) {
                body.push_str(&format!("    dump(\"{0}\", &{0}, sizeof {0});\n", f.name));
            } else {
                body.push_str(&format!("    (void){};\n", f.name));
            }
        }
        want.extend(f32s);
    }
    main.push_str(
        "static void dump(const char *name, const void *p, size_t n) {\n    const unsigned char *b = p;\n    \
         printf(\"%s\", name);\n    for (size_t i = 0; i < n; i += 4) {\n        unsigned int u;\n        \
         memcpy(&u, b + i, 4);\n        printf(\" %08x\", u);\n    }\n    printf(\"\\n\");\n}\n\nint main(void) {\n",
    );
    main.push_str(&body);
    main.push_str("    return 0;\n}\n");
    std::fs::write(d.path().join("main.c"), &main).unwrap();
    let exe = d.path().join("dump");
    run_ok(
        Command::new(&cc).args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-o"]).arg(&exe).arg(d.path().join("main.c")),
        "cc main.c",
    );
    let o = Command::new(&exe).output().unwrap();
    assert!(o.status.success());
    let out = String::from_utf8(o.stdout).unwrap();
    let mut seen = 0;
    for line in out.lines() {
        let mut parts = line.split(' ');
        let name = parts.next().unwrap();
        let got: Vec<f32> = parts.map(|h| f32::from_bits(u32::from_str_radix(h, 16).unwrap())).collect();
        assert!(same_bits(&got, &want[name]), "{name}: the C compiler's values differ from the WGSL's");
        seen += 1;
    }
    assert_eq!(seen, want.len(), "every f32 constant printed");
    if let Some(cxx) = tool("c++") {
        std::fs::write(d.path().join("all.cpp"), main.replace("const unsigned char *b = p;", "const unsigned char *b = static_cast<const unsigned char *>(p);")).unwrap();
        run_ok(
            Command::new(&cxx).args(["-std=c++11", "-Wall", "-Wextra", "-Werror", "-fsyntax-only"]).arg(d.path().join("all.cpp")),
            "c++ all.cpp",
        );
    }
}

fn write_targets_names() -> String {
    Target::ALL.iter().map(|t| t.name()).collect::<Vec<_>>().join(",")
}

/// What a build wrote under the target folders of a scratch project.
fn target_files(d: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    snapshot(&d.join("generated")).into_iter().filter(|(p, _)| Target::ALL[1..].iter().any(|t| p.starts_with(t.name()))).collect()
}

#[test]
fn build_target_writes_every_target_identically_at_any_thread_count_and_check_holds() {
    let all = write_targets_names();
    let run = |threads: &str| {
        let d = scratch();
        let o = Command::new(env!("CARGO_BIN_EXE_shadefit"))
            .args(["build", "--only", "gloss_length,gloss_table", "--target", &all])
            .current_dir(d.path())
            .env("RAYON_NUM_THREADS", threads)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
        (target_files(d.path()), d)
    };
    let (one, d) = run("1");
    // Two modules in each target but the module one, and the WESL package's wesl.toml.
    assert_eq!(one.len(), 2 * (Target::ALL.len() - 1) + 1, "{:?}", one.iter().map(|f| &f.0).collect::<Vec<_>>());
    assert!(one.iter().any(|f| f.0 == Path::new("wesl/wesl.toml")));
    assert_eq!(one, run("2").0, "RAYON_NUM_THREADS=1 and =2 must give the same bytes");
    // The same targets are up to date; without --target they are not looked at.
    let o = shadefit(&["build", "--check", "--only", "gloss_length,gloss_table", "--target", &all], Some(d.path()));
    assert!(o.status.success(), "{}{}", String::from_utf8_lossy(&o.stdout), stderr(&o));
    let o = shadefit(&["build", "--check", "--only", "gloss_length,gloss_table"], Some(d.path()));
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn build_check_with_a_target_reports_its_missing_files() {
    let d = scratch();
    copy_dir(&root().join("generated"), &d.path().join("generated"));
    copy_dir(&root().join("fits/scenes"), &d.path().join("fits/scenes"));
    let before = snapshot(&d.path().join("generated"));
    let o = shadefit(&["build", "--check", "--target", "hlsl"], Some(d.path()));
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    let stale = out.lines().filter(|l| l.starts_with("stale: hlsl/")).count();
    assert_eq!(stale, modules().len(), "one HLSL file per module (specs and scenes):\n{out}");
    assert!(!out.contains("stale: wgsl/"), "{out}");
    assert_eq!(before, snapshot(&d.path().join("generated")), "--check writes nothing");
}

#[test]
fn spec_targets_are_emitted_and_checked() {
    let d = scratch();
    let p = d.path().join("fits/gloss_table.toml");
    let spec = std::fs::read_to_string(&p).unwrap();
    assert!(spec.contains("[emit]"));
    std::fs::write(&p, spec.replace("[emit]\n", "[emit]\ntargets = [\"spirv\", \"c\"]\n")).unwrap();
    let o = shadefit(&["build", "--only", "gloss_table"], Some(d.path()));
    assert!(o.status.success(), "{}", stderr(&o));
    let names: Vec<PathBuf> = target_files(d.path()).into_iter().map(|f| f.0).collect();
    assert_eq!(names, [PathBuf::from("c/gloss_table.h"), PathBuf::from("spirv/gloss_table.spv")]);

    // An unknown name is bad input: exit 2, naming the file, the line and the field.
    std::fs::write(&p, spec.replace("[emit]\n", "[emit]\ntargets = [\"dxil\"]\n")).unwrap();
    let o = shadefit(&["build", "--only", "gloss_table"], Some(d.path()));
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let e = stderr(&o);
    let line = spec.lines().position(|l| l == "[emit]").unwrap() + 2;
    assert!(e.contains("gloss_table.toml") && e.contains(&format!(":{line}")) && e.contains("targets") && e.contains("dxil"), "{e}");
    // And on the command line too (clap's usage error).
    let o = shadefit(&["build", "--check", "--target", "dxil"], Some(d.path()));
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

/// The GLSL and SPIR-V files among `files` through glslangValidator and spirv-val (when
/// installed), each also equal to `translate` of the module's WGSL as written beside it.
fn validate_written(d: &Path, files: &[PathBuf]) {
    let (glslang, val) = (tool("glslangValidator"), tool("spirv-val"));
    let scratch = tempfile::tempdir().unwrap();
    for f in files {
        let module = f.file_stem().unwrap().to_str().unwrap();
        let target = Target::from_name(f.iter().next().unwrap().to_str().unwrap()).unwrap();
        let wgsl = std::fs::read_to_string(d.join("generated/wgsl").join(format!("{module}.wgsl"))).unwrap();
        let bytes = std::fs::read(d.join("generated").join(f)).unwrap();
        let again = translate(module, &wgsl, &[target]).unwrap();
        assert_eq!(again.iter().find(|a| a.path == *f).map(|a| &a.contents), Some(&bytes), "{}: the translation of the WGSL beside it", f.display());
        match (target, &glslang, &val) {
            (Target::Glsl | Target::GlslEs, Some(g), _) => {
                let p = scratch.path().join(format!("{module}.{}.frag", target.name()));
                std::fs::write(&p, check_source(module, target, std::str::from_utf8(&bytes).unwrap())).unwrap();
                run_ok(Command::new(g).arg(&p), &format!("glslangValidator {}", f.display()));
            }
            (Target::Spirv, _, Some(v)) => {
                let p = scratch.path().join(format!("{module}.spv"));
                std::fs::write(&p, &bytes).unwrap();
                run_ok(Command::new(v).args(["--target-env", "vulkan1.0"]).arg(&p), &format!("spirv-val {}", f.display()));
            }
            _ => {}
        }
    }
}

#[test]
fn a_lut_kind_takes_emit_targets() {
    // ggx_dfg_lut (kind = "ggx-dfg-lut"): functions taking a texture and a sampler.
    let d = scratch();
    let p = d.path().join("fits/ggx_dfg_lut.toml");
    let spec = std::fs::read_to_string(&p).unwrap();
    std::fs::write(&p, spec.replace("[emit]\n", "[emit]\ntargets = [\"glsl\", \"glsl-es\", \"spirv\", \"hlsl\"]\n")).unwrap();
    let o = shadefit(&["build", "--only", "ggx_dfg_lut"], Some(d.path()));
    assert!(o.status.success(), "{}", stderr(&o));
    let names: Vec<PathBuf> = target_files(d.path()).into_iter().map(|f| f.0).collect();
    assert_eq!(names, ["glsl/ggx_dfg_lut.glsl", "glsl-es/ggx_dfg_lut.glsl", "hlsl/ggx_dfg_lut.hlsl", "spirv/ggx_dfg_lut.spv"].map(PathBuf::from));
    validate_written(d.path(), &names);
    let o = shadefit(&["build", "--check", "--only", "ggx_dfg_lut"], Some(d.path()));
    assert!(o.status.success(), "{}", stderr(&o));

    // An unknown name in a family kind's spec is bad input too (exit 2, file, line, field).
    std::fs::write(&p, spec.replace("[emit]\n", "[emit]\ntargets = [\"dxil\"]\n")).unwrap();
    let o = shadefit(&["build", "--only", "ggx_dfg_lut"], Some(d.path()));
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let e = stderr(&o);
    let line = spec.lines().position(|l| l == "[emit]").unwrap() + 2;
    assert!(e.contains(&format!("ggx_dfg_lut.toml:{line}")) && e.contains("targets") && e.contains("dxil"), "{e}");
}

#[test]
fn build_scene_takes_targets() {
    // A scene over the committed outputs: its module and the node modules it reaches (the skin
    // LUTs, with textures and samplers) in GLSL and SPIR-V, rebuilt or not.
    let d = scratch();
    copy_dir(&root().join("generated"), &d.path().join("generated"));
    copy_dir(&root().join("fits/scenes"), &d.path().join("fits/scenes"));
    let o = shadefit(&["build", "--scene", "fits/scenes/skin_character.toml", "--target", "glsl,spirv"], Some(d.path()));
    assert!(o.status.success(), "{}", stderr(&o));
    let names: Vec<PathBuf> = target_files(d.path()).into_iter().map(|f| f.0).collect();
    for m in ["scene_skin_character", "skin_punctual_lut", "skin_sh_lut"] {
        for f in [format!("glsl/{m}.glsl"), format!("spirv/{m}.spv")] {
            assert!(names.contains(&PathBuf::from(&f)), "{f} in {names:?}");
        }
    }
    validate_written(d.path(), &names);
    // The scene is up to date: a second run writes nothing, the targets included.
    let o = shadefit(&["build", "--scene", "fits/scenes/skin_character.toml", "--target", "glsl,spirv"], Some(d.path()));
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("0 file(s) written"), "{}", String::from_utf8_lossy(&o.stdout));
}
