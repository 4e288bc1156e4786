//! DFG LUT figures from the committed outputs: for every `generated/json/*.json` of kind
//! `ggx-dfg-lut`, the scale and bias maps over (n·v, roughness) (`NAME_scale`, `NAME_bias`,
//! as in the split-sum papers' figures) and the texture's storage error under bilinear
//! filtering, the largest per texel footprint on the verification grid (`NAME_storage_error`,
//! log₁₀). Malformed files are errors naming the file.

use super::spec::KIND;
use crate::plot::{PlotError, heatmap};
use serde_json::Value;
use std::path::{Path, PathBuf};

struct Lut {
    name: String,
    width: usize,
    height: usize,
    row: String,
    values: Vec<[f64; 2]>,
    error_map: Vec<f64>,
}

fn read(path: &Path) -> Result<Option<Lut>, PlotError> {
    let text = std::fs::read_to_string(path).map_err(|source| PlotError::Io { path: path.to_path_buf(), source })?;
    let v: Value = serde_json::from_str(&text).map_err(|source| PlotError::Json { path: path.to_path_buf(), source })?;
    if v["kind"] != KIND {
        return Ok(None);
    }
    let err = |m: &str| PlotError::Data { path: path.to_path_buf(), message: m.to_string() };
    let width = v["texture"]["width"].as_u64().ok_or_else(|| err("no texture.width"))? as usize;
    let height = v["texture"]["height"].as_u64().ok_or_else(|| err("no texture.height"))? as usize;
    let values: Vec<[f64; 2]> = v["values"]
        .as_array()
        .and_then(|a| a.iter().map(|t| Some([t.get(0)?.as_f64()?, t.get(1)?.as_f64()?])).collect())
        .ok_or_else(|| err("values is not an array of [scale, bias]"))?;
    let error_map: Vec<f64> = v["verification"]["error_map"]
        .as_array()
        .and_then(|a| a.iter().map(Value::as_f64).collect())
        .ok_or_else(|| err("no verification.error_map"))?;
    if values.len() != width * height || error_map.len() != values.len() || width < 2 || height < 2 {
        return Err(err(&format!("{} values, {} error map cells for a {width}×{height} texture", values.len(), error_map.len())));
    }
    let row = v["axes"][1]["name"].as_str().unwrap_or("roughness").to_string();
    let name = v["name"].as_str().ok_or_else(|| err("no name"))?.to_string();
    Ok(Some(Lut { name, width, height, row, values, error_map }))
}

/// The figures of every DFG LUT in `generated/json` into `out`.
pub fn figures(out: &Path, generated: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let dir = generated.join("json");
    let Ok(entries) = std::fs::read_dir(&dir) else { return Ok(Vec::new()) };
    let mut paths: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).filter(|p| p.extension().is_some_and(|x| x == "json")).collect();
    paths.sort();
    let mut files = Vec::new();
    for p in paths {
        let Some(lut) = read(&p)? else { continue };
        let xs: Vec<f64> = (0..lut.width).map(|i| (i as f64 + 0.5) / lut.width as f64).collect();
        let ys: Vec<f64> = (0..lut.height).map(|j| (j as f64 + 0.5) / lut.height as f64).collect();
        let y_label = if lut.row == "alpha" { "α" } else { "perceptual roughness (α = r²)" };
        for (c, what) in ["scale", "bias"].iter().enumerate() {
            let v: Vec<f64> = lut.values.iter().map(|t| t[c]).collect();
            files.extend(heatmap(
                &out.join(format!("{}_{what}", lut.name)),
                &format!("{}: split-sum {what}", lut.name),
                "n·v",
                y_label,
                &xs,
                &ys,
                &v,
                what,
                false,
            )?);
        }
        let log: Vec<f64> = lut.error_map.iter().map(|&e| if e > 0.0 { e.log10() } else { f64::NAN }).collect();
        files.extend(heatmap(
            &out.join(format!("{}_storage_error", lut.name)),
            &format!("{}: f16 texture, bilinear, vs the integral (max per texel)", lut.name),
            "n·v",
            y_label,
            &xs,
            &ys,
            &log,
            "log10 |error|",
            false,
        )?);
    }
    Ok(files)
}
