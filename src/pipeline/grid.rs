//! The grid of a table, shared by the `table` kind and every family's table kind (its presets):
//! axes in storage order (first fastest: a texture's x, y, z), each `count` points of its
//! argument on a range at nodes or texel centres, mapped to one parameter of the quantity
//! tabulated; sampled through a [`Sampler`] (the quantity's integral, so through the lobe layer
//! for a lobe's quantities) in parallel and collected in grid order, so that a table is
//! byte-identical at any thread count.

use crate::integrate::Estimate;
use crate::spec::{AxisMapping, Placement, Sampler};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// The quadrature work of a tabulated grid, as its JSON states it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Quadrature {
    /// The absolute tolerance asked of each texel.
    pub tolerance: f64,
    /// The largest error estimate over texels and channels.
    pub max_error_estimate: f64,
    /// Integrand evaluations a texel, rounded.
    pub evals_per_texel: f64,
}

/// One axis of a table's grid.
#[derive(Debug, Clone)]
pub struct GridAxis {
    /// The argument's range (what the emitted lookup takes, and what the table is uniform in).
    pub range: [f64; 2],
    pub count: usize,
    pub placement: Placement,
    /// The argument to the parameter.
    pub mapping: &'static AxisMapping,
    /// The index of the quantity's parameter the axis gives.
    pub param: usize,
}

impl GridAxis {
    /// The axis's `count` arguments at its placement.
    pub fn arguments(&self) -> Vec<f64> {
        self.placement.points(self.range, self.count)
    }

    /// Argument `i` of the axis's `count`.
    pub fn argument(&self, i: usize) -> f64 {
        self.placement.point(self.range, self.count, i)
    }

    /// The centres of `cells` equal cells of the range: points off the table's own points
    /// (for a denser verification) that never reach the ends.
    pub fn cell_centres(&self, cells: usize) -> Vec<f64> {
        Placement::Centres.points(self.range, cells)
    }

    /// The parameter at argument `t`.
    pub fn parameter(&self, t: f64) -> f64 {
        (self.mapping.to_parameter)(t)
    }
}

/// A table's grid: its axes in storage order.
#[derive(Debug, Clone)]
pub struct Grid {
    pub axes: Vec<GridAxis>,
}

impl Grid {
    /// Points a table holds (the product of the counts).
    pub fn len(&self) -> usize {
        self.axes.iter().map(|a| a.count).product()
    }

    /// Whether the grid has no points.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The table's points in its arguments, first axis fastest.
    pub fn points(&self) -> Vec<Vec<f64>> {
        super::product(self.axes.iter().map(GridAxis::arguments).collect())
    }

    /// The product of per-axis argument lists (`per_axis[k]` on axis k), first axis fastest.
    pub fn product(per_axis: Vec<Vec<f64>>) -> Vec<Vec<f64>> {
        super::product(per_axis)
    }

    /// The quantity's parameters at arguments `t` (one per axis, in storage order), in the
    /// quantity's order; a parameter no axis gives is left to the sampler's default.
    pub fn parameters(&self, t: &[f64]) -> Vec<f64> {
        let n = self.axes.iter().map(|a| a.param + 1).max().unwrap_or(0);
        let mut p = vec![f64::NAN; n];
        for (a, &x) in self.axes.iter().zip(t) {
            p[a.param] = a.parameter(x);
        }
        p
    }

    /// The channels `picks` of the sampler's quantity (all of a scalar's one value with no
    /// picks) at every point of `points` (arguments), in parallel, in order.
    pub fn sample(&self, sampler: &Sampler, picks: &[usize], points: &[Vec<f64>]) -> Vec<Vec<Estimate>> {
        points.par_iter().map(|t| sampler.eval_channels(&self.parameters(t), picks)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::table::{LINEAR, PERCEPTUAL};

    fn axis(range: [f64; 2], count: usize, placement: Placement, mapping: &'static AxisMapping, param: usize) -> GridAxis {
        GridAxis { range, count, placement, mapping, param }
    }

    /// Points run first axis fastest, each at its placement (exact binary fractions); the
    /// parameters follow the axes' `param` and mappings (r = 0.75 at a centre gives α = r²
    /// = 0.5625 exactly).
    #[test]
    fn points_and_parameters_follow_the_axes() {
        let g = Grid {
            axes: vec![
                axis([0.0, 1.0], 2, Placement::Centres, &LINEAR, 1),
                axis([0.0, 1.0], 2, Placement::Centres, &PERCEPTUAL, 0),
                axis([0.5, 0.5], 1, Placement::Nodes, &LINEAR, 2),
            ],
        };
        assert_eq!(g.len(), 4);
        assert_eq!(g.points(), [[0.25, 0.25, 0.5], [0.75, 0.25, 0.5], [0.25, 0.75, 0.5], [0.75, 0.75, 0.5]]);
        assert_eq!(g.parameters(&[0.25, 0.75, 0.5]), [0.5625, 0.25, 0.5]);
        assert_eq!(g.axes[0].cell_centres(4), [0.125, 0.375, 0.625, 0.875]);
    }
}
