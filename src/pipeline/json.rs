//! The committed JSON of a spec: input hashes, reading it back (hash-checked), and writing
//! JSON text (number arrays on one line).

use super::*;

/// Lowercase hex of a digest.
pub fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// Lowercase hex of the SHA-256 of `bytes`.
pub fn sha256_hex(bytes: &[u8]) -> String {
    hex(&Sha256::digest(bytes))
}

/// The files `(path under generated, SHA-256)` read back from `generated`, when each is there
/// with that digest (`None` otherwise, or when there are none).
pub fn read_unchanged<'a>(generated: &Path, files: impl IntoIterator<Item = (&'a str, &'a str)>) -> Option<Vec<Artifact>> {
    let out: Vec<Artifact> = files
        .into_iter()
        .map(|(p, want)| {
            let contents = std::fs::read(generated.join(p)).ok()?;
            (sha256_hex(&contents) == want).then(|| Artifact { path: p.into(), contents })
        })
        .collect::<Option<_>>()?;
    (!out.is_empty()).then_some(out)
}

pub fn input_hash(spec: &Spec) -> String {
    let mut h = Sha256::new();
    h.update(GENERATOR.as_bytes());
    h.update(b"\n");
    h.update(spec.text.as_bytes());
    format!("sha256:{}", hex(&h.finalize()))
}

pub(super) fn committed_json(root: &Path, spec: &Spec) -> Result<Value, BuildError> {
    committed_json_with_hash(root, spec, &input_hash(spec))
}

/// `generated/json/NAME.json` of a spec, if it records `hash` as its input hash (a spec kind
/// whose build reads more than the spec text passes its own hash): `NoCommitted` when it is
/// missing or unreadable, `SpecChanged` when it records another hash.
pub fn committed_json_with_hash(root: &Path, spec: &Spec, hash: &str) -> Result<Value, BuildError> {
    let name = &spec.file.name;
    let path = root.join("json").join(format!("{name}.json"));
    let text = std::fs::read_to_string(&path)
        .map_err(|e| BuildError::NoCommitted { spec: name.clone(), why: e.to_string() })?;
    let v: Value = serde_json::from_str(&text)
        .map_err(|e| BuildError::NoCommitted { spec: name.clone(), why: e.to_string() })?;
    let committed = v["input_hash"].as_str().unwrap_or("").to_string();
    if committed != hash {
        return Err(BuildError::SpecChanged { spec: name.clone(), committed, current: hash.to_string() });
    }
    Ok(v)
}

pub(super) fn f64_array(v: &Value, spec: &str, key: &str) -> Result<Vec<f64>, BuildError> {
    v[key]
        .as_array()
        .and_then(|a| a.iter().map(Value::as_f64).collect::<Option<Vec<f64>>>())
        .ok_or_else(|| BuildError::NoCommitted { spec: spec.into(), why: format!("no numeric array '{key}'") })
}

/// The committed texels `values` of a LUT's JSON: an array of `texels` arrays of N numbers
/// (`what` names them in the error, e.g. "[r, g, b]").
pub fn committed_texels<const N: usize>(v: &Value, spec: &str, texels: usize, what: &str) -> Result<Vec<[f64; N]>, BuildError> {
    let bad = |why: String| BuildError::NoCommitted { spec: spec.into(), why };
    let values: Vec<[f64; N]> = v["values"]
        .as_array()
        .and_then(|a| {
            a.iter()
                .map(|t| {
                    let t = t.as_array()?;
                    (t.len() == N).then_some(())?;
                    let mut out = [0.0; N];
                    for (o, x) in out.iter_mut().zip(t) {
                        *o = x.as_f64()?;
                    }
                    Some(out)
                })
                .collect::<Option<Vec<_>>>()
        })
        .ok_or_else(|| bad(format!("no array 'values' of {what} numbers")))?;
    if values.len() != texels {
        return Err(bad("texel count differs from the spec".into()));
    }
    Ok(values)
}

pub fn json_text(v: &Value) -> String {
    let mut s = serde_json::to_string_pretty(v).expect("JSON values serialise");
    s.push('\n');
    s
}

/// JSON text with every array of numbers on one line (a texel list stays one texel
/// per line; everything else as serde_json's pretty printer writes it).
pub fn compact_json(v: &Value) -> String {
    let pretty = json_text(v);
    let lines: Vec<&str> = pretty.lines().collect();
    let is_number = |s: &str| {
        let t = s.trim().trim_end_matches(',');
        !t.is_empty() && t.parse::<f64>().is_ok()
    };
    let mut out = String::with_capacity(pretty.len());
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i];
        if line.ends_with('[') {
            let mut j = i + 1;
            while j < lines.len() && is_number(lines[j]) {
                j += 1;
            }
            if j > i + 1 && j < lines.len() && lines[j].trim_start().starts_with(']') {
                let items: Vec<&str> = lines[i + 1..j].iter().map(|l| l.trim().trim_end_matches(',')).collect();
                out.push_str(line);
                out.push_str(&items.join(", "));
                out.push_str(lines[j].trim_start());
                out.push('\n');
                i = j + 1;
                continue;
            }
        }
        out.push_str(line);
        out.push('\n');
        i += 1;
    }
    out
}
