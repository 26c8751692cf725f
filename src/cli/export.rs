//! `softarm export`: a model's equations for use outside softarm.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;
use clap::Args;
use eomgen::model::Override;

#[derive(Args)]
pub struct ExportArgs {
    /// A model file (TOML or JSON) or the name of a compiled-in model.
    pub model: String,
    /// Override a model value: PATH=VALUE (the exported defaults).
    #[arg(long = "set", value_name = "PATH=VALUE")]
    pub set: Vec<String>,
    /// Write a C99 library (DIR/<model>.h and DIR/<model>.c) into DIR.
    #[arg(long = "c", value_name = "DIR")]
    pub c: Option<PathBuf>,
    /// Write an FMI 2.0 model-exchange FMU (sources and a binary for this
    /// platform, built by the C compiler `cc` or $CC).
    #[arg(long, value_name = "FILE.fmu")]
    pub fmu: Option<PathBuf>,
    /// Write a MATLAB/Octave MEX function's sources and `.m` wrappers into
    /// DIR (compile them with DIR/<model>_build.m).
    #[arg(long, value_name = "DIR")]
    pub mex: Option<PathBuf>,
    /// Directory of the tape cache (default: $SOFTARM_CACHE_DIR or .softarm-cache).
    #[arg(long, value_name = "DIR")]
    pub cache_dir: Option<PathBuf>,
}

/// `softarm export MODEL --c DIR`.
pub fn export(a: ExportArgs) -> Result<ExitCode> {
    let overrides = (a.set.iter())
        .map(|s| Override::parse(s))
        .collect::<Result<Vec<_>, _>>()?;
    let targets = crate::export::Targets {
        c: a.c,
        fmu: a.fmu,
        mex: a.mex,
    };
    let out = crate::export::export(&a.model, &overrides, &targets, a.cache_dir)?;
    for f in &out.files {
        println!("wrote {}", f.display());
    }
    println!(
        "{} coordinates, {} joint rows; C names start with {}_",
        out.dof, out.constraints, out.prefix
    );
    for (i, name) in &out.inputs {
        println!(
            "  input-driven parameter {i} ({name}): set it each step with {}_set_parameter",
            out.prefix
        );
    }
    Ok(ExitCode::SUCCESS)
}
