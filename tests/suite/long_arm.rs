//! The long, thin arm that broke TMTDyn runs (models/long_arm.toml:
//! 150 mm + 200 mm, r 12.5 mm, E 120 kPa, rho 1820, under gravity): 20 s to
//! the end with `auto`, finite, the total energy never rising under damping
//! (dE/dt = -2 R <= 0), and settling towards the static equilibrium that
//! `solve_static` finds independently.

use runtime::{SimOptions, Solver, StaticOptions, simulate, solve_static};
use softarm::backend::{BackendChoice, load};

#[test]
fn long_thin_arm_runs_twenty_seconds_with_energy_decreasing() {
    let dir = std::env::temp_dir().join("softarm-test-cache");
    let mut l = load("long_arm", &[], BackendChoice::Auto, Some(dir)).unwrap();
    let n = l.arm.dof();
    let opts = SimOptions {
        t_end: 20.0,
        solver: Solver::Auto,
        output_dt: 0.02,
        ..Default::default()
    };
    let (traj, stats) = simulate(&*l.arm, vec![0.0; 2 * n], &opts).unwrap();
    assert!(stats.switched.is_some(), "the arm is stiff: auto switches");
    assert_eq!(*traj.t.last().unwrap(), 20.0);
    let energy: Vec<f64> = traj
        .t
        .iter()
        .zip(&traj.x)
        .map(|(&t, x)| {
            assert!(
                x.iter().all(|v| v.is_finite()),
                "non-finite state at t = {t}"
            );
            let o = l.arm.outputs(t, &x[..n], &x[n..]);
            o[3] + o[4]
        })
        .collect();
    let drop = energy[0] - energy[energy.len() - 1];
    assert!(drop > 0.1, "the arm falls and dissipates: {drop} J");
    for (k, w) in energy.windows(2).enumerate() {
        assert!(
            w[1] <= w[0] + 1e-6 * drop,
            "energy rose from {} to {} J at t = {}",
            w[0],
            w[1],
            traj.t[k + 1]
        );
    }
    let rest = solve_static(&mut *l.arm, &vec![0.0; n], &StaticOptions::default()).unwrap();
    let last = traj.x.last().unwrap();
    for (a, b) in last[..n].iter().zip(&rest.q) {
        assert!(
            (a - b).abs() < 0.02,
            "settling towards equilibrium: {a} vs {b}"
        );
    }
}
