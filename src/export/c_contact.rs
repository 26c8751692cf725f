//! Contact in the exported C library: the model's obstacles, laws and
//! pairs as data in the model struct (a caller may change them after
//! init, as softarm changes them without a rebuild), the points' kernels
//! (`Contact`, the `ContactJacobian` groups) as C functions, and the
//! generalised contact force Q_c = sum J^T f subtracted from h, pair by
//! pair in softarm's order (`runtime::contact`). The distances and laws
//! are `contact.c`, a line-for-line port of `runtime::contact::distance`
//! and `law`. Hunt-Crossley from a restitution reads each pair's impact
//! speed, a record the caller keeps with `<prefix>_contact_update` after
//! each step (softarm updates it where a pair begins to touch).

use std::fmt::Write;

use runtime::contact::{Against, ContactSet, Damping, Law, Normal, Shape, law::SLOWEST_IMPACT};
use runtime::{KernelKind, ModelInfo};

use super::c_tape::literal;

/// The distances and laws.
const SUPPORT: &str = include_str!("contact.c");

/// Numbers an obstacle holds (a box's: centre, rotation, half sizes).
const OBSTACLE_LEN: usize = 15;
/// Numbers a law holds: kind, k, c or n, b or a, friction, slip speed.
const LAW_LEN: usize = 6;

/// What the export cannot carry of a contact set, if anything.
pub fn refusal(set: &ContactSet) -> Option<String> {
    if let Some(o) = set.obstacles.iter().find(|o| o.motion.is_some()) {
        return Some(format!(
            "[[obstacle]] \"{}\" moves: a moving obstacle is not exported to C yet (fix it in place \
             to export the rest)",
            o.name
        ));
    }
    set.pairs
        .iter()
        .any(|p| matches!(p.law.normal, Normal::Impulse { .. }))
        .then(|| {
            "[contact]: the impulse law (a velocity jump, then a held constraint) is not exported \
             to C; choose hunt_crossley, hertz or spring_dashpot"
                .to_string()
        })
}

/// The model's contact, as the C library holds it.
pub struct Contact<'a> {
    pub set: &'a ContactSet,
    pub info: &'a ModelInfo,
    /// The distinct laws, in the order the pairs first use them.
    laws: Vec<Law>,
}

impl<'a> Contact<'a> {
    pub fn new(set: &'a ContactSet, info: &'a ModelInfo) -> Self {
        let mut laws: Vec<Law> = Vec::new();
        for p in &set.pairs {
            if !laws.contains(&p.law) {
                laws.push(p.law);
            }
        }
        Self { set, info, laws }
    }

    fn points(&self) -> usize {
        self.set.points.len()
    }
    fn pairs(&self) -> usize {
        self.set.pairs.len()
    }
    /// Array lengths in C, which has no empty arrays.
    fn obstacles_len(&self) -> usize {
        self.set.obstacles.len().max(1)
    }
    /// Values a point takes in the `ContactJacobian` output: p, v, dp/dq.
    fn width(&self) -> usize {
        6 + 3 * self.info.dof()
    }

    /// The workspace pieces: the `Contact` kernel's positions and frames,
    /// every point's p, v and dp/dq, and Q_c.
    pub fn work(&self) -> [(&'static str, usize); 3] {
        [
            ("CPOS", KernelKind::Contact.output_len(self.info)),
            ("CJAC", KernelKind::ContactJacobian.output_len(self.info)),
            ("CQ", self.info.dof()),
        ]
    }

    /// The kernels: the points' positions, then each group's.
    pub fn kernels<'t>(&self, tapes: &'t runtime::TapeSet) -> Vec<(String, &'t runtime::Tape)> {
        let mut k = vec![("k_contact".to_string(), &tapes.contact)];
        for (g, tape) in tapes.contact_jacobian.iter().enumerate() {
            k.push((format!("k_contact_jacobian_{g}"), tape));
        }
        k
    }

    pub fn defines(&self) -> [(&'static str, usize, &'static str); 4] {
        [
            ("NPOINTS", self.points(), "contact points"),
            (
                "NPAIRS",
                self.pairs(),
                "contact pairs (point and obstacle, point and point)",
            ),
            ("NOBSTACLES", self.set.obstacles.len(), "obstacles"),
            ("NLAWS", self.laws.len(), "distinct contact laws"),
        ]
    }

    /// The model struct's contact fields.
    pub fn fields(&self) -> String {
        format!(
            "    /* Contact, set by init from the model file; change them after init. Obstacle k:\n     \
             * its kind (0 plane: point, normal; 1 sphere: centre, radius; 2 cylinder: centre,\n     \
             * axis, radius, half length; 3 box: centre, rotation row-major, half sizes) and\n     \
             * numbers. Law l: kind (0 spring-dashpot, 1 Hertz, 2 Hunt-Crossley with b = k alpha,\n     \
             * 3 Hunt-Crossley from a restitution), k, then c or the exponent n, b or a, the\n     \
             * friction coefficient, the slip speed. Each pair's record: the normal speed at\n     \
             * which it began to touch (Hunt-Crossley from a restitution damps by it) and\n     \
             * whether it touches, kept by contact_update. */\n    \
             int obstacle_kind[{o}];\n    double obstacle[{o}][{OBSTACLE_LEN}];\n    \
             double law[{l}][{LAW_LEN}];\n    double impact[{np}];\n    unsigned char touching[{np}];\n",
            o = self.obstacles_len(),
            l = self.laws.len().max(1),
            np = self.pairs().max(1),
        )
    }

    pub fn prototypes(&self, p: &str) -> String {
        format!(
            "/* Each contact pair's gap (m, negative: penetrating) and normal force (N) at\n \
             * (t, x). */\n\
             void {p}_contact({p}_model *model, double t, const double *x, double *gap, double *normal);\n\
             /* Bring the pairs' records up to the state x: call it after each accepted step\n \
             * (softarm does where a pair begins or ends to touch). A pair that begins to touch\n \
             * records its speed of approach. */\n\
             void {p}_contact_update({p}_model *model, double t, const double *x);\n"
        )
    }

    /// The support code, the pair tables and the functions (`m` the model).
    pub fn source(&self, p: &str) -> String {
        let slowest = "1e-3 /*SLOWEST_IMPACT*/";
        debug_assert!(SUPPORT.contains(slowest));
        let mut c = SUPPORT.replace(slowest, &literal(SLOWEST_IMPACT));
        c.push('\n');
        let list = |v: Vec<String>| match v.is_empty() {
            true => "0".to_string(),
            false => v.join(", "),
        };
        let pairs = &self.set.pairs;
        let point = pairs.iter().map(|q| q.point.to_string()).collect();
        // An obstacle's index, or -1 - j for point j.
        let other = pairs
            .iter()
            .map(|q| match q.other {
                Against::Obstacle(k) => k.to_string(),
                Against::Point(j) => format!("-{}", j + 1),
            })
            .collect();
        let law = pairs
            .iter()
            .map(|q| self.law_index(&q.law).to_string())
            .collect();
        let radius = self.set.points.iter().map(|q| literal(q.radius)).collect();
        let _ = writeln!(
            c,
            "static const size_t PAIR_POINT[] = {{{}}};\nstatic const int PAIR_OTHER[] = {{{}}};\n\
             static const size_t PAIR_LAW[] = {{{}}};\nstatic const double POINT_RADIUS[] = {{{}}};\n",
            list(point),
            list(other),
            list(law),
            list(radius)
        );
        c.push_str(&self.defaults());
        c.push_str(&self.points_function());
        c.push_str(&self.pair_function());
        c.push_str(&self.force_function());
        c.push_str(&self.public_functions(p));
        c
    }

    fn law_index(&self, law: &Law) -> usize {
        self.laws
            .iter()
            .position(|l| l == law)
            .expect("every pair's law is listed")
    }

    /// `contact_defaults`: the model file's obstacles and laws, no records.
    fn defaults(&self) -> String {
        let mut c = String::from("static void contact_defaults(MODEL *m)\n{\n");
        for (k, o) in self.set.obstacles.iter().enumerate() {
            let (kind, v) = obstacle_numbers(&o.shape);
            let _ = writeln!(c, "    m->obstacle_kind[{k}] = {kind};");
            for (i, x) in v.iter().enumerate() {
                let _ = writeln!(c, "    m->obstacle[{k}][{i}] = {};", literal(*x));
            }
        }
        for (l, law) in self.laws.iter().enumerate() {
            for (i, x) in law_numbers(law).iter().enumerate() {
                let _ = writeln!(c, "    m->law[{l}][{i}] = {};", literal(*x));
            }
        }
        c.push_str("}\n\n");
        c
    }

    /// `contact_points`: every point's p, v and dp/dq into CJAC.
    fn points_function(&self) -> String {
        let frames = 3 * self.points();
        let mut c = String::from(
            "/* Every point's position, velocity and dp/dq (the groups read the contact\n \
             * frames after the positions). */\n\
             static void contact_points(MODEL *m, double t, const double *q, const double *qd)\n{\n    \
             k_contact(t, q, qd, NULL, NULL, m->p, NULL, CPOS, SCRATCH);\n",
        );
        let mut first = 0;
        for (g, &len) in self.info.contact_groups.iter().enumerate() {
            let _ = writeln!(
                c,
                "    k_contact_jacobian_{g}(t, q, qd, NULL, NULL, m->p, CPOS + {frames}, CJAC + {}, SCRATCH);",
                first * self.width()
            );
            first += len;
        }
        c.push_str("}\n\n");
        c
    }

    /// `pair_force`: pair i's gap, normal force, force on its point and
    /// speed of approach (`runtime::contact::pair_force`).
    fn pair_function(&self) -> String {
        format!(
            "static void pair_force(const MODEL *m, size_t i, double *gap, double *f_n, double *force,\n    \
             double *approach)\n{{\n    \
             const double *p = CJAC + PAIR_POINT[i] * {w}, *v = p + 3, *law = m->law[PAIR_LAW[i]];\n    \
             double n[3], v_rel[3], v_t[3], f_t[3], dist, v_n;\n    int o = PAIR_OTHER[i], k;\n    \
             if (o >= 0) {{\n        \
             dist = sa_distance(m->obstacle_kind[o], m->obstacle[o], p, n);\n        \
             for (k = 0; k < 3; k++) v_rel[k] = v[k];\n    }} else {{\n        \
             static const double up[3] = {{0.0, 0.0, 1.0}};\n        \
             const double *b = CJAC + (size_t)(-1 - o) * {w};\n        double rel[3];\n        \
             for (k = 0; k < 3; k++) rel[k] = p[k] - b[k];\n        sa_unit3(rel, up, n);\n        \
             dist = sa_norm3(rel) - POINT_RADIUS[-1 - o];\n        \
             for (k = 0; k < 3; k++) v_rel[k] = v[k] - b[3 + k];\n    }}\n    \
             dist -= POINT_RADIUS[PAIR_POINT[i]];\n    \
             v_n = v_rel[0] * n[0] + v_rel[1] * n[1] + v_rel[2] * n[2];\n    \
             *f_n = sa_normal_force(law, -dist, -v_n, m->impact[i]);\n    \
             for (k = 0; k < 3; k++) v_t[k] = v_rel[k] - v_n * n[k];\n    \
             sa_friction(law, *f_n, v_t, f_t);\n    \
             for (k = 0; k < 3; k++) force[k] = n[k] * *f_n + f_t[k];\n    \
             *gap = dist;\n    *approach = -v_n;\n}}\n\n",
            w = self.width()
        )
    }

    /// `contact_force`: Q_c = sum J^T f into CQ, the pairs in order.
    fn force_function(&self) -> String {
        let (n, pairs, w) = (self.info.dof(), self.pairs(), self.width());
        format!(
            "/* J^T f of point j, times sign, added to out. */\n\
             static void add_jt(const MODEL *m, size_t j, const double *f, double sign, double *out)\n{{\n    \
             size_t c, o;\n    for (c = 0; c < 3; c++)\n        for (o = 0; o < {n}; o++)\n            \
             out[o] += sign * f[c] * CJAC[j * {w} + 6 + c * {n} + o];\n}}\n\n\
             /* h less Q_c: the contact forces are applied forces. */\n\
             static void contact_bias(MODEL *m, double t, const double *q, const double *qd, double *h)\n{{\n    \
             size_t i;\n    double gap, f_n, force[3], approach;\n    \
             contact_points(m, t, q, qd);\n    memset(CQ, 0, {n} * sizeof(double));\n    \
             for (i = 0; i < {pairs}; i++) {{\n        \
             pair_force(m, i, &gap, &f_n, force, &approach);\n        \
             if (f_n == 0.0) continue;\n        add_jt(m, PAIR_POINT[i], force, 1.0, CQ);\n        \
             if (PAIR_OTHER[i] < 0) add_jt(m, (size_t)(-1 - PAIR_OTHER[i]), force, -1.0, CQ);\n    }}\n    \
             for (i = 0; i < {n}; i++) h[i] -= CQ[i];\n}}\n\n"
        )
    }

    fn public_functions(&self, p: &str) -> String {
        let (n, pairs) = (self.info.dof(), self.pairs());
        let restitution = SA_HC_RESTITUTION;
        format!(
            "void {p}_contact({p}_model *m, double t, const double *x, double *gap, double *normal)\n{{\n    \
             size_t i;\n    double force[3], approach;\n    \
             contact_points(m, t, x, x + {n});\n    \
             for (i = 0; i < {pairs}; i++) pair_force(m, i, gap + i, normal + i, force, &approach);\n}}\n\n\
             void {p}_contact_update({p}_model *m, double t, const double *x)\n{{\n    \
             size_t i;\n    double gap, f_n, force[3], approach;\n    \
             contact_points(m, t, x, x + {n});\n    \
             for (i = 0; i < {pairs}; i++) {{\n        int touches;\n        \
             if ((int)m->law[PAIR_LAW[i]][0] != {restitution}) continue;\n        \
             pair_force(m, i, &gap, &f_n, force, &approach);\n        \
             /* Exactly at the surface, the pair touches if it approaches. */\n        \
             touches = gap < 0.0 || (gap == 0.0 && approach > 0.0);\n        \
             if (touches && !m->touching[i]) m->impact[i] = fmax(approach, 0.0);\n        \
             m->touching[i] = (unsigned char)touches;\n    }}\n}}\n\n"
        )
    }
}

/// `SA_HC_RESTITUTION` in contact.c.
const SA_HC_RESTITUTION: usize = 3;

/// An obstacle's kind and numbers as contact.c reads them.
fn obstacle_numbers(shape: &Shape) -> (usize, [f64; OBSTACLE_LEN]) {
    let mut v = [0.0; OBSTACLE_LEN];
    let kind = match shape {
        Shape::Plane { point, normal } => {
            v[..3].copy_from_slice(point);
            v[3..6].copy_from_slice(normal);
            0
        }
        Shape::Sphere { center, radius } => {
            v[..3].copy_from_slice(center);
            v[3] = *radius;
            1
        }
        Shape::Cylinder {
            center,
            axis,
            radius,
            half_length,
        } => {
            v[..3].copy_from_slice(center);
            v[3..6].copy_from_slice(axis);
            v[6] = *radius;
            v[7] = *half_length;
            2
        }
        Shape::Box {
            center,
            rotation,
            half,
        } => {
            v[..3].copy_from_slice(center);
            for (r, row) in rotation.iter().enumerate() {
                v[3 + 3 * r..6 + 3 * r].copy_from_slice(row);
            }
            v[12..].copy_from_slice(half);
            3
        }
    };
    (kind, v)
}

/// A law's numbers as contact.c reads them (an impulse law is refused
/// before: `refusal`).
fn law_numbers(law: &Law) -> [f64; LAW_LEN] {
    let (kind, k, second, third) = match law.normal {
        Normal::SpringDashpot { k, c } => (0, k, c, 0.0),
        Normal::Hertz { k, n } => (1, k, n, 0.0),
        Normal::HuntCrossley {
            k,
            n,
            damping: Damping::Given(b),
        } => (2, k, n, b),
        Normal::HuntCrossley {
            k,
            n,
            damping: Damping::Restitution { a, .. },
        } => (SA_HC_RESTITUTION, k, n, a),
        Normal::Impulse { .. } => unreachable!("the impulse law is refused"),
    };
    [kind as f64, k, second, third, law.friction, law.slip]
}
