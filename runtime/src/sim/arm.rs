//! An arm: a kernel set plus its parameter values, with the physics on top
//! (full mass matrix, Cholesky solve for accelerations, energies).

use std::cell::RefCell;

use nalgebra::{DMatrix, DVector};

use crate::kernels::{KernelKind, Kernels, ModelInfo, N_OUTPUTS};
use crate::linalg::Ldlt;
use crate::signal::Drive;
use crate::tape::Inputs;

/// The equations of motion `M(q) qdd + h(q, qd, t) = 0` of one arm.
///
/// Both backends implement it through [`Arm`]; integrators, statics and the
/// CLI see only this trait.
pub trait Dynamics {
    fn info(&self) -> &ModelInfo;
    fn backend(&self) -> &'static str;
    fn dof(&self) -> usize {
        self.info().dof()
    }
    /// Full symmetric M(q) into `m` (dof x dof).
    fn mass(&self, t: f64, q: &[f64], m: &mut DMatrix<f64>);
    /// h(q, qd, t) into `h`.
    fn bias(&self, t: f64, q: &[f64], qd: &[f64], h: &mut DVector<f64>);
    /// Both at once, sharing subexpressions.
    fn mass_bias(&self, t: f64, q: &[f64], qd: &[f64], m: &mut DMatrix<f64>, h: &mut DVector<f64>);
    /// Tip position and energies, laid out as [`crate::OUTPUT_NAMES`].
    fn outputs(&self, t: f64, q: &[f64], qd: &[f64]) -> [f64; N_OUTPUTS];
    /// A kernel's raw output (layouts in [`KernelKind`]); the hot path of
    /// the integrators, free of matrix copies.
    fn eval_kernel(&self, kind: KernelKind, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]);
    /// Solve M x = b in place for x, M given as the packed upper triangle
    /// (the `Mass` layout); false unless M is positive definite.
    fn solve_mass(&self, packed: &[f64], b: &mut [f64], ws: &mut Ldlt) -> bool;
    /// qdd = -M^-1 h without the mass matrix, where the kernels have a
    /// recursion for it ([`Kernels::accelerations`]); None where not,
    /// Some(false) where M is not positive definite.
    fn direct_accelerations(
        &self,
        _t: f64,
        _q: &[f64],
        _qd: &[f64],
        _qdd: &mut [f64],
    ) -> Option<bool> {
        None
    }
    /// d tau/dq and d tau/dqd of the inverse dynamics tau = M qdd + h
    /// (row-major n x n each) at the given accelerations, column by column
    /// from the `Jvp` kernel.
    fn jacobian_parts(&self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], out: &mut [f64]);
    /// The tangent stiffness K = d h(q, 0) / dq (row-major n x n) at time
    /// t: d tau/dq at qd = qdd = 0, where inertial and damping forces
    /// vanish to first order.
    fn stiffness(&self, t: f64, q: &[f64], k: &mut [f64]) {
        let n = q.len();
        let zeros = vec![0.0; n];
        let mut parts = vec![0.0; 2 * n * n];
        self.jacobian_parts(t, q, &zeros, &zeros, &mut parts);
        k.copy_from_slice(&parts[..n * n]);
    }
    /// The base parameter values (layout `info().parameters`).
    fn base_params(&self) -> &[f64];
    /// The parameters at time t (base then derived), driven ones from
    /// their signals: what the kernels read then.
    fn params_at(&self, t: f64) -> Vec<f64>;
    /// Replace the base parameters; the derived ones are recomputed.
    fn set_base_params(&mut self, params: &[f64]);
    /// Drive parameters by signals of time (inputs); replaces earlier ones.
    fn set_drives(&mut self, drives: Vec<Drive>);
    /// Replace the signal of drive k (in `set_drives`' order): a
    /// controller's input held over a step, without rebuilding the rest.
    fn set_drive_signal(&mut self, k: usize, signal: crate::signal::Signal);
    /// A kernel along a direction `dir` (2n: dq, then dqd), as the `Jvp`
    /// and `ContactJvp` kernels read it (the `ContactJacobian` kernel: the
    /// groups to evaluate), reading `aux` (the contact frames for
    /// `ContactJacobian`; else empty).
    #[allow(clippy::too_many_arguments)]
    fn eval_direction(
        &self,
        kind: KernelKind,
        t: f64,
        q: &[f64],
        qd: &[f64],
        dir: &[f64],
        aux: &[f64],
        out: &mut [f64],
    );
    /// The contact frames' bounds alone, without the points, where the
    /// kernels give them so ([`Kernels::contact_bounds`]); false where not.
    fn contact_bounds(&self, _t: f64, _q: &[f64], _qd: &[f64], _out: &mut [f64]) -> bool {
        false
    }
    /// The obstacles and pairs this system touches (none by default).
    fn contact(&self) -> Option<&crate::contact::ContactSet> {
        None
    }
    /// Give the system its contacts (replacing any).
    fn set_contact(&mut self, _contact: Option<crate::contact::ContactSet>) {}
    /// Its viscoelastic groups (none by default: elastic).
    fn relaxation(&self) -> Option<&crate::relaxation::Relaxation> {
        None
    }
    /// Give the system its viscoelastic groups (replacing any).
    fn set_relaxation(&mut self, _relaxation: Option<crate::relaxation::Relaxation>) {}
    /// Extra first-order states after [q, qd]: the relaxed forces.
    fn internal_len(&self) -> usize {
        self.relaxation().map_or(0, |r| r.states(self.dof()))
    }
    /// The relaxed forces the next accelerations take (`internal_len`
    /// values; ignored by an elastic system).
    fn set_internal(&self, _z: &[f64]) {}
    /// Add the relaxed forces' sum to the generalised force `out`; false
    /// (and `out` untouched) for an elastic system.
    fn add_internal_force(&self, _out: &mut [f64]) -> bool {
        false
    }
    /// The elastic force of relaxing group g alone at (t, q).
    fn group_force(&self, _t: f64, _q: &[f64], _g: usize, _out: &mut [f64]) {}
    /// Its tangent stiffness (row-major n x n).
    fn group_stiffness(&self, _t: f64, _q: &[f64], _g: usize, _out: &mut [f64]) {}
}

/// Why the accelerations could not be computed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum AccelError {
    #[error(
        "mass matrix is not positive definite at t = {t} (estimated condition number {condition:.3e}); \
         check masses and lengths for zero or negative values"
    )]
    SingularMass { t: f64, condition: f64 },
    #[error("non-finite {what} at t = {t}: the state has left the model's valid range")]
    NonFinite { t: f64, what: &'static str },
    #[error(
        "the joints' constraints became dependent at t = {t} (the constraint Jacobian lost rank: \
         redundant or conflicting joints, or a loop stretched straight); check that no two joints \
         hold the same freedom"
    )]
    DependentJoints { t: f64 },
}

/// A model's kernels with numeric parameter values bound.
pub struct Arm<K> {
    kernels: K,
    params: Vec<f64>,
    packed: RefCell<Vec<f64>>,
    /// Inputs: parameters set from signals at each evaluation's time (never
    /// inside derived parameters: the generator keeps them in the kernels).
    drives: Vec<Drive>,
    /// Where else each drive's parameter is kept (`ModelInfo::copies`).
    copies: Vec<Vec<usize>>,
    /// `params` with the driven entries at the last time asked for.
    live: RefCell<Vec<f64>>,
    /// Contact forces on the right-hand side (`crate::contact`).
    contact: Option<crate::contact::ContactSet>,
    /// Viscoelastic groups, each with its parameters (base then derived)
    /// without the group's stiffnesses.
    relax: Option<(crate::relaxation::Relaxation, Vec<Vec<f64>>)>,
    /// The relaxed forces of the last `set_internal`.
    internal: RefCell<Vec<f64>>,
}

impl Arm<Box<dyn Kernels>> {
    /// An arm on kernels chosen at run time, as the integrators see it. Not
    /// generic, so that this arm's methods are compiled here with the
    /// runtime's optimisation, not in the caller's crate (the CLI's is
    /// built at opt-level 1: chain's mass + bias 8 to 13 % slower through it).
    pub fn boxed(kernels: Box<dyn Kernels>, params: Vec<f64>) -> Box<dyn Dynamics> {
        Box::new(Self::new(kernels, params))
    }
}

impl<K: Kernels> Arm<K> {
    /// `params` must follow `kernels.info().parameters`; the derived
    /// parameters are computed from them here, once.
    pub fn new(kernels: K, params: Vec<f64>) -> Self {
        assert_eq!(
            params.len(),
            kernels.info().parameters.len(),
            "parameter vector does not match the model's layout"
        );
        let derived = derived_params(&kernels, &params);
        let mut extended = params;
        extended.extend(derived);
        Self {
            kernels,
            params: extended,
            packed: RefCell::new(Vec::new()),
            drives: Vec::new(),
            copies: Vec::new(),
            live: RefCell::new(Vec::new()),
            contact: None,
            relax: None,
            internal: RefCell::new(Vec::new()),
        }
    }

    /// Each relaxing group's parameters without its stiffnesses.
    fn group_params(&self) -> Option<(crate::relaxation::Relaxation, Vec<Vec<f64>>)> {
        let (relax, _) = self.relax.as_ref()?;
        let n = self.kernels.info().parameters.len();
        let without = (0..relax.groups.len())
            .map(|g| {
                let base = relax.without(g, &self.params[..n]);
                let derived = derived_params(&self.kernels, &base);
                base.into_iter().chain(derived).collect()
            })
            .collect();
        Some((relax.clone(), without))
    }

    /// `f` on group g's parameters without its stiffnesses at time t
    /// (driven ones from their signals).
    fn with_group_params<R>(&self, g: usize, t: f64, f: impl FnOnce(&[f64]) -> R) -> R {
        let (_, without) = self.relax.as_ref().expect("a relaxing group");
        if self.drives.is_empty() {
            return f(&without[g]);
        }
        let mut p = without[g].clone();
        self.drive(t, &mut p);
        f(&p)
    }

    /// The driven parameters of `p` (and their copies) at time t.
    fn drive(&self, t: f64, p: &mut [f64]) {
        for (d, copies) in self.drives.iter().zip(&self.copies) {
            let v = d.signal.at(t);
            p[d.param] = v;
            for &k in copies {
                p[k] = v;
            }
        }
    }

    /// h(q, 0) at parameters `p` into `out`.
    fn static_bias_at(&self, p: &[f64], t: f64, q: &[f64], out: &mut [f64]) {
        let n = q.len();
        let zeros = vec![0.0; n];
        let mut packed = vec![0.0; KernelKind::MassBias.output_len(self.kernels.info())];
        let inp = Inputs {
            t,
            q,
            qd: &zeros,
            qdd: &[],
            dir: &[],
            p,
            aux: &[],
        };
        self.kernels.eval(KernelKind::MassBias, &inp, &mut packed);
        out.copy_from_slice(&packed[n * (n + 1) / 2..]);
    }

    /// d h(q, 0)/dq at parameters `p` (row-major) into `out`.
    fn stiffness_at(&self, p: &[f64], t: f64, q: &[f64], out: &mut [f64]) {
        let n = q.len();
        let zeros = vec![0.0; n];
        let (mut dir, mut col) = (vec![0.0; 2 * n], vec![0.0; n]);
        for j in 0..n {
            dir[j] = 1.0;
            let inp = Inputs {
                t,
                q,
                qd: &zeros,
                qdd: &zeros,
                dir: &dir,
                p,
                aux: &[],
            };
            self.kernels.eval(KernelKind::Jvp, &inp, &mut col);
            dir[j] = 0.0;
            for i in 0..n {
                out[i * n + j] = col[i];
            }
        }
    }

    /// The parameters at time t: the bound values, driven ones from their
    /// signals.
    fn with_params<R>(&self, t: f64, f: impl FnOnce(&[f64]) -> R) -> R {
        if self.drives.is_empty() {
            return f(&self.params);
        }
        let mut live = self.live.borrow_mut();
        if live.len() != self.params.len() {
            live.clone_from(&self.params);
        }
        self.drive(t, &mut live);
        f(&live)
    }

    /// `f` of the kernels' inputs at (t, q, qd): the parameters at t, no
    /// accelerations, direction or frames.
    fn at<R>(&self, t: f64, q: &[f64], qd: &[f64], f: impl FnOnce(&Inputs) -> R) -> R {
        self.with_params(t, |p| {
            f(&Inputs {
                t,
                q,
                qd,
                qdd: &[],
                dir: &[],
                p,
                aux: &[],
            })
        })
    }

    /// Base parameters followed by the derived ones.
    pub fn params(&self) -> &[f64] {
        &self.params
    }

    pub fn kernels(&self) -> &K {
        &self.kernels
    }

    fn eval_packed(&self, kind: KernelKind, t: f64, q: &[f64], qd: &[f64], f: impl FnOnce(&[f64])) {
        let mut packed = self.packed.borrow_mut();
        packed.resize(kind.output_len(self.kernels.info()), 0.0);
        self.at(t, q, qd, |inp| self.kernels.eval(kind, inp, &mut packed));
        f(&packed);
    }
}

/// The derived parameters of `base` (the `Derived` kernel).
fn derived_params<K: Kernels + ?Sized>(kernels: &K, base: &[f64]) -> Vec<f64> {
    let info = kernels.info();
    let mut extended = base.to_vec();
    extended.resize(info.extended_params(), 0.0);
    let zeros = vec![0.0; info.dof()];
    let mut derived = vec![0.0; info.derived];
    let inp = Inputs {
        t: 0.0,
        q: &zeros,
        qd: &zeros,
        qdd: &[],
        dir: &[],
        p: &extended,
        aux: &[],
    };
    kernels.eval(KernelKind::Derived, &inp, &mut derived);
    derived
}

/// Unpack the upper triangle (row by row) into a full symmetric matrix.
fn unpack_symmetric(packed: &[f64], m: &mut DMatrix<f64>) {
    let n = m.nrows();
    let mut k = 0;
    for i in 0..n {
        for j in i..n {
            m[(i, j)] = packed[k];
            m[(j, i)] = packed[k];
            k += 1;
        }
    }
}

impl<K: Kernels> Dynamics for Arm<K> {
    fn info(&self) -> &ModelInfo {
        self.kernels.info()
    }
    fn backend(&self) -> &'static str {
        self.kernels.backend()
    }
    fn mass(&self, t: f64, q: &[f64], m: &mut DMatrix<f64>) {
        let zeros = vec![0.0; q.len()];
        let tri = q.len() * (q.len() + 1) / 2;
        self.eval_packed(KernelKind::MassBias, t, q, &zeros, |p| {
            unpack_symmetric(&p[..tri], m)
        });
    }
    fn bias(&self, t: f64, q: &[f64], qd: &[f64], h: &mut DVector<f64>) {
        let tri = q.len() * (q.len() + 1) / 2;
        self.eval_packed(KernelKind::MassBias, t, q, qd, |p| {
            h.copy_from_slice(&p[tri..])
        });
        crate::contact::subtract_from_bias(self, t, q, qd, h.as_mut_slice());
    }
    fn mass_bias(&self, t: f64, q: &[f64], qd: &[f64], m: &mut DMatrix<f64>, h: &mut DVector<f64>) {
        let tri = q.len() * (q.len() + 1) / 2;
        self.eval_packed(KernelKind::MassBias, t, q, qd, |p| {
            unpack_symmetric(&p[..tri], m);
            h.copy_from_slice(&p[tri..]);
        });
        crate::contact::subtract_from_bias(self, t, q, qd, h.as_mut_slice());
    }
    fn outputs(&self, t: f64, q: &[f64], qd: &[f64]) -> [f64; N_OUTPUTS] {
        let mut out = [0.0; N_OUTPUTS];
        self.eval_packed(KernelKind::Outputs, t, q, qd, |p| out.copy_from_slice(p));
        out
    }
    fn eval_kernel(&self, kind: KernelKind, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) {
        self.at(t, q, qd, |inp| self.kernels.eval(kind, inp, out))
    }
    fn solve_mass(&self, packed: &[f64], b: &mut [f64], ws: &mut Ldlt) -> bool {
        self.kernels.solve_mass(packed, b, ws)
    }
    fn contact_bounds(&self, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) -> bool {
        self.at(t, q, qd, |inp| self.kernels.contact_bounds(inp, out))
    }
    fn direct_accelerations(&self, t: f64, q: &[f64], qd: &[f64], qdd: &mut [f64]) -> Option<bool> {
        self.at(t, q, qd, |inp| self.kernels.accelerations(inp, qdd))
    }
    fn jacobian_parts(&self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], out: &mut [f64]) {
        // Column j of d tau/dq along dq = e_j, of d tau/dqd along dqd = e_j.
        let n = q.len();
        let (mut dir, mut col) = (vec![0.0; 2 * n], vec![0.0; n]);
        self.with_params(t, |p| {
            for j in 0..2 * n {
                dir[j] = 1.0;
                let inp = Inputs {
                    t,
                    q,
                    qd,
                    qdd,
                    dir: &dir,
                    p,
                    aux: &[],
                };
                self.kernels.eval(KernelKind::Jvp, &inp, &mut col);
                dir[j] = 0.0;
                let (part, c) = if j < n { (0, j) } else { (1, j - n) };
                for i in 0..n {
                    out[part * n * n + i * n + c] = col[i];
                }
            }
        });
        crate::contact::subtract_from_jacobian(self, t, q, qd, out);
    }
    fn eval_direction(
        &self,
        kind: KernelKind,
        t: f64,
        q: &[f64],
        qd: &[f64],
        dir: &[f64],
        aux: &[f64],
        out: &mut [f64],
    ) {
        self.with_params(t, |p| {
            let inp = Inputs {
                t,
                q,
                qd,
                qdd: &[],
                dir,
                p,
                aux,
            };
            self.kernels.eval(kind, &inp, out);
        });
    }
    fn contact(&self) -> Option<&crate::contact::ContactSet> {
        self.contact.as_ref()
    }
    fn set_contact(&mut self, contact: Option<crate::contact::ContactSet>) {
        self.contact = contact;
    }
    fn relaxation(&self) -> Option<&crate::relaxation::Relaxation> {
        self.relax.as_ref().map(|(r, _)| r)
    }
    fn set_relaxation(&mut self, relaxation: Option<crate::relaxation::Relaxation>) {
        self.relax = relaxation.map(|r| (r, Vec::new()));
        self.relax = self.group_params();
        self.internal.borrow_mut().clear();
    }
    fn set_internal(&self, z: &[f64]) {
        let mut internal = self.internal.borrow_mut();
        internal.clear();
        internal.extend_from_slice(z);
    }
    fn add_internal_force(&self, out: &mut [f64]) -> bool {
        let internal = self.internal.borrow();
        if self.relax.is_none() || internal.is_empty() {
            return false;
        }
        for branch in internal.chunks(out.len()) {
            for (o, r) in out.iter_mut().zip(branch) {
                *o += r;
            }
        }
        true
    }
    fn group_force(&self, t: f64, q: &[f64], g: usize, out: &mut [f64]) {
        let mut without = vec![0.0; q.len()];
        self.with_params(t, |p| self.static_bias_at(p, t, q, out));
        self.with_group_params(g, t, |p| self.static_bias_at(p, t, q, &mut without));
        for (o, w) in out.iter_mut().zip(&without) {
            *o -= w;
        }
    }
    fn group_stiffness(&self, t: f64, q: &[f64], g: usize, out: &mut [f64]) {
        let mut without = vec![0.0; out.len()];
        self.with_params(t, |p| self.stiffness_at(p, t, q, out));
        self.with_group_params(g, t, |p| self.stiffness_at(p, t, q, &mut without));
        for (o, w) in out.iter_mut().zip(&without) {
            *o -= w;
        }
    }
    fn base_params(&self) -> &[f64] {
        &self.params[..self.kernels.info().parameters.len()]
    }
    fn params_at(&self, t: f64) -> Vec<f64> {
        self.with_params(t, <[f64]>::to_vec)
    }
    fn set_base_params(&mut self, params: &[f64]) {
        let derived = derived_params(&self.kernels, params);
        let n = params.len();
        self.params[..n].copy_from_slice(params);
        self.params[n..].copy_from_slice(&derived);
        self.live.borrow_mut().clear();
        self.relax = self.group_params();
    }
    fn set_drive_signal(&mut self, k: usize, signal: crate::signal::Signal) {
        self.drives[k].signal = signal;
    }
    fn set_drives(&mut self, drives: Vec<Drive>) {
        let n = self.kernels.info().parameters.len();
        assert!(
            drives.iter().all(|d| d.param < n),
            "a drive names a parameter outside the layout"
        );
        let copies = &self.kernels.info().copies;
        self.copies = (drives.iter())
            .map(|d| {
                (copies.iter())
                    .filter(|c| c.0 == d.param)
                    .map(|c| c.1)
                    .collect()
            })
            .collect();
        self.drives = drives;
        self.live.borrow_mut().clear();
    }
}

/// Reusable buffers for [`accelerations`].
pub struct Workspace {
    n: usize,
    /// `MassBias` kernel output: packed upper triangle of M, then h.
    packed: Vec<f64>,
    /// `Accel` kernel output: qdd, then the pivots of M = L D L^T.
    accel: Vec<f64>,
    ldlt: Ldlt,
    /// The constrained solve's buffers, made on first use.
    kkt: Option<crate::constraints::KktWorkspace>,
    /// The contact forces Q_c of the last evaluation (or M^-1 Q_c).
    contact: Vec<f64>,
}

impl Workspace {
    pub fn new(dof: usize) -> Self {
        Self {
            n: dof,
            packed: vec![0.0; dof * (dof + 1) / 2 + dof],
            accel: vec![0.0; 2 * dof],
            ldlt: Ldlt::new(dof),
            kkt: None,
            contact: vec![0.0; dof],
        }
    }

    /// The joint forces of the last constrained solve (empty without
    /// joints).
    pub fn lambda(&self) -> &[f64] {
        self.kkt.as_ref().map_or(&[], |k| &k.lambda)
    }
}

/// qdd = -M(q)^-1 h(q, qd, t), by the L D L^T Cholesky factorisation (M is
/// symmetric positive definite). Small arms run the generated solve (the
/// `Accel` kernel); larger ones factor the `MassBias` output here.
pub fn accelerations<D: Dynamics + ?Sized>(
    d: &D,
    ws: &mut Workspace,
    t: f64,
    q: &[f64],
    qd: &[f64],
    qdd: &mut [f64],
) -> Result<(), AccelError> {
    let n = ws.n;
    let info = d.info();
    let rows = info.constraints.len();
    if let Some(set) = d.contact().filter(|s| s.any_held()) {
        let held = set.held_pairs();
        if !held.is_empty() {
            let (a, _) = crate::contact::impact::held_accelerations(d, set, t, q, qd, &held)?;
            qdd.copy_from_slice(&a);
            return Ok(());
        }
    }
    let solved = if rows == 0 && info.accel {
        // The generated solve, then contact forces that push (found from
        // the points the kernel gives) solved by its factors: qdd =
        // -M^-1 h + M^-1 Q_c.
        ws.accel.resize(KernelKind::Accel.output_len(info), 0.0);
        d.eval_kernel(KernelKind::Accel, t, q, qd, &mut ws.accel);
        qdd.copy_from_slice(&ws.accel[..n]);
        let (pivots, rest) = ws.accel[n..].split_at(n);
        let (lower, points) = rest.split_at(n * n.saturating_sub(1) / 2);
        if applied_force(d, t, q, qd, Some(points), &mut ws.contact) {
            solve_unit_ldl(lower, pivots, &mut ws.contact);
            for (a, x) in qdd.iter_mut().zip(&ws.contact) {
                *a += x;
            }
        }
        // Positive pivots: M positive definite (false for NaN too).
        pivots.iter().all(|&p| p > 0.0)
    } else {
        // Contact forces that push make the right-hand side M^-1 (Q_c - h).
        let contact = applied_force(d, t, q, qd, None, &mut ws.contact);
        let direct = match contact || rows > 0 {
            true => None,
            false => d.direct_accelerations(t, q, qd, qdd),
        };
        if let Some(solved) = direct {
            return match solved && qdd.iter().all(|v| v.is_finite()) {
                true => Ok(()),
                false => Err(diagnose(d, t, q, qd)),
            };
        }
        d.eval_kernel(KernelKind::MassBias, t, q, qd, &mut ws.packed);
        if contact {
            let tri = n * (n + 1) / 2;
            for (h, f) in ws.packed[tri..].iter_mut().zip(&ws.contact) {
                *h -= f;
            }
        }
        if rows > 0 {
            let kkt = ws.kkt.get_or_insert_with(|| {
                crate::constraints::KktWorkspace::new(n, rows, &info.blocks)
            });
            crate::constraints::solve_constrained(d, kkt, &ws.packed, t, q, qd, qdd)?
        } else {
            let (mass, bias) = ws.packed.split_at(n * (n + 1) / 2);
            for (a, b) in qdd.iter_mut().zip(bias) {
                *a = -b;
            }
            d.solve_mass(mass, qdd, &mut ws.ldlt)
        }
    };
    if !solved || qdd.iter().any(|v| !v.is_finite()) {
        return Err(diagnose(d, t, q, qd));
    }
    Ok(())
}

/// The generalised forces beyond h into `out`: contact forces that push
/// and a viscoelastic arm's relaxed forces; false when there are none
/// (`out` then unspecified).
fn applied_force<D: Dynamics + ?Sized>(
    d: &D,
    t: f64,
    q: &[f64],
    qd: &[f64],
    points: Option<&[f64]>,
    out: &mut [f64],
) -> bool {
    let contact = crate::contact::generalised_force_at(d, t, q, qd, points, out);
    if d.internal_len() == 0 {
        return contact;
    }
    if !contact {
        out.fill(0.0);
    }
    d.add_internal_force(out) || contact
}

/// Solve L D L^T x = b in place, L unit lower triangular given below its
/// diagonal row by row (the `Accel` kernel's layout). Sizes the `Accel`
/// kernel has (up to 24) run with the size a constant: loops of known
/// length unroll, where loops of every length 1 to n - 1 would each
/// mispredict their exit (most of the cost at n = 10).
fn solve_unit_ldl(lower: &[f64], pivots: &[f64], b: &mut [f64]) {
    macro_rules! fixed {
        ($($n:literal)*) => {
            match b.len() {
                $($n => {
                    let b: &mut [f64; $n] = b.try_into().expect("length matched");
                    return solve_unit_ldl_n::<$n>(lower, pivots, b);
                })*
                _ => {}
            }
        };
    }
    fixed!(1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24);
    solve_unit_ldl_any(lower, pivots, b);
}

fn solve_unit_ldl_n<const N: usize>(lower: &[f64], pivots: &[f64], b: &mut [f64; N]) {
    let lower = &lower[..N * N.saturating_sub(1) / 2];
    // L z = b by columns: one column's updates are independent.
    for j in 0..N {
        let zj = b[j];
        for i in j + 1..N {
            b[i] -= lower[i * (i - 1) / 2 + j] * zj;
        }
    }
    for (x, p) in b.iter_mut().zip(&pivots[..N]) {
        *x /= p;
    }
    for i in (1..N).rev() {
        let xi = b[i];
        for j in 0..i {
            b[j] -= lower[i * (i - 1) / 2 + j] * xi;
        }
    }
}

fn solve_unit_ldl_any(lower: &[f64], pivots: &[f64], b: &mut [f64]) {
    let n = b.len();
    for i in 1..n {
        let row = &lower[i * (i - 1) / 2..][..i];
        let s: f64 = row.iter().zip(&b[..i]).map(|(l, y)| l * y).sum();
        b[i] -= s;
    }
    for (x, p) in b.iter_mut().zip(pivots) {
        *x /= p;
    }
    // L^T x = z by rows of L (contiguous): x_i is final once the rows
    // below it have been subtracted.
    for i in (1..n).rev() {
        let xi = b[i];
        let row = &lower[i * (i - 1) / 2..][..i];
        for (bj, l) in b[..i].iter_mut().zip(row) {
            *bj -= l * xi;
        }
    }
}

/// Why the accelerations failed: off the hot path, so it may allocate.
fn diagnose<D: Dynamics + ?Sized>(d: &D, t: f64, q: &[f64], qd: &[f64]) -> AccelError {
    let n = q.len();
    let mut m = DMatrix::zeros(n, n);
    let mut h = DVector::zeros(n);
    d.mass_bias(t, q, qd, &mut m, &mut h);
    if m.iter().any(|v| !v.is_finite()) {
        return AccelError::NonFinite {
            t,
            what: "mass matrix",
        };
    }
    if h.iter().any(|v| !v.is_finite()) {
        return AccelError::NonFinite {
            t,
            what: "bias (generalised force)",
        };
    }
    let sv = m.singular_values();
    let condition = sv.max() / sv.min().max(f64::MIN_POSITIVE);
    AccelError::SingularMass { t, condition }
}
