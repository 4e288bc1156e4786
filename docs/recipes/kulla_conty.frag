#version 450 core
#extension GL_GOOGLE_include_directive : require
// Kulla–Conty multiple-scattering energy compensation for GGX (Kulla & Conty, "Revisiting
// Physically Based Shading at Imageworks", SIGGRAPH 2017 course), built from shadefit's
// emitted GLSL 450 modules in include form. Compile with generated/ on the include path
// (`build --target glsl` writes generated/glsl/); tests/targets.rs compiles this file with
// `glslangValidator -V -I<generated>`.
#include "glsl/ggx_albedo_rational.glsl"   // E(μ):   ggx_albedo(alpha, n_dot_v)
#include "glsl/ggx_albedo_avg.glsl"        // E_avg:  ggx_albedo_avg_fit(alpha)
#include "glsl/ggx_published_refits.glsl"  // F_avg of a dielectric: ggx_refit_fresnel_avg_dielectric(eta)

const float KC_PI = 3.14159265;

// The compensation lobe f_ms(μo, μi) = (1 − E(μo)) (1 − E(μi)) / (π (1 − E_avg)). Near α = 0,
// E and E_avg tend to 1 together; the floor keeps the ratio finite.
float kulla_conty_fms(float alpha, float n_dot_v, float n_dot_l) {
    float e_avg = ggx_albedo_avg_fit(alpha);
    return (1.0 - ggx_albedo(alpha, n_dot_v)) * (1.0 - ggx_albedo(alpha, n_dot_l)) / (KC_PI * max(1.0 - e_avg, 1e-6));
}

// The Fresnel term of the multiply scattered light: F_avg² E_avg / (1 − F_avg (1 − E_avg)).
vec3 kulla_conty_fresnel_ms(vec3 f_avg, float e_avg) {
    return f_avg * f_avg * e_avg / (1.0 - f_avg * (1.0 - e_avg));
}

// Schlick's Fresnel averaged over the hemisphere (cosine-weighted): F0 + (1 − F0) / 21.
vec3 kulla_conty_f_avg_schlick(vec3 f0) {
    return f0 + (1.0 - f0) / 21.0;
}

layout(location = 0) in vec4 params;   // alpha, n·v, n·l, eta
layout(location = 1) in vec3 f0;
layout(location = 0) out vec4 color;

// A conductor of reflectance f0 and a dielectric of index eta: the compensation term each adds
// to its single-scattering BRDF (times n·l).
void main() {
    float alpha = params.x, n_dot_v = params.y, n_dot_l = params.z, eta = params.w;
    float e_avg = ggx_albedo_avg_fit(alpha);
    float fms = kulla_conty_fms(alpha, n_dot_v, n_dot_l);
    vec3 conductor = kulla_conty_fresnel_ms(kulla_conty_f_avg_schlick(f0), e_avg) * fms * n_dot_l;
    float dielectric = kulla_conty_fresnel_ms(vec3(ggx_refit_fresnel_avg_dielectric(eta)), e_avg).x * fms * n_dot_l;
    color = vec4(conductor, dielectric);
}
