//! DFG LUT specs (`kind = "ggx-dfg-lut"`): the split-sum scale and bias tabulated as a 2-D
//! texture.
//!
//! ```toml
//! name = "ggx_dfg_lut"             # output stem; must equal the file stem
//! kind = "ggx-dfg-lut"
//! quantity = "ggx-env"             # or "ggx-env-ue4" (UE4's separable G, no cone)
//! description = "..."
//! resolution = [128, 128]          # [n·v columns, roughness rows]
//! roughness_mapping = "perceptual" # optional: rows at perceptual roughness r (α = r²),
//!                                  # "alpha" (rows at α) or "gloss" (rows at COD: WWII gloss g,
//!                                  # α = sqrt(2/(1 + 2^(18 g))))
//! n_dot_v_mapping = "linear"       # optional: columns at n·v (the only mapping)
//! layout = "scale-bias"            # optional: R = scale, G = bias (UE), or "filament":
//!                                  # R = bias, G = scale + bias
//! cos_cone = 0.0                   # optional, ggx-env only: the visibility cone's cosine
//! tolerance = 1e-7                 # optional: absolute quadrature tolerance per texel
//! texture_format = "rg16float"     # optional: "rg16float" or "rgba16float" (B = 0, A = 1)
//!
//! [emit]
//! function = "ggx_dfg"             # WGSL and Rust function prefix
//! ```
//!
//! Texel (i, j) holds the integrals at n·v = (i + 0.5)/width and at row coordinate
//! t = (j + 0.5)/height, α = t² (perceptual), α = t (alpha) or α = sqrt(2/(1 + 2^(18 t)))
//! (gloss): texel centres, as engines sample
//! the table at uv = (n·v, roughness) with no half-texel remap (UE's PreIntegratedGF,
//! Filament's n·v axis, MaterialX, bevy). Row 0 is the first row of the texture (v = 0).
//!
//! The spec is checked here (errors name the file, the line and the field) and enters the
//! common [`SpecFile`] with its axes spelled out: alpha (the rows' α, count = rows), n_dot_v
//! (count = columns) and, for ggx-env, cos_cone as an axis of one point.

use crate::family::ggx::integrals::Shadowing;
use crate::pipeline::{Grid, GridAxis};
use crate::shading::roughness::alpha_from_gloss;
use crate::spec::table::{self, AxisMapping, Placement, TableTextureFormat};
use crate::quantity::QuantityDef;
use crate::spec::{CustomSpec, Sampler, SpecError, SpecFile, check_resolution, check_tolerance, line_of, parse_toml, Preset};
use serde::Deserialize;
use serde_json::json;
use std::path::Path;

/// The `kind` value of DFG LUT specs.
pub const KIND: &str = "ggx-dfg-lut";
/// Default quadrature tolerance per texel (each of scale and bias): far below f16 storage
/// (2⁻¹² relative) and what the acceptance asks of the 128² table.
pub const DEFAULT_TOLERANCE: f64 = 1e-7;
/// Tolerances accepted: above 1e-5 the texels would carry quadrature error comparable to f16
/// rounding of small biases; below 1e-12 the nested rules stop converging in f64.
pub const TOLERANCE_RANGE: [f64; 2] = [1e-12, 1e-5];
/// Largest texture side.
pub const MAX_RESOLUTION: usize = 1024;
/// Largest cone cosine: the cone closes at 1 (everything 0).
pub const MAX_COS_CONE: f64 = 0.99;

/// How the rows map to α.
#[derive(Debug, Clone, Copy, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum RoughnessMapping {
    /// Rows at perceptual roughness r, α = r² (UE, Filament, bevy, HDRP).
    #[default]
    Perceptual,
    /// Rows at α (MaterialX).
    Alpha,
    /// Rows at COD: WWII gloss g, α = sqrt(2/(1 + 2^(18 g))) (the gloss family's mapping; gloss
    /// 0 is α = 1, gloss 1 is α ≈ 0.00276).
    Gloss,
}

impl RoughnessMapping {
    pub fn name(self) -> &'static str {
        match self {
            RoughnessMapping::Perceptual => "perceptual",
            RoughnessMapping::Alpha => "alpha",
            RoughnessMapping::Gloss => "gloss",
        }
    }

    /// The emitted functions' row argument.
    pub fn argument(self) -> &'static str {
        match self {
            RoughnessMapping::Perceptual => "roughness",
            RoughnessMapping::Alpha => "alpha",
            RoughnessMapping::Gloss => "gloss",
        }
    }

    /// The rows' axis mapping (the table kind's: α = r², α itself, or [`GLOSS_ROWS`]).
    pub fn axis_mapping(self) -> &'static AxisMapping {
        match self {
            RoughnessMapping::Perceptual => &table::PERCEPTUAL,
            RoughnessMapping::Alpha => &table::LINEAR,
            RoughnessMapping::Gloss => &GLOSS_ROWS,
        }
    }

    /// α at row coordinate t ∈ [0, 1].
    pub fn alpha(self, t: f64) -> f64 {
        (self.axis_mapping().to_parameter)(t)
    }
}

/// Rows at COD: WWII gloss g: α = sqrt(2/(1 + 2^(18 g))) (`shading::roughness`).
pub static GLOSS_ROWS: AxisMapping =
    AxisMapping { name: "gloss", doc: "gloss g, alpha = sqrt(2/(1 + 2^(18 g)))", to_parameter: alpha_from_gloss, argument: [0.0, 1.0] };

#[derive(Debug, Clone, Copy, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
enum NDotVMapping {
    #[default]
    Linear,
}

/// What the two stored channels hold.
#[derive(Debug, Clone, Copy, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum Layout {
    /// R = scale, G = bias: specular = F0·R + G (UE's PreIntegratedGF, bevy, three.js).
    #[default]
    ScaleBias,
    /// R = bias, G = scale + bias = E: specular = mix(R, G, F0) (Filament's multiscatter DFG).
    Filament,
}

impl Layout {
    pub fn name(self) -> &'static str {
        match self {
            Layout::ScaleBias => "scale-bias",
            Layout::Filament => "filament",
        }
    }

    /// WGSL expression of (scale, bias) from the stored texel `t` (a `vec2<f32>`).
    pub fn decode_wgsl(self) -> &'static str {
        match self {
            Layout::ScaleBias => "t",
            Layout::Filament => "vec2<f32>(t.y - t.x, t.x)",
        }
    }

    /// Rust expression of (scale, bias) from the stored texel `t` (an `[f32; 2]`).
    pub fn decode_rust(self) -> &'static str {
        match self {
            Layout::ScaleBias => "t",
            Layout::Filament => "[t[1] - t[0], t[0]]",
        }
    }

    /// Names of the stored channels (R, G).
    pub fn channels(self) -> [&'static str; 2] {
        match self {
            Layout::ScaleBias => ["scale", "bias"],
            Layout::Filament => ["bias", "scale + bias"],
        }
    }

    /// The stored channels of (scale, bias).
    pub fn encode(self, [scale, bias]: [f64; 2]) -> [f64; 2] {
        match self {
            Layout::ScaleBias => [scale, bias],
            Layout::Filament => [bias, scale + bias],
        }
    }
}

/// The texel formats a DFG LUT may take (the table kind's, two f16 channels: RG16F, or RGBA16F
/// with B = 0, A = 1 where RG16F is not wanted).
pub const FORMATS: [TableTextureFormat; 2] = [TableTextureFormat::Rg16float, TableTextureFormat::Rgba16float];

/// `texture_format` checked against [`FORMATS`] (default RG16F).
pub fn check_format(f: Option<TableTextureFormat>, at: impl Fn(&str, String) -> SpecError) -> Result<TableTextureFormat, SpecError> {
    let f = f.unwrap_or(TableTextureFormat::Rg16float);
    if !FORMATS.contains(&f) {
        return Err(at("texture_format", format!("'{}': a DFG LUT stores two f16 channels: \"rg16float\" or \"rgba16float\"", f.name())));
    }
    Ok(f)
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct DfgEmit {
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
struct DfgLutFile {
    name: String,
    #[allow(dead_code)] // checked by the caller: "ggx-dfg-lut"
    kind: String,
    quantity: String,
    #[serde(default)]
    description: String,
    tolerance: Option<f64>,
    resolution: Vec<usize>,
    #[serde(default)]
    roughness_mapping: RoughnessMapping,
    #[serde(default)]
    #[allow(dead_code)] // one variant: parsing it is the check
    n_dot_v_mapping: NDotVMapping,
    #[serde(default)]
    layout: Layout,
    cos_cone: Option<f64>,
    texture_format: Option<TableTextureFormat>,
    emit: DfgEmit,
}

/// A validated DFG LUT spec.
#[derive(Debug, Clone, PartialEq)]
pub struct DfgLut {
    pub name: String,
    pub quantity: String,
    pub description: String,
    pub function: String,
    /// Columns (n·v) and rows (roughness).
    pub width: usize,
    pub height: usize,
    pub mapping: RoughnessMapping,
    pub layout: Layout,
    pub cos_cone: f64,
    /// UE4's separable Schlick–Smith G (quantity ggx-env-ue4) instead of the height-correlated G2.
    pub ue4: bool,
    pub format: TableTextureFormat,
    /// Absolute quadrature tolerance per texel (each of scale and bias).
    pub tolerance: f64,
}

impl DfgLut {

    /// n·v of column i (texel centre).
    pub fn n_dot_v(&self, i: usize) -> f64 {
        (i as f64 + 0.5) / self.width as f64
    }

    /// Row coordinate t of row j (texel centre): the roughness, or α.
    pub fn row_coordinate(&self, j: usize) -> f64 {
        (j as f64 + 0.5) / self.height as f64
    }

    /// α of row j.
    pub fn alpha(&self, j: usize) -> f64 {
        self.mapping.alpha(self.row_coordinate(j))
    }

    /// [lowest, highest] α of the rows' centres (gloss rows run from rough to smooth).
    pub fn alpha_range(&self) -> [f64; 2] {
        let (a, b) = (self.alpha(0), self.alpha(self.height - 1));
        [a.min(b), a.max(b)]
    }

    /// The table's axes as the table kind's grid: n·v columns and roughness rows at the texel
    /// centres of [0, 1] (the rows mapped to α), and for ggx-env the cone cosine as one point.
    pub fn grid(&self) -> Grid {
        let centres = |count, mapping, param| GridAxis { range: [0.0, 1.0], count, placement: Placement::Centres, mapping, param };
        let mut axes = vec![centres(self.width, &table::LINEAR, 1), centres(self.height, self.mapping.axis_mapping(), 0)];
        if !self.ue4 {
            axes.push(GridAxis { range: [self.cos_cone; 2], count: 1, placement: Placement::Nodes, mapping: &table::LINEAR, param: 2 });
        }
        Grid { axes }
    }

    /// The quantity tabulated ([scale, bias]), integrated to `tolerance`.
    pub fn sampler(&self, tolerance: f64) -> Sampler {
        let quantity: &'static QuantityDef = crate::family::ggx::QUANTITIES.iter().find(|q| q.name == self.quantity).expect("a checked DFG quantity");
        Sampler::new(quantity, None, tolerance)
    }

    /// The shadowing at α (UE4's separable G takes k = α/2).
    pub fn shadowing_at(&self, alpha: f64) -> Shadowing {
        if self.ue4 { Shadowing::Separable { k: 0.5 * alpha } } else { Shadowing::HeightCorrelated }
    }

}

impl Preset for DfgLut {
    const KIND: &'static str = KIND;

    /// Parse and check a DFG LUT spec (its `kind` must be "ggx-dfg-lut").
    fn parse(path: &Path, text: &str) -> Result<DfgLut, SpecError> {
        let f: DfgLutFile = parse_toml(path, text)?;
        let at = |field: &str, msg: String| SpecError::new(path, line_of(text, field), field, msg);
        let ue4 = match f.quantity.as_str() {
            "ggx-env" => false,
            "ggx-env-ue4" => true,
            other => return Err(at("quantity", format!("'{other}': DFG LUTs tabulate 'ggx-env' or 'ggx-env-ue4'"))),
        };
        if f.resolution.len() != 2 {
            return Err(at("resolution", format!("needs resolution = [n·v columns, roughness rows], found {} numbers", f.resolution.len())));
        }
        check_resolution(&f.resolution, MAX_RESOLUTION).map_err(|m| at("resolution", m))?;
        let cos_cone = f.cos_cone.unwrap_or(0.0);
        if ue4 && f.cos_cone.is_some() {
            return Err(at("cos_cone", "ggx-env-ue4 integrates the hemisphere; 'cos_cone' applies to ggx-env only".into()));
        }
        if !(0.0..=MAX_COS_CONE).contains(&cos_cone) {
            return Err(at("cos_cone", format!("{cos_cone} must be in [0, {MAX_COS_CONE}] (0: the hemisphere)")));
        }
        let tolerance = f.tolerance.unwrap_or(DEFAULT_TOLERANCE);
        check_tolerance(tolerance, TOLERANCE_RANGE, "above, quadrature error would rival f16 rounding; below, the rules cannot converge in f64").map_err(|m| at("tolerance", m))?;
        Ok(DfgLut {
            name: f.name,
            quantity: f.quantity,
            description: f.description,
            function: f.emit.function,
            width: f.resolution[0],
            height: f.resolution[1],
            mapping: f.roughness_mapping,
            layout: f.layout,
            cos_cone,
            ue4,
            format: check_format(f.texture_format, at)?,
            tolerance,
        })
    }

    /// The common spec: axes alpha (rows), n_dot_v (columns), and for ggx-env cos_cone fixed.
    fn common(&self, path: &Path, text: &str) -> Result<SpecFile, SpecError> {
        let (w, h) = (self.width, self.height);
        let mut axes = vec![
            json!({"name": "alpha", "range": self.alpha_range(), "count": h, "verify": 4 * h}),
            json!({"name": "n_dot_v", "range": [self.n_dot_v(0), self.n_dot_v(w - 1)], "count": w, "verify": 4 * w}),
        ];
        if self.quantity == "ggx-env" {
            axes.push(json!({"name": "cos_cone", "range": [self.cos_cone, self.cos_cone], "count": 1, "verify": 1}));
        }
        CustomSpec {
            kind: KIND,
            name: &self.name,
            quantity: &self.quantity,
            description: &self.description,
            tolerance: self.tolerance,
            axes,
            function: &self.function,
        }
        .spec_file(path, text)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    pub const SPEC: &str = "name = \"ggx_x\"\nkind = \"ggx-dfg-lut\"\nquantity = \"ggx-env\"\n\
        resolution = [8, 4]\n\n[emit]\nfunction = \"ggx_x\"\n";

    fn parse(text: &str) -> Result<DfgLut, SpecError> {
        DfgLut::parse(Path::new("fits/ggx_x.toml"), text)
    }

    #[test]
    fn defaults_and_texel_centres() {
        let l = parse(SPEC).unwrap();
        assert_eq!((l.width, l.height, l.tolerance, l.cos_cone), (8, 4, DEFAULT_TOLERANCE, 0.0));
        assert_eq!((l.mapping, l.layout, l.format), (RoughnessMapping::Perceptual, Layout::ScaleBias, TableTextureFormat::Rg16float));
        // Centres: n·v = (i + 0.5)/8, r = (j + 0.5)/4, α = r².
        assert_eq!((l.n_dot_v(0), l.n_dot_v(7)), (0.0625, 0.9375));
        assert_eq!((l.alpha(0), l.alpha(3)), (0.015625, 0.765625));
        let a = parse(&SPEC.replace("[8, 4]", "[8, 4]\nroughness_mapping = \"alpha\"")).unwrap();
        assert_eq!(a.alpha(1), 0.375);
        let spec = crate::spec::Spec::parse(Path::new("fits/ggx_x.toml"), SPEC.to_string(), crate::family::catalog()).unwrap();
        assert_eq!(spec.file.kind, crate::spec::Kind::Custom(KIND));
        let axes: Vec<(&str, usize)> = spec.file.axis.iter().map(|a| (a.name.as_str(), a.count)).collect();
        assert_eq!(axes, [("alpha", 4), ("n_dot_v", 8), ("cos_cone", 1)]);
        let ue4 = SPEC.replace("ggx-env", "ggx-env-ue4");
        let spec = crate::spec::Spec::parse(Path::new("fits/ggx_x.toml"), ue4, crate::family::catalog()).unwrap();
        assert_eq!(spec.file.axis.len(), 2);
    }

    #[test]
    fn errors_name_line_and_field() {
        let bad = |edit: (&str, &str), line: usize, field: &str, msg: &str| {
            let text = SPEC.replace(edit.0, edit.1);
            let e = crate::spec::Spec::parse(Path::new("fits/ggx_x.toml"), text, crate::family::catalog()).unwrap_err();
            assert_eq!((e.line, e.field.as_str()), (line, field), "{e}");
            assert!(e.msg.contains(msg), "{e}");
        };
        bad(("[8, 4]", "[8]"), 4, "resolution", "[n·v columns, roughness rows]");
        bad(("[8, 4]", "[8, 1]"), 4, "resolution", "[2, 1024]");
        bad(("[8, 4]", "[8, 4]\ncos_cone = 1.0"), 5, "cos_cone", "[0, 0.99]");
        bad(("[8, 4]", "[8, 4]\ncos_cone = nan"), 5, "cos_cone", "[0, 0.99]");
        bad(("[8, 4]", "[8, 4]\ntolerance = 1e-3"), 5, "tolerance", "[1e-12, 1e-5]");
        bad(("[8, 4]", "[8, 4]\nlayout = \"ue\""), 5, "layout", "unknown variant");
        bad(("[8, 4]", "[8, 4]\nroughness_mapping = \"sqrt\""), 5, "roughness_mapping", "unknown variant");
        bad(("[8, 4]", "[8, 4]\nn_dot_v_mapping = \"sqrt\""), 5, "n_dot_v_mapping", "unknown variant");
        bad(("[8, 4]", "[8, 4]\ntexture_format = \"rgba32float\""), 5, "texture_format", "\"rg16float\" or \"rgba16float\"");
        bad(("[8, 4]", "[8, 4]\ntexture_format = \"rgb\""), 5, "texture_format", "unknown variant");
        bad(("quantity = \"ggx-env\"", "quantity = \"ggx-albedo\""), 3, "quantity", "'ggx-env' or 'ggx-env-ue4'");
        bad(("quantity = \"ggx-env\"", "quantity = \"ggx-env-ue4\"\ncos_cone = 0.5"), 4, "cos_cone", "ggx-env only");
        bad(("name = \"ggx_x\"", "name = \"ggx_y\""), 1, "name", "must match the file name");
        bad(("function = \"ggx_x\"", "function = \"ggx-x\""), 7, "function", "not a valid function name");
        bad(("[8, 4]", "[8, 4]\nmipmaps = 3"), 5, "mipmaps", "unknown field");
    }
}
