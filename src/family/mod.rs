//! The family registry. A family is everything about one shading model's terms: its
//! quantities and integrands, its published constants and findings, its figures, its benchmark
//! rows and shader forms, its scene features and its own spec kinds. Each lives in one folder
//! here and describes itself with a [`Family`]; [`families`] lists them.
//!
//! The generic stages (`spec`, `pipeline`, `validate`, `plot`, `bench`, `scene`) never name a
//! family: they take the hooks they need (a [`Catalog`], slices of functions) from the caller,
//! and the build orchestration (`src/build.rs`) and the CLI fill them from this registry. Adding
//! a family is one folder and one line in [`FAMILIES`] (see ARCHITECTURE.md).

pub mod fiber;
pub mod fuzz;
pub mod ggx;
pub mod gloss;
pub mod ltc;
pub mod msdiffuse;
pub mod sggx;
pub mod sheen;
pub mod skin;

use crate::bench::FamilyBench;
use crate::fit::published::PublishedForm;
use crate::pipeline::{self, BuildError, Built, Mode};
use crate::plot::PlotError;
use crate::quantity::QuantityDef;
use crate::scene::Feature;
use crate::spec::{Catalog, KindDef, Spec};
use crate::validate::Item;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// A spec kind of a family's own: how its specs are checked and how they are built.
#[derive(Debug)]
pub struct SpecKind {
    pub spec: KindDef,
    pub build: fn(&Spec, Mode, &Path) -> Result<Built, BuildError>,
    /// Kinds whose work splits into independent cells (`build --shard K/N`, `merge`).
    pub shard: Option<Sharding>,
}

/// How a spec kind's work splits into cells: their count, and the payload of a range of them
/// (bytes that depend on the spec and the cells only). Concatenated in cell order, the payloads
/// of every range are what the kind's builder takes from `Spec::merged` in
/// `Mode::Fit` instead of computing.
#[derive(Debug)]
pub struct Sharding {
    pub cells: fn(&Spec) -> Result<u64, BuildError>,
    pub compute: fn(&Spec, std::ops::Range<u64>) -> Result<Vec<u8>, BuildError>,
}

/// `shadefit eval` options a family may take (`--profile`, `--kernel`).
#[derive(Debug, Clone, Copy, Default)]
pub struct EvalOptions<'a> {
    pub profile: Option<&'a Path>,
    pub kernel: Option<&'a str>,
}

/// What `eval` prints for a quantity evaluated with options: one value per channel, the largest
/// error estimate, extra JSON fields and a note for the text form.
#[derive(Debug, Clone)]
pub struct OptionEval {
    pub values: Vec<f64>,
    pub error: f64,
    pub extra: serde_json::Map<String, serde_json::Value>,
    pub note: String,
}

/// Evaluates a quantity (canonical parameters) with options; `Err` is bad input.
pub type EvalWithOptions = fn(&QuantityDef, &[f64], &EvalOptions) -> Result<OptionEval, String>;

/// A subcommand a family adds to the CLI (`shadefit NAME ARGS…`): it parses its own arguments
/// (`ARGS`, after the name) and returns what to print.
pub struct FamilyCommand {
    pub name: &'static str,
    pub about: &'static str,
    pub run: fn(&[String]) -> Result<String, CommandError>,
}

/// A family command's failure: bad input (exit 2, naming the file and field) or a failed job.
#[derive(Debug, thiserror::Error)]
pub enum CommandError {
    #[error("{0}")]
    Input(String),
    #[error("{0}")]
    Failed(String),
}

/// The family command named `name`.
pub fn command(name: &str) -> Option<&'static FamilyCommand> {
    FAMILIES.iter().flat_map(|f| f.commands.iter()).find(|c| c.name == name)
}

/// The `--help` lines of the family commands.
pub fn commands_help() -> String {
    let mut out = String::from("Family commands (`shadefit NAME --help` for their options):\n");
    for c in FAMILIES.iter().flat_map(|f| f.commands.iter()) {
        out.push_str(&format!("  {:<12} {}\n", c.name, c.about));
    }
    out
}

/// What a family offers. Plain data and function pointers.
pub struct Family {
    pub name: &'static str,
    /// The runtime crate's cargo feature that gates the family's emitted modules
    /// (`generated/Cargo.toml` declares it).
    pub feature: &'static str,
    pub doc: &'static str,
    /// Quantities `eval` serves and specs sample.
    pub quantities: &'static [QuantityDef],
    /// Spec kinds of the family's own (beyond fit, table, fields).
    pub spec_kinds: &'static [SpecKind],
    /// `eval` with `--profile`/`--kernel`: which quantities take them, and the evaluator.
    pub eval_options: Option<(&'static [&'static str], EvalWithOptions)>,
    /// Published constants measured against the integrals (`shadefit validate`); the argument
    /// is the generated/ folder (committed refits are measured beside them).
    pub validate: fn(&Path) -> Vec<Item>,
    /// Figures into the first folder from the committed outputs in the second.
    pub figures: fn(&Path, &Path) -> Result<Vec<PathBuf>, PlotError>,
    /// Benchmark rows: integrators, tables against numpy/scipy, shader forms.
    pub bench: FamilyBench,
    /// Scene features (`features = [...]` in scene manifests).
    pub scene_features: &'static [Feature],
    /// CLI subcommands of the family's own (e.g. texture tools).
    pub commands: &'static [FamilyCommand],
    /// Table axis mappings of the family's own (`mapping = "NAME"` on a table axis).
    pub axis_mappings: &'static [&'static crate::spec::AxisMapping],
    /// Published forms offered for refitting (`kind = "refit"` specs name them).
    pub forms: &'static [PublishedForm],
}

/// Every family, in the order `eval --help`, `validate` and `plot` list them.
pub static FAMILIES: &[&Family] =
    &[&gloss::FAMILY, &fuzz::FAMILY, &skin::FAMILY, &ggx::FAMILY, &fiber::FAMILY, &sggx::FAMILY, &msdiffuse::FAMILY, &sheen::FAMILY, &ltc::FAMILY];

pub fn families() -> &'static [&'static Family] {
    FAMILIES
}

/// Every quantity and family spec kind, for the spec layer: the families' and those of the lobe
/// specs registered so far ([`register_lobes`]; a registration makes the next call build the
/// catalog again, and catalogs handed out before stay valid).
pub fn catalog() -> &'static Catalog {
    if let Some(c) = *CATALOG.read().expect("the catalog lock") {
        return c;
    }
    let mut slot = CATALOG.write().expect("the catalog lock");
    if let Some(c) = *slot {
        return c;
    }
    let lobes = lobe_quantities();
    let c: &'static Catalog = Box::leak(Box::new(Catalog {
        quantities: FAMILIES.iter().flat_map(|f| f.quantities.iter()).chain(lobes.iter().copied()).collect(),
        kinds: FAMILIES.iter().flat_map(|f| f.spec_kinds.iter().map(|k| &k.spec)).chain([&REFIT.spec, &FORM.spec, &LOBE.spec]).collect(),
        features: FAMILIES
            .iter()
            .flat_map(|f| f.quantities.iter().map(|q| (q.name, f.feature)))
            .chain(lobes.iter().map(|q| (q.name, LOBES_FEATURE)))
            .collect(),
        mappings: FAMILIES.iter().flat_map(|f| f.axis_mappings.iter().copied()).collect(),
    }));
    *slot = Some(c);
    c
}

static CATALOG: std::sync::RwLock<Option<&'static Catalog>> = std::sync::RwLock::new(None);

/// The family spec kind named `name`.
pub fn spec_kind(name: &str) -> Option<&'static SpecKind> {
    FAMILIES.iter().flat_map(|f| f.spec_kinds.iter()).chain([&REFIT, &FORM, &LOBE]).find(|k| k.spec.name == name)
}

/// Every family's published forms, in registry order.
pub fn published_forms() -> &'static [&'static PublishedForm] {
    static FORMS: OnceLock<Vec<&'static PublishedForm>> = OnceLock::new();
    FORMS.get_or_init(|| FAMILIES.iter().flat_map(|f| f.forms.iter()).collect())
}

/// The generic kind `refit` (`pipeline::refit`) over the registry's forms.
pub static REFIT: SpecKind = SpecKind {
    spec: KindDef {
        name: pipeline::refit::KIND,
        spec_file: |path, text| pipeline::refit::spec_file(path, text, published_forms(), catalog()),
        samples_note: "{name} emits the committed refits of published forms: it has no samples of its own (see `shadefit validate`)",
        input_hash: |spec| pipeline::refit::input_hash(spec, published_forms()),
    },
    build: |spec, mode, root| pipeline::refit::build(spec, mode, root, published_forms()),
    shard: None,
};

/// The generic kind `form` (`pipeline::form`): the user's own formula for any quantity.
pub static FORM: SpecKind = SpecKind {
    spec: KindDef {
        name: pipeline::form::KIND,
        spec_file: |path, text| pipeline::form::spec_file(path, text, catalog()),
        samples_note: "{name} measures a formula on its own grid: `shadefit measure fits/{name}.toml` prints it",
        input_hash: pipeline::input_hash,
    },
    build: |spec, mode, root| pipeline::form::build(spec, mode, root, catalog()),
    shard: None,
};

/// The generic kind `lobe` (`pipeline::lobe`): the user's own BRDF lobe, its quantities
/// registered from the specs folder ([`register_lobes`]).
pub static LOBE: SpecKind = SpecKind {
    spec: KindDef {
        name: pipeline::lobe::KIND,
        spec_file: pipeline::lobe::spec_file,
        samples_note: "{name} is a lobe: `shadefit eval {name}-albedo …` integrates it, and table specs sample its quantities",
        input_hash: pipeline::input_hash,
    },
    build: pipeline::lobe::build,
    shard: None,
};

/// The runtime crate's feature of the lobe specs' modules (and of tables of their quantities).
pub const LOBES_FEATURE: &str = "lobes";

/// The registered lobes, each with its quantities.
static LOBES: std::sync::Mutex<Vec<(&'static pipeline::lobe::LobeDef, Vec<&'static QuantityDef>)>> = std::sync::Mutex::new(Vec::new());

/// Registers the lobe specs (`kind = "lobe"`) directly in `dir` — the `--fits` folder — so that
/// the catalog serves their quantities (the CLI calls it before parsing the command line, the
/// build before loading the specs). A lobe registered before from the same file is kept; one of
/// the same name from another file is refused. Returns how many it added.
pub fn register_lobes(dir: &Path) -> Result<usize, crate::spec::SpecError> {
    let known: Vec<&str> = FAMILIES.iter().flat_map(|f| f.quantities.iter().map(|q| q.name)).collect();
    let defs = pipeline::lobe::read_dir(dir, &known)?;
    let mut lobes = LOBES.lock().expect("the lobe registry lock");
    let mut added = 0;
    for d in defs {
        if let Some((old, _)) = lobes.iter().find(|(l, _)| l.name == d.name) {
            if old.path == d.path {
                continue;
            }
            let text = std::fs::read_to_string(&d.path).unwrap_or_default();
            return Err(crate::spec::SpecError::new(&d.path, crate::spec::line_of(&text, "name"), "name", format!("lobe '{}' is also {}", d.name, old.path.display())));
        }
        let def: &'static pipeline::lobe::LobeDef = Box::leak(Box::new(d));
        lobes.push((def, pipeline::lobe::quantities(def)));
        added += 1;
    }
    if added > 0 {
        *CATALOG.write().expect("the catalog lock") = None;
    }
    Ok(added)
}

/// The registered lobes' quantities, in registration order.
fn lobe_quantities() -> Vec<&'static QuantityDef> {
    LOBES.lock().expect("the lobe registry lock").iter().flat_map(|(_, q)| q.iter().copied()).collect()
}

/// The specs whose committed outputs `spec` reads when built (a refit spec's forms' `reads`;
/// none for the other kinds): the build writes them first.
pub fn reads(spec: &Spec) -> Vec<&'static str> {
    match spec.file.kind {
        crate::spec::Kind::Custom(k) if k == pipeline::refit::KIND => pipeline::refit::reads(spec, published_forms()),
        _ => vec![],
    }
}

/// The committed refits of the refit spec `spec` (generated/json/SPEC.json under `generated`,
/// checked against fits/SPEC.toml): how a family's audit, figures and benchmarks read a refit.
pub fn committed_refits(generated: &Path, spec: &str) -> Result<pipeline::refit::CommittedRefits, BuildError> {
    pipeline::refit::CommittedRefits::load(generated, spec, catalog(), published_forms())
}

/// The family that serves quantity `name`.
pub fn of_quantity(name: &str) -> Option<&'static Family> {
    FAMILIES.iter().copied().find(|f| f.quantities.iter().any(|q| q.name == name))
}

/// Every family's scene features, in registry order.
pub fn scene_features() -> Vec<&'static Feature> {
    FAMILIES.iter().flat_map(|f| f.scene_features.iter()).collect()
}

/// The `eval --help` text: every quantity with its parameters and what it is.
pub fn eval_help() -> String {
    let mut out = String::from("Quantities:\n");
    for q in FAMILIES.iter().flat_map(|f| f.quantities.iter()).chain(lobe_quantities()) {
        let mut params: Vec<String> = q
            .params
            .iter()
            .map(|p| match p.default {
                Some(d) => format!("[{}={d}]", p.name),
                None => format!("{}=…", p.name),
            })
            .collect();
        for (a, _, _) in q.aliases {
            params.push(format!("| {}=…", a.name));
        }
        out.push_str(&format!("  {:<18} {:<36} {}\n", q.name, params.join(" "), q.doc));
    }
    out.push_str("(angles in radians; README lists the domains)");
    out
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::bench::forms::{testing, FormRow};
    use std::collections::BTreeMap;

    /// The quick run of each family's shader forms, by family name (computed once).
    pub(crate) fn quick_forms(family: &str) -> &'static [FormRow] {
        static ROWS: OnceLock<BTreeMap<&'static str, Vec<FormRow>>> = OnceLock::new();
        ROWS.get_or_init(|| FAMILIES.iter().map(|f| (f.name, testing::quick(f.bench.forms, catalog()))).collect())[family].as_slice()
    }

    /// Families that benchmark no shader form yet, with the reason (each must say why).
    const NO_FORMS: &[(&str, &str)] = &[
        ("sheen", "its published curves are measured by validate; their shader forms are not ranked yet"),
        ("sggx", "emits exact formulas (the course's decoder and D): no approximations to rank yet"),
        ("ltc", "its light functions integrate a polygon light, not one quantity on a grid: their op counts and the tables' fit times are in the builds section, their end-to-end error in the tables' JSON"),
    ];

    /// Families whose shader forms include no table form, with the reason (each must say why).
    const NO_TABLE_FORMS: &[(&str, &str)] = &[(
        "msdiffuse",
        "its reference is a Monte Carlo walk (standard error ~0.015 rms on the bench grid): a table \
         of it at growing resolution stops improving at the noise, so tables cannot be ranked by \
         error; its committed slice tables are measured by validate",
    )];

    #[test]
    fn every_family_s_forms_are_sorted_by_cost_with_a_front_and_tables_converge() {
        for f in FAMILIES {
            if NO_FORMS.iter().any(|(n, _)| *n == f.name) {
                assert!(f.bench.forms.is_empty(), "{} has forms now: take it off NO_FORMS", f.name);
                continue;
            }
            let quantities: Vec<&str> = f.bench.forms.iter().map(|s| s.quantity).collect();
            assert!(!quantities.is_empty(), "{} benchmarks no shader form", f.name);
            let rows = quick_forms(f.name);
            testing::every_quantity_has_three_forms_sorted_by_cost_with_a_front(rows, &quantities);
            if NO_TABLE_FORMS.iter().any(|(n, _)| *n == f.name) {
                assert!(rows.iter().all(|r| r.table_bytes == 0), "{} has table forms now: take it off NO_TABLE_FORMS", f.name);
                continue;
            }
            testing::table_error_decreases_with_resolution(rows, &quantities);
        }
    }

    #[test]
    fn names_are_unique_across_families() {
        let mut seen = std::collections::BTreeSet::new();
        for f in FAMILIES {
            assert!(seen.insert(format!("family {}", f.name)), "family {} twice", f.name);
            for q in f.quantities {
                assert!(seen.insert(format!("quantity {}", q.name)), "quantity {} twice", q.name);
            }
            for k in f.spec_kinds {
                assert!(seen.insert(format!("kind {}", k.spec.name)), "spec kind {} twice", k.spec.name);
                assert!(!["fit", "table", "fields", "refit"].contains(&k.spec.name), "{} shadows a generic kind", k.spec.name);
            }
            for p in f.forms {
                assert!(seen.insert(format!("form {}", p.name)), "published form {} twice", p.name);
            }
            for x in f.scene_features {
                assert!(seen.insert(format!("feature {}", x.name)), "scene feature {} twice", x.name);
            }
            for c in f.commands {
                assert!(seen.insert(format!("command {}", c.name)), "family command {} twice", c.name);
            }
        }
    }
}
