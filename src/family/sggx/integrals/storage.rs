//! Storage: the 8/16-bit encoding [√Sxx, ½ Sxy/√(Sxx Syy) + ½, √Syy] of a block, and the
//! course's `DecodeSggx`, written once as a program and evaluated in f64 here (conventions in
//! the module doc of `super`).

use super::Aniso;
use crate::fit::expr::Expr;
use crate::fit::expr::program::{Record, build::*};
use std::sync::LazyLock;

/// [√Sxx, ½ Sxy/√(Sxx Syy) + ½, √Syy] (the middle channel ½ where Sxx Syy = 0).
pub fn encode(a: Aniso) -> [f64; 3] {
    let (x, z) = (a.sxx.max(0.0).sqrt(), a.syy.max(0.0).sqrt());
    let r = if x * z > 0.0 { (a.sxy / (x * z)).clamp(-1.0, 1.0) } else { 0.0 };
    [x, 0.5 * r + 0.5, z]
}

/// Each channel rounded to the nearest `bits`-bit UNORM value.
pub fn quantize(v: [f64; 3], bits: u32) -> [f64; 3] {
    let q = ((1u64 << bits) - 1) as f64;
    v.map(|c| (c.clamp(0.0, 1.0) * q).round() / q)
}

/// The matrix of stored channels (no clamp: the inverse of [`encode`]).
pub fn decode_matrix(t: [f64; 3]) -> Aniso {
    Aniso { sxx: t[0] * t[0], sxy: t[0] * (2.0 * t[1] - 1.0) * t[2], syy: t[2] * t[2] }
}

/// What the course's `DecodeSggx` returns, besides the rotated frame: α_t², α_b², α_t α_b and
/// the cosine and sine of the α_t axis's angle from t_n.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Decoded {
    pub alpha_t_sqr: f64,
    pub alpha_b_sqr: f64,
    pub alpha_tb: f64,
    pub cos: f64,
    pub sin: f64,
}

impl Decoded {
    /// The 2×2 matrix the decoded values describe.
    pub fn aniso(&self) -> Aniso {
        let (c, s) = (self.cos, self.sin);
        let (a, b) = (self.alpha_t_sqr, self.alpha_b_sqr);
        Aniso { sxx: c * c * a + s * s * b, sxy: c * s * (a - b), syy: s * s * a + c * c * b }
    }
}

/// The floor of discr under its reciprocal in `DecodeSggx` (a constant of [`DECODE_FORM`]).
pub const DISCR_MIN: f64 = 1e-6;

/// The constants of [`DECODE_FORM`]: the eigenvalues' floor α_min² and [`DISCR_MIN`].
pub fn decode_consts(alpha_min: f64) -> [f64; 2] {
    [alpha_min * alpha_min, DISCR_MIN]
}

/// The course's `DecodeSggx` written once, over the channels (x, y, z) (inputs 0–2) with the
/// constants of [`decode_consts`]: eigenvalues of the 2×2 matrix clamped to [α_min², 1]
/// (guarding the indefinite matrices that filtering the encoded channels produces), the
/// rotation from the half-angle identity cos²ψ = ½((Sxx − Syy)/discr + 1):
/// ```text
/// Sxx = x²,  Sxy = x (y + y − 1) z,  Syy = z²,  discr = √(4 Sxy² + (Sxx − Syy)²)
/// α_t², α_b² = max(clamp(½ (Sxx + Syy ± discr), 0, 1), α_min²)
/// c² = clamp(½ ((Sxx − Syy)/max(discr, 1e-6) + 1), 0, 1),  sign = Sxy < 0 ? −1 : 1
/// → (α_t², α_b², √(α_t² α_b²), √c², sign √(1 − c²))
/// ```
/// The listing's `Sign` must not return 0: at Sxy = 0 with Sxx < Syy (an axis-aligned lobe
/// rougher along b_n, or the texture unit's halfway mix of ±ρ) cos ψ = 0, and HLSL's sign(0) = 0
/// would make the sine 0 too, collapsing the frame; Sign(x) = x < 0 ? −1 : 1 here. 2y − 1 is
/// written y + y − 1 (the same value, exactly): no product for a GPU to fuse. Its f64
/// evaluation is [`decode_course`]; the emitted decoder (`super::super::emit`) is its WGSL,
/// Rust and f32 evaluation.
pub static DECODE_FORM: LazyLock<Record> = LazyLock::new(|| {
    let (x, y, z) = (|| bind(0), || bind(1), || bind(2));
    let (sxx, sxy, syy, discr, discr_rcp) = (|| bind(3), || bind(4), || bind(5), || bind(6), || bind(7));
    let (alpha_t_sqr, alpha_b_sqr, c_sqr, sign) = (|| bind(8), || bind(9), || bind(10), || bind(11));
    let unit = |e: Expr| clamp(e, lit(0.0), lit(1.0));
    let lets = vec![
        ("x".into(), var(0)),
        ("y".into(), var(1)),
        ("z".into(), var(2)),
        ("sxx".into(), x() * x()),
        ("sxy".into(), x() * (y() + y() - lit(1.0)) * z()),
        ("syy".into(), z() * z()),
        ("discr".into(), sqrt(lit(4.0) * (sxy() * sxy()) + (sxx() - syy()) * (sxx() - syy()))),
        ("discr_rcp".into(), lit(1.0) / max(discr(), k(1))),
        ("alpha_t_sqr".into(), max(unit(lit(0.5) * (sxx() + syy() + discr())), k(0))),
        ("alpha_b_sqr".into(), max(unit(lit(0.5) * (sxx() + syy() - discr())), k(0))),
        ("c_sqr".into(), unit(lit(0.5) * ((sxx() - syy()) * discr_rcp() + lit(1.0)))),
        ("sign".into(), less(sxy(), lit(0.0), lit(-1.0), lit(1.0))),
    ];
    let fields = vec![
        ("alpha_t_sqr".into(), alpha_t_sqr()),
        ("alpha_b_sqr".into(), alpha_b_sqr()),
        ("alpha_tb".into(), sqrt(alpha_t_sqr() * alpha_b_sqr())),
        ("cos_psi".into(), sqrt(c_sqr())),
        ("sin_psi".into(), sign() * sqrt(lit(1.0) - c_sqr())),
    ];
    Record { lets, name: "SggxAniso".into(), fields }
});

/// `DecodeSggx` in f64: [`DECODE_FORM`] at the channels `t`, with no clamp of the channels.
pub fn decode_course(t: [f64; 3], alpha_min: f64) -> Decoded {
    let v = DECODE_FORM.eval_f64(&t, &decode_consts(alpha_min));
    Decoded { alpha_t_sqr: v[0], alpha_b_sqr: v[1], alpha_tb: v[2], cos: v[3], sin: v[4] }
}

#[cfg(test)]
mod tests {
    use super::super::ALPHA_MIN;
    use super::*;
    use crate::integrate::rng::SplitMix64;

    #[test]
    fn encode_of_a_singular_block_has_middle_channel_one_half() {
        // The doc: the middle channel is ½ where Sxx·Syy = 0; the others are √Sxx, √Syy.
        assert_eq!(encode(Aniso { sxx: 0.25, sxy: 0.0, syy: 0.0 }), [0.5, 0.5, 0.0]);
        assert_eq!(encode(Aniso { sxx: 0.0, sxy: 0.0, syy: 0.64 }), [0.0, 0.5, 0.8]);
        // And a regular one: Sxy/√(Sxx Syy) = 0.03/(0.5·0.3) = 0.2, stored 0.6.
        let e = encode(Aniso { sxx: 0.25, sxy: 0.03, syy: 0.09 });
        assert!((e[0] - 0.5).abs() < 1e-16 && (e[1] - 0.6).abs() < 1e-15 && (e[2] - 0.3).abs() < 1e-16, "{e:?}");
    }

    #[test]
    fn encode_decode_round_trip() {
        // Unquantised: decode ∘ encode is the identity to f64 rounding of a product of three
        // values ≤ 1 (1e-15). Quantised to b bits, each channel moves ≤ 2^-(b+1); Sxx = x² moves
        // ≤ 2x·δ + δ² ≤ 2^-b + 2^-2(b+1), and Sxy = x(2y−1)z by ≤ (1 + 2 + 1)δ(1 + δ)².
        let mut rng = SplitMix64(3);
        for bits in [8u32, 16] {
            let delta = 0.5 / ((1u64 << bits) - 1) as f64;
            let bound = 4.0 * delta * (1.0 + delta).powi(2);
            let mut worst: f64 = 0.0;
            for _ in 0..10_000 {
                let a = Aniso::from_alphas(rng.next_f64(), rng.next_f64(), 6.3 * rng.next_f64());
                assert!(decode_matrix(encode(a)).max_diff(&a) < 1e-15);
                let e = decode_matrix(quantize(encode(a), bits)).max_diff(&a);
                worst = worst.max(e);
            }
            println!("{bits}-bit round trip: max |ΔS| {worst:.3e} (bound {bound:.3e})");
            assert!(worst <= bound && worst > 0.1 * bound, "{bits} bits: {worst} vs {bound}");
        }
    }

    #[test]
    fn course_decoder_recovers_alphas_and_axis_and_guards_indefinite_matrices() {
        // Exact channels: α², the axis and the matrix come back to f64 rounding amplified by
        // 1/discr where the eigenvalues nearly coincide (here discr ≥ 1e-3: 1e-12).
        let mut rng = SplitMix64(5);
        for _ in 0..1000 {
            let (at, ab) = (0.05 + 0.95 * rng.next_f64(), 0.05 + 0.95 * rng.next_f64());
            if (at * at - ab * ab).abs() < 1e-3 {
                continue;
            }
            let a = Aniso::from_alphas(at, ab, 6.3 * rng.next_f64());
            let d = decode_course(encode(a), ALPHA_MIN);
            assert!(d.aniso().max_diff(&a) < 1e-12, "{:?} vs {a:?}", d.aniso());
            assert!((d.alpha_t_sqr - at.max(ab).powi(2)).abs() < 1e-12);
            // α_t α_b, the product of the two roots (the same 1e-12 of rounding).
            assert!((d.alpha_tb - at * ab).abs() < 1e-12, "α_t α_b {} vs {}", d.alpha_tb, at * ab);
            assert!((d.cos * d.cos + d.sin * d.sin - 1.0).abs() < 1e-12);
        }
        // Channels in [0, 1] always decode to a positive semi-definite matrix: |2y − 1| ≤ 1 gives
        // Sxy² ≤ Sxx Syy. Filtering the channels (not S) therefore reaches singular matrices,
        // not indefinite ones: the mean of (1, 1, 1) (Sxy = +1, rank 1) and (0, 1, 0) is
        // (½, 1, ½), of rank 1, whose zero eigenvalue the decoder clamps to α_min².
        for _ in 0..10_000 {
            let m = decode_matrix([rng.next_f64(), rng.next_f64(), rng.next_f64()]);
            assert!(m.sxx * m.syy - m.sxy * m.sxy >= -1e-16);
        }
        let mix = [0.5, 1.0, 0.5];
        let m = decode_matrix(mix);
        assert_eq!(m.sxx * m.syy - m.sxy * m.sxy, 0.0, "the average is singular");
        let d = decode_course(mix, ALPHA_MIN);
        assert_eq!(d.alpha_b_sqr, ALPHA_MIN * ALPHA_MIN);
        assert!((d.alpha_t_sqr - 0.5).abs() < 1e-15 && d.alpha_tb > 0.0);
    }

    #[test]
    fn decoder_keeps_the_frame_of_axis_aligned_lobes_rougher_along_b() {
        // Sxy = 0 exactly, Sxx < Syy (α 0.25 along t_n, 0.5 along b_n): cos ψ = 0, so sin ψ must
        // be ±1 (HLSL's sign(0) = 0 would give a zero tangent). Exact: the channels 0.25, 0.5,
        // 0.5 and every operation on them are exact in binary.
        // Sign(0) = +1 (the listing's Sign as read here, and the emitted decoder's): sin ψ = +1.
        let d = decode_course(encode(Aniso { sxx: 0.0625, sxy: 0.0, syy: 0.25 }), ALPHA_MIN);
        assert_eq!((d.cos, d.sin), (0.0, 1.0));
        assert_eq!((d.alpha_t_sqr, d.alpha_b_sqr), (0.25, 0.0625));
    }

    /// `quantize` returns the nearest of the 2^b values k/(2^b − 1): every 8-bit code k/255
    /// comes back exactly, and so does a value 0.3/255 either side of it; values outside
    /// [0, 1] clamp to the ends; at 16 bits the step is 1/65535.
    #[test]
    fn quantize_rounds_to_the_nearest_unorm_code() {
        for k in 0..=255u32 {
            let code = k as f64 / 255.0;
            let near = [code, (k as f64 + 0.3) / 255.0, (k as f64 - 0.3).max(0.0) / 255.0];
            assert_eq!(quantize(near, 8), [code; 3], "code {k}");
        }
        assert_eq!(quantize([-0.2, 1.7, 0.5], 8), [0.0, 1.0, 128.0 / 255.0]);
        assert_eq!(quantize([1000.4 / 65535.0, 0.0, 1.0], 16), [1000.0 / 65535.0, 0.0, 1.0]);
    }
}
