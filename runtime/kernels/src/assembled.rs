//! An assembly's kernels through its arms' own ([`ArmBlocks`]) at run
//! time: what a compiled-in assembly's generated code does, for one that
//! is not compiled in. Each distinct arm structure brings its own kernels
//! (its link cells, linked); the rest of the system (bodies, what joins
//! the arms), the joints and contact run on the assembly's tapes.

use std::cell::RefCell;

use crate::kernels::{ArmBlocks, Interpreted, KernelKind, Kernels, ModelInfo, TapeSet};
use crate::linalg::add_block;
use crate::output;
use crate::tape::{Inputs, Tape};

/// An assembly's kernels: `MassBias`, `Jvp`, `Outputs` and `Derived` as
/// the rest's tapes plus each arm's kernels in its block; the joints and
/// contact by the assembly's tapes.
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
            ..tapes.info.clone()
        };
        Some(Self {
            info,
            flat: Interpreted::new(tapes),
            blocks,
            kinds,
            starts,
            slots: RefCell::new(Vec::new()),
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
            let mut block = vec![0.0; dof * (dof + 1) / 2 + dof];
            kernels.eval(KernelKind::MassBias, &arm, &mut block);
            add_block(n, first, dof, &block, out);
        }
    }

    /// The Jvp along `inp.dir` (absent accelerations and direction read
    /// as zeros, as every backend's).
    fn jvp(&self, inp: &Inputs, out: &mut [f64]) {
        let n = self.info.dof();
        let zeros = vec![0.0; 2 * n];
        let inp = inp.zero_filled(&zeros);
        self.rest(&self.blocks.rest_jvp, &inp, out);
        for i in 0..self.blocks.arms.len() {
            let (kernels, first, arm) = self.arm(i, &inp);
            let dof = arm.q.len();
            let mut d = vec![0.0; 2 * dof];
            d[..dof].copy_from_slice(&inp.dir[first..first + dof]);
            d[dof..].copy_from_slice(&inp.dir[n + first..n + first + dof]);
            if d.iter().all(|&x| x == 0.0) {
                continue;
            }
            let mut tau = vec![0.0; dof];
            let arm = Inputs {
                qdd: &inp.qdd[first..first + dof],
                dir: &d,
                ..arm
            };
            kernels.eval(KernelKind::Jvp, &arm, &mut tau);
            for (o, x) in out[first..first + dof].iter_mut().zip(&tau) {
                *o += x;
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
            // No symbolic solve (`new` says so); joints and contact from
            // the assembly's tapes.
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
