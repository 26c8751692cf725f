//! Measured data in CSV files: numeric columns by header name, with errors
//! that name the file, the column and the row.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

/// A CSV file with a header row and numeric cells.
pub struct Csv {
    pub path: PathBuf,
    headers: Vec<String>,
    rows: Vec<Vec<f64>>,
}

impl Csv {
    pub fn read(path: &Path) -> Result<Self> {
        let mut reader = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .from_path(path)
            .with_context(|| format!("{}: cannot read the CSV file", path.display()))?;
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

/// Resolve a path written in a model file against the model's folder.
pub fn resolve(base: &Path, file: &str) -> PathBuf {
    let p = Path::new(file);
    if p.is_absolute() {
        p.to_path_buf()
    } else {
        base.join(p)
    }
}
