//! The SGGX decoder and NDF (`sggx_decode`) for the interpreter and GPU tests: `sggx_decode`
//! returns a struct, so neither it nor `sggx_d` is in `FUNCTIONS`; they run through the scalar
//! wrappers [`WRAPPERS`] (composed after the library): one per decoded field of a channel
//! triple, and D of a triple's decoded values at (t·h, b·h, n·h).

#![allow(dead_code)]

use shadefit_runtime::sggx_decode::{SggxAniso, sggx_d, sggx_decode};

pub const WRAPPERS: &str = "
fn t_alpha_t_sqr(x: f32, y: f32, z: f32) -> f32 { return sggx_decode(vec3<f32>(x, y, z)).alpha_t_sqr; }
fn t_alpha_b_sqr(x: f32, y: f32, z: f32) -> f32 { return sggx_decode(vec3<f32>(x, y, z)).alpha_b_sqr; }
fn t_alpha_tb(x: f32, y: f32, z: f32) -> f32 { return sggx_decode(vec3<f32>(x, y, z)).alpha_tb; }
fn t_cos_psi(x: f32, y: f32, z: f32) -> f32 { return sggx_decode(vec3<f32>(x, y, z)).cos_psi; }
fn t_sin_psi(x: f32, y: f32, z: f32) -> f32 { return sggx_decode(vec3<f32>(x, y, z)).sin_psi; }
fn t_d(x: f32, y: f32, z: f32, th: f32, bh: f32, nh: f32) -> f32 {
    return sggx_d(sggx_decode(vec3<f32>(x, y, z)), th, bh, nh);
}
";

/// The decoded fields, by wrapper name.
pub const FIELDS: [(&str, fn(&SggxAniso) -> f32); 5] = [
    ("t_alpha_t_sqr", |a| a.alpha_t_sqr),
    ("t_alpha_b_sqr", |a| a.alpha_b_sqr),
    ("t_alpha_tb", |a| a.alpha_tb),
    ("t_cos_psi", |a| a.cos_psi),
    ("t_sin_psi", |a| a.sin_psi),
];

/// Channel values: a grid of [0, 1], −0, out-of-range values and 1⁻. No tiny channels: a
/// subnormal Sxy may flush to zero on a GPU and flip the sign test (harmlessly: the α's are
/// then equal to rounding and the axis is arbitrary).
pub fn channels() -> Vec<f32> {
    let mut v: Vec<f32> = (0..=12).map(|i| i as f32 / 12.0).collect();
    v.extend([-0.0, -0.5, 1.5, 0.999_999_94]);
    v
}

/// Every channel triple, as f32 bits (3 words each).
pub fn decode_points() -> Vec<u32> {
    let ch = channels();
    let mut p = Vec::new();
    for &x in &ch {
        for &y in &ch {
            for &z in &ch {
                p.extend([x.to_bits(), y.to_bits(), z.to_bits()]);
            }
        }
    }
    p
}

/// Channel triples × (t·h, b·h, n·h), as f32 bits (6 words each).
pub fn d_points() -> Vec<u32> {
    let dots = [-1.0f32, -0.7, -0.3, 0.0, 0.2, 0.5, 0.9, 1.0, 1.5];
    let few = [0.0f32, 0.1, 0.5, 0.75, 1.0];
    let mut p = Vec::new();
    for &x in &few {
        for &y in &few {
            for &z in &few {
                for &th in &dots {
                    for &bh in &dots {
                        for &nh in &dots {
                            p.extend([x, y, z, th, bh, nh].map(f32::to_bits));
                        }
                    }
                }
            }
        }
    }
    p
}

pub fn cpu_field(name: &str, p: &[f32]) -> f32 {
    let f = FIELDS.iter().find(|f| f.0 == name).expect("a field wrapper").1;
    f(&sggx_decode([p[0], p[1], p[2]]))
}

pub fn cpu_d(p: &[f32]) -> f32 {
    sggx_d(&sggx_decode([p[0], p[1], p[2]]), p[3], p[4], p[5])
}
