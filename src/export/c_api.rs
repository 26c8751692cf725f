//! The exported library's header and source: named parameters with the
//! model's values as defaults, the kernels, and the functions a caller
//! uses (docs/export.md).

use std::collections::HashSet;
use std::fmt::Write;

use runtime::relaxation::Relaxation;
use runtime::{N_OUTPUTS, OUTPUT_NAMES, Tape, TapeSet};

use super::c_contact::Contact;
use super::c_links::Links;
use super::c_tape::{self, literal};

/// The support code every export carries (special functions, L D L^T).
const SUPPORT: &str = include_str!("support.c");

/// Values a shape row holds: the point, then the section's quaternion.
const SHAPE_ROW: usize = eomgen::shape::ROW;

/// One model's library.
pub struct Library<'a> {
    pub prefix: &'a str,
    pub model: &'a str,
    pub hash: &'a str,
    pub tapes: &'a TapeSet,
    /// The base parameters' values (the defaults).
    pub values: &'a [f64],
    /// Parameters that inputs drive.
    pub inputs: &'a [(usize, String)],
    /// The arm's shape, one point per element (`eomgen::shape`).
    pub shape: &'a Tape,
    /// A viscoelastic model's relaxing groups: their relaxed forces are
    /// states after q and qd.
    pub relax: Option<&'a Relaxation>,
    /// Obstacles, laws and pairs: the contact forces are applied forces.
    pub contact: Option<Contact<'a>>,
    /// A chain the link recursion covers: its cells and the recursion give
    /// M and h, their tangent and the outputs.
    pub links: Option<Links<'a>>,
}

/// A C identifier from any name: other characters become `_`, runs of
/// them one, and a leading digit gets a `_` before it.
pub fn identifier(name: &str) -> String {
    let mut out = String::new();
    for ch in name.chars() {
        let c = if ch.is_ascii_alphanumeric() { ch } else { '_' };
        if !(c == '_' && out.ends_with('_')) {
            out.push(c);
        }
    }
    let out = out.trim_matches('_').to_string();
    match out.chars().next() {
        None => "model".into(),
        Some(c) if c.is_ascii_digit() => format!("_{out}"),
        Some(_) => out,
    }
}

/// Each parameter's field name in the struct: its identifier, made
/// unique by a suffix where two names meet.
fn field_names(names: &[String]) -> Vec<String> {
    let mut seen = HashSet::new();
    names
        .iter()
        .map(|n| {
            let base = identifier(n);
            let mut f = base.clone();
            let mut k = 2;
            while !seen.insert(f.clone()) {
                f = format!("{base}_{k}");
                k += 1;
            }
            f
        })
        .collect()
}

/// `text` with every identifier that starts with `from` starting with
/// `to` instead: the support functions are external (a model need not
/// call all of them, and -Wall warns of an unused static one), named for
/// the model so that two exports link together.
fn with_prefix(text: &str, from: &str, to: &str) -> String {
    let mut out = String::with_capacity(text.len() + text.len() / 8);
    let mut rest = text;
    while let Some(k) = rest.find(from) {
        let (before, after) = rest.split_at(k);
        out.push_str(before);
        let starts = !(out.chars().last()).is_some_and(|c| c.is_ascii_alphanumeric() || c == '_');
        out.push_str(if starts { to } else { from });
        rest = &after[from.len()..];
    }
    out.push_str(rest);
    out
}

impl Library<'_> {
    fn n(&self) -> usize {
        self.tapes.info.dof()
    }
    fn m(&self) -> usize {
        self.tapes.info.constraints.len()
    }
    fn upper(&self) -> String {
        self.prefix.to_ascii_uppercase()
    }
    /// Relaxed forces: n per Prony branch.
    fn nz(&self) -> usize {
        self.relax.map_or(0, |r| r.states(self.n()))
    }
    /// States: q, qd, then the relaxed forces.
    pub fn nx(&self) -> usize {
        2 * self.n() + self.nz()
    }
    /// Contact pairs: the FMU's event indicators are their gaps.
    pub fn contact_pairs(&self) -> usize {
        self.contact.as_ref().map_or(0, |c| c.set.pairs.len())
    }
    fn groups(&self) -> usize {
        self.relax.map_or(0, |r| r.groups.len())
    }

    /// `<prefix>.h`.
    pub fn header(&self) -> String {
        let (p, up) = (self.prefix, self.upper());
        let info = &self.tapes.info;
        let mut h = String::new();
        let _ = write!(
            h,
            "/* {p}.h: the equations of motion of the softarm model \"{model}\" (structure \
             {hash}), exported by softarm {version}. Generated: do not edit; export again.\n \
             * C99 and libm alone. The state is x = (q, qd), then a viscoelastic model's \
             relaxed forces; docs/export.md in softarm explains every function. */\n#ifndef {up}_H\n#define {up}_H\n\n#include <stddef.h>\n\n",
            model = self.model,
            hash = self.hash,
            version = env!("CARGO_PKG_VERSION"),
        );
        let defines = [
            ("NQ", self.n(), "generalised coordinates"),
            ("NX", self.nx(), "states: q, qd, then NRELAXED"),
            (
                "NRELAXED",
                self.nz(),
                "relaxed forces: NQ per Prony branch (0: elastic)",
            ),
            ("NPARAMS", info.parameters.len(), "base parameters"),
            (
                "NOUTPUTS",
                N_OUTPUTS,
                "outputs (tip, energies, tip orientation)",
            ),
            ("NCONSTRAINTS", self.m(), "joint rows (0: no joints)"),
            ("NSHAPE", self.shape.outputs.len() / SHAPE_ROW, "shape rows"),
            ("NINPUTS", self.inputs.len(), "parameters driven by inputs"),
        ];
        let contact = self.contact.iter().flat_map(|c| c.defines());
        for (name, v, what) in defines.into_iter().chain(contact) {
            let _ = writeln!(h, "#define {up}_{name} {v} /* {what} */");
        }
        h.push_str("\n/* The model's parameters, named; ");
        let _ = writeln!(h, "{p}_default_params gives the model file's values. */");
        h.push_str("typedef struct {\n");
        let fields = field_names(&info.parameters);
        for (f, name) in fields.iter().zip(&info.parameters) {
            let _ = writeln!(h, "    double {f}; /* {name} */");
        }
        let _ = writeln!(h, "}} {p}_params;\n");
        let work = self.work_len();
        let ext = info.extended_params().max(1);
        let relaxing = match self.groups() {
            0 => String::new(),
            g => format!(
                "    /* Each relaxing group's parameters with its stiffnesses zeroed. */\n    \
                 double zeroed[{g}][{ext}];\n"
            ),
        };
        let _ = writeln!(
            h,
            "/* Parameters (base, then derived) and workspace: one per thread. */\n\
             typedef struct {{\n    double p[{ext}];\n{relaxing}{contact}    double work[{work}];\n}} {p}_model;\n",
            contact = self.contact.as_ref().map_or(String::new(), |c| c.fields()),
        );
        h.push_str(&self.prototypes());
        let _ = writeln!(h, "\n#endif /* {up}_H */");
        h
    }

    /// Length of the model struct's workspace.
    fn work_len(&self) -> usize {
        let (n, m) = (self.n(), self.m());
        let tri = n * (n + 1) / 2;
        // packed M and h, L, D, the state derivative, a direction, d tau;
        // with joints the constraint rows, X, S, its factors, lambda and
        // the differenced Jacobian's shifted state and its two slopes.
        let base = tri + n + n * n + n + 2 * n + 2 * n + n;
        let joints = m * (n + 2) + m * n + m * (m + 1) / 2 + m * m + m + m;
        let contact: usize = self.contact_work().iter().map(|(_, len)| len).sum();
        base + joints
            + self.relax_work()
            + 3 * self.nx() * self.differenced()
            + contact
            + self.scratch_len()
    }

    /// The contact forces' workspace pieces (none without contact).
    fn contact_work(&self) -> Vec<(&'static str, usize)> {
        self.contact.iter().flat_map(|c| c.work()).collect()
    }

    /// The Jacobian by central differences: with joints, relaxed forces
    /// or contact.
    fn differenced(&self) -> usize {
        usize::from(self.m() > 0 || self.nz() > 0 || self.contact.is_some())
    }

    /// Workspace of the relaxed forces' rates: zero rates, the packed M
    /// and h twice, the group's force.
    fn relax_work(&self) -> usize {
        let (n, tri) = (self.n(), self.n() * (self.n() + 1) / 2);
        match self.nz() {
            0 => 0,
            _ => n + 2 * (tri + n) + n,
        }
    }

    fn prototypes(&self) -> String {
        let p = self.prefix;
        let mut h = String::new();
        let _ = writeln!(
            h,
            "extern const char *const {p}_coordinate_names[];\n\
             extern const char *const {p}_parameter_names[];\n\
             extern const char *const {p}_output_names[];\n\
             /* Indices in the parameters of those that inputs drive (set them each step\n \
             * with {p}_set_parameter); none when NINPUTS is 0. */\n\
             extern const size_t {p}_input_parameters[];\n\n\
             /* The model file's values. */\n\
             void {p}_default_params({p}_params *params);\n\
             /* Bind parameter values: copies them and computes the derived ones. */\n\
             void {p}_init({p}_model *model, const {p}_params *params);\n\
             /* Change parameter i (in {p}_parameter_names' order), an input's at each step. */\n\
             void {p}_set_parameter({p}_model *model, size_t i, double value);\n\
             /* M(q) (NQ x NQ, row-major) and h(t, q, qd), M qdd + h = 0 the equations. */\n\
             void {p}_mass_bias({p}_model *model, double t, const double *q, const double *qd,\n    \
             double *mass, double *bias);\n\
             /* The outputs ({p}_output_names). */\n\
             void {p}_outputs({p}_model *model, double t, const double *q, const double *qd, double *out);\n\
             /* The arm's shape: NSHAPE rows of (x, y, z, qw, qx, qy, qz), each arm's base then\n \
             * its element ends. */\n\
             void {p}_shape({p}_model *model, double t, const double *q, double *out);\n\
             /* The directional derivative of tau = M qdd + h along (dq, dqd) at qdd. */\n\
             void {p}_inverse_dynamics_jvp({p}_model *model, double t, const double *q,\n    \
             const double *qd, const double *qdd, const double *dq, const double *dqd, double *dtau);\n\
             /* dx = f(t, x). Returns 0, 1 when M is not positive definite, 2 when the joints\n \
             * are dependent. */\n\
             int {p}_state_derivative({p}_model *model, double t, const double *x, double *dx);"
        );
        let _ = writeln!(
            h,
            "/* df/dx (NX x NX, row-major); returns as {p}_state_derivative. Exact without\n \
             * joints or relaxed forces; with them by central differences of the state\n \
             * derivative. */\n\
             int {p}_state_jacobian({p}_model *model, double t, const double *x, double *jac);"
        );
        if self.m() > 0 {
            let _ = writeln!(
                h,
                "/* The joints phi(q) = 0: phi (NCONSTRAINTS), J = dphi/dq (NCONSTRAINTS x NQ,\n \
                 * row-major), gamma = (dJ/dt) qd (NCONSTRAINTS). */\n\
                 void {p}_constraints({p}_model *model, double t, const double *q, const double *qd,\n    \
                 double *phi, double *jac, double *gamma);"
            );
        }
        if let Some(c) = &self.contact {
            h.push_str(&c.prototypes(p));
        }
        h
    }

    /// After `k_mass_bias` into PACKED: h less the contact forces.
    fn contact_bias(&self) -> String {
        let tri = self.n() * (self.n() + 1) / 2;
        match self.contact {
            Some(_) => format!("    contact_bias(m, t, q, qd, PACKED + {tri});\n"),
            None => String::new(),
        }
    }

    /// The kernels by their C names.
    fn kernels(&self) -> Vec<(String, &Tape)> {
        let t = self.tapes;
        let mut kernels: Vec<(String, &Tape)> = vec![("k_derived".into(), &t.derived)];
        match &self.links {
            Some(links) => kernels.extend(links.kernels()),
            None => kernels.extend(
                [
                    ("k_mass_bias", &t.mass_bias),
                    ("k_outputs", &t.outputs),
                    ("k_jvp", &t.jvp),
                ]
                .map(|(name, tape)| (name.to_string(), tape)),
            ),
        }
        if !self.links.as_ref().is_some_and(|l| l.draws_shape()) {
            kernels.push(("k_shape".into(), self.shape));
        }
        if self.m() > 0 {
            kernels.push(("k_constraints".into(), &t.constraints));
        }
        if let Some(c) = &self.contact {
            kernels.extend(c.kernels(t));
        }
        kernels
    }

    /// Scratch values the table kernels need (the largest one's).
    fn scratch_len(&self) -> usize {
        let sizes = self
            .kernels()
            .into_iter()
            .map(|(_, tape)| c_tape::scratch(tape));
        let tapes = sizes.max().unwrap_or(0);
        let recursion = (self.links.as_ref()).map_or(0, |l| l.scratch(l.cells_scratch()));
        tapes.max(recursion).max(1)
    }

    /// `<prefix>.c`.
    pub fn source(&self) -> String {
        let p = self.prefix;
        let mut c = format!(
            "/* {p}.c: the equations of motion of the softarm model \"{}\" (structure {}).\n \
             * Generated by `softarm export`: do not edit. C99 and libm alone. */\n\
             #include \"{p}.h\"\n\n#include <float.h>\n#include <math.h>\n#include <stddef.h>\n#include <string.h>\n\n",
            self.model, self.hash
        );
        // 1/n! as literals: the series' coefficients, exact to the last bit.
        let mut f = 1.0_f64;
        let inv: Vec<String> = (0..48)
            .map(|n| {
                if n > 0 {
                    f *= n as f64;
                }
                literal(1.0 / f)
            })
            .collect();
        // The support functions' names get the model's prefix in the code
        // alone: the name tables and the parameters' fields are the
        // model's own words, which no rewrite may touch.
        let own = |code: &str| with_prefix(code, "sa_", &format!("{p}_sa_"));
        let mut code = SUPPORT.replace("/*INV_FACTORIALS*/", &inv.join(", "));
        code.push('\n');
        for (name, tape) in self.kernels() {
            code.push_str(&c_tape::kernel(&name, tape));
            code.push('\n');
        }
        if let Some(links) = &self.links {
            code.push_str(&links.source());
        }
        code.push_str(&self.workspace_macros());
        if let Some(contact) = &self.contact {
            let _ = writeln!(code, "#define MODEL {p}_model\n");
            code.push_str(&contact.source(p));
        }
        c.push_str(&own(&code));
        c.push_str(&self.names());
        c.push_str(&self.parameter_functions());
        c.push_str(&own(&self.dynamics_functions()));
        c
    }

    /// A template of the support code (`fmi2.c`, `mex.c`) with this
    /// model's names: `PFXU_` its macros' prefix, `PFX_` its functions',
    /// `PFX` its file and identifier.
    pub fn named(&self, template: &str) -> String {
        let p = self.prefix;
        template
            .replace("PFXU_", &format!("{}_", p.to_ascii_uppercase()))
            .replace("PFX_", &format!("{p}_"))
            .replace("PFX", p)
    }

    /// The name tables.
    fn names(&self) -> String {
        let p = self.prefix;
        let info = &self.tapes.info;
        let quoted = |v: &[String]| {
            let items: Vec<String> = v
                .iter()
                .map(|s| format!("\"{}\"", s.escape_default()))
                .collect();
            if items.is_empty() {
                "\"\"".to_string()
            } else {
                items.join(", ")
            }
        };
        let outputs: Vec<String> = OUTPUT_NAMES.iter().map(|s| s.to_string()).collect();
        let inputs: Vec<String> = self.inputs.iter().map(|(i, _)| i.to_string()).collect();
        format!(
            "const char *const {p}_coordinate_names[] = {{{}}};\n\
             const char *const {p}_parameter_names[] = {{{}}};\n\
             const char *const {p}_output_names[] = {{{}}};\n\
             const size_t {p}_input_parameters[] = {{{}}};\n\n",
            quoted(&info.coordinates),
            quoted(&info.parameters),
            quoted(&outputs),
            if inputs.is_empty() {
                "0".into()
            } else {
                inputs.join(", ")
            },
        )
    }

    /// Defaults, binding and changing parameters.
    fn parameter_functions(&self) -> String {
        let p = self.prefix;
        let info = &self.tapes.info;
        let fields = field_names(&info.parameters);
        let mut c = format!("void {p}_default_params({p}_params *v)\n{{\n");
        for (f, &v) in fields.iter().zip(self.values) {
            let _ = writeln!(c, "    v->{f} = {};", literal(v));
        }
        c.push_str("}\n\n");
        let np = info.parameters.len();
        let mut zeroed = String::new();
        for (g, group) in self.relax.iter().flat_map(|r| r.groups.iter()).enumerate() {
            let _ = writeln!(
                zeroed,
                "    memcpy(m->zeroed[{g}], m->p, {np} * sizeof(double));"
            );
            for &i in &group.stiffness {
                let _ = writeln!(zeroed, "    m->zeroed[{g}][{i}] = 0.0;");
            }
            let _ = writeln!(
                zeroed,
                "    k_derived(0.0, NULL, NULL, NULL, NULL, m->zeroed[{g}], NULL, m->zeroed[{g}] + {np}, SCRATCH);"
            );
        }
        let _ = writeln!(
            c,
            "/* The derived parameters after the base ones (and each relaxing group's\n \
             * parameters without its stiffnesses). */\n\
             static void derive_params({p}_model *m)\n{{\n    \
             k_derived(0.0, NULL, NULL, NULL, NULL, m->p, NULL, m->p + {np}, SCRATCH);\n{zeroed}}}\n"
        );
        let _ = writeln!(c, "void {p}_init({p}_model *m, const {p}_params *v)\n{{");
        c.push_str("    memset(m, 0, sizeof *m);\n");
        if self.contact.is_some() {
            c.push_str("    contact_defaults(m);\n");
        }
        for (i, f) in fields.iter().enumerate() {
            let _ = writeln!(c, "    m->p[{i}] = v->{f};");
        }
        c.push_str("    derive_params(m);\n}\n\n");
        let _ = writeln!(
            c,
            "void {p}_set_parameter({p}_model *m, size_t i, double value)\n{{\n    \
             if (i < {}) {{\n        m->p[i] = value;\n        derive_params(m);\n    }}\n}}\n",
            info.parameters.len()
        );
        c
    }

    /// Mass and bias, outputs, shape, the state derivative and its
    /// Jacobian (or the joints' rows).
    fn dynamics_functions(&self) -> String {
        let (p, n, m) = (self.prefix, self.n(), self.m());
        let tri = n * (n + 1) / 2;
        let mut c = String::new();
        let _ = writeln!(
            c,
            "void {p}_mass_bias({p}_model *m, double t, const double *q, const double *qd,\n    \
             double *mass, double *bias)\n{{\n    size_t i, j;\n    \
             k_mass_bias(t, q, qd, NULL, NULL, m->p, NULL, PACKED, SCRATCH);\n{contact}    \
             for (i = 0; i < {n}; i++) {{\n        bias[i] = PACKED[{tri} + i];\n        \
             for (j = i; j < {n}; j++)\n            \
             mass[i * {n} + j] = mass[j * {n} + i] = PACKED[sa_packed({n}, i, j)];\n    }}\n}}\n\n\
             void {p}_outputs({p}_model *m, double t, const double *q, const double *qd, double *out)\n{{\n    \
             k_outputs(t, q, qd, NULL, NULL, m->p, NULL, out, SCRATCH);\n}}\n\n\
             void {p}_shape({p}_model *m, double t, const double *q, double *out)\n{{\n    \
             k_shape(t, q, NULL, NULL, NULL, m->p, NULL, out, SCRATCH);\n}}\n\n\
             void {p}_inverse_dynamics_jvp({p}_model *m, double t, const double *q,\n    \
             const double *qd, const double *qdd, const double *dq, const double *dqd, double *dtau)\n{{\n    \
             memcpy(DIR, dq, {n} * sizeof(double));\n    \
             memcpy(DIR + {n}, dqd, {n} * sizeof(double));\n    \
             k_jvp(t, q, qd, qdd, DIR, m->p, NULL, dtau, SCRATCH);\n}}\n",
            contact = self.contact_bias(),
        );
        c.push_str(&self.relaxed_rates());
        c.push_str(&self.state_derivative());
        if self.differenced() == 0 {
            c.push_str(&self.state_jacobian());
        } else {
            c.push_str(&self.differenced_jacobian());
        }
        if m > 0 {
            let _ = writeln!(
                c,
                "void {p}_constraints({p}_model *m, double t, const double *q, const double *qd,\n    \
                 double *phi, double *jac, double *gamma)\n{{\n    \
                 k_constraints(t, q, qd, NULL, NULL, m->p, NULL, ROWS, SCRATCH);\n    \
                 memcpy(phi, ROWS, {m} * sizeof(double));\n    \
                 memcpy(jac, ROWS + {m}, {mn} * sizeof(double));\n    \
                 memcpy(gamma, ROWS + {m} + {mn}, {m} * sizeof(double));\n}}\n",
                mn = m * n
            );
        }
        c
    }

    /// Names for the workspace's pieces (laid out as `work_len` counts).
    fn workspace_macros(&self) -> String {
        let (n, m) = (self.n(), self.m());
        let tri = n * (n + 1) / 2;
        let pieces = [
            ("PACKED", tri + n),
            ("LOWER", n * n),
            ("PIVOTS", n),
            ("DX", 2 * n),
            ("DIR", 2 * n),
            ("DTAU", n),
            ("ROWS", m * (n + 2)),
            ("XCOLS", m * n),
            ("SCHUR", m * (m + 1) / 2),
            ("SLOWER", m * m),
            ("SPIVOTS", m),
            ("LAMBDA", m),
            ("ZEROS", n * self.nz().min(1)),
            ("GWITH", (tri + n) * self.nz().min(1)),
            ("GWITHOUT", (tri + n) * self.nz().min(1)),
            ("GFORCE", n * self.nz().min(1)),
            ("SHIFTED", self.nx() * self.differenced()),
            ("PLUS", self.nx() * self.differenced()),
            ("MINUS", self.nx() * self.differenced()),
            ("SCRATCH", self.scratch_len()),
        ];
        let mut c = String::new();
        let mut at = 0;
        for (name, len) in pieces.into_iter().chain(self.contact_work()) {
            let _ = writeln!(c, "#define {name} (m->work + {at})");
            at += len;
        }
        debug_assert_eq!(at, self.work_len());
        c.push('\n');
        c
    }

    /// Whether the state derivative is the articulated-body recursion's
    /// (`Links::with_articulated`).
    fn articulated(&self) -> bool {
        self.links.as_ref().is_some_and(|l| l.articulated())
    }

    /// dx = (qd, qdd): L D L^T of M, then the joints' Schur complement; or
    /// the articulated-body recursion.
    fn state_derivative(&self) -> String {
        let (p, n, m) = (self.prefix, self.n(), self.m());
        if self.articulated() {
            return format!(
                "int {p}_state_derivative({p}_model *m, double t, const double *x, double *dx)\n{{\n    \
                 size_t i;\n    for (i = 0; i < {n}; i++) dx[i] = x[{n} + i];\n    \
                 return links_accelerations(t, x, x + {n}, m->p, dx + {n}, SCRATCH) ? 0 : 1;\n}}\n\n"
            );
        }
        let tri = n * (n + 1) / 2;
        let mut c = format!(
            "int {p}_state_derivative({p}_model *m, double t, const double *x, double *dx)\n{{\n    \
             const double *q = x, *qd = x + {n};\n    size_t i;\n    \
             k_mass_bias(t, q, qd, NULL, NULL, m->p, NULL, PACKED, SCRATCH);\n{contact}    \
             if (sa_ldlt_factor({n}, PACKED, LOWER, PIVOTS)) return 1;\n    \
             for (i = 0; i < {n}; i++) {{\n        dx[i] = qd[i];\n        \
             dx[{n} + i] = -PACKED[{tri} + i];\n    }}\n{relaxed}    \
             sa_ldlt_solve({n}, LOWER, PIVOTS, dx + {n});\n",
            contact = self.contact_bias(),
            relaxed = match self.nz() {
                0 => String::new(),
                nz => format!(
                    "    /* M qdd + h = the relaxed forces' sum; their rates. */\n    \
                     for (i = 0; i < {nz}; i++) dx[{n} + i % {n}] += x[{x0} + i];\n    \
                     relaxed_rates(m, t, q, x + {x0}, dx + {x0});\n",
                    x0 = 2 * n
                ),
            }
        );
        if m > 0 {
            let _ = write!(
                c,
                "    {{\n        /* qdd = a0 - X lambda, X = M^-1 J^T, (J X) lambda = J a0 + gamma. */\n        \
                 const double *jac = ROWS + {m}, *gamma = ROWS + {m} + {mn};\n        \
                 size_t r, s, k = 0;\n        \
                 k_constraints(t, q, qd, NULL, NULL, m->p, NULL, ROWS, SCRATCH);\n        \
                 for (r = 0; r < {m}; r++) {{\n            \
                 memcpy(XCOLS + r * {n}, jac + r * {n}, {n} * sizeof(double));\n            \
                 sa_ldlt_solve({n}, LOWER, PIVOTS, XCOLS + r * {n});\n        }}\n        \
                 for (r = 0; r < {m}; r++) {{\n            double v = gamma[r];\n            \
                 for (s = r; s < {m}; s++) {{\n                double d = 0.0;\n                \
                 for (i = 0; i < {n}; i++) d += jac[r * {n} + i] * XCOLS[s * {n} + i];\n                \
                 SCHUR[k++] = d;\n            }}\n            \
                 for (i = 0; i < {n}; i++) v += jac[r * {n} + i] * dx[{n} + i];\n            \
                 LAMBDA[r] = v;\n        }}\n        \
                 if (sa_ldlt_factor({m}, SCHUR, SLOWER, SPIVOTS)) return 2;\n        \
                 sa_ldlt_solve({m}, SLOWER, SPIVOTS, LAMBDA);\n        \
                 for (r = 0; r < {m}; r++)\n            \
                 for (i = 0; i < {n}; i++) dx[{n} + i] -= LAMBDA[r] * XCOLS[r * {n} + i];\n    }}\n",
                mn = m * n
            );
        }
        c.push_str("    return 0;\n}\n\n");
        c
    }

    /// With joints or relaxed forces, df/dx by central differences of the
    /// state derivative, with softarm's steps (`runtime::jacobian`):
    /// cbrt(eps) max(|x_j|, 1); the rows of q' = qd exact.
    fn differenced_jacobian(&self) -> String {
        let (p, n) = (self.prefix, self.n());
        format!(
            "int {p}_state_jacobian({p}_model *m, double t, const double *x, double *jac)\n{{\n    \
             size_t i, j;\n    int status = {p}_state_derivative(m, t, x, DX);\n    \
             if (status) return status;\n    \
             memset(jac, 0, {nx} * {nx} * sizeof(double));\n    \
             for (i = 0; i < {n}; i++) jac[i * {nx} + {n} + i] = 1.0;\n    \
             memcpy(SHIFTED, x, {nx} * sizeof(double));\n    \
             for (j = 0; j < {nx}; j++) {{\n        \
             double step = cbrt(DBL_EPSILON) * fmax(fabs(x[j]), 1.0);\n        \
             SHIFTED[j] = x[j] + step;\n        \
             if ((status = {p}_state_derivative(m, t, SHIFTED, PLUS))) return status;\n        \
             SHIFTED[j] = x[j] - step;\n        \
             if ((status = {p}_state_derivative(m, t, SHIFTED, MINUS))) return status;\n        \
             SHIFTED[j] = x[j];\n        \
             for (i = {n}; i < {nx}; i++)\n            \
             jac[i * {nx} + j] = (PLUS[i] - MINUS[i]) / (2.0 * step);\n    }}\n    \
             return 0;\n}}\n",
            nx = self.nx()
        )
    }

    /// A viscoelastic model's relaxed forces' rates (`runtime::relaxation`):
    /// each group's elastic force f_g = h(q, 0) less h(q, 0) with its
    /// stiffnesses zeroed, then time_k z_k' = ratio_k f_g - z_k for each of
    /// its branches, in the groups' order.
    fn relaxed_rates(&self) -> String {
        let Some(relax) = self.relax else {
            return String::new();
        };
        let (n, tri) = (self.n(), self.n() * (self.n() + 1) / 2);
        let mut c = format!(
            "static void relaxed_rates({p}_model *m, double t, const double *q, const double *z,\n    \
             double *dz)\n{{\n    size_t i;\n    \
             k_mass_bias(t, q, ZEROS, NULL, NULL, m->p, NULL, GWITH, SCRATCH);\n",
            p = self.prefix
        );
        let mut k = 0;
        for (g, group) in relax.groups.iter().enumerate() {
            let _ = writeln!(
                c,
                "    k_mass_bias(t, q, ZEROS, NULL, NULL, m->zeroed[{g}], NULL, GWITHOUT, SCRATCH);\n    \
                 for (i = 0; i < {n}; i++) GFORCE[i] = GWITH[{tri} + i] - GWITHOUT[{tri} + i];"
            );
            for b in &group.branches {
                let _ = writeln!(
                    c,
                    "    for (i = 0; i < {n}; i++)\n        \
                     dz[{at} + i] = ({ratio} * GFORCE[i] - z[{at} + i]) / {time};",
                    at = k * n,
                    ratio = literal(b.ratio),
                    time = literal(b.time),
                );
                k += 1;
            }
        }
        c.push_str("}\n\n");
        c
    }

    /// df/dx: [0 I; dqdd/dq dqdd/dqd], dqdd = -M^-1 d tau column by column.
    fn state_jacobian(&self) -> String {
        let (p, n) = (self.prefix, self.n());
        format!(
            "int {p}_state_jacobian({p}_model *m, double t, const double *x, double *jac)\n{{\n    \
             const double *q = x, *qd = x + {n};\n    size_t i, col;\n    \
             int status = {p}_state_derivative(m, t, x, DX);\n    \
             if (status) return status;\n{factor}    \
             memset(jac, 0, {nx} * {nx} * sizeof(double));\n    \
             for (i = 0; i < {n}; i++) jac[i * {nx} + {n} + i] = 1.0;\n    \
             for (col = 0; col < {nx}; col++) {{\n        \
             memset(DIR, 0, {nx} * sizeof(double));\n        DIR[col] = 1.0;\n        \
             k_jvp(t, q, qd, DX + {n}, DIR, m->p, NULL, DTAU, SCRATCH);\n        \
             for (i = 0; i < {n}; i++) DTAU[i] = -DTAU[i];\n        \
             sa_ldlt_solve({n}, LOWER, PIVOTS, DTAU);\n        \
             for (i = 0; i < {n}; i++) jac[({n} + i) * {nx} + col] = DTAU[i];\n    }}\n    \
             return 0;\n}}\n",
            nx = 2 * n,
            // The articulated state derivative forms no M: factor it here.
            factor = match self.articulated() {
                true => format!(
                    "    k_mass_bias(t, q, qd, NULL, NULL, m->p, NULL, PACKED, SCRATCH);\n    \
                     if (sa_ldlt_factor({n}, PACKED, LOWER, PIVOTS)) return 1;\n"
                ),
                false => String::new(),
            },
        )
    }
}
