//! The grid the published sheen forms are measured and refitted on, and the integrals there:
//! a roughness r uniform on [0.1, 1] (19 values) × n·v uniform on [0, 1] (33), point k at
//! (r_{k / 33}, n·v_{k % 33}). r is each form's own roughness argument; a [`Target`] says which
//! α the integral takes from it (α = r² for glTF, three.js, Babylon and Filament, α = r for
//! MaterialX, whose D takes its roughness as α) and under which visibility.

use super::QUANTITIES;
use crate::shading::charlie::lambda_estevez_kulla;
use rayon::prelude::*;
use std::sync::OnceLock;

pub const NR: usize = 19;
pub const NV: usize = 33;
/// The least roughness measured: α = 0.01 at α = r² (the exact Λ's tables reach 3e-3).
pub const R_MIN: f64 = 0.1;

/// Integrator tolerance (absolute, on E ≤ ~4): a thousandth of the smallest error measured.
pub const TOL: f64 = 1e-8;

pub fn roughness(i: usize) -> f64 {
    let t = i as f64 / (NR - 1) as f64;
    R_MIN * (1.0 - t) + t
}

pub fn n_dot_v(j: usize) -> f64 {
    j as f64 / (NV - 1) as f64
}

/// The grid's points [r, n·v] (built once: the refits' objectives read them at every step).
pub fn points() -> &'static [Vec<f64>] {
    static POINTS: OnceLock<Vec<Vec<f64>>> = OnceLock::new();
    POINTS.get_or_init(|| (0..NR * NV).map(|k| vec![roughness(k / NV), n_dot_v(k % NV)]).collect())
}

/// The domain line of an item on this grid.
pub fn domain(convention: Convention) -> String {
    format!("roughness r ∈ [{R_MIN}, 1] ({NR} uniform, {}), n·v ∈ [0, 1] ({NV} uniform)", convention.describe())
}

/// The visibility of the Charlie lobe integrated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Visibility {
    /// V = 1/(4(n·l + n·v − n·l n·v)) (Neubelt–Pettineo/Ashikhmin: Filament, three.js, MaterialX, Babylon).
    Ashikhmin,
    /// Height-correlated Smith with Estevez–Kulla's fitted Λ curve (glTF KHR_materials_sheen).
    EstevezKulla,
    /// Height-correlated Smith with the exact Λ of the distribution.
    Smith,
    /// Not Charlie's D: Ashikhmin's velvet D with Neubelt's V (`super::velvet`).
    Velvet,
}

/// How a form's roughness argument gives the lobe's α.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Convention {
    Squared,
    Linear,
}

impl Convention {
    pub fn alpha(self, r: f64) -> f64 {
        match self {
            Convention::Squared => r * r,
            Convention::Linear => r,
        }
    }

    pub fn describe(self) -> &'static str {
        match self {
            Convention::Squared => "α = r²",
            Convention::Linear => "α = r",
        }
    }
}

/// An integral a form approximates: E under one visibility at α from the form's roughness.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Target {
    pub visibility: Visibility,
    pub convention: Convention,
}

impl Target {
    pub const fn new(visibility: Visibility, convention: Convention) -> Target {
        Target { visibility, convention }
    }

    /// Every target, in [`Target::index`] order.
    pub const ALL: [Target; 8] = [
        Target::new(Visibility::Ashikhmin, Convention::Squared),
        Target::new(Visibility::EstevezKulla, Convention::Squared),
        Target::new(Visibility::Smith, Convention::Squared),
        Target::new(Visibility::Velvet, Convention::Squared),
        Target::new(Visibility::Ashikhmin, Convention::Linear),
        Target::new(Visibility::EstevezKulla, Convention::Linear),
        Target::new(Visibility::Smith, Convention::Linear),
        Target::new(Visibility::Velvet, Convention::Linear),
    ];

    fn index(self) -> usize {
        Target::ALL.iter().position(|t| *t == self).expect("every target is listed")
    }

    fn quantity(self) -> &'static str {
        match self.visibility {
            Visibility::Ashikhmin => "sheen-albedo-ashikhmin",
            Visibility::EstevezKulla => "sheen-albedo-ek",
            Visibility::Smith => "sheen-albedo",
            Visibility::Velvet => "sheen-albedo-velvet",
        }
    }

    /// A short name (`extra` keys): e.g. `ashikhmin_r2`.
    pub fn key(self) -> String {
        let v = match self.visibility {
            Visibility::Ashikhmin => "ashikhmin",
            Visibility::EstevezKulla => "ek",
            Visibility::Smith => "smith",
            Visibility::Velvet => "velvet",
        };
        format!("{v}_{}", if self.convention == Convention::Squared { "r2" } else { "r" })
    }

    pub fn describe(self) -> String {
        let v = match self.visibility {
            Visibility::Ashikhmin => "Charlie D × Ashikhmin's V",
            Visibility::EstevezKulla => "Charlie D × Smith G2 of Estevez–Kulla's Λ curve",
            Visibility::Smith => "Charlie D × Smith G2 of the exact Λ",
            Visibility::Velvet => "Ashikhmin's velvet D × Neubelt's V",
        };
        format!("E of {v} at {}", self.convention.describe())
    }

    /// E at every grid point (computed once per process; n·v = 0 is taken at the quantity's
    /// least n·v, 1e-6 under Estevez–Kulla's curve, whose E is unbounded at 0).
    pub fn albedo(self) -> &'static [f64] {
        static CACHE: [OnceLock<Vec<f64>>; 8] = [const { OnceLock::new() }; 8];
        CACHE[self.index()].get_or_init(|| {
            let q = QUANTITIES.iter().find(|q| q.name == self.quantity()).expect("a sheen quantity");
            points().par_iter().map(|p| (q.eval)(&[self.convention.alpha(p[0]), p[1].max(q.params[1].min)], TOL).value).collect()
        })
    }
}

/// G1 = 1/(1 + Λ) of the exact Λ at every grid point, α = r² (0 at n·v = 0, where Λ = ∞).
pub fn g1_exact() -> &'static [f64] {
    static G: OnceLock<Vec<f64>> = OnceLock::new();
    G.get_or_init(|| points().par_iter().map(|p| if p[1] == 0.0 { 0.0 } else { 1.0 / (1.0 + super::lambda_table(p[0] * p[0]).lambda(p[1])) }).collect())
}

/// G1 of Estevez–Kulla's curve at every grid point, α = r².
pub fn g1_estevez_kulla() -> Vec<f64> {
    points().iter().map(|p| 1.0 / (1.0 + lambda_estevez_kulla(p[0] * p[0], p[1]))).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The grid's ends and order: r from 0.1 to 1 slowest, n·v from 0 to 1 fastest.
    #[test]
    fn the_grid_runs_roughness_slowest() {
        let p = points();
        assert_eq!(p.len(), NR * NV);
        assert_eq!((p[0].clone(), p[NV - 1].clone(), p[NV].clone()), (vec![0.1, 0.0], vec![0.1, 1.0], vec![roughness(1), 0.0]));
        assert!((roughness(1) - 0.15).abs() < 1e-15 && (n_dot_v(1) - 1.0 / 32.0).abs() < 1e-17);
        assert_eq!(p[NR * NV - 1], vec![1.0, 1.0]);
    }
}
