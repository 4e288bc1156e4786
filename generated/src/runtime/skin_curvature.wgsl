#define_import_path shadefit::skin_curvature

// Directional curvature for the pre-integrated skin LUTs (hand-written; shadefit-runtime,
// src/runtime/skin_curvature.wgsl; the Rust versions in src/runtime/skin.rs compute the same).
//
// Inputs: `tangent`, `bitangent`: an orthonormal frame of the tangent plane (with the normal
// n = tangent × bitangent); `curv_tensor` = vec3(k_tt, k_tb, k_bb): the symmetric curvature
// tensor (second fundamental form) C = [[k_tt, k_tb], [k_tb, k_bb]] in that frame, in 1/mm,
// positive where the surface bends away from its normal (a convex bump, a sphere of radius r
// has C = I/r); `light_dir`: unit vector towards the light. With l_t = (l·t, l·b), the light
// direction projected onto the tangent plane in that frame:
//
//   skin_curvature_from_light            κ = l_tᵀ C l_t, which is the curvature along the
//                                        projected direction times |l_t|² = 1 − (n·l)²: it fades
//                                        to 0 as the light nears the normal; cheap, continuous;
//   skin_curvature_from_light_normalized κ = l_tᵀ C l_t / |l_t|², the normal curvature of the
//                                        surface along the projected light direction (Euler:
//                                        k1 cos²ψ + k2 sin²ψ), which is what the LUT's ring
//                                        model assumes; the mean curvature (k_tt + k_bb)/2 when
//                                        |l_t|² < 1e-8 (light along the normal: no direction).
//
// Neither clamps: concave (negative) curvature is passed on, and the LUT lookups clamp it to
// the κ = 0 row (max(n·l, 0)).

fn skin_curvature_from_light(tangent: vec3<f32>, bitangent: vec3<f32>, curv_tensor: vec3<f32>, light_dir: vec3<f32>) -> f32 {
    let x = dot(light_dir, tangent);
    let y = dot(light_dir, bitangent);
    return curv_tensor.x * x * x + 2.0 * curv_tensor.y * x * y + curv_tensor.z * y * y;
}

fn skin_curvature_from_light_normalized(tangent: vec3<f32>, bitangent: vec3<f32>, curv_tensor: vec3<f32>, light_dir: vec3<f32>) -> f32 {
    let x = dot(light_dir, tangent);
    let y = dot(light_dir, bitangent);
    let q = curv_tensor.x * x * x + 2.0 * curv_tensor.y * x * y + curv_tensor.z * y * y;
    let len2 = x * x + y * y;
    return select(0.5 * (curv_tensor.x + curv_tensor.z), q / len2, len2 > 1e-8);
}
