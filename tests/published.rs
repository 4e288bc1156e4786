//! The committed refits against the published COD: WWII constants, measured against the
//! integrals (the closed form, itself checked against quadrature in the library's tests).

use shadefit::family::gloss::integrals::{combine, gloss_from_length, length_from_gloss};
use shadefit::family::gloss::published::{published_combine, published_fit_coefficients, rational_1d, PUBLISHED_ENDS};
use std::path::PathBuf;

fn committed(name: &str) -> Vec<f64> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("generated/json/{name}.json"));
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap();
    v["model"]["coefficients"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

fn max_rms(errs: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut m, mut ss, mut n) = (0.0f64, 0.0, 0);
    for e in errs {
        m = m.max(e.abs());
        ss += e * e;
        n += 1;
    }
    (m, (ss / n as f64).sqrt())
}

#[test]
fn refit_a_beats_published_on_256_uniform_glosses() {
    let c = committed("gloss_length");
    let c: [f64; 6] = c.try_into().unwrap();
    let p = published_fit_coefficients(PUBLISHED_ENDS.1);
    let g: Vec<f64> = (0..256).map(|i| i as f64 / 255.0).collect();
    let (ours, _) = max_rms(g.iter().map(|&x| rational_1d(&c, x) - length_from_gloss(x)));
    let (theirs, _) = max_rms(g.iter().map(|&x| rational_1d(&p, x) - length_from_gloss(x)));
    eprintln!("gloss_length max abs: refit {ours:.4e}, published {theirs:.4e}");
    assert!(ours < theirs, "refit {ours} must be strictly below published {theirs}");
    // Endpoints are pinned exactly to the integral (rounding of a 2×2 solve: 1e-15).
    assert!((rational_1d(&c, 0.0) - 2.0 / 3.0).abs() < 1e-15);
    assert!((rational_1d(&c, 1.0) - length_from_gloss(1.0)).abs() < 1e-15);
    // The error in recovered gloss units is reported; it is large near g = 1 where dL/dg → 0.
    let (gerr, _) = max_rms(g.iter().map(|&x| gloss_from_length(rational_1d(&c, x)) - x));
    eprintln!("gloss_length max error in gloss units: {gerr:.4e}");
    assert!(gerr.is_finite());
}

#[test]
fn refit_b_beats_published_max_and_rms_on_65x65() {
    let c = committed("gloss_combine");
    let f = |x: f64, y: f64| {
        let (s, s2, xy) = (x + y, x * x + y * y, x * y);
        ((c[0] + c[1] * s + c[2] * s2 + c[3] * xy) / (1.0 + c[4] * s + c[5] * s2 + c[6] * xy)).clamp(0.0, 1.0)
    };
    let a: Vec<f64> = (0..65).map(|i| i as f64 / 64.0).collect();
    let pts: Vec<(f64, f64)> = a.iter().flat_map(|&y| a.iter().map(move |&x| (x, y))).collect();
    let truth: Vec<f64> = pts.iter().map(|&(x, y)| combine(x, y)).collect();
    let (om, or) = max_rms(pts.iter().zip(&truth).map(|(&(x, y), t)| f(x, y) - t));
    let (pm, pr) = max_rms(pts.iter().zip(&truth).map(|(&(x, y), t)| published_combine(x, y) - t));
    eprintln!("gloss_combine: refit max {om:.4e} rms {or:.4e}; published max {pm:.4e} rms {pr:.4e}");
    assert!(om < pm && or < pr);
}
