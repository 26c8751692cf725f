//! Compiled `MassBias` timings of several models, interleaved: 200 rounds,
//! each timing a batch of 2000 calls of every model in turn, and for each
//! model the minimum, 10th percentile and median of its batch means.
//!
//! This machine's speed drifts by up to a factor of two from minute to
//! minute; interleaving puts every model in the same phases, so their
//! ratios hold even when the absolute figures move (BENCHMARKS.md).
//!
//! `cargo bench --bench interleaved -- cantilever chain tentacle3d`
//! (`ROUNDS=50` for a quicker look). `rhs:MODEL` times the right-hand
//! side instead (`runtime::accelerations`: mass + bias and the mass solve,
//! or the generated symbolic solve, and for a model with joints the
//! constrained solve); `free:MODEL` the same without its joints (mass +
//! bias and the mass solve alone: what the constraint solve adds is the
//! difference); `joints:MODEL` the constraint kernel alone;
//! `nocontact:MODEL` the right-hand side with the model's contacts taken
//! away (what contact adds is `rhs:MODEL` minus this); `points:MODEL` the
//! `Contact` kernel alone (the points' positions); `straight:MODEL` the
//! right-hand side at q = qd = 0 instead of the default state;
//! `forces:MODEL` the contact forces alone (`generalised_force_at`);
//! `jac:MODEL` the inverse dynamics' Jacobian (`Dynamics::jacobian_parts`,
//! 2n `Jvp` directions: what an implicit step factors);
//! `contactjac:MODEL` the contact forces' Jacobian (the `ContactJvp`
//! kernel's columns with the forces);
//! `Q=q0,q1,...` (env) times every model at that configuration, at rest;
//! `interpreted:` before any of these runs the model on the tape
//! interpreter instead (a model file not compiled in runs on its linked
//! cells when it can, as `softarm simulate` would);
//! `recursion:tentacle3d` the numeric element-by-element
//! recursion of tests/suite/common/pcc3d.rs.

#[path = "../tests/suite/common/pcc3d.rs"]
mod pcc3d;

use std::hint::black_box;
use std::time::Instant;

use runtime::KernelKind;
use softarm::backend::{BackendChoice, load};

const CALLS: usize = 2000;

/// What a name times: its prefix, or mass + bias without one.
#[derive(Clone, Copy, PartialEq)]
enum What {
    MassBias,
    /// `rhs:`, `straight:` and `nocontact:`: `runtime::accelerations`.
    Rhs,
    /// `free:`: mass + bias and the mass solve, no joints.
    Free,
    /// `joints:`: the constraint kernel.
    Joints,
    /// `points:`: the `Contact` kernel.
    Points,
    /// `forces:`: the contact forces alone.
    Forces,
    /// `recursion:`: tests/suite/common/pcc3d.rs's numeric recursion.
    Recursion,
    /// `jac:`: d tau/dq and d tau/dqd.
    Jacobian,
    /// `contactjac:`: the contact forces' Jacobian.
    ContactJacobian,
}

/// A name's prefixes (any number, e.g. `rhs:straight:cantilever`): what
/// it times, at the straight state or not, with the model's contacts or
/// not; and the model.
fn parse(name: &str) -> (What, bool, bool, bool, &str) {
    // `interpreted:` picks the backend, not what is timed.
    let (interpreted, name) = match name.strip_prefix("interpreted:") {
        Some(rest) => (true, rest),
        None => (false, name),
    };
    let prefixes = [
        ("recursion:", What::Recursion),
        ("jac:", What::Jacobian),
        ("contactjac:", What::ContactJacobian),
        ("rhs:", What::Rhs),
        ("free:", What::Free),
        ("joints:", What::Joints),
        ("points:", What::Points),
        ("forces:", What::Forces),
        ("straight:", What::Rhs),
        ("nocontact:", What::Rhs),
    ];
    let (mut asked, mut straight, mut nocontact, mut model) = (Vec::new(), false, false, name);
    while let Some((prefix, what)) = prefixes.iter().find(|(p, _)| model.starts_with(p)) {
        model = &model[prefix.len()..];
        straight |= *prefix == "straight:";
        nocontact |= *prefix == "nocontact:";
        asked.push(*what);
    }
    // When several are asked, the first of this order is timed.
    let order = [
        What::Jacobian,
        What::ContactJacobian,
        What::Forces,
        What::Rhs,
        What::Joints,
        What::Points,
        What::Free,
        What::Recursion,
    ];
    let what = (order.into_iter())
        .find(|w| asked.contains(w))
        .unwrap_or(What::MassBias);
    (what, straight, nocontact, interpreted, model)
}

/// The state a model is timed at: angles of a few tenths of a radian and
/// stretches (metres) of a few tenths of a millimetre; `Q` (env) at rest;
/// zero at the straight state.
fn state(coordinates: &[String], straight: bool) -> (Vec<f64>, Vec<f64>) {
    let dof = coordinates.len();
    if straight {
        return (vec![0.0; dof], vec![0.0; dof]);
    }
    if let Ok(s) = std::env::var("Q") {
        let g: Vec<f64> = (s.split(','))
            .map(|v| v.trim().parse().expect("Q: numbers"))
            .collect();
        assert_eq!(g.len(), dof, "Q: {dof} coordinates");
        return (g, vec![0.0; dof]);
    }
    let q = (0..dof)
        .map(|i| {
            let scale = if coordinates[i].contains("stretch") {
                1e-3
            } else {
                1.0
            };
            scale * 0.3 * ((i as f64) * 0.7).sin()
        })
        .collect();
    let qd = (0..dof).map(|i| 0.2 * ((i as f64) * 1.3).cos()).collect();
    (q, qd)
}

/// The callable a name times, on the criterion benches' state
/// (benches/kernels.rs).
fn timed(name: &str) -> Box<dyn FnMut()> {
    let (what, straight, nocontact, interpreted, model) = parse(name);
    let choice = match interpreted {
        true => BackendChoice::Interpreted,
        false => BackendChoice::Compiled,
    };
    let cache = Some(std::env::temp_dir().join("softarm-bench-tapes"));
    let mut l = load(model, &[], choice, cache).unwrap_or_else(|e| panic!("{model}: {e:#}"));
    if nocontact {
        l.arm.set_contact(None);
    }
    let dof = l.arm.dof();
    let (q, qd) = state(&l.arm.info().coordinates, straight);
    let mut out = vec![0.0; KernelKind::MassBias.output_len(l.arm.info())];
    match what {
        What::Forces => {
            let mut qc = vec![0.0; dof];
            Box::new(move || {
                runtime::contact::generalised_force_at(
                    &*l.arm,
                    0.0,
                    black_box(&q),
                    black_box(&qd),
                    None,
                    &mut qc,
                );
                black_box(&qc);
            })
        }
        What::Jacobian => {
            let qdd = vec![0.1; dof];
            let mut parts = vec![0.0; 2 * dof * dof];
            Box::new(move || {
                l.arm
                    .jacobian_parts(0.0, black_box(&q), black_box(&qd), &qdd, &mut parts);
                black_box(&parts);
            })
        }
        What::ContactJacobian => {
            let mut jac = vec![0.0; 2 * dof * dof];
            Box::new(move || {
                runtime::contact::subtract_from_jacobian(
                    &*l.arm,
                    0.0,
                    black_box(&q),
                    black_box(&qd),
                    &mut jac,
                );
                black_box(&jac);
            })
        }
        What::Rhs => {
            let mut ws = runtime::Workspace::new(dof);
            let mut qdd = vec![0.0; dof];
            Box::new(move || {
                runtime::accelerations(
                    &*l.arm,
                    &mut ws,
                    0.0,
                    black_box(&q),
                    black_box(&qd),
                    &mut qdd,
                )
                .expect("accelerations");
                black_box(&qdd);
            })
        }
        What::Joints | What::Points => {
            let kind = if what == What::Joints {
                KernelKind::Constraints
            } else {
                KernelKind::Contact
            };
            let mut c = vec![0.0; kind.output_len(l.arm.info())];
            Box::new(move || {
                l.arm
                    .eval_kernel(kind, 0.0, black_box(&q), black_box(&qd), &mut c)
            })
        }
        What::Free => {
            let mut ldlt = runtime::Ldlt::new(dof);
            let mut qdd = vec![0.0; dof];
            Box::new(move || {
                l.arm.eval_kernel(
                    KernelKind::MassBias,
                    0.0,
                    black_box(&q),
                    black_box(&qd),
                    &mut out,
                );
                let (mass, bias) = out.split_at(dof * (dof + 1) / 2);
                for (a, b) in qdd.iter_mut().zip(bias) {
                    *a = -b;
                }
                assert!(l.arm.solve_mass(mass, &mut qdd, &mut ldlt));
                black_box(&qdd);
            })
        }
        What::Recursion => {
            let mut r = pcc3d::Pcc3d::new(&l.arm.info().parameters, l.arm.base_params());
            Box::new(move || r.mass_bias(black_box(&q), black_box(&qd), &mut out))
        }
        What::MassBias => Box::new(move || {
            l.arm.eval_kernel(
                KernelKind::MassBias,
                0.0,
                black_box(&q),
                black_box(&qd),
                &mut out,
            )
        }),
    }
}

fn main() {
    // `cargo bench` passes `--bench`; every other argument is a model.
    let names: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let names = if names.is_empty() {
        vec!["cantilever".to_string(), "chain".to_string()]
    } else {
        names
    };
    let rounds: usize = std::env::var("ROUNDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(200)
        .max(1);
    let mut timed: Vec<Box<dyn FnMut()>> = names.iter().map(|n| timed(n)).collect();
    let mut means: Vec<Vec<f64>> = vec![Vec::with_capacity(rounds); timed.len()];
    for _ in 0..rounds {
        for (f, batch) in timed.iter_mut().zip(&mut means) {
            let start = Instant::now();
            for _ in 0..CALLS {
                f();
            }
            batch.push(start.elapsed().as_nanos() as f64 / CALLS as f64);
        }
    }
    for (name, mut batch) in names.iter().zip(means) {
        batch.sort_by(f64::total_cmp);
        println!(
            "{name}: min {:.1} ns  p10 {:.1}  median {:.1}",
            batch[0],
            batch[rounds / 10],
            batch[rounds / 2]
        );
    }
}
