//! User data for `shadefit fit`: a CSV file with a header row.

use super::SpecError;
use crate::fit::Data;
use std::path::Path;

/// Read columns `x_cols` (features, in order) and `y_col` from a CSV file with a header (read
/// through `input::read_input`: a regular file within its byte limit). Every cell must be a
/// finite number, no two columns may share a header, and each feature column must take two
/// values at least; errors name the file, the line and the column.
pub fn read_csv(path: &Path, x_cols: &[String], y_col: &str) -> Result<Data, SpecError> {
    let bytes = super::input::read_input(path).map_err(|e| SpecError::unreadable(path, e))?;
    let mut rdr = csv::ReaderBuilder::new().trim(csv::Trim::All).comment(Some(b'#')).from_reader(&bytes[..]);
    let headers = rdr
        .headers()
        .map_err(|e| SpecError::new(path, 1, "(header)", e.to_string()))?
        .clone();
    for (i, h) in headers.iter().enumerate() {
        if let Some(j) = headers.iter().take(i).position(|g| g == h) {
            return Err(SpecError::new(
                path,
                1,
                h,
                format!("the header '{h}' names columns {} and {}; each column needs a name of its own", j + 1, i + 1),
            ));
        }
    }
    let find = |name: &str| {
        headers.iter().position(|h| h == name).ok_or_else(|| {
            SpecError::new(
                path,
                1,
                name,
                format!("no such column (columns: {})", headers.iter().collect::<Vec<_>>().join(", ")),
            )
        })
    };
    let xi: Vec<usize> = x_cols.iter().map(|c| find(c)).collect::<Result<_, _>>()?;
    let yi = find(y_col)?;
    let mut data = Data::default();
    for rec in rdr.records() {
        let rec = rec.map_err(|e| {
            let line = e.position().map_or(0, |p| p.line() as usize);
            SpecError::new(path, line, "(row)", e.to_string())
        })?;
        let line = rec.position().map_or(0, |p| p.line() as usize);
        let cell = |i: usize, name: &str| -> Result<f64, SpecError> {
            let s = rec.get(i).unwrap_or("");
            let v: f64 = s
                .parse()
                .map_err(|_| SpecError::new(path, line, name, format!("'{s}' is not a number")))?;
            if !v.is_finite() {
                return Err(SpecError::new(path, line, name, format!("'{s}' is not finite")));
            }
            Ok(v)
        };
        let x = xi.iter().zip(x_cols).map(|(&i, n)| cell(i, n)).collect::<Result<Vec<_>, _>>()?;
        data.x.push(x);
        data.y.push(cell(yi, y_col)?);
    }
    if data.is_empty() {
        return Err(SpecError::new(path, 2, "(rows)", "no data rows"));
    }
    // A feature that takes one value only spans nothing: a model in it is fitted at a single
    // abscissa, where a rational may put its pole anywhere else. The header names the column.
    // One row is too few for any model with a feature, which the fit says in its own terms.
    for (j, name) in x_cols.iter().enumerate().filter(|_| data.len() > 1) {
        let v = data.x[0][j];
        if data.x.iter().all(|p| p[j] == v) {
            return Err(SpecError::new(
                path,
                1,
                name,
                format!("column '{name}' takes one value only ({v:?} on all {} rows): a fit needs each feature to span a range", data.len()),
            ));
        }
    }
    Ok(data)
}
