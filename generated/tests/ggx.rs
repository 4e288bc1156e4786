//! The DFG LUT modules: the CPU lookups read the KTX2 texels they ship (f16, exact) and hit them
//! at the texel centres, clamp beyond the outer centres, and decode both layouts to (scale, bias).

use shadefit_runtime::{ggx_dfg_lut as sb, ggx_dfg_lut_filament as fil};

#[test]
fn ktx2_headers_name_rg16f_and_the_size() {
    for (bytes, size) in [(sb::GGX_DFG_LUT_KTX2, sb::GGX_DFG_LUT_SIZE), (fil::GGX_DFG_LUT_FILAMENT_KTX2, fil::GGX_DFG_LUT_FILAMENT_SIZE)] {
        let u32_at = |k: usize| u32::from_le_bytes(bytes[k..k + 4].try_into().unwrap());
        assert_eq!(&bytes[1..4], b"KTX");
        assert_eq!(u32_at(12), 83, "VK_FORMAT_R16G16_SFLOAT");
        assert_eq!([u32_at(20), u32_at(24)], size);
    }
}

#[test]
fn lookups_hit_texel_centres_and_hold_the_edges() {
    let [w, h] = sb::GGX_DFG_LUT_SIZE;
    for (i, j) in [(0, 0), (5, 77), (w - 1, h - 1), (64, 3)] {
        // (i + 0.5)/n is dyadic: exact in f32, so the weights are exactly 0 at the centres.
        let (u, r) = ((i as f32 + 0.5) / w as f32, (j as f32 + 0.5) / h as f32);
        assert_eq!(sb::ggx_dfg(u, r), sb::ggx_dfg_texel(i, j));
    }
    assert_eq!(sb::ggx_dfg(0.0, 0.0), sb::ggx_dfg_texel(0, 0));
    assert_eq!(sb::ggx_dfg(f32::NAN, 2.0), sb::ggx_dfg_texel(0, h - 1));
    // F0 = 1: the albedo scale + bias.
    let [scale, bias] = sb::ggx_dfg_scale_bias(0.5, 0.5);
    assert_eq!(sb::ggx_dfg_specular([1.0, 0.0, 0.04], 0.5, 0.5), [scale + bias, bias, 0.04 * scale + bias]);
}

#[test]
fn both_layouts_decode_to_the_same_scale_and_bias() {
    // The 128² scale-bias table and the 64² Filament one at shared points: equal within the
    // 64² table's interpolation error there (≲ 2e-3 away from grazing n·v and low roughness,
    // fits/*.json "texture_interior") plus f16 rounding.
    for &(u, r) in &[(0.3f32, 0.4f32), (0.7, 0.2), (0.95, 0.9), (0.5, 0.6)] {
        let a = sb::ggx_dfg_scale_bias(u, r);
        let b = fil::ggx_dfg_filament_scale_bias(u, r);
        for c in 0..2 {
            assert!((a[c] - b[c]).abs() < 3e-3, "({u}, {r}): {a:?} vs {b:?}");
        }
    }
}
