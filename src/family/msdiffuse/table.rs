//! Simulated tables (`kind = "ms-diffuse-table"`): 2-D slices f(θh, θd) of the BRDF at several
//! glosses and the directional albedo, each cell a Monte Carlo estimate with its standard error.
//!
//! ```toml
//! name = "ms_diffuse_slices"        # output stem; must equal the file stem
//! kind = "ms-diffuse-table"
//! quantity = "ms-diffuse"
//! description = "..."
//! resolution = [32, 32, 5]          # [θh columns, θd rows, gloss layers]
//! phi_d = 1.5707963267948966        # optional: the slice's φd (π/2, BRDF Explorer's default)
//! f0 = 0.04                         # optional: Schlick F0 of the facets (the talk's 0.04)
//! specular = "gone"                 # optional: "gone" (the talk) or "walks"
//! paths = 4096                      # random-walk paths per slice cell
//! albedo_resolution = 32            # optional: n·v columns of the albedo table per gloss
//! albedo_paths = 4096               # optional: paths per albedo cell
//! merl_paths = 64                   # optional: also the full isotropic BRDF of every gloss
//!                                   # layer in MERL's binary layout (90·90·180 cells each,
//!                                   # these paths a cell; 35 MB a layer: for jobs, not fits/)
//!
//! [emit]
//! function = "ms_diffuse_slice"     # WGSL and Rust function prefix
//! ```
//!
//! Cell (i, j) of layer k: θh = (i + 0.5)/W · π/2, θd = (j + 0.5)/H · π/2 (centres), gloss
//! g_k = k/(G − 1) (ends included); albedo cell (a, k): n·v = (a + 0.5)/A. Cells are numbered
//! slices first (k, j, i, i fastest), then the albedo cells (k, a), then the MERL cells (k, then
//! the file's order); the RNG key is the spec name, so any cell's bits depend only on (name,
//! cell, path).
//!
//! Outputs: `json/NAME.json` (settings, every cell's value and standard error in f64, the albedo
//! table, statistics), `data/NAME.ktx2` (RG32F atlas: layer k at rows kH…kH + H − 1, R = π f/ρ,
//! G = its standard error), `data/NAME.png` (sRGB preview of R), and a small runtime module
//! (`wgsl/NAME.wgsl`, `src/NAME.rs`) mapping (n·h, l·h, gloss) to atlas coordinates; with
//! `merl_paths`, `data/NAME_merl_K.binary` per layer K (`super::merl`).
//! `Mode::Committed` (build --check) reads the values from the committed JSON (and MERL files)
//! and re-renders every file without simulating.

use super::integrals::{TALK_F0, albedo, at_cosine, brdf, directions, surface, Order};
use super::merl;
use super::walk::{Specular, key_of};
use crate::emit::texture::{TextureFormat, ktx2_texels, png_srgb_preview};
use crate::emit::{Artifact, GENERATOR, f32_literal, header_lines};
use crate::family::SpecKind;
use crate::pipeline::{BuildError, Built, Mode, Verification, compact_json, fmt_err, spec_rel_path};
use crate::spec::{CustomSpec, KindDef, Preset, Spec, SpecError, SpecFile, line_of, parse_toml};
use rayon::prelude::*;
use serde::Deserialize;
use serde_json::json;
use crate::pipeline::{Grid, GridAxis};
use crate::spec::table::{self, AxisMapping, Placement};
use std::f64::consts::{FRAC_PI_2, PI};

fn quarter_turn(t: f64) -> f64 {
    t * FRAC_PI_2
}

/// A texel coordinate t ∈ [0, 1] to the angle t·π/2 (θh and θd of the slices).
static QUARTER_TURN: AxisMapping = AxisMapping { name: "quarter-turn", doc: "t, parameter t*pi/2", to_parameter: quarter_turn, argument: [0.0, 1.0] };
use std::path::Path;

/// The `kind` value.
pub const KIND: &str = "ms-diffuse-table";
/// Limits: a side of a slice, gloss layers, paths per cell.
pub const MAX_SIDE: usize = 256;
pub const MAX_LAYERS: usize = 64;
pub const PATHS_RANGE: [u64; 2] = [256, 1 << 24];

/// The spec kind (registered by the family).
pub const TABLE: SpecKind = SpecKind {
    spec: KindDef {
        name: KIND,
        spec_file: crate::spec::preset_spec_file::<Table>,
        samples_note: "{name} is a simulated table: its cells are in generated/json/{name}.json (\"slices\", \"albedo\")",
        input_hash: crate::pipeline::input_hash,
    },
    build,
    shard: Some(crate::family::Sharding { cells: shard_cells, compute: shard_compute }),
};

fn shard_cells(spec: &Spec) -> Result<u64, BuildError> {
    Ok(Table::from_spec(spec)?.cells())
}

/// The payload of a range of cells: each cell's value and standard error, f64 little-endian.
fn shard_compute(spec: &Spec, range: std::ops::Range<u64>) -> Result<Vec<u8>, BuildError> {
    let t = Table::from_spec(spec)?;
    Ok(t.simulate(range).iter().flat_map(|c| [c.value.to_le_bytes(), c.se.to_le_bytes()]).flatten().collect())
}

fn cells_of_payload(t: &Table, bytes: &[u8]) -> Result<Vec<Cell>, BuildError> {
    if bytes.len() as u64 != 16 * t.cells() {
        return Err(BuildError::NoCommitted { spec: t.name.clone(), why: format!("merged shards hold {} bytes, {} cells need {}", bytes.len(), t.cells(), 16 * t.cells()) });
    }
    Ok(bytes
        .chunks(16)
        .map(|c| Cell { value: f64::from_le_bytes(c[..8].try_into().unwrap()), se: f64::from_le_bytes(c[8..].try_into().unwrap()) })
        .collect())
}

#[derive(Debug, Clone, Copy, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
enum SpecularName {
    #[default]
    Gone,
    Walks,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct TableEmit {
    function: String,
    /// Outputs besides the WGSL module, as for every spec (`[emit] targets`; the common spec
    /// reads them from the text: `spec::CustomSpec::spec_file`).
    #[allow(dead_code)]
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
    resolution: Vec<usize>,
    phi_d: Option<f64>,
    f0: Option<f64>,
    #[serde(default)]
    specular: SpecularName,
    paths: u64,
    albedo_resolution: Option<usize>,
    albedo_paths: Option<u64>,
    merl_paths: Option<u64>,
    emit: TableEmit,
}

/// A checked table spec.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    pub name: String,
    pub description: String,
    pub function: String,
    pub width: usize,
    pub height: usize,
    pub layers: usize,
    pub phi_d: f64,
    pub f0: f64,
    pub specular: Specular,
    pub paths: u64,
    pub albedo_width: usize,
    pub albedo_paths: u64,
    pub merl_paths: Option<u64>,
}

impl Table {

    /// The slices' grid, as the table kind's: θh columns and θd rows at the texel centres of
    /// [0, 1] mapped to [0, π/2], gloss layers at the nodes of [0, 1] (parameters 1, 2, 0 of
    /// ms-diffuse).
    pub fn slices_grid(&self) -> Grid {
        let angle = |count, param| GridAxis { range: [0.0, 1.0], count, placement: Placement::Centres, mapping: &QUARTER_TURN, param };
        Grid { axes: vec![angle(self.width, 1), angle(self.height, 2), self.layers_axis()] }
    }

    /// The albedo table's grid: n·v at the texel centres of [0, 1], the gloss layers.
    pub fn albedo_grid(&self) -> Grid {
        let n_dot_v = GridAxis { range: [0.0, 1.0], count: self.albedo_width, placement: Placement::Centres, mapping: &table::LINEAR, param: 1 };
        Grid { axes: vec![n_dot_v, self.layers_axis()] }
    }

    fn layers_axis(&self) -> GridAxis {
        GridAxis { range: [0.0, 1.0], count: self.layers, placement: Placement::Nodes, mapping: &table::LINEAR, param: 0 }
    }

    /// Parameter of point `i` on axis `k` of `grid`.
    fn at(grid: Grid, k: usize, i: usize) -> f64 {
        let a = &grid.axes[k];
        a.parameter(a.argument(i))
    }

    pub fn theta_h(&self, i: usize) -> f64 {
        Table::at(self.slices_grid(), 0, i)
    }

    pub fn theta_d(&self, j: usize) -> f64 {
        Table::at(self.slices_grid(), 1, j)
    }

    pub fn gloss(&self, k: usize) -> f64 {
        Table::at(self.slices_grid(), 2, k)
    }

    pub fn n_dot_v(&self, a: usize) -> f64 {
        Table::at(self.albedo_grid(), 0, a)
    }

    pub fn slice_cells(&self) -> u64 {
        (self.width * self.height * self.layers) as u64
    }

    pub fn albedo_cells(&self) -> u64 {
        (self.albedo_width * self.layers) as u64
    }

    pub fn merl_cells(&self) -> u64 {
        if self.merl_paths.is_some() { (merl::CELLS * self.layers) as u64 } else { 0 }
    }

    /// Every cell: slices, then albedo, then MERL.
    pub fn cells(&self) -> u64 {
        self.slice_cells() + self.albedo_cells() + self.merl_cells()
    }

    pub fn key(&self) -> u64 {
        key_of(&self.name)
    }

    /// Cell `c` (its paths sequential, in chunk order).
    pub fn cell(&self, c: u64) -> Cell {
        let n = self.slice_cells();
        let key = self.key();
        if c < n {
            let (w, h) = (self.width as u64, self.height as u64);
            let (i, j, k) = ((c % w) as usize, ((c / w) % h) as usize, (c / (w * h)) as usize);
            let s = surface(self.gloss(k), self.f0, self.specular);
            let (l, v) = directions(self.theta_h(i), self.theta_d(j), self.phi_d).expect("slice cells lie above the horizon");
            Cell::of(brdf(&s, l, v, Order::All, key, c, self.paths, false))
        } else if c >= n + self.albedo_cells() {
            let m = (c - n - self.albedo_cells()) as usize;
            let (k, cell) = (m / merl::CELLS, m % merl::CELLS);
            let (th, td, pd) = merl::cell_angles(cell);
            let s = surface(self.gloss(k), self.f0, self.specular);
            // The MERL cell stores the red value of f = (π f/ρ)/π at ρ = 1; se of the same.
            match directions(th, td, pd) {
                Some((l, v)) => {
                    let e = brdf(&s, l, v, Order::All, key, c, self.merl_paths.unwrap_or(1), false);
                    Cell { value: merl::red_of(Some(e.value / PI)), se: e.error / PI / merl::SCALES[0] }
                }
                None => Cell { value: merl::red_of(None), se: 0.0 },
            }
        } else {
            let a = ((c - n) % self.albedo_width as u64) as usize;
            let k = ((c - n) / self.albedo_width as u64) as usize;
            let s = surface(self.gloss(k), self.f0, self.specular);
            Cell::of(albedo(&s, at_cosine(self.n_dot_v(a)), key, c, self.albedo_paths, false))
        }
    }

    /// The cells in `range`, in parallel, collected in order.
    pub fn simulate(&self, range: std::ops::Range<u64>) -> Vec<Cell> {
        range.into_par_iter().map(|c| self.cell(c)).collect()
    }

}

impl Preset for Table {
    const KIND: &'static str = KIND;

    fn parse(path: &Path, text: &str) -> Result<Table, SpecError> {
        let f: TableFile = parse_toml(path, text)?;
        let at = |field: &str, msg: String| SpecError::new(path, line_of(text, field), field, msg);
        if f.quantity != "ms-diffuse" {
            return Err(at("quantity", format!("'{}': kind = \"{KIND}\" tabulates 'ms-diffuse'", f.quantity)));
        }
        if f.resolution.len() != 3 {
            return Err(at("resolution", format!("needs resolution = [theta_h columns, theta_d rows, gloss layers], found {} numbers", f.resolution.len())));
        }
        let (w, h, g) = (f.resolution[0], f.resolution[1], f.resolution[2]);
        if !(2..=MAX_SIDE).contains(&w) || !(2..=MAX_SIDE).contains(&h) || !(1..=MAX_LAYERS).contains(&g) {
            return Err(at("resolution", format!("[{w}, {h}, {g}]: sides must be in [2, {MAX_SIDE}], layers in [1, {MAX_LAYERS}]")));
        }
        let phi_d = f.phi_d.unwrap_or(FRAC_PI_2);
        if !(0.0..=PI).contains(&phi_d) {
            return Err(at("phi_d", format!("{phi_d} must be in [0, π]")));
        }
        let f0 = f.f0.unwrap_or(TALK_F0);
        if !(0.0..=1.0).contains(&f0) {
            return Err(at("f0", format!("{f0} must be in [0, 1]")));
        }
        let paths_ok = |p: u64| (PATHS_RANGE[0]..=PATHS_RANGE[1]).contains(&p);
        if !paths_ok(f.paths) {
            return Err(at("paths", format!("{} must be in [{}, {}]", f.paths, PATHS_RANGE[0], PATHS_RANGE[1])));
        }
        let albedo_paths = f.albedo_paths.unwrap_or(f.paths);
        if !paths_ok(albedo_paths) {
            return Err(at("albedo_paths", format!("{albedo_paths} must be in [{}, {}]", PATHS_RANGE[0], PATHS_RANGE[1])));
        }
        if let Some(p) = f.merl_paths
            && !(2..=PATHS_RANGE[1]).contains(&p)
        {
            return Err(at("merl_paths", format!("{p} must be in [2, {}] (two paths give a standard error)", PATHS_RANGE[1])));
        }
        let albedo_width = f.albedo_resolution.unwrap_or(32);
        if !(2..=MAX_SIDE).contains(&albedo_width) {
            return Err(at("albedo_resolution", format!("{albedo_width} must be in [2, {MAX_SIDE}]")));
        }
        Ok(Table {
            name: f.name,
            description: f.description,
            function: f.emit.function,
            width: w,
            height: h,
            layers: g,
            phi_d,
            f0,
            specular: match f.specular {
                SpecularName::Gone => Specular::Gone,
                SpecularName::Walks => Specular::Walks,
            },
            paths: f.paths,
            albedo_width,
            albedo_paths,
            merl_paths: f.merl_paths,
        })
    }

    /// The common spec: every parameter of ms-diffuse as an axis.
    fn common(&self, path: &Path, text: &str) -> Result<SpecFile, SpecError> {
        let one = |name: &str, x: f64| json!({"name": name, "range": [x, x], "count": 1, "verify": 1});
        let walks = if self.specular == Specular::Walks { 1.0 } else { 0.0 };
        let axes = vec![
            json!({"name": "gloss", "range": [0.0, self.gloss(self.layers - 1)], "count": self.layers, "verify": self.layers}),
            json!({"name": "theta_h", "range": [self.theta_h(0), self.theta_h(self.width - 1)], "count": self.width, "verify": self.width}),
            json!({"name": "theta_d", "range": [self.theta_d(0), self.theta_d(self.height - 1)], "count": self.height, "verify": self.height}),
            one("phi_d", self.phi_d),
            one("f0", self.f0),
            one("specular_walks", walks),
        ];
        CustomSpec {
            kind: KIND,
            name: &self.name,
            quantity: "ms-diffuse",
            description: &self.description,
            tolerance: 1.0 / (self.paths as f64).sqrt(),
            axes,
            function: &self.function,
        }
        .spec_file(path, text)
        .map(|mut file| {
            // `f0` is reserved for the emitted bodies' locals: the arguments are named here.
            file.emit.args = Some(["gloss", "theta_h", "theta_d", "phi_d", "fresnel_f0", "specular_walks"].map(String::from).to_vec());
            file
        })
    }
}

/// A cell's result: its value and standard error (f64; shards carry these bits).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    pub value: f64,
    pub se: f64,
}

impl Cell {
    pub fn of(e: crate::integrate::Estimate) -> Cell {
        Cell { value: e.value, se: e.error }
    }
}

/// Statistics of a set of cells: the largest standard error, the rms one and the number of
/// the first cell with the largest.
fn stats(cells: &[Cell]) -> (f64, f64, usize) {
    let mut worst = (0.0f64, 0usize);
    let mut ss = 0.0;
    for (k, c) in cells.iter().enumerate() {
        if c.se > worst.0 {
            worst = (c.se, k);
        }
        ss += c.se * c.se;
    }
    (worst.0, (ss / cells.len().max(1) as f64).sqrt(), worst.1)
}

fn committed_cells(v: &serde_json::Value, t: &Table, key: &str, count: usize) -> Result<Vec<Cell>, BuildError> {
    let bad = |why: String| BuildError::NoCommitted { spec: t.name.clone(), why };
    let arr = v[key].as_array().ok_or_else(|| bad(format!("no '{key}' array")))?;
    if arr.len() != count {
        return Err(bad(format!("'{key}' holds {} cells, the spec asks {count}", arr.len())));
    }
    arr.iter()
        .map(|c| {
            let p = c.as_array().filter(|p| p.len() == 2).and_then(|p| Some(Cell { value: p[0].as_f64()?, se: p[1].as_f64()? }));
            p.ok_or_else(|| bad(format!("'{key}': a cell is not [value, standard error]")))
        })
        .collect()
}

/// The artifacts of a table from its cells (slices, then albedo).
pub fn render(spec: &Spec, t: &Table, cells: &[Cell]) -> Result<Built, BuildError> {
    let name = spec.file.name.clone();
    let hash = crate::pipeline::input_hash(spec);
    let n = t.slice_cells() as usize;
    let (slices, rest) = cells.split_at(n);
    let (albedo_cells, merl_cells) = rest.split_at(t.albedo_cells() as usize);
    if let Some(k) = cells.iter().position(|c| !(c.value.is_finite() && c.se.is_finite())) {
        return Err(BuildError::NonFinite { spec: name, at: vec![k as f64] });
    }
    let (max_se, rms_se, worst) = stats(slices);
    let (max_se_a, rms_se_a, _) = stats(albedo_cells);
    let (w, h) = (t.width, t.height);
    let worst_point = vec![t.gloss(worst / (w * h)), t.theta_h(worst % w), t.theta_d((worst / w) % h)];
    let err_line = format!(
        "Monte Carlo standard error of the slice cells (pi f/rho): max abs {}, rms {} over {} cells of {} paths; albedo cells: max abs {}, rms {}",
        fmt_err(max_se),
        fmt_err(rms_se),
        n,
        t.paths,
        fmt_err(max_se_a),
        fmt_err(rms_se_a)
    );
    let header = header_lines(&spec_rel_path(spec), &hash, &err_line);
    let provenance = header.join("\n");
    let flat: Vec<f32> = slices.iter().flat_map(|c| [c.value as f32, c.se as f32]).collect();
    let ktx2 = ktx2_texels(w as u32, (h * t.layers) as u32, 2, &flat, TextureFormat::Rgba32float, &[("shadefit", &provenance)]);
    let preview: Vec<[f64; 3]> = slices.iter().map(|c| [c.value / 2.0; 3]).collect();
    let s = (256 / w.max(h)).max(1);
    let png = png_srgb_preview(w, h * t.layers, &preview, s, s, &[("Software", GENERATOR.to_string()), ("Comment", provenance.clone())]);
    let specular = match t.specular {
        Specular::Gone => "gone: the share F reflected specularly at a facet leaves the diffuse term (the talk)",
        Specular::Walks => "walks: the share F continues as a mirror reflection and counts once diffused",
    };
    let glosses: Vec<f64> = (0..t.layers).map(|k| t.gloss(k)).collect();
    let json = json!({
        "generator": GENERATOR,
        "spec": spec_rel_path(spec),
        "input_hash": hash,
        "name": name,
        "kind": KIND,
        "quantity": "ms-diffuse",
        "description": t.description,
        "function": t.function,
        "model": "Heitz et al. 2016 random walk (Smith height model, GGX visible normals), Lambertian facets rho = 1, Schlick Fresnel on both crossings of a facet",
        "value": "pi f / rho (Lambert = 1)",
        "f0": t.f0,
        "specular": specular,
        "phi_d": t.phi_d,
        "gloss": glosses,
        "alpha": glosses.iter().map(|&g| crate::shading::roughness::alpha_from_gloss(g)).collect::<Vec<_>>(),
        "axes": [
            {"name": "theta_h", "texture_axis": "x", "count": w, "texel_centres": "theta_h = (i + 0.5)/width * pi/2"},
            {"name": "theta_d", "texture_axis": "y within a layer", "count": h, "texel_centres": "theta_d = (j + 0.5)/height * pi/2"},
            {"name": "gloss", "texture_axis": "layer k at rows k*height .. k*height + height - 1", "count": t.layers, "values": "gloss = k/(layers - 1)"},
        ],
        "paths": {"slice": t.paths, "albedo": t.albedo_paths, "rng": "SplitMix64 seeded by a hash of (spec name, cell, path)"},
        "statistics": {
            "slice_max_standard_error": max_se,
            "slice_rms_standard_error": rms_se,
            "slice_worst_cell": worst_point,
            "albedo_max_standard_error": max_se_a,
            "albedo_rms_standard_error": rms_se_a,
        },
        "texture": {
            "width": w,
            "height": h * t.layers,
            "format": "rg32float",
            "ktx2": format!("data/{name}.ktx2"),
            "preview": format!("data/{name}.png"),
            "encoding": "linear; R = pi f/rho, G = its standard error; the PNG preview is sRGB-encoded R/2",
        },
        "albedo_axes": {"n_dot_v": "(a + 0.5)/albedo_resolution", "count": t.albedo_width},
        "slices_layout": "layer-major, then theta_d rows, theta_h fastest: slices[(k * height + j) * width + i] = [value, standard error]",
        "slices": slices.iter().map(|c| [c.value, c.se]).collect::<Vec<_>>(),
        "albedo_layout": "albedo[k * albedo_resolution + a] = [albedo, standard error] at gloss k, n_dot_v (a + 0.5)/albedo_resolution",
        "albedo": albedo_cells.iter().map(|c| [c.value, c.se]).collect::<Vec<_>>(),
    });
    let verification = Verification {
        points: n,
        max_abs_error: max_se,
        rms_error: rms_se,
        worst_point: worst_point.clone(),
        max_abs_error_f32: max_se,
        rms_error_f32: rms_se,
        max_abs_error_in_parameter: None,
    };
    let (wgsl, rust) = module(&name, t, &header);
    let mut artifacts = vec![
        Artifact { path: format!("wgsl/{name}.wgsl").into(), contents: wgsl.into() },
        Artifact { path: format!("src/{name}.rs").into(), contents: rust.into() },
        Artifact { path: format!("json/{name}.json").into(), contents: compact_json(&json).into() },
        Artifact { path: format!("data/{name}.ktx2").into(), contents: ktx2 },
        Artifact { path: format!("data/{name}.png").into(), contents: png },
    ];
    for (k, layer) in merl_cells.chunks(merl::CELLS).enumerate() {
        let red: Vec<f64> = layer.iter().map(|c| c.value).collect();
        artifacts.push(Artifact { path: merl_path(&name, k).into(), contents: merl::encode(&red) });
    }
    Ok(Built { name, artifacts, verification, fit: None })
}

/// The MERL file of layer k.
pub fn merl_path(name: &str, k: usize) -> String {
    format!("data/{name}_merl_{k}.binary")
}

/// The runtime module: atlas size and coordinates of (n·h, l·h, gloss).
fn module(name: &str, t: &Table, header: &[String]) -> (String, String) {
    let f = &t.function;
    let up = name.to_uppercase();
    let (w, h, g) = (t.width, t.height, t.layers);
    let two_over_pi = f32_literal((2.0 / PI) as f32);
    let doc = [
        format!("Simulated multiple-scattering diffuse BRDF slices (pi f/rho at phi_d = {}), {w} theta_h columns x {h} theta_d rows per gloss layer, {g} layers stacked as rows (RG32F: R = value, G = standard error).", t.phi_d),
        "Texel centres: theta_h = (i + 0.5)/width * pi/2, theta_d = (j + 0.5)/height * pi/2; layer k holds gloss k/(layers - 1).".to_string(),
    ];
    let mut wgsl = String::new();
    for line in header {
        wgsl.push_str(&format!("// {line}\n"));
    }
    wgsl.push_str(&format!("#define_import_path shadefit::{name}\n\n"));
    for line in &doc {
        wgsl.push_str(&format!("// {line}\n"));
    }
    wgsl.push_str(&format!("\nconst {up}_SIZE: vec3<u32> = vec3<u32>({w}u, {h}u, {g}u);\n\n"));
    wgsl.push_str(&format!(
        "// Coordinates (u, v) within a layer of (n·h, l·h): the angles over pi/2, clamped to [0, 1].\n\
         fn {f}_uv(n_dot_h: f32, l_dot_h: f32) -> vec2<f32> {{\n    \
         let th = acos(clamp(n_dot_h, 0f, 1f)) * {two_over_pi};\n    \
         let td = acos(clamp(l_dot_h, 0f, 1f)) * {two_over_pi};\n    \
         return vec2<f32>(th, td);\n}}\n\n\
         // The continuous layer index of a gloss (layers at gloss k/(layers - 1)).\n\
         fn {f}_layer(gloss: f32) -> f32 {{\n    \
         return clamp(gloss, 0f, 1f) * f32({up}_SIZE.z - 1u);\n}}\n"
    ));
    let mut rust = String::new();
    for line in header {
        rust.push_str(&format!("//! {line}\n"));
    }
    rust.push_str("//!\n");
    for line in &doc {
        rust.push_str(&format!("//! {line}\n"));
    }
    rust.push_str(&format!(
        "\n/// Slice size (theta_h columns, theta_d rows, gloss layers).\npub const {up}_SIZE: [u32; 3] = [{w}, {h}, {g}];\n\
         /// The atlas as a KTX2 texture (RG32F, linear), as written by `shadefit build`.\n\
         pub const {up}_KTX2: &[u8] = include_bytes!(\"../data/{name}.ktx2\");\n\n\
         /// Coordinates (u, v) within a layer of (n·h, l·h): the angles over pi/2, clamped to [0, 1].\n\
         pub fn {f}_uv(n_dot_h: f32, l_dot_h: f32) -> [f32; 2] {{\n    \
         let th = n_dot_h.clamp(0.0, 1.0).acos() * {two_over_pi};\n    \
         let td = l_dot_h.clamp(0.0, 1.0).acos() * {two_over_pi};\n    \
         [th, td]\n}}\n\n\
         /// The continuous layer index of a gloss (layers at gloss k/(layers - 1)).\n\
         pub fn {f}_layer(gloss: f32) -> f32 {{\n    \
         gloss.clamp(0.0, 1.0) * ({up}_SIZE[2] - 1) as f32\n}}\n"
    ));
    (wgsl, rust)
}

/// Build a table spec: simulate every cell (Fit) or read them (Committed), then render.
pub fn build(spec: &Spec, mode: Mode, root: &Path) -> Result<Built, BuildError> {
    let t = Table::from_spec(spec)?;
    let cells = match mode {
        Mode::Fit => match spec.merged.as_deref() {
            Some(bytes) => cells_of_payload(&t, bytes)?,
            None => t.simulate(0..t.cells()),
        },
        Mode::Committed => {
            let v = crate::pipeline::committed_json_with_hash(root, spec, &crate::pipeline::input_hash(spec))?;
            let mut c = committed_cells(&v, &t, "slices", t.slice_cells() as usize)?;
            c.extend(committed_cells(&v, &t, "albedo", t.albedo_width * t.layers)?);
            if t.merl_paths.is_some() {
                // The MERL values are the committed files themselves (the red block; the
                // standard errors are not stored there and are not rendered anywhere).
                for k in 0..t.layers {
                    let bad = |why: String| BuildError::NoCommitted { spec: t.name.clone(), why };
                    let bytes = std::fs::read(root.join(merl_path(&t.name, k))).map_err(|e| bad(format!("{}: {e}", merl_path(&t.name, k))))?;
                    let red = merl::decode_red(&bytes).ok_or_else(|| bad(format!("{} is not a 90x90x180 MERL file", merl_path(&t.name, k))))?;
                    c.extend(red.into_iter().map(|value| Cell { value, se: 0.0 }));
                }
            }
            c
        }
    };
    render(spec, &t, &cells)
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    pub const SPEC: &str = "name = \"msd_t\"\nkind = \"ms-diffuse-table\"\nquantity = \"ms-diffuse\"\n\
        resolution = [4, 3, 2]\npaths = 1024\nalbedo_resolution = 3\n\n[emit]\nfunction = \"msd_t\"\n";

    fn spec(text: &str) -> Spec {
        Spec::parse(Path::new("fits/msd_t.toml"), text.to_string(), crate::family::catalog()).unwrap()
    }

    #[test]
    fn errors_name_line_and_field() {
        let bad = |edit: (&str, &str), line: usize, field: &str, msg: &str| {
            let text = SPEC.replace(edit.0, edit.1);
            let e = Spec::parse(Path::new("fits/msd_t.toml"), text, crate::family::catalog()).unwrap_err();
            assert_eq!((e.line, e.field.as_str()), (line, field), "{e}");
            assert!(e.msg.contains(msg), "{e}");
        };
        bad(("[4, 3, 2]", "[4, 3]"), 4, "resolution", "gloss layers");
        bad(("[4, 3, 2]", "[4, 1, 2]"), 4, "resolution", "sides must be in");
        bad(("paths = 1024", "paths = 10"), 5, "paths", "must be in");
        bad(("paths = 1024", "paths = 1024\nf0 = 2.0"), 6, "f0", "[0, 1]");
        bad(("paths = 1024", "paths = 1024\nphi_d = 4.0"), 6, "phi_d", "[0, π]");
        bad(("paths = 1024", "paths = 1024\nspecular = \"kept\""), 6, "specular", "unknown variant");
        bad(("quantity = \"ms-diffuse\"", "quantity = \"ms-diffuse-albedo\""), 3, "quantity", "tabulates 'ms-diffuse'");
    }

    /// The test spec's table rendered from cells of the given values (standard error 0.01),
    /// without simulating them, with those cells.
    fn rendered(value: impl Fn(usize) -> f64) -> (Built, Vec<Cell>) {
        let s = spec(SPEC);
        let t = Table::from_spec(&s).unwrap();
        let n = (t.slice_cells() + t.albedo_cells()) as usize;
        let cells: Vec<Cell> = (0..n).map(|k| Cell { value: value(k), se: 0.01 }).collect();
        (render(&s, &t, &cells).unwrap(), cells)
    }

    #[test]
    fn png_preview_is_256_pixels_across_a_layer() {
        // Texels of a 4 × 3 layer are scaled by ⌊256/4⌋ = 64: the preview is 256 wide and
        // 2 layers × 3 rows × 64 = 384 tall. The cells need not be simulated to be rendered.
        let (built, _) = rendered(|k| 1.0 + 0.01 * k as f64);
        let png = &built.artifacts.iter().find(|a| a.path.ends_with("data/msd_t.png")).unwrap().contents;
        // PNG: 8-byte signature, IHDR length and type, then width and height big-endian.
        assert_eq!(&png[12..16], b"IHDR");
        let be = |i: usize| u32::from_be_bytes(png[i..i + 4].try_into().unwrap());
        assert_eq!((be(16), be(20)), (256, 384));
    }

    /// The statistics a table states (JSON and verification) are those of its cells, worked
    /// out by hand: 24 slice cells of standard error 0.01 but cell 17 (layer 1, row 1, column 1)
    /// at 0.05, so max 0.05, rms √((23·1e-4 + 25e-4)/24) = √2e-4, worst point (gloss 1,
    /// θh = 1.5/4·π/2, θd = 1.5/3·π/2); 6 albedo cells of 0.002 but one at 0.004: max 0.004, rms
    /// √((5·4e-6 + 16e-6)/6) = √6e-6.
    #[test]
    fn stated_statistics_are_those_of_the_cells() {
        let s = spec(SPEC);
        let t = Table::from_spec(&s).unwrap();
        let (n, a) = (t.slice_cells() as usize, t.albedo_cells() as usize);
        assert_eq!((n, a), (24, 6));
        let mut cells: Vec<Cell> = (0..n + a).map(|k| Cell { value: 1.0, se: if k < n { 0.01 } else { 0.002 } }).collect();
        cells[17].se = 0.05;
        cells[n + 4].se = 0.004;
        let built = render(&s, &t, &cells).unwrap();
        let json = &built.artifacts.iter().find(|a| a.path.ends_with("json/msd_t.json")).unwrap().contents;
        let v: serde_json::Value = serde_json::from_slice(json).unwrap();
        let st = &v["statistics"];
        let close = |got: &serde_json::Value, want: f64| {
            // Sums of ≤ 24 squares of values ≤ 0.05, then a square root: a few ulps.
            let g = got.as_f64().unwrap();
            assert!((g - want).abs() <= 1e-15 * want, "{g} vs {want}");
        };
        close(&st["slice_max_standard_error"], 0.05);
        close(&st["slice_rms_standard_error"], 2e-4f64.sqrt());
        close(&st["albedo_max_standard_error"], 0.004);
        close(&st["albedo_rms_standard_error"], 6e-6f64.sqrt());
        let worst: Vec<f64> = st["slice_worst_cell"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
        let want = [1.0, 1.5 / 4.0 * FRAC_PI_2, 1.5 / 3.0 * FRAC_PI_2];
        assert!(worst.iter().zip(want).all(|(g, w)| (g - w).abs() <= 1e-15), "{worst:?}");
        let ver = &built.verification;
        assert_eq!((ver.points, ver.max_abs_error, ver.worst_point.clone()), (24, 0.05, worst));
        assert!((ver.rms_error - 2e-4f64.sqrt()).abs() <= 1e-15 * ver.rms_error, "{ver:?}");
    }

    /// A table's axes, as its docs state them: gloss k/(layers − 1) at layer k (0 for one
    /// layer), θh and θd at the cell centres (i + ½)/n·π/2, n·v at (a + ½)/n; the JSON lists the
    /// glosses of its layers. Five layers: 0, ¼, ½, ¾, 1, each exact in f64.
    #[test]
    fn the_axes_are_the_stated_layers_and_cell_centres() {
        let s = spec(&SPEC.replace("[4, 3, 2]", "[4, 3, 5]"));
        let t = Table::from_spec(&s).unwrap();
        assert_eq!((0..5).map(|k| t.gloss(k)).collect::<Vec<_>>(), [0.0, 0.25, 0.5, 0.75, 1.0]);
        assert_eq!((0..4).map(|i| t.theta_h(i)).collect::<Vec<_>>(), [0.5, 1.5, 2.5, 3.5].map(|c| c / 4.0 * FRAC_PI_2));
        assert_eq!((0..3).map(|j| t.theta_d(j)).collect::<Vec<_>>(), [0.5, 1.5, 2.5].map(|c| c / 3.0 * FRAC_PI_2));
        assert_eq!((0..3).map(|a| t.n_dot_v(a)).collect::<Vec<_>>(), [0.5, 1.5, 2.5].map(|c| c / 3.0));
        let n = (t.slice_cells() + t.albedo_cells()) as usize;
        let cells = vec![Cell { value: 1.0, se: 0.01 }; n];
        let built = render(&s, &t, &cells).unwrap();
        let json = &built.artifacts.iter().find(|a| a.path.ends_with("json/msd_t.json")).unwrap().contents;
        let v: serde_json::Value = serde_json::from_slice(json).unwrap();
        assert_eq!(v["gloss"], serde_json::json!([0.0, 0.25, 0.5, 0.75, 1.0]));
        let one = Table::from_spec(&spec(&SPEC.replace("[4, 3, 2]", "[4, 3, 1]"))).unwrap();
        assert_eq!(one.gloss(0), 0.0);
    }

    #[test]
    fn merl_files_hold_the_walk_at_the_cell_centres() {
        // merl_paths = 2 (1.46M cells a layer, the smallest run): a cell of the file is the
        // estimate at its centre (same key, cell number and paths), and check mode re-renders
        // the file byte for byte from the committed one.
        let text = SPEC.replace("[4, 3, 2]", "[2, 2, 1]").replace("albedo_resolution = 3", "albedo_resolution = 2\nmerl_paths = 2");
        let s = spec(&text);
        let t = Table::from_spec(&s).unwrap();
        let built = build(&s, Mode::Fit, Path::new("")).unwrap();
        let file = &built.artifacts.iter().find(|a| a.path.ends_with("data/msd_t_merl_0.binary")).unwrap().contents;
        let red = merl::decode_red(file).unwrap();
        let base = t.slice_cells() + t.albedo_cells();
        for cell in [0usize, 1234, 90 * 180 * 45 + 180 * 30 + 90, merl::CELLS - 1] {
            let (th, td, pd) = merl::cell_angles(cell);
            let want = match directions(th, td, pd) {
                Some((l, v)) => brdf(&surface(0.0, TALK_F0, Specular::Gone), l, v, Order::All, t.key(), base + cell as u64, 2, true).value / PI / merl::SCALES[0],
                None => -1.0,
            };
            assert_eq!(red[cell], want, "cell {cell}");
        }
        let dir = tempfile::tempdir().unwrap();
        for a in &built.artifacts {
            std::fs::create_dir_all(dir.path().join(&a.path).parent().unwrap()).unwrap();
            std::fs::write(dir.path().join(&a.path), &a.contents).unwrap();
        }
        let again = build(&s, Mode::Committed, dir.path()).unwrap();
        for (a, b) in built.artifacts.iter().zip(&again.artifacts) {
            assert!(a.path == b.path && a.contents == b.contents, "{} differs when re-rendered", a.path.display());
        }
    }

    /// A MERL cell states its standard error in its value's units: both the walk's estimate of
    /// π f/ρ divided by π and by the file's red scale (merl::SCALES[0]), so the cell's relative
    /// error is the walk's. Checked on cells of directions above the horizon (with 2 paths a
    /// cell, their errors are not zero) and on one below it (the file's −1, no error).
    #[test]
    fn merl_cells_state_their_error_in_the_values_units() {
        let text = SPEC.replace("[4, 3, 2]", "[2, 2, 1]").replace("albedo_resolution = 3", "albedo_resolution = 2\nmerl_paths = 2");
        let t = Table::from_spec(&spec(&text)).unwrap();
        let base = t.slice_cells() + t.albedo_cells();
        let mut seen = 0;
        for cell in [0usize, 1234, 90 * 180 * 45 + 180 * 30 + 90, merl::CELLS - 1] {
            let got = t.cell(base + cell as u64);
            let (th, td, pd) = merl::cell_angles(cell);
            match directions(th, td, pd) {
                Some((l, v)) => {
                    let e = brdf(&surface(0.0, TALK_F0, Specular::Gone), l, v, Order::All, t.key(), base + cell as u64, 2, false);
                    assert!(e.error > 0.0 && e.value > 0.0, "cell {cell}: {e:?}");
                    // Relative error: the same quotient up to a few roundings of the two divisions.
                    let (rel_got, rel_want) = (got.se / got.value, e.error / e.value);
                    assert!((rel_got - rel_want).abs() <= 1e-12 * rel_want, "cell {cell}: {rel_got} vs {rel_want}");
                    assert!((got.value * merl::SCALES[0] * PI - e.value).abs() <= 1e-12 * e.value, "cell {cell}");
                    seen += 1;
                }
                None => assert_eq!((got.value, got.se), (-1.0, 0.0), "cell {cell}"),
            }
        }
        assert!(seen >= 2, "{seen} cells above the horizon");
    }

    /// The cluster sharding: the table's cells computed in two ranges (split off the middle),
    /// merged and decoded, are each cell of the table computed alone, bit for bit (value and
    /// standard error); the count is the slices', the albedo's and the MERL cells'; a merged
    /// payload one cell short is refused, naming the spec and both sizes.
    #[test]
    fn shards_merge_to_the_cells_of_one_run() {
        let s = spec(SPEC);
        let t = Table::from_spec(&s).unwrap();
        let n = shard_cells(&s).unwrap();
        assert_eq!(n, 4 * 3 * 2 + t.albedo_cells() + t.merl_cells());
        let k = n / 2 + 1;
        let mut payload = shard_compute(&s, 0..k).unwrap();
        assert_eq!(payload.len() as u64, 16 * k);
        payload.extend(shard_compute(&s, k..n).unwrap());
        let cells = cells_of_payload(&t, &payload).unwrap();
        assert_eq!(cells.len() as u64, n);
        for (c, got) in cells.iter().enumerate() {
            let want = t.cell(c as u64);
            assert_eq!((got.value.to_bits(), got.se.to_bits()), (want.value.to_bits(), want.se.to_bits()), "cell {c}");
        }
        let short = &payload[..payload.len() - 16];
        let e = cells_of_payload(&t, short).unwrap_err().to_string();
        let (have, need) = (short.len().to_string(), (16 * n).to_string());
        assert!(e.contains("msd_t") && e.contains(&have) && e.contains(&need), "{e}");
    }

    #[test]
    fn cells_are_the_quantity_and_check_mode_rerenders_them() {
        let s = spec(SPEC);
        let t = Table::from_spec(&s).unwrap();
        let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap().install(|| build(&s, Mode::Fit, Path::new("")).unwrap());
        let two = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap().install(|| build(&s, Mode::Fit, Path::new("")).unwrap());
        for (a, b) in one.artifacts.iter().zip(&two.artifacts) {
            assert!(a.path == b.path && a.contents == b.contents, "{} differs between 1 and 2 threads", a.path.display());
        }
        let json = &one.artifacts.iter().find(|a| a.path.ends_with("json/msd_t.json")).unwrap().contents;
        let v: serde_json::Value = serde_json::from_slice(json).unwrap();
        // A cell is the ms-diffuse estimate at its point (same key, cell and paths: same bits);
        // the key is the spec's name (the module doc).
        let c = 5u64; // layer 0, row 1, column 1
        let (l, vv) = directions(t.theta_h(1), t.theta_d(1), t.phi_d).unwrap();
        let e = brdf(&surface(0.0, TALK_F0, Specular::Gone), l, vv, Order::All, key_of("msd_t"), c, 1024, true);
        let cell = &v["slices"][c as usize];
        assert_eq!((cell[0].as_f64().unwrap(), cell[1].as_f64().unwrap()), (e.value, e.error));
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(dir.path().join("json")).unwrap();
        std::fs::write(dir.path().join("json/msd_t.json"), json).unwrap();
        let again = build(&s, Mode::Committed, dir.path()).unwrap();
        for (a, b) in one.artifacts.iter().zip(&again.artifacts) {
            assert!(a.path == b.path && a.contents == b.contents, "{} differs when re-rendered", a.path.display());
        }
    }

    /// Every cell of a table is the walk at its stated point, the numbering of the module doc
    /// worked out here by hand: slice cell c = (k·H + j)·W + i at gloss k/(G − 1), θh = (i +
    /// ½)/W·π/2, θd = (j + ½)/H·π/2 and the default φd = π/2; then albedo cell n + k·A + a at
    /// n·v = (a + ½)/A; then MERL cell n + G·A + k·CELLS + m at the centre of MERL's cell m.
    /// Each keyed by the spec's name and its own number, with its paths: bit for bit. The
    /// earlier test read one slice cell (c = 5, where c/W = c mod W and c/(W·H) = c/(W + H))
    /// and no albedo cell; the MERL tests had one layer, where every layer index is 0.
    #[test]
    fn every_cell_is_the_walk_at_its_stated_point() {
        let same = |got: Cell, want: crate::integrate::Estimate, c: u64| {
            assert_eq!((got.value.to_bits(), got.se.to_bits()), (want.value.to_bits(), want.error.to_bits()), "cell {c}: {got:?} vs {want:?}");
        };
        let t = Table::from_spec(&spec(SPEC)).unwrap(); // 4 × 3 × 2, A = 3, 1024 paths
        let key = key_of("msd_t");
        let mut c = 0u64;
        for k in 0..2 {
            let s = surface(k as f64, TALK_F0, Specular::Gone);
            for j in 0..3 {
                for i in 0..4 {
                    let (th, td) = ((i as f64 + 0.5) / 4.0 * FRAC_PI_2, (j as f64 + 0.5) / 3.0 * FRAC_PI_2);
                    let (l, v) = directions(th, td, FRAC_PI_2).unwrap();
                    same(t.cell(c), brdf(&s, l, v, Order::All, key, c, 1024, false), c);
                    c += 1;
                }
            }
        }
        for k in 0..2 {
            for a in 0..3 {
                let s = surface(k as f64, TALK_F0, Specular::Gone);
                same(t.cell(c), albedo(&s, at_cosine((a as f64 + 0.5) / 3.0), key, c, 1024, false), c);
                c += 1;
            }
        }
        let text = SPEC.replace("[4, 3, 2]", "[2, 2, 2]").replace("albedo_resolution = 3", "albedo_resolution = 2\nmerl_paths = 2");
        let t = Table::from_spec(&spec(&text)).unwrap();
        for k in 0..2usize {
            let s = surface(k as f64, TALK_F0, Specular::Gone);
            for m in [0usize, 1234, 90 * 180 * 45 + 180 * 30 + 90] {
                let c = (8 + 4 + k * merl::CELLS + m) as u64;
                let (th, td, pd) = merl::cell_angles(m);
                let got = t.cell(c);
                match directions(th, td, pd) {
                    Some((l, v)) => {
                        let e = brdf(&s, l, v, Order::All, key, c, 2, false);
                        assert_eq!((got.value, got.se), (e.value / PI / merl::SCALES[0], e.error / PI / merl::SCALES[0]), "layer {k} MERL cell {m}");
                    }
                    None => assert_eq!((got.value, got.se), (-1.0, 0.0), "layer {k} MERL cell {m}"),
                }
            }
        }
    }

    /// MERL's layout has 90·90·180 = 1 458 000 cells a layer: a table with MERL files counts
    /// that many per gloss layer after its slices and albedo (3 layers of 2 × 2 and 2 albedo
    /// columns: 12 + 6 + 4 374 000), one without counts none.
    #[test]
    fn merl_cells_are_a_files_cells_per_layer() {
        let text = SPEC.replace("[4, 3, 2]", "[2, 2, 3]").replace("albedo_resolution = 3", "albedo_resolution = 2");
        let t = Table::from_spec(&spec(&text)).unwrap();
        assert_eq!((t.slice_cells(), t.albedo_cells(), t.merl_cells(), t.cells()), (12, 6, 0, 18));
        let t = Table::from_spec(&spec(&text.replace("albedo_resolution = 2", "albedo_resolution = 2\nmerl_paths = 2"))).unwrap();
        assert_eq!((t.merl_cells(), t.cells()), (4_374_000, 4_374_018));
    }

    /// A cell whose value or standard error is not finite is refused, naming the spec and the
    /// cell's number; both halves of a cell are checked, slices and albedo alike.
    #[test]
    fn non_finite_cells_are_refused_by_number() {
        let s = spec(SPEC);
        let t = Table::from_spec(&s).unwrap();
        let n = (t.slice_cells() + t.albedo_cells()) as usize;
        for (k, bad) in [(7, Cell { value: 1.0, se: f64::INFINITY }), (25, Cell { value: f64::NAN, se: 0.01 }), (3, Cell { value: f64::NEG_INFINITY, se: 0.01 }), (12, Cell { value: 1.0, se: f64::NAN })] {
            let mut cells = vec![Cell { value: 1.0, se: 0.01 }; n];
            cells[k] = bad;
            match render(&s, &t, &cells) {
                Err(BuildError::NonFinite { spec, at }) => assert_eq!((spec.as_str(), at), ("msd_t", vec![k as f64])),
                other => panic!("cell {k} {bad:?}: {:?}", other.map(|b| b.name)),
            }
        }
    }

    /// The atlas is W texels wide and H·G tall (KTX 2.0 header: pixelWidth at byte 20,
    /// pixelHeight at 24, little-endian), and the PNG preview shows R/2, sRGB-encoded, as the
    /// JSON states: texel (i, row r) fills the 64 × 64 block at (64 i, 64 r). Values 0.2 to
    /// 1.35, so R/2 differs from R (and from R mod 2) in every 8-bit code.
    #[test]
    fn the_atlas_is_layers_of_rows_and_the_preview_shows_half_the_value() {
        let (built, cells) = rendered(|k| 0.2 + 0.05 * k as f64);
        let file = |end: &str| built.artifacts.iter().find(|a| a.path.ends_with(end)).unwrap().contents.clone();
        let ktx2 = file("data/msd_t.ktx2");
        let le = |i: usize| u32::from_le_bytes(ktx2[i..i + 4].try_into().unwrap());
        assert_eq!((le(20), le(24)), (4, 6));
        let png = file("data/msd_t.png");
        let mut reader = png::Decoder::new(std::io::Cursor::new(&png[..])).read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        reader.next_frame(&mut buf).unwrap();
        for r in 0..6 {
            for i in 0..4 {
                let want = crate::emit::texture::srgb8(cells[r * 4 + i].value / 2.0);
                let p = &buf[((64 * r + 10) * 256 + 64 * i + 10) * 3..][..3];
                assert_eq!(p, [want; 3], "texel ({i}, {r})");
            }
        }
    }

    /// The runtime module states the atlas size (4 × 3 × 2) and maps an angle to [0, 1] by
    /// 2/π, written as the f32 nearest 0.6366197723… (6.3661975e-1), in both languages.
    #[test]
    fn the_module_states_the_atlas_size_and_the_angle_scale() {
        let (built, _) = rendered(|_| 1.0);
        let text = |end: &str| String::from_utf8(built.artifacts.iter().find(|a| a.path.ends_with(end)).unwrap().contents.to_vec()).unwrap();
        let (wgsl, rust) = (text("wgsl/msd_t.wgsl"), text("src/msd_t.rs"));
        assert!(wgsl.contains("MSD_T_SIZE: vec3<u32> = vec3<u32>(4u, 3u, 2u);"), "{wgsl}");
        assert!(wgsl.contains("acos(clamp(n_dot_h, 0f, 1f)) * 6.3661975e-1;") && wgsl.contains("acos(clamp(l_dot_h, 0f, 1f)) * 6.3661975e-1;"), "{wgsl}");
        assert!(rust.contains("MSD_T_SIZE: [u32; 3] = [4, 3, 2];"), "{rust}");
        assert!(rust.contains("n_dot_h.clamp(0.0, 1.0).acos() * 6.3661975e-1;") && rust.contains("l_dot_h.clamp(0.0, 1.0).acos() * 6.3661975e-1;"), "{rust}");
    }

    /// The common spec a table offers states its grid and its settings: gloss over [0, 1] in
    /// G layers, θh and θd over their first and last cell centres, the convention as
    /// specular_walks 0 (gone) or 1 (walks), and the tolerance of a cell, 1/√paths (1/32 at
    /// 1024 paths, exact).
    #[test]
    fn the_common_spec_states_the_grid_the_convention_and_the_tolerance() {
        for (specular, walks) in [("gone", 0.0), ("walks", 1.0)] {
            let s = spec(&SPEC.replace("paths = 1024", &format!("paths = 1024\nspecular = \"{specular}\"")));
            let axis = |name: &str| s.file.axis.iter().find(|a| a.name == name).unwrap().clone();
            assert_eq!(s.file.tolerance, 1.0 / 32.0);
            assert_eq!((axis("gloss").range, axis("gloss").count), ([0.0, 1.0], 2));
            assert_eq!((axis("theta_h").range, axis("theta_h").count), ([0.5 / 4.0 * FRAC_PI_2, 3.5 / 4.0 * FRAC_PI_2], 4));
            assert_eq!((axis("theta_d").range, axis("theta_d").count), ([0.5 / 3.0 * FRAC_PI_2, 2.5 / 3.0 * FRAC_PI_2], 3));
            assert_eq!(axis("specular_walks").range, [walks, walks], "{specular}");
        }
    }

    /// Of several cells with the largest standard error, the first in the slices' order is
    /// the worst: cells 5 and 17 at 0.05, the 22 others at 0.01 (rms √((22·1e-4 + 2·25e-4)/24)
    /// = √3e-4, a few roundings).
    #[test]
    fn the_worst_cell_is_the_first_of_the_largest() {
        let mut cells = vec![Cell { value: 1.0, se: 0.01 }; 24];
        cells[5].se = 0.05;
        cells[17].se = 0.05;
        let (max, rms, worst) = stats(&cells);
        assert_eq!((max, worst), (0.05, 5));
        assert!((rms - 3e-4f64.sqrt()).abs() <= 1e-15, "{rms}");
    }
}

#[cfg(test)]
mod study {
    use super::*;

    /// `cargo test --release --lib msdiffuse::table::study -- --ignored --nocapture`: the error
    /// against paths over a 32 × 32 slice per gloss (the standard errors scale as σ/√n: the
    /// largest per-path σ sets the paths for a target), and the throughput on one thread.
    #[test]
    #[ignore]
    fn error_against_paths() {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        for paths in [1024u64, 4096] {
            let text = tests::SPEC.replace("[4, 3, 2]", "[32, 32, 5]").replace("paths = 1024", &format!("paths = {paths}")).replace("albedo_resolution = 3", "albedo_resolution = 2");
            let t = Table::parse(Path::new("fits/msd_t.toml"), &text).unwrap();
            for k in 0..t.layers {
                let cells: Vec<u64> = (0..1024u64).map(|c| k as u64 * 1024 + c).collect();
                let t0 = std::time::Instant::now();
                let r: Vec<Cell> = pool.install(|| cells.iter().map(|&c| t.cell(c)).collect());
                let dt = t0.elapsed().as_secs_f64();
                let (max, rms, w) = stats(&r);
                println!(
                    "gloss {:.2} paths {paths}: max se {max:.4} (cell {w}: θh {:.3} θd {:.3}), rms se {rms:.4}, σ_max {:.3}; {:.2e} paths/s on one thread",
                    t.gloss(k), t.theta_h(w % 32), t.theta_d(w / 32), max * (paths as f64).sqrt(), (1024 * paths) as f64 / dt
                );
            }
        }
    }
}
