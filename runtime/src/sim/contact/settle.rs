//! The impact speed a Hunt-Crossley contact that begins at rest is damped
//! as.
//!
//! Damping from a restitution is alpha = a(e) / v_in: a contact that
//! begins without approaching (a body set down on a surface, an arm
//! resting on an obstacle at t = 0) has no impact speed, and the floor
//! speed (`law::SLOWEST_IMPACT`) damps it tens of times past critical, so
//! that it creeps to its depth over hundreds of its periods. What sets
//! such a contact's scale is the load pressing it: the force F that stops
//! the point's normal acceleration, with m the point's effective mass
//! along the normal, gives the static depth delta_s = (F / k)^(1/n) and
//! the speed of the impact that would reach it,
//!
//!   v_s = sqrt(2 F delta_s / ((n + 1) m)),
//!
//! (m v_s^2 / 2 = k delta_s^(n+1) / (n + 1)). Damped as that impact, the
//! contact's damping ratio at delta_s is (a / 2) sqrt((n + 1) / (2 n)),
//! whatever k, n and m: a damped settle within a few periods, as an
//! impact at that speed would have. A faster approach keeps its own speed.

use nalgebra::{DMatrix, DVector};

use super::{ContactSet, Damping, Normal, impact};
use crate::arm::{Dynamics, Workspace, accelerations};

/// v_s for `pair` beginning at (t, q, qd), or `None` where it does not
/// apply: not Hunt-Crossley from a restitution, or nothing presses the
/// point in.
pub fn settling_speed<D: Dynamics + ?Sized>(
    d: &D,
    set: &ContactSet,
    t: f64,
    q: &[f64],
    qd: &[f64],
    pair: usize,
) -> Option<f64> {
    let Normal::HuntCrossley {
        k,
        n: exponent,
        damping: Damping::Restitution { .. },
    } = set.pairs[pair].law.normal
    else {
        return None;
    };
    let nq = q.len();
    let rows = impact::rows(d, set, t, q, qd, &[pair]);
    let (start, axes, normal) = &rows.pairs[0];
    // The normal row and its J' qd (a pair with friction has the point's
    // world rows).
    let (row, gamma) = match axes.is_empty() {
        true => (rows.jac.row(*start).transpose(), rows.gamma[*start]),
        false => axes
            .iter()
            .enumerate()
            .fold((DVector::zeros(nq), 0.0), |(r, g), (i, &c)| {
                (
                    r + rows.jac.row(start + i).transpose() * normal[c],
                    g + rows.gamma[start + i] * normal[c],
                )
            }),
    };
    let mut m = DMatrix::zeros(nq, nq);
    d.mass(t, q, &mut m);
    let inverse_mass = row.dot(&m.cholesky()?.solve(&row));
    let mut qdd = vec![0.0; nq];
    accelerations(d, &mut Workspace::new(nq), t, q, qd, &mut qdd).ok()?;
    // Positive: the point accelerates away from the surface.
    let a_n = row.dot(&DVector::from_column_slice(&qdd)) + gamma;
    let force = -a_n / inverse_mass;
    if !(force > 0.0 && inverse_mass > 0.0) {
        return None;
    }
    let depth = (force / k).powf(1.0 / exponent);
    let v = (2.0 * force * depth * inverse_mass / (exponent + 1.0)).sqrt();
    v.is_finite().then_some(v)
}
