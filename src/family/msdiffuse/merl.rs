//! MERL's isotropic BRDF file layout (Matusik, Pfister, Brand & McMillan 2003, "A Data-Driven
//! Reflectance Model"; the database's reader `BRDFRead.cpp`, whose `read_brdf`,
//! `theta_half_index`, `theta_diff_index`, `phi_diff_index` and `lookup_brdf_val` define it), which
//! BRDF Explorer and the MERL tools open:
//!
//! - three little-endian int32: 90, 90, 180 (θh, θd, φd sample counts);
//! - 3 × 90·90·180 little-endian f64: the red block, then green, then blue; within a block the
//!   index is φd + 180·(θd + 90·θh);
//! - a reader multiplies red by 1/1500, green by 1.15/1500 and blue by 1.66/1500;
//! - indices (the reader truncates): θh → ⌊√(θh/(π/2)·90·90)⌋ (non-linear: fine near the
//!   specular peak), θd → ⌊θd/(π/2)·90⌋, φd → ⌊φd/π·180⌋ after φd < 0 ↦ φd + π (reciprocity
//!   and isotropy fold φd into [0, π)), each clamped to its last index;
//! - negative values mark directions below the horizon.
//!
//! shadefit writes each cell's value at the cell's centre in index space (the value a
//! truncating reader returns over the whole cell): θh = ((i + ½)/90)² π/2, θd = (j + ½)/90 · π/2,
//! φd = (k + ½)/180 · π, and a grey BRDF (the same f in the three channels: red f·1500, green
//! f·1500/1.15, blue f·1500/1.66). Cells whose light or view is below the horizon hold −1.

use std::f64::consts::{FRAC_PI_2, PI};

pub const THETA_H: usize = 90;
pub const THETA_D: usize = 90;
pub const PHI_D: usize = 180;
/// Cells per channel block.
pub const CELLS: usize = THETA_H * THETA_D * PHI_D;
pub const SCALES: [f64; 3] = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];
/// Bytes of a file: the dimensions and three blocks.
pub const BYTES: usize = 12 + 3 * CELLS * 8;

/// (θh, θd, φd) of cell `c` = k + 180 (j + 90 i): the centre of the cell in index space.
pub fn cell_angles(c: usize) -> (f64, f64, f64) {
    let k = c % PHI_D;
    let j = (c / PHI_D) % THETA_D;
    let i = c / (PHI_D * THETA_D);
    let u = (i as f64 + 0.5) / THETA_H as f64;
    (u * u * FRAC_PI_2, (j as f64 + 0.5) / THETA_D as f64 * FRAC_PI_2, (k as f64 + 0.5) / PHI_D as f64 * PI)
}

/// The red channel's stored value of a BRDF value f (None: below the horizon).
pub fn red_of(f: Option<f64>) -> f64 {
    match f {
        Some(f) => f / SCALES[0],
        None => -1.0,
    }
}

/// The file of the red channel's stored values `red` (one per cell); green and blue hold the
/// same BRDF (red·1/1.15, red·1/1.66; −1 stays −1).
pub fn encode(red: &[f64]) -> Vec<u8> {
    assert_eq!(red.len(), CELLS, "a MERL table has 90·90·180 cells");
    let mut out = Vec::with_capacity(BYTES);
    for d in [THETA_H, THETA_D, PHI_D] {
        out.extend_from_slice(&(d as i32).to_le_bytes());
    }
    for ratio in [1.0, 1.15, 1.66] {
        for &r in red {
            let v = if r < 0.0 { -1.0 } else { r / ratio };
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    out
}

/// The red channel's stored values of a file written by [`encode`] (None: not one).
pub fn decode_red(bytes: &[u8]) -> Option<Vec<f64>> {
    if bytes.len() != BYTES {
        return None;
    }
    let dims: Vec<i32> = (0..3).map(|k| i32::from_le_bytes(bytes[4 * k..4 * k + 4].try_into().unwrap())).collect();
    if dims != [90, 90, 180] {
        return None;
    }
    Some(bytes[12..12 + CELLS * 8].chunks(8).map(|b| f64::from_le_bytes(b.try_into().unwrap())).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reader written from the format's public description (the module doc), independent of
    /// `cell_angles`: the three channels at (θh, θd, φd).
    fn lookup(bytes: &[u8], th: f64, td: f64, pd: f64) -> [f64; 3] {
        let dims: Vec<i32> = (0..3).map(|k| i32::from_le_bytes(bytes[4 * k..4 * k + 4].try_into().unwrap())).collect();
        assert_eq!(dims, [90, 90, 180]);
        let ih = if th <= 0.0 { 0 } else { ((th / FRAC_PI_2 * 90.0 * 90.0).sqrt() as usize).min(89) };
        let id = ((td / FRAC_PI_2 * 90.0) as usize).min(89);
        let pd = if pd < 0.0 { pd + PI } else { pd };
        let ip = ((pd / PI * 180.0) as usize).min(179);
        let ind = ip + id * 180 + ih * 180 * 90;
        let at = |block: usize| f64::from_le_bytes(bytes[12 + 8 * (ind + block * 90 * 90 * 180)..][..8].try_into().unwrap());
        [at(0) * SCALES[0], at(1) * SCALES[1], at(2) * SCALES[2]]
    }

    #[test]
    fn a_reader_of_the_published_layout_returns_the_written_function() {
        // A smooth grey test BRDF f(θh, θd, φd), written at the cell centres, read back at
        // arbitrary angles by the independent reader: every channel returns f at the centre of
        // the cell holding the angles (the reader truncates), within f64 rounding of the scale
        // products (1e-12 relative).
        let f = |th: f64, td: f64, pd: f64| 0.3 + th.cos() * td.sin() + 0.1 * pd.cos();
        let red: Vec<f64> = (0..CELLS).map(|c| {
            let (a, b, p) = cell_angles(c);
            red_of(Some(f(a, b, p)))
        }).collect();
        let bytes = encode(&red);
        assert_eq!(bytes.len(), BYTES);
        assert_eq!(decode_red(&bytes).unwrap(), red);
        let mut state = 12345u64;
        let mut rnd = || {
            state = super::super::walk::mix64(state.wrapping_add(0x9e37_79b9_7f4a_7c15));
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..2000 {
            let (th, td, pd) = (rnd() * FRAC_PI_2, rnd() * FRAC_PI_2, (rnd() * 2.0 - 1.0) * PI);
            let got = lookup(&bytes, th, td, pd);
            // The centre of the cell in index space, computed from the angles directly.
            let ih = ((th / FRAC_PI_2).sqrt() * 90.0).floor().min(89.0);
            let (ch, cd) = (((ih + 0.5) / 90.0).powi(2) * FRAC_PI_2, ((td / FRAC_PI_2 * 90.0).floor().min(89.0) + 0.5) / 90.0 * FRAC_PI_2);
            let p = if pd < 0.0 { pd + PI } else { pd };
            let cp = ((p / PI * 180.0).floor().min(179.0) + 0.5) / 180.0 * PI;
            let want = f(ch, cd, cp);
            for g in got {
                assert!((g - want).abs() <= 1e-12 * want.abs(), "{got:?} vs {want} at ({th}, {td}, {pd})");
            }
        }
    }
}
