//! Keeping `generated/` in step with `models/`: used by build.rs and by
//! `softarm derive`.
//!
//! Invariants: a model whose structural hash equals the one in its generated
//! file's header is not re-derived (unless forced); a file is written only
//! when its content changes; generated files without a model are removed.

use std::path::{Path, PathBuf};

use crate::derive::derive;
use crate::emit::{emit_model, hash_in_header};
use crate::load::load_model;
use crate::model::{ModelError, Structure};

#[derive(Clone, Debug, Default)]
pub struct SyncOptions {
    /// Re-derive every model, whatever its hash.
    pub force: bool,
    /// Write nothing; report what would change.
    pub check: bool,
    /// Reference model sources by absolute path (for output in OUT_DIR).
    pub absolute_paths: bool,
}

#[derive(Clone, Debug, Default)]
pub struct SyncReport {
    /// Models derived in this run.
    pub derived: Vec<String>,
    /// Files written (or, with `check`, that would be).
    pub written: Vec<PathBuf>,
    /// Files removed (or that would be).
    pub removed: Vec<PathBuf>,
}

impl SyncReport {
    pub fn is_clean(&self) -> bool {
        self.written.is_empty() && self.removed.is_empty()
    }
}

#[derive(Debug, thiserror::Error)]
pub enum GenerateError {
    #[error(transparent)]
    Model(#[from] ModelError),
    #[error("{path}: {message}")]
    Io { path: String, message: String },
}

fn io_err(path: &Path, e: std::io::Error) -> GenerateError {
    GenerateError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

/// Files of the output folder that are not a model's: the registry and
/// the crate root (hand-written).
const NOT_MODELS: [&str; 2] = ["mod", "lib"];

fn valid_stem(s: &str) -> bool {
    let mut chars = s.chars();
    if NOT_MODELS.contains(&s) {
        return false;
    }
    chars.next().is_some_and(|c| c.is_ascii_lowercase())
        && chars.all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
}

/// The model files of a directory, sorted.
pub fn model_files(models_dir: &Path) -> Result<Vec<PathBuf>, GenerateError> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(models_dir)
        .map_err(|e| io_err(models_dir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    Ok(files)
}

/// Bring `out_dir` in step with `models_dir`.
pub fn sync(
    models_dir: &Path,
    out_dir: &Path,
    opts: &SyncOptions,
) -> Result<SyncReport, GenerateError> {
    let mut report = SyncReport::default();
    let mut stems = Vec::new();
    if !opts.check {
        std::fs::create_dir_all(out_dir).map_err(|e| io_err(out_dir, e))?;
    }
    for path in model_files(models_dir)? {
        let stem = path
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or_default()
            .to_string();
        if !valid_stem(&stem) {
            return Err(GenerateError::Model(ModelError::new(
                &path.display().to_string(),
                "",
                "a compiled-in model's file name must be lower_snake_case (it names a Rust module), and not `mod` or `lib`",
            )));
        }
        let model = load_model(&path, &[])?;
        let hash = Structure::of(&model).hash();
        let target = out_dir.join(format!("{stem}.rs"));
        let existing = std::fs::read_to_string(&target).ok();
        let up_to_date = existing.as_deref().and_then(hash_in_header) == Some(hash.as_str());
        if opts.force || !up_to_date {
            let tapes = derive(&model);
            report.derived.push(stem.clone());
            let source = emit_model(&format!("models/{stem}.toml"), &tapes);
            write_if_changed(&target, existing.as_deref(), &source, opts, &mut report)?;
        }
        let files = data_files(&model, &path);
        stems.push(Entry { stem, path, files });
    }
    let registry = registry_source(&stems, opts.absolute_paths.then_some(out_dir));
    let mod_rs = out_dir.join("mod.rs");
    let existing = std::fs::read_to_string(&mod_rs).ok();
    write_if_changed(&mod_rs, existing.as_deref(), &registry, opts, &mut report)?;
    // Files whose model is gone.
    if let Ok(entries) = std::fs::read_dir(out_dir) {
        let mut stray: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "rs"))
            .filter(|p| {
                let s = p.file_stem().and_then(|s| s.to_str()).unwrap_or_default();
                !NOT_MODELS.contains(&s) && !stems.iter().any(|e| e.stem == s)
            })
            .collect();
        stray.sort();
        for p in stray {
            if !opts.check {
                std::fs::remove_file(&p).map_err(|e| io_err(&p, e))?;
            }
            report.removed.push(p);
        }
    }
    Ok(report)
}

fn write_if_changed(
    target: &Path,
    existing: Option<&str>,
    content: &str,
    opts: &SyncOptions,
    report: &mut SyncReport,
) -> Result<(), GenerateError> {
    if existing == Some(content) {
        return Ok(());
    }
    if !opts.check {
        // An interrupted build never leaves a half-written file.
        crate::atomic_write::write_atomic(target, content.as_bytes()).map_err(|e| {
            GenerateError::Io {
                path: target.display().to_string(),
                message: e.kind().to_string(),
            }
        })?;
    }
    report.written.push(target.to_path_buf());
    Ok(())
}

/// A compiled-in model: its module's name, its file, and the data files
/// it names (paths as written, relative to the model's folder).
struct Entry {
    stem: String,
    path: PathBuf,
    files: Vec<String>,
}

/// The files a model reads at run time (its CSV inputs and the record it
/// is compared with), with the README beside each (a data set's licence
/// notice travels with its copies), which the registry carries inside the
/// binary so that a copy of softarm runs its bundled models anywhere.
/// Absolute paths and files that do not exist are left to run time, which
/// names them in its error.
fn data_files(model: &crate::model::Model, path: &Path) -> Vec<String> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let named = model
        .inputs
        .values()
        .filter_map(|i| match i {
            crate::model::Input::Csv { file, .. } => Some(file.as_str()),
            _ => None,
        })
        .chain(model.compare.iter().map(|c| c.file.as_str()));
    let mut files = Vec::new();
    for file in named {
        let readme = Path::new(file).with_file_name("README.md");
        for f in [file.to_string(), readme.display().to_string()] {
            if !Path::new(&f).is_absolute() && dir.join(&f).is_file() && !files.contains(&f) {
                files.push(f);
            }
        }
    }
    files
}

/// `mod.rs`: the modules and the registry of compiled-in models.
/// With `absolute` (the output directory), modules and sources are named by
/// absolute path, as `include!` from OUT_DIR needs.
fn registry_source(stems: &[Entry], absolute: Option<&Path>) -> String {
    let mut s = String::from(
        "// @generated by eomgen: the compiled-in models. Do not edit.\n\n\
         use runtime::CompiledModel;\n\n",
    );
    for Entry { stem, .. } in stems {
        if let Some(dir) = absolute {
            s.push_str(&format!(
                "#[path = {:?}]\n",
                dir.join(format!("{stem}.rs")).display().to_string()
            ));
        }
        s.push_str(&format!(
            "#[allow(clippy::all, clippy::pedantic)]\npub mod {stem};\n"
        ));
    }
    s.push_str(
        "\n/// Every compiled-in model, by name.\npub static MODELS: &[CompiledModel] = &[\n",
    );
    for Entry { stem, path, files } in stems {
        // include_str! paths: relative to generated/, or absolute.
        let include = |rel: &str| {
            if absolute.is_some() {
                let p = path.parent().unwrap_or(Path::new(".")).join(rel);
                let abs = p.canonicalize().unwrap_or(p);
                format!("{:?}", abs.display().to_string())
            } else {
                format!("{:?}", format!("../models/{rel}"))
            }
        };
        let source = include(&format!("{stem}.toml"));
        let files: String = files
            .iter()
            .map(|f| format!("\n            ({f:?}, include_str!({})),", include(f)))
            .collect();
        let files = if files.is_empty() {
            files
        } else {
            format!("{files}\n        ")
        };
        s.push_str(&format!(
            "    CompiledModel {{\n        name: \"{stem}\",\n        hash: {stem}::HASH,\n        dof: {stem}::DOF,\n        source: include_str!({source}),\n        files: &[{files}],\n        kernels: || Box::new({stem}::Compiled::default()),\n        cells: {stem}::CELLS,\n        parts: {stem}::PART_KERNELS,\n    }},\n"
        ));
    }
    s.push_str("];\n");
    s
}
