//! `softarm sweep`: a parameter study. Every combination of the `--vary`
//! values (a grid) is one run of `simulate`, `static` or `modes` with
//! those values as `--set` overrides, in parallel on all cores (rayon),
//! each in its own folder; `sweep.csv` has a row per run (the values, its
//! status, the chosen figures) and `sweep.png` one figure against the
//! first varied value, a line per value of the second.
//!
//! Before any run every varied value is checked as `--set` checks it, so
//! a typo fails at once, and the grid is counted: a big one needs
//! `--yes`, and its refusal says the disk and time it would take, from a
//! pilot of its first run.
//! A run that fails is a row with its failure; the sweep goes on, and
//! exits non-zero at its end. Each run that ended writes its row into its
//! folder, so that `--resume` redoes only the runs that did not.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Args;
use rayon::prelude::*;
use serde_json::Value;

use super::commands::{self, ModesArgs, SimulateArgs, StaticArgs};
use crate::grid::{Vary, checked_size_with, grid};

#[derive(Args, Clone)]
pub struct SweepArgs {
    /// The run for every combination, with its options (`--t-end`,
    /// `--solver`, `--set`, ...).
    #[command(flatten)]
    pub simulate: SimulateArgs,
    /// What each combination runs.
    #[arg(long, value_enum, default_value_t = Study::Simulate)]
    pub run: Study,
    /// PATH=VALUES: the values of a model key to combine, as a list
    /// (`0.1,0.2,0.3`), `lin:a:b:n` or `log:a:b:n` (n values from a to b).
    /// Repeat for a grid.
    #[arg(long, value_name = "PATH=VALUES", required = true)]
    pub vary: Vec<String>,
    /// Runs at once (default: every core).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Start a sweep of more than 10,000 runs.
    #[arg(long)]
    pub yes: bool,
    /// Keep the runs of an earlier sweep into the same folder that ended
    /// (ok or failed) with the same overrides; run the others.
    #[arg(long)]
    pub resume: bool,
    /// The figure sweep.png plots (a column of sweep.csv; default tip_y,
    /// or f1_hz for modes).
    #[arg(long)]
    pub plot: Option<String>,
}

/// What a sweep runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Study {
    Simulate,
    Static,
    Modes,
}

/// One run's row: its figures by name, or its failure. Written into the
/// run's folder last (`ROW`), so that `--resume` finds the runs that
/// ended, with the overrides they ran with.
#[derive(Clone, serde::Serialize, serde::Deserialize)]
struct Row {
    status: String,
    wall_s: f64,
    figures: Vec<(String, f64)>,
}

pub fn sweep(a: SweepArgs) -> Result<ExitCode> {
    let varies: Vec<Vary> = a
        .vary
        .iter()
        .map(|s| Vary::parse(s))
        .collect::<Result<_>>()?;
    // A grid past what a sweep makes is refused before its values are
    // read one by one (a model read each).
    crate::grid::checked_size(&varies, true, "--yes")?;
    check_values(&a.simulate.model, &varies)?;
    checked_size_with(&varies, a.yes, "--yes", |runs| pilot(&a, &varies, runs))?;
    let combos = grid(&varies);
    let name = model_name(&a.simulate.model.model);
    let out_dir = a
        .simulate
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(format!("{name}-sweep")));
    let mut dir = crate::output_dir::OutputDir::claim(&out_dir)?;
    let jobs = a.jobs.unwrap_or_else(rayon::current_num_threads).max(1);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .build()
        .context("cannot start the sweep's threads")?;
    eprintln!(
        "sweep: {} runs of {} on {jobs} threads into {}",
        combos.len(),
        format!("{:?}", a.run).to_lowercase(),
        out_dir.display()
    );
    // Ctrl-C or SIGTERM: the runs under way stop and keep what they
    // computed, the others are not started; sweep.csv says which.
    crate::interrupt::catch();
    let started = Instant::now();
    let table = Progress::new(dir.file("sweep.csv")?, combos.len());
    let rows: Vec<Row> = pool.install(|| {
        combos
            .par_iter()
            .enumerate()
            .map(|(i, combo)| {
                let row = run_one(&a, &varies, combo, &out_dir.join(format!("run_{i:04}")));
                table.finished(i, &row, &varies, &combos);
                row
            })
            .collect()
    });
    let wall = started.elapsed().as_secs_f64();
    table.write(&varies, &combos, &rows.iter().map(Some).collect::<Vec<_>>())?;
    let figure = a.plot.clone().unwrap_or_else(|| match a.run {
        Study::Modes => "f1_hz".into(),
        _ => "tip_y".into(),
    });
    plot(&dir.plot("sweep")?, &name, &figure, &varies, &combos, &rows)?;
    let failed = rows.iter().filter(|r| r.status != "ok").count();
    let serial: f64 = rows.iter().map(|r| r.wall_s).sum();
    eprintln!(
        "sweep: {} runs, {failed} failed, {wall:.2} s wall ({serial:.2} s of runs); wrote {}",
        rows.len(),
        out_dir.join("sweep.csv").display()
    );
    Ok(match crate::interrupt::requested() {
        Some(stop) => {
            eprintln!(
                "sweep: stopped by {}; sweep.csv has every run's status",
                stop.name()
            );
            ExitCode::from(stop.exit_code())
        }
        None if failed == 0 => ExitCode::SUCCESS,
        None => ExitCode::FAILURE,
    })
}

/// Every varied value as `--set` takes it, one at a time on the sweep's
/// own overrides: the model must read and validate with it.
fn check_values(model: &commands::ModelArgs, varies: &[Vary]) -> Result<()> {
    let base = model
        .set
        .iter()
        .map(|s| eomgen::model::Override::parse(s))
        .collect::<Result<Vec<_>, _>>()?;
    for v in varies {
        for value in &v.values {
            let set = format!("{}={value}", v.path);
            let mut overrides = base.clone();
            overrides.push(
                eomgen::model::Override::parse(&set).with_context(|| format!("--vary {set}"))?,
            );
            crate::backend::read_model(&model.model, &overrides)
                .with_context(|| format!("--vary {set}"))?;
        }
    }
    Ok(())
}

fn model_name(model: &str) -> String {
    Path::new(model)
        .file_stem()
        .map_or_else(|| model.to_string(), |s| s.to_string_lossy().into_owned())
}

/// One combination: its overrides on the sweep's own, the run in `dir`,
/// its figures.
fn run_one(a: &SweepArgs, varies: &[Vary], combo: &[usize], dir: &Path) -> Row {
    let started = Instant::now();
    if let Some(stop) = crate::interrupt::requested() {
        return Row {
            status: format!("not run: {} before it started", stop.name()),
            wall_s: 0.0,
            figures: Vec::new(),
        };
    }
    let mut model = a.simulate.model.clone();
    for (v, &i) in varies.iter().zip(combo) {
        model.set.push(format!("{}={}", v.path, v.values[i]));
    }
    let key = format!("{:?} {:?}", a.run, model.set);
    if a.resume
        && let Some(row) = ended(dir, &key)
    {
        return row;
    }
    // A run redone is not ended until its row is written again.
    let _ = std::fs::remove_file(dir.join(ROW));
    let result = std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create {}", dir.display()))
        .and_then(|()| study(a, model, dir));
    let wall_s = started.elapsed().as_secs_f64();
    let row = match result {
        Ok((status, figures)) => Row {
            status,
            wall_s,
            figures,
        },
        Err(e) => {
            let msg = format!("{e:#}");
            let _ = std::fs::write(dir.join("error.txt"), &msg);
            Row {
                status: format!("failed: {msg}"),
                wall_s,
                figures: Vec::new(),
            }
        }
    };
    // An interrupted run is not an ended one: `--resume` runs it again.
    if !row.status.contains(runtime::INTERRUPTED) && crate::interrupt::requested().is_none() {
        let text = serde_json::json!({"run": key, "row": &row}).to_string();
        let _ = eomgen::atomic_write::write_atomic(&dir.join(ROW), text.as_bytes());
    }
    row
}

/// How long a pilot of the grid's first run may take (s).
const PILOT_WALL_S: f64 = 2.0;

/// The disk and time `runs` runs would take, from a pilot of the first
/// run (stopped after [`PILOT_WALL_S`], scaled from the time it reached to
/// the whole run), in a folder of the system's temporary one, removed.
fn pilot(a: &SweepArgs, varies: &[Vary], runs: usize) -> Option<String> {
    let dir = std::env::temp_dir().join(format!("softarm-sweep-pilot-{}", std::process::id()));
    let mut pilot = a.clone();
    pilot.simulate.max_wall = Some(PILOT_WALL_S);
    let mut model = a.simulate.model.clone();
    for v in varies {
        model.set.push(format!("{}={}", v.path, v.values[0]));
    }
    let ran = std::fs::create_dir_all(&dir)
        .ok()
        .and_then(|()| study(&pilot, model, &dir).ok());
    let summary: Option<Value> = std::fs::read_to_string(dir.join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok());
    let bytes: u64 = std::fs::read_dir(&dir)
        .into_iter()
        .flatten()
        .flatten()
        .filter_map(|e| e.metadata().ok())
        .map(|m| m.len())
        .sum();
    let _ = std::fs::remove_dir_all(&dir);
    ran?;
    let v = summary?;
    let wall = v["wall_s"].as_f64()?;
    // A study without time (static, modes) or a run that ended: as it is.
    let scale = match (v["t_end"].as_f64(), v["failure"]["t_reached"].as_f64()) {
        (Some(t_end), Some(t)) if t > 0.0 => t_end / t,
        _ => 1.0,
    };
    let jobs = a.jobs.unwrap_or_else(rayon::current_num_threads).max(1);
    let hours = wall * scale * runs as f64 / jobs as f64 / 3600.0;
    let gb = bytes as f64 * scale * runs as f64 / 1e9;
    Some(format!(
        "about {gb:.3} GB and {hours:.2} h on {jobs} threads, from a pilot of the first run"
    ))
}

/// The row a run writes into its folder when it has ended.
const ROW: &str = "sweep-row.json";

/// The row of the run in `dir` if it ended with the same study and
/// overrides (`key`).
fn ended(dir: &Path, key: &str) -> Option<Row> {
    let text = std::fs::read_to_string(dir.join(ROW)).ok()?;
    let v: Value = serde_json::from_str(&text).ok()?;
    (v["run"] == key)
        .then(|| serde_json::from_value(v["row"].clone()).ok())
        .flatten()
}

/// Run the study with `model`'s overrides; (status, figures).
fn study(
    a: &SweepArgs,
    model: commands::ModelArgs,
    dir: &Path,
) -> Result<(String, Vec<(String, f64)>)> {
    let tip = |v: &Value| -> Vec<(String, f64)> {
        ["tip_x", "tip_y", "tip_z"]
            .iter()
            .enumerate()
            .filter_map(|(k, n)| v.get(k).and_then(Value::as_f64).map(|x| (n.to_string(), x)))
            .collect()
    };
    match a.run {
        Study::Simulate => {
            let mut s = a.simulate.clone();
            s.model = model;
            s.out = Some(dir.to_path_buf());
            s.quiet = true;
            commands::simulate(s)?;
            let text = std::fs::read_to_string(dir.join("summary.json"))
                .context("the run wrote no summary.json")?;
            let v: Value = serde_json::from_str(&text)?;
            let status = match v["failure"]["reason"].as_str() {
                Some(f) => format!("failed: {f}"),
                None => "ok".into(),
            };
            let mut figures = tip(&v["final_state"]["tip_position"]);
            if let Some(e) = v["tip_error"]["mean_m"].as_f64() {
                figures.push(("tip_error_mean_mm".into(), 1e3 * e));
            }
            if let Some(w) = v["wall_s"].as_f64() {
                figures.push(("run_wall_s".into(), w));
            }
            Ok((status, figures))
        }
        Study::Static => {
            let v = commands::static_value(&StaticArgs {
                model,
                q0: a.simulate.q0.clone(),
                shape_points: a.simulate.shape_points,
                json: true,
            })?;
            std::fs::write(dir.join("static.json"), serde_json::to_string_pretty(&v)?)?;
            Ok(("ok".into(), tip(&v["tip_position"])))
        }
        Study::Modes => {
            let v = commands::modes_value(&ModesArgs {
                model,
                q0: a.simulate.q0.clone(),
                shapes: false,
                json: true,
            })?;
            std::fs::write(dir.join("modes.json"), serde_json::to_string_pretty(&v)?)?;
            let f = v["frequencies_hz"].as_array().cloned().unwrap_or_default();
            let figures = f
                .iter()
                .take(3)
                .enumerate()
                .filter_map(|(k, x)| x.as_f64().map(|x| (format!("f{}_hz", k + 1), x)))
                .collect();
            Ok(("ok".into(), figures))
        }
    }
}

/// `sweep.csv` as runs finish: rewritten whole (atomically, in grid order,
/// the runs not finished yet `pending`) at most once a second, so that a
/// sweep killed outright still leaves the table of what it finished.
struct Progress {
    path: PathBuf,
    state: std::sync::Mutex<(Vec<Option<Row>>, Instant)>,
}

impl Progress {
    fn new(path: PathBuf, runs: usize) -> Self {
        let mut rows = Vec::new();
        rows.resize_with(runs, || None);
        Self {
            path,
            state: std::sync::Mutex::new((rows, Instant::now())),
        }
    }

    /// Run `i` finished with `row`.
    fn finished(&self, i: usize, row: &Row, varies: &[Vary], combos: &[Vec<usize>]) {
        let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        state.0[i] = Some(row.clone());
        if state.1.elapsed().as_secs_f64() >= 1.0 {
            let rows: Vec<Option<&Row>> = state.0.iter().map(Option::as_ref).collect();
            // A failed snapshot is not the sweep's failure: the last write says.
            let _ = self.write(varies, combos, &rows);
            state.1 = Instant::now();
        }
    }

    fn write(&self, varies: &[Vary], combos: &[Vec<usize>], rows: &[Option<&Row>]) -> Result<()> {
        let csv = sweep_csv(varies, combos, rows);
        eomgen::atomic_write::write_atomic(&self.path, csv.as_bytes())
            .with_context(|| format!("cannot write {}", self.path.display()))
    }
}

/// `sweep.csv`: run, the varied values, status, wall time, then every
/// figure any run reported (empty where a run has none); a run not
/// finished yet is `pending`.
fn sweep_csv(varies: &[Vary], combos: &[Vec<usize>], rows: &[Option<&Row>]) -> String {
    let mut names: Vec<String> = Vec::new();
    for r in rows.iter().flatten() {
        for (n, _) in &r.figures {
            if !names.contains(n) {
                names.push(n.clone());
            }
        }
    }
    let quote = |s: &str| format!("\"{}\"", s.replace('"', "\"\""));
    let mut out = String::from("run");
    for v in varies {
        out.push(',');
        out.push_str(&quote(&v.path));
    }
    out.push_str(",status,wall_s");
    for n in &names {
        out.push(',');
        out.push_str(n);
    }
    out.push('\n');
    let pending = Row {
        status: "pending".into(),
        wall_s: 0.0,
        figures: Vec::new(),
    };
    for (i, (combo, r)) in combos.iter().zip(rows).enumerate() {
        let r = r.unwrap_or(&pending);
        out.push_str(&i.to_string());
        for (v, &k) in varies.iter().zip(combo) {
            out.push(',');
            out.push_str(&quote(&v.values[k]));
        }
        out.push(',');
        out.push_str(&quote(r.status.lines().next().unwrap_or("")));
        out.push_str(&format!(",{:.6}", r.wall_s));
        for n in &names {
            out.push(',');
            if let Some((_, x)) = r.figures.iter().find(|(m, _)| m == n) {
                out.push_str(&format!("{x:.12e}"));
            }
        }
        out.push('\n');
    }
    out
}

/// `<stem>.png`: `figure` against the first varied value (numeric), one
/// line per value of the second.
fn plot(
    stem: &Path,
    name: &str,
    figure: &str,
    varies: &[Vary],
    combos: &[Vec<usize>],
    rows: &[Row],
) -> Result<()> {
    let Some(first) = varies.first() else {
        return Ok(());
    };
    // (series, x, y) of every run that has the figure and a numeric x.
    let points: Vec<(usize, f64, f64)> = combos
        .iter()
        .zip(rows)
        .filter_map(|(c, r)| {
            let x = first.numbers[c[0]]?;
            let y = r.figures.iter().find(|(m, _)| m == figure)?.1;
            let series = c.get(1).copied().unwrap_or(0);
            (x.is_finite() && y.is_finite()).then_some((series, x, y))
        })
        .collect();
    if points.is_empty() {
        eprintln!(
            "sweep: no run has a numeric `{figure}` against {}: no plot",
            first.path
        );
        return Ok(());
    }
    let series: Vec<(String, Vec<(f64, f64)>)> = match varies.get(1) {
        Some(second) => (0..second.values.len())
            .map(|s| {
                let pts = points
                    .iter()
                    .filter(|p| p.0 == s)
                    .map(|p| (p.1, p.2))
                    .collect();
                (format!("{} = {}", second.path, second.values[s]), pts)
            })
            .collect(),
        None => vec![(
            figure.to_string(),
            points.iter().map(|p| (p.1, p.2)).collect(),
        )],
    };
    let title = format!("{name}: {figure} against {}", first.path);
    plot_lines(stem, &title, &first.path, figure, first.log, &series)
}

/// Lines of (x, y) points, x on a log scale when `log` (as log10 x).
fn plot_lines(
    stem: &Path,
    title: &str,
    x_name: &str,
    y_name: &str,
    log: bool,
    series: &[(String, Vec<(f64, f64)>)],
) -> Result<()> {
    use plotters::prelude::*;
    let fx = |x: f64| if log { x.log10() } else { x };
    let all = || series.iter().flat_map(|(_, p)| p.iter());
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in all() {
        (x0, x1) = (x0.min(fx(x)), x1.max(fx(x)));
        (y0, y1) = (y0.min(y), y1.max(y));
    }
    let pad = |a: f64, b: f64| {
        let d = (b - a).abs().max(1e-12 * a.abs().max(1.0));
        (a - 0.05 * d, b + 0.05 * d)
    };
    let ((x0, x1), (y0, y1)) = (pad(x0, x1), pad(y0, y1));
    crate::compare::register_font();
    let size = (900u32, 500u32);
    let mut rgb = vec![255u8; 3 * (size.0 * size.1) as usize];
    {
        let e = |e: &dyn std::fmt::Display| anyhow::anyhow!("{}: {e}", stem.display());
        let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
        root.fill(&WHITE).map_err(|x| e(&x))?;
        let root = root.titled(title, ("sans-serif", 20)).map_err(|x| e(&x))?;
        let mut chart = ChartBuilder::on(&root)
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(80)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|x| e(&x))?;
        let x_desc = if log {
            format!("log10 {x_name}")
        } else {
            x_name.to_string()
        };
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc(with_unit(y_name))
            .draw()
            .map_err(|x| e(&x))?;
        for (k, (label, pts)) in series.iter().enumerate() {
            let color = Palette99::pick(k).to_rgba();
            let line: Vec<(f64, f64)> = pts.iter().map(|&(x, y)| (fx(x), y)).collect();
            chart
                .draw_series(LineSeries::new(line.clone(), color.stroke_width(2)))
                .map_err(|x| e(&x))?
                .label(label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
            chart
                .draw_series(line.iter().map(|&p| Circle::new(p, 3, color.filled())))
                .map_err(|x| e(&x))?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|x| e(&x))?;
        root.present().map_err(|x| e(&x))?;
    }
    crate::compare::write_png(&stem.with_extension("png"), size, &rgb)
}

/// A figure's name with its unit where the name does not already say it
/// (tip coordinates are metres; `f1_hz`, `wall_s` and `_mm` say theirs).
fn with_unit(name: &str) -> String {
    let says = ["_hz", "_s", "_mm", "_m"].iter().any(|u| name.ends_with(u));
    match name.starts_with("tip_") && !says {
        true => format!("{name} (m)"),
        false => name.to_string(),
    }
}
