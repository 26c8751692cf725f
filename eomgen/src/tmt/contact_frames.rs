//! The contact frames of a serial chain (`runtime::ModelInfo::contact_frames`):
//! what the `Accel` kernel exports so that contact costs little where
//! nothing touches and a few elements' worth where something does.
//!
//! A point of element e moves with the coordinates before e only through
//! the frame e starts from (the chain's invariant, `Chain`). So the
//! `ContactJacobian` group of element e need not compute the chain from
//! the base: it reads that frame F_e = (O_e, R_e) and, for each earlier
//! coordinate j, the twist (w_j, v_j) its rate gives every frame past its
//! link (about the world origin), and computes
//!
//! * p = O_e + R_e l(q_e), l the point in F_e: the point with the earlier
//!   coordinates set to zero, taken back into its frame there;
//! * dp/dq_j = R_e dl/dq_j for e's own coordinates and v_j + w_j x p for
//!   the earlier ones;
//! * v = (dp/dq) qd.
//!
//! The frames also carry each element's start A = O_e, last point B and
//! centreline length L: a point s along the centreline is within s L of A
//! and (1 - s) L of B, so every point of the element lies in the
//! ellipsoid of foci A and B and major axis L. The runtime's broad phase
//! skips the elements whose ellipsoid clears every obstacle, and the
//! `Accel` kernel gives these few values per element in place of every
//! point.

use std::ops::Range;

use rustc_hash::FxHashMap as HashMap;

use super::system::{Sample, System};
use crate::cas::{Cas, ExprId, SymKind};

/// The frames' values (the `Accel` and `Contact` kernels' outputs) and the
/// `ContactJacobian` groups that read them.
pub struct ContactFrames {
    pub values: Vec<ExprId>,
    /// Per group, per point: p (3), v (3), dp/dq (3 x n, row-major).
    pub groups: Vec<Vec<ExprId>>,
}

/// A group of points: the coordinates they depend on, and which points.
pub struct PointGroup {
    pub depends: Vec<bool>,
    pub points: Range<usize>,
}

/// Each group's base frame: the arm's base, then the last point of the
/// group before (its link's end); None where a group reads a later link's
/// coordinates, has no points, or has points without a centreline.
fn group_bases(
    sys: &System,
    groups: &[PointGroup],
    link_of: &[Option<usize>],
    planar: bool,
) -> Option<Vec<Sample>> {
    let n = sys.coords.q.len();
    let mut bases: Vec<Sample> = Vec::with_capacity(groups.len());
    for (g, group) in groups.iter().enumerate() {
        let on_later_link = (0..n).any(|j| group.depends[j] && link_of[j].is_none_or(|k| k > g));
        let samples = &sys.samples[group.points.clone()];
        if on_later_link
            || group.points.is_empty()
            || samples
                .iter()
                .any(|s| s.arc.is_none() || s.angle.is_some() != planar)
        {
            return None;
        }
        bases.push(match g {
            0 => sys.bases[0],
            _ => sys.samples[groups[g - 1].points.end - 1],
        });
    }
    Some(bases)
}

/// The values the groups read: A, B, L per group (the ends as the chain
/// has them, which the mass matrix shares); the base frames' orientations
/// (from `orientation_at`); the twists of every link's coordinates but
/// the last's (from `twist_at`, at `twist_index` of a coordinate).
fn frame_values(
    cas: &mut Cas,
    sys: &System,
    groups: &[PointGroup],
    bases: &[Sample],
    link_of: &[Option<usize>],
) -> (Vec<ExprId>, usize, usize, Vec<usize>) {
    let chain = sys.chain.as_ref().expect("a chain");
    let n = sys.coords.q.len();
    let mut values = Vec::new();
    for (g, group) in groups.iter().enumerate() {
        let last = sys.samples[group.points.end - 1];
        values.extend(match g {
            0 => sys.bases[0].point,
            _ => chain.links[g - 1].end,
        });
        values.extend(chain.links[g].end);
        values.push(last.arc.expect("checked above"));
    }
    let orientation_at = values.len();
    for base in bases {
        match base.angle {
            Some(a) => values.push(a),
            None => values.extend(base.frame),
        }
    }
    // Twists of the coordinates of every link but the last.
    let twist_at = values.len();
    let upstream: Vec<usize> = chain.links[..chain.links.len() - 1]
        .iter()
        .flat_map(|l| l.coords.iter().copied())
        .collect();
    let mut twist_index = vec![usize::MAX; n];
    for (t, &j) in upstream.iter().enumerate() {
        twist_index[j] = t;
        let link = &chain.links[link_of[j].expect("a link's coordinate")];
        let (q, qd) = (sys.coords.q[j], sys.coords.qd[j]);
        let w = link.end_omega.map(|c| cas.diff(c, qd));
        let jo = link.end.map(|c| cas.diff(c, q));
        let w_x_end = cas.cross(&w, &link.end);
        let v: Vec<ExprId> = (0..3).map(|c| cas.sub(jo[c], w_x_end[c])).collect();
        values.extend(v);
        values.extend(w);
    }
    (values, orientation_at, twist_at, twist_index)
}

/// The contact frames of `sys`, when it is one serial chain of elements
/// each sampled along a centreline of known length, group g on link g;
/// None where not (assemblies, shared coordinates, a moving base, a method
/// that does not give its centreline's length): those groups compute the
/// chain from the base.
pub fn contact_frames(cas: &mut Cas, sys: &System, groups: &[PointGroup]) -> Option<ContactFrames> {
    let chain = sys.chain.as_ref()?;
    if !sys.seeds.is_empty() || sys.bases.len() != 1 || chain.links.len() != groups.len() {
        return None;
    }
    let n = sys.coords.q.len();
    let mut link_of = vec![None; n];
    for (k, l) in chain.links.iter().enumerate() {
        for &c in &l.coords {
            link_of[c] = Some(k);
        }
    }
    let planar = sys.bases[0].angle.is_some();
    let bases = group_bases(sys, groups, &link_of, planar)?;
    let per_frame = if planar { 1 } else { 4 };
    let (values, orientation_at, twist_at, twist_index) =
        frame_values(cas, sys, groups, &bases, &link_of);
    // What the groups read: a constant value in place, else `aux[m]`.
    let aux: Vec<ExprId> = values
        .iter()
        .enumerate()
        .map(|(m, &v)| match cas.as_const(v) {
            Some(_) => v,
            None => cas.symbol(&format!("aux{m}"), SymKind::Aux(m as u32)),
        })
        .collect();

    let zero = cas.zero();
    let mut outs = Vec::with_capacity(groups.len());
    for (g, (group, base)) in groups.iter().zip(&bases).enumerate() {
        let own = &chain.links[g].coords;
        // The point in its frame: earlier coordinates at zero, taken back
        // by the frame there (parameters only: hoisted out of the kernel).
        let earlier: HashMap<_, _> = chain.links[..g]
            .iter()
            .flat_map(|l| l.coords.iter())
            .map(|&j| {
                (
                    cas.sym_id(sys.coords.q[j]).expect("a coordinate symbol"),
                    zero,
                )
            })
            .collect();
        let mut exprs: Vec<ExprId> = base.point.to_vec();
        match base.angle {
            Some(a) => exprs.push(a),
            None => exprs.extend(base.frame),
        }
        for s in &sys.samples[group.points.clone()] {
            exprs.extend(s.point);
        }
        let at_zero = cas.substitute(&exprs, &earlier);
        let (o0, rest) = at_zero.split_at(3);
        let (f0, points0) = rest.split_at(per_frame);
        let r0 = rotation(cas, f0);
        let o = [0, 1, 2].map(|c| aux[7 * g + c]);
        let f = &aux[orientation_at + per_frame * g..][..per_frame];
        let r = rotation(cas, f);
        // The frame's twist (about the world origin) from the earlier
        // coordinates' rates.
        let (mut frame_v, mut frame_w) = ([zero; 3], [zero; 3]);
        for l in &chain.links[..g] {
            for &j in &l.coords {
                let at = twist_at + 6 * twist_index[j];
                let qd = sys.coords.qd[j];
                for c in 0..3 {
                    let v = cas.mul(aux[at + c], qd);
                    frame_v[c] = cas.add(frame_v[c], v);
                    let w = cas.mul(aux[at + 3 + c], qd);
                    frame_w[c] = cas.add(frame_w[c], w);
                }
            }
        }
        let frame_v = frame_v.map(|e| cas.bind(e));
        let frame_w = frame_w.map(|e| cas.bind(e));
        let mut out = Vec::new();
        for p0 in points0.chunks_exact(3) {
            let d: Vec<ExprId> = (0..3).map(|c| cas.sub(p0[c], o0[c])).collect();
            let local: Vec<ExprId> = (0..3)
                .map(|c| {
                    let col = [r0[0][c], r0[1][c], r0[2][c]];
                    cas.dot(&col, &d)
                })
                .collect();
            // Bound: the Jacobian's columns read p whole.
            let p: [ExprId; 3] = [0, 1, 2].map(|c| {
                let turned = cas.dot(&r[c], &local);
                let p = cas.add(o[c], turned);
                cas.bind(p)
            });
            let mut jac = vec![zero; 3 * n];
            for j in 0..n {
                if own.contains(&j) {
                    for c in 0..3 {
                        jac[c * n + j] = cas.diff(p[c], sys.coords.q[j]);
                    }
                } else if twist_index[j] != usize::MAX && link_of[j].is_some_and(|k| k < g) {
                    let at = twist_at + 6 * twist_index[j];
                    let v = [0, 1, 2].map(|c| aux[at + c]);
                    let w = [0, 1, 2].map(|c| aux[at + 3 + c]);
                    let w_x_p = cas.cross(&w, &p);
                    for c in 0..3 {
                        jac[c * n + j] = cas.add(v[c], w_x_p[c]);
                    }
                }
            }
            // v = V + W x p + (own columns) qd: the frame's twist from the
            // earlier rates, once for every point of the group.
            let w_x_p = cas.cross(&frame_w, &p);
            let vel: Vec<ExprId> = (0..3)
                .map(|c| {
                    let own_part: Vec<ExprId> = own
                        .iter()
                        .map(|&j| cas.mul(jac[c * n + j], sys.coords.qd[j]))
                        .collect();
                    let own_sum = cas.add_all(&own_part);
                    cas.add_all(&[frame_v[c], w_x_p[c], own_sum])
                })
                .collect();
            out.extend(p);
            out.extend(vel);
            out.extend(jac);
        }
        outs.push(out);
    }
    Some(ContactFrames {
        values,
        groups: outs,
    })
}

/// The rotation matrix (rows) of a planar angle or a unit quaternion
/// (w, x, y, z).
fn rotation(cas: &mut Cas, f: &[ExprId]) -> [[ExprId; 3]; 3] {
    let (zero, one) = (cas.zero(), cas.one());
    if let [a] = *f {
        let (c, s) = (cas.cos(a), cas.sin(a));
        let ns = cas.neg(s);
        return [[c, ns, zero], [s, c, zero], [zero, zero, one]];
    }
    let [w, x, y, z] = [f[0], f[1], f[2], f[3]];
    let two = |cas: &mut Cas, a: ExprId, b: ExprId| {
        let m = cas.mul(a, b);
        cas.scaled(2.0, m)
    };
    let (xx, yy, zz) = (two(cas, x, x), two(cas, y, y), two(cas, z, z));
    let (xy, xz, yz) = (two(cas, x, y), two(cas, x, z), two(cas, y, z));
    let (wx, wy, wz) = (two(cas, w, x), two(cas, w, y), two(cas, w, z));
    let diag = |cas: &mut Cas, a: ExprId, b: ExprId| {
        let s = cas.add(a, b);
        cas.sub(one, s)
    };
    [
        [diag(cas, yy, zz), cas.sub(xy, wz), cas.add(xz, wy)],
        [cas.add(xy, wz), diag(cas, xx, zz), cas.sub(yz, wx)],
        [cas.sub(xz, wy), cas.add(yz, wx), diag(cas, xx, yy)],
    ]
}
