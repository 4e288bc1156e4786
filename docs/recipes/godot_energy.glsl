#[compute]
#version 450
#extension GL_GOOGLE_include_directive : require
// A Godot 4 RenderingDevice compute shader (a `.glsl` file in the project; Godot compiles it
// with glslang after its own `#[compute]` section line) that bakes the Kulla–Conty compensation
// inputs into a 2-D image: R = E(μ) of GGX, G = E_avg(α), over uv = (μ, α) at texel centres.
// The includes are shadefit's GLSL 450 include forms (`build --target glsl`), copied with their
// folder beside this file. tests/targets.rs compiles it with `glslangValidator -V -S comp`.
#include "glsl/ggx_albedo_rational.glsl"   // ggx_albedo(alpha, n_dot_v)
#include "glsl/ggx_albedo_avg.glsl"        // ggx_albedo_avg_fit(alpha)

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(set = 0, binding = 0, rg32f) uniform restrict writeonly image2D energy_lut;

void main() {
    ivec2 size = imageSize(energy_lut);
    ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(texel, size))) {
        return;
    }
    vec2 uv = (vec2(texel) + 0.5) / vec2(size);
    float e = ggx_albedo(uv.y, uv.x);
    float e_avg = ggx_albedo_avg_fit(uv.y);
    imageStore(energy_lut, texel, vec4(e, e_avg, 0.0, 0.0));
}
