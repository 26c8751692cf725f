//! Loads along the arm (`[[load]]`, `[fluid]`): each acts at a point of an
//! element, which the element's method places (the same frame it samples
//! its contact points from); a force per unit length acts at every
//! element's middle, times the element's length (the midpoint rule:
//! second order). An immersed element's buoyancy is such a force; its
//! drag a dissipation function of its middle's velocity relative to the
//! current.

use crate::cas::{Cas, ExprId};
use crate::model::{ElementParam, FluidParam, LoadParam, Param, Structure, Xyz};

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

/// What the loads apply, each with the chain link it moves with, and the
/// fluid's drag (its dissipation function's terms).
#[derive(Default)]
pub struct Applied {
    pub forces: Vec<(PointForce, usize)>,
    pub moments: Vec<(AppliedMoment, usize)>,
    /// The fluid, where it drags.
    pub drag: Option<Drag>,
    dissipation: Vec<ExprId>,
    /// The fluid's density, where the arm is immersed.
    pub buoyancy: Option<ExprId>,
}

/// A dragging fluid's parameters.
#[derive(Clone, Copy)]
pub struct Drag {
    density: ExprId,
    normal: ExprId,
    tangential: ExprId,
    current: [ExprId; 3],
}

impl Drag {
    /// The structure's fluid, where it drags.
    pub fn of(st: &Structure, symbols: &ParamSymbols) -> Option<Drag> {
        let p = |f| symbols.get(Param::Fluid(f));
        st.fluid.filter(|&drags| drags).map(|_| Drag {
            density: p(FluidParam::Density),
            normal: p(FluidParam::DragNormal),
            tangential: p(FluidParam::DragTangential),
            current: symbols.xyz(|c| Param::Fluid(FluidParam::Current(c))),
        })
    }

    /// Morison's drag on element k as a dissipation function of its
    /// middle's velocity v relative to the current: (c_n / 3) |v_n|^3 +
    /// (c_t / 3) |v_t|^3, c_n = rho C_n d l / 2, c_t = rho C_t pi d l / 2,
    /// whose rate derivatives are the forces -c |v_n| v_n and -c |v_t| v_t.
    /// The magnitudes are sqrt(v^2 + eps^2), eps 1 um/s, so that the
    /// Jacobian stays finite at rest.
    fn dissipation(
        &self,
        cas: &mut Cas,
        symbols: &ParamSymbols,
        k: usize,
        axis: [ExprId; 3],
        velocity: [ExprId; 3],
    ) -> ExprId {
        let v: [ExprId; 3] = std::array::from_fn(|c| cas.sub(velocity[c], self.current[c]));
        let along = cas.dot(&v, &axis);
        let along = cas.bind(along);
        let speed2 = cas.dot(&v, &v);
        let along2 = cas.mul(along, along);
        let across2 = cas.sub(speed2, along2);
        let eps2 = cas.constant(1e-12);
        let cubed = |cas: &mut Cas, x2: ExprId| {
            let x2 = cas.add(x2, eps2);
            let x2 = cas.bind(x2);
            let r = cas.sqrt(x2);
            cas.mul(x2, r)
        };
        let (n3, t3) = (cubed(cas, across2), cubed(cas, along2));
        let d = symbols.element(k, ElementParam::Width);
        let l = symbols.element(k, ElementParam::Length);
        let base = cas.mul_all(&[self.density, d, l]);
        let cn = cas.mul(self.normal, base);
        let ct = cas.mul_all(&[self.tangential, base]);
        let ct = cas.scaled(std::f64::consts::PI, ct);
        let terms = [cas.mul(cn, n3), cas.mul(ct, t3)];
        let sum = cas.add_all(&terms);
        cas.scaled(1.0 / 6.0, sum)
    }
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

/// The displaced fluid's weight on every body of the arm, upward, where
/// the body's own weight acts (so that an arm of the fluid's density
/// floats exactly): body b of element k displaces its share of the
/// element's volume, m_b rho_f V_k / m_k. Bodies are the arm's elements'
/// (link k is element k); a tip body displaces nothing.
fn buoyancy(
    cas: &mut Cas,
    sys: &mut System,
    symbols: &ParamSymbols,
    body_link: &[usize],
    rho: ExprId,
) {
    let g = sys.gravity;
    let mut forces = Vec::new();
    for (b, &k) in body_link.iter().enumerate() {
        let body = &sys.bodies[b];
        let v = symbols.element(k, ElementParam::Volume);
        let m = symbols.element(k, ElementParam::Mass);
        let inv = cas.powi(m, -1);
        let displaced = cas.mul_all(&[body.mass, rho, v, inv]);
        let displaced = cas.neg(displaced);
        let force = g.map(|c| cas.mul(displaced, c));
        forces.push((
            PointForce {
                point: body.position,
                force,
            },
            k,
        ));
    }
    for (f, link) in forces {
        sys.point_forces.push(f);
        if let Some(c) = &mut sys.chain {
            c.point_force_link.push(link);
        }
    }
}

impl Applied {
    /// Add what the loads apply to `sys`, each with its chain link.
    pub fn attach(
        self,
        cas: &mut Cas,
        sys: &mut System,
        symbols: &ParamSymbols,
        body_link: &[usize],
    ) {
        if let Some(rho) = self.buoyancy {
            buoyancy(cas, sys, symbols, body_link, rho);
        }
        if !self.dissipation.is_empty() {
            let terms = [&[sys.rayleigh][..], &self.dissipation].concat();
            sys.rayleigh = cas.add_all(&terms);
        }
        for (f, link) in self.forces {
            sys.point_forces.push(f);
            if let Some(c) = &mut sys.chain {
                c.point_force_link.push(link);
            }
        }
        for (m, link) in self.moments {
            sys.moments.push(m);
            if let Some(c) = &mut sys.chain {
                c.moment_link.push((link, true));
            }
        }
    }

    /// Apply the loads on element `k`, which moves with chain link `link`,
    /// its points placed by `at`, their velocities by the time derivative
    /// over the arm's (coordinate, rate) pairs.
    pub fn element(
        &mut self,
        cas: &mut Cas,
        loads: &[AlongLoad],
        (k, link): (usize, usize),
        at: &mut dyn FnMut(&mut Cas, f64) -> Placed,
        rate_pairs: &[(ExprId, ExprId)],
        symbols: &ParamSymbols,
    ) {
        if let Some(drag) = self.drag {
            let middle = at(cas, 0.5);
            let axis = middle.rotation.map(|row| row[0]);
            let v = cas.time_derivatives(&middle.point, rate_pairs);
            let v = [v[0], v[1], v[2]];
            let d = drag.dissipation(cas, symbols, k, axis, v);
            self.dissipation.push(d);
        }
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
