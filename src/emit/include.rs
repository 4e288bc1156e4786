//! The include form of naga's HLSL, GLSL and MSL: a module's file holds only what an engine
//! includes (its own functions and constants, naga's helpers renamed after the module), and the
//! harness that calls every function (the entry point and its bindings) sits behind
//! `#ifdef SHADEFIT_KEEP_ALL`, where the compiler checks find it and an including shader does
//! not. Every module can then be included beside every other in one shader.
//!
//! naga writes a module as top-level items (a declaration, a `struct`, a function), one after
//! another, separated by blank lines; its helpers (HLSL's `ret_ConstructarrayN_float_` typedefs
//! and constructors, MSL's `type_N` array wrappers, `naga_mod`, …) are named after a type or an
//! operation, and MSL's `type_N` after the type's index in one module, so two modules' helpers
//! of one name need not be the same. Each item is classified by the name it declares:
//! - owned: a function, constant or struct of the WGSL module (naga may append `_` to a name
//!   ending in a digit or one that is a keyword of the language);
//! - harness: the entry point (`main` in GLSL) and its texture and sampler globals;
//! - preamble: a preprocessor line, `using …;`, `precision …;`;
//! - helper: anything else naga wrote. A helper nothing reads is dropped (the constructors the
//!   HLSL brace initialisers no longer call); the others are renamed `MODULE_name` everywhere.
//!
//! GLSL's harness becomes a function `MODULE_keep_all` (a shader has one `main`), and the
//! `#version` line goes: the including shader declares its version first.

use std::collections::{BTreeMap, BTreeSet};

/// The shading languages with an include form.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Lang {
    Hlsl,
    Glsl,
    Msl,
}

/// The macro that turns the harness on.
pub const KEEP_ALL_MACRO: &str = "SHADEFIT_KEEP_ALL";

/// naga's translation of one module, split.
#[derive(Debug, Clone, PartialEq)]
pub struct Included {
    /// GLSL's `#version` line (empty for the other languages): a standalone check puts it first.
    pub version: String,
    /// The preamble lines (MSL's `#include <metal_stdlib>`, `using metal::uint;`, GLSL ES's
    /// precision statements), then the helpers and the module's own items.
    pub body: String,
    /// The entry point's globals and the entry point (in GLSL a function `MODULE_keep_all`).
    pub harness: String,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Preamble,
    Owned,
    Harness,
    Helper,
}

struct Item {
    text: String,
    name: String,
    kind: Kind,
}

/// A line of its own at the top level: a preprocessor line, a comment (MSL's `// language:`),
/// `using …;` or `precision …;`.
fn is_preamble(t: &str) -> bool {
    t.starts_with('#') || t.starts_with("//") || t.starts_with("using ") || t.starts_with("precision ")
}

fn is_ident(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// The last identifier of `s`.
fn last_ident(s: &str) -> &str {
    let s = s.trim_end();
    let start = s.char_indices().rev().find(|&(_, c)| !is_ident(c)).map_or(0, |(i, c)| i + c.len_utf8());
    &s[start..]
}

/// The name a top-level item declares.
fn declared_name(text: &str) -> String {
    let first = text.lines().next().unwrap_or_default().trim();
    if let Some(rest) = first.strip_prefix("struct ") {
        return rest.split(|c: char| !is_ident(c)).next().unwrap_or_default().to_string();
    }
    if first.starts_with("typedef ") {
        let end = first.find(['[', ';']).unwrap_or(first.len());
        return last_ident(&first[..end]).to_string();
    }
    let single = text.trim_end().ends_with(';') && !text.contains('{') || text.lines().count() == 1;
    if single {
        // A declaration: the identifier before its initialiser, array size, register or end.
        let end = [" = ", " : ", "[", ";"].iter().filter_map(|d| first.find(d)).min().unwrap_or(first.len());
        return last_ident(&first[..end]).to_string();
    }
    match first.find('(') {
        Some(k) => last_ident(&first[..k]).to_string(),
        None => last_ident(first).to_string(),
    }
}

/// Top-level items of naga's output: blank lines at depth 0 separate them, and an item ends
/// where its braces close on a line ending in `}` or `;`.
fn items(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut depth: i64 = 0;
    for line in code.lines() {
        let t = line.trim();
        if depth == 0 && cur.is_empty() {
            if t.is_empty() {
                continue;
            }
            if is_preamble(t) {
                out.push(format!("{line}\n"));
                continue;
            }
        }
        cur.push_str(line);
        cur.push('\n');
        for c in line.chars() {
            match c {
                '{' => depth += 1,
                '}' => depth -= 1,
                _ => {}
            }
        }
        if depth == 0 && (t.ends_with('}') || t.ends_with(';')) {
            out.push(std::mem::take(&mut cur));
        }
    }
    if !cur.trim().is_empty() {
        out.push(cur);
    }
    out
}

/// The byte ranges of the identifiers of `text`: a letter or `_`, then letters, digits or `_`;
/// nothing inside a number (a token starting with a digit: `10.3e-5`, `2u`) counts.
fn ident_spans(text: &str) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start: Option<usize> = None;
    let mut number = false;
    for (i, c) in text.char_indices().chain(std::iter::once((text.len(), ' '))) {
        if number && (is_ident(c) || c == '.') {
            continue;
        }
        if is_ident(c) && (start.is_some() || !c.is_ascii_digit()) {
            start.get_or_insert(i);
            number = false;
        } else {
            if let Some(s) = start.take() {
                out.push((s, i));
            }
            number = c.is_ascii_digit();
        }
    }
    out
}

/// Every identifier of `text` in `map` replaced by its value.
fn rename(text: &str, map: &BTreeMap<String, String>) -> String {
    let mut out = String::with_capacity(text.len());
    let mut at = 0;
    for (s, e) in ident_spans(text) {
        out.push_str(&text[at..s]);
        out.push_str(map.get(&text[s..e]).map_or(&text[s..e], |r| r.as_str()));
        at = e;
    }
    out.push_str(&text[at..]);
    out
}

/// The identifiers of `text`.
fn idents(text: &str) -> BTreeSet<&str> {
    ident_spans(text).into_iter().map(|(s, e)| &text[s..e]).collect()
}

/// A name for helper `name` of `module`: the module's prefix, without a doubled underscore
/// (GLSL reserves names holding `__`).
fn helper_name(module: &str, name: &str) -> String {
    let mut s = format!("{module}_{}", name.trim_start_matches('_'));
    while s.contains("__") {
        s = s.replace("__", "_");
    }
    s
}

/// naga's `code` for `module` in `lang`, split into its include form and its harness. `owned`
/// names the module's functions, constants and structs; `entry` is the harness entry point's
/// name (`main` in GLSL).
pub fn split(module: &str, lang: Lang, code: &str, owned: &BTreeSet<String>, entry: &str) -> Result<Included, String> {
    let is_owned = |n: &str| owned.contains(n) || n.strip_suffix('_').is_some_and(|b| owned.contains(b));
    let mut version = String::new();
    let mut list: Vec<Item> = Vec::new();
    for text in items(code) {
        let t = text.trim_start();
        if lang == Lang::Glsl && t.starts_with("#version") {
            version = text.clone();
            continue;
        }
        let preamble = is_preamble(t);
        let name = if preamble { String::new() } else { declared_name(&text) };
        let kind = if preamble {
            Kind::Preamble
        } else if name == entry || name.contains("_keep_binding_") || (lang == Lang::Glsl && t.starts_with("uniform ")) {
            Kind::Harness
        } else if is_owned(&name) {
            Kind::Owned
        } else if name.is_empty() || name.starts_with(|c: char| c.is_ascii_digit()) {
            return Err(format!("{module}: an item of naga's output declares no name:\n{text}"));
        } else {
            Kind::Helper
        };
        list.push(Item { text, name, kind });
    }
    if !list.iter().any(|i| i.name == entry) {
        return Err(format!("{module}: naga's output has no entry point {entry}"));
    }
    // Drop helpers nothing else reads, until none is left (each item's identifiers read once).
    let mut reads: Vec<BTreeSet<String>> = list.iter().map(|i| idents(&i.text).into_iter().map(str::to_string).collect()).collect();
    loop {
        let unused = (0..list.len())
            .find(|&k| list[k].kind == Kind::Helper && !reads.iter().enumerate().any(|(j, r)| j != k && r.contains(&list[k].name)));
        match unused {
            Some(k) => {
                list.remove(k);
                reads.remove(k);
            }
            None => break,
        }
    }
    let mut map: BTreeMap<String, String> = BTreeMap::new();
    for i in &list {
        match i.kind {
            Kind::Helper => {
                map.insert(i.name.clone(), helper_name(module, &i.name));
            }
            Kind::Harness if lang == Lang::Glsl => {
                let renamed = if i.name == entry { format!("{module}_keep_all") } else { helper_name(module, &i.name) };
                map.insert(i.name.clone(), renamed);
            }
            _ => {}
        }
    }
    let mut seen = BTreeSet::new();
    for i in &list {
        let n = map.get(&i.name).unwrap_or(&i.name);
        if i.kind != Kind::Preamble && !seen.insert(n.clone()) {
            return Err(format!("{module}: two items of naga's output declare {n}"));
        }
    }
    // Items one blank line apart; consecutive preamble lines together.
    let join = |pick: &dyn Fn(Kind) -> bool| -> String {
        let mut s = String::new();
        let mut prev: Option<Kind> = None;
        for i in list.iter().filter(|i| pick(i.kind)) {
            if prev.is_some() && !(i.kind == Kind::Preamble && prev == Some(Kind::Preamble)) {
                s.push('\n');
            }
            s.push_str(&rename(&i.text, &map));
            prev = Some(i.kind);
        }
        s
    };
    Ok(Included {
        version,
        body: join(&|k| k != Kind::Harness),
        harness: join(&|k| k == Kind::Harness),
    })
}

/// The include guard macro of `module` in a language's file (`SHADEFIT_GGX_DFG_LUT_HLSL`).
pub fn guard(module: &str, ext: &str) -> String {
    format!("SHADEFIT_{}_{}", module.to_ascii_uppercase(), ext.to_ascii_uppercase())
}

/// The file's text after its header: an include guard around the body and, behind
/// [`KEEP_ALL_MACRO`], the harness.
pub fn file_text(module: &str, ext: &str, inc: &Included) -> String {
    let g = guard(module, ext);
    format!(
        "#ifndef {g}\n#define {g}\n\n{}\n// The harness the compiler checks build (define {KEEP_ALL_MACRO} before including): every\n// function above called once; an including shader leaves it out.\n#ifdef {KEEP_ALL_MACRO}\n{}#endif // {KEEP_ALL_MACRO}\n\n#endif // {g}\n",
        inc.body, inc.harness
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn owned(names: &[&str]) -> BTreeSet<String> {
        names.iter().map(|s| s.to_string()).collect()
    }

    // A shape of naga's HLSL written by hand: a used and an unused constructor helper, a
    // constant, two functions, the entry point and a binding.
    const HLSL: &str = "typedef float ret_Constructarray2_float_[2];\n\
        ret_Constructarray2_float_ Constructarray2_float_(float arg0, float arg1) {\n    float ret[2] = { arg0, arg1 };\n    return ret;\n}\n\n\
        typedef float ret_Constructarray3_float_[3];\n\
        ret_Constructarray3_float_ Constructarray3_float_(float arg0, float arg1, float arg2) {\n    float ret[3] = { arg0, arg1, arg2 };\n    return ret;\n}\n\n\
        static const float M_A[3] = {1.0, 2.0, 3.0};\n\
        Texture2D<float4> m_keep_binding_0 : register(t0);\n\n\
        float m_f(float x)\n{\n    float a[2] = Constructarray2_float_(x, x);\n    return a[0];\n}\n\n\
        float m_g2(float x)\n{\n    return m_f(x);\n}\n\n\
        void m_keep_all()\n{\n    const float _e1 = m_f(0.0);\n    return;\n}\n";

    #[test]
    fn hlsl_helpers_are_renamed_the_unused_dropped_and_the_harness_split_off() {
        let inc = split("m", Lang::Hlsl, HLSL, &owned(&["M_A", "m_f", "m_g2"]), "m_keep_all").unwrap();
        assert!(!inc.body.contains("Constructarray3"), "unused constructor and its typedef dropped:\n{}", inc.body);
        assert!(inc.body.contains("typedef float m_ret_Constructarray2_float_[2];"), "{}", inc.body);
        assert!(inc.body.contains("m_ret_Constructarray2_float_ m_Constructarray2_float_(float arg0"), "{}", inc.body);
        assert!(inc.body.contains("float a[2] = m_Constructarray2_float_(x, x);"), "{}", inc.body);
        assert!(inc.body.contains("float m_g2(float x)"), "owned names kept");
        assert!(!inc.body.contains("keep"), "{}", inc.body);
        assert!(inc.harness.contains("Texture2D<float4> m_keep_binding_0") && inc.harness.contains("void m_keep_all()"));
        assert_eq!(inc.version, "");
        // A comment line at the top level (MSL's `// language: metal1.0`) is kept as it is.
        let msl = "// language: metal1.0\n#include <metal_stdlib>\n\nusing metal::uint;\n\nfloat m_f(\n    float x\n) {\n    return x * 10.5;\n}\n\nfragment void m_keep_all(\n) {\n    return;\n}\n";
        let inc = split("m", Lang::Msl, msl, &owned(&["m_f"]), "m_keep_all").unwrap();
        assert!(inc.body.starts_with("// language: metal1.0\n#include <metal_stdlib>\nusing metal::uint;\n\nfloat m_f("), "{}", inc.body);
        assert!(inc.body.contains("x * 10.5;"), "{}", inc.body);
    }

    #[test]
    fn glsl_loses_its_version_and_main_becomes_a_function() {
        let code = "#version 300 es\n\nprecision highp float;\nprecision highp int;\n\nconst float M_A = 1.0;\n\n\
            uniform highp sampler2D _group_0_binding_0_fs;\n\n\
            float m_f(float x) {\n    return x;\n}\n\nvoid main() {\n    float _e1 = m_f(0.0);\n    return;\n}\n";
        let inc = split("m", Lang::Glsl, code, &owned(&["M_A", "m_f"]), "main").unwrap();
        assert_eq!(inc.version, "#version 300 es\n");
        assert!(inc.body.starts_with("precision highp float;\nprecision highp int;\n\nconst float M_A"), "{}", inc.body);
        assert!(inc.harness.contains("uniform highp sampler2D m_group_0_binding_0_fs;"), "{}", inc.harness);
        assert!(inc.harness.contains("void m_keep_all() {"), "{}", inc.harness);
        assert!(!inc.body.contains("main") && !inc.body.contains("#version"));
    }

    #[test]
    fn a_missing_entry_point_or_a_nameless_item_is_an_error() {
        assert!(split("m", Lang::Hlsl, "float m_f(float x)\n{\n    return x;\n}\n", &owned(&["m_f"]), "m_keep_all").is_err());
        assert!(split("m", Lang::Hlsl, "{\n}\n\nvoid m_keep_all()\n{\n}\n", &owned(&[]), "m_keep_all").is_err());
    }

    #[test]
    fn renaming_touches_whole_identifiers_only() {
        let map: BTreeMap<String, String> = [("type_1".to_string(), "m_type_1".to_string())].into();
        assert_eq!(rename("type_1 x; type_12 y; my_type_1 z; type_1.inner", &map), "m_type_1 x; type_12 y; my_type_1 z; m_type_1.inner");
        // Digits inside a number never start a name: `10.3`, `1e-5`, `2u` stay as they are.
        let digits: BTreeMap<String, String> = [("0".to_string(), "X".to_string()), ("u".to_string(), "X".to_string()), ("e".to_string(), "X".to_string())].into();
        assert_eq!(rename("10.309364 + 1e-5 * 2u", &digits), "10.309364 + 1e-5 * 2u");
        assert_eq!(idents("a1 + 10.3e5 * b_2u"), ["a1", "b_2u"].into());
        assert_eq!(helper_name("m", "_modf_result_f32_"), "m_modf_result_f32_");
        assert_eq!(declared_name("constant type_2 M_NUM = type_2 {{1.0}};\n"), "M_NUM");
        assert_eq!(declared_name("metal::float2 m_uv(\n    float x\n) {\n}\n"), "m_uv");
    }
}
