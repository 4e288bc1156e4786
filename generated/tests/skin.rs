//! Skin LUTs in the runtime crate: the curvature functions against independent geometry (a
//! sphere, Euler's formula, the normal section of a surface by finite differences), the
//! emitted lookups against their own texels and the κ = 0 limit, the KTX2 bytes against the
//! const arrays, and naga validation of a shader using the const-array and texture versions.

// Channel loops index several arrays.
#![allow(clippy::needless_range_loop)]

use shadefit_runtime::skin::{
    Ktx2Image, LutFormat, skin_curvature_from_light, skin_curvature_from_light_normalized,
};
use shadefit_runtime::{compose, compose_shader, skin_punctual_lut as punctual, skin_sh_lut as sh};

fn validate(src: &str) {
    let module = naga::front::wgsl::parse_str(src).unwrap_or_else(|e| panic!("{}\n{src}", e.emit_to_string(src)));
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
        .validate(&module)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(src)));
}

#[test]
fn shader_using_curvature_and_both_luts_validates_with_naga() {
    validate(&compose(&["skin_curvature"]).unwrap());
    let shader = "#import shadefit::skin_curvature\n\
        #import shadefit::skin_punctual_lut\n\
        #import shadefit::skin_sh_lut\n\
        @group(0) @binding(0) var punctual_tex: texture_2d<f32>;\n\
        @group(0) @binding(1) var sh_tex: texture_2d<f32>;\n\
        @group(0) @binding(2) var lut_sampler: sampler;\n\
        struct In { @location(0) n: vec3<f32>, @location(1) t: vec3<f32>, @location(2) b: vec3<f32>, @location(3) k: vec3<f32> };\n\
        @fragment\n\
        fn fs(v: In) -> @location(0) vec4<f32> {\n\
            let l = normalize(vec3<f32>(0.3, 0.4, 0.8));\n\
            let kappa = skin_curvature_from_light_normalized(v.t, v.b, v.k, l);\n\
            let kappa_faded = skin_curvature_from_light(v.t, v.b, v.k, l);\n\
            let nl = dot(v.n, l);\n\
            let d_tex = skin_punctual_lut_sample(punctual_tex, lut_sampler, nl, kappa);\n\
            let d_const = skin_punctual_lut(nl, kappa_faded);\n\
            let k1 = skin_sh_lut_sample(sh_tex, lut_sampler, kappa, 1u) * skin_sh_lut(kappa, 2u);\n\
            let uv = skin_punctual_lut_uv(nl, kappa) + skin_sh_lut_uv(kappa, 2u);\n\
            return vec4<f32>(d_tex + d_const + k1, uv.x + uv.y);\n\
        }\n";
    let src = compose_shader(shader).unwrap();
    assert_eq!(src.matches("// ---- shadefit::").count(), 3);
    validate(&src);
}

/// f64 → f32 vector.
fn v32(v: [f64; 3]) -> [f32; 3] {
    v.map(|x| x as f32)
}

fn normalize(v: [f64; 3]) -> [f64; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    v.map(|x| x / n)
}

#[test]
fn a_sphere_has_curvature_one_over_its_radius_in_every_direction() {
    let r = 5.0f64; // mm
    let c = [1.0 / r, 0.0, 1.0 / r];
    let (t, b) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    for k in 0..24 {
        let phi = k as f64 * 0.27;
        for elev in [-0.6f64, -0.1, 0.0, 0.3, 0.9, 1.4] {
            let l = [elev.cos() * phi.cos(), elev.cos() * phi.sin(), elev.sin()];
            let kn = skin_curvature_from_light_normalized(t, b, c.map(|x| x as f32), v32(l));
            let kf = skin_curvature_from_light(t, b, c.map(|x| x as f32), v32(l));
            // f32 rounding of l (½ ulp per component) and of the ~8 operations: a few 1e-7
            // relative to 1/r.
            assert!((kn as f64 - 1.0 / r).abs() < 2e-7, "{phi} {elev}: {kn}");
            let sin2 = 1.0 - elev.sin().powi(2);
            assert!((kf as f64 - sin2 / r).abs() < 2e-7, "{phi} {elev}: {kf}");
        }
    }
    // The light along the normal: no direction, the mean curvature (the faded one is 0).
    assert_eq!(skin_curvature_from_light_normalized(t, b, [0.2, 0.0, 0.2], [0.0, 0.0, 1.0]), 0.2);
    assert_eq!(skin_curvature_from_light(t, b, [0.2, 0.0, 0.2], [0.0, 0.0, 1.0]), 0.0);
}

/// Tensor of principal curvatures (k1 along direction angle θ from the tangent, k2 across) in
/// the (tangent, bitangent) frame: R diag(k1, k2) Rᵀ.
fn tensor(k1: f64, k2: f64, theta: f64) -> [f64; 3] {
    let (s, c) = theta.sin_cos();
    [k1 * c * c + k2 * s * s, (k1 - k2) * s * c, k1 * s * s + k2 * c * c]
}

#[test]
fn principal_directions_and_euler_formula() {
    let (t, b) = ([1.0f32, 0.0, 0.0], [0.0f32, 1.0, 0.0]);
    for (k1, k2, theta) in [(0.8, 0.1, 0.0), (0.5, -0.2, 0.7), (1.5, 0.3, 2.2), (0.05, 0.05, 1.0)] {
        let c = v32(tensor(k1, k2, theta));
        for k in 0..16 {
            // Euler: the normal curvature at angle ψ from the first principal direction is
            // k1 cos²ψ + k2 sin²ψ, whatever the light's elevation.
            let psi = k as f64 * 0.4;
            let dir = theta + psi;
            for elev in [0.0f64, 0.5, -0.3] {
                let l = [elev.cos() * dir.cos(), elev.cos() * dir.sin(), elev.sin()];
                let want = k1 * psi.cos().powi(2) + k2 * psi.sin().powi(2);
                let got = skin_curvature_from_light_normalized(t, b, c, v32(l)) as f64;
                // f32 rounding of the tensor, the light and ~8 operations on values ≤ 1.5.
                assert!((got - want).abs() < 1e-6, "k=({k1},{k2}) θ={theta} ψ={psi}: {got} vs {want}");
            }
        }
    }
}

#[test]
fn normal_section_curvature_of_a_surface_by_finite_differences() {
    // Height field z = f(x, y) with a critical point at the origin (normal +z); the normal
    // section along the unit tangent d is the curve s ↦ (s·d, f(s·d)), whose curvature at s = 0
    // is g''(0), g(s) = f(s·d) (g'(0) = 0). Computed by a central difference, independently of
    // any tensor; the tensor handed to the function is the Hessian in a rotated tangent frame.
    let (a, b2, c) = (0.9, -0.35, 0.25); // f = (a x² + 2 b2 xy + c y²)/2 + cubic terms
    let f = |x: f64, y: f64| 0.5 * (a * x * x + 2.0 * b2 * x * y + c * y * y) + 0.3 * x * x * x - 0.2 * x * y * y;
    for phi in [0.0f64, 0.4, 1.9, -2.5] {
        let t = [phi.cos(), phi.sin(), 0.0];
        let bt = [-phi.sin(), phi.cos(), 0.0];
        // Hessian H = [[a, b2], [b2, c]] in the frame (t, bt): tᵀHt, tᵀH bt, btᵀH bt.
        let h = |u: [f64; 3], v: [f64; 3]| a * u[0] * v[0] + b2 * (u[0] * v[1] + u[1] * v[0]) + c * u[1] * v[1];
        let tensor = v32([h(t, t), h(t, bt), h(bt, bt)]);
        for k in 0..12 {
            let psi = k as f64 * 0.53;
            let d = [psi.cos(), psi.sin()];
            let g = |s: f64| f(s * d[0], s * d[1]);
            let step = 1e-3;
            // Central difference: the cubic terms cancel; rounding ~1e-16·|g|/h² ≈ 1e-16.
            let want = (g(step) - 2.0 * g(0.0) + g(-step)) / (step * step);
            for elev in [0.2f64, 1.1, -0.4] {
                let l = normalize([elev.cos() * d[0], elev.cos() * d[1], elev.sin()]);
                let kn = skin_curvature_from_light_normalized(v32(t), v32(bt), tensor, v32(l)) as f64;
                let kf = skin_curvature_from_light(v32(t), v32(bt), tensor, v32(l)) as f64;
                // f32 rounding of the frame, the tensor, the light and the arithmetic on
                // values ≤ 1: 1e-6.
                assert!((kn - want).abs() < 1e-6, "φ={phi} ψ={psi}: {kn} vs {want}");
                assert!((kf - want * elev.cos().powi(2)).abs() < 1e-6, "φ={phi} ψ={psi}: {kf}");
            }
        }
    }
}

fn size(s: [u32; 2]) -> (usize, usize) {
    (s[0] as usize, s[1] as usize)
}

#[test]
fn punctual_lookup_reproduces_texels_and_the_flat_limit() {
    let (w, h) = size(punctual::SKIN_PUNCTUAL_LUT_SIZE);
    let kmax = punctual::SKIN_PUNCTUAL_LUT_CURVATURE_MAX;
    let rgb = &punctual::SKIN_PUNCTUAL_LUT_RGB;
    assert_eq!(rgb.len(), w * h);
    // Every texel is in [0, 1]; rows do not decrease in n·l (a normalised, symmetric kernel
    // against a shifted clamped cosine; f32 rounding of values ≤ 1 allows 1e-7).
    for j in 0..h {
        for i in 0..w {
            for c in 0..3 {
                let v = rgb[j * w + i][c];
                assert!((0.0..=1.0).contains(&v), "texel ({i}, {j})[{c}] = {v}");
                if i > 0 {
                    assert!(v >= rgb[j * w + i - 1][c] - 1e-7, "row {j} decreases at {i}");
                }
            }
        }
    }
    // Exact nodes: n·l = −1 + 2i/(w − 1) is exact in f32 for these widths, κ = 0 and κ_max.
    for i in 0..w {
        let nl = -1.0 + 2.0 * i as f32 / (w - 1) as f32;
        assert_eq!(punctual::skin_punctual_lut(nl, 0.0), rgb[i], "i = {i}");
        assert_eq!(punctual::skin_punctual_lut(nl, kmax), rgb[(h - 1) * w + i], "i = {i}");
        // κ → 0 is Lambert: the κ = 0 row is max(n·l, 0).
        assert_eq!(rgb[i], [nl.max(0.0); 3]);
    }
    if w % 2 == 1 {
        // n·l = 0 is a texel, so interpolating the κ = 0 row is exact up to f32 rounding.
        for k in 0..=1000 {
            let nl = -1.0 + 2.0 * k as f32 / 1000.0;
            let d = punctual::skin_punctual_lut(nl, 0.0);
            assert!(d.iter().all(|&x| (x - nl.max(0.0)).abs() < 2e-7), "{nl}: {d:?}");
        }
    }
    // Concave curvature reads the κ = 0 row; NaN and ±inf stay finite and in range.
    assert_eq!(punctual::skin_punctual_lut(0.3, -2.0), punctual::skin_punctual_lut(0.3, 0.0));
    for x in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -0.0, 1e-45, f32::MAX] {
        for y in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.5, -1e-45] {
            let d = punctual::skin_punctual_lut(x, y);
            assert!(d.iter().all(|v| (0.0..=1.0).contains(v)), "({x}, {y}): {d:?}");
            let uv = punctual::skin_punctual_lut_uv(x, y);
            assert!(uv.iter().all(|v| (0.0..=1.0).contains(v)), "({x}, {y}): {uv:?}");
        }
    }
    // Half-texel offsets: the first and last texel centres.
    assert_eq!(punctual::skin_punctual_lut_uv(-1.0, 0.0), [0.5 / w as f32, 0.5 / h as f32]);
    assert_eq!(punctual::skin_punctual_lut_uv(1.0, kmax), [1.0 - 0.5 / w as f32, 1.0 - 0.5 / h as f32]);
}

#[test]
fn sh_lookup_limits() {
    let (w, h) = size(sh::SKIN_SH_LUT_SIZE);
    assert_eq!((h, sh::SKIN_SH_LUT_RGB.len()), (2, 2 * w));
    let kmax = sh::SKIN_SH_LUT_CURVATURE_MAX;
    for band in 0..4 {
        // κ = 0: no blur, every band kept; band 0 is always 1 (light is conserved).
        assert_eq!(sh::skin_sh_lut(0.0, band), [1.0; 3]);
    }
    assert_eq!(sh::skin_sh_lut(kmax, 0), [1.0; 3]);
    for j in 1..w {
        for c in 0..3 {
            let (k1, k2) = (sh::SKIN_SH_LUT_RGB[j][c], sh::SKIN_SH_LUT_RGB[w + j][c]);
            // Blur damps higher bands more: 0 < k_2 < k_1 < 1, decreasing with κ.
            assert!(0.0 < k2 && k2 < k1 && k1 < 1.0, "column {j}: {k1} {k2}");
            assert!(k1 < sh::SKIN_SH_LUT_RGB[j - 1][c] && k2 < sh::SKIN_SH_LUT_RGB[w + j - 1][c]);
        }
    }
    assert_eq!(sh::skin_sh_lut(kmax, 2), sh::SKIN_SH_LUT_RGB[2 * w - 1]);
    assert_eq!(sh::skin_sh_lut(kmax, 9), sh::SKIN_SH_LUT_RGB[2 * w - 1]);
    assert_eq!(sh::skin_sh_lut_uv(0.0, 1), [0.5 / w as f32, 0.25]);
    assert_eq!(sh::skin_sh_lut_uv(kmax, 2), [1.0 - 0.5 / w as f32, 0.75]);
}

#[test]
fn ktx2_textures_hold_the_const_texels() {
    type Case<'a> = (&'a [u8], &'a str, [u32; 2], &'a [[f32; 3]]);
    let cases: [Case; 2] = [
        (punctual::SKIN_PUNCTUAL_LUT_KTX2, punctual::SKIN_PUNCTUAL_LUT_FORMAT, punctual::SKIN_PUNCTUAL_LUT_SIZE, &punctual::SKIN_PUNCTUAL_LUT_RGB),
        (sh::SKIN_SH_LUT_KTX2, sh::SKIN_SH_LUT_FORMAT, sh::SKIN_SH_LUT_SIZE, &sh::SKIN_SH_LUT_RGB),
    ];
    for (bytes, format, [w, h], rgb) in cases {
        let img = Ktx2Image::parse(bytes).unwrap();
        assert_eq!((img.width, img.height), (w, h));
        let want = match format {
            "rgba16float" => LutFormat::Rgba16Float,
            "rgba32float" => LutFormat::Rgba32Float,
            other => panic!("format {other}"),
        };
        assert_eq!(img.format, want);
        for y in 0..h {
            for x in 0..w {
                let t = img.texel(x, y);
                let v = rgb[(y * w + x) as usize];
                assert_eq!(t[3], 1.0);
                for c in 0..3 {
                    // Round to nearest binary16: ≤ 2⁻¹¹ relative (normal range) plus 2⁻²⁵
                    // absolute (subnormal half-ulp); exact for rgba32float.
                    let bound = match img.format {
                        LutFormat::Rgba16Float => v[c].abs() * 2f32.powi(-11) + 2f32.powi(-25),
                        LutFormat::Rgba32Float => 0.0,
                        other => panic!("a skin LUT is RGBA, not {other:?}"),
                    };
                    assert!((t[c] - v[c]).abs() <= bound, "({x}, {y})[{c}]: {} vs {}", t[c], v[c]);
                }
            }
        }
    }
}
