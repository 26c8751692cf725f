//! The CLI's commands. Errors go to stderr with a non-zero exit; JSON to
//! stdout.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use crate::backend::{self, BackendChoice, Loaded};
use crate::compare;
use crate::generated::MODELS;
use crate::run::RunRequest;
use crate::run_output::{Kept, RunOutput};
use anyhow::{Context, Result, bail};
use clap::Args;
use eomgen::atomic_write::write_atomic;
use eomgen::model::{Override, SimulateDefaults, Start};
use nalgebra::{DMatrix, DVector};
use runtime::{Dynamics, KernelKind, SimOptions, Solver, Trajectory, Workspace, accelerations};
use serde_json::json;

/// Options shared by every command that takes a model.
#[derive(Args, Clone)]
pub struct ModelArgs {
    /// A model file (TOML or JSON) or the name of a compiled-in model.
    pub model: String,
    /// Override a model value: PATH=VALUE, e.g. segment.0.length=0.25 or tip.force=[0,-2,0].
    #[arg(long = "set", value_name = "PATH=VALUE")]
    pub set: Vec<String>,
    /// Backend: compiled when available (auto), or force one.
    #[arg(long, value_enum, default_value_t = BackendChoice::Auto)]
    pub backend: BackendChoice,
    /// Directory of the tape cache (default: $SOFTARM_CACHE_DIR or .softarm-cache).
    #[arg(long, value_name = "DIR")]
    pub cache_dir: Option<PathBuf>,
}

/// The model the arguments name, with their overrides, on its backend.
pub fn load(a: &ModelArgs) -> Result<Loaded> {
    let overrides = a
        .set
        .iter()
        .map(|s| Override::parse(s))
        .collect::<Result<Vec<_>, _>>()?;
    backend::load(&a.model, &overrides, a.backend, a.cache_dir.clone())
}

/// Parse a comma-separated vector of `n` numbers for option `name`.
fn parse_vector(name: &str, s: &str, n: usize, coords: &[String]) -> Result<Vec<f64>> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("{name}: expected comma-separated numbers, got `{s}`"))?;
    if v.len() != n {
        bail!(
            "{name}: expected {n} values (one per coordinate: {}), got {}",
            coords.join(", "),
            v.len()
        );
    }
    if let Some(x) = v.iter().find(|x| !x.is_finite()) {
        bail!("{name}: values must be finite, got {x}");
    }
    Ok(v)
}

fn optional_vector(
    name: &str,
    s: &Option<String>,
    n: usize,
    coords: &[String],
) -> Result<Vec<f64>> {
    match s {
        Some(s) => parse_vector(name, s, n, coords),
        None => Ok(vec![0.0; n]),
    }
}

pub fn list(json: bool) -> Result<ExitCode> {
    if json {
        let items: Vec<_> = MODELS
            .iter()
            .map(|m| json!({"name": m.name, "dof": m.dof, "hash": m.hash}))
            .collect();
        println!("{}", serde_json::to_string_pretty(&items)?);
    } else {
        println!("{:<24} {:>5}  hash", "model", "dof");
        for m in MODELS {
            println!("{:<24} {:>5}  {}", m.name, m.dof, m.hash);
        }
    }
    Ok(ExitCode::SUCCESS)
}

#[derive(Args)]
pub struct DeriveArgs {
    /// Derive these models (files or compiled-in names) into the tape cache
    /// and report their size, instead of syncing generated/.
    pub models: Vec<String>,
    /// Do not write: exit non-zero if generated/ is not what the models give.
    #[arg(long)]
    pub check: bool,
    /// Re-derive every model even when its structural hash is unchanged.
    #[arg(long)]
    pub force: bool,
    /// Project root holding models/ and generated/.
    #[arg(long, default_value = ".")]
    pub root: PathBuf,
}

pub fn derive(a: DeriveArgs) -> Result<ExitCode> {
    if !a.models.is_empty() {
        for spec in &a.models {
            let (model, origin) = backend::read_model(spec, &[])?;
            let start = Instant::now();
            let tapes = eomgen::derive::derive(&model);
            let s = start.elapsed().as_secs_f64();
            crate::cache::store(&crate::cache::default_dir(), &tapes)
                .map_err(anyhow::Error::msg)?;
            println!(
                "{origin}: dof {}, mass + bias {} ops, derived in {:.3} s (hash {})",
                tapes.info.dof(),
                tapes.mass_bias.op_count(),
                s,
                tapes.info.hash
            );
        }
        return Ok(ExitCode::SUCCESS);
    }
    let models = a.root.join("models");
    let generated = a.root.join("generated");
    // A check re-derives everything: a stale file with a current hash
    // (generator changed without a version bump) is caught too.
    let opts = eomgen::generate::SyncOptions {
        force: a.force || a.check,
        check: a.check,
        absolute_paths: false,
    };
    let report = eomgen::generate::sync(&models, &generated, &opts)?;
    if a.check {
        if report.is_clean() {
            println!(
                "generated/ is current ({} models checked)",
                report.derived.len()
            );
            return Ok(ExitCode::SUCCESS);
        }
        for p in &report.written {
            eprintln!("stale: {}", p.display());
        }
        for p in &report.removed {
            eprintln!("stray: {} (its model is gone)", p.display());
        }
        eprintln!("error: generated/ is out of date: run `softarm derive` and commit the result");
        return Ok(ExitCode::FAILURE);
    }
    println!(
        "derived {} model(s), wrote {} file(s), removed {}",
        report.derived.len(),
        report.written.len(),
        report.removed.len()
    );
    Ok(ExitCode::SUCCESS)
}

#[derive(Args, Clone)]
pub struct SimulateArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// End time (s) [default: the model's simulate.t_end, else 5].
    #[arg(long, allow_negative_numbers = true)]
    pub t_end: Option<f64>,
    /// Integrator [default: the model's simulate.solver, else auto].
    #[arg(long, value_parser = Solver::NAMES)]
    pub solver: Option<String>,
    /// Step of fixed-step solvers (s) [default: simulate.dt, else 1e-3].
    #[arg(long, allow_negative_numbers = true)]
    pub dt: Option<f64>,
    /// Relative tolerance [default: simulate.rtol, else 1e-6].
    #[arg(long, allow_negative_numbers = true)]
    pub rtol: Option<f64>,
    /// Absolute tolerance [default: simulate.atol, else 1e-9].
    #[arg(long, allow_negative_numbers = true)]
    pub atol: Option<f64>,
    /// Give up after this many steps (accepted and rejected).
    #[arg(long, default_value_t = SimOptions::default().max_steps)]
    pub max_steps: usize,
    /// genalpha's spectral radius at infinity, in [0, 1]: how much of a
    /// mode far above the step's resolution survives a step [default:
    /// simulate.rho_inf, else 0.8].
    #[arg(long)]
    pub rho_inf: Option<f64>,
    /// Spacing of trajectory.csv rows (s) [default: simulate.output_dt,
    /// else t_end / 500].
    #[arg(long, allow_negative_numbers = true)]
    pub output_dt: Option<f64>,
    /// Initial coordinates, comma-separated (default 0).
    #[arg(long, allow_hyphen_values = true)]
    pub q0: Option<String>,
    /// Initial rates, comma-separated (default 0).
    #[arg(long, allow_hyphen_values = true)]
    pub qd0: Option<String>,
    /// Initial state: `rest` (q0 as given, at rest) or `static` (the
    /// equilibrium at t = 0 under the loads and inputs, found from q0).
    #[arg(long, value_enum)]
    pub start: Option<StartArg>,
    /// Output directory (default out/<model name>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// No progress report (a bar on a terminal for runs over a second,
    /// else a line every ten seconds).
    #[arg(long)]
    pub quiet: bool,
    /// Stop the run after this many seconds of wall time, with what it
    /// computed written, as Ctrl-C does.
    #[arg(long, value_name = "SECONDS")]
    pub max_wall: Option<f64>,
    /// Points per element of shape.csv's centreline (0: no shape.csv).
    #[arg(long, default_value_t = crate::shape::DEFAULT_POINTS)]
    pub shape_points: usize,
}

/// `--start`: how a simulation starts (the model's `[simulate] start`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum StartArg {
    Rest,
    Static,
}

/// The run the command line asks for.
fn request(a: &SimulateArgs, loaded: &Loaded) -> Result<RunRequest> {
    let n = loaded.arm.dof();
    let coords = &loaded.arm.info().coordinates;
    Ok(RunRequest {
        t_end: a.t_end,
        solver: a.solver.clone(),
        dt: a.dt,
        rtol: a.rtol,
        atol: a.atol,
        max_steps: Some(a.max_steps),
        output_dt: a.output_dt,
        rho_inf: a.rho_inf,
        q0: a
            .q0
            .as_ref()
            .map(|s| parse_vector("--q0", s, n, coords))
            .transpose()?,
        qd0: a
            .qd0
            .as_ref()
            .map(|s| parse_vector("--qd0", s, n, coords))
            .transpose()?,
        start: a.start.map(|s| match s {
            StartArg::Rest => Start::Rest,
            StartArg::Static => Start::Static,
        }),
    })
}

/// Where each of the run's options came from, for summary.json:
/// `{"solver": {"value": "radau5", "from": "model"}, ...}`.
fn option_sources(
    a: &SimulateArgs,
    file: &SimulateDefaults,
    opts: &SimOptions,
) -> serde_json::Value {
    let from = |cli: bool, model: bool| match (cli, model) {
        (true, _) => "command line",
        (false, true) => "model",
        (false, false) => "default",
    };
    json!({
        "solver": {"value": opts.solver, "from": from(a.solver.is_some(), file.solver.is_some())},
        "t_end": {"value": opts.t_end, "from": from(a.t_end.is_some(), file.t_end.is_some())},
        "rtol": {"value": opts.rtol, "from": from(a.rtol.is_some(), file.rtol.is_some())},
        "atol": {"value": opts.atol, "from": from(a.atol.is_some(), file.atol.is_some())},
        "dt": {"value": opts.dt, "from": from(a.dt.is_some(), file.dt.is_some()),
               "used": opts.solver.fixed_step()},
        "output_dt": {"value": opts.output_dt,
                      "from": match (a.output_dt.is_some(), file.output_dt.is_some()) {
                          (true, _) => "command line",
                          (false, true) => "model",
                          (false, false) => "default (t_end / 500)",
                      }},
        "max_steps": {"value": opts.max_steps,
                      "from": if a.max_steps == SimOptions::default().max_steps { "default" } else { "command line" }},
    })
}

/// The simulated tip against the measured one: the error statistics over
/// the comparison window (none if the run ended before it) and the plot.
fn compare_tip(
    loaded: &Loaded,
    m: &compare::Measured,
    tips: &[(f64, [f64; 3])],
    dir: &mut crate::output_dir::OutputDir,
) -> Result<Option<compare::TipError>> {
    // A run that ends before the window has no statistics, but
    // still its plot.
    let err = crate::run::tip_error(loaded, m, tips)
        .map_err(|e| eprintln!("warning: no tip error: {e}"))
        .ok();
    let title = match &err {
        Some(e) => format!(
            "{}: mean tip error {:.2} mm ({:.2} % of length)",
            loaded.model.name,
            1e3 * e.mean_m,
            e.mean_percent_length
        ),
        None => format!("{}: simulated and measured tip", loaded.model.name),
    };
    compare::plot(&dir.plot("tip")?, &title, tips, Some(m))?;
    Ok(err)
}

pub fn simulate(a: SimulateArgs) -> Result<ExitCode> {
    let mut loaded = load(&a.model)?;
    let req = request(&a, &loaded)?;
    let mut opts = crate::run::options(&req, &loaded.model.simulate)?;
    let deadline = match a.max_wall {
        Some(s) if s > 0.0 && s.is_finite() => {
            Some(std::time::Instant::now() + std::time::Duration::from_secs_f64(s))
        }
        Some(s) => bail!("--max-wall must be a positive number of seconds, got {s}"),
        None => None,
    };
    let (x0, assembled_m) = crate::run::initial_state(&req, &mut loaded)?;
    report_assembly(&loaded, assembled_m);
    // Checked before the run: a bad option writes nothing.
    let shape = (a.shape_points > 0)
        .then(|| crate::shape::Shape::new(&loaded, a.shape_points))
        .transpose()?;
    let arm = &*loaded.arm;
    let t_end = opts.t_end;
    // Measured data to compare with: sampled at its own times.
    let measured = crate::run::measured(&loaded, &x0)?;
    let output_times = measured
        .as_ref()
        .map(|m| crate::run::compare_times(m, t_end));
    opts.output_times = output_times;
    let out_dir = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(&loaded.model.name));
    let mut dir = crate::output_dir::OutputDir::claim(&out_dir)?;
    let out_of_scale = crate::scale::out_of_scale(&loaded.model, arm, t_end);
    for line in &out_of_scale {
        eprintln!("warning: {line}");
    }

    let rows = match &opts.output_times {
        Some(t) => t.len() as f64,
        None => (t_end / opts.output_dt).floor() + 1.0,
    };
    if let Some(line) = crate::run_output::size_warning(&loaded, &x0, shape.as_ref(), rows) {
        eprintln!("warning: {line}");
    }
    // Rows go to disk as the run hands them over.
    let shape_csv = match shape {
        Some(s) => Some((s, dir.file("shape.csv")?)),
        None => None,
    };
    let output = RunOutput::create(
        &loaded,
        &dir.file("trajectory.csv")?,
        shape_csv,
        measured.is_some(),
    )?;
    opts.rows = Some(output.sink());
    // Ctrl-C, SIGTERM or --max-wall stops the run with what it computed
    // written.
    opts.interrupt = Some(crate::interrupt::for_run(deadline));
    let progress = crate::progress::Progress::start(&loaded.model.name, opts.t_end, a.quiet);
    opts.progress = progress.as_ref().map(|p| p.cell());
    let result = runtime::simulate(arm, x0.clone(), &opts);
    drop(progress);
    let (traj, stats, failure) = match result {
        Ok((traj, stats)) => (traj, stats, None),
        Err(f) => explained(arm, *f, &out_of_scale),
    };
    let kept = output.finish()?;
    plot_paths_and_contact(&loaded, &kept, &mut dir)?;
    let tip_error = match (&measured, &loaded.model.compare) {
        (Some(m), Some(_)) => compare_tip(&loaded, m, &kept.tips, &mut dir)?,
        // Every arm's run plots its tip over time (a run with contact
        // plots its path; bodies alone have their own plots).
        _ if arm.contact().is_none() && !no_arm(&loaded.model) => {
            let title = format!("{}: tip", loaded.model.name);
            compare::plot(&dir.plot("tip")?, &title, &kept.tip.points(), None)?;
            None
        }
        _ => None,
    };
    let mut summary = crate::run::summary(
        &loaded,
        &opts,
        &stats,
        &traj,
        tip_error.as_ref(),
        failure.as_ref().map(|f| f.1.clone()),
    );
    summary["options"] = option_sources(&a, &loaded.model.simulate, &opts);
    summary["assembly_moved"] = json!(assembled_m);
    write_atomic(
        &dir.file("summary.json")?,
        serde_json::to_string_pretty(&summary)?.as_bytes(),
    )?;
    if !a.quiet {
        report_run(&loaded, &stats, &tip_error, &out_dir);
    }
    if let Some((msg, f)) = failure {
        let stopped = f["reason"] == runtime::INTERRUPTED;
        let stop = crate::interrupt::requested().filter(|_| stopped);
        // Said even when quiet: the folder holds an incomplete run.
        if stopped {
            eprintln!(
                "{}: stopped by {} at t = {} s; the trajectory up to then is in {}",
                loaded.model.name,
                stop.map_or("--max-wall", |s| s.name()),
                f["t_reached"],
                out_dir.join("trajectory.csv").display()
            );
        } else if !a.quiet {
            eprintln!("error: {msg}");
            eprintln!(
                "the trajectory up to then is in {}",
                out_dir.join("trajectory.csv").display()
            );
        }
        return Ok(stop.map_or(ExitCode::FAILURE, |s| ExitCode::from(s.exit_code())));
    }
    Ok(ExitCode::SUCCESS)
}

/// A model of free bodies alone (no tip to plot).
fn no_arm(model: &eomgen::model::Model) -> bool {
    model.segments.is_empty() && model.arms.is_empty()
}

/// A failed run's trajectory and counts, with its message (the joints
/// that became dependent named) and its summary entry; inputs out of
/// their model's scale (`crate::scale`) come first in what to try.
fn explained(
    arm: &dyn Dynamics,
    mut f: runtime::SimFailure,
    out_of_scale: &[String],
) -> (
    Trajectory,
    runtime::SimStats,
    Option<(String, serde_json::Value)>,
) {
    let n = arm.dof();
    if !out_of_scale.is_empty() {
        f.suggestion = format!(
            "bring the inputs into the model's scale: {}; then, if it still fails, {}",
            out_of_scale.join("; "),
            f.suggestion
        );
    }
    let mut msg = f.to_string();
    // Joints that became dependent during the run, by name.
    if f.state.len() >= 2 * n {
        let rows = runtime::constraints::dependent_rows(arm, f.t_reached, &f.state[..n]);
        for group in rows {
            msg.push_str(&format!(
                "\n  dependent joints at t = {:.6} s: {} (rows {})",
                f.t_reached,
                runtime::constraints::joints_of(&group).join(", "),
                group.join(", ")
            ));
        }
    }
    let fail = json!({"t_reached": f.t_reached, "last_step_s": f.last_step_s, "reason": f.reason, "suggestion": f.suggestion, "state": f.state});
    (f.trajectory, f.stats, Some((msg, fail)))
}

/// The free bodies' paths, and with contact the tip's path and the contact
/// forces, as pictures in `out_dir`.
fn plot_paths_and_contact(
    loaded: &Loaded,
    kept: &Kept,
    dir: &mut crate::output_dir::OutputDir,
) -> Result<()> {
    for (body, path) in &kept.paths {
        let title = format!("{}: path of {body}", loaded.model.name);
        crate::joints::plot_path(&dir.plot(body)?, &title, &path.points())?;
    }
    if let Some(set) = loaded.arm.contact()
        && !kept.tip_path.is_empty()
    {
        // The tip's path and the contact forces.
        let name = &loaded.model.name;
        let tips = kept.tip_path.points();
        crate::joints::plot_path(&dir.plot("tip")?, &format!("{name}: tip path"), &tips)?;
        crate::contact::plot_forces(
            &dir.plot("contact")?,
            &format!("{name}: contact forces"),
            &set.channels,
            &kept.forces.points(),
        )?;
    }
    Ok(())
}

/// The lines a finished run prints on stderr.
fn report_run(
    loaded: &Loaded,
    stats: &runtime::SimStats,
    tip_error: &Option<compare::TipError>,
    out_dir: &Path,
) {
    let arm = &*loaded.arm;
    eprintln!(
        "{}: {} backend{}, {} {} steps, {} rhs evaluations, {:.3} s wall; wrote {}",
        loaded.model.name,
        arm.backend(),
        match loaded.cache {
            backend::CacheStatus::Hit => " (tape cache hit)",
            backend::CacheStatus::Miss => " (derived, tape cached)",
            backend::CacheStatus::Unused => "",
            backend::CacheStatus::Linked => " (cells linked to this element count)",
        },
        stats.solver.name(),
        stats.steps,
        stats.rhs_evaluations,
        stats.wall_s,
        out_dir.display()
    );
    if arm.backend() == "interpreted" {
        eprintln!("  why interpreted: {}", loaded.route);
    } else if loaded.cache == backend::CacheStatus::Linked {
        eprintln!("  route: {}", loaded.route);
    }
    if let Some(e) = &tip_error {
        eprintln!(
            "tip error over {} to {} s ({} samples): mean {:.3} mm ({:.2} % of length), rms {:.3} mm, max {:.3} mm; plot in {}",
            e.window_s[0],
            e.window_s[1],
            e.samples,
            1e3 * e.mean_m,
            e.mean_percent_length,
            1e3 * e.rms_m,
            1e3 * e.max_m,
            out_dir.join("tip.png").display()
        );
    }
    if let Some(sw) = &stats.switched {
        eprintln!(
            "auto: switched to {} at t = {} s ({})",
            sw.to.name(),
            sw.at_s,
            sw.reason
        );
    }
}

#[derive(Args)]
pub struct EomArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Coordinates, comma-separated.
    #[arg(long, allow_hyphen_values = true)]
    pub q: Option<String>,
    /// Rates, comma-separated (default 0).
    #[arg(long, allow_hyphen_values = true)]
    pub qd: Option<String>,
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub t: f64,
    /// Print JSON (the only format for now; accepted for scripts).
    #[arg(long)]
    pub json: bool,
}

pub fn eom(a: EomArgs) -> Result<ExitCode> {
    let loaded = load(&a.model)?;
    let arm = &*loaded.arm;
    let n = arm.dof();
    let coords = arm.info().coordinates.clone();
    let q = optional_vector("--q", &a.q, n, &coords)?;
    let qd = optional_vector("--qd", &a.qd, n, &coords)?;
    let mut m = DMatrix::zeros(n, n);
    let mut h = DVector::zeros(n);
    arm.mass_bias(a.t, &q, &qd, &mut m, &mut h);
    let out = arm.outputs(a.t, &q, &qd);
    let rows: Vec<Vec<f64>> = (0..n).map(|i| m.row(i).iter().copied().collect()).collect();
    // The state derivative's Jacobian, with the accelerations; null where
    // they fail (M not positive definite, dependent joints).
    let x: Vec<f64> = q.iter().chain(&qd).copied().collect();
    let mut jac = DMatrix::zeros(2 * n, 2 * n);
    let mut ws = runtime::Workspace::new(n);
    let (qdd, jacobian) = match runtime::state_jacobian(arm, &mut ws, a.t, &x, &mut jac) {
        Ok(qdd) => {
            let rows: Vec<Vec<f64>> = (0..2 * n)
                .map(|i| jac.row(i).iter().copied().collect())
                .collect();
            (json!(qdd), json!(rows))
        }
        Err(_) => (serde_json::Value::Null, serde_json::Value::Null),
    };
    let v = json!({
        "model": loaded.model.name,
        "backend": arm.backend(),
        "coordinates": coords,
        "mass": rows,
        "bias": h.as_slice(),
        "accelerations": qdd,
        "jacobian": jacobian,
        "outputs": out.as_slice(),
        "output_names": runtime::OUTPUT_NAMES,
        "tip_position": &out[..3],
        "kinetic_energy": out[3],
        "potential_energy": out[4],
    });
    println!("{}", serde_json::to_string_pretty(&v)?);
    Ok(ExitCode::SUCCESS)
}

#[derive(Args)]
pub struct BenchArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Number of timed batches (the median is reported).
    #[arg(long, default_value_t = 21)]
    pub batches: usize,
    #[arg(long)]
    pub json: bool,
}

/// Median over batches of the time per call of `f`, in ns.
fn time_ns(batches: usize, mut f: impl FnMut()) -> f64 {
    // Size a batch to about 20 ms.
    let start = Instant::now();
    let mut calls = 0u64;
    while start.elapsed().as_secs_f64() < 0.02 {
        f();
        calls += 1;
    }
    let mut per_call: Vec<f64> = (0..batches.max(1))
        .map(|_| {
            let t = Instant::now();
            for _ in 0..calls {
                f();
            }
            t.elapsed().as_nanos() as f64 / calls as f64
        })
        .collect();
    per_call.sort_by(f64::total_cmp);
    per_call[per_call.len() / 2]
}

pub fn bench(a: BenchArgs) -> Result<ExitCode> {
    let loaded = load(&a.model)?;
    let arm = &*loaded.arm;
    let n = arm.dof();
    // Derivation from scratch, whatever backend runs.
    let start = Instant::now();
    let tapes = eomgen::derive::derive(&loaded.model);
    let derive_s = start.elapsed().as_secs_f64();
    let q: Vec<f64> = (0..n).map(|i| 0.3 * ((i as f64) * 0.7).sin()).collect();
    let qd: Vec<f64> = (0..n).map(|i| 0.2 * ((i as f64) * 1.3).cos()).collect();
    let mut ws = Workspace::new(n);
    let mut qdd = vec![0.0; n];
    // Kernels as the integrators call them (packed outputs, no matrix copies).
    let kernel_ns = |kind: KernelKind| {
        let mut out = vec![0.0; kind.output_len(arm.info())];
        time_ns(a.batches, || {
            arm.eval_kernel(kind, 0.0, std::hint::black_box(&q), &qd, &mut out)
        })
    };
    let mass_bias_ns = kernel_ns(KernelKind::MassBias);
    let rhs_ns = time_ns(a.batches, || {
        let _ = accelerations(arm, &mut ws, 0.0, std::hint::black_box(&q), &qd, &mut qdd);
    });
    let v = json!({
        "model": loaded.model.name,
        "backend": arm.backend(),
        "dof": n,
        "derive_s": derive_s,
        "mass_bias_ops": tapes.mass_bias.op_count(),
        "mass_bias_ns": mass_bias_ns,
        "rhs_ns": rhs_ns,
    });
    if a.json {
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        let mut out = std::io::stdout().lock();
        writeln!(
            out,
            "{} ({} backend, {} dof)",
            loaded.model.name,
            arm.backend(),
            n
        )?;
        writeln!(out, "  derive      {:>10.4} s", derive_s)?;
        writeln!(out, "  mass+bias   {:>10.1} ns", mass_bias_ns)?;
        writeln!(out, "  rhs (qdd)   {:>10.1} ns", rhs_ns)?;
    }
    Ok(ExitCode::SUCCESS)
}

#[derive(Args, Clone)]
pub struct StaticArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Starting configuration, comma-separated (default: straight).
    #[arg(long, allow_hyphen_values = true)]
    pub q0: Option<String>,
    /// Points per element of the equilibrium's `shape` (0: none).
    #[arg(long, default_value_t = crate::shape::DEFAULT_POINTS)]
    pub shape_points: usize,
    /// Print JSON (every value, for scripts) instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// The coordinates to start from: `--q0`, else the model's (`[simulate]
/// q0`, free bodies where declared, the rest 0), put onto the joints.
fn start_coordinates(loaded: &Loaded, q0: &Option<String>) -> Result<(Vec<f64>, f64)> {
    let n = loaded.arm.dof();
    let coords = &loaded.arm.info().coordinates;
    let q0 = q0
        .as_ref()
        .map(|s| parse_vector("--q0", s, n, coords))
        .transpose()?;
    let (q, moved) = crate::run::start_coordinates(loaded, q0.as_deref())?;
    report_assembly(loaded, moved);
    Ok((q, moved))
}

/// Say when the start was moved onto the joints.
fn report_assembly(loaded: &Loaded, moved: f64) {
    if moved > 0.0 {
        eprintln!(
            "{}: the initial state was assembled onto the joints, moving the coordinates by {moved:.3e} (Euclidean norm)",
            loaded.model.name
        );
    }
}

/// Solve the static equilibrium of a loaded model, or explain why not.
fn equilibrium(loaded: &mut Loaded, q0: &Option<String>) -> Result<runtime::StaticSolution> {
    let (q0, _) = start_coordinates(loaded, q0)?;
    runtime::solve_static(&mut *loaded.arm, &q0, &runtime::StaticOptions::default())
        .map_err(|e| anyhow::anyhow!("{}: {e}", loaded.origin))
}

pub fn statics(a: StaticArgs) -> Result<ExitCode> {
    let v = static_value(&a)?;
    match a.json {
        true => println!("{}", serde_json::to_string_pretty(&v)?),
        false => super::tables::statics(&v),
    }
    Ok(ExitCode::SUCCESS)
}

/// `softarm static`'s answer, as JSON.
pub fn static_value(a: &StaticArgs) -> Result<serde_json::Value> {
    let overrides = a
        .model
        .set
        .iter()
        .map(|s| Override::parse(s))
        .collect::<Result<Vec<_>, _>>()?;
    let (model, origin) = backend::read_model(&a.model.model, &overrides)?;
    if crate::continuum::is_cosserat(&model) {
        let sol = crate::continuum::solve(&model, &origin)?;
        let v = json!({
            "model": model.name,
            "method": "cosserat",
            "tip_position": sol.tip_position,
            "base_force": sol.base_force,
            "base_moment": sol.base_moment,
            "residual": sol.residual,
            "iterations": sol.iterations,
            "load_steps": sol.load_steps,
            "centerline": sol.positions,
        });
        return Ok(v);
    }
    let mut loaded = load(&a.model)?;
    let sol = equilibrium(&mut loaded, &a.q0)?;
    let n = sol.q.len();
    let out = loaded.arm.outputs(0.0, &sol.q, &vec![0.0; n]);
    let shape = match a.shape_points {
        0 => None,
        p => Some(crate::shape::Shape::new(&loaded, p)?.at(&*loaded.arm, 0.0, &sol.q)),
    };
    let v = json!({
        "model": loaded.model.name,
        "backend": loaded.arm.backend(),
        "coordinates": loaded.arm.info().coordinates,
        "q": sol.q,
        "tip_position": &out[..3],
        "joint_forces": crate::joints::static_forces(&*loaded.arm, &sol.lambda),
        "residual": sol.residual,
        "iterations": sol.iterations,
        "load_steps": sol.load_steps,
        "shape": shape,
    });
    Ok(v)
}

#[derive(Args, Clone)]
pub struct ModesArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Starting configuration of the static solve, comma-separated.
    #[arg(long, allow_hyphen_values = true)]
    pub q0: Option<String>,
    /// Also print the mode shapes (generalised coordinates).
    #[arg(long)]
    pub shapes: bool,
    /// Print JSON (every value, for scripts) instead of a table.
    #[arg(long)]
    pub json: bool,
}

pub fn modes(a: ModesArgs) -> Result<ExitCode> {
    let v = modes_value(&a)?;
    match a.json {
        true => println!("{}", serde_json::to_string_pretty(&v)?),
        false => super::tables::modes(&v),
    }
    Ok(ExitCode::SUCCESS)
}

/// `softarm modes`' answer, as JSON.
pub fn modes_value(a: &ModesArgs) -> Result<serde_json::Value> {
    let mut loaded = load(&a.model)?;
    let sol = equilibrium(&mut loaded, &a.q0)?;
    let m = runtime::modes(&*loaded.arm, &sol.q)
        .map_err(|e| anyhow::anyhow!("{}: {e}", loaded.origin))?;
    let kinds = mode_kinds(&loaded, &sol.q, &m.shapes);
    let mut v = json!({
        "model": loaded.model.name,
        "backend": loaded.arm.backend(),
        "frequencies_hz": m.frequencies_hz,
        "kinds": kinds,
        "equilibrium_q": sol.q,
    });
    if a.shapes {
        v["shapes"] = json!(m.shapes);
    }
    Ok(v)
}

/// What each mode is: the family of coordinates (`bend_y`, `twist`,
/// `stretch`, ...: a coordinate's name without its segment and element
/// indices) that holds the largest share of its kinetic energy
/// phi_i (M phi)_i / phi^T M phi, with that share.
fn mode_kinds(loaded: &Loaded, q: &[f64], shapes: &[Vec<f64>]) -> Vec<serde_json::Value> {
    let n = q.len();
    let mut m = DMatrix::zeros(n, n);
    loaded.arm.mass(0.0, q, &mut m);
    let names = &loaded.arm.info().coordinates;
    let family = |name: &str| -> String {
        let kept: Vec<&str> = name
            .split('_')
            .take_while(|p| {
                let digits = p.trim_start_matches('c');
                digits.is_empty() || !digits.chars().all(|c| c.is_ascii_digit())
            })
            .collect();
        kept.join("_")
    };
    shapes
        .iter()
        .map(|phi| {
            let v = nalgebra::DVector::from_column_slice(phi);
            let mv = &m * &v;
            let total = v.dot(&mv);
            let mut shares: Vec<(String, f64)> = Vec::new();
            for i in 0..n {
                let f = family(&names[i]);
                let e = phi[i] * mv[i] / total;
                match shares.iter_mut().find(|(g, _)| *g == f) {
                    Some((_, s)) => *s += e,
                    None => shares.push((f, e)),
                }
            }
            let (kind, share) = shares
                .into_iter()
                .max_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap_or_default();
            json!({ "kind": kind, "share": share })
        })
        .collect()
}

#[derive(Args)]
pub struct InspectArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// The configuration to linearise at (default: the static equilibrium).
    #[arg(long, allow_hyphen_values = true)]
    pub q: Option<String>,
    /// Rates at that configuration (default 0).
    #[arg(long, allow_hyphen_values = true)]
    pub qd: Option<String>,
    /// Print JSON (every value, for scripts) instead of a table.
    #[arg(long)]
    pub json: bool,
}

pub fn inspect(a: InspectArgs) -> Result<ExitCode> {
    let mut loaded = load(&a.model)?;
    let n = loaded.arm.dof();
    let coords = loaded.arm.info().coordinates.clone();
    let q = match &a.q {
        Some(_) => optional_vector("--q", &a.q, n, &coords)?,
        None => equilibrium(&mut loaded, &None)?.q,
    };
    let qd = optional_vector("--qd", &a.qd, n, &coords)?;
    let x: Vec<f64> = q.iter().chain(&qd).copied().collect();
    let mut jac = DMatrix::zeros(2 * n, 2 * n);
    runtime::rhs_jacobian(&*loaded.arm, &mut Workspace::new(n), 0.0, &x, &mut jac)
        .map_err(|e| anyhow::anyhow!("{}: {e}", loaded.origin))?;
    let report = runtime::analyse_stiffness(&jac).ok_or_else(|| {
        anyhow::anyhow!(
            "{}: the Jacobian at this state is not finite or its eigenvalues do not converge: no stiffness to report",
            loaded.origin
        )
    })?;
    let mut v = serde_json::to_value(&report)?;
    v["model"] = json!(loaded.model.name);
    v["q"] = json!(q);
    match a.json {
        true => println!("{}", serde_json::to_string_pretty(&v)?),
        false => super::tables::inspect(&v),
    }
    Ok(ExitCode::SUCCESS)
}

#[derive(Args)]
pub struct FixedStepArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// The fixed-step solver.
    #[arg(long, default_value = "rk4", value_parser = ["rk4", "euler", "gauss", "radau5-fixed"])]
    pub solver: String,
    /// The tip's largest allowed distance from the reference (m).
    #[arg(long, default_value_t = 1e-3)]
    pub tol: f64,
    /// Simulated time (s) [default: simulate.t_end, else 5].
    #[arg(long)]
    pub t_end: Option<f64>,
    /// Print JSON (the only format; accepted for scripts).
    #[arg(long)]
    pub json: bool,
}

/// `softarm fixed-step`: the chapter's step-size procedure.
pub fn fixed_step(a: FixedStepArgs) -> Result<ExitCode> {
    let mut loaded = load(&a.model)?;
    let req = RunRequest {
        t_end: a.t_end,
        ..Default::default()
    };
    let opts = crate::run::options(&req, &loaded.model.simulate)?;
    let (x0, _) = crate::run::initial_state(&req, &mut loaded)?;
    let solver = runtime::Solver::parse(&a.solver).expect("clap checked the name");
    let choice = crate::fixed_step::choose(&loaded, &x0, opts.t_end, solver, a.tol)?;
    let mut v = serde_json::to_value(&choice)?;
    v["model"] = json!(loaded.model.name);
    v["t_end"] = json!(opts.t_end);
    println!("{}", serde_json::to_string_pretty(&v)?);
    Ok(ExitCode::SUCCESS)
}

#[derive(Args)]
pub struct LinearizeArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// The input channels u, comma-separated (e.g. p0,p1,p2); none for the
    /// free arm.
    #[arg(long, value_delimiter = ',')]
    pub inputs: Vec<String>,
    /// The inputs' values at the equilibrium (default 0).
    #[arg(long, allow_hyphen_values = true)]
    pub u0: Option<String>,
    /// The coordinates to linearise about (default: the equilibrium under
    /// u0).
    #[arg(long, allow_hyphen_values = true)]
    pub q0: Option<String>,
    /// Print JSON (the only format; accepted for scripts).
    #[arg(long)]
    pub json: bool,
}

/// `softarm linearize`: A, B, C, D about an equilibrium, as JSON.
pub fn linearize(a: LinearizeArgs) -> Result<ExitCode> {
    let mut loaded = load(&a.model)?;
    let n = loaded.arm.dof();
    let coords = loaded.arm.info().coordinates.clone();
    let q0 =
        a.q0.as_ref()
            .map(|s| parse_vector("--q0", s, n, &coords))
            .transpose()?;
    let u0 =
        a.u0.as_ref()
            .map(|s| parse_vector("--u0", s, a.inputs.len(), &a.inputs))
            .transpose()?;
    let lin = crate::linearize::linearize(&mut loaded, &a.inputs, u0.as_deref(), q0.as_deref())?;
    let rows = |m: &DMatrix<f64>| -> Vec<Vec<f64>> {
        (0..m.nrows())
            .map(|i| m.row(i).iter().copied().collect())
            .collect()
    };
    let v = json!({
        "model": loaded.model.name,
        "states": lin.states,
        "inputs": lin.inputs,
        "outputs": lin.outputs,
        "q0": lin.q0,
        "u0": lin.u0,
        "A": rows(&lin.a),
        "B": rows(&lin.b),
        "C": rows(&lin.c),
        "D": rows(&lin.d),
    });
    println!("{}", serde_json::to_string_pretty(&v)?);
    Ok(ExitCode::SUCCESS)
}
