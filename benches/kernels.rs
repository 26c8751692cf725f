//! Criterion benchmarks behind BENCHMARKS.md: derivation time, compiled
//! kernel evaluation and the integrator's right-hand side.
//!
//! Run: `cargo bench --bench kernels` (add a filter, e.g. `-- mass_bias`).

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use eomgen::model::{Model, Override};
use runtime::{KernelKind, Ldlt, Workspace, accelerations};
use softarm::backend::{BackendChoice, load};

fn chain_with(elements: usize) -> Model {
    let length = 0.1 * elements as f64;
    let mass = 0.05 * elements as f64;
    let sets = [
        format!("segment.0.elements={elements}"),
        format!("segment.0.length={length}"),
        format!("segment.0.mass={mass}"),
    ];
    let overrides: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
    softarm::backend::read_model("chain", &overrides).unwrap().0
}

fn derivation(c: &mut Criterion) {
    let mut g = c.benchmark_group("derive");
    g.sample_size(10);
    for n in [10, 32] {
        let model = chain_with(n);
        g.bench_function(format!("chain{n}"), |b| {
            b.iter(|| eomgen::derive::derive(black_box(&model)))
        });
    }
    let sets = [Override::parse("segment.0.elements=20").unwrap()];
    let pcc20 = softarm::backend::read_model("cantilever", &sets).unwrap().0;
    g.bench_function("cantilever_pcc20", |b| {
        b.iter(|| eomgen::derive::derive(black_box(&pcc20)))
    });
    // 3D: every method at 10 elements (rom: its default cubic fields).
    for method in ["pcc", "ebr", "eba", "rigid", "rom"] {
        let sets = [
            Override::parse(&format!("segment.0.method={method}")).unwrap(),
            Override::parse("segment.0.elements=10").unwrap(),
        ];
        let model = softarm::backend::read_model("cantilever3d", &sets)
            .unwrap()
            .0;
        g.bench_function(format!("cantilever3d_{method}10"), |b| {
            b.iter(|| eomgen::derive::derive(black_box(&model)))
        });
    }
    g.finish();
}

fn state(n: usize) -> (Vec<f64>, Vec<f64>) {
    let q = (0..n).map(|i| 0.3 * ((i as f64) * 0.7).sin()).collect();
    let qd = (0..n).map(|i| 0.2 * ((i as f64) * 1.3).cos()).collect();
    (q, qd)
}

fn kernels(c: &mut Criterion) {
    let mut g = c.benchmark_group("compiled");
    for name in [
        "chain",
        "chain32",
        "cantilever",
        "cantilever3d",
        "tentacle3d",
    ] {
        let l = load(name, &[], BackendChoice::Compiled, None).unwrap();
        let arm = &*l.arm;
        let n = arm.dof();
        let (q, qd) = state(n);
        let mut out = vec![0.0; KernelKind::MassBias.output_len(arm.info())];
        g.bench_function(format!("{name}/mass_bias"), |b| {
            b.iter(|| {
                arm.eval_kernel(
                    KernelKind::MassBias,
                    0.0,
                    black_box(&q),
                    black_box(&qd),
                    &mut out,
                )
            })
        });
        let mut ws = Workspace::new(n);
        let mut qdd = vec![0.0; n];
        g.bench_function(format!("{name}/rhs"), |b| {
            b.iter(|| accelerations(arm, &mut ws, 0.0, black_box(&q), black_box(&qd), &mut qdd))
        });
    }
    g.finish();
}

/// The right-hand side of pcc chains linked at another element count
/// (the articulated-body sweep): cantilever3d at 10 and 20 elements.
fn linked(c: &mut Criterion) {
    let mut g = c.benchmark_group("linked");
    for elements in [10, 20] {
        let set = Override::parse(&format!("segment.0.elements={elements}")).unwrap();
        let l = load("cantilever3d", &[set], BackendChoice::Auto, None).unwrap();
        let arm = &*l.arm;
        let n = arm.dof();
        let (q, qd) = state(n);
        let mut ws = Workspace::new(n);
        let mut qdd = vec![0.0; n];
        g.bench_function(format!("cantilever3d_{elements}/rhs"), |b| {
            b.iter(|| accelerations(arm, &mut ws, 0.0, black_box(&q), black_box(&qd), &mut qdd))
        });
    }
    g.finish();
}

/// The L D L^T factorisation of a dense positive definite matrix.
fn ldlt(c: &mut Criterion) {
    let mut g = c.benchmark_group("ldlt");
    for n in [20, 40, 60] {
        let packed: Vec<f64> = (0..n)
            .flat_map(|i| (i..n).map(move |j| (i, j)))
            .map(|(i, j)| match i == j {
                true => 2.0 * n as f64,
                false => ((i * 7 + j * 3) as f64 * 0.37).sin(),
            })
            .collect();
        let mut ws = Ldlt::new(n);
        g.bench_function(format!("factor/{n}"), |b| {
            b.iter(|| assert!(ws.factor(black_box(&packed))))
        });
    }
    g.finish();
}

fn interpreted(c: &mut Criterion) {
    let dir = std::env::temp_dir().join("softarm-bench-cache");
    let l = load("chain", &[], BackendChoice::Interpreted, Some(dir)).unwrap();
    let arm = &*l.arm;
    let (q, qd) = state(arm.dof());
    let mut out = vec![0.0; KernelKind::MassBias.output_len(arm.info())];
    c.bench_function("interpreted/chain/mass_bias", |b| {
        b.iter(|| {
            arm.eval_kernel(
                KernelKind::MassBias,
                0.0,
                black_box(&q),
                black_box(&qd),
                &mut out,
            )
        })
    });
}

// No plots: criterion draws them with plotters, which this workspace builds
// with pure-Rust text (ab_glyph) and a font the CLI registers, not criterion.
criterion_group! {
    name = benches;
    config = Criterion::default().without_plots();
    targets = derivation, kernels, linked, ldlt, interpreted
}
criterion_main!(benches);
