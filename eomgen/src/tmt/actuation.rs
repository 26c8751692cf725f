//! Actuators by virtual work on fibre lengths.
//!
//! Every kinematics reports the lumped strain of each element, slice or
//! joint (a [`Strain`]: its stretch and its rotation vector in the element
//! frame). A fibre embedded at (y, z) in the section (a chamber, a tendon)
//! changes its length across that strain by
//!
//! dL = stretch + rho_y z - rho_z y,
//!
//! exact for a constant-curvature arc without twist, to first order
//! otherwise (with offsets scaled by lambda^-1/2 when a stretched
//! incompressible element has thinned). A chamber at pressure p does virtual work p a dL (it pushes its
//! ends apart: an axial force p a and a moment p a r about the axis normal
//! to its direction); a tendon at tension T does -T dL, and only pulls
//! (T is clamped at 0). Both enter as a potential V_a(q) = -W(q), so that
//! the generalised forces are -dV_a/dq and the static stiffness includes
//! their change with the configuration.

use crate::cas::{Cas, ExprId, Func};
use crate::model::{ChamberParam, Param, Structure};

use super::system::ParamSymbols;

/// The lumped strain of one element, slice or joint.
pub struct Strain {
    pub segment: usize,
    /// Length change (m).
    pub stretch: ExprId,
    /// Rotation vector across it in its base frame (twist, bend about y,
    /// bend about z), rad.
    pub rho: [ExprId; 3],
    /// Fibre offsets scale by this (lambda^-1/2 in a stretched
    /// incompressible element); None for 1.
    pub offset_scale: Option<ExprId>,
}

/// An incompressible element stretched to `len` from rest length `l`
/// (lambda = len / l): the factor lambda^-3 of its bending and twist
/// stiffness per angle (I by lambda^-2 over a length lambda l) and the
/// factor lambda^-1/2 of offsets in its section, both bound.
pub fn thinning(cas: &mut Cas, l: ExprId, len: ExprId) -> (ExprId, ExprId) {
    let inv = cas.powi(len, -1);
    let ratio = cas.mul(l, inv);
    let ratio = cas.bind(ratio);
    let soft = cas.powi(ratio, 3);
    let off = cas.sqrt(ratio);
    (cas.bind(soft), cas.bind(off))
}

/// V_a(q) of the structure's chambers and tendons; zero without them.
pub fn actuation(
    cas: &mut Cas,
    symbols: &ParamSymbols,
    structure: &Structure,
    strains: &[Strain],
) -> ExprId {
    if structure.chambers.iter().all(|&c| c == 0) && structure.tendons.is_empty() {
        return cas.zero();
    }
    let n = structure.segments.len();
    // Per segment: total stretch and total bend about y and z.
    let mut sums = vec![[Vec::new(), Vec::new(), Vec::new()]; n];
    for s in strains {
        let (by, bz) = match s.offset_scale {
            Some(k) => (cas.mul(s.rho[1], k), cas.mul(s.rho[2], k)),
            None => (s.rho[1], s.rho[2]),
        };
        sums[s.segment][0].push(s.stretch);
        sums[s.segment][1].push(by);
        sums[s.segment][2].push(bz);
    }
    let totals: Vec<[ExprId; 3]> = sums
        .iter()
        .map(|parts| {
            parts.clone().map(|p| {
                let e = cas.add_all(&p);
                cas.bind(e)
            })
        })
        .collect();
    // Length change of a fibre at (y, z) through segment s.
    let fibre = |cas: &mut Cas, s: usize, y: ExprId, z: ExprId| {
        let [st, by, bz] = totals[s];
        let a = cas.mul(by, z);
        let b = cas.mul(bz, y);
        let b = cas.neg(b);
        cas.add_all(&[st, a, b])
    };
    let mut potential = Vec::new();
    for (s, &count) in structure.chambers.iter().enumerate() {
        for j in 0..count {
            let key = |what| {
                symbols.get(Param::Chamber {
                    segment: s,
                    position: j,
                    what,
                })
            };
            let p = key(ChamberParam::Pressure);
            // The position's holes together: area a, first moments a sum z
            // (lever of bend y) and a sum y (of bend z).
            let (area, arm_y, arm_z) = (
                key(ChamberParam::Area),
                key(ChamberParam::ArmY),
                key(ChamberParam::ArmZ),
            );
            let [st, by, bz] = totals[s];
            let a = cas.mul(area, st);
            let b = cas.mul(arm_y, by);
            let c = cas.mul(arm_z, bz);
            let c = cas.neg(c);
            let work = cas.add_all(&[a, b, c]);
            let w = cas.mul(p, work);
            potential.push(cas.neg(w));
        }
    }
    for (i, &end) in structure.tendons.iter().enumerate() {
        let t = symbols.get(Param::TendonTension(i));
        // Tension only: (T + |T|) / 2.
        let abs = cas.func(Func::Abs, t);
        let sum = cas.add(t, abs);
        let pull = cas.scaled(0.5, sum);
        let lengths: Vec<ExprId> = (0..=end)
            .map(|s| {
                let offset = |z| {
                    symbols.get(Param::TendonOffset {
                        tendon: i,
                        segment: s,
                        z,
                    })
                };
                let (y, z) = (offset(false), offset(true));
                fibre(cas, s, y, z)
            })
            .collect();
        let length = cas.add_all(&lengths);
        potential.push(cas.mul(pull, length));
    }
    cas.add_all(&potential)
}
