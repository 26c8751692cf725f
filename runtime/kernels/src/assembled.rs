//! An assembly's kernels through its arms' own ([`ArmBlocks`]) at run
//! time: what a compiled-in assembly's generated code does, for one that
//! is not compiled in. Each distinct arm structure brings its own kernels
//! (its link cells, linked), its contact points' too, and the frames its
//! joints hold; the rest of the system (bodies, what joins the arms, the
//! bodies' contact points, the joints' rows on those frames) runs on the
//! assembly's tapes.

use std::cell::RefCell;

use crate::joints::{self, HeldFrame, JointFrame};
use crate::kernels::{ArmBlocks, Interpreted, KernelKind, Kernels, ModelInfo, TapeSet};
use crate::linalg::{add_block, place_groups, place_point_rows};
use crate::links::frame;
use crate::output;
use crate::tape::{Inputs, Tape};

/// An assembly's kernels: `MassBias`, `Jvp`, `Outputs` and `Derived` as
/// the rest's tapes plus each arm's kernels in its block, the contact
/// kernels so too where the tapes split them (`ArmBlocks::rest_contact`),
/// the joints on the arms' frames where the tapes have their rows on them
/// (`ArmBlocks::joints`); else by the assembly's flat tapes.
pub struct BlockKernels {
    info: ModelInfo,
    /// The assembly's tapes: its own derived parameters, joints, contact.
    flat: Interpreted,
    blocks: ArmBlocks,
    /// The kernels of each arm kind (`blocks.kinds`).
    kinds: Vec<Box<dyn Kernels>>,
    /// Where each arm's parameters start among the derived ones.
    starts: Vec<usize>,
    slots: RefCell<Vec<f64>>,
    /// The arms' outputs before they are placed in the assembly's, the
    /// held frames' motions ([`BlockKernels::scratch`]).
    scratch: RefCell<Vec<f64>>,
}

impl BlockKernels {
    /// The assembly of `tapes` with `kinds[k]` the kernels of its arm kind
    /// k; `None` when its arms have no kernels of their own.
    pub fn new(tapes: TapeSet, kinds: Vec<Box<dyn Kernels>>) -> Option<Self> {
        let blocks = tapes.arm_blocks.clone()?;
        assert_eq!(kinds.len(), blocks.kinds.len(), "one set of kernels a kind");
        let (starts, total) = blocks.derived_layout(tapes.info.derived);
        let info = ModelInfo {
            derived: total,
            accel: false,
            copies: blocks.copies(tapes.info.parameters.len(), tapes.info.derived),
            ..tapes.info.clone()
        };
        Some(Self {
            info,
            flat: Interpreted::new(tapes),
            blocks,
            kinds,
            starts,
            slots: RefCell::new(Vec::new()),
            scratch: RefCell::new(Vec::new()),
        })
    }

    /// Arm `i`'s kernels, first coordinate and inputs: its slices of the
    /// coordinates and rates, its parameters among the extended ones, no
    /// accelerations or direction (the Jvp sets its own).
    fn arm<'a>(&'a self, i: usize, inp: &Inputs<'a>) -> (&'a dyn Kernels, usize, Inputs<'a>) {
        let a = &self.blocks.arms[i];
        let kernels = &*self.kinds[a.kind];
        let at = self.info.parameters.len() + self.starts[i];
        let len = kernels.info().extended_params();
        let (first, dof) = (a.first, a.dof);
        let arm = Inputs {
            q: &inp.q[first..first + dof],
            qd: &inp.qd[first..first + dof],
            qdd: &[],
            dir: &[],
            p: &inp.p[at..at + len],
            ..*inp
        };
        (kernels, first, arm)
    }

    /// `len` zeros for an arm's outputs, reused from call to call: a
    /// right-hand side asks for every arm's mass + bias and contact, an
    /// implicit step for 2n Jvp columns.
    fn scratch(&self, len: usize) -> std::cell::RefMut<'_, Vec<f64>> {
        let mut s = self.scratch.borrow_mut();
        s.clear();
        s.resize(len, 0.0);
        s
    }

    fn rest(&self, tape: &Tape, inp: &Inputs, out: &mut [f64]) {
        tape.eval(inp, &mut self.slots.borrow_mut(), out);
    }

    /// The assembly's own derived parameters, then each arm's base ones
    /// (copied) and derived ones.
    fn derived(&self, inp: &Inputs, out: &mut [f64]) {
        let own = self.flat.info().derived;
        self.flat.eval(KernelKind::Derived, inp, &mut out[..own]);
        for (i, a) in self.blocks.arms.iter().enumerate() {
            let kernels = &*self.kinds[a.kind];
            let (base, all) = (
                kernels.info().parameters.len(),
                kernels.info().extended_params(),
            );
            let mut pe = vec![0.0; all];
            pe[..base].copy_from_slice(&inp.p[a.params..a.params + base]);
            let s = self.starts[i];
            out[s..s + base].copy_from_slice(&pe[..base]);
            let zeros = vec![0.0; 2 * a.dof];
            let arm = Inputs {
                q: &zeros[..a.dof],
                qd: &zeros[..a.dof],
                qdd: &zeros[..a.dof],
                dir: &zeros,
                p: &pe,
                ..*inp
            };
            kernels.eval(KernelKind::Derived, &arm, &mut out[s + base..s + all]);
        }
    }

    fn mass_bias(&self, inp: &Inputs, out: &mut [f64]) {
        self.rest(&self.blocks.rest_mass_bias, inp, out);
        let n = self.info.dof();
        for i in 0..self.blocks.arms.len() {
            let (kernels, first, arm) = self.arm(i, inp);
            let dof = arm.q.len();
            let mut block = self.scratch(dof * (dof + 1) / 2 + dof);
            kernels.eval(KernelKind::MassBias, &arm, &mut block);
            add_block(n, first, dof, &block, out);
        }
    }

    /// The Jvp along `inp.dir` (absent accelerations and direction read
    /// as zeros, as every backend's).
    fn jvp(&self, inp: &Inputs, out: &mut [f64]) {
        let n = self.info.dof();
        let most = self.blocks.arms.iter().map(|a| a.dof).max().unwrap_or(0);
        let mut scratch = self.scratch(2 * n + 3 * most);
        let (zeros, free) = scratch.split_at_mut(2 * n);
        let inp = inp.zero_filled(zeros);
        self.rest(&self.blocks.rest_jvp, &inp, out);
        for i in 0..self.blocks.arms.len() {
            let (kernels, first, arm) = self.arm(i, &inp);
            let dof = arm.q.len();
            let (d, tau) = free.split_at_mut(2 * dof);
            let tau = &mut tau[..dof];
            d[..dof].copy_from_slice(&inp.dir[first..first + dof]);
            d[dof..].copy_from_slice(&inp.dir[n + first..n + first + dof]);
            if d.iter().all(|&x| x == 0.0) {
                continue;
            }
            let arm = Inputs {
                qdd: &inp.qdd[first..first + dof],
                dir: d,
                ..arm
            };
            tau.fill(0.0);
            kernels.eval(KernelKind::Jvp, &arm, tau);
            for (o, x) in out[first..first + dof].iter_mut().zip(tau.iter()) {
                *o += x;
            }
        }
    }

    /// A contact kernel: each arm's points from its own kernels (the
    /// `ContactJacobian` groups `inp.dir` selects, its columns placed in
    /// the arm's block), then the bodies' from the rest's tapes; as the
    /// generated code of a compiled-in assembly does (`eomgen::emit`).
    fn contact(&self, kind: KernelKind, inp: &Inputs, out: &mut [f64]) {
        let rest = self.blocks.rest_contact.as_ref().expect("split contact");
        let n = self.info.dof();
        let (width, tail) = (6 + 3 * n, 3 + 3 * n);
        let all = inp.dir.is_empty();
        let (mut point, mut group) = (0, 0);
        let mut slots = self.slots.borrow_mut();
        for i in 0..self.blocks.arms.len() {
            let (kernels, first, arm) = self.arm(i, inp);
            let info = kernels.info();
            let (np, ng, m) = (info.contact_points, info.contact_groups.len(), arm.q.len());
            // The arm's points, and its contact frames for its groups; a
            // direction; the rows of its groups.
            let n_own = 3 * np + info.contact_frames;
            let mut scratch = self.scratch(n_own + 2 * m + np * (6 + 3 * m));
            let (own, free) = scratch.split_at_mut(n_own);
            let (d, rows) = free.split_at_mut(2 * m);
            if kind == KernelKind::Contact || info.contact_frames > 0 {
                kernels.eval(KernelKind::Contact, &arm, own);
            }
            match kind {
                KernelKind::Contact => {
                    out[3 * point..3 * (point + np)].copy_from_slice(&own[..3 * np]);
                }
                KernelKind::ContactJacobian => {
                    if !all {
                        d[..ng].copy_from_slice(&inp.dir[group..group + ng]);
                    }
                    if all || d.iter().any(|&x| x != 0.0) {
                        let arm = Inputs {
                            dir: if all { &[] } else { d },
                            aux: &own[3 * np..],
                            ..arm
                        };
                        kernels.eval(KernelKind::ContactJacobian, &arm, rows);
                        let o = &mut out[point * width..(point + np) * width];
                        place_groups(all, d, &info.contact_groups, n, first, m, rows, o);
                    }
                }
                _ => {
                    d[..m].copy_from_slice(&inp.dir[first..first + m]);
                    let o = &mut out[point * tail..(point + np) * tail];
                    // Along a direction off its block, an arm's points do
                    // not move.
                    if d.iter().any(|&x| x != 0.0) {
                        let rows = &mut rows[..np * (3 + 3 * m)];
                        kernels.eval(KernelKind::ContactJvp, &Inputs { dir: d, ..arm }, rows);
                        place_point_rows(3, n, first, m, rows, o);
                    } else {
                        o.fill(0.0);
                    }
                }
            }
            point += np;
            group += ng;
        }
        if rest.groups.iter().sum::<usize>() == 0 {
            return;
        }
        match kind {
            KernelKind::Contact => rest.contact.eval(inp, &mut slots, &mut out[3 * point..]),
            KernelKind::ContactJacobian => {
                for (r, (tape, &len)) in rest.contact_jacobian.iter().zip(&rest.groups).enumerate()
                {
                    if all || inp.dir[group + r] != 0.0 {
                        let o = &mut out[point * width..(point + len) * width];
                        tape.eval(inp, &mut slots, o);
                    }
                    point += len;
                }
            }
            _ => {
                let n2 = 2 * n;
                let zeros = vec![0.0; n2];
                let inp = inp.zero_filled(&zeros);
                rest.contact_jvp
                    .eval(&inp, &mut slots, &mut out[point * tail..]);
            }
        }
    }

    /// The rest's energies with each arm's added; the tip is the first
    /// arm's.
    fn outputs(&self, inp: &Inputs, out: &mut [f64]) {
        self.rest(&self.blocks.rest_outputs, inp, out);
        for i in 0..self.blocks.arms.len() {
            let (kernels, _, arm) = self.arm(i, inp);
            let mut o = [0.0; output::N_OUTPUTS];
            kernels.eval(KernelKind::Outputs, &arm, &mut o);
            out[output::KINETIC] += o[output::KINETIC];
            out[output::POTENTIAL] += o[output::POTENTIAL];
            if i == 0 {
                out[output::TIP].copy_from_slice(&o[output::TIP]);
                out[output::ORIENTATION].copy_from_slice(&o[output::ORIENTATION]);
            }
        }
    }

    /// The joints through their arms' frames (`crate::joints`); false,
    /// leaving `out` to the flat tapes, where the assembly has no such
    /// kernel or an arm's kernels give no frames.
    fn joints(&self, inp: &Inputs, out: &mut [f64]) -> bool {
        let Some(joints) = &self.blocks.joints else {
            return false;
        };
        let dof = |f: &JointFrame| self.blocks.arms[f.arm].dof;
        let (n, m) = (self.info.dof(), self.info.constraints.len());
        let lens: usize = joints.frames.iter().map(|f| frame::len(dof(f))).sum();
        let n_aux = frame::STATE * joints.frames.len();
        let mut scratch = self.scratch(lens + n_aux + joints::rows_len(m, n, joints.frames.len()));
        let (motions, rest) = scratch.split_at_mut(lens);
        let (aux, rows) = rest.split_at_mut(n_aux);
        let mut free = &mut motions[..];
        for f in &joints.frames {
            let (kernels, _, arm) = self.arm(f.arm, inp);
            let (motion, next) = free.split_at_mut(frame::len(dof(f)));
            if !kernels.frames(&arm, &[f.at], motion) {
                return false;
            }
            free = next;
        }
        let mut at = 0;
        let held: Vec<HeldFrame> = (joints.frames.iter())
            .map(|f| {
                let a = &self.blocks.arms[f.arm];
                let motion = &motions[at..at + frame::len(a.dof)];
                at += motion.len();
                HeldFrame {
                    first: a.first,
                    dof: a.dof,
                    motion,
                }
            })
            .collect();
        joints::aux(&held, aux);
        self.rest(&joints.rows, &Inputs { aux, ..*inp }, rows);
        joints::constraints(n, &held, rows, out);
        true
    }
}

impl Kernels for BlockKernels {
    fn info(&self) -> &ModelInfo {
        &self.info
    }

    fn eval(&self, kind: KernelKind, inp: &Inputs, out: &mut [f64]) {
        match kind {
            KernelKind::Derived => self.derived(inp, out),
            KernelKind::MassBias => self.mass_bias(inp, out),
            KernelKind::Jvp => self.jvp(inp, out),
            KernelKind::Outputs => self.outputs(inp, out),
            KernelKind::Contact | KernelKind::ContactJacobian | KernelKind::ContactJvp
                if self.blocks.rest_contact.is_some() =>
            {
                self.contact(kind, inp, out)
            }
            KernelKind::Constraints if self.joints(inp, out) => {}
            // No symbolic solve (`new` says so); the joints (and contact
            // the tapes do not split) from the assembly's tapes.
            KernelKind::Accel
            | KernelKind::Constraints
            | KernelKind::Contact
            | KernelKind::ContactJacobian
            | KernelKind::ContactJvp => self.flat.eval(kind, inp, out),
        }
    }

    fn backend(&self) -> &'static str {
        "compiled"
    }
}
