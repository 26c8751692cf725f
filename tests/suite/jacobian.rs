//! The generated Jacobian of the right-hand side against (five-point)
//! central finite differences of the right-hand side, on random states of every bundled
//! model (including states with angles exactly 0).

use crate::common::*;
use nalgebra::DMatrix;
use runtime::{Dynamics, Workspace, accelerations, rhs_jacobian};
use softarm::backend::{BackendChoice, load};
use softarm::generated::MODELS;

fn rhs(d: &dyn Dynamics, ws: &mut Workspace, x: &[f64]) -> Vec<f64> {
    let n = d.dof();
    let mut qdd = vec![0.0; n];
    accelerations(d, ws, 0.3, &x[..n], &x[n..], &mut qdd).unwrap();
    x[n..].iter().copied().chain(qdd).collect()
}

#[test]
fn generated_jacobian_matches_central_differences() {
    let damped: Vec<eomgen::model::Override> = [
        "segment.0.elements=6",
        "segment.0.bending_damping=1e-4",
        "gravity=[0, -9.81, 0]",
    ]
    .iter()
    .map(|s| eomgen::model::Override::parse(s).unwrap())
    .collect();
    let eba: Vec<eomgen::model::Override> = [
        "segment.0.method=eba",
        "segment.0.elements=3",
        "segment.0.bending_damping=1e-3",
        "gravity=[0, -9.81, 0]",
        "tip.force=[0.1, 0.2, -0.3]",
    ]
    .iter()
    .map(|s| eomgen::model::Override::parse(s).unwrap())
    .collect();
    let cases: Vec<(&str, &[eomgen::model::Override], BackendChoice)> = MODELS
        .iter()
        .map(|m| (m.name, &[][..], BackendChoice::Compiled))
        .chain([
            ("cantilever", &damped[..], BackendChoice::Interpreted),
            ("cantilever3d", &eba[..], BackendChoice::Interpreted),
        ])
        .collect();
    for (name, sets, backend) in cases {
        let dir = std::env::temp_dir().join("softarm-test-cache");
        let l = load(name, sets, backend, Some(dir)).unwrap();
        let m = &l.model;
        let d = &*l.arm;
        let n = d.dof();
        // With joints the Jacobian is central differences of the
        // constrained solve itself: nothing generated to check here
        // (tests/suite/joints.rs runs every solver on it).
        if !d.info().constraints.is_empty() {
            continue;
        }
        let mut ws = Workspace::new(n);
        // Each model its own states: adding a model moves no other's.
        let seed = name
            .bytes()
            .fold(5u64, |h, b| h.wrapping_mul(31).wrapping_add(b.into()));
        let mut rng = Rng::new(seed);
        for it in 0..4 {
            let mut x = rng.coordinates(&d.info().coordinates, -1.0, 1.0);
            x.extend(rng.vec(n, -1.0, 1.0));
            if it == 0 {
                x[..n].fill(0.0);
            }
            let mut jac = DMatrix::zeros(2 * n, 2 * n);
            rhs_jacobian(d, &mut ws, 0.3, &x, &mut jac).unwrap();
            let scale = jac.amax();
            for j in 0..2 * n {
                // Five-point central difference: O(h^4) truncation, so a
                // step large enough to keep round-off well below 1e-6.
                let h = 1e-4 * (1.0 + x[j].abs());
                let at = |k: f64, ws: &mut Workspace| {
                    let mut y = x.clone();
                    y[j] += k * h;
                    rhs(d, ws, &y)
                };
                let (f2, f1, m1, m2) = (
                    at(2.0, &mut ws),
                    at(1.0, &mut ws),
                    at(-1.0, &mut ws),
                    at(-2.0, &mut ws),
                );
                for i in 0..2 * n {
                    let fd = (-f2[i] + 8.0 * f1[i] - 8.0 * m1[i] + m2[i]) / (12.0 * h);
                    assert_close(
                        jac[(i, j)],
                        fd,
                        1e-6,
                        scale,
                        format_args!("{} J[{i}][{j}] (state {it})", m.name),
                    );
                }
            }
        }
    }
}
