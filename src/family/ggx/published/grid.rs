//! The grids the published forms are measured on, with the integrals there (computed once per
//! run, in parallel, collected in grid order: the same at any thread count).

use super::super::integrals::{self, Shadowing};
use super::forms;
use rayon::prelude::*;
use std::sync::OnceLock;

/// Absolute tolerance of the reference integrals: three decades below the smallest error
/// measured here (≥ 1e-4), loose enough that the grids take a few seconds.
pub const TOL: f64 = 1e-7;

/// n·v at the 64 texel centres (i + ½)/64 (the sampling of the engines' LUTs). n·v = 0 itself is
/// left out: there the height-correlated albedo jumps to its limit 1 through a boundary layer
/// of width ~α (E(n·v = 0.01, α = 0.01) = 0.892), which no published form models and shaders
/// never see (they clamp n·v away from 0).
pub fn n_dot_v_axis() -> Vec<f64> {
    (0..64).map(|i| (i as f64 + 0.5) / 64.0).collect()
}

/// 65 uniform values on [0, 1].
pub fn unit_axis() -> Vec<f64> {
    (0..65).map(|j| j as f64 / 64.0).collect()
}

/// How a grid's second coordinate becomes α, and which G the integral uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// Perceptual roughness r (α = r²), UE4's separable Schlick–Smith G, k = α/2 (ggx-env-ue4).
    RoughnessUe4,
    /// Perceptual roughness r (α = r²), height-correlated Smith (ggx-env).
    Roughness,
    /// Black Ops II gloss g: α = sqrt(2/(8192^g + 2)) (see [`forms::alpha_of_gloss`]), height-correlated.
    Gloss,
    /// α itself, height-correlated.
    Alpha,
}

impl Target {
    pub fn alpha(self, y: f64) -> f64 {
        match self {
            Target::RoughnessUe4 | Target::Roughness => y * y,
            Target::Gloss => forms::alpha_of_gloss(y),
            Target::Alpha => y,
        }
    }

    pub fn axis_name(self) -> &'static str {
        match self {
            Target::RoughnessUe4 | Target::Roughness => "roughness r",
            Target::Gloss => "gloss g",
            Target::Alpha => "alpha",
        }
    }

    pub fn integral(self) -> &'static str {
        match self {
            Target::RoughnessUe4 => "ggx-env-ue4 (separable Schlick–Smith, k = α/2; α = r²)",
            Target::Roughness => "ggx-env (height-correlated Smith; α = r²)",
            Target::Gloss => "ggx-env (height-correlated Smith; α = sqrt(2/(8192^g + 2)))",
            Target::Alpha => "ggx-env (height-correlated Smith; α as given)",
        }
    }
}

/// [scale, bias] at (α, n·v) with the target's G (α = 0: the mirror limit of `integrals::env`).
pub fn env(target: Target, alpha: f64, mu: f64, tol: f64) -> [f64; 2] {
    let shadowing = match target {
        Target::RoughnessUe4 => Shadowing::Separable { k: 0.5 * alpha },
        _ => Shadowing::HeightCorrelated,
    };
    let r = integrals::env(alpha, mu, 0.0, shadowing, tol);
    [r.scale, r.bias]
}

/// A grid n·v × y (n·v fastest) with [scale, bias] at each point.
#[derive(Debug, Clone)]
pub struct Grid {
    pub target: Target,
    pub mu: Vec<f64>,
    pub y: Vec<f64>,
    pub values: Vec<[f64; 2]>,
}

impl Grid {
    pub fn compute(target: Target, mu: Vec<f64>, y: Vec<f64>, tol: f64) -> Grid {
        let pts: Vec<(f64, f64)> = y.iter().flat_map(|&y| mu.iter().map(move |&m| (m, y))).collect();
        let values = pts.par_iter().map(|&(m, y)| env(target, target.alpha(y), m, tol)).collect();
        Grid { target, mu, y, values }
    }

    /// (n·v, y) of every point, in value order.
    pub fn points(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.y.iter().flat_map(move |&y| self.mu.iter().map(move |&m| (m, y)))
    }

    /// Errors of a form (a function of (n·v, y) → [A, B]) at every point: [A − A*, B − B*].
    pub fn errors(&self, form: impl Fn(f64, f64) -> [f64; 2]) -> Vec<[f64; 2]> {
        self.points().zip(&self.values).map(|((m, y), t)| {
            let a = form(m, y);
            [a[0] - t[0], a[1] - t[1]]
        }).collect()
    }

    /// The largest |error| over both channels of a form; a NaN in either channel is infinite.
    pub fn max_error(&self, form: impl Fn(f64, f64) -> [f64; 2]) -> f64 {
        self.points().zip(&self.values).fold(0.0f64, |m, ((x, y), t)| {
            let a = form(x, y);
            let (ea, eb) = ((a[0] - t[0]).abs(), (a[1] - t[1]).abs());
            // f64::max drops a NaN: test each channel.
            if ea.is_nan() || eb.is_nan() { f64::INFINITY } else { m.max(ea).max(eb) }
        })
    }
}

/// The standard grid of a target (64 n·v texel centres × 65 uniform values of r, g or α),
/// computed once per run.
pub fn standard(target: Target) -> &'static Grid {
    static GRIDS: [OnceLock<Grid>; 4] = [OnceLock::new(), OnceLock::new(), OnceLock::new(), OnceLock::new()];
    let i = target as usize;
    GRIDS[i].get_or_init(|| Grid::compute(target, n_dot_v_axis(), unit_axis(), TOL))
}

/// The Fresnel-average grid: η ∈ [1, 3] (η ≥ 1 branch) or its reciprocals η ∈ [1/3, 1)
/// (η < 1 branch: the same interfaces seen from inside), 513 points each, with F_avg(η).
pub fn fresnel(above: bool) -> &'static (Vec<f64>, Vec<f64>) {
    static G: [OnceLock<(Vec<f64>, Vec<f64>)>; 2] = [OnceLock::new(), OnceLock::new()];
    G[above as usize].get_or_init(|| {
        let n = 513;
        let eta: Vec<f64> = (0..n)
            .map(|i| {
                let t = i as f64 / (n - 1) as f64;
                if above { 1.0 + 2.0 * t } else { 1.0 / 3.0 + (1.0 - 1.0 / 3.0) * t * (n - 1) as f64 / n as f64 }
            })
            .collect();
        let f = eta.par_iter().map(|&e| integrals::f_avg_dielectric(e, 1e-12).value).collect();
        (eta, f)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Fresnel-average grids are the ones the doc states, and their F_avg is each η's own:
    /// η ≥ 1 is 513 points 1 + i/256 (exact in binary), η < 1 is 1/3 + (2/3)·i/513, the
    /// reciprocal range [1/3, 1) without its end. The values are judged by physics, not by
    /// the integrator: F_avg(1) = 0 (no interface), F_avg rises with |ln η| on both sides,
    /// and the two grids' ends η = 3 and 1/3 are one interface seen from both sides, where
    /// reciprocity (radiance scales with η²) gives 1 − F_avg(1/η) = (1 − F_avg(η))/η².
    #[test]
    fn fresnel_grids_are_their_stated_etas_with_reciprocal_ends() {
        let (ea, fa) = fresnel(true);
        let (eb, fb) = fresnel(false);
        assert_eq!((ea.len(), fa.len(), eb.len(), fb.len()), (513, 513, 513, 513));
        for i in 0..513 {
            assert_eq!(ea[i], 1.0 + i as f64 / 256.0, "η ≥ 1, point {i}");
            // A few roundings of values ≤ 1: 4e-16.
            let want = 1.0 / 3.0 + 2.0 / 3.0 * i as f64 / 513.0;
            assert!((eb[i] - want).abs() <= 4e-16, "η < 1, point {i}: {} vs {want}", eb[i]);
        }
        // Each F_avg is integrated to 1e-12 (the grid's tolerance): at η = 1 it is 0 to that.
        assert!(fa[0].abs() <= 1e-12, "F_avg(1) = {}", fa[0]);
        assert!(fa.windows(2).all(|w| w[1] > w[0]), "F_avg rises with η above 1");
        assert!(fb.windows(2).all(|w| w[1] < w[0]), "F_avg falls as η rises to 1 from below");
        // Both values carry 1e-12; (1 − F)/9 then 1.1e-13: 3e-12 bounds the difference.
        let (inside, outside) = (1.0 - fb[0], (1.0 - fa[512]) / 9.0);
        assert!((inside - outside).abs() <= 3e-12, "1 − F_avg(1/3) = {inside}, (1 − F_avg(3))/9 = {outside}");
    }

    /// Each target's labels say what its integral does: the axis names the coordinate whose
    /// map to α it uses (α = r² for roughness, α itself, Black Ops II's gloss map), and the
    /// description names the G its [scale, bias] is integrated with (the separable
    /// Schlick–Smith only for UE4's target; both integrals are the crate's own, compared here
    /// only to tell which one `env` took).
    #[test]
    fn target_labels_name_their_coordinate_and_shadowing() {
        let (alpha, mu, y) = (0.3, 0.6, 0.5);
        let hc = integrals::env(alpha, mu, 0.0, Shadowing::HeightCorrelated, 1e-9);
        let sep = integrals::env(alpha, mu, 0.0, Shadowing::Separable { k: 0.15 }, 1e-9);
        assert!((hc.scale - sep.scale).abs() > 1e-3, "the two G must differ here to tell them apart");
        for target in [Target::RoughnessUe4, Target::Roughness, Target::Gloss, Target::Alpha] {
            let e = env(target, alpha, mu, 1e-9);
            let separable = e == [sep.scale, sep.bias];
            assert!(separable || e == [hc.scale, hc.bias], "{target:?}: neither G");
            let label = target.integral();
            assert_eq!(label.contains("separable Schlick–Smith"), separable, "{target:?}: {label}");
            assert_eq!(label.contains("height-correlated"), !separable, "{target:?}: {label}");
            // The α map each axis name stands for, and the phrase the description gives it.
            let axis = target.axis_name();
            let (want, phrase) = match axis {
                "roughness r" => (y * y, "α = r²"),
                "alpha" => (y, "α as given"),
                // α = sqrt(2/(8192^g + 2)) (Lazarov 2013, Black Ops II).
                "gloss g" => ((2.0 / (8192f64.powf(y) + 2.0)).sqrt(), "α = sqrt(2/(8192^g + 2))"),
                other => panic!("{target:?}: axis {other:?}"),
            };
            // powf and sqrt round: a few ulps of values ≤ 1.
            assert!((target.alpha(y) - want).abs() <= 1e-15, "{target:?}: α({y}) = {} for axis {axis}", target.alpha(y));
            assert!(label.contains(phrase), "{target:?}: {label}");
        }
    }
}
