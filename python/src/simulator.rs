//! A stepping simulator for closed-loop control: `step(u)` holds the
//! controlled input channels at u (zero-order hold) and integrates one
//! control step from the current state with the run's solver; the state
//! can be read, set and reset. Each step is a `runtime::simulate` from
//! (t, x) to t + dt sampled at its end, so a sequence of steps with a
//! channel's values is the run that channel would give.

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use runtime::SimOptions;
use softarm::backend::Loaded;
use softarm::inputs::Controls;
use softarm::run::RunRequest;

use crate::{integration_error, value_error, vector};

#[pyclass(unsendable, module = "softarm._softarm")]
pub struct Simulator {
    loaded: Loaded,
    opts: SimOptions,
    dt: f64,
    t: f64,
    x: Vec<f64>,
    /// The start `reset` returns to.
    x0: Vec<f64>,
    controls: Controls,
}

impl Simulator {
    /// `req`: the solver and its tolerances and fixed step; its t_end is
    /// the control step dt.
    pub fn new(
        mut loaded: Loaded,
        dt: f64,
        inputs: Vec<String>,
        req: RunRequest,
    ) -> PyResult<Self> {
        if !(dt > 0.0 && dt.is_finite()) {
            return Err(PyValueError::new_err(format!(
                "dt = {dt}: must be a positive step (s)"
            )));
        }
        let opts = softarm::run::options(&req, &loaded.model.simulate).map_err(value_error)?;
        let (x0, _) = softarm::run::initial_state(&req, &mut loaded).map_err(value_error)?;
        let controls =
            Controls::new(&loaded.model, &loaded.base_dir, &inputs).map_err(value_error)?;
        let mut sim = Self {
            loaded,
            opts,
            dt,
            t: 0.0,
            x: x0.clone(),
            x0,
            controls,
        };
        // Until the first step, the channels hold zero.
        sim.hold(&vec![0.0; sim.controls.names.len()]);
        Ok(sim)
    }

    fn hold(&mut self, u: &[f64]) {
        self.controls.hold(&mut *self.loaded.arm, u);
    }

    /// The next step begins a run of its own: how the contacts began is
    /// the last run's, not this start's.
    fn new_start(&mut self) {
        self.opts.continues = false;
    }
}

#[pymethods]
impl Simulator {
    /// Hold the inputs at u over one step of dt; the new state (q, qd).
    #[pyo3(signature = (u=None))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        u: Option<PyReadonlyArray1<f64>>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let u = vector("u", u, self.controls.names.len())?;
        self.hold(&u);
        self.opts.t0 = self.t;
        self.opts.t_end = self.t + self.dt;
        self.opts.output_times = Some(vec![self.opts.t_end]);
        let arm = &*self.loaded.arm;
        let run = runtime::simulate(arm, self.x.clone(), &self.opts);
        // The next step goes on from this one.
        self.opts.continues = true;
        match run {
            Ok((traj, _)) => match (traj.t.last(), traj.x.last()) {
                (Some(&t), Some(x)) if t == self.opts.t_end => {
                    self.x = x.clone();
                    self.t = t;
                }
                _ => {
                    return Err(pyo3::exceptions::PyRuntimeError::new_err(format!(
                        "the step from t = {} did not reach t = {} (a bug: please report it)",
                        self.t, self.opts.t_end
                    )));
                }
            },
            Err(f) => return Err(integration_error(&f)),
        }
        Ok(self.x.clone().into_pyarray(py))
    }

    /// The state (q, qd), 2n values.
    #[getter]
    fn get_state<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.x.clone().into_pyarray(py)
    }

    #[setter]
    fn set_state(&mut self, x: PyReadonlyArray1<f64>) -> PyResult<()> {
        self.x = vector("state", Some(x), self.x.len())?;
        self.new_start();
        Ok(())
    }

    #[getter]
    fn t(&self) -> f64 {
        self.t
    }

    #[setter]
    fn set_t(&mut self, t: f64) -> PyResult<()> {
        if !t.is_finite() {
            return Err(PyValueError::new_err(format!("t = {t}: must be finite")));
        }
        self.t = t;
        Ok(())
    }

    #[getter]
    fn dt(&self) -> f64 {
        self.dt
    }

    #[getter]
    fn inputs(&self) -> Vec<String> {
        self.controls.names.clone()
    }

    /// Back to t = 0 and the start state (or the given one); inputs zero.
    #[pyo3(signature = (state=None))]
    fn reset<'py>(
        &mut self,
        py: Python<'py>,
        state: Option<PyReadonlyArray1<f64>>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.x = match state {
            Some(x) => vector("state", Some(x), self.x.len())?,
            None => self.x0.clone(),
        };
        self.t = 0.0;
        self.hold(&vec![0.0; self.controls.names.len()]);
        self.new_start();
        Ok(self.x.clone().into_pyarray(py))
    }

    /// The outputs (tip, energies, tip orientation) at the current state.
    fn outputs<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let n = self.loaded.arm.dof();
        let o = self
            .loaded
            .arm
            .outputs(self.t, &self.x[..n], &self.x[n..2 * n]);
        o.to_vec().into_pyarray(py)
    }
}
