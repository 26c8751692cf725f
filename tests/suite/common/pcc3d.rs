//! M and h of a 3D pcc arm (bending pair per element, no twist or stretch,
//! still base, tip force and moment) by a numeric recursion over the
//! elements: forward kinematics and convective accelerations element by
//! element, then composite-body sums from the tip (Featherstone's CRBA and
//! RNEA in the world frame). The same lumped model as softarm's pcc
//! (`eomgen/src/tmt/spatial.rs`: one body per arc at its exact centroid,
//! turning with the mid-arc frame, axisymmetric inertia) computed without
//! the CAS: directional derivatives of the arc formulas by hand, Rodrigues
//! coefficients from `runtime::rodrigues::family`.
//!
//! Two uses: a second method for the generated kernels (tests/suite/spatial.rs),
//! and what a kernel made of one element's code run in a loop costs
//! (benches/interleaved.rs), against the unrolled kernels whose size puts
//! them past the instruction caches (measured by benches/interleaved.rs and callgrind).

type V3 = [f64; 3];
type M3 = [[f64; 3]; 3];

#[inline(always)]
fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
#[inline(always)]
fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
#[inline(always)]
fn scale(s: f64, a: V3) -> V3 {
    [s * a[0], s * a[1], s * a[2]]
}
#[inline(always)]
fn dot(a: V3, b: V3) -> f64 {
    a[0].mul_add(b[0], a[1].mul_add(b[1], a[2] * b[2]))
}
#[inline(always)]
fn cross(a: V3, b: V3) -> V3 {
    [
        a[1].mul_add(b[2], -(a[2] * b[1])),
        a[2].mul_add(b[0], -(a[0] * b[2])),
        a[0].mul_add(b[1], -(a[1] * b[0])),
    ]
}
#[inline(always)]
fn mat_vec(r: &M3, v: V3) -> V3 {
    [dot(r[0], v), dot(r[1], v), dot(r[2], v)]
}
fn mat_mat(a: &M3, b: &M3) -> M3 {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j])
    })
}
/// a0 + a1 + ..., for the sums of several terms.
#[inline(always)]
fn sum(vs: &[V3]) -> V3 {
    vs.iter().fold([0.0; 3], |s, &v| add(s, v))
}

const EX: V3 = [1.0, 0.0, 0.0];

/// f(rho) = (A I + B K + C K^2) e_x with K = [rho]x and A, B, C functions
/// of w = |rho|^2 (given with their first two derivatives in w):
/// K e_x = rho x e_x, K^2 e_x = rho_x rho - w e_x.
struct OnX {
    a: [f64; 3],
    b: [f64; 3],
    c: [f64; 3],
}

impl OnX {
    #[inline(always)]
    fn value(&self, rho: V3, w: f64) -> V3 {
        let p = sub(scale(rho[0], rho), scale(w, EX));
        sum(&[
            scale(self.a[0], EX),
            scale(self.b[0], cross(rho, EX)),
            scale(self.c[0], p),
        ])
    }

    /// The derivative along `d`.
    #[inline(always)]
    fn along(&self, rho: V3, w: f64, d: V3) -> V3 {
        let wd = 2.0 * dot(rho, d);
        let p = sub(scale(rho[0], rho), scale(w, EX));
        let pd = sub(add(scale(d[0], rho), scale(rho[0], d)), scale(wd, EX));
        sum(&[
            scale(self.a[1] * wd, EX),
            scale(self.b[1] * wd, cross(rho, EX)),
            scale(self.b[0], cross(d, EX)),
            scale(self.c[1] * wd, p),
            scale(self.c[0], pd),
        ])
    }

    /// The second derivative along `d` twice.
    #[inline(always)]
    fn along_twice(&self, rho: V3, w: f64, d: V3) -> V3 {
        let wd = 2.0 * dot(rho, d);
        let wdd = 2.0 * dot(d, d);
        let p = sub(scale(rho[0], rho), scale(w, EX));
        let pd = sub(add(scale(d[0], rho), scale(rho[0], d)), scale(wd, EX));
        let pdd = sub(scale(2.0 * d[0], d), scale(wdd, EX));
        sum(&[
            scale(self.a[2] * wd * wd + self.a[1] * wdd, EX),
            scale(self.b[2] * wd * wd + self.b[1] * wdd, cross(rho, EX)),
            scale(2.0 * self.b[1] * wd, cross(d, EX)),
            scale(self.c[2] * wd * wd + self.c[1] * wdd, p),
            scale(2.0 * self.c[1] * wd, pd),
            scale(self.c[0], pdd),
        ])
    }
}

/// g(rho) u = (A I + B K + C rho rho^T) u, the left Jacobian's form, with
/// its rate along rho' = u (rho'' = 0).
struct LeftJacobian {
    a: [f64; 2],
    b: [f64; 2],
    c: [f64; 2],
}

impl LeftJacobian {
    #[inline(always)]
    fn apply(&self, rho: V3, u: V3) -> V3 {
        sum(&[
            scale(self.a[0], u),
            scale(self.b[0], cross(rho, u)),
            scale(self.c[0] * dot(rho, u), rho),
        ])
    }

    /// d/dt (g(rho) rho') at rho'' = 0.
    #[inline(always)]
    fn rate(&self, rho: V3, rate: V3) -> V3 {
        let wd = 2.0 * dot(rho, rate);
        let rr = dot(rho, rate);
        sum(&[
            scale(self.a[1] * wd, rate),
            scale(self.b[1] * wd, cross(rho, rate)),
            scale(self.c[1] * wd * rr + self.c[0] * dot(rate, rate), rho),
            scale(self.c[0] * rr, rate),
        ])
    }
}

/// A spatial inertia about the world origin.
#[derive(Clone, Copy, Default)]
struct Inertia {
    m: f64,
    h: V3,
    /// Symmetric, full.
    j: M3,
}

impl Inertia {
    #[inline(always)]
    fn of_body(m: f64, r: V3, lateral: f64, axial: f64, axis: V3) -> Self {
        let r2 = dot(r, r);
        let j = std::array::from_fn(|i| {
            std::array::from_fn(|k| {
                let id = if i == k { 1.0 } else { 0.0 };
                lateral * id + (axial - lateral) * axis[i] * axis[k] + m * (r2 * id - r[i] * r[k])
            })
        });
        Self {
            m,
            h: scale(m, r),
            j,
        }
    }

    #[inline(always)]
    fn add(&mut self, o: &Self) {
        self.m += o.m;
        self.h = add(self.h, o.h);
        for i in 0..3 {
            for k in 0..3 {
                self.j[i][k] += o.j[i][k];
            }
        }
    }

    /// The momentum of the twist (w, v): (J w + h x v, m v + w x h).
    #[inline(always)]
    fn momentum(&self, (w, v): (V3, V3)) -> (V3, V3) {
        (
            add(mat_vec(&self.j, w), cross(self.h, v)),
            add(scale(self.m, v), cross(w, self.h)),
        )
    }
}

#[inline(always)]
fn pair(a: (V3, V3), b: (V3, V3)) -> f64 {
    dot(a.0, b.0) + dot(a.1, b.1)
}

/// Axisymmetric body inertia applied to a vector.
#[inline(always)]
fn apply_body(lateral: f64, axial: f64, axis: V3, w: V3) -> V3 {
    add(
        scale(lateral, w),
        scale((axial - lateral) * dot(axis, w), axis),
    )
}

#[derive(Clone, Copy, Default)]
struct Element {
    l: f64,
    m: f64,
    lateral: f64,
    axial: f64,
    stiffness: f64,
    damping: f64,
    rest: f64,
}

/// What the backward sweep needs of element k.
#[derive(Clone, Copy, Default)]
struct Computed {
    /// Twists of the two coordinates (angular, velocity of the point at
    /// the origin).
    twist: [(V3, V3); 2],
    /// The body's own columns (angular, centroid velocity).
    own: [(V3, V3); 2],
    /// Velocity columns of the end point (where a tip force acts).
    end_velocity: [V3; 2],
    end: V3,
    centroid: V3,
    axis: V3,
    force: V3,
    torque: V3,
}

pub struct Pcc3d {
    elements: Vec<Element>,
    gravity: V3,
    base_r: M3,
    base_p: V3,
    tip_force: V3,
    tip_moment: V3,
    computed: Vec<Computed>,
    momenta: Vec<(V3, V3)>,
}

impl Pcc3d {
    /// From a model's parameter names and values (the layout of
    /// `Arm::params`).
    pub fn new(names: &[String], p: &[f64]) -> Self {
        let get = |n: &str| {
            p[names
                .iter()
                .position(|x| x == n)
                .unwrap_or_else(|| panic!("no parameter {n}"))]
        };
        let n = names.iter().filter(|x| x.ends_with("].length")).count();
        let elements = (0..n)
            .map(|k| Element {
                l: get(&format!("element[{k}].length")),
                m: get(&format!("element[{k}].mass")),
                lateral: get(&format!("element[{k}].inertia")),
                axial: get(&format!("element[{k}].axial_inertia")),
                stiffness: get(&format!("joint[{k}].stiffness")),
                damping: get(&format!("joint[{k}].damping")),
                rest: get(&format!("joint[{k}].rest")),
            })
            .collect();
        let v = |pre: &str| ["x", "y", "z"].map(|c| get(&format!("{pre}.{c}")));
        Self {
            elements,
            gravity: v("gravity"),
            base_r: std::array::from_fn(|i| std::array::from_fn(|j| get(&format!("base.R{i}{j}")))),
            base_p: v("base"),
            tip_force: v("tip.force"),
            tip_moment: v("tip.moment"),
            computed: vec![Computed::default(); n],
            momenta: vec![([0.0; 3], [0.0; 3]); 2 * n],
        }
    }

    pub fn dof(&self) -> usize {
        2 * self.elements.len()
    }

    /// The upper triangle of M row by row, then h: the `MassBias` layout.
    pub fn mass_bias(&mut self, q: &[f64], qd: &[f64], out: &mut [f64]) {
        // Built for FMA where the processor has it, like the kernels.
        #[cfg(target_arch = "x86_64")]
        if runtime::cpu::has_fma() {
            // SAFETY: the processor has FMA (checked just above).
            return unsafe { self.mass_bias_fma(q, qd, out) };
        }
        self.mass_bias_any(q, qd, out)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "fma")]
    unsafe fn mass_bias_fma(&mut self, q: &[f64], qd: &[f64], out: &mut [f64]) {
        self.mass_bias_any(q, qd, out)
    }

    #[inline(always)]
    fn mass_bias_any(&mut self, q: &[f64], qd: &[f64], out: &mut [f64]) {
        let n = self.dof();
        assert_eq!(out.len(), n * (n + 1) / 2 + n);
        self.outward(q, qd);
        self.inward(q, qd, out);
    }

    /// From the base: every element's frames, its body's motion and the
    /// force and torque its motion takes, its twists (`computed`).
    fn outward(&mut self, q: &[f64], qd: &[f64]) {
        let (mut r, mut p) = (self.base_r, self.base_p);
        let (mut omega, mut alpha, mut acc) = ([0.0; 3], [0.0; 3], [0.0; 3]);
        for (k, e) in self.elements.iter().enumerate() {
            let rho = [0.0, q[2 * k], q[2 * k + 1]];
            let rate = [0.0, qd[2 * k], qd[2 * k + 1]];
            let w = dot(rho, rho);
            let c = runtime::rodrigues::family::<3>(w);
            let h = runtime::rodrigues::family::<3>(0.25 * w);
            let l = e.l;
            // Chord l (I + c2 K + c3 K^2) e_x, centroid l (I/2 + c3 K + c4 K^2) e_x.
            let chord = OnX {
                a: [l, 0.0, 0.0],
                b: c[2].map(|x| l * x),
                c: c[3].map(|x| l * x),
            };
            let centroid = OnX {
                a: [0.5 * l, 0.0, 0.0],
                b: c[3].map(|x| l * x),
                c: c[4].map(|x| l * x),
            };
            // exp([rho/2]x) e_x: the mid-arc axis.
            let axis = OnX {
                a: [1.0, 0.0, 0.0],
                b: [0.5 * h[1][0], 0.0, 0.0],
                c: [0.25 * h[2][0], 0.0, 0.0],
            };
            // End: J_l(rho) = c1 I + c2 K + c3 rho rho^T; mid-arc: J_l(rho/2) / 2
            // with w/4, so the w-derivatives carry 1/4.
            let jl = LeftJacobian {
                a: [c[1][0], c[1][1]],
                b: [c[2][0], c[2][1]],
                c: [c[3][0], c[3][1]],
            };
            let jm = LeftJacobian {
                a: [0.5 * h[1][0], 0.125 * h[1][1]],
                b: [0.25 * h[2][0], 0.0625 * h[2][1]],
                c: [0.125 * h[3][0], 0.03125 * h[3][1]],
            };
            let rel_r: M3 = {
                let kk: M3 = [
                    [0.0, -rho[2], rho[1]],
                    [rho[2], 0.0, -rho[0]],
                    [-rho[1], rho[0], 0.0],
                ];
                let k2 = mat_mat(&kk, &kk);
                std::array::from_fn(|i| {
                    std::array::from_fn(|j| {
                        (if i == j { 1.0 } else { 0.0 }) + c[1][0] * kk[i][j] + c[2][0] * k2[i][j]
                    })
                })
            };

            let d = mat_vec(&r, chord.value(rho, w));
            let dd = mat_vec(&r, chord.along(rho, w, rate));
            let ddd = mat_vec(&r, chord.along_twice(rho, w, rate));
            let cen = mat_vec(&r, centroid.value(rho, w));
            let cend = mat_vec(&r, centroid.along(rho, w, rate));
            let cendd = mat_vec(&r, centroid.along_twice(rho, w, rate));
            let w_rel = mat_vec(&r, jl.apply(rho, rate));
            let w_rel_d = mat_vec(&r, jl.rate(rho, rate));
            let w_mid = mat_vec(&r, jm.apply(rho, rate));
            let w_mid_d = mat_vec(&r, jm.rate(rho, rate));

            // The body: centroid, its convective accelerations, its forces.
            let body_r = add(p, cen);
            let body_a = sum(&[
                acc,
                cross(alpha, cen),
                cross(omega, cross(omega, cen)),
                scale(2.0, cross(omega, cend)),
                cendd,
            ]);
            let body_w = add(omega, w_mid);
            let body_alpha = sum(&[alpha, cross(omega, w_mid), w_mid_d]);
            let ax = mat_vec(&r, axis.value(rho, w));
            let iw = apply_body(e.lateral, e.axial, ax, body_w);
            let torque = add(
                apply_body(e.lateral, e.axial, ax, body_alpha),
                cross(body_w, iw),
            );
            let force = scale(e.m, sub(body_a, self.gravity));

            let end = add(p, d);
            let mut out_k = Computed {
                end,
                centroid: body_r,
                axis: ax,
                force,
                torque,
                ..Default::default()
            };
            for ci in 0..2 {
                let mut unit = [0.0; 3];
                unit[ci + 1] = 1.0;
                let s_w = mat_vec(&r, jl.apply(rho, unit));
                let v_end = mat_vec(&r, chord.along(rho, w, unit));
                out_k.twist[ci] = (s_w, sub(v_end, cross(s_w, end)));
                out_k.end_velocity[ci] = v_end;
                out_k.own[ci] = (
                    mat_vec(&r, jm.apply(rho, unit)),
                    mat_vec(&r, centroid.along(rho, w, unit)),
                );
            }
            self.computed[k] = out_k;

            // The next frame.
            acc = sum(&[
                acc,
                cross(alpha, d),
                cross(omega, cross(omega, d)),
                scale(2.0, cross(omega, dd)),
                ddd,
            ]);
            alpha = sum(&[alpha, cross(omega, w_rel), w_rel_d]);
            omega = add(omega, w_rel);
            p = end;
            r = mat_mat(&r, &rel_r);
        }
    }

    /// From the tip: composite inertias and wrenches, the coordinates'
    /// momenta, and so M and h into `out`.
    fn inward(&mut self, q: &[f64], qd: &[f64], out: &mut [f64]) {
        let n = self.dof();
        // From the tip: composite inertia and wrench of everything past
        // element k; momenta and generalised forces of its coordinates.
        let n_el = self.elements.len();
        let (mass, bias) = out.split_at_mut(n * (n + 1) / 2);
        let index = |i: usize, j: usize| i * n - i * (i + 1) / 2 + j;
        let mut past = Inertia::default();
        let mut wrench: (V3, V3) = ([0.0; 3], [0.0; 3]);
        let tip_f = scale(-1.0, self.tip_force);
        let tip_m = scale(-1.0, self.tip_moment);
        for k in (0..n_el).rev() {
            let e = self.elements[k];
            let c = self.computed[k];
            let last = k == n_el - 1;
            for ci in 0..2 {
                let j = 2 * k + ci;
                let s = c.twist[ci];
                let (ow, ov) = c.own[ci];
                let mv = scale(e.m, ov);
                let (pa, pl) = past.momentum(s);
                self.momenta[j] = (
                    sum(&[
                        pa,
                        apply_body(e.lateral, e.axial, c.axis, ow),
                        cross(c.centroid, mv),
                    ]),
                    add(pl, mv),
                );
                let mut g = pair(s, wrench) + dot(ov, c.force) + dot(ow, c.torque);
                if last {
                    g += dot(c.end_velocity[ci], tip_f) + dot(s.0, tip_m);
                }
                let (qj, rest) = (q[j], if ci == 1 { e.rest } else { 0.0 });
                bias[j] = g + e.stiffness * (qj - rest) + e.damping * qd[j];
            }
            for ci in 0..2 {
                for cj in ci..2 {
                    let (i, j) = (2 * k + ci, 2 * k + cj);
                    let (wi, vi) = c.own[ci];
                    let (wj, vj) = c.own[cj];
                    mass[index(i, j)] = pair(c.twist[ci], past.momentum(c.twist[cj]))
                        + e.m * dot(vi, vj)
                        + dot(wi, apply_body(e.lateral, e.axial, c.axis, wj));
                }
            }
            past.add(&Inertia::of_body(
                e.m, c.centroid, e.lateral, e.axial, c.axis,
            ));
            let body_wrench = (add(c.torque, cross(c.centroid, c.force)), c.force);
            wrench = (add(wrench.0, body_wrench.0), add(wrench.1, body_wrench.1));
            if last {
                wrench = (
                    add(wrench.0, add(cross(c.end, tip_f), tip_m)),
                    add(wrench.1, tip_f),
                );
            }
        }
        // Coordinates of different elements: twist . momentum, a row at a
        // time from the element after i's.
        for i in 0..n {
            let (w, v) = self.computed[i / 2].twist[i % 2];
            let first = 2 * (i / 2 + 1);
            let row = &mut mass[index(i, first)..index(i, n - 1) + 1];
            for (m, &(a, l)) in row.iter_mut().zip(&self.momenta[first..]) {
                *m = pair((w, v), (a, l));
            }
        }
    }
}
