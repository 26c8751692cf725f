//! The checks every concern of validation uses, each naming the file and
//! key path and saying what is allowed. Modelling methods check their own
//! keys with them too (`method/`).

use super::error::ModelError;
use super::profile::Profile;
use super::schema::Model;

/// The model under check and its file, with the checks every concern uses.
pub(crate) struct Check<'a> {
    pub m: &'a Model,
    pub file: &'a str,
}

impl Check<'_> {
    pub fn err(&self, path: String, msg: String) -> Result<(), ModelError> {
        Err(ModelError::new(self.file, path, msg))
    }

    /// A name that becomes a file or folder name (a model's output folder,
    /// a body's plot): letters, digits, `_` and `-`, so that nothing is
    /// written outside the output folder.
    pub fn file_name(&self, path: &str, what: &str, name: &str) -> Result<(), ModelError> {
        let ok = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '-';
        if !name.is_empty() && name.len() <= 100 && name.chars().all(ok) {
            return Ok(());
        }
        self.err(
            path.into(),
            format!(
                "{name:?} cannot name {what}: it names files, so use 1 to 100 letters, digits, '_' and '-'"
            ),
        )
    }

    pub fn finite(&self, path: &str, v: f64) -> Result<(), ModelError> {
        if v.is_finite() {
            return Ok(());
        }
        self.err(path.into(), format!("must be a finite number, got {v}"))
    }

    pub fn vec3(&self, path: &str, v: &[f64; 3]) -> Result<(), ModelError> {
        for (i, x) in v.iter().enumerate() {
            self.finite(&format!("{path}[{i}]"), *x)?;
        }
        Ok(())
    }

    pub fn positive(&self, path: &str, v: f64) -> Result<(), ModelError> {
        self.finite(path, v)?;
        if v > 0.0 {
            return Ok(());
        }
        self.err(path.into(), format!("must be positive, got {v}"))
    }

    pub fn non_negative(&self, path: &str, v: f64) -> Result<(), ModelError> {
        self.finite(path, v)?;
        if v >= 0.0 {
            return Ok(());
        }
        self.err(path.into(), format!("must be zero or positive, got {v}"))
    }

    /// A value along a segment is positive everywhere (it is linear
    /// between its points, so at each of them).
    pub fn positive_along(&self, path: &str, v: &Profile) -> Result<(), ModelError> {
        self.along(path, v, |x| x > 0.0, "positive")
    }

    pub fn non_negative_along(&self, path: &str, v: &Profile) -> Result<(), ModelError> {
        self.along(path, v, |x| x >= 0.0, "zero or positive")
    }

    fn along(
        &self,
        path: &str,
        v: &Profile,
        ok: fn(f64) -> bool,
        what: &str,
    ) -> Result<(), ModelError> {
        for x in v.knots() {
            self.finite(path, x)?;
            if !ok(x) {
                let msg = match v.uniform() {
                    Some(_) => format!("must be {what}, got {x}"),
                    None => format!("must be {what} everywhere along the segment, got {x}"),
                };
                return self.err(path.into(), msg);
            }
        }
        Ok(())
    }

    /// `name` is a declared input channel.
    pub fn channel(&self, path: &str, name: &str) -> Result<(), ModelError> {
        let inputs = &self.m.inputs;
        if inputs.contains_key(name) {
            return Ok(());
        }
        let known: Vec<&str> = inputs.keys().map(String::as_str).collect();
        self.err(
            path.into(),
            if known.is_empty() {
                format!("no input channel \"{name}\": declare it as [inputs.{name}]")
            } else {
                format!(
                    "no input channel \"{name}\"; declared: {} (or add [inputs.{name}])",
                    known.join(", ")
                )
            },
        )
    }
}
