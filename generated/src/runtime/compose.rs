//! A minimal WGSL composer for the emitted libraries.
//!
//! Each emitted library `wgsl/NAME.wgsl` starts with `#define_import_path shadefit::NAME` (the
//! naga_oil / Bevy convention) and defines its names with the module name as prefix, so
//! libraries can share one flat WGSL namespace. The composer:
//! - [`compose`]: concatenates the requested libraries (and whatever they import), each once,
//!   dependencies first, with the `#define_import_path` lines removed;
//! - [`compose_shader`]: does the same for the `#import shadefit::NAME` lines of a user's
//!   shader, then appends the shader with those lines turned into comments.
//!
//! Supported directives, each alone on its line (leading whitespace allowed):
//! `#define_import_path shadefit::NAME` (dropped) and `#import shadefit::NAME` (an optional
//! trailing `;` is accepted). Any other `#import` form (items, aliases, braces, another
//! namespace) is an error rather than silently ignored; other lines are copied unchanged.
//! The result is plain WGSL for `wgpu::ShaderSource::Wgsl` or naga.
//!
//! Names resolve to the emitted libraries (`wgsl::module`) first, then to the hand-written
//! ones of this crate (`runtime::library`: `skin_curvature`).

use std::fmt;

/// Why a composition failed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ComposeError {
    /// No emitted module of that name, or its family feature is disabled.
    UnknownModule {
        name: String,
        /// The library or "shader" whose `#import` asked for it (None: requested directly).
        wanted_by: Option<String>,
    },
    /// An `#import` line the composer does not understand.
    BadImport { file: String, line: usize, text: String },
    /// Libraries that import each other, as the chain that closes the cycle.
    Cycle(Vec<String>),
}

impl fmt::Display for ComposeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ComposeError::UnknownModule { name, wanted_by: None } => {
                write!(f, "unknown WGSL module `shadefit::{name}` (not emitted, or its family feature is off)")
            }
            ComposeError::UnknownModule { name, wanted_by: Some(by) } => write!(
                f,
                "`{by}` imports unknown WGSL module `shadefit::{name}` (not emitted, or its family feature is off)"
            ),
            ComposeError::BadImport { file, line, text } => write!(
                f,
                "{file}:{line}: unsupported import `{}` (expected `#import shadefit::NAME`)",
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

/// A user shader with its `#import shadefit::NAME` lines resolved: the imported libraries
/// (each once, dependencies first) followed by the shader, whose import lines become comments
/// (so its line count is unchanged).
///
/// ```
/// # if shadefit_runtime::wgsl::module("gloss_combine").is_some() {
/// let shader = "#import shadefit::gloss_combine\n\
///               @fragment fn fs() -> @location(0) vec4<f32> { return vec4<f32>(combine_gloss(0.5, 0.7)); }\n";
/// let src = shadefit_runtime::compose_shader(shader).unwrap();
/// assert!(src.find("fn combine_gloss(").unwrap() < src.find("@fragment").unwrap());
/// # }
/// ```
pub fn compose_shader(source: &str) -> Result<String, ComposeError> {
    compose_with(&module_or_library, &[], Some(source))
}

/// One preprocessed line of a source.
enum Line<'a> {
    Define,
    Import(&'a str),
    Code(&'a str),
}

fn is_module_name(s: &str) -> bool {
    !s.is_empty()
        && s.bytes().all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'_')
        && !s.as_bytes()[0].is_ascii_digit()
}

fn parse<'a>(file: &str, src: &'a str) -> Result<Vec<Line<'a>>, ComposeError> {
    src.lines()
        .enumerate()
        .map(|(i, line)| {
            let t = line.trim();
            if let Some(rest) = t.strip_prefix("#define_import_path")
                && (rest.is_empty() || rest.starts_with(char::is_whitespace))
            {
                return Ok(Line::Define);
            }
            if let Some(rest) = t.strip_prefix("#import") {
                let name = rest.trim().trim_end_matches(';').trim_end().strip_prefix("shadefit::");
                return match name {
                    Some(n) if rest.starts_with(char::is_whitespace) && is_module_name(n) => Ok(Line::Import(n)),
                    _ => Err(ComposeError::BadImport { file: file.to_string(), line: i + 1, text: line.to_string() }),
                };
            }
            Ok(Line::Code(line))
        })
        .collect()
}

/// Depth-first post-order walk: every library after everything it imports.
struct Walk<'a, 'l> {
    lookup: &'l dyn Fn(&str) -> Option<&'a str>,
    done: Vec<String>,
    out: String,
    stack: Vec<String>,
}

impl<'a> Walk<'a, '_> {
    fn visit(&mut self, name: &str, wanted_by: Option<&str>) -> Result<(), ComposeError> {
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
            wanted_by: wanted_by.map(str::to_string),
        })?;
        let lines = parse(&format!("shadefit::{name}"), src)?;
        self.stack.push(name.to_string());
        for l in &lines {
            if let Line::Import(dep) = l {
                self.visit(dep, Some(name))?;
            }
        }
        self.stack.pop();
        self.out.push_str(&format!("// ---- shadefit::{name} ----\n"));
        for l in &lines {
            if let Line::Code(c) = l {
                self.out.push_str(c);
                self.out.push('\n');
            }
        }
        self.out.push('\n');
        self.done.push(name.to_string());
        Ok(())
    }
}

/// [`compose`] / [`compose_shader`] over any module lookup (tests use a fake one).
pub(crate) fn compose_with<'a>(
    lookup: &dyn Fn(&str) -> Option<&'a str>,
    names: &[&str],
    shader: Option<&str>,
) -> Result<String, ComposeError> {
    let mut w = Walk { lookup, done: Vec::new(), out: String::new(), stack: Vec::new() };
    for n in names {
        w.visit(n, None)?;
    }
    let Some(shader) = shader else { return Ok(w.out) };
    let lines = parse("shader", shader)?;
    for l in &lines {
        if let Line::Import(dep) = l {
            w.visit(dep, Some("shader"))?;
        }
    }
    w.out.push_str("// ---- shader ----\n");
    for l in &lines {
        match l {
            Line::Code(c) => w.out.push_str(c),
            Line::Import(dep) => w.out.push_str(&format!("// (imported above) shadefit::{dep}")),
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
            "c" => Some("#define_import_path shadefit::c\nfn c() -> f32 { return 1.0; }"),
            "x" => Some("#import shadefit::y\nfn x() {}"),
            "y" => Some("#import shadefit::z\nfn y() {}"),
            "z" => Some("#import shadefit::x\nfn z() {}"),
            "bad" => Some("#import shadefit::c::c\n"),
            _ => None,
        }
    }

    fn order(src: &str) -> Vec<&str> {
        src.lines().filter_map(|l| l.strip_prefix("// ---- shadefit::")).map(|l| l.trim_end_matches(" ----")).collect()
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
        let shader = "#import shadefit::b\n#import shadefit::c\nfn main() { let v = b(); }\n";
        let s = compose_with(&fake, &[], Some(shader)).unwrap();
        assert_eq!(order(&s), ["c", "b"]);
        let (_, tail) = s.split_once("// ---- shader ----\n").unwrap();
        assert_eq!(tail.lines().count(), shader.lines().count());
        assert!(tail.lines().nth(2).unwrap().starts_with("fn main()"));
    }

    #[test]
    fn errors() {
        assert_eq!(
            compose_with(&fake, &["x"], None),
            Err(ComposeError::Cycle(vec!["x".into(), "y".into(), "z".into(), "x".into()]))
        );
        assert_eq!(
            compose_with(&fake, &["nope"], None),
            Err(ComposeError::UnknownModule { name: "nope".into(), wanted_by: None })
        );
        assert_eq!(
            compose_with(&fake, &[], Some("\n#import shadefit::missing\n")),
            Err(ComposeError::UnknownModule { name: "missing".into(), wanted_by: Some("shader".into()) })
        );
        assert!(matches!(compose_with(&fake, &["bad"], None), Err(ComposeError::BadImport { line: 1, .. })));
        for line in ["#import other::c", "#import shadefit::{a, b}", "#import shadefit::c as d", "#importshadefit::c"] {
            let e = compose_with(&fake, &[], Some(line)).unwrap_err();
            assert!(matches!(e, ComposeError::BadImport { line: 1, .. }), "{line}: {e}");
        }
    }

    #[cfg(feature = "gloss")]
    #[test]
    fn real_modules_compose() {
        let all = compose(crate::wgsl::NAMES).unwrap();
        assert_eq!(order(&all), crate::wgsl::NAMES);
        assert!(!all.contains("#define_import_path"));
        assert!(matches!(compose(&["gloss_nope"]), Err(ComposeError::UnknownModule { .. })));
    }
}
