//! Loading a model: TOML or JSON text, `--set` overrides, typed
//! deserialisation with key paths, then validation; and what a checked
//! model yields by asking each segment's method: its structure and its
//! parameter values.
//!
//! Above `method` in the layer order: `model` holds the file's data and
//! knows methods by name only; here their answers are used.

mod assembly_check;
mod contact_check;
mod load_check;
mod structure_of;
mod validate;
mod values;

use std::path::Path;

use crate::model::{Model, ModelError, Override};
use validate::validate;

pub use validate::MAX_ELEMENTS;
pub use values::{ElementProps, element_props, parameters, segment_stiffness};

/// Parse model text (TOML, or JSON when `json`), apply overrides, check.
pub fn parse_model(
    text: &str,
    file: &str,
    json: bool,
    overrides: &[Override],
) -> Result<Model, ModelError> {
    let tree = model_tree(text, file, json, overrides)?;
    let model: Model = serde_path_to_error::deserialize(tree).map_err(|e| {
        let path = e.path().to_string();
        let path = if path == "." { String::new() } else { path };
        let message = crate::model::with_suggestion(&e.into_inner().to_string());
        ModelError::new(file, path, message)
    })?;
    let mut model = model;
    validate(&model, file)?;
    // Checked, then cut.
    model.joints.retain(|j| j.active);
    Ok(model)
}

/// A model file's tree of keys with `overrides` applied, before the
/// typed reading: what `softarm fit` reads start values from and writes
/// fitted values into.
pub fn model_tree(
    text: &str,
    file: &str,
    json: bool,
    overrides: &[Override],
) -> Result<toml::Value, ModelError> {
    let mut tree: toml::Value = if json {
        serde_json::from_str(text)
            .map_err(|e| ModelError::new(file, "", format!("invalid JSON: {e}")))?
    } else {
        let table: toml::Table = toml::from_str(text).map_err(|e| {
            ModelError::new(
                file,
                "",
                format!("invalid TOML: {}", e.to_string().trim_end()),
            )
        })?;
        toml::Value::Table(table)
    };
    for o in overrides {
        o.apply(&mut tree)?;
    }
    Ok(tree)
}

/// Read a model file (`.json` is read as JSON, anything else as TOML).
pub fn load_model(path: &Path, overrides: &[Override]) -> Result<Model, ModelError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| ModelError::new(&file, "", format!("cannot read the file: {e}")))?;
    let json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    parse_model(&text, &file, json, overrides)
}
