//! Hot paths of the build: one integrand evaluation, one P_s / R / G / skin texel at the
//! default tolerance, the gloss closed form, and one rational fit.
//!
//!     cargo bench --bench hot_paths            (full)
//!     cargo bench --bench hot_paths -- --quick (a few seconds per benchmark)

use criterion::{criterion_group, criterion_main, Criterion};
use shadefit::fit::{self, Data, FitOptions, Objective, RationalModel};
use shadefit::family::fuzz::integrals as fuzz;
use shadefit::family::gloss::integrals as gloss;
use shadefit::family::skin::integrals as skin;
use std::hint::black_box;

fn integrands(c: &mut Criterion) {
    let t = [0.6f64.sin(), 0.0, 0.6f64.cos()];
    let u = [0.5, 0.3, (1.0f64 - 0.34).sqrt()];
    let v = [-0.2, 0.4, -(1.0f64 - 0.2).sqrt()];
    c.bench_function("sggx_phase", |b| b.iter(|| fuzz::sggx_phase(black_box(0.35), t, u, v)));
    c.bench_function("gloss_length_closed_form", |b| b.iter(|| gloss::length_from_gloss(black_box(0.7))));
}

fn points(c: &mut Criterion) {
    c.bench_function("fuzz_ps_point", |b| {
        b.iter(|| fuzz::ps(black_box(0.35), 0.6, 1.0, 0.5, fuzz::DEFAULT_TOL))
    });
    c.bench_function("fuzz_ps_point_grazing", |b| {
        b.iter(|| fuzz::ps(black_box(0.15), 0.1, std::f64::consts::FRAC_PI_2 - 1e-3, 2.5, fuzz::DEFAULT_TOL))
    });
    c.bench_function("fuzz_g_point", |b| b.iter(|| fuzz::g(black_box(0.2), 0.3, fuzz::DEFAULT_TOL)));
    let profile = skin::default_skin_profile();
    c.bench_function("skin_punctual_texel", |b| {
        b.iter(|| skin::punctual(&profile, skin::Kernel::Linear, black_box(0.5), 0.3, skin::DEFAULT_TOLERANCE))
    });
    let mut g = c.benchmark_group("slow");
    g.sample_size(10);
    g.bench_function("fuzz_r_point", |b| b.iter(|| fuzz::r(black_box(0.35), 0.6, fuzz::DEFAULT_TOL)));
    g.finish();
}

fn fits(c: &mut Criterion) {
    // The published gloss-length form, rational(3, 2) in gloss, on 256 samples.
    let x: Vec<Vec<f64>> = (0..256).map(|i| vec![i as f64 / 255.0]).collect();
    let y: Vec<f64> = x.iter().map(|p| gloss::length_from_gloss(p[0])).collect();
    let data = Data { x, y };
    let model = RationalModel::rational_1d("gloss", 3, 2);
    let mut g = c.benchmark_group("fit");
    g.sample_size(10);
    for objective in [Objective::Lsq, Objective::Minimax] {
        let opts = FitOptions { objective, ..FitOptions::default() };
        g.bench_function(format!("gloss_rational_3_2_{objective:?}").to_lowercase(), |b| {
            b.iter(|| fit::fit(&model, black_box(&data), &opts, "bench").expect("the gloss form fits"))
        });
    }
    g.finish();
}

criterion_group!(benches, integrands, points, fits);
criterion_main!(benches);
