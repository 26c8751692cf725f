//! Planar kinematics: chains in the x-y plane, rotations about z.
//!
//! Rigid elements: each element k has a revolute joint at its base with
//! relative angle q_k; its frame is the previous frame rotated by q_k. The
//! body is the element's centre of mass at half its length.

use crate::cas::{Cas, ExprId, SymKind};
use crate::model::{Method, Model, Structure, parameters};

use super::system::{Body, Coordinates, PointForce, System};

/// Build the planar system of a model. Only the structure and the
/// parameter layout are read from `model`; values stay symbols.
pub fn planar_system(cas: &mut Cas, model: &Model) -> System {
    let structure = Structure::of(model);
    let names: Vec<String> = parameters(model).into_iter().map(|(n, _)| n).collect();
    let p: Vec<ExprId> = names
        .iter()
        .enumerate()
        .map(|(i, n)| cas.symbol(n, SymKind::Param(i as u32)))
        .collect();
    let param = |name: &str| -> ExprId {
        let i = names
            .iter()
            .position(|n| n == name)
            .unwrap_or_else(|| panic!("no parameter {name}"));
        p[i]
    };

    let mut coord_names = Vec::new();
    for (s, &(method, n)) in structure.segments.iter().enumerate() {
        for e in 0..n {
            coord_names.push(match method {
                Method::Rigid => format!("theta_{s}_{e}"),
            });
        }
    }
    let coords = Coordinates::new(cas, coord_names);
    let zero = cas.zero();

    // Frame: origin (x, y) and absolute angle phi (from +x); w = its rate.
    // Absolute angles keep the velocity map cheap: d(cos phi)/dt = -sin(phi) w,
    // whose partial derivative in any qd_i (i <= k) is one shared node.
    let mut x = param("base.x");
    let mut y = param("base.y");
    let z = param("base.z");
    let mut phi = param("base.angle");
    let mut w = zero;

    let mut bodies = Vec::new();
    let mut elastic = Vec::new();
    let mut rayleigh = Vec::new();
    let mut k = 0;
    for &(method, n) in &structure.segments {
        for _ in 0..n {
            let (q, qd) = (coords.q[k], coords.qd[k]);
            let l = param(&format!("element[{k}].length"));
            let m = param(&format!("element[{k}].mass"));
            let inertia = param(&format!("element[{k}].inertia"));
            let stiff = param(&format!("joint[{k}].stiffness"));
            let damp = param(&format!("joint[{k}].damping"));
            match method {
                Method::Rigid => {
                    let p1 = cas.add(phi, q);
                    phi = cas.bind(p1);
                    let w1 = cas.add(w, qd);
                    w = cas.bind(w1);
                    let (c, s) = (cas.cos(phi), cas.sin(phi));
                    let half = cas.scaled(0.5, l);
                    let cx = offset(cas, x, half, c);
                    let cy = offset(cas, y, half, s);
                    bodies.push(Body {
                        mass: m,
                        inertia: [inertia; 3],
                        position: [cas.bind(cx), cas.bind(cy), z],
                        omega: [zero, zero, w],
                    });
                    let nx = offset(cas, x, l, c);
                    let ny = offset(cas, y, l, s);
                    x = cas.bind(nx);
                    y = cas.bind(ny);
                    elastic.push(half_k_sq(cas, stiff, q));
                    rayleigh.push(half_k_sq(cas, damp, qd));
                }
            }
            k += 1;
        }
    }

    let tip = [x, y, z];
    if structure.tip_mass {
        let mass = param("tip.mass");
        bodies.push(Body {
            mass,
            inertia: [zero; 3],
            position: tip,
            omega: [zero; 3],
        });
    }
    let mut point_forces = Vec::new();
    if structure.tip_force {
        let force = [
            param("tip.force.x"),
            param("tip.force.y"),
            param("tip.force.z"),
        ];
        point_forces.push(PointForce { point: tip, force });
    }
    let gravity = [param("gravity.x"), param("gravity.y"), param("gravity.z")];
    let elastic = cas.add_all(&elastic);
    let rayleigh = cas.add_all(&rayleigh);
    System {
        coords,
        bodies,
        gravity,
        elastic,
        rayleigh,
        point_forces,
        tip,
    }
}

/// x + l * dir
fn offset(cas: &mut Cas, x: ExprId, l: ExprId, dir: ExprId) -> ExprId {
    let d = cas.mul(l, dir);
    cas.add(x, d)
}

/// k x^2 / 2
fn half_k_sq(cas: &mut Cas, k: ExprId, x: ExprId) -> ExprId {
    let x2 = cas.powi(x, 2);
    let e = cas.mul(k, x2);
    cas.scaled(0.5, e)
}
