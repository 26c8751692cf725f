//! A simulation's setup, shared by every front end (the CLI, Python):
//! the options asked for, else the model's `[simulate]`, else runtime's
//! defaults; the start state (given, the model's, assembled onto the
//! joints, checked against the obstacles, or the equilibrium at t = 0).
//! One place, so that a run from Python is the CLI's run to the bit.

use anyhow::{Result, anyhow, bail};
use eomgen::model::{SimulateDefaults, Start};
use runtime::{SimOptions, Solver, output};

use crate::backend::Loaded;

/// What a run is asked; `None` leaves the choice to the model's
/// `[simulate]`, then to the defaults.
#[derive(Clone, Debug, Default)]
pub struct RunRequest {
    pub t_end: Option<f64>,
    pub solver: Option<String>,
    pub dt: Option<f64>,
    pub rtol: Option<f64>,
    pub atol: Option<f64>,
    pub max_steps: Option<usize>,
    pub output_dt: Option<f64>,
    pub q0: Option<Vec<f64>>,
    pub qd0: Option<Vec<f64>>,
    pub start: Option<Start>,
    /// generalized-alpha's spectral radius at infinity.
    pub rho_inf: Option<f64>,
}

/// The run's options. Errors name the option as the command line spells
/// it (`--rtol`), which Python's keyword (`rtol`) follows.
pub fn options(req: &RunRequest, file: &SimulateDefaults) -> Result<SimOptions> {
    let defaults = SimOptions::default();
    let t_end = req.t_end.or(file.t_end).unwrap_or(defaults.t_end);
    let dt = req.dt.or(file.dt).unwrap_or(defaults.dt);
    let rtol = req.rtol.or(file.rtol).unwrap_or(defaults.rtol);
    let atol = req.atol.or(file.atol).unwrap_or(defaults.atol);
    let solver = match req.solver.as_ref().or(file.solver.as_ref()) {
        Some(name) => Solver::parse(name).ok_or_else(|| {
            anyhow!(
                "--solver {name}: unknown solver; the solvers are {}",
                Solver::NAMES.join(", ")
            )
        })?,
        None => defaults.solver,
    };
    if !(t_end > 0.0 && t_end.is_finite()) {
        bail!("--t-end must be a positive number of seconds, got {t_end}");
    }
    for (name, v) in [("--dt", dt), ("--rtol", rtol), ("--atol", atol)] {
        if !(v > 0.0 && v.is_finite()) {
            bail!("{name} must be positive, got {v}");
        }
    }
    let rho_inf = req.rho_inf.or(file.rho_inf).unwrap_or(defaults.rho_inf);
    if !(0.0..=1.0).contains(&rho_inf) {
        bail!(
            "--rho-inf must lie in [0, 1] (1: no numerical damping, 0: unresolved modes gone in a step), got {rho_inf}"
        );
    }
    let max_steps = req.max_steps.unwrap_or(defaults.max_steps);
    if max_steps == 0 {
        bail!("--max-steps must be at least 1");
    }
    let output_dt = (req.output_dt.or(file.output_dt)).unwrap_or(t_end / runtime::DEFAULT_SAMPLES);
    if !(output_dt > 0.0 && output_dt.is_finite()) {
        bail!("--output-dt must be positive, got {output_dt}");
    }
    // Options against each other, before anything runs or is written.
    if solver.fixed_step() && dt > t_end {
        bail!(
            "--dt {dt} s is longer than the run (--t-end {t_end} s): a fixed-step solver takes steps of --dt"
        );
    }
    if output_dt > t_end {
        bail!(
            "--output-dt {output_dt} s is longer than the run (--t-end {t_end} s): the trajectory would hold its first row only"
        );
    }
    let rows = (t_end / output_dt).floor() + 1.0;
    if rows > MAX_WRITTEN_ROWS as f64 {
        bail!(
            "--output-dt {} s over --t-end {t_end} s is {rows:.3e} trajectory rows; a run writes at most {MAX_WRITTEN_ROWS} (tens of gigabytes): take --output-dt {} s or longer, or a shorter --t-end",
            short(output_dt),
            short(up_to_two_digits(t_end / (MAX_WRITTEN_ROWS - 1) as f64))
        );
    }
    Ok(SimOptions {
        t_end,
        solver,
        rtol,
        atol,
        dt,
        output_dt,
        max_steps,
        rho_inf,
        ..defaults
    })
}

/// The most trajectory rows a run writes to disk (its rows stream, but a
/// hundred million are already tens of gigabytes, and a spacing far below
/// the steps would spend the run interpolating).
pub const MAX_WRITTEN_ROWS: usize = 100_000_000;

/// A run whose rows are returned in memory (Python's `simulate`) keeps at
/// most [`MAX_OUTPUT_ROWS`]; the CLI writes them as they come, any number.
pub fn rows_in_memory(opts: &SimOptions) -> Result<()> {
    let (t_end, output_dt) = (opts.t_end, opts.output_dt);
    let rows = (t_end / output_dt).floor() + 1.0;
    if rows > MAX_OUTPUT_ROWS as f64 {
        bail!(
            "--output-dt {} s over --t-end {t_end} s is {rows:.0} trajectory rows; a run returned in memory keeps at most {MAX_OUTPUT_ROWS}: take --output-dt {} s or longer, a shorter --t-end, or `softarm simulate`, which writes its rows to disk as they come",
            short(output_dt),
            short(up_to_two_digits(t_end / (MAX_OUTPUT_ROWS - 1) as f64))
        );
    }
    Ok(())
}

/// x as a person writes it: plain between 1e-4 and 1e6, else in
/// exponent form to three digits.
fn short(x: f64) -> String {
    match x.abs() {
        a if (1e-4..1e6).contains(&a) => format!("{}", (x * 1e12).round() / 1e12),
        _ => format!("{x:.3e}"),
    }
}

/// x rounded up to two significant digits (a suggestion that holds).
fn up_to_two_digits(x: f64) -> f64 {
    let unit = 10f64.powf(x.log10().floor() - 1.0);
    (x / unit).ceil() * unit
}

/// The coordinates to start from: `q0`, else the model's (`[simulate]
/// q0`, free bodies where declared, the rest 0), put onto the joints and
/// checked against the obstacles; and how far the joints moved them.
pub fn start_coordinates(loaded: &Loaded, q0: Option<&[f64]>) -> Result<(Vec<f64>, f64)> {
    let n = loaded.arm.dof();
    let coords = loaded.arm.info().coordinates.clone();
    let mut q = match q0 {
        Some(q) if q.len() != n => {
            bail!(
                "q0 has {} values; the model has {n} coordinates: {}",
                q.len(),
                coords.join(", ")
            )
        }
        Some(q) => q.to_vec(),
        None => {
            eomgen::model::assembly::initial_coordinates(&loaded.model, &coords, &loaded.origin)?
        }
    };
    if let Some(i) = q.iter().position(|v| !v.is_finite()) {
        bail!(
            "q0[{i}] ({}) is {}: the start must be finite",
            coords[i],
            q[i]
        );
    }
    let moved = crate::joints::assemble(&*loaded.arm, &loaded.origin, &mut q, &mut vec![0.0; n])?;
    crate::contact::check_start(&*loaded.arm, &loaded.origin, &q)?;
    Ok((q, moved))
}

/// The start state x0 = (q0, qd0) of a run and how far assembling moved
/// the coordinates: at rest, or (`Start::Static`) in equilibrium at t = 0
/// under the loads and inputs.
pub fn initial_state(req: &RunRequest, loaded: &mut Loaded) -> Result<(Vec<f64>, f64)> {
    let n = loaded.arm.dof();
    let (q0, moved) = start_coordinates(loaded, req.q0.as_deref())?;
    let start = req
        .start
        .or(loaded.model.simulate.start)
        .unwrap_or(Start::Rest);
    let mut q0 = match start {
        Start::Rest => q0,
        Start::Static => {
            runtime::solve_static(&mut *loaded.arm, &q0, &runtime::StaticOptions::default())
                .map_err(|e| {
                    anyhow!(
                        "{}: --start static: no equilibrium at t = 0: {e}; start from rest instead",
                        loaded.origin
                    )
                })?
                .q
        }
    };
    let mut qd0 = match &req.qd0 {
        Some(v) if v.len() != n => {
            bail!("qd0 has {} values; the model has {n} coordinates", v.len())
        }
        Some(v) => v.clone(),
        None => vec![0.0; n],
    };
    if let Some(i) = qd0.iter().position(|v| !v.is_finite()) {
        bail!("qd0[{i}] is {}: the start must be finite", qd0[i]);
    }
    // The rates onto the joints too (the coordinates already are).
    crate::joints::assemble(&*loaded.arm, &loaded.origin, &mut q0, &mut qd0)?;
    // A viscoelastic arm's relaxed forces: in equilibrium with q0 (it has
    // rested there), or none (it was deformed just before t = 0).
    let z0 = match loaded.model.simulate.start_relaxed.unwrap_or(true) {
        true => runtime::relaxed_forces::relaxed(&*loaded.arm, 0.0, &q0),
        false => vec![0.0; loaded.arm.internal_len()],
    };
    Ok((q0.into_iter().chain(qd0).chain(z0).collect(), moved))
}

/// The measured tip of the model's `[compare]` in the model frame (its
/// start at the simulated tip of x0 unless the file says), if it has one.
pub fn measured(loaded: &Loaded, x0: &[f64]) -> Result<Option<crate::compare::Measured>> {
    let Some(spec) = &loaded.model.compare else {
        return Ok(None);
    };
    let n = loaded.arm.dof();
    let start = loaded.arm.outputs(0.0, &x0[..n], &x0[n..2 * n]);
    let m = crate::compare::measured(spec, &loaded.base_dir, [start[0], start[1], start[2]])
        .map_err(|e| anyhow!("{}: [compare]: {e:#}", loaded.origin))?;
    Ok(Some(m))
}

/// A compared run's output times: the measured ones up to t_end, and t_end.
pub fn compare_times(m: &crate::compare::Measured, t_end: f64) -> Vec<f64> {
    let mut t: Vec<f64> = m.t.iter().copied().filter(|&t| t <= t_end).collect();
    if t.last() != Some(&t_end) {
        t.push(t_end);
    }
    t
}

/// The simulated tip at every row of a trajectory.
pub fn tips(loaded: &Loaded, traj: &runtime::Trajectory) -> Vec<(f64, [f64; 3])> {
    let n = loaded.arm.dof();
    (traj.t.iter().zip(&traj.x))
        .map(|(t, x)| {
            let o = loaded.arm.outputs(*t, &x[..n], &x[n..2 * n]);
            (*t, [o[0], o[1], o[2]])
        })
        .collect()
}

/// The tip error over `[compare]`'s window (default: the whole record),
/// relative to the arm's length with its tip body; an error when the run
/// ended before the window.
pub fn tip_error(
    loaded: &Loaded,
    m: &crate::compare::Measured,
    tips: &[(f64, [f64; 3])],
) -> Result<crate::compare::TipError> {
    let spec = loaded
        .model
        .compare
        .as_ref()
        .ok_or_else(|| anyhow!("{}: no [compare]", loaded.origin))?;
    let window = spec
        .window
        .unwrap_or([m.t[0], *m.t.last().expect("a CSV has rows")]);
    let length = loaded.model.segments.iter().map(|s| s.length).sum::<f64>()
        + loaded.model.tip.length.unwrap_or(0.0);
    crate::compare::tip_error(m, window, length, |t| {
        tips.iter().find(|s| (s.0 - t).abs() < 1e-9).map(|s| s.1)
    })
}

/// Each arm's tip (x, y, z) in a model of several arms, as trajectory.csv's
/// last columns (`ARM.tip_x`, ...): the `Outputs` kernel's tip is the
/// first arm's. From the shape's tape at one point per element.
pub struct ArmTips {
    tape: eomgen::shape::ShapeTape,
}

impl ArmTips {
    /// None for a model of one arm (its tip is `tip_x`, ...).
    pub fn of(loaded: &Loaded) -> Option<Self> {
        let structure = eomgen::model::Structure::of(&loaded.model);
        let arms = structure.assembly.as_ref().map_or(1, |a| a.arms.len());
        (arms > 1).then(|| Self {
            tape: eomgen::shape::shape_tape(&structure, 1),
        })
    }

    pub fn names(&self) -> Vec<String> {
        (self.tape.arms.iter())
            .flat_map(|a| ["x", "y", "z"].map(|c| format!("{}.tip_{c}", a.name)))
            .collect()
    }

    /// The tips at time t, coordinates q: 3 values an arm.
    pub fn at(&self, arm: &dyn runtime::Dynamics, t: f64, q: &[f64]) -> Vec<f64> {
        let out = self.tape.eval(t, q, &arm.params_at(t));
        let mut first = 0;
        let mut tips = Vec::with_capacity(3 * self.tape.arms.len());
        for a in &self.tape.arms {
            let last = first + a.rows() - 1;
            tips.extend_from_slice(&out[last * eomgen::shape::ROW..last * eomgen::shape::ROW + 3]);
            first += a.rows();
        }
        tips
    }
}

/// The most trajectory rows a run returned in memory keeps (a
/// 30-coordinate arm's million rows are about a gigabyte with their
/// outputs).
pub const MAX_OUTPUT_ROWS: usize = 1_000_000;

/// A run's table, every column of `trajectory.csv` by name: t, the
/// coordinates, their rates (`<name>_dot`), the outputs
/// (`runtime::OUTPUT_NAMES`), the joints' forces and moments, the
/// contacts' forces, each arm's tip, a viscoelastic arm's relaxed forces
/// (`relaxed<k>.<coordinate>`, branch k: the state a run continues from). Built once for the CLI and Python, so that both have
/// every column.
pub struct Table {
    pub names: Vec<String>,
    pub rows: Vec<Vec<f64>>,
}

impl Table {
    /// The table of a run of `arm` (`tips`: each arm's, for a model of
    /// several).
    pub fn of(
        arm: &dyn runtime::Dynamics,
        tips: Option<&ArmTips>,
        traj: &runtime::Trajectory,
    ) -> Self {
        let n = arm.dof();
        let joints = !arm.info().constraints.is_empty();
        let rows = (traj.t.iter().zip(&traj.x).enumerate())
            .map(|(i, (t, x))| {
                let out = arm.outputs(*t, &x[..n], &x[n..2 * n]);
                let contact = crate::contact::columns(arm, traj, i);
                let tips = tips.map_or(Vec::new(), |a| a.at(arm, *t, &x[..n]));
                Self::row(arm, *t, x, &out, joints, &contact, &tips)
            })
            .collect();
        Self {
            names: Self::names(arm, tips),
            rows,
        }
    }

    /// The columns' names.
    pub fn names(arm: &dyn runtime::Dynamics, tips: Option<&ArmTips>) -> Vec<String> {
        let coords = &arm.info().coordinates;
        let mut names = vec!["t".to_string()];
        names.extend(coords.iter().cloned());
        names.extend(coords.iter().map(|c| format!("{c}_dot")));
        names.extend(runtime::OUTPUT_NAMES.iter().map(|o| o.to_string()));
        names.extend(crate::joints::reaction_names(arm));
        names.extend(crate::contact::column_names(arm));
        names.extend(tips.map_or(Vec::new(), ArmTips::names));
        names.extend(relaxed_names(arm));
        names
    }

    /// The row at (t, x): `outputs` the arm's there, `joints` whether it
    /// has joints (their reactions), `contact` its contact columns, `tips`
    /// each arm's tip (`ArmTips::at`; empty for one arm).
    pub fn row(
        arm: &dyn runtime::Dynamics,
        t: f64,
        x: &[f64],
        outputs: &[f64],
        joints: bool,
        contact: &[f64],
        tips: &[f64],
    ) -> Vec<f64> {
        let mut row = Vec::with_capacity(1 + x.len() + outputs.len() + contact.len());
        let n = arm.dof();
        row.push(t);
        row.extend_from_slice(&x[..2 * n]);
        row.extend_from_slice(outputs);
        if joints {
            row.extend(crate::joints::reactions(arm, t, x));
        }
        row.extend_from_slice(contact);
        row.extend_from_slice(tips);
        row.extend_from_slice(&x[2 * n..]);
        row
    }

    /// The first column of the forces (joints', then contacts'): after t,
    /// q, qd and the outputs.
    pub fn forces_from(dof: usize) -> usize {
        1 + 2 * dof + runtime::N_OUTPUTS
    }

    /// `trajectory.csv` streamed to `w`: a header of the names, t to 9
    /// decimals, the rest to 13 significant digits (no copy of the text in
    /// memory, which is twice the table's size).
    pub fn write_csv(&self, w: &mut impl std::io::Write) -> std::io::Result<()> {
        writeln!(w, "{}", self.names.join(","))?;
        for row in &self.rows {
            Self::write_row(w, row)?;
        }
        Ok(())
    }

    /// One row of `trajectory.csv`.
    pub fn write_row(w: &mut impl std::io::Write, row: &[f64]) -> std::io::Result<()> {
        write!(w, "{:.9}", row[0])?;
        for v in &row[1..] {
            write!(w, ",{v:.12e}")?;
        }
        writeln!(w)
    }
}

/// The relaxed forces' columns: `relaxed<k>.<coordinate>` for branch k.
pub fn relaxed_names(arm: &dyn runtime::Dynamics) -> Vec<String> {
    let Some(relax) = arm.relaxation() else {
        return Vec::new();
    };
    let coords = &arm.info().coordinates;
    (0..relax.branches().count())
        .flat_map(|k| coords.iter().map(move |c| format!("relaxed{k}.{c}")))
        .collect()
}

/// What `summary.json` says of a run, for the CLI and Python alike: the
/// model and its backend, the options, what the solver counted, the tip
/// error, the joints' drift, the contacts, the failure (if any) and the
/// final state. A front end adds only what is its own (the CLI: where each
/// option came from).
pub fn summary(
    loaded: &Loaded,
    opts: &SimOptions,
    stats: &runtime::SimStats,
    traj: &runtime::Trajectory,
    tip_error: Option<&crate::compare::TipError>,
    failure: Option<serde_json::Value>,
) -> serde_json::Value {
    let arm = &*loaded.arm;
    let n = arm.dof();
    let final_state = traj.x.last().cloned().unwrap_or_default();
    let t_final = traj.t.last().copied().unwrap_or(0.0);
    let tip = if final_state.len() >= 2 * n {
        arm.outputs(t_final, &final_state[..n], &final_state[n..2 * n])
    } else {
        [f64::NAN; runtime::N_OUTPUTS]
    };
    serde_json::json!({
        "model": loaded.model.name,
        "origin": loaded.origin,
        "structural_hash": loaded.hash,
        "backend": arm.backend(),
        "cache": loaded.cache,
        "route": loaded.route,
        "derive_s": loaded.derive_s,
        "solver": stats.solver,
        "rtol": opts.rtol,
        "atol": opts.atol,
        "dt": opts.solver.fixed_step().then_some(opts.dt),
        "t_end": opts.t_end,
        "steps": stats.steps,
        "rejected_steps": stats.rejected_steps,
        "rhs_evaluations": stats.rhs_evaluations,
        "jacobian_evaluations": stats.jacobian_evaluations,
        "solver_switch": stats.switched,
        "wall_s": stats.wall_s,
        "status": match &failure {
            None => "ok",
            Some(f) if f["reason"] == runtime::INTERRUPTED => "interrupted",
            Some(_) => "failed",
        },
        "tip_error": tip_error,
        "constraint_drift_max_m": stats.constraints.map(|c| c.drift_max_m),
        "constraints": stats.constraints,
        "contact": crate::contact::summary(arm, traj, stats.contact),
        "failure": failure,
        "final_state": {
            "t": t_final,
            "q": final_state.get(..n),
            "qd": final_state.get(n..),
            "tip_position": &tip[output::TIP],
            "kinetic_energy": tip[output::KINETIC],
            "potential_energy": tip[output::POTENTIAL],
        },
    })
}
