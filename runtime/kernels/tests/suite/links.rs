//! The link recursion against closed forms and the flat sums (`links`).

use runtime_kernels::links::*;

/// A rigid link turning about z at its base by its one coordinate:
/// length p[0], mass p[1] at its middle, inertia p[2] about a diameter
/// and p[3] about its axis, a joint spring p[4] and damper p[5].
struct Pendulums;

impl Cells for Pendulums {
    fn one(&mut self, _c: usize, x: &[f64], xd: &[f64], p: &[f64], out: &mut [f64]) {
        let (th, w, l) = (x[0], xd[0], p[0]);
        let (s, c) = th.sin_cos();
        out.fill(0.0);
        out[cell::ROTATION..][..9].copy_from_slice(&[c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0]);
        // The end and the centroid, their rates and convective
        // accelerations.
        for (at, f) in [(cell::END, 1.0), (cell::CENTROID, 0.5)] {
            let r = f * l;
            out[at..][..3].copy_from_slice(&[r * c, r * s, 0.0]);
            out[at + 3..][..3].copy_from_slice(&[-r * s * w, r * c * w, 0.0]);
            out[at + 6..][..3].copy_from_slice(&[-r * c * w * w, -r * s * w * w, 0.0]);
        }
        out[cell::OMEGA + 2] = w;
        out[cell::BODY_OMEGA + 2] = w;
        out[cell::AXIS..][..3].copy_from_slice(&[c, s, 0.0]);
        out[cell::MASS] = p[1];
        out[cell::LATERAL] = p[2];
        out[cell::AXIAL] = p[3];
        // The columns: end frame turn and end velocity, body turn and
        // centroid velocity, per unit rate.
        let col = &mut out[cell::COLUMNS..][..12];
        col[2] = 1.0;
        col[3..6].copy_from_slice(&[-l * s, l * c, 0.0]);
        col[8] = 1.0;
        col[9..12].copy_from_slice(&[-0.5 * l * s, 0.5 * l * c, 0.0]);
        out[cell::forces(1)] = p[4] * th + p[5] * w;
    }

    fn forces(&mut self, _out: &mut [f64]) {
        unreachable!("no non-local forces")
    }

    fn tangent(
        &mut self,
        _: usize,
        _: &[f64],
        _: &[f64],
        _: &[f64],
        _: &[f64],
        _: &[f64],
        _: &mut [f64],
    ) {
        unreachable!("mass + bias only")
    }

    fn forces_tangent(&mut self, _dir: &[f64], _out: &mut [f64]) {
        unreachable!("no non-local forces")
    }

    fn loads(&mut self, _out: &mut [f64]) {
        unreachable!("no actuators")
    }

    fn pose(&mut self, _: usize, _: &[f64], _: &[f64], _: &[f64], _: &mut [f64]) {
        unreachable!("mass + bias only")
    }

    fn energy(&mut self) -> f64 {
        unreachable!("no non-local forces")
    }
}

const G: f64 = 9.81;
/// Length, mass, inertia about a diameter and about the axis, joint
/// spring and damper of each link.
const LINKS: [[f64; 6]; 3] = [
    [0.3, 0.5, 4e-3, 1e-4, 2.0, 0.1],
    [0.2, 0.3, 1e-3, 5e-5, 1.0, 0.05],
    [0.25, 0.2, 2e-3, 2e-5, 0.5, 0.02],
];

/// The chain's layout and parameters: gravity along -y, the base at the
/// origin unturned, then each link's parameters.
fn chain() -> (LinkLayout, Vec<f64>) {
    let mut p = vec![0.0, -G, 0.0, 0.0, 0.0, 0.0];
    p.extend([
        1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0,
    ]);
    let mut links = Vec::new();
    for (k, link) in LINKS.iter().enumerate() {
        let at = p.len();
        p.extend(link);
        p.extend([0.0; ELEMENT_PARAMS - 6]);
        links.push(LinkSpec {
            cell: 0,
            map: vec![LocalCoordinate {
                terms: vec![(k, 1.0)],
                scale: None,
            }],
            params: (at..at + ELEMENT_PARAMS).chain([at; REST_PARAMS]).collect(),
            load: None,
            displaced: None,
            principal: None,
        });
    }
    let layout = LinkLayout {
        links,
        dof: LINKS.len(),
        gravity: [0, 1, 2],
        base_position: [3, 4, 5],
        base_rotation: std::array::from_fn(|i| 6 + i),
        base_quaternion: [15, 16, 17, 18],
        ..Default::default()
    };
    (layout, p)
}

/// M of the planar pendulum chain from its bodies' Jacobians (the
/// closed form: centroid columns z x (c_b - joint_i), turn columns 1).
fn mass(q: &[f64]) -> Vec<Vec<f64>> {
    let n = q.len();
    let mut m = vec![vec![0.0; n]; n];
    let (mut joint, mut phi) = ([0.0; 2], 0.0);
    let mut joints = Vec::new();
    for (b, link) in LINKS.iter().enumerate() {
        phi += q[b];
        joints.push(joint);
        let c = [
            joint[0] + 0.5 * link[0] * phi.cos(),
            joint[1] + 0.5 * link[0] * phi.sin(),
        ];
        let col = |i: usize| -> [f64; 2] {
            let j: [f64; 2] = joints[i];
            [-(c[1] - j[1]), c[0] - j[0]]
        };
        for (i, row) in m.iter_mut().enumerate().take(b + 1) {
            for (k, entry) in row.iter_mut().enumerate().take(b + 1) {
                let (a, d) = (col(i), col(k));
                *entry += link[1] * (a[0] * d[0] + a[1] * d[1]) + link[2];
            }
        }
        joint = [
            joint[0] + link[0] * phi.cos(),
            joint[1] + link[0] * phi.sin(),
        ];
    }
    m
}

/// h of the chain from Lagrange's equations on the closed-form M and
/// potential by central differences: Christoffel terms, gravity,
/// springs and dampers.
fn bias(q: &[f64], qd: &[f64]) -> Vec<f64> {
    let n = q.len();
    let e = 1e-6;
    let at = |k: usize, s: f64| {
        let mut x = q.to_vec();
        x[k] += s;
        x
    };
    let dm: Vec<Vec<Vec<f64>>> = (0..n)
        .map(|k| {
            let (a, b) = (mass(&at(k, e)), mass(&at(k, -e)));
            (0..n)
                .map(|i| (0..n).map(|j| (a[i][j] - b[i][j]) / (2.0 * e)).collect())
                .collect()
        })
        .collect();
    let potential = |x: &[f64]| {
        let (mut y, mut phi, mut v) = (0.0, 0.0, 0.0);
        for (b, link) in LINKS.iter().enumerate() {
            phi += x[b];
            v += link[1] * G * (y + 0.5 * link[0] * phi.sin());
            y += link[0] * phi.sin();
        }
        v
    };
    (0..n)
        .map(|i| {
            let mut h = (potential(&at(i, e)) - potential(&at(i, -e))) / (2.0 * e);
            for j in 0..n {
                for k in 0..n {
                    h += (dm[k][i][j] - 0.5 * dm[i][j][k]) * qd[j] * qd[k];
                }
            }
            h + LINKS[i][4] * q[i] + LINKS[i][5] * qd[i]
        })
        .collect()
}

/// The recursion's M and h of a three-link planar pendulum chain (cells
/// written here) are the closed form's: M from the bodies' Jacobians,
/// h by Lagrange's equations on it (a cell without its convective
/// accelerations fails it).
#[test]
fn the_recursion_gives_a_pendulum_chains_m_and_h() {
    let (spatial, p) = chain();
    // The same chain as a planar one (a base angle): the sums in the
    // plane.
    let mut planar = (spatial.clone(), p.clone());
    planar.0.base_angle = Some(planar.1.len());
    planar.1.push(0.0);
    for (layout, p) in [(spatial, p), planar] {
        pendulum_chain_matches_the_closed_form(&layout, &p);
    }
}

fn pendulum_chain_matches_the_closed_form(layout: &LinkLayout, p: &[f64]) {
    let n = layout.dof;
    for (q, qd) in [
        ([0.0, 0.0, 0.0], [0.0, 0.0, 0.0]),
        ([0.4, -0.7, 1.1], [0.5, -1.2, 2.0]),
        ([-2.0, 0.3, -0.9], [-1.5, 0.7, 0.2]),
    ] {
        let mut out = vec![f64::NAN; n * (n + 1) / 2 + n];
        mass_bias(layout, &mut Pendulums, &q, &qd, p, &mut out);
        let (m, h) = (mass(&q), bias(&q, &qd));
        let upper = (0..n).flat_map(|i| (i..n).map(move |j| (i, j)));
        for ((i, j), got) in upper.zip(&out) {
            assert!((got - m[i][j]).abs() < 1e-12, "M[{i}][{j}] at {q:?}");
        }
        for (i, (got, want)) in out[n * (n + 1) / 2..].iter().zip(&h).enumerate() {
            assert!(
                (got - want).abs() < 1e-7,
                "h[{i}] at {q:?}: {got} against {want}"
            );
        }
    }
}

/// A planar chain turned by its base angle: the sums in the plane
/// equal the 3D recursion's on the same cells under the same turn
/// (with a tip body and tip loads in the tip frame).
#[test]
fn planar_sums_equal_the_spatial_recursion() {
    let (mut spatial, mut p) = chain();
    let angle = 0.7;
    let (s, c) = f64::sin_cos(angle);
    p[6..15].copy_from_slice(&[c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0]);
    let at = p.len();
    // Tip mass, length, lateral and axial inertia, force, moment.
    p.extend([0.3, 0.1, 2e-3, 1e-4, 0.4, -0.8, 0.0, 0.0, 0.0, 0.25]);
    spatial.tip_mass = Some(at);
    spatial.tip_length = Some(at + 1);
    spatial.tip_inertia = Some([at + 2, at + 3]);
    spatial.tip_force = Some([at + 4, at + 5, at + 6]);
    spatial.tip_moment = Some([at + 7, at + 8, at + 9]);
    spatial.tip_frame = true;
    let mut planar = spatial.clone();
    planar.base_angle = Some(p.len());
    p.push(angle);
    let n = spatial.dof;
    let (q, qd) = ([0.4, -0.7, 1.1], [0.5, -1.2, 2.0]);
    let mut want = vec![f64::NAN; n * (n + 1) / 2 + n];
    mass_bias_spatial::<_, false>(&spatial, &mut Pendulums, &q, &qd, &p, &mut want);
    let mut got = vec![f64::NAN; want.len()];
    mass_bias(&planar, &mut Pendulums, &q, &qd, &p, &mut got);
    for (i, (g, w)) in got.iter().zip(&want).enumerate() {
        assert!((g - w).abs() < 1e-12, "output {i}: {g} against {w}");
    }
}
