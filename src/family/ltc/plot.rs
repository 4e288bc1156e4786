//! ltc figures from the committed tables (`generated/json/*.json` of kind `ltc-table`): per-cell
//! maps of δ and of the mass below the horizon over (roughness, sqrt(1 − cos θ)) — beside
//! ltc_code's for a 64² GGX table, with their difference — and lobe slices in the plane of
//! incidence: the normalised lobe p = f cos θl / E against the table's LTC (and ltc_code's).

use super::fit::{Cell, cell_parameters};
use super::table::{self, LobeName, Table};
use super::transform::Ltc;
use super::{fit, published};
use crate::plot::{Panel, PlotError, Series, SeriesStyle, data_err, grid_of_heatmaps, heatmap, line_plot};
use crate::shading::Lobe;
use std::path::{Path, PathBuf};

/// Cells (i, j) of the lobe slices: glossy at 45°, medium at 60°, rough near grazing.
const SLICE_CELLS: [(usize, usize); 3] = [(16, 24), (32, 40), (56, 58)];
/// Polar angles of a slice, −90°…90° (the view at +θv).
const SLICE_POINTS: usize = 181;

/// A committed ltc-table: its table parameters and the per-cell arrays the figures show (the
/// texels and δ through the build's own reader, [`table::committed`]; ltc_code's δ as the build
/// measured it, when the table is beside it).
struct Committed {
    table: Table,
    ltc_1: Vec<[f64; 4]>,
    distance: Vec<f64>,
    ltc_code_distance: Option<Vec<f64>>,
}

fn load(path: &Path) -> Result<Option<Committed>, PlotError> {
    let text = std::fs::read_to_string(path).map_err(|e| data_err(path, e.to_string()))?;
    let v: serde_json::Value = serde_json::from_str(&text).map_err(|e| data_err(path, e.to_string()))?;
    if v["kind"] != "ltc-table" {
        return Ok(None);
    }
    let lobe = match v["quantity"].as_str() {
        Some(q) if q == LobeName::Ggx.quantity() => LobeName::Ggx,
        Some(q) if q == LobeName::Charlie.quantity() => LobeName::Charlie,
        _ => return Err(data_err(path, "'quantity' names no LTC lobe")),
    };
    let number = |k: &str| v[k].as_f64().ok_or_else(|| data_err(path, format!("no number '{k}'")));
    let n = number("resolution")? as usize;
    if n < 2 {
        return Err(data_err(path, "'resolution' is below 2"));
    }
    let table = Table {
        name: v["name"].as_str().unwrap_or_default().to_string(),
        description: String::new(),
        function: String::new(),
        lobe,
        n,
        nodes: number("nodes")? as usize,
        min_alpha: number("min_alpha")?,
    };
    let texels = table::committed(&v, &table).map_err(|e| data_err(path, e.to_string()))?;
    let ltc_code_distance = v["end_to_end"]["per_cell_versus_ltc_code"]["ltc_code_distance"]
        .as_array()
        .map(|a| a.iter().filter_map(|x| x.as_f64()).collect::<Vec<f64>>())
        .filter(|d| d.len() == n * n);
    Ok(Some(Committed { table, ltc_1: texels.ltc_1, distance: texels.distance, ltc_code_distance }))
}

pub fn figures(out: &Path, generated: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let mut paths: Vec<PathBuf> = match std::fs::read_dir(generated.join("json")) {
        Ok(dir) => dir.filter_map(|e| e.ok().map(|e| e.path())).filter(|p| p.extension().is_some_and(|x| x == "json")).collect(),
        Err(_) => return Ok(vec![]),
    };
    paths.sort();
    let mut files = Vec::new();
    for path in paths {
        if let Some(c) = load(&path)? {
            files.extend(table_figures(out, &c)?);
        }
    }
    Ok(files)
}

fn table_figures(out: &Path, c: &Committed) -> Result<Vec<PathBuf>, PlotError> {
    let t = &c.table;
    let axis: Vec<f64> = (0..t.n).map(|i| i as f64 / (t.n - 1) as f64).collect();
    let (xl, yl) = ("roughness", "sqrt(1 − cos θv)");
    let name = &t.name;
    let mass_below = |texels: &[[f64; 4]]| -> Vec<f64> { texels.iter().map(|q| Ltc::from_texel(*q).mass_below_horizon()).collect() };
    let below = mass_below(&c.ltc_1);
    // ltc_code's tables are GGX at 64²: beside a table the build measured against them only.
    let theirs = c.ltc_code_distance.clone().map(|d| {
        let (p1, _) = published::tables();
        let below = mass_below(&p1);
        (p1, d, below)
    });
    let mut files = Vec::new();
    match &theirs {
        Some((_, d, theirs_below)) => {
            let panels = [Panel { title: "shadefit", values: &c.distance }, Panel { title: "ltc_code", values: d }];
            files.extend(grid_of_heatmaps(&out.join(format!("{name}_distance")), &format!("{name}: δ = ∫|p − D| per cell"), xl, yl, &axis, &axis, &panels, 2, "δ", false, None)?);
            let diff: Vec<f64> = c.distance.iter().zip(d).map(|(a, b)| a - b).collect();
            files.extend(heatmap(&out.join(format!("{name}_distance_versus_ltc_code")), &format!("{name}: δ(shadefit) − δ(ltc_code); negative: shadefit closer"), xl, yl, &axis, &axis, &diff, "Δδ", true)?);
            let panels = [Panel { title: "shadefit", values: &below }, Panel { title: "ltc_code", values: theirs_below }];
            files.extend(grid_of_heatmaps(&out.join(format!("{name}_horizon")), &format!("{name}: LTC mass below the horizon per cell"), xl, yl, &axis, &axis, &panels, 2, "mass", false, None)?);
        }
        None => {
            files.extend(heatmap(&out.join(format!("{name}_distance")), &format!("{name}: δ = ∫|p − D| per cell"), xl, yl, &axis, &axis, &c.distance, "δ", false)?);
            files.extend(heatmap(&out.join(format!("{name}_horizon")), &format!("{name}: LTC mass below the horizon per cell"), xl, yl, &axis, &axis, &below, "mass", false)?);
        }
    }
    for (i, j) in SLICE_CELLS.map(|(i, j)| (i * (t.n - 1) / 63, j * (t.n - 1) / 63)) {
        let k = i + t.n * j;
        let (alpha, theta) = cell_parameters(i, j, t.n, t.min_alpha);
        let mut ltcs = vec![("shadefit LTC", Ltc::from_texel(c.ltc_1[k]))];
        if let Some((p1, _, _)) = &theirs {
            ltcs.push(("ltc_code LTC", Ltc::from_texel(p1[k])));
        }
        let series = match t.lobe {
            LobeName::Ggx => slice(&published::ggx(alpha), theta, &ltcs),
            LobeName::Charlie => slice(&crate::shading::charlie::Charlie::new(alpha.max(t.lobe.floor())), theta, &ltcs),
        };
        let title = format!("{name}: cell ({i}, {j}), α {alpha:.3}, θv {:.1}°, plane of incidence", theta.to_degrees());
        files.extend(line_plot(&out.join(format!("{name}_slice_{i}_{j}")), &title, "θl (degrees; the view at +θv, its mirror direction at −θv)", "density (1/sr)", &series, false)?);
    }
    Ok(files)
}

/// p and the LTCs' densities along l = (sin t, 0, cos t), t in [−90°, 90°].
fn slice<L: Lobe>(lobe: &L, theta: f64, ltcs: &[(&str, Ltc)]) -> Vec<Series> {
    let cell = Cell::new(lobe, theta, fit::FIT_NODES);
    let ts: Vec<f64> = (0..SLICE_POINTS).map(|k| (-90.0 + 180.0 * k as f64 / (SLICE_POINTS - 1) as f64).to_radians()).collect();
    let dir = |t: f64| [t.sin(), 0.0, t.cos()];
    let mut series = vec![Series::new("lobe f cos θl / E", ts.iter().map(|&t| (t.to_degrees(), cell.normalised(dir(t)))).collect(), SeriesStyle::Line).color(0)];
    for (n, (label, ltc)) in ltcs.iter().enumerate() {
        series.push(Series::new(*label, ts.iter().map(|&t| (t.to_degrees(), ltc.eval(dir(t)))).collect(), SeriesStyle::Line).color(n + 1));
    }
    series
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The committed sheen table draws its two maps and three slices; a table whose per-cell
    /// array is short is refused naming its file and the array.
    #[test]
    fn committed_tables_draw_and_short_arrays_are_refused() {
        let dir = std::env::temp_dir().join(format!("ltc_plot_test_{}", std::process::id()));
        let (generated, out) = (dir.join("generated"), dir.join("out"));
        std::fs::create_dir_all(generated.join("json")).unwrap();
        std::fs::create_dir_all(&out).unwrap();
        let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(repo.join("generated/json/ltc_sheen.json")).unwrap();
        std::fs::write(generated.join("json/ltc_sheen.json"), &text).unwrap();
        let files = figures(&out, &generated).unwrap();
        assert_eq!(files.iter().filter(|f| f.extension().is_some_and(|x| x == "png")).count(), 5, "{files:?}");
        assert!(files.iter().all(|f| f.is_file()));
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        v["distance"].as_array_mut().unwrap().pop();
        std::fs::write(generated.join("json/ltc_sheen.json"), v.to_string()).unwrap();
        let e = figures(&out, &generated).unwrap_err().to_string();
        assert!(e.contains("ltc_sheen.json") && e.contains("'distance'"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
