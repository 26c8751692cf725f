//! Rotational inertia of a lumped body in the world frame.
//!
//! Every body softarm lumps is axisymmetric about its own axis (a slice of
//! a rod, a link) or has one moment that matters (planar bodies turn about
//! z only; point masses have none). Then the world-frame tensor needs no
//! rotation matrix: J = lateral 1 + (axial - lateral) a a^T with a the
//! body's axis, and everything TMT needs (J w, the gyroscopic w x J w, the
//! composite sums) is a few dot products.
//!
//! The moments may depend on q (a bent planar pcc element's arc): the
//! Lagrangian then has the shape terms `shape_rate` and `shape_force` on
//! top of the rigid-body ones.

use crate::cas::{Cas, ExprId};

#[derive(Clone)]
pub enum Inertia {
    /// The same moment about every axis: planar bodies (whose angular
    /// velocity is along z) and point masses.
    Isotropic(ExprId),
    /// `axial` about the unit world-frame `axis` (a function of q that turns
    /// with the body), `lateral` about every axis normal to it.
    Axisymmetric {
        axis: [ExprId; 3],
        axial: ExprId,
        lateral: ExprId,
    },
    /// A rigid body of three principal moments about its unit world-frame
    /// axes (the columns of its rotation): a free body of an assembly.
    Principal {
        axes: [[ExprId; 3]; 3],
        moments: [ExprId; 3],
    },
}

impl Inertia {
    /// J w.
    pub fn apply(&self, cas: &mut Cas, w: &[ExprId; 3]) -> [ExprId; 3] {
        match self {
            Inertia::Isotropic(i) => w.map(|c| cas.mul(*i, c)),
            Inertia::Axisymmetric {
                axis,
                axial,
                lateral,
            } => {
                let aw = cas.dot(axis, w);
                let diff = cas.sub(*axial, *lateral);
                let along = cas.mul(diff, aw);
                std::array::from_fn(|k| {
                    let l = cas.mul(*lateral, w[k]);
                    let a = cas.mul(along, axis[k]);
                    cas.add(l, a)
                })
            }
            // sum_k I_k a_k (a_k . w)
            Inertia::Principal { axes, moments } => {
                let along: [ExprId; 3] = std::array::from_fn(|k| {
                    let aw = cas.dot(&axes[k], w);
                    cas.mul(moments[k], aw)
                });
                std::array::from_fn(|c| {
                    let terms: Vec<ExprId> =
                        (0..3).map(|k| cas.mul(along[k], axes[k][c])).collect();
                    cas.add_all(&terms)
                })
            }
        }
    }

    /// u^T J v.
    pub fn quadratic(&self, cas: &mut Cas, u: &[ExprId; 3], v: &[ExprId; 3]) -> ExprId {
        let jv = self.apply(cas, v);
        cas.dot(u, &jv)
    }

    /// The tensor, packed xx, yy, zz, xy, xz, yz.
    pub fn packed(&self, cas: &mut Cas) -> [ExprId; 6] {
        match self {
            Inertia::Isotropic(i) => {
                let zero = cas.zero();
                [*i, *i, *i, zero, zero, zero]
            }
            Inertia::Axisymmetric {
                axis,
                axial,
                lateral,
            } => {
                let diff = cas.sub(*axial, *lateral);
                let diag: [ExprId; 3] = std::array::from_fn(|k| {
                    let a2 = cas.powi(axis[k], 2);
                    let t = cas.mul(diff, a2);
                    cas.add(*lateral, t)
                });
                let off =
                    [(0, 1), (0, 2), (1, 2)].map(|(a, b)| cas.mul_all(&[diff, axis[a], axis[b]]));
                [diag[0], diag[1], diag[2], off[0], off[1], off[2]]
            }
            Inertia::Principal { axes, moments } => {
                let entry = |cas: &mut Cas, a: usize, b: usize| {
                    let t: Vec<ExprId> = (0..3)
                        .map(|k| cas.mul_all(&[moments[k], axes[k][a], axes[k][b]]))
                        .collect();
                    cas.add_all(&t)
                };
                let e = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)];
                e.map(|(a, b)| entry(cas, a, b))
            }
        }
    }

    /// w x (J w); zero for isotropic bodies.
    pub fn gyroscopic(&self, cas: &mut Cas, w: &[ExprId; 3]) -> [ExprId; 3] {
        match self {
            Inertia::Isotropic(_) => [cas.zero(); 3],
            Inertia::Axisymmetric {
                axis,
                axial,
                lateral,
            } => {
                // (axial - lateral) (a . w) (w x a)
                let aw = cas.dot(axis, w);
                let diff = cas.sub(*axial, *lateral);
                let s = cas.mul(diff, aw);
                let wa = cas.cross(w, axis);
                wa.map(|c| cas.mul(s, c))
            }
            Inertia::Principal { .. } => {
                let jw = self.apply(cas, w);
                cas.cross(w, &jw)
            }
        }
    }

    /// (dJ/dt at a fixed axis) w: the rate of the moments themselves.
    pub fn shape_rate(
        &self,
        cas: &mut Cas,
        pairs: &[(ExprId, ExprId)],
        w: &[ExprId; 3],
    ) -> [ExprId; 3] {
        match self {
            Inertia::Isotropic(i) => {
                let di = cas.time_derivatives(&[*i], pairs)[0];
                w.map(|c| cas.mul(di, c))
            }
            Inertia::Axisymmetric {
                axis,
                axial,
                lateral,
            } => {
                let d = cas.time_derivatives(&[*axial, *lateral], pairs);
                Inertia::Axisymmetric {
                    axis: *axis,
                    axial: d[0],
                    lateral: d[1],
                }
                .apply(cas, w)
            }
            Inertia::Principal { axes, moments } => {
                let d = cas.time_derivatives(moments, pairs);
                Inertia::Principal {
                    axes: *axes,
                    moments: [d[0], d[1], d[2]],
                }
                .apply(cas, w)
            }
        }
    }

    /// -(1/2) d/dq (w^T J w) at a fixed axis and w, per coordinate: the
    /// Lagrangian's term of moments that depend on q.
    pub fn shape_force(&self, cas: &mut Cas, w: &[ExprId; 3], q: &[ExprId]) -> Vec<ExprId> {
        match self {
            Inertia::Isotropic(i) => {
                let w2: Vec<ExprId> = w.iter().map(|&c| cas.powi(c, 2)).collect();
                let w2 = cas.add_all(&w2);
                let cot = cas.scaled(-0.5, w2);
                cas.vjp(&[*i], &[cot], q)
            }
            Inertia::Axisymmetric {
                axis,
                axial,
                lateral,
            } => {
                // w^T J w = lateral (|w|^2 - (a.w)^2) + axial (a.w)^2
                let w2: Vec<ExprId> = w.iter().map(|&c| cas.powi(c, 2)).collect();
                let w2 = cas.add_all(&w2);
                let aw = cas.dot(axis, w);
                let aw2 = cas.powi(aw, 2);
                let normal = cas.sub(w2, aw2);
                let cot = [cas.scaled(-0.5, aw2), cas.scaled(-0.5, normal)];
                cas.vjp(&[*axial, *lateral], &cot, q)
            }
            // w^T J w = sum_k I_k (a_k . w)^2
            Inertia::Principal { axes, moments } => {
                let cot: Vec<ExprId> = (0..3)
                    .map(|k| {
                        let aw = cas.dot(&axes[k], w);
                        let aw2 = cas.powi(aw, 2);
                        cas.scaled(-0.5, aw2)
                    })
                    .collect();
                cas.vjp(moments, &cot, q)
            }
        }
    }
}
