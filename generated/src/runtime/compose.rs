//! A minimal WGSL composer for the emitted libraries, accepting naga_oil's import styles.
//!
//! Each emitted library `wgsl/NAME.wgsl` starts with `#define_import_path shadefit::NAME` (the
//! naga_oil / Bevy convention) and defines its names with a family prefix, so that every
//! top-level name of every library is distinct (`real_modules_share_one_namespace` checks it)
//! and the libraries can share one flat WGSL namespace. The composer:
//! - [`compose`]: concatenates the requested libraries (and whatever they import), each once,
//!   dependencies first, with the `#define_import_path` lines removed;
//! - [`compose_shader`] / [`compose_shader_named`]: does the same for the imports of a user's
//!   shader, then appends the shader with its import lines turned into comments and its
//!   module-qualified names (`gloss_length::gloss_to_normal_length`) written plain.
//!
//! Directives, each starting its line (leading whitespace allowed; an optional trailing `;`):
//! - `#define_import_path shadefit::NAME` (dropped);
//! - `#import shadefit::NAME`: the library's names are usable both plain (`combine_gloss`, the
//!   original style of this crate) and qualified (`gloss_combine::combine_gloss`, naga_oil's);
//! - `#import shadefit::NAME as alias`: qualified as `alias::item`;
//! - `#import shadefit::NAME::item` and `#import shadefit::NAME::{a, b as c}`: the items (and
//!   the library) imported, `c` standing for `b`; braces may nest (`shadefit::{x, y::{a}}`)
//!   and span lines.
//!
//! Anywhere in code, `shadefit::NAME::item` is also accepted without an import (naga_oil
//! accepts fully qualified names). An item alias (`b as c`) stands for the item wherever the
//! identifier `c` appears in the importing source, so it should not also name a local, a field
//! or a parameter there. Names after a `.` (members) and inside comments are left alone. Any other `#import` form (another namespace, `*`, `self`), a qualifier that names no
//! imported library, a library that does not exist and an item a library does not declare are
//! errors naming the file and line; other lines are copied unchanged. The result is plain
//! WGSL for `wgpu::ShaderSource::Wgsl` or naga. naga_oil itself composes the same shaders
//! (tests/naga_oil.rs).
//!
//! Names resolve to the emitted libraries (`wgsl::module`) first, then to the hand-written
//! ones of this crate (`runtime::library`: `skin_curvature`).

use std::collections::BTreeMap;
use std::fmt;

/// Why a composition failed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ComposeError {
    /// No emitted module of that name, or its family feature is disabled.
    UnknownModule {
        name: String,
        /// The library or shader whose `#import` (or qualified name) asked for it, and its
        /// line (None: requested directly).
        wanted_by: Option<(String, usize)>,
    },
    /// A library imported, or named in a qualified name, that does not declare `item`.
    UnknownItem { file: String, line: usize, module: String, item: String },
    /// A qualified name `a::b` whose `a` is no imported library (nor `shadefit::NAME::item`).
    NotImported { file: String, line: usize, path: String },
    /// An `#import` line the composer does not understand.
    BadImport { file: String, line: usize, text: String },
    /// Libraries that import each other, as the chain that closes the cycle.
    Cycle(Vec<String>),
}

impl fmt::Display for ComposeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        const WHY: &str = "not emitted, or its family feature is off";
        match self {
            ComposeError::UnknownModule { name, wanted_by: None } => {
                write!(f, "unknown WGSL module `shadefit::{name}` ({WHY})")
            }
            ComposeError::UnknownModule { name, wanted_by: Some((by, line)) } => {
                write!(f, "{by}:{line}: unknown WGSL module `shadefit::{name}` ({WHY})")
            }
            ComposeError::UnknownItem { file, line, module, item } => {
                write!(f, "{file}:{line}: `shadefit::{module}` declares no `{item}`")
            }
            ComposeError::NotImported { file, line, path } => write!(
                f,
                "{file}:{line}: `{path}`: `{}` is no imported module (add `#import shadefit::MODULE`, or write `shadefit::MODULE::item`)",
                path.split("::").next().unwrap_or_default()
            ),
            ComposeError::BadImport { file, line, text } => write!(
                f,
                "{file}:{line}: unsupported import `{}` (expected `#import shadefit::MODULE`, `shadefit::MODULE::item`, `shadefit::MODULE::{{a, b}}`, optionally `as alias`)",
                text.trim()
            ),
            ComposeError::Cycle(chain) => write!(f, "WGSL import cycle: {}", chain.join(" -> ")),
        }
    }
}

impl std::error::Error for ComposeError {}

/// The requested emitted libraries (and their imports), each once, dependencies first, as one
/// WGSL source without preprocessor lines. Order of `names` is kept where dependencies allow;
/// duplicates are ignored.
///
/// ```
/// use shadefit_runtime::{compose, wgsl};
/// let all = compose(wgsl::NAMES).unwrap(); // every library compiled in
/// assert!(!all.contains("#define_import_path"));
/// assert!(compose(&["no_such_module"]).is_err());
/// # if wgsl::module("gloss_length").is_some() {
/// let src = compose(&["gloss_length", "gloss_combine"]).unwrap();
/// assert!(src.contains("fn gloss_to_normal_length(") && src.contains("fn combine_gloss("));
/// # }
/// ```
pub fn compose(names: &[&str]) -> Result<String, ComposeError> {
    compose_with(&module_or_library, names, None)
}

/// An emitted library, else a hand-written one (`runtime::library`, e.g. `skin_curvature`).
fn module_or_library(name: &str) -> Option<&'static str> {
    crate::wgsl::module(name).or_else(|| super::library(name))
}

/// A user shader with its imports resolved: the imported libraries (each once, dependencies
/// first) followed by the shader, whose import lines become comments (so its line count is
/// unchanged) and whose qualified names (`gloss_combine::combine_gloss`) are written plain.
/// Errors name the shader `shader`; [`compose_shader_named`] takes its file name.
///
/// ```
/// # if shadefit_runtime::wgsl::module("gloss_combine").is_some() {
/// // naga_oil's style: the module imported, its functions called through its name.
/// let shader = "#import shadefit::gloss_combine\n\
///               @fragment fn fs() -> @location(0) vec4<f32> { return vec4<f32>(gloss_combine::combine_gloss(0.5, 0.7)); }\n";
/// let src = shadefit_runtime::compose_shader(shader).unwrap();
/// assert!(src.find("fn combine_gloss(").unwrap() < src.find("@fragment").unwrap());
/// assert!(src.contains("vec4<f32>(combine_gloss(0.5, 0.7))"));
/// # }
/// ```
pub fn compose_shader(source: &str) -> Result<String, ComposeError> {
    compose_shader_named("shader", source)
}

/// [`compose_shader`], with errors naming the shader `file` (e.g. its path).
pub fn compose_shader_named(file: &str, source: &str) -> Result<String, ComposeError> {
    compose_with(&module_or_library, &[], Some((file, source)))
}

/// One token of WGSL (comments, whitespace and numbers skipped); byte offsets and line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Tok<'a> {
    Ident(&'a str),
    /// `::`
    Colons,
    Sym(u8),
}

#[derive(Clone, Copy, Debug)]
struct Token<'a> {
    tok: Tok<'a>,
    start: usize,
    end: usize,
    line: usize,
}

/// The identifiers, `::` and punctuation of `src`, without comments (`//`, nested `/* */`) and
/// number literals. Identifier bytes: ASCII letters, digits, `_` and every non-ASCII byte (WGSL
/// identifiers may be Unicode; whole UTF-8 sequences stay together).
fn tokens(src: &str) -> Vec<Token<'_>> {
    let b = src.as_bytes();
    let ident = |c: u8| c.is_ascii_alphanumeric() || c == b'_' || c >= 0x80;
    let (mut i, mut line, mut out) = (0, 1, Vec::new());
    while i < b.len() {
        let c = b[i];
        let next = b.get(i + 1).copied();
        if c == b'\n' {
            line += 1;
            i += 1;
        } else if c.is_ascii_whitespace() {
            i += 1;
        } else if c == b'/' && next == Some(b'/') {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if c == b'/' && next == Some(b'*') {
            let mut depth = 1;
            i += 2;
            while i < b.len() && depth > 0 {
                match (b[i], b.get(i + 1).copied()) {
                    (b'/', Some(b'*')) => (depth, i) = (depth + 1, i + 2),
                    (b'*', Some(b'/')) => (depth, i) = (depth - 1, i + 2),
                    (b'\n', _) => (line, i) = (line + 1, i + 1),
                    _ => i += 1,
                }
            }
        } else if c.is_ascii_digit() || (c == b'.' && next.is_some_and(|n| n.is_ascii_digit())) {
            // A number: digits, letters (suffixes, exponents, hex), `.`, and a sign after an
            // exponent letter.
            i += 1;
            while i < b.len() && (ident(b[i]) || b[i] == b'.' || (matches!(b[i], b'+' | b'-') && matches!(b[i - 1], b'e' | b'E' | b'p' | b'P'))) {
                i += 1;
            }
        } else if ident(c) {
            let start = i;
            while i < b.len() && ident(b[i]) {
                i += 1;
            }
            out.push(Token { tok: Tok::Ident(&src[start..i]), start, end: i, line });
        } else if c == b':' && next == Some(b':') {
            out.push(Token { tok: Tok::Colons, start: i, end: i + 2, line });
            i += 2;
        } else {
            out.push(Token { tok: Tok::Sym(c), start: i, end: i + 1, line });
            i += 1;
        }
    }
    out
}

/// The names a library declares at top level: functions, constants, overrides, structs,
/// aliases and module-scope variables.
fn declared(src: &str) -> Vec<String> {
    let t = tokens(src);
    let (mut depth, mut out) = (0i32, Vec::new());
    let mut i = 0;
    while i < t.len() {
        match t[i].tok {
            Tok::Sym(b'{') => depth += 1,
            Tok::Sym(b'}') => depth -= 1,
            Tok::Ident(k) if depth == 0 && matches!(k, "fn" | "const" | "override" | "struct" | "alias" | "var") => {
                let mut j = i + 1;
                if k == "var" && matches!(t.get(j).map(|t| t.tok), Some(Tok::Sym(b'<'))) {
                    while j < t.len() && t[j].tok != Tok::Sym(b'>') {
                        j += 1;
                    }
                    j += 1;
                }
                if let Some(Token { tok: Tok::Ident(name), .. }) = t.get(j) {
                    out.push(name.to_string());
                }
                i = j;
            }
            _ => {}
        }
        i += 1;
    }
    out
}

fn is_module_name(s: &str) -> bool {
    !s.is_empty()
        && s.bytes().all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'_')
        && !s.as_bytes()[0].is_ascii_digit()
}

fn is_ident(s: &str) -> bool {
    !s.is_empty() && !s.as_bytes()[0].is_ascii_digit() && s.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_') && s != "_"
}

/// One imported path: a library, or one of its items, and the name it is used under.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Import {
    module: String,
    item: Option<String>,
    alias: Option<String>,
}

/// The imports of an `#import` directive's text (after `#import`), naga_oil's grammar:
/// `tree = path ["as" ident] | path "::" "{" tree ("," tree)* [","] "}"`, every path under
/// `shadefit::` and one or two segments below it. None: not of that form.
fn parse_import(text: &str) -> Option<Vec<Import>> {
    fn tree<'a>(t: &[Token<'a>], pos: &mut usize, prefix: &[&'a str], out: &mut Vec<(Vec<&'a str>, Option<&'a str>)>) -> Option<()> {
        match t.get(*pos)?.tok {
            Tok::Sym(b'{') => {
                *pos += 1;
                loop {
                    tree(t, pos, prefix, out)?;
                    match t.get(*pos)?.tok {
                        Tok::Sym(b',') => {
                            *pos += 1;
                            if t.get(*pos)?.tok == Tok::Sym(b'}') {
                                *pos += 1;
                                return Some(());
                            }
                        }
                        Tok::Sym(b'}') => {
                            *pos += 1;
                            return Some(());
                        }
                        _ => return None,
                    }
                }
            }
            Tok::Ident(s) if s != "as" => {
                let path: Vec<&str> = prefix.iter().copied().chain([s]).collect();
                *pos += 1;
                match t.get(*pos).map(|t| t.tok) {
                    Some(Tok::Colons) => {
                        *pos += 1;
                        tree(t, pos, &path, out)
                    }
                    Some(Tok::Ident("as")) => match t.get(*pos + 1)?.tok {
                        Tok::Ident(alias) if is_ident(alias) => {
                            *pos += 2;
                            out.push((path, Some(alias)));
                            Some(())
                        }
                        _ => None,
                    },
                    _ => {
                        out.push((path, None));
                        Some(())
                    }
                }
            }
            _ => None,
        }
    }
    let t = tokens(text);
    let mut pos = 0;
    let mut paths = Vec::new();
    tree(&t, &mut pos, &[], &mut paths)?;
    if t.get(pos).is_some_and(|t| t.tok == Tok::Sym(b';')) {
        pos += 1;
    }
    if pos != t.len() {
        return None;
    }
    paths
        .into_iter()
        .map(|(path, alias)| match path.as_slice() {
            ["shadefit", m] if is_module_name(m) => Some(Import { module: m.to_string(), item: None, alias: alias.map(str::to_string) }),
            ["shadefit", m, item] if is_module_name(m) && is_ident(item) => {
                Some(Import { module: m.to_string(), item: Some(item.to_string()), alias: alias.map(str::to_string) })
            }
            _ => None,
        })
        .collect()
}

/// One preprocessed line of a source.
enum Line<'a> {
    Define,
    /// The first line of an `#import` directive, with what it imports.
    Import(Vec<Import>),
    /// A further line of an `#import` whose braces span lines.
    ImportMore,
    Code(&'a str),
}

fn parse<'a>(file: &str, src: &'a str) -> Result<Vec<Line<'a>>, ComposeError> {
    let lines: Vec<&str> = src.lines().collect();
    let mut out = Vec::with_capacity(lines.len());
    let mut i = 0;
    while i < lines.len() {
        let t = lines[i].trim();
        let directive = |d: &str| t.strip_prefix(d).filter(|rest| rest.is_empty() || rest.starts_with(char::is_whitespace));
        if directive("#define_import_path").is_some() {
            out.push(Line::Define);
            i += 1;
        } else if t.starts_with("#import") {
            let bad = || ComposeError::BadImport { file: file.to_string(), line: i + 1, text: lines[i].to_string() };
            let Some(rest) = directive("#import") else { return Err(bad()) };
            // Braces open at the end of a line continue the directive on the next.
            let mut text = rest.to_string();
            let mut end = i;
            let open = |s: &str| tokens(s).iter().map(|t| (t.tok == Tok::Sym(b'{')) as i32 - (t.tok == Tok::Sym(b'}')) as i32).sum::<i32>();
            while open(&text) > 0 && end + 1 < lines.len() {
                end += 1;
                text.push('\n');
                text.push_str(lines[end]);
            }
            out.push(Line::Import(parse_import(&text).ok_or_else(bad)?));
            out.extend((i..end).map(|_| Line::ImportMore));
            i = end + 1;
        } else {
            out.push(Line::Code(lines[i]));
            i += 1;
        }
    }
    Ok(out)
}

/// How a source refers to what it imported: qualifier -> library, and item aliases.
#[derive(Default)]
struct Scope {
    modules: BTreeMap<String, String>,
    aliases: BTreeMap<String, String>,
}

/// Depth-first post-order walk: every library after everything it imports.
struct Walk<'a, 'l> {
    lookup: &'l dyn Fn(&str) -> Option<&'a str>,
    done: Vec<String>,
    out: String,
    stack: Vec<String>,
    /// The names each library seen so far declares.
    items: BTreeMap<String, Vec<String>>,
}

impl<'a> Walk<'a, '_> {
    /// Visit library `name` (asked for by file `by` at its line) and check that it declares
    /// `item`.
    fn require(&mut self, name: &str, item: Option<&str>, by: Option<(&str, usize)>) -> Result<(), ComposeError> {
        self.visit(name, by)?;
        if let (Some(item), Some((file, line))) = (item, by)
            && !self.items[name].iter().any(|d| d == item)
        {
            return Err(ComposeError::UnknownItem { file: file.to_string(), line, module: name.to_string(), item: item.to_string() });
        }
        Ok(())
    }

    fn visit(&mut self, name: &str, wanted_by: Option<(&str, usize)>) -> Result<(), ComposeError> {
        if self.done.iter().any(|d| d == name) {
            return Ok(());
        }
        if let Some(pos) = self.stack.iter().position(|s| s == name) {
            let mut chain = self.stack[pos..].to_vec();
            chain.push(name.to_string());
            return Err(ComposeError::Cycle(chain));
        }
        let src = (self.lookup)(name).ok_or_else(|| ComposeError::UnknownModule {
            name: name.to_string(),
            wanted_by: wanted_by.map(|(f, l)| (f.to_string(), l)),
        })?;
        self.items.insert(name.to_string(), declared(src));
        let file = format!("shadefit::{name}");
        self.stack.push(name.to_string());
        let lines = parse(&file, src)?;
        let code = self.resolve(&file, &lines)?;
        self.stack.pop();
        self.out.push_str(&format!("// ---- shadefit::{name} ----\n"));
        for (l, c) in lines.iter().zip(code.split('\n')) {
            if let Line::Code(_) = l {
                self.out.push_str(c);
                self.out.push('\n');
            }
        }
        self.out.push('\n');
        self.done.push(name.to_string());
        Ok(())
    }

    /// Visit what `lines` import and return their code (one line per line, directives empty)
    /// with qualified names written plain.
    fn resolve(&mut self, file: &str, lines: &[Line<'_>]) -> Result<String, ComposeError> {
        let mut scope = Scope::default();
        for (i, l) in lines.iter().enumerate() {
            let Line::Import(imports) = l else { continue };
            for im in imports {
                self.require(&im.module, im.item.as_deref(), Some((file, i + 1)))?;
                match (&im.item, &im.alias) {
                    (None, alias) => {
                        scope.modules.insert(alias.clone().unwrap_or_else(|| im.module.clone()), im.module.clone());
                    }
                    (Some(item), Some(alias)) if alias != item => {
                        scope.aliases.insert(alias.clone(), item.clone());
                    }
                    _ => {}
                }
            }
        }
        let code: Vec<&str> = lines.iter().map(|l| if let Line::Code(c) = l { *c } else { "" }).collect();
        self.rewrite(file, &code.join("\n"), &scope)
    }

    /// `code` with every qualified name (`q::item`, `shadefit::NAME::item`) and item alias
    /// replaced by the item's own name; line breaks kept.
    fn rewrite(&mut self, file: &str, code: &str, scope: &Scope) -> Result<String, ComposeError> {
        let t = tokens(code);
        let (mut out, mut copied, mut i) = (String::with_capacity(code.len()), 0, 0);
        while i < t.len() {
            let Tok::Ident(first) = t[i].tok else {
                i += 1;
                continue;
            };
            let mut segs = vec![first];
            let mut j = i + 1;
            while let (Some(Tok::Colons), Some(Tok::Ident(s))) = (t.get(j).map(|t| t.tok), t.get(j + 1).map(|t| t.tok)) {
                segs.push(s);
                j += 2;
            }
            let line = t[i].line;
            let member = i > 0 && t[i - 1].tok == Tok::Sym(b'.');
            let plain = match segs.as_slice() {
                [one] if !member => scope.aliases.get(*one).cloned(),
                [_] => None,
                ["shadefit", m, item] if is_module_name(m) => {
                    self.require(m, Some(*item), Some((file, line)))?;
                    Some(item.to_string())
                }
                [q, item] if scope.modules.contains_key(*q) => {
                    let m = scope.modules[*q].clone();
                    self.require(&m, Some(*item), Some((file, line)))?;
                    Some(item.to_string())
                }
                _ => return Err(ComposeError::NotImported { file: file.to_string(), line, path: segs.join("::") }),
            };
            if let Some(p) = plain {
                let (start, end) = (t[i].start, t[j - 1].end);
                out.push_str(&code[copied..start]);
                out.push_str(&p);
                out.extend(code[start..end].matches('\n').map(|_| '\n'));
                copied = end;
            }
            i = j;
        }
        out.push_str(&code[copied..]);
        Ok(out)
    }
}

/// [`compose`] / [`compose_shader`] over any module lookup (tests use a fake one); `shader`:
/// its file name for errors and its text.
pub(crate) fn compose_with<'a>(
    lookup: &dyn Fn(&str) -> Option<&'a str>,
    names: &[&str],
    shader: Option<(&str, &str)>,
) -> Result<String, ComposeError> {
    let mut w = Walk { lookup, done: Vec::new(), out: String::new(), stack: Vec::new(), items: BTreeMap::new() };
    for n in names {
        w.visit(n, None)?;
    }
    let Some((file, shader)) = shader else { return Ok(w.out) };
    let lines = parse(file, shader)?;
    let code = w.resolve(file, &lines)?;
    w.out.push_str("// ---- shader ----\n");
    let src: Vec<&str> = shader.lines().collect();
    for ((l, c), s) in lines.iter().zip(code.split('\n')).zip(&src) {
        match l {
            Line::Code(_) => w.out.push_str(c),
            Line::Import(_) | Line::ImportMore => w.out.push_str(&format!("// (imported above) {}", s.trim())),
            Line::Define => w.out.push_str("// (#define_import_path removed)"),
        }
        w.out.push('\n');
    }
    Ok(w.out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fake(name: &str) -> Option<&'static str> {
        match name {
            "a" => Some("#define_import_path shadefit::a\n#import shadefit::b\n#import shadefit::c;\nfn a() -> f32 { return b() + c(); }"),
            "b" => Some("#define_import_path shadefit::b\n  #import shadefit::c\nfn b() -> f32 { return c(); }"),
            "c" => Some("#define_import_path shadefit::c\nfn c() -> f32 { return 1.0; }\nconst C_K: f32 = 2.0;\nstruct CS { x: f32 }"),
            // naga_oil's style inside a library: qualified names, an alias, an item import.
            "d" => Some("#define_import_path shadefit::d\n#import shadefit::c as cc\n#import shadefit::b::b\nfn d() -> f32 { return cc::c() * cc::C_K + b(); }"),
            "x" => Some("#import shadefit::y\nfn x() {}"),
            "y" => Some("#import shadefit::z\nfn y() {}"),
            "z" => Some("#import shadefit::x\nfn z() {}"),
            "bad" => Some("#import shadefit::c::c::c\n"),
            _ => None,
        }
    }

    fn order(src: &str) -> Vec<&str> {
        src.lines().filter_map(|l| l.strip_prefix("// ---- shadefit::")).map(|l| l.trim_end_matches(" ----")).collect()
    }

    fn shader(src: &str) -> Result<String, ComposeError> {
        compose_with(&fake, &[], Some(("s.wgsl", src)))
    }

    /// The shader part of a composition.
    fn tail(s: &str) -> &str {
        s.split_once("// ---- shader ----\n").unwrap().1
    }

    #[test]
    fn dependencies_first_each_once() {
        let s = compose_with(&fake, &["a", "c", "b", "a"], None).unwrap();
        assert_eq!(order(&s), ["c", "b", "a"]);
        assert!(!s.contains('#'), "{s}");
        assert_eq!(s.matches("fn c()").count(), 1);
    }

    #[test]
    fn shader_imports_are_inlined_and_commented_out() {
        let src = "#import shadefit::b\n#import shadefit::c\nfn main() { let v = b(); }\n";
        let s = shader(src).unwrap();
        assert_eq!(order(&s), ["c", "b"]);
        assert_eq!(tail(&s).lines().count(), src.lines().count());
        assert!(tail(&s).lines().nth(2).unwrap().starts_with("fn main()"));
    }

    #[test]
    fn declared_names_are_the_top_level_ones() {
        let src = "// fn not_me()\nconst A: f32 = 1.0;\n@group(0) @binding(1) var<uniform> u: vec4<f32>;\nvar<private> p: f32;\n\
                   override o: f32 = 1.0;\nstruct S { f: f32 }\nalias T = f32;\nfn f(x: f32) -> f32 { const inner = 2.0; return x; }\n/* fn no() /* nested */ fn no2() */";
        assert_eq!(declared(src), ["A", "u", "p", "o", "S", "T", "f"]);
    }

    #[test]
    fn naga_oil_styles_resolve_to_the_same_names() {
        // Each import form, with a call through each kind of name.
        let cases = [
            ("#import shadefit::c", "c::c() + c::C_K"),
            ("#import shadefit::c;", "c() + C_K"),
            ("#import shadefit::c as k", "k::c() + k::C_K"),
            ("#import shadefit::c::c", "c() + shadefit::c::C_K"),
            ("#import shadefit::c::{c, C_K}", "c() + C_K"),
            ("#import shadefit::c::{c as one, C_K as K,}", "one() + K"),
            ("#import shadefit::{c::{c as one}, b}", "one() + b::b() - b() + shadefit::c::C_K"),
            ("#import shadefit::{\n    c::{c as one},\n    b,\n}", "one() + b::b() - b() + shadefit::c::C_K"),
            ("", "shadefit::c::c() + shadefit::c::C_K"),
        ];
        for (imports, expr) in cases {
            let src = format!("{imports}\nfn main() -> f32 {{\n    return {expr};\n}}\n");
            let s = shader(&src).unwrap_or_else(|e| panic!("{imports}: {e}"));
            let want = expr.replace("shadefit::c::", "").replace("c::", "").replace("k::", "").replace("b::", "").replace("one", "c").replace(" K", " C_K");
            assert!(tail(&s).contains(&format!("    return {want};\n")), "{imports}:\n{s}");
            assert_eq!(tail(&s).lines().count(), src.lines().count(), "{imports}: one line per shader line");
            assert_eq!(s.matches("fn c()").count(), 1, "{imports}");
        }
    }

    #[test]
    fn libraries_may_use_the_prefixed_style_too() {
        let s = compose_with(&fake, &["d"], None).unwrap();
        assert_eq!(order(&s), ["c", "b", "d"]);
        assert!(s.contains("fn d() -> f32 { return c() * C_K + b(); }"), "{s}");
    }

    #[test]
    fn comments_members_and_other_names_are_left_alone() {
        let src = "#import shadefit::c::{c as x}\n// c::c() and x() in a comment\n/* x */ fn main() { let s = S(); let v = s.x + x() + xx + 1e-5x; }\n";
        let t = shader(src).unwrap();
        let t = tail(&t);
        assert!(t.contains("// c::c() and x() in a comment"), "{t}");
        assert!(t.contains("/* x */ fn main() { let s = S(); let v = s.x + c() + xx + 1e-5x; }"), "{t}");
    }

    #[test]
    fn errors_name_the_file_and_line() {
        assert_eq!(
            compose_with(&fake, &["x"], None),
            Err(ComposeError::Cycle(vec!["x".into(), "y".into(), "z".into(), "x".into()]))
        );
        assert_eq!(compose_with(&fake, &["nope"], None), Err(ComposeError::UnknownModule { name: "nope".into(), wanted_by: None }));
        assert_eq!(
            shader("\n#import shadefit::missing\n"),
            Err(ComposeError::UnknownModule { name: "missing".into(), wanted_by: Some(("s.wgsl".into(), 2)) })
        );
        assert_eq!(
            shader("fn f() {}\n\nfn g() -> f32 { return shadefit::missing::m(); }"),
            Err(ComposeError::UnknownModule { name: "missing".into(), wanted_by: Some(("s.wgsl".into(), 3)) })
        );
        let item = |line, item: &str| Err(ComposeError::UnknownItem { file: "s.wgsl".into(), line, module: "c".into(), item: item.into() });
        assert_eq!(shader("#import shadefit::c::{c, nope}"), item(1, "nope"));
        assert_eq!(shader("#import shadefit::c\n\nfn f() -> f32 { return c::nope(); }"), item(3, "nope"));
        assert_eq!(shader("fn f() -> f32 {\n return shadefit::c::b(); }"), item(2, "b"));
        assert_eq!(
            shader("#import shadefit::c as k\nfn f() -> f32 { return c::c(); }"),
            Err(ComposeError::NotImported { file: "s.wgsl".into(), line: 2, path: "c::c".into() })
        );
        let e = shader("#import shadefit::c\n fn f() { b::b(); }").unwrap_err();
        assert_eq!(e.to_string(), "s.wgsl:2: `b::b`: `b` is no imported module (add `#import shadefit::MODULE`, or write `shadefit::MODULE::item`)");
        assert!(matches!(compose_with(&fake, &["bad"], None), Err(ComposeError::BadImport { line: 1, ref file, .. }) if file == "shadefit::bad"));
        for line in [
            "#import other::c",
            "#import shadefit",
            "#import shadefit::c::*",
            "#import shadefit::c::{c",
            "#import shadefit::c as",
            "#import shadefit::c as 1x",
            "#import shadefit::c c",
            "#import shadefit::Big",
            "#importshadefit::c",
        ] {
            let e = shader(&format!("fn f() {{}}\n{line}")).unwrap_err();
            assert!(matches!(e, ComposeError::BadImport { line: 2, .. }), "{line}: {e}");
            assert!(e.to_string().starts_with("s.wgsl:2: unsupported import"), "{e}");
        }
    }

    #[test]
    fn real_modules_compose() {
        let all = compose(crate::wgsl::NAMES).unwrap();
        assert_eq!(order(&all), crate::wgsl::NAMES);
        assert!(!all.contains("#define_import_path"));
        assert!(matches!(compose(&["gloss_nope"]), Err(ComposeError::UnknownModule { .. })));
    }

    /// Writing `NAME::item` as `item` is only sound if no two libraries declare the same name.
    #[test]
    fn real_modules_share_one_namespace() {
        let mut seen: BTreeMap<String, &str> = BTreeMap::new();
        let libraries = crate::wgsl::NAMES.iter().copied().chain(["skin_curvature"]);
        for m in libraries {
            // (A scene module may declare nothing: scene_skin_character has no functions.)
            for n in declared(module_or_library(m).unwrap()) {
                if let Some(other) = seen.insert(n.clone(), m) {
                    panic!("`{n}` is declared by both {other} and {m}");
                }
            }
        }
        assert!(seen.len() > 2 * crate::wgsl::NAMES.len(), "{} names", seen.len());
    }
}
