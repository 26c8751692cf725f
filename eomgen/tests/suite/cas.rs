//! Tests of every rewrite rule and property tests of the CAS against
//! independent references: naive f64 evaluation of the same expression tree,
//! central finite differences, and direct evaluation vs the tape.

use std::collections::HashMap;

use proptest::prelude::*;
use runtime::tape::Inputs;

use eomgen::cas::*;

fn vals(pairs: &[(&str, f64)]) -> HashMap<String, f64> {
    pairs.iter().map(|(k, v)| (k.to_string(), *v)).collect()
}

#[test]
fn constants_fold() {
    let mut c = Cas::new();
    let a = c.constant(2.0);
    let b = c.constant(3.0);
    let s = c.add(a, b);
    assert_eq!(c.as_const(s), Some(5.0));
    let p = c.mul(a, b);
    assert_eq!(c.as_const(p), Some(6.0));
    let e = c.pow(a, b);
    assert_eq!(c.as_const(e), Some(8.0));
    let z = c.constant(-0.0);
    assert_eq!(z, c.zero(), "-0.0 is canonicalised to 0.0");
    let k0 = c.constant(0.0);
    let s = c.sin(k0);
    assert_eq!(c.as_const(s), Some(0.0));
    // sqrt(-1) does not fold to NaN: it stays symbolic.
    let m1 = c.constant(-1.0);
    let r = c.sqrt(m1);
    assert!(c.as_const(r).is_none());
}

#[test]
fn like_terms_collect_and_cancel() {
    let mut c = Cas::new();
    let x = c.var("x");
    let y = c.var("y");
    let x2 = c.scaled(2.0, x);
    let x3 = c.scaled(3.0, x);
    let s = c.add_all(&[x2, y, x3]);
    let x5 = c.scaled(5.0, x);
    let expect = c.add(y, x5);
    assert_eq!(s, expect);
    let d = c.sub(x, x);
    assert!(c.is_zero(d));
    // Order does not matter: canonical form.
    let a = c.add_all(&[x, y, x2]);
    let b = c.add_all(&[x2, x, y]);
    assert_eq!(a, b);
}

#[test]
fn sums_and_products_flatten() {
    let mut c = Cas::new();
    let (x, y, z) = (c.var("x"), c.var("y"), c.var("z"));
    let xy = c.add(x, y);
    let s1 = c.add(xy, z);
    let yz = c.add(y, z);
    let s2 = c.add(x, yz);
    assert_eq!(s1, s2);
    assert_eq!(c.children(s1).len(), 3);
    let xy_ = c.mul(x, y);
    let m1 = c.mul(xy_, z);
    let yz_ = c.mul(y, z);
    let m2 = c.mul(x, yz_);
    assert_eq!(m1, m2);
    assert_eq!(c.children(m1).len(), 3);
}

#[test]
fn powers_merge() {
    let mut c = Cas::new();
    let x = c.var("x");
    let xx = c.mul(x, x);
    let x2p = c.powi(x, 2);
    assert_eq!(xx, x2p);
    let x3 = c.powi(x, 3);
    let xm1 = c.powi(x, -1);
    let (a, b) = (c.mul(x3, xm1), c.powi(x, 2));
    assert_eq!(a, b);
    let (a, b) = (c.mul(x, xm1), c.one());
    assert_eq!(a, b);
    let a = c.var("a");
    let xa = c.pow(x, a);
    let prod = c.mul(xa, x);
    let one = c.one();
    let ap1 = c.add(a, one);
    let expect = c.pow(x, ap1);
    assert_eq!(prod, expect);
}

#[test]
fn power_rules() {
    let mut c = Cas::new();
    let (x, y) = (c.var("x"), c.var("y"));
    assert_eq!(c.powi(x, 1), x);
    let (a, b) = (c.powi(x, 0), c.one());
    assert_eq!(a, b);
    let x2 = c.powi(x, 2);
    let (a, b) = (c.powi(x2, 3), c.powi(x, 6));
    assert_eq!(a, b);
    let xy = c.mul(x, y);
    let xy2 = c.powi(xy, 2);
    let (px, py) = (c.powi(x, 2), c.powi(y, 2));
    let expect = c.mul(px, py);
    assert_eq!(xy2, expect);
    // (x^2)^0.5 is |x|, not x: not merged.
    let h = c.constant(0.5);
    let r = c.pow(x2, h);
    assert_ne!(r, x);
}

#[test]
fn zero_and_one_factors() {
    let mut c = Cas::new();
    let x = c.var("x");
    let z = c.zero();
    let xz = c.mul(x, z);
    assert!(c.is_zero(xz));
    let one = c.one();
    assert_eq!(c.mul(x, one), x);
    assert_eq!(c.add(x, z), x);
}

#[test]
fn parity_pulls_out_signs() {
    let mut c = Cas::new();
    let x = c.var("x");
    let mx = c.neg(x);
    let s = c.sin(mx);
    let sx = c.sin(x);
    assert_eq!(s, c.neg(sx));
    let (a, b) = (c.cos(mx), c.cos(x));
    assert_eq!(a, b);
    let (a, b) = (c.sinc(mx), c.sinc(x));
    assert_eq!(a, b);
    let (a, b) = (c.cosc(mx), c.cosc(x));
    assert_eq!(a, c.neg(b));
    let (a, b) = (c.func(Func::Abs, mx), c.func(Func::Abs, x));
    assert_eq!(a, b);
    let d1 = c.func(Func::Sinc(1), mx);
    let d1p = c.func(Func::Sinc(1), x);
    assert_eq!(d1, c.neg(d1p));
}

#[test]
fn inverse_functions_cancel() {
    let mut c = Cas::new();
    let x = c.var("x");
    let e = c.func(Func::Exp, x);
    assert_eq!(c.func(Func::Ln, e), x);
    let l = c.func(Func::Ln, x);
    assert_eq!(c.func(Func::Exp, l), x);
    let a = c.func(Func::Abs, x);
    assert_eq!(c.func(Func::Abs, a), a);
}

#[test]
fn bind_is_opaque_to_canonicalisation_but_not_to_value() {
    let mut c = Cas::new();
    let (x, y) = (c.var("x"), c.var("y"));
    let bx = c.bind(x);
    assert_eq!(bx, x);
    let s = c.add(x, y);
    let b = c.bind(s);
    let bb = c.bind(b);
    assert_eq!(bb, b);
    // x + y + Bind(x + y) keeps the bound sum whole.
    let t = c.add(s, b);
    assert_eq!(c.children(t).len(), 3);
    let v = c.eval_named(t, &vals(&[("x", 1.0), ("y", 2.0)])).unwrap();
    assert_eq!(v, 6.0);
    // d/dx Bind(x*y) = Bind(y) = y
    let p = c.mul(x, y);
    let bp = c.bind(p);
    let dbp = c.diff(bp, x);
    assert_eq!(dbp, y);
}

#[test]
fn hash_consing_shares_nodes() {
    let mut c = Cas::new();
    let x = c.var("x");
    let a = c.sin(x);
    let n = c.len();
    let b = c.sin(x);
    assert_eq!(a, b);
    assert_eq!(c.len(), n, "no new node for an existing expression");
}

#[test]
fn derivative_rules() {
    let mut c = Cas::new();
    let (x, y) = (c.var("x"), c.var("y"));
    let sx = c.sin(x);
    let (a, b) = (c.diff(sx, x), c.cos(x));
    assert_eq!(a, b);
    let dy = c.diff(sx, y);
    assert!(c.is_zero(dy));
    let x3 = c.powi(x, 3);
    let x2 = c.powi(x, 2);
    let expect = c.scaled(3.0, x2);
    assert_eq!(c.diff(x3, x), expect);
    let sc = c.sinc(x);
    let (a, b) = (c.diff(sc, x), c.func(Func::Sinc(1), x));
    assert_eq!(a, b);
    // Derivatives at the removable singularity are finite.
    let d2 = c.diff(a, x);
    let v = c.eval_named(d2, &vals(&[("x", 0.0)])).unwrap();
    assert!((v + 1.0 / 3.0).abs() < 1e-15);
}

#[test]
fn time_derivative_by_chain_rule() {
    let mut c = Cas::new();
    let q = c.symbol("q", SymKind::Q(0));
    let qd = c.symbol("qd", SymKind::Qd(0));
    let qdd = c.symbol("qdd", SymKind::Qdd(0));
    // d/dt (qd sin q) = qd^2 cos q + qdd sin q
    let sq = c.sin(q);
    let e = c.mul(qd, sq);
    let full = c.time_derivative(e, &[(q, qd), (qd, qdd)]);
    let (qd2, cq) = (c.powi(qd, 2), c.cos(q));
    let t1 = c.mul(qd2, cq);
    let t2 = c.mul(qdd, sq);
    assert_eq!(full, c.add(t1, t2));
    let conv = c.time_derivative(e, &[(q, qd)]);
    assert_eq!(conv, t1);
}

#[test]
fn turned_vectors_move_by_w_cross_u() {
    // Two frames: Rz(q0), then Rx(q1) on top, each with its angular
    // velocity; a local vector that also moves. The rule's velocity and
    // convective acceleration must equal the chain rule through R.
    let mut c = Cas::new();
    let (q0, q1) = (c.symbol("q0", SymKind::Q(0)), c.symbol("q1", SymKind::Q(1)));
    let (u0, u1) = (
        c.symbol("u0", SymKind::Qd(0)),
        c.symbol("u1", SymKind::Qd(1)),
    );
    let (zero, one) = (c.zero(), c.one());
    let rot = |c: &mut Cas, q: ExprId, axis: usize| {
        let (co, si) = (c.cos(q), c.sin(q));
        let ns = c.neg(si);
        let mut r = [[zero; 3]; 3];
        let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
        r[axis][axis] = one;
        (r[a][a], r[b][b], r[a][b], r[b][a]) = (co, co, ns, si);
        r
    };
    let r1 = rot(&mut c, q0, 2);
    let w1 = [zero, zero, u0];
    let e = rot(&mut c, q1, 0);
    let r2: [[ExprId; 3]; 3] = std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            let col = [e[0][j], e[1][j], e[2][j]];
            let x = c.dot(&r1[i], &col);
            c.bind(x)
        })
    });
    let rel = c.turn(&r1, &w1, &[u1, zero, zero]);
    let w2: [ExprId; 3] = std::array::from_fn(|k| c.add(w1[k], rel[k]));
    let q1sq = c.powi(q1, 2);
    let half = c.constant(0.5);
    let local = [one, q1, q1sq];
    let a = c.turn(&r1, &w1, &[half, zero, q1]);
    let b = c.turn(&r2, &w2, &local);
    let p: Vec<ExprId> = (0..3).map(|k| c.add(a[k], b[k])).collect();
    let pairs = [(q0, u0), (q1, u1)];
    let v_rule = c.kinematic_rates(&p, &pairs);
    let a_rule = c.kinematic_rates(&v_rule, &pairs);
    let v_chain = c.time_derivatives(&p, &pairs);
    let a_chain = c.time_derivatives(&v_chain, &pairs);
    let at = vals(&[("q0", 0.7), ("q1", -1.3), ("u0", 0.4), ("u1", 2.1)]);
    for (x, y) in v_rule
        .iter()
        .chain(&a_rule)
        .zip(v_chain.iter().chain(&a_chain))
    {
        let (x, y) = (
            c.eval_named(*x, &at).unwrap(),
            c.eval_named(*y, &at).unwrap(),
        );
        assert!((x - y).abs() < 1e-13 * (1.0 + y.abs()), "{x} vs {y}");
    }
    // The rule is what was used: the chain rule's velocity differs in form.
    assert_ne!(v_rule, v_chain);
}

// ---- property tests --------------------------------------------------------

/// An expression tree, evaluated naively as the independent reference.
#[derive(Clone, Debug)]
enum Tree {
    X,
    Y,
    Z,
    K(f64),
    Add(Box<Tree>, Box<Tree>),
    Sub(Box<Tree>, Box<Tree>),
    Mul(Box<Tree>, Box<Tree>),
    /// a / (1 + b^2): never divides by zero.
    DivSafe(Box<Tree>, Box<Tree>),
    Powi(Box<Tree>, i32),
    Sin(Box<Tree>),
    Cos(Box<Tree>),
    /// exp(sin a): bounded.
    ExpSin(Box<Tree>),
    /// ln(1 + a^2)
    LnSafe(Box<Tree>),
    /// sqrt(1 + a^2)
    SqrtSafe(Box<Tree>),
    Sinc(Box<Tree>),
    Cosc(Box<Tree>),
}

fn tree() -> impl Strategy<Value = Tree> {
    let leaf = prop_oneof![
        Just(Tree::X),
        Just(Tree::Y),
        Just(Tree::Z),
        (-3.0..3.0f64).prop_map(Tree::K),
    ];
    leaf.prop_recursive(5, 40, 2, |inner| {
        let b = |t| Box::new(t);
        prop_oneof![
            (inner.clone(), inner.clone()).prop_map(move |(x, y)| Tree::Add(b(x), b(y))),
            (inner.clone(), inner.clone()).prop_map(move |(x, y)| Tree::Sub(b(x), b(y))),
            (inner.clone(), inner.clone()).prop_map(move |(x, y)| Tree::Mul(b(x), b(y))),
            (inner.clone(), inner.clone()).prop_map(move |(x, y)| Tree::DivSafe(b(x), b(y))),
            (inner.clone(), -3..4i32).prop_map(move |(x, n)| Tree::Powi(b(x), n)),
            inner.clone().prop_map(move |x| Tree::Sin(b(x))),
            inner.clone().prop_map(move |x| Tree::Cos(b(x))),
            inner.clone().prop_map(move |x| Tree::ExpSin(b(x))),
            inner.clone().prop_map(move |x| Tree::LnSafe(b(x))),
            inner.clone().prop_map(move |x| Tree::SqrtSafe(b(x))),
            inner.clone().prop_map(move |x| Tree::Sinc(b(x))),
            inner.clone().prop_map(move |x| Tree::Cosc(b(x))),
        ]
    })
}

fn naive(t: &Tree, x: f64, y: f64, z: f64) -> f64 {
    let r = |t: &Tree| naive(t, x, y, z);
    match t {
        Tree::X => x,
        Tree::Y => y,
        Tree::Z => z,
        Tree::K(k) => *k,
        Tree::Add(a, b) => r(a) + r(b),
        Tree::Sub(a, b) => r(a) - r(b),
        Tree::Mul(a, b) => r(a) * r(b),
        Tree::DivSafe(a, b) => r(a) / (1.0 + r(b) * r(b)),
        Tree::Powi(a, n) => r(a).powi(*n),
        Tree::Sin(a) => r(a).sin(),
        Tree::Cos(a) => r(a).cos(),
        Tree::ExpSin(a) => r(a).sin().exp(),
        Tree::LnSafe(a) => (1.0 + r(a) * r(a)).ln(),
        Tree::SqrtSafe(a) => (1.0 + r(a) * r(a)).sqrt(),
        // The textbook formulas, not the runtime's branches.
        Tree::Sinc(a) => {
            let v = r(a);
            if v == 0.0 { 1.0 } else { v.sin() / v }
        }
        // (1 - cos v) / v as 2 sin^2(v / 2) / v: the same function without
        // the cancellation that made small v a bad reference.
        Tree::Cosc(a) => {
            let v = r(a);
            if v == 0.0 {
                0.0
            } else {
                2.0 * (0.5 * v).sin().powi(2) / v
            }
        }
    }
}

struct Syms {
    x: ExprId,
    y: ExprId,
    z: ExprId,
}

fn build(c: &mut Cas, s: &Syms, t: &Tree) -> ExprId {
    let r = |c: &mut Cas, t: &Tree| build(c, s, t);
    match t {
        Tree::X => s.x,
        Tree::Y => s.y,
        Tree::Z => s.z,
        Tree::K(k) => c.constant(*k),
        Tree::Add(a, b) => {
            let (a, b) = (r(c, a), r(c, b));
            c.add(a, b)
        }
        Tree::Sub(a, b) => {
            let (a, b) = (r(c, a), r(c, b));
            c.sub(a, b)
        }
        Tree::Mul(a, b) => {
            let (a, b) = (r(c, a), r(c, b));
            c.mul(a, b)
        }
        Tree::DivSafe(a, b) => {
            let (a, b) = (r(c, a), r(c, b));
            let one = c.one();
            let b2 = c.powi(b, 2);
            let d = c.add(one, b2);
            c.div(a, d)
        }
        Tree::Powi(a, n) => {
            let a = r(c, a);
            c.powi(a, *n)
        }
        Tree::Sin(a) => {
            let a = r(c, a);
            c.sin(a)
        }
        Tree::Cos(a) => {
            let a = r(c, a);
            c.cos(a)
        }
        Tree::ExpSin(a) => {
            let a = r(c, a);
            let s = c.sin(a);
            c.func(Func::Exp, s)
        }
        Tree::LnSafe(a) | Tree::SqrtSafe(a) => {
            let a = r(c, a);
            let one = c.one();
            let a2 = c.powi(a, 2);
            let u = c.add(one, a2);
            if matches!(t, Tree::LnSafe(_)) {
                c.func(Func::Ln, u)
            } else {
                c.sqrt(u)
            }
        }
        Tree::Sinc(a) => {
            let a = r(c, a);
            c.sinc(a)
        }
        Tree::Cosc(a) => {
            let a = r(c, a);
            c.cosc(a)
        }
    }
}

fn setup() -> (Cas, Syms) {
    let mut c = Cas::new();
    let s = Syms {
        x: c.symbol("x", SymKind::Q(0)),
        y: c.symbol("y", SymKind::Qd(0)),
        z: c.symbol("z", SymKind::Param(0)),
    };
    (c, s)
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * (1.0 + a.abs().max(b.abs()))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn simplification_preserves_value(t in tree(), x in -2.0..2.0f64, y in -2.0..2.0f64, z in -2.0..2.0f64) {
        let reference = naive(&t, x, y, z);
        prop_assume!(reference.is_finite() && reference.abs() < 1e6);
        // A reference is one only where the function is well conditioned:
        // inputs moved by 1e-12 of themselves must not move it past the
        // tolerance (cos(y^-6) at y = 0.056 has an argument of 3e7, whose
        // last bits, rounded differently by y^-6 and (y^3)^-2, move it by
        // 1e-8).
        let moved = naive(&t, x * (1.0 + 1e-12), y * (1.0 + 1e-12), z * (1.0 + 1e-12));
        prop_assume!(close(moved, reference, 1e-10));
        let (mut c, s) = setup();
        let e = build(&mut c, &s, &t);
        let v = c.eval_named(e, &vals(&[("x", x), ("y", y), ("z", z)])).unwrap();
        prop_assert!(close(v, reference, 1e-9), "cas {v} vs naive {reference} for {t:?}");
    }

    #[test]
    fn derivative_matches_central_differences(t in tree(), x in -2.0..2.0f64, y in -2.0..2.0f64, z in -2.0..2.0f64) {
        let f = |x: f64| naive(&t, x, y, z);
        let central = |h: f64| (f(x + h) - f(x - h)) / (2.0 * h);
        let (f0, fd_coarse, fd) = (f(x), central(2e-5), central(1e-5));
        prop_assume!(f0.is_finite() && f0.abs() < 1e4 && fd.is_finite() && fd_coarse.is_finite());
        // A finite difference is a reference only where it has converged:
        // halving the step must not change it (near kinks, poles and fast
        // oscillation it does, and the case says nothing about the CAS).
        prop_assume!((fd - fd_coarse).abs() <= 1e-6 * (1.0 + fd.abs()));
        // A function numerically flat at the step's scale (a tiny amplitude
        // oscillating faster than the step: cosc(x^-4) near 0) gives both
        // differences as ~0 whatever its derivative.
        prop_assume!(f0.abs() > 1e-9 || fd.abs() > 1e-9);
        let (mut c, s) = setup();
        let e = build(&mut c, &s, &t);
        let d = c.diff(e, s.x);
        let v = c.eval_named(d, &vals(&[("x", x), ("y", y), ("z", z)])).unwrap();
        let tol = 1e-5 * (1.0 + v.abs()) + 1e-10 * (1.0 + f0.abs()) / 1e-5;
        prop_assert!((v - fd).abs() <= tol, "d/dx {v} vs fd {fd} for {t:?}");
    }

    #[test]
    fn tape_equals_direct_evaluation(t in tree(), x in -2.0..2.0f64, y in -2.0..2.0f64, z in -2.0..2.0f64) {
        let (mut c, s) = setup();
        let e = build(&mut c, &s, &t);
        let d = c.diff(e, s.x);
        let direct = c.eval_many(&[e, d], &|sym| match c.sym_name(sym) {
            "x" => Some(x), "y" => Some(y), "z" => Some(z), _ => None,
        }).unwrap();
        // The tape rounds differently (shared subexpressions, fused
        // multiply-adds): differences of the inputs' size, which an
        // ill-conditioned expression (sin of (x/z)^-2) amplifies as it
        // amplifies a nudge of its inputs by 1e-14.
        let nudge = 1.0 + 1e-14;
        let nudged = c.eval_many(&[e, d], &|sym| match c.sym_name(sym) {
            "x" => Some(x * nudge), "y" => Some(y * nudge), "z" => Some(z * nudge), _ => None,
        }).unwrap();
        let tape = c.to_tape(&[e, d]);
        let mut out = [0.0; 2];
        let mut slots = Vec::new();
        tape.eval(&Inputs { t: 0.0, q: &[x], qd: &[y], qdd: &[], dir: &[], p: &[z], aux: &[] }, &mut slots, &mut out);
        for k in 0..2 {
            let (a, b) = (out[k], direct[k]);
            let sensitivity = (nudged[k] - b).abs();
            prop_assert!(a == b || close(a, b, 1e-12) || (a - b).abs() <= 100.0 * sensitivity
                    || (a.is_nan() && b.is_nan()),
                "output {k}: tape {a} vs direct {b} (a 1e-14 nudge moves it {sensitivity:e}) for {t:?}");
        }
    }

    #[test]
    fn hoisted_tape_with_derived_parameters_equals_direct_evaluation(t in tree(), x in -2.0..2.0f64, y in -2.0..2.0f64, z in -2.0..2.0f64) {
        let (mut c, s) = setup();
        let e = build(&mut c, &s, &t);
        let d = c.diff(e, s.x);
        let direct = c.eval_many(&[e, d], &|sym| match c.sym_name(sym) {
            "x" => Some(x), "y" => Some(y), "z" => Some(z), _ => None,
        }).unwrap();
        let mut hoist = Hoist::new(1);
        let tape = c.to_tape_hoisted(&[e, d], &mut hoist);
        let derived = hoist.finish(&mut c);
        // p = [z, derived(z)...]: what Arm::new does.
        let mut p = vec![z; 1 + hoist.len()];
        let mut slots = Vec::new();
        derived.eval(&Inputs { t: 0.0, q: &[], qd: &[], qdd: &[], dir: &[], p: &p.clone(), aux: &[] }, &mut slots, &mut p[1..]);
        let mut out = [0.0; 2];
        tape.eval(&Inputs { t: 0.0, q: &[x], qd: &[y], qdd: &[], dir: &[], p: &p, aux: &[] }, &mut slots, &mut out);
        for k in 0..2 {
            let (a, b) = (out[k], direct[k]);
            prop_assert!(a == b || close(a, b, 1e-9) || (a.is_nan() && b.is_nan()) || !b.is_finite() || b.abs() > 1e12,
                "output {k}: hoisted tape {a} vs direct {b} for {t:?}");
        }
    }
}
