//! `softarm._softarm`: the Rust core for Python. A thin layer: numpy in and
//! out, every error a Python exception (model errors `ValueError` with the
//! key path, a failed integration `IntegrationError`, a `RuntimeError`),
//! never a panic across the boundary. The Pythonic surface (keyword
//! arguments, dicts, docstrings) is `python/softarm/__init__.py`; the
//! runs themselves are the CLI's (`softarm::run`), so a result here is the
//! CLI's to the bit.

use nalgebra::{DMatrix, DVector};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1};
use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use runtime::N_OUTPUTS;
use runtime::signal::Signal;
use softarm::backend::{BackendChoice, Loaded, load};
use softarm::run::RunRequest;

mod simulator;

create_exception!(
    _softarm,
    IntegrationError,
    PyRuntimeError,
    "The integrator gave up: args are (message, report as JSON)."
);

/// A matrix and a vector for Python.
type MatVec<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>);

/// A failed integration as IntegrationError((message, report JSON)).
pub(crate) fn integration_error(f: &runtime::SimFailure) -> PyErr {
    let report = serde_json::json!({
        "t_reached": f.t_reached, "last_step_s": f.last_step_s,
        "reason": f.reason, "suggestion": f.suggestion, "state": f.state,
    });
    IntegrationError::new_err((f.to_string(), report.to_string()))
}

/// A model error (a bad file, key or value) as ValueError, with its whole
/// chain of context (file, key path, what is allowed).
pub(crate) fn value_error(e: anyhow::Error) -> PyErr {
    PyValueError::new_err(format!("{e:#}"))
}

/// A value moved into `Python::detach`, which runs its closure on this
/// same thread without the GIL: the model's dynamics are not `Send`
/// (interior caches), but they never leave the thread, and `&mut self`
/// keeps every other caller out while the GIL is released.
struct AssertSend<T>(T);
// SAFETY: `detach` runs the closure synchronously on the calling thread;
// the value is never touched from another thread (see above).
unsafe impl<T> Send for AssertSend<T> {}

impl<T> AssertSend<T> {
    fn into_inner(self) -> T {
        self.0
    }
}

/// A loaded model: its compiled (or interpreted) dynamics and its file.
#[pyclass(unsendable, module = "softarm._softarm")]
struct Model {
    loaded: Loaded,
    /// How it was loaded: a simulator loads its own copy.
    spec: String,
    overrides: Vec<String>,
    /// Channels this copy's runs take from Python instead of the model.
    replaced: std::collections::BTreeMap<String, Signal>,
}

/// A vector of `n` finite values, or a ValueError naming it.
pub(crate) fn vector(name: &str, v: Option<PyReadonlyArray1<f64>>, n: usize) -> PyResult<Vec<f64>> {
    let Some(v) = v else {
        return Ok(vec![0.0; n]);
    };
    let v = v.as_slice()?.to_vec();
    if v.len() != n {
        return Err(PyValueError::new_err(format!(
            "{name} has {} values; the model has {n}",
            v.len()
        )));
    }
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "{name}[{i}] is {}, not a finite number",
            v[i]
        )));
    }
    Ok(v)
}

#[pymethods]
impl Model {
    /// `softarm fit` on this model: fit.json's content as JSON text.
    /// `free` as the command line's `--free` ("PATH" or "PATH=LO:HI"),
    /// `validate` as its `--validate` ("A:B" or a model).
    #[pyo3(signature = (free, window=None, validate=None, rtol=None, atol=None, max_iterations=40))]
    #[allow(clippy::too_many_arguments)]
    fn fit(
        &self,
        py: Python<'_>,
        free: Vec<String>,
        window: Option<(f64, f64)>,
        validate: Option<String>,
        rtol: Option<f64>,
        atol: Option<f64>,
        max_iterations: usize,
    ) -> PyResult<String> {
        use softarm::fit;
        let overrides = (self.overrides.iter())
            .map(|s| eomgen::model::Override::parse(s))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        let free = (free.iter())
            .map(|s| fit::Free::parse(s))
            .collect::<anyhow::Result<Vec<_>>>()
            .map_err(value_error)?;
        let validate = (validate.as_deref())
            .map(fit::Validation::parse)
            .transpose()
            .map_err(value_error)?;
        let req = fit::Request {
            model: self.spec.clone(),
            overrides,
            free,
            window: window.map(|(a, b)| [a, b]),
            validate,
            run: RunRequest {
                rtol,
                atol,
                ..Default::default()
            },
            cache_dir: None,
            lm: fit::lm::Options {
                max_iterations,
                ..Default::default()
            },
        };
        let prepared = fit::prepare(&req).map_err(value_error)?;
        let fitted = py
            .detach(|| prepared.fit(&req.lm, &mut |_, _| {}))
            .map_err(value_error)?;
        Ok(fit::report::json(&fitted).to_string())
    }

    /// A stepping simulator of its own copy of the model (see
    /// `simulator.rs`).
    #[pyo3(signature = (dt, inputs=Vec::new(), solver=None, rtol=None, atol=None, step=None))]
    fn simulator(
        &self,
        dt: f64,
        inputs: Vec<String>,
        solver: Option<String>,
        rtol: Option<f64>,
        atol: Option<f64>,
        step: Option<f64>,
    ) -> PyResult<simulator::Simulator> {
        let loaded = load_with(&self.spec, &self.overrides)?;
        let req = RunRequest {
            t_end: Some(dt),
            solver,
            rtol,
            atol,
            dt: step,
            ..Default::default()
        };
        simulator::Simulator::new(loaded, dt, inputs, req)
    }

    #[getter]
    fn name(&self) -> String {
        self.loaded.model.name.clone()
    }
    #[getter]
    fn dof(&self) -> usize {
        self.loaded.arm.dof()
    }
    #[getter]
    fn coordinates(&self) -> Vec<String> {
        self.loaded.arm.info().coordinates.clone()
    }
    #[getter]
    fn parameters(&self) -> Vec<String> {
        self.loaded.arm.info().parameters.clone()
    }
    #[getter]
    fn backend(&self) -> &'static str {
        self.loaded.arm.backend()
    }
    #[getter]
    fn origin(&self) -> String {
        self.loaded.origin.clone()
    }

    /// (A, B, C, D, q0, u0) about the equilibrium under u0 (or q0), on a
    /// copy of the model (its channels stay as they are here).
    #[pyo3(signature = (inputs=Vec::new(), u0=None, q0=None))]
    fn linearize<'py>(
        &self,
        py: Python<'py>,
        inputs: Vec<String>,
        u0: Option<PyReadonlyArray1<f64>>,
        q0: Option<PyReadonlyArray1<f64>>,
    ) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        let mut loaded = load_with(&self.spec, &self.overrides)?;
        let n = self.dof();
        let u0 = u0
            .map(|v| vector("u0", Some(v), inputs.len()))
            .transpose()?;
        let q0 = q0.map(|v| vector("q0", Some(v), n)).transpose()?;
        let lin = softarm::linearize::linearize(&mut loaded, &inputs, u0.as_deref(), q0.as_deref())
            .map_err(value_error)?;
        let matrix = |m: &DMatrix<f64>| {
            Array2::from_shape_fn((m.nrows(), m.ncols()), |(i, j)| m[(i, j)])
                .into_pyarray(py)
                .into_any()
        };
        let items: Vec<Bound<'py, PyAny>> = vec![
            matrix(&lin.a),
            matrix(&lin.b),
            matrix(&lin.c),
            matrix(&lin.d),
            lin.q0.into_pyarray(py).into_any(),
            lin.u0.into_pyarray(py).into_any(),
        ];
        pyo3::types::PyTuple::new(py, items)
    }

    /// The right-hand side's Jacobian d(q', qd')/d(q, qd) (2n x 2n) at
    /// (q, qd, t): the generated analytic one the implicit solvers use.
    #[pyo3(signature = (q, qd=None, t=0.0))]
    fn jacobian<'py>(
        &self,
        py: Python<'py>,
        q: PyReadonlyArray1<f64>,
        qd: Option<PyReadonlyArray1<f64>>,
        t: f64,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let n = self.dof();
        let x: Vec<f64> = vector("q", Some(q), n)?
            .into_iter()
            .chain(vector("qd", qd, n)?)
            .collect();
        let mut ws = runtime::Workspace::new(n);
        let mut jac = DMatrix::zeros(2 * n, 2 * n);
        runtime::rhs_jacobian(&*self.loaded.arm, &mut ws, t, &x, &mut jac)
            .map_err(|e| PyRuntimeError::new_err(format!("{}: {e}", self.loaded.origin)))?;
        Ok(Array2::from_shape_fn((2 * n, 2 * n), |(i, j)| jac[(i, j)]).into_pyarray(py))
    }

    /// (M, h) at (q, qd, t): M qdd + h = 0.
    #[pyo3(signature = (q, qd=None, t=0.0))]
    fn mass_bias<'py>(
        &self,
        py: Python<'py>,
        q: PyReadonlyArray1<f64>,
        qd: Option<PyReadonlyArray1<f64>>,
        t: f64,
    ) -> PyResult<MatVec<'py>> {
        let n = self.dof();
        let q = vector("q", Some(q), n)?;
        let qd = vector("qd", qd, n)?;
        let (mut m, mut h) = (DMatrix::zeros(n, n), DVector::zeros(n));
        self.loaded.arm.mass_bias(t, &q, &qd, &mut m, &mut h);
        let m = Array2::from_shape_fn((n, n), |(i, j)| m[(i, j)]);
        Ok((m.into_pyarray(py), h.as_slice().to_vec().into_pyarray(py)))
    }

    /// The base parameters at times `t`, a row a time (`parameters`'
    /// order): the model's values with its inputs applied, what the
    /// kernels read then (and what an exported C library or FMU is given).
    fn parameters_at<'py>(
        &self,
        py: Python<'py>,
        t: PyReadonlyArray1<f64>,
    ) -> Bound<'py, PyArray2<f64>> {
        let t = t
            .as_slice()
            .map(<[f64]>::to_vec)
            .unwrap_or_else(|_| t.as_array().to_vec());
        let nb = self.loaded.arm.info().parameters.len();
        let rows: Vec<Vec<f64>> = (t.iter())
            .map(|&t| self.loaded.arm.params_at(t)[..nb].to_vec())
            .collect();
        Array2::from_shape_fn((rows.len(), nb), |(i, j)| rows[i][j]).into_pyarray(py)
    }

    /// The outputs at (q, qd, t): tip x, y, z, kinetic and potential
    /// energy, tip orientation w, x, y, z.
    #[pyo3(signature = (q, qd=None, t=0.0))]
    fn outputs<'py>(
        &self,
        py: Python<'py>,
        q: PyReadonlyArray1<f64>,
        qd: Option<PyReadonlyArray1<f64>>,
        t: f64,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let n = self.dof();
        let q = vector("q", Some(q), n)?;
        let qd = vector("qd", qd, n)?;
        Ok(self
            .loaded
            .arm
            .outputs(t, &q, &qd)
            .to_vec()
            .into_pyarray(py))
    }

    /// The static equilibrium from q0: (q, residual, iterations).
    #[pyo3(signature = (q0=None))]
    fn equilibrium<'py>(
        &mut self,
        py: Python<'py>,
        q0: Option<PyReadonlyArray1<f64>>,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, f64, usize)> {
        let n = self.dof();
        let q0 = q0.map(|v| vector("q0", Some(v), n)).transpose()?;
        let (q0, _) =
            softarm::run::start_coordinates(&self.loaded, q0.as_deref()).map_err(value_error)?;
        let sol = runtime::solve_static(&mut *self.loaded.arm, &q0, &Default::default())
            .map_err(|e| PyRuntimeError::new_err(format!("{}: {e}", self.loaded.origin)))?;
        Ok((sol.q.into_pyarray(py), sol.residual, sol.iterations))
    }

    /// Mode shapes (columns) and natural frequencies (Hz) about q.
    fn modes<'py>(&self, py: Python<'py>, q: PyReadonlyArray1<f64>) -> PyResult<MatVec<'py>> {
        let n = self.dof();
        let q = vector("q", Some(q), n)?;
        let m = runtime::modes(&*self.loaded.arm, &q)
            .map_err(|e| PyRuntimeError::new_err(format!("{}: {e}", self.loaded.origin)))?;
        let k = m.shapes.len();
        let shapes = Array2::from_shape_fn((n, k), |(i, j)| m.shapes[j][i]);
        Ok((shapes.into_pyarray(py), m.frequencies_hz.into_pyarray(py)))
    }

    /// Integrate as `softarm simulate` does: (t, states, outputs, summary
    /// JSON); states (N, 2n) are q then qd, outputs (N, 9).
    #[pyo3(signature = (t_end=None, solver=None, rtol=None, atol=None, dt=None,
                        output_dt=None, max_steps=None, q0=None, qd0=None, start=None,
                        inputs=Vec::new(), rho_inf=None))]
    #[allow(clippy::too_many_arguments)]
    fn simulate<'py>(
        &mut self,
        py: Python<'py>,
        t_end: Option<f64>,
        solver: Option<String>,
        rtol: Option<f64>,
        atol: Option<f64>,
        dt: Option<f64>,
        output_dt: Option<f64>,
        max_steps: Option<usize>,
        q0: Option<PyReadonlyArray1<f64>>,
        qd0: Option<PyReadonlyArray1<f64>>,
        start: Option<String>,
        inputs: Vec<(String, Vec<f64>, Vec<f64>)>,
        rho_inf: Option<f64>,
    ) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        // Channels given as samples in time (linear between them) replace
        // the model's for this run, on a copy of the model.
        if !inputs.is_empty() {
            let mut copy = Model {
                loaded: load_with(&self.spec, &self.overrides)?,
                spec: self.spec.clone(),
                overrides: self.overrides.clone(),
                replaced: Default::default(),
            };
            let names: Vec<String> = inputs.iter().map(|(n, ..)| n.clone()).collect();
            let controls =
                softarm::inputs::Controls::new(&copy.loaded.model, &copy.loaded.base_dir, &names)
                    .map_err(value_error)?;
            for (i, (name, t, v)) in inputs.into_iter().enumerate() {
                let table = runtime::signal::Table::new(t, v)
                    .map_err(|e| PyValueError::new_err(format!("inputs[{name:?}]: {e}")))?;
                let signal = Signal::Table(table);
                controls.drive(&mut *copy.loaded.arm, i, &signal);
                copy.replaced.insert(name, signal);
            }
            return copy.simulate(
                py,
                t_end,
                solver,
                rtol,
                atol,
                dt,
                output_dt,
                max_steps,
                q0,
                qd0,
                start,
                Vec::new(),
                rho_inf,
            );
        }
        let n = self.dof();
        let start = match start.as_deref() {
            None => None,
            Some("rest") => Some(eomgen::model::Start::Rest),
            Some("static") => Some(eomgen::model::Start::Static),
            Some(s) => {
                return Err(PyValueError::new_err(format!(
                    "start = {s:?}: the starts are \"rest\" and \"static\""
                )));
            }
        };
        let req = RunRequest {
            t_end,
            solver,
            dt,
            rtol,
            atol,
            max_steps,
            output_dt,
            q0: q0.map(|v| vector("q0", Some(v), n)).transpose()?,
            qd0: qd0.map(|v| vector("qd0", Some(v), n)).transpose()?,
            start,
            rho_inf,
        };
        let mut opts =
            softarm::run::options(&req, &self.loaded.model.simulate).map_err(value_error)?;
        softarm::run::rows_in_memory(&opts).map_err(value_error)?;
        let (x0, _) = softarm::run::initial_state(&req, &mut self.loaded).map_err(value_error)?;
        // A compared model samples at the measured times, as the CLI does.
        let measured = softarm::run::measured(&self.loaded, &x0).map_err(value_error)?;
        if let Some(m) = &measured {
            opts.output_times = Some(softarm::run::compare_times(m, opts.t_end));
        }
        // Ctrl-C: the run asks Python for pending signals now and then.
        opts.interrupt = Some(runtime::Interrupt(std::sync::Arc::new(|| {
            Python::attach(|py| py.check_signals().is_err())
        })));
        let arm = &*self.loaded.arm;
        // The run releases the GIL: other Python threads go on meanwhile.
        let job = AssertSend((arm, x0, &opts));
        let result = py
            .detach(move || {
                // (Through a method: the closure takes `job` whole.)
                let (arm, x0, opts) = job.into_inner();
                AssertSend(runtime::simulate(arm, x0, opts))
            })
            .0;
        let (traj, stats) = match result {
            Ok(r) => r,
            Err(f) if f.reason == runtime::INTERRUPTED => {
                return Err(pyo3::exceptions::PyKeyboardInterrupt::new_err(format!(
                    "the run stopped at t = {} s",
                    f.t_reached
                )));
            }
            Err(f) => return Err(integration_error(&f)),
        };
        // trajectory.csv's table, built as the CLI builds it: the states,
        // the outputs, and every column after them (the joints' and the
        // contacts' forces) by name.
        let tips = softarm::run::ArmTips::of(&self.loaded);
        let table = softarm::run::Table::of(arm, tips.as_ref(), &traj);
        let rows = table.rows.len();
        let outs_at = 1 + 2 * n;
        let forces_at = softarm::run::Table::forces_from(n);
        let states = Array2::from_shape_fn((rows, 2 * n), |(i, j)| table.rows[i][1 + j]);
        let outputs = Array2::from_shape_fn((rows, N_OUTPUTS), |(i, j)| table.rows[i][outs_at + j]);
        let names = table.names[forces_at..].to_vec();
        let columns =
            Array2::from_shape_fn((rows, names.len()), |(i, j)| table.rows[i][forces_at + j]);
        let tip_error = measured.as_ref().and_then(|m| {
            let tips = softarm::run::tips(&self.loaded, &traj);
            softarm::run::tip_error(&self.loaded, m, &tips).ok()
        });
        let summary =
            softarm::run::summary(&self.loaded, &opts, &stats, &traj, tip_error.as_ref(), None);
        let (channel_names, channel_values) = self.channels_at(&traj.t)?;
        let t = traj.t.into_pyarray(py);
        let items: Vec<Bound<'py, PyAny>> = vec![
            t.into_any(),
            states.into_pyarray(py).into_any(),
            outputs.into_pyarray(py).into_any(),
            summary.to_string().into_pyobject(py)?.into_any(),
            names.into_pyobject(py)?.into_any(),
            columns.into_pyarray(py).into_any(),
            channel_names.into_pyobject(py)?.into_any(),
            channel_values.into_pyarray(py).into_any(),
        ];
        pyo3::types::PyTuple::new(py, items)
    }
}

impl Model {
    /// Every input channel's name and its values at times `t` (a column a
    /// channel), the channels this run replaced included.
    fn channels_at(&self, t: &[f64]) -> PyResult<(Vec<String>, Array2<f64>)> {
        let mut channels = Vec::new();
        for (name, input) in &self.loaded.model.inputs {
            let signal = match self.replaced.get(name) {
                Some(s) => s.clone(),
                None => softarm::inputs::signal(name, input, &self.loaded.base_dir)
                    .map_err(value_error)?,
            };
            channels.push((
                name.clone(),
                t.iter().map(|&t| signal.at(t)).collect::<Vec<_>>(),
            ));
        }
        let names = channels.iter().map(|(n, _)| n.clone()).collect();
        let values = Array2::from_shape_fn((t.len(), channels.len()), |(i, j)| channels[j].1[i]);
        Ok((names, values))
    }
}

/// Load a model file or a compiled-in model by name, with `--set`
/// overrides ("PATH=VALUE").
#[pyfunction]
#[pyo3(signature = (spec, overrides=Vec::new()))]
fn load_model(spec: &str, overrides: Vec<String>) -> PyResult<Model> {
    let loaded = load_with(spec, &overrides)?;
    Ok(Model {
        loaded,
        spec: spec.to_string(),
        overrides,
        replaced: Default::default(),
    })
}

fn load_with(spec: &str, overrides: &[String]) -> PyResult<Loaded> {
    let parsed = overrides
        .iter()
        .map(|s| eomgen::model::Override::parse(s))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    load(spec, &parsed, BackendChoice::Auto, None).map_err(value_error)
}

/// A sweep's grid (`softarm sweep`'s): the keys, each key's values as
/// `--set` takes them, and every combination as value indices.
#[pyfunction]
#[allow(clippy::type_complexity)]
#[pyo3(signature = (specs, yes = false))]
fn sweep_grid(
    specs: Vec<String>,
    yes: bool,
) -> PyResult<(Vec<String>, Vec<Vec<String>>, Vec<Vec<usize>>)> {
    let varies = specs
        .iter()
        .map(|s| softarm::grid::Vary::parse(s))
        .collect::<anyhow::Result<Vec<_>>>()
        .map_err(value_error)?;
    softarm::grid::checked_size(&varies, yes, "yes=True").map_err(value_error)?;
    let combos = softarm::grid::grid(&varies);
    Ok((
        varies.iter().map(|v| v.path.clone()).collect(),
        varies.into_iter().map(|v| v.values).collect(),
        combos,
    ))
}

/// The compiled-in models' names.
#[pyfunction]
fn models() -> Vec<&'static str> {
    softarm::generated::MODELS.iter().map(|m| m.name).collect()
}

#[pymodule]
fn _softarm(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Model>()?;
    m.add_class::<simulator::Simulator>()?;
    m.add_function(wrap_pyfunction!(load_model, m)?)?;
    m.add_function(wrap_pyfunction!(models, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_grid, m)?)?;
    m.add("IntegrationError", m.py().get_type::<IntegrationError>())?;
    m.add("OUTPUT_NAMES", runtime::OUTPUT_NAMES.to_vec())?;
    Ok(())
}
