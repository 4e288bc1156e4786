//! COD: WWII's 3-D environment BRDF for cone-based specular occlusion: the split-sum scale and
//! bias over (n·v, roughness, cos θc), a 3-D texture whose slice cos θc = 0 is the 2-D DFG
//! table and whose last slice (cos θc = 1) is zero. Its spec kind (`kind = "ggx-cone-lut"`,
//! [`spec`]), build ([`build`]), emitted files ([`emit`]) and figures ([`plot`]).

pub mod build;
pub mod emit;
pub mod plot;
pub mod spec;

use crate::family::SpecKind;
use crate::spec::KindDef;

/// The `ggx-cone-lut` spec kind: checked and spelled out by [`spec`], built by [`build`].
pub const CONE_LUT: SpecKind = SpecKind {
    spec: KindDef {
        name: spec::KIND,
        spec_file: crate::spec::preset_spec_file::<spec::ConeLut>,
        samples_note: "{name} is a cone LUT: its samples are its texels, \"values\" ([scale, bias]) in generated/json/{name}.json",
        input_hash: crate::pipeline::input_hash,
    },
    build: build::build,
    shard: None,
};

#[cfg(test)]
mod tests {
    use crate::spec::Preset;
    use super::build::{build, tabulate, trilinear};
    use super::spec::ConeLut;
    use crate::family::ggx::integrals::{Inner, Shadowing, env_with};
    use crate::family::ggx::lut::build::tabulate as tabulate_2d;
    use crate::family::ggx::lut::spec::DfgLut;
    use crate::pipeline::{Built, Mode};
    use crate::spec::Spec;
    use serde_json::Value;
    use std::path::Path;

    const SPEC: &str = "name = \"ggx_c\"\nkind = \"ggx-cone-lut\"\nquantity = \"ggx-env\"\n\
        resolution = [6, 5, 4]\ntolerance = 1e-8\n\n[emit]\nfunction = \"ggx_c\"\n";

    fn cone(text: &str) -> ConeLut {
        ConeLut::parse(Path::new("fits/ggx_c.toml"), text).unwrap()
    }

    fn built(text: &str) -> Built {
        let spec = Spec::parse(Path::new("fits/ggx_c.toml"), text.to_string(), crate::family::catalog()).unwrap();
        build(&spec, Mode::Fit, Path::new("")).unwrap()
    }

    fn artifact<'a>(b: &'a Built, suffix: &str) -> &'a [u8] {
        &b.artifacts.iter().find(|a| a.path.to_str().unwrap().ends_with(suffix)).unwrap().contents
    }

    fn committed(name: &str) -> Value {
        let path = format!("{}/generated/json/{name}.json", env!("CARGO_MANIFEST_DIR"));
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
    }

    fn values(v: &Value) -> Vec<[f64; 2]> {
        serde_json::from_value(v["values"].clone()).unwrap()
    }

    #[test]
    fn slice_zero_is_the_2d_table_bit_for_bit() {
        // The committed 128² DFG table (fits/ggx_dfg_lut.toml: perceptual rows, tolerance 1e-7)
        // against slice 0 of a cone LUT of the same resolution, mapping and tolerance.
        let dfg = values(&committed("ggx_dfg_lut"));
        let lut = cone(&SPEC.replace("[6, 5, 4]", "[128, 128, 2]\nroughness_mapping = \"perceptual\"").replace("1e-8", "1e-7"));
        let slice0 = tabulate_2d(&lut.slice(0)).0;
        assert_eq!(dfg.len(), slice0.len());
        for (k, (a, b)) in dfg.iter().zip(&slice0).enumerate() {
            assert!(a[0].to_bits() == b[0].to_bits() && a[1].to_bits() == b[1].to_bits(), "texel {k}: {a:?} vs {b:?}");
        }
        // The committed cone LUT (gloss rows) against a 2-D table spec with the same rows.
        let c = committed("ggx_cone_lut");
        let cone_values = values(&c);
        let (w, h) = (c["texture"]["width"].as_u64().unwrap() as usize, c["texture"]["height"].as_u64().unwrap() as usize);
        let text = format!(
            "name = \"ggx_x\"\nkind = \"ggx-dfg-lut\"\nquantity = \"ggx-env\"\nresolution = [{w}, {h}]\nroughness_mapping = \"gloss\"\ntolerance = {:e}\n\n[emit]\nfunction = \"ggx_x\"\n",
            c["quadrature"]["tolerance"].as_f64().unwrap()
        );
        let table = tabulate_2d(&DfgLut::parse(Path::new("fits/ggx_x.toml"), &text).unwrap()).0;
        for (k, (a, b)) in table.iter().zip(&cone_values[..w * h]).enumerate() {
            assert!(a[0].to_bits() == b[0].to_bits() && a[1].to_bits() == b[1].to_bits(), "texel {k}: {a:?} vs {b:?}");
        }
    }

    #[test]
    fn committed_lut_is_zero_in_the_last_slice_and_monotone_in_the_cone() {
        let c = committed("ggx_cone_lut");
        let v = values(&c);
        let t = &c["texture"];
        let [w, h, d] = ["width", "height", "depth"].map(|k| t[k].as_u64().unwrap() as usize);
        assert_eq!(v.len(), w * h * d);
        // The closed cone keeps no light direction: exactly 0 (the integral's empty region).
        assert!(v[(d - 1) * w * h..].iter().all(|x| x[0] == 0.0 && x[1] == 0.0));
        // Nested cones keep nested sets of directions of a non-negative integrand: along every
        // (n·v, row) column each channel is non-increasing in cos θc. No slack: each texel's
        // quadrature error (≤ 1e-7) is far below the drop between slices 1/7 apart wherever the
        // values differ, and equal values (0 past the mirror's reach at small α) compare equal.
        // f16 rounding is monotone, so the stored texels inherit it; checked on them too.
        let f16 = |x: f64| half::f16::from_f32(x as f32).to_f32();
        let mut drops = 0usize;
        for j in 0..h {
            for i in 0..w {
                for k in 1..d {
                    let (a, b) = (v[((k - 1) * h + j) * w + i], v[(k * h + j) * w + i]);
                    for ch in 0..2 {
                        assert!(b[ch] <= a[ch], "column ({i}, {j}), slice {k}, channel {ch}: {} after {}", b[ch], a[ch]);
                        assert!(f16(b[ch]) <= f16(a[ch]));
                        drops += usize::from(b[ch] < a[ch]);
                    }
                }
            }
        }
        // Most steps are strict drops (a test that passes on a constant table would be vacuous).
        assert!(drops > w * h * (d - 1), "{drops} strict drops");
    }

    #[test]
    fn texels_match_the_adaptive_reference_and_the_ktx2_is_a_3d_texture() {
        let b = built(SPEC);
        let json: Value = serde_json::from_slice(artifact(&b, ".json")).unwrap();
        let v = values(&json);
        let lut = cone(SPEC);
        let (w, h, d) = (lut.base.width, lut.base.height, lut.depth);
        // Independent of the nested azimuth rules: G10/K21 panels at 1e-12; each texel within the
        // spec's 1e-8 (env's contract) plus the reference's 1e-12.
        for (idx, x) in v.iter().enumerate() {
            let (i, j, k) = (idx % w, (idx / w) % h, idx / (w * h));
            let alpha = lut.base.alpha(j);
            let r = env_with(alpha, lut.base.n_dot_v(i), lut.cos_cone(k), Shadowing::HeightCorrelated, 1e-12, Inner::Adaptive);
            assert!((x[0] - r.scale).abs() <= 1e-8 + 1e-12 && (x[1] - r.bias).abs() <= 1e-8 + 1e-12, "texel ({i}, {j}, {k}): {x:?} vs {r:?}");
        }
        // KTX2: a 3-D texture (pixelDepth = slices, no layers), RG16F, slice-major texels.
        let r = ktx2::Reader::new(artifact(&b, ".ktx2")).expect("a valid KTX2 file");
        let hd = r.header();
        assert_eq!((hd.pixel_width, hd.pixel_height, hd.pixel_depth, hd.layer_count, hd.face_count), (w as u32, h as u32, d as u32, 0, 1));
        assert_eq!(hd.format.map(|f| f.value()), Some(83));
        let data = r.levels().next().unwrap().data;
        let t: Vec<f32> = data.chunks(2).map(|c| half::f16::from_le_bytes([c[0], c[1]]).to_f32()).collect();
        let f16 = |x: f64| half::f16::from_f32(x as f32).to_f32();
        for (k, &[s, bias]) in v.iter().enumerate() {
            assert_eq!((t[2 * k], t[2 * k + 1]), (f16(s), f16(bias)), "texel {k}");
        }
        let kv: Vec<(&str, &[u8])> = r.key_value_data().collect();
        assert!(kv.iter().any(|(k, val)| *k == "KTXorientation" && val[..] == b"rdi\0"[..]));
        // The recorded filtering error: the stored texels, trilinear, at the recorded worst point
        // against the integral there (adaptive reference) reproduce the recorded maximum to
        // within the verification integral's tolerance (1e-6) plus the reference's 1e-12.
        let m = &json["verification"]["texture"];
        let p: Vec<f64> = serde_json::from_value(m["worst_point"].clone()).unwrap();
        let stored: Vec<[f64; 2]> = v.iter().map(|x| x.map(|y| f16(y) as f64)).collect();
        let got = trilinear(&stored, (w, h, d), p[0], p[1], p[2]);
        let r = env_with(lut.base.mapping.alpha(p[1]), p[0], p[2], Shadowing::HeightCorrelated, 1e-12, Inner::Adaptive);
        let e = (got[0] - r.scale).abs().max((got[1] - r.bias).abs());
        assert!((e - m["max_abs_error"].as_f64().unwrap()).abs() <= 1e-6 + 1e-12, "{e} vs {m}");
        assert_eq!(json["verification"]["points"], 12 * 10 * 6);
    }

    #[test]
    fn build_is_deterministic_across_threads_and_committed_mode_rerenders_it() {
        let s = Spec::parse(Path::new("fits/ggx_c.toml"), SPEC.to_string(), crate::family::catalog()).unwrap();
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| build(&s, Mode::Fit, Path::new("")).unwrap())
        };
        let (one, two) = (run(1), run(2));
        assert_eq!(one.artifacts.len(), 5);
        for (a, b) in one.artifacts.iter().zip(&two.artifacts) {
            assert!(a.path == b.path && a.contents == b.contents, "{} differs between 1 and 2 threads", a.path.display());
        }
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(dir.path().join("json")).unwrap();
        std::fs::write(dir.path().join("json/ggx_c.json"), artifact(&one, ".json")).unwrap();
        let again = build(&s, Mode::Committed, dir.path()).unwrap();
        for (a, b) in one.artifacts.iter().zip(&again.artifacts) {
            assert!(a.path == b.path && a.contents == b.contents, "{} differs when re-rendered", a.path.display());
        }
        // tabulate is the 2-D tables slice by slice.
        let lut = cone(SPEC);
        let (v, _) = tabulate(&lut);
        assert_eq!(v[3 * 30..], tabulate_2d(&lut.slice(3)).0[..]);
    }
}
