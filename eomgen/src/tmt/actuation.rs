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
use crate::model::{ChamberParam, Param, ParamLayout, Structure};
use runtime::Tape;

use super::system::ParamSymbols;

/// The lumped strain of one element, slice or joint.
pub struct Strain {
    pub segment: usize,
    /// The element (slice, link) whose parameters it reads.
    pub element: usize,
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

/// The actuators' loads on a segment's fibre strains: V_a of one element
/// is -(st c_st + k (by c_by + bz c_bz)) for its strain (stretch st,
/// bends by, bz, offset scale k), linear in the strain, so the loads are
/// per segment and the potential a sum over elements (which lets the link
/// recursion give each link's cell its segment's loads as parameters).
/// With chambers j (pressure p, area a, first moments arm_y, arm_z) and
/// tendons i through the segment (pull T+ = max(T, 0), offset (y, z)):
///
///   c_st = sum_j p_j a_j - sum_i T+_i,
///   c_by = sum_j p_j arm_y_j - sum_i T+_i z_i,
///   c_bz = -sum_j p_j arm_z_j + sum_i T+_i y_i.
///
/// None for a segment no actuator acts on.
pub fn segment_loads(
    cas: &mut Cas,
    symbols: &ParamSymbols,
    structure: &Structure,
) -> Vec<Option<[ExprId; 3]>> {
    (0..structure.segments.len())
        .map(|s| loads_on(cas, symbols, structure, s, None))
        .collect()
}

/// The loads on segment `s`'s strains ([`segment_loads`]), with element
/// `element`'s own chamber levers where they vary along the segment.
pub fn loads_on(
    cas: &mut Cas,
    symbols: &ParamSymbols,
    structure: &Structure,
    s: usize,
    element: Option<usize>,
) -> Option<[ExprId; 3]> {
    let mut parts = [Vec::new(), Vec::new(), Vec::new()];
    for position in 0..structure.chambers[s] {
        let key = |what| {
            symbols.get(Param::Chamber {
                segment: s,
                position,
                what,
            })
        };
        let lever = |what, z| match element {
            Some(element) => symbols.get(Param::ChamberArm {
                element,
                position,
                z,
            }),
            None => key(what),
        };
        let p = key(ChamberParam::Pressure);
        // The position's holes together: area a, first moments a sum z
        // (lever of bend y) and a sum y (of bend z).
        let area = cas.mul(p, key(ChamberParam::Area));
        let arm_y = cas.mul(p, lever(ChamberParam::ArmY, false));
        let arm_z = cas.mul(p, lever(ChamberParam::ArmZ, true));
        parts[0].push(area);
        parts[1].push(arm_y);
        parts[2].push(cas.neg(arm_z));
    }
    for (i, &end) in structure.tendons.iter().enumerate() {
        if s > end {
            continue;
        }
        let t = symbols.get(Param::TendonTension(i));
        // Tension only: (T + |T|) / 2.
        let abs = cas.func(Func::Abs, t);
        let sum = cas.add(t, abs);
        let pull = cas.scaled(0.5, sum);
        let offset = |z| {
            symbols.get(Param::TendonOffset {
                tendon: i,
                segment: s,
                z,
            })
        };
        let (y, z) = (offset(false), offset(true));
        parts[0].push(cas.neg(pull));
        let pz = cas.mul(pull, z);
        parts[1].push(cas.neg(pz));
        parts[2].push(cas.mul(pull, y));
    }
    (!parts[0].is_empty()).then(|| parts.map(|p| cas.add_all(&p)))
}

/// The virtual work of a segment's loads ([`segment_loads`]) on one
/// element's strain, in the strain's own symbols: st c_st + k (by c_by +
/// bz c_bz) with by, bz the bends about y and z and k the offset scale.
pub fn strain_work(
    cas: &mut Cas,
    [c_st, c_by, c_bz]: [ExprId; 3],
    stretch: ExprId,
    rho: [ExprId; 3],
    offset_scale: Option<ExprId>,
) -> ExprId {
    let a = cas.mul(c_by, rho[1]);
    let b = cas.mul(c_bz, rho[2]);
    let bend = cas.add(a, b);
    let bend = match offset_scale {
        Some(k) => cas.mul(k, bend),
        None => bend,
    };
    let st = cas.mul(c_st, stretch);
    cas.add(st, bend)
}

/// V_a(q) of the structure's chambers and tendons: minus the work of each
/// segment's loads on its elements' strains; zero without actuators.
pub fn actuation(
    cas: &mut Cas,
    symbols: &ParamSymbols,
    structure: &Structure,
    strains: &[Strain],
) -> ExprId {
    let loads = segment_loads(cas, symbols, structure);
    let mut work = Vec::new();
    for s in strains {
        let load = match structure.segments[s.segment].chambers_vary {
            true => loads_on(cas, symbols, structure, s.segment, Some(s.element)),
            false => loads[s.segment],
        };
        if let Some(load) = load {
            work.push(strain_work(cas, load, s.stretch, s.rho, s.offset_scale));
        }
    }
    let work = cas.add_all(&work);
    cas.neg(work)
}

/// The actuated segments' loads ([`segment_loads`]) as a kernel of the
/// parameters alone, three values a segment, or an element where its
/// chamber levers vary along the segment: what the link cells and an eba
/// arm's joint parts read their loads from, so that an actuated arm and a
/// bare one share those kernels.
pub struct ActuationLoads {
    /// None without actuators.
    pub tape: Option<Tape>,
    /// Whose each triple is: a segment's (element None), or one element's
    /// of it.
    pub owners: Vec<(usize, Option<usize>)>,
}

impl ActuationLoads {
    pub fn of(params: &ParamLayout, st: &Structure) -> Self {
        let mut cas = Cas::new();
        let cas = &mut cas;
        let symbols = ParamSymbols::new(cas, params);
        let loads = segment_loads(cas, &symbols, st);
        let (mut owners, mut out) = (Vec::new(), Vec::new());
        let mut first = 0;
        for (s, g) in st.segments.iter().enumerate() {
            if loads[s].is_some() {
                let elements: Vec<Option<usize>> = match g.chambers_vary {
                    true => (first..first + g.elements).map(Some).collect(),
                    false => vec![None],
                };
                for element in elements {
                    let load = match element {
                        Some(k) => loads_on(cas, &symbols, st, s, Some(k)),
                        None => loads[s],
                    };
                    out.extend(load.expect("the segment is actuated"));
                    owners.push((s, element));
                }
            }
            first += g.elements;
        }
        let tape = (!owners.is_empty()).then(|| cas.to_tape(&out));
        Self { tape, owners }
    }

    /// Which triple acts on element `k` of segment `s`; None where no
    /// actuator acts.
    pub fn find(&self, s: usize, k: usize) -> Option<usize> {
        (self.owners.iter()).position(|&(seg, el)| seg == s && el.is_none_or(|el| el == k))
    }
}
