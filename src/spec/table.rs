//! The `table` kind's own keys: the channels of a vector quantity it takes, where each axis's
//! points lie (`placement`) and how its argument maps to the quantity's parameter (`mapping`),
//! and the texel formats of its texture.
//!
//! ```toml
//! kind = "table"
//! quantity = "some-vector-quantity"
//! channels = ["scale", "bias"]     # optional: several channels of a vector quantity, in order
//!                                  # (the emitted function returns vec2<f32> / [f32; 2])
//! order = ["n_dot_v", "alpha"]     # optional: the axes in storage order (first fastest: the
//!                                  # texture's x, y, z) and argument order; default [[axis]]'s
//!
//! [[axis]]
//! name = "alpha"                   # the quantity's parameter
//! mapping = "perceptual"           # optional: the argument t is r, alpha = r² (see below)
//! placement = "centres"            # optional: "nodes" (default: the first and the last point at
//!                                  # the range's ends) or "centres" (texel centres (i + ½)/n)
//! range = [0.0, 1.0]               # of the argument t (the mapped coordinate)
//! count = 32
//!
//! [emit]
//! form = "both"
//! texture_format = "rg16float"     # r / rg / rgba × 16float / 32float, by the channel count
//! ```
//!
//! A mapping is a monotone function from the argument t (what the emitted function takes, and
//! what the table is uniform in) to the quantity's parameter; the generic ones are `linear`
//! (t itself), `perceptual` (t², perceptual roughness to α; also `square`: √κ to κ) and
//! `sqrt-one-minus` (1 − t², t = √(1 − cos θ) to cos θ); families add their own through the
//! [`super::Catalog`].

use super::{Spec, SpecError, SpecFile, is_kind};
use serde::Deserialize;
use std::path::Path;

/// A family's table kind, a preset of the table kind: its spec file read by its own schema
/// (errors name the file, the line and the field) and the common spec it enters the pipeline
/// as. Its `KindDef::spec_file` is [`preset_spec_file`]; its build reads it back with
/// [`Preset::from_spec`].
pub trait Preset: Sized {
    /// The spec files' `kind`.
    const KIND: &'static str;
    /// Parse and check a spec file of this kind.
    fn parse(path: &Path, text: &str) -> Result<Self, SpecError>;
    /// The common spec (the quantity's parameters as axes, the function, the tolerance).
    fn common(&self, path: &Path, text: &str) -> Result<SpecFile, SpecError>;
    /// The preset of a loaded spec (parsed again from its text: the spec layer checked it).
    fn from_spec(spec: &Spec) -> Result<Self, SpecError> {
        Self::parse(&spec.path, &spec.text)
    }
}

/// For `Spec::parse` (a `KindDef::spec_file`): the common spec of a spec of preset `P`
/// (checked), or `None` when the text is not one (its `kind` differs, or it is not TOML: the
/// common parser reports that).
pub fn preset_spec_file<P: Preset>(path: &Path, text: &str) -> Result<Option<SpecFile>, SpecError> {
    if !is_kind(text, P::KIND) {
        return Ok(None);
    }
    P::parse(path, text)?.common(path, text).map(Some)
}

/// Where the points of a table axis of `count` points lie on its range [lo, hi].
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "lowercase")]
pub enum Placement {
    /// lo + (hi − lo)·i/(n − 1): the first and the last point at the ends (a table over its
    /// domain; a texture of it is sampled at `(t + ½)/n`).
    #[default]
    Nodes,
    /// lo + (hi − lo)·(i + ½)/n: texel centres, so that a texture is sampled at
    /// (x − lo)/(hi − lo) with no remap; outside the first and the last centre the edge texel.
    Centres,
}

impl Placement {
    /// The spec's spelling.
    pub fn name(self) -> &'static str {
        match self {
            Placement::Nodes => "nodes",
            Placement::Centres => "centres",
        }
    }

    /// The `n` points on `[lo, hi]` (the last node is `hi` exactly).
    pub fn points(self, range: [f64; 2], n: usize) -> Vec<f64> {
        (0..n).map(|i| self.point(range, n, i)).collect()
    }

    /// Point `i` of the `n` on `[lo, hi]`.
    pub fn point(self, [lo, hi]: [f64; 2], n: usize, i: usize) -> f64 {
        match self {
            Placement::Nodes if n == 1 => lo,
            Placement::Nodes if i + 1 == n => hi,
            Placement::Nodes => lo + (hi - lo) * i as f64 / (n - 1) as f64,
            Placement::Centres => lo + (hi - lo) * (i as f64 + 0.5) / n as f64,
        }
    }
}

/// A mapping from a table axis's argument t to its quantity's parameter.
#[derive(Debug)]
pub struct AxisMapping {
    /// The spec's spelling (`mapping = "NAME"`).
    pub name: &'static str,
    /// What the argument is, for reports (`"perceptual roughness r, alpha = r^2"`).
    pub doc: &'static str,
    /// The parameter at argument t.
    pub to_parameter: fn(f64) -> f64,
    /// Where t may lie (the mapping is monotone there).
    pub argument: [f64; 2],
}

fn identity(t: f64) -> f64 {
    t
}

fn square(t: f64) -> f64 {
    t * t
}

fn one_minus_square(t: f64) -> f64 {
    1.0 - t * t
}

/// The argument is the parameter.
pub static LINEAR: AxisMapping = AxisMapping { name: "linear", doc: "the parameter itself", to_parameter: identity, argument: [f64::NEG_INFINITY, f64::INFINITY] };
/// Perceptual roughness r to GGX α = r² (`shading::roughness::alpha_from_roughness`).
pub static PERCEPTUAL: AxisMapping = AxisMapping { name: "perceptual", doc: "perceptual roughness r, parameter r^2", to_parameter: square, argument: [0.0, f64::INFINITY] };
/// The same square under its plain name (e.g. √κ to a curvature κ).
pub static SQUARE: AxisMapping = AxisMapping { name: "square", doc: "t, parameter t^2", to_parameter: square, argument: [0.0, f64::INFINITY] };
/// t = √(1 − cos θ) to cos θ = 1 − t² (points uniform in t crowd towards cos θ = 1).
pub static SQRT_ONE_MINUS: AxisMapping =
    AxisMapping { name: "sqrt-one-minus", doc: "t = sqrt(1 - c), parameter c = 1 - t^2", to_parameter: one_minus_square, argument: [0.0, 1.0] };

/// The mappings every spec may name.
pub static GENERIC_MAPPINGS: &[&AxisMapping] = &[&LINEAR, &PERCEPTUAL, &SQUARE, &SQRT_ONE_MINUS];

/// Texel format of a table texture (WebGPU names): 1, 2 or 4 channels (3 channels are stored
/// as RGBA with alpha 1) of 16- or 32-bit floats.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum TableTextureFormat {
    /// IEEE half floats: filterable in core WebGPU; 11 significant bits.
    R16float,
    /// f32: the table values exactly; unfilterable in core WebGPU (`float32-filterable`).
    R32float,
    Rg16float,
    Rg32float,
    Rgba16float,
    Rgba32float,
}

impl TableTextureFormat {
    pub fn name(self) -> &'static str {
        match self {
            TableTextureFormat::R16float => "r16float",
            TableTextureFormat::R32float => "r32float",
            TableTextureFormat::Rg16float => "rg16float",
            TableTextureFormat::Rg32float => "rg32float",
            TableTextureFormat::Rgba16float => "rgba16float",
            TableTextureFormat::Rgba32float => "rgba32float",
        }
    }

    /// The 32-bit float format of a table of `channels` (the default: the f32 values exactly).
    pub fn default_for(channels: usize) -> TableTextureFormat {
        match channels {
            1 => TableTextureFormat::R32float,
            2 => TableTextureFormat::Rg32float,
            _ => TableTextureFormat::Rgba32float,
        }
    }

    /// Channels per texel (1, 2 or 4).
    pub fn texel_channels(self) -> usize {
        match self {
            TableTextureFormat::R16float | TableTextureFormat::R32float => 1,
            TableTextureFormat::Rg16float | TableTextureFormat::Rg32float => 2,
            TableTextureFormat::Rgba16float | TableTextureFormat::Rgba32float => 4,
        }
    }

    /// Whether a table of `channels` values a point fits this format exactly (3 in RGBA).
    pub fn holds(self, channels: usize) -> bool {
        self.texel_channels() == if channels == 3 { 4 } else { channels }
    }

    /// 32-bit floats (filterable only with WebGPU's `float32-filterable`).
    pub fn is_32bit(self) -> bool {
        matches!(self, TableTextureFormat::R32float | TableTextureFormat::Rg32float | TableTextureFormat::Rgba32float)
    }
}

/// A table spec's layout as checked: the channels it takes and each axis's placement and
/// mapping.
#[derive(Debug, Clone)]
pub struct TableLayout {
    /// Indices of the channels of a vector quantity the table holds, in order (`channels`);
    /// empty for one value a point (a scalar quantity, or the one `channel`).
    pub channels: Vec<usize>,
    /// Per axis (in the `[[axis]]` order): where its points lie and how its argument maps to
    /// the parameter.
    pub axes: Vec<(Placement, &'static AxisMapping)>,
    /// The table's axes in storage order (first fastest; the emitted function's arguments and
    /// the texture's x, y, z), as indices of `[[axis]]`: `order = [...]`, else 0, 1, 2.
    pub order: Vec<usize>,
}

impl TableLayout {
    /// Values a point: the channels taken, or 1.
    pub fn width(&self) -> usize {
        self.channels.len().max(1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Nodes put the first and the last point on the ends (the last exactly `hi`), centres the
    /// n points at (i + ½)/n of the range: on [0, 1] with n = 4, 0.125, 0.375, 0.625, 0.875
    /// (exact in binary).
    #[test]
    fn placements_put_points_at_nodes_or_texel_centres() {
        assert_eq!(Placement::Nodes.points([0.0, 1.0], 5), [0.0, 0.25, 0.5, 0.75, 1.0]);
        assert_eq!(Placement::Nodes.points([0.1, 0.7], 3)[2], 0.7);
        assert_eq!(Placement::Centres.points([0.0, 1.0], 4), [0.125, 0.375, 0.625, 0.875]);
        assert_eq!(Placement::Centres.points([2.0, 4.0], 2), [2.5, 3.5]);
    }

    /// The generic mappings against their formulas at points exact in binary; formats hold
    /// their channel counts (3 in RGBA).
    #[test]
    fn mappings_and_formats() {
        assert_eq!((PERCEPTUAL.to_parameter)(0.5), 0.25);
        assert_eq!((SQUARE.to_parameter)(3.0), 9.0);
        assert_eq!((SQRT_ONE_MINUS.to_parameter)(0.5), 0.75);
        assert_eq!((LINEAR.to_parameter)(-2.5), -2.5);
        assert!(TableTextureFormat::Rgba16float.holds(3) && TableTextureFormat::Rgba16float.holds(4));
        assert!(TableTextureFormat::Rg32float.holds(2) && !TableTextureFormat::Rg32float.holds(1));
        for c in 1..=4 {
            let f = TableTextureFormat::default_for(c);
            assert!(f.holds(c) && f.is_32bit(), "{c}: {f:?}");
        }
    }
}
