//! An arm as the first-order system x' = f(t, x), x = [q, qd] (and a
//! viscoelastic arm's relaxed forces z after them, `crate::relaxation`),
//! with its analytic Jacobian; the first failure of either is kept for
//! the report.

use std::cell::{Cell, RefCell};

use differential_equations::prelude::*;
use nalgebra::DMatrix;

use super::state::StateVec;
use super::stepper::OdeSystem;
use crate::arm::{AccelError, Dynamics, Workspace, accelerations};
use crate::jacobian::state_jacobian;

/// (power, depth) of the contacts at (t, x).
pub(super) type MeterFn<'a> = dyn Fn(f64, &[f64]) -> super::outcome::MeterSample + 'a;

/// The first-order system x' = f(t, x) of an arm; components past `len`
/// are padding.
pub(super) struct ArmOde<'a, D: ?Sized> {
    arm: &'a D,
    pub(super) n: usize,
    /// The state's length: 2 n, and the relaxed forces.
    pub(super) len: usize,
    ws: RefCell<Workspace>,
    qdd: RefCell<Vec<f64>>,
    pub(super) evals: Cell<usize>,
    pub(super) jac_evals: Cell<usize>,
    /// Rejected steps of our own methods (`drivers::run_own`), which keep
    /// them past a failure; None for the ODE crate's.
    pub(super) rejected: Cell<Option<usize>>,
    jac: RefCell<DMatrix<f64>>,
    pub(super) first_error: RefCell<Option<AccelError>>,
    /// Set when a right-hand side failed since the last accepted step.
    pub(super) failed_in_step: Cell<bool>,
}

impl<'a, D: Dynamics + ?Sized> ArmOde<'a, D> {
    pub(super) fn new(arm: &'a D) -> Self {
        let n = arm.dof();
        let len = 2 * n + arm.internal_len();
        Self {
            arm,
            n,
            len,
            ws: RefCell::new(Workspace::new(n)),
            qdd: RefCell::new(vec![0.0; n]),
            evals: Cell::new(0),
            jac_evals: Cell::new(0),
            rejected: Cell::new(None),
            jac: RefCell::new(DMatrix::zeros(len, len)),
            first_error: RefCell::new(None),
            failed_in_step: Cell::new(false),
        }
    }

    /// The contact switch g(t, x) of the arm's pairs that keep records,
    /// if any: it falls through zero when one begins or ends to touch.
    pub(super) fn contact_switch(&self) -> Option<Box<super::events::SwitchFn<'_>>> {
        let set = self.arm.contact()?;
        if !set.keeps_records() {
            return None;
        }
        let n = self.n;
        Some(Box::new(move |t, x| {
            crate::contact::switching_gap(self.arm, set, t, &x[..n], &x[n..2 * n])
        }))
    }

    /// The contact meter's sample at (t, x), when the arm has contacts.
    pub(super) fn contact_meter(&self) -> Option<Box<MeterFn<'_>>> {
        let set = self.arm.contact()?;
        let n = self.n;
        Some(Box::new(move |t, x| {
            crate::contact::meter_sample(self.arm, set, t, &x[..n], &x[n..2 * n])
        }))
    }

    fn rhs(&self, t: f64, x: &[f64], dx: &mut [f64]) {
        self.evals.set(self.evals.get() + 1);
        let (n, len) = (self.n, self.len);
        let (q, rest) = x.split_at(n);
        let (qd, z) = (&rest[..n], &rest[n..len - n]);
        dx[..n].copy_from_slice(qd);
        dx[2 * n..].fill(0.0);
        if len > 2 * n {
            self.arm.set_internal(z);
            crate::relaxed_forces::rates(self.arm, t, q, z, &mut dx[2 * n..len]);
        }
        let mut qdd = self.qdd.borrow_mut();
        match accelerations(self.arm, &mut self.ws.borrow_mut(), t, q, qd, &mut qdd) {
            Ok(()) => dx[n..2 * n].copy_from_slice(&qdd),
            Err(e) => {
                // NaN makes an adaptive method reject the step; the record
                // explains the failure if the method then gives up.
                self.first_error.borrow_mut().get_or_insert(e);
                self.failed_in_step.set(true);
                dx[n..2 * n].fill(f64::NAN);
            }
        }
    }

    /// The Jacobian of the unpadded system into `j` (NaN if it fails).
    fn jacobian_dense(&self, t: f64, x: &[f64], j: &mut DMatrix<f64>) {
        self.jac_evals.set(self.jac_evals.get() + 1);
        if let Err(e) = state_jacobian(self.arm, &mut self.ws.borrow_mut(), t, x, j) {
            self.first_error.borrow_mut().get_or_insert(e);
            j.fill(f64::NAN);
        }
    }

    fn jacobian_into(&self, t: f64, x: &[f64], j: &mut Matrix<f64>) {
        self.jac_evals.set(self.jac_evals.get() + 1);
        let m = self.len;
        let mut jac = self.jac.borrow_mut();
        let ok = match state_jacobian(self.arm, &mut self.ws.borrow_mut(), t, &x[..m], &mut jac) {
            Ok(_) => true,
            Err(e) => {
                self.first_error.borrow_mut().get_or_insert(e);
                false
            }
        };
        for r in 0..x.len() {
            for c in 0..x.len() {
                j[(r, c)] = match (r < m && c < m, ok) {
                    (true, true) => jac[(r, c)],
                    (true, false) => f64::NAN,
                    (false, _) => 0.0,
                };
            }
        }
    }
}

impl<D: Dynamics + ?Sized> OdeSystem for &ArmOde<'_, D> {
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
        ArmOde::rhs(self, t, y, dy);
    }

    fn jacobian(&mut self, t: f64, y: &[f64], j: &mut DMatrix<f64>) {
        self.jacobian_dense(t, y, j);
    }
}

impl<D: Dynamics + ?Sized, Y: StateVec> ODE<f64, Y> for ArmOde<'_, D> {
    fn diff(&self, t: f64, x: &Y, dx: &mut Y) {
        self.rhs(t, x.as_ref(), dx.as_mut());
    }

    fn jacobian(&self, t: f64, x: &Y, j: &mut Matrix<f64>) {
        self.jacobian_into(t, x.as_ref(), j);
    }
}
