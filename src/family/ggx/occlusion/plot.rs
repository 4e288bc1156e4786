//! Specular occlusion figures: the error maps of the approximations against the cone integral,
//! SO − SO_cone over (n·v, V) at a few roughnesses (`ggx_occlusion_error_rR`, one per
//! roughness): Lagarde & de Rousiers 2014 and Jimenez et al. 2016 with the published and the
//! refitted constants, and each committed COD: WWII 3-D table read trilinearly. SO is for a
//! dielectric's F0 = 4 % as in `shadefit validate`; the integrals are computed here (1e-8).

use super::{F0, exact_so, jimenez, jimenez_with, lagarde, lagarde_with, lut_readers};
use crate::plot::{Panel, PlotError, grid_of_heatmaps};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// Perceptual roughnesses of the figures.
const ROUGHNESS: [f64; 3] = [0.2, 0.5, 0.9];
/// Grid side: n·v at texel centres, V at k/N, k = 1..N.
const N: usize = 32;

/// The figures into `out`, the 3-D tables read from `generated`.
pub fn figures(out: &Path, generated: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let readers = lut_readers(generated);
    let refits = super::refit::Refits::committed(generated)
        .map_err(|e| PlotError::Draw { path: generated.join("json").join(format!("{}.json", super::refit::SPEC)), message: e.to_string() })?;
    let xs: Vec<f64> = (0..N).map(|i| (i as f64 + 0.5) / N as f64).collect();
    let ys: Vec<f64> = (1..=N).map(|k| k as f64 / N as f64).collect();
    let mut files = Vec::new();
    for r in ROUGHNESS {
        let alpha = r * r;
        let pts: Vec<(f64, f64)> = ys.iter().flat_map(|&v| xs.iter().map(move |&mu| (mu, v))).collect();
        let exact: Vec<f64> = pts.par_iter().map(|&(mu, v)| exact_so(alpha, mu, v, F0, 1e-8)).collect();
        let err = |f: &dyn Fn(f64, f64) -> f64| -> Vec<f64> { pts.iter().zip(&exact).map(|(&(mu, v), e)| f(mu, v) - e).collect() };
        let mut maps: Vec<(String, Vec<f64>)> = vec![
            ("Lagarde 2014".into(), err(&|mu, v| lagarde(mu, v, alpha))),
            ("Lagarde, refitted".into(), err(&|mu, v| lagarde_with(refits.lagarde, mu, v, alpha))),
            ("Jimenez 2016".into(), err(&|mu, v| jimenez(mu, v, r))),
            ("Jimenez, refitted".into(), err(&|mu, v| jimenez_with(refits.jimenez, mu, v, r))),
        ];
        for reader in &readers {
            maps.push((format!("{} (trilinear)", reader.name()), err(&|mu, v| reader.so(mu, alpha, v, F0))));
        }
        let panels: Vec<Panel> = maps.iter().map(|(t, v)| Panel { title: t, values: v }).collect();
        files.extend(grid_of_heatmaps(
            &out.join(format!("ggx_occlusion_error_r{:02}", (r * 100.0).round() as u32)),
            &format!("specular occlusion − cone model (F0 = 4 %), perceptual roughness {r}"),
            "n·v",
            "visibility V (cos θc = sqrt(1 − V))",
            &xs,
            &ys,
            &panels,
            3,
            "SO error",
            true,
            Some((-1.0, 1.0)),
        )?);
    }
    Ok(files)
}
