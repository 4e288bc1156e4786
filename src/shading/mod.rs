//! The shading layer: BRDF lobes, the terms they are made of (distributions, masking, Fresnel,
//! roughness mappings), and the hemispherical operators over any lobe.
//!
//! - [`lobe`]: the [`Lobe`] trait, what a lobe tells the integrator (its BRDF, its sampling
//!   measure, its narrow features);
//! - [`hemisphere`]: the operators generic over lobes on the one adaptive engine: split-sum
//!   [scale, bias] (optionally in a visibility cone), directional albedo E(μ), E_avg;
//! - [`trowbridge_reitz`]: the GGX lobe (height-correlated and separable Schlick–Smith
//!   masking), D and Λ; [`lambert`]: Lambert's lobe; [`charlie`]: the Charlie cloth lobe with
//!   Ashikhmin's visibility;
//! - [`written`]: a lobe given as its BRDF function alone (a user's lobe spec) in the cosine
//!   or GGX's measure;
//! - [`fresnel`]: Schlick's and the dielectric Fresnel and their averages;
//! - [`roughness`]: α from perceptual roughness and from WWII's Gloss.
//!
//! The layer depends on `integrate` only; families take their terms from here.

pub mod charlie;
pub mod fresnel;
pub mod hemisphere;
pub mod lambert;
pub mod lobe;
pub mod roughness;
pub mod trowbridge_reitz;
pub mod written;

pub use lobe::Lobe;

/// The unit vector (sin θ cos φ, sin θ sin φ, cos θ).
pub fn direction(theta: f64, phi: f64) -> [f64; 3] {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    [st * cp, st * sp, ct]
}
