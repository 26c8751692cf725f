//! Measured data in CSV files: numeric columns by header name, with errors
//! that name the file, the column and the row; and where a model's data
//! files are: beside its file, or, for a compiled-in model, inside the
//! binary.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

use crate::generated::MODELS;

/// A CSV file with a header row and numeric cells.
pub struct Csv {
    pub path: PathBuf,
    headers: Vec<String>,
    rows: Vec<Vec<f64>>,
}

impl Csv {
    pub fn read(path: &Path) -> Result<Self> {
        let text = read_text(path)
            .with_context(|| format!("{}: cannot read the CSV file", path.display()))?;
        let mut reader = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .from_reader(text.as_bytes());
        let headers: Vec<String> = reader
            .headers()
            .with_context(|| format!("{}: cannot read the header row", path.display()))?
            .iter()
            .map(str::to_string)
            .collect();
        let mut rows = Vec::new();
        for (i, record) in reader.records().enumerate() {
            // Row numbers as a spreadsheet shows them: the header is row 1.
            let row = i + 2;
            let record =
                record.with_context(|| format!("{}: row {row}: not valid CSV", path.display()))?;
            let values = record
                .iter()
                .enumerate()
                .map(|(c, cell)| {
                    cell.parse::<f64>().map_err(|_| {
                        anyhow::anyhow!(
                            "{}: row {row}, column \"{}\": `{cell}` is not a number",
                            path.display(),
                            headers.get(c).map_or("?", String::as_str)
                        )
                    })
                })
                .collect::<Result<Vec<f64>>>()?;
            rows.push(values);
        }
        if rows.is_empty() {
            bail!("{}: no data rows below the header", path.display());
        }
        Ok(Self {
            path: path.to_path_buf(),
            headers,
            rows,
        })
    }

    /// A time column: strictly increasing.
    pub fn time_column(&self, name: &str) -> Result<Vec<f64>> {
        let t = self.column(name)?;
        if let Some(i) = (1..t.len()).find(|&i| t[i] <= t[i - 1]) {
            bail!(
                "{}: column \"{name}\" must increase: row {} has {} after {}",
                self.path.display(),
                i + 2,
                t[i],
                t[i - 1]
            );
        }
        Ok(t)
    }

    /// The values of column `name`.
    pub fn column(&self, name: &str) -> Result<Vec<f64>> {
        let Some(c) = self.headers.iter().position(|h| h == name) else {
            bail!(
                "{}: no column \"{name}\"; the header has: {}",
                self.path.display(),
                self.headers.join(", ")
            );
        };
        Ok(self.rows.iter().map(|r| r[c]).collect())
    }
}

/// The folder a compiled-in model's relative paths start from: a name,
/// not a place on disk, so that its files are the ones compiled in with
/// it (`CompiledModel::files`) wherever the binary is.
const COMPILED_IN: &str = "compiled-in:";

pub fn compiled_in_base(name: &str) -> PathBuf {
    PathBuf::from(format!("{COMPILED_IN}{name}"))
}

/// Resolve a path written in a model file against the model's folder. A
/// path into a compiled-in model stays as it is wherever it is written
/// again (a fitted model's file names its data this way). A compiled-in
/// model has no folder: a file it does not carry (a `--set` of another
/// record) is read from the current one.
pub fn resolve(base: &Path, file: &str) -> PathBuf {
    let p = Path::new(file);
    if p.is_absolute() || compiled_in(p).is_some() {
        return p.to_path_buf();
    }
    match compiled_in(base) {
        Some((name, _)) if carried(name, p).is_none() => p.to_path_buf(),
        _ => base.join(p),
    }
}

/// The text of a file a compiled-in model carries.
fn carried(name: &str, file: &Path) -> Option<&'static str> {
    let model = MODELS.iter().find(|m| m.name == name)?;
    model
        .files
        .iter()
        .find(|(f, _)| Path::new(f) == file)
        .map(|(_, text)| *text)
}

/// The compiled-in model a path starts from, and the rest of the path.
fn compiled_in(path: &Path) -> Option<(&str, &Path)> {
    let mut parts = path.components();
    let first = parts.next()?.as_os_str().to_str()?;
    let name = first.strip_prefix(COMPILED_IN)?;
    Some((name, parts.as_path()))
}

/// A data file's text: from disk, or from the binary for a compiled-in
/// model's file.
pub fn read_text(path: &Path) -> Result<String> {
    match compiled_in(path) {
        None => Ok(std::fs::read_to_string(path)?),
        Some((name, rest)) => carried(name, rest)
            .map(str::to_string)
            .with_context(|| format!("no compiled-in model `{name}` carries {}", rest.display())),
    }
}
