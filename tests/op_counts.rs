//! Shader cost report: operation counts of every emitted WGSL function (generated/wgsl, as the
//! runtime crate composes it), from naga's IR through `shadefit::bench::ops`, next to the
//! measured error in its file's header.
//!
//!     cargo test --release --test op_counts -- --nocapture
//!
//! prints one table of every function of every emitted library (helpers included), one per
//! quantity with several forms (fit, table, texture) to pick from, and checks the counts of a
//! few functions against hand counts of their source. What is counted: see `src/bench/ops.rs`;
//! `shadefit bench` compares forms built for the purpose (`src/bench/forms.rs`). The time of
//! each function on a GPU: `generated/tests/timing.rs` of the runtime crate.
//!
//! # Error column
//! `max abs` from the `// measured error:` header line of the function's file (the fit or
//! table against the integral; for skin LUTs the bilinear lookup of the f32 texels, to which
//! the KTX2 texture adds its f16 storage error, shown in `note`). Helpers carry their module's
//! figure in parentheses.

use shadefit::bench::ops::{OpCounts, Source};
use shadefit_runtime::{compose, lut, wgsl};

/// `max abs` of a `// measured error:` line, and the texture storage error if it names one.
fn header_error(src: &str) -> (Option<f64>, Option<String>) {
    let Some(line) = src.lines().find(|l| l.starts_with("// measured error:")) else { return (None, None) };
    let number_after = |key: &str| {
        line.find(key).and_then(|i| line[i + key.len()..].split([',', ' ', ';', ')']).find(|s| !s.is_empty())?.parse::<f64>().ok())
    };
    let storage = line.find("storage <=").map(|i| {
        let fmt = line[..i].rsplit("; ").next().unwrap_or("").trim();
        format!("texture +{:.1e} ({fmt} storage)", number_after("storage <=").unwrap_or(f64::NAN))
    });
    (number_after("max abs"), storage)
}

/// A string field of the module's JSON provenance (`"key": "value"`), read without a JSON
/// parser: the generator writes one key per line.
fn json_field(module: &str, key: &str) -> Option<String> {
    let path = format!("{}/generated/json/{module}.json", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let pat = format!("\"{key}\": \"");
    let i = text.find(&pat)? + pat.len();
    Some(text[i..i + text[i..].find('"')?].to_string())
}

/// One row: a function of an emitted library (or a runtime texture accessor of a table).
struct Row {
    module: String,
    function: String,
    form: String,
    helper: bool,
    quantity: String,
    counts: OpCounts,
    error: Option<f64>,
    note: String,
}

/// Inclusive counts of every function of a WGSL source.
fn count_all(src: &str) -> Vec<(String, OpCounts)> {
    Source::parse(src).and_then(|s| s.count_all()).unwrap_or_else(|e| panic!("{e}"))
}

fn is_helper(module: &str, name: &str) -> bool {
    (name.starts_with(module) && name.ends_with("_input")) || name.ends_with("_coords") || name.ends_with("_uv") || name.ends_with("_tex_input") || name.ends_with("_tex_load")
}

/// Every function of every emitted library, then the texture accessor of every table.
fn rows() -> Vec<Row> {
    let mut rows = Vec::new();
    for &module in wgsl::NAMES {
        let text = wgsl::module(module).expect("compiled-in module");
        let (error, storage) = header_error(text);
        let kind = json_field(module, "kind").unwrap_or_default();
        let quantity = json_field(module, "quantity").unwrap_or_default();
        for (name, counts) in count_all(&compose(&[module]).unwrap()) {
            let helper = is_helper(module, &name);
            let sampled = counts.tex > 0;
            let form = match kind.as_str() {
                "fit" | "fields" => "rational fit",
                "table" => "table, const array",
                "skin-lut" if sampled => "LUT, KTX2 texture",
                "skin-lut" => "LUT, const array",
                "lobe" => "a lobe spec's BRDF",
                _ => "?",
            };
            let note = if sampled { storage.clone().unwrap_or_default() } else { String::new() };
            rows.push(Row { module: module.into(), function: name, form: form.into(), helper, quantity: quantity.clone(), counts, error, note });
        }
    }
    // The hand-written WGSL library of the runtime (no measured error: it is exact algebra).
    for (name, counts) in count_all(&compose(&["skin_curvature"]).unwrap()) {
        rows.push(Row {
            module: "skin_curvature (runtime)".into(),
            function: name,
            form: "hand-written".into(),
            helper: false,
            quantity: "skin-curvature".into(),
            counts,
            error: None,
            note: "directional curvature for the skin LUTs".into(),
        });
    }
    for t in lut::TABLES {
        let (error, _) = header_error(t.emitted_wgsl());
        for (name, counts) in count_all(&t.wgsl(0, 0)) {
            rows.push(Row {
                module: format!("{} (lut::Table::wgsl)", t.module),
                helper: is_helper(t.module, &name),
                function: name,
                form: "table, R32Float texture".into(),
                quantity: json_field(t.module, "quantity").unwrap_or_default(),
                counts,
                error,
                note: "same values as the const array".into(),
            });
        }
    }
    rows
}

fn print_table(rows: &[&Row]) {
    println!("| function | form | add | mul | div | transc | tex | const | other | fns | max abs error | note |");
    println!("|---|---|---:|---:|---:|---:|---:|---:|---:|---|---:|---|");
    for r in rows {
        let c = &r.counts;
        let err = match (r.error, r.helper) {
            (Some(e), false) => format!("{e:.3e}"),
            (Some(e), true) => format!("({e:.3e})"),
            (None, _) => "-".into(),
        };
        let fns: Vec<&str> = c.transc_fns.iter().copied().collect();
        let name = if r.helper { format!("{} (helper)", r.function) } else { r.function.clone() };
        println!(
            "| {name} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {err} | {} |",
            r.form,
            c.add,
            c.mul,
            c.div,
            c.transc,
            c.tex,
            c.const_loads,
            c.other,
            fns.join(" "),
            r.note
        );
    }
}

fn print_report() {
    let rows = rows();
    println!("\nShader cost of every emitted WGSL function (naga IR; inclusive of callees; see tests/op_counts.rs)\n");
    let mut by_module: Vec<&Row> = rows.iter().collect();
    by_module.sort_by(|a, b| (a.module.as_str(), a.helper).cmp(&(b.module.as_str(), b.helper)));
    print_table(&by_module);

    // Quantities with several non-helper forms: the table a user picks from.
    let mut quantities: Vec<&str> = rows.iter().map(|r| r.quantity.as_str()).collect();
    quantities.sort_unstable();
    quantities.dedup();
    for q in quantities {
        let mut forms: Vec<&Row> = rows.iter().filter(|r| r.quantity == q && !r.helper).collect();
        let mut kinds: Vec<&str> = forms.iter().map(|r| r.form.as_str()).collect();
        kinds.sort_unstable();
        kinds.dedup();
        if kinds.len() < 2 {
            continue; // one form (the P̃_s pair is two parts of one form)
        }
        forms.sort_by_key(|r| (r.counts.arith(), r.counts.tex, r.counts.const_loads));
        println!("\nForms of `{q}` (cheapest arithmetic first):\n");
        print_table(&forms);
    }
}

#[test]
fn cost_report() {
    print_report();
}

/// Hand counts of the source, so the walker is checked against something it did not compute.
#[test]
fn counts_match_hand_counts() {
    let rows = rows();
    let get = |f: &str| &rows.iter().find(|r| r.function == f).unwrap_or_else(|| panic!("no row {f}")).counts;
    {
        // gloss_to_normal_length_lut: the input clamp (mask, compare, clamp, select: 4 other);
        // t0 = (x0 − 0)·255 (1 add, 1 mul); i0 = min(u32(t0), 254) (2 other); f0 =
        // clamp(t0 − f32(i0), 0, 1) (1 add, 2 other); T[i0]·(1 − f0) + T[i0 + 1]·f0 (2 add, 2
        // mul, 1 integer add, two loads at computed indices).
        let c = get("gloss_to_normal_length_lut");
        assert_eq!((c.add, c.mul, c.div, c.transc, c.tex), (4, 3, 0, 0, 0), "{c:?}");
        assert_eq!((c.const_loads, c.other), (2, 9), "{c:?}");
        // The texture accessor: the same arithmetic, two fetches instead of the loads, each
        // with its texel address (i % width, i / width: 2 other).
        let t = get("gloss_to_normal_length_lut_tex");
        assert_eq!((t.add, t.mul, t.tex, t.const_loads, t.other), (4, 3, 2, 0, 13), "{t:?}");
    }
    {
        // fuzz_average_penetration: one input clamp (4 other); (N[0] + x0·(N[1] + x0·N[2])) / 1:
        // 2 add, 2 mul, 1 div (the N[k] are immediates).
        let c = get("fuzz_average_penetration");
        assert_eq!((c.add, c.mul, c.div, c.transc, c.const_loads, c.other), (2, 2, 1, 0, 0, 4), "{c:?}");
        // fuzz_average_ps: one sin, one cos.
        let r = get("fuzz_average_ps");
        assert_eq!((r.transc, r.transc_fns.iter().copied().collect::<Vec<_>>()), (2, vec!["cos", "sin"]), "{r:?}");
    }
    {
        // skin_punctual_lut_sample: one texture fetch, no table loads.
        let c = get("skin_punctual_lut_sample");
        assert_eq!((c.tex, c.const_loads), (1, 0), "{c:?}");
        // skin_punctual_lut: four loads of a vec3 texel (counted once each), then two vec3
        // lerps a·(1 − f0) + b·f0 and one across rows (9 mul, 3 add each).
        let c = get("skin_punctual_lut");
        assert_eq!(c.const_loads, 4);
        assert!(c.mul >= 18 && c.add >= 9, "{c:?}");
    }
    // A lobe spec's BRDF approximates nothing: it is the lobe (its header says so).
    assert!(
        rows.iter().all(|r| r.error.is_some() || r.form == "hand-written" || r.form == "a lobe spec's BRDF"),
        "every emitted file has a measured error"
    );
}

