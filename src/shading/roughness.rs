//! Roughness parameterisations: GGX α from the artist's parameter and back.
//!
//! - Perceptual roughness r (Burley 2012): α = r².
//! - Call of Duty: WWII's Gloss g ∈ [0, 1]: α = sqrt(2 / (1 + 2^(18 g))) (the talk's
//!   parameterisation, after the slides' erratum: the exponent is 18·g); g = 0 is α = 1, g = 1
//!   is α = sqrt(2/262145) ≈ 0.002762.

/// Exponent scale of the WWII Gloss parameterisation.
const GLOSS_EXPONENT: f64 = 18.0;

/// GGX α for perceptual roughness r: r².
pub fn alpha_from_roughness(r: f64) -> f64 {
    r * r
}

/// GGX α for Gloss g (WWII parameterisation).
pub fn alpha_from_gloss(g: f64) -> f64 {
    (2.0 / (1.0 + (GLOSS_EXPONENT * g).exp2())).sqrt()
}

/// Gloss for GGX α ∈ (0, 1] (inverse of [`alpha_from_gloss`]).
pub fn gloss_from_alpha(alpha: f64) -> f64 {
    (2.0 / (alpha * alpha) - 1.0).log2() / GLOSS_EXPONENT
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The WWII mapping by its definition, α²(1 + 2^(18 g)) = 2, with its two ends (α = 1 and
    /// sqrt(2/262145)); the inverse returns g to a few roundings of log2 (1e-14 absolute).
    #[test]
    fn the_wwii_mapping_is_its_definition_and_inverts() {
        assert_eq!(alpha_from_gloss(0.0), 1.0);
        assert!((alpha_from_gloss(1.0) - (2.0f64 / 262145.0).sqrt()).abs() < 1e-18);
        for i in 0..=20 {
            let g = i as f64 / 20.0;
            let a = alpha_from_gloss(g);
            // A few roundings of the square and the sum: 1e-15 relative.
            assert!((a * a * (1.0 + 2f64.powf(18.0 * g)) - 2.0).abs() <= 1e-14, "g {g}: α {a}");
            assert!((gloss_from_alpha(a) - g).abs() < 1e-14, "g {g}: back {}", gloss_from_alpha(a));
        }
        assert_eq!(alpha_from_roughness(0.5), 0.25);
    }
}
