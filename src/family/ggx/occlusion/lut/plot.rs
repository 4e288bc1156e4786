//! Cone LUT figures from the committed outputs: for every `generated/json/*.json` of kind
//! `ggx-cone-lut`, the slices of scale and of bias side by side as COD: WWII shows them
//! (`NAME_scale_slices`, `NAME_bias_slices`, one colour scale per figure), and the texture's
//! filtering error per slice interval, the largest per texel footprint on the verification grid
//! (`NAME_filter_error`, log₁₀). Malformed files are errors naming the file.

use super::spec::KIND;
use crate::plot::{Panel, PlotError, grid_of_heatmaps};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// A committed cone LUT: sizes, row parameter and texels (slice-major).
pub struct Committed {
    pub name: String,
    pub width: usize,
    pub height: usize,
    pub depth: usize,
    /// The row parameter: "gloss", "roughness" or "alpha".
    pub row: String,
    /// The layout's name: "scale-bias" (stored R, G = scale, bias) or "filament" (bias, scale + bias).
    pub layout: String,
    /// [scale, bias] in f64 (whatever the layout stores).
    pub values: Vec<[f64; 2]>,
    pub error_map: Vec<f64>,
}

/// The cone LUT in `path`, or `None` when the file is another kind.
pub fn read(path: &Path) -> Result<Option<Committed>, PlotError> {
    let text = std::fs::read_to_string(path).map_err(|source| PlotError::Io { path: path.to_path_buf(), source })?;
    let v: Value = serde_json::from_str(&text).map_err(|source| PlotError::Json { path: path.to_path_buf(), source })?;
    if v["kind"] != KIND {
        return Ok(None);
    }
    let err = |m: &str| PlotError::Data { path: path.to_path_buf(), message: m.to_string() };
    let size = |k: &str| v["texture"][k].as_u64().map(|x| x as usize).ok_or_else(|| err(&format!("no texture.{k}")));
    let (width, height, depth) = (size("width")?, size("height")?, size("depth")?);
    let values: Vec<[f64; 2]> = v["values"]
        .as_array()
        .and_then(|a| a.iter().map(|t| Some([t.get(0)?.as_f64()?, t.get(1)?.as_f64()?])).collect())
        .ok_or_else(|| err("values is not an array of [scale, bias]"))?;
    let error_map: Vec<f64> = v["verification"]["error_map"]
        .as_array()
        .and_then(|a| a.iter().map(Value::as_f64).collect())
        .ok_or_else(|| err("no verification.error_map"))?;
    if width < 2 || height < 2 || depth < 2 || values.len() != width * height * depth || error_map.len() != width * height * (depth - 1) {
        return Err(err(&format!("{} values, {} error map cells for a {width}×{height}×{depth} texture", values.len(), error_map.len())));
    }
    let row = v["axes"][1]["name"].as_str().unwrap_or("gloss").to_string();
    let layout = v["layout"]["name"].as_str().unwrap_or("scale-bias").to_string();
    let name = v["name"].as_str().ok_or_else(|| err("no name"))?.to_string();
    Ok(Some(Committed { name, width, height, depth, row, layout, values, error_map }))
}

/// The committed cone LUTs in `generated/json`, in file-name order.
pub fn committed(generated: &Path) -> Result<Vec<Committed>, PlotError> {
    let Ok(entries) = std::fs::read_dir(generated.join("json")) else { return Ok(Vec::new()) };
    let mut paths: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).filter(|p| p.extension().is_some_and(|x| x == "json")).collect();
    paths.sort();
    let mut out = Vec::new();
    for p in paths {
        if let Some(c) = read(&p)? {
            out.push(c);
        }
    }
    Ok(out)
}

/// The axis label of a row parameter.
pub fn row_label(row: &str) -> &'static str {
    match row {
        "gloss" => "gloss g (α = sqrt(2/(1 + 2^(18g))))",
        "alpha" => "α",
        _ => "perceptual roughness (α = r²)",
    }
}

/// The figures of every cone LUT in `generated/json` into `out`.
pub fn figures(out: &Path, generated: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let mut files = Vec::new();
    for lut in committed(generated)? {
        let (w, h, d) = (lut.width, lut.height, lut.depth);
        let xs: Vec<f64> = (0..w).map(|i| (i as f64 + 0.5) / w as f64).collect();
        let ys: Vec<f64> = (0..h).map(|j| (j as f64 + 0.5) / h as f64).collect();
        let y_label = row_label(&lut.row);
        let columns = d.min(4);
        for (c, what) in ["scale", "bias"].iter().enumerate() {
            let slices: Vec<Vec<f64>> = (0..d).map(|k| lut.values[k * w * h..(k + 1) * w * h].iter().map(|t| t[c]).collect()).collect();
            let titles: Vec<String> = (0..d).map(|k| format!("cos θc = {:.3}", k as f64 / (d - 1) as f64)).collect();
            let panels: Vec<Panel> = slices.iter().zip(&titles).map(|(v, t)| Panel { title: t, values: v }).collect();
            files.extend(grid_of_heatmaps(
                &out.join(format!("{}_{what}_slices", lut.name)),
                &format!("{}: split-sum {what} over the visibility cone", lut.name),
                "n·v",
                y_label,
                &xs,
                &ys,
                &panels,
                columns,
                what,
                false,
                None,
            )?);
        }
        let logs: Vec<Vec<f64>> = (0..d - 1)
            .map(|k| lut.error_map[k * w * h..(k + 1) * w * h].iter().map(|&e| if e > 0.0 { e.log10() } else { f64::NAN }).collect())
            .collect();
        let titles: Vec<String> = (0..d - 1).map(|k| format!("cos θc in [{:.3}, {:.3}]", k as f64 / (d - 1) as f64, (k + 1) as f64 / (d - 1) as f64)).collect();
        let panels: Vec<Panel> = logs.iter().zip(&titles).map(|(v, t)| Panel { title: t, values: v }).collect();
        files.extend(grid_of_heatmaps(
            &out.join(format!("{}_filter_error", lut.name)),
            &format!("{}: f16 3-D texture, trilinear, vs the integral (max per texel and slice interval)", lut.name),
            "n·v",
            y_label,
            &xs,
            &ys,
            &panels,
            columns,
            "log10 |error|",
            false,
            None,
        )?);
    }
    Ok(files)
}
