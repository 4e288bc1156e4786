//! Published tables and approximations, measured against the project's integrals.
//!
//! Each item gives its domain, the points measured, max abs and rms error, the worst point and
//! findings: what the numbers say about the published constants (noise, typos, conventions).

use crate::pipeline::committed::Refit;
use crate::pipeline::form::Form;
use crate::fit::published::as_emitted;
use crate::spec::{Spec, SpecError};
use crate::spec::Catalog;
use serde::{Deserialize, Serialize};
use std::path::Path;

pub mod cache;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Item {
    pub name: String,
    pub source: String,
    pub domain: String,
    pub points: usize,
    pub max_abs_error: f64,
    pub rms_error: f64,
    pub worst_point: Vec<f64>,
    /// Extra measures (e.g. error in parameter units), name → value.
    pub extra: Vec<(String, f64)>,
    pub findings: Vec<String>,
}

pub use crate::pipeline::measure;

impl Item {
    /// An item measured from `approx − truth` over `points`, with no extras or findings yet.
    pub fn measured(name: &str, source: &str, domain: &str, points: &[Vec<f64>], truth: &[f64], approx: &[f64]) -> Item {
        let (max_abs_error, rms_error, worst_point) = measure(points, truth, approx);
        Item {
            name: name.into(),
            source: source.into(),
            domain: domain.into(),
            points: points.len(),
            max_abs_error,
            rms_error,
            worst_point,
            extra: vec![],
            findings: vec![],
        }
    }

    /// Measure the committed refit `generated/json/NAME.json` on the same points, through the
    /// model of its spec, and add it side by side. Returns the refit's values (None when the
    /// refit is not committed, or was written for another version of its spec).
    pub fn add_refit(&mut self, generated: &Path, name: &str, catalog: &Catalog, points: &[Vec<f64>], truth: &[f64]) -> Option<Vec<f64>> {
        let refit = Refit::load(generated, name, catalog).ok()?;
        let approx: Vec<f64> = points.iter().map(|x| refit.eval(x)).collect();
        let (m, r, _) = measure(points, truth, &approx);
        let objective = refit.spec.file.fit.as_ref().map_or("?".to_string(), |f| format!("{:?}", f.objective).to_lowercase());
        self.extra.push(("refit_max_abs_error".into(), m));
        self.extra.push(("refit_rms_error".into(), r));
        self.findings.push(format!(
            "shadefit's refit (fits/{name}.toml, same form, {objective}): max {m:.3e} ({:.2}× the published), rms {r:.3e} ({:.2}×).",
            m / self.max_abs_error,
            r / self.rms_error
        ));
        Some(approx)
    }
}

/// Every item of the given validators (one per family, in registry order).
pub fn all(generated: &Path, validators: &[fn(&Path) -> Vec<Item>]) -> Vec<Item> {
    validators.iter().flat_map(|v| v(generated)).collect()
}

/// One `validate` item of a form spec: the published constants measured against the integral,
/// with the committed refit beside them when it is committed for this version of the spec.
pub fn form_item(spec: &Spec, generated: &Path, catalog: &Catalog) -> Result<Item, SpecError> {
    let form = Form::from_spec(spec, catalog)?;
    let truth = form.truth();
    let published = form.errors(&truth, &form.published);
    let e = &published.all;
    let mut worst: Vec<f64> = form.args.iter().map(|a| e.worst[a]).collect();
    worst.push(form.outputs.iter().position(|o| *o == e.worst_output).unwrap_or(0) as f64);
    let mut item = Item {
        name: format!("form {}: {}", form.name, spec.file.description),
        source: form.source.clone(),
        domain: format!("{}; worst point is [{}, output ({})]", form.grid_doc(), form.args.join(", "), form.outputs.join(", ")),
        points: e.points,
        max_abs_error: e.max_abs_error,
        rms_error: e.rms_error,
        worst_point: worst,
        extra: vec![("mean_signed_error".into(), e.mean_signed_error)],
        findings: vec![],
    };
    for (o, s) in &published.outputs {
        item.extra.push((format!("{o}_max_abs_error"), s.max_abs_error));
    }
    match crate::pipeline::form::committed(generated, spec) {
        Some(k) => {
            let refit: Vec<f64> = k.constants.iter().map(|k| k.refit).collect();
            let r = form.errors(&truth, &as_emitted(&refit)).all;
            item.extra.push(("refit_max_abs_error".into(), r.max_abs_error));
            item.extra.push(("refit_rms_error".into(), r.rms_error));
            item.findings.push(format!(
                "shadefit's refit ({:?}, same form, generated/json/{}.json): max {:.3e} ({:.2}× the published), rms {:.3e} ({:.2}×), worst at {:?} ({}).",
                form.objective,
                form.name,
                r.max_abs_error,
                r.max_abs_error / e.max_abs_error,
                r.rms_error,
                r.rms_error / e.rms_error,
                r.worst,
                r.worst_output
            ));
        }
        None => item.findings.push(format!("The refit is not committed for this version of the spec: run `shadefit build --only {}`.", form.name)),
    }
    Ok(item)
}

/// The number printed right after `key` in a finding's text: the longest run of digits,
/// points, signs and exponent letters there that parses (so `1.5e-3.` reads 1.5e-3).
#[cfg(test)]
pub(crate) fn number_after(text: &str, key: &str) -> f64 {
    let rest = &text[text.find(key).unwrap_or_else(|| panic!("{key} in {text}")) + key.len()..];
    let end = rest.find(|c: char| !(c.is_ascii_digit() || ".eE+-".contains(c))).unwrap_or(rest.len());
    (1..=end).rev().find_map(|n| rest[..n].parse().ok()).unwrap_or_else(|| panic!("{key}: {rest}"))
}

/// The value of `key` among an item's extras; panics, naming the item, when it has none.
#[cfg(test)]
pub(crate) fn extra(it: &Item, key: &str) -> f64 {
    it.extra.iter().find(|(k, _)| k == key).unwrap_or_else(|| panic!("{}: no {key}", it.name)).1
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::build_tests::{fit_rational, floats, json_of, spec, uniform, EXP, FIT};
    use crate::pipeline::{build_spec, write_all, Mode};

    /// `all` runs every validator on the generated folder and keeps their items in registry
    /// order.
    #[test]
    fn all_keeps_every_validators_items_in_order() {
        fn one(g: &Path) -> Vec<Item> {
            vec![Item::measured("a", &g.display().to_string(), "x", &[vec![0.0]], &[1.0], &[1.5])]
        }
        fn two(_: &Path) -> Vec<Item> {
            ["b", "c"].iter().map(|n| Item::measured(n, "s", "x", &[vec![0.0], vec![1.0]], &[1.0, 2.0], &[1.0, 2.25])).collect()
        }
        let items = all(Path::new("gen"), &[one, two]);
        let names: Vec<&str> = items.iter().map(|i| i.name.as_str()).collect();
        assert_eq!(names, ["a", "b", "c"]);
        assert_eq!(items[0].source, "gen");
        assert_eq!((items[0].max_abs_error, items[2].max_abs_error), (0.5, 0.25));
    }

    /// A validation item beside its committed refit: `Item::add_refit` loads the refit through its
    /// spec (`fits/NAME.toml` next to the outputs), evaluates it at the item's points and adds its
    /// errors; each is re-measured here from the written coefficients against the closed form. A
    /// refit that is not committed adds nothing.
    #[test]
    fn a_validation_item_measures_the_committed_refit() {
        let catalog = Catalog { quantities: vec![&EXP], kinds: vec![], features: vec![], mappings: vec![] };
        let tmp = tempfile::tempdir().unwrap();
        let generated = tmp.path().join("generated");
        std::fs::create_dir_all(tmp.path().join("fits")).unwrap();
        std::fs::write(tmp.path().join("fits/exp_fit.toml"), FIT).unwrap();
        let b = build_spec(&spec(FIT), Mode::Fit, &generated, &|_| None).unwrap();
        write_all(&generated, &b.artifacts).unwrap();
        let c = floats(&json_of(&b)["model"]["coefficients"]);
        let r64 = |x: f64| fit_rational(&c, x);
        // A "published" form to set beside it: the Taylor polynomial 1 − x + x²/2.
        let xs = uniform(21);
        let points: Vec<Vec<f64>> = xs.iter().map(|&x| vec![x]).collect();
        let truth: Vec<f64> = xs.iter().map(|&x| (-x).exp()).collect();
        let taylor: Vec<f64> = xs.iter().map(|&x| 1.0 - x + 0.5 * x * x).collect();
        let mut item = Item::measured("taylor", "a test", "x ∈ [0, 2]", &points, &truth, &taylor);
        let values = item.add_refit(&generated, "exp_fit", &catalog, &points, &truth).expect("the refit is committed");
        let (mut max, mut ss) = (0.0f64, 0.0);
        for ((&x, v), t) in xs.iter().zip(&values).zip(&truth) {
            // The refit evaluated through its model against the coefficients written out: rounding.
            assert!((v - r64(x)).abs() < 1e-15, "refit at {x}: {v} vs {}", r64(x));
            max = max.max((r64(x) - t).abs());
            ss += (r64(x) - t).powi(2);
        }
        let extra = |k: &str| item.extra.iter().find(|(n, _)| n == k).unwrap().1;
        assert!((extra("refit_max_abs_error") - max).abs() < 1e-15, "{} vs {max}", extra("refit_max_abs_error"));
        assert!((extra("refit_rms_error") - (ss / 21.0).sqrt()).abs() < 1e-15);
        // The Taylor form's own error (at x = 2: 1 − e⁻² ≈ 0.865) is far above the refit's.
        assert!(item.max_abs_error > 0.8 && max < 1e-3, "taylor {}, refit {max}", item.max_abs_error);
        assert_eq!(item.findings.len(), 1, "{:?}", item.findings);
        // The finding names the spec and its objective, and sets the refit's errors beside the
        // published form's as ratios: for a form with twice the refit's error at every point,
        // 0.50 and 0.50 (to 2 decimals; the doubling rounds by an ulp).
        let doubled: Vec<f64> = xs.iter().zip(&truth).map(|(&x, t)| t + 2.0 * (r64(x) - t)).collect();
        let mut half = Item::measured("doubled", "a test", "x ∈ [0, 2]", &points, &truth, &doubled);
        half.add_refit(&generated, "exp_fit", &catalog, &points, &truth).unwrap();
        let f = &half.findings[0];
        for part in ["(fits/exp_fit.toml, same form, minimax)", "(0.50× the published)", "(0.50×)."] {
            assert!(f.contains(part), "{f:?} lacks {part:?}");
        }
        let mut bare = Item::measured("taylor", "a test", "x ∈ [0, 2]", &points, &truth, &taylor);
        assert!(bare.add_refit(&generated, "no_such_fit", &catalog, &points, &truth).is_none());
        assert!(bare.extra.is_empty() && bare.findings.is_empty());
    }
}
