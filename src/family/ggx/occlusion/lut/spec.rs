//! Cone LUT specs (`kind = "ggx-cone-lut"`): the split-sum scale and bias over (n·v, roughness,
//! cos θc), COD: WWII's 3-D environment BRDF for cone-based specular occlusion.
//!
//! ```toml
//! name = "ggx_cone_lut"            # output stem; must equal the file stem
//! kind = "ggx-cone-lut"
//! quantity = "ggx-env"             # the only quantity with a cone
//! description = "..."
//! resolution = [32, 32, 8]         # [n·v columns, roughness rows, cone slices] (COD: WWII)
//! roughness_mapping = "gloss"      # optional: "gloss" (COD, the default), "perceptual", "alpha"
//! cone_mapping = "linear"          # optional: slice k at cos θc = k/(slices − 1) (the only one)
//! layout = "scale-bias"            # optional: as the 2-D table ("scale-bias" or "filament")
//! tolerance = 1e-7                 # optional: absolute quadrature tolerance per texel
//! texture_format = "rg16float"     # optional: "rg16float" or "rgba16float"
//!
//! [emit]
//! function = "ggx_cone_dfg"        # WGSL and Rust function prefix
//! ```
//!
//! Each slice is the 2-D DFG table of the same resolution and mapping (`kind = "ggx-dfg-lut"`,
//! texel (i, j) at n·v = (i + 0.5)/width and row coordinate (j + 0.5)/height) with the cone
//! cosine of the slice: slice 0 (cos θc = 0, the hemisphere) is that table's texels computed by
//! the same code, bit for bit, and the last (cos θc = 1, a closed cone) is exactly 0. The cone
//! axis puts its first and last texel centres on cos θc = 0 and 1: a sampler reads it at
//! w = (cos θc (slices − 1) + 0.5)/slices.

use crate::family::ggx::lut::spec::{DfgLut, check_format, Layout, MAX_RESOLUTION, RoughnessMapping, TOLERANCE_RANGE};
use crate::pipeline::{Grid, GridAxis};
use crate::spec::Placement;
use crate::spec::{CustomSpec, SpecError, SpecFile, check_resolution, check_tolerance, line_of, parse_toml, Preset};
use serde::Deserialize;
use serde_json::json;
use std::path::Path;

/// The `kind` value of cone LUT specs.
pub const KIND: &str = "ggx-cone-lut";
/// Default quadrature tolerance per texel: the 2-D table's default.
pub const DEFAULT_TOLERANCE: f64 = crate::family::ggx::lut::spec::DEFAULT_TOLERANCE;
/// Largest number of cone slices (a 3-D texture's depth; 2 is the fewest: open and closed).
pub const MAX_SLICES: usize = 256;

#[derive(Debug, Clone, Copy, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
enum ConeMapping {
    #[default]
    Linear,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct ConeEmit {
    function: String,
    /// Outputs besides the WGSL module, as for every spec (`[emit] targets`; the common spec
    /// reads them from the text: `spec::CustomSpec::spec_file`).
    #[allow(dead_code)]
    targets: Option<Vec<String>>,
    /// The texture's file formats, as for every spec (`[emit] formats`, read the same way).
    #[allow(dead_code)]
    formats: Option<Vec<String>>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct ConeLutFile {
    name: String,
    #[allow(dead_code)] // checked by the caller: "ggx-cone-lut"
    kind: String,
    quantity: String,
    #[serde(default)]
    description: String,
    tolerance: Option<f64>,
    resolution: Vec<usize>,
    roughness_mapping: Option<RoughnessMapping>,
    #[serde(default)]
    #[allow(dead_code)] // one variant: parsing it is the check
    cone_mapping: ConeMapping,
    #[serde(default)]
    layout: Layout,
    texture_format: Option<crate::spec::TableTextureFormat>,
    emit: ConeEmit,
}

/// A validated cone LUT spec: the 2-D table of its slices (at cos θc = 0) and the slice count.
#[derive(Debug, Clone, PartialEq)]
pub struct ConeLut {
    /// The table every slice is (its `cos_cone` is 0; [`ConeLut::slice`] sets it).
    pub base: DfgLut,
    /// Cone slices (the texture's depth).
    pub depth: usize,
}

impl ConeLut {

    /// cos θc of slice k: k/(slices − 1).
    pub fn cos_cone(&self, k: usize) -> f64 {
        k as f64 / (self.depth - 1) as f64
    }

    /// The 2-D table of cone cosine `c` (slice k is `table(cos_cone(k))`).
    pub fn table(&self, c: f64) -> DfgLut {
        DfgLut { cos_cone: c, ..self.base.clone() }
    }

    /// The table's grid: the 2-D table's n·v columns and rows, and the cone slices at nodes
    /// k/(slices − 1) of [0, 1].
    pub fn grid(&self) -> Grid {
        let mut g = self.base.grid();
        g.axes[2] = GridAxis { range: [0.0, 1.0], count: self.depth, placement: Placement::Nodes, mapping: &crate::spec::table::LINEAR, param: 2 };
        g
    }

    /// The 2-D table of slice k.
    pub fn slice(&self, k: usize) -> DfgLut {
        self.table(self.cos_cone(k))
    }

}

impl Preset for ConeLut {
    const KIND: &'static str = KIND;

    /// Parse and check a cone LUT spec (its `kind` must be "ggx-cone-lut").
    fn parse(path: &Path, text: &str) -> Result<ConeLut, SpecError> {
        let f: ConeLutFile = parse_toml(path, text)?;
        let at = |field: &str, msg: String| SpecError::new(path, line_of(text, field), field, msg);
        if f.quantity != "ggx-env" {
            return Err(at("quantity", format!("'{}': cone LUTs tabulate 'ggx-env' (the quantity with a cone)", f.quantity)));
        }
        if f.resolution.len() != 3 {
            return Err(at("resolution", format!("needs resolution = [n·v columns, roughness rows, cone slices], found {} numbers", f.resolution.len())));
        }
        check_resolution(&f.resolution[..2], MAX_RESOLUTION).map_err(|m| at("resolution", m))?;
        check_resolution(&f.resolution[2..], MAX_SLICES).map_err(|m| at("resolution", format!("cone slices: {m}")))?;
        let tolerance = f.tolerance.unwrap_or(DEFAULT_TOLERANCE);
        check_tolerance(tolerance, TOLERANCE_RANGE, "above, quadrature error would rival f16 rounding; below, the rules cannot converge in f64").map_err(|m| at("tolerance", m))?;
        let base = DfgLut {
            name: f.name,
            quantity: f.quantity,
            description: f.description,
            function: f.emit.function,
            width: f.resolution[0],
            height: f.resolution[1],
            mapping: f.roughness_mapping.unwrap_or(RoughnessMapping::Gloss),
            layout: f.layout,
            cos_cone: 0.0,
            ue4: false,
            format: check_format(f.texture_format, at)?,
            tolerance,
        };
        Ok(ConeLut { base, depth: f.resolution[2] })
    }

    /// The common spec: axes alpha (rows), n_dot_v (columns), cos_cone (slices).
    fn common(&self, path: &Path, text: &str) -> Result<SpecFile, SpecError> {
        let b = &self.base;
        let (w, h, d) = (b.width, b.height, self.depth);
        let axes = vec![
            json!({"name": "alpha", "range": b.alpha_range(), "count": h, "verify": 2 * h}),
            json!({"name": "n_dot_v", "range": [b.n_dot_v(0), b.n_dot_v(w - 1)], "count": w, "verify": 2 * w}),
            json!({"name": "cos_cone", "range": [0.0, 1.0], "count": d, "verify": 2 * (d - 1)}),
        ];
        CustomSpec { kind: KIND, name: &b.name, quantity: &b.quantity, description: &b.description, tolerance: b.tolerance, axes, function: &b.function }
            .spec_file(path, text)
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// An 8 × 4 × 3 cone LUT spec, the least a spec names.
    pub(in crate::family::ggx::occlusion::lut) const SPEC: &str = "name = \"ggx_c\"\nkind = \"ggx-cone-lut\"\nquantity = \"ggx-env\"\n\
        resolution = [8, 4, 3]\n\n[emit]\nfunction = \"ggx_c\"\n";

    #[test]
    fn defaults_slices_and_axes() {
        let l = ConeLut::parse(Path::new("fits/ggx_c.toml"), SPEC).unwrap();
        assert_eq!((l.base.width, l.base.height, l.depth, l.base.tolerance), (8, 4, 3, DEFAULT_TOLERANCE));
        assert_eq!((l.base.mapping, l.base.layout, l.base.format), (RoughnessMapping::Gloss, Layout::ScaleBias, crate::spec::TableTextureFormat::Rg16float));
        assert_eq!([l.cos_cone(0), l.cos_cone(1), l.cos_cone(2)], [0.0, 0.5, 1.0]);
        // Gloss rows: g = (j + 0.5)/4, α = sqrt(2/(1 + 2^(18 g))); g = 1/8 gives sqrt(2/(1 + 2^2.25)).
        assert_eq!(l.base.alpha(0), (2.0 / (1.0 + 2f64.powf(2.25))).sqrt());
        assert_eq!(l.slice(1).cos_cone, 0.5);
        let spec = crate::spec::Spec::parse(Path::new("fits/ggx_c.toml"), SPEC.to_string(), crate::family::catalog()).unwrap();
        let axes: Vec<(&str, usize)> = spec.file.axis.iter().map(|a| (a.name.as_str(), a.count)).collect();
        assert_eq!(axes, [("alpha", 4), ("n_dot_v", 8), ("cos_cone", 3)]);
    }

    #[test]
    fn errors_name_line_and_field() {
        let bad = |edit: (&str, &str), line: usize, field: &str, msg: &str| {
            let text = SPEC.replace(edit.0, edit.1);
            let e = crate::spec::Spec::parse(Path::new("fits/ggx_c.toml"), text, crate::family::catalog()).unwrap_err();
            assert_eq!((e.line, e.field.as_str()), (line, field), "{e}");
            assert!(e.msg.contains(msg), "{e}");
        };
        bad(("[8, 4, 3]", "[8, 4]"), 4, "resolution", "cone slices]");
        bad(("[8, 4, 3]", "[8, 4, 1]"), 4, "resolution", "cone slices");
        bad(("[8, 4, 3]", "[8, 4, 3]\ntolerance = 1e-3"), 5, "tolerance", "[1e-12, 1e-5]");
        bad(("[8, 4, 3]", "[8, 4, 3]\ncone_mapping = \"angle\""), 5, "cone_mapping", "unknown variant");
        bad(("[8, 4, 3]", "[8, 4, 3]\nroughness_mapping = \"sqrt\""), 5, "roughness_mapping", "unknown variant");
        bad(("[8, 4, 3]", "[8, 4, 3]\ncos_cone = 0.5"), 5, "cos_cone", "unknown field");
        bad(("quantity = \"ggx-env\"", "quantity = \"ggx-env-ue4\""), 3, "quantity", "'ggx-env'");
        bad(("function = \"ggx_c\"", "function = \"ggx c\""), 7, "function", "not a valid function name");
    }
}
