//! Compiled cells linked at run time: a chain whose element count (or rom
//! order) no compiled-in model has runs the link recursion over the
//! compiled cells (`links::CompiledCell`) of the same link shapes, found by
//! their keys. The cell is what is compiled; the count is the layout's, a
//! runtime value, so `--set segment.0.elements=20` on a bundled 10-element
//! arm needs neither a rebuild nor the interpreter. An arm with contact
//! takes its contact kernels (and the derived parameters they read) from
//! its tapes: the recursion covers M, h and their tangent, the costly part.
//! A link shape no compiled-in model has (a pre-curved rod's, a kink's)
//! runs on its cell's tapes, the rest of the chain compiled.

use std::cell::RefCell;

use crate::kernels::{Interpreted, KernelKind, Kernels, ModelInfo, TapeSet};
use crate::linalg::Ldlt;
use crate::links::{
    self, Cells, CompiledCell, LinkKernels, accelerations_owned, all_owned, by_lanes,
    inverse_dynamics_tangent, mass_bias_owned, mass_bias_shared_dyn, outputs,
};
use crate::tape::{Inputs, Tape};

/// The kernels of a chain by the link recursion over linked compiled
/// cells: `MassBias`, `Jvp` and `Outputs`; the few kernels of the
/// parameters or of the whole arm's coordinates that a layout may have
/// (a rom segment's forces, the actuation loads) by their tapes, and the
/// rest (contact, derived parameters) by the arm's interpreted tapes.
pub struct LinkedKernels {
    info: ModelInfo,
    links: LinkKernels,
    cells: Vec<Option<CompiledCell>>,
    slots: RefCell<Vec<f64>>,
    rest: Option<Interpreted>,
    /// Each contact point's group (`ModelInfo::contact_groups`).
    group_of: Vec<usize>,
    /// The links' cells at the state the contact kernels last ran at.
    kept: RefCell<links::LinkOutputs>,
    /// The actuation loads at the parameters they were last taken at:
    /// every sweep of a right-hand side reads them, its tape runs once.
    kept_loads: RefCell<KeptLoads>,
}

/// The actuation loads kernel's values at the parameters `p`.
#[derive(Default)]
struct KeptLoads {
    p: Vec<f64>,
    values: Vec<f64>,
}

impl LinkedKernels {
    /// `cells[c]` is the compiled cell of `links.cells[c]`, or None where
    /// no compiled-in model has it: its tapes then run.
    pub fn new(info: ModelInfo, links: LinkKernels, cells: Vec<Option<CompiledCell>>) -> Self {
        assert_eq!(cells.len(), links.cells.len(), "one compiled cell a cell");
        let mut info = info;
        if contact_by_links(&links, &info) {
            // The recursion's contact kernels read no frames but the
            // bounds of its groups, where it has them.
            let groups = &info.contact_groups;
            info.contact_frames = match links::has_contact_bounds(&links.layout, groups) {
                true => links::CONTACT_BOUND * groups.len(),
                false => 0,
            };
        }
        let group_of = (info.contact_groups.iter().enumerate())
            .flat_map(|(g, &len)| std::iter::repeat_n(g, len))
            .collect();
        Self {
            group_of,
            kept: RefCell::new(links::LinkOutputs::default()),
            kept_loads: RefCell::new(KeptLoads::default()),
            info,
            links,
            cells,
            slots: RefCell::new(Vec::new()),
            rest: None,
        }
    }

    /// The chain of `tapes` (its `links`) on `cells`, the kernels the
    /// recursion does not give (contact, derived parameters) by `tapes`;
    /// `None` when the tapes have no link recursion. M and h come from the
    /// recursion and the mass solve, never the tapes' symbolic solve.
    pub fn with_tapes(tapes: TapeSet, cells: Vec<Option<CompiledCell>>) -> Option<Self> {
        let links = tapes.links.clone()?;
        let info = ModelInfo {
            accel: false,
            ..tapes.info.clone()
        };
        let mut linked = Self::new(info, links, cells);
        linked.rest = Some(Interpreted::new(tapes));
        Some(linked)
    }
}

/// Whether the recursion gives the chain's contact kernels: its layout
/// places every contact point on a link.
fn contact_by_links(links: &LinkKernels, info: &ModelInfo) -> bool {
    info.contact_points > 0 && links.layout.contact.len() == info.contact_points
}

struct Linked<'a> {
    links: &'a LinkKernels,
    cells: &'a [Option<CompiledCell>],
    inp: Inputs<'a>,
    slots: &'a mut Vec<f64>,
    kept_loads: &'a RefCell<KeptLoads>,
}

/// A cell's tape at its coordinates `x`, rates `xd`, parameters `p` and
/// direction `dir` (the tangent's).
fn cell_by_tape(
    tape: &Tape,
    (x, xd, dir, p): (&[f64], &[f64], &[f64], &[f64]),
    slots: &mut Vec<f64>,
    out: &mut [f64],
) {
    let inp = Inputs {
        t: 0.0,
        q: x,
        qd: xd,
        qdd: &[],
        dir,
        p,
        aux: &[],
    };
    tape.eval(&inp, slots, out)
}

/// A kernel of the layout's own by its tape.
fn by_tape(tape: &Option<Tape>, what: &str, inp: &Inputs, slots: &mut Vec<f64>, out: &mut [f64]) {
    let tape = tape
        .as_ref()
        .unwrap_or_else(|| panic!("the layout asks for its {what} kernel"));
    tape.eval(inp, slots, out);
}

impl Cells for Linked<'_> {
    fn one(&mut self, c: usize, x: &[f64], xd: &[f64], p: &[f64], out: &mut [f64]) {
        match &self.cells[c] {
            Some(cell) => (cell.one)(x, xd, p, out),
            None => cell_by_tape(&self.links.cells[c], (x, xd, &[], p), self.slots, out),
        }
    }

    fn four(
        &mut self,
        c: usize,
        x: &[[f64; 4]],
        xd: &[[f64; 4]],
        p: &[[f64; 4]],
        out: &mut [[f64; 4]],
    ) {
        match &self.cells[c] {
            Some(CompiledCell {
                four: Some(four), ..
            }) => four(x, xd, p, out),
            Some(cell) => by_lanes(cell.one, x, xd, p, out),
            None => {
                let (tape, slots) = (&self.links.cells[c], &mut *self.slots);
                by_lanes(
                    |x, xd, p, out| cell_by_tape(tape, (x, xd, &[], p), slots, out),
                    x,
                    xd,
                    p,
                    out,
                )
            }
        }
    }

    fn forces(&mut self, out: &mut [f64]) {
        by_tape(&self.links.forces, "forces", &self.inp, self.slots, out)
    }

    fn tangent(
        &mut self,
        c: usize,
        x: &[f64],
        xd: &[f64],
        dx: &[f64],
        dxd: &[f64],
        p: &[f64],
        out: &mut [f64],
    ) {
        match &self.cells[c] {
            Some(cell) => (cell.tangent)(x, xd, dx, dxd, p, out),
            None => {
                let dir: Vec<f64> = dx.iter().chain(dxd).copied().collect();
                cell_by_tape(&self.links.tangents[c], (x, xd, &dir, p), self.slots, out)
            }
        }
    }

    fn forces_tangent(&mut self, dir: &[f64], out: &mut [f64]) {
        let inp = Inputs { dir, ..self.inp };
        by_tape(
            &self.links.forces_tangent,
            "forces' tangent",
            &inp,
            self.slots,
            out,
        )
    }

    fn loads(&mut self, out: &mut [f64]) {
        let mut kept = self.kept_loads.borrow_mut();
        let p = self.inp.p;
        let same = kept.p.len() == p.len()
            && kept.values.len() == out.len()
            && links::bits_equal(&kept.p, p);
        if !same {
            by_tape(&self.links.loads, "loads", &self.inp, self.slots, out);
            kept.p.clear();
            kept.p.extend_from_slice(p);
            kept.values.clear();
            kept.values.extend_from_slice(out);
        }
        out.copy_from_slice(&kept.values);
    }

    fn pose(&mut self, c: usize, x: &[f64], xd: &[f64], p: &[f64], out: &mut [f64]) {
        match &self.cells[c] {
            Some(cell) => (cell.pose)(x, xd, p, out),
            None => cell_by_tape(&self.links.poses[c], (x, xd, &[], p), self.slots, out),
        }
    }

    fn energy(&mut self) -> f64 {
        let mut out = [0.0];
        by_tape(
            &self.links.energy,
            "energy",
            &self.inp,
            self.slots,
            &mut out,
        );
        out[0]
    }
}

impl Kernels for LinkedKernels {
    fn info(&self) -> &ModelInfo {
        &self.info
    }

    fn eval(&self, kind: KernelKind, inp: &Inputs, out: &mut [f64]) {
        crate::cpu::require_fma();
        // SAFETY: `require_fma` has checked that the processor has FMA.
        unsafe { self.eval_fma(kind, inp, out) }
    }

    fn backend(&self) -> &'static str {
        "compiled"
    }

    fn solve_mass(&self, packed: &[f64], b: &mut [f64], ws: &mut Ldlt) -> bool {
        crate::cpu::require_fma();
        // SAFETY: `require_fma` has checked that the processor has FMA.
        unsafe { solve_fma(packed, b, ws) }
    }

    fn contact_bounds(&self, inp: &Inputs, out: &mut [f64]) -> bool {
        if self.info.contact_frames == 0 || !contact_by_links(&self.links, &self.info) {
            return false;
        }
        crate::cpu::require_fma();
        // SAFETY: `require_fma` has checked that the processor has FMA.
        unsafe { self.bounds_fma(inp, out) };
        true
    }

    fn frames(&self, inp: &Inputs, which: &[links::ArmFrame], out: &mut [f64]) -> bool {
        crate::cpu::require_fma();
        // SAFETY: `require_fma` has checked that the processor has FMA.
        unsafe { self.frames_fma(inp, which, out) };
        true
    }

    fn accelerations(&self, inp: &Inputs, qdd: &mut [f64]) -> Option<bool> {
        let layout = &self.links.layout;
        if !layout.direct_accelerations() {
            return None;
        }
        crate::cpu::require_fma();
        // SAFETY: `require_fma` has checked that the processor has FMA.
        Some(unsafe { self.accelerations_fma(inp, qdd) })
    }
}

/// The L D L^T solve built for FMA.
#[cfg_attr(target_arch = "x86_64", target_feature(enable = "fma"))]
unsafe fn solve_fma(packed: &[f64], b: &mut [f64], ws: &mut Ldlt) -> bool {
    if !ws.factor_fma(packed) {
        return false;
    }
    ws.solve_fma(b);
    true
}

impl LinkedKernels {
    /// A contact kernel by the recursion: `ContactJacobian` for the
    /// groups `dir` selects (empty: every group), `ContactJvp` along the
    /// first n of `dir`.
    #[inline(always)]
    fn contact(&self, kind: KernelKind, cells: &mut Linked, inp: &Inputs, out: &mut [f64]) {
        let layout = &self.links.layout;
        let state = (inp.q, inp.qd, inp.p);
        let mut kept = self.kept.borrow_mut();
        let kept = &mut *kept;
        match kind {
            KernelKind::Contact => {
                links::contact_points(layout, (cells, kept), state, out);
                let (groups, points) = (&self.info.contact_groups, 3 * self.info.contact_points);
                if self.info.contact_frames > 0 {
                    let out = &mut out[points..];
                    links::contact_bounds(layout, (cells, kept), state, groups, out);
                }
            }
            KernelKind::ContactJacobian => {
                let mask = inp.dir;
                let want = |i: usize| mask.is_empty() || mask[self.group_of[i]] != 0.0;
                links::contact_jacobian(layout, (cells, kept), state, want, out)
            }
            _ => links::contact_jvp(layout, cells, state, &inp.dir[..layout.dof], out),
        }
    }

    /// The cells of this chain at `inp`, its tapes' scratch in `slots`.
    #[inline(always)]
    fn linked<'a>(&'a self, inp: &Inputs<'a>, slots: &'a mut Vec<f64>) -> Linked<'a> {
        Linked {
            links: &self.links,
            cells: &self.cells,
            inp: *inp,
            slots,
            kept_loads: &self.kept_loads,
        }
    }

    /// The frames joints hold, built for FMA.
    #[cfg_attr(target_arch = "x86_64", target_feature(enable = "fma"))]
    unsafe fn frames_fma(&self, inp: &Inputs, which: &[links::ArmFrame], out: &mut [f64]) {
        let mut slots = self.slots.borrow_mut();
        let mut cells = self.linked(inp, &mut slots);
        let (q, qd, p) = (inp.q, inp.qd, inp.p);
        links::frames(&self.links.layout, &mut cells, q, qd, p, which, out);
    }

    /// The contact groups' bounds built for FMA.
    #[cfg_attr(target_arch = "x86_64", target_feature(enable = "fma"))]
    unsafe fn bounds_fma(&self, inp: &Inputs, out: &mut [f64]) {
        let mut slots = self.slots.borrow_mut();
        let mut cells = self.linked(inp, &mut slots);
        let (layout, groups) = (&self.links.layout, &self.info.contact_groups);
        let mut kept = self.kept.borrow_mut();
        let state = (inp.q, inp.qd, inp.p);
        links::contact_bounds(layout, (&mut cells, &mut kept), state, groups, out);
    }

    /// The articulated-body sweeps built for FMA.
    #[cfg_attr(target_arch = "x86_64", target_feature(enable = "fma"))]
    unsafe fn accelerations_fma(&self, inp: &Inputs, qdd: &mut [f64]) -> bool {
        let mut slots = self.slots.borrow_mut();
        let mut cells = self.linked(inp, &mut slots);
        let layout = &self.links.layout;
        match layout.general_bodies() {
            true => accelerations_owned::<_, true>(layout, &mut cells, inp.q, inp.qd, inp.p, qdd),
            false => accelerations_owned::<_, false>(layout, &mut cells, inp.q, inp.qd, inp.p, qdd),
        }
    }

    /// The recursion built for FMA as the generated kernels build it: its
    /// `mul_add`s are instructions, not calls.
    #[cfg_attr(target_arch = "x86_64", target_feature(enable = "fma"))]
    unsafe fn eval_fma(&self, kind: KernelKind, inp: &Inputs, out: &mut [f64]) {
        let mut slots = self.slots.borrow_mut();
        let mut cells = self.linked(inp, &mut slots);
        let layout = &self.links.layout;
        match kind {
            KernelKind::MassBias if all_owned(layout) => match layout.general_bodies() {
                true => mass_bias_owned::<_, true>(layout, &mut cells, inp.q, inp.qd, inp.p, out),
                false => mass_bias_owned::<_, false>(layout, &mut cells, inp.q, inp.qd, inp.p, out),
            },
            KernelKind::MassBias => {
                mass_bias_shared_dyn(layout, &mut cells, inp.q, inp.qd, inp.p, out)
            }
            KernelKind::Outputs => outputs(layout, &mut cells, inp.q, inp.qd, inp.p, out),
            KernelKind::Jvp => {
                let zeros = vec![0.0; 2 * layout.dof];
                let inp = inp.zero_filled(&zeros);
                let mut tau = vec![0.0; layout.dof];
                inverse_dynamics_tangent(
                    layout, &mut cells, inp.q, inp.qd, inp.qdd, inp.dir, inp.p, &mut tau, out,
                )
            }
            KernelKind::Contact | KernelKind::ContactJacobian | KernelKind::ContactJvp
                if contact_by_links(&self.links, &self.info) =>
            {
                self.contact(kind, &mut cells, inp, out)
            }
            // No symbolic solve (`with_tapes` says so); derived parameters
            // and contact from the tapes when the chain has them.
            KernelKind::Derived
            | KernelKind::Accel
            | KernelKind::Constraints
            | KernelKind::Contact
            | KernelKind::ContactJacobian
            | KernelKind::ContactJvp => match &self.rest {
                Some(rest) => rest.eval(kind, inp, out),
                None => debug_assert!(out.is_empty(), "{kind:?} of a linked chain"),
            },
        }
    }
}
