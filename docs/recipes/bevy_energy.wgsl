// Energy terms for a bevy material (or any naga_oil / wgpu shader), from shadefit's emitted WGSL
// modules: Kulla–Conty multiple-scattering compensation for GGX (Kulla & Conty, "Revisiting
// Physically Based Shading at Imageworks", SIGGRAPH 2017 course: E, E_avg, F_avg) and the
// albedo scaling of glTF's KHR_materials_sheen (Charlie lobe): the base below a sheen of colour c
// is scaled by min(1 − max(c)·E_sheen(n·v), 1 − max(c)·E_sheen(n·l)).
// Register generated/wgsl/{ggx_albedo_rational,ggx_albedo_avg,ggx_published_refits,
// sheen_albedo_rational}.wgsl as shader libraries (README "Using shadefit's WGSL in bevy"); the
// runtime crate's tests/naga_oil.rs composes this file with naga_oil and naga validates it.
#import shadefit::ggx_albedo_rational
#import shadefit::ggx_albedo_avg
#import shadefit::ggx_published_refits
#import shadefit::sheen_albedo_rational

const KC_PI: f32 = 3.14159265;

// f_ms(μo, μi) = (1 − E(μo)) (1 − E(μi)) / (π (1 − E_avg)); near α = 0, E and E_avg tend to 1
// together, and the floor keeps the ratio finite.
fn kulla_conty_fms(alpha: f32, n_dot_v: f32, n_dot_l: f32) -> f32 {
    let e_avg = ggx_albedo_avg::ggx_albedo_avg_fit(alpha);
    let ev = ggx_albedo_rational::ggx_albedo(alpha, n_dot_v);
    let el = ggx_albedo_rational::ggx_albedo(alpha, n_dot_l);
    return (1.0 - ev) * (1.0 - el) / (KC_PI * max(1.0 - e_avg, 1e-6));
}

// The Fresnel term of the multiply scattered light: F_avg² E_avg / (1 − F_avg (1 − E_avg)).
fn kulla_conty_fresnel_ms(f_avg: vec3<f32>, e_avg: f32) -> vec3<f32> {
    return f_avg * f_avg * e_avg / (1.0 - f_avg * (1.0 - e_avg));
}

// The base layer's scale under a sheen of colour `sheen` and Charlie roughness `sheen_alpha`.
fn sheen_base_scale(sheen: vec3<f32>, sheen_alpha: f32, n_dot_v: f32, n_dot_l: f32) -> f32 {
    let c = max(sheen.r, max(sheen.g, sheen.b));
    let ev = sheen_albedo_rational::sheen_albedo(sheen_alpha, n_dot_v);
    let el = sheen_albedo_rational::sheen_albedo(sheen_alpha, n_dot_l);
    return min(1.0 - c * ev, 1.0 - c * el);
}

@fragment
fn energy_fs(
    @location(0) params: vec4<f32>,  // GGX α, n·v, n·l, dielectric index of refraction
    @location(1) f0: vec3<f32>,
    @location(2) sheen: vec4<f32>,   // sheen colour, Charlie α
) -> @location(0) vec4<f32> {
    let alpha = params.x;
    let n_dot_v = params.y;
    let n_dot_l = params.z;
    let e_avg = ggx_albedo_avg::ggx_albedo_avg_fit(alpha);
    let fms = kulla_conty_fms(alpha, n_dot_v, n_dot_l);
    // Schlick's F averaged over the hemisphere (cosine-weighted): F0 + (1 − F0)/21.
    let conductor = kulla_conty_fresnel_ms(f0 + (1.0 - f0) / 21.0, e_avg) * fms * n_dot_l;
    let f_avg = vec3<f32>(ggx_published_refits::ggx_refit_fresnel_avg_dielectric(params.w));
    let dielectric = kulla_conty_fresnel_ms(f_avg, e_avg).x * fms * n_dot_l;
    return vec4<f32>(conductor * sheen_base_scale(sheen.rgb, sheen.a, n_dot_v, n_dot_l), dielectric);
}
