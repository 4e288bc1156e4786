//! The one multilinear interpolator of every table (1-D, 2-D, 3-D; any number of channels), in
//! f64 for the build's measurements and in f32 with the emitted code's operation order.
//!
//! A lookup is an address per axis, (i0, i1, f): the two texels it blends and the weight of the
//! second. The blend is the same everywhere: along the first axis
//! a = v[i0]·(1 − f) + v[i1]·f, then the results along the second axis the same way, then the
//! third, so one written order serves the f64 reference and the f32 replay of the emitted code.
//! Two address modes:
//! - [`centred`]: texture coordinates p ∈ [0, 1] with texels at their centres (p = (i + ½)/n),
//!   clamped to the edge texels (GPU sampling with clamp-to-edge);
//! - [`nodes`]: a continuous node coordinate x ∈ [0, n − 1] with the first and the last node at
//!   the ends (a table over its domain; the last cell takes x = n − 1 with f = 1).

use crate::fit::expr::Float;

/// An axis's address: the two texels blended and the weight of the second.
pub type Address<T> = (usize, usize, T);

/// The address of texture coordinate `p` on an axis of `n` texels at their centres, clamped to
/// the edge texels (outside [½, n − ½] both indices are the edge's).
pub fn centred(p: f64, n: usize) -> Address<f64> {
    let x = p * n as f64 - 0.5;
    let x0 = x.floor();
    let i0 = (x0.max(0.0) as usize).min(n - 1);
    let i1 = ((x0 + 1.0).max(0.0) as usize).min(n - 1);
    (i0, i1, x - x0)
}

/// The address of node coordinate `x` ∈ [0, n − 1] on an axis of `n` ≥ 2 nodes.
pub fn nodes(x: f64, n: usize) -> Address<f64> {
    let i = (x.floor() as usize).min(n - 2);
    (i, i + 1, x - i as f64)
}

/// Where the points of an emitted table's axis lie on its domain [lo, hi]: nodes (the first and
/// the last point at the ends) or texel centres ((i + ½)/n of the domain).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Placement {
    #[default]
    Nodes,
    Centres,
}

/// The f32 factor taking an argument's offset from `lo` to table steps (the emitted literal):
/// (n − 1)/(hi − lo) for nodes, n/(hi − lo) for centres.
pub fn step_scale(lo: f32, hi: f32, n: usize, placement: Placement) -> f32 {
    match placement {
        Placement::Nodes => (n as f32 - 1.0) / (hi - lo),
        Placement::Centres => n as f32 / (hi - lo),
    }
}

/// The emitted lookup's address of `x` ∈ [lo, hi] (already clamped) on an axis of `n` ≥ 2
/// points, in f32 with the emitted operations: t = (x − lo)·scale (minus ½ at centres, so that
/// t is in texel steps from the first centre), i = min(⌊max(t, 0)⌋, n − 2), f = clamp(t − i, 0,
/// 1). Outside the first and last centre f is 0 or 1: the edge texel, as clamp-to-edge sampling.
pub fn emitted_address(x: f32, lo: f32, hi: f32, n: usize, placement: Placement) -> Address<f32> {
    let scale = step_scale(lo, hi, n, placement);
    let t = match placement {
        Placement::Nodes => (x - lo) * scale,
        Placement::Centres => (x - lo) * scale - 0.5,
    };
    let i = (t.max(0.0) as u32).min(n as u32 - 2) as usize;
    (i, i + 1, (t - i as f32).clamp(0.0, 1.0))
}

/// The blend of `texels` (first axis fastest, `dims` texels per axis) at one address per axis,
/// channel by channel.
pub fn multilinear<T: Float, const C: usize>(texels: &[[T; C]], dims: &[usize], at: &[Address<T>]) -> [T; C] {
    debug_assert_eq!(dims.len(), at.len());
    std::array::from_fn(|c| blend(texels, dims, at, c, at.len(), 0))
}

/// The blend over the first `axes` axes of channel `c` at offset `base` (the index of the
/// texel where those axes are 0).
fn blend<T: Float, const C: usize>(texels: &[[T; C]], dims: &[usize], at: &[Address<T>], c: usize, axes: usize, base: usize) -> T {
    if axes == 0 {
        return texels[base][c];
    }
    let d = axes - 1;
    let stride: usize = dims[..d].iter().product();
    let (i0, i1, f) = at[d];
    let a = blend(texels, dims, at, c, d, base + i0 * stride);
    let b = blend(texels, dims, at, c, d, base + i1 * stride);
    a * (T::ONE - f) + b * f
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Multilinear interpolation reproduces a function linear in each coordinate (its nodes'
    /// values blended: exact up to rounding, 1e-14 of values ≤ 10) in one, two and three
    /// dimensions, with two channels; `centred` clamps to the edge texels outside the texel
    /// centres and `nodes` takes the last cell at the upper end with weight 1.
    #[test]
    fn it_reproduces_multilinear_functions_and_clamps_at_the_edges() {
        let dims = [4usize, 3, 5];
        let f = |x: f64, y: f64, z: f64| [1.0 + 2.0 * x - y + 0.5 * z + 0.25 * x * y * z, 3.0 - x * z];
        let texels: Vec<[f64; 2]> = (0..60).map(|k| f((k % 4) as f64, ((k / 4) % 3) as f64, (k / 12) as f64)).collect();
        for (x, y, z) in [(0.0, 0.0, 0.0), (0.3, 1.7, 2.2), (3.0, 2.0, 4.0), (2.5, 0.5, 3.999)] {
            let got = multilinear(&texels, &dims, &[nodes(x, 4), nodes(y, 3), nodes(z, 5)]);
            let want = f(x, y, z);
            assert!((got[0] - want[0]).abs() < 1e-14 && (got[1] - want[1]).abs() < 1e-14, "({x}, {y}, {z}): {got:?} vs {want:?}");
        }
        assert_eq!(nodes(3.0, 4), (2, 3, 1.0));
        // 2-D slice (the first 12 texels) at texel centres: p = (i + ½)/n hits texel i exactly.
        let got = multilinear(&texels[..12], &dims[..2], &[centred(2.5 / 4.0, 4), centred(0.5 / 3.0, 3)]);
        assert_eq!(got, texels[2]);
        // Below the first centre and above the last: the edge texel.
        assert_eq!(centred(0.01, 4), (0, 0, 0.01 * 4.0 - 0.5 - (-1.0)));
        let edge = multilinear(&texels[..12], &dims[..2], &[centred(0.01, 4), centred(0.99, 3)]);
        assert_eq!(edge, texels[8]);
        // 1-D in f32.
        let line: Vec<[f32; 1]> = [1.0f32, 3.0, 7.0].iter().map(|&v| [v]).collect();
        assert_eq!(multilinear(&line, &[3], &[(1, 2, 0.25f32)]), [4.0]);
    }
}
