//! The LTC light functions' CPU twin (`ltc_ggx`) against what the build measured in f64 with
//! the same texels (json/ltc_ggx.json "end_to_end"): every committed light and view through
//! the clipped polygon and the sphere path, from the RGBA16F texels (read back from the KTX2 by
//! the runtime's reader, interpolated bilinearly here in f64 at the nodes the build uses). Then
//! the functions on inputs no light has: NaN, ±inf, huge and zero vectors, back-facing lights.

use shadefit_runtime::ltc_ggx as l;
use shadefit_runtime::skin::Ktx2Image;

fn json() -> serde_json::Value {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/json/ltc_ggx.json");
    serde_json::from_str(&std::fs::read_to_string(path).expect("json/ltc_ggx.json")).expect("valid JSON")
}

fn f64s(v: &serde_json::Value) -> Vec<f64> {
    v.as_array().expect("an array").iter().map(|x| x.as_f64().expect("a number")).collect()
}

/// Bilinear interpolation of the image at (x, y) ∈ [0, 1]², texel nodes at i/(n − 1).
fn lookup(img: &Ktx2Image, x: f64, y: f64) -> [f32; 4] {
    let n = img.width as usize;
    let at = |t: f64| {
        let s = t.clamp(0.0, 1.0) * (n - 1) as f64;
        let i = (s.floor() as usize).min(n - 2);
        (i, s - i as f64)
    };
    let ((i, fx), (j, fy)) = (at(x), at(y));
    let t = |i: usize, j: usize| img.texel_3d(i as u32, j as u32, 0);
    std::array::from_fn(|c| {
        let lo = t(i, j)[c] as f64 * (1.0 - fx) + t(i + 1, j)[c] as f64 * fx;
        let hi = t(i, j + 1)[c] as f64 * (1.0 - fx) + t(i + 1, j + 1)[c] as f64 * fx;
        (lo * (1.0 - fy) + hi * fy) as f32
    })
}

/// The twin reproduces the build's f64 results within 2e-5 absolute: the f32 path rounds the
/// texels (2⁻²⁴ relative), the normalisations and the edge terms (each a few ulps of an angle
/// ≤ π, over ≤ 5 edges, divided by 2π), the whole scaled by E ≤ 1; 2e-5 is that sum (≈ 1e-6)
/// times the largest growth the cosine-space matrices give it (|M⁻¹| up to ~20 at the committed
/// views' roughness ≥ 0.2).
#[test]
fn the_cpu_twin_reproduces_the_measured_pairs() {
    let j = json();
    let e = &j["end_to_end"];
    let (t1, t2) = (Ktx2Image::parse(l::LTC_GGX_1_KTX2).unwrap(), Ktx2Image::parse(l::LTC_GGX_2_KTX2).unwrap());
    let lights: Vec<Vec<[f32; 3]>> = e["lights"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x["vertices"].as_array().unwrap().iter().map(|p| {
            let v = f64s(p);
            [v[0] as f32, v[1] as f32, v[2] as f32]
        }).collect())
        .collect();
    let views: Vec<(f64, f64)> = e["views"].as_array().unwrap().iter().map(|v| (v["roughness"].as_f64().unwrap(), v["theta"].as_f64().unwrap())).collect();
    let pairs = e["pairs"].as_array().unwrap();
    assert_eq!(pairs.len(), lights.len() * views.len());
    let (mut worst_clipped, mut worst_sphere) = (0.0f64, 0.0f64);
    for (k, pair) in pairs.iter().enumerate() {
        let p = f64s(pair);
        let (light, (roughness, theta)) = (&lights[k % lights.len()], views[k / lights.len()]);
        let (a, b) = (roughness, (1.0 - theta.cos()).max(0.0).sqrt());
        let (q1, q2) = (lookup(&t1, a, b), lookup(&t2, a, b));
        let v = [theta.sin() as f32, 0.0, theta.cos() as f32];
        let (n, origin) = ([0.0, 0.0, 1.0], [0.0; 3]);
        let clipped = l::ltc_ggx_polygon(q1, n, v, origin, light, false) * l::ltc_ggx_scale(q2, [1.0; 3])[0];
        worst_clipped = worst_clipped.max((clipped as f64 - p[1]).abs());
        if light.len() == 4 {
            let mid = |a: [f32; 3], b: [f32; 3]| std::array::from_fn(|i| 0.5 * (a[i] + b[i]));
            let half = |a: [f32; 3], b: [f32; 3]| std::array::from_fn(|i| 0.5 * (b[i] - a[i]));
            let (c, hx, hy) = (mid(light[0], light[2]), half(light[0], light[1]), half(light[0], light[3]));
            let s = l::ltc_ggx_rect_sphere(q1, n, v, origin, c, hx, hy, false) * q2[0];
            worst_sphere = worst_sphere.max((s as f64 - p[2]).abs());
            let r = l::ltc_ggx_rect(q1, n, v, origin, c, hx, hy, false) * q2[0];
            assert!((r - clipped).abs() <= 1e-6 * clipped.max(1.0), "pair {k}: rect {r} vs polygon {clipped}");
        }
    }
    eprintln!("ltc_ggx CPU twin vs the build's f64 pairs: clipped {worst_clipped:.2e}, sphere path {worst_sphere:.2e}");
    assert!(worst_clipped < 2e-5 && worst_sphere < 2e-5, "clipped {worst_clipped} sphere {worst_sphere}");
}

/// Every function returns a finite value in [0, 1] for any input: NaN, ±inf and huge
/// components, zero vectors, degenerate and back-facing lights, any texel.
#[test]
fn no_input_gives_a_non_finite_or_out_of_range_result() {
    let specials = [0.0, -0.0, 1.0, -1.0, 0.5, 1e-30, 1e30, -1e30, f32::MAX, f32::MIN, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, f32::MIN_POSITIVE];
    let vector = |k: usize| -> [f32; 3] { [specials[k % 14], specials[(k / 14) % 14], specials[(k / 196) % 14]] };
    let mut count = 0;
    for k in 0..14 * 14 * 14 {
        let x = vector(k);
        let t1 = [specials[k % 14], specials[(k / 3) % 14], specials[(k / 7) % 14], specials[(k / 11) % 14]];
        for (n, v, p, c) in [
            ([0.0, 0.0, 1.0], [0.6, 0.0, 0.8], [0.0; 3], x),
            (x, [0.6, 0.0, 0.8], [0.0; 3], [0.0, 0.0, 2.0]),
            ([0.0, 0.0, 1.0], x, x, [0.0, 0.0, 2.0]),
        ] {
            for two in [false, true] {
                let r = [
                    l::ltc_ggx_rect(t1, n, v, p, c, [0.5, 0.0, 0.0], x, two),
                    l::ltc_ggx_rect_sphere(t1, n, v, p, c, x, [0.0, 0.5, 0.0], two),
                    l::ltc_ggx_polygon([1.0, 0.0, 0.0, 1.0], n, v, p, &[c, x, [1.0, 1.0, 1.0]], two),
                    l::ltc_ggx_sphere_clip(x[0], x[1]),
                ];
                assert!(r.iter().all(|y| (0.0..=1.0).contains(y)), "input {k}: {r:?}");
                count += 1;
            }
        }
        let uv = l::ltc_ggx_uv(x[0], x[1]);
        assert!(uv.iter().all(|u| (0.0..=1.0).contains(u)), "{uv:?}");
        assert!(l::ltc_ggx_scale(t1, x).iter().all(|y| y.is_finite()));
    }
    assert_eq!(count, 14 * 14 * 14 * 6);
}

/// A one-sided light behind its emitting side gives 0; two-sided, the same as in front (the
/// polygon's integral is odd in the winding); a light entirely below the horizon gives 0.
#[test]
fn orientation_and_the_horizon() {
    let t1 = [1.0, 0.0, 0.0, 1.0];
    let (n, v, p) = ([0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0; 3]);
    let c = [0.0, 0.0, 2.0];
    let front = l::ltc_ggx_rect(t1, n, v, p, c, [0.5, 0.0, 0.0], [0.0, 0.5, 0.0], false);
    let back = l::ltc_ggx_rect(t1, n, v, p, c, [0.0, 0.5, 0.0], [0.5, 0.0, 0.0], false);
    let back_two = l::ltc_ggx_rect(t1, n, v, p, c, [0.0, 0.5, 0.0], [0.5, 0.0, 0.0], true);
    // The clamped cosine over a 1 × 1 square 2 above: the parallel-rectangle form factor (four
    // corner rectangles X = Y = 1/4: 4·(1/π)·X/√(1+X²)·atan(Y/√(1+X²))) is 0.0734776.
    assert!((front - 0.0734776).abs() < 1e-6 && back == 0.0 && (back_two - front).abs() < 1e-7, "{front} {back} {back_two}");
    let sphere = l::ltc_ggx_rect_sphere(t1, n, v, p, c, [0.5, 0.0, 0.0], [0.0, 0.5, 0.0], false);
    assert!((sphere - front).abs() < 1e-6, "{sphere} vs {front}");
    assert_eq!(l::ltc_ggx_rect(t1, n, v, p, [0.0, 0.0, -2.0], [0.5, 0.0, 0.0], [0.0, -0.5, 0.0], true), 0.0);
}
