//! LTC tables (`kind = "ltc-table"`): ltc_code's two 64 × 64 textures fitted for a lobe by
//! [`super::fit::fit_table`], with their per-cell error and the end-to-end error of the
//! emitted light functions over the committed lights ([`super::reference`]).
//!
//! ```toml
//! name = "ltc_ggx"                  # output stem; must equal the file stem
//! kind = "ltc-table"
//! quantity = "ltc-ggx-distance"     # the lobe: ltc-ggx-distance (GGX, height-correlated
//!                                   # Smith: ltc_code's) or ltc-sheen-distance (Charlie)
//! description = "..."
//! resolution = 64                   # optional: texels per side (ltc_code's 64)
//! nodes = 24                        # optional: Gauss–Legendre nodes per axis of the metric
//! min_alpha = 1e-5                  # optional: least α (ltc_code's MIN_ALPHA)
//!
//! [emit]
//! function = "ltc_ggx"              # WGSL and Rust function prefix
//! ```
//!
//! Texel (i, j): roughness i/(n − 1) (α = max(r², min_alpha)), sqrt(1 − cos θ) = j/(n − 1)
//! (ltc_code's nodes; a shader samples at uv·(n − 1)/n + 0.5/n). ltc_1 = (a, c, b, d): M⁻¹ over
//! its middle element; ltc_2 = (E, ∫ f cos (1 − v·h)⁵, 0, w) with w the clipped sphere form
//! factor at (cos ω·½ + ½, sin²σ) ([`super::sphere`]).
//!
//! Outputs: `json/NAME.json` (settings, every texel in f64, per-cell δ and mass below the
//! horizon, the end-to-end measurement beside ltc_code's for GGX), `data/NAME_1.ktx2` and
//! `data/NAME_2.ktx2` (RGBA16F, filterable in core WebGPU) and `data/NAME_1_f32.ktx2`,
//! `data/NAME_2_f32.ktx2` (RGBA32F), `data/NAME.h` and `data/NAME.js` (the f32 arrays engines
//! paste), and the light functions (`wgsl/NAME.wgsl`, `src/NAME.rs`: [`super::emit`]).
//! `Mode::Committed` (build --check) reads the texels and δ from the committed JSON and
//! re-renders every file without fitting.

use super::fit::{FIT_NODES, Table as Fitted, fit_table};
use super::{published, reference, sphere};
use crate::emit::texture::{TextureFormat, ktx2_rgba};
use crate::emit::{Artifact, GENERATOR, header_lines};
use crate::family::SpecKind;
use crate::pipeline::{BuildError, Built, Mode, Verification, compact_json, fmt_err, spec_rel_path};
use crate::spec::{CustomSpec, KindDef, Preset, Spec, SpecError, SpecFile, line_of, parse_toml};
use crate::shading::Lobe;
use serde::Deserialize;
use serde_json::json;
use std::path::Path;

/// The `kind` value.
pub const KIND: &str = "ltc-table";
/// Texels per side.
pub const RESOLUTION: [usize; 2] = [8, 128];
/// Nodes per axis of the metric.
pub const NODES: [usize; 2] = [8, 64];

/// The spec kind (registered by the family).
pub const TABLE: SpecKind = SpecKind {
    spec: KindDef {
        name: KIND,
        spec_file: crate::spec::preset_spec_file::<Table>,
        samples_note: "{name} is an LTC table: its texels and per-cell errors are in generated/json/{name}.json (\"ltc_1\", \"ltc_2\", \"distance\")",
        input_hash: crate::pipeline::input_hash,
    },
    build,
    shard: None,
};

/// The lobes a table fits, by the quantity that names them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LobeName {
    /// GGX with height-correlated Smith G2 (ltc_code's `brdf_ggx.h`).
    Ggx,
    /// Charlie sheen with its exact Smith Λ (`crate::shading::charlie`).
    Charlie,
}

impl LobeName {
    pub fn quantity(self) -> &'static str {
        match self {
            LobeName::Ggx => "ltc-ggx-distance",
            LobeName::Charlie => "ltc-sheen-distance",
        }
    }

    /// The least α the lobe is integrated at (Charlie's exact Λ holds from 3e-3).
    pub fn floor(self) -> f64 {
        match self {
            LobeName::Ggx => 1e-6,
            LobeName::Charlie => 3e-3,
        }
    }

    pub fn describe(self) -> &'static str {
        match self {
            LobeName::Ggx => "GGX D G2/(4 n.v), height-correlated Smith G2 (ltc_code fit/brdf_ggx.h), F = 1",
            LobeName::Charlie => "Charlie sheen D G2/(4 n.v n.l) with the exact Smith Lambda of the Charlie distribution, F = 1",
        }
    }
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct TableEmit {
    function: String,
    #[allow(dead_code)] // read from the text by the common spec
    targets: Option<Vec<String>>,
    /// The texture's file formats, as for every spec (`[emit] formats`, read the same way).
    #[allow(dead_code)]
    formats: Option<Vec<String>>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct TableFile {
    name: String,
    #[allow(dead_code)] // checked by the caller
    kind: String,
    quantity: String,
    #[serde(default)]
    description: String,
    resolution: Option<usize>,
    nodes: Option<usize>,
    min_alpha: Option<f64>,
    emit: TableEmit,
}

/// A checked LTC table spec.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    pub name: String,
    pub description: String,
    pub function: String,
    pub lobe: LobeName,
    pub n: usize,
    pub nodes: usize,
    pub min_alpha: f64,
}

impl Preset for Table {
    const KIND: &'static str = KIND;

    fn parse(path: &Path, text: &str) -> Result<Table, SpecError> {
        let f: TableFile = parse_toml(path, text)?;
        let at = |field: &str, msg: String| SpecError::new(path, line_of(text, field), field, msg);
        let lobe = match f.quantity.as_str() {
            "ltc-ggx-distance" => LobeName::Ggx,
            "ltc-sheen-distance" => LobeName::Charlie,
            q => return Err(at("quantity", format!("'{q}': kind = \"{KIND}\" fits ltc-ggx-distance or ltc-sheen-distance"))),
        };
        let n = f.resolution.unwrap_or(published::SIZE);
        if !(RESOLUTION[0]..=RESOLUTION[1]).contains(&n) {
            return Err(at("resolution", format!("{n} texels: must be in [{}, {}]", RESOLUTION[0], RESOLUTION[1])));
        }
        let nodes = f.nodes.unwrap_or(FIT_NODES);
        if !(NODES[0]..=NODES[1]).contains(&nodes) {
            return Err(at("nodes", format!("{nodes} must be in [{}, {}]", NODES[0], NODES[1])));
        }
        let min_alpha = f.min_alpha.unwrap_or(published::MIN_ALPHA.max(lobe.floor()));
        if !(min_alpha >= lobe.floor() && min_alpha <= 0.5) {
            return Err(at("min_alpha", format!("{min_alpha} must be in [{:e}, 0.5] for this lobe", lobe.floor())));
        }
        Ok(Table { name: f.name, description: f.description, function: f.emit.function, lobe, n, nodes, min_alpha })
    }

    /// The common spec: α and n·v over the table's cells.
    fn common(&self, path: &Path, text: &str) -> Result<SpecFile, SpecError> {
        let n_dot_v_min = super::fit::MAX_THETA.cos();
        let axes = vec![
            json!({"name": "alpha", "range": [self.min_alpha, 1.0], "count": self.n, "verify": self.n}),
            json!({"name": "n_dot_v", "range": [n_dot_v_min, 1.0], "count": self.n, "verify": self.n}),
        ];
        CustomSpec { kind: KIND, name: &self.name, quantity: self.lobe.quantity(), description: &self.description, tolerance: 1e-3, axes, function: &self.function }
            .spec_file(path, text)
    }
}

/// The fitted texels of a table: ltc_1 and ltc_2 (texel i + j n) and δ per cell.
#[derive(Debug, Clone, PartialEq)]
pub struct Texels {
    pub ltc_1: Vec<[f64; 4]>,
    pub ltc_2: Vec<[f64; 4]>,
    pub distance: Vec<f64>,
    /// |δ(n) − δ(2n)| per cell: the estimate of the error of `distance`.
    pub distance_error: Vec<f64>,
    /// Cells the repair pass refitted (0 when read back).
    pub repaired: usize,
}

/// Fits a table spec's texels.
pub fn fit(t: &Table) -> Texels {
    match t.lobe {
        LobeName::Ggx => texels(t, fit_table(t.n, t.min_alpha, t.nodes, &published::ggx)),
        LobeName::Charlie => texels(t, fit_table(t.n, t.min_alpha, t.nodes, &crate::shading::charlie::Charlie::new)),
    }
}

fn texels(t: &Table, f: Fitted) -> Texels {
    let w = sphere::table(t.n);
    let ltc_1: Vec<[f64; 4]> = f.cells.iter().map(|c| c.ltc.texel()).collect();
    let (distance, distance_error) = distances(t, &ltc_1);
    Texels {
        ltc_2: f.cells.iter().zip(&w).map(|(c, &w)| [c.magnitude, c.fresnel, 0.0, w]).collect(),
        ltc_1,
        distance,
        distance_error,
        repaired: f.repaired,
    }
}

/// δ of each cell's LTC (texels of ltc_1) at twice the fit's nodes, and |δ(n) − δ(2n)| (the fit
/// minimised δ(n), whose kinks converge as n⁻²: the reported δ is the finer rule's).
pub fn distances(t: &Table, ltc_1: &[[f64; 4]]) -> (Vec<f64>, Vec<f64>) {
    use rayon::prelude::*;
    fn of<L: Lobe>(t: &Table, ltc_1: &[[f64; 4]], lobe: &(dyn Fn(f64) -> L + Sync)) -> (Vec<f64>, Vec<f64>) {
        (0..t.n * t.n)
            .into_par_iter()
            .map(|k| {
                let (alpha, theta) = super::fit::cell_parameters(k % t.n, k / t.n, t.n, t.min_alpha);
                let ltc = super::transform::Ltc::from_texel(ltc_1[k]);
                super::fit::distance_with_error(&lobe(alpha), theta, &ltc, t.nodes)
            })
            .unzip()
    }
    match t.lobe {
        LobeName::Ggx => of(t, ltc_1, &published::ggx),
        LobeName::Charlie => of(t, ltc_1, &crate::shading::charlie::Charlie::new),
    }
}

/// Root mean square of `v`.
fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|d| d * d).sum::<f64>() / v.len() as f64).sqrt()
}

/// The texels rounded to binary16 (what an RGBA16F texture holds).
pub fn half(texels: &[[f64; 4]]) -> Vec<[f64; 4]> {
    texels.iter().map(|t| t.map(|x| half::f16::from_f64(x).to_f64())).collect()
}

/// The end-to-end measurement of the RGBA16F texels of `x` (and of ltc_code's for GGX):
/// [`reference::summary`]s and the per-pair shares.
fn end_to_end(t: &Table, x: &Texels) -> (serde_json::Value, [f64; 6]) {
    /// The committed (light, view) references and the per-cell errors of `tables`, for one lobe.
    #[allow(clippy::type_complexity)]
    fn integrals<L: Lobe>(lobe: &(dyn Fn(f64) -> L + Sync), t: &Table, tables: &[(&[[f64; 4]], &[[f64; 4]])]) -> (Vec<(f64, f64, f64)>, Vec<Option<(Vec<f64>, f64)>>) {
        (reference::references(lobe), reference::per_cell(lobe, t.n, t.min_alpha, tables))
    }
    let (h1, h2) = (half(&x.ltc_1), half(&x.ltc_2));
    let published_tables = (t.lobe == LobeName::Ggx && t.n == published::SIZE).then(published::tables);
    let mut tables: Vec<(&[[f64; 4]], &[[f64; 4]])> = vec![(&h1, &h2)];
    if let Some((p1, p2)) = &published_tables {
        tables.push((p1, p2));
    }
    let (r, cells) = match t.lobe {
        LobeName::Ggx => integrals(&published::ggx, t, &tables),
        LobeName::Charlie => integrals(&|a: f64| crate::shading::charlie::Charlie::new(a.max(LobeName::Charlie.floor())), t, &tables),
    };
    let ours = reference::measure(&h1, &h2, t.n, &r);
    let s = reference::summary(&ours);
    let row = |s: [f64; 6]| {
        json!({"clipped_max": s[0], "clipped_rms": s[1], "sphere_max": s[2], "sphere_rms": s[3], "relative_max_where_reference_at_least_e_over_20": s[4]})
    };
    let mut out = json!({
        "metric": "|LTC result - reference| / E(n.v) per (light, view): the error as a share of the lobe's energy; texels in binary16, bilinear at (roughness, sqrt(1 - n.v))",
        "reference": format!("the lobe integrated over each light by nested adaptive G10/K21 at relative tolerance {:e}; largest error estimate / E: {:e}", reference::TOLERANCE * 1e-2, s[5]),
        "lights": reference::lights().iter().map(|l| json!({"name": l.name, "vertices": l.vertices})).collect::<Vec<_>>(),
        "views": reference::views().iter().map(|v| json!({"roughness": v.roughness, "theta": v.theta})).collect::<Vec<_>>(),
        "shadefit": row(s),
        "pairs_layout": "pairs[view * lights + light] = [reference, clipped, sphere, E]",
        "pairs": ours.iter().map(|m| [m.reference, m.clipped, m.sphere, m.energy]).collect::<Vec<_>>(),
    });
    out["per_cell"] = per_cell_json(&cells, published_tables.is_some());
    if let Some((p1, p2)) = published_tables {
        let theirs = reference::measure(&p1, &p2, t.n, &r);
        out["ltc_code"] = row(reference::summary(&theirs));
        out["ltc_code_pairs"] = json!(theirs.iter().map(|m| [m.clipped, m.sphere]).collect::<Vec<_>>());
        out["per_cell_versus_ltc_code"] = versus_published(t, x, &p1);
    }
    (out, s)
}

/// The per-cell end-to-end errors ([`reference::per_cell`]: shadefit's, and ltc_code's when
/// `published`) with their max, rms and how many cells are no worse.
fn per_cell_json(cells: &[Option<(Vec<f64>, f64)>], published: bool) -> serde_json::Value {
    let column = |c: usize| -> Vec<Option<f64>> { cells.iter().map(|x| x.as_ref().map(|(w, _)| w[c])).collect() };
    let stats = |v: &[Option<f64>]| {
        let x: Vec<f64> = v.iter().flatten().copied().collect();
        (x.iter().copied().fold(0.0, f64::max), rms(&x))
    };
    let ours = column(0);
    let (max, rms) = stats(&ours);
    let measured = ours.iter().flatten().count();
    let mut out = json!({
        "metric": format!("per cell at its node, roughness >= {}: max over the committed lights of |LTC result - reference| / E through the cell's own binary16 texels (clipped path); null below that roughness", reference::PER_CELL_MIN_ROUGHNESS),
        "cells": measured,
        "reference_error_max": cells.iter().flatten().map(|(_, e)| *e).fold(0.0, f64::max),
        "shadefit_max": max,
        "shadefit_rms": rms,
        "shadefit": ours,
    });
    if published {
        let theirs = column(1);
        let (tmax, trms) = stats(&theirs);
        let no_worse = ours.iter().zip(&theirs).filter(|(a, b)| matches!((a, b), (Some(a), Some(b)) if a <= b)).count();
        out["ltc_code_max"] = json!(tmax);
        out["ltc_code_rms"] = json!(trms);
        out["no_worse_than_ltc_code"] = json!(no_worse);
        out["no_worse_than_ltc_code_share"] = json!(no_worse as f64 / measured.max(1) as f64);
        out["ltc_code"] = json!(theirs);
    }
    out
}

/// Per cell, ltc_code's δ (at the table's nodes) and mass below the horizon beside the table's:
/// how many cells are no worse in each.
fn versus_published(t: &Table, x: &Texels, p1: &[[f64; 4]]) -> serde_json::Value {
    let (theirs, _) = distances(t, p1);
    let below = |q: &[f64; 4]| super::transform::Ltc::from_texel(*q).mass_below_horizon();
    let cells = (t.n * t.n) as f64;
    let no_worse_distance = x.distance.iter().zip(&theirs).filter(|(a, b)| a <= b).count();
    let no_worse_below = x.ltc_1.iter().zip(p1).filter(|(a, b)| below(a) <= below(b)).count();
    // The cells that leak more than ltc_code's: by how much, and whether their δ is lower.
    let leak: Vec<(f64, bool)> = (0..t.n * t.n)
        .filter_map(|k| {
            let more = below(&x.ltc_1[k]) - below(&p1[k]);
            (more > 0.0).then_some((more, x.distance[k] <= theirs[k]))
        })
        .collect();
    let within = t.n * t.n - leak.iter().filter(|(m, _)| *m > 1e-4).count();
    json!({
        "cells": t.n * t.n,
        "distance_no_worse": no_worse_distance,
        "distance_no_worse_share": no_worse_distance as f64 / cells,
        "mass_below_horizon_no_worse": no_worse_below,
        "mass_below_horizon_no_worse_share": no_worse_below as f64 / cells,
        "mass_below_horizon_no_worse_within_1e-4": within,
        "mass_below_horizon_most_above_ltc_code": leak.iter().map(|l| l.0).fold(0.0, f64::max),
        "cells_leaking_more_with_lower_distance": leak.iter().filter(|l| l.1).count(),
        "ltc_code_distance_max": theirs.iter().copied().fold(0.0, f64::max),
        "ltc_code_distance_rms": rms(&theirs),
        "ltc_code_mass_below_horizon_max": p1.iter().map(below).fold(0.0, f64::max),
        "ltc_code_distance": theirs,
    })
}

pub(super) fn committed(v: &serde_json::Value, t: &Table) -> Result<Texels, BuildError> {
    let bad = |why: String| BuildError::NoCommitted { spec: t.name.clone(), why };
    let quad = |key: &str| -> Result<Vec<[f64; 4]>, BuildError> {
        let a = v[key].as_array().ok_or_else(|| bad(format!("no '{key}' array")))?;
        if a.len() != t.n * t.n {
            return Err(bad(format!("'{key}' holds {} texels, the spec asks {}", a.len(), t.n * t.n)));
        }
        a.iter()
            .map(|x| {
                let q = x.as_array().filter(|q| q.len() == 4).and_then(|q| Some([q[0].as_f64()?, q[1].as_f64()?, q[2].as_f64()?, q[3].as_f64()?]));
                q.ok_or_else(|| bad(format!("'{key}': a texel is not 4 numbers")))
            })
            .collect()
    };
    let numbers = |key: &str| -> Result<Vec<f64>, BuildError> {
        let v: Vec<f64> = v[key].as_array().map(|a| a.iter().filter_map(|x| x.as_f64()).collect()).unwrap_or_default();
        if v.len() != t.n * t.n {
            return Err(bad(format!("'{key}' does not hold one number per cell")));
        }
        Ok(v)
    };
    let (distance, distance_error) = (numbers("distance")?, numbers("distance_error")?);
    let repaired = v["statistics"]["repaired_cells"].as_u64().unwrap_or(0) as usize;
    Ok(Texels { ltc_1: quad("ltc_1")?, ltc_2: quad("ltc_2")?, distance, distance_error, repaired })
}

/// The artifacts of a table from its texels.
pub fn render(spec: &Spec, t: &Table, x: &Texels) -> Result<Built, BuildError> {
    let name = spec.file.name.clone();
    let hash = crate::pipeline::input_hash(spec);
    let n = t.n;
    if let Some(k) = x.ltc_1.iter().chain(&x.ltc_2).position(|q| q.iter().any(|v| !v.is_finite())) {
        return Err(BuildError::NonFinite { spec: name, at: vec![(k % (n * n)) as f64] });
    }
    let below: Vec<f64> = x.ltc_1.iter().map(|q| super::transform::Ltc::from_texel(*q).mass_below_horizon()).collect();
    let max_at = |v: &[f64]| v.iter().enumerate().fold((0.0f64, 0usize), |m, (k, &d)| if d > m.0 { (d, k) } else { m });
    let (dmax, worst) = max_at(&x.distance);
    let cell_point = |k: usize| vec![(k % n) as f64 / (n - 1) as f64, (k / n) as f64 / (n - 1) as f64];
    let (e2e, s) = end_to_end(t, x);
    let err_line = format!(
        "end to end over {} lights x {} views, |LTC - reference|/E of the clipped path: max abs {}, rms {}; sphere path max {} rms {}; per cell L1 distance to the lobe max {} rms {}",
        reference::lights().len(),
        reference::views().len(),
        fmt_err(s[0]),
        fmt_err(s[1]),
        fmt_err(s[2]),
        fmt_err(s[3]),
        fmt_err(dmax),
        fmt_err(rms(&x.distance))
    );
    let header = header_lines(&spec_rel_path(spec), &hash, &err_line);
    let provenance = header.join("\n");
    let f32s = |v: &[[f64; 4]]| -> Vec<[f32; 4]> { v.iter().map(|q| q.map(|x| x as f32)).collect() };
    let (l1, l2) = (f32s(&x.ltc_1), f32s(&x.ltc_2));
    let meta = [("shadefit", provenance.as_str())];
    let tex = |v: &[[f32; 4]], f| ktx2_rgba(n as u32, n as u32, v, f, &meta);
    let json = json!({
        "generator": GENERATOR,
        "spec": spec_rel_path(spec),
        "input_hash": hash,
        "name": name,
        "kind": KIND,
        "quantity": t.lobe.quantity(),
        "description": t.description,
        "function": t.function,
        "lobe": t.lobe.describe(),
        "resolution": n,
        "min_alpha": t.min_alpha,
        "nodes": t.nodes,
        "metric": "per cell: delta = int |p - D| over the sphere (p = f cos / E, D the LTC), by Gauss-Legendre on two maps (src/family/ltc/fit.rs) at twice the fit's nodes per axis, distance_error = its change from the fit's nodes; delta/2 bounds the relative error of any light at the cell",
        "axes": [
            {"name": "roughness", "texture_axis": "x", "nodes": "i/(n - 1); alpha = max(roughness^2, min_alpha)"},
            {"name": "sqrt(1 - cos theta)", "texture_axis": "y", "nodes": "j/(n - 1); theta at most 1.57"},
        ],
        "sampling": "uv = (roughness, sqrt(1 - n.v)) * (n - 1)/n + 0.5/n, linear, clamp to edge",
        "ltc_1_layout": "ltc_1[i + j n] = (a, c, b, d): M^-1 = [[a, 0, b], [0, 1, 0], [c, 0, d]] (ltc_code's packing)",
        "ltc_2_layout": "ltc_2[i + j n] = (E, int f cos (1 - v.h)^5, 0, clipped sphere form factor / sin^2 sigma at x = cos(omega)/2 + 1/2, y = sin^2 sigma)",
        "textures": {
            "rgba16float": [format!("data/{name}_1.ktx2"), format!("data/{name}_2.ktx2")],
            "rgba32float": [format!("data/{name}_1_f32.ktx2"), format!("data/{name}_2_f32.ktx2")],
            "arrays": [format!("data/{name}.h"), format!("data/{name}.js")],
        },
        "statistics": {
            "distance_max": dmax,
            "distance_rms": rms(&x.distance),
            "distance_error_max": x.distance_error.iter().copied().fold(0.0, f64::max),
            "distance_worst_cell": cell_point(worst),
            "mass_below_horizon_max": max_at(&below).0,
            "mass_below_horizon_rms": rms(&below),
            "repaired_cells": x.repaired,
        },
        "end_to_end": e2e,
        "distance": x.distance,
        "distance_error": x.distance_error,
        "mass_below_horizon": below,
        "ltc_1": x.ltc_1,
        "ltc_2": x.ltc_2,
    });
    let verification = Verification {
        points: e2e_pairs(),
        max_abs_error: s[0],
        rms_error: s[1],
        worst_point: cell_point(worst),
        max_abs_error_f32: s[0],
        rms_error_f32: s[1],
        max_abs_error_in_parameter: None,
    };
    let (wgsl, rust) = super::emit::module(&name, &t.function, n, &header);
    let artifacts = vec![
        Artifact { path: format!("wgsl/{name}.wgsl").into(), contents: wgsl.into() },
        Artifact { path: format!("src/{name}.rs").into(), contents: rust.into() },
        Artifact { path: format!("json/{name}.json").into(), contents: compact_json(&json).into() },
        Artifact { path: format!("data/{name}_1.ktx2").into(), contents: tex(&l1, TextureFormat::Rgba16float) },
        Artifact { path: format!("data/{name}_2.ktx2").into(), contents: tex(&l2, TextureFormat::Rgba16float) },
        Artifact { path: format!("data/{name}_1_f32.ktx2").into(), contents: tex(&l1, TextureFormat::Rgba32float) },
        Artifact { path: format!("data/{name}_2_f32.ktx2").into(), contents: tex(&l2, TextureFormat::Rgba32float) },
        Artifact { path: format!("data/{name}.h").into(), contents: arrays_c(&name, n, &header, &l1, &l2).into() },
        Artifact { path: format!("data/{name}.js").into(), contents: arrays_js(&name, n, &header, &l1, &l2).into() },
    ];
    Ok(Built { name, artifacts, verification, fit: None })
}

fn e2e_pairs() -> usize {
    reference::lights().len() * reference::views().len()
}

fn numbers(v: &[[f32; 4]]) -> String {
    let mut s = String::new();
    for (k, q) in v.iter().enumerate() {
        s.push_str(if k % 4 == 0 { "\n    " } else { " " });
        s.push_str(&q.iter().map(|x| crate::emit::f32_literal(*x)).collect::<Vec<_>>().join(", "));
        s.push(',');
    }
    s
}

/// The C form: two `static const float` arrays of n·n RGBA texels (row j, column i).
fn arrays_c(name: &str, n: usize, header: &[String], l1: &[[f32; 4]], l2: &[[f32; 4]]) -> String {
    let up = name.to_uppercase();
    let mut s: String = header.iter().map(|l| format!("// {l}\n")).collect();
    s.push_str(&format!("// LTC tables, {n} x {n} RGBA texels each, texel i + j*{n} (see json/{name}.json for the layout).\n"));
    s.push_str(&format!("#ifndef {up}_H\n#define {up}_H\n\n#define {up}_SIZE {n}\n\n"));
    s.push_str(&format!("static const float {up}_1[{}] = {{{}\n}};\n\n", 4 * n * n, numbers(l1)));
    s.push_str(&format!("static const float {up}_2[{}] = {{{}\n}};\n\n#endif\n", 4 * n * n, numbers(l2)));
    s
}

/// The JavaScript form: two Float32Arrays (three.js: `new DataTexture(ARRAY, n, n, RGBAFormat, FloatType)`).
fn arrays_js(name: &str, n: usize, header: &[String], l1: &[[f32; 4]], l2: &[[f32; 4]]) -> String {
    let up = name.to_uppercase();
    let mut s: String = header.iter().map(|l| format!("// {l}\n")).collect();
    s.push_str(&format!("// LTC tables, {n} x {n} RGBA texels each, texel i + j*{n} (see json/{name}.json for the layout).\n"));
    s.push_str(&format!("export const {up}_SIZE = {n};\n"));
    s.push_str(&format!("export const {up}_1 = new Float32Array([{}\n]);\n", numbers(l1)));
    s.push_str(&format!("export const {up}_2 = new Float32Array([{}\n]);\n", numbers(l2)));
    s
}

/// Build a table spec: fit (Fit) or read the texels (Committed), then render.
pub fn build(spec: &Spec, mode: Mode, root: &Path) -> Result<Built, BuildError> {
    let t = Table::from_spec(spec)?;
    let x = match mode {
        Mode::Fit => fit(&t),
        Mode::Committed => {
            let v = crate::pipeline::committed_json_with_hash(root, spec, &crate::pipeline::input_hash(spec))?;
            committed(&v, &t)?
        }
    };
    render(spec, &t, &x)
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    pub const SPEC: &str = "name = \"ltc_t\"\nkind = \"ltc-table\"\nquantity = \"ltc-ggx-distance\"\n\
        resolution = 8\nnodes = 12\n\n[emit]\nfunction = \"ltc_t\"\n";

    fn spec(text: &str) -> Spec {
        Spec::parse(Path::new("fits/ltc_t.toml"), text.to_string(), crate::family::catalog()).unwrap()
    }

    #[test]
    fn errors_name_line_and_field() {
        let bad = |edit: (&str, &str), line: usize, field: &str, msg: &str| {
            let text = SPEC.replace(edit.0, edit.1);
            let e = Spec::parse(Path::new("fits/ltc_t.toml"), text, crate::family::catalog()).unwrap_err();
            assert_eq!((e.line, e.field.as_str()), (line, field), "{e}");
            assert!(e.msg.contains(msg), "{e}");
        };
        bad(("resolution = 8", "resolution = 4"), 4, "resolution", "must be in");
        bad(("nodes = 12", "nodes = 2"), 5, "nodes", "must be in");
        bad(("nodes = 12", "nodes = 12\nmin_alpha = 0.9"), 6, "min_alpha", "must be in");
        bad(("quantity = \"ltc-ggx-distance\"", "quantity = \"ggx-albedo\""), 3, "quantity", "fits ltc-ggx-distance");
        bad(("nodes = 12", "nodes = 12\nmin_alpha = nan"), 6, "min_alpha", "must be in");
    }

    /// A small table builds in both modes to the same bytes: the committed JSON holds every
    /// texel the files are rendered from (Fit, then Committed reading Fit's JSON).
    #[test]
    fn committed_texels_render_the_same_files() {
        let s = spec(SPEC);
        let t = Table::from_spec(&s).unwrap();
        let x = fit(&t);
        let built = render(&s, &t, &x).unwrap();
        let dir = std::env::temp_dir().join(format!("ltc_table_test_{}", std::process::id()));
        std::fs::create_dir_all(dir.join("json")).unwrap();
        let json = built.artifacts.iter().find(|a| a.path.ends_with("json/ltc_t.json")).unwrap();
        std::fs::write(dir.join("json/ltc_t.json"), &json.contents).unwrap();
        let again = build(&s, Mode::Committed, &dir).unwrap();
        std::fs::remove_dir_all(&dir).ok();
        assert_eq!(built.artifacts, again.artifacts);
        // The ltc_2.w channel is the sphere table's, and the normal-incidence row isotropic.
        assert_eq!(x.ltc_2[3][3], sphere::clipped_ratio(2.0 * 3.0 / 7.0 - 1.0, 0.0));
        assert!(x.ltc_1[..8].iter().all(|q| q[0] == 1.0 && q[1] == 0.0 && q[2] == 0.0));
    }
}
