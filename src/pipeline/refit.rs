//! `kind = "refit"`: the one committed way to refit a published form. A refit spec names forms
//! the families register ([`PublishedForm`]); `Mode::Fit` runs each form's refit, measures the
//! published and the refitted constants against the integral the form approximates, and writes
//! one WGSL library and one Rust module of the refitted forms (each function keeps its source's
//! form and argument order, inputs clamped to the box it was fitted on, NaN → the lower end)
//! with `json/NAME.json`, which commits the constants (f64 as refitted; the code carries them
//! as f32) and the errors. `Mode::Committed` re-renders from that JSON. Everything else that
//! uses a refit — `validate`, figures, benchmarks — reads its constants through
//! [`CommittedRefits`], never a copy.
//!
//! The input hash covers the generator, the spec text and each named form's identity (name,
//! arguments, domain, published constants, program): a changed form makes `build --check`
//! fail until the spec is rebuilt. The refit procedure itself is code: changing it without
//! changing the form is seen by `build` (Fit mode), which rewrites the JSON.
//!
//! ```toml
//! name = "my_refits"
//! kind = "refit"
//! quantity = "…"            # the quantity the forms approximate (the runtime crate's feature)
//! forms = ["form-a", "form-b"]
//! doc = ["The module's doc lines."]
//! [emit]
//! function = "my_refit"     # prefix: my_refit_FUNCTION for each form
//! ```

use super::module::{module_built, module_json};
use super::{BuildError, Built, Mode, committed_json_with_hash, fmt_err, hex, spec_rel_path};
use crate::emit::lang::{Lang, form_body};
use crate::emit::{GENERATOR, header_lines};
use crate::fit::published::{FormError, PublishedForm, as_emitted};
use crate::spec::{Catalog, CustomSpec, Spec, SpecError, SpecFile, is_kind, line_of, parse_toml};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::path::Path;

pub const KIND: &str = "refit";

/// The spec file of a refit spec.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RefitFile {
    name: String,
    #[allow(dead_code)]
    kind: String,
    quantity: String,
    #[serde(default)]
    description: String,
    /// The registered forms to refit, in the order the module defines them.
    forms: Vec<String>,
    /// The module's doc lines.
    #[serde(default)]
    doc: Vec<String>,
    emit: Prefix,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Prefix {
    function: String,
    #[allow(dead_code)]
    targets: Option<Vec<String>>,
}

/// One function of a committed refit module.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CommittedForm {
    /// The emitted function, `PREFIX_FUNCTION`.
    pub function: String,
    /// The registered form's name.
    pub form: String,
    /// The refitted constants as the refit returned them (the emitted code carries them as f32).
    pub constants: Vec<f64>,
    pub published_constants: Vec<f64>,
    /// The form's check of the emitted constants (e.g. a proven denominator bound).
    pub checks: BTreeMap<String, f64>,
    /// Published and refitted errors on each grid (refit: the f32 constants, evaluated in f64).
    pub errors: Vec<FormError>,
}

fn find<'a>(registry: &[&'a PublishedForm], name: &str) -> Option<&'a PublishedForm> {
    registry.iter().copied().find(|f| f.name == name)
}

/// For `Spec::parse`: the common spec of a refit spec, or `None` when the text is not one. The
/// forms must be registered, each named once, with distinct function names. Its axes are the
/// quantity's parameters without defaults (two points each: a refit spec has no samples of its
/// own; its forms measure on their own grids).
pub fn spec_file(path: &Path, text: &str, registry: &[&PublishedForm], catalog: &Catalog) -> Result<Option<SpecFile>, SpecError> {
    if !is_kind(text, KIND) {
        return Ok(None);
    }
    let f: RefitFile = parse_toml(path, text)?;
    let at = |why: String| SpecError::new(path, line_of(text, "forms"), "forms", why);
    if f.forms.is_empty() {
        return Err(at("names no form: give at least one of the registered forms".into()));
    }
    let mut functions: Vec<&str> = Vec::new();
    for (i, name) in f.forms.iter().enumerate() {
        let Some(form) = find(registry, name) else {
            let known: Vec<&str> = registry.iter().map(|f| f.name).collect();
            return Err(at(format!("'{name}' is not a registered form (forms: {})", known.join(", "))));
        };
        if f.forms[..i].contains(name) {
            return Err(at(format!("'{name}' is named twice")));
        }
        if functions.contains(&form.function) {
            return Err(at(format!("'{name}' emits {}_{} as another form does", f.emit.function, form.function)));
        }
        functions.push(form.function);
    }
    let axes = match catalog.lookup(&f.quantity) {
        Ok(q) => q
            .params
            .iter()
            .filter(|p| p.default.is_none())
            .map(|p| {
                let finite = |v: f64, d: f64| if v.is_finite() { v } else { d };
                serde_json::json!({"name": p.name, "range": [finite(p.min, 0.0), finite(p.max, finite(p.min, 0.0) + 1.0)], "count": 2})
            })
            .collect(),
        // The common parser reports the unknown quantity.
        Err(_) => vec![],
    };
    let common = CustomSpec { kind: KIND, name: &f.name, quantity: &f.quantity, description: &f.description, tolerance: 1e-9, axes, function: &f.emit.function };
    common.spec_file(path, text).map(Some)
}

/// The spec's forms, resolved in the registry (the spec was checked when parsed).
fn forms<'a>(spec: &Spec, registry: &[&'a PublishedForm]) -> Result<(RefitFile, Vec<&'a PublishedForm>), BuildError> {
    let f: RefitFile = parse_toml(&spec.path, &spec.text)?;
    let forms = f
        .forms
        .iter()
        .map(|n| find(registry, n).ok_or_else(|| BuildError::NoCommitted { spec: spec.file.name.clone(), why: format!("form '{n}' is not registered") }))
        .collect::<Result<Vec<_>, _>>()?;
    Ok((f, forms))
}

/// The specs whose committed outputs the spec's forms read (`PublishedForm::reads`): the build
/// writes those before it builds this spec.
pub fn reads(spec: &Spec, registry: &[&PublishedForm]) -> Vec<&'static str> {
    let mut names: Vec<&'static str> = match forms(spec, registry) {
        Ok((_, forms)) => forms.iter().flat_map(|f| f.reads.iter().copied()).collect(),
        Err(_) => vec![],
    };
    names.sort_unstable();
    names.dedup();
    names
}

/// The generator, the spec text and each named form's identity.
pub fn input_hash(spec: &Spec, registry: &[&PublishedForm]) -> String {
    let mut h = Sha256::new();
    h.update(GENERATOR.as_bytes());
    h.update(b"\n");
    h.update(spec.text.as_bytes());
    if let Ok((_, forms)) = forms(spec, registry) {
        for f in forms {
            h.update(format!("\n{}|{:?}|{:?}|{:?}|{:?}", f.name, f.args, f.domain, (f.published)(), f.program.map(|p| p())).as_bytes());
            for read in f.reads {
                h.update(format!("\n{read}: {}", read_hash(spec, read)).as_bytes());
            }
        }
    }
    format!("sha256:{}", hex(&h.finalize()))
}

/// The input hash recorded by the committed JSON of the spec `name` that a form reads, in the
/// generated/ folder beside the refit spec's fits/ folder ("missing" when there is none): a
/// rebuilt table makes the refits that read it stale.
fn read_hash(spec: &Spec, name: &str) -> String {
    let generated = spec.path.parent().and_then(Path::parent).unwrap_or(Path::new("")).join("generated");
    std::fs::read_to_string(generated.join("json").join(format!("{name}.json")))
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .and_then(|v| v["input_hash"].as_str().map(String::from))
        .unwrap_or_else(|| "missing".into())
}

/// The committed functions of a refit spec whose input hash is `hash`, checked against it and
/// against the spec's `forms`.
fn committed(spec: &Spec, root: &Path, hash: &str, forms: &[&PublishedForm]) -> Result<Vec<CommittedForm>, BuildError> {
    let name = &spec.file.name;
    let bad = |why: String| BuildError::NoCommitted { spec: name.clone(), why };
    let v = committed_json_with_hash(root, spec, hash)?;
    let functions: Vec<CommittedForm> = serde_json::from_value(v["functions"].clone()).map_err(|e| bad(format!("\"functions\": {e}")))?;
    if functions.len() != forms.len() || functions.iter().zip(forms).any(|(c, f)| c.form != f.name || c.constants.len() != (f.published)().len()) {
        return Err(bad("its functions are not the spec's forms".into()));
    }
    Ok(functions)
}

/// The committed refits of one refit spec, read once: what every use of a refit outside its
/// own module reads.
#[derive(Debug, Clone)]
pub struct CommittedRefits {
    spec: String,
    forms: Vec<CommittedForm>,
}

impl CommittedRefits {
    /// The refit spec `name` (`fits/NAME.toml` beside `generated`) and its committed
    /// `generated/json/NAME.json`, checked against the spec's input hash.
    pub fn load(generated: &Path, name: &str, catalog: &Catalog, registry: &[&PublishedForm]) -> Result<CommittedRefits, BuildError> {
        let spec = super::committed::load_spec(generated, name, catalog)?;
        let (_, forms) = forms(&spec, registry)?;
        let forms = committed(&spec, generated, &input_hash(&spec, registry), &forms)?;
        Ok(CommittedRefits { spec: name.into(), forms })
    }

    /// The committed constants of `form`.
    pub fn constants(&self, form: &str) -> Result<Vec<f64>, BuildError> {
        self.forms
            .iter()
            .find(|c| c.form == form)
            .map(|c| c.constants.clone())
            .ok_or_else(|| BuildError::NoCommitted { spec: self.spec.clone(), why: format!("it does not refit '{form}'") })
    }
}

/// Refit and measure one form (the committed outputs it reads are in `root`).
fn refit(spec: &str, prefix: &str, form: &PublishedForm, root: &Path) -> Result<CommittedForm, BuildError> {
    let failed = |why: String| BuildError::NoCommitted { spec: spec.into(), why: format!("the refit of '{}': {why}", form.name) };
    let constants = (form.refit)(root).map_err(failed)?;
    let published = (form.published)();
    let errors = (form.measure)(root, &published, &as_emitted(&constants)).map_err(failed)?;
    Ok(CommittedForm { function: format!("{prefix}_{}", form.function), form: form.name.into(), constants, published_constants: published, checks: BTreeMap::new(), errors })
}

pub fn build(spec: &Spec, mode: Mode, root: &Path, registry: &[&PublishedForm]) -> Result<Built, BuildError> {
    let name = spec.file.name.clone();
    let prefix = spec.file.emit.function.clone();
    let hash = input_hash(spec, registry);
    let (file, forms) = forms(spec, registry)?;
    let mut functions = match mode {
        Mode::Fit => forms.par_iter().map(|f| refit(&name, &prefix, f, root)).collect::<Result<Vec<_>, _>>()?,
        Mode::Committed => committed(spec, root, &hash, &forms)?,
    };
    for (c, f) in functions.iter_mut().zip(&forms) {
        if let Some(check) = f.check {
            let figures = check(&as_emitted(&c.constants))
                .map_err(|why| BuildError::NoCommitted { spec: name.clone(), why: format!("the refit of '{}' fails its check: {why}", f.name) })?;
            c.checks = figures.into_iter().collect();
        }
    }
    let rows: Vec<&FormError> = functions.iter().flat_map(|c| &c.errors).collect();
    let worst = rows.iter().map(|r| r.refit.max_abs_error / r.published.max_abs_error).fold(0.0f64, f64::max);
    let max = rows.iter().map(|r| r.refit.max_abs_error).fold(0.0f64, f64::max);
    let err_line = format!(
        "max abs {} (the largest of the forms, each on its own grid; each at most {worst:.2}x its published form's max abs there; per function below; forms in f64 with these f32 constants)",
        fmt_err(max)
    );
    let header = header_lines(&spec_rel_path(spec), &hash, &err_line);
    let doc: Vec<&str> = file.doc.iter().map(String::as_str).collect();
    let render = |lang: Lang| {
        let mut s = lang.preamble(&header, &name, &doc);
        for (c, f) in functions.iter().zip(&forms) {
            s += "\n";
            s += &function_doc(lang, f.doc, &c.errors);
            match f.program {
                Some(program) => {
                    let program = program();
                    s += &lang.signature(&c.function, f.args, program.width());
                    s += &form_body(lang, &name, program, &as_emitted(&c.constants), f.args, f.domain);
                }
                None => {
                    let consts: Vec<String> = c.constants.iter().map(|&v| lang.lit(v)).collect();
                    s += &format!("{} No function: the form is not written as a program; its refitted constants are [{}].\n", lang.comment(), consts.join(", "));
                }
            }
        }
        s
    };
    let (wgsl, rust) = (render(Lang::Wgsl), render(Lang::Rust));
    let points: usize = rows.iter().map(|r| r.points).sum();
    let rms = (rows.iter().map(|r| r.refit.rms_error.powi(2) * r.points as f64).sum::<f64>() / points.max(1) as f64).sqrt();
    let mut json = module_json(spec, &hash, KIND);
    json.insert("functions".into(), serde_json::to_value(&functions).expect("plain data serialises"));
    // The forms' errors pooled (each row is on its own grid and quantity; the per-form figures are in the JSON).
    Ok(module_built(&name, wgsl, rust, json, points, max, rms))
}

/// Doc lines of a function: what it is and its measured errors.
fn function_doc(lang: Lang, what: &str, rows: &[FormError]) -> String {
    let c = lang.comment();
    let mut s = format!("{c} {what}\n");
    for r in rows {
        s += &format!(
            "{c} {}: max abs {} (published {}, {:.2}x), rms {} (published {}) over {} values; {}.\n",
            r.form,
            fmt_err(r.refit.max_abs_error),
            fmt_err(r.published.max_abs_error),
            r.refit.max_abs_error / r.published.max_abs_error,
            fmt_err(r.refit.rms_error),
            fmt_err(r.published.rms_error),
            r.points,
            r.grid
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::expr::program::build::{k, var};
    use crate::fit::expr::program::Program;
    use crate::fit::published::Errors;
    use crate::pipeline::build_tests::{EXP, json_of};
    use crate::pipeline::write_all;
    use std::sync::LazyLock;

    /// c₀ + c₁x, the line every test form is.
    static LINE: LazyLock<Program> = LazyLock::new(|| Program { lets: vec![], result: k(0) + k(1) * var(0) });

    /// Max and rms |c₀ + c₁x − e^−x| over 201 uniform points of [0, 2].
    fn line_errors(c: &[f64]) -> Errors {
        let e: Vec<f64> = (0..=200).map(|i| 0.01 * i as f64).map(|x| c[0] + c[1] * x - (-x).exp()).collect();
        Errors { max_abs_error: e.iter().fold(0.0f64, |m, v| m.max(v.abs())), rms_error: (e.iter().map(|v| v * v).sum::<f64>() / e.len() as f64).sqrt() }
    }

    /// The chord of e^−x over [0, 2]: (1, (e^−2 − 1)/2), its published constants the tangent at 0.
    static CHORD: PublishedForm = PublishedForm {
        name: "test-chord",
        function: "chord",
        doc: "e^-x by a line.",
        args: &["x"],
        domain: &[(0.0, 2.0)],
        program: Some(|| &*LINE),
        published: || vec![1.0, -1.0],
        reads: &[],
        refit: |_| Ok(vec![1.0, ((-2.0f64).exp() - 1.0) / 2.0]),
        measure: |_, p, r| Ok(vec![FormError { form: "a line".into(), grid: "201 points of [0, 2]".into(), points: 201, published: line_errors(p), refit: line_errors(r) }]),
        check: None,
    };

    /// A form whose check refuses any constants.
    static REFUSED: PublishedForm = PublishedForm { name: "test-refused", function: "refused", check: Some(|_| Err("never".into())), ..CHORD };

    fn registry() -> Vec<&'static PublishedForm> {
        vec![&CHORD, &REFUSED]
    }

    fn quantities() -> Catalog {
        Catalog { quantities: vec![&EXP], kinds: vec![], features: vec![], mappings: vec![] }
    }

    /// The refit kind over the test forms, as the registry defines it over the families'.
    static KIND_DEF: crate::spec::KindDef = crate::spec::KindDef {
        name: KIND,
        spec_file: |p, t| spec_file(p, t, &registry(), &quantities()),
        samples_note: "",
        input_hash: |s| input_hash(s, &registry()),
    };

    fn catalog() -> Catalog {
        Catalog { kinds: vec![&KIND_DEF], ..quantities() }
    }

    const TEXT: &str = "name = \"line_refits\"\nkind = \"refit\"\nquantity = \"exp-decay\"\nforms = [\"test-chord\"]\ndoc = [\"Lines.\"]\n\n[emit]\nfunction = \"line_refit\"\n";

    fn parse(text: &str) -> Result<Spec, SpecError> {
        Spec::parse(Path::new("fits/line_refits.toml"), text.to_string(), &catalog())
    }

    /// A spec naming an unregistered form, the same form twice, no form, or two forms with one
    /// function name is refused at the `forms` line, naming the form (and listing the
    /// registered ones); text of another kind is not a refit spec.
    #[test]
    fn a_refit_spec_names_registered_forms_once() {
        let err = |text: &str| parse(text).expect_err("refused").to_string();
        let unknown = err(&TEXT.replace("[\"test-chord\"]", "[\"test-chord\", \"no-such-form\"]"));
        assert!(unknown.contains("fits/line_refits.toml:4") && unknown.contains("'no-such-form' is not a registered form (forms: test-chord, test-refused)"), "{unknown}");
        assert!(err(&TEXT.replace("[\"test-chord\"]", "[\"test-chord\", \"test-chord\"]")).contains("'test-chord' is named twice"));
        assert!(err(&TEXT.replace("[\"test-chord\"]", "[]")).contains("names no form"));
        assert!(err(&TEXT.replace("doc = ", "docs = ")).contains("docs"));
        assert!(spec_file(Path::new("fits/x.toml"), &TEXT.replace("\"refit\"", "\"fit\""), &registry(), &quantities()).unwrap().is_none());
    }

    /// Fit mode commits the refit's constants bit for bit, the errors its measure gives for the
    /// published and the f32-rounded refitted constants, and a WGSL/Rust function of the form
    /// with those f32 constants and the domain's clamp; Committed mode re-renders every file
    /// byte for byte from the JSON; `CommittedRefits` reads the constants back through the
    /// spec beside the folder. A JSON whose constants are not the spec's forms' is refused, and
    /// so is a refit that fails its form's check.
    #[test]
    fn fit_commits_the_constants_and_committed_mode_reproduces_the_files() {
        let registry = registry();
        let spec = parse(TEXT).unwrap();
        let tmp = tempfile::tempdir().unwrap();
        let generated = tmp.path().join("generated");
        std::fs::create_dir_all(tmp.path().join("fits")).unwrap();
        std::fs::write(tmp.path().join("fits/line_refits.toml"), TEXT).unwrap();
        let fit = build(&spec, Mode::Fit, &generated, &registry).unwrap();
        let v = json_of(&fit);
        let chord = [1.0, ((-2.0f64).exp() - 1.0) / 2.0];
        let f: Vec<CommittedForm> = serde_json::from_value(v["functions"].clone()).unwrap();
        assert_eq!(f.len(), 1);
        assert_eq!((f[0].function.as_str(), f[0].form.as_str()), ("line_refit_chord", "test-chord"));
        assert_eq!(f[0].constants, chord);
        assert_eq!(f[0].published_constants, [1.0, -1.0]);
        let c32 = [1.0f32 as f64, chord[1] as f32 as f64];
        assert_eq!(f[0].errors[0].refit, line_errors(&c32));
        assert_eq!(f[0].errors[0].published, line_errors(&[1.0, -1.0]));
        let wgsl = String::from_utf8(fit.artifacts[0].contents.clone()).unwrap();
        let c1 = crate::emit::f32_literal(chord[1] as f32);
        assert!(wgsl.contains("fn line_refit_chord(x: f32) -> f32 {"), "{wgsl}");
        assert!(wgsl.contains("line_refits_input(x, 0e0f, 2e0f)") && wgsl.contains(&format!("1e0f + {c1}f * ")), "{wgsl}");
        assert!(wgsl.contains("// Lines.\n") && wgsl.contains("// e^-x by a line.\n"), "{wgsl}");
        write_all(&generated, &fit.artifacts).unwrap();
        let again = build(&spec, Mode::Committed, &generated, &registry).unwrap();
        for (a, b) in fit.artifacts.iter().zip(&again.artifacts) {
            assert_eq!(a.contents, b.contents, "{}", a.path.display());
        }
        let cat = catalog();
        let refits = CommittedRefits::load(&generated, "line_refits", &cat, &registry).unwrap();
        assert_eq!(refits.constants("test-chord").unwrap(), chord);
        assert!(refits.constants("test-refused").is_err());
        // Tampered: one constant too many.
        let path = generated.join("json/line_refits.json");
        let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        v["functions"][0]["constants"] = serde_json::json!([1.0, 1.0, -0.5]);
        std::fs::write(&path, v.to_string()).unwrap();
        assert!(build(&spec, Mode::Committed, &generated, &registry).is_err());
        let refused = parse(&TEXT.replace("test-chord", "test-refused")).unwrap();
        let err = build(&refused, Mode::Fit, &generated, &registry).expect_err("its check refuses it").to_string();
        assert!(err.contains("fails its check: never"), "{err}");
    }

    /// The input hash follows the spec text and the forms' published constants.
    #[test]
    fn the_input_hash_covers_the_spec_and_the_forms() {
        static OTHER: PublishedForm = PublishedForm { published: || vec![1.0, -0.5], ..CHORD };
        let spec = parse(TEXT).unwrap();
        let h = input_hash(&spec, &registry());
        assert_ne!(h, input_hash(&spec, &[&OTHER]));
        assert_ne!(h, input_hash(&parse(&TEXT.replace("Lines.", "Lines!")).unwrap(), &registry()));
        assert_eq!(h, input_hash(&parse(TEXT).unwrap(), &registry()));
    }
}
