//! Compiled and interpreted backends agree to round-off on random states
//! for every bundled model, and the tape cache is hit on a second run.

use crate::common::*;
use runtime::kernels::CONTACT_BOUND;
use runtime::{Arm, Dynamics, Interpreted, KernelKind, ModelInfo, output};
use softarm::backend::{BackendChoice, load};
use softarm::generated::MODELS;

#[test]
fn compiled_and_interpreted_agree_on_every_bundled_model() {
    let mut rng = Rng::new(7);
    assert!(MODELS.len() >= 3);
    for m in MODELS {
        let l = load(m.name, &[], BackendChoice::Compiled, None).unwrap();
        let p: Vec<f64> = eomgen::load::parameters(&l.model)
            .into_iter()
            .map(|(_, v)| v)
            .collect();
        let compiled = Arm::new((m.kernels)(), p.clone());
        let tapes = eomgen::derive::derive(&l.model);
        let interpreted = Arm::new(Interpreted::new(tapes), p);
        // The same layout, but for the derived parameters: a compiled
        // assembly's arms add their own after the ones both share.
        let layout = ModelInfo {
            derived: interpreted.info().derived,
            ..compiled.info().clone()
        };
        assert_eq!(&layout, interpreted.info(), "{}: layouts differ", m.name);
        // The derived parameters (the `Derived` kernel) agree.
        for (k, (a, b)) in compiled
            .params()
            .iter()
            .zip(interpreted.params())
            .enumerate()
        {
            assert_close(*a, *b, 1e-12, 0.0, format_args!("{} parameter {k}", m.name));
        }
        assert_backends_agree(m.name, &compiled, &interpreted, &mut rng, 12);
    }
}

/// The compiled and interpreted arms agree on M, h, the outputs, the
/// generated solve and the Jacobian's parts, at `rounds` random states
/// (straight ones among them).
fn assert_backends_agree(
    what: &str,
    compiled: &dyn Dynamics,
    interpreted: &dyn Dynamics,
    rng: &mut Rng,
    rounds: usize,
) {
    let n = compiled.dof();
    let names = compiled.info().coordinates.clone();
    for it in 0..rounds {
        let mut q = rng.coordinates(&names, -2.0, 2.0);
        // The straight configuration, and some angles exactly 0: the
        // removable singularities of pcc segments.
        match it % 3 {
            0 => q.fill(0.0),
            1 => q.iter_mut().step_by(2).for_each(|x| *x = 0.0),
            _ => {}
        }
        let qd = rng.vec(n, -3.0, 3.0);
        let t = rng.uniform(0.0, 10.0);
        let kinds = [
            KernelKind::MassBias,
            KernelKind::Outputs,
            KernelKind::Accel,
            KernelKind::Constraints,
        ];
        for kind in kinds {
            let len = kind.output_len(compiled.info());
            let (mut a, mut b) = (vec![0.0; len], vec![0.0; len]);
            compiled.eval_kernel(kind, t, &q, &qd, &mut a);
            interpreted.eval_kernel(kind, t, &q, &qd, &mut b);
            // Compiled chains take MassBias (3D) and Outputs from the
            // link recursion (runtime/kernels/src/links/), eba from its parts
            // (runtime/kernels/src/parts.rs), not the interpreter's flat tapes:
            // entries zero in closed form come out as different
            // round-off, so M and h are each held to 1e-12 of their
            // largest entry, and the outputs to 1e-12 of their kind's
            // (position, energy, quaternion). Accel runs the same
            // operations in both backends.
            let m_len = n * (n + 1) / 2;
            let largest =
                |r: std::ops::Range<usize>| b[r].iter().fold(0.0f64, |s, x| s.max(x.abs()));
            let (m_scale, h_scale) = (largest(0..m_len.min(len)), largest(m_len.min(len)..len));
            // The joints' phi, J and gamma: an assembly's through its arms'
            // frames (runtime/kernels/src/joints.rs), each held to 1e-12 of
            // its largest entry.
            let rows = compiled.info().constraints.len();
            let (phi, jac) = (0..rows, rows..rows * (n + 1));
            for k in 0..len {
                assert!(a[k].is_finite(), "{} {kind:?}[{k}] not finite", what);
                let (rel, floor) = match kind {
                    KernelKind::MassBias if k < m_len => (1e-12, m_scale),
                    KernelKind::MassBias => (1e-12, h_scale),
                    KernelKind::Outputs => match k {
                        0..3 => (1e-12, largest(0..3)),
                        3 | 4 => (1e-12, largest(3..5)),
                        _ => (1e-12, 1.0),
                    },
                    KernelKind::Constraints if phi.contains(&k) => (1e-12, largest(phi.clone())),
                    KernelKind::Constraints if jac.contains(&k) => (1e-12, largest(jac.clone())),
                    KernelKind::Constraints => (1e-12, largest(jac.end..len)),
                    _ => (1e-12, 0.0),
                };
                assert_close(
                    a[k],
                    b[k],
                    rel,
                    floor,
                    format_args!("{} {kind:?}[{k}]", what),
                );
            }
        }
        assert_contact_agrees(what, compiled, interpreted, rng, t, &q, &qd);
        // The Jacobian's parts, column by column from the Jvp kernel.
        let qdd = rng.vec(n, -5.0, 5.0);
        let (mut a, mut b) = (vec![0.0; 2 * n * n], vec![0.0; 2 * n * n]);
        compiled.jacobian_parts(t, &q, &qd, &qdd, &mut a);
        interpreted.jacobian_parts(t, &q, &qd, &qdd, &mut b);
        // Compiled chains take the Jvp from the link recursion in dual
        // numbers (runtime/kernels/src/links/tangent.rs), eba from its parts:
        // another order of the same sums, held to 1e-12 of each
        // block's largest entry.
        let floors: Vec<f64> = b
            .chunks(n * n)
            .map(|block| block.iter().fold(1e-300f64, |s, x| s.max(x.abs())))
            .collect();
        for k in 0..2 * n * n {
            assert!(a[k].is_finite(), "{} Jacobian part {k} not finite", what);
            let floor = floors[k / (n * n)];
            assert_close(
                a[k],
                b[k],
                1e-12,
                floor,
                format_args!("{} Jacobian part {k}", what),
            );
        }
    }
}

/// The contact kernels agree: every point's position; every group's
/// positions, velocities and dp/dq, all at once and each group alone (the
/// others' rows left as they were); and dv, d(dp/dq) along a random dq.
fn assert_contact_agrees(
    what: &str,
    compiled: &dyn Dynamics,
    interpreted: &dyn Dynamics,
    rng: &mut Rng,
    t: f64,
    q: &[f64],
    qd: &[f64],
) {
    let info = compiled.info();
    let (n, points) = (q.len(), info.contact_points);
    if points == 0 {
        return;
    }
    let close = |a: &[f64], b: &[f64], label: &str| {
        let scale = b.iter().fold(1e-300f64, |s, x| s.max(x.abs()));
        for (k, (x, y)) in a.iter().zip(b).enumerate() {
            assert!(x.is_finite(), "{what} {label}[{k}] not finite");
            assert_close(*x, *y, 1e-12, scale, format_args!("{what} {label}[{k}]"));
        }
    };
    let eval = |d: &dyn Dynamics, kind: KernelKind, dir: &[f64], out: &mut Vec<f64>| {
        out.resize(kind.output_len(d.info()), 0.0);
        d.eval_direction(kind, t, q, qd, dir, &[], out);
    };
    let (mut a, mut b) = (Vec::new(), Vec::new());
    eval(compiled, KernelKind::Contact, &[], &mut a);
    eval(interpreted, KernelKind::Contact, &[], &mut b);
    close(&a[..3 * points], &b[..3 * points], "contact point");
    // The broad phase's bounds, where the kernels give them without the
    // points: every point of a group lies in the ellipsoid of foci A, B
    // and major axis L (the triangle inequality along its centreline),
    // as the Contact kernel's frames say too.
    let mut bounds = vec![f64::NAN; info.contact_frames];
    if compiled.contact_bounds(t, q, qd, &mut bounds) {
        close(&bounds, &a[3 * points..], "contact bounds");
        for (g, (first, len)) in info.contact_group_ranges().enumerate() {
            let bound = &bounds[CONTACT_BOUND * g..];
            let (from, to, l) = (&bound[..3], &bound[3..6], bound[6]);
            for i in first..first + len {
                let p = &b[3 * i..3 * i + 3];
                let dist = |x: &[f64]| (0..3).map(|c| (p[c] - x[c]).powi(2)).sum::<f64>().sqrt();
                let reach = dist(from) + dist(to);
                assert!(
                    reach <= l * (1.0 + 1e-12),
                    "{what}: point {i} outside its bound: {reach} > {l}"
                );
            }
        }
    }
    eval(compiled, KernelKind::ContactJacobian, &[], &mut a);
    eval(interpreted, KernelKind::ContactJacobian, &[], &mut b);
    close(&a, &b, "contact jacobian");
    // Each group alone against every group's rows (the two backends may
    // group the points differently: a chain's recursion by element, the
    // tapes by the coordinates the points read); the others' rows left as
    // they were.
    let width = 6 + 3 * n;
    for (g, (first, len)) in info.contact_group_ranges().enumerate() {
        let mut mask = vec![0.0; 2 * n];
        mask[g] = 1.0;
        let rows = first * width..(first + len) * width;
        a.fill(f64::NAN);
        compiled.eval_direction(KernelKind::ContactJacobian, t, q, qd, &mask, &[], &mut a);
        close(
            &a[rows.clone()],
            &b[rows.clone()],
            &format!("contact group {g}"),
        );
        let untouched = (a.iter().enumerate()).all(|(k, x)| rows.contains(&k) || x.is_nan());
        assert!(
            untouched,
            "{what}: contact group {g} wrote other groups' rows"
        );
    }
    // Along a random dq, and along one coordinate (a Jacobian's column,
    // where the groups that coordinate does not move are skipped).
    let mut dir = rng.vec(n, -1.0, 1.0);
    dir.resize(2 * n, 0.0);
    let mut column = vec![0.0; 2 * n];
    column[(rng.uniform(0.0, n as f64) as usize).min(n - 1)] = 1.0;
    for (dir, label) in [(dir, "contact jvp"), (column, "contact jvp column")] {
        eval(compiled, KernelKind::ContactJvp, &dir, &mut a);
        eval(interpreted, KernelKind::ContactJvp, &dir, &mut b);
        close(&a, &b, label);
    }
}

#[test]
fn second_interpreted_run_hits_the_disk_cache() {
    let dir = tempfile::tempdir().unwrap();
    // A structure no compiled-in model has: 3 links.
    let text = std::fs::read_to_string(model_path("chain"))
        .unwrap()
        .replace("elements = 8", "elements = 3");
    let model = dir.path().join("three.toml");
    std::fs::write(&model, text).unwrap();
    let m = model.to_str().unwrap();
    let mut seen = Vec::new();
    for run in 0..2 {
        let out = softarm(
            &[
                "simulate",
                m,
                "--t-end",
                "0.2",
                "--backend",
                "interpreted",
                "--out",
                "run",
            ],
            dir.path(),
        );
        assert!(out.status.success(), "run {run}: {}", stderr(&out));
        let summary: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(dir.path().join("run/summary.json")).unwrap(),
        )
        .unwrap();
        assert_eq!(summary["backend"], "interpreted");
        seen.push(summary["cache"].as_str().unwrap().to_string());
    }
    assert_eq!(seen, ["miss", "hit"]);
    assert_eq!(
        std::fs::read_dir(dir.path().join("cache")).unwrap().count(),
        1
    );
}

#[test]
fn structural_override_derives_anew_numeric_keeps_compiled() {
    let dir = tempfile::tempdir().unwrap();
    let numeric = softarm(
        &[
            "simulate",
            "chain",
            "--t-end",
            "0.05",
            "--set",
            "segment.0.length=1.0",
            "--out",
            "a",
        ],
        dir.path(),
    );
    assert!(numeric.status.success(), "{}", stderr(&numeric));
    assert!(stderr(&numeric).contains("compiled backend"));
    let structural = softarm(
        &[
            "simulate",
            "chain",
            "--t-end",
            "0.05",
            "--set",
            "segment.0.elements=5",
            "--out",
            "b",
        ],
        dir.path(),
    );
    assert!(structural.status.success(), "{}", stderr(&structural));
    // Another element count: not the compiled-in model's kernels, but its
    // cells linked to the new layout.
    assert!(stderr(&structural).contains("cells linked to this element count"));
}

#[test]
fn corrupt_cache_entry_is_rederived() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(model_path("chain"))
        .unwrap()
        .replace("elements = 8", "elements = 2");
    std::fs::write(dir.path().join("two.toml"), text).unwrap();
    let args = ["eom", "two.toml", "--json", "--backend", "interpreted"];
    let first = softarm(&args, dir.path());
    assert!(first.status.success());
    for e in std::fs::read_dir(dir.path().join("cache")).unwrap() {
        std::fs::write(e.unwrap().path(), "{ not json").unwrap();
    }
    let second = softarm(&args, dir.path());
    assert!(second.status.success(), "{}", stderr(&second));
    assert_eq!(stdout(&first), stdout(&second));
}

#[test]
fn generated_mass_solve_matches_a_dense_solve() {
    // The Accel kernel (L D L^T run symbolically) against nalgebra's
    // Cholesky on the same M and h, and its pivots against positivity.
    let mut rng = Rng::new(99);
    for m in MODELS {
        let l = load(m.name, &[], BackendChoice::Compiled, None).unwrap();
        let arm = &*l.arm;
        let n = arm.dof();
        if !arm.info().accel {
            continue;
        }
        for _ in 0..10 {
            let q = rng.coordinates(&arm.info().coordinates, -2.0, 2.0);
            let qd = rng.vec(n, -3.0, 3.0);
            let mut out = vec![0.0; KernelKind::Accel.output_len(arm.info())];
            arm.eval_kernel(KernelKind::Accel, 0.0, &q, &qd, &mut out);
            // The kernel's own M and h (`Dynamics::mass_bias` adds contact
            // forces, which the Accel kernel does not see).
            let mut packed = vec![0.0; n * (n + 1) / 2 + n];
            arm.eval_kernel(KernelKind::MassBias, 0.0, &q, &qd, &mut packed);
            let mut mm = nalgebra::DMatrix::zeros(n, n);
            let mut k = 0;
            for i in 0..n {
                for j in i..n {
                    mm[(i, j)] = packed[k];
                    mm[(j, i)] = packed[k];
                    k += 1;
                }
            }
            let h = nalgebra::DVector::from_column_slice(&packed[k..]);
            let reference = mm.clone().cholesky().expect("M is SPD").solve(&(-h));
            let scale = reference.amax();
            for i in 0..n {
                assert_close(
                    out[i],
                    reference[i],
                    1e-9,
                    scale,
                    format_args!("{} qdd[{i}]", m.name),
                );
                assert!(out[n + i] > 0.0, "{}: pivot {i} not positive", m.name);
            }
            // Its factors: L D L^T is M.
            let (d, lower) = (&out[n..2 * n], &out[2 * n..]);
            let l = |i: usize, j: usize| match i.cmp(&j) {
                std::cmp::Ordering::Equal => 1.0,
                std::cmp::Ordering::Less => 0.0,
                std::cmp::Ordering::Greater => lower[i * (i - 1) / 2 + j],
            };
            let m_scale = mm.amax();
            for i in 0..n {
                for j in 0..n {
                    let ldlt: f64 = (0..n).map(|k| l(i, k) * d[k] * l(j, k)).sum();
                    let what = format!("{} (L D L^T)[{i}][{j}]", m.name);
                    assert_close(ldlt, mm[(i, j)], 1e-12, m_scale, &what);
                }
            }
            // The contact frames it carries (or the points, without
            // frames) are the Contact kernel's.
            let points = arm.info().contact_points;
            let mut contact = vec![0.0; KernelKind::Contact.output_len(arm.info())];
            arm.eval_kernel(KernelKind::Contact, 0.0, &q, &qd, &mut contact);
            let reference = match arm.info().contact_frames {
                0 => &contact[..],
                _ => &contact[3 * points..],
            };
            let carried = &out[2 * n + n * (n - 1) / 2..];
            assert_eq!(carried.len(), reference.len(), "{}: carried", m.name);
            for (i, (a, b)) in carried.iter().zip(reference).enumerate() {
                assert_close(
                    *a,
                    *b,
                    1e-14,
                    1.0,
                    format_args!("{} point coordinate {i}", m.name),
                );
            }
        }
    }
}

/// The link recursion's cells and forces evaluated from their tapes.
struct TapeCells<'a> {
    links: &'a runtime::links::LinkKernels,
    inp: runtime::Inputs<'a>,
    slots: &'a mut Vec<f64>,
    force_slots: &'a mut Vec<f64>,
}

impl runtime::links::Cells for TapeCells<'_> {
    fn one(&mut self, c: usize, q: &[f64], qd: &[f64], p: &[f64], out: &mut [f64]) {
        let inp = runtime::Inputs {
            t: 0.0,
            q,
            qd,
            qdd: &[],
            dir: &[],
            p,
            aux: &[],
        };
        self.links.cells[c].eval(&inp, self.slots, out)
    }
    fn forces(&mut self, out: &mut [f64]) {
        let forces = self.links.forces.as_ref().expect("a forces kernel");
        forces.eval(&self.inp, self.force_slots, out)
    }
    fn tangent(
        &mut self,
        c: usize,
        q: &[f64],
        qd: &[f64],
        dx: &[f64],
        dxd: &[f64],
        p: &[f64],
        out: &mut [f64],
    ) {
        let dir: Vec<f64> = dx.iter().chain(dxd).copied().collect();
        let inp = runtime::Inputs {
            t: 0.0,
            q,
            qd,
            qdd: &[],
            dir: &dir,
            p,
            aux: &[],
        };
        self.links.tangents[c].eval(&inp, self.slots, out)
    }
    fn loads(&mut self, out: &mut [f64]) {
        let loads = self.links.loads.as_ref().expect("a loads kernel");
        loads.eval(&self.inp, self.force_slots, out)
    }
    fn pose(&mut self, c: usize, q: &[f64], qd: &[f64], p: &[f64], out: &mut [f64]) {
        let inp = runtime::Inputs {
            t: 0.0,
            q,
            qd,
            qdd: &[],
            dir: &[],
            p,
            aux: &[],
        };
        self.links.poses[c].eval(&inp, self.slots, out)
    }
    fn energy(&mut self) -> f64 {
        let energy = self.links.energy.as_ref().expect("an energy kernel");
        let mut out = [0.0];
        energy.eval(&self.inp, self.force_slots, &mut out);
        out[0]
    }
    fn forces_tangent(&mut self, dir: &[f64], out: &mut [f64]) {
        let tangent = self.links.forces_tangent.as_ref().expect("a forces kernel");
        let inp = runtime::Inputs { dir, ..self.inp };
        tangent.eval(&inp, self.force_slots, out)
    }
}

/// A model of pcc, rom and vc segments, of eba elements.
fn as_eba(text: &str) -> String {
    let segments = text.matches("[[segment]]").count();
    let text = text
        .replace("method = \"pcc\"", "method = \"eba\"")
        .replace("method = \"rom\"\norder = 2", "method = \"eba\"")
        .replace("method = \"vc\"", "method = \"eba\"")
        .replace("extension = true\n", "");
    assert_eq!(text.matches("\"eba\"").count(), segments);
    text
}

/// [`ACTUATED_3D`] of eba elements.
fn actuated_eba() -> String {
    as_eba(ACTUATED_3D)
}

/// A 3D arm whose pcc and rom segments both carry chambers, with a tendon
/// through both.
const ACTUATED_3D: &str = r#"
name = "actuated3d"
dimensions = 3
gravity = [0.0, -3.0, -9.81]
[base]
position = [0.0, 0.0, 0.0]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "pcc"
length = 0.12
elements = 3
density = 1100.0
outer_radius = 0.012
inner_radius = 0.003
youngs_modulus = 2.0e5
extension = true
[segment.chambers]
angles = [0.0, 120.0, 240.0]
radius = 0.002
distance = 0.007
inputs = ["p0", "p1", "p0"]
[[segment]]
method = "rom"
order = 2
length = 0.1
elements = 4
density = 1100.0
outer_radius = 0.01
youngs_modulus = 2.0e5
extension = true
[segment.chambers]
angles = [30.0, 150.0, 270.0]
radius = 0.002
distance = 0.006
inputs = ["p1", "p0", "p0"]
[[tendon]]
input = "pull"
distance = 0.009
angle = 45.0
end = 1
[tip]
mass = 0.01
[inputs.p0]
kind = "constant"
value = 2.0e4
[inputs.p1]
kind = "constant"
value = 1.0e4
[inputs.pull]
kind = "constant"
value = 0.5
"#;

/// Loads along a 3D arm of a pcc (stretching), a rom and a vc segment:
/// point forces inside an element, on an element boundary and at the
/// base, a follower force and moment, a force per unit length in the
/// world frame and one turning with the section, and a driven moment.
const LOADED_3D: &str = r#"
name = "loaded3d"
dimensions = 3
gravity = [0.0, -3.0, -9.81]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "pcc"
length = 0.12
elements = 3
density = 1100.0
outer_radius = 0.012
youngs_modulus = 2.0e5
extension = true
[[segment]]
method = "rom"
order = 2
length = 0.1
elements = 4
density = 1100.0
outer_radius = 0.01
youngs_modulus = 2.0e5
[[segment]]
method = "vc"
length = 0.08
elements = 2
density = 1100.0
outer_radius = 0.008
youngs_modulus = 2.0e5
[[load]]
segment = 0
s = 0.05
force = [0.1, -0.2, 0.3]
[[load]]
segment = 0
s = 0.0
force = [0.2, 0.1, -0.1]
[[load]]
segment = 0
s = 0.08
force = [0.0, 0.3, -0.2]
moment = [0.01, -0.02, 0.03]
frame = "local"
[[load]]
segment = 1
s = 0.037
moment = [0.02, 0.01, -0.01]
[[load]]
segment = 1
force = [0.5, -1.0, 2.0]
[[load]]
segment = 2
force = [-1.0, 0.5, 1.5]
frame = "local"
[[load]]
segment = 2
s = 0.05
moment_inputs = ["m", "m", "m"]
force = [0.1, 0.1, 0.1]
[inputs.m]
kind = "constant"
value = 0.01
"#;

/// Loads along a planar pcc arm: a point force inside an element, a
/// follower force at the tip and a moment, a force per unit length.
const LOADED_2D: &str = r#"
name = "loaded2d"
gravity = [0.0, -9.81, 0.0]
[base]
direction = [1.0, -0.3, 0.0]
[[segment]]
method = "pcc"
length = 0.2
elements = 5
density = 1100.0
outer_radius = 0.01
youngs_modulus = 2.0e5
[[load]]
segment = 0
s = 0.07
force = [0.2, -0.3, 0.0]
moment = [0.0, 0.0, 0.01]
[[load]]
segment = 0
s = 0.2
force = [0.0, 0.4, 0.0]
frame = "local"
[[load]]
segment = 0
force = [0.3, 1.0, 0.0]
"#;

/// A planar arm of two pcc segments joined at a kink (turned and offset),
/// a third after a kink with a turn alone.
const KINKED_2D: &str = r#"
name = "kinked2d"
gravity = [0.0, -9.81, 0.0]
[base]
direction = [1.0, 0.2, 0.0]
[[segment]]
method = "pcc"
length = 0.1
elements = 3
density = 1100.0
outer_radius = 0.01
youngs_modulus = 2.0e5
[[segment]]
method = "pcc"
length = 0.08
elements = 2
density = 1100.0
outer_radius = 0.008
youngs_modulus = 2.0e5
turn = [70.0]
offset = [0.01, 0.02, 0.0]
[[segment]]
method = "pcc"
length = 0.05
elements = 2
density = 1100.0
outer_radius = 0.006
youngs_modulus = 2.0e5
turn = [-30.0]
[tip]
force = [0.1, -0.2, 0.0]
"#;

/// A planar arm of a rigid link and a pcc segment with a tendon through
/// both and chambers on the pcc segment, a tip body with a length and a
/// tip wrench.
const ACTUATED_2D: &str = r#"
name = "actuated2d"
gravity = [0.0, -9.81, 0.0]
[base]
direction = [1.0, -0.3, 0.0]
[[segment]]
method = "rigid"
length = 0.1
elements = 1
density = 1000.0
outer_radius = 0.01
youngs_modulus = 1.0e6
joints = "base"
[[segment]]
method = "pcc"
length = 0.15
elements = 4
density = 1000.0
outer_radius = 0.01
youngs_modulus = 5.0e5
rest_curvature = -2.0
bending_damping = 1e-4
[segment.chambers]
angles = [90.0, 210.0, 330.0]
radius = 0.002
distance = 0.006
inputs = ["p0", "p1", "p1"]
[[tendon]]
input = "pull"
distance = 0.006
angle = 90.0
end = 1
[tip]
mass = 0.01
length = 0.02
radius = 0.005
force = [0.1, 0.02, 0.0]
moment = [0.0, 0.0, 0.001]
[inputs.p0]
kind = "constant"
value = 2.0e4
[inputs.p1]
kind = "constant"
value = 1.0e4
[inputs.pull]
kind = "constant"
value = 0.3
"#;

/// The link recursion (runtime/kernels/src/links/) with its cells interpreted
/// against the flat `MassBias` tape of the TMT sums, for every link shape
/// and tip it covers: twist, stretch, thinning, vc modules, rom slices, a
/// tip point mass, a tip cylinder, loads in the tip frame, a turned base;
/// by both strategies (composite rows for owned links, shared sums).
#[test]
fn link_recursion_matches_the_flat_tape_for_every_link_shape_and_tip() {
    let dir = std::env::temp_dir().join("softarm-test-cache");
    recursion_matches_flat_tapes(link_shapes(&dir), 11);
}

/// Sections that bend unequally about y and z, on every covered 3D
/// method, with shear, stretch, thinning and a rest shape: a test of its
/// own, to keep each under its time.
#[test]
fn link_recursion_matches_the_flat_tape_for_anisotropic_sections() {
    let dir = std::env::temp_dir().join("softarm-test-cache");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("ribbon3d.toml");
    std::fs::write(&path, RIBBON_3D).unwrap();
    let ribbon = path.to_str().unwrap();
    let cases: [&[&'static str]; 5] = [
        &[],
        &[
            "segment.0.shear=true",
            "segment.1.shear=true",
            "segment.1.extension=true",
            "segment.2.shear=true",
        ],
        &[
            "segment.0.method=vc",
            "segment.1.incompressible=true",
            "segment.1.extension=true",
        ],
        &[
            "segment.0.method=ebr",
            "segment.0.rest_curvature=[1.0,-2.0]",
        ],
        &["segment.0.method=pcs", "segment.0.twist=true"],
    ];
    let models = cases.iter().map(|sets| (ribbon.to_string(), sets.to_vec()));
    recursion_matches_flat_tapes(models.collect(), 12);
}

/// Rigid chains in space: joints of one to three axes in any order at
/// the links' bases and middles, a rest shape in the plane and in space,
/// an anisotropic section, gravity, a tip body, chambers and a tendon,
/// loads along the links.
#[test]
fn link_recursion_matches_the_flat_tape_for_rigid_joints_in_space() {
    let dir = std::env::temp_dir().join("softarm-test-cache");
    std::fs::create_dir_all(&dir).unwrap();
    let file = |name: &str, text: &str| {
        let path = dir.join(format!("{name}.toml"));
        std::fs::write(&path, text).unwrap();
        path.to_str().unwrap().to_string()
    };
    let ribbon = file("ribbon3d", RIBBON_3D);
    let actuated = file("actuated3d", ACTUATED_3D);
    let loaded = file("loaded3d", LOADED_3D);
    let cases: [(&str, &[&'static str]); 9] = [
        ("cantilever3d", &["segment.0.method=rigid"]),
        (
            "cantilever3d",
            &[
                "segment.0.method=rigid",
                "segment.0.joints=\"base\"",
                "segment.0.joint_axes=[\"y\",\"x\",\"z\"]",
                "segment.0.rest_curvature=1.5",
                "gravity=[0,-9.81,0]",
                "tip.mass=0.01",
            ],
        ),
        (
            "cantilever3d",
            &[
                "segment.0.method=rigid",
                "segment.0.joint_axes=[\"x\"]",
                "segment.0.rest_curvature=[1.0,-2.0]",
                "gravity=[0,-9.81,-3.0]",
            ],
        ),
        (
            "cantilever3d",
            &[
                "segment.0.method=rigid",
                "segment.0.joint_axes=[\"z\",\"y\"]",
                "tip.length=0.05",
                "tip.mass=0.005",
                "tip.radius=0.005",
            ],
        ),
        (
            &ribbon,
            &["segment.0.method=rigid", "segment.2.method=rigid"],
        ),
        (&actuated, &["segment.0.method=rigid"]),
        (
            &actuated,
            &["segment.0.method=rigid", "segment.0.joints=\"base\""],
        ),
        // Loads along straight links: forces and moments at points, in the
        // world frame and turning with the section, per unit length.
        (&loaded, &["segment.2.method=rigid"]),
        (
            &loaded,
            &["segment.2.method=rigid", "segment.2.joints=\"base\""],
        ),
    ];
    let models = cases.iter().map(|(m, sets)| (m.to_string(), sets.to_vec()));
    recursion_matches_flat_tapes(models.collect(), 16);
}

/// A floor under a hanging planar chain.
const FLOOR: &str = "\n[[obstacle]]\nname = \"floor\"\nshape = \"plane\"\npoint = [0.0, -0.7, 0.0]\nnormal = [0.0, 1.0, 0.0]\n\n[contact]\nstiffness = 1.0e4\n";

/// The loaded arms on bases moved along driven paths and turned by
/// inputs, immersed (buoyed) and dragged by a current, in space and in
/// the plane.
#[test]
fn link_recursion_matches_the_flat_tape_on_moving_bases_and_in_fluids() {
    let dir = std::env::temp_dir().join("softarm-test-cache");
    std::fs::create_dir_all(&dir).unwrap();
    let shaken3d = shaken(LOADED_3D, r#"["sx", "sy", "sz"]"#);
    let models = [
        ("shaken3d", shaken3d.clone()),
        ("shaken2d", shaken(LOADED_2D, r#"["sx", "sy"]"#)),
        ("immersed3d", format!("{ACTUATED_3D}{IMMERSED}")),
        ("immersed2d", format!("{LOADED_2D}{IMMERSED}")),
        ("dragged3d", format!("{ACTUATED_3D}{DRAGGED}")),
        ("dragged2d", format!("{LOADED_2D}{DRAGGED}")),
        // Two turns about axes of any length on a shaken base; one in
        // the plane.
        ("turned3d", turned(&shaken3d, 3)),
        ("turned2d", turned(LOADED_2D, 2)),
    ];
    let models = (models.into_iter())
        .map(|(name, text)| {
            let path = dir.join(format!("{name}.toml"));
            std::fs::write(&path, text).unwrap();
            (path.to_str().unwrap().to_string(), Vec::new())
        })
        .collect();
    recursion_matches_flat_tapes(models, 15);
}

/// Arms of more coordinates than the shared sums take at once
/// (`runtime::links::AT_ONCE`), summed a block of columns at a time:
/// pcs's half-arcs and two rom segments of all six strains.
#[test]
fn link_recursion_matches_the_flat_tape_past_one_block() {
    let dir = std::env::temp_dir().join("softarm-test-cache");
    std::fs::create_dir_all(&dir).unwrap();
    let text = std::fs::read_to_string(model_path("rod_swing_rom")).unwrap();
    let (head, rest) = text.split_at(text.find("[[segment]]").unwrap());
    let (segment, tail) = rest.split_at(rest.find("[simulate]").unwrap());
    let segment = segment.replace("length = 0.3", "length = 0.15");
    let path = dir.join("rom_pair.toml");
    std::fs::write(&path, format!("{head}{segment}{segment}{tail}")).unwrap();
    let models = vec![
        ("rod_swing".to_string(), vec!["segment.0.elements=11"]),
        (
            path.to_str().unwrap().to_string(),
            vec!["segment.1.order=4"],
        ),
    ];
    recursion_matches_flat_tapes(models, 14);
}

/// Driven forces on named coordinates (`[[torque]]`) on 3D and planar
/// actuated arms: taken from h, the tangent unchanged.
#[test]
fn link_recursion_matches_the_flat_tape_under_coordinate_forces() {
    let dir = std::env::temp_dir().join("softarm-test-cache");
    std::fs::create_dir_all(&dir).unwrap();
    let mut models = Vec::new();
    for (name, text) in [
        ("torqued3d", format!("{ACTUATED_3D}{TORQUES_3D}")),
        ("torqued2d", format!("{ACTUATED_2D}{TORQUES_2D}")),
    ] {
        let path = dir.join(format!("{name}.toml"));
        std::fs::write(&path, text).unwrap();
        models.push((path.to_str().unwrap().to_string(), Vec::new()));
    }
    recursion_matches_flat_tapes(models, 13);
}

/// Each model (with its `--set`s) by its link recursion against its flat
/// tapes at random states ([`recursion_matches_at`]).
fn recursion_matches_flat_tapes(models: Vec<(String, Vec<&'static str>)>, seed: u64) {
    let mut rng = Rng::new(seed);
    for (model, sets) in models {
        let overrides: Vec<eomgen::model::Override> = sets
            .iter()
            .map(|s| eomgen::model::Override::parse(s).unwrap())
            .collect();
        // The model alone: its tapes are derived here, once.
        let (m, _) = softarm::backend::read_model(&model, &overrides).unwrap();
        let tapes = eomgen::derive::derive(&m);
        let links = tapes
            .links
            .clone()
            .unwrap_or_else(|| panic!("the recursion covers {model} {sets:?}"));
        let chain = Chain {
            links,
            flat: tapes.mass_bias.clone(),
            jvp: tapes.jvp.clone(),
            outputs: tapes.outputs.clone(),
        };
        let mut p: Vec<f64> = eomgen::load::parameters(&m)
            .into_iter()
            .map(|(_, v)| v)
            .collect();
        // Inputs at values of their kind's scale (a constant input's value
        // is not in the model's numbers).
        let layout = eomgen::model::ParamLayout::of(&eomgen::model::Structure::of(&m));
        for d in layout.driven() {
            use eomgen::model::{ChamberParam, Param};
            let scale = match d.param {
                Param::Chamber {
                    what: ChamberParam::Pressure,
                    ..
                } => 3e4,
                Param::TendonTension(_) => 2.0,
                _ => 0.2,
            };
            p[layout.index(d.param)] = rng.uniform(-scale, scale);
        }
        let arm = Arm::new(Interpreted::new(tapes), p);
        let p = arm.params().to_vec();
        let n = arm.dof();
        let names = arm.info().coordinates.clone();
        for trial in 0..6 {
            let mut q = rng.coordinates(&names, -1.5, 1.5);
            if trial == 0 {
                q.fill(0.0);
            }
            let qd = rng.vec(n, -3.0, 3.0);
            let what = format!("{model} {sets:?} trial {trial}");
            recursion_matches_at(&chain, &p, &q, &qd, &mut rng, &what);
        }
    }
}

/// Sections that bend unequally about y and z (a rectangle, an ellipse
/// of tapered stiffness, a section given by unequal properties): their bodies' inertia has principal axes of
/// its own, their bend about y and shear along z springs of their own.
const RIBBON_3D: &str = r#"
name = "ribbon3d"
dimensions = 3
gravity = [0.0, -3.0, -9.81]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "pcc"
length = 0.12
elements = 3
density = 1100.0
section = { shape = "rectangle", width = 0.02, height = 0.006 }
youngs_modulus = 2.0e5
extension = true
[[segment]]
method = "rom"
order = 2
length = 0.1
elements = 4
density = 1100.0
section = { shape = "ellipse", width = 0.016, height = 0.008 }
youngs_modulus = [2.0e5, 1.0e5]
[[segment]]
method = "pcc"
length = 0.08
elements = 2
section = { shape = "properties", axial_stiffness = 20.0, shear_stiffness = [5.0, 12.0], bending_stiffness = [1.0e-4, 2.5e-4], torsional_stiffness = 8.0e-5, mass_per_length = 0.1, rotary_inertia = [4.0e-7, 1.0e-6] }
[tip]
mass = 0.01
"#;

/// Driven forces on a 3D arm's coordinates: a moment on a pcc element's
/// bend, a force on its stretch, one on a rom segment's coefficient.
const TORQUES_3D: &str = r#"
[[torque]]
coordinate = "bend_y_0_1"
input = "tq"
[[torque]]
coordinate = "stretch_0_2"
input = "pull"
[[torque]]
coordinate = "bend_z_1_c1"
input = "tq"
[inputs.tq]
kind = "constant"
value = 0.01
"#;

/// A rigid joint's torque and a moment on a planar pcc element.
const TORQUES_2D: &str = r#"
[[torque]]
coordinate = "theta_0_0"
input = "tq"
[[torque]]
coordinate = "theta_1_2"
input = "pull"
[inputs.tq]
kind = "constant"
value = 0.01
"#;

/// Immersed without drag: each link's body buoyed by its share of its
/// element's displaced fluid.
const IMMERSED: &str = "\n[fluid]\ndensity = 1500.0\n";

/// Dragged across and along by a fluid flowing past: Morison's drag at
/// each element's middle, of its velocity relative to the current.
const DRAGGED: &str = "\n[fluid]\ndensity = 1000.0\ndrag_normal = 1.2\ndrag_tangential = 0.05\ncurrent = [0.1, -0.2, 0.3]\n";

/// `text` on a base moved along the path of the channels `inputs` (sines
/// in x and y, still in z).
fn shaken(text: &str, inputs: &str) -> String {
    let signals = "[inputs.sx]\nkind = \"sine\"\namplitude = 0.02\nfrequency = 3.0\n\
                   [inputs.sy]\nkind = \"sine\"\namplitude = 0.01\nfrequency = 2.0\n\
                   [inputs.sz]\nkind = \"constant\"\nvalue = 0.0\n";
    let text = text.replacen(
        "[base]",
        &format!("[base]\ntranslation_inputs = {inputs}"),
        1,
    );
    format!("{text}{signals}")
}

/// `text` on a base turned by inputs: in space (`dimensions` 3) a yaw
/// and a pitch about axes of any length, in the plane one turn.
fn turned(text: &str, dimensions: u8) -> String {
    let turns = match dimensions {
        3 => {
            "rotation_inputs = [\"yaw\", \"pitch\"]\nrotation_axes = [[0.0, 0.0, 2.0], [0.3, 1.0, 0.0]]"
        }
        _ => "rotation_inputs = [\"yaw\"]",
    };
    let mut signals =
        "[inputs.yaw]\nkind = \"sine\"\namplitude = 0.4\nfrequency = 1.5\n".to_string();
    if dimensions == 3 {
        signals += "[inputs.pitch]\nkind = \"sine\"\namplitude = 0.3\nfrequency = 2.5\n";
    }
    let text = text.replacen("[base]", &format!("[base]\n{turns}"), 1);
    format!("{text}{signals}")
}

/// A chain of every link shape and tip the recursion covers: every
/// bundled chain, actuated arms of every covered method, and cantilever3d
/// under rom slices, stretch, thinning, vc, tip wrenches and tip bodies;
/// with the `--set`s of each.
fn link_shapes(dir: &std::path::Path) -> Vec<(String, Vec<&'static str>)> {
    // Actuators on every covered method: chambers on a pcc and a rom
    // segment, a tendon through both, each link loaded by its segment's
    // loads (the `loads` kernel).
    std::fs::create_dir_all(dir).unwrap();
    let file = |name: &str, text: &str| {
        let path = dir.join(format!("{name}.toml"));
        std::fs::write(&path, text).unwrap();
        path.to_str().unwrap().to_string()
    };
    let actuated = file("actuated3d", ACTUATED_3D);
    let actuated2d = file("actuated2d", ACTUATED_2D);
    let loaded = file("loaded3d", LOADED_3D);
    let loaded2d = file("loaded2d", LOADED_2D);
    let kinked2d = file("kinked2d", KINKED_2D);
    // Chamber levers that vary along a segment (tapered, the chambers
    // nearer the axis towards the tip): each element's own loads.
    let varying = file(
        "varying3d",
        &ACTUATED_3D
            .replace("outer_radius = 0.012", "outer_radius = [0.012, 0.009]")
            .replace("distance = 0.007", "distance = [0.008, 0.005]")
            .replace("distance = 0.006", "distance = [0.006, 0.004]"),
    );
    let varying2d = file(
        "varying2d",
        &ACTUATED_2D.replacen("distance = 0.006", "distance = [0.007, 0.004]", 1),
    );
    let mut models: Vec<(&str, &[&'static str])> = vec![
        // Loads along the arm.
        (&loaded, &[]),
        (&loaded2d, &[]),
        // Kinks in the plane: links of no coordinates.
        (&kinked2d, &[]),
        (&varying, &[]),
        (&varying2d, &[]),
        // Planar chains: rigid links and pcc arcs (whose inertia changes
        // with the bend), a turned base, actuators, tip bodies and loads.
        ("double_pendulum", &[]),
        ("chain", &["base.direction=[0.6,-0.8,0.0]"]),
        // Rigid elements of midpoint joints: two links each, the half
        // before the joint without a coordinate.
        ("chain", &["segment.0.joints=\"midpoint\""]),
        (
            "double_pendulum",
            &["segment.1.joints=\"midpoint\"", "segment.1.elements=3"],
        ),
        ("chain32", &[]),
        // Every bundled 3D model as it is.
        ("cantilever3d", &[]),
        ("tentacle3d", &[]),
        ("vc_arm", &[]),
        ("rom_arm", &[]),
        ("stiff_flop_rom", &[]),
        ("cantilever", &["tip.mass=0.02"]),
        ("hybrid_arm", &[]),
        ("long_arm", &[]),
        ("soft_finger", &[]),
        (&actuated2d, &[]),
        (&actuated2d, &["tip.wrench_frame=\"tip\""]),
        ("stiff_flop", &[]),
        ("stiff_flop", &["segment.0.method=rom", "segment.0.order=2"]),
        // ebr: each element two links, the half before its joint without
        // coordinates.
        ("ebr_arm", &[]),
        ("stiff_flop", &["segment.0.method=ebr"]),
        (
            "cantilever3d",
            &[
                "segment.0.method=ebr",
                "segment.0.extension=true",
                "segment.0.incompressible=true",
                "segment.0.twist=false",
                "tip.length=0.05",
                "tip.mass=0.005",
                "tip.radius=0.005",
                "gravity=[0,-9.81,0]",
            ],
        ),
        (&actuated, &[]),
        (&actuated, &["segment.1.incompressible=true"]),
    ];
    let cases = cantilever3d_cases();
    models.extend(cases.iter().map(|&sets| ("cantilever3d", sets)));
    (models.into_iter())
        .map(|(m, sets)| (m.to_string(), sets.to_vec()))
        .collect()
}

/// cantilever3d's variants in [`link_shapes`]: rom slices, stretch,
/// thinning, vc, tip wrenches and tip bodies.
fn cantilever3d_cases() -> [&'static [&'static str]; 9] {
    [
        // rom slices: coordinates shared along the segment, the segment's
        // energies from the forces kernel.
        &[
            "segment.0.method=rom",
            "segment.0.order=3",
            "segment.0.rest_curvature=2.0",
            "segment.0.bending_damping=0.01",
            "tip.force=[0.1,-0.2,0.05]",
            "gravity=[1,-2,-9.81]",
        ],
        &[
            "segment.0.method=rom",
            "segment.0.order=2",
            "segment.0.quadrature=5",
            "segment.0.extension=true",
            "segment.0.axial_damping=0.02",
            "tip.mass=0.01",
            "tip.moment=[0.01,-0.02,0.005]",
        ],
        &[
            "segment.0.method=rom",
            "segment.0.order=1",
            "segment.0.twist=false",
            "segment.0.extension=true",
            "segment.0.incompressible=true",
            "segment.0.rest_curvature=-1.0",
            "tip.force=[0.0,0.3,0.0]",
        ],
        &["segment.0.twist=false", "tip.force=[0.2,0.1,-0.3]"],
        &[
            "segment.0.extension=true",
            "tip.moment=[0.01,-0.02,0.005]",
            "gravity=[0,0,-9.81]",
        ],
        &[
            "segment.0.extension=true",
            "segment.0.incompressible=true",
            "tip.mass=0.01",
        ],
        &[
            "segment.0.method=vc",
            "tip.mass=0.02",
            "tip.length=0.03",
            "tip.radius=0.01",
            "gravity=[1,-2,-9.81]",
        ],
        &[
            "tip.force=[0.1,0.2,0.3]",
            "tip.moment=[0.01,0.0,0.02]",
            "tip.wrench_frame=\"tip\"",
            "base.direction=[0.6,0.0,0.8]",
        ],
        &[
            "tip.length=0.05",
            "tip.mass=0.005",
            "tip.radius=0.005",
            "tip.force=[0.0,0.3,0.0]",
            "gravity=[0,-9.81,0]",
        ],
    ]
}

/// The flat tapes of a chain and its link recursion.
struct Chain {
    links: runtime::links::LinkKernels,
    flat: runtime::Tape,
    jvp: runtime::Tape,
    outputs: runtime::Tape,
}

/// At (q, qd): mass + bias by the recursion (as generated code picks it,
/// and by the shared sums) and the outputs by the pose cells against the
/// flat tapes; tau = M qdd + h and its tangent (the Jvp) by the cells'
/// tangents at a random qdd and direction, at 1e-12 of each block's scale.
fn recursion_matches_at(
    chain: &Chain,
    p: &[f64],
    q: &[f64],
    qd: &[f64],
    rng: &mut Rng,
    what: &str,
) {
    let Chain {
        links,
        flat,
        jvp,
        outputs,
    } = chain;
    let n = q.len();
    let len = flat.outputs.len();
    let (mut want, mut got) = (vec![0.0; len], vec![0.0; len]);
    let inp = runtime::Inputs {
        t: 0.0,
        q,
        qd,
        qdd: &[],
        dir: &[],
        p,
        aux: &[],
    };
    flat.eval(&inp, &mut Vec::new(), &mut want);
    let mut slots = Vec::new();
    let mut force_slots = Vec::new();
    let m_len = n * (n + 1) / 2;
    let largest = |r: std::ops::Range<usize>| want[r].iter().fold(0.0f64, |s, x| s.max(x.abs()));
    let (m_scale, h_scale) = (largest(0..m_len), largest(m_len..len));
    // The recursion as generated code picks it, and the shared
    // sums on every chain (for owned links a second strategy).
    for shared in [false, true] {
        got.fill(f64::NAN);
        let mut cells = TapeCells {
            links,
            inp,
            slots: &mut slots,
            force_slots: &mut force_slots,
        };
        let layout = &links.layout;
        if shared {
            runtime::links::mass_bias_shared_dyn(layout, &mut cells, q, qd, p, &mut got);
        } else {
            runtime::links::mass_bias(layout, &mut cells, q, qd, p, &mut got);
        }
        for k in 0..len {
            let floor = if k < m_len { m_scale } else { h_scale };
            assert_close(
                got[k],
                want[k],
                1e-12,
                floor,
                format_args!("{what} shared {shared} entry {k}"),
            );
        }
    }
    // The outputs by the pose cells against the flat tape's.
    let mut want_out = vec![0.0; runtime::N_OUTPUTS];
    outputs.eval(&inp, &mut Vec::new(), &mut want_out);
    let mut got_out = vec![f64::NAN; runtime::N_OUTPUTS];
    let mut cells = TapeCells {
        links,
        inp,
        slots: &mut slots,
        force_slots: &mut force_slots,
    };
    runtime::links::outputs(&links.layout, &mut cells, q, qd, p, &mut got_out);
    let energy_scale = want_out[output::KINETIC]
        .abs()
        .max(want_out[output::POTENTIAL].abs());
    let position_scale = want_out[output::TIP]
        .iter()
        .fold(0.0f64, |s, x| s.max(x.abs()));
    for (k, name) in runtime::OUTPUT_NAMES.iter().enumerate() {
        let floor = match k {
            0..3 => position_scale,
            3 | 4 => energy_scale,
            _ => 1.0,
        };
        let what = format!("{what} output {name}");
        assert_close(got_out[k], want_out[k], 1e-12, floor, &what);
    }
    // The Jvp by dual numbers through the cells' tangents against
    // the flat tape's symbolic derivative, and tau = M qdd + h
    // against the flat mass + bias.
    let qdd = rng.vec(n, -5.0, 5.0);
    let dir = rng.vec(2 * n, -1.0, 1.0);
    let inp = runtime::Inputs {
        qdd: &qdd,
        dir: &dir,
        ..inp
    };
    let mut want_jvp = vec![0.0; n];
    jvp.eval(&inp, &mut Vec::new(), &mut want_jvp);
    let (mut tau, mut dtau) = (vec![f64::NAN; n], vec![f64::NAN; n]);
    let mut cells = TapeCells {
        links,
        inp,
        slots: &mut slots,
        force_slots: &mut force_slots,
    };
    runtime::links::inverse_dynamics_tangent(
        &links.layout,
        &mut cells,
        q,
        qd,
        &qdd,
        &dir,
        p,
        &mut tau,
        &mut dtau,
    );
    let mut want_tau = want[m_len..].to_vec();
    for (i, tau) in want_tau.iter_mut().enumerate() {
        for (j, a) in qdd.iter().enumerate() {
            let (r, c) = (i.min(j), i.max(j));
            *tau += want[r * n - r * (r + 1) / 2 + c] * a;
        }
    }
    let scale = |v: &[f64]| v.iter().fold(0.0f64, |s, x| s.max(x.abs()));
    let (tau_scale, jvp_scale) = (scale(&want_tau), scale(&want_jvp));
    for i in 0..n {
        let what = format!("{what} coordinate {i}");
        assert_close(
            tau[i],
            want_tau[i],
            1e-12,
            tau_scale,
            format_args!("tau {what}"),
        );
        assert_close(
            dtau[i],
            want_jvp[i],
            1e-12,
            jvp_scale,
            format_args!("jvp {what}"),
        );
    }
}

/// An eba arm as a sum of parts (runtime/kernels/src/parts.rs: bodies, beam
/// springs, the tip) against the flat `MassBias`, `Jvp` and `Outputs`
/// tapes of the whole system at 1e-12 of their scale, with tip bodies and
/// loads, extension and thinning.
/// The eba arms whose parts are compared with their flat tapes, their
/// files written into `dir`: (model, overrides).
fn eba_part_cases(dir: &std::path::Path) -> Vec<(String, &'static [&'static str])> {
    let cases: [&'static [&'static str]; 4] = [
        &["segment.0.method=eba", "gravity=[1,-2,-9.81]"],
        &[
            "segment.0.method=eba",
            "segment.0.elements=3",
            "tip.force=[0.1,-0.2,0.05]",
            "tip.moment=[0.01,0.02,-0.03]",
            "gravity=[0,0,-9.81]",
        ],
        &[
            "segment.0.method=eba",
            "segment.0.incompressible=true",
            "tip.mass=0.02",
            "tip.length=0.03",
            "tip.radius=0.01",
            "tip.force=[0.1,0.2,0.3]",
            "tip.wrench_frame=\"tip\"",
            "base.direction=[0.6,0.0,0.8]",
        ],
        &["segment.0.method=eba", "segment.0.bending_damping=0.01"],
    ];
    // Chambers and a tendon across two segments, the first's chamber
    // levers tapering (a triple of loads per element), the second's not.
    let actuated = dir.join("actuated_eba.toml");
    std::fs::write(&actuated, actuated_eba()).unwrap();
    let actuated = actuated.to_string_lossy().into_owned();
    // Driven torques on an element's turn and its displacement.
    let torqued = dir.join("torqued_eba.toml");
    let text = actuated_eba()
        + "[[torque]]\ncoordinate = \"ry_0_1\"\ninput = \"tq\"\n\
           [[torque]]\ncoordinate = \"uz_1_2\"\ninput = \"tq\"\n\
           [inputs.tq]\nkind = \"constant\"\nvalue = 0.02\n";
    std::fs::write(&torqued, text).unwrap();
    let torqued = torqued.to_string_lossy().into_owned();
    // Loads along the arm: point forces inside an element, at the base
    // and on an element boundary, a follower force and moment, forces per
    // unit length in the world frame and turning with the section, a
    // driven moment.
    let loaded = dir.join("loaded_eba.toml");
    std::fs::write(&loaded, as_eba(LOADED_3D)).unwrap();
    let loaded = loaded.to_string_lossy().into_owned();
    // Immersed: buoyancy, Morison drag and a current on the underwater
    // arm (a chamber driven), and buoyancy alone with the loads along.
    let underwater = dir.join("underwater_eba.toml");
    let text = std::fs::read_to_string(root().join("examples/underwater_arm.toml")).unwrap();
    std::fs::write(&underwater, as_eba(&text)).unwrap();
    let underwater = underwater.to_string_lossy().into_owned();
    let afloat = dir.join("afloat_eba.toml");
    let text = as_eba(LOADED_3D).replace("[inputs.m]", "[fluid]\ndensity = 1000.0\n\n[inputs.m]");
    assert!(text.contains("[fluid]"));
    std::fs::write(&afloat, text).unwrap();
    let afloat = afloat.to_string_lossy().into_owned();
    let mut models: Vec<(String, &[&str])> = vec![
        (loaded, &[]),
        (underwater, &[]),
        (afloat, &[]),
        ("ebr_arm".into(), &["segment.0.method=eba"]),
        (
            actuated.clone(),
            &["segment.0.chambers.distance=[0.008, 0.006]"],
        ),
        (actuated, &["segment.0.incompressible=true"]),
        (torqued, &[]),
    ];
    models.extend(cases.iter().map(|&s| ("cantilever3d".into(), s)));
    models
}

#[test]
fn eba_parts_match_the_flat_tapes() {
    let mut rng = Rng::new(29);
    let dir = tempfile::tempdir().unwrap();
    for (model, sets) in eba_part_cases(dir.path()) {
        let model = model.as_str();
        let overrides: Vec<eomgen::model::Override> = sets
            .iter()
            .map(|s| eomgen::model::Override::parse(s).unwrap())
            .collect();
        // The model alone: its tapes are derived here, once.
        let (m, _) = softarm::backend::read_model(model, &overrides).unwrap();
        let tapes = eomgen::derive::derive(&m);
        let parts = tapes
            .parts
            .clone()
            .unwrap_or_else(|| panic!("parts cover {model} {sets:?}"));
        let (flat, jvp) = (tapes.mass_bias.clone(), tapes.jvp.clone());
        let flat_outputs = tapes.outputs.clone();
        let p: Vec<f64> = eomgen::load::parameters(&m)
            .into_iter()
            .map(|(_, v)| v)
            .collect();
        let arm = Arm::new(Interpreted::new(tapes), p);
        let n = arm.dof();
        // The parameters the kernels read at a time, chamber pressures and
        // tendon tensions driven by their inputs (zero at rest).
        let cache = tempfile::tempdir().unwrap();
        let choice = BackendChoice::Interpreted;
        let driven = load(model, &overrides, choice, Some(cache.path().to_path_buf())).unwrap();
        let p = driven.arm.params_at(0.5);
        assert_eq!(p.len(), arm.params().len());
        let mut tp = runtime::parts::TapeParts {
            kernels: &parts,
            slots: Vec::new(),
        };
        // An incompressible element compressed past its length has no
        // section: its displacements stay a fraction of an element's.
        let incompressible = sets.iter().any(|s| s.contains("incompressible"));
        for trial in 0..4 {
            let mut q = rng.vec(n, -0.3, 0.3);
            if incompressible {
                (q.chunks_mut(6)).for_each(|c| c[..3].iter_mut().for_each(|u| *u *= 0.05));
            }
            if trial == 0 {
                q.fill(0.0);
            }
            let qd = rng.vec(n, -2.0, 2.0);
            let qdd = rng.vec(n, -5.0, 5.0);
            let dir = rng.vec(2 * n, -1.0, 1.0);
            let inp = runtime::Inputs {
                t: 0.0,
                q: &q,
                qd: &qd,
                qdd: &qdd,
                dir: &dir,
                p: &p,
                aux: &[],
            };
            let len = flat.outputs.len();
            let (mut want, mut got) = (vec![0.0; len], vec![f64::NAN; len]);
            flat.eval(&inp, &mut Vec::new(), &mut want);
            runtime::parts::mass_bias(&parts.layout, &mut tp, &q, &qd, &p, &mut got);
            let m_len = n * (n + 1) / 2;
            let scale = |v: &[f64]| v.iter().fold(1e-300f64, |s, x| s.max(x.abs()));
            let (m_scale, h_scale) = (scale(&want[..m_len]), scale(&want[m_len..]));
            for k in 0..len {
                let floor = if k < m_len { m_scale } else { h_scale };
                let what = format!("{model} {sets:?} trial {trial} entry {k}");
                assert_close(got[k], want[k], 1e-12, floor, &what);
            }
            let mut want_jvp = vec![0.0; n];
            jvp.eval(&inp, &mut Vec::new(), &mut want_jvp);
            // The outputs, each at 1e-12 of its kind's scale.
            let mut want_out = vec![0.0; runtime::N_OUTPUTS];
            flat_outputs.eval(&inp, &mut Vec::new(), &mut want_out);
            let mut got_out = vec![f64::NAN; runtime::N_OUTPUTS];
            runtime::parts::outputs(&parts.layout, &mut tp, &q, &qd, &p, &mut got_out);
            let energy = want_out[3].abs().max(want_out[4].abs());
            let position = scale(&want_out[..3]);
            for (k, name) in runtime::OUTPUT_NAMES.iter().enumerate() {
                let (rel, floor) = match k {
                    0..3 => (1e-12, position),
                    3 | 4 => (1e-12, energy),
                    _ => (1e-12, 1.0),
                };
                let what = format!("{model} {sets:?} trial {trial} output {name}");
                assert_close(got_out[k], want_out[k], rel, floor, &what);
            }
            let mut dtau = vec![f64::NAN; n];
            runtime::parts::jvp(&parts.layout, &mut tp, &q, &qd, &qdd, &dir, &p, &mut dtau);
            let jvp_scale = scale(&want_jvp);
            for i in 0..n {
                let what = format!("{model} {sets:?} trial {trial} coordinate {i}");
                assert_close(
                    dtau[i],
                    want_jvp[i],
                    1e-12,
                    jvp_scale,
                    format_args!("jvp {what}"),
                );
            }
        }
    }
}

/// A 3D arm holding two free bodies: a weld at its tip (the far end of a
/// tip body; offset, turned), a pin at its first segment's end.
const HELD_3D: &str = r#"
name = "held_3d"
dimensions = 3
gravity = [0.0, -9.81, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "pcc"
length = 0.3
elements = 3
mass = 1.0
bending_stiffness = 0.6
twist = false
[[segment]]
method = "pcc"
length = 0.3
elements = 2
mass = 1.0
bending_stiffness = 0.6
twist = false
[tip]
mass = 0.01
length = 0.02
radius = 0.005
[[body]]
name = "ball"
shape = "sphere"
radius = 0.05
mass = 1.0
position = [0.67, 0.0, 0.0]
[[body]]
name = "ring"
shape = "sphere"
radius = 0.02
mass = 0.1
position = [0.3, 0.0, 0.0]
[[joint]]
name = "grip"
kind = "weld"
a = "tip"
b = "ball"
offset_a = [0.01, 0.02, -0.01]
offset_b = [-0.05, 0.0, 0.0]
orientation = [0.9689124217106447, 0.0, 0.24740395925452294, 0.0]
[[joint]]
name = "hold"
kind = "pin"
a = "segment.0.end"
b = "ring"
"#;

/// Two 3D arms holding a ball, one bent by a chamber whose pressure is a
/// sine.
const PINCH: &str = r#"
name = "pinch"
dimensions = 3
gravity = [0.0, 0.0, -9.81]
[[arm]]
name = "left"
base = { position = [0.0, 0.0, 0.0], direction = [1.0, 0.0, 0.0] }
[[arm.segment]]
method = "pcc"
length = 0.1
elements = 3
twist = false
density = 1100.0
outer_radius = 0.012
youngs_modulus = 5e5
[arm.segment.chambers]
count = 3
radius = 0.002
distance = 0.006
inputs = ["p", "q", "q"]
[[arm]]
name = "right"
base = { position = [0.25, 0.0, 0.0], direction = [-1.0, 0.0, 0.0] }
[[arm.segment]]
method = "pcc"
length = 0.1
elements = 2
twist = false
density = 1100.0
outer_radius = 0.012
youngs_modulus = 5e5
[[body]]
name = "ball"
shape = "sphere"
radius = 0.02
mass = 0.05
position = [0.125, 0.0, 0.0]
[[joint]]
name = "grip"
kind = "weld"
a = "left.tip"
b = "ball"
offset_b = [-0.02, 0.0, 0.0]
[[joint]]
name = "hold"
kind = "pin"
a = "right.tip"
b = "ball"
offset_b = [0.02, 0.0, 0.0]
[inputs.p]
kind = "sine"
amplitude = 3000.0
frequency = 2.0
[inputs.q]
kind = "constant"
value = 0.0
"#;

/// Models no compiled-in model has, whose link shapes one has, written
/// into `dir`, each with its `--set`: (file or name, set).
fn linked_cases(dir: &std::path::Path) -> Vec<(String, &'static str)> {
    let chambered = dir.join("chambered.toml");
    let text = std::fs::read_to_string(model_path("tentacle3d")).unwrap();
    let chambers = "[segment.chambers]\ncount = 3\nradius = 0.002\ndistance = 0.006\ninputs = [\"p\", \"q\", \"q\"]\n\n[inputs.p]\nkind = \"constant\"\nvalue = 3000.0\n\n[inputs.q]\nkind = \"constant\"\nvalue = 0.0\n\n[tip]";
    std::fs::write(&chambered, text.replace("[tip]", chambers)).unwrap();
    let chambered = chambered.to_string_lossy().into_owned();
    // A link shape no compiled-in model has (a stretching pcc arc): its
    // cell runs on its tapes, the rest of the recursion compiled.
    let stretching = dir.join("stretching.toml");
    let text = text.replace("twist = false", "twist = false\nextension = true");
    assert!(text.contains("extension = true"));
    std::fs::write(&stretching, text).unwrap();
    let stretching = stretching.to_string_lossy().into_owned();
    // A right-angle frame of one arm: its kink a link of no coordinates
    // whose cell (the constant turn and offset) runs on its tapes.
    let frame = root().join("examples/right_angle_frame.toml");
    let frame = frame.to_string_lossy().into_owned();
    // 3D arms on a sphere: contact by the recursion over pcc arcs, pcs's
    // half-arcs (all six strains) and rom slices.
    let sphere = "\n[[obstacle]]\nname = \"ball\"\nshape = \"sphere\"\ncenter = [0.15, 0.0, -0.08]\nradius = 0.05\n\n[contact]\nmodel = \"hunt_crossley\"\nstiffness = 1.0e4\nrestitution = 0.5\nfriction = 0.4\npoints_per_element = 4\n";
    let on_sphere = |name: &str, model: &str| {
        let path = dir.join(format!("{name}.toml"));
        let text = std::fs::read_to_string(model_path(model)).unwrap();
        std::fs::write(&path, format!("{text}{sphere}")).unwrap();
        path.to_string_lossy().into_owned()
    };
    // Joints through the arms' frames: a 3D arm of two segments holding a
    // ball at its tip (a weld) and a ring at its first segment's end (a
    // pin), both free bodies on quaternions.
    let held = dir.join("held_3d.toml");
    std::fs::write(&held, HELD_3D).unwrap();
    let held = held.to_string_lossy().into_owned();
    // An assembly whose arm has inputs: a driven chamber, whose pressure
    // the arm's slice of the parameters gets each time it is written.
    let pinch = dir.join("pinch.toml");
    std::fs::write(&pinch, PINCH).unwrap();
    let pinch = pinch.to_string_lossy().into_owned();
    // A finger on a base moved along a driven path, tapping: the contact
    // points' velocities carry the base's.
    let shaken_tap = dir.join("shaken_tap.toml");
    let text = std::fs::read_to_string(model_path("finger_tap")).unwrap() + "\n";
    std::fs::write(&shaken_tap, shaken(&text, r#"["sx", "sy"]"#)).unwrap();
    let shaken_tap = shaken_tap.to_string_lossy().into_owned();
    // Turned by inputs, tapping and on the sphere: the points'
    // velocities carry the base's spin.
    let turned_tap = dir.join("turned_tap.toml");
    let text = std::fs::read_to_string(model_path("finger_tap")).unwrap() + "\n";
    std::fs::write(&turned_tap, turned(&text, 2)).unwrap();
    let turned_tap = turned_tap.to_string_lossy().into_owned();
    let turned_ball = dir.join("turned_ball.toml");
    let text = std::fs::read_to_string(model_path("tentacle3d")).unwrap();
    std::fs::write(&turned_ball, turned(&format!("{text}{sphere}"), 3)).unwrap();
    let turned_ball = turned_ball.to_string_lossy().into_owned();
    // Swimming on the sphere: the drag beside the contact.
    let dragged_ball = dir.join("dragged_ball.toml");
    std::fs::write(&dragged_ball, format!("{text}{sphere}{DRAGGED}")).unwrap();
    let dragged_ball = dragged_ball.to_string_lossy().into_owned();
    // An assembly whose arm turns on its base.
    let turned_ball_drop = dir.join("turned_falling_ball.toml");
    let text = std::fs::read_to_string(model_path("falling_ball")).unwrap().replacen(
        "base = { position = [0.0, 0.0, 0.0], direction = [1.0, 0.0, 0.0] }",
        "base = { position = [0.0, 0.0, 0.0], direction = [1.0, 0.0, 0.0], rotation_inputs = [\"yaw\"] }",
        1,
    );
    assert!(text.contains("rotation_inputs"));
    let text = format!("{text}\n[inputs.yaw]\nkind = \"sine\"\namplitude = 0.4\nfrequency = 1.5\n");
    std::fs::write(&turned_ball_drop, text).unwrap();
    let turned_ball_drop = turned_ball_drop.to_string_lossy().into_owned();
    let (tentacle_ball, rod_ball, rom_ball, rigid_ball) = (
        on_sphere("tentacle_ball", "tentacle3d"),
        on_sphere("rod_ball", "rod_swing"),
        on_sphere("rom_ball", "rod_swing_rom"),
        on_sphere("rigid_ball", "cantilever3d"),
    );
    // A pendulum chain over a floor: contact on straight rigid links.
    let chain_floor = dir.join("chain_floor.toml");
    let text = std::fs::read_to_string(model_path("chain")).unwrap();
    std::fs::write(&chain_floor, format!("{text}{FLOOR}")).unwrap();
    let chain_floor = chain_floor.to_string_lossy().into_owned();
    let actuated_eba_file = dir.join("actuated_eba.toml");
    std::fs::write(&actuated_eba_file, self::actuated_eba()).unwrap();
    let actuated_eba = actuated_eba_file.to_string_lossy().into_owned();
    let loaded_eba = dir.join("loaded_eba.toml");
    std::fs::write(&loaded_eba, as_eba(LOADED_3D)).unwrap();
    let loaded_eba = loaded_eba.to_string_lossy().into_owned();
    let cases: Vec<(&str, &'static str)> = vec![
        (stretching.as_str(), "segment.0.elements=6"),
        (frame.as_str(), "segment.1.offset=[0.01, -0.02, 0.005]"),
        ("tentacle3d", "segment.0.elements=13"),
        ("cantilever3d", "segment.0.elements=7"),
        ("rod_swing", "segment.0.elements=4"),
        // Past the shared sums' width: a block of columns at a time.
        ("rod_swing", "segment.0.elements=11"),
        ("rom_arm", "segment.0.order=5"),
        ("stiff_flop", "segment.0.elements=5"),
        (chambered.as_str(), "segment.0.elements=4"),
        // Planar arms: the sums in the plane (`links::planar`) over
        // cantilever's pcc cells, soft_finger's with its chambers'
        // loads, chain's rigid links and hybrid_arm's two kinds.
        ("cantilever", "segment.0.elements=7"),
        ("soft_finger", "segment.0.elements=5"),
        ("chain", "segment.0.elements=11"),
        ("hybrid_arm", "segment.1.elements=3"),
        // Arms with contact: the recursion's M and h beside their tapes'
        // contact kernels (3D, planar with friction).
        ("finger_tap", "segment.0.elements=7"),
        ("wrap", "segment.0.elements=9"),
        (shaken_tap.as_str(), "segment.0.elements=7"),
        (turned_tap.as_str(), "segment.0.elements=7"),
        (turned_ball.as_str(), "segment.0.elements=5"),
        (dragged_ball.as_str(), "segment.0.elements=5"),
        (tentacle_ball.as_str(), "segment.0.elements=5"),
        (rod_ball.as_str(), "segment.0.elements=3"),
        (rom_ball.as_str(), "segment.0.quadrature=3"),
        // Rigid links: points on straight links past their joints, in
        // space (the halves about midpoint joints) and in the plane.
        (rigid_ball.as_str(), "segment.0.method=rigid"),
        (chain_floor.as_str(), "segment.0.elements=9"),
        (chain_floor.as_str(), "segment.0.joints=\"midpoint\""),
        // Assemblies: each arm kind on its linked cells, its contact
        // points too; the rest (the ball, its contact point, the joints)
        // by the assembly's tapes.
        ("falling_ball", "arm.left.segment.0.elements=7"),
        (turned_ball_drop.as_str(), "arm.left.segment.0.elements=7"),
        (held.as_str(), "segment.1.elements=3"),
        (pinch.as_str(), "arm.right.segment.0.elements=3"),
        ("ball_drop", "arm.right.segment.1.elements=3"),
        // A system of parts: eba's elements, each a part of its kind's
        // kernels (`parts.rs`), the tip's too; chambers and a tendon on
        // the bare arm's joints (their loads zero where none act).
        ("eba_arm", "segment.0.elements=4"),
        (actuated_eba.as_str(), "segment.1.elements=2"),
        // Loads along it, each element's on its own part (on its tapes).
        (loaded_eba.as_str(), "segment.2.elements=3"),
    ];
    (cases.into_iter())
        .map(|(m, set)| (m.to_string(), set))
        .collect()
}

#[test]
fn other_element_counts_and_orders_run_on_linked_compiled_cells() {
    // Structures no compiled-in model has, whose link shapes one has:
    // pcc without twist (tentacle3d's), with twist (cantilever3d's), pcs's
    // half-arcs (rod_swing's), rom slices of another order (rom_arm's).
    // And arms with chambers on bare arms' cells: stiff_flop at another
    // element count, and tentacle3d with chambers in it (its cells read
    // their segment's actuation loads, zero where none act). And planar
    // arms.
    let mut rng = Rng::new(11);
    let dir = tempfile::tempdir().unwrap();
    for (model, set) in linked_cases(dir.path()) {
        let model = model.as_str();
        let what = format!("{model} {set}");
        let sets = [eomgen::model::Override::parse(set).unwrap()];
        let tapes = tempfile::tempdir().unwrap();
        let l = load(
            model,
            &sets,
            BackendChoice::Auto,
            Some(tapes.path().to_path_buf()),
        )
        .unwrap();
        assert!(
            matches!(l.cache, softarm::backend::CacheStatus::Linked),
            "{what}: not linked"
        );
        assert_eq!(l.arm.backend(), "compiled", "{what}");
        // The interpreter's flat tapes, with the same inputs driving them.
        let cache = tempfile::tempdir().unwrap();
        let interpreted = load(
            model,
            &sets,
            BackendChoice::Interpreted,
            Some(cache.path().to_path_buf()),
        )
        .unwrap();
        assert_eq!(
            l.arm.info().coordinates,
            interpreted.arm.info().coordinates,
            "{what}"
        );
        assert_backends_agree(&what, &*l.arm, &*interpreted.arm, &mut rng, 4);
    }
}

#[test]
fn articulated_body_accelerations_equal_the_mass_matrix_solve() {
    // Linked chains whose links own their coordinates take qdd by the
    // articulated-body sweeps (runtime/kernels/src/links/articulated.rs), O(links)
    // and without M; the reference is the interpreter's flat M and h and
    // a dense solve, -M^-1 h, at bent, moving states, with and without a
    // tip body and tip loads, and with loads along the arm.
    let mut rng = Rng::new(29);
    // Loads along an arm of owned links (the rom segment as pcc, no
    // stretch, whose half-arcs share their element's coordinates): their
    // generalised forces enter each coordinate's elimination.
    let dir = tempfile::tempdir().unwrap();
    let owned = dir.path().join("loaded_owned.toml");
    std::fs::write(
        &owned,
        LOADED_3D
            .replace("method = \"rom\"\norder = 2", "method = \"pcc\"")
            .replace("extension = true\n", "")
            // The reference runs no input channels.
            .replace(
                "moment_inputs = [\"m\", \"m\", \"m\"]",
                "moment = [0.01, -0.02, 0.01]",
            )
            // A driven moment on an element's bend, the reference's
            // parameters at its input's value.
            + "[[torque]]\ncoordinate = \"bend_z_1_2\"\ninput = \"tq\"\n\
               [inputs.tq]\nkind = \"constant\"\nvalue = 0.02\n",
    )
    .unwrap();
    let owned = owned.to_str().unwrap().to_string();
    // On a base turned by inputs: the sweep starts in the spinning frame.
    let spun = dir.path().join("turned_tentacle.toml");
    let text = std::fs::read_to_string(model_path("tentacle3d")).unwrap();
    std::fs::write(&spun, turned(&text, 3)).unwrap();
    let spun = spun.to_str().unwrap().to_string();
    // Dragged by a current: forces of the rates in each elimination.
    let dragged = dir.path().join("dragged_tentacle.toml");
    std::fs::write(&dragged, format!("{text}{DRAGGED}")).unwrap();
    let dragged = dragged.to_str().unwrap().to_string();
    for (model, sets) in [
        (owned.as_str(), &[][..]),
        (dragged.as_str(), &["segment.0.elements=7"][..]),
        (spun.as_str(), &["segment.0.elements=13"][..]),
        ("tentacle3d", &["segment.0.elements=13"][..]),
        ("cantilever3d", &["segment.0.elements=7"][..]),
        // Compiled in: their own cells' sweeps (`link_accelerations`).
        ("tentacle3d", &[][..]),
        ("ebr_arm", &[][..]),
        ("cantilever3d", &["gravity=[0,-3,-9.81]"][..]),
        (
            "cantilever3d",
            &[
                "segment.0.elements=9",
                "tip.mass=0.02",
                "tip.length=0.01",
                "tip.force=[0.1,0.2,-0.3]",
                "tip.moment=[0.01,0.0,0.02]",
            ][..],
        ),
    ] {
        let what = format!("{model} {sets:?}");
        let sets: Vec<_> = sets
            .iter()
            .map(|s| eomgen::model::Override::parse(s).unwrap())
            .collect();
        let l = load(model, &sets, BackendChoice::Auto, None).unwrap();
        assert_eq!(l.arm.backend(), "compiled", "{what}");
        let tapes = eomgen::derive::derive(&l.model);
        // The parameters at t = 0.3, driven ones from their channels.
        let base = l.arm.base_params().len();
        let p = l.arm.params_at(0.3)[..base].to_vec();
        let interpreted = Arm::new(Interpreted::new(tapes), p);
        let n = l.arm.dof();
        let names = l.arm.info().coordinates.clone();
        for it in 0..4 {
            let mut q = rng.coordinates(&names, -1.5, 1.5);
            if it == 0 {
                q.fill(0.0);
            }
            let qd = rng.vec(n, -3.0, 3.0);
            let mut qdd = vec![0.0; n];
            let solved = l.arm.direct_accelerations(0.3, &q, &qd, &mut qdd);
            assert_eq!(solved, Some(true), "{what}: no articulated-body sweep");
            let mut m = nalgebra::DMatrix::zeros(n, n);
            let mut h = nalgebra::DVector::zeros(n);
            interpreted.mass_bias(0.3, &q, &qd, &mut m, &mut h);
            let reference = m.cholesky().expect("M positive definite").solve(&(-h));
            let scale = reference.iter().fold(0.0f64, |s, x| s.max(x.abs()));
            for k in 0..n {
                assert_close(
                    qdd[k],
                    reference[k],
                    1e-9,
                    scale,
                    format_args!("{what} qdd[{k}]"),
                );
            }
        }
    }
    // A rom segment's slices share its coordinates: composite sums, not
    // this sweep.
    let rom = load(
        "rom_arm",
        &[eomgen::model::Override::parse("segment.0.order=5").unwrap()],
        BackendChoice::Auto,
        None,
    )
    .unwrap();
    let n = rom.arm.dof();
    let mut qdd = vec![0.0; n];
    assert_eq!(
        rom.arm
            .direct_accelerations(0.0, &vec![0.0; n], &vec![0.0; n], &mut qdd),
        None
    );
}

/// A run says which kernels it took and why: compiled in by name, linked
/// cells for a new element count of a compiled-in chain (planar, 3D, with
/// contact, an assembly's arms), and for the interpreter what the
/// compiled routes lacked (a link shape no model has).
/// A tapered 3D pcc arm of two segments, chambers in the first.
const TAPERED_3D: &str = r#"
name = "tapered"
dimensions = 3
gravity = [0.0, 0.0, -9.81]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "pcc"
length = 0.1
elements = 2
density = 1100.0
outer_radius = 0.012
youngs_modulus = 5e5
[segment.chambers]
count = 3
radius = 0.002
distance = 0.006
inputs = ["p", "p", "p"]
[[segment]]
method = "pcc"
length = 0.1
elements = 2
density = 1100.0
outer_radius = 0.008
youngs_modulus = 5e5
[inputs.p]
kind = "constant"
value = 1000.0
"#;

/// The backend and route of `model` with one override (none if empty).
fn route_of(model: &str, set: &str, choice: BackendChoice) -> (&'static str, String) {
    let sets: Vec<_> = (!set.is_empty())
        .then(|| eomgen::model::Override::parse(set).unwrap())
        .into_iter()
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let l = load(model, &sets, choice, Some(dir.path().to_path_buf())).unwrap();
    (l.arm.backend(), l.route)
}

#[test]
fn rigid_chains_and_systems_of_parts_say_their_route() {
    let (auto, route) = (BackendChoice::Auto, route_of);
    let dir = tempfile::tempdir().unwrap();
    // A rigid chain in space: its joints' link cells (the half before a
    // midpoint joint is ebr_arm's).
    let (b, r) = route("cantilever3d", "segment.0.method=rigid", auto);
    assert_eq!(b, "compiled", "{r}");
    assert!(r.contains("link cells") && r.contains("1 of its 2"), "{r}");
    // A rigid chain's points lie on its straight links past their
    // joints.
    let rigid = dir.path().join("rigid_on_floor.toml");
    let text = std::fs::read_to_string(model_path("chain")).unwrap();
    std::fs::write(&rigid, format!("{text}{FLOOR}")).unwrap();
    let (b, r) = route(&rigid.to_string_lossy(), "", auto);
    assert_eq!(b, "compiled");
    assert!(r.contains("link cells") && !r.contains("contact"), "{r}");
    // Its halves about midpoint joints: link cells no compiled-in model
    // has.
    let midpoint = "segment.0.joints=\"midpoint\"";
    let (b, r) = route(&rigid.to_string_lossy(), midpoint, auto);
    assert_eq!(b, "compiled");
    assert!(
        r.contains("2 of its 2 link shapes") && !r.contains("contact"),
        "{r}"
    );
    // A system of parts (eba): each kind of part compiled, the tip's
    // too (it reads the tip's, the base's and the last element's
    // parameters, whatever the element count).
    let (b, r) = route("eba_arm", "segment.0.elements=4", auto);
    assert_eq!(b, "compiled");
    assert!(
        r.contains("link cells") && r.contains("parts of 4 kinds, 0 on their tapes"),
        "{r}"
    );
    // An eba arm on a moving base: what the parts lack, said.
    let shaken = dir.path().join("shaken_eba.toml");
    let text = std::fs::read_to_string(model_path("eba_arm"))
        .unwrap()
        .replacen(
            "[base]\n",
            "[base]\ntranslation_inputs = [\"x\", \"x\", \"x\"]\n",
            1,
        );
    let text = format!("{text}\n[inputs.x]\nkind = \"sine\"\namplitude = 0.01\nfrequency = 1.0\n");
    std::fs::write(&shaken, text).unwrap();
    let (b, r) = route(&shaken.to_string_lossy(), "", auto);
    assert_eq!(b, "interpreted");
    assert!(r.contains("its eba elements sit on a moving base"), "{r}");
}

#[test]
fn a_run_says_which_route_it_took_and_why() {
    let route = route_of;
    let auto = BackendChoice::Auto;
    // A tapered 3D pcc arm with chambers: no bundled model has its
    // structure, but every link shape (cells read their actuation loads,
    // zero where none act: tentacle3d's bare cells serve it).
    let dir = tempfile::tempdir().unwrap();
    let tapered = dir.path().join("tapered.toml");
    std::fs::write(&tapered, TAPERED_3D).unwrap();
    let tapered = tapered.to_string_lossy().into_owned();
    // The same with a driven moment on an element's bend.
    let torqued = dir.path().join("torqued.toml");
    let text = std::fs::read_to_string(&tapered).unwrap()
        + "[[torque]]\ncoordinate = \"bend_y_1_0\"\ninput = \"p\"\n";
    std::fs::write(&torqued, text).unwrap();
    let torqued = torqued.to_string_lossy().into_owned();
    // A stretching pcc arm whose section keeps its area: a link shape no
    // bundled model has (stiff_flop's stretch thins its section).
    let stretching = dir.path().join("stretching.toml");
    let text = std::fs::read_to_string(model_path("tentacle3d"))
        .unwrap()
        .replace("twist = false", "twist = false\nextension = true");
    std::fs::write(&stretching, text).unwrap();
    let stretching = stretching.to_string_lossy().into_owned();
    let (b, r) = route("soft_finger", "", auto);
    assert_eq!((b, r.as_str()), ("compiled", "compiled in as soft_finger"));
    for (model, set) in [
        ("tentacle3d", "segment.0.elements=13"),
        (tapered.as_str(), ""),
        (torqued.as_str(), ""),
        ("soft_finger", "segment.0.elements=7"),
    ] {
        let (b, r) = route(model, set, auto);
        assert_eq!(b, "compiled", "{model} {set}");
        assert!(
            r.contains("link cells") && !r.contains("contact"),
            "{model}: {r}"
        );
    }
    // README's two-chamber finger and continuously tapered tentacle,
    // files no build has seen.
    for file in ["two_chamber_finger", "tapered_tentacle"] {
        let example = root().join(format!("examples/{file}.toml"));
        let example = example.to_string_lossy();
        let (b, r) = route(&example, "", auto);
        assert_eq!(b, "compiled", "{file}: {r}");
        assert!(r.contains("link cells"), "{file}: {r}");
    }
    let example = root().join("examples/right_angle_frame.toml");
    let (b, r) = route(&example.to_string_lossy(), "", auto);
    assert_eq!(b, "compiled");
    assert!(
        r.contains("link cells") && r.contains("runs on its tapes"),
        "{r}"
    );
    // A section that bends unequally: link cells of their own, which no
    // compiled-in model has.
    let example = root().join("examples/two_chamber_finger_3d.toml");
    let (b, r) = route(&example.to_string_lossy(), "", auto);
    assert_eq!(b, "compiled", "{r}");
    assert!(r.contains("link cells") && r.contains("tapes"), "{r}");
    // A base turned by an input: the same link cells, the sweeps started
    // in the turning frame.
    let turned = dir.path().join("turned.toml");
    let text = std::fs::read_to_string(&tapered)
        .unwrap()
        .replace("[base]\n", "[base]\nrotation_inputs = [\"p\"]\n");
    std::fs::write(&turned, text).unwrap();
    let (b, r) = route(&turned.to_string_lossy(), "", auto);
    assert_eq!(b, "compiled", "{r}");
    assert!(r.contains("link cells") && !r.contains("tapes"), "{r}");
    let example = root().join("examples/palm.toml");
    let (b, r) = route(&example.to_string_lossy(), "", auto);
    assert_eq!(b, "interpreted");
    assert!(r.contains("sits on another arm"), "{r}");
    // Contact by the recursion where the points lie on the links' arcs;
    // a rigid chain's points do not: its contact kernels are its tapes'.
    let (b, r) = route("finger_tap", "segment.0.elements=5", auto);
    assert_eq!(b, "compiled");
    assert!(r.contains("link cells") && !r.contains("contact"), "{r}");
    let (b, r) = route("falling_ball", "arm.left.segment.0.elements=3", auto);
    assert_eq!(b, "compiled");
    assert!(
        r.contains("each arm's layout")
            && r.contains("assembly interpreted")
            && r.contains("joints' rows on the arms' frames"),
        "{r}"
    );
    let (b, r) = route(&stretching, "", auto);
    assert_eq!(b, "compiled");
    assert!(
        r.contains("1 of its 1 link shapes is in no compiled-in model and runs on its tapes")
            && r.contains("cargo build"),
        "{r}"
    );
    let (b, r) = route("soft_finger", "", BackendChoice::Interpreted);
    assert_eq!(
        (b, r.as_str()),
        ("interpreted", "the interpreter, as asked")
    );
}
