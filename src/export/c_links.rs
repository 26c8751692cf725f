//! A chain the link recursion covers, exported as its cells and the
//! recursion (`links.c`) rather than as whole-arm kernels: each distinct
//! cell's value, tangent and pose kernels as C functions, the chain's
//! layout as tables, and the sweeps of `runtime_kernels::links` written
//! once in C. `k_mass_bias`, `k_jvp`, `k_outputs` (and `k_shape` where the
//! links' ends are the shape's rows) are then functions of the recursion
//! with the kernels' signature, so the rest of the library calls them as
//! it calls tapes; a chain of links that own their coordinates takes its
//! state derivative from the articulated-body recursion. The library's size grows with the distinct
//! cells, not with the links times the coordinates (a rom arm's flat
//! kernels are megabytes of C).

use std::fmt::Write;

use runtime::links::{
    ACTUATION_LOADS, CELL_PARAMS, ELEMENT_PARAMS, LinkKernels, MAX_LINK_DOF, REST_PARAMS, cell,
    pose,
};
use runtime::{Tape, TapeSet};

use super::c_tape::{self, literal};

/// The recursion, the same for every chain but its layout.
const RECURSION: &str = include_str!("links.c");

/// Doubles a link's record (links.c's `sa_link`) takes: centroid, force,
/// torque, axis, mass and inertia, four twists a coordinate and its local
/// force, as duals.
const LINK_RECORD: usize = 2 * (15 + 12 * MAX_LINK_DOF + MAX_LINK_DOF);
/// Doubles a link's elimination (links.c's `sa_eliminated`) takes.
const ELIMINATED: usize = 3 * 6 * MAX_LINK_DOF + MAX_LINK_DOF;

/// A chain's export: its link kernels and layout, whether the recursion
/// draws the shape, and whether it gives the state derivative.
pub struct Links<'a> {
    links: &'a LinkKernels,
    dof: usize,
    /// Where each shape row's links end, when the links' ends are the
    /// shape's rows (`with_shape`).
    rows: Option<Vec<usize>>,
    /// The state derivative runs the articulated-body recursion.
    articulated: bool,
}

impl<'a> Links<'a> {
    /// The chain of `tapes`, if the recursion covers it and pays.
    pub fn of(tapes: &'a TapeSet) -> Option<Self> {
        Self::new(tapes.links.as_ref()?, tapes.info.dof())
    }

    /// A chain of `dof` coordinates by `links`, where compiled code takes
    /// M and h from the recursion too (`LinkKernels::mass_bias`: 3D chains
    /// of four links or more, planar ones of 32): a shorter chain's flat
    /// kernels are small, and quicker than the recursion in C as in Rust
    /// (the soft finger's state derivative 5 against 17 us).
    pub fn new(links: &'a LinkKernels, dof: usize) -> Option<Self> {
        // Loads along the arm or on its coordinates, a driven base
        // translation, buoyancy, a section that bends unequally: the flat
        // kernels carry them in C.
        let layout = &links.layout;
        let covered = !layout.loaded()
            && layout.base_translation.is_none()
            && layout.fluid_density.is_none()
            && layout.links.iter().all(|l| l.principal.is_none());
        (links.mass_bias && covered).then_some(Self {
            links,
            dof,
            rows: None,
            articulated: false,
        })
    }

    /// Draw the shape's `rows` (the base and each element's end) by the
    /// recursion, if each element is one link with coordinates, after any
    /// links without (a kink's turn); else the shape stays its own kernel.
    pub fn with_shape(mut self, rows: usize) -> Self {
        let mut ends = vec![0];
        for (k, spec) in self.links.layout.links.iter().enumerate() {
            if !spec.map.is_empty() {
                ends.push(k + 1);
            }
        }
        let covered = ends.last() == Some(&self.links.layout.links.len());
        self.rows = (covered && ends.len() == rows).then_some(ends);
        self
    }

    /// Run the state derivative by the articulated-body recursion where
    /// it applies, as softarm's compiled chains do (links that own their
    /// coordinates, no non-local forces, no inertia that changes with the
    /// coordinates) and `alone`: nothing else needs M (joints, contact,
    /// relaxed forces).
    pub fn with_articulated(mut self, alone: bool) -> Self {
        let layout = &self.links.layout;
        self.articulated = alone
            && runtime::links::all_owned(layout)
            && !layout.forces
            && !layout.variable_inertia;
        self
    }

    /// Whether the state derivative runs the articulated-body recursion.
    pub fn articulated(&self) -> bool {
        self.articulated
    }

    /// Whether the recursion draws the shape.
    pub fn draws_shape(&self) -> bool {
        self.rows.is_some()
    }

    /// The cells' kernels and the chain's own (actuation loads, the
    /// non-local forces' tangent and their energy), by their C names.
    pub fn kernels(&self) -> Vec<(String, &'a Tape)> {
        let l = self.links;
        let mut k = Vec::new();
        let cells = l.cells.iter().zip(&l.tangents).zip(&l.poses);
        for (c, ((one, tangent), pose)) in cells.enumerate() {
            k.push((format!("k_cell_{c}"), one));
            k.push((format!("k_cell_tangent_{c}"), tangent));
            k.push((format!("k_cell_pose_{c}"), pose));
        }
        let own = [
            ("k_links_loads", &l.loads),
            ("k_links_forces_tangent", &l.forces_tangent),
            ("k_links_energy", &l.energy),
        ];
        for (name, tape) in own {
            if let Some(tape) = tape {
                k.push((name.to_string(), tape));
            }
        }
        k
    }

    /// Scratch the recursion's kernels take beyond the cells' own:
    /// `k_mass_bias`'s vectors, the links' records, the loads, a cell's
    /// tangent and the non-local forces with their derivatives.
    pub fn scratch(&self, kernels: usize) -> usize {
        let n = self.dof;
        let layout = &self.links.layout;
        let cells = 2 * cell::len(MAX_LINK_DOF) * layout.links.len();
        // `links_mass`: each link's geometry and its force and torque for
        // each column, the frames' accelerations, wrenches and M.
        let mass = layout.links.len() * (6 + 15 * MAX_LINK_DOF + 6 * n) + 12 * n + n * n;
        let articulated = layout.links.len() * ELIMINATED + 2 * n;
        mass + articulated
            + 5 * n
            + cells
            + layout.links.len() * LINK_RECORD
            + 3 * layout.loads
            + 1
            + 2 * cell::len(MAX_LINK_DOF)
            + 2 * n
            + pose::LEN
            + kernels
    }

    /// The layout's macros and tables, the kernels' dispatch and the
    /// recursion (after the kernels and the workspace macros).
    pub fn source(&self) -> String {
        let mut c = self.layout_tables();
        c.push_str(&self.dispatch());
        c.push_str(RECURSION);
        c
    }

    fn layout_tables(&self) -> String {
        let layout = &self.links.layout;
        let flag = |b: bool| usize::from(b);
        let index = |i: Option<usize>| i.map_or("-1".to_string(), |i| i.to_string());
        let mut c =
            String::from("/* The chain's layout (runtime_kernels::links::LinkLayout). */\n");
        let defines = [
            ("NQ_LINKS", self.dof.to_string()),
            ("LINK_COUNT", layout.links.len().to_string()),
            ("LINK_MAX_DOF", MAX_LINK_DOF.to_string()),
            ("LINK_ELEMENT_PARAMS", ELEMENT_PARAMS.to_string()),
            ("LINK_ACTUATION", ACTUATION_LOADS.to_string()),
            ("LINK_REST_PARAMS", REST_PARAMS.to_string()),
            ("LINK_CELL_PARAMS", CELL_PARAMS.to_string()),
            ("LINK_RECORD", LINK_RECORD.to_string()),
            ("LINK_LOADS", layout.loads.to_string()),
            ("LINK_FORCES", flag(layout.forces).to_string()),
            (
                "VARIABLE_INERTIA",
                flag(layout.variable_inertia).to_string(),
            ),
            (
                "LINK_CELL_LEN(n)",
                format!("({} + 14 * (n))", cell::COLUMNS),
            ),
            ("LINK_ROTATION", cell::ROTATION.to_string()),
            ("LINK_END", cell::END.to_string()),
            ("LINK_OMEGA", cell::OMEGA.to_string()),
            ("LINK_CENTROID", cell::CENTROID.to_string()),
            ("LINK_BODY_OMEGA", cell::BODY_OMEGA.to_string()),
            ("LINK_AXIS", cell::AXIS.to_string()),
            ("LINK_MASS", cell::MASS.to_string()),
            ("LINK_COLUMNS", cell::COLUMNS.to_string()),
            ("LINK_POSE_LEN", pose::LEN.to_string()),
            ("POSE_ROTATION", pose::ROTATION.to_string()),
            ("POSE_END", pose::END.to_string()),
            ("POSE_OMEGA", pose::OMEGA.to_string()),
            ("POSE_CENTROID", pose::CENTROID.to_string()),
            ("POSE_BODY_OMEGA", pose::BODY_OMEGA.to_string()),
            ("POSE_AXIS", pose::AXIS.to_string()),
            ("POSE_MASS", pose::MASS.to_string()),
            ("POSE_QUAT", pose::QUAT.to_string()),
            ("POSE_ENERGY", pose::ENERGY.to_string()),
            ("BASE_ANGLE", index(layout.base_angle)),
            ("TIP_MASS", index(layout.tip_mass)),
            ("TIP_LENGTH", index(layout.tip_length)),
            ("TIP_LATERAL", index(layout.tip_inertia.map(|[l, _]| l))),
            ("TIP_AXIAL", index(layout.tip_inertia.map(|[_, a]| a))),
            ("TIP_FRAME", flag(layout.tip_frame).to_string()),
            ("LINK_ABA", flag(self.articulated()).to_string()),
        ];
        for (name, v) in defines {
            let _ = writeln!(c, "#define {name} {v}");
        }
        let list = |v: &[String]| match v.is_empty() {
            true => "0".to_string(),
            false => v.join(", "),
        };
        let ints = |v: &[usize]| list(&v.iter().map(|i| i.to_string()).collect::<Vec<_>>());
        let three = |t: Option<[usize; 3]>| {
            list(
                &t.map_or([-1i64; 3], |t| t.map(|i| i as i64))
                    .map(|i| i.to_string()),
            )
        };
        match &self.rows {
            Some(rows) => {
                let _ = writeln!(
                    c,
                    "#define LINK_SHAPE 1\n#define LINK_ROWS {}\nstatic const size_t LINK_ROW_FROM[] = {{{}}};",
                    rows.len(),
                    ints(rows)
                );
            }
            None => c.push_str("#define LINK_SHAPE 0\n"),
        }
        let _ = writeln!(
            c,
            "static const int TIP_FORCE[3] = {{{}}};\nstatic const int TIP_MOMENT[3] = {{{}}};\n\
             static const size_t GRAVITY[3] = {{{}}};\nstatic const size_t BASE_POSITION[3] = {{{}}};\n\
             static const size_t BASE_ROTATION[9] = {{{}}};\nstatic const size_t BASE_QUATERNION[4] = {{{}}};",
            three(layout.tip_force),
            three(layout.tip_moment),
            ints(&layout.gravity),
            ints(&layout.base_position),
            ints(&layout.base_rotation),
            ints(&layout.base_quaternion),
        );
        c.push_str(&self.link_tables());
        c
    }

    /// Per link: coordinates, cell, parameters, load; each cell
    /// coordinate's terms (coordinate, weight) and scale.
    fn link_tables(&self) -> String {
        let layout = &self.links.layout;
        let (mut dof, mut cells, mut params, mut load, mut scale, mut terms) =
            (vec![], vec![], vec![], vec![], vec![], vec![]);
        let (mut start, mut coord, mut weight) = (vec!["0".to_string()], vec![], vec![]);
        for spec in &layout.links {
            dof.push(spec.map.len().to_string());
            cells.push(spec.cell.to_string());
            let ids: Vec<String> = spec.params.iter().map(|i| i.to_string()).collect();
            params.push(format!("{{{}}}", ids.join(", ")));
            load.push(spec.load.map_or("-1".into(), |l| l.to_string()));
            let mut sc = vec!["-1".to_string(); MAX_LINK_DOF];
            let mut at = vec!["0".to_string(); MAX_LINK_DOF];
            for (f, local) in spec.map.iter().enumerate() {
                sc[f] = local.scale.map_or("-1".into(), |i| i.to_string());
                at[f] = (start.len() - 1).to_string();
                for &(a, w) in &local.terms {
                    coord.push(a.to_string());
                    weight.push(literal(w));
                }
                start.push(coord.len().to_string());
            }
            scale.push(format!("{{{}}}", sc.join(", ")));
            terms.push(format!("{{{}}}", at.join(", ")));
        }
        // Each coordinate's first link: M's sweep starts its column there.
        let mut first = vec![layout.links.len(); self.dof];
        for (k, spec) in layout.links.iter().enumerate() {
            for &(a, _) in spec.map.iter().flat_map(|c| &c.terms) {
                first[a] = first[a].min(k);
            }
        }
        let first = first.iter().map(|k| k.to_string()).collect();
        let width = ELEMENT_PARAMS + REST_PARAMS;
        let list = |v: Vec<String>| match v.is_empty() {
            true => "0".to_string(),
            false => v.join(", "),
        };
        format!(
            "static const size_t LINK_DOF[] = {{{}}};\nstatic const size_t LINK_CELL[] = {{{}}};\n\
             static const size_t LINK_PARAM[][{width}] = {{{}}};\nstatic const int LINK_LOAD[] = {{{}}};\n\
             static const int LINK_SCALE[][{MAX_LINK_DOF}] = {{{}}};\n\
             static const size_t LINK_TERMS[][{MAX_LINK_DOF}] = {{{}}};\n\
             static const size_t TERM_START[] = {{{}}};\nstatic const size_t TERM_COORD[] = {{{}}};\n\
             static const double TERM_WEIGHT[] = {{{}}};\n\
             static const size_t COORD_FIRST_LINK[] = {{{}}};\n\n",
            list(dof),
            list(cells),
            list(params),
            list(load),
            list(scale),
            list(terms),
            list(start),
            list(coord),
            list(weight),
            list(first),
        )
    }

    /// The cells by index, and the chain's own kernels (nothing where the
    /// chain has none).
    fn dispatch(&self) -> String {
        let l = self.links;
        let (mut one, mut tangent, mut pose) = (String::new(), String::new(), String::new());
        for c in 0..l.tangents.len() {
            let _ = writeln!(
                one,
                "    case {c}: k_cell_{c}(0.0, x, xd, NULL, NULL, p, NULL, out, scratch); break;"
            );
            let _ = writeln!(
                tangent,
                "    case {c}: k_cell_tangent_{c}(0.0, x, xd, NULL, dir, p, NULL, out, scratch); break;"
            );
            let _ = writeln!(
                pose,
                "    case {c}: k_cell_pose_{c}(0.0, x, xd, NULL, NULL, p, NULL, out, scratch); break;"
            );
        }
        let call = |tape: &Option<Tape>, name: &str, args: &str| match tape {
            Some(_) => format!("    {name}({args});\n"),
            None => String::new(),
        };
        let energy = match &l.energy {
            Some(_) => {
                "    double e;\n    k_links_energy(t, q, qd, NULL, NULL, p, NULL, &e, scratch);\n    return e;\n"
            }
            None => "    (void)t; (void)q; (void)qd; (void)p; (void)scratch;\n    return 0.0;\n",
        };
        format!(
            "/* Cell c's outputs. */\n\
             static void cell_one(size_t c, const double *x, const double *xd, const double *p,\n    \
             double *out, double *scratch)\n{{\n    switch (c) {{\n{one}    default: break;\n    }}\n}}\n\n\
             /* Cell c's outputs and their derivatives along dir (the cell coordinates'\n \
             * then their rates'). */\n\
             static void cell_tangent(size_t c, const double *x, const double *xd, const double *dir,\n    \
             const double *p, double *out, double *scratch)\n{{\n    switch (c) {{\n{tangent}    \
             default: break;\n    }}\n}}\n\n\
             static void cell_pose(size_t c, const double *x, const double *xd, const double *p,\n    \
             double *out, double *scratch)\n{{\n    switch (c) {{\n{pose}    default: break;\n    }}\n}}\n\n\
             static void links_loads(double t, const double *q, const double *qd, const double *p,\n    \
             double *out, double *scratch)\n{{\n    \
             (void)t; (void)q; (void)qd; (void)p; (void)out; (void)scratch;\n{loads}}}\n\n\
             static void links_forces_tangent(double t, const double *q, const double *qd,\n    \
             const double *qdd, const double *dir, const double *p, double *out, double *scratch)\n{{\n    \
             (void)t; (void)q; (void)qd; (void)qdd; (void)dir; (void)p; (void)out; (void)scratch;\n{forces}}}\n\n\
             static double links_energy(double t, const double *q, const double *qd, const double *p,\n    \
             double *scratch)\n{{\n{energy}}}\n\n",
            loads = call(
                &l.loads,
                "k_links_loads",
                "t, q, qd, NULL, NULL, p, NULL, out, scratch"
            ),
            forces = call(
                &l.forces_tangent,
                "k_links_forces_tangent",
                "t, q, qd, qdd, dir, p, NULL, out, scratch"
            ),
        )
    }

    /// Scratch the chain's own kernels and cells need (the largest).
    pub fn cells_scratch(&self) -> usize {
        self.kernels()
            .into_iter()
            .map(|(_, tape)| c_tape::scratch(tape))
            .max()
            .unwrap_or(0)
    }
}
