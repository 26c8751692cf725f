//! From a MODEL argument to runnable dynamics: find the model (a file, or
//! the name of a compiled-in model), apply overrides, and pick the backend.
//!
//! The compiled backend is used whenever a compiled-in model has the same
//! structural hash (numeric overrides keep it); otherwise the model is
//! derived into tapes and interpreted, through the disk cache.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use eomgen::load::parse_model;
use eomgen::model::{Model, Override, ParamLayout, Structure};
use runtime::assembled::BlockKernels;
use runtime::linked::LinkedKernels;
use runtime::linked_parts::LinkedPartKernels;
use runtime::links::{CompiledCell, LinkKernels};
use runtime::parts::{CompiledPart, PartKernels};
use runtime::{Arm, CompiledModel, Dynamics, Interpreted, Kernels, TapeSet};
use serde::Serialize;

use crate::cache;
use crate::generated::MODELS;

/// Which backend to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, Default)]
pub enum BackendChoice {
    /// Compiled when a compiled-in model has this structure, else interpreted.
    #[default]
    Auto,
    Compiled,
    Interpreted,
}

/// Whether the tape cache was used.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum CacheStatus {
    /// Compiled backend: no tape needed.
    Unused,
    Hit,
    Miss,
    /// Compiled link cells of another model's, linked to this chain's
    /// layout (`runtime::linked::LinkedKernels`): no tape needed but, for
    /// their contact kernels, an assembly's and an arm's whose contact
    /// points are off its links' arcs (from the cache or derived into it).
    Linked,
}

pub struct Loaded {
    pub model: Model,
    /// Where the model came from (a path or `compiled-in:<name>`).
    pub origin: String,
    pub hash: String,
    pub arm: Box<dyn Dynamics>,
    /// The folder that paths in the model file are relative to.
    pub base_dir: PathBuf,
    pub cache: CacheStatus,
    /// Time spent deriving (0 when compiled or cached).
    pub derive_s: f64,
    /// Why the kernels are the ones they are (compiled in, linked cells,
    /// or the interpreter and what a compiled route lacked).
    pub route: String,
}

pub fn compiled_by_name(name: &str) -> Option<&'static CompiledModel> {
    MODELS.iter().find(|m| m.name == name)
}

pub fn compiled_by_hash(hash: &str) -> Option<&'static CompiledModel> {
    MODELS.iter().find(|m| m.hash == hash)
}

/// The folder paths in a model are relative to: the model file's, or for
/// a compiled-in model the files compiled in with it (`data::read_text`),
/// never the checkout it was built in.
pub fn base_dir(spec: &str) -> PathBuf {
    let path = Path::new(spec);
    if path.exists() {
        path.parent()
            .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
    } else {
        crate::data::compiled_in_base(spec)
    }
}

/// A model's text as written: the file named by `spec`, or a compiled-in
/// model's source; whether it is JSON, and its label for messages.
pub struct Source {
    pub text: String,
    pub json: bool,
    pub label: String,
}

/// The text of the model named by `spec`: a file path, or a compiled-in
/// model's name.
pub fn model_source(spec: &str) -> Result<Source> {
    let path = Path::new(spec);
    if path.exists() {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("{spec}: cannot read the file"))?;
        let json = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"));
        return Ok(Source {
            text,
            json,
            label: spec.to_string(),
        });
    }
    if let Some(m) = compiled_by_name(spec) {
        return Ok(Source {
            text: m.source.to_string(),
            json: false,
            label: format!("compiled-in:{}", m.name),
        });
    }
    let names: Vec<&str> = MODELS.iter().map(|m| m.name).collect();
    bail!(
        "{spec}: no such model file, and no compiled-in model of that name (compiled in: {})",
        names.join(", ")
    )
}

/// Read the model named by `spec`: a file path, or a compiled-in model's name.
pub fn read_model(spec: &str, overrides: &[Override]) -> Result<(Model, String)> {
    let src = model_source(spec)?;
    let model = parse_model(&src.text, &src.label, src.json, overrides)?;
    Ok((model, src.label))
}

/// A chain whose element count (or rom order) no compiled-in model has, on
/// the compiled cells of its link shapes when every one is compiled in
/// (found by key), with the seconds its layout took to derive; or why it
/// cannot run so. Its contact kernels are the recursion's where its points
/// lie on its links' arcs, else its tapes' ([`tapes`]: the cache's, else
/// derived and cached); an assembly
/// its arms' kernels so (their contact points too, and the frames its
/// joints hold), and the rest (the bodies, their contact points, the
/// joints' rows on those frames) by its tapes
/// (`runtime::assembled::BlockKernels`).
fn linked(
    model: &Model,
    structure: &Structure,
    cache_dir: &Path,
) -> std::result::Result<(Box<dyn Kernels>, f64, String), String> {
    if !runtime::cpu::has_fma() {
        return Err("this processor lacks the fused multiply-add compiled code needs".into());
    }
    let start = Instant::now();
    let not_cells = || "not every one of its methods' elements is a link cell".to_string();
    let kernels: (Box<dyn Kernels>, String) = if structure.assembly.is_some() {
        let (tapes, _, _) = tapes(model, &structure.hash(), cache_dir);
        let blocks = tapes.arm_blocks.as_ref().ok_or_else(|| {
            "its arms run on the assembly's kernels (an arm has a compliant base or sits on another arm or a body)"
                .to_string()
        })?;
        let cells = (blocks.kinds.iter())
            .map(|kind| Ok(compiled_cells(kind.links.as_ref().ok_or_else(not_cells)?)))
            .collect::<std::result::Result<Vec<_>, String>>()?;
        let joints = match (&blocks.joints, tapes.info.constraints.is_empty()) {
            (Some(_), _) => ", its joints' rows on the arms' frames",
            (None, false) => ", its joints too",
            (None, true) => "",
        };
        let note = format!("{joints}{}", taped(cells.iter().flatten()));
        let kinds = (blocks.kinds.iter().zip(cells))
            .map(|(kind, cells)| {
                let arm = LinkedKernels::with_tapes(kind.clone(), cells).ok_or_else(not_cells)?;
                Ok(Box::new(arm) as Box<dyn Kernels>)
            })
            .collect::<std::result::Result<Vec<_>, String>>()?;
        (
            Box::new(BlockKernels::new(tapes, kinds).ok_or_else(not_cells)?),
            note,
        )
    } else if let Some((info, parts)) = eomgen::derive::derive_parts(structure) {
        let compiled = compiled_parts(&parts);
        let k = compiled.iter().filter(|c| c.is_none()).count();
        let note = format!(
            ", its elements parts of {} kinds, {k} on their tapes",
            compiled.len()
        );
        (
            Box::new(LinkedPartKernels::new(info, parts, compiled)),
            note,
        )
    } else if let Some((info, links)) = eomgen::derive::derive_links(structure) {
        // Contact too, where its points lie on the links' arcs.
        let cells = compiled_cells(&links);
        let note = taped(&cells);
        (Box::new(LinkedKernels::new(info, links, cells)), note)
    } else if structure.contact_points > 0 {
        let (tapes, _, _) = tapes(model, &structure.hash(), cache_dir);
        let cells = compiled_cells(tapes.links.as_ref().ok_or_else(not_cells)?);
        // Its points are not all on the links' arcs (a rigid chain's).
        let note = format!(", its contact kernels interpreted{}", taped(&cells));
        (
            Box::new(LinkedKernels::with_tapes(tapes, cells).ok_or_else(not_cells)?),
            note,
        )
    } else {
        return Err(eomgen::derive::why_not_linked(structure));
    };
    let (kernels, note) = kernels;
    Ok((kernels, start.elapsed().as_secs_f64(), note))
}

/// The compiled cells of a chain's link shapes, found by key among the
/// compiled-in models' cells; None for a shape no compiled-in model has,
/// whose tapes then run.
fn compiled_cells(links: &LinkKernels) -> Vec<Option<CompiledCell>> {
    let found = |key: String| MODELS.iter().flat_map(|m| m.cells).find(|c| c.key == key);
    (links.cells.iter().zip(&links.tangents).zip(&links.poses))
        .map(|((cell, tangent), pose)| {
            found(eomgen::build::kernel_key(&[cell, tangent, pose])).copied()
        })
        .collect()
}

/// The compiled part kernels of a system's kinds of parts, found by key
/// among the compiled-in models'; None for a kind no compiled-in model
/// has, whose tapes then run.
fn compiled_parts(parts: &PartKernels) -> Vec<Option<CompiledPart>> {
    let found = |key: String| MODELS.iter().flat_map(|m| m.parts).find(|c| c.key == key);
    (parts.kernels.iter().zip(&parts.tangents))
        .map(|(kernel, tangent)| found(eomgen::build::kernel_key(&[kernel, tangent])).copied())
        .collect()
}

/// What of a chain's cells (or an assembly's arms' cells) runs on tapes,
/// for the route: empty when all are compiled in.
fn taped<'a>(cells: impl IntoIterator<Item = &'a Option<CompiledCell>>) -> String {
    let (mut k, mut total) = (0, 0);
    for c in cells {
        total += 1;
        k += usize::from(c.is_none());
    }
    match k {
        0 => String::new(),
        _ => format!(
            "; {k} of its {total} link shapes {} in no compiled-in model and {} on {} tapes \
             (add the file to models/ and `cargo build --release` to compile {})",
            if k == 1 { "is" } else { "are" },
            if k == 1 { "runs" } else { "run" },
            if k == 1 { "its" } else { "their" },
            if k == 1 { "it" } else { "them" },
        ),
    }
}

/// A model's tapes: the cache's in `dir`, else derived and stored there;
/// whether the cache had them, and the seconds the derivation took.
/// The model's tapes: from the cache in `dir`, or derived into it.
pub fn tapes(model: &Model, hash: &str, dir: &Path) -> (TapeSet, CacheStatus, f64) {
    if let Some(tapes) = cache::load(dir, hash) {
        return (tapes, CacheStatus::Hit, 0.0);
    }
    let start = Instant::now();
    let tapes = eomgen::derive::derive(model);
    let derive_s = start.elapsed().as_secs_f64();
    if let Err(e) = cache::store(dir, &tapes) {
        eprintln!("warning: {e}");
    }
    (tapes, CacheStatus::Miss, derive_s)
}

/// A viscoelastic model's relaxing groups: each segment with a Prony
/// series, by its elements' stiffness parameters.
pub(crate) fn relaxation(
    model: &Model,
    layout: &ParamLayout,
) -> Option<runtime::relaxation::Relaxation> {
    let groups: Vec<_> = (model.segments.iter().enumerate())
        .filter(|(_, s)| !s.relaxation.is_empty())
        .map(|(i, s)| runtime::relaxation::Group {
            stiffness: eomgen::load::segment_stiffness(layout, model, i),
            branches: (s.relaxation.iter())
                .map(|r| runtime::relaxation::Branch {
                    ratio: r.ratio,
                    time: r.time,
                })
                .collect(),
        })
        .collect();
    (!groups.is_empty()).then_some(runtime::relaxation::Relaxation { groups })
}

/// Load a model and bind its parameters to the chosen backend.
pub fn load(
    spec: &str,
    overrides: &[Override],
    choice: BackendChoice,
    cache_dir: Option<PathBuf>,
) -> Result<Loaded> {
    let (model, origin) = read_model(spec, overrides)?;
    if crate::continuum::is_cosserat(&model) {
        bail!(
            "{origin}: segment.method: \"cosserat\" is solved as a static boundary value problem: run `softarm static` with it, or choose pcc, vc, ebr or rigid for the dynamics"
        );
    }
    let structure = Structure::of(&model);
    let hash = structure.hash();
    let layout = ParamLayout::of(&structure);
    // Compiled kernels use fused multiply-adds; without them the
    // interpreter gives the same bits.
    let compiled = compiled_by_hash(&hash);
    if choice == BackendChoice::Compiled && compiled.is_some() && !runtime::cpu::has_fma() {
        bail!(
            "{origin}: the compiled kernels need a processor with fused multiply-add (FMA3),              which this one lacks; use --backend interpreted (the same results, slower)"
        );
    }
    let compiled = compiled.filter(|_| runtime::cpu::has_fma());
    let wanted_compiled = matches!(choice, BackendChoice::Auto | BackendChoice::Compiled);
    let dir = cache_dir.unwrap_or_else(cache::default_dir);
    let linked = match compiled {
        None if wanted_compiled => Some(linked(&model, &structure, &dir)),
        _ => None,
    };
    let route = match (&compiled, &linked) {
        (Some(c), _) if wanted_compiled => format!("compiled in as {}", c.name),
        (_, Some(Ok((_, _, note)))) if structure.assembly.is_some() => format!(
            "compiled link cells of bundled models, linked to each arm's layout, the rest of \
             the assembly interpreted{note}"
        ),
        (_, Some(Ok((_, _, note)))) => {
            format!("compiled link cells of bundled models, linked to its layout{note}")
        }
        (_, Some(Err(why))) => format!(
            "no compiled-in model has this structure and {why}: add the file to models/ and \
             `cargo build --release` to compile it in"
        ),
        _ => "the interpreter, as asked".into(),
    };
    let (kernels, cache, derive_s): (Box<dyn Kernels>, CacheStatus, f64) = match (choice, compiled)
    {
        (BackendChoice::Auto | BackendChoice::Compiled, None)
            if let Some(Ok((k, s, _))) = linked =>
        {
            (k, CacheStatus::Linked, s)
        }
        (BackendChoice::Compiled, None) => {
            bail!("{origin} (hash {hash}): {route}; or use --backend interpreted")
        }
        (BackendChoice::Auto | BackendChoice::Compiled, Some(c)) => {
            ((c.kernels)(), CacheStatus::Unused, 0.0)
        }
        _ => {
            let (tapes, cache, derive_s) = tapes(&model, &hash, &dir);
            (Box::new(Interpreted::new(tapes)), cache, derive_s)
        }
    };
    // The kernels' metadata names their layout: it must be this one.
    if kernels.info().parameters != layout.names() {
        bail!(
            "{origin}: the {} kernels do not match this generator's parameter layout; \
             run `softarm derive` (or `cargo build`) to regenerate",
            kernels.backend()
        );
    }
    let values = layout.values(&model);
    let mut arm = Arm::boxed(kernels, values);
    let base_dir = base_dir(spec);
    let drives = crate::inputs::model_drives(&model, &layout, &base_dir)
        .with_context(|| format!("{origin}: reading the input channels"))?;
    arm.set_drives(drives);
    let contact = crate::contact::contact_set(&model, &base_dir, arm.info().contact_points)
        .with_context(|| format!("{origin}: contact"))?;
    arm.set_contact(contact);
    arm.set_relaxation(relaxation(&model, &layout));
    Ok(Loaded {
        model,
        origin,
        hash,
        arm,
        base_dir,
        cache,
        derive_s,
        route,
    })
}
