//! Diffusion profiles in specs: the `[profile]` section of skin LUT specs (and of the profile
//! files `shadefit eval --profile FILE.toml` reads), and the CSV radial-profile reader.
//!
//! ```toml
//! [profile]                 # at most one of the three keys; none: preset "deon-luebke"
//! preset = "deon-luebke"    # d'Eon & Luebke's six Gaussians (integrals::DEON_LUEBKE_SKIN)
//! gaussians = [             # your own sum of Gaussians: variance in mm², RGB weights
//!   { variance = 0.0064, weights = [0.233, 0.455, 0.649] },
//!   { variance = 0.0484, weights = [0.100, 0.336, 0.344] },
//! ]
//! csv = "profiles/my_skin.csv"  # a tabulated radial profile R(r), relative to this file
//! ```
//!
//! The CSV has a header row `radius_mm,red,green,blue` (`#` starts a comment line): radii in mm,
//! strictly increasing from r ≥ 0, values R(r) in 1/mm² (any overall scale: LUT values are
//! normalised), interpolated linearly and zero beyond the last radius.
//!
//! Every error names the file (the spec, or the CSV), the line and the field: a variance that
//! is zero, negative or NaN, a negative or NaN weight, a channel that is zero everywhere, a
//! radius that does not increase.

use crate::spec::SpecError;
use super::integrals::{DEON_LUEBKE_SKIN, Gaussian, Profile, ProfileError};
use serde::Deserialize;
use serde_json::{Value, json};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};
use toml::Spanned;

/// The `[profile]` section as written (spans give the lines of errors).
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProfileSection {
    pub preset: Option<Spanned<String>>,
    pub gaussians: Option<Spanned<Vec<GaussianEntry>>>,
    pub csv: Option<Spanned<String>>,
}

/// One `{ variance = .., weights = [r, g, b] }` entry.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GaussianEntry {
    /// Variance v (mm²) of the normalised 2-D Gaussian exp(−r²/(2v))/(2πv).
    pub variance: Spanned<f64>,
    /// RGB weights (three; the length is checked with the values, to name the entry).
    pub weights: Spanned<Vec<f64>>,
}

/// Named profiles a spec can ask for with `preset = "NAME"`.
pub const PRESETS: &[&str] = &["deon-luebke"];

/// Where a profile came from, for the provenance in generated JSON and for the input hash.
#[derive(Debug, Clone, PartialEq)]
pub enum ProfileSource {
    /// A named profile of [`PRESETS`].
    Preset(&'static str),
    /// Gaussians written in the spec.
    Gaussians,
    /// A CSV file: the path as written, the path read, and its bytes.
    Csv { written: String, path: PathBuf, bytes: Vec<u8> },
}

/// A validated profile and its source.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadedProfile {
    pub profile: Profile,
    pub source: ProfileSource,
}

impl LoadedProfile {
    /// The default: [`DEON_LUEBKE_SKIN`].
    pub fn deon_luebke() -> LoadedProfile {
        LoadedProfile { profile: Profile::Gaussians(DEON_LUEBKE_SKIN.to_vec()), source: ProfileSource::Preset("deon-luebke") }
    }

    /// Bytes that determine the profile besides the spec text (a CSV file's contents), hashed
    /// into the input hash of generated files so that an edited CSV makes them stale.
    pub fn hash_input(&self) -> &[u8] {
        match &self.source {
            ProfileSource::Csv { bytes, .. } => bytes,
            _ => &[],
        }
    }

    /// Provenance: where the profile came from, its terms or samples, and its total per
    /// channel (∫ R 2πr dr in closed form; 1 for normalised Gaussian weights).
    pub fn provenance(&self) -> Value {
        let total = self.profile.total();
        let data = match &self.profile {
            Profile::Gaussians(gs) => json!({
                "gaussian": "exp(-r^2/(2 v)) / (2 pi v), v in mm^2, r in mm",
                "gaussians": gs.iter().map(|g| json!({"variance_mm2": g.variance_mm2, "weights": g.weight})).collect::<Vec<_>>(),
            }),
            Profile::Tabulated { radius_mm, value } => json!({
                "interpolation": "linear in r, held at R(r_0) below r_0, zero beyond the last radius",
                "radius_mm": radius_mm,
                "values": value,
            }),
        };
        let source = match &self.source {
            ProfileSource::Preset(name) => json!({
                "source": "preset",
                "preset": name,
                "reference": "E. d'Eon and D. Luebke, \"Advanced Techniques for Realistic Real-Time Skin Rendering\", GPU Gems 3, ch. 14 (2007): six-Gaussian fit of a three-layer skin profile",
            }),
            ProfileSource::Gaussians => json!({"source": "gaussians"}),
            ProfileSource::Csv { written, bytes, .. } => json!({
                "source": "csv",
                "csv": written,
                "csv_sha256": sha256_hex(bytes),
            }),
        };
        let mut v = source;
        let obj = v.as_object_mut().expect("an object");
        for (k, x) in data.as_object().expect("an object") {
            obj.insert(k.clone(), x.clone());
        }
        obj.insert("channels".into(), json!(["red", "green", "blue"]));
        obj.insert("total".into(), json!(total));
        v
    }
}

/// Hex SHA-256 of some bytes.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes).iter().map(|b| format!("{b:02x}")).collect()
}

fn line_at(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].bytes().filter(|&b| b == b'\n').count() + 1
}

const CHANNELS: [&str; 3] = ["red", "green", "blue"];

impl ProfileSection {
    /// The validated profile. `file`/`text` are the TOML file holding the section (CSV paths
    /// are relative to its folder); `section_line` is the line of `[profile]`, for errors
    /// about the section as a whole.
    pub fn load(&self, file: &Path, text: &str, section_line: usize) -> Result<LoadedProfile, SpecError> {
        let given = [self.preset.is_some(), self.gaussians.is_some(), self.csv.is_some()];
        if given.iter().filter(|&&g| g).count() > 1 {
            return Err(SpecError::new(file, section_line, "profile", "give at most one of 'preset', 'gaussians' and 'csv'"));
        }
        if let Some(p) = &self.preset {
            let line = line_at(text, p.span().start);
            return match PRESETS.iter().find(|&&n| n == p.get_ref()) {
                Some(&"deon-luebke") => Ok(LoadedProfile::deon_luebke()),
                _ => Err(SpecError::new(
                    file,
                    line,
                    "profile.preset",
                    format!("unknown preset '{}' (known: {})", p.get_ref(), PRESETS.join(", ")),
                )),
            };
        }
        if let Some(gs) = &self.gaussians {
            return load_gaussians(gs, file, text);
        }
        if let Some(c) = &self.csv {
            let line = line_at(text, c.span().start);
            let written = c.get_ref().clone();
            let rel = Path::new(&written);
            let path = if rel.is_absolute() {
                rel.to_path_buf()
            } else {
                file.parent().unwrap_or(Path::new("")).join(rel)
            };
            let bytes = crate::spec::input::read_input(&path).map_err(|e| {
                SpecError::new(file, line, "profile.csv", format!("{}: {e}", path.display()))
            })?;
            let profile = read_profile_csv(&path, &bytes)?;
            return Ok(LoadedProfile { profile, source: ProfileSource::Csv { written, path, bytes } });
        }
        Ok(LoadedProfile::deon_luebke())
    }
}

fn load_gaussians(gs: &Spanned<Vec<GaussianEntry>>, file: &Path, text: &str) -> Result<LoadedProfile, SpecError> {
    let mut terms = Vec::new();
    for (index, g) in gs.get_ref().iter().enumerate() {
        let weight: [f64; 3] = g.weights.get_ref().as_slice().try_into().map_err(|_| {
            SpecError::new(
                file,
                line_at(text, g.weights.span().start),
                &format!("profile.gaussians[{index}].weights"),
                format!("needs 3 weights [red, green, blue], found {}", g.weights.get_ref().len()),
            )
        })?;
        terms.push(Gaussian { variance_mm2: *g.variance.get_ref(), weight });
    }
    let profile = Profile::Gaussians(terms);
    profile.validate().map_err(|e| {
        let entry = |i: usize| &gs.get_ref()[i];
        let (line, field) = match &e {
            ProfileError::BadVariance { index, .. } => {
                (line_at(text, entry(*index).variance.span().start), format!("profile.gaussians[{index}].variance"))
            }
            ProfileError::BadWeight { index, .. } => {
                (line_at(text, entry(*index).weights.span().start), format!("profile.gaussians[{index}].weights"))
            }
            _ => (line_at(text, gs.span().start), "profile.gaussians".to_string()),
        };
        let msg = match e {
            ProfileError::BadWeight { channel, value, .. } => {
                format!("{} weight {value} must be finite and >= 0", CHANNELS[channel])
            }
            other => other.to_string(),
        };
        SpecError::new(file, line, &field, msg)
    })?;
    Ok(LoadedProfile { profile, source: ProfileSource::Gaussians })
}

/// A tabulated radial profile from CSV bytes (header `radius_mm,red,green,blue`); errors name
/// `path`, the line and the column.
/// The largest magnitude a profile CSV's radius or channel may take.
pub const PROFILE_VALUE_MAX: f64 = 1e100;

pub fn read_profile_csv(path: &Path, bytes: &[u8]) -> Result<Profile, SpecError> {
    let mut rdr = csv::ReaderBuilder::new().trim(csv::Trim::All).comment(Some(b'#')).from_reader(bytes);
    let headers = rdr.headers().map_err(|e| SpecError::new(path, 1, "(header)", e.to_string()))?.clone();
    let header_line = headers.position().map_or(1, |p| p.line() as usize);
    let columns = ["radius_mm", "red", "green", "blue"];
    let mut index = [0usize; 4];
    for (k, name) in columns.iter().enumerate() {
        index[k] = headers.iter().position(|h| h == *name).ok_or_else(|| {
            SpecError::new(
                path,
                header_line,
                name,
                format!(
                    "no such column (the header must name radius_mm, red, green, blue; found {})",
                    headers.iter().collect::<Vec<_>>().join(", ")
                ),
            )
        })?;
    }
    let mut radius_mm = Vec::new();
    let mut value = Vec::new();
    let mut lines = Vec::new();
    for rec in rdr.records() {
        let rec = rec.map_err(|e| {
            let line = e.position().map_or(0, |p| p.line() as usize);
            SpecError::new(path, line, "(row)", e.to_string())
        })?;
        let line = rec.position().map_or(0, |p| p.line() as usize);
        let mut row = [0.0; 4];
        for k in 0..4 {
            let s = rec.get(index[k]).unwrap_or("");
            let v: f64 = s
                .parse()
                .map_err(|_| SpecError::new(path, line, columns[k], format!("'{s}' is not a number")))?;
            if !v.is_finite() {
                return Err(SpecError::new(path, line, columns[k], format!("'{s}' is not finite")));
            }
            // The profile is normalised by integrals of value × r (and r²): past this bound
            // their products overflow f64 and the channel would read as zero.
            if v.abs() > PROFILE_VALUE_MAX {
                return Err(SpecError::new(path, line, columns[k], format!("'{s}' is beyond ±{PROFILE_VALUE_MAX:e}: the profile's integrals would overflow; scale the column")));
            }
            row[k] = v;
        }
        radius_mm.push(row[0]);
        value.push([row[1], row[2], row[3]]);
        lines.push(line);
    }
    let profile = Profile::Tabulated { radius_mm, value };
    profile.validate().map_err(|e| {
        let at = |i: usize| lines.get(i).copied().unwrap_or(header_line);
        let (line, field, msg) = match e {
            ProfileError::BadRadius { index, radius_mm } => {
                (at(index), "radius_mm", format!("{radius_mm} mm must be finite and >= 0"))
            }
            ProfileError::NonMonotoneRadius { index, previous_mm, radius_mm } => (
                at(index),
                "radius_mm",
                format!("{radius_mm} mm does not increase (previous row: {previous_mm} mm); radii must be strictly increasing"),
            ),
            ProfileError::BadWeight { index, channel, value } => {
                (at(index), CHANNELS[channel], format!("{value} must be finite and >= 0"))
            }
            ProfileError::ZeroChannel { channel } => {
                (header_line, CHANNELS[channel], "the channel is zero at every radius".to_string())
            }
            other => (header_line, "(rows)", other.to_string()),
        };
        SpecError::new(path, line, field, msg)
    })?;
    Ok(profile)
}

/// A profile file for `shadefit eval --profile`: a TOML file with a `[profile]` section, or a
/// CSV radial profile (by extension `.csv`).
pub fn load_profile_file(path: &Path) -> Result<LoadedProfile, SpecError> {
    let bytes = crate::spec::input::read_input(path).map_err(|e| SpecError::unreadable(path, e))?;
    if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("csv")) {
        let profile = read_profile_csv(path, &bytes)?;
        let written = path.display().to_string();
        return Ok(LoadedProfile { profile, source: ProfileSource::Csv { written, path: path.to_path_buf(), bytes } });
    }
    let text = String::from_utf8(bytes).map_err(|_| SpecError::new(path, 0, "(file)", "not UTF-8 text"))?;
    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    struct ProfileFile {
        profile: ProfileSection,
    }
    let f: ProfileFile = crate::spec::parse_toml(path, &text)?;
    f.profile.load(path, &text, crate::spec::line_of(&text, "profile"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn section(text: &str) -> Result<LoadedProfile, SpecError> {
        #[derive(Deserialize)]
        struct F {
            profile: ProfileSection,
        }
        let path = Path::new("fits/x.toml");
        let f: F = crate::spec::parse_toml(path, text)?;
        f.profile.load(path, text, crate::spec::line_of(text, "profile"))
    }

    #[test]
    fn presets_gaussians_and_defaults() {
        assert_eq!(section("[profile]\n").unwrap(), LoadedProfile::deon_luebke());
        assert_eq!(section("[profile]\npreset = \"deon-luebke\"\n").unwrap(), LoadedProfile::deon_luebke());
        let p = section("[profile]\ngaussians = [\n  { variance = 1, weights = [1, 0.5, 0.25] },\n]\n").unwrap();
        assert_eq!(p.profile, Profile::Gaussians(vec![Gaussian { variance_mm2: 1.0, weight: [1.0, 0.5, 0.25] }]));
        // Normalisation of a closed-form profile: the total is Σ w exactly (rounding only).
        assert_eq!(p.profile.total(), [1.0, 0.5, 0.25]);
    }

    #[test]
    fn errors_name_line_and_field() {
        let bad = |text: &str, line: usize, field: &str, msg: &str| {
            let e = section(text).unwrap_err();
            assert_eq!((e.line, e.field.as_str()), (line, field), "{e}");
            assert!(e.msg.contains(msg), "{e}");
            assert!(e.to_string().starts_with(&format!("fits/x.toml:{line}:")), "{e}");
        };
        let two = "[profile]\ngaussians = [\n  { variance = 0.5, weights = [1, 1, 1] },\n  { variance = VAR, weights = W },\n]\n";
        let g = |var: &str, w: &str| two.replace("VAR", var).replace("W", w);
        bad(&g("0.0", "[1, 1, 1]"), 4, "profile.gaussians[1].variance", "must be finite and > 0");
        bad(&g("-2", "[1, 1, 1]"), 4, "profile.gaussians[1].variance", "-2");
        bad(&g("nan", "[1, 1, 1]"), 4, "profile.gaussians[1].variance", "NaN");
        bad(&g("1", "[1, -0.5, 1]"), 4, "profile.gaussians[1].weights", "green weight -0.5");
        bad(&g("1", "[1, 1, nan]"), 4, "profile.gaussians[1].weights", "blue weight NaN");
        bad(&g("1", "[1, 1]"), 4, "profile.gaussians[1].weights", "needs 3 weights");
        bad("[profile]\ngaussians = []\n", 2, "profile.gaussians", "no terms");
        bad("[profile]\ngaussians = [{ variance = 1, weights = [1, 0, 1] }]\n", 2, "profile.gaussians", "green channel");
        bad("[profile]\npreset = \"penner\"\n", 2, "profile.preset", "unknown preset");
        bad("[profile]\npreset = \"deon-luebke\"\ncsv = \"a.csv\"\n", 1, "profile", "at most one");
        bad("[profile]\ncsv = \"no/such/file.csv\"\n", 2, "profile.csv", "cannot read");
        bad("[profile]\nsigma = 1\n", 2, "sigma", "unknown field");
    }

    /// A CSV profile loaded from its file: the profile, its bytes as the hash input (so an
    /// edited file makes generated files stale), and their SHA-256 in the provenance. The hash
    /// against FIPS 180-2's example ("abc", Appendix B.1) and the empty message; a preset has no
    /// hash input.
    #[test]
    fn a_csv_profile_file_hashes_its_bytes() {
        assert_eq!(sha256_hex(b"abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
        assert_eq!(sha256_hex(b""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
        let d = tempfile::tempdir().unwrap();
        let path = d.path().join("p.CSV");
        let body = "radius_mm,red,green,blue\n0,3,6,1.5\n2,0,0,0\n";
        std::fs::write(&path, body).unwrap();
        let p = load_profile_file(&path).unwrap();
        assert_eq!(p.profile, Profile::Tabulated { radius_mm: vec![0.0, 2.0], value: vec![[3.0, 6.0, 1.5], [0.0; 3]] });
        assert_eq!(p.hash_input(), body.as_bytes());
        assert_eq!(p.provenance()["csv_sha256"], sha256_hex(body.as_bytes()));
        assert!(LoadedProfile::deon_luebke().hash_input().is_empty());
        let e = load_profile_file(&d.path().join("missing.csv")).unwrap_err();
        assert!(e.file.ends_with("missing.csv") && e.msg.contains("cannot read"), "{e}");
    }

    #[test]
    fn csv_profiles_and_their_errors() {
        let d = tempfile::tempdir().unwrap();
        let path = d.path().join("p.csv");
        let read = |body: &str| read_profile_csv(&path, body.as_bytes());
        let p = read("# a tent\nradius_mm,red,green,blue\n0,3,6,1.5\n2,0,0,0\n").unwrap();
        assert_eq!(
            p,
            Profile::Tabulated { radius_mm: vec![0.0, 2.0], value: vec![[3.0, 6.0, 1.5], [0.0; 3]] }
        );
        // Columns in any order.
        let q = read("red,green,blue,radius_mm\n3,6,1.5,0\n0,0,0,2\n").unwrap();
        assert_eq!(p, q);
        let bad = |body: &str, line: usize, field: &str, msg: &str| {
            let e = read(body).unwrap_err();
            assert_eq!((e.line, e.field.as_str()), (line, field), "{e}");
            assert!(e.msg.contains(msg), "{e}");
            assert!(e.file.ends_with("p.csv"), "{e}");
        };
        let h = "radius_mm,red,green,blue\n";
        bad(&format!("{h}0,1,1,1\n1,1,1,1\n1,0,0,0\n"), 4, "radius_mm", "does not increase");
        bad(&format!("{h}0,1,1,1\n2,1,1,1\n1.5,0,0,0\n"), 4, "radius_mm", "does not increase");
        bad(&format!("{h}0,1,1,1\nnan,1,1,1\n"), 3, "radius_mm", "not finite");
        bad(&format!("{h}0,1,NaN,1\n1,0,0,0\n"), 2, "green", "not finite");
        bad(&format!("{h}0,1,-1,1\n1,0,0,0\n"), 2, "green", "must be finite and >= 0");
        bad(&format!("{h}-1,1,1,1\n1,0,0,0\n"), 2, "radius_mm", ">= 0");
        bad(&format!("{h}0,1,1,x\n1,0,0,0\n"), 2, "blue", "not a number");
        bad(&format!("{h}0,1,0,1\n1,0,0,0\n"), 1, "green", "zero at every radius");
        bad(&format!("{h}0,1,1,1\n"), 1, "(rows)", "at least 2");
        bad("r,red,green,blue\n0,1,1,1\n", 1, "radius_mm", "no such column");
    }
}
