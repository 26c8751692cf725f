//! Conservation of energy: the chain with springs and dampers zeroed by
//! overrides is conservative, so KE + PE must stay constant to the
//! integrator's tolerance.

use eomgen::model::Override;
use runtime::{SimOptions, Solver, simulate};
use softarm::backend::{BackendChoice, load};

#[test]
fn chain_conserves_energy_with_dopri5() {
    let sets = ["segment.0.joint_stiffness=0", "segment.0.joint_damping=0"];
    let overrides: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
    let l = load("chain", &overrides, BackendChoice::Auto, None).unwrap();
    assert_eq!(
        l.arm.backend(),
        "compiled",
        "numeric overrides keep the compiled EOM"
    );
    let n = l.arm.dof();
    let mut x0 = vec![0.0; 2 * n];
    x0[0] = 1.2; // swing the chain out from the first joint
    x0[3] = -0.5;
    let opts = SimOptions {
        t_end: 10.0,
        solver: Solver::Dopri5,
        rtol: 1e-10,
        atol: 1e-12,
        output_dt: 0.01,
        ..Default::default()
    };
    let (traj, stats) = simulate(&*l.arm, x0, &opts).unwrap();
    assert!((traj.t.last().unwrap() - 10.0).abs() < 1e-9);
    let energy: Vec<f64> = traj
        .x
        .iter()
        .zip(&traj.t)
        .map(|(x, &t)| {
            let o = l.arm.outputs(t, &x[..n], &x[n..]);
            o[3] + o[4]
        })
        .collect();
    let e0 = energy[0];
    // The motion is large: kinetic energy reaches a good share of |E0|.
    let ke_max = traj
        .x
        .iter()
        .map(|x| l.arm.outputs(0.0, &x[..n], &x[n..])[3])
        .fold(0.0, f64::max);
    assert!(
        ke_max > 0.1 * e0.abs(),
        "the test must exercise real motion"
    );
    let drift = energy.iter().map(|e| (e - e0).abs()).fold(0.0, f64::max) / e0.abs();
    assert!(
        drift < 1e-7,
        "relative energy drift {drift:e} over 10 s ({} steps)",
        stats.steps
    );
}

#[test]
fn damping_dissipates_energy() {
    // With the dampers on, energy must fall monotonically (second law).
    let l = load("chain", &[], BackendChoice::Auto, None).unwrap();
    let n = l.arm.dof();
    let mut x0 = vec![0.0; 2 * n];
    x0[0] = 0.8;
    let opts = SimOptions {
        t_end: 3.0,
        rtol: 1e-9,
        atol: 1e-11,
        output_dt: 0.01,
        ..Default::default()
    };
    let (traj, _) = simulate(&*l.arm, x0, &opts).unwrap();
    let e: Vec<f64> = traj
        .x
        .iter()
        .map(|x| {
            let o = l.arm.outputs(0.0, &x[..n], &x[n..]);
            o[3] + o[4]
        })
        .collect();
    for w in e.windows(2) {
        assert!(
            w[1] <= w[0] + 1e-9 * w[0].abs(),
            "energy rose: {} -> {}",
            w[0],
            w[1]
        );
    }
    assert!(
        e.last().unwrap() < &(e[0] - 1e-4),
        "dampers must remove energy"
    );
}
