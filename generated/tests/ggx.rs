//! The DFG LUT modules: the CPU lookups read the KTX2 texels they ship (f16, exact) and hit them
//! at the texel centres, clamp beyond the outer centres, and decode both layouts to (scale, bias).

use shadefit_runtime::{ggx_dfg_lut as sb, ggx_dfg_lut_bevy as bevy, ggx_dfg_lut_filament as fil, skin};

#[test]
fn ktx2_headers_name_rg16f_and_the_size() {
    for (bytes, size) in [
        (sb::GGX_DFG_LUT_KTX2, sb::GGX_DFG_LUT_SIZE),
        (fil::GGX_DFG_LUT_FILAMENT_KTX2, fil::GGX_DFG_LUT_FILAMENT_SIZE),
        (bevy::GGX_DFG_LUT_BEVY_KTX2, bevy::GGX_DFG_LUT_BEVY_SIZE),
    ] {
        let u32_at = |k: usize| u32::from_le_bytes(bytes[k..k + 4].try_into().unwrap());
        assert_eq!(&bytes[1..4], b"KTX");
        assert_eq!(u32_at(12), 83, "VK_FORMAT_R16G16_SFLOAT");
        assert_eq!([u32_at(20), u32_at(24)], size);
    }
}

#[test]
fn the_runtime_ktx2_reader_gives_the_emitted_texels() {
    // Two readers of the same bytes: the runtime's `Ktx2Image` (header and level index, what the
    // GPU upload uses) and the emitted module's fixed offset; every texel equal, bit for bit.
    for (bytes, [w, h], texel) in [
        (sb::GGX_DFG_LUT_KTX2, sb::GGX_DFG_LUT_SIZE, sb::ggx_dfg_texel as fn(u32, u32) -> [f32; 2]),
        (fil::GGX_DFG_LUT_FILAMENT_KTX2, fil::GGX_DFG_LUT_FILAMENT_SIZE, fil::ggx_dfg_filament_texel),
        (bevy::GGX_DFG_LUT_BEVY_KTX2, bevy::GGX_DFG_LUT_BEVY_SIZE, bevy::ggx_dfg_bevy_texel),
    ] {
        let img = skin::Ktx2Image::parse(bytes).expect("an RG16F KTX2");
        assert_eq!((img.width, img.height, img.depth, img.format), (w, h, 0, skin::LutFormat::Rg16Float));
        for y in 0..h {
            for x in 0..w {
                let [r, g] = texel(x, y);
                let got = img.texel(x, y);
                // The missing channels read as WGSL reads an RG texture: (r, g, 0, 1).
                assert_eq!(got.map(f32::to_bits), [r, g, 0.0, 1.0].map(f32::to_bits), "texel ({x}, {y})");
            }
        }
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
        // bevy's layout is the 64² table in the scale-bias layout: the same bound.
        let c = bevy::ggx_dfg_bevy_scale_bias(u, r);
        for k in 0..2 {
            assert!((a[k] - b[k]).abs() < 3e-3 && (a[k] - c[k]).abs() < 3e-3, "({u}, {r}): {a:?} vs {b:?}, {c:?}");
        }
    }
}

mod cone {
    //! The cone LUT (COD: WWII's 3-D table): a 3-D RG16F texture whose lookups hit the texels
    //! at the centres and on the slices, interpolate linearly in cos θc between slices, and whose
    //! first slice holds what the 2-D table holds where the two share a sample.
    use shadefit_runtime::ggx_cone_lut as cone;

    #[test]
    fn ktx2_header_is_a_3d_rg16f_texture_of_the_size() {
        let bytes = cone::GGX_CONE_LUT_KTX2;
        let u32_at = |k: usize| u32::from_le_bytes(bytes[k..k + 4].try_into().unwrap());
        assert_eq!(&bytes[1..4], b"KTX");
        assert_eq!(u32_at(12), 83, "VK_FORMAT_R16G16_SFLOAT");
        // pixelWidth, pixelHeight, pixelDepth, layerCount (0: not an array).
        assert_eq!([u32_at(20), u32_at(24), u32_at(28)], cone::GGX_CONE_LUT_SIZE);
        assert_eq!(u32_at(32), 0);
    }

    #[test]
    fn the_runtime_ktx2_reader_gives_the_emitted_texels_of_every_slice() {
        let [w, h, d] = cone::GGX_CONE_LUT_SIZE;
        let img = shadefit_runtime::skin::Ktx2Image::parse(cone::GGX_CONE_LUT_KTX2).expect("a 3-D RG16F KTX2");
        assert_eq!((img.width, img.height, img.depth, img.format), (w, h, d, shadefit_runtime::skin::LutFormat::Rg16Float));
        for z in 0..d {
            for y in 0..h {
                for x in 0..w {
                    let [r, g] = cone::ggx_cone_dfg_texel(x, y, z);
                    assert_eq!(img.texel_3d(x, y, z).map(f32::to_bits), [r, g, 0.0, 1.0].map(f32::to_bits), "texel ({x}, {y}, {z})");
                }
            }
        }
    }

    #[test]
    fn lookups_hit_texels_on_slices_and_are_linear_between_them() {
        let [w, h, d] = cone::GGX_CONE_LUT_SIZE;
        for (i, j, k) in [(0, 0, 0), (5, 17, 3), (w - 1, h - 1, d - 1), (16, 3, 6)] {
            // (i + 0.5)/n is dyadic and k/(d − 1)·(d − 1) rounds back to k: exact weights of 0.
            let (u, g, c) = ((i as f32 + 0.5) / w as f32, (j as f32 + 0.5) / h as f32, k as f32 / (d - 1) as f32);
            assert_eq!(cone::ggx_cone_dfg(u, g, c), cone::ggx_cone_dfg_texel(i, j, k));
        }
        // The closed cone is zero; NaN and out-of-range arguments clamp.
        assert_eq!(cone::ggx_cone_dfg(0.5, 0.5, 1.0), [0.0, 0.0]);
        assert_eq!(cone::ggx_cone_dfg(f32::NAN, 2.0, -1.0), cone::ggx_cone_dfg_texel(0, h - 1, 0));
        // Half way between slices 2 and 3 at a texel centre: the mean of the two texels. f32(2.5/7)·7
        // lands within 2 ulps of 2.5 (weight error ≤ 2.4e-7 on |a − b| ≤ 1), plus the lerp's two
        // roundings of values ≤ 1 (≤ 1.2e-7): 4e-7 bounds both.
        let (u, g) = (10.5 / w as f32, 20.5 / h as f32);
        let c = 2.5 / (d - 1) as f32;
        let (a, b) = (cone::ggx_cone_dfg_texel(10, 20, 2), cone::ggx_cone_dfg_texel(10, 20, 3));
        let m = cone::ggx_cone_dfg(u, g, c);
        for ch in 0..2 {
            assert!((m[ch] - 0.5 * (a[ch] + b[ch])).abs() <= 4e-7, "{m:?} vs {a:?}, {b:?}");
        }
    }

    /// Special f32 inputs (signed zeros, denormals, infinities, NaN, out of the domain) and a
    /// coarse grid, for every argument of the 3-argument cone functions.
    fn specials() -> Vec<f32> {
        let mut v = vec![0.0, -0.0, 1e-45, -1e-45, f32::MIN_POSITIVE, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, f32::MAX, f32::MIN, 1.0, 1.0 + f32::EPSILON, -1.0, 0.05];
        v.extend((0..=20).map(|i| i as f32 / 20.0));
        v
    }

    #[test]
    fn cone_functions_are_finite_and_in_range_for_every_input() {
        use shadefit_runtime::{ggx_cone_bias_rational as br, ggx_cone_scale_rational as sr};
        // Scale and bias lie in [0, 1] (clamped fits; f16 texels of values in [0, 1], convex
        // combinations of them): no allowance needed.
        let s = specials();
        for &a in &s {
            for &b in &s {
                for &c in &s {
                    let t = cone::ggx_cone_dfg_scale_bias(a, b, c);
                    let f = [sr::ggx_cone_scale(a, b, c), br::ggx_cone_bias(a, b, c)];
                    for v in t.into_iter().chain(f) {
                        assert!(v.is_finite() && (0.0..=1.0).contains(&v), "({a:e}, {b:e}, {c:e}): {t:?} {f:?}");
                    }
                }
            }
        }
        // The (1 − cos θc) factor: the closed cone is exactly 0, as the table's last slice.
        assert_eq!((sr::ggx_cone_scale(0.3, 0.5, 1.0), br::ggx_cone_bias(0.3, 0.5, 1.0)), (0.0, 0.0));
    }
}
