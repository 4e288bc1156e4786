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

/// Files of the runtime crate (`generated/src/`) that specs must not overwrite: the crate root,
/// the emitted index and the hand-written runtime module.
const RESERVED_MODULES: &[&str] = &["lib", "emitted", "runtime", "main"];

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
    if s.starts_with(SCENE_PREFIX) {
        return Some(format!("'{s}' starts with '{SCENE_PREFIX}', the prefix of scene modules"));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

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
        for good in ["gloss_length", "x", "_x", "n_dot_v", "alpha2", "scene"] {
            assert_eq!(check_identifier(good), None, "{good}");
            assert_eq!(check_spec_name(good), None, "{good}");
        }
    }
}
