//! Loads along the arm (`[[load]]`): each acts at a point of an element,
//! which the element's method places (the same frame it samples its
//! contact points from); a force per unit length acts at every element's
//! middle, times the element's length (the midpoint rule: second order).

use crate::cas::{Cas, ExprId};
use crate::model::{ElementParam, LoadParam, Param, Structure, Xyz};

use super::system::{AppliedMoment, ParamSymbols, PointForce, System};

/// A load at the fraction `fraction` of element `element`.
#[derive(Clone)]
pub struct AlongLoad {
    pub element: usize,
    pub fraction: f64,
    /// Given in the section's frame, turning with it.
    pub local: bool,
    pub force: Option<[ExprId; 3]>,
    pub moment: Option<[ExprId; 3]>,
}

/// Where along an element a load acts, as the element's method places it:
/// the point, the section's rotation (rows: world from section) and its
/// angular velocity.
pub struct Placed {
    pub point: [ExprId; 3],
    pub rotation: [[ExprId; 3]; 3],
    pub omega: [ExprId; 3],
}

/// What the loads apply, each with the chain link it moves with.
#[derive(Default)]
pub struct Applied {
    pub forces: Vec<(PointForce, usize)>,
    pub moments: Vec<(AppliedMoment, usize)>,
}

/// The structure's loads element by element.
pub fn along_loads(cas: &mut Cas, st: &Structure, symbols: &ParamSymbols) -> Vec<AlongLoad> {
    let mut out = Vec::new();
    for (i, l) in st.loads.iter().enumerate() {
        let vector = |what: fn(Xyz) -> LoadParam| symbols.xyz(|c| Param::Load(i, what(c)));
        let force = l.force.then(|| vector(LoadParam::Force));
        let moment = l.moment.then(|| vector(LoadParam::Moment));
        match l.at {
            Some((element, bits)) => out.push(AlongLoad {
                element,
                fraction: f64::from_bits(bits),
                local: l.local,
                force,
                moment,
            }),
            None => {
                let first: usize = st.segments[..l.segment].iter().map(|g| g.elements).sum();
                for k in first..first + st.segments[l.segment].elements {
                    let len = symbols.element(k, ElementParam::Length);
                    out.push(AlongLoad {
                        element: k,
                        fraction: 0.5,
                        local: l.local,
                        force: force.map(|f| f.map(|c| cas.mul(c, len))),
                        moment: None,
                    });
                }
            }
        }
    }
    out
}

impl Applied {
    /// Add what the loads apply to `sys`, each with its chain link.
    pub fn attach(self, sys: &mut System) {
        for (f, link) in self.forces {
            sys.point_forces.push(f);
            if let Some(c) = &mut sys.chain {
                c.point_force_link.push(link);
            }
        }
        for (m, link) in self.moments {
            sys.moments.push(m);
            if let Some(c) = &mut sys.chain {
                c.moment_link.push(link);
            }
        }
    }

    /// Apply the loads on element `k`, which moves with chain link `link`,
    /// its points placed by `at`.
    pub fn element(
        &mut self,
        cas: &mut Cas,
        loads: &[AlongLoad],
        (k, link): (usize, usize),
        at: &mut dyn FnMut(&mut Cas, f64) -> Placed,
    ) {
        for l in loads.iter().filter(|l| l.element == k) {
            let placed = at(cas, l.fraction);
            let turned = |cas: &mut Cas, v: [ExprId; 3]| match l.local {
                true => placed.rotation.map(|row| {
                    let e = cas.dot(&row, &v);
                    cas.bind(e)
                }),
                false => v,
            };
            if let Some(f) = l.force {
                let force = turned(cas, f);
                let point = placed.point.map(|c| cas.bind(c));
                self.forces.push((PointForce { point, force }, link));
            }
            if let Some(m) = l.moment {
                let moment = turned(cas, m);
                let omega = placed.omega;
                self.moments.push((AppliedMoment { omega, moment }, link));
            }
        }
    }
}
