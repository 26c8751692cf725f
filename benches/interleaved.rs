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
//! `Q=q0,q1,...` (env) times every model at that configuration, at rest;
//! `recursion:tentacle3d` the numeric element-by-element
//! recursion of tests/common/pcc3d.rs.

#[path = "../tests/common/pcc3d.rs"]
mod pcc3d;

use std::hint::black_box;
use std::time::Instant;

use runtime::KernelKind;
use softarm::backend::{BackendChoice, load};

const CALLS: usize = 2000;

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
    // Each name times a callable on the criterion benches' state
    // (benches/kernels.rs); `recursion:MODEL` times the numeric recursion
    // of tests/common/pcc3d.rs on MODEL's parameters (3D pcc arms without
    // twist): a kernel of one element's code run in a loop.
    let mut timed: Vec<Box<dyn FnMut()>> = names
        .iter()
        .map(|n| {
            let (recursion, model) = match n.strip_prefix("recursion:") {
                Some(m) => (true, m),
                None => (false, n.as_str()),
            };
            let (rhs, model) = match model.strip_prefix("rhs:") {
                Some(m) => (true, m),
                None => (false, model),
            };
            let (free, model) = match model.strip_prefix("free:") {
                Some(m) => (true, m),
                None => (false, model),
            };
            let (joints, model) = match model.strip_prefix("joints:") {
                Some(m) => (true, m),
                None => (false, model),
            };
            let (points, model) = match model.strip_prefix("points:") {
                Some(m) => (true, m),
                None => (false, model),
            };
            let (forces, model) = match model.strip_prefix("forces:") {
                Some(m) => (true, m),
                None => (false, model),
            };
            let (straight, model) = match model.strip_prefix("straight:") {
                Some(m) => (true, m),
                None => (false, model),
            };
            let (nocontact, model) = match model.strip_prefix("nocontact:") {
                Some(m) => (true, m),
                None => (false, model),
            };
            let mut l = load(model, &[], BackendChoice::Compiled, None)
                .unwrap_or_else(|e| panic!("{model}: {e:#}"));
            if nocontact {
                l.arm.set_contact(None);
            }
            let rhs = rhs || nocontact;
            let dof = l.arm.dof();
            // Angles of a few tenths of a radian; stretches (metres) of
            // a few tenths of a millimetre.
            let names = &l.arm.info().coordinates;
            let q: Vec<f64> = (0..dof)
                .map(|i| {
                    let scale = if names[i].contains("stretch") {
                        1e-3
                    } else {
                        1.0
                    };
                    scale * 0.3 * ((i as f64) * 0.7).sin()
                })
                .collect();
            let qd: Vec<f64> = (0..dof).map(|i| 0.2 * ((i as f64) * 1.3).cos()).collect();
            let given: Option<Vec<f64>> = std::env::var("Q").ok().map(|s| {
                s.split(',')
                    .map(|v| v.trim().parse().expect("Q: numbers"))
                    .collect()
            });
            let (q, qd) = match (straight, given) {
                (true, _) => (vec![0.0; dof], vec![0.0; dof]),
                (false, Some(g)) => {
                    assert_eq!(g.len(), dof, "Q: {dof} coordinates");
                    (g, vec![0.0; dof])
                }
                (false, None) => (q, qd),
            };
            let rhs = rhs || straight;
            let mut out = vec![0.0; KernelKind::MassBias.output_len(l.arm.info())];
            if forces {
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
            } else if rhs {
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
            } else if joints || points {
                let kind = if joints {
                    KernelKind::Constraints
                } else {
                    KernelKind::Contact
                };
                let mut c = vec![0.0; kind.output_len(l.arm.info())];
                Box::new(move || {
                    l.arm
                        .eval_kernel(kind, 0.0, black_box(&q), black_box(&qd), &mut c)
                })
            } else if free {
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
            } else if recursion {
                let mut r = pcc3d::Pcc3d::new(&l.arm.info().parameters, l.arm.base_params());
                Box::new(move || r.mass_bias(black_box(&q), black_box(&qd), &mut out))
                    as Box<dyn FnMut()>
            } else {
                Box::new(move || {
                    l.arm.eval_kernel(
                        KernelKind::MassBias,
                        0.0,
                        black_box(&q),
                        black_box(&qd),
                        &mut out,
                    )
                })
            }
        })
        .collect();
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
