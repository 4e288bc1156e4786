//! Names a spec gives to emitted things: the spec name (a module and file stem in the runtime
//! crate), function names and argument names. They must be identifiers in every language the
//! files are emitted in, and must not collide with the runtime crate's own files.
//!
//! Keyword lists: the Rust Reference, "Keywords" (strict, reserved and weak keywords of the 2024
//! edition); the WGSL specification (W3C), §15.1 "Keyword Summary" and §15.2 "Reserved Words".

/// Rust keywords (strict and reserved, 2024 edition) and the weak ones that cannot name items.
const RUST: &[&str] = &[
    "as", "async", "await", "break", "const", "continue", "crate", "dyn", "else", "enum", "extern", "false", "fn", "for",
    "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut", "pub", "ref", "return", "self", "static", "struct",
    "super", "trait", "true", "type", "unsafe", "use", "where", "while", "abstract", "become", "box", "do", "final",
    "gen", "macro", "override", "priv", "try", "typeof", "unsized", "virtual", "yield", "union",
];

/// WGSL keywords and reserved words.
const WGSL: &[&str] = &[
    "alias", "break", "case", "const", "const_assert", "continue", "continuing", "default", "diagnostic", "discard",
    "else", "enable", "false", "fn", "for", "if", "let", "loop", "override", "requires", "return", "struct", "switch",
    "true", "var", "while", "NULL", "Self", "abstract", "active", "alignas", "alignof", "as", "asm", "asm_fragment",
    "async", "attribute", "auto", "await", "become", "cast", "catch", "class", "co_await", "co_return", "co_yield",
    "coherent", "column_major", "common", "compile", "compile_fragment", "concept", "const_cast", "consteval",
    "constexpr", "constinit", "crate", "debugger", "decltype", "delete", "demote", "demote_to_helper", "do",
    "dynamic_cast", "enum", "explicit", "export", "extends", "extern", "external", "fallthrough", "filter", "final",
    "finally", "friend", "from", "fxgroup", "get", "goto", "groupshared", "highp", "impl", "implements", "import",
    "inline", "instanceof", "interface", "layout", "lowp", "macro", "macro_rules", "match", "mediump", "meta", "mod",
    "module", "move", "mut", "mutable", "namespace", "new", "nil", "noexcept", "noinline", "nointerpolation",
    "non_coherent", "noncoherent", "noperspective", "null", "nullptr", "of", "operator", "package", "packoffset",
    "partition", "pass", "patch", "pixelfragment", "precise", "precision", "premerge", "priv", "protected", "pub",
    "public", "readonly", "ref", "regardless", "register", "reinterpret_cast", "require", "resource", "restrict",
    "self", "set", "shared", "sizeof", "smooth", "snorm", "static", "static_assert", "static_cast", "std", "subroutine",
    "super", "target", "template", "this", "thread_local", "throw", "trait", "try", "type", "typedef", "typeid",
    "typename", "typeof", "union", "unless", "unorm", "unsafe", "unsized", "use", "using", "varying", "virtual",
    "volatile", "wgsl", "where", "with", "writeonly", "yield",
];

/// WGSL built-ins (functions and predeclared types) that emitted code calls or names: a
/// module, function, argument, constant or binding of the same name would shadow it in the
/// bodies (`args = ["min"]`: the table body's `min(u32(t0), 254u)` then calls the argument).
/// Names the bodies do not use (`length`, `dot`…) stay free. Kept true by the test
/// `every_builtin_the_emitted_modules_use_is_reserved`, which reads every committed module.
const EMITTED_BUILTINS: &[&str] = &[
    "abs", "acos", "array", "atan2", "bitcast", "bool", "clamp", "cos", "exp", "exp2", "f16", "f32", "floor", "fma",
    "fract", "i32", "log", "log2", "mat2x2", "mat3x3", "mat4x4", "max", "min", "mix", "pow", "round", "sampler",
    "saturate", "select", "sign", "sin", "sqrt", "texture_2d", "texture_2d_array", "texture_3d", "trunc", "u32",
    "vec2", "vec2f", "vec3", "vec3f", "vec4", "vec4f",
];

/// WGSL built-ins called only by emitted functions whose every argument the emitter names
/// itself (the polygon- and rectangle-light integrals: `p`, `n`, `v`, `vertices`…): no spec name
/// reaches their bodies, so these stay free for spec arguments (`length` names an axis).
#[cfg(test)]
const FIXED_SIGNATURE_BUILTINS: &[&str] = &["atan", "cross", "dot", "inverseSqrt", "length"];

/// The input clamp every emitted WGSL module declares (`fn NAME_input(v, lo, hi)`; its CPU
/// twin in Rust is `input`): each body calls it on each argument.
pub fn input_helper(module: &str) -> String {
    format!("{module}_input")
}

/// Why a spec's function and argument names collide with what its emitted module declares
/// (`None`: they do not), as (field, reason): the function may not be the module's input clamp;
/// an argument may not be the clamp (WGSL's `NAME_input`, Rust's `input`), the function, or a
/// function derived from the function's or the module's name (`FUNCTION_load`, `NAME_uv`…),
/// which the bodies call.
pub fn check_emitted(module: &str, function: &str, args: &[&str]) -> Option<(&'static str, String)> {
    let helper = input_helper(module);
    if function == helper {
        return Some(("function", format!("'{function}' is the input clamp the emitted module declares ({helper})")));
    }
    for a in args {
        if *a == helper || *a == "input" {
            return Some(("args", format!("'{a}' is the input clamp the emitted module declares ({helper} in WGSL, input in Rust)")));
        }
        if *a == function || a.starts_with(&format!("{function}_")) || *a == module || a.starts_with(&format!("{module}_")) {
            return Some(("args", format!("'{a}' is a name the module's functions take ({function}, {function}_…, {module}_…)")));
        }
    }
    None
}

/// Files of the runtime crate (`generated/src/`) that specs must not overwrite: the crate root,
/// the emitted index and the hand-written runtime module.
const RESERVED_MODULES: &[&str] = &["lib", "emitted", "runtime", "main"];

/// Names the runtime crate uses beside the emitted modules, which a spec's module would collide
/// with, read from its hand-written sources (compiled in):
/// - the crate root (`generated/src/lib.rs`): its module `runtime` and what it re-exports from
///   it: a `pub mod` of the same name in the index it includes does not compile (E0255);
/// - the runtime's modules (`generated/src/runtime/mod.rs`) and the hand-written WGSL libraries
///   its `library` resolves (its `"NAME" =>` arms), imported as `shadefit::NAME` like the
///   emitted modules;
/// - the index (`pipeline::runtime_index`): its module `wgsl`, and in it the list `NAMES`, which
///   the constant of a module named `names` (the name upper-cased) would redeclare (E0428).
fn runtime_names() -> &'static [String] {
    static NAMES: std::sync::OnceLock<Vec<String>> = std::sync::OnceLock::new();
    NAMES.get_or_init(|| {
        let runtime = include_str!("../../generated/src/runtime/mod.rs");
        let libraries = runtime.lines().filter_map(|l| l.trim().strip_prefix('"')?.split_once("\" =>").map(|(n, _)| n.to_string()));
        let mut names = declared_names(include_str!("../../generated/src/lib.rs"));
        names.extend(declared_names(runtime));
        names.extend(libraries);
        names.extend(["wgsl", "names"].map(String::from));
        names.sort();
        names.dedup();
        names
    })
}

/// The lowercase names a Rust source declares at its top level: `mod NAME`, and what each
/// `use` brings in (a path's last segment, each item of a one-line `{…}` list, the alias of
/// `as`). Upper-case names (types, constants) cannot be a spec's module name.
pub(crate) fn declared_names(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let lowercase = |n: &str| is_identifier(n).then(|| n.to_string());
    for line in text.lines().map(str::trim).filter(|l| !l.starts_with("//")) {
        let line = line.strip_prefix("pub ").unwrap_or(line);
        if let Some(rest) = line.strip_prefix("mod ") {
            out.extend(lowercase(rest.trim_end_matches([';', '{', ' '])));
        } else if let Some(rest) = line.strip_prefix("use ") {
            let path = rest.trim_end_matches(';');
            let items: Vec<&str> = match path.split_once('{') {
                Some((_, list)) => list.trim_end_matches('}').split(',').collect(),
                None => vec![path.rsplit("::").next().unwrap_or(path)],
            };
            for item in items.iter().map(|i| i.trim()).filter(|i| !i.is_empty()) {
                out.extend(lowercase(item.rsplit(" as ").next().unwrap_or(item).trim()));
            }
        }
    }
    out
}

/// Scene modules are named `scene_MANIFEST`.
pub const SCENE_PREFIX: &str = "scene_";

/// A lowercase identifier: a-z or _, then a-z, 0-9 or _ (not `_` alone).
pub fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    s != "_"
        && matches!(chars.next(), Some(c) if c.is_ascii_lowercase() || c == '_')
        && chars.all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
}

/// Why `s` cannot name an emitted function or argument (`None`: it can).
pub fn check_identifier(s: &str) -> Option<String> {
    if !is_identifier(s) {
        return Some(format!("'{s}' must be a lowercase identifier (a-z, 0-9, _; not '_' alone)"));
    }
    if s.starts_with("__") {
        return Some(format!("'{s}' starts with '__', which WGSL reserves"));
    }
    if RUST.contains(&s) {
        return Some(format!("'{s}' is a Rust keyword"));
    }
    if WGSL.contains(&s) {
        return Some(format!("'{s}' is a WGSL keyword or reserved word"));
    }
    if EMITTED_BUILTINS.contains(&s) {
        return Some(format!("'{s}' is a WGSL built-in that emitted code calls"));
    }
    None
}

/// Locals of the emitted function bodies (clamped inputs x0…, table coordinates t0…, i0…,
/// f0…, evaluator arguments a0…, the table index k, the bilinear rows a, b, the field values c):
/// an argument of the same name would be shadowed or redeclared.
fn emitted_local(s: &str) -> bool {
    matches!(s, "k" | "a" | "b" | "c")
        || (s.len() > 1 && matches!(&s[..1], "x" | "t" | "i" | "f" | "a") && s[1..].chars().all(|c| c.is_ascii_digit()))
}

/// Why `s` cannot name an argument of an emitted function (`None`: it can).
pub fn check_argument(s: &str) -> Option<String> {
    if let Some(why) = check_identifier(s) {
        return Some(why);
    }
    if emitted_local(s) {
        return Some(format!("'{s}' is a local of the emitted function bodies (reserved: k, a, b, c, x0…, t0…, i0…, f0…, a0…)"));
    }
    None
}

/// Why `s` cannot name a spec (its runtime module and files), `None` when it can.
pub fn check_spec_name(s: &str) -> Option<String> {
    if let Some(why) = check_identifier(s) {
        return Some(why);
    }
    if RESERVED_MODULES.contains(&s) {
        return Some(format!("'{s}' is a file of the runtime crate (reserved: {})", RESERVED_MODULES.join(", ")));
    }
    if runtime_names().iter().any(|n| n == s) {
        return Some(format!("'{s}' is a name the runtime crate uses (reserved: {})", runtime_names().join(", ")));
    }
    if s.starts_with(SCENE_PREFIX) {
        return Some(format!("'{s}' starts with '{SCENE_PREFIX}', the prefix of scene modules"));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every lowercase name a committed module calls or names as a type (`name(` or `name<`)
    /// that the module does not declare itself is a WGSL built-in, and must be reserved.
    #[test]
    fn every_builtin_the_emitted_modules_use_is_reserved() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("generated/wgsl");
        let mut seen = 0;
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let text = std::fs::read_to_string(&path).unwrap();
            let code: String = text.lines().filter(|l| !l.trim_start().starts_with("//") && !l.starts_with('#')).collect::<Vec<_>>().join("\n");
            let declared: Vec<&str> = code
                .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .collect::<Vec<_>>()
                .windows(2)
                .filter(|w| matches!(w[0], "fn" | "struct" | "alias"))
                .map(|w| w[1])
                .collect();
            let bytes = code.as_bytes();
            let mut i = 0;
            while i < bytes.len() {
                if bytes[i].is_ascii_alphabetic() || bytes[i] == b'_' {
                    let start = i;
                    while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                        i += 1;
                    }
                    let name = &code[start..i];
                    // A call `name (` or a type `name<` (a comparison `x < y` has spaces).
                    let call = code[i..].trim_start().starts_with('(') || code[i..].starts_with('<');
                    let preceded_by_digit = start > 0 && bytes[start - 1].is_ascii_digit();
                    if call && is_identifier(name) && !declared.contains(&name) && !preceded_by_digit {
                        assert!(
                            EMITTED_BUILTINS.contains(&name) || FIXED_SIGNATURE_BUILTINS.contains(&name) || WGSL.contains(&name),
                            "{} calls or names '{name}', which EMITTED_BUILTINS does not hold",
                            path.display()
                        );
                        seen += 1;
                    }
                } else {
                    i += 1;
                }
            }
        }
        assert!(seen > 100, "{seen} built-in uses: the scan read too little");
    }

    #[test]
    fn emitted_names_may_not_take_the_modules_own() {
        assert!(check_emitted("len_fit", "len_fit_input", &["g"]).is_some_and(|e| e.0 == "function"));
        assert!(check_emitted("len_fit", "f", &["len_fit_input"]).is_some_and(|e| e.0 == "args"));
        assert!(check_emitted("m", "f", &["input"]).is_some());
        assert!(check_emitted("m", "f", &["f_load"]).is_some());
        assert!(check_emitted("m", "f", &["f"]).is_some());
        assert!(check_emitted("len_table", "lut", &["g"]).is_none());
        assert!(check_identifier("min").is_some() && check_identifier("length").is_none());
    }

    #[test]
    fn rejects_keywords_reserved_names_and_collisions() {
        for bad in ["fn", "self", "loop", "_", "let", "var", "override", "struct", "__x", "Fn", "1x", "a-b", ""] {
            assert!(check_identifier(bad).is_some(), "{bad}");
        }
        for bad in ["lib", "emitted", "runtime", "scene_velvet_horse", "fn"] {
            assert!(check_spec_name(bad).is_some(), "{bad}");
        }
        for bad in ["k", "a", "b", "c", "x0", "t1", "i12", "f0", "a3", "fn"] {
            assert!(check_argument(bad).is_some(), "{bad}");
        }
        for good in ["x", "t", "f", "k2x", "x0a", "alpha", "n_dot_v", "schlick_k"] {
            assert_eq!(check_argument(good), None, "{good}");
        }
        for good in ["gloss_length", "x", "_x", "n_dot_v", "alpha2", "scene", "lut2", "skin_lut", "functions"] {
            assert_eq!(check_identifier(good), None, "{good}");
            assert_eq!(check_spec_name(good), None, "{good}");
        }
    }

    #[test]
    fn declared_names_reads_modules_uses_lists_and_aliases() {
        let text = "//! mod doc;\nmod a;\npub mod b {\n#[cfg(x)]\npub use c::d;\nuse e::{f, G, h as i};\npub struct Z;\n";
        assert_eq!(declared_names(text), ["a", "b", "d", "f", "i"]);
    }

    /// Every name the runtime crate's root declares or re-exports (generated/src/lib.rs), every
    /// module of its hand-written runtime (runtime/mod.rs), every hand-written WGSL library it
    /// resolves (the `"NAME" =>` arms of `runtime::library`) and every hand-written file or folder
    /// in generated/src (no `@generated` header) is refused as a spec name: read from the files,
    /// so a name added there and not to the reserved lists fails here.
    #[test]
    fn every_name_the_runtime_crate_uses_is_reserved() {
        let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("generated/src");
        let read = |p: &str| std::fs::read_to_string(src.join(p)).unwrap_or_else(|e| panic!("{p}: {e}"));
        let lib = declared_names(&read("lib.rs"));
        for n in ["runtime", "compose", "gpu", "lut"] {
            assert!(lib.contains(&n.to_string()), "lib.rs is read: {n} in {lib:?}");
        }
        let runtime = read("runtime/mod.rs");
        let libraries: Vec<String> = runtime
            .lines()
            .filter_map(|l| l.trim().strip_prefix('"')?.split_once("\" =>").map(|(n, _)| n.to_string()))
            .collect();
        assert!(!libraries.is_empty(), "runtime::library is read");
        let mut hand_written = Vec::new();
        for e in std::fs::read_dir(&src).unwrap() {
            let p = e.unwrap().path();
            let stem = p.file_stem().unwrap().to_string_lossy().into_owned();
            let generated = p.is_file()
                && std::fs::read_to_string(&p).is_ok_and(|t| t.lines().next().is_some_and(|l| l.contains("@generated by")));
            if !generated {
                hand_written.push(stem);
            }
        }
        assert!(hand_written.contains(&"lib".to_string()) && hand_written.contains(&"runtime".to_string()), "{hand_written:?}");
        for n in lib.iter().chain(&declared_names(&runtime)).chain(&libraries).chain(&hand_written) {
            assert!(check_spec_name(n).is_some(), "'{n}', a name of the runtime crate, is accepted as a spec name");
        }
    }
}
