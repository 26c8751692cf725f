//! `--set PATH=VALUE` overrides of a model file's keys, applied to its
//! tree before the typed reading.

use super::error::ModelError;

/// One `--set PATH=VALUE` override.
#[derive(Clone, Debug, PartialEq)]
pub struct Override {
    /// Dotted path; array items by index (`segment.1.length`) or name
    /// (`arm.left.segment.0.length`).
    pub path: Vec<String>,
    pub value: toml::Value,
    /// The text as given, for messages.
    pub text: String,
}

impl Override {
    /// Parse `PATH=VALUE`. VALUE is a TOML value (`0.25`, `[0, -2, 0]`,
    /// `"pcc"`); a bare word is taken as a string.
    pub fn parse(s: &str) -> Result<Self, ModelError> {
        let (path, value) = s.split_once('=').ok_or_else(|| {
            ModelError::new(
                "--set",
                s,
                "expected PATH=VALUE, e.g. segment.0.length=0.25",
            )
        })?;
        let path = path.trim();
        if path.is_empty() || path.split('.').any(|p| p.trim().is_empty()) {
            return Err(ModelError::new(
                "--set",
                path,
                "the path must be dotted keys and indices, e.g. segment.0.length",
            ));
        }
        let value = value.trim();
        let parsed = toml::from_str::<toml::Table>(&format!("v = {value}"))
            .ok()
            .and_then(|mut t| t.remove("v"));
        let value = match parsed {
            Some(v) => v,
            None if !value.is_empty()
                && value
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') =>
            {
                toml::Value::String(value.to_string())
            }
            None => {
                return Err(ModelError::new(
                    "--set",
                    path,
                    format!(
                        "cannot read the value `{value}`: give a number, an array like [0, -2, 0], or a word"
                    ),
                ));
            }
        };
        Ok(Self {
            path: path.split('.').map(|p| p.trim().to_string()).collect(),
            value,
            text: s.to_string(),
        })
    }

    /// Apply to a model's tree of keys (`load::model_tree`).
    pub fn apply(&self, root: &mut toml::Value) -> Result<(), ModelError> {
        self.apply_from(root, 0)
    }

    /// The value at `path` below `root`, items of a list by index or by
    /// their `name` as `--set` finds them; None where nothing is there.
    pub fn value_at<'v>(root: &'v toml::Value, path: &str) -> Option<&'v toml::Value> {
        path.split('.').try_fold(root, |cur, key| match cur {
            toml::Value::Table(t) => t.get(key),
            toml::Value::Array(a) => match key.parse::<usize>() {
                Ok(i) => a.get(i),
                Err(_) => a
                    .iter()
                    .find(|item| item.get("name").and_then(toml::Value::as_str) == Some(key)),
            },
            _ => None,
        })
    }

    /// The path from `from` on, below `root`; `*` in a list is every item
    /// (`segment.*.youngs_modulus`: the same value on every segment).
    fn apply_from(&self, root: &mut toml::Value, from: usize) -> Result<(), ModelError> {
        let err = |m: String| ModelError::new("--set", self.path.join("."), m);
        let mut cur = root;
        for (depth, key) in self.path.iter().enumerate().skip(from) {
            let last = depth + 1 == self.path.len();
            cur = match cur {
                toml::Value::Table(t) => {
                    if last {
                        t.insert(key.clone(), self.value.clone());
                        return Ok(());
                    }
                    // A missing table on the way is created (the schema
                    // check afterwards rejects keys that do not exist), but
                    // not inside a table of named entries (`inputs`): there
                    // a missing name is a misspelt entry, not a new table.
                    let named_entries =
                        depth > 0 && !t.is_empty() && t.values().all(toml::Value::is_table);
                    if named_entries && !t.contains_key(key) {
                        let at = self.path[..depth].join(".");
                        let names: Vec<&str> = t.keys().map(String::as_str).collect();
                        return Err(err(format!(
                            "`{at}` has no entry `{key}`; it has {}",
                            names.join(", ")
                        )));
                    }
                    t.entry(key.clone())
                        .or_insert_with(|| toml::Value::Table(toml::Table::new()))
                }
                toml::Value::Array(a) if key == "*" => {
                    for item in a.iter_mut() {
                        match last {
                            true => *item = self.value.clone(),
                            false => self.apply_from(item, depth + 1)?,
                        }
                    }
                    return Ok(());
                }
                toml::Value::Array(a) => {
                    let n = a.len();
                    // An item by index, or by its `name` (`arm.left`).
                    let named = a.iter().position(|item| {
                        item.get("name").and_then(toml::Value::as_str) == Some(key.as_str())
                    });
                    let i: usize = match (key.parse(), named) {
                        (Ok(i), _) => i,
                        (Err(_), Some(i)) => i,
                        (Err(_), None) => {
                            return Err(err(format!(
                                "`{key}` is neither an index nor an item's name: this level is a list of {n} items, use 0 to {}, a name or * (every item)",
                                n.saturating_sub(1)
                            )));
                        }
                    };
                    let item = a.get_mut(i).ok_or_else(|| {
                        err(format!("index {i} is out of range: the list has {n} items"))
                    })?;
                    if last {
                        *item = self.value.clone();
                        return Ok(());
                    }
                    item
                }
                _ => {
                    let at = self.path[..depth].join(".");
                    return Err(err(format!(
                        "`{at}` is a value, not a table or list: `{key}` cannot be set inside it"
                    )));
                }
            };
        }
        Ok(())
    }
}
