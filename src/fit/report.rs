//! What `softarm fit` writes: fit.json (the values, their standard
//! errors and correlations, the costs), fitted.toml (the model with the
//! fitted values written in) and fit.png / fit.svg (measured, start and
//! fitted tip against time, the validation window shaded).

use anyhow::Result;
use eomgen::atomic_write::write_atomic;
use serde_json::{Map, Value, json};

use super::{Fitted, Problem};
use crate::compare::{Curve, Measured, plot_curves};
use crate::output_dir::OutputDir;

/// fit.json's content.
pub fn json(f: &Fitted) -> Value {
    let by_name = |values: &[f64]| -> Map<String, Value> {
        (f.names.iter().zip(values))
            .map(|(n, v)| (n.clone(), finite(*v)))
            .collect()
    };
    let correlation: Map<String, Value> = (f.names.iter().enumerate())
        .map(|(a, n)| {
            let row: Map<String, Value> = (f.names.iter().enumerate())
                .map(|(b, m)| (m.clone(), finite(f.correlation[(a, b)])))
                .collect();
            (n.clone(), Value::Object(row))
        })
        .collect();
    let mut warnings: Vec<String> = (f.at_bound.iter())
        .map(|n| format!("{n} ended on a bound: widen it if the bound is not physical"))
        .collect();
    warnings.extend(f.inseparable.iter().map(|(a, b, c)| {
        format!(
            "{a} and {b} have correlation {c:.4}: the data cannot separate them; fix one of them"
        )
    }));
    json!({
        "parameters": by_name(&f.values),
        "initial": by_name(&f.initial),
        "std_error": by_name(&f.std_error),
        "correlation": correlation,
        "cost": {
            "measure": "mean Euclidean tip error (m)",
            "fit": f.fit_cost,
            "validation": f.validation_cost,
        },
        "iterations": f.iterations,
        "evaluations": f.evaluations,
        "wall_s": f.wall_s,
        "status": match (f.interrupted, f.converged) {
            (true, _) => "interrupted",
            (false, true) => "converged",
            (false, false) => "not converged",
        },
        "reason": f.status,
        "at_bound": f.at_bound,
        "warnings": warnings,
    })
}

/// JSON has no infinity: a value the data do not determine is null.
fn finite(v: f64) -> Value {
    if v.is_finite() { json!(v) } else { Value::Null }
}

/// fit.json, fitted.toml and the plot into `dir`.
pub fn write(
    dir: &mut OutputDir,
    problem: &Problem,
    f: &Fitted,
    validation_window: Option<[f64; 2]>,
) -> Result<()> {
    let text = serde_json::to_string_pretty(&json(f))?;
    write_atomic(&dir.file("fit.json")?, text.as_bytes())?;
    let tree = problem.tree_at(&f.values)?;
    let header = format!(
        "# {} with the values `softarm fit` found on {} to {} s of its record\n# ({}); data files by absolute path.\n",
        problem.label(),
        f.fit_cost.window_s[0],
        f.fit_cost.window_s[1],
        f.names.join(", ")
    );
    let model = format!("{header}{}", toml::to_string_pretty(&tree)?);
    write_atomic(&dir.file("fitted.toml")?, model.as_bytes())?;
    let run = &f.fitted_run;
    let measured = Measured {
        t: run.t.clone(),
        tip: run.measured.clone(),
    };
    let points = |e: &super::Evaluation| -> Vec<(f64, [f64; 3])> {
        e.t.iter().copied().zip(e.tip.iter().copied()).collect()
    };
    let (start, fitted) = (points(&f.start_run), points(run));
    let curves = [
        Curve {
            label: "start values",
            color: plotters::style::RGBColor(120, 120, 220),
            points: &start,
        },
        Curve {
            label: "fitted",
            color: plotters::style::RED,
            points: &fitted,
        },
    ];
    let title = format!(
        "{}: mean tip error {:.2} -> {:.2} mm on the fit window",
        problem.label(),
        1e3 * f.fit_cost.initial,
        1e3 * f.fit_cost.fitted
    );
    plot_curves(
        &dir.plot("fit")?,
        &title,
        &curves,
        Some(&measured),
        validation_window,
    )
}
