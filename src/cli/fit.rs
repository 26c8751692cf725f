//! `softarm fit`: the command line of `crate::fit`.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;
use clap::Args;
use eomgen::model::Override;

use crate::fit::{self, Free, Validation, lm};
use crate::run::RunRequest;

#[derive(Args, Clone)]
pub struct FitArgs {
    /// A model file with a [compare] record, or a compiled-in model's name.
    pub model: String,
    /// A value to fit, as --set names it, with optional bounds:
    /// PATH or PATH=LO:HI (either bound may be empty). Repeat for each.
    #[arg(long = "free", value_name = "PATH[=LO:HI]", required = true)]
    pub free: Vec<String>,
    /// Fit on the samples between A and B seconds [default: [compare]
    /// window, else the whole record].
    #[arg(long, value_name = "A:B")]
    pub window: Option<String>,
    /// Report the error on data the fit did not see: a window A:B of the
    /// same record, or another model file (another record of the arm).
    #[arg(long, value_name = "A:B|MODEL")]
    pub validate: Option<String>,
    /// Override a model value first: PATH=VALUE.
    #[arg(long = "set", value_name = "PATH=VALUE")]
    pub set: Vec<String>,
    /// Relative tolerance of the runs [default: simulate.rtol, else 1e-6].
    #[arg(long)]
    pub rtol: Option<f64>,
    /// Absolute tolerance of the runs [default: simulate.atol, else 1e-9].
    #[arg(long)]
    pub atol: Option<f64>,
    /// Most Levenberg-Marquardt iterations.
    #[arg(long, default_value_t = lm::Options::default().max_iterations)]
    pub max_iterations: usize,
    /// Output directory (default out/<model name>-fit).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Directory of the tape cache (default: $SOFTARM_CACHE_DIR or .softarm-cache).
    #[arg(long, value_name = "DIR")]
    pub cache_dir: Option<PathBuf>,
    /// No line per iteration.
    #[arg(long)]
    pub quiet: bool,
}

pub fn fit(a: FitArgs) -> Result<ExitCode> {
    let req = fit::Request {
        model: a.model.clone(),
        overrides: (a.set.iter())
            .map(|s| Override::parse(s))
            .collect::<Result<Vec<_>, _>>()?,
        free: (a.free.iter())
            .map(|s| Free::parse(s))
            .collect::<Result<Vec<_>>>()?,
        window: a
            .window
            .as_deref()
            .map(|s| fit::parse_window("--window", s))
            .transpose()?,
        validate: a.validate.as_deref().map(Validation::parse).transpose()?,
        run: RunRequest {
            rtol: a.rtol,
            atol: a.atol,
            ..RunRequest::default()
        },
        cache_dir: a.cache_dir.clone(),
        lm: lm::Options {
            max_iterations: a.max_iterations,
            stop: Some(|| crate::interrupt::requested().is_some()),
            ..lm::Options::default()
        },
    };
    // Ctrl-C or SIGTERM ends the search with the best values so far
    // written.
    crate::interrupt::catch();
    // Checked before anything is written.
    let prepared = fit::prepare(&req)?;
    let out_dir = (a.out.clone())
        .unwrap_or_else(|| PathBuf::from("out").join(format!("{}-fit", model_name(&a.model))));
    let mut dir = crate::output_dir::OutputDir::claim(&out_dir)?;
    let quiet = a.quiet;
    let mut progress = |k: usize, mean: f64| {
        if !quiet {
            eprintln!("fit: iteration {k}: mean tip error {:.4} mm", 1e3 * mean);
        }
    };
    let f = prepared.fit(&req.lm, &mut progress)?;
    fit::report::write(&mut dir, &prepared.problem, &f, prepared.shaded())?;
    if !quiet {
        print_table(&f);
        println!("wrote {}", out_dir.display());
    }
    if let Some(stop) = crate::interrupt::requested().filter(|_| f.interrupted) {
        eprintln!(
            "fit: stopped by {} after {} iterations; the best values so far are in {}",
            stop.name(),
            f.iterations,
            out_dir.join("fit.json").display()
        );
        return Ok(ExitCode::from(stop.exit_code()));
    }
    Ok(ExitCode::SUCCESS)
}

/// The model's name for the default folder: a file's stem, or the name.
fn model_name(spec: &str) -> String {
    std::path::Path::new(spec)
        .file_stem()
        .map_or_else(|| spec.to_string(), |s| s.to_string_lossy().into_owned())
}

fn print_table(f: &fit::Fitted) {
    println!(
        "{:<40} {:>14} {:>14} {:>12}",
        "value", "start", "fitted", "std error"
    );
    for (k, n) in f.names.iter().enumerate() {
        println!(
            "{n:<40} {:>14.6e} {:>14.6e} {:>12.3e}",
            f.initial[k], f.values[k], f.std_error[k]
        );
    }
    let c = &f.fit_cost;
    println!(
        "mean tip error on {}..{} s ({} samples): {:.3} mm -> {:.3} mm",
        c.window_s[0],
        c.window_s[1],
        c.samples,
        1e3 * c.initial,
        1e3 * c.fitted
    );
    if let Some(v) = &f.validation_cost {
        println!(
            "validation on {}..{} s ({} samples): {:.3} mm -> {:.3} mm",
            v.window_s[0],
            v.window_s[1],
            v.samples,
            1e3 * v.initial,
            1e3 * v.fitted
        );
    }
    println!(
        "{} iterations, {} evaluations, {:.1} s: {}",
        f.iterations, f.evaluations, f.wall_s, f.status
    );
    for n in &f.at_bound {
        println!("warning: {n} ended on a bound");
    }
    for (a, b, c) in &f.inseparable {
        println!("warning: {a} and {b}: correlation {c:.4}: the data cannot separate them");
    }
}
