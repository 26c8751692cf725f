//! A fit's problem: the model, its free values and its record; an
//! evaluation is a run with the tip's derivatives in the free values at
//! the record's samples.

use std::path::PathBuf;

use anyhow::{Context, Result, anyhow, bail};
use eomgen::load::model_tree;
use eomgen::model::{Override, Start};
use nalgebra::{DMatrix, DVector};
use runtime::Dynamics;
use runtime::integrate::sensitivity::{Perturbed, forward_sensitivities, static_sensitivities};
use runtime::integrate::stepper::Options;

use super::{Free, rows_in};
use crate::backend::{BackendChoice, Loaded, load, model_source};
use crate::run::RunRequest;

/// Keys that are not values of the arm or its record: what they would
/// change is the run or the comparison itself.
const NOT_VALUES: &[&str] = &[
    "name",
    "description",
    "dimensions",
    "simulate",
    "compare.window",
    "compare.smooth",
    "compare.time",
];

/// Relative size of the perturbation of a value for its difference
/// quotients: their truncation error is 1e-12 of the derivative, their
/// rounding 1e-10.
const DELTA: f64 = 1e-6;

pub struct Problem {
    spec: String,
    label: String,
    overrides: Vec<Override>,
    free: Vec<Free>,
    start: Vec<f64>,
    run: RunRequest,
    cache_dir: Option<PathBuf>,
    record: [f64; 2],
    /// The record's sample times (s).
    times: Vec<f64>,
}

/// A run at some values: the simulated and measured tip at the record's
/// samples, and the derivatives of their difference in each free value.
#[derive(Clone, Debug, Default)]
pub struct Evaluation {
    pub t: Vec<f64>,
    pub tip: Vec<[f64; 3]>,
    pub measured: Vec<[f64; 3]>,
    /// d(tip - measured)/d value, [sample][value].
    pub derivative: Vec<Vec<[f64; 3]>>,
}

impl Evaluation {
    /// The residuals (tip - measured, x y z a sample) in `window`, and
    /// their Jacobian.
    pub fn residuals(&self, window: [f64; 2]) -> (DVector<f64>, DMatrix<f64>) {
        let rows = rows_in(&self.t, window);
        let m = self.derivative.first().map_or(0, Vec::len);
        let r = DVector::from_fn(3 * rows.len(), |k, _| {
            let i = rows[k / 3];
            self.tip[i][k % 3] - self.measured[i][k % 3]
        });
        let j = DMatrix::from_fn(3 * rows.len(), m, |k, p| {
            self.derivative[rows[k / 3]][p][k % 3]
        });
        (r, j)
    }

    /// The mean Euclidean tip error (m) over the samples in `window`.
    pub fn mean_error(&self, window: [f64; 2]) -> f64 {
        let rows = rows_in(&self.t, window);
        let sum: f64 = rows
            .iter()
            .map(|&i| {
                let (a, b) = (self.tip[i], self.measured[i]);
                ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
            })
            .sum();
        sum / rows.len().max(1) as f64
    }

    pub fn samples(&self, window: [f64; 2]) -> usize {
        rows_in(&self.t, window).len()
    }
}

impl Problem {
    /// Check the model and the free values; nothing runs yet.
    pub fn new(
        spec: &str,
        overrides: Vec<Override>,
        free: Vec<Free>,
        run: RunRequest,
        cache_dir: Option<PathBuf>,
    ) -> Result<Self> {
        let base = load(spec, &overrides, BackendChoice::Auto, cache_dir.clone())?;
        let label = base.origin.clone();
        let Some(compare) = &base.model.compare else {
            bail!(
                "{label}: no [compare] section: fit needs the record to fit to (docs/model-format.md, [compare])"
            );
        };
        if !base.arm.info().constraints.is_empty() || base.arm.contact().is_some() {
            bail!(
                "{label}: fit covers arms without joints or contact: their runs switch and project, which its sensitivities do not follow yet"
            );
        }
        let src = model_source(spec)?;
        let tree = model_tree(&src.text, &src.label, src.json, &overrides)?;
        let mut start = Vec::with_capacity(free.len());
        for (k, f) in free.iter().enumerate() {
            if free[..k].iter().any(|g| g.path == f.path) {
                bail!("--free {}: given twice", f.path);
            }
            not_a_value(f)?;
            // A key the file does not set: an unknown one fails here with
            // the schema's message (and its suggestion).
            if Override::value_at(&tree, &f.path).is_none() {
                check_numeric(spec, &overrides, f, &tree, &base)?;
            }
            start.push(start_value(&tree, f, &label)?);
            check_numeric(spec, &overrides, f, &tree, &base)?;
        }
        let m = crate::compare::measured(compare, &base.base_dir, [0.0; 3])
            .map_err(|e| anyhow!("{label}: [compare]: {e:#}"))?;
        let whole = [m.t[0], *m.t.last().expect("a record has rows")];
        let record = compare.window.unwrap_or(whole);
        Ok(Self {
            spec: spec.to_string(),
            label,
            overrides,
            free,
            start,
            run,
            cache_dir,
            record,
            times: m.t,
        })
    }

    pub fn label(&self) -> &str {
        &self.label
    }

    pub fn names(&self) -> Vec<String> {
        self.free.iter().map(|f| f.path.clone()).collect()
    }

    pub fn start_values(&self) -> Vec<f64> {
        self.start.clone()
    }

    pub fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        (
            self.free.iter().map(|f| f.lo).collect(),
            self.free.iter().map(|f| f.hi).collect(),
        )
    }

    /// The size of value j: its start, else the width of its bounds, else
    /// 1 (a delay or an offset that starts at zero).
    pub fn typical(&self, j: usize) -> f64 {
        let f = &self.free[j];
        match (self.start[j], f.hi - f.lo) {
            (v, _) if v != 0.0 => v.abs(),
            (_, w) if w.is_finite() => w,
            _ => 1.0,
        }
    }

    /// The record's samples within `window`.
    pub fn samples_in(&self, window: [f64; 2]) -> usize {
        rows_in(&self.times, window).len()
    }

    /// Where a run for `window` ends: its last sample (a window may reach
    /// past the record).
    pub fn end_of(&self, window: [f64; 2]) -> f64 {
        let last = rows_in(&self.times, window).last().map(|&i| self.times[i]);
        last.unwrap_or(window[1]).max(0.0)
    }

    /// `[compare] window`, else the whole record.
    pub fn record_window(&self) -> [f64; 2] {
        self.record
    }

    /// The user's overrides and the free values at `theta`.
    pub fn overrides_at(&self, theta: &[f64]) -> Result<Vec<Override>> {
        let mut all = self.overrides.clone();
        for (f, v) in self.free.iter().zip(theta) {
            all.push(Override::parse(&format!("{}={v:e}", f.path))?);
        }
        Ok(all)
    }

    /// The model's tree of keys with the values at `theta` written in, its
    /// data files' paths made absolute (so that it runs from anywhere).
    pub fn tree_at(&self, theta: &[f64]) -> Result<toml::Value> {
        let src = model_source(&self.spec)?;
        let mut tree = model_tree(&src.text, &src.label, src.json, &self.overrides_at(theta)?)?;
        absolute_files(&mut tree, &crate::backend::base_dir(&self.spec));
        Ok(tree)
    }

    fn load_at(&self, theta: &[f64]) -> Result<Loaded> {
        let overrides = self.overrides_at(theta)?;
        load(
            &self.spec,
            &overrides,
            BackendChoice::Auto,
            self.cache_dir.clone(),
        )
    }

    /// The run at `theta` up to `t_end`, with the derivatives when
    /// `derivatives`.
    pub fn evaluate(&self, theta: &[f64], derivatives: bool, t_end: f64) -> Result<Evaluation> {
        let mut loaded = self.load_at(theta)?;
        let m = if derivatives { theta.len() } else { 0 };
        let mut pairs = Vec::with_capacity(m);
        for j in 0..m {
            let delta = DELTA * theta[j].abs().max(1e-3 * self.typical(j));
            let at = |sign: f64| {
                let mut t = theta.to_vec();
                t[j] += sign * delta;
                self.load_at(&t)
            };
            pairs.push((at(1.0)?, at(-1.0)?, delta));
        }
        let (x0, _) = crate::run::initial_state(&self.run, &mut loaded)?;
        // A viscoelastic start moves its relaxed forces with the values:
        // the centred quotient of the perturbed starts.
        let differenced = match loaded.arm.internal_len() {
            0 => None,
            _ => Some(self.start_differences(&mut pairs, &x0)?),
        };
        let perturbed: Vec<Perturbed> = (pairs.iter())
            .map(|(p, q, d)| Perturbed {
                plus: &*p.arm,
                minus: &*q.arm,
                delta: *d,
            })
            .collect();
        let arm = &*loaded.arm;
        let n = arm.dof();
        let start = self.run.start.or(loaded.model.simulate.start);
        let s0 = match (differenced, start) {
            (Some(s0), _) => s0,
            (None, Some(Start::Static)) => static_sensitivities(arm, &perturbed, 0.0, &x0[..n])
                .map_err(|e| anyhow!("{}: the start's sensitivities: {e}", self.label))?,
            _ => vec![vec![0.0; 2 * n]; m],
        };
        let measured = crate::run::measured(&loaded, &x0)?.expect("checked: it has [compare]");
        let samples: Vec<usize> = (0..measured.t.len())
            .filter(|&i| measured.t[i] >= 0.0 && measured.t[i] <= t_end)
            .collect();
        let times: Vec<f64> = samples.iter().map(|&i| measured.t[i]).collect();
        let sim = crate::run::options(&self.run, &loaded.model.simulate)?;
        let opts = Options {
            t_end,
            rtol: sim.rtol,
            atol: sim.atol,
            max_steps: sim.max_steps,
            rho_inf: sim.rho_inf,
            dt: sim.dt,
            // radau5 integrates the state and its sensitivities together.
            positions: 0,
        };
        let run =
            forward_sensitivities(arm, &perturbed, 0.0, x0.clone(), s0.clone(), &times, &opts)
                .map_err(|f| anyhow!("{}: {f}", self.label))?;
        let tip = |a: &dyn Dynamics, t: f64, x: &[f64]| {
            let o = a.outputs(t, &x[..n], &x[n..2 * n]);
            [o[0], o[1], o[2]]
        };
        // d tip/d value by the centred quotient along (x +- delta s).
        let tip_derivative = |t: f64, x: &[f64], s: &[f64], p: &Perturbed| {
            let shifted = |sign: f64| -> Vec<f64> {
                x.iter()
                    .zip(s)
                    .map(|(a, b)| a + sign * p.delta * b)
                    .collect()
            };
            let (a, b) = (
                tip(p.plus, t, &shifted(1.0)),
                tip(p.minus, t, &shifted(-1.0)),
            );
            [0, 1, 2].map(|k| (a[k] - b[k]) / (2.0 * p.delta))
        };
        let start_derivative: Vec<[f64; 3]> = (perturbed.iter().zip(&s0))
            .map(|(p, s)| tip_derivative(0.0, &x0, s, p))
            .collect();
        let record = self.record_derivatives(&loaded, &pairs, &x0, &samples)?;
        let initial_given = loaded
            .model
            .compare
            .as_ref()
            .is_some_and(|c| c.initial.is_some());
        let derivative = (0..times.len())
            .map(|i| {
                (0..m)
                    .map(|j| {
                        let d = tip_derivative(times[i], &run.x[i], &run.s[i][j], &perturbed[j]);
                        // The record starts at the simulated start tip
                        // unless `initial` is given: it moves with it.
                        let moved = if initial_given {
                            [0.0; 3]
                        } else {
                            start_derivative[j]
                        };
                        [0, 1, 2].map(|k| d[k] - moved[k] - record[i][j][k])
                    })
                    .collect()
            })
            .collect();
        Ok(Evaluation {
            tip: (0..times.len())
                .map(|i| tip(arm, times[i], &run.x[i]))
                .collect(),
            measured: samples.iter().map(|&i| measured.tip[i]).collect(),
            t: times,
            derivative,
        })
    }

    /// dx0/d value of each pair (value + delta, value - delta) by the
    /// centred quotient of their start states.
    fn start_differences(
        &self,
        pairs: &mut [(Loaded, Loaded, f64)],
        x0: &[f64],
    ) -> Result<Vec<Vec<f64>>> {
        (pairs.iter_mut())
            .map(|(plus, minus, delta)| {
                let (a, _) = crate::run::initial_state(&self.run, plus)?;
                let (b, _) = crate::run::initial_state(&self.run, minus)?;
                debug_assert_eq!(a.len(), x0.len());
                Ok(a.iter()
                    .zip(&b)
                    .map(|(a, b)| (a - b) / (2.0 * *delta))
                    .collect())
            })
            .collect()
    }

    /// d measured/d value at the samples, for values of `[compare]` (the
    /// registration: sensor offset, rotation, scale); zero for the rest.
    fn record_derivatives(
        &self,
        loaded: &Loaded,
        pairs: &[(Loaded, Loaded, f64)],
        x0: &[f64],
        samples: &[usize],
    ) -> Result<Vec<Vec<[f64; 3]>>> {
        let n = loaded.arm.dof();
        let o = loaded.arm.outputs(0.0, &x0[..n], &x0[n..2 * n]);
        let initial = [o[0], o[1], o[2]];
        let mut d = vec![vec![[0.0; 3]; pairs.len()]; samples.len()];
        for (j, (plus, minus, delta)) in pairs.iter().enumerate() {
            if !self.free[j].path.starts_with("compare.") {
                continue;
            }
            let read = |l: &Loaded| {
                let spec = l.model.compare.as_ref().expect("checked: it has [compare]");
                crate::compare::measured(spec, &l.base_dir, initial)
            };
            let (a, b) = (read(plus)?, read(minus)?);
            for (i, &s) in samples.iter().enumerate() {
                d[i][j] = [0, 1, 2].map(|k| (a.tip[s][k] - b.tip[s][k]) / (2.0 * delta));
            }
        }
        Ok(d)
    }
}

/// Every `file = "..."` below `v` as an absolute path from `base`.
fn absolute_files(v: &mut toml::Value, base: &std::path::Path) {
    match v {
        toml::Value::Table(t) => {
            for (k, item) in t.iter_mut() {
                match item {
                    toml::Value::String(s) if k == "file" => {
                        let path = crate::data::resolve(base, s);
                        let path = std::fs::canonicalize(&path).unwrap_or(path);
                        *s = path.display().to_string();
                    }
                    other => absolute_files(other, base),
                }
            }
        }
        toml::Value::Array(a) => a.iter_mut().for_each(|item| absolute_files(item, base)),
        _ => {}
    }
}

/// Keys that are not values of the arm or its record are refused.
fn not_a_value(f: &Free) -> Result<()> {
    let path = &f.path;
    if let Some(key) = NOT_VALUES
        .iter()
        .find(|k| path == *k || path.starts_with(&format!("{k}.")))
    {
        bail!(
            "--free {path}: `{key}` is not a value of the arm or its record; fit values such as segment.0.youngs_modulus, segment.0.bending_damping, tip.mass, compare.sensor_offset.0 or inputs.NAME.delay"
        );
    }
    Ok(())
}

/// The start value of a free value: the model's, as written (after the
/// user's --set), within its bounds.
fn start_value(tree: &toml::Value, f: &Free, label: &str) -> Result<f64> {
    let path = &f.path;
    let v = match Override::value_at(tree, path) {
        Some(toml::Value::Float(v)) => *v,
        Some(toml::Value::Integer(v)) => *v as f64,
        Some(other) => bail!(
            "--free {path}: {label} has {} there, not a number",
            other.type_str()
        ),
        None => bail!(
            "--free {path}: {label} does not set this value; give its start with --set {path}=VALUE"
        ),
    };
    if v < f.lo || v > f.hi {
        bail!(
            "--free {path}: the start value {v} lies outside its bounds {}:{}",
            f.lo,
            f.hi
        );
    }
    Ok(v)
}

/// A free value must change numbers only: set to a nearby value, the
/// model keeps its structure (its derived equations).
fn check_numeric(
    spec: &str,
    overrides: &[Override],
    f: &Free,
    tree: &toml::Value,
    base: &Loaded,
) -> Result<()> {
    // A whole number may be a count (elements, order): the next one.
    let near = match Override::value_at(tree, &f.path) {
        Some(toml::Value::Integer(v)) => format!("{}", v + 1),
        Some(toml::Value::Float(v)) if *v != 0.0 => format!("{:e}", v * (1.0 + 1e-3)),
        _ => "1e-3".to_string(),
    };
    let mut all = overrides.to_vec();
    all.push(Override::parse(&format!("{}={near}", f.path))?);
    let (model, _) = crate::backend::read_model(spec, &all)
        .with_context(|| format!("--free {}: the model does not take a value there", f.path))?;
    let hash = eomgen::model::Structure::of(&model).hash();
    if hash != base.hash {
        bail!(
            "--free {}: a structural value (it changes the form of the derived equations, not their numbers); fit takes numeric values only",
            f.path
        );
    }
    Ok(())
}
