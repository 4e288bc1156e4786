//! msdiffuse figures, like the talk's: polar plots in the plane of incidence against Lambert
//! (the full simulated BRDF, the shipped hand fit and the published gloss-0 rational), and the
//! committed slices f(θh, θd) per gloss as heatmaps. The polar curves are estimated here (2^14
//! paths a point, keyed by the figure; the standard errors are below 0.03 of Lambert away from
//! grazing views); the slices are the committed `generated/json/ms_diffuse_slices.json`.

use super::integrals::{Order, TALK_F0, brdf, surface};
use super::published::{Cosines, RATIONAL_DEN, RATIONAL_NUM, Slices, hand_fit, rational};
use super::walk::{Specular, key_of};
use crate::plot::{PlotError, Series, SeriesStyle};
use std::f64::consts::{FRAC_PI_2, PI};
use std::path::{Path, PathBuf};

/// Views in the plane of incidence, from −89° to 89°.
const VIEWS: usize = 61;

/// (l, v, cosines) of light at θl (azimuth 0) and view at signed θv in the same plane.
fn plane(theta_l: f64, theta_v: f64) -> ([f64; 3], [f64; 3], Cosines) {
    let l = [theta_l.sin(), 0.0, theta_l.cos()];
    let v = [theta_v.sin(), 0.0, theta_v.cos()];
    let s = [l[0] + v[0], 0.0, l[2] + v[2]];
    let n = (s[0] * s[0] + s[2] * s[2]).sqrt();
    let h = [s[0] / n, 0.0, s[2] / n];
    let c = Cosines { n_dot_l: l[2], n_dot_v: v[2], n_dot_h: h[2], l_dot_h: l[0] * h[0] + l[2] * h[2], l_dot_v: l[0] * v[0] + l[2] * v[2] };
    (l, v, c)
}

pub fn figures(out: &Path, generated: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let mut files = Vec::new();
    let key = key_of("ms-diffuse polar figure");
    for (g, theta_l) in [(0.0, 60f64.to_radians()), (0.0, 80f64.to_radians()), (1.0, 60f64.to_radians())] {
        let s = surface(g, TALK_F0, Specular::Gone);
        let views: Vec<f64> = (0..VIEWS).map(|i| (-89.0 + 178.0 * i as f64 / (VIEWS - 1) as f64).to_radians()).collect();
        let polar = |r: f64, tv: f64| (r * tv.sin(), r * tv.cos());
        let sim: Vec<(f64, f64)> = views
            .iter()
            .enumerate()
            .map(|(i, &tv)| {
                let (l, v, _) = plane(theta_l, tv);
                polar(brdf(&s, l, v, Order::All, key, i as u64, 1 << 14, true).value, tv)
            })
            .collect();
        let hand: Vec<(f64, f64)> = views.iter().map(|&tv| polar(hand_fit(g, &plane(theta_l, tv).2), tv)).collect();
        let lambert: Vec<(f64, f64)> = views.iter().map(|&tv| polar(1.0, tv)).collect();
        let mut series = vec![
            Series::new("Lambert", lambert, SeriesStyle::Line).color(0),
            Series::new("simulated (F0 = 0.04, specular share gone)", sim, SeriesStyle::Line).color(1),
            Series::new("shipped hand fit", hand, SeriesStyle::Line).color(2),
        ];
        if g == 0.0 {
            let r: Vec<(f64, f64)> = views.iter().map(|&tv| {
                let c = plane(theta_l, tv).2;
                polar(PI * rational(&RATIONAL_NUM, &RATIONAL_DEN, c.n_dot_h, c.l_dot_h), tv)
            }).collect();
            series.push(Series::new("published rational (π R)", r, SeriesStyle::Line).color(3));
        }
        let stem = format!("ms_diffuse_polar_g{}_l{:.0}", g, theta_l.to_degrees());
        files.extend(crate::plot::line_plot(
            &out.join(stem),
            &format!("π f/ρ in the plane of incidence, gloss {g}, light at {:.0}° (polar: radius = value)", theta_l.to_degrees()),
            "x (the light's side: positive)",
            "z",
            &series,
            false,
        )?);
    }
    if let Some(sl) = Slices::load(generated, "ms_diffuse_slices") {
        let mut gl: Vec<f64> = sl.points.iter().map(|p| p[0]).collect();
        gl.dedup();
        for g in gl {
            let idx = sl.at_gloss(g);
            let mut xs: Vec<f64> = idx.iter().map(|&k| sl.points[k][1].to_degrees()).collect();
            xs.dedup();
            xs.sort_by(f64::total_cmp);
            xs.dedup();
            let mut ys: Vec<f64> = idx.iter().map(|&k| sl.points[k][2].to_degrees()).collect();
            ys.sort_by(f64::total_cmp);
            ys.dedup();
            let values: Vec<f64> = idx.iter().map(|&k| sl.values[k].min(3.0)).collect();
            files.extend(crate::plot::heatmap(
                &out.join(format!("ms_diffuse_slice_g{g}")),
                &format!("simulated slice π f/ρ (clamped at 3), gloss {g}, φd = {:.0}°", sl.phi_d.to_degrees()),
                "θh (degrees)",
                "θd (degrees)",
                &xs,
                &ys,
                &values,
                "π f/ρ",
                false,
            )?);
        }
    }
    let _ = FRAC_PI_2;
    Ok(files)
}
