//! Errors about a model: which file, which key, what is wrong, what is allowed.

/// A problem with a model file or an override, located by key path
/// (`segment[1].length`).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub struct ModelError {
    /// The file (or `--set` for an override).
    pub file: String,
    /// Key path, empty for the file as a whole.
    pub path: String,
    pub message: String,
}

impl std::fmt::Display for ModelError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.path.is_empty() {
            write!(f, "{}: {}", self.file, self.message)
        } else {
            write!(f, "{}: {}: {}", self.file, self.path, self.message)
        }
    }
}

impl ModelError {
    pub fn new(file: &str, path: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            file: file.to_string(),
            path: path.into(),
            message: message.into(),
        }
    }

    /// The same error with `suffix` after its message (where along a
    /// segment it holds).
    pub fn with_suffix(mut self, suffix: &str) -> Self {
        self.message.push_str(suffix);
        self
    }
}
