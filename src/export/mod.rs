//! `softarm export MODEL --c DIR`: a model's equations as a self-contained
//! C99 library (one header, one source, libm alone), for controllers,
//! Simulink S-functions and anything else that links C.
//!
//! The kernels are the model's tapes, each a C function running the
//! interpreter's operations in its order (`c_tape`); a chain of link cells
//! is its cells' tapes and the link recursion (`c_links`); the state derivative
//! solves M qdd = -h by L D L^T (and the joints' rows by their Schur
//! complement, as `runtime::constraints`), its Jacobian comes column by
//! column from the inverse dynamics' directional derivative, as the
//! runtime's. Contact (`c_contact`) subtracts J^T f from h as the runtime
//! does. docs/export.md is the user's guide.

mod c_api;
mod c_contact;
mod c_links;
mod c_tape;
mod fmu;
mod mex;

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use eomgen::model::{Override, ParamLayout, Structure};

use crate::backend;

/// What an export writes: the C library into a folder, an FMU file, or
/// both.
#[derive(Debug, Default)]
pub struct Targets {
    pub c: Option<PathBuf>,
    pub fmu: Option<PathBuf>,
    /// A folder for the MATLAB/Octave MEX sources and `.m` wrappers.
    pub mex: Option<PathBuf>,
}

/// What an export wrote.
#[derive(Debug)]
pub struct CExport {
    /// The C identifier prefix of every name the library declares.
    pub prefix: String,
    /// The files written, in order.
    pub files: Vec<PathBuf>,
    pub dof: usize,
    pub constraints: usize,
    /// The parameters that inputs drive: (index, name), set by the caller
    /// at each step.
    pub inputs: Vec<(usize, String)>,
}

/// Export the model `spec` (a name or file, with `--set` overrides) as C
/// into `dir` (created if missing; nothing else in it is touched).
pub fn export_c(
    spec: &str,
    overrides: &[Override],
    dir: &Path,
    cache_dir: Option<PathBuf>,
) -> Result<CExport> {
    let targets = Targets {
        c: Some(dir.to_path_buf()),
        ..Default::default()
    };
    export(spec, overrides, &targets, cache_dir)
}

/// Export the model `spec` to `targets`; a model the export cannot carry
/// is refused before anything is written.
pub fn export(
    spec: &str,
    overrides: &[Override],
    targets: &Targets,
    cache_dir: Option<PathBuf>,
) -> Result<CExport> {
    if targets.c.is_none() && targets.fmu.is_none() && targets.mex.is_none() {
        bail!(
            "export: say what to write: --c DIR (a C library), --fmu FILE.fmu (an FMU) or \
             --mex DIR (a MATLAB/Octave MEX function)"
        );
    }
    let (model, origin) = backend::read_model(spec, overrides)?;
    if crate::continuum::is_cosserat(&model) {
        bail!(
            "{origin}: segment.method: \"cosserat\" is solved as a boundary value problem, which \
             has no equations of motion to export; choose pcc, vc, ebr, eba, rom, pcs or rigid"
        );
    }
    let structure = Structure::of(&model);
    let base = backend::base_dir(spec);
    let hash = structure.hash();
    let layout = ParamLayout::of(&structure);
    let (tapes, _, _) = backend::tapes(
        &model,
        &hash,
        &cache_dir.unwrap_or_else(crate::cache::default_dir),
    );
    if tapes.info.parameters != layout.names() {
        bail!("{origin}: the cached kernels do not match this generator's parameter layout");
    }
    let values = layout.values(&model);
    let contact = crate::contact::contact_set(&model, &base, tapes.info.contact_points)
        .with_context(|| format!("{origin}: contact"))?;
    if let Some(why) = contact.as_ref().and_then(c_contact::refusal) {
        bail!("{origin}: {why}");
    }
    let drives = crate::inputs::model_drives(&model, &layout, &base)
        .with_context(|| format!("{origin}: reading the input channels"))?;
    let inputs: Vec<(usize, String)> = (drives.iter())
        .map(|d| (d.param, tapes.info.parameters[d.param].clone()))
        .collect();
    let shape = eomgen::shape::shape_tape(&structure, 1);
    let relax = backend::relaxation(&model, &layout);
    // A chain whose full derivation keeps flat kernels but whose every
    // element is a link cell (a kink, say) still exports as its cells: the
    // linked route's own derivation, on the same base parameters.
    let derived_links = match (&tapes.links, contact.is_some()) {
        (None, false) => eomgen::derive::derive_links(&structure)
            .filter(|(info, _)| info.parameters == tapes.info.parameters)
            .map(|(_, links)| links),
        _ => None,
    };
    let links = c_links::Links::of(&tapes)
        .or_else(|| (derived_links.as_ref()).and_then(|l| c_links::Links::new(l, tapes.info.dof())))
        .map(|l| l.with_shape(shape.tape.outputs.len() / eomgen::shape::ROW))
        .map(|l| {
            let alone = tapes.info.constraints.is_empty() && relax.is_none() && contact.is_none();
            l.with_articulated(alone)
        });
    let prefix = c_api::identifier(&model.name);
    let library = c_api::Library {
        prefix: &prefix,
        model: &model.name,
        hash: &hash,
        tapes: &tapes,
        values: &values,
        inputs: &inputs,
        shape: &shape.tape,
        relax: relax.as_ref(),
        contact: (contact.as_ref()).map(|set| c_contact::Contact::new(set, &tapes.info)),
        links,
    };
    let mut files = Vec::new();
    if let Some(dir) = &targets.c {
        let set = [
            (format!("{prefix}.h"), library.header()),
            (format!("{prefix}.c"), library.source()),
        ];
        files.extend(write_set(dir, &set)?);
    }
    if let Some(dir) = &targets.mex {
        files.extend(mex::write(&library, dir)?);
    }
    if let Some(path) = &targets.fmu {
        // The build folder sits beside the FMU and goes, success or not.
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or("model.fmu");
        let build = path.with_file_name(format!(".{name}.build-{}", std::process::id()));
        let written = fmu::write(&library, path, &build);
        let _ = std::fs::remove_dir_all(&build);
        written?;
        files.push(path.clone());
    }
    Ok(CExport {
        prefix,
        files,
        dof: tapes.info.dof(),
        constraints: tapes.info.constraints.len(),
        inputs,
    })
}

/// Write a set of files that belong together (a header and its source, a
/// MEX function's sources and wrappers) into `dir`, all or none: each is
/// written beside its target first, then all are moved in. A failure
/// takes back what this call put in place and leaves the folder's earlier
/// files as they were, except one it had already replaced.
fn write_set(dir: &Path, files: &[(String, String)]) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let staged: Vec<(PathBuf, PathBuf)> = files
        .iter()
        .map(|(name, _)| {
            let target = dir.join(name);
            let tmp = dir.join(format!(".{name}.tmp{}", std::process::id()));
            (tmp, target)
        })
        .collect();
    let clean = |from: usize| {
        for (tmp, _) in &staged[from..] {
            let _ = std::fs::remove_file(tmp);
        }
    };
    for ((tmp, target), (_, text)) in staged.iter().zip(files) {
        if let Err(e) = std::fs::write(tmp, text) {
            clean(0);
            return Err(e).with_context(|| format!("writing {}", target.display()));
        }
    }
    for (k, (tmp, target)) in staged.iter().enumerate() {
        if let Err(e) = std::fs::rename(tmp, target) {
            for (_, done) in &staged[..k] {
                let _ = std::fs::remove_file(done);
            }
            clean(k);
            return Err(e).with_context(|| {
                format!(
                    "writing {} (nothing of this export is left)",
                    target.display()
                )
            });
        }
    }
    Ok(staged.into_iter().map(|(_, target)| target).collect())
}
