//! Skin LUT specs (`kind = "skin-lut"`): pre-integrated skin scattering tabulated as textures.
//!
//! ```toml
//! name = "skin_punctual_lut"       # output stem; must equal the file stem
//! kind = "skin-lut"
//! quantity = "skin-punctual"       # D(n·l, κ) for punctual lights; "skin-sh": k_1, k_2 (κ)
//! description = "..."
//! resolution = [64, 64]            # skin-punctual: [n·l columns, κ rows]; skin-sh: [κ columns]
//! curvature_max = 1.0              # κ_max (1/mm): rows cover κ ∈ [0, κ_max], larger κ clamps
//! curvature_mapping = "linear"     # optional: "linear" (t = κ/κ_max) or "sqrt" (t = √(κ/κ_max))
//! n_dot_l_mapping = "linear"       # optional: n·l ∈ [−1, 1] uniform (the only mapping)
//! kernel = "linear"                # optional, skin-punctual only: "linear" (default) or "radial"
//! tolerance = 1e-10                # optional: quadrature tolerance per texel and channel
//! texture_format = "rgba16float"   # optional: KTX2 texels, "rgba16float" or "rgba32float"
//! float32_filterable = false       # required true with "rgba32float" (see below)
//!
//! [profile]                        # optional (see super::profile): preset, gaussians or csv
//! preset = "deon-luebke"
//!
//! [emit]
//! function = "skin_punctual_lut"   # WGSL and Rust function name
//! ```
//!
//! Texel (i, j) of a skin-punctual LUT holds D at n·l = −1 + 2i/(n_u − 1) and at
//! κ = κ_max·mapping⁻¹(j/(n_v − 1)); a skin-sh LUT has one row per band (1 and 2; band 0 is 1)
//! and column i at κ = κ_max·mapping⁻¹(i/(n − 1)). See `super::build` for the outputs.
//!
//! `NAME_sample` reads the texture through a linear sampler. Core WebGPU filters RGBA16F but
//! not RGBA32F (linear filtering of 32-bit floats is the optional `float32-filterable`
//! feature, `wgpu::Features::FLOAT32_FILTERABLE`), so an "rgba32float" LUT must say
//! `float32_filterable = true`: the engine promises to request that feature (the runtime's
//! `create_lut_texture` refuses the texture on a device without it). Without that line the
//! spec is rejected rather than emitting a sampler pairing that fails validation on most
//! devices.
//!
//! The spec is checked here with errors that name the file, the line and the field; it then
//! enters the common [`SpecFile`] with its axes (curvature, n_dot_l or band) spelled out, so
//! listing, staleness and the runtime index treat it like any other spec.

use super::profile::{LoadedProfile, ProfileSection};
use crate::spec::{CustomSpec, SpecError, SpecFile, check_resolution, check_tolerance, line_of, parse_toml, Preset};
use crate::pipeline::GridAxis;
use crate::spec::TableTextureFormat as TextureFormat;
use crate::spec::table::{self, Placement};
use super::integrals::{CurvatureMapping, Kernel};
use serde::Deserialize;
use serde_json::json;
use std::path::Path;

/// The `kind` value of skin LUT specs.
pub const KIND: &str = "skin-lut";
/// Default quadrature tolerance per texel and channel (integrals::DEFAULT_TOLERANCE).
pub const DEFAULT_TOLERANCE: f64 = 1e-10;
/// Tolerances accepted: the LUT promises ≤ 1e-6 per channel; below 1e-14 the adaptive rule
/// cannot converge in f64 on values of order 1.
pub const TOLERANCE_RANGE: [f64; 2] = [1e-14, 1e-6];
/// Largest texture side.
pub const MAX_RESOLUTION: usize = 4096;
/// Largest κ_max (1/mm): the `curvature` parameter's domain.
pub const MAX_CURVATURE: f64 = 100.0;

#[derive(Debug, Clone, Copy, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
enum NDotLMapping {
    #[default]
    Linear,
}

#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
enum KernelName {
    Linear,
    Radial,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct SkinEmit {
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
struct SkinLutFile {
    name: String,
    #[allow(dead_code)] // checked by the caller: "skin-lut"
    kind: String,
    quantity: String,
    #[serde(default)]
    description: String,
    tolerance: Option<f64>,
    resolution: Vec<usize>,
    curvature_max: f64,
    #[serde(default)]
    curvature_mapping: CurvatureMapping,
    #[allow(dead_code)] // one variant: parsing it is the check (and its presence on skin-sh)
    n_dot_l_mapping: Option<NDotLMapping>,
    kernel: Option<KernelName>,
    texture_format: Option<TextureFormat>,
    #[serde(default)]
    float32_filterable: bool,
    profile: Option<ProfileSection>,
    emit: SkinEmit,
}

/// What a skin LUT tabulates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SkinLutKind {
    /// D(n·l, κ) (RGB) on `n_dot_l` columns × the curvature rows, ring integral with `kernel`.
    Punctual { kernel: Kernel, n_dot_l: usize },
    /// k_1(κ), k_2(κ) (RGB): one row per band, the curvature along the columns.
    Sh,
}

/// A validated skin LUT spec.
#[derive(Debug, Clone, PartialEq)]
pub struct SkinLut {
    pub name: String,
    pub quantity: String,
    pub description: String,
    pub function: String,
    pub kind: SkinLutKind,
    /// Samples along κ (rows of a punctual LUT, columns of an SH LUT).
    pub curvature_count: usize,
    pub curvature_max: f64,
    pub curvature_mapping: CurvatureMapping,
    pub format: TextureFormat,
    /// Absolute quadrature tolerance per texel and channel.
    pub tolerance: f64,
    pub profile: LoadedProfile,
}

impl SkinLut {

    /// κ (1/mm) of the curvature samples, in order (ends included, mapped).
    pub fn curvatures(&self) -> Vec<f64> {
        self.curvatures_at(self.curvature_count)
    }

    /// κ at `n` nodes of the mapped coordinate (the table's `curvature_count`, or the
    /// verification's 2n − 1).
    pub fn curvatures_at(&self, n: usize) -> Vec<f64> {
        let axis = GridAxis { count: n, ..self.curvature_axis() };
        axis.arguments().into_iter().map(|t| self.curvature_max * axis.parameter(t)).collect()
    }

    /// The curvature axis of the table kind's grid: nodes of the mapped coordinate t ∈ [0, 1],
    /// whose parameter is κ/κ_max (t, or t² for `sqrt` rows).
    pub fn curvature_axis(&self) -> GridAxis {
        let mapping = match self.curvature_mapping {
            CurvatureMapping::Linear => &table::LINEAR,
            CurvatureMapping::Sqrt => &table::SQUARE,
        };
        GridAxis { range: [0.0, 1.0], count: self.curvature_count, placement: Placement::Nodes, mapping, param: 0 }
    }

    /// The n·l axis of a punctual LUT's grid: `n` nodes on [−1, 1].
    pub fn n_dot_l_axis(n: usize) -> GridAxis {
        GridAxis { range: [-1.0, 1.0], count: n, placement: Placement::Nodes, mapping: &table::LINEAR, param: 1 }
    }

}

impl Preset for SkinLut {
    const KIND: &'static str = KIND;

    /// Parse and check a skin LUT spec (its `kind` must be "skin-lut").
    fn parse(path: &Path, text: &str) -> Result<SkinLut, SpecError> {
        let f: SkinLutFile = parse_toml(path, text)?;
        let at = |field: &str, msg: String| SpecError::new(path, line_of(text, field), field, msg);
        let punctual = match f.quantity.as_str() {
            "skin-punctual" => true,
            "skin-sh" => false,
            other => {
                return Err(at("quantity", format!("'{other}': skin LUTs tabulate 'skin-punctual' or 'skin-sh'")));
            }
        };
        let want = if punctual { "[n·l columns, curvature rows]" } else { "[curvature columns]" };
        if f.resolution.len() != if punctual { 2 } else { 1 } {
            return Err(at("resolution", format!("{} needs resolution = {want}", f.quantity)));
        }
        check_resolution(&f.resolution, MAX_RESOLUTION).map_err(|m| at("resolution", m))?;
        let k = f.curvature_max;
        if !(k.is_finite() && k > 0.0 && k <= MAX_CURVATURE) {
            return Err(at("curvature_max", format!("{k}/mm must be finite and in (0, {MAX_CURVATURE}]")));
        }
        let format = f.texture_format.unwrap_or(TextureFormat::Rgba16float);
        if !matches!(format, TextureFormat::Rgba16float | TextureFormat::Rgba32float) {
            return Err(at("texture_format", format!("'{}': a skin LUT stores RGB with alpha 1: \"rgba16float\" or \"rgba32float\"", format.name())));
        }
        match (format, f.float32_filterable) {
            (TextureFormat::Rgba32float, false) => {
                return Err(at(
                    "texture_format",
                    "rgba32float is not filterable in core WebGPU and NAME_sample uses a linear sampler: \
                     set float32_filterable = true (the device must enable FLOAT32_FILTERABLE) or use rgba16float"
                        .into(),
                ));
            }
            (TextureFormat::Rgba16float, true) => {
                return Err(at("float32_filterable", "applies to texture_format = \"rgba32float\" only".into()));
            }
            _ => {}
        }
        let tolerance = f.tolerance.unwrap_or(DEFAULT_TOLERANCE);
        check_tolerance(tolerance, TOLERANCE_RANGE, "the LUT promises 1e-6 per channel; below 1e-14 the quadrature cannot converge").map_err(|m| at("tolerance", m))?;
        let kind = if punctual {
            let kernel = match f.kernel.unwrap_or(KernelName::Linear) {
                KernelName::Linear => Kernel::Linear,
                KernelName::Radial => Kernel::Radial,
            };
            SkinLutKind::Punctual { kernel, n_dot_l: f.resolution[0] }
        } else {
            if f.kernel.is_some() {
                return Err(at(
                    "kernel",
                    "skin-sh integrates the radial profile over the sphere; 'kernel' applies to skin-punctual only".into(),
                ));
            }
            if f.n_dot_l_mapping.is_some() {
                return Err(at("n_dot_l_mapping", "a skin-sh LUT has no n·l axis (its rows are SH bands); 'n_dot_l_mapping' applies to skin-punctual only".into()));
            }
            SkinLutKind::Sh
        };
        let profile = match &f.profile {
            Some(p) => p.load(path, text, line_of(text, "profile"))?,
            None => LoadedProfile::deon_luebke(),
        };
        // The ring and the sphere of curvature κ reach chord 2/κ: each channel needs some of
        // its profile within 2/κ_max, or the largest-κ texels cannot be normalised.
        let reach = profile.profile.mass_within(2.0 / k);
        // (NaN compares false: a NaN mass is no mass.)
        if let Some(c) = (0..3).find(|&c| reach[c].partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)) {
            return Err(at(
                "curvature_max",
                format!(
                    "the profile's {} channel has no mass within chord 2/κ_max = {} mm; lower curvature_max",
                    ["red", "green", "blue"][c],
                    2.0 / k
                ),
            ));
        }
        Ok(SkinLut {
            name: f.name,
            quantity: f.quantity,
            description: f.description,
            function: f.emit.function,
            kind,
            curvature_count: *f.resolution.last().expect("checked length"),
            curvature_max: k,
            curvature_mapping: f.curvature_mapping,
            format,
            tolerance,
            profile,
        })
    }

    /// The common spec this LUT enters the pipeline as: axes in the quantity's parameter order
    /// (curvature, then n_dot_l or band), counts as tabulated, verification on the grid that
    /// adds every midpoint (2n − 1).
    fn common(&self, path: &Path, text: &str) -> Result<SpecFile, SpecError> {
        let n = self.curvature_count;
        let mut axes = vec![json!({"name": "curvature", "range": [0.0, self.curvature_max], "count": n, "verify": 2 * n - 1})];
        axes.push(match self.kind {
            SkinLutKind::Punctual { n_dot_l, .. } => {
                json!({"name": "n_dot_l", "range": [-1.0, 1.0], "count": n_dot_l, "verify": 2 * n_dot_l - 1})
            }
            SkinLutKind::Sh => json!({"name": "band", "range": [1.0, 2.0], "count": 2, "verify": 2}),
        });
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

    const PUNCTUAL: &str = "name = \"skin_x\"\nkind = \"skin-lut\"\nquantity = \"skin-punctual\"\n\
        resolution = [8, 5]\ncurvature_max = 2.0\n\n[emit]\nfunction = \"skin_x\"\n";

    fn parse(text: &str) -> Result<SkinLut, SpecError> {
        SkinLut::parse(Path::new("fits/skin_x.toml"), text)
    }

    #[test]
    fn defaults_and_grid() {
        let l = parse(PUNCTUAL).unwrap();
        assert_eq!(l.kind, SkinLutKind::Punctual { kernel: Kernel::Linear, n_dot_l: 8 });
        assert_eq!((l.curvature_count, l.curvature_max, l.tolerance), (5, 2.0, DEFAULT_TOLERANCE));
        assert_eq!(l.format, TextureFormat::Rgba16float);
        assert_eq!(l.profile, LoadedProfile::deon_luebke());
        assert_eq!(l.curvatures(), [0.0, 0.5, 1.0, 1.5, 2.0]);
        let s = parse(&PUNCTUAL.replace("curvature_max = 2.0", "curvature_max = 2.0\ncurvature_mapping = \"sqrt\"")).unwrap();
        assert_eq!(s.curvatures(), [0.0, 0.125, 0.5, 1.125, 2.0]);
        let sh = PUNCTUAL.replace("skin-punctual", "skin-sh").replace("[8, 5]", "[5]");
        assert_eq!(parse(&sh).unwrap().kind, SkinLutKind::Sh);
        let spec = crate::spec::Spec::parse(Path::new("fits/skin_x.toml"), PUNCTUAL.to_string(), crate::family::catalog()).unwrap();
        assert_eq!(spec.file.kind, crate::spec::Kind::Custom(KIND));
        let axes: Vec<(&str, usize)> = spec.file.axis.iter().map(|a| (a.name.as_str(), a.count)).collect();
        assert_eq!(axes, [("curvature", 5), ("n_dot_l", 8)]);
    }

    #[test]
    fn errors_name_line_and_field() {
        let bad = |edit: (&str, &str), line: usize, field: &str, msg: &str| {
            let text = PUNCTUAL.replace(edit.0, edit.1);
            let e = crate::spec::Spec::parse(Path::new("fits/skin_x.toml"), text, crate::family::catalog()).unwrap_err();
            assert_eq!((e.line, e.field.as_str()), (line, field), "{e}");
            assert!(e.msg.contains(msg), "{e}");
        };
        bad(("[8, 5]", "[8]"), 4, "resolution", "[n·l columns, curvature rows]");
        bad(("[8, 5]", "[8, 1]"), 4, "resolution", "[2, 4096]");
        bad(("curvature_max = 2.0", "curvature_max = -1.0"), 5, "curvature_max", "(0, 100]");
        bad(("curvature_max = 2.0", "curvature_max = nan"), 5, "curvature_max", "NaN");
        bad(("curvature_max = 2.0", "curvature_max = 2.0\ntolerance = 1e-3"), 6, "tolerance", "1e-6");
        bad(("curvature_max = 2.0", "curvature_max = 2.0\nkernel = \"cubic\""), 6, "kernel", "unknown variant");
        bad(("curvature_max = 2.0", "curvature_max = 2.0\ncurvature_mapping = \"log\""), 6, "curvature_mapping", "unknown variant");
        bad(("curvature_max = 2.0", "curvature_max = 2.0\nn_dot_l_mapping = \"angle\""), 6, "n_dot_l_mapping", "unknown variant");
        bad(("skin-punctual", "skin-diffuse"), 3, "quantity", "skin-punctual' or 'skin-sh'");
        // A 32-bit float texture behind a linear sampler only with the feature requested.
        let f32_tex = "curvature_max = 2.0\ntexture_format = \"rgba32float\"";
        bad(("curvature_max = 2.0", f32_tex), 6, "texture_format", "set float32_filterable = true");
        let two = "curvature_max = 2.0\ntexture_format = \"rg16float\"";
        bad(("curvature_max = 2.0", two), 6, "texture_format", "\"rgba16float\" or \"rgba32float\"");
        bad(("curvature_max = 2.0", "curvature_max = 2.0\nfloat32_filterable = true"), 6, "float32_filterable", "rgba32float");
        let ok = parse(&PUNCTUAL.replace("curvature_max = 2.0", &format!("{f32_tex}\nfloat32_filterable = true"))).unwrap();
        assert_eq!(ok.format, TextureFormat::Rgba32float);
        bad(("name = \"skin_x\"", "name = \"skin_y\""), 1, "name", "must match the file name");
        bad(("function = \"skin_x\"", "function = \"Skin-X\""), 8, "function", "not a valid function name");
        let sh = PUNCTUAL.replace("skin-punctual", "skin-sh").replace("[8, 5]", "[5]") ;
        let e = SkinLut::parse(Path::new("fits/skin_x.toml"), &sh.replace("curvature_max = 2.0", "curvature_max = 2.0\nkernel = \"radial\"")).unwrap_err();
        assert_eq!((e.line, e.field.as_str()), (6, "kernel"), "{e}");
    }
}
